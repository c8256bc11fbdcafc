"""The built-in models (and one user model) that the conformance and code-generation tests run:
each case is a model and a start state that makes a short run cross dead-zone edges where the
model has them."""

from __future__ import annotations

import math

import numba
import numpy as np

import geardyn

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}
#: The user model's coefficients: backlash half-width, damping ratio, force amplitude,
#: stiffness, forcing frequency.
USER_PARAMS = ("b", "zeta", "F", "k", "Omega")


@numba.njit(**_JIT)
def dead_zone_rhs(t, y, dy, p):
    """A forced oscillator with a dead zone, in the plain user interface."""
    x = y[0]
    b = p[0]
    g = x - b if x > b else (x + b if x < -b else 0.0)
    dy[0] = y[1]
    dy[1] = -2.0 * p[1] * y[1] - p[3] * g + p[2] * math.cos(p[4] * t)


@numba.njit(**_JIT)
def dead_zone_events(t, y, g, p):
    g[0] = y[0] - p[0]
    g[1] = y[0] + p[0]


@numba.njit(**_JIT)
def dead_zone_observe(t, y, out, p):
    x = y[0]
    b = p[0]
    out[0] = p[3] * (x - b if x > b else (x + b if x < -b else 0.0))


def user_model(k: float = 1.0, natural_frequency: bool = True, **kw) -> geardyn.UserModel:
    """The dead-zone oscillator as a :class:`geardyn.UserModel` (stiffness k)."""
    args = dict(n_states=2, params=[0.5, 0.05, 0.6, k, 1.2], param_names=USER_PARAMS,
                state_names=("x", "v"), events=dead_zone_events, n_events=2,
                observe=dead_zone_observe, observable_names=("F",), name="dead-zone oscillator",
                natural_frequency=(lambda p: math.sqrt(p[3])) if natural_frequency else None)
    args.update(kw)
    return geardyn.UserModel(dead_zone_rhs, **args)


def _catt(**params) -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(error="10 um", **params)
                              ).with_omega(1.1)


def _kicked(m: geardyn.Model, kick: list[float]) -> np.ndarray:
    return m.initial_state() + np.resize(np.asarray(kick), m.n_states)


def cases() -> dict[str, tuple[geardyn.Model, np.ndarray]]:
    """Case id -> (model, start state)."""
    reduced = _catt()
    general = reduced.general()
    dim = reduced.dimensional()
    pair = geardyn.GearPair(Omega=1.3, kappa=0.2, Fa=0.2)
    user = user_model()
    return {
        "CATTDevice-reduced": (reduced, _kicked(reduced, [0.3, 0.1, -0.2, 0.05])),
        "CATTDevice-general": (general, _kicked(general, [0.3, 0.1, -0.2, 0.05])),
        "DimensionalCATT": (dim, dim.initial_state()),
        "GearPair": (pair, np.zeros(2)),
        "UserModel": (user, np.array([1.0, 0.0])),
    }


IDS = ("CATTDevice-reduced", "CATTDevice-general", "DimensionalCATT", "GearPair", "UserModel")
