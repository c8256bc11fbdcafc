"""PlanetaryGearSet.from_geometry: the gear set built from a geardyn.gears.PlanetaryGeometry.

The mesh stiffness the compiled kernel sees is compared with the geometry's stiffness wave
evaluated at the mesh's delay (end-to-end sign convention), the mesh phases with Parker & Lin's
rules written out here, the static sun mesh forces with the sun's torque balance over its base
radius (m z cos(alpha) / 2 computed here), and bad geometries with the field they name.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError

M = geardyn.Member
MEMBERS = dict(
    sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8),
    ring=M(mass=2.35, inertia_over_r2=3.0, bearing_stiffness=1e8, torsional_stiffness=1e9),
    carrier=M(mass=5.43, inertia_over_r2=6.29, bearing_stiffness=1e8, torsional_stiffness=1e9),
    planet=M(mass=0.66, inertia_over_r2=0.61, bearing_stiffness=1e8))
MODULE = 2e-3


def stage(zs: int, zp: int, zr: int, n: int = 4, **gear) -> g.PlanetaryGeometry:
    def gear_(z: int, name: str, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, MODULE, "20 deg", "20 mm", internal=internal, name=name, **gear)
    return g.PlanetaryGeometry(gear_(zs, "sun"), gear_(zp, "planet"),
                               gear_(zr, "ring", internal=True), n_planets=n)


def built(geometry: g.PlanetaryGeometry, **kw) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet.from_geometry(geometry, **{**MEMBERS, **kw})


def kernel_stiffness(gs: geardyn.PlanetaryGearSet, theta: float) -> np.ndarray:
    """k_m [N/m] of every mesh at mesh phase theta, from the compiled observable: at a state
    with unit (dimensionless) deflection in every mesh, at rest, no backlash or error, the mesh
    force is k_m(theta) L."""
    W = gs.mesh_rows()
    X = np.linalg.lstsq(W, np.ones(W.shape[0]), rcond=None)[0]
    assert np.allclose(W @ X, 1.0)
    out = np.empty(W.shape[0])
    tau = theta / gs.omega
    gs.kernel.observe(tau, np.r_[X, np.zeros_like(X)], out, gs.params, math.sin(theta),
                      math.cos(theta))
    return out / gs.length_scale


def test_kernel_stiffness_is_the_geometry_wave_delayed_by_the_phase():
    """Every mesh's stiffness at mesh phase theta is the geometry's wave at theta - 2 pi gamma_n:
    exactly its Fourier series, and pointwise the (ramped) wave itself."""
    geo = stage(25, 23, 71)
    gs = built(geo, harmonics=200, waveform_options={"transition": 0.05})
    w_sun, w_ring = geo.waveforms(transition=0.05)
    gam = np.concatenate([geo.phases.sun, geo.phases.ring])
    waves = [w_sun] * 4 + [w_ring] * 4
    assert len(set(np.round(gam[:4], 9))) == 4  # the phases differ: the check has teeth
    h = np.arange(1, 201)
    worst = 0.0
    for theta in np.linspace(0.0, 2 * math.pi, 37):
        k = kernel_stiffness(gs, theta)
        for m, (w, gm) in enumerate(zip(waves, gam, strict=True)):
            a, b = w.fourier(200, phase=gm)
            series = w.mean * (1.0 + a @ np.cos(h * theta) + b @ np.sin(h * theta))
            assert k[m] == pytest.approx(series, rel=1e-9)
            worst = max(worst, abs(k[m] - float(w(theta, gm))) / w.mean)
    assert worst < 0.02
    # the opposite sign convention would be far off
    k = kernel_stiffness(gs, 0.3)
    wrong = [float(w(0.3, -gm)) for w, gm in zip(waves, gam, strict=True)]
    assert np.max(np.abs(k - wrong)) / w_sun.mean > 0.2


def test_in_phase_set_has_equal_sun_mesh_phases():
    """Z_s = 24, Z_r = 72, N = 4: Z_s psi_n / 2 pi = 6 n is whole, every sun mesh in phase
    (and every ring mesh: 18 n), so all sun meshes get the same stiffness coefficients."""
    gs = built(stage(24, 24, 72))
    n = 4
    ph = np.mod(gs.mesh_phase, 2 * math.pi)
    ph[np.isclose(ph, 2 * math.pi)] = 0.0
    assert np.allclose(ph[:n], ph[0]) and np.allclose(ph[n:], ph[n])
    assert np.allclose(gs.fourier[:n], gs.fourier[0], atol=1e-12)
    assert np.allclose(gs.fourier[n:], gs.fourier[n], atol=1e-12)


def test_sequentially_phased_set_has_parker_lin_phases():
    """Z_s = 25, Z_r = 71, N = 4: gamma_sn = 25 (n - 1) / 4, gamma_rn = gamma_rs - 71 (n - 1) / 4
    (mod 1), gamma_rs = 0 for an odd, unshifted planet (Z_p = 23); the model's phases are
    -2 pi gamma."""
    gs = built(stage(25, 23, 71))
    n = np.arange(4)
    want = np.concatenate([(25 * n / 4) % 1.0, (-71 * n / 4) % 1.0])
    got = (-gs.mesh_phase / (2 * math.pi)) % 1.0
    got[np.isclose(got, 1.0)] = 0.0
    assert np.allclose(got, want, atol=1e-12)
    assert np.allclose(want[:4], [0.0, 0.25, 0.5, 0.75])


def test_angles_stiffness_radii_and_static_forces_from_the_geometry():
    """Operating pressure angles, mean stiffnesses (ISO c_gamma_alpha b), radii; the static
    sun mesh forces balance the sun torque over the base radius m z cos(20 deg) / 2."""
    geo = stage(25, 23, 71)
    gs = built(geo, sun_torque=50.0)
    iso_s, iso_r = geo.stiffness()
    assert gs.k_s == pytest.approx(iso_s.mesh_stiffness, rel=1e-12)
    assert gs.k_r == pytest.approx(iso_r.mesh_stiffness, rel=1e-12)
    assert gs.alpha_s == pytest.approx(math.radians(20.0), rel=1e-9)  # tight, unshifted
    assert gs.alpha_r == pytest.approx(math.radians(20.0), rel=1e-9)
    r_bs = MODULE * 25 * math.cos(math.radians(20.0)) / 2
    assert gs.members["sun"].radius == pytest.approx(r_bs, rel=1e-12)
    assert gs.members["carrier"].radius == pytest.approx(MODULE * (25 + 23) / 2, rel=1e-12)
    assert gs.members["ring"].radius == pytest.approx(r_bs * 71 / 25, rel=1e-12)
    F = gs.static_mesh_forces()
    assert F[:4].sum() == pytest.approx(50.0 / r_bs, rel=1e-6)
    assert np.allclose(F[:4], F[0], rtol=1e-6)  # equally spaced: equal load sharing


def test_with_params_keeps_the_geometry():
    """A set built from geometry keeps its geometry and stiffness waves through with_params
    (a rebuild from its inputs) and lane_params, and the rebuilt set is what from_geometry
    builds with the changed input."""
    geo = stage(25, 23, 71)
    gs = built(geo, sun_torque=50.0)
    changed = gs.with_params(sun_backlash=2e-5)
    assert changed.geometry is geo and changed.stiffness_waveforms == gs.stiffness_waveforms
    assert np.array_equal(changed.params, built(geo, sun_torque=50.0, sun_backlash=2e-5).params)
    assert changed.with_params(sun_torque=10.0).geometry is geo
    assert gs.with_params(Omega=0.3).geometry is geo


def test_backlash_from_a_wider_centre_distance():
    """A stage built at a wider centre distance (the ring shifted out so that its mesh opens
    too): half the normal backlash of each mesh, j cos(alpha_w) / 2, unless given."""
    sun = g.SpurGear(25, MODULE, "20 deg", "20 mm", name="sun")
    planet = g.SpurGear(23, MODULE, "20 deg", "20 mm", name="planet")
    ring = g.SpurGear(71, MODULE, "20 deg", "20 mm", internal=True, name="ring",
                      profile_shift=0.05)
    geo = g.PlanetaryGeometry(sun, planet, ring, n_planets=4, centre_distance=0.04802)
    gs = built(geo)
    for m, mesh in ((0, geo.sun_mesh), (4, geo.ring_mesh)):
        assert mesh.backlash > 0
        want = 0.5 * mesh.backlash * math.cos(mesh.operating_pressure_angle)
        assert gs.backlash[m] == pytest.approx(want, rel=1e-12)
    assert gs.alpha_s > math.radians(20.0)
    assert np.all(built(geo, sun_backlash=1e-6).backlash[:4] == 1e-6)


def test_bad_geometry_and_inputs_name_the_field():
    with pytest.raises(ParameterError) as e:  # 6 planets: tip circles overlap
        stage(25, 23, 71, n=6)
    assert e.value.field == "planet_angles" and "collide" in str(e.value)
    with pytest.raises(ParameterError) as e:  # stub teeth: too short a path of contact
        stage(25, 23, 71, addendum=0.5)
    assert e.value.field == "contact_ratio"
    geo = stage(25, 23, 71)
    with pytest.raises(ParameterError) as e:
        built(geo, sun_mesh_stiffness=1e8)
    assert e.value.field == "sun_mesh_stiffness"
    with pytest.raises(ParameterError) as e:
        built(geo, sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8, radius=0.05))
    assert e.value.field == "sun.radius"
    with pytest.raises(ParameterError) as e:
        geardyn.PlanetaryGearSet.from_geometry("not a geometry", **MEMBERS)
    assert e.value.field == "geometry"


@pytest.mark.parametrize("n", [0, 33, 3.0, True])
def test_the_gear_formulas_take_the_planet_counts_the_set_takes(n):
    """equally_spaced, mesh_phases and planetary_reduced_masses refuse a planet count outside
    1..32 (or not whole) naming the field, as PlanetaryGearSet does."""
    with pytest.raises(ParameterError) as model:
        geardyn.PlanetaryGearSet(n_planets=n, sun_mesh_stiffness=1e8, ring_mesh_stiffness=1e8,
                                 **MEMBERS)
    with pytest.raises(ParameterError) as spaced:
        g.equally_spaced(n)
    with pytest.raises(ParameterError) as masses:
        g.planetary_reduced_masses(1e-3, 1e-4, 0.02, 0.02, n, 0.02)
    assert model.value.field == spaced.value.field == masses.value.field == "n_planets"
    if isinstance(n, int) and not isinstance(n, bool):
        with pytest.raises(ParameterError) as angles:  # the count of given angles too
            g.mesh_phases(25, 71, np.zeros(n))
        assert angles.value.field == "planet_angles"


def test_the_gear_formulas_take_32_planets():
    """32 planets (the largest count): 32 angles 2 pi k / 32, and the sun-planet reduced mass
    m_P* m_S* / (32 m_P* + m_S*) per mm of face width computed here."""
    assert np.array_equal(g.equally_spaced(32), 2.0 * np.pi * np.arange(32) / 32)
    ms, mp = 1e-3 / 0.02 ** 2, 1e-4 / 0.03 ** 2
    sun, ring = g.planetary_reduced_masses(1e-3, 1e-4, 0.02, 0.03, np.int64(32), 0.02)
    assert math.isclose(sun, mp * ms / (32 * mp + ms) / 20.0, rel_tol=1e-15)
    assert math.isclose(ring, mp / 20.0, rel_tol=1e-15)
    assert len(g.mesh_phases(32, 96, 32).sun) == 32


def test_builtin_study_builds_from_its_geometry():
    """planetary_example: [params.geometry] gives the same set as from_geometry here; a
    mesh stiffness next to the geometry, or none without it, names params.<field>."""
    from geardyn.io import load_study
    from geardyn.study import build_model

    path = Path(geardyn.__file__).parent / "studies" / "planetary_example.toml"
    text = path.read_text()
    gs = build_model(load_study(path))
    geo = stage(25, 23, 71)
    w_sun, w_ring = geo.waveforms(transition=0.05)
    assert gs.k_s == pytest.approx(w_sun.mean, rel=1e-12)
    assert gs.k_r == pytest.approx(w_ring.mean, rel=1e-12)
    assert np.allclose(gs.mesh_phase[:4], -2 * math.pi * geo.phases.sun)
    assert np.all(gs.backlash == 1e-5) and gs.fourier.shape == (8, 30)
    bad = text.replace("[params]\n", "[params]\nsun_mesh_stiffness = 1e8\n", 1)
    with pytest.raises(ParameterError) as e:
        build_model(load_study(bad))
    assert e.value.field == "params.sun_mesh_stiffness"
    start = text.index("[params.geometry]")
    without = text[:start] + text[text.index("[params.sun]"):]
    with pytest.raises(ParameterError) as e:
        build_model(load_study(without))
    assert e.value.field == "params.sun_mesh_stiffness"


def test_saved_study_round_trips():
    """A study written back (every field, defaults included) builds the same set."""
    from geardyn.io import load_study
    from geardyn.io.toml import study_to_toml
    from geardyn.study import build_model

    study = load_study(Path(geardyn.__file__).parent / "studies" / "planetary_example.toml")
    again = build_model(load_study(study_to_toml(study)))
    assert np.array_equal(again.params, build_model(study).params)


@pytest.mark.parametrize(("teeth", "torque", "force"), [
    ((25, 23, 71), {4, 8}, {1, 3, 5, 7}),   # sequentially phased: Z_s = 25, N = 4
    ((24, 24, 72), set(range(1, 9)), set()),  # in phase: every harmonic is rotational
])
def test_net_sun_excitation_keeps_the_harmonics_the_phasing_rules_allow(teeth, torque, force):
    """Equal deflection in every mesh: the net torque and force on the sun from the kernel's
    mesh forces over one mesh cycle hold harmonic l of the mesh frequency only where the rules
    say (Parker 2000): torque where l Z_s / N is whole, force where l Z_s = +-1 (mod N)."""
    gs = built(stage(*teeth), harmonics=12, waveform_options={"transition": 0.05})
    names = gs.dof_names()
    sun = [names.index(d) for d in ("x_s", "y_s", "u_s")]
    W = gs.mesh_rows()[:4, sun]  # the sun meshes' rows on the sun's coordinates
    theta = np.linspace(0.0, 2 * math.pi, 64, endpoint=False)
    net = np.array([W.T @ kernel_stiffness(gs, th)[:4] for th in theta])  # (64, 3)
    spec = np.abs(np.fft.rfft(net, axis=0)) / len(theta)
    scale = spec[1:9].max()
    for ell in range(1, 9):
        f_amp = math.hypot(spec[ell, 0], spec[ell, 1])
        assert (spec[ell, 2] > 1e-6 * scale) == (ell in torque), ell
        assert (f_amp > 1e-6 * scale) == (ell in force), ell


def test_builtin_study_sweep_finds_periods_and_contact_loss(tmp_path):
    """Regression: ``geardyn bifurcation planetary_example`` with the study's [run] settings
    found no period at any point (a 300 tau transient against bearing modes damped ~1e-4).
    With the study's settings (transient in forcing periods, by convergence; modal damping)
    every point of a few Omega values gets a period, and the meshes lose contact near 0.8."""
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.io.netcdf import load_dataset

    out = tmp_path / "b.nc"
    r = CliRunner().invoke(app, ["bifurcation", "planetary_example", "--param", "Omega",
                                 "--range", "0.3:0.8:3", "--quiet", "--out", str(out)])
    assert r.exit_code == 0, r.output
    ds = load_dataset(out)
    assert np.all(ds["period"].values >= 1), ds["period"].values
    assert ds.attrs["converge"] == 1e-6
    assert ds.attrs["transient"] >= 20 * 2 * math.pi / 0.3
    assert np.any(ds["contact"].sel(Omega=0.8).values != "none")


def _willis_mesh_frequency(zs: int, zr: int, held: str, input_rpm: float) -> float:
    """Mesh frequency [rad/s] by the Willis equation z_s w_s + z_r w_r = (z_s + z_r) w_c with
    the held member still and the input (the sun; the carrier when the sun is held) at
    ``input_rpm``: z_s times the sun's speed relative to the carrier."""
    w_in = input_rpm * 2 * math.pi / 60
    if held == "ring":
        w_s, w_c = w_in, zs * w_in / (zs + zr)
    elif held == "carrier":
        w_s, w_c = w_in, 0.0
    else:  # sun held, carrier input
        w_s, w_c = 0.0, w_in
    return zs * abs(w_s - w_c)


@pytest.mark.parametrize("held", ["ring", "carrier", "sun"])
def test_input_speed_sets_the_mesh_frequency_by_the_kinematics(held):
    """input_speed [rpm] (a number or a unit string) sets the mesh frequency of the Willis
    equation for the held member; lane_params sweeps it; a set without geometry refuses it."""
    gs = built(stage(25, 23, 71), held=held)
    want = _willis_mesh_frequency(25, 71, held, 3000.0)
    for value in (3000.0, "3000 rpm", f"{3000 * 2 * math.pi / 60!r} rad/s"):
        lane = gs.with_params(input_speed=value)
        assert lane.omega * lane.time_scale == pytest.approx(want, rel=1e-12)
        assert lane.input_speed == pytest.approx(3000.0, rel=1e-12)
    P = gs.lane_params("input_speed", [1000.0, 3000.0])
    assert P[:, gs.omega_index] * gs.time_scale == pytest.approx(
        [_willis_mesh_frequency(25, 71, held, 1000.0), want], rel=1e-12)
    assert gs.input_member == ("carrier" if held == "sun" else "sun")
    assert "input_speed" in gs.physical_names
    plain = geardyn.PlanetaryGearSet(**MEMBERS, n_planets=4, sun_mesh_stiffness=3e8,
                                     ring_mesh_stiffness=4e8)
    assert "input_speed" not in plain.physical_names
    with pytest.raises(ParameterError) as e:
        plain.with_params(input_speed=3000.0)
    assert e.value.field == "input_speed"
    with pytest.raises(ParameterError) as e:
        gs.with_params(input_speed=-1.0)
    assert e.value.field == "input_speed"


def test_study_held_and_input_speed_sweep_axis_units(tmp_path):
    """[params].held sets the kinematics (only with [params.geometry]); the CLI sweeps
    input_speed [rpm] and the dataset's axis carries its unit, as a mesh_frequency axis its."""
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.io import load_study
    from geardyn.io.netcdf import load_dataset
    from geardyn.study import build_model

    path = Path(geardyn.__file__).parent / "studies" / "planetary_example.toml"
    text = path.read_text()
    assert build_model(load_study(path)).held == "ring"
    carrier = text.replace("[params]\n", '[params]\nheld = "carrier"\n', 1)
    assert build_model(load_study(carrier)).mesh_frequency_per_input_speed() == 25.0
    start = text.index("[params.geometry]")
    without = text[:start] + text[text.index("[params.sun]"):]
    without = without.replace("[params]\n", '[params]\nheld = "ring"\nsun_mesh_stiffness = 3e8\n'
                              "ring_mesh_stiffness = 4e8\n", 1)
    with pytest.raises(ParameterError) as e:
        build_model(load_study(without))
    assert e.value.field == "params.held"
    for param, rng, unit in (("input_speed", "3000:6000:2", "rpm"),
                             ("mesh_frequency", "5000:9000:2", "rad/s")):
        out = tmp_path / f"{param}.nc"
        r = CliRunner().invoke(app, ["bifurcation", "planetary_example", "--param", param,
                                     "--range", rng, "--transient", "20", "--samples", "2",
                                     "--quiet", "--out", str(out)])
        assert r.exit_code == 0, r.output
        ds = load_dataset(out)
        assert ds[param].attrs["units"] == unit
        assert list(ds[param].values) == [float(v) for v in rng.split(":")[:2]]


def test_frequency_response_axes_of_a_set_from_geometry():
    """The frc dataset's physical axes of a set from geometry: mesh frequency [Hz] and input
    (sun) speed [rpm] by the Willis kinematics (ring held); without geometry only the first."""
    from geardyn.analysis.frc import physical_axes

    gs = built(stage(25, 23, 71))
    om = np.array([0.2, 0.5])
    axes = physical_axes(gs, om)
    w = om * gs.time_scale
    assert axes["mesh_frequency"][0] == pytest.approx(w / (2 * math.pi), rel=1e-12)
    assert axes["mesh_frequency"][1]["units"] == "Hz"
    rpm = [3000.0 * w_m / _willis_mesh_frequency(25, 71, "ring", 3000.0) for w_m in w]
    assert axes["input_speed"][0] == pytest.approx(rpm, rel=1e-12)
    assert axes["input_speed"][1]["units"] == "rpm"
    plain = geardyn.PlanetaryGearSet(**MEMBERS, n_planets=4, sun_mesh_stiffness=3e8,
                                     ring_mesh_stiffness=4e8)
    assert set(physical_axes(plain, om)) == {"mesh_frequency"}


@pytest.mark.parametrize(("old", "new", "fragments"), [
    ("teeth = 23", "teeth = 3", ("params.geometry.planet.teeth", ">= 5", "3")),
    ("n_planets = 4", "n_planets = 7", ("params.planet_angles", "collide")),
    ("teeth = 71", "teeth = 70", ("params.geometry.ring.teeth", "Z_s + 2 Z_p = 71", "70")),
    ("teeth = 71", "teeth = 71\nprofile_shift = 0.5",
     ("params.geometry.ring.profile_shift", "does not mesh")),
    ('module = "2 mm"', 'module = "-2 mm"', ("params.geometry.sun.module", "> 0")),
])
def test_bad_geometry_in_a_study_is_a_one_line_cli_error(tmp_path, old, new, fragments):
    """A study file with impossible gear geometry (too few teeth, colliding planets, a ring
    that does not fit the sun and planets, a negative module): exit status 2 and one line
    naming the field, before anything runs."""
    from typer.testing import CliRunner

    from geardyn.cli.main import app

    text = (Path(geardyn.__file__).parent / "studies" / "planetary_example.toml").read_text()
    assert old in text
    study = tmp_path / "bad.toml"
    study.write_text(text.replace(old, new, 1))
    r = CliRunner().invoke(app, ["bifurcation", str(study), "--range", "1000:2000:2",
                                 "--quiet"])
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert all(f in lines[0] for f in fragments), lines[0]


def _flank_at(gear: g.SpurGear, radius: float) -> tuple[float, np.ndarray]:
    """The upper (counter-clockwise) flank of a tooth centred at angle 0, drawn here as an
    involute unwound from the base circle: its polar angle at ``radius`` and its outward unit
    normal there (by finite differences, pointing away from the tooth)."""
    from scipy.optimize import brentq

    rb, r0 = gear.base_radius, gear.module * gear.teeth / 2
    s0 = gear.module * (math.pi / 2 + 2 * gear.profile_shift * math.tan(gear.pressure_angle))
    t0 = math.sqrt(r0**2 - rb**2) / rb
    b = s0 / (2 * r0) + t0 - math.atan(t0)  # half the tooth's angle at the base circle

    def q(t: float) -> np.ndarray:  # unwound clockwise from the base circle at angle b
        return rb * _rotated(np.array([math.cos(t) + t * math.sin(t),
                                       t * math.cos(t) - math.sin(t)]), b)

    t = brentq(lambda t: np.linalg.norm(q(t)) - radius, 0.0, 5.0)
    p, d = q(t), (q(t + 1e-7) - q(t - 1e-7)) / 2e-7
    n = np.array([d[1], -d[0]]) / np.linalg.norm(d)
    if np.dot(n, np.array([-p[1], p[0]])) < 0:  # away from the tooth: towards larger angles
        n = -n
    return math.atan2(p[1], p[0]), n


def _rotated(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


@pytest.mark.parametrize(("teeth", "shifts"), [
    ((25, 23, 71), (-0.2, 0.2, 0.2)),   # shifted teeth, both pitch radii equal
    ((25, 23, 72), (-0.4, 0.4, 0.0)),   # unequal operating pitch radii of the planet
    ((25, 23, 71), (0.0, 0.0, 0.0)),
])
def test_sun_ring_phase_by_tooth_construction(teeth, shifts):
    """gamma_rs from the planet's teeth drawn here: the planet (centre (a, 0), sun at the origin)
    turns clockwise as the sun drives counter-clockwise; at the sun-side pitch point (angle pi,
    operating pitch radius) the sun pushes the planet tooth's flank whose outward normal points
    to -y, and at the ring-side one (angle 0) the planet pushes the ring with its flank whose
    normal points to -y (its direction of motion). The delay from the one flank's passage to the
    other's, in planet tooth pitches, is gamma_rs."""
    zs, zp, zr = teeth
    gears = [g.SpurGear(z, MODULE, "20 deg", "20 mm", profile_shift=x, internal=i, name=nm)
             for z, x, i, nm in zip(teeth, shifts, (False, False, True), ("sun", "planet", "ring"),
                                    strict=True)]
    geo = g.PlanetaryGeometry(*gears, n_planets=1)
    planet = gears[1]
    r_sun_side = geo.sun_mesh.operating_pitch_radii[1]
    r_ring_side = geo.ring_mesh.operating_pitch_radii[0]

    def loaded_centre(radius: float, at: float) -> float:
        """The centre angle of the tooth whose loaded (-y facing) flank is at angle ``at``."""
        h, n = _flank_at(planet, radius)
        for side in (1, -1):  # upper flank at `at` (centre at - h), or the mirrored lower one
            centre = at - side * h
            normal = _rotated(np.array([n[0], side * n[1]]), centre)
            if normal[1] < 0:
                return centre
        raise AssertionError("no flank faces -y")

    c_sun = loaded_centre(r_sun_side, math.pi)
    c_ring = loaded_centre(r_ring_side, 0.0)
    # tooth centres c0 + 2 pi k / Z_p - beta: the ring-side passage comes (c_sun - c_ring) later
    gamma = ((c_sun - c_ring) * zp / (2 * math.pi)) % 1.0
    assert min(abs(gamma - geo.phases.sun_ring), 1 - abs(gamma - geo.phases.sun_ring)) < 1e-9
    if shifts != (0.0, 0.0, 0.0):
        assert 1e-3 < geo.phases.sun_ring < 1 - 1e-3 and abs(geo.phases.sun_ring - 0.5) > 1e-3


def _willis_speeds(zs: int, zr: int, held: str) -> dict[str, float]:
    """Speeds [rad/s] of sun, ring and carrier with ``held`` still and the input (the sun; the
    carrier when the sun is held) at +1 in the sense of psi: Z_s w_s + Z_r w_r = (Z_s + Z_r) w_c."""
    if held == "ring":
        return {"sun": 1.0, "ring": 0.0, "carrier": zs / (zs + zr)}
    if held == "carrier":
        return {"sun": 1.0, "ring": -zs / zr, "carrier": 0.0}
    return {"sun": 0.0, "ring": (zs + zr) / zr, "carrier": 1.0}


@pytest.mark.parametrize("held", ["ring", "carrier", "sun"])
def test_mesh_phases_follow_the_teeth_for_every_held_member(held):
    """Unequally spaced planets (25/23/71, psi = 0, 90, 187.5, 277.5 deg): in the carrier frame
    the sun's teeth turn at w_s - w_c and the ring's at w_r - w_c (Willis, the input turning in
    the sense of psi, as the model's kinematic carrier speed does); a mesh event is a tooth
    passing the planet's direction psi_n, and mesh n's phase is the delay of its first event
    after planet 1's, in mesh cycles. With the sun held the sun turns backwards relative to the
    carrier, so its phases are -Z_s psi_n / 2 pi, not Z_s psi_n / 2 pi."""
    zs, zr = 25, 71
    psi = np.radians([0.0, 90.0, 187.5, 277.5])
    even = stage(zs, 23, zr)
    geo = g.PlanetaryGeometry(even.sun, even.planet, even.ring, planet_angles=tuple(psi))
    gs = built(geo, held=held, carrier_speed="kinematic")
    w = _willis_speeds(zs, zr, held)
    w_mesh = zs * abs(w["sun"] - w["carrier"])
    assert zr * abs(w["ring"] - w["carrier"]) == pytest.approx(w_mesh)
    # the model's carrier turns as assumed here: carrier speed / mesh frequency
    assert gs.carrier_speed_ratio == pytest.approx(w["carrier"] / w_mesh, abs=1e-15)

    def first_event(teeth: int, rate: float, offset: float) -> np.ndarray:
        # tooth j at offset + rate t + 2 pi j / teeth; t in mesh cycles (one pitch per cycle)
        return ((psi - offset) * np.sign(rate) / (2 * np.pi / teeth)) % 1.0

    sun = first_event(zs, w["sun"] - w["carrier"], 0.123)
    ring = first_event(zr, w["ring"] - w["carrier"], 0.456)
    model = (-gs.mesh_phase / (2 * math.pi)) % 1.0
    n = len(psi)

    def close(a: np.ndarray, b: np.ndarray) -> bool:
        d = np.abs((a - b) % 1.0)
        return bool(np.all(np.minimum(d, 1.0 - d) < 1e-9))

    assert close(model[:n], (sun - sun[0]) % 1.0)
    assert close(model[n:] - model[n], (ring - ring[0]) % 1.0)
    assert not close(model[:n], (-(sun - sun[0])) % 1.0)  # the other sense differs here
