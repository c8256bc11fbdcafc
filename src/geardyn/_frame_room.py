"""Room on the Python frame stack for a compile, so that numba's deep calls cross no chunk edge.

CPython 3.11+ keeps a thread's Python frames on a stack of memory chunks (16 KiB, or the
smallest power-of-two multiple of that which holds the frame that needs a new one). A chunk is
allocated by ``mmap`` when a frame does not fit in the current one, and unmapped as soon as its
first frame returns. Where a hot loop inside numba's compiler calls a function just across a
chunk's edge, every call maps and unmaps a chunk and touches its pages afresh: measured in a
cold compile of the planetary set's sweep in a worker thread, 2.7 million ``mmap``/``munmap``
pairs of 16 KiB and ~14 s of system CPU more than the same compile at another depth. Which
depth is unlucky depends on everything above the compile on the stack (the thread, the caller).

:func:`call_with_room` calls ``fn(arg)`` from a trampoline whose frame declares a large value
stack (:data:`ROOM_WORDS`, never touched: its pages are only reserved): the trampoline's frame
opens a chunk of its own, :data:`CHUNK_BYTES`, and everything ``fn`` calls fits in the rest of
that chunk (numba's deepest compiles use a small part of it), so no chunk is mapped or unmapped
inside; the one chunk is unmapped when ``fn`` returns. Only the frame's memory changes: the
call and its result are ``fn(arg)``'s.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")

#: The trampoline frame's declared value-stack size, in pointers (2.4 MiB of address space).
ROOM_WORDS = 300_000
#: The chunk the trampoline's frame opens (CPython doubles 16 KiB until the frame fits).
CHUNK_BYTES = 4 << 20


def _trampoline(fn: Callable[[Any], T], arg: Any) -> T:
    return fn(arg)


_trampoline.__code__ = _trampoline.__code__.replace(co_stacksize=ROOM_WORDS)


def call_with_room(fn: Callable[[Any], T], arg: Any) -> T:
    """``fn(arg)``, called from a frame that opens a frame-stack chunk of its own (see the
    module docstring)."""
    return _trampoline(fn, arg)
