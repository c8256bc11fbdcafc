"""Many independent integrations at once: one lane per parameter set, compiled and parallel.

:func:`run_lanes` is the engine under every sweep. Each lane integrates the model with its own
coefficient vector for a transient (a time, rounded up to whole forcing periods of that lane),
then records stroboscopic samples and statistics. All lanes run in one parallel kernel call: each
worker advances its queue of lanes (whatever their steps per period) through a block of
refilling slots (see ``_kernel_template``). Results do not depend on the schedule, the block
width or the thread count.
The settings come as one :class:`~geardyn.core.settings.RunSettings` and what each lane has of
its own as one :class:`~geardyn.core.plan.LaneSettings`; every step count is derived once by
:class:`~geardyn.core.plan.LanePlan` (:func:`run_plan` runs a given plan).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn.core.kernel_args import LaneInputs, LaneOutputs, Schedule, SweepConfig
from geardyn.core.model import Model
from geardyn.core.moved import moved
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.settings import RunSettings, replacement, warn_deprecated
from geardyn.core.status import Status
from geardyn.solvers._step_shared import phase_table_values
from geardyn.solvers.kernels import kernels_for

#: Names whose home is now the core layer (deprecated here).
__getattr__ = moved(__name__, dict.fromkeys(("_LADDER", "ladder_steps", "lane_steps_per_period"),
                                            "geardyn.core.plan"))


@dataclass
class LaneResults:
    """Raw per-lane results of :func:`run_lanes` (arrays indexed by lane)."""

    samples: np.ndarray  # (L, n_samples, n_states); NaN for diverged lanes
    final: np.ndarray  # (L, n_states) state at the end
    final_time: np.ndarray  # (L,) model time at the end
    status: np.ndarray  # (L,) geardyn.core.status.Status codes
    event_min: np.ndarray  # (L, n_events) over the sampled stretch
    event_max: np.ndarray
    crossings: np.ndarray  # (L, n_events) located edge crossings while sampling
    obs_max: np.ndarray  # (L, n_obs)
    obs_min: np.ndarray
    obs_rms: np.ndarray
    unresolved: np.ndarray  # (L,) steps that reached the split limit
    steps_per_period: np.ndarray  # (L,)
    transient_periods: np.ndarray  # (L,) transient used, in forcing periods
    converged: np.ndarray  # (L,) transient by convergence: 1 settled, 0 hit the limit, -1 off
    sample_every: np.ndarray  # (L,) forcing periods between samples (the section's period)
    commensurate: np.ndarray  # (L,) False: a second excitation at an irrational frequency ratio
    steps: np.ndarray  # (L,) grid steps integrated (transient + sampled; fewer where diverged)

    def take(self, index: slice | np.ndarray) -> LaneResults:
        """The lanes ``index`` (a slice or an index array) of every field."""
        return LaneResults(**{f: getattr(self, f)[index] for f in self.__dataclass_fields__})

    @staticmethod
    def concat(parts: list[LaneResults]) -> LaneResults:
        """Lane results one after another."""
        return LaneResults(**{f: np.concatenate([getattr(r, f) for r in parts])
                              for f in LaneResults.__dataclass_fields__})


def run_lanes(
    model: Model,
    P: np.ndarray,
    y0: np.ndarray,
    *legacy_args: Any,
    run: RunSettings | None = None,
    lanes: LaneSettings | None = None,
    chain: np.ndarray | None = None,
    converge_depth: int | None = None,
    **legacy: Any,
) -> LaneResults:
    """Integrate one lane per row of ``P`` (coefficient vectors) from ``y0`` (one state, or one
    per lane) and return stroboscopic samples and statistics over the sampled stretch, under
    the settings ``run`` (:class:`~geardyn.core.settings.RunSettings`, default its defaults)
    and the per-lane values ``lanes`` (:class:`~geardyn.core.plan.LaneSettings`: start times
    ``t0`` (whole periods), per-lane ``transient``, ``transient_max`` and ``steps_per_period``
    in place of the run's, ``sample_every``). By default a lane is sampled at the common period
    of the forcings when the model has a second, commensurate excitation
    (:func:`~geardyn.core.section.common_section`, up to ``run.max_section_periods``), else
    every period. The transient is rounded up to whole sampling intervals. Everything is
    planned once by :class:`~geardyn.core.plan.LanePlan`.

    The settings as separate arguments after ``y0`` (``transient, samples, steps_per_period,
    sample_every, locate_edges, bound, t0, transient_max, converge_tol, converge_depth,
    max_section_periods``, positional or keyword; ``converge_tol``: ``converge``, 0 off) are
    deprecated: one DeprecationWarning per process naming the equivalent ``run=`` and
    ``lanes=``; the result is the same, bit for bit.

    Transient by convergence: with a tolerance ``run.converge`` the transient (then a minimum)
    goes on, one sampling interval at a time up to ``transient_max`` (default 10 x
    transient), until the section point is estimated within ``converge (1 + |point|)`` of a
    periodic orbit of period <= ``converge_depth`` sections (default 16; from the contraction
    of successive differences, docs/numerics.md); ``converged`` tells per lane whether it was.

    ``chain`` (one int per lane, -1: none) makes sweeps by continuation: lane ``chain[l]``
    starts where lane l ended (its final state, at its end time; its own ``y0`` row and
    ``t0`` are ignored), in the same slot, if lane l ended well (status ok); after a lane that
    did not, the rest of its chain is not run (status ``Status.NOT_RUN``, ``steps`` 0, the
    other results as allocated; the caller restarts them). ``steps`` counts the grid steps
    each lane was integrated: its transient plus its sampled stretch (fewer if it diverged)."""
    if legacy_args or legacy:
        run, lanes, converge_depth = _legacy_settings(legacy_args, legacy, run, lanes,
                                                      converge_depth)
    run = RunSettings() if run is None else run
    if not isinstance(run, RunSettings):
        raise TypeError(f"run must be a RunSettings (got {type(run).__name__})")
    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    plan = LanePlan.build(model, P, run, lanes)
    return run_plan(model, P, y0, plan, 16 if converge_depth is None else converge_depth,
                    chain=chain)


#: The settings of :func:`run_lanes` as separate arguments (deprecated), in their old order.
LEGACY_ORDER = ("transient", "samples", "steps_per_period", "sample_every", "locate_edges",
                "bound", "t0", "transient_max", "converge_tol", "converge_depth",
                "max_section_periods")
#: Of those, the ones that are always run settings (the rest are per lane where arrays).
_RUN_ONLY = ("samples", "locate_edges", "bound", "max_section_periods")


def _legacy_settings(args: tuple[Any, ...], keywords: dict[str, Any],
                     run: RunSettings | None, lanes: LaneSettings | None,
                     converge_depth: int | None
                     ) -> tuple[RunSettings | None, LaneSettings | None, int | None]:
    """``run``, ``lanes`` and ``converge_depth`` of a :func:`run_lanes` call that gives its
    settings as separate arguments (``args`` after ``y0``, ``keywords``), with one
    DeprecationWarning per process naming the replacement. Run fields beside ``run=``, lane
    fields beside ``lanes=``, and unknown or twice-given names are TypeErrors."""
    if any(isinstance(a, (RunSettings, LaneSettings)) for a in args):
        raise TypeError("run_lanes takes its settings as keywords: run_lanes(model, P, y0, "
                        "run=RunSettings(...), lanes=LaneSettings(...))")
    if len(args) > len(LEGACY_ORDER):
        raise TypeError(f"run_lanes() takes at most {3 + len(LEGACY_ORDER)} positional "
                        f"arguments ({3 + len(args)} given)")
    given = dict(zip(LEGACY_ORDER, args, strict=False))
    for name, value in keywords.items():
        if name not in LEGACY_ORDER:
            raise TypeError(f"run_lanes() got an unexpected keyword argument {name!r}")
        if name in given:
            raise TypeError(f"run_lanes() got multiple values for argument {name!r}")
        given[name] = value
    given = {k: v for k, v in given.items()
             if v is not None and not (k == "sample_every" and isinstance(v, str)
                                       and v == "auto")}
    if not given:
        return run, lanes, converge_depth
    run_fields: dict[str, Any] = {}
    lane_fields: dict[str, Any] = {}
    for name, value in given.items():
        if name == "converge_depth":
            if converge_depth is not None:
                raise TypeError("run_lanes() got multiple values for argument 'converge_depth'")
            converge_depth = value
        elif name == "converge_tol":
            if value < 0:
                raise ValueError(f"converge_tol must be >= 0 (got {value!r})")
            run_fields["converge"] = float(value) if value > 0 else None
        elif name in ("t0", "sample_every") or (name not in _RUN_ONLY and np.ndim(value)):
            lane_fields[name] = value
        elif name == "steps_per_period" and int(value) <= 0:
            continue  # <= 0: the step rule, the run's default
        else:
            run_fields[name] = value
    if run_fields and run is not None:
        raise TypeError(f"run_lanes: give the settings as run= or as keywords, not both "
                        f"(got run= and {next(iter(run_fields))}=)")
    if lane_fields and lanes is not None:
        raise TypeError(f"run_lanes: give lanes=LaneSettings(...) or keyword arguments, not "
                        f"both (got lanes= and {next(iter(lane_fields))}=)")
    replacements = []
    if run_fields:
        run = RunSettings(**run_fields)
        replacements.append(replacement("run", RunSettings, run_fields))
    if lane_fields:
        lanes = LaneSettings(**lane_fields)
        replacements.append(replacement("lanes", LaneSettings, lanes.fields(),
                                        home="geardyn.core"))
    if "converge_depth" in given:
        replacements.append(f"converge_depth={converge_depth!r}")
    warn_deprecated("run_lanes", given, replacements, stacklevel=3)
    return run, lanes, converge_depth


def run_plan(model: Model, P: np.ndarray, y0: np.ndarray, plan: LanePlan,
             converge_depth: int = 16, *, width: int | None = None,
             workers: int | None = None, chain: np.ndarray | None = None) -> LaneResults:
    """Run the lanes ``P`` from ``y0`` as ``plan`` says (see :func:`run_lanes`). ``width``:
    slots per worker's block (default the kernel's ``BLOCK``), ``workers``: parallel workers
    (default numba's thread count); neither changes a lane's result, bit for bit."""
    if converge_depth < 1:
        raise ValueError(f"converge_depth must be >= 1 (got {converge_depth!r})")
    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    L = P.shape[0]
    ns = model.n_states
    # always a fresh writable array: a read-only view (one lane broadcast) would compile the
    # sweep kernel a second time, for the read-only type
    Y0 = np.array(np.broadcast_to(np.asarray(y0, dtype=float), (L, ns)), order="C")
    run = plan.settings
    samples = run.samples
    n_lane = np.ascontiguousarray(plan.steps_per_period, dtype=np.int64)
    n_ev, n_obs = model.n_events, model.n_observables
    k = kernels_for(model.kernel)
    out = LaneResults(
        samples=np.full((L, samples, ns), np.nan),
        final=np.full((L, ns), np.nan),
        final_time=np.zeros(L),
        status=np.full(L, int(Status.NOT_RUN), np.int64),  # each lane sets its own when it runs
        event_min=np.zeros((L, n_ev)),
        event_max=np.zeros((L, n_ev)),
        crossings=np.zeros((L, n_ev), np.int64),
        obs_max=np.zeros((L, n_obs)),
        obs_min=np.zeros((L, n_obs)),
        obs_rms=np.zeros((L, n_obs)),
        unresolved=np.zeros(L, np.int64),
        steps_per_period=plan.steps_per_period,
        transient_periods=plan.transient_periods.copy(),
        converged=np.full(L, -1, np.int64),
        sample_every=plan.sample_every.copy(),
        commensurate=plan.commensurate.copy(),
        steps=np.zeros(L, np.int64),
    )
    tr_steps = np.zeros(L, np.int64)
    s_tab, c_tab, lane_tab = _phase_tables(n_lane)
    cost = plan.total_periods * n_lane
    if chain is None:
        chain = np.empty(0, np.int64)
        start, queue = _schedule(cost, workers)
    else:
        chain = _check_chain(chain, L)
        heads, chain_cost = _chain_heads(chain, cost)
        start, queue = _schedule(chain_cost, workers)
        queue = heads[queue]

    def lane_array(x, dtype):
        return np.ascontiguousarray(x, dtype=dtype)

    T0 = np.array(plan.t0, dtype=float)  # a copy: chained lanes' start times are set in it
    lanes = LaneInputs(P, Y0, lane_array(plan.step, float), lane_array(plan.omega, float),
                       T0, lane_array(plan.transient_steps, np.int64),
                       lane_array(plan.transient_max_steps, np.int64),
                       lane_array(plan.sample_steps, np.int64))
    cfg = SweepConfig(float(run.converge_tol), int(converge_depth), int(samples),
                      bool(run.locate_edges), float(run.bound), int(n_ev), int(n_obs),
                      int(width or block_width(np.diff(start), k.BLOCK)))
    if cfg.width < 1:
        raise ValueError(f"width must be >= 1 (got {width!r})")
    sched = Schedule(start, queue, n_lane, lane_tab, s_tab, c_tab, chain)
    res = LaneOutputs(out.samples, out.final, out.status, out.event_min, out.event_max,
                      out.crossings, out.obs_max, out.obs_min, out.obs_rms, out.unresolved,
                      tr_steps, out.converged, out.steps)
    k.sweep(lanes, cfg, sched, res)
    out.transient_periods = tr_steps // n_lane
    out.final_time = plan.final_time(out.transient_periods, T0)
    return out


def block_width(queued: np.ndarray, block: int) -> int:
    """Slots of a worker's block: at most ``block``, and as few as fill the rounds that the
    most lanes (or chains) ``queued`` on one worker take evenly (e.g. 100 lanes in blocks of
    64: two rounds of 50, not 64 then 36 with 28 slots stepped idle to the end)."""
    most = int(np.max(queued, initial=1))
    rounds = -(-most // block)
    return max(1, -(-most // max(rounds, 1)))


def _check_chain(chain: np.ndarray, lanes: int) -> np.ndarray:
    """``chain`` as the kernel takes it (int64, one entry per lane), checked: each entry -1 or
    another lane, no lane the successor of two, no cycle."""
    c = np.ascontiguousarray(chain, dtype=np.int64)
    if c.shape != (lanes,):
        raise ValueError(f"chain must have one entry per lane ({lanes}), got shape {c.shape}")
    linked = c[c >= 0]
    if np.any(c < -1) or np.any(linked >= lanes) or np.any(linked == np.flatnonzero(c >= 0)):
        raise ValueError("chain entries must be -1 or the index of another lane")
    if np.unique(linked).size != linked.size:
        raise ValueError("chain: a lane follows two lanes")
    heads = np.setdiff1d(np.arange(lanes), linked)
    seen = 0
    for h in heads:
        lane = h
        while lane >= 0:
            seen += 1
            lane = c[lane]
    if seen != lanes:
        raise ValueError("chain: a cycle (some lanes follow no first lane)")
    return c


def _chain_heads(chain: np.ndarray, cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first lane of every chain and the chain's total cost (lane-steps)."""
    heads = np.setdiff1d(np.arange(chain.size), chain[chain >= 0]).astype(np.int64)
    total = np.zeros(heads.size)
    for i, h in enumerate(heads):
        lane = h
        while lane >= 0:
            total[i] += cost[lane]
            lane = chain[lane]
    return heads, total


def _phase_tables(n_lane: np.ndarray):
    """Concatenated forcing-phase tables of every distinct step count, and each lane's offset
    into them."""
    s_parts, c_parts, offset, pos = [], [], {}, 0
    for n in np.unique(n_lane):
        s, c = phase_table_values(int(n), True)
        offset[int(n)] = pos
        s_parts.append(s)
        c_parts.append(c)
        pos += s.size
    lane_tab = np.array([offset[int(n)] for n in n_lane], np.int64)
    return np.concatenate(s_parts), np.concatenate(c_parts), lane_tab


def busy_lanes(lanes: int, threads: int | None = None) -> int:
    """The lanes' worth of work a run of ``lanes`` lanes costs on ``threads`` threads (default
    numba's): the schedule (:func:`_schedule`) gives each of up to ``threads`` workers its share,
    and a worker steps its block's slots in whole vectors of ``SIMD_SLOTS``, so that fewer than
    ``SIMD_SLOTS`` lanes per thread take as long as ``SIMD_SLOTS`` per thread (e.g. 1 lane on 2
    threads: 16). Equal to ``lanes`` when they fill the vectors of every thread."""
    import numba

    from geardyn.solvers._step_shared import SIMD_SLOTS

    threads = max(1, int(threads or numba.get_num_threads()))
    lanes = max(1, int(lanes))
    per_worker = -(-lanes // min(threads, lanes))
    return threads * (-(-per_worker // SIMD_SLOTS) * SIMD_SLOTS)


def _schedule(cost: np.ndarray, workers: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A cost-balanced static schedule of lanes (``cost``: lane-steps of each) over workers:
    lanes longest first, dealt to the workers back and forth (1, 2, .., w, w, .., 1, 1, ..), so
    that each worker's total is about the same and its queue runs longest first (the block's
    tail is short lanes). Returns (start, queue): worker w takes the lanes
    queue[start[w]:start[w + 1]] in that order."""
    import numba

    L = cost.size
    workers = max(1, min(int(workers or numba.get_num_threads()), L))
    order = np.argsort(-np.asarray(cost, dtype=float), kind="stable")
    pos = np.arange(L)
    rnd, col = np.divmod(pos, workers)
    worker = np.where(rnd % 2 == 0, col, workers - 1 - col)
    by_worker = np.argsort(worker, kind="stable")  # keeps the longest-first order per worker
    queue = order[by_worker].astype(np.int64)
    start = np.zeros(workers + 1, np.int64)
    start[1:] = np.cumsum(np.bincount(worker, minlength=workers))
    return start, queue
