"""Potential-energy stiffness of an internal spur pair: a pinion (planet) in a ring.

The references are written out here from the geometry, independently of the module: the ring
tooth's flank is the involute of the ring's base circle on the other branch from an external
tooth's, x(a) = r_b [cos a + (a - a2) sin a], h(a) = r_b [sin a - (a - a2) cos a] for
a = a2 + t (t the roll angle, a2 the tooth's half angle on the base circle), loaded at
a1 = a2 + t_c; its energies are integrated by scipy's adaptive quad from the contact to the
root circle. The internal geometry (operating pressure angle, tip and root circles, contact
ratio) comes from the textbook relations of internal gears (profile shift x moving the ring's
profile outwards, KHK's sign).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, SpurGear, iso6336_stiffness
from geardyn.gears.faults import BrokenTooth, RootCrack, Spall, Wear
from geardyn.gears.potential_energy import potential_energy_stiffness, prepare_pair

M, ALPHA, B, E, NU = 2e-3, math.radians(20.0), 20e-3, 2.068e11, 0.3
Z1, Z2 = 23, 71
BORES = (8e-3, 85e-3)  # planet bore, ring outer (rim) radius [m]


def _inv(a: float) -> float:
    return math.tan(a) - a


def _inverse_inv(v: float) -> float:
    a = 0.5
    for _ in range(100):
        a -= (_inv(a) - v) / math.tan(a) ** 2
    return a


def _internal(x1: float = 0.0, x2: float = 0.0) -> dict[str, float]:
    """Textbook geometry of the internal pair (zero-backlash centre distance)."""
    a_w = _inverse_inv(_inv(ALPHA) + 2.0 * math.tan(ALPHA) * (x2 - x1) / (Z2 - Z1))
    rb1, rb2 = M * Z1 / 2.0 * math.cos(ALPHA), M * Z2 / 2.0 * math.cos(ALPHA)
    return {"a_w": a_w, "rb1": rb1, "rb2": rb2, "a": (rb2 - rb1) / math.cos(a_w),
            "ra1": M * (Z1 / 2.0 + 1.0 + x1), "ra2": M * (Z2 / 2.0 - 1.0 + x2),
            "rf2": M * (Z2 / 2.0 + 1.25 + x2),
            "a2": math.pi / (2.0 * Z2) - 2.0 * x2 * math.tan(ALPHA) / Z2 - _inv(ALPHA)}


def _mesh(x1: float = 0.0, x2: float = 0.0, z2: int = Z2) -> GearMesh:
    return GearMesh(SpurGear(Z1, M, ALPHA, B, profile_shift=x1, name="pinion"),
                    SpurGear(z2, M, ALPHA, B, profile_shift=x2, internal=True, name="wheel"),
                    internal=True)


def _ring_reference(g: dict[str, float], position: float) -> dict[str, float]:
    """The ring tooth's bending, shear and axial compliances by quad for the contact at
    ``position`` [m] from the pitch point on the line of action."""
    rb, a2 = g["rb2"], g["a2"]
    a1 = a2 + (rb * math.tan(g["a_w"]) + position) / rb
    top = a2 + math.sqrt((g["rf2"] / rb) ** 2 - 1.0)
    c, s = math.cos(a1), math.sin(a1)

    def den(a: float) -> float:
        return math.sin(a) - (a - a2) * math.cos(a)

    def bend(a: float) -> float:
        return (3.0 * (1.0 - c * ((a - a2) * math.sin(a) + math.cos(a))) ** 2
                * (a - a2) * math.cos(a) / (2.0 * E * B * den(a) ** 3))

    def shear(a: float) -> float:
        return 1.2 * (1.0 + NU) * (a - a2) * math.cos(a) * c ** 2 / (E * B * den(a))

    def axial(a: float) -> float:
        return (a - a2) * math.cos(a) * s ** 2 / (2.0 * E * B * den(a))

    return {name: quad(f, a1, top, epsabs=0.0, epsrel=1e-13, limit=200)[0]
            for name, f in (("bending", bend), ("shear", shear), ("axial", axial))}


@pytest.mark.parametrize("shift", [(0.0, 0.0), (0.2, 0.4)])
def test_ring_tooth_energies_match_quad(shift: tuple[float, float]) -> None:
    """Each ring-tooth term at the start, the pitch point and the end of the path of contact."""
    g = _internal(*shift)
    mesh = _mesh(*shift)
    assert mesh.operating_pressure_angle == pytest.approx(g["a_w"], abs=1e-13)
    pair = prepare_pair(mesh, bore_radius=BORES, young=E, poisson=NU)
    g_f = g["rb2"] * math.tan(g["a_w"]) - math.sqrt(g["ra2"] ** 2 - g["rb2"] ** 2)
    g_a = math.sqrt(g["ra1"] ** 2 - g["rb1"] ** 2) - g["rb1"] * math.tan(g["a_w"])
    positions = np.array([-g_f, 0.0, 0.5 * g_a, g_a * (1.0 - 1e-12)])
    terms = pair.terms(positions)
    for i, s in enumerate(positions):
        ref = _ring_reference(g, float(s))
        for name, value in ref.items():
            assert 1.0 / terms[f"{name}_wheel"][i] == pytest.approx(value, rel=1e-11), name
    assert np.all(np.isinf(terms["fillet_wheel"]))  # rigid ring body
    assert np.all(np.isfinite(terms["fillet_pinion"]))


def _cracked_ring_reference(g: dict[str, float], position: float,
                            reach: float) -> dict[str, float]:
    """The cracked ring tooth by quad: Tian's crack limit line h_q = h_r - q sin v from the
    centre line (h_r the half thickness at the root circle) leaves every section
    h + min(h, h_q) thick."""
    rb, a2 = g["rb2"], g["a2"]
    a1 = a2 + (rb * math.tan(g["a_w"]) + position) / rb
    top = a2 + math.sqrt((g["rf2"] / rb) ** 2 - 1.0)
    c, s = math.cos(a1), math.sin(a1)
    xc = rb * (math.cos(a1) + (a1 - a2) * math.sin(a1))
    hc = rb * (math.sin(a1) - (a1 - a2) * math.cos(a1))
    hq = rb * (math.sin(top) - (top - a2) * math.cos(top)) - reach

    def geom(a: float) -> tuple[float, float, float]:
        h = rb * (math.sin(a) - (a - a2) * math.cos(a))
        x = rb * (math.cos(a) + (a - a2) * math.sin(a))
        return h + min(h, hq), x, rb * (a - a2) * math.cos(a)

    def bend(a: float) -> float:
        t, x, dx = geom(a)
        return (c * (x - xc) - s * hc) ** 2 / (E * t ** 3 * B / 12.0) * dx

    def inv_area(a: float) -> float:
        t, _, dx = geom(a)
        return dx / (t * B)

    tight = dict(epsabs=0.0, epsrel=1e-12, limit=400)
    area = quad(inv_area, a1, top, **tight)[0]
    return {"bending": quad(bend, a1, top, **tight)[0],
            "shear": 1.2 * c ** 2 * 2.0 * (1.0 + NU) / E * area, "axial": s ** 2 / E * area}


@pytest.mark.parametrize("depth", [0.3e-3, 1.0e-3, 1.8e-3])
def test_cracked_ring_tooth_matches_quad(depth: float) -> None:
    g = _internal()
    pair = prepare_pair(_mesh(), bore_radius=BORES, young=E, poisson=NU)
    crack = RootCrack(depth, "45 deg", gear="wheel")
    positions = np.array([-3e-3, 0.0, 2e-3])
    terms = pair.terms(positions, wheel=crack)
    for i, s in enumerate(positions):
        ref = _cracked_ring_reference(g, float(s), depth * math.sin(math.radians(45.0)))
        for name, value in ref.items():
            assert 1.0 / terms[f"{name}_wheel"][i] == pytest.approx(value, rel=1e-9), name


def test_ring_crack_lowers_its_pairs_once_per_ring_revolution() -> None:
    """Stiffness falls strictly with crack depth wherever the cracked ring tooth is in contact,
    is unchanged elsewhere, and zero depth is healthy bitwise."""
    mesh = _mesh()
    kw = dict(bore_radius=BORES, angles=12, cycles=Z2 + 10)
    healthy = potential_energy_stiffness(mesh, **kw)
    zero = potential_energy_stiffness(mesh, faults=RootCrack(0.0, gear="wheel", tooth=7), **kw)
    np.testing.assert_array_equal(zero.mesh_stiffness.values, healthy.mesh_stiffness.values)
    on = ((healthy.tooth_wheel.values == 7) & healthy.in_contact.values).any(axis=1)
    assert on[: len(on) // 2].any() and on[len(on) // 2:].any()  # tooth 7 at cycles 7 and 78
    previous = healthy.mesh_stiffness.values
    for depth in (0.5e-3, 1.0e-3, 1.5e-3):
        k = potential_energy_stiffness(mesh, faults=RootCrack(depth, gear="wheel", tooth=7),
                                       **kw).mesh_stiffness.values
        assert np.all(k[on] < previous[on])
        np.testing.assert_array_equal(k[~on], healthy.mesh_stiffness.values[~on])
        previous = k


def test_internal_contact_ratio_is_the_closed_form() -> None:
    """eps = [sqrt(r_a1^2 - r_b1^2) - sqrt(r_a2^2 - r_b2^2) + a sin a_w] / p_b, and two pairs
    carry during the fraction eps - 1 of a mesh cycle."""
    for shift in ((0.0, 0.0), (0.2, 0.4)):
        g = _internal(*shift)
        eps = (math.sqrt(g["ra1"] ** 2 - g["rb1"] ** 2) - math.sqrt(g["ra2"] ** 2 - g["rb2"] ** 2)
               + g["a"] * math.sin(g["a_w"])) / (math.pi * M * math.cos(ALPHA))
        n = 4000
        ds = potential_energy_stiffness(_mesh(*shift), bore_radius=BORES, angles=n)
        assert ds.attrs["contact_ratio"] == pytest.approx(eps, rel=1e-12)
        two = float(np.mean(ds.pairs_in_contact.values == 2))
        assert set(np.unique(ds.pairs_in_contact.values)) == {1, 2}
        assert two == pytest.approx(eps - 1.0, abs=1.0 / n)
        both = ds.in_contact.values.sum(axis=1)
        np.testing.assert_array_equal(both, ds.pairs_in_contact.values)
        np.testing.assert_allclose(ds.mesh_stiffness.values,
                                   ds.pair_stiffness.values.sum(axis=1), rtol=1e-15)


def _without_wheel_foundation(ds) -> np.ndarray:  # noqa: ANN001
    """Each pair's stiffness from its terms, less the wheel's fillet-foundation term."""
    names = ["k_hertz", *(f"k_{t}_pinion" for t in ("bending", "shear", "axial", "fillet")),
             *(f"k_{t}_wheel" for t in ("bending", "shear", "axial"))]
    return 1.0 / sum(1.0 / ds[n].values for n in names)


def _rack_gaps(z2: int) -> dict[str, float]:
    """Largest relative difference, over the contacts both pairs share, between the internal
    and the external pair of the same pinion and z2 teeth: of the wheel's bending, shear and
    axial terms, and of the pair stiffness less the wheel's foundation."""
    c = (np.arange(64) + 0.5) / 64.0 * 360.0 / Z1
    p = SpurGear(Z1, M, ALPHA, B, name="pinion")
    ext = GearMesh(p, SpurGear(z2, M, ALPHA, B, name="wheel"))
    ring = SpurGear(z2, M, ALPHA, B, internal=True, name="wheel")
    r_f = ring.root_radius
    d_e = potential_energy_stiffness(ext, bore_radius=(8e-3, 0.5 * r_f), angles=c)
    d_i = potential_energy_stiffness(GearMesh(p, ring, internal=True),
                                     bore_radius=(8e-3, 1.2 * r_f), angles=c)
    pairs = np.intersect1d(d_e.pair.values, d_i.pair.values)
    d_e, d_i = d_e.sel(pair=pairs), d_i.sel(pair=pairs)
    both = d_e.in_contact.values & d_i.in_contact.values
    assert both.sum() >= 64
    # the pinion's terms are the same at the same contact positions
    np.testing.assert_allclose(d_i.k_bending_pinion.values[both],
                               d_e.k_bending_pinion.values[both], rtol=1e-12)
    out = {t: float(np.max(np.abs(d_i[f"k_{t}_wheel"].values[both]
                                  / d_e[f"k_{t}_wheel"].values[both] - 1.0)))
           for t in ("bending", "shear", "axial")}
    k_e, k_i = _without_wheel_foundation(d_e)[both], _without_wheel_foundation(d_i)[both]
    out["pair"] = float(np.max(np.abs(k_i / k_e - 1.0)))
    return out


def test_large_ring_and_large_wheel_tend_to_the_rack() -> None:
    """As z2 grows, the ring's and an external wheel's teeth both tend to the rack tooth: the
    ring's terms and the pair stiffness (less the wheel's foundation, which the rigid ring has
    not) of the internal and the external pair with the same pinion converge to each other
    like 1/z2."""
    gaps = {z2: _rack_gaps(z2) for z2 in (200, 2000, 20000)}
    for name in ("bending", "shear", "axial", "pair"):
        assert gaps[200][name] > 5.0 * gaps[2000][name] > 25.0 * gaps[20000][name], name
    assert gaps[2000]["pair"] < 1e-2
    assert gaps[20000]["pair"] < 1e-3
    assert max(gaps[20000].values()) < 1e-2


def test_coast_stiffness_is_the_drive_stiffness_mirrored() -> None:
    """K_coast(c) = K_drive(phi - c), phi = 1/2 for unshifted teeth at zero backlash."""
    mesh = _mesh()
    c = (np.arange(97) + 0.3183) / 97.0 * 3.0
    deg = 360.0 / Z1
    coast = potential_energy_stiffness(mesh, bore_radius=BORES, angles=c * deg)
    drive = potential_energy_stiffness(mesh, bore_radius=BORES, angles=(0.5 - c) * deg)
    assert coast.attrs["coast_phase_cycles"] == pytest.approx(0.5, abs=1e-12)
    np.testing.assert_allclose(coast.mesh_stiffness_coast.values, drive.mesh_stiffness.values,
                               rtol=1e-12)
    assert not np.allclose(coast.mesh_stiffness_coast.values, coast.mesh_stiffness.values)


def test_faults_on_the_planet_tooth() -> None:
    """A root crack on the planet lowers the stiffness of its pairs only, zero depth is healthy
    bitwise, and a missing ring tooth takes its pairs out of contact."""
    mesh = _mesh()
    kw = dict(bore_radius=BORES, angles=30, cycles=Z1)
    healthy = potential_energy_stiffness(mesh, **kw)
    zero = potential_energy_stiffness(mesh, faults=RootCrack(0.0, gear="pinion", tooth=2), **kw)
    np.testing.assert_array_equal(zero.mesh_stiffness.values, healthy.mesh_stiffness.values)
    crack = RootCrack(1e-3, gear="pinion", tooth=2)
    cracked = potential_energy_stiffness(mesh, faults=crack, **kw)
    on = (cracked.tooth_pinion.values == 2) & cracked.in_contact.values
    ratio = cracked.pair_stiffness.values / np.where(healthy.in_contact, healthy.pair_stiffness,
                                                     1.0)
    assert np.all(ratio[on] < 1.0)
    np.testing.assert_array_equal(ratio[~on & healthy.in_contact.values], 1.0)
    broken = potential_energy_stiffness(mesh, faults=BrokenTooth(gear="wheel", tooth=5), **kw)
    gone = (broken.tooth_wheel.values == 5) & healthy.in_contact.values
    assert gone.any()
    assert not broken.in_contact.values[gone].any()


def test_planet_archard_slip_is_the_internal_kinematics() -> None:
    """In single contact (the whole load on one pair) Archard's rate of the planet's flank is
    its slip |v_1 - v_2| / v_1 = |(1 - z1/z2) s| / rho_1: the planet and the ring turn the same
    way, so the flanks slide at (omega_1 - omega_2) s, not (omega_1 + omega_2) s."""
    g = _internal()
    mesh = _mesh()
    pair = prepare_pair(mesh, bore_radius=BORES)
    p_b = math.pi * M * math.cos(ALPHA)
    g_f = g["rb2"] * math.tan(g["a_w"]) - math.sqrt(g["ra2"] ** 2 - g["rb2"] ** 2)
    g_a = math.sqrt(g["ra1"] ** 2 - g["rb1"] ** 2) - g["rb1"] * math.tan(g["a_w"])
    s = np.linspace(g_a - p_b, p_b - g_f, 9)[1:-1]
    assert s[0] < s[-1]
    slip = np.abs((1.0 - Z1 / Z2) * s) / (g["rb1"] * math.tan(g["a_w"]) + s)
    np.testing.assert_allclose(pair.archard_rate("pinion", s), slip, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("kwargs, field", [
    (dict(bore_radius=(8e-3, 0.0760)), "wheel.bore_radius"),  # rim thinner than the teeth
    (dict(bore_radius=(8e-3, 0.0)), "wheel.bore_radius"),
    (dict(bore_radius=BORES, ring_foundation="sainsot"), "ring_foundation"),
    (dict(bore_radius=BORES, faults=Wear(1e-3, gear="wheel")), "wear.depth"),
    (dict(bore_radius=BORES, faults=RootCrack(4e-3, "90 deg", gear="wheel")), "crack.depth"),
    (dict(bore_radius=BORES, faults=Spall(length=1e-4, width=1e-3, depth=1e-5,
                                          position=3e-3, gear="wheel")), "spall.position"),
    (dict(bore_radius=BORES, faults=Spall(length=1e-4, width=30e-3, depth=1e-5,
                                          gear="wheel")), "spall.width"),
])
def test_bad_inputs_name_the_field(kwargs: dict, field: str) -> None:
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(_mesh(), **kwargs)
    assert info.value.field == field


def test_rim_just_as_thick_as_the_teeth_is_accepted() -> None:
    ring = _mesh().wheel
    rim = 2.0 * ring.root_radius - ring.tip_radius  # r_f + tooth height
    ds = potential_energy_stiffness(_mesh(), bore_radius=(8e-3, rim), angles=8)
    assert ds.attrs["wheel_bore_radius_m"] == rim
    assert ds.attrs["ring_foundation"] == "rigid"
    assert np.all(np.isfinite(ds.mesh_stiffness.values))


_ROW = re.compile(r"^\| (\d+)/(\d+), m ([\d.]+) mm, b (\d+) mm \|(.*)\|$", re.M)


def test_docs_internal_iso_table_is_computed() -> None:
    """Every number of docs/gears.md's planet-ring table, recomputed."""
    text = (Path(__file__).resolve().parent.parent / "docs" / "gears.md").read_text()
    table = text.split("<!-- pe-iso-internal:begin")[1].split("<!-- pe-iso-internal:end")[0]
    rows = _ROW.findall(table)
    assert len(rows) >= 3
    for z1, z2, m, b, cells in rows:
        doc = [float(c) for c in cells.split("|")]
        planet = SpurGear(int(z1), f"{m} mm", "20 deg", f"{b} mm", name="pinion")
        ring = SpurGear(int(z2), f"{m} mm", "20 deg", f"{b} mm", internal=True, name="wheel")
        mesh = GearMesh(planet, ring, internal=True)
        iso = iso6336_stiffness(mesh)
        per_width = planet.face_width * 1e9  # N/m -> N/(mm um)
        rim = ring.root_radius + 3.0 * ring.module
        means = {}
        for h_fi in (1.5, 2.0, 3.0):
            ds = potential_energy_stiffness(mesh, bore_radius=(planet.root_radius / h_fi, rim),
                                            angles=720)
            means[h_fi] = float(ds.mesh_stiffness.mean()) / per_width
        pair = prepare_pair(mesh, bore_radius=(planet.root_radius / 2.0, rim))
        single = pair.terms(np.array([0.0]))["pair"][0]
        got = [mesh.contact_ratio, iso.c_prime, iso.c_gamma_alpha, single / per_width,
               means[1.5], means[2.0], means[3.0], means[2.0] / iso.c_gamma_alpha]
        digits = [4, 2, 2, 2, 2, 2, 2, 2]
        assert [round(g, d) for g, d in zip(got, digits, strict=True)] == doc, (z1, z2)


# ---------------------------------------------------------------------------------------------
# a spall or wear on a ring tooth


def _worn_ring_reference(g: dict[str, float], position: float, cut: object) -> dict[str, float]:
    """The ring tooth by quad with the sections between the roll angles ``cut.rolls`` (t from
    the base circle, alpha = a2 + t) losing ``cut.area(h)`` and with ``cut.inertia(h)`` about
    their own centroid (module docstring; healthy I = (2/3) h^3 b, A = 2 h b elsewhere)."""
    rb, a2 = g["rb2"], g["a2"]
    a1 = a2 + (rb * math.tan(g["a_w"]) + position) / rb
    top = a2 + math.sqrt((g["rf2"] / rb) ** 2 - 1.0)
    c, s = math.cos(a1), math.sin(a1)
    xc = rb * (math.cos(a1) + (a1 - a2) * math.sin(a1))
    hc = rb * (math.sin(a1) - (a1 - a2) * math.cos(a1))
    lo, hi = (a2 + t for t in cut.rolls)

    def geom(a: float) -> tuple[float, float, float, float]:
        h = rb * (math.sin(a) - (a - a2) * math.cos(a))
        x = rb * (math.cos(a) + (a - a2) * math.sin(a))
        inertia, area = (cut.section(h) if lo <= a <= hi
                         else ((2.0 / 3.0) * h ** 3 * B, 2.0 * h * B))
        return inertia, area, x, rb * (a - a2) * math.cos(a)

    def bend(a: float) -> float:
        inertia, _, x, dx = geom(a)
        return (c * (x - xc) - s * hc) ** 2 / (E * inertia) * dx

    def inv_area(a: float) -> float:
        _, area, _, dx = geom(a)
        return dx / area

    points = [p for p in (lo, hi) if a1 < p < top]
    tight = dict(epsabs=0.0, epsrel=1e-12, limit=400, points=points or None)
    area = quad(inv_area, a1, top, **tight)[0]
    return {"bending": quad(bend, a1, top, **tight)[0],
            "shear": 1.2 * c ** 2 * 2.0 * (1.0 + NU) / E * area, "axial": s ** 2 / E * area}


class _Cut:
    def __init__(self, rolls: tuple[float, float], section) -> None:  # noqa: ANN001
        self.rolls, self.section = rolls, section


def test_worn_and_spalled_ring_tooth_match_quad() -> None:
    """Uniform wear d over the ring tooth's active profile (from its tip to the deepest contact,
    the end of the path) leaves sections 2h - d thick; a w x d spall centred ``position`` along
    the profile (positive towards the ring's tip, i.e. inwards) removes a rectangle at the
    flank, I about the remaining section's centroid (parallel axes) - each by quad against the
    ring tooth's compliance terms at contacts on and off the fault."""
    g = _internal()
    mesh = _mesh()
    rb = g["rb2"]
    g_a = math.sqrt(g["ra1"] ** 2 - g["rb1"] ** 2) - g["rb1"] * math.tan(g["a_w"])
    t_tip = math.sqrt((g["ra2"] / rb) ** 2 - 1.0)
    t_deep = (rb * math.tan(g["a_w"]) + g_a) / rb
    d = 20e-6
    wear = Wear(d, gear="wheel")
    worn = _Cut((t_tip, t_deep), lambda h: ((2.0 * h - d) ** 3 * B / 12.0, (2.0 * h - d) * B))
    length, width, depth, centre = 1e-3, 4e-3, 0.2e-3, 0.6e-3  # edges off the contacts
    p = math.tan(ALPHA)  # the reference circle's roll; towards the tip the roll falls

    def roll(along: float) -> float:
        return math.sqrt(p * p - 2.0 * along / rb)

    spall = Spall(length=length, width=width, depth=depth, position=centre, gear="wheel")

    def spalled(h: float) -> tuple[float, float]:
        cut_area = width * depth
        area = 2.0 * h * B - cut_area
        y_c = -cut_area * (h - 0.5 * depth) / area  # the centroid moves away from the cut
        inertia = ((2.0 * h) ** 3 * B / 12.0 + 2.0 * h * B * y_c ** 2
                   - (width * depth ** 3 / 12.0 + cut_area * (h - 0.5 * depth - y_c) ** 2))
        return inertia, area

    pitted = _Cut((roll(centre + 0.5 * length), roll(centre - 0.5 * length)), spalled)
    positions = np.array([-3e-3, -1e-3, 0.0, 1e-3, 2e-3])
    for fault, cut in ((wear, worn), (spall, pitted)):
        pair = prepare_pair(mesh, bore_radius=BORES, young=E, poisson=NU, faults=[fault])
        terms = pair.terms(positions, wheel=fault)
        healthy = pair.terms(positions)
        for i, s in enumerate(positions):
            ref = _worn_ring_reference(g, float(s), cut)
            for name, value in ref.items():
                got = 1.0 / terms[f"{name}_wheel"][i]
                assert got == pytest.approx(value, rel=1e-9), (fault.kind, name, s)
                assert got >= (1.0 - 1e-12) / healthy[f"{name}_wheel"][i]  # never stiffer
        # the spall narrows the Hertz contact where the contact lies on it
        on = [cut.rolls[0] <= (rb * math.tan(g["a_w"]) + s) / rb <= cut.rolls[1]
              for s in positions]
        narrowed = math.pi * E * (B - (width if fault is spall else 0.0)) / (4.0 * (1 - NU ** 2))
        for i in range(positions.size):
            want = narrowed if on[i] else math.pi * E * B / (4.0 * (1 - NU ** 2))
            assert terms["hertz"][i] == pytest.approx(want, rel=1e-12)
    assert any(on) and not all(on)  # the check has teeth


def test_ring_flank_faults_mirror_between_the_flanks() -> None:
    """A spall (or wear) on the ring tooth's coast flank acts on the coast contacts as the same
    fault on the drive flank acts on the drive contacts, over a ring revolution."""
    mesh = _mesh()
    kw = dict(bore_radius=BORES, young=E, poisson=NU, angles=60, cycles=Z2)
    spall = dict(length=1e-3, width=4e-3, depth=0.2e-3, position=0.5e-3, gear="wheel", tooth=5)
    drive = potential_energy_stiffness(mesh, faults=[Spall(**spall)], **kw)
    coast = potential_energy_stiffness(mesh, faults=[Spall(**spall, flank="coast")], **kw)
    base = potential_energy_stiffness(mesh, **kw)
    for a, b in (("mesh_stiffness", "mesh_stiffness_coast"),
                 ("mesh_stiffness_coast", "mesh_stiffness")):
        da = drive[a].values - base[a].values
        db = coast[b].values - base[b].values
        assert da.min() < -1e5
        np.testing.assert_allclose(np.sort(da), np.sort(db), rtol=0.0,
                                   atol=1e-6 * np.ptp(da))
