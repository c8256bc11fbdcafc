"""Accuracy of the fixed-step RK4 integrator against the adaptive DOP853 reference.

Order of convergence with and without located dead-zone edge crossings, and the accuracy of the
default step choice on periodic attractors with contact loss (see docs/numerics.md).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn.solvers._step_shared import phase_table, phase_table_values

K_PERIODS = 10


def order(ns, errors) -> float:
    """Least-squares order p of errors ~ n^-p."""
    return -float(np.polyfit(np.log(ns), np.log(errors), 1)[0])


def dense(lo, hi):
    """Step counts between lo and hi, four per octave (the error without edge location depends
    on where the crossings fall in a step, so a fit needs many step sizes)."""
    k = np.arange(round(4 * math.log2(lo)), round(4 * math.log2(hi)) + 1)
    return np.unique(np.round(2.0 ** (k / 4)).astype(int))


def trajectory_errors(model, y0, ns, locate):
    """Max Poincare-point error over K_PERIODS periods from y0, for each steps per period."""
    T = 2 * math.pi / model.omega
    times = np.arange(K_PERIODS + 1) * T
    ref = geardyn.reference_solution(model, y0, times, rtol=1e-13, atol=1e-14)
    errs = []
    for n in ns:
        ds = geardyn.simulate(model,
                              run=geardyn.RunSettings(transient=0.0, samples=K_PERIODS,
                                                      steps_per_period=int(n), locate_edges=locate),
                              y0=y0)
        errs.append(np.max(np.abs(ds["poincare"].values - ref)))
    return np.array(errs)


def on_attractor(model, n=1024):
    ds = geardyn.simulate(model,
                          run=geardyn.RunSettings(transient=3000.0, samples=1, steps_per_period=n))
    return ds["poincare"].values[-1], ds


def test_rk4_is_fourth_order_while_teeth_stay_in_contact():
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(error="0.1 um")).with_omega(1.1)
    y0, _ = on_attractor(m, 512)
    ds = geardyn.simulate(m, run=geardyn.RunSettings(transient=0.0, samples=K_PERIODS), y0=y0)
    assert int(ds["edge_crossings"].sum()) == 0
    ns = np.array([32, 64, 128, 256])
    for locate in (True, False):
        errs = trajectory_errors(m, y0, ns, locate)
        assert errs[-1] < 1e-7
        assert order(ns, errs) > 3.7


@pytest.mark.parametrize("omega", [0.6, 1.1, 3.5])
def test_edge_location_keeps_fourth_order_with_contact_loss(omega):
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper()).with_omega(omega)
    y0, _ = on_attractor(m)
    ds = geardyn.simulate(m, run=geardyn.RunSettings(transient=0.0, samples=K_PERIODS), y0=y0)
    assert int(ds["edge_crossings"].sum()) >= K_PERIODS  # the teeth separate every period
    ns_loc = dense(32, 256)
    p_loc = order(ns_loc, trajectory_errors(m, y0, ns_loc, True))
    ns_raw = dense(64, 1024)
    e_raw = trajectory_errors(m, y0, ns_raw, False)
    p_raw = order(ns_raw, e_raw)
    assert p_loc > 3.7
    assert 1.4 < p_raw < 2.6
    # at 256 steps, locating the edges gains at least two orders of magnitude
    e_loc_256 = trajectory_errors(m, y0, [256], True)[0]
    assert e_loc_256 * 100 < e_raw[ns_raw == 256][0]


def _poincare_distance(A, B):
    """Largest distance from a point of B to the nearest point of A (max norm)."""
    return max(float(np.min(np.max(np.abs(A - b), axis=1))) for b in B)


@pytest.mark.parametrize(("omega", "loss"), [(0.5, False), (0.6, True), (1.1, True),
                                             (3.5, True)])
def test_default_steps_reach_1e6_on_periodic_attractors(omega, loss):
    """The default steps per period put the Poincare points of a periodic attractor within 1e-6
    of the reference orbit (regimes with and without tooth separation)."""
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper()).with_omega(omega)
    T = 2 * math.pi / omega
    y_fine, fine = on_attractor(m)
    assert (int(fine["edge_crossings"].sum()) > 0) == loss
    # the reference's own attractor: run it on from the fine RK4 point, keep the last points
    ref = geardyn.reference_solution(m, y_fine, np.arange(25) * T, rtol=1e-12, atol=1e-13)[-4:]
    # period 1 or 2, converged: to 1e-8, the reference's own reproducibility here (at
    # Omega = 0.6 a start moved by 1e-14 changed this difference from 2e-10 to 9e-9)
    assert np.max(np.abs(ref[2:] - ref[:2])) < 1e-8
    ds = geardyn.simulate(m, run=geardyn.RunSettings(transient=4000.0, samples=4))
    assert ds.attrs["steps_per_period"] == geardyn.default_steps_per_period(m)
    assert _poincare_distance(ref, ds["poincare"].values) < 1e-6
    assert _poincare_distance(ds["poincare"].values, ref) < 1e-6


@pytest.mark.parametrize("n_per", [4, 7, 128, 1000, 4096, 16384])
def test_phase_table_by_rotation_stays_within_a_few_ulp_of_the_exact_phase(n_per):
    """The forcing-phase table is built by the rotations the fused step loop applies on the fly
    (phase_rotate); against sin and cos in extended precision, its drift over a period stays
    below 1e-14 (libm's own table: ~7e-16), and the period's end is exactly (0, 1)."""
    s, c = phase_table_values(n_per, True)
    pi = np.longdouble("3.14159265358979323846264338327950288")
    a = pi * np.arange(2 * n_per + 1, dtype=np.longdouble) / n_per
    err = max(np.max(np.abs(s - np.sin(a))), np.max(np.abs(c - np.cos(a))))
    assert err < 1e-14
    assert (s[0], c[0], s[-1], c[-1]) == (0.0, 1.0, 0.0, 1.0)
    s0, c0 = phase_table_values(n_per, False)
    assert np.all(s0 == 0.0) and np.all(c0 == 1.0)


@nb.njit
def _compiled_phase_table(n_per, forced):
    return phase_table(n_per, forced)


@pytest.mark.parametrize("n_per", [1, 4, 7, 1000, 4096])
def test_the_interpreters_phase_table_is_the_compiled_one_bitwise(n_per):
    """The orchestrating code takes the forcing-phase table from the interpreter
    (phase_table_values); the kernels compute it compiled (phase_table): the same bits."""
    for forced in (True, False):
        want = _compiled_phase_table(n_per, forced)
        got = phase_table_values(n_per, forced)
        for g, w in zip(got, want, strict=True):
            assert g.dtype == w.dtype and np.array_equal(g.view(np.int64), w.view(np.int64))
    assert not phase_table_values(n_per, True)[0].flags.writeable
