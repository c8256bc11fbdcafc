"""Benchmark of issue 13's speed target: a 400-point bifurcation diagram of the N = 4 planetary
gear set (42 states) of the built-in study ``planetary_example``.

Workload: the study's model, 400 Omega in [0.05, 1.2] (mesh frequency over the time scale;
about 1250-30000 rpm input speed), no continuation, through ``geardyn.bifurcation``, with
explicit settings instead of the study's [run]: ``--samples`` (32) Poincare points after a
transient of ``--transient-periods`` (200) mesh periods at the lowest Omega, i.e. a transient of
200 * 2 pi / 0.05 = 25133 time units in every lane (more periods at higher Omega), default steps
per period (``--study-run``: the study's own [run] instead, i.e. transient_periods and
converge, with ``--samples``). ``--stride k`` runs every k-th point only (a quick subset). Prints
the workload (lane-steps, steps per period used), the median of ``--repeat`` warm runs (wall
and process CPU time) and ns per lane-step, and a checksum of the Poincare points.

``--carrier-speed kinematic`` (or a speed such as ``"3000 rpm"``) runs the set with its
carrier's gyroscopic and centripetal terms (``docs/planetary.md``, "Rotating carrier").

    .venv/bin/python bench/planetary.py [--threads 2] [--repeat 3] [--stride 1]
        [--transient-periods 200] [--samples 32] [--study-run] [--carrier-speed kinematic]
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

import geardyn
from geardyn.core.plan import LanePlan
from geardyn.io.toml import builtin_study


def workload(args: argparse.Namespace):
    study = builtin_study("planetary_example")
    if args.carrier_speed is not None:
        study = study.model_copy(update={"params": study.params.model_copy(
            update={"carrier_speed": args.carrier_speed})})
    model = geardyn.build_model(study)
    omegas = np.linspace(0.05, 1.2, 400)[::args.stride]
    if args.study_run:  # the study's [run] (transient in periods of the lowest Omega, converge)
        return model, omegas, study.run_settings(sweep=True, omega=float(np.min(omegas)),
                                                 samples=args.samples)
    transient = args.transient_periods * 2.0 * math.pi / float(np.min(omegas))
    run = geardyn.RunSettings(transient=transient, samples=args.samples)
    return model, omegas, run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--stride", type=int, default=1)
    ap.add_argument("--transient-periods", type=float, default=200.0)
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--study-run", action="store_true",
                    help="the study's own [run] settings (with --samples) instead")
    ap.add_argument("--carrier-speed", default=None,
                    help="the set's carrier_speed: 'kinematic' or a speed ('3000 rpm')")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    model, omegas, run = workload(args)
    plan = LanePlan.build(model, model.lane_params("Omega", omegas), run)
    n = plan.steps_per_period.astype(np.int64)
    steps = int(np.sum(plan.transient_steps + run.samples * plan.sample_steps))
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, {args.threads} threads, "
          f"{platform.machine()}, {os.cpu_count()} cpus, load {os.getloadavg()[0]:.1f}, "
          f"SIMD {geardyn._jit_target.APPLIED.split(':')[0]}")
    print(f"workload: planetary_example ({model!r}), {omegas.size} Omega in "
          f"[{omegas.min():g}, {omegas.max():g}], transient {run.transient:.1f} "
          f"({run.transient * omegas.min() / (2 * math.pi):g} periods at Omega "
          f"{omegas.min():g}; converge {run.converge}), {run.samples} "
          f"samples, default steps per period: {n.max()} at Omega {omegas.min():g} .. "
          f"{n.min()} at Omega {omegas.max():g} (fastest natural frequency "
          f"{float(model.fastest_natural_frequency()[0]):.4f})")
    print(f"lane-steps: {steps:.4e}")
    geardyn.bifurcation(model, "Omega", omegas[:2], run.replace(transient=10.0, samples=2))
    walls, cpus = [], []
    for _ in range(args.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        ds = geardyn.bifurcation(model, "Omega", omegas, run)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall, cpu = statistics.median(walls), statistics.median(cpus)
    if "transient_periods" in ds and "steps_per_period" in ds:  # as run (converge: longer)
        steps = int(np.sum((ds["transient_periods"].values + run.samples * plan.sample_every)
                           * ds["steps_per_period"].values.astype(np.int64)))
        print(f"lane-steps as run: {steps:.4e}")
    print(f"warm wall time: median {wall:.2f} s of {[round(w, 2) for w in walls]}; "
          f"CPU {cpu:.2f} s of {[round(c, 2) for c in cpus]}")
    print(f"{wall * 1e9 / steps:.0f} ns wall per lane-step, {cpu * 1e9 / steps:.0f} ns CPU "
          f"per lane-step")
    pts = ds["poincare"].values if "poincare" in ds else ds[list(ds.data_vars)[0]].values
    print(f"checksum {np.nansum(pts):.17g}; crossings {int(np.sum(ds['crossings'].values))}"
          if "crossings" in ds else f"checksum {np.nansum(pts):.17g}")


if __name__ == "__main__":
    main()
