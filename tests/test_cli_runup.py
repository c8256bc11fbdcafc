"""``geardyn runup``: the study's [runup] table and the options, what it writes (the API's
run-up, bit for bit), ``geardyn plot`` of the result, and errors naming the field."""

from __future__ import annotations

import numpy as np
import pytest

import geardyn
from geardyn.analysis.runup import RunupSettings, runup
from geardyn.io.netcdf import load_dataset
from geardyn.testing import assert_result
from test_cli import invoke

PNG = b"\x89PNG\r\n\x1a\n"
STUDY = """[study]
name = "gp_runup"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.2
Fm = 0.1
Fa = 0.05
[runup]
start = 0.4
stop = 1.6
rate = 4e-3
sample_rate = 4.0
outputs = ["x", "F"]
"""


@pytest.fixture
def study(tmp_path):
    path = tmp_path / "gp.toml"
    path.write_text(STUDY)
    return path


def test_runup_writes_what_the_api_computes(tmp_path, study):
    nc, png, om = tmp_path / "o" / "r.nc", tmp_path / "o" / "r.png", tmp_path / "o" / "m.pdf"
    r = invoke("runup", study, "--quiet", "--out", nc, "--plot", png, "--order-map", om)
    assert r.returncode == 0, r.stderr
    assert "gp_runup: run-up of Omega 0.4 -> 1.6" in r.stdout and ", ok," in r.stdout
    ds = load_dataset(nc)
    assert_result(ds, "runup")
    api = runup(geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.05),
                RunupSettings(start=0.4, stop=1.6, rate=4e-3, sample_rate=4.0,
                              outputs=("x", "F")))
    np.testing.assert_array_equal(ds["x"].values, api["x"].values)
    assert "v" not in ds and ds.attrs["study"] == "gp_runup"
    assert png.read_bytes()[:8] == PNG and om.read_bytes()[:5] == b"%PDF-"
    again = tmp_path / "again.png"
    r = invoke("plot", nc, "--out", again)
    assert r.returncode == 0 and "run-up dataset (F)" in r.stdout
    assert again.read_bytes()[:8] == PNG


def test_options_override_the_table(tmp_path, study):
    nc = tmp_path / "r.nc"
    r = invoke("runup", study, "--start", "1.5", "--stop", "0.5", "--duration", "100",
               "--outputs", "v", "--quiet", "--out", nc)
    assert r.returncode == 0, r.stderr
    ds = load_dataset(nc)
    assert list(ds.attrs["outputs"].split(",")) == ["v"]
    assert ds["Omega"].values[0] == 1.5 and ds.attrs["ramp_duration"] == 100.0


def test_input_speed_of_a_planetary_study_is_ramped_in_rpm(tmp_path):
    nc = tmp_path / "p.nc"
    r = invoke("runup", "planetary_example", "--param", "input_speed", "--start", "2000",
               "--stop", "4000", "--duration", "200", "--outputs", "F_s1", "--quiet",
               "--out", nc)
    assert r.returncode == 0, r.stderr
    ds = load_dataset(nc)
    np.testing.assert_allclose(ds["input_speed"].values[[0, -1]], [2000.0, 4000.0], rtol=1e-9)
    assert "mesh_frequency" in ds.coords and ds["mesh_frequency"].attrs["units"] == "Hz"


@pytest.mark.parametrize("args,message", [
    (("--rate", "-1"), "--rate: must be > 0"),
    (("--output", "q"), "--output: not a recorded output"),
    (("--steps-per-period", "4"), "--steps-per-period: must be an integer >= 8"),
    (("--param", "Lambda"), "--param: GearPair has no such parameter"),
    (("--plot", "x.gif"), "--plot: suffix must be one of"),
    (("--harmonics", "0"), "--harmonics: must be an integer from 1 to 40"),
])
def test_bad_options_name_the_option(study, args, message):
    r = invoke("runup", study, "--quiet", *args)
    assert r.returncode == 2 and message in r.stderr, r.stderr


@pytest.mark.parametrize("table,message", [
    ("start = 0.5\nstop = 1.0\nrat = 3\n", "runup.rat: unknown key"),
    ("start = 0.5\nstop = 1.0\nrate = 3\nduration = 4\n",
     "runup: give exactly one of rate and duration"),
    ("start = 0.5\nstop = 0.5\nrate = 3\n", "runup: start and stop must differ"),
    ("start = -0.5\nstop = 1.0\nrate = 3\n", "runup.start: Input should be greater than"),
    ("start = 0.5\nstop = 1.0\nrate = 3\nsteps_per_period = 2\n",
     "runup.steps_per_period: Input should be greater than or equal to 8"),
])
def test_bad_tables_name_the_field(tmp_path, table, message):
    path = tmp_path / "bad.toml"
    path.write_text('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.05\n[runup]\n' + table)
    r = invoke("runup", path, "--quiet")
    assert r.returncode == 2 and message in r.stderr, r.stderr


def test_without_a_table_the_range_is_asked_for(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.05\n')
    r = invoke("runup", path, "--quiet")
    assert r.returncode == 2 and "--start: not given, and the study has no [runup]" in r.stderr


def test_a_train_with_a_non_whole_stage_ratio_runs_up_in_rpm(tmp_path):
    out = tmp_path / "train.nc"
    r = invoke("runup", "two_stage_train", "--param", "input_speed", "--start", "1000",
               "--stop", "1100", "--duration", "20", "--outputs", "F_stage1,F_stage2",
               "--quiet", "--out", out)
    assert r.returncode == 0, r.stderr
    from geardyn.io.netcdf import load_dataset

    ds = load_dataset(out)
    assert np.all(np.isfinite(ds["F_stage2"].values)) and ds.attrs["status"] == 0
