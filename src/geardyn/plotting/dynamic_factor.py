"""The model's dynamic factor beside ISO 6336-1 K_v (method B) against pinion speed
(:func:`geardyn.analysis.dynamic_factor.dynamic_factor_sweep`): one colour per torque, the
model solid with markers (open where the teeth separate, a triangle at the top where off the
axis or diverged), K_v dashed, ISO's resonance speed
N_M and the model's linear resonance speed as vertical lines, the mesh frequency on top."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["plot_dynamic_factor"]


def plot_dynamic_factor(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Figure of a dynamic-factor sweep ``ds``; saved to ``path`` (.png, .pdf, .svg) when
    given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.figure import Figure

    need = {"dynamic_factor", "K_v", "resonance_speed", "contact"}
    if not need <= set(ds):
        raise ValueError(f"not a dynamic-factor sweep (needs {', '.join(sorted(need))}; "
                         "geardyn.analysis.dynamic_factor.dynamic_factor_sweep)")
    rpm = ds["speed"].values
    finite = ds["dynamic_factor"].values[np.isfinite(ds["dynamic_factor"].values)]
    kv_max = float(np.nanmax(ds["K_v"].values))
    y_top = min(float(finite.max()) if finite.size else kv_max, max(3.0 * kv_max, 6.0)) * 1.08
    colours = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 4.4), layout="constrained")
        ax = fig.subplots()
        for j, t1 in enumerate(ds["torque"].values):
            c = colours[j % len(colours)]
            row = ds.isel(torque=j)
            lost = row["contact"].values.astype(str) != "none"
            ax.plot(rpm, row["dynamic_factor"].values, "-", color=c, lw=1.0,
                    label=f"model, {t1:g} N m")
            ax.plot(rpm[~lost], row["dynamic_factor"].values[~lost], "o", color=c, ms=2.5)
            ax.plot(rpm[lost], row["dynamic_factor"].values[lost], "o", mfc="none", color=c,
                    ms=3.5)
            above = ~(row["dynamic_factor"].values <= y_top)  # beyond the axis, or diverged
            ax.plot(rpm[above], np.full(above.sum(), y_top), "^", color=c, ms=4, clip_on=False)
            ax.plot(rpm, row["K_v"].values, "--", color=c, lw=1.2,
                    label=f"ISO 6336-1 $K_v$, {t1:g} N m")
            ax.axvline(float(row["resonance_speed"]), color=c, ls=":", lw=1.0)
        lin = ds.attrs.get("linear_resonance_speed")
        if lin is not None:
            ax.axvline(float(lin), color="k", ls="-.", lw=0.8,
                       label="model linear resonance")
        ax.plot([], [], ":", color="0.3", label="ISO resonance speed $N_M$ ($n_{E1}$)")
        ax.plot([], [], "o", mfc="none", color="0.3", ms=3.5, label="model: teeth separate")
        ax.plot([], [], "^", color="0.3", ms=4, label="model: off the axis or diverged")
        ax.set_xlabel("pinion speed [rpm]")
        ax.set_ylabel("dynamic factor [–]")
        ax.set_xlim(rpm.min(), rpm.max())
        low = min(1.0, float(finite.min()) if finite.size else 1.0, float(np.nanmin(ds["K_v"])))
        ax.set_ylim(low - 0.05, y_top)
        ax.legend(loc="upper left", ncols=2)
        if "mesh_frequency" in ds.coords:
            per_rpm = float(ds["mesh_frequency"].values[0] / rpm[0])
            top = ax.secondary_xaxis("top", functions=(lambda x: x * per_rpm,
                                                       lambda f: f / per_rpm))
            top.set_xlabel("mesh frequency [Hz]")
        fig.suptitle(f"dynamic factor against ISO 6336-1 method B "
                     f"(c' and $c_{{\\gamma\\alpha}}$: {ds.attrs.get('stiffness_source', '?')})")
    if path is not None:
        fig.savefig(Path(path))
    return fig
