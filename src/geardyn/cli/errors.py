"""One-line messages for the command line's expected errors: the field path and the value where
known (pydantic validation errors, :class:`~geardyn.ParameterError`, file errors, ...)."""

from __future__ import annotations

import tomllib
from typing import Any

from pydantic import BaseModel, ValidationError

__all__ = ["format_error"]


def _loc_text(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _one_validation_error(err: dict[str, Any]) -> str:
    msg = str(err.get("msg", "invalid value"))
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    if err.get("type") == "extra_forbidden":
        msg = "unknown key (not a field of this table)"
    where = _loc_text(tuple(err.get("loc", ())))
    text = f"{where}: {msg}" if where else msg
    value = err.get("input")
    if err.get("type") != "missing" and not isinstance(value, dict | list | BaseModel) and (
        "(got " not in msg
    ):
        text += f" (got {value!r})"
    return text


def format_error(exc: BaseException) -> str:
    """One line describing an expected error: the field path and the value where known.

    >>> format_error(ParameterError("sun_mesh.mean_stiffness", -1.0, "must be > 0"))
    'sun_mesh.mean_stiffness: must be > 0 (got -1.0)'
    """
    if isinstance(exc, ValidationError):
        # an unknown key is usually the cause of the "Field required" errors beside it
        errors = sorted(exc.errors(include_url=False),
                        key=lambda e: e.get("type") != "extra_forbidden")
        text = _one_validation_error(errors[0]) if errors else str(exc)
        if len(errors) > 1:
            text += f" (and {len(errors) - 1} more error{'s' if len(errors) > 2 else ''})"
    elif isinstance(exc, tomllib.TOMLDecodeError):
        text = f"invalid TOML: {exc}"
    elif isinstance(exc, KeyError):
        text = str(exc.args[0]) if exc.args else "unknown key"
    elif isinstance(exc, FileNotFoundError):
        text = f"file not found: {exc.filename}" if exc.filename else str(exc)
    elif isinstance(exc, IsADirectoryError | PermissionError | NotADirectoryError):
        text = f"{exc.strerror}: {exc.filename}" if exc.filename else str(exc)
    elif isinstance(exc, OSError):
        text = f"{exc.strerror or exc}: {exc.filename}" if exc.filename else str(exc)
    else:
        text = str(exc) or type(exc).__name__
    return " ".join(text.split())
