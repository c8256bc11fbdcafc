"""Python's full garbage collections held back while geardyn compiles.

numba's compiler allocates millions of objects (IR, types, LLVM IR text), many in reference
cycles. Python's cyclic collector runs a full collection (every tracked object of the process)
whenever enough objects have survived into its oldest generation, and the compiler's own live
objects make each one slow (the measured share is in bench/RESULTS.md). The young generations
hold the compiler's short-lived cycles and are still collected as usual.

:func:`young_collections` raises the collector's third threshold (full collections per
collections of the middle generation) to :data:`FULL_EVERY` for the outermost compile inside
it and restores the process's thresholds when that compile returns (a
:func:`geardyn._scoped_patch.scoped_patch` guard); code outside geardyn's compiles collects as
before. Entered under numba's compiler lock (one compile at a time).
"""

from __future__ import annotations

import gc
from collections.abc import Iterator

from geardyn._scoped_patch import scoped_patch

#: The collector's third threshold during a compile (Python's default is 10).
FULL_EVERY = 100


@scoped_patch
def young_collections() -> Iterator[None]:
    """Full collections at most every :data:`FULL_EVERY` middle-generation collections inside
    (re-entrant; the outermost entry sets the thresholds, the last exit restores them)."""
    saved = gc.get_threshold()
    if saved[0] > 0:  # a threshold of 0 disables the collector: left as it is
        gc.set_threshold(saved[0], saved[1], max(saved[2], FULL_EVERY))
    yield
    gc.set_threshold(*saved)
