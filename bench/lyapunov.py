"""Lyapunov kernel benchmark: the variational tangent against the difference rows, in one run.

Workload: the paper's device (Tables 1-2, consistent interpretation, reduced model (written in the
one form), xi1 = xi2 = 0.05), ``--lanes`` values of Omega in [``--lo``, ``--hi``], the largest
exponent (k = 1, as ``bifurcation(..., lyapunov=True)`` computes it) over ``--transient`` +
``--duration`` time units at the default steps per period, with edge location, through
``geardyn.lyapunov_lanes`` (the lane blocks) with ``LyapunovSettings(tangent=...)``: ``variational``
(the state and its tangent vector stepped together, J v from dual numbers through the one form; a
step split at an edge with the tangent through its sub-steps, corrected at each split point) and
``difference`` (per lane the state and two perturbed rows, central differences of the step map),
alternately, in this process. Reports per method: warm wall time and CPU time (medians of
``--repeat``), ns per lane-step per thread (one lane-step: one grid step of one lane with its
tangent vector; wall time x threads / lane-steps, and CPU time / lane-steps), the ratio of the two,
the largest difference of the exponents (relative to their error), the CPU time of each without edge
location (``n_ev = 0``: the stepping alone; the difference rows then run the row blocks) and whether
the variational blocks are bitwise the one-lane-at-a-time rows (``tests/_lyapunov_rows.py``).

    .venv/bin/python bench/lyapunov.py [--repeat 3] [--lanes 42] [--threads N]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np

import geardyn
from geardyn.analysis.lyapunov import lyapunov_lanes
from geardyn.core.plan import forcing_period, lane_steps, periods_covering
from geardyn.solvers.kernels import kernels_for

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import _results as results  # noqa: E402
from _lyapunov_rows import rows_for  # noqa: E402


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


def run_kernel(fn, args, variational: bool) -> float:
    """CPU time of one call of the kernel's ``lyapunov_lanes`` without edge location."""
    L = args[0].shape[0]
    out, err = np.full(L, np.nan), np.full(L, np.nan)
    t_cpu = time.process_time()
    fn(*args, 10, 1e6, out, err, 0, 16, None, None, variational)
    return time.process_time() - t_cpu


def run(model, P, transient, duration, tangent):
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    lam, err = lyapunov_lanes(model, P, run=geardyn.RunSettings(transient=transient),
                              settings=geardyn.LyapunovSettings(duration=duration,
                                                                tangent=tangent),
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
    methods = ("variational", "difference")
    times = {name: [] for name in methods}
    exponents = {}
    for rep in range(a.repeat + 1):  # the first round compiles / warms up
        for name in methods:
            wall, cpu, lam, err = run(model, P, a.transient, a.duration, name)
            exponents[name] = (lam, err)
            if rep:
                times[name].append((wall, cpu))
    print(f"paper device, reduced, one form, {a.lanes} lanes Omega in [{a.lo}, {a.hi}], "
          f"transient {a.transient}, duration {a.duration}: {steps} lane-steps (k = 1), "
          f"{a.threads} thread(s), median of {a.repeat}")
    per = {}
    for name, tt in times.items():
        wall = statistics.median(t[0] for t in tt)
        cpu = statistics.median(t[1] for t in tt)
        per[name] = (wall * a.threads / steps * 1e9, cpu / steps * 1e9)
        print(f"  {name:12s} wall {wall:8.4f} s  cpu {cpu:8.4f} s  "
              f"{per[name][0]:7.1f} ns/lane-step/thread (wall)  "
              f"{per[name][1]:7.1f} ns/lane-step (cpu)")
    ratio_wall = per["difference"][0] / per["variational"][0]
    ratio_cpu = per["difference"][1] / per["variational"][1]
    print(f"  difference / variational: {ratio_wall:.2f}x (wall), {ratio_cpu:.2f}x (cpu)")
    (lv, ev), (lf, ef) = exponents["variational"], exponents["difference"]
    ok = np.isfinite(lv) & np.isfinite(lf)
    gap = np.abs(lv - lf)[ok]
    rel = (gap / np.maximum(np.maximum(ev, ef)[ok], 1e-300)) if ok.any() else gap
    print(f"  exponents: finite {ok.sum()}/{lv.size}; max |variational - difference| "
          f"{gap.max() if gap.size else np.nan:.3g} ({rel.max() if rel.size else np.nan:.3g} "
          f"standard errors)")
    kern = kernels_for(model.kernel, "lyapunov")
    # the same lanes without edge location (n_ev = 0): the cost of stepping alone (the
    # difference rows then run the row blocks, not the fused loop, which needs the events)
    args = kernel_args(model, P, a.transient, a.duration)
    plain = {name: [] for name in methods}
    for rep in range(a.repeat + 1):
        for name in methods:
            cpu = run_kernel(kern.lyapunov_lanes, args, name == "variational")
            if rep:
                plain[name].append(cpu)
    for name, tt in plain.items():
        print(f"  {name:12s} no edge location: {statistics.median(tt) / steps * 1e9:7.1f} "
              f"ns/lane-step (cpu)")
    blocks = kern.lyapunov_lanes
    kern.lyapunov_lanes = rows_for(kern)
    try:
        _, _, lr, er = run(model, P, a.transient, a.duration, "variational")
    finally:
        kern.lyapunov_lanes = blocks
    same = np.array_equal(lv, lr, equal_nan=True) and np.array_equal(ev, er, equal_nan=True)
    print(f"  variational blocks and rows bitwise equal: {same}")
    if a.write:
        wall_ns, cpu_ns = per["variational"]
        results.record(
            "lyapunov", "Lyapunov kernel <= 30 ns per lane-step",
            f"{wall_ns:.1f} ns wall per lane-step per thread, {cpu_ns:.1f} ns CPU, variational "
            f"tangent, one-form reduced device (median of {a.repeat}, {a.threads} threads; "
            f"difference rows {ratio_cpu:.2f}x the CPU); blocks and rows bitwise equal: {same}",
            results.against(wall_ns, 30.0),
            f".venv/bin/python bench/lyapunov.py --repeat {a.repeat} --write")


if __name__ == "__main__":
    main()
