"""Figures: what is drawn is what the dataset holds (checked through matplotlib's artists)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from matplotlib.collections import PathCollection, QuadMesh
from matplotlib.colors import to_hex

import geardyn
from geardyn.io.netcdf import load_dataset, save_dataset
from geardyn.plotting import plot_bifurcation, plot_simulation
from geardyn.plotting.bifurcation import PERIOD_CLASSES, REGIME_COLORS

PNG = b"\x89PNG\r\n\x1a\n"
PDF = b"%PDF-"
CLASS_OF_COLOR = {to_hex(color): cls for cls, _, color in PERIOD_CLASSES}
LABEL_OF_CLASS = {cls: label for cls, label, _ in PERIOD_CLASSES}


def _synthetic_sweep(lyapunov: bool = True) -> xr.Dataset:
    """A dataset shaped like geardyn.bifurcation's, with every period class, every contact regime
    and the parameter values out of order."""
    omega = np.array([1.3, 0.5, 0.8, 2.0, 1.1, 0.6, 1.7, 0.9])
    period = np.array([1, 2, 3, 4, 6, 0, -1, 1])
    n_samples = 12
    rng = np.random.default_rng(3)
    pc = np.empty((omega.size, n_samples, 2))
    for j, k in enumerate(period):
        if k > 0:
            orbit = rng.normal(size=(k, 2))
            pc[j] = orbit[np.arange(n_samples) % k]
        elif k == 0:
            pc[j] = rng.normal(size=(n_samples, 2))
        else:
            pc[j] = np.nan
    contact = np.array([["none", "single"], ["single", "single"], ["double", "none"],
                        ["none", "none"], ["single", "double"], ["double", "double"],
                        ["unbounded", "unbounded"], ["none", "single"]])
    ds = xr.Dataset(
        {
            "poincare": (("Omega", "sample", "state"), pc),
            "period": ("Omega", period),
            "contact": (("Omega", "mesh"), contact),
        },
        coords={"Omega": omega, "sample": np.arange(n_samples), "state": ["x", "v"],
                "mesh": ["sq", "pq"]},
        attrs={"param": "Omega", "model": "CATTDevice", "transient": 100.0, "samples": 12,
               "continuation": "none", "time_unit": "1"},
    )
    if lyapunov:
        ds["lyapunov"] = ("Omega", np.linspace(-0.05, 0.03, omega.size))
    return ds


def _points_by_class(ax) -> dict[int, set[tuple[float, float]]]:
    out: dict[int, set] = {}
    for coll in ax.collections:
        if isinstance(coll, PathCollection):
            cls = CLASS_OF_COLOR[to_hex(coll.get_facecolor()[0])]
            out.setdefault(cls, set()).update(map(tuple, np.asarray(coll.get_offsets())))
    return out


def test_bifurcation_points_coloured_by_period_class():
    ds = _synthetic_sweep()
    fig = plot_bifurcation(ds, state="v")
    ax = fig.axes[0]
    drawn = _points_by_class(ax)
    expected: dict[int, set] = {}
    for j, k in enumerate(ds["period"].values):
        cls = min(int(k), 5)
        if k < 0:
            continue
        pts = {(float(ds["Omega"][j]), float(y)) for y in ds["poincare"].values[j, :, 1]}
        expected.setdefault(cls, set()).update(pts)
    assert drawn == expected
    # the unbounded value is marked on the top edge
    marks = [ln for ln in ax.lines if ln.get_marker() == "v"]
    assert len(marks) == 1 and list(marks[0].get_xdata()) == [1.7]
    # one legend entry per class present, with the number of values in it
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    counts = {cls: int(np.sum(np.minimum(ds["period"].values, 5) == cls))
              for cls in (1, 2, 3, 4, 5, 0, -1)}
    assert legend == [f"{LABEL_OF_CLASS[c]} ({n})" for c, n in counts.items() if n]
    assert "Omega" in ax.get_title() and "[–]" in ax.get_ylabel()


def test_bifurcation_contact_bands_and_lyapunov_panel():
    ds = _synthetic_sweep()
    fig = plot_bifurcation(ds)
    assert len(fig.axes) == 1 + 2 + 1  # points, two meshes, Lyapunov exponent
    order = np.argsort(ds["Omega"].values)
    names = list(REGIME_COLORS)
    for j, ax in enumerate(fig.axes[1:3]):
        mesh = next(c for c in ax.collections if isinstance(c, QuadMesh))
        codes = np.asarray(mesh.get_array()).ravel()
        assert [names[int(c)] for c in codes] == list(ds["contact"].values[order, j])
        assert ds["mesh"].values[j] in ax.get_ylabel()
    ax_l = fig.axes[3]
    lines = [ln for ln in ax_l.lines if ln.get_linestyle() == "-"]
    curve = next(ln for ln in lines if len(ln.get_xdata()) == ds.sizes["Omega"])
    np.testing.assert_array_equal(curve.get_ydata(), ds["lyapunov"].values[order])
    zero = [ln for ln in lines if list(ln.get_ydata()) == [0, 0]]
    assert zero, "no zero line"
    assert ax_l.get_ylabel().endswith(r"[1/$\tau$]")  # per unit of dimensionless time
    assert ax_l.get_xlabel() == r"$\Omega = \omega/\omega_n$ [–]"  # on the bottom panel only
    assert fig.axes[0].get_xlabel() == ""
    # without a Lyapunov exponent: no such panel
    assert len(plot_bifurcation(_synthetic_sweep(lyapunov=False)).axes) == 3


def test_bifurcation_state_choice_and_errors():
    ds = _synthetic_sweep()
    ds.attrs["plot_state"] = "v"
    fig = plot_bifurcation(ds)
    ys = {y for pts in _points_by_class(fig.axes[0]).values() for _, y in pts}
    assert ys <= set(ds["poincare"].values[..., 1].ravel().tolist())
    with pytest.raises(ValueError, match="'X_pq'.*known: x, v"):
        plot_bifurcation(ds, state="X_pq")


def test_real_sweep_figure_files_and_round_trip(tmp_path):
    g = geardyn.GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
    ds = geardyn.bifurcation(g, values=np.linspace(0.6, 1.4, 9),
                             run=geardyn.RunSettings(transient=200.0, samples=8),
                             starts=2, lyapunov=True)
    for name, magic in (("bif.png", PNG), ("bif.pdf", PDF)):
        plot_bifurcation(ds, path=tmp_path / name)
        assert (tmp_path / name).read_bytes()[: len(magic)] == magic
    # several starts: every sample is coloured by its own start's period
    drawn = _points_by_class(plot_bifurcation(ds).axes[0])
    by_start = ds["period_by_start"].values[:, ds["start_of_sample"].values]
    for cls, pts in drawn.items():
        j, s = np.nonzero(np.minimum(by_start, 5) == cls)
        assert pts == {(float(ds["Omega"][a]), float(ds["poincare"][a, b, 0]))
                       for a, b in zip(j, s, strict=True)}
    # the figure of the saved file is the same figure
    back = load_dataset(save_dataset(ds, tmp_path / "bif.nc"))
    assert _points_by_class(plot_bifurcation(back).axes[0]) == drawn


# --------------------------------------------------------------------------- single points
def _synthetic_simulation(components, omega=1.1, lam=0.1375, periods=64, per_period=64):
    dt = 2 * math.pi / omega / per_period
    t = np.arange(periods * per_period + 1) * dt
    x = sum(a * np.cos(f * omega * t) for f, a in components)
    v = sum(-a * f * omega * np.sin(f * omega * t) for f, a in components)
    idx = np.arange(0, t.size, per_period)
    return xr.Dataset(
        {"X_sq": ("time", x, {"units": "1"}), "V_sq": ("time", v, {"units": "1"}),
         "poincare": (("sample", "state"), np.column_stack([x[idx], v[idx]])),
         "poincare_time": ("sample", t[idx])},
        coords={"time": ("time", t, {"units": "1"}), "sample": np.arange(idx.size),
                "state": ["X_sq", "V_sq"]},
        attrs={"model": "CATTDevice", "Omega": omega, "period": 2 * math.pi / omega,
               "periods": periods, "Lambda": lam, "status": 0, "time_unit": "1"},
    )


def _spectrum_labels(fig) -> set[str]:
    return {t.get_text() for t in fig.axes[3].texts}


def test_simulation_figure_labels_harmonics_subharmonics_and_sidebands(tmp_path):
    lam_ratio = 0.125  # Lambda / Omega, on the frequency grid of 64 periods
    comps = [(1.0, 1.0), (2.0, 0.2), (0.5, 0.05), (1 - lam_ratio, 0.08), (1 + lam_ratio, 0.08)]
    ds = _synthetic_simulation(comps, lam=1.1 * lam_ratio)
    fig = plot_simulation(ds, "X_sq", path=tmp_path / "sim.pdf")
    assert _spectrum_labels(fig) == {"Ω", "2Ω", "Ω/2", "Ω−Λ", "Ω+Λ"}
    assert (tmp_path / "sim.pdf").read_bytes()[:5] == PDF
    # the labels sit on the peaks: at the line's frequency and amplitude
    spots = {t.get_text(): t.xy for t in fig.axes[3].texts}
    assert spots["2Ω"][0] == pytest.approx(2.0) and spots["2Ω"][1] == pytest.approx(0.2)
    # no load fluctuation known: the sidebands are not named as such
    ds.attrs.pop("Lambda")
    assert not {"Ω−Λ", "Ω+Λ"} & _spectrum_labels(plot_simulation(ds, "X_sq"))


@pytest.mark.parametrize(("omega", "period"), [(0.8, 1), (0.95, 2)])
def test_simulation_spectrum_shows_the_subharmonic_of_a_period_two_motion(omega, period):
    """The gear pair's period from its Poincaré points (bifurcation) and from its spectrum
    (an Ω/2 line) agree."""
    g = geardyn.GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
    sweep = geardyn.bifurcation(g, values=[omega],
                                run=geardyn.RunSettings(transient=500.0, samples=32))
    assert int(sweep["period"][0]) == period
    ds = geardyn.simulate(g, omega=omega, run=geardyn.RunSettings(transient=500.0, samples=32))
    labels = _spectrum_labels(plot_simulation(ds, "x"))
    assert "Ω" in labels
    assert ("Ω/2" in labels) == (period == 2)


@pytest.mark.parametrize(("param", "model", "label"), [
    ("backlash", "CATTDevice", "backlash $b$ [m]"),
    ("B1", "CATTDevice", "$B_1$ [N m]"),
    ("xi1", "CATTDevice", r"$\xi_1$ [–]"),
    ("backlash", "GearPair", "backlash $b$ [–]"),  # the gear pair is dimensionless
])
def test_swept_parameter_axis_label_has_units(param, model, label):
    ds = _synthetic_sweep(lyapunov=False).rename(Omega=param)
    ds.attrs.update(param=param, model=model)
    assert plot_bifurcation(ds).axes[-1].get_xlabel() == label
