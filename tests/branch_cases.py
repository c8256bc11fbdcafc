"""Compiled right-hand sides for the bifurcation tests of tests/test_branch_points.py, in their
own module so that editing the tests does not change the generated kernels' digest."""

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


@nb.njit(cache=True)
def parametric_rayleigh(t, y, dy, p):
    """x'' + 2 zeta x' + mu x^2 x' + (1 + kappa cos(Omega t)) x = 0; p = (Omega, zeta, kappa,
    mu): the damped Mathieu equation about x = 0, with a damping that grows with the
    amplitude."""
    dy[0] = y[1]
    dy[1] = (-2.0 * p[1] * y[1] - p[3] * y[0] * y[0] * y[1]
             - (1.0 + p[2] * math.cos(p[0] * t)) * y[0])

