"""Transient by convergence and the period classifier's resolution next to a period doubling.

The gear pair (zeta 0.05, kappa 0.2, Fm 0.1, Fa 0.2) has a period-1 orbit whose Floquet
multiplier crosses -1 at Omega = 0.90081 (a period doubling). The multipliers, orbits and the
flip are computed independently here: Newton on the period map of the reference integrator
(DOP853, rtol 1e-12, edges located) with a finite-difference monodromy matrix.
"""

from __future__ import annotations

import numpy as np
import pytest

import geardyn
from geardyn.analysis.periodicity import classify_period
from geardyn.core.settings import DEFAULT_TOL
from geardyn.solvers.reference import reference_solution

PAIR = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
TOL = 1e-8


def period_map(model, y: np.ndarray, n: int) -> np.ndarray:
    return reference_solution(model, y, [n * model.period])[0]


def monodromy(model, y: np.ndarray, n: int, e: float = 1e-6) -> np.ndarray:
    cols = []
    for j in range(y.size):
        d = np.zeros(y.size)
        d[j] = e
        cols.append((period_map(model, y + d, n) - period_map(model, y - d, n)) / (2 * e))
    return np.array(cols).T


def reference_orbit(model, y: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A point of the period-n orbit near y (Newton) and its Floquet multipliers."""
    for _ in range(10):
        step = np.linalg.solve(monodromy(model, y, n) - np.eye(y.size),
                               y - period_map(model, y, n))
        y = y + step
        if np.max(np.abs(step)) < 1e-12:
            break
    return y, np.linalg.eigvals(monodromy(model, y, n))


def runs(omega: float):
    """The sweep's samples at omega: transient by convergence (tolerance TOL) and a long fixed
    transient (40000 tau, over 5700 periods) as the reference."""
    model = geardyn.GearPair(**PAIR, Omega=omega)
    conv = geardyn.bifurcation(model, "Omega", [omega],
                               run=geardyn.RunSettings(transient=200.0, samples=8, converge=TOL,
                                                       transient_max=40000.0))
    fixed = geardyn.bifurcation(model, "Omega", [omega],
                                run=geardyn.RunSettings(transient=40000.0, samples=8))
    return model, conv, fixed


def distance(a: np.ndarray, b: np.ndarray, k: int) -> float:
    """Largest difference of two sample sequences of a period-k orbit, over the k phases."""
    return min(float(np.max(np.abs(a[s:] - b[: b.shape[0] - s]))) for s in range(k))


def test_converged_next_to_a_flip():
    """mu -> -1: the period-1 orbit at Omega = 0.899 attracts slowly (|mu| ~ 0.99), so the
    section points alternate around it and the old test (a point repeats to 1e-8) stopped
    6.5e-7 away. Now the estimated distance decides: within the tolerance of the long run."""
    model, conv, fixed = runs(0.899)
    _, mu = reference_orbit(model, fixed["poincare"].values[0, -1], 1)
    assert np.all(np.isreal(mu)) and -1.0 < np.min(mu.real) < -0.97
    assert int(conv["converged"][0]) == 1 and int(conv["period"][0]) == 1
    x, ref = conv["poincare"].values[0], fixed["poincare"].values[0]
    assert distance(x, ref, 1) < 2 * TOL * (1 + np.max(np.abs(ref)))


def test_converged_slow_period_two():
    """Just past the flip (Omega = 0.903) the period-2 orbit's multiplier (of two periods) is
    near +1: a slow monotone approach that stopped 2.7e-7 away under the old test."""
    model, conv, fixed = runs(0.903)
    ref = fixed["poincare"].values[0]
    _, mu1 = reference_orbit(model, ref[-1], 1)  # the period-1 orbit, now unstable
    assert np.min(mu1.real) < -1.0
    _, mu2 = reference_orbit(model, ref[-1], 2)
    assert 0.8 < np.max(np.abs(mu2)) < 1.0 and np.all(np.isreal(mu2))
    assert int(conv["converged"][0]) == 1 and int(conv["period"][0]) == 2
    assert distance(conv["poincare"].values[0], ref, 2) < 2 * TOL * (1 + np.max(np.abs(ref)))


def test_period_two_past_the_flip_is_resolved():
    """The documented resolution of classify_period: a period-2 orbit splitting by s reads
    period-2 exactly when s > tol max(1, |x|). Checked on the orbit just past the flip, whose
    splitting (reference orbit) grows as sqrt(Omega - Omega_flip)."""
    model = geardyn.GearPair(**PAIR, Omega=0.9)
    y1, mu_a = reference_orbit(model, np.array([0.625, 0.067]), 1)
    mu_a = np.min(mu_a.real)
    model_b = model.with_omega(0.901)
    _, mu_b = reference_orbit(model_b, y1, 1)
    mu_b = np.min(mu_b.real)
    flip = 0.9 + 0.001 * (-1.0 - mu_a) / (mu_b - mu_a)  # mu = -1, linearly interpolated
    assert 0.9 < flip < 0.901
    split = {}
    for omega in (0.903, 0.906):
        m = model.with_omega(omega)
        conv = geardyn.bifurcation(m, "Omega", [omega],
                                   run=geardyn.RunSettings(transient=200.0, samples=8, converge=TOL,
                                                           transient_max=40000.0))
        x = conv["poincare"].values[0]
        y2, _ = reference_orbit(m, x[-1], 2)
        s = float(np.max(np.abs(period_map(m, y2, 1) - y2)))
        split[omega] = s
        scale = max(1.0, float(np.max(np.abs(x))))
        # the sweep's orbit is the reference's to its RK4 error (2e-6 of |x| here)
        assert float(np.max(np.abs(x[1:] - x[:-1]))) == pytest.approx(s, abs=1e-5)
        assert classify_period(x) == 2 and DEFAULT_TOL * scale < s
        assert classify_period(x, tol=0.99 * s / scale) == 2
        assert classify_period(x, tol=1.01 * s / scale) == 1
    # the splitting follows the square-root law the documentation extrapolates with
    ratio = split[0.906] ** 2 / split[0.903] ** 2
    assert ratio == pytest.approx((0.906 - flip) / (0.903 - flip), rel=0.1)
