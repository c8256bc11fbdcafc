"""ISO 6336-1 K_v for gear trains: the dynamic_factor capability on TrainModel, checked against
the spur pair's own inputs, the static torque balance and the eigenvalue problem of ISO's
idealisation."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

import geardyn
from geardyn.analysis.dynamic_factor import dynamic_factor_sweep, iso_inputs
from geardyn.core.capabilities import Capabilities
from geardyn.core.model import Model
from geardyn.gears.iso6336_kv import resonance_speed
from geardyn.io.toml import builtin_study
from geardyn.trains import Bearing, Gear, GearTrain, Mesh, TrainModel
from test_dynamic_factor import _pair

ACCURACY = dict(base_pitch_deviation=9.0, profile_form_deviation=8.0, pitch_running_in=0.5,
                profile_running_in=0.5, tip_relief=3.0)


def _one_stage(pair: geardyn.SpurPair, torque: float, wheel_first: bool) -> TrainModel:
    """The pair as a one-mesh train: both gears on rigid bearings, the pinion driven, the
    wheel's torque balancing it; ``wheel_first``: the mesh names the wheel as its gear a."""
    i1, i2 = pair.inertia
    gears = [Gear("pinion", i1, geometry=pair.mesh.pinion),
             Gear("wheel", i2, geometry=pair.mesh.wheel)]
    ends = ("wheel", "pinion") if wheel_first else ("pinion", "wheel")
    train = GearTrain(gears, bearings=[Bearing(f"b_{g.name}", g.name, math.inf) for g in gears],
                      meshes=[Mesh("mesh", *ends, "iso")], driven="pinion", free=True)
    return TrainModel(train, torques={"pinion": torque}, load="wheel", backlash="10 um")


@pytest.mark.parametrize("wheel_first", [False, True])
def test_one_stage_train_gives_the_spur_pairs_iso_inputs(wheel_first):
    pair = _pair()
    train = _one_stage(pair, 50.0, wheel_first)
    assert train.capabilities.dynamic_factor and train.input_torque == pytest.approx(50.0)
    for t1 in (20.0, 150.0):
        want = iso_inputs(pair, torque=t1, **ACCURACY)["mesh"].as_dict()
        got = iso_inputs(train, torque=t1, **ACCURACY)["mesh"].as_dict()
        # the pair's F_t = T1 / r1; the train's from its static mesh force: two paths
        assert got == pytest.approx(want, rel=1e-9)
    group = train.kv_groups(50.0)[0]
    assert group.meshes == (0,) and group.speed_per_input == pytest.approx(1.0, rel=1e-12)


def test_at_input_torque_scales_the_load_and_keeps_the_balance():
    pair = _pair()
    train = _one_stage(pair, 50.0, False)
    heavier = train.at_input_torque(120.0)
    assert heavier.body_torques["pinion"] == pytest.approx(120.0)
    assert abs(heavier.body_torques["wheel"]) == pytest.approx(120.0 * 48 / 19)
    assert heavier.static_mesh_forces()[0] == pytest.approx(
        120.0 / pair.mesh.pinion.base_radius, rel=1e-9)


def _nrel() -> TrainModel:
    return geardyn.build_model(builtin_study("nrel_5mw_gearbox_sweep"))


def test_nrel_groups_follow_the_torque_through_every_stage():
    model = _nrel()
    train = model.train
    groups = {g.name: g for g in model.kv_groups(model.input_torque)}
    assert set(groups) == {"stage3", "sun1", "ring1", "sun2", "ring2"}
    assert groups["sun1"].meshes == (1, 2, 3) and groups["ring2"].meshes == (10, 11, 12)
    ratios = train.speed_ratios()
    t_in = model.input_torque
    # no losses: every stage carries the input power, T_gear1 |omega_gear1| = T_in omega_in
    stage3 = train.meshes[0]
    pinion = min((stage3.a, stage3.b), key=lambda g: train.bodies[g].geometry.teeth)
    for name, gear in (("sun1", "sun1"), ("sun2", "sun2"), ("stage3", pinion)):
        g = groups[name]
        geo = train.bodies[gear].geometry
        r1 = getattr(geo, "transverse", geo).reference_radius
        torque = g.tangential_force * r1 * len(g.meshes)
        assert torque * abs(ratios[gear]) == pytest.approx(t_in, rel=1e-6), name
    # a planet in moment balance: its ring force equals its sun force (equal cos(alpha_t))
    for stage in ("1", "2"):
        assert groups[f"ring{stage}"].tangential_force == pytest.approx(
            groups[f"sun{stage}"].tangential_force, rel=1e-9)
    inputs = iso_inputs(model, **ACCURACY)
    assert inputs["stage3"].contact_ratio > 2.0  # helical: eps_alpha + the overlap ratio


def test_nrel_sun_group_resonance_is_the_in_phase_mode_of_sun_and_planets():
    model = _nrel()
    train = model.train
    inp = iso_inputs(model, **ACCURACY)["sun1"]
    group = next(g for g in model.kv_groups(model.input_torque) if g.name == "sun1")
    sun = train.bodies["sun1"]
    planet = train.bodies["pa1"]
    n = len(group.meshes)
    k = inp.mesh_stiffness * 1e9 * group.face_width
    K = np.zeros((n + 1, n + 1))
    for p in range(1, n + 1):
        e = np.zeros(n + 1)
        e[0] = e[p] = 1.0
        K += k * np.outer(e, e)
    masses = [sun.inertia / sun.base_radius ** 2] + [planet.inertia / planet.base_radius ** 2] * n
    w2 = scipy.linalg.eigh(K, np.diag(masses), eigvals_only=True)
    f_mesh = math.sqrt(max(w2)) / (2.0 * math.pi)  # Hz, ISO's idealisation of clause 6.5.9
    assert resonance_speed(inp) / 60.0 * inp.pinion_teeth == pytest.approx(f_mesh, rel=1e-9)


def test_train_dynamic_factor_is_one_without_excitation_and_grows_with_it():
    model = geardyn.build_model(builtin_study("two_stage_train"))
    run = geardyn.RunSettings(transient=400.0, samples=8)
    quiet = dynamic_factor_sweep(model.with_params(stiffness_fluctuation=0.0), [300.0, 600.0],
                                 None, run, **ACCURACY)
    assert list(quiet["group"].values) == ["stage1", "stage2"]
    # no stiffness variation, no error, constant torque: the response is the static one
    np.testing.assert_allclose(quiet["dynamic_factor"].values, 1.0, atol=1e-6)
    assert np.all(np.isfinite(quiet["K_v"].values)) and np.all(quiet["K_v"].values > 1.0)
    loud = dynamic_factor_sweep(model, [300.0, 600.0], [60.0, 120.0], run, **ACCURACY)
    assert np.all(loud["dynamic_factor"].values > 1.0 + 1e-4)
    assert np.size(loud.attrs["natural_speeds"]) > 0
    # K_v falls with load (B_p, B_f ~ 1 / line load) in the subcritical range
    assert np.all(loud["K_v"].values[1] < loud["K_v"].values[0])


def test_models_without_the_capability_are_refused():
    with pytest.raises(geardyn.ParameterError, match="model"):
        iso_inputs(geardyn.GearPair(), base_pitch_deviation=1.0, profile_form_deviation=1.0)
    with pytest.raises(TypeError, match="kv_groups"):
        type("Half", (Model,), {"capabilities": Capabilities(
            mesh_forces=True, dynamic_factor=True, natural_frequencies="Hz")})
    with pytest.raises(ValueError, match="mesh_forces"):
        Capabilities(dynamic_factor=True)
