"""Chunked lane execution: independent of the chunking, and bitwise the same on a Dask cluster."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import geardyn
from geardyn.execution.executor import inputs_digest, lane_results, run_chunks, run_lanes_task
from geardyn.solvers.ensemble import LaneResults, run_lanes

GEAR = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
OMEGAS = np.linspace(0.4, 3.0, 13)
SETTINGS = dict(run=geardyn.RunSettings(transient=150.0, samples=8, steps_per_period=128))
MAP = dict(x=("Omega", np.linspace(0.5, 3.0, 7)), y=("zeta", [0.02, 0.05, 0.1]),
           run=geardyn.RunSettings(transient=200.0, samples=16), lyapunov=True, chunk=4)


def _assert_same(a: LaneResults, b: LaneResults, skip: tuple[str, ...] = ()) -> None:
    for name in LaneResults.__dataclass_fields__:
        if name not in skip:
            assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name


def _chunked(chunk: int, progress=None) -> tuple[LaneResults, LaneResults]:
    P = GEAR.lane_params("Omega", OMEGAS)
    one = run_lanes(GEAR, P, GEAR.initial_state(), **SETTINGS)
    out = run_chunks(functools.partial(run_lanes_task, **SETTINGS), GEAR,
                     {"P": P, "y0": np.tile(GEAR.initial_state(), (OMEGAS.size, 1))},
                     chunk=chunk, progress=progress)
    return lane_results(out), one


@pytest.mark.parametrize("chunk", [1, 4, 13, 100])
def test_chunks_equal_one_kernel_call(chunk):
    seen = []
    chunked, one = _chunked(chunk, lambda done, total: seen.append((done, total)))
    _assert_same(chunked, one)
    n_chunks = -(-OMEGAS.size // chunk)
    assert seen[0] == (0, 13) and seen[-1] == (13, 13) and len(seen) == n_chunks + 1


def test_crossing_counts_do_not_depend_on_the_chunking():
    # a lane's counters stop at its end, whatever else runs on in its lockstep block
    chunked, one = _chunked(1)
    _assert_same(chunked, one)


def test_digest_follows_every_input():
    P = GEAR.lane_params("Omega", OMEGAS)
    y0 = np.tile(GEAR.initial_state(), (OMEGAS.size, 1))
    task = functools.partial(run_lanes_task, **SETTINGS)
    base = inputs_digest(task, GEAR, {"P": P, "y0": y0}, 4)
    assert base == inputs_digest(task, GEAR, {"P": P.copy(), "y0": y0.copy()}, 4)
    P2 = P.copy()
    P2[3, 0] = np.nextafter(P2[3, 0], 9.0)  # one bit of one lane
    other_task = functools.partial(run_lanes_task, **dict(SETTINGS, samples=9))
    for changed in (inputs_digest(task, GEAR, {"P": P2, "y0": y0}, 4),
                    inputs_digest(task, GEAR, {"P": P, "y0": y0}, 5),
                    inputs_digest(other_task, GEAR, {"P": P, "y0": y0}, 4),
                    inputs_digest(task, GEAR, {"P": P, "y0": y0}, 4, meta={"x": "Omega"})):
        assert changed != base


def test_map_does_not_depend_on_the_chunk_size():
    a = geardyn.map2d(GEAR, **MAP)
    b = geardyn.map2d(GEAR, **dict(MAP, chunk=100))
    for name in ("period", "lyapunov", "force_peak", "force_rms", "status"):
        assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name


@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield client


def test_map_on_two_dask_workers_is_bitwise_the_local_map(dask_client):
    from dask.distributed import get_task_stream

    local = geardyn.map2d(GEAR, **MAP)
    with get_task_stream(dask_client) as stream:
        remote = geardyn.map2d(GEAR, client=dask_client, **MAP)
    chunk_tasks = [t for t in stream.data if t["key"].startswith("_run_portable")]
    assert len(chunk_tasks) == 6  # 21 points in chunks of 4
    assert len({t["worker"] for t in chunk_tasks}) == 2  # both workers computed chunks
    assert set(local.data_vars) == set(remote.data_vars)
    for name in local.data_vars:
        a, b = local[name].values, remote[name].values
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name
    assert local.identical(remote)


def test_sweep_on_dask_is_bitwise_the_local_sweep(dask_client):
    kw = dict(values=OMEGAS, run=geardyn.RunSettings(transient=150.0, samples=8), starts=2,
              chunk=5)
    local = geardyn.bifurcation(GEAR, **kw)
    remote = geardyn.bifurcation(GEAR, client=dask_client, **kw)
    assert np.array_equal(local["poincare"].values, remote["poincare"].values, equal_nan=True)
    assert local.identical(remote)
