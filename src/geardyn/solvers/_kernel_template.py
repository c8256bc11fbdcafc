"""Fixed-step RK4 kernels, specialised per model from this template (see :mod:`.kernels`).

This file is a template: :func:`geardyn.solvers.kernels.kernels_for` copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions, so that numba compiles
(and caches on disk) one kernel per model with the right-hand side inlined. As it stands it is a
valid module bound to a small test oscillator.

Numerics
--------
* Classic 4th-order Runge-Kutta on a grid aligned to the forcing period: ``n_per`` steps of
  ``h = T / n_per``; the forcing phase ``sin/cos(Omega t)`` at the grid and half-grid points comes
  from a table, so it is exact and periodic.
* Kinks of the right-hand side (the edges of the backlash dead zone) are the zero crossings of the
  model's ``events``. With ``locate`` on, a step whose end lies on another side of an edge than its
  start is split at the crossing, located by root-finding on the cubic Hermite interpolant of the
  step (error O(h^4) in the crossing time), and integrated in sub-steps. Every RK4 stage then sees
  a smooth right-hand side and the method keeps 4th order. A step is split at most
  ``MAX_SPLITS`` times (grazing contacts); the count of steps that hit the limit is returned.
* Lanes (parameter sets) are advanced in lockstep blocks of ``BLOCK`` lanes so the CPU overlaps
  their independent dependency chains; blocks run in parallel (``prange``). A lane's arithmetic
  does not depend on its neighbours, so results are bitwise independent of blocking and threads.
* A lane whose state leaves ``|y| <= bound`` or stops being finite is marked diverged (status 1)
  and frozen; the others go on.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False}
BLOCK = 8
MAX_SPLITS = 16
#: Crossings located within this fraction of a step of the earliest are taken together (identical
#: planet sets cross their edges at the same instant).
SIMULTANEOUS = 1e-9
STATUS_OK = 0
STATUS_DIVERGED = 1


@nb.njit(**_JIT)
def phase_table(n_per, forced):
    """sin and cos of the forcing phase at the 2 n_per + 1 half-step points of one period."""
    s = np.zeros(2 * n_per + 1)
    c = np.ones(2 * n_per + 1)
    if forced:
        for k in range(1, 2 * n_per):
            a = math.pi * k / n_per
            s[k] = math.sin(a)
            c[k] = math.cos(a)
    return s, c


@nb.njit(inline="always", **_JIT)
def _side(x):
    return 1 if x > 0.0 else -1


@nb.njit(**_JIT)
def _rk4(t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, k4, tmp, out, have_k1):
    """One RK4 step of size h from (t, y) into out; k1 holds f(t, y) if have_k1."""
    ns = y.size
    if not have_k1:
        rhs(t, y, k1, p, s0, c0)
    hh = 0.5 * h
    for q in range(ns):
        tmp[q] = y[q] + hh * k1[q]
    rhs(t + hh, tmp, k2, p, s1, c1)
    for q in range(ns):
        tmp[q] = y[q] + hh * k2[q]
    rhs(t + hh, tmp, k3, p, s1, c1)
    for q in range(ns):
        tmp[q] = y[q] + h * k3[q]
    rhs(t + h, tmp, k4, p, s2, c2)
    h6 = h / 6.0
    for q in range(ns):
        out[q] = y[q] + h6 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])


@nb.njit(**_JIT)
def _hermite(y0, f0, y1, f1, dt, theta, out):
    """Cubic Hermite interpolant of a step of length dt at fraction theta."""
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = (t3 - 2.0 * t2 + theta) * dt
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = (t3 - t2) * dt
    for q in range(y0.size):
        out[q] = h00 * y0[q] + h10 * f0[q] + h01 * y1[q] + h11 * f1[q]


@nb.njit(**_JIT)
def _locate(j, side_j, g0j, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf):
    """Fraction in (0, 1] of the step where event j leaves side side_j (Illinois method)."""
    a = 0.0
    fa = g0j if _side(g0j) == side_j else (1e-300 if side_j > 0 else 0.0)
    b = 1.0
    fb = g1j
    last = 0
    for _ in range(60):
        denom = fb - fa
        x = (a * fb - b * fa) / denom if denom != 0.0 else 0.5 * (a + b)
        if not (a < x < b):
            x = 0.5 * (a + b)
        _hermite(y0, f0, y1, f1, dt, x, ybuf)
        events(t + x * dt, ybuf, gbuf, p)
        fx = gbuf[j]
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


@nb.njit(**_JIT)
def _split_step(i, t0, y, y_trial, p, h, omega, n_per, side, g1, ncross, work, ybuf, gbuf):
    """Finish grid step i of one lane with edge crossings located; y holds the start, and
    y_trial/g1 the unsplit trial step. Returns 1 if the split limit was reached, else 0."""
    k1 = work[0]
    k2 = work[1]
    k3 = work[2]
    k4 = work[3]
    tmp = work[4]
    f1 = work[5]
    ystart = work[6]
    n_ev = g1.size
    u = 0.0  # fraction of the grid step done
    i_mod = i % n_per
    wh = omega * h
    t_end = t0 + (i + 1) * h
    s_end = math.sin(wh * (i_mod + 1))
    c_end = math.cos(wh * (i_mod + 1))
    for _ in range(MAX_SPLITS):
        t = t0 + (i + u) * h
        dt = (1.0 - u) * h
        s0 = math.sin(wh * (i_mod + u))
        c0 = math.cos(wh * (i_mod + u))
        if u > 0.0:
            sm = math.sin(wh * (i_mod + 0.5 * (1.0 + u)))
            cm = math.cos(wh * (i_mod + 0.5 * (1.0 + u)))
            _rk4(t, y, dt, p, s0, c0, sm, cm, s_end, c_end, k1, k2, k3, k4, tmp, y_trial, False)
            events(t_end, y_trial, g1, p)
        else:
            rhs(t, y, k1, p, s0, c0)
        first = -1
        theta = 2.0
        rhs(t_end, y_trial, f1, p, s_end, c_end)
        for q in range(y.size):
            ystart[q] = y[q]
        events(t, y, gbuf[0], p)
        for j in range(n_ev):
            gbuf[2, j] = 2.0
            if _side(g1[j]) != side[j]:
                th = _locate(j, side[j], gbuf[0, j], g1[j], ystart, k1, y_trial, f1, dt, t, p,
                             ybuf, gbuf[1])
                gbuf[2, j] = th
                if th < theta:
                    theta = th
                    first = j
        if first < 0:
            for q in range(y.size):
                y[q] = y_trial[q]
            return 0
        dts = theta * dt
        tm = u + 0.5 * theta * (1.0 - u)
        tu = u + theta * (1.0 - u)
        _rk4(t, ystart, dts, p, s0, c0, math.sin(wh * (i_mod + tm)), math.cos(wh * (i_mod + tm)),
             math.sin(wh * (i_mod + tu)), math.cos(wh * (i_mod + tu)), k1, k2, k3, k4, tmp, y,
             True)
        for j in range(n_ev):
            if gbuf[2, j] <= theta + SIMULTANEOUS:
                side[j] = -side[j]
                ncross[j] += 1
        u = tu
        if u >= 1.0:
            events(t_end, y, g1, p)
            return 0
    for q in range(y.size):
        y[q] = y_trial[q]
    for j in range(n_ev):
        side[j] = _side(g1[j])
    return 1


@nb.njit(**_JIT)
def _block_step(i, lanes, nl, Y, Y1, K1, K2, K3, K4, TMP, P, H, OMEGA, T0, n_per, s_tab, c_tab,
                locate, SIDE, G, NCROSS, UNRES, work, ybuf, gbuf):
    """Advance lanes[0:nl] of a block by grid step i: a lockstep RK4 trial for all lanes, then,
    for a lane whose trial crossed an edge, the step redone with the crossing located."""
    ns = Y.shape[1]
    j0 = 2 * (i % n_per)
    sa = s_tab[j0]
    ca = c_tab[j0]
    sb = s_tab[j0 + 1]
    cb = c_tab[j0 + 1]
    se = s_tab[j0 + 2]
    ce = c_tab[j0 + 2]
    for k in range(nl):
        lane = lanes[k]
        rhs(T0[lane] + i * H[lane], Y[k], K1[k], P[lane], sa, ca)
    for k in range(nl):
        lane = lanes[k]
        hh = 0.5 * H[lane]
        for q in range(ns):
            TMP[k, q] = Y[k, q] + hh * K1[k, q]
        rhs(T0[lane] + i * H[lane] + hh, TMP[k], K2[k], P[lane], sb, cb)
    for k in range(nl):
        lane = lanes[k]
        hh = 0.5 * H[lane]
        for q in range(ns):
            TMP[k, q] = Y[k, q] + hh * K2[k, q]
        rhs(T0[lane] + i * H[lane] + hh, TMP[k], K3[k], P[lane], sb, cb)
    for k in range(nl):
        lane = lanes[k]
        h = H[lane]
        for q in range(ns):
            TMP[k, q] = Y[k, q] + h * K3[k, q]
        rhs(T0[lane] + (i + 1) * h, TMP[k], K4[k], P[lane], se, ce)
    for k in range(nl):
        lane = lanes[k]
        h6 = H[lane] / 6.0
        for q in range(ns):
            Y1[k, q] = Y[k, q] + h6 * (K1[k, q] + 2.0 * K2[k, q] + 2.0 * K3[k, q] + K4[k, q])
        g = G[k]
        events(T0[lane] + (i + 1) * H[lane], Y1[k], g, P[lane])
        crossed = False
        for j in range(g.size):
            if _side(g[j]) != SIDE[k, j]:
                crossed = True
        if crossed and locate:
            UNRES[lane] += _split_step(i, T0[lane], Y[k], Y1[k], P[lane], H[lane], OMEGA[lane],
                                       n_per, SIDE[k], g, NCROSS[lane], work, ybuf, gbuf)
        else:
            if crossed:
                for j in range(g.size):
                    s_new = _side(g[j])
                    if s_new != SIDE[k, j]:
                        SIDE[k, j] = s_new
                        NCROSS[lane, j] += 1
            for q in range(ns):
                Y[k, q] = Y1[k, q]


@nb.njit(**_JIT)
def _healthy(y, bound):
    for q in range(y.size):
        v = y[q]
        if not (abs(v) <= bound):  # False for NaN too
            return False
    return True


@nb.njit(**_JIT)
def _alloc(nb_lanes, ns, n_ev):
    Y = np.zeros((nb_lanes, ns))
    work = np.zeros((7, ns))
    return (Y, Y.copy(), Y.copy(), Y.copy(), Y.copy(), Y.copy(), Y.copy(),
            np.zeros((nb_lanes, max(n_ev, 1))), np.ones((nb_lanes, max(n_ev, 1)), np.int64),
            work, np.zeros(ns), np.zeros((3, max(n_ev, 1))))


@nb.njit(**_JIT)
def trajectory(p, y0, h, omega, n_per, i0, n_steps, stride, locate, bound, n_ev, n_obs):
    """Integrate one lane from grid point i0 (time i0 h) for n_steps grid steps, recording every
    stride-th grid point.

    Returns (Y[n_rec, ns], O[n_rec, n_obs], G[n_rec, n_ev], ncross[n_ev], status, unresolved,
    steps_done); n_rec = n_steps // stride + 1. Rows after a divergence are NaN.
    """
    ns = y0.size
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    Y, Y1, K1, K2, K3, K4, TMP, G, SIDE, work, ybuf, gbuf = _alloc(1, ns, n_ev)
    P = p.reshape((1, p.size))
    H = np.array([h])
    OM = np.array([omega])
    T0 = np.zeros(1)
    lanes = np.zeros(1, np.int64)
    NCROSS = np.zeros((1, max(n_ev, 1)), np.int64)
    UNRES = np.zeros(1, np.int64)
    n_rec = n_steps // stride + 1
    out_y = np.full((n_rec, ns), np.nan)
    out_o = np.full((n_rec, max(n_obs, 1)), np.nan)
    out_g = np.full((n_rec, max(n_ev, 1)), np.nan)
    for q in range(ns):
        Y[0, q] = y0[q]
    events(i0 * h, Y[0], G[0], p)
    for j in range(n_ev):
        SIDE[0, j] = _side(G[0, j])
    status = STATUS_OK
    done = 0
    obuf = np.zeros(max(n_obs, 1))
    for i in range(i0, i0 + n_steps + 1):
        if (i - i0) % stride == 0:
            r = (i - i0) // stride
            t = i * h
            j0 = 2 * (i % n_per)
            for q in range(ns):
                out_y[r, q] = Y[0, q]
            if n_obs > 0:
                observe(t, Y[0], obuf, p, s_tab[j0], c_tab[j0])
                for q in range(n_obs):
                    out_o[r, q] = obuf[q]
            if n_ev > 0:
                events(t, Y[0], gbuf[0], p)
                for q in range(n_ev):
                    out_g[r, q] = gbuf[0, q]
        if i == i0 + n_steps:
            break
        _block_step(i, lanes, 1, Y, Y1, K1, K2, K3, K4, TMP, P, H, OM, T0, n_per, s_tab, c_tab,
                    locate, SIDE, G, NCROSS, UNRES, work, ybuf, gbuf)
        done = i + 1 - i0
        if not _healthy(Y[0], bound):
            status = STATUS_DIVERGED
            break
    return out_y, out_o[:, :n_obs], out_g[:, :n_ev], NCROSS[0, :n_ev], status, UNRES[0], done


@nb.njit(parallel=True, **_JIT)
def sweep(P, Y0, H, OMEGA, T0, n_per, n_transient, n_samples, sample_every, locate, bound, n_ev,
          n_obs, samples, final, status, gmin, gmax, ncross, omax, omin, orms, unresolved):
    """Integrate every lane from time T0[lane] (a whole number of forcing periods):
    ``n_transient[lane]`` grid steps, then ``n_samples`` section samples, one every
    ``sample_every`` grid steps, with statistics over the sampled stretch.

    Outputs (preallocated, filled here): samples[L, n_samples, ns] (NaN where diverged),
    final[L, ns], status[L], gmin/gmax[L, n_ev] (extremes of the events at grid points),
    ncross[L, n_ev] (edge crossings while sampling), omax/omin/orms[L, n_obs] (extremes and RMS
    of the observables at grid points), unresolved[L] (steps that reached the split limit).
    A block runs in lockstep to its longest lane; a lane past its end keeps integrating
    harmlessly (its results are already stored), a diverged lane is reset to zero.
    """
    L, ns = Y0.shape
    forced = False
    for lane in range(L):
        if OMEGA[lane] != 0.0:
            forced = True
    s_tab, c_tab = phase_table(n_per, forced)
    n_blocks = (L + BLOCK - 1) // BLOCK
    for blk in nb.prange(n_blocks):
        first = blk * BLOCK
        nl = min(BLOCK, L - first)
        lanes = np.arange(first, first + nl)
        Y, Y1, K1, K2, K3, K4, TMP, G, SIDE, work, ybuf, gbuf = _alloc(BLOCK, ns, n_ev)
        obuf = np.zeros(max(n_obs, 1))
        n_end = np.zeros(nl, np.int64)
        n_stat = np.zeros(nl, np.int64)
        max_end = 0
        for k in range(nl):
            lane = first + k
            for q in range(ns):
                Y[k, q] = Y0[lane, q]
            events(T0[lane], Y[k], G[k], P[lane])
            for j in range(n_ev):
                SIDE[k, j] = _side(G[k, j])
                gmin[lane, j] = np.inf
                gmax[lane, j] = -np.inf
                ncross[lane, j] = 0
            for j in range(n_obs):
                omax[lane, j] = -np.inf
                omin[lane, j] = np.inf
                orms[lane, j] = 0.0
            status[lane] = STATUS_OK
            unresolved[lane] = 0
            n_end[k] = n_transient[lane] + n_samples * sample_every
            max_end = max(max_end, n_end[k])
        for i in range(max_end):
            _block_step(i, lanes, nl, Y, Y1, K1, K2, K3, K4, TMP, P, H, OMEGA, T0, n_per, s_tab,
                        c_tab, locate, SIDE, G, ncross, unresolved, work, ybuf, gbuf)
            step = i + 1
            for k in range(nl):
                lane = first + k
                if step > n_end[k] or status[lane] != STATUS_OK:
                    continue
                if (step % n_per == 0 or step == n_end[k]) and not _healthy(Y[k], bound):
                    status[lane] = STATUS_DIVERGED
                    for r in range(n_samples):
                        for q in range(ns):
                            samples[lane, r, q] = np.nan
                    for q in range(ns):
                        final[lane, q] = np.nan
                        Y[k, q] = 0.0
                    continue
                if step == n_transient[lane]:
                    for j in range(n_ev):
                        ncross[lane, j] = 0
                if step <= n_transient[lane]:
                    continue
                for j in range(n_ev):
                    gmin[lane, j] = min(gmin[lane, j], G[k, j])
                    gmax[lane, j] = max(gmax[lane, j], G[k, j])
                if n_obs > 0:
                    j0 = 2 * (step % n_per)
                    observe(T0[lane] + step * H[lane], Y[k], obuf, P[lane], s_tab[j0], c_tab[j0])
                    for j in range(n_obs):
                        omax[lane, j] = max(omax[lane, j], obuf[j])
                        omin[lane, j] = min(omin[lane, j], obuf[j])
                        orms[lane, j] += obuf[j] * obuf[j]
                n_stat[k] += 1
                rel = step - n_transient[lane]
                if rel % sample_every == 0:
                    r = rel // sample_every - 1
                    for q in range(ns):
                        samples[lane, r, q] = Y[k, q]
                if step == n_end[k]:
                    for q in range(ns):
                        final[lane, q] = Y[k, q]
        for k in range(nl):
            lane = first + k
            for j in range(n_obs):
                if n_stat[k] > 0 and status[lane] == STATUS_OK:
                    orms[lane, j] = math.sqrt(orms[lane, j] / n_stat[k])
                else:
                    orms[lane, j] = np.nan
