"""The step machinery every model shares, compiled once: the forcing-phase table, one RK4 step,
the cubic Hermite interpolant of a step, crossing location, a grid step split at the located edge
crossings, and the rows of a lane advanced together (the Lyapunov and monodromy kernels).

It does not depend on the model: the functions that evaluate the model take ``fn``, the
addresses of the model's ``rhs`` and ``events`` in array form (:mod:`.model_calls`), and call
them through those, so that numba compiles and caches this module once for every model. A
model's generated core module (:mod:`._step_core`) binds ``fn`` to its own functions.

Edge location: a step that leaves a side of an edge (a zero of ``events``) is split at the
crossing, located on the cubic Hermite interpolant of the step (error O(h^4) in the crossing
time: Newton's method on the event's cubic along it, :func:`_cubic_locate`, checked on the model's
event once), and integrated in sub-steps, so every RK4 stage sees a smooth
right-hand side and the method keeps 4th order. A step leaves a side when its end lies on the
other side, or when it grazes the edge: crosses it twice (or any even number of times) inside the
step. A graze is found from the interior extrema of the edge function along the interpolant
(:func:`first_crossing`); the first crossing of a step is always the one located. A step is split
at most ``MAX_SPLITS`` times (chattering); a step that reaches the limit falls back unsplit and is
counted (``unresolved_steps`` in every result). Crossings located within ``SIMULTANEOUS`` of a
step of the earliest are taken together (identical planet sets cross their edges at the same
instant).

Cost: the check of an ordinary step (:func:`_leaves_side`) is the sign test at the step's end
and a bound on the dip of each edge function from its last three grid values (no evaluation of
the model); only steps that can graze by that bound are redone (:func:`_split_step`). A split
costs about 9 evaluations of the model's rhs and 8 of its events (``bench/crossing.py``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers.model_calls import call_form

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False}
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
#: the step) below this: the error left is about |P''/2P'| ROOT_TOL^2 (quadratic convergence).
ROOT_TOL = 1e-8
#: ... or, where it bisects, when the bracket is below this.
BRACKET_TOL = 1e-13
#: The root of the cubic is taken when the model's event there is within this fraction of the
#: step (in time) from its zero, by the cubic's slope; else the model's events refine it.
CONFIRM_TOL = 1e-9
#: Largest phase increment (radians) that :func:`_phase_at` takes from its polynomials.
SMALL_ANGLE = 0.8
STATUS_OK = 0
STATUS_DIVERGED = 1
#: Some grid steps reached the split limit (MAX_SPLITS) and fell back unsplit (the Lyapunov
#: kernels' lane status; the sweep counts them in ``unresolved_steps`` instead).
STATUS_SPLIT_LIMIT = 2
#: The model's functions inlined (numba IR inlining) where a model's kernels call them in a loop.
_INLINE = {"inline": "always", "error_model": "numpy", "boundscheck": False}


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


@nb.njit(**_JIT)
def phase_table(n_per, forced):
    """sin and cos of the forcing phase at the 2 n_per + 1 half-step points of one period (the
    points pi k / n_per), by the rotations that the sweep's fused step loop applies to a
    slot's phase on the fly (:func:`phase_rotate`): from the grid point 2 p, the half step to
    2 p + 1 and the whole step to 2 p + 2; the period's end is exactly (0, 1). So every path
    that reads the table (the one-lane and block kernels, the Lyapunov and monodromy kernels)
    sees the phases of the fused loop, bitwise. Unforced: (0, 1) throughout."""
    s = np.zeros(2 * n_per + 1)
    c = np.ones(2 * n_per + 1)
    if forced:
        ah, bh, ad, bd = phase_increments(n_per)
        for p in range(n_per):
            s[2 * p + 1], c[2 * p + 1] = phase_rotate(s[2 * p], c[2 * p], ah, bh)
            if p < n_per - 1:
                s[2 * p + 2], c[2 * p + 2] = phase_rotate(s[2 * p], c[2 * p], ad, bd)
    return s, c


@nb.njit(inline="always", **_JIT)
def _side(x):
    return 1 if x > 0.0 else -1


@nb.njit(**_JIT)
def _rk4(fn, t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, k4, tmp, out, have_k1):
    """One RK4 step of size h from (t, y) into out; k1 holds f(t, y) if have_k1."""
    ns = y.size
    if not have_k1:
        call_form(fn[0], t, y, k1, p, s0, c0)
    hh = 0.5 * h
    for q in range(ns):
        tmp[q] = y[q] + hh * k1[q]
    call_form(fn[0], t + hh, tmp, k2, p, s1, c1)
    for q in range(ns):
        tmp[q] = y[q] + hh * k2[q]
    call_form(fn[0], t + hh, tmp, k3, p, s1, c1)
    for q in range(ns):
        tmp[q] = y[q] + h * k3[q]
    call_form(fn[0], t + h, tmp, k4, p, s2, c2)
    h6 = h / 6.0
    for q in range(ns):
        out[q] = y[q] + h6 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])


@nb.njit(inline="always", **_JIT)
def _hermite_weights(dt, theta):
    """The cubic Hermite basis of a step of length dt at fraction theta: the weights of y0, f0,
    y1, f1."""
    t2 = theta * theta
    t3 = t2 * theta
    return (2.0 * t3 - 3.0 * t2 + 1.0, (t3 - 2.0 * t2 + theta) * dt, -2.0 * t3 + 3.0 * t2,
            (t3 - t2) * dt)


@nb.njit(inline="always", **_JIT)
def _hermite(y0, f0, y1, f1, dt, theta, out):
    """Cubic Hermite interpolant of a step of length dt at fraction theta."""
    h00, h10, h01, h11 = _hermite_weights(dt, theta)
    for q in range(y0.size):
        out[q] = h00 * y0[q] + h10 * f0[q] + h01 * y1[q] + h11 * f1[q]


@nb.njit(**_JIT)
def _illinois(fn, j, side_j, a, fa, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, g, pc):
    """Illinois root finding of event j (the model's, on the step's interpolant) in the
    bracket [a, b]: fa on side side_j, fb off it. Returns the bracket's end off the side.
    pc: the step's forcing phase (:func:`_phase_in`)."""
    last = 0
    for _ in range(60):
        denom = fb - fa
        x = (a * fb - b * fa) / denom if denom != 0.0 else 0.5 * (a + b)
        if not (a < x < b):
            x = 0.5 * (a + b)
        _hermite(y0, f0, y1, f1, dt, x, ybuf)
        sx, cx = _phase_in(pc, x)
        call_form(fn[1], t + x * dt, ybuf, g, p, sx, cx)
        fx = g[j]
        if _side(fx) == side_j:
            a = x
            fa = fx
            if last == -1:
                fb *= 0.5
            last = -1
        else:
            b = x
            fb = fx
            if last == 1:
                fa *= 0.5
            last = 1
        if b - a < 1e-13:
            break
    return b


@nb.njit(inline="always", **_JIT)
def _forced(g0j, side_j):
    """The event at the start of a (sub-)step taken as on side side_j (a start a hair beyond
    the edge, just after a located crossing, counts as on it)."""
    return g0j if _side(g0j) == side_j else (1e-300 if side_j > 0 else 0.0)


@nb.njit(**_JIT)
def _locate(fn, j, side_j, g0j, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """Fraction in (0, b] of the step where event j leaves side side_j (Illinois method on the
    step's interpolant, the model's event evaluated at every iterate), given a bracket [0, b]
    that holds exactly one crossing: g0j the event at the start (taken as on side side_j), fb
    its value at b (on the other side). The split path uses :func:`_cubic_locate`; this is its
    fallback for events that are not affine in the state. pc: the step's forcing phase
    (:func:`_phase_in`)."""
    return _illinois(fn, j, side_j, 0.0, _forced(g0j, side_j), b, fb, y0, f0, y1, f1, dt, t, p,
                     ybuf, gbuf, pc)


@nb.njit(inline="always", **_JIT)
def _cubic_coeffs(v0, v1, v2, v3):
    """Power-basis coefficients (c0, c1, c2, c3) in theta of the cubic through (0, v0),
    (1/3, v1), (2/3, v2), (1, v3)."""
    d1 = v1 - v0
    d2 = v2 - 2.0 * v1 + v0
    d3 = v3 - 3.0 * v2 + 3.0 * v1 - v0
    return v0, 3.0 * d1 - 1.5 * d2 + d3, 4.5 * (d2 - d3), 4.5 * d3


@nb.njit(inline="always", **_JIT)
def _cubic_locate(fn, j, side_j, c0, c1, c2, c3, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, g, pc):
    """Fraction in (0, b] of the step where event j leaves side side_j, given the cubic
    c0 + c1 x + c2 x^2 + c3 x^3 of the event along the step's interpolant (exact for an event
    affine in time and state) and a bracket [0, b] that holds exactly one crossing (the start
    taken as on side side_j; fb: the model's event at b, off the side).

    Newton's method on the cubic, safeguarded by the bracket (no model evaluations), then one
    evaluation of the model's event at the root: it is taken when the event there is within
    CONFIRM_TOL of the step from its crossing (always, up to round-off, for affine events);
    otherwise the model's events take over (:func:`_illinois`, bracket narrowed)."""
    a = 0.0
    hi = b
    fa = _forced(c0, side_j)
    x = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * b
    if not (a < x < b):
        x = 0.5 * (a + b)
    for _ in range(60):
        px = ((c3 * x + c2) * x + c1) * x + c0
        if px == 0.0:
            break
        if _side(px) == side_j:
            a = x
        else:
            b = x
        dp = (3.0 * c3 * x + 2.0 * c2) * x + c1
        xn = x - px / dp if dp != 0.0 else 0.5 * (a + b)
        newton = a < xn < b
        if not newton:
            xn = 0.5 * (a + b)
        step = abs(xn - x)
        x = xn
        if (newton and step <= ROOT_TOL) or b - a <= BRACKET_TOL:
            break
    _hermite(y0, f0, y1, f1, dt, x, ybuf)
    sx, cx = _phase_in(pc, x)
    call_form(fn[1], t + x * dt, ybuf, g, p, sx, cx)
    gx = g[j]
    if abs(gx) <= CONFIRM_TOL * abs((3.0 * c3 * x + 2.0 * c2) * x + c1):
        return x
    if _side(gx) == side_j:
        return _illinois(fn, j, side_j, x, gx, hi, fb, y0, f0, y1, f1, dt, t, p, ybuf, g, pc)
    return _illinois(fn, j, side_j, 0.0, _forced(c0, side_j), x, gx, y0, f0, y1, f1, dt, t, p, ybuf,
                     g, pc)


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


@nb.njit(**_JIT)
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


@nb.njit(**_JIT)
def _beyond(fn, th, e, j, side_j, tol, y0, f0, y1, f1, dt, t, p, ybuf, g, pc):
    """The event j on the interpolant at th if the cubic's value e there and it both lie beyond
    the edge (off side side_j, by more than tol); else NaN. g: scratch row."""
    if not (th > 0.0 and side_j * e < 0.0 and abs(e) > tol):
        return np.nan
    _hermite(y0, f0, y1, f1, dt, th, ybuf)
    sx, cx = _phase_in(pc, th)
    call_form(fn[1], t + th * dt, ybuf, g, p, sx, cx)
    ge = g[j]
    return ge if _side(ge) != side_j and abs(ge) > tol else np.nan


@nb.njit(inline="always", **_JIT)
def _interpolant_events(fn, y0, f0, y1, f1, dt, t, p, ybuf, g0, g13, g23, pc):
    """:func:`interpolant_events` into the rows g0, g13, g23 (theta = 0, 1/3, 2/3)."""
    sx, cx = _phase_in(pc, 0.0)
    call_form(fn[1], t, y0, g0, p, sx, cx)
    _hermite(y0, f0, y1, f1, dt, 1.0 / 3.0, ybuf)
    sx, cx = _phase_in(pc, 1.0 / 3.0)
    call_form(fn[1], t + 1.0 / 3.0 * dt, ybuf, g13, p, sx, cx)
    _hermite(y0, f0, y1, f1, dt, 2.0 / 3.0, ybuf)
    sx, cx = _phase_in(pc, 2.0 / 3.0)
    call_form(fn[1], t + 2.0 / 3.0 * dt, ybuf, g23, p, sx, cx)


@nb.njit(**_JIT)
def interpolant_events(fn, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """The events along a step's cubic Hermite interpolant (start y0, end y1, derivatives f0, f1,
    length dt, from time t; forcing phase pc, see :func:`_phase_in`) at theta = 0, 1/3, 2/3
    into rows 0, 3, 4 of gbuf (GBUF_ROWS rows)."""
    _interpolant_events(fn, y0, f0, y1, f1, dt, t, p, ybuf, gbuf[0], gbuf[3], gbuf[4], pc)


@nb.njit(inline="always", **_JIT)
def _first_crossing(fn, j, side_j, graze, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, gsc, pc):
    """:func:`first_crossing`; without ``graze`` the end's side alone decides (one crossing at
    most: the caller's prefilter ruled a graze out)."""
    v0 = gbuf[0, j]
    v1 = gbuf[3, j]
    v2 = gbuf[4, j]
    b = 1.0
    gb = g1j
    if graze:
        tol = GRAZE_TOL * max(max(abs(v0), abs(v1)), max(abs(v2), abs(g1j)))
        th1, e1, th2, e2 = cubic_extrema(v0, v1, v2, g1j)
        b = th1
        gb = _beyond(fn, th1, e1, j, side_j, tol, y0, f0, y1, f1, dt, t, p, ybuf, gsc, pc)
        if gb != gb:
            b = th2
            gb = _beyond(fn, th2, e2, j, side_j, tol, y0, f0, y1, f1, dt, t, p, ybuf, gsc, pc)
        if gb != gb:
            b = 1.0
            gb = g1j
    if b == 1.0 and _side(g1j) == side_j:
        return 2.0
    c0, c1, c2, c3 = _cubic_coeffs(v0, v1, v2, g1j)
    return _cubic_locate(fn, j, side_j, c0, c1, c2, c3, b, gb, y0, f0, y1, f1, dt, t, p, ybuf, gsc,
                         pc)


@nb.njit(**_JIT)
def first_crossing(fn, j, side_j, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """Fraction in (0, 1] of the step where event j first leaves side side_j along the step's
    cubic Hermite interpolant, or 2.0 if it stays on its side. g1j: the event at the end; gbuf
    rows 0, 3, 4: the events at theta = 0, 1/3, 2/3 (:func:`interpolant_events`); row 1 is
    scratch.

    Along the interpolant an event that is affine in time and state is exactly the cubic
    through those four values (in general: to the interpolant's O(h^4)). An interior extremum
    of that cubic beyond the edge (by more than GRAZE_TOL of the event's size over the step),
    confirmed by the event on the interpolant there, has a crossing before it: the orbit grazes
    the edge (an even number of crossings in the step) or crosses it several times. Otherwise
    the end's side decides. The bracket [0, b] handed to the root finder ends at the first such
    extremum (or the end), so it holds exactly one crossing, the first; the root is found on
    the cubic (:func:`_cubic_locate`). pc: the step's forcing phase (:func:`_phase_in`)."""
    return _first_crossing(fn, j, side_j, True, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, gbuf[1],
                           pc)


@nb.njit(**_JIT)
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
def _leaves_side(i, k, G, SIDE, locate, gbuf):
    """Whether the trial grid step i of block row k may leave a side of an edge: 1 if its end
    (events G[k]) lies on another side than its start (SIDE[k]); with ``locate``, 2 if it may
    graze an edge, so that the step must be checked (:func:`_split_step`); else 0. An event may
    graze (flag in gbuf row GRAZE_ROW) when min(|g_i|, |g_{i+1}|) <= GRAZE_BOUND |d2|, d2 =
    g_{i+1} - 2 g_i + g_{i-1}, from the grid values kept in gbuf's history (:func:`_keep_start`;
    none yet: it may), and, unless the end crossed, d2 does not bend away from the edge. No
    evaluations of the model: the common step stays cheap."""
    out = 0
    nb_lanes = (gbuf.shape[0] - GBUF_ROWS) // 2
    r0 = GBUF_ROWS + (i % 2) * nb_lanes + k
    rp = GBUF_ROWS + ((i + 1) % 2) * nb_lanes + k
    for j in range(G.shape[1]):
        g1 = G[k, j]
        s = SIDE[k, j]
        crossed = _side(g1) != s
        graze = 0.0
        if locate:
            g0 = gbuf[r0, j]
            d2 = g1 - 2.0 * g0 + gbuf[rp, j]
            # a dip across the edge bends towards it (curvature of the sign of the side)
            if (crossed or not s * d2 < 0.0) and not min(abs(g0), abs(g1)) > GRAZE_BOUND * abs(d2):
                graze = 1.0
                out = 2
        gbuf[GRAZE_ROW, j] = graze
        if crossed:
            out = 1 if out == 0 else out
    return out


@nb.njit(inline="always", **_JIT)
def _leaves_side_step(fn, r, t0, t1, Y, K1, G0, G1, SIDE, p, ybuf, gbuf, s1, c1):
    """:func:`_leaves_side` for a lone step without history (row r: Y[r] at time t0 to the trial
    end at t1, K1[r] = f(t0, Y[r]), events G0[r], G1[r] at the ends, sides SIDE[r]): an event may
    graze when min(|g(t0)|, |g(t1)|) <= GRAZE_BOUND_STEP |a|, a = events(y + h f) - events(y1)
    = h g'(t0) - (g(t1) - g(t0)) (exact for events linear in the state); one evaluation of
    ``events`` (at the end's forcing phase s1, c1). ybuf, gbuf row 1: scratch."""
    h = t1 - t0
    for q in range(Y.shape[1]):
        ybuf[q] = Y[r, q] + h * K1[r, q]
    call_form(fn[1], t1, ybuf, gbuf[1], p, s1, c1)
    out = 0
    for j in range(G1.shape[1]):
        g1 = G1[r, j]
        if _side(g1) != SIDE[r, j]:
            out = 1
        graze = 0.0
        if not min(abs(G0[r, j]), abs(g1)) > GRAZE_BOUND_STEP * abs(gbuf[1, j] - g1):
            graze = 1.0
            out = max(out, 2)
        gbuf[GRAZE_ROW, j] = graze
    return out


@nb.njit(inline="always", **_JIT)
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


@nb.njit(inline="always", **_JIT)
def _phase_at(sa, ca, wh, i_mod, x):
    """sin and cos of the forcing phase wh (i_mod + x) at the fraction x in [0, 1] of grid step
    i_mod, from those at its start (sa, ca) by angle addition (libm only for long steps)."""
    d = wh * x
    if abs(d) <= SMALL_ANGLE:
        sd, cd = _sincos_small(d)
        return sa * cd + ca * sd, ca * cd - sa * sd
    a = wh * (i_mod + x)
    return math.sin(a), math.cos(a)


@nb.njit(inline="always", **_JIT)
def _phase_in(pc, x):
    """sin and cos of the forcing phase at the fraction x of a (sub-)step of the split path:
    pc = (sa, ca, wh, i_mod, u, span), the sub-step from the fraction u of grid step i_mod
    (phase sa, ca at its start, wh = Omega h) over the fraction span of it (:func:`_phase_at`
    at u + x span: at x = 0, bitwise the phase the sub-step's rhs takes)."""
    sa, ca, wh, i_mod, u, span = pc
    return _phase_at(sa, ca, wh, i_mod, u + x * span)


#: The phase context (:func:`_phase_in`) of an unforced step: phase 0 throughout.
NO_PHASE = (0.0, 1.0, 0.0, 0, 0.0, 1.0)


@nb.njit(inline="always", **_JIT)
def _rk4_stages(fn, t, y, h, p, s1, c1, s2, c2, k1, kst, acc, tmp, out):
    """:func:`_rk4` with k1 given, one call site of the model's rhs for the three stages (each
    stage's k in kst, their weighted sum in acc), the same arithmetic."""
    ns = y.size
    hh = 0.5 * h
    for q in range(ns):
        acc[q] = k1[q]
        tmp[q] = y[q] + hh * k1[q]
    for st in range(1, 4):
        if st > 1:
            a = h if st == 3 else hh
            for q in range(ns):
                tmp[q] = y[q] + a * kst[q]
        ts = t + hh
        ss = s1
        cc = c1
        if st == 3:
            ts = t + h
            ss = s2
            cc = c2
        call_form(fn[0], ts, tmp, kst, p, ss, cc)
        if st == 3:
            for q in range(ns):
                acc[q] = acc[q] + kst[q]
        else:
            for q in range(ns):
                acc[q] = acc[q] + 2.0 * kst[q]
    h6 = h / 6.0
    for q in range(ns):
        out[q] = y[q] + h6 * acc[q]


@nb.njit(inline="always", **_JIT)
def _split_rhs(fn, t, y, out, p, s, c):
    """The model's rhs f(t, y) into out, on the split path."""
    call_form(fn[0], t, y, out, p, s, c)


@nb.njit(inline="always", **_JIT)
def _split_copy(dst, src):
    """dst[:] = src, on the split path."""
    for q in range(src.size):
        dst[q] = src[q]


@nb.njit(_nrt=False, **_JIT)  # it allocates nothing: no reference counting of its views
def _split_step(fn, i, t0, y, y_trial, p, h, omega, n_per, sa, ca, s_end, c_end, side, g1, ncross,
                work, ybuf, gbuf):
    """Finish grid step i of one lane with edge crossings located; y holds the start, and
    y_trial/g1 the unsplit trial step; gbuf has GBUF_ROWS rows, row GRAZE_ROW flagging the
    events that may graze (set by the caller's prefilter: those get :func:`first_crossing`,
    the others a crossing only where the end's side differs). Returns 1 if the split limit was
    reached, else 0.

    Per (sub-)step to check: f at its start (the RK4's k1) and end, the events at 0, 1/3, 2/3
    of the step's interpolant, the first crossing on the cubic of each event
    (:func:`_cubic_locate`: no model evaluations but one per located event), then RK4 to the
    crossing (k1 reused) and from there to the grid point; after that last sub-step only the
    end's side is tested unless an event may graze. The forcing phase at the fractional points
    comes from that at the grid point by angle addition. The model's rhs and events are called
    through ``fn`` (:mod:`.model_calls`).
    sa, ca and s_end, c_end: sin and cos of the forcing phase at the step's start and end,
    the caller's phase-table values (:func:`phase_table`), so a split sees the phases of the
    unsplit step, bitwise, and calls no libm for them. work: 7 rows of the
    state's size."""
    n_ev = g1.size
    ns = y.size
    k1 = work[0]
    kst = work[1]
    acc = work[2]
    tmp = work[4]
    f1 = work[5]
    ystart = work[6]
    g0 = gbuf[0]
    gsc = gbuf[1]
    g13 = gbuf[3]
    g23 = gbuf[4]
    u = 0.0  # fraction of the grid step done
    i_mod = i % n_per
    wh = omega * h
    t_end = t0 + (i + 1) * h
    s0 = sa
    c0 = ca
    for _ in range(MAX_SPLITS):
        t = t0 + (i + u) * h
        dt = (1.0 - u) * h
        _split_rhs(fn, t, y, k1, p, s0, c0)
        graze = False
        need = False
        for j in range(n_ev):
            flag = gbuf[GRAZE_ROW, j] != 0.0
            graze = graze or flag
            need = need or flag or _side(g1[j]) != side[j]
        if u > 0.0:
            sm, cm = _phase_at(sa, ca, wh, i_mod, 0.5 * (1.0 + u))
            _rk4_stages(fn, t, y, dt, p, sm, cm, s_end, c_end, k1, kst, acc, tmp, y_trial)
            call_form(fn[1], t_end, y_trial, g1, p, s_end, c_end)
            need = graze
            for j in range(n_ev):
                need = need or _side(g1[j]) != side[j]
        if not need:
            _split_copy(y, y_trial)
            return 0
        _split_rhs(fn, t_end, y_trial, f1, p, s_end, c_end)
        _split_copy(ystart, y)
        pc = (sa, ca, wh, i_mod, u, 1.0 - u)
        _interpolant_events(fn, ystart, k1, y_trial, f1, dt, t, p, ybuf, g0, g13, g23, pc)
        first = -1
        theta = 2.0
        for j in range(n_ev):
            flag = gbuf[GRAZE_ROW, j] != 0.0
            if flag or _side(g1[j]) != side[j]:
                th = _first_crossing(fn, j, side[j], flag, g1[j], ystart, k1, y_trial, f1, dt, t,
                                     p, ybuf, gbuf, gsc, pc)
            else:
                th = 2.0
            gbuf[2, j] = th
            if th < theta:
                theta = th
                first = j
        if first < 0:
            _split_copy(y, y_trial)
            return 0
        tm = u + 0.5 * theta * (1.0 - u)
        tu = u + theta * (1.0 - u)
        sm, cm = _phase_at(sa, ca, wh, i_mod, tm)
        s0, c0 = _phase_at(sa, ca, wh, i_mod, tu)
        _rk4_stages(fn, t, ystart, theta * dt, p, sm, cm, s0, c0, k1, kst, acc, tmp, y)
        for j in range(n_ev):
            if gbuf[2, j] <= theta + SIMULTANEOUS:
                side[j] = -side[j]
                ncross[j] += 1
        u = tu
        if u >= 1.0:
            call_form(fn[1], t_end, y, g1, p, s_end, c_end)
            return 0
    for q in range(ns):
        y[q] = y_trial[q]
    for j in range(n_ev):
        side[j] = _side(g1[j])
    return 1


@nb.njit(**_JIT)
def _healthy(y, bound):
    for q in range(y.size):
        v = y[q]
        if not (abs(v) <= bound):  # False for NaN too
            return False
    return True


@nb.njit(**_JIT)
def _rows_step(fn, i, t0, Y, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0, G1, W,
               gbuf, NCR, UNRES):
    """Advance every row of Y (independent states of one lane, e.g. a state and its
    finite-difference neighbours) by grid step i (time t0 + i h to t0 + (i + 1) h, forcing
    phase from the table s_tab, c_tab at i mod n_per): one RK4 step per row, the rows' stages
    interleaved; a row whose trial step may leave a side of an edge (:func:`_leaves_side_step`)
    is redone with the crossings located (:func:`_split_step`). Row r's crossings are counted
    in NCR[r], its steps that reached the split limit in UNRES[r]. Scratch: K[4, nr, ns], TMP,
    Y1 like Y, SIDE, G0, G1 [nr, max(n_ev, 1)], W[9, ns], gbuf[GBUF_ROWS, max(n_ev, 1)]."""
    nr, ns = Y.shape
    t = t0 + i * h
    hh = 0.5 * h
    j0 = 2 * (i % n_per)
    if n_ev > 0:
        for r in range(nr):
            call_form(fn[1], t, Y[r], G0[r], p, s_tab[j0], c_tab[j0])
            for j in range(n_ev):
                SIDE[r, j] = _side(G0[r, j])
    for st in range(4):
        if st == 0:
            ts = t
            jj = j0
        elif st < 3:
            ts = t + hh
            jj = j0 + 1
        else:
            ts = t + h
            jj = j0 + 2
        a = h if st == 3 else hh
        for r in range(nr):
            if st > 0:
                for q in range(ns):
                    TMP[r, q] = Y[r, q] + a * K[st - 1, r, q]
            call_form(fn[0], ts, Y[r] if st == 0 else TMP[r], K[st, r], p, s_tab[jj], c_tab[jj])
    h6 = h / 6.0
    for r in range(nr):
        for q in range(ns):
            Y1[r, q] = Y[r, q] + h6 * (K[0, r, q] + 2.0 * K[1, r, q] + 2.0 * K[2, r, q]
                                       + K[3, r, q])
    for r in range(nr):
        crossed = 0
        if n_ev > 0:
            call_form(fn[1], t + h, Y1[r], G1[r], p, s_tab[j0 + 2], c_tab[j0 + 2])
            crossed = _leaves_side_step(fn, r, t, t + h, Y, K[0], G0, G1, SIDE, p, W[8], gbuf,
                                        s_tab[j0 + 2], c_tab[j0 + 2])
        if crossed:
            UNRES[r] += _split_step(fn, i, t0, Y[r], Y1[r], p, h, omega, n_per, s_tab[j0],
                                    c_tab[j0], s_tab[j0 + 2], c_tab[j0 + 2], SIDE[r], G1[r],
                                    NCR[r], W, W[8], gbuf)
        else:
            for q in range(ns):
                Y[r, q] = Y1[r, q]


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
