"""The sweep of the pointer kernel path: the fused block loop with the model called once per grid
step for a block of slots, compiled once for every model.

This file is a template (see :mod:`._pointer_kernels`): its ``CORE-IMPORT`` statement is
replaced by the names of the trajectory and sweep module of the pointer model
(:mod:`._pointer_model`; the ``"rk4"`` template bound to it), so that it uses that module's
block arrays, lane loading, bookkeeping and split step; as it stands it is a valid module bound
to the template's test oscillator. Nothing here depends on the model: the generated module is
the same text for every model, compiled and cached once.

Each grid step of a block (:func:`_p_steps`) is the fused step of
:func:`._kernel_template._fused_steps` in three parts: the slots' times and forcing phases
(rows of X), the model's fused trial step for every slot in one call through its address
(the model's ``c_trial``: the four RK4 stages with the state in registers, the events and the
observables at the trial's end, written to Y1, G1, O), then the screen, the commit, the clocks
and the statistics as loops over slots. Flagged slots and bookkeeping are done out of line
(:func:`_p_slots_out`) as on the fused path; a flagged step's split is the model's own split
step (its core module's ``_split_step``, compiled with the model inlined), called through its
address. The operations are those of the fused loop, in the same order: the results are bitwise
the same.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn.solvers._kernel_template import (  # CORE-IMPORT
    _JIT,
    _JIT_NOALIAS,
    GRAZE_ROW,
    _block_arrays,
    _load_slot,
    _next_lane,
    _slot_check_i,
    _slot_sample_i,
    events,
    observe,
)
from geardyn.solvers._parallel import run_workers
from geardyn.solvers._pointer_calls import N_ADDRESSES, TRIAL_ROWS, call_flat, call_trial
from geardyn.solvers._step_shared import (
    BLOCK,
    _padded,
    _pick,
    phase_increments,
    phase_rotate,
    rk4_sixth,
    screen_grid,
    stat_max,
    stat_min,
    stat_square,
)
from geardyn.solvers._sweep_books import _compact

__all__ = ["sweep"]


@nb.njit(inline="always", **_JIT)
def _p_steps(nl, n_ev, n_obs, locate, bound, addr, X, BAD, Y, Y1, G1, O, PT, SE, CE, H6, FLAG,
             G, ST, slots, ROT):
    """One grid step of every slot (see the module docstring): the trial into Y1, committed
    into Y where the slot is active and unflagged; the events' history shifted (GP = g_i,
    GS = g_{i+1}), graze flags into GR; the clocks advanced, SE, CE the phase at the grid point
    reached; the statistics of the slots that sample and need nothing out of line. FLAG[k] = 1
    where slot k's step is flagged, MSK[k] where it is flagged or has bookkeeping due (as
    :func:`._kernel_template._fused_steps`). Returns (flagged, marked)."""
    GS, GP, GR, SIDE = G
    GMIN, GMAX, OMAX, OMIN, OSQ = ST
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    AH, BH, AD, BD = ROT
    ns = Y.shape[0]
    for k in range(nl):
        s0 = SE[k]
        c0 = CE[k]
        sb, cb = phase_rotate(s0, c0, AH[k], BH[k])
        se, ce = phase_rotate(s0, c0, AD[k], BD[k])
        end = PHASE[k] + 1 == NPER[k]  # the period's end, as in the table
        h = HB[k]
        st = STEP[k]
        t0b = T0B[k]
        X[0, k] = t0b + st * h
        X[1, k] = t0b + st * h + 0.5 * h
        X[2, k] = t0b + (st + 1) * h
        X[3, k] = h
        X[4, k] = H6[k]
        X[5, k] = s0
        X[6, k] = c0
        X[7, k] = sb
        X[8, k] = cb
        X[9, k] = 0.0 if end else se
        X[10, k] = 1.0 if end else ce
        FLAG[k] = 0.0
        BAD[k] = 0.0
    call_trial(addr, X, Y, Y1, G1, O, PT, nl)
    for j in range(n_ev):
        for k in range(nl):
            g1 = G1[j, k]
            g0 = GS[j, k]
            gr, fl = screen_grid(g1, SIDE[j, k], g0, GP[j, k], locate)
            GR[j, k] = _pick(gr, 1.0, 0.0)
            GP[j, k] = g0
            GS[j, k] = g1
            FLAG[k] += _pick(fl, 1.0, 0.0)
    for q in range(ns):
        for k in range(nl):
            BAD[k] += _pick(abs(Y1[q, k]) <= bound, 0.0, 1.0)
    n_flag = 0
    n_out = 0
    for k in range(nl):
        hit = FLAG[k] != 0.0
        act = ACT[k]
        flagged = act & hit
        SE[k] = X[9, k]
        CE[k] = X[10, k]
        st1 = STEP[k] + 1
        ph1 = PHASE[k] + 1
        ph1 = 0 if ph1 == NPER[k] else ph1
        STEP[k] = st1
        PHASE[k] = ph1
        # a period's start needs the health check out of line only where it fails (NaN too)
        due = act & (((ph1 == 0) & (BAD[k] != 0.0)) | (st1 >= DUE[k]))
        stat = act & (st1 > n_tr[k]) & (not hit) & (not due)
        STAT[k] = stat
        n_stat[k] += 1 if stat else 0
        FLAG[k] = 1.0 if flagged else 0.0
        BAD[k] = 1.0 if act & (not hit) else 0.0  # the commit
        mark = flagged | due
        MSK[k] = mark
        n_flag += 1 if flagged else 0
        n_out += 1 if mark else 0
    for q in range(ns):
        for k in range(nl):
            Y[q, k] = _pick(BAD[k] != 0.0, Y1[q, k], Y[q, k])
    for j in range(n_ev):
        for k in range(nl):
            g = G1[j, k]
            GMIN[j, k] = stat_min(GMIN[j, k], g, STAT[k])
            GMAX[j, k] = stat_max(GMAX[j, k], g, STAT[k])
    for j in range(n_obs):
        for k in range(nl):
            v = O[j, k]
            OMAX[j, k] = stat_max(OMAX[j, k], v, STAT[k])
            OMIN[j, k] = stat_min(OMIN[j, k], v, STAT[k])
            OSQ[j, k] = stat_square(OSQ[j, k], v, STAT[k])
    return n_flag, n_out


@nb.njit(_nrt=False, **_JIT)
def _p_slots_out(nl, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
    """:func:`_p_slot_out` for every marked slot (MSK), gathered first (as
    :func:`._kernel_template._slots_out`). Returns the number of lanes that ended."""
    MSK = slots[1]
    marked = scratch[10]
    n = 0
    for k in range(nl):
        if MSK[k]:
            marked[n] = k
            n += 1
    gone = 0
    for m in range(n):
        if _p_slot_out(marked[m], SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
            gone += 1
    return gone


@nb.njit(inline="always", **_JIT)
def _p_slot_out(k, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
    """Slot k's step out of line, as :func:`._kernel_template._slot_out`, the observables at
    the grid point reached through the model's array form."""
    P, Y0, H, OMEGA, T0, n_transient, n_transient_max, sample_every = lanes
    locate = cfg[3]
    n_obs = cfg[6]
    (samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved, transient_steps,
     converged, steps) = out
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, _, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, _ = scratch
    if FLAG[k] != 0.0:
        _p_finish_flagged(k, STEP[k] - 1, NPER, Y, Y1, GS, GR, SIDE, P, LANE, HB, T0B, OMEGA,
                          locate, ncross, unresolved, ys, y1s, sides, g1s, work, ybuf, gbuf,
                          TABS, OFF)
    step = STEP[k]
    if PHASE[k] == 0 or step >= DUE[k]:
        gone, _ = _slot_check_i(k, Y, R, D, ys, LANE, STEP, PHASE, n_end, n_tr, next_sample, DUE,
                                n_ring, ACT, END, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, lanes, cfg,
                                out)
        if gone:
            return True
    if step <= n_tr[k]:
        return False
    n_stat[k] += 1
    for j in range(cfg[5]):
        g = GS[j, k]
        GMIN[j, k] = stat_min(GMIN[j, k], g, True)
        GMAX[j, k] = stat_max(GMAX[j, k], g, True)
    if n_obs > 0:
        for q in range(Y.shape[0]):
            ybuf[q] = Y[q, k]
        observe(T0B[k] + step * HB[k], ybuf, ob, P[LANE[k]], SE[k], CE[k])
        for j in range(n_obs):
            v = ob[j]
            OMAX[j, k] = stat_max(OMAX[j, k], v, True)
            OMIN[j, k] = stat_min(OMIN[j, k], v, True)
            OSQ[j, k] = stat_square(OSQ[j, k], v, True)
    if step < DUE[k]:
        return False
    return _slot_sample_i(k, Y, LANE, STEP, n_end, n_tr, next_sample, DUE, ACT, END, GMIN, GMAX,
                          OMAX, OMIN, OSQ, n_stat, lanes, cfg, out)


@nb.njit(inline="always", **_JIT)
def _p_finish_flagged(k, i, NPER, Y, Y1, G1, GR, SIDE, P, LANE, HB, T0B, OMEGA, locate, NCROSS,
                      UNRES, ys, y1s, sides, g1s, work, ybuf, gbuf, TABS, OFF):
    """:func:`._kernel_template._finish_flagged`, the split step the model's own (its core
    module's ``_split_step``, compiled with the model and called through its address)."""
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
    p = P[lane]
    UNRES[lane] += call_flat(np.int64(p[p.size - N_ADDRESSES + 4]), (
        np.int64(i), T0B[k], ys, y1s, p, HB[k], OMEGA[lane], NPER[k], S_TAB[j0], C_TAB[j0],
        S_TAB[j0 + 2], C_TAB[j0 + 2], sides, g1s, NCROSS[lane], work, ybuf, gbuf))
    for q in range(ns):
        Y[q, k] = ys[q]
    for j in range(n_ev):
        SIDE[j, k] = float(sides[j])
        G1[j, k] = g1s[j]


@nb.njit(_nrt=False, **_JIT_NOALIAS)
def _p_block_run(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch, X, BAD):
    """The block loop of a worker (as :func:`._kernel_template._fused_run`, one pass, every
    lane), the model's trial step called through its address (X, BAD: the trial's times and
    phases, and a row of scratch)."""
    P = lanes[0]
    n_ev, n_obs, locate, bound = cfg[5], cfg[6], cfg[3], cfg[4]
    start, queue, lane_nper, lane_tab, S_TAB, C_TAB, chain = sched
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, G1, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, _ = scratch
    addr = np.int64(P[0, P.shape[1] - N_ADDRESSES + 3])  # the model's fused trial step
    SE = PH[2]  # the phase at the grid point reached
    CE = PH[3]
    H6 = HW[2]  # h / 6 of slot k at [k] (row q = 0 of HW3[2])
    ROT = (SC[4], SC[5], SC[6], SC[7])  # the slot's phase increments (phase_increments)
    nxt = q0
    n_act = np.int64(0)
    nv = _padded(nl)
    for k in range(nl):
        END[k] = True
        STEP[k] = 0
    ended = True
    while True:
        if ended:  # (re)fill the ended slots from the queue: a lane starts at its grid step 0
            ended = False
            for k in range(nl):
                if not END[k]:
                    continue
                END[k] = False
                lane, nxt = _next_lane(k, nxt, q1, lanes, cfg, sched, out, slots, -1)
                if lane < 0:
                    continue
                n_act += 1
                _load_slot(k, lane, lanes, cfg, sched, out, blk, slots, GP)
                SE[k] = S_TAB[OFF[k]]  # the phase at the start
                CE[k] = C_TAB[OFF[k]]
                ROT[0][k], ROT[1][k], ROT[2][k], ROT[3][k] = phase_increments(NPER[k])
                H6[k] = rk4_sixth(HB[k])
                if n_ev > 0:
                    for q in range(Y.shape[0]):
                        ybuf[q] = Y[q, k]
                    events(TT[k], ybuf, gb, P[lane], SE[k], CE[k])
                    for j in range(n_ev):
                        GS[j, k] = gb[j]
                        SIDE[j, k] = _pick(gb[j] > 0.0, 1.0, -1.0)
        if n_act == 0:
            break
        if nxt >= q1 and _padded(n_act) < nv:  # the queue is out: running lanes move down
            _compact(nv, n_act, blk, slots)
            nv = _padded(n_act)
        n_flag, n_out = _p_steps(nv, n_ev, n_obs, locate, bound, addr, X, BAD, Y, Y1, G1, O,
                                 PT, SE, CE, H6, FLAG, (GS, GP, GR, SIDE),
                                 (GMIN, GMAX, OMAX, OMIN, OSQ), slots, ROT)
        if n_out > 0:
            gone = _p_slots_out(min(nl, nv), SE, CE, (S_TAB, C_TAB), lanes, cfg, out, blk,
                                slots, scratch)
            if gone > 0:
                ended = True
                n_act -= gone


@nb.njit(nogil=True, **_JIT)
def _p_worker(w, lanes, cfg, sched, out):
    """Worker w of :func:`sweep`: its queue of lanes through one block of BLOCK refilling
    slots."""
    start = sched[0]
    q0 = start[w]
    q1 = start[w + 1]
    nl = min(max(min(cfg[7], q1 - q0), 0), BLOCK)
    if nl > 0:
        blk, slots, scratch = _block_arrays(BLOCK, lanes, cfg)
        X = np.zeros((TRIAL_ROWS, BLOCK))
        BAD = np.zeros(BLOCK)
        _p_block_run(q0, q1, nl, lanes, cfg, sched, out, blk, slots, scratch, X, BAD)


def sweep(lanes, cfg, work_queues, out):
    """The sweep kernel (:func:`._kernel_template.sweep`'s arguments and results) on the
    pointer path: every coefficient row of ``lanes.P`` ends with the model's callback
    addresses (:mod:`._pointer_kernels`)."""
    run_workers(_p_worker, work_queues.start.size - 1, (lanes, cfg, work_queues, out))
