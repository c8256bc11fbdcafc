"""The user model of the codimension-2 tests (in its own module, so that editing a test does not
change its kernels' digest): a damped Mathieu oscillator beside a scalar saddle-node."""

from __future__ import annotations

import math

import numba as nb

import geardyn

#: The coefficients and their defaults: forcing frequency Omega, damping ratio zeta, stiffness
#: variation kappa, the saddle-node's threshold lam.
MATHIEU_SADDLE_NODE = {"Omega": 1.6, "zeta": 0.02, "kappa": 0.3, "lam": 0.3}


@nb.njit(cache=True)
def mathieu_saddle_node_rhs(t, y, dy, p):
    """x'' + 2 zeta x' + (1 + kappa cos(Omega t)) x = 0 and w' = kappa - lam - w^2 (uncoupled);
    p in the order of :data:`MATHIEU_SADDLE_NODE`."""
    dy[0] = y[1]
    dy[1] = -2.0 * p[1] * y[1] - (1.0 + p[2] * math.cos(p[0] * t)) * y[0]
    dy[2] = p[2] - p[3] - y[2] * y[2]


def mathieu_saddle_node(**coefficients: float) -> geardyn.UserModel:
    """The model of :func:`mathieu_saddle_node_rhs` (states x, v, w). Its orbit x = v = 0,
    w = +-sqrt(kappa - lam) has the damped Mathieu equation's two multipliers and
    exp(-+2 sqrt(kappa - lam) T), T = 2 pi / Omega: a fold where kappa = lam (multiplier +1),
    a period doubling on the Mathieu equation's instability boundary (multiplier -1)."""
    values = {**MATHIEU_SADDLE_NODE, **coefficients}
    return geardyn.UserModel(mathieu_saddle_node_rhs, n_states=3, params=list(values.values()),
                             param_names=tuple(values), state_names=("x", "v", "w"),
                             name="mathieu_saddle_node", natural_frequency=1.0)
