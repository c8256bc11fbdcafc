"""Poincare sections: the common period of two forcings, and the transient set by convergence."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.analysis.periodicity import classify_period
from geardyn.core.plan import LaneSettings
from geardyn.core.section import common_section
from geardyn.core.settings import RunSettings
from geardyn.solvers.ensemble import run_lanes


def test_common_section_of_rational_and_irrational_ratios():
    omega = np.array([1.0, 1.0, 1.5, 2.0, 1.0, 1.0])
    others = np.array([[0.5, np.nan], [1 / 3, 0.25], [1.0, np.nan], [np.nan, np.nan],
                       [math.sqrt(2), np.nan], [1 / 97, np.nan]])
    every, ok = common_section(omega, others)
    # 1/2 -> 2 periods; 1/3 and 1/4 -> lcm 12; 1/1.5 = 2/3 -> 3; none -> 1; sqrt 2 and a
    # denominator beyond the limit are not commensurate
    assert every.tolist() == [2, 12, 3, 1, 1, 1]
    assert ok.tolist() == [True, True, True, True, False, False]


@pytest.fixture(scope="module")
def noisy_device():
    # load fluctuation at Lambda = Omega / 2: the forcing repeats every two mesh periods
    p = geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1, B1=0.2, B2=0.2, Lambda=0.3)
    return geardyn.CATTDevice(p, omega=0.6)


def test_model_reports_the_load_fluctuation(noisy_device):
    P = noisy_device.lane_params("Omega", [0.6, 0.9])
    every, ok = common_section(P[:, noisy_device.omega_index],
                               noisy_device.other_frequencies(P))
    assert every.tolist() == [2, 3] and ok.all()
    quiet = geardyn.CATTDevice(geardyn.PlanetaryParams.paper())
    assert np.isnan(quiet.other_frequencies(quiet.lane_params("Omega", [1.0]))).all()


def test_samples_every_common_period_match_reference(noisy_device):
    m = noisy_device
    P = m.lane_params("Omega", [0.6])
    r = run_lanes(m, P, m.initial_state(), run=RunSettings(transient=150.0, samples=4),
                  lanes=LaneSettings(sample_every=2))
    T = 2 * math.pi / 0.6
    n_tr = int(r.transient_periods[0])
    assert n_tr % 2 == 0  # the transient is whole common periods
    t_eval = (n_tr + 2 * np.arange(1, 5)) * T
    ref = geardyn.reference_solution(m, m.initial_state(), t_eval)
    assert np.max(np.abs(r.samples[0] - ref)) < 1e-6 * np.max(np.abs(ref))


def test_transient_by_convergence_stops_early_on_a_periodic_attractor():
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    P = m.lane_params("Omega", [0.6, 1.1])
    long = run_lanes(m, P, m.initial_state(), run=RunSettings(transient=3000.0, samples=8))
    auto = run_lanes(m, P, m.initial_state(),
                     run=RunSettings(transient=100.0, samples=8, transient_max=3000.0,
                                     converge=1e-8))
    assert auto.converged.tolist() == [1, 1]
    assert np.all(auto.transient_periods < long.transient_periods)
    assert classify_period(auto.samples).tolist() == classify_period(long.samples).tolist()
    # the points agree with those after the long transient (to the tolerance's order), up to
    # the phase along a period-k orbit
    scale = np.max(np.abs(long.samples))
    for lane, k in enumerate(classify_period(long.samples)):
        a, b = auto.samples[lane], long.samples[lane]
        err = min(np.max(np.abs(np.roll(a, s, axis=0) - b)) for s in range(k))
        assert err < 1e-6 * scale
    assert long.converged.tolist() == [-1, -1]


def test_transient_by_convergence_gives_up_on_chaos():
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    P = m.lane_params("Omega", [2.5])  # chaotic (Fig. 3 band 2.3-2.7)
    r = run_lanes(m, P, m.initial_state(),
                  run=RunSettings(transient=100.0, samples=8, transient_max=600.0, converge=1e-8))
    T = 2 * math.pi / 2.5
    assert r.converged[0] == 0
    assert r.transient_periods[0] == math.floor(600.0 / T)


def test_simulation_records_the_second_excitation(noisy_device):
    ds = geardyn.simulate(noisy_device,
                          run=geardyn.RunSettings(transient=0.0, samples=1, steps_per_period=64))
    assert ds.attrs["Lambda"] == 0.3


def test_bifurcation_reports_sections_and_convergence(noisy_device):
    # Lambda = 0.3: Omega = 0.6 is commensurate (2 periods), 0.3 * sqrt(5) is not
    values = [0.6, 0.3 * math.sqrt(5)]
    ds = geardyn.bifurcation(noisy_device, "Omega", values,
                             run=geardyn.RunSettings(transient=300.0, samples=8, converge=1e-8,
                                                     transient_max=3000.0))
    assert ds["section_periods"].values.tolist() == [2, 1]
    # heavily damped: the common-period orbit is period-1 in the section, 2 forcing periods;
    # the quasi-periodically forced point has no period
    assert ds["period"].values.tolist() == [2, 0]
    assert ds["converged"].values[0] == 1 and ds["converged"].values[1] == 0
    assert ds.attrs["converge"] == 1e-8
    # the section samples really are two forcing periods apart: compare with the reference
    T = 2 * math.pi / 0.6
    n_tr = int(ds["transient_periods"].values[0])
    t_eval = (n_tr + 2 * np.arange(1, 4)) * T
    ref = geardyn.reference_solution(noisy_device.with_omega(0.6), noisy_device.initial_state(),
                                     t_eval)
    got = ds["poincare"].values[0, :3]
    assert np.max(np.abs(got - ref)) < 1e-6 * np.max(np.abs(ref))
