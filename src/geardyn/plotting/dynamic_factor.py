"""The model's dynamic factor beside ISO 6336-1 K_v (method B) against pinion speed
(:func:`geardyn.analysis.dynamic_factor.dynamic_factor_sweep`): one colour per torque and mesh
group, the
model solid with markers (open where the teeth separate, a triangle at the top where off the
axis or diverged), K_v dashed, ISO's resonance speed
N_M (named at the right edge when beyond the axis) and the model's linear resonance speed (a
spur pair's) or the speeds at which the mesh frequency meets each natural frequency (a planetary
stage's, grey) as vertical lines, the mesh frequency on top."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["plot_dynamic_factor"]

#: Curves (model and K_v per torque and group) above which the legend goes below the axes (a
#: train's many groups).
LEGEND_INSIDE_MAX = 7


def _torque_text(t: float) -> str:
    """A torque [N m] with an SI prefix: 60 N m, 3.95 MN m."""
    for scale, prefix in ((1e6, "M"), (1e3, "k")):
        if abs(t) >= scale:
            return f"{t / scale:.3g} {prefix}N m"
    return f"{t:g} N m"


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
    y_top = min(max(float(finite.max()) if finite.size else kv_max, kv_max),
                max(3.0 * kv_max, 6.0)) * 1.08
    colours = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    with matplotlib.rc_context(RC):
        groups = [str(g) for g in ds["group"].values]
        below = 2 * ds.sizes["torque"] * len(groups) > LEGEND_INSIDE_MAX
        fig = Figure(figsize=(7.2, 5.6 if below else 4.4), layout="constrained")
        ax = fig.subplots()
        for j, t1 in enumerate(ds["torque"].values):
            for g, group in enumerate(groups):
                c = colours[(j * len(groups) + g) % len(colours)]
                row = ds.isel(torque=j, group=g)
                what = _torque_text(float(t1)) + ("" if len(groups) == 1
                                                  else f", {group} meshes")
                df = row["dynamic_factor"].values
                lost = row["contact"].values.astype(str) != "none"
                ax.plot(rpm, df, "-", color=c, lw=1.0, label=f"model, {what}")
                ax.plot(rpm[~lost], df[~lost], "o", color=c, ms=2.5)
                ax.plot(rpm[lost], df[lost], "o", mfc="none", color=c, ms=3.5)
                above = ~(df <= y_top)  # beyond the axis, or diverged
                ax.plot(rpm[above], np.full(above.sum(), y_top), "^", color=c, ms=4,
                        clip_on=False)
                ax.plot(rpm, row["K_v"].values, "--", color=c, lw=1.2,
                        label=f"ISO 6336-1 $K_v$, {what}")
                n_m = float(row["resonance_speed"])
                if n_m <= rpm.max():
                    ax.axvline(n_m, color=c, ls=":", lw=1.0)
                else:  # beyond the axis: named at its right edge
                    ax.annotate(f"$N_M$ {n_m:.0f} rpm →", (1.0, 0.02 + 0.06 * g),
                                xycoords="axes fraction", ha="right", color=c, fontsize=7)
        shown = [float(n) for n in np.atleast_1d(ds.attrs.get("natural_speeds", []))
                 if rpm.min() <= n <= rpm.max()]
        for k, n in enumerate(shown):
            ax.axvline(n, color="0.75", lw=0.6, zorder=0,
                       label="model natural frequencies" if k == 0 else None)
        lin = ds.attrs.get("linear_resonance_speed")
        if lin is not None:
            ax.axvline(float(lin), color="k", ls="-.", lw=0.8,
                       label="model linear resonance")
        ax.plot([], [], ":", color="0.3", label="ISO resonance speed $N_M$ ($n_{E1}$)")
        ax.plot([], [], "o", mfc="none", color="0.3", ms=3.5, label="model: teeth separate")
        ax.plot([], [], "^", color="0.3", ms=4, label="model: off the axis or diverged")
        ax.set_xlabel(f"{ds['speed'].attrs.get('long_name', 'input speed')} [rpm]")
        ax.set_ylabel("dynamic factor [–]")
        ax.set_xlim(rpm.min(), rpm.max())
        low = min(1.0, float(finite.min()) if finite.size else 1.0, float(np.nanmin(ds["K_v"])))
        ax.set_ylim(low - 0.05, y_top)
        if below:
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=3,
                      fontsize="x-small")
        else:
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
