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

numba also runs its whole untyped pipeline (bytecode analysis, closure inlining, rewrites,
nested inlining, SSA) on an ``inline="always"`` function once per call site
(``InlineWorker.run_untyped_passes``): a helper inlined at 40 sites is analysed 40 times. Inside
geardyn's compiles the result is kept per function (and per the flags the untyped pipeline
reads) for the outermost compile: each later call site takes a copy of the FunctionIR (blocks
copied, a fresh ``FunctionIdentity``, so that the inlined variables are named per call site as
numba names them), which ``inline_ir`` copies again before it changes anything. The IR of an
untyped pipeline depends only on the function, its globals (fixed during a compile) and those
flags, so the inlined code is the same.

numba types an ``overload(..., inline="always")`` by compiling its implementation for the
argument types (``Dispatcher.get_call_template``, run for its side effect: a ``literally`` in
the implementation must dispatch first), lowering and optimising it too, then types the
implementation's IR once more for the inlining and never uses the compiled function. An
implementation marked :data:`INLINE_ONLY` (geardyn's tuple helpers, which take no literal
arguments) is not compiled inside geardyn's compiles: the inlined IR and its types are the
same, so the compiled code is the same.

numba keeps an overload's implementation per argument types and per the whole set of flags
of the function being compiled (``_OverloadFunctionTemplate._get_impl``), so a builtin such as
``max`` or ``np.zeros`` is compiled anew for every combination of flags among its callers
(geardyn's differ in ``no_cpython_wrapper``, ``noalias``, ``forceinline``, ...). The
implementation's compile takes from its caller's flags only those numba's CPU target
inherits (``CPUTargetOptions.finalize``: ``nrt``, ``fastmath``, ``error_model``,
``forceinline``); inside geardyn's compiles (:func:`overload_keys`) the implementation is
kept per those, so callers that differ in other flags share it: the same implementation,
compiled with the same flags. It is compiled without a C entry point (``no_cfunc_wrapper``, as
it already is without a Python one): compiled code calls an implementation, never C (a
wrapper cost about as much as a small implementation's own lowering).

They are installed only inside geardyn's own compiles (:func:`block_copy`, entered under numba's
compiler lock by :func:`geardyn.solvers.kernels._quiet_compile`); numba outside them is
untouched.
"""

from __future__ import annotations

import copy as _copy
from collections.abc import Iterator
from typing import Any

from numba.core import bytecode as _bytecode
from numba.core import dispatcher as _dispatcher
from numba.core import inline_closurecall as _icc
from numba.core import ir as _ir
from numba.core import targetconfig as _targetconfig
from numba.core import typing as _typing
from numba.core.typing import templates as _templates

from geardyn._scoped_patch import scoped_patch


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
_ORIGINAL_UNTYPED = _icc.InlineWorker.run_untyped_passes
#: Attribute of an ``overload(..., inline="always")`` implementation (the Python function it
#: returns) that takes no literal arguments: typed, not compiled, for its inlining.
INLINE_ONLY = "_geardyn_inline_only"
_ORIGINAL_TEMPLATE = _dispatcher.Dispatcher.get_call_template
#: Untyped IR per (function, flags the untyped pipeline reads), for the outermost compile.
_UNTYPED: dict[tuple, Any] = {}


def _untyped_key(worker: Any, func: Any, enable_ssa: bool) -> tuple:
    flags = worker.flags
    return (func, bool(enable_ssa), bool(flags.no_rewrites), bool(flags.enable_looplift),
            bool(flags.enable_pyobject), bool(flags.force_pyobject))


def _run_untyped_passes(self: Any, func: Any, enable_ssa: bool = False) -> Any:
    """numba's ``run_untyped_passes`` run once per function and flags; a copy per call."""
    if self._permit_update_type_and_call_maps:  # a typed inliner may change its callee's maps
        return _ORIGINAL_UNTYPED(self, func, enable_ssa)
    key = _untyped_key(self, func, enable_ssa)
    kept = _UNTYPED.get(key)
    if kept is None:
        kept = _UNTYPED[key] = _ORIGINAL_UNTYPED(self, func, enable_ssa)
    else:
        self.flags.enable_ssa = enable_ssa  # as numba's own run sets it on the caller's flags
    ir = kept.copy()
    ir.func_id = _bytecode.FunctionIdentity.from_function(func)
    return ir


def _get_call_template(self: Any, args: Any, kws: Any) -> Any:
    """numba's ``get_call_template`` without the compile for an :data:`INLINE_ONLY`
    implementation (its caller, the overload's typing, takes only the folded argument types)."""
    if not getattr(self.py_func, INLINE_ONLY, False):
        return _ORIGINAL_TEMPLATE(self, args, kws)
    pysig, args = self._compiler.fold_argument_types(args, kws)
    name = self.py_func.__name__
    template = _typing.make_concrete_template(f"CallTemplate({name})", key=name,
                                              signatures=self.nopython_signatures)
    return template, pysig, args, {}


#: The flags an overload's implementation inherits from its caller's compile (numba's
#: ``CPUTargetOptions.finalize``).
INHERITED_FLAGS = ("nrt", "fastmath", "error_model", "forceinline")
_ORIGINAL_GET_IMPL = _templates._OverloadFunctionTemplate._get_impl


def _inherited(flags: Any) -> Any:
    """The values of :data:`INHERITED_FLAGS` in ``flags`` (hashable), None without flags."""
    if flags is None:
        return None
    return tuple(frozenset(v.flags) if n == "fastmath" else v
                 for n, v in ((n, getattr(flags, n)) for n in INHERITED_FLAGS))


def _get_impl(self: Any, args: Any, kws: Any) -> Any:
    """numba's ``_OverloadFunctionTemplate._get_impl`` with the implementation kept per the
    flags it inherits (:data:`INHERITED_FLAGS`), not per all of the caller's flags."""
    flags = _targetconfig.ConfigStack.top_or_none()
    cache_key = self.context, tuple(args), tuple(kws.items()), _inherited(flags)
    try:
        return self._impl_cache[cache_key]
    except KeyError:
        pass
    return self._build_impl(cache_key, args, kws)


def _get_jit_decorator(self: Any) -> Any:
    """numba's jit decorator of an overload's implementation, without a C entry point unless
    the overload asks for one."""
    jitter = _ORIGINAL_JIT_DECORATOR(self)

    def decorator(**options: Any) -> Any:
        return jitter(**{"no_cfunc_wrapper": True, **options})
    return decorator


_ORIGINAL_JIT_DECORATOR = _templates._OverloadFunctionTemplate._get_jit_decorator


@scoped_patch
def overload_keys() -> Iterator[None]:
    """Overload implementations kept per the flags they inherit, compiled without a C entry
    point (re-entrant; to be entered under numba's compiler lock)."""
    template = _templates._OverloadFunctionTemplate
    saved = template._get_impl, template._get_jit_decorator
    template._get_impl, template._get_jit_decorator = _get_impl, _get_jit_decorator
    yield
    template._get_impl, template._get_jit_decorator = saved


def _inline_ir(self: Any, *args: Any, **kwargs: Any) -> Any:
    saved, _SHIM.memos = _SHIM.memos, {}  # a fresh memo per inlined call site
    try:
        return _ORIGINAL(self, *args, **kwargs)
    finally:
        _SHIM.memos = saved


@scoped_patch
def block_copy() -> Iterator[None]:
    """numba's ``inline_ir`` with the shared block copy inside, its untyped pipeline kept per
    function, :data:`INLINE_ONLY` implementations typed, not compiled (re-entrant; to be
    entered under numba's compiler lock, so that no other thread compiles meanwhile)."""
    worker = _icc.InlineWorker
    disp = _dispatcher.Dispatcher
    saved = _icc.copy, worker.inline_ir, worker.run_untyped_passes, disp.get_call_template
    _icc.copy = _SHIM
    worker.inline_ir = _inline_ir
    worker.run_untyped_passes = _run_untyped_passes
    disp.get_call_template = _get_call_template
    yield
    _UNTYPED.clear()
    (_icc.copy, worker.inline_ir, worker.run_untyped_passes,
     disp.get_call_template) = saved
