"""Compiles shared between processes: one process compiles a kernel function, the others load it.

numba caches a compiled function on disk (see :mod:`geardyn._cache`), but two processes that
need the same uncached function at once (two test workers, the Dask workers of a sweep, a
helper process started by :func:`compile_ahead`) would each compile it. Here a compile of a
generated kernel module's function takes a file lock named after the function
(``cache_root()/locks``) first: a process that finds it held waits, then loads what the holder
wrote to the cache. Locks are taken down the call graph (a function's compile compiles its
callees, never its callers), so two processes cannot wait on each other.

:func:`compile_ahead` starts a helper process that compiles named functions of a generated
kernel module with their declared signatures while the caller compiles something else: on a
machine with two cores, the model's split step (the scalar path every analysis shares) compiles
beside the sweep's block kernel instead of after it. The helper is an optimisation only: where
it cannot start, is switched off (``GEARDYN_COMPILE_AHEAD=0``) or fails, the caller compiles the
function itself when it needs it, with the same result.
"""

from __future__ import annotations

import atexit
import os
import subprocess
import sys
import types
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from numba.core import sigutils

from geardyn._cache import cache_root

try:
    import fcntl
except ImportError:  # not POSIX (Windows): no lock; each process compiles what it needs
    fcntl = None

__all__ = ["ENV", "compile_ahead", "compile_lock", "signature_types"]

#: The environment variable that switches :func:`compile_ahead` off (``0``).
ENV = "GEARDYN_COMPILE_AHEAD"
#: Helper processes started by this process, by (module, names): each starts once.
_STARTED: dict[tuple[str, tuple[str, ...]], subprocess.Popen] = {}


def lock_path(module: str, name: str) -> Path:
    """The lock file of function ``name`` of the generated module ``module``."""
    return cache_root() / "locks" / f"{module}.{name}.lock"


#: Lock files this process holds, with the depth of their holds: a compile may compile another
#: signature of the same function inside it (an flock is per open file, so a second open of
#: the same file would wait on this process's own lock for ever).
_HELD: dict[Path, int] = {}


@contextmanager
def compile_lock(module: str, name: str) -> Iterator[None]:
    """Hold the lock of ``module.name``'s compile (blocking while another process holds it;
    re-entrant within this process, where numba's compiler lock serialises compiles)."""
    path = lock_path(module, name)
    if fcntl is None or path in _HELD:
        if path in _HELD:
            _HELD[path] += 1
        try:
            yield
        finally:
            if path in _HELD:
                _HELD[path] -= 1
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        _HELD[path] = 1
        try:
            yield
        finally:
            del _HELD[path]
            fcntl.flock(fh, fcntl.LOCK_UN)


def shared(dispatcher: Any, compile_: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """``compile_`` (a dispatcher's compile) under the function's :func:`compile_lock` for a
    signature it has not compiled yet (a compiled one returns at once, without the lock)."""
    module, name = dispatcher.py_func.__module__, dispatcher.py_func.__name__

    def compile(sig: Any) -> Any:
        if isinstance(sig, tuple) and sig in dispatcher.overloads:
            return compile_(sig)
        with compile_lock(module, name):
            return compile_(sig)

    return compile


def signature_types(text: str) -> tuple:
    """The argument types of a numba signature written as text, e.g. ``"(int64, float64[::1])"``,
    as the tuple numba keys its overloads and its cache index by."""
    args, _ = sigutils.normalize_signature(text)
    return tuple(args)


def _cached(dispatcher: Any, sig: tuple) -> bool:
    """Whether ``dispatcher`` has ``sig`` compiled in this process or in numba's disk cache
    (its index names it)."""
    if sig in dispatcher.overloads:
        return True
    cache = dispatcher._cache
    try:
        key = cache._index_key(sig, dispatcher.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except Exception:  # no disk cache, or an unreadable index: the compile will tell
        return False


def compile_ahead(module: types.ModuleType, signatures: dict[str, str]) -> subprocess.Popen | None:
    """Start a helper process that compiles ``module``'s functions ``signatures`` (name ->
    signature text) where neither this process nor the disk cache has them. Returns the process
    (None where nothing is to compile, the module is not a cached file, or :data:`ENV` is 0).
    The helper holds each function's :func:`compile_lock` while it compiles it, so this process
    waits for it there instead of compiling the function a second time."""
    path = getattr(module, "__file__", None)
    if os.environ.get(ENV, "1") == "0" or path is None:
        return None
    names = tuple(n for n, text in signatures.items()
                  if not _cached(getattr(module, n), signature_types(text)))
    key = (module.__name__, names)
    if not names or key in _STARTED:
        return None
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    cmd = [sys.executable, "-m", "geardyn.solvers.compile_helper", module.__name__, path,
           *(f"{n}={signatures[n]}" for n in names)]
    try:
        proc = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None
    if not _STARTED:
        atexit.register(_leave_helpers_running)
    _STARTED[key] = proc
    return proc


def _leave_helpers_running() -> None:
    """At exit, a helper still compiling goes on and fills the disk cache for the next process;
    its ``Popen`` object is released here, unwaited, which is meant: its ResourceWarning is
    ignored while it is released (the warning filters are as before afterwards)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"subprocess \d+ is still running",
                                category=ResourceWarning)
        _STARTED.clear()
