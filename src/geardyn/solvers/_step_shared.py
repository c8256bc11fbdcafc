"""The parts of the step machinery that do not depend on the model, compiled once for every model.

The RK4 combination of a step's stages, the split step's constants, the forcing-phase table and
its rotations, the phase at a fraction of a grid step, the cubic Hermite weights, the cubic of an
edge function along a step and its extrema, the sides of the edges and the block screen that flags
a step, the events' scratch buffer, the statistics update of a grid point (:func:`stat_min`,
:func:`stat_max`, :func:`stat_square`) and the finite-difference tangent step's rows and their
read-back (:func:`fd_scale`, :func:`fd_size`, :func:`fd_rows`, :func:`fd_tangent`). A model's
generated core module (:mod:`._step_core`) imports them beside the functions that evaluate the
model (the split step, its root finders, the rows of a lane), which it compiles with the model's
functions inlined; the kernel templates and the sweep's and the Lyapunov kernels' bookkeeping
(:mod:`._sweep_books`, :mod:`._lyapunov_books`) import them from here too.

The helpers of the split path that it calls at many sites (the forcing phase at a fraction of
a step and its polynomials) are compiled once per argument types and
inlined by LLVM (``forceinline``, without reference counting: they allocate nothing), not copied
into every call site by numba's frontend; the arithmetic is the same (bitwise equal).
"""

from __future__ import annotations

import functools
import math

import numba as nb
import numpy as np

from geardyn._jit_target import WidthCompiler

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}
#: Options of a function that only compiled code calls (never Python): no Python or C entry
#: point is made for it (numba makes both for every function it compiles, a callee too). The
#: sweep's bookkeeping takes the block's tuples of ~60 arrays, whose unboxing wrapper cost more
#: compile time than the function (~0.25 s CPU each). A call from Python would find no entry
#: point. Not for a function compiled from another's ``py_func`` (the model's ``_rhs_i`` and
#: the like): numba's cache keys an entry by the Python function and signature, not the
#: options, so the other, called from Python, could load the entry without one.
INNER = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True}
#: Options of a function that Python calls but no compiled code takes as a C callback: no C
#: entry point is made for it (numba makes one for every function by default).
OUTER = {"no_cfunc_wrapper": True}
MAX_SPLITS = 16
SIMULTANEOUS = 1e-9
#: Rows of the events scratch buffer ``gbuf`` that :func:`_split_step` needs (events at the start,
#: at the root finder's point, located fractions, at two interior points of the step, and the
#: events that may graze: row GRAZE_ROW, set by the prefilters).
GBUF_ROWS = 6
GRAZE_ROW = 5
#: Prefilter of the sweep (history of grid values g_{i-1}, g_i, g_{i+1} of an edge function): a
#: step may graze the edge only if min(|g_i|, |g_{i+1}|) <= GRAZE_BOUND |g_{i+1} - 2 g_i +
#: g_{i-1}|. The dip of the parabola through the three values below min(g_i, g_{i+1}) is at most
#: an eighth of that second difference, so 1 leaves a margin of 8 for the cubic terms.
GRAZE_BOUND = 1.0
#: Prefilter of a lone step (no history): min(|g(t0)|, |g(t1)|) <= GRAZE_BOUND_STEP |a|,
#: a = h g'(t0) - (g(t1) - g(t0)), the quadratic part of g over the step; its dip is |a| / 4, that
#: of a cubic at most 4/27 (|a| + |b|) (b: the same at the end), so 0.6 admits |b| up to 3 |a|.
GRAZE_BOUND_STEP = 0.6
#: An interior extremum of an edge function counts as a crossing only beyond the edge by more than
#: this fraction of the function's size over the step (shallower dips are touching, not crossing).
GRAZE_TOL = 1e-9
#: Newton's method on an event's cubic along the step stops after a step (in the fraction of
#: the step) below this: the error left is about |P''/2P'| ROOT_TOL^2 (quadratic convergence);
#: the step cores of other revisions that ``bench/kernel.py`` builds (``old_kernels``) use it.
ROOT_TOL = 1e-8
#: Halley's method on an event's cubic along the step (the step core's ``_cubic_locate``) stops
#: after a step (in the fraction of the step) below this: the error left is about
#: |(P''/2P')^2 - P'''/6P'| HALLEY_TOL^3 (cubic convergence).
HALLEY_TOL = 1e-5
#: ... or, where it bisects, when the bracket is below this.
BRACKET_TOL = 1e-13
#: The root of the cubic is taken when the model's event there is within this fraction of the
#: step (in time) from its zero, by the cubic's slope; else the model's events refine it.
CONFIRM_TOL = 1e-9
#: Relative size of the finite-difference perturbation of the tangent steps (Lyapunov
#: exponents, monodromy matrices): e |v| = FD_DELTA (1 + min(|y / s|, FD_NORM_CAP)), in the
#: scaled coordinates z = y / s (s: the model's ``state_scale``).
FD_DELTA = 2.0**-20
#: Cap on |y / s| in the perturbation size (no built-in model's dimensionless state comes
#: near it, so for them it changes nothing).
FD_NORM_CAP = 2.0**10
#: Largest phase increment (radians) that :func:`_phase_at` takes from its polynomials.
SMALL_ANGLE = 0.8
STATUS_OK = 0
STATUS_DIVERGED = 1
#: Some grid steps reached the split limit (MAX_SPLITS) and fell back unsplit (the Lyapunov
#: kernels' lane status; the sweep counts them in ``unresolved_steps`` instead).
STATUS_SPLIT_LIMIT = 2


@nb.njit(inline="always", **_JIT)
def phase_increments(n_per):
    """The rotations of the forcing phase by half a grid step and by a whole one, for
    :func:`phase_rotate`: (alpha, beta) = (2 sin^2(d / 2), sin d) for d = pi / n_per, then for
    d = 2 pi / n_per."""
    a = math.pi / n_per
    sh = math.sin(0.5 * a)
    sd = math.sin(a)
    return 2.0 * sh * sh, sd, 2.0 * sd * sd, math.sin(2.0 * a)


@nb.njit(inline="always", **_JIT)
def phase_rotate(s, c, alpha, beta):
    """sin, cos of the phase theta + d from s = sin theta, c = cos theta and the increment's
    (alpha, beta) = (2 sin^2(d / 2), sin d) (:func:`phase_increments`). This form of the
    angle addition (cos d = 1 - alpha) rounds so that n rotations stay within a few ulp of the
    exact values (measured: 2.2e-15 over a period of 4096 steps, 3.6e-15 of 16384; the plain
    form s cos d + c sin d drifts to 1.3e-13 and 6.8e-13)."""
    return s - (alpha * s - beta * c), c - (alpha * c + beta * s)


@nb.njit(**_JIT, **OUTER)
def phase_table(n_per, forced):
    """sin and cos of the forcing phase at the 2 n_per + 1 half-step points of one period (the
    points pi k / n_per), by the rotations that the sweep's fused step loop applies to a
    slot's phase on the fly (:func:`phase_rotate`): from the grid point 2 p, the half step to
    2 p + 1 and the whole step to 2 p + 2; the period's end is exactly (0, 1). So every path
    that reads the table (the one-lane and block kernels, the Lyapunov and monodromy kernels)
    sees the phases of the fused loop, bitwise. Unforced: (0, 1) throughout."""
    s = np.zeros(2 * n_per + 1)
    c = np.zeros(2 * n_per + 1)
    c[:] = 1.0
    if forced:
        ah, bh, ad, bd = phase_increments(n_per)
        for p in range(n_per):
            s[2 * p + 1], c[2 * p + 1] = phase_rotate(s[2 * p], c[2 * p], ah, bh)
            if p < n_per - 1:
                s[2 * p + 2], c[2 * p + 2] = phase_rotate(s[2 * p], c[2 * p], ad, bd)
    return s, c


@functools.lru_cache(maxsize=64)
def phase_table_values(n_per: int, forced: bool) -> tuple[np.ndarray, np.ndarray]:
    """:func:`phase_table` computed by the interpreter (read-only arrays, kept per ``n_per``),
    for the orchestrating code: the same rotations in the same order of IEEE operations, so
    bitwise the compiled table. Python code does not call this module's compiled functions
    itself: their code is linked into every model's cached kernels, and their own entry from
    Python has read a wrong environment when cached copies compiled by other processes were
    loaded beside it (numba's "'descr' is NULL" SystemError)."""
    s = np.zeros(2 * n_per + 1)
    c = np.ones(2 * n_per + 1)
    if forced:
        ah, bh, ad, bd = phase_increments.py_func(n_per)
        rotate = phase_rotate.py_func
        for p in range(n_per):
            s[2 * p + 1], c[2 * p + 1] = rotate(s[2 * p], c[2 * p], ah, bh)
            if p < n_per - 1:
                s[2 * p + 2], c[2 * p + 2] = rotate(s[2 * p], c[2 * p], ad, bd)
    s.setflags(write=False)
    c.setflags(write=False)
    return s, c


@nb.njit(inline="always", **_JIT)
def rk4_sixth(h):
    """The weight h / 6 of the RK4 combination (:func:`rk4_comb`) of a step of size h."""
    return h / 6.0


@nb.njit(inline="always", **_JIT)
def rk4_update(y, h6, ksum):
    """The end of an RK4 step, one component: y + h6 ksum, ksum the stages' weighted sum
    k1 + 2 k2 + 2 k3 + k4 (summed left to right) and h6 = h / 6 (:func:`rk4_sixth`)."""
    return y + h6 * ksum


@nb.njit(inline="always", **_JIT)
def rk4_comb(y, h6, k1, k2, k3, k4):
    """The RK4 combination, one component: y + h6 (k1 + 2 k2 + 2 k3 + k4), summed left to right
    (((k1 + 2 k2) + 2 k3) + k4), h6 = h / 6 (:func:`rk4_sixth`). Every RK4 step of every
    kernel (rows, flat slot rows, lane tuples, tangent pairs) ends with it, so the order of the
    floating-point operations, and with it every result, is the same on every path. A step
    that sums its stages as they come (the split path's :func:`_rk4_stages`: one call site of
    the model for three stages) adds them in this order and ends with :func:`rk4_update`."""
    return rk4_update(y, h6, k1 + 2.0 * k2 + 2.0 * k3 + k4)


@nb.njit(**_JIT, **INNER)
def _pick(cond, a, b):
    """a if cond else b, a select (a call, inlined by LLVM: numba's inliner would leave the
    generated tuple helpers with phi variables it then warns about, and the fused loops take
    more instructions with the select inlined by numba)."""
    return a if cond else b


@nb.njit(inline="always", **_JIT)
def stat_min(lo, v, stat):
    """The statistics update of a running minimum lo by the value v at a grid point (the
    sweep's GMIN of an edge function, OMIN of an observable): min(lo, v) where ``stat``, else
    lo. With :func:`stat_max` and :func:`stat_square` every kernel's statistics update (the
    fused loop's generated ``_t_stats``, the block loop's, the out-of-line slot's): selects of
    values computed unconditionally (:func:`_pick`, no branch), so that the slot loops
    vectorise; one statement per statistic, each a load, the select and a store (the
    paper's fused sweep loop: 765 instructions so; 826 with numba's ``x if stat else y`` in
    place of ``_pick``, 789 with an element's statistics updated by one call, see
    ``bench/fused_loop.py --asm``)."""
    return _pick(stat, min(lo, v), lo)


@nb.njit(inline="always", **_JIT)
def stat_max(hi, v, stat):
    """The running maximum hi by v where ``stat`` (GMAX, OMAX; see :func:`stat_min`)."""
    return _pick(stat, max(hi, v), hi)


@nb.njit(inline="always", **_JIT)
def stat_square(sq, v, stat):
    """The running sum of squares sq by v where ``stat``: sq + v v (OSQ; see
    :func:`stat_min`)."""
    return _pick(stat, sq + v * v, sq)


@nb.njit(inline="always", **_JIT)
def fd_scale(ny):
    """The size e |v| of the finite-difference perturbation of every tangent step (Lyapunov
    rows, monodromy columns; one lane, row blocks or fused lanes) from ny = |y / s|^2 (the
    state in the scaled coordinates, summed from 0.0 in the order of the states):
    FD_DELTA (1 + min(|y / s|, FD_NORM_CAP))."""
    return FD_DELTA * (1.0 + min(math.sqrt(ny), FD_NORM_CAP))


@nb.njit(inline="always", **_JIT)
def fd_size(scale, vv):
    """(e, ok) of a tangent vector v with vv = |v|^2 (summed from 0.0 in the order of the
    states) and the perturbation size ``scale`` (:func:`fd_scale`): e = scale / |v|; a lost
    vector (|v| zero or not finite) gets e = NaN and ok False (its rows follow the state).
    The tangent helpers select by :func:`_pick`, as the statistics do (the fused Lyapunov
    loop: 2009 instructions so, 2018 with numba's ``x if ok else y``)."""
    nv = math.sqrt(vv)
    ok = (nv > 0.0) & math.isfinite(nv)
    return _pick(ok, scale / nv, np.nan), ok


@nb.njit(inline="always", **_JIT)
def fd_rows(z0, e, s, v, ok):
    """One state component of a tangent vector's two perturbed rows: z0 + e (s v) and
    z0 - e (s v) (s: the state's scale), z0 for both where not ``ok`` (:func:`fd_size`)."""
    d = e * (s * v)
    return _pick(ok, z0 + d, z0), _pick(ok, z0 - d, z0)


@nb.njit(inline="always", **_JIT)
def fd_tangent(ya, yb, e, inv_s):
    """One component of the stepped tangent vector from its rows' ends ya, yb (the rows of
    :func:`fd_rows` stepped): ((ya - yb) (0.5 / e)) / s, with inv_s = 1 / s; NaN where e is not
    finite (a lost vector)."""
    return _pick(math.isfinite(e), ((ya - yb) * (0.5 / e)) * inv_s, np.nan)


@nb.njit(inline="always", **_JIT)
def _side(x):
    return 1 if x > 0.0 else -1


@nb.njit(inline="always", **_JIT)
def _hermite_weights(dt, theta):
    """The cubic Hermite basis of a step of length dt at fraction theta: the weights of y0, f0,
    y1, f1."""
    t2 = theta * theta
    t3 = t2 * theta
    return (2.0 * t3 - 3.0 * t2 + 1.0, (t3 - 2.0 * t2 + theta) * dt, -2.0 * t3 + 3.0 * t2,
            (t3 - t2) * dt)


@nb.njit(inline="always", **_JIT)
def _forced(g0j, side_j):
    """The event at the start of a (sub-)step taken as on side side_j (a start a hair beyond
    the edge, just after a located crossing, counts as on it)."""
    return g0j if _side(g0j) == side_j else (1e-300 if side_j > 0 else 0.0)


@nb.njit(inline="always", **_JIT)
def _cubic_coeffs(v0, v1, v2, v3):
    """Power-basis coefficients (c0, c1, c2, c3) in theta of the cubic through (0, v0),
    (1/3, v1), (2/3, v2), (1, v3)."""
    d1 = v1 - v0
    d2 = v2 - 2.0 * v1 + v0
    d3 = v3 - 3.0 * v2 + 3.0 * v1 - v0
    return v0, 3.0 * d1 - 1.5 * d2 + d3, 4.5 * (d2 - d3), 4.5 * d3


@nb.njit(inline="always", **_JIT)
def _quadratic_roots(a, b, c):
    """Real roots r1 <= r2 of a s^2 + b s + c (NaN where there is none; r2 NaN for a linear
    equation), by the cancellation-free formula."""
    if a == 0.0:
        if b == 0.0:
            return np.nan, np.nan
        return -c / b, np.nan
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return np.nan, np.nan
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    if q == 0.0:
        return 0.0, 0.0
    r1 = q / a
    r2 = c / q
    return (r1, r2) if r1 <= r2 else (r2, r1)


@nb.njit(inline="always", **_JIT)
def _cubic_at(s, v0, d1, d2, d3):
    """Newton form of the cubic through 4 equally spaced values, at s (in spacings from v0)."""
    return v0 + s * (d1 + (s - 1.0) * (0.5 * d2 + (s - 2.0) / 6.0 * d3))


@nb.njit(**_JIT, **OUTER)
def cubic_extrema(v0, v1, v2, v3):
    """The cubic through (0, v0), (1/3, v1), (2/3, v2), (1, v3): its stationary points in (0, 1)
    and its values there, as (theta1, value1, theta2, value2), theta1 < theta2; NaN for a point
    that does not exist."""
    d1 = v1 - v0
    d2 = v2 - 2.0 * v1 + v0
    d3 = v3 - 3.0 * v2 + 3.0 * v1 - v0
    # dP/ds of P(s) = v0 + s d1 + s (s - 1) / 2 d2 + s (s - 1) (s - 2) / 6 d3, s = 3 theta
    r1, r2 = _quadratic_roots(0.5 * d3, d2 - d3, d1 - 0.5 * d2 + d3 / 3.0)
    if not 0.0 < r2 < 3.0:
        r2 = np.nan
    if not 0.0 < r1 < 3.0:
        r1, r2 = r2, np.nan
    return (r1 / 3.0, _cubic_at(r1, v0, d1, d2, d3), r2 / 3.0, _cubic_at(r2, v0, d1, d2, d3))


@nb.njit(**_JIT, **OUTER)
def event_buffer(nb_lanes, n_ev):
    """The events scratch buffer of a block of nb_lanes lanes: GBUF_ROWS rows for
    :func:`_split_step`, then two rows per lane for the grid values of the events at even and at
    odd grid points (:func:`_keep_start`; NaN: none yet)."""
    g = np.zeros((GBUF_ROWS + 2 * nb_lanes, max(n_ev, 1)))
    g[GBUF_ROWS:] = np.nan
    return g


@nb.njit(inline="always", **_JIT)
def _keep_start(i, nl, active, G, gbuf):
    """Before grid step i: keep the events at its start (G, rows 0..nl-1) in gbuf's history
    (an inactive lane's too: it takes no more steps)."""
    nb_lanes = (gbuf.shape[0] - GBUF_ROWS) // 2
    row = GBUF_ROWS + (i % 2) * nb_lanes
    for k in range(nl):
        for j in range(G.shape[1]):
            gbuf[row + k, j] = G[k, j]


@nb.njit(inline="always", **_JIT)
def screen_grid(g1, s, g0, gp, locate):
    """The edge screen of one event at a grid step with history, every kernel's (the one-lane
    :func:`_leaves_side`, the block's and the fused loop's): (graze, flagged) for the event g1 at
    the trial step's end, s its side at the start (+-1) and g0, gp its grid values at the start
    and one step before. The step leaves the side when sign(g1) != s; with ``locate`` it may graze
    the edge when min(|g0|, |g1|) <= GRAZE_BOUND |d2|, d2 = g1 - 2 g0 + gp, and, unless it left
    the side, d2 does not bend away from the edge (a dip across the edge bends towards it:
    curvature of the sign of the side). Branch-free, so that the slot loops vectorise."""
    d2 = g1 - 2.0 * g0 + gp
    crossed = (1.0 if g1 > 0.0 else -1.0) != s
    near = not min(abs(g0), abs(g1)) > GRAZE_BOUND * abs(d2)
    graze = locate & (crossed | (not s * d2 < 0.0)) & near
    return graze, crossed | graze


@nb.njit(inline="always", **_JIT)
def screen_lone(g1, s, g0, ge):
    """The edge screen of one event at a lone step without history (the one-lane
    :func:`_leaves_side_step`, the Lyapunov rows'): (graze, flagged) for the event g1 at the
    trial step's end, s its side at the start (+-1), g0 its value at the start and ge at the Euler
    point y + h f(t0, y). The step leaves the side when sign(g1) != s; it may graze the edge when
    min(|g0|, |g1|) <= GRAZE_BOUND_STEP |ge - g1| (ge - g1 = h g'(t0) - (g1 - g0), the quadratic
    part of the event over the step, exact for events linear in the state). Branch-free."""
    crossed = (1.0 if g1 > 0.0 else -1.0) != s
    graze = not min(abs(g0), abs(g1)) > GRAZE_BOUND_STEP * abs(ge - g1)
    return graze, crossed | graze


@nb.njit(inline="always", **_JIT)
def _leaves_side(i, k, G, SIDE, locate, gbuf):
    """Whether the trial grid step i of block row k may leave a side of an edge: 1 if its end
    (events G[k]) lies on another side than its start (SIDE[k]); with ``locate``, 2 if it may
    graze an edge, so that the step must be checked (:func:`_split_step`); else 0. Each event is
    screened by :func:`screen_grid` (graze flag in gbuf row GRAZE_ROW) from the grid values kept in
    gbuf's history (:func:`_keep_start`; none yet: it may graze). No evaluations of the model: the
    common step stays cheap."""
    out = 0
    nb_lanes = (gbuf.shape[0] - GBUF_ROWS) // 2
    r0 = GBUF_ROWS + (i % 2) * nb_lanes + k
    rp = GBUF_ROWS + ((i + 1) % 2) * nb_lanes + k
    for j in range(G.shape[1]):
        graze, flagged = screen_grid(G[k, j], SIDE[k, j], gbuf[r0, j], gbuf[rp, j], locate)
        gbuf[GRAZE_ROW, j] = 1.0 if graze else 0.0
        if graze:
            out = 2
        elif flagged:
            out = 1 if out == 0 else out
    return out


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _sincos_small(d):
    """sin d, cos d for |d| <= SMALL_ANGLE, no libm call: Taylor polynomials to d^9 and d^10
    for |d| <= 0.1, else to d^17 and d^18 (truncation below 1e-18 either way)."""
    d2 = d * d
    if abs(d) <= 0.1:
        sn = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0 + d2 * (
            1.0 / 362880.0)))))
        cs = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (
            1.0 / 40320.0 + d2 * (-1.0 / 3628800.0)))))
        return sn, cs
    sn = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0 + d2 * (
        1.0 / 362880.0 + d2 * (-1.0 / 39916800.0 + d2 * (1.0 / 6227020800.0 + d2 * (
            -1.0 / 1307674368000.0 + d2 * (1.0 / 355687428096000.0)))))))))
    cs = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0 + d2 * (
        -1.0 / 3628800.0 + d2 * (1.0 / 479001600.0 + d2 * (-1.0 / 87178291200.0 + d2 * (
            1.0 / 20922789888000.0 + d2 * (-1.0 / 6402373705728000.0)))))))))
    return sn, cs


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _phase_at(sa, ca, wh, i_mod, x):
    """sin and cos of the forcing phase wh (i_mod + x) at the fraction x in [0, 1] of grid step
    i_mod, from those at its start (sa, ca) by angle addition (libm only for long steps)."""
    d = wh * x
    if abs(d) <= SMALL_ANGLE:
        sd, cd = _sincos_small(d)
        return sa * cd + ca * sd, ca * cd - sa * sd
    a = wh * (i_mod + x)
    return math.sin(a), math.cos(a)


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _phase_in(pc, x):
    """sin and cos of the forcing phase at the fraction x of a (sub-)step of the split path:
    pc = (sa, ca, wh, i_mod, u, span), the sub-step from the fraction u of grid step i_mod
    (phase sa, ca at its start, wh = Omega h) over the fraction span of it (:func:`_phase_at`
    at u + x span: at x = 0, bitwise the phase the sub-step's rhs takes)."""
    sa, ca, wh, i_mod, u, span = pc
    return _phase_at(sa, ca, wh, i_mod, u + x * span)


#: The phase context (:func:`_phase_in`) of an unforced step: phase 0 throughout.
NO_PHASE = (0.0, 1.0, 0.0, 0, 0.0, 1.0)


@nb.njit(**_JIT, **OUTER)
def _healthy(y, bound):
    for q in range(y.size):
        v = y[q]
        if not (abs(v) <= bound):  # False for NaN too
            return False
    return True


BLOCK = 64
#: The fused loops run their slots in groups of this many (8 doubles: one AVX-512 register, two
#: AVX2 ones): a block's loop over nl slots is padded with idle slots to a multiple of it
#: (:func:`_padded`), so that LLVM's scalar remainder loop, which costs a slot about as much as
#: eight slots cost in the vector body, never runs (half the fused Lyapunov loop's time with
#: 42 lanes).
SIMD_SLOTS = 8


@nb.njit(inline="always", **_JIT)
def _padded(nl):
    """nl rounded up to a multiple of SIMD_SLOTS (at most BLOCK): the fused loops' trip count."""
    return min(BLOCK, (nl + SIMD_SLOTS - 1) // SIMD_SLOTS * SIMD_SLOTS)
