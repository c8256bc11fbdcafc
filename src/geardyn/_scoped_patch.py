"""Process-wide patches held only while geardyn compiles: one re-entrant, thread-safe guard.

geardyn changes a few process-wide things for the length of its own compiles (numba's IR
inlining and function numbering, its alias analysis, the garbage collector's thresholds), and
must leave them as they were afterwards. :func:`scoped_patch` makes such a guard from a
generator function that yields once: the code before its ``yield`` applies the patch, the code
after it undoes it. Entering the guard (``with guard():``) runs the generator to its ``yield``
on the outermost entry, the first while no caller of any thread is inside; the last exit runs
the rest, also when the body raised (the generator sees no exception: the exit that restores
need not be the one that failed); the entries in between change nothing. A lock makes the count
and the patch and restore one step each, so callers on several threads share one patch, set
by the first to enter and undone by the last to leave.

The patch and the restore must not enter the same guard.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager


class ScopedPatch:
    """A re-entrant guard around ``patch`` (a one-yield generator function, see the module
    docstring); call it for a context manager. :attr:`depth` is how many callers are inside."""

    def __init__(self, patch: Callable[[], Iterator[None]]) -> None:
        self._patch = patch
        self._lock = threading.Lock()
        self._depth = 0
        self._open: Iterator[None] | None = None  # the outermost entry's generator
        functools.update_wrapper(self, patch)

    @property
    def depth(self) -> int:
        """How many entries (of all threads) are inside now; the patch is applied iff > 0."""
        return self._depth

    @contextmanager
    def __call__(self) -> Iterator[None]:
        self._enter()
        try:
            yield
        finally:
            self._exit()

    def _enter(self) -> None:
        with self._lock:
            if self._depth == 0:
                steps = self._patch()
                if next(steps, _DONE) is _DONE:
                    raise RuntimeError(f"{self._patch.__qualname__} did not yield")
                self._open = steps
            self._depth += 1

    def _exit(self) -> None:
        with self._lock:
            self._depth -= 1
            if self._depth > 0:
                return
            steps, self._open = self._open, None
            if next(steps, _DONE) is not _DONE:
                raise RuntimeError(f"{self._patch.__qualname__} yielded more than once")


_DONE = object()


def scoped_patch(patch: Callable[[], Iterator[None]]) -> ScopedPatch:
    """Decorator: the re-entrant, thread-safe guard of ``patch`` (see the module docstring)."""
    return ScopedPatch(patch)
