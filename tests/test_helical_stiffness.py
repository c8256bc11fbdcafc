"""Helical pairs by thin slices and lead crowning (geardyn.gears.helical, .crowning) against
published geometry, closed forms, the box-filter (sinc) property of the slice sum and
independent load-sharing solves."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from geardyn.errors import ParameterError
from geardyn.gears import (
    BrokenTooth,
    HelicalGear,
    HelicalMesh,
    LeadCrowning,
    RootCrack,
    Spall,
    TipRelief,
    Wear,
    helical_loaded_contact,
    helical_stiffness,
    loaded_contact,
    potential_energy_stiffness,
    prepare_pair,
)
from pair_19_48 import BORES, Z1, Z2, B, M, pair_mesh

DEG = math.pi / 180.0


def helical(beta: object, *, b: float = B, m: float = M, z: tuple[int, int] = (Z1, Z2),
            x: tuple[float, float] = (0.0, 0.0)) -> HelicalMesh:
    """The 19/48 pair's teeth (normal module m) at helix angle ``beta``."""
    return HelicalMesh(HelicalGear(z[0], m, 20 * DEG, beta, b, x[0], name="pinion"),
                       HelicalGear(z[1], m, 20 * DEG, beta, b, x[1], name="wheel"))


# -- geometry -----------------------------------------------------------------------------------

def test_khk_profile_shifted_helical_pair_in_the_normal_system():
    """KHK Gear Technical Reference, "Calculation of profile shifted helical gears in the normal
    system" (z = 12/60, m_n = 3 mm, alpha_n = 20 deg, beta = 30 deg, x_n = 0.09809/0, chosen for
    a = 125 mm): alpha_t = 22.79588 deg, inv(alpha_wt) = 0.023405, alpha_wt = 23.1126 deg,
    a = 125.000 mm, d = 41.569 mm, d_b = 38.322 mm, d_w = 41.667 mm (pinion). The 12-tooth
    pinion would be undercut as a spur gear (x >= 0.2984) but not as this helical one."""
    mesh = helical(30 * DEG, m=3e-3, z=(12, 60), x=(0.09809, 0.0), b=0.03)
    p, t = mesh.pinion, mesh.transverse
    assert math.degrees(p.transverse_pressure_angle) == pytest.approx(22.79588, abs=5e-6)
    alpha_wt = t.operating_pressure_angle
    assert math.tan(alpha_wt) - alpha_wt == pytest.approx(0.023405, abs=5e-7)
    assert math.degrees(alpha_wt) == pytest.approx(23.1126, abs=5e-5)
    assert mesh.centre_distance * 1e3 == pytest.approx(125.000, abs=5e-4)
    assert 2e3 * t.pinion.reference_radius == pytest.approx(41.569, abs=5e-4)
    assert 2e3 * t.pinion.base_radius == pytest.approx(38.322, abs=5e-4)
    assert 2e3 * t.operating_pitch_radii[0] == pytest.approx(41.667, abs=5e-4)
    assert p.min_profile_shift < 0.09809 < 1.0 - 12 * math.sin(20 * DEG) ** 2 / 2


@pytest.mark.parametrize("beta, x", [(0.0, (0.0, 0.0)), (12 * DEG, (0.2, -0.1)),
                                     (25 * DEG, (0.4, 0.1)), (45 * DEG, (0.0, 0.3))])
def test_contact_ratios_against_iso_21771_written_out(beta, x):
    """eps_alpha, eps_beta, eps_gamma and the base helix angle by the ISO 21771 formulas in
    normal data, written out here (tip diameters d + 2 m_n (1 + x_n), no tip shortening)."""
    mn, an, b, z = 2.5e-3, 20 * DEG, 0.04, (23, 61)
    mesh = helical(beta, m=mn, z=z, x=x, b=b)
    at = math.atan(math.tan(an) / math.cos(beta))
    inv_wt = math.tan(at) - at + 2 * math.tan(an) * (x[0] + x[1]) / (z[0] + z[1])
    awt = brentq(lambda a: math.tan(a) - a - inv_wt, 1e-3, 1.2, xtol=1e-15)
    d = [mn * zi / math.cos(beta) for zi in z]
    db = [di * math.cos(at) for di in d]
    a = (db[0] + db[1]) / (2 * math.cos(awt))
    da = [di + 2 * mn * (1 + xi) for di, xi in zip(d, x, strict=True)]
    g_alpha = 0.5 * (math.sqrt(da[0] ** 2 - db[0] ** 2) + math.sqrt(da[1] ** 2 - db[1] ** 2)) \
        - a * math.sin(awt)
    eps_a = g_alpha / (math.pi * mn / math.cos(beta) * math.cos(at))
    eps_b = b * math.sin(beta) / (math.pi * mn)
    assert mesh.centre_distance == pytest.approx(a, rel=1e-12)
    assert mesh.transverse_contact_ratio == pytest.approx(eps_a, rel=1e-11)
    assert mesh.overlap_ratio == pytest.approx(eps_b, rel=1e-14, abs=1e-300)
    assert mesh.total_contact_ratio == pytest.approx(eps_a + eps_b, rel=1e-11)
    sin_bb = math.sin(beta) * math.cos(an)  # ISO 21771: sin(beta_b) = sin(beta) cos(alpha_n)
    assert math.sin(mesh.base_helix_angle) == pytest.approx(sin_bb, rel=1e-13, abs=1e-300)


def test_geometry_errors_name_the_field():
    with pytest.raises(ParameterError, match="pinion.helix_angle"):
        helical("50 deg")
    with pytest.raises(ParameterError, match="wheel.helix_angle"):
        HelicalMesh(HelicalGear(19, M, "20 deg", "15 deg", B, name="pinion"),
                    HelicalGear(48, M, "20 deg", "16 deg", B, name="wheel"))
    with pytest.raises(ParameterError, match="pinion.profile_shift"):  # x_min = -0.0397
        helical(30 * DEG, m=3e-3, z=(12, 60), x=(-0.05, 0.0))
    helical(30 * DEG, m=3e-3, z=(12, 60), x=(-0.03, 0.0))
    with pytest.raises(ParameterError, match="slices"):
        helical_stiffness(helical("10 deg"), bore_radius=BORES, slices=0)
    with pytest.raises(ParameterError, match="faults"):
        helical_stiffness(helical("10 deg"), bore_radius=BORES,
                          faults=Spall("1 mm", "4 mm", "0.1 mm"))
    with pytest.raises(ParameterError, match="wear.profile"):
        helical_stiffness(helical("10 deg"), bore_radius=BORES,
                          faults=Wear("10 um", profile="archard"))
    with pytest.raises(ParameterError, match="crowning.amount"):
        LeadCrowning("-1 um")


def test_unit_strings_equal_si():
    mesh = HelicalMesh(HelicalGear(19, "3.2 mm", "20 deg", "15 deg", "16 mm", name="pinion"),
                       HelicalGear(48, "3.2 mm", "20 deg", "15 deg", "16 mm", name="wheel"))
    assert mesh.helix_angle == pytest.approx(15 * DEG, rel=1e-15)
    assert (mesh.face_width, mesh.pinion.module) == (B, M)


# -- the slices ---------------------------------------------------------------------------------

def test_zero_helix_angle_is_the_spur_pair():
    """beta = 0: one slice gives the spur Dataset's variables bitwise; 20 slices to 1e-15
    (the same terms at width b/20, summed)."""
    spur = potential_energy_stiffness(pair_mesh(), bore_radius=BORES, angles=90,
                                      faults=RootCrack("1 mm", tooth=0), cycles=2)
    one = helical_stiffness(helical(0.0), bore_radius=BORES, angles=90, slices=1,
                            faults=RootCrack("1 mm", tooth=0), cycles=2)
    for name in ("mesh_stiffness", "mesh_stiffness_coast", "pair_stiffness", "in_contact",
                 "tooth_pinion", "tooth_wheel", "position", "pair_stiffness_coast",
                 "pairs_in_contact", "pairs_in_contact_coast"):
        np.testing.assert_array_equal(one[name].values, spur[name].values, err_msg=name)
    np.testing.assert_array_equal(one.k_bending_pinion.values[..., 0],
                                  spur.k_bending_pinion.values)
    many = helical_stiffness(helical(0.0), bore_radius=BORES, angles=90, slices=20,
                             faults=RootCrack("1 mm", tooth=0), cycles=2)
    for name in ("mesh_stiffness", "mesh_stiffness_coast"):
        np.testing.assert_allclose(many[name].values, spur[name].values, rtol=1e-15, atol=0)


def _fourier(values: np.ndarray, harmonics: int) -> np.ndarray:
    return np.fft.rfft(values)[: harmonics + 1] / values.size


def test_slice_sum_is_the_box_filter_of_the_spur_stiffness():
    """The slice-summed stiffness is the spur stiffness k(c) averaged over a box eps_beta mesh
    cycles wide, so its Fourier coefficients are k_n sinc(pi n eps_beta). With eps_beta = 3/4
    and 256 angles a cycle every slice's shift is a whole number of grid steps, so the
    discrete spectra compare without aliasing: exactly (to rounding) the S-point midpoint rule
    of the box, k_n sin(pi n eps) / (S sin(pi n eps / S)), and its difference from the sinc
    falls as 1/S^2 (harmonics n <= 4; higher ones need S >> n eps)."""
    mn, beta, angles = M, 15 * DEG, 256
    b = 0.75 * math.pi * mn / math.sin(beta)  # eps_beta = 3/4
    mesh = helical(beta, b=b)
    eps = b * math.sin(beta) / (math.pi * mn)
    spur = potential_energy_stiffness(mesh.transverse, bore_radius=BORES, angles=angles)
    k_n = _fourier(spur.mesh_stiffness.values, 24)
    n = np.arange(k_n.size)
    expected = k_n * np.sinc(n * eps)  # numpy's sinc(x) = sin(pi x) / (pi x)
    errors = []
    for slices in (4, 8, 16, 32):
        ds = helical_stiffness(mesh, bore_radius=BORES, angles=angles, slices=slices)
        h_n = _fourier(ds.mesh_stiffness.values, 24)
        midpoint = np.ones(n.size)
        midpoint[1:] = np.sin(np.pi * n[1:] * eps) / (slices * np.sin(np.pi * n[1:] * eps
                                                                      / slices))
        assert np.max(np.abs(h_n - k_n * midpoint)) < 1e-13 * abs(k_n[0])
        errors.append(np.max(np.abs(h_n - expected)[:5]) / abs(k_n[0]))
    assert all(e2 < e1 / 3.5 for e1, e2 in zip(errors, errors[1:], strict=False)), errors
    assert errors[-1] < 1e-4, errors
    # the harmonics the box removes (n eps_beta whole: n = 4, 8, ...) are gone
    assert np.all(np.abs(h_n[[4, 8, 12]]) < 1e-13 * abs(k_n[0]))


def test_whole_overlap_ratio_gives_a_constant_stiffness():
    """eps_beta = 1: the box spans one mesh cycle, the stiffness is its mean; the ripple left by
    S slices falls as 1/S and the mean is the spur one."""
    mn, beta = M, 20 * DEG
    b = math.pi * mn / math.sin(beta)  # eps_beta = 1
    mesh = helical(beta, b=b)
    spur = potential_energy_stiffness(mesh.transverse, bore_radius=BORES, angles=240)
    mean = float(spur.mesh_stiffness.mean())
    ripple = []
    for slices in (5, 10, 20, 40):
        k = helical_stiffness(mesh, bore_radius=BORES, angles=240, slices=slices)\
            .mesh_stiffness.values
        assert k.mean() == pytest.approx(mean, rel=1e-12)
        ripple.append((k.max() - k.min()) / mean)
    assert all(r2 < 0.6 * r1 for r1, r2 in zip(ripple, ripple[1:], strict=False)), ripple
    spur_ripple = float(spur.mesh_stiffness.max() - spur.mesh_stiffness.min()) / mean
    assert ripple[-1] < spur_ripple / 20.0


def test_contact_counts_follow_the_contact_ratios():
    """The mean face fraction in contact is eps_alpha; the mean number of pairs touching
    anywhere is eps_alpha + eps_beta (1 - 1/S) (the outer slice centres lie b/2S inside)."""
    mesh = helical(25 * DEG, b=0.03)
    slices, angles = 10, 720
    ds = helical_stiffness(mesh, bore_radius=BORES, angles=angles, slices=slices)
    eps_a, eps_b = mesh.transverse_contact_ratio, mesh.overlap_ratio
    assert float(ds.pairs_in_contact.mean()) == pytest.approx(eps_a, abs=2.0 / angles)
    assert float(ds.teeth_in_contact.mean()) == pytest.approx(eps_a + eps_b * (1 - 1 / slices),
                                                              abs=2.0 / angles)
    np.testing.assert_allclose(ds.pairs_in_contact.values,
                               ds.contact_fraction.sum("pair").values, rtol=1e-15)
    # each slice: the transverse spur pair's stiffness at the slice's position, over S (every
    # term is proportional to the face width), its position the centre's + y tan(beta_b)
    pair = prepare_pair(mesh.transverse, bore_radius=BORES)
    inside = ds.slice_in_contact.values
    s = ds.slice_position.values
    np.testing.assert_allclose(ds.slice_stiffness.values[inside],
                               pair.terms(s[inside])["pair"] / slices, rtol=1e-13)
    y = ds.axial_position.values
    np.testing.assert_allclose(s, ds.position.values[..., None]
                               + y * math.tan(mesh.base_helix_angle), rtol=0, atol=1e-15)


def test_root_crack_acts_on_the_whole_face_of_its_tooth():
    """A cracked pinion tooth lowers the stiffness while any slice of it is in contact and
    nowhere else; a zero crack is the healthy result bitwise; a missing tooth removes all its
    slices."""
    mesh = helical(15 * DEG)
    kw = dict(bore_radius=BORES, angles=60, slices=8, cycles=Z1)
    healthy = helical_stiffness(mesh, **kw)
    zero = helical_stiffness(mesh, faults=RootCrack(0.0, tooth=2), **kw)
    np.testing.assert_array_equal(zero.mesh_stiffness.values, healthy.mesh_stiffness.values)
    cracked = helical_stiffness(mesh, faults=RootCrack("2 mm", tooth=2), **kw)
    touching = ((healthy.tooth_pinion == 2) & healthy.in_contact).any("pair").values
    drop = healthy.mesh_stiffness.values - cracked.mesh_stiffness.values
    assert np.all(drop[touching] > 0.0) and np.all(drop[~touching] == 0.0)
    broken = helical_stiffness(mesh, faults=BrokenTooth(tooth=2), **kw)
    gone = ((healthy.tooth_pinion == 2) * healthy.pair_stiffness).sum("pair").values
    np.testing.assert_allclose(broken.mesh_stiffness.values,
                               healthy.mesh_stiffness.values - gone, rtol=1e-13)
    worn = helical_stiffness(mesh, faults=Wear("5 um", tooth=2), **kw)
    on_tooth = (worn.tooth_pinion == 2).values[..., None] & worn.slice_in_contact.values
    assert np.all(worn.fault_gap.values[on_tooth] == 5e-6)
    assert np.all(worn.fault_gap.values[~on_tooth] == 0.0) and on_tooth.any()


# -- lead crowning and the loaded contact -------------------------------------------------------

@pytest.fixture(scope="module")
def crowned_case():
    mesh = helical(15 * DEG, b=0.024)
    return mesh, helical_stiffness(mesh, bore_radius=BORES, angles=45, slices=12)


def test_zero_crowning_is_the_uncrowned_contact_bitwise(crowned_case):
    mesh, ds = crowned_case
    relief = (TipRelief("15 um", "2 mm", "parabolic"),)
    plain = helical_loaded_contact(mesh, ds, 1500.0, relief)
    zero = helical_loaded_contact(mesh, ds, 1500.0, relief, (LeadCrowning(0.0),))
    for name in plain.data_vars:
        np.testing.assert_array_equal(zero[name].values, plain[name].values, err_msg=name)


def test_one_slice_at_zero_helix_is_the_spur_loaded_contact():
    """beta = 0, one slice: the spur pair's loaded contact with its tip relief bitwise (the same
    solver on the same numbers)."""
    relief = (TipRelief("20 um", "3 mm", "parabolic"), TipRelief("10 um", "4 mm", "linear",
                                                                  "wheel"))
    spur = loaded_contact(pair_mesh(), potential_energy_stiffness(
        pair_mesh(), bore_radius=BORES, angles=90), 2000.0, relief)
    mesh = helical(0.0)
    one = helical_loaded_contact(mesh, helical_stiffness(mesh, bore_radius=BORES, angles=90,
                                                         slices=1), 2000.0, relief)
    for name in ("transmission_error", "unloaded_transmission_error", "tangent_stiffness",
                 "secant_stiffness", "pair_force"):
        np.testing.assert_array_equal(one[name].values, spur[name].values, err_msg=name)


@pytest.mark.parametrize("force", [30.0, 800.0, 2.5e4])
def test_force_balance_and_brentq(crowned_case, force):
    """delta against brentq on sum k max(0, delta - e) = F with the crowning gap of each slice
    written out from its index, plus a wheel tip relief; the slice forces sum to F."""
    mesh, ds = crowned_case
    b, slices = mesh.face_width, ds.sizes["slice"]
    crowning = (LeadCrowning("12 um"), LeadCrowning("4 um", gear="wheel"))
    relief = (TipRelief("10 um", "2.5 mm", "linear", "wheel"),)
    out = helical_loaded_contact(mesh, ds, force, relief, crowning)
    y = -0.5 * b + (np.arange(slices) + 0.5) * b / slices
    e = 16e-6 * (2 * y / b) ** 2 + np.zeros(ds.slice_position.shape)
    s = ds.slice_position.values
    g_f = mesh.transverse.approach_length
    e += 10e-6 * np.clip((2.5e-3 - g_f - s) / 2.5e-3, 0.0, None)
    k = ds.slice_stiffness.values
    for i in range(k.shape[0]):
        def balance(d: float, i: int = i) -> float:
            return float(np.sum(k[i] * np.clip(d - e[i], 0.0, None))) - force
        ref = brentq(balance, 0.0, 1e-2, xtol=1e-18, rtol=1e-15)
        assert out.transmission_error.values[i] == pytest.approx(ref, rel=1e-12, abs=1e-18)
        assert abs(out.slice_force.values[i].sum() - force) <= 1e-10 * force
    inside = ds.slice_in_contact.values
    np.testing.assert_allclose(out.gap.values[inside], e[inside], rtol=1e-13, atol=1e-18)
    e_min = np.min(np.where(inside, e, np.inf), axis=(1, 2))
    np.testing.assert_allclose(out.unloaded_transmission_error.values, e_min, rtol=1e-13)


def test_crowned_stiffness_approaches_the_uncrowned_one_as_the_load_grows(crowned_case):
    """Once every slice in contact carries load the secant stiffness is
    1 / (1/K + (sum k_i e_i / K - min e_i) / F): its deficit falls as 1/F; at a light load the
    crowned face ends carry nothing."""
    mesh, ds = crowned_case
    k_mesh = ds.mesh_stiffness.values
    crowning = (LeadCrowning("15 um"),)
    deficits = []
    for force in (1e3, 1e4, 1e5, 1e6):
        out = helical_loaded_contact(mesh, ds, force, (), crowning)
        deficits.append(float(np.max(1.0 - out.secant_stiffness.values / k_mesh)))
        assert np.all(out.tangent_stiffness.values <= k_mesh * (1 + 1e-14))
    assert all(d2 < d1 for d1, d2 in zip(deficits, deficits[1:], strict=False)), deficits
    force = 1e6
    out = helical_loaded_contact(mesh, ds, force, (), crowning)
    k = ds.slice_stiffness.values
    e = out.gap.fillna(0.0).values
    full = (np.sum(k * e, axis=(1, 2)) / k_mesh - out.unloaded_transmission_error.values)
    np.testing.assert_allclose(out.secant_stiffness.values, 1.0 / (1.0 / k_mesh + full / force),
                               rtol=1e-11)
    np.testing.assert_allclose(out.tangent_stiffness.values, k_mesh, rtol=1e-14)
    assert deficits[-1] < 1e-2 and deficits[-1] * 1e6 == pytest.approx(deficits[-2] * 1e5,
                                                                        rel=0.05)
    light = helical_loaded_contact(mesh, ds, 50.0, (), crowning)
    ends = light.slice_force.isel(slice=[0, -1]).values
    assert np.all(ends == 0.0) and np.all(light.tangent_stiffness.values < 0.8 * k_mesh)


# -- docs/gears.md's numbers --------------------------------------------------------------------

DOCS = Path(__file__).resolve().parent.parent / "docs" / "gears.md"


def _table_rows(text: str, header: str) -> list[list[str]]:
    """The body rows of the markdown table whose header line starts with ``header``."""
    lines = text[text.index(header):].splitlines()[2:]
    rows = []
    for line in lines:
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows


def test_docs_helical_and_crowning_tables():
    """Every number of docs/gears.md's helical-stiffness and lead-crowning tables, recomputed
    (19/48 teeth, m_n 3.2 mm, b 16 mm, 20 slices, 360 angles)."""
    text = DOCS.read_text(encoding="utf-8")
    stiffness = {}
    for beta, eps_a, eps_b, mean, pp, ratio in _table_rows(text, "| β | ε_α | ε_β | mean"):
        deg = float(beta.rstrip("°"))
        mesh = helical(deg * DEG)
        ds = helical_stiffness(mesh, bore_radius=BORES, angles=360, slices=20)
        stiffness[deg] = (mesh, ds)
        k = ds.mesh_stiffness.values
        assert f"{mesh.transverse_contact_ratio:.4f}" == eps_a
        assert f"{mesh.overlap_ratio:.4f}" == eps_b
        assert f"{k.mean():.4e}".replace("e+0", "e") == mean
        assert f"{k.max() - k.min():.4e}".replace("e+0", "e") == pp
        assert f"{(k.max() - k.min()) / k.mean():.3f}" == ratio
    mesh, ds = stiffness[20.0]
    for amount, force, mean, pp, tangent, secant, loaded in _table_rows(text, "| C_c | F |"):
        c = 0.0 if amount == "0" else float(amount.split()[0]) * 1e-6
        f = float(force.split()[0]) * (1e3 if "kN" in force else 1.0)
        out = helical_loaded_contact(mesh, ds, f, (), (LeadCrowning(c),))
        te = out.transmission_error.values * 1e6
        k = ds.mesh_stiffness.values
        got = (f"{te.mean():.2f} µm", f"{te.max() - te.min():.2f} µm",
               f"{np.mean(out.tangent_stiffness.values / k):.3f}",
               f"{np.mean(out.secant_stiffness.values / k):.3f}",
               f"{float(out.pairs_loaded.mean()):.2f}")
        assert got == (mean, pp, tangent, secant, loaded), (amount, force)


def test_coast_flank_mirrors_the_drive_flank():
    """Symmetric slices: K_coast(c) = K_drive(phi - c), as for the spur pair (c in mesh cycles,
    phi the coast phase), at angles off the grid."""
    mesh = helical(18 * DEG, b=0.03)
    rng = np.random.default_rng(3)
    cycles = rng.uniform(0.0, 3.0, 40)
    per_cycle = 360.0 / Z1
    kw = dict(bore_radius=BORES, slices=12)
    ds = helical_stiffness(mesh, angles=cycles * per_cycle, **kw)
    phi = ds.attrs["coast_phase_cycles"]
    mirrored = helical_stiffness(mesh, angles=(phi - cycles) * per_cycle, **kw)
    np.testing.assert_allclose(ds.mesh_stiffness_coast.values, mirrored.mesh_stiffness.values,
                               rtol=1e-12)
