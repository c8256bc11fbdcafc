"""``geardyn stiffness`` and the study tables [gears], [[faults]], [stiffness]: the command
writes what :func:`geardyn.gears.potential_energy_stiffness` computes for the same geometry
(built here from the same literal inputs, not through the study), refuses bad tables with one
line naming the field, and draws the stiffness."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from pydantic import ValidationError

import geardyn.gears as g
from geardyn.cli.main import main
from geardyn.io.netcdf import load_dataset
from geardyn.io.toml import builtin_study, load_study, save_study
from test_cli import assert_one_line_error

#: Every field away from its default, so that a field the study layer drops or mixes up
#: changes the result: profile shifts, per-gear tooth proportions, face widths and bores, a
#: centre distance with backlash, the material, the quadrature, the straight root flank, a
#: crack on a wheel tooth.
STUDY = """
[study]
name = "shifted"

[gears]
module = "3.2 mm"
pressure_angle = "20 deg"
face_width = "16 mm"
dedendum = 1.3
centre_distance = "107.8 mm"
young = "210 GPa"
poisson = 0.29

[gears.pinion]
teeth = 19
profile_shift = 0.25
addendum = 1.05
bore_radius = "11 mm"

[gears.wheel]
teeth = 48
profile_shift = -0.1
addendum = 0.95
dedendum = 1.25
face_width = "18 mm"
bore_radius = "36 mm"

[[faults]]
kind = "crack"
gear = "wheel"
tooth = 2
depth = "1.5 mm"
angle = "40 deg"

[stiffness]
angles = 90
cycles = 5
nodes = 24
root_segment = false
"""


def _shifted_by_api():
    pinion = g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", profile_shift=0.25, addendum=1.05,
                        dedendum=1.3, name="pinion")
    wheel = g.SpurGear(48, "3.2 mm", "20 deg", "18 mm", profile_shift=-0.1, addendum=0.95,
                       dedendum=1.25, name="wheel")
    mesh = g.GearMesh(pinion, wheel, centre_distance="107.8 mm")
    return g.potential_energy_stiffness(
        mesh, bore_radius=("11 mm", "36 mm"), angles=90, cycles=5, young="210 GPa",
        poisson=0.29, nodes=24, root_segment=False,
        faults=(g.RootCrack("1.5 mm", "40 deg", gear="wheel", tooth=2),))


def _example_by_api():
    """The packaged example: the 19/48, m 3.2 mm, 20 deg pair with pinion tooth 9 cracked."""
    mesh = g.GearMesh(g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                      g.SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    return g.potential_energy_stiffness(
        mesh, bore_radius=("12 mm", "35 mm"), angles=360, cycles=19, young="206.8 GPa",
        poisson=0.3, faults=(g.RootCrack("2 mm", "45 deg", gear="pinion", tooth=9),))


def run(capsys, *args) -> subprocess.CompletedProcess:
    """``geardyn ARGS`` in this process (the console script's code path)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in args])
    out = capsys.readouterr()
    return subprocess.CompletedProcess(args, info.value.code, out.out, out.err)


def assert_bitwise_equal(written, computed) -> None:
    """Every variable and coordinate of ``computed`` in ``written``, same dims, dtype and
    bytes (NaN where NaN); the API's attributes kept."""
    for name, var in computed.variables.items():
        got = written[name]
        assert got.dims == var.dims, name
        assert got.dtype == var.dtype, (name, got.dtype, var.dtype)
        assert got.values.tobytes() == var.values.tobytes(), name
    for key, value in computed.attrs.items():
        assert np.array_equal(written.attrs[key], value), key


@pytest.mark.parametrize(("source", "by_api"), [("shifted", _shifted_by_api),
                                                ("stiffness_19_48", _example_by_api)])
def test_cli_writes_what_the_api_computes(tmp_path, capsys, source, by_api):
    study = tmp_path / "shifted.toml"
    study.write_text(STUDY, encoding="utf-8")
    arg = study if source == "shifted" else source
    out = tmp_path / "k.nc"
    r = run(capsys, "stiffness", arg, "-o", out)
    assert r.returncode == 0, r.stderr
    written, computed = load_dataset(out), by_api()
    assert_bitwise_equal(written, computed)
    assert written.attrs["study"] == source
    assert f"contact ratio {computed.attrs['contact_ratio']:.5f}" in r.stdout
    tooth = "wheel tooth 2" if source == "shifted" else "pinion tooth 9"
    assert f"faults: root crack on {tooth}: depth" in r.stdout
    if source == "stiffness_19_48":  # the pair the issue names
        assert round(written.attrs["contact_ratio"], 5) == 1.64563


def test_default_output_is_named_after_the_study(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = run(capsys, "stiffness", "stiffness_19_48")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stiffness_19_48_stiffness.nc"]


def test_study_tables_round_trip(tmp_path):
    study = load_study(STUDY)
    save_study(study, tmp_path / "again.toml")
    again = load_study(tmp_path / "again.toml")
    assert again == study
    assert again.stiffness_inputs()[1] == study.stiffness_inputs()[1]


#: (replaced, replacement, fragments of the one-line error).
BAD = [
    ("dedendum = 1.3\n", "dedendum = 1.3\nbogus = 1\n", ("gears.bogus", "unknown key")),
    ("addendum = 1.05\n", "addendum = 1.05\nteth = 19\n", ("gears.pinion.teth", "unknown key")),
    ('angle = "40 deg"\n', 'angle = "40 deg"\nsize = "1 mm"\n',
     ("faults[0].size", "unknown key", "depth, angle, gear, tooth")),
    ('module = "3.2 mm"', 'module = "-3.2 mm"', ("gears.module", "greater than 0")),
    ('module = "3.2 mm"', 'module = "3.2 kg"', ("gears.module",)),
    ('depth = "1.5 mm"', 'depth = "8 mm"', ("faults[0].depth", "centre line")),
    ('depth = "1.5 mm"', "depth = nan", ("faults[0].depth", "finite")),
    ('depth = "1.5 mm"\n', "", ("faults[0].depth", "required")),
    ("tooth = 2", "tooth = 48", ("faults[0].tooth", "[0, 47]")),
    ('gear = "wheel"', 'gear = "ring"', ("faults[0].gear", "pinion")),
    ('kind = "crack"', 'kind = "pitting"', ("faults[0].kind", "unknown fault kind",
                                                 "crack")),
    ("teeth = 19", "teeth = 9", ("gears.pinion.profile_shift", "undercut", "9 teeth")),
    ('bore_radius = "36 mm"', 'bore_radius = "80 mm"', ("gears.wheel.bore_radius",
                                                         "root radius")),
    ('face_width = "16 mm"\n', "", ("gears.face_width", "required")),
    ("dedendum = 1.25\n", "", ()),  # valid: the wheel takes [gears].dedendum (checked below)
    ('young = "210 GPa"', "young = -2e11", ("gears.young",)),
    ("poisson = 0.29", "poisson = 0.5", ("gears.poisson", "[0, 0.5)")),
    ('centre_distance = "107.8 mm"', 'centre_distance = "107 mm"',
     ("gears.centre_distance", "overlap")),
    ("cycles = 5", "cycles = 0", ("stiffness.cycles", "hunting")),
    ("nodes = 24", "nodes = 2", ("stiffness.nodes",)),
    ("angles = 90", "angles = 10000000000", ("stiffness.angles", "GiB", "--yes")),
    ('angle = "40 deg"', 'angle = "1 kg"', ("faults[0]:", "rad")),
    ("[stiffness]", '[[faults]]\nkind = "crack"\ngear = "wheel"\ntooth = 2\n'
     'depth = "1 mm"\n\n[stiffness]', ("faults:",)),  # a second fault on the same tooth
]


@pytest.mark.parametrize(("old", "new", "fragments"), BAD,
                         ids=[b[2][0] if b[2] else "valid" for b in BAD])
def test_bad_tables_are_one_line_errors_naming_the_field(tmp_path, capsys, old, new,
                                                         fragments):
    assert old in STUDY
    study = tmp_path / "bad.toml"
    study.write_text(STUDY.replace(old, new, 1), encoding="utf-8")
    out = tmp_path / "k.nc"
    r = run(capsys, "stiffness", study, "-o", out)
    if not fragments:
        assert r.returncode == 0, r.stderr
        assert load_study(study).gears.gear("wheel").dedendum == 1.3
        return
    assert_one_line_error(r, *fragments)
    assert not out.exists()


def test_errors_are_raised_when_the_study_is_read():
    """Validated where it enters: load_study refuses the crack, at its field's location."""
    with pytest.raises(ValidationError) as info:
        load_study(STUDY.replace('depth = "1.5 mm"', 'depth = "8 mm"'))
    assert info.value.errors()[0]["loc"] == ("faults", 0, "depth")
    with pytest.raises(ValidationError) as info:
        load_study(STUDY.replace("teeth = 19", "teeth = 9"))
    assert info.value.errors()[0]["loc"] == ("gears", "pinion", "profile_shift")


def test_tables_need_gears_and_models_need_params(tmp_path, capsys):
    no_gears = '[study]\nname = "x"\n[[faults]]\nkind = "crack"\ndepth = "1 mm"\n'
    study = tmp_path / "x.toml"
    study.write_text(no_gears, encoding="utf-8")
    r = run(capsys, "stiffness", study)
    assert r.returncode == 2 and "faults: needs a [gears] table" in r.stderr, r.stderr
    r = run(capsys, "simulate", "stiffness_19_48", "--omega", "1.1")
    assert r.returncode == 2 and "has no [params]" in r.stderr, r.stderr
    r = run(capsys, "stiffness", "paper_fig3")
    assert r.returncode == 2 and "no [gears] table" in r.stderr, r.stderr


@pytest.mark.parametrize("suffix", [".png", ".pdf"])
def test_plot_writes_a_figure_with_the_healthy_pair(tmp_path, capsys, suffix):
    out, fig = tmp_path / "k.nc", tmp_path / f"k{suffix}"
    r = run(capsys, "stiffness", "stiffness_19_48", "-o", out, "--plot", "--figure", fig)
    assert r.returncode == 0, r.stderr
    magic = {".png": b"\x89PNG", ".pdf": b"%PDF"}[suffix]
    data = fig.read_bytes()
    assert data.startswith(magic) and len(data) > 10_000
    assert f"wrote {out}, {fig}" in r.stdout


def test_help_shows_the_command(capsys):
    r = run(capsys, "stiffness", "--help")
    assert r.returncode == 0
    text = " ".join(r.stdout.split())
    assert "gears table" in text and "faults on its teeth" in text and "--figure" in text
    r = run(capsys, "--help")
    assert "stiffness" in r.stdout


def test_geardyn_plot_redraws_a_saved_stiffness(tmp_path, capsys):
    out = tmp_path / "k.nc"
    assert run(capsys, "stiffness", "stiffness_19_48", "-o", out).returncode == 0
    r = run(capsys, "plot", out, "--out", tmp_path / "again.pdf")
    assert r.returncode == 0, r.stderr
    assert "mesh stiffness dataset" in r.stdout
    assert (tmp_path / "again.pdf").read_bytes().startswith(b"%PDF")


def test_plot_default_figure_and_bad_figure_paths(tmp_path, capsys):
    out = tmp_path / "k.nc"
    r = run(capsys, "stiffness", "stiffness_19_48", "-o", out, "--plot")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "k.png").read_bytes().startswith(b"\x89PNG")
    r = run(capsys, "stiffness", "stiffness_19_48", "-o", tmp_path / "j.nc", "--figure",
            tmp_path / "j.png")
    assert r.returncode == 2 and "--figure" in r.stderr and "without --plot" in r.stderr
    r = run(capsys, "stiffness", "stiffness_19_48", "-o", tmp_path / "j.nc", "--plot",
            "--figure", tmp_path / "j.jpg")
    assert r.returncode == 2 and "--figure" in r.stderr
    r = run(capsys, "stiffness", "stiffness_19_48", "-o", tmp_path / "j.txt")
    assert r.returncode == 2 and "--out" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["k.nc", "k.png"]


def test_figure_draws_both_flanks_and_the_healthy_drive_flank():
    from geardyn.plotting.stiffness import plot_mesh_stiffness
    from geardyn.study import mesh_stiffness

    study = builtin_study("stiffness_19_48")
    faulty, healthy = mesh_stiffness(study), mesh_stiffness(study, faults=False)
    assert not np.array_equal(faulty.mesh_stiffness, healthy.mesh_stiffness)
    fig = plot_mesh_stiffness(faulty, healthy=healthy)
    top = fig.axes[0]
    drawn = {line.get_label(): line.get_ydata() for line in top.get_lines()}
    assert set(drawn) == {"drive flank, healthy", "drive flank", "coast flank"}
    scale = faulty.mesh_stiffness.values[0] / drawn["drive flank"][0]
    np.testing.assert_allclose(drawn["drive flank, healthy"] * scale,
                               healthy.mesh_stiffness.values, rtol=1e-14)
    np.testing.assert_allclose(drawn["coast flank"] * scale,
                               faulty.mesh_stiffness_coast.values, rtol=1e-14)
    with pytest.raises(ValueError, match="not a mesh stiffness"):
        plot_mesh_stiffness(faulty.drop_vars("mesh_stiffness_coast"))


def test_a_study_holds_several_fault_kinds_each_on_its_tooth(tmp_path):
    """Every kind of geardyn.gears.FAULT_KINDS is a [[faults]] table; the study's stiffness
    equals the API's with the same faults."""
    from geardyn.study import mesh_stiffness

    study = tmp_path / "s.toml"
    study.write_text(
        '[study]\nname = "s"\n[gears]\nmodule = "3.2 mm"\npressure_angle = "20 deg"\n'
        'face_width = "16 mm"\nbore_radius = "12 mm"\n[gears.pinion]\nteeth = 19\n'
        '[gears.wheel]\nteeth = 48\nbore_radius = "35 mm"\n'
        '[[faults]]\nkind = "crack"\ntooth = 1\ndepth = "1 mm"\n'
        '[[faults]]\nkind = "spall"\ntooth = 2\nlength = "1 mm"\nwidth = "4 mm"\n'
        'depth = "0.2 mm"\n'
        '[[faults]]\nkind = "wear"\ngear = "wheel"\ntooth = 3\ndepth = "20 um"\n'
        '[[faults]]\nkind = "broken_tooth"\ntooth = 4\n'
        '[stiffness]\nangles = 36\ncycles = 6\n')
    got = mesh_stiffness(load_study(study))
    mesh = g.GearMesh(g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                      g.SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    want = g.potential_energy_stiffness(
        mesh, bore_radius=("12 mm", "35 mm"), angles=36, cycles=6,
        faults=(g.RootCrack("1 mm", tooth=1), g.Spall("1 mm", "4 mm", "0.2 mm", tooth=2),
                g.Wear("20 um", gear="wheel", tooth=3), g.BrokenTooth("pinion", 4)))
    assert np.array_equal(got["mesh_stiffness"].values, want["mesh_stiffness"].values)
    assert np.array_equal(got["mesh_stiffness_coast"].values,
                          want["mesh_stiffness_coast"].values)


@pytest.mark.parametrize("command", [("simulate",), ("bifurcation",), ("frc",), ("continue",),
                                     ("explore",), ("params", "show")])
def test_commands_that_run_a_model_refuse_a_gears_only_study_first(capsys, command):
    """A study of gears alone (no [params]) is refused by name before any option is resolved
    (``simulate`` asked for --omega, ``explore`` for --range)."""
    r = run(capsys, *command, "stiffness_19_48")
    assert_one_line_error(r, "has no [params]")
