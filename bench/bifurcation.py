"""Benchmark of the reference bifurcation workload (issue 3), and a work-precision table.

Workload: the paper's device (Tables 1-2, consistent interpretation), xi1 = xi2 = 0.05,
1000 values of Omega in [0.1, 4], transient tau >= 2000, 200 sampled periods, default steps per
period. Reports, in one run: warm wall time of ``geardyn.bifurcation`` (median of ``--repeat``),
lane-steps and ns per RK4 step per lane, the same without edge location, the located crossings
per lane-step (counted while sampling) and the time edge location adds per crossing, the same
work with ``scipy.integrate.solve_ivp`` (RK45, rtol 1e-6) measured on a few points and
extrapolated by simulated time, the ratio, and the agreement of the Poincare points with the
reference integrator (DOP853, rtol 1e-12, restarted at every edge crossing).

    .venv/bin/python bench/bifurcation.py [--repeat 3] [--points 1000] [--no-precision]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

import _results as results
import geardyn
from geardyn.solvers.ensemble import run_lanes
from geardyn.solvers.kernels import kernels_for
from geardyn.solvers.reference import reference_solution

TRANSIENT = 2000.0
SAMPLES = 200


def device() -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))


def lane_steps(ds) -> int:
    n = ds["steps_per_period"].values.astype(np.int64)
    return int(np.sum((ds["transient_periods"].values + ds.attrs["samples"]) * n))


def time_geardyn(model, values, repeat: int):
    geardyn.bifurcation(model, "Omega", values[:4],
                        run=geardyn.RunSettings(transient=20.0, samples=2))  # compile/load
    times = []
    ds = None
    for _ in range(repeat):
        t = time.perf_counter()
        ds = geardyn.bifurcation(model, "Omega", values,
                                 run=geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES))
        times.append(time.perf_counter() - t)
    return statistics.median(times), times, ds


def scipy_cost_per_time(model, omegas, span: float = 300.0) -> float:
    """Seconds of solve_ivp (RK45, rtol 1e-6) per unit of model time, median over ``omegas``."""
    k = kernels_for(model.kernel)
    costs = []
    for om in omegas:
        m = model.with_omega(om)
        p = np.ascontiguousarray(m.params)
        dy = np.empty(m.n_states)

        def f(t, y, p=p, om=om, dy=dy):
            k.rhs(t, y, dy, p, math.sin(om * t), math.cos(om * t))
            return dy.copy()

        t = time.perf_counter()
        solve_ivp(f, (0.0, span), m.initial_state(), method="RK45", rtol=1e-6, atol=1e-9)
        costs.append((time.perf_counter() - t) / span)
    return statistics.median(costs)


def simulated_time(ds) -> float:
    om = ds["Omega"].values
    return float(np.sum((ds["transient_periods"].values + SAMPLES) * 2 * np.pi / om))


def agreement(model, ds, omegas, periods: int = 20) -> float:
    """Largest deviation of geardyn's Poincare points from the reference integrator's, relative
    to the largest |X| of the point, over the first ``periods`` sampled periods (same start,
    same transient)."""
    worst = 0.0
    for om in omegas:
        i = int(np.argmin(np.abs(ds["Omega"].values - om)))
        om = float(ds["Omega"].values[i])
        T = 2 * np.pi / om
        n_tr = int(ds["transient_periods"].values[i])
        t_eval = (n_tr + np.arange(1, periods + 1)) * T
        ref = reference_solution(model.with_omega(om), model.initial_state(), t_eval)
        ours = ds["poincare"].values[i, :periods]
        scale = np.max(np.abs(ref[:, ::2]))
        worst = max(worst, float(np.max(np.abs(ours - ref)) / scale))
    return worst


def work_precision(model, omegas=(0.6, 1.1, 3.5), periods: int = 10, transient: float = 200.0):
    """Rows (method, setting, error, cost): error of the Poincare points over ``periods`` periods
    after ``transient`` against DOP853 at rtol 1e-13, cost in seconds per unit model time."""
    rows = []
    for om in omegas:
        m = model.with_omega(om)
        T = 2 * np.pi / om
        n_tr = math.ceil(transient / T)
        t_eval = (n_tr + np.arange(1, periods + 1)) * T
        y0 = m.initial_state()
        truth = reference_solution(m, y0, t_eval, rtol=1e-13, atol=1e-14)
        scale = np.max(np.abs(truth[:, ::2]))
        n0 = geardyn.default_steps_per_period(m)
        for factor in (0.5, 1.0, 2.0, 4.0):
            n = max(8, int(round(n0 * factor)))
            geardyn.simulate(m, run=geardyn.RunSettings(transient=T, samples=1,
                                                        steps_per_period=n))  # warm
            run = geardyn.RunSettings(transient=n_tr * T, samples=periods, steps_per_period=n)
            t = time.perf_counter()
            ds = geardyn.simulate(m, run=run, y0=y0, record_every=n)
            cost = (time.perf_counter() - t) / t_eval[-1]
            pts = np.stack([ds[s].values for s in m.state_names], axis=1)[1:]
            err = float(np.max(np.abs(pts - truth)) / scale)
            rows.append((om, "RK4 fixed (geardyn)", f"{n} steps/period ({factor:g}x default)",
                         err, cost))
        for rtol in (1e-6, 1e-8, 1e-10, 1e-12):
            t = time.perf_counter()
            ref = reference_solution(m, y0, t_eval, rtol=rtol, atol=rtol * 1e-2)
            cost = (time.perf_counter() - t) / t_eval[-1]
            err = float(np.max(np.abs(ref - truth)) / scale)
            rows.append((om, "DOP853 + event restarts", f"rtol {rtol:g}", err, cost))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--no-precision", action="store_true")
    ap.add_argument("--write", action="store_true",
                    help="record the figure in bench/RESULTS.md's current-figures table")
    args = ap.parse_args()
    model = device()
    values = np.linspace(0.1, 4.0, args.points)
    import numba

    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, "
          f"{numba.config.NUMBA_NUM_THREADS} threads, {platform.processor() or platform.machine()}"
          f", {os.cpu_count()} cpus; SIMD {geardyn._jit_target.APPLIED.split(':')[0]}")
    wall, times, ds = time_geardyn(model, values, args.repeat)
    steps = lane_steps(ds)
    threads = numba.config.NUMBA_NUM_THREADS
    print(f"reference workload: {args.points} Omega in [0.1, 4], transient {TRANSIENT:g}, "
          f"{SAMPLES} periods, default steps/period")
    print(f"geardyn warm wall time: median {wall:.2f} s of {[round(x, 2) for x in times]}")
    print(f"lane-steps: {steps:.3e}; {wall / steps * 1e9:.1f} ns wall per lane-step, "
          f"{wall * threads / steps * 1e9:.1f} ns per lane-step per thread")
    print(f"periods classified: {np.bincount(np.clip(ds['period'].values + 1, 0, 18))}")
    t_off = []
    for _ in range(args.repeat):
        t = time.perf_counter()
        geardyn.bifurcation(model, "Omega", values, run=geardyn.RunSettings(
            transient=TRANSIENT, samples=SAMPLES, locate_edges=False))
        t_off.append(time.perf_counter() - t)
    wall_off = statistics.median(t_off)
    # the located crossings are counted while sampling only: their rate over the sampled
    # lane-steps, and the time edge location adds per crossing at that rate over every lane-step
    r = run_lanes(model, model.lane_params("Omega", values), model.initial_state(),
                  run=geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES))
    sampled = int(np.sum(r.steps_per_period.astype(np.int64) * r.sample_every * SAMPLES))
    rate = float(r.crossings.sum()) / sampled
    extra = (wall - wall_off) * threads / (rate * steps) * 1e9
    print(f"edge location off: median {wall_off:.2f} s ({wall_off * threads / steps * 1e9:.1f} "
          f"ns per lane-step per thread); located crossings while sampling: {rate:.4f} per "
          f"lane-step, so ~{rate * steps:.2e} in the run, {extra:.0f} ns of thread time each "
          f"(the time edge location adds / those crossings)")
    sim_time = simulated_time(ds)
    per_time = scipy_cost_per_time(model, [0.3, 1.1, 2.5])
    scipy_total = per_time * sim_time
    print(f"scipy RK45 rtol 1e-6: {per_time * 1e3:.3f} ms per unit time, extrapolated to "
          f"{sim_time:.3e} time units: {scipy_total:.0f} s; ratio {scipy_total / wall:.0f}x")
    err = agreement(model, ds, [0.35, 1.1, 3.5])
    print(f"Poincare points vs DOP853 rtol 1e-12 (3 points, 20 periods): max rel. error {err:.2e}")
    if args.write:
        results.record(
            "paper-workload", "paper reference workload (1000 Omega, transient 2000, 200 "
            "periods) <= 0.3 s",
            f"{wall:.2f} s wall, median of {args.repeat} ({wall * threads / steps * 1e9:.1f} ns "
            f"per lane-step per thread; {wall_off:.2f} s without edge location; Poincare points "
            f"{err:.1e} from DOP853; SciPy RK45 {scipy_total / wall:.0f}x slower)",
            results.against(wall, 0.3),
            f".venv/bin/python bench/bifurcation.py --repeat {args.repeat} --no-precision --write")
    if not args.no_precision:
        print("\n| Omega | method | setting | max rel. error | cost [ms per unit time] |")
        print("|---|---|---|---|---|")
        for om, method, setting, e, c in work_precision(model):
            print(f"| {om:g} | {method} | {setting} | {e:.1e} | {c * 1e3:.3f} |")


if __name__ == "__main__":
    main()
