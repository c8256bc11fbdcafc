"""ISO 6336-1 method B K_v (geardyn.gears.iso6336_kv) and the model's dynamic factor beside it
(geardyn.analysis.dynamic_factor).

K_v: Table 8's factors, values worked by hand from the standard's equations (Eqs. 6, 9,
11-22; the arithmetic written out below, not taken from the code), the ranges' continuity where
Eq. 22 makes it continuous and the jump at N_S where the standard has one. The resonance speed:
against the eigenvalue problem of the two gear inertias on the mesh spring."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

import geardyn
from geardyn.analysis.dynamic_factor import dynamic_factor_sweep, iso_inputs, linear_resonance_speed
from geardyn.gears import GearMesh, SpurGear
from geardyn.gears.iso6336_kv import (
    DynamicFactorInputs,
    cv_factors,
    dynamic_factor_iso,
    lower_resonance_limit,
    resonance_speed,
)

#: A hand-worked case: z1 19, m_red 0.0109 kg/mm, c' 14 and c_gamma 20 N/(mm um), 200 N/mm,
#: f_pb 10 um, f_falpha 8 um, y_p = y_f = 1 um, no tip relief, eps_gamma 1.6.
HAND = DynamicFactorInputs(pinion_teeth=19, reduced_mass=0.0109, single_stiffness=14.0,
                           mesh_stiffness=20.0, line_load=200.0, base_pitch_deviation=10.0,
                           profile_form_deviation=8.0, pitch_running_in=1.0,
                           profile_running_in=1.0, tip_relief=0.0, contact_ratio=1.6)
# B_p = 14 * 9 / 200 = 0.63; B_f = 14 * 7 / 200 = 0.49; B_k = |1 - 0| = 1
# main resonance (Eq. 20): 0.32*0.63 + 0.34*0.49 + 0.90*1 + 1 = 0.2016 + 0.1666 + 0.9 + 1
KV_MAIN = 2.2682
# supercritical (Eq. 21), eps_gamma 1.6 <= 2: C_v7 = 0.125 sin(pi (1.6 - 2)) + 0.875
CV7 = 0.125 * math.sin(math.pi * -0.4) + 0.875  # = 0.75612...
KV_SUPER = 0.47 * 0.63 + 0.47 * 0.49 + CV7  # 0.2961 + 0.2303 + C_v7
# subcritical (Eqs. 13, 14): K = 0.2016 + 0.1666 + 0.23 = 0.5982, K_v = N K + 1
K_SUB = 0.5982
# Eq. 6: n_E1 = 30000 / (pi 19) sqrt(20 / 0.0109) = 502.6112 * 42.8352
N_E1 = 30000.0 / (math.pi * 19) * math.sqrt(20.0 / 0.0109)


def test_table_8_factors():
    low = cv_factors(1.4)
    assert low == pytest.approx({"C_v1": 0.32, "C_v2": 0.34, "C_v3": 0.23, "C_v4": 0.90,
                                 "C_v5": 0.47, "C_v6": 0.47, "C_v7": 0.75})
    high = cv_factors(3.0)
    assert high["C_v2"] == pytest.approx(0.57 / 2.7)
    assert high["C_v3"] == pytest.approx(0.096 / 1.44)
    assert high["C_v4"] == pytest.approx(0.42 / 1.56)
    assert high["C_v6"] == pytest.approx(0.12 / 1.26)
    assert high["C_v7"] == 1.0
    # C_v7 is continuous at eps_gamma 1.5 and 2.5 (its three pieces meet)
    for e in (1.5, 2.5):
        assert cv_factors(e - 1e-9)["C_v7"] == pytest.approx(cv_factors(e + 1e-9)["C_v7"],
                                                            abs=1e-8)


def test_hand_worked_values_in_every_range():
    assert resonance_speed(HAND) == pytest.approx(N_E1, rel=1e-12)
    n_s = lower_resonance_limit(200.0)
    assert n_s == 0.85
    ratios = np.array([0.5, 1.0, 1.3, 2.0])
    kv, regime = dynamic_factor_iso(HAND, ratios * N_E1)
    assert regime.tolist() == [0, 1, 2, 3]
    assert kv[0] == pytest.approx(0.5 * K_SUB + 1.0, rel=1e-12)
    assert kv[1] == pytest.approx(KV_MAIN, rel=1e-12)
    assert kv[2] == pytest.approx(KV_SUPER + (KV_MAIN - KV_SUPER) * 0.2 / 0.35, rel=1e-12)
    assert kv[3] == pytest.approx(KV_SUPER, rel=1e-12)


def test_light_load_lowers_n_s():
    # Eq. 11: 0.5 + 0.35 sqrt(50 / 100) = 0.74749; continuous with Eq. 12 at 100 N/mm
    assert lower_resonance_limit(50.0) == pytest.approx(0.5 + 0.35 * math.sqrt(0.5))
    assert lower_resonance_limit(100.0 - 1e-9) == pytest.approx(0.85, abs=1e-9)


def test_continuous_at_1_15_and_1_5_and_a_jump_at_n_s():
    eps = 1e-9
    for n in (1.15, 1.5):
        kv, _ = dynamic_factor_iso(HAND, np.array([n - eps, n + eps]) * N_E1)
        assert kv[0] == pytest.approx(kv[1], abs=1e-7)
    kv, regime = dynamic_factor_iso(HAND, np.array([0.85 - eps, 0.85 + eps]) * N_E1)
    assert regime.tolist() == [0, 1]
    # the standard's ranges meet with a step at N_S: N_S K + 1 against the main-range value
    assert kv[1] - kv[0] == pytest.approx(KV_MAIN - (0.85 * K_SUB + 1.0), abs=1e-6)


def _pair(torque: float = 50.0) -> geardyn.SpurPair:
    mesh = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                    SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))
    return geardyn.SpurPair.from_geometry(mesh, bore_radius=(0.012, 0.035), speed=3000.0,
                                          torque=torque, speed_unit="rpm", backlash="10 um",
                                          period="mesh", angles=64, harmonics=16)


def test_resonance_speed_is_the_eigenvalue_of_the_two_inertias_on_the_mesh_spring():
    m = _pair()
    i1, i2 = m.inertia
    r1, r2 = m.mesh.pinion.base_radius, m.mesh.wheel.base_radius
    for source in ("model", "iso"):
        inp = iso_inputs(m, base_pitch_deviation=8.0, profile_form_deviation=7.0,
                         stiffness=source)["mesh"]
        k = inp.mesh_stiffness * 1e9 * 0.016  # N/(mm um) * b -> N/m
        K = k * np.array([[r1 * r1, -r1 * r2], [-r1 * r2, r2 * r2]])
        w2 = scipy.linalg.eigh(K, np.diag([i1, i2]), eigvals_only=True)
        f = math.sqrt(max(w2)) / (2.0 * math.pi)  # Hz; the other root is the rigid rotation
        assert resonance_speed(inp) == pytest.approx(f * 60.0 / 19, rel=1e-9)
    model_inputs = iso_inputs(m, base_pitch_deviation=8.0, profile_form_deviation=7.0,
                              stiffness="model")["mesh"]
    assert linear_resonance_speed(m) == pytest.approx(resonance_speed(model_inputs), rel=1e-9)


def test_sweep_dataset_holds_both_factors_and_n_m():
    m = _pair()
    ds = dynamic_factor_sweep(m, [5000.0, 20000.0, 35000.0], [20.0, 200.0],
                              geardyn.RunSettings(transient=0.02, samples=8),
                              base_pitch_deviation=8.0, profile_form_deviation=7.0,
                              tip_relief=5.0)
    assert ds["dynamic_factor"].dims == ("torque", "speed", "group")
    assert ds["speed"].attrs["units"] == "rpm"
    for j, t1 in enumerate((20.0, 200.0)):
        inp = iso_inputs(m, torque=t1, base_pitch_deviation=8.0, profile_form_deviation=7.0,
                         tip_relief=5.0)["mesh"]
        kv, regime = dynamic_factor_iso(inp, ds["speed"].values)
        np.testing.assert_allclose(ds["K_v"].values[j, :, 0], kv)
        np.testing.assert_array_equal(ds["iso_range"].values[j, :, 0], regime)
        assert float(ds["resonance_speed"][j, 0]) == pytest.approx(resonance_speed(inp))
        alone = geardyn.bifurcation(m.with_params(torque=t1), "speed", ds["speed"].values,
                                    geardyn.RunSettings(transient=0.02, samples=8))
        np.testing.assert_allclose(ds["dynamic_factor"].values[j, :, 0],
                                   alone["dynamic_factor"].values[:, 0])
    assert np.all(ds["dynamic_factor"].values > 1.0)
    # a heavier load stiffens ISO's c' below 100 N/mm: N_M moves up
    assert float(ds["resonance_speed"][1, 0]) > float(ds["resonance_speed"][0, 0])


def test_bad_inputs_name_the_field():
    base = HAND.as_dict() | {"pinion_teeth": 19}
    for field, value in (("reduced_mass", 0.0), ("line_load", -1.0), ("contact_ratio", 1.0),
                         ("tip_relief", float("nan")), ("pitch_running_in", 20.0)):
        with pytest.raises(geardyn.ParameterError, match=field):
            DynamicFactorInputs(**(base | {field: value}))
    with pytest.raises(geardyn.ParameterError, match="speed"):
        dynamic_factor_iso(HAND, [-1.0])
    with pytest.raises(geardyn.ParameterError, match="stiffness"):
        iso_inputs(_pair(), base_pitch_deviation=1.0, profile_form_deviation=1.0,
                   stiffness="fem")
    with pytest.raises(geardyn.ParameterError, match="torque"):
        iso_inputs(_pair(), base_pitch_deviation=1.0, profile_form_deviation=1.0, torque=0.0)


def test_plot_dynamic_factor(tmp_path):
    from geardyn.plotting.dynamic_factor import plot_dynamic_factor

    ds = dynamic_factor_sweep(_pair(), [5000.0, 20000.0], None,
                              geardyn.RunSettings(transient=0.02, samples=8),
                              base_pitch_deviation=8.0, profile_form_deviation=7.0)
    fig = plot_dynamic_factor(ds, tmp_path / "df.pdf")
    assert (tmp_path / "df.pdf").stat().st_size > 0
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("ISO 6336-1" in t for t in labels) and any("N_M" in t for t in labels)
    with pytest.raises(ValueError, match="dynamic-factor sweep"):
        plot_dynamic_factor(ds.drop_vars("K_v"))


def _planetary():
    import tomllib
    from importlib.resources import files

    from planetary_example_set import planetary_by_hand

    doc = tomllib.loads(files("geardyn.studies").joinpath("planetary_example.toml").read_text())
    return planetary_by_hand(doc)


def test_planetary_sun_resonance_is_the_in_phase_mode_of_sun_and_planets():
    gs = _planetary()
    inp = iso_inputs(gs, base_pitch_deviation=8.0, profile_form_deviation=7.0)
    geo, n = gs.geometry, gs.n_planets
    b = 0.02
    k = inp["sun"].mesh_stiffness * 1e9 * b  # one sun-planet mesh [N/m]
    ms = gs.members["sun"].inertia_over_r2  # I / r_b^2 [kg]
    mp = gs.members["planet"].inertia_over_r2
    # rotations on the base radii u_s, u_1..u_N; sun-planet springs on u_s + u_n; carrier and
    # ring held, no ring mesh: ISO's idealisation of clause 6.5.9
    K = np.zeros((n + 1, n + 1))
    for p in range(1, n + 1):
        e = np.zeros(n + 1)
        e[0] = e[p] = 1.0
        K += k * np.outer(e, e)
    w2 = scipy.linalg.eigh(K, np.diag([ms] + [mp] * n), eigvals_only=True)
    f_mesh = math.sqrt(max(w2)) / (2.0 * math.pi)  # Hz, the in-phase mode
    ds = dynamic_factor_sweep(gs, [3000.0], None, geardyn.RunSettings(transient=50.0, samples=8),
                              base_pitch_deviation=8.0, profile_form_deviation=7.0)
    n_m = float(ds["resonance_speed"].sel(group="sun")[0])  # input speed [rpm]
    assert n_m / 60.0 * gs.mesh_frequency_per_input_speed() == pytest.approx(f_mesh, rel=1e-9)
    # the ring-planet mesh: the planet alone on the ring mesh spring (ring infinitely heavy)
    k_r = inp["ring"].mesh_stiffness * 1e9 * b
    n_r = float(ds["resonance_speed"].sel(group="ring")[0])
    assert n_r / 60.0 * gs.mesh_frequency_per_input_speed() \
        == pytest.approx(math.sqrt(k_r / mp) / (2.0 * math.pi), rel=1e-9)
    assert geo.sun.teeth == inp["sun"].pinion_teeth and geo.planet.teeth == \
        inp["ring"].pinion_teeth


def test_planetary_sweep_groups_the_meshes():
    gs = _planetary()
    run = geardyn.RunSettings(transient=200.0, samples=8)
    speeds = [4000.0, 14000.0]
    ds = dynamic_factor_sweep(gs, speeds, [20.0, 60.0], run, base_pitch_deviation=8.0,
                              profile_form_deviation=7.0)
    assert list(ds["group"].values) == ["sun", "ring"]
    alone = geardyn.bifurcation(gs.with_params(sun_torque=60.0), "input_speed", speeds, run)
    df = alone["dynamic_factor"].values
    np.testing.assert_allclose(ds["dynamic_factor"].sel(torque=60.0, group="sun"),
                               df[:, :4].max(axis=1))
    np.testing.assert_allclose(ds["dynamic_factor"].sel(torque=60.0, group="ring"),
                               df[:, 4:].max(axis=1))
    np.testing.assert_allclose(ds["mesh_frequency"].values,
                               np.array(speeds) / 60.0 * gs.mesh_frequency_per_input_speed())
