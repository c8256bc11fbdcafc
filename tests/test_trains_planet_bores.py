"""Per-gear bore radii of a train's meshes (``Mesh.bore_radius`` a pair, the planetary stage's
``sun_bore_radius``, ``planet_bore_radius``, ``ring_rim_radius``): the potential-energy
stiffness on a planetary stage's ring meshes, and Archard wear on a planet of a train.

Checks: a ring-planet mesh's table is potential_energy_stiffness of that internal pair with the
same bores (called here); a stage on the potential-energy stiffness of both meshes has mean
stiffnesses equal to the means of tables computed here and runs, and on every mesh
PlanetaryGearSet.from_geometry's series with the same bores (drive and coast), healthy and with a
cracked planet; a mesh whose gear a turns in the negative sense reads its tables backwards in
time (a pair driven from its wheel is SpurPair's mirror image; its mirrored coast flank lies
about -phi); Archard wear on a planet's flank (the sun mesh loads one flank, the ring mesh the
other) is, in the mesh that loads it, that pair's own Archard wear (its table computed here)
and, in the other mesh, opens that mesh's depth at the flank point of its contacts; bad bores
are refused naming the field, in Python and in a study file.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest
from pydantic import ValidationError

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, potential_energy_stiffness
from geardyn.io.toml import load_study
from geardyn.models.spur_pair import evaluate_series
from geardyn.trains import (
    Bearing,
    Gear,
    GearTrain,
    Inertia,
    Mesh,
    Shaft,
    TrainModel,
    planetary_stage,
)
from test_planetary_pe import MEMBERS, stage
from test_trains_faults import _train_stiffness, set_series_misses
from test_trains_faults_wear import assert_wear_follows_the_loading_mesh

#: Bores [m]: sun, planet, the ring's rim radius (those of tests/test_planetary_pe.py).
SUN_BORE, PLANET_BORE, RIM = 12e-3, 10e-3, 85e-3
BORES = dict(sun_bore_radius="12 mm", planet_bore_radius="10 mm", ring_rim_radius="85 mm")
DEPTH = 20e-6
H = 4


def _train(faults=(), **bores) -> GearTrain:
    """The 25/23/71 stage of four planets from elements, both meshes on the potential-energy
    stiffness, ring held, sun driven, carrier on an output shaft."""
    geo = stage()
    st = planetary_stage(
        sun=Gear("sun", 1e-3, mass=0.5, geometry=geo.sun),
        ring=Gear("ring", 1.0, mass=3.0, geometry=geo.ring),
        carrier=Inertia("carrier", 0.1, mass=5.0),
        planet=Gear("p", 1e-3, mass=0.3, geometry=geo.planet), n_planets=4, pin_stiffness=1e8,
        sun_mesh_stiffness="potential_energy", ring_mesh_stiffness="potential_energy",
        **(bores or BORES))
    bearings = [Bearing(f"{k}_bearing", k, 1e8) for k in ("sun", "ring", "carrier")]
    return GearTrain(st.bodies, [Shaft("output", "carrier", "ground", 1e6)],
                     [*bearings, *st.bearings], st.meshes, fixed=("ring",), driven="sun",
                     faults=faults)


def _model(faults=(), **kw) -> TrainModel:
    return TrainModel(_train(faults), torques={"sun": 5.0}, mesh_phase="geometry",
                      harmonics=H, **kw)


# ---------------------------------------------------------------- step 1: the bores
def test_ring_mesh_table_is_the_internal_pairs_with_its_bores():
    """p1_ring (planet p1 with the ring) takes (planet's bore, ring's rim radius); its table is
    potential_energy_stiffness of GearMesh(planet, ring, internal) with those, called here."""
    geo = stage()
    train = _train()
    mesh = next(m for m in train.meshes if m.name == "p1_ring")
    assert mesh.internal and mesh.bore_radius == (PLANET_BORE, RIM)
    assert next(m for m in train.meshes if m.name == "sun_p1").bore_radius == (SUN_BORE,
                                                                               PLANET_BORE)
    want = potential_energy_stiffness(GearMesh(geo.planet, geo.ring, internal=True),
                                      bore_radius=(PLANET_BORE, RIM))
    got = train.mesh_data["p1_ring"].table
    for var in ("mesh_stiffness", "mesh_stiffness_coast"):
        np.testing.assert_array_equal(got[var].values, want[var].values)
    assert train.mesh_data["p1_ring"].stiffness == pytest.approx(
        float(want["mesh_stiffness"].mean()), rel=1e-15)


def test_stage_on_potential_energy_stiffness_runs_on_the_tables_means():
    """Both meshes of every planet on the potential-energy stiffness: the means (drive and
    coast) are those of the two tables computed here; a short run ends with finite states and
    mesh forces."""
    geo = stage()
    model = _model()
    n = geo.n_planets
    sun = potential_energy_stiffness(GearMesh(geo.sun, geo.planet),
                                     bore_radius=(SUN_BORE, PLANET_BORE))
    ring = potential_energy_stiffness(GearMesh(geo.planet, geo.ring, internal=True),
                                      bore_radius=(PLANET_BORE, RIM))
    for var, got in (("mesh_stiffness", model.mesh_stiffnesses()),
                     ("mesh_stiffness_coast", model.coast_stiffnesses())):
        want = [float(sun[var].mean())] * n + [float(ring[var].mean())] * n
        np.testing.assert_allclose(got, want, rtol=1e-13)
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0.0, samples=3,
                                                         steps_per_period=64))
    assert ds.attrs["mesh_stiffness_methods"] == ",".join(["potential_energy"] * 2 * n)
    assert np.all(np.isfinite(ds["poincare"].values))
    for m in model.mesh_names:
        assert np.all(np.isfinite(ds[f"F_{m}"].values))


def test_stage_meshes_are_the_planetary_sets():
    """Every mesh's series is PlanetaryGearSet.from_geometry's with the same bores (mesh phases
    from the geometry: the set's Parker & Lin phases) to 1e-10 of the mean: a sun-planet mesh
    flank by flank; a planet-ring mesh with the flanks named the other way round (the train's
    drive flank of the ring mesh is the planet's flank the sun loads, the set's coast flank
    there), its table read backwards in time (the planet, gear a, turns in the negative sense
    relative to the carrier)."""
    geo = stage()
    model = _model()
    n = geo.n_planets
    assert model.backward_meshes() == tuple(f"p{i + 1}_ring" for i in range(n))
    gs = geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=H, stiffness="potential_energy", stiffness_options=BORES, **MEMBERS)
    assert model._kernel_orders.tolist() == [1.0] * (2 * n)
    assert max(set_series_misses(model, gs, points=721)) <= 1e-10


@pytest.mark.parametrize("shift", [0.0, 0.3])
def test_pair_driven_from_the_wheel_is_the_spur_pairs_mirror_image(shift):
    """A one-stage train driven from its wheel w (w turns in the positive sense, the pinion p,
    gear a, in the negative): its mirror image is SpurPair of the same gears (pinion turning
    positive) with p's flanks swapped, so the train's drive flank is SpurPair's coast flank and
    its coast flank SpurPair's drive flank, each moved by the coast phase phi (SpurPair's coast
    flank of tooth 0 passes phi mesh cycles after its drive flank, where the train's drive flank
    passes at 0). Unshifted gears (phi = 1/2, on the tables' 360 angles) to 1e-12 of the peak;
    pinion profile shift 0.3 (phi = 0.556, off the grid: the two flanks' tables are sampled at
    different points of the stiffness, whose jumps the series then resolve differently) to
    1e-2 (read forwards the train is off by half the peak). Driven from the pinion: flank by
    flank."""
    from geardyn.gears.potential_energy import coast_phase

    pinion = g.SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, profile_shift=shift)
    wheel = g.SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, profile_shift=-shift / 3.0)
    phi = coast_phase(GearMesh(pinion, wheel))
    assert (abs(phi - 0.5) > 0.05) == (shift > 0.0)
    tol = 1e-2 if shift else 1e-12
    pair = geardyn.SpurPair.from_geometry(GearMesh(pinion, wheel), bore_radius=8e-3,
                                          speed=100.0, torque=40.0, harmonics=H,
                                          period="mesh", angles=360,
                                          inertia=(2.4e-4, 8.5e-3))
    theta = np.linspace(0.0, 2.0 * math.pi, 997)
    for driven, other in (("p", "w"), ("w", "p")):
        train = GearTrain([Gear("p", 2.4e-4, geometry=pinion), Gear("w", 8.5e-3, geometry=wheel)],
                          bearings=[Bearing("bp", "p", math.inf), Bearing("bw", "w", math.inf)],
                          meshes=[Mesh("m", "p", "w", "potential_energy", bore_radius=8e-3)],
                          driven=driven, free=True)
        model = TrainModel(train, torques={driven: 40.0}, load=other, harmonics=H)
        back = driven == "w"
        assert model.backward_meshes() == (("m",) if back else ())
        for coast in (False, True):
            theirs = pair.coast_series if coast != back else pair.drive_series
            want = evaluate_series(theirs, theta + (2.0 * math.pi * phi if back else 0.0))
            got = _train_stiffness(model, 0, theta, coast)
            np.testing.assert_allclose(got, want, rtol=0.0,
                                       atol=(tol if back else 1e-12) * np.max(want))


def test_backward_mesh_mirrors_its_coast_flank_about_minus_the_coast_phase():
    """Driven from the wheel, the profile-shifted pair (coast phase phi = 0.556) meets a
    tooth's coast flank phi mesh cycles before its drive flank: the coast flank of its
    potential-energy tables, read backwards, is the drive flank's mirror image about -phi,
    k_c(theta) = k_d(-2 pi phi - theta), to 1e-2 of the peak (the tables' sampling, as above;
    about +phi it is off by more than 5e-2); a mesh of the same gears with a given stiffness
    and waveform takes that mirror image for its coast flank, to 1e-12."""
    from geardyn.gears.potential_energy import coast_phase

    pinion = g.SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, profile_shift=0.3)
    wheel = g.SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, profile_shift=-0.1)
    phi = coast_phase(GearMesh(pinion, wheel))
    theta = np.linspace(0.0, 2.0 * math.pi, 997)

    def model(stiffness, **kw):
        train = GearTrain([Gear("p", 2.4e-4, geometry=pinion), Gear("w", 8.5e-3, geometry=wheel)],
                          bearings=[Bearing("bp", "p", math.inf), Bearing("bw", "w", math.inf)],
                          meshes=[Mesh("m", "p", "w", stiffness, bore_radius=8e-3)],
                          driven="w", free=True)
        return TrainModel(train, torques={"w": 40.0}, load="p", harmonics=H, **kw)

    pe = model("potential_energy")
    peak = np.max(_train_stiffness(pe, 0, theta))
    coast = _train_stiffness(pe, 0, theta, coast=True)
    for sign, within in ((-1.0, True), (1.0, False)):
        mirror = _train_stiffness(pe, 0, sign * 2.0 * math.pi * phi - theta)
        assert (np.max(np.abs(coast - mirror)) < 1e-2 * peak) == within
        assert within or np.max(np.abs(coast - mirror)) > 5e-2 * peak
    given = model(3e8, waveform=([0.15, 0.05], [0.2, -0.04]))
    np.testing.assert_allclose(_train_stiffness(given, 0, theta, coast=True),
                               _train_stiffness(given, 0, -2.0 * math.pi * phi - theta),
                               rtol=1e-12)


def test_bad_bores_are_named():
    """A pair of three, an unreadable rim radius, one bore for a ring mesh (the ring's rim then
    inside its teeth) and a stage without a planet bore are refused naming the field and the
    gear."""
    geo = stage()
    with pytest.raises(ParameterError) as err:
        Mesh("r", "p", "ring", "potential_energy", internal=True, bore_radius=(1, 2, 3))
    assert err.value.field == "r.bore_radius"
    with pytest.raises(ParameterError) as err:
        Mesh("r", "p", "ring", "potential_energy", internal=True, bore_radius=("10 mm", "x"))
    assert err.value.field == "r.bore_radius" and "ring's rim radius" in err.value.reason
    with pytest.raises(ParameterError) as err:
        Mesh("r", "p", "ring", "potential_energy", internal=True, bore_radius=("10 mm", -1.0))
    assert err.value.field == "r.bore_radius" and err.value.reason.startswith("ring's")
    with pytest.raises(ParameterError) as err:
        GearTrain([Gear("p", 1e-3, geometry=geo.planet), Gear("ring", 1.0, geometry=geo.ring)],
                  bearings=[Bearing("bp", "p", math.inf), Bearing("br", "ring", math.inf)],
                  meshes=[Mesh("r", "p", "ring", "potential_energy", internal=True,
                               bore_radius="10 mm")], driven="p", free=True)
    assert err.value.field == "r.bore_radius" and "ring's rim radius" in err.value.reason
    assert "give two" in err.value.reason
    with pytest.raises(ParameterError) as err:
        _train(sun_bore_radius="12 mm", ring_rim_radius="85 mm")
    assert err.value.field == "planet_bore_radius"
    with pytest.raises(ParameterError) as err:
        _train(**BORES, ring_planet_bore_radius="10 mm")
    assert err.value.field == "ring_planet_bore_radius"


STUDY = """\
[study]
name = "planet_bores"
model = "train"
[params]
torques = {{ sun = 5.0 }}
mesh_phase = "geometry"
harmonics = 4
[train]
driven = "sun"
fixed = ["ring"]
[train.gears.sun]
inertia = 1e-3
mass = 0.5
geometry = {{ teeth = 25, module = "2 mm", pressure_angle = "20 deg", face_width = "20 mm" }}
[train.gears.ring]
inertia = 1.0
mass = 3.0
geometry = {{ teeth = 71, module = "2 mm", pressure_angle = "20 deg", face_width = "20 mm", \
internal = true }}
[train.gears.p]
inertia = 1e-3
mass = 0.3
geometry = {{ teeth = 23, module = "2 mm", pressure_angle = "20 deg", face_width = "20 mm" }}
[train.inertias.carrier]
inertia = 0.1
mass = 5.0
[train.shafts.output]
a = "carrier"
b = "ground"
stiffness = 1e6
[train.bearings.sun_bearing]
body = "sun"
stiffness = 1e8
[train.bearings.carrier_bearing]
body = "carrier"
stiffness = 1e8
[train.planetary.stage]
sun = "sun"
ring = "ring"
carrier = "carrier"
planet = "p"
n_planets = 4
pin_stiffness = 1e8
sun_mesh_stiffness = "potential_energy"
ring_mesh_stiffness = "potential_energy"
{stage}
{extra}
"""


def test_study_file_takes_the_bores(tmp_path):
    """A [train.planetary] table takes the stage's bore radii and a [train.meshes] table a
    bore_radius pair of unit strings: the same tables as in Python; a bad radius is an error
    naming train.meshes.<mesh>.bore_radius (or the stage's key)."""
    stage_bores = 'sun_bore_radius = "12 mm"\nplanet_bore_radius = "10 mm"\n' \
                  'ring_rim_radius = "85 mm"'
    def study(stage_text: str, more: str = ""):
        path = tmp_path / "planet_bores.toml"
        path.write_text(STUDY.format(stage=stage_text, extra=more))
        return load_study(path)

    train = study(stage_bores).gear_train
    python = _train()
    for name in ("sun_p2", "p2_ring"):
        np.testing.assert_array_equal(train.mesh_data[name].table["mesh_stiffness"].values,
                                      python.mesh_data[name].table["mesh_stiffness"].values)
    internal = textwrap.dedent("""\
        [train.gears.q]
        inertia = 1e-3
        geometry = {{ teeth = 23, module = "2 mm", pressure_angle = "20 deg", \
face_width = "20 mm" }}
        [train.meshes.q_ring]
        a = "q"
        b = "ring"
        internal = true
        angle = "180 deg"
        stiffness = "potential_energy"
        bore_radius = {bores}
        """)
    got = study(stage_bores, internal.format(bores='["10 mm", "85 mm"]')).gear_train
    np.testing.assert_array_equal(got.mesh_data["q_ring"].table["mesh_stiffness"].values,
                                  python.mesh_data["p1_ring"].table["mesh_stiffness"].values)
    for bores, says in (('["10 mm", "1 mm"]', "ring's rim radius"),
                        ('"10 mm"', "give two"), ('["10 mm", "85 mm", "90 mm"]', "or two")):
        with pytest.raises(ValidationError) as err:
            study(stage_bores, internal.format(bores=bores))
        (error,) = err.value.errors()
        assert error["loc"] == ("train", "meshes", "q_ring", "bore_radius")
        assert says in error["msg"]
    with pytest.raises(ValidationError) as err:
        study('sun_bore_radius = "12 mm"\nring_rim_radius = "85 mm"')
    assert err.value.errors()[0]["loc"] == ("train", "planetary", "stage", "planet_bore_radius")


# ---------------------------------------------------------------- step 2: Archard on a planet
@pytest.mark.parametrize("flank", ["drive", "coast"])
def test_planet_flank_takes_the_wear_of_the_mesh_that_loads_it(flank):
    """The sun drives: each sun-planet mesh force is positive (the planet's drive flank, the
    planet the wheel), each planet-ring mesh force negative (the planet's coast flank, the
    planet the pinion of the internal pair): the torque balance of the planet. Archard wear on
    p1's drive (coast) flank is then that of sun_p1 (p1_ring) alone: that mesh's table equals
    potential_energy_stiffness of its pair with the same wear and bores (called here, the
    fault on the pair's gear and tooth), and the other mesh's contacts on the worn flank open
    the loading mesh's depth at their flank point (0 below its lowest contact on the flank)."""
    geo = stage()
    tooth, z = 5, geo.planet.teeth
    wear = g.Wear(depth=DEPTH, gear="p1", tooth=tooth, profile="archard", flank=flank)
    model = _model((wear,))
    loads = model.static_loads()
    assert loads["sun_p1"] > 0.0 and loads["p1_ring"] == pytest.approx(-loads["sun_p1"],
                                                                       rel=1e-9)
    assert model.faults.meshes == ("sun_p1", "p1_ring") and model.mesh_order == z
    offsets = model._fault_offsets()
    # the planet, gear a of p1_ring, turns in the negative sense relative to the carrier: that
    # mesh's table is read backwards in time, the tooth passing at c = j the table's tooth -j
    assert "p1_ring" in model.backward_meshes() and "sun_p1" not in model.backward_meshes()
    on = {"sun_p1": ("wheel", GearMesh(geo.sun, geo.planet), (SUN_BORE, PLANET_BORE), tooth),
          "p1_ring": ("pinion", GearMesh(geo.planet, geo.ring, internal=True),
                      (PLANET_BORE, RIM), -(tooth + offsets["p1_ring"]) % z)}
    assert_wear_follows_the_loading_mesh(model, on, flank, DEPTH, z)
    # the other planets' meshes are healthy
    assert set(model.fault_tables()) == {"sun_p1", "p1_ring"}


def test_cracked_planet_of_a_train_stage_is_the_planetary_sets():
    """A crack on tooth 7 of planet p1: over p1's revolution relative to the carrier (23 mesh
    cycles) every mesh's stiffness equals PlanetaryGearSet.from_geometry's with the same crack
    on planet1 (its tooth passages from the planet's half turn between its two pitch points,
    geardyn.models.planetary_faults): the train's, from its passage step across the planet and
    the ring mesh read backwards, put the crack on p1_ring's table at the same time. Drive and
    coast (the ring meshes' flanks named the other way round), the healthy planets' meshes at
    their orders, to 1e-10 of the mean."""
    geo = stage()
    crack = dict(depth="1.5 mm", angle="45 deg", tooth=7)
    model = _model((g.RootCrack(**crack, gear="p1"),))
    assert model.mesh_order == geo.planet.teeth
    gs = geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=H, stiffness="potential_energy", stiffness_options=BORES,
        faults=[g.RootCrack(**crack, gear="planet1")], **MEMBERS)
    assert gs.mesh_order == geo.planet.teeth
    assert max(set_series_misses(model, gs)) <= 1e-10


@pytest.mark.parametrize("flank, torque", [("drive", 5.0), ("coast", 5.0), ("drive", -5.0)])
def test_planet_archard_wear_of_the_planetary_set_is_the_trains(flank, torque):
    """PlanetaryGearSet.from_geometry with Archard wear on planet1 (each of its meshes wearing
    the flank it loads under the mean torques, from the healthy set's static mesh forces) has,
    on every mesh, the series of the train stage with the same wear on p1 (checked above
    against single-pair tables), drive and coast (the ring meshes' flanks named the other way
    round), to 1e-10 of the mean; a reversed sun torque moves the drive flank's wear to the
    ring mesh in both. Without torques the set refuses it naming ``wear.flank``."""
    geo = stage()
    wear = dict(depth=DEPTH, tooth=5, profile="archard", flank=flank)
    model = TrainModel(_train((g.Wear(**wear, gear="p1"),)), torques={"sun": torque},
                       mesh_phase="geometry", harmonics=H)
    gs = geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=H, stiffness="potential_energy", stiffness_options=BORES,
        faults=[g.Wear(**wear, gear="planet1")], sun_torque=torque, **MEMBERS)
    assert np.all(np.sign(gs.static_mesh_forces()) == np.sign(torque))
    assert max(set_series_misses(model, gs)) <= 1e-10
    if torque > 0.0 and flank == "drive":
        with pytest.raises(ParameterError) as err:
            geardyn.PlanetaryGearSet.from_geometry(
                geo, harmonics=H, stiffness="potential_energy", stiffness_options=BORES,
                faults=[g.Wear(**wear, gear="planet1")], **MEMBERS)
        assert err.value.field == "wear.flank"
