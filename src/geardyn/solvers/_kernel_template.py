"""Fixed-step RK4 kernels, specialised per model from this template (see :mod:`.kernels`).

This file is a template: :func:`geardyn.solvers.kernels.kernels_for` copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions, so that numba compiles
(and caches on disk) one kernel per model with the model's functions. As it stands it is a
valid module bound to a small test oscillator.

Numerics
--------
* Classic 4th-order Runge-Kutta on a grid aligned to the forcing period: ``n_per`` steps of
  ``h = T / n_per``; the forcing phase ``sin/cos(Omega t)`` at the grid and half-grid points comes
  from a table, so it is exact and periodic.
* Kinks of the right-hand side (the edges of the backlash dead zone) are the zero crossings of the
  model's ``events``. With ``locate`` on, a step that leaves a side of an edge (its end on the
  other side, or a graze: two crossings inside the step) is split at the first crossing, located
  by root-finding on the cubic Hermite interpolant of the step (error O(h^4) in the crossing
  time), and integrated in sub-steps. Every RK4 stage then sees a smooth right-hand side and the
  method keeps 4th order. A step is split at most ``MAX_SPLITS`` times (chattering); the count of
  steps that hit the limit is returned (see :mod:`._step_core`).
* The sweep advances lanes (parameter sets) through blocks of up to ``BLOCK`` refilling slots,
  one block per worker, each slot with its own lane, grid step, phase and steps per period, in
  structure-of-arrays layout (slot index innermost, block width a runtime value), so that the
  RK4 stages, the model's lane-block functions where it has them, the side test and the
  statistics vectorise over slots; lanes that leave a side of an edge finish on the scalar
  path. Workers run in parallel (threads). A lane's arithmetic does not depend on its
  neighbours (no fastmath), so results are bitwise independent of slots, schedule and threads.
  ``trajectory`` (one lane) keeps the row layout of ``_block_step``.
* A lane whose state leaves ``|y| <= bound`` or stops being finite is marked diverged (status 1)
  and frozen; the others go on.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn._bound_calls import optimise_once
from geardyn.core.kernel_source import FORM_GENERAL, FORM_LOAD, FORM_QUIET, LANE_FORMS
from geardyn.solvers._parallel import run_workers
from geardyn.solvers._step_core import (  # CORE-IMPORT
    _JIT,
    _JIT_NOALIAS,
    FUSED,
    GRAZE_ROW,
    _events_columns,
    _events_i,
    _events_l,
    _flat,
    _lane_form,
    _observe_l,
    _rhs_columns,
    _rhs_i,
    _rhs_l,
    _split_step,
    _t_axpy,
    _t_comb,
    _t_healthy,
    _t_like,
    _t_load,
    _t_screen,
    _t_side,
    _t_stats,
    _t_store,
)
from geardyn.solvers._step_shared import (
    BLOCK,
    INNER,
    MAX_SPLITS,
    OUTER,
    SIMULTANEOUS,
    STATUS_DIVERGED,
    STATUS_OK,
    _healthy,
    _keep_start,
    _leaves_side,
    _padded,
    _side,
    event_buffer,
    phase_increments,
    phase_rotate,
    phase_table,
    rk4_comb,
    rk4_sixth,
    screen_grid,
    stat_max,
    stat_min,
    stat_square,
)
from geardyn.solvers._sweep_books import (  # compiled once for every model
    _alloc,
    _chained,
    _compact,
    _full,
    _slot_check,
    _slot_sample,
)
from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

_observe_i = nb.njit(forceinline=True, _nrt=False, **_JIT)(observe.py_func)  # (as ._step_core's)

__all__ = ["BLOCK", "MAX_SPLITS", "SIMULTANEOUS", "events", "observe", "phase_table", "rhs",
           "sweep", "trajectory"]


@nb.njit(**_JIT, **INNER)
def _rhs_block(T, Y, DY, P, first, nl, active, s, c):
    """rhs of the active rows of 0..nl-1 (lanes first..) at times T; the model's rhs inlined,
    once per block."""
    for k in range(nl):
        if active[k]:
            _rhs_i(T[k], Y[k], DY[k], P[first + k], s, c)


@nb.njit(**_JIT, **INNER)
def _events_block(T, Y, G, P, first, nl, active, s, c):
    for k in range(nl):
        if active[k]:
            _events_i(T[k], Y[k], G[k], P[first + k], s, c)


@nb.njit(**_JIT, **INNER)
def _block_step(i, first, nl, active, Y, Y1, K1, K2, K3, K4, TMP, TT, G, SIDE, P, H, OMEGA, T0,
                n_per, sa, ca, sb, cb, se, ce, locate, NCROSS, UNRES, work, ybuf, gbuf):
    """Advance the active lanes of first..first+nl-1 (rows 0..nl-1 of the block arrays) by grid
    step i: a lockstep RK4 trial, then, for a lane whose trial crossed an edge, the step redone
    with the crossing located. G holds the events at the new states afterwards; inactive lanes
    (finished or diverged) stay as they are."""
    ns = Y.shape[1]
    n_ev = G.shape[1]
    for k in range(nl):
        lane = first + k
        TT[k] = T0[lane] + i * H[lane]
    _rhs_block(TT, Y, K1, P, first, nl, active, sa, ca)
    for k in range(nl):
        lane = first + k
        hh = 0.5 * H[lane]
        for q in range(ns):
            TMP[k, q] = Y[k, q] + hh * K1[k, q]
        TT[k] = T0[lane] + i * H[lane] + hh
    _rhs_block(TT, TMP, K2, P, first, nl, active, sb, cb)
    for k in range(nl):
        hh = 0.5 * H[first + k]
        for q in range(ns):
            TMP[k, q] = Y[k, q] + hh * K2[k, q]
    _rhs_block(TT, TMP, K3, P, first, nl, active, sb, cb)
    for k in range(nl):
        lane = first + k
        h = H[lane]
        for q in range(ns):
            TMP[k, q] = Y[k, q] + h * K3[k, q]
        TT[k] = T0[lane] + (i + 1) * h
    _rhs_block(TT, TMP, K4, P, first, nl, active, se, ce)
    for k in range(nl):
        h6 = rk4_sixth(H[first + k])
        for q in range(ns):
            Y1[k, q] = rk4_comb(Y[k, q], h6, K1[k, q], K2[k, q], K3[k, q], K4[k, q])
    _keep_start(i, nl, active, G, gbuf)
    _events_block(TT, Y1, G, P, first, nl, active, se, ce)
    for k in range(nl):
        if not active[k]:
            continue
        lane = first + k
        crossed = _leaves_side(i, k, G, SIDE, locate, gbuf)
        if crossed and locate:
            UNRES[lane] += _split_step(i, T0[lane], Y[k], Y1[k], P[lane], H[lane], OMEGA[lane],
                                       n_per, sa, ca, se, ce, SIDE[k], G[k], NCROSS[lane], work,
                                       ybuf, gbuf)
            continue
        if crossed:
            for j in range(n_ev):
                s_new = _side(G[k, j])
                if s_new != SIDE[k, j]:
                    SIDE[k, j] = s_new
                    NCROSS[first + k, j] += 1
        for q in range(ns):
            Y[k, q] = Y1[k, q]


@nb.njit(**_JIT, **OUTER)
def trajectory(p, y0, h, omega, n_per, i0, n_steps, stride, locate, bound, n_ev, n_obs):
    """Integrate one lane from grid point i0 (time i0 h) for n_steps grid steps, recording every
    stride-th grid point.

    Returns (Y[n_rec, ns], O[n_rec, n_obs], G[n_rec, n_ev], ncross[n_ev], status, unresolved,
    steps_done); n_rec = n_steps // stride + 1. Rows after a divergence are NaN.
    """
    ns = y0.size
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    Y, Y1, K1, K2, K3, K4, TMP, TT, G, SIDE, work, ybuf, gbuf = _alloc(1, ns, n_ev)
    P = p.reshape((1, p.size))
    H = np.zeros(1)
    H[0] = h
    OM = np.zeros(1)
    OM[0] = omega
    T0 = np.zeros(1)
    NCROSS = np.zeros((1, max(n_ev, 1)), np.int64)
    UNRES = np.zeros(1, np.int64)
    ACTIVE = np.zeros(1, np.bool_)
    ACTIVE[0] = True
    n_rec = n_steps // stride + 1
    out_y = _full((n_rec, ns), np.nan)
    out_o = _full((n_rec, max(n_obs, 1)), np.nan)
    out_g = _full((n_rec, max(n_ev, 1)), np.nan)
    for q in range(ns):
        Y[0, q] = y0[q]
    j0 = 2 * (i0 % n_per)
    _events_i(i0 * h, Y[0], G[0], p, s_tab[j0], c_tab[j0])
    for j in range(n_ev):
        SIDE[0, j] = _side(G[0, j])
    status = STATUS_OK
    done = 0
    obuf = np.zeros(max(n_obs, 1))
    for i in range(i0, i0 + n_steps + 1):
        j0 = 2 * (i % n_per)
        if (i - i0) % stride == 0:
            r = (i - i0) // stride
            t = i * h
            for q in range(ns):
                out_y[r, q] = Y[0, q]
            if n_obs > 0:
                observe(t, Y[0], obuf, p, s_tab[j0], c_tab[j0])
                for q in range(n_obs):
                    out_o[r, q] = obuf[q]
            if n_ev > 0:
                _events_i(t, Y[0], gbuf[0], p, s_tab[j0], c_tab[j0])
                for q in range(n_ev):
                    out_g[r, q] = gbuf[0, q]
        if i == i0 + n_steps:
            break
        _block_step(i, 0, 1, ACTIVE, Y, Y1, K1, K2, K3, K4, TMP, TT, G, SIDE, P, H, OM, T0, n_per,
                    s_tab[j0], c_tab[j0], s_tab[j0 + 1], c_tab[j0 + 1], s_tab[j0 + 2],
                    c_tab[j0 + 2], locate, NCROSS, UNRES, work, ybuf, gbuf)
        done = i + 1 - i0
        if not _healthy(Y[0], bound):
            status = STATUS_DIVERGED
            break
    return out_y, out_o[:, :n_obs], out_g[:, :n_ev], NCROSS[0, :n_ev], status, UNRES[0], done


# ---------------------------------------------------------------------------------------------
# The sweep's lane blocks, structure of arrays. Each worker owns a block of ``width`` slots; a
# slot holds one lane at a time, with its own grid step, phase (grid point within the period),
# steps per period and forcing-phase table, so lanes of every step count share a block. The
# block holds its state as Y[q, k], its events as G[j, k], its coefficients transposed as
# PT[j, k] (slot k innermost and contiguous; the width is a runtime value). All slots advance
# one grid step per iteration; when a lane ends (or diverges) its results are written out and
# the slot takes the next lane of the worker's queue, so blocks stay full until the queue's
# tail. The RK4 stages, the phase gathers, the side test and the statistics are loops over
# slots without calls, which LLVM vectorises; a built-in model's ``*_lanes`` functions
# (generated module: ``rhs_lanes``, ``events_lanes``, ``observe_lanes``) evaluate the model the
# same way, with the forcing phase per slot (S[k], C[k]), called once per block step (compiled
# once per model, shared with the Lyapunov kernel's lane blocks; the call's cost is spread over
# the block's slots). A model without them is evaluated lane
# by lane (the per-lane functions, gathered). Lanes that leave a side of an edge are finished
# one by one on the scalar path (:func:`_split_step`). No fastmath: each lane's arithmetic is
# the scalar kernel's, so a lane's result does not depend on its slot, its neighbours, its
# worker or the thread count.


@nb.njit(inline="always", **_JIT)
def _observe_lanes_generic(T, Y, O, PT, P, LANE, nl, S, C, SC, ybuf, ob):
    ns = Y.shape[0]
    for k in range(nl):
        for q in range(ns):
            ybuf[q] = Y[q, k]
        _observe_i(T[k], ybuf, ob, P[LANE[k]], S[k], C[k])
        for j in range(O.shape[0]):
            O[j, k] = ob[j]


if "rhs_lanes" in globals():  # the model's lane-block functions (see .kernels), called

    @nb.njit(inline="always", **_JIT)
    def _rhs_lanes(T, Y, DY, PT, P, LANE, nl, S, C, SC, ybuf, dbuf):
        rhs_lanes(T, Y, DY, PT, nl, S, C, SC)  # noqa: F821

    @nb.njit(inline="always", **_JIT)
    def _events_lanes(T, Y, G, PT, P, LANE, nl, S, C, ybuf, gb):
        events_lanes(T, Y, G, PT, nl, S, C)  # noqa: F821

    @nb.njit(inline="always", **_JIT)
    def _observe_lanes(T, Y, O, PT, P, LANE, nl, S, C, SC, ybuf, ob):
        observe_lanes(T, Y, O, PT, nl, S, C, SC)  # noqa: F821

else:
    _rhs_lanes = _rhs_columns
    _events_lanes = _events_columns
    _observe_lanes = _observe_lanes_generic


@nb.njit(inline="always", **_JIT)
def _lanes_phase(nl, OFF, PHASE, S_TAB, C_TAB, SB, CB, SE, CE):
    """Every slot's forcing phase at the middle and the end of its next grid step (sin, cos)
    into SB, CB, SE, CE, gathered from the concatenated tables (the phase at the step's start
    is the last step's end, SE and CE before the call: set to the table's first point when a
    lane is loaded; the table's last point, 2 n_per, equals its first bit for bit)."""
    for k in range(nl):
        j1 = np.uint64(OFF[k] + 2 * PHASE[k] + 1)  # unsigned: no wraparound test
        j2 = np.uint64(OFF[k] + 2 * PHASE[k] + 2)
        SB[k] = S_TAB[j1]
        CB[k] = C_TAB[j1]
        SE[k] = S_TAB[j2]
        CE[k] = C_TAB[j2]


@nb.njit(inline="always", **_JIT)
def _lanes_rk4(STEP, nl, Y, Y1, K1, K2, K3, K4, TMP, FL, HW, TT, HB, T0B, PT, P, LANE, PH, SC,
               ybuf, dbuf, OFF, PHASE, S_TAB, C_TAB):
    """The RK4 trial of every slot's grid step STEP[k] into Y1; TT holds the step's end times
    afterwards. FL: flat views (state and slot in one index) of Y, Y1, K1..K4, TMP; HW: flat
    rows of h/2, h and h/6 per (state, slot), so the stage updates are one loop each; PH: the
    slots' forcing phases (SB, CB, SE, CE: sin/cos at the step's middle and end; SE, CE hold
    the start's on entry, see :func:`_lanes_phase`)."""
    Yf, Y1f, K1f, K2f, K3f, K4f, TMPf = FL
    HHf, HFf, H6f = HW
    SB, CB, SE, CE = PH
    m_all = Yf.size
    KS = (K1, K2, K3, K4)
    KSf = (K1f, K2f, K3f, K4f)
    for k in range(nl):
        TT[k] = T0B[k] + STEP[k] * HB[k]
    for stage in range(4):  # one call site of the model (one inlined copy: compile time)
        mid = stage == 1 or stage == 2
        _rhs_lanes(TT, Y if stage == 0 else TMP, KS[stage], PT, P, LANE, nl, SB if mid else SE,
                   CB if mid else CE, SC, ybuf, dbuf)
        if stage == 0:
            _lanes_phase(nl, OFF, PHASE, S_TAB, C_TAB, SB, CB, SE, CE)
        if stage == 3:
            break
        Kf = KSf[stage]
        Hf = HFf if stage == 2 else HHf
        for m in range(m_all):
            TMPf[m] = Yf[m] + Hf[m] * Kf[m]
        if stage == 0:
            for k in range(nl):
                TT[k] = T0B[k] + STEP[k] * HB[k] + 0.5 * HB[k]
        elif stage == 2:
            for k in range(nl):
                TT[k] = T0B[k] + (STEP[k] + 1) * HB[k]
    for m in range(m_all):
        Y1f[m] = rk4_comb(Yf[m], H6f[m], K1f[m], K2f[m], K3f[m], K4f[m])


@nb.njit(inline="always", **_JIT)
def _lanes_screen(nl, G1, GS, GP, SIDE, GR, FLAG, locate):
    """The side test of a block's trial step, vectorised over slots (:func:`screen_grid` for
    every lane and event): FLAG[k] != 0 where slot k's step ends on another side of an edge or,
    with ``locate``, may graze one (GR[j, k] = 1: edge j may; from the grid values g_{i-1} = GP,
    g_i = GS, g_{i+1} = G1)."""
    for k in range(nl):
        FLAG[k] = 0.0
    for j in range(G1.shape[0]):
        for k in range(nl):
            graze, flagged = screen_grid(G1[j, k], SIDE[j, k], GS[j, k], GP[j, k], locate)
            GR[j, k] = 1.0 if graze else 0.0
            FLAG[k] += 1.0 if flagged else 0.0


@nb.njit(inline="always", **_JIT)
def _lanes_finish(STEP, nl, NPER, Y, Y1, G1, GR, SIDE, FLAG, ACT, P, LANE, HB, T0B, OMEGA,
                  locate, NCROSS, UNRES, ys, y1s, sides, g1s, work, ybuf, gbuf, TABS, OFF):
    """Commit the trial step of the active slots: the unflagged ones vectorised (a select of
    values loaded unconditionally, so that no branch stops the vectoriser), the flagged ones (a
    side left or a possible graze) one by one (:func:`_finish_flagged`). FLAG[k] is 1 on
    return where slot k was flagged and active, else 0."""
    ns = Y.shape[0]
    n_flag = 0
    for k in range(nl):
        flagged = ACT[k] & (FLAG[k] != 0.0)
        FLAG[k] = 1.0 if flagged else 0.0
        n_flag += 1 if flagged else 0
    for q in range(ns):
        for k in range(nl):
            a = Y1[q, k]
            b = Y[q, k]
            Y[q, k] = a if (ACT[k] & (FLAG[k] == 0.0)) else b
    if n_flag == 0:
        return
    for k in range(nl):
        if FLAG[k] != 0.0:
            _finish_flagged(k, STEP[k], NPER, Y, Y1, G1, GR, SIDE, P, LANE, HB, T0B, OMEGA, locate,
                            NCROSS, UNRES, ys, y1s, sides, g1s, work, ybuf, gbuf, TABS, OFF)


@nb.njit(_nrt=False, **_JIT, **INNER)
def _finish_flagged(k, i, NPER, Y, Y1, G1, GR, SIDE, P, LANE, HB, T0B, OMEGA, locate, NCROSS,
                    UNRES, ys, y1s, sides, g1s, work, ybuf, gbuf, TABS, OFF):
    """Finish slot k's flagged trial step (grid step i) on the scalar path: the crossings located
    (:func:`_split_step`) or, without ``locate``, counted at the step's end. Out of the slot
    loops, so that they stay small: a call from the SoA loop, inlined into :func:`_slot_out`
    (itself out of the fused loop; a call there passed its ~20 arrays by value). TABS: the
    concatenated phase tables (S_TAB, C_TAB), slot k's at OFF[k]: the step's start and end
    phase for the split."""
    ns = Y.shape[0]
    n_ev = G1.shape[0]
    lane = LANE[k]
    if not locate:
        for j in range(n_ev):
            s_new = 1.0 if G1[j, k] > 0.0 else -1.0
            if s_new != SIDE[j, k]:
                SIDE[j, k] = s_new
                NCROSS[lane, j] += 1
        for q in range(ns):
            Y[q, k] = Y1[q, k]
        return
    for q in range(ns):
        ys[q] = Y[q, k]
        y1s[q] = Y1[q, k]
    for j in range(n_ev):
        sides[j] = 1 if SIDE[j, k] > 0.0 else -1
        g1s[j] = G1[j, k]
        gbuf[GRAZE_ROW, j] = GR[j, k]
    S_TAB, C_TAB = TABS
    j0 = OFF[k] + 2 * (i % NPER[k])
    UNRES[lane] += _split_step(i, T0B[k], ys, y1s, P[lane], HB[k], OMEGA[lane], NPER[k],
                               S_TAB[j0], C_TAB[j0], S_TAB[j0 + 2], C_TAB[j0 + 2], sides, g1s,
                               NCROSS[lane], work, ybuf, gbuf)
    for q in range(ns):
        Y[q, k] = ys[q]
    for j in range(n_ev):
        SIDE[j, k] = float(sides[j])
        G1[j, k] = g1s[j]


@nb.njit(inline="always", **_JIT)
def _advance(nl, STEP, PHASE, NPER):
    """One grid step on every slot's clock: its step count and its grid point in the period."""
    for k in range(nl):
        STEP[k] += 1
        ph = PHASE[k] + 1
        PHASE[k] = 0 if ph == NPER[k] else ph


@nb.njit(nogil=True, **_JIT, **OUTER)
def _sweep_worker(w, lanes, cfg, sched, out):
    """Worker w of :func:`sweep`: its queue of lanes through one block of refilling slots
    (:func:`_block_run_soa`; a model without lane-scalar functions)."""
    q0, q1, nl, nw = _worker_span(w, cfg, sched)
    if nl > 0:
        blk, slots, scratch = _block_arrays(nw, lanes, cfg)
        _block_run_soa(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


# One worker per lane form (a model with lane-scalar functions), each compiled on its first call:
# a sweep compiles the fused loop of the forms its lanes take only (see :func:`sweep`).
@nb.njit(nogil=True, **_JIT, **OUTER)
def _sweep_worker_form0(w, lanes, cfg, sched, out):
    """Worker w of :func:`sweep`: the entries of its queue in lane form FORM_GENERAL through
    one block of refilling slots (:func:`_block_run_form0`)."""
    q0, q1, nl, nw = _worker_span(w, cfg, sched)
    if nl > 0:
        blk, slots, scratch = _block_arrays(nw, lanes, cfg)
        _block_run_form0(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _sweep_worker_form1(w, lanes, cfg, sched, out):
    """:func:`_sweep_worker_form0` in the lane form FORM_QUIET."""
    q0, q1, nl, nw = _worker_span(w, cfg, sched)
    if nl > 0:
        blk, slots, scratch = _block_arrays(nw, lanes, cfg)
        _block_run_form1(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _sweep_worker_form2(w, lanes, cfg, sched, out):
    """:func:`_sweep_worker_form0` in the lane form FORM_LOAD."""
    q0, q1, nl, nw = _worker_span(w, cfg, sched)
    if nl > 0:
        blk, slots, scratch = _block_arrays(nw, lanes, cfg)
        _block_run_form2(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


@nb.njit(**_JIT, **OUTER)
def _forms_present(P, sched):
    """present[w, f]: whether worker w's queue holds an entry of lane form f
    (:func:`_entry_form`)."""
    start, queue, chain = sched[0], sched[1], sched[6]
    present = np.zeros((start.size - 1, LANE_FORMS), np.bool_)
    for w in range(start.size - 1):
        for i in range(start[w], start[w + 1]):
            present[w, _entry_form(P, chain, queue[i])] = True
    return present


@nb.njit(inline="always", **_JIT)
def _worker_span(w, cfg, sched):
    """Worker w's queue positions q0..q1, the slots it runs (nl, 0 for none) and the width of
    its block's arrays (nw; the fused loop's rows are BLOCK slots apart)."""
    start = sched[0]
    q0 = start[w]
    q1 = start[w + 1]
    nl = max(min(cfg[7], q1 - q0), 0)
    nw = nl
    if FUSED:
        nl = min(nl, BLOCK)
        nw = BLOCK
    return q0, q1, nl, nw


@nb.njit(inline="always", **_JIT)
def _block_arrays(nw, lanes, cfg):
    """The arrays of a worker's block of nw slots (blk, slots, scratch). Slot arrays: LANE (the
    lane held), ACT (holds a running lane), END (to be refilled), STEP (the lane's grid steps
    done), PHASE (its grid point in the period), NPER, OFF (its phase table's offset), HB, T0B
    (step, start time), n_tr, n_end, next_sample, DUE (the next step with bookkeeping: end of
    the transient or a sample), n_stat, n_ring (section points kept)."""
    P, Y0 = lanes[0], lanes[1]
    conv_depth, n_ev, n_obs = cfg[1], cfg[5], cfg[6]
    ns = Y0.shape[1]
    n_g = max(n_ev, 1)
    n_o = max(n_obs, 1)
    depth = max(conv_depth, 1)
    R = np.zeros((nw, depth, ns))  # the last section points of the transient
    D = np.zeros((nw, 3 * depth, depth))  # their differences, per candidate period
    Y = np.zeros((ns, nw))
    Y1 = np.zeros((ns, nw))
    K1 = np.zeros((ns, nw))
    K2 = np.zeros((ns, nw))
    K3 = np.zeros((ns, nw))
    K4 = np.zeros((ns, nw))
    TMP = np.zeros((ns, nw))
    PT = np.zeros((P.shape[1], nw))
    SC = np.zeros((8, nw))  # scratch; in the fused loop rows 4-7: the slot's phase increments
    # sin, cos of the forcing phase at a step's middle and end
    PH6 = np.zeros((4, nw))
    PH = (PH6[0], PH6[1], PH6[2], PH6[3])
    TT = np.zeros(nw)
    GP = _full((n_g, nw), np.nan)  # events at the grid points i - 1, i, i + 1
    GS = np.zeros((n_g, nw))
    G1 = np.zeros((n_g, nw))
    GR = np.zeros((n_g, nw))
    SIDE = _full((n_g, nw), 1.0)
    FLAG = np.zeros(nw)
    GMIN = _full((n_g, nw), np.inf)
    GMAX = _full((n_g, nw), -np.inf)
    O = np.zeros((n_o, nw))
    OMAX = _full((n_o, nw), -np.inf)
    OMIN = _full((n_o, nw), np.inf)
    OSQ = np.zeros((n_o, nw))
    STAT = np.zeros(nw, np.bool_)
    MSK = np.zeros(nw, np.bool_)  # slots with bookkeeping due
    ACT = np.zeros(nw, np.bool_)
    END = np.zeros(nw, np.bool_)  # slots to (re)fill
    END[:] = True
    LANE = np.zeros(nw, np.int64)
    STEP = np.zeros(nw, np.int64)
    PHASE = np.zeros(nw, np.int64)
    NPER = np.zeros(nw, np.int64)
    NPER[:] = 1
    OFF = np.zeros(nw, np.int64)
    HB = np.zeros(nw)
    T0B = np.zeros(nw)
    n_end = np.zeros(nw, np.int64)
    n_tr = np.zeros(nw, np.int64)
    next_sample = np.zeros(nw, np.int64)
    DUE = np.zeros(nw, np.int64)
    n_stat = np.zeros(nw, np.int64)
    n_ring = np.zeros(nw, np.int64)
    # the scalar path's scratch
    ys = np.zeros(ns)
    y1s = np.zeros(ns)
    dbuf = np.zeros(ns)
    sides = np.zeros(n_g, np.int64)
    sides[:] = 1
    g1s = np.zeros(n_g)
    gb = np.zeros(n_g)
    ob = np.zeros(n_o)
    work = np.zeros((7, ns))
    ybuf = np.zeros(ns)
    gbuf = event_buffer(np.int64(0), n_ev)  # (int64 as _alloc's: one compile)
    marked = np.zeros(nw, np.int64)  # the marked slots of a block step (_slots_out)
    HW3 = np.zeros((3, ns, nw))  # h/2, h, h/6 per (state, slot)
    FL = (Y.reshape(ns * nw), Y1.reshape(ns * nw), K1.reshape(ns * nw), K2.reshape(ns * nw),
          K3.reshape(ns * nw), K4.reshape(ns * nw), TMP.reshape(ns * nw))
    HW = (HW3[0].reshape(ns * nw), HW3[1].reshape(ns * nw), HW3[2].reshape(ns * nw))
    blk = (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, G1, GR, SIDE,
           FLAG, GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW)
    slots = (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample,
             DUE, n_stat, n_ring)
    scratch = (ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, marked)
    return blk, slots, scratch


@nb.njit(inline="always", **_JIT)
def _next_lane(k, nxt, q1, lanes, cfg, sched, out, slots, form):
    """The lane slot k takes next, and the queue position after it: the successor on the
    chain of the lane that ended there (:func:`_chained`), else the queue's next lane of lane
    form ``form`` (:func:`_entry_form`; any lane where ``form`` < 0); -1 when there is
    neither."""
    lane = _chained(k, lanes, cfg, sched, out, slots)
    if lane >= 0:
        return lane, nxt
    queue = sched[1]
    while nxt < q1:
        lane = queue[nxt]
        nxt += 1
        if form < 0 or _entry_form(lanes[0], sched[6], lane) == form:
            return lane, nxt
    return -1, nxt


@nb.njit(_nrt=False, **_JIT, **INNER)
def _entry_form(P, chain, lane):
    """The lane form of a queue entry: that of the lane and of every lane chained after it if
    they agree, else FORM_GENERAL (``rhs_lane_form``; FORM_GENERAL without lane forms)."""
    PTq = P.T  # coefficient rows, lane innermost (as rhs_lane_form reads them)
    form = _lane_form(PTq, lane)
    nxt = chain[lane] if chain.size > 0 else -1
    while nxt >= 0 and form != FORM_GENERAL:
        if _lane_form(PTq, nxt) != form:
            return FORM_GENERAL
        nxt = chain[nxt]
    return form


@nb.njit(inline="always", **_JIT)
def _load_slot(k, lane, lanes, cfg, sched, out, blk, slots, GP):
    """Slot k takes lane ``lane`` at its grid step 0 (GP: the block's events at the grid point
    before, rotated by the block loop). Returns 1 if the lane samples from step 0 (no
    transient), else 0."""
    P, Y0, H, OMEGA, T0, n_transient, n_transient_max, sample_every = lanes
    conv_tol, conv_depth, n_samples, locate, bound, n_ev, n_obs, width = cfg
    start, queue, lane_nper, lane_tab, S_TAB, C_TAB, chain = sched
    (samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved, transient_steps,
     converged, steps) = out
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, _, GS, G1, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    ns = Y0.shape[1]
    n_g = GP.shape[0]
    n_o = O.shape[0]
    ACT[k] = True
    STAT[k] = False  # (the fused loop: no statistics pending)
    LANE[k] = lane
    STEP[k] = 0
    PHASE[k] = 0
    NPER[k] = lane_nper[lane]
    OFF[k] = lane_tab[lane]
    h = H[lane]
    HB[k] = h
    T0B[k] = T0[lane]
    TT[k] = T0[lane]
    for q in range(ns):
        Y[q, k] = Y0[lane, q]
    for j in range(P.shape[1]):
        PT[j, k] = P[lane, j]
    status[lane] = STATUS_OK
    unresolved[lane] = 0
    converged[lane] = 0 if conv_tol > 0.0 else -1
    for j in range(n_ev):
        ncross[lane, j] = 0
    n_tr[k] = n_transient[lane]
    n_end[k] = n_transient[lane] + n_samples * sample_every[lane]
    next_sample[k] = n_transient[lane] + sample_every[lane]
    DUE[k] = n_tr[k] if n_tr[k] > 0 else next_sample[k]
    n_stat[k] = 0
    n_ring[k] = 0
    for j in range(n_g):
        GP[j, k] = np.nan
        GMIN[j, k] = np.inf
        GMAX[j, k] = -np.inf
    for j in range(n_o):
        OMAX[j, k] = -np.inf
        OMIN[j, k] = np.inf
        OSQ[j, k] = 0.0
    R[k] = 0.0
    D[k] = 0.0
    return 1 if n_tr[k] == 0 else 0  # no transient: it samples from step 0


@nb.njit(_nrt=False, **_JIT, **INNER)
def _block_run_soa(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch):
    """The block loop of :func:`_sweep_worker` (its arrays allocated there). Compiled without
    reference counting (``_nrt=False``: it allocates nothing), so that passing the block's
    arrays to the inlined helpers and rotating the event history cost no atomic increments."""
    P, Y0, H, OMEGA, T0, n_transient, n_transient_max, sample_every = lanes
    conv_tol, conv_depth, n_samples, locate, bound, n_ev, n_obs, width = cfg
    start, queue, lane_nper, lane_tab, S_TAB, C_TAB, chain = sched
    (samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved, transient_steps,
     converged, steps) = out
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, G1, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, _ = scratch
    SE = PH[2]  # the phase at the grid point reached (see _lanes_phase)
    CE = PH[3]
    ns = Y0.shape[1]
    nxt = q0  # the next lane of the queue
    n_act = 0  # slots holding a running lane
    n_samp = 0  # of those, past their transient (or at its end): the statistics run
    ended = True
    while True:
        if ended:  # (re)fill the ended slots from the queue: a lane starts at its grid step 0
            ended = False
            loaded = False
            for k in range(nl):
                if not END[k]:
                    continue
                END[k] = False
                lane, nxt = _next_lane(k, nxt, q1, lanes, cfg, sched, out, slots, -1)
                if lane < 0:
                    continue
                loaded = True
                n_act += 1
                n_samp += _load_slot(k, lane, lanes, cfg, sched, out, blk, slots, GP)
                PH6[2, k] = S_TAB[OFF[k]]  # the phase at the start (see _lanes_phase)
                PH6[3, k] = C_TAB[OFF[k]]
                for q in range(ns):
                    HW3[0, q, k] = 0.5 * H[lane]
                    HW3[1, q, k] = H[lane]
                    HW3[2, q, k] = rk4_sixth(H[lane])
            if loaded and n_ev > 0:  # the events at the new lanes' start (G1: scratch here)
                _events_lanes(TT, Y, G1, PT, P, LANE, nl, SE, CE, ybuf, gb)
                for k in range(nl):
                    if ACT[k] and STEP[k] == 0:
                        for j in range(n_ev):
                            GS[j, k] = G1[j, k]
                            SIDE[j, k] = 1.0 if G1[j, k] > 0.0 else -1.0
        if n_act == 0:
            break
        # one grid step of every slot
        _lanes_rk4(STEP, nl, Y, Y1, K1, K2, K3, K4, TMP, FL, HW, TT, HB, T0B, PT, P, LANE, PH,
                   SC, ybuf, dbuf, OFF, PHASE, S_TAB, C_TAB)
        if n_ev > 0:
            _events_lanes(TT, Y1, G1, PT, P, LANE, nl, SE, CE, ybuf, gb)
            _lanes_screen(nl, G1, GS, GP, SIDE, GR, FLAG, locate)
        _lanes_finish(STEP, nl, NPER, Y, Y1, G1, GR, SIDE, FLAG, ACT, P, LANE, HB, T0B, OMEGA,
                      locate, ncross, unresolved, ys, y1s, sides, g1s, work, ybuf, gbuf,
                      (S_TAB, C_TAB), OFF)
        GP, GS, G1 = GS, G1, GP  # history of the grid values: g_{i}, g_{i+1}
        _advance(nl, STEP, PHASE, NPER)
        due = False
        for k in range(nl):
            MSK[k] = ACT[k] & ((PHASE[k] == 0) | (STEP[k] >= DUE[k]))
            due |= MSK[k]
        if due:
            for k in range(nl):  # health, end of the transient (out of line: a short scan)
                if MSK[k]:
                    gone, d_samp = _slot_check(k, Y, R, D, ys, LANE, STEP, PHASE, n_end, n_tr,
                                               next_sample, DUE, n_ring, ACT, END, GMIN, GMAX,
                                               OMAX, OMIN, OSQ, n_stat, lanes, cfg, out)
                    n_samp += d_samp
                    if gone:
                        ended = True
                        n_act -= 1
        # statistics over the sampled stretch, vectorised over the slots
        if n_samp == 0:
            continue
        sampling = False
        for k in range(nl):
            STAT[k] = ACT[k] & (STEP[k] > n_tr[k])
            n_stat[k] += 1 if STAT[k] else 0
            sampling |= STAT[k]
        if not sampling:
            continue
        for j in range(n_ev):
            for k in range(nl):
                g = GS[j, k]
                GMIN[j, k] = stat_min(GMIN[j, k], g, STAT[k])
                GMAX[j, k] = stat_max(GMAX[j, k], g, STAT[k])
        if n_obs > 0:  # at the grid point just reached: TT and the step's end phase (SE, CE)
            _observe_lanes(TT, Y, O, PT, P, LANE, nl, SE, CE, SC, ybuf, ob)
            for j in range(n_obs):
                for k in range(nl):
                    v = O[j, k]
                    OMAX[j, k] = stat_max(OMAX[j, k], v, STAT[k])
                    OMIN[j, k] = stat_min(OMIN[j, k], v, STAT[k])
                    OSQ[j, k] = stat_square(OSQ[j, k], v, STAT[k])
        due = False
        for k in range(nl):
            MSK[k] = STAT[k] & (STEP[k] >= DUE[k])
            due |= MSK[k]
        if not due:
            continue
        for k in range(nl):  # samples, end (out of line: a short scan)
            if MSK[k] and _slot_sample(k, Y, LANE, STEP, n_end, n_tr, next_sample, DUE, ACT, END,
                                       GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, lanes, cfg, out):
                ended = True
                n_act -= 1
                n_samp -= 1


@nb.njit(inline="always", **_JIT)
def _fused_steps(form, nl, locate, bound, Y, Y1, PT, SE, CE, H6, FLAG, G, ST, slots, ROT, PH):
    """One grid step of every slot, fused (see above), on flat views of the block arrays (rows
    of BLOCK slots, see :func:`_flat`): the trial into Y1, committed into Y
    where the slot is active and unflagged; the events' history shifted (GP = g_i, GS =
    g_{i+1}), graze flags into GR; the slots'
    clocks advanced, SE, CE the phase at the grid point reached. The statistics of a grid
    point are taken at the start of the step that leaves it, where STAT[k] (set by the step
    that reached it: the slot samples and has no bookkeeping due there; a flagged step's
    point too, its split done out of line in between), with the observables at the point k1
    is taken at. FLAG[k] = 1 where slot k's step is flagged,
    MSK[k] where it is flagged or has bookkeeping due (see :func:`_slot_out`: a sample, the
    transient's end or the lane's, or a period's start where the state is out of ``bound`` or
    not finite; a healthy period's start is done here). ``form``: a
    constant, the model's lane form (every active lane takes it). G: the events (GS, GP, GR,
    SIDE), ST: the statistics (GMIN, GMAX, OMAX, OMIN, OSQ). The phases at the step's middle
    and end (into the scratch rows PH) are SE, CE rotated (:func:`phase_rotate`) by the slot's
    increments ROT (rows: alpha, beta of half a step, of a whole one:
    :func:`phase_increments`), the period's end exactly (0, 1): the values of the slot's phase
    table (:func:`phase_table`), bitwise, in a vector loop of their own (no scalar gathers
    from the tables). ROT are rows of the
    block's scratch SC: the same rows as a new member of ``blk`` left the fused loop scalar
    (3.3x the time; the cause was not found). Returns (flagged, marked)."""
    GS, GP, GR, SIDE = G
    GMIN, GMAX, OMAX, OMIN, OSQ = ST
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    AH, BH, AD, BD = ROT
    SB, CB, SN, CN = PH
    for k in range(nl):
        s0 = SE[k]
        c0 = CE[k]
        sb, cb = phase_rotate(s0, c0, AH[k], BH[k])
        se, ce = phase_rotate(s0, c0, AD[k], BD[k])
        end = PHASE[k] + 1 == NPER[k]  # the period's end, as in the table
        SB[k] = sb
        CB[k] = cb
        SN[k] = 0.0 if end else se
        CN[k] = 1.0 if end else ce
    n_flag = 0
    n_out = 0
    for k in range(nl):
        h = HB[k]
        st = STEP[k]
        ph = PHASE[k]
        t0b = T0B[k]
        sb = SB[k]
        cb = CB[k]
        se = SN[k]
        ce = CN[k]
        y = _t_load(Y, k)
        hh = 0.5 * h
        k1 = _rhs_l(t0b + st * h, y, PT, k, SE[k], CE[k], form)
        tb = t0b + st * h + 0.5 * h
        k2 = _rhs_l(tb, _t_axpy(y, hh, k1), PT, k, sb, cb, form)
        k3 = _rhs_l(tb, _t_axpy(y, hh, k2), PT, k, sb, cb, form)
        te = t0b + (st + 1) * h
        k4 = _rhs_l(te, _t_axpy(y, h, k3), PT, k, se, ce, form)
        y1 = _t_comb(y, H6[k], k1, k2, k3, k4)
        g1 = _events_l(te, y1, PT, k, se, ce)
        # the statistics of the grid point the last step reached (this step's start), where
        # STAT[k]: its events GS (before the screen shifts them), its observables at the
        # point k1 is taken at (the same inputs as k1: shared arithmetic)
        pend = STAT[k] & ACT[k]
        o = _observe_l(t0b + st * h, y, PT, k, SE[k], CE[k], form)
        _t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, _t_like(GS, k, g1), o, pend)
        n_stat[k] += 1 if pend else 0
        hit = _t_screen(g1, GS, GP, SIDE, GR, k, locate)
        act = ACT[k]
        flagged = act & hit
        _t_store(Y1, k, y1, y1, True)
        _t_store(Y, k, y1, y, act & (not hit))
        SE[k] = se
        CE[k] = ce
        st1 = st + 1
        ph1 = ph + 1
        ph1 = 0 if ph1 == NPER[k] else ph1
        STEP[k] = st1
        PHASE[k] = ph1
        # a period's start needs the health check out of line only where it fails (NaN too)
        due = act & (((ph1 == 0) & (not _t_healthy(y1, bound))) | (st1 >= DUE[k]))
        # the grid point reached is sampled at the next step's start (a flagged step's too,
        # after its split out of line); one with bookkeeping due, out of line (_slot_out)
        STAT[k] = act & (st1 > n_tr[k]) & (not due)
        FLAG[k] = 1.0 if flagged else 0.0
        mark = flagged | due
        MSK[k] = mark
        n_flag += 1 if flagged else 0
        n_out += 1 if mark else 0
    return n_flag, n_out


_slot_check_i = nb.njit(inline="always", **_JIT)(_slot_check.py_func)
_finish_flagged_i = nb.njit(inline="always", **_JIT)(_finish_flagged.py_func)
_slot_sample_i = nb.njit(inline="always", **_JIT)(_slot_sample.py_func)


@optimise_once  # cold: optimised once where bound (see geardyn._bound_calls)
@nb.njit(_nrt=False, **_JIT, **INNER)
def _slots_out(nl, G1, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
    """:func:`_slot_out` for every marked slot (MSK), in one call per block step (a call
    passes every block array by value: one per slot cost a fifth of the run). The marked slots
    are gathered first, in a loop of their own: the loop over the block's slots with the
    bookkeeping inlined in it kept a dozen pointers stepping on the stack, half of this
    function's time on the paper's lanes, where ~1 slot in 60 is marked. Returns the number
    of lanes that ended."""
    MSK = slots[1]
    marked = scratch[10]
    n = 0
    for k in range(nl):
        if MSK[k]:
            marked[n] = k
            n += 1
    gone = 0
    for m in range(n):
        if _slot_out(marked[m], G1, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
            gone += 1
    return gone


@nb.njit(inline="always", **_JIT)
def _slot_out(k, G1, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
    """Slot k's step out of line (marked by :func:`_fused_steps`): a flagged step finished on
    the scalar path (:func:`_finish_flagged`), the bookkeeping of a period's start
    (:func:`_slot_check`), the statistics at the grid point reached (unless STAT[k]: the
    next step's start takes them), the sample and the end (:func:`_slot_sample`), in the order
    of the other paths. G1: the events at the grid point
    reached (the block's GS, see :func:`_fused_steps`). Returns True when the lane has ended."""
    P, Y0, H, OMEGA, T0, n_transient, n_transient_max, sample_every = lanes
    locate = cfg[3]
    (samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved, transient_steps,
     converged, steps) = out
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, _, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, _ = scratch
    if FLAG[k] != 0.0:
        _finish_flagged_i(k, STEP[k] - 1, NPER, Y, Y1, G1, GR, SIDE, P, LANE, HB, T0B, OMEGA,
                          locate, ncross, unresolved, ys, y1s, sides, g1s, work, ybuf, gbuf,
                          TABS, OFF)
    step = STEP[k]
    if PHASE[k] == 0 or step >= DUE[k]:
        gone, _ = _slot_check_i(k, Y, R, D, ys, LANE, STEP, PHASE, n_end, n_tr, next_sample, DUE,
                              n_ring, ACT, END, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, lanes, cfg,
                              out)
        if gone:
            return True
    if STAT[k]:  # a flagged step's grid point: sampled at the next step's start (_fused_steps)
        return False
    if step <= n_tr[k]:
        return False
    n_stat[k] += 1
    on = bool(True)  # noqa: UP018 - not a literal: the statistics' selects compile once
    for j in range(G1.shape[0]):
        g = G1[j, k]
        GMIN[j, k] = stat_min(GMIN[j, k], g, on)
        GMAX[j, k] = stat_max(GMAX[j, k], g, on)
    _slot_observe(k, T0B[k] + step * HB[k], SE[k], CE[k], Y, PT, (GMIN, GMAX, OMAX, OMIN, OSQ),
                  lanes, cfg, slots, scratch)
    if step < DUE[k]:
        return False
    return _slot_sample_i(k, Y, LANE, STEP, n_end, n_tr, next_sample, DUE, ACT, END, GMIN, GMAX,
                        OMAX, OMIN, OSQ, n_stat, lanes, cfg, out)


@nb.njit(inline="always", **_JIT)
def _slot_observe(k, t, s, c, Y, PT, ST, lanes, cfg, slots, scratch):
    """The observables' statistics (ST: OMAX, OMIN, OSQ of GMIN, GMAX, OMAX, OMIN, OSQ) of slot
    k at the grid point reached (time t, forcing phase s, c) in :func:`_slot_out`: the model's
    lane-scalar ``observe`` (:mod:`._pointer_template` replaces it)."""
    o = _observe_l(t, _t_load(Y, k), PT, k, s, c, FORM_GENERAL)
    _t_stats(ST[0], ST[1], ST[2], ST[3], ST[4], k, (), o, bool(True))  # noqa: UP018


@nb.njit(inline="always", **_JIT)
def _start_sides(k, lane, TT, Y, PT, GS, SIDE, SE, CE, lanes, cfg, scratch):
    """The events at the start of lane ``lane`` (loaded into slot k) into GS[:, k], their sides
    into SIDE[:, k], in :func:`_fused_run`: the model's lane-scalar ``events``
    (:mod:`._pointer_template` replaces it)."""
    _t_side(GS, SIDE, k, _events_l(TT[k], _t_load(Y, k), PT, k, SE[k], CE[k]))


@nb.njit(inline="always", **_JIT)
def _fused_run(form, q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch):
    """:func:`_block_run_soa` with the fused step loop (a model with lane-scalar functions),
    every lane of the worker's queue taking the model's lane form ``form`` (a constant: one
    copy of the loop per compiled function, see :func:`sweep`)."""
    locate = cfg[3]
    start, queue, lane_nper, lane_tab, S_TAB, C_TAB, chain = sched
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, G1, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    SE = PH[2]  # the phase at the grid point reached
    CE = PH[3]
    H6 = HW[2]  # h / 6 of slot k at [k] (row q = 0 of HW3[2])
    phx = (PH[0], PH[1], SC[0], SC[1])  # sin, cos at the step's middle; at its end (scratch)
    ROT = (SC[4], SC[5], SC[6], SC[7])  # the slot's phase increments (phase_increments)
    stats = _flat((GMIN, GMAX, OMAX, OMIN, OSQ))
    Yf, Y1f = _flat((Y, Y1, Y, Y, Y))[:2]
    GSf, GPf, GRf, SIDEf, _ = _flat((GS, GP, GR, SIDE, GR))
    nxt = q0  # the next lane of the queue
    n_act = np.int64(0)  # slots holding a running lane (not the literal 0: see _compact)
    nv = _padded(nl)  # the fused loop's slots: nl and idle ones (never filled, never active)
    for k in range(nl):  # every slot is free (an earlier pass, of another form, has ended)
        END[k] = True
        # and continues no chain (_chained): an earlier pass ran its chains to their ends, and
        # the fused loop advances a free slot's clock too (STEP > 0 would read as a lane held)
        STEP[k] = 0
    ended = True
    while True:
        if ended:  # (re)fill the ended slots from the queue: a lane starts at its grid step 0
            ended = False
            for k in range(nl):
                if not END[k]:
                    continue
                END[k] = False
                lane, nxt = _next_lane(k, nxt, q1, lanes, cfg, sched, out, slots, form)
                if lane < 0:
                    continue
                n_act += 1
                _load_slot(k, lane, lanes, cfg, sched, out, blk, slots, GP)
                SE[k] = S_TAB[OFF[k]]  # the phase at the start
                CE[k] = C_TAB[OFF[k]]
                ROT[0][k], ROT[1][k], ROT[2][k], ROT[3][k] = phase_increments(NPER[k])
                H6[k] = rk4_sixth(HB[k])
                _start_sides(k, lane, TT, Y, PT, GS, SIDE, SE, CE, lanes, cfg, scratch)
        if n_act == 0:
            break
        if nxt >= q1 and _padded(n_act) < nv:  # the queue is out: no slot empties for a lane
            _compact(nv, n_act, blk, slots)  # of it, so the block's running lanes move down
            # (n_act an int64 from the start: typed from a literal 0 first, numba compiled
            # _compact for Literal[int](0) as well)
            nv = _padded(n_act)
        n_flag, n_out = _fused_steps(form, nv, locate, cfg[4], Yf, Y1f, PT, SE, CE, H6, FLAG,
                                     (GSf, GPf, GRf, SIDEf), stats, slots, ROT, phx)
        if n_out > 0:
            gone = _slots_out(min(nl, nv), GS, SE, CE, (S_TAB, C_TAB), lanes, cfg, out, blk,
                              slots, scratch)
            if gone > 0:
                ended = True
                n_act -= gone


# One compiled copy of the loop per lane form (a second copy in the same function, or a branch
# around it, stops LLVM's alias analysis).
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _block_run_form0(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch):
    """:func:`_fused_run` in the model's general lane form (FORM_GENERAL)."""
    _fused_run(FORM_GENERAL, q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _block_run_form1(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch):
    """:func:`_fused_run` in the lane form FORM_QUIET."""
    _fused_run(FORM_QUIET, q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _block_run_form2(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch):
    """:func:`_fused_run` in the lane form FORM_LOAD."""
    _fused_run(FORM_LOAD, q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch)


def sweep(lanes, cfg, work_queues, out):
    """Integrate every lane l from time T0[l] (a whole number of forcing periods):
    ``n_transient[l]`` grid steps, then ``n_samples`` section samples, one every
    ``sample_every[l]`` grid steps, with statistics over the sampled stretch. Arguments:
    :class:`~geardyn.core.kernel_args.LaneInputs`, ``SweepConfig``, ``Schedule`` and
    ``LaneOutputs`` (preallocated, filled here).

    With ``conv_tol > 0`` the transient goes on, one section period at a time up to
    ``n_transient_max[l]`` steps, until the section point is estimated within
    conv_tol (1 + |point|) of a periodic orbit of period k <= ``conv_depth`` sections: from the
    contraction of the differences |x_n - x_{n-k}| over successive k sections (see
    :func:`_settled`; a slowly attracting orbit, Floquet multiplier near +-1, needs the longer
    transient it takes); converged[l] is 1 then, 0 if the limit came first, -1 without the
    test; transient_steps[l] is the transient used.

    Worker w (in parallel, on threads: :func:`geardyn.solvers._parallel.run_workers`) runs the
    lanes queue[start[w]:start[w + 1]] (a static,
    cost-balanced schedule made by the caller) through one block of ``width`` slots that are
    refilled from the queue as lanes end (see above). Lanes are independent, so results do not
    depend on the schedule, the width or the threads.

    Outputs: samples[L, n_samples, ns] (NaN where diverged), final[L, ns], status[L],
    gmin/gmax[L, n_ev] (extremes of the events at grid points), ncross[L, n_ev] (edge crossings
    while sampling), omax/omin/orms[L, n_obs] (extremes and RMS of the observables at grid
    points), unresolved[L] (steps that reached the split limit), transient_steps[L],
    converged[L] (above), steps[L] (grid steps integrated, added to: each lane is run once, so
    it equals the lane's transient plus sampled steps, or where it diverged; 0 for a chain's
    lanes not run). A lane that diverges stops there (no further steps, crossings or
    statistics).
    """
    args = (lanes, cfg, work_queues, out)
    n_workers = work_queues.start.size - 1
    if not FUSED:
        run_workers(_sweep_worker, n_workers, args)
        return
    present = _forms_present(lanes.P, work_queues)
    used = [f for f in _FORM_ORDER if present[:, f].any()]
    workers = {f: _FORM_WORKERS[f] for f in used}  # (compiled on their first call)

    def passes(w, *args):  # one pass of worker w's queue per lane form present in it
        for f in used:
            if present[w, f]:
                workers[f](w, *args)

    run_workers(passes, n_workers, args)


#: The sweep's workers by lane form, and the order of a worker's passes (one per form).
_FORM_WORKERS = {FORM_GENERAL: _sweep_worker_form0, FORM_QUIET: _sweep_worker_form1,
                 FORM_LOAD: _sweep_worker_form2}
_FORM_ORDER = (FORM_QUIET, FORM_LOAD, FORM_GENERAL)
