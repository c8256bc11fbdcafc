"""Compiled right-hand side of the Lin & Parker planetary gear set (numba).

Dimensionless form (see :mod:`geardyn.models.planetary`): state ``(X, X')`` with X = q / L the
generalised coordinates over the length scale L and ' = d/dtau, tau = omega_0 t::

    X'' = F0 + F1 sin(r Omega tau + psi) - Kt X - Ct X' - sum_m f_m G_m
    f_m = KF_m k_m(Omega tau) g(W_m . X - e_m, b_m) + CF_m (W_m . X' - e_m')

Kt, Ct: the linear (bearing, support) stiffness and the modal damping matrices premultiplied by
M^-1 (dense); per mesh m: W_m the deflection row, G_m = M^-1 W_m / (L omega_0^2) [1/N], KF_m and
CF_m [N] the force per unit deflection and deflection rate, k_m the relative stiffness (Fourier
series in the mesh phase), e_m = ES_m sin(Omega tau) + EC_m cos(Omega tau) the transmission error.
f_m is the dynamic mesh force [N], the observable.

Coefficient vector: a header (``DAMPED`` is 1 where Ct is not zero), the dof vectors F0, F1,
the matrices Kt, Ct (row-major), then one block per mesh (fixed entries, 2 nh Fourier
coefficients, W, G).
"""

from __future__ import annotations

import math

import numba as nb

# header
OMEGA, N_DOF, N_MESH, N_HARM, TORQUE_ON, TORQUE_ORDER, TORQUE_PHASE, DAMPED = range(8)
HEADER = 8
# mesh block fixed entries
M_B, M_ES, M_EC, M_KF, M_CF = range(5)
MESH_FIXED = 5

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}


def layout(n: int, n_mesh: int, nh: int) -> dict[str, int]:
    """Offsets of the parts of the coefficient vector for n dofs, n_mesh meshes, nh harmonics."""
    f0 = HEADER
    f1 = f0 + n
    kt = f1 + n
    ct = kt + n * n
    mesh = ct + n * n
    bs = MESH_FIXED + 2 * nh + 2 * n
    return {"F0": f0, "F1": f1, "Kt": kt, "Ct": ct, "mesh": mesh, "block": bs,
            "size": mesh + n_mesh * bs}


@nb.njit(inline="always", **_JIT)
def _dead_zone(x, b):
    return x - min(max(x, -b), b)


@nb.njit(inline="always", **_JIT)
def _relative_stiffness(p, f, nh, s, c):
    """1 + sum_h p[f+2h] cos(h theta) + p[f+2h+1] sin(h theta), theta the forcing phase."""
    if nh == 0:
        return 1.0
    acc = p[f] * c + p[f + 1] * s
    ch = c
    sh = s
    for h in range(1, nh):
        ch, sh = ch * c - sh * s, sh * c + ch * s
        acc += p[f + 2 * h] * ch + p[f + 2 * h + 1] * sh
    return 1.0 + acc


@nb.njit(inline="always", **_JIT)
def _mesh_state(y, p, o, n, nh, s, c):
    """Deflection minus error and its rate (W . X - e, W . X' - e') of the mesh block at o."""
    w = o + MESH_FIXED + 2 * nh
    d = 0.0
    v = 0.0
    for j in range(n):
        d += p[w + j] * y[j]
        v += p[w + j] * y[n + j]
    om = p[OMEGA]
    d -= p[o + M_ES] * s + p[o + M_EC] * c
    v -= om * (p[o + M_ES] * c - p[o + M_EC] * s)
    return d, v


@nb.njit(inline="always", **_JIT)
def _mesh_force(y, p, o, n, nh, s, c):
    d, v = _mesh_state(y, p, o, n, nh, s, c)
    k = _relative_stiffness(p, o + MESH_FIXED, nh, s, c)
    return p[o + M_KF] * k * _dead_zone(d, p[o + M_B]) + p[o + M_CF] * v


@nb.njit(**_JIT)
def planetary_rhs(t, y, dy, p, s, c):
    """dy/dt of the planetary gear set (dimensionless)."""
    n = int(p[N_DOF])
    nm = int(p[N_MESH])
    nh = int(p[N_HARM])
    f0 = HEADER
    f1 = f0 + n
    kt = f1 + n
    ct = kt + n * n
    mesh = ct + n * n
    bs = MESH_FIXED + 2 * nh + 2 * n
    fl = 0.0
    if p[TORQUE_ON] != 0.0:
        fl = math.sin(p[TORQUE_ORDER] * p[OMEGA] * t + p[TORQUE_PHASE])
    damped = p[DAMPED] != 0.0  # modal damping: the Ct product (skipped when Ct = 0)
    for i in range(n):
        acc = p[f0 + i] + p[f1 + i] * fl
        r = kt + i * n
        for j in range(n):
            acc -= p[r + j] * y[j]
        if damped:
            q = ct + i * n
            for j in range(n):
                acc -= p[q + j] * y[n + j]
        dy[i] = y[n + i]
        dy[n + i] = acc
    for m in range(nm):
        o = mesh + m * bs
        f = _mesh_force(y, p, o, n, nh, s, c)
        g = o + MESH_FIXED + 2 * nh + n
        for j in range(n):
            dy[n + j] -= f * p[g + j]


@nb.njit(**_JIT)
def planetary_events(t, y, g, p):
    """Dead-zone edges: x_m - b_m and x_m + b_m of every mesh (x_m = W_m . X - e_m)."""
    n = int(p[N_DOF])
    nm = int(p[N_MESH])
    nh = int(p[N_HARM])
    mesh = HEADER + 2 * n + 2 * n * n
    bs = MESH_FIXED + 2 * nh + 2 * n
    s = 0.0
    c = 1.0
    errors = False
    for m in range(nm):
        o = mesh + m * bs
        errors |= (p[o + M_ES] != 0.0) | (p[o + M_EC] != 0.0)
    if errors:
        s = math.sin(p[OMEGA] * t)
        c = math.cos(p[OMEGA] * t)
    for m in range(nm):
        o = mesh + m * bs
        d, _ = _mesh_state(y, p, o, n, nh, s, c)
        g[2 * m] = d - p[o + M_B]
        g[2 * m + 1] = d + p[o + M_B]


@nb.njit(**_JIT)
def planetary_observe(t, y, out, p, s, c):
    """Dynamic mesh forces [N], one per mesh (sun-planet meshes, then ring-planet meshes)."""
    n = int(p[N_DOF])
    nm = int(p[N_MESH])
    nh = int(p[N_HARM])
    mesh = HEADER + 2 * n + 2 * n * n
    bs = MESH_FIXED + 2 * nh + 2 * n
    for m in range(nm):
        out[m] = _mesh_force(y, p, mesh + m * bs, n, nh, s, c)
