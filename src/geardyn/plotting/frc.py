"""Frequency-response curves: RMS and peak dynamic transmission error and the dynamic factor
against Omega, the up and down sweeps side by side (the hysteresis band shaded, the jumps
marked), the mesh frequency [Hz] and input speed [rpm] as extra axes where the model has
physical units, and optionally continuation branches drawn over them (stable solid, unstable
dashed)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["PANELS", "plot_frc"]

#: (variable, axis label) of each panel, top to bottom.
PANELS = (("dte_rms", "RMS DTE"), ("dte_amplitude", "DTE amplitude\n(max - min) / 2"),
          ("dynamic_factor", "dynamic factor"))
#: Names a continuation branch may give each variable (geardyn.continuation's first).
BRANCH_NAMES = {"dte_rms": ("dte_rms", "deflection_rms"),
                "dte_amplitude": ("dte_amplitude", "deflection_amplitude"),
                "dte_max": ("dte_max", "deflection_max"),
                "dte_peak": ("dte_peak",),
                "dynamic_factor": ("dynamic_factor",)}
SWEEP_STYLE = {"up": {"color": "#1f77b4", "marker": ">", "label": "sweep up"},
               "down": {"color": "#d62728", "marker": "<", "label": "sweep down"}}


def _bands(omega: np.ndarray, band: np.ndarray) -> list[tuple[float, float]]:
    """(lo, hi) of each run of True in ``band``, out to the midpoints of the grid steps on
    either side (where the band's edges lie, to the grid's resolution)."""
    mid = np.concatenate([[omega[0]], 0.5 * (omega[1:] + omega[:-1]), [omega[-1]]])
    out, start = [], None
    for j, b in enumerate(band):
        if b and start is None:
            start = j
        if start is not None and (not b or j == band.size - 1):
            stop = j if b else j - 1
            out.append((float(mid[start]), float(mid[stop + 1])))
            start = None
    return out


def _stable(branch: xr.Dataset) -> np.ndarray:
    """Per point: stable (``stable`` bool, or ``stability == "stable"``; all when neither)."""
    if "stable" in branch:
        return branch["stable"].values.astype(bool)
    if "stability" in branch:
        return branch["stability"].values.astype(str) == "stable"
    return np.ones(branch.sizes["point"], dtype=bool)


def _branch(ax, branch: xr.Dataset, name: str, mesh: str | None, labelled: set[str]) -> None:
    """A continuation branch dataset (dim ``point``) of ``name`` (or an alias,
    :data:`BRANCH_NAMES`): stable solid, unstable dashed, one line per ``branch`` number."""
    param = str(branch.attrs.get("param", "Omega"))
    found = next((n for n in BRANCH_NAMES.get(name, (name,)) if n in branch), None)
    if found is None or param not in branch:
        return
    y = branch[found]
    if "mesh" in y.dims:
        y = y.sel(mesh=mesh) if mesh is not None and mesh in y["mesh"] else y.isel(mesh=0)
    x, y = branch[param].values, y.values
    stable = _stable(branch)
    ids = branch["branch"].values if "branch" in branch else np.zeros(x.size, int)
    for b in np.unique(ids):
        on = ids == b
        for flag, ls in ((True, "-"), (False, "--")):
            label = "branch, " + ("stable" if flag else "unstable")
            yy = np.where(on & (stable == flag), y, np.nan)
            ax.plot(x[on], yy[on], color="black", ls=ls, lw=1.0,
                    label=None if label in labelled else label)
            labelled.add(label)


def plot_frc(ds: xr.Dataset, path: str | os.PathLike | None = None, *, mesh: str | None = None,
             branches: Sequence[xr.Dataset] = ()):
    """Figure of a :func:`geardyn.frequency_response` dataset (one mesh: ``mesh``, default the
    first), with continuation ``branches`` drawn over it; saved to ``path`` (.png, .pdf, .svg)
    when given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.figure import Figure

    if ds.attrs.get("geardyn_kind") != "frequency-response":
        raise ValueError("not a frequency-response result (attrs['geardyn_kind'])")
    meshes = [str(m) for m in ds["mesh"].values]
    mesh = meshes[0] if mesh is None else mesh
    if mesh not in meshes:
        raise ValueError(f"mesh {mesh!r} not in the result; meshes: {', '.join(meshes)}")
    om = ds["Omega"].values
    panels = [p for p in PANELS if p[0] in ds]
    bands = _bands(om, ds["hysteresis"].values)
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 2.4 * len(panels) + 0.8), layout="constrained")
        axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
        for ax, (name, label) in zip(axes, panels, strict=True):
            for lo, hi in bands:
                ax.axvspan(lo, hi, color="0.9", zorder=0)
            for s in ds["sweep"].values:
                style = SWEEP_STYLE.get(str(s), {"label": str(s)})
                ax.plot(om, ds[name].sel(sweep=s, mesh=mesh).values, ms=3, lw=0.8,
                        markevery=max(1, om.size // 60), **style)
            labelled: set[str] = set()
            for b in branches:
                _branch(ax, b, name, mesh, labelled)
            for j in range(ds.sizes.get("jump", 0)):
                if str(ds["jump_mesh"].values[j]) != mesh:
                    continue
                sw = str(ds["jump_sweep"].values[j])
                ax.axvline(float(ds["jump_omega"].values[j]), ls=":", lw=1.0,
                           color=SWEEP_STYLE.get(sw, {}).get("color", "k"))
            units = ds[name].attrs.get("units")
            ax.set_ylabel(label + (f" [{units}]" if units not in (None, "1") else ""))
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False,
                       title=(f"mesh {mesh}: " if len(meshes) > 1 else "")
                       + "jumps dotted, hysteresis grey")
        axes[-1].set_xlabel(r"$\Omega$ (forcing frequency"
                            + (f" [{ds['Omega'].attrs['units']}])"
                               if ds["Omega"].attrs.get("units", "1") != "1" else ")"))
        _physical_axes(ds, axes[0], axes[-1])
        name = ds.attrs.get("study") or ds.attrs.get("model", "")
        res = ds.attrs.get("resolution")
        fig.suptitle(f"{name}: frequency response, up and down sweeps"
                     + (f" (jumps located to {res:.3g})" if res else ""))
        if path is not None:
            fig.savefig(Path(path))
    return fig


def _physical_axes(ds: xr.Dataset, top, bottom) -> None:
    """Mesh frequency [Hz] on top of the first panel, input speed [rpm] under the last (linear
    in Omega)."""
    om = ds["Omega"].values
    for name, ax, where in (("mesh_frequency", top, "top"), ("input_speed", bottom, -0.32)):
        if name not in ds.coords:
            continue
        factor = float(ds[name].values[-1] / om[-1])
        sec = ax.secondary_xaxis(where, functions=(lambda w, f=factor: w * f,
                                                   lambda v, f=factor: v / f))
        sec.set_xlabel(f"{ds[name].attrs.get('long_name', name)} [{ds[name].attrs['units']}]")
