"""The linear model of a gear train described from elements (geardyn.trains), checked against
independent computations: the closed form of a gear pair, a stiffness matrix written out by hand,
and the Lin & Parker planetary set of geardyn.PlanetaryGearSet."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

import geardyn
from geardyn.errors import ParameterError
from geardyn.gears import SpurGear
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Inertia, Mesh, Shaft

ALPHA = math.radians(20.0)


def _rb(module: float, teeth: int, alpha: float = ALPHA) -> float:
    return 0.5 * module * teeth * math.cos(alpha)


# ---------------------------------------------------------------- (a) one gear pair
def test_gear_pair_matches_two_inertia_closed_form():
    i1, i2, r1, r2, k = 2e-3, 9e-3, 0.03, 0.055, 3.2e8
    train = GearTrain(
        [Gear("pinion", i1, base_radius=r1), Gear("wheel", i2, base_radius=r2)],
        bearings=[Bearing("b1", "pinion", math.inf), Bearing("b2", "wheel", math.inf)],
        meshes=[Mesh("m", "pinion", "wheel", k)], free=True)
    m_e = i1 * i2 / (i1 * r2 ** 2 + i2 * r1 ** 2)
    f = train.natural_frequencies()
    assert f[0] == 0.0 and train.rigid_body_modes == 1
    assert f[1] == pytest.approx(math.sqrt(k / m_e) / (2 * math.pi), rel=1e-12)
    modes = train.modes()
    assert bool(modes.rigid_body[0]) and not bool(modes.rigid_body[1])
    assert float(modes.energy_share.sel(element="m")[1]) == pytest.approx(1.0, rel=1e-12)


def test_gear_pair_on_stiff_lateral_bearings_tends_to_the_torsional_frequency():
    """Lateral dofs along the line of action soften the mesh: with bearings 1e4 times the mesh
    stiffness the torsional mode is within 1e-3 of the rigid-bearing value, and below it."""
    i1, i2, r1, r2, k = 2e-3, 9e-3, 0.03, 0.055, 3.2e8
    train = GearTrain(
        [Gear("pinion", i1, mass=1.5, base_radius=r1), Gear("wheel", i2, mass=3.0,
                                                            base_radius=r2)],
        bearings=[Bearing("b1", "pinion", 1e4 * k), Bearing("b2", "wheel", 1e4 * k)],
        meshes=[Mesh("m", "pinion", "wheel", k, angle=0.7)], free=True)
    f0 = math.sqrt(k * (i1 * r2 ** 2 + i2 * r1 ** 2) / (i1 * i2)) / (2 * math.pi)
    f = train.natural_frequencies()
    assert train.dof_names() == ("pinion.theta", "pinion.x", "pinion.y", "wheel.theta",
                                 "wheel.x", "wheel.y")
    torsional = f[np.argmin(np.abs(f - f0))]
    assert torsional < f0 and torsional == pytest.approx(f0, rel=1e-3)


# ---------------------------------------------------------------- (b) two parallel stages
MODULE = 3e-3
Z = (19, 61, 23, 71)
INERTIA = (0.01, 0.35, 0.02, 0.6)
K_IN, K_MID, K_OUT, KA, KB = 4e4, 9e5, 2.5e5, 6e8, 8e8


def _two_stage(**kw) -> GearTrain:
    g = [Gear(f"g{i + 1}", INERTIA[i], base_radius=_rb(MODULE, Z[i]), n_teeth=Z[i])
         for i in range(4)]
    return GearTrain(
        g,
        shafts=[Shaft("input", "g1", GROUND, K_IN), Shaft("mid", "g2", "g3", K_MID),
                Shaft("output", "g4", GROUND, K_OUT)],
        bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf) for i in range(4)],
        meshes=[Mesh("stage1", "g1", "g2", KA), Mesh("stage2", "g3", "g4", KB)],
        driven="g1", **kw)


def _hand_matrices() -> tuple[np.ndarray, np.ndarray]:
    r1, r2, r3, r4 = (_rb(MODULE, z) for z in Z)
    K = np.array([
        [K_IN + KA * r1 ** 2, KA * r1 * r2, 0.0, 0.0],
        [KA * r1 * r2, KA * r2 ** 2 + K_MID, -K_MID, 0.0],
        [0.0, -K_MID, K_MID + KB * r3 ** 2, KB * r3 * r4],
        [0.0, 0.0, KB * r3 * r4, KB * r4 ** 2 + K_OUT]])
    return K, np.diag(INERTIA)


def test_two_stage_train_matches_hand_assembled_matrices():
    train = _two_stage()
    K, M = _hand_matrices()
    lam = eigh(K, M, eigvals_only=True)
    assert train.dof_names() == ("g1.theta", "g2.theta", "g3.theta", "g4.theta")
    assert train.natural_frequencies() == pytest.approx(np.sqrt(lam) / (2 * math.pi),
                                                        rel=1e-10)
    assert train.rigid_body_modes == 0


def test_two_stage_energy_shares_sum_to_one_and_match_hand_computation():
    modes = _two_stage().modes()
    share = modes.energy_share
    assert share.sum("element").values == pytest.approx(np.ones(4), rel=1e-12)
    K, M = _hand_matrices()
    lam, phi = eigh(K, M)
    r1, r2 = _rb(MODULE, Z[0]), _rb(MODULE, Z[1])
    stage1 = [0.5 * KA * (r1 * p[0] + r2 * p[1]) ** 2 / (0.5 * p @ K @ p) for p in phi.T]
    mid = [0.5 * K_MID * (p[1] - p[2]) ** 2 / (0.5 * p @ K @ p) for p in phi.T]
    assert share.sel(element="stage1").values == pytest.approx(stage1, rel=1e-9)
    assert share.sel(element="mid").values == pytest.approx(mid, rel=1e-9)
    assert list(modes.element_kind.values) == ["mesh", "mesh", "shaft", "shaft", "shaft"]


def test_two_stage_campbell_orders_and_crossings_from_tooth_counts():
    train = _two_stage()
    ratios = train.speed_ratios()
    assert ratios["g2"] == pytest.approx(-Z[0] / Z[1], rel=1e-12)
    assert ratios["g4"] == pytest.approx(Z[0] * Z[2] / (Z[1] * Z[3]), rel=1e-12)
    order2 = Z[2] * Z[0] / Z[1]
    ds = train.campbell(np.linspace(0.0, 3000.0, 301), harmonics=2)
    assert list(ds.order.values) == pytest.approx([Z[0], Z[0], order2, order2], rel=1e-12)
    K, M = _hand_matrices()
    f_n = np.sqrt(eigh(K, M, eigvals_only=True)) / (2 * math.pi)
    expected = 60.0 * f_n[None, :] / np.array([Z[0], 2 * Z[0], order2, 2 * order2])[:, None]
    expected = np.where(expected <= 3000.0, expected, np.nan)
    np.testing.assert_allclose(ds.crossing_speed.values, expected, rtol=1e-10)
    assert np.isfinite(ds.crossing_speed.values).any()
    assert float(ds.excitation_frequency.isel(excitation=2, speed=-1)) == pytest.approx(
        order2 * 3000.0 / 60.0, rel=1e-12)


def test_rayleigh_damping():
    train = _two_stage(rayleigh=(0.5, 1e-5))
    K, M = _hand_matrices()
    np.testing.assert_allclose(train.damping_matrix(), 0.5 * M + 1e-5 * K, rtol=1e-12)


def test_element_damping_acts_on_the_element_deflections():
    r3, r4 = _rb(MODULE, Z[2]), _rb(MODULE, Z[3])
    g = [Gear(f"g{i + 1}", INERTIA[i], base_radius=_rb(MODULE, Z[i])) for i in range(4)]
    train = GearTrain(
        g, shafts=[Shaft("input", "g1", GROUND, K_IN), Shaft("mid", "g2", "g3", K_MID, 7.0),
                   Shaft("output", "g4", GROUND, K_OUT)],
        meshes=[Mesh("stage1", "g1", "g2", KA), Mesh("stage2", "g3", "g4", KB, damping=900.0)])
    C = np.zeros((4, 4))
    C[1:3, 1:3] += 7.0 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    C[2:, 2:] += 900.0 * np.array([[r3 * r3, r3 * r4], [r3 * r4, r4 * r4]])
    np.testing.assert_allclose(train.damping_matrix(), C, rtol=1e-12, atol=1e-15)


# ---------------------------------------------------------------- (c) one planetary stage
LP = {"sun": (0.4, 0.39), "ring": (2.35, 3.0), "carrier": (5.43, 6.29), "planet": (0.66, 0.61)}
K_BEARING, K_PLANET, K_MESH, K_RING_U, K_CARRIER_U = 1e8, 1e8, 5e8, 1e9, 2e8
ZS, ZP = 23, 19
ZR = ZS + 2 * ZP
M_P = 2e-3
A_S = A_R = math.radians(24.6)


def _lp_set(n: int, fixed: tuple[str, ...], rotational_only: bool) -> geardyn.PlanetaryGearSet:
    member = {k: geardyn.Member(mass=m, inertia_over_r2=i, bearing_stiffness=K_BEARING)
              for k, (m, i) in LP.items()}
    member["ring"] = geardyn.Member(*LP["ring"], K_BEARING, torsional_stiffness=K_RING_U)
    member["carrier"] = geardyn.Member(*LP["carrier"], K_BEARING,
                                       torsional_stiffness=K_CARRIER_U)
    member["planet"] = geardyn.Member(*LP["planet"], K_PLANET)
    return geardyn.PlanetaryGearSet(n, A_S, A_R, **member, sun_mesh_stiffness=K_MESH,
                                    ring_mesh_stiffness=K_MESH, fixed=fixed,
                                    rotational_only=rotational_only)


def _element_set(n: int, fixed: tuple[str, ...], rotational_only: bool) -> GearTrain:
    """The same stage from elements; rotations in rad, so inertias I = (I/r^2) r^2 and torsional
    stiffnesses k_u r^2 (LP's u = r theta)."""
    rb = {"sun": _rb(M_P, ZS, A_S), "ring": _rb(M_P, ZR, A_R), "planet": _rb(M_P, ZP, A_S)}
    rc = 0.5 * M_P * (ZS + ZP)  # planet-centre radius
    teeth = {"sun": ZS, "ring": ZR}
    mass = (lambda k: None) if rotational_only else (lambda k: LP[k][0])  # noqa: E731
    bodies: list[Inertia] = [Gear(k, LP[k][1] * rb[k] ** 2, mass=mass(k), base_radius=rb[k],
                                  n_teeth=teeth[k]) for k in ("sun", "ring")]
    bodies.append(Inertia("carrier", LP["carrier"][1] * rc ** 2, mass=mass("carrier")))
    planet_k = math.inf if rotational_only else K_PLANET
    bearings = [] if rotational_only else [Bearing(f"{k}_bearing", k, K_BEARING)
                                           for k in ("sun", "ring", "carrier")]
    meshes = []
    for i in range(n):
        psi = 2 * math.pi * i / n
        p = f"planet{i + 1}"
        bodies.append(Gear(p, LP["planet"][1] * rb["planet"] ** 2, mass=LP["planet"][0],
                           base_radius=rb["planet"], n_teeth=ZP))
        bearings.append(Bearing(f"pin{i + 1}", p, planet_k, host="carrier", radius=rc,
                                angle=psi))
        meshes += [Mesh(f"sun_{p}", "sun", p, K_MESH, angle=psi, pressure_angle=A_S),
                   Mesh(f"{p}_ring", p, "ring", K_MESH, internal=True, angle=psi + math.pi,
                        pressure_angle=A_R)]
    shafts = [Shaft("ring_support", "ring", GROUND, K_RING_U * rb["ring"] ** 2),
              Shaft("output", "carrier", GROUND, K_CARRIER_U * rc ** 2)]
    if "ring" in fixed:
        shafts = shafts[1:]
    return GearTrain(bodies, shafts, bearings, meshes, fixed=fixed, driven="sun")


@pytest.mark.parametrize(("n", "fixed", "rotational_only"),
                         [(3, ("ring",), False), (4, (), False), (5, ("ring",), True)])
def test_planetary_stage_from_elements_matches_planetary_gear_set(n, fixed, rotational_only):
    train = _element_set(n, fixed, rotational_only)
    lp = _lp_set(n, fixed, rotational_only)
    f = train.natural_frequencies()
    assert f.size == lp.natural_frequencies().size
    np.testing.assert_allclose(f, lp.natural_frequencies(), rtol=1e-9)
    modes, lp_modes = train.modes(), lp.modes()
    np.testing.assert_allclose(modes.energy_share.sum("element").values, 1.0, rtol=1e-10)
    assert list(modes.multiplicity.values) == list(lp_modes.multiplicity.values)
    assert list(modes.type.values) == list(lp_modes.type.values)
    kinds = {"rotational"} | ({"planet"} if n >= 4 else set())
    assert kinds | ({"translational"} if not rotational_only else set()) <= set(
        modes.type.values)


def test_planetary_mesh_order_from_tooth_counts():
    """Ring fixed, sun input: the carrier turns at Z_s / (Z_s + Z_r) of the sun and the mesh
    frequency over the sun's speed is Z_s Z_r / (Z_s + Z_r) (both meshes)."""
    train = _element_set(3, ("ring",), False)
    assert train.speed_ratios()["carrier"] == pytest.approx(ZS / (ZS + ZR), rel=1e-9)
    orders = train.mesh_orders()
    assert len(orders) == 6
    for value in orders.values():
        assert value == pytest.approx(ZS * ZR / (ZS + ZR), rel=1e-9)


def test_star_arrangement_turns_the_ring_backwards():
    """Carrier held, sun input: the ring turns at -Z_s / Z_r of the sun, the planets at
    -Z_s / Z_p, and the mesh order is Z_s."""
    train = _element_set(3, ("carrier",), False)
    ratios = train.speed_ratios()
    assert ratios["ring"] == pytest.approx(-ZS / ZR, rel=1e-9)
    assert ratios["planet2"] == pytest.approx(-ZS / ZP, rel=1e-9)
    assert list(train.mesh_orders().values()) == pytest.approx([ZS] * 6, rel=1e-9)


# ---------------------------------------------------------------- (d) errors
def _spur(z: int, module: float, name: str) -> SpurGear:
    return SpurGear(z, module, ALPHA, 0.02, name=name)


def _pair(mesh: Mesh, g1: SpurGear, g2: SpurGear) -> GearTrain:
    return GearTrain([Gear("p", 1e-3, geometry=g1), Gear("w", 4e-3, geometry=g2)],
                     shafts=[Shaft("s", "p", GROUND, 1e4)], meshes=[mesh])


def test_mesh_between_different_modules_is_refused_naming_the_mesh():
    with pytest.raises(ParameterError) as err:
        _pair(Mesh("stage", "p", "w", 1e8), _spur(20, 2e-3, "p"), _spur(40, 3e-3, "w"))
    assert err.value.field == "stage.wheel.module"


def test_inconsistent_centre_distance_is_refused_naming_the_mesh():
    with pytest.raises(ParameterError) as err:
        _pair(Mesh("stage", "p", "w", 1e8, centre_distance=0.07), _spur(20, 2e-3, "p"),
              _spur(40, 2e-3, "w"))
    assert err.value.field == "stage.centre_distance"
    with pytest.raises(ParameterError) as err:  # without geometry: against radii and angle
        GearTrain([Gear("p", 1e-3, base_radius=0.02), Gear("w", 4e-3, base_radius=0.04)],
                  shafts=[Shaft("s", "p", GROUND, 1e4)],
                  meshes=[Mesh("stage", "p", "w", 1e8, centre_distance=0.07)])
    assert err.value.field == "stage.centre_distance"


def test_iso_stiffness_from_geometry():
    g1, g2 = _spur(20, 2e-3, "p"), _spur(40, 2e-3, "w")
    train = _pair(Mesh("stage", "p", "w", "iso"), g1, g2)
    expected = geardyn.gears.iso6336_stiffness(geardyn.gears.GearMesh(g1, g2)).mesh_stiffness
    assert train.mesh_data["stage"].stiffness == expected
    assert train.mesh_data["stage"].method == "iso"


def test_gear_on_no_shaft_is_refused():
    with pytest.raises(ParameterError) as err:
        GearTrain([Gear("p", 1e-3, base_radius=0.02), Gear("w", 4e-3, base_radius=0.04),
                   Gear("idle", 1e-3, base_radius=0.02)],
                  shafts=[Shaft("s", "p", GROUND, 1e4)], meshes=[Mesh("m", "p", "w", 1e8)])
    assert err.value.field == "idle"


@pytest.mark.parametrize(("make", "field"), [
    (lambda: Shaft("s", "a", GROUND, -5.0), "s.stiffness"),
    (lambda: Mesh("m", "a", "b", float("nan")), "m.stiffness"),
    (lambda: Bearing("brg", "a", "-1 N/m"), "brg.stiffness"),
    (lambda: Inertia("a", 0.0), "a.inertia"),
    (lambda: Mesh("m", "a", "b", 1e8, backlash=(1e-5, -1e-5)), "m.backlash"),
])
def test_bad_element_values_name_the_element_and_field(make, field):
    with pytest.raises(ParameterError) as err:
        make()
    assert err.value.field == field


def test_topology_errors_name_the_element_and_field():
    a, b = Gear("a", 1e-3, base_radius=0.02), Gear("b", 4e-3, base_radius=0.04)
    shaft = Shaft("s", "a", GROUND, 1e4)
    with pytest.raises(ParameterError) as err:
        GearTrain([a, b], [shaft], meshes=[Mesh("m", "a", "c", 1e8)])
    assert err.value.field == "m.b"
    with pytest.raises(ParameterError) as err:  # a free rigid-body mode, not accepted
        GearTrain([a, b], meshes=[Mesh("m", "a", "b", 1e8)],
                  bearings=[Bearing("ba", "a", math.inf)])
    assert err.value.field == "fixed"
    with pytest.raises(ParameterError) as err:  # lateral dofs need a mass
        GearTrain([a, b], [shaft], [Bearing("bb", "b", 1e8)], [Mesh("m", "a", "b", 1e8)])
    assert err.value.field == "b.mass"
    with pytest.raises(ParameterError) as err:
        GearTrain([a, b], [shaft], meshes=[Mesh("m", "a", "b", 1e8)], driven="b",
                  fixed=("b",))
    assert err.value.field == "driven"
    with pytest.raises(ParameterError) as err:  # not a gear
        GearTrain([a, Inertia("rotor", 1.0)], [shaft], meshes=[Mesh("m", "a", "rotor", 1e8)])
    assert err.value.field == "m.b"
    with pytest.raises(ParameterError) as err:  # a pair joined neither to the rest nor ground
        GearTrain([a, b, Gear("c", 1e-3, base_radius=0.02), Gear("d", 1e-3, base_radius=0.02)],
                  [shaft], meshes=[Mesh("m", "a", "b", 1e8), Mesh("m2", "c", "d", 1e8)])
    assert err.value.field == "c"
    with pytest.raises(ParameterError) as err:  # a name used twice, bodies given by an iterator
        GearTrain(iter([a, b, Gear("a", 1e-3, base_radius=0.02)]), [shaft],
                  meshes=[Mesh("m", "a", "b", 1e8)])
    assert err.value.field == "a.name"
    wheel = Gear("wheel", 4e-3, base_radius=0.04)
    held = GearTrain([a, wheel], meshes=[Mesh("m", "a", "wheel", 1e8)], fixed="wheel")
    assert held.fixed == ("wheel",) and held.dof_names() == ("a.theta",)
    with pytest.raises(ParameterError) as err:
        GearTrain([a, b], [shaft], meshes=[Mesh("m", "a", "b", 1e8)],
                  rayleigh=(0.0, float("nan")))
    assert err.value.field == "rayleigh[1]"
    with pytest.raises(ParameterError) as err:
        Mesh("m", "a", "b", 1e8, pressure_angle="95 deg")
    assert err.value.field == "m.pressure_angle"


def test_potential_energy_stiffness_is_the_mean_over_a_mesh_cycle():
    """The mean of the potential-energy wave on a finer grid (720 points a cycle) agrees to
    1e-3, and lies within 40 % of ISO 6336-1's mean stiffness."""
    g1, g2 = _spur(20, 2e-3, "p"), _spur(40, 2e-3, "w")
    train = _pair(Mesh("stage", "p", "w", "potential_energy", bore_radius=8e-3), g1, g2)
    k = train.mesh_data["stage"].stiffness
    fine = geardyn.gears.potential_energy_stiffness(geardyn.gears.GearMesh(g1, g2),
                                                    bore_radius=8e-3, angles=720)
    assert k == pytest.approx(float(fine.mesh_stiffness.mean()), rel=1e-3)
    iso = geardyn.gears.iso6336_stiffness(geardyn.gears.GearMesh(g1, g2)).mesh_stiffness
    assert 0.6 < k / iso < 1.4


def test_docs_example_gives_the_hand_assembled_frequencies():
    from pathlib import Path

    text = (Path(__file__).resolve().parent.parent / "docs" / "trains.md").read_text()
    block = text.split("```python\n", 1)[1].split("```", 1)[0]
    scope: dict = {}
    exec(block, scope)  # noqa: S102 - the documented example, run as written
    K, M = _hand_matrices()
    np.testing.assert_allclose(scope["train"].natural_frequencies(),
                               np.sqrt(eigh(K, M, eigvals_only=True)) / (2 * math.pi),
                               rtol=1e-10)


def test_campbell_plot_marks_every_crossing(tmp_path):
    from geardyn.plotting.campbell import plot_campbell

    ds = _two_stage().campbell(np.linspace(0.0, 3000.0, 61), harmonics=2)
    fig = plot_campbell(ds, tmp_path / "campbell.png")
    assert (tmp_path / "campbell.png").stat().st_size > 0
    marks = [ln for ln in fig.axes[0].lines if ln.get_label() == "crossing"][0]
    x, y = marks.get_data()
    finite = np.isfinite(ds.crossing_speed.values)
    assert len(x) == finite.sum() > 0
    np.testing.assert_allclose(np.sort(x), np.sort(ds.crossing_speed.values[finite]))
    # each crossing lies on its excitation ray: frequency = harmonic * order * rpm / 60
    rays = (ds.harmonic * ds.order).values[:, None] * ds.crossing_speed.values / 60.0
    np.testing.assert_allclose(np.sort(y), np.sort(rays[finite]), rtol=1e-12)


def test_planetary_stage_helper_matches_planetary_gear_set():
    from geardyn.trains import planetary_stage

    n = 4
    rb = {"sun": _rb(M_P, ZS, A_S), "ring": _rb(M_P, ZR, A_R), "planet": _rb(M_P, ZP, A_S)}
    rc = 0.5 * M_P * (ZS + ZP)
    stage = planetary_stage(
        sun=Gear("sun", LP["sun"][1] * rb["sun"] ** 2, LP["sun"][0], rb["sun"], n_teeth=ZS),
        ring=Gear("ring", LP["ring"][1] * rb["ring"] ** 2, LP["ring"][0], rb["ring"],
                  n_teeth=ZR),
        carrier=Inertia("carrier", LP["carrier"][1] * rc ** 2, LP["carrier"][0]),
        planet=Gear("p", LP["planet"][1] * rb["planet"] ** 2, LP["planet"][0], rb["planet"],
                    n_teeth=ZP),
        n_planets=n, pin_stiffness=K_PLANET, sun_mesh_stiffness=K_MESH,
        ring_mesh_stiffness=K_MESH, sun_pressure_angle=A_S, ring_pressure_angle=A_R)
    assert stage.carrier_radius == pytest.approx(rc, rel=1e-12)
    assert stage.planets == ("p1", "p2", "p3", "p4")
    train = GearTrain(
        stage.bodies,
        [Shaft("ring_support", "ring", GROUND, K_RING_U * rb["ring"] ** 2),
         Shaft("output", "carrier", GROUND, K_CARRIER_U * rc ** 2)],
        [*stage.bearings, *(Bearing(f"{k}_bearing", k, K_BEARING)
                            for k in ("sun", "ring", "carrier"))],
        stage.meshes, driven="sun")
    lp = _lp_set(n, (), False)
    np.testing.assert_allclose(train.natural_frequencies(), lp.natural_frequencies(), rtol=1e-9)
    assert list(train.modes().type.values) == list(lp.modes().type.values)


def test_planetary_stage_from_geometry_takes_iso_stiffness_and_orders():
    """Gears with geometry: ISO 6336-1 stiffness of each mesh as geardyn.gears computes it for
    the same pair, the carrier radius the sun-planet centre distance, and the mesh order of a
    ring-held stage Z_s Z_r / (Z_s + Z_r)."""
    from geardyn.gears import GearMesh, iso6336_stiffness
    from geardyn.trains import planetary_stage

    zs, zp, zr = 21, 33, 87
    s, p = _spur(zs, 2e-3, "sun"), _spur(zp, 2e-3, "planet")
    r = SpurGear(zr, 2e-3, ALPHA, 0.02, internal=True, name="ring")
    stage = planetary_stage(
        sun=Gear("sun", 1e-3, 1.0, geometry=s), ring=Gear("ring", 0.05, 3.0, geometry=r),
        carrier=Inertia("carrier", 0.02, 4.0), planet=Gear("p", 2e-4, 0.3, geometry=p),
        n_planets=3, pin_stiffness=1e8, sun_mesh_stiffness="iso", ring_mesh_stiffness="iso")
    assert stage.carrier_radius == pytest.approx(1e-3 * (zs + zp), rel=1e-12)
    train = GearTrain(stage.bodies, [Shaft("out", "carrier", GROUND, 1e5)],
                      [*stage.bearings, Bearing("sun_bearing", "sun", 1e8)], stage.meshes,
                      fixed="ring", driven="sun")
    k_sun = iso6336_stiffness(GearMesh(s, p)).mesh_stiffness
    k_ring = iso6336_stiffness(GearMesh(p, r, internal=True)).mesh_stiffness
    assert train.mesh_data["sun_p2"].stiffness == k_sun
    assert train.mesh_data["p2_ring"].stiffness == k_ring
    assert list(train.mesh_orders().values()) == pytest.approx([zs * zr / (zs + zr)] * 6,
                                                                rel=1e-9)
