"""PlanetaryGearSet.from_geometry with a tooth fault: the forcing period a revolution of the faulty
gear relative to the carrier.

Checks: a zero-size fault gives the one-mesh-cycle set (the compiled stiffness at the same times
to round-off, the same natural frequencies, a short simulation); the faulty meshes' compiled
stiffness against potential-energy tables computed here with the fault on the tooth that the
carrier-frame kinematics (worked out here from the planet angles) put in contact, the healthy
meshes untouched; the fault felt once per revolution at the faulty tooth's contact (the peak of
the quasi-static mesh deflection); bad fault specifications named by their field.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from test_planetary_pe import BORES, KW, MEMBERS, kernel_stiffness, stage

CRACK = dict(depth="1.5 mm", angle="45 deg")


def pe_set(geo, faults=(), harmonics: int = 9, angles: int = 120, **kw):
    return geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=harmonics, stiffness="potential_energy",
        stiffness_options={**BORES, "angles": angles}, faults=faults,
        **{**MEMBERS, **KW, **kw})


@pytest.fixture(scope="module")
def geo():
    return stage()


@pytest.mark.parametrize("gear", ["sun", "planet2", "ring"])
def test_zero_size_fault_is_the_one_mesh_cycle_set(geo, gear):
    healthy = pe_set(geo)
    zero = pe_set(geo, [g.RootCrack(depth=0.0, gear=gear, tooth=3)])
    z = {"sun": 25, "planet2": 23, "ring": 71}[gear]
    assert zero.mesh_order == z and zero.fourier.shape[1] == 2 * 9 * z
    theta = np.linspace(0.0, 2.0 * math.pi * z, 61)  # mesh phase over the revolution
    want = kernel_stiffness(healthy, theta)
    got = kernel_stiffness(zero, theta / z)
    np.testing.assert_allclose(got, want, rtol=1e-11)
    np.testing.assert_allclose(zero.natural_frequencies(), healthy.natural_frequencies(),
                               rtol=1e-12)
    assert zero.mesh_frequency == pytest.approx(healthy.mesh_frequency, rel=1e-14)
    assert zero.input_speed == pytest.approx(healthy.input_speed, rel=1e-14)


def test_zero_size_fault_simulates_as_the_one_mesh_cycle_set(geo):
    healthy = pe_set(geo).with_params(input_speed=3000.0)
    zero = pe_set(geo, [g.RootCrack(depth=0.0, gear="sun", tooth=3)]).with_params(
        input_speed=3000.0)
    n = 64
    a = geardyn.simulate(healthy, run=geardyn.RunSettings(transient=0.0, samples=25,
                                                          steps_per_period=n))
    b = geardyn.simulate(zero, run=geardyn.RunSettings(transient=0.0, samples=1,
                                                       steps_per_period=25 * n))
    assert a.sizes["time"] == b.sizes["time"]
    np.testing.assert_allclose(b["time"].values, a["time"].values, rtol=1e-12)
    for name in healthy.observable_names:
        scale = float(np.max(np.abs(a[name].values)))
        np.testing.assert_allclose(b[name].values, a[name].values, rtol=0.0,
                                   atol=1e-8 * scale)


def test_kinematic_carrier_speed_follows_the_mesh_frequency(geo):
    """With the carrier's gyroscopic terms tied to the input speed, a zero-size fault keeps the
    carrier speed and the rotating-frame frequencies of the one-mesh-cycle set."""
    kw = dict(carrier_speed="kinematic", carrier=MEMBERS["carrier"])
    healthy = pe_set(geo, **kw).with_params(input_speed=4000.0)
    zero = pe_set(geo, [g.RootCrack(depth=0.0, gear="planet1", tooth=0)], **kw).with_params(
        input_speed=4000.0)
    assert zero.carrier_omega() == pytest.approx(healthy.carrier_omega(), rel=1e-14)
    assert zero.carrier_omega() == pytest.approx(
        4000.0 * 2.0 * math.pi / 60.0 * 25 / (25 + 71), rel=1e-12)  # ring held, sun input
    np.testing.assert_allclose(zero.natural_frequencies(), healthy.natural_frequencies(),
                               rtol=1e-10)
    assert zero.param_attrs("Omega")["long_name"] == "forcing frequency / time_scale"


def _passage(geo, gear: str, tooth: int, mesh: int, sun_turns: int = 1) -> float:
    """The mesh cycle [0, Z_f) at which ``tooth`` of ``gear`` passes the pitch point of mesh
    ``mesh`` (0 .. N-1 sun-planet, N .. 2N-1 ring-planet), from the carrier-frame kinematics:
    the sun turns in the sense of psi by 2 pi / Z_s a mesh cycle, the ring against it by
    2 pi / Z_r (``sun_turns`` -1: the other way round, the sun held and the carrier driven);
    sun tooth 0 sits at psi_1 at c = 0. A ring tooth is numbered by its clockwise-facing flank
    (the planet-ring table's drive flank), ring tooth 0's passing psi_1 first in [0, 1), at
    gamma_T: a planet tooth's counter-clockwise-facing flank at the sun-side pitch point at
    c = 0 reaches the ring side after Z_p sigma (pi - (psi_r - psi_s) / 2) / 2 pi mesh cycles
    (sigma = -s the planet's sense, psi its angular thickness at each operating pitch radius).
    For the ring the time returned is that of the table's pair of the cracked tooth, whose
    clockwise-facing flank passes s (1 - phi_r) mesh cycles earlier (phi_r the ring mesh's
    coast phase: the table's coast flank of wheel tooth j passes 1 - phi_r before its drive
    pair; a table read forwards is the ring mesh's mirror image, s = +1, or it is read
    backwards, s = -1)."""
    from geardyn.gears.potential_energy import coast_phase

    n = geo.n_planets
    psi = sun_turns * (np.asarray(geo.planet_angles) - geo.planet_angles[0])
    if gear == "sun":  # tooth j sits at angle 2 pi (c - j) / Z_s
        zs = geo.sun.teeth
        return (tooth + zs * psi[mesh] / (2.0 * math.pi)) % zs
    planet = geo.planet
    thick_s = planet.angular_thickness(geo.sun_mesh.operating_pitch_radii[1])
    thick_r = planet.angular_thickness(geo.ring_mesh.operating_pitch_radii[0])
    gamma_t = (planet.teeth * -sun_turns * (math.pi - 0.5 * (thick_r - thick_s))
               / (2.0 * math.pi)) % 1.0
    pair = gamma_t + sun_turns * (1.0 - coast_phase(geo.ring_mesh))
    zr = geo.ring.teeth  # the pair of tooth j at 2 pi (j + pair - c) / Z_r
    return (tooth + pair - zr * psi[mesh - n] / (2.0 * math.pi)) % zr


@pytest.mark.parametrize(("gear", "held"), [("sun", "ring"), ("ring", "ring"), ("sun", "sun"),
                                            ("ring", "sun")])
def test_faulty_meshes_are_the_tables_with_the_tooth_in_contact(geo, gear, held):
    """Each mesh of the faulty gear against the table computed here over the revolution with
    the crack on tooth 0 of the table's pinion (sun) or wheel (ring), shifted so that the cracked
    tooth passes at its own passage time: the difference faulty - healthy of the compiled
    stiffness matches the tables' within the truncation, and is nil away from the passages.
    With the sun held (the carrier driven) the sun turns against psi relative to the
    carrier, and every mesh reads its table backwards in time."""
    tooth, H, angles = 5, 40, 90
    faulty = pe_set(geo, [g.RootCrack(**CRACK, gear=gear, tooth=tooth)], harmonics=H,
                    angles=angles, held=held)
    healthy = pe_set(geo, harmonics=H, angles=angles, held=held)
    turns = -1 if held == "sun" else 1
    z = faulty.mesh_order
    n = geo.n_planets
    if gear == "sun":
        mesh, bores, role, meshes = geo.sun_mesh, (0.012, 0.010), "pinion", range(n)
        extra = {}
    else:
        mesh, bores, role, meshes = geo.ring_mesh, (0.010, 0.085), "wheel", range(n, 2 * n)
        extra = {"ring_foundation": "rigid"}
    table = g.potential_energy_stiffness(mesh, bore_radius=bores, angles=angles, cycles=z,
                                         faults=[g.RootCrack(**CRACK, gear=role, tooth=0)],
                                         **extra)["mesh_stiffness"].values
    base = g.potential_energy_stiffness(mesh, bore_radius=bores, angles=angles, **extra)[
        "mesh_stiffness"].values
    drop = table - np.tile(base, z)  # < 0 while the cracked tooth (passing at c = 0) is loaded
    assert drop.min() < -0.02 * base.mean()
    if held == "sun":  # the sun turns backwards: the mesh meets the table's pairs backwards
        drop = np.roll(drop[::-1], 1)  # in time, T(-c), the cracked tooth still at c = 0
    c = np.arange(z * angles) / angles
    for m in meshes:
        start = _passage(geo, gear, tooth, m, turns)  # the cracked tooth passes here
        theta = 2.0 * math.pi * (c + start) / z
        diff = (kernel_stiffness(faulty, theta)[:, m]
                - kernel_stiffness(healthy, theta * z)[:, m])
        err = np.sqrt(np.mean((diff - drop) ** 2))
        assert err < 0.15 * np.sqrt(np.mean(drop ** 2)), m
        away = (c > 3.0) & (c < z - 3.0)
        assert np.max(np.abs(diff[away])) < 0.1 * np.max(np.abs(drop)), m
    for m in set(range(2 * n)) - set(meshes):  # the other group keeps its healthy series
        theta = np.linspace(0.0, 2.0 * math.pi, 17)
        np.testing.assert_allclose(kernel_stiffness(faulty, theta)[:, m],
                                   kernel_stiffness(healthy, theta * z)[:, m], rtol=1e-10)


def test_planet_fault_weakens_its_own_two_meshes(geo):
    """A crack on a tooth of planet 2: its sun-planet mesh sees the crack at the tooth's
    sun-side passages, its ring-planet mesh D mesh cycles later (half a planet turn less the
    tooth's half thicknesses: the table with the crack on the ring mesh's pinion tooth 0); the
    other planets' meshes keep the healthy series."""
    tooth, H, angles = 4, 40, 90
    faulty = pe_set(geo, [g.RootCrack(**CRACK, gear="planet2", tooth=tooth)], harmonics=H,
                    angles=angles)
    healthy = pe_set(geo, harmonics=H, angles=angles)
    z, n = geo.planet.teeth, geo.n_planets
    planet = geo.planet
    half = (planet.angular_thickness(geo.sun_mesh.operating_pitch_radii[1])
            + planet.angular_thickness(geo.ring_mesh.operating_pitch_radii[0])) / 2.0
    delay = z * (math.pi - half) / (2.0 * math.pi)  # planet rotation from sun side to ring side
    c = np.arange(z * angles) / angles
    for m, mesh, bores, role, start, extra in (
            (1, geo.sun_mesh, (0.012, 0.010), "wheel", geo.phases.sun[1] + tooth, {}),
            (n + 1, geo.ring_mesh, (0.010, 0.085), "pinion", geo.phases.sun[1] + tooth + delay,
             {"ring_foundation": "rigid"})):
        table = g.potential_energy_stiffness(mesh, bore_radius=bores, angles=angles, cycles=z,
                                             faults=[g.RootCrack(**CRACK, gear=role, tooth=0)],
                                             **extra)["mesh_stiffness"].values
        base = g.potential_energy_stiffness(mesh, bore_radius=bores, angles=angles, **extra)[
            "mesh_stiffness"].values
        drop = table - np.tile(base, z)
        theta = 2.0 * math.pi * (c + start) / z
        diff = (kernel_stiffness(faulty, theta)[:, m]
                - kernel_stiffness(healthy, theta * z)[:, m])
        assert np.sqrt(np.mean((diff - drop) ** 2)) < 0.15 * np.sqrt(np.mean(drop ** 2)), m
    theta = np.linspace(0.0, 2.0 * math.pi, 17)
    others = [m for m in range(2 * n) if m not in (1, n + 1)]
    np.testing.assert_allclose(kernel_stiffness(faulty, theta)[:, others],
                               kernel_stiffness(healthy, theta * z)[:, others], rtol=1e-10)
    assert faulty.k_s[1] < faulty.k_s[0] == pytest.approx(healthy.k_s, rel=1e-12)


def test_planet_spall_acts_on_its_flank_in_both_meshes(geo):
    """A spall on the flank of a planet tooth that the sun drives narrows the sun-planet mesh's
    drive contacts and the ring-planet mesh's coast contacts (the same flank meets the ring on
    reversal); on the other flank the reverse, the mirror image to round-off (symmetric teeth).
    Mean stiffnesses of planet 1's meshes [N/m], against the healthy set's."""
    spall = dict(length="1 mm", width="4 mm", depth="0.2 mm", position="0 mm", gear="planet1",
                 tooth=2)
    healthy = pe_set(geo, angles=90)
    k0 = np.r_[healthy.mesh_stiffnesses()[[0, 4]], healthy.coast_stiffnesses()[[0, 4]]]

    def loss(flank: str) -> np.ndarray:  # sun drive, ring drive, sun coast, ring coast
        gs = pe_set(geo, [g.Spall(**spall, flank=flank)], angles=90)
        return k0 - np.r_[gs.mesh_stiffnesses()[[0, 4]], gs.coast_stiffnesses()[[0, 4]]]

    drive, coast = loss("drive"), loss("coast")
    assert np.all(drive > 0.0)  # the thinned sections: every contact of the tooth
    assert drive[0] > 5.0 * drive[2] and drive[3] > 5.0 * drive[1]  # the narrowed contacts
    np.testing.assert_allclose(coast, drive[[2, 3, 0, 1]], rtol=1e-9)


def test_ring_spall_acts_on_the_ring_meshes_drive_contacts(geo):
    """A spall on a ring tooth's drive flank: every ring-planet mesh's drive mean falls more
    than its coast mean, the sun-planet meshes keep theirs."""
    healthy = pe_set(geo, angles=90)
    gs = pe_set(geo, [g.Spall(length="1 mm", width="4 mm", depth="0.2 mm", position="0.6 mm",
                              gear="ring", tooth=9)], angles=90)
    assert gs.mesh_order == 71
    drive = healthy.mesh_stiffnesses() - gs.mesh_stiffnesses()
    coast = healthy.coast_stiffnesses() - gs.coast_stiffnesses()
    np.testing.assert_array_equal(drive[:4], 0.0)
    assert np.all(drive[4:] > 5.0 * coast[4:]) and np.all(coast[4:] > 0.0)


def test_series_error_is_the_truncation(geo):
    """stiffness_error: the series against the tables; it falls as the harmonics grow."""
    crack = [g.RootCrack(**CRACK, gear="sun", tooth=2)]
    coarse, fine = (pe_set(geo, crack, harmonics=h, angles=90) for h in (8, 40))
    e1, e2 = coarse.stiffness_error(), fine.stiffness_error()
    assert e2["drive_rms"] < 0.6 * e1["drive_rms"] and e2["coast_rms"] < 0.6 * e1["coast_rms"]
    assert coarse.dataset_attrs()["stiffness_rms_error_rel"] == pytest.approx(
        max(e1["drive_rms"], e1["coast_rms"]))


def _quasi_static_run(geo, depth: str, tooth: int):
    """One sun revolution, after one of transient, of the set with a crack of ``depth`` on sun
    tooth ``tooth``, nearly quasi-static (mesh frequency below the first natural frequency)."""
    gs = pe_set(geo, [g.RootCrack(depth=depth, gear="sun", tooth=tooth)], harmonics=8,
                angles=90, sun_backlash=0.0, ring_backlash=0.0, modal_damping=0.1,
                rotational_only=True).with_params(input_speed=500.0)
    first = gs.natural_frequencies()[gs.natural_frequencies() > 0][0] * 2.0 * math.pi
    assert gs.mesh_frequency < 0.2 * first
    revolution = 2.0 * math.pi / gs.omega
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=revolution, samples=1,
                                                      steps_per_period=25 * 512))
    assert ds.attrs["status"] == geardyn.Status.OK
    return gs, ds


def test_fault_is_felt_once_per_revolution_at_the_tooth_contact(geo):
    """A deep crack on sun tooth 7: each sun-planet mesh's deflection peaks once per sun
    revolution, while the cracked tooth is loaded (its contact from the start to the end of the
    path of contact around its pitch-point passage, computed from the planet angles here); the
    mesh force's spectrum gains sidebands at the sun's relative rotation frequency (Omega)
    around the mesh frequency (25 Omega), which the zero-size crack does not have."""
    tooth = 7
    gs, ds = _quasi_static_run(geo, "2 mm", tooth)
    y = np.stack([ds[s].values for s in gs.state_names[:len(gs.dof_names())]], axis=1)
    deflection = y @ gs.mesh_rows().T
    cycles = (ds["time"].values * gs.omega * gs.mesh_order / (2.0 * math.pi)) % 25
    mesh = geo.sun_mesh
    start, end = -mesh.approach_length / mesh.base_pitch, mesh.recess_length / mesh.base_pitch
    peaks = []
    for m in range(geo.n_planets):
        at = cycles[np.argmax(deflection[:, m])]
        passage = _passage(geo, "sun", tooth, m)
        offset = (at - passage + 12.5) % 25 - 12.5  # from the passage, in (-12.5, 12.5]
        assert start <= offset <= end, (m, at, passage)
        peaks.append(at)
    assert len({round(p, 3) for p in peaks}) == geo.n_planets  # each planet at its own time

    def lines(data):  # amplitudes at the harmonics k Omega of one revolution (whole period)
        return np.abs(np.fft.rfft(data["F_s1"].values[:-1])) / (data.sizes["time"] - 1)

    cracked, healthy = lines(ds), lines(_quasi_static_run(geo, "0 mm", tooth)[1])
    mesh_line = healthy[25]
    # sidebands at 25 Omega -3, -2, +1, +2 Omega; at 25 - 1 = 24, a multiple of N = 4, the four
    # equally spaced planets' contributions cancel
    for k in (22, 23, 26, 27):
        assert cracked[k] > 1e-3 * mesh_line > 1e3 * healthy[k], k
    assert cracked[24] < 1e-2 * cracked[23]


def test_analyses_run_on_it(geo):
    """A sweep in the input speed, the modes and the static forces of a set with a cracked
    planet tooth; the datasets say what Omega is."""
    gs = pe_set(geo, [g.RootCrack(**CRACK, gear="planet3", tooth=1)])
    revolution = 2.0 * math.pi / gs.with_params(input_speed=2000.0).omega
    br = geardyn.bifurcation(gs, "input_speed", [2000.0, 3000.0],
                             run=geardyn.RunSettings(transient=revolution, samples=2,
                                                     steps_per_period=23 * 128))
    assert np.all(br["status"].values == 0) and np.all(np.isfinite(br["poincare"].values))
    assert br.attrs["mesh_cycles_per_period"] == 23 and br.attrs["faulty_gear"] == "planet3"
    assert br["input_speed"].attrs["units"] == "rpm"
    axes = gs.speed_axes(np.array([gs.omega]))  # Omega's axes: the mesh frequency, the speed
    assert axes["mesh_frequency"][0][0] == pytest.approx(gs.mesh_frequency / (2.0 * math.pi))
    assert axes["input_speed"][0][0] == pytest.approx(gs.input_speed)
    assert gs.mesh_frequency == pytest.approx(23 * gs.omega * gs.time_scale, rel=1e-14)
    modes = gs.modes()
    assert np.all(np.isfinite(modes["frequency"].values))
    forces = gs.static_mesh_forces()
    assert np.all(forces[:4] > 0.0) and np.all(np.isfinite(forces))


@pytest.mark.parametrize(("fault", "field"), [
    (dict(gear="planet5"), "crack.gear"),
    (dict(gear="pinion"), "crack.gear"),
    (dict(gear="sun", tooth=25), "crack.tooth"),
    (dict(gear="planet1", tooth=23), "crack.tooth"),
    (dict(gear="ring", tooth=71), "crack.tooth"),
])
def test_bad_fault_names_the_field(geo, fault, field):
    with pytest.raises(ParameterError) as err:
        pe_set(geo, [g.RootCrack(**{**CRACK, **fault})])
    assert err.value.field == field
    assert "\n" not in str(err.value)


def test_bad_fault_specs_name_the_field(geo):
    with pytest.raises(ParameterError) as err:  # no gear of the set
        pe_set(geo, [g.RootCrack(depth="1 mm", gear="moon")])
    assert err.value.field == "crack.gear"
    with pytest.raises(ParameterError) as err:  # no gear's name at all
        g.RootCrack(depth="1 mm", gear="")
    assert err.value.field == "crack.gear"
    with pytest.raises(ParameterError) as err:  # off the ring tooth's active flank
        pe_set(geo, [g.Spall(length="1 mm", width="2 mm", depth="0.1 mm", position="3 mm",
                             gear="ring")])
    assert err.value.field == "spall.position"
    with pytest.raises(ParameterError) as err:
        pe_set(geo, [g.RootCrack(**CRACK, gear="sun"), g.BrokenTooth(gear="planet1")])
    assert err.value.field == "faults"
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet.from_geometry(geo, faults=[g.RootCrack(**CRACK, gear="sun")],
                                               **MEMBERS)
    assert err.value.field == "faults"
    with pytest.raises(ParameterError) as err:  # no torque: no mesh loads the worn flank
        pe_set(geo, [g.Wear(depth="20 um", gear="planet2", profile="archard")], sun_torque=0.0)
    assert err.value.field == "wear.flank"
    with pytest.raises(ParameterError) as err:
        pe_set(geo, [g.RootCrack(**CRACK, gear="sun")], sun_mesh_error="1 um")
    assert err.value.field == "sun_mesh_error"
    with pytest.raises(ParameterError) as err:  # a pair's faults lie on its pinion or wheel
        geardyn.SpurPair.from_geometry(geo.sun_mesh, bore_radius="10 mm", speed=100.0,
                                       torque=10.0, faults=[g.RootCrack(**CRACK, gear="sun")])
    assert err.value.field == "crack.gear"


@pytest.mark.parametrize("gear", ["sun", "planet3", "ring"])
def test_period_stiffness_is_the_compiled_series_and_the_faulty_meshes_are_named(geo, gear):
    """PlanetaryGearSet.period_stiffness: every mesh's series at its cycles is the compiled
    kernel's stiffness at the same forcing phase (drive flank: deflection +1, coast: -1); its
    table lies under the series as stiffness_error (an inverse FFT of the coefficients) says
    (the largest rms over the meshes); the table differs from the healthy set's one-cycle
    table, repeated, exactly on the meshes FaultPlacement.meshes names (every sun mesh, every
    ring mesh, planet 3's two)."""
    faulty = pe_set(geo, [g.RootCrack(**CRACK, gear=gear, tooth=2)], harmonics=3, angles=16)
    healthy = pe_set(geo, harmonics=3, angles=16)
    z = faulty.mesh_order
    expected = {"sun": {"s1", "s2", "s3", "s4"}, "planet3": {"s3", "r3"},
                "ring": {"r1", "r2", "r3", "r4"}}[gear]
    assert set(faulty.faults.meshes(geo.n_planets)) == expected
    error = faulty.stiffness_error()
    for flank, sign in (("drive", 1.0), ("coast", -1.0)):
        differ, rms = set(), []
        for m, ((c, k, series), (_, k_h, _)) in enumerate(zip(
                faulty.period_stiffness(flank), healthy.period_stiffness(flank), strict=True)):
            pick = slice(None, None, 9)
            compiled = kernel_stiffness(faulty, 2.0 * math.pi * c[pick] / z, sign)[:, m]
            np.testing.assert_allclose(series[pick], compiled, rtol=1e-9, err_msg=flank)
            rms.append(np.sqrt(np.mean((series - k) ** 2)) / np.mean(k))
            if not np.allclose(k.reshape(z, -1), k_h, rtol=1e-12, atol=0.0):
                differ.add(faulty.mesh_names[m])
        assert max(rms) == pytest.approx(error[f"{flank}_rms"], rel=1e-6), flank
        assert differ == expected, flank


@pytest.mark.parametrize("coast", ["mirror", "symmetric"])
def test_a_missing_planet_tooth_runs_on_the_series_clipped_at_zero(geo, coast):
    """A missing planet tooth leaves no pair in contact over part of its passage in its two
    meshes (the tables fall to 0 there): the set is built with ``stiffness_gaps``, the compiled
    stiffness is the series summed here with numpy from the set's coefficients and clipped at 0
    (it rings below 0 about the gaps), 0 where the clip acts, and a trajectory through the gaps
    agrees with DOP853 on the model (rtol 1e-10) to 1e-5 of its motion (the clip is a kink in
    time that RK4 does not locate). Without the flag the same coefficients are refused. Both
    coast forms: ``symmetric`` runs the kernels' one-flank path."""
    gs = pe_set(geo, [g.BrokenTooth(gear="planet1", tooth=2)], harmonics=3, angles=16,
                coast=coast)
    assert gs.stiffness_gaps and gs.faults.meshes(geo.n_planets) == ("s1", "r1")
    z = gs.mesh_order
    theta = np.linspace(0.0, 2.0 * math.pi, 4 * gs.fourier.shape[1] + 1)
    h = np.arange(1, gs.fourier.shape[1] // 2 + 1)
    raw = 1.0 + (gs.fourier[:, 0::2] @ np.cos(np.outer(h, theta))
                 + gs.fourier[:, 1::2] @ np.sin(np.outer(h, theta)))  # (meshes, phases)
    s1 = gs.mesh_names.index("s1")
    assert raw[s1].min() < 0.0
    compiled = kernel_stiffness(gs, theta)
    mean = gs.mesh_stiffnesses()
    np.testing.assert_allclose(compiled, (mean[:, None] * np.maximum(raw, 0.0)).T,
                               rtol=1e-9, atol=1e-9 * float(mean.max()))
    c, table, _ = gs.period_stiffness("drive")[s1]
    assert table.min() == 0.0 and table.max() > 0.0
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet(**{**gs.inputs, "stiffness_gaps": False})
    assert err.value.field == "waveform"
    run = gs.with_params(input_speed=1500.0)
    y0 = run.initial_state()
    ds = geardyn.simulate(run, run=geardyn.RunSettings(transient=0.0, samples=1), y0=y0)
    t = ds["time"].values[::16]
    ref = geardyn.reference_solution(run, y0, t)
    x = np.column_stack([ds[n].values[::16] for n in run.state_names])
    assert np.max(np.abs(x - ref)) < 1e-5 * np.max(np.ptp(ref, axis=0))
    assert 2.0 * math.pi * z / run.omega >= t[-1] > 0.0
