"""geardyn._frame_room: a compile's calls open no frame-stack chunk of their own.

At some call depths a thread's next Python frame does not fit in what is left of its current
frame-stack chunk: each call there maps and unmaps a chunk (page faults every time). Found by
scanning the depth, the same calls made through :func:`call_with_room` there fault (almost)
never.
"""

from __future__ import annotations

import resource
import sys

import pytest

from geardyn._frame_room import ROOM_WORDS, call_with_room

CALLS = 2000


def _leaf() -> None:
    pass


#: A leaf frame of about half a chunk (8 KiB of declared value stack): at about half the depths
#: it does not fit in what is left of the current 16 KiB chunk.
_leaf.__code__ = _leaf.__code__.replace(co_stacksize=1000)


def _loop(_: object) -> int:
    for _ in range(CALLS):
        _leaf()
    return 7


def _faults(depth: int, room: bool) -> int:
    """Minor page faults of :data:`CALLS` calls of a leaf function made ``depth`` frames down."""
    if depth > 0:
        return _faults(depth - 1, room)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    assert (call_with_room(_loop, None) if room else _loop(None)) == 7
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


def test_result_and_errors_pass_through() -> None:
    assert call_with_room(lambda x: x + 1, 41) == 42
    with pytest.raises(KeyError):
        call_with_room({}.__getitem__, "missing")
    assert ROOM_WORDS * 8 > 1 << 20  # the trampoline's frame opens a chunk of over 1 MiB


@pytest.mark.skipif(sys.version_info < (3, 11), reason="frame-stack chunks: CPython 3.11+")
def test_no_chunk_thrashing_at_an_unlucky_depth() -> None:
    unlucky = [d for d in range(200) if _faults(d, room=False) >= CALLS]
    assert unlucky, "no depth where each call maps a chunk (CPython's frame stack changed?)"
    for depth in unlucky[:3]:
        assert _faults(depth, room=True) < CALLS // 10
