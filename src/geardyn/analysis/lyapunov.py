"""Lyapunov exponents of any geardyn model from its tangent (variational) equations.

The state and k tangent vectors are integrated by fixed-step RK4 on the main solver's grid, the
tangent dynamics J(t, y) v coming from a central finite difference of the model's ``rhs``; the
vectors are re-orthonormalised (modified Gram-Schmidt) every ``renorm_every`` steps and the logs
of the stretching factors averaged (Benettin et al. 1980). See ``docs/lyapunov.md`` and the kernel
template :mod:`geardyn.solvers._lyapunov_template`.
"""

from __future__ import annotations

import math

import numpy as np

from geardyn.models.base import Model
from geardyn.solvers.ensemble import lane_steps_per_period
from geardyn.solvers.kernels import kernels_for
from geardyn.solvers.simulate import DEFAULT_BOUND, default_steps_per_period

#: Default step of an autonomous model.
DEFAULT_DT = 0.01
#: Default number of RK4 steps between re-orthonormalisations.
DEFAULT_RENORM_EVERY = 10

__all__ = ["DEFAULT_DT", "DEFAULT_RENORM_EVERY", "lyapunov", "lyapunov_lanes"]


def _check_time(name: str, value: float, positive: bool) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0 or (positive and value == 0):
        need = "> 0" if positive else ">= 0"
        raise ValueError(f"{name} must be a finite time {need} (got {value!r})")
    return value


def _whole_periods(time: float, period: float) -> int:
    """Whole periods covering ``time`` (rounded up, tolerant of rounding error)."""
    return math.ceil(time / period - 1e-9)


def _initial(model: Model, y0) -> np.ndarray:
    y = np.asarray(model.initial_state() if y0 is None else y0, dtype=float).ravel().copy()
    if y.shape != (model.n_states,):
        raise ValueError(f"y0 must have {model.n_states} entries ({', '.join(model.state_names)})")
    if not np.all(np.isfinite(y)):
        raise ValueError("y0 must be finite")
    return y


def lyapunov(
    model: Model,
    y0=None,
    transient: float = 100.0,
    duration: float = 2000.0,
    spectrum: bool = False,
    dt: float | None = None,
    steps_per_period: int | None = None,
    renorm_every: int | None = None,
    bound: float = DEFAULT_BOUND,
) -> float | np.ndarray:
    """Largest Lyapunov exponent of ``model`` (or the whole spectrum), per unit model time.

    Parameters
    ----------
    y0
        Initial state (default: ``model.initial_state()``).
    transient, duration
        Time discarded first and time averaged over, in the model's time unit. For a forced model
        both are rounded up to whole forcing periods.
    spectrum
        False: the largest exponent (one tangent vector), a float. True: all ``n_states``
        exponents, in descending order, as an array.
    dt
        Step of an autonomous model (``model.omega == 0``; default 0.01). Not used for a forced
        model, whose grid has ``steps_per_period`` steps per forcing period (default
        :func:`~geardyn.solvers.simulate.default_steps_per_period`), as in ``simulate``.
    renorm_every
        RK4 steps between re-orthonormalisations (default 10).
    bound
        A state beyond this magnitude counts as diverged; the result is then NaN.

    For a forced model the exponent of the flow's zero direction (along the forcing phase) is not
    included: the phase is not a state, so a forced model with n states has n exponents.
    """
    transient = _check_time("transient", transient, False)
    duration = _check_time("duration", duration, True)
    y = _initial(model, y0)
    om = model.omega
    if om == 0.0:
        if steps_per_period is not None:
            raise ValueError("steps_per_period applies to forced models; give dt instead")
        h = DEFAULT_DT if dt is None else float(dt)
        if not (h > 0 and math.isfinite(h)):
            raise ValueError(f"dt must be > 0 (got {dt!r})")
        n_per = 1
        n_tr = math.ceil(transient / h - 1e-9)
        n_st = max(1, math.ceil(duration / h - 1e-9))
    else:
        if not (om > 0 and math.isfinite(om)):
            raise ValueError(f"omega must be a positive finite number (got {om!r})")
        if dt is not None:
            raise ValueError("dt applies to autonomous models; give steps_per_period instead")
        n_per = int(steps_per_period or default_steps_per_period(model, om))
        if n_per < 4:
            raise ValueError(f"steps_per_period must be >= 4 (got {n_per})")
        period = 2.0 * math.pi / om
        h = period / n_per
        n_tr = _whole_periods(transient, period) * n_per
        n_st = max(1, _whole_periods(duration, period)) * n_per
    renorm = int(DEFAULT_RENORM_EVERY if renorm_every is None else renorm_every)
    if renorm < 1:
        raise ValueError(f"renorm_every must be >= 1 (got {renorm_every!r})")
    k = model.n_states if spectrum else 1
    kern = kernels_for(model.kernel, "lyapunov")
    p = np.ascontiguousarray(model.params, dtype=float)
    ex, _status = kern.lyapunov_single(p, y, h, om, n_per, n_tr, n_st, renorm, k, float(bound),
                                         model.n_events)
    ex = np.asarray(ex, dtype=float)
    if spectrum:
        return np.sort(ex)[::-1].copy()
    return float(ex[0])


def lyapunov_lanes(
    model: Model,
    P: np.ndarray,
    y0=None,
    transient: float = 100.0,
    duration: float = 2000.0,
    steps_per_period: int | None = None,
    dt: float | None = None,
    renorm_every: int | None = None,
    bound: float = DEFAULT_BOUND,
) -> np.ndarray:
    """Largest Lyapunov exponent for each row of the coefficient matrix ``P`` (lanes x n_params,
    e.g. from ``model.lane_params``), computed in parallel; NaN for diverged lanes.

    ``y0``: one initial state for all lanes, or one per lane (lanes x n_states); default
    ``model.initial_state()``. ``transient`` and ``duration`` are times, rounded up to whole
    forcing periods of each lane (lanes differ in Omega, so their step counts differ). The grid has
    ``steps_per_period`` steps per period (default: each lane's own
    :func:`default_steps_per_period`, rounded up to the sweep's step ladder, as in
    :func:`~geardyn.solvers.ensemble.run_lanes`); an autonomous model uses the step ``dt``
    (default 0.01).
    """
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    L = P.shape[0]
    if P.shape[1] != model.params.size:
        raise ValueError(f"P must have {model.params.size} columns (got {P.shape[1]})")
    if not np.all(np.isfinite(P)):
        raise ValueError("P must be finite")
    transient = _check_time("transient", transient, False)
    duration = _check_time("duration", duration, True)
    if y0 is None:
        Y0 = np.tile(model.initial_state(), (L, 1))
    else:
        Y0 = np.asarray(y0, dtype=float)
        Y0 = np.tile(Y0, (L, 1)) if Y0.ndim == 1 else Y0.copy()
    if Y0.shape != (L, model.n_states):
        raise ValueError(f"y0 must have {model.n_states} entries or shape ({L}, {model.n_states})")
    Y0 = np.ascontiguousarray(Y0)
    if model.omega_index is None:
        if steps_per_period is not None:
            raise ValueError("steps_per_period applies to forced models; give dt instead")
        h = DEFAULT_DT if dt is None else float(dt)
        if not (h > 0 and math.isfinite(h)):
            raise ValueError(f"dt must be > 0 (got {dt!r})")
        OMEGA = np.zeros(L)
        H = np.full(L, h)
        n_per = 1
        n_tr = np.full(L, math.ceil(transient / h - 1e-9), dtype=np.int64)
        n_st = np.full(L, max(1, math.ceil(duration / h - 1e-9)), dtype=np.int64)
    else:
        if dt is not None:
            raise ValueError("dt applies to autonomous models; give steps_per_period instead")
        OMEGA = np.ascontiguousarray(P[:, model.omega_index])
        if not np.all(OMEGA > 0):
            raise ValueError("every lane needs a forcing frequency Omega > 0")
        if steps_per_period is None:
            n_lane = lane_steps_per_period(model, P)
        else:
            n_lane = np.full(L, int(steps_per_period), dtype=np.int64)
        if np.any(n_lane < 4):
            raise ValueError(f"steps_per_period must be >= 4 (got {steps_per_period})")
        periods = 2.0 * np.pi / OMEGA
        H = periods / n_lane
        n_tr = np.array([_whole_periods(transient, T) * n
                         for T, n in zip(periods, n_lane, strict=True)], dtype=np.int64)
        n_st = np.array([max(1, _whole_periods(duration, T)) * n
                         for T, n in zip(periods, n_lane, strict=True)], dtype=np.int64)
    renorm = int(DEFAULT_RENORM_EVERY if renorm_every is None else renorm_every)
    if renorm < 1:
        raise ValueError(f"renorm_every must be >= 1 (got {renorm_every!r})")
    out = np.full(L, np.nan)
    if L == 0:
        return out
    kern = kernels_for(model.kernel, "lyapunov")
    if model.omega_index is None:
        kern.lyapunov_lanes(P, Y0, H, OMEGA, n_per, n_tr, n_st, renorm, float(bound), out,
                            model.n_events)
        return out
    for n in np.unique(n_lane):  # one kernel call per step count (one phase table)
        idx = np.nonzero(n_lane == n)[0]
        part = np.full(idx.size, np.nan)
        kern.lyapunov_lanes(P[idx], Y0[idx], H[idx], OMEGA[idx], int(n), n_tr[idx], n_st[idx],
                            renorm, float(bound), part, model.n_events)
        out[idx] = part
    return out
