"""``make demo`` on a fresh clone: what a new user waits for, install and first compile included.

Clones this repository's committed HEAD into a temporary folder and runs ``make demo`` there with
an empty ``GEARDYN_CACHE_DIR`` (so every kernel compiles), timing the whole command (wall
seconds) and, inside it, the virtual environment's install (``make venv``, run first). Target
(issue 34): <= 90 s end to end.

    .venv/bin/python bench/demo.py [--repeat 1] [--write]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

TARGET = 90.0


def once() -> tuple[float, float]:
    """(install, install + demo) wall seconds of one fresh clone."""
    with tempfile.TemporaryDirectory(prefix="geardyn-demo-") as tmp:
        clone = Path(tmp) / "geardyn"
        subprocess.run(["git", "clone", "--quiet", str(HERE.parent), str(clone)], check=True)
        env = {k: v for k, v in os.environ.items()
               if k not in ("NUMBA_CACHE_DIR", "VIRTUAL_ENV", "PYTHONPATH")}
        env["GEARDYN_CACHE_DIR"] = str(Path(tmp) / "cache")
        t0 = time.perf_counter()
        subprocess.run(["make", "venv"], cwd=clone, env=env, check=True,
                       stdout=subprocess.DEVNULL)
        t1 = time.perf_counter()
        subprocess.run(["make", "demo"], cwd=clone, env=env, check=True,
                       stdout=subprocess.DEVNULL)
        t2 = time.perf_counter()
        for name in ("fig3.png", "fig3.nc", "fig3_omega1.1.png", "fig3_omega1.1.nc"):
            if not (clone / "out" / name).is_file():
                raise SystemExit(f"make demo did not write out/{name}")
    return t1 - t0, t2 - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--write", action="store_true", help="record in bench/RESULTS.md")
    args = ap.parse_args()
    runs = [once() for _ in range(args.repeat)]
    for install, total in runs:
        print(f"make demo, fresh clone: {total:.1f} s (install {install:.1f} s, "
              f"diagram and point with their first compile {total - install:.1f} s)")
    total = statistics.median(r[1] for r in runs)
    install = statistics.median(r[0] for r in runs)
    if args.write:
        from _results import against, record

        record("demo", f"`make demo` on a fresh clone, empty cache <= {TARGET:.0f} s",
               f"{total:.0f} s wall, median of {len(runs)} (install {install:.0f} s, diagram "
               f"and point with their first compile {total - install:.0f} s; 2 cores)",
               against(total, TARGET),
               f".venv/bin/python bench/demo.py --repeat {args.repeat} --write")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
