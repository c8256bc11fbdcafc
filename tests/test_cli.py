"""The ``geardyn`` command line, run in a subprocess as a user would."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from geardyn import PlanetaryParams
from geardyn.cli.main import main
from geardyn.io.netcdf import load_dataset
from geardyn.io.toml import load_study, paper_study, study_to_toml


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
    r = geardyn("--help")
    assert r.returncode == 0, r.stderr
    assert "simulate" in r.stdout and "params" in r.stdout
    r = geardyn_here(capsys, "--version")
    assert r.returncode == 0 and r.stdout.strip() == "geardyn 0.1.0"
    r = geardyn_here(capsys, "params", "--help")
    assert r.returncode == 0 and "show" in r.stdout and "save" in r.stdout


def test_params_show_default_lists_derived_quantities(capsys):
    r = geardyn("params", "show")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    for name in ("omega_n", "M_c", "J_c_eff", "C_sq", "k_sq_c", "f_c0", "Natural frequencies"):
        assert name in out
    assert "24.9914" in out  # M_c, consistent interpretation
    r = geardyn_here(capsys, "params", "show", "--interpretation", "as-printed")
    assert r.returncode == 0 and "130.689" in r.stdout
    r = geardyn_here(capsys, "params", "show", "paper_fig3", "--interpretation", "carrier-only")
    assert r.returncode == 0 and "0.687528" in r.stdout


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
    cases = ["negative-stiffness", "unknown-key", "nan", "wrong-unit"]
    studies = [_bad_study(tmp_path, c) for c in cases]
    calls = [("params", "show", path) for path, _ in studies[:2]]
    calls += [("simulate", path, "--omega", "1") for path, _ in studies[2:]]
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
