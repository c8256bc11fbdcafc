"""Run-ups (geardyn.analysis.runup): the ramped forcing against independent computations.

* a fast run-up of a linear oscillator (the gear pair with kappa = 0, always in contact) against
  the same chirp-forced ODE written here and integrated by scipy's DOP853 at rtol 1e-10: the
  time history, the peak reduction and the delay of the peak past the resonance;
* a slow run-up against the stepped steady state (``geardyn.simulate`` at fixed Omega) where
  the response is unique (in contact: a stable linear time-periodic system);
* the step converges (4th order on a linear run, and with impacts it still converges);
* a run-up over a vanishing speed range equals ``simulate`` at that speed for the other model
  families (the phase and the coefficients that follow Omega are driven right);
* models it cannot drive and bad settings are refused, naming the field.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from geardyn.analysis.runup import RunupSettings, runup, speed_coefficients
from geardyn.errors import ParameterError
from geardyn.testing import assert_result

ZETA, FM, FA = 0.05, 1.0, 0.02


def _linear_pair() -> geardyn.GearPair:
    """kappa = 0 and a mean load far above the dynamic amplitude: x - b > 0 throughout, so
    x'' + 2 zeta x' + (x - 1) = Fm + Fa Omega^2 cos theta, a linear oscillator."""
    return geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=FA)


def _reference(start: float, accel: float, t_end: float, t_eval: np.ndarray,
               y0: tuple[float, float]) -> np.ndarray:
    """x(t) of the chirp-forced oscillator, written from the equation (not from geardyn's
    functions): Omega = start + accel t, theta = start t + accel t^2 / 2."""
    def f(t, y):
        om = start + accel * t
        th = start * t + 0.5 * accel * t * t
        x, v = y
        return [v, FM + FA * om * om * math.cos(th) - 2.0 * ZETA * v - (x - 1.0)]

    sol = solve_ivp(f, (0.0, t_end), list(y0), method="DOP853", rtol=1e-10, atol=1e-12,
                    t_eval=t_eval)
    assert sol.success
    return sol.y[0]


def _envelope_peak(t: np.ndarray, x: np.ndarray, omega: np.ndarray, width: float
                   ) -> tuple[float, float]:
    """(largest half peak-to-peak of x over sliding windows of ``width`` time, the Omega at
    that window's centre)."""
    dt = t[1] - t[0]
    n = max(2, int(round(width / dt)))
    best, where = -1.0, 0
    for i in range(0, x.size - n, max(1, n // 8)):
        a = 0.5 * (x[i:i + n].max() - x[i:i + n].min())
        if a > best:
            best, where = a, i + n // 2
    return best, float(omega[where])


def _stationary_peak(omegas: np.ndarray) -> tuple[float, float]:
    """The steady-state amplitude Fa W^2 / |1 - W^2 + 2 i zeta W| at its largest."""
    amp = FA * omegas**2 / np.abs(1.0 - omegas**2 + 2j * ZETA * omegas)
    k = int(np.argmax(amp))
    return float(amp[k]), float(omegas[k])


def test_fast_runup_of_a_linear_oscillator_matches_dop853():
    model = _linear_pair()
    start, stop, rate = 0.5, 1.5, 0.004
    s = RunupSettings(start=start, stop=stop, rate=rate, sample_rate=4.0,
                      steps_per_period=128)
    ds = runup(model, s)
    assert_result(ds, "runup")
    assert ds.attrs["status"] == 0
    t = ds["time"].values
    x_ref = _reference(start, rate, t[-1], t, (FM + 1.0, 0.0))
    err = np.max(np.abs(ds["x"].values - x_ref))
    assert err < 5e-8, err  # RK4: 2.4e-8 at this step, 16 times less per halving
    # the instantaneous speed and phase are the ramp's
    np.testing.assert_allclose(ds["Omega"].values, np.minimum(start + rate * t, stop),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(ds["phase"].values, start * t + 0.5 * rate * t * t,
                               rtol=1e-13, atol=1e-9)
    # the peak is reduced and delayed past the stationary one, as the reference says
    w = ds["Omega"].values
    width = 2.0 * math.pi * 2.0  # two forcing periods near resonance
    peak, at = _envelope_peak(t, ds["x"].values, w, width)
    peak_ref, at_ref = _envelope_peak(t, x_ref, w, width)
    stat, at_stat = _stationary_peak(np.linspace(start, stop, 20001))
    assert abs(peak - peak_ref) < 1e-6 * stat and abs(at - at_ref) < 1e-9
    assert peak < 0.95 * stat and at > at_stat + 0.01  # reduction and delay (this rate)


def test_a_faster_sweep_lowers_and_delays_the_peak_more():
    """The classical trend of a constant-rate passage (Lewis 1932): the faster the sweep, the
    lower the peak and the later it comes; here each against the stationary peak."""
    model = _linear_pair()
    out = []
    for rate in (0.0005, 0.002, 0.008):
        ds = runup(model, RunupSettings(start=0.6, stop=1.4, rate=rate, sample_rate=4.0))
        out.append(_envelope_peak(ds["time"].values, ds["x"].values, ds["Omega"].values,
                                  4.0 * math.pi))
    stat, at_stat = _stationary_peak(np.linspace(0.6, 1.4, 20001))
    peaks, ats = zip(*out, strict=True)
    assert peaks[0] > peaks[1] > peaks[2]
    assert at_stat < ats[0] < ats[1] < ats[2]
    assert abs(peaks[0] / stat - 1.0) < 0.05  # slow enough: close to the stationary peak


def test_slow_runup_equals_the_stepped_steady_state():
    """Always in contact (a stable linear time-periodic system): one periodic response per
    speed, so a slow run-up passes through it."""
    model = geardyn.GearPair(zeta=ZETA, kappa=0.1, Fm=FM, Fa=FA)
    ds = runup(model, RunupSettings(start=1.15, stop=1.55, rate=2e-5, sample_rate=8.0))
    assert ds.attrs["status"] == 0
    t, x, w = ds["time"].values, ds["x"].values, ds["Omega"].values
    for om in (1.2, 1.3, 1.4, 1.5):
        st = geardyn.simulate(model, omega=om, run=geardyn.RunSettings(transient=400.0,
                                                                       samples=8))
        ref = 0.5 * (st["x"].max() - st["x"].min()).item()
        i = int(np.argmin(np.abs(w - om)))
        n = int(round(8 * 2.0 * math.pi / om / (t[1] - t[0])))  # 8 periods around it
        seg = x[i - n // 2:i + n // 2]
        amp = 0.5 * (seg.max() - seg.min())
        assert abs(amp / ref - 1.0) < 0.003, (om, amp, ref)


def _final_x(model, n: int) -> tuple[float, float]:
    """(x at the ramp's end, t = 60, the step) with about n steps per period at Omega = 1.2
    (refined so that the step divides the sample interval 1, and so the ramp)."""
    ds = runup(model, RunupSettings(start=0.8, stop=1.2, duration=60.0, steps_per_period=n,
                                    sample_rate=1.0))
    assert ds["time"].values[-1] == pytest.approx(60.0, rel=1e-14)
    return float(ds["x"].values[-1]), float(ds.attrs["step"])


def test_step_converges_at_fourth_order_on_a_linear_run():
    model = _linear_pair()
    ref, _ = _final_x(model, 1024)
    (x1, h1), (x2, h2) = _final_x(model, 32), _final_x(model, 64)
    order = math.log(abs(x1 - ref) / abs(x2 - ref)) / math.log(h1 / h2)
    assert 3.7 < order < 4.3, order


def test_step_converges_with_impacts():
    model = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.1)
    ds = runup(model, RunupSettings(start=0.8, stop=1.2, duration=60.0, steps_per_period=64))
    assert int(ds["edge_crossings"].sum()) > 10  # the teeth separate and impact
    ref, _ = _final_x(model, 2048)
    errs = [abs(_final_x(model, n)[0] - ref) for n in (64, 128, 256)]
    assert errs[2] < errs[1] < errs[0] and errs[0] / errs[2] > 8.0, errs


def test_runup_down_and_divergence_is_marked():
    model = _linear_pair()
    ds = runup(model, RunupSettings(start=1.5, stop=0.5, rate=0.01, sample_rate=2.0))
    assert ds["Omega"].values[0] == 1.5 and ds["Omega"].values[-1] == pytest.approx(0.5)
    assert np.all(np.diff(ds["phase"].values) > 0)
    small = RunupSettings(start=0.9, stop=1.1, rate=0.01, bound=0.5)
    bad = runup(model, small)
    assert bad.attrs["status"] == int(geardyn.Status.DIVERGED)
    assert np.isnan(bad["x"].values[-1]) and bad["time"].size > 1


@pytest.mark.slow
@pytest.mark.parametrize("case", ["catt", "planetary"])
def test_vanishing_range_equals_simulate(case):
    """A run-up over a speed range of 1e-12 relative at the simulation's step is
    ``simulate`` at that speed: the phase and the coefficients reach every model family's
    functions as its own kernels pass them."""
    from geardyn.io import builtin_study

    study = {"catt": "paper_fig3", "planetary": "planetary_example"}[case]
    model = geardyn.build_model(builtin_study(study))
    om = model.omega
    n = 128
    sim = geardyn.simulate(model, omega=om, run=geardyn.RunSettings(
        transient=0.0, samples=6, steps_per_period=n))
    T = 2.0 * math.pi / om
    ds = runup(model, RunupSettings(start=om, stop=om * (1 + 1e-12), duration=6 * T,
                                    steps_per_period=n))
    name = model.state_names[0]
    a, b = sim[name].values, ds[name].values[: sim[name].size]
    scale = np.max(np.abs(a))
    assert np.max(np.abs(a - b)) < 1e-7 * scale


def test_speed_coefficients_follow_a_carrier_speed_tied_to_omega():
    """A planetary set whose carrier speed follows the mesh frequency: the entries that move
    with Omega are found and their quadratics reproduce lane_params."""
    from geardyn.io import builtin_study

    base = geardyn.build_model(builtin_study("planetary_example"))
    model = base.with_params(carrier_speed_ratio=0.05)
    cols, coef = speed_coefficients(model, 1.0)
    assert cols.size > 1 and model.omega_index in cols
    w = np.array([0.3, 0.55, 0.9])
    P = model.lane_params("Omega", w)
    fit = coef[:, 0] + w[:, None] * coef[:, 1] + w[:, None] ** 2 * coef[:, 2]
    np.testing.assert_allclose(fit, P[:, cols], rtol=1e-9, atol=1e-12)


def test_models_it_cannot_drive_are_refused():
    from shared_models import lorenz, oscillator

    with pytest.raises(ParameterError, match="model.*plain UserModel"):
        runup(oscillator(F=1.0), RunupSettings(start=0.5, stop=1.0, rate=0.01))
    with pytest.raises(ParameterError, match="model.*autonomous"):
        runup(lorenz(), RunupSettings(start=0.5, stop=1.0, rate=0.01))


@pytest.mark.parametrize("kw,field", [
    ({"start": -1.0, "stop": 1.0, "rate": 0.1}, "start"),
    ({"start": 1.0, "stop": 1.0, "rate": 0.1}, "stop"),
    ({"start": 0.5, "stop": 1.0}, "rate"),
    ({"start": 0.5, "stop": 1.0, "rate": 0.1, "duration": 5.0}, "rate"),
    ({"start": 0.5, "stop": 1.0, "rate": 0.0}, "rate"),
    ({"start": 0.5, "stop": 1.0, "duration": float("nan")}, "duration"),
    ({"start": 0.5, "stop": 1.0, "rate": 0.1, "sample_rate": -2.0}, "sample_rate"),
    ({"start": 0.5, "stop": 1.0, "rate": 0.1, "steps_per_period": 4}, "steps_per_period"),
    ({"start": 0.5, "stop": 1.0, "rate": 0.1, "outputs": "x"}, "outputs"),
    ({"start": 0.5, "stop": 1.0, "rate": 0.1, "transient": -1.0}, "transient"),
])
def test_bad_settings_name_the_field(kw, field):
    with pytest.raises(ParameterError, match=f"^{field}"):
        RunupSettings(**kw)


def test_unknown_output_is_named():
    with pytest.raises(ParameterError, match="outputs: not a state.*known: x, v, F.*'y'"):
        runup(_linear_pair(), RunupSettings(start=0.5, stop=1.0, rate=0.1, outputs=("y",)))


def test_progress_cuts_the_run_into_pieces_with_the_same_result():
    model = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.1)
    s = RunupSettings(start=0.5, stop=1.5, rate=0.005, sample_rate=2.0)
    whole = runup(model, s)
    calls = []
    pieces = runup(model, s, progress=lambda done, total: calls.append((done, total)))
    assert len(calls) == 3 and calls[-1][0] == calls[-1][1]  # 3200 steps: a piece per 1000
    assert whole.sizes == pieces.sizes
    np.testing.assert_array_equal(pieces["x"].values, whole["x"].values)  # bitwise
    assert int(pieces["edge_crossings"].sum()) == int(whole["edge_crossings"].sum())


def test_frequency_scale_of_a_physical_pair_and_a_planetary_set():
    """The spur pair's Omega is the pinion's rotation [rad/s]: 1 / (2 pi) Hz per rad/s, the
    mesh 19 (the pinion's teeth) times faster; the planetary set's Omega is the dimensionless
    mesh frequency, tau = omega_0 t: omega_0 / (2 pi) Hz per unit."""
    from geardyn.analysis.runup import frequency_scale
    from geardyn.io import builtin_study

    pair = geardyn.build_model(builtin_study("spur_pair_cracked"))
    hz, order = frequency_scale(pair)
    assert hz == pytest.approx(1.0 / (2.0 * math.pi), rel=1e-15)
    assert order == pytest.approx(pair.dataset_attrs()["mesh_cycles_per_period"], rel=1e-12)
    assert order == pytest.approx(19.0, rel=1e-12)
    gs = geardyn.build_model(builtin_study("planetary_example"))
    hz, order = frequency_scale(gs)
    assert order == 1.0 and hz == pytest.approx(gs.time_scale / (2.0 * math.pi), rel=1e-12)
    assert frequency_scale(_linear_pair()) == (None, 1.0)
