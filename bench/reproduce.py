"""Wall and CPU time of the paper's whole study under every interpretation (issue 11's target).

Runs ``geardyn reproduce --all --interpretation all --quiet`` in a child process (warm kernel
cache: run it once first after a change to the kernels) and reports its wall time and the CPU
time of the process and its workers; ``--write`` records the figure in bench/RESULTS.md.

    .venv/bin/python bench/reproduce.py [--repeat 1] [--write]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import _results as results

TARGET = 90.0


def run_once() -> tuple[float, float]:
    """Wall and CPU seconds (children's user + system) of one reproduction."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "geardyn.cli.main", "reproduce", "--all",
                        "--interpretation", "all", "--quiet", "--out", out], check=True)
        wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--write", action="store_true",
                    help="record the figure in bench/RESULTS.md's current-figures table")
    args = ap.parse_args()
    runs = [run_once() for _ in range(args.repeat)]
    wall = statistics.median(w for w, _ in runs)
    cpu = statistics.median(c for _, c in runs)
    print(f"reproduce --all --interpretation all: {wall:.1f} s wall, {cpu:.1f} s CPU "
          f"(median of {args.repeat}; {os.cpu_count()} cores)")
    if args.write:
        results.record("reproduce", f"`geardyn reproduce --all --interpretation all` <= "
                       f"{TARGET:g} s", f"{wall:.1f} s wall, {cpu:.1f} s CPU (median of "
                       f"{args.repeat})", results.against(wall, TARGET),
                       f".venv/bin/python bench/reproduce.py --repeat {args.repeat} --write")


if __name__ == "__main__":
    main()
