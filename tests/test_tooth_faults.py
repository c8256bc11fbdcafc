"""Spall, wear, broken tooth and several faults at once in the potential-energy stiffness.

References are written out here independently of the module: the tooth integrals by SciPy's
quad over Tian's sections with the faulty section built from its rectangles, the geometry of
the unshifted 19/48 pair from the textbook relations, the involute arc length r_b t^2 / 2.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad

from geardyn.errors import ParameterError
from geardyn.gears import (
    FAULT_KINDS,
    BrokenTooth,
    GearMesh,
    RootCrack,
    Spall,
    Wear,
    loaded_contact,
    potential_energy_stiffness,
)
from geardyn.gears.potential_energy import prepare_pair, tooth_compliances
from pair_19_48 import ALPHA, BORES, NU, Z1, Z2, B, E, M, pair_mesh

HUNT = Z1 * Z2  # lcm(19, 48)


@pytest.fixture(scope="module")
def mesh() -> GearMesh:
    return pair_mesh()


@pytest.fixture(scope="module")
def healthy(mesh: GearMesh):
    return potential_energy_stiffness(mesh, bore_radius=BORES, angles=40, cycles=Z1)


def _run(mesh: GearMesh, faults, angles: int = 40, cycles: int = Z1):
    return potential_energy_stiffness(mesh, bore_radius=BORES, angles=angles, cycles=cycles,
                                      faults=faults)


# -- independent geometry of the unshifted pinion (r_f < r_b: straight root flank) ------------


def _pinion() -> dict[str, float]:
    r = M * Z1 / 2.0
    rw = M * Z2 / 2.0
    rb, ra = r * math.cos(ALPHA), r + M
    rb2, ra2 = rw * math.cos(ALPHA), rw + M
    a = r + rw
    return {"rb": rb, "rf": r - 1.25 * M, "ra": ra,
            "a2": math.pi / (2.0 * Z1) + math.tan(ALPHA) - ALPHA,
            "t_low": (a * math.sin(ALPHA) - math.sqrt(ra2 ** 2 - rb2 ** 2)) / rb,
            "t_tip": math.sqrt(ra ** 2 - rb ** 2) / rb}


def _roll_at(along: float) -> float:
    """Roll angle of the pinion flank point ``along`` [m] from the reference circle along the
    involute (arc length from the base circle r_b t^2 / 2)."""
    g = _pinion()
    return math.sqrt(2.0 * (g["rb"] * math.tan(ALPHA) ** 2 / 2.0 + along) / g["rb"])


def _reference(a1: float, section, points: tuple[float, ...] = ()) -> dict[str, float]:
    """Bending, shear, axial compliance of the pinion tooth by quad in alpha, the section at
    alpha (I, A) from ``section(alpha, h)`` (discontinuous at most at ``points``); straight
    root flank healthy."""
    g = _pinion()
    rb, rf, a2 = g["rb"], g["rf"], g["a2"]
    c, s = math.cos(a1), math.sin(a1)
    xc = rb * (math.cos(a1) + (a1 + a2) * math.sin(a1))
    hc = rb * ((a1 + a2) * math.cos(a1) - math.sin(a1))
    g_mod = E / (2.0 * (1.0 + NU))

    def geom(a: float) -> tuple[float, float, float, float]:
        h = rb * (math.sin(a) + (a2 - a) * math.cos(a))
        x = rb * (math.cos(a) - (a2 - a) * math.sin(a))
        inertia, area = section(a, h)
        return inertia, area, x, rb * (a2 - a) * math.cos(a)

    def bend(a: float) -> float:
        inertia, _, x, dx = geom(a)
        return (c * (xc - x) - s * hc) ** 2 / (E * inertia) * dx

    def inv_area(a: float) -> float:
        _, area, _, dx = geom(a)
        return dx / area

    inner = [p for p in points if -a1 < p < a2]
    tight = dict(epsabs=0.0, epsrel=1e-12, limit=400, points=inner or None)
    hb = rb * math.sin(a2)
    x0, x1 = math.sqrt(rf ** 2 - hb ** 2), rb * math.cos(a2)
    i_b, a_b = 2.0 * hb ** 3 * B / 3.0, 2.0 * hb * B
    bending = (quad(bend, -a1, a2, **tight)[0]
               + quad(lambda x: (c * (xc - x) - s * hc) ** 2 / (E * i_b), x0, x1,
                      epsabs=0.0, epsrel=1e-12)[0])
    area = quad(inv_area, -a1, a2, **tight)[0] + (x1 - x0) / a_b
    return {"bending": bending, "shear": 1.2 * c ** 2 / g_mod * area, "axial": s ** 2 / E * area}


def _two_rectangles(h: float, width: float, depth: float) -> tuple[float, float]:
    """(I, A) of the spalled section as the union of the full-height part (b - w wide, from -h
    to h) and the spalled part (w wide, from -h to h - d), I about the union's centroid."""
    parts = [(B - width, -h, h), (width, -h, h - depth)]
    area = sum(w * (top - bot) for w, bot, top in parts)
    y_c = sum(w * (top - bot) * 0.5 * (top + bot) for w, bot, top in parts) / area
    inertia = sum(w * ((top - y_c) ** 3 - (bot - y_c) ** 3) / 3.0 for w, bot, top in parts)
    return inertia, area


# -- spall -----------------------------------------------------------------------------------


SPALL = dict(length=1.2e-3, width=4e-3, depth=0.3e-3, position=0.4e-3)


def test_spalled_tooth_matches_quad(mesh: GearMesh) -> None:
    spall = Spall(**SPALL)
    pair = prepare_pair(mesh, bore_radius=BORES, faults=spall)
    g = _pinion()
    t_lo = _roll_at(SPALL["position"] - SPALL["length"] / 2.0)
    t_hi = _roll_at(SPALL["position"] + SPALL["length"] / 2.0)

    def section(a: float, h: float) -> tuple[float, float]:
        if g["a2"] - t_hi <= a <= g["a2"] - t_lo:
            return _two_rectangles(h, SPALL["width"], SPALL["depth"])
        return 2.0 * h ** 3 * B / 3.0, 2.0 * h * B

    rolls = [g["t_low"] + 1e-3, 0.5 * (t_lo + t_hi), t_hi + 0.05, g["t_tip"]]  # below, on, above
    a1 = np.array(rolls) - g["a2"]
    got = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B, fault=spall)
    healthy = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B)
    for i, alpha1 in enumerate(a1):
        ref = _reference(float(alpha1), section, (g["a2"] - t_hi, g["a2"] - t_lo))
        for name, value in ref.items():
            assert got[name][i] == pytest.approx(value, rel=1e-10, abs=0.0), (name, i)
        assert got["fillet"][i] == healthy["fillet"][i]
    assert got["bending"][0] == healthy["bending"][0]  # the spall lies above that contact
    assert np.all(got["bending"][1:] > healthy["bending"][1:])
    # Hertz: the contact width b - w on the spall only
    pos = (np.array(rolls) - math.tan(ALPHA)) * g["rb"]  # on the line of action
    hertz = pair.terms(pos, spall)["hertz"]
    k_h = math.pi * E / (4.0 * (1.0 - NU ** 2))
    np.testing.assert_allclose(hertz, [k_h * B, k_h * (B - SPALL["width"]), k_h * B, k_h * B],
                               rtol=1e-15)
    assert pair.terms(pos, spall, coast=True)["hertz"][1] == pytest.approx(k_h * B, rel=1e-15)


@pytest.mark.parametrize("spall", [Spall(0.0, 4e-3, 3e-4, tooth=3), Spall(1e-3, 0.0, 3e-4),
                                   Spall(1e-3, 4e-3, 0.0, gear="wheel", tooth=2)])
def test_zero_spall_is_healthy_bitwise(mesh: GearMesh, healthy, spall: Spall) -> None:
    ds = _run(mesh, spall)
    for name in healthy.data_vars:
        np.testing.assert_array_equal(ds[name].values, healthy[name].values)


@pytest.mark.parametrize("field, sizes", [
    ("length", [0.0, 0.2e-3, 0.6e-3, 1.2e-3, 2.0e-3]),
    ("width", [0.0, 1e-3, 4e-3, 8e-3, 15e-3]),
    ("depth", [0.0, 0.05e-3, 0.2e-3, 0.5e-3, 0.9e-3]),
])
def test_stiffness_falls_monotonically_with_spall_size(mesh: GearMesh, healthy, field: str,
                                                       sizes: list[float]) -> None:
    touched = ((healthy.tooth_pinion == 4) & healthy.in_contact).any("pair").values
    runs = []
    for size in sizes:
        kw = dict(SPALL, tooth=4) | {field: size}
        runs.append(_run(mesh, Spall(**kw)).mesh_stiffness.values)
    for smaller, larger in zip(runs, runs[1:], strict=False):
        assert np.all(larger[touched] <= smaller[touched])
        assert np.count_nonzero(larger[touched] < smaller[touched]) >= touched.sum() // 3
        np.testing.assert_array_equal(larger[~touched], smaller[~touched])


# -- wear ------------------------------------------------------------------------------------


def test_worn_tooth_matches_quad(mesh: GearMesh) -> None:
    depth = 40e-6
    wear = Wear(depth)
    pair = prepare_pair(mesh, bore_radius=BORES, faults=wear)
    g = _pinion()

    def section(a: float, h: float) -> tuple[float, float]:
        if a <= g["a2"] - g["t_low"]:  # the active profile
            return (2.0 * h - depth) ** 3 * B / 12.0, (2.0 * h - depth) * B
        return 2.0 * h ** 3 * B / 3.0, 2.0 * h * B

    a1 = np.array([g["t_low"] + 0.02, math.tan(ALPHA), g["t_tip"]]) - g["a2"]
    got = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B, fault=wear)
    for i, alpha1 in enumerate(a1):
        for name, value in _reference(float(alpha1), section, (g["a2"] - g["t_low"],)).items():
            assert got[name][i] == pytest.approx(value, rel=1e-10, abs=0.0), (name, i)


def test_zero_wear_is_healthy_bitwise(mesh: GearMesh, healthy) -> None:
    ds = _run(mesh, [Wear(0.0, tooth=5), Wear("0 um", gear="wheel", tooth=1)])
    for name in healthy.data_vars:
        np.testing.assert_array_equal(ds[name].values, healthy[name].values)


def test_stiffness_falls_monotonically_with_wear_depth(mesh: GearMesh, healthy) -> None:
    touched = ((healthy.tooth_pinion == 6) & healthy.in_contact).any("pair").values
    runs = [_run(mesh, Wear(d, tooth=6)) for d in (0.0, 1e-6, 10e-6, 50e-6, 200e-6)]
    for thin, thick in zip(runs, runs[1:], strict=False):
        k0, k1 = thin.mesh_stiffness.values, thick.mesh_stiffness.values
        assert np.all(k1[touched] < k0[touched])
        np.testing.assert_array_equal(k1[~touched], k0[~touched])
    gap = runs[-1].fault_gap.values
    worn = runs[-1].in_contact.values & (runs[-1].tooth_pinion.values == 6)
    np.testing.assert_array_equal(gap[worn], 200e-6)
    np.testing.assert_array_equal(gap[~worn], 0.0)


def test_wear_gap_enters_the_loaded_contact(mesh: GearMesh) -> None:
    """In single contact of the worn pair the approach is F/k + h_w; in double contact the worn
    pair carries less than it would healthy, and the pair forces still sum to F."""
    depth, force = 20e-6, 2000.0
    ds = _run(mesh, Wear(depth, tooth=2), angles=60)
    out = loaded_contact(mesh, ds, force)
    worn = ds.in_contact.values & (ds.tooth_pinion.values == 2)
    single = worn.any(axis=1) & (ds.pairs_in_contact.values == 1)
    k = ds.mesh_stiffness.values
    np.testing.assert_allclose(out.transmission_error.values[single],
                               force / k[single] + depth, rtol=1e-12)
    np.testing.assert_allclose(out.unloaded_transmission_error.values[single], depth, rtol=0)
    np.testing.assert_allclose(out.pair_force.sum("pair").values, force, rtol=1e-10)
    healthy = loaded_contact(mesh, _run(mesh, (), angles=60), force)
    double = worn.any(axis=1) & (ds.pairs_in_contact.values == 2)
    assert double.any()
    share = out.pair_force.values[worn & double[:, None]]
    share0 = healthy.pair_force.values[worn & double[:, None]]
    assert np.all(share < share0)


# -- broken tooth ----------------------------------------------------------------------------


@pytest.mark.parametrize("gear, tooth", [("pinion", 7), ("wheel", 30)])
def test_missing_tooth_leaves_the_other_pairs(mesh: GearMesh, gear: str, tooth: int) -> None:
    """While the missing tooth would be in contact the mesh stiffness is the sum of the other
    pairs' healthy stiffness columns (summed here), zero where it would carry alone."""
    cycles = Z1 if gear == "pinion" else Z2
    ds0 = _run(mesh, (), angles=30, cycles=cycles)
    ds = _run(mesh, BrokenTooth(gear=gear, tooth=tooth), angles=30, cycles=cycles)
    idx = (ds0.tooth_pinion if gear == "pinion" else ds0.tooth_wheel).values
    gone = ds0.in_contact.values & (idx == tooth)
    assert gone.any()
    k0 = ds0.pair_stiffness.values
    for i in range(k0.shape[0]):
        expected = 0.0
        for j in range(k0.shape[1]):
            if not gone[i, j]:
                expected += float(k0[i, j])
        assert ds.mesh_stiffness.values[i] == pytest.approx(expected, rel=1e-15, abs=0.0)
    lone = gone.any(axis=1) & (ds0.pairs_in_contact.values == 1)
    assert lone.any()
    np.testing.assert_array_equal(ds.mesh_stiffness.values[lone], 0.0)
    np.testing.assert_array_equal(ds.in_contact.values, ds0.in_contact.values & ~gone)
    assert np.all(np.isnan(ds.k_hertz.values[gone]))
    # the coast flank likewise
    idx_c = (ds0.tooth_pinion_coast if gear == "pinion" else ds0.tooth_wheel_coast).values
    gone_c = ds0.in_contact_coast.values & (idx_c == tooth)
    expected_c = np.where(gone_c, 0.0, ds0.pair_stiffness_coast.values).sum(axis=1)
    np.testing.assert_allclose(ds.mesh_stiffness_coast.values, expected_c, rtol=1e-15)
    with pytest.raises(ParameterError) as info:
        loaded_contact(mesh, ds, 1000.0)
    assert info.value.field == "stiffness"


# -- when a fault is felt --------------------------------------------------------------------


@pytest.mark.parametrize("fault", [Spall(2e-3, 4e-3, 0.3e-3, position=-0.5e-3, gear="wheel",
                                         tooth=11),
                                   Wear(30e-6, gear="wheel", tooth=11),
                                   BrokenTooth(gear="wheel", tooth=11),
                                   Spall(1.5e-3, 6e-3, 0.2e-3, tooth=13)])
def test_fault_felt_only_in_contact_once_per_revolution(mesh: GearMesh, fault) -> None:
    """Over the hunting period: the stiffness changes only while the faulty tooth is in
    contact, in every revolution of its gear, and repeats with that gear's revolution."""
    n = 6
    ds0 = _run(mesh, (), angles=n, cycles=HUNT)
    ds = _run(mesh, fault, angles=n, cycles=HUNT)
    idx = (ds0.tooth_pinion if fault.gear == "pinion" else ds0.tooth_wheel).values
    contact = (ds0.in_contact.values & (idx == fault.tooth)).any(axis=1)
    changed = ds.mesh_stiffness.values != ds0.mesh_stiffness.values
    assert np.all(contact[changed])
    z = Z1 if fault.gear == "pinion" else Z2
    per_rev = changed.reshape(HUNT // z, z * n)
    assert np.all(per_rev.any(axis=1))  # felt in every revolution
    k = ds.mesh_stiffness.values.reshape(HUNT // z, z * n)
    np.testing.assert_array_equal(k, np.broadcast_to(k[0], k.shape))
    if isinstance(fault, (Wear, BrokenTooth)):  # the whole active profile is affected
        np.testing.assert_array_equal(changed, contact)


# -- several faults --------------------------------------------------------------------------


def test_several_faults_each_on_its_own_tooth(mesh: GearMesh) -> None:
    """A cracked pinion tooth, a spalled wheel tooth and a missing pinion tooth: each angle
    equals the run with the faults whose teeth are in contact there; where the cracked and the
    spalled tooth meet, the pair is their series sum written out here."""
    crack = RootCrack("1.5 mm", tooth=2)
    spall = Spall(1.2e-3, 4e-3, 0.3e-3, position=0.4e-3, gear="wheel", tooth=5)
    broken = BrokenTooth(tooth=10)
    n = 8
    both = _run(mesh, [crack, spall, broken], angles=n, cycles=HUNT)
    single = {f: _run(mesh, f, angles=n, cycles=HUNT) for f in (crack, spall, broken)}
    tp, tw = both.tooth_pinion.values, both.tooth_wheel.values
    geo = single[crack].in_contact.values
    on = {crack: (geo & (tp == 2)).any(axis=1), spall: (geo & (tw == 5)).any(axis=1),
          broken: (geo & (tp == 10)).any(axis=1)}
    k = both.mesh_stiffness.values
    alone = {f: on[f] & ~np.any([on[g] for g in on if g is not f], axis=0) for f in on}
    for f, mask in alone.items():
        assert mask.any()
        np.testing.assert_array_equal(k[mask], single[f].mesh_stiffness.values[mask])
    meet = geo & (tp == 2) & (tw == 5)
    assert meet.any()
    pair = prepare_pair(mesh, bore_radius=BORES)
    pos = both.position.values[meet]
    a_p, a_w = pair.load_angles(pos)
    kw = dict(young=E, poisson=NU, face_width=B)
    comp = (sum(tooth_compliances(pair.pinion, a_p, fault=crack, **kw).values())
            + sum(tooth_compliances(pair.wheel, a_w, fault=spall, **kw).values()))
    t_w = a_w + pair.wheel.half_base_angle
    r_b2 = mesh.wheel.base_radius

    def roll(along: float) -> float:
        return math.sqrt(2.0 * (r_b2 * math.tan(ALPHA) ** 2 / 2.0 + along) / r_b2)

    on_spall = (t_w >= roll(0.4e-3 - 0.6e-3)) & (t_w <= roll(0.4e-3 + 0.6e-3))
    width = np.where(on_spall, B - 4e-3, B)
    comp = comp + 4.0 * (1.0 - NU ** 2) / (math.pi * E * width)
    np.testing.assert_allclose(both.pair_stiffness.values[meet], 1.0 / comp, rtol=1e-12)
    assert "missing" in both.attrs["faults"] and "spall" in both.attrs["faults"]


# -- construction, errors, the deprecated crack= ---------------------------------------------


def test_faults_from_keywords_with_units() -> None:
    spall = FAULT_KINDS["spall"](**{"length": "1 mm", "width": "4 mm", "depth": "100 um",
                                    "position": "-0.5 mm", "gear": "wheel", "tooth": 3})
    assert spall == Spall(1e-3, 4e-3, 1e-4, position=-5e-4, gear="wheel", tooth=3)
    assert FAULT_KINDS["wear"](depth="20 um", tooth=1) == Wear(2e-5, tooth=1)
    assert FAULT_KINDS["broken_tooth"](gear="wheel", tooth=4) == BrokenTooth("wheel", 4)
    assert FAULT_KINDS["crack"](depth="1 mm", angle="30 deg").angle == pytest.approx(
        math.radians(30.0))


@pytest.mark.parametrize("make, field", [
    (lambda: Spall(-1e-3, 4e-3, 1e-4), "spall.length"),
    (lambda: Spall("1 deg", 4e-3, 1e-4), "spall.length"),
    (lambda: Spall(1e-3, -4e-3, 1e-4), "spall.width"),
    (lambda: Spall(1e-3, 16e-3, 1e-4), "spall.width"),
    (lambda: Spall(1e-3, 4e-3, float("nan")), "spall.depth"),
    (lambda: Spall(1e-3, 4e-3, 1.2e-3, position=3e-3), "spall.depth"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, position=5e-3), "spall.position"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, position=-4e-3), "spall.position"),
    (lambda: Spall(3e-3, 4e-3, 1e-4, position=3e-3), "spall.length"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, gear="ring"), "spall.gear"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, tooth=19), "spall.tooth"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, tooth=-1), "spall.tooth"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, tooth=1.5), "spall.tooth"),
    (lambda: Wear(-1e-6), "wear.depth"),
    (lambda: Wear(1.2e-3), "wear.depth"),
    (lambda: Wear(1e-5, gear="wheel", tooth=48), "wear.tooth"),
    (lambda: BrokenTooth(gear="sun"), "broken_tooth.gear"),
    (lambda: BrokenTooth(tooth=19), "broken_tooth.tooth"),
    (lambda: [Wear(1e-5, tooth=3), Spall(1e-3, 4e-3, 1e-4, tooth=3)], "faults"),
    (lambda: [RootCrack(1e-3), "spall"], "faults"),
])
def test_bad_faults_name_the_field(mesh: GearMesh, make, field: str) -> None:
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(mesh, bore_radius=BORES, angles=4, faults=make())
    assert info.value.field == field


def test_crack_keyword_is_deprecated(mesh: GearMesh) -> None:
    crack = RootCrack("2 mm", tooth=1)
    new = potential_energy_stiffness(mesh, bore_radius=BORES, angles=10, cycles=3, faults=crack)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = potential_energy_stiffness(mesh, bore_radius=BORES, angles=10, cycles=3,
                                         crack=crack)
    assert [w.category for w in caught] == [DeprecationWarning]
    assert caught[0].filename == __file__
    assert "faults=" in str(caught[0].message)
    for name in new.data_vars:
        np.testing.assert_array_equal(old[name].values, new[name].values)
    with pytest.raises(TypeError):
        potential_energy_stiffness(mesh, bore_radius=BORES, angles=4, crack=crack,
                                   faults=Wear(1e-5))
    pair = prepare_pair(mesh, bore_radius=BORES, faults=crack)
    a1 = np.array([0.2, 0.4])
    kw = dict(young=E, poisson=NU, face_width=B)
    with pytest.warns(DeprecationWarning, match="prepare_pair"):
        assert prepare_pair(mesh, bore_radius=BORES, crack=crack).faults == (crack,)
    with pytest.warns(DeprecationWarning, match="tooth_compliances"):
        old_c = tooth_compliances(pair.pinion, a1, crack=crack, **kw)
    new_c = tooth_compliances(pair.pinion, a1, fault=crack, **kw)
    for name in new_c:
        np.testing.assert_array_equal(old_c[name], new_c[name])


def test_missing_tooth_takes_one_z_th_of_the_mean(mesh: GearMesh) -> None:
    """Every pinion tooth runs through the same contacts once a revolution, so a missing one
    takes exactly 1/z1 of the mean stiffness over a revolution."""
    k0 = _run(mesh, (), angles=36).mesh_stiffness.values
    k = _run(mesh, BrokenTooth(tooth=4), angles=36).mesh_stiffness.values
    assert k.mean() == pytest.approx(k0.mean() * (1.0 - 1.0 / Z1), rel=1e-13, abs=0.0)


# -- Archard's wear profile ------------------------------------------------------------------


def _slip(gear: str, s: np.ndarray) -> np.ndarray:
    """|v1 - v2| / v of the flank point of ``gear`` in contact at line-of-action position s:
    v_i = omega_i rho_i, rho the distance from the gear's tangent point, omega_2/omega_1 =
    z1/z2 (textbook geometry of the unshifted pair)."""
    rb1, rb2 = M * Z1 / 2.0 * math.cos(ALPHA), M * Z2 / 2.0 * math.cos(ALPHA)
    rho1 = rb1 * math.tan(ALPHA) + s
    rho2 = (rb1 + rb2) * math.tan(ALPHA) - rho1
    v1, v2 = rho1, Z1 / Z2 * rho2
    return np.abs(v1 - v2) / (v1 if gear == "pinion" else v2)


@pytest.mark.parametrize("gear", ["pinion", "wheel"])
def test_archard_gap_follows_load_share_times_slip(mesh: GearMesh, gear: str) -> None:
    """The gap of an Archard-worn tooth is proportional to k_i / sum k (from the healthy
    Dataset's pair columns) times the slip written out here, zero at the pitch point, at most
    the given depth and reaching it near the path's ends."""
    depth, tooth = 30e-6, 3
    cycles = Z1 if gear == "pinion" else Z2
    ds0 = _run(mesh, (), angles=48, cycles=cycles)
    ds = _run(mesh, Wear(depth, gear=gear, tooth=tooth, profile="archard"), angles=48,
              cycles=cycles)
    idx = (ds0.tooth_pinion if gear == "pinion" else ds0.tooth_wheel).values
    worn = ds0.in_contact.values & (idx == tooth)
    share = ds0.pair_stiffness.values / ds0.mesh_stiffness.values[:, None]
    rate = (share * _slip(gear, ds0.position.values))[worn]
    gap = ds.fault_gap.values[worn]
    pitch = np.abs(ds0.position.values[worn]) < 1e-15
    assert pitch.any()
    np.testing.assert_allclose(gap[pitch], 0.0, atol=1e-18)
    top = int(np.argmax(rate))
    np.testing.assert_allclose(gap, gap[top] / rate[top] * rate, rtol=1e-9, atol=1e-10 * depth)
    assert gap.max() <= depth and gap.max() > 0.8 * depth
    np.testing.assert_array_equal(ds.fault_gap.values[~worn], 0.0)


def test_archard_worn_tooth_matches_quad(mesh: GearMesh) -> None:
    """The sections thinned by the profile's depth at their flank point, by quad with the
    stretches' ends as break points."""
    wear = Wear(40e-6, profile="archard")
    pair = prepare_pair(mesh, bore_radius=BORES, faults=wear)
    profile = pair.profile_of(wear)
    g = _pinion()

    def section(a: float, h: float) -> tuple[float, float]:
        if a <= g["a2"] - g["t_low"]:
            t = 2.0 * h - float(profile.depth_at(np.array([g["a2"] - a]))[0])
            return t ** 3 * B / 12.0, t * B
        return 2.0 * h ** 3 * B / 3.0, 2.0 * h * B

    a1 = np.array([g["t_low"] + 0.02, math.tan(ALPHA) + 0.05, g["t_tip"]]) - g["a2"]
    got = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B, fault=wear,
                            wear_profile=profile)
    healthy = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B)
    for i, alpha1 in enumerate(a1):
        breaks = tuple(g["a2"] - t for t in profile.rolls)
        for name, value in _reference(float(alpha1), section, breaks).items():
            assert got[name][i] == pytest.approx(value, rel=1e-9, abs=0.0), (name, i)
            assert got[name][i] > healthy[name][i]
    with pytest.raises(ParameterError) as info:
        tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B, fault=wear)
    assert info.value.field == "wear.profile"


def test_archard_wear_zero_and_monotone(mesh: GearMesh, healthy) -> None:
    zero = _run(mesh, Wear(0.0, tooth=6, profile="archard"))
    for name in healthy.data_vars:
        np.testing.assert_array_equal(zero[name].values, healthy[name].values)
    touched = ((healthy.tooth_pinion == 6) & healthy.in_contact).any("pair").values
    runs = [_run(mesh, Wear(d, tooth=6, profile="archard")).mesh_stiffness.values
            for d in (0.0, 5e-6, 50e-6, 200e-6)]
    for thin, thick in zip(runs, runs[1:], strict=False):
        assert np.all(thick[touched] <= thin[touched])
        assert np.count_nonzero(thick[touched] < thin[touched]) >= touched.sum() // 2
        np.testing.assert_array_equal(thick[~touched], thin[~touched])
    with pytest.raises(ParameterError) as info:
        Wear(1e-5, profile="linear")
    assert info.value.field == "wear.profile"
