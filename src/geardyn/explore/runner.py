"""Long computations off the page's thread, the newest request winning.

:class:`Runner` runs one job at a time in a worker thread. Submitting a job supersedes every
earlier one: a superseded job that is still running is stopped at its next progress report
(:class:`Superseded` is raised inside it), and its result or error is discarded. A job that
fails reports the message through ``on_error`` and the caller keeps its last good result.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

__all__ = ["Runner", "Superseded"]


class Superseded(Exception):  # noqa: N818 (a signal, not an error)
    """Raised inside a running job once a newer one has been submitted."""


class Runner:
    """One worker thread; :meth:`submit` a job ``job(progress)``, where ``progress(done,
    total)`` reports and raises :class:`Superseded` when the job is no longer wanted."""

    def __init__(self, describe_error: Callable[[BaseException], str] = str) -> None:
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="geardyn-explore")
        self._lock = threading.Lock()
        self._generations: dict[str, int] = {}
        self._futures: list[Future] = []
        self.describe_error = describe_error

    def generation(self, key: str = "") -> int:
        """The newest job of kind ``key``."""
        return self._generations.get(key, 0)

    def current(self, generation: int, key: str = "") -> bool:
        """True while job ``generation`` of kind ``key`` is the newest of its kind."""
        return generation == self._generations.get(key, 0)

    def submit(self, job: Callable[[Callable[[int, int], None]], Any],
               on_done: Callable[[Any], None], on_error: Callable[[str], None],
               on_progress: Callable[[int, int], None] | None = None, key: str = "") -> int:
        """Run ``job`` after the jobs before it (one thread: the compiled kernels never run
        twice at once); it supersedes the earlier jobs of the same kind ``key`` (a new diagram
        the running diagram, not a running orbit). ``on_done(result)``, ``on_error(message)``
        and ``on_progress(done, total)`` are called, from the worker thread, only while this job
        is the newest of its kind. Returns the job's generation (see :meth:`current`)."""
        with self._lock:
            gen = self._generations.get(key, 0) + 1
            self._generations[key] = gen

        def progress(done: int, total: int) -> None:
            if not self.current(gen, key):
                raise Superseded
            if on_progress is not None:
                on_progress(done, total)

        def work() -> None:
            if not self.current(gen, key):
                return
            try:
                result = job(progress)
            except Superseded:
                return
            except Exception as exc:  # reported, never raised into the worker
                if self.current(gen, key):
                    on_error(self.describe_error(exc))
                return
            if self.current(gen, key):
                on_done(result)

        self._futures = [f for f in self._futures if not f.done()]
        self._futures.append(self._pool.submit(work))
        return gen

    def cancel(self, key: str = "") -> None:
        """Supersede the running (or waiting) job of kind ``key`` without starting another."""
        with self._lock:
            self._generations[key] = self._generations.get(key, 0) + 1

    def wait(self, timeout: float | None = None) -> None:
        """Block until every submitted job has finished (for tests and shutdown)."""
        for f in list(self._futures):
            f.result(timeout)

    def shutdown(self) -> None:
        for key in list(self._generations):
            self.cancel(key)
        self._pool.shutdown(wait=False, cancel_futures=True)
