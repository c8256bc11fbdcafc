"""Bifurcation sweeps: the steady motion of a model, point by point along one parameter."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import xarray as xr

from geardyn.analysis.contact import contact_regime
from geardyn.analysis.periodicity import DEFAULT_MAX_PERIOD, DEFAULT_TOL, classify_period
from geardyn.models.base import Model
from geardyn.solvers.ensemble import LaneResults, run_lanes
from geardyn.solvers.simulate import DEFAULT_BOUND


def _concat(parts: list[LaneResults]) -> LaneResults:
    fields = LaneResults.__dataclass_fields__
    return LaneResults(**{f: np.concatenate([getattr(r, f) for r in parts]) for f in fields})


def _continuation(model, P, order, y0, transient, samples, steps_per_period, locate_edges,
                  bound, progress=None) -> LaneResults:
    parts: list[LaneResults | None] = [None] * len(order)
    y, t0 = np.asarray(y0, dtype=float), 0.0
    for done, pos in enumerate(order):
        if progress is not None:
            progress(done, len(order))
        r = run_lanes(model, P[pos : pos + 1], y, transient, samples, steps_per_period,
                      locate_edges=locate_edges, bound=bound, t0=np.array([t0]))
        parts[pos] = r
        if r.status[0] == 0:
            y, t0 = r.final[0], float(r.final_time[0])
        else:  # lost the branch: restart from the model's initial state
            y, t0 = np.asarray(y0, dtype=float), 0.0
    if progress is not None:
        progress(len(order), len(order))
    return _concat(parts)  # type: ignore[arg-type]


def _chunked(model, P, y0, transient, samples, steps_per_period, locate_edges, bound, chunk,
             progress, offset, total) -> LaneResults:
    """run_lanes over consecutive chunks of lanes, reporting progress after each."""
    L = P.shape[0]
    size = chunk or max(64, -(-L // 20))
    Y0 = np.broadcast_to(np.asarray(y0, dtype=float), (L, model.n_states))
    parts = []
    for a in range(0, L, size):
        b = min(L, a + size)
        parts.append(run_lanes(model, P[a:b], Y0[a:b], transient, samples, steps_per_period,
                               locate_edges=locate_edges, bound=bound))
        if progress is not None:
            progress(offset + b, total)
    return parts[0] if len(parts) == 1 else _concat(parts)


def bifurcation(
    model: Model,
    param: str = "Omega",
    values: Sequence[float] | np.ndarray = (),
    transient: float = 4000.0,
    samples: int = 200,
    continuation: str | None = None,
    steps_per_period: int | None = None,
    lyapunov: bool = False,
    max_period: int = DEFAULT_MAX_PERIOD,
    tol: float = DEFAULT_TOL,
    y0: np.ndarray | None = None,
    starts: int = 1,
    seed: int = 0,
    spread: float = 1.0,
    locate_edges: bool = True,
    bound: float = DEFAULT_BOUND,
    progress: Callable[[int, int], None] | None = None,
    chunk: int | None = None,
) -> xr.Dataset:
    """Sweep ``param`` over ``values`` and classify the steady motion at every point.

    Parameters
    ----------
    param
        ``"Omega"`` (the forcing frequency) or any parameter name the model accepts in
        ``lane_params`` (for :class:`~geardyn.CATTDevice`: ``xi1``, ``xi``, ``backlash``,
        ``error``, ``B1``, ``T_D``, ...).
    transient
        Time discarded at every point, in model time units (tau), rounded up to whole periods.
    samples
        Forcing periods recorded (one Poincare point each) after the transient.
    continuation
        ``None``: every point starts from ``y0``; ``"up"``/``"down"``: each point starts from the
        final state of the previous one in ascending/descending order (shows hysteresis).
    starts
        Independent starts per point (``continuation=None`` only): the first from ``y0``, the
        others from ``y0`` plus uniform noise of half-width ``spread`` on each state (``seed``).
        Their Poincare points are stacked along ``sample``; ``period_by_start`` keeps each.
    progress
        Called as ``progress(done, total)`` (integrations finished, of all) after each chunk.
    chunk
        Lanes per kernel call (default: about a twentieth of the sweep, at least 64). Lanes are
        independent, so the result does not depend on it.

    Returns
    -------
    xarray.Dataset with coordinates ``param``, ``sample``, ``state``, ``mesh`` and variables
    ``poincare`` (param, sample, state), ``period`` (param; k >= 1 period-k, 0 quasi-periodic or
    chaotic, -1 unbounded), ``contact`` (param, mesh: none/single/double/unbounded),
    ``force_peak``, ``force_rms``, ``dynamic_factor`` (param, mesh), ``status``, and
    ``lyapunov`` (param) when asked.
    """
    values = np.asarray(values, dtype=float).ravel()
    if values.size == 0:
        raise ValueError("values: give at least one parameter value")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"values: must be finite (got {values[~np.isfinite(values)][0]!r})")
    if continuation not in (None, "up", "down"):
        raise ValueError(f"continuation must be None, 'up' or 'down' (got {continuation!r})")
    if starts < 1 or (starts > 1 and continuation):
        raise ValueError("starts must be >= 1, and 1 with continuation")
    P = model.lane_params(param, values)
    if y0 is not None:
        base_y0 = np.asarray(y0, dtype=float)
    elif param == "Omega":
        base_y0 = model.initial_state()
    else:  # each point starts from its own model's initial (static) state
        base_y0 = np.array([model.with_params(**{param: float(v)}).initial_state()
                            for v in values])
    L, ns = values.size, model.n_states
    if continuation:
        order = np.argsort(values, kind="stable")
        if continuation == "down":
            order = order[::-1]
        runs = [_continuation(model, P, order, base_y0 if base_y0.ndim == 1 else base_y0[0],
                              transient, samples, steps_per_period, locate_edges, bound,
                              progress)]
    else:
        rng = np.random.default_rng(seed)
        runs = []
        for s in range(starts):
            y_s = base_y0 if s == 0 else base_y0 + rng.uniform(-spread, spread, (L, ns))
            runs.append(_chunked(model, P, y_s, transient, samples, steps_per_period,
                                 locate_edges, bound, chunk, progress, s * L, starts * L))
    first = runs[0]
    poincare = np.concatenate([r.samples for r in runs], axis=1)
    periods = np.stack([classify_period(r.samples, max_period, tol) for r in runs], axis=1)
    status = np.max(np.stack([r.status for r in runs], axis=1), axis=1)
    ds = xr.Dataset(coords={
        param: (param, values),
        "sample": ("sample", np.arange(poincare.shape[1])),
        "state": ("state", list(model.state_names)),
    })
    ds["poincare"] = ((param, "sample", "state"), poincare, {
        "long_name": "Poincare points (states once per forcing period after the transient)"})
    ds["period"] = (param, periods[:, 0], {
        "long_name": "period in forcing periods", "meaning": "k>=1 period-k, 0 quasi-periodic "
        "or chaotic, -1 unbounded", "tolerance": tol, "max_period": max_period})
    if starts > 1:
        ds["period_by_start"] = ((param, "start"), periods)
        ds["start_of_sample"] = ("sample", np.repeat(np.arange(starts), samples))
    ds["status"] = (param, status, {"meaning": "0 ok, 1 diverged in at least one start"})
    ds["steps_per_period"] = (param, first.steps_per_period)
    ds["transient_periods"] = (param, first.transient_periods)
    ds["unresolved_steps"] = (param, first.unresolved)
    if model.meshes:
        names = [m[0] for m in model.meshes]
        ds = ds.assign_coords(mesh=("mesh", names))
        regimes = np.stack([contact_regime(first.event_min, first.event_max, first.crossings,
                                           d, b, first.status) for _, d, b in model.meshes],
                           axis=1)
        ds["contact"] = ((param, "mesh"), regimes, {
            "meaning": "none: teeth never separate; single: separation, no back-flank contact; "
                       "double: back-flank contact; unbounded: diverged"})
        if model.n_observables == len(names):
            peak = np.maximum(np.abs(first.obs_max), np.abs(first.obs_min))
            ds["force_peak"] = ((param, "mesh"), peak, {"units": model.observable_units})
            ds["force_rms"] = ((param, "mesh"), first.obs_rms, {"units": model.observable_units})
            static = _static_forces(model, param, values)
            if static is not None:
                with np.errstate(divide="ignore", invalid="ignore"):
                    ds["dynamic_factor"] = ((param, "mesh"), peak / np.abs(static), {
                        "long_name": "peak dynamic mesh force / static mesh force"})
    if lyapunov:
        from geardyn.analysis.lyapunov import lyapunov_lanes

        exps = lyapunov_lanes(model, P, base_y0, transient, samples * _mean_period(model, P),
                              steps_per_period)
        ds["lyapunov"] = (param, np.where(status == 0, exps, np.nan), {
            "long_name": "largest Lyapunov exponent", "units": f"1/{model.time_unit}"})
    ds.attrs.update(
        model=model.name, param=param, transient=float(transient), samples=int(samples),
        continuation=continuation or "none", starts=int(starts),
        integrator="RK4, fixed step aligned to the forcing period",
        locate_edges=int(bool(locate_edges)), bound=float(bound), period_tol=float(tol),
        max_period=int(max_period), time_unit=model.time_unit,
    )
    for key in ("interpretation",):
        if hasattr(model, key):
            ds.attrs[key] = getattr(model, key)
    if hasattr(model, "omega_n"):
        ds.attrs["omega_n"] = float(model.omega_n)
    return ds


def _mean_period(model: Model, P: np.ndarray) -> float:
    return float(np.mean(2.0 * math.pi / P[:, model.omega_index]))


def _static_forces(model: Model, param: str, values: np.ndarray) -> np.ndarray | None:
    base = model.static_mesh_forces()
    if base is None:
        return None
    if param == "Omega":
        return np.broadcast_to(base, (values.size, base.size))
    rows = [model.with_params(**{param: float(v)}).static_mesh_forces() for v in values]
    return np.array(rows)
