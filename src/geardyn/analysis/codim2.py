"""Codimension-2 points on fold, period-doubling and Neimark-Sacker curves: test functions
and their location.

Each test function is evaluated at every accepted point of a curve (scaled state coordinates,
M the scaled monodromy, p and q the left and right eigenvectors of its critical eigenvalue with
p^T q = 1, |q| = 1, f = P^k in scaled coordinates, B and C its second and third derivatives at
the fixed point by central differences of step :data:`NF_STEP`):

* on a fold curve
    - ``cusp``: the fold's normal-form coefficient a = p^T B(q, q) / 2 (two fold curves meet
      in a cusp of the parameter plane where it vanishes);
    - ``fold_flip``: det(M + I) (a second multiplier through -1);
* on a period-doubling curve
    - ``fold_flip``: det(M - I) (a second multiplier through +1);
    - ``generalised_period_doubling``: the period doubling's normal-form coefficient
      c = p^T [C(q, q, q) / 6 + B(q, (I - M)^-1 B(q, q)) / 2] (the doubling changes from
      super- to subcritical where it vanishes);
* on a Neimark-Sacker curve, with cos(theta) = Re(mu_i + mu_j) / 2 of the two multipliers whose
  product is nearest 1 (|cos theta| > 1 on the neutral-saddle part)
    - ``resonance_1_1``: cos(theta) - 1 (the pair meets at +1, theta -> 0);
    - ``resonance_1_2``: cos(theta) + 1 (the pair meets at -1, theta -> pi).

The normal-form coefficients carry an error estimate, the change of the value when the
difference step is doubled; their sign change counts only where the value exceeds
:data:`ERROR_RATIO` times its estimate at both points (a linear system has a = c = 0 up to
round-off: no point is reported there).

A sign change between two curve points is located by regula falsi (Illinois) on the arclength
fraction between them, each trial corrected onto the curve on the hyperplane normal to the chord,
until the bracket is shorter than ``locate_tol`` in the scaled unknowns. The location error
(``special_error``) bounds the distance, in the scaled parameters (x / x_scale, y / y_scale),
of the located point from the zero of the discretised system's test function: the distance in
the scaled unknowns z from the located point to the bracket's farther end (the zero lies on the
arc between the ends, and the scaled parameters are coordinates of z: a bound also where the
curve turns in a parameter inside the bracket, e.g. a period-doubling curve at a fold-flip
point), plus the test function's error estimate at the located point over its slope between
the two curve points (per unit distance in z). It does not hold the discretisation error of the
fixed step (the difference from the exact flow's point, which falls as the step's fourth
power).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geardyn.analysis.arclength import ArclengthSettings, CurvePoint, correct
from geardyn.analysis.curve_systems import CurveInfo, CurveSystem

#: The codimension-2 points (``special_kind``), in words.
SPECIAL_KINDS = {
    "cusp": "two fold curves meet (fold normal-form coefficient a = 0)",
    "fold_flip": "multipliers +1 and -1 at once",
    "generalised_period_doubling": "period-doubling normal-form coefficient c = 0",
    "resonance_1_1": "Neimark-Sacker pair at +1 (strong resonance 1:1, theta = 0)",
    "resonance_1_2": "Neimark-Sacker pair at -1 (strong resonance 1:2, theta = pi)",
}
#: The test functions of each curve kind.
TESTS = {
    "fold": ("cusp", "fold_flip"),
    "period_doubling": ("fold_flip", "generalised_period_doubling"),
    "neimark_sacker": ("resonance_1_1", "resonance_1_2"),
}
#: Difference step of the normal-form derivatives, in the scaled state.
NF_STEP = 2e-3
#: A normal-form coefficient's sign change counts where |value| > ERROR_RATIO x its estimate.
ERROR_RATIO = 4.0
#: Most regula-falsi trials of a location.
LOCATE_MAX_ITER = 40


@dataclass
class Special:
    """A located codimension-2 point: ``kind``, the parameters ``x``, ``y`` with ``error``
    (see the module docstring), the index of the curve point before it, ``z`` and ``detail``;
    ``located`` False: the bracket's midpoint, the location failed (``detail`` says why)."""

    kind: str
    x: float
    y: float
    error: float
    index: int
    z: np.ndarray
    detail: str
    located: bool = True


def _second(f: Callable[[np.ndarray], np.ndarray], f0: np.ndarray, u: np.ndarray,
            h: float) -> np.ndarray:
    """B(u, u) by the central second difference."""
    return (f(h * u) - 2.0 * f0 + f(-h * u)) / (h * h)


def _third(f: Callable[[np.ndarray], np.ndarray], u: np.ndarray, h: float) -> np.ndarray:
    """C(u, u, u) by the central third difference."""
    return (f(2 * h * u) - 2.0 * f(h * u) + 2.0 * f(-h * u) - f(-2 * h * u)) / (2.0 * h ** 3)


def _fold_coefficient(sys: CurveSystem, info: CurveInfo, z: np.ndarray, h: float) -> float:
    p, q = sys.directions(info, 1.0)
    u0 = z[: sys.n]
    f0 = info.ev.end / sys.scale

    def f(du: np.ndarray) -> np.ndarray:
        return sys.period_map(info.problem, u0 + du)

    return 0.5 * float(p @ _second(f, f0, q, h))


def _pd_coefficient(sys: CurveSystem, info: CurveInfo, z: np.ndarray, h: float) -> float:
    p, q = sys.directions(info, -1.0)
    u0 = z[: sys.n]
    f0 = info.ev.end / sys.scale

    def f(du: np.ndarray) -> np.ndarray:
        return sys.period_map(info.problem, u0 + du)

    Bqq = _second(f, f0, q, h)
    r = np.linalg.solve(np.eye(sys.n) - info.M, Bqq)
    Bqr = 0.25 * (_second(f, f0, q + r, h) - _second(f, f0, q - r, h))
    return float(p @ (_third(f, q, h) / 6.0 + 0.5 * Bqr))


def _cos_theta(mu: np.ndarray) -> float:
    """Re(mu_i + mu_j) / 2 of the two multipliers whose product is nearest 1."""
    best, out = math.inf, math.nan
    for i in range(mu.size):
        for j in range(i + 1, mu.size):
            d = abs(mu[i] * mu[j] - 1.0)
            if d < best:
                best, out = d, 0.5 * float(np.real(mu[i] + mu[j]))
    return out


def special_tests(sys: CurveSystem, info: CurveInfo, z: np.ndarray
                ) -> dict[str, tuple[float, float]]:
    """The test functions of the curve's kind at a point: name -> (value, error estimate)."""
    M = info.M
    eye = np.eye(sys.n)
    out: dict[str, tuple[float, float]] = {}
    if sys.kind == "fold":
        a1 = _fold_coefficient(sys, info, z, NF_STEP)
        a2 = _fold_coefficient(sys, info, z, 2 * NF_STEP)
        out["cusp"] = (a1, abs(a2 - a1))
        out["fold_flip"] = (float(np.linalg.det(M + eye)), 0.0)
    elif sys.kind == "period_doubling":
        out["fold_flip"] = (float(np.linalg.det(M - eye)), 0.0)
        c1 = _pd_coefficient(sys, info, z, NF_STEP)
        c2 = _pd_coefficient(sys, info, z, 2 * NF_STEP)
        out["generalised_period_doubling"] = (c1, abs(c2 - c1))
    else:
        k = _cos_theta(info.mu)
        out["resonance_1_1"] = (k - 1.0, 0.0)
        out["resonance_1_2"] = (k + 1.0, 0.0)
    return out


def _changes(a: tuple[float, float], b: tuple[float, float]) -> bool:
    (fa, ea), (fb, eb) = a, b
    if not (math.isfinite(fa) and math.isfinite(fb)) or fa == 0.0 or fb == 0.0:
        return False
    return (np.sign(fa) != np.sign(fb) and abs(fa) > ERROR_RATIO * ea
            and abs(fb) > ERROR_RATIO * eb)


def detect_and_locate(sys: CurveSystem, points: list[CurvePoint],
                      tests: list[dict[str, tuple[float, float]]], settings: ArclengthSettings,
                      locate_tol: float) -> list[Special]:
    """Every codimension-2 point whose test function changes sign between successive points,
    located (:func:`locate`)."""
    found: list[Special] = []
    for i in range(len(points) - 1):
        for name in TESTS[sys.kind]:
            if _changes(tests[i][name], tests[i + 1][name]):
                found.append(locate(sys, points[i], points[i + 1], name, i,
                                    (tests[i][name][0], tests[i + 1][name][0]), settings,
                                    locate_tol))
    return found


def _error(z: np.ndarray, ends: tuple[np.ndarray, np.ndarray]) -> float:
    """The distance in the scaled unknowns from z to the farther of ``ends``."""
    return max(float(np.linalg.norm(z - e)) for e in ends)


def locate(sys: CurveSystem, a: CurvePoint, b: CurvePoint, name: str, index: int,
           values: tuple[float, float], settings: ArclengthSettings, locate_tol: float
           ) -> Special:
    """The zero of the test function ``name`` between the curve points a and b (module
    docstring); not located (the bracket's midpoint) where a trial's corrector fails."""
    fa, fb = values
    slope = abs(fb - fa) / max(_error(a.z, (b.z, b.z)), 1e-300)
    sa, sb = 0.0, 1.0
    za, zb = a.z, b.z
    chord = b.z - a.z
    t = chord / np.linalg.norm(chord)
    best: tuple[float, float, np.ndarray] | None = None
    side = 0
    why = ""
    sys.set_border(a.info)
    for _ in range(LOCATE_MAX_ITER):
        if float(np.linalg.norm(zb - za)) <= locate_tol:
            break
        sig = (sa * fb - sb * fa) / (fb - fa)
        sig = min(max(sig, sa + 0.02 * (sb - sa)), sb - 0.02 * (sb - sa))
        got = correct(sys.residual, a.z + sig * chord, t, settings, a.jac)
        if not isinstance(got, CurvePoint):
            why = got.message
            break
        f, f_err = special_tests(sys, got.info, got.z)[name]
        if best is None or abs(f) < abs(best[0]):
            best = (f, f_err, got.z)
        if f == 0.0:
            za = zb = got.z
            break
        if np.sign(f) == np.sign(fa):
            sa, fa, za = sig, f, got.z
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            sb, fb, zb = sig, f, got.z
            if side == 1:
                fa *= 0.5
            side = 1
    sys.set_border(b.info)
    if best is None:
        z = 0.5 * (za + zb)
        x, y = sys.xy(z)
        return Special(name, x, y, _error(z, (za, zb)), index, z,
                       f"not located ({why or 'no trial'}): the test function changed sign "
                       f"between points {index} and {index + 1}", located=False)
    z = best[2]
    x, y = sys.xy(z)
    return Special(name, x, y, _error(z, (za, zb)) + best[1] / slope, index, z,
                   f"{SPECIAL_KINDS[name]}; test function {best[0]:.3g} at the located point")
