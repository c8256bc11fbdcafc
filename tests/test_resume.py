"""Resumable runs: finished chunks in a Zarr store survive interruption (SIGKILL included), a
rerun computes only the rest, and the result is that of an uninterrupted run. The finished
dataset sits at the store's root, where plain ``xarray.open_zarr`` finds it."""

from __future__ import annotations

import functools
import os
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.execution.executor import lane_results, run_chunks, run_lanes_task
from geardyn.execution.zarr_store import (
    LaneStore,
    StoreMismatchError,
    load_zarr_dataset,
    save_zarr_dataset,
)
from geardyn.io.toml import load_study
from geardyn.study import build_model

GEAR = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
OMEGAS = np.linspace(0.4, 3.0, 10)
SETTINGS = dict(run=geardyn.RunSettings(transient=100.0, samples=8, steps_per_period=128))
CALLS: list[int] = []  # lanes each task call ran (the task reads no settings from here)
FAIL_AFTER: list[int] = []  # when set, the task raises once this many chunks ran


def _counting_task(model, P, y0, **settings):
    if FAIL_AFTER and len(CALLS) >= FAIL_AFTER[0]:
        raise KeyboardInterrupt("simulated interruption")
    CALLS.append(P.shape[0])
    return run_lanes_task(model, P, y0, **settings)


def _run(store, chunk=3):
    P = GEAR.lane_params("Omega", OMEGAS)
    y0 = np.tile(GEAR.initial_state(), (OMEGAS.size, 1))
    task = functools.partial(_counting_task, **SETTINGS)
    return lane_results(run_chunks(task, GEAR, {"P": P, "y0": y0}, chunk=chunk, store=store))


def _same(a, b):
    for name in a.__dataclass_fields__:
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name


def test_interrupted_run_resumes_with_the_missing_chunks_only(tmp_path):
    path = tmp_path / "lanes.zarr"
    CALLS.clear()
    whole = _run(None)
    CALLS.clear()
    FAIL_AFTER[:] = [2]
    try:
        with pytest.raises(KeyboardInterrupt):
            _run(path)
    finally:
        FAIL_AFTER.clear()
    store = LaneStore(path)
    np.testing.assert_array_equal(store.chunk_runs(), [1, 1, 0, 0])
    # a chunk whose data were written but whose marker was not counts as missing
    CALLS.clear()
    resumed = _run(path)
    assert CALLS == [3, 1]  # chunks 2 and 3 (3 + 1 lanes); 0 and 1 came from the store
    np.testing.assert_array_equal(LaneStore(path).chunk_runs(), [1, 1, 2, 2])
    _same(resumed, whole)
    CALLS.clear()
    _same(_run(path), whole)  # finished: nothing left to compute
    assert CALLS == []


def test_half_written_chunk_is_recomputed(tmp_path):
    path = tmp_path / "lanes.zarr"
    whole = _run(None)
    _run(path)
    store = LaneStore(path)
    store.begin(store.info["digest"], OMEGAS.size, 3, {})
    # simulate a kill between a chunk's data and its marker: garbage data, marker cleared
    store._group["outputs"]["samples"][3:6] = -7.0
    store._group["done"][1] = 0
    CALLS.clear()
    resumed = _run(path)
    assert CALLS == [3]
    _same(resumed, whole)


def test_store_refuses_other_inputs(tmp_path):
    path = tmp_path / "lanes.zarr"
    _run(path)
    with pytest.raises(StoreMismatchError, match="other inputs"):
        _run(path, chunk=4)
    with pytest.raises(StoreMismatchError, match="other inputs"):
        geardyn.map2d(GEAR, x=("Omega", [1.0, 2.0]), y=("zeta", [0.1]),
                      run=geardyn.RunSettings(transient=10.0, samples=4), store=path)


def test_resumable_sweep_equals_the_plain_sweep(tmp_path):
    kw = dict(values=OMEGAS, run=geardyn.RunSettings(transient=100.0, samples=8), chunk=4)
    plain = geardyn.bifurcation(GEAR, **kw)
    stored = geardyn.bifurcation(GEAR, store=tmp_path / "sweep.zarr", **kw)
    again = geardyn.bifurcation(GEAR, store=tmp_path / "sweep.zarr", **kw)
    assert plain.identical(stored) and plain.identical(again)
    np.testing.assert_array_equal(LaneStore(tmp_path / "sweep.zarr").chunk_runs(), [1, 1, 1])


# ------------------------------------------------------------------ the dataset at the root
MAP = dict(x=("Omega", np.linspace(0.5, 3.0, 5)), y=("zeta", [0.03, 0.08]),
           run=geardyn.RunSettings(transient=50.0, samples=8), chunk=3)


def _open_quietly(path) -> xr.Dataset:
    """``xarray.open_zarr(path)`` with every warning an error, loaded."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with xr.open_zarr(path) as ds:
            return ds.load()


class _Interrupt(Exception):
    pass


def test_map_store_opens_with_plain_xarray_before_and_after_resuming(tmp_path):
    whole = geardyn.map2d(GEAR, **MAP)
    path = tmp_path / "m.zarr"
    reports: list[int] = []

    def stop_after_two_chunks(done: int, total: int) -> None:
        reports.append(done)
        if len(reports) == 3:  # the start, then two finished chunks
            raise _Interrupt

    with pytest.raises(_Interrupt):
        geardyn.map2d(GEAR, store=path, progress=stop_after_two_chunks, **MAP)
    np.testing.assert_array_equal(LaneStore(path).chunk_runs(), [1, 1, 0, 0])
    unfinished = _open_quietly(path)  # no dataset yet: empty, and says why
    assert not unfinished.variables and "geardyn_unfinished" in unfinished.attrs
    with pytest.raises(FileNotFoundError, match="no finished dataset"):
        load_zarr_dataset(path)

    resumed = geardyn.map2d(GEAR, store=path, **MAP)
    np.testing.assert_array_equal(LaneStore(path).chunk_runs(), [1, 1, 2, 2])
    assert resumed.identical(whole)
    assert _open_quietly(path).identical(whole)
    assert load_zarr_dataset(path).identical(whole)
    assert geardyn.map2d(GEAR, store=path, **MAP).identical(whole)  # again: read, rewritten
    assert _open_quietly(path).identical(whole)
    assert sorted(p.name for p in path.iterdir() if p.is_dir()) == sorted(
        [*map(str, whole.variables), "lanes"])


def test_saving_again_replaces_the_dataset_and_keeps_the_lane_store(tmp_path):
    path = tmp_path / "m.zarr"
    ds = geardyn.map2d(GEAR, store=path, **MAP)
    other = xr.Dataset({"a": ("t", [1.0, 2.0])}, attrs={"note": "other"})
    save_zarr_dataset(other, path)
    assert _open_quietly(path).identical(other)
    assert not (path / "period").exists()
    assert geardyn.map2d(GEAR, store=path, **MAP).identical(ds)  # lanes kept: nothing rerun
    assert LaneStore(path).info["runs"] == 2
    with pytest.raises(ValueError, match="reserved"):
        save_zarr_dataset(xr.Dataset({"lanes": ("t", [1.0])}), path)


def test_a_zarr_store_geardyn_did_not_write_is_left_alone(tmp_path):
    path = tmp_path / "theirs.zarr"
    theirs = xr.Dataset({"a": ("t", [1.0, 2.0])})
    theirs.to_zarr(path, zarr_format=3, consolidated=False)
    for call in (lambda: geardyn.map2d(GEAR, store=path, **MAP),
                 lambda: save_zarr_dataset(theirs, path)):
        with pytest.raises(StoreMismatchError, match="did not write") as err:
            call()
        assert str(path) in str(err.value)
    assert xr.open_zarr(path, consolidated=False).load().identical(theirs)
    assert not (path / "lanes").exists()


def _legacy_store(path, ds: xr.Dataset) -> None:
    """A store as geardyn wrote it before the dataset moved to the root: lane store at the
    root, dataset in group "result" with strings as flag codes."""
    import zarr

    root = zarr.open_group(str(path), mode="w", zarr_format=3)
    root.attrs["geardyn_lanes"] = {"format": 1, "digest": "0" * 64, "n_lanes": 10, "chunk": 10,
                                   "n_chunks": 1, "meta": {}, "runs": 1}
    root.create_array("done", shape=(1,), chunks=(1,), dtype="int32", fill_value=0)[:] = 1
    root.create_group("lanes")
    enc = ds.copy()
    for name in ("contact", "mesh"):  # strings as flag codes, as the earlier layout kept them
        var = ds[name].variable
        labels = sorted(set(var.values.ravel().tolist()))
        codes = np.searchsorted(labels, var.values).astype(np.int16)
        enc[name] = xr.Variable(var.dims, codes, dict(
            var.attrs, flag_values=list(range(len(labels))), flag_meanings=" ".join(labels),
            geardyn_categorical=1))
    enc.to_zarr(str(path), group="result", mode="w", consolidated=False, zarr_format=3)


def test_store_of_the_earlier_layout_is_read_but_not_resumed(tmp_path):
    path = tmp_path / "old.zarr"
    ds = geardyn.map2d(GEAR, **MAP)
    _legacy_store(path, ds)
    got = load_zarr_dataset(path)  # what geardyn plot reads
    np.testing.assert_array_equal(got["contact"].values, ds["contact"].values)
    np.testing.assert_array_equal(got["period"].values, ds["period"].values)
    for call in (lambda: geardyn.map2d(GEAR, store=path, **MAP),
                 lambda: save_zarr_dataset(ds, path), lambda: LaneStore(path).chunk_runs()):
        with pytest.raises(StoreMismatchError, match="earlier geardyn layout") as err:
            call()
        assert str(path) in str(err.value) and "delete it" in str(err.value)


# ------------------------------------------------------------------ a real run, SIGKILLed
STUDY = """
[study]
name = "resume"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.2
Fm = 0.1
Fa = 0.2
[run]
transient = 300.0
periods = 16
"""
X, Y, CHUNK = "Omega:0.5:3:30", "zeta:0.02:0.1:20", 10  # 600 points, 60 chunks


def _axis(spec):
    name, a, b, n = spec.split(":")
    return name, np.linspace(float(a), float(b), int(n))


@pytest.mark.slow  # ~25 s of subprocesses; the fast tests above interrupt in-process
def test_killed_cli_run_resumes_to_the_uninterrupted_result(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    out = tmp_path / "map.zarr"
    cmd = [sys.executable, "-m", "geardyn.cli.main", "map", str(study), "--x", X, "--y", Y,
           "--out", str(out), "--chunk", str(CHUNK)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=os.environ.copy())
    deadline = time.monotonic() + 120
    done = np.zeros(0)
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                done = LaneStore(out).chunk_runs()
            except Exception:  # not created yet
                done = np.zeros(0)
            if np.count_nonzero(done) >= 5:
                break
            time.sleep(0.02)
        assert proc.poll() is None, "the run ended before it could be killed"
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    killed = LaneStore(out).chunk_runs()
    n_chunks = killed.size
    assert 5 <= np.count_nonzero(killed) < n_chunks
    with pytest.raises(FileNotFoundError, match="no finished dataset"):
        load_zarr_dataset(out)

    rerun = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy(),
                           timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    runs = LaneStore(out).chunk_runs()
    # chunks finished before the kill were kept (run 1), the others computed by the rerun
    np.testing.assert_array_equal(runs[killed > 0], 1)
    np.testing.assert_array_equal(runs[killed == 0], 2)

    model = build_model(load_study(study))
    whole = geardyn.map2d(model, x=_axis(X), y=_axis(Y),
                          run=geardyn.RunSettings(transient=300.0, samples=16),
                          chunk=CHUNK)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        opened = xr.open_zarr(out).load()  # plain xarray, quietly
    xr.testing.assert_identical(opened.drop_attrs(), whole.drop_attrs())
    assert opened.attrs == dict(whole.attrs, study="resume")
    got = load_zarr_dataset(out)
    assert set(got.data_vars) == set(whole.data_vars)
    for name in whole.data_vars:
        a, b = whole[name].values, got[name].values
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name
    for name in whole.coords:
        np.testing.assert_array_equal(whole[name].values, got[name].values)
