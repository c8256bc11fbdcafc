"""Physical inputs declared once: what a user passes to a model's constructor (or writes under
``[params]`` in a study file).

A model's coefficients (:mod:`geardyn.core.coefficients`) are what its kernels read; its
*physical inputs* are what a user gives (SI numbers or unit strings, counts, choices, nested
tables), from which the model derives the coefficients. Each input is declared once, by a
:class:`PhysicalInput` (name, kind and unit, meaning, default, form, choices), in a tuple next to
the model's coefficient declarations. From the declarations come:

* the ``[params]`` table of the model's study files (:func:`geardyn.io.params_table.params_table`:
  one field per input, its type from the kind and form, its default and description);
* the unit kinds ``with_params`` reads unit strings by;
* the names a sweep takes (``swept``: :func:`swept`; a model's ``physical_names``, those that
  re-derive its coefficients, :func:`rederived`), the units of their axes
  (:attr:`PhysicalInput.axis_unit`) and the refusal, naming the input, of a sweep of any other
  declared input (:meth:`geardyn.core.model.Model.lane_params`);
* the explorer's controls (``explore``: :func:`explored`);
* a check that the declaration and the model's constructor agree: every declared input a
  keyword of its builder (``of``) with the declared default, every keyword of the constructor
  declared (``tests/test_model_inputs.py``).

Kinds (:data:`INPUT_KINDS`): a :data:`geardyn.units.SI_UNITS` kind (an SI number or a unit
string of that kind), ``"pair"`` (two values of ``unit_kind``), ``"number"`` (a plain real
number), ``"count"`` (a whole number), ``"flag"`` (True or False), ``"choice"`` (one of
``choices``), ``"name"`` (the name of a part of the model, e.g. a mesh or a body) or ``"table"``
(a nested table, named by ``table``; the study layer maps that name to its table).

Forms (:data:`FORMS`): ``"one"`` (one value), ``"per_planet"`` (one value for every planet or a
list of one per planet), ``"per_mesh"`` (one value for every mesh or ``{mesh: value}``),
``"list"`` (a list of values) and ``"by_name"`` (``{name: value}``).

A swept input (``swept=True``) is a number of its kind, one value (for every planet or mesh where
its form is ``"per_planet"`` or ``"per_mesh"``): a sweep re-derives the coefficients from each
value. Counts, flags, choices, names, tables, lists and the model's scales are not swept. A swept
input declared with the coefficient of its own name (``coefficient``) is that coefficient: a
sweep or ``with_params`` sets the entry (in range), and the input is no physical name
(:func:`rederived`); any other swept input re-derives the coefficients from its value.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn.core.coefficients import Coefficient
from geardyn.units import SI_UNITS

__all__ = ["AXIS_UNITS", "FORMS", "INPUT_KINDS", "REQUIRED", "SWEPT_FORMS", "SWEPT_KINDS",
           "PhysicalInput", "by_name", "explored", "one_value", "rederived", "swept",
           "unit_kind"]


class _Required:
    """The default of a required input (a singleton)."""

    def __repr__(self) -> str:
        return "REQUIRED"


#: The default of a required input.
REQUIRED = _Required()
#: The kinds of physical input (see the module doc).
INPUT_KINDS: tuple[str, ...] = (*SI_UNITS, "pair", "number", "count", "flag", "choice", "name",
                                "table")
#: The forms of physical input (see the module doc).
FORMS: tuple[str, ...] = ("one", "per_planet", "per_mesh", "list", "by_name")
#: The unit of a sweep's axis (dataset attribute ``units``) of each kind of swept input.
AXIS_UNITS: dict[str, str] = {
    "length": "m", "angle": "rad", "stiffness": "N/m", "inertia": "kg m^2", "mass": "kg",
    "density": "kg/m^3", "torque": "N m", "force": "N", "pressure": "Pa", "dimensionless": "1",
    "frequency": "rad/s", "number": "1"}
#: The kinds of input a sweep may take (numbers: an SI kind or a plain number).
SWEPT_KINDS: tuple[str, ...] = tuple(AXIS_UNITS)
#: The forms of input a sweep may take (one value, for every planet or mesh).
SWEPT_FORMS: tuple[str, ...] = ("one", "per_planet", "per_mesh")


@dataclass(frozen=True)
class PhysicalInput:
    """One physical input of a model: a keyword of its constructor (or of the builder named by
    ``of``, e.g. ``"from_geometry"``).

    ``kind`` one of :data:`INPUT_KINDS` (``unit_kind`` the SI kind of each value of a
    ``"pair"``), ``form`` one of :data:`FORMS`; ``default`` :data:`REQUIRED` or the value (None:
    derived or left out, see ``meaning``); ``coefficient`` the declared coefficient the input
    sets directly, whose range applies, or ``minimum``/``maximum`` (inclusive); ``choices`` the
    values of a ``"choice"``; ``table`` the name of a ``"table"`` input's nested table;
    ``alternative`` the input that stands for this one (a required input the study may leave out
    where it gives that one: the study table's default is then None and the model's builder says
    which is missing); ``study`` False for a constructor keyword a study's ``[params]`` does not
    take (``meaning`` says where it comes from); ``swept`` whether a sweep takes it by name (a
    number of one of :data:`SWEPT_KINDS` in one of :data:`SWEPT_FORMS`); ``unit`` the unit a
    plain number, a sweep's values and its axis are in where it is not the kind's SI unit (e.g.
    ``"rpm"``); ``explore`` whether the explorer offers the input as a control (a number, a
    count or a choice of the study's ``[params]``, where the study gives it one value), in
    declared order."""

    name: str
    kind: str
    meaning: str
    default: object = REQUIRED
    form: str = "one"
    coefficient: Coefficient | None = None
    unit_kind: str | None = None
    choices: tuple[str, ...] = ()
    minimum: float | None = None
    maximum: float | None = None
    table: str | None = None
    of: str = "__init__"
    alternative: str | None = None
    study: bool = True
    swept: bool = False
    unit: str | None = None
    explore: bool = False

    def __post_init__(self) -> None:
        if self.kind not in INPUT_KINDS:
            raise ValueError(f"{self.name}: kind must be one of {', '.join(INPUT_KINDS)}; "
                             f"got {self.kind!r}")
        if self.form not in FORMS:
            raise ValueError(f"{self.name}: form must be one of {', '.join(FORMS)}; "
                             f"got {self.form!r}")
        if (self.kind == "choice") != bool(self.choices):
            raise ValueError(f"{self.name}: a choice (and only a choice) declares its choices")
        if (self.kind == "table") != (self.table is not None):
            raise ValueError(f"{self.name}: a table input (and only one) names its table")
        if (self.kind == "pair") != (self.unit_kind is not None):
            raise ValueError(f"{self.name}: a pair (and only a pair) declares its unit_kind")
        if self.unit_kind is not None and self.unit_kind not in SI_UNITS:
            raise ValueError(f"{self.name}: unit_kind must be one of {', '.join(SI_UNITS)}")
        if (self.kind == "choice" and self.form == "one" and self.default not in (
                REQUIRED, None, *self.choices)):
            raise ValueError(f"{self.name}: default {self.default!r} is not one of the choices")
        if self.swept and (self.kind not in SWEPT_KINDS or self.form not in SWEPT_FORMS):
            raise ValueError(f"{self.name}: a swept input is a number ({', '.join(SWEPT_KINDS)}) "
                             f"of form {', '.join(SWEPT_FORMS)}; got {self.kind} {self.form}")
        if self.unit is not None and self.kind not in SWEPT_KINDS:
            raise ValueError(f"{self.name}: only a number of a unit kind declares its unit")
        if self.explore and (self.kind not in (*SWEPT_KINDS, "count", "choice")
                             or not self.study):
            raise ValueError(f"{self.name}: an explorer control is a number, a count or a "
                             f"choice of the study's [params]; got {self.kind}")

    @property
    def required(self) -> bool:
        """Whether the builder requires the input (no default)."""
        return self.default is REQUIRED

    @property
    def axis_unit(self) -> str | None:
        """The unit of a sweep's axis in the input: ``unit``, else its kind's
        (:data:`AXIS_UNITS`); None for a kind that is no number."""
        return self.unit or AXIS_UNITS.get(self.kind)

    def bounds(self) -> dict[str, float]:
        """The admissible range (pydantic's ``ge``/``gt``/... keywords): the declared
        coefficient's range, or ``minimum``/``maximum``."""
        c = self.coefficient
        if c is None:
            return {k: v for k, v in (("ge", self.minimum), ("le", self.maximum))
                    if v is not None}
        return {k: v for k, v in (("ge", c.minimum), ("le", c.maximum),
                                  ("gt", c.exclusive_minimum), ("lt", c.exclusive_maximum))
                if v is not None}

    def count(self, value: Any) -> int:
        """``value``, a count (a whole number, not a bool) within ``minimum``/``maximum``: what
        the study file's schema takes too; else a :class:`~geardyn.ParameterError` naming the
        input."""
        from geardyn.errors import ParameterError

        lo, hi = self.minimum, self.maximum
        if isinstance(value, bool) or not isinstance(value, int | np.integer) \
                or (lo is not None and value < lo) or (hi is not None and value > hi):
            span = (f"from {lo:g} to {hi:g}" if lo is not None and hi is not None
                    else f">= {lo:g}" if lo is not None else f"<= {hi:g}" if hi is not None
                    else "")
            raise ParameterError(self.name, value, f"must be a whole number {span}".strip())
        return int(value)


def by_name(inputs: Iterable[PhysicalInput]) -> dict[str, PhysicalInput]:
    """The declared inputs by name; a ValueError where a name is declared twice."""
    out: dict[str, PhysicalInput] = {}
    for i in inputs:
        if i.name in out:
            raise ValueError(f"input {i.name!r} is declared twice")
        out[i.name] = i
    return out


def swept(inputs: Iterable[PhysicalInput]) -> dict[str, PhysicalInput]:
    """The swept inputs (``swept``) by name, in declared order."""
    return {i.name: i for i in by_name(inputs).values() if i.swept}


def rederived(inputs: Iterable[PhysicalInput]) -> tuple[str, ...]:
    """The swept inputs the coefficients are re-derived from, in declared order: every swept
    input but one declared with the coefficient of its own name (that coefficient itself)."""
    return tuple(n for n, i in swept(inputs).items()
                 if i.coefficient is None or i.coefficient.name != n)


def explored(inputs: Iterable[PhysicalInput]) -> tuple[str, ...]:
    """The inputs the explorer offers as controls (``explore``), in declared order."""
    return tuple(n for n, i in by_name(inputs).items() if i.explore)


#: The SI kind of each axis unit (:data:`AXIS_UNITS`), "1" the dimensionless kind.
_KIND_OF_UNIT: dict[str, str] = {u: k for k, u in AXIS_UNITS.items() if k in SI_UNITS}


def unit_kind(unit: str) -> str:
    """The SI kind (:data:`geardyn.units.SI_UNITS`) of a declared coefficient's ``unit`` (its
    axis unit, :data:`AXIS_UNITS`: ``"N m"`` -> ``"torque"``, ``"1"`` -> ``"dimensionless"``);
    a ValueError for a unit of no kind."""
    if unit not in _KIND_OF_UNIT:
        raise ValueError(f"unit {unit!r} is none of {', '.join(_KIND_OF_UNIT)}")
    return _KIND_OF_UNIT[unit]


def one_value(value: object) -> bool:
    """Whether an input's value is one value (a number, a unit string or None), not one per
    planet or mesh (a list, a tuple, an array or a mapping) nor a flag."""
    return not isinstance(value, bool | Mapping | list | tuple | np.ndarray)


#: Most planets of a planetary stage: the limit of every model, study table, builder and gear
#: formula that takes ``n_planets`` (read from :data:`N_PLANETS`).
MAX_PLANETS = 32
#: The count ``n_planets``, declared once with its range (:meth:`PhysicalInput.count`): read by
#: the planetary models, trains and study tables, and by the planetary gear formulas
#: (:func:`geardyn.gears.phasing.equally_spaced`,
#: :func:`geardyn.gears.iso6336_kv.planetary_reduced_masses`) below them.
N_PLANETS = PhysicalInput("n_planets", "count", "number of planets N", 3, minimum=1,
                          maximum=MAX_PLANETS)
