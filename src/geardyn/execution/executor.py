"""Chunked execution of lane tasks: in this process, or on a Dask cluster; optionally resumable.

A *lane task* is a picklable function ``task(model, **inputs) -> {name: array}`` whose inputs and
outputs are lane-first arrays (row ``i`` belongs to lane ``i``): typically one compiled-kernel call
(:func:`~geardyn.solvers.ensemble.run_lanes`) on a block of coefficient vectors. Lanes are
independent and the kernels deterministic, so :func:`run_chunks` may cut the lanes into chunks,
run them anywhere and in any order, and the assembled result is bitwise the same as one call.

* ``client=None``: chunks run one after the other in this process (each call is itself parallel
  over the cores). No Dask needed.
* ``client=dask.distributed.Client(...)``: every chunk is one Dask task carrying the packed
  model and its lanes' inputs. Workers import the model's compiled functions by name and build
  (or load from ``$GEARDYN_CACHE_DIR``) their own kernels, see :func:`portable`.
* ``client=concurrent.futures.ProcessPoolExecutor(...)``: the same, on local processes (a task
  whose kernel call runs one lane at a time uses every core this way).
* ``store``: a :class:`~geardyn.execution.zarr_store.LaneStore` (or a path to one): every
  finished chunk is written there as it completes, then marked done; a rerun with the same
  inputs computes only the chunks not marked done. See ``docs/scaling.md``.
"""

from __future__ import annotations

import concurrent.futures
import copy
import functools
import hashlib
import importlib
import json
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from geardyn._version import __version__
from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model
from geardyn.core.one_form import OneForm
from geardyn.core.plan import LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.execution.zarr_store import LaneStore
from geardyn.solvers.ensemble import LaneResults, run_lanes

__all__ = ["PortableModel", "chunk_bounds", "default_chunk", "inputs_digest", "lane_results",
           "portable", "run_chunks", "run_lanes_task"]

#: Smallest default chunk (lanes per task): a kernel call runs lanes in lockstep blocks of 8 on
#: every core, so fewer lanes leave cores idle.
MIN_CHUNK = 64
#: Default number of chunks a sweep is cut into where it reports progress, runs on Dask or keeps
#: a store (:func:`run_chunks`; else it runs in one call).
DEFAULT_CHUNKS = 20

#: Packages whose source (with the model's modules) determines what a store keeps.
_COMPUTING_PACKAGES = ("core", "solvers", "analysis")

LaneTask = Callable[..., dict[str, np.ndarray]]
Progress = Callable[[int, int], None]


def default_chunk(n_lanes: int) -> int:
    """Lanes per chunk by default: about a twentieth of the lanes, at least :data:`MIN_CHUNK`."""
    return max(MIN_CHUNK, -(-n_lanes // DEFAULT_CHUNKS))


def chunk_bounds(n_lanes: int, chunk: int) -> list[tuple[int, int]]:
    """Consecutive ``(start, stop)`` lane ranges of at most ``chunk`` lanes."""
    if chunk < 1:
        raise ValueError(f"chunk must be >= 1 lane (got {chunk})")
    return [(a, min(n_lanes, a + chunk)) for a in range(0, n_lanes, chunk)]


# ---------------------------------------------------------------------------- shipping models
def _function_ref(fn: Any) -> tuple[str, str] | None:
    """``(module, name)`` of a compiled function importable by name, else None."""
    if fn is None:
        return None
    py = getattr(fn, "py_func", fn)
    module = getattr(py, "__module__", None)
    if not module or module == "__main__":
        return None
    try:
        mod = importlib.import_module(module)
    except ImportError:
        return None
    return (module, py.__name__) if getattr(mod, py.__name__, None) is fn else None


def _resolve(ref: tuple[str, str]) -> Any:
    return getattr(importlib.import_module(ref[0]), ref[1])


@dataclass
class PortableModel:
    """A model packed for another process: its compiled functions travel by name (module and
    function), so the receiving process imports the very same functions and reuses the kernels
    cached on disk. (numba pickles a function by value; the copy would not be importable and its
    kernel would be compiled again in memory by every worker.) Functions that cannot be imported
    by name (defined in ``__main__``) travel by value."""

    model: Model
    refs: dict[str, tuple[str, str] | None]
    by_value: dict[str, Any]
    plain: bool
    one_form: OneForm | None = None
    _unpacked: Model | None = field(default=None, repr=False, compare=False)

    def unpack(self) -> Model:
        """The model with its kernel functions restored (built once per process)."""
        if self._unpacked is None:
            funcs = {name: (_resolve(ref) if ref is not None else self.by_value.get(name))
                     for name, ref in self.refs.items()}
            model = copy.copy(self.model)
            model.kernel = KernelSource(funcs["rhs"], funcs["events"], funcs["observe"],
                                        plain=self.plain, one_form=self.one_form)
            self._unpacked = model
        return self._unpacked

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_unpacked"] = None
        return state


def portable(model: Model) -> PortableModel:
    """Pack ``model`` for a Dask worker (see :class:`PortableModel`)."""
    k = model.kernel
    funcs = {"rhs": k.rhs, "events": k.events, "observe": k.observe}
    refs = {name: _function_ref(fn) for name, fn in funcs.items()}
    by_value = {name: fn for name, fn in funcs.items() if fn is not None and refs[name] is None}
    bare = copy.copy(model)
    bare.kernel = None  # type: ignore[assignment]
    return PortableModel(bare, refs, by_value, bool(k.plain), k.one_form)


def _run_portable(task: LaneTask, packed: PortableModel, inputs: dict[str, np.ndarray]
                  ) -> dict[str, np.ndarray]:
    return task(packed.unpack(), **inputs)


# ---------------------------------------------------------------------------- lane tasks
def run_lanes_task(model: Model, P: np.ndarray, y0: np.ndarray, *,
                   run: RunSettings | None = None, lanes: LaneSettings | None = None
                   ) -> dict[str, np.ndarray]:
    """The plain lane task: :func:`run_lanes` on the chunk (``run``, ``lanes`` as there), every
    field of its result."""
    r = run_lanes(model, P, y0, run=run, lanes=lanes)
    return {name: getattr(r, name) for name in LaneResults.__dataclass_fields__}


def lane_results(outputs: Mapping[str, np.ndarray]) -> LaneResults:
    """The :class:`LaneResults` of :func:`run_lanes_task` outputs."""
    return LaneResults(**{name: outputs[name] for name in LaneResults.__dataclass_fields__})


# ---------------------------------------------------------------------------- input digest
def _task_text(task: LaneTask) -> str:
    if isinstance(task, functools.partial):
        kw = json.dumps(task.keywords, sort_keys=True, default=repr)
        return f"{_task_text(task.func)}|{task.args!r}|{kw}"
    return f"{getattr(task, '__module__', '?')}.{getattr(task, '__qualname__', repr(task))}"


@functools.lru_cache(maxsize=32)
def _code_digest(modules: tuple[str, ...]) -> str:
    """SHA-256 of the source of geardyn's core, solvers and analyses and of ``modules`` (the
    model's): the code that computes what a store keeps."""
    root = Path(__file__).resolve().parent.parent  # the geardyn package, read, not imported
    files: list[Path] = []
    for pkg in _COMPUTING_PACKAGES:
        files += sorted((root / pkg).glob("*.py"))
    for name in modules:
        origin = getattr(importlib.import_module(name), "__file__", None)
        if origin:
            files.append(Path(origin))
    h = hashlib.sha256()
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def inputs_digest(task: LaneTask, model: Model, inputs: Mapping[str, np.ndarray], chunk: int,
                  meta: Mapping[str, Any] | None = None) -> str:
    """SHA-256 (hex) of everything that determines a chunked run's result: the task and its
    settings, the model's kind and compiled functions, every input array (bytes, shape, dtype),
    the chunk size and ``meta`` (JSON-able study details), the geardyn version and the source of
    the code that computes the results (solvers, analyses, the model's modules)."""
    h = hashlib.sha256()
    k = model.kernel
    refs = [_function_ref(f) for f in (k.rhs, k.events, k.observe)]
    modules = tuple(sorted({type(model).__module__} | {r[0] for r in refs if r is not None}))
    head = {
        "geardyn": __version__, "code": _code_digest(modules), "task": _task_text(task),
        "chunk": int(chunk),
        "model": [type(model).__module__, type(model).__qualname__, model.name,
                  list(model.state_names)],
        "kernel": [r or repr(f) for r, f in zip(refs, (k.rhs, k.events, k.observe),
                                                strict=True)]
        + ([repr(k.one_form)] if k.one_form is not None else []),
        "meta": meta or {},
    }
    h.update(json.dumps(head, sort_keys=True, default=repr).encode())
    for name in sorted(inputs):
        a = np.ascontiguousarray(inputs[name])
        h.update(f"{name}|{a.dtype.str}|{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()


# ---------------------------------------------------------------------------- running
def _concat(parts: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    if len(parts) == 1:
        return parts[0]
    return {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}


def run_chunks(
    task: LaneTask,
    model: Model,
    inputs: Mapping[str, np.ndarray],
    chunk: int | None = None,
    client: Any = None,
    store: LaneStore | str | os.PathLike[str] | None = None,
    progress: Progress | None = None,
    meta: Mapping[str, Any] | None = None,
) -> dict[str, np.ndarray]:
    """Run ``task(model, **inputs[a:b])`` over consecutive chunks of lanes and concatenate the
    outputs in lane order.

    Parameters
    ----------
    inputs
        Lane-first arrays, all with the same number of lanes.
    chunk
        Lanes per task. Default: every lane in one task where there is no ``client``,
        ``store`` or ``progress`` (chunks serve those; without them a chunk's tail, where a
        core waits for another's last lanes, is lost time: the gear pair's 400-lane sweep of
        bench/peers.py in 7 chunks took 1.13x one call), else :func:`default_chunk`.
    client
        ``None`` (run here), a ``dask.distributed.Client`` or a ``concurrent.futures.Executor``
        (e.g. a ``ProcessPoolExecutor``; one task per chunk).
    store
        A :class:`~geardyn.execution.zarr_store.LaneStore`, or the path of a Zarr store to create or
        resume: finished chunks are read from it instead of being run, new ones written to it as
        they complete. A store holding a run with other inputs (:func:`inputs_digest`) is refused.
    progress
        Called as ``progress(lanes_done, lanes_total)`` after every chunk (and once at the start).
    meta
        JSON-able description of the run, part of the digest and kept in the store.
    """
    arrays = {name: np.asarray(a) for name, a in inputs.items()}
    sizes = {a.shape[0] for a in arrays.values()}
    if len(sizes) != 1:
        raise ValueError("inputs must all have the same number of lanes")
    n_lanes = sizes.pop()
    if n_lanes == 0:
        raise ValueError("no lanes to run")
    lane_store = _open_store(store)
    if chunk:
        size = int(chunk)
    elif client is None and lane_store is None and progress is None:
        size = n_lanes  # nothing to report, keep or ship between chunks: one call
    else:
        size = default_chunk(n_lanes)
    bounds = chunk_bounds(n_lanes, size)
    results: list[dict[str, np.ndarray] | None] = [None] * len(bounds)
    todo = list(range(len(bounds)))
    if lane_store is not None:
        digest = inputs_digest(task, model, arrays, size, meta)
        lane_store.begin(digest, n_lanes, size, dict(meta or {}))
        done = lane_store.done_chunks()
        todo = [i for i in todo if not done[i]]
    finished = n_lanes - sum(bounds[i][1] - bounds[i][0] for i in todo)
    if progress is not None:
        progress(finished, n_lanes)

    def complete(i: int, out: dict[str, np.ndarray]) -> None:
        nonlocal finished
        a, b = bounds[i]
        if lane_store is not None:
            lane_store.write_chunk(i, a, b, out)
        else:
            results[i] = out
        finished += b - a
        if progress is not None:
            progress(finished, n_lanes)

    def chunk_inputs(i: int) -> dict[str, np.ndarray]:
        a, b = bounds[i]
        return {name: np.ascontiguousarray(arr[a:b]) for name, arr in arrays.items()}

    if client is None:
        for i in todo:
            complete(i, task(model, **chunk_inputs(i)))
    elif todo and isinstance(client, concurrent.futures.Executor):
        packed = portable(model)
        pending = {client.submit(_run_portable, task, packed, chunk_inputs(i)): i for i in todo}
        try:
            for fut in concurrent.futures.as_completed(pending):
                complete(pending[fut], fut.result())
        finally:  # an interrupted run leaves no queued chunk behind
            for fut in pending:
                fut.cancel()
    elif todo:
        from dask.distributed import as_completed

        # the packed model (a few kB) goes with every task rather than scattered once: a task
        # whose worker dies is then simply run again elsewhere
        packed = portable(model)
        futures = {client.submit(_run_portable, task, packed, chunk_inputs(i), pure=False): i
                   for i in todo}
        for fut in as_completed(futures):
            complete(futures[fut], fut.result())
            fut.release()
    if lane_store is not None:
        return lane_store.read()
    return _concat(results)  # type: ignore[arg-type]


def _open_store(store: Any) -> LaneStore | None:
    if store is None:
        return None
    return store if isinstance(store, LaneStore) else LaneStore(store)
