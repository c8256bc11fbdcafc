"""Two-parameter maps: the steady motion over a grid of two parameters (e.g. Omega x damping).

Every grid point is one lane (its own coefficient vector, from
:meth:`~geardyn.Model.lane_params_grid`) integrated from the model's initial state, as in a
bifurcation sweep with independent starts; the per-lane analysis is the same
(:func:`geardyn.analysis.lanes.lane_variables`). Chunks of lanes run through
:func:`geardyn.execution.executor.run_chunks`: locally, on a Dask cluster, and resumable with a Zarr
store. :func:`estimate_map` tells the cost of a grid before it is built.
"""

from __future__ import annotations

import functools
import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.dataset import map_dataset, model_attrs
from geardyn.analysis.lanes import (
    CONTACT_LABELS,
    has_mesh_forces,
    lane_variables,
)
from geardyn.analysis.motion import averaging_time, motion_variable
from geardyn.core.model import Model
from geardyn.core.plan import (
    default_steps_per_period,
    forcing_period,
    ladder_steps,
    lane_section,
    periods_covering,
)
from geardyn.core.results import finish
from geardyn.core.settings import LyapunovSettings, RunSettings, check_omega, resolve_run
from geardyn.core.status import Status
from geardyn.execution.executor import default_chunk, run_chunks
from geardyn.solvers.ensemble import busy_lanes, run_lanes

__all__ = ["MapEstimate", "check_steps", "estimate_map", "map2d", "measure_ns_per_lane_step"]

Axis = tuple[str, Sequence[float] | np.ndarray]

#: Assumed cost of a Lyapunov lane-step (state plus tangent vector, finite-difference Jacobian)
#: relative to a plain RK4 lane-step.
LYAPUNOV_COST = 3.0


# ---------------------------------------------------------------------------- the chunk task
def _map_task(model: Model, P: np.ndarray, y0: np.ndarray, static: np.ndarray | None = None, *,
              run: RunSettings, lyapunov: dict[str, Any] | None) -> dict[str, np.ndarray]:
    """One chunk of a map: run_lanes, the per-lane analysis, optionally Lyapunov exponents.
    Returns numeric lane-first arrays only (``contact`` as codes into ``CONTACT_LABELS``)."""
    r = run_lanes(model, P, y0, run=run)
    out = lane_variables(model, r, static, run.max_period, run.period_tol)
    if "contact" in out:
        codes = {label: k for k, label in enumerate(CONTACT_LABELS)}
        out["contact"] = np.vectorize(codes.__getitem__, otypes=[np.int8])(out["contact"])
    out["status"] = r.status
    if lyapunov is not None:
        from geardyn.analysis.lyapunov import lyapunov_lanes

        # from each point's final state at its final time (both forcing phases continue): the
        # attractor its period and contact describe
        start = np.where(np.isfinite(r.final), r.final,
                         np.broadcast_to(np.asarray(y0, dtype=float), r.final.shape))
        exps, errs, unres, _ = lyapunov_lanes(model, P, start, t0=r.final_time,
                                              with_status=True, **lyapunov)
        out["lyapunov"] = np.where(r.status == Status.OK, exps, np.nan)
        out["lyapunov_err"] = np.where(np.isfinite(out["lyapunov"]), errs, np.nan)
        out["lyapunov_unresolved"] = unres
    return out


# ---------------------------------------------------------------------------- lanes of a grid
def _axis(axis: Axis, label: str) -> tuple[str, np.ndarray]:
    try:
        name, values = axis
    except (TypeError, ValueError):
        raise ValueError(f"{label}: give (parameter name, values)") from None
    if not isinstance(name, str) or not name:
        raise ValueError(f"{label}: the parameter name must be a non-empty string (got {name!r})")
    v = np.asarray(values, dtype=float).ravel()
    if v.size == 0:
        raise ValueError(f"{label}: give at least one value of {name}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{label}: values of {name} must be finite "
                         f"(got {v[~np.isfinite(v)][0]!r})")
    return name, v


def _per_lane(model: Model, xn: str, xv: np.ndarray, yn: str, yv: np.ndarray,
              fn: Callable[[Model], np.ndarray]) -> np.ndarray:
    """``fn`` of each grid point's model, (ny * nx, ...); Omega changes no model property here
    (the forcing frequency is a lane setting), so a model is built per row, column or point."""
    def at(name: str, value: float, m: Model) -> Model:
        return m if name == "Omega" else m.with_params(**{name: float(value)})

    if xn == "Omega":
        rows = [fn(at(yn, v, model)) for v in yv]
        return np.repeat(np.array(rows), xv.size, axis=0)
    if yn == "Omega":
        row = np.array([fn(at(xn, u, model)) for u in xv])
        return np.tile(row, (yv.size,) + (1,) * (row.ndim - 1))
    return np.array([fn(at(xn, u, at(yn, v, model))) for v in yv for u in xv])


# ---------------------------------------------------------------------------- the map
def map2d(
    model: Model,
    x: Axis,
    y: Axis,
    run: RunSettings | None = None,
    *,
    lyapunov: bool = False,
    client: Any = None,
    store: str | os.PathLike[str] | None = None,
    chunk: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    **settings: Any,
) -> xr.Dataset:
    """Classify the steady motion over the grid ``y x x`` of two model parameters.

    Parameters
    ----------
    x, y
        ``(name, values)``: ``"Omega"`` or any parameter the model accepts in ``lane_params``
        (for :class:`~geardyn.CATTDevice`: ``xi``, ``xi1``, ``backlash``, ``error``, ``B1``, ...).
    run
        :class:`~geardyn.RunSettings`, as for :func:`~geardyn.bifurcation` (independent
        starts from each point's own initial state; ``samples`` >= 2), or its fields as the
        old keyword arguments (``transient``, ``samples``, ``steps_per_period``,
        ``max_period``, ``tol``, ``locate_edges``, ``bound``, ...; deprecated, one
        DeprecationWarning naming the equivalent ``run=``).
    lyapunov
        Also compute the largest Lyapunov exponent per point (over ``samples`` mean forcing
        periods, with the run's ``transient``, ``locate_edges``, ``bound`` and grid of
        ``steps_per_period`` steps, default each point's own step rule), from the point's
        final state at its final time, with its standard error
        (``lyapunov_err``) and the motion class (``motion``, see :mod:`geardyn.analysis.motion`).
    client
        A ``dask.distributed.Client``: chunks run as tasks on its cluster. The result is bitwise
        that of the local run.
    store
        Path of a Zarr store: finished chunks are written there (group ``lanes``) as they
        complete, and a rerun with the same inputs computes only the missing ones; the finished
        map is written at its root, so ``xarray.open_zarr(store)`` opens it (see
        ``docs/scaling.md``).
    chunk
        Lanes (grid points) per task; default about a twentieth of the grid, at least 64.
    progress
        Called as ``progress(points_done, points_total)`` after every chunk.

    Returns
    -------
    xarray.Dataset with dimensions (y name, x name[, mesh]) and variables ``period`` (k >= 1
    period-k, 0 no period <= max_period found, -1 unbounded), ``contact`` (none/single/double/
    unbounded per mesh), ``force_peak``, ``force_rms``, ``dynamic_factor``, ``status``, step
    counts, and ``lyapunov`` and ``lyapunov_err`` when asked; the settings in ``attrs``
    (``x``, ``y``, ...).
    """
    run = resolve_run(run, settings, aliases={"tol": "period_tol"}, where="map2d")
    transient, samples, steps_per_period = run.transient, run.samples, run.steps_per_period
    xn, xv = _axis(x, "x")
    yn, yv = _axis(y, "y")
    if model.omega_index is None:
        raise ValueError(f"{model.name} is not periodically forced: a map samples once a period")
    if samples < 2:
        raise ValueError(f"samples must be >= 2 to classify periods (got {samples})")
    P = model.lane_params_grid(xn, xv, yn, yv)
    check_steps(model, P[:, model.omega_index], transient, samples, steps_per_period)
    Y0 = _per_lane(model, xn, xv, yn, yv, lambda m: m.initial_state())
    inputs = {"P": P, "y0": Y0}
    if has_mesh_forces(model) and model.static_mesh_forces() is not None:
        inputs["static"] = _per_lane(model, xn, xv, yn, yv, lambda m: m.static_mesh_forces())
    lyap = None
    if lyapunov:
        omega = P[:, model.omega_index]
        duration = float(samples * np.mean(forcing_period(omega)))
        # the map's own run (transient, step, locate_edges, bound); without a step, each
        # lane's own (lyapunov_lanes: the step rule on the lane's coefficients)
        lyap = dict(run=run, settings=LyapunovSettings(duration=duration))
    task = functools.partial(_map_task, run=run, lyapunov=lyap)
    size = int(chunk) if chunk else default_chunk(P.shape[0])
    meta = {"analysis": "map2d", "model": model.name, "x": xn, "y": yn}
    out = run_chunks(task, model, inputs, chunk=size, client=client, store=store,
                     progress=progress, meta=meta)

    ds = map_dataset(model, (yn, yv), (xn, xv), out, run.max_period, run.period_tol)
    ny, nx = yv.size, xv.size
    if lyap is not None:
        period = ds["period"].values.ravel()
        section = lane_section(model, P, P[:, model.omega_index], run.max_section_periods)[1]
        labels, motion_attrs = motion_variable(
            period, ds["lyapunov"].values.ravel(), ds["lyapunov_err"].values.ravel(),
            averaging_time(lyap["settings"].duration, P[:, model.omega_index]), section)
        ds["motion"] = ((yn, xn), labels.reshape(ny, nx), motion_attrs)
    ds.attrs.update(run.attrs())
    ds.attrs.update(
        model=model.name, x=xn, y=yn, lyapunov=int(bool(lyapunov)),
        time_unit=model.time_unit,
        chunk=size, start="each point from its own model's initial state",
    )
    if lyap is not None:
        ds.attrs.update(lyapunov_duration=lyap["settings"].duration,
                        lyapunov_steps_per_period=int(steps_per_period or 0))
    ds.attrs.update(model_attrs(model))
    finish(ds, "map2d")
    if store is not None:
        _save_store(ds, store)
    return ds


def _save_store(ds: xr.Dataset, store: Any) -> None:
    """Write the finished map at the root of its Zarr store (beside the lane store)."""
    from geardyn.execution.zarr_store import LaneStore, save_zarr_dataset

    save_zarr_dataset(ds, store.path if isinstance(store, LaneStore) else store)


# ---------------------------------------------------------------------------- cost estimate
@dataclass(frozen=True)
class MapEstimate:
    """What a map will cost (before it is built)."""

    lanes: int
    lane_steps: float  # RK4 steps over all lanes (Lyapunov steps weighted by LYAPUNOV_COST)
    memory_bytes: float  # peak memory of this process
    seconds: float  # wall time at ``ns_per_lane_step``, times ``busy_share``
    ns_per_lane_step: float
    busy_share: float = 1.0  # > 1: too few lanes to fill every thread's vectors (busy_lanes)

    def describe(self) -> str:
        idle = (f", x{self.busy_share:.3g} for vector slots left idle"
                if self.busy_share > 1.0 else "")
        return (f"{self.lanes} points, {self.lane_steps:.3g} lane-steps, about "
                f"{_bytes_text(self.memory_bytes)} of memory and {_time_text(self.seconds)} "
                f"(at {self.ns_per_lane_step:.3g} ns per lane-step{idle})")


def _bytes_text(n: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 2**10:.3g} KiB"


def _time_text(s: float) -> str:
    if s >= 86400:
        return f"{s / 86400:.3g} days"
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.3g} s"


#: More RK4 steps than this in one lane is refused as a mistake (years of computing).
MAX_STEPS_PER_LANE = 1e13


def _steps_per_lane(model: Model, omegas: np.ndarray, transient: float, samples: int,
                    steps_per_period: int | None) -> np.ndarray:
    """RK4 steps of one lane (transient plus samples) at each Omega, as floats (inf where the
    count overflows)."""
    om = np.asarray(omegas, dtype=float).ravel()
    out = np.empty(om.size)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        periods = periods_covering(np.full(om.size, float(transient)), forcing_period(om))
        for k, w in enumerate(om):
            n = float(steps_per_period) if steps_per_period else float(
                ladder_steps(default_steps_per_period(model, float(w))))
            out[k] = n * (periods[k] + samples)
    return out


def check_steps(model: Model, omegas: np.ndarray, transient: float, samples: int,
                steps_per_period: int | None) -> None:
    """Raise ValueError when a lane would need more than :data:`MAX_STEPS_PER_LANE` steps."""
    steps = _steps_per_lane(model, np.unique(omegas), transient, samples, steps_per_period)
    worst = float(np.max(steps)) if np.all(np.isfinite(steps)) else math.inf
    if worst > MAX_STEPS_PER_LANE:
        raise ValueError(f"Omega/transient: a point would need {worst:.3g} RK4 steps (more than "
                         f"{MAX_STEPS_PER_LANE:.0e}); check Omega, transient and samples")


def estimate_map(model: Model, lanes: int, omegas: Sequence[float] | np.ndarray,
                 transient: float, samples: int, steps_per_period: int | None = None,
                 lyapunov: bool = False, chunk: int | None = None,
                 ns_per_lane_step: float = 300.0, parallel: float = 1.0,
                 blocks: bool = True) -> MapEstimate:
    """Cost of a map of ``lanes`` points, from a few representative forcing frequencies
    ``omegas`` (the Omega axis subsampled, or the model's one Omega) — nothing of the size of the
    grid is allocated.

    Memory: the coefficient vectors, initial states and per-point results of all points (twice,
    for assembly), plus one chunk's Poincare samples (``chunk x samples x states x 8`` bytes,
    twice). Time: lane-steps x ``ns_per_lane_step`` (wall time per lane-step of this machine with
    every core busy, e.g. :func:`measure_ns_per_lane_step`) / ``parallel`` (how many such
    machines a cluster is worth). ``blocks``: the lanes run in the sweep kernels' blocks, where
    fewer lanes than fill every thread's vectors take as long as that many
    (:func:`~geardyn.solvers.ensemble.busy_lanes`: one lane on 2 threads costs 16 lanes' time);
    False: one lane on its own (a simulation).
    """
    om = np.asarray(omegas, dtype=float).ravel()
    check_omega(om)
    per_lane = float(np.mean(_steps_per_lane(model, om, transient, samples, steps_per_period)))
    steps = lanes * per_lane
    share = busy_lanes(lanes) / lanes if blocks and lanes > 0 else 1.0  # vectors left idle
    if lyapunov:
        n = int(steps_per_period or default_steps_per_period(model, float(om.min())))
        duration = samples * float(np.mean(forcing_period(om)))
        per = np.mean([n * (periods_covering(transient, forcing_period(float(w)))
                            + max(1, periods_covering(duration, forcing_period(float(w)))))
                       for w in om])
        steps += LYAPUNOV_COST * lanes * per
    ns, n_par = model.n_states, model.params.size
    n_mesh = len(model.meshes)
    per_point = 8.0 * (n_par + ns + n_mesh + 2 * (6 + 5 * n_mesh + 2 * int(lyapunov)))
    size = chunk or default_chunk(lanes)
    memory = lanes * per_point + 2 * 8.0 * min(size, lanes) * samples * ns
    return MapEstimate(lanes=int(lanes), lane_steps=float(steps), memory_bytes=float(memory),
                       seconds=float(steps * share * ns_per_lane_step * 1e-9
                                     / max(parallel, 1e-9)),
                       ns_per_lane_step=float(ns_per_lane_step), busy_share=float(share))


#: The environment variable that fixes the speed :func:`measure_ns_per_lane_step` returns (ns per
#: lane-step, > 0) instead of measuring it: run-time estimates and the refusals that rest on
#: them then do not depend on this machine's load (the tests set it).
SPEED_ENV = "GEARDYN_NS_PER_LANE_STEP"


def fixed_ns_per_lane_step() -> float | None:
    """The speed ``$GEARDYN_NS_PER_LANE_STEP`` fixes (ns per lane-step), or None where unset;
    ValueError naming the variable for a value that is not a positive finite number."""
    text = os.environ.get(SPEED_ENV, "").strip()
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{SPEED_ENV}={text!r}: must be a positive number of ns per lane-step")
    return value


def measure_ns_per_lane_step(model: Model, omega: float, steps_per_period: int | None = None,
                             steps: int = 20000) -> float:
    """Wall time per lane-step (ns) of :func:`run_lanes` on this machine with every core busy:
    a short run of the lanes that just fill every thread's vectors (:func:`busy_lanes` of one
    lane: 8 per thread), timed after a first call that compiles or loads the kernel. Where
    ``$GEARDYN_NS_PER_LANE_STEP`` is set (:data:`SPEED_ENV`), its value, and nothing runs."""
    fixed = fixed_ns_per_lane_step()
    if fixed is not None:
        return fixed
    lanes = busy_lanes(1)
    n = int(steps_per_period) if steps_per_period else ladder_steps(
        default_steps_per_period(model, omega))
    n = min(n, steps // 2)  # the cost of a step hardly depends on the steps per period
    periods = max(2, steps // n)
    P = model.lane_params("Omega", np.full(lanes, float(omega)))
    y0 = model.initial_state()
    run_lanes(model, P[:1], y0, run=RunSettings(transient=0.0, samples=2, steps_per_period=n))
    t0 = time.perf_counter()
    run_lanes(model, P, y0, run=RunSettings(transient=0.0, samples=periods, steps_per_period=n))
    return (time.perf_counter() - t0) * 1e9 / (lanes * periods * n)
