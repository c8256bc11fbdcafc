"""A small model that binds the kernel template when it is imported as it stands.

A unit-mass oscillator with a dead zone of half-width p[1], damping p[2] and harmonic forcing
p[3] sin(Omega t), Omega = p[0]: x'' + p[2] x' + g(x, p[1]) = p[3] sin(Omega t).
"""

from __future__ import annotations

import numba as nb

from geardyn._jit_target import WidthCompiler
from geardyn.models.elements import dead_zone

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}


@nb.njit(**_JIT)
def rhs(t, y, dy, p, s, c):
    x = y[0]
    b = p[1]
    g = dead_zone(x, b)
    dy[0] = y[1]
    dy[1] = -p[2] * y[1] - g + p[3] * s


@nb.njit(**_JIT)
def events(t, y, g, p, s, c):
    g[0] = y[0] - p[1]
    g[1] = y[0] + p[1]


@nb.njit(**_JIT)
def observe(t, y, out, p, s, c):
    out[0] = y[0]
