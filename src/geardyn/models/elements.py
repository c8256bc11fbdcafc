"""Physics shared by the models' compiled functions (numba, inlined where they are called)."""

from __future__ import annotations

import numba as nb

from geardyn._jit_target import WidthCompiler

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}


@nb.njit(inline="always", **_JIT)
def dead_zone(x, b):
    """The backlash dead zone g(x, b): x - b above b, x + b below -b, 0 between (branch-free;
    the same values as the branching form, 0 included)."""
    return x - min(max(x, -b), b)


@nb.njit(inline="always", **_JIT)
def harmonic_factor(p, f, nh, s, c):
    """1 + sum_{j=1..nh} p[f+2(j-1)] cos(j theta) + p[f+2(j-1)+1] sin(j theta): a relative mesh
    stiffness from its Fourier coefficients at row ``f`` of the coefficient vector ``p``, for
    the phase theta with sin ``s`` and cos ``c`` (harmonics by the angle-addition recurrence,
    no libm call); 1 for nh = 0. Clipped at 0: a series that rings below 0 where the mesh has
    no pair in contact (a missing tooth) carries no force there; a positive value is returned
    unchanged (bitwise)."""
    if nh == 0:
        return 1.0
    acc = p[f] * c + p[f + 1] * s
    ch = c
    sh = s
    for h in range(1, nh):
        ch, sh = ch * c - sh * s, sh * c + ch * s
        acc += p[f + 2 * h] * ch + p[f + 2 * h + 1] * sh
    v = 1.0 + acc
    return v if v > 0.0 else 0.0


@nb.njit(inline="always", **_JIT)
def harmonic_factor_lane(PT, k, f, nh, s, c):
    """:func:`harmonic_factor` of lane ``k`` of the lane-major coefficients ``PT`` (rows f..),
    the same operations in the same order (bitwise the same value)."""
    if nh == 0:
        return 1.0
    acc = PT[f, k] * c + PT[f + 1, k] * s
    ch = c
    sh = s
    for h in range(1, nh):
        ch, sh = ch * c - sh * s, sh * c + ch * s
        acc += PT[f + 2 * h, k] * ch + PT[f + 2 * h + 1, k] * sh
    v = 1.0 + acc
    return v if v > 0.0 else 0.0
