"""PlanetaryGearSet.from_geometry: the coast (back) flank of the ISO 6336-1 waves.

``coast="mirror"`` (the default) gives the coast flank the drive wave mirrored about the coast
phase phi, K_coast(theta) = K_drive(2 pi phi - theta); ``coast="symmetric"`` the drive wave on
both flanks. Checked against: the drive series evaluated here at 2 pi phi - theta (the mirror
algebra, and the compiled kernel's stiffness at negative deflection, every mesh with its own
Parker & Lin phase); phi from the involute tooth thickness written out here; the potential-energy
tables' own coast flank (computed there contact by contact), which fixes the mirror and phase
conventions; a static equilibrium solved here from the kernel's right-hand side at frozen mesh
phases against -(b + F / k_coast) from the torque balance; the one-flank set built directly from
the waves (what from_geometry built before it had a coast flank) bitwise; the study path against
the API bitwise.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import fsolve

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears.potential_energy import coast_phase
from geardyn.models import planetary_kernels as pk
from geardyn.models.planetary_stiffness import flank_series, mirrored
from test_planetary_pe import kernel_stiffness

M = geardyn.Member
MEMBERS = dict(
    sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8),
    ring=M(mass=2.35, inertia_over_r2=3.0, bearing_stiffness=1e8, torsional_stiffness=1e9),
    carrier=M(mass=5.43, inertia_over_r2=6.29, bearing_stiffness=1e8, torsional_stiffness=1e9),
    planet=M(mass=0.66, inertia_over_r2=0.61, bearing_stiffness=1e8))
KW = dict(sun_backlash="10 um", ring_backlash="10 um", sun_torque=100.0, mesh_damping=0.05)
H = 15


def shifted_stage(n_planets: int = 4) -> g.PlanetaryGeometry:
    """25/23/71, m 2 mm, sun and ring shifted (+0.2, +0.3) at a widened centre distance: both
    meshes have backlash and a coast phase away from 1/2 (0.52 and 0.48 mesh cycles)."""
    def gear(z: int, name: str, x: float, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, "2 mm", "20 deg", "20 mm", internal=internal, name=name,
                          profile_shift=x)
    return g.PlanetaryGeometry(gear(25, "sun", 0.2), gear(23, "planet", 0.0),
                               gear(71, "ring", 0.3, internal=True), n_planets=n_planets,
                               centre_distance=0.0484)


def example_stage() -> g.PlanetaryGeometry:
    """The example stage of docs/planetary.md (unshifted, tight: phi = 1/2)."""
    def gear(z: int, name: str, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, "2 mm", "20 deg", "20 mm", internal=internal, name=name)
    return g.PlanetaryGeometry(gear(25, "sun"), gear(23, "planet"),
                               gear(71, "ring", internal=True), n_planets=4)


def wave(a: np.ndarray, b: np.ndarray, x: np.ndarray) -> np.ndarray:
    """1 + sum a_h cos(h x) + b_h sin(h x), by direct sums."""
    h = np.arange(1, a.size + 1)
    return 1.0 + a @ np.cos(np.outer(h, x)) + b @ np.sin(np.outer(h, x))


def test_mirrored_series_is_the_wave_at_phi_minus_theta():
    """The mirrored coefficients evaluated at theta equal the original series evaluated at
    2 pi phi - theta (1e-12), for random coefficients and phases (also beyond a cycle)."""
    rng = np.random.default_rng(3)
    theta = np.linspace(-7.0, 7.0, 1001)
    for phi in (0.5, 0.4987912785903951, 0.3, 1.7, -0.25):
        a, b = rng.normal(0.0, 0.2, 12), rng.normal(0.0, 0.2, 12)
        am, bm = mirrored(a, b, phi)
        np.testing.assert_allclose(wave(am, bm, theta), wave(a, b, 2.0 * math.pi * phi - theta),
                                   rtol=0.0, atol=1e-12)
        assert np.max(np.abs(wave(am, bm, theta) - wave(a, b, theta))) > 0.1


@pytest.mark.parametrize("mesh", ["sun_mesh", "ring_mesh"])
def test_coast_phase_is_the_geometry_s_tooth_thickness(mesh):
    """phi = s_w1 / p_w1 of the pinion (the planet in the ring mesh) from the involute tooth
    thickness written out here, s_w = d_w (s / d + inv alpha - inv alpha_w), s = m (pi/2 +
    2 x tan alpha): the geometry alone, no stiffness method."""
    m = getattr(shifted_stage(), mesh)
    p, alpha, alpha_w = m.pinion, math.radians(20.0), m.operating_pressure_angle
    inv = lambda x: math.tan(x) - x  # noqa: E731
    s = 2e-3 * (math.pi / 2 + 2 * p.profile_shift * math.tan(alpha))
    d = 2e-3 * p.teeth
    d_w = d * math.cos(alpha) / math.cos(alpha_w)
    s_w = d_w * (s / d + inv(alpha) - inv(alpha_w))
    want = s_w / (math.pi * d_w / p.teeth)
    assert coast_phase(m) == pytest.approx(want, rel=1e-12)
    assert abs(want - 0.5) > 0.02  # shifted and widened: the phase is not the trivial 1/2


@pytest.mark.parametrize("held", ["ring", "sun"])
def test_kernel_coast_stiffness_is_the_mirrored_wave(held):
    """Deflected onto the coast flank every mesh's stiffness is the drive ISO series (computed
    here from the wave's coefficients) at 2 pi phi_g - x, phi_g the coast phase of its mesh
    group; onto the drive flank the series at x = s (theta - 2 pi gamma_n), s = -1 with the sun
    held (every mesh reads its wave backwards in time; tests/test_planetary_held_sun.py)."""
    geo = shifted_stage()
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=H, held=held,
                                                waveform_options={"transition": 0.05},
                                                **MEMBERS, **KW)
    assert gs.params[pk.TWO_FLANK] == 1.0 and gs.coast_flank == "mirror"
    assert gs.dataset_attrs() == {"mesh_stiffness_method": "iso", "mesh_coast_flank": "mirror"}
    phases = geo.phases_turning(-1 if held == "sun" else 1)
    gam = np.concatenate([phases.sun, phases.ring])
    assert len(set(np.round(gam, 9))) == 8  # every mesh its own phase: the check has teeth
    waves = {"sun": gs.stiffness_waveforms[0], "ring": gs.stiffness_waveforms[1]}
    phi = {"sun": coast_phase(geo.sun_mesh), "ring": coast_phase(geo.ring_mesh)}
    thetas = np.linspace(0.0, 2.0 * math.pi, 29)
    drive, coast = kernel_stiffness(gs, thetas, 1.0), kernel_stiffness(gs, thetas, -1.0)
    for m in range(8):
        grp = "sun" if m < 4 else "ring"
        w = waves[grp]
        x = (-1.0 if held == "sun" else 1.0) * (thetas - 2.0 * math.pi * gam[m])
        np.testing.assert_allclose(drive[:, m], w.mean * wave(*w.fourier(H), x), rtol=1e-10)
        want = w.mean * wave(*w.fourier(H), 2.0 * math.pi * phi[grp] - x)
        np.testing.assert_allclose(coast[:, m], want, rtol=1e-10)
    assert np.max(np.abs(coast / drive - 1.0)) > 0.3  # the flanks differ


def _jumps(table, var: str, kvar: str) -> float:
    """Sum of the magnitudes of the table's jumps (where the number of pairs in contact
    changes) [N/m]."""
    pc, k = table[var].values, table[kvar].values
    at = np.nonzero(pc != np.roll(pc, 1))[0]
    assert at.size >= 2
    return float(np.sum(np.abs(k[at] - k[at - 1])))


@pytest.mark.parametrize("stage", [example_stage, shifted_stage])
def test_mirror_of_the_pe_drive_series_is_the_pe_coast_series(stage):
    """The potential-energy drive table's series mirrored about coast_phase equals the series of
    the table's own coast flank (computed there from the coast contacts) within the sampling of
    the tables: a jump of J anywhere in a cell of 2 pi / n moves a relative coefficient pair by at
    most 2 J / (n k0). Mirrored about -phi instead (the other convention) it misses by more than
    five times that on the shifted stage."""
    geo = stage()
    n = 720
    tables = (g.potential_energy_stiffness(geo.sun_mesh, bore_radius=(0.012, 0.010), angles=n),
              g.potential_energy_stiffness(geo.ring_mesh, bore_radius=(0.010, 0.085), angles=n,
                                           ring_foundation="rigid"))
    for table, mesh in zip(tables, (geo.sun_mesh, geo.ring_mesh), strict=True):
        phi = coast_phase(mesh)
        assert table.attrs["coast_phase_cycles"] == phi
        drive = flank_series(table["mesh_stiffness"].values, 30)
        coast = flank_series(table["mesh_stiffness_coast"].values, 30)
        bound = 2.0 * (_jumps(table, "pairs_in_contact", "mesh_stiffness")
                       + _jumps(table, "pairs_in_contact_coast", "mesh_stiffness_coast")
                       ) / (n * drive.mean)
        assert coast.mean == pytest.approx(drive.mean, rel=bound)
        am, bm = mirrored(drive.a, drive.b, phi)
        err = np.hypot(am - coast.a, bm - coast.b)
        assert err.max() < bound, (err.max(), bound)
        if abs(phi - 0.5) > 0.02:
            aw, bw = mirrored(drive.a, drive.b, -phi)
            assert np.hypot(aw - coast.a, bw - coast.b).max() > 5 * bound


def _direct(geo: g.PlanetaryGeometry, harmonics: int, transition: float = 0.0,
            **kw) -> geardyn.PlanetaryGearSet:
    """The set built directly from the ISO waves, one stiffness on both flanks (what
    from_geometry built before the coast flank), ring held."""
    ws, wr = geo.waveforms(transition=transition)
    members = {k: m.__class__(**{**m.__dict__, "radius": r}) for (k, m), r in zip(
        MEMBERS.items(), (geo.sun.base_radius, geo.ring.base_radius,
                          geo.sun_mesh.centre_distance, geo.planet.base_radius), strict=True)}
    for grp, mesh in (("sun", geo.sun_mesh), ("ring", geo.ring_mesh)):
        kw.setdefault(f"{grp}_backlash",
                      0.5 * max(mesh.backlash, 0.0) * math.cos(mesh.operating_pressure_angle))
    return geardyn.PlanetaryGearSet(
        n_planets=geo.n_planets, planet_angles=list(geo.planet_angles),
        sun_pressure_angle=geo.sun_mesh.operating_pressure_angle,
        ring_pressure_angle=geo.ring_mesh.operating_pressure_angle,
        sun_mesh_stiffness=ws.mean, ring_mesh_stiffness=wr.mean,
        waveform={"sun": ws.fourier(harmonics), "ring": wr.fourier(harmonics)},
        harmonics=harmonics,
        sun_mesh_phase=[-2.0 * math.pi * float(x) for x in geo.phases.sun],
        ring_mesh_phase=[-2.0 * math.pi * float(x) for x in geo.phases.ring], **members, **kw)


@pytest.mark.parametrize("stage", [example_stage, shifted_stage])
def test_symmetric_is_the_one_flank_set_bitwise(stage):
    """coast="symmetric" builds bitwise the one-flank set of the waves (TWO_FLANK 0, so the
    kernels run main's one-flank arithmetic); the mirror differs only in the coast entries
    and the flag."""
    geo = stage()
    kw = {k: v for k, v in KW.items() if not k.endswith("backlash")}
    sym = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=H, coast="symmetric",
                                                 **MEMBERS, **kw)
    direct = _direct(geo, H, **kw)
    np.testing.assert_array_equal(sym.params, direct.params)
    assert sym.params[pk.TWO_FLANK] == 0.0 and sym.coast_flank == "symmetric"
    mirror = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=H, **MEMBERS, **kw)
    differ = np.nonzero(mirror.params != sym.params)[0]
    coast = {mirror.param_index(f"{m}_{c}{i}") for m in mirror.mesh_names
             for c in ("ac", "bc") for i in range(1, H + 1)}
    assert set(differ.tolist()) - coast == {pk.TWO_FLANK}
    assert len(set(differ.tolist()) & coast) > 8 * H
    changed = mirror.with_params(sun_backlash="5 um")  # the choice survives a rebuild
    assert changed.coast_flank == "mirror" and changed.params[pk.TWO_FLANK] == 1.0
    stiffer = mirror.with_params(sun_mesh_stiffness=2 * mirror.k_s)
    assert stiffer.k_s_coast == stiffer.k_s  # the mirror's mean follows the drive flank's


def test_pe_symmetric_puts_the_drive_table_on_both_flanks():
    """With the potential-energy method coast="symmetric" drops the coast table's series: the
    set is the one built with the drive table's series and no coast inputs."""
    geo = example_stage()
    opts = {"sun_bore_radius": "12 mm", "planet_bore_radius": "10 mm",
            "ring_rim_radius": "85 mm", "angles": 64}
    pe = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=H, stiffness="potential_energy",
                                                stiffness_options=opts, coast="symmetric",
                                                **MEMBERS, **KW)
    two = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=H, stiffness="potential_energy",
                                                 stiffness_options=opts, **MEMBERS, **KW)
    assert pe.params[pk.TWO_FLANK] == 0.0 and two.params[pk.TWO_FLANK] == 1.0
    assert pe.inputs["coast_waveform"] is None and pe.inputs["sun_coast_stiffness"] is None
    for grp in ("sun", "ring"):
        for x, y in zip(pe.inputs["waveform"][grp], two.inputs["waveform"][grp], strict=True):
            np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(kernel_stiffness(pe, np.linspace(0, 6, 5), -1.0),
                                  kernel_stiffness(pe, np.linspace(0, 6, 5), 1.0))
    assert pe.dataset_attrs()["mesh_coast_flank"] == "symmetric"


def test_bad_coast_names_the_field():
    for bad in ("mirrored", None, 1):
        with pytest.raises(ParameterError) as err:
            geardyn.PlanetaryGearSet.from_geometry(example_stage(), coast=bad, **MEMBERS)
        assert err.value.field == "coast"


def _static_mesh_deflections(gs: geardyn.PlanetaryGearSet, theta: float) -> np.ndarray:
    """Mesh deflections [m] of the equilibrium at the frozen mesh phase ``theta``: the
    positions where the kernel's accelerations vanish at rest, solved here (fsolve from the
    mean-stiffness static state)."""
    n = len(gs.dof_names())
    t, s, c = theta / gs.omega, math.sin(theta), math.cos(theta)

    def accel(X: np.ndarray) -> np.ndarray:
        dy = np.zeros(2 * n)
        pk.planetary_rhs(t, np.r_[X, np.zeros(n)], dy, gs.params, s, c)
        return dy[n:]

    x0 = gs.static_state()
    X, info, ok, msg = fsolve(accel, x0, xtol=1e-13, full_output=True)
    # converged to rounding: fsolve may stop with "not making good progress" (ier 5) there,
    # so the residual is what is checked (measured ~4e-15 of the start's)
    assert np.max(np.abs(accel(X))) <= 1e-11 * np.max(np.abs(accel(x0))), msg
    return gs.mesh_rows() @ X * gs.length_scale


@pytest.mark.parametrize("torque", [-100.0, 100.0])
def test_static_deflection_on_the_loaded_flank(torque):
    """One planet (its meshes carry F = T_s / r_s: the sun's and the planet's torque balance),
    the phase frozen: the mesh deflections are +-(b + F / k) with k the loaded flank's ISO
    stiffness at that phase, the mirrored wave's under a negative sun torque (from the wave's
    coefficients here at 2 pi phi - (theta - 2 pi gamma)); with coast="symmetric" the drive
    wave's, which is off."""
    geo = shifted_stage(n_planets=1)
    kw = dict(harmonics=H, sun_torque=torque, mesh_damping=0.05, sun_backlash="10 um",
              ring_backlash="5 um", mesh_frequency=1000.0)
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, **MEMBERS, **kw)
    sym = geardyn.PlanetaryGearSet.from_geometry(geo, coast="symmetric", **MEMBERS, **kw)
    F = abs(torque) / geo.sun.base_radius
    b = {"s": 10e-6, "r": 5e-6}
    gam = {"s": float(geo.phases.sun[0]), "r": float(geo.phases.ring[0])}
    waves = {"s": gs.stiffness_waveforms[0], "r": gs.stiffness_waveforms[1]}
    phi = {"s": coast_phase(geo.sun_mesh), "r": coast_phase(geo.ring_mesh)}
    worst = 0.0
    for theta in np.linspace(0.0, 2.0 * math.pi, 7, endpoint=False):
        want = []
        for m in gs.mesh_names:
            w, x = waves[m[0]], theta - 2.0 * math.pi * gam[m[0]]
            arg = 2.0 * math.pi * phi[m[0]] - x if torque < 0 else x
            k = w.mean * wave(*w.fourier(H), np.array([arg]))[0]
            want.append(math.copysign(b[m[0]] + F / k, torque))
        got = _static_mesh_deflections(gs, float(theta))
        np.testing.assert_allclose(got, want, rtol=1e-8)
        other = _static_mesh_deflections(sym, float(theta))
        worst = max(worst, float(np.max(np.abs(other / np.array(want) - 1.0))))
    assert (worst > 0.05) == (torque < 0)  # only the coast flank tells mirror from symmetric


def _study_text(coast: str | None) -> str:
    text = (Path(geardyn.__file__).parent / "studies" / "planetary_example.toml").read_text()
    if coast is None:
        return text
    return text.replace("transition = 0.05", f"transition = 0.05\ncoast = \"{coast}\"", 1)


@pytest.mark.parametrize("coast", [None, "mirror", "symmetric"])
def test_study_coast_field_is_the_api_bitwise(coast):
    """[params.geometry] coast (default "mirror") builds bitwise the set from_geometry builds
    with that choice; a saved study keeps it; a bad value names params.geometry.coast."""
    from geardyn.io import load_study
    from geardyn.io.toml import study_to_toml
    from geardyn.study import build_model

    study = load_study(_study_text(coast))
    gs = build_model(study)
    mem = dict(sun=M(0.31, 0.17, 1e8), planet=M(0.26, 0.15, 1e8),
               ring=M(0.67, 0.86, 1e8, 1e9), carrier=M(1.5, 1.0, 1e8, 1e9))
    api = geardyn.PlanetaryGearSet.from_geometry(
        example_stage(), harmonics=15, waveform_options={"transition": 0.05},
        coast=coast or "mirror", sun_backlash="10 um", ring_backlash="10 um",
        mesh_damping=0.03, modal_damping=0.02, sun_torque="20 N m", **mem)
    np.testing.assert_array_equal(gs.params, api.with_params(Omega=gs.omega).params)
    assert gs.coast_flank == (coast or "mirror")
    assert gs.params[pk.TWO_FLANK] == (0.0 if coast == "symmetric" else 1.0)
    again = build_model(load_study(study_to_toml(study)))
    np.testing.assert_array_equal(again.params, gs.params)


def test_study_bad_coast_names_the_field():
    from pydantic import ValidationError

    from geardyn.io import load_study

    with pytest.raises(ValidationError) as err:
        load_study(_study_text("both"))
    assert err.value.errors()[0]["loc"] == ("params", "geometry", "coast")
