"""Amplitude spectra of one steady motion, and names for their peaks.

:func:`amplitude_spectrum` returns the single-sided amplitude spectrum of one coordinate with
frequency in units of the mesh (forcing) frequency Omega, so the mesh harmonics sit at 1, 2, 3 ...
The record is cut to whole forcing periods (the harmonics then fall on frequency bins), the mean
is removed and a window applied; amplitudes are scaled by the window's coherent gain,
``A_k = 2 |X_k| / sum(w)``, so a sinusoid ``A cos(2 pi f t)`` whose frequency lies on a bin reads
``A`` exactly (Hann, the default, separates tones 2 bins apart). Off-bin tones read low by up
to 15 % with Hann (scalloping); ``window="flattop"`` reads them within 0.1 % at the cost of a
wider peak. The bin at frequency 0 holds ``|mean|``.

:func:`label_peaks` names the largest peaks: mesh harmonics ``kΩ``, subharmonics ``jΩ/n``,
load-fluctuation lines ``mΛ`` and their sidebands ``kΩ ± mΛ`` (Λ = omega_l / omega_n, the load
fluctuation frequency of Eq. 14, in the same units as Omega).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from geardyn.core.settings import check_omega

__all__ = ["amplitude_spectrum", "label_peaks", "time_series"]


def time_series(ds: xr.Dataset, state: str) -> xr.DataArray:
    """The time history of ``state`` in a simulation dataset: itself, or planet set 1's
    (``X_sq`` -> ``X_sq1``) in a general (4N-state) simulation."""
    for name in (state, f"{state}1"):
        if name in ds.data_vars and ds[name].dims == ("time",):
            return ds[name]
    known = [str(v) for v in ds.data_vars if ds[v].dims == ("time",)]
    raise ValueError(f"state: {state!r} is not in the simulation; known: {', '.join(known)}")


def _as_signal(data, state, dt, omega):
    """(samples, dt, Omega, attributes) of the supported inputs."""
    attrs: dict = {}
    if isinstance(data, xr.Dataset):
        attrs = dict(data.attrs)
        if state is None:
            state = str(data["state"].values[0]) if "state" in data.coords else None
        if state is None:
            raise ValueError("state: name the coordinate to analyse")
        data = time_series(data, state)
    if isinstance(data, xr.DataArray):
        attrs = {**attrs, **data.attrs, "state": str(data.name)}
        if dt is None:
            t = np.asarray(data["time"].values, dtype=float)
            steps = np.diff(t)
            if t.size < 2 or not np.allclose(steps, steps[0], rtol=1e-9, atol=0.0):
                raise ValueError("time: the samples must be equally spaced")
            dt = float(steps[0])
        if omega is None:
            omega = attrs.get("Omega")
        x = np.asarray(data.values, dtype=float)
    else:
        x = np.asarray(data, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"signal: expected one coordinate over time (got shape {x.shape})")
    if dt is None or not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt: a positive sampling interval is needed (got {dt!r})")
    if omega is None:
        raise ValueError("omega: the mesh frequency is needed (not given, not in the attrs)")
    check_omega(omega, "omega")
    return x, float(dt), float(omega), attrs


def amplitude_spectrum(
    data: xr.Dataset | xr.DataArray | np.ndarray,
    state: str | None = None,
    *,
    dt: float | None = None,
    omega: float | None = None,
    window: str = "hann",
    Lambda: float | None = None,
) -> xr.DataArray:
    """Single-sided amplitude spectrum of one coordinate (see the module docs for the scaling).

    Parameters
    ----------
    data
        A dataset from :func:`geardyn.simulate` (``state`` picks the coordinate, default the first
        state), a DataArray over ``time``, or an array of equally spaced samples.
    dt
        Sampling interval in model time units (default: from the ``time`` coordinate).
    omega
        Mesh (forcing) frequency Omega, angular, in the same time units (default: the dataset's
        ``Omega`` attribute).
    window
        Any window :func:`scipy.signal.get_window` knows: ``"hann"``, ``"flattop"``, ``"boxcar"``.
    Lambda
        Load fluctuation frequency, stored for :func:`label_peaks` (default: the ``Lambda``
        attribute of the data, if any).

    Returns
    -------
    xarray.DataArray ``amplitude`` over ``frequency`` (in units of Omega), in the units of the
    coordinate; attributes ``Omega``, ``window``, ``resolution`` (bin width, units of Omega),
    ``n_samples``, ``state`` and ``Lambda`` where known.
    """
    x, dt, omega, attrs = _as_signal(data, state, dt, omega)
    per_period = 2.0 * math.pi / omega / dt
    n_per = round(per_period)
    if n_per >= 1 and abs(per_period - n_per) < 1e-6 * per_period and x.size >= n_per:
        x = x[: (x.size // n_per) * n_per]  # whole forcing periods (drops a closing endpoint)
    n = x.size
    if n < 4:
        raise ValueError(f"signal: at least 4 samples are needed (got {n})")
    if not np.all(np.isfinite(x)):
        raise ValueError("signal: holds NaN or inf (a diverged run has no spectrum)")
    from scipy.signal import get_window  # imported here: scipy.signal takes ~1 s to import

    w = get_window(window, n, fftbins=True)
    mean = float(np.mean(x))
    amp = 2.0 * np.abs(np.fft.rfft(w * (x - mean))) / np.sum(w)
    if n % 2 == 0:
        amp[-1] /= 2.0  # the Nyquist bin has no mirror image
    amp[0] = abs(mean)
    resolution = 2.0 * math.pi / (n * dt * omega)
    freq = np.arange(amp.size) * resolution
    lam = Lambda if Lambda is not None else attrs.get("Lambda")
    out_attrs = {
        "long_name": "single-sided amplitude",
        "units": str(attrs.get("units", "1")),
        "Omega": omega,
        "window": str(window),
        "resolution": resolution,
        "n_samples": int(n),
        "dt": dt,
    }
    if "state" in attrs:
        out_attrs["state"] = attrs["state"]
    if lam is not None:
        out_attrs["Lambda"] = float(lam)
    coords = {"frequency": ("frequency", freq, {
        "units": "Omega", "long_name": "frequency / mesh frequency Omega"})}
    return xr.DataArray(amp, dims=("frequency",), coords=coords, name="amplitude",
                        attrs=out_attrs)


# --------------------------------------------------------------------------- peak names
def _times(k: int, symbol: str) -> str:
    return symbol if k == 1 else f"{k}{symbol}"


def _candidates(lam: float | None, max_harmonic: int, max_sideband: int,
                max_subharmonic: int) -> list[tuple[float, str, str, int]]:
    """(frequency / Omega, label, kind, rank) of every line considered; lower rank wins ties."""
    out = [(float(k), _times(k, "Ω"), "harmonic", 0) for k in range(1, max_harmonic + 1)]
    for n in range(2, max_subharmonic + 1):
        for j in range(1, n * max_harmonic):
            if math.gcd(j, n) == 1:
                out.append((j / n, f"{_times(j, 'Ω')}/{n}", "subharmonic", 1))
    if lam is not None and lam > 0:
        for m in range(1, max_sideband + 1):
            out.append((m * lam, _times(m, "Λ"), "load", 2))
            for k in range(1, max_harmonic + 1):
                for sign in (1, -1):
                    f = k + sign * m * lam
                    if f > 0:
                        op = "+" if sign > 0 else "−"
                        out.append((f, f"{_times(k, 'Ω')}{op}{_times(m, 'Λ')}", "sideband", 3))
    return out


def label_peaks(
    spectrum: xr.DataArray,
    Lambda: float | None = None,
    *,
    threshold: float = 1e-2,
    max_peaks: int = 12,
    max_harmonic: int = 10,
    max_sideband: int = 3,
    max_subharmonic: int = 4,
    tol: float | None = None,
) -> xr.Dataset:
    """The largest peaks of an :func:`amplitude_spectrum`, each named after the line it sits on.

    A peak is a local maximum (frequency > 0) of at least ``threshold`` times the largest one;
    the ``max_peaks`` largest are kept. A peak within ``tol`` (default: one frequency bin) of a
    line is named after it: ``kΩ`` (mesh harmonic), ``jΩ/n`` (subharmonic, n <= max_subharmonic),
    ``mΛ`` (load fluctuation) or ``kΩ±mΛ`` (sideband), where ``Lambda`` (default: the spectrum's
    ``Lambda`` attribute; None or 0: no load lines) is the load fluctuation frequency in the units
    of Omega's. Where several lines are that close, the simpler kind (harmonic, subharmonic, load,
    sideband) wins. Other peaks are labelled by their frequency (kind ``other``).

    Returns
    -------
    xarray.Dataset over ``peak`` (largest first): ``frequency`` (units of Omega), ``amplitude``,
    ``label``, ``kind`` (harmonic, subharmonic, load, sideband, other) and ``offset`` (peak minus
    line frequency).
    """
    freq = np.asarray(spectrum["frequency"].values, dtype=float)
    amp = np.asarray(spectrum.values, dtype=float)
    resolution = float(spectrum.attrs.get("resolution", freq[1] - freq[0] if freq.size > 1 else 1))
    tol = resolution if tol is None else float(tol)
    lam_abs = Lambda if Lambda is not None else spectrum.attrs.get("Lambda")
    omega = float(spectrum.attrs.get("Omega", 1.0))
    lam = None if lam_abs in (None, 0.0) else float(lam_abs) / omega

    a = amp[1:]
    top = float(np.max(a)) if a.size else 0.0
    idx = []
    if top > 0 and a.size >= 3:
        inner = np.arange(1, a.size - 1)
        is_peak = (a[inner] > a[inner - 1]) & (a[inner] >= a[inner + 1])
        idx = [int(i) + 1 for i in inner[is_peak] if a[i] >= threshold * top]
        idx.sort(key=lambda i: -amp[i])
        idx = idx[:max_peaks]
    lines = _candidates(lam, max_harmonic, max_sideband, max_subharmonic)
    rows = []
    for i in idx:
        f = float(freq[i])
        near = [c for c in lines if abs(c[0] - f) <= tol]
        if near:
            line = min(near, key=lambda c: (c[3], abs(c[0] - f)))
            rows.append((f, float(amp[i]), line[1], line[2], f - line[0]))
        else:
            rows.append((f, float(amp[i]), f"{f:.3g}Ω", "other", float("nan")))
    cols = list(zip(*rows, strict=True)) if rows else [[], [], [], [], []]
    return xr.Dataset(
        {
            "frequency": ("peak", np.array(cols[0], dtype=float), {"units": "Omega"}),
            "amplitude": ("peak", np.array(cols[1], dtype=float),
                          {"units": spectrum.attrs.get("units", "1")}),
            "label": ("peak", np.array(cols[2], dtype=str)),
            "kind": ("peak", np.array(cols[3], dtype=str)),
            "offset": ("peak", np.array(cols[4], dtype=float), {"units": "Omega"}),
        },
        attrs={"tolerance": tol, "threshold": threshold,
               **({"Lambda": float(lam_abs)} if lam is not None else {})},
    )
