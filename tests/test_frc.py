"""geardyn.frequency_response: up/down brute-force frequency-response curves, checked against
the analytic linear response and against the hysteresis band of the bifurcation engine's own
up and down sweeps on a finer grid."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.analysis.frc import physical_axes
from geardyn.testing import assert_result

SOFT = dict(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)  # contact loss: a softening resonance


def test_linear_regime_equals_the_analytic_frequency_response():
    """Always in contact (Fm = 2), constant stiffness: x = Fm + b + Re(A e^{i W t}) with
    A = Fa W^2 / (1 - W^2 + 2 i zeta W); the mesh force's alternating part is
    A (1 + 2 i zeta W)."""
    zeta, fm, fa = 0.05, 2.0, 0.02
    g = geardyn.GearPair(zeta=zeta, kappa=0.0, Fm=fm, Fa=fa)
    om = np.linspace(0.5, 2.0, 7)
    ds = geardyn.frequency_response(g, om, run=geardyn.RunSettings(transient=400.0, samples=4))
    assert_result(ds, "frequency-response")
    A = np.abs(fa * om**2 / (1 - om**2 + 2j * zeta * om))
    for s in ("up", "down"):
        one = ds.sel(sweep=s, mesh="mesh")
        np.testing.assert_allclose(one["dte_rms"].values, A / math.sqrt(2), rtol=2e-6)
        np.testing.assert_allclose(one["dte_peak"].values, A, rtol=5e-6)
        np.testing.assert_allclose(one["dte_amplitude"].values, A, rtol=5e-6)
        np.testing.assert_allclose(one["dte_max"].values, fm + 1.0 + A, rtol=5e-6)
        np.testing.assert_allclose(one["dte_mean"].values, fm + 1.0, rtol=1e-9)
        force = A * np.abs(1 + 2j * zeta * om)
        np.testing.assert_allclose(one["dynamic_factor"].values, 1 + force / fm, rtol=1e-3)
    assert ds.sizes["jump"] == 0 and not ds["hysteresis"].values.any()
    assert ds.attrs["resolution"] == pytest.approx(0.25)
    assert "mesh_frequency" not in ds.coords  # a dimensionless model: no physical axes


def test_dte_of_an_impacting_orbit_equals_the_reference_integration():
    """Contact loss (single-sided impacts): the DTE statistics over the orbit against scipy
    DOP853 (rtol 1e-12, restarted at every edge) over one period from the orbit's section
    point (Newton shooting), sampled at 4000 points."""
    g = geardyn.GearPair(**SOFT)
    ds = geardyn.frequency_response(g, np.array([0.88, 0.9, 0.92]),
                                    run=geardyn.RunSettings(transient=300.0, samples=8))
    orb = geardyn.periodic_orbit(g, omega=0.9)
    assert orb.converged and orb.contact() == {"mesh": "single"}
    t = np.linspace(0.0, 2 * math.pi / 0.9, 4001)
    x = geardyn.reference_solution(g.with_omega(0.9), orb.x, t)[:-1, 0]
    mean = x.mean()
    for s in ("up", "down"):
        one = ds.sel(sweep=s, mesh="mesh", Omega=0.9)
        assert float(one["dte_mean"]) == pytest.approx(mean, rel=1e-6)
        assert float(one["dte_rms"]) == pytest.approx(np.sqrt(np.mean((x - mean) ** 2)),
                                                      rel=1e-5)
        assert float(one["dte_amplitude"]) == pytest.approx((x.max() - x.min()) / 2, rel=1e-5)
        assert float(one["dte_max"]) == pytest.approx(np.abs(x).max(), rel=1e-5)


def _band(up, down) -> np.ndarray:
    """Where the bifurcation engine's up and down sweeps disagree (force RMS by > 1 %)."""
    a, b = up["force_rms"].values[:, 0], down["force_rms"].values[:, 0]
    return np.abs(a - b) > 0.01 * np.maximum(a, b)


def test_jumps_of_the_softening_pair_lie_in_the_hysteresis_band_of_the_sweeps():
    g = geardyn.GearPair(**SOFT)
    ds = geardyn.frequency_response(g, np.linspace(0.6, 1.0, 21),
                                    run=geardyn.RunSettings(transient=300.0, samples=8))
    assert_result(ds, "frequency-response")
    res = ds.attrs["resolution"]
    fine = np.linspace(0.66, 0.88, 45)  # step 0.005
    up = geardyn.bifurcation(g, values=fine,
                             run=geardyn.RunSettings(transient=300.0, samples=8), continuation="up")
    down = geardyn.bifurcation(g, values=fine,
                               run=geardyn.RunSettings(transient=300.0, samples=8),
                               continuation="down")
    band = fine[_band(up, down)]
    assert band.size >= 5, "expected a hysteresis band"
    lo, hi = band.min(), band.max()
    jumps = {str(ds["jump_sweep"].values[j]): j for j in range(ds.sizes["jump"])}
    assert set(jumps) == {"up", "down"} and ds.sizes["jump"] == 2
    for name, edge_lo, edge_hi in (("up", hi, hi + 0.005), ("down", lo - 0.005, lo)):
        j = jumps[name]
        w = float(ds["jump_omega"].values[j])
        assert lo - res <= w <= hi + res, (name, w, lo, hi)
        # the grid step it is located in overlaps the fine sweeps' jump step
        assert ds["jump_lo"].values[j] <= edge_hi and ds["jump_hi"].values[j] >= edge_lo
    # the up sweep jumps up (onto the impacting branch), the down sweep down
    assert ds["jump_to"].values[jumps["up"]] > ds["jump_from"].values[jumps["up"]]
    assert ds["jump_to"].values[jumps["down"]] < ds["jump_from"].values[jumps["down"]]
    marked = ds["Omega"].values[ds["hysteresis"].values]
    assert marked.min() >= lo - res and marked.max() <= hi + res


def test_physical_axes_of_the_device():
    """Mesh frequency omega_n Omega / 2 pi; the carrier drives, the sun (40 teeth, Table 1) is
    held, so the input speed is 60 f / 40 rpm."""
    dev = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=1.0)
    axes = physical_axes(dev, np.array([0.5, 1.0]))
    f = np.array([0.5, 1.0]) * dev.omega_n / (2 * math.pi)
    np.testing.assert_allclose(axes["mesh_frequency"][0], f, rtol=1e-14)
    np.testing.assert_allclose(axes["input_speed"][0], 60 * f / 40, rtol=1e-14)
    dim = dev.dimensional()
    axes = physical_axes(dim, np.array([1000.0]))
    np.testing.assert_allclose(axes["mesh_frequency"][0], 1000.0 / (2 * math.pi), rtol=1e-14)
    assert physical_axes(geardyn.GearPair(), np.array([1.0])) is None


STUDY = """
[study]
name = "soft"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.0
Fm = 0.1
Fa = 0.05
[run]
transient = 300.0
[sweep]
param = "Omega"
start = 0.6
stop = 1.0
num = 21
samples = 8
"""


def test_cli_writes_what_the_api_computes_and_draws_it(tmp_path):
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.io.netcdf import load_dataset
    from geardyn.plotting.frc import plot_frc

    study = tmp_path / "soft.toml"
    study.write_text(STUDY)
    nc, png = tmp_path / "frc.nc", tmp_path / "frc.png"
    r = CliRunner().invoke(app, ["frc", str(study), "--quiet", "--out", str(nc),
                                 "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert "2 jumps" in r.stdout
    saved = load_dataset(nc)
    assert_result(saved, "frequency-response")
    direct = geardyn.frequency_response(geardyn.GearPair(**SOFT), np.linspace(0.6, 1.0, 21),
                                        run=geardyn.RunSettings(transient=300.0, samples=8))
    np.testing.assert_array_equal(saved["dte_rms"].values, direct["dte_rms"].values)
    np.testing.assert_array_equal(saved["jump_omega"].values, direct["jump_omega"].values)
    assert png.read_bytes()[:4] == b"\x89PNG"
    # a continuation branch (dim 'point', Omega a variable, 'stable') drawn over the curves
    branch = direct.sel(sweep="up").rename_dims(Omega="point").reset_coords()
    branch["stable"] = ("point", np.arange(branch.sizes["point"]) % 2 == 0)
    fig = plot_frc(direct, branches=[branch])
    labels = {t.get_text() for t in fig.axes[0].get_legend().get_texts()}
    assert {"sweep up", "sweep down", "branch, stable", "branch, unstable"} <= labels
    # ... and one named as geardyn.continuation names its variables, two branch numbers
    cont = branch.drop_vars("stable").rename(dte_rms="deflection_rms",
                                             dte_amplitude="deflection_amplitude")
    cont["stability"] = ("point", np.where(branch["stable"].values, "stable", "unstable"))
    cont["branch"] = ("point", (np.arange(cont.sizes["point"]) >= 10).astype(int))
    fig = plot_frc(direct, branches=[cont])
    for ax in fig.axes[:3]:
        drawn = [ln for ln in ax.get_lines() if ln.get_color() == "black"]
        assert len(drawn) == 4  # two branches, stable and unstable each
    r = CliRunner().invoke(app, ["frc", str(study), "--mesh", "nope", "--quiet"])
    assert r.exit_code == 2 and "--mesh" in r.stderr
    # the branch from a file, over the figure; and geardyn plot redraws the saved curves
    from geardyn.io.netcdf import save_dataset

    save_dataset(branch, tmp_path / "branch.nc")
    r = CliRunner().invoke(app, ["frc", str(study), "--quiet", "--branch",
                                 str(tmp_path / "branch.nc"), "--plot", str(png)])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(app, ["frc", str(study), "--quiet", "--branch", str(nc)])
    assert r.exit_code == 2 and "no dimension 'point'" in r.stderr
    r = CliRunner().invoke(app, ["plot", str(nc), "--out", str(tmp_path / "again.pdf")])
    assert r.exit_code == 0 and "frequency response dataset" in r.stdout


def test_cli_sweeps_the_studys_input_speed(tmp_path):
    """``geardyn frc planetary_example`` sweeps the study's own [sweep] parameter, the input
    speed in rpm: each speed becomes Omega through the model's kinematics (with_params), and
    the dataset's input_speed axis, computed back from Omega by speed_axes, gives the speeds
    asked. A model without that parameter, or a parameter that is not a frequency, is a
    one-line error naming --param."""
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.io.netcdf import load_dataset

    nc = tmp_path / "p.nc"
    r = CliRunner().invoke(app, ["frc", "planetary_example", "--range", "4000:6000:2",
                                 "--transient", "30", "--samples", "2", "--quiet", "--yes",
                                 "--out", str(nc)])
    assert r.exit_code == 0, r.output
    assert "input_speed [4000, 6000]" in r.stdout
    saved = load_dataset(nc)
    assert_result(saved, "frequency-response")
    np.testing.assert_allclose(saved["input_speed"].values, [4000.0, 6000.0], rtol=1e-12)
    study = tmp_path / "soft.toml"
    study.write_text(STUDY)
    r = CliRunner().invoke(app, ["frc", str(study), "--param", "input_speed", "--range",
                                 "1:2:2", "--quiet"])
    assert r.exit_code == 2 and "--param" in r.stderr
    r = CliRunner().invoke(app, ["frc", str(study), "--param", "zeta", "--quiet"])
    assert r.exit_code == 2 and "--param" in r.stderr and "frequency" in r.stderr
