"""Pseudo-arclength continuation of periodic orbits (geardyn.continuation) against independent
results: the analytic frequency response of the linear oscillator, the principal instability
zone of the damped Mathieu equation (its monodromy by DOP853 here, boundaries by brentq), the
closed-form onset of tooth separation, the hysteresis band of up/down brute-force sweeps, the
reference integrator's period map, and the paper device's brute-force diagram."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import geardyn
import geardyn.io
from geardyn import BranchStatus, ContinuedSweep, continued_sweeps
from shared_models import oscillator


def _table(ds, kind: str) -> np.ndarray:
    return np.sort(ds["bifurcation_value"].values[ds["bifurcation_kind"].values == kind])


def _linear_amplitude(om, zeta: float, fa: float) -> np.ndarray:
    """|A| of x = b + Fm + Re(A e^{i Omega t}) for x'' + 2 zeta x' + x - b = Fm + Fa Omega^2
    cos(Omega t) (teeth in contact, constant stiffness)."""
    om = np.asarray(om)
    return fa * om**2 / np.abs(1.0 - om**2 + 2j * zeta * om)


def test_linear_branch_is_the_analytic_frequency_response(tmp_path):
    zeta, fa = 0.05, 0.02
    m = geardyn.GearPair(zeta=zeta, kappa=0.0, Fm=2.0, Fa=fa)
    seen = []
    ds = geardyn.continuation(m, "Omega", 0.5, 1.5, progress=lambda k, v: seen.append((k, v)))
    geardyn.testing.assert_result(ds, "continuation")
    assert seen[-1] == (ds.sizes["point"], 1.5)
    geardyn.io.save_dataset(ds, tmp_path / "branch.nc")
    assert geardyn.io.load_dataset(tmp_path / "branch.nc").identical(ds)
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    om = ds["Omega"].values
    assert om[0] == 0.5 and om[-1] == 1.5 and ds.sizes["point"] > 10
    A = _linear_amplitude(om, zeta, fa)
    # RMS of a sinusoid sampled evenly over its period is exact: |A| / sqrt 2 (the error left
    # is RK4's at the branch's step)
    assert np.max(np.abs(ds["deflection_rms"].values[:, 0] * math.sqrt(2) - A)) < 1e-6 * A.max()
    assert np.max(np.abs(ds["deflection_amplitude"].values[:, 0] - A)) < 1e-4 * A.max()
    # the multipliers: exp((-zeta +- i sqrt(1 - zeta^2)) T), |mu| = exp(-zeta T)
    T = 2 * math.pi / om
    assert np.allclose(ds["multiplier_abs"].values, np.exp(-zeta * T)[:, None], rtol=1e-7)
    assert ds.sizes["bifurcation"] == 0
    assert set(ds["stability"].values) == {"stable"}
    assert set(ds["contact"].values.ravel()) == {"none"}


def _mathieu_pd_test(om: float, zeta: float, kappa: float) -> float:
    """det(M + I) of x'' + 2 zeta x' + (1 + kappa cos(Omega t)) x = 0 over one period (DOP853):
    zero where a multiplier is -1 (a boundary of the principal instability zone)."""
    def f(t, z):
        J = np.array([[0.0, 1.0], [-(1.0 + kappa * math.cos(om * t)), -2.0 * zeta]])
        return (J @ z.reshape(2, 2)).ravel()

    M = solve_ivp(f, (0.0, 2 * math.pi / om), np.eye(2).ravel(), method="DOP853", rtol=1e-12,
                  atol=1e-14).y[:, -1].reshape(2, 2)
    return float(np.linalg.det(M + np.eye(2)))


def test_mathieu_hill_period_doublings_are_the_instability_zone_boundaries():
    """Teeth always in contact (large mean load, no transmission error): the variational
    equation is the damped Mathieu equation, whose principal zone (Omega near 2) is bounded by
    multipliers -1; the period-1 branch's period doublings lie on its boundaries."""
    zeta, kappa = 0.05, 0.4
    m = geardyn.GearPair(zeta=zeta, kappa=kappa, Fm=1.0, Fa=0.0)
    ds = geardyn.continuation(m, "Omega", 1.5, 2.6)
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    assert np.all(ds["mesh_crossings"].values == 0)
    grid = np.linspace(1.5, 2.6, 12)
    f = [_mathieu_pd_test(o, zeta, kappa) for o in grid]
    zone = [brentq(_mathieu_pd_test, grid[i], grid[i + 1], args=(zeta, kappa), xtol=1e-12)
            for i in range(grid.size - 1) if np.sign(f[i]) != np.sign(f[i + 1])]
    assert len(zone) == 2
    pd = _table(ds, "period-doubling")
    assert pd.size == 2
    assert np.max(np.abs(pd - zone)) < 1e-4
    assert np.max(ds["bifurcation_error"].values) < 1e-6
    # unstable inside the zone, stable outside
    om = ds["Omega"].values
    inside = (om > zone[0] + 1e-3) & (om < zone[1] - 1e-3)
    outside = (om < zone[0] - 1e-3) | (om > zone[1] + 1e-3)
    assert set(ds["stability"].values[inside]) == {"unstable"}
    assert set(ds["stability"].values[outside]) == {"stable"}


def test_softening_folds_bracket_the_sweeps_hysteresis_and_contact_onset():
    """Contact loss at Fa = 0.05, zeta = 0.05: the resonance bends to lower frequencies; the
    branch's folds bound the band where up and down sweeps disagree (within the sweep's step),
    and its contact changes are the closed-form onsets of separation, where the linear
    response's amplitude equals the mean load."""
    zeta, fa, fm = 0.05, 0.05, 0.1
    m = geardyn.GearPair(zeta=zeta, Fm=fm, Fa=fa)
    ds = geardyn.continuation(m, "Omega", 0.5, 1.6)
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    folds = _table(ds, "fold")
    assert folds.size == 2
    onset = _table(ds, "contact")

    def g(om):
        return _linear_amplitude(om, zeta, fa) - fm

    exact = [brentq(g, 0.5, 1.0, xtol=1e-14), brentq(g, 1.1, 2.0, xtol=1e-14)]
    assert onset.size == 2
    assert np.max(np.abs(onset - exact)) < 1e-6
    # the unstable middle branch lies between the folds
    st = ds["stability"].values
    om = ds["Omega"].values
    bad = om[st == "unstable"]
    assert bad.size and bad.min() >= folds[0] - 1e-9 and bad.max() <= folds[1] + 1e-9
    # brute force: up and down sweeps by continuation
    h = 0.01
    vals = np.round(np.arange(0.6, 0.9 + h / 2, h), 6)
    up, down = continued_sweeps(
        [ContinuedSweep(m, "Omega", vals, d,
                        run=geardyn.RunSettings(transient=300.0, transient_max=3000.0,
                                                continued_transient=50.0)) for d in ("up", "down")],
        run=geardyn.RunSettings(samples=4, converge=1e-8))
    a, b = up["force_peak"].values[:, 0], down["force_peak"].values[:, 0]
    differ = vals[np.abs(a - b) > 1e-3 * np.abs(a).max()]
    assert differ.size > 3
    assert differ.min() - h <= folds[0] <= differ.min()
    assert differ.max() <= folds[1] <= differ.max() + h


def test_branch_switching_follows_the_period_two_orbit():
    """At the period doubling of the gear pair with stiffness variation, the period-2 branch:
    its points are fixed points of the reference integrator's twice-iterated map, not of the
    once-iterated one, and it starts at the located doubling."""
    m = geardyn.GearPair(zeta=0.02, Fm=0.1, Fa=0.1, kappa=0.2)
    ds = geardyn.continuation(m, "Omega", 1.9, 1.5, switch=True,
                              settings=geardyn.ContinuationSettings(max_period=2))
    pd = np.flatnonzero((ds["bifurcation_kind"].values == "period-doubling")
                        & (ds["bifurcation_branch"].values == 0))
    assert pd.size >= 1
    assert ds.sizes["branch_id"] == 1 + pd.size  # period-2 branches not switched again
    two = ds.where(ds["branch"] == 1, drop=True)
    assert np.all(two["period"].values == 2) and two.sizes["point"] > 3
    assert ds["branch_parent"].values[1] == pd[0]
    first = float(two["Omega"].values[0])
    assert abs(first - ds["bifurcation_value"].values[pd[0]]) < 0.02
    k = two.sizes["point"] // 2
    om = float(two["Omega"].values[k])
    x = two["section_point"].values[k]
    T = 2 * math.pi / om
    mm = m.with_omega(om)
    ref = geardyn.reference_solution(mm, x, np.array([T, 2 * T]))
    assert np.max(np.abs(ref[1] - x)) < 1e-7
    assert np.max(np.abs(ref[0] - x)) > 1e-3
    # a function decides which doublings to switch at
    asked = []
    none = geardyn.continuation(m, "Omega", 1.9, 1.5, switch=lambda b: asked.append(b) or False)
    assert none.sizes["branch_id"] == 1 and len(asked) == pd.size
    assert np.all(ds["branch_period"].values[1:] == 2)
    assert asked[0].kind == "period-doubling" and asked[0].value == pytest.approx(
        ds["bifurcation_value"].values[pd[0]], abs=1e-6)


def test_failures_end_the_branch_with_a_message_keeping_the_points():
    m = geardyn.GearPair(zeta=0.05, kappa=0.5, Fm=1.0, Fa=0.0, Omega=1.2)
    ds = geardyn.continuation(m, "kappa", 0.5, 1.5)  # |kappa| < 1 is the valid region
    assert ds.attrs["status"] == BranchStatus.INVALID
    assert "kappa=" in ds.attrs["message"] and ds.sizes["point"] > 2
    assert ds["kappa"].values.max() < 1.0
    with pytest.raises(ValueError, match="valid region"):
        geardyn.continuation(m, "kappa", 1.2, 1.5)
    with pytest.raises(KeyError, match="known"):
        geardyn.continuation(m, "kapa", 0.2, 0.5)
    # a bound that the resonant orbit exceeds: the integration diverges
    lin = geardyn.GearPair(zeta=0.05, Fm=2.0, Fa=0.02)
    ds = geardyn.continuation(lin, "Omega", 0.5, 1.5, run=geardyn.RunSettings(bound=3.1))
    assert ds.attrs["status"] == BranchStatus.DIVERGED
    assert "Omega=" in ds.attrs["message"] and ds.sizes["point"] > 2
    assert ds["Omega"].values.max() < 1.0
    # no orbit at the start: a Newton that cannot converge (one iteration)
    bad = geardyn.continuation(geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05), "Omega", 0.9,
                               1.0, guess=np.array([3.0, 2.0]),
                               settings=geardyn.ContinuationSettings(tol=1e-300))
    assert bad.attrs["status"] == BranchStatus.START_FAILED and bad.sizes["point"] == 0
    assert "Omega=0.9" in bad.attrs["message"]
    # a second excitation at a fixed Lambda: next to Omega = 3 the forcings have no common
    # period, so no branch of periodic orbits leaves it
    from geardyn.io import builtin_study

    fig14 = geardyn.build_model(builtin_study("paper_fig14")).with_omega(3.0)
    qp = geardyn.continuation(fig14, "Omega", 3.0, 3.5)
    assert qp.attrs["status"] == BranchStatus.START_FAILED
    assert "no common period" in qp.attrs["message"]


def test_paper_device_period_doubling_agrees_with_the_brute_force_diagram():
    """Fig. 3's device: the period-1 branch turns period 2 at a located period doubling that
    lies in the step of the brute-force diagram where its period goes from 1 to 2; the switched
    period-2 branch ends at Omega = 1.05 on the attractor the sweep shows there; the branch's
    multipliers agree with differences of the reference integrator's period map."""
    base = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05),
                              interpretation="consistent")
    end = 1.05
    ds = geardyn.continuation(base, "Omega", 0.9, end, switch=True,
                              settings=geardyn.ContinuationSettings(max_period=2))
    pd = _table(ds.where(ds["bifurcation_branch"] == 0, drop=True), "period-doubling")
    assert pd.size == 1
    h = 0.01
    vals = np.round(np.arange(0.95, 1.1 + h / 2, h), 6)
    bf = geardyn.bifurcation(base, "Omega", vals, continuation="up",
                             run=geardyn.RunSettings(transient=1500.0, samples=8, converge=1e-9,
                                                     transient_max=6000.0,
                                                     continued_transient=200.0))
    per = bf["period"].values
    first2 = vals[np.argmax(per == 2)]
    assert per[0] == 1 and np.any(per == 2)
    assert first2 - h - 1e-9 <= pd[0] <= first2 + 1e-9
    # the period-2 branch's last point, at Omega = end, is on the sweep's period-2 attractor
    two = ds.where(ds["branch"] == 1, drop=True)
    assert np.all(two["period"].values == 2)
    assert two["Omega"].values[-1] == end and two["stability"].values[-1] == "stable"
    k = int(np.argmin(np.abs(vals - end)))
    assert per[k] == 2
    seen = bf["poincare"].values[k]  # (sample, state)
    x = two["section_point"].values[-1]
    assert np.min(np.max(np.abs(seen - x), axis=1)) < 1e-5
    # multipliers at the branch point nearest Omega = 1 vs the reference integrator
    one = ds.where(ds["branch"] == 0, drop=True)
    j = int(np.argmin(np.abs(one["Omega"].values - 1.0)))
    om, x = float(one["Omega"].values[j]), one["section_point"].values[j]
    # d = 1e-4: central differences of the reference's period map are noisy below it (its
    # located edge crossings; measured 6e-4 off at d = 1e-5 and 5e-5 at 1e-6 on an AMD EPYC,
    # 1e-7 at 1e-4, where the O(d^2) truncation of the smooth map is far below the bound)
    m, T, d = base.with_omega(om), 2 * math.pi / om, 1e-4
    M = np.empty((x.size, x.size))
    for q in range(x.size):
        e = np.zeros(x.size)
        e[q] = d
        M[:, q] = (geardyn.reference_solution(m, x + e, np.array([T]))[0]
                   - geardyn.reference_solution(m, x - e, np.array([T]))[0]) / (2 * d)
    mu = one["multiplier_real"].values[j] + 1j * one["multiplier_imag"].values[j]
    ref = np.linalg.eigvals(M)
    assert np.max(np.abs(np.sort_complex(mu) - np.sort_complex(ref))) < 1e-4


def test_neimark_sacker_of_the_forced_van_der_pol_oscillator_keeps_liouville():
    """x'' - eps (1 - x^2) x' + x = gamma cos(Omega t), far from 1:1 resonance: as the forcing
    weakens the entrained orbit loses stability through a complex pair. Liouville gives
    |mu|^2 = det M = exp(eps * integral of (1 - x^2)) for a complex pair, so at the
    Neimark-Sacker point the orbit's mean of x^2 is 1: checked on the reference integrator's
    orbit from the located section point."""
    om, eps = 1.2, 0.1
    m = oscillator(Omega=om, mu=eps, F=1.5, natural_frequency=1.0)  # gamma: F
    ds = geardyn.continuation(m, "F", 1.5, 0.2)
    ns = np.flatnonzero(ds["bifurcation_kind"].values == "neimark-sacker")
    assert ns.size == 1, ds["bifurcation_kind"].values
    k = int(ns[0])
    gamma = float(ds["bifurcation_value"].values[k])
    assert ds["bifurcation_error"].values[k] < 1e-6
    assert abs(ds["bifurcation_multiplier_imag"].values[k]) > 0.1
    x0 = ds["bifurcation_section_point"].values[k]
    T = 2 * math.pi / om

    def f(t, z):
        x, v = z[0], z[1]
        return [v, eps * (1 - x * x) * v - x + gamma * math.cos(om * t), x * x]

    sol = solve_ivp(f, (0.0, T), [x0[0], x0[1], 0.0], method="DOP853", rtol=1e-12,
                    atol=1e-14)
    assert np.max(np.abs(sol.y[:2, -1] - x0)) < 1e-7  # a periodic orbit of the exact flow
    assert abs(sol.y[2, -1] / T - 1.0) < 1e-6
    # stable before (strong forcing), unstable after
    g = ds["F"].values
    assert set(ds["stability"].values[g > gamma + 1e-3]) == {"stable"}
    assert set(ds["stability"].values[g < gamma - 1e-3]) == {"unstable"}


def test_physical_parameter_of_the_device_period_doubling_on_the_reference_map():
    """Continued in the device's damping ratio xi (a physical parameter: every coefficient is
    re-derived) at Omega = 1.2, the period-1 orbit regains stability through -1; at the located
    xi the reference integrator's period map (DOP853, central differences) has a multiplier -1."""
    base = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05),
                              interpretation="consistent")
    guess = geardyn.periodic_orbit(base, omega=1.0).x
    m = base.with_omega(1.2)
    ds = geardyn.continuation(m, "xi", 0.05, 0.3, guess=guess)
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    pd = np.flatnonzero(ds["bifurcation_kind"].values == "period-doubling")
    assert pd.size == 1
    xi = float(ds["bifurcation_value"].values[pd[0]])
    x = ds["bifurcation_section_point"].values[pd[0]]
    at = m.with_params(xi=xi)
    T, d = 2 * math.pi / 1.2, 1e-5
    assert np.max(np.abs(geardyn.reference_solution(at, x, np.array([T]))[0] - x)) < 1e-6
    M = np.empty((x.size, x.size))
    for q in range(x.size):
        e = np.zeros(x.size)
        e[q] = d
        M[:, q] = (geardyn.reference_solution(at, x + e, np.array([T]))[0]
                   - geardyn.reference_solution(at, x - e, np.array([T]))[0]) / (2 * d)
    assert np.min(np.abs(np.linalg.eigvals(M) + 1.0)) < 1e-4
    assert ds["stability"].values[0] == "unstable" and ds["stability"].values[-1] == "stable"
