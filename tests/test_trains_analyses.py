"""Every analysis on a gear train: a sweep in input torque, a 2-D map in speed and torque, and,
for a train with whole mesh orders (periodic forcing), a periodic orbit, its continuation and
the Lyapunov exponent, each checked against an independent computation (the single runs, a
long simulation, the Floquet multipliers)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Mesh, Shaft, TrainModel
from test_trains_model import (
    C_MESH,
    INERTIA,
    K_MID,
    KA,
    KB,
    RBP,
    T_IN,
    Z_WHOLE,
    Z,
    _parallel,
    _radii,
)

RUN = geardyn.RunSettings(transient=200.0, samples=8, steps_per_period=128)


def test_a_sweep_in_input_torque_scales_the_static_load_and_equals_single_runs():
    model = _parallel(input_speed=2500.0, backlash=20e-6)
    assert "input_torque" in model.physical_names
    torques = [30.0, 60.0, 240.0]
    ds = geardyn.bifurcation(model, "input_torque", torques, RUN)
    assert ds["input_torque"].attrs["units"] == "N m"
    for j, t in enumerate(torques):
        one = model.with_params(input_torque=t)
        # the torque balance of stage 1's pinion: F = T_in / r_b1
        assert abs(one.static_mesh_forces()[0]) == pytest.approx(t / RBP[0], rel=1e-9)
        assert abs(one.body_torques["g4"]) == pytest.approx(
            t * (Z[1] / Z[0]) * (Z[3] / Z[2]), rel=1e-9)
        sim = geardyn.simulate(one, run=RUN)
        np.testing.assert_array_equal(ds["poincare"].values[j], sim["poincare"].values[-8:])
    with pytest.raises(geardyn.ParameterError, match="input_torque"):
        model.with_params(input_torque=10.0, torques={"g1": 1.0})


def test_a_map_in_speed_and_torque_is_the_speed_sweeps_row_by_row():
    model = _parallel(input_speed=2000.0, backlash=20e-6)
    speeds, torques = [1800.0, 2600.0], [40.0, 120.0]
    grid = geardyn.map2d(model, ("input_speed", speeds), ("input_torque", torques), RUN)
    for i, t in enumerate(torques):
        row = geardyn.bifurcation(model.with_params(input_torque=t), "input_speed", speeds, RUN)
        np.testing.assert_array_equal(grid["period"].values[i], row["period"].values)
        np.testing.assert_array_equal(
            grid["contact"].values[i].astype(str), row["contact"].values.astype(str))


def _periodic(rpm: float = 1500.0) -> TrainModel:
    """Stage 2 at twice stage 1's mesh frequency (periodic forcing), the output held by a
    flexible brake shaft to the ground (no rigid-body mode), every mode damped."""
    rb = _radii(Z_WHOLE)
    g = [Gear(f"g{i + 1}", INERTIA[i], base_radius=rb[i], n_teeth=Z_WHOLE[i])
         for i in range(4)]
    train = GearTrain(g, shafts=[Shaft("mid", "g2", "g3", K_MID),
                                 Shaft("brake", "g4", GROUND, 2e5, damping=20.0)],
                      bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf) for i in range(4)],
                      meshes=[Mesh("stage1", "g1", "g2", KA, damping=C_MESH),
                              Mesh("stage2", "g3", "g4", KB, damping=C_MESH)],
                      driven="g1")
    return TrainModel(train, torques={"g1": T_IN}, stiffness_fluctuation=0.25,
                      backlash=20e-6, modal_damping=0.03, input_speed=rpm)


def test_periodic_train_orbit_is_the_long_runs_limit_and_its_exponent_the_floquet_rate():
    model = _periodic()
    assert not model.quasi_periodic
    orbit = geardyn.periodic_orbit(model, run=geardyn.RunSettings(transient=400.0))
    assert orbit.converged
    mu = float(np.max(np.abs(orbit.multipliers)))
    assert mu < 0.95
    long = geardyn.simulate(model, run=geardyn.RunSettings(transient=2000.0, samples=2))
    end = long["poincare"].values[-1]
    np.testing.assert_allclose(end, orbit.x, rtol=0, atol=1e-7 * np.max(np.abs(orbit.x)))
    ly = geardyn.lyapunov(model, run=geardyn.RunSettings(transient=400.0), with_error=True)
    period = 2.0 * math.pi / model.omega  # one forcing period (a period-1 orbit)
    floquet_rate = math.log(mu) / period
    assert ly.value == pytest.approx(floquet_rate,
                                     abs=max(5.0 * ly.stderr, 0.05 * abs(floquet_rate)))


def test_periodic_train_continuation_follows_the_orbits_newton_finds():
    model = _periodic()
    w0 = model.omega
    branch = geardyn.continuation(model, "Omega", w0, 1.05 * w0)
    assert branch.sizes["point"] >= 3 and int(branch.attrs["status"]) == 0
    for k in (0, branch.sizes["point"] - 1):
        w = float(branch["Omega"].values[k])
        x = branch["section_point"].values[k]
        orbit = geardyn.periodic_orbit(model, omega=w, guess=x)
        assert orbit.converged
        np.testing.assert_allclose(x, orbit.x, rtol=0, atol=1e-6 * np.max(np.abs(orbit.x)))


def test_periodic_train_frequency_response_and_basins_meet_the_orbit_newton_finds():
    """Up and down sweeps agree with the periodic orbit of Newton shooting (its peak mesh
    forces), and every start of a basin grid ends on that one attractor."""
    model = _periodic()
    w = model.omega
    omegas = np.array([0.95 * w, w])
    run = geardyn.RunSettings(transient=2000.0, samples=8)
    frc = geardyn.frequency_response(model, omegas, run)
    for k, om in enumerate(omegas):
        orbit = geardyn.periodic_orbit(model, omega=float(om), run=RUN)
        assert orbit.converged
        peak = np.max(np.abs(orbit.observables), axis=0)
        for sweep in ("up", "down"):
            np.testing.assert_allclose(frc["force_peak"].sel(sweep=sweep).values[k], peak,
                                       rtol=2e-3)
    basins = geardyn.basins(model, None, ("g1.theta", -1e3, 1e3, 3),
                            ("dg1.theta", -50.0, 50.0, 3), RUN)
    assert basins.sizes["attractor"] == 1
    assert float(basins["attractor_fraction"].values[0]) == 1.0
