"""Stores into arrays reached through tuples kept by numba's dead-code elimination, in
geardyn's compiles.

numba's dead-code elimination (``numba.core.ir_utils.remove_dead``, run by its
``InlineOverloads`` pass after it inlines an ``overload(..., inline="always")``, and by
``InlineClosureLikes``) drops an array store (``A[i] = v``) when neither ``A`` nor an alias of
it is live afterwards and ``A`` is not known to alias an argument. Its alias analysis
(``find_potential_aliases``) follows copies, ``getitem`` and some attributes and calls, but not
tuple unpacking (``exhaust_iter``: ``a, b = t``), tuple construction (``build_tuple``) or
iteration over a tuple: an array unpacked from a tuple argument and written last in the
function (as an inlined helper does) is taken for a dead local, and its store is removed
(numba 0.68; numba PR #7167 covers tuple construction). geardyn's kernels pass their block
arrays in tuples and unpack them in inlined helpers: the sweep's count of steps at the split
limit (``unresolved``) was lost that way in the fused block loop.

:func:`tuple_aliases` registers, for the compiles inside it (geardyn's pipelines enter it, see
:class:`geardyn._jit_target.WidthCompiler`), an alias-analysis extension that links the
result of those tuple operations with their operands, so such a store is live wherever the
tuple (the argument) is. Other code compiled by numba in the process is analysed as numba does.
The extension only adds aliases: it removes nothing and changes no store that numba keeps.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from numba.core import ir, ir_utils

#: The IR expressions whose result may hold (or be) an array of their operands.
TUPLE_OPS = frozenset({"exhaust_iter", "build_tuple", "getiter", "iternext", "pair_first",
                       "typed_getitem"})

_DEPTH = threading.local()


def _active() -> bool:
    return getattr(_DEPTH, "n", 0) > 0


def _link(lhs: str, rhs: str, alias_map: dict[str, set[str]], arg_aliases: set[str]) -> None:
    """Record that ``lhs`` may alias ``rhs`` (as numba's own analysis records an alias)."""
    if rhs in arg_aliases:
        arg_aliases.add(lhs)
        return
    alias_map.setdefault(rhs, set()).add(lhs)
    alias_map.setdefault(lhs, set()).add(rhs)


def _operands(expr: ir.Expr) -> list[ir.Var]:
    return list(expr.items) if expr.op == "build_tuple" else [expr.value]


def _make_extension(previous: Callable[..., Any] | None) -> Callable[..., Any]:
    def extension(instr: ir.Assign, args: Any, typemap: Any, func_ir: Any,
                  alias_map: dict[str, set[str]], arg_aliases: set[str]) -> None:
        if previous is not None:
            previous(instr, args, typemap, func_ir, alias_map, arg_aliases)
        expr = instr.value
        if not (_active() and isinstance(expr, ir.Expr) and expr.op in TUPLE_OPS):
            return
        lhs = instr.target.name
        if ir_utils.is_immutable_type(lhs, typemap):
            return
        for var in _operands(expr):
            if not ir_utils.is_immutable_type(var.name, typemap):
                _link(lhs, var.name, alias_map, arg_aliases)

    extension.geardyn_tuple_alias = True  # type: ignore[attr-defined]
    return extension


def _register() -> None:
    """Install the extension for ``ir.Assign`` once (after any other one, which still runs)."""
    current = ir_utils.alias_analysis_extensions.get(ir.Assign)
    if current is None or not getattr(current, "geardyn_tuple_alias", False):
        ir_utils.alias_analysis_extensions[ir.Assign] = _make_extension(current)


@contextmanager
def tuple_aliases() -> Iterator[None]:
    """numba's alias analysis follows tuples (see above) for the compiles run inside."""
    _register()
    _DEPTH.n = getattr(_DEPTH, "n", 0) + 1
    try:
        yield
    finally:
        _DEPTH.n -= 1
