"""The fixed-sensor signal of a planetary stage (geardyn.analysis.sensor): a single planet gives
the amplitude modulation whose sidebands are the window's Fourier coefficients (computed here by
quadrature), equally spaced identical planets keep only the carrier orders that are multiples of
N (synthetic forces and a PlanetaryGearSet run)."""

from __future__ import annotations

import math
import tomllib
from importlib.resources import files

import numpy as np
import pytest
from scipy.integrate import quad

import geardyn
from geardyn.analysis.sensor import (
    carrier_angle,
    label_sidebands,
    planet_window,
    planetary_sensor_signal,
    sensor_signal,
    sensor_spectrum,
    surviving_orders,
)
from planetary_example_set import planetary_by_hand

ZR = 71


def hann_coefficient(k: int, width: float) -> float:
    """c_k = (1/2pi) int w(a) e^{-ika} da of the Hann window cos^2(pi a / width), |a| <
    width / 2 (real: the window is even), by adaptive quadrature."""
    def w(a):
        return math.cos(math.pi * a / width) ** 2 * math.cos(k * a)
    val, _ = quad(w, -width / 2, width / 2, epsabs=1e-14, epsrel=1e-12, limit=200)
    return val / (2.0 * math.pi)


def uniform_angle(revolutions: int, per_rev: int) -> np.ndarray:
    return 2.0 * math.pi * np.arange(revolutions * per_rev) / per_rev


def test_single_planet_gives_the_window_coefficients_as_sidebands():
    width, theta_s, A, R = 1.3, 0.4, 5.0, 3
    phi = uniform_angle(R, 4096)
    F = (A * np.cos(ZR * phi))[:, None]
    s = sensor_signal(F, phi, [0.0], sensor_angle=theta_s, width=width)
    # textbook modulation: the envelope is the window, largest with the planet at the sensor
    np.testing.assert_allclose(s, A * np.cos(ZR * phi) * planet_window(phi - theta_s, width))
    spec = sensor_spectrum(s, R)
    amp = spec["amplitude"].values
    for k in range(-12, 13):
        q = ZR + k
        # e^{iq phi} collects c_{q-Zr} e^{-i(q-Zr) theta_s} and the image c_{q+Zr} e^{-i(q+Zr)...}
        coef = 0.5 * A * (hann_coefficient(q - ZR, width) * np.exp(-1j * (q - ZR) * theta_s)
                          + hann_coefficient(q + ZR, width) * np.exp(-1j * (q + ZR) * theta_s))
        # (the sampled window aliases c_{k +- 4096}: relative error ~1e-7)
        assert amp[q * R] == pytest.approx(2.0 * abs(coef), rel=1e-6, abs=1e-12)
    # the carrier sidebands are symmetric for one planet: |c_k| = |c_-k|
    assert amp[(ZR + 2) * R] == pytest.approx(amp[(ZR - 2) * R], rel=1e-3)


@pytest.mark.parametrize(("n_planets", "ring_teeth"), [(3, 71), (4, 71), (5, 72), (4, 72)])
def test_equally_spaced_planets_keep_only_orders_that_are_multiples_of_n(n_planets, ring_teeth):
    width, R = 1.1, 2
    phi = uniform_angle(R, 1920)  # psi_n on the grid for N = 3, 4, 5
    psi = 2.0 * math.pi * np.arange(n_planets) / n_planets
    ang = phi[:, None] + psi  # each planet's angle relative to the ring
    F = 300.0 + 7.0 * np.cos(ring_teeth * ang + 0.3) + 2.0 * np.cos(2 * ring_teeth * ang - 1.0)
    s = sensor_signal(F, phi, psi, sensor_angle=0.2, width=width)
    amp = sensor_spectrum(s, R)["amplitude"].values
    single = sensor_spectrum(sensor_signal(F[:, :1], phi, psi[:1], 0.2, width), R)
    one = single["amplitude"].values
    top = amp.max()
    for m in (1, 2):
        keep = surviving_orders(ring_teeth, n_planets, m, 10)
        assert keep == [k for k in range(-10, 11) if (m * ring_teeth + k) % n_planets == 0]
        for k in range(-10, 11):
            i = (m * ring_teeth + k) * R
            if k in keep:  # N planets in phase: N times one planet's line
                assert amp[i] == pytest.approx(n_planets * one[i], rel=1e-8, abs=1e-9 * top)
            else:
                assert amp[i] < 1e-10 * top
    # the kept sidebands are symmetric about Z_r only where 2 Z_r is a multiple of N
    keep1 = surviving_orders(ring_teeth, n_planets, 1, 10)
    assert all(-k in keep1 for k in keep1) == ((2 * ring_teeth) % n_planets == 0)


def test_planetary_gear_set_run_cancels_the_sidebands_phasing_cancels():
    doc = tomllib.loads(files("geardyn.studies").joinpath("planetary_example.toml").read_text())
    model = planetary_by_hand(doc)
    R = 3
    ds = geardyn.simulate(model, omega=0.2, run=geardyn.RunSettings(transient=3000.0,
                                                                    samples=R * ZR),
                          record_every=15)
    sig = planetary_sensor_signal(ds.isel(time=slice(0, -1)), model, width=math.pi / 2)
    assert sig["carrier_revolutions"].values[-1] - sig["carrier_revolutions"].values[0] \
        == pytest.approx(R, abs=0.01)
    spec = sensor_spectrum(sig["signal"].values, R)
    amp = spec["amplitude"].values
    band = {k: amp[(ZR + k) * R] for k in range(-8, 9)}
    top = max(band.values())
    keep = surviving_orders(ZR, 4, 1, 8)  # 71 = 3 (mod 4): k = -7, -3, 1, 5
    assert keep == [-7, -3, 1, 5]
    for k, a in band.items():
        if k in keep:
            assert a > 1e-3 * top
        else:
            assert a < 1e-4 * top, (k, a / top)
    labels = {lab for _, _, lab in label_sidebands(spec, ZR, harmonics=1, span=8)}
    assert {"1Zr-3", "1Zr+1"} <= labels and "1Zr" not in labels


def test_bad_inputs_name_the_field():
    with pytest.raises(geardyn.ParameterError, match="width"):
        planet_window(0.0, 0.0)
    with pytest.raises(geardyn.ParameterError, match="window"):
        planet_window(0.0, 1.0, window="box")
    with pytest.raises(geardyn.ParameterError, match="forces"):
        sensor_signal(np.zeros((10, 3)), np.zeros(10), [0.0, 1.0])
    with pytest.raises(geardyn.ParameterError, match="carrier_angle"):
        sensor_signal(np.zeros((10, 2)), np.zeros(9), [0.0, 1.0])
    with pytest.raises(geardyn.ParameterError, match="carrier_revolutions"):
        sensor_spectrum(np.zeros(64), 1.5)


def test_lanes_go_through_at_once():
    phi = uniform_angle(1, 256)
    psi = np.array([0.0, 2.1, 4.2])
    F = np.random.default_rng(1).normal(size=(5, 256, 3))
    many = sensor_signal(F, phi, psi, 0.3, 1.0, "gaussian")
    for lane in range(5):
        np.testing.assert_allclose(many[lane], sensor_signal(F[lane], phi, psi, 0.3, 1.0,
                                                             "gaussian"))


def test_plot_sensor_draws_the_signal_and_labelled_sidebands(tmp_path):
    import xarray as xr

    from geardyn.plotting.sensor import plot_sensor

    R, per_rev, n_p = 2, 1920, 4
    phi = uniform_angle(R, per_rev)
    psi = 2.0 * math.pi * np.arange(n_p) / n_p
    F = 100.0 + 5.0 * np.cos(ZR * (phi[:, None] + psi))
    s = sensor_signal(F, phi, psi, 0.0, math.pi / 2)
    sig = xr.Dataset({"signal": ("time", s), "carrier_angle": ("time", phi),
                      "carrier_revolutions": ("time", phi / (2 * math.pi))},
                     attrs={"ring_teeth": ZR, "n_planets": n_p, "planet_angles": psi.tolist(),
                            "window": "hann", "width": math.pi / 2, "sensor_angle": 0.0})
    fig = plot_sensor(sig, tmp_path / "sensor.png", harmonics=1)
    assert (tmp_path / "sensor.png").stat().st_size > 0
    texts = {t.get_text() for ax in fig.axes for t in ax.texts}
    assert {"1Zr-3", "1Zr+1"} <= texts and "1Zr" not in texts


def test_unequal_spacing_weighs_each_order_by_the_phasor_sum():
    """For planets at any angles psi_n the line at order q is |sum_n e^{i q psi_n}| times one
    planet's (the derivation in docs/sensor.md before the equal-spacing step)."""
    R, per_rev = 2, 2048
    phi = uniform_angle(R, per_rev)
    psi = 2.0 * math.pi * np.array([0, 47, 101]) / per_rev * 8  # on the sampling grid
    F = 50.0 + 4.0 * np.cos(ZR * (phi[:, None] + psi))
    amp = sensor_spectrum(sensor_signal(F, phi, psi, 0.0, 1.2), R)["amplitude"].values
    one = sensor_spectrum(sensor_signal(F[:, :1], phi, psi[:1], 0.0, 1.2), R)["amplitude"].values
    for q in range(ZR - 10, ZR + 11):
        gain = abs(np.sum(np.exp(1j * q * psi)))
        assert amp[q * R] == pytest.approx(gain * one[q * R], rel=1e-8, abs=1e-9 * amp.max())


def test_carrier_angle_follows_the_mesh_angle_over_the_ring_teeth():
    doc = tomllib.loads(files("geardyn.studies").joinpath("planetary_example.toml").read_text())
    model = planetary_by_hand(doc)
    t = np.linspace(0.0, 10.0, 5)
    np.testing.assert_allclose(carrier_angle(model, t, 0.3), 0.3 * t / ZR)
    lanes = carrier_angle(model, t, np.array([0.1, 0.2]))
    assert lanes.shape == (2, 5)
    np.testing.assert_allclose(lanes[1], 0.2 * t / ZR)
    with pytest.raises(geardyn.ParameterError, match="geometry"):
        carrier_angle(geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.05), t)


def test_the_carrier_angle_needs_the_declared_ring_sensor_not_a_geometry_attribute():
    """A model whose class does not declare the ring sensor is refused even where the instance
    carries a ``geometry`` with a ring (the capability is read, not the attribute probed); a
    planetary set built without geometry is refused too."""
    from types import SimpleNamespace

    t = np.linspace(0.0, 10.0, 5)
    pair = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.05)
    pair.geometry = SimpleNamespace(ring=SimpleNamespace(teeth=ZR))
    pair.held, pair.mesh_order = "ring", 1.0
    with pytest.raises(geardyn.ParameterError, match="model.*geometry"):
        carrier_angle(pair, t)
    doc = tomllib.loads(files("geardyn.studies").joinpath("planetary_example.toml").read_text())
    bare = planetary_by_hand(doc)
    bare.geometry = None
    assert bare.capabilities.fault_dataset.signal == "ring_sensor"
    with pytest.raises(geardyn.ParameterError, match="model.*geometry"):
        carrier_angle(bare, t)
