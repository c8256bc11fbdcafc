"""Compile-time benchmark: what a model's first use of each analysis costs with an empty cache.

For each model (the conformance cases of ``tests/conformance_cases.py``: the reduced and general
CATT device, the dimensional device, the gear pair, the small user model, the planetary set) a
fresh Python process with an empty temporary ``GEARDYN_CACHE_DIR`` (numba's cache in it) runs,
one after the other on a tiny workload, the first call of each analysis: ``simulate``,
``bifurcation`` (the sweep kernel), ``lyapunov`` (one lane), ``lyapunov_lanes`` (the lane
blocks of ``bifurcation(..., lyapunov=True)``), ``periodic_orbit`` (the monodromy kernel) and
``continuation`` (a few points), each timed in process CPU seconds (all threads) and wall
seconds. A second process on the same, now filled, cache runs them again (loaded, not
compiled). An analysis's figure is what it compiles beyond those before it (shared functions
compile once). numba's compile events give the functions that dominate: the exclusive time of
each compiled function (its own compile, those it compiles in turn subtracted), summed by name.
The split step is not compiled ahead in a helper process here (``GEARDYN_COMPILE_AHEAD=0``), so
that the process's CPU seconds are the whole compile.

    .venv/bin/python bench/compile.py [--models GearPair UserModel] [--primer GearPair] [--top 8]
                                      [--json F] [--write]

``--primer CASE`` runs that case first on each empty cache, so that a model's figure is its own
compile with what every model shares already cached: with ``GearPair`` the shared modules;
with ``Duffing-one-form`` (a one-form user model on the pointer path, the default of
``UserModel.from_one_form``: the Duffing oscillator of examples/duffing_model.py, another model
than the conformance case) also the pointer path's kernels, compiled once for every pointer
model, so that ``UserModel-one-form``'s figure is its own compile (the row
``compile-UserModel-one-form-own``); primed by ``GearPair`` it is the first pointer model's,
the pointer kernels included.

``--write`` replaces the ``compile-*`` rows of bench/RESULTS.md's current-figures table
(``--from-json F``: those of an earlier run's ``--json F``, without measuring again). Cold
compiles on a shared machine are noisy: CPU seconds are the steadier figure.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numba.core.event as ev

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

#: The analyses, in the order a child runs them.
ANALYSES = ("simulate", "sweep", "lyapunov", "lanes", "orbit", "continuation")
#: Every built-in model's target (simulate + sweep + Lyapunov + continuation), and a user
#: model's, CPU seconds (issue 34).
TARGET_BUILTIN = 30.0
TARGET_USER = 15.0


def _runs(model, y0):
    import numpy as np

    import geardyn

    omega = float(model.params[model.omega_index])
    values = np.array([omega, 1.05 * omega])
    return {
        "simulate": lambda: geardyn.simulate(model, omega=omega, y0=y0,
                                             run=geardyn.RunSettings(transient=0.0, samples=2)),
        "sweep": lambda: geardyn.bifurcation(model, "Omega", values,
                                             run=geardyn.RunSettings(transient=0.0, samples=2)),
        "lyapunov": lambda: geardyn.lyapunov(model, y0=y0, run=geardyn.RunSettings(transient=0.0),
                                             settings=geardyn.LyapunovSettings(duration=1.0)),
        "lanes": lambda: geardyn.lyapunov_lanes(model, model.lane_params("Omega", values),
                                                run=geardyn.RunSettings(transient=0.0),
                                                settings=geardyn.LyapunovSettings(duration=1.0)),
        "orbit": lambda: geardyn.periodic_orbit(model, omega=omega, guess=y0,
                                                settings=geardyn.NewtonSettings(max_iter=1)),
        "continuation": lambda: geardyn.continuation(
            model, "Omega", omega, 1.02 * omega, guess=y0,
            settings=geardyn.ContinuationSettings(max_points=3)),
    }


class _CpuRecorder(ev.Listener):
    """numba's ``numba:compile`` events with the process CPU clock (all threads) at each."""

    def __init__(self) -> None:
        self.buffer: list[tuple[float, ev.Event]] = []

    def on_start(self, event: ev.Event) -> None:
        self.buffer.append((time.process_time(), event))

    def on_end(self, event: ev.Event) -> None:
        self.buffer.append((time.process_time(), event))


def _exclusive(buffer) -> dict[str, list]:
    """Exclusive compile CPU seconds and compiles per function name: each compile's time less
    that of the compiles it started (its callees)."""
    stack: list[list] = []
    out: dict[str, list] = defaultdict(lambda: [0.0, 0])
    for ts, event in buffer:
        if event.is_start:
            stack.append([ts, 0.0])
            continue
        t0, inner = stack.pop()
        total = ts - t0
        name = getattr(event.data["dispatcher"], "py_func", None)
        name = name.__qualname__ if name is not None else "?"
        out[name][0] += total - inner
        out[name][1] += 1
        if stack:
            stack[-1][1] += total
    return dict(out)


def _duffing() -> tuple:
    """The primer ``Duffing-one-form``: the forced Duffing oscillator of
    examples/duffing_model.py as a one-form user model (the pointer path, the default), and its
    start state."""
    import numpy as np

    import geardyn

    sys.path.insert(0, str(HERE.parent / "examples"))
    from duffing_model import duffing_one

    model = geardyn.UserModel.from_one_form(
        duffing_one, params={"delta": 0.3, "gamma": 0.1, "Omega": 1.2}, states=("x", "v"),
        initial_state=(1.0, 0.0), natural_frequency=2.0 ** 0.5, name="Duffing")
    return model, np.array([1.0, 0.0])


#: Cases besides the conformance cases (primers).
EXTRA_CASES = {"Duffing-one-form": _duffing}


def child(case: str) -> dict:
    """Run every analysis once in this process; their CPU and wall seconds, and compile events."""
    t_wall = time.perf_counter()
    import geardyn  # noqa: F401
    from conformance_cases import cases

    model, y0 = EXTRA_CASES[case]() if case in EXTRA_CASES else cases()[case]
    # import: the process's CPU so far (interpreter, numba, geardyn, the model)
    rows = {"import": (time.process_time(), time.perf_counter() - t_wall, {}, "")}
    for name, fn in _runs(model, y0).items():
        c0, w0 = time.process_time(), time.perf_counter()
        note = ""
        rec = _CpuRecorder()
        ev.register("numba:compile", rec)
        try:
            fn()
        except Exception as exc:  # noqa: BLE001 - recorded in the row, the others go on
            note = f"{type(exc).__name__}: {exc}"[:120]
        finally:
            ev.unregister("numba:compile", rec)
        rows[name] = (time.process_time() - c0, time.perf_counter() - w0,
                      _exclusive(rec.buffer), note)
    return rows


def run_child(case: str, cache: str) -> dict:
    env = dict(os.environ, GEARDYN_CACHE_DIR=cache, GEARDYN_COMPILE_AHEAD="0")
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, __file__, "--child", case], env=env, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure(case: str, primer: str | None = None) -> tuple[dict, dict]:
    """(cold, warm) rows of ``case``: a process on an empty cache, then one on the filled one.
    With ``primer`` (another case), a process running that case first fills the cache with what
    every model shares (the shared modules), so that ``cold`` is the model's own compile."""
    with tempfile.TemporaryDirectory(prefix="geardyn-compile-") as cache:
        if primer is not None:
            run_child(primer, cache)
        cold = run_child(case, cache)
        warm = run_child(case, cache)
    return cold, warm


def report(case: str, cold: dict, warm: dict, top: int) -> str:
    lines = [f"## {case}", "", "| analysis | cold CPU s | cold wall s | cached CPU s | "
             "cached wall s | note |", "|---|---|---|---|---|---|"]
    for name, (c, w, _, note) in cold.items():
        wc, ww = warm[name][0], warm[name][1]
        lines.append(f"| {name} | {c:.1f} | {w:.1f} | {wc:.2f} | {ww:.2f} | {note} |")
    total = {k: sum(v[k] for v in cold.values()) for k in (0, 1)}
    wtot = {k: sum(v[k] for v in warm.values()) for k in (0, 1)}
    lines.append(f"| **all** | {total[0]:.1f} | {total[1]:.1f} | {wtot[0]:.2f} | {wtot[1]:.2f} "
                 "| |")
    fns: dict[str, list] = defaultdict(lambda: [0.0, 0])
    for _, _, ex, _ in cold.values():
        for name, (s, n) in ex.items():
            fns[name][0] += s
            fns[name][1] += n
    big = sorted(fns.items(), key=lambda kv: -kv[1][0])[:top]
    lines += ["", "compiled functions (exclusive seconds, compiles): "
              + ", ".join(f"{n} {s:.1f} ({c})" for n, (s, c) in big), ""]
    return "\n".join(lines)


def record(case: str, cold: dict, warm: dict, primer: str | None = None) -> None:
    """Replace the row ``compile-<case>`` (``compile-<case>-own`` with a primer) of
    bench/RESULTS.md's current-figures table."""
    import _results as results

    cpu = sum(v[0] for v in cold.values())
    wall = sum(v[1] for v in cold.values())
    cached = sum(v[0] for v in warm.values())
    target = TARGET_USER if case.startswith("UserModel") else TARGET_BUILTIN
    per = ", ".join(f"{k} {v[0]:.0f}" for k, v in cold.items() if k != "import")
    if primer is None:
        key, what, flag = f"compile-{case}", "empty cache", ""
    else:
        key, what, flag = (f"compile-{case}-own", f"shared kernels cached (by {primer})",
                           f" --primer {primer}")
    results.record(
        key, f"first use of every analysis, {what}: <= {target:.0f} s CPU",
        f"{cpu:.0f} s CPU ({wall:.0f} s wall; {per}); cached {cached:.1f} s CPU",
        results.against(cpu, target),
        f".venv/bin/python bench/compile.py --models {case}{flag} --write")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--models", nargs="*", default=None, help="case ids (default: all)")
    ap.add_argument("--top", type=int, default=8, help="compiled functions listed per model")
    ap.add_argument("--json", type=Path, default=None, help="also write the raw rows here")
    ap.add_argument("--write", action="store_true",
                    help="replace the compile-* rows of bench/RESULTS.md's table")
    ap.add_argument("--from-json", type=Path, default=None,
                    help="report (and --write) the rows of an earlier run's --json instead")
    ap.add_argument("--primer", default=None,
                    help="a case run first on the empty cache (its figures discarded), so that "
                         "each model's figure is its own compile with the shared kernels cached "
                         "(GearPair: the shared modules; Duffing-one-form, a pointer model: the "
                         "pointer path's kernels too)")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child)))
        return 0
    from conformance_cases import IDS

    if args.from_json:
        raw = json.loads(args.from_json.read_text())
    else:
        raw = {}
    for case in args.models or ([c for c in IDS if c in raw] if args.from_json else IDS):
        if not args.from_json:
            cold, warm = measure(case, args.primer)
            raw[case] = {"cold": cold, "warm": warm}
        cold, warm = raw[case]["cold"], raw[case]["warm"]
        print(report(case, cold, warm, args.top), flush=True)
        if args.json:
            args.json.write_text(json.dumps(raw, indent=1))
        if args.write:
            record(case, cold, warm, args.primer)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
