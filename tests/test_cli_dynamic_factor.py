"""``geardyn dynamic-factor``: the command writes what geardyn.dynamic_factor_sweep computes for
the study's model, draws it, and refuses bad input with one line naming the option or field."""

from __future__ import annotations

import numpy as np

import geardyn
from geardyn.io.netcdf import load_dataset
from geardyn.io.toml import builtin_study
from test_cli import assert_one_line_error, geardyn_here


def test_writes_the_sweep_and_its_figure(capsys, tmp_path):
    out, fig = tmp_path / "df.nc", tmp_path / "df.png"
    r = geardyn_here(capsys, "dynamic-factor", "spur_pair_cracked", "--f-pb", 9, "--f-falpha",
                     8, "--y-alpha", 0.7, "--range", "12000:24000:4", "--torque", 20,
                     "--torque", 80, "--transient", 0.02, "--samples", 8, "--out", out,
                     "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert "N_M" in r.stdout and fig.stat().st_size > 0
    written = load_dataset(out)
    model = geardyn.build_model(builtin_study("spur_pair_cracked"))
    ds = geardyn.dynamic_factor_sweep(
        model, np.linspace(12000, 24000, 4), [20.0, 80.0],
        geardyn.RunSettings(transient=0.02, samples=8), base_pitch_deviation=9.0,
        profile_form_deviation=8.0, pitch_running_in=0.7, profile_running_in=0.7)
    for name in ("dynamic_factor", "K_v", "resonance_speed", "iso_range"):
        np.testing.assert_array_equal(written[name].values, ds[name].values)
    assert written.attrs["geardyn_kind"] == "dynamic-factor"
    redrawn = tmp_path / "again.png"
    r = geardyn_here(capsys, "plot", out, "--out", redrawn)
    assert r.returncode == 0, r.stderr
    assert "dynamic factor dataset" in r.stdout and redrawn.stat().st_size > 0


def test_bad_input_is_one_line(capsys):
    r = geardyn_here(capsys, "dynamic-factor", "spur_pair_cracked", "--f-pb", 9, "--f-falpha",
                     8, "--stiffness", "fem", "--range", "12000:24000:2")
    assert_one_line_error(r, "stiffness")
    r = geardyn_here(capsys, "dynamic-factor", "spur_pair_cracked", "--f-pb", -1, "--f-falpha",
                     8, "--range", "12000:24000:2")
    assert_one_line_error(r, "base_pitch_deviation")
    r = geardyn_here(capsys, "dynamic-factor", "paper_fig3", "--f-pb", 9, "--f-falpha", 8,
                     "--range", "1000:2000:2")
    assert_one_line_error(r, "geometry")


def test_a_train_study_gives_one_group_per_stage(capsys, tmp_path):
    out = tmp_path / "train.nc"
    r = geardyn_here(capsys, "dynamic-factor", "two_stage_train", "--f-pb", 9, "--f-falpha",
                     8, "--range", "1000:2000:2", "--transient", 200, "--samples", 8,
                     "--out", out)
    assert r.returncode == 0, r.stderr
    written = load_dataset(out)
    assert list(written["group"].values) == ["stage1", "stage2"]
    ds = geardyn.dynamic_factor_sweep(
        geardyn.build_model(builtin_study("two_stage_train")), [1000.0, 2000.0], None,
        geardyn.RunSettings(transient=200.0, samples=8), base_pitch_deviation=9.0,
        profile_form_deviation=8.0)
    np.testing.assert_array_equal(written["dynamic_factor"].values, ds["dynamic_factor"].values)
    assert "stage2" in r.stdout
