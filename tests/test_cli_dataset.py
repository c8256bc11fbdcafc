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
