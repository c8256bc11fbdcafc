"""Potential-energy mesh stiffness of spur pairs (geardyn.gears.potential_energy).

The reference values are computed here from the published formulas, written out independently
of the module (Tian 2004's closed-form integrands in the involute parameter, scipy's adaptive
quad, the geometry from the textbook relations for unshifted gears), never from its output.
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
from geardyn.gears.potential_energy import (
    RootCrack,
    potential_energy_stiffness,
    prepare_pair,
    tooth_compliances,
)
from pair_19_48 import ALPHA, BORES, NU, Z1, Z2, B, E, M


def _mesh(width: float = B) -> GearMesh:
    return GearMesh(SpurGear(Z1, M, ALPHA, width, name="pinion"),
                    SpurGear(Z2, M, ALPHA, width, name="wheel"))


@pytest.fixture(scope="module")
def mesh() -> GearMesh:
    return _mesh()


# -- independent geometry of unshifted gears (h_a = 1, h_f = 1.25) ---------------------------


def _geometry(z: int) -> dict[str, float]:
    r = M * z / 2.0
    inv = math.tan(ALPHA) - ALPHA
    return {"rb": r * math.cos(ALPHA), "rf": r - 1.25 * M, "ra": r + M,
            "a2": math.pi / (2.0 * z) + inv}


def _alpha1(z: int, roll: float) -> float:
    """Load angle alpha_1 of a contact at roll angle ``roll`` (= tan of its pressure angle)."""
    return roll - _geometry(z)["a2"]


def _rolls(z: int, z_other: int) -> list[float]:
    """Roll angles of the lowest contact, the pitch point and the tip of gear ``z``."""
    g, o = _geometry(z), _geometry(z_other)
    a = M * (z + z_other) / 2.0
    lowest = (a * math.sin(ALPHA) - math.sqrt(o["ra"] ** 2 - o["rb"] ** 2)) / g["rb"]
    return [lowest, math.tan(ALPHA), math.sqrt(g["ra"] ** 2 - g["rb"] ** 2) / g["rb"]]


def _reference(z: int, a1: float, root_segment: bool = True) -> dict[str, float]:
    """Tian (2004)'s integrands in alpha, by quad, plus the straight root flank by quad in x
    (r_f < r_b), and Sainsot (2004)'s fillet formula."""
    g = _geometry(z)
    rb, rf, a2 = g["rb"], g["rf"], g["a2"]
    top = a2 if rf <= rb else a2 - math.sqrt((rf / rb) ** 2 - 1.0)
    c, s = math.cos(a1), math.sin(a1)

    def den(a: float) -> float:
        return math.sin(a) + (a2 - a) * math.cos(a)

    def bend(a: float) -> float:
        return (3.0 * (1.0 + c * ((a2 - a) * math.sin(a) - math.cos(a))) ** 2
                * (a2 - a) * math.cos(a) / (2.0 * E * B * den(a) ** 3))

    def shear(a: float) -> float:
        return 1.2 * (1.0 + NU) * (a2 - a) * math.cos(a) * c ** 2 / (E * B * den(a))

    def axial(a: float) -> float:
        return (a2 - a) * math.cos(a) * s ** 2 / (2.0 * E * B * den(a))

    tight = dict(epsabs=0.0, epsrel=1e-12, limit=200)
    out = {name: quad(f, -a1, top, **tight)[0]
           for name, f in (("bending", bend), ("shear", shear), ("axial", axial))}
    xc = rb * (math.cos(a1) + (a1 + a2) * math.sin(a1))
    hc = rb * ((a1 + a2) * math.cos(a1) - math.sin(a1))
    hb = rb * math.sin(a2)
    if rf < rb and root_segment:
        x0, x1 = math.sqrt(rf ** 2 - hb ** 2), rb * math.cos(a2)
        inertia, area = 2.0 * hb ** 3 * B / 3.0, 2.0 * hb * B
        g_mod = E / (2.0 * (1.0 + NU))
        out["bending"] += quad(lambda x: (c * (xc - x) - s * hc) ** 2 / (E * inertia),
                               x0, x1, **tight)[0]
        out["shear"] += quad(lambda x: 1.2 * c ** 2 / (g_mod * area), x0, x1, **tight)[0]
        out["axial"] += quad(lambda x: s ** 2 / (E * area), x0, x1, **tight)[0]
    # fillet foundation: theta_f, the half angle of the tooth at the root circle
    if rf <= rb:
        theta_f = math.asin(hb / rf)
    else:
        alpha_f = math.acos(rb / rf)
        theta_f = a2 - (math.tan(alpha_f) - alpha_f)
    bore = BORES[0] if z == Z1 else BORES[1]
    h = rf / bore
    coef = {"L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
            "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
            "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
            "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904)}
    lmpq = {k: v[0] / theta_f ** 2 + v[1] * h ** 2 + v[2] * h / theta_f + v[3] / theta_f
            + v[4] * h + v[5] for k, v in coef.items()}
    u_f = xc - hc * math.tan(a1) - rf  # where the force line crosses the centre line
    ratio = u_f / (2.0 * rf * theta_f)
    out["fillet"] = (c ** 2 / (E * B) * (lmpq["L"] * ratio ** 2 + lmpq["M"] * ratio
                                         + lmpq["P"] * (1.0 + lmpq["Q"] * math.tan(a1) ** 2)))
    return out


# -- closed forms ----------------------------------------------------------------------------


def test_contact_ratio_of_the_19_48_pair(mesh: GearMesh) -> None:
    assert round(mesh.contact_ratio, 5) == 1.64563  # issue 35's closed form


def test_hertz_term_is_the_closed_form(mesh: GearMesh) -> None:
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=16)
    k_h = math.pi * E * B / (4.0 * (1.0 - NU ** 2))
    values = ds.k_hertz.values[ds.in_contact.values]
    assert values.size > 0
    np.testing.assert_allclose(values, k_h, rtol=1e-15, atol=0.0)


# -- each energy integral against quad -------------------------------------------------------


@pytest.mark.parametrize("root_segment", [True, False])
@pytest.mark.parametrize("which", ["pinion", "wheel"])
def test_energy_terms_match_quad(mesh: GearMesh, which: str, root_segment: bool) -> None:
    pair = prepare_pair(mesh, bore_radius=BORES, young=E, poisson=NU,
                        root_segment=root_segment)
    tooth = pair.pinion if which == "pinion" else pair.wheel
    z, zo = (Z1, Z2) if which == "pinion" else (Z2, Z1)
    a1 = np.array([_alpha1(z, roll) for roll in _rolls(z, zo)])
    got = tooth_compliances(tooth, a1, young=E, poisson=NU, face_width=B)
    for i, alpha1 in enumerate(a1):
        ref = _reference(z, float(alpha1), root_segment)
        for name, value in ref.items():
            assert got[name][i] == pytest.approx(value, rel=1e-10, abs=0.0), (which, name, i)


def test_root_circle_sides(mesh: GearMesh) -> None:
    """The 19-tooth pinion has its root circle below the base circle, the 48-tooth wheel above
    it (z (1 - cos 20 deg) = 2.5 at about 41.5 teeth)."""
    p, w = _geometry(Z1), _geometry(Z2)
    assert p["rf"] < p["rb"] and w["rf"] > w["rb"]
    pair = prepare_pair(mesh, bore_radius=BORES)
    assert pair.pinion.segment is not None and pair.wheel.segment is None


def test_mesh_stiffness_over_the_cycle_matches_an_independent_computation(
        mesh: GearMesh) -> None:
    """Pairs placed on the line of action here, each tooth's terms by quad (above)."""
    n = 12
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=n)
    p, w = _geometry(Z1), _geometry(Z2)
    pb = math.pi * M * math.cos(ALPHA)
    g_f = math.sqrt(w["ra"] ** 2 - w["rb"] ** 2) - w["rb"] * math.tan(ALPHA)
    g_a = math.sqrt(p["ra"] ** 2 - p["rb"] ** 2) - p["rb"] * math.tan(ALPHA)
    k_h = math.pi * E * B / (4.0 * (1.0 - NU ** 2))
    for i in range(n):
        total = 0.0
        for u in (i / n, i / n - 1.0):  # the pair at or past the pitch point, the next one
            if not -g_f <= u * pb < g_a:
                continue
            c = 1.0 / k_h
            for z, roll in ((Z1, math.tan(ALPHA) + u * pb / p["rb"]),
                            (Z2, math.tan(ALPHA) - u * pb / w["rb"])):
                c += sum(_reference(z, _alpha1(z, roll)).values())
            total += 1.0 / c
        assert ds.mesh_stiffness.values[i] == pytest.approx(total, rel=1e-10), i


def test_pair_stiffness_is_the_series_sum(mesh: GearMesh) -> None:
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=24)
    names = [f"k_{t}_{g}" for g in ("pinion", "wheel")
             for t in ("bending", "shear", "axial", "fillet")] + ["k_hertz"]
    inside = ds.in_contact.values
    compliance = sum(1.0 / ds[n].values[inside] for n in names)
    np.testing.assert_allclose(ds.pair_stiffness.values[inside], 1.0 / compliance, rtol=1e-14)
    np.testing.assert_array_equal(ds.pair_stiffness.values[~inside], 0.0)
    np.testing.assert_allclose(ds.mesh_stiffness.values, ds.pair_stiffness.sum("pair").values,
                               rtol=1e-15)


def test_quadrature_is_converged(mesh: GearMesh) -> None:
    a = potential_energy_stiffness(mesh, bore_radius=BORES, angles=36)
    b = potential_energy_stiffness(mesh, bore_radius=BORES, angles=36, nodes=96)
    np.testing.assert_allclose(a.mesh_stiffness, b.mesh_stiffness, rtol=1e-10)


# -- pairs in contact ------------------------------------------------------------------------


def test_pairs_in_contact_follow_the_contact_ratio(mesh: GearMesh) -> None:
    n = 3600
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=n)
    count = ds.pairs_in_contact.values
    assert set(np.unique(count)) == {1, 2}
    eps = 1.64563  # closed form above
    assert np.mean(count == 2) == pytest.approx(eps - 1.0, abs=1.5 / n)
    # one double and one single interval per cycle
    assert np.count_nonzero(np.diff(np.r_[count, count[0]]) != 0) == 2
    # double contact from the entry of a new pair at the wheel's tip to the exit of the old
    # one at the pinion's tip: g_f / p_b before, g_a / p_b after the pitch point
    p, w = _geometry(Z1), _geometry(Z2)
    pb = math.pi * M * math.cos(ALPHA)
    g_f = math.sqrt(w["ra"] ** 2 - w["rb"] ** 2) - w["rb"] * math.tan(ALPHA)
    g_a = math.sqrt(p["ra"] ** 2 - p["rb"] ** 2) - p["rb"] * math.tan(ALPHA)
    f = ds.cycle.values
    np.testing.assert_array_equal(count == 2, (f >= 1.0 - g_f / pb) & (f < g_a / pb))
    assert ds.angle.values[-1] == pytest.approx(360.0 / Z1 * (n - 1) / n)


# -- scaling ---------------------------------------------------------------------------------


def test_stiffness_proportional_to_young_and_face_width(mesh: GearMesh) -> None:
    base = potential_energy_stiffness(mesh, bore_radius=BORES, angles=45)
    stiff = potential_energy_stiffness(mesh, bore_radius=BORES, angles=45, young=3.0 * E)
    wide = potential_energy_stiffness(_mesh(2.5 * B), bore_radius=BORES, angles=45)
    for name in ("mesh_stiffness", "k_hertz", "k_bending_pinion", "k_fillet_wheel"):
        np.testing.assert_allclose(stiff[name], 3.0 * base[name], rtol=1e-13)
        np.testing.assert_allclose(wide[name], 2.5 * base[name], rtol=1e-13)


def test_poisson_enters_hertz_and_shear_only(mesh: GearMesh) -> None:
    a = potential_energy_stiffness(mesh, bore_radius=BORES, angles=20, poisson=0.3)
    b = potential_energy_stiffness(mesh, bore_radius=BORES, angles=20, poisson=0.25)
    np.testing.assert_allclose(b.k_hertz, a.k_hertz * (1 - 0.09) / (1 - 0.0625), rtol=1e-14)
    np.testing.assert_allclose(b.k_shear_pinion, a.k_shear_pinion * 1.3 / 1.25, rtol=1e-14)
    for name in ("k_bending_pinion", "k_axial_wheel", "k_fillet_pinion"):
        np.testing.assert_array_equal(a[name].values, b[name].values)


def test_bore_enters_the_fillet_term_only(mesh: GearMesh) -> None:
    a = potential_energy_stiffness(mesh, bore_radius=BORES, angles=20)
    b = potential_energy_stiffness(mesh, bore_radius=(0.02, 0.05), angles=20)
    for name in ("k_hertz", "k_bending_pinion", "k_shear_wheel", "k_axial_pinion"):
        np.testing.assert_array_equal(a[name].values, b[name].values)
    inside = a.in_contact.values
    assert not np.allclose(a.k_fillet_pinion.values[inside], b.k_fillet_pinion.values[inside])


# -- errors ----------------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs, field", [
    (dict(young=float("nan")), "young"),
    (dict(young=-1.0), "young"),
    (dict(young="200 mm"), "young"),
    (dict(poisson=0.5), "poisson"),
    (dict(poisson=float("nan")), "poisson"),
    (dict(bore_radius=-0.01), "pinion.bore_radius"),
    (dict(bore_radius=(0.01, 0.08)), "wheel.bore_radius"),
    (dict(bore_radius=(0.01, float("nan"))), "wheel.bore_radius"),
    (dict(bore_radius=(0.01, 0.02, 0.03)), "bore_radius"),
    (dict(angles=0), "angles"),
    (dict(angles=[0.0, float("nan")]), "angles"),
    (dict(nodes=2), "nodes"),
    (dict(cycles=0), "cycles"),
    (dict(cycles=1.5), "cycles"),
    (dict(faults="1 mm"), "faults"),
])
def test_bad_inputs_name_the_field(mesh: GearMesh, kwargs: dict, field: str) -> None:
    args = dict(bore_radius=BORES) | kwargs
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(mesh, **args)
    assert info.value.field == field


def test_undercut_is_refused() -> None:
    """(Internal pairs: tests/test_internal_stiffness.py.)"""
    p = SpurGear(14, M, ALPHA, B, name="pinion", check_undercut=False)  # x_min = 0.18
    w = SpurGear(25, M, ALPHA, B, name="wheel")
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(GearMesh(p, w), bore_radius=0.005)
    assert info.value.field == "pinion.profile_shift"
    with pytest.raises(ParameterError) as info:
        SpurGear(Z1, M, ALPHA, -B, name="pinion")
    assert info.value.field == "pinion.face_width"


# -- docs/gears.md's comparison with ISO 6336-1 ----------------------------------------------

_ROW = re.compile(r"^\| (\d+)/(\d+), m ([\d.]+) mm, b (\d+) mm \|(.*)\|$", re.M)


def test_docs_iso_comparison_table_is_computed() -> None:
    """Every number of docs/gears.md's potential-energy vs ISO table, recomputed."""
    text = (Path(__file__).resolve().parent.parent / "docs" / "gears.md").read_text()
    table = text.split("<!-- pe-iso-table:begin")[1].split("<!-- pe-iso-table:end")[0]
    rows = _ROW.findall(table)
    assert len(rows) >= 3
    for z1, z2, m, b, cells in rows:
        doc = [float(c) for c in cells.split("|")]
        mesh = GearMesh(SpurGear(int(z1), f"{m} mm", "20 deg", f"{b} mm", name="pinion"),
                        SpurGear(int(z2), f"{m} mm", "20 deg", f"{b} mm", name="wheel"))
        iso = iso6336_stiffness(mesh)
        per_width = mesh.pinion.face_width * 1e9  # N/m -> N/(mm um)
        means = {}
        for h_fi in (1.5, 2.0, 3.0):
            bores = (mesh.pinion.root_radius / h_fi, mesh.wheel.root_radius / h_fi)
            ds = potential_energy_stiffness(mesh, bore_radius=bores, angles=720)
            means[h_fi] = float(ds.mesh_stiffness.mean()) / per_width
        bores = (mesh.pinion.root_radius / 2.0, mesh.wheel.root_radius / 2.0)
        single = prepare_pair(mesh, bore_radius=bores).terms(np.array([0.0]))["pair"][0]
        got = [mesh.contact_ratio, iso.c_prime, iso.c_gamma_alpha, single / per_width,
               means[1.5], means[2.0], means[3.0], means[2.0] / iso.c_gamma_alpha]
        digits = [4, 2, 2, 2, 2, 2, 2, 2]
        assert [round(g, d) for g, d in zip(got, digits, strict=True)] == doc, (z1, z2)


# -- root crack on one tooth -----------------------------------------------------------------


def _cracked_reference(z: int, a1: float, reach: float) -> dict[str, float]:
    """Tian's cracked tooth by quad: every section is h + min(h, h_q) thick (the crack limit
    line at h_q = h_r - q sin v from the centre line cuts the sections wider than h_q), the
    straight root flank h_b + h_q; pinion (r_f < r_b) only."""
    g = _geometry(z)
    rb, rf, a2 = g["rb"], g["rf"], g["a2"]
    hb = rb * math.sin(a2)
    hq = hb - reach
    c, s = math.cos(a1), math.sin(a1)
    xc = rb * (math.cos(a1) + (a1 + a2) * math.sin(a1))
    hc = rb * ((a1 + a2) * math.cos(a1) - math.sin(a1))
    g_mod = E / (2.0 * (1.0 + NU))

    def geom(a: float) -> tuple[float, float, float]:
        h = rb * (math.sin(a) + (a2 - a) * math.cos(a))
        x = rb * (math.cos(a) - (a2 - a) * math.sin(a))
        return h + min(h, hq), x, rb * (a2 - a) * math.cos(a)

    def bend(a: float) -> float:
        t, x, dx = geom(a)
        return (c * (xc - x) - s * hc) ** 2 / (E * t ** 3 * B / 12.0) * dx

    def inv_area(a: float) -> float:
        t, _, dx = geom(a)
        return dx / (t * B)

    tight = dict(epsabs=0.0, epsrel=1e-12, limit=400)
    x0, x1 = math.sqrt(rf ** 2 - hb ** 2), rb * math.cos(a2)
    t_b = hb + hq
    bending = (quad(bend, -a1, a2, **tight)[0]
               + quad(lambda x: (c * (xc - x) - s * hc) ** 2 / (E * t_b ** 3 * B / 12.0),
                      x0, x1, **tight)[0])
    area = quad(inv_area, -a1, a2, **tight)[0] + (x1 - x0) / (t_b * B)
    return {"bending": bending, "shear": 1.2 * c ** 2 / g_mod * area,
            "axial": s ** 2 / E * area}


@pytest.mark.parametrize("depth", [0.4e-3, 1.5e-3, 3.5e-3])
def test_cracked_tooth_matches_quad(mesh: GearMesh, depth: float) -> None:
    crack = RootCrack(depth, "45 deg")
    pair = prepare_pair(mesh, bore_radius=BORES, faults=crack)
    a1 = np.array([_alpha1(Z1, roll) for roll in _rolls(Z1, Z2)])
    got = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B, fault=crack)
    healthy = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B)
    for i, alpha1 in enumerate(a1):
        ref = _cracked_reference(Z1, float(alpha1), depth * math.sin(math.radians(45.0)))
        for name, value in ref.items():
            assert got[name][i] == pytest.approx(value, rel=1e-8, abs=0.0), (name, i)
            assert got[name][i] > healthy[name][i]
        assert got["fillet"][i] == healthy["fillet"][i]


def test_zero_crack_is_healthy_bitwise(mesh: GearMesh) -> None:
    healthy = potential_energy_stiffness(mesh, bore_radius=BORES, angles=60, cycles=Z1)
    zero = potential_energy_stiffness(mesh, bore_radius=BORES, angles=60, cycles=Z1,
                                      faults=RootCrack(0.0, tooth=3))
    for name in healthy.data_vars:
        np.testing.assert_array_equal(zero[name].values, healthy[name].values)


def test_stiffness_falls_monotonically_with_crack_depth(mesh: GearMesh) -> None:
    depths = [0.0, 1e-5, 0.5e-3, 1e-3, 1.5e-3, 2e-3, 2.5e-3, 3e-3, 3.5e-3]
    runs = [potential_energy_stiffness(mesh, bore_radius=BORES, angles=40, cycles=2 * Z1,
                                       faults=RootCrack(q, tooth=5)).mesh_stiffness.values
            for q in depths]
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=40, cycles=2 * Z1)
    touched = ((ds.tooth_pinion == 5) & ds.in_contact).any("pair").values
    assert touched.any() and not touched.all()
    for shallower, deeper in zip(runs, runs[1:], strict=False):
        assert np.all(deeper[touched] < shallower[touched])
        np.testing.assert_array_equal(deeper[~touched], shallower[~touched])
    # once per pinion revolution: the pattern repeats every z1 mesh cycles
    n = 40 * Z1
    np.testing.assert_array_equal(runs[-1][:n], runs[-1][n:])


def test_tooth_indices_follow_the_pitch_point_passages(mesh: GearMesh) -> None:
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=10, cycles=3 * Z2)
    n = np.floor(ds.cycle.values).astype(int)
    for j, k in enumerate(ds.pair.values):
        np.testing.assert_array_equal(ds.tooth_pinion.values[:, j], (n - k) % Z1)
        np.testing.assert_array_equal(ds.tooth_wheel.values[:, j], (n - k) % Z2)
    cracked = potential_energy_stiffness(mesh, bore_radius=BORES, angles=10, cycles=3 * Z2,
                                         faults=RootCrack("1 mm", gear="wheel", tooth=7))
    changed = cracked.mesh_stiffness.values != ds.mesh_stiffness.values
    assert np.array_equal(changed, ((ds.tooth_wheel == 7) & ds.in_contact).any("pair").values)


@pytest.mark.parametrize("crack, field", [
    (lambda: RootCrack(4.0e-3, "90 deg"), "crack.depth"),  # past the centre line
    (lambda: RootCrack(1e-3, tooth=19), "crack.tooth"),
    (lambda: RootCrack(-1e-3), "crack.depth"),
    (lambda: RootCrack(float("nan")), "crack.depth"),
    (lambda: RootCrack(1e-3, angle=0.0), "crack.angle"),
    (lambda: RootCrack(1e-3, gear="ring"), "crack.gear"),
])
def test_bad_cracks_name_the_field(mesh: GearMesh, crack, field: str) -> None:
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(mesh, bore_radius=BORES, faults=crack())
    assert info.value.field == field


# -- the coast (back) flank --------------------------------------------------------------------


def _inv(a: float) -> float:
    return math.tan(a) - a


def _pitch_thickness_fraction(z1: int, z2: int, x1: float, x2: float,
                              a: float) -> tuple[float, float]:
    """(s_w1 / p_w1, j / p_w1) at centre distance ``a`` from the textbook thickness formula
    s_w = d_w (s / d + inv alpha - inv alpha_w), s = m (pi/2 + 2 x tan alpha)."""
    r1, r2 = M * z1 / 2.0, M * z2 / 2.0
    a_w = math.acos((r1 + r2) * math.cos(ALPHA) / a)
    rw1, rw2 = r1 * math.cos(ALPHA) / math.cos(a_w), r2 * math.cos(ALPHA) / math.cos(a_w)

    def s_w(r: float, rw: float, x: float) -> float:
        s = M * (math.pi / 2.0 + 2.0 * x * math.tan(ALPHA))
        return 2.0 * rw * (s / (2.0 * r) + _inv(ALPHA) - _inv(a_w))

    p_w1 = 2.0 * math.pi * rw1 / z1
    t1, t2 = s_w(r1, rw1, x1), s_w(r2, rw2, x2)  # arcs of the rolling circles
    return t1 / p_w1, (p_w1 - t1 - t2) / p_w1


@pytest.mark.parametrize("shift, extra", [((0.0, 0.0), 0.0), ((0.3, -0.1), 0.0),
                                          ((0.2, 0.1), 2e-4)])
def test_coast_stiffness_is_the_drive_stiffness_mirrored(shift: tuple[float, float],
                                                         extra: float) -> None:
    """K_coast(c) = K_drive(phi - c), phi = s_w1 / p_w1 from the thickness formula here
    (1/2 for unshifted teeth without backlash), for zero and nonzero backlash."""
    p = SpurGear(Z1, M, ALPHA, B, profile_shift=shift[0], name="pinion")
    w = SpurGear(Z2, M, ALPHA, B, profile_shift=shift[1], name="wheel")
    a0 = GearMesh(p, w).centre_distance
    mesh = GearMesh(p, w, centre_distance=a0 + extra)
    phi, j = _pitch_thickness_fraction(Z1, Z2, *shift, a0 + extra)
    if shift == (0.0, 0.0):
        assert phi == pytest.approx(0.5, abs=1e-12)
    c = (np.arange(97) + 0.3183) / 97.0 * 3.0  # off the contact boundaries
    deg = 360.0 / Z1
    coast = potential_energy_stiffness(mesh, bore_radius=BORES, angles=c * deg)
    drive = potential_energy_stiffness(mesh, bore_radius=BORES, angles=(phi - c) * deg)
    assert coast.attrs["coast_phase_cycles"] == pytest.approx(phi, abs=1e-12)
    assert coast.attrs["backlash_cycles"] == pytest.approx(j, abs=1e-12)
    assert (extra == 0.0) == (abs(j) < 1e-12)
    np.testing.assert_allclose(coast.mesh_stiffness_coast.values,
                               drive.mesh_stiffness.values, rtol=1e-12)
    np.testing.assert_array_equal(coast.pairs_in_contact_coast.values,
                                  drive.pairs_in_contact.values)
    assert coast.mesh_stiffness_coast.attrs["units"] == "N/m"
    # not the drive side itself: the phase matters
    assert not np.allclose(coast.mesh_stiffness_coast.values, coast.mesh_stiffness.values)


def test_coast_teeth_and_contact_follow_the_flanks(mesh: GearMesh) -> None:
    """Pinion tooth j's coast flank passes the pitch point phi + j cycles after angle 0 (its
    contact there at position 0). Wheel tooth i's drive flank passes it at cycle i, its coast
    flank s_w2 / p_w cycles earlier: the wheel tooth there is i = phi + j + s_w2 / p_w. A coast
    contact moves towards the pinion root as the pinion turns."""
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=40, cycles=Z1 + 2)
    phi, j_b = _pitch_thickness_fraction(Z1, Z2, 0.0, 0.0, mesh.centre_distance)
    for j in (0, 3, Z1 - 1):
        c = phi + j
        wheel_tooth = round(c + (1.0 - phi - j_b)) % Z2
        i = int(np.argmin(np.abs(ds.cycle.values - c)))
        sel = ds.isel(angle=i)
        at = np.flatnonzero(np.abs(sel.position_coast.values) < 1e-12)
        assert at.size == 1
        assert int(sel.tooth_pinion_coast.values[at[0]]) == j
        assert int(sel.tooth_wheel_coast.values[at[0]]) == wheel_tooth
        assert bool(sel.in_contact_coast.values[at[0]])
    d = ds.isel(angle=slice(0, 2))
    moved = d.position_coast.values[1] - d.position_coast.values[0]
    np.testing.assert_allclose(moved, -mesh.base_pitch / 40.0, rtol=1e-9)


def test_coast_crack_is_felt_by_the_cracked_tooth_only(mesh: GearMesh) -> None:
    crack = RootCrack(depth=2e-3, gear="pinion", tooth=2)
    ds = potential_energy_stiffness(mesh, bore_radius=BORES, angles=24, cycles=Z1, faults=crack)
    healthy = potential_energy_stiffness(mesh, bore_radius=BORES, angles=24, cycles=Z1)
    hit = (ds.in_contact_coast & (ds.tooth_pinion_coast == 2)).any("pair_coast").values
    k, k0 = ds.mesh_stiffness_coast.values, healthy.mesh_stiffness_coast.values
    assert hit.any()
    assert np.all(k[hit] < k0[hit])
    np.testing.assert_array_equal(k[~hit], k0[~hit])
