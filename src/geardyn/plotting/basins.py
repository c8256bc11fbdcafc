"""Basins of attraction: the attractor reached from each initial condition as a colour map, one
colour per attractor (diverged cells black, unresolved cells light grey), the attractors' section
points marked on the same axes (the grid's axes are states), and a legend with each attractor's
period, share of the grid, contact regime and matched orbit, and the diverged and unresolved
shares."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC, state_label

__all__ = ["plot_basins"]

#: Attractor colours (cycled); diverged cells are black, unresolved ones light grey.
COLORS = ("#4C72B0", "#DD8452", "#55A868", "#C44E52", "#8172B3", "#937860", "#DA8BC3",
          "#8C8C8C", "#CCB974", "#64B5CD")
DIVERGED_COLOR = "#000000"
UNRESOLVED_COLOR = "#D9D9D9"


def _label(ds: xr.Dataset, a: int) -> str:
    k = int(ds["attractor_period"].values[a])
    text = f"#{a}: " + (f"period-{k}" if k > 0 else "no period")
    text += f", {100 * float(ds['attractor_fraction'].values[a]):.1f}%"
    if "attractor_contact" in ds:
        text += f", contact {', '.join(str(c) for c in ds['attractor_contact'].values[a])}"
    orbit = int(ds["attractor_orbit"].values[a])
    names = str(ds.attrs.get("orbit_names", "")).split(", ")
    if orbit >= 0:
        text += f", {names[orbit]}" if orbit < len(names) and names[orbit] else f", orbit {orbit}"
    return text


def plot_basins(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Figure of a :func:`geardyn.basins` dataset (or one loaded from its file); saved to
    ``path`` (.png, .pdf, .svg) when given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    if ds.attrs.get("geardyn_kind") != "basins":
        raise ValueError("not a basins result (attrs['geardyn_kind'] != 'basins')")
    xn, yn = ds.attrs["x"], ds.attrs["y"]
    ids = ds["attractor_id"].values
    n = ds.sizes["attractor"]
    colors = [UNRESOLVED_COLOR, DIVERGED_COLOR] + [COLORS[a % len(COLORS)] for a in range(n)]
    cmap = ListedColormap(colors)
    norm = BoundaryNorm(np.arange(-2, n + 1) - 0.5, cmap.N)
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.6, 4.8), layout="constrained")
        ax = fig.subplots()
        ax.pcolormesh(ds[xn].values, ds[yn].values, ids, cmap=cmap, norm=norm,
                      shading="nearest")
        handles = [Patch(facecolor=colors[a + 2], label=_label(ds, a)) for a in range(n)]
        if np.any(ids == -1):
            handles.append(Patch(facecolor=DIVERGED_COLOR,
                                 label=f"diverged, {100 * np.mean(ids == -1):.1f}%"))
        if np.any(ids == -2):
            handles.append(Patch(facecolor=UNRESOLVED_COLOR, edgecolor="0.5",
                                 label=f"unresolved (unsettled or split limit), "
                                       f"{100 * np.mean(ids == -2):.1f}%"))
        states = [str(s) for s in ds["state"].values]
        pts = ds["attractor_point"].values
        for a in range(n):
            p = pts[a][np.all(np.isfinite(pts[a]), axis=1)]
            ax.plot(p[:, states.index(xn)], p[:, states.index(yn)], ls="none", marker="*",
                    ms=13, mfc=colors[a + 2], mec="black", mew=1.0)
        ax.set_xlim(ds[xn].values.min(), ds[xn].values.max())
        ax.set_ylim(ds[yn].values.min(), ds[yn].values.max())
        ax.set_xlabel(f"initial {state_label(xn)}")
        ax.set_ylabel(f"initial {state_label(yn)}")
        ax.grid(False)
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False,
                  title="attractor (* section points)")
        name = ds.attrs.get("study") or ds.attrs.get("model", "")
        fig.suptitle(f"{name}: basins of attraction at Omega = {ds.attrs['Omega']:g}")
        if path is not None:
            fig.savefig(Path(path))
    return fig
