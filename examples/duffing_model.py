"""The forced double-well Duffing oscillator as compiled functions for geardyn.UserModel (used by
plot_03_user_lyapunov.py). Defined in an importable module, not in the script itself, so that
geardyn caches the kernels built from it on disk (functions of ``__main__`` get in-memory
kernels, compiled again in every process)."""

import math

import numba


@numba.njit(cache=True)
def duffing(t, y, dydt, p):
    """x'' + delta x' - x + x^3 = gamma cos(Omega t); p = (delta, gamma, Omega)."""
    delta, gamma, omega = p[0], p[1], p[2]
    dydt[0] = y[1]
    dydt[1] = -delta * y[1] + y[0] - y[0] ** 3 + gamma * math.cos(omega * t)


@numba.njit(cache=True)
def duffing_one(t, y, p, s, c):
    """The same oscillator in the one form (the way to write a model, see
    geardyn.UserModel.from_one_form): y = (x, v), the coefficients by name, c = cos(Omega t)."""
    x, v = y
    return (v, -p.delta * v + x - x * x * x + p.gamma * c)
