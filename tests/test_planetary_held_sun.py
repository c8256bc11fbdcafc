"""The order in which a planetary set's meshes meet their tooth pairs, for every held member.

A mesh's stiffness is a function of its gear a's rotation relative to the carrier (the sun in
a sun-planet mesh, the planet in a planet-ring mesh): the pairs in contact sit on the line of
action at positions that the rotation moves, on the face of a that leads in the sense it
turns from a's root towards its tip. Computed here from that alone, with the Willis
kinematics for the sense of each rotation (the input member turning in the positive sense):
ring or carrier held, the sun turns positive and a planet negative relative to the carrier;
sun held (the carrier driven), the sun negative and a planet positive. Each contact's stiffness
is ``PotentialEnergyPair.terms`` at its position; which face a mesh's positive deflection
loads is read from the set's deflection row (the sign of a's rotation coordinate in it).

Checks: PlanetaryGearSet.from_geometry's series of each sun-planet mesh, both flanks, are those
of the stiffness so computed, at the set's own pitch-point times (the Parker & Lin phases), to
1e-10 of the mean, for the potential-energy tables and the ISO waves (these to the sampling of
their jumps here); a planet-ring mesh's series are those of the stiffness so computed up to a
shift in time (compared by shift-invariant products of the Fourier coefficients), to 1e-9; in
each case the time-reversed stiffness differs by far more, so a mesh that reads its table the
wrong way round fails. The sun-held set is the train stage of the same gears (sun fixed,
carrier driven; geardyn.trains, whose meshes read their tables backwards where gear a turns in
the negative sense from the train's own speed ratios) on every mesh, healthy and with a crack on
the sun, the ring or a planet and a spall on a planet's flank, to 1e-10 of the mean; on a
V-zero shifted stage (gamma_rs = 0.954) its ring meshes lie -gamma_rs after its sun meshes, as
the train's and as a planet tooth drawn from its angular thicknesses gives. Held in the
kinematics only (no sun support), the set's static mesh forces under a carrier torque are
round-off, and Archard wear on a planet is refused (``wear.flank``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears.potential_energy import coast_phase, prepare_pair
from geardyn.trains import Bearing, Gear, GearTrain, Inertia, Shaft, TrainModel, planetary_stage
from test_planetary_iso_flanks import shifted_stage
from test_planetary_pe import MEMBERS, stage
from test_trains_faults import set_series_misses

BORES = dict(sun_bore_radius="12 mm", planet_bore_radius="10 mm", ring_rim_radius="85 mm")
BORE_M = {"sun": (12e-3, 10e-3), "ring": (10e-3, 85e-3)}
H = 9
N = 360  # points per mesh cycle, the tables' own


def _senses(geo: g.PlanetaryGeometry, held: str) -> dict[str, float]:
    """Sense (+1, -1) of the sun's and a planet's rotation relative to the carrier, the input
    (the sun; the carrier with the sun held) turning in the positive sense: Willis, then rolling
    without slip at the sun-planet pitch point."""
    zs, zp, zr = geo.sun.teeth, geo.planet.teeth, geo.ring.teeth
    sun, carrier = {"ring": (1.0, zs / (zs + zr)), "carrier": (1.0, 0.0),
                    "sun": (0.0, 1.0)}[held]
    sun_rel = sun - carrier
    planet_rel = -sun_rel * zs / zp
    return {"sun": math.copysign(1.0, sun_rel), "planet": math.copysign(1.0, planet_rel)}


def _faces(gs: geardyn.PlanetaryGearSet) -> dict[str, float]:
    """The sense in which gear a must turn to close a mesh's positive deflection, from the
    set's deflection rows: the sign of u_s in a sun-planet row, of u_1 in planet 1's ring row."""
    rows, names = gs.full_mesh_rows(), gs.full_dof_names()
    n = gs.n_planets
    return {"sun": float(np.sign(rows[0, names.index("u_s")])),
            "ring": float(np.sign(rows[n, names.index("u_1")]))}


def _contacts(pair, rolls: np.ndarray, drive: bool) -> np.ndarray:
    """Mesh stiffness [N/m] at gear a's rotations ``rolls`` [mesh cycles from a pair of the
    face at the pitch point]: every pair on the path of contact, on the face that leads when a
    turns in the positive sense (``drive``: its contacts move towards a's tip as a turns
    positive, at (roll + k) base pitches from the pitch point, the path [start, end)) or on the
    other face (its contacts φ after, at (φ - roll - k) base pitches, the path (start, end])."""
    mesh = pair.mesh
    p_b = mesh.base_pitch
    start, end = -mesh.approach_length / p_b, mesh.recess_length / p_b
    phi = coast_phase(mesh)
    total = np.zeros(rolls.size)
    for k in range(-4, 5):
        u = rolls + k if drive else phi - rolls - k
        inside = (u >= start) & (u < end) if drive else (u > start) & (u <= end)
        if inside.any():
            total[inside] += pair.terms(u[inside] * p_b)["pair"]
    return total


def _pairs(contacts: np.ndarray) -> np.ndarray:
    """Complex Fourier coefficients c_h, h = 0..H, of samples uniform over one cycle."""
    return np.fft.rfft(contacts)[:H + 1] / contacts.size


def _set_pairs(mean: float, coef: np.ndarray) -> np.ndarray:
    """c_h of a set's series k0 (1 + sum a_h cos + b_h sin)."""
    a, b = coef[0::2], coef[1::2]
    return np.concatenate([[mean], 0.5 * mean * (a[:H] - 1j * b[:H])])


def _invariants(c: np.ndarray) -> np.ndarray:
    """c_h conj(c_1)^h / abs(c_1)^h, h = 1..H: unchanged by a shift in time, conjugated by its
    reversal."""
    h = np.arange(1, H + 1)
    return c[1:] * (np.conj(c[1]) / abs(c[1])) ** h


def _pe_set(geo, held: str) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=H, stiffness="potential_energy",
        stiffness_options={**BORES, "angles": N}, held=held, **MEMBERS)


def _pair(geo, group: str):
    mesh = geo.sun_mesh if group == "sun" else geo.ring_mesh
    extra = {"ring_foundation": "rigid"} if group == "ring" else {}
    return prepare_pair(mesh, bore_radius=BORE_M[group], **extra)


@pytest.mark.parametrize("held", ["ring", "carrier", "sun"])
@pytest.mark.parametrize("geometry", [stage, shifted_stage])
def test_sun_meshes_meet_their_pairs_as_the_sun_turns(held, geometry):
    """Sun-planet mesh n's series, both flanks, against the stiffness of its pairs at the sun's
    rotation relative to the carrier, r = s (c - gamma_n) mesh cycles (s the Willis sense,
    gamma_n the set's phase: a pair of the face that its positive deflection loads passes the
    pitch point at c = gamma_n), sampled at the tables' points; the positive deflection on the
    face that leads when the sun turns in the sense of its row's u_s."""
    geo = geometry()
    gs = _pe_set(geo, held)
    turns, face = _senses(geo, held)["sun"], _faces(gs)["sun"]
    assert face == 1.0
    pair = _pair(geo, "sun")
    c = np.arange(N) / N
    phases = geo.phases_turning(int(turns)).sun
    for m in range(gs.n_planets):
        rolls = turns * (c - phases[m])
        for coast, coef, mean in ((False, gs.fourier, gs.mesh_stiffnesses()),
                                  (True, gs.fourier_coast, gs.coast_stiffnesses())):
            want = _pairs(_contacts(pair, rolls, drive=not coast))
            backwards = _pairs(_contacts(pair, -rolls, drive=not coast))
            got = _set_pairs(float(mean[m]), coef[m])
            np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-10 * float(mean[m]))
            assert np.max(np.abs(backwards - want)) > 1e-3 * float(mean[m])


@pytest.mark.parametrize("held", ["ring", "carrier", "sun"])
def test_sun_meshes_iso_waves_meet_the_double_contact_as_the_sun_turns(held):
    """The ISO waves (single contact stiffness where one pair is in contact, double where two)
    of the profile-shifted stage, whose double contact lies off the middle of the mesh cycle:
    each sun-planet mesh's series, both flanks, against the wave of the pair count at the sun's
    rotation r = s (c - gamma_n), sampled at 36000 points (to 1e-3 of the mean, the sampling of
    the jumps); read the other way round they are off by more than 0.05."""
    geo = shifted_stage()
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=H, held=held, **MEMBERS)
    turns = _senses(geo, held)["sun"]
    wave = geo.waveforms()[0]
    mesh = geo.sun_mesh
    p_b = mesh.base_pitch
    start, end = -mesh.approach_length / p_b, mesh.recess_length / p_b
    phi = coast_phase(mesh)
    n = 36000
    c = (np.arange(n) + 0.5) / n
    phases = geo.phases_turning(int(turns)).sun

    def iso(rolls: np.ndarray, drive: bool) -> np.ndarray:
        count = np.zeros(rolls.size)
        for k in range(-4, 5):
            u = rolls + k if drive else phi - rolls - k
            count += (u >= start) & (u < end)
        return np.where(count >= 2, wave.double, wave.single)

    coast_mean = gs.coast_stiffnesses()
    for m in range(gs.n_planets):
        rolls = turns * (c - phases[m])
        for coast, coef, mean in ((False, gs.fourier, gs.mesh_stiffnesses()[m]),
                                  (True, gs.fourier_coast, coast_mean[m])):
            want = _pairs(iso(rolls, not coast))
            backwards = _pairs(iso(-rolls, not coast))
            got = _set_pairs(float(mean), coef[m])
            np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-3 * float(mean))
            assert np.max(np.abs(backwards - want)) > 0.05 * float(mean)


@pytest.mark.parametrize("held", ["ring", "carrier", "sun"])
@pytest.mark.parametrize("geometry", [stage, shifted_stage])
def test_ring_meshes_meet_their_pairs_as_the_planet_turns(held, geometry):
    """Planet-ring mesh n's series, both flanks, against the stiffness of its pairs at the
    planet's rotation relative to the carrier, in the Willis sense, on the face its positive
    deflection loads: the one that leads when the planet turns in the sense of u_n in its row
    (negative: the face the sun loads in forward drive). Its phase is the set's own, so the two
    are compared by their shift-invariant products c_h conj(c_1)^h / abs(c_1)^h, h = 1..H, to
    1e-9 of abs(c_1)."""
    geo = geometry()
    gs = _pe_set(geo, held)
    turns, face = _senses(geo, held)["planet"], _faces(gs)["ring"]
    assert face == -1.0
    pair = _pair(geo, "ring")
    c = np.arange(N) / N
    phi = coast_phase(geo.ring_mesh)
    for m in range(gs.n_planets, 2 * gs.n_planets):
        for coast, coef, mean in ((False, gs.fourier, gs.mesh_stiffnesses()),
                                  (True, gs.fourier_coast, gs.coast_stiffnesses())):
            # the positive deflection's face leads as the planet turns in the sense `face`: its
            # pairs are the table's drive pairs when face = +1, else its other face's; the
            # offset phi puts the positions on the points of the set's table of that flank
            drive = (face > 0) != coast
            offset = phi
            rolls = turns * c + offset
            want = _invariants(_pairs(_contacts(pair, rolls, drive)))
            backwards = _invariants(_pairs(_contacts(pair, offset - turns * c, drive)))
            got = _invariants(_set_pairs(float(mean[m]), coef[m]))
            scale = abs(_set_pairs(float(mean[m]), coef[m])[1])
            np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-9 * scale)
            assert np.max(np.abs(backwards - want)) > 1e-3 * scale


def vzero_stage() -> g.PlanetaryGeometry:
    """25/23/71, m 2 mm, the planet and ring shifted +0.2 and the sun -0.2 at the standard
    centre distance: gamma_rs = 0.954, coast phases 0.454 (sun mesh) and 0.546 (ring mesh)."""
    def gear(z: int, name: str, x: float, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, "2 mm", "20 deg", "20 mm", internal=internal, name=name,
                          profile_shift=x)
    return g.PlanetaryGeometry(gear(25, "sun", -0.2), gear(23, "planet", 0.2),
                               gear(71, "ring", 0.2, internal=True), n_planets=4)


@pytest.mark.parametrize("held", ["ring", "carrier", "sun"])
def test_ring_mesh_phase_follows_the_planet_tooth(held):
    """Planet 1's ring mesh, positive deflection, against its pairs at the planet's rotation
    from the tooth drawn here: a planet tooth's flank that the sun mesh's positive deflection
    loads (its counter-clockwise leading flank) passes the sun-side pitch point (angle pi from
    the planet centre, operating pitch radius) at the set's gamma_s1; the flank that the ring
    mesh's positive deflection loads (its clockwise leading one) reaches the ring-side pitch
    point (angle 0) after the planet turns by pi + s (psi_s + psi_r) / 2 in its sense s, psi the
    tooth's angular thicknesses at the two radii (less than half a turn with the ring held, more
    with the sun held). Fourier coefficients to 2e-3 of the mean (the set samples its table at
    its own 360 points, the coast phase off them: 6.5e-4); the delay of the other sense (the
    sun-held set's ring phases gamma_rs, not -gamma_rs) misses by more than 3e-2 (0.068)."""
    geo = vzero_stage()
    gs = _pe_set(geo, held)
    sense = _senses(geo, held)["planet"]
    planet = geo.planet
    psi = (planet.angular_thickness(geo.sun_mesh.operating_pitch_radii[1])
           + planet.angular_thickness(geo.ring_mesh.operating_pitch_radii[0]))
    pair = _pair(geo, "ring")
    phi = coast_phase(geo.ring_mesh)
    gamma_s = geo.phases_turning(int(_senses(geo, held)["sun"])).sun[0]
    n = 3600
    c = (np.arange(n) + 0.5) / n
    m = gs.n_planets
    got = _set_pairs(float(gs.mesh_stiffnesses()[m]), gs.fourier[m])
    misses = []
    for s in (sense, -sense):
        delay = planet.teeth * (math.pi + s * psi / 2.0) / (2.0 * math.pi)
        # the positive deflection's pairs (the table's other face, at phi - roll) pass the
        # pitch point at c = gamma_s + delay, where roll = phi
        rolls = np.mod(sense * (c - gamma_s - delay) + phi, 1.0)
        want = _pairs(_contacts(pair, rolls, drive=False))
        misses.append(float(np.max(np.abs(got - want))))
    mean = float(gs.mesh_stiffnesses()[m])
    assert misses[0] < 2e-3 * mean
    assert misses[1] > 3e-2 * mean


def _train_stage(geo, faults=()) -> TrainModel:
    """The stage as a train: sun fixed, carrier driven, the ring on an output shaft."""
    st = planetary_stage(
        sun=Gear("sun", 1e-3, mass=0.5, geometry=geo.sun),
        ring=Gear("ring", 1.0, mass=3.0, geometry=geo.ring),
        carrier=Inertia("carrier", 0.1, mass=5.0),
        planet=Gear("p", 1e-3, mass=0.3, geometry=geo.planet), n_planets=geo.n_planets,
        pin_stiffness=1e8, sun_mesh_stiffness="potential_energy",
        ring_mesh_stiffness="potential_energy", **BORES)
    bearings = [Bearing(f"{k}_bearing", k, 1e8) for k in ("sun", "ring", "carrier")]
    train = GearTrain(st.bodies, [Shaft("output", "ring", "ground", 1e6)],
                      [*bearings, *st.bearings], st.meshes, fixed=("sun",), driven="carrier",
                      faults=faults)
    return TrainModel(train, torques={"carrier": 5.0}, mesh_phase="geometry", harmonics=4)


CRACK = dict(depth="1.5 mm", angle="45 deg")
SPALL = dict(width="4 mm", length="1 mm", position="0.5 mm", depth="50 um", flank="drive")


@pytest.mark.parametrize(("kind", "kw", "train_gear", "set_gear"), [
    (None, {}, None, None),
    (g.RootCrack, dict(CRACK, tooth=3), "sun", "sun"),
    (g.RootCrack, dict(CRACK, tooth=5), "ring", "ring"),
    (g.RootCrack, dict(CRACK, tooth=7), "p1", "planet1"),
    (g.Spall, dict(SPALL, tooth=7), "p1", "planet1"),
])
def test_sun_held_set_is_the_train_stage(kind, kw, train_gear, set_gear):
    """The 25/23/71 stage with the sun held and the carrier driven: every mesh's series, drive
    and coast (the ring meshes' flanks named the other way round, as in
    tests/test_trains_planet_bores.py), is the train stage's, whose sun meshes read backwards
    from its own speed ratios, to 1e-10 of the mean; with a fault over the faulty gear's
    revolution (a planet tooth reaching the ring-side pitch point after the planet turns on
    through more than half a turn)."""
    geo = stage()
    n = geo.n_planets
    model = _train_stage(geo, () if kind is None else (kind(**kw, gear=train_gear),))
    assert model.backward_meshes() == tuple(f"sun_p{i + 1}" for i in range(n))
    gs = geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=4, stiffness="potential_energy", stiffness_options=BORES, held="sun",
        faults=() if kind is None else [kind(**kw, gear=set_gear)], **MEMBERS)
    assert gs.mesh_order == model.mesh_order
    assert max(set_series_misses(model, gs)) <= 1e-10


def test_sun_held_tables_are_met_backwards():
    """A sun-held set keeps its tables as it meets them in time (``mesh_tables``, attrs
    ``read_backward``; ``stiffness_tables`` as computed, in gear a's rotation): its series
    against them (``stiffness_error``) are as close as the ring-held set's against its own."""
    geo = stage()
    sun, ring = _pe_set(geo, "sun"), _pe_set(geo, "ring")
    assert sun.mesh_tables[0].attrs["read_backward"] == 1
    assert "read_backward" not in ring.mesh_tables[0].attrs
    np.testing.assert_array_equal(sun.stiffness_tables[0]["mesh_stiffness"].values,
                                  ring.stiffness_tables[0]["mesh_stiffness"].values)
    e_sun, e_ring = sun.stiffness_error(), ring.stiffness_error()
    for key in e_sun:
        assert e_sun[key] == pytest.approx(e_ring[key], rel=1e-9)


def test_sun_held_set_is_the_train_stage_with_a_ring_phase():
    """The V-zero shifted stage (gamma_rs = 0.954): the sun-held set's ring meshes lie -gamma_rs
    after its sun meshes as the train stage's, whose phases follow each gear's sense of rotation
    (docs/trains.md, "mesh_phase"), on every mesh, drive and coast: the sun meshes to 1e-10 of
    the mean, the ring meshes to 1e-2 (the train moves the ring table by the planet's coast
    phase, 0.546, off the tables' 360 angles: 5.2e-3), where gamma_rs would miss by 0.39."""
    geo = vzero_stage()
    model = _train_stage(geo)
    gs = geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=4, stiffness="potential_energy", stiffness_options=BORES, held="sun",
        **MEMBERS)
    sun_miss, ring_miss = set_series_misses(model, gs, points=721)
    assert sun_miss <= 1e-10 and ring_miss <= 1e-2


@pytest.mark.parametrize("flank", ["drive", "coast"])
def test_planet_archard_wear_under_round_off_forces_is_refused(flank):
    """The sun held only in the kinematics (no ``fixed=("sun",)``, no sun torsional
    stiffness), the carrier driven: nothing reacts a planet's moment at the sun, so no mesh can
    carry a force (the planet's moment balance), and the static mesh forces are round-off,
    below 1e-12 of the torque's force scale T_c / r_c; Archard wear on a planet's either flank
    is refused naming ``wear.flank`` and the forces."""
    geo = stage()
    kw = dict(harmonics=4, stiffness="potential_energy", stiffness_options=BORES, held="sun",
              carrier_torque=100.0, **MEMBERS)
    forces = geardyn.PlanetaryGearSet.from_geometry(geo, **kw).static_mesh_forces()
    assert np.max(np.abs(forces)) < 1e-12 * 100.0 / geo.sun_mesh.centre_distance
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet.from_geometry(
            geo, faults=[g.Wear(depth="20 um", gear="planet1", profile="archard", flank=flank)],
            **kw)
    assert err.value.field == "wear.flank"
    assert "round-off" in str(err.value) and "ring-side" in str(err.value)
