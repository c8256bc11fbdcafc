"""Order analysis of run-ups (geardyn.analysis.orders) on synthetic signals whose orders are
known: a run-up dataset written here by hand (a chirp's phase in closed form, the signal a sum
of sines of whole and fractional orders of it), then the waterfall and the order spectrum
must put each component at its frequency / order with its amplitude; bad inputs name the
field. The figures are drawn for a gear-pair run-up."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from geardyn.analysis.orders import order_spectrum, waterfall
from geardyn.core.results import finish
from geardyn.core.status import status_meaning
from geardyn.errors import ParameterError

#: (order, amplitude) of the synthetic signal's components.
COMPONENTS = ((1.0, 2.0), (2.0, 0.5), (3.5, 0.25))


def _synthetic(start: float = 1.0, stop: float = 3.0, duration: float = 4000.0,
               fs: float = 20.0, hz_per_omega: float | None = None) -> xr.Dataset:
    t = np.arange(0.0, duration + 0.5 / fs, 1.0 / fs)
    a = (stop - start) / duration
    omega = start + a * t
    phase = start * t + 0.5 * a * t * t
    x = sum(amp * np.sin(k * phase + 0.3 * k) for k, amp in COMPONENTS) + 7.0
    ds = xr.Dataset(coords={"time": ("time", t, {"units": "1"})})
    ds["Omega"] = ("time", omega, {"units": "1"})
    ds["phase"] = ("time", phase, {"units": "rad"})
    ds["x"] = ("time", x, {"units": "m"})
    if hz_per_omega is not None:
        ds = ds.assign_coords(mesh_frequency=("time", omega * hz_per_omega, {"units": "Hz"}),
                              input_speed=("time", omega * hz_per_omega * 60.0 / 20.0,
                                           {"units": "rpm"}))
    if hz_per_omega is not None:
        ds.attrs["hz_per_rad"] = hz_per_omega
    ds.attrs.update(status=0, status_meaning=status_meaning(), integrator="synthetic",
                    step=1.0 / fs, steps_per_period=1, time_unit="1", start=start, stop=stop,
                    rate=a, outputs="x", natural_frequencies=np.array([4.0]))
    return finish(ds, "runup")


def test_order_spectrum_puts_each_order_at_its_amplitude():
    ds = _synthetic()
    spec = order_spectrum(ds, "x", cycles=32, samples_per_cycle=32)
    orders = spec["order"].values
    A = spec["amplitude"].values
    for k, amp in COMPONENTS:
        j = int(np.argmin(np.abs(orders - k)))
        assert orders[j] == k  # whole and half orders fall on bins at 32 cycles
        np.testing.assert_allclose(A[:, j], amp, rtol=2e-3)
    elsewhere = np.ones(orders.size, bool)
    for k, _ in COMPONENTS:
        elsewhere &= np.abs(orders - k) > 0.1
    assert A[:, elsewhere].max() < 2e-3 * max(a for _, a in COMPONENTS)
    # each window's speed is the chirp's at its centre
    np.testing.assert_allclose(spec["Omega"].values, 1.0 + (2.0 / 4000.0) * spec["time"].values,
                               rtol=1e-9)


def test_waterfall_peaks_on_the_order_lines():
    ds = _synthetic(hz_per_omega=50.0)
    wf = waterfall(ds, "x", window=200.0)
    f = wf["frequency"].values
    df = f[1] - f[0]
    A = wf["amplitude"].values
    for i in range(0, wf.sizes["window"], 5):
        om = wf["Omega"].values[i]
        for k, amp in COMPONENTS:
            band = np.abs(f - k * om) < 3 * df
            j = np.flatnonzero(band)[np.argmax(A[i, band])]
            assert abs(f[j] - k * om) <= df  # the peak on the order line
            # the speed moves by rate x window = 0.1 within a window: the line smears over
            # k * 0.1 / df bins, so the peak reads less than the amplitude
            assert 0.2 * amp < A[i, j] <= 1.01 * amp
    assert wf.attrs["hz_per_rad"] == pytest.approx(50.0)
    np.testing.assert_allclose(wf["frequency_hz"].values, f * 50.0)
    assert "input_speed" in wf.coords and list(wf.attrs["natural_frequencies"]) == [4.0]


def test_a_steady_sine_reads_its_amplitude():
    """At a (nearly) constant speed the Hann-windowed spectrum reads the sine's amplitude."""
    ds = _synthetic(start=1.0, stop=1.0 + 1e-9)
    wf = waterfall(ds, "x", window=2.0 * math.pi * 64)  # 64 periods: order 1 on a bin
    A = wf["amplitude"].values
    f = wf["frequency"].values
    j = int(np.argmin(np.abs(f - 1.0)))
    np.testing.assert_allclose(A[:, j], 2.0, rtol=1e-3)


@pytest.mark.parametrize("call,field", [
    (lambda ds: waterfall(ds, "nope"), "output"),
    (lambda ds: waterfall(ds, "Omega"), "output"),
    (lambda ds: waterfall(ds, "x", window=-1.0), "window"),
    (lambda ds: waterfall(ds, "x", window=1e9), "window"),
    (lambda ds: waterfall(ds, "x", overlap=1.0), "overlap"),
    (lambda ds: order_spectrum(ds, "x", cycles=1), "cycles"),
    (lambda ds: order_spectrum(ds, "x", samples_per_cycle=2.5), "samples_per_cycle"),
    (lambda ds: waterfall(ds.drop_vars("phase"), "x"), "ds"),
])
def test_bad_inputs_name_the_field(call, field):
    with pytest.raises(ParameterError, match=f"^{field}"):
        call(_synthetic(duration=400.0))


def test_diverged_output_is_refused():
    ds = _synthetic(duration=400.0)
    ds["x"].values[-5:] = np.nan
    with pytest.raises(ParameterError, match="^output.*non-finite"):
        waterfall(ds, "x")


def test_figures_are_drawn(tmp_path):
    import geardyn
    from geardyn.analysis.runup import RunupSettings, runup
    from geardyn.plotting.orders import plot_order_map, plot_waterfall

    ds = runup(geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.05),
               RunupSettings(start=0.3, stop=2.0, rate=2e-3, sample_rate=4.0))
    fig = plot_waterfall(waterfall(ds, "F"), ds, path=tmp_path / "wf.png")
    ax = fig.axes[1]
    assert "speed" in ax.get_xlabel() or "Omega" in ax.get_xlabel()
    assert ax.get_ylabel().startswith("frequency")
    assert (tmp_path / "wf.png").stat().st_size > 10_000
    plot_order_map(order_spectrum(ds, "F"), max_order=5, path=tmp_path / "om.pdf")
    assert (tmp_path / "om.pdf").stat().st_size > 1_000
    with pytest.raises(ValueError, match="not a waterfall"):
        plot_waterfall(ds)
