"""The figure of a continued branch (geardyn.plotting.branch): one line per stability segment,
solid where stable and dashed where not, a labelled marker per located bifurcation, the
multipliers on the unit circle, the brute-force diagram under the branch."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.plotting.branch import plot_branch

PNG = b"\x89PNG\r\n\x1a\n"
PDF = b"%PDF-"
LABELS = {"fold": "LP", "period-doubling": "PD", "neimark-sacker": "NS", "contact": "CC"}


@pytest.fixture(scope="module")
def soft() -> xr.Dataset:
    """The softening gear pair's period-1 branch through its two folds (stable, unstable,
    stable) and a contact change."""
    return geardyn.continuation(geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05), "Omega", 0.6, 1.0)


@pytest.fixture(scope="module")
def doubled() -> xr.Dataset:
    """A period-1 branch with two period doublings and the period-2 branches switched to."""
    m = geardyn.GearPair(zeta=0.02, Fm=0.1, Fa=0.1, kappa=0.2)
    return geardyn.continuation(m, "Omega", 1.9, 1.5, switch=True,
                                settings=geardyn.ContinuationSettings(max_period=2))


def _runs(ds: xr.Dataset) -> list[tuple[int, bool]]:
    """(branch, stable) of each run of equally stable points, counted point by point."""
    runs: list[tuple[int, bool]] = []
    prev = None
    for b, s in zip(ds["branch"].values, ds["stability"].values, strict=True):
        key = (int(b), str(s) == "stable")
        if key != prev:
            runs.append(key)
        prev = key
    return runs


def _lines(ax, gid: str) -> list:
    return [ln for ln in ax.lines if ln.get_gid() == gid]


@pytest.mark.parametrize("case", ["soft", "doubled"])
def test_one_solid_line_per_stable_and_dashed_per_unstable_segment(case, request):
    ds = request.getfixturevalue(case)
    runs = _runs(ds)
    assert any(s for _, s in runs) and any(not s for _, s in runs)  # both kinds drawn
    fig = plot_branch(ds)
    ax = fig.axes[0]
    solid, dashed = _lines(ax, "branch-stable"), _lines(ax, "branch-unstable")
    assert len(solid) == sum(s for _, s in runs)
    assert len(dashed) == sum(not s for _, s in runs)
    assert all(ln.get_linestyle() == "-" for ln in solid)
    assert all(ln.get_linestyle() == "--" for ln in dashed)
    # each line runs over its segment's points (and on to the next segment's first point),
    # the section coordinate against the parameter
    om, x0 = ds["Omega"].values, ds["section_point"].sel(state="x").values
    stable = ds["stability"].values == "stable"
    covered: set[int] = set()
    for ln in solid + dashed:
        idx = [int(np.flatnonzero((om == u) & (x0 == v))[0])
               for u, v in zip(ln.get_xdata(), ln.get_ydata(), strict=True)]
        assert np.all(stable[idx[:-1]] == (ln.get_gid() == "branch-stable"))
        assert np.all(np.diff(idx) == 1)  # consecutive points of one branch
        covered.update(idx)
    assert covered == set(range(ds.sizes["point"]))  # every point is on a line


@pytest.mark.parametrize("case", ["soft", "doubled"])
def test_a_labelled_marker_per_located_bifurcation(case, request):
    ds = request.getfixturevalue(case)
    kinds = [str(k) for k in ds["bifurcation_kind"].values]
    assert kinds
    fig = plot_branch(ds)
    ax = fig.axes[0]
    markers = _lines(ax, "bifurcation")
    labels = [t for t in ax.texts if t.get_gid() == "bifurcation-label"]
    assert len(markers) == len(labels) == len(kinds)
    np.testing.assert_array_equal([ln.get_xdata()[0] for ln in markers],
                                  ds["bifurcation_value"].values)
    assert [t.get_text() for t in labels] == [LABELS[k] for k in kinds]
    # the marker sits at the located section point
    np.testing.assert_array_equal([ln.get_ydata()[0] for ln in markers],
                                  ds["bifurcation_section_point"].sel(state="x").values)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    for k in set(kinds):
        assert any(t.startswith(LABELS[k] + ":") for t in legend)
    assert "stable" in legend and "unstable" in legend


def test_multipliers_on_the_unit_circle_coloured_by_the_parameter(soft):
    fig = plot_branch(soft)
    ax = fig.axes[1]
    circle = _lines(ax, "unit-circle")[0]
    np.testing.assert_allclose(np.hypot(circle.get_xdata(), circle.get_ydata()), 1.0)
    mu = soft["multiplier_real"].values + 1j * soft["multiplier_imag"].values
    shown = np.abs(mu) <= 2.5
    (points,) = ax.collections
    offsets = points.get_offsets()
    assert len(offsets) == int(shown.sum())
    np.testing.assert_allclose(offsets[:, 0] + 1j * offsets[:, 1], mu[shown])
    colours = np.asarray(points.get_array())
    np.testing.assert_array_equal(colours, np.broadcast_to(
        soft["Omega"].values[:, None], mu.shape)[shown])
    without = plot_branch(soft, multipliers=False)
    assert len(without.axes) == 1


def test_amplitude_against_the_parameter(soft):
    fig = plot_branch(soft, quantity="deflection_rms")
    ax = fig.axes[0]
    om = soft["Omega"].values
    rms = soft["deflection_rms"].sel(mesh="mesh").values
    for ln in _lines(ax, "branch-stable") + _lines(ax, "branch-unstable"):
        idx = [int(np.flatnonzero(om == v)[0]) for v in ln.get_xdata()]
        np.testing.assert_array_equal(ln.get_ydata(), rms[idx])
    # a marker between the two points either side of its value
    for ln, j in zip(_lines(ax, "bifurcation"), range(soft.sizes["bifurcation"]), strict=True):
        i = int(soft["bifurcation_point"].values[j])
        lo, hi = sorted(rms[i:i + 2])
        assert lo - 1e-12 <= ln.get_ydata()[0] <= hi + 1e-12
    assert "deflection rms" in ax.get_ylabel()
    with pytest.raises(ValueError, match="quantity"):
        plot_branch(soft, quantity="nothing")
    with pytest.raises(ValueError, match="mesh"):
        plot_branch(soft, quantity="deflection_rms", mesh="ring")


def test_over_the_brute_force_diagram_and_files(soft, tmp_path):
    m = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05)
    run = geardyn.RunSettings(transient=100.0, samples=4, steps_per_period=64)
    bif = geardyn.bifurcation(m, "Omega", np.linspace(0.6, 1.0, 5), run)
    fig = plot_branch(soft, tmp_path / "b.png", over=bif)
    (points,) = fig.axes[0].collections
    assert len(points.get_offsets()) == int(np.isfinite(bif["poincare"].sel(state="x")).sum())
    assert any("brute-force" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    assert (tmp_path / "b.png").read_bytes()[:8] == PNG
    plot_branch(soft, tmp_path / "b.pdf", over=bif, quantity="dynamic_factor")
    assert (tmp_path / "b.pdf").read_bytes()[:5] == PDF
    other = geardyn.bifurcation(m.with_omega(0.9), "Fa", [0.04, 0.05], run)
    with pytest.raises(ValueError, match="sweeps Fa"):
        plot_branch(soft, over=other)
    with pytest.raises(ValueError, match="no 'deflection_rms'"):
        plot_branch(soft, over=bif, quantity="deflection_rms")
    with pytest.raises(ValueError, match="not a continuation"):
        plot_branch(bif)


def test_a_branch_that_ended_early_says_so(soft):
    short = geardyn.continuation(geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05), "Omega", 0.6,
                                 1.0, settings=geardyn.ContinuationSettings(max_points=4))
    fig = plot_branch(short)
    assert "ended early" in fig.get_suptitle() and "4 points" in fig.get_suptitle()
    assert "ended early" not in plot_branch(soft).get_suptitle()
    # nothing continued at all: an empty figure with the reason
    none = geardyn.continuation(geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05), "Omega", 0.9,
                                1.0, guess=np.array([3.0, 2.0]),
                                settings=geardyn.ContinuationSettings(tol=1e-300))
    assert none.sizes["point"] == 0
    fig = plot_branch(none)
    assert not _lines(fig.axes[0], "branch-stable") and "Omega=0.9" in fig.get_suptitle()
