"""Lyapunov exponents from the tangent (variational) equations, specialised per model.

This file is a template, like :mod:`geardyn.solvers._kernel_template`:
:func:`geardyn.solvers.kernels.kernels_for` (template ``"lyapunov"``) copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions. As it stands it is a valid
module bound to the small test oscillator of :mod:`geardyn.solvers._template_model`.

Numerics
--------
* The state y is advanced on the main solver's grid (``n_per`` RK4 steps of ``h`` per forcing
  period, forcing phase from the same half-step table; an autonomous model has ``omega = 0`` and
  any ``h``), with the crossings of the ``n_ev`` switching functions located inside a step and
  the step split there, as in :mod:`geardyn.solvers._kernel_template` (``_grid_step``).
* Each tangent vector v is advanced by the derivative of that step map Phi, by a central
  difference: ``(Phi(y + e v) - Phi(y - e v)) / (2 e)`` with ``e |v| = FD_DELTA (1 + |y|)``
  (Euclidean norms, FD_DELTA = 2^-20 ~ 1e-6). For a smooth field this is RK4 applied to the
  variational equation v' = J(t, y) v (to O(e^2)); the perturbed states locate their own edge
  crossings, so a step in which one of them crosses an edge is differentiated correctly and the
  exponent keeps the solver's order. It is exact for affine step maps (linear models) up to
  rounding (~ eps / FD_DELTA ~ 1e-10 relative per step). The vector field is continuous across
  the dead-zone edges, so the flow is C^1 there and no saltation matrix is needed.
* Every ``renorm_every`` steps (and at the end of the transient and of the run) the tangent
  vectors are re-orthonormalised by modified Gram-Schmidt (a QR factorisation); the logs of the
  diagonal of R are summed over the measuring window (Benettin et al. 1980; Shimada & Nagashima
  1979). The transient advances the tangent vectors too (renormalised, not summed) so that they
  are aligned when measuring starts.
* A lane whose state leaves ``|y| <= bound`` (checked at each renormalisation) or whose tangent
  vectors stop being finite is marked diverged (status 1) and its exponents are NaN.
* Cost per step: (2 k + 1) RK4 steps for k tangent vectors.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False}
#: Relative size of the finite-difference perturbation: e |v| = FD_DELTA (1 + |y|).
FD_DELTA = 2.0**-20
#: Most located edge crossings inside one grid step (then the step is taken unsplit).
MAX_SPLITS = 8
STATUS_OK = 0
STATUS_DIVERGED = 1

# the model interface names are part of the template's namespace (the generated copy re-binds
# them); only rhs is used here
__all__ = ["events", "lyapunov_lanes", "lyapunov_single", "observe", "phase_table", "rhs"]


@nb.njit(**_JIT)
def phase_table(n_per, forced):
    """sin and cos of the forcing phase at the 2 n_per + 1 half-step points of one period."""
    s = np.zeros(2 * n_per + 1)
    c = np.ones(2 * n_per + 1)
    if forced:
        for k in range(1, 2 * n_per):
            a = math.pi * k / n_per
            s[k] = math.sin(a)
            c[k] = math.cos(a)
    return s, c


@nb.njit(inline="always", **_JIT)
def _side(x):
    return 1 if x > 0.0 else -1


@nb.njit(**_JIT)
def _rk4(t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, k4, tmp, out, have_k1):
    """One RK4 step of size h from (t, y) into out; k1 holds f(t, y) if have_k1."""
    ns = y.size
    if not have_k1:
        rhs(t, y, k1, p, s0, c0)
    hh = 0.5 * h
    for q in range(ns):
        tmp[q] = y[q] + hh * k1[q]
    rhs(t + hh, tmp, k2, p, s1, c1)
    for q in range(ns):
        tmp[q] = y[q] + hh * k2[q]
    rhs(t + hh, tmp, k3, p, s1, c1)
    for q in range(ns):
        tmp[q] = y[q] + h * k3[q]
    rhs(t + h, tmp, k4, p, s2, c2)
    h6 = h / 6.0
    for q in range(ns):
        out[q] = y[q] + h6 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])


@nb.njit(**_JIT)
def _hermite(y0, f0, y1, f1, dt, theta, out):
    """Cubic Hermite interpolant of a step of length dt at fraction theta."""
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = (t3 - 2.0 * t2 + theta) * dt
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = (t3 - t2) * dt
    for q in range(y0.size):
        out[q] = h00 * y0[q] + h10 * f0[q] + h01 * y1[q] + h11 * f1[q]


@nb.njit(**_JIT)
def _locate(j, side_j, g0j, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf):
    """Fraction in (0, 1] of the step where event j leaves side side_j (Illinois method)."""
    a = 0.0
    fa = g0j if _side(g0j) == side_j else (1e-300 if side_j > 0 else 0.0)
    b = 1.0
    fb = g1j
    last = 0
    for _ in range(60):
        denom = fb - fa
        x = (a * fb - b * fa) / denom if denom != 0.0 else 0.5 * (a + b)
        if not (a < x < b):
            x = 0.5 * (a + b)
        _hermite(y0, f0, y1, f1, dt, x, ybuf)
        events(t + x * dt, ybuf, gbuf, p)
        fx = gbuf[j]
        if _side(fx) == side_j:
            a = x
            fa = fx
            if last == -1:
                fb *= 0.5
            last = -1
        else:
            b = x
            fb = fx
            if last == 1:
                fa *= 0.5
            last = 1
        if b - a < 1e-13:
            break
    return b


@nb.njit(**_JIT)
def _grid_step(i, y, p, h, omega, n_per, sa, ca, sb, cb, se, ce, n_ev, W, side, g0, g1, gbuf):
    """Advance y (in place) by grid step i (time i h to (i + 1) h): one RK4 step, or, with
    ``n_ev`` switching functions of which one changes side, the step split at the located
    crossings (at most MAX_SPLITS times), as the main solver does."""
    k1 = W[0]
    k2 = W[1]
    k3 = W[2]
    k4 = W[3]
    tmp = W[4]
    f1 = W[5]
    ystart = W[6]
    ytrial = W[7]
    ybuf = W[8]
    t = i * h
    t_end = (i + 1) * h
    if n_ev > 0:
        events(t, y, g0, p)
        for j in range(n_ev):
            side[j] = _side(g0[j])
    _rk4(t, y, h, p, sa, ca, sb, cb, se, ce, k1, k2, k3, k4, tmp, ytrial, False)
    crossed = False
    if n_ev > 0:
        events(t_end, ytrial, g1, p)
        for j in range(n_ev):
            if _side(g1[j]) != side[j]:
                crossed = True
    if not crossed:
        for q in range(y.size):
            y[q] = ytrial[q]
        return
    # k1 holds f(t, y); locate and split (the forcing phase at fractions of the step by sin/cos)
    u = 0.0
    i_mod = i % n_per
    wh = omega * h
    for _ in range(MAX_SPLITS):
        tu0 = t + u * h
        dt = (1.0 - u) * h
        s0 = math.sin(wh * (i_mod + u))
        c0 = math.cos(wh * (i_mod + u))
        if u > 0.0:
            sm = math.sin(wh * (i_mod + 0.5 * (1.0 + u)))
            cm = math.cos(wh * (i_mod + 0.5 * (1.0 + u)))
            _rk4(tu0, y, dt, p, s0, c0, sm, cm, se, ce, k1, k2, k3, k4, tmp, ytrial, False)
            events(t_end, ytrial, g1, p)
        rhs(t_end, ytrial, f1, p, se, ce)
        for q in range(y.size):
            ystart[q] = y[q]
        events(tu0, y, gbuf[0], p)
        first = -1
        theta = 2.0
        for j in range(n_ev):
            if _side(g1[j]) != side[j]:
                th = _locate(j, side[j], gbuf[0, j], g1[j], ystart, k1, ytrial, f1, dt, tu0, p,
                             ybuf, gbuf[1])
                if th < theta:
                    theta = th
                    first = j
        if first < 0:
            for q in range(y.size):
                y[q] = ytrial[q]
            return
        tm = u + 0.5 * theta * (1.0 - u)
        tu = u + theta * (1.0 - u)
        _rk4(tu0, ystart, theta * dt, p, s0, c0, math.sin(wh * (i_mod + tm)),
             math.cos(wh * (i_mod + tm)), math.sin(wh * (i_mod + tu)),
             math.cos(wh * (i_mod + tu)), k1, k2, k3, k4, tmp, y, True)
        side[first] = -side[first]
        u = tu
        if u >= 1.0:
            return
    for q in range(y.size):
        y[q] = ytrial[q]


@nb.njit(**_JIT)
def _tangent_step(i, Z, p, h, omega, n_per, s_tab, c_tab, n_ev, W, YP, side, g0, g1, gbuf):
    """Advance the state (row 0 of Z) by one grid step and each tangent vector v (rows 1..) by
    the derivative of that step map: (Phi(y + e v) - Phi(y - e v)) / (2 e)."""
    m, ns = Z.shape
    j0 = 2 * (i % n_per)
    sa = s_tab[j0]
    ca = c_tab[j0]
    sb = s_tab[j0 + 1]
    cb = c_tab[j0 + 1]
    se = s_tab[j0 + 2]
    ce = c_tab[j0 + 2]
    ny = 0.0
    for q in range(ns):
        ny += Z[0, q] * Z[0, q]
    scale = FD_DELTA * (1.0 + math.sqrt(ny))
    for j in range(1, m):
        nv = 0.0
        for q in range(ns):
            nv += Z[j, q] * Z[j, q]
        nv = math.sqrt(nv)
        if not (nv > 0.0 and math.isfinite(nv)):
            for q in range(ns):
                Z[j, q] = np.nan
            continue
        e = scale / nv
        for q in range(ns):
            YP[0, q] = Z[0, q] + e * Z[j, q]
            YP[1, q] = Z[0, q] - e * Z[j, q]
        _grid_step(i, YP[0], p, h, omega, n_per, sa, ca, sb, cb, se, ce, n_ev, W, side, g0, g1,
                   gbuf)
        _grid_step(i, YP[1], p, h, omega, n_per, sa, ca, sb, cb, se, ce, n_ev, W, side, g0, g1,
                   gbuf)
        inv = 0.5 / e
        for q in range(ns):
            Z[j, q] = (YP[0, q] - YP[1, q]) * inv
    _grid_step(i, Z[0], p, h, omega, n_per, sa, ca, sb, cb, se, ce, n_ev, W, side, g0, g1, gbuf)


@nb.njit(**_JIT)
def _orthonormalise(Z, acc, add):
    """Modified Gram-Schmidt on the tangent rows 1.. of Z; adds log of R's diagonal to acc when
    ``add``. Returns False if a vector vanished or is not finite."""
    m, ns = Z.shape
    for j in range(1, m):
        for i in range(1, j):
            d = 0.0
            for q in range(ns):
                d += Z[j, q] * Z[i, q]
            for q in range(ns):
                Z[j, q] -= d * Z[i, q]
        r = 0.0
        for q in range(ns):
            r += Z[j, q] * Z[j, q]
        r = math.sqrt(r)
        if not (r > 0.0 and math.isfinite(r)):
            return False
        if add:
            acc[j - 1] += math.log(r)
        inv = 1.0 / r
        for q in range(ns):
            Z[j, q] *= inv
    return True


@nb.njit(**_JIT)
def _healthy(y, bound):
    for q in range(y.size):
        if not (abs(y[q]) <= bound):  # False for NaN too
            return False
    return True


@nb.njit(**_JIT)
def _run(p, y0, h, omega, n_per, s_tab, c_tab, n_transient, n_steps, renorm_every, k, bound,
         n_ev):
    """Exponents (sum of logs / measured time) and status of one lane."""
    ns = y0.size
    m = k + 1
    Z = np.zeros((m, ns))
    W = np.zeros((9, ns))
    YP = np.zeros((2, ns))
    ne = max(n_ev, 1)
    side = np.ones(ne, np.int64)
    g0 = np.zeros(ne)
    g1 = np.zeros(ne)
    gbuf = np.zeros((2, ne))
    acc = np.zeros(k)
    out = np.full(k, np.nan)
    for q in range(ns):
        Z[0, q] = y0[q]
    # generic, orthonormalised start vectors: e_j + 0.1 (1, ..., 1)
    for j in range(1, m):
        for q in range(ns):
            Z[j, q] = 0.1 + (1.0 if q == j - 1 else 0.0)
    _orthonormalise(Z, acc, False)
    renorm = max(renorm_every, 1)
    total = n_transient + n_steps
    since = 0
    for i in range(total):
        _tangent_step(i, Z, p, h, omega, n_per, s_tab, c_tab, n_ev, W, YP, side, g0, g1, gbuf)
        since += 1
        step = i + 1
        if since == renorm or step == n_transient or step == total:
            since = 0
            if not _healthy(Z[0], bound):
                return out, STATUS_DIVERGED
            if not _orthonormalise(Z, acc, step > n_transient):
                return out, STATUS_DIVERGED
    if n_steps <= 0:
        return out, STATUS_OK
    tm = n_steps * h
    for j in range(k):
        out[j] = acc[j] / tm
    return out, STATUS_OK


@nb.njit(**_JIT)
def lyapunov_single(p, y0, h, omega, n_per, n_transient, n_steps, renorm_every, k, bound,
                    n_ev=0):
    """The k leading Lyapunov exponents (per unit time of the model) of one parameter set.

    Grid: step h (= 2 pi / (omega n_per) for a forced model); ``n_transient`` steps are discarded
    and ``n_steps`` measured. ``n_ev``: the model's number of switching functions, whose
    crossings are located inside a step (0: none located). Returns (exponents[k], status);
    exponents are NaN if diverged.
    """
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    return _run(p, y0, h, omega, n_per, s_tab, c_tab, n_transient, n_steps, renorm_every, k,
                bound, n_ev)


@nb.njit(parallel=True, **_JIT)
def lyapunov_lanes(P, Y0, H, OMEGA, n_per, n_transient, n_steps, renorm_every, bound, out,
                   n_ev=0):
    """Largest exponent of every lane (row of P, Y0), in parallel over lanes.

    H, OMEGA: step and forcing frequency per lane; n_transient, n_steps: per-lane step counts
    (int arrays); n_ev as in :func:`lyapunov_single`. Fills out[L] (NaN for diverged lanes).
    """
    L, ns = Y0.shape
    forced = False
    for lane in range(L):
        if OMEGA[lane] != 0.0:
            forced = True
    s_tab, c_tab = phase_table(n_per, forced)
    for lane in nb.prange(L):
        ex, st = _run(P[lane], Y0[lane], H[lane], OMEGA[lane], n_per, s_tab, c_tab,
                      n_transient[lane], n_steps[lane], renorm_every, 1, bound, n_ev)
        out[lane] = ex[0] if st == STATUS_OK else np.nan
