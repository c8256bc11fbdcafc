"""Benchmark of two-parameter maps (issue 5): throughput locally and on a Dask LocalCluster.

Workload: the paper's device (Tables 1-2, consistent interpretation), Omega in [0.5, 3.5] x
xi in [0.02, 0.2] (``--nx`` x ``--ny`` points), transient tau = 1000, 64 sampled periods, default
steps per period, ``--chunk`` points per task. Configurations, each the median of ``--repeat``
warm runs:

* ``local``: ``geardyn.map2d`` in this process (numba threads on every core);
* ``dask 1w x 1t``: a LocalCluster of 1 worker process, numba limited to 1 thread (one core);
* ``dask 2w x 1t``: 2 such workers (two cores);
* ``dask 1w x Nt``: 1 worker whose numba uses every core (the recommended layout: one worker
  per machine, parallel inside each task).

Reports lane-steps per second, the scaling efficiency of 2 workers against 1
(throughput_2 / (2 throughput_1)), and checks that every configuration gives bitwise the same
map. ``--write`` puts the table under the "map" heading of bench/RESULTS.md.

    .venv/bin/python bench/map.py [--nx 32] [--ny 8] [--chunk 32] [--repeat 3] [--write]
    .venv/bin/python bench/map.py --nx 500 --ny 500 --chunk 0 --repeat 1 --local-only

(``--chunk 0``: map2d's default chunk.)
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import statistics
import sys
import time
from pathlib import Path

import numpy as np

# geardyn (and numba) are imported inside the functions: Dask's spawned workers import this
# module as __mp_main__, and numba must not be loaded there before the worker's
# NUMBA_NUM_THREADS is set.
TRANSIENT = 1000.0
SAMPLES = 64
RESULTS = Path(__file__).with_name("RESULTS.md")


def lane_steps(ds) -> int:
    n = ds["steps_per_period"].values.astype(np.int64)
    return int(np.sum((ds["transient_periods"].values + ds.attrs["samples"]) * n))


def run_map(model, args, client=None, warm=False):
    import geardyn

    if warm:  # 8 one-point tasks: every worker compiles or loads its kernel
        return geardyn.map2d(model, x=("Omega", [0.5, 1.0, 2.0, 3.0]), y=("xi", [0.02, 0.2]),
                             run=geardyn.RunSettings(transient=20.0, samples=2), chunk=1,
                             client=client)
    return geardyn.map2d(model, x=("Omega", np.linspace(0.5, 3.5, args.nx)),
                         y=("xi", np.linspace(0.02, 0.2, args.ny)),
                         run=geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES),
                         chunk=args.chunk, client=client)


def timed(model, args, client=None):
    run_map(model, args, client, warm=True)
    times, ds = [], None
    for _ in range(args.repeat):
        t = time.perf_counter()
        ds = run_map(model, args, client)
        times.append(time.perf_counter() - t)
    return statistics.median(times), ds


def on_cluster(model, args, workers: int, numba_threads: int):
    from dask.distributed import Client, LocalCluster

    env = {"NUMBA_NUM_THREADS": str(numba_threads)}
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None, env=env) as cluster, Client(cluster) as client:
        threads = client.run(lambda: __import__("numba").get_num_threads())
        assert all(t == numba_threads for t in threads.values()), threads
        return timed(model, args, client)


def same(a, b) -> bool:
    return all(np.array_equal(a[n].values, b[n].values, equal_nan=a[n].dtype.kind == "f")
               for n in a.data_vars)


def write_results(text: str) -> None:
    old = RESULTS.read_text() if RESULTS.exists() else "# Benchmark results\n"
    section = "## map\n\n" + text.strip() + "\n"
    pattern = re.compile(r"^## map\n.*?(?=^## |\Z)", re.S | re.M)
    new = pattern.sub(lambda _: section + "\n", old) if pattern.search(old) else (
        old.rstrip() + "\n\n" + section)
    RESULTS.write_text(new.rstrip() + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=32)
    ap.add_argument("--ny", type=int, default=8)
    ap.add_argument("--chunk", type=int, default=32)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--write", action="store_true", help="update bench/RESULTS.md")
    ap.add_argument("--local-only", action="store_true",
                    help="only the local map (issue 11's 500 x 500 target), printed")
    args = ap.parse_args()
    import numba

    import geardyn

    cores = os.cpu_count() or 1
    model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    if args.local_only:
        t, ds = timed(model, args)
        steps = lane_steps(ds)
        bad = int(np.sum(ds["status"].values != 0))
        print(f"local map {args.nx} x {args.ny}: median {t:.1f} s of {args.repeat}, "
              f"{steps:.3e} lane-steps, {t / steps * 1e9:.1f} ns wall per lane-step, "
              f"{t * cores / steps * 1e9:.1f} ns per lane-step per thread ({cores} threads), "
              f"points not ok: {bad}; load average {os.getloadavg()[0]:.2f}")
        if args.write:
            import _results as results

            results.record(
                f"map-{args.nx}" if args.nx == args.ny else f"map-{args.nx}x{args.ny}",
                f"{args.nx} x {args.ny} map" + (" <= 120 s" if args.nx == args.ny == 500
                                                 else ""),
                f"{t:.1f} s (median of {args.repeat}; {steps:.3e} lane-steps, "
                f"{t * cores / steps * 1e9:.1f} ns per lane-step per thread; points not ok: "
                f"{bad})", results.against(t, 120.0) if args.nx == args.ny == 500 else "-",
                f".venv/bin/python bench/map.py --nx {args.nx} --ny {args.ny} --chunk "
                f"{args.chunk} --repeat {args.repeat} --local-only --write")
        return
    configs = [("local", None, None), ("dask 1w x 1t", 1, 1), ("dask 2w x 1t", 2, 1),
               (f"dask 1w x {cores}t", 1, cores)]
    rows, ref, steps = [], None, 0
    for name, workers, threads in configs:
        t, ds = timed(model, args) if workers is None else on_cluster(model, args, workers,
                                                                        threads)
        if ref is None:
            ref, steps = ds, lane_steps(ds)
        rows.append((name, t, steps / t, same(ref, ds)))
        print(f"{name:>14}: {t:7.3f} s  {steps / t:.3e} lane-steps/s  identical: "
              f"{rows[-1][3]}", flush=True)
    thr = {name: r for name, _, r, _ in rows}
    efficiency = thr["dask 2w x 1t"] / (2 * thr["dask 1w x 1t"])
    load = os.getloadavg()
    import geardyn

    simd = geardyn._jit_target.APPLIED.split(":")[0]
    lines = [
        f"Workload: paper device, Omega [0.5, 3.5] x xi [0.02, 0.2], {args.nx} x {args.ny} = "
        f"{args.nx * args.ny} points, transient tau = {TRANSIENT:g}, {SAMPLES} samples, default "
        f"steps per period, {args.chunk} points per task; {steps:.3e} lane-steps per map.",
        f"Machine: {platform.machine()}, {cores} cores, numba {numba.__version__}, Python "
        f"{sys.version.split()[0]}, SIMD {simd}; 1-min load average at the end {load[0]:.2f} "
        "(shared).",
        f"Command: `.venv/bin/python bench/map.py --nx {args.nx} --ny {args.ny} --chunk "
        f"{args.chunk} --repeat {args.repeat} --write` (median of {args.repeat} warm runs).",
        "",
        "| configuration | wall time [s] | lane-steps per second | bitwise equal to local |",
        "|---|---:|---:|---|",
    ]
    lines += [f"| {n} | {t:.3f} | {r:.3e} | {'yes' if s else 'NO'} |" for n, t, r, s in rows]
    lines += [
        "",
        f"Scaling efficiency, 2 workers against 1 (1 numba thread each): {efficiency:.2f}. "
        f"2 workers against local (all {cores} cores in one process): "
        f"{thr['dask 2w x 1t'] / thr['local']:.2f}; one worker using all cores against local: "
        f"{thr[f'dask 1w x {cores}t'] / thr['local']:.2f}.",
    ]
    text = "\n".join(lines)
    print(text)
    if args.write:
        write_results(text)
        print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
