"""Spalls and wear on the coast (back) flank, ``flank="coast"``, in the potential-energy
stiffness, the helical slices and the study files.

The references: the mirror symmetry of the symmetric tooth (a coast contact at position s on
the coast line of action loads the teeth at the load angles of the drive contact at s, and a
pinion tooth's coast flank passes the pitch point phi mesh cycles after its drive flank, so
K_coast(c) = K_drive(phi - c) with pinion tooth j's coast fault on the drive flank of pinion
tooth -j, wheel tooth i's on wheel tooth 1 - i: the pair labels of the module docstring); the
tooth integrals by SciPy's quad over sections built here from rectangles (the spall at the
other flank); the Hertz line contact pi E b / (4 (1 - nu^2)) written out.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, RootCrack, Spall, SpurGear, Wear, potential_energy_stiffness
from geardyn.gears.helical import HelicalGear, HelicalMesh, helical_stiffness
from geardyn.gears.potential_energy import coast_phase, prepare_pair, tooth_compliances
from pair_19_48 import ALPHA, BORES, NU, Z1, Z2, B, E, M, pair_mesh
from test_tooth_faults import _pinion, _reference, _roll_at

SPALL = dict(length=1.2e-3, width=4e-3, depth=0.3e-3, position=0.4e-3)
K_H = math.pi * E / (4.0 * (1.0 - NU ** 2))  # Hertz stiffness per unit face width [N/m^2]


@pytest.fixture(scope="module")
def mesh() -> GearMesh:
    return pair_mesh()


def _run(mesh: GearMesh, faults, angles: object = 40, cycles: int = Z1):
    return potential_energy_stiffness(mesh, bore_radius=BORES, angles=angles, cycles=cycles,
                                      faults=faults)


def _shifted() -> GearMesh:
    """Shifted teeth (x 0.2, 0.1) with backlash (centre distance 0.2 mm long): phi != 1/2."""
    p = SpurGear(Z1, M, ALPHA, B, profile_shift=0.2, name="pinion")
    w = SpurGear(Z2, M, ALPHA, B, profile_shift=0.1, name="wheel")
    return GearMesh(p, w, centre_distance=GearMesh(p, w).centre_distance + 2e-4)


def _mirrored(fault, flank: str):
    """``fault`` on ``flank`` of the tooth the mirror maps it to (pinion j -> -j, wheel
    i -> 1 - i) when ``flank`` is "drive", else on its own tooth."""
    if flank == "coast":
        return type(fault)(**{**fault.__dict__, "flank": "coast"})
    z = Z1 if fault.gear == "pinion" else Z2
    tooth = (-fault.tooth if fault.gear == "pinion" else 1 - fault.tooth) % z
    return type(fault)(**{**fault.__dict__, "tooth": tooth, "flank": "drive"})


# -- the mirror identity ------------------------------------------------------------------------


MIRROR_FAULTS = [Spall(**SPALL, tooth=5), Spall(**SPALL, gear="wheel", tooth=7),
                 Wear(30e-6, tooth=3), Wear(30e-6, tooth=5, profile="archard"),
                 Wear(20e-6, gear="wheel", tooth=9, profile="archard")]


@pytest.mark.parametrize("shifted", [False, True], ids=["19/48", "shifted+backlash"])
@pytest.mark.parametrize("fault", MIRROR_FAULTS,
                         ids=lambda f: f"{f.kind}-{getattr(f, 'profile', '')}-{f.gear}")
def test_coast_fault_is_the_drive_fault_mirrored(mesh: GearMesh, fault, shifted: bool) -> None:
    """K_coast(c) with the fault on a tooth's coast flank = K_drive(phi - c) with it on the
    mirrored tooth's drive flank, to 1e-12, over one pinion revolution; the coast gap likewise
    (Archard's coast profile is the drive one's mirror: the same slip and load share)."""
    m = _shifted() if shifted else mesh
    phi = coast_phase(m)
    c = (np.arange(Z1 * 16) + 0.3183) / 16.0  # off the contact boundaries
    deg = 360.0 / Z1
    coast = _run(m, _mirrored(fault, "coast"), angles=c * deg)
    drive = _run(m, _mirrored(fault, "drive"), angles=(phi - c) * deg)
    np.testing.assert_allclose(coast.mesh_stiffness_coast.values, drive.mesh_stiffness.values,
                               rtol=1e-12, atol=0.0)
    np.testing.assert_array_equal(coast.pairs_in_contact_coast.values,
                                  drive.pairs_in_contact.values)
    depth = fault.depth if isinstance(fault, Wear) else 0.0
    np.testing.assert_allclose(coast.fault_gap_coast.values.sum(axis=1),
                               drive.fault_gap.values.sum(axis=1), rtol=1e-9,
                               atol=1e-10 * depth)
    np.testing.assert_array_equal(coast.fault_gap.values, 0.0)  # no gap on the drive flank
    # felt: the coast stiffness is not the healthy one, nor the drive-flank fault's (a spall
    # narrows the coast contact only when it lies on the coast flank)
    healthy = _run(m, (), angles=c * deg).mesh_stiffness_coast.values
    k = coast.mesh_stiffness_coast.values
    assert np.count_nonzero(k < healthy) >= 8 and np.all(k <= healthy)
    if isinstance(fault, Spall):
        on_drive = _run(m, type(fault)(**{**fault.__dict__, "flank": "drive"}),
                        angles=c * deg).mesh_stiffness_coast.values
        assert np.count_nonzero(k < on_drive) >= 2 and np.all(k <= on_drive)


# -- what the other flank sees -------------------------------------------------------------------


def test_coast_spall_thins_the_drive_sections_only(mesh: GearMesh) -> None:
    """The drive contacts of a coast-spalled pinion tooth: the full-width Hertz contact, every
    tooth term the drive-spalled run's (the sections are the same, mirrored), so the pair is
    the series sum of those terms with the full Hertz stiffness; the other pairs bitwise
    healthy. The coast contacts narrow to b - w on the spall."""
    tooth = 4
    ds0 = _run(mesh, ())
    ds = _run(mesh, Spall(**SPALL, tooth=tooth, flank="coast"))
    dsd = _run(mesh, Spall(**SPALL, tooth=tooth))
    on = ds0.in_contact.values & (ds0.tooth_pinion.values == tooth)
    assert on.any()
    np.testing.assert_array_equal(ds.pair_stiffness.values[~on], ds0.pair_stiffness.values[~on])
    np.testing.assert_array_equal(ds.k_hertz.values[on], B * K_H)
    terms = [n for n in ds.data_vars if n.startswith("k_") and n != "k_hertz"]
    for name in terms:
        np.testing.assert_array_equal(ds[name].values[on], dsd[name].values[on], err_msg=name)
    comp = 1.0 / (B * K_H) + sum(1.0 / dsd[n].values[on] for n in terms)
    np.testing.assert_allclose(ds.pair_stiffness.values[on], 1.0 / comp, rtol=1e-13)
    narrowed = dsd.k_hertz.values[on] < B * K_H  # the drive spall's contacts on the spall
    assert narrowed.any() and not narrowed.all()
    k, kd, k0 = (x.pair_stiffness.values[on] for x in (ds, dsd, ds0))
    assert np.all(k[narrowed] > kd[narrowed])
    np.testing.assert_array_equal(k[~narrowed], kd[~narrowed])
    assert np.all(k <= k0) and np.count_nonzero(k < k0) >= on.sum() // 2
    # the coast Hertz contact on the spall, at the load angles of the drive contact there
    g_ = _pinion()
    t_mid = _roll_at(SPALL["position"])
    pos = np.array([(t_mid - math.tan(ALPHA)) * g_["rb"], (g_["t_tip"] - math.tan(ALPHA))
                    * g_["rb"] * 0.999])
    pair = prepare_pair(mesh, bore_radius=BORES, faults=Spall(**SPALL, flank="coast"))
    spall = pair.faults[0]
    np.testing.assert_allclose(pair.terms(pos, spall, coast=True)["hertz"],
                               [K_H * (B - SPALL["width"]), K_H * B], rtol=1e-15)
    np.testing.assert_allclose(pair.terms(pos, spall)["hertz"], K_H * B, rtol=1e-15)


def test_coast_spalled_tooth_matches_quad(mesh: GearMesh) -> None:
    """The coast-spalled section built here with the rectangle cut at the other flank (y from
    -h to -h + d), I about its own centroid: quad of the tooth integrals to 1e-10."""
    spall = Spall(**SPALL, flank="coast")
    pair = prepare_pair(mesh, bore_radius=BORES, faults=spall)
    g_ = _pinion()
    t_lo = _roll_at(SPALL["position"] - SPALL["length"] / 2.0)
    t_hi = _roll_at(SPALL["position"] + SPALL["length"] / 2.0)
    w, d = SPALL["width"], SPALL["depth"]

    def section(a: float, h: float) -> tuple[float, float]:
        if not g_["a2"] - t_hi <= a <= g_["a2"] - t_lo:
            return 2.0 * h ** 3 * B / 3.0, 2.0 * h * B
        parts = [(B - w, -h, h), (w, -h + d, h)]
        area = sum(b * (top - bot) for b, bot, top in parts)
        y_c = sum(b * (top - bot) * 0.5 * (top + bot) for b, bot, top in parts) / area
        return sum(b * ((top - y_c) ** 3 - (bot - y_c) ** 3) / 3.0 for b, bot, top in parts), area

    a1 = np.array([0.5 * (t_lo + t_hi), t_hi + 0.05, g_["t_tip"]]) - g_["a2"]
    got = tooth_compliances(pair.pinion, a1, young=E, poisson=NU, face_width=B, fault=spall)
    for i, alpha1 in enumerate(a1):
        ref = _reference(float(alpha1), section, (g_["a2"] - t_hi, g_["a2"] - t_lo))
        for name, value in ref.items():
            assert got[name][i] == pytest.approx(value, rel=1e-10, abs=0.0), (name, i)


@pytest.mark.parametrize("gear", ["pinion", "wheel"])
def test_coast_wear_gap_on_the_coast_contacts_only(mesh: GearMesh, gear: str) -> None:
    """Uniform coast wear: fault_gap_coast is its depth at the worn tooth's coast contacts, 0
    elsewhere, and fault_gap is 0; drive wear opens no coast gap. The drive stiffness is the
    drive-worn run's (the same thinner sections)."""
    depth, tooth = 25e-6, 6
    cycles = Z1 if gear == "pinion" else Z2
    coast = _run(mesh, Wear(depth, gear=gear, tooth=tooth, flank="coast"), angles=12,
                 cycles=cycles)
    drive = _run(mesh, Wear(depth, gear=gear, tooth=tooth), angles=12, cycles=cycles)
    idx = (coast.tooth_pinion_coast if gear == "pinion" else coast.tooth_wheel_coast).values
    worn = coast.in_contact_coast.values & (idx == tooth)
    assert worn.any()
    np.testing.assert_array_equal(coast.fault_gap_coast.values[worn], depth)
    np.testing.assert_array_equal(coast.fault_gap_coast.values[~worn], 0.0)
    np.testing.assert_array_equal(coast.fault_gap.values, 0.0)
    np.testing.assert_array_equal(drive.fault_gap_coast.values, 0.0)
    assert drive.fault_gap.values.max() == depth
    np.testing.assert_array_equal(coast.mesh_stiffness.values, drive.mesh_stiffness.values)
    np.testing.assert_array_equal(coast.mesh_stiffness_coast.values,
                                  drive.mesh_stiffness_coast.values)
    assert coast.fault_gap_coast.attrs["units"] == "m"


# -- zero size, the default flank ---------------------------------------------------------------


@pytest.mark.parametrize("faults", [
    Spall(0.0, 4e-3, 3e-4, tooth=3, flank="coast"),
    Spall(1e-3, 4e-3, 0.0, gear="wheel", tooth=2, flank="coast"),
    [Wear(0.0, tooth=5, flank="coast"), Wear(0.0, gear="wheel", tooth=1, flank="coast",
                                              profile="archard")],
])
def test_zero_coast_faults_are_healthy_bitwise(mesh: GearMesh, faults) -> None:
    healthy = _run(mesh, (), angles=24)
    ds = _run(mesh, faults, angles=24)
    for name in healthy.variables:
        np.testing.assert_array_equal(ds[name].values, healthy[name].values, err_msg=name)


def test_default_flank_is_the_drive_flank(mesh: GearMesh) -> None:
    """flank defaults to "drive": the same fault, the same Dataset bitwise, the same attrs
    text; a coast fault says so in the attrs."""
    faults = [Spall(**SPALL, tooth=2), Wear(20e-6, gear="wheel", tooth=3, profile="archard")]
    explicit = [type(f)(**{**f.__dict__, "flank": "drive"}) for f in faults]
    assert faults == explicit and all(f.flank == "drive" for f in faults)
    a, b = _run(mesh, faults, angles=12), _run(mesh, explicit, angles=12)
    for name in a.variables:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    assert a.attrs["faults"].startswith("spall on pinion tooth 2: 0.0012 m along the profile")
    coast = _run(mesh, [Spall(**SPALL, tooth=2, flank="coast")], angles=12)
    assert coast.attrs["faults"].startswith("spall on the coast flank of pinion tooth 2:")


# -- errors ---------------------------------------------------------------------------------


@pytest.mark.parametrize("make, field", [
    (lambda: Spall(**SPALL, flank="back"), "spall.flank"),
    (lambda: Spall(**SPALL, flank=None), "spall.flank"),
    (lambda: Wear(1e-5, flank="Coast"), "wear.flank"),
    (lambda: Spall(1e-3, 4e-3, 1e-4, position=5e-3, flank="coast"), "spall.position"),
    (lambda: Spall(1e-3, 16e-3, 1e-4, flank="coast"), "spall.width"),
    (lambda: Wear(1.2e-3, flank="coast"), "wear.depth"),
    (lambda: [Spall(**SPALL, tooth=3), Wear(1e-5, tooth=3)], "faults"),  # the same flank
    (lambda: [Spall(**SPALL, tooth=3), Wear(1e-5, tooth=3, flank="coast"),
              Wear(1e-5, tooth=3)], "faults"),
    (lambda: [RootCrack(1e-3, tooth=3), Spall(**SPALL, tooth=3, flank="coast")], "faults"),
    (lambda: [Wear(1e-5, tooth=3, flank="coast"), g.BrokenTooth(tooth=3)], "faults"),
])
def test_bad_coast_faults_name_the_field(mesh: GearMesh, make, field: str) -> None:
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(mesh, bore_radius=BORES, angles=4, faults=make())
    assert info.value.field == field


def test_crack_has_no_flank_and_loads_both_flanks(mesh: GearMesh) -> None:
    """A root crack has no flank field (its faces are taken open under either load): both
    flanks' stiffness falls while the cracked tooth is in their contact."""
    with pytest.raises(TypeError):
        RootCrack(1e-3, flank="coast")  # type: ignore[call-arg]
    ds0, ds = _run(mesh, (), angles=24), _run(mesh, RootCrack(2e-3, tooth=3), angles=24)
    for suffix, pair in (("", "pair"), ("_coast", "pair_coast")):
        hit = (ds0[f"in_contact{suffix}"] & (ds0[f"tooth_pinion{suffix}"] == 3)).any(pair).values
        k, k0 = ds[f"mesh_stiffness{suffix}"].values, ds0[f"mesh_stiffness{suffix}"].values
        assert hit.any() and np.all(k[hit] < k0[hit])
        np.testing.assert_array_equal(k[~hit], k0[~hit])


def test_ring_tooth_refuses_a_coast_spall_off_its_flank() -> None:
    mesh = GearMesh(SpurGear(23, 2e-3, ALPHA, 20e-3, name="pinion"),
                    SpurGear(71, 2e-3, ALPHA, 20e-3, internal=True, name="wheel"), internal=True)
    with pytest.raises(ParameterError) as info:
        potential_energy_stiffness(mesh, bore_radius=(8e-3, 85e-3), angles=4,
                                   faults=Spall(**{**SPALL, "position": 3e-3}, gear="wheel",
                                                flank="coast"))
    assert info.value.field == "spall.position"


# -- helical slices ---------------------------------------------------------------------------


def test_helical_coast_wear_at_zero_helix_angle_is_the_spur_pair(mesh: GearMesh) -> None:
    """beta = 0, one slice: the spur pair's stiffness and coast gap bitwise with uniform coast
    wear; with 5 slices the coast gap is the depth on every slice in coast contact."""
    wear = Wear(15e-6, tooth=2, flank="coast")
    spur = _run(mesh, wear, angles=30, cycles=4)
    both = [wear, Wear(10e-6, tooth=2)]  # each flank of the tooth worn
    hm = HelicalMesh(HelicalGear(Z1, M, ALPHA, 0.0, B, name="pinion"),
                     HelicalGear(Z2, M, ALPHA, 0.0, B, name="wheel"))
    one = helical_stiffness(hm, bore_radius=BORES, angles=30, slices=1, cycles=4, faults=wear)
    for name in ("mesh_stiffness", "mesh_stiffness_coast", "pair_stiffness_coast"):
        np.testing.assert_array_equal(one[name].values, spur[name].values, err_msg=name)
    np.testing.assert_array_equal(one.fault_gap_coast.values[..., 0], spur.fault_gap_coast.values)
    np.testing.assert_array_equal(one.fault_gap.values, 0.0)
    assert spur.fault_gap_coast.values.max() == 15e-6
    spur2 = _run(mesh, both, angles=30, cycles=4)
    one2 = helical_stiffness(hm, bore_radius=BORES, angles=30, slices=1, cycles=4, faults=both)
    for name in ("mesh_stiffness", "mesh_stiffness_coast"):
        np.testing.assert_array_equal(one2[name].values, spur2[name].values, err_msg=name)
    assert not np.array_equal(spur2.mesh_stiffness.values, spur.mesh_stiffness.values)
    many = helical_stiffness(hm, bore_radius=BORES, angles=30, slices=5, cycles=4, faults=wear)
    worn = many.slice_in_contact_coast.values & (
        many.tooth_pinion_coast.values == 2)[:, :, None]
    np.testing.assert_array_equal(many.fault_gap_coast.values[worn], 15e-6)
    np.testing.assert_array_equal(many.fault_gap_coast.values[~worn], 0.0)


# -- study files --------------------------------------------------------------------------------


STUDY = """
[study]
name = "coast"

[gears]
module = "3.2 mm"
pressure_angle = "20 deg"
face_width = "16 mm"
bore_radius = "12 mm"

[gears.pinion]
teeth = 19

[gears.wheel]
teeth = 48
bore_radius = "35 mm"

[[faults]]
kind = "spall"
tooth = 2
length = "1.2 mm"
width = "4 mm"
depth = "0.3 mm"
position = "0.4 mm"
flank = "coast"

[stiffness]
angles = 36
cycles = 19
"""


def test_a_coast_spall_in_a_study_reaches_the_stiffness(tmp_path) -> None:
    """[[faults]] takes flank: the study's stiffness is the API's with the coast spall,
    bitwise, not the drive spall's; the table round-trips."""
    from geardyn.io.toml import load_study, save_study
    from geardyn.study import mesh_stiffness

    study = load_study(STUDY)
    got = mesh_stiffness(study)
    mesh = g.GearMesh(g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                      g.SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    kw = dict(bore_radius=("12 mm", "35 mm"), angles=36, cycles=19)
    spall = dict(length="1.2 mm", width="4 mm", depth="0.3 mm", position="0.4 mm", tooth=2)
    want = g.potential_energy_stiffness(mesh, faults=g.Spall(**spall, flank="coast"), **kw)
    drive = g.potential_energy_stiffness(mesh, faults=g.Spall(**spall), **kw)
    for name in ("mesh_stiffness", "mesh_stiffness_coast", "pair_stiffness_coast"):
        np.testing.assert_array_equal(got[name].values, want[name].values, err_msg=name)
    assert not np.array_equal(got.mesh_stiffness_coast.values, drive.mesh_stiffness_coast.values)
    assert not np.array_equal(got.mesh_stiffness.values, drive.mesh_stiffness.values)
    save_study(study, tmp_path / "again.toml")
    assert load_study(tmp_path / "again.toml") == study


def test_a_study_wears_both_flanks_of_a_tooth() -> None:
    """Two [[faults]] on one tooth, a wear on each flank: the API's stiffness bitwise."""
    from geardyn.io.toml import load_study
    from geardyn.study import mesh_stiffness

    text = STUDY.replace('kind = "spall"', 'kind = "wear"').replace(
        'length = "1.2 mm"\nwidth = "4 mm"\ndepth = "0.3 mm"\nposition = "0.4 mm"\n',
        'depth = "30 um"\n')
    text = text.replace("[stiffness]", '[[faults]]\nkind = "wear"\ntooth = 2\n'
                        'depth = "10 um"\nprofile = "archard"\n\n[stiffness]')
    got = mesh_stiffness(load_study(text))
    mesh = g.GearMesh(g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                      g.SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    want = g.potential_energy_stiffness(
        mesh, bore_radius=("12 mm", "35 mm"), angles=36, cycles=19,
        faults=(g.Wear("30 um", tooth=2, flank="coast"),
                g.Wear("10 um", tooth=2, profile="archard")))
    for name in ("mesh_stiffness", "mesh_stiffness_coast", "fault_gap", "fault_gap_coast"):
        np.testing.assert_array_equal(got[name].values, want[name].values, err_msg=name)
    assert got.fault_gap.values.max() > 0.0 and got.fault_gap_coast.values.max() == 30e-6


def test_cli_names_a_bad_flank(tmp_path, capsys) -> None:
    from geardyn.cli.main import main

    path = tmp_path / "bad.toml"
    path.write_text(STUDY.replace('flank = "coast"', 'flank = "back"'), encoding="utf-8")
    with pytest.raises(SystemExit) as info:
        main(["stiffness", str(path), "-o", str(tmp_path / "k.nc")])
    err = capsys.readouterr().err.strip()
    assert info.value.code == 2
    assert len(err.splitlines()) == 1 and "faults[0].flank" in err and "coast" in err, err


def test_the_documented_figures(mesh: GearMesh) -> None:
    """docs/gears.md, *Where the flanks are concerned*: a 19/48 pinion spall centred on the
    reference circle on the coast flank lowers the coast stiffness by the drive spall's
    figures and the drive stiffness (sections only) by 0.034 and 0.30 % at the worst angle
    (mean relative change 0.0009 and 0.010 %)."""
    healthy = _run(mesh, (), angles=360)
    for size, worst, mean in (((1e-3, 4e-3, 0.2e-3), 0.034, 0.0009),
                              ((2e-3, 8e-3, 0.5e-3), 0.30, 0.010)):
        coast = _run(mesh, Spall(*size, flank="coast"), angles=360)
        drive = _run(mesh, Spall(*size), angles=360)
        r = coast.mesh_stiffness.values / healthy.mesh_stiffness.values - 1.0
        assert float(f"{-100.0 * r.min():.2g}") == worst
        assert float(f"{-100.0 * r.mean():.1g}") == mean
        rc = coast.mesh_stiffness_coast.values / healthy.mesh_stiffness_coast.values - 1.0
        rd = drive.mesh_stiffness.values / healthy.mesh_stiffness.values - 1.0
        assert rc.min() == pytest.approx(rd.min(), rel=1e-9)


# -- a fault on each flank of one tooth -------------------------------------------------------


def _strips(h: float, drive: tuple[float, float], coast: tuple[float, float]
            ) -> tuple[float, float]:
    """(I, A) of the section 2h x B less a w x d cut at each face (drive at y = h, coast at
    y = -h), as three strips of the width left at each height, I about their centroid."""
    (w1, d1), (w2, d2) = drive, coast
    parts = [(B, -h + d2, h - d1), (B - w1, h - d1, h), (B - w2, -h, -h + d2)]
    area = sum(b * (top - bot) for b, bot, top in parts)
    y_c = sum(b * (top - bot) * 0.5 * (top + bot) for b, bot, top in parts) / area
    return sum(b * ((top - y_c) ** 3 - (bot - y_c) ** 3) / 3.0 for b, bot, top in parts), area


@pytest.mark.parametrize("coast", [Wear(30e-6, flank="coast"),
                                   Wear(30e-6, flank="coast", profile="archard"),
                                   Spall(2e-3, 6e-3, 0.2e-3, position=0.0, flank="coast")],
                         ids=["uniform", "archard", "spall"])
def test_two_flank_tooth_matches_quad(mesh: GearMesh, coast) -> None:
    """A drive spall and a coast wear or spall on one pinion tooth: the bending, shear and
    axial compliances against quad with the section built from strips (1e-9)."""
    drive = Spall(**SPALL)
    pair = prepare_pair(mesh, bore_radius=BORES, faults=[coast, drive])
    g_ = _pinion()
    a2 = g_["a2"]

    def spall_range(sp) -> tuple[float, float]:
        return (a2 - _roll_at(sp.position + sp.length / 2.0),
                a2 - _roll_at(sp.position - sp.length / 2.0))

    d_lo, d_hi = spall_range(drive)
    profile = pair.profile_of(coast)
    if isinstance(coast, Spall):
        c_lo, c_hi = spall_range(coast)
        breaks = (d_lo, d_hi, c_lo, c_hi)
    else:
        c_lo, c_hi = -math.inf, a2 - g_["t_low"]
        breaks = (d_lo, d_hi, *(a2 - t for t in profile.rolls))

    def section(a: float, h: float) -> tuple[float, float]:
        cut_d = (drive.width, drive.depth) if d_lo <= a <= d_hi else (0.0, 0.0)
        cut_c = (0.0, 0.0)
        if c_lo <= a <= c_hi:
            cut_c = ((coast.width, coast.depth) if isinstance(coast, Spall) else
                     (B, float(profile.depth_at(np.array([a2 - a]))[0])))
        return _strips(h, cut_d, cut_c)

    a1 = np.array([g_["t_low"] + 0.01, math.tan(ALPHA), _roll_at(SPALL["position"]),
                   g_["t_tip"]]) - a2
    kw = dict(young=E, poisson=NU, face_width=B)
    got = tooth_compliances(pair.pinion, a1, fault=(drive, coast),
                            wear_profile=(None, profile), **kw)
    alone = [tooth_compliances(pair.pinion, a1, fault=f, wear_profile=pair.profile_of(f), **kw)
             for f in (drive, coast)]
    for i, alpha1 in enumerate(a1):
        for name, value in _reference(float(alpha1), section, breaks).items():
            assert got[name][i] == pytest.approx(value, rel=1e-9, abs=0.0), (name, i)
            assert got[name][i] >= max(c[name][i] for c in alone)


def _swapped(faults):
    """The faults on the other flank of the mirrored tooth (pinion j -> -j, wheel i -> 1 - i)."""
    out = []
    for f in faults:
        z = Z1 if f.gear == "pinion" else Z2
        tooth = (-f.tooth if f.gear == "pinion" else 1 - f.tooth) % z
        out.append(type(f)(**{**f.__dict__, "tooth": tooth,
                              "flank": "coast" if f.flank == "drive" else "drive"}))
    return out


@pytest.mark.parametrize("faults", [
    [Spall(**SPALL, tooth=5), Wear(30e-6, tooth=5, flank="coast", profile="archard")],
    [Spall(**SPALL, gear="wheel", tooth=7),
     Spall(2e-3, 6e-3, 0.2e-3, position=-0.3e-3, gear="wheel", tooth=7, flank="coast")],
], ids=["pinion-spall+archard", "wheel-spall+spall"])
def test_two_flank_tooth_is_its_mirror(mesh: GearMesh, faults) -> None:
    """A fault on each flank of one tooth: K_coast(c) equals K_drive(phi - c) of the mirrored
    tooth with the faults' flanks swapped, and K_drive(phi - c) its K_coast(c) (1e-12); each
    flank's gap is its own wear's; the Hertz width on each flank is its own spall's."""
    phi = coast_phase(mesh)
    c = (np.arange(Z1 * 16) + 0.3183) / 16.0
    deg = 360.0 / Z1
    one = _run(mesh, faults, angles=c * deg)
    other = _run(mesh, _swapped(faults), angles=(phi - c) * deg)
    np.testing.assert_allclose(one.mesh_stiffness_coast.values, other.mesh_stiffness.values,
                               rtol=1e-12, atol=0.0)
    one_d = _run(mesh, faults, angles=(phi - c) * deg)
    other_c = _run(mesh, _swapped(faults), angles=c * deg)
    np.testing.assert_allclose(other_c.mesh_stiffness_coast.values, one_d.mesh_stiffness.values,
                               rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(one.fault_gap_coast.values.sum(axis=1),
                               other.fault_gap.values.sum(axis=1), rtol=1e-9, atol=1e-15)
    # both flanks felt: below each single-flank run where the tooth meets
    for f in faults:
        alone = _run(mesh, f, angles=c * deg)
        for v in ("mesh_stiffness", "mesh_stiffness_coast"):
            assert np.all(one[v].values <= alone[v].values)
            assert np.count_nonzero(one[v].values < alone[v].values) >= 8
    pair = prepare_pair(mesh, bore_radius=BORES, faults=faults)
    entry = tuple(faults)
    role = faults[0].gear
    g_ = _pinion()
    pos = np.linspace(-0.9, 0.9, 41) * g_["rb"] * 0.2
    for coast, f in ((False, faults[0]), (True, faults[1])):
        kw = {role: entry}
        hertz = pair.terms(pos, **kw, coast=coast)["hertz"]
        single = pair.terms(pos, **{role: f}, coast=coast)["hertz"]
        np.testing.assert_array_equal(hertz, single)


def test_two_flank_zero_fault_is_the_other_alone(mesh: GearMesh) -> None:
    """A zero-size fault on one flank leaves the other flank's fault's result bitwise; two
    uniformly worn flanks open both gaps and lower both flanks below either wear alone."""
    spall = Spall(**SPALL, tooth=2)
    a = _run(mesh, [spall, Wear(0.0, tooth=2, flank="coast")], angles=24)
    b = _run(mesh, spall, angles=24)
    for name in b.variables:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    both = _run(mesh, [Wear(20e-6, tooth=2), Wear(30e-6, tooth=2, flank="coast")], angles=24)
    drive = _run(mesh, Wear(20e-6, tooth=2), angles=24)
    assert both.fault_gap.values.max() == 20e-6 and both.fault_gap_coast.values.max() == 30e-6
    for v in ("mesh_stiffness", "mesh_stiffness_coast"):
        k, kd = both[v].values, drive[v].values
        assert np.all(k <= kd) and np.count_nonzero(k < kd) >= 4


def test_spur_pair_from_geometry_feels_the_coast_spall(mesh: GearMesh) -> None:
    """SpurPair.from_geometry with a coast spall: its coast-flank stiffness series is the
    Fourier series of the coast spall's mesh_stiffness_coast, changed ten times more than the
    drive series (which feels the sections only)."""
    from geardyn.models.spur_pair import SpurPair, fourier_series

    kw = dict(bore_radius=BORES, speed="1000 rpm", torque="100 N m", angles=64)
    spall = Spall(2e-3, 8e-3, 0.5e-3, flank="coast")
    healthy = SpurPair.from_geometry(mesh, **kw)
    faulty = SpurPair.from_geometry(mesh, faults=spall, **kw)
    table = _run(mesh, spall, angles=64)
    np.testing.assert_array_equal(
        faulty.coast_series,
        fourier_series(table.mesh_stiffness_coast.values, faulty.coast_series.size // 2))
    dc = np.abs(faulty.coast_series - healthy.coast_series).max()
    dd = np.abs(faulty.drive_series - healthy.drive_series).max()
    assert dd > 0.0 and dc > 10.0 * dd
