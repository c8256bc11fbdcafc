"""Run-up figures: the output against speed over its waterfall, drawn Campbell-style (amplitude
as colour against speed and frequency, the mesh orders and their harmonics as rays, the
natural frequencies as horizontal lines, their crossings marked), and the order map."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["plot_order_map", "plot_waterfall"]


def _speed_axis(wf: xr.Dataset) -> tuple[np.ndarray, str, float]:
    """(speed values, label, speed per unit of Omega) of the x axis: the input speed [rpm]
    where the run-up has it, else Omega."""
    w = wf["Omega"].values
    if "input_speed" in wf.coords:
        rpm = wf["input_speed"].values
        k = int(np.argmax(np.abs(w)))
        return rpm, "input speed [rpm]", float(rpm[k] / w[k]) if w[k] else 1.0
    units = wf["Omega"].attrs.get("units", "")
    return w, f"forcing frequency Omega [{units}]", 1.0


def _mesh(x: np.ndarray) -> np.ndarray:
    """Cell edges of centres x (for pcolormesh)."""
    if x.size == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[2 * x[0] - mid[0]], mid, [2 * x[-1] - mid[-1]]])


def _colour_limits(A: np.ndarray) -> tuple[float, float]:
    top = float(np.nanmax(A)) if A.size else 1.0
    top = top if top > 0 else 1.0
    return top * 1e-4, top


def plot_waterfall(wf: xr.Dataset, run: xr.Dataset | None = None, *, harmonics: int = 4,
                   path: str | os.PathLike | None = None):
    """Figure of a :func:`geardyn.analysis.orders.waterfall`: the amplitude (log colour) against
    speed (input speed [rpm] where the model has it, else Omega) and frequency (Hz where it has
    it, else Omega's units); the rays of orders 1..``harmonics`` of the forcing (mesh)
    frequency, the natural frequencies (``attrs["natural_frequencies"]``) as dashed lines and
    each crossing of a ray with one (a resonance the run-up passes) marked. With ``run`` (the
    run-up dataset) a panel above shows the output against the same speed. Saved to ``path``
    (.png, .pdf, .svg) when given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure

    if "amplitude" not in wf or wf["amplitude"].dims != ("window", "frequency"):
        raise ValueError("not a waterfall (needs amplitude over window and frequency; "
                         "geardyn.analysis.orders.waterfall)")
    output = wf.attrs.get("output", "output")
    speed, xlabel, per_omega = _speed_axis(wf)
    hz = wf.attrs.get("hz_per_rad")
    yscale = float(hz) if hz is not None else 1.0
    ylabel = "frequency [Hz]" if hz is not None else \
        f"frequency [{wf['frequency'].attrs.get('units', '')}]"
    m = float(wf.attrs.get("mesh_order", 1.0))
    freq = wf["frequency"].values * yscale
    A = wf["amplitude"].values
    order = np.argsort(speed)
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 6.4 if run is not None else 4.8), layout="constrained")
        if run is not None:
            top, ax = fig.subplots(2, 1, height_ratios=(1, 2.4), sharex=True)
            _output_panel(top, run, output)
        else:
            ax = fig.subplots()
        lo, hi = _colour_limits(A)
        mesh = ax.pcolormesh(_mesh(speed[order]), _mesh(freq), np.clip(A[order].T, lo, None),
                             norm=LogNorm(lo, hi), cmap="viridis", shading="flat",
                             rasterized=True)
        fig.colorbar(mesh, ax=ax, label=f"amplitude of {output} "
                     f"[{wf['amplitude'].attrs.get('units', '')}]")
        s_lo, s_hi = float(speed.min()), float(speed.max())

        def ray(k: float, s_: np.ndarray | float) -> np.ndarray | float:
            """Frequency (axis units) of order k of Omega at speed s_ (axis units)."""
            return k * np.asarray(s_) / per_omega * yscale

        f_top = min(float(freq.max()), float(ray((harmonics + 1) * m, s_hi)))
        ss = np.array([s_lo, s_hi])
        if m != 1.0:  # Omega is a shaft's rotation: its own order, thin
            ax.plot(ss, ray(1.0, ss), color="w", lw=0.5, ls=":", alpha=0.8)
        for k in range(1, harmonics + 1):
            ax.plot(ss, ray(k * m, ss), color="w", lw=0.9, ls="-" if k == 1 else "--",
                    alpha=0.9)
            label = f"{k}×" if m == 1.0 else f"{k}× mesh"
            if ray(k * m, s_hi) <= f_top:
                ax.annotate(label, (s_hi, ray(k * m, s_hi)), color="w", fontsize=7,
                            xytext=(-12 if m == 1.0 else -36, 2), textcoords="offset points")
            else:
                ax.annotate(label, (f_top * per_omega / (k * m * yscale), f_top), color="w",
                            fontsize=7, xytext=(2, -10), textcoords="offset points")
        nat = np.atleast_1d(wf.attrs.get("natural_frequencies", np.array([])))
        nat = nat[nat * yscale <= f_top]
        for j, f in enumerate(nat):
            ax.axhline(f * yscale, color="#ff7f0e", lw=0.9, ls=":",
                       label="natural frequency (linear)" if j == 0 else None)
            for k in range(1, harmonics + 1):  # mesh harmonic k crosses it at speed f / (k m)
                s_x = f / (k * m) * per_omega
                if s_lo <= s_x <= s_hi:
                    ax.plot(s_x, f * yscale, "o", ms=5, mfc="none", color="#ff7f0e")
        what = "of the forcing frequency Omega" if m == 1.0 else \
            f"of the mesh frequency, {m:g} Omega; dotted: Omega"
        ax.set(xlim=(s_lo, s_hi), ylim=(0.0, f_top), xlabel=xlabel, ylabel=ylabel,
               title=f"{wf.attrs.get('model', '')} run-up: waterfall of {output}\n"
                     f"(white: harmonics 1–{harmonics} {what})")
        ax.grid(False)
        if nat.size:
            ax.legend(loc="upper left", fontsize="small")
        if path is not None:
            fig.savefig(Path(path))
    return fig


def _output_panel(ax, run: xr.Dataset, output: str) -> None:
    w = run["Omega"].values
    speed = run["input_speed"].values if "input_speed" in run.coords else w
    ax.plot(speed, run[output].values, lw=0.3, color="k")
    ax.set(ylabel=f"{output} [{run[output].attrs.get('units', '')}]",
           title=f"{output} through the run-up (rate {run.attrs.get('rate', float('nan')):.3g} "
                 f"per time unit)")


def plot_order_map(spec: xr.Dataset, *, max_order: float | None = None,
                   path: str | os.PathLike | None = None):
    """Figure of a :func:`geardyn.analysis.orders.order_spectrum`: amplitude (log colour)
    against speed and order, the harmonics of the mesh frequency (``mesh_order``) marked.
    Saved to ``path`` when given; returns a matplotlib Figure."""
    import matplotlib
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure

    if "amplitude" not in spec or spec["amplitude"].dims != ("window", "order"):
        raise ValueError("not an order spectrum (needs amplitude over window and order; "
                         "geardyn.analysis.orders.order_spectrum)")
    speed, xlabel, _ = _speed_axis(spec)
    orders = spec["order"].values
    top = float(orders.max()) if max_order is None else float(max_order)
    keep = orders <= top
    A = spec["amplitude"].values[:, keep]
    idx = np.argsort(speed)
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 4.4), layout="constrained")
        ax = fig.subplots()
        lo, hi = _colour_limits(A)
        mesh = ax.pcolormesh(_mesh(orders[keep]), _mesh(speed[idx]), np.clip(A[idx], lo, None),
                             norm=LogNorm(lo, hi), cmap="viridis", shading="flat",
                             rasterized=True)
        fig.colorbar(mesh, ax=ax, label=f"amplitude of {spec.attrs.get('output', '')} "
                     f"[{spec['amplitude'].attrs.get('units', '')}]")
        m = float(spec.attrs.get("mesh_order", 1.0))
        for k in range(1, int(top / m) + 1):
            ax.axvline(k * m, color="w", lw=0.5, alpha=0.5)
        ax.set(xlim=(0.0, top), xlabel="order (multiples of Omega; white: mesh harmonics)",
               ylabel=xlabel, title=f"{spec.attrs.get('model', '')} run-up: order map of "
                                    f"{spec.attrs.get('output', '')}")
        ax.grid(False)
        if path is not None:
            fig.savefig(Path(path))
    return fig
