"""``geardyn envelope``: the curves and figure it writes, the [envelope] table, and its errors
naming the option or the table's field."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.io import load_dataset, load_study
from test_cli import invoke

STUDY = """
[study]
name = "gp_rattle"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.0
Fm = 0.1
Fa = 0.05
[run]
transient = 300.0
[envelope]
y = "Fa"
x_range = [0.6, 1.8]
y_range = [0.0, 0.4]
flanks = ["drive"]
starts = [1.2]
scan = 12
resolution = 30
"""


@pytest.fixture
def study(tmp_path):
    path = tmp_path / "gp.toml"
    path.write_text(STUDY)
    return path


def test_envelope_writes_the_curves_and_the_figure(study, tmp_path):
    out, png = tmp_path / "env", tmp_path / "env.png"
    r = invoke("envelope", study, "--out", out, "--plot", png, "--map", "4:3", "--quiet")
    assert r.returncode == 0, r.stderr
    assert "1 drive" in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ds = load_dataset(out / "grazing_drive_0.nc")
    assert ds.attrs["geardyn_kind"] == "curve" and ds.attrs["study"] == "gp_rattle"
    om, fa = ds["Omega"].values, ds["Fa"].values
    # the linear pair's contact-loss curve (tests/test_grazing_curves.py derives it)
    np.testing.assert_allclose(fa, 0.1 * np.abs(1 - om**2 + 0.1j * om) / om**2, rtol=2e-5)
    redrawn = tmp_path / "curve.png"
    r = invoke("plot", out / "grazing_drive_0.nc", "--out", redrawn)
    assert r.returncode == 0, r.stderr
    assert "curve dataset" in r.stdout and redrawn.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args,message", [
    (("--x", "Omega:2:1"), "--x"),
    (("--y", "stiffness:0:1"), "--y: stiffness"),
    (("--flank", "top"), "--flank"),
    (("--map", "1:3"), "--map"),
    (("--plot", "a.txt"), "--plot"),
    (("--resolution", "1"), "--resolution"),
    (("--curve", "missing.nc"), "--curve"),
])
def test_bad_options_name_the_option(study, tmp_path, args, message):
    r = invoke("envelope", study, "--out", tmp_path / "o", *args)
    assert r.returncode == 2
    assert message in r.stderr


@pytest.mark.parametrize("line,field", [
    ("resolutio = 12", "envelope.resolutio"),
    ("x_range = [2.0, 1.0]", "envelope.x_range"),
    ("flanks = [\"top\"]", "envelope.flanks"),
    ("map = [1, 4]", "envelope.map"),
    ("scan = 1", "envelope.scan"),
])
def test_bad_envelope_table_names_the_field(tmp_path, line, field):
    key = line.split("=")[0].strip()
    kept = [ln for ln in STUDY.splitlines() if not ln.startswith(f"{key} ")]
    text = "\n".join(kept).replace("[envelope]", f"[envelope]\n{line}")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    r = invoke("envelope", path, "--out", tmp_path / "o")
    assert r.returncode == 2
    assert field in r.stderr, r.stderr


def test_the_envelope_table_reads_its_defaults():
    table = load_study(STUDY).envelope
    assert table.x == "Omega" and table.flanks == ("drive",) and table.map is None
