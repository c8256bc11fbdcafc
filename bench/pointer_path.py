"""The pointer kernel path of a one-form user model: its own compile and its sweep's speed.

Compile (``--compile``): fresh processes on an empty temporary ``GEARDYN_CACHE_DIR``, each timing
in process CPU seconds the first ``simulate`` and ``bifurcation`` of the gear pair written as a
one-form user model (examples/gear_pair_model.py):

1. a ``GearPair`` primer (the shared modules, compiled once for every model);
2. the user model on the pointer path (``kernel_path="pointer"``): the pointer kernels, compiled
   once for every pointer model, and its own part;
3. a second pointer model (the same equations, from a copy of the example module: another
   model to numba and geardyn): its own compile alone;
4. that second model on the inlined path (``kernel_path="lane-form"``) on another cache
   primed the same way: today's own compile, for comparison.

Speed (``--speed``): bench/user_model.py's sweep (400 Omega, 128 steps per period, edges
located) of ``GearPair``, the one form inlined and on the pointer path, on one thread, CPU
seconds per lane-step (median of ``--repeat``, the rows alternating), and whether the points
are bitwise ``GearPair``'s.

    .venv/bin/python bench/pointer_path.py [--compile] [--speed] [--repeat 7]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"

_CHILD = r"""
import importlib, json, sys, time
t0 = time.process_time()
sys.path[:0] = sys.argv[1].split(":")
import numpy as np
import geardyn
module, path = sys.argv[2], sys.argv[3]
if module == "GearPair":
    model = geardyn.GearPair(Omega=1.3, kappa=0.2, Fa=0.2)
else:
    model = importlib.import_module(module).gear_pair(Omega=1.3, kappa=0.2, Fa=0.2,
                                                      kernel_path=path)
rows = {"import": time.process_time() - t0}
run = geardyn.RunSettings(transient=0.0, samples=2)
for name, fn in (("simulate", lambda: geardyn.simulate(model, y0=np.zeros(2), run=run)),
                 ("sweep", lambda: geardyn.bifurcation(model, "Omega", np.array([1.3, 1.4]),
                                                       run=run))):
    c = time.process_time()
    fn()
    rows[name] = time.process_time() - c
print(json.dumps(rows))
"""


def _child(cache: str, paths: str, module: str, path: str) -> dict:
    env = dict(os.environ, GEARDYN_CACHE_DIR=cache, GEARDYN_COMPILE_AHEAD="0")
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, "-c", _CHILD, paths, module, path], env=env,
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fmt(rows: dict) -> str:
    own = rows["simulate"] + rows["sweep"]
    return f"simulate {rows['simulate']:.1f} + sweep {rows['sweep']:.1f} = {own:.1f} s CPU"


def compile_figures() -> None:
    with tempfile.TemporaryDirectory(prefix="geardyn-pointer-") as tmp:
        copy = Path(tmp) / "src"
        copy.mkdir()
        shutil.copy(EXAMPLES / "gear_pair_model.py", copy / "gear_pair_copy.py")
        paths = f"{EXAMPLES}:{copy}"
        for label, cache in (("pointer", Path(tmp) / "a"), ("inlined", Path(tmp) / "b")):
            cache.mkdir()
            _child(str(cache), paths, "GearPair", "")
            if label == "pointer":
                first = _child(str(cache), paths, "gear_pair_model", "pointer")
                print(f"first pointer model (pointer kernels + its part): {_fmt(first)}")
                own = _child(str(cache), paths, "gear_pair_copy", "pointer")
                print(f"second pointer model, its own compile: {_fmt(own)}")
            else:
                own = _child(str(cache), paths, "gear_pair_copy", "lane-form")
                print(f"the same model inlined (lane-form), its own compile: {_fmt(own)}")


def speed_figures(repeat: int) -> None:
    import numba

    numba.set_num_threads(1)
    import numpy as np

    import geardyn
    from geardyn.solvers.ensemble import run_lanes

    sys.path.insert(0, str(EXAMPLES))
    from gear_pair_model import gear_pair

    coeffs = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    models = {"GearPair": geardyn.GearPair(**coeffs), "one form inlined": gear_pair(**coeffs),
              "one form, pointer path": gear_pair(**coeffs, kernel_path="pointer")}
    omegas = np.linspace(0.2, 3.0, 400)
    run = geardyn.RunSettings(transient=500.0 * math.pi, samples=100, steps_per_period=128)

    def sweep(m):
        return run_lanes(m, m.lane_params("Omega", omegas), m.initial_state(), run=run)

    first = {name: sweep(m) for name, m in models.items()}
    cpu: dict[str, list[float]] = {name: [] for name in models}
    for _ in range(repeat):
        for name, m in models.items():
            c = time.process_time()
            sweep(m)
            cpu[name].append(time.process_time() - c)
    ref = first["GearPair"]
    base = None
    for name in models:
        per = statistics.median(cpu[name]) / float(np.sum(first[name].steps)) * 1e9
        base = base or per
        same = np.array_equal(first[name].samples, ref.samples, equal_nan=True)
        print(f"{name:24s} {per:6.2f} ns CPU per lane-step (one thread)  {per / base:5.3f}x  "
              f"points bitwise GearPair's: {same}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--compile", action="store_true")
    ap.add_argument("--speed", action="store_true")
    ap.add_argument("--repeat", type=int, default=7)
    a = ap.parse_args(argv)
    if not (a.compile or a.speed):
        a.compile = a.speed = True
    if a.speed:
        speed_figures(a.repeat)
    if a.compile:
        compile_figures()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
