"""Benchmark of the NREL 5 MW gearbox's speed sweep: a 200-point bifurcation diagram in rotor
speed of the built-in study ``nrel_5mw_gearbox_sweep`` (16 bodies, 13 nonlinear meshes, 34
coordinates, quasi-periodic forcing: three mesh frequencies), target <= 2 min warm on 2 cores
(issue 36).

Workload: the study's model, 200 rotor speeds in [2, 25] rpm (``input_speed``), no
continuation, through ``geardyn.bifurcation``, a transient of ``--transient-periods`` (200)
stage-3 mesh periods at the lowest speed in every lane (more at higher speeds), ``--samples``
(16) Poincare points, default steps per period. Prints the workload (lane-steps), the median of
``--repeat`` warm runs (wall and process CPU time), ns per lane-step, the meshes' contact
regimes and a checksum of the Poincare points; ``--write`` records the median in the
current-figures table of bench/RESULTS.md (row ``nrel-sweep``).

    .venv/bin/python bench/nrel_sweep.py [--threads 2] [--repeat 1] [--transient-periods 200]
        [--samples 16] [--write]
"""

from __future__ import annotations

import argparse
import collections
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

TARGET_S = 120.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--transient-periods", type=float, default=200.0)
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--write", action="store_true", help="record the figure in RESULTS.md")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    model = geardyn.build_model(builtin_study("nrel_5mw_gearbox_sweep"))
    rpm = np.linspace(2.0, 25.0, 200)
    P = model.lane_params("input_speed", rpm)
    omegas = P[:, model.omega_index]
    transient = args.transient_periods * 2.0 * math.pi / float(omegas.min())
    run = geardyn.RunSettings(transient=transient, samples=args.samples)
    plan = LanePlan.build(model, P, run)
    n = plan.steps_per_period.astype(np.int64)
    steps = int(np.sum(plan.transient_steps + run.samples * plan.sample_steps))
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, {args.threads} threads, "
          f"{platform.machine()}, {os.cpu_count()} cpus, load {os.getloadavg()[0]:.1f}")
    print(f"workload: nrel_5mw_gearbox_sweep ({model!r}), {rpm.size} rotor speeds in "
          f"[{rpm.min():g}, {rpm.max():g}] rpm, transient {args.transient_periods:g} periods "
          f"at the lowest, {run.samples} samples, steps per period {n.max()} .. {n.min()}")
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
    for name in ds["mesh"].values:
        print(f"contact {name}: {dict(collections.Counter(ds['contact'].sel(mesh=name).values))}")
    print(f"checksum {np.nansum(ds['poincare'].values):.17g}")
    if args.write:
        results.record(
            "nrel-sweep", f"<= {TARGET_S:g} s warm, 2 cores",
            f"{wall:.2f} s wall (median of {args.repeat}; {cpu:.2f} s CPU; "
            f"{wall * 1e9 / steps:.0f} ns per lane-step, {steps:.3g} lane-steps; load "
            f"{os.getloadavg()[0]:.1f})", results.against(wall, TARGET_S),
            f".venv/bin/python bench/nrel_sweep.py --threads {args.threads} --repeat "
            f"{args.repeat} --write")


if __name__ == "__main__":
    main()
