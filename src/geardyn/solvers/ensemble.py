"""Many independent integrations at once: one lane per parameter set, compiled and parallel.

:func:`run_lanes` is the engine under every sweep. Each lane integrates the model with its own
coefficient vector for a transient (a time, rounded up to whole forcing periods of that lane),
then records stroboscopic samples and statistics. Lanes sharing a number of steps per period run
in one parallel kernel call; within it, lanes are advanced in lockstep blocks (see
``_kernel_template``). Results do not depend on how lanes are grouped or on the thread count.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geardyn.models.base import Model
from geardyn.solvers.kernels import kernels_for
from geardyn.solvers.simulate import DEFAULT_BOUND, steps_per_period_rule

#: Automatic steps per period are rounded up to this geometric ladder (ratio 2^(1/4)), so that a
#: sweep over Omega needs only a few kernel calls.
_LADDER = np.unique(np.ceil(8 * 2.0 ** (np.arange(0, 60) / 4.0)).astype(int) * 2)


def ladder_steps(n: int) -> int:
    """The smallest value of the step ladder that is >= n."""
    idx = np.searchsorted(_LADDER, n)
    return int(_LADDER[min(idx, _LADDER.size - 1)]) if idx < _LADDER.size else int(n)


def lane_steps_per_period(model: Model, P: np.ndarray) -> np.ndarray:
    """Default steps per forcing period of each lane (row of ``P``), rounded up to the ladder:
    the rule of :func:`~geardyn.solvers.simulate.default_steps_per_period` with the lane's own
    Omega, other forcings and fastest natural frequency (from the lane's coefficients, so a
    sweep over a stiffness or a mass refines the step where the device is stiffer)."""
    P = np.atleast_2d(P)
    n = steps_per_period_rule(model, P, P[:, model.omega_index])
    if not np.all(np.isfinite(n)) or np.any(n >= 2.0**62):
        raise OverflowError("steps per period do not fit an integer; check Omega")
    idx = np.searchsorted(_LADDER, n)  # as ladder_steps, for every lane at once
    return np.where(idx < _LADDER.size, _LADDER[np.minimum(idx, _LADDER.size - 1)],
                    n).astype(np.int64)


@dataclass
class LaneResults:
    """Raw per-lane results of :func:`run_lanes` (arrays indexed by lane)."""

    samples: np.ndarray  # (L, n_samples, n_states); NaN for diverged lanes
    final: np.ndarray  # (L, n_states) state at the end
    final_time: np.ndarray  # (L,) model time at the end
    status: np.ndarray  # (L,) 0 ok, 1 diverged
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
    transient: float | np.ndarray,
    samples: int,
    steps_per_period: int | np.ndarray | None = None,
    sample_every: int | np.ndarray | str = "auto",
    locate_edges: bool = True,
    bound: float = DEFAULT_BOUND,
    t0: np.ndarray | None = None,
    transient_max: float | np.ndarray | None = None,
    converge_tol: float = 0.0,
    converge_depth: int = 16,
    max_section_periods: int | None = None,
) -> LaneResults:
    """Integrate one lane per row of ``P`` (coefficient vectors) from ``y0`` (one state, or one
    per lane) and return stroboscopic samples (one every ``sample_every`` forcing periods) and
    statistics over the sampled stretch. ``t0``: per-lane start times (whole periods);
    ``transient``, ``transient_max``, ``steps_per_period`` (<= 0: automatic) and
    ``sample_every`` may differ per lane; ``"auto"`` samples at the common period of the
    forcings when the model has a second, commensurate excitation
    (:func:`~geardyn.analysis.periodicity.common_section`), else every period. The transient is
    rounded up to whole sampling intervals.

    Transient by convergence: with ``converge_tol > 0`` the transient (then a minimum) goes on,
    one sampling interval at a time up to ``transient_max`` (default 10 x transient), until the
    section point is estimated within ``converge_tol (1 + |point|)`` of a periodic orbit of
    period <= ``converge_depth`` sections (from the contraction of successive differences,
    docs/numerics.md); ``converged`` tells per lane whether it was.

    ``max_section_periods``: with ``"auto"``, the longest common period (in forcing periods)
    taken as a section (default that of :func:`~geardyn.analysis.periodicity.common_section`,
    32); a lane whose forcings repeat only over more is treated as incommensurate."""
    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    L = P.shape[0]
    ns = model.n_states
    Y0 = np.ascontiguousarray(np.broadcast_to(np.asarray(y0, dtype=float), (L, ns)))
    if model.omega_index is None:
        raise ValueError("run_lanes needs a periodically forced model (it samples once a period)")
    omega = P[:, model.omega_index].copy()
    if np.any(~np.isfinite(omega)) or np.any(omega <= 0):
        bad = omega[~(np.isfinite(omega) & (omega > 0))][0]
        raise ValueError(f"Omega must be positive and finite in every lane (got {bad!r})")
    if isinstance(sample_every, str):
        if sample_every != "auto":
            raise ValueError(f"sample_every must be 'auto' or >= 1 (got {sample_every!r})")
        from geardyn.analysis.periodicity import common_section

        limit = {} if max_section_periods is None else {"max_periods": int(max_section_periods)}
        sample_every, commensurate = common_section(omega, model.other_frequencies(P), **limit)
    else:
        commensurate = np.ones(L, bool)
    if samples < 1 or np.any(np.asarray(sample_every) < 1):
        raise ValueError("samples and sample_every must be >= 1")
    given = np.broadcast_to(np.asarray(0 if steps_per_period is None else steps_per_period,
                                       dtype=np.int64), (L,))
    n_lane = given.copy()
    auto = n_lane <= 0
    if np.any(auto):
        n_lane[auto] = lane_steps_per_period(model, P[auto])
    period = 2.0 * math.pi / omega
    every = np.broadcast_to(np.asarray(sample_every, dtype=np.int64), (L,))
    transient = np.broadcast_to(np.asarray(transient, dtype=float), (L,))
    n_tr_periods = _whole(np.ceil(transient / period - 1e-9), every)
    if transient_max is None:
        transient_max = 10.0 * transient
    transient_max = np.broadcast_to(np.asarray(transient_max, dtype=float), (L,))
    n_max_periods = np.maximum(_whole(np.floor(transient_max / period + 1e-9), every),
                               n_tr_periods)
    if converge_tol < 0 or converge_depth < 1:
        raise ValueError("converge_tol must be >= 0 and converge_depth >= 1")
    T0 = np.zeros(L) if t0 is None else np.broadcast_to(np.asarray(t0, float), (L,)).copy()
    n_ev, n_obs = model.n_events, model.n_observables
    k = kernels_for(model.kernel)
    out = LaneResults(
        samples=np.full((L, samples, ns), np.nan),
        final=np.full((L, ns), np.nan),
        final_time=np.zeros(L),
        status=np.zeros(L, np.int64),
        event_min=np.zeros((L, n_ev)),
        event_max=np.zeros((L, n_ev)),
        crossings=np.zeros((L, n_ev), np.int64),
        obs_max=np.zeros((L, n_obs)),
        obs_min=np.zeros((L, n_obs)),
        obs_rms=np.zeros((L, n_obs)),
        unresolved=np.zeros(L, np.int64),
        steps_per_period=n_lane,
        transient_periods=n_tr_periods,
        converged=np.full(L, -1, np.int64),
        sample_every=every.copy(),
        commensurate=np.asarray(commensurate, bool),
    )
    # lanes sorted by steps per period, then period: a lockstep block holds lanes of one step
    # count and similar length
    order = np.lexsort((period, n_lane))
    sched = _schedule(n_lane[order], n_tr_periods[order] + samples * every[order], k.BLOCK)
    tr_steps = np.empty(L, np.int64)
    conv = np.empty(L, np.int64)
    s_tab, c_tab, tab_of = _phase_tables(k, n_lane)
    smp = np.empty((L, samples, ns))
    fin = np.empty((L, ns))
    st = np.empty(L, np.int64)
    gmin = np.empty((L, n_ev))
    gmax = np.empty((L, n_ev))
    nc = np.empty((L, n_ev), np.int64)
    omax = np.empty((L, n_obs))
    omin = np.empty((L, n_obs))
    orms = np.empty((L, n_obs))
    unres = np.empty(L, np.int64)
    first, nl, nper, w_start, w_blocks = sched
    k.sweep(P[order], Y0[order], (period / n_lane)[order], omega[order], T0[order],
            (n_tr_periods * n_lane)[order].astype(np.int64),
            (n_max_periods * n_lane)[order].astype(np.int64), float(converge_tol),
            int(converge_depth), int(samples),
            (every * n_lane)[order].astype(np.int64), bool(locate_edges), float(bound), n_ev,
            n_obs, first, nl, nper, np.array([tab_of[int(n)] for n in nper], np.int64),
            s_tab, c_tab, w_start, w_blocks, smp, fin, st, gmin, gmax, nc, omax, omin, orms,
            unres, tr_steps, conv)
    out.samples[order] = smp
    out.final[order] = fin
    out.status[order] = st
    out.event_min[order] = gmin
    out.event_max[order] = gmax
    out.crossings[order] = nc
    out.obs_max[order] = omax
    out.obs_min[order] = omin
    out.obs_rms[order] = orms
    out.unresolved[order] = unres
    out.converged[order] = conv
    out.transient_periods[order] = tr_steps // n_lane[order]
    out.final_time = T0 + (out.transient_periods + samples * every) * period
    return out


def _whole(periods: np.ndarray, every: np.ndarray) -> np.ndarray:
    """Periods rounded up to whole multiples of ``every``."""
    return (np.ceil(periods / every) * every).astype(np.int64)


def _phase_tables(k, n_lane: np.ndarray):
    """Concatenated forcing-phase tables of every distinct step count, and their offsets."""
    s_parts, c_parts, offset, pos = [], [], {}, 0
    for n in np.unique(n_lane):
        s, c = k.phase_table(int(n), True)
        offset[int(n)] = pos
        s_parts.append(s)
        c_parts.append(c)
        pos += s.size
    return np.concatenate(s_parts), np.concatenate(c_parts), offset


def _schedule(n_per: np.ndarray, periods: np.ndarray, block: int, workers: int | None = None):
    """Lockstep blocks over lanes (already sorted by step count) and a cost-balanced static
    assignment of blocks to workers (longest block first to the least loaded worker).

    Returns (block_first, block_nl, block_nper, worker_start, worker_blocks)."""
    import numba

    workers = workers or numba.get_num_threads()
    first, nl, nper, cost = [], [], [], []
    L = n_per.size
    a = 0
    while a < L:
        b = a + 1
        while b < L and b - a < block and n_per[b] == n_per[a]:
            b += 1
        first.append(a)
        nl.append(b - a)
        nper.append(int(n_per[a]))
        cost.append(float(np.max(periods[a:b])) * int(n_per[a]) * (b - a + block) / 2)
        a = b
    load = np.zeros(workers)
    assigned: list[list[int]] = [[] for _ in range(workers)]
    for blk in np.argsort(cost, kind="stable")[::-1]:
        w = int(np.argmin(load))
        assigned[w].append(int(blk))
        load[w] += cost[blk]
    start = np.cumsum([0] + [len(x) for x in assigned]).astype(np.int64)
    blocks = np.array([b for x in assigned for b in x], dtype=np.int64)
    return (np.array(first, np.int64), np.array(nl, np.int64), np.array(nper, np.int64), start,
            blocks)
