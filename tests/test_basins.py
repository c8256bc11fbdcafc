"""geardyn.basins: the attractor of every initial condition of a grid, checked against Newton
shooting (geardyn.periodic_orbit), the reference integrator (scipy DOP853, rtol 1e-12) and the
linear steady state."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.analysis.basins import basins_run
from geardyn.testing import assert_result

#: The softening gear pair (contact loss) of the hysteresis band: up and down continued sweeps
#: of this pair disagree for 0.72 <= Omega <= 0.82 (no contact loss up, single-sided impacts
#: down; see tests/test_frc.py).
PAIR = dict(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
OMEGA = 0.78
TRANSIENT = 300.0  # decay exp(-zeta T) = 3e-7 of the transient


@pytest.fixture(scope="module")
def bistable():
    g = geardyn.GearPair(**PAIR)
    ds = geardyn.basins(g, omega=OMEGA, x=("x", -1.0, 3.0, 20), y=("v", -1.5, 1.5, 16),
                        run=basins_run(transient=TRANSIENT))
    return g, ds


def _interior_cell(ids: np.ndarray, a: int) -> tuple[int, int]:
    """The grid cell of attractor ``a`` with the most neighbours (of 8) that share it."""
    best, where = -1, (0, 0)
    ny, nx = ids.shape
    for i in range(ny):
        for j in range(nx):
            if ids[i, j] != a:
                continue
            block = ids[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2]
            score = int(np.sum(block == a))
            if score > best:
                best, where = score, (i, j)
    return where


def _reference_end(g, y0: np.ndarray, periods: int) -> np.ndarray:
    T = 2 * math.pi / OMEGA
    return geardyn.reference_solution(g.with_omega(OMEGA), y0, np.array([periods * T]))[-1]


def test_two_attractors_in_the_hysteresis_band_match_shooting_and_reference(bistable):
    g, ds = bistable
    assert_result(ds, "basins")
    assert ds.attrs["n_attractors"] == 2
    np.testing.assert_array_equal(ds["attractor_period"].values, [1, 1])
    assert set(ds["attractor_contact"].values[:, 0]) == {"none", "single"}
    ids = ds["attractor_id"].values
    xs, vs = ds["x"].values, ds["v"].values
    periods = math.ceil(TRANSIENT * OMEGA / (2 * math.pi))
    orbits = []
    for a in range(2):
        i, j = _interior_cell(ids, a)
        y0 = np.array([xs[j], vs[i]])
        # the reference integrator from the same initial state lands on the same attractor
        end = _reference_end(g, y0, periods)
        point = ds["attractor_point"].values[a, 0]
        assert np.max(np.abs(end - point)) < 1e-4, (a, end, point)
        # Newton shooting from the reference end state finds the attractor's fixed point
        orb = geardyn.periodic_orbit(g, omega=OMEGA, guess=end)
        assert orb.converged and orb.stable, orb.message
        np.testing.assert_allclose(orb.x, point, atol=1e-6)
        orbits.append(orb)
    # passed in (in reverse order), the orbits are matched to their attractors
    again = geardyn.basins(g, omega=OMEGA, x=("x", -1.0, 3.0, 20), y=("v", -1.5, 1.5, 16),
                           run=basins_run(transient=TRANSIENT), orbits=orbits[::-1])
    np.testing.assert_array_equal(again["attractor_orbit"].values, [1, 0])
    np.testing.assert_array_equal(again["attractor_id"].values, ids)


def test_fractions_sum_to_one_with_diverged_cells_apart(bistable):
    _, ds = bistable
    frac = ds["attractor_fraction"].values
    assert np.all(frac > 0) and frac[0] >= frac[1]
    assert ds.attrs["diverged_fraction"] == 0.0
    assert math.isclose(frac.sum(), 1.0, rel_tol=1e-12)
    cells = ds["attractor_cells"].values
    np.testing.assert_array_equal(cells, [np.sum(ds["attractor_id"].values == a) for a in (0, 1)])


def test_linear_case_has_one_attractor_the_analytic_steady_state():
    """Always in contact (large mean load): one attractor with fraction 1, its section point the
    linear steady state; cells started beyond the bound diverge and are counted apart."""
    zeta, fm, fa, om = 0.05, 2.0, 0.02, 1.3
    g = geardyn.GearPair(zeta=zeta, kappa=0.0, Fm=fm, Fa=fa)
    ds = geardyn.basins(g, omega=om, x=("x", 2.0, 4.0, 6), y=("v", -0.5, 0.5, 5),
                        run=basins_run(transient=400.0, samples=4, max_period=2))
    assert_result(ds, "basins")
    assert ds.attrs["n_attractors"] == 1
    np.testing.assert_array_equal(ds["attractor_fraction"].values, [1.0])
    assert np.all(ds["attractor_id"].values == 0)
    amp = fa * om**2 / (1 - om**2 + 2j * zeta * om)
    expect = np.array([fm + 1.0 + amp.real, -om * amp.imag])  # x = Fm + b + Re(A e^{i om t})
    np.testing.assert_allclose(ds["attractor_point"].values[0, 0], expect, atol=1e-7)
    # a bound that the first forcing period of the far cells leaves (amplitude ~37 e^{-zeta T}
    # ~ 29 about x = 3; |state| is checked once a period): they diverge, never dropped
    out = geardyn.basins(g, omega=om, x=("x", 2.0, 40.0, 6), y=("v", -0.5, 0.5, 5),
                         run=basins_run(transient=400.0, samples=4, max_period=2, bound=10.0))
    ids = out["attractor_id"].values
    assert np.all(ids[:, -1] == -1) and np.all(ids[:, 0] == 0)
    np.testing.assert_array_equal(out["status"].values == 1, ids == -1)
    assert out.attrs["diverged_cells"] == np.sum(ids == -1)
    assert math.isclose(out["attractor_fraction"].values.sum() + out.attrs["diverged_fraction"],
                        1.0, rel_tol=1e-12)


def test_a_chaotic_attractor_is_one_attractor_without_period():
    """The gear pair that tests/test_lyapunov.py shows chaotic (nearby trajectories separate):
    every cell reaches it; non-periodic lanes are grouped by their section points' extent.
    The extent of 64 section points is too rough an estimate for a 10 % tolerance: a change of
    the forcing phase's rounding (1e-16) split one cell of 20 off at 64 samples; at 128 and 256
    every cell groups as one."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3, Omega=0.92)
    ds = geardyn.basins(g, None, ("x", 0.0, 2.0, 5), ("v", -1.0, 1.0, 4),
                        run=basins_run(transient=500.0, samples=256, converge=None))
    assert np.all(ds["period"].values == 0)
    np.testing.assert_array_equal(ds["attractor_period"].values, [0])
    np.testing.assert_array_equal(ds["attractor_fraction"].values, [1.0])
    assert np.all(np.isfinite(ds["attractor_point"].values[0, 0]))


def test_orbits_at_another_frequency_are_refused(bistable):
    from geardyn.analysis.basins import match_orbits

    g, ds = bistable
    with pytest.raises(ValueError, match="Omega"):
        match_orbits(ds, [geardyn.periodic_orbit(g, omega=0.9)])


def test_bad_input_is_named():
    g = geardyn.GearPair(**PAIR)
    with pytest.raises(ValueError, match="X_sq"):
        geardyn.basins(g, omega=OMEGA, x=("X_sq", 0, 1, 3), y=("v", 0, 1, 3))
    with pytest.raises(ValueError, match="another state"):
        geardyn.basins(g, omega=OMEGA, x=("x", 0, 1, 3), y=("x", 0, 1, 3))
    with pytest.raises(ValueError, match="n must be"):
        geardyn.basins(g, omega=OMEGA, x=("x", 0, 1, 0), y=("v", 0, 1, 3))


STUDY = """
[study]
name = "softening"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.0
Fm = 0.1
Fa = 0.05
[run]
transient = 300.0
omega = 0.78
"""


def _invoke(*args):
    from typer.testing import CliRunner

    from geardyn.cli.main import app

    result = CliRunner().invoke(app, [str(a) for a in args])
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception
    return result


def test_cli_writes_what_the_api_computes_and_draws_it(tmp_path, bistable):
    from geardyn.io.netcdf import load_dataset

    g, direct = bistable
    study = tmp_path / "soft.toml"
    study.write_text(STUDY)
    nc, png = tmp_path / "b.nc", tmp_path / "b.png"
    r = _invoke("basins", study, "--x", "x:-1:3:20", "--y", "v:-1.5:1.5:16", "--orbit-period",
                "1", "--quiet", "--out", nc, "--plot", png)
    assert r.exit_code == 0, r.output
    assert "#0 period-1" in r.stdout and "diverged 0.0%" in r.stdout
    saved = load_dataset(nc)
    assert_result(saved, "basins")
    np.testing.assert_array_equal(saved["attractor_id"].values, direct["attractor_id"].values)
    # each attractor matched to the Newton orbit started from its own section point
    np.testing.assert_array_equal(saved["attractor_orbit"].values, [0, 1])
    assert png.read_bytes()[:4] == b"\x89PNG"
    # a bad state: one line naming the option
    r = _invoke("basins", study, "--x", "X_sq:-1:3:4", "--y", "v:-1:1:4", "--quiet")
    assert r.exit_code == 2 and "--x" in r.stderr and "not a state" in r.stderr


def test_figure_marks_every_attractor_and_the_diverged_cells(tmp_path, bistable):
    from geardyn.plotting.basins import plot_basins

    _, ds = bistable
    fig = plot_basins(ds, path=tmp_path / "b.pdf")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert len(labels) == 2 and labels[0].startswith("#0: period-1")
    assert (tmp_path / "b.pdf").read_bytes()[:5] == b"%PDF-"
    ds = ds.copy()
    ds["attractor_id"][0, 0] = -1
    fig = plot_basins(ds)
    assert any("diverged" in t.get_text() for t in fig.axes[0].get_legend().get_texts())


def test_plot_command_redraws_a_saved_basins_result(tmp_path, bistable):
    from geardyn.io.netcdf import save_dataset

    _, ds = bistable
    nc = tmp_path / "b.nc"
    save_dataset(ds, nc)
    r = _invoke("plot", nc, "--out", tmp_path / "again.png")
    assert r.exit_code == 0, r.output
    assert "basins dataset" in r.stdout and (tmp_path / "again.png").exists()


# -- unresolved cells ----------------------------------------------------------------------------

#: Always in contact (the linear case above): one attractor, the analytic steady state.
LINEAR = dict(zeta=0.05, kappa=0.0, Fm=2.0, Fa=0.02)
LINEAR_OMEGA = 1.3


def _linear_steady_state() -> np.ndarray:
    zeta, fm, fa, om = LINEAR["zeta"], LINEAR["Fm"], LINEAR["Fa"], LINEAR_OMEGA
    amp = fa * om**2 / (1 - om**2 + 2j * zeta * om)
    return np.array([fm + 1.0 + amp.real, -om * amp.imag])


def test_cells_whose_transient_did_not_settle_are_unresolved_not_an_attractor():
    """A transient budget too short for the far cells (converge 1e-3, transient_max 120): the
    cells that settled form the one attractor, the analytic steady state; every cell that hit
    transient_max unsettled gets id -2, is flagged in ``unresolved`` and counted apart, and no
    attractor is made of them (drifting by ~1e-3 a period, they would otherwise be grouped as a
    'no period' attractor)."""
    g = geardyn.GearPair(**LINEAR)
    ds = geardyn.basins(g, omega=LINEAR_OMEGA, x=("x", 2.0, 4.0, 6), y=("v", -0.5, 0.5, 5),
                        run=basins_run(transient=20.0, transient_max=120.0, converge=1e-3,
                                       samples=4, max_period=2))
    assert_result(ds, "basins")
    settled = ds["converged"].values == 1
    assert settled.any() and (~settled).any()  # both kinds present: the check has teeth
    ids = ds["attractor_id"].values
    np.testing.assert_array_equal(ids == -2, ~settled)
    np.testing.assert_array_equal(ds["unresolved"].values, (~settled).astype(np.int8))
    assert ds.attrs["n_attractors"] == 1 and np.all(ids[settled] == 0)
    np.testing.assert_allclose(ds["attractor_point"].values[0, 0], _linear_steady_state(),
                               atol=2e-2)
    assert ds.attrs["unresolved_cells"] == int(np.sum(~settled))
    assert ds.attrs["diverged_cells"] == 0
    assert math.isclose(ds["attractor_fraction"].values.sum() + ds.attrs["unresolved_fraction"],
                        1.0, rel_tol=1e-12)


def test_cells_at_the_split_limit_are_unresolved_not_diverged(monkeypatch):
    """Lanes whose steps reached the edge-split limit (the kernel's count ``unresolved`` > 0,
    or status SPLIT_LIMIT) are set here on a fixed-transient run of the linear case: they get
    id -2 (not an attractor, not diverged), the others the one attractor."""
    import geardyn.analysis.basins as basins_module
    from geardyn.core.status import Status

    real = basins_module.run_lanes
    marked = {3: ("steps", 5), 7: ("status", Status.SPLIT_LIMIT), 12: ("steps", 1)}

    def run_lanes(model, P, y0, run):
        r = real(model, P, y0, run=run)
        for lane, (what, value) in marked.items():
            if what == "steps":
                r.unresolved[lane] = value
            else:
                r.status[lane] = value
        return r

    monkeypatch.setattr(basins_module, "run_lanes", run_lanes)
    g = geardyn.GearPair(**LINEAR)
    ds = geardyn.basins(g, omega=LINEAR_OMEGA, x=("x", 2.0, 4.0, 6), y=("v", -0.5, 0.5, 5),
                        run=basins_run(transient=400.0, samples=4, max_period=2, converge=None))
    assert_result(ds, "basins")
    ids = ds["attractor_id"].values.ravel()
    want = np.zeros(ids.size, np.int64)
    want[list(marked)] = -2
    np.testing.assert_array_equal(ids, want)
    assert ds.attrs["n_attractors"] == 1 and ds.attrs["diverged_cells"] == 0
    assert ds.attrs["unresolved_cells"] == len(marked)
    assert ds["unresolved_steps"].values.ravel()[3] == 5
    np.testing.assert_allclose(ds["attractor_point"].values[0, 0], _linear_steady_state(),
                               atol=1e-7)


def test_figure_and_summary_show_the_unresolved_cells(bistable):
    from geardyn.cli.basins import _summary
    from geardyn.plotting.basins import plot_basins

    _, ds = bistable
    ds = ds.copy(deep=True)
    ds["attractor_id"][0, 0] = -2
    ds.attrs["unresolved_fraction"] = 1 / ds["attractor_id"].size
    labels = [t.get_text() for t in plot_basins(ds).axes[0].get_legend().get_texts()]
    assert any(t.startswith("unresolved") for t in labels)
    assert "unresolved 0.3%" in _summary(ds)
