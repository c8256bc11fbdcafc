"""The sweep kernel's refilling slots: a worker's block holds lanes of every step count at once,
each slot with its own step, phase and phase table, and takes the next lane of its queue when
one ends. A lane's arithmetic is the scalar kernel's whatever its slot, neighbours, worker, the
block width or the queue's order, so every result is bitwise the same, and equal to the
one-lane path (``trajectory``, under :func:`geardyn.simulate`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.solvers.ensemble import LaneResults, _schedule, block_width, run_plan

_FIELDS = [f for f in LaneResults.__dataclass_fields__ if f != "final_time"]


def _lanes(n_lanes: int = 23):
    """Gear-pair lanes with five step counts, different transients (so lanes end, and slots
    refill, at different steps) and a bound that some lanes near resonance exceed."""
    model = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    omega = np.linspace(0.3, 3.0, n_lanes)
    P = model.lane_params("Omega", omega)
    n_per = np.array([64, 128, 96, 256, 80])[np.arange(n_lanes) % 5]
    transient = (5 + np.arange(n_lanes) * 7 % 31) * 2 * math.pi / omega
    return model, P, n_per, transient


def _run(model, P, n_per, transient, run, **kw) -> LaneResults:
    lanes = LaneSettings(transient=transient, steps_per_period=n_per, sample_every=1)
    plan = LanePlan.build(model, P, run, lanes)
    return run_plan(model, P, model.initial_state(), plan, **kw)


def _assert_same(a: LaneResults, b: LaneResults, index=slice(None)) -> None:
    for f in _FIELDS:
        np.testing.assert_array_equal(getattr(a, f)[index], getattr(b, f), err_msg=f)


@pytest.mark.parametrize("converge", [None, 1e-6])
def test_results_do_not_depend_on_width_workers_or_queue_order(converge):
    model, P, n_per, transient = _lanes()
    run = RunSettings(samples=6, bound=1.1, converge=converge,
                      transient_max=None if converge is None else 200.0)
    ref = _run(model, P, n_per, transient, run)
    assert len(set(n_per)) == 5
    assert np.any(ref.status == 1) and np.any(ref.status == 0)  # some lanes diverge
    assert np.all(ref.crossings.sum(axis=1) >= 0) and ref.crossings.sum() > 0
    if converge is not None:
        assert np.any(ref.converged == 1)
    for width, workers in ((5, 3), (1, 1), (64, 1), (3, 7)):
        _assert_same(ref, _run(model, P, n_per, transient, run, width=width, workers=workers))
    perm = np.random.default_rng(3).permutation(P.shape[0])
    got = _run(model, P[perm], n_per[perm], transient[perm], run, width=4, workers=2)
    _assert_same(ref, got, perm)


def test_lanes_equal_the_one_lane_path_bitwise():
    model, P, n_per, transient = _lanes(11)
    run = RunSettings(samples=6)
    r = _run(model, P, n_per, transient, run, width=4, workers=2)
    assert np.all(r.status == 0)
    omega = P[:, 0]
    for j in (0, 3, 7, 10):
        ds = geardyn.simulate(model, omega=float(omega[j]),
                              run=geardyn.RunSettings(transient=float(transient[j]), samples=6,
                                                      steps_per_period=int(n_per[j])))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])


def test_schedule_balances_lane_steps_and_runs_longest_first():
    cost = np.random.default_rng(0).integers(1, 1000, 301).astype(float)
    start, queue = _schedule(cost, workers=4)
    assert np.array_equal(np.sort(queue), np.arange(cost.size))
    loads = [cost[queue[start[w]:start[w + 1]]].sum() for w in range(4)]
    assert max(loads) - min(loads) <= cost.max()
    for w in range(4):
        q = cost[queue[start[w]:start[w + 1]]]
        assert np.all(np.diff(q) <= 0)
    start, queue = _schedule(cost[:2], workers=8)  # no more workers than lanes
    assert start.size == 3 and sorted(queue) == [0, 1]


def test_block_width_fills_the_workers_rounds_evenly():
    """The default width: at most the block, as few slots as hold the most lanes queued on a
    worker in as many rounds as the block would (100 lanes: two rounds of 50, not 64 + 36)."""
    assert block_width(np.array([100, 100]), 64) == 50
    assert block_width(np.array([200, 199]), 64) == 50
    assert block_width(np.array([65]), 64) == 33
    assert block_width(np.array([64, 63]), 64) == 64
    assert block_width(np.array([3]), 64) == 3
    assert block_width(np.array([128]), 64) == 64
    for most in range(1, 400):
        w = block_width(np.array([most]), 64)
        rounds = -(-most // w)
        assert w <= 64 and rounds == -(-most // 64) and (rounds - 1) * w < most


@pytest.mark.parametrize("converge", [None, 1e-7])
def test_block_compaction_keeps_every_lane_bitwise(converge):
    """Once a worker's queue is out, its block's running lanes move down into the free slots
    (``_compact``) so that the fused loop runs fewer vectors of eight slots. 40 CATT lanes in
    one block (width 64, one worker) of very different lengths (transients 5-200 periods, two
    chains) leave the block with fewer than 32, 24, 16 and 8 running lanes in turn, so lanes
    move mid-run (mid-transient, with their convergence rings, and mid-sampling); with width 1
    no lane ever moves. Every result is bitwise the same."""
    model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    omega = np.linspace(0.4, 3.6, 40)
    P = model.lane_params("Omega", omega)
    periods = 5 + (np.arange(40) * 37) % 196
    assert np.ptp(periods) > 150
    transient = periods * 2 * math.pi / omega
    chain = np.full(40, -1, np.int64)
    chain[[3, 4, 20]] = [4, 5, 21]  # chains 3 -> 4 -> 5 and 20 -> 21
    run = RunSettings(samples=8, converge=converge,
                      transient_max=None if converge is None else 2000.0)
    plan = LanePlan.build(model, P, run, LaneSettings(
        transient=transient, transient_max=None if converge is None else 2 * transient))
    y0 = model.initial_state()
    wide = run_plan(model, P, y0, plan, width=64, workers=1, chain=chain)
    narrow = run_plan(model, P, y0, plan, width=1, workers=1, chain=chain)
    assert np.all(wide.status == 0)
    if converge is not None:
        assert np.any(wide.converged == 1) and np.any(wide.transient_periods > periods)
    for f in _FIELDS:
        np.testing.assert_array_equal(getattr(wide, f), getattr(narrow, f), err_msg=f)
