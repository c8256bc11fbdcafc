"""Compiled right-hand sides of the CATT device (numba).

Kernel interface shared by every geardyn model (see :mod:`geardyn.models.base`):

``rhs(t, y, dy, p, s, c)``
    writes dy/dt; ``s, c`` are sin and cos of the forcing (mesh) phase, supplied by the solver
    (from a table on the period-aligned grid, 0 at the start of a run or lane), ``p`` is the
    coefficient vector. Every term at the mesh frequency takes its phase from (s, c); the load
    fluctuation at Lambda (a second excitation, in general incommensurate) from the time t.
``events(t, y, g, p, s, c)``
    switching functions whose zero crossings are the kinks of the right-hand side, at the same
    forcing phase (s, c) as the right-hand side.
``observe(t, y, o, p, s, c)``
    derived outputs (here: the dynamic mesh forces in newtons).

Mesh-coordinate form (Eq. 10 corrected), state per planet set i: X_sq, X_sq', X_pq, X_pq'.
The coefficient vector is a header followed by one block per planet set. The reduced model for N
identical planet sets is the same right-hand side with one block whose carrier-coupling
coefficients are multiplied by N, written in the one form (:mod:`geardyn.models.catt_reduced`);
with one block in ``p`` the functions here give its bits (``tests/test_catt_one_form.py``).
"""

from __future__ import annotations

import math

import numba as nb

from geardyn._jit_target import WidthCompiler
from geardyn.models.derived import CATT_BLOCK, CATT_HEADER, THETA_BLOCK, THETA_HEADER
from geardyn.models.elements import dead_zone, harmonic_factor

# Index constants: the offsets of the declared coefficients (geardyn.models.derived).
# header
_H = CATT_HEADER.offset
OMEGA, LAMBDA, N_BLOCKS, N_HARM = _H("Omega"), _H("Lambda"), _H("n_blocks"), _H("n_harmonics")
F_C0, F_C1, PSI1, PSI2 = _H("f_c0"), _H("f_c1"), _H("psi1"), _H("psi2")
HEADER = CATT_HEADER.size
# block
_B = CATT_BLOCK.offset
K_SQ_C, C_SQ_C, K_SQ_Q, C_SQ_Q = _B("k_sq_c"), _B("c_sq_c"), _B("k_sq_q"), _B("c_sq_q")
K_PQ_Q, C_PQ_Q, K_PQ_P, C_PQ_P = _B("k_pq_q"), _B("c_pq_q"), _B("k_pq_p"), _B("c_pq_p")
B_SQ, B_PQ, F_P0, F_P1 = _B("b_sq"), _B("b_pq"), _B("f_p0"), _B("f_p1")
E_SQ_S, E_SQ_C, E_PQ_S, E_PQ_C = _B("E_sq_s"), _B("E_sq_c"), _B("E_pq_s"), _B("E_pq_c")
FORCE_SCALE, SPARE = _B("force_scale"), _B("spare")
BLOCK_FIXED = CATT_BLOCK.size


def block_size(n_harmonics: int) -> int:
    """Length of one planet-set block for the given number of stiffness harmonics."""
    return BLOCK_FIXED + 4 * n_harmonics


_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}


# The load fluctuation's sine, as arithmetic (no libm call), so that the sweep kernel's fused
# lane loop vectorises with the load on: Cody-Waite reduction by pi/2 in three parts (exact for
# |x| < 2^20 pi / 2 ~ 1.6e6), then the minimax polynomials of fdlibm's __kernel_sin and
# __kernel_cos (coefficients from Sun's fdlibm, k_sin.c / k_cos.c) and a branch-free quadrant
# select. Within 2 ulp of sin(x) there; beyond, the reduction rounds by about ulp(x), the
# rounding of the argument Lambda t + psi itself (tests/test_catt_lane_forms.py). Every form of
# the load term (this general model's, the reduced one form's every layout) calls it, so they
# stay bitwise equal.
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00  # pi/2 in three parts: 33 + 33 + 53 bits
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21
#: |x| below which :func:`load_sin` is within 2 ulp of sin(x) (the reduction is exact).
LOAD_SIN_EXACT_BELOW = 1.6e6


@nb.njit(inline="always", **_JIT)
def load_sin(x):
    """sin(x) without a libm call (see above): within 2 ulp for |x| < LOAD_SIN_EXACT_BELOW."""
    n = math.floor(x * _INV_PIO2 + 0.5)
    r = ((x - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_3
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (((1.0 - w) - hz) + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (
        _C5 + z * _C6))))))
    q = n - 4.0 * math.floor(n * 0.25)  # the quadrant, 0..3
    v = s if q == 0.0 else c
    v = -s if q == 2.0 else v
    return -c if q == 3.0 else v


# Each function below is written once, inline, for n_sets planet sets (the general model reads
# n_sets from p; the reduced model, one set, is its one form: geardyn.models.catt_reduced).
# Helpers take arrays only when inlined.


@nb.njit(inline="always", **_JIT)
def _rhs(t, y, dy, p, s, c, n_sets):
    om2 = p[OMEGA] * p[OMEGA]
    nh = int(p[N_HARM])
    bs = BLOCK_FIXED + 4 * nh
    load_c = p[F_C0]
    sin_l1 = 0.0
    if p[F_C1] != 0.0 or p[HEADER + F_P1] != 0.0:
        load_c += p[F_C1] * load_sin(p[LAMBDA] * t + p[PSI2])
        sin_l1 = load_sin(p[LAMBDA] * t + p[PSI1])
    carrier = 0.0
    for i in range(n_sets):
        o = HEADER + i * bs
        j = 4 * i
        xs = y[j]
        vs = y[j + 1]
        xp = y[j + 2]
        vp = y[j + 3]
        gs = harmonic_factor(p, o + BLOCK_FIXED, nh, s, c) * dead_zone(xs, p[o + B_SQ])
        gp = harmonic_factor(p, o + BLOCK_FIXED + 2 * nh, nh, s, c) * dead_zone(xp, p[o + B_PQ])
        carrier += p[o + K_SQ_C] * gs + p[o + C_SQ_C] * vs
        f_sq = p[o + K_SQ_Q] * gs + p[o + C_SQ_Q] * vs
        f_pq = p[o + K_PQ_Q] * gp + p[o + C_PQ_Q] * vp
        f_pp = p[o + K_PQ_P] * gp + p[o + C_PQ_P] * vp
        load_p = p[o + F_P0] + p[o + F_P1] * sin_l1
        dy[j] = vs
        dy[j + 1] = -f_sq + f_pq + om2 * (p[o + E_SQ_S] * s + p[o + E_SQ_C] * c)
        dy[j + 2] = vp
        dy[j + 3] = (f_sq - f_pq - f_pp + load_p
                     + om2 * (p[o + E_PQ_S] * s + p[o + E_PQ_C] * c))
    for i in range(n_sets):
        dy[4 * i + 1] += load_c - carrier


@nb.njit(inline="always", **_JIT)
def _events(y, g, p, n_sets):
    bs = BLOCK_FIXED + 4 * int(p[N_HARM])
    for i in range(n_sets):
        o = HEADER + i * bs
        g[4 * i] = y[4 * i] - p[o + B_SQ]
        g[4 * i + 1] = y[4 * i] + p[o + B_SQ]
        g[4 * i + 2] = y[4 * i + 2] - p[o + B_PQ]
        g[4 * i + 3] = y[4 * i + 2] + p[o + B_PQ]


@nb.njit(inline="always", **_JIT)
def _observe(y, out, p, s, c, n_sets):
    nh = int(p[N_HARM])
    bs = BLOCK_FIXED + 4 * nh
    for i in range(n_sets):
        o = HEADER + i * bs
        j = 4 * i
        gs = harmonic_factor(p, o + BLOCK_FIXED, nh, s, c) * dead_zone(y[j], p[o + B_SQ])
        gp = (harmonic_factor(p, o + BLOCK_FIXED + 2 * nh, nh, s, c)
              * dead_zone(y[j + 2], p[o + B_PQ]))
        scale = p[o + FORCE_SCALE]
        out[2 * i] = scale * (p[o + K_SQ_Q] * gs + p[o + C_SQ_Q] * y[j + 1])
        out[2 * i + 1] = scale * (p[o + K_PQ_Q] * gp + p[o + C_PQ_Q] * y[j + 3])


@nb.njit(**_JIT)
def catt_rhs(t, y, dy, p, s, c):
    """dy/dt of the CATT device with p[N_BLOCKS] planet sets."""
    _rhs(t, y, dy, p, s, c, int(p[N_BLOCKS]))


@nb.njit(**_JIT)
def catt_events(t, y, g, p, s, c):
    """Dead-zone edges: X - b and X + b of every mesh."""
    _events(y, g, p, int(p[N_BLOCKS]))


@nb.njit(**_JIT)
def catt_observe(t, y, out, p, s, c):
    """Dynamic mesh forces [N] (sun-inside, inside-outside per planet set)."""
    _observe(y, out, p, s, c, int(p[N_BLOCKS]))


# ---------------------------------------------------------------------------------------------
# Dimensional form, Eq. (1), in the body angles (SI units, time in seconds).
# State: theta_c, theta_c', then per planet set theta_q, theta_q', theta_p, theta_p'.
# Index constants: the offsets of the declared coefficients (geardyn.models.derived).
_TH, _TB = THETA_HEADER.offset, THETA_BLOCK.offset
T_OMEGA, T_OMEGA_L, T_N, T_NH = _TH("omega"), _TH("omega_L"), _TH("n_sets"), _TH("n_harmonics")
T_TD, T_A1, T_B1, T_PSI1 = _TH("T_D"), _TH("A1"), _TH("B1"), _TH("psi1")
T_A2, T_B2, T_PSI2 = _TH("A2"), _TH("B2"), _TH("psi2")
T_JC, T_RC1, T_ARM = _TH("J_c"), _TH("r_c1"), _TH("arm")
T_HEADER = THETA_HEADER.size
T_JQ, T_JP, T_RBQ, T_RBP = _TB("J_q"), _TB("J_p"), _TB("r_bq"), _TB("r_bp")
T_KM_SQ, T_KM_PQ, T_C_SQ, T_C_PQ = _TB("Km_sq"), _TB("Km_pq"), _TB("C_sq"), _TB("C_pq")
T_B_SQ, T_B_PQ = _TB("b_sq"), _TB("b_pq")
T_E_SQ_S, T_E_SQ_C = _TB("E_sq_s"), _TB("E_sq_c")
T_E_PQ_S, T_E_PQ_C = _TB("E_pq_s"), _TB("E_pq_c")
T_BLOCK_FIXED = THETA_BLOCK.size


@nb.njit(**_JIT)
def theta_rhs(t, y, dy, p, s, c):
    w = p[T_OMEGA]
    n = int(p[T_N])
    nh = int(p[T_NH])
    bs = T_BLOCK_FIXED + 4 * nh
    tl1 = p[T_A1] + p[T_B1] * math.sin(p[T_OMEGA_L] * t + p[T_PSI1])
    tl2 = p[T_A2] + p[T_B2] * math.sin(p[T_OMEGA_L] * t + p[T_PSI2])
    th_c = y[0]
    w_c = y[1]
    carrier_torque = p[T_TD] - tl2
    for i in range(n):
        o = T_HEADER + i * bs
        j = 2 + 4 * i
        th_q = y[j]
        w_q = y[j + 1]
        th_p = y[j + 2]
        w_p = y[j + 3]
        # meshing errors e = E sin(w t + phi) and their rates
        e_sq = p[o + T_E_SQ_S] * s + p[o + T_E_SQ_C] * c
        de_sq = w * (p[o + T_E_SQ_S] * c - p[o + T_E_SQ_C] * s)
        e_pq = p[o + T_E_PQ_S] * s + p[o + T_E_PQ_C] * c
        de_pq = w * (p[o + T_E_PQ_S] * c - p[o + T_E_PQ_C] * s)
        x_sq = th_c * p[T_RC1] - th_q * p[o + T_RBQ] - e_sq
        dx_sq = w_c * p[T_RC1] - w_q * p[o + T_RBQ] - de_sq
        x_pq = th_q * p[o + T_RBQ] - th_p * p[o + T_RBP] - e_pq
        dx_pq = w_q * p[o + T_RBQ] - w_p * p[o + T_RBP] - de_pq
        k_sq = p[o + T_KM_SQ] * harmonic_factor(p, o + T_BLOCK_FIXED, nh, s, c)
        k_pq = p[o + T_KM_PQ] * harmonic_factor(p, o + T_BLOCK_FIXED + 2 * nh, nh, s, c)
        f_sq = k_sq * dead_zone(x_sq, p[o + T_B_SQ]) + p[o + T_C_SQ] * dx_sq
        f_pq = k_pq * dead_zone(x_pq, p[o + T_B_PQ]) + p[o + T_C_PQ] * dx_pq
        dy[j] = w_q
        dy[j + 1] = (f_sq - f_pq) * p[o + T_RBQ] / p[o + T_JQ]
        dy[j + 2] = w_p
        dy[j + 3] = (f_pq * p[o + T_RBP] - tl1) / p[o + T_JP]
        carrier_torque -= f_sq * p[T_ARM]
    dy[0] = w_c
    dy[1] = carrier_torque / p[T_JC]


@nb.njit(**_JIT)
def theta_events(t, y, g, p, s, c):
    """Dead-zone edges of Eq. (1): x - b and x + b of every mesh deflection [m] (sun-inside,
    inside-outside per planet set), the deflections written as in :func:`theta_rhs` (the
    meshing errors at the forcing phase s, c)."""
    n = int(p[T_N])
    bs = T_BLOCK_FIXED + 4 * int(p[T_NH])
    for i in range(n):
        o = T_HEADER + i * bs
        j = 2 + 4 * i
        e_sq = p[o + T_E_SQ_S] * s + p[o + T_E_SQ_C] * c
        e_pq = p[o + T_E_PQ_S] * s + p[o + T_E_PQ_C] * c
        x_sq = y[0] * p[T_RC1] - y[j] * p[o + T_RBQ] - e_sq
        x_pq = y[j] * p[o + T_RBQ] - y[j + 2] * p[o + T_RBP] - e_pq
        g[4 * i] = x_sq - p[o + T_B_SQ]
        g[4 * i + 1] = x_sq + p[o + T_B_SQ]
        g[4 * i + 2] = x_pq - p[o + T_B_PQ]
        g[4 * i + 3] = x_pq + p[o + T_B_PQ]
