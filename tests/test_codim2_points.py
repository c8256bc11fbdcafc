"""Fold-flip and 1:2 resonance points on two-parameter curves (geardyn.curve_at) against
locations known independently: a damped Mathieu oscillator beside a scalar saddle-node (the
fold line in closed form, the period-doubling edge by an adaptive integrator), and the undamped
Mathieu equation's instability boundary from its characteristic values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.special import mathieu_a

import geardyn
from geardyn.testing import assert_result

ZETA, LAM = 0.02, 0.3


def _mathieu_pd_test(omega: float, kappa: float) -> float:
    """det(M + I) of x'' + 2 zeta x' + (1 + kappa cos(Omega t)) x = 0 over one period (DOP853,
    rtol 1e-11): zero where a Floquet multiplier is -1."""
    T = 2 * math.pi / omega

    def f(t, y):
        return [y[1], -2 * ZETA * y[1] - (1 + kappa * math.cos(omega * t)) * y[0]]

    cols = [solve_ivp(f, (0.0, T), e, method="DOP853", rtol=1e-11, atol=1e-13).y[:, -1]
            for e in ([1.0, 0.0], [0.0, 1.0])]
    return float(np.linalg.det(np.column_stack(cols) + np.eye(2)))


@pytest.fixture(scope="module")
def saddle_node():
    """The model, and the two edges (Omega) of the Mathieu equation's principal instability
    zone at kappa = LAM, root-found on the independent integrator's det(M + I)."""
    from codim2_models import mathieu_saddle_node

    edges = [brentq(lambda w: _mathieu_pd_test(w, LAM), lo, hi, xtol=1e-13)
             for lo, hi in ((1.6, 2.0), (2.0, 2.4))]
    return mathieu_saddle_node(zeta=ZETA, lam=LAM), edges


def test_fold_curve_meets_both_period_doubling_edges_in_fold_flip_points(saddle_node):
    """The fold curve is the line kappa = lam (w = 0, multiplier exp(0) = +1); the Mathieu
    pair passes through -1 where it crosses the principal zone's edges: two fold-flip points,
    at kappa = lam exactly and Omega on the edges."""
    m, edges = saddle_node
    c = geardyn.curve_at(m, "fold", "kappa", LAM + 1e-5, np.array([0.0, 0.0, 3e-3]), "Omega",
                         2.4, y_start=1.6)
    assert_result(c, "curve")
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert np.max(np.abs(c["kappa"].values - LAM)) < 1e-9
    assert c["special_kind"].values.tolist() == ["fold_flip", "fold_flip"]
    assert c["special_located"].values.tolist() == [1, 1]
    err = c["special_error"].values
    assert np.all(err < 1e-7)
    # kappa: the closed form, within the stated error (the RK4 map's fold is at kappa = lam
    # too: w' = 0 at w = 0 whatever the step)
    assert np.all(np.abs(c["special_x"].values - LAM) / c.attrs["x_scale"] <= err)
    # Omega: the independent edges, within the stated error plus the RK4 step's error of the
    # edge (the curve's own: its period doubling at the edge is as far off)
    assert np.all(np.abs(c["special_y"].values - edges) < 1e-6)
    # the multipliers at the located points: +1 and -1
    for j in range(2):
        mu = _multipliers(m, c["special_section_point"].values[j],
                          float(c["special_x"][j]), float(c["special_y"][j]))
        assert np.min(np.abs(mu - 1.0)) < 1e-6 and np.min(np.abs(mu + 1.0)) < 1e-6


def test_period_doubling_curve_turns_at_the_fold_flip_point(saddle_node):
    """The period-doubling curve of the stable orbit w = +sqrt(kappa - lam) follows the edge
    down to kappa = lam, where its orbit meets the unstable one (w -> 0, a multiplier +1) and it
    goes back up the edge on that one: det(M - I) changes sign there."""
    m, edges = saddle_node
    c = geardyn.curve_at(m, "period_doubling", "Omega", edges[0] + 0.01,
                         np.array([0.0, 0.0, math.sqrt(0.5 - LAM)]), "kappa", 0.2,
                         y_start=0.5)
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    w = c["section_point"].sel(state="w").values
    assert w[0] > 0.4 and w[-1] < -0.4  # from one orbit to the other
    assert float(c["kappa"].min()) > LAM - 1e-9
    assert c["special_kind"].values.tolist() == ["fold_flip"]
    err = float(c["special_error"][0])
    assert err < 1e-7
    assert abs(float(c["special_y"][0]) - LAM) / c.attrs["y_scale"] <= err
    assert abs(float(c["special_x"][0]) - edges[0]) < 1e-6
    assert abs(float(c["special_section_point"].sel(state="w")[0])) < 1e-3


def _multipliers(m, x0: np.ndarray, kappa: float, omega: float) -> np.ndarray:
    """The orbit's Floquet multipliers by DOP853 (rtol 1e-11) on the variational equations."""
    T = 2 * math.pi / omega

    def f(t, y):
        x, v, w = y[:3]
        c = math.cos(omega * t)
        A = np.array([[0.0, 1.0, 0.0], [-(1 + kappa * c), -2 * ZETA, 0.0], [0.0, 0.0, -2 * w]])
        return np.concatenate([[v, -2 * ZETA * v - (1 + kappa * c) * x, kappa - LAM - w * w],
                               (A @ y[3:].reshape(3, 3)).ravel()])

    y = solve_ivp(f, (0.0, T), np.concatenate([x0, np.eye(3).ravel()]), method="DOP853",
                  rtol=1e-11, atol=1e-13).y[:, -1]
    assert np.max(np.abs(y[:3] - x0)) < 1e-6  # the orbit closes
    return np.linalg.eigvals(y[3:].reshape(3, 3))


def test_neimark_sacker_curve_of_the_undamped_mathieu_equation_hits_1_2_resonance():
    """x'' + (2 zeta - mu) x' + (1 + kappa cos(Omega t)) x = 0 (the shared oscillator at x = 0):
    det M = exp(-(2 zeta - mu) T), so the Neimark-Sacker curve in (mu, kappa) is the line
    mu = 2 zeta, the undamped Mathieu equation. With tau = Omega t / 2 that is Mathieu's
    y'' + (a - 2 q cos 2 tau) y = 0, a = 4 / Omega^2, q = -2 kappa / Omega^2: the pair meets
    at -1 (1:2) on the principal zone's edge a = a_1(|q|) (a > 1), a characteristic value
    (scipy.special.mathieu_a)."""
    from shared_models import oscillator

    om = 1.9
    kappa_12 = brentq(lambda k: mathieu_a(1, 2 * k / om**2) - 4 / om**2, 1e-6, 1.0,
                      xtol=1e-14)
    m = oscillator(Omega=om, zeta=ZETA, natural_frequency=1.0)
    c = geardyn.curve_at(m, "neimark_sacker", "mu", 2 * ZETA + 1e-3, np.zeros(2), "kappa",
                         0.35, y_start=0.05)
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert np.max(np.abs(c["mu"].values - 2 * ZETA)) < 1e-9
    assert c["special_kind"].values.tolist() == ["resonance_1_2"]
    err = float(c["special_error"][0])
    assert err < 1e-7
    assert abs(float(c["special_x"][0]) - 2 * ZETA) / c.attrs["x_scale"] <= err
    # kappa: the characteristic value's, within the stated error plus the RK4 step's error
    assert abs(float(c["special_y"][0]) - kappa_12) < 1e-6
    # a complex pair on the circle below, a real pair mu, 1 / mu < 0 above
    cos_theta = c["test_resonance_1_2"].values - 1.0
    kap = c["kappa"].values
    assert np.all((cos_theta > -1) == (kap < kappa_12))
