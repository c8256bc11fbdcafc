"""Sequential continuation: each point of a branch starts from the final state (and time) of
the previous one, so a sweep follows one attractor and shows hysteresis.

A branch is inherently sequential, but several branches (a sweep up and one down, or the
sweeps of several studies) are independent of each other: :func:`continue_branches` advances
all of them together in one :func:`~geardyn.solvers.ensemble.run_lanes` call per
:data:`SEGMENT` points, each branch's points a *chain* of lanes: a point starts in the slot
where the point before it ended, from its final state at its end time. The branches then share
the vector blocks and threads instead of running one after another, and a slot whose point
settles early goes on with the branch's next point instead of idling until the slowest point
of the call has ended. Each branch's result is bitwise the one it gets alone, point by point
(lanes do not interact).

A continued point starts next to its attractor, so it needs a far shorter transient than a cold
start: ``continued_transient`` is its minimum, and the transient goes on until the Poincare
point settles (``converge``), up to ``transient_max``. A point with a second excitation at an
incommensurate frequency has no stroboscopic section that could repeat, so it cannot be tested:
it runs ``continued_transient`` only when continued, ``transient_max`` when cold. A cold start is
the first point of a branch, and any point after one whose integration diverged (the branch
restarts from its initial state).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geardyn.core.model import Model
from geardyn.core.plan import LaneSettings, lane_omega, lane_section, lane_steps
from geardyn.core.settings import RunSettings, resolve_run
from geardyn.core.status import Status
from geardyn.solvers.ensemble import LaneResults, run_lanes
from geardyn.solvers.kernels import kernels_for

__all__ = ["Branch", "continue_branches"]


@dataclass(frozen=True)
class Branch:
    """One continuation branch: ``P`` (points, coefficients), the model's lane coefficient
    vectors in the order the branch visits them; ``y0`` the initial state of a cold start;
    transients in model time units (see the module docs); ``steps_per_period`` None: the
    model's default at each point; ``max_section_periods`` as in
    :func:`~geardyn.solvers.ensemble.run_lanes`."""

    model: Model
    P: np.ndarray
    y0: np.ndarray
    transient: float
    continued_transient: float | None = None
    transient_max: float | None = None
    steps_per_period: int | None = None
    max_section_periods: int | None = None
    commensurate: np.ndarray = field(init=False, repr=False)
    steps: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        P = np.atleast_2d(np.asarray(self.P, dtype=float))
        object.__setattr__(self, "P", P)
        object.__setattr__(self, "y0", np.asarray(self.y0, dtype=float))
        omega = lane_omega(self.model, P)
        object.__setattr__(self, "commensurate", lane_section(
            self.model, P, omega, self.max_section_periods)[1])
        object.__setattr__(self, "steps", lane_steps(self.model, P, self.steps_per_period))

    def transients(self, j: int, cold: bool, converge: bool) -> tuple[float, float]:
        """(minimum, maximum) transient of point ``j``."""
        longest = (self.transient_max if self.transient_max is not None
                   else 10.0 * self.transient) if converge else self.transient
        if cold:
            return (self.transient if self.commensurate[j] else longest), longest
        short = self.transient if self.continued_transient is None else self.continued_transient
        if not converge or not self.commensurate[j]:
            return short, short
        return short, max(short, longest)


#: Points of each branch per kernel call (a segment of its chain): the calls report progress,
#: and a branch's last lane of a segment waits for the slowest one only there.
SEGMENT = 64


def continue_branches(
    branches: Sequence[Branch],
    run: RunSettings | int | None = None,
    progress: Callable[[int, int], None] | None = None,
    *,
    segment: int = SEGMENT,
    **settings: Any,
) -> list[LaneResults]:
    """Run every branch by continuation, all branches together (see the module docs), with the
    ``samples``, ``converge``, ``locate_edges`` and ``bound`` of ``run`` (the branches' own
    transients and steps apply); those as keyword arguments, or an int as ``run`` (the
    samples), are deprecated (one DeprecationWarning naming ``run=geardyn.RunSettings(...)``).
    The branches must share the model's compiled kernel. Returns one
    :class:`~geardyn.solvers.ensemble.LaneResults` per branch, its lanes in the branch's
    order. ``progress(done, total)`` counts points of all branches.

    Each kernel call runs the next ``segment`` points of every branch as a chain of lanes
    (``run_lanes(chain=...)``): a branch's point starts in the slot where the point before it
    ended, from its final state and time, so the slots stay busy however the points'
    transients differ. After a point that did not end well the branch restarts cold in the
    next call (its initial state, time 0, the cold transient), as a lone point would."""
    if not branches:
        return []
    kernel = kernels_for(branches[0].model.kernel)
    if any(kernels_for(b.model.kernel) is not kernel for b in branches):
        raise ValueError("continue_branches: the branches must share one model kernel")
    sections = {b.max_section_periods for b in branches}
    if len(sections) > 1:
        raise ValueError("continue_branches: the branches must share max_section_periods")
    if isinstance(run, (int, np.integer)):
        settings["samples"] = run
        run = None
    if int(segment) < 1:
        raise ValueError(f"segment must be >= 1 (got {segment!r})")
    run = resolve_run(run, settings, where="continue_branches")
    # the branches' transients, steps and section are per lane (below)
    run = run.replace(max_section_periods=branches[0].max_section_periods)
    converge = run.converge_tol
    n = [b.P.shape[0] for b in branches]
    total = sum(n)
    parts: list[list[LaneResults]] = [[] for _ in branches]
    y = [b.y0 for b in branches]
    t0 = [0.0 for _ in branches]
    cold = [True for _ in branches]
    nxt = [0 for _ in branches]  # each branch's next point
    done = 0
    while True:
        live = [i for i in range(len(branches)) if nxt[i] < n[i]]
        if not live:
            break
        if progress is not None:
            progress(done, total)
        points = {i: range(nxt[i], min(n[i], nxt[i] + int(segment))) for i in live}
        P, Y0, T0, tr, tmax, steps, chain, first = [], [], [], [], [], [], [], {}
        for i in live:
            b = branches[i]
            first[i] = len(P)
            for q, j in enumerate(points[i]):
                lo, hi = b.transients(j, cold[i] and q == 0, converge > 0)
                P.append(b.P[j])
                Y0.append(np.broadcast_to(y[i] if q == 0 else b.y0, b.y0.shape[-1:]))
                T0.append(t0[i] if q == 0 else 0.0)
                tr.append(lo)
                tmax.append(hi)
                steps.append(b.steps[j])
                chain.append(len(P) if q + 1 < len(points[i]) else -1)
        lanes = LaneSettings(t0=T0, transient=tr, transient_max=tmax, steps_per_period=steps)
        r = run_lanes(branches[live[0]].model, np.stack(P), np.stack(Y0), run=run, lanes=lanes,
                      chain=np.array(chain, np.int64))
        for i in live:
            b = branches[i]
            for q, j in enumerate(points[i]):
                lane = first[i] + q
                parts[i].append(r.take(slice(lane, lane + 1)))
                if converge > 0 and not b.commensurate[j]:
                    parts[i][-1].converged[:] = -1  # no section to test: a fixed transient
                done += 1
                nxt[i] = j + 1
                if r.status[lane] == Status.OK:
                    y[i], t0[i], cold[i] = r.final[lane], float(r.final_time[lane]), False
                else:  # lost the branch: restart from the initial state (the chain stopped)
                    y[i], t0[i], cold[i] = b.y0, 0.0, True
                    break
    if progress is not None:
        progress(total, total)
    return [LaneResults.concat(p) for p in parts]
