"""Located edge crossings: the crossing time that the step core finds inside one grid step (on
the cubic of the event along the step's interpolant, :func:`_step_core._cubic_locate`) against
an independent DOP853 event location, for a single crossing and for a graze, and against the
root finder that evaluates the model's events (for affine and for non-affine events)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from _reference_step import step_pieces
from geardyn.solvers._step_shared import GBUF_ROWS
from geardyn.solvers.kernels import kernels_for

ZETA, KAPPA, FM, OMEGA = 0.05, 0.2, 0.1, 0.9


@pytest.fixture(scope="module")
def pair():
    model = geardyn.GearPair(zeta=ZETA, kappa=KAPPA, Fm=FM, Fa=0.0, Omega=OMEGA)
    return model, kernels_for(model.kernel), np.ascontiguousarray(model.params, float)


def _rhs(k, p, om):
    def f(t, y):
        dy = np.empty(y.size)
        k.rhs(t, y, dy, p, math.sin(om * t), math.cos(om * t))
        return dy
    return f


def located(k, p, om, y0, h, j=0):
    """One RK4 grid step of length h from (0, y0) and the crossing of event j inside it, as the
    split path finds it (time), and as the Illinois root finder on the model's events finds it
    from the same bracket (NaN where it sees no crossing: the step's ends on one side)."""
    f = _rhs(k, p, om)
    sc = [(math.sin(om * t), math.cos(om * t)) for t in (0.0, 0.5 * h, h)]
    w = np.zeros((5, y0.size))
    y1 = np.zeros(y0.size)
    step = step_pieces(k)
    step.rk4(0.0, y0, h, p, *sc[0], *sc[1], *sc[2], w[0], w[1], w[2], w[3], y1)
    f0, f1 = f(0.0, y0), f(h, y1)
    n_ev = 2
    g1 = np.zeros(n_ev)
    k.events(h, y1, g1, p, *sc[2])
    pc = (*sc[0], om * h, 0, 0.0, 1.0)  # the step's forcing phase (_step_core._phase_in)
    ybuf, gbuf = np.zeros(y0.size), np.zeros((GBUF_ROWS, n_ev))
    step.interpolant_events(y0, f0, y1, f1, h, 0.0, p, ybuf, gbuf, pc)
    side = 1 if gbuf[0, j] > 0 else -1
    theta = step.first_crossing(j, side, g1[j], y0, f0, y1, f1, h, 0.0, p, ybuf, gbuf, pc)
    ill = np.nan
    if (g1[j] > 0) != (side > 0):
        ill = step.illinois(j, side, gbuf[0, j], 1.0, g1[j], y0, f0, y1, f1, h, 0.0, p, ybuf,
                            gbuf[1], pc) * h
    return theta * h, ill


def dop853_crossings(y0, t_end):
    """Zeros of x - b of the gear pair in contact (the smooth branch the orbit follows up to its
    first crossing: g = x - b on both sides), by DOP853 at rtol 1e-12."""
    b = 1.0

    def f(t, y):
        c = math.cos(OMEGA * t)
        return [y[1], FM - 2 * ZETA * y[1] - (1.0 + KAPPA * c) * (y[0] - b)]

    def edge(t, y):
        return y[0] - b

    sol = solve_ivp(f, (0.0, t_end), y0, method="DOP853", rtol=1e-12, atol=1e-14, events=edge)
    return sol.t_events[0]


@pytest.mark.parametrize("h", [0.2, 0.1, 0.05])
def test_single_crossing_time_matches_dop853(pair, h):
    model, k, p = pair
    y0 = np.array([1.0 + 0.01, -1.0])  # leaving contact at speed 1, x - b = 0 at t ~ 0.01
    ref = dop853_crossings(y0, h)
    assert ref.size == 1
    t, t_ill = located(k, p, OMEGA, y0, h)
    # the interpolant's end comes from an RK4 step across the kink: O(h^3) in the state
    assert abs(t - ref[0]) <= 1e-3 * h**3
    assert abs(t - t_ill) <= 1e-12 * h  # the same root as the model-evaluating root finder


@pytest.mark.parametrize("h", [0.2, 0.1])
def test_graze_inside_a_step_matches_dop853(pair, h):
    """x - b dips below the edge and back within the step (both ends in contact): the first of
    the two crossings is the one located; the end-sign root finder sees none."""
    model, k, p = pair
    y0 = np.array([1.0 + 5e-5, -0.005])
    ref = dop853_crossings(y0, h)
    assert ref.size == 2 and ref[1] < h
    t, t_ill = located(k, p, OMEGA, y0, h)
    assert math.isnan(t_ill)
    assert abs(t - ref[0]) <= 1e-3 * h**3


# --- events that are not affine in the state: the cubic's root is refined on the model ----------

@nb.njit(cache=True)
def _osc_rhs(t, y, dy, p):
    dy[0] = y[1]
    dy[1] = -y[0]


@nb.njit(cache=True)
def _osc_events(t, y, g, p):
    g[0] = y[0] * y[0] - p[1]  # |x| = sqrt(c): a quadratic in the state
    g[1] = math.exp(y[1]) - p[2]


def test_nonaffine_event_is_located_on_the_model():
    model = geardyn.UserModel(_osc_rhs, 2, [1.0, 0.25, 1.0], param_names=["Omega", "c", "d"],
                              events=_osc_events, n_events=2)
    k = kernels_for(model.kernel)
    p = np.ascontiguousarray(model.params, float)
    y0 = np.array([0.9, -1.0])
    h = 0.5
    t, t_ill = located(k, p, 1.0, y0, h)
    # x(t) = 0.9 cos t - sin t reaches 0.5 at:
    r = math.hypot(0.9, 1.0)
    exact = math.acos(0.5 / r) - math.atan2(1.0, 0.9)
    assert abs(t - t_ill) <= 1e-9 * h
    assert abs(t - exact) <= 1e-2 * h**3
    # the second event (exp(v) - 1 = 0 where v = 0, not crossed in this step) stays off
    t2, _ = located(k, p, 1.0, y0, h, j=1)
    assert t2 == 2.0 * h
