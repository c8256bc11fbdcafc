"""File primitives shared by the layers that write files (execution's Zarr stores, io's NetCDF
and TOML): atomic replacement (a reader sees the old file or the new one, never half a file) and
the conversion of dataset attributes to what netCDF and Zarr can hold (booleans -> ints, ``None``
dropped, dicts and lists holding them -> JSON). Imports nothing of geardyn."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np


@contextmanager
def atomic_replace(path: Path) -> Iterator[str]:
    """Yield the name of a new temporary file beside ``path`` to write; when the block ends
    normally it gets the permissions a new file would get and atomically replaces ``path``,
    otherwise it is removed. Raises OSError when the temporary file cannot be created."""
    folder = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


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
