"""The dynamic factor against ISO 6336-1 K_v (geardyn.dynamic_factor_sweep) of a user's one-form
model that declares it (geardyn.DynamicFactorDeclaration).

The gear pair of examples/gear_pair_model.py, dimensionless (time scaled by omega_n =
sqrt(k0 / m), deflection by the backlash b), is the SpurPair's equation with one stiffness
harmonic and the same stiffness on both flanks: its dynamic factor over input speed and torque
equals the SpurPair's to round-off. With the teeth always in contact it is a linear oscillator,
whose dynamic factor follows from its frequency response."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import geardyn
from geardyn.analysis.dynamic_factor import dynamic_factor_sweep
from geardyn.gears import GearMesh, SpurGear, potential_energy_stiffness
from geardyn.gears.iso6336_kv import KvMeshGroup, reduced_mass
from geardyn.testing import check_model

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
import gear_pair_model as gp  # noqa: E402

MESH = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))
ACCURACY = dict(base_pitch_deviation=8.0, profile_form_deviation=7.0, tip_relief=5.0)
DERIVED = {"cos_phi_k": ("phi_k", math.cos), "sin_phi_k": ("phi_k", math.sin),
           "cos_phi_e": ("phi_e", math.cos), "sin_phi_e": ("phi_e", math.sin)}


def _spur_pair() -> geardyn.SpurPair:
    """The 19/48 pair over one mesh cycle, one stiffness harmonic, the coast flank given the
    drive flank's stiffness (the user pair has one stiffness for both)."""
    table = potential_energy_stiffness(MESH, bore_radius=(0.012, 0.035), angles=64, cycles=1)
    table["mesh_stiffness_coast"] = table["mesh_stiffness"]
    return geardyn.SpurPair(MESH, table, speed=3000.0, torque=50.0, speed_unit="rpm",
                            backlash="10 um", error="2 um", error_phase=0.4, harmonics=1)


def _user_pair(params: dict[str, float], *, per_rpm: float, per_nm: float, omega_n: float,
               m_red: float, k0: float, declare: bool = True, **extra) -> geardyn.UserModel:
    """The gear pair of examples/gear_pair_model.py, its time unit 1 / omega_n [rad/s], with
    the dynamic factor declared: Omega per rpm of pinion speed, Fm per N m of pinion torque,
    the pair's mesh group (reduced mass m_red [kg/mm], mean stiffness k0 [N/m])."""
    def groups(p, torque):
        return (KvMeshGroup("mesh", MESH, (0,), torque / MESH.pinion.reference_radius, m_red,
                            1.0, k0),)

    decl = geardyn.DynamicFactorDeclaration(
        speed=("Omega", per_rpm), torque=("Fm", per_nm), groups=groups,
        natural_frequencies=lambda p: (omega_n / (2.0 * math.pi),), time_scale=omega_n)
    kw = dict(events=gp.pair_events, event_names=("x-b", "x+b"), observe=gp.pair_force,
              observable_names=("F",), meshes=[("mesh", "x-b", "x+b", "F")],
              static_forces=lambda p: (p.Fm,), natural_frequency=1.0, name="user spur pair")
    return geardyn.UserModel.from_one_form(
        gp.pair_rhs, params=params, derived=DERIVED, states=("x", "v"),
        **(kw | ({"dynamic_factor": decl} if declare else {}) | extra))


def _scaled(sp: geardyn.SpurPair, **extra) -> geardyn.UserModel:
    """``sp`` as the dimensionless user pair: m x'' + c x' + k(theta) g(x) = T / r_b +
    m e (Omega)^2 cos(theta + phi_e), divided by k0 b with tau = omega_n t, x = b X."""
    v = sp.coefficient_values()
    k0, a1, b1 = (float(c) for c in sp.drive_series)
    m, b, r_b = v["mass"], v["backlash"], MESH.pinion.base_radius
    omega_n = math.sqrt(k0 / m)
    per_nm = 1.0 / (r_b * k0 * b)
    params = dict(Omega=v["Omega"] / omega_n, zeta=v["zeta"], kappa=math.hypot(a1, b1) / k0,
                  Fm=v["torque"] * per_nm, Fa=v["error"] / b, phi_k=-math.atan2(b1, a1),
                  phi_e=v["error_phase"], b=1.0)
    i1, i2 = sp.inertia
    m_red = reduced_mass(i1, i2, r_b, MESH.wheel.base_radius, 0.016)
    return _user_pair(params, per_rpm=19 * 2.0 * math.pi / 60.0 / omega_n, per_nm=per_nm,
                      omega_n=omega_n, m_red=m_red, k0=k0, **extra)


def test_the_user_pair_gives_the_spur_pairs_dynamic_factor_to_round_off():
    sp = _spur_pair()
    user = _scaled(sp)
    omega_n = user.time_scale
    rpm = np.array([3000.0, 9000.0, 14000.0, 17000.0, 20000.0])
    torques = [20.0, 200.0]
    a = dynamic_factor_sweep(sp, rpm, torques, geardyn.RunSettings(
        transient=0.02, samples=8, steps_per_period=128), **ACCURACY)
    u = dynamic_factor_sweep(user, rpm, torques, geardyn.RunSettings(
        transient=0.02 * omega_n, samples=8, steps_per_period=128), **ACCURACY)
    # contact lost and regained, back flanks struck, a period-3 response: the nonlinear range
    assert {"none", "single", "double"} <= set(a["contact"].values.ravel())
    assert 3 in a["period"].values
    for name in ("contact", "period", "iso_range"):
        np.testing.assert_array_equal(u[name].values, a[name].values, err_msg=name)
    for name in ("dynamic_factor", "K_v", "resonance_ratio", "resonance_speed", "line_load",
                 "mesh_stiffness", "mesh_frequency"):
        np.testing.assert_allclose(u[name].values, a[name].values, rtol=1e-12, atol=0.0,
                                   err_msg=name)
    np.testing.assert_array_equal(u.attrs["natural_speeds"], a.attrs["natural_speeds"])
    for t in torques:  # the declared proportion: Fm per N m
        assert user.at_input_torque(t).input_torque == pytest.approx(t, rel=1e-15)
    assert check_model(user, run=False).ok


def test_in_contact_the_dynamic_factor_is_the_linear_oscillators():
    # kappa 0 and a mean load far above the response: u = x - b obeys u'' + 2 zeta u' + u =
    # Fm + Fa Omega^2 cos(Omega tau), amplitude |H| = Fa Omega^2 / |1 - Omega^2 + 2 i zeta
    # Omega|, mesh force u + 2 zeta u' peaking at Fm + |H| |1 + 2 i zeta Omega|
    zeta, Fa, omega_n, per_nm = 0.1, 0.02, 2.0e4, 0.01
    per_rpm = 19 * 2.0 * math.pi / 60.0 / omega_n
    user = _user_pair(dict(Omega=1.0, zeta=zeta, kappa=0.0, Fm=2.0, Fa=Fa, phi_k=0.0,
                           phi_e=0.0, b=1.0), per_rpm=per_rpm, per_nm=per_nm,
                      omega_n=omega_n, m_red=0.01, k0=3e8)
    om = np.array([0.5, 0.8, 1.2, 1.6])
    torques = np.array([200.0, 400.0])
    ds = dynamic_factor_sweep(user, om / per_rpm, torques, geardyn.RunSettings(
        transient=300.0, samples=20, steps_per_period=256), **ACCURACY)
    H = Fa * om**2 / np.abs(1.0 - om**2 + 2j * zeta * om)
    for j, t in enumerate(torques):
        fm = t * per_nm
        assert list(ds["contact"].values[j, :, 0]) == ["none"] * om.size
        np.testing.assert_allclose(ds["dynamic_factor"].values[j, :, 0],
                                   (fm + H * np.abs(1.0 + 2j * zeta * om)) / fm, rtol=1e-5)
    # the natural frequency's input speed: omega_n / (2 pi) Hz over the mesh's 19 teeth
    np.testing.assert_allclose(ds.attrs["natural_speeds"],
                               [round(omega_n / (2.0 * math.pi) * 60.0 / 19, 3)])


def test_a_user_model_without_the_declaration_is_refused_naming_it():
    user = _scaled(_spur_pair(), declare=False)
    assert not user.capabilities.dynamic_factor
    with pytest.raises(geardyn.ParameterError, match="dynamic_factor=DynamicFactorDeclaration"):
        dynamic_factor_sweep(user, [3000.0], None, **ACCURACY)
    with pytest.raises(geardyn.ParameterError, match="^dynamic_factor: .*declares no"):
        user.kv_groups(50.0)


def test_the_declaration_is_checked_naming_the_field():
    sp = _spur_pair()
    decl = _scaled(sp)._dynamic_factor
    with pytest.raises(geardyn.ParameterError, match="dynamic_factor.speed"):
        geardyn.DynamicFactorDeclaration(("Omega", 0.0), decl.torque, decl.groups,
                                         decl.natural_frequencies)
    with pytest.raises(geardyn.ParameterError, match="dynamic_factor.torque"):
        geardyn.DynamicFactorDeclaration(decl.speed, "Fm", decl.groups, decl.natural_frequencies)
    with pytest.raises(geardyn.ParameterError, match="dynamic_factor.time_scale"):
        geardyn.DynamicFactorDeclaration(decl.speed, decl.torque, decl.groups,
                                         decl.natural_frequencies, time_scale=-1.0)
    for bad, field in ((("speed", 1.0), "dynamic_factor.speed"),
                       (("cos_phi_k", 1.0), "dynamic_factor.speed")):  # unknown; derived
        spec = geardyn.DynamicFactorDeclaration(bad, decl.torque, decl.groups,
                                                decl.natural_frequencies)
        with pytest.raises(geardyn.ParameterError, match=field):
            _scaled(sp, dynamic_factor=spec)
    with pytest.raises(geardyn.ParameterError, match="static_forces"):
        _scaled(sp, static_forces=None)
    with pytest.raises(geardyn.ParameterError, match="meshes"):
        _scaled(sp, meshes=[("mesh", "x-b", "x+b")])
    far = geardyn.DynamicFactorDeclaration(
        decl.speed, decl.torque, lambda p, t: (KvMeshGroup("m", MESH, (1,), t, 0.01, 1.0, 1e8),),
        decl.natural_frequencies)
    with pytest.raises(geardyn.ParameterError, match=r"dynamic_factor.groups\['m'\].meshes"):
        _scaled(sp, dynamic_factor=far).kv_groups(50.0)
