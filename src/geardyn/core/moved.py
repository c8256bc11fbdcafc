"""Names that moved to another module: their old home answers for one deprecation cycle with a
DeprecationWarning naming the new one."""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any


def moved(old_home: str, new_homes: Mapping[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``old_home``: each name of ``new_homes`` (name -> module it
    lives in now) is looked up there, with a DeprecationWarning the first time; any other name
    is an AttributeError."""
    warned: set[str] = set()

    def __getattr__(name: str) -> Any:
        home = new_homes.get(name)
        if home is None:
            raise AttributeError(f"module {old_home!r} has no attribute {name!r}")
        if name not in warned:
            warned.add(name)
            warnings.warn(f"{old_home}.{name} is deprecated: import it from {home}",
                          DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(home), name)

    return __getattr__
