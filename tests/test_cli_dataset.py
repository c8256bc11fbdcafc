"""``geardyn dataset``: the study's [dataset] table gives the spec of geardyn.fault_dataset (the
store holds what the API computes, bit for bit, with the labels); a run killed after its first
chunk and rerun gives the bits of one uninterrupted run; bad input names the field."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.execution.zarr_store import LaneStore
from geardyn.gears import GearMesh, RootCrack, SpurGear
from test_cli import invoke

GEARS = """[study]
name = "tiny_dataset"
model = "spur_pair"
[gears]
module = "3.2 mm"
pressure_angle = "20 deg"
face_width = "16 mm"
[gears.pinion]
teeth = 19
bore_radius = "12 mm"
[gears.wheel]
teeth = 48
bore_radius = "35 mm"
[stiffness]
angles = 32
[params]
speed = 1000.0
speed_unit = "rpm"
torque = "50 N m"
inertia = [4.3659e-4, 8.3602e-3]
backlash = "10 um"
stiffness_form = "table"
"""
DATASET = """[dataset]
speeds = [1000.0, 2000.0]
torques = [40.0]
seeds = 2
snr_db = 10.0
duration = 0.01
sample_rate = 20000.0
steps_per_mode = 50
chunk = 1
workers = 1
[[dataset.faults]]
kind = "healthy"
[[dataset.faults]]
kind = "crack"
gear = "pinion"
tooth = 2
depth = "1.5 mm"
"""


@pytest.fixture
def study(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(GEARS + DATASET)
    return path


def api_dataset() -> xr.Dataset:
    """The same dataset by the Python API."""
    mesh = GearMesh(SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                    SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))

    def build(faults):
        return geardyn.SpurPair.from_geometry(
            mesh, bore_radius=(0.012, 0.035), angles=32, speed=1000.0, speed_unit="rpm",
            torque=50.0, inertia=(4.3659e-4, 8.3602e-3), backlash=10e-6, faults=faults,
            stiffness_form="table")

    spec = geardyn.FaultDatasetSpec(build, [None, RootCrack("1.5 mm", tooth=2)],
                                    speeds=[1000.0, 2000.0], torques=[40.0], seeds=[0, 1],
                                    snr_db=10.0, duration=0.01, sample_rate=20000.0,
                                    steps_per_mode=50, chunk=1)
    return geardyn.fault_dataset(spec, workers=1)


def test_the_store_opens_with_the_labels_and_holds_what_the_api_computes(tmp_path, study):
    store = tmp_path / "out" / "d.zarr"
    r = invoke("dataset", study, "--quiet", "--store", store)
    assert r.returncode == 0, r.stderr
    assert "tiny_dataset: 4 conditions, 8 signals of 0.01 s at 20000 Hz, diverged 0" in r.stdout
    ds = xr.open_zarr(store)
    assert ds.sizes == {"fault": 2, "speed": 2, "torque": 1, "seed": 2, "time": 200}
    assert [str(k) for k in ds["fault_kind"].values] == ["healthy", "crack"]
    assert ds["fault_tooth"].values.tolist() == [-1, 2]
    assert ds["speed"].values.tolist() == [1000.0, 2000.0]
    assert ds.attrs["snr_db"] == 10.0 and ds.attrs["steps_per_mode"] == 50.0
    api = api_dataset()
    for name in ("signal", "status", "noise_std"):
        np.testing.assert_array_equal(ds[name].values, api[name].values)


def test_a_killed_run_rerun_gives_the_bits_of_one_run(tmp_path, study, monkeypatch):
    whole = tmp_path / "whole.zarr"
    assert invoke("dataset", study, "-q", "--store", whole).returncode == 0
    killed = tmp_path / "killed.zarr"
    write = LaneStore.write_chunk
    calls = []

    def kill_after_first(self, *args, **kw):
        if calls:
            raise KeyboardInterrupt
        calls.append(1)
        return write(self, *args, **kw)

    monkeypatch.setattr(LaneStore, "write_chunk", kill_after_first)
    r = invoke("dataset", study, "-q", "--store", killed)  # click: KeyboardInterrupt -> exit 1
    assert r.returncode != 0 and calls == [1]
    monkeypatch.setattr(LaneStore, "write_chunk", write)
    r = invoke("dataset", study, "-q", "--store", killed)
    assert r.returncode == 0, r.stderr
    assert LaneStore(killed).chunk_runs().tolist() == [1, 2, 2, 2]  # the first not recomputed
    a, b = xr.open_zarr(whole).load(), xr.open_zarr(killed).load()
    for name in a.data_vars:
        np.testing.assert_array_equal(a[name].values, b[name].values)


@pytest.mark.parametrize(("change", "field"), [
    ("torques = []", "dataset.torques"),
    ("duration = -1.0", "dataset.duration"),
    ("snr_db = \"loud\"", "dataset.snr_db"),
    ("colour = 3", "dataset.colour"),
    ("steps_per_period = 2000", "dataset"),  # with steps_per_mode: one of them
])
def test_bad_dataset_fields_are_named(tmp_path, change, field):
    key = change.split(" = ")[0]
    text = "\n".join(line for line in DATASET.splitlines()
                     if not line.startswith(key + " ")).replace(
        "[dataset]\n", f"[dataset]\n{change}\n")
    path = tmp_path / "bad.toml"
    path.write_text(GEARS + text)
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2
    assert f"error: {field}" in r.stderr


def test_a_fault_the_gears_refuse_names_its_table(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(GEARS + DATASET.replace("tooth = 2", "tooth = 19"))
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2
    assert "error: dataset.faults[1].tooth" in r.stderr


def test_a_study_without_a_store_or_a_dataset_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(GEARS)
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2 and "no [dataset] table" in r.stderr
    path.write_text(GEARS + DATASET)
    r = invoke("dataset", path, "-q")
    assert r.returncode == 2 and "error: --store" in r.stderr


# ---------------------------------------------------------------------------------------------
# a planetary study: the ring sensor's dataset of the stage built from [params.geometry]

PLANETARY = """[study]
name = "tiny_planetary_dataset"
model = "planetary"
[params]
n_planets = 4
sun_backlash = "10 um"
ring_backlash = "10 um"
mesh_damping = 0.03
modal_damping = 0.02
sun_torque = "20 N m"
harmonics = 15
[params.geometry]
module = "2 mm"
pressure_angle = "20 deg"
face_width = "20 mm"
stiffness = "potential_energy"
[params.geometry.stiffness_options]
sun_bore_radius = "12 mm"
planet_bore_radius = "10 mm"
ring_rim_radius = "85 mm"
angles = 32
[params.geometry.sun]
teeth = 25
[params.geometry.planet]
teeth = 23
[params.geometry.ring]
teeth = 71
[params.sun]
mass = 0.31
inertia_over_r2 = 0.17
bearing_stiffness = 1e8
[params.planet]
mass = 0.26
inertia_over_r2 = 0.15
bearing_stiffness = 1e8
[params.ring]
mass = 0.67
inertia_over_r2 = 0.86
bearing_stiffness = 1e8
torsional_stiffness = 1e9
[params.carrier]
mass = 1.5
inertia_over_r2 = 1.0
bearing_stiffness = 1e8
torsional_stiffness = 1e9
"""
PLANETARY_DATASET = """[dataset]
speeds = [3000.0]
torques = [30.0]
seeds = [0, 5]
snr_db = 20.0
duration = 0.004
sample_rate = 20000.0
chunk = 1
workers = 1
sensor = { width = 1.5707963267948966 }  # pi / 2 (a unit string rounds to 15 digits)
[[dataset.faults]]
kind = "crack"
gear = "sun"
tooth = 0
depth = "0 mm"
[[dataset.faults]]
kind = "crack"
gear = "sun"
tooth = 0
depth = "1.5 mm"
"""


def planetary_api_dataset() -> xr.Dataset:
    """The same dataset by the Python API: the stage built by hand
    (tests/planetary_example_set.py, not through the study loader)."""
    import math
    import tomllib
    from importlib.resources import files

    from planetary_example_set import planetary_by_hand

    doc = tomllib.loads(files("geardyn.studies").joinpath("planetary_example.toml").read_text())

    def build(faults):
        return planetary_by_hand(doc, stiffness="potential_energy", faults=faults,
                                 stiffness_options=dict(sun_bore_radius="12 mm",
                                                        planet_bore_radius="10 mm",
                                                        ring_rim_radius="85 mm", angles=32))

    faults = [RootCrack("0 mm", gear="sun"), RootCrack("1.5 mm", gear="sun")]
    spec = geardyn.FaultDatasetSpec(build, faults, speeds=[3000.0], torques=[30.0],
                                    seeds=[0, 5], snr_db=20.0, duration=0.004,
                                    sample_rate=20000.0, chunk=1,
                                    sensor={"width": math.pi / 2})
    return geardyn.fault_dataset(spec, workers=1)


def test_a_planetary_study_gives_the_ring_sensor_dataset_the_api_computes(tmp_path):
    """Two conditions (a zero-size and a 1.5 mm sun crack: the same forcing period) of the
    example stage on its potential-energy stiffness, the conditions' faults in place of
    [[params.geometry.faults]]: the store holds the labels and, bit for bit, the dataset of
    the stage built by hand through the API (which tests/test_fault_dataset.py checks against
    geardyn.simulate and the ring sensor signal)."""
    study = tmp_path / "planetary.toml"
    study.write_text(PLANETARY + PLANETARY_DATASET)
    store = tmp_path / "p.zarr"
    r = invoke("dataset", study, "-q", "--store", store)
    assert r.returncode == 0, r.stderr
    assert "tiny_planetary_dataset: 2 conditions, 4 signals of 0.004 s" in r.stdout
    ds = xr.open_zarr(store).load()
    assert ds.sizes == {"fault": 2, "speed": 1, "torque": 1, "seed": 2, "time": 80}
    assert [str(k) for k in ds["fault_kind"].values] == ["crack", "crack"]
    assert [str(g) for g in ds["fault_gear"].values] == ["sun", "sun"]
    assert ds["fault_size"].values.tolist() == [0.0, 1.5e-3]
    assert ds.attrs["speed_input"] == "input_speed" and ds["speed"].attrs["units"] == "rpm"
    assert ds.attrs["torque_input"] == "sun_torque" and ds.attrs["signal"] == "ring_sensor"
    assert (ds["status"].values == 0).all()
    api = planetary_api_dataset()
    for name in ("signal", "status", "noise_std"):
        np.testing.assert_array_equal(ds[name].values, api[name].values)
    assert not np.array_equal(ds["signal"].values[0], ds["signal"].values[1])  # the crack


def test_a_killed_planetary_run_resumes_to_the_bits_of_one_run(tmp_path, monkeypatch):
    path = tmp_path / "planetary.toml"
    path.write_text(PLANETARY + PLANETARY_DATASET)
    whole = tmp_path / "whole.zarr"
    assert invoke("dataset", path, "-q", "--store", whole).returncode == 0
    killed = tmp_path / "killed.zarr"
    write = LaneStore.write_chunk

    def kill_after_first(self, *args, **kw):
        monkeypatch.setattr(LaneStore, "write_chunk", _raise_interrupt)
        return write(self, *args, **kw)

    monkeypatch.setattr(LaneStore, "write_chunk", kill_after_first)
    assert invoke("dataset", path, "-q", "--store", killed).returncode != 0
    monkeypatch.setattr(LaneStore, "write_chunk", write)
    assert invoke("dataset", path, "-q", "--store", killed).returncode == 0
    assert LaneStore(killed).chunk_runs().tolist() == [1, 2]  # the first not recomputed
    a, b = xr.open_zarr(whole).load(), xr.open_zarr(killed).load()
    for name in a.data_vars:
        np.testing.assert_array_equal(a[name].values, b[name].values)


def _raise_interrupt(*args, **kw):
    raise KeyboardInterrupt


@pytest.mark.parametrize(("change", "field"), [
    (("gear = \"sun\"\ntooth = 0\ndepth = \"1.5 mm\"",
      "gear = \"planet9\"\ntooth = 0\ndepth = \"1.5 mm\""), "dataset.faults[1].gear"),
    (("width = 1.5707963267948966", "width = \"-1 deg\""), "dataset.sensor.width"),
    (("width = 1.5707963267948966", "mesh = \"s1\""), "dataset.sensor.mesh"),
])
def test_bad_planetary_dataset_input_names_the_field(tmp_path, change, field):
    path = tmp_path / "bad.toml"
    path.write_text(PLANETARY + PLANETARY_DATASET.replace(*change))
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2, r.stderr
    assert f"error: {field}" in r.stderr


def test_a_planetary_study_without_geometry_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    text = PLANETARY.split("[params.geometry]")[0] + (
        "sun_mesh_stiffness = 5e8\nring_mesh_stiffness = 5e8\n"
        + PLANETARY.split("teeth = 71\n")[1] + PLANETARY_DATASET)
    path.write_text(text)
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2 and "[params.geometry]" in r.stderr


# ---------------------------------------------------------------------------------------------
# a train study: the mesh force of the two-stage train with a cracked input pinion


def train_study_text(depth: str | None = None) -> str:
    """The shipped two_stage_train on the potential-energy stiffness (as
    tests/test_trains_faults.py builds it); with ``depth``, its own [[train.faults]]: a crack
    of that depth on g1's tooth 3."""
    from importlib.resources import files

    text = files("geardyn.studies").joinpath("two_stage_train.toml").read_text()
    text = text.replace('stiffness = "iso"', 'stiffness = "potential_energy"\n'
                        'bore_radius = "10 mm"').replace("stiffness_fluctuation = 0.25\n", "")
    if depth is not None:
        text += (f'\n[[train.faults]]\nkind = "crack"\ngear = "g1"\ntooth = 3\n'
                 f'depth = "{depth}"\nangle = "45 deg"\n')
    return text


TRAIN_DATASET = """
[dataset]
speeds = [3000.0]
torques = [40.0, 60.0]
seeds = 1
snr_db = 20.0
duration = 0.003
sample_rate = 20000.0
chunk = 1
workers = 1
sensor = { mesh = "stage2" }
[[dataset.faults]]
kind = "crack"
gear = "g1"
tooth = 3
depth = "0 mm"
angle = "45 deg"
[[dataset.faults]]
kind = "crack"
gear = "g1"
tooth = 3
depth = "2 mm"
angle = "45 deg"
"""


def test_a_train_study_gives_the_mesh_force_dataset_of_its_own_faults(tmp_path):
    """Two conditions (a zero-size and a 2 mm crack on g1) x two input torques: the store holds
    the labels and, bit for bit, the API's dataset of the models that study files with those
    faults in their own [[train.faults]] give (geardyn.study.build_model)."""
    from geardyn.io.toml import load_study
    from geardyn.study import build_model

    path = tmp_path / "train.toml"
    path.write_text(train_study_text() + TRAIN_DATASET)
    store = tmp_path / "t.zarr"
    r = invoke("dataset", path, "-q", "--store", store)
    assert r.returncode == 0, r.stderr
    ds = xr.open_zarr(store).load()
    assert ds.sizes == {"fault": 2, "speed": 1, "torque": 2, "seed": 1, "time": 60}
    assert ds["fault_size"].values.tolist() == [0.0, 2e-3]
    assert [str(g) for g in ds["fault_gear"].values] == ["g1", "g1"]
    assert ds.attrs["torque_input"] == "input_torque" and ds["speed"].attrs["units"] == "rpm"
    assert ds["signal"].attrs["meaning"] == "dynamic mesh force F_stage2"
    assert (ds["status"].values == 0).all()
    studies = {}
    for depth in ("0 mm", "2 mm"):
        own = tmp_path / f"own_{depth.split()[0]}.toml"
        own.write_text(train_study_text(depth))
        studies[depth] = load_study(own)
    faults = [RootCrack(depth, gear="g1", tooth=3, angle="45 deg") for depth in studies]
    spec = geardyn.FaultDatasetSpec(
        lambda f: build_model(studies["0 mm" if f[0].depth == 0.0 else "2 mm"]), faults,
        speeds=[3000.0], torques=[40.0, 60.0], seeds=[0], snr_db=20.0, duration=0.003,
        sample_rate=20000.0, chunk=1, sensor={"mesh": "stage2"})
    api = geardyn.fault_dataset(spec, workers=1)
    for name in ("signal", "status", "noise_std"):
        np.testing.assert_array_equal(ds[name].values, api[name].values)


@pytest.mark.parametrize(("change", "field"), [
    (("tooth = 3\ndepth = \"2 mm\"", "tooth = 30\ndepth = \"2 mm\""), "dataset.faults[1].tooth"),
    (("gear = \"g1\"\ntooth = 3\ndepth = \"2 mm\"", "gear = \"g9\"\ntooth = 3\ndepth = \"2 mm\""),
     "dataset.faults[1].gear"),
    (("mesh = \"stage2\"", "mesh = \"stage3\""), "dataset.sensor.mesh"),
])
def test_bad_train_dataset_input_names_the_field(tmp_path, change, field):
    path = tmp_path / "bad.toml"
    path.write_text(train_study_text() + TRAIN_DATASET.replace(*change))
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2, r.stderr
    assert f"error: {field}" in r.stderr


def test_a_train_without_an_input_torque_is_refused_saying_so(tmp_path):
    path = tmp_path / "free.toml"
    text = train_study_text().replace('torques = { g1 = "60 N m" }\nload = "g4"\n', "")
    assert "\ntorques" not in text
    path.write_text(text + TRAIN_DATASET)
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2
    assert "its model (TrainModel) lacks what a fault dataset needs" in r.stderr
    assert "'input_torque'" in r.stderr


def test_a_study_of_another_model_is_refused_naming_the_ones_taken(tmp_path):
    from importlib.resources import files

    path = tmp_path / "fig3.toml"
    path.write_text(files("geardyn.studies").joinpath("paper_fig3.toml").read_text() + DATASET)
    r = invoke("dataset", path, "-q", "--store", tmp_path / "x.zarr")
    assert r.returncode == 2
    assert "takes a spur_pair, planetary or train study" in r.stderr
