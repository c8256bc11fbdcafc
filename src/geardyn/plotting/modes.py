"""Natural frequencies of a gear train and where each mode's strain energy lies
(:meth:`geardyn.trains.GearTrain.modes`): a map of the energy shares, mode by element."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["plot_energy_shares"]


def plot_energy_shares(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Figure of modal data: one row per (non rigid-body) mode, labelled with its natural
    frequency [Hz] (and its class where the train has planets), one column per mesh, shaft and
    bearing, the colour its share of the mode's strain energy (0..1). Saved to ``path`` (.png,
    .pdf, .svg) when given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.figure import Figure

    if not {"frequency", "energy_share"} <= set(ds):
        raise ValueError("not modal data (needs frequency and energy_share; GearTrain.modes)")
    keep = ~ds["rigid_body"].values
    share = ds["energy_share"].values[keep]
    f = ds["frequency"].values[keep]
    kinds = ds["type"].values[keep] if "type" in ds else None
    labels = [f"{v:.4g} Hz" + (f" ({kinds[i]})" if kinds is not None else "")
              for i, v in enumerate(f)]
    elements = [str(e) for e in ds["element"].values]
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(max(5.0, 1.0 + 0.32 * len(elements)),
                              max(3.0, 1.2 + 0.24 * len(labels))), layout="constrained")
        ax = fig.subplots()
        image = ax.imshow(np.nan_to_num(share), vmin=0.0, vmax=1.0, cmap="viridis",
                          aspect="auto", interpolation="nearest")
        ax.set_xticks(range(len(elements)), elements, rotation=90, fontsize="small")
        ax.set_yticks(range(len(labels)), labels, fontsize="small")
        ax.grid(False)
        ax.set(xlabel="element", ylabel="mode", title="Strain-energy share of each element")
        fig.colorbar(image, ax=ax, label="share of the mode's strain energy")
        if path is not None:
            fig.savefig(Path(path))
    return fig
