"""A run-up (or run-down): one lane integrated while its forcing frequency is ramped.

This file is a template, like :mod:`geardyn.solvers._kernel_template`:
:func:`geardyn.solvers.kernels.kernels_for` (template ``"runup"``) copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions. As it stands it is a
valid module bound to the small test oscillator of :mod:`geardyn.solvers._template_model`.

Numerics
--------
* The forcing frequency follows a ramp: ``Omega(t) = start`` up to ``t_on``, then
  ``start + accel (t - t_on)`` up to ``t_off``, then constant. The forcing phase is its
  integral, ``theta(t)`` (:func:`speed_phase`, closed form), and the model's functions get
  ``sin theta, cos theta`` at every RK4 stage (not ``Omega t``: the phase of a non-stationary
  speed).
* Coefficients that move with Omega (Omega's own entry, and e.g. a carrier speed that follows
  it) are quadratics in Omega, ``p[cols[j]] = coef[j, 0] + coef[j, 1] Omega + coef[j, 2]
  Omega^2``, set at each stage's time (:func:`set_speed`).
* Classic RK4 with a fixed step ``h``: the step core's RK4 (``_rk4_stages``, the one of the
  split step), given each stage's time, coefficients and phase (start, middle, end: three
  coefficient vectors). A step that leaves a side of an edge (a backlash dead-zone edge, the
  model's ``events``) is redone split at the located crossings by the model's split step
  (:mod:`._step_core`), which takes the coefficients at the step's middle and the phase
  rotated linearly across the step (phase error at most ``accel h^2 / 8``).
* A model that reads a forcing from the time, at a non-whole order r of Omega (a gear train's
  stage at r Omega t, a torque fluctuation of non-whole order), runs with ``time_phase``: its
  functions get the time theta(t) / Omega(t) instead of t, so that r Omega t is r theta(t), the
  integral of r Omega (in a split step the time origin moves so that Omega at the step's
  middle times the time is the phase rotated linearly across the step).
* A state that leaves ``|y| <= bound`` or stops being finite ends the run (status 1); the rows
  after it are NaN.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._step_core import (  # CORE-IMPORT
    _JIT,
    _events_i,
    _rhs_i,
    _rk4_stages,
    _split_step,
)
from geardyn.solvers._step_shared import (
    GBUF_ROWS,
    STATUS_DIVERGED,
    STATUS_OK,
    _healthy,
    _keep_start,
    _leaves_side,
    _side,
)
from geardyn.solvers._sweep_books import _alloc  # compiled once for every model
from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

_observe_i = nb.njit(forceinline=True, _nrt=False, **_JIT)(observe.py_func)  # (as ._step_core's)

__all__ = ["events", "observe", "phase_time", "rhs", "runup_trajectory", "set_speed",
           "speed_phase"]


@nb.njit(inline="always", **_JIT)
def speed_phase(t, start, accel, t_on, t_off):
    """Forcing frequency Omega(t) and phase theta(t) = integral of Omega from 0 to t of the
    ramp (module docs)."""
    if t <= t_on:
        return start, start * t
    if t <= t_off:
        d = t - t_on
        return start + accel * d, start * t + 0.5 * accel * d * d
    d = t_off - t_on
    stop = start + accel * d
    return stop, start * t_off + 0.5 * accel * d * d + stop * (t - t_off)


@nb.njit(inline="always", **_JIT)
def set_speed(p, om, cols, coef):
    """Write the coefficients that follow Omega (quadratics in it) into p for Omega = om."""
    for j in range(cols.size):
        p[cols[j]] = coef[j, 0] + om * (coef[j, 1] + om * coef[j, 2])


@nb.njit(inline="always", **_JIT)
def phase_time(t, om, th, time_phase):
    """The time the model's functions get: t, or with ``time_phase`` theta / Omega (module
    docs; t where Omega is 0)."""
    if time_phase and om != 0.0:
        return th / om
    return t


@nb.njit(**_JIT)
def runup_trajectory(p0, y0, h, i_begin, i_end, i0, stride, last, start, accel, t_on, t_off,
                     cols, coef, locate, bound, n_ev, n_obs, resume, hist, side, time_phase):
    """Integrate one lane from grid point i_begin (time i_begin h, state y0) to i_end through
    the ramp, recording every stride-th grid point counted from i0 (none before it; the point
    i_end only if ``last``: a run cut into pieces records each point once). ``resume``: the
    run goes on from an earlier piece, whose edge sides ``side`` (n_ev) and graze-screen
    history ``hist`` (2, max(n_ev, 1): the events at the last even and odd grid points) it
    takes, so that pieces give bitwise the steps of one call; else both start afresh.
    ``time_phase``: the model's functions get the time theta / Omega (module docs).

    Returns (Y[n_rec, ns], O[n_rec, n_obs], W[n_rec] (Omega), TH[n_rec] (the phase),
    ncross[n_ev], status, unresolved, steps_done, y_end, hist, side). Rows after a divergence
    are NaN.
    """
    ns = y0.size
    p = p0.copy()  # the coefficients at the step's start, middle and end (set_speed)
    pm = p0.copy()
    pe = p0.copy()
    n_per = np.int64(1)  # the split step's phase-table period (int64, its compiled signature)
    Y, Y1, K1, K2, K3, K4, TMP, TT, G, SIDE, work, ybuf, gbuf = _alloc(1, ns, n_ev)
    ACTIVE = np.ones(1, np.bool_)
    ncross = np.zeros(max(n_ev, 1), np.int64)
    first = max(i_begin, i0)
    r0 = (first - i0 + stride - 1) // stride  # the first recorded point's number
    stop_rec = i_end if last else i_end - 1
    n_rec = max(0, (stop_rec - i0) // stride - r0 + 1) if stop_rec >= i0 else 0
    out_y = np.full((n_rec, ns), np.nan)
    out_o = np.full((n_rec, max(n_obs, 1)), np.nan)
    out_w = np.full(n_rec, np.nan)
    out_th = np.full(n_rec, np.nan)
    obuf = np.zeros(max(n_obs, 1))
    y = Y[0]
    y1 = Y1[0]
    k1 = K1[0]
    kst = K2[0]
    acc = K3[0]
    tmp = TMP[0]
    for q in range(ns):
        y[q] = y0[q]
    om, th = speed_phase(i_begin * h, start, accel, t_on, t_off)
    set_speed(p, om, cols, coef)
    _events_i(phase_time(i_begin * h, om, th, time_phase), y, G[0], p, math.sin(th),
              math.cos(th))
    for j in range(n_ev):
        SIDE[0, j] = side[j] if resume else _side(G[0, j])
    if resume:
        for r in range(2):
            for j in range(hist.shape[1]):
                gbuf[GBUF_ROWS + r, j] = hist[r, j]
    status = STATUS_OK
    unresolved = 0
    done = 0
    hh = 0.5 * h
    for i in range(i_begin, i_end + 1):
        t = i * h
        om, th = speed_phase(t, start, accel, t_on, t_off)
        sa = math.sin(th)
        ca = math.cos(th)
        set_speed(p, om, cols, coef)
        if i >= i0 and (i - i0) % stride == 0 and i <= stop_rec:
            r = (i - i0) // stride - r0
            for q in range(ns):
                out_y[r, q] = y[q]
            out_w[r] = om
            out_th[r] = th
            if n_obs > 0:
                _observe_i(phase_time(t, om, th, time_phase), y, obuf, p, sa, ca)
                for q in range(n_obs):
                    out_o[r, q] = obuf[q]
        if i == i_end:
            break
        _rhs_i(phase_time(t, om, th, time_phase), y, k1, p, sa, ca)
        om_m, th_m = speed_phase(t + hh, start, accel, t_on, t_off)
        set_speed(pm, om_m, cols, coef)
        om_e, th_e = speed_phase(t + h, start, accel, t_on, t_off)
        se = math.sin(th_e)
        ce = math.cos(th_e)
        set_speed(pe, om_e, cols, coef)
        te = phase_time(t + h, om_e, th_e, time_phase)
        _rk4_stages(y, h, phase_time(t + hh, om_m, th_m, time_phase), pm, math.sin(th_m),
                    math.cos(th_m), te, pe, se, ce, k1, kst, acc, tmp, y1)
        if n_ev > 0:
            _keep_start(i, 1, ACTIVE, G, gbuf)
            _events_i(te, y1, G[0], pe, se, ce)
            crossed = _leaves_side(i, 0, G, SIDE, locate, gbuf)
        else:
            crossed = 0
        if crossed and locate:
            # with time_phase, Omega_m (t0 + i h) is theta at the step's start
            t0 = th / om_m - i * h if time_phase and om_m != 0.0 else 0.0
            unresolved += _split_step(i, t0, y, y1, pm, h, (th_e - th) / h, n_per, sa, ca, se,
                                      ce, SIDE[0], G[0], ncross, work, ybuf, gbuf)
        else:
            if crossed:
                for j in range(n_ev):
                    s_new = _side(G[0, j])
                    if s_new != SIDE[0, j]:
                        SIDE[0, j] = s_new
                        ncross[j] += 1
            for q in range(ns):
                y[q] = y1[q]
        done = i + 1 - i_begin
        if not _healthy(y, bound):
            status = STATUS_DIVERGED
            break
    return (out_y, out_o[:, :n_obs], out_w, out_th, ncross[:n_ev], status, unresolved, done,
            y.copy(), gbuf[GBUF_ROWS:GBUF_ROWS + 2].copy(), SIDE[0, :n_ev].copy())
