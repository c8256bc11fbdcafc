"""The built-in study of the NREL 5 MW reference gearbox (Nejad et al. 2016) against the values
published for it: the gear data of Table V (centre distances, tip and root diameters, stage
ratios), the turbine's first drivetrain torsional frequency, and the stand-ins the study states
for what is not published (body masses and inertias from the geometry)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.gears import GearMesh, HelicalMesh
from geardyn.io.toml import builtin_study

#: Nejad et al. 2016, Table V (as reproduced in gfsReboucas/Drivetrain, @NREL_5MW/NREL_5MW.m):
#: per body, (tip diameter, root diameter) [mm].
TABLE_V_DIAMETERS = {
    "sun1": (978.839, 798.061), "pa": (905.440, 724.662), "ring1": (2475.087, 2677.507),
    "sun2": (432.845, 341.845), "pb": (815.655, 724.655), "ring2": (1906.074, 2000.574),
    "pinion3": (380.751, 319.627), "wheel3": (1395.372, 1334.248)}
#: Table V: centre distances [mm] and stage ratios.
TABLE_V_CENTRE_DISTANCE = {1: 863.0, 2: 584.0, 3: 861.0}
TABLE_V_RATIOS = (3.947, 6.167, 3.958)
#: First torsional frequency of the turbine's drivetrain, free-free [Hz] (Anaya-Lara et al.
#: 2019, p. 45, as cited in @NREL_5MW/NREL_5MW.m).
DRIVETRAIN_FREE_FREE_HZ = 2.18


@pytest.fixture(scope="module")
def study():
    return builtin_study("nrel_5mw_gearbox")


@pytest.fixture(scope="module")
def train(study):
    return study.gear_train


def _geometry(train, name):
    g = train.bodies[name if name in train.bodies else f"{name}1"].geometry
    return getattr(g, "transverse", g)


def test_gear_geometry_reproduces_table_v_diameters(train):
    """Tip and root diameters within 0.1 mm of Table V (its values are KISSsoft's, given to
    3 decimals with the tip alteration to 3 decimals of a millimetre)."""
    for name, (tip, root) in TABLE_V_DIAMETERS.items():
        g = _geometry(train, name)
        assert 2e3 * g.tip_radius == pytest.approx(tip, abs=0.1), name
        assert 2e3 * g.root_radius == pytest.approx(root, abs=0.1), name


def test_zero_backlash_centre_distances_are_table_v(train):
    """The tooth counts and profile shifts close each stage at Table V's centre distance:
    sun-planet and planet-ring alike (within 0.01 mm), the helical stage from its transverse
    sections."""
    b = train.bodies
    for stage, sun, planet, ring in ((1, "sun1", "pa1", "ring1"), (2, "sun2", "pb1", "ring2")):
        external = GearMesh(b[sun].geometry, b[planet].geometry)
        internal = GearMesh(b[planet].geometry, b[ring].geometry, internal=True)
        for mesh in (external, internal):
            assert 1e3 * mesh.centre_distance == pytest.approx(
                TABLE_V_CENTRE_DISTANCE[stage], abs=0.01)
    helical = HelicalMesh(b["pinion3"].geometry, b["wheel3"].geometry)
    assert 1e3 * helical.centre_distance == pytest.approx(TABLE_V_CENTRE_DISTANCE[3], abs=0.01)


def test_stage_ratios_are_table_v(train):
    r = train.speed_ratios()
    got = (r["sun1"] / r["carrier1"], r["sun2"] / r["carrier2"], -r["pinion3"] / r["wheel3"])
    assert got == pytest.approx(TABLE_V_RATIOS, abs=5e-4)  # Table V gives 3 decimals
    assert abs(r["generator"]) == pytest.approx(np.prod(TABLE_V_RATIOS), rel=1e-3)


def test_stand_in_masses_and_inertias_follow_the_stated_formula(train):
    """No silent numbers: the study's masses and inertias are those of the steel annuli it
    states (density 7830 kg/m^3; gears from the bore to the reference circle, carriers from
    0.7 to 1.3 a_w, face width wide), to the 5 digits written."""
    rho = 7830.0
    bores = {"sun1": 0.4, "pa1": 0.4, "sun2": 0.2, "pb1": 0.38, "pinion3": 0.2, "wheel3": 0.4}
    width = {"sun1": 0.491, "pa1": 0.491, "sun2": 0.55, "pb1": 0.55, "pinion3": 0.36,
             "wheel3": 0.36}

    def annulus(outer, inner, b):
        m = rho * math.pi * b * (outer ** 2 - inner ** 2)
        return m, 0.5 * m * (outer ** 2 + inner ** 2)

    for name, bore in bores.items():
        g = _geometry(train, name)
        m, inertia = annulus(g.reference_radius, bore / 2, width[name])
        body = train.bodies[name]
        assert body.inertia == pytest.approx(inertia, rel=1e-4), name
        if body.mass is not None:
            assert body.mass == pytest.approx(m, rel=1e-4), name
    for name, a_w, b in (("carrier1", 0.863, 0.491), ("carrier2", 0.584, 0.55)):
        m, inertia = annulus(1.3 * a_w, 0.7 * a_w, b)
        assert train.bodies[name].inertia == pytest.approx(inertia, rel=1e-4), name
        assert train.bodies[name].mass == pytest.approx(m, rel=1e-4), name


def test_first_drivetrain_mode_against_the_published_frequency(train):
    """The first elastic mode is the drivetrain's torsion on the main shaft. It is bounded by
    the two-inertia value of the rigid gearbox, sqrt(k (1/J_R + 1/J_G,eq)) with J_G,eq the
    kinetic energy of every other body referred to the rotor speed (a Rayleigh bound: the
    gearbox's own compliance only lowers it), and lies within 15 % of the published 2.18 Hz.
    The tolerance: the gearbox's body inertias are stand-ins (they make 12 % of
    J_G,eq) and the published value comes from a turbine model with flexible blades."""
    modes = train.modes()
    f = modes["frequency"].values
    assert f[0] == 0.0 and train.rigid_body_modes == 1
    first = f[1]
    assert modes["energy_share"].sel(element="main").values[1] > 0.8
    r = train.speed_ratios()
    planets = {n: train.bearings[[b.body for b in train.bearings].index(n)]
               for n in train.bodies if n[:2] in ("pa", "pb")}
    j_eq = 0.0
    for name, body in train.bodies.items():
        if name in ("rotor", "ring1", "ring2"):
            continue
        j_eq += body.inertia * r[name] ** 2
        if name in planets:
            pin = planets[name]
            j_eq += body.mass * (pin.radius * r[pin.host]) ** 2
    k_main = train.shafts[0].stiffness
    j_rotor = train.bodies["rotor"].inertia
    bound = math.sqrt(k_main * (1.0 / j_rotor + 1.0 / j_eq)) / (2.0 * math.pi)
    assert first <= bound * (1.0 + 1e-9)
    assert first == pytest.approx(bound, rel=0.1)
    assert first == pytest.approx(DRIVETRAIN_FREE_FREE_HZ, rel=0.15)


def test_campbell_orders_follow_the_tooth_counts(train):
    """Mesh orders (mesh frequency over rotor speed): z_ring of stage 1 (carrier = rotor),
    z_ring2 times the speed of carrier 2 over it, z_wheel3 times the wheel's ratio. The pins
    sit at Table V's 863 mm, 4 um off the zero-backlash distance of the geometry: the rigid
    kinematics then carry a relative error of about 1e-5."""
    orders = train.mesh_orders()
    r = train.speed_ratios()
    assert orders["sun1_pa1"] == pytest.approx(56.0, rel=1e-4)
    assert orders["pb1_ring2"] == pytest.approx(93.0 * r["carrier2"], rel=1e-4)
    assert orders["stage3"] == pytest.approx(95.0 * abs(r["wheel3"]), rel=1e-12)
