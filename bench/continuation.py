"""Benchmark of the reproduction's continued sweeps: every kernel call of
:func:`geardyn.analysis.continuation.continue_branches` timed, with its chains' lengths.

Runs :func:`geardyn.reproduction.runner.run_cases` for the paper's figure cases under the
given interpretations, with ``continuation.run_lanes`` wrapped to record, per call, the lanes,
the chains, the lane-steps planned and those integrated (``LaneResults.steps``: a
lane run twice shows), the longest chain and the mean one (lane-steps) and the wall
time; and the Lyapunov calls' total wall time. A call waits for its longest chain, so
mean / max says how much of it a block's tail can waste.

    .venv/bin/python bench/continuation.py [consistent[,carrier-only,...]]
"""

from __future__ import annotations

import sys
import time

import numpy as np

import geardyn.analysis.continuation as continuation
import geardyn.reproduction.runner as runner
from geardyn.reproduction.cases import paper_cases


def main() -> None:
    calls: list[dict] = []
    lyapunov: list[float] = []
    run_lanes = continuation.run_lanes
    lyapunov_lanes = runner.lyapunov_lanes

    def timed_run_lanes(model, P, Y0, *, chain, **kw):
        t = time.perf_counter()
        r = run_lanes(model, P, Y0, chain=chain, **kw)
        wall = time.perf_counter() - t
        # sample_every is in forcing periods (before 2026-12-02 this divided it by the steps
        # per period, and so counted the transients only: 3.5e8 lane-steps for 6.9e8)
        steps = (r.transient_periods + kw["run"].samples * r.sample_every) * r.steps_per_period
        heads = np.setdiff1d(np.arange(chain.size), chain[chain >= 0])
        lengths = []
        for lane in heads:
            total = 0
            while lane >= 0:
                total += int(steps[lane])
                lane = chain[lane]
            lengths.append(total)
        done = int(r.steps.sum()) if hasattr(r, "steps") else -1  # measured (since 2026-12-02)
        calls.append(dict(lanes=int(chain.size), chains=len(lengths), steps=int(steps.sum()),
                          done=done, longest=max(lengths), mean=float(np.mean(lengths)),
                          wall=wall))
        return r

    def timed_lyapunov(*args, **kw):
        t = time.perf_counter()
        out = lyapunov_lanes(*args, **kw)
        lyapunov.append(time.perf_counter() - t)
        return out

    continuation.run_lanes = timed_run_lanes
    runner.lyapunov_lanes = timed_lyapunov
    interpretations = sys.argv[1].split(",") if len(sys.argv) > 1 else ["consistent"]
    start = time.perf_counter()
    runner.run_cases(paper_cases(), interpretations)
    total = time.perf_counter() - start
    print(f"total wall {total:.1f} s")
    print(f"continuation: {len(calls)} calls, {sum(c['wall'] for c in calls):.1f} s, "
          f"{sum(c['steps'] for c in calls):.3e} lane-steps")
    print(f"lane-steps integrated (measured, LaneResults.steps): "
          f"{sum(c['done'] for c in calls):.3e}")
    print("lanes chains lane-steps integrated longest mean/longest wall_s")
    for c in calls:
        print(f"{c['lanes']} {c['chains']} {c['steps']} {c['done']} {c['longest']} "
              f"{c['mean'] / c['longest']:.2f} {c['wall']:.2f}")
    print(f"lyapunov: {len(lyapunov)} calls, {sum(lyapunov):.1f} s")


if __name__ == "__main__":
    main()
