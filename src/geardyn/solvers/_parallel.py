"""Parallel runs of a compiled worker on threads, without numba's ``parallel=True``.

The generated kernels' parallel entry points (the sweep, the Lyapunov lane blocks) call a
compiled worker (``nogil``: it releases the GIL) once per worker index, each on its own slice of
the work with no shared state but disjoint outputs. Running those calls on Python threads
spares the compile of a ``parallel=True`` function (numba's parfor passes and the
re-optimisation of the whole worker's code inside it), which took about as long as the
worker's own compile. The threads are kept between calls (a pool per calling thread and
thread count: starting two threads cost ~0.1 ms of CPU per call, ~1 % of a Lyapunov bench
run); a forked child starts its own. A worker's arithmetic does not depend on the thread that
runs it: results are bitwise the same for any thread count.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, wait
from typing import Any

import numba

#: The calling thread's pools, by thread count, with the process that started them.
_POOLS = threading.local()


def _pool(threads: int) -> ThreadPoolExecutor:
    """The calling thread's pool of ``threads`` threads (started on first use, and again in a
    forked child, whose copy of the parent's pool has no threads)."""
    pid = os.getpid()
    if getattr(_POOLS, "pid", None) != pid:
        _POOLS.pid = pid
        _POOLS.by_count = {}
    pool = _POOLS.by_count.get(threads)
    if pool is None:
        pool = _POOLS.by_count[threads] = ThreadPoolExecutor(
            max_workers=threads, thread_name_prefix="geardyn-worker")
    return pool


def run_workers(worker: Callable[..., Any], n: int, args: tuple, threads: int | None = None
                ) -> None:
    """``worker(w, *args)`` for w in 0..n-1 on up to ``threads`` threads (default numba's thread
    count, :func:`numba.get_num_threads` of the calling thread), each thread taking the next
    index when it is free; one index or one thread: in the calling thread. A worker's error is
    raised once every worker has returned."""
    threads = max(1, min(int(threads or numba.get_num_threads()), n))
    if threads == 1:
        for w in range(n):
            worker(w, *args)
        return
    pool = _pool(threads)
    futures = [pool.submit(worker, w, *args) for w in range(n)]
    wait(futures)  # every worker done (none left writing its outputs) before any error is raised
    for future in futures:
        future.result()
