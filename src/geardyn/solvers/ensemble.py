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
from geardyn.solvers.simulate import DEFAULT_BOUND, default_steps_per_period

#: Automatic steps per period are rounded up to this geometric ladder (ratio 2^(1/4)), so that a
#: sweep over Omega needs only a few kernel calls.
_LADDER = np.unique(np.ceil(8 * 2.0 ** (np.arange(0, 60) / 4.0)).astype(int) * 2)


def ladder_steps(n: int) -> int:
    """The smallest value of the step ladder that is >= n."""
    idx = np.searchsorted(_LADDER, n)
    return int(_LADDER[min(idx, _LADDER.size - 1)]) if idx < _LADDER.size else int(n)


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
    transient_periods: np.ndarray  # (L,)


def run_lanes(
    model: Model,
    P: np.ndarray,
    y0: np.ndarray,
    transient: float,
    samples: int,
    steps_per_period: int | None = None,
    sample_every: int = 1,
    locate_edges: bool = True,
    bound: float = DEFAULT_BOUND,
    t0: np.ndarray | None = None,
) -> LaneResults:
    """Integrate one lane per row of ``P`` (coefficient vectors) from ``y0`` (one state, or one
    per lane) and return stroboscopic samples (one every ``sample_every`` forcing periods) and
    statistics over the sampled stretch. ``t0``: per-lane start times (whole periods)."""
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
    if samples < 1 or sample_every < 1:
        raise ValueError("samples and sample_every must be >= 1")
    if steps_per_period is None:
        n_lane = np.array([ladder_steps(default_steps_per_period(model, w)) for w in omega])
    else:
        n_lane = np.full(L, int(steps_per_period))
    period = 2.0 * math.pi / omega
    n_tr_periods = np.ceil(transient / period - 1e-9).astype(np.int64)
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
    )
    for n in np.unique(n_lane):
        # lanes of one group, sorted by period so lockstep blocks hold similar step counts
        idx = np.nonzero(n_lane == n)[0]
        idx = idx[np.argsort(period[idx], kind="stable")]
        m = idx.size
        smp = np.empty((m, samples, ns))
        fin = np.empty((m, ns))
        st = np.empty(m, np.int64)
        gmin = np.empty((m, max(n_ev, 1)))
        gmax = np.empty((m, max(n_ev, 1)))
        nc = np.empty((m, max(n_ev, 1)), np.int64)
        omax = np.empty((m, max(n_obs, 1)))
        omin = np.empty((m, max(n_obs, 1)))
        orms = np.empty((m, max(n_obs, 1)))
        unres = np.empty(m, np.int64)
        H = period[idx] / n
        k.sweep(P[idx], Y0[idx], H, omega[idx], T0[idx], int(n),
                (n_tr_periods[idx] * n).astype(np.int64), int(samples), int(sample_every * n),
                bool(locate_edges), float(bound), n_ev, n_obs, smp, fin, st, gmin, gmax, nc,
                omax, omin, orms, unres)
        out.samples[idx] = smp
        out.final[idx] = fin
        out.status[idx] = st
        out.event_min[idx] = gmin[:, :n_ev]
        out.event_max[idx] = gmax[:, :n_ev]
        out.crossings[idx] = nc[:, :n_ev]
        out.obs_max[idx] = omax[:, :n_obs]
        out.obs_min[idx] = omin[:, :n_obs]
        out.obs_rms[idx] = orms[:, :n_obs]
        out.unresolved[idx] = unres
    out.final_time = T0 + (n_tr_periods + samples * sample_every) * period
    return out
