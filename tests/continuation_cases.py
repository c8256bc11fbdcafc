"""Compiled right-hand sides for tests/test_orbit_continuation.py, in their own module so that
editing the tests does not change the generated kernels' digest (no recompile)."""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True)
def van_der_pol(t, y, dy, p):
    """x'' - eps (1 - x^2) x' + x = gamma cos(Omega t); p = (Omega, eps, gamma)."""
    dy[0] = y[1]
    dy[1] = p[1] * (1.0 - y[0] * y[0]) * y[1] - y[0] + p[2] * math.cos(p[0] * t)
