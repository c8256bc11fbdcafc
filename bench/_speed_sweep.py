"""The timed speed sweep that bench/train.py and bench/nrel_sweep.py share: a bifurcation
diagram of a train study in input speed, its workload (lane-steps), the median of warm runs
(wall and process CPU time), ns per lane-step, a checksum of the Poincare points and, with
``write``, the median as a row of bench/RESULTS.md's current figures."""

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


def arguments(doc: str, repeat: int, samples: int) -> argparse.ArgumentParser:
    """The options both scripts take (their defaults of ``--repeat`` and ``--samples``)."""
    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--repeat", type=int, default=repeat)
    ap.add_argument("--transient-periods", type=float, default=200.0)
    ap.add_argument("--samples", type=int, default=samples)
    ap.add_argument("--write", action="store_true", help="record the figure in RESULTS.md")
    return ap


def timed_sweep(model: geardyn.Model, label: str, rpm: np.ndarray, args: argparse.Namespace,
                row: str, target_s: float, script: str) -> object:
    """Sweep ``model`` over the input speeds ``rpm`` [rpm] (``args``: threads, repeat,
    transient periods of the forcing at the lowest speed, samples, write), print the figures,
    record them as ``row`` against ``target_s`` [s] with ``--write``; the last run's Dataset."""
    numba.set_num_threads(args.threads)
    P = model.lane_params("input_speed", rpm)
    omegas = P[:, model.omega_index]
    transient = args.transient_periods * 2.0 * math.pi / float(omegas.min())
    run = geardyn.RunSettings(transient=transient, samples=args.samples)
    plan = LanePlan.build(model, P, run)
    n = plan.steps_per_period.astype(np.int64)
    steps = int(np.sum(plan.transient_steps + run.samples * plan.sample_steps))
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, {args.threads} threads, "
          f"{platform.machine()}, {os.cpu_count()} cpus, load {os.getloadavg()[0]:.1f}")
    print(f"workload: {label} ({model!r}), {rpm.size} input speeds in [{rpm.min():g}, "
          f"{rpm.max():g}] rpm (Omega {omegas.min():.4g} .. {omegas.max():.4g}), transient "
          f"{args.transient_periods:g} periods at the lowest, {run.samples} samples, steps per "
          f"period {n.max()} .. {n.min()}")
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
            row, f"<= {target_s:g} s warm, 2 cores",
            f"{wall:.2f} s wall (median of {args.repeat}; {cpu:.2f} s CPU, "
            f"{cpu * 1e9 / steps:.0f} ns CPU per lane-step, {cpu / args.threads:.1f} s of "
            f"CPU per thread; {wall * 1e9 / steps:.0f} ns wall per lane-step, {steps:.3g} "
            f"lane-steps; load {os.getloadavg()[0]:.1f})", results.against(wall, target_s),
            f".venv/bin/python bench/{script} --threads {args.threads} --repeat {args.repeat} "
            "--write")
    return ds
