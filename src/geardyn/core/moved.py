"""Deprecations, each warned once per process: names that moved to another module (their old
home answers for one deprecation cycle with a DeprecationWarning naming the new one), and any
other deprecated use (:func:`warn_once`, the one registry of what has been warned)."""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Hashable, Mapping
from typing import Any

#: The deprecations warned in this process, by the key their caller gives.
_WARNED: set[Hashable] = set()


def warn_once(key: Hashable, message: str, stacklevel: int) -> None:
    """A DeprecationWarning ``message``, the first time in this process for ``key``
    (``stacklevel``: as :func:`warnings.warn`'s, seen from the caller of this function)."""
    if key in _WARNED:
        return
    _WARNED.add(key)
    warnings.warn(message, DeprecationWarning, stacklevel=stacklevel + 1)


def forget_deprecations() -> None:
    """Let every deprecation warn again (for tests: each test sees the process as fresh)."""
    _WARNED.clear()


def moved(old_home: str, new_homes: Mapping[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``old_home``: each name of ``new_homes`` (name -> module it
    lives in now, or ``module:new_name`` where it has another name there) is looked up there,
    with a DeprecationWarning the first time (:func:`warn_once`); any other name is an
    AttributeError."""

    def __getattr__(name: str) -> Any:
        where = new_homes.get(name)
        if where is None:
            raise AttributeError(f"module {old_home!r} has no attribute {name!r}")
        home, _, new_name = where.partition(":")
        as_ = f" as {new_name}" if new_name else ""
        warn_once(("moved", old_home, name),
                  f"{old_home}.{name} is deprecated: import it from {home}{as_}", stacklevel=2)
        return getattr(importlib.import_module(home), new_name or name)

    return __getattr__
