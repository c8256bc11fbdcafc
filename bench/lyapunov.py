"""Lyapunov kernel benchmark: lanes in SoA blocks against one lane at a time, in one run (issue 11).

Workload: the paper's device (Tables 1-2, consistent interpretation, reduced model, xi1 = xi2 =
0.05), ``--lanes`` values of Omega in [``--lo``, ``--hi``], the largest exponent (k = 1, as
``bifurcation(..., lyapunov=True)`` computes it: one state row and two perturbed rows per lane)
over ``--transient`` + ``--duration`` time units at the default steps per period, with edge
location. Both kernels run the same lanes through ``geardyn.lyapunov_lanes`` (the generated
module's ``lyapunov_lanes`` swapped for the one-lane-at-a-time ``lyapunov_lanes_rows``, the
kernel of main before the lane blocks), alternately, in this process. Reports per kernel: warm
wall time (median of ``--repeat``), CPU time, and ns per lane-step per thread (one lane-step:
one grid step of one lane with its 2k tangent rows; wall time x threads / lane-steps, and CPU
time / lane-steps), and whether the exponents and errors are bitwise equal.

    .venv/bin/python bench/lyapunov.py [--repeat 3] [--lanes 42] [--threads N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np

import _results as results
import geardyn
from geardyn.analysis.lyapunov import lyapunov_lanes
from geardyn.core.plan import forcing_period, lane_steps, periods_covering
from geardyn.solvers.kernels import kernels_for


def device() -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))


def count_lane_steps(model, P, transient: float, duration: float) -> int:
    """Grid steps of all lanes, as ``lyapunov_lanes`` plans them (transient + measured)."""
    n = lane_steps(model, P, None)
    periods = forcing_period(P[:, model.omega_index])
    return int(sum((periods_covering(transient, T) + max(1, periods_covering(duration, T))) * k
                   for T, k in zip(periods, n, strict=True)))


def kernel_args(model, P, transient: float, duration: float):
    """The kernel's lane arrays, as ``lyapunov_lanes`` builds them."""
    n = lane_steps(model, P, None).astype(np.int64)
    om = np.ascontiguousarray(P[:, model.omega_index])
    periods = forcing_period(om)
    n_tr = np.array([periods_covering(transient, T) * k for T, k in zip(periods, n, strict=True)],
                    dtype=np.int64)
    n_st = np.array([max(1, periods_covering(duration, T)) * k
                     for T, k in zip(periods, n, strict=True)], dtype=np.int64)
    Y0 = np.ascontiguousarray(np.tile(model.initial_state(), (P.shape[0], 1)))
    return P, Y0, np.ones(model.n_states), np.zeros(P.shape[0]), periods / n, om, n, n_tr, n_st


def run_kernel(fn, args, n_ev):
    out, err = np.full(args[0].shape[0], np.nan), np.full(args[0].shape[0], np.nan)
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    fn(*args, 10, 1e6, out, err, n_ev, 16)
    return time.perf_counter() - t_wall, time.process_time() - t_cpu


def run(model, P, transient, duration):
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    lam, err = lyapunov_lanes(model, P, run=geardyn.RunSettings(transient=transient),
                              settings=geardyn.LyapunovSettings(duration=duration),
                              with_error=True)
    return time.perf_counter() - t_wall, time.process_time() - t_cpu, lam, err


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--lanes", type=int, default=42)
    ap.add_argument("--lo", type=float, default=0.5)
    ap.add_argument("--hi", type=float, default=3.5)
    ap.add_argument("--transient", type=float, default=20.0)
    ap.add_argument("--duration", type=float, default=200.0)
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    ap.add_argument("--write", action="store_true",
                    help="record the figure in bench/RESULTS.md's current-figures table")
    a = ap.parse_args()
    numba.set_num_threads(a.threads)
    model = device()
    P = np.ascontiguousarray(model.lane_params("Omega", np.linspace(a.lo, a.hi, a.lanes)))
    steps = count_lane_steps(model, P, a.transient, a.duration)
    kern = kernels_for(model.kernel, "lyapunov")
    kernels = {"blocks": kern.lyapunov_lanes, "rows (main)": kern.lyapunov_lanes_rows}
    times = {name: [] for name in kernels}
    exponents = {}
    for rep in range(a.repeat + 1):  # the first round compiles / warms up
        for name, fn in kernels.items():
            kern.lyapunov_lanes = fn
            try:
                wall, cpu, lam, err = run(model, P, a.transient, a.duration)
            finally:
                kern.lyapunov_lanes = kernels["blocks"]
            exponents[name] = (lam, err)
            if rep:
                times[name].append((wall, cpu))
    print(f"paper device, reduced, {a.lanes} lanes Omega in [{a.lo}, {a.hi}], transient "
          f"{a.transient}, duration {a.duration}: {steps} lane-steps (k = 1: 3 rows each), "
          f"{a.threads} thread(s), median of {a.repeat}")
    for name, tt in times.items():
        wall = statistics.median(t[0] for t in tt)
        cpu = statistics.median(t[1] for t in tt)
        print(f"  {name:12s} wall {wall:8.4f} s  cpu {cpu:8.4f} s  "
              f"{wall * a.threads / steps * 1e9:7.1f} ns/lane-step/thread (wall)  "
              f"{cpu / steps * 1e9:7.1f} ns/lane-step (cpu)")
    # the same lanes without edge location (n_ev = 0): the cost of stepping alone
    args = kernel_args(model, P, a.transient, a.duration)
    plain = {name: [] for name in kernels}
    for rep in range(a.repeat + 1):
        for name, fn in kernels.items():
            wall, cpu = run_kernel(fn, args, 0)
            if rep:
                plain[name].append((wall, cpu))
    for name, tt in plain.items():
        wall = statistics.median(t[0] for t in tt)
        cpu = statistics.median(t[1] for t in tt)
        print(f"  {name:12s} no edge location: wall {wall:8.4f} s  "
              f"{wall * a.threads / steps * 1e9:7.1f} ns/lane-step/thread (wall)  "
              f"{cpu / steps * 1e9:7.1f} ns/lane-step (cpu)")
    (la, ea), (lb, eb) = exponents["blocks"], exponents["rows (main)"]
    same = np.array_equal(la, lb, equal_nan=True) and np.array_equal(ea, eb, equal_nan=True)
    print(f"  exponents and errors bitwise equal: {same}; finite {np.isfinite(la).sum()}/{la.size}")
    if a.write:
        tt = times["blocks"]
        wall = statistics.median(t[0] for t in tt)
        cpu = statistics.median(t[1] for t in tt)
        per = wall * a.threads / steps * 1e9
        results.record(
            "lyapunov", "Lyapunov kernel <= 30 ns per lane-step",
            f"{per:.1f} ns wall per lane-step per thread, {cpu / steps * 1e9:.1f} ns CPU "
            f"(median of {a.repeat}, {a.threads} threads); block and row kernels bitwise equal: "
            f"{same}", results.against(per, 30.0),
            f".venv/bin/python bench/lyapunov.py --repeat {a.repeat} --write")


if __name__ == "__main__":
    main()
