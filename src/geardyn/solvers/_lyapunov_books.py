"""The Lyapunov kernels' bookkeeping that does not depend on the model, compiled once for every
model: the orthonormalisation of the tangent vectors and their stretch logs, the blocks of a
lane's measurement and their standard error, and the lane books of the lane-block kernel (when
a lane is due, its transient and measured steps, its result). The Lyapunov template
(:mod:`._lyapunov_template`) imports them; they take only arrays and numbers, so numba compiles
and caches them once, not once per model.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._step_shared import (
    _JIT,
    INNER,
    STATUS_DIVERGED,
    STATUS_OK,
    phase_table_values,
)

#: Columns of the per-lane integer state of a block (IST): the step of the last
#: renormalisation, the block being measured, transient and measured steps, their total, the
#: number of blocks, the lane's next due step.
_LAST, _CUR, _NTR, _NST, _TOTAL, _NBK, _DUE = range(7)


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _orthonormalise(Z, logs, add):
    """Modified Gram-Schmidt on the tangent rows 1.. of Z; writes the log of R's diagonal to logs
    when ``add``. Returns False if a vector vanished or is not finite."""
    m, ns = Z.shape
    for j in range(1, m):
        for i in range(1, j):
            d = 0.0
            for q in range(ns):
                d += Z[j, q] * Z[i, q]
            for q in range(ns):
                Z[j, q] -= d * Z[i, q]
        r = 0.0
        for q in range(ns):
            r += Z[j, q] * Z[j, q]
        r = math.sqrt(r)
        if not (r > 0.0 and math.isfinite(r)):
            return False
        if add:
            logs[j - 1] = math.log(r)
        inv = 1.0 / r
        for q in range(ns):
            Z[j, q] *= inv
    return True


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _stretch_logs(Z, C, logs):
    """The logs of R's diagonal that orthonormalising Z's tangent rows would give now (the
    stretch since the last renormalisation), computed on the copy C: Z is left as it is."""
    m, ns = Z.shape
    for j in range(m):
        for q in range(ns):
            C[j, q] = Z[j, q]
    for j in range(1, m):
        logs[j - 1] = np.nan
    _orthonormalise(C, logs, np.bool_(True))  # np.bool_: see _lanes_init


@nb.njit(**_JIT, **INNER)
def _block_bounds(n_steps, n_per, n_blocks):
    """Ends of the blocks of the measuring window (measured steps): whole forcing periods
    (``n_per`` steps; one step for an autonomous model, n_per = 1), as equal as they divide, at
    most ``n_blocks`` and at most one per period."""
    units = n_steps // n_per
    nbk = max(min(n_blocks, units), 1)
    ends = np.zeros(nbk, np.int64)
    for b in range(nbk):
        ends[b] = ((b + 1) * units // nbk) * n_per
    ends[nbk - 1] = n_steps
    return ends


@nb.njit(**_JIT, **INNER)
def _block_stderr(blk, ends, h, err):
    """Standard error of each exponent from its blocks: blk[b, j] (log stretch in block b),
    block b ending at measured step ends[b]. With rates r_b = blk[b] / T_b, weights T_b and
    lambda = sum(blk) / sum(T_b): err^2 = n / (n - 1) sum(T_b^2 (r_b - lambda)^2) / T^2 (for
    equal blocks std(r, ddof=1)^2 / n). Writes err[j] (NaN with fewer than 2 blocks)."""
    n, k = blk.shape
    for j in range(k):
        err[j] = np.nan
    if n < 2:
        return
    tt = ends[n - 1] * h
    for j in range(k):
        lam = 0.0
        for b in range(n):
            lam += blk[b, j]
        lam /= tt
        ss = 0.0
        prev = 0
        for b in range(n):
            tb = (ends[b] - prev) * h
            prev = ends[b]
            d = blk[b, j] - lam * tb  # = T_b (r_b - lambda)
            ss += d * d
        err[j] = math.sqrt(ss * n / (n - 1)) / tt


@nb.njit(**_JIT, **INNER)
def _lanes_init(first, nl, k, Y0, NPER, n_transient, n_steps, renorm_every, n_blocks, out, err,
                used, status, ZT, ACT):
    """A Lyapunov block's per-lane start (both block kernels): outputs cleared, step counts,
    blocks of the measuring window and first due step (IST, ENDS), the orthonormalised start
    vectors into ZT[:, :, l], ACT. Returns (IST, ENDS, BLK, ACC, Zl, Cl, logs, max_total)."""
    m, ns = k + 1, Y0.shape[1]
    IST = np.zeros((nl, 7), np.int64)  # see _LAST, ...
    nbmax = max(n_blocks, 1)
    ENDS = np.zeros((nl, nbmax), np.int64)
    BLK = np.zeros((nl, nbmax, k))
    ACC = np.zeros((nl, k))
    # the one-lane machinery's scratch
    Zl = np.zeros((m, ns))
    Cl = np.zeros((m, ns))
    logs = np.zeros(k)
    renorm = max(renorm_every, 1)
    max_total = 0
    for l in range(nl):
        lane = first + l
        for j in range(k):
            out[lane, j] = np.nan
            err[lane, j] = np.nan
        used[lane] = 0
        status[lane] = STATUS_OK
        IST[l, _NTR] = n_transient[lane]
        IST[l, _NST] = n_steps[lane]
        IST[l, _TOTAL] = n_transient[lane] + n_steps[lane]
        ACT[l] = IST[l, _TOTAL] > 0
        max_total = max(max_total, IST[l, _TOTAL])
        ends = _block_bounds(max(n_steps[lane], 1), NPER[lane], n_blocks)
        IST[l, _NBK] = ends.size
        for b in range(ends.size):
            ENDS[l, b] = ends[b]
        IST[l, _DUE] = _lane_due(IST, l, renorm, ENDS)
        for q in range(ns):
            Zl[0, q] = Y0[lane, q]
        # generic, orthonormalised start vectors: e_j + 0.1 (1, ..., 1)
        for j in range(1, m):
            for q in range(ns):
                Zl[j, q] = 0.1 + (1.0 if q == j - 1 else 0.0)
        # np.bool_: a literal flag would compile _orthonormalise once more (once per flag)
        _orthonormalise(Zl, logs, np.bool_(False))
        for j in range(m):
            for q in range(ns):
                ZT[j, q, l] = Zl[j, q]
    return IST, ENDS, BLK, ACC, Zl, Cl, logs, max_total


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _lane_due(IST, l, renorm, ENDS):
    """The next step at which lane l needs its bookkeeping: a renormalisation (every
    ``renorm`` steps, at the end of the transient, at the end) or the end of a block of the
    measuring window."""
    due = min(IST[l, _LAST] + renorm, IST[l, _TOTAL])
    if IST[l, _NTR] > IST[l, _LAST]:
        due = min(due, IST[l, _NTR])
    if IST[l, _CUR] < IST[l, _NBK]:
        due = min(due, IST[l, _NTR] + ENDS[l, IST[l, _CUR]])
    return due


@nb.njit(**_JIT, **INNER)
def _lane_books(step, first, nl, k, renorm, bound, ZT, Zl, Cl, logs, IST, ENDS, BLK, ACC, ACT,
                ACTR, H, out, err, used, status):
    """:func:`_lane_books_core`, then the result of every lane that ended well at this step
    (:func:`_lane_result`). Returns the next step at which a lane is due."""
    nxt = _lane_books_core(step, first, nl, k, renorm, bound, ZT, Zl, Cl, logs, IST, ENDS, BLK,
                           ACC, ACT, ACTR, status)
    for l in range(nl):
        if IST[l, _TOTAL] == step and status[first + l] != STATUS_DIVERGED:
            _lane_result(l, first + l, k, IST[l, _NST], H[first + l], ENDS, IST[l, _NBK], BLK,
                         ACC, out, err, used)
    return nxt


@nb.njit(inline="always", **_JIT)
def _due_now(IST, ENDS, l, step, renorm):
    """What lane l, due at this step, does (the books): (measure: past its transient, c: the
    block being measured, renormalise, block_end: a block of the measuring window ends)."""
    n_tr = IST[l, _NTR]
    measure = step > n_tr
    c = IST[l, _CUR]
    renormalise = step - IST[l, _LAST] == renorm or step == n_tr or step == IST[l, _TOTAL]
    return measure, c, renormalise, measure and step - n_tr == ENDS[l, c]


@nb.njit(inline="always", **_JIT)
def _renorm_one(Y, V, W, l, bound, logs, add):
    """The renormalisation of lane l's one tangent vector (k = 1) in place: its state Y and
    tangent vector V (flat rows, element q of lane l at q W + l), the state's health
    (|y| <= bound) and :func:`_orthonormalise`'s arithmetic for one vector (the same
    operations, bitwise). Returns False where the state is out of bound or the vector vanished
    or is not finite (Y, V untouched)."""
    ns = Y.size // W
    healthy = True
    for q in range(ns):
        healthy = healthy and abs(Y[q * W + l]) <= bound  # False for NaN too
    if not healthy:
        return False
    r = 0.0
    for q in range(ns):
        r += V[q * W + l] * V[q * W + l]
    r = math.sqrt(r)
    if not (r > 0.0 and math.isfinite(r)):
        return False
    if add:
        logs[0] = math.log(r)
    inv = 1.0 / r
    for q in range(ns):
        V[q * W + l] *= inv
    return True


@nb.njit(inline="always", **_JIT)
def _lane_books_one(step, first, nl, renorm, bound, Z0, Z1, Zl, Cl, logs, IST, ENDS, BLK, ACC,
                    ACT, status):
    """:func:`_lane_books_core` with one tangent vector (k = 1) on the fused loop's rows Z0 (the
    lanes' states) and Z1 (their tangent vectors; element q of lane l at q BLOCK + l), inlined
    into the loop's function: that function declares its arrays ``noalias``, so the books
    reach the rows through the loop's own arrays, not through ZT (a view of the same memory).
    The same operations, bitwise (ACTR is not kept: the variational block does not use it).
    Returns the next step at which a lane is due."""
    ns = Zl.shape[1]
    W = Z0.size // ns
    nxt = np.iinfo(np.int64).max
    for l in range(nl):
        if not ACT[l]:
            continue
        if IST[l, _DUE] == step:
            measure, c, renormalise, block_end = _due_now(IST, ENDS, l, step, renorm)
            if renormalise:
                IST[l, _LAST] = step
                if not _renorm_one(Z0, Z1, W, l, bound, logs, measure):
                    ACT[l] = False
                    status[first + l] = STATUS_DIVERGED
                    continue
                if measure:
                    ACC[l, 0] += logs[0]
                    BLK[l, c, 0] += logs[0]
                if block_end:
                    IST[l, _CUR] = c + 1
            elif block_end:
                # a block ends between renormalisations: its share of the running stretch, on
                # a copy
                for q in range(ns):
                    Zl[0, q] = Z0[q * W + l]
                    Zl[1, q] = Z1[q * W + l]
                _stretch_logs(Zl, Cl, logs)
                BLK[l, c, 0] += logs[0]
                BLK[l, c + 1, 0] -= logs[0]
                IST[l, _CUR] = c + 1
            if step == IST[l, _TOTAL]:
                ACT[l] = False
                continue
            IST[l, _DUE] = _lane_due(IST, l, renorm, ENDS)
        nxt = min(nxt, IST[l, _DUE])
    return nxt


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _lane_books_core(step, first, nl, k, renorm, bound, ZT, Zl, Cl, logs, IST, ENDS, BLK, ACC,
                     ACT, ACTR, status):
    """The bookkeeping of the block's lanes due at this step, as in :func:`_run`:
    renormalisation (health, modified Gram-Schmidt on a gathered copy), block statistics, the
    end of a lane at its last step (its result is the caller's: :func:`_lane_result`
    allocates, and the fused block's loop allocates nothing). Returns the next step at which a
    lane is due. (One loop, no
    inlined helpers with array arguments: each would cost reference counting per lane.)"""
    m, ns = Zl.shape
    nxt = np.iinfo(np.int64).max
    changed = False
    for l in range(nl):
        if not ACT[l]:
            continue
        if IST[l, _DUE] == step:
            lane = first + l
            measure, c, renormalise, block_end = _due_now(IST, ENDS, l, step, renorm)
            one = renormalise and k == 1  # in place, no gathered copy (:func:`_renorm_one`)
            if (renormalise or block_end) and not one:
                for j in range(m):
                    for q in range(ns):
                        Zl[j, q] = ZT[j, q, l]
            if renormalise:
                IST[l, _LAST] = step
                if one:
                    nw = ZT.shape[2]
                    ok = _renorm_one(ZT[0].reshape(ns * nw), ZT[1].reshape(ns * nw), nw, l,
                                     bound, logs, measure)
                else:
                    ok = True
                    for q in range(ns):
                        ok = ok and abs(Zl[0, q]) <= bound  # False for NaN too
                    ok = ok and _orthonormalise(Zl, logs, measure)
                if not ok:
                    ACT[l] = False
                    status[lane] = STATUS_DIVERGED
                    changed = True
                    continue
                if not one:
                    for j in range(m):
                        for q in range(ns):
                            ZT[j, q, l] = Zl[j, q]
                if measure:
                    for j in range(k):
                        ACC[l, j] += logs[j]
                        BLK[l, c, j] += logs[j]
                if block_end:
                    IST[l, _CUR] = c + 1
            elif block_end:
                # a block ends between renormalisations: its share of the running stretch, on
                # a copy
                _stretch_logs(Zl, Cl, logs)
                for j in range(k):
                    BLK[l, c, j] += logs[j]
                    BLK[l, c + 1, j] -= logs[j]
                IST[l, _CUR] = c + 1
            if step == IST[l, _TOTAL]:
                ACT[l] = False
                changed = True
                continue
            IST[l, _DUE] = _lane_due(IST, l, renorm, ENDS)
        nxt = min(nxt, IST[l, _DUE])
    if changed:
        for s in range(2 * k + 1):
            for l in range(nl):
                ACTR[s * nl + l] = ACT[l]
    return nxt


#: :func:`_lane_books_core` inlined into its caller (one lane's time loop, where a call of it at
#: each renormalisation costs more than its arithmetic).
_lane_books_inline = nb.njit(inline="always", _nrt=False, **_JIT)(_lane_books_core.py_func)


@nb.njit(**_JIT, **INNER)
def _lane_result(l, lane, k, n_steps, h, ENDS, nbk, BLK, ACC, out, err, used):
    """The exponents and standard errors of lane l at its end (as :func:`_run` returns them)."""
    if n_steps <= 0:
        return
    tm = n_steps * h
    for j in range(k):
        out[lane, j] = ACC[l, j] / tm
    blk = BLK[l, :nbk].copy()
    ends = ENDS[l, :nbk].copy()
    er = np.full(k, np.nan)
    _block_stderr(blk, ends, h, er)
    for j in range(k):
        err[lane, j] = er[j]
    used[lane] = nbk


def _block_count(L: int, k: int, block_rows: int, min_blocks: int) -> int:
    """Blocks for L lanes of 2 k + 1 rows: at most ``block_rows`` rows each (at least one
    lane), at least ``min_blocks`` (e.g. one per thread) while there are lanes; lanes are dealt
    out evenly (block b: lanes b L // n to (b + 1) L // n)."""
    per = max(block_rows // (2 * k + 1), 1)
    return max((L + per - 1) // per, min(L, min_blocks))


def _block_tables(OMEGA: np.ndarray, NPER: np.ndarray, k: int, block_rows: int,
                  min_blocks: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The lanes' phase tables (one per grid, concatenated: S_TAB, C_TAB; OFF[lane]: the start
    of the lane's) and the number of blocks (:func:`_block_count`) of
    :func:`lyapunov_block_lanes`: orchestration, run by the interpreter (the tables from
    :func:`phase_table_values`, bitwise the compiled tables)."""
    L = OMEGA.shape[0]
    forced = bool(np.any(OMEGA != 0.0))
    grids = np.unique(NPER)
    starts = np.zeros(grids.size + 1, np.int64)
    starts[1:] = np.cumsum(2 * grids + 1)
    S_TAB = np.zeros(int(starts[-1]))
    C_TAB = np.ones(int(starts[-1]))
    for g in range(grids.size):
        s_tab, c_tab = phase_table_values(int(grids[g]), forced)
        S_TAB[starts[g]:starts[g + 1]] = s_tab
        C_TAB[starts[g]:starts[g + 1]] = c_tab
    OFF = starts[np.searchsorted(grids, NPER)].astype(np.int64)
    return S_TAB, C_TAB, OFF, np.int64(_block_count(int(L), int(k), int(block_rows),
                                                    int(min_blocks)))
