"""The count of steps that reached the edge-split limit (``unresolved``) is kept by every path.

The one-form model of tests/levels_model.py crosses 18 close levels within one grid step twice
per forcing period: more distinct crossings than the split limit (MAX_SPLITS = 16), so every
such step falls back unsplit and counts once. The expected count is 2 per period run, from the
analytic motion (x' does not depend on x). The sweep's fused block loop is checked in its three
lane forms (FORM_QUIET: B = 0; FORM_LOAD: B != 0; FORM_GENERAL: a chain of lanes of both), and
the one-lane path (``simulate``, the trajectory kernel). numba's dead-code elimination dropped
the fused loop's store of this count (an array unpacked from a tuple argument, see
:mod:`geardyn._tuple_alias`): this test fails with 0 counts there.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest
from numba.extending import overload

import geardyn
from geardyn._jit_target import WidthCompiler
from geardyn.solvers.ensemble import run_lanes
from geardyn.solvers.kernels import kernels_for
from levels_model import B_BELOW, LEVELS, RUN, levels_model

OMEGAS = np.array([0.8, 1.1, 1.4, 1.7])


def _lanes(model, omega, b):
    P = model.lane_params("Omega", omega)
    P[:, model.param_names.index("B")] = b
    return P


def test_the_levels_are_crossed_in_one_step_twice_per_period():
    """The premise of the counts below, from the analytic motion: the levels lie between the
    grid points at the passages, at most one grid step apart, and more than MAX_SPLITS."""
    from geardyn.solvers._step_shared import MAX_SPLITS

    assert len(LEVELS) > MAX_SPLITS
    step = 2.0 * math.pi / RUN.steps_per_period
    for b in (0.0, 0.01):
        theta = np.linspace(0.0, 2.0 * math.pi, 200001)
        x = np.sin(theta) + b * (1.0 - np.cos(theta))
        for level in LEVELS:
            up = theta[:-1][(x[:-1] < level) & (x[1:] >= level)]
            down = theta[:-1][(x[:-1] >= level) & (x[1:] < level)]
            assert up.size == 1 and down.size == 1
            assert 0.0 < up[0] < step  # in the first grid step of a period
            assert math.pi - step < down[0] < math.pi  # in the step ending at half a period
    # B_BELOW (tests/test_grazing.py's lane without crossings): x stays below every level
    x = np.sin(theta) + B_BELOW * (1.0 - np.cos(theta))
    assert x.max() < min(LEVELS)


def test_sweep_counts_every_step_at_the_split_limit_in_each_lane_form():
    model = levels_model()
    assert kernels_for(model.kernel).FUSED  # the fused block loop
    y0 = model.initial_state()
    n = len(OMEGAS)
    runs = {form: run_lanes(model, _lanes(model, OMEGAS, b), y0, run=RUN)
            for form, b in (("quiet", 0.0), ("load", 0.01))}
    # FORM_GENERAL: chains of a quiet and a loud lane (either order), lane l + n after lane l
    P = np.vstack([_lanes(model, OMEGAS, np.where(np.arange(n) % 2, 0.01, 0.0)),
                   _lanes(model, OMEGAS, np.where(np.arange(n) % 2, 0.0, 0.01))])
    chain = np.concatenate([np.arange(n, 2 * n), np.full(n, -1)])
    runs["general"] = run_lanes(model, P, y0, run=RUN, chain=chain)
    counts = {}
    for form, out in runs.items():
        assert np.all(out.status == geardyn.Status.OK), form
        nper = out.steps_per_period
        assert np.all(out.steps % nper == 0) and np.all(out.steps > 0), form
        counts[form] = (out.unresolved.tolist(), (2 * (out.steps // nper)).tolist())
    assert all(got == expected for got, expected in counts.values()), counts


def test_one_lane_path_counts_every_step_at_the_split_limit():
    model = levels_model()
    for omega, b in ((1.1, 0.0), (1.4, 0.01)):
        ds = geardyn.simulate(model.with_params(Omega=omega, B=b), run=RUN)
        assert ds.attrs["status"] == geardyn.Status.OK
        periods = ds.attrs["transient_periods"] + ds.attrs["periods"]
        assert ds.attrs["unresolved_steps"] == 2 * periods


def _twice(x):
    pass


@overload(_twice, inline="always")
def _ov_twice(x):
    return lambda x: 2 * x


def _bump(out, k):
    counts, _ = out  # an array unpacked from a tuple argument, written last
    counts[k] += 1
    return _twice(k)  # an inline overload: numba's InlineOverloads then runs its dead-code pass


@pytest.mark.parametrize("body", ["unpack", "loop"])
def test_geardyn_pipeline_keeps_stores_into_arrays_of_tuple_arguments(body):
    """The mechanism, in a small function: compiled with geardyn's pipeline, the store into an
    array reached through a tuple argument (unpacked, or iterated over) is kept."""
    def loop(out, k):
        for a in out:
            a[k] += 1
        return _twice(k)

    fn = nb.njit(pipeline_class=WidthCompiler)(_bump if body == "unpack" else loop)
    out = (np.zeros(3, np.int64), np.zeros(3, np.int64))
    assert fn(out, 1) == 2
    assert out[0].tolist() == [0, 1, 0]
