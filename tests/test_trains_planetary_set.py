"""A gear train's planetary stage (geardyn.trains.planetary_stage) against PlanetaryGearSet
.from_geometry of the same gears, where they used to part: which ring tooth a fault's ``tooth``
names, the centre distance of a widened stage, the ISO waves of the meshes read backwards, and
Archard wear on a planet with the sun held.

Checks:

* ring tooth j is one physical tooth in both models: over the ring's revolution the flank that
  the planet-ring table calls drive (the ring tooth's clockwise-facing flank; the train's drive
  flank of a ring mesh, the set's coast flank) of a cracked tooth j is in contact, in each
  model's tables as met in time, from L_1 before to L_2 after c = gamma_T + j, where gamma_T
  is worked out here from the planet's angular thicknesses (the train's definition of the tooth
  numbers, docs/trains.md "Tooth faults": a planet tooth carried from the sun-side pitch point
  at c = 0 to the ring side) and {L_1, L_2} = {approach, recess} lengths over the base pitch
  (GearMesh), to 3 of the tables' 360 angles a cycle (one tooth earlier or later misses by
  1 - (L_2 - L_1) or more); and every mesh's series of the two models agree (1e-10 of the
  mean on the unshifted stage, where the set used to put the crack one mesh cycle earlier with
  the ring held, and to the off-grid coast sampling on shifted stages), ring and sun held;
* a stage of shifted gears at a widened centre distance (0.0484 m, planetary_stage's
  ``centre_distance``) builds both meshes there:
  their tables' contact ratios are (sqrt(r_a1^2 - r_b1^2) +- sqrt(r_a2^2 - r_b2^2) +- a sin
  alpha_w) / p_b with cos alpha_w = (r_b2 +- r_b1) / a, computed here from the gears' radii,
  and the meshes' series are the set's; a carrier radius alone leaves each mesh at its own
  zero-backlash distance;
* ISO waves: the train takes a given waveform as the mesh meets it in time, so the ISO waves
  (in gear a's positive rotation) given reversed, (a, -b), on its backward meshes are the
  set's series, both flanks, ring and sun held; given as they are, the backward meshes miss by
  more than 0.2;
* Archard wear on a planet with the sun held (carrier driven, either sense, either flank):
  every mesh's series equals the set's; the mesh that loads the worn flank is the one that the
  planet's torque balance gives (the sun held, the carrier driving: the planet presses on the
  sun's coast flank, so the planet's drive flank is worn by the ring mesh), and that mesh's
  table is potential_energy_stiffness of its pair with that pair's own Archard wear, called
  here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, potential_energy_stiffness
from geardyn.models.planetary_stiffness import table_in_time
from geardyn.trains import Bearing, Gear, GearTrain, Inertia, Shaft, TrainModel, planetary_stage
from test_planetary_held_sun import vzero_stage
from test_planetary_iso_flanks import shifted_stage
from test_planetary_pe import MEMBERS, stage
from test_trains_faults import set_series_misses

BORES = dict(sun_bore_radius="12 mm", planet_bore_radius="10 mm", ring_rim_radius="85 mm")
H = 4
N = 360  # the tables' angles per mesh cycle
CRACK = dict(depth="1.5 mm", angle="45 deg")
GEOMETRIES = {"unshifted": stage, "vzero": vzero_stage, "shifted": shifted_stage}


def _stage(geo, held: str, faults=(), torque: float = 5.0, stiffness="potential_energy",
           place: dict | None = None, **kw) -> TrainModel:
    """The stage as a train: ring held (sun driven, carrier on the output shaft) or sun held
    (carrier driven, ring on the output shaft); its meshes at the geometry's centre distance
    (``place``: planetary_stage's centre_distance and carrier_radius instead)."""
    if place is None:
        place = {"centre_distance": geo.sun_mesh.centre_distance}
    bores = BORES if stiffness == "potential_energy" else {}
    st = planetary_stage(
        sun=Gear("sun", 1e-3, mass=0.5, geometry=geo.sun),
        ring=Gear("ring", 1.0, mass=3.0, geometry=geo.ring),
        carrier=Inertia("carrier", 0.1, mass=5.0),
        planet=Gear("p", 1e-3, mass=0.3, geometry=geo.planet), n_planets=geo.n_planets,
        pin_stiffness=1e8, sun_mesh_stiffness=stiffness, ring_mesh_stiffness=stiffness,
        **place, **bores)
    bearings = [Bearing(f"{k}_bearing", k, 1e8) for k in ("sun", "ring", "carrier")]
    output, driven = ("carrier", "sun") if held == "ring" else ("ring", "carrier")
    train = GearTrain(st.bodies, [Shaft("output", output, "ground", 1e6)],
                      [*bearings, *st.bearings], st.meshes, fixed=(held,), driven=driven,
                      faults=faults)
    return TrainModel(train, torques={driven: torque}, mesh_phase="geometry",
                      harmonics=kw.pop("harmonics", H), **kw)


def _set(geo, held: str, faults=(), **kw) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=H, stiffness="potential_energy", stiffness_options=BORES, held=held,
        faults=faults, **MEMBERS, **kw)


# ---------------------------------------------------------------- ring tooth numbers
def _gamma_t(geo, held: str) -> float:
    """gamma_T [mesh cycles in [0, 1)]: when the clockwise-facing flank of ring tooth 0 passes
    planet 1's ring-side pitch point. The planet turns against the carrier (sigma = -1) with
    the ring held, with it (+1) with the sun held; its counter-clockwise-facing flank, at the
    sun-side pitch point at c = 0, reaches the ring-side one (half a turn round the planet)
    after Z_p sigma (pi - (psi_r - psi_s) / 2) / 2 pi mesh cycles (psi: its angular thickness
    at each mesh's operating pitch radius), and meets the ring tooth's clockwise-facing flank
    there."""
    planet = geo.planet
    psi_s = planet.angular_thickness(geo.sun_mesh.operating_pitch_radii[1])
    psi_r = planet.angular_thickness(geo.ring_mesh.operating_pitch_radii[0])
    sigma = -1.0 if held == "ring" else 1.0
    gamma = (planet.teeth * sigma * (math.pi - 0.5 * (psi_r - psi_s)) / (2.0 * math.pi)) % 1.0
    return 0.0 if math.isclose(gamma, 1.0, abs_tol=1e-9) else gamma


def _contact(faulty: np.ndarray, healthy: np.ndarray, shift: float, centre: float,
             teeth: int) -> tuple[float, float]:
    """The cracked tooth's contact on one flank [mesh cycles before and after ``centre``]:
    where that flank's table over the revolution as met in time, delayed by ``shift`` (K(c) =
    T(c - shift)), falls below the healthy one-cycle table's (as met in time)."""
    h = np.tile(healthy, teeth)
    hit = np.nonzero(faulty - h < -1e-9 * np.max(h))[0]
    u = (hit / N + shift - centre + 0.5 * teeth) % teeth - 0.5 * teeth
    assert np.max(u) - np.min(u) < 3.0  # one tooth's contact
    return float(-np.min(u)), float(np.max(u) + 1.0 / N)


@pytest.mark.parametrize("geometry", sorted(GEOMETRIES))
@pytest.mark.parametrize("held", ["ring", "sun"])
def test_ring_tooth_j_is_in_contact_about_its_passage(geometry, held):
    """A crack on ring tooth 5: in both models the ring tooth's clockwise-facing flank is in
    contact from L_1 before to L_2 after c = gamma_T + 5 (computed here), {L_1, L_2} the
    approach and recess lengths over the base pitch, to 3 / 360 mesh cycles."""
    geo = GEOMETRIES[geometry]()
    n, j, z = geo.n_planets, 5, geo.ring.teeth
    faults = (g.RootCrack(**CRACK, gear="ring", tooth=j),)
    centre = _gamma_t(geo, held) + j
    mesh = geo.ring_mesh
    lengths = sorted((mesh.approach_length / mesh.base_pitch,
                      mesh.recess_length / mesh.base_pitch))
    assert lengths[1] - lengths[0] > 0.05  # the sides are told apart
    gs = _set(geo, held, [g.RootCrack(**CRACK, gear="ring", tooth=j)])
    var = "mesh_stiffness_coast"  # the set's mesh_tables are as met in time
    got = _contact(gs.mesh_tables[n][var].values,
                   table_in_time(gs.stiffness_tables[1], held == "sun")[var].values,
                   -gs.mesh_phase[n] / (2.0 * math.pi), centre, z)
    np.testing.assert_allclose(sorted(got), lengths, atol=3.0 / N)
    model = _stage(geo, held, faults)
    back = "p1_ring" in model.backward_meshes()
    assert back == (held == "ring")
    var = "mesh_stiffness"  # the train's tables are in gear a's rotation
    got = _contact(table_in_time(model.fault_tables()["p1_ring"], back)[var].values,
                   table_in_time(model.train.mesh_data["p1_ring"].table, back)[var].values,
                   -model.mesh_phase[n] / (2.0 * math.pi), centre, z)
    np.testing.assert_allclose(sorted(got), lengths, atol=3.0 / N)


@pytest.mark.parametrize("geometry", sorted(GEOMETRIES))
@pytest.mark.parametrize("held", ["ring", "sun"])
def test_cracked_ring_of_the_set_is_the_train_stages(geometry, held):
    """A crack on ring tooth 5: every mesh's series of the set is the train stage's, drive and
    coast, over the ring's revolution: to 1e-10 of the mean on the unshifted stage, on the
    shifted ones to 1e-2 (the healthy ring meshes' own difference there, the coast phase off
    the tables' angles) where one tooth off misses by more than 3e-2."""
    geo = GEOMETRIES[geometry]()
    crack = dict(CRACK, tooth=5)
    model = _stage(geo, held, (g.RootCrack(**crack, gear="ring"),))
    gs = _set(geo, held, [g.RootCrack(**crack, gear="ring")])
    assert gs.mesh_order == model.mesh_order == geo.ring.teeth
    sun, ring = set_series_misses(model, gs)
    assert sun < 1e-10
    assert ring < (1e-10 if geometry == "unshifted" else 1e-2)


# ---------------------------------------------------------------- the centre distance
def _contact_ratio(pinion, wheel, a: float, internal: bool) -> float:
    """epsilon_alpha at centre distance a from the gears' tip and base radii."""
    sign = -1.0 if internal else 1.0
    r1, r2 = pinion.base_radius, wheel.base_radius
    alpha_w = math.acos((r2 + sign * r1) / a)
    p_b = 2.0 * math.pi * r1 / pinion.teeth
    return (sign * math.sqrt(wheel.tip_radius ** 2 - r2 ** 2)
            + math.sqrt(pinion.tip_radius ** 2 - r1 ** 2) - sign * a * math.sin(alpha_w)) / p_b


def test_widened_stage_builds_its_meshes_at_its_centre_distance():
    """Sun and ring shifted (+0.2, +0.3) at centre distance 0.0484 m (zero-backlash distances:
    0.04839 m sun-side, 0.04858 m ring-side): planetary_stage(centre_distance=0.0484) builds
    both meshes there, the planets' pins at that radius, both tables' contact ratios those at
    0.0484 m computed here (1.5438, 1.7440; at the zero-backlash distances 1.5492, 1.8248), the
    sun meshes' series the set's to 1e-10 and the ring meshes' to 5e-3 of the mean (the coast
    phase off the tables' angles). A carrier radius alone leaves each mesh at its gears'
    zero-backlash distance; one that differs from the centre distance is refused naming
    carrier_radius; a study file's stage takes centre_distance as a length."""
    geo = shifted_stage()
    a = geo.sun_mesh.centre_distance
    assert a == 0.0484
    model = _stage(geo, "ring")
    want = {"sun_p1": _contact_ratio(geo.sun, geo.planet, a, False),
            "p1_ring": _contact_ratio(geo.planet, geo.ring, a, True)}
    for name, eps in want.items():
        assert model.train.mesh_data[name].table.attrs["contact_ratio"] == pytest.approx(
            eps, rel=1e-12)
    assert {b.radius for b in model.train.bearings if b.host == "carrier"} == {a}
    zero = {"sun_p1": GearMesh(geo.sun, geo.planet),
            "p1_ring": GearMesh(geo.planet, geo.ring, internal=True)}
    assert abs(zero["sun_p1"].centre_distance - zero["p1_ring"].centre_distance) > 1e-4
    assert abs(want["sun_p1"] - zero["sun_p1"].contact_ratio) > 5e-3
    sun, ring = set_series_misses(model, _set(geo, "ring"))
    assert sun < 1e-10 and ring < 5e-3
    pins = _stage(geo, "ring", place={"carrier_radius": a})
    for name, mesh in zero.items():
        assert pins.train.mesh_data[name].table.attrs["contact_ratio"] == pytest.approx(
            mesh.contact_ratio, rel=1e-12)
    with pytest.raises(ParameterError) as err:
        _stage(geo, "ring", place={"carrier_radius": "48.5 mm", "centre_distance": a})
    assert err.value.field == "carrier_radius"
    same = _stage(geo, "ring", place={"carrier_radius": a, "centre_distance": "48.4 mm"})
    np.testing.assert_array_equal(same.fourier, model.fourier)


# ---------------------------------------------------------------- ISO waves read backwards
@pytest.mark.parametrize("held", ["ring", "sun"])
def test_iso_waves_given_reversed_on_backward_meshes_are_the_sets(held):
    """The shifted stage on ISO stiffness (double contact off the middle of the cycle): a train
    given the ISO waves of geo.waveforms() (in gear a's positive rotation) reversed in time,
    (a, -b), on its backward meshes (the ring meshes with the ring held, the sun meshes with the
    sun held) has the set's relative series on every mesh, both flanks, to 1e-12; the waves
    given as they are miss by more than 0.2 on the backward meshes."""
    h = 9
    geo = shifted_stage()
    n = geo.n_planets
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, harmonics=h, held=held, **MEMBERS)
    waves = [w.fourier(h) for w in geo.waveforms()]
    names = _stage(geo, held, stiffness="iso").mesh_names
    back = _stage(geo, held, stiffness="iso").backward_meshes()
    assert back == tuple(names[n:] if held == "ring" else names[:n])
    for reverse in (True, False):
        given = {}
        for i, name in enumerate(names):
            a, b = waves[i >= n]
            given[name] = (a, -b) if reverse and name in back else (a, b)
        model = _stage(geo, held, stiffness="iso", harmonics=h, waveform=given)
        for i, name in enumerate(names):
            ours = (model.fourier[i], model.fourier_coast[i])
            theirs = (gs.fourier[i], gs.fourier_coast[i])[::1 if i < n else -1]
            miss = max(float(np.max(np.abs(o[:2 * h] - t[:2 * h])))
                       for o, t in zip(ours, theirs, strict=True))
            if reverse or name not in back:
                assert miss < 1e-12
            else:
                assert miss > 0.2


# ---------------------------------------------------------------- Archard wear, sun held
@pytest.mark.parametrize("flank, torque", [("drive", 5.0), ("coast", 5.0), ("drive", -5.0)])
def test_planet_archard_wear_with_the_sun_held_is_the_trains(flank, torque):
    """The sun held, the carrier driven by ``torque``: Archard wear on planet 1's ``flank``.
    With the carrier driving forwards the planet presses on the held sun with the sun mesh's
    coast flank and on the ring with its drive flank (both models' static forces say so), so
    the planet's drive flank is worn by the ring mesh, its coast flank by the sun mesh (the
    other way round with the torque reversed); that mesh's table in the train is
    potential_energy_stiffness of its pair with the pair's own Archard wear on the tooth the
    mesh meets (called here), and every mesh's series of the set is the train's to 1e-10 of
    the mean."""
    geo = stage()
    z = geo.planet.teeth
    wear = dict(depth=20e-6, tooth=5, profile="archard", flank=flank)
    model = _stage(geo, "sun", (g.Wear(**wear, gear="p1"),), torque=torque)
    gs = _set(geo, "sun", [g.Wear(**wear, gear="planet1")], carrier_torque=torque,
              fixed=("sun",))
    loads, forces = model.static_loads(), gs.static_mesh_forces()
    forward = torque > 0.0
    assert (loads["sun_p1"] < 0.0) == forward and (loads["p1_ring"] > 0.0) == forward
    assert np.all((forces < 0.0) == forward)
    loading = "p1_ring" if (flank == "drive") == forward else "sun_p1"
    offsets = model._fault_offsets()
    back = model.backward_meshes()
    assert back == tuple(f"sun_p{i + 1}" for i in range(geo.n_planets))
    if loading == "p1_ring":
        role, pair, bores = "pinion", GearMesh(geo.planet, geo.ring, internal=True), (10e-3,
                                                                                      85e-3)
        at = (wear["tooth"] + offsets["p1_ring"]) % z
    else:
        role, pair, bores = "wheel", GearMesh(geo.sun, geo.planet), (12e-3, 10e-3)
        at = -wear["tooth"] % z
    own = g.Wear(depth=wear["depth"], gear=role, tooth=at, profile="archard", flank=flank)
    ref = potential_energy_stiffness(pair, bore_radius=bores, faults=(own,), cycles=z)
    table = model.fault_tables()[loading]
    for var in ("mesh_stiffness", "mesh_stiffness_coast", "fault_gap", "fault_gap_coast"):
        want = ref[var].values
        np.testing.assert_allclose(table[var].values, want, rtol=0.0,
                                   atol=1e-8 * np.max(np.abs(want)))
    assert np.max(ref["fault_gap" if flank == "drive" else "fault_gap_coast"].values) > 0.9 * (
        wear["depth"])
    sun, ring = set_series_misses(model, gs)
    assert sun < 1e-10 and ring < 1e-10
