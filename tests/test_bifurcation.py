"""Sweep engine, period classification and contact-loss regimes."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn.analysis.bifurcation import bifurcation
from geardyn.analysis.periodicity import classify_period
from geardyn.solvers.ensemble import run_lanes
from geardyn.testing import assert_result


@nb.njit(cache=True)
def forced_oscillator(t, y, dy, p):
    """x'' + 2 c x' + x = cos(Omega t), Omega = p[1]; unstable for c < 0."""
    dy[0] = y[1]
    dy[1] = -2.0 * p[0] * y[1] - y[0] + math.cos(p[1] * t)


# ------------------------------------------------------------------ period classification
def test_classify_period_on_synthetic_orbits():
    rng = np.random.default_rng(1)
    n = 64
    orbit3 = rng.normal(size=(3, 4))
    period3 = np.tile(orbit3, (n // 3 + 1, 1))[:n]
    period1 = np.tile(rng.normal(size=(1, 4)), (n, 1))
    angle = 2 * math.pi * (math.sqrt(5) - 1) / 2 * np.arange(n)  # irrational rotation: a torus
    torus = np.stack([np.cos(angle), np.sin(angle), 0 * angle, 0 * angle], axis=1)
    diverged = period1.copy()
    diverged[5, 0] = np.nan
    period5_small = np.tile(rng.normal(size=(5, 4)) * 1e-3 + 10.0, (n // 5 + 1, 1))[:n]
    got = classify_period(np.stack([period1, period3, torus, diverged, period5_small]))
    np.testing.assert_array_equal(got, [1, 3, 0, -1, 5])
    # a period-2 orbit whose two points differ by less than the tolerance reads as period 1
    near = np.tile(np.array([[1.0, 0.0], [1.0 + 1e-8, 0.0]]), (16, 1))
    assert classify_period(near) == 1
    assert classify_period(near, tol=1e-10) == 2


# ------------------------------------------------------------------ engine
def test_lanes_reproduce_single_simulations_bitwise():
    """A lane's arithmetic must not depend on its block or neighbours: run_lanes equals simulate."""
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper())
    omegas = np.array([0.7, 1.1, 1.3, 2.2, 3.1, 0.9, 1.7, 2.9, 3.9, 0.45, 1.05])
    run = geardyn.RunSettings(transient=300.0, samples=4, steps_per_period=64)
    r = run_lanes(m, m.lane_params("Omega", omegas), m.initial_state(), run=run)
    for j in (0, 1, 8, 10):
        ds = geardyn.simulate(m, omega=omegas[j],
                              run=geardyn.RunSettings(transient=300.0, samples=4,
                                                      steps_per_period=64))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])
    # and it does not depend on the order of the lanes
    perm = np.random.default_rng(0).permutation(omegas.size)
    r2 = run_lanes(m, m.lane_params("Omega", omegas[perm]), m.initial_state(), run=run)
    np.testing.assert_array_equal(r2.samples, r.samples[perm])


def test_diverging_lane_is_marked_and_sweep_goes_on():
    u = geardyn.UserModel(forced_oscillator, n_states=2, params=[0.05, 1.3],
                          param_names=["c", "Omega"])
    ds = bifurcation(u, param="c", values=[-0.2, 0.05, 0.1],
                     run=geardyn.RunSettings(transient=500.0, samples=8, steps_per_period=256,
                                             bound=1e3))
    assert_result(ds, "bifurcation")
    np.testing.assert_array_equal(ds["status"].values, [1, 0, 0])
    np.testing.assert_array_equal(ds["period"].values, [-1, 1, 1])
    assert np.all(np.isnan(ds["poincare"].values[0]))
    # the stable lanes' Poincare point is the linear steady state x = Re[e^{i W t}/(1-W^2+2icW)]
    for j, c in ((1, 0.05), (2, 0.1)):
        amp = 1.0 / (1.0 - 1.3**2 + 2j * c * 1.3)
        np.testing.assert_allclose(ds["poincare"].values[j, -1, 0], amp.real, atol=1e-7)


def test_gear_pair_contact_regime_matches_reference_trajectory():
    """The regime from the sweep statistics agrees with the extremes of an accurate trajectory."""
    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
    omegas = np.array([0.5, 1.2, 3.0])
    ds = bifurcation(g, values=omegas, run=geardyn.RunSettings(transient=600.0, samples=10))
    for j, om in enumerate(omegas):
        gw = g.with_omega(om)
        y_start = ds["poincare"].values[j, 0]
        t0 = 0.0
        t = np.linspace(t0, t0 + 9 * 2 * math.pi / om, 2000)
        ref = geardyn.reference_solution(gw, y_start, t, t0=t0)
        x = ref[:, 0]
        expect = "none" if x.min() > 1.0 else ("double" if x.min() < -1.0 else "single")
        assert ds["contact"].values[j, 0] == expect, (om, x.min())
    # linear prediction: separation iff Fa W^2/|1-W^2+2i zeta W| > Fm
    onset = g.separation_onset(omegas)
    np.testing.assert_array_equal(ds["contact"].values[:, 0] != "none", onset > 0)


def test_continuation_shows_coexisting_solutions_of_the_softening_oscillator():
    """A gear pair near its primary resonance has coexisting no-impact and impact motions:
    sweeping up and down must each follow one branch somewhere in the hysteresis band."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.0, Fm=0.2, Fa=0.06)
    om = np.linspace(0.6, 1.2, 25)
    up = bifurcation(g, values=om,
                     run=geardyn.RunSettings(transient=400.0, samples=8), continuation="up")
    down = bifurcation(g, values=om,
                       run=geardyn.RunSettings(transient=400.0, samples=8), continuation="down")
    amp_up = np.ptp(up["poincare"].values[..., 0], axis=1) + np.abs(up["poincare"].values[:, 0, 0])
    amp_dn = np.ptp(down["poincare"].values[..., 0], axis=1) + np.abs(
        down["poincare"].values[:, 0, 0])
    assert np.all(up["status"].values == 0) and np.all(down["status"].values == 0)
    assert np.max(np.abs(amp_up - amp_dn)) > 0.1, "expected a hysteresis band"


@pytest.mark.parametrize("param,values", [("xi", [0.05, 0.2]), ("backlash", ["30 um", 5e-5])])
def test_physical_parameter_sweeps(param, values):
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=1.1)
    vals = [geardyn.units.to_si(v, "length") if isinstance(v, str) else v for v in values]
    ds = bifurcation(m, param=param, values=vals,
                     run=geardyn.RunSettings(transient=300.0, samples=4, steps_per_period=64))
    for j, v in enumerate(vals):
        one = geardyn.simulate(m.with_params(**{param: v}),
                               run=geardyn.RunSettings(transient=300.0, samples=4,
                                                       steps_per_period=64))
        np.testing.assert_array_equal(ds["poincare"].values[j], one["poincare"].values[1:])


def test_bifurcation_lyapunov_separates_periodic_from_chaotic():
    """Omega = 0.92 is chaotic for this gear pair (tests/test_lyapunov.py shows nearby
    trajectories separating); Omega = 0.5 is period-1."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
    ds = bifurcation(g, values=[0.5, 0.92],
                     run=geardyn.RunSettings(transient=500.0, samples=50), lyapunov=True)
    np.testing.assert_array_equal(ds["period"].values, [1, 0])
    lam = ds["lyapunov"].values
    assert lam[0] < -0.005 and lam[1] > 0.02
    # the motion class decides against each exponent's uncertainty (analysis.motion)
    assert list(ds["motion"].values) == ["period-1", "chaotic"]
    assert np.all(ds["lyapunov_err"].values > 0) and lam[1] > 3 * ds["lyapunov_err"].values[1]


def test_classify_period_of_many_lanes_equals_the_rule_lane_by_lane():
    """classify_period works on batches of lanes at once; against the module's rule written out
    for one lane at a time (smallest k with max |x[i + k] - x[i]| <= tol max(1, max |x|)), on
    lanes of periods 1-6, aperiodic, diverged and near-tolerance ones, across batch edges."""
    from geardyn.analysis import periodicity

    rng = np.random.default_rng(7)
    n_lanes, n, ns, tol = 300, 24, 3, 1e-5
    x = np.empty((n_lanes, n, ns))
    for lane in range(n_lanes):
        k = int(rng.integers(1, 8))  # 7: no period <= 6 in 24 samples
        base = rng.normal(size=(k, ns)) * 10.0 ** rng.integers(-2, 3)
        x[lane] = np.tile(base, (n // k + 1, 1))[:n]
        x[lane] += rng.normal(size=(n, ns)) * tol * 10.0 ** rng.uniform(-1.5, 0.5)
    x[5, 3, 1] = np.nan
    x[17, -1, 0] = np.inf

    def one(xl):
        if not np.all(np.isfinite(xl)):
            return -1
        scale = tol * max(1.0, float(np.max(np.abs(xl))))
        for k in range(1, 7):
            if np.max(np.abs(xl[k:] - xl[:-k])) <= scale:
                return k
        return 0

    expect = np.array([one(xl) for xl in x])
    assert {-1, 0, 1, 2, 3, 6} <= set(expect.tolist())
    old = periodicity._BATCH
    try:
        for batch in (7, 4096):
            periodicity._BATCH = batch
            np.testing.assert_array_equal(classify_period(x, max_period=6, tol=tol), expect)
    finally:
        periodicity._BATCH = old
