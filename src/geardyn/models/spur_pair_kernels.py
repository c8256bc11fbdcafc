"""The compiled physics of :class:`geardyn.SpurPair` (see :mod:`geardyn.models.spur_pair` for
the equation): the lane-scalar forms the sweep's fused step loop inlines, and the array interface
on them. Kept apart from the model class, so that an edit there recompiles no kernel (a generated
kernel is keyed by the source of the modules its functions live in)."""

from __future__ import annotations

import math

import numba as nb

from geardyn._jit_target import WidthCompiler
from geardyn.core.kernel_source import FORM_GENERAL, KernelSource
from geardyn.models.elements import harmonic_turn
from geardyn.models.spur_pair_coefficients import HEADER

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}
OMEGA, MASS, TORQUE, ZETA, BACKLASH = (HEADER.offset(n) for n in
                                       ("Omega", "mass", "torque", "zeta", "backlash"))
ERROR, PHI_E, K_MEAN, COS_E, SIN_E = (HEADER.offset(n) for n in
                                      ("error", "error_phase", "k_mean", "cos_error_phase",
                                       "sin_error_phase"))
R_B1, MESH_ORDER, N_HARM = (HEADER.offset(n) for n in ("base_radius", "mesh_order",
                                                         "n_harmonics"))
FORM, N_TABLE = HEADER.offset("stiffness_form"), HEADER.offset("table_points")
#: Offset of the drive flank's series (k0, a1, b1, ..., aH, bH) or table (n values); the coast
#: flank's follows it.
KD0 = HEADER.size
#: 1 / (2 pi): the forcing phase in periods.
_INV_TWO_PI = 0.5 / math.pi


# ---------------------------------------------------------------------------------------------
# The physics, once, in the engine's lane-scalar form (see geardyn.core.kernel_source): lane k's
# coefficients are the column PT[:, k], y = (x, v) [m, m/s] a tuple, s, c sin and cos of theta.
# The sweep's fused step loop inlines these; the array interface rhs(t, y, dy, p, s, c) of the
# trajectory, split steps, Lyapunov and monodromy kernels calls them on p as a one-lane column
# (p[None, :].T, as the engine itself does). The series are indexed at run time, so one compiled
# kernel serves every number of harmonics (the one form's named tuple of ~4H coefficients would
# not: numba lowers each indexing of it at a run-time offset to a switch over every field).

@nb.njit(inline="always", **_JIT)
def flank_stiffness(PT, k, o, n, s, c):
    """k0 + sum_{h=1..n} a_h cos(h theta) + b_h sin(h theta) of the series at row o of lane k.
    cos and sin of h theta by rotation from those of theta (no libm call), in four independent
    chains (h = 4 m + 1 .. 4 m + 4, each turned by 4 theta per m) so that the rotations overlap
    instead of waiting on one another."""
    c2, s2 = c * c - s * s, 2.0 * c * s
    c3, s3 = harmonic_turn(c2, s2, c, s)
    c4, s4 = c2 * c2 - s2 * s2, 2.0 * c2 * s2
    ca, sa, cb, sb, cc, sc, cd, sd = c, s, c2, s2, c3, s3, c4, s4
    acc0, acc1, acc2, acc3 = PT[o, k], 0.0, 0.0, 0.0
    q = o + 1
    for _ in range(n // 4):
        acc0 += PT[q, k] * ca + PT[q + 1, k] * sa
        acc1 += PT[q + 2, k] * cb + PT[q + 3, k] * sb
        acc2 += PT[q + 4, k] * cc + PT[q + 5, k] * sc
        acc3 += PT[q + 6, k] * cd + PT[q + 7, k] * sd
        ca, sa = harmonic_turn(ca, sa, c4, s4)
        cb, sb = harmonic_turn(cb, sb, c4, s4)
        cc, sc = harmonic_turn(cc, sc, c4, s4)
        cd, sd = harmonic_turn(cd, sd, c4, s4)
        q += 8
    r = n % 4  # the last harmonics: chains a, b, c continue where they stand
    if r > 0:
        acc0 += PT[q, k] * ca + PT[q + 1, k] * sa
    if r > 1:
        acc1 += PT[q + 2, k] * cb + PT[q + 3, k] * sb
    if r > 2:
        acc2 += PT[q + 4, k] * cc + PT[q + 5, k] * sc
    return (acc0 + acc1) + (acc2 + acc3)


@nb.njit(inline="always", **_JIT)
def flank_table(PT, k, o, n, s, c):
    """The n-point table at row o of lane k (the stiffness at theta_j = 2 pi j / n), linear
    between its angles, at the forcing phase theta = atan2(s, c): O(1) per evaluation."""
    u = math.atan2(s, c) * _INV_TWO_PI * n  # in [-n/2, n/2]
    if u < 0.0:
        u += n
    j = int(u)
    f = u - j
    if j >= n:  # u == n after the wrap, by rounding
        j -= n
    j1 = j + 1
    if j1 == n:
        j1 = 0
    return PT[o + j, k] * (1.0 - f) + PT[o + j1, k] * f


@nb.njit(inline="always", **_JIT)
def rotate_power(n, s, c):
    """(cos, sin) of n theta from those of theta (n >= 0, by repeated squaring)."""
    rc, rs = 1.0, 0.0
    bc, bs = c, s
    while n > 0:
        if n & 1:
            rc, rs = harmonic_turn(rc, rs, bc, bs)
        bc, bs = bc * bc - bs * bs, 2.0 * bc * bs
        n >>= 1
    return rc, rs


@nb.njit(inline="always", **_JIT)
def contact_force(x, PT, k, s, c):
    """The flanks' elastic force f(x, theta) [N] (module docstring)."""
    b = PT[BACKLASH, k]
    if PT[FORM, k] != 0.0:  # the tables
        n = int(PT[N_TABLE, k])
        if x > b:
            row, deflection = KD0, x - b
        elif x < -b:
            row, deflection = KD0 + n, x + b
        else:
            return 0.0
        return flank_table(PT, k, row, n, s, c) * deflection
    n = int(PT[N_HARM, k])
    if x > b:
        row, deflection = KD0, x - b
    elif x < -b:
        row, deflection = KD0 + 1 + 2 * n, x + b
    else:
        return 0.0
    stiffness = flank_stiffness(PT, k, row, n, s, c)
    if stiffness < 0.0:  # the series' ringing below 0 where no pair is in contact (a gap)
        stiffness = 0.0
    return stiffness * deflection


@nb.njit(inline="always", **_JIT)
def damping_coefficient(PT, k):
    """c = 2 zeta sqrt(k_mean m) [N s/m]."""
    return 2.0 * PT[ZETA, k] * math.sqrt(PT[K_MEAN, k] * PT[MASS, k])


# The lane-scalar rhs and observables compiled once per argument types and inlined by LLVM
# where they are called (``forceinline``), not by numba's frontend, which would copy and type
# the flanks' series and table at every call site of the kernels (the RK4 stages of the split
# step, of the fused step loop and of the Lyapunov rows); without reference counting (they
# allocate nothing). The lane-scalar interface functions below are thin numba-inlined calls.
_JIT_ONCE = {**_JIT, "forceinline": True, "_nrt": False}


@nb.njit(**_JIT_ONCE)
def _rhs_lane_once(t, y, PT, k, s, c):
    x, v = y
    order = PT[MESH_ORDER, k]
    cn, sn = rotate_power(int(order), s, c)
    ce = cn * PT[COS_E, k] - sn * PT[SIN_E, k]
    wm = order * PT[OMEGA, k]
    m = PT[MASS, k]
    f = PT[TORQUE, k] / PT[R_B1, k] - damping_coefficient(PT, k) * v - contact_force(x, PT, k, s, c)
    return (v, f / m + PT[ERROR, k] * wm * wm * ce)


@nb.njit(**_JIT_ONCE)
def _observe_lane_once(t, y, PT, k, s, c):
    return (contact_force(y[0], PT, k, s, c) + damping_coefficient(PT, k) * y[1],)


@nb.njit(inline="always", **_JIT)
def spur_pair_rhs_lane(t, y, PT, k, s, c, form):
    return _rhs_lane_once(t, y, PT, k, s, c)


#: The state size of the lane-scalar forms.
spur_pair_rhs_lane_states = 2


@nb.njit(inline="always", **_JIT)
def spur_pair_rhs_lane_form(PT, k):
    return FORM_GENERAL


@nb.njit(inline="always", **_JIT)
def spur_pair_events_lane(t, y, PT, k, s, c):
    b = PT[BACKLASH, k]
    return (y[0] - b, y[0] + b)


@nb.njit(inline="always", **_JIT)
def spur_pair_observe_lane(t, y, PT, k, s, c, form):
    return _observe_lane_once(t, y, PT, k, s, c)


# the array interface, on the lane-scalar forms
@nb.njit(**_JIT)
def spur_pair_rhs(t, y, dy, p, s, c):
    v = spur_pair_rhs_lane(t, (y[0], y[1]), p[None, :].T, 0, s, c, FORM_GENERAL)
    dy[0] = v[0]
    dy[1] = v[1]


@nb.njit(**_JIT)
def spur_pair_events(t, y, g, p, s, c):
    v = spur_pair_events_lane(t, (y[0], y[1]), p[None, :].T, 0, s, c)
    g[0] = v[0]
    g[1] = v[1]


@nb.njit(**_JIT)
def spur_pair_observe(t, y, out, p, s, c):
    out[0] = spur_pair_observe_lane(t, (y[0], y[1]), p[None, :].T, 0, s, c, FORM_GENERAL)[0]


#: The model's compiled functions (the lane-scalar forms beside them, found by their names).
KERNEL = KernelSource(spur_pair_rhs, spur_pair_events, spur_pair_observe)
