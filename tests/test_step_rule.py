"""The default step follows every lane's own coefficients (issue 10): checked against an
independent eigenvalue problem in the body angles and against DOP853 (rtol 1e-12)."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
import scipy.linalg

import geardyn
from geardyn.core.plan import (
    MIN_STEPS_PER_PERIOD,
    STEPS_PER_FASTEST_MODE,
    default_steps_per_period,
    lane_steps_per_period,
)
from geardyn.solvers.ensemble import run_lanes

KM_PQ = np.array([1.0e9, 4.0e9, 16.0e9])


def body_angle_fastest(m: geardyn.CATTDevice) -> float:
    """Fastest natural frequency [rad/s] of Eq. (1) linearised in the body angles, written here
    from the free-body diagram (carrier: arm r_bs cos(alpha); deflections r_c1 theta_c -
    r_bq theta_q and r_bq theta_q - r_bp theta_p), not from the package's matrices."""
    prm, d = m.params_in, m.derived
    n, rc1 = prm.n_planets, prm.carrier.r_c1
    M = np.diag([d.J_c_eff] + [j for i in range(n) for j in (d.J_q[i], d.J_p[i])])
    K = np.zeros_like(M)
    for i in range(n):
        sq, pq, _, _ = prm.planet_set(i)
        ks, kp, rq, rp = sq.mean_stiffness, pq.mean_stiffness, d.r_bq[i], d.r_bp[i]
        q, p = 1 + 2 * i, 2 + 2 * i
        ds = np.zeros(2 * n + 1)  # d(deflection)/d(angles)
        ds[0], ds[q] = rc1, -rq
        dp = np.zeros(2 * n + 1)
        dp[q], dp[p] = rq, -rp
        moment_s = np.zeros(2 * n + 1)  # generalised moments of a unit mesh force
        moment_s[0], moment_s[q] = -d.arm, rq
        moment_p = np.zeros(2 * n + 1)
        moment_p[q], moment_p[p] = -rq, rp
        K -= ks * np.outer(moment_s, ds) + kp * np.outer(moment_p, dp)
    lam = scipy.linalg.eig(K, M, right=False)
    return float(np.sqrt(np.max(np.abs(lam))))


@pytest.mark.parametrize("interpretation", ["consistent", "as-printed"])
def test_fastest_frequency_of_every_lane_from_the_body_angles(interpretation):
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), interpretation=interpretation)
    for name, values in (("Km_pq", KM_PQ), ("Km_sq", [0.4e9, 0.825e9, 4e9])):
        P = m.lane_params(name, values)
        got = m.fastest_natural_frequency(P)
        expect = [body_angle_fastest(m.with_params(**{name: v})) for v in values]
        # each lane in units of its own omega_n
        wn = np.array([m.with_params(**{name: v}).omega_n for v in values])
        np.testing.assert_allclose(got * wn, expect, rtol=1e-9)
        g = m.general()
        np.testing.assert_allclose(g.fastest_natural_frequency(g.lane_params(name, values)),
                                   got, rtol=1e-12)
        d = m.dimensional()
        np.testing.assert_allclose(
            d.fastest_natural_frequency(np.array([m.with_params(**{name: v}).dimensional().params
                                                  for v in values])), expect, rtol=1e-9)


def test_steps_per_period_grow_with_the_stiffness():
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=1.1)
    P = m.lane_params("Km_pq", KM_PQ)
    n = lane_steps_per_period(m, P)
    assert np.all(np.diff(n) > 0)
    w = np.array([body_angle_fastest(m.with_params(Km_pq=v)) for v in KM_PQ]) / m.omega_n
    need = np.ceil(STEPS_PER_FASTEST_MODE * w / 1.1)
    assert np.all(n >= need) and np.all(n < 1.2 * need)  # the ladder rounds up by < 2^(1/4)
    for k, v in enumerate(KM_PQ):  # each lane's step is that of its own model
        lane = m.with_params(Km_pq=v)
        assert default_steps_per_period(lane) == default_steps_per_period(m, params=P[k])
        assert n[k] == lane_steps_per_period(lane, lane.params[None])[0]
    assert n[-1] > 3 * n[0]


def test_km_pq_sweep_at_the_default_step_agrees_with_dop853():
    """The stiffest lane of a Km_pq sweep, with tooth separation, against DOP853 (rtol 1e-12);
    the base model's step (what every lane got before) misses 1e-6 there."""
    omega = 2.0
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=omega)
    ds = geardyn.bifurcation(m, "Km_pq", KM_PQ, run=geardyn.RunSettings(transient=60.0, samples=3))
    stiff = m.with_params(Km_pq=KM_PQ[-1])
    n = ds["steps_per_period"].values
    assert n[-1] > n[0] and n[-1] == lane_steps_per_period(stiff, stiff.params[None])[0]
    T = 2 * math.pi / omega
    k0 = int(ds["transient_periods"].values[-1])
    ref = geardyn.reference_solution(stiff, stiff.initial_state(), (k0 + 1 + np.arange(3)) * T)
    assert ds["contact"].values[-1].tolist() != ["double", "double"]
    scale = np.max(np.abs(ref))
    err = np.max(np.abs(ds["poincare"].values[-1] - ref))
    assert err < 1e-6 * scale
    old = run_lanes(stiff, stiff.params[None], stiff.initial_state(),
                    run=geardyn.RunSettings(transient=60.0, samples=3, steps_per_period=int(n[0])))
    assert np.max(np.abs(old.samples[0] - ref)) > 1e-6 * scale


def test_explicit_steps_win_and_models_without_modes_keep_the_floor():
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=1.1)
    P = m.lane_params("Km_pq", KM_PQ)
    r = run_lanes(m, P, m.initial_state(),
                  run=geardyn.RunSettings(transient=0.0, samples=1, steps_per_period=96))
    assert r.steps_per_period.tolist() == [96] * 3
    g = geardyn.GearPair(Omega=0.5)
    assert default_steps_per_period(g) == math.ceil(STEPS_PER_FASTEST_MODE / 0.5)


@numba.njit(cache=False)
def _oscillator(t, y, dy, p):
    dy[0] = y[1]
    dy[1] = -p[0] * y[0] - 0.1 * y[1] + math.cos(p[1] * t)


def test_user_model_natural_frequency_sets_the_step():
    kw = dict(n_states=2, params=[1.0, 1.0], param_names=["k", "Omega"])
    plain = geardyn.UserModel(_oscillator, **kw)
    assert default_steps_per_period(plain) == MIN_STEPS_PER_PERIOD  # unknown: the floor
    known = geardyn.UserModel(_oscillator, natural_frequency=lambda p: math.sqrt(p[0]), **kw)
    P = known.lane_params("k", [1.0, 100.0, 10000.0])
    n = lane_steps_per_period(known, P)
    assert n[0] >= STEPS_PER_FASTEST_MODE and n[2] >= STEPS_PER_FASTEST_MODE * 100
    fixed = geardyn.UserModel(_oscillator, natural_frequency=3.0, **kw)
    assert default_steps_per_period(fixed) == math.ceil(STEPS_PER_FASTEST_MODE * 3.0)
    with pytest.raises(ValueError, match="natural_frequency"):
        geardyn.UserModel(_oscillator, natural_frequency=-1.0, **kw)
