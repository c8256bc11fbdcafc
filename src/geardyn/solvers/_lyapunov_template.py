"""Lyapunov exponents from the tangent (variational) equations, specialised per model.

This file is a template, like :mod:`geardyn.solvers._kernel_template`:
:func:`geardyn.solvers.kernels.kernels_for` (template ``"lyapunov"``) copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions. As it stands it is a valid
module bound to the small test oscillator of :mod:`geardyn.solvers._template_model`.

Numerics
--------
* The state y is advanced on the main solver's grid (``n_per`` RK4 steps of ``h`` per forcing
  period, forcing phase from the same half-step table; an autonomous model has ``omega = 0`` and
  any ``h``), with the crossings of the ``n_ev`` switching functions located inside a step and
  the step split there, as in :mod:`geardyn.solvers._kernel_template` (shared
  :mod:`._step_core`).
* The tangent vectors live in the scaled coordinates z = y / s, s the model's characteristic
  scale of each state (:attr:`geardyn.Model.state_scale`, ones by default): a tangent vector v
  (in z) is advanced by the derivative of that step map Phi, by a central difference:
  ``(Phi(y + e s v) - Phi(y - e s v)) / (2 e s)`` (componentwise products and quotient) with
  ``e |v| = FD_DELTA (1 + min(|y / s|, FD_NORM_CAP))`` (Euclidean norms, FD_DELTA = 2^-20 ~
  1e-6, FD_NORM_CAP = 2^10), so that the perturbation is ~1e-6 of each state's own scale, not
  of its unit (in SI body angles 1e-6 rad would be ~0.1 % of a backlash). The term |y / s|
  keeps the perturbation above the rounding of y (relative error ~ eps / FD_DELTA); the cap
  keeps it small where a state drifts far from its scale without changing the dynamics (the
  rigid rotation of a device in body angles: |y / s| ~ 1e5 after 4000 tau of an unbalanced
  carrier), at a rounding error ~ eps |y / s| / (FD_DELTA FD_NORM_CAP) (2e-7 at 1e6).
  Exponents do not change under a constant linear change of coordinates, and with s = 1 every
  operation is the unscaled one (multiplying by 1.0 is exact): below the cap results are
  bitwise those of the unscaled kernel. For a smooth field this is RK4 applied to the
  variational equation v' = J(t, y) v (to O(e^2)); the perturbed states locate their own edge
  crossings, so a step in which one of them crosses an edge is differentiated correctly and the
  exponent keeps the solver's order. It is exact for affine step maps
  (linear models) up to rounding (~ eps / FD_DELTA ~ 1e-10 relative per step). The vector
  field is continuous across the dead-zone edges, so the flow is C^1 there and no saltation
  matrix is needed.
* Every ``renorm_every`` steps (and at the end of the transient and of the run) the tangent
  vectors are re-orthonormalised by modified Gram-Schmidt (a QR factorisation); the logs of the
  diagonal of R are summed over the measuring window (Benettin et al. 1980; Shimada & Nagashima
  1979). The transient advances the tangent vectors too (renormalised, not summed) so that they
  are aligned when measuring starts.
* Start time: the state y0 is given at time t0, where the forcing phase is zero (grid step i
  runs from t0 + i h, forcing phase from the table at i mod n_per; the time passed to ``rhs``,
  e.g. for a load fluctuation at Lambda, is t0 + i h), exactly as the sweep kernel runs a lane
  started at T0. A sweep's final state lies at forcing phase zero of its lane, so started at
  the lane's final time the exponent continues the lane in both forcing phases.
* Uncertainty: the measuring window is cut into up to ``n_blocks`` blocks of whole forcing
  periods (as equal as they divide); the log stretch of each block (the renormalisations in it,
  plus, where a block ends between two, the stretch so far, taken from a copy of the tangent
  vectors) over its time gives a block rate, and the spread of the rates the standard error
  (:func:`_block_stderr`). The exponent itself is summed as before, untouched.
* A lane whose state leaves ``|y| <= bound`` (checked at each renormalisation) or whose tangent
  vectors stop being finite is marked diverged (status 1) and its exponents are NaN.
* Cost per step: (2 k + 1) RK4 steps for k tangent vectors. They are independent integrations
  of one grid step, so they run as the rows of one lockstep block (their RK4 stages interleaved,
  the model's functions inlined once), which overlaps their dependency chains; each row's
  arithmetic is that of a lone step, so the result does not depend on it.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._step_core import (  # CORE-IMPORT
    _JIT,
    GBUF_ROWS,
    STATUS_DIVERGED,
    STATUS_OK,
    _events_i,
    _healthy,
    _leaves_side_step,
    _rhs_i,
    _side,
    _split_step,
    phase_table,
)
from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

#: Relative size of the finite-difference perturbation: e |v| = FD_DELTA (1 + min(|y / s|,
#: FD_NORM_CAP)), in the scaled coordinates z = y / s (s: the model's ``state_scale``).
FD_DELTA = 2.0**-20

#: Cap on |y / s| in the perturbation size (see the module docstring; no built-in model's
#: dimensionless state comes near it, so for them it changes nothing).
FD_NORM_CAP = 2.0**10

# the model interface names are part of the template's namespace (the generated copy re-binds
# them); only rhs and events are used here
__all__ = ["events", "lyapunov_lanes", "lyapunov_single", "observe", "phase_table", "rhs"]


@nb.njit(**_JIT)
def _grid_step_rows(i, t0, Y, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0, G1, W,
                    gbuf, ncross):
    """Advance every row of Y (independent states of one lane) by grid step i (time t0 + i h to
    t0 + (i + 1) h, forcing phase from the table at i mod n_per): one RK4 step per row, the
    rows' stages interleaved; a row whose trial step changes the side of a switching function is
    redone with the crossings located (:func:`_split_step`), as the main solver does."""
    nr, ns = Y.shape
    t = t0 + i * h
    hh = 0.5 * h
    j0 = 2 * (i % n_per)
    if n_ev > 0:
        for r in range(nr):
            _events_i(t, Y[r], G0[r], p)
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
    h6 = h / 6.0
    for r in range(nr):
        for q in range(ns):
            Y1[r, q] = Y[r, q] + h6 * (K[0, r, q] + 2.0 * K[1, r, q] + 2.0 * K[2, r, q]
                                       + K[3, r, q])
    for r in range(nr):
        crossed = 0
        if n_ev > 0:
            _events_i(t + h, Y1[r], G1[r], p)
            crossed = _leaves_side_step(r, t, t + h, Y, K[0], G0, G1, SIDE, p, W[8], gbuf)
        if crossed:
            _split_step(i, t0, Y[r], Y1[r], p, h, omega, n_per, SIDE[r], G1[r], ncross, W,
                        W[8], gbuf)
        else:
            for q in range(ns):
                Y[r, q] = Y1[r, q]


@nb.njit(**_JIT)
def _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP, Y1,
                  SIDE, G0, G1, W, gbuf, ncross):
    """Advance the state y (row 0 of Z) by one grid step and each tangent vector v (rows 1..,
    in the scaled coordinates z = y / S; IS = 1 / S) by the derivative of that step map:
    (Phi(y + e S v) - Phi(y - e S v)) / (2 e S). The 2 k + 1 states are the rows of YP
    (tangent j: rows 2 j - 2 and 2 j - 1; the state: the last row)."""
    m, ns = Z.shape
    ny = 0.0
    for q in range(ns):
        zq = Z[0, q] * IS[q]
        ny += zq * zq
    scale = FD_DELTA * (1.0 + min(math.sqrt(ny), FD_NORM_CAP))
    last = 2 * (m - 1)
    for q in range(ns):
        YP[last, q] = Z[0, q]
    for j in range(1, m):
        nv = 0.0
        for q in range(ns):
            nv += Z[j, q] * Z[j, q]
        nv = math.sqrt(nv)
        if not (nv > 0.0 and math.isfinite(nv)):
            E[j] = np.nan  # lost: its rows just follow the state
            for q in range(ns):
                YP[2 * j - 2, q] = Z[0, q]
                YP[2 * j - 1, q] = Z[0, q]
            continue
        e = scale / nv
        E[j] = e
        for q in range(ns):
            d = e * (S[q] * Z[j, q])
            YP[2 * j - 2, q] = Z[0, q] + d
            YP[2 * j - 1, q] = Z[0, q] - d
    _grid_step_rows(i, t0, YP, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0, G1, W,
                    gbuf, ncross)
    for j in range(1, m):
        if not math.isfinite(E[j]):
            for q in range(ns):
                Z[j, q] = np.nan
            continue
        inv = 0.5 / E[j]
        for q in range(ns):
            Z[j, q] = ((YP[2 * j - 2, q] - YP[2 * j - 1, q]) * inv) * IS[q]
    for q in range(ns):
        Z[0, q] = YP[last, q]


@nb.njit(**_JIT)
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


@nb.njit(**_JIT)
def _stretch_logs(Z, C, logs):
    """The logs of R's diagonal that orthonormalising Z's tangent rows would give now (the
    stretch since the last renormalisation), computed on the copy C: Z is left as it is."""
    m, ns = Z.shape
    for j in range(m):
        for q in range(ns):
            C[j, q] = Z[j, q]
    for j in range(1, m):
        logs[j - 1] = np.nan
    _orthonormalise(C, logs, True)


@nb.njit(**_JIT)
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


@nb.njit(**_JIT)
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


@nb.njit(**_JIT)
def _run(p, y0, S, t0, h, omega, n_per, s_tab, c_tab, n_transient, n_steps, renorm_every, k,
         bound, n_ev, n_blocks):
    """Exponents (sum of logs / measured time), their standard errors (from up to ``n_blocks``
    blocks of whole forcing periods of the measuring window), the number of blocks and the
    status of one lane, started at time t0 (forcing phase zero there); tangent vectors in the
    coordinates y / S (S: the state scale)."""
    ns = y0.size
    IS = np.empty(ns)
    for q in range(ns):
        IS[q] = 1.0 / S[q]
    m = k + 1
    Z = np.zeros((m, ns))
    W = np.zeros((9, ns))
    nr = 2 * k + 1
    YP = np.zeros((nr, ns))
    E = np.zeros(m)  # the perturbation size of each tangent vector in this step
    K = np.zeros((4, nr, ns))
    TMP = np.zeros((nr, ns))
    Y1 = np.zeros((nr, ns))
    ne = max(n_ev, 1)
    SIDE = np.ones((nr, ne), np.int64)
    G0 = np.zeros((nr, ne))
    G1 = np.zeros((nr, ne))
    gbuf = np.zeros((GBUF_ROWS, ne))
    ncross = np.zeros(ne, np.int64)
    acc = np.zeros(k)
    logs = np.zeros(k)
    ends = _block_bounds(max(n_steps, 1), n_per, n_blocks)
    nbk = ends.size
    blk = np.zeros((nbk, k))  # log stretch per block of the measuring window
    C = np.zeros((m, ns))
    out = np.full(k, np.nan)
    err = np.full(k, np.nan)
    for q in range(ns):
        Z[0, q] = y0[q]
    # generic, orthonormalised start vectors: e_j + 0.1 (1, ..., 1)
    for j in range(1, m):
        for q in range(ns):
            Z[j, q] = 0.1 + (1.0 if q == j - 1 else 0.0)
    _orthonormalise(Z, logs, False)
    renorm = max(renorm_every, 1)
    total = n_transient + n_steps
    since = 0
    cur = 0  # the block being measured
    for i in range(total):
        _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP, Y1,
                      SIDE, G0, G1, W, gbuf, ncross)
        since += 1
        step = i + 1
        measure = step > n_transient
        if since == renorm or step == n_transient or step == total:
            since = 0
            if not _healthy(Z[0], bound):
                return out, err, 0, STATUS_DIVERGED
            if not _orthonormalise(Z, logs, measure):
                return out, err, 0, STATUS_DIVERGED
            if measure:
                for j in range(k):
                    acc[j] += logs[j]
                    blk[cur, j] += logs[j]
            if measure and step - n_transient == ends[cur]:
                cur += 1
        elif measure and step - n_transient == ends[cur]:
            # a block ends between renormalisations: its share of the running stretch, on a
            # copy (the exponent's own arithmetic is untouched)
            _stretch_logs(Z, C, logs)
            for j in range(k):
                blk[cur, j] += logs[j]
                blk[cur + 1, j] -= logs[j]
            cur += 1
    if n_steps <= 0:
        return out, err, 0, STATUS_OK
    tm = n_steps * h
    for j in range(k):
        out[j] = acc[j] / tm
    _block_stderr(blk, ends, h, err)
    return out, err, nbk, STATUS_OK


@nb.njit(**_JIT)
def lyapunov_single(p, y0, scale, t0, h, omega, n_per, n_transient, n_steps, renorm_every, k,
                    bound, n_ev=0, n_blocks=16):
    """The k leading Lyapunov exponents (per unit time of the model) of one parameter set.

    ``scale``: the characteristic scale of each state (``Model.state_scale``, positive; ones give
    the unscaled kernel); the tangent vectors live in y / scale. Grid: step h (= 2 pi /
    (omega n_per) for a forced model); the state y0 is given at time t0,
    where the forcing phase is zero; ``n_transient`` steps are discarded and ``n_steps``
    measured. ``n_ev``: the model's number of switching functions, whose crossings are located
    inside a step (0: none located). Returns (exponents[k], stderr[k], blocks, status): the
    standard errors from ``n_blocks`` blocks of the measuring window (:func:`_block_stderr`;
    ``blocks`` of them used); exponents are NaN if diverged.
    """
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    return _run(p, y0, scale, t0, h, omega, n_per, s_tab, c_tab, n_transient, n_steps,
                renorm_every, k, bound, n_ev, n_blocks)


@nb.njit(parallel=True, **_JIT)
def lyapunov_lanes(P, Y0, scale, T0, H, OMEGA, n_per, n_transient, n_steps, renorm_every, bound,
                   out, err, n_ev=0, n_blocks=16):
    """Largest exponent of every lane (row of P, Y0), in parallel over lanes.

    scale: the state scale (one vector for all lanes, as in :func:`lyapunov_single`); T0: start
    time (forcing phase zero there, as in :func:`lyapunov_single`) per lane; H, OMEGA:
    step and forcing frequency per lane; n_transient, n_steps: per-lane step counts (int
    arrays); n_ev and n_blocks as in :func:`lyapunov_single`. Fills out[L] and err[L] (the
    standard error; NaN for diverged lanes).
    """
    L, ns = Y0.shape
    forced = False
    for lane in range(L):
        if OMEGA[lane] != 0.0:
            forced = True
    s_tab, c_tab = phase_table(n_per, forced)
    for lane in nb.prange(L):
        ex, er, _nb, st = _run(P[lane], Y0[lane], scale, T0[lane], H[lane], OMEGA[lane], n_per,
                               s_tab, c_tab, n_transient[lane], n_steps[lane], renorm_every, 1,
                               bound, n_ev, n_blocks)
        out[lane] = ex[0] if st == STATUS_OK else np.nan
        err[lane] = er[0] if st == STATUS_OK else np.nan
