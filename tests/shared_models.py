"""The user models the tests share: one forced 2-state oscillator whose coefficients select each
equation family the tests run (linear, Duffing, van der Pol, Rayleigh-Mathieu, a tanh step,
incommensurate or modulated forcing) and the Lorenz system. Each is one compiled function, so its
kernels (sweep, trajectory, Lyapunov, monodromy) compile once for every test that uses it; in
their own module, so that editing a test does not change the generated kernels' digest."""

from __future__ import annotations

import math
from collections.abc import Callable

import numba as nb
import numpy as np

import geardyn

#: The oscillator's coefficients and their defaults (the undamped unforced oscillator x'' + x =
#: 0): forcing frequency Omega; damping ratio zeta, Rayleigh damping rho, van der Pol damping
#: mu; stiffness k, its parametric modulation kappa, cubic stiffness beta, tanh step a of width
#: w; forcing amplitude F, subharmonic forcing G at Omega / q, amplitude modulation m at
#: Lambda. See :func:`oscillator_rhs`.
OSCILLATOR = {"Omega": 1.0, "zeta": 0.0, "rho": 0.0, "mu": 0.0, "k": 1.0, "kappa": 0.0,
              "beta": 0.0, "a": 0.0, "w": 1.0, "F": 0.0, "G": 0.0, "q": 1.0, "m": 0.0,
              "Lambda": 0.0}


@nb.njit(cache=True)
def oscillator_rhs(t, y, dy, p):
    """x'' + (2 zeta + rho x^2 - mu (1 - x^2)) x' + (k + kappa cos(Omega t)) x + beta x^3
    + a tanh(x / w) = F cos(Omega t) + G cos(Omega t / q) + m cos(Lambda t) cos(Omega t);
    p in the order of :data:`OSCILLATOR`. A term whose coefficient a, G or m is 0 is not
    evaluated (no tanh or cos call)."""
    x, v = y[0], y[1]
    c = math.cos(p[0] * t)
    damping = 2.0 * p[1] + p[2] * x * x - p[3] * (1.0 - x * x)
    restoring = (p[4] + p[5] * c) * x + p[6] * x * x * x
    if p[7] != 0.0:
        restoring += p[7] * math.tanh(x / p[8])
    force = p[9] * c
    if p[10] != 0.0:
        force += p[10] * math.cos(p[0] * t / p[11])
    if p[12] != 0.0:
        force += p[12] * math.cos(p[13] * t) * c
    dy[0] = v
    dy[1] = force - damping * v - restoring


def oscillator(name: str = "oscillator",
               natural_frequency: float | Callable[[np.ndarray], float] | None = None,
               **coefficients: float) -> geardyn.UserModel:
    """The oscillator of :func:`oscillator_rhs` as a plain :class:`geardyn.UserModel` (states x,
    v), the coefficients by name (the others at their :data:`OSCILLATOR` defaults)."""
    unknown = sorted(set(coefficients) - set(OSCILLATOR))
    if unknown:
        raise ValueError(f"oscillator: no coefficient {unknown} (known: {', '.join(OSCILLATOR)})")
    values = {**OSCILLATOR, **coefficients}
    return geardyn.UserModel(oscillator_rhs, n_states=2, params=list(values.values()),
                             param_names=tuple(values), state_names=("x", "v"), name=name,
                             natural_frequency=natural_frequency)


@nb.njit(cache=True)
def lorenz_rhs(t, y, dy, p):
    """The Lorenz system; p = (sigma, rho, beta)."""
    dy[0] = p[0] * (y[1] - y[0])
    dy[1] = y[0] * (p[1] - y[2]) - y[1]
    dy[2] = y[0] * y[1] - p[2] * y[2]


def lorenz(sigma: float = 10.0, rho: float = 28.0, beta: float = 8.0 / 3.0) -> geardyn.UserModel:
    """The Lorenz system as an autonomous :class:`geardyn.UserModel` (states x, y, z)."""
    return geardyn.UserModel(lorenz_rhs, n_states=3, params=[sigma, rho, beta], period=None,
                             state_names=["x", "y", "z"])
