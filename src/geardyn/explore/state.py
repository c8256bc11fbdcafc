"""What the explorer shows and how it changes, as plain Python (no web framework): the study,
the parameter window and its history, the parameter overrides, the command line that reproduces
the view, and the saving of the view.

A study whose model is built from geometry also offers that geometry and its faults as
controls (:meth:`ExplorerState.geometry_params`), named by their study-file keys: a gear pair's
(a ``[gears]`` table: ``gears.pinion.bore_radius``, ``faults[0].depth``), a planetary set's (a
``[params.geometry]`` table: ``params.geometry.stiffness``,
``params.geometry.stiffness_options.sun_bore_radius``, ``params.geometry.faults[0].gear``); a
new value rebuilds the model from the changed study, as the study file would.

Every change goes through :class:`ExplorerState`; a change that is not valid returns the message
to show and leaves the state as it was. The computations live in :mod:`geardyn.explore.compute`.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shlex
import typing
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from geardyn.core.model import Model
from geardyn.core.settings import OMEGA_RULE, check_continuation, usable_omega
from geardyn.errors import ParameterError
from geardyn.gears.faults import FAULT_KINDS
from geardyn.io.study_models import STUDY_MODELS, StudyModel, study_model
from geardyn.io.toml import CONTINUATIONS, FaultTable, Study, is_paper_base
from geardyn.models.derived import INTERPRETATIONS
from geardyn.models.planetary_stiffness import COAST_FLANKS, STIFFNESS_METHODS

__all__ = ["CONTINUATIONS", "GEOMETRY_KEYS", "INTERPRETATIONS", "MAIN_PARAMS",
           "PLANETARY_GEOMETRY_KEYS", "DiagramRequest", "ExplorerState", "Window",
           "fault_fields", "key_path", "parse_value", "switched_fault"]

#: The main parameters offered as controls, per model kind (``[study].model``), in declared
#: order: the model's declared inputs flagged ``explore``
#: (:attr:`~geardyn.core.model.Model.explorer_names`; damping ratios, backlash, meshing error,
#: load or torque fluctuation; ``StudyModel.explored``). A train's are offered where its study
#: gives them as one number for every mesh (``StudyModel.explore_given_only``: a per-mesh table
#: is not a control).
MAIN_PARAMS: dict[str, tuple[str, ...]] = {k: m.explored for k, m in STUDY_MODELS.items()}
#: The ``[gears]`` inputs offered as controls of a model built from a pair's geometry (study-file
#: keys; each gear's own value, which wins over a shared ``[gears]`` one). The faults' controls
#: come from the study's ``[[faults]]`` (:func:`fault_fields`).
GEOMETRY_KEYS = ("gears.pinion.bore_radius", "gears.wheel.bore_radius")
#: The ``[params.geometry]`` inputs offered as controls of a planetary set built from geometry:
#: the stiffness method, the coast flank, the bores and the ring's rim (``stiffness_options``).
#: The faults' controls come from ``[[params.geometry.faults]]``.
PLANETARY_GEOMETRY_KEYS = ("params.geometry.stiffness", "params.geometry.coast",
                           "params.geometry.stiffness_options.sun_bore_radius",
                           "params.geometry.stiffness_options.planet_bore_radius",
                           "params.geometry.stiffness_options.ring_rim_radius")


@dataclass(frozen=True)
class Window:
    """A parameter window: ``num`` evenly spaced values from ``start`` to ``stop``."""

    start: float
    stop: float
    num: int

    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)

    @property
    def text(self) -> str:
        """``START:STOP:NUM`` as ``--range`` takes it (shortest repr: reproduces exactly)."""
        return f"{_num(self.start)}:{_num(self.stop)}:{self.num}"


def _num(x: float) -> str:
    return repr(float(x)) if float(x) != int(x) else str(int(x))


def _rounded(lo: float, hi: float, digits: int = 4) -> tuple[float, float]:
    """The ends of a zoomed window rounded to ``digits`` significant digits of its width (a
    box zoom gives ends like 0.8992665036674817; the command line reads better with 0.8993)."""
    decimals = max(0, digits - 1 - math.floor(math.log10(hi - lo)))
    a, b = round(lo, decimals), round(hi, decimals)
    return (a, b) if a < b else (lo, hi)


def parse_value(text: str) -> float | str:
    """A control's text: a number where it reads as one, else the text (a unit string such as
    ``"30 um"``, which the parameter validation converts or refuses)."""
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        return text


def fault_fields(kind: str) -> tuple[str, ...]:
    """The numeric fields (float or int) of the fault class of ``kind``
    (:data:`geardyn.gears.FAULT_KINDS`), in its declared order; () for an unknown kind."""
    cls = FAULT_KINDS.get(kind)
    if cls is None:
        return ()
    hints = typing.get_type_hints(cls)
    return tuple(f.name for f in dataclasses.fields(cls) if hints.get(f.name) in (float, int))


#: The fields that place a fault (kept when it changes kind); the others are its size.
PLACEMENT_FIELDS = ("gear", "tooth", "flank")


def switched_fault(table: dict[str, Any], kind: str) -> dict[str, Any]:
    """A fault table (``kind`` and fields) as a fault of ``kind``: where it sits (its
    :data:`PLACEMENT_FIELDS` that the new kind has) kept, its size dropped, and every field the
    new kind needs without a default at 0: a fault of zero size (the healthy tooth; a missing
    tooth has no size), whose size the controls then set (a crack's depth is no wear depth)."""
    cls = FAULT_KINDS[kind]
    fields = {f.name: f for f in dataclasses.fields(cls)}
    out: dict[str, Any] = {"kind": kind}
    out.update({k: v for k, v in table.items() if k in fields and k in PLACEMENT_FIELDS})
    for name, f in fields.items():
        if name not in out and f.default is dataclasses.MISSING:
            out[name] = 0.0
    return out


def key_path(key: str) -> tuple[str | int, ...]:
    """The path of a study-file key in the study's TOML tables: ``faults[0].depth`` ->
    ("faults", 0, "depth")."""
    out: list[str | int] = []
    for part in key.split("."):
        m = re.fullmatch(r"(\w+)\[(\d+)\]", part)
        out += [m[1], int(m[2])] if m else [part]
    return tuple(out)


def _get_path(doc: dict[str, Any], path: tuple[str | int, ...]) -> Any:
    """The value at ``path`` of the TOML tables ``doc``."""
    target: Any = doc
    for part in path:
        target = target[part]
    return target


def _set_path(doc: dict[str, Any], path: tuple[str | int, ...], value: Any) -> None:
    """Set ``value`` at ``path`` of the TOML tables ``doc`` (missing tables made)."""
    target: Any = doc
    for part in path[:-1]:
        target = target[part] if isinstance(part, int) else target.setdefault(part, {})
    target[path[-1]] = value


@dataclass(frozen=True)
class DiagramRequest:
    """Everything one diagram computation needs, captured when it is asked for (a later change of
    the state does not alter a running computation)."""

    model: Model
    param: str
    window: Window
    run: Any  # RunSettings
    continuation: str
    plot_state: str
    attrs: dict[str, Any] = field(default_factory=dict)
    #: The state's view when the request was made (:meth:`ExplorerState.restore` returns to it).
    view: dict[str, Any] = field(default_factory=dict, repr=False)


def _error_text(exc: BaseException) -> str:
    return str(exc)


def _geometry_tables(study: Study) -> tuple[tuple[str, ...], str, list[FaultTable]]:
    """The fixed geometry controls of ``study``, the key of its fault tables and the tables:
    a pair's ``[gears]`` and ``[[faults]]``, a planetary set's ``[params.geometry]`` and
    ``[[params.geometry.faults]]``, a gear train's ``[[train.faults]]`` (no fixed controls);
    ((), "", []) for a study without geometry."""
    if study.gears is not None:
        return GEOMETRY_KEYS, "faults", list(study.faults or [])
    if study.train is not None and study.train.faults:
        return (), "train.faults", [FaultTable(**t) for t in study.train.faults]
    table = study_model(study.study.model).geometry
    geometry = _attribute_path(study, key_path(table)) if table else None
    if geometry is not None:
        keys = tuple(k for k in PLANETARY_GEOMETRY_KEYS if k.startswith(table + "."))
        return keys, f"{table}.faults", list(geometry.faults or [])
    return (), "", []


def _attribute_path(study: Study, path: tuple[str | int, ...]) -> Any:
    """The value at the study-file key ``path`` of the validated ``study`` (None where a
    table on the way is absent)."""
    target: Any = study
    for part in path:
        target = (target.get(part) if isinstance(target, dict)
                  else getattr(target, str(part), None))
    return target


def _fault_table(study: Study, path: tuple[str | int, ...]) -> FaultTable | None:
    """The fault table of the control at ``path`` (``(..., "faults", i, field)``), None for a
    control of another table."""
    _, prefix, tables = _geometry_tables(study)
    if not prefix or path[:-2] != key_path(prefix) or not isinstance(path[-2], int):
        return None
    return tables[path[-2]] if path[-2] < len(tables) else None


class ExplorerState:
    """The explorer's view of one study.

    Parameters
    ----------
    study
        The study (:func:`geardyn.io.load_study`).
    source
        How the study was named on the command line (file or built-in name), for the reproducing
        command.
    param, window
        The swept parameter and the first window (default: the study's ``[sweep]``).
    save_dir
        Where :meth:`save` writes the view (and the study with the overrides).
    describe_error
        Turns an exception into the one-line message shown (the CLI passes its formatter).
    curves
        Two-parameter ``"curve"`` datasets (grazing, fold, period doubling) drawn over the
        diagram where they cross it (:mod:`geardyn.explore.overlay`).
    """

    def __init__(self, study: Study, source: str, param: str | None = None,
                 window: Window | None = None, *, interpretation: str | None = None,
                 continuation: str | None = None, save_dir: Path | str = Path("out/explore"),
                 describe_error: Callable[[BaseException], str] = _error_text,
                 curves: Sequence[Any] = ()):
        sweep = study.sweep
        self.study = study
        self.source = source
        self.param = param or (sweep.param if sweep is not None else "Omega")
        if window is None:
            if sweep is None or sweep.param != self.param:
                raise ParameterError("--range", None, "not given, and the study's [sweep] does "
                                     f"not sweep {self.param}")
            window = Window(float(sweep.start), float(sweep.stop), int(sweep.num))
        if window.start == window.stop or window.num < 2:
            raise ParameterError("--range", window.text, "needs START != STOP and NUM >= 2")
        self.window = window
        self.history: list[Window] = []
        self.overrides: dict[str, float | str] = {}
        self.interpretation = interpretation
        self.continuation = continuation or (sweep.continuation if sweep is not None else "none")
        self.describe_error = describe_error
        self.curves = tuple(curves)
        self.save_dir = Path(save_dir)
        from geardyn.study import study_omega

        self._effective = study
        self._model = self._build(study, interpretation)
        if self.param != "Omega" and study_omega(study, self._model) is None:
            raise ParameterError("--param", self.param, "a sweep of another parameter than "
                                 "Omega needs [run].omega in the study")

    # ------------------------------------------------------------------ model
    @property
    def kind(self) -> str:
        return self.study.study.model

    @property
    def model_kind(self) -> StudyModel:
        """What the study's model kind declares (:mod:`geardyn.io.study_models`)."""
        return study_model(self.kind)

    def main_params(self) -> tuple[str, ...]:
        """The parameters offered as controls (the model's
        :attr:`~geardyn.core.model.Model.explorer_names`; the swept one left out)."""
        offered = self.model.explorer_names
        if self.model_kind.explore_given_only:
            offered = tuple(p for p in offered if p in self.model.physical_names)
        return tuple(p for p in offered if p != self.param)

    def geometry_params(self) -> tuple[str, ...]:
        """The geometry and fault controls of a study built from geometry, as study-file keys:
        :data:`GEOMETRY_KEYS` (a ``[gears]`` table) or :data:`PLANETARY_GEOMETRY_KEYS` (a
        planetary ``[params.geometry]``), then, per fault table of the current view, its kind,
        its gear and the numeric fields of its fault class (``faults[0].kind``,
        ``faults[0].gear``, ``faults[0].depth``, ``faults[0].angle``, ``faults[0].tooth``); ()
        for a study without geometry."""
        keys, prefix, tables = _geometry_tables(self._effective)
        out = list(keys)
        for i, table in enumerate(tables):
            out += [f"{prefix}[{i}].{name}"
                    for name in ("kind", "gear", *fault_fields(table.kind))]
        return tuple(out)

    def choices(self, name: str) -> tuple[str, ...]:
        """The values a text control takes (a planetary set's stiffness method and coast flank,
        a fault's kind and gear); () for a control that takes a number."""
        path = key_path(name)
        if name not in self.geometry_params():
            return ()
        if path[-1] == "kind" and _fault_table(self._effective, path) is not None:
            return tuple(FAULT_KINDS)
        if path[-1] == "stiffness":
            return STIFFNESS_METHODS
        if path[-1] == "coast":
            return COAST_FLANKS
        if path[-1] == "gear":
            if self.study.gears is not None:
                return ("pinion", "wheel")
            if self.study.train is not None:  # the train's gears
                from geardyn.trains import Gear

                return tuple(name for name, body in self._effective.gear_train.bodies.items()
                             if isinstance(body, Gear))
            n = self.study.params.n_planets  # type: ignore[union-attr]
            return ("sun", *(f"planet{i + 1}" for i in range(n)), "ring")
        return ()

    def param_help(self, name: str) -> str:
        """What a control's parameter is (meaning and unit), from the model's declared
        coefficients (:mod:`geardyn.core.coefficients`; the gear pair's
        :data:`~geardyn.models.gear_pair_coefficients.GEAR_PAIR`), its declared physical input
        (:mod:`geardyn.core.inputs`), the units of its sweep axis, the ``[params]`` field's
        description, or, for a geometry control, its table; empty where nothing is
        declared."""
        if name in self.geometry_params():
            return self._geometry_help(name)
        layout = self.model.coefficient_layout
        if name in layout.names and layout.slot(name).coefficient.meaning:
            return layout.slot(name).coefficient.describe()
        block = self.model_kind.coefficients
        if block is not None and name in block.vocabulary():
            return block[name].describe()
        declared = {i.name: i for i in self.model.input_declarations}.get(name)
        if declared is not None:
            return declared.meaning
        units = self.model.param_attrs(name).get("units")
        if units:
            return f"[{units}]"
        declared = type(self.study.params).model_fields.get(name)
        return (declared.description or "") if declared is not None else ""

    def _geometry_help(self, key: str) -> str:
        path = key_path(key)
        kind = ("one of " + ", ".join(self.choices(key)) if self.choices(key)
                else "a whole number" if self._whole(key) else "SI number or unit string")
        table = _fault_table(self._effective, path)
        if table is not None:
            gear = table.fields().get("gear", "pinion")
            where = ".".join(str(p) for p in path[:-2])
            return f"{path[-1]} of the {table.kind} on the {gear} ([[{where}]] {path[-2]}; {kind})"
        return f"{path[-1]} ([{'.'.join(str(p) for p in path[:-1])}]; {kind})"

    def _build(self, study: Study, interpretation: str | None) -> Model:
        from geardyn.study import build_model

        model = build_model(study, interpretation=interpretation, omega=study.run.omega)
        if self.param != "Omega":
            model.lane_params(self.param, [self.window.start, self.window.stop])
        return model

    @property
    def model(self) -> Model:
        """The model of the current view (study plus overrides and interpretation)."""
        return self._model

    @property
    def effective_study(self) -> Study:
        """The study with the overrides applied (what the reproducing command runs)."""
        return self._effective

    def current_value(self, name: str) -> Any:
        """The value of a main parameter in the current view (override text, else the study's
        value in SI units)."""
        if name in self.overrides:
            return self.overrides[name]
        if name in self.geometry_params():
            return self._geometry_value(key_path(name))
        params = self._effective.params
        if self.model_kind.paper_device:  # by the paper's names
            from geardyn.models.params import PAPER_NAMES

            target: Any = self._effective.planetary_params
            for part in PAPER_NAMES[name][0]:
                target = getattr(target, part)
            return target
        value = getattr(params, name)
        return value[0] if isinstance(value, list | tuple) else value

    def _geometry_value(self, path: tuple[str | int, ...]) -> Any:
        """A geometry control's value in the current view: a fault field as its table gives
        it (else the fault class's default), a gear's value (its own, else ``[gears]``'s), a
        ``[params.geometry]`` value as the study gives it ("" where it gives none)."""
        study = self._effective
        table = _fault_table(study, path)
        if table is not None:
            name = str(path[-1])
            if name == "kind":
                return table.kind
            given = table.fields()
            if name in given:
                return given[name]
            declared = {f.name: f for f in dataclasses.fields(FAULT_KINDS[table.kind])}
            return declared[name].default
        if path[0] == "gears":
            return study.gears.value(str(path[1]), str(path[2]))[0]  # type: ignore[union-attr]
        target = _attribute_path(study, path)
        return "" if target is None else target

    def _with_overrides(self, overrides: dict[str, float | str]) -> Study:
        """The study with ``overrides`` applied, validated as a study file is (a geometry
        control's value set at its key, a parameter's in ``[params]``)."""
        doc = self.study.to_toml_dict()  # as the file says it (transient_periods alone)
        geometry = self.geometry_params()
        for key, value in overrides.items():
            path = key_path(key)
            if key in geometry and path[-1] == "kind" and value in FAULT_KINDS:
                # the table as a fault of that kind (an unknown kind: the study refuses it)
                _set_path(doc, path[:-1], switched_fault(_get_path(doc, path[:-1]), value))
            elif key in geometry:
                _set_path(doc, path, value)
        changes = {k: v for k, v in overrides.items() if k not in geometry}
        params = self.study.params
        if not self.model_kind.paper_device:  # [params] names the kind's declared inputs
            doc["params"].update(changes)
        elif is_paper_base(params):  # base = "paper", changes by the paper's names
            doc["params"]["changes"] = {**doc["params"].get("changes", {}), **changes}
        else:  # the device's PlanetaryParams in full
            doc["params"] = params.replace(**changes).model_dump(exclude_none=True)
        return Study.model_validate(doc)

    def set_override(self, name: str, text: str) -> str | None:
        """Set a main parameter or a geometry control from a control's text. Returns None, or
        the validation message (the state is then unchanged)."""
        geometry = self.geometry_params()
        if name not in self.main_params() and name not in geometry:
            return f"{name}: not a parameter of this explorer"
        value: float | str = text.strip() if self.choices(name) else parse_value(text)
        if name in geometry and isinstance(value, float) and value.is_integer() and (
                self._whole(name)):
            value = int(value)  # a tooth index: 3, not 3.0
        overrides = {**self.overrides, name: value}
        path = key_path(name)
        if name in geometry and path[-1] == "kind" and value in FAULT_KINDS:
            # the old fault's size goes with it; where it sits stays
            table = ".".join(name.split(".")[:-1]) + "."
            keep = {"kind", *PLACEMENT_FIELDS}
            overrides = {k: v for k, v in overrides.items()
                         if not k.startswith(table) or k.rpartition(".")[2] in keep}
        return self._apply(overrides, self.interpretation)

    def _whole(self, key: str) -> bool:
        """True where the geometry control ``key`` is an int field of its fault class."""
        path = key_path(key)
        table = _fault_table(self._effective, path)
        if table is None:
            return False
        return typing.get_type_hints(FAULT_KINDS[table.kind]).get(str(path[-1])) is int

    def set_interpretation(self, value: str) -> str | None:
        """Change the interpretation (CATT device studies only); None or the message."""
        if not self.model_kind.paper_device:
            return f"interpretation: a {self.kind} study has none"
        if value not in INTERPRETATIONS:
            return f"interpretation: must be one of {', '.join(INTERPRETATIONS)} (got {value!r})"
        return self._apply(self.overrides, value)

    def set_continuation(self, value: str) -> str | None:
        try:
            self.continuation = check_continuation(value)
        except ParameterError as err:
            return str(err)
        return None

    def _apply(self, overrides: dict[str, float | str], interpretation: str | None
               ) -> str | None:
        try:
            study = self._with_overrides(overrides)
            model = self._build(study, interpretation)
        except Exception as exc:  # every refusal is shown, the state kept
            return self.describe_error(exc)
        self.overrides, self.interpretation = overrides, interpretation
        self._effective, self._model = study, model
        return None

    # ------------------------------------------------------------------ window
    def zoom(self, start: float, stop: float) -> str | None:
        """Move to the window [start, stop] (same number of points); the current one goes on the
        history. None, or why not (the state is then unchanged)."""
        lo, hi = sorted((float(start), float(stop)))
        if not (math.isfinite(lo) and math.isfinite(hi)) or lo == hi:
            return f"window: needs two different finite ends (got {start!r}, {stop!r})"
        lo, hi = _rounded(lo, hi)
        if self.param == "Omega" and not usable_omega(lo):
            return f"window: Omega {OMEGA_RULE} (got {lo:g})"
        new = Window(lo, hi, self.window.num)
        if self.param != "Omega":
            try:
                self._model.lane_params(self.param, [lo, hi])
            except Exception as exc:
                return self.describe_error(exc)
        if new != self.window:
            self.history.append(self.window)
            self.window = new
        return None

    def back(self) -> bool:
        """Return to the previous window; False when there is none."""
        if not self.history:
            return False
        self.window = self.history.pop()
        return True

    # ------------------------------------------------------------------ requests
    def run_settings(self):
        """The run of the current view's sweep (``[run]`` as every command reads it; a
        ``transient_periods`` counts periods of the window's lowest Omega, also where the swept
        parameter is a speed that sets Omega)."""
        from geardyn.analysis.bifurcation import lane_params_held

        model = self._model
        ends = [self.window.start, self.window.stop]
        if self.param == "Omega" or model.omega_index is None:
            low = min(ends) if self.param == "Omega" else model.omega
        else:  # a speed sweep moves Omega: the window's lowest
            low = float(min(lane_params_held(model, self.param, ends, "Omega")
                            [:, model.omega_index]))
        return self._effective.run_settings(sweep=True, omega=low)

    def diagram_request(self) -> DiagramRequest:
        """The computation of the current view's diagram."""
        return DiagramRequest(
            model=self._model, param=self.param, window=self.window, run=self.run_settings(),
            continuation=self.continuation, plot_state=self._effective.plot_state,
            attrs={"study": self.study.study.name, "plot_state": self._effective.plot_state,
                   "command": self.command()},
            view={"window": self.window, "overrides": dict(self.overrides),
                  "interpretation": self.interpretation, "continuation": self.continuation,
                  "effective": self._effective, "model": self._model})

    def restore(self, request: DiagramRequest) -> None:
        """Return to the view of ``request`` (the last good one, after a computation failed):
        its window (dropping a history entry that repeats it), parameters and settings."""
        v = request.view
        if not v:
            return
        if self.window != v["window"] and self.history and self.history[-1] == v["window"]:
            self.history.pop()
        self.window = v["window"]
        self.overrides, self.interpretation = dict(v["overrides"]), v["interpretation"]
        self.continuation = v["continuation"]
        self._effective, self._model = v["effective"], v["model"]

    def nearest_value(self, x: float) -> float:
        """The window's parameter value nearest to ``x``."""
        values = self.window.values()
        return float(values[int(np.argmin(np.abs(values - x)))])

    # ------------------------------------------------------------------ reproduce, save
    def command(self, out: Path | str | None = None, plot: Path | str | None = None,
                study_file: Path | str | None = None) -> str:
        """The ``geardyn bifurcation`` command line that computes the current view. With
        overrides it names ``study_file`` (the study with them, which :meth:`save` writes)."""
        source = str(study_file) if study_file is not None else self.source
        if self.overrides and study_file is None:
            source = str(self.study_file())
        args = ["geardyn", "bifurcation", source, "--param", self.param,
                "--range", self.window.text, "--continuation", self.continuation]
        if self.interpretation is not None:
            args += ["--interpretation", self.interpretation]
        if out is not None:
            args += ["--out", str(out)]
        if plot is not None:
            args += ["--plot", str(plot)]
        return shlex.join(args)

    def study_file(self) -> Path:
        """Where :meth:`save` writes the study with the overrides."""
        return self.save_dir / f"{self.study.study.name}-explore.toml"

    def file_stem(self) -> str:
        w = self.window
        return f"{self.study.study.name}_{self.param}_{w.start:.6g}-{w.stop:.6g}_{w.num}"

    def save(self, ds: Any, directory: Path | str | None = None) -> list[Path]:
        """Write the view ``ds`` (the current diagram) to ``directory`` (default
        :attr:`save_dir`) as NetCDF and PNG, the files ``geardyn bifurcation --out --plot``
        writes, plus the study with the overrides (when there are any) and the command line;
        returns the paths written."""
        from geardyn.io.netcdf import save_dataset
        from geardyn.io.toml import save_study
        from geardyn.plotting.bifurcation import plot_bifurcation

        directory = self.save_dir if directory is None else Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        stem = self.file_stem()
        nc, png = directory / f"{stem}.nc", directory / f"{stem}.png"
        written = []
        study_file = None
        if self.overrides:
            study_file = directory / self.study_file().name
            save_study(self._effective, study_file)
            written.append(study_file)
        command = self.command(out=nc, plot=png, study_file=study_file)
        ds = ds.copy()
        ds.attrs.update(study=self.study.study.name, plot_state=self._effective.plot_state,
                        command=command)
        save_dataset(ds, nc)
        plot_bifurcation(ds, state=self._effective.plot_state, path=png)
        cmd = directory / f"{stem}.command.txt"
        cmd.write_text(command + "\n", encoding="utf-8")
        return [*written, nc, png, cmd]

    def snapshot(self) -> dict[str, Any]:
        """The view as plain data (for display and tests)."""
        return {"param": self.param, "window": replace(self.window),
                "history": list(self.history), "overrides": dict(self.overrides),
                "interpretation": self.interpretation, "continuation": self.continuation}
