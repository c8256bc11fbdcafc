"""The paper workload (bench/bifurcation.py's), two source trees against each other in one run:
CPU time of one thread, the trees' calls alternating, and whether their results are bitwise
the same.

Each tree runs in a process of its own (``PYTHONPATH`` on its ``src``, its own kernel cache),
warmed up once, then told to run the workload ``--repeat`` times in turn with the other (A, B,
A, B, ...); each run's CPU time is the process's ``time.process_time`` around
``geardyn.bifurcation`` (one numba thread, so that other processes on a shared machine count
as little as possible). Printed: the medians, their ratio B / A, the load average, and a hash
of every data variable of each tree's dataset (the same hash: bitwise the same results).

    .venv/bin/python bench/ab_paper.py --a /tmp/main_tree --a-cache /tmp/cache_a \\
        [--b .] [--b-cache DIR] [--repeat 7] [--points 1000] [--no-edges]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

WORKER = r"""
import hashlib, json, sys, time
sys.path.insert(0, {bench!r})
import numba
import numpy as np
import geardyn
from bifurcation import SAMPLES, TRANSIENT, device
numba.set_num_threads(1)
model = device()
values = np.linspace(0.1, 4.0, {points})
run = geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES, locate_edges={edges})
geardyn.bifurcation(model, "Omega", values[:4],
                    run=geardyn.RunSettings(transient=20.0, samples=2))
print(json.dumps({{"ready": True}}), flush=True)
for line in sys.stdin:
    if line.strip() != "run":
        break
    t0 = time.process_time()
    ds = geardyn.bifurcation(model, "Omega", values, run=run)
    t = time.process_time() - t0
    h = hashlib.sha256()
    for name in sorted(ds.data_vars):
        h.update(name.encode())
        h.update(np.ascontiguousarray(ds[name].values).tobytes())
    print(json.dumps({{"cpu": t, "hash": h.hexdigest()[:16]}}), flush=True)
"""


def start(tree: Path, cache: str | None, points: int, edges: bool) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(tree / "src"), NUMBA_NUM_THREADS="1")
    if cache:
        env["GEARDYN_CACHE_DIR"] = cache
    code = WORKER.format(bench=str(HERE), points=points, edges=edges)
    proc = subprocess.Popen([sys.executable, "-c", code], env=env, cwd=tree, text=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    return proc


def ask(proc: subprocess.Popen) -> dict:
    proc.stdin.write("run\n")
    proc.stdin.flush()
    return json.loads(proc.stdout.readline())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--a", required=True, help="tree A (e.g. a worktree of main)")
    ap.add_argument("--a-cache", default=None, help="tree A's GEARDYN_CACHE_DIR")
    ap.add_argument("--b", default=str(HERE.parent), help="tree B (default: this one)")
    ap.add_argument("--b-cache", default=None, help="tree B's GEARDYN_CACHE_DIR")
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--no-edges", action="store_true")
    args = ap.parse_args()
    edges = not args.no_edges
    procs = {"A": start(Path(args.a), args.a_cache, args.points, edges),
             "B": start(Path(args.b), args.b_cache, args.points, edges)}
    for p in procs.values():  # warmed up (and compiled, where a cache is cold)
        assert json.loads(p.stdout.readline())["ready"]
    load0 = os.getloadavg()
    times = {"A": [], "B": []}
    hashes = {"A": set(), "B": set()}
    for _ in range(args.repeat):
        for side in ("A", "B"):
            r = ask(procs[side])
            times[side].append(r["cpu"])
            hashes[side].add(r["hash"])
    load1 = os.getloadavg()
    for p in procs.values():
        p.stdin.close()
        p.wait()
    ma, mb = statistics.median(times["A"]), statistics.median(times["B"])
    print(f"paper workload ({args.points} points, edges {'on' if edges else 'off'}), "
          f"CPU s of one thread, median of {args.repeat}, alternating")
    for side in ("A", "B"):
        print(f"  {side}: {statistics.median(times[side]):.3f} s "
              f"({', '.join(f'{t:.3f}' for t in times[side])}); result hash "
              f"{', '.join(sorted(hashes[side]))}")
    print(f"  B / A = {mb / ma:.3f}; results bitwise the same: {hashes['A'] == hashes['B']}")
    print(f"  load average {load0[0]:.2f} at the start, {load1[0]:.2f} at the end")


if __name__ == "__main__":
    main()
