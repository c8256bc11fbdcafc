"""Parallel runs of a compiled worker on threads, without numba's ``parallel=True``.

The generated kernels' parallel entry points (the sweep, the Lyapunov lane blocks) call a
compiled worker (``nogil``: it releases the GIL) once per worker index, each on its own slice of
the work with no shared state but disjoint outputs. Running those calls on Python threads costs
nothing measurable against minutes-long workers, and spares the compile of a ``parallel=True``
function (numba's parfor passes and the re-optimisation of the whole worker's code inside it),
which took about as long as the worker's own compile. A worker's arithmetic does not depend on
the thread that runs it: results are bitwise the same for any thread count.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numba


def run_workers(worker: Callable[..., Any], n: int, args: tuple, threads: int | None = None
                ) -> None:
    """``worker(w, *args)`` for w in 0..n-1 on up to ``threads`` threads (default numba's thread
    count, :func:`numba.get_num_threads` of the calling thread), each thread taking the next
    index when it is free; one index or one thread: in the calling thread."""
    threads = max(1, min(int(threads or numba.get_num_threads()), n))
    if threads == 1:
        for w in range(n):
            worker(w, *args)
        return
    with ThreadPoolExecutor(max_workers=threads) as pool:
        for _ in pool.map(lambda w: worker(w, *args), range(n)):
            pass
