"""The pointer kernel path of a one-form user model: its own compile and its sweep's speed.

Compile (``--compile``): fresh processes on an empty temporary ``GEARDYN_CACHE_DIR``, each timing
in process CPU seconds the first ``simulate`` and ``bifurcation`` (``--analyses all``: every
analysis of bench/compile.py, Lyapunov, its lane blocks, the periodic orbit and continuation
too) of the gear pair written as a one-form user model (examples/gear_pair_model.py), with the
compile CPU seconds of each analysis by module (numba's compile events, exclusive):

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

Lyapunov speed (``--lyapunov``): ``lyapunov_lanes`` (the variational lane blocks, k = 1, as
``bifurcation(..., lyapunov=True)`` runs them) of the same three on 64 Omega in [0.2, 3.0], 128
steps per period, edges located, 100 time units of transient and 400 measured, one thread: CPU
seconds per lane-step (one grid step of one lane with its tangent vector; the steps of the whole
forcing periods the transient and the window cover), median of ``--repeat``, the rows
alternating, and whether the exponents are bitwise ``GearPair``'s.

    .venv/bin/python bench/pointer_path.py [--compile [--analyses all]] [--speed] [--lyapunov]
        [--repeat 7]
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
import importlib, importlib.util, json, re, sys, time
t0 = time.process_time()
sys.path[:0] = sys.argv[1].split(":")
import numpy as np
import numba.core.event as ev
import geardyn
spec = importlib.util.spec_from_file_location("bench_compile", sys.argv[5])
cb = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cb)
module, path, analyses = sys.argv[2], sys.argv[3], sys.argv[4].split(",")
if module == "GearPair":
    model = geardyn.GearPair(Omega=1.3, kappa=0.2, Fa=0.2)
else:
    model = importlib.import_module(module).gear_pair(Omega=1.3, kappa=0.2, Fa=0.2,
                                                      kernel_path=path)


def by_module(buffer):
    # exclusive compile CPU seconds by module (a generated module's digest dropped)
    stack, out = [], {}
    for ts, event in buffer:
        if event.is_start:
            stack.append([ts, 0.0])
            continue
        t, inner = stack.pop()
        py = getattr(event.data["dispatcher"], "py_func", None)
        name = re.sub(r"_[0-9a-f]{12,}$", "", getattr(py, "__module__", None) or "?")
        out[name] = out.get(name, 0.0) + (ts - t) - inner
        if stack:
            stack[-1][1] += ts - t
    return out


rows = {"import": [time.process_time() - t0, {}]}
runs = cb._runs(model, np.zeros(2))
for name in analyses:
    rec = cb._CpuRecorder()
    ev.register("numba:compile", rec)
    c = time.process_time()
    try:
        runs[name]()
    finally:
        ev.unregister("numba:compile", rec)
    rows[name] = [time.process_time() - c, by_module(rec.buffer)]
print(json.dumps(rows))
"""

#: The analyses of ``--analyses all`` (bench/compile.py's, in its order).
ALL = ("simulate", "sweep", "lyapunov", "lanes", "orbit", "continuation")


def _child(cache: str, paths: str, module: str, path: str, analyses: tuple) -> dict:
    env = dict(os.environ, GEARDYN_CACHE_DIR=cache, GEARDYN_COMPILE_AHEAD="0")
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, "-c", _CHILD, paths, module, path, ",".join(analyses),
                          str(HERE / "compile.py")], env=env, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{module} ({path or 'built-in'}) failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fmt(rows: dict) -> str:
    names = [k for k in rows if k != "import"]
    own = sum(rows[k][0] for k in names)
    text = " + ".join(f"{k} {rows[k][0]:.1f}" for k in names) + f" = {own:.1f} s CPU"
    four = [k for k in ("simulate", "sweep", "lyapunov", "continuation") if k in rows]
    if len(four) == 4 and len(names) > 4:
        text += f" (simulate + sweep + lyapunov + continuation {sum(rows[k][0] for k in four):.1f})"
    for k in names:
        mods = sorted(rows[k][1].items(), key=lambda kv: -kv[1])
        text += f"\n    {k}: " + (", ".join(f"{m} {t:.1f}" for m, t in mods[:4] if t >= 0.05)
                                  or "nothing compiled")
    return text


def compile_figures(analyses: tuple) -> None:
    with tempfile.TemporaryDirectory(prefix="geardyn-pointer-") as tmp:
        copy = Path(tmp) / "src"
        copy.mkdir()
        shutil.copy(EXAMPLES / "gear_pair_model.py", copy / "gear_pair_copy.py")
        paths = f"{EXAMPLES}:{copy}"
        for label, cache in (("pointer", Path(tmp) / "a"), ("inlined", Path(tmp) / "b")):
            cache.mkdir()
            _child(str(cache), paths, "GearPair", "", analyses)
            if label == "pointer":
                first = _child(str(cache), paths, "gear_pair_model", "pointer", analyses)
                print(f"first pointer model (pointer kernels + its part): {_fmt(first)}")
                own = _child(str(cache), paths, "gear_pair_copy", "pointer", analyses)
                print(f"second pointer model, its own compile: {_fmt(own)}")
            else:
                own = _child(str(cache), paths, "gear_pair_copy", "lane-form", analyses)
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
    models = {"GearPair": geardyn.GearPair(**coeffs),
              "one form inlined": gear_pair(**coeffs, kernel_path="lane-form"),
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


def lyapunov_figures(repeat: int) -> None:
    import numba

    numba.set_num_threads(1)
    import numpy as np

    import geardyn
    from geardyn.core.plan import forcing_period, periods_covering

    sys.path.insert(0, str(EXAMPLES))
    from gear_pair_model import gear_pair

    coeffs = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    models = {"GearPair": geardyn.GearPair(**coeffs),
              "one form inlined": gear_pair(**coeffs, kernel_path="lane-form"),
              "one form, pointer path": gear_pair(**coeffs, kernel_path="pointer")}
    omegas = np.linspace(0.2, 3.0, 64)
    transient, duration, n_per = 100.0, 400.0, 128
    run = geardyn.RunSettings(transient=transient, steps_per_period=n_per)
    ls = geardyn.LyapunovSettings(duration=duration)
    steps = sum((periods_covering(transient, T) + max(1, periods_covering(duration, T))) * n_per
                for T in forcing_period(omegas))

    def exponents(m):
        return geardyn.lyapunov_lanes(m, m.lane_params("Omega", omegas), run=run, settings=ls)

    first = {name: exponents(m) for name, m in models.items()}
    cpu: dict[str, list[float]] = {name: [] for name in models}
    for _ in range(repeat):
        for name, m in models.items():
            c = time.process_time()
            exponents(m)
            cpu[name].append(time.process_time() - c)
    base = None
    for name in models:
        per = statistics.median(cpu[name]) / steps * 1e9
        base = base or per
        same = np.array_equal(first[name], first["GearPair"], equal_nan=True)
        print(f"{name:24s} {per:6.2f} ns CPU per lane-step (one thread, lyapunov_lanes)  "
              f"{per / base:5.3f}x  exponents bitwise GearPair's: {same}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--compile", action="store_true")
    ap.add_argument("--speed", action="store_true")
    ap.add_argument("--lyapunov", action="store_true")
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--analyses", default="simulate,sweep",
                    help="with --compile: the analyses timed (comma-separated, or all)")
    a = ap.parse_args(argv)
    if not (a.compile or a.speed or a.lyapunov):
        a.compile = a.speed = a.lyapunov = True
    if a.speed:
        speed_figures(a.repeat)
    if a.lyapunov:
        lyapunov_figures(a.repeat)
    if a.compile:
        compile_figures(ALL if a.analyses == "all" else tuple(a.analyses.split(",")))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
