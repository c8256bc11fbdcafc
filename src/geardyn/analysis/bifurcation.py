"""Bifurcation sweeps: the steady motion of a model, point by point along one parameter."""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.continuation import SEGMENT, Branch, continue_branches
from geardyn.analysis.dataset import sweep_dataset
from geardyn.analysis.lanes import (
    has_mesh_forces,
)
from geardyn.analysis.lyapunov import (
    lyapunov_err_attrs,
    lyapunov_tangent,
    lyapunov_unresolved_attrs,
    lyapunov_variational,
)
from geardyn.analysis.motion import averaging_time, motion_variable
from geardyn.core.model import Model
from geardyn.core.plan import forcing_period
from geardyn.core.settings import (
    SWEEP_DIRECTIONS,
    LyapunovSettings,
    RunSettings,
    check_continuation,
    resolve_run,
)
from geardyn.core.status import Status
from geardyn.errors import ParameterError
from geardyn.execution.executor import lane_results, run_chunks, run_lanes_task
from geardyn.solvers.ensemble import LaneResults
from geardyn.solvers.kernels import kernels_for

#: Old keyword names of run settings and the RunSettings field each maps onto.
ALIASES = {"tol": "period_tol"}

#: Time (model units) the tangent vectors run before the exponent is measured, when it starts from
#: a point's final (already settled) state.
LYAPUNOV_ALIGN = 200.0


def _independent(model, P, Y0, chunk, progress, client, store, **opts) -> LaneResults:
    """run_lanes over chunks of lanes through the executor (here or on a Dask cluster, resumable
    with a store), reporting progress after each chunk."""
    out = run_chunks(functools.partial(run_lanes_task, **opts), model,
                     {"P": P, "y0": Y0}, chunk=chunk, client=client, store=store,
                     progress=progress, meta={"analysis": "bifurcation"})
    return lane_results(out)


def bifurcation(
    model: Model,
    param: str = "Omega",
    values: Sequence[float] | np.ndarray = (),
    run: RunSettings | None = None,
    *,
    continuation: str | None = None,
    lyapunov: bool = False,
    starts: int = 1,
    y0: np.ndarray | None = None,
    seed: int = 0,
    spread: float = 1.0,
    progress: Callable[[int, int], None] | None = None,
    chunk: int | None = None,
    client: Any = None,
    store: str | os.PathLike[str] | None = None,
    hold: str = "Omega",
    **settings: Any,
) -> xr.Dataset:
    """Sweep ``param`` over ``values`` and classify the steady motion at every point.

    Parameters
    ----------
    param
        ``"Omega"`` (the forcing frequency) or any parameter name the model accepts in
        ``lane_params`` (for :class:`~geardyn.CATTDevice`: ``xi1``, ``xi``, ``backlash``,
        ``error``, ``B1``, ``T_D``, ...).
    run
        The run settings, :class:`~geardyn.RunSettings` (default ``RunSettings()``). The old
        keyword arguments ``transient``, ``samples``, ``steps_per_period``, ``converge``,
        ``transient_max``, ``continued_transient``, ``max_period``, ``tol`` (the field
        ``period_tol``), ``locate_edges``, ``bound`` and ``max_section_periods`` still build it
        (not together with ``run``) but are deprecated: one DeprecationWarning naming the
        equivalent ``run=geardyn.RunSettings(...)``. The settings:
    transient
        Time discarded at every point, in model time units (tau), rounded up to whole periods
        (whole common periods when a second excitation is commensurate with Omega).
    converge, transient_max
        Transient by convergence: with a tolerance ``converge`` (e.g. 1e-8), ``transient`` is a
        minimum and each point runs on, up to ``transient_max`` (default 10 x transient), until
        its Poincare point is estimated within ``converge (1 + |point|)`` of a periodic orbit of
        period <= 16 (from the contraction of successive differences; docs/numerics.md); the
        variable ``converged`` says where that happened and ``transient_periods`` what it took.
    samples
        Poincare points recorded after the transient: one per forcing period, or per common
        period of the excitations when the model has a second one at a commensurate frequency
        (``section_periods``; see :func:`geardyn.core.section.common_section`).
    continuation
        ``None`` or ``"none"``: every point starts from ``y0``; ``"up"``/``"down"``: each point
        starts from the final state of the previous one in ascending/descending order (shows
        hysteresis; see :mod:`geardyn.analysis.continuation`); one of
        :data:`~geardyn.core.settings.SWEEP_CONTINUATIONS`.
    continued_transient
        With continuation: the (minimum) transient of a continued point, which starts next to
        its attractor (default ``transient``; the first point always gets ``transient``).
        A continued point whose second excitation is incommensurate with Omega cannot be tested
        for convergence and runs exactly this long.
    starts
        Independent starts per point (``continuation=None`` only): the first from ``y0``, the
        others from ``y0`` plus uniform noise of half-width ``spread`` on each state (``seed``).
        Their Poincare points are stacked along ``sample``; ``period_by_start`` keeps each.
    progress
        Called as ``progress(done, total)`` (integrations finished, of all) after each chunk.
    chunk
        Lanes per kernel call. Default: the whole sweep in one call where there is no
        ``progress``, ``client`` or ``store`` (chunks serve those; without them each chunk's
        tail, where one core waits for the other's last lanes, is only lost time), else about a
        twentieth of the sweep, at least 64. Lanes are independent, so the result does not
        depend on it.
    client, store
        Independent starts only: a ``dask.distributed.Client`` runs the chunks on its cluster,
        and a Zarr ``store`` path keeps finished chunks so that a rerun resumes (see
        :func:`geardyn.execution.executor.run_chunks` and ``docs/scaling.md``). Either way the
        result is bitwise that of a local run.
    hold
        What stays fixed along a sweep of another parameter: ``"Omega"`` (default) the
        dimensionless frequency, or ``"speed"`` the physical mesh frequency omega = Omega omega_n
        of ``model`` (and the load fluctuation's likewise): each point then runs at
        Omega = omega / omega_n(point) (Lambda likewise), for a parameter that moves omega_n
        (``Km_sq``, the carrier's mass). Needs a model with a physical ``omega_n``; the dataset
        records ``hold`` and the per-point ``Omega`` (and ``Lambda``) as coordinates.

    Returns
    -------
    xarray.Dataset with coordinates ``param``, ``sample``, ``state``, ``mesh`` and variables
    ``poincare`` (param, sample, state), ``period`` (param; k >= 1 period-k, 0 no period <=
    max_period found, -1 unbounded), ``contact`` (param, mesh: none/single/double/unbounded),
    ``force_peak``, ``force_rms``, ``dynamic_factor`` (param, mesh), ``status``,
    ``final_time`` (param: the model time of the final state, the last Poincare point), and
    ``lyapunov`` with its standard error ``lyapunov_err`` and ``lyapunov_unresolved`` (param:
    its steps at the edge-split limit) when asked: with the run's step, ``locate_edges`` and
    ``bound``, started from each point's final state at its final time (after at most
    :data:`LYAPUNOV_ALIGN` time units aligning the tangent vector), so both forcing phases
    continue (see
    ``docs/lyapunov.md``), and then ``motion`` (param: the motion class of
    :func:`geardyn.analysis.motion.motion_classes`).
    """
    run = resolve_run(run, settings, aliases=ALIASES, where="bifurcation")
    if continuation is not None and check_continuation(continuation) == "none":
        continuation = None
    values = _check_values(values)
    if starts < 1 or (starts > 1 and continuation):
        raise ValueError("starts must be >= 1, and 1 with continuation")
    if continuation and (client is not None or store is not None):
        raise ValueError("client and store apply to independent starts, not to continuation")
    P = lane_params_held(model, param, values, hold)
    base_y0 = _initial_states(model, param, values, y0, P)
    if continuation:
        sweep = ContinuedSweep(model, param, values, continuation, y0=base_y0, hold=hold,
                               run=run)
        ((ds, last),) = _continued([sweep], run, progress)
    else:
        L, ns = values.size, model.n_states
        rng = np.random.default_rng(seed)
        Y0 = [np.broadcast_to(base_y0, (L, ns))]
        Y0 += [base_y0 + rng.uniform(-spread, spread, (L, ns)) for _ in range(1, starts)]
        every = _independent(model, np.tile(P, (starts, 1)), np.concatenate(Y0), chunk,
                             progress, client, store, run=run)
        runs = [every.take(slice(s * L, (s + 1) * L)) for s in range(starts)]
        last = runs[0]
        ds = _dataset(model, param, values, runs, run.max_period, run.period_tol, P)
        ds.attrs.update(run.attrs(), continuation="none", starts=int(starts))
        ds = _record_hold(ds, model, param, P, hold)
    if lyapunov:
        from geardyn.analysis.lyapunov import lyapunov_lanes

        # from each point's own final state at its final time (on the attractor the Poincare
        # points show, also in continuation, both forcing phases continued), with each lane's
        # own step; a short run aligns the tangent vectors
        final = last.final
        start = np.where(np.isfinite(final), final, np.broadcast_to(base_y0, final.shape))
        asked = run.samples * _mean_period(model, P)  # averaging time asked for
        # the sweep's own run (step, locate_edges, bound), with the short aligning transient
        align = run.replace(transient=min(run.transient, LYAPUNOV_ALIGN))
        exps, errs, unres, _ = lyapunov_lanes(model, P, start, align,
                                              settings=LyapunovSettings(duration=asked),
                                              t0=last.final_time, with_status=True)
        ok = ds["status"].values == Status.OK
        method = ("tangent-map QR (Benettin), from the point's final state at its final time, "
                  f"{LYAPUNOV_ALIGN:g} time units to align, then as long as the sampling")
        ds["lyapunov"] = (param, np.where(ok, exps, np.nan), {
            "long_name": "largest Lyapunov exponent", "units": f"1/{model.time_unit}",
            "method": method,
            "tangent": lyapunov_tangent(lyapunov_variational(model, LyapunovSettings()))})
        ds["lyapunov_err"] = (param, np.where(ok & np.isfinite(exps), errs, np.nan),
                              lyapunov_err_attrs(model.time_unit))
        ds["lyapunov_unresolved"] = (param, unres, lyapunov_unresolved_attrs())
        ds["motion"] = (param, *motion_variable(ds["period"].values, ds["lyapunov"].values,
                                                ds["lyapunov_err"].values,
                                                averaging_time(asked, P[:, model.omega_index]),
                                                last.commensurate))
    return ds


@dataclass(frozen=True)
class ContinuedSweep:
    """One sweep by continuation for :func:`continued_sweeps`: ``model`` swept in ``param``
    over ``values`` in the ``direction`` "up" (ascending) or "down" (``y0``: the cold start's
    state, default the model's initial state).

    ``run``: the sweep's own :class:`~geardyn.RunSettings`, whose transients (``transient``,
    ``continued_transient``, ``transient_max``) and ``steps_per_period`` the sweep uses, as
    :func:`bifurcation` does; or those four as keyword arguments (not both; deprecated, one
    DeprecationWarning naming the equivalent ``run=``). The other fields of a ``run`` are
    those of the run given to :func:`continued_sweeps`: one left at its default takes that
    run's value, one set otherwise must equal it (else TypeError naming both). None (and no
    keywords): the sweep takes its transients and step from the run given to
    :func:`continued_sweeps`.
    After construction ``run`` holds the validated settings and the four fields their values,
    or all five are None (the shared run applies)."""

    model: Model
    param: str
    values: np.ndarray
    direction: str = "up"
    transient: float | None = None
    continued_transient: float | None = None
    transient_max: float | None = None
    steps_per_period: int | None = None
    y0: np.ndarray | None = None
    hold: str = "Omega"
    run: RunSettings | None = None

    def __post_init__(self) -> None:
        legacy = {k: getattr(self, k) for k in _SWEEP_FIELDS if getattr(self, k) is not None}
        if self.run is None and not legacy:
            return  # the run given to continued_sweeps applies
        # stacklevel: the caller of the dataclass's __init__
        run = resolve_run(self.run, legacy, where="ContinuedSweep", stacklevel=4)
        object.__setattr__(self, "run", run)
        for k in _SWEEP_FIELDS:
            object.__setattr__(self, k, getattr(run, k))


#: The settings each continued sweep has of its own (the others are shared by the sweeps).
_SWEEP_FIELDS = ("transient", "continued_transient", "transient_max", "steps_per_period")


def continued_sweeps(
    sweeps: Sequence[ContinuedSweep],
    run: RunSettings | None = None,
    *,
    progress: Callable[[int, int], None] | None = None,
    segment: int = SEGMENT,
    **settings: Any,
) -> list[xr.Dataset]:
    """Several sweeps by continuation at once (up and down, several studies): the datasets of
    :func:`bifurcation` with ``continuation=direction``, each bitwise what it gets alone, but
    their points advance together as lanes of one kernel call (see
    :mod:`geardyn.analysis.continuation`). Sweeps whose models compile to different kernels
    run one group after another. ``run``: the :class:`~geardyn.RunSettings` shared by the
    sweeps (samples, converge, max_period, period_tol, locate_edges, bound,
    max_section_periods, and the transients and step of every sweep made without a run of
    its own), or the old keyword arguments of those (``tol`` for period_tol; deprecated, one
    DeprecationWarning naming the equivalent ``run=``). A sweep made with its own run takes
    its transients (``transient``, ``continued_transient``, ``transient_max``) and
    ``steps_per_period`` from it; any other field of it set to other than its default and
    ``run``'s value is a TypeError naming both values. Each dataset records the settings it
    ran with in its attributes. ``segment``: points of each sweep per kernel call (see
    :func:`~geardyn.analysis.continuation.continue_branches`; ``progress`` is called once per
    call): a longer segment leaves fewer slots idle at the calls' ends; the results are bitwise
    the same whatever it is."""
    run = resolve_run(run, settings, aliases=ALIASES, where="continued_sweeps")
    return [ds for ds, _ in _continued(sweeps, run, progress, segment)]


def shared_settings(run: RunSettings) -> tuple[tuple[str, Any], ...]:
    """The fields of ``run`` that the sweeps of one :func:`continued_sweeps` call share (all
    but each sweep's transients and step), as (name, value) pairs."""
    return tuple((f.name, getattr(run, f.name)) for f in fields(RunSettings)
                 if f.name not in _SWEEP_FIELDS)


def _sweep_run(sw: ContinuedSweep, run: RunSettings) -> RunSettings:
    """The shared ``run`` with the transients and step of the sweep ``sw`` where it has a run
    of its own. Raises TypeError naming both values where the sweep's run sets a shared field
    (one the sweep cannot set) to other than its default and ``run``'s value."""
    if sw.run is None:
        return run
    default = dict(shared_settings(RunSettings()))
    clash = [f"{name}={own!r} (the sweep's run) and {name}={shared!r} (continued_sweeps' run)"
             for (name, own), (_, shared) in zip(shared_settings(sw.run), shared_settings(run),
                                                 strict=True)
             if own != default[name] and own != shared]
    if clash:
        raise TypeError("a ContinuedSweep's run sets its transients and step; its other "
                        "settings are continued_sweeps' run's, so not both: got "
                        + "; ".join(clash))
    return run.replace(**{k: getattr(sw.run, k) for k in _SWEEP_FIELDS})


def _continued(sweeps: Sequence[ContinuedSweep], run: RunSettings,
               progress: Callable[[int, int], None] | None, segment: int = SEGMENT
               ) -> list[tuple[xr.Dataset, LaneResults]]:
    """continued_sweeps, with each sweep's lane results (in value order: final states and
    times)."""
    prepared = []
    for sw in sweeps:
        if sw.direction not in SWEEP_DIRECTIONS:
            raise ParameterError("direction", sw.direction,
                                 "must be one of " + ", ".join(SWEEP_DIRECTIONS))
        values = _check_values(sw.values)
        order = np.argsort(values, kind="stable")
        if sw.direction == "down":
            order = order[::-1]
        P = lane_params_held(sw.model, sw.param, values, sw.hold)
        start = _initial_states(sw.model, sw.param, values, sw.y0, P)
        start = start if start.ndim == 1 else start[order[0]]
        sr = _sweep_run(sw, run)
        branch = Branch(sw.model, P[order], start, sr.transient, sr.continued_transient,
                        sr.transient_max, sr.steps_per_period, run.max_section_periods)
        prepared.append((sw, values, order, branch))
    groups: dict[int, list[int]] = {}
    for i, (sw, *_rest) in enumerate(prepared):
        groups.setdefault(id(kernels_for(sw.model.kernel)), []).append(i)
    total = sum(p[3].P.shape[0] for p in prepared)
    results: dict[int, LaneResults] = {}
    done = 0
    for members in groups.values():
        offset = done

        def tick(d: int, _t: int, offset: int = offset) -> None:
            if progress is not None:
                progress(offset + d, total)

        runs = continue_branches([prepared[i][3] for i in members], run, tick,
                                 segment=segment)
        for i, r in zip(members, runs, strict=True):
            results[i] = r
            done += r.status.size
    out = []
    for i, (sw, values, order, branch) in enumerate(prepared):
        r = results[i]
        back = np.empty_like(order)
        back[order] = np.arange(order.size)
        r = r.take(back)
        ds = _dataset(sw.model, sw.param, values, [r], run.max_period, run.period_tol,
                      branch.P[back])
        sr = _sweep_run(sw, run)
        ds.attrs.update(sr.attrs(), continuation=sw.direction, starts=1)
        if sr.continued_transient is not None:
            ds.attrs["continued_transient"] = sr.continued_transient
        ds = _record_hold(ds, sw.model, sw.param, branch.P[back], sw.hold)
        out.append((ds, r))
    return out


#: What a sweep of a parameter other than Omega holds fixed (see :func:`bifurcation`).
HOLDS = ("Omega", "speed")


def lane_params_held(model: Model, param: str, values: np.ndarray | Sequence[float],
                     hold: str = "Omega") -> np.ndarray:
    """Coefficient vectors of a sweep of ``param`` over ``values``: ``model.lane_params`` with
    ``hold="Omega"``; with ``hold="speed"`` each point's model, with Omega (and Lambda, where
    the model has one) rescaled by omega_n(model) / omega_n(point), so that the physical mesh
    (and load) frequency is that of ``model``. Raises ValueError for an unknown mode, for
    ``param`` Omega or Lambda, or for a model without a physical ``omega_n``."""
    if hold not in HOLDS:
        raise ValueError(f"hold must be one of {', '.join(HOLDS)} (got {hold!r})")
    if hold == "Omega":
        return model.lane_params(param, values)
    if param in ("Omega", "Lambda"):
        raise ValueError(f"hold='speed' sweeps another parameter at a fixed physical speed; "
                         f"param {param!r} is a speed itself")
    if not model.capabilities.frequency_scale:
        raise ValueError(f"hold='speed' needs a model whose time unit is a physical frequency "
                         f"omega_n; {model.name} has none")
    base = float(model.omega_n)
    lam = _lambda(model)
    rows = []
    for v in np.asarray(values, dtype=float).ravel():
        lane = model.with_params(**{param: float(v)})
        ratio = base / float(lane.omega_n)
        changes = {"Omega": model.omega * ratio}
        if lam:
            changes["Lambda"] = lam * ratio
        rows.append(lane.with_params(**changes).params)
    return np.array(rows)


def _lambda(model: Model) -> float:
    """The model's Lambda parameter (0 when it has none)."""
    if "Lambda" not in model.param_names:
        return 0.0
    return float(model.params[model.param_index("Lambda")])


def _record_hold(ds: xr.Dataset, model: Model, param: str, P: np.ndarray,
                 hold: str) -> xr.Dataset:
    """Record the hold mode and, at a fixed speed, each point's Omega (and Lambda)."""
    ds.attrs["hold"] = hold
    if hold != "speed":
        return ds
    wn = float(model.omega_n)  # type: ignore[attr-defined]
    ds.attrs["omega_phys"] = model.omega * wn
    ds.attrs["omega_phys_units"] = "rad/s"
    coords = {"Omega": (param, P[:, model.omega_index], {
        "long_name": "dimensionless mesh frequency of each point (fixed physical speed)"})}
    if _lambda(model):
        k = model.param_index("Lambda")
        coords["Lambda"] = (param, P[:, k], {
            "long_name": "dimensionless load frequency of each point (fixed physical speed)"})
    return ds.assign_coords(coords)


def _check_values(values: Sequence[float] | np.ndarray) -> np.ndarray:
    values = np.asarray(values, dtype=float).ravel()
    if values.size == 0:
        raise ValueError("values: give at least one parameter value")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"values: must be finite (got {values[~np.isfinite(values)][0]!r})")
    return values


def _omega_alone(model: Model, param: str, P: np.ndarray | None) -> bool:
    """Whether the sweep's lanes ``P`` differ from the model's own coefficients in Omega alone
    (``param`` Omega, or a speed that sets it, e.g. a gear train's ``input_speed``): then every
    point's initial state and static forces are the model's own."""
    if param == "Omega":
        return True
    i = model.omega_index
    if P is None or i is None:
        return False
    rest = np.delete(np.atleast_2d(P), i, axis=1)
    own = np.delete(np.asarray(model.params, dtype=float), i)
    return rest.shape[1] == own.size and bool(np.array_equal(
        rest, np.broadcast_to(own, rest.shape), equal_nan=True))


def _initial_states(model: Model, param: str, values: np.ndarray, y0: np.ndarray | None,
                    P: np.ndarray | None = None) -> np.ndarray:
    """``y0``, or the model's initial state (one per value when ``param`` changes more than
    Omega in the lanes ``P``)."""
    if y0 is not None:
        return np.asarray(y0, dtype=float)
    if _omega_alone(model, param, P):
        return model.initial_state()
    return np.array([model.with_params(**{param: float(v)}).initial_state() for v in values])


def _dataset(model: Model, param: str, values: np.ndarray, runs: list[LaneResults],
             max_period: int, tol: float, P: np.ndarray | None = None) -> xr.Dataset:
    """The sweep dataset of one or more starts' lane results (without the settings; ``P``:
    the lanes' coefficients)."""
    static = _static_forces(model, param, values, P) if has_mesh_forces(model) else None
    return sweep_dataset(model, param, values, runs, max_period, tol, static)


def _mean_period(model: Model, P: np.ndarray) -> float:
    return float(np.mean(forcing_period(P[:, model.omega_index])))


def _static_forces(model: Model, param: str, values: np.ndarray,
                   P: np.ndarray | None = None) -> np.ndarray | None:
    base = model.static_mesh_forces()
    if base is None:
        return None
    if _omega_alone(model, param, P):
        return np.broadcast_to(base, (values.size, base.size))
    rows = [model.with_params(**{param: float(v)}).static_mesh_forces() for v in values]
    return np.array(rows)
