"""Accurate reference integration with SciPy (for verification, not speed).

An adaptive high-order method (DOP853 by default) at tight tolerance, stopped exactly at every
zero crossing of the model's switching functions and restarted there, so that no step straddles a
kink of the right-hand side. Each event remembers the side the trajectory is on and fires only
when it leaves that side, so a restart on the edge does not fire again.
"""

from __future__ import annotations

import numpy as np

from geardyn.core.model import Model
from geardyn.solvers.kernels import kernels_for


def _functions(model: Model):
    k = kernels_for(model.kernel)
    p = np.ascontiguousarray(model.params, dtype=float)
    om = model.omega
    dy = np.empty(model.n_states)
    g = np.empty(max(model.n_events, 1))

    def f(t, y):
        k.rhs(t, y, dy, p, np.sin(om * t), np.cos(om * t))
        return dy.copy()

    def ev(t, y):
        k.events(t, y, g, p, np.sin(om * t), np.cos(om * t))
        return g[: model.n_events].copy()

    return f, ev


def reference_solution(
    model: Model,
    y0: np.ndarray,
    t_eval: np.ndarray,
    t0: float = 0.0,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    method: str = "DOP853",
    locate: bool = True,
    max_restarts: int = 1_000_000,
) -> np.ndarray:
    """States at the times ``t_eval`` (ascending, >= t0), shape (len(t_eval), n_states).

    Every requested time is the end of an integration (not a point of the solver's interpolant,
    which is less accurate than its steps); every switching-function crossing ends one too.
    """
    from scipy.integrate import solve_ivp  # imported here: ~1 s, needed by this call only

    f, ev = _functions(model)
    t_eval = np.asarray(t_eval, dtype=float)
    out = np.full((t_eval.size, model.n_states), np.nan)
    t, y = float(t0), np.asarray(y0, dtype=float).copy()
    n_ev = model.n_events if locate else 0
    side = np.where(ev(t, y) > 0.0, 1.0, -1.0) if n_ev else np.zeros(0)
    restarts = 0
    for k, target in enumerate(t_eval):
        if target < t:
            raise ValueError("t_eval must be ascending and >= t0")
        while target > t:
            restarts += 1
            if restarts > max_restarts:
                raise RuntimeError("reference integration: too many restarts")
            events = []
            for j in range(n_ev):
                def event(tt, yy, j=j):
                    return ev(tt, yy)[j]

                event.terminal = True
                event.direction = -side[j]
                events.append(event)
            sol = solve_ivp(f, (t, float(target)), y, method=method, rtol=rtol, atol=atol,
                            events=events or None)
            if sol.status == -1:
                raise RuntimeError(f"reference integration failed at t={t:g}: {sol.message}")
            if sol.status == 1:
                hit = [j for j in range(n_ev) if sol.t_events[j].size]
                j = min(hit, key=lambda jj: sol.t_events[jj][0])
                t, y = float(sol.t_events[j][0]), sol.y_events[j][0].copy()
                side[j] = -side[j]
            else:
                t, y = float(target), sol.y[:, -1].copy()
        out[k] = y
    return out
