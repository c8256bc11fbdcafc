"""The scalar step machinery shared by the kernel templates: the forcing-phase table, one RK4
step, the cubic Hermite interpolant of a step, crossing location, and a grid step split at the
located edge crossings.

Like the templates, this is template text: :func:`geardyn.solvers.kernels.kernels_for` splices it
into a generated kernel module in place of the template's ``CORE-IMPORT`` line, bound there to the
model's ``rhs`` and ``events``. As it stands it is a valid module bound to the test oscillator of
:mod:`geardyn.solvers._template_model`. What does not evaluate the model (constants, the
phase table, the cubic of an edge function, the block screen) is in :mod:`._step_shared`,
compiled once for every model, and imported here.

Edge location: a step that leaves a side of an edge (a zero of ``events``) is split at the
crossing and integrated in sub-steps, so every RK4 stage sees a smooth right-hand side and
the method keeps 4th order. The crossing is located on the cubic Hermite interpolant of the
trial step by Halley's method on the event's cubic along it (:func:`_cubic_locate`), checked
on the model's event once; the trial step straddled the edge, so the point found lies O(h^3)
off it (the right-hand side is continuous there). A step leaves a side when its end lies on the
other side, or when it grazes the edge: crosses it twice (or any even number of times) inside the
step. A graze is found from the interior extrema of the edge function along the interpolant
(:func:`_first_crossing`); the first crossing of a step is always the one located. A step is split
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

import numba as nb
import numpy as np

from geardyn._jit_target import WidthCompiler
from geardyn.core.kernel_source import FORM_GENERAL
from geardyn.solvers._step_shared import (
    BLOCK,
    BRACKET_TOL,
    CONFIRM_TOL,
    GRAZE_ROW,
    GRAZE_TOL,
    HALLEY_TOL,
    INNER,
    MAX_SPLITS,
    OUTER,
    SIMULTANEOUS,
    _cubic_coeffs,
    _forced,
    _hermite_weights,
    _phase_at,
    _phase_in,
    _pick,
    _side,
    cubic_extrema,
    fd_rows,
    fd_scale,
    fd_size,
    fd_tangent,
    rk4_comb,
    rk4_sixth,
    rk4_update,
    screen_grid,
    screen_lone,
    stat_max,
    stat_min,
    stat_square,
)
from geardyn.solvers._template_model import events, rhs  # MODEL-IMPORT

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}
# MODEL-ADAPTERS (a user's plain functions are adapted to the kernel interface here)
# The model's functions where they are called in a loop: compiled once (per argument types) and
# inlined by LLVM at every call site (``forceinline``; a call with array arguments would cost
# reference counting on every stage of every step), not by numba's frontend, which would copy
# and type the model's IR anew at each call site (the bulk of a big model's compile).
# Without reference counting, as inlined into the split step (``_nrt=False``; a model's
# functions allocate nothing).
_rhs_i = nb.njit(forceinline=True, _nrt=False, **_JIT)(rhs.py_func)
_events_i = nb.njit(forceinline=True, _nrt=False, **_JIT)(events.py_func)
# The split path (a step with a located crossing: :func:`_split_step`, :func:`_rk4_stages` and
# the root finders) inlines them too; a model with lane-scalar functions takes those there
# instead, the state in registers (see :func:`_split_rhs` and the FUSED block below).
# The split path's helpers that it calls at several sites (the interpolant and its events, the
# first crossing, the RK4 sub-step, the rhs and copies of the split path) are compiled the same
# way, so that numba types each once per argument types, not once per call site in each split
# step (the plain one and the Lyapunov kernel's variational one); LLVM inlines them, the same
# arithmetic (bitwise equal).


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _hermite(y0, f0, y1, f1, dt, theta, out):
    """Cubic Hermite interpolant of a step of length dt at fraction theta."""
    h00, h10, h01, h11 = _hermite_weights(dt, theta)
    for q in range(y0.size):
        out[q] = h00 * y0[q] + h10 * f0[q] + h01 * y1[q] + h11 * f1[q]


@nb.njit(**_JIT, **INNER)
def _illinois(j, side_j, a, fa, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, g, pc):
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
        _events_i(t + x * dt, ybuf, g, p, sx, cx)
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
def _inverse_cubic(v0, v1, v2, v3):
    """The zero of the inverse cubic interpolant through (v0, 0), (v1, 1/3), (v2, 2/3), (v3, 1)
    (Lagrange's form): an estimate of where along the step the cubic through the four equally
    spaced values vanishes, exact where the fraction is a cubic in the value; not finite where
    two values coincide, and of no meaning where they are not monotone (the caller keeps it
    only inside the third of the step where the sign changes)."""
    return -((v0 * v2 * v3) / (3.0 * ((v1 - v0) * (v1 - v2) * (v1 - v3)))
             + (2.0 * (v0 * v1 * v3)) / (3.0 * ((v2 - v0) * (v2 - v1) * (v2 - v3)))
             + (v0 * v1 * v2) / ((v3 - v0) * (v3 - v1) * (v3 - v2)))


@nb.njit(inline="always", **_JIT)
def _cubic_locate(j, side_j, c0, c1, c2, c3, b, fb, v1, v2, y0, f0, y1, f1, dt, t, p, ybuf, g,
                  pc):
    """Fraction in (0, b] of the step where event j leaves side side_j, given the cubic
    c0 + c1 x + c2 x^2 + c3 x^3 of the event along the step's interpolant (exact for an event
    affine in time and state) and a bracket [0, b] that holds exactly one crossing (the start
    taken as on side side_j; fb: the model's event at b, off the side); v1, v2: the event at
    1/3 and 2/3 of the step.

    Halley's method on the cubic, safeguarded by the bracket (no model evaluations), from the
    inverse cubic interpolation of the four values (:func:`_inverse_cubic`) where it falls in the
    third of the step where the sign changes, else from the secant of that third (of [0, b]
    where b < 1); then one evaluation of the model's event at the root: it is taken when the
    event there is within CONFIRM_TOL of the step from its crossing (always, up to round-off,
    for affine events); otherwise the model's events take over (:func:`_illinois`, bracket
    narrowed)."""
    a = 0.0
    hi = b
    fa = _forced(c0, side_j)
    lo = a
    flo = fa
    up = b
    fup = fb
    if b == 1.0:  # (selects, no branches: where the sign changes is unpredictable)
        o1 = _side(v1) != side_j
        o2 = _side(v2) != side_j
        lo = 0.0 if o1 else (1.0 / 3.0 if o2 else 2.0 / 3.0)
        flo = fa if o1 else (v1 if o2 else v2)
        up = 1.0 / 3.0 if o1 else (2.0 / 3.0 if o2 else 1.0)
        fup = v1 if o1 else (v2 if o2 else fb)
    x = (lo * fup - up * flo) / (fup - flo) if fup != flo else 0.5 * (lo + up)
    if b == 1.0:
        xi = _inverse_cubic(fa, v1, v2, fb)
        x = xi if lo < xi < up else x
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
        d2 = 6.0 * c3 * x + 2.0 * c2
        den = 2.0 * dp * dp - px * d2
        xn = x - 2.0 * px * dp / den if den != 0.0 else 0.5 * (a + b)
        halley = a < xn < b
        if not halley:
            xn = 0.5 * (a + b)
        step = abs(xn - x)
        x = xn
        if (halley and step <= HALLEY_TOL) or b - a <= BRACKET_TOL:
            break
    _hermite(y0, f0, y1, f1, dt, x, ybuf)
    sx, cx = _phase_in(pc, x)
    _events_i(t + x * dt, ybuf, g, p, sx, cx)
    gx = g[j]
    if abs(gx) <= CONFIRM_TOL * abs((3.0 * c3 * x + 2.0 * c2) * x + c1):
        return x
    if _side(gx) == side_j:
        return _illinois(j, side_j, x, gx, hi, fb, y0, f0, y1, f1, dt, t, p, ybuf, g, pc)
    return _illinois(j, side_j, 0.0, _forced(c0, side_j), x, gx, y0, f0, y1, f1, dt, t, p, ybuf,
                     g, pc)


@nb.njit(**_JIT, **INNER)
def _beyond(th, e, j, side_j, tol, y0, f0, y1, f1, dt, t, p, ybuf, g, pc):
    """The event j on the interpolant at th if the cubic's value e there and it both lie beyond
    the edge (off side side_j, by more than tol); else NaN. g: scratch row."""
    if not (th > 0.0 and side_j * e < 0.0 and abs(e) > tol):
        return np.nan
    _hermite(y0, f0, y1, f1, dt, th, ybuf)
    sx, cx = _phase_in(pc, th)
    _events_i(t + th * dt, ybuf, g, p, sx, cx)
    ge = g[j]
    return ge if _side(ge) != side_j and abs(ge) > tol else np.nan


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _interpolant_events(y0, f0, y1, f1, dt, t, p, ybuf, g0, g13, g23, pc):
    """The events along a step's cubic Hermite interpolant (start y0, end y1, derivatives f0, f1,
    length dt, from time t; forcing phase pc, see :func:`_phase_in`) at theta = 0, 1/3, 2/3
    into the rows g0, g13, g23."""
    sx, cx = _phase_in(pc, 0.0)
    _events_i(t, y0, g0, p, sx, cx)
    _hermite(y0, f0, y1, f1, dt, 1.0 / 3.0, ybuf)
    sx, cx = _phase_in(pc, 1.0 / 3.0)
    _events_i(t + 1.0 / 3.0 * dt, ybuf, g13, p, sx, cx)
    _hermite(y0, f0, y1, f1, dt, 2.0 / 3.0, ybuf)
    sx, cx = _phase_in(pc, 2.0 / 3.0)
    _events_i(t + 2.0 / 3.0 * dt, ybuf, g23, p, sx, cx)


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _first_crossing(j, side_j, graze, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, gsc, pc):
    """Fraction in (0, 1] of the step where event j first leaves side side_j along the step's
    cubic Hermite interpolant, or 2.0 if it stays on its side. g1j: the event at the end; gbuf
    rows 0, 3, 4: the events at theta = 0, 1/3, 2/3 (:func:`_interpolant_events`); gsc: a
    scratch row.

    Along the interpolant an event that is affine in time and state is exactly the cubic
    through those four values (in general: to the interpolant's error). With ``graze``, an
    interior extremum of that cubic beyond the edge (by more than GRAZE_TOL of the event's size
    over the step), confirmed by the event on the interpolant there, has a crossing before it:
    the orbit grazes the edge (an even number of crossings in the step) or crosses it several
    times. Otherwise (and without ``graze``: the caller's prefilter ruled a graze out) the
    end's side decides. The bracket [0, b] handed to the root finder ends at the first such
    extremum (or the end), so it holds exactly one crossing, the first; the root is found on
    the cubic (:func:`_cubic_locate`). pc: the step's forcing phase (:func:`_phase_in`)."""
    v0 = gbuf[0, j]
    v1 = gbuf[3, j]
    v2 = gbuf[4, j]
    b = 1.0
    gb = g1j
    if graze:
        tol = GRAZE_TOL * max(max(abs(v0), abs(v1)), max(abs(v2), abs(g1j)))
        th1, e1, th2, e2 = cubic_extrema(v0, v1, v2, g1j)
        b = th1
        gb = _beyond(th1, e1, j, side_j, tol, y0, f0, y1, f1, dt, t, p, ybuf, gsc, pc)
        if gb != gb:
            b = th2
            gb = _beyond(th2, e2, j, side_j, tol, y0, f0, y1, f1, dt, t, p, ybuf, gsc, pc)
        if gb != gb:
            b = 1.0
            gb = g1j
    if b == 1.0 and _side(g1j) == side_j:
        return 2.0
    c0, c1, c2, c3 = _cubic_coeffs(v0, v1, v2, g1j)
    return _cubic_locate(j, side_j, c0, c1, c2, c3, b, gb, v1, v2, y0, f0, y1, f1, dt, t, p,
                         ybuf, gsc, pc)


@nb.njit(inline="always", **_JIT)
def _leaves_side_step(r, t0, t1, Y, K1, G0, G1, SIDE, p, ybuf, gbuf, s1, c1):
    """:func:`_leaves_side` for a lone step without history (row r: Y[r] at time t0 to the trial
    end at t1, K1[r] = f(t0, Y[r]), events G0[r], G1[r] at the ends, sides SIDE[r]), each event
    screened by :func:`screen_lone` from its value at the Euler point y + h f; one evaluation of
    ``events`` (at the end's forcing phase s1, c1). ybuf, gbuf row 1: scratch."""
    h = t1 - t0
    for q in range(Y.shape[1]):
        ybuf[q] = Y[r, q] + h * K1[r, q]
    _events_i(t1, ybuf, gbuf[1], p, s1, c1)
    out = 0
    for j in range(G1.shape[1]):
        graze, flagged = screen_lone(G1[r, j], SIDE[r, j], G0[r, j], gbuf[1, j])
        gbuf[GRAZE_ROW, j] = 1.0 if graze else 0.0
        if graze:
            out = 2
        elif flagged:
            out = max(out, 1)
    return out


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _rk4_stages(y, h, tm, pm, sm, cm, te, pe, se, ce, k1, kst, acc, tmp, out):
    """One classic RK4 step of size h from y into out, k1 (the rhs at the step's start) given:
    the middle stages at time tm with coefficients pm and forcing phase sm, cm, the last at te
    with pe, se, ce (for a step from t: tm = t + h / 2, te = t + h; a run-up passes the
    coefficients and phase of its ramped speed at each stage). The model's rhs is inlined once
    (one call site for the three stages: each stage's k in kst, their weighted sum in acc,
    added as they come in the order of :func:`rk4_comb`, ((k1 + 2 k2) + 2 k3) + k4):
    out = y + h / 6 (k1 + 2 k2 + 2 k3 + k4) by :func:`rk4_update`."""
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
        ts = tm
        ps = pm
        ss = sm
        cc = cm
        if st == 3:
            ts = te
            ps = pe
            ss = se
            cc = ce
        _rhs_i(ts, tmp, kst, ps, ss, cc)
        if st == 3:
            for q in range(ns):
                acc[q] = acc[q] + kst[q]
        else:
            for q in range(ns):
                acc[q] = acc[q] + 2.0 * kst[q]
    h6 = rk4_sixth(h)
    for q in range(ns):
        out[q] = rk4_update(y[q], h6, acc[q])


@nb.njit(inline="always", **_JIT)
def _rhs_columns(T, Y, DY, PT, P, LANE, nl, S, C, SC, ybuf, dbuf):
    """The model's rhs of columns 0..nl-1 of Y (one lane or tangent row each, coefficients
    P[LANE[k]]) into DY, one column at a time through the array form (ybuf, dbuf: one state
    each); for models without lane-block functions."""
    ns = Y.shape[0]
    for k in range(nl):
        for q in range(ns):
            ybuf[q] = Y[q, k]
        _rhs_i(T[k], ybuf, dbuf, P[LANE[k]], S[k], C[k])
        for q in range(ns):
            DY[q, k] = dbuf[q]


@nb.njit(inline="always", **_JIT)
def _events_columns(T, Y, G, PT, P, LANE, nl, S, C, ybuf, gb):
    """The model's events of columns 0..nl-1 of Y into G (as :func:`_rhs_columns`)."""
    ns = Y.shape[0]
    for k in range(nl):
        for q in range(ns):
            ybuf[q] = Y[q, k]
        _events_i(T[k], ybuf, gb, P[LANE[k]], S[k], C[k])
        for j in range(G.shape[0]):
            G[j, k] = gb[j]


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _split_rhs(t, y, out, p, s, c):
    """The model's rhs f(t, y) into out, on the split path (for a model with lane-scalar
    functions: the lane form, see below)."""
    _rhs_i(t, y, out, p, s, c)


@nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
def _split_copy(dst, src):
    """dst[:] = src, on the split path (see :func:`_split_rhs`)."""
    for q in range(src.size):
        dst[q] = src[q]


@nb.njit(inline="always", **_JIT)
def _plain_sub(tan, ys, k1, hs, t, tm, sm, cm, te, se, ce, s0, c0, p, side, h, trial, out, work):
    """The split step's sub-step of a plain run (no tangent, ``tan`` None): RK4 of size hs from
    ys (f(ys) = k1; middle stages at tm, phase sm, cm, the last at te, se, ce) into out
    (:func:`_rk4_stages`, scratch rows 1, 2, 4 of work). True: nothing to refuse."""
    _rk4_stages(ys, hs, tm, p, sm, cm, te, p, se, ce, k1, work[1], work[2], work[4], out)
    return True


@nb.njit(inline="always", **_JIT)
def _plain_correct(tan, t, y, k1, u, s, c, p, side, jx, h, pc, fresh):
    """The split step's correction at a split point of a plain run: none (True)."""
    return True


@nb.njit(inline="always", **_JIT)
def _plain_finish(tan, u, ok, y, y_trial):
    """The split step's end on the trial of the (sub-)step from the fraction u of a plain run:
    y = y_trial; 0."""
    _split_copy(y, y_trial)
    return 0


@nb.njit(inline="always", **_JIT)
def _split_run(i, t0, y, y_trial, p, h, omega, n_per, sa, ca, s_end, c_end, side, g1, ncross,
               work, ybuf, gbuf, tan, sub, correct, finish, single):
    """The split step (:func:`_split_step`), with an optional tangent carried through it:
    ``tan`` (None for a plain run) is handed to three hooks, ``sub`` (a sub-step of the state
    from ys into out, ``trial`` where it runs to the grid point; False: ill-posed),
    ``correct`` (at a split point, just after the crossing of event jx; ``fresh``: k1 = f(y)
    is to be computed there first; False: ill-posed) and ``finish`` (the step ends on the
    trial of the (sub-)step from the fraction u: its return value is the step's); ``single``:
    a split point must cross exactly one edge (else 1). A plain run's hooks
    (:func:`_plain_sub`, :func:`_plain_correct`, :func:`_plain_finish`, ``single`` False) are
    inlined to the plain step's operations; the Lyapunov kernel's variational tangent passes
    its own (``_var_split``). Returns 1 where the split limit was reached (y = y_trial, the
    sides those of g1) or a hook refused, else the finish hook's value or 0."""
    n_ev = g1.size
    k1 = work[0]
    f1 = work[5]
    ystart = work[6]
    g0 = gbuf[0]
    gsc = gbuf[1]
    g13 = gbuf[3]
    g23 = gbuf[4]
    u = 0.0  # fraction of the grid step done
    i_mod = i % n_per
    wh = omega * h
    pc = (sa, ca, wh, i_mod)
    t_end = t0 + (i + 1) * h
    s0 = sa
    c0 = ca
    crossed = -1  # the event crossed at the split point y (corrected at the next start)
    for _ in range(MAX_SPLITS):
        t = t0 + (i + u) * h
        dt = (1.0 - u) * h
        _split_rhs(t, y, k1, p, s0, c0)
        if crossed >= 0 and not correct(tan, t, y, k1, u, s0, c0, p, side, crossed, h, pc,
                                        False):
            return 1
        graze = False
        need = False
        for j in range(n_ev):
            flag = gbuf[GRAZE_ROW, j] != 0.0
            graze = graze or flag
            need = need or flag or _side(g1[j]) != side[j]
        ok = True
        if u > 0.0:
            sm, cm = _phase_at(sa, ca, wh, i_mod, 0.5 * (1.0 + u))
            # bool(): a literal True / False would compile a hook once for each
            ok = sub(tan, y, k1, dt, t, t + 0.5 * dt, sm, cm, t + dt, s_end, c_end, s0, c0, p,
                     side, h, bool(True), y_trial, work)  # noqa: UP018
            _events_i(t_end, y_trial, g1, p, s_end, c_end)
            need = graze
            for j in range(n_ev):
                need = need or _side(g1[j]) != side[j]
        if not need:
            return finish(tan, u, ok, y, y_trial)
        _split_rhs(t_end, y_trial, f1, p, s_end, c_end)
        _split_copy(ystart, y)
        pcs = (sa, ca, wh, i_mod, u, 1.0 - u)
        _interpolant_events(ystart, k1, y_trial, f1, dt, t, p, ybuf, g0, g13, g23, pcs)
        first = -1
        theta = 2.0
        for j in range(n_ev):
            flag = gbuf[GRAZE_ROW, j] != 0.0
            if flag or _side(g1[j]) != side[j]:
                th = _first_crossing(j, side[j], flag, g1[j], ystart, k1, y_trial, f1, dt, t,
                                     p, ybuf, gbuf, gsc, pcs)
            else:
                th = 2.0
            gbuf[2, j] = th
            if th < theta:
                theta = th
                first = j
        if first < 0:
            return finish(tan, u, ok, y, y_trial)
        tm = u + 0.5 * theta * (1.0 - u)
        tu = u + theta * (1.0 - u)
        sm, cm = _phase_at(sa, ca, wh, i_mod, tm)
        s1, c1 = _phase_at(sa, ca, wh, i_mod, tu)
        hs = theta * dt
        if not sub(tan, ystart, k1, hs, t, t + 0.5 * hs, sm, cm, t + hs, s1, c1, s0, c0, p,
                   side, h, bool(False), y, work):  # noqa: UP018
            return 1
        n_cross = 0
        for j in range(n_ev):
            if gbuf[2, j] <= theta + SIMULTANEOUS:
                side[j] = -side[j]
                ncross[j] += 1
                n_cross += 1
                crossed = j
        if single and n_cross != 1:
            return 1
        s0 = s1
        c0 = c1
        u = tu
        if u >= 1.0:
            _events_i(t_end, y, g1, p, s_end, c_end)
            if not correct(tan, t0 + (i + u) * h, y, k1, u, s0, c0, p, side, crossed, h, pc,
                           True):
                return 1
            return 0
    _split_copy(y, y_trial)
    for j in range(n_ev):
        side[j] = _side(g1[j])
    return 1


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
def _split_step(i, t0, y, y_trial, p, h, omega, n_per, sa, ca, s_end, c_end, side, g1, ncross,
                work, ybuf, gbuf):
    """Finish grid step i of one lane with edge crossings located (:func:`_split_run` with a
    plain run's hooks, no tangent); y holds the start, and y_trial/g1 the unsplit trial step;
    gbuf has GBUF_ROWS rows, row GRAZE_ROW flagging the events that may graze (set by the
    caller's prefilter: those get :func:`_first_crossing`, the others a crossing only where the
    end's side differs). Returns 1 if the split limit was
    reached, else 0.

    Per (sub-)step to check: f at its start (the RK4's k1) and end, the events at 0, 1/3, 2/3
    of the step's interpolant, the first crossing on the cubic of each event
    (:func:`_cubic_locate`: no model evaluations but one per located event), then RK4 to the
    crossing (k1 reused) and from there to the grid point; after that last sub-step only the
    end's side is tested unless an event may graze. The forcing phase at the fractional points
    comes from that at the grid point by angle addition. The model's rhs and events are inlined by
    LLVM here and in the helpers (``_rhs_i``, ``_events_i``: no calls, no reference counting;
    the same arithmetic), except in the rare fallbacks :func:`_illinois` and :func:`_beyond`,
    compiled once and called (each inlined copy costs compile time, see docs/engine.md).
    sa, ca and s_end, c_end: sin and cos of the forcing phase at the step's start and end,
    the caller's phase-table values (:func:`phase_table`), so a split sees the phases of the
    unsplit step, bitwise, and calls no libm for them. work: 7 rows of the
    state's size."""
    return _split_run(i, t0, y, y_trial, p, h, omega, n_per, sa, ca, s_end, c_end, side, g1,
                      ncross, work, ybuf, gbuf, None, _plain_sub, _plain_correct, _plain_finish,
                      False)


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
def _rows_step(i, t0, Y, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0, G1, W,
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
            _events_i(t, Y[r], G0[r], p, s_tab[j0], c_tab[j0])
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
            _rhs_i(ts, Y[r] if st == 0 else TMP[r], K[st, r], p, s_tab[jj], c_tab[jj])
    h6 = rk4_sixth(h)
    for r in range(nr):
        for q in range(ns):
            Y1[r, q] = rk4_comb(Y[r, q], h6, K[0, r, q], K[1, r, q], K[2, r, q], K[3, r, q])
    for r in range(nr):
        crossed = 0
        if n_ev > 0:
            _events_i(t + h, Y1[r], G1[r], p, s_tab[j0 + 2], c_tab[j0 + 2])
            crossed = _leaves_side_step(r, t, t + h, Y, K[0], G0, G1, SIDE, p, W[8], gbuf,
                                        s_tab[j0 + 2], c_tab[j0 + 2])
        if crossed:
            UNRES[r] += _split_step(i, t0, Y[r], Y1[r], p, h, omega, n_per, s_tab[j0],
                                    c_tab[j0], s_tab[j0 + 2], c_tab[j0 + 2], SIDE[r], G1[r],
                                    NCR[r], W, W[8], gbuf)
        else:
            for q in range(ns):
                Y[r, q] = Y1[r, q]


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
def _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP, Y1,
                  SIDE, G0, G1, W, gbuf, NCR, UNRES):
    """Advance the state y (row 0 of Z) by one grid step and each tangent vector v (rows 1..,
    in the scaled coordinates z = y / S; IS = 1 / S) by the derivative of that step map:
    (Phi(y + e S v) - Phi(y - e S v)) / (2 e S), the rows built and read back by the shared
    tangent helpers (:func:`fd_scale`, :func:`fd_size`, :func:`fd_rows`, :func:`fd_tangent`, as
    every Lyapunov layout does). The 2 k + 1 states are the rows of YP
    (tangent j: rows 2 j - 2 and 2 j - 1; the state: the last row), stepped by
    :func:`_rows_step` (row r's crossings counted in NCR[r], its split-limit steps in UNRES[r]).
    Returns False where a tangent vector was lost (zero or not finite: its rows NaN from here).
    Both the Lyapunov and the monodromy kernels step their tangents so."""
    m, ns = Z.shape
    alive = True
    ny = 0.0
    for q in range(ns):
        zq = Z[0, q] * IS[q]
        ny += zq * zq
    scale = fd_scale(ny)
    last = 2 * (m - 1)
    for q in range(ns):
        YP[last, q] = Z[0, q]
    for j in range(1, m):
        vv = 0.0
        for q in range(ns):
            vv += Z[j, q] * Z[j, q]
        e, ok = fd_size(scale, vv)
        E[j] = e
        alive = alive & ok  # a lost vector: its rows just follow the state
        for q in range(ns):
            YP[2 * j - 2, q], YP[2 * j - 1, q] = fd_rows(Z[0, q], e, S[q], Z[j, q], ok)
    _rows_step(i, t0, YP, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0, G1, W,
               gbuf, NCR, UNRES)
    for j in range(1, m):
        for q in range(ns):
            Z[j, q] = fd_tangent(YP[2 * j - 2, q], YP[2 * j - 1, q], E[j], IS[q])
    for q in range(ns):
        Z[0, q] = YP[last, q]
    return alive


# ---------------------------------------------------------------------------------------------
# The fused step loop, for a model with lane-scalar functions (``rhs_lane``, ``events_lane``,
# ``observe_lane``, ``rhs_lane_form``; see :mod:`geardyn.core.kernel_source`): one loop over the
# slots does a slot's whole grid step, the four RK4 stages with the model's rhs inlined and the
# state, stages and coefficients in local variables (registers), the events, the side test, the
# commit, the clocks and the statistics; nothing but the block's state goes through memory, and
# LLVM vectorises the loop over slots. Slots whose step was flagged (a side left or a possible
# graze) or that have bookkeeping due (a period's start, a sample, the end) are finished out of
# line (:func:`_slot_out`); a grid point's statistics are taken in the loop at the start of the
# next step (a flagged step's point too, after its split), out of line where bookkeeping is
# due there. The arithmetic of every lane is that of the scalar kernel, operation for
# operation (no fastmath), so results are bitwise those of the other paths. The tuple helpers
# below are written out per tuple length when numba types them.


def _tuple_source(args, lines, scope=None):
    """A Python function ``f(args)`` with the body ``lines`` (for the overloads below), marked
    to be typed, not compiled, for its inlining (:data:`._inline_copy.INLINE_ONLY`: it takes
    no literal arguments)."""
    text = f"def _f({args}):\n" + "".join(f"    {line}\n" for line in lines)
    env = dict(scope or {})
    exec(compile(text, "<geardyn-lane-tuples>", "exec"), env)
    fn = env["_f"]
    fn._geardyn_inline_only = True
    return fn


def _t_load(Y, k):
    """(Y[0, k], .., Y[LANE_NS - 1, k])."""


def _t_store(Y, k, y, keep, cond):
    """Y[q, k] = y[q] if cond else keep[q]."""


def _t_like(G, k, like):
    """(G[0, k], .., G[len(like) - 1, k]): a slot's column of as many rows as ``like`` has."""


def _t_axpy(y, a, x):
    """y + a x, elementwise."""


def _t_comb(y, h6, k1, k2, k3, k4):
    """The RK4 combination y + h6 (k1 + 2 k2 + 2 k3 + k4), elementwise (:func:`rk4_comb`)."""


def _t_screen(g1, GS, GP, SIDE, GR, k, locate):
    """:func:`_lanes_screen` of slot k for the events g1 at the trial step's end; the history
    shifted in place (GP[:, k] = GS[:, k], GS[:, k] = g1). True when the step is flagged."""


def _t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, g, o, stat):
    """The statistics of slot k at a grid point (events g, observables o), where ``stat``."""


def _t_side(GS, SIDE, k, g):
    """A lane's start: the events g into GS[:, k], their sides into SIDE[:, k]."""


def _t_healthy(y, bound):
    """:func:`_healthy_lane` of the state tuple y, branch-free."""


def _t_get(y):
    """(y[0], .., y[LANE_NS - 1]) of a state vector."""


def _t_put(y, v):
    """y[q] = v[q] for the state vector y."""


def _t_hermite(y0, f0, y1, f1, h00, h10, h01, h11):
    """The cubic Hermite combination h00 y0 + h10 f0 + h01 y1 + h11 f1, elementwise."""


def _ix(arr, name, row):
    """Source text of element (row, k) of a block array: ``name[row, k]``, or of its flat view
    (rows of BLOCK slots: constant offsets, so that LLVM sees rows that cannot overlap)."""
    return f"{name}[{row}, k]" if arr.ndim == 2 else f"{name}[{row * BLOCK} + k]"


def _ov_t_load(Y, k):
    n = globals()["LANE_NS"]
    return _tuple_source("Y, k", ["return (" + "".join(f"{_ix(Y, 'Y', q)}, " for q in range(n))
                                  + ")"])


def _ov_t_like(G, k, like):
    return _tuple_source("G, k, like", ["return (" + "".join(f"{_ix(G, 'G', j)}, "
                                                            for j in range(len(like))) + ")"])


def _ov_t_store(Y, k, y, keep, cond):
    return _tuple_source("Y, k, y, keep, cond",
                         [f"{_ix(Y, 'Y', q)} = _pick(cond, y[{q}], keep[{q}])"
                          for q in range(len(y))] or ["pass"], {"_pick": _pick})


def _ov_t_axpy(y, a, x):
    return _tuple_source("y, a, x",
                         ["return (" + "".join(f"y[{q}] + a * x[{q}], " for q in range(len(y)))
                          + ")"])


def _ov_t_comb(y, h6, k1, k2, k3, k4):
    terms = "".join(f"rk4_comb(y[{q}], h6, k1[{q}], k2[{q}], k3[{q}], k4[{q}]), "
                    for q in range(len(y)))
    return _tuple_source("y, h6, k1, k2, k3, k4", [f"return ({terms})"], {"rk4_comb": rk4_comb})


def _ov_t_screen(g1, GS, GP, SIDE, GR, k, locate):
    lines = ["hit = False"]
    for j in range(len(g1)):
        gs, gp = _ix(GS, "GS", j), _ix(GP, "GP", j)
        lines += [f"g0 = {gs}",
                  f"gr, fl = screen_grid(g1[{j}], {_ix(SIDE, 'SIDE', j)}, g0, {gp}, locate)",
                  f"{_ix(GR, 'GR', j)} = _pick(gr, 1.0, 0.0)", f"{gp} = g0", f"{gs} = g1[{j}]",
                  "hit = hit | fl"]
    return _tuple_source("g1, GS, GP, SIDE, GR, k, locate", [*lines, "return hit"],
                         {"screen_grid": screen_grid, "_pick": _pick})


def _ov_t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, g, o, stat):
    lines = ["pass"]
    for j in range(len(g)):
        for arr, name, update in ((GMIN, "GMIN", "stat_min"), (GMAX, "GMAX", "stat_max")):
            e = _ix(arr, name, j)
            lines.append(f"{e} = {update}({e}, g[{j}], stat)")
    for j in range(len(o)):
        lines.append(f"v = o[{j}]")
        for arr, name, update in ((OMAX, "OMAX", "stat_max"), (OMIN, "OMIN", "stat_min"),
                                  (OSQ, "OSQ", "stat_square")):
            e = _ix(arr, name, j)
            lines.append(f"{e} = {update}({e}, v, stat)")
    return _tuple_source("GMIN, GMAX, OMAX, OMIN, OSQ, k, g, o, stat", lines,
                         {"stat_min": stat_min, "stat_max": stat_max,
                          "stat_square": stat_square})


def _ov_t_healthy(y, bound):
    terms = " & ".join(f"(abs(y[{q}]) <= bound)" for q in range(len(y))) or "True"
    return _tuple_source("y, bound", [f"return {terms}"])


def _ov_t_get(y):
    n = globals()["LANE_NS"]
    return _tuple_source("y", ["return (" + "".join(f"y[{q}], " for q in range(n)) + ")"])


def _ov_t_put(y, v):
    return _tuple_source("y, v", [f"y[{q}] = v[{q}]" for q in range(len(v))] or ["pass"])


def _ov_t_hermite(y0, f0, y1, f1, h00, h10, h01, h11):
    terms = "".join(f"h00 * y0[{q}] + h10 * f0[{q}] + h01 * y1[{q}] + h11 * f1[{q}], "
                    for q in range(len(y0)))
    return _tuple_source("y0, f0, y1, f1, h00, h10, h01, h11", [f"return ({terms})"])


def _ov_t_side(GS, SIDE, k, g):
    lines = ["pass"]
    for j in range(len(g)):
        lines += [f"{_ix(GS, 'GS', j)} = g[{j}]",
                  f"{_ix(SIDE, 'SIDE', j)} = _pick(g[{j}] > 0.0, 1.0, -1.0)"]
    return _tuple_source("GS, SIDE, k, g", lines, {"_pick": _pick})


if "rhs_lane" in globals():  # the model's lane-scalar functions (see .kernels)
    FUSED = True
    _rhs_l = rhs_lane  # noqa: F821
    _events_l = events_lane  # noqa: F821
    _observe_l = observe_lane  # noqa: F821
    _lane_form = rhs_lane_form  # noqa: F821
    #: The state size of the model's lane-scalar functions (``<rhs>_lane_states``).
    LANE_NS = int(_rhs_l.py_func.__globals__[_rhs_l.py_func.__name__ + "_states"])
    for _stub, _impl in ((_t_load, _ov_t_load), (_t_like, _ov_t_like), (_t_store, _ov_t_store),
                         (_t_axpy, _ov_t_axpy),
                         (_t_comb, _ov_t_comb), (_t_screen, _ov_t_screen),
                         (_t_stats, _ov_t_stats), (_t_side, _ov_t_side),
                         (_t_healthy, _ov_t_healthy), (_t_get, _ov_t_get), (_t_put, _ov_t_put),
                         (_t_hermite, _ov_t_hermite)):
        nb.extending.overload(_stub, inline="always")(_impl)

    #: The lane index of a split's one-lane coefficient view (``p[:, None]``, PT[j, 0] = p[j]):
    #: an int64 and a C-layout view, the argument types of the fused loop's calls, so that the
    #: model's lane-scalar functions compile once (a literal 0 and the transposed view
    #: ``p[None, :].T``, F layout, compiled a second copy of the model's rhs).
    _K0 = np.int64(0)

    # The split path in the lane form: the state and the stages in registers, read and written
    # element by element. With the array loops LLVM loaded a freshly stored state or stage as
    # one vector, which no store can forward to (a stall of ~15 cycles each, ~1/5 of a split,
    # see bench/perf_map.py); the same arithmetic (bitwise equal).
    @nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
    def _split_rhs(t, y, out, p, s, c):  # noqa: F811 - the lane form of the generic one
        v = _rhs_l(t, _t_get(y), p[:, None], _K0, s, c, FORM_GENERAL)
        _t_put(out, v)

    @nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
    def _split_copy(dst, src):  # noqa: F811
        _t_put(dst, _t_get(src))

    @nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
    def _rk4_stages(y, h, tm, pm, sm, cm, te, pe, se, ce, k1, kst, acc, tmp, out):  # noqa: F811
        ptm = pm[:, None]  # PT[j, 0] = p[j]: the lane functions' coefficient layout, a view
        pte = pe[:, None]
        yt = _t_get(y)
        k1t = _t_get(k1)
        hh = 0.5 * h
        k2 = _rhs_l(tm, _t_axpy(yt, hh, k1t), ptm, _K0, sm, cm, FORM_GENERAL)
        k3 = _rhs_l(tm, _t_axpy(yt, hh, k2), ptm, _K0, sm, cm, FORM_GENERAL)
        k4 = _rhs_l(te, _t_axpy(yt, h, k3), pte, _K0, se, ce, FORM_GENERAL)
        _t_put(out, _t_comb(yt, rk4_sixth(h), k1t, k2, k3, k4))

    @nb.njit(forceinline=True, _nrt=False, **_JIT, **INNER)
    def _hermite(y0, f0, y1, f1, dt, theta, out):  # noqa: F811
        h00, h10, h01, h11 = _hermite_weights(dt, theta)
        _t_put(out, _t_hermite(_t_get(y0), _t_get(f0), _t_get(y1), _t_get(f1), h00, h10, h01,
                               h11))
else:
    FUSED = False
    LANE_NS = 0
    _rhs_l = _events_l = _observe_l = None

    @nb.njit(**_JIT, **OUTER)  # tests call it from Python
    def _lane_form(PT, k):
        return FORM_GENERAL


@nb.njit(inline="always", **_JIT)
def _flat(arrays):
    """Flat views of a tuple of five block arrays (rows of BLOCK slots)."""
    a, b, c, d, e = arrays
    return (a.reshape(a.size), b.reshape(b.size), c.reshape(c.size), d.reshape(d.size),
            e.reshape(e.size))


class _NoAliasCompiler(WidthCompiler):
    """numba's pipeline with the function's array arguments declared ``noalias`` (LLVM), so
    that the fused loop needs no runtime overlap checks of its ~30 block arrays (there are too
    many: LLVM would not vectorise it). The caller guarantees it: no two array arguments of
    a function compiled with it (the sweep's ``_block_run_form*``, the Lyapunov kernel's
    ``_lyap_run_form*``) that it touches share memory (``blk``'s views ``PH``,
    ``HW`` and ``FL`` of ``PH6``, ``HW3`` and the state arrays are used there, not those), with
    one exception: the compaction (:func:`._sweep_books._compact`, called there) moves a slot's
    phase and step weights through ``PH6`` and ``HW3``, which the fused loop reads as ``PH``
    and ``HW``. Made honest (moved through ``PH`` and ``HW``, or the loop reading ``PH6`` and
    ``HW3``, or the phases recomputed from the tables after the move), the paper workload ran
    ~3x slower (the fused loop's speed depends on LLVM taking the compaction's stores to be
    apart from its arrays); the compaction runs between loop calls, never inside one."""

    def define_pipelines(self):
        self.state.flags.noalias = True
        return super().define_pipelines()


#: ``_JIT`` with :class:`_NoAliasCompiler` (geardyn's vector width, noalias array arguments).
_JIT_NOALIAS = {**_JIT, "pipeline_class": _NoAliasCompiler}
