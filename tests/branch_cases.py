"""The five-state compiled right-hand side of the slow bifurcation test of
tests/test_branch_points.py, in its own module so that editing the tests does not change the
generated kernels' digest."""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True)
def duffing_with_spectators(t, y, dy, p):
    """x'' + 2 zeta x' + x + beta x^3 = F cos(Omega t) with two uncoupled linear spectators:
    y' = -c y (the real multiplier exp(-c T)) and u'' + 2 zu u' + u = 0 (the complex pair
    exp((-zu +- i sqrt(1 - zu^2)) T)); p = (Omega, zeta, beta, F, c, zu)."""
    dy[0] = y[1]
    dy[1] = (-2.0 * p[1] * y[1] - y[0] - p[2] * y[0] * y[0] * y[0]
             + p[3] * math.cos(p[0] * t))
    dy[2] = -p[4] * y[2]
    dy[3] = y[4]
    dy[4] = -2.0 * p[5] * y[4] - y[3]
