"""Rigid shafts and compound planetary stages in a gear train's linear model: a rigid joint is
one body (closed form), and a compound stage keeps the three mode classes of Kiracofe & Parker
(2007): rotational (simple), translational (double) and planet modes (multiplicity N - 3)."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

from geardyn.errors import ParameterError
from geardyn.io.toml import load_study
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Inertia, Mesh, Shaft, planetary_stage


def test_rigid_shaft_makes_one_body():
    """g1 and its rigidly joined disc turn as one: the pair's torsional frequency is the
    closed form with their inertias summed, the disc has no coordinate and the rigid shaft
    holds no strain energy."""
    i1, i_disc, i2, r1, r2, k = 2e-3, 3e-3, 9e-3, 0.03, 0.055, 3.2e8
    train = GearTrain(
        [Gear("g1", i1, base_radius=r1), Inertia("disc", i_disc),
         Gear("g2", i2, base_radius=r2)],
        shafts=[Shaft("joint", "disc", "g1", "inf")],
        bearings=[Bearing("b1", "g1", math.inf), Bearing("b2", "g2", math.inf)],
        meshes=[Mesh("m", "g1", "g2", k)], free=True, driven="g1")
    j1 = i1 + i_disc
    f = math.sqrt(k * (j1 * r2 ** 2 + i2 * r1 ** 2) / (j1 * i2)) / (2 * math.pi)
    assert train.dof_names() == ("g1.theta", "g2.theta")
    assert train.natural_frequencies()[1] == pytest.approx(f, rel=1e-12)
    assert list(train.modes()["element"].values) == ["m"]
    assert train.speed_ratios()["disc"] == pytest.approx(1.0, rel=1e-12)


def test_rigid_shaft_to_ground_holds_the_body_and_refuses_damping():
    a, b = Gear("a", 1e-3, base_radius=0.02), Gear("b", 4e-3, base_radius=0.04)
    held = GearTrain([a, b], [Shaft("lock", "b", GROUND, math.inf)],
                     meshes=[Mesh("m", "a", "b", 1e8)])
    assert held.dof_names() == ("a.theta",)
    rb = 0.02 ** 2 * 1e8 / 1e-3
    assert held.natural_frequencies()[0] == pytest.approx(math.sqrt(rb) / (2 * math.pi),
                                                         rel=1e-12)
    with pytest.raises(ParameterError) as err:
        Shaft("lock", "b", GROUND, "inf", damping=3.0)
    assert err.value.field == "lock.damping"


N_PLANETS = 5


def _compound(n: int = N_PLANETS, **extra):
    sun = Gear("sun", 0.013, mass=2.1, base_radius=0.047, n_teeth=20)
    ring = Gear("ring", 1.9, mass=9.7, base_radius=0.17, n_teeth=80)
    carrier = Inertia("carrier", 0.31, mass=6.3)
    planet = Gear("p", 0.0041, mass=0.83, base_radius=0.052, n_teeth=22)
    second = Gear("q", 0.0017, mass=0.41, base_radius=0.031, n_teeth=13)
    stage = planetary_stage(sun=sun, ring=ring, carrier=carrier, planet=planet, n_planets=n,
                            ring_planet=second, pin_stiffness=7.3e8, sun_mesh_stiffness=4.1e8,
                            ring_mesh_stiffness=5.6e8, **extra)
    return stage, GearTrain(
        stage.bodies,
        shafts=[Shaft("input", "sun", GROUND, 2.2e4), Shaft("ring_support", "ring", GROUND,
                                                                3.7e6),
                Shaft("output", "carrier", GROUND, 8.9e5), *stage.shafts],
        bearings=[Bearing("sun_bearing", "sun", 1.3e8), Bearing("ring_bearing", "ring", 2.9e9),
                  Bearing("carrier_bearing", "carrier", 1.1e9), *stage.bearings],
        meshes=stage.meshes, driven="sun")


def test_compound_stage_keeps_the_mode_classes_of_kiracofe_and_parker():
    """Five equally spaced compound planets, every member on flexible bearings: each
    eigenspace is rotational (multiplicity 1, c + 3 = 6 of them with c = 3 central members),
    translational (multiplicity 2, 6 pairs) or a planet mode (multiplicity N - 3 = 2, 3 pairs),
    none mixed: 9 + 3 N modes in all (Kiracofe & Parker 2007, as Lin & Parker 1999 for
    simple planets)."""
    stage, train = _compound()
    modes = train.modes()
    assert modes.sizes["mode"] == 9 + 3 * N_PLANETS
    assert "q1.theta" not in train.dof_names() and "q1.x" not in train.dof_names()
    kinds = modes["type"].values
    mult = modes["multiplicity"].values
    assert Counter(kinds) == {"rotational": 6, "translational": 12, "planet": 6}
    assert set(mult[kinds == "rotational"]) == {1}
    assert set(mult[kinds == "translational"]) == {2}
    assert set(mult[kinds == "planet"]) == {N_PLANETS - 3}


def test_compound_stage_without_equal_spacing_mixes_the_classes():
    """The classes need the symmetry: planets moved off equal spacing give mixed modes (the
    check can fail)."""
    _, train = _compound(planet_angles=["0 deg", "70 deg", "150 deg", "220 deg", "290 deg"])
    assert "mixed" in set(train.modes()["type"].values)


def test_compound_mesh_orders_and_ratios_follow_the_tooth_counts():
    """Ring held, z_r = z_s + z_p + z_q (one module): the sun drives, the carrier turns at
    1 / (1 + z_r z_p / (z_s z_q)) (the compound planetary ratio), and every mesh's order is
    taken relative to the carrier."""
    ring = Gear("ring", 1.9, base_radius=0.0025 * 55 / 2, n_teeth=55)
    planet = Gear("p", 0.0041, base_radius=0.0025 * 22 / 2, n_teeth=22)
    second = Gear("q", 0.0017, base_radius=0.0025 * 13 / 2, n_teeth=13)
    sun = Gear("sun", 0.013, base_radius=0.0025 * 20 / 2, n_teeth=20)
    carrier = Inertia("carrier", 0.31)
    stage = planetary_stage(sun=sun, ring=ring, carrier=carrier, planet=planet, n_planets=3,
                            ring_planet=second, pin_stiffness=math.inf,
                            sun_mesh_stiffness=4e8, ring_mesh_stiffness=5e8)
    train = GearTrain(stage.bodies, [Shaft("out", "carrier", GROUND, 1e5), *stage.shafts],
                      stage.bearings, stage.meshes, fixed="ring", driven="sun")
    ratio = 1.0 / (1.0 + 55 * 22 / (20 * 13))
    r = train.speed_ratios()
    assert r["carrier"] == pytest.approx(ratio, rel=1e-12)
    orders = train.mesh_orders()
    assert orders["sun_p1"] == pytest.approx(20 * (1 - ratio), rel=1e-12)
    assert orders["q1_ring"] == pytest.approx(55 * ratio, rel=1e-12)


COMPOUND = """
[train]
driven = "sun"

[train.gears.sun]
inertia = 0.013
mass = 2.1
base_radius = 0.047

[train.gears.p]
inertia = 0.0041
mass = 0.83
base_radius = 0.052

[train.gears.q]
inertia = 0.0017
mass = 0.41
base_radius = 0.031

[train.gears.ring]
inertia = 1.9
mass = 9.7
base_radius = 0.17

[train.inertias.carrier]
inertia = 0.31
mass = 6.3

[train.shafts.input]
a = "sun"
b = "ground"
stiffness = 2.2e4

[train.shafts.ring_support]
a = "ring"
b = "ground"
stiffness = 3.7e6

[train.shafts.output]
a = "carrier"
b = "ground"
stiffness = 8.9e5

[train.bearings.sun_bearing]
body = "sun"
stiffness = 1.3e8

[train.bearings.ring_bearing]
body = "ring"
stiffness = 2.9e9

[train.bearings.carrier_bearing]
body = "carrier"
stiffness = 1.1e9

[train.planetary.stage]
sun = "sun"
ring = "ring"
carrier = "carrier"
planet = "p"
ring_planet = "q"
n_planets = 5
pin_stiffness = 7.3e8
sun_mesh_stiffness = 4.1e8
ring_mesh_stiffness = 5.6e8
"""


def test_toml_compound_stage_equals_python_bitwise():
    from test_trains_toml import assert_same_train

    _, by_api = _compound()
    by_toml = load_study(COMPOUND).gear_train
    # same elements, in the order the [train] table defines (see geardyn.io.train_table)
    order = ["sun", "p1", "p2", "p3", "p4", "p5", "q1", "q2", "q3", "q4", "q5", "ring",
             "carrier"]
    assert list(by_toml.bodies) == order
    reordered = GearTrain([by_api.bodies[n] for n in order], by_api.shafts, by_api.bearings,
                          by_api.meshes, driven="sun")
    assert_same_train(by_toml, reordered)
    assert np.allclose(by_toml.natural_frequencies(), by_api.natural_frequencies(),
                       rtol=1e-10)
