"""One schema per result kind, the registry that the dataset builders fill and
:func:`geardyn.testing.assert_result` reads.

A result records its kind in ``attrs["geardyn_kind"]``. A kind's :class:`ResultSchema` names its
required attributes, coordinates and variables with their dimensions, the attributes (units,
meaning) a variable of a given name carries, and its status variables. Names and dimensions in
braces are the dataset's own: ``{param}`` the value of ``attrs["param"]`` (default ``Omega``),
``{x}``/``{y}`` those of ``attrs["x"]``/``attrs["y"]``; the variable ``{state}`` stands for one
variable per entry of the ``state`` coordinate. Every builder ends with :func:`finish`, which
records the kind and checks the dataset against its schema (a builder that leaves out a
registered part fails there, not in a user's plot).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: A variable of one name: which attributes it carries (its units or the meaning of its codes).
VARIABLE_ATTRS: Mapping[str, tuple[str, ...]] = {
    "period": ("meaning",), "status": ("meaning",),
    "final_time": ("units",), "poincare_time": ("units",), "time": ("units",),
    "attractor_id": ("meaning",), "attractor_fraction": ("meaning",), "unresolved": ("meaning",),
    "dte_rms": ("units",), "dte_peak": ("units",), "jump_omega": ("meaning",),
    "period_time": ("units",), "special_kind": ("meaning",),
    "bifurcation_kind": ("meaning",), "bifurcation_located": ("meaning",)}


class ResultSchemaError(AssertionError):
    """A dataset that does not hold what its kind's schema requires; the message names every
    problem."""


@dataclass(frozen=True)
class ResultSchema:
    """What a result of one kind holds (see the module docs for the names in braces)."""

    kind: str
    attrs: tuple[str, ...]
    coords: Mapping[str, tuple[str, ...]]
    variables: Mapping[str, tuple[str, ...]]
    statuses: tuple[str, ...] = ()
    #: Attributes that hold a :class:`~geardyn.Status` code.
    status_attrs: tuple[str, ...] = ()
    defaults: Mapping[str, str] = field(default_factory=lambda: {"param": "Omega", "x": "x",
                                                                 "y": "y"})
    #: What a result of the kind is called in messages ("" the kind itself).
    label: str = ""

    @property
    def name(self) -> str:
        """What a result of the kind is called in messages (``"map"`` for ``"map2d"``)."""
        return self.label or self.kind

    def _name(self, ds: Any, text: str) -> str:
        if text.startswith("{") and text.endswith("}"):
            key = text[1:-1]
            return str(ds.attrs.get(key, self.defaults[key]))
        return text

    def resolve(self, ds: Any) -> tuple[list[str], dict[str, tuple[str, ...]],
                                        dict[str, tuple[str, ...]]]:
        """(attributes, coordinates with their dims, variables with their dims) for ``ds``."""
        def dims(d: tuple[str, ...]) -> tuple[str, ...]:
            return tuple(self._name(ds, x) for x in d)

        coords = {self._name(ds, k): dims(d) for k, d in self.coords.items()}
        variables: dict[str, tuple[str, ...]] = {}
        for k, d in self.variables.items():
            if k == "{state}":
                states = ds["state"].values if "state" in ds.coords else []
                variables.update({str(s): dims(d) for s in states})
            else:
                variables[self._name(ds, k)] = dims(d)
        return list(self.attrs), coords, variables


_LEAD = ("{param}",)
_FRC = ("sweep", "Omega")

#: The registry: every kind of result geardyn returns, by ``attrs["geardyn_kind"]``.
SCHEMAS: dict[str, ResultSchema] = {s.kind: s for s in (
    ResultSchema(
        "simulation", ("status", "status_meaning", "steps_per_period", "time_unit"),
        {"time": ("time",), "sample": ("sample",), "state": ("state",)},
        {"poincare": ("sample", "state"), "poincare_time": ("sample",), "{state}": ("time",)},
        status_attrs=("status",)),
    ResultSchema(
        "bifurcation", ("param", "time_unit"),
        {"{param}": _LEAD, "sample": ("sample",), "state": ("state",)},
        {"poincare": (*_LEAD, "sample", "state"), "period": _LEAD, "status": _LEAD,
         "final_time": _LEAD}, ("status",)),
    ResultSchema(
        "reproduction-case", ("param", "time_unit"),
        {"{param}": _LEAD, "sample": ("sample",), "state": ("state",), "sweep": ("sweep",)},
        {"poincare": ("sweep", *_LEAD, "sample", "state"), "period": ("sweep", *_LEAD),
         "status": ("sweep", *_LEAD), "final_time": ("sweep", *_LEAD)}, ("status",),
        label="reproduction"),
    ResultSchema(
        "map2d", ("x", "y", "time_unit"), {"{y}": ("{y}",), "{x}": ("{x}",)},
        {"period": ("{y}", "{x}"), "status": ("{y}", "{x}")}, ("status",), label="map"),
    ResultSchema(
        "periodic-orbit",
        ("status", "status_meaning", "steps_per_period", "time_unit", "Omega", "period",
         "converged", "orbit_status", "message", "residual", "stability"),
        {"time": ("time",), "state": ("state",), "multiplier": ("multiplier",)},
        {"section_point": ("state",), "monodromy": ("state", "state_in"),
         "multiplier_real": ("multiplier",), "multiplier_imag": ("multiplier",),
         "{state}": ("time",)},
        status_attrs=("status",), label="periodic orbit"),
    ResultSchema(
        "continuation",
        ("param", "start", "stop", "period", "status", "message", "status_meaning", "time_unit"),
        {"point": ("point",), "{param}": ("point",), "state": ("state",),
         "multiplier": ("multiplier",), "branch_id": ("branch_id",)},
        {"section_point": ("point", "state"), "multiplier_real": ("point", "multiplier"),
         "multiplier_imag": ("point", "multiplier"), "stability": ("point",),
         "branch": ("point",), "bifurcation_kind": ("bifurcation",),
         "bifurcation_value": ("bifurcation",), "bifurcation_error": ("bifurcation",),
         "bifurcation_located": ("bifurcation",), "branch_status": ("branch_id",),
         "branch_message": ("branch_id",)}),
    ResultSchema(
        "curve",
        ("curve_kind", "x", "y", "period", "status", "message", "status_meaning",
         "time_unit"),
        {"point": ("point",), "{x}": ("point",), "{y}": ("point",), "state": ("state",),
         "multiplier": ("multiplier",), "special": ("special",)},
        {"section_point": ("point", "state"),
         "multiplier_real": ("point", "multiplier"),
         "multiplier_imag": ("point", "multiplier"), "period_time": ("point",),
         "special_kind": ("special",), "special_x": ("special",), "special_y": ("special",),
         "special_error": ("special",)}),  # its status: a BranchStatus code, not a Status
    ResultSchema(
        "dynamic-factor", ("standard", "stiffness_source"),
        {"torque": ("torque",), "speed": ("speed",), "group": ("group",)},
        {"dynamic_factor": ("torque", "speed", "group"), "K_v": ("torque", "speed", "group"),
         "contact": ("torque", "speed", "group"), "period": ("torque", "speed"),
         "resonance_speed": ("torque", "group")}, label="dynamic factor"),
    ResultSchema(
        "basins",
        ("x", "y", "Omega", "time_unit", "diverged_fraction", "unresolved_fraction",
         "n_attractors"),
        {"{y}": ("{y}",), "{x}": ("{x}",), "attractor": ("attractor",), "state": ("state",)},
        {"attractor_id": ("{y}", "{x}"), "period": ("{y}", "{x}"), "status": ("{y}", "{x}"),
         "unresolved": ("{y}", "{x}"), "attractor_period": ("attractor",),
         "attractor_fraction": ("attractor",),
         "attractor_point": ("attractor", "point", "state"), "attractor_orbit": ("attractor",)},
        ("status",)),
    ResultSchema(
        "frequency-response", ("param", "time_unit", "resolution"),
        {"sweep": ("sweep",), "Omega": ("Omega",), "mesh": ("mesh",), "jump": ("jump",)},
        {"dte_rms": (*_FRC, "mesh"), "dte_peak": (*_FRC, "mesh"), "dte_mean": (*_FRC, "mesh"),
         "period": _FRC, "status": _FRC, "hysteresis": ("Omega",), "jump_omega": ("jump",),
         "jump_sweep": ("jump",)}, ("status",), label="frequency response"),
    ResultSchema(
        "runup",
        ("status", "status_meaning", "integrator", "step", "steps_per_period", "time_unit",
         "start", "stop", "rate", "outputs"),
        {"time": ("time",)}, {"Omega": ("time",), "phase": ("time",)},
        status_attrs=("status",), label="run-up"),
    ResultSchema(
        "fault-dataset", ("model", "time_unit", "snr_db", "duration", "sample_rate"),
        {"fault": ("fault",), "fault_kind": ("fault",), "fault_size": ("fault",),
         "fault_gear": ("fault",), "fault_tooth": ("fault",), "speed": ("speed",),
         "torque": ("torque",), "seed": ("seed",), "time": ("time",)},
        {"signal": ("fault", "speed", "torque", "seed", "time"),
         "status": ("fault", "speed", "torque"), "unresolved": ("fault", "speed", "torque"),
         "noise_std": ("fault", "speed", "torque")}, ("status",), label="fault dataset"),
)}

#: The kinds of result, as recorded in ``attrs["geardyn_kind"]``.
KINDS: tuple[str, ...] = tuple(SCHEMAS)


def schema(kind: str) -> ResultSchema:
    """The schema of ``kind``; an AssertionError naming the known kinds for any other."""
    if kind not in SCHEMAS:
        raise ResultSchemaError(f"unknown result kind {kind!r}: one of {', '.join(KINDS)}")
    return SCHEMAS[kind]


def status_problems(name: str, values: Any) -> list[str]:
    """What is wrong with the status codes ``values`` of ``name`` (empty when all are known)."""
    from geardyn.core.status import Status

    codes = np.asarray(values)
    if codes.dtype.kind not in "iuf" or np.any(~np.isfinite(codes.astype(float))):
        return [f"{name}: not integer status codes (dtype {codes.dtype})"]
    bad = np.setdiff1d(codes.astype(np.int64), [int(s) for s in Status])
    if bad.size:
        return [f"{name}: codes {bad.tolist()} are not geardyn.Status codes "
                f"{[int(s) for s in Status]}"]
    return []


def problems(ds: Any, kind: str) -> list[str]:
    """Everything ``ds`` lacks against the schema of ``kind``: the recorded kind, the
    attributes, coordinates (dims in order) and variables (dims in any order), the attributes of
    variables (:data:`VARIABLE_ATTRS`) and the status codes."""
    sc = schema(kind)
    out: list[str] = []
    recorded = ds.attrs.get("geardyn_kind")
    if recorded != kind:
        out.append(f"attrs['geardyn_kind'] is {recorded!r}, expected {kind!r}")
    attrs, coords, variables = sc.resolve(ds)
    out += [f"attribute {a!r} missing" for a in attrs if a not in ds.attrs]
    for group, wanted, ordered in (("coordinate", coords, True), ("variable", variables, False)):
        for name, dims in wanted.items():
            if name not in (ds.coords if group == "coordinate" else ds.variables):
                out.append(f"{group} {name!r} missing")
                continue
            have = tuple(ds[name].dims)
            if (have != dims) if ordered else (sorted(have) != sorted(dims)):
                out.append(f"{group} {name!r} has dims {have}, expected {dims}")
    for name, keys in VARIABLE_ATTRS.items():
        if name in ds.variables:
            out += [f"{name!r} has no {k!r} attribute" for k in keys if k not in ds[name].attrs]
    for name in sc.statuses:
        if name in ds.variables:
            out += status_problems(name, ds[name].values)
    for name in sc.status_attrs:
        if name in ds.attrs:
            out += status_problems(f"attrs[{name!r}]", ds.attrs[name])
    return out


def finish(ds: Any, kind: str) -> Any:
    """Record ``kind`` in ``ds.attrs["geardyn_kind"]`` and check ``ds`` against its schema:
    a :class:`ResultSchemaError` naming every missing or malformed part (a builder's bug).
    Returns ``ds``."""
    ds.attrs["geardyn_kind"] = schema(kind).kind
    found = problems(ds, kind)
    if found:
        raise ResultSchemaError(f"not a geardyn {kind} result: " + "; ".join(found))
    return ds
