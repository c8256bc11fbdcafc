"""Zarr stores (format 3): resumable lane results, and finished datasets.

A :class:`LaneStore` keeps the per-lane outputs of a chunked run
(:func:`geardyn.solvers.executor.run_chunks`) as they complete::

    map.zarr/zarr.json      root attributes "geardyn_lanes": inputs digest, lanes, chunk size, runs
    map.zarr/lanes/<name>   one array per output, lane-first, chunked like the run
    map.zarr/done           per chunk: 0 = missing, else the number of the run that computed it
    map.zarr/result/        the finished dataset (:func:`save_zarr_dataset`)

A chunk's data are written before its ``done`` entry, and every file of the store is written
atomically (zarr's local store writes a temporary file, then renames it), so a run killed at any
moment leaves no half-written chunk counted as done: the next run with the same inputs recomputes
exactly the chunks not marked done. A store whose recorded inputs digest differs is refused.

String variables (e.g. the contact regime) are stored as small integer codes with CF
``flag_values`` / ``flag_meanings`` attributes (zarr format 3 has no stable string type) and
decoded by :func:`load_zarr_dataset`.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from geardyn.errors import GeardynError

__all__ = ["LaneStore", "StoreMismatchError", "load_zarr_dataset", "save_zarr_dataset"]

_ATTR = "geardyn_lanes"
_FORMAT = 1
_CATEGORICAL = "geardyn_categorical"


class StoreMismatchError(GeardynError, ValueError):
    """A store holds a run with other inputs than the one asked for."""


def _open_group(path: Path, mode: str):
    import zarr

    return zarr.open_group(str(path), mode=mode, zarr_format=3)


class LaneStore:
    """Per-lane outputs of a chunked run, resumable (see the module docstring)."""

    def __init__(self, path: str | os.PathLike[str]):
        self.path = Path(path)
        self.run = 0
        self._group = None
        self._done = None
        self._n_lanes = 0
        self._chunk = 0

    # ------------------------------------------------------------------ opening
    def begin(self, digest: str, n_lanes: int, chunk: int, meta: dict[str, Any]) -> int:
        """Open (or create) the store for a run with inputs ``digest`` and return this run's
        number (1 for a fresh store). Raises :class:`StoreMismatchError` when the store holds a
        run with other inputs."""
        if self.path.exists() and not self.path.is_dir():
            raise StoreMismatchError(f"{self.path}: exists and is not a Zarr store")
        if self.path.is_dir() and any(self.path.iterdir()) and not (
                self.path / "zarr.json").is_file():
            raise StoreMismatchError(f"{self.path}: exists and is not a Zarr store")
        group = _open_group(self.path, "a")
        n_chunks = -(-n_lanes // chunk)
        info = group.attrs.get(_ATTR)
        if info is None:  # fresh (or interrupted before it was initialised)
            group.create_array("done", shape=(n_chunks,), chunks=(1,), dtype="int32",
                               fill_value=0, overwrite=True)
            if "lanes" in group:
                del group["lanes"]
            group.create_group("lanes")
            info = {"format": _FORMAT, "digest": digest, "n_lanes": int(n_lanes),
                    "chunk": int(chunk), "n_chunks": int(n_chunks), "meta": meta, "runs": 0}
        elif info.get("digest") != digest:
            raise StoreMismatchError(
                f"{self.path}: holds a run with other inputs (study, grid or settings differ: "
                f"digest {str(info.get('digest'))[:12]} here, {digest[:12]} now); "
                "use another output or delete it")
        info = dict(info, runs=int(info["runs"]) + 1)
        group.attrs[_ATTR] = info
        self.run = info["runs"]
        self._group, self._done = group, group["done"]
        self._n_lanes, self._chunk = int(n_lanes), int(chunk)
        return self.run

    @property
    def info(self) -> dict[str, Any]:
        """The store's record: digest, n_lanes, chunk, n_chunks, meta, runs."""
        return dict(_open_group(self.path, "r").attrs[_ATTR])

    # ------------------------------------------------------------------ chunks
    def done_chunks(self) -> np.ndarray:
        """Bool per chunk: finished and marked done."""
        return self.chunk_runs() > 0

    def chunk_runs(self) -> np.ndarray:
        """Per chunk, the run (1, 2, ...) that computed it; 0 where still missing."""
        done = self._done if self._done is not None else _open_group(self.path, "r")["done"]
        return np.asarray(done[:])

    def write_chunk(self, index: int, start: int, stop: int, outputs: dict[str, np.ndarray]
                    ) -> None:
        """Write one chunk's outputs (lanes ``start:stop``), then mark it done."""
        if self._group is None:
            raise RuntimeError("LaneStore.begin() first")
        lanes = self._group["lanes"]
        for name, value in outputs.items():
            value = np.asarray(value)
            if value.dtype.kind not in "biuf":
                raise TypeError(f"store output {name!r}: numeric arrays only (got {value.dtype})")
            if value.shape[0] != stop - start:
                raise ValueError(f"store output {name!r}: {value.shape[0]} lanes, "
                                 f"expected {stop - start}")
            shape = (self._n_lanes, *value.shape[1:])
            if name in lanes:
                arr = lanes[name]
                if tuple(arr.shape) != shape or arr.dtype != value.dtype:
                    raise StoreMismatchError(f"{self.path}: output {name!r} changed shape/type")
            else:
                arr = lanes.create_array(name, shape=shape, chunks=(self._chunk, *shape[1:]),
                                         dtype=value.dtype, fill_value=0)
            arr[start:stop] = value
        self._done[index] = self.run

    def read(self) -> dict[str, np.ndarray]:
        """Every output, all lanes (every chunk must be done)."""
        group = self._group if self._group is not None else _open_group(self.path, "r")
        missing = np.nonzero(~self.done_chunks())[0]
        if missing.size:
            raise RuntimeError(f"{self.path}: chunks {missing.tolist()[:5]} are not finished")
        return {name: np.asarray(arr[:]) for name, arr in group["lanes"].arrays()}


# ---------------------------------------------------------------------------- datasets
def _encode(var: xr.Variable) -> xr.Variable:
    if var.dtype.kind not in "US":
        return var
    labels = np.asarray(var.values).astype(str)
    categories = sorted(set(labels.ravel().tolist()))
    if any((" " in c) or not c for c in categories):
        raise ValueError("string values with spaces or empty strings cannot be stored")
    codes = np.searchsorted(np.array(categories), labels).astype(np.int16)
    attrs = dict(var.attrs, flag_values=list(range(len(categories))),
                 flag_meanings=" ".join(categories))
    attrs[_CATEGORICAL] = 1
    return xr.Variable(var.dims, codes, attrs)


def _decode(var: xr.Variable) -> xr.Variable:
    if not var.attrs.get(_CATEGORICAL):
        return var
    attrs = dict(var.attrs)
    categories = np.array(attrs.pop("flag_meanings").split())
    attrs.pop("flag_values")
    attrs.pop(_CATEGORICAL)
    return xr.Variable(var.dims, categories[np.asarray(var.values)], attrs)


def _map_variables(ds: xr.Dataset, fn) -> xr.Dataset:
    coords = {name: fn(ds[name].variable) for name in ds.coords}
    data = {name: fn(ds[name].variable) for name in ds.data_vars}
    return xr.Dataset(data, coords=coords, attrs=dict(ds.attrs))


def save_zarr_dataset(ds: xr.Dataset, path: str | os.PathLike[str], group: str = "result"
                      ) -> Path:
    """Write ``ds`` into the Zarr store ``path`` under ``group`` (replacing that group only;
    attributes converted as for NetCDF, strings as flag codes). Returns the path."""
    from geardyn.io.netcdf import netcdf_attrs

    path = Path(path)
    out = _map_variables(ds, _encode)
    out.attrs = netcdf_attrs(ds.attrs)
    for name in out.variables:
        out[name].attrs = netcdf_attrs(out[name].attrs)
    tmp = f"{group}.partial"
    root = _open_group(path, "a")
    if tmp in root:
        del root[tmp]
    out.to_zarr(str(path), group=tmp, mode="w", consolidated=False, zarr_format=3)
    if group in root:  # the finished group replaces the old one only once it is complete
        shutil.rmtree(path / group)
    os.replace(path / tmp, path / group)
    return path


def load_zarr_dataset(path: str | os.PathLike[str], group: str = "result") -> xr.Dataset:
    """Read a dataset written by :func:`save_zarr_dataset` fully into memory."""
    path = Path(path)
    if not (path / group / "zarr.json").is_file():
        raise FileNotFoundError(2, f"no finished dataset ('{group}') in this Zarr store",
                                str(path))
    with xr.open_zarr(str(path), group=group, consolidated=False) as ds:
        ds = ds.load()
    return _map_variables(ds, _decode)
