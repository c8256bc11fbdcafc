"""A gear train from a study's [train] table and ``geardyn modes``: the TOML-built train equals
the one built in Python from the same literal inputs (matrices bitwise), bad tables are refused
naming the table and field, and the command writes what the API computes."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest
from pydantic import ValidationError

from geardyn.cli.errors import format_error
from geardyn.cli.main import main
from geardyn.gears import HelicalGear, SpurGear
from geardyn.io.netcdf import load_dataset
from geardyn.io.toml import load_study, save_study
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Inertia, Mesh, Shaft, planetary_stage
from test_cli import assert_one_line_error

#: Two parallel stages, every kind of element and most fields away from their defaults: a gear
#: by base radius, spur gears by geometry on an ISO mesh, helical gears on a given stiffness, a
#: flexible bearing, damping, Rayleigh damping.
TWO_STAGE = """
[study]
name = "two_stage"

[train]
driven = "g1"
rayleigh = [0.5, 1e-6]

[train.gears.g1]
inertia = "0.01 kg m^2"
mass = "2.5 kg"
geometry.teeth = 19
geometry.module = "3 mm"
geometry.pressure_angle = "20 deg"
geometry.face_width = "20 mm"
geometry.profile_shift = 0.1

[train.gears.g2]
inertia = 0.35

[train.gears.g2.geometry]
teeth = 61
module = "3 mm"
pressure_angle = "20 deg"
face_width = "18 mm"

[train.gears.g3]
inertia = 0.02
geometry.teeth = 23
geometry.module = "4 mm"
geometry.pressure_angle = "20 deg"
geometry.helix_angle = "12 deg"
geometry.face_width = "30 mm"

[train.gears.g4]
inertia = 0.6
geometry.teeth = 71
geometry.module = "4 mm"
geometry.pressure_angle = "20 deg"
geometry.helix_angle = "12 deg"
geometry.face_width = "30 mm"

[train.inertias.load]
inertia = "1.5 kg m^2"

[train.shafts.input]
a = "g1"
b = "ground"
stiffness = "4e4 N m"
damping = 2.0

[train.shafts.mid]
a = "g2"
b = "g3"
stiffness = 9e5

[train.shafts.output]
a = "g4"
b = "load"
stiffness = 2.5e5

[train.shafts.brake]
a = "load"
b = "ground"
stiffness = 1e5

[train.bearings.b1]
body = "g1"
stiffness = "2e9 N/m"
damping = 300.0

[train.bearings.b2]
body = "g2"
stiffness = "inf"

[train.bearings.b3]
body = "g3"
stiffness = "inf"

[train.bearings.b4]
body = "g4"
stiffness = "inf"

[train.meshes.stage1]
a = "g1"
b = "g2"
stiffness = "iso"
angle = "30 deg"
damping = 500.0

[train.meshes.stage2]
a = "g3"
b = "g4"
stiffness = "8e8 N/m"
backlash = ["50 um", "60 um"]
"""


def _two_stage_by_api() -> GearTrain:
    spur = {"module": "3 mm", "pressure_angle": "20 deg"}
    helical = {"module": "4 mm", "pressure_angle": "20 deg", "helix_angle": "12 deg",
               "face_width": "30 mm"}
    gears = [
        Gear("g1", "0.01 kg m^2", mass="2.5 kg", geometry=SpurGear(
            19, face_width="20 mm", profile_shift=0.1, name="g1", **spur)),
        Gear("g2", 0.35, geometry=SpurGear(61, face_width="18 mm", name="g2", **spur)),
        Gear("g3", 0.02, geometry=HelicalGear(23, name="g3", **helical)),
        Gear("g4", 0.6, geometry=HelicalGear(71, name="g4", **helical)),
        Inertia("load", "1.5 kg m^2")]
    return GearTrain(
        gears,
        shafts=[Shaft("input", "g1", GROUND, "4e4 N m", 2.0), Shaft("mid", "g2", "g3", 9e5),
                Shaft("output", "g4", "load", 2.5e5), Shaft("brake", "load", GROUND, 1e5)],
        bearings=[Bearing("b1", "g1", "2e9 N/m", damping=300.0),
                  *(Bearing(f"b{i}", f"g{i}", math.inf) for i in (2, 3, 4))],
        meshes=[Mesh("stage1", "g1", "g2", "iso", angle="30 deg", damping=500.0),
                Mesh("stage2", "g3", "g4", "8e8 N/m", backlash=("50 um", "60 um"))],
        driven="g1", rayleigh=(0.5, 1e-6))


PLANETARY = """
[study]
name = "planetary"

[train]
driven = "carrier"
fixed = ["ring"]

[train.gears.sun]
inertia = 0.8
mass = 40.0
base_radius = "0.2 m"
n_teeth = 21

[train.gears.planet]
inertia = 0.5
mass = 30.0
base_radius = "0.15 m"
n_teeth = 17

[train.gears.ring]
inertia = 20.0
base_radius = "0.5 m"
n_teeth = 57

[train.inertias.carrier]
inertia = 9.0
mass = 200.0

[train.inertias.rotor]
inertia = 5000.0

[train.shafts.main]
a = "rotor"
b = "carrier"
stiffness = "5e8 N m"

[train.shafts.out]
a = "sun"
b = "ground"
stiffness = "2e6 N m"

[train.bearings.sun_bearing]
body = "sun"
stiffness = "1e9 N/m"

[train.bearings.carrier_bearing]
body = "carrier"
stiffness = "5e9 N/m"

[train.planetary.stage1]
sun = "sun"
ring = "ring"
carrier = "carrier"
planet = "planet"
n_planets = 4
pin_stiffness = "2e9 N/m"
sun_mesh_stiffness = "6e9 N/m"
ring_mesh_stiffness = "7e9 N/m"
planet_angles = ["0 deg", "92 deg", "180 deg", "268 deg"]
"""


def _planetary_by_api() -> GearTrain:
    sun = Gear("sun", 0.8, mass=40.0, base_radius="0.2 m", n_teeth=21)
    planet = Gear("planet", 0.5, mass=30.0, base_radius="0.15 m", n_teeth=17)
    ring = Gear("ring", 20.0, base_radius="0.5 m", n_teeth=57)
    carrier = Inertia("carrier", 9.0, mass=200.0)
    stage = planetary_stage(sun=sun, ring=ring, carrier=carrier, planet=planet, n_planets=4,
                            pin_stiffness="2e9 N/m", sun_mesh_stiffness="6e9 N/m",
                            ring_mesh_stiffness="7e9 N/m",
                            planet_angles=["0 deg", "92 deg", "180 deg", "268 deg"])
    planets = [b for b in stage.bodies if b.name in stage.planets]
    return GearTrain(
        [sun, *planets, ring, carrier, Inertia("rotor", 5000.0)],
        shafts=[Shaft("main", "rotor", "carrier", "5e8 N m"),
                Shaft("out", "sun", GROUND, "2e6 N m")],
        bearings=[Bearing("sun_bearing", "sun", "1e9 N/m"),
                  Bearing("carrier_bearing", "carrier", "5e9 N/m"), *stage.bearings],
        meshes=list(stage.meshes), fixed=["ring"], driven="carrier")


def assert_same_train(got: GearTrain, want: GearTrain) -> None:
    assert got.dof_names() == want.dof_names()
    for method in ("mass_matrix", "stiffness_matrix", "damping_matrix"):
        a, b = getattr(got, method)(), getattr(want, method)()
        assert a.tobytes() == b.tobytes(), method
    assert got.mesh_data == want.mesh_data
    assert [e[:2] for e in got.elements()] == [e[:2] for e in want.elements()]


@pytest.mark.parametrize(("text", "by_api"), [(TWO_STAGE, _two_stage_by_api),
                                              (PLANETARY, _planetary_by_api)])
def test_toml_train_equals_python_train_bitwise(text, by_api, tmp_path):
    train = load_study(text).gear_train
    assert_same_train(train, by_api())
    path = save_study(load_study(text), tmp_path / "again.toml")  # a written study reads back
    assert_same_train(load_study(path).gear_train, train)


def test_toml_train_keeps_the_helical_and_planetary_facts():
    two = load_study(TWO_STAGE).gear_train
    assert two.mesh_data["stage1"].method == "iso"
    assert two.mesh_data["stage2"].base_helix_angle > 0.0
    assert two.meshes[1].backlash == (50e-6, 60e-6)
    planetary = load_study(PLANETARY).gear_train
    assert [b for b in planetary.bodies][:5] == ["sun", "planet1", "planet2", "planet3",
                                                  "planet4"]
    assert set(planetary.modes()["type"].values) >= {"planet", "rotational", "translational"}


def _bad(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


@pytest.mark.parametrize(("old", "new", "where"), [
    ('stiffness = "8e8 N/m"', 'stiffness = "-8e8 N/m"',
     "train.meshes.stage2.stiffness: must be > 0"),
    ('stiffness = 9e5', 'stiffness = 9e5\nlength = 1.0', "train.shafts.mid.length: unknown key"),
    ('[train.gears.g2]\ninertia = 0.35', '[train.gears.g2]\nname = "x"\ninertia = 0.35',
     "train.gears.g2.name"),
    ('teeth = 61\nmodule = "3 mm"', 'teeth = 61\nmodule = "3.5 mm"',
     "train.meshes.stage1.wheel.module: differs from the pinion's"),
    ('stiffness = "iso"', 'stiffness = "iso"\ncentre_distance = "140 mm"',
     "train.meshes.stage1.centre_distance"),
    ('stiffness = 1e5', 'stiffness = -1e5', "train.shafts.brake.stiffness: must be > 0"),
    ('[train.inertias.load]', '[train.gears.idler]\ninertia = 1.0\nbase_radius = 0.1\n'
                              '[train.inertias.load]', "train.gears.idler: is on no shaft"),
    ('b = "g2"\nstiffness = "iso"', 'b = "g9"\nstiffness = "iso"',
     "train.meshes.stage1.b: names no body"),
    ('rayleigh = [0.5, 1e-6]', 'rayleigh = [0.5, 1e-6]\ngearbox = true', "train.gearbox"),
    ('[train.meshes.stage1]', '[train.meshes.b1]', "train.meshes.b1: the name is used twice"),
])
def test_bad_train_tables_name_the_table_and_field(old, new, where):
    with pytest.raises(ValidationError) as err:
        load_study(_bad(TWO_STAGE, old, new))
    assert where in format_error(err.value)


def test_free_train_is_refused_unless_free():
    """No shaft to ground and nothing fixed: a free rigid-body mode, refused naming ``fixed``,
    kept with ``free = true``."""
    text = _bad(_bad(TWO_STAGE, '[train.shafts.brake]\na = "load"\nb = "ground"\n'
                                'stiffness = 1e5\n', ''),
                '[train.shafts.input]\na = "g1"\nb = "ground"\nstiffness = "4e4 N m"\n'
                'damping = 2.0\n', '')
    with pytest.raises(ValidationError) as err:
        load_study(text)
    assert "train.fixed: the train has 1 free rigid-body mode" in format_error(err.value)
    free = load_study(_bad(text, 'driven = "g1"', 'driven = "g1"\nfree = true')).gear_train
    assert free.rigid_body_modes == 1


@pytest.mark.parametrize(("old", "new", "where"), [
    ('planet = "planet"', 'planet = "moon"', "train.planetary.stage1.planet: names no gear"),
    ('n_planets = 4', 'n_planets = 0', "train.planetary.stage1.n_planets: must be a whole"),
    ('n_planets = 4', 'n_planets = 4\nspacing = 1', "train.planetary.stage1.spacing: unknown"),
    ('planet_angles = ["0 deg", "92 deg", "180 deg", "268 deg"]', 'planet_angles = ["0 deg"]',
     "train.planetary.stage1.planet_angles: needs 4 angles"),
])
def test_bad_planetary_tables_name_the_stage_and_field(old, new, where):
    with pytest.raises(ValidationError) as err:
        load_study(_bad(PLANETARY, old, new))
    assert where in format_error(err.value)


# ---------------------------------------------------------------- geardyn modes
def run(capsys, *args) -> subprocess.CompletedProcess:
    """``geardyn ARGS`` in this process (the console script's code path)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in args])
    out = capsys.readouterr()
    return subprocess.CompletedProcess(args, info.value.code, out.out, out.err)


def test_modes_command_writes_what_the_api_computes(tmp_path, capsys):
    study = tmp_path / "two_stage.toml"
    study.write_text(TWO_STAGE, encoding="utf-8")
    out, shares, campbell = tmp_path / "m.nc", tmp_path / "s.png", tmp_path / "c.svg"
    r = run(capsys, "modes", study, "-o", out, "--plot", shares, "--speed", "0..50 Hz",
            "--points", 101, "--harmonics", 2, "--campbell", campbell)
    assert r.returncode == 0, r.stderr
    train = _two_stage_by_api()
    modes, cds = train.modes(), train.campbell(np.linspace(0.0, 3000.0, 101), harmonics=2)
    written = load_dataset(out)
    for name in ("frequency", "shape", "energy_share", "multiplicity"):
        assert written[name].values.tobytes() == modes[name].values.tobytes(), name
    for name in ("crossing_speed", "excitation_frequency"):
        np.testing.assert_allclose(written[name].values, cds[name].values, rtol=1e-12)
    assert written.attrs["study"] == "two_stage"
    assert shares.stat().st_size > 0 and campbell.stat().st_size > 0
    for f in modes["frequency"].values:
        assert f"{f:.6g}" in r.stdout
    n = int(np.isfinite(cds["crossing_speed"].values).sum())
    assert f"{n} crossings" in r.stdout


def test_modes_command_runs_a_study_without_outputs(tmp_path, capsys):
    study = tmp_path / "planetary.toml"
    study.write_text(PLANETARY, encoding="utf-8")
    r = run(capsys, "modes", study)
    assert r.returncode == 0, r.stderr
    assert "rotational" in r.stdout and "nothing written" in r.stdout


@pytest.mark.parametrize(("args", "fragments"), [
    (("stiffness_19_48",), ("STUDY", "has no [train] table")),
    (("{study}", "--campbell", "c.png"), ("--campbell", "needs the speed range")),
    (("{study}", "--speed", "0-50 rpm"), ("--speed", "A..B UNIT")),
    (("{study}", "--speed", "50..0 rpm"), ("--speed", "from a speed >= 0")),
    (("{study}", "--speed", "0..50 1/s"), ("--speed",)),
    (("{study}", "-o", "m.txt"), ("--out", ".nc")),
    (("{study}", "--harmonics", "2"), ("--harmonics", "needs the speed range")),
    (("{study}", "--speed", "0..50 rpm", "--harmonics", "0"), ("--harmonics", "1..100")),
    (("{study}", "--speed", "0..50 rpm", "--points", "1"), ("--points", "2..")),
])
def test_modes_command_errors_are_one_line(tmp_path, capsys, args, fragments):
    study = tmp_path / "two_stage.toml"
    study.write_text(TWO_STAGE, encoding="utf-8")
    r = run(capsys, "modes", *(str(a).format(study=study) for a in args))
    assert_one_line_error(r, *fragments)


def test_campbell_without_an_input_body_is_refused_naming_train_driven(tmp_path, capsys):
    study = tmp_path / "undriven.toml"
    study.write_text(_bad(TWO_STAGE, 'driven = "g1"\n', ""), encoding="utf-8")
    assert run(capsys, "modes", study).returncode == 0
    r = run(capsys, "modes", study, "--speed", "0..10 Hz")
    assert_one_line_error(r, "train.driven", "needs the input body")


def test_modes_command_refuses_a_bad_train_in_one_line(tmp_path, capsys):
    study = tmp_path / "bad.toml"
    study.write_text(_bad(TWO_STAGE, 'stiffness = 1e5', 'stiffness = -1e5'), encoding="utf-8")
    r = run(capsys, "modes", study)
    assert_one_line_error(r, "train.shafts.brake.stiffness")


def test_docs_train_table_reads():
    """The [train] example of docs/trains.md is a valid study."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "trains.md").read_text("utf-8")
    block = re.search(r"```toml\n(.*?)```", text, re.S)
    assert block is not None
    train = load_study(block.group(1)).gear_train
    assert train.mesh_data["stage1"].method == "iso" and train.driven == "g1"


def test_campbell_plot_draws_one_ray_per_order_and_harmonic(tmp_path):
    """A planetary stage's sun and ring meshes share their order: one ray each harmonic,
    labelled with the meshes it stands for; every crossing still marked."""
    from geardyn.plotting.campbell import plot_campbell

    train = load_study(PLANETARY).gear_train
    ds = train.campbell(np.linspace(0.0, 3000.0, 31), harmonics=2)
    fig = plot_campbell(ds)
    rays = [ln for ln in fig.axes[0].lines if len(ln.get_xdata()) == ds.sizes["speed"]]
    orders = sorted({round(float(o), 9) for o in ds["order"].values})
    assert len(ds["order"]) == 16 and len(orders) == 2 and len(rays) == 4
    labels = [ln.get_label() for ln in rays if not ln.get_label().startswith("_")]
    assert labels == [f"sun_planet1 and 3 more (order {orders[0]:.4g})",
                      f"planet1_ring and 3 more (order {orders[1]:.4g})"]
    marks = [ln for ln in fig.axes[0].lines if ln.get_label() == "crossing"][0]
    assert len(marks.get_xdata()) == int(np.isfinite(ds["crossing_speed"].values).sum())
