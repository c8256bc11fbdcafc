"""The scalar step machinery shared by the kernel templates: the forcing-phase table, one RK4
step, the cubic Hermite interpolant of a step, crossing location, and a grid step split at the
located edge crossings.

Like the templates, this is template text: :func:`geardyn.solvers.kernels.kernels_for` splices it
into a generated kernel module in place of the template's ``CORE-IMPORT`` line, bound there to the
model's ``rhs`` and ``events``. As it stands it is a valid module bound to the test oscillator of
:mod:`geardyn.solvers._template_model`.

Edge location: a step whose end lies on another side of an edge (a zero of ``events``) than its
start is split at the crossing, located by root-finding (Illinois) on the cubic Hermite
interpolant of the step (error O(h^4) in the crossing time), and integrated in sub-steps, so every
RK4 stage sees a smooth right-hand side and the method keeps 4th order. A step is split at most
``MAX_SPLITS`` times (grazing contacts); crossings located within ``SIMULTANEOUS`` of a step of
the earliest are taken together (identical planet sets cross their edges at the same instant).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._template_model import events, rhs  # MODEL-IMPORT

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False}
MAX_SPLITS = 16
SIMULTANEOUS = 1e-9
STATUS_OK = 0
STATUS_DIVERGED = 1
# MODEL-ADAPTERS (a user's plain functions are adapted to the kernel interface here)
# The model's functions inlined (numba IR inlining) where they are called in a loop: a call with
# array arguments would otherwise cost reference counting on every stage of every step.
_INLINE = {"inline": "always", "error_model": "numpy", "boundscheck": False}
_rhs_i = nb.njit(**_INLINE)(rhs.py_func)
_events_i = nb.njit(**_INLINE)(events.py_func)


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


@nb.njit(inline="always", **_JIT)
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
def _healthy(y, bound):
    for q in range(y.size):
        v = y[q]
        if not (abs(v) <= bound):  # False for NaN too
            return False
    return True
