"""The fixed sensor of a planetary stage
(:func:`geardyn.analysis.sensor.planetary_sensor_signal`): the signal against carrier
revolutions with the planet-pass windows, and its order spectrum around the mesh harmonics with
the sidebands labelled m Z_r +- k (those the phasing keeps for equally spaced planets marked)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.analysis.sensor import label_sidebands, planet_window, sensor_spectrum
from geardyn.plotting.style import RC

__all__ = ["plot_sensor"]


def plot_sensor(sig: xr.Dataset, path: str | os.PathLike | None = None, *,
                harmonics: int = 2, span: int = 8, revolutions: int | None = None):
    """Figure of a sensor signal ``sig``: top, the signal over (at most) two carrier
    revolutions with each planet's window (right axis); below, the amplitude spectrum in carrier
    orders around each of the first ``harmonics`` mesh harmonics m Z_r (+- ``span`` orders),
    the lines m Z_r + k labelled. ``revolutions``: the whole carrier revolutions the signal
    spans (default: from ``carrier_revolutions``, rounded). Saved to ``path`` when given;
    returns a matplotlib Figure."""
    import matplotlib
    from matplotlib.figure import Figure

    if not {"signal", "carrier_revolutions"} <= set(sig):
        raise ValueError("not a sensor signal (needs signal and carrier_revolutions; "
                         "geardyn.analysis.sensor.planetary_sensor_signal)")
    z_r, n_p = int(sig.attrs["ring_teeth"]), int(sig.attrs["n_planets"])
    rev = sig["carrier_revolutions"].values
    rev = rev - rev[0]
    if revolutions is None:
        step = rev[1] - rev[0] if rev.size > 1 else 0.0
        revolutions = int(round(rev[-1] + step))
    spec = sensor_spectrum(sig["signal"].values, revolutions)
    peaks = label_sidebands(spec, z_r, harmonics=harmonics, span=span, rel=1e-3)
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 2.6 + 2.2 * harmonics), layout="constrained")
        axes = fig.subplots(1 + harmonics, 1, squeeze=False)[:, 0]
        ax = axes[0]
        shown = rev <= min(2.0, rev[-1])
        ax.plot(rev[shown], sig["signal"].values[shown], lw=0.5, color="C0")
        ax.set_xlabel("carrier revolutions relative to the ring, from the start of the record")
        ax.set_ylabel("sensor signal [N]")
        ax.set_title(f"sensor on the ring: {n_p} planets, Z_r = {z_r}, {sig.attrs['window']} "
                     f"window {np.degrees(sig.attrs['width']):.0f} deg wide")
        win = ax.twinx()
        win.grid(False)
        phi = sig["carrier_angle"].values[shown]
        psi = np.atleast_1d(np.asarray(sig.attrs["planet_angles"], dtype=float))
        for n, p in enumerate(psi):
            win.plot(rev[shown], planet_window(phi + p - sig.attrs["sensor_angle"],
                                               sig.attrs["width"], sig.attrs["window"]),
                     color=f"C{n + 1}", lw=0.8, alpha=0.6)
        win.set_ylabel("planet window w [–]")
        win.set_ylim(0.0, 3.0)
        order, amp = spec["order"].values, spec["amplitude"].values
        for m, ax in enumerate(axes[1:], start=1):
            lo, hi = m * z_r - span - 0.5, m * z_r + span + 0.5
            sel = (order >= lo) & (order <= hi)
            ax.vlines(order[sel], 0.0, amp[sel], color="0.3", lw=1.0)
            ax.axvline(m * z_r, color="C3", ls=":", lw=0.8)
            top = max((a for q, a, _ in peaks if lo <= q <= hi), default=0.0)
            for q, a, lab in peaks:
                if lo <= q <= hi:
                    k = int(round(q)) - m * z_r
                    kept = (m * z_r + k) % n_p == 0
                    ax.annotate(lab, (q, a), xytext=(0, 3), textcoords="offset points",
                                ha="center", fontsize=7, color="C0" if kept else "0.5")
            ax.set_xlim(lo, hi)
            ax.set_ylim(0.0, 1.25 * top if top > 0 else 1.0)
            ax.set_xlabel(f"carrier order (mesh harmonic {m}: {m * z_r}, dotted)")
            ax.set_ylabel("amplitude [N]")
    if path is not None:
        fig.savefig(Path(path))
    return fig
