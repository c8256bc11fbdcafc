"""Calls of big callees bound to their one compiled copy (:mod:`geardyn._bound_calls`): the
caller's module declares the callee, results are bitwise those of numba's linking
(``GEARDYN_BIND=0``) and what numpy computes, and numba's cache keeps working: a fresh process
loads a caller whose callee it has not loaded (the caller's loader brings the callee's code),
one loads the callee from Python first, one compiles a new caller against the cached callee
after loading a cached caller. Plain numba functions link the callee as numba does."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from geardyn import _bound_calls
from geardyn._jit_target import WidthCompiler

ROOT = Path(__file__).resolve().parents[1]

#: A callee (bound: the subprocesses set GEARDYN_BIND_MIN=1) and two callers, in geardyn's
#: generated-kernels folder (geardyn's cache locator keeps their code), cached.
_MODULE = """
import numba
import numpy as np
from geardyn._jit_target import WidthCompiler

J = dict(cache=True, pipeline_class=WidthCompiler)


@numba.njit(**J)
def callee(x, k, out):
    if k < 0.0:
        raise ValueError("negative k", k)
    s = 0.0
    for i in range(x.size):
        s += np.sin(k * x[i]) + np.sqrt(abs(x[i]))
        out[i] = s
    return s


@numba.njit(**J)
def caller(x, k):
    out = np.empty_like(x)
    return callee(x, k, out) + callee(x[1:], 2.0 * k, out) + out[3]


@numba.njit(**J)
def other_caller(x, k):
    out = np.empty_like(x)
    return 3.0 * callee(x[::2], k, out) - callee(x, k, out)
"""

#: argv[1]: the module's folder; argv[2]: the calls, comma-separated. Prints JSON.
_STEP = """
import json, sys
import numpy as np
from geardyn import _bound_calls
from geardyn.solvers.kernels import _quiet_module
sys.path.insert(0, sys.argv[1])
import bound_probe as m
_quiet_module(m)
x = np.linspace(-1.0, 2.0, 23)
out = {}
for call in sys.argv[2].split(","):
    if call == "caller":
        out["caller"] = m.caller(x, 1.5).hex()
    elif call == "other":
        out["other"] = m.other_caller(x, 0.5).hex()
    elif call == "callee":
        out["callee"] = m.callee(x, 1.5, np.empty_like(x)).hex()
    elif call == "raise":
        try:
            m.caller(x, -1.0)
        except ValueError as exc:
            out["raised"] = list(exc.args)
declared = {}
for f in (m.caller, m.other_caller):
    for cres in f.overloads.values():
        fns = {fn.name: fn.is_declaration for fn in cres.library._final_module.functions
               if "bound_probe" in fn.name and "callee" in fn.name
               and not fn.name.startswith("_ZN7cpython")}
        if fns:  # compiled here (one loaded from the cache has an empty module)
            declared[f.__name__] = sorted(set(fns.values()))
out["declared"] = declared
out["hits"] = {f.__name__: sum(f.stats.cache_hits.values())
               for f in (m.callee, m.caller, m.other_caller)}
out["loaded"] = len(_bound_calls._LOADED)
print(json.dumps(out))
"""


def _callee(x: np.ndarray, k: float) -> tuple[float, np.ndarray]:
    terms = np.sin(k * x) + np.sqrt(np.abs(x))
    return float(np.sum(terms)), np.cumsum(terms)


@pytest.mark.slow
def test_bound_calls_through_the_cache(tmp_path):
    def steps(cache: Path, bind: str) -> callable:
        kernels = cache / "kernels"
        kernels.mkdir(parents=True)
        (kernels / "bound_probe.py").write_text(_MODULE)
        env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
        env.update(GEARDYN_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT / "src"),
                   GEARDYN_BIND=bind, GEARDYN_BIND_MIN="1")

        def step(calls: str) -> dict:
            out = subprocess.run([sys.executable, "-c", _STEP, str(kernels), calls], env=env,
                                 capture_output=True, text=True, timeout=600)
            assert out.returncode == 0, out.stderr[-3000:]
            return json.loads(out.stdout.strip().splitlines()[-1])
        return step

    bound, linked = steps(tmp_path / "bound", "1"), steps(tmp_path / "linked", "0")
    ref = linked("caller,other,callee,raise")
    assert all(True not in v for v in ref["declared"].values())  # numba's linking
    cold = bound("caller,other,callee,raise")
    assert cold["declared"] == {"caller": [True], "other_caller": [True]}  # declared, bound
    # a fresh process loads the caller before its callee: the caller's loader brings it
    warm = bound("caller,raise,callee")
    assert warm["hits"]["caller"] == 1 and warm["loaded"] == 1
    # the callee loaded (from Python) first: the caller binds to that copy, nothing loaded
    first = bound("callee,caller")
    assert first["hits"] == {"callee": 1, "caller": 1, "other_caller": 0}
    assert first["loaded"] == 0
    for got in (cold, warm, first):
        for key in ("caller", "other", "callee", "raised"):
            if key in got:
                assert got[key] == ref[key], key

    x = np.linspace(-1.0, 2.0, 23)
    s1, c1 = _callee(x, 1.5)
    s2, _ = _callee(x[1:], 3.0)
    c_out = np.array(c1)
    c_out[:22] = np.cumsum(np.sin(3.0 * x[1:]) + np.sqrt(np.abs(x[1:])))
    np.testing.assert_allclose(float.fromhex(ref["caller"]), s1 + s2 + c_out[3], rtol=1e-12)
    np.testing.assert_allclose(float.fromhex(ref["other"]),
                               3.0 * _callee(x[::2], 0.5)[0] - _callee(x, 0.5)[0], rtol=1e-12)
    np.testing.assert_allclose(float.fromhex(ref["callee"]), s1, rtol=1e-12)
    assert ref["raised"] == ["negative k", -1.0]


@pytest.mark.slow
def test_a_new_caller_binds_to_a_loaded_copy(tmp_path):
    """A cached caller loaded first (its loader brings the callee's code), then a caller
    compiled here against the callee's cached form: both bind to the loaded copy."""
    cache = tmp_path / "cache"
    kernels = cache / "kernels"
    kernels.mkdir(parents=True)
    (kernels / "bound_probe.py").write_text(_MODULE.replace(
        "def other_caller(x, k):", "def other_caller(x, k):  # compiled later"))
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(GEARDYN_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT / "src"), GEARDYN_BIND_MIN="1")

    def step(calls: str) -> dict:
        out = subprocess.run([sys.executable, "-c", _STEP, str(kernels), calls], env=env,
                             capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr[-3000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    step("caller")  # compiles the callee and the caller
    got = step("caller,other,callee")
    assert got["hits"] == {"callee": 1, "caller": 1, "other_caller": 0}
    assert got["loaded"] == 1 and got["declared"] == {"other_caller": [True]}
    x = np.linspace(-1.0, 2.0, 23)
    np.testing.assert_allclose(float.fromhex(got["other"]),
                               3.0 * _callee(x[::2], 0.5)[0] - _callee(x, 0.5)[0], rtol=1e-12)
    np.testing.assert_allclose(float.fromhex(got["callee"]), _callee(x, 1.5)[0], rtol=1e-12)


def _body(a, out):
    s = 0.0
    for i in range(a.size):
        s += np.cos(a[i])
        out[i] = s
    return s


_inner = numba.njit(_nrt=False, pipeline_class=WidthCompiler)(_body)


def _call_inner(a):
    out = np.empty_like(a)
    return _inner(a, out) + out[0]


def _defines(dispatcher, name_part: str) -> list[bool]:
    (cres,) = dispatcher.overloads.values()
    return sorted(not fn.is_declaration for fn in cres.library._final_module.functions
                  if name_part in fn.name and not fn.name.startswith("_ZN7cpython"))


def test_geardyn_callers_declare_and_plain_numba_links(monkeypatch):
    monkeypatch.setattr(_bound_calls, "MIN_INSTRUCTIONS", 1)
    a = np.linspace(0.0, 3.0, 17)
    geardyn_caller = numba.njit(pipeline_class=WidthCompiler)(_call_inner)
    plain_caller = numba.njit(_call_inner)
    want = np.sum(np.cos(a)) + np.cos(a[0])
    np.testing.assert_allclose(geardyn_caller(a), want, rtol=1e-12)
    np.testing.assert_allclose(plain_caller(a), want, rtol=1e-12)
    assert geardyn_caller(a) == plain_caller(a)
    assert _defines(geardyn_caller, "_body") == [False]  # declared, bound to the one copy
    assert False not in _defines(plain_caller, "_body")  # numba's linked copy (or inlined)


_forced = numba.njit(forceinline=True, _nrt=False, pipeline_class=WidthCompiler)(_body)


def _call_forced(a):
    out = np.empty_like(a)
    return _forced(a, out) + out[0]


def test_a_forceinline_callee_is_inlined_not_bound(monkeypatch):
    """A callee marked ``forceinline`` (LLVM's ``alwaysinline``) is never bound, however big:
    its geardyn callers link it and LLVM inlines it (a declaration could not be inlined)."""
    monkeypatch.setattr(_bound_calls, "MIN_INSTRUCTIONS", 1)
    a = np.linspace(0.0, 3.0, 17)
    caller = numba.njit(pipeline_class=WidthCompiler)(_call_forced)
    np.testing.assert_allclose(caller(a), np.sum(np.cos(a)) + np.cos(a[0]), rtol=1e-12)
    assert _defines(caller, "_body") == []  # inlined: neither declared nor defined

def _body_marked(a, out):  # _body's body: always_bind marks a Python function, not a copy
    s = 0.0
    for i in range(a.size):
        s += np.cos(a[i])
        out[i] = s
    return s


# A dispatcher of _body of its own: compiled here with the default MIN_INSTRUCTIONS (_inner is
# compiled bound by the test that lowers it).
_body_linked = numba.njit(_nrt=False, pipeline_class=WidthCompiler)(_body)
_body_bound = _bound_calls.always_bind(
    numba.njit(_nrt=False, pipeline_class=WidthCompiler)(_body_marked))


def _call_body_linked(a):
    out = np.empty_like(a)
    return _body_linked(a, out) + out[0]


def _call_body_bound(a):
    out = np.empty_like(a)
    return _body_bound(a, out) + out[0]


def test_an_always_bind_callee_is_bound_whatever_its_size():
    """A callee marked by ``always_bind``, far below MIN_INSTRUCTIONS, is declared in its
    geardyn callers (bound to its one copy), the same body unmarked is linked (defined or
    inlined); the results are the same, bitwise. A library loaded from numba's cache (no
    compile to mark it) is recognised by its function's name."""
    assert _bound_calls.MIN_INSTRUCTIONS > 100
    a = np.linspace(0.0, 3.0, 17)
    bound = numba.njit(pipeline_class=WidthCompiler)(_call_body_bound)
    linked = numba.njit(pipeline_class=WidthCompiler)(_call_body_linked)
    want = np.sum(np.cos(a)) + np.cos(a[0])
    np.testing.assert_allclose(bound(a), want, rtol=1e-12)
    assert bound(a) == linked(a)
    assert _defines(bound, "_body_marked") == [False]  # declared: bound
    assert False not in _defines(linked, "_body")  # linked (or inlined)

    class Loaded:  # a library as numba's cache loads it: its name, no compile's mark
        name = _body_marked.__qualname__
    assert _bound_calls._always(Loaded())
    Loaded.name = _body.__qualname__
    assert not _bound_calls._always(Loaded())
