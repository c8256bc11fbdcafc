"""``import geardyn`` changes no process-wide setting: no warning filter, no environment
variable, no numba configuration value (numba's CPU name and features included: the kernels'
vector width is set on geardyn's own functions, :mod:`geardyn._jit_target`), neither at import
nor after a first run (geardyn's compile-time warning filters are scoped to its own compiles)."""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: A fresh interpreter: the process-wide state before ``import geardyn`` (its dependencies, named
#: in argv[2], imported already: what they do at import is theirs), after it, and after a first
#: small run (a gear-pair trajectory, kernels from the cache).
_PROBE = """
import importlib, json, os, sys, warnings
import numba
from numba.core import config

for name in json.loads(sys.argv[2]):
    try:
        importlib.import_module(name)
    except Exception:
        pass


def state():
    cfg = {k: repr(getattr(config, k)) for k in dir(config) if k.isupper()}
    return {"filters": [repr(f) for f in warnings.filters], "environ": dict(os.environ),
            "config": cfg}


out = {"before": state()}
import geardyn
out["imported"] = state()
if sys.argv[1] == "run":
    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.0)
    geardyn.simulate(g, omega=1.2, run=geardyn.RunSettings(transient=10.0, samples=4))
    out["ran"] = state()
print(json.dumps(out))
"""


#: The modules other than geardyn's that ``import geardyn`` imports, and with ``run`` those the
#: probe's first run imports too (geardyn imports some, e.g. SciPy's, where they are used; numba's
#: own are left to the run: which of them set up its CPU target is what the probe looks at).
_DEPENDENCIES = """
import json, sys
before = set(sys.modules)
import geardyn
imported = set(sys.modules)
if sys.argv[1] == "run":
    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.0)
    geardyn.simulate(g, omega=1.2, run=geardyn.RunSettings(transient=10.0, samples=4))
ran = {m for m in set(sys.modules) - imported if not m.startswith(("numba", "llvmlite"))}
print(json.dumps(sorted(m for m in (imported | ran) - before
                        if not m.startswith(("geardyn", "__main__")))))
"""


#: The caller's settings a probe starts without: the width and numba's own CPU and cache settings.
_SETTINGS = ("GEARDYN_SIMD_WIDTH", "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NUMBA_CACHE_DIR")


def _run(code: str, env: dict[str, str], *args: str) -> object:
    base = {k: v for k, v in os.environ.items() if k not in _SETTINGS}
    base["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), base.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, "-c", code, *args], env={**base, **env},
                         capture_output=True, text=True, timeout=600, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


@functools.cache
def _dependencies(mode: str) -> list[str]:
    """The modules of :data:`_DEPENDENCIES` under the caller's settings less :data:`_SETTINGS`,
    one probe per mode for every test here: a module that geardyn imported only under another
    width or cache setting would not be imported before the probe's first state, so its
    import-time changes would show as geardyn's (a failure, not a change hidden)."""
    return _run(_DEPENDENCIES, {}, mode)


def _states(env: dict[str, str], mode: str) -> dict:
    return _run(_PROBE, env, mode, json.dumps(_dependencies(mode)))


def _changes(a: dict, b: dict) -> dict:
    """What differs between two states: per part, the keys (or filters) added, removed or
    changed."""
    diff = {"filters": sorted(set(b["filters"]) ^ set(a["filters"]))
            if a["filters"] != b["filters"] else []}
    for part in ("environ", "config"):
        keys = set(a[part]) | set(b[part])
        diff[part] = sorted(k for k in keys if a[part].get(k) != b[part].get(k))
    return diff


_NONE = {"filters": [], "environ": [], "config": []}


@pytest.mark.parametrize("width", ["default", "256", "native"])
def test_import_and_first_run_change_no_global_state(width):
    """At every vector width (the default 512 bits included): warning filters, the environment
    and every numba configuration value (CPU name and features too) are as before the import,
    and after a first run (which compiles or loads kernels)."""
    env = {} if width == "default" else {"GEARDYN_SIMD_WIDTH": width}
    got = _states(env, "run" if width == "default" else "import")
    assert _changes(got["before"], got["imported"]) == _NONE
    if "ran" in got:
        assert _changes(got["before"], got["ran"]) == _NONE


@pytest.mark.parametrize("cache_var", ["unset", "set"])
def test_import_changes_nothing_whether_or_not_numbas_cache_is_set(tmp_path, cache_var):
    """``import geardyn`` changes no warning filter, environment variable or numba
    configuration value, whether or not ``NUMBA_CACHE_DIR`` is set."""
    env = {"NUMBA_CACHE_DIR": str(tmp_path)} if cache_var == "set" else {}
    got = _states(env, "import")
    assert _changes(got["before"], got["imported"]) == _NONE


def test_quiet_compile_scopes_its_filter():
    """A kernel's compile runs with numba's two noisy categories ignored; other warnings pass,
    and the warning filters are as before once it returns."""
    import warnings

    import numba

    from geardyn.solvers.kernels import _quiet_compile

    class Dispatcher:
        def compile(self, sig):
            warnings.warn("pedantic", numba.core.errors.NumbaIRAssumptionWarning,
                          stacklevel=1)
            warnings.warn("debug lines", numba.core.errors.NumbaDebugInfoWarning,
                          stacklevel=1)
            warnings.warn("a real one", UserWarning, stacklevel=1)
            return sig

    d = Dispatcher()
    _quiet_compile(d)
    filters = list(warnings.filters)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert d.compile("sig") == "sig"
    assert [str(w.message) for w in caught] == ["a real one"]
    assert warnings.filters == filters


def test_quiet_compiles_on_threads_leave_the_filters_as_they_were():
    """Threads that compile at once (the sweep's workers start on threads) restore the warning
    filters in pairs: none of the scoped filters is left installed afterwards."""
    import threading
    import time
    import warnings

    from geardyn.solvers.kernels import _quiet_compile

    class Dispatcher:
        def compile(self, sig):
            time.sleep(0.02 * sig)  # overlapping compiles: the first to start ends first
            return sig

    filters = list(warnings.filters)
    dispatchers = [Dispatcher() for _ in range(8)]
    for d in dispatchers:
        _quiet_compile(d)
    threads = [threading.Thread(target=d.compile, args=(k + 1,))
               for k, d in enumerate(dispatchers)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert warnings.filters == filters


def test_helpers_left_running_at_exit_leave_the_filters_as_they_were(monkeypatch):
    """At exit, a compile helper still running is released unwaited: without a ResourceWarning,
    and with no warning filter left installed."""
    import signal
    import warnings

    from geardyn.solvers import compile_share

    proc = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    pid = proc.pid
    monkeypatch.setattr(compile_share, "_STARTED", {("kernels", ("f",)): proc})
    del proc
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            filters = list(warnings.filters)
            compile_share._leave_helpers_running()
            assert warnings.filters == filters
        assert not compile_share._STARTED
        assert not [w for w in caught if issubclass(w.category, ResourceWarning)]
    finally:
        os.kill(pid, signal.SIGTERM)
