"""Full garbage collections held back inside geardyn's compiles (geardyn.solvers._compile_gc):
the thresholds raised only there, restored after each compile and on errors."""

from __future__ import annotations

import gc

import numpy as np
import pytest

from geardyn.solvers._compile_gc import FULL_EVERY, young_collections


@pytest.fixture
def thresholds():
    saved = gc.get_threshold()
    yield saved
    gc.set_threshold(*saved)


def test_raised_inside_restored_after_and_reentrant(thresholds):
    gc.set_threshold(500, 7, 3)
    with young_collections():
        assert gc.get_threshold() == (500, 7, FULL_EVERY)
        with young_collections():
            assert gc.get_threshold() == (500, 7, FULL_EVERY)
        assert gc.get_threshold() == (500, 7, FULL_EVERY)
    assert gc.get_threshold() == (500, 7, 3)
    assert young_collections.depth == 0


def test_restored_on_errors_and_a_higher_threshold_kept(thresholds):
    gc.set_threshold(700, 10, 10)
    with pytest.raises(RuntimeError, match="inside"):
        with young_collections():
            raise RuntimeError("inside")
    assert gc.get_threshold() == (700, 10, 10)
    gc.set_threshold(700, 10, 10 * FULL_EVERY)
    with young_collections():
        assert gc.get_threshold() == (700, 10, 10 * FULL_EVERY)  # never lowered
    gc.set_threshold(0, 10, 10)  # a disabled collector stays disabled
    with young_collections():
        assert gc.get_threshold() == (0, 10, 10)
    assert gc.get_threshold() == (0, 10, 10)


def test_a_geardyn_compile_runs_with_it_and_leaves_the_process_as_it_was(thresholds):
    import numba as nb

    from geardyn.solvers import kernels

    seen: list = []
    original = kernels.young_collections

    def watching():
        seen.append(young_collections.depth)
        return original()

    @nb.njit
    def f(x):
        return np.sin(x) + 2.0 * x

    kernels._quiet_compile(f)  # as geardyn wraps its own kernels' dispatchers
    gc.set_threshold(700, 10, 10)
    kernels.young_collections = watching
    try:
        assert f(0.5) == np.sin(0.5) + 1.0
    finally:
        kernels.young_collections = original
    assert seen == [0]  # the outermost compile entered it
    assert gc.get_threshold() == (700, 10, 10)
