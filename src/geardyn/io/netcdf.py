"""Simulation results as NetCDF-4 files (h5netcdf engine), written atomically.

netCDF attributes hold numbers, strings and arrays of them only, so :func:`save_dataset` converts
the attributes of the dataset and of every variable: booleans become ints (``True`` -> 1), ``None``
values are dropped, and dicts (and lists holding dicts or ``None``) become JSON strings.
:func:`load_dataset` reads a file back fully into memory and closes it; the data, coordinates and
the converted attributes come back identical.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from geardyn.io.atomic import atomic_replace

__all__ = ["load_dataset", "netcdf_attrs", "save_dataset"]

ENGINE = "h5netcdf"


def _attr_value(value: Any) -> Any:
    """A netCDF-safe attribute value, or ``None`` to drop it."""
    if value is None:
        return None
    if isinstance(value, bool | np.bool_):
        return int(value)
    if isinstance(value, dict):
        return json.dumps(value, default=_json_default, sort_keys=True)
    if isinstance(value, list | tuple):
        items = list(value)
        if any(isinstance(v, dict | list | tuple) or v is None for v in items):
            return json.dumps(items, default=_json_default)
        if any(isinstance(v, bool | np.bool_) for v in items):
            return [int(v) if isinstance(v, bool | np.bool_) else v for v in items]
        return items
    if isinstance(value, np.ndarray) and value.dtype == bool:
        return value.astype(np.int8)
    return value


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"attribute value of type {type(obj).__name__} cannot be stored")


def netcdf_attrs(attrs: dict[str, Any]) -> dict[str, Any]:
    """``attrs`` with the conversions :func:`save_dataset` applies."""
    out = {}
    for key, value in attrs.items():
        v = _attr_value(value)
        if v is not None:
            out[str(key)] = v
    return out


def _converted(ds: xr.Dataset) -> xr.Dataset:
    out = ds.copy(deep=False)
    out.attrs = netcdf_attrs(ds.attrs)
    for name in out.variables:
        out[name].attrs = netcdf_attrs(ds[name].attrs)
    return out


def save_dataset(ds: xr.Dataset, path: str | os.PathLike[str]) -> Path:
    """Write ``ds`` to ``path`` (NetCDF-4 via h5netcdf): a temporary file in the same folder,
    then an atomic rename, so a reader never sees half a file. Returns the path."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(2, "output folder does not exist", str(folder))
    with atomic_replace(path) as tmp:
        _converted(ds).to_netcdf(tmp, engine=ENGINE)
    return path


def load_dataset(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read a file written by :func:`save_dataset` fully into memory (the file is closed)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(2, "No such file", str(path))
    with xr.open_dataset(path, engine=ENGINE, decode_timedelta=False) as ds:
        return ds.load()
