"""numba's IR inlining with the callee's blocks copied in one pass (geardyn.solvers._inline_copy):
the same copies, each object copied once; installed only inside geardyn's own compiles."""

from __future__ import annotations

import copy
import re

import numba as nb
import numpy as np
import pytest
from numba.core import dispatcher
from numba.core import inline_closurecall as icc
from numba.core.compiler import run_frontend
from numba.core.compiler_lock import global_compiler_lock
from numba.core.typing import templates

from geardyn.solvers import _inline_copy
from geardyn.solvers._inline_copy import block_copy, overload_keys

_SOURCE = '''
@nb.njit(inline="always")
def callee(x, n):
    acc = 0.0
    for j in range(n):
        if x > j:
            acc += x * j
        else:
            acc -= j / (1.0 + x * x)
    return acc


@nb.njit
def caller(x, n):
    return callee(x, n) + 2.0 * callee(-x, n + 1) - callee(0.5 * x, 2 * n)
'''


def _caller():
    """A fresh compiled function with an inlined callee of several blocks, called three times."""
    scope = {"nb": nb}
    exec(compile(_SOURCE, "<test_inline_copy>", "exec"), scope)  # noqa: S102 (fixed text)
    return scope["caller"]


def _numba_untouched() -> bool:
    template = templates._OverloadFunctionTemplate
    return (icc.copy is copy and icc.InlineWorker.inline_ir is _inline_copy._ORIGINAL
            and icc.InlineWorker.run_untyped_passes is _inline_copy._ORIGINAL_UNTYPED
            and dispatcher.Dispatcher.get_call_template is _inline_copy._ORIGINAL_TEMPLATE
            and template._get_impl is _inline_copy._ORIGINAL_GET_IMPL
            and template._get_jit_decorator is _inline_copy._ORIGINAL_JIT_DECORATOR
            and not _inline_copy._UNTYPED)


def _asm_without_names(dispatcher) -> list[str]:
    """The assembly of ``dispatcher``'s one compiled signature, symbol names replaced (numba
    numbers its symbols per compile)."""
    asm = dispatcher.inspect_asm(dispatcher.signatures[0])
    return [re.sub(r"_ZN[0-9A-Za-z_$.]*", "SYM", s) for s in asm.splitlines()
            if not s.lstrip().startswith(".file")]


def test_the_callee_blocks_share_one_scope_and_equal_numbas_copies():
    def f(x, n):
        acc = 0.0
        for j in range(n):
            if x > j:
                acc += x
            else:
                acc -= j
        return acc

    ir = run_frontend(f)
    assert len(ir.blocks) > 3
    plain = {k: copy.deepcopy(b) for k, b in ir.blocks.items()}  # numba's own: a memo per block
    _inline_copy._SHIM.memos = {}
    try:
        shared = {k: _inline_copy._SHIM.deepcopy(b) for k, b in ir.blocks.items()}
    finally:
        _inline_copy._SHIM.memos = None
    assert len({id(b.scope) for b in plain.values()}) == len(plain)  # the scope copied per block
    assert len({id(b.scope) for b in shared.values()}) == 1  # once, as in the original
    assert all(b.scope is not ir.blocks[k].scope for k, b in shared.items())  # a copy
    for k, b in ir.blocks.items():
        assert shared[k] == plain[k] == b
        assert [str(s) for s in shared[k].body] == [str(s) for s in b.body]


def test_a_function_compiled_with_the_block_copy_gives_the_same_results():
    xs = np.linspace(-3.0, 7.0, 41)
    own = _caller()
    with global_compiler_lock, block_copy():
        assert not _numba_untouched()
        shared = _caller()
        shared.compile("float64(float64, int64)")
    assert _numba_untouched()
    own.compile("float64(float64, int64)")
    for x in xs:
        for n in (0, 1, 5, 9):
            ref = own.py_func(x, n)  # the Python function, uncompiled
            assert shared(x, n) == own(x, n)
            assert shared(x, n) == pytest.approx(ref, rel=1e-12, abs=1e-12)
    # the two compiled functions are the same code: their assembly differs only in names
    asm_own = own.inspect_asm(own.signatures[0])
    asm_shared = shared.inspect_asm(shared.signatures[0])
    assert len(asm_own.splitlines()) == len(asm_shared.splitlines())


def test_the_untyped_pipeline_runs_once_per_inlined_function_and_the_code_is_the_same():
    """numba runs its untyped pipeline on an inlined callee at every call site (three here);
    inside a geardyn compile it runs once, and the machine code is numba's own, instruction
    for instruction."""
    calls: list = []

    def counting(self, func, enable_ssa=False):
        calls.append(func.__name__)
        return original(self, func, enable_ssa)

    original = _inline_copy._ORIGINAL_UNTYPED
    own, shared = _caller(), _caller()
    try:
        icc.InlineWorker.run_untyped_passes = counting
        own.compile("float64(float64, int64)")
        assert calls.count("callee") == 3  # numba's own: one run per call site
        del calls[:]
        _inline_copy._ORIGINAL_UNTYPED = counting
        with global_compiler_lock, block_copy():
            shared.compile("float64(float64, int64)")
        assert calls.count("callee") == 1
    finally:
        _inline_copy._ORIGINAL_UNTYPED = original
        icc.InlineWorker.run_untyped_passes = original
    assert _numba_untouched()
    assert _asm_without_names(shared) == _asm_without_names(own)
    for x in np.linspace(-3.0, 7.0, 11):
        assert shared(x, 4) == own(x, 4)


def test_numba_is_restored_after_each_compile_and_on_errors():
    assert _numba_untouched()
    with global_compiler_lock, block_copy():
        with block_copy():  # re-entrant: a compile inside a compile
            assert icc.copy is _inline_copy._SHIM
        assert icc.copy is _inline_copy._SHIM
    assert _numba_untouched()
    with pytest.raises(RuntimeError, match="inside"):
        with global_compiler_lock, block_copy():
            raise RuntimeError("inside")
    assert _numba_untouched()


def test_geardyns_compiles_leave_numba_untouched():
    import geardyn
    from shared_models import oscillator

    geardyn.simulate(oscillator(zeta=0.1, F=1.0, Omega=1.3), y0=np.zeros(2),
                     run=geardyn.RunSettings(transient=0.0, samples=2))
    assert _numba_untouched()



def _counting(predicate):
    """A context manager counting numba's compiles (``add_overload``) of the dispatchers for
    which ``predicate(dispatcher)``; yields the list of their compile results."""
    import contextlib

    @contextlib.contextmanager
    def counting():
        counted = []
        add = dispatcher.Dispatcher.add_overload

        def add_overload(self, cres):
            if predicate(self):
                counted.append(cres)
            return add(self, cres)

        dispatcher.Dispatcher.add_overload = add_overload
        try:
            yield counted
        finally:
            dispatcher.Dispatcher.add_overload = add
    return counting()


def _stub_unguarded(x):
    """An overload target (typed outside the guard)."""


def _stub_guarded(x):
    """An overload target (typed inside the guard)."""


def _inline_only(stub, made):
    def implementation(x):
        def impl(x):
            return x * x + 1.0
        setattr(impl, _inline_copy.INLINE_ONLY, True)
        made.append(impl)
        return impl

    nb.extending.overload(stub, inline="always")(implementation)

    @nb.njit
    def caller(x):
        return stub(x) - 2.0 * stub(0.5 * x)
    return caller


def test_an_inline_only_overload_is_typed_not_compiled_and_gives_the_same_results():
    want = (3.0 * 3.0 + 1.0) - 2.0 * (1.5 * 1.5 + 1.0)
    made = []
    outside = _inline_only(_stub_unguarded, made)
    with _counting(lambda d: d.py_func in made) as counted:
        assert outside(3.0) == want
    assert counted  # numba compiles the implementation it inlines
    made.clear()
    inside = _inline_only(_stub_guarded, made)
    with _counting(lambda d: d.py_func in made) as counted:
        with global_compiler_lock, block_copy():
            assert inside(3.0) == want
    assert made and not counted  # typed for the inlining, not compiled
    assert _numba_untouched()


_MAX_CALLERS = """
@nb.njit(no_cfunc_wrapper=True)
def a(x, y):
    return max(x, y) + np.int16(1)


@nb.njit(no_cfunc_wrapper=True, no_cpython_wrapper=True)
def b(x, y):
    return max(x, y) + np.int16(2)


@nb.njit
def c(x, y):
    return b(x, y) + max(y, x)
"""


def _max_compiles(guarded: bool, dtype) -> int:
    """Compiles of numba's ``max`` for callers that differ only in their entry points (flags
    the implementation does not inherit)."""
    scope = {"nb": nb, "np": np}
    exec(compile(_MAX_CALLERS, "<test_overload_keys>", "exec"), scope)  # noqa: S102 (fixed text)
    x, y = dtype(1), dtype(3)
    with _counting(lambda d: d.py_func.__qualname__.startswith("ol_max")) as counted:
        with global_compiler_lock:
            if guarded:
                with overload_keys():
                    got = (scope["a"](x, y), scope["c"](x, y))
            else:
                got = (scope["a"](x, y), scope["c"](x, y))
    assert got == (4, 8)
    return len(counted)


def test_overload_implementations_are_kept_per_inherited_flags():
    """numba compiles ``max`` once per caller's flags; inside the guard once per the flags it
    inherits (the same for all three callers). Argument types no other test uses, so that
    numba has compiled ``max`` for them in neither way before."""
    assert _max_compiles(guarded=False, dtype=np.int16) >= 2
    assert _max_compiles(guarded=True, dtype=np.uint16) == 1
    assert _numba_untouched()
