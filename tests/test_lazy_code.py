"""A nested geardyn function's machine code emitted on first need (:mod:`geardyn._lazy_code`):
its callers compute what numpy computes, an exception raised inside it (which reads its numba
environment) reaches Python, it works called from Python (emitting its code then), and numba's
cache keeps it: a second process loads the caller, a third compiles a new caller against the
cached callee. Plain numba functions are compiled as numba compiles them."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from geardyn import _lazy_code
from geardyn._jit_target import WidthCompiler

ROOT = Path(__file__).resolve().parents[1]

#: A callee and its callers, in a module of geardyn's (its generated-kernels folder, where
#: geardyn's cache locator keeps their code), compiled with geardyn's pipeline and cached.
_MODULE = """
import numba
import numpy as np
from geardyn._jit_target import WidthCompiler

J = dict(cache=True, pipeline_class=WidthCompiler)


@numba.njit(**J)
def callee(x, k):
    if k < 0.0:
        raise ValueError("negative k", k)
    s = 0.0
    for i in range(x.size):
        s += np.sin(k * x[i]) + np.sqrt(abs(x[i]))
    return s


@numba.njit(**J)
def caller(x, k):
    return callee(x, k) + callee(x[1:], 2.0 * k)


@numba.njit(**J)
def other_caller(x, k):
    return 3.0 * callee(x[::2], k) - callee(x, k)
"""

#: argv[1]: the module's folder; argv[2]: which step. Prints the results and states as JSON.
_STEP = """
import json, sys
import numpy as np
from geardyn import _lazy_code
sys.path.insert(0, sys.argv[1])
import lazy_probe as m
x = np.linspace(-1.0, 2.0, 23)
out = {}
if sys.argv[2] in ("cold", "warm"):
    out["caller"] = m.caller(x, 1.5)
    out["callee_pending"] = [_lazy_code.is_pending(c.library) for c in m.callee.overloads.values()]
    out["callee"] = m.callee(x, 1.5)
    try:
        m.caller(x, -1.0)
    except ValueError as exc:
        out["raised"] = list(exc.args)
else:
    out["other_caller"] = m.other_caller(x, 0.5)
    out["callee_pending"] = [_lazy_code.is_pending(c.library) for c in m.callee.overloads.values()]
out["hits"] = {f.__name__: sum(f.stats.cache_hits.values())
               for f in (m.callee, m.caller, m.other_caller)}
print(json.dumps(out))
"""


def _callee(x: np.ndarray, k: float) -> float:
    return float(np.sum(np.sin(k * x) + np.sqrt(np.abs(x))))


def _body(a):
    return np.sum(np.cos(a))


def _outer(a):
    return _inner(a) + 1.0


_inner = numba.njit(pipeline_class=WidthCompiler)(_body)
_outer_jit = numba.njit(pipeline_class=WidthCompiler)(_outer)
_plain_inner = numba.njit(_body)


def test_a_callee_is_compiled_without_machine_code_until_called_from_python():
    a = np.linspace(0.0, 3.0, 17)
    np.testing.assert_allclose(_outer_jit(a), np.sum(np.cos(a)) + 1.0, rtol=1e-12)
    (cres,) = _inner.overloads.values()
    assert _lazy_code.is_pending(cres.library)
    np.testing.assert_allclose(_inner(a), np.sum(np.cos(a)), rtol=1e-12)  # via the stand-in
    assert not _lazy_code.is_pending(cres.library)
    np.testing.assert_allclose(_inner(2.0 * a), np.sum(np.cos(2.0 * a)), rtol=1e-12)


def test_plain_numba_is_untouched():
    @numba.njit
    def outer(a):
        return _plain_inner(a) * 2.0

    a = np.linspace(0.0, 1.0, 9)
    np.testing.assert_allclose(outer(a), 2.0 * np.sum(np.cos(a)), rtol=1e-12)
    (cres,) = _plain_inner.overloads.values()
    assert not _lazy_code.is_pending(cres.library)
    assert _lazy_code.scope.depth == 0


@pytest.mark.slow
def test_the_cache_keeps_a_deferred_callee(tmp_path):
    kernels = tmp_path / "kernels"
    kernels.mkdir()
    (kernels / "lazy_probe.py").write_text(_MODULE)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(GEARDYN_CACHE_DIR=str(tmp_path), PYTHONPATH=str(ROOT / "src"))

    def step(name: str) -> dict:
        out = subprocess.run([sys.executable, "-c", _STEP, str(kernels), name], env=env,
                             capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout.strip().splitlines()[-1])

    x = np.linspace(-1.0, 2.0, 23)
    caller = _callee(x, 1.5) + _callee(x[1:], 3.0)
    cold, warm, third = step("cold"), step("warm"), step("third")
    for got in (cold, warm):
        np.testing.assert_allclose(got["caller"], caller, rtol=1e-12)
        np.testing.assert_allclose(got["callee"], _callee(x, 1.5), rtol=1e-12)
        assert got["raised"] == ["negative k", -1.0]
    assert cold["callee_pending"] == [True] and cold["hits"]["caller"] == 0
    assert warm["callee_pending"] == [] and warm["hits"]["caller"] >= 1
    np.testing.assert_allclose(third["other_caller"],
                               3.0 * _callee(x[::2], 0.5) - _callee(x, 0.5), rtol=1e-12)
    # the callee's contiguous form came from the cache (compiled by the first process), its
    # strided form was compiled here: both wait for a call from Python
    assert third["hits"]["callee"] == 1 and third["callee_pending"] == [True, True]
