"""Dual numbers (:mod:`geardyn.core.dual`): each operation's tangent against a central difference
of the float function, values bitwise those of the float function; J v of the one-form models'
rhs (the gear pair against its Jacobian by hand, the reduced CATT device against central
differences of its float rhs) at points off the dead-zone edges; a result slot that does not
depend on the state (a plain float) has tangent 0."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn.core.dual import dual, tangent_of, value_of
from geardyn.core.one_form import call_tuple, coefficient_type
from geardyn.models.catt_reduced import catt_reduced_rhs
from geardyn.models.elements import dead_zone
from geardyn.models.gear_pair import gear_pair_rhs


def _ops(x):
    """Every dual operation a model uses (and a few more), as a float function of x."""
    a = 2.0 * x * x - 3 + x / (1.5 + x) - 0.25 * x
    a -= 1.0 / x
    a += x ** 2 + x ** 1.5
    a *= 0.5
    a /= 1.25
    b = math.sqrt(x * x + 1.0) + math.sin(x) * math.cos(x) + math.exp(-x) + math.log(x)
    b += abs(-x) + math.tanh(x) - (+x)
    c = max(x, 0.5) + min(0.25, x) + dead_zone(x, 0.5) + (x if x > 0.1 else 0.0)
    return a + b + c


_ops_float = nb.njit(_ops)


@nb.njit
def _ops_dual(x, v):
    d = _ops_float(dual(x, v))
    return value_of(d), tangent_of(d)


@pytest.mark.parametrize("x", [0.3, 0.8, 1.7, 3.2])
def test_each_operation_against_a_central_difference(x):
    h = 1e-6
    value, tangent = _ops_dual(x, 1.0)
    assert value == _ops_float(x)  # bitwise: the primal work is the float function's
    fd = (_ops_float(x + h) - _ops_float(x - h)) / (2 * h)
    assert tangent == pytest.approx(fd, rel=1e-7, abs=1e-8)
    assert _ops_dual(x, 2.5)[1] == pytest.approx(2.5 * tangent, rel=1e-14)


@nb.njit
def _compare(x, y):
    d = dual(x, 1.0)
    return (d < y, d <= y, d > y, d >= y, d == y, d != y, y < d, dual(y, 0.0) > d)


def test_comparisons_by_value():
    for x, y in ((1.0, 2.0), (2.0, 1.0), (1.5, 1.5)):
        assert _compare(x, y) == (x < y, x <= y, x > y, x >= y, x == y, x != y, y < x, y > x)


@nb.njit
def _jv2(t, y, v, p, s, c):
    d = gear_pair_rhs(t, (dual(y[0], v[0]), dual(y[1], v[1])), p, s, c)
    return (value_of(d[0]), value_of(d[1])), (tangent_of(d[0]), tangent_of(d[1]))


@nb.njit
def _jv4(t, y, v, p, s, c):
    d = catt_reduced_rhs(t, (dual(y[0], v[0]), dual(y[1], v[1]), dual(y[2], v[2]),
                             dual(y[3], v[3])), p, s, c)
    return ((value_of(d[0]), value_of(d[1]), value_of(d[2]), value_of(d[3])),
            (tangent_of(d[0]), tangent_of(d[1]), tangent_of(d[2]), tangent_of(d[3])))


def _coef(model):
    form = model.kernel.one_form
    return coefficient_type(form.coefficients, form.quiet)(*(float(v) for v in model.params))


@pytest.mark.parametrize("x", [1.7, 0.3, -2.2])
def test_gear_pair_jv_against_its_jacobian_by_hand(x):
    m = geardyn.GearPair(zeta=0.06, kappa=0.3, Fm=0.1, Fa=0.2, Omega=1.3, kappa_phase=0.4,
                         error_phase=0.9)
    p = _coef(m)
    t, th = 0.7, 2.1
    s, c = math.sin(th), math.cos(th)
    y = (x, -0.4)
    ck = math.cos(th + 0.4)
    gprime = 0.0 if abs(x) < 1.0 else 1.0
    J = np.array([[0.0, 1.0], [-(1.0 + 0.3 * ck) * gprime, -2.0 * 0.06]])
    for v in ((1.0, 0.0), (0.0, 1.0), (0.3, -1.2)):
        f, jv = _jv2(t, y, v, p, s, c)
        assert f == gear_pair_rhs(t, y, p, s, c)
        np.testing.assert_allclose(jv, J @ np.array(v), rtol=1e-12, atol=1e-15)


def _catt(**load):
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05, **load))


@pytest.mark.parametrize("load", [{}, {"B1": "100 N m", "B2": "100 N m", "Lambda": 0.1}],
                         ids=["quiet", "load"])
def test_reduced_catt_jv_against_central_differences(load):
    m = _catt(**load)
    names, quiet = m.kernel.one_form.coefficients, m.kernel.one_form.quiet
    p = _coef(m)
    assert (p.f_c1 != 0.0) == bool(load)
    b_sq = p.b_sq
    b_pq = p.b_pq
    t, th = 3.3, 0.8
    s, c = math.sin(th), math.cos(th)
    rng = np.random.default_rng(4)
    for xs, xp in ((1.8 * b_sq, 1.5 * b_pq), (0.4 * b_sq, -2.5 * b_pq), (-3.0 * b_sq, 0.1 * b_pq)):
        y = np.array([xs, 0.2, xp, -0.1])
        f0 = np.array(call_tuple(catt_reduced_rhs, names, t, y, m.params, s, c, quiet))
        J = np.empty((4, 4))
        for q in range(4):
            h = 1e-6 * max(1.0, abs(y[q]))
            e = np.zeros(4)
            e[q] = h
            fp = np.array(call_tuple(catt_reduced_rhs, names, t, y + e, m.params, s, c,
                                    quiet))
            fm = np.array(call_tuple(catt_reduced_rhs, names, t, y - e, m.params, s, c,
                                    quiet))
            J[:, q] = (fp - fm) / (2 * h)
        for v in (*np.eye(4), rng.standard_normal(4)):
            f, jv = _jv4(t, tuple(y), tuple(v), p, s, c)
            np.testing.assert_array_equal(f, f0)
            scale = np.abs(J).max()
            np.testing.assert_allclose(jv, J @ v, rtol=1e-6, atol=1e-8 * scale)


@nb.njit
def _mixed_rhs(t, y, p, s, c):
    return (y[1], p.a * c, -y[0])


@nb.njit
def _mixed(y, v, p):
    d = _mixed_rhs(0.0, (dual(y[0], v[0]), dual(y[1], v[1])), p, 0.5, 0.25)
    return (value_of(d[0]), value_of(d[1]), value_of(d[2]),
            tangent_of(d[0]), tangent_of(d[1]), tangent_of(d[2]))


def test_a_float_slot_has_tangent_zero():
    p = coefficient_type(("a",))(2.0)
    assert _mixed((1.5, -0.5), (0.3, 0.7), p) == (-0.5, 0.5, -1.5, 0.7, 0.0, -0.3)


def test_python_calls_are_refused():
    with pytest.raises(NotImplementedError):
        dual(1.0, 0.0)
