"""The envelope picture: the contact regions of a parameter plane filled from its grazing
curves, coexisting (between fold curves), period-doubled and chaotic regions hatched, the curves
and their codimension-2 points drawn over them, optionally over a brute-force map's contact
labels (one marker per map cell, in the regions' colours: where both agree a marker disappears
into its region)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.analysis.envelope import CONTACT_REGIONS, Envelope
from geardyn.plotting.bifurcation import REGIME_COLORS
from geardyn.plotting.style import RC, param_label

__all__ = ["CURVE_STYLES", "draw_curves", "plot_curves", "plot_envelope"]

#: Region names of the legend, by contact code.
REGION_LABELS = {"none": "contact kept", "single": "one-sided impacts",
                 "double": "two-sided impacts"}
#: How each curve kind is drawn: (colour, line style, legend label).
CURVE_STYLES: dict[str, tuple[str, str, str]] = {
    "grazing drive": ("black", "-", "contact loss (drive-flank grazing)"),
    "grazing back": ("black", "--", "back-flank impacts begin (grazing)"),
    "fold": ("#1f4e9c", "-", "fold"),
    "period_doubling": ("#9c1f8a", "-", "period doubling"),
    "neimark_sacker": ("#1f9c8f", "-.", "Neimark-Sacker"),
}


def _style(ds: xr.Dataset) -> tuple[str, str, str]:
    kind = ds.attrs["curve_kind"]
    if kind == "grazing":
        kind = f"grazing {ds.attrs.get('flank', 'drive')}"
    return CURVE_STYLES.get(kind, ("grey", ":", kind))


def draw_curves(ax, curves: list[xr.Dataset], x: str, y: str,
                x_factor: float = 1.0, y_factor: float = 1.0) -> list:
    """Draw ``curves`` (``"curve"`` datasets) on ``ax`` in the plane (``x``, ``y``) (a curve
    with the axes the other way round is transposed), each kind in its style, the
    codimension-2 points as labelled stars. Returns the legend handles, one per kind."""
    from matplotlib.lines import Line2D

    seen: dict[str, Line2D] = {}
    for c in curves:
        if c.sizes["point"] == 0:
            continue
        colour, ls, label = _style(c)
        ax.plot(c[x].values * x_factor, c[y].values * y_factor, color=colour, ls=ls, lw=1.4)
        seen.setdefault(label, Line2D([], [], color=colour, ls=ls, lw=1.4, label=label))
        if c.sizes.get("special", 0):
            sx, sy = c["special_x"].values, c["special_y"].values
            if c.attrs["x"] != x:
                sx, sy = sy, sx
            ax.plot(sx * x_factor, sy * y_factor, "*", color="gold", mec="black", ms=10)
            for u, v, k in zip(sx, sy, c["special_kind"].values, strict=True):
                ax.annotate(str(k), (u * x_factor, v * y_factor), textcoords="offset points",
                            xytext=(4, 4), fontsize=7)
            seen.setdefault("special", Line2D([], [], ls="none", marker="*", color="gold",
                                              mec="black", ms=10, label="codimension-2 point"))
    return list(seen.values())


def plot_envelope(env: Envelope, path: str | os.PathLike | None = None, *,
                  title: str | None = None):
    """Figure of an :class:`~geardyn.analysis.envelope.Envelope`: regions filled, curves drawn,
    the map's contact labels as markers when it has a map, physical axes (input speed, mesh
    frequency) where the model gives them. Saved to ``path`` (.png, .pdf, .svg) when given.

    Returns a matplotlib Figure (created without pyplot)."""
    import matplotlib
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    x, y = env.x, env.y
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.6, 4.6), layout="constrained")
        ax = fig.add_subplot()
        colours = ["#eeeeee"] + [REGIME_COLORS[r] for r in CONTACT_REGIONS]
        cmap = ListedColormap(colours)
        norm = BoundaryNorm(np.arange(-1, len(CONTACT_REGIONS) + 1) - 0.5, cmap.N)
        ax.pcolormesh(env.xv, env.yv, env.contact, cmap=cmap, norm=norm, shading="nearest")
        handles = [Patch(facecolor=REGIME_COLORS[r], label=REGION_LABELS[r])
                   for i, r in enumerate(CONTACT_REGIONS) if np.any(env.contact == i)]
        for mask, hatch, label in ((env.coexisting, "//", "coexisting responses"),
                                   (env.period_doubled, "\\\\", "period doubled"),
                                   (env.chaotic, "xx", "chaotic (map: no period)")):
            if np.any(mask):
                ax.contourf(env.xv, env.yv, mask.astype(float), levels=[0.5, 1.5],
                            colors="none", hatches=[hatch])
                handles.append(Patch(facecolor="none", hatch=hatch, label=label))
        if env.map is not None and "contact" in env.map:
            _map_markers(ax, env.map, x, y)
            handles.append(Patch(facecolor="white", edgecolor="black",
                                 label="map cell (its contact label)"))
        handles += draw_curves(ax, env.curves, x, y)
        ax.set_xlim(*env.x_range)
        ax.set_ylim(*env.y_range)
        ax.grid(False)
        ax.set_xlabel(param_label(x, env.model_name, _units(env, x)))
        ax.set_ylabel(param_label(y, env.model_name, _units(env, y)))
        for key, where in (("x", "top"), ("y", "right")):
            if key in env.axes:
                factor, label = env.axes[key]
                fn = (lambda v, f=factor: v * f, lambda v, f=factor: v / f)
                sec = (ax.secondary_xaxis(where, functions=fn) if key == "x"
                       else ax.secondary_yaxis(where, functions=fn))
                (sec.set_xlabel if key == "x" else sec.set_ylabel)(label)
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  frameon=False)
        ax.set_title(title or f"{env.model_name}: contact regions in ({x}, {y})")
        if path is not None:
            fig.savefig(Path(path))
    return fig


def plot_curves(curves: list[xr.Dataset], path: str | os.PathLike | None = None):
    """Figure of two-parameter ``curves`` (``"curve"`` datasets) in the plane of the first one,
    each kind in its style, codimension-2 points labelled, each curve's end status in the
    title when it did not complete. Saved to ``path`` (.png, .pdf, .svg) when given; returns
    a matplotlib Figure (created without pyplot)."""
    import matplotlib
    from matplotlib.figure import Figure

    if not curves:
        raise ValueError("no curve to draw")
    x, y = curves[0].attrs["x"], curves[0].attrs["y"]
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(6.4, 4.4), layout="constrained")
        ax = fig.add_subplot()
        handles = draw_curves(ax, curves, x, y)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.legend(handles=handles, loc="best", frameon=False)
        ended = [str(c.attrs.get("message", "")) for c in curves
                 if int(c.attrs.get("status", 0)) != 0]
        ax.set_title(f"curves in ({x}, {y})" + (f"; ended: {ended[0]}"[:90] if ended else ""))
        if path is not None:
            fig.savefig(Path(path))
    return fig


def _units(env: Envelope, name: str) -> str | None:
    for c in env.curves:
        if name in c.coords and "units" in c[name].attrs:
            return str(c[name].attrs["units"])
    return None


def _map_markers(ax, mp: xr.Dataset, x: str, y: str) -> None:
    """One marker per map cell in its contact label's colour (the first mesh)."""
    labels = mp["contact"]
    if "mesh" in labels.dims:
        labels = labels.isel(mesh=0)
    labels = labels.transpose(y, x).values
    X, Y = np.meshgrid(mp[x].values, mp[y].values)
    for name, colour in REGIME_COLORS.items():
        sel = labels == name
        if np.any(sel):
            ax.scatter(X[sel], Y[sel], s=14, c=colour, edgecolors="black", linewidths=0.5,
                       zorder=3)
