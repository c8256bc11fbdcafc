"""Play in a gear train besides the meshes: a flexible bearing's clearance (a dead zone in x
and in y) and a coupling's torsional backlash (a dead zone on a shaft's twist), checked
against equations written out by hand and integrated by DOP853."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Inertia, Mesh, Shaft, TrainModel

Z = (19, 48)
RB = tuple(0.5 * 3e-3 * z * math.cos(math.radians(20.0)) for z in Z)
I_P, I_W, M_P = 2e-4, 6e-3, 0.6
K_B, C_B, K_M, C_M, CLEARANCE, TORQUE = 1e8, 100.0, 3e8, 100.0, 15e-6, 2.0
BACKLASH = 10e-6
AMPLITUDE = 0.3
C_COUPLING = 0.5


def _pair(clearance: float = CLEARANCE, rpm: float = 5500.0) -> TrainModel:
    """A spur pair, the pinion on a flexible bearing with ``clearance``, the wheel on a rigid
    one; near 5500 rpm the pinion's journal leaves its bearing's load side."""
    gears = [Gear("p", I_P, base_radius=RB[0], n_teeth=Z[0], mass=M_P),
             Gear("w", I_W, base_radius=RB[1], n_teeth=Z[1])]
    train = GearTrain(gears, bearings=[Bearing("bp", "p", K_B, clearance=clearance,
                                               damping=C_B),
                                       Bearing("bw", "w", math.inf)],
                      meshes=[Mesh("mesh", "p", "w", K_M, damping=C_M)], driven="p",
                      free=True)
    return TrainModel(train, torques={"p": TORQUE}, load="w", backlash=BACKLASH,
                      stiffness_fluctuation=AMPLITUDE, input_speed=rpm)


def _dead(d: np.ndarray, b: float) -> np.ndarray:
    return d - np.clip(d, -b, b)


def test_bearing_clearance_matches_dop853_on_hand_written_equations():
    model = _pair()
    assert [m[0] for m in model.meshes] == ["mesh", "bp_x", "bp_y"]
    names = model.dof_names()
    assert names == ("p.theta", "p.x", "p.y", "w.theta")
    L, w0 = model.length_scale, model.time_scale
    run = geardyn.RunSettings(transient=0, samples=40, steps_per_period=256)
    ds = geardyn.simulate(model, run=run)
    M = np.diag([I_P, M_P, M_P, I_W])
    W = model.mesh_rows()[0]  # the train's assembly (checked by the linear tests)
    F = np.array([model.body_torques["p"], 0.0, 0.0, model.body_torques["w"]])
    w = model.omega * w0

    def bearing(q, v):
        return K_B * _dead(q[1:3], CLEARANCE), C_B * v[1:3]

    def rhs(t, y):
        q, v = y[:4], y[4:]
        f = K_M * (1.0 + AMPLITUDE * np.sin(w * t)) * _dead(W @ q, BACKLASH) + C_M * (W @ v)
        spring, damper = bearing(q, v)
        acc = F - W * f
        acc[1:3] -= spring + damper
        return np.concatenate([v, acc / np.diag(M)])

    y0 = model.initial_state()
    t = ds.time.values / w0
    ref = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([L * y0[:4], L * w0 * y0[4:]]),
                    method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.success
    spring = K_B * _dead(ref.y[1:3], CLEARANCE)
    # the journal crosses its clearance: the dead zone acts
    assert np.any(np.abs(ref.y[1]) < CLEARANCE) and np.any(np.abs(ref.y[1]) > CLEARANCE)
    scale = np.max(np.abs(spring))
    got = np.array([ds["F_bp_x"].values, ds["F_bp_y"].values])
    np.testing.assert_allclose(got, spring, rtol=0, atol=2e-5 * scale)
    mesh_ref = K_M * (1.0 + AMPLITUDE * np.sin(w * t)) * _dead(W @ ref.y[:4], BACKLASH) \
        + C_M * (W @ ref.y[4:])
    np.testing.assert_allclose(ds["F_mesh"].values, mesh_ref, rtol=0,
                               atol=2e-5 * np.max(np.abs(mesh_ref)))


def test_a_clearance_the_journal_never_crosses_moves_it_and_not_the_forces():
    """Loaded on one side in x and y throughout (c well below the static deflection), the
    journal sits c further out on each axis and every force is the plain bearing's."""
    plain = _pair(0.0)
    assert [m[0] for m in plain.meshes] == ["mesh"]
    run = geardyn.RunSettings(transient=0, samples=10, steps_per_period=256)
    base = geardyn.simulate(plain, run=run)["F_mesh"].values
    L = plain.length_scale
    x0 = plain.static_state()[1:3] * L
    for c in (1e-7, 3e-7):
        model = _pair(c)
        np.testing.assert_allclose(np.abs(model.static_state()[1:3] * L - x0), c, rtol=1e-6)
        forces = geardyn.simulate(model, run=run)["F_mesh"].values
        np.testing.assert_allclose(forces, base, rtol=0, atol=1e-9 * np.max(np.abs(base)))


def test_a_sweep_reports_the_bearing_losing_contact():
    ds = geardyn.bifurcation(_pair(), "input_speed", [3000.0, 5500.0],
                             geardyn.RunSettings(transient=300, samples=16))
    contact = ds["contact"].sel(mesh="bp_x").values.astype(str)
    assert contact[0] == "none" and contact[1] != "none"


def _coupled(backlash: float) -> TrainModel:
    """A motor inertia driving a gear through a coupling with torsional ``backlash``."""
    bodies = [Inertia("motor", 1e-3), Gear("p", I_P, base_radius=RB[0], n_teeth=Z[0]),
              Gear("w", I_W, base_radius=RB[1], n_teeth=Z[1])]
    train = GearTrain(bodies, shafts=[Shaft("coupling", "motor", "p", 2e4, damping=C_COUPLING,
                                            backlash=backlash)],
                      bearings=[Bearing(f"b{b.name}", b.name, math.inf) for b in bodies],
                      meshes=[Mesh("mesh", "p", "w", K_M, damping=C_M)], driven="motor",
                      free=True)
    return TrainModel(train, torques={"motor": 0.5}, load="w", backlash=BACKLASH,
                      stiffness_fluctuation=AMPLITUDE, torque_fluctuation=2.0,
                      input_speed=1500.0)


def test_coupling_backlash_matches_dop853_on_hand_written_equations():
    b = 2e-3  # rad, half-width
    model = _coupled(b)
    assert [m[0] for m in model.meshes] == ["mesh", "coupling"]
    L, w0 = model.length_scale, model.time_scale
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0, samples=30,
                                                          steps_per_period=256))
    W = model.mesh_rows()[0]
    inertia = np.diag(model.mass_matrix())
    torques = model.body_torques
    w = model.omega * w0

    def rhs(t, y):
        q, v = y[:3], y[3:]
        f = K_M * (1.0 + AMPLITUDE * np.sin(w * t)) * _dead(W @ q, BACKLASH) + C_M * (W @ v)
        twist, rate = q[0] - q[1], v[0] - v[1]
        tc = 2e4 * _dead(twist, b) + C_COUPLING * rate
        drive = torques["motor"] * (1.0 + 2.0 * np.sin(w * t))
        acc = np.array([drive - tc, tc, torques["w"]]) - W * f
        return np.concatenate([v, acc / inertia])

    y0 = model.initial_state()
    t = ds.time.values / w0
    ref = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([L * y0[:3], L * w0 * y0[3:]]),
                    method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.success
    twist = ref.y[0] - ref.y[1]
    assert np.any(np.abs(twist) < b)  # the coupling's play is crossed
    tc = 2e4 * _dead(twist, b)
    np.testing.assert_allclose(ds["F_coupling"].values, tc, rtol=0,
                               atol=2e-5 * np.max(np.abs(tc)))


def test_play_on_a_rigid_element_names_the_field():
    with pytest.raises(geardyn.ParameterError, match="bw.clearance"):
        Bearing("bw", "w", math.inf, clearance=1e-6)
    with pytest.raises(geardyn.ParameterError, match="j.backlash"):
        Shaft("j", "a", GROUND, math.inf, backlash=1e-3)
    with pytest.raises(geardyn.ParameterError, match="j.backlash"):
        Shaft("j", "a", "b", 1e3, backlash=-1e-3)


def test_study_file_takes_clearance_and_coupling_backlash():
    from importlib.resources import files

    from pydantic import ValidationError

    from geardyn.io.toml import load_study

    text = files("geardyn.studies").joinpath("two_stage_train.toml").read_text()
    text = text.replace('stiffness = "9e5 N m/rad"',
                        'stiffness = "9e5 N m/rad"\nbacklash = "0.1 deg"')
    text = text.replace('stiffness = "2e8 N/m"', 'stiffness = "2e8 N/m"\nclearance = "20 um"')
    model = geardyn.build_model(load_study(text))
    assert [m[0] for m in model.meshes] == ["stage1", "stage2", "b1_x", "b1_y", "mid"]
    plays = {name: (k, b) for name, _, k, b in model.play_elements()}
    assert plays["mid"] == (pytest.approx(9e5), pytest.approx(math.radians(0.1)))
    assert plays["b1_x"][1] == pytest.approx(20e-6)
    with pytest.raises(ValidationError, match="train.bearings.b1.clearance"):
        load_study(text.replace('clearance = "20 um"', 'clearance = "-1 um"'))
