"""Accuracy order of a split step's tangent carried through the state's RK4 sub-steps (a study in
plain Python on the gear pair; no kernel).

The finite-time largest exponent of the tests' gear-pair cases (``tests/test_lyapunov_variational``:
the same start, start vector, windows and DOP853 reference of the state and variational
equations) at 128 to 1024 steps per period, by three tangents of a grid step split at its edge
crossings (crossing fraction on the cubic Hermite interpolant of the trial step, RK4 sub-steps,
as ``_split_step`` does; grazes are not screened here):

* ``rows``: central differences of the split step map, each of the rows y +- e v split at its
  own crossing (what the kernels' flagged lanes do; reproduces their error, 1.67e-8 and 2.9e-9
  at 128 and 256 steps);
* ``substeps``: the variational RK4 through the state's sub-steps, the Jacobian of each sub-step
  taken on the side that sub-step integrates (forced; unsplit steps as the stages fall);
* ``corrected``: ``substeps`` plus, at each split point x, the tangent moved to where the
  numerical orbit crosses the edge: ``w -= (g(x) / g'(x)) (J_before - J_after) w``, g the edge
  crossed, g' its rate along the orbit. The split point lies off the edge by the trial step's
  error across the kink (O(h^3)), so without it the tangent switches sides O(h^3) early or late
  at every crossing.

    .venv/bin/python bench/split_tangent_order.py [--cases impacting chaotic]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import geardyn

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from test_lyapunov_variational import CASES, _gear_pair_reference  # noqa: E402

B = 1.0  # the backlash edges x = +-B


def region(x: float) -> int:
    return 1 if x > B else (-1 if x < -B else 0)


def make(pars):
    """The gear pair's f(t, y) and J(t, y) w, each on side ``reg`` where given."""
    zeta, kappa, fm, fa, om = (pars[k] for k in ("zeta", "kappa", "Fm", "Fa", "Omega"))

    def f(t, y):
        x, xd = y
        r = region(x)
        g = (x - B) if r == 1 else ((x + B) if r == -1 else 0.0)
        k = 1.0 + kappa * math.cos(om * t)
        return np.array([xd, fm + fa * om * om * math.cos(om * t) - 2 * zeta * xd - k * g])

    def jv(t, y, w, reg=None):
        r = region(y[0]) if reg is None else reg
        k = 1.0 + kappa * math.cos(om * t)
        return np.array([w[1], -k * (1.0 if r else 0.0) * w[0] - 2 * zeta * w[1]])

    return f, jv, om


def rk4(f, t, y, h):
    k1 = f(t, y)
    k2 = f(t + h / 2, y + h / 2 * k1)
    k3 = f(t + h / 2, y + h / 2 * k2)
    k4 = f(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def rk4_var(f, jv, t, y, w, h, reg):
    """RK4 of the state and its tangent (the tangent's Jacobian on side ``reg``, or as the
    stages fall where None)."""
    k1, q1 = f(t, y), jv(t, y, w, reg)
    y2, w2 = y + h / 2 * k1, w + h / 2 * q1
    k2, q2 = f(t + h / 2, y2), jv(t + h / 2, y2, w2, reg)
    y3, w3 = y + h / 2 * k2, w + h / 2 * q2
    k3, q3 = f(t + h / 2, y3), jv(t + h / 2, y3, w3, reg)
    y4, w4 = y + h * k3, w + h * q3
    k4, q4 = f(t + h, y4), jv(t + h, y4, w4, reg)
    return (y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), w + h / 6 * (q1 + 2 * q2 + 2 * q3 + q4))


def crossing(f, t, y0, y1, h, r0):
    """Fraction of the step where x leaves region r0 on the step's cubic Hermite interpolant."""
    f0, f1 = f(t, y0), f(t + h, y1)

    def x_at(th):
        h00, h10 = 2 * th**3 - 3 * th**2 + 1, th**3 - 2 * th**2 + th
        h01, h11 = -2 * th**3 + 3 * th**2, th**3 - th**2
        return h00 * y0[0] + h10 * h * f0[0] + h01 * y1[0] + h11 * h * f1[0]

    a, b = 0.0, 1.0
    for _ in range(60):  # bisection to round-off
        m = 0.5 * (a + b)
        a, b = (m, b) if region(x_at(m)) == r0 else (a, m)
    return b


def split(f, t, y, h, w=None, jv=None, corrected=False):
    """One grid step of the state split at its crossings; w: the tangent through the
    sub-steps."""
    u, r = 0.0, region(y[0])
    while True:
        dt, tt = (1 - u) * h, t + u * h
        y1 = rk4(f, tt, y, dt)
        if region(y1[0]) == r:
            if w is not None:
                y1, w = rk4_var(f, jv, tt, y, w, dt, None if u == 0.0 else r)
            return y1, w
        th = crossing(f, tt, y, y1, dt, r)
        if w is not None:
            y, w = rk4_var(f, jv, tt, y, w, th * dt, r)
        else:
            y = rk4(f, tt, y, th * dt)
        u = u + th * (1 - u)
        r_new = (1 if y1[0] > 0 else -1) if r == 0 else 0
        if w is not None and corrected:
            edge = B if 1 in (r, r_new) else -B
            tx = t + u * h
            w = w - (y[0] - edge) / y[1] * (jv(tx, y, w, r) - jv(tx, y, w, r_new))
        r = r_new


def exponent(pars, n_per, n_tr, n_m, method, y0):
    """The finite-time exponent over n_m periods after n_tr (renormalised every 10 steps)."""
    f, jv, om = make(pars)
    h = 2 * math.pi / om / n_per
    y = np.array(y0, float)
    v = np.array([1.1, 0.1]) / math.hypot(1.1, 0.1)
    acc, total = 0.0, (n_tr + n_m) * n_per
    for i in range(total):
        t = i * h
        if method == "rows":
            e = 2.0**-20 * (1 + min(np.linalg.norm(y), 1024.0)) / np.linalg.norm(v)
            yp, ym = split(f, t, y + e * v, h)[0], split(f, t, y - e * v, h)[0]
            y, v = split(f, t, y, h)[0], (yp - ym) / (2 * e)
        else:
            y, v = split(f, t, y, h, v, jv, corrected=method == "corrected")
        if (i + 1) % 10 == 0 or i + 1 == n_tr * n_per or i + 1 == total:
            r = np.linalg.norm(v)
            acc += math.log(r) if i + 1 > n_tr * n_per else 0.0
            v /= r
    return acc / (n_m * n_per * h)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--steps", nargs="+", type=int, default=[128, 256, 512, 1024])
    a = ap.parse_args()
    for case in a.cases:
        pars, n_tr, n_m, _ = CASES[case]
        model = geardyn.GearPair(**pars)
        T, y0 = model.period, model.initial_state()
        ref = _gear_pair_reference(pars, y0, np.array([1.1, 0.1]),
                                   [n_tr * T, (n_tr + n_m) * T])[1] / (n_m * T)
        for n_per in a.steps:
            errs = {m: abs(exponent(pars, n_per, n_tr, n_m, m, y0) - ref)
                    for m in ("rows", "substeps", "corrected")}
            print(f"{case:9s} {n_per:5d} steps/period: |exponent - DOP853| "
                  + "  ".join(f"{m} {e:.3g}" for m, e in errs.items()), flush=True)


if __name__ == "__main__":
    main()
