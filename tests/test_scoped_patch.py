"""The guard of geardyn's process-wide compile-time patches (geardyn._scoped_patch): the patch
applied by the outermost entry only, undone by the last exit (on errors too), shared by threads;
and each of geardyn's guards leaves numba and the collector as they were."""

from __future__ import annotations

import gc
import threading

import numba as nb
import numpy as np
import pytest
from numba.core import bytecode, ir, ir_utils

from geardyn._scoped_patch import scoped_patch
from geardyn._tuple_alias import tuple_aliases
from geardyn.solvers._compile_gc import young_collections
from geardyn.solvers._inline_copy import block_copy
from geardyn.solvers.kernels import unique_names


def _counting_guard(state: dict):
    """A guard that sets ``state["value"]`` to "patched" and counts its patches and restores."""
    @scoped_patch
    def guard():
        """Patch the state."""
        saved = state["value"]
        state["value"] = "patched"
        state["patches"] += 1
        yield
        state["value"] = saved
        state["restores"] += 1

    return guard


def _fresh() -> dict:
    return {"value": "original", "patches": 0, "restores": 0}


def test_nested_entries_patch_once_and_the_last_exit_restores():
    state = _fresh()
    guard = _counting_guard(state)
    assert guard.__doc__ == "Patch the state." and guard.__name__ == "guard"
    with guard():
        assert state["value"] == "patched" and guard.depth == 1
        with guard():
            with guard():
                assert guard.depth == 3
            assert state["value"] == "patched"
        assert state["value"] == "patched" and guard.depth == 1
    assert state == {"value": "original", "patches": 1, "restores": 1}
    assert guard.depth == 0
    with guard():  # usable again: a second outermost entry patches again
        assert state["value"] == "patched"
    assert state == {"value": "original", "patches": 2, "restores": 2}


def test_an_error_inside_restores_and_propagates():
    state = _fresh()
    guard = _counting_guard(state)
    with pytest.raises(KeyError, match="inner"):
        with guard():
            with guard():
                raise KeyError("inner")
    assert state == {"value": "original", "patches": 1, "restores": 1}
    assert guard.depth == 0
    with pytest.raises(ValueError, match="outer"):
        with guard():
            with guard():
                pass
            assert state["value"] == "patched"  # the inner exit left the patch in place
            raise ValueError("outer")
    assert state == {"value": "original", "patches": 2, "restores": 2}


def test_a_failed_patch_leaves_the_guard_closed():
    calls: list = []

    @scoped_patch
    def failing():
        calls.append("patch")
        raise OSError("cannot patch")
        yield  # pragma: no cover

    @scoped_patch
    def no_yield():
        return
        yield  # pragma: no cover

    for _ in range(2):  # the second entry tries again
        with pytest.raises(OSError, match="cannot patch"):
            with failing():
                pass  # pragma: no cover
        assert failing.depth == 0
    assert calls == ["patch", "patch"]
    with pytest.raises(RuntimeError, match="did not yield"):
        with no_yield():
            pass  # pragma: no cover
    assert no_yield.depth == 0


def test_two_threads_share_one_patch_undone_by_the_last_to_leave():
    """Thread A enters first and leaves first, while thread B is still inside: the patch stays
    until B leaves (the restore is the last exit's, whichever thread it is)."""
    state = _fresh()
    guard = _counting_guard(state)
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()
    seen: dict = {}

    def a():
        with guard():
            a_in.set()
            b_in.wait(10)
        a_out.set()

    def b():
        a_in.wait(10)
        with guard():
            b_in.set()
            a_out.wait(10)
            seen["after A left"] = (state["value"], guard.depth)

    threads = [threading.Thread(target=a), threading.Thread(target=b)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(20)
    assert seen["after A left"] == ("patched", 1)
    assert state == {"value": "original", "patches": 1, "restores": 1}


def test_many_threads_entering_at_once_never_see_the_patch_missing():
    state = _fresh()
    guard = _counting_guard(state)
    missing: list = []
    start = threading.Barrier(8)

    def work():
        start.wait(10)
        for _ in range(300):
            with guard():
                if state["value"] != "patched":
                    missing.append(state["value"])

    threads = [threading.Thread(target=work) for _ in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(60)
    assert not missing
    assert state["value"] == "original" and guard.depth == 0
    assert state["patches"] == state["restores"] >= 1


def test_geardyns_guards_patch_inside_and_restore_after():
    """Each guard of geardyn's compiles changes its process-wide state inside, nested, and
    leaves it as it was after (collector thresholds, numba's function numbering, its table of
    alias-analysis extensions, its inliner)."""
    from numba.core import inline_closurecall as icc

    saved_gc = gc.get_threshold()
    gc.set_threshold(700, 10, 10)
    ident = bytecode.FunctionIdentity
    numbering = ident._unique_ids
    extensions = dict(ir_utils.alias_analysis_extensions)
    inline_ir = icc.InlineWorker.inline_ir
    try:
        with pytest.raises(RuntimeError, match="inside"):
            with young_collections(), unique_names(), tuple_aliases(), block_copy():
                with young_collections(), unique_names(), tuple_aliases(), block_copy():
                    assert gc.get_threshold()[2] >= 100
                    assert ident._unique_ids is not numbering
                    assert ir.Assign in ir_utils.alias_analysis_extensions
                    assert icc.InlineWorker.inline_ir is not inline_ir
                raise RuntimeError("inside")
        assert gc.get_threshold() == (700, 10, 10)
        assert ident._unique_ids is numbering
        assert dict(ir_utils.alias_analysis_extensions) == extensions
        assert icc.InlineWorker.inline_ir is inline_ir
    finally:
        gc.set_threshold(*saved_gc)


def test_a_geardyn_pipeline_compile_leaves_numbas_alias_table_as_it_was():
    """The tuple-alias extension is installed for a compile with geardyn's pipeline only: the
    table of alias-analysis extensions is the same before and after, and the store into an
    array of a tuple argument is kept (as numpy computes it)."""
    from geardyn._jit_target import WidthCompiler

    def bump(out, k):
        counts, _ = out
        counts[k] += 1
        return k

    before = dict(ir_utils.alias_analysis_extensions)
    fn = nb.njit(pipeline_class=WidthCompiler)(bump)
    out = (np.zeros(3, np.int64), np.zeros(3, np.int64))
    assert fn(out, 2) == 2
    np.testing.assert_array_equal(out[0], np.eye(3, dtype=np.int64)[2])
    assert dict(ir_utils.alias_analysis_extensions) == before
    assert tuple_aliases.depth == 0
