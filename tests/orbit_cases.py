"""Compiled right-hand sides for tests/test_periodic_orbit.py, in their own module so that
editing the tests does not change the generated kernels' digest (no recompile)."""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True)
def duffing(t, y, dy, p):
    """x'' + delta x' + x + beta x^3 = gamma cos(Omega t); p = (Omega, delta, beta, gamma)."""
    dy[0] = y[1]
    dy[1] = -p[1] * y[1] - y[0] - p[2] * y[0] ** 3 + p[3] * math.cos(p[0] * t)
