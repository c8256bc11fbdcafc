import numba as nb
import numpy as np


@nb.njit(cache=True)
def vdp_rhs(t, y, dy, p):
    # x'' - mu (1 - x^2) x' + x = F cos(Omega t); p = (mu, F, Omega)
    dy[0] = y[1]
    dy[1] = p[0] * (1.0 - y[0] * y[0]) * y[1] - y[0] + p[1] * np.cos(p[2] * t)


@nb.njit(cache=True)
def sub_rhs(t, y, dy, p):
    # x'' + 2 zeta x' + x = F cos(Omega t) + G cos(Omega t / q); p = (zeta, F, G, q, Omega)
    dy[0] = y[1]
    dy[1] = (-2.0 * p[0] * y[1] - y[0] + p[1] * np.cos(p[4] * t)
             + p[2] * np.cos(p[4] * t / p[3]))
