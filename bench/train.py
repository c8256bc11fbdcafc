"""Benchmark of a gear train's speed sweep: a 400-point bifurcation diagram in input speed of the
built-in study ``two_stage_train`` (two parallel spur stages, 8 coordinates, 16 states,
quasi-periodic forcing: stage 2 meshes at 23/61 of stage 1's frequency), target <= 10 s warm on
2 cores.

Workload: the study's model, 400 input speeds in [1000, 6000] rpm (``input_speed``, which sets
Omega alone), no continuation, through ``geardyn.bifurcation``, a transient of
``--transient-periods`` (200) stage-1 mesh periods at the lowest speed in every lane (more
periods at higher speeds), ``--samples`` (32) Poincare points, default steps per period. Prints
the workload (lane-steps), the median of ``--repeat`` warm runs (wall and process CPU time), ns
per lane-step and a checksum of the Poincare points; ``--write`` records the median in the
current-figures table of bench/RESULTS.md (row ``train-sweep``). ``--order-one`` sets stage 2's
order to 1 (one mesh frequency: the planetary kernels' shared-phase path) to show what the
second frequency costs; not with ``--write``.

    .venv/bin/python bench/train.py [--threads 2] [--repeat 3] [--transient-periods 200]
        [--samples 32] [--order-one] [--write]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import time

import numba
import numpy as np

import _results as results
import geardyn
from geardyn.core.plan import LanePlan
from geardyn.io.toml import builtin_study

TARGET_S = 10.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--transient-periods", type=float, default=200.0)
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--order-one", action="store_true",
                    help="stage 2's order set to 1 (one mesh frequency), for comparison")
    ap.add_argument("--write", action="store_true", help="record the figure in RESULTS.md")
    args = ap.parse_args()
    if args.order_one and args.write:
        ap.error("--order-one is a comparison, not the benchmark: not with --write")
    numba.set_num_threads(args.threads)
    model = geardyn.build_model(builtin_study("two_stage_train"))
    if args.order_one:
        model = model.with_params(stage2_order=1.0)
    rpm = np.linspace(1000.0, 6000.0, 400)
    P = model.lane_params("input_speed", rpm)
    omegas = P[:, model.omega_index]
    transient = args.transient_periods * 2.0 * math.pi / float(omegas.min())
    run = geardyn.RunSettings(transient=transient, samples=args.samples)
    plan = LanePlan.build(model, P, run)
    n = plan.steps_per_period.astype(np.int64)
    steps = int(np.sum(plan.transient_steps + run.samples * plan.sample_steps))
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, {args.threads} threads, "
          f"{platform.machine()}, {os.cpu_count()} cpus, load {os.getloadavg()[0]:.1f}")
    print(f"workload: two_stage_train ({model!r}), {rpm.size} input speeds in "
          f"[{rpm.min():g}, {rpm.max():g}] rpm (Omega {omegas.min():.4g} .. "
          f"{omegas.max():.4g}), transient {args.transient_periods:g} periods at the lowest, "
          f"{run.samples} samples, steps per period {n.max()} .. {n.min()}")
    print(f"lane-steps: {steps:.4e}")
    geardyn.bifurcation(model, "input_speed", rpm[:2], run.replace(transient=10.0, samples=2))
    walls, cpus = [], []
    for _ in range(args.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        ds = geardyn.bifurcation(model, "input_speed", rpm, run)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall, cpu = statistics.median(walls), statistics.median(cpus)
    print(f"warm wall time: median {wall:.2f} s of {[round(w, 2) for w in walls]}; "
          f"CPU {cpu:.2f} s of {[round(c, 2) for c in cpus]}")
    print(f"{wall * 1e9 / steps:.0f} ns wall per lane-step, {cpu * 1e9 / steps:.0f} ns CPU "
          f"per lane-step")
    print(f"checksum {np.nansum(ds['poincare'].values):.17g}")
    if args.write:
        results.record(
            "train-sweep", f"<= {TARGET_S:g} s warm, 2 cores",
            f"{wall:.2f} s wall (median of {args.repeat}; {cpu:.2f} s CPU; "
            f"{wall * 1e9 / steps:.0f} ns per lane-step, {steps:.3g} lane-steps; load "
            f"{os.getloadavg()[0]:.1f})", results.against(wall, TARGET_S),
            f".venv/bin/python bench/train.py --threads {args.threads} --repeat {args.repeat} "
            "--write")


if __name__ == "__main__":
    main()
