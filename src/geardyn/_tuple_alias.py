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

:func:`tuple_aliases` installs, for the compiles inside it (geardyn's pipelines enter it, see
:class:`geardyn._jit_target.WidthCompiler`), an alias-analysis extension that links the
result of those tuple operations with their operands, so such a store is live wherever the
tuple (the argument) is, and removes it when the outermost of them returns (a
:func:`geardyn._scoped_patch.scoped_patch` guard). Other code compiled by numba in the process
is analysed as numba does.
The extension only adds aliases: it removes nothing and changes no store that numba keeps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

from numba.core import ir, ir_utils

from geardyn._scoped_patch import scoped_patch

#: The IR expressions whose result may hold (or be) an array of their operands.
TUPLE_OPS = frozenset({"exhaust_iter", "build_tuple", "getiter", "iternext", "pair_first",
                       "typed_getitem"})


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
        if not (tuple_aliases.depth and isinstance(expr, ir.Expr) and expr.op in TUPLE_OPS):
            return
        lhs = instr.target.name
        if ir_utils.is_immutable_type(lhs, typemap):
            return
        for var in _operands(expr):
            if not ir_utils.is_immutable_type(var.name, typemap):
                _link(lhs, var.name, alias_map, arg_aliases)

    return extension


@scoped_patch
def tuple_aliases() -> Iterator[None]:
    """numba's alias analysis follows tuples (see above) for the compiles run inside: the
    extension is installed in numba's table (after any other one for ``ir.Assign``, which still
    runs) by the outermost entry and the table restored by the last exit (re-entrant)."""
    table = ir_utils.alias_analysis_extensions
    previous = table.get(ir.Assign)
    table[ir.Assign] = ours = _make_extension(previous)
    yield
    if table.get(ir.Assign) is ours:  # an extension registered meanwhile keeps its place
        if previous is None:
            del table[ir.Assign]
        else:
            table[ir.Assign] = previous
