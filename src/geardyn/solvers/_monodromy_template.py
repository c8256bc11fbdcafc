"""The period map and its Jacobian (the monodromy matrix), specialised per model.

This file is a template, like :mod:`geardyn.solvers._kernel_template`:
:func:`geardyn.solvers.kernels.kernels_for` (template ``"monodromy"``) copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions. As it stands it is a valid
module bound to the small test oscillator of :mod:`geardyn.solvers._template_model`.

Numerics (the approach of :mod:`geardyn.solvers._lyapunov_template`, without renormalisation)
------------------------------------------------------------------------------------------------
* The state y is advanced on the main solver's grid (RK4 steps of ``h``, ``n_per`` per forcing
  period, forcing phase from the half-step table), every step split at the located crossings of
  the switching functions (:mod:`._step_core`).
* The Jacobian of the map over ``n_steps`` grid steps, M = D Phi_n ... D Phi_1, is built one
  grid step at a time: its columns (in the scaled coordinates z = y / s, s the model's
  ``state_scale``) are tangent vectors, each advanced by the central difference of that grid
  step's map, ``(Phi(y + e s v) - Phi(y - e s v)) / (2 e s)`` with ``e |v| = FD_DELTA (1 +
  min(|y / s|, FD_NORM_CAP))``. The perturbed states locate their own edge crossings, so a step
  in which one of them crosses is differentiated correctly: the Jacobian switches exactly at the
  edge. The vector field is continuous across the edges (the dead-zone force is), so the flow is
  C^1 there and no saltation matrix is needed. For a step map affine in y (a linear model, also
  with time-varying stiffness) the difference is exact up to rounding, ~eps / FD_DELTA ~ 1e-10
  relative per step; otherwise its error is O(e^2) per step.
* Cost: (2 n + 1) RK4 steps per grid step for n states, run as the rows of one lockstep block.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.solvers._step_core import (  # CORE-IMPORT
    _JIT,
    _rows_step,
    _tangent_step,
)
from geardyn.solvers._step_shared import (
    GBUF_ROWS,
    STATUS_DIVERGED,
    STATUS_OK,
    _healthy,
    phase_table,
)
from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

__all__ = ["events", "observe", "period_map", "phase_table", "rhs"]


@nb.njit(**_JIT)
def period_map(p, y0, scale, t0, h, omega, n_per, n_steps, n_ev, bound, stride, jacobian):
    """The map y0 -> y(t0 + n_steps h) of one lane and, with ``jacobian``, its Jacobian.

    Grid: step h (= 2 pi / (omega n_per)); y0 is given at time t0, where the forcing phase is
    zero; ``n_ev`` switching functions are located inside steps. ``scale``: the model's state
    scale (the finite differences are sized in y / scale). Returns (y_end[ns], M[ns, ns] (the
    Jacobian dy_end / dy0; NaN without ``jacobian``), Y[n_rec, ns] (the state at every stride-th
    grid point, n_rec = n_steps // stride + 1), ncross[n_ev] (the state's edge crossings),
    status, unresolved (steps of any row that reached the split limit)).
    """
    ns = y0.size
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    S = np.empty(ns)
    IS = np.empty(ns)
    for q in range(ns):
        S[q] = scale[q]
        IS[q] = 1.0 / scale[q]
    m = ns + 1 if jacobian else 1
    nr = 2 * m - 1
    Z = np.zeros((m, ns))
    for q in range(ns):
        Z[0, q] = y0[q]
    for j in range(1, m):
        Z[j, j - 1] = 1.0
    YP = np.zeros((nr, ns))
    E = np.zeros(m)  # the perturbation size of each tangent vector in this step
    K = np.zeros((4, nr, ns))
    TMP = np.zeros((nr, ns))
    Y1 = np.zeros((nr, ns))
    ne = max(n_ev, 1)
    SIDE = np.ones((nr, ne), np.int64)
    G0 = np.zeros((nr, ne))
    G1 = np.zeros((nr, ne))
    W = np.zeros((9, ns))
    gbuf = np.zeros((GBUF_ROWS, ne))
    NCR = np.zeros((nr, ne), np.int64)
    UNRES = np.zeros(nr, np.int64)
    n_rec = n_steps // stride + 1
    Y = np.full((n_rec, ns), np.nan)
    M = np.full((ns, ns), np.nan)
    status = STATUS_OK
    for q in range(ns):
        Y[0, q] = y0[q]
    for i in range(n_steps):
        if jacobian:
            ok = _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E,
                               K, TMP, Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES)
        else:
            _rows_step(i, t0, Z, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0,
                       G1, W, gbuf, NCR, UNRES)
            ok = True
        if not ok or not _healthy(Z[0], bound):
            status = STATUS_DIVERGED
            break
        if (i + 1) % stride == 0:
            for q in range(ns):
                Y[(i + 1) // stride, q] = Z[0, q]
    unres = 0
    for r in range(nr):
        unres += UNRES[r]
    if status == STATUS_OK and jacobian:
        for j in range(ns):  # column j of M in y: S (Z[j + 1] in z) / S[j]
            for q in range(ns):
                M[q, j] = S[q] * Z[j + 1, q] * IS[j]
        for j in range(ns):
            for q in range(ns):
                if not math.isfinite(M[q, j]):
                    status = STATUS_DIVERGED
    return Z[0].copy(), M, Y, NCR[nr - 1, :n_ev].copy(), status, unres  # the state: last row
