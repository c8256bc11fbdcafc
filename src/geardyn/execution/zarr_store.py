"""Zarr stores (format 3): a finished dataset that plain xarray opens, with the resumable lane
results of the run that computed it.

A map's store (``geardyn.map2d(..., store="map.zarr")``, ``geardyn map --out map.zarr``)::

    map.zarr/zarr.json              the dataset's attributes, and consolidated metadata
    map.zarr/<variable>/            the dataset's arrays: ``xarray.open_zarr("map.zarr")``
    map.zarr/lanes/zarr.json        attribute "geardyn_lanes": inputs digest, lanes, chunk, runs
    map.zarr/lanes/done             per chunk: 0 = missing, else the number of the run that did it
    map.zarr/lanes/outputs/<name>   one array per output, lane-first, chunked like the run

A :class:`LaneStore` keeps the per-lane outputs of a chunked run
(:func:`geardyn.execution.executor.run_chunks`) in the ``lanes`` group as they complete. A chunk's
data are written before its ``done`` entry, and every file of the store is written atomically
(zarr's local store writes a temporary file, then renames it), so a run killed at any moment
leaves no half-written chunk counted as done: the next run with the same inputs recomputes
exactly the chunks not marked done. A store whose recorded inputs digest differs is refused.

Until the dataset is written (:func:`save_zarr_dataset`, once every chunk is done) the root holds
no arrays and its attribute ``geardyn_unfinished`` says so; the dataset replaces the root's
arrays and then, in one atomic write, its ``zarr.json`` (attributes and consolidated metadata).
String variables (e.g. the contact regime) are stored with zarr's variable-length ``string``
type.

Stores of the earlier layout (lane store at the root, dataset in the group ``result``) are still
read by :func:`load_zarr_dataset` (``geardyn plot``) but not resumed: :meth:`LaneStore.begin`
refuses them with a message naming the path.
"""

from __future__ import annotations

import json
import os
import shutil
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from geardyn.errors import GeardynError
from geardyn.files import atomic_replace, netcdf_attrs

__all__ = ["LANES_GROUP", "LaneStore", "StoreMismatchError", "load_zarr_dataset",
           "save_zarr_dataset"]

_ATTR = "geardyn_lanes"
_FORMAT = 2  # 1: lane store at the root, dataset in "result" (geardyn 0.1 before issue 10)
_CATEGORICAL = "geardyn_categorical"
_UNFINISHED = "geardyn_unfinished"
#: Group of a store that holds the lane store.
LANES_GROUP = "lanes"
_OUTPUTS = "outputs"
_PARTIAL = "dataset.partial"  # a dataset being written, beside the root's arrays
_LEGACY_RESULT = "result"


class StoreMismatchError(GeardynError, ValueError):
    """A store holds a run with other inputs than the one asked for, or is not a geardyn store
    of the current layout."""


def _open_group(path: Path, mode: str):
    import zarr

    return zarr.open_group(str(path), mode=mode, zarr_format=3, use_consolidated=False)


def _read_meta(path: Path) -> dict[str, Any] | None:
    """The ``zarr.json`` of the node at ``path`` (None when there is none)."""
    try:
        return json.loads((path / "zarr.json").read_text())
    except FileNotFoundError:
        return None


def _write_meta(path: Path, meta: dict[str, Any]) -> None:
    """Replace ``path/zarr.json`` atomically."""
    with atomic_replace(path / "zarr.json") as tmp:
        Path(tmp).write_text(json.dumps(meta, indent=2))


def _empty_root(note: str) -> dict[str, Any]:
    """A group node holding no dataset yet (consolidated: xarray opens it, empty, quietly)."""
    return {"zarr_format": 3, "node_type": "group", "attributes": {_UNFINISHED: note},
            "consolidated_metadata": {"kind": "inline", "must_understand": False,
                                      "metadata": {}}}


_NOTE = ("no dataset yet: the run writing this store has not finished (a rerun of the same "
         "command resumes it)")


def _is_legacy(meta: dict[str, Any] | None) -> bool:
    return meta is not None and _ATTR in meta.get("attributes", {})


def _legacy_message(path: Path) -> str:
    return (f"{path}: a Zarr store of the earlier geardyn layout (lane store at the root, "
            f"dataset in the group '{_LEGACY_RESULT}'); `geardyn plot` still reads it, but a run "
            "cannot resume it: delete it, or write to another path, to compute it again")


def _prepare_root(path: Path) -> None:
    """Create the store's root group (no dataset yet) and its ``lanes`` group unless they are
    there; refuse a path that is not a geardyn store of the current layout (another Zarr store's
    arrays would be replaced by the dataset)."""
    if path.exists() and not path.is_dir():
        raise StoreMismatchError(f"{path}: exists and is not a Zarr store")
    meta = _read_meta(path) if path.is_dir() else None
    if meta is None:
        if path.is_dir() and any(path.iterdir()):
            raise StoreMismatchError(f"{path}: exists and is not a Zarr store")
        path.mkdir(parents=True, exist_ok=True)
        _write_meta(path, _empty_root(_NOTE))
    elif _is_legacy(meta):
        raise StoreMismatchError(_legacy_message(path))
    elif meta.get("node_type") != "group":
        raise StoreMismatchError(f"{path}: a Zarr array, not a store")
    elif (_UNFINISHED not in meta.get("attributes", {}) and _read_meta(path / LANES_GROUP) is None
          and any(p.name != "zarr.json" for p in path.iterdir())):
        raise StoreMismatchError(f"{path}: a Zarr store that geardyn did not write (its data "
                                 "would be replaced); choose another path")
    if _read_meta(path / LANES_GROUP) is None:  # marks the store as geardyn's
        (path / LANES_GROUP).mkdir(exist_ok=True)
        _write_meta(path / LANES_GROUP, {"zarr_format": 3, "node_type": "group",
                                         "attributes": {}})


class LaneStore:
    """Per-lane outputs of a chunked run, resumable (see the module docstring). ``path`` is the
    store (``map.zarr``); the lane store is its group ``lanes``."""

    def __init__(self, path: str | os.PathLike[str]):
        self.path = Path(path)
        self.run = 0
        self._group = None
        self._done = None
        self._n_lanes = 0
        self._chunk = 0

    @property
    def lanes_path(self) -> Path:
        """Folder of the lane store (group ``lanes`` of the store)."""
        return self.path / LANES_GROUP

    def _lanes(self, mode: str = "r"):
        if mode == "r" and _is_legacy(_read_meta(self.path)):
            raise StoreMismatchError(_legacy_message(self.path))
        return _open_group(self.lanes_path, mode)

    # ------------------------------------------------------------------ opening
    def begin(self, digest: str, n_lanes: int, chunk: int, meta: dict[str, Any]) -> int:
        """Open (or create) the store for a run with inputs ``digest`` and return this run's
        number (1 for a fresh store). Raises :class:`StoreMismatchError` when the store holds a
        run with other inputs, or is not a store of the current layout."""
        _prepare_root(self.path)
        group = _open_group(self.lanes_path, "a")
        n_chunks = -(-n_lanes // chunk)
        info = group.attrs.get(_ATTR)
        if info is None:  # fresh (or interrupted before it was initialised)
            group.create_array("done", shape=(n_chunks,), chunks=(1,), dtype="int32",
                               fill_value=0, overwrite=True)
            if _OUTPUTS in group:
                del group[_OUTPUTS]
            group.create_group(_OUTPUTS)
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
        return dict(self._lanes().attrs[_ATTR])

    # ------------------------------------------------------------------ chunks
    def done_chunks(self) -> np.ndarray:
        """Bool per chunk: finished and marked done."""
        return self.chunk_runs() > 0

    def chunk_runs(self) -> np.ndarray:
        """Per chunk, the run (1, 2, ...) that computed it; 0 where still missing."""
        done = self._done if self._done is not None else self._lanes()["done"]
        return np.asarray(done[:])

    def write_chunk(self, index: int, start: int, stop: int, outputs: dict[str, np.ndarray]
                    ) -> None:
        """Write one chunk's outputs (lanes ``start:stop``), then mark it done."""
        if self._group is None:
            raise RuntimeError("LaneStore.begin() first")
        lanes = self._group[_OUTPUTS]
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
        group = self._group if self._group is not None else self._lanes()
        missing = np.nonzero(~self.done_chunks())[0]
        if missing.size:
            raise RuntimeError(f"{self.path}: chunks {missing.tolist()[:5]} are not finished")
        return {name: np.asarray(arr[:]) for name, arr in group[_OUTPUTS].arrays()}


# ---------------------------------------------------------------------------- datasets
def _decode(var: xr.Variable) -> xr.Variable:
    """Flag codes of the earlier layout's string variables as strings."""
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


def _strings_as_objects(var: xr.Variable) -> xr.Variable:
    """Fixed-width strings as Python strings (zarr's stable variable-length ``string`` type)."""
    if var.dtype.kind not in "US":
        return var
    return xr.Variable(var.dims, np.asarray(var.values).astype(str).astype(object), var.attrs)


def _strings_as_str(var: xr.Variable) -> xr.Variable:
    """Strings read back (object or numpy StringDType) as fixed-width numpy strings."""
    if var.dtype.kind not in "OT":
        return var
    return xr.Variable(var.dims, np.asarray(var.values).astype(object).astype(str), var.attrs)


def _is_array(path: Path) -> bool:
    meta = _read_meta(path) if path.is_dir() else None
    return meta is not None and meta.get("node_type") == "array"


def _write_dataset(ds: xr.Dataset, target: Path) -> None:
    """Write ``ds`` as the dataset of the group folder ``target``: into a standalone store
    beside it first, then its arrays replace the group's arrays (subgroups stay), then its
    ``zarr.json`` (attributes, consolidated metadata) replaces the group's in one atomic write.
    Until that last write the group carries the ``geardyn_unfinished`` attribute."""
    import zarr.errors

    reserved = {LANES_GROUP, _PARTIAL, _LEGACY_RESULT} & {str(n) for n in ds.variables}
    if reserved:
        raise ValueError(f"variable names {sorted(reserved)} are reserved in a geardyn store")
    tmp = target / _PARTIAL
    if tmp.exists():
        shutil.rmtree(tmp)
    with warnings.catch_warnings():  # the format-3 consolidation note (xarray reads it fine)
        warnings.filterwarnings("ignore", category=zarr.errors.ZarrUserWarning,
                                message="Consolidated metadata")
        ds.to_zarr(str(tmp), mode="w", consolidated=True, zarr_format=3)
    _write_meta(target, _empty_root("a dataset is being written here; if this stays, the "
                                    "writing was interrupted: write it again"))
    for child in target.iterdir():
        if child.name != _PARTIAL and _is_array(child):
            shutil.rmtree(child)
    for name in ds.variables:
        os.replace(tmp / str(name), target / str(name))
    os.replace(tmp / "zarr.json", target / "zarr.json")
    shutil.rmtree(tmp)


def save_zarr_dataset(ds: xr.Dataset, path: str | os.PathLike[str], group: str | None = None
                      ) -> Path:
    """Write ``ds`` as the dataset of the Zarr store ``path`` (its root, or the subgroup
    ``group``), so that ``xarray.open_zarr(path)`` opens it, quietly (consolidated metadata).
    The store's other groups (the lane store) stay; its earlier dataset is replaced. Attributes
    are converted as for NetCDF. Returns the path."""
    path = Path(path)
    _prepare_root(path)
    out = _map_variables(ds, _strings_as_objects)
    out.attrs = netcdf_attrs(ds.attrs)
    for name in out.variables:
        out[name].attrs = netcdf_attrs(out[name].attrs)
    target = path
    if group is not None:
        target = path / group
        if _read_meta(target) is None:
            target.mkdir(parents=True, exist_ok=True)
            _write_meta(target, _empty_root(_NOTE))
    _write_dataset(out, target)
    return path


def load_zarr_dataset(path: str | os.PathLike[str], group: str | None = None) -> xr.Dataset:
    """Read the dataset of a Zarr store written by :func:`save_zarr_dataset` (the root, or the
    subgroup ``group``) fully into memory. A store of the earlier layout is read from its group
    ``result``. Raises FileNotFoundError when the store holds no finished dataset."""
    path = Path(path)
    root = _read_meta(path)
    if root is None:
        raise FileNotFoundError(2, "not a Zarr store", str(path))
    if group is None and _is_legacy(root):
        group = _LEGACY_RESULT
    node = path if group is None else path / group
    meta = _read_meta(node)
    if meta is None or _UNFINISHED in meta.get("attributes", {}):
        note = (meta or {}).get("attributes", {}).get(_UNFINISHED, "no dataset")
        raise FileNotFoundError(2, f"no finished dataset in this Zarr store ({note})", str(path))
    consolidated = "consolidated_metadata" in meta
    with xr.open_zarr(str(path), group=group, consolidated=consolidated) as ds:
        ds = ds.load()
    return _map_variables(_map_variables(ds, _decode), _strings_as_str)
