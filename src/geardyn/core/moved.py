"""Names that moved to another module: their old home answers for one deprecation cycle with a
DeprecationWarning naming the new one."""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any


def moved(old_home: str, new_homes: Mapping[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``old_home``: each name of ``new_homes`` (name -> module it
    lives in now, or ``module:new_name`` where it has another name there) is looked up there,
    with a DeprecationWarning the first time; any other name is an AttributeError."""
    warned: set[str] = set()

    def __getattr__(name: str) -> Any:
        where = new_homes.get(name)
        if where is None:
            raise AttributeError(f"module {old_home!r} has no attribute {name!r}")
        home, _, new_name = where.partition(":")
        if name not in warned:
            warned.add(name)
            as_ = f" as {new_name}" if new_name else ""
            warnings.warn(f"{old_home}.{name} is deprecated: import it from {home}{as_}",
                          DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(home), new_name or name)

    return __getattr__
