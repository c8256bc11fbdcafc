"""numba's IR inlining with the callee's blocks copied in one pass, while geardyn compiles.

numba inlines a function (``inline="always"``, an inlined overload) by deep-copying the
callee's IR twice, block by block (``InlineWorker.inline_ir``), each block with a memo of its
own. Every variable of a block refers to the function's one scope, which holds every variable
of the function, so each block's copy copies the whole scope again: O(blocks x variables) per
inlined call site, the larger part of numba's frontend time on the templates' big inlined
functions (the fused step loops, the out-of-line slot work). :func:`block_copy` makes the
blocks of one IR share one memo per call of ``inline_ir`` (keyed by the scope they share):
each object of the callee is copied once, and the copy keeps the sharing of the original (one
scope for all blocks, as numba's own IR has). The copied IR is otherwise the same, so the
compiled code is the same.

It is installed only inside geardyn's own compiles (:func:`block_copy`, entered under numba's
compiler lock by :func:`geardyn.solvers.kernels._quiet_compile`); numba outside them is
untouched.
"""

from __future__ import annotations

import copy as _copy
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from numba.core import inline_closurecall as _icc
from numba.core import ir as _ir


class _SharedBlockCopy:
    """A stand-in for the ``copy`` module in numba's ``inline_closurecall`` (whose only use is
    ``copy.deepcopy(block)`` in ``inline_ir``): a block is copied with the memo of its scope
    for the current ``inline_ir`` call; anything else as ``copy`` does."""

    def __init__(self) -> None:
        self.memos: dict[int, dict] | None = None

    def deepcopy(self, x: Any, memo: dict | None = None) -> Any:
        if memo is None and self.memos is not None and isinstance(x, _ir.Block):
            memo = self.memos.setdefault(id(x.scope), {})
        return _copy.deepcopy(x, memo)

    def __getattr__(self, name: str) -> Any:
        return getattr(_copy, name)


_SHIM = _SharedBlockCopy()
_ORIGINAL = _icc.InlineWorker.inline_ir
_DEPTH = [0]


def _inline_ir(self: Any, *args: Any, **kwargs: Any) -> Any:
    saved, _SHIM.memos = _SHIM.memos, {}  # a fresh memo per inlined call site
    try:
        return _ORIGINAL(self, *args, **kwargs)
    finally:
        _SHIM.memos = saved


@contextmanager
def block_copy() -> Iterator[None]:
    """numba's ``inline_ir`` with the shared block copy inside (re-entrant; to be entered under
    numba's compiler lock, so that no other thread compiles meanwhile)."""
    if _DEPTH[0] == 0:
        _icc.copy = _SHIM
        _icc.InlineWorker.inline_ir = _inline_ir
    _DEPTH[0] += 1
    try:
        yield
    finally:
        _DEPTH[0] -= 1
        if _DEPTH[0] == 0:
            _icc.InlineWorker.inline_ir = _ORIGINAL
            _icc.copy = _copy
