"""Amplitude spectra and peak names, against signals whose lines are known analytically."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.analysis.spectrum import amplitude_spectrum, label_peaks
from shared_models import oscillator

OMEGA = 1.1
PER_PERIOD = 128
PERIODS = 64


def _signal(components, mean=0.0, omega=OMEGA, periods=PERIODS, per_period=PER_PERIOD,
            endpoint=True):
    """Samples of mean + sum A cos(f * omega * t + phase) over whole forcing periods; ``f`` in
    units of omega. Returns (t, x)."""
    dt = 2.0 * math.pi / omega / per_period
    t = np.arange(periods * per_period + (1 if endpoint else 0)) * dt
    x = np.full_like(t, mean)
    for f, amp, phase in components:
        x += amp * np.cos(f * omega * t + phase)
    return t, x


def _at(spec: xr.DataArray, f: float) -> float:
    return float(spec.sel(frequency=f, method="nearest"))


def test_on_bin_lines_read_their_exact_amplitudes_with_hann():
    # lines at least 2 bins apart (bin = 1/64 Omega); the closing endpoint is dropped
    comps = [(1.0, 1.0, 0.3), (2.0, 0.3, -1.0), (0.5, 0.05, 0.0), (3.0, 0.02, 2.0),
             (1.125, 0.1, 0.7), (0.875, 0.1, -0.2)]
    t, x = _signal(comps, mean=0.7)
    spec = amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA)
    assert spec.attrs["n_samples"] == PERIODS * PER_PERIOD
    assert spec.attrs["resolution"] == pytest.approx(1.0 / PERIODS)
    assert spec["frequency"].attrs["units"] == "Omega"
    for f, amp, _ in comps:
        assert _at(spec, f) == pytest.approx(amp, rel=1e-9)
        assert float(spec["frequency"].sel(frequency=f, method="nearest")) == pytest.approx(f)
    assert float(spec[0]) == pytest.approx(0.7, rel=1e-12)
    # nothing else: two bins away from every line the spectrum is at round-off level
    lines = np.array([f for f, _, _ in comps])
    far = np.min(np.abs(spec["frequency"].values[1:, None] - lines[None, :]), axis=1) > 2.5 / 64
    assert np.max(spec.values[1:][far]) < 1e-12


def test_off_bin_sidebands_with_flattop_window():
    """Sidebands Omega +- Lambda with Lambda/Omega = 0.118 (7.55 bins: off the bin grid)."""
    lam = 0.13
    comps = [(1.0, 1.0, 0.0), (1 - lam / OMEGA, 0.1, 0.4), (1 + lam / OMEGA, 0.07, 1.1)]
    t, x = _signal(comps)
    flat = amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA, window="flattop", Lambda=lam)
    hann = amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA, window="hann")
    peaks = label_peaks(flat)
    by_label = {str(lb): (float(f), float(a)) for lb, f, a in
                zip(peaks["label"].values, peaks["frequency"].values,
                    peaks["amplitude"].values, strict=True)}
    for f, amp, _ in comps:
        name = {1.0: "Ω"}.get(f, "Ω−Λ" if f < 1 else "Ω+Λ")
        got_f, got_a = by_label[name]
        assert abs(got_f - f) <= 0.5 / PERIODS + 1e-12
        assert got_a == pytest.approx(amp, rel=2e-3)
    # Hann reads an off-bin line low (scalloping, at most 1.42 dB) but never high
    lower = hann.sel(frequency=slice(1 - lam / OMEGA - 0.02, 1 - lam / OMEGA + 0.02)).max()
    assert 0.1 * 10 ** (-1.43 / 20) <= float(lower) < 0.1


def test_amplitude_does_not_depend_on_sampling_or_record_length():
    comps = [(1.0, 0.8, 0.2), (2.0, 0.25, 0.0)]
    readings = []
    for periods, per_period in ((16, 64), (64, 200), (33, 97)):
        t, x = _signal(comps, periods=periods, per_period=per_period)
        spec = amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA)
        readings.append([_at(spec, 1.0), _at(spec, 2.0)])
    np.testing.assert_allclose(readings, [[0.8, 0.25]] * 3, rtol=1e-9)


def test_label_peaks_names_harmonics_subharmonics_and_sidebands():
    lam = OMEGA * 8 / PERIODS  # sidebands on bins: amplitudes exact with Hann
    comps = [(1.0, 1.0, 0.0), (2.0, 0.3, 0.5), (0.5, 0.05, 0.0), (1.5, 0.04, 0.0),
             (1 - 8 / PERIODS, 0.1, 0.0), (1 + 8 / PERIODS, 0.1, 0.2),
             (2 + 8 / PERIODS, 0.03, 0.0), (8 / PERIODS, 0.2, 0.0), (3.0, 0.02, 0.0)]
    t, x = _signal(comps)
    spec = amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA, Lambda=lam)
    peaks = label_peaks(spec)
    got = dict(zip(peaks["label"].values.tolist(), peaks["kind"].values.tolist(), strict=True))
    assert got == {"Ω": "harmonic", "2Ω": "harmonic", "3Ω": "harmonic",
                   "Ω/2": "subharmonic", "3Ω/2": "subharmonic",
                   "Ω−Λ": "sideband", "Ω+Λ": "sideband", "2Ω+Λ": "sideband", "Λ": "load"}
    amps = dict(zip(peaks["label"].values.tolist(), peaks["amplitude"].values, strict=True))
    assert amps["2Ω+Λ"] == pytest.approx(0.03, rel=1e-9)
    # largest first
    assert np.all(np.diff(peaks["amplitude"].values) <= 0)
    # without Lambda the load lines are not passed off as harmonics: they stay unnamed
    blind = label_peaks(spec, Lambda=0.0)
    kinds = dict(zip(blind["label"].values.tolist(), blind["kind"].values.tolist(), strict=True))
    assert kinds["Ω"] == "harmonic" and kinds["Ω/2"] == "subharmonic"
    assert sorted(k for k in kinds.values() if k == "other") == ["other"] * 4
    assert "Ω+Λ" not in kinds
    # threshold and max_peaks
    top = label_peaks(spec, threshold=0.09)
    assert set(top["label"].values.tolist()) == {"Ω", "2Ω", "Λ", "Ω−Λ", "Ω+Λ"}
    assert label_peaks(spec, max_peaks=2)["label"].values.tolist() == ["Ω", "2Ω"]


def test_dataset_input_uses_time_axis_and_omega_and_drops_the_endpoint():
    t, x = _signal([(1.0, 1.0, 0.0), (0.5, 0.2, 0.0)], mean=3.0)
    ds = xr.Dataset({"X_sq": ("time", x, {"units": "1"}), "V_sq": ("time", np.gradient(x, t))},
                    coords={"time": t, "state": ["X_sq", "V_sq"]},
                    attrs={"Omega": OMEGA, "Lambda": 0.25})
    spec = amplitude_spectrum(ds, "X_sq")
    direct = amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA)
    xr.testing.assert_allclose(spec.drop_attrs(), direct.drop_attrs())
    assert spec.attrs["Lambda"] == 0.25 and spec.attrs["state"] == "X_sq"
    assert spec.attrs["n_samples"] == x.size - 1
    assert amplitude_spectrum(ds).attrs["state"] == "X_sq"  # the first state by default


def test_bad_input_is_named():
    t, x = _signal([(1.0, 1.0, 0.0)])
    with pytest.raises(ValueError, match="omega"):
        amplitude_spectrum(x, dt=t[1] - t[0])
    with pytest.raises(ValueError, match="dt"):
        amplitude_spectrum(x, omega=OMEGA)
    x[10] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        amplitude_spectrum(x, dt=t[1] - t[0], omega=OMEGA)
    ds = xr.Dataset({"x": ("time", np.ones(8))}, coords={"time": np.arange(8.0)},
                    attrs={"Omega": 1.0})
    with pytest.raises(ValueError, match="'y'.*known: x"):
        amplitude_spectrum(ds, "y")


def test_simulated_linear_oscillator_spectrum_matches_its_frequency_response():
    """The steady response of a linear oscillator to cos(W t) + m/2 cos((W -+ L) t) has the line
    amplitudes F / |1 - w^2 + 2 i c w|: simulate, take the spectrum, compare line by line."""
    c, m, om, periods = 0.1, 0.6, 1.3, 64
    lam = om * 8 / periods  # sidebands on frequency bins
    # x'' + 2 c x' + x = (1 + m cos(Lambda t)) cos(Omega t)
    u = oscillator(zeta=c, F=1.0, m=m, Lambda=lam, Omega=om)
    ds = geardyn.simulate(u,
                          run=geardyn.RunSettings(transient=400.0, samples=periods,
                                                  steps_per_period=256))
    spec = amplitude_spectrum(ds, "x", Lambda=lam)
    peaks = label_peaks(spec)
    amps = dict(zip(peaks["label"].values.tolist(), peaks["amplitude"].values, strict=True))
    assert set(amps) == {"Ω", "Ω−Λ", "Ω+Λ"}
    for label, w, force in (("Ω", om, 1.0), ("Ω−Λ", om - lam, m / 2), ("Ω+Λ", om + lam, m / 2)):
        expected = force / abs(1.0 - w**2 + 2j * c * w)
        assert amps[label] == pytest.approx(expected, rel=1e-6), label
