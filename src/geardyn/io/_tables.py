"""Study-table helpers shared by the study schema (:mod:`geardyn.io.toml`) and the gear-train
table (:mod:`geardyn.io.train_table`): a one-error ValidationError at a study location, and an
object built from a table whose keys are its class's keyword arguments."""

from __future__ import annotations

import inspect
from typing import Any

from pydantic import ValidationError
from pydantic_core import InitErrorDetails, PydanticCustomError

from geardyn.errors import ParameterError


def study_error(loc: tuple, value: object, reason: str, kind: str = "value_error"
                 ) -> ValidationError:
    """A one-error :class:`ValidationError` at ``loc`` of a study."""
    return ValidationError.from_exception_data("Study", [InitErrorDetails(
        type=PydanticCustomError(kind, "{msg}", {"msg": reason}), loc=loc, input=value)])


def build_from_fields(cls: type, given: dict[str, Any], where: tuple, what: str,
                       listed: str = "") -> object:
    """``cls(**given)``, the table's keys being the class's keyword arguments (its dataclass
    fields: one declaration); an unknown key, a missing one or a value the class refuses is an
    error at ``where`` + the key (``what`` names the object in the message, ``listed`` the
    table's other keys)."""
    params = inspect.signature(cls).parameters
    for key in given:
        if key not in params:
            raise study_error(where + (key,), given[key],
                               f"unknown key (not a field of {what}; fields:"
                               f" {listed}{', '.join(params)})")
    for name, p in params.items():
        if p.default is inspect.Parameter.empty and name not in given:
            raise study_error(where + (name,), None, f"required by {what}", kind="missing")
    try:
        return cls(**given)
    except ParameterError as exc:  # a field the class names, else the whole table
        name = exc.field.rpartition(".")[2]
        if name in params:
            raise study_error(where + (name,), exc.value, exc.reason) from None
        raise study_error(where, given, exc.reason) from None
