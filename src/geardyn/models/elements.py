"""Physics shared by the models' compiled functions (numba, inlined where they are called)."""

from __future__ import annotations

import numba as nb
from numba.core import errors, types
from numba.extending import overload

from geardyn._jit_target import WidthCompiler

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}


@nb.njit(inline="always", **_JIT)
def dead_zone(x, b):
    """The backlash dead zone g(x, b): x - b above b, x + b below -b, 0 between (branch-free;
    the same values as the branching form, 0 included)."""
    return x - min(max(x, -b), b)


@nb.njit(inline="always", **_JIT)
def harmonic_turn(ch, sh, c, s):
    """(cos, sin) of (h + 1) theta from those of h theta (``ch``, ``sh``) and of theta (``c``,
    ``s``) by angle addition: the one recurrence of every stiffness series (no libm call)."""
    return ch * c - sh * s, sh * c + ch * s


@nb.njit(inline="always", **_JIT)
def harmonic_clip(v):
    """A series' value ``v`` (1 + its harmonic sum) clipped at 0: a series that rings below 0
    where the mesh has no pair in contact (a missing tooth) carries no force there; a positive
    value is returned unchanged (bitwise)."""
    return v if v > 0.0 else 0.0


@nb.njit(inline="always", **_JIT)
def harmonic_series(at, a, k, f, nh, s, c):
    """1 + sum_{j=1..nh} a_j cos(j theta) + b_j sin(j theta), clipped at 0
    (:func:`harmonic_clip`), for the phase theta with sin ``s`` and cos ``c``; 1 for nh = 0.
    The coefficients a_1, b_1, .., a_nh, b_nh are ``at(a, k, f)``, ``at(a, k, f + 1)``, ..
    (``at`` an inlined getter: :func:`harmonic_factor`'s 1-D vector, :func:`harmonic_factor_lane`'s
    lane column); the harmonics by :func:`harmonic_turn`."""
    if nh == 0:
        return 1.0
    acc = at(a, k, f) * c + at(a, k, f + 1) * s
    ch = c
    sh = s
    for h in range(1, nh):
        ch, sh = harmonic_turn(ch, sh, c, s)
        acc += at(a, k, f + 2 * h) * ch + at(a, k, f + 2 * h + 1) * sh
    return harmonic_clip(1.0 + acc)


@nb.njit(inline="always", **_JIT)
def _entry(p, k, i):
    """p[i] (``k`` unused): :func:`harmonic_series`' getter of a 1-D coefficient vector."""
    return p[i]


@nb.njit(inline="always", **_JIT)
def _lane_entry(PT, k, i):
    """PT[i, k]: :func:`harmonic_series`' getter of lane ``k`` of lane-major coefficients."""
    return PT[i, k]


@nb.njit(inline="always", **_JIT)
def harmonic_factor(p, f, nh, s, c):
    """1 + sum_{j=1..nh} p[f+2(j-1)] cos(j theta) + p[f+2(j-1)+1] sin(j theta): a relative mesh
    stiffness from its Fourier coefficients at row ``f`` of the coefficient vector ``p``, for
    the phase theta with sin ``s`` and cos ``c``, clipped at 0 (:func:`harmonic_series`)."""
    return harmonic_series(_entry, p, 0, f, nh, s, c)


@nb.njit(inline="always", **_JIT)
def harmonic_factor_lane(PT, k, f, nh, s, c):
    """:func:`harmonic_factor` of lane ``k`` of the lane-major coefficients ``PT`` (rows f..),
    the same operations in the same order (bitwise the same value)."""
    return harmonic_series(_lane_entry, PT, k, f, nh, s, c)


def harmonic_factors(h, n_meshes, s, c):
    """The relative stiffness of each of ``n_meshes`` meshes, as :func:`harmonic_factor` gives
    it, from the tuple ``h`` of their Fourier coefficients one mesh after the other (a1, b1,
    .., a_nh, b_nh of the first, then of the next): a tuple of ``n_meshes`` values (clipped at
    0), for the phase with sin ``s`` and cos ``c``. In compiled code only (a one-form model's
    functions, ``h`` a static slice of its coefficients, ``n_meshes`` a constant): the number
    of harmonics follows from the tuple's length, and the series is written out term by term
    (the same operations in the same order as :func:`harmonic_factor`, so the same bits; the
    harmonics' cos and sin by one :func:`harmonic_turn` for every mesh, each sum clipped by
    :func:`harmonic_clip`), with no loop and no libm call, so that a lane loop over it
    vectorises."""
    raise NotImplementedError("harmonic_factors is compiled code's (numba) only")


@overload(harmonic_factors, inline="always")
def _harmonic_factors(h, n_meshes, s, c):
    if not isinstance(n_meshes, types.IntegerLiteral):
        raise errors.TypingError("harmonic_factors: n_meshes must be a constant")
    m = n_meshes.literal_value
    if not isinstance(h, types.BaseTuple) or m < 1 or len(h) % (2 * m):
        raise errors.TypingError(f"harmonic_factors: a tuple of 2 nh coefficients per mesh "
                                 f"for {m} meshes (got {h})")
    nh = len(h) // (2 * m)
    lines = ["def impl(h, n_meshes, s, c):"]
    if nh == 0:
        lines.append(f"    return {(1.0,) * m!r}")
    else:
        lines += [f"    a{j} = h[{2 * nh * j}] * c + h[{2 * nh * j + 1}] * s" for j in range(m)]
        lines += ["    ch = c", "    sh = s"]
        for q in range(1, nh):
            lines.append("    ch, sh = harmonic_turn(ch, sh, c, s)")
            lines += [f"    a{j} += h[{2 * nh * j + 2 * q}] * ch + h[{2 * nh * j + 2 * q + 1}] * sh"
                      for j in range(m)]
        lines += [f"    v{j} = 1.0 + a{j}" for j in range(m)]
        lines.append("    return (" + "".join(f"harmonic_clip(v{j}), " for j in range(m)) + ")")
    env: dict = {"harmonic_turn": harmonic_turn, "harmonic_clip": harmonic_clip}
    exec(compile("\n".join(lines) + "\n", "<harmonic_factors>", "exec"), env)
    return env["impl"]
