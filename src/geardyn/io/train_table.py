"""The ``[train]`` table of a study: a gear train from its elements, by name, as
:mod:`geardyn.trains` describes it in Python::

    [train]
    driven = "g1"                  # the input body (speeds and mesh orders refer to it)
    fixed = ["ring"]               # bodies held fixed; free = true keeps a rigid-body mode
    rayleigh = [0.0, 1e-5]         # a [1/s], b [s] of the Rayleigh damping a M + b K
    [train.gears.g1]               # a Gear: inertia, mass, base_radius, n_teeth ...
    inertia = "0.01 kg m^2"
    [train.gears.g1.geometry]      # ... or its geometry: a SpurGear (internal = true: a ring)
    teeth = 19                     #   or, with helix_angle, a HelicalGear (normal section)
    module = "3 mm"
    face_width = "20 mm"
    [train.inertias.carrier]       # an Inertia: inertia, mass
    [train.shafts.input]           # a Shaft: a, b ("ground"), stiffness, damping
    [train.bearings.b1]            # a Bearing: body, stiffness ("inf": rigid), host, ...
    [train.meshes.stage1]          # a Mesh: a, b, stiffness (N/m, "iso", "potential_energy"), ...
    [train.planetary.stage1]       # planetary_stage(): sun, ring, carrier, planet name bodies
                                   #   (ring_planet: a compound stage's second planet gear)
    [[train.faults]]               # a tooth fault (geardyn.trains.faults): kind (crack, spall,
    kind = "crack"                 #   wear, broken_tooth) and its fields, its gear a gear of
    gear = "g1"                    #   the train (all faults on one gear, whose meshes take
    tooth = 3                      #   stiffness = "potential_energy")
    depth = "1 mm"

Every sub-table's keys are the keyword arguments of its element (one declaration: the element's
dataclass fields, :func:`geardyn.trains.planetary_stage`'s parameters), the table's own key
its name; values are SI numbers or unit strings. A ``[[train.faults]]`` table's keys are
``kind`` (a key of :data:`geardyn.gears.FAULT_KINDS`) and that fault's fields. The bodies are
the gears, then the inertias, in the order written, a planetary stage's planet (and ring
planet) replaced where it stands by the stage's copies (``<planet>1`` ...); then the shafts,
bearings and meshes written, each followed by the stages' own (joints, pins and hubs, meshes).
An unknown key, a missing one or a value an element refuses is an error naming
``train.<group>.<name>.<field>`` (a fault's ``train.faults[<i>].<field>``); what the train as a
whole refuses (a reference to no body, a free rigid-body mode, a mesh of gears that cannot mesh,
a fault on a gear without the potential-energy stiffness) names the element's (or the fault's)
table likewise.
"""

from __future__ import annotations

import inspect
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, StrictBool

from geardyn.errors import ParameterError
from geardyn.gears.faults import FAULT_KINDS
from geardyn.gears.geometry import SpurGear
from geardyn.gears.helical import HelicalGear
from geardyn.io._tables import build_from_fields, study_error
from geardyn.trains import (
    Bearing,
    Gear,
    GearTrain,
    Inertia,
    Mesh,
    PlanetaryStage,
    Shaft,
    planetary_stage,
)

__all__ = ["TrainTable"]

#: The element tables of ``[train]``: group -> (element class, what the messages call it).
GROUPS: dict[str, tuple[Any, str]] = {
    "gears": (Gear, "a Gear"), "inertias": (Inertia, "an Inertia"),
    "shafts": (Shaft, "a Shaft"), "bearings": (Bearing, "a Bearing"),
    "meshes": (Mesh, "a Mesh")}
#: The keys of a ``[train.planetary.<name>]`` table that name bodies of the train (and the
#: optional ``ring_planet``, a compound stage's second planet gear).
STAGE_MEMBERS = ("sun", "ring", "carrier", "planet")

Tables = dict[str, dict[str, Any]]


class TrainTable(BaseModel):
    """``[train]``: the train's elements by group and name (each a table of the element's
    fields) and the arguments of :class:`~geardyn.trains.GearTrain` (module docstring).
    :meth:`build` makes the train; its errors name the table and field."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    driven: str | None = Field(None, description="the input body")
    fixed: list[str] = Field(default_factory=list, description="bodies held fixed")
    free: StrictBool = Field(False, description="keep a free rigid-body mode")
    rayleigh: list[Any] = Field(default_factory=lambda: [0.0, 0.0],
                                description="(a [1/s], b [s]) of the Rayleigh damping")
    gears: Tables = Field(default_factory=dict)
    inertias: Tables = Field(default_factory=dict)
    shafts: Tables = Field(default_factory=dict)
    bearings: Tables = Field(default_factory=dict)
    meshes: Tables = Field(default_factory=dict)
    planetary: Tables = Field(default_factory=dict)
    faults: list[Any] = Field(default_factory=list, description="[[train.faults]]: tooth "
                              "faults on one gear (kind and the fault's fields)")

    def build(self, where: tuple = ("train",)) -> GearTrain:
        """The :class:`~geardyn.trains.GearTrain` (a ValidationError at ``where`` + the table
        and field where an element or the train refuses it)."""
        located: dict[str, tuple] = {}
        made: dict[str, list[Any]] = {}
        for group, (cls, what) in GROUPS.items():
            made[group] = []
            for name, table in getattr(self, group).items():
                loc = where + (group, name)
                if name in located:
                    raise study_error(loc, name, f"the name is used twice (also"
                                      f" {'.'.join(map(str, located[name]))})")
                located[name] = loc
                made[group].append(_element(cls, what, name, table, loc))
        bodies = {b.name: b for b in made["gears"] + made["inertias"]}
        templates: dict[str, list[Any]] = {}  # a stage's planet (or ring_planet): its copies
        stages: list[PlanetaryStage] = []
        for name, table in self.planetary.items():
            stage = self._stage(name, table, bodies, where + ("planetary", name), located)
            stages.append(stage)
            for key, names in (("planet", stage.planets), ("ring_planet", stage.compound)):
                if key in table:
                    templates[str(table[key])] = [b for b in stage.bodies if b.name in names]
        order: list[Any] = []
        for name, body in bodies.items():
            order.extend(templates.get(name, [body]))
        faults = [_fault(t, where + ("faults", i)) for i, t in enumerate(self.faults)]
        try:
            return GearTrain(
                order, [*made["shafts"], *(s for st in stages for s in st.shafts)],
                [*made["bearings"], *(b for s in stages for b in s.bearings)],
                [*made["meshes"], *(m for s in stages for m in s.meshes)],
                fixed=tuple(self.fixed), driven=self.driven, free=self.free,
                rayleigh=tuple(self.rayleigh), faults=faults)
        except ParameterError as exc:
            raise _located(exc, located, where, faults) from None

    def _stage(self, name: str, table: dict[str, Any], bodies: dict[str, Any], loc: tuple,
               located: dict[str, tuple]) -> PlanetaryStage:
        """The planetary stage of ``[train.planetary.<name>]`` on the bodies it names."""
        given = dict(table)
        params = inspect.signature(planetary_stage).parameters
        for key in STAGE_MEMBERS:
            if key not in given:
                raise study_error(loc + (key,), None, "required: the name of a body of the"
                                  " train", kind="missing")
            if given[key] not in bodies:
                raise study_error(loc + (key,), given[key], "names no gear or inertia of the"
                                  " train")
            given[key] = bodies[given[key]]
        if "ring_planet" in given:
            if given["ring_planet"] not in bodies:
                raise study_error(loc + ("ring_planet",), given["ring_planet"], "names no gear"
                                  " of the train")
            given["ring_planet"] = bodies[given["ring_planet"]]
        for key in given:
            if key not in params:
                raise study_error(loc + (key,), given[key], "unknown key (not a parameter of"
                                  f" planetary_stage; known: {', '.join(params)})")
        try:
            stage = planetary_stage(**given)
        except ParameterError as exc:
            head = exc.field.split(".")[0].split("[")[0]
            raise study_error(loc + ((head,) if head in params else ()), exc.value,
                              f"{exc.field}: {exc.reason}" if head not in params
                              else exc.reason) from None
        for element in (*stage.bodies[3:], *stage.bearings, *stage.meshes, *stage.shafts):
            if element.name in located:
                raise study_error(loc, element.name, f"the stage's element {element.name!r}"
                                  " has the name of another element")
            located[element.name] = loc
        return stage


def _element(cls: Any, what: str, name: str, table: Any, loc: tuple) -> Any:
    """The element ``cls`` of the table ``[train.<group>.<name>]``."""
    if not isinstance(table, dict):
        raise study_error(loc, table, f"must be a table of the fields of {what}")
    given = dict(table)
    if "name" in given:
        raise study_error(loc + ("name",), given["name"], "the table's key is the name")
    if cls is Gear and isinstance(given.get("geometry"), dict):
        given["geometry"] = _geometry(name, given["geometry"], loc + ("geometry",))
    return build_from_fields(cls, {**given, "name": name}, loc, what)


def _geometry(name: str, table: dict[str, Any], loc: tuple) -> SpurGear | HelicalGear:
    """A gear's ``geometry`` table: a HelicalGear where it has ``helix_angle``, else a
    SpurGear."""
    cls, what = (HelicalGear, "a HelicalGear") if "helix_angle" in table else (
        SpurGear, "a SpurGear")
    if "name" in table:
        raise study_error(loc + ("name",), table["name"], "the gear's table names it")
    return build_from_fields(cls, {**table, "name": name}, loc, what)


def _fault(table: Any, loc: tuple) -> object:
    """The fault of a ``[[train.faults]]`` table (``kind`` and the fault's fields)."""
    if not isinstance(table, dict):
        raise study_error(loc, table, "must be a table: kind and the fault's fields")
    given = dict(table)
    if "kind" not in given:
        raise study_error(loc + ("kind",), None, "required: one of " + ", ".join(FAULT_KINDS),
                          kind="missing")
    kind = given.pop("kind")
    cls = FAULT_KINDS.get(kind)
    if cls is None:
        raise study_error(loc + ("kind",), kind, "unknown fault kind; known: "
                          + ", ".join(FAULT_KINDS))
    return build_from_fields(cls, given, loc, f"a {kind} fault", "kind, ")


def _located(exc: ParameterError, located: dict[str, tuple], where: tuple,
             faults: list[Any]) -> Exception:
    """The study error of a ParameterError the train raised: its field's first part is an
    element's name (that element's table, then the rest of the field), a fault's kind (the
    first fault of that kind holding the value: its table and field) or a GearTrain
    argument."""
    head, _, rest = exc.field.partition(".")
    kinds = [f.kind for f in faults]
    if head in kinds and rest:
        hit = [i for i, k in enumerate(kinds) if k == head]
        i = next((i for i in hit if getattr(faults[i], rest, None) == exc.value), hit[0])
        return study_error(where + ("faults", i, rest), exc.value, exc.reason)
    if head in located:
        loc = located[head]
        if rest and loc[-2] != "planetary":
            return study_error(loc + tuple(rest.split(".")), exc.value, exc.reason)
        return study_error(loc, exc.value, f"{exc.field}: {exc.reason}" if rest else exc.reason)
    return study_error(where + (head.split("[")[0],), exc.value, exc.reason)
