"""Two-parameter maps: the grid's coefficient vectors, the per-point analysis, plot, estimate."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.analysis.map2d import estimate_map
from geardyn.analysis.periodicity import classify_period
from geardyn.plotting.map2d import plot_map
from geardyn.solvers.ensemble import busy_lanes
from geardyn.testing import assert_result


@pytest.fixture(scope="module")
def device():
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=1.1)


# ------------------------------------------------------------------ coefficient vectors
@pytest.mark.parametrize("x,xv,y,yv", [
    ("Omega", [0.5, 1.1, 2.0], "xi", [0.02, 0.1]),
    ("xi", [0.02, 0.1], "Omega", [0.5, 1.1, 2.0]),
    ("backlash", [2e-5, 5e-5], "xi1", [0.03, 0.07, 0.2]),
])
def test_lane_params_grid_equals_one_model_per_point(device, x, xv, y, yv):
    """Lane j*nx+i must hold the coefficients of the device built with both values set."""
    P = device.lane_params_grid(x, xv, y, yv)
    assert P.shape == (len(xv) * len(yv), device.params.size)
    for j, v in enumerate(yv):
        for i, u in enumerate(xv):
            expect = device.with_params(**{x: u, y: v}).params
            np.testing.assert_allclose(P[j * len(xv) + i], expect, rtol=1e-14, atol=0)


def test_lane_params_grid_of_a_raw_coefficient_model():
    g = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.2)
    P = g.lane_params_grid("zeta", [0.01, 0.02, 0.03], "Fa", [0.1, 0.4])
    np.testing.assert_array_equal(P[:, 1], [0.01, 0.02, 0.03] * 2)      # zeta column
    np.testing.assert_array_equal(P[:, 4], [0.1] * 3 + [0.4] * 3)       # Fa column


def test_lane_params_grid_refuses_an_order_that_loses_a_setting(device):
    # a raw coefficient as y would be undone by re-deriving the coefficients for a physical x
    # that sets it: refused; one that x leaves alone is kept (raw overrides survive changes
    # that commute with them), so both orders give the same grid
    with pytest.raises(ValueError, match="swap the axes"):
        device.lane_params_grid("xi", [0.02, 0.1], "c_sq_q", [0.1, 0.2])
    P = device.lane_params_grid("xi", [0.02, 0.1], "k_sq_q", [0.1, 0.2])
    Q = device.lane_params_grid("k_sq_q", [0.1, 0.2], "xi", [0.02, 0.1])
    np.testing.assert_array_equal(P.reshape(2, 2, -1), Q.reshape(2, 2, -1).transpose(1, 0, 2))
    P = device.lane_params_grid("c_sq_q", [0.1, 0.2], "xi", [0.02, 0.1])  # the working order
    np.testing.assert_array_equal(P[:, device.param_index("c_sq_q")], [0.1, 0.2] * 2)
    with pytest.raises(ValueError, match="different parameters"):
        device.lane_params_grid("xi", [0.02], "xi", [0.1])


# ------------------------------------------------------------------ per-point analysis
def test_contact_map_matches_the_linear_separation_boundary():
    """Without stiffness variation the teeth of a gear pair separate iff the linear response
    amplitude Fa W^2/|1-W^2+2i zeta W| exceeds the mean load Fm: an analytical boundary in the
    (Omega, Fa) plane, which also checks that the map's axes are not swapped."""
    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
    om = np.linspace(0.4, 2.5, 8)
    fa = np.array([0.02, 0.05, 0.12])
    ds = geardyn.map2d(g, x=("Omega", om), y=("Fa", fa),
                       run=geardyn.RunSettings(transient=600.0, samples=10))
    assert ds["contact"].dims == ("Fa", "Omega", "mesh")
    onset = np.array([g.with_params(Fa=a).separation_onset(om) for a in fa])
    clear = np.abs(onset) > 0.05
    assert clear.sum() > 15
    separated = ds["contact"].values[..., 0] != "none"
    np.testing.assert_array_equal(separated[clear], onset[clear] > 0)
    assert np.any(separated) and np.any(~separated)


def test_map_points_equal_single_simulations(device):
    """Each point of a (xi, Omega) map is the device built with that xi, simulated at that
    Omega: its period class and its Poincare points' class agree, and the map equals a
    bifurcation sweep along Omega at each xi."""
    om, xi = np.array([0.6, 1.1, 2.2]), np.array([0.03, 0.12])
    kw = dict(run=geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64))
    ds = geardyn.map2d(device, x=("Omega", om), y=("xi", xi), **kw)
    assert_result(ds, "map2d")
    for j, v in enumerate(xi):
        row = geardyn.bifurcation(device.with_params(xi=v), values=om, **kw)
        for name in ("period", "contact", "force_peak", "force_rms", "dynamic_factor"):
            np.testing.assert_array_equal(ds[name].values[j], row[name].values, err_msg=name)
    one = geardyn.simulate(device.with_params(xi=xi[1]), omega=om[2],
                           run=geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64))
    assert_result(one, "simulation")
    assert ds["period"].values[1, 2] == classify_period(one["poincare"].values[1:])


def test_map_lyapunov_separates_chaos_from_periodic_motion():
    """Omega = 0.92 is chaotic for this gear pair and Omega = 0.5 period-1 (see
    tests/test_lyapunov.py); a map over (Omega, zeta) shows both."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
    ds = geardyn.map2d(g, x=("Omega", [0.5, 0.92]), y=("zeta", [0.02]),
                       run=geardyn.RunSettings(transient=500.0, samples=50), lyapunov=True)
    np.testing.assert_array_equal(ds["period"].values, [[1, 0]])
    lam = ds["lyapunov"].values[0]
    assert lam[0] < -0.005 and lam[1] > 0.02
    assert ds["motion"].values.tolist() == [["period-1", "chaotic"]]
    assert ds.attrs["lyapunov"] == 1 and ds.attrs["x"] == "Omega" and ds.attrs["y"] == "zeta"


@pytest.mark.parametrize("kwargs,match", [
    (dict(x=("Omega", [1.0]), y=("Omega", [2.0])), "different parameters"),
    (dict(x=("Omega", [1.0, math.nan]), y=("zeta", [0.1])), "finite"),
    (dict(x=("Omega", []), y=("zeta", [0.1])), "at least one"),
    (dict(x=("Omega", [1.0]), y=("nonsense", [0.1])), "no parameter"),
])
def test_bad_axes_give_an_error_naming_them(kwargs, match):
    g = geardyn.GearPair()
    with pytest.raises((ValueError, KeyError), match=match):
        geardyn.map2d(g, run=geardyn.RunSettings(transient=10.0, samples=4), **kwargs)


# ------------------------------------------------------------------ plot and estimate
def test_plot_map_legend_lists_the_classes_present(tmp_path):
    g = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    ds = geardyn.map2d(g, x=("Omega", np.linspace(0.5, 3.0, 6)), y=("zeta", [0.03, 0.1]),
                       run=geardyn.RunSettings(transient=200.0, samples=16))
    path = tmp_path / "map.png"
    fig = plot_map(ds, path=path)
    assert path.stat().st_size > 5000
    period_ax, contact_ax = fig.axes[:2]
    legend = [t.get_text() for t in period_ax.get_legend().get_texts()]
    p = ds["period"].values
    assert ("no period found" in legend) == bool(np.any(p == 0))
    assert ("period 1" in legend) == bool(np.any(p == 1))
    regimes = {t.get_text() for t in contact_ax.get_legend().get_texts()}
    assert regimes == set(np.unique(ds["contact"].values))


def test_estimate_counts_the_lane_steps_the_map_takes():
    g = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.2)
    om = np.array([0.5, 1.3, 2.9])
    ds = geardyn.map2d(g, x=("Omega", om), y=("zeta", [0.05, 0.1]),
                       run=geardyn.RunSettings(transient=100.0, samples=8))
    taken = np.sum(ds["steps_per_period"].values * (ds["transient_periods"].values + 8))
    est = estimate_map(g, lanes=6, omegas=om, transient=100.0, samples=8,
                       ns_per_lane_step=100.0)
    assert est.lane_steps == pytest.approx(taken, rel=1e-12)
    # 6 lanes leave vector slots idle: they take as long as busy_lanes(6) lanes
    assert est.busy_share == busy_lanes(6) / 6 > 1.0
    assert est.seconds == pytest.approx(taken * 100e-9 * est.busy_share)
    alone = estimate_map(g, lanes=6, omegas=om, transient=100.0, samples=8,
                         ns_per_lane_step=100.0, blocks=False)
    assert alone.busy_share == 1.0 and alone.seconds == pytest.approx(taken * 100e-9)
    big = estimate_map(g, lanes=10**9, omegas=om, transient=100.0, samples=8)
    assert big.memory_bytes > 10**9 * 8 * g.params.size
    assert big.busy_share == pytest.approx(1.0, rel=1e-6)


@pytest.mark.parametrize("threads", [1, 2, 3, 64])
def test_busy_lanes_are_the_slots_the_schedule_fills(threads):
    """The lanes' worth of time of a run: every thread's share (as the kernels' schedule deals
    the lanes) in whole vectors of SIMD_SLOTS, times the threads (the speed is measured with
    SIMD_SLOTS lanes per thread)."""
    from geardyn.solvers._step_shared import SIMD_SLOTS
    from geardyn.solvers.ensemble import _schedule

    for lanes in (1, 2, 7, 8, 9, 16, 17, 100, 1000):
        start, _ = _schedule(np.ones(lanes), threads)
        widest = int(np.max(np.diff(start)))
        vectors = -(-widest // SIMD_SLOTS)
        assert busy_lanes(lanes, threads) == threads * vectors * SIMD_SLOTS, lanes
        assert busy_lanes(lanes, threads) >= lanes


# ------------------------------------------------------------------ command line
GEAR_STUDY = """
[study]
name = "gp"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.2
Fm = 0.1
Fa = 0.2
[run]
transient = 100.0
periods = 8
"""


def _cli(args, capsys):
    from geardyn.cli.main import main

    with pytest.raises(SystemExit) as exc:
        main(["map", *args])
    captured = capsys.readouterr()
    return exc.value.code, captured.out, captured.err


def test_cli_map_writes_the_map_and_its_figure(tmp_path, capsys):
    from geardyn.io.netcdf import load_dataset

    study = tmp_path / "gp.toml"
    study.write_text(GEAR_STUDY)
    code, out, err = _cli([str(study), "--x", "Omega:0.5:3:6", "--y", "zeta:0.02:0.1:3",
                           "--out", str(tmp_path / "m.nc"), "--plot", str(tmp_path / "m.png")],
                          capsys)
    assert code == 0, err
    assert "18 points" in out and (tmp_path / "m.png").stat().st_size > 5000
    got = load_dataset(tmp_path / "m.nc")
    model = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    want = geardyn.map2d(model, x=("Omega", np.linspace(0.5, 3, 6)),
                         y=("zeta", np.linspace(0.02, 0.1, 3)),
                         run=geardyn.RunSettings(transient=100.0, samples=8))
    np.testing.assert_array_equal(got["period"].values, want["period"].values)
    np.testing.assert_array_equal(got["contact"].values, want["contact"].values)


def test_cli_map_zarr_output_opens_with_plain_xarray_and_redraws(tmp_path, capsys):
    """``--out m.zarr``: the store's root is the map (plain ``xarray.open_zarr``, no warning),
    the same as the API's; ``geardyn plot`` redraws it; a rerun computes nothing again."""
    import warnings

    import xarray as xr

    from geardyn.cli.main import main
    from geardyn.execution.zarr_store import LaneStore

    study = tmp_path / "gp.toml"
    study.write_text(GEAR_STUDY)
    out = tmp_path / "m.zarr"
    args = [str(study), "--x", "Omega:0.5:3:4", "--y", "zeta:0.02:0.1:2", "--out", str(out),
            "--chunk", "3"]
    for run in (1, 2):
        code, _, err = _cli(args, capsys)
        assert code == 0, err
        np.testing.assert_array_equal(LaneStore(out).chunk_runs(), [1, 1, 1])
        assert LaneStore(out).info["runs"] == run
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with xr.open_zarr(out) as opened:
            opened = opened.load()
    model = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    want = geardyn.map2d(model, x=("Omega", np.linspace(0.5, 3, 4)),
                         y=("zeta", np.linspace(0.02, 0.1, 2)),
                         run=geardyn.RunSettings(transient=100.0, samples=8),
                         chunk=3)
    xr.testing.assert_identical(opened, want.assign_attrs(study="gp"))
    with pytest.raises(SystemExit) as exc:
        main(["plot", str(out), "--out", str(tmp_path / "m.png")])
    assert exc.value.code == 0 and (tmp_path / "m.png").stat().st_size > 5000


@pytest.mark.parametrize("axes,field", [
    (["--x", "Omega:0.5:3", "--y", "zeta:0.1:0.2:2"], "--x"),
    (["--x", "Omega:0.5:3:4", "--y", "zeta:a:0.2:2"], "--y"),
    (["--x", "Omega:inf:3:4", "--y", "zeta:0.1:0.2:2"], "--x"),
    (["--x", "Omega:0.5:3:0", "--y", "zeta:0.1:0.2:2"], "--x"),
    (["--x", "Omega:-1:3:4", "--y", "zeta:0.1:0.2:2"], "--x"),
    (["--x", "warp:0.5:3:4", "--y", "zeta:0.1:0.2:2"], "--x"),
    (["--x", "Omega:0.5:3:4", "--y", "Omega:0.1:0.2:2"], "--y"),
    (["--x", "Omega:1e-300:1e-300:2", "--y", "zeta:0.1:0.2:2"], "Omega/transient"),
    (["--x", "Omega:0.5:3:100000", "--y", "zeta:0.1:0.2:100000"], "--x/--y: map too large"),
    # 1.7e13 lane-steps: more than the 1 h limit at any speed above 0.21 ns per lane-step (at
    # 1e9, 1.7e11 lane-steps, a measured speed under 21 ns passed the check and ran for hours);
    # the speed is fixed below, so the refusal does not rest on this machine's load
    (["--x", "Omega:0.5:3:4", "--y", "zeta:0.1:0.2:2", "--transient", "1e11"],
     "--x/--y: map too long"),
])
def test_cli_map_bad_input_is_one_line_naming_the_field(tmp_path, capsys, monkeypatch, axes,
                                                        field):
    import geardyn.analysis.map2d as map2d_module

    monkeypatch.setenv(map2d_module.SPEED_ENV, "300")
    monkeypatch.setattr(map2d_module, "run_lanes", _no_kernel_runs)
    study = tmp_path / "gp.toml"
    study.write_text(GEAR_STUDY)
    code, _, err = _cli([str(study), *axes, "--out", str(tmp_path / "m.nc")], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {field}"), err
    assert not (tmp_path / "m.nc").exists()


def _no_kernel_runs(*args, **kwargs):
    raise AssertionError("a kernel ran: the speed was measured, not taken from the environment")


def test_fixed_speed_replaces_the_measurement(monkeypatch):
    """$GEARDYN_NS_PER_LANE_STEP is the speed the estimates use, and no kernel runs for it; a
    value that is not a positive number is an error naming the variable."""
    import geardyn.analysis.map2d as map2d_module

    g = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.2)
    monkeypatch.setattr(map2d_module, "run_lanes", _no_kernel_runs)
    monkeypatch.setenv(map2d_module.SPEED_ENV, "123.5")
    assert map2d_module.measure_ns_per_lane_step(g, 1.0) == 123.5
    for bad in ("0", "-3", "nan", "inf", "fast"):
        monkeypatch.setenv(map2d_module.SPEED_ENV, bad)
        with pytest.raises(ValueError, match=map2d_module.SPEED_ENV):
            map2d_module.measure_ns_per_lane_step(g, 1.0)
