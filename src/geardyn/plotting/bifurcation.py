"""The bifurcation diagram: Poincaré points against the swept parameter, coloured by period,
with the contact-loss regime of every mesh in a band under it and the largest Lyapunov exponent
below when the sweep computed it."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC, param_label, state_label, time_unit_label, unit_text

__all__ = ["PERIOD_CLASSES", "REGIME_COLORS", "period_class", "plot_bifurcation",
           "resolve_sweep_state"]

#: Period classes of the legend: (class, label, colour). Class 5 stands for every period >= 5;
#: class 0 is "no period <= max_period found" (chaotic, quasi-periodic, longer or unsettled).
PERIOD_CLASSES: tuple[tuple[int, str, str], ...] = (
    (1, "period 1", "#1f77b4"),
    (2, "period 2", "#2ca02c"),
    (3, "period 3", "#9467bd"),
    (4, "period 4", "#ff7f0e"),
    (5, "other periodic (≥ 5)", "#8c564b"),
    (0, "no period found", "#7f7f7f"),
    (-1, "unbounded", "#d62728"),
)
OTHER_PERIODIC = 5

#: Colours of the contact-loss regimes (see :mod:`geardyn.analysis.contact`).
REGIME_COLORS: dict[str, str] = {
    "none": "#c7e9c0",
    "single": "#fdae6b",
    "double": "#e6550d",
    "unbounded": "#252525",
}


def period_class(period: np.ndarray) -> np.ndarray:
    """Legend class of each period: 1-4 as they are, 5 for any longer period, 0 and -1 kept."""
    p = np.asarray(period)
    return np.where(p >= OTHER_PERIODIC, OTHER_PERIODIC, p)


def resolve_sweep_state(ds: xr.Dataset, state: str | None = None) -> str:
    """The state of a bifurcation dataset to show: ``state`` (or planet set 1's, ``X_sq`` ->
    ``X_sq1``), else the dataset's ``plot_state`` attribute, ``X_sq`` or ``x``, else the first."""
    states = [str(s) for s in ds["state"].values]
    wanted = [state] if state is not None else [ds.attrs.get("plot_state"), "X_sq", "x"]
    for name in wanted:
        if name is None:
            continue
        for candidate in (name, f"{name}1"):
            if candidate in states:
                return candidate
    if state is not None:
        raise ValueError(f"state: {state!r} is not a state of the sweep; known: "
                         f"{', '.join(states)}")
    return states[0]


def _sample_classes(ds: xr.Dataset, param: str) -> np.ndarray:
    """Period class of every (value, sample): each start's own when several starts were run."""
    if "period_by_start" in ds and "start_of_sample" in ds:
        by_start = ds["period_by_start"].transpose(param, ...).values
        return period_class(by_start[:, ds["start_of_sample"].values])
    period = ds["period"].values
    return np.broadcast_to(period_class(period)[:, None], (period.size, ds.sizes["sample"]))


def _edges(x: np.ndarray) -> np.ndarray:
    """Cell edges around sorted values ``x`` (midpoints; half a spacing beyond the ends)."""
    if x.size == 1:
        half = 0.5 * (abs(x[0]) or 1.0) * 0.02
        return np.array([x[0] - half, x[0] + half])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[2 * x[0] - mid[0]], mid, [2 * x[-1] - mid[-1]]])


def _draw_points(ax, x, y, classes) -> None:
    from matplotlib.lines import Line2D

    xx = np.broadcast_to(x[:, None], y.shape)
    handles = []
    for cls, label, color in PERIOD_CLASSES:
        mask = classes == cls
        n_values = int(np.count_nonzero(mask.any(axis=1)))
        if not n_values:
            continue
        if cls == -1:  # no finite points: mark the values on the top edge
            ax.plot(x[mask.any(axis=1)], np.full(n_values, 0.98), "v", color=color, ms=4,
                    transform=ax.get_xaxis_transform(), clip_on=False)
            marker = "v"
        else:
            keep = mask & np.isfinite(y)
            ax.scatter(xx[keep], y[keep], s=1.5 if cls else 0.6, c=color, linewidths=0,
                       rasterized=True)
            marker = "o"
        handles.append(Line2D([], [], ls="", marker=marker, ms=5, color=color,
                              label=f"{label} ({n_values})"))
    ax.figure.legend(handles=handles, loc="outside right upper", title="period (values)")


def _draw_regimes(ax_main, axes, ds, param, order, edges) -> None:
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    names = list(REGIME_COLORS)
    cmap = ListedColormap([REGIME_COLORS[n] for n in names])
    norm = BoundaryNorm(np.arange(len(names) + 1) - 0.5, cmap.N)
    contact = ds["contact"].transpose(param, "mesh").values[order]
    seen: set[str] = set()
    for ax, j in zip(axes, range(contact.shape[1]), strict=True):
        labels = contact[:, j].astype(str)
        codes = np.array([names.index(s) if s in names else names.index("unbounded")
                          for s in labels])
        seen.update(labels)
        ax.pcolormesh(edges, [0.0, 1.0], codes[None, :], cmap=cmap, norm=norm, rasterized=True)
        ax.set_yticks([])
        ax.grid(False)
        ax.set_ylabel(f"contact\n{ds['mesh'].values[j]}", rotation=0, ha="right", va="center")
    handles = [Patch(color=REGIME_COLORS[n], label=n) for n in names if n in seen]
    ax_main.figure.legend(handles=handles, loc="outside right lower",
                          title="contact loss (bands)")


def _title(ds: xr.Dataset, name: str, param: str) -> str:
    a = ds.attrs
    who = a.get("study") or a.get("model", "model")
    interp = f", {a['interpretation']}" if "interpretation" in a else ""
    settings = []
    if "transient" in a:
        settings.append(f"transient {float(a['transient']):g}")
    if "samples" in a:
        settings.append(f"{a['samples']} periods sampled")
    if "continuation" in a:
        settings.append(f"continuation {a['continuation']}")
    return f"{who}{interp}: {name} against {param}" + (
        f"; {', '.join(settings)}" if settings else "")


def _state_unit(ds: xr.Dataset, name: str) -> str | None:
    """The unit of state ``name`` from the dataset's ``state_units`` (one unit for all
    states, or one per state separated by commas, as ``Model.state_units``)."""
    units = ds.attrs.get("state_units")
    if units is None:
        return None
    parts = [u.strip() for u in str(units).split(",")]
    names = [str(n) for n in ds["state"].values]
    if len(parts) == 1:
        return parts[0]
    return parts[names.index(name)] if len(parts) == len(names) else None


def plot_bifurcation(ds: xr.Dataset, state: str | None = None,
                     path: str | os.PathLike | None = None):
    """Bifurcation diagram of a dataset from :func:`geardyn.bifurcation` (or its NetCDF file).

    Parameters
    ----------
    state
        The state whose Poincaré points are drawn (default: the dataset's ``plot_state``
        attribute, else ``X_sq`` or ``x``, else the first state).
    path
        Where to save the figure; the suffix picks the format (.png, .pdf, .svg). None: only
        return it.

    Returns
    -------
    matplotlib.figure.Figure: Poincaré points coloured by period class (legend: classes with the
    number of parameter values in each), one contact-regime band per mesh, and the largest
    Lyapunov exponent with a zero line when ``ds`` has ``lyapunov``.
    """
    import matplotlib
    from matplotlib.figure import Figure

    param = str(ds.attrs.get("param", ds["poincare"].dims[0]))
    name = resolve_sweep_state(ds, state)
    x = np.asarray(ds[param].values, dtype=float)
    y = ds["poincare"].sel(state=name).transpose(param, "sample").values
    classes = _sample_classes(ds, param)
    order = np.argsort(x, kind="stable")
    edges = _edges(x[order])
    meshes = list(ds["mesh"].values) if "contact" in ds and "mesh" in ds.dims else []
    has_lyap = "lyapunov" in ds
    xlabel = param_label(param, str(ds.attrs.get("model", "")), ds[param].attrs.get("units"))

    heights = [6.0] + [0.35] * len(meshes) + ([2.2] if has_lyap else [])
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(10.0, 4.2 + 0.3 * len(meshes) + (1.6 if has_lyap else 0.0)),
                     layout="constrained")
        axes = fig.subplots(len(heights), 1, sharex=True,
                            gridspec_kw={"height_ratios": heights}, squeeze=False)[:, 0]
        ax = axes[0]
        _draw_points(ax, x, y, classes)
        units = ds["poincare"].attrs.get("units", _state_unit(ds, name))
        ax.set_ylabel(f"{state_label(name)} {unit_text(units)} (Poincaré points)")
        ax.set_title(_title(ds, name, param))
        if meshes:
            _draw_regimes(ax, axes[1:1 + len(meshes)], ds, param, order, edges)
        if has_lyap:
            ax_l = axes[-1]
            lam = ds["lyapunov"].transpose(param).values[order]
            ax_l.plot(x[order], lam, "-", color="C0", lw=0.6)
            ax_l.plot(x[order], lam, ".", color="C0", ms=2)
            ax_l.axhline(0.0, color="k", lw=0.8)
            unit = time_unit_label(ds.attrs.get("time_unit"))
            ax_l.set_ylabel(rf"$\lambda_{{max}}$ [1/{unit}]")
        axes[-1].set_xlabel(xlabel)
        ax.set_xlim(edges[0], edges[-1])
        if path is not None:
            fig.savefig(Path(path))
    return fig
