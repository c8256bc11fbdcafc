"""The ``geardyn`` command line, run in a subprocess as a user would."""

from __future__ import annotations

import contextlib
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from geardyn import GearPair, PlanetaryParams, RunSettings, bifurcation, simulate
from geardyn.cli import bifurcation as cli_bifurcation
from geardyn.cli.main import app, main
from geardyn.io.netcdf import load_dataset, save_dataset
from geardyn.io.toml import builtin_study, load_study, paper_study, study_to_toml
from geardyn.study import build_model
from geardyn.testing import assert_result


def _command(*args) -> list[str]:
    return [sys.executable, "-m", "geardyn.cli.main", *map(str, args)]


def geardyn(*args, cwd=None) -> subprocess.CompletedProcess:
    """Run the command line in a subprocess, as a user would."""
    return subprocess.run(_command(*args), capture_output=True, text=True, cwd=cwd, timeout=180)


def geardyn_many(*calls: tuple) -> list[subprocess.CompletedProcess]:
    """Run several command lines concurrently (each ~2 s of start-up, mostly imports)."""
    procs = [
        (c, subprocess.Popen(_command(*c), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True))
        for c in calls
    ]
    out = []
    for c, p in procs:
        stdout, stderr = p.communicate(timeout=180)
        out.append(subprocess.CompletedProcess(c, p.returncode, stdout, stderr))
    return out


def geardyn_here(capsys, *args) -> subprocess.CompletedProcess:
    """Run ``main()`` in this process (fast; same code path as the console script)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in args])
    captured = capsys.readouterr()
    return subprocess.CompletedProcess(args, info.value.code, captured.out, captured.err)


def assert_one_line_error(result: subprocess.CompletedProcess, *fragments: str) -> str:
    assert result.returncode == 2, (result.stdout, result.stderr)
    err = result.stderr.strip()
    assert "Traceback" not in result.stderr
    assert len(err.splitlines()) == 1, err
    assert err.startswith("error: "), err
    for fragment in fragments:
        assert fragment in err, err
    return err


def test_help_and_version(capsys):
    r = geardyn_here(capsys, "--help")
    assert r.returncode == 0, r.stderr
    assert "simulate" in r.stdout and "params" in r.stdout
    assert "bifurcation" in r.stdout and "plot" in r.stdout
    r = geardyn_here(capsys, "--version")
    assert r.returncode == 0 and r.stdout.strip() == "geardyn 0.1.0"
    r = geardyn_here(capsys, "params", "--help")
    assert r.returncode == 0 and "show" in r.stdout and "save" in r.stdout


def test_params_save_writes_loadable_template(tmp_path, capsys):
    out = tmp_path / "paper.toml"
    r = geardyn_here(capsys, "params", "save", out)
    assert r.returncode == 0, r.stderr
    assert load_study(out).planetary_params == PlanetaryParams.paper()
    assert "sun_mesh" in tomllib.loads(out.read_text())["params"]
    assert_one_line_error(geardyn_here(capsys, "params", "save", out), "exists")


TEMPLATE = study_to_toml(paper_study())

BAD_STUDIES = {
    "negative-stiffness": ("mean_stiffness = 825000000.0", "mean_stiffness = -1.0",
                           ("params.sun_mesh.mean_stiffness", "-1.0")),
    "unknown-key": ("[params.carrier]\n", "[params.carrier]\nfriction = 0.2\n",
                    ("params.carrier.friction", "unknown key", "0.2")),
    "nan": ("inertia = 0.00758", "inertia = nan", ("params.carrier.inertia", "nan")),
    "wrong-unit": ("r_c2 = 0.21", 'r_c2 = "210 kg"', ("params.carrier.r_c2", "210 kg")),
    "bad-choice": ('interpretation = "consistent"', 'interpretation = "printed"',
                   ("study.interpretation", "printed")),
    "toml-syntax": ("[params]", "[params", ("invalid TOML", "line")),
    "zero-planets": ("n_planets = 4", "n_planets = 0", ("params.n_planets", "0")),
}


def _bad_study(tmp_path, case: str):
    old, new, fragments = BAD_STUDIES[case]
    assert old in TEMPLATE, old
    path = tmp_path / f"{case}.toml"
    path.write_text(TEMPLATE.replace(old, new, 1))
    return path, fragments


def test_bad_study_in_subprocess_is_one_line_error(tmp_path):
    """Each command that loads a study, in a process of its own (every process imports geardyn,
    ~5 s CPU); every bad study through both commands in this process:
    test_bad_study_is_one_line_error."""
    cases = ["negative-stiffness", "nan"]
    studies = [_bad_study(tmp_path, c) for c in cases]
    calls = [("params", "show", studies[0][0]), ("simulate", studies[1][0], "--omega", "1")]
    for result, (_, fragments) in zip(geardyn_many(*calls), studies, strict=True):
        assert_one_line_error(result, *fragments)


@pytest.mark.parametrize("case", list(BAD_STUDIES))
def test_bad_study_is_one_line_error(tmp_path, capsys, case):
    path, fragments = _bad_study(tmp_path, case)
    assert_one_line_error(geardyn_here(capsys, "params", "show", path), *fragments)
    assert_one_line_error(geardyn_here(capsys, "simulate", path, "--omega", "1"), *fragments)


def test_bad_input_to_simulate(tmp_path, capsys):
    def run(*args):
        return geardyn_here(capsys, "simulate", *args)

    assert_one_line_error(run(tmp_path / "missing.toml", "--omega", "1"), "missing.toml")
    assert_one_line_error(run("no_such_study", "--omega", "1"), "no_such_study")
    assert_one_line_error(run("paper_fig3", "--omega", "-1"), "--omega", "-1")
    assert_one_line_error(run("paper_fig3", "--omega", "inf"), "--omega", "inf")
    assert_one_line_error(run("paper_fig3"), "--omega")
    assert_one_line_error(run("paper_fig3", "--omega", "x"), "--omega")
    assert_one_line_error(run("paper_fig3", "--omega", "1", "--plot", "a.jpg"), "--plot", "a.jpg")
    assert_one_line_error(run("paper_fig3", "--omega", "1", "--interpretation", "x"),
                          "--interpretation")
    assert_one_line_error(run("paper_fig3", "--omega", "1", "--plot", tmp_path / "a.png",
                              "--state", "Y_sq"), "--state", "'Y_sq'", "X_sq")
    assert not (tmp_path / "a.png").exists()
    assert_one_line_error(geardyn_here(capsys, "frobnicate"), "frobnicate")


def test_simulate_writes_netcdf_and_figure(tmp_path):
    nc, png = tmp_path / "out" / "run.nc", tmp_path / "out" / "run.png"
    r = geardyn("simulate", "src/geardyn/studies/paper_fig3.toml", "--omega", "1.1",
                "--periods", "4", "--transient", "100", "--out", nc, "--plot", png,
                cwd=Path(__file__).resolve().parents[1])
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    assert "status ok" in r.stdout and "distinct Poincaré point" in r.stdout
    assert str(nc) in r.stdout and str(png) in r.stdout
    ds = load_dataset(nc)
    assert ds.attrs["Omega"] == 1.1 and ds.attrs["periods"] == 4
    assert ds.attrs["study"] == "fig3"
    assert ds.sizes["sample"] == 5
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"



# --------------------------------------------------------------------------- bifurcation, plot
# In this process through typer's CliRunner: the root group itself turns errors into one line.
PNG = b"\x89PNG\r\n\x1a\n"
PDF = b"%PDF-"


def invoke(*args) -> subprocess.CompletedProcess:
    result = CliRunner().invoke(app, [str(a) for a in args])
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception
    return subprocess.CompletedProcess(args, result.exit_code, result.stdout, result.stderr)


TINY = ("--transient", "60", "--samples", "6", "--steps-per-period", "64", "--quiet")


def test_bifurcation_writes_what_the_api_computes(tmp_path):
    nc, png = tmp_path / "out" / "fig3.nc", tmp_path / "out" / "fig3.png"
    r = invoke("bifurcation", "paper_fig3", "--range", "0.6:2.6:5", *TINY, "--out", nc,
               "--plot", png)
    assert r.returncode == 0, r.stderr
    assert "fig3: 5 values of Omega in [0.6, 2.6], continuation none" in r.stdout
    assert str(nc) in r.stdout and str(png) in r.stdout
    assert png.read_bytes()[:8] == PNG
    saved = load_dataset(nc)
    study = builtin_study("paper_fig3")
    direct = bifurcation(build_model(study), param="Omega", values=np.linspace(0.6, 2.6, 5),
                         run=RunSettings(transient=60.0, samples=6, steps_per_period=64))
    np.testing.assert_array_equal(saved["period"].values, direct["period"].values)
    np.testing.assert_array_equal(saved["poincare"].values, direct["poincare"].values)
    np.testing.assert_array_equal(saved["contact"].values, direct["contact"].values)
    assert saved.attrs["study"] == "fig3" and saved.attrs["plot_state"] == "X_sq"
    assert saved.attrs["interpretation"] == "consistent" and saved.attrs["samples"] == 6
    # the summary counts what the file holds
    n1 = int(np.sum(saved["period"].values == 1))
    assert (f"period-1 {n1}" in r.stdout) == (n1 > 0)


GEAR_PAIR_STUDY = """
[study]
name = "gp"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.2
Fa = 0.2
[run]
transient = 150.0
[sweep]
param = "Omega"
start = 0.6
stop = 1.4
num = 5
continuation = "down"
samples = 8
lyapunov = true
"""


def test_bifurcation_defaults_come_from_the_study(tmp_path):
    study = tmp_path / "gp.toml"
    study.write_text(GEAR_PAIR_STUDY)
    nc, pdf = tmp_path / "gp.nc", tmp_path / "gp.pdf"
    r = invoke("bifurcation", study, "--quiet", "--out", nc, "--plot", pdf)
    assert r.returncode == 0, r.stderr
    assert "continuation down" in r.stdout
    assert pdf.read_bytes()[:5] == PDF
    saved = load_dataset(nc)
    g = GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
    direct = bifurcation(g, values=np.linspace(0.6, 1.4, 5),
                         run=RunSettings(transient=150.0, samples=8),
                                 continuation="down", lyapunov=True)
    np.testing.assert_array_equal(saved["period"].values, direct["period"].values)
    np.testing.assert_array_equal(saved["lyapunov"].values, direct["lyapunov"].values)
    assert saved.attrs["continuation"] == "down" and saved.sizes["sample"] == 8
    # options win over the study: another parameter at a fixed Omega, no Lyapunov exponent
    r = invoke("bifurcation", study, "--param", "Fa", "--range", "0.1:0.3:3", "--omega", "0.9",
               "--continuation", "none", "--no-lyapunov", "--samples", "4", "--quiet",
               "--out", nc)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    direct = bifurcation(g.with_omega(0.9), param="Fa", values=[0.1, 0.2, 0.3],
                                 run=RunSettings(transient=150.0, samples=4))
    np.testing.assert_array_equal(saved["poincare"].values, direct["poincare"].values)
    assert "lyapunov" not in saved and list(saved["Fa"].values) == [0.1, 0.2, 0.3]


def test_bifurcation_progress_reaches_the_total(tmp_path, monkeypatch):
    calls: list[tuple[int, int]] = []
    real_bar = cli_bifurcation._progress_bar

    @contextlib.contextmanager
    def recording_bar(show, label):
        with real_bar(show, label) as callback:  # the rich bar itself, on the captured stderr
            def record(done, total):
                calls.append((done, total))
                callback(done, total)

            yield None if callback is None else record

    monkeypatch.setattr(cli_bifurcation, "_stderr_is_terminal", lambda: True)
    monkeypatch.setattr(cli_bifurcation, "_progress_bar", recording_bar)
    r = invoke("bifurcation", "paper_fig3", "--range", "0.6:2.6:3", *TINY[:-1])
    assert r.returncode == 0, r.stderr
    assert calls and calls[-1] == (3, 3)
    assert all(a <= b for (a, _), (b, _) in zip(calls, calls[1:], strict=False))
    # --quiet: no bar, no callback
    calls.clear()
    r = invoke("bifurcation", "paper_fig3", "--range", "0.6:2.6:3", *TINY)
    assert r.returncode == 0 and calls == []


@pytest.mark.parametrize(("args", "fragments"), [
    (("--range", "0.1:4"), ("--range", "START:STOP:NUM", "'0.1:4'")),
    (("--range", "a:4:10"), ("--range", "numbers", "'a:4:10'")),
    (("--range", "0.1:4:1"), ("--range", "NUM must be >= 2")),
    (("--range", "0.1:4:2.5"), ("--range", "whole number")),
    (("--range", "1:1:5"), ("--range", "differ")),
    (("--range", "0.1:inf:5"), ("--range", "finite")),
    (("--param", "xi9"), ("--param", "'xi9'", "known: Omega, xi1")),
    (("--param", "xi1"), ("--range", "not given")),
    (("--param", "xi1", "--range", "0.01:0.1:3"), ("--omega", "not given")),
    (("--param", "xi1", "--range", "-0.1:0.1:3", "--omega", "1"), ("--range", "-0.1")),
    (("--continuation", "sideways"), ("--continuation", "sideways")),
    (("--samples", "1"), ("--samples", "1")),
    (("--transient", "-5"), ("--transient", "-5")),
    (("--omega", "0"), ("--omega",)),
    (("--plot", "fig.jpg"), ("--plot", "fig.jpg")),
    (("--out", "sweep.zarr"), ("--out", ".nc")),
    (("--state", "Q_sq"), ("--state", "'Q_sq'", "X_sq")),
    (("--interpretation", "printed"), ("--interpretation",)),
])
def test_bifurcation_bad_input_is_one_line_error(tmp_path, args, fragments):
    files = [] if "--out" in args else ["--out", tmp_path / "x.nc"]
    files += [] if "--plot" in args else ["--plot", tmp_path / "x.png"]
    r = invoke("bifurcation", "paper_fig3", *TINY, *args, *files)
    assert_one_line_error(r, *fragments)
    assert not list(tmp_path.iterdir())  # checked before anything runs or is written


def test_bifurcation_bad_study_is_one_line_error(tmp_path):
    assert_one_line_error(invoke("bifurcation", "no_such_study"), "no_such_study")
    path, fragments = _bad_study(tmp_path, "negative-stiffness")
    assert_one_line_error(invoke("bifurcation", path, "--range", "1:2:3"), *fragments)
    r = invoke("bifurcation", path.with_name("no_sweep.toml").as_posix())
    assert_one_line_error(r, "no_sweep.toml")
    plain = tmp_path / "plain.toml"
    plain.write_text('[params]\nbase = "paper"\n')
    assert_one_line_error(invoke("bifurcation", plain), "--range", "no [sweep]")


def test_bifurcation_continued_transient(tmp_path):
    study = tmp_path / "gp.toml"
    study.write_text(GEAR_PAIR_STUDY)
    nc = tmp_path / "gp.nc"
    r = invoke("bifurcation", study, "--continued-transient", "20", "--converge", "1e-8",
               "--no-lyapunov", "--quiet", "--out", nc)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    g = GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
    direct = bifurcation(g, values=np.linspace(0.6, 1.4, 5),
                         run=RunSettings(transient=150.0, samples=8, converge=1e-8,
                                         continued_transient=20.0),
                         continuation="down")
    np.testing.assert_array_equal(saved["poincare"].values, direct["poincare"].values)
    assert saved.attrs["continued_transient"] == 20.0
    np.testing.assert_array_equal(saved["transient_periods"].values,
                                  direct["transient_periods"].values)
    assert_one_line_error(invoke("bifurcation", study, "--continuation", "none",
                                 "--continued-transient", "20"), "--continued-transient",
                          "continuation")
    assert_one_line_error(invoke("bifurcation", study, "--continued-transient", "-1"),
                          "--continued-transient", "-1")


def test_plot_redraws_saved_results(tmp_path):
    g = GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
    bif = save_dataset(bifurcation(g, values=[0.8, 0.95, 1.2],
                                   run=RunSettings(transient=100.0, samples=8)),
                       tmp_path / "bif.nc")
    sim = save_dataset(simulate(g, omega=0.95, run=RunSettings(transient=100.0, samples=8)),
                       tmp_path / "sim.nc")
    assert_result(load_dataset(sim), "simulation")
    assert_result(load_dataset(bif), "bifurcation")
    r = invoke("plot", bif, "--out", tmp_path / "figs" / "bif.pdf")
    assert r.returncode == 0, r.stderr
    assert "bifurcation dataset" in r.stdout
    assert (tmp_path / "figs" / "bif.pdf").read_bytes()[:5] == PDF
    r = invoke("plot", sim, "--state", "v")
    assert r.returncode == 0 and "simulation dataset" in r.stdout, r.stderr
    assert (tmp_path / "sim.png").read_bytes()[:8] == PNG  # default: RESULT with .png
    assert_one_line_error(invoke("plot", bif, "--state", "X_sq"), "--state", "'X_sq'", "x, v")
    assert_one_line_error(invoke("plot", bif, "--out", tmp_path / "a.gif"), "--out", "a.gif")
    assert_one_line_error(invoke("plot", tmp_path / "none.nc"), "none.nc")
    other = save_dataset(xr.Dataset({"a": ("t", [1.0, 2.0])}), tmp_path / "other.nc")
    assert_one_line_error(invoke("plot", other), "RESULT", "not a geardyn")
    # the recorded kind decides, checked by assert_result: a variable missing is named ...
    broken = load_dataset(bif).drop_vars("period")
    assert_one_line_error(invoke("plot", save_dataset(broken, tmp_path / "broken.nc")),
                          "RESULT", "'period' missing")
    # ... and a file written before the kind was recorded is still recognised
    old = load_dataset(sim)
    del old.attrs["geardyn_kind"]
    r = invoke("plot", save_dataset(old, tmp_path / "old.nc"), "--state", "v")
    assert r.returncode == 0 and "simulation dataset" in r.stdout, r.stderr


def test_plot_redraws_maps_and_reproduction_cases(tmp_path):
    from geardyn import map2d
    from geardyn.execution.zarr_store import save_zarr_dataset

    g = GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
    m = map2d(g, x=("Omega", [0.8, 1.2]), y=("zeta", [0.05, 0.1]),
              run=RunSettings(transient=50.0, samples=4))
    nc = save_dataset(m, tmp_path / "map.nc")
    save_zarr_dataset(m, tmp_path / "map.zarr")
    for path in (nc, tmp_path / "map.zarr"):
        r = invoke("plot", path, "--out", tmp_path / f"{path.suffix[1:]}.png")
        assert r.returncode == 0, r.stderr
        assert "map dataset" in r.stdout
        assert (tmp_path / f"{path.suffix[1:]}.png").read_bytes()[:8] == PNG
    assert_one_line_error(invoke("plot", nc, "--state", "x"), "--state", "map")
    # a reproduction case file: the sweeps up and down along "sweep"
    parts = [bifurcation(g, values=[0.8, 0.95, 1.2], run=RunSettings(transient=50.0, samples=4),
                         continuation=d) for d in ("up", "down")]
    case = xr.concat(parts, dim="sweep", combine_attrs="drop_conflicts")
    case = case.assign_coords(sweep=("sweep", ["up", "down"]))
    case.attrs["geardyn_kind"] = "reproduction-case"  # as geardyn reproduce writes it
    assert_result(case, "reproduction-case")
    path = save_dataset(case, tmp_path / "case.nc")
    r = invoke("plot", path, "--sweep", "down", "--out", tmp_path / "case-down.png")
    assert r.returncode == 0, r.stderr
    assert "reproduction dataset" in r.stdout
    assert (tmp_path / "case-down.png").read_bytes()[:8] == PNG
    assert_one_line_error(invoke("plot", path, "--sweep", "sideways"), "--sweep")


def test_simulate_records_plot_state_and_labels_spectrum(tmp_path):
    nc = tmp_path / "run.nc"
    r = invoke("simulate", "paper_fig3", "--omega", "1.1", "--periods", "4", "--transient",
               "50", "--state", "X_pq", "--out", nc)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    # no load fluctuation in Fig. 3: no second excitation frequency is recorded
    assert saved.attrs["plot_state"] == "X_pq" and "Lambda" not in saved.attrs


def test_bifurcation_transient_by_convergence(tmp_path):
    nc = tmp_path / "conv.nc"
    r = invoke("bifurcation", "paper_fig3", "--range", "0.6:0.7:2", "--transient", "300",
               "--samples", "4", "--converge", "1e-8", "--quiet", "--out", nc)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    assert saved.attrs["converge"] == 1e-8
    assert saved["converged"].values.tolist() == [1, 1]  # periodic there: it settles
    # the transient used is longer than the minimum and shorter than the limit (10x)
    T = 2 * np.pi / saved["Omega"].values
    used = saved["transient_periods"].values * T
    assert np.all(used >= 300.0) and np.all(used < 3000.0)
    assert_one_line_error(invoke("bifurcation", "paper_fig3", "--converge", "-1", "--quiet"),
                          "--converge")


# --------------------------------------------------------------------------- continue
SOFT_STUDY = """
[study]
name = "soft"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.0
Fm = 0.1
Fa = 0.05
[run]
omega = 1.2
"""


def _soft_study(tmp_path) -> Path:
    study = tmp_path / "soft.toml"
    study.write_text(SOFT_STUDY)
    return study


def test_continue_writes_the_branch_and_its_figure(tmp_path):
    from geardyn import continuation

    study = _soft_study(tmp_path)
    nc, png = tmp_path / "out" / "branch.nc", tmp_path / "out" / "branch.png"
    r = invoke("continue", study, "--param", "Omega", "--range", "0.6:1.0", "--quiet",
               "--out", nc, "--plot", png)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    assert_result(saved, "continuation")
    assert png.read_bytes()[:8] == PNG
    assert saved.attrs["study"] == "soft" and saved.attrs["status"] == 0
    direct = continuation(GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05), "Omega", 0.6, 1.0)
    np.testing.assert_array_equal(saved["Omega"].values, direct["Omega"].values)
    assert list(saved["bifurcation_kind"].values) == list(direct["bifurcation_kind"].values)
    assert "2 fold" in r.stdout and str(nc) in r.stdout and "ended early" not in r.stderr
    # geardyn plot recognises the kind and redraws it
    r = invoke("plot", nc, "--out", tmp_path / "again.pdf")
    assert r.returncode == 0, r.stderr
    assert "continuation dataset" in r.stdout
    assert (tmp_path / "again.pdf").read_bytes()[:5] == PDF
    assert_one_line_error(invoke("plot", nc, "--state", "Q"), "--state", "'Q'")


def test_continue_takes_the_first_orbits_transient_from_the_study(tmp_path, monkeypatch):
    """[run] transient_periods (at the start's Omega), converge and transient_max reach the
    continuation's first orbit (--transient replaces the study's transient only)."""
    import geardyn.analysis.branch as branch_module
    from geardyn import RunSettings, continuation

    study = tmp_path / "settled.toml"
    study.write_text(SOFT_STUDY.replace("omega = 1.2", "omega = 1.2\ntransient_periods = 30\n"
                                        "converge = 1e-9\ntransient_max = 900.0"))
    seen: list = []
    real = branch_module.continuation

    def recording(*args, **kwargs):
        seen.append(kwargs["run"])
        return real(*args, **kwargs)

    monkeypatch.setattr(branch_module, "continuation", recording)
    nc = tmp_path / "b.nc"
    r = invoke("continue", study, "--range", "0.6:1.0", "--quiet", "--out", nc)
    assert r.returncode == 0, r.stderr
    run = seen[-1]
    assert run.transient == pytest.approx(30 * 2 * math.pi / 0.6)
    assert run.converge == 1e-9 and run.transient_max == 900.0
    direct = continuation(GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05), "Omega", 0.6, 1.0,
                          run=RunSettings(transient=30 * 2 * math.pi / 0.6, converge=1e-9,
                                          transient_max=900.0))
    np.testing.assert_array_equal(load_dataset(nc)["Omega"].values, direct["Omega"].values)
    r = invoke("continue", study, "--range", "0.6:1.0", "--transient", "50", "--quiet")
    assert r.returncode == 0, r.stderr
    assert seen[-1].transient == 50.0 and seen[-1].converge == 1e-9
    # a study without any transient keeps the continuation's own default guess
    r = invoke("continue", _soft_study(tmp_path), "--range", "0.6:1.0", "--quiet")
    assert r.returncode == 0, r.stderr
    assert seen[-1] is None


def test_continue_over_a_brute_force_diagram_with_progress(tmp_path, monkeypatch):
    from geardyn.cli import continuation as cli_continuation

    study = _soft_study(tmp_path)
    bif = tmp_path / "bif.nc"
    r = invoke("bifurcation", study, "--range", "0.6:1.0:5", "--transient", "100", "--samples",
               "4", "--steps-per-period", "64", "--quiet", "--out", bif)
    assert r.returncode == 0, r.stderr
    calls: list[tuple[int, float]] = []
    real_bar = cli_continuation._continue_bar

    @contextlib.contextmanager
    def recording_bar(show, label, param, start, stop):
        with real_bar(show, label, param, start, stop) as callback:
            def record(points, value):
                calls.append((points, value))
                callback(points, value)

            yield None if callback is None else record

    monkeypatch.setattr(cli_bifurcation, "_stderr_is_terminal", lambda: True)
    monkeypatch.setattr(cli_continuation, "_continue_bar", recording_bar)
    png = tmp_path / "over.png"
    r = invoke("continue", study, "--range", "0.6:1.0", "--over", bif, "--quantity",
               "dynamic_factor", "--plot", png)
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == PNG and "nothing written" not in r.stdout
    assert calls and calls[-1][1] == 1.0
    assert [p for p, _ in calls] == list(range(1, len(calls) + 1))
    # a diagram of another parameter, or not a diagram at all
    other = tmp_path / "fa.nc"
    r = invoke("bifurcation", study, "--param", "Fa", "--range", "0.04:0.05:2", "--omega", "0.9",
               "--transient", "50", "--samples", "2", "--quiet", "--out", other)
    assert r.returncode == 0, r.stderr
    assert_one_line_error(invoke("continue", study, "--range", "0.6:1.0", "--over", other),
                          "--over", "sweeps Fa")
    assert_one_line_error(invoke("continue", study, "--range", "0.6:1.0", "--over",
                                 tmp_path / "none.nc"), "none.nc")
    assert_one_line_error(invoke("continue", study, "--range", "0.6:1.0", "--over", bif,
                                 "--quantity", "deflection_rms"), "--quantity", "--over")


@pytest.mark.parametrize(("args", "fragments"), [
    (("--range", "0.6"), ("--range", "START:STOP", "'0.6'")),
    (("--range", "a:1"), ("--range", "numbers", "'a:1'")),
    (("--range", "1:1"), ("--range", "differ")),
    (("--range", "0.6:nan"), ("--range", "finite")),
    (("--range", "-1:1"), ("--range", "Omega = -1")),
    (("--range", "0.6:1", "--period", "0"), ("--period",)),
    (("--range", "0.6:1", "--param", "kapa"), ("--param", "'kapa'", "known")),
    (("--range", "0.6:1", "--quantity", "nothing"), ("--quantity", "'nothing'")),
    (("--range", "0.6:1", "--state", "Q"), ("--state", "'Q'")),
    (("--range", "0.6:1", "--out", "b.zarr"), ("--out", ".nc")),
    (("--range", "0.6:1", "--plot", "b.gif"), ("--plot", "b.gif")),
    ((), ("--range", "no [sweep]")),
])
def test_continue_bad_input_is_one_line_error(tmp_path, args, fragments):
    study = _soft_study(tmp_path)
    r = invoke("continue", study, "--quiet", *args)
    assert_one_line_error(r, *fragments)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["soft.toml"]  # nothing written


def test_continue_writes_a_branch_that_ends_early(tmp_path):
    from geardyn.analysis.branch_data import BranchStatus

    study = _soft_study(tmp_path)
    nc, png = tmp_path / "short.nc", tmp_path / "short.png"
    r = invoke("continue", study, "--range", "0.6:1.0", "--max-points", "5", "--quiet",
               "--out", nc, "--plot", png)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    assert_result(saved, "continuation")
    assert saved.sizes["point"] == 5 and saved.attrs["status"] == BranchStatus.MAX_POINTS
    assert "ended early" in r.stderr and saved.attrs["message"] in " ".join(r.stderr.split())
    assert png.read_bytes()[:8] == PNG
    # the parameter leaves the valid region (|kappa| < 1): the points up to there are kept
    r = invoke("continue", study, "--param", "kappa", "--range", "0.5:1.5", "--omega", "1.2",
               "--quiet", "--out", nc)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    assert saved.attrs["status"] == BranchStatus.INVALID and saved.sizes["point"] > 2
    assert saved["kappa"].values.max() < 1.0 and "kappa=" in r.stderr


def test_continue_switches_at_period_doublings(tmp_path):
    study = tmp_path / "pd.toml"
    study.write_text(SOFT_STUDY.replace("kappa = 0.0", "kappa = 0.2")
                     .replace("zeta = 0.05", "zeta = 0.02").replace("Fa = 0.05", "Fa = 0.1"))
    nc, png = tmp_path / "pd.nc", tmp_path / "pd.png"
    r = invoke("continue", study, "--range", "1.9:1.5", "--switch", "--max-period", "2",
               "--quiet", "--out", nc, "--plot", png)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    assert_result(saved, "continuation")
    doublings = int(np.sum(saved["bifurcation_kind"].values[saved["bifurcation_branch"].values
                                                            == 0] == "period-doubling"))
    assert doublings >= 1 and saved.sizes["branch_id"] == 1 + doublings
    assert list(saved["branch_period"].values) == [1] + [2] * doublings
    assert "period-2" in r.stdout and png.read_bytes()[:8] == PNG


def test_help_keeps_bracketed_text(capsys):
    """Every bracketed word of an option's help ("[rad/s]", "[sweep]") reaches ``--help`` as
    written: the help is plain text, not rich markup (which drops an unknown "[tag]")."""
    import re

    import typer.main

    from geardyn.cli.main import app

    group = typer.main.get_command(app)
    checked = 0
    for name, command in group.commands.items():
        if not hasattr(command, "params"):
            continue
        texts = [command.help or ""] + [getattr(p, "help", None) or "" for p in command.params]
        words = {w for text in texts for w in re.findall(r"\[[a-z][^\]\s]*\]", text)}
        if not words:
            continue
        r = geardyn_here(capsys, name, "--help")
        assert r.returncode == 0, r.stderr
        for word in words:
            assert word in r.stdout, f"geardyn {name} --help lost {word}"
            checked += 1
    assert checked >= 3
