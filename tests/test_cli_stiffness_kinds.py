"""``geardyn stiffness`` on internal (planet-ring) and helical pairs, with tip relief, lead
crowning and a load: the study tables ``[gears]`` (``helix_angle``, ``internal``,
``ring_foundation``), ``[stiffness]`` (``slices``, ``torque``, ``force``), ``[[relief]]`` and
``[crowning]``. The command writes what the API computes for the same geometry (built here
from literal inputs, not through the study; the torque turned into a force by the base radius
written out here), refuses contradictory or bad tables with one line naming the field, and
draws the loaded contact."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

import geardyn.gears as g
from geardyn.io.netcdf import load_dataset
from geardyn.io.toml import builtin_study, load_study, save_study
from test_cli import assert_one_line_error
from test_cli_stiffness import assert_bitwise_equal, run


def _base_radius(teeth: int, module: float, alpha_n: float, beta: float = 0.0) -> float:
    """r_b of the (transverse) section [m], written out: z m_n / (2 cos b) cos(alpha_t)."""
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    return teeth * module / (2.0 * math.cos(beta)) * math.cos(alpha_t)


def _with_contact(ds, contact, **attrs):
    """The stiffness Dataset with the loaded contact's variables and attrs (the layout the
    command writes)."""
    out = ds.assign(contact.data_vars)
    out.attrs.update(contact.attrs, **attrs)
    return out


def _planet_ring_by_api():
    """The packaged 23/71 planet-ring study: internal pair, rigid ring, relief, 50 N m."""
    mesh = g.GearMesh(g.SpurGear(23, "2 mm", "20 deg", "20 mm", name="pinion"),
                      g.SpurGear(71, "2 mm", "20 deg", "20 mm", internal=True, name="wheel"),
                      internal=True)
    ds = g.potential_energy_stiffness(mesh, bore_radius=("10 mm", "80 mm"), angles=180,
                                      cycles=2, ring_foundation="rigid")
    force = 50.0 / _base_radius(23, 0.002, math.radians(20.0))
    np.testing.assert_allclose(force, 50.0 / mesh.pinion.base_radius, rtol=1e-14)
    contact = g.loaded_contact(mesh, ds, 50.0 / mesh.pinion.base_radius,
                               relief=(g.TipRelief("10 um", "1.5 mm", "linear", "pinion"),))
    return _with_contact(ds, contact, torque_Nm=50.0), force


def _helical_by_api():
    """The packaged 19/48 helical study: beta 20 deg, 10 slices, crowning, relief, 100 N m."""
    mesh = g.HelicalMesh(
        g.HelicalGear(19, "3.2 mm", "20 deg", "20 deg", "16 mm", name="pinion"),
        g.HelicalGear(48, "3.2 mm", "20 deg", "20 deg", "16 mm", name="wheel"))
    ds = g.helical_stiffness(mesh, bore_radius=("12 mm", "35 mm"), angles=90, cycles=2,
                             slices=10, young="206.8 GPa", poisson=0.3)
    force = 100.0 / _base_radius(19, 0.0032, math.radians(20.0), math.radians(20.0))
    r_b1 = mesh.transverse.pinion.base_radius
    np.testing.assert_allclose(force, 100.0 / r_b1, rtol=1e-14)
    contact = g.helical_loaded_contact(
        mesh, ds, 100.0 / r_b1, relief=(g.TipRelief("8 um", "2 mm", "parabolic", "wheel"),),
        crowning=(g.LeadCrowning("5 um", "pinion"),))
    return _with_contact(ds, contact, torque_Nm=100.0), force


#: A helical pair with every field away from its default, so that a field the study layer
#: drops or mixes up changes the result: normal profile shifts, per-gear face widths and
#: tooth proportions, the centre distance, the material, quadrature, the straight root flank,
#: a crack and uniform wear, crowning on both gears, two reliefs, the load as a force.
HELICAL = """
[study]
name = "helix"

[gears]
module = "2.5 mm"
pressure_angle = "20 deg"
helix_angle = "15 deg"
face_width = "30 mm"
dedendum = 1.3
centre_distance = "97.5 mm"
young = "210 GPa"
poisson = 0.29

[gears.pinion]
teeth = 22
profile_shift = 0.2
addendum = 1.05
bore_radius = "12 mm"

[gears.wheel]
teeth = 53
profile_shift = -0.1
face_width = "32 mm"
bore_radius = "40 mm"

[[faults]]
kind = "crack"
gear = "pinion"
tooth = 1
depth = "1 mm"
angle = "40 deg"

[[faults]]
kind = "wear"
gear = "wheel"
tooth = 2
depth = "5 um"

[[crowning]]
amount = "4 um"
gear = "pinion"

[[crowning]]
amount = "3 um"
gear = "wheel"

[[relief]]
amount = "6 um"
length = "1.2 mm"
shape = "parabolic"
gear = "pinion"

[[relief]]
amount = "5 um"
length = "1 mm"
gear = "wheel"

[stiffness]
angles = 40
cycles = 3
slices = 7
nodes = 24
root_segment = false
force = "2.5 kN"
"""


def _helix_by_api():
    pinion = g.HelicalGear(22, "2.5 mm", "20 deg", "15 deg", "30 mm", profile_shift=0.2,
                           addendum=1.05, dedendum=1.3, name="pinion")
    wheel = g.HelicalGear(53, "2.5 mm", "20 deg", "15 deg", "32 mm", profile_shift=-0.1,
                          dedendum=1.3, name="wheel")
    mesh = g.HelicalMesh(pinion, wheel, centre_distance="97.5 mm")
    ds = g.helical_stiffness(
        mesh, bore_radius=("12 mm", "40 mm"), angles=40, cycles=3, slices=7, young="210 GPa",
        poisson=0.29, nodes=24, root_segment=False,
        faults=(g.RootCrack("1 mm", "40 deg", gear="pinion", tooth=1),
                g.Wear("5 um", gear="wheel", tooth=2)))
    contact = g.helical_loaded_contact(
        mesh, ds, 2500.0,
        relief=(g.TipRelief("6 um", "1.2 mm", "parabolic", "pinion"),
                g.TipRelief("5 um", "1 mm", "linear", "wheel")),
        crowning=(g.LeadCrowning("4 um", "pinion"), g.LeadCrowning("3 um", "wheel")))
    return _with_contact(ds, contact), 2500.0


#: An internal pair with shifted teeth, a cracked planet tooth and a cracked ring tooth, no
#: load (the stiffness alone).
RING = """
[study]
name = "ring"

[gears]
module = "3 mm"
pressure_angle = "20 deg"
face_width = "30 mm"
internal = true

[gears.pinion]
teeth = 31
profile_shift = 0.1
bore_radius = "20 mm"

[gears.wheel]
teeth = 82
profile_shift = 0.1
bore_radius = "140 mm"

[[faults]]
kind = "crack"
gear = "pinion"
tooth = 1
depth = "1 mm"

[[faults]]
kind = "crack"
gear = "wheel"
tooth = 0
depth = "1.5 mm"
angle = "30 deg"

[stiffness]
angles = 60
cycles = 2
"""


def _ring_by_api():
    mesh = g.GearMesh(
        g.SpurGear(31, "3 mm", "20 deg", "30 mm", profile_shift=0.1, name="pinion"),
        g.SpurGear(82, "3 mm", "20 deg", "30 mm", profile_shift=0.1, internal=True,
                   name="wheel"), internal=True)
    ds = g.potential_energy_stiffness(
        mesh, bore_radius=("20 mm", "140 mm"), angles=60, cycles=2,
        faults=(g.RootCrack("1 mm", tooth=1),
                g.RootCrack("1.5 mm", "30 deg", gear="wheel", tooth=0)))
    return ds, None


CASES = {"stiffness_planet_ring": _planet_ring_by_api, "stiffness_helical": _helical_by_api,
         "helix": _helix_by_api, "ring": _ring_by_api}
TEXTS = {"helix": HELICAL, "ring": RING}


@pytest.mark.parametrize("source", list(CASES))
def test_cli_writes_what_the_api_computes(tmp_path, capsys, source):
    arg = source
    if source in TEXTS:
        arg = tmp_path / f"{source}.toml"
        arg.write_text(TEXTS[source], encoding="utf-8")
    out = tmp_path / "k.nc"
    r = run(capsys, "stiffness", arg, "-o", out)
    assert r.returncode == 0, r.stderr
    written = load_dataset(out)
    computed, force = CASES[source]()
    assert_bitwise_equal(written, computed)
    assert written.attrs["study"] == source
    if force is None:
        assert "transmission_error" not in written and "force_N" not in written.attrs
        assert "under" not in r.stdout
    else:
        np.testing.assert_allclose(written.attrs["force_N"], force, rtol=1e-14)
        te = written["transmission_error"].values
        assert f"under {force:.4g} N transmission error {te.mean() * 1e6:.4g} um" in r.stdout
    if "slices" in computed.attrs:
        assert f"{computed.attrs['slices']} slices" in r.stdout


def test_packaged_studies_are_what_the_docs_say():
    """The internal study's ring is a ring with a rigid body; the helical one's overlap."""
    from geardyn.study import mesh_stiffness

    ring = mesh_stiffness(builtin_study("stiffness_planet_ring"))
    assert ring.attrs["internal"] == 1 and ring.attrs["ring_foundation"] == "rigid"
    assert np.all(np.isinf(ring["k_fillet_wheel"].values[ring["in_contact"].values]))
    mesh, kw = builtin_study("stiffness_helical").stiffness_inputs()
    assert isinstance(mesh, g.HelicalMesh) and kw["slices"] == 10
    np.testing.assert_allclose(mesh.overlap_ratio,
                               0.016 * math.sin(math.radians(20.0)) / (math.pi * 0.0032),
                               rtol=1e-14)


def test_study_tables_round_trip(tmp_path):
    for text in (HELICAL, RING):
        study = load_study(text)
        save_study(study, tmp_path / "again.toml")
        again = load_study(tmp_path / "again.toml")
        assert again == study
        assert again.stiffness_inputs()[1] == study.stiffness_inputs()[1]
        assert again.contact_inputs() == study.contact_inputs()


def test_a_single_crowning_table_is_one_crowning():
    one = load_study(HELICAL.replace("[[crowning]]\namount = \"3 um\"\ngear = \"wheel\"\n", "")
                     .replace("[[crowning]]", "[crowning]"))
    assert one.contact_inputs()["crowning"] == (g.LeadCrowning("4 um", "pinion"),)


#: (study text, replaced, replacement, fragments of the one-line error).
BAD = [
    (RING, "angles = 60", "angles = 60\nslices = 10", ("stiffness.slices", "helix_angle")),
    (HELICAL, 'kind = "crack"\ngear = "pinion"\ntooth = 1\ndepth = "1 mm"\nangle = "40 deg"',
     'kind = "spall"\ngear = "pinion"\ntooth = 1\nlength = "1 mm"\nwidth = "4 mm"\n'
     'depth = "0.1 mm"', ("faults[0].kind", "spall on a helical pair")),
    (HELICAL, 'depth = "5 um"', 'depth = "5 um"\nprofile = "archard"',
     ("faults[1].profile", "uniform wear only")),
    (HELICAL, 'force = "2.5 kN"', "", ("crowning", "needs a load", "torque")),
    (HELICAL.replace('[[crowning]]\namount = "4 um"\ngear = "pinion"\n', "")
     .replace('[[crowning]]\namount = "3 um"\ngear = "wheel"\n', ""), 'force = "2.5 kN"', "",
     ("relief", "needs a load")),
    (RING, "[stiffness]", '[crowning]\namount = "5 um"\n\n[stiffness]\ntorque = "10 N m"',
     ("crowning", "helical pair", "helix_angle")),
    (HELICAL, 'force = "2.5 kN"', 'force = "2.5 kN"\ntorque = "10 N m"',
     ("stiffness.force", "not both")),
    (HELICAL, 'force = "2.5 kN"', 'torque = "-10 N m"', ("stiffness.torque", "greater than 0")),
    (HELICAL, 'force = "2.5 kN"', 'torque = "10 kg"', ("stiffness.torque",)),
    (HELICAL, 'force = "2.5 kN"', 'force = "2.5 kN m"', ("stiffness.force",)),
    (HELICAL, 'helix_angle = "15 deg"', 'helix_angle = "50 deg"',
     ("gears.helix_angle", "45 deg")),
    (HELICAL, 'helix_angle = "15 deg"', 'helix_angle = "15 deg"\ninternal = true',
     ("gears.internal", "internal helical pair")),
    (RING, "internal = true", 'internal = "yes"', ("gears.internal",)),
    (RING, "internal = true", "internal = true\nring_foundation = \"elastic\"",
     ("gears.ring_foundation", "rigid")),
    (HELICAL, "poisson = 0.29", 'poisson = 0.29\nring_foundation = "rigid"',
     ("gears.ring_foundation", "internal = true")),
    (RING, 'bore_radius = "140 mm"', 'bore_radius = "125 mm"',
     ("gears.wheel.bore_radius", "rim")),
    (RING, 'bore_radius = "140 mm"\n', "", ("gears.wheel.bore_radius", "required")),
    (RING, 'kind = "crack"\ngear = "wheel"\ntooth = 0\ndepth = "1.5 mm"\nangle = "30 deg"',
     'kind = "spall"\ngear = "wheel"\ntooth = 0\nlength = "1 mm"\nwidth = "4 mm"\n'
     'depth = "0.1 mm"\nposition = "3 mm"', ("faults[1].position", "active")),
    (HELICAL, 'amount = "6 um"', 'amout = "6 um"',
     ("relief[0].amout", "unknown key", "amount, length, shape, gear")),
    (HELICAL, 'amount = "6 um"\n', "", ("relief[0].amount", "required")),
    (HELICAL, 'length = "1.2 mm"', 'length = "30 mm"', ("relief[0].length", "path of contact")),
    (HELICAL, 'shape = "parabolic"', 'shape = "cubic"', ("relief[0].shape", "linear")),
    (HELICAL, 'amount = "5 um"', 'amount = "5 kg"', ("relief[1].amount",)),
    (HELICAL, 'amount = "4 um"', 'amount = "-4 um"', ("crowning[0].amount", ">= 0")),
    (HELICAL, 'amount = "3 um"\ngear = "wheel"', 'amount = "3 um"\ngear = "ring"',
     ("crowning[1].gear", "pinion")),
    (HELICAL, 'amount = "3 um"', 'amount = "3 um"\nlength = "1 mm"',
     ("crowning[1].length", "unknown key", "amount, gear")),
    (HELICAL, "slices = 7", "slices = 0", ("stiffness.slices",)),
    (HELICAL, "angles = 40", "angles = 400000000", ("stiffness.angles", "GiB", "--yes")),
]


@pytest.mark.parametrize(("text", "old", "new", "fragments"), BAD,
                         ids=[f"{i}-{b[3][0]}" for i, b in enumerate(BAD)])
def test_bad_tables_are_one_line_errors_naming_the_field(tmp_path, capsys, text, old, new,
                                                         fragments):
    assert old in text
    study = tmp_path / "bad.toml"
    study.write_text(text.replace(old, new, 1), encoding="utf-8")
    out = tmp_path / "k.nc"
    r = run(capsys, "stiffness", study, "-o", out)
    assert_one_line_error(r, *fragments)
    assert not out.exists()


def test_contradictions_are_refused_when_the_study_is_read():
    with pytest.raises(ValidationError) as info:
        load_study(RING.replace("angles = 60", "angles = 60\nslices = 4"))
    assert info.value.errors()[0]["loc"] == ("stiffness", "slices")
    with pytest.raises(ValidationError) as info:
        load_study(HELICAL.replace('force = "2.5 kN"', ""))
    assert info.value.errors()[0]["loc"] == ("crowning",)


def test_plot_draws_the_loaded_contact(tmp_path, capsys):
    """Four panels: both flanks, the face in contact, the unloaded and loaded transmission
    error [um] and the loaded stiffness, each curve the Dataset's values."""
    from geardyn.plotting.stiffness import plot_mesh_stiffness

    out, fig_path = tmp_path / "k.nc", tmp_path / "k.png"
    r = run(capsys, "stiffness", "stiffness_helical", "-o", out, "--plot")
    assert r.returncode == 0, r.stderr
    assert fig_path.read_bytes().startswith(b"\x89PNG")
    ds = load_dataset(out)
    fig = plot_mesh_stiffness(ds)
    assert len(fig.axes) >= 4
    te = {line.get_label(): line.get_ydata() for line in fig.axes[2].get_lines()}
    np.testing.assert_allclose(te["loaded"], ds["transmission_error"].values * 1e6,
                               rtol=1e-14)
    np.testing.assert_allclose(te["unloaded"],
                               ds["unloaded_transmission_error"].values * 1e6, rtol=1e-14)
    loaded = {line.get_label(): line.get_ydata() for line in fig.axes[3].get_lines()}
    scale = ds["tangent_stiffness"].values[0] / loaded["tangent"][0]
    np.testing.assert_allclose(loaded["secant"] * scale, ds["secant_stiffness"].values,
                               rtol=1e-14)
    steps = {line.get_label(): line.get_ydata() for line in fig.axes[1].get_lines()}
    np.testing.assert_array_equal(steps["drive flank"], ds["pairs_in_contact"].values)
    assert "10 slices" in fig.get_suptitle()
    r = run(capsys, "plot", out, "--out", tmp_path / "again.pdf")
    assert r.returncode == 0, r.stderr


def test_internal_plot_and_default_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = run(capsys, "stiffness", "stiffness_planet_ring", "--plot")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "stiffness_planet_ring_stiffness.nc", "stiffness_planet_ring_stiffness.png"]


def test_docs_table_of_the_packaged_studies():
    """docs/gears.md's table of the packaged studies' loaded contact, recomputed."""
    import re
    from pathlib import Path

    from geardyn.study import mesh_stiffness

    text = (Path(__file__).resolve().parent.parent / "docs" / "gears.md").read_text()
    table = text.split("<!-- study-loaded-table:begin")[1].split("<!-- study-loaded-table:end")[0]
    rows = [line for line in table.splitlines() if line.startswith("| `")]
    assert len(rows) == 2
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        ds = mesh_stiffness(builtin_study(re.sub("`", "", cells[0])))
        te = ds["transmission_error"].values * 1e6
        got = [f"{float(ds.mesh_stiffness.mean()):.3e}".replace("e+0", "e"),
               f"{ds.attrs['torque_Nm']:g}", f"{ds.attrs['force_N']:.0f}", f"{te.mean():.2f}",
               f"{np.ptp(te):.2f}",
               f"{float(ds.tangent_stiffness.mean()):.3e}".replace("e+0", "e"),
               f"{float(ds.secant_stiffness.mean()):.3e}".replace("e+0", "e")]
        assert cells[1:] == got, (cells[0], got)


def test_relief_and_crowning_need_gears(tmp_path, capsys):
    for table in ('[[relief]]\namount = "5 um"\nlength = "1 mm"\n',
                  '[crowning]\namount = "5 um"\n'):
        study = tmp_path / "x.toml"
        study.write_text('[study]\nname = "x"\n' + table, encoding="utf-8")
        r = run(capsys, "stiffness", study)
        name = "relief" if "relief" in table else "crowning"
        assert r.returncode == 2 and f"{name}: needs a [gears] table" in r.stderr, r.stderr


@pytest.mark.parametrize(("old", "new", "field"), [
    ('face_width = "16 mm"', 'face_width = "16 mm"\nhelix_angle = "20 deg"',
     ("gears", "helix_angle")),
    ('face_width = "16 mm"', 'face_width = "16 mm"\ninternal = true', ("gears", "internal")),
    ("angles = 64", "angles = 64\nslices = 4", ("stiffness", "slices")),
    ("angles = 64", 'angles = 64\ntorque = "5 N m"', ("stiffness", "torque")),
    ("angles = 64", 'angles = 64\nforce = "5 N"', ("stiffness", "force")),
    ("\n[params]", '\n[[relief]]\namount = "5 um"\nlength = "1 mm"\n\n[params]', ("relief",)),
])
def test_a_spur_pair_model_refuses_what_it_does_not_model(old, new, field):
    """A spur_pair study's model is an external spur pair on its unloaded stiffness: the
    helical, internal and loaded-contact fields are refused where the study is read, not
    dropped."""
    from importlib import resources

    text = resources.files("geardyn.studies").joinpath("spur_pair_cracked.toml").read_text()
    assert old in text
    with pytest.raises(ValidationError) as info:
        load_study(text.replace(old, new, 1))
    err = info.value.errors()[0]
    assert err["loc"] == field and "not part of a spur_pair model" in err["msg"]
