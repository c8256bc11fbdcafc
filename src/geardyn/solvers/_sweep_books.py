"""The sweep's bookkeeping that does not depend on the model, compiled once for every model.

A lane's start and end in a block (:func:`_alloc`, :func:`_chained`, :func:`_move_slot`), the
checks at a period's start (transient end, settled section points: :func:`_slot_check`,
:func:`_settled`), its samples (:func:`_slot_sample`), its results (:func:`_write_out`) and the
compaction of a worker's finished lanes (:func:`_compact`). The kernel template
(:mod:`._kernel_template`) imports them; they take only arrays and numbers, so numba compiles
and caches them once, not once per model.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn.solvers._step_shared import (
    _JIT,
    INNER,
    STATUS_DIVERGED,
    STATUS_OK,
    event_buffer,
)

#: A difference of section points below this fraction of the tolerance counts as settled
#: whatever its contraction rate (the rate of differences at round-off level is noise).
CONV_ROUNDOFF = 1.0e-3


@nb.njit(inline="always", **_JIT)
def _full(shape, value):
    """A new float array of ``shape`` filled with ``value``: ``np.zeros`` filled in place, so
    that the kernels' allocations compile numba's implementations of ``np.zeros`` only (each
    of ``np.full``, ``np.ones`` and ``np.zeros`` is compiled per shape and dtype it is used
    with)."""
    a = np.zeros(shape)
    a[...] = value
    return a


@nb.njit(**_JIT, **INNER)
def _alloc(nb_lanes, ns, n_ev):
    Y = np.zeros((nb_lanes, ns))
    work = np.zeros((7, ns))
    SIDE = np.zeros((nb_lanes, n_ev), np.int64)
    SIDE[...] = 1
    gbuf = event_buffer(np.int64(nb_lanes), n_ev)  # int64 (not a literal): one compile
    return (Y, Y.copy(), Y.copy(), Y.copy(), Y.copy(), Y.copy(), Y.copy(), np.zeros(nb_lanes),
            np.zeros((nb_lanes, n_ev)), SIDE, work, np.zeros(ns), gbuf)


@nb.njit(**_JIT, **INNER)
def _section_diffs(y, R, n, D):
    """Record the differences of the new section point y (the n-th, counting from 0) to the
    ring R of earlier ones: D[n % len(D), k - 1] = max_q |y_q - x_{n-k,q}| for k = 1 ..
    min(n, len(R)) (x_{n-k} in row (n - k) % len(R) of R)."""
    depth = R.shape[0]
    row = n % D.shape[0]
    for k in range(1, min(n, depth) + 1):
        m = (n - k) % depth
        d = 0.0
        for q in range(y.size):
            d = max(d, abs(y[q] - R[m, q]))
        D[row, k - 1] = d


@nb.njit(**_JIT, **INNER)
def _settled(y, D, n, tol):
    """True when the section point y (the n-th) is estimated within tol (1 + max |y|) of a
    period-k orbit for some k <= depth = D.shape[1]: with the differences d_j = |x_j - x_{j-k}|
    (recorded by :func:`_section_diffs`), D0 = max over j = n-k+1..n, D1 over the k before and
    D2 over the k before those, the contraction per k sections is r = max(D0 / D1, D1 / D2)
    (two windows: the rate is confirmed, not read off one ratio) and the distance left to the
    orbit is about D0 r / (1 - r) (a geometric series). Needs 4k points; D0 below
    CONV_ROUNDOFF tol counts as settled."""
    scale = 0.0
    for q in range(y.size):
        scale = max(scale, abs(y[q]))
    lim = tol * (1.0 + scale)
    rows = D.shape[0]
    for k in range(1, D.shape[1] + 1):
        if n < 4 * k - 1:
            break
        d0 = 0.0
        d1 = 0.0
        d2 = 0.0
        for i in range(k):
            d0 = max(d0, D[(n - i) % rows, k - 1])
            d1 = max(d1, D[(n - k - i) % rows, k - 1])
            d2 = max(d2, D[(n - 2 * k - i) % rows, k - 1])
        if d0 <= CONV_ROUNDOFF * lim:
            return True
        if d0 < d1 and d1 < d2:
            r = max(d0 / d1, d1 / d2)
            if d0 * r <= lim * (1.0 - r):  # d0 r / (1 - r) <= lim
                return True
    return False


@nb.njit(inline="always", **_JIT)
def _healthy_lane(Y, k, bound):
    for q in range(Y.shape[0]):
        if not (abs(Y[q, k]) <= bound):  # False for NaN too
            return False
    return True


@nb.njit(_nrt=False, **_JIT, **INNER)
def _write_out(k, lane, n_ev, n_obs, n_tr, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, status,
               transient_steps, gmin, gmax, omax, omin, orms, STEP, steps):
    """The statistics of the lane that has ended in slot k, to its outputs; its grid steps
    added to ``steps[lane]`` (a count of the work done: a lane run twice would show). Called,
    not inlined: once per lane, from two sites of the bookkeeping that the block loops inline
    (a copy each cost compile time)."""
    transient_steps[lane] = n_tr[k]
    steps[lane] += STEP[k]
    for j in range(n_ev):
        gmin[lane, j] = GMIN[j, k]
        gmax[lane, j] = GMAX[j, k]
    for j in range(n_obs):
        omax[lane, j] = OMAX[j, k]
        omin[lane, j] = OMIN[j, k]
        if n_stat[k] > 0 and status[lane] == STATUS_OK:
            orms[lane, j] = np.sqrt(OSQ[j, k] / n_stat[k])
        else:
            orms[lane, j] = np.nan


@nb.njit(_nrt=False, **_JIT, **INNER)
def _chained(k, lanes, cfg, sched, out, slots):
    """The lane that follows the one that has just ended in slot k on its chain
    (``sched.chain``: a sweep by continuation, each point starting where the one before
    ended), its start state and time set to that lane's final state and end time (the time
    as :meth:`~geardyn.core.plan.LanePlan.final_time` computes it); -1 when there is no
    chain, the slot has held no lane in this pass (STEP[k] == 0: a lane takes at least one
    step; the fused loop's passes reset it), the chain ends there, or that lane did not end
    well (the caller restarts the rest of the chain). A slot without a lane must never read as
    one: LANE[k] is then stale (0, or a lane whose chain has run), and continuing from it
    would run a chain's tail a second time, in another worker too (a race on its outputs;
    bench/determinism.py checks for it). Out of line:
    called once per lane, and kept out of the block loop's function, whose size decides
    whether LLVM vectorises its step loop."""
    chain = sched[6]
    if chain.size == 0:
        return -1
    LANE = slots[4]
    STEP = slots[5]
    if STEP[k] == 0:  # holds no lane (see above)
        return -1
    prev = LANE[k]
    succ = chain[prev]
    status = out[2]
    if succ < 0 or status[prev] != STATUS_OK:
        return -1
    Y0 = lanes[1]
    OMEGA = lanes[3]
    T0 = lanes[4]
    sample_every = lanes[7]
    final = out[1]
    transient_steps = out[10]
    nper = sched[2][prev]
    for q in range(Y0.shape[1]):
        Y0[succ, q] = final[prev, q]
    periods = transient_steps[prev] // nper + cfg[2] * (sample_every[prev] // nper)
    T0[succ] = T0[prev] + periods * (2.0 * np.pi / OMEGA[prev])
    return succ


@nb.njit(_nrt=False, **_JIT, **INNER)
def _slot_check(k, Y, R, D, ys, LANE, STEP, PHASE, n_end, n_tr, next_sample, DUE, n_ring, ACT,
                END, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, lanes, cfg, out):
    """Slot k at the start of a period or at its due step (see :func:`_sweep_worker`): its
    health (at a period's start or the lane's end; a diverged lane ends here) and the end of its
    transient. Returns (ended, change of the count of sampling slots)."""
    n_transient_max, sample_every = lanes[6], lanes[7]
    conv_tol, bound, n_ev, n_obs = cfg[0], cfg[4], cfg[5], cfg[6]
    (samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved, transient_steps,
     converged, steps) = out
    lane = LANE[k]
    step = STEP[k]
    if (PHASE[k] == 0 or step == n_end[k]) and not _healthy_lane(Y, k, bound):
        _diverged(k, lane, n_ev, n_obs, n_tr, ACT, END, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat,
                  STEP, samples, final, status, transient_steps, gmin, gmax, omax, omin, orms,
                  steps)
        return True, -1 if step > n_tr[k] else 0
    d_samp = 0
    if step == n_tr[k]:
        _transient_end(k, lane, Y, ys, R, D, n_ring, n_tr, n_end, next_sample, conv_tol,
                       converged, sample_every, n_transient_max, ncross, n_ev)
        d_samp = 1 if step == n_tr[k] else 0  # not extended: sampling starts
    DUE[k] = n_tr[k] if n_tr[k] > step else next_sample[k]
    return False, d_samp


@nb.njit(_nrt=False, **_JIT, **INNER)
def _diverged(k, lane, n_ev, n_obs, n_tr, ACT, END, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, STEP,
              samples, final, status, transient_steps, gmin, gmax, omax, omin, orms, steps):
    """Slot k's lane has diverged (:func:`_slot_check`): it ends there, its samples and final
    state NaN, its statistics written out. Called, not inlined (once per diverged lane)."""
    status[lane] = STATUS_DIVERGED
    ACT[k] = False
    END[k] = True
    for r in range(samples.shape[1]):
        for q in range(samples.shape[2]):
            samples[lane, r, q] = np.nan
    for q in range(final.shape[1]):
        final[lane, q] = np.nan
    _write_out(k, lane, n_ev, n_obs, n_tr, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, status,
               transient_steps, gmin, gmax, omax, omin, orms, STEP, steps)


@nb.njit(_nrt=False, **_JIT, **INNER)
def _slot_sample(k, Y, LANE, STEP, n_end, n_tr, next_sample, DUE, ACT, END, GMIN, GMAX, OMAX,
                 OMIN, OSQ, n_stat, lanes, cfg, out):
    """Slot k (sampling) at its due step: the section sample, the lane's end. Returns True
    when the lane has ended."""
    sample_every = lanes[7]
    n_ev, n_obs = cfg[5], cfg[6]
    (samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved, transient_steps,
     converged, steps) = out
    ns = Y.shape[0]
    lane = LANE[k]
    step = STEP[k]
    if step == next_sample[k]:
        r = (step - n_tr[k]) // sample_every[lane] - 1
        for q in range(ns):
            samples[lane, r, q] = Y[q, k]
        next_sample[k] += sample_every[lane]
    DUE[k] = next_sample[k]
    if step != n_end[k]:
        return False
    ACT[k] = False
    END[k] = True
    for q in range(ns):
        final[lane, q] = Y[q, k]
    _write_out(k, lane, n_ev, n_obs, n_tr, GMIN, GMAX, OMAX, OMIN, OSQ, n_stat, status,
               transient_steps, gmin, gmax, omax, omin, orms, STEP, steps)
    return True


@nb.njit(_nrt=False, **_JIT, **INNER)
def _transient_end(k, lane, Y, ys, R, D, n_ring, n_tr, n_end, next_sample, conv_tol, converged,
                   sample_every, n_transient_max, ncross, n_ev):
    """Slot k's lane has reached the end of its transient: with the convergence test on and the
    lane not settled yet (:func:`_settled`), one more section period of transient (up to the
    limit); else the sampled stretch starts (its crossing counts from 0). Called, not inlined
    (once per lane, or per section period of a transient extended by the convergence test)."""
    if conv_tol > 0.0 and converged[lane] == 0:
        every = sample_every[lane]
        for q in range(ys.size):
            ys[q] = Y[q, k]
        _section_diffs(ys, R[k], n_ring[k], D[k])
        if _settled(ys, D[k], n_ring[k], conv_tol):
            converged[lane] = 1
        elif n_tr[k] + every <= n_transient_max[lane]:
            slot = n_ring[k] % R.shape[1]
            for q in range(ys.size):
                R[k, slot, q] = ys[q]
            n_ring[k] += 1
            n_tr[k] += every
            n_end[k] += every
            next_sample[k] += every
            return
    for j in range(n_ev):
        ncross[lane, j] = 0


@nb.njit(_nrt=False, **_JIT, **INNER)
def _compact(nv, n_act, blk, slots):
    """Move the running lanes of slots n_act.. (n_act: the number of running lanes) of the
    fused loop's nv slots into the free slots below n_act, so that the loop can run over
    _padded(n_act) slots: once a worker's queue is out, its block's last lanes (the longest, or
    a branch's chain of continued points) would otherwise drag every vector of the block along
    to the end. A lane's arithmetic does not depend on its slot: its results stay bitwise the
    same. Out of line: called at most once per vector of slots freed."""
    ACT = slots[2]
    dst = 0
    for src in range(n_act, nv):
        if not ACT[src]:
            continue
        while ACT[dst]:
            dst += 1
        _move_slot(src, dst, blk, slots)


@nb.njit(inline="always", **_JIT)
def _move_slot(src, dst, blk, slots):
    """Slot src's lane into the free slot dst: every column that lives from one step to the next
    (state, coefficients, phase, events and their history, statistics, convergence ring,
    clocks); src is left free (not running, not to be refilled, nothing marked, no lane
    held)."""
    (R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, G1, GR, SIDE, FLAG,
     GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk
    (STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE,
     n_stat, n_ring) = slots
    for A in (Y, PT, PH6, SC, GP, GS, G1, GR, SIDE, GMIN, GMAX, OMAX, OMIN, OSQ):
        for j in range(A.shape[0]):
            A[j, dst] = A[j, src]
    for j in range(HW3.shape[0]):
        for q in range(HW3.shape[1]):
            HW3[j, q, dst] = HW3[j, q, src]
    for j in range(R.shape[1]):
        for q in range(R.shape[2]):
            R[dst, j, q] = R[src, j, q]
    for j in range(D.shape[1]):
        for q in range(D.shape[2]):
            D[dst, j, q] = D[src, j, q]
    TT[dst] = TT[src]
    FLAG[dst] = FLAG[src]
    for B in (STAT, MSK, ACT, END):
        B[dst] = B[src]
    for I in (LANE, STEP, PHASE, NPER, OFF, n_end, n_tr, next_sample, DUE, n_stat, n_ring):
        I[dst] = I[src]
    HB[dst] = HB[src]
    T0B[dst] = T0B[src]
    ACT[src] = False
    END[src] = False  # not refilled in this pass (a next pass starts every slot afresh)
    MSK[src] = False
    STAT[src] = False
    FLAG[src] = 0.0
