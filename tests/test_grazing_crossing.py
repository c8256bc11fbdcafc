"""Where the gear pair's contact-loss (grazing) curve meets its period-doubling curve, located
(intersect_curves with the model) against an independent computation: the damped Mathieu
equation's zone edge and the in-contact orbit's closed-contact limit, both by DOP853."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

import geardyn
from geardyn.analysis.envelope import intersect_curves
from geardyn.analysis.grazing import grazing_curve

ZETA, KAPPA = 0.02, 0.3
TIGHT = {"method": "DOP853", "rtol": 1e-12, "atol": 1e-14}


def _homogeneous(omega: float):
    def f(t, y):
        return [y[1], -2 * ZETA * y[1] - (1 + KAPPA * math.cos(omega * t)) * y[0]]

    return f


def _monodromy(omega: float) -> np.ndarray:
    T = 2 * math.pi / omega
    return np.column_stack([solve_ivp(_homogeneous(omega), (0.0, T), e, **TIGHT).y[:, -1]
                            for e in ([1.0, 0.0], [0.0, 1.0])])


def _orbit_minimum(omega: float, fa: float) -> tuple[float, np.ndarray]:
    """(min over the period of u, u's section point) of the periodic orbit of the in-contact
    gear pair u'' + 2 zeta u' + (1 + kappa cos(Omega t)) u = 1 + Fa Omega^2 cos(Omega t)
    (u = x - b, linear while u > 0): u0 = (I - M)^-1 phi_T(0)."""
    T = 2 * math.pi / omega

    def f(t, y):
        c = math.cos(omega * t)
        return [y[1], 1.0 + fa * omega**2 * c - 2 * ZETA * y[1] - (1 + KAPPA * c) * y[0]]

    p = solve_ivp(f, (0.0, T), [0.0, 0.0], **TIGHT).y[:, -1]
    u0 = np.linalg.solve(np.eye(2) - _monodromy(omega), p)
    sol = solve_ivp(f, (0.0, T), u0, dense_output=True, **TIGHT)
    ts = np.linspace(0.0, T, 4001)
    i = int(np.argmin(sol.sol(ts)[0]))
    r = minimize_scalar(lambda t: sol.sol(t)[0], bounds=(ts[max(i - 1, 0)], ts[min(i + 1, 4000)]),
                        method="bounded", options={"xatol": 1e-13})
    return float(r.fun), u0


@pytest.fixture(scope="module")
def crossing():
    """The period-doubling curve (in Fa, from the lower edge of the principal zone) and the
    drive flank's grazing curve of the gear pair kept in contact by its mean load; the
    independent crossing: Omega on the zone's edge (det(M + I) = 0), Fa where the orbit there
    just touches the edge."""
    m = geardyn.GearPair(zeta=ZETA, Fm=1.0, Fa=0.0, kappa=KAPPA)
    br = geardyn.continuation(m, "Omega", 1.6, 2.4)
    pd = geardyn.curve(m, br, 0, "Fa", 1.5, settings=geardyn.CurveSettings(max_points=30))
    g = grazing_curve(m, "Omega", "Fa", (1.6, 2.2), (0.5, 1.5), at=(1.85, 0.9))
    edge = brentq(lambda w: float(np.linalg.det(_monodromy(w) + np.eye(2))), 1.6, 2.0,
                  xtol=1e-13)
    fa = brentq(lambda a: _orbit_minimum(edge, a)[0], 0.1, 2.0, xtol=1e-13)
    return m, pd, g, (edge, fa, _orbit_minimum(edge, fa)[1])


def test_grazing_period_doubling_point_is_located_on_the_kept_side(crossing):
    m, pd, g, (edge, fa, u0) = crossing
    coarse = intersect_curves(g, pd)
    fine = intersect_curves(g, pd, model=m)
    for out in (coarse, fine):
        geardyn.testing.assert_result(out, "curve")
        assert out["special_kind"].values.tolist() == ["grazing-period-doubling"]
    sx, sy = g.attrs["x_scale"], g.attrs["y_scale"]

    def miss(out):
        return max(abs(float(out["special_x"][0]) - edge) / sx,
                   abs(float(out["special_y"][0]) - fa) / sy)

    # the polylines' crossing: within its bound, not located
    assert int(coarse["special_located"][0]) == 0
    assert miss(coarse) <= float(coarse["special_error"][0])
    # located: on the independent point to the step's discretisation error (the period-doubling
    # edge alone is off by ~1e-8 at this step), its stated error small too
    assert int(fine["special_located"][0]) == 1, str(fine["special_detail"].values[0])
    assert miss(fine) < 1e-6
    assert float(fine["special_error"][0]) < 1e-6
    assert miss(fine) < 1e-3 * miss(coarse)
    x0 = fine["special_section_point"].values[0]
    np.testing.assert_allclose(x0, [u0[0] + 1.0, u0[1]], atol=1e-6)
    # the other order: the point on the period-doubling curve's dataset
    other = intersect_curves(pd, g, model=m)
    assert other["special_kind"].values.tolist() == ["grazing-period-doubling"]
    assert abs(float(other["special_x"][0]) - float(fine["special_x"][0])) < 1e-12


def test_curves_without_the_attrs_keep_the_polyline_crossing(crossing):
    m, pd, g, _ = crossing
    bare = pd.copy()
    bare.attrs = {k: v for k, v in pd.attrs.items() if k != "steps_per_period"}
    out = intersect_curves(g, bare, model=m)
    assert int(out["special_located"][0]) == 0
    assert "steps_per_period" in str(out["special_detail"].values[0])


def _pair_minimum(x0: np.ndarray, omega: float, fa: float) -> float:
    """min over one period of x + b (b = 1) of the softening pair's orbit from x0 (DOP853,
    rtol 1e-10; x'' + 0.1 x' + g(x) = 0.1 + Fa Omega^2 cos(Omega t), g the dead zone)."""
    def f(t, y):
        g = y[0] - 1.0 if y[0] > 1.0 else (y[0] + 1.0 if y[0] < -1.0 else 0.0)
        return [y[1], 0.1 + fa * omega**2 * math.cos(omega * t) - 0.1 * y[1] - g]

    sol = solve_ivp(f, (0.0, 2 * math.pi / omega), x0, method="DOP853", rtol=1e-10,
                    atol=1e-12, dense_output=True, max_step=0.01)
    assert np.max(np.abs(sol.y[:, -1] - x0)) < 1e-5  # the orbit closes
    return float(np.min(sol.sol(np.linspace(0.0, 2 * math.pi / omega, 20001))[0])) + 1.0


def test_curves_of_different_orbits_cross_without_a_codimension_2_point():
    """The softening pair's upper fold curve crosses, in (Omega, Fa), the back flank's grazing
    curve of a larger coexisting orbit: no codimension-2 point. The polylines report a crossing;
    with the model it is not located (the fold's orbit keeps far off the back edge on both
    sides), checked by DOP853 from the two curves' section points nearest the crossing."""
    from geardyn.analysis.envelope import find_starts

    m = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05, kappa=0.0)
    br = geardyn.continuation(m, "Omega", 0.6, 1.4)
    fold = geardyn.curve(m, br, 1, "Fa", 0.6)
    assert fold.attrs["curve_kind"] == "fold"
    ((lo, hi, x0),) = find_starts(m, "Omega", "Fa", 0.45, np.linspace(0.05, 1.5, 30),
                                  flank="back")
    back = grazing_curve(m, "Omega", "Fa", (0.3, 1.5), (0.0, 2.0), flank="back",
                         at=(0.45, 0.5 * (lo + hi)), guess=x0)
    out = intersect_curves(back, fold, model=m)
    assert out["special_kind"].values.tolist() == ["grazing-fold"]
    assert int(out["special_located"][0]) == 0
    assert "different orbits" in str(out["special_detail"].values[0])
    at = np.array([float(out["special_x"][0]), float(out["special_y"][0])])
    for curve, want_far in ((fold, True), (back, False)):
        d = np.hypot(curve["Omega"].values - at[0], curve["Fa"].values - at[1])
        i = int(np.argmin(d))
        low = _pair_minimum(curve["section_point"].values[i], float(curve["Omega"][i]),
                            float(curve["Fa"][i]))
        assert (low > 0.5) if want_far else abs(low) < 1e-3, (curve.attrs["curve_kind"], low)
