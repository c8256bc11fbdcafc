"""The single-mesh gear pair: onset of tooth separation against linear theory, and RK4 against
the adaptive reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import geardyn

ZETA, FM, FA, B = 0.05, 0.1, 0.05, 1.0


def linear_response(omega: float) -> complex:
    """Complex amplitude H of the steady response u = x - b = Fm + Re(H e^{i Omega tau}) of
    u'' + 2 zeta u' + u = Fm + Fa Omega^2 cos(Omega tau) (teeth in contact, kappa = 0)."""
    return FA * omega**2 / (1.0 - omega**2 + 2j * ZETA * omega)


def onset() -> float:
    """Lowest Omega where the linear amplitude |H| reaches the mean deflection Fm, solved here
    from |H| = Fm, cross-checked against GearPair.separation_onset."""
    g = geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=FA)
    w = brentq(lambda om: abs(linear_response(om)) - FM, 0.3, 1.0, xtol=1e-14)
    w_lib = brentq(lambda om: float(g.separation_onset(np.array([om]))[0]), 0.3, 1.0,
                   xtol=1e-14)
    assert w_lib == pytest.approx(w, rel=1e-10)
    return w


def _closed_form_onset() -> float:
    """The onset from the linear in-contact solution, in closed form: Fa Omega^2 =
    Fm |1 - Omega^2 + 2 i zeta Omega| is a quadratic in W = Omega^2,
    (Fa^2 - Fm^2) W^2 - Fm^2 (4 zeta^2 - 2) W - Fm^2 = 0."""
    a, b, c = FA**2 - FM**2, -(FM**2) * (4 * ZETA**2 - 2), -(FM**2)
    roots = np.roots([a, b, c])
    return math.sqrt(min(r.real for r in roots if r.real > 0))


def _loses_contact(omega: float, steps_per_period: int | None) -> tuple[bool, int]:
    """Whether the gear pair, started on the linear in-contact steady state at Omega, leaves the
    contact edge x = b within 4 periods (an edge crossing, or a grid point past the edge), by
    simulate(); and the steps per period it used."""
    g = geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=FA, backlash=B, Omega=omega)
    H = linear_response(omega)
    y0 = np.array([B + FM + H.real, -omega * H.imag])
    ds = geardyn.simulate(g,
                          run=geardyn.RunSettings(transient=0.0, samples=4,
                                                  steps_per_period=steps_per_period), y0=y0)
    lost = int(ds["edge_crossings"].sel(event="x-b")) > 0 or float(ds["x"].min()) < B
    return lost, int(ds.attrs["steps_per_period"])


def _dip_error(omega: float, n: int) -> float:
    """The RK4 error of the state over 4 periods at ``n`` steps per period (from the linear
    in-contact steady state at Omega), against a run at 32 n (2^-20 of the error): the largest
    over the grid points, the size of the error in the orbit's lowest point."""
    g = geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=FA, backlash=B, Omega=omega)
    H = linear_response(omega)
    y0 = np.array([B + FM + H.real, -omega * H.imag])
    coarse = geardyn.simulate(g,
                              run=geardyn.RunSettings(transient=0.0, samples=4, steps_per_period=n),
                              y0=y0)
    fine = geardyn.simulate(g,
                            run=geardyn.RunSettings(transient=0.0, samples=4,
                                                    steps_per_period=32 * n), y0=y0)
    fine = fine.sel(time=coarse["time"].values, method="nearest")
    np.testing.assert_allclose(fine["time"].values, coarse["time"].values, rtol=0, atol=1e-9)
    return max(float(np.max(np.abs(coarse[s].values - fine[s].values))) for s in ("x", "v"))


@pytest.mark.parametrize("steps_per_period", [None, 1024])
def test_separation_onset_found_by_simulation_matches_the_closed_form(steps_per_period):
    """Bisect Omega on whether simulate() loses contact, and compare the bracket with the closed
    form. A dip past the edge shorter than one step can hide between two grid points (a graze):
    the orbit u = Fm - |H| + |H| (1 - cos) dips below the edge by at most
    |H| pi^2 / (2 n^2) then, so the simulated onset may lie later than the closed form by that
    depth over d|H|/dOmega; a graze inside a step is located, so it may also lie earlier by the
    4th-order RK4 error of the dip's depth over d|H|/dOmega (measured against a finer run)."""
    w_closed = _closed_form_onset()
    assert w_closed == pytest.approx(onset(), rel=1e-10)  # the quadratic is |H| = Fm
    lo, hi = 0.9 * w_closed, 1.1 * w_closed
    assert not _loses_contact(lo, steps_per_period)[0]
    lost, n = _loses_contact(hi, steps_per_period)
    assert lost
    resolution = 1e-7
    while hi - lo > resolution:
        mid = 0.5 * (lo + hi)
        if _loses_contact(mid, steps_per_period)[0]:
            hi = mid
        else:
            lo = mid
    dh = 1e-6
    slope = (abs(linear_response(w_closed + dh)) - abs(linear_response(w_closed - dh))) / (2 * dh)
    graze = FM * math.pi**2 / (2 * n**2) / slope  # |H| = Fm at the onset
    # grazes inside a step are located, so the onset may also be early by the RK4 error of the
    # dip's depth: the state error of the run at the bracket's end against a 32x finer run
    rk4 = _dip_error(hi, n) / slope
    assert hi >= w_closed - rk4 - 1e-9, (lo, hi, w_closed, rk4)
    assert lo <= w_closed + graze + 1e-9, (lo, hi, w_closed, graze)


@pytest.mark.parametrize("side", [-1, 1])
def test_separation_onset_matches_linear_theory(side):
    w_star = onset()
    om = w_star * (1.0 + 0.02 * side)
    g = geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=FA, backlash=B, Omega=om)
    H = linear_response(om)
    # start on the linear steady state (phase 0 at tau = 0), so that below the onset the
    # transient cannot knock the pair onto a coexisting impacting branch
    y0 = np.array([B + FM + H.real, -om * H.imag])
    ds = geardyn.simulate(g, run=geardyn.RunSettings(transient=600.0, samples=8), y0=y0)
    x = ds["x"].values
    gap = x.min() - B
    crossed = int(ds["edge_crossings"].sel(event="x-b"))
    if side < 0:
        # stays in contact, on the linear solution: min x - b = Fm - |H| (grid-sampled min)
        n = ds.attrs["steps_per_period"]
        assert gap >= 0.0 and crossed == 0
        assert gap == pytest.approx(FM - abs(H), abs=abs(H) * (1 - math.cos(math.pi / n)) + 1e-7)
        assert 0.5 * np.ptp(x) == pytest.approx(abs(H), rel=2e-3)
    else:
        assert gap < 0.0 and crossed > 0


@pytest.mark.parametrize(("kappa", "omega"), [(0.0, 1.0), (0.2, 0.9), (0.2, 2.0)])
def test_gear_pair_rk4_matches_reference(kappa, omega):
    g = geardyn.GearPair(zeta=ZETA, kappa=kappa, Fm=FM, Fa=FA, Omega=omega)
    y0 = geardyn.simulate(g,
                          run=geardyn.RunSettings(transient=1000.0, samples=1,
                                                  steps_per_period=1024))[
        "poincare"].values[-1]
    T = 2 * math.pi / omega
    ref = [y0]
    for k in range(10):  # segment by segment: every sample is a step end of DOP853
        ref.append(geardyn.reference_solution(g, ref[-1], [(k + 1) * T], t0=k * T, rtol=1e-13,
                                              atol=1e-14)[0])
    ref = np.array(ref)
    ds = geardyn.simulate(g, run=geardyn.RunSettings(transient=0.0, samples=10), y0=y0)
    assert np.max(np.abs(ds["poincare"].values - ref)) < 1e-6
    errs = [np.max(np.abs(geardyn.simulate(g,
                                           run=geardyn.RunSettings(transient=0.0, samples=10,
                                                                   steps_per_period=n), y0=y0)[
        "poincare"].values - ref)) for n in (32, 64, 128, 256)]
    p = -np.polyfit(np.log([32, 64, 128, 256]), np.log(errs), 1)[0]
    assert p > 3.7


def test_phased_and_unphased_lanes_equal_single_simulations_bitwise():
    # the sweep kernel runs the gear pair in its fused step loop (lane-scalar layout generated
    # from the one form), phased and unphased lanes in one queue (the phases' cos and sin are
    # derived coefficients); each lane must equal simulate (the one-lane path, array layout)
    from geardyn.solvers.ensemble import run_lanes
    from geardyn.solvers.kernels import kernels_for

    m = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    assert kernels_for(m.kernel).FUSED
    omegas = np.array([0.5, 0.8, 1.1, 1.6, 2.1, 2.7, 0.9, 1.3])
    phases = [(0.0, 0.0), (0.3, 0.0), (0.0, -0.7)]
    P = np.array([m.with_params(Omega=float(om), kappa_phase=phases[j % 3][0],
                                error_phase=phases[j % 3][1]).params
                  for j, om in enumerate(omegas)])
    r = run_lanes(m, P, m.initial_state(),
                  run=geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64))
    assert np.all(r.status == 0)
    assert np.sum(r.crossings) > 40  # contact lost and regained: the split ran
    for j in range(omegas.size):
        kp, ep = phases[j % 3]
        mj = m.with_params(kappa_phase=kp, error_phase=ep)
        ds = geardyn.simulate(mj, omega=omegas[j],
                              run=geardyn.RunSettings(transient=300.0, samples=6,
                                                      steps_per_period=64))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])


def test_a_sweep_axis_carries_the_declared_unit_and_meaning():
    """The swept coefficient's axis is labelled from its declaration: a phase in radians, the
    dimensionless mesh frequency in 1 (the base model read nothing and left both unlabelled)."""
    pair = geardyn.GearPair(Fa=0.2)
    ds = geardyn.bifurcation(pair, "kappa_phase", np.array([0.0, 0.5]),
                             run=geardyn.RunSettings(transient=2, samples=2))
    assert ds["kappa_phase"].attrs["units"] == "rad"
    assert "phase" in ds["kappa_phase"].attrs["long_name"]
    assert pair.param_attrs("Omega")["units"] == "1"
    assert pair.param_attrs("no_such_name") == {}
