"""Simulation results as NetCDF-4 files (h5netcdf engine), written atomically.

netCDF attributes hold numbers, strings and arrays of them only, so :func:`save_dataset` converts
the attributes of the dataset and of every variable: booleans become ints (``True`` -> 1), ``None``
values are dropped, and dicts (and lists holding dicts or ``None``) become JSON strings.
:func:`load_dataset` reads a file back fully into memory and closes it; the data, coordinates and
the converted attributes come back identical.
"""

from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

from geardyn.core.moved import moved
from geardyn.files import atomic_replace
from geardyn.files import netcdf_attrs as _netcdf_attrs

__all__ = ["load_dataset", "save_dataset"]

__getattr__ = moved(__name__, {"netcdf_attrs": "geardyn.files"})

ENGINE = "h5netcdf"


def _converted(ds: xr.Dataset) -> xr.Dataset:
    out = ds.copy(deep=False)
    out.attrs = _netcdf_attrs(ds.attrs)
    for name in out.variables:
        out[name].attrs = _netcdf_attrs(ds[name].attrs)
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
