"""Two-parameter maps: the period class over the grid as a colour map with a discrete legend,
the contact-loss regime of each mesh beside it, and the largest Lyapunov exponent when computed.
Colours and classes are those of the bifurcation diagram (:mod:`geardyn.plotting.bifurcation`)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.analysis.lanes import CONTACT_LABELS
from geardyn.plotting.bifurcation import PERIOD_CLASSES, REGIME_COLORS, period_class
from geardyn.plotting.style import RC, param_label

__all__ = ["plot_map"]

#: Meshes drawn one panel each; a model with more gets one panel of the most severe regime.
MAX_MESH_PANELS = 2


def _categorical(ax, ds: xr.Dataset, codes: np.ndarray, classes: list[tuple[int, str, str]],
                 title: str) -> None:
    """Draw integer ``codes`` (y, x) with one colour per class and a legend of the classes
    present."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    x, y = ds[ds.attrs["x"]].values, ds[ds.attrs["y"]].values
    present = [c for c in classes if np.any(codes == c[0])]
    index = {c[0]: k for k, c in enumerate(present)}
    img = np.vectorize(index.__getitem__, otypes=[float])(codes) if present else codes * np.nan
    cmap = ListedColormap([c[2] for c in present] or ["white"])
    norm = BoundaryNorm(np.arange(len(present) + 1) - 0.5, cmap.N)
    ax.pcolormesh(x, y, img, cmap=cmap, norm=norm, shading="nearest")
    ax.set_title(title)
    handles = [Patch(facecolor=c[2], edgecolor="none", label=c[1]) for c in present]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)


def _axis_labels(ax, ds: xr.Dataset) -> None:
    model = ds.attrs.get("model", "")
    ax.set_xlabel(param_label(ds.attrs["x"], model, ds[ds.attrs["x"]].attrs.get("units")))
    ax.set_ylabel(param_label(ds.attrs["y"], model, ds[ds.attrs["y"]].attrs.get("units")))
    ax.grid(False)


def plot_map(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Figure of a :func:`geardyn.map2d` dataset (or one loaded from its file): the period class,
    the contact-loss regime (when the model has backlash meshes) and the largest Lyapunov
    exponent (when computed). Saved to ``path`` (.png, .pdf, .svg) when given.

    Returns a matplotlib Figure (created without pyplot: no GUI, nothing global to close).
    """
    import matplotlib
    from matplotlib.figure import Figure

    if "period" not in ds or "x" not in ds.attrs or "y" not in ds.attrs:
        raise ValueError("not a two-parameter map (needs 'period' and the x, y attributes)")
    panels = [("period", None)]
    if "contact" in ds:
        meshes = [str(m) for m in ds["mesh"].values]
        if len(meshes) <= MAX_MESH_PANELS:
            panels += [("contact", m) for m in meshes]
        else:
            panels.append(("contact", None))
    if "lyapunov" in ds:
        panels.append(("lyapunov", None))

    regimes = [(k, label, REGIME_COLORS[label]) for k, label in enumerate(CONTACT_LABELS)]
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(6.8, 3.4 * len(panels)), layout="constrained")
        axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
        for ax, (kind, mesh) in zip(axes, panels, strict=True):
            if kind == "period":
                _categorical(ax, ds, period_class(ds["period"].values), list(PERIOD_CLASSES),
                             "steady motion (period in forcing periods)")
            elif kind == "contact":
                labels = ds["contact"].sel(mesh=mesh).values if mesh else ds["contact"].values
                codes = np.vectorize(CONTACT_LABELS.index, otypes=[int])(labels)
                if mesh is None:  # the most severe regime over the meshes
                    codes = codes.max(axis=-1)
                where = (f", mesh {mesh}" if mesh and len(ds["mesh"]) > 1 else
                         "" if mesh else ", most severe over the meshes")
                _categorical(ax, ds, codes, regimes, f"contact-loss regime{where}")
            else:
                lam = ds["lyapunov"].values
                finite = lam[np.isfinite(lam)]
                top = float(np.max(np.abs(finite))) if finite.size else 1.0
                mesh_img = ax.pcolormesh(ds[ds.attrs["x"]].values, ds[ds.attrs["y"]].values,
                                         lam, cmap="RdBu_r", vmin=-top, vmax=top,
                                         shading="nearest")
                fig.colorbar(mesh_img, ax=ax, label="largest Lyapunov exponent")
                ax.set_title("largest Lyapunov exponent (> 0: chaos)")
            _axis_labels(ax, ds)
        name = ds.attrs.get("study") or ds.attrs.get("model", "")
        fig.suptitle(f"{name}: {ds.attrs['y']} x {ds.attrs['x']} map")
        if path is not None:
            path = Path(path)
            fig.savefig(path)
    return fig
