"""Campbell (interference) diagram of a gear train (:meth:`geardyn.trains.GearTrain.campbell`):
natural frequencies against input speed, the mesh orders and their harmonics as rays, and the
crossings marked."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["plot_campbell"]


def plot_campbell(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Figure of Campbell data: each non-zero natural frequency [Hz] as a horizontal grey line,
    each excitation (mesh, harmonic) as a ray harmonic * order * rpm / 60 [Hz] (one ray and
    colour for the meshes of one order, e.g. a planetary stage's sun and ring meshes; dashed
    above the first harmonic), and a marker at every crossing in the speed range. Saved to
    ``path`` (.png, .pdf, .svg) when given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.figure import Figure

    if not {"natural_frequency", "excitation_frequency", "crossing_speed"} <= set(ds):
        raise ValueError("not Campbell data (needs natural_frequency, excitation_frequency and"
                         " crossing_speed; GearTrain.campbell)")
    rpm = ds["speed"].values
    f_n = ds["natural_frequency"].values
    rays = _rays(ds)
    orders = list(dict.fromkeys(order for order, _, _, _ in rays))
    colours = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 4.8), layout="constrained")
        ax = fig.subplots()
        for f in f_n[f_n > 0.0]:
            ax.axhline(f, color="0.7", lw=0.7, zorder=1)
        for order, h, e, meshes in rays:
            colour = colours[orders.index(order) % len(colours)]
            names = meshes[0] if len(meshes) == 1 else f"{meshes[0]} and {len(meshes) - 1} more"
            ax.plot(rpm, ds["excitation_frequency"].values[e], color=colour,
                    ls="-" if h == 1 else "--", lw=1.0, zorder=2,
                    label=f"{names} (order {order:.4g})" if h == 1 else None)
        cross = ds["crossing_speed"].values
        hit = np.isfinite(cross)
        ax.plot(cross[hit], np.broadcast_to(f_n, cross.shape)[hit], "o", ms=4, mfc="none",
                color="k", zorder=3, label="crossing")
        top = max(float(np.max(f_n)) if f_n.size else 1.0,
                  float(np.max(ds["excitation_frequency"].values)))
        ax.set(xlim=(float(rpm.min()), float(rpm.max())), ylim=(0.0, 1.05 * top),
               xlabel="input speed [rpm]", ylabel="frequency [Hz]",
               title="Campbell diagram (solid: 1st harmonic; dashed: higher)")
        ax.legend(loc="upper left", fontsize="small")
        if path is not None:
            fig.savefig(Path(path))
    return fig


def _rays(ds: xr.Dataset) -> list[tuple[float, int, int, list[str]]]:
    """(order, harmonic, index of its first excitation, meshes) of each distinct ray: the
    excitations of equal order (to 1e-4 relative, closer than a line's width) and harmonic
    drawn once."""
    out: list[tuple[float, int, int, list[str]]] = []
    for e in range(ds.sizes["excitation"]):
        order, h = float(ds["order"].values[e]), int(ds["harmonic"].values[e])
        mesh = str(ds["mesh"].values[e])
        same = next((r for r in out if r[1] == h and np.isclose(r[0], order, rtol=1e-4)), None)
        if same is None:
            out.append((order, h, e, [mesh]))
        elif mesh not in same[3]:
            same[3].append(mesh)
    return out
