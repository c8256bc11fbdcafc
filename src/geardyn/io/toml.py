"""Parameter and study files in TOML.

A *parameter file* holds the fields of :class:`~geardyn.PlanetaryParams` as nested tables (SI
floats, angles in rad; unit strings such as ``"50 um"`` are accepted on input).
:func:`save_params` writes floats with ``repr`` precision, so a load-save round trip is lossless.

A *study file* holds the device parameters plus run settings::

    [study]
    name = "fig3"
    description = "Paper Fig. 3"
    model = "catt"                  # or "gear_pair", "planetary", "spur_pair", "train"
    interpretation = "consistent"   # consistent | carrier-only | as-printed
    plot_state = "X_sq"             # the coordinate figures show
    [params]                        # PlanetaryParams fields (nested tables), or:
    base = "paper"                  # PlanetaryParams.paper() ...
    [params.changes]                # ... with changes by the paper's names (xi1, backlash, B1, ...)
    xi1 = 0.05
    [run]                           # optional: omega and every geardyn.RunSettings field
    transient = 4000.0              # the transient: a time (tau) ...
    # transient_periods = 20        # ... or forcing periods of the run's lowest Omega
    converge = 1e-6                 # optional: transient by convergence (then a minimum),
    transient_max = 40000.0         #   up to this (default 10 x transient)
    # periods (samples), steps_per_period, locate_edges, bound, continued_transient,
    # max_period, period_tol, max_section_periods: as geardyn.RunSettings
    [sweep]                         # optional: param, start, stop, num, continuation,
                                    # samples, lyapunov (see SweepSettings)
    [envelope]                      # optional: geardyn envelope's plane, box, flanks, ...
                                    # (see geardyn.io.envelope_table)
    [runup]                         # optional: geardyn runup's ramp: param, start, stop,
                                    # rate or duration, sample_rate, outputs (RunupTable)
    [dataset]                       # optional: geardyn dataset's labelled fault data: faults,
                                    # speeds, torques, seeds, ... (DatasetTable)

A spur pair for the potential-energy mesh stiffness (``geardyn stiffness``), with or instead
of ``[params]``::

    [gears]                         # GearsTable: the pair's common values
    module = "3.2 mm"
    pressure_angle = "20 deg"
    face_width = "16 mm"            # or per gear
    bore_radius = "12 mm"           # or per gear
    # addendum = 1.0, dedendum = 1.25, centre_distance, young = 206.8e9, poisson = 0.3
    [gears.pinion]                  # PairGearTable: teeth, profile_shift, and per-gear values
    teeth = 19
    [gears.wheel]
    teeth = 48
    bore_radius = "35 mm"
    [[faults]]                      # FaultTable: kind (gears.FAULT_KINDS) and its fields
    kind = "crack"
    gear = "pinion"
    tooth = 0
    depth = "1 mm"
    angle = "45 deg"
    [stiffness]                     # StiffnessTable: angles per mesh cycle, cycles or
    angles = 360                    #   "hunting", nodes, root_segment; slices (helical);
    cycles = "hunting"              #   the load of the loaded contact: torque or force
    torque = "50 N m"
    [[relief]]                      # ReliefTable: a TipRelief's fields
    amount = "10 um"
    length = "1.5 mm"
    [crowning]                      # CrowningTable (or [[crowning]]): a LeadCrowning's
    amount = "5 um"                 #   fields (helical pairs)

``[gears]`` also takes ``helix_angle`` (a helical pair by thin slices; module, pressure angle
and profile shifts then in the normal section) or ``internal = true`` (the wheel a ring, its
``[gears.wheel]`` ``bore_radius`` the ring's outer radius; ``ring_foundation``).

A gear train from elements (``geardyn modes``), with or instead of ``[params]``: the
``[train]`` table (:mod:`geardyn.io.train_table`). For ``model = "train"`` the model is that
train's nonlinear model, :class:`~geardyn.trains.TrainModel`, and ``[params]``
(:class:`TrainModelParams`) holds its inputs: ``input_speed`` [rpm], ``torques`` (``{body =
torque}``), ``load``, ``backlash``, ``mesh_damping``, ``stiffness_fluctuation``, ``mesh_phase``,
``mesh_error`` (each a scalar or ``{mesh = value}``), ...

For ``model = "spur_pair"`` the model is :meth:`geardyn.SpurPair.from_geometry` of the
``[gears]``, ``[[faults]]`` and ``[stiffness]`` tables, and ``[params]``
(:class:`SpurPairParams`, generated from SpurPair's declared inputs) holds its dynamics:
``speed`` (a number in ``speed_unit``: rad/s, rpm or Hz; or a unit string), ``torque``,
``inertia`` ([I1, I2]), ``zeta``, ``backlash``, ``error``, ``error_phase``, ``harmonics``,
``period``; its runs are in seconds, and the default transient is
:data:`DEFAULT_TRANSIENT_PERIODS` forcing periods.
For ``model = "gear_pair"`` the ``[params]`` table holds :class:`~geardyn.GearPair` arguments
(``zeta``, ``kappa``, ``Fm``, ``Fa``, ``Omega``, ``kappa_phase``, ``error_phase``, ``backlash``).
For ``model = "planetary"`` it holds :class:`~geardyn.PlanetaryGearSet` arguments
(:class:`PlanetaryGearSetParams`: SI numbers or unit strings; ``[params.sun]``, ``[params.ring]``,
``[params.carrier]``, ``[params.planet]`` are :class:`~geardyn.Member` tables; a
``[params.geometry]`` table (:class:`GeometryTable`) builds it from gear geometry instead of
mesh stiffnesses); their values are checked when the model is built (errors name
``params.<field>``).

The ``[run]`` table (:class:`RunTable`) sets the :class:`geardyn.RunSettings` of the study's
runs (command-line options win, see :meth:`Study.run_sources`): one key per RunSettings field,
generated from RunSettings' declaration (``periods`` for ``samples``, :data:`RUN_TABLE_NAMES`)
and checked by RunSettings' own rules when the study is read: ``transient`` (tau) or
``transient_periods`` (not both: the transient is then that many forcing periods at the lowest
Omega of the run, e.g. of a sweep's range, so every point gets at least that many),
``periods``, ``steps_per_period``, ``locate_edges``, ``bound``, ``converge`` (a relative
tolerance in (0, 1): the transient runs on until the Poincare point has settled, up to
``transient_max``, which needs ``converge``), ``continued_transient``, ``max_period`` and
``period_tol`` (the period classifier), ``max_section_periods``. Errors name ``run.<key>``.

This module only reads and validates: a study file becomes a :class:`Study` (plain, validated
data; its device parameters a :class:`~geardyn.PlanetaryParams`). Turning a study into a model is
:func:`geardyn.study.build_model`'s job, one layer up; every error names the field path and the
value, and :func:`geardyn.cli.errors.format_error` renders it as one line.
"""

from __future__ import annotations

import inspect
import math
import os
import tomllib
from collections.abc import Callable, Mapping
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import tomli_w
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    StrictBool,
    ValidationError,
    ValidationInfo,
    create_model,
    field_validator,
    model_validator,
)
from pydantic_core import InitErrorDetails, PydanticCustomError

from geardyn.core.coefficients import CoefficientBlock
from geardyn.core.inputs import PhysicalInput
from geardyn.core.settings import (
    DEFAULT_MAX_PERIOD,
    DEFAULT_TOL,
    FIELDS,
    OMEGA_RULE,
    SWEEP_CONTINUATIONS,
    SettingsError,
    check_continuation,
    settings_from_named,
    usable_omega,
)
from geardyn.core.settings import RunSettings as Settings
from geardyn.errors import ParameterError, StudyError
from geardyn.files import atomic_replace
from geardyn.gears.crowning import LeadCrowning
from geardyn.gears.faults import FAULT_KINDS
from geardyn.gears.geometry import GearMesh, SpurGear
from geardyn.gears.helical import HelicalGear, HelicalMesh, _helical_faults
from geardyn.gears.potential_energy import (
    DEFAULT_NODES,
    STEEL_POISSON,
    STEEL_YOUNG,
    prepare_pair,
)
from geardyn.gears.tip_relief import TipRelief, relief_gap
from geardyn.io._tables import build_from_fields as _build_from_fields
from geardyn.io._tables import study_error as _study_error
from geardyn.io.dataset_table import DatasetTable
from geardyn.io.envelope_table import EnvelopeTable
from geardyn.io.params_table import PerMesh as PerMesh  # the types of a quantity's forms
from geardyn.io.params_table import PerPlanet as PerPlanet
from geardyn.io.params_table import Quantity, params_table
from geardyn.io.runup_table import RunupTable
from geardyn.io.study_models import STUDY_MODELS, StudyModel, study_model
from geardyn.io.train_table import TrainTable
from geardyn.models.derived import Interpretation
from geardyn.models.gear_pair_coefficients import GEAR_PAIR
from geardyn.models.params import PAPER_NAMES, Angle, Length, PlanetaryParams, Real, Whole
from geardyn.models.planetary_coefficients import INPUTS as PLANETARY_INPUTS
from geardyn.models.spur_pair_coefficients import INPUTS as SPUR_PAIR_INPUTS
from geardyn.trains.inputs import INPUTS as TRAIN_INPUTS
from geardyn.units import to_si

__all__ = [
    "CrowningTable",
    "FaultTable",
    "GearPairParams",
    "GearTable",
    "GearsTable",
    "GeometryTable",
    "MemberTable",
    "PairGearTable",
    "PaperBase",
    "PlanetaryGearSetParams",
    "ReliefTable",
    "RunSettings",
    "RunTable",
    "SpurPairParams",
    "StiffnessTable",
    "Study",
    "StudyInfo",
    "SweepSettings",
    "builtin_study",
    "builtin_study_names",
    "load_params",
    "load_study",
    "paper_study",
    "save_params",
    "save_study",
]

_CONFIG = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

_HEADER = (
    "# geardyn {what} (TOML). Plain numbers are SI: m, kg, kg m^2, N/m, N m; angles in rad.\n"
    "# Unit strings such as \"50 um\" or \"20 deg\" are accepted on input.\n\n"
)

#: The kinds of study model (:data:`~geardyn.io.study_models.STUDY_MODELS`), by name.
Model = Literal[tuple(sorted(STUDY_MODELS))]  # type: ignore[valid-type]
#: The coordinate figures show by default, per study model that has one.
DEFAULT_PLOT_STATE: dict[str, str] = {k: m.plot_state for k, m in STUDY_MODELS.items()
                                      if m.plot_state}


# --------------------------------------------------------------------------- study schema
class StudyInfo(BaseModel):
    """The ``[study]`` table: what the study is and how to read the model."""

    model_config = _CONFIG

    name: str = Field("unnamed", min_length=1, description="short name")
    description: str = Field("", description="one-line description")
    model: Model = Field("catt", description="catt (the paper's device), gear_pair, "
                         "planetary (Lin & Parker gear set) or spur_pair (the SI pair of "
                         "[gears] on its potential-energy stiffness)")
    interpretation: Interpretation = Field(
        "consistent", description="how to read the paper's ambiguous formulas (catt only)"
    )
    plot_state: str | None = Field(
        None, description="coordinate shown in figures; default X_sq (catt) or x (gear_pair)"
    )


def _usable_omega(value: float) -> float:
    if not usable_omega(value):
        raise ValueError(OMEGA_RULE)
    return value


#: A forcing frequency Omega (``[run].omega``): the rule every ``--omega`` reads too
#: (:func:`geardyn.core.settings.usable_omega`).
ForcingFrequency = Annotated[Real, AfterValidator(_usable_omega)]

def _sweep_continuation(value: Any) -> Any:
    try:
        return check_continuation(value)
    except ParameterError as err:
        raise ValueError(err.reason) from None


#: ``[sweep].continuation``: where each point of a sweep starts (:class:`SweepSettings`), one
#: of :data:`~geardyn.core.settings.SWEEP_CONTINUATIONS`, refused by the rule every entry point
#: reads (:func:`~geardyn.core.settings.check_continuation`).
Continuation = Annotated[Literal[SWEEP_CONTINUATIONS], BeforeValidator(_sweep_continuation)]
CONTINUATIONS: tuple[str, ...] = SWEEP_CONTINUATIONS

#: The ``[run]`` table's name of a :class:`geardyn.RunSettings` field where it differs.
RUN_TABLE_NAMES: dict[str, str] = {"samples": "periods"}
#: What the ``[run]`` table adds to a :class:`geardyn.RunSettings` field: its default where the
#: table has its own (else None: RunSettings' default applies), bounds checked with pydantic's
#: messages before RunSettings' own check, and its description (else the field's ``help``).
RUN_TABLE_EXTRAS: dict[str, dict[str, Any]] = {
    "transient": {"default": 4000.0, "ge": 0, "description": "discarded time, dimensionless tau"},
    "samples": {"default": 64, "ge": 1, "description": "forcing periods recorded"},
    "steps_per_period": {"ge": 4, "description": "RK4 steps per period"},
    "converge": {"gt": 0, "lt": 1, "description": "transient by convergence: relative "
                 "tolerance to which the Poincare point must settle (the transient is then a "
                 "minimum)"},
    "transient_max": {"gt": 0, "description": "longest transient by convergence, tau (default "
                      "10 x transient)"},
    "continued_transient": {"ge": 0, "description": "transient of a continued sweep point, tau "
                            "(default transient)"},
    "max_period": {"ge": 1, "le": 256, "description": "longest period (in forcing periods) "
                   f"classified (default {DEFAULT_MAX_PERIOD})"},
    "period_tol": {"gt": 0, "lt": 1, "description": "relative tolerance of the period "
                   f"classifier (default {DEFAULT_TOL:g})"},
}
#: Models whose time is in seconds: the default transient of their runs in forcing periods of
#: the lowest Omega of the run (not ``[run].transient``'s 4000, a dimensionless time).
DEFAULT_TRANSIENT_PERIODS: dict[str, float] = {
    k: m.transient_periods for k, m in STUDY_MODELS.items() if m.transient_periods is not None}
#: The ``[run]`` table's keys that are no RunSettings field: the run's Omega and the transient
#: in forcing periods (instead of ``transient``).
RUN_TABLE_OWN = ("omega", "transient_periods")
#: The RunSettings field of each ``[run]`` key that is one.
RUN_FIELDS: dict[str, str] = {RUN_TABLE_NAMES.get(f, f): f for f in FIELDS}


def _table_type(hint: Any) -> Any:
    """The pydantic type of a RunSettings field of type ``hint`` in the table: bool strict,
    numbers finite and not booleans (:data:`Real`, :data:`Whole`)."""
    import typing

    base = next(t for t in (typing.get_args(hint) or (hint,)) if t is not type(None))
    return {bool: StrictBool, int: Whole, float: Real}[base]


def _run_table_fields() -> dict[str, Any]:
    """The ``[run]`` table's fields: ``omega``, then one per :class:`geardyn.RunSettings` field
    (named by :data:`RUN_TABLE_NAMES`; ``transient_periods`` after ``transient``), generated
    from RunSettings' declaration so that every setting is settable from a study."""
    import dataclasses
    import typing

    hints = typing.get_type_hints(Settings)
    out: dict[str, Any] = {"omega": (ForcingFrequency | None, Field(
        None, description="mesh frequency Omega = omega/omega_n"))}
    for f in dataclasses.fields(Settings):
        extra = dict(RUN_TABLE_EXTRAS.get(f.name, {}))
        default = extra.pop("default", None)
        extra.setdefault("description", f.metadata.get("help", f"RunSettings.{f.name}"))
        kind = _table_type(hints[f.name])
        out[RUN_TABLE_NAMES.get(f.name, f.name)] = (
            kind if default is not None else kind | None, Field(default, **extra))
        if f.name == "transient":
            out["transient_periods"] = (Real | None, Field(
                None, gt=0, description="discarded time in forcing periods of the lowest Omega "
                "of the run (instead of transient)"))
    return out


class _RunTableRules(BaseModel):
    """The ``[run]`` table: defaults of the run settings of every command that runs lanes
    (``geardyn simulate``, ``bifurcation``, ``frc``, ``map``, ``basins``, ``continue``,
    ``explore``, ``reproduce``; command-line options win). One key per
    :class:`geardyn.RunSettings` field (``periods`` for ``samples``), checked by RunSettings'
    own rules when the study is read (errors name ``run.<key>``), plus ``omega`` (also the
    fixed Omega of a sweep of another parameter) and ``transient_periods``.
    :meth:`Study.run_settings` turns it into the :class:`geardyn.RunSettings` of a run.

    The transient is given either as a time (``transient``, dimensionless tau) or in forcing
    periods (``transient_periods``: at least that many periods at every point of the run, i.e.
    ``transient_periods`` x 2 pi / the lowest Omega of the run), not both. ``converge`` turns the
    transient into a minimum: the run goes on, up to ``transient_max``, until the Poincare point
    has settled to that relative tolerance."""

    model_config = _CONFIG

    @field_validator("*", mode="after")
    @classmethod
    def _settings_rule(cls, value: Any, info: ValidationInfo) -> Any:
        """RunSettings' own check of the field (the value it normalises to)."""
        field = RUN_FIELDS.get(info.field_name or "")
        if field is None or value is None:
            return value
        try:
            return getattr(Settings(**{field: value}), field)
        except SettingsError as exc:
            raise ValueError(str(exc).removeprefix(f"{field} ")) from None

    @model_validator(mode="after")
    def _consistent(self) -> Any:
        if self.transient_periods is not None and "transient" in self.model_fields_set:
            raise ValueError("give the transient either as transient (time) or as "
                             "transient_periods (forcing periods), not both")
        if self.transient_max is not None:
            if self.converge is None:
                raise ValueError("transient_max is the limit of a transient by convergence: "
                                 "set converge too")
            if self.transient_periods is None and self.transient_max < self.transient:
                raise ValueError(f"transient_max ({self.transient_max:g}) must be >= "
                                 f"transient ({self.transient:g})")
        return self

    def transient_time(self, omega: float | None = None) -> float:
        """The discarded time [tau]: ``transient``, or ``transient_periods`` x 2 pi / ``omega``,
        ``omega`` the lowest forcing frequency Omega of the run (a StudyError without it)."""
        if self.transient_periods is None:
            return self.transient
        if omega is None or not usable_omega(omega):
            raise StudyError(f"run.transient_periods: needs the run's forcing frequency Omega "
                             f"(got {omega!r})")
        return self.transient_periods * 2.0 * math.pi / omega

    def written(self, key: str) -> bool:
        """Whether the study file gives ``key`` (a table default does not count)."""
        return key in self.model_fields_set and getattr(self, key) is not None


RunTable = create_model("RunTable", __base__=_RunTableRules, __module__=__name__,
                        __doc__=_RunTableRules.__doc__, **_run_table_fields())

#: The old name of :class:`RunTable` (not :class:`geardyn.RunSettings`, which it builds).
RunSettings = RunTable


class SweepSettings(BaseModel):
    """The ``[sweep]`` table: defaults of ``geardyn bifurcation`` (command-line options win).

    ``continuation``: ``"none"`` (every point starts from the model's initial state), ``"up"`` or
    ``"down"`` (each point starts from the previous point's final state, in ascending or
    descending order). The old boolean form is read as ``true`` -> ``"up"``, ``false`` ->
    ``"none"``. ``samples`` (Poincare points per value) defaults to ``[run].periods``.
    """

    model_config = _CONFIG

    param: str = Field("Omega", min_length=1, description="swept parameter: Omega or a swept "
                       "input of the model (its declared physical inputs, e.g. a CATT study's "
                       "paper names, or its input coefficients)")
    start: Real
    stop: Real
    num: Whole = Field(ge=2, description="number of parameter values")
    continuation: Continuation = Field(
        "none", description="none, up or down: start each point from the previous one's state"
    )
    samples: Whole | None = Field(None, ge=2, description="forcing periods recorded per value")
    lyapunov: bool = Field(False, description="also compute the largest Lyapunov exponent")

    @field_validator("continuation", mode="before")
    @classmethod
    def _boolean_continuation(cls, value: Any) -> Any:
        if isinstance(value, bool):
            return "up" if value else "none"
        return value

    @model_validator(mode="after")
    def _distinct_ends(self) -> SweepSettings:
        if self.start == self.stop:
            raise ValueError(f"start and stop must differ (got {self.start!r} twice)")
        return self


class PaperBase(BaseModel):
    """``[params]`` as ``base = "paper"`` plus ``[params.changes]`` by the paper's names."""

    model_config = _CONFIG

    base: Literal["paper"]
    changes: dict[str, Any] = Field(default_factory=dict)

    _device: PlanetaryParams | None = PrivateAttr(None)

    def resolve(self) -> PlanetaryParams:
        """The paper's device with the changes (built from the changes each call)."""
        return PlanetaryParams.paper(**self.changes)

    @property
    def device(self) -> PlanetaryParams:
        """The paper's device with the changes, checked once (when the study file is read, or
        at the first call), errors naming ``params.changes.<name>``."""
        if self._device is None:
            self._device = _resolve_paper(self.model_dump())[1]
        return self._device


def study_table(name: str, block: CoefficientBlock, doc: str) -> type[BaseModel]:
    """A ``[params]`` table generated from a model's declared coefficients: one field per
    input of ``block`` (its default, range and meaning; an angle for a unit of rad, else a
    number; derived entries follow their inputs), unknown keys refused naming the field."""
    fields: dict[str, Any] = {}
    for c in block.entries:
        if c.kind != "input":
            continue
        kind: Any = Angle if c.unit == "rad" else Real
        limits = {k: v for k, v in (("ge", c.minimum), ("le", c.maximum),
                                    ("gt", c.exclusive_minimum), ("lt", c.exclusive_maximum))
                  if v is not None}
        default = ... if c.default is None else c.default
        fields[c.name] = (kind, Field(default, description=c.meaning, **limits))
    return create_model(name, __config__=_CONFIG, __doc__=doc, __module__=__name__, **fields)


#: ``[params]`` of a ``gear_pair`` study: the arguments of :class:`~geardyn.GearPair`, from its
#: declared coefficients (:data:`~geardyn.models.gear_pair_coefficients.GEAR_PAIR`).
GearPairParams = study_table(
    "GearPairParams", GEAR_PAIR,
    "``[params]`` of a ``gear_pair`` study: the arguments of :class:`~geardyn.GearPair`.")


def spur_pair_table(inputs: tuple[PhysicalInput, ...] = SPUR_PAIR_INPUTS) -> type[BaseModel]:
    """``[params]`` of a ``spur_pair`` study, generated from the declared physical inputs of
    :class:`~geardyn.SpurPair` (:data:`~geardyn.models.spur_pair_coefficients.INPUTS`): one
    field per input (SI numbers or unit strings; speed a number in ``speed_unit`` or the unit
    string of an angular frequency, kept as given), unknown keys refused naming the field."""
    return params_table("SpurPairParams", inputs, spur_pair_table.__doc__ or "", values="si")


#: ``[params]`` of a ``spur_pair`` study: the dynamics of :meth:`geardyn.SpurPair.from_geometry`
#: of the study's ``[gears]``, ``[[faults]]`` and ``[stiffness]``.
SpurPairParams = spur_pair_table()


class MemberTable(BaseModel):
    """A ``[params.<member>]`` table of a planetary study: :class:`~geardyn.Member` fields."""

    model_config = _CONFIG

    mass: Quantity
    inertia_over_r2: Quantity
    bearing_stiffness: Quantity
    torsional_stiffness: Quantity = 0.0
    radius: Quantity | None = None


class FaultTable(BaseModel):
    """One ``[[faults]]`` table: ``kind`` (a key of :data:`geardyn.gears.FAULT_KINDS`:
    ``crack``, ``spall``, ``wear``, ``broken_tooth``) and that fault's fields (its class's
    parameters, e.g. ``gear``, ``tooth``, ``depth``, ``angle`` of a
    :class:`~geardyn.gears.RootCrack`). Checked by :meth:`build`, once the gears are known."""

    model_config = ConfigDict(extra="allow", frozen=True, allow_inf_nan=False)

    kind: str

    def fields(self) -> dict[str, Any]:
        """The fault's own fields (the table without ``kind``)."""
        return dict(self.model_extra or {})

    def build(self, where: tuple) -> object:
        """The fault object; errors name ``where`` + the field (``faults[0].depth``)."""
        cls = FAULT_KINDS.get(self.kind)
        if cls is None:
            raise _study_error(where + ("kind",), self.kind, "unknown fault kind; known: "
                               + ", ".join(FAULT_KINDS))
        return _build_from_fields(cls, self.fields(), where, f"a {self.kind} fault", "kind, ")


class GearTable(BaseModel):
    """A ``[params.geometry.<sun|planet|ring>]`` table: one gear's teeth and profile shift
    (module, pressure angle, face width and tooth proportions default to the stage's)."""

    model_config = _CONFIG

    teeth: int
    profile_shift: float = 0.0
    face_width: Quantity | None = None


class GeometryTable(BaseModel):
    """``[params.geometry]`` of a planetary study: the stage the gear set is built from
    (:meth:`~geardyn.PlanetaryGearSet.from_geometry`); ``n_planets`` and ``planet_angles`` of
    ``[params]`` place the planets."""

    model_config = _CONFIG

    module: Quantity
    pressure_angle: Quantity = "20 deg"
    face_width: Quantity
    addendum: float = 1.0
    dedendum: float = 1.25
    centre_distance: Quantity | None = None
    transition: float = 0.0
    stiffness: str = Field("iso", description="mesh stiffness: 'iso' (ISO 6336-1 waves) or "
                           "'potential_energy' (from the teeth, drive and coast flanks)")
    stiffness_options: dict[str, Any] = Field(
        default_factory=dict, description="the potential-energy inputs "
        "(PlanetaryGearSet.from_geometry's stiffness_options: bores, rim, material, angles)")
    coast: Literal["mirror", "symmetric"] = "mirror"  # the coast flank (from_geometry's coast)
    faults: list[FaultTable] | None = Field(
        None, description="[[params.geometry.faults]]: tooth faults on one gear of the set "
        "(kind and the fault's fields; gear 'sun', 'ring' or 'planet<n>'), with stiffness = "
        "'potential_energy': the forcing period is then that gear's revolution")
    sun: GearTable
    planet: GearTable
    ring: GearTable


#: ``[params]`` of a ``planetary`` study: the arguments of :class:`~geardyn.PlanetaryGearSet`,
#: generated from its declared inputs (:data:`geardyn.models.planetary_coefficients.INPUTS`).
PlanetaryGearSetParams = params_table(
    "PlanetaryGearSetParams", PLANETARY_INPUTS,
    """``[params]`` of a ``planetary`` study: the arguments of :class:`~geardyn.PlanetaryGearSet`
    (types checked here; values when the model is built), generated from its declared inputs
    (:data:`geardyn.models.planetary_coefficients.INPUTS`); ``[params.sun]``, ``[params.ring]``,
    ``[params.carrier]``, ``[params.planet]`` are :class:`MemberTable` s, ``[params.geometry]``
    a :class:`GeometryTable`.""",
    values="given", tables={"member": MemberTable, "planetary_geometry": GeometryTable})

#: ``[params]`` of a ``train`` study: the arguments of :class:`~geardyn.trains.TrainModel` but
#: the train, generated from its declared inputs (:data:`geardyn.trains.inputs.INPUTS`).
TrainModelParams = params_table(
    "TrainModelParams", TRAIN_INPUTS,
    """``[params]`` of a ``train`` study: the arguments of :class:`~geardyn.trains.TrainModel`
    but the train (the study's ``[train]`` table), generated from its declared inputs
    (:data:`geardyn.trains.inputs.INPUTS`); types checked here, values when the model is built
    (errors name ``params.<field>``).""",
    values="given")


#: The ``[params]`` table classes of the study models, by class name (``StudyModel.params``).
_PARAMS_CLASSES: dict[str, type[BaseModel]] = {c.__name__: c for c in (
    PlanetaryParams, GearPairParams, SpurPairParams, PlanetaryGearSetParams, TrainModelParams)}


def params_class(kind: StudyModel | str) -> type[BaseModel]:
    """The class of the ``[params]`` table of a study model ``kind`` (a
    :class:`~geardyn.io.study_models.StudyModel` or its name)."""
    declared = study_model(kind) if isinstance(kind, str) else kind
    return _PARAMS_CLASSES[declared.params]


def params_kind(params: BaseModel) -> StudyModel:
    """The study model whose ``[params]`` table ``params`` is (the paper's device for any
    other, a ``base = "paper"`` table)."""
    return next((m for m in STUDY_MODELS.values()
                 if isinstance(params, _PARAMS_CLASSES[m.params])), STUDY_MODELS["catt"])


# --------------------------------------------------------------------------- gears and faults
#: Young's modulus: an SI number [Pa] or a unit string ("206.8 GPa").
Pressure = Annotated[float, BeforeValidator(lambda v: to_si(v, "pressure")), Field(gt=0)]
#: A force: an SI number [N] or a unit string ("2 kN"); a torque [N m] ("50 N m").
Force = Annotated[float, BeforeValidator(lambda v: to_si(v, "force"))]
Torque = Annotated[float, BeforeValidator(lambda v: to_si(v, "torque"))]


class PairGearTable(BaseModel):
    """``[gears.pinion]`` or ``[gears.wheel]``: one gear's teeth and profile shift, and where it
    differs from the pair's ``[gears]`` values, its face width, bore radius, addendum and
    dedendum factors."""

    model_config = _CONFIG

    teeth: Whole
    profile_shift: Real = 0.0
    face_width: Length | None = None
    bore_radius: Length | None = None
    addendum: Real | None = None
    dedendum: Real | None = None


class GearsTable(BaseModel):
    """``[gears]``: a spur pair (:class:`~geardyn.gears.GearMesh` of two
    :class:`~geardyn.gears.SpurGear`) for the potential-energy mesh stiffness: the common
    module, pressure angle and tooth proportions (addendum and dedendum factors of the basic
    rack), face width and bore radius (each also per gear), the centre distance (default: that
    of zero backlash), the material (E, nu), and the ``pinion`` and ``wheel`` sub-tables
    (:class:`PairGearTable`). SI numbers or unit strings. Values the geometry refuses (undercut,
    interference, a bore outside the root circle, ...) are errors naming ``gears.<field>``.

    ``helix_angle``: a helical pair (:class:`~geardyn.gears.HelicalMesh` of two
    :class:`~geardyn.gears.HelicalGear`; module, pressure angle, profile shifts and factors in
    the normal section). ``internal = true``: the wheel is a ring (``GearMesh(...,
    internal=True)``), its ``bore_radius`` (in ``[gears.wheel]``) the ring's outer (rim)
    radius and ``ring_foundation`` the treatment of its body
    (:data:`~geardyn.gears.potential_energy.RING_FOUNDATIONS`; default ``"rigid"``)."""

    model_config = _CONFIG

    module: Length
    pressure_angle: Angle = Field(math.radians(20.0), description="rad or e.g. \"20 deg\"")
    face_width: Length | None = None
    bore_radius: Length | None = None
    addendum: Real = 1.0
    dedendum: Real = 1.25
    centre_distance: Length | None = None
    young: Pressure = STEEL_YOUNG
    poisson: Real = STEEL_POISSON
    helix_angle: Angle | None = Field(None, description="helical pair: rad or e.g. \"20 deg\"")
    internal: StrictBool = Field(False, description="the wheel is a ring (internal pair)")
    ring_foundation: str | None = Field(None, description="the ring body (internal pairs)")
    pinion: PairGearTable
    wheel: PairGearTable

    @property
    def helical(self) -> bool:
        """A helical pair (``helix_angle`` given)."""
        return self.helix_angle is not None

    def check_kind(self) -> None:
        """The pair's kind consistent: no internal helical pair, ``ring_foundation`` only on a
        ring (a ParameterError naming the field)."""
        if self.internal and self.helical:
            raise ParameterError("internal", True, "an internal helical pair is not covered"
                                 " (give helix_angle or internal, not both)")
        if self.ring_foundation is not None and not self.internal:
            raise ParameterError("ring_foundation", self.ring_foundation,
                                 "applies to a ring only (internal = true)")

    def value(self, role: str, name: str) -> tuple[Any, tuple[str, ...]]:
        """``name`` of gear ``role`` ("pinion" or "wheel") and where it is set: its own table,
        else ``[gears]``."""
        own = getattr(getattr(self, role), name, None)
        if own is not None:
            return own, ("gears", role, name)
        return getattr(self, name), ("gears", name)

    def gear(self, role: str) -> SpurGear:
        """The pinion or the wheel (a ParameterError names the gear's field)."""
        table = getattr(self, role)
        kw = {}
        for name in ("face_width", "addendum", "dedendum"):
            value = self.value(role, name)[0]
            if value is None:
                raise ParameterError(f"{role}.{name}", None, f"required (in [gears] or in "
                                     f"[gears.{role}])")
            kw[name] = value
        if self.helical:
            return HelicalGear(table.teeth, self.module, self.pressure_angle,
                               self.helix_angle, kw["face_width"],
                               profile_shift=table.profile_shift, addendum=kw["addendum"],
                               dedendum=kw["dedendum"], name=role)
        return SpurGear(table.teeth, self.module, self.pressure_angle, kw["face_width"],
                        profile_shift=table.profile_shift, addendum=kw["addendum"],
                        dedendum=kw["dedendum"], internal=self.internal and role == "wheel",
                        name=role)

    def mesh(self) -> GearMesh | HelicalMesh:
        """The pair, pinion driving."""
        self.check_kind()
        if self.helical:
            return HelicalMesh(self.gear("pinion"), self.gear("wheel"),
                               centre_distance=self.centre_distance)
        return GearMesh(self.gear("pinion"), self.gear("wheel"),
                        centre_distance=self.centre_distance, internal=self.internal)

    def bores(self) -> tuple[float, float]:
        """The bore radii [m] of pinion and wheel (a ring: its outer radius, from
        ``[gears.wheel]`` only)."""
        if self.internal and self.wheel.bore_radius is None:
            raise ParameterError("wheel.bore_radius", None, "required in [gears.wheel] for a"
                                 " ring: its outer (rim) radius")
        out = []
        for role in ("pinion", "wheel"):
            value = self.value(role, "bore_radius")[0]
            if value is None:
                raise ParameterError(f"{role}.bore_radius", None, f"required (in [gears] or in "
                                     f"[gears.{role}])")
            out.append(value)
        return out[0], out[1]

    def location(self, field: str) -> tuple[str, ...]:
        """The study location of a :class:`ParameterError`'s ``field`` raised by the gears or
        the potential-energy method (``pinion.teeth`` -> gears.pinion.teeth; a shared value
        set in ``[gears]`` -> gears.<name>)."""
        role, _, name = field.partition(".")
        if role in ("pinion", "wheel") and name:
            if name in PairGearTable.model_fields:
                if name in ("teeth", "profile_shift") or (self.internal and role == "wheel"
                                                           and name == "bore_radius"):
                    return ("gears", role, name)
                return self.value(role, name)[1]
            if name in GearsTable.model_fields:
                return ("gears", name)
            return ("gears", role, name)
        return ("gears", *field.split("."))




class _ClassTable(BaseModel):
    """A table whose keys are the keyword arguments of :attr:`OF` (its dataclass fields,
    declared there once), checked by :meth:`build`."""

    model_config = ConfigDict(extra="allow", frozen=True, allow_inf_nan=False)

    OF: ClassVar[type]
    WHAT: ClassVar[str]

    def build(self, where: tuple) -> Any:
        """The object; errors name ``where`` + the field (``relief[0].length``)."""
        return _build_from_fields(self.OF, dict(self.model_extra or {}), where, self.WHAT)


class ReliefTable(_ClassTable):
    """One ``[[relief]]`` table: a :class:`~geardyn.gears.TipRelief` (``amount``, ``length``,
    ``shape`` "linear" or "parabolic", ``gear`` "pinion" or "wheel"; lengths in m or unit
    strings), for the loaded contact under ``[stiffness]``'s ``torque`` or ``force``."""

    OF: ClassVar[type] = TipRelief
    WHAT: ClassVar[str] = "a tip relief"


class CrowningTable(_ClassTable):
    """A ``[crowning]`` table (or each of ``[[crowning]]``): a
    :class:`~geardyn.gears.LeadCrowning` (``amount`` at each face end, ``gear``), on a helical
    pair under ``[stiffness]``'s ``torque`` or ``force``."""

    OF: ClassVar[type] = LeadCrowning
    WHAT: ClassVar[str] = "a lead crowning"


def _one_or_many(value: Any) -> Any:
    """A single table as a list of one (``[crowning]`` and ``[[crowning]]`` alike)."""
    return [value] if isinstance(value, dict) else value


class StiffnessTable(BaseModel):
    """``[stiffness]``: the settings of ``geardyn stiffness`` (the potential-energy mesh
    stiffness of ``[gears]``): ``angles`` per mesh cycle, ``cycles`` (mesh cycles, or
    ``"hunting"``: lcm(z1, z2), every pinion tooth against every wheel tooth), ``nodes``
    (Gauss-Legendre nodes of the tooth integrals) and ``root_segment`` (the straight flank
    between the root and base circles in the cantilever)."""

    model_config = _CONFIG

    angles: Whole = Field(360, ge=1, description="pinion angles per mesh cycle")
    cycles: Whole | Literal["hunting"] | None = Field(
        None, description="mesh cycles from tooth 0's pitch-point passage, or \"hunting\" "
        "(default 1; a spur_pair model's: its forcing period)")
    nodes: Whole = Field(DEFAULT_NODES, ge=4, description="Gauss-Legendre nodes")
    root_segment: bool = Field(True, description="straight flank from the root to the base "
                               "circle in the cantilever")
    slices: Whole | None = Field(None, ge=1, description="thin slices across the face width "
                                 "(helical pairs; default 20)")
    torque: Torque | None = Field(None, gt=0, description="pinion torque [N m] of the loaded "
                                  "contact")
    force: Force | None = Field(None, gt=0, description="normal force [N] along the "
                                "(transverse) line of action of the loaded contact")

    @field_validator("cycles", mode="before")
    @classmethod
    def _cycles(cls, value: Any) -> Any:
        if value == "hunting" and isinstance(value, str):
            return value
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError("must be a whole number >= 1 or \"hunting\"")
        return value

    def mesh_cycles(self, mesh: GearMesh) -> int:
        """The number of mesh cycles: ``cycles`` (default 1), or lcm(z1, z2) for
        ``"hunting"``."""
        if self.cycles is None:
            return 1
        if self.cycles == "hunting":
            return math.lcm(mesh.pinion.teeth, mesh.wheel.teeth)
        return int(self.cycles)


def _check_fault(mesh: GearMesh, kw: dict[str, Any], fault: object, where: tuple) -> None:
    """:func:`~geardyn.gears.prepare_pair` of the pair with ``fault`` (None: the faults ``kw``
    holds); a refusal is an error at ``where`` and the fault's field it names."""
    try:
        prepare_pair(mesh, **kw, **({} if fault is None else _fault_keywords([fault])))
    except ParameterError as exc:
        name = exc.field.rpartition(".")[2]
        fields = () if fault is None else inspect.signature(type(fault)).parameters
        raise _study_error(where + ((name,) if name in fields else ()), exc.value,
                           exc.reason) from None


def _check_helical_faults(faults: list) -> None:
    """The faults a helical pair takes (a spall or Archard wear: an error at its table)."""
    for i, fault in enumerate(faults):
        try:
            _helical_faults((fault,))
        except ParameterError as exc:
            name = exc.field.rpartition(".")[2]
            raise _study_error(("faults", i, "kind" if name == "faults" else name),
                               exc.value if name != "faults" else type(fault).__name__,
                               exc.reason) from None


def _fault_keywords(faults: list) -> dict[str, Any]:
    """The keywords of :func:`~geardyn.gears.potential_energy_stiffness` that put ``faults``
    (built :data:`~geardyn.gears.FAULT_KINDS` objects, each on its own tooth) on the pair."""
    return {"faults": tuple(faults)} if faults else {}


def _relocated(exc: ValidationError, loc_of) -> ValidationError:
    """``exc`` with every error's location mapped by ``loc_of(loc) -> loc``."""
    details: list[InitErrorDetails] = []
    seen: set[tuple] = set()
    for err in exc.errors(include_url=False):
        loc = tuple(loc_of(tuple(err["loc"])))
        if (loc, err["msg"]) in seen:  # one change can set several fields alike
            continue
        seen.add((loc, err["msg"]))
        details.append(
            InitErrorDetails(
                type=PydanticCustomError(err["type"], "{msg}", {"msg": err["msg"]}),
                loc=loc,
                input=err.get("input"),
            )
        )
    return ValidationError.from_exception_data(exc.title, details)


def _resolve_paper(data: dict[str, Any]) -> tuple[PaperBase, PlanetaryParams]:
    try:
        spec = PaperBase.model_validate(data)
    except ValidationError as exc:
        raise _relocated(exc, lambda loc: ("params", *loc)) from None
    known = set(PAPER_NAMES) | set(PlanetaryParams.model_fields)
    unknown = [k for k in spec.changes if k not in known]
    if unknown:
        details = [
            InitErrorDetails(
                type=PydanticCustomError(
                    "unknown_name",
                    "unknown parameter name; known: {known}",
                    {"known": ", ".join(sorted(PAPER_NAMES))},
                ),
                loc=("params", "changes", k),
                input=spec.changes[k],
            )
            for k in unknown
        ]
        raise ValidationError.from_exception_data("Study", details)
    try:
        params = spec.resolve()
    except ValidationError as exc:

        def loc_of(loc: tuple) -> tuple:
            for name in spec.changes:
                for path in PAPER_NAMES.get(name, ((name,),)):
                    if loc[: len(path)] == path:
                        return ("params", "changes", name, *loc[len(path):])
            return ("params", *loc)

        raise _relocated(exc, loc_of) from None
    spec._device = params
    return spec, params


def is_paper_base(params: Mapping[str, Any] | BaseModel) -> bool:
    """True where a paper device's ``[params]`` (a table or its validated form) is the
    ``base = "paper"`` form (:class:`PaperBase`: changes by the paper's names), False for the
    device in full (:class:`~geardyn.models.params.PlanetaryParams`)."""
    return isinstance(params, PaperBase) or (isinstance(params, Mapping) and "base" in params)


def device_params(params: BaseModel) -> PlanetaryParams:
    """The paper device of a ``catt`` study's ``[params]``: the table itself (the device in
    full) or the paper's device with the table's changes (``base = "paper"``, checked once)."""
    return params.device if isinstance(params, PaperBase) else params  # type: ignore[return-value]


class Study(BaseModel):
    """A study: device parameters plus run and sweep settings (one TOML file).

    ``params`` is a :class:`PlanetaryParams` (full form), a :class:`PaperBase` (paper values plus
    changes) or, for ``model = "gear_pair"``, a :class:`GearPairParams`, for
    ``model = "planetary"`` a :class:`PlanetaryGearSetParams`.

    ``gears`` (:class:`GearsTable`), ``faults`` (:class:`FaultTable` each) and ``stiffness``
    (:class:`StiffnessTable`) describe a spur pair for the potential-energy mesh stiffness
    (``geardyn stiffness``); a study may hold them instead of ``params``. They are checked when
    the study is read: the gears, the faults on them and the settings are built once
    (:meth:`stiffness_inputs`), and what they refuse is an error naming the field. ``relief``
    (:class:`ReliefTable` each) and ``crowning`` (:class:`CrowningTable` each) with a load
    (``[stiffness]`` ``torque`` or ``force``) add the loaded contact
    (:meth:`contact_inputs`).

    ``train`` (:class:`~geardyn.io.train_table.TrainTable`) describes a gear train from its
    elements (``geardyn modes``), with or instead of ``params``; it is built when the study is
    read (:attr:`gear_train`), and what it refuses is an error naming ``train.<group>.<name>.
    <field>``.
    """

    model_config = _CONFIG

    study: StudyInfo = Field(default_factory=StudyInfo)
    params: (PlanetaryParams | PaperBase | GearPairParams | PlanetaryGearSetParams
             | SpurPairParams | TrainModelParams | None) = None
    run: RunTable = Field(default_factory=RunTable)
    sweep: SweepSettings | None = None
    gears: GearsTable | None = None
    faults: list[FaultTable] | None = None
    stiffness: StiffnessTable | None = None
    relief: Annotated[list[ReliefTable], BeforeValidator(_one_or_many)] | None = None
    crowning: Annotated[list[CrowningTable], BeforeValidator(_one_or_many)] | None = None
    train: TrainTable | None = None
    envelope: EnvelopeTable | None = None
    runup: RunupTable | None = None
    dataset: DatasetTable | None = None

    _planetary: PlanetaryParams | None = PrivateAttr(None)
    _train: Any = PrivateAttr(None)

    def run_settings(self, sweep: bool = False,
                     omega: float | Callable[[], float | None] | None = None, *,
                     given: Mapping[str, tuple[str, Any]] | None = None,
                     defaults: Mapping[str, Any] | None = None, **options: Any) -> Settings:
        """The :class:`geardyn.RunSettings` of a run of this study, every field read the same
        way for every command (:meth:`run_sources`): ``options`` (RunSettings fields; None
        keeps the study's value) or ``given`` (field -> (option name, value or None)) win, then
        the study's ``[run]`` table, then ``defaults``. An invalid value is a
        :class:`~geardyn.ParameterError` naming the option or study key it came from."""
        named = {k: (k, v) for k, v in options.items()}
        named.update(given or {})
        return settings_from_named(Settings, self.run_sources(named, sweep=sweep, omega=omega,
                                                              defaults=defaults))

    def run_sources(self, given: Mapping[str, tuple[str, Any]] | None = None, *,
                    sweep: bool = False,
                    omega: float | Callable[[], float | None] | None = None,
                    defaults: Mapping[str, Any] | None = None) -> dict[str, tuple[str, Any]]:
        """Every :class:`geardyn.RunSettings` field of a run of this study with where its value
        comes from (field -> (source, value)), first found of:

        1. ``given`` (field -> (option name, value); a None value is not given);
        2. what the study file writes: ``[sweep].samples`` for ``samples`` (with ``sweep``),
           the ``[run]`` key of the field (:data:`RUN_TABLE_NAMES`), ``transient_periods`` x
           2 pi / ``omega`` for ``transient`` (``omega``: the lowest forcing frequency of the
           run, or a function giving it, called only then);
        3. ``defaults``: the command's own (``basins``' samples and convergence);
        4. the ``[run]`` table's defaults (``transient`` 4000, ``periods`` 64); for a model
           in seconds (:data:`DEFAULT_TRANSIENT_PERIODS`) the transient is that many forcing
           periods of the lowest Omega of the run instead.

        A field found nowhere is left out (RunSettings' default applies)."""
        named = {k: v for k, v in (given or {}).items() if v[1] is not None}
        defaults = dict(defaults or {})
        unknown = sorted((set(named) | set(defaults)) - set(FIELDS))
        if unknown:
            raise TypeError(f"RunSettings has no field {unknown[0]!r}")
        out: dict[str, tuple[str, Any]] = {}
        for field in FIELDS:
            key = RUN_TABLE_NAMES.get(field, field)
            found = named.get(field) or self._written_run_value(field, sweep, omega)
            if found is None and field in defaults:
                found = (f"default {field}", defaults[field])
            if found is None and field == "transient" and (
                    self.study.model in DEFAULT_TRANSIENT_PERIODS):
                om = omega() if callable(omega) else omega
                periods = DEFAULT_TRANSIENT_PERIODS[self.study.model]
                found = (f"default transient_periods {periods:g} ({self.study.model})",
                         RunTable(transient_periods=periods).transient_time(om))
            if found is None and getattr(self.run, key) is not None:
                found = (f"run.{key}", getattr(self.run, key))
            if found is not None:
                out[field] = found
        return out

    def _written_run_value(self, field: str, sweep: bool,
                           omega: float | Callable[[], float | None] | None
                           ) -> tuple[str, Any] | None:
        """The value the study file gives ``field`` and its key, or None (see
        :meth:`run_sources`)."""
        table = self.run
        if field == "transient" and table.transient_periods is not None:
            om = omega() if callable(omega) else omega
            return "run.transient_periods", table.transient_time(om)
        if field == "samples" and sweep and self.sweep is not None and (
                self.sweep.samples is not None):
            return "sweep.samples", self.sweep.samples
        key = RUN_TABLE_NAMES.get(field, field)
        return (f"run.{key}", getattr(table, key)) if table.written(key) else None

    @model_validator(mode="before")
    @classmethod
    def _dispatch_params(cls, data: Any) -> Any:
        """Validate ``params`` with the class the model kind calls for, so that errors name
        ``params.<field path>`` rather than every member of the union."""
        if not isinstance(data, dict) or "params" not in data:
            return data
        raw = data["params"]
        info = data.get("study", {})
        kind = info.get("model", "catt") if isinstance(info, dict) else getattr(info, "model", "")
        if isinstance(raw, BaseModel):
            return data
        if not isinstance(raw, dict):  # one error naming params, not one per union member
            raise ValidationError.from_exception_data("Study", [InitErrorDetails(
                type=PydanticCustomError("dict_type", "must be a table of parameters"),
                loc=("params",), input=raw)])
        out = dict(data)
        # an unknown kind is read as the paper's device (study.model's own check names it)
        declared = STUDY_MODELS.get(kind) if isinstance(kind, str) else None
        declared = declared or STUDY_MODELS["catt"]
        if declared.paper_device and is_paper_base(raw):
            out["params"] = _resolve_paper(raw)[0]
            return out
        target = params_class(declared)
        try:
            out["params"] = target.model_validate(raw)
        except ValidationError as exc:
            raise _relocated(exc, lambda loc: ("params", *loc)) from None
        return out

    @model_validator(mode="after")
    def _check_consistency(self) -> Study:
        self._check_gears()
        if self.train is not None:
            self._train = self.train.build()
        if self.params is None:
            return self
        holds = params_kind(self.params)
        if holds.name != self.study.model:
            raise ValueError(
                f"study.model is {self.study.model!r} but [params] holds {holds.label} parameters"
            )
        if holds.paper_device:
            self._planetary = device_params(self.params)
        return self

    def _check_gears(self) -> None:
        """``[params]`` or ``[gears]`` present; ``[faults]`` and ``[stiffness]`` only with
        ``[gears]``; the gears, faults and settings buildable (errors name the field); a
        ``spur_pair`` study has both ``[gears]`` (its pair) and ``[params]`` (its dynamics), a
        ``train`` study ``[train]`` (the tables its kind requires, ``StudyModel.requires``)."""
        kind = study_model(self.study.model)
        for name, what in kind.requires:
            if getattr(self, name) is None:
                raise _study_error((name,), None, f"required by a {kind.name} study ({what})",
                                   "missing")
        if self.gears is None:
            for name in ("faults", "stiffness", "relief", "crowning"):
                if getattr(self, name) is not None:
                    where = (" (a planetary set's faults: [[params.geometry.faults]])"
                             if name == "faults" else "")
                    raise _study_error((name,), None, "needs a [gears] table (the pair whose"
                                       f" mesh stiffness it is for){where}")
            if self.params is None and self.train is None:
                raise _study_error(("params",), None, "required (or a [gears] or [train]"
                                   " table)", "missing")
            return
        if kind.spur_pair_gears:
            self._check_spur_pair_gears()
        mesh, _ = self.stiffness_inputs()
        self.contact_inputs(mesh)

    def _check_spur_pair_gears(self) -> None:
        """A ``spur_pair`` model is an external spur pair on its unloaded mesh stiffness: the
        fields of a helical or internal pair and of the loaded contact are refused, naming the
        field (they are ``geardyn stiffness``'s)."""
        gears, table = self.gears, self.stiffness
        given = [(("gears", "helix_angle"), gears.helix_angle),  # type: ignore[union-attr]
                 (("gears", "internal"), gears.internal or None),  # type: ignore[union-attr]
                 (("gears", "ring_foundation"), gears.ring_foundation),  # type: ignore[union-attr]
                 (("relief",), self.relief), (("crowning",), self.crowning)]
        if table is not None:
            given += [(("stiffness", name), getattr(table, name))
                      for name in ("slices", "torque", "force")]
        for loc, value in given:
            if value is not None:
                raise _study_error(loc, value, "not part of a spur_pair model (an external spur"
                                   " pair on its unloaded mesh stiffness; geardyn stiffness"
                                   " takes it)")

    def stiffness_inputs(self, faults: bool = True) -> tuple[GearMesh, dict[str, Any]]:
        """The ``[gears]`` pair and the keywords of
        :func:`~geardyn.gears.potential_energy_stiffness` for it: bore radii, material,
        ``[stiffness]`` settings and (unless ``faults`` is false: the healthy pair) the
        ``[[faults]]``, built and checked against the teeth; a ValidationError naming the
        field where they are refused (each fault is checked on its own first, so that an error
        names its table)."""
        if self.gears is None:
            raise StudyError(f"study {self.study.name!r} has no [gears] table")
        tables = (self.faults or []) if faults else []
        built = [f.build(("faults", i)) for i, f in enumerate(tables)]
        settings = self.stiffness or StiffnessTable()
        try:
            mesh = self.gears.mesh()
            kw: dict[str, Any] = {
                "bore_radius": self.gears.bores(), "young": self.gears.young,
                "poisson": self.gears.poisson, "root_segment": settings.root_segment,
                "nodes": settings.nodes}
            if self.gears.internal:
                kw["ring_foundation"] = self.gears.ring_foundation or "rigid"
            spur = mesh.transverse if isinstance(mesh, HelicalMesh) else mesh
            prepare_pair(spur, **kw)
        except ParameterError as exc:
            missing = exc.value is None and exc.reason.startswith("required")
            raise _study_error(self._location(exc.field), exc.value, exc.reason,
                               "missing" if missing else "value_error") from None
        if isinstance(mesh, HelicalMesh):
            _check_helical_faults(built)
        elif settings.slices is not None:
            raise _study_error(("stiffness", "slices"), settings.slices, "slices the face width"
                               " of a helical pair: give gears.helix_angle (0 deg for spur"
                               " teeth by slices)")
        for i, fault in enumerate(built):
            _check_fault(spur, kw, fault, ("faults", i))
        if built:
            kw.update(_fault_keywords(built))
            _check_fault(spur, kw, None, ("faults",))
        kw.update(angles=settings.angles, cycles=settings.mesh_cycles(spur))
        if isinstance(mesh, HelicalMesh) and settings.slices is not None:
            kw["slices"] = settings.slices
        return mesh, kw

    def contact_inputs(self, mesh: GearMesh | HelicalMesh | None = None
                       ) -> dict[str, Any] | None:
        """The loaded contact of the ``[gears]`` pair (``mesh``, else built), or None without
        a load: ``force`` [N] (``[stiffness].force``, or ``torque`` / r_b1 with r_b1 the
        pinion's (transverse) base radius), ``relief`` and ``crowning`` (tuples of
        :class:`~geardyn.gears.TipRelief`, :class:`~geardyn.gears.LeadCrowning`) and
        ``torque`` [N m] (None where the force is given). A relief or crowning without a
        load, a crowning on a spur pair, both torque and force are errors naming the field."""
        if mesh is None:
            mesh = self.stiffness_inputs(faults=False)[0]
        settings = self.stiffness or StiffnessTable()
        relief = tuple(r.build(("relief", i)) for i, r in enumerate(self.relief or []))
        crowning = tuple(c.build(("crowning", i)) for i, c in enumerate(self.crowning or []))
        spur = mesh.transverse if isinstance(mesh, HelicalMesh) else mesh
        for i, r in enumerate(relief):
            try:
                relief_gap(spur, [0.0], (r,))
            except ParameterError as exc:
                raise _study_error(("relief", i, exc.field.rpartition(".")[2]), exc.value,
                                   exc.reason) from None
        if crowning and not isinstance(mesh, HelicalMesh):
            raise _study_error(("crowning",), None, "lead crowning needs the slices of a"
                               " helical pair: give gears.helix_angle (0 deg for spur teeth)")
        if settings.torque is not None and settings.force is not None:
            raise _study_error(("stiffness", "force"), settings.force,
                               "give the load as torque or as force, not both")
        if settings.torque is None and settings.force is None:
            for name, given in (("crowning", crowning), ("relief", relief)):
                if given:
                    raise _study_error((name,), None, "needs a load for the loaded contact:"
                                       " [stiffness] torque (N m on the pinion) or force (N)")
            return None
        force = (settings.force if settings.torque is None
                 else settings.torque / spur.pinion.base_radius)
        return {"force": force, "relief": relief, "crowning": crowning,
                "torque": settings.torque}

    def _location(self, field: str) -> tuple:
        """Where in the study a :class:`ParameterError` of the gears' ``field`` lies."""
        if field in StiffnessTable.model_fields:
            return ("stiffness", field)
        return self.gears.location(field)  # type: ignore[union-attr]

    # ------------------------------------------------------------------ accessors
    @property
    def planetary_params(self) -> PlanetaryParams:
        """The resolved device parameters (catt studies)."""
        if self._planetary is None:
            raise StudyError(f"study {self.study.name!r} is a {self.study.model} study: no CATT "
                             "device params")
        return self._planetary

    @property
    def gear_train(self) -> Any:
        """The :class:`~geardyn.trains.GearTrain` of the ``[train]`` table (built once, when
        the study is read)."""
        if self._train is None:
            raise StudyError(f"study {self.study.name!r} has no [train] table")
        return self._train

    @property
    def plot_state(self) -> str:
        return self.study.plot_state or DEFAULT_PLOT_STATE[self.study.model]

    def to_toml_dict(self) -> dict[str, Any]:
        """The study as TOML-ready tables (``None`` values left out; ``[run].transient`` too
        where ``transient_periods`` stands for it)."""
        data = self.model_dump(exclude_none=True)
        if self.run.transient_periods is not None:
            data["run"].pop("transient", None)
        return data


# --------------------------------------------------------------------------- reading
def _is_text(source: object) -> bool:
    """A string is TOML text, not a file name, when it has a newline, starts with a table or is
    blank (an empty document, not the current directory)."""
    return isinstance(source, str) and (
        "\n" in source or source.lstrip().startswith("[") or not source.strip()
    )


def _read_toml(source: str | os.PathLike[str]) -> tuple[dict[str, Any], str]:
    """Parse TOML text or a file; returns the document and a label for error messages."""
    if _is_text(source):
        text, label = str(source), "<text>"
    else:
        path = Path(source)
        label = str(path)
        if "\x00" in label:
            raise StudyError(f"{label!r}: not a valid file name (holds a NUL character)")
        if path.is_dir():
            raise StudyError(f"{label}: is a directory, not a TOML file")
        try:
            text = path.read_text(encoding="utf-8")  # FileNotFoundError names the file
        except UnicodeDecodeError as exc:
            raise StudyError(f"{label}: not a UTF-8 text file ({exc.reason} at byte "
                             f"{exc.start})") from None
    try:
        return tomllib.loads(text), label
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(f"{label}: invalid TOML: {exc}") from None


_STUDY_KEYS = {"study", "params", "run", "sweep", "gears", "faults", "stiffness", "relief",
               "crowning", "train", "envelope", "runup", "dataset"}


def load_params(path_or_text: str | os.PathLike[str]) -> PlanetaryParams:
    """Read :class:`PlanetaryParams` from a TOML file or TOML text.

    The document holds the parameter fields at the top level, or a ``[params]`` table as in a
    study file (full form or ``base = "paper"`` plus changes).
    """
    doc, label = _read_toml(path_or_text)
    if not doc:
        raise StudyError(f"{label}: empty parameter file (needs the parameter tables)")
    if set(doc) & _STUDY_KEYS:
        return load_study_dict(doc).planetary_params  # every table checked, not only [params]
    return PlanetaryParams.model_validate(doc)


def _study_document(doc: dict[str, Any]) -> dict[str, Any]:
    """``doc`` with a bare parameter document (PlanetaryParams fields at the top level) moved
    into ``[params]``; a document of neither kind is refused naming its first key."""
    if not doc or set(doc) & _STUDY_KEYS:
        return doc
    if not set(doc) & set(PlanetaryParams.model_fields):
        first = next(iter(doc))
        raise StudyError(f"{first}: unknown key; a study file holds the tables "
                         f"{', '.join(f'[{k}]' for k in sorted(_STUDY_KEYS))}")
    return {"params": doc}


def load_study_dict(doc: dict[str, Any]) -> Study:
    """A :class:`Study` from a parsed document; a bare parameter document becomes ``[params]``."""
    return Study.model_validate(_study_document(doc))


def load_study(path_or_text: str | os.PathLike[str]) -> Study:
    """Read a study from a TOML file or TOML text (see the module docs for the format).

    A file without ``[study]`` gets the file's stem as its name; a bare parameter file (fields at
    the top level) is read as a study of the paper's device with those parameters.
    """
    doc, label = _read_toml(path_or_text)
    if not doc:
        raise StudyError(f"{label}: empty study file (needs at least a [params] or a [gears]"
                         " table)")
    doc = _study_document(doc)
    if not _is_text(path_or_text) and isinstance(doc.get("study", {}), dict):
        doc.setdefault("study", {}).setdefault("name", Path(path_or_text).stem)
    return Study.model_validate(doc)


# --------------------------------------------------------------------------- writing
def _write_atomic(path: str | os.PathLike[str], text: str) -> Path:
    path = Path(path)
    if path.is_dir():
        raise StudyError(f"{path}: is a directory, not a file to write")
    try:
        with atomic_replace(path) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
    except OSError as exc:  # name the file asked for, not the temporary one
        raise StudyError(f"{path}: cannot write ({exc.strerror or exc})") from None
    return path


def _check_finite(obj: Any, where: str = "") -> None:
    if isinstance(obj, float) and not math.isfinite(obj):
        raise ParameterError(where or "value", obj, "TOML files hold finite numbers only")
    if isinstance(obj, dict):
        for k, v in obj.items():
            _check_finite(v, f"{where}.{k}" if where else str(k))
    elif isinstance(obj, list | tuple):
        for i, v in enumerate(obj):
            _check_finite(v, f"{where}[{i}]")


def params_to_toml(params: PlanetaryParams) -> str:
    """TOML text of ``params`` in full form (SI floats with repr precision, angles in rad)."""
    data = params.model_dump(exclude_none=True)
    _check_finite(data)
    return _HEADER.format(what="device parameters") + tomli_w.dumps(data)


def save_params(params: PlanetaryParams, path: str | os.PathLike[str]) -> Path:
    """Write ``params`` to a TOML file (atomically); :func:`load_params` reads it back equal."""
    return _write_atomic(path, params_to_toml(params))


def study_to_toml(study: Study) -> str:
    data = study.to_toml_dict()
    _check_finite(data)
    return _HEADER.format(what="study") + tomli_w.dumps(data)


def save_study(study: Study, path: str | os.PathLike[str]) -> Path:
    """Write ``study`` to a TOML file (atomically); :func:`load_study` reads it back equal."""
    return _write_atomic(path, study_to_toml(study))


def paper_study(name: str = "paper") -> Study:
    """A study of the paper's device (Tables 1 and 2) in full form, e.g. as a template."""
    return Study(
        study=StudyInfo(
            name=name,
            description="The paper's device, Tables 1 and 2 (xi1 = xi2 = 0.05)",
            plot_state="X_sq",
        ),
        params=PlanetaryParams.paper(),
    )


# --------------------------------------------------------------------------- built-in studies
def builtin_study_names() -> list[str]:
    """Names of the studies shipped in :mod:`geardyn.studies`."""
    root = resources.files("geardyn.studies")
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def builtin_study_text(name: str) -> str:
    res = resources.files("geardyn.studies") / f"{name}.toml"
    if not res.is_file():
        known = ", ".join(builtin_study_names()) or "none"
        raise StudyError(f"no built-in study {name!r}; known: {known}")
    return res.read_text(encoding="utf-8")


def builtin_study(name: str) -> Study:
    """A study shipped with geardyn, by name (``"paper_fig3"``)."""
    return load_study(builtin_study_text(name))
