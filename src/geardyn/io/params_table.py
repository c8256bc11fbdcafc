"""``[params]`` tables generated from a model's declared physical inputs
(:mod:`geardyn.core.inputs`): one field per input a study takes (its type from the kind and
form, its default and its meaning as the description), unknown keys refused naming the field.

Two ways of reading values:

``"si"``
    each value is read into SI here (a unit string of the input's kind, a pair of them), its
    declared range checked (a ``spur_pair`` study);
``"given"``
    values are kept as given (an SI number or a unit string; one or per planet, per mesh, a
    list or ``{name = value}`` as the form says), only their types checked; the model checks
    the values when it is built (errors name ``params.<field>``: ``planetary`` and ``train``
    studies).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, create_model

from geardyn.core.inputs import PhysicalInput
from geardyn.models.params import Real, Whole
from geardyn.units import to_si

__all__ = ["PerMesh", "PerPlanet", "Quantity", "input_field", "params_table"]

_CONFIG = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

#: A quantity: an SI number or a unit string ("24.6 deg", "5e8 N/m").
Quantity = float | str
#: A quantity, or one per planet.
PerPlanet = float | str | list[float | str]
#: A quantity for every mesh, or one per mesh by name ({mesh = value}).
PerMesh = float | str | dict[str, float | str]


def _frequency_text(value: float | str) -> float | str:
    """A speed as given: a number >= 0 (in the model's speed_unit), or a unit string that reads
    as an angular frequency >= 0 (e.g. "3000 rpm")."""
    if (to_si(value, "frequency") if isinstance(value, str) else value) < 0:
        raise ValueError("must be >= 0")
    return value


def _si_type(i: PhysicalInput) -> Any:
    """The type of an input read into SI, range checked (form ``"one"`` only)."""
    if i.form != "one":
        raise ValueError(f"{i.name}: an input of form {i.form!r} is read as given, not in SI")
    if i.kind == "choice":
        return Literal[i.choices]  # type: ignore[valid-type]
    if i.kind == "count":
        return Annotated[Whole, Field(**i.bounds())]
    if i.kind == "pair":
        one = Annotated[float, BeforeValidator(lambda v, k=i.unit_kind: to_si(v, k)),
                        Field(gt=0)]
        return Annotated[list[one], Field(min_length=2, max_length=2)]  # type: ignore[valid-type]
    if i.kind == "frequency":  # a number in the model's speed unit, or a unit string (as given)
        return Annotated[Real | str, AfterValidator(_frequency_text)]
    if i.kind in ("number", "flag", "name", "table"):
        raise ValueError(f"{i.name}: a {i.kind} input is read as given, not in SI")
    return Annotated[float, BeforeValidator(lambda v, k=i.kind: to_si(v, k)),
                     Field(**i.bounds())]


def _given_type(i: PhysicalInput, tables: Mapping[str, type[BaseModel]]) -> Any:
    """The type of an input kept as given: one value of its kind in its form."""
    one: Any
    if i.kind == "table":
        one = tables[i.table]  # type: ignore[index]
    elif i.kind == "choice":
        one = Literal[i.choices]  # type: ignore[valid-type]
    else:
        one = {"number": float, "count": int, "flag": bool, "name": str,
               "pair": list[Quantity]}.get(i.kind, Quantity)
    return {"one": one, "per_planet": one | list[one], "per_mesh": one | dict[str, one],
            "list": list[one], "by_name": dict[str, one]}[i.form]


def input_field(i: PhysicalInput, values: str = "si",
                tables: Mapping[str, type[BaseModel]] | None = None) -> tuple[Any, Any]:
    """The pydantic type and field of one declared input (``values``: ``"si"`` or ``"given"``,
    see the module doc; ``tables``: the nested tables by the names inputs give). A required
    input with an ``alternative`` is optional here (None), as is one whose default is None;
    an empty list default is a new list per study."""
    if values == "si":
        kind = _si_type(i)
    elif values == "given":
        kind = _given_type(i, tables or {})
    else:
        raise ValueError(f"values must be 'si' or 'given' (got {values!r})")
    default = None if i.required and i.alternative is not None else (
        ... if i.required else i.default)
    if default is None:
        kind = kind | None
    if i.form == "list" and default == ():
        return kind, Field(default_factory=list, description=i.meaning)
    return kind, Field(default, description=i.meaning)


def params_table(name: str, inputs: Iterable[PhysicalInput], doc: str, *, values: str = "si",
                 tables: Mapping[str, type[BaseModel]] | None = None) -> type[BaseModel]:
    """A ``[params]`` table class ``name`` (docstring ``doc``) with one field per declared input
    a study takes (``study`` true), in their order; unknown keys refused naming the field."""
    fields = {i.name: input_field(i, values, tables) for i in inputs if i.study}
    return create_model(name, __config__=_CONFIG, __doc__=doc, __module__="geardyn.io.toml",
                        **fields)
