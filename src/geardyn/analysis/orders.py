"""Order analysis of a run-up: the waterfall (short-time spectra against speed and frequency)
and the order spectrum (order tracking: the signal resampled on the forcing phase).

Both read a :func:`geardyn.analysis.runup.runup` dataset (kind ``"runup"``). Frequencies are
in the units of the model's Omega (rad per time unit), so that the orders are the rays
``k Omega`` (the mesh frequency is ``attrs["mesh_order"]`` Omega) and the natural
frequencies (``attrs["natural_frequencies"]``) horizontal lines; where the run-up has physical
axes (``hz_per_rad``, ``input_speed`` [rpm]) the waterfall carries them too. Amplitudes are
single-sided sine amplitudes (a Hann window, amplitude-corrected: a steady sine of amplitude A
in one bin reads A).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from geardyn.core.results import problems
from geardyn.errors import ParameterError

__all__ = ["order_spectrum", "waterfall"]


def _signal(ds: xr.Dataset, output: str) -> np.ndarray:
    found = problems(ds, "runup")
    if found:
        raise ParameterError("ds", ds.attrs.get("geardyn_kind"),
                             "not a run-up: " + "; ".join(found))
    if output not in ds.data_vars or ds[output].dims != ("time",) \
            or output in ("Omega", "phase"):
        have = [v for v in ds.data_vars if ds[v].dims == ("time",)
                and v not in ("Omega", "phase")]
        raise ParameterError("output", output, f"not an output of this run-up (recorded: "
                             f"{', '.join(have)})")
    x = np.asarray(ds[output].values, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ParameterError("output", output, "has non-finite values (the run diverged: "
                             f"status {ds.attrs.get('status')})")
    return x


def _windows(n: int, size: int, overlap: float) -> np.ndarray:
    """Start indices of windows of ``size`` samples over ``n`` with ``overlap`` (0..1)."""
    if not 0.0 <= overlap < 1.0:
        raise ParameterError("overlap", overlap, "must be in [0, 1)")
    if size < 8:
        raise ParameterError("window", size, "must span at least 8 samples (got that many)")
    if size > n:
        raise ParameterError("window", size, f"is longer than the run ({n} samples; got "
                             "that many)")
    hop = max(1, int(round(size * (1.0 - overlap))))
    return np.arange(0, n - size + 1, hop)


def _amplitudes(X: np.ndarray) -> np.ndarray:
    """Single-sided amplitude spectra of the rows of X (Hann, amplitude-corrected, the mean
    of each row removed)."""
    w = np.hanning(X.shape[1])
    A = np.abs(np.fft.rfft((X - X.mean(axis=1, keepdims=True)) * w, axis=1)) * (2.0 / w.sum())
    A[:, 0] *= 0.5
    return A


def _speed_coords(ds: xr.Dataset, omega: np.ndarray, t: np.ndarray) -> dict:
    coords = {"time": ("window", t, {"units": ds["time"].attrs.get("units", ""),
                                     "long_name": "time of the window's centre"}),
              "Omega": ("window", omega, {**ds["Omega"].attrs,
                                          "long_name": "forcing frequency at the centre"})}
    if "input_speed" in ds.coords:
        rpm = np.interp(t, ds["time"].values, ds["input_speed"].values)
        coords["input_speed"] = ("window", rpm, dict(ds["input_speed"].attrs))
    return coords


def _attrs(ds: xr.Dataset, output: str, what: str) -> dict:
    out = {"output": output, "analysis": what, "model": ds.attrs.get("model", ""),
           "omega_units": ds.attrs.get("omega_units", ""),
           "output_units": ds[output].attrs.get("units", "")}
    if "natural_frequencies" in ds.attrs:
        out["natural_frequencies"] = np.atleast_1d(ds.attrs["natural_frequencies"])
    out["mesh_order"] = float(ds.attrs.get("mesh_order", 1.0))
    if "hz_per_rad" in ds.attrs:
        out["hz_per_rad"] = float(ds.attrs["hz_per_rad"])
    return out


def waterfall(ds: xr.Dataset, output: str, *, window: float | None = None,
              overlap: float = 0.5) -> xr.Dataset:
    """Short-time amplitude spectra of ``output`` along a run-up.

    Windows of ``window`` time units (default: a 32nd of the run; Hann, ``overlap`` between
    windows): the frequency resolution is 2 pi / window in Omega's units, and the speed
    moves by rate x window within one. Returns a Dataset over (``window``, ``frequency``):
    ``amplitude`` [output units], ``frequency`` in Omega's units (rad per time unit: the
    order-k line is ``k Omega``) and, where the run-up has them, ``frequency_hz`` [Hz]; per
    window its centre ``time``, ``Omega`` (and ``input_speed`` [rpm]). Attributes carry the
    model's ``natural_frequencies`` (Omega's units), ``mesh_order`` and ``hz_per_rad``.
    """
    x = _signal(ds, output)
    t = ds["time"].values
    if t.size < 2:
        raise ParameterError("ds", t.size, "a run-up of at least 2 samples")
    dt = float(t[1] - t[0])
    if window is None:
        window = (t[-1] - t[0]) / 32.0
    if isinstance(window, bool) or not isinstance(window, int | float) \
            or not math.isfinite(window) or window <= 0:
        raise ParameterError("window", window, "must be a positive time")
    size = int(math.ceil(window / dt))
    starts = _windows(x.size, size, overlap)
    idx = starts[:, None] + np.arange(size)[None, :]
    A = _amplitudes(x[idx])
    freq = 2.0 * math.pi * np.fft.rfftfreq(size, dt)
    centre = starts + size // 2
    coords = _speed_coords(ds, ds["Omega"].values[centre], t[centre])
    coords["frequency"] = ("frequency", freq, {"units": ds["Omega"].attrs.get("units", ""),
                                               "long_name": "angular frequency"})
    hz = ds.attrs.get("hz_per_rad")
    if hz is not None:
        coords["frequency_hz"] = ("frequency", freq * hz, {"units": "Hz",
                                                           "long_name": "frequency"})
    out = xr.Dataset(coords=coords)
    out["amplitude"] = (("window", "frequency"), A, {
        "units": ds[output].attrs.get("units", ""),
        "long_name": f"amplitude of {output} (Hann, single-sided)"})
    out.attrs.update(_attrs(ds, output, "waterfall"), window_samples=size,
                     window_time=size * dt, overlap=overlap)
    return out


def order_spectrum(ds: xr.Dataset, output: str, *, cycles: int = 32,
                   samples_per_cycle: int = 32, overlap: float = 0.5) -> xr.Dataset:
    """Order tracking: ``output`` resampled at ``samples_per_cycle`` equal steps of the forcing
    phase per forcing cycle (a cubic spline in the phase), then amplitude spectra of
    windows of ``cycles`` cycles (Hann, ``overlap``). Orders are multiples of the forcing
    frequency (order 1: the mesh frequency), exact at every speed. Returns a Dataset over
    (``window``, ``order``): ``amplitude``; per window its centre ``time``, ``Omega``."""
    x = _signal(ds, output)
    for name, v in (("cycles", cycles), ("samples_per_cycle", samples_per_cycle)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 2:
            raise ParameterError(name, v, "must be an integer >= 2")
    th = ds["phase"].values
    if not (np.all(np.diff(th) > 0) or np.all(np.diff(th) < 0)):
        raise ParameterError("ds", "phase", "the phase must move one way (a speed that "
                             "never reaches 0)")
    sign = 1.0 if th[-1] > th[0] else -1.0
    grid = th[0] + sign * np.arange(0.0, abs(th[-1] - th[0]), 2.0 * math.pi / samples_per_cycle)
    from scipy.interpolate import CubicSpline

    order_ = np.argsort(th)
    xs = CubicSpline(th[order_], x[order_])(grid)
    size = cycles * samples_per_cycle
    starts = _windows(xs.size, size, overlap)
    A = _amplitudes(xs[starts[:, None] + np.arange(size)[None, :]])
    orders = np.fft.rfftfreq(size, 1.0 / samples_per_cycle)
    centre_phase = grid[starts + size // 2]
    t_c = np.interp(centre_phase, th[order_], ds["time"].values[order_])
    w_c = np.interp(t_c, ds["time"].values, ds["Omega"].values)
    out = xr.Dataset(coords={**_speed_coords(ds, w_c, t_c),
                             "order": ("order", orders, {"units": "1", "long_name":
                                                         "order of the forcing frequency"})})
    out["amplitude"] = (("window", "order"), A, {
        "units": ds[output].attrs.get("units", ""),
        "long_name": f"amplitude of {output} per order (Hann, single-sided)"})
    out.attrs.update(_attrs(ds, output, "order spectrum"), cycles=cycles,
                     samples_per_cycle=samples_per_cycle, overlap=overlap)
    return out
