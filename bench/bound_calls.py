"""Bound calls (``geardyn._bound_calls``) against linked callees: cold compile CPU and machine code.

For each model (a conformance case) two fresh processes, each on an empty private cache, run
``bench/compile_phases.py``'s analyses: one with ``GEARDYN_BIND=0`` (every callee's optimised
IR linked into each caller, numba's way), one with the binding on. Printed: each process's
CPU seconds of the compile and their ratio; with ``--asm``, the machine code compared function
by function as numba's engine emitted it (``compile_phases.py --asm-emitted``, symbol names
left out): every function's code with binding must be code the linked build emitted for it
(in one of the callers it was linked into).

    PYTHONPATH=src python bench/bound_calls.py [--models GearPair ...] [--order ba] [--asm]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def run(case: str, bind: str, asm: Path | None) -> float:
    """CPU seconds of ``case``'s cold compile with ``GEARDYN_BIND=bind``; with ``asm``, the
    digests of the emitted machine code written there (the compile then takes longer)."""
    with tempfile.TemporaryDirectory(prefix="gdc_bound_") as cache:
        env = dict(os.environ, GEARDYN_CACHE_DIR=cache, GEARDYN_BIND=bind,
                   GEARDYN_COMPILE_AHEAD="0")
        env.pop("NUMBA_CACHE_DIR", None)
        extra = [] if asm is None else ["--asm-emitted", str(asm)]
        out = subprocess.run([sys.executable, str(HERE / "compile_phases.py"), case, "--top", "0",
                              *extra], env=env, check=True, capture_output=True, text=True).stdout
    m = re.search(r": ([0-9.]+) s CPU in all; per analysis: (.*)", out)
    print(f"  {case} GEARDYN_BIND={bind}: {m.group(1)} s CPU ({m.group(2)})", flush=True)
    return float(m.group(1))


def compare(a: dict, b: dict) -> tuple[int, list, list]:
    """Machine code per function (name without geardyn's numbering): (functions whose code with
    binding is one the linked build emitted too, those with other code, those the linked build
    emitted and the bound one did not)."""
    same = sum(1 for k in b if k in a and set(b[k]) <= set(a[k]))
    other = sorted(k for k in b if k not in a or not set(b[k]) <= set(a[k]))
    missing = sorted(k for k in a if k not in b)
    return same, other, missing


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--models", nargs="*", default=["GearPair", "PlanetaryGearSet"])
    ap.add_argument("--order", choices=("ab", "ba"), default="ab",
                    help="which process runs first: a (linked) or b (bound)")
    ap.add_argument("--asm", action="store_true",
                    help="compare the emitted machine code (the CPU figures then include it)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bound_asm_") as tmp:
        for case in args.models:
            paths = {k: Path(tmp) / f"{case}_{k}.json" if args.asm else None for k in "ab"}
            cpu = {k: run(case, "0" if k == "a" else "1", paths[k]) for k in args.order}
            line = (f"{case}: linked {cpu['a']:.1f} s, bound {cpu['b']:.1f} s CPU "
                    f"(bound / linked {cpu['b'] / cpu['a']:.3f})")
            if args.asm:
                a, b = (json.loads(paths[k].read_text()) for k in "ab")
                same, other, missing = compare(a, b)
                line += (f"; machine code: {same} functions as linked, {len(other)} other, "
                         f"{len(missing)} emitted only linked")
                print(line)
                for key in other:
                    print(f"  other code: {key[:120]}")
                for key in missing:
                    print(f"  only linked: {key[:120]}")
            else:
                print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
