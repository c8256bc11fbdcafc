"""Compiles shared between processes (geardyn.solvers.compile_share): a function's compile waits
for another process that holds its lock, and the split step compiled ahead in a helper process
is the one the kernels load."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
import types
from pathlib import Path

from geardyn.solvers import compile_share

TESTS = Path(__file__).resolve().parent


def _fake_dispatcher(module: str, name: str, compiled: tuple = ()) -> types.SimpleNamespace:
    def py_func():
        pass

    py_func.__module__, py_func.__name__ = module, name
    return types.SimpleNamespace(py_func=py_func, overloads=dict.fromkeys(compiled))


def _hold(path: Path, seconds: float) -> subprocess.Popen:
    """Another process that holds the lock file ``path`` for ``seconds`` once it says so."""
    script = ("import fcntl, sys, time\nf = open(sys.argv[1], 'a')\n"
              "fcntl.flock(f, fcntl.LOCK_EX)\nprint('held', flush=True)\n"
              "time.sleep(float(sys.argv[2]))\n")
    proc = subprocess.Popen([sys.executable, "-c", script, str(path), str(seconds)],
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "held"
    return proc


def test_a_compile_waits_for_the_process_that_holds_its_lock(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path))
    path = compile_share.lock_path("geardyn_rk4_x", "_block")
    path.parent.mkdir(parents=True)
    holder = _hold(path, 1.5)
    started = time.monotonic()
    calls = []
    compile_ = compile_share.shared(_fake_dispatcher("geardyn_rk4_x", "_block"),
                                    lambda sig: calls.append(time.monotonic() - started))
    compile_(("float64",))
    holder.wait()
    assert len(calls) == 1 and calls[0] >= 1.0  # it waited for the holder to let go


def test_a_compiled_signature_returns_without_the_lock(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path))
    path = compile_share.lock_path("geardyn_rk4_x", "_block")
    path.parent.mkdir(parents=True)
    holder = _hold(path, 3.0)
    started = time.monotonic()
    calls = []
    compile_ = compile_share.shared(_fake_dispatcher("geardyn_rk4_x", "_block", [("int64",)]),
                                    lambda sig: calls.append(time.monotonic() - started))
    compile_(("int64",))
    holder.kill()
    assert len(calls) == 1 and calls[0] < 1.0


def test_another_function_has_its_own_lock(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path))
    assert (compile_share.lock_path("geardyn_core_a", "_split_step")
            != compile_share.lock_path("geardyn_core_a", "_illinois")
            != compile_share.lock_path("geardyn_core_b", "_split_step"))


# In a fresh process with an empty cache: the helper started by kernels_for (its first template
# of the model) compiles the split step; the trajectory kernel, compiled after the helper has
# ended, loads it from the cache (numba counts a cache hit for the signature, no miss), and the
# run-up kernel, compiled next in the same process, calls the one loaded (another signature would
# be a miss and a compile): the signature declared in AHEAD is the one both templates call it
# with.
_SCRIPT = """
import json, sys
import geardyn
from geardyn.analysis.runup import RunupSettings, runup
from geardyn.solvers import compile_share, kernels

model = geardyn.GearPair()
for template in ("rk4", "runup"):
    kernels.kernels_for(model.kernel, template)
helpers = list(compile_share._STARTED.values())
for proc in helpers:
    proc.wait()
geardyn.simulate(model, omega=1.2, run=geardyn.RunSettings(samples=3))
core = kernels.kernels_for(model.kernel, "core")
stats = core._split_step.stats
after = {"hits": [str(s) for s in stats.cache_hits], "misses": [str(s) for s in stats.cache_misses]}
runup(model, RunupSettings(start=0.8, stop=0.9, duration=5.0))
print(json.dumps({"helpers": len(helpers), "codes": [p.returncode for p in helpers],
                  "simulate": after,
                  "hits": [str(s) for s in stats.cache_hits],
                  "misses": [str(s) for s in stats.cache_misses],
                  "signatures": [str(s) for s in core._split_step.signatures],
                  "ahead": str(compile_share.signature_types(kernels.AHEAD["_split_step"])),
                  "locks": sorted(p.name for p in compile_share.lock_path("m", "f").parent.glob(
                      "*_split_step.lock"))}))
"""


def _run(tmp_path: Path, **env: str) -> dict:
    """The script in a fresh process, with an empty cache and the helper on (``make test``
    switches it off for the suite)."""
    environ = {k: v for k, v in os.environ.items()
               if k not in ("NUMBA_CACHE_DIR", compile_share.ENV)}
    environ.update(GEARDYN_CACHE_DIR=str(tmp_path), PYTHONPATH=os.pathsep.join(
        [str(TESTS), *sys.path]), **env)
    out = subprocess.run([sys.executable, "-c", _SCRIPT], env=environ,
                         capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_split_step_compiled_ahead_is_the_one_the_kernels_load(tmp_path):
    """The trajectory kernel (simulate) and the run-up call the split step with the signature
    compiled ahead: no other is compiled (a literal argument would compile a second one)."""
    r = _run(tmp_path)
    assert r["helpers"] == 1 and r["codes"] == [0]
    assert r["simulate"] == {"hits": [r["ahead"]], "misses": []}
    assert r["misses"] == [] and r["hits"] == [r["ahead"]]
    assert r["signatures"] == [r["ahead"]]
    assert len(r["locks"]) == 1


def test_compile_ahead_switched_off(monkeypatch):
    module = types.ModuleType("geardyn_core_x")
    module.__file__ = "/nonexistent/geardyn_core_x.py"
    monkeypatch.setenv(compile_share.ENV, "0")
    assert compile_share.compile_ahead(module, {"_split_step": "(int64,)"}) is None
    assert not any(name == "geardyn_core_x" for name, _ in compile_share._STARTED)


def test_a_compile_inside_a_compile_of_the_same_function_does_not_wait_on_itself(
        tmp_path, monkeypatch):
    """numba may compile another signature of a function inside its compile (a literal
    argument): the lock is re-entrant within the process (an flock per open file is not)."""
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path))
    d = _fake_dispatcher("geardyn_core_x", "rhs_lane_form")
    calls = []

    def compile_(sig):
        calls.append(sig)
        if sig == ("int64",):
            inner(("Literal[int](1)",))

    inner = compile_share.shared(d, compile_)
    done = []
    th = threading.Thread(target=lambda: (inner(("int64",)), done.append(True)), daemon=True)
    th.start()
    th.join(10.0)
    assert done and calls == [("int64",), ("Literal[int](1)",)]
