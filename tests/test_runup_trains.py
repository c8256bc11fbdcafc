"""A run-up of a gear train whose stages mesh at a non-whole ratio (quasi-periodic forcing):
each stage's mesh phase is the integral of its own mesh frequency, checked against the train's
equations written out by hand with that phase and integrated by DOP853."""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

import geardyn
from geardyn.analysis.runup import RunupSettings, phase_from_time, runup
from test_trains_model import C_MESH, INERTIA, K_MID, KA, KB, RBP, T_IN, Z, _parallel

AMPLITUDE = 0.25
BACKLASH = 20e-6


def test_a_trains_runup_follows_each_stages_phase_integral():
    model = _parallel(input_speed=1000.0, backlash=BACKLASH, stiffness_fluctuation=AMPLITUDE)
    assert model.quasi_periodic and phase_from_time(model, 2.0 * model.omega)
    w0, L = model.time_scale, model.length_scale
    start, stop = model.omega, 2.5 * model.omega  # 1000 -> 2500 rpm at the input
    duration = 400.0  # model time units
    ds = runup(model, RunupSettings(start=start, stop=stop, duration=duration,
                                    sample_rate=0.5, steps_per_period=96))
    accel = (stop - start) / duration
    order = np.array([1.0, model.orders[1]])
    k = np.array([KA, KB])
    W = np.array([[RBP[0], RBP[1], 0.0, 0.0], [0.0, 0.0, RBP[2], RBP[3]]])
    t_load = -T_IN * (Z[1] / Z[0]) * (Z[3] / Z[2])
    F = np.array([T_IN, 0.0, 0.0, t_load])
    K = np.zeros((4, 4))
    K[1, 1] = K[2, 2] = K_MID
    K[1, 2] = K[2, 1] = -K_MID

    def theta(t):  # SI time: the reference mesh's phase, the integral of its frequency
        tau = w0 * t
        return start * tau + 0.5 * accel * tau * tau

    def rhs(t, y):
        q, v = y[:4], y[4:]
        d = W @ q
        g = d - np.clip(d, -BACKLASH, BACKLASH)
        f = k * (1.0 + AMPLITUDE * np.sin(order * theta(t))) * g + C_MESH * (W @ v)
        return np.concatenate([v, (F - K @ q - W.T @ f) / np.array(INERTIA)])

    y0 = model.initial_state()
    t = ds["time"].values / w0
    ref = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([L * y0[:4], L * w0 * y0[4:]]),
                    method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.success
    d = W @ ref.y[:4]
    forces = k[:, None] * (1.0 + AMPLITUDE * np.sin(order[:, None] * theta(t))) \
        * (d - np.clip(d, -BACKLASH, BACKLASH)) + C_MESH * (W @ ref.y[4:])
    assert np.any(np.abs(d[0]) < BACKLASH)  # the run passes a resonance losing contact
    for m, name in enumerate(("F_stage1", "F_stage2")):
        scale = np.max(np.abs(forces[m]))
        np.testing.assert_allclose(ds[name].values, forces[m], rtol=0, atol=2e-5 * scale)


def test_a_trains_runup_at_constant_speed_is_simulate():
    model = _parallel(input_speed=2000.0, backlash=BACKLASH, stiffness_fluctuation=AMPLITUDE)
    om = model.omega
    n = 128
    sim = geardyn.simulate(model, run=geardyn.RunSettings(transient=0.0, samples=6,
                                                          steps_per_period=n))
    ds = runup(model, RunupSettings(start=om, stop=om * (1 + 1e-12),
                                    duration=6 * 2.0 * math.pi / om, steps_per_period=n))
    a, b = sim["F_stage2"].values, ds["F_stage2"].values[: sim["F_stage2"].size]
    assert np.max(np.abs(a - b)) < 1e-7 * np.max(np.abs(a))


