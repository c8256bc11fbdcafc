"""The four-panel figure of one simulation: time history, phase portrait, Poincaré section and
amplitude spectrum of one coordinate."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.core.status import Status
from geardyn.plotting.style import RC, state_label, unit_text

__all__ = ["plot_simulation", "resolve_state", "velocity_of"]


def resolve_state(ds: xr.Dataset, state: str) -> str:
    """The variable of ``ds`` that shows ``state``: itself, or the first planet set's
    (``X_sq`` -> ``X_sq1``) in a general (4N-state) simulation."""
    from geardyn.analysis.spectrum import time_series

    return str(time_series(ds, state).name)


def velocity_of(ds: xr.Dataset, name: str) -> str | None:
    """The name of the velocity belonging to coordinate ``name`` (``X_sq`` -> ``V_sq``,
    ``x`` -> ``v``, else the next state), or None."""
    candidates = []
    if name.startswith("X_"):
        candidates.append("V_" + name[2:])
    if name == "x":
        candidates.append("v")
    if name.startswith("theta"):
        candidates.append("d" + name)
    states = [str(s) for s in ds["state"].values] if "state" in ds.coords else []
    if name in states and states.index(name) + 1 < len(states):
        candidates.append(states[states.index(name) + 1])
    for c in candidates:
        if c in ds.data_vars and c != name:
            return c
    return None


def _units(ds: xr.Dataset, name: str, index: int = 0) -> str:
    units = str(ds[name].attrs.get("units", "1"))
    parts = [u.strip() for u in units.split(",")]
    return parts[min(index, len(parts) - 1)]


def _time_label(ds: xr.Dataset) -> str:
    unit = str(ds.attrs.get("time_unit", ds["time"].attrs.get("units", "1")))
    if unit in ("1", ""):
        return r"$\tau = \omega_n t$ [–]"
    return f"t [{unit}]"


def _poincare(ds: xr.Dataset, name: str) -> np.ndarray:
    if "poincare" in ds and "state" in ds.coords and name in ds["state"].values:
        return ds["poincare"].sel(state=name).values
    if "poincare_time" in ds:
        return ds[name].sel(time=ds["poincare_time"].values, method="nearest").values
    return np.array([])


def _draw_spectrum(ax, ds: xr.Dataset, name: str, ylabel: str, max_order: float = 8.0,
                   n_labels: int = 8) -> None:
    """Amplitude spectrum of ``name`` (log scale, up to ``max_order`` Omega) with its largest
    peaks named (mesh harmonics, subharmonics, load-fluctuation lines and sidebands)."""
    from geardyn.analysis.spectrum import amplitude_spectrum, label_peaks

    ax.set_xlabel(r"frequency / $\Omega$ (multiples of the mesh frequency)")
    ax.set_ylabel(ylabel)
    ax.set_title("amplitude spectrum (Hann window, mean removed)")
    try:
        spec = amplitude_spectrum(ds, name)
    except ValueError:  # a diverged run, or too few samples
        ax.set_title("amplitude spectrum (not available: diverged or too short)")
        return
    spec = spec.sel(frequency=slice(0.0, max_order))
    f, amp = spec["frequency"].values[1:], spec.values[1:]
    if not f.size:
        return
    top = float(np.max(amp))
    ax.semilogy(f, np.maximum(amp, 1e-300), color="C0")
    ax.set_xlim(0.0, float(f[-1]))
    if top > 0:
        ax.set_ylim(top * 1e-8, top * 10.0)
    peaks = label_peaks(spec, threshold=1e-3, max_peaks=n_labels)
    for fp, ap, label, kind in zip(peaks["frequency"].values, peaks["amplitude"].values,
                                   peaks["label"].values, peaks["kind"].values, strict=True):
        ax.annotate(str(label), (fp, ap), xytext=(0, 3), textcoords="offset points",
                    ha="center", va="bottom", fontsize=7,
                    color="0.4" if kind == "other" else "k")


def plot_simulation(ds: xr.Dataset, state: str = "X_sq", path: str | os.PathLike | None = None):
    """Time history, phase portrait, Poincaré points and amplitude spectrum of ``state``; the
    largest spectral peaks are named (kΩ, jΩ/n, mΛ, kΩ±mΛ; Λ from the ``Lambda`` attribute).

    Parameters
    ----------
    ds
        A dataset returned by :func:`geardyn.simulate` (or loaded from its NetCDF file).
    state
        The coordinate to show (``X_sq``, ``X_pq``, ``x`` ...; for a general simulation
        ``X_sq`` means planet set 1's).
    path
        Where to save the figure (format from the suffix: .png, .pdf, .svg); None to only return
        it.

    Returns
    -------
    matplotlib.figure.Figure (created without pyplot: no GUI, nothing global to close).
    """
    import matplotlib
    from matplotlib.figure import Figure

    name = resolve_state(ds, state)
    vname = velocity_of(ds, name)
    t = ds["time"].values
    x = ds[name].values
    if vname is not None:
        v = ds[vname].values
        vlabel = f"{state_label(vname)} {unit_text(_units(ds, vname, 1))}"
    else:
        v = np.gradient(x, t) if t.size > 1 else np.zeros_like(x)
        vlabel = f"d{state_label(name)}/dt"
    xlabel = f"{state_label(name)} {unit_text(_units(ds, name, 0))}"
    pc_x = _poincare(ds, name)
    pc_v = _poincare(ds, vname) if vname is not None else np.array([])
    a = ds.attrs
    omega = a.get("Omega", float("nan"))
    status = Status(int(a.get("status", Status.OK)))

    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(10.0, 7.0), layout="constrained")
        ax_t, ax_p, ax_s, ax_f = fig.subplots(2, 2).ravel()

        ax_t.plot(t, x, color="C0", label=state_label(name))
        if pc_x.size:
            ax_t.plot(ds["poincare_time"].values[: pc_x.size], pc_x, "o", color="C3", ms=3,
                      label="once per period")
            ax_t.legend(loc="upper right")
        ax_t.set_xlabel(_time_label(ds))
        ax_t.set_ylabel(xlabel)
        ax_t.set_title("time history")

        ax_p.plot(x, v, color="C0", alpha=0.8)
        if pc_x.size and pc_v.size:
            ax_p.plot(pc_x, pc_v, "o", color="C3", ms=3)
        ax_p.set_xlabel(xlabel)
        ax_p.set_ylabel(vlabel)
        ax_p.set_title("phase portrait (dots: Poincaré points)")

        if pc_x.size and pc_v.size:
            ax_s.plot(pc_x, pc_v, "o", color="C3", ms=4)
            distinct = count_distinct(np.column_stack([pc_x, pc_v]))
            ax_s.set_title(f"Poincaré section ({pc_x.size} points, {distinct} distinct)")
        else:
            ax_s.set_title("Poincaré section (no samples)")
        ax_s.set_xlabel(xlabel)
        ax_s.set_ylabel(vlabel)

        _draw_spectrum(ax_f, ds, name,
                       f"amplitude of {state_label(name)} {unit_text(_units(ds, name, 0))}")

        model = a.get("model", "model")
        interp = f", {a['interpretation']}" if "interpretation" in a else ""
        title = (
            f"{model}{interp}: $\\Omega$ = {omega:.6g}; {a.get('integrator', 'integrator ?')}, "
            f"{a.get('steps_per_period', '?')} steps per period"
        )
        if status != Status.OK:
            title += "  [DIVERGED]"
        fig.suptitle(title)
        if path is not None:
            path = Path(path)
            fig.savefig(path)
    return fig


def count_distinct(points: np.ndarray, tol: float = 1e-6) -> int:
    """Number of distinct rows of ``points`` (max-norm distance > ``tol`` from each other);
    non-finite rows are ignored."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim == 1:
        pts = pts[:, None]
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    reps: list[np.ndarray] = []
    for p in pts:
        if not any(np.max(np.abs(p - r)) <= tol for r in reps):
            reps.append(p)
    return len(reps)
