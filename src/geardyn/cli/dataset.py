"""``geardyn dataset``: labelled fault data of a study, written to a Zarr store.

::

    geardyn dataset STUDY.toml [--store faults.zarr] [--workers N] [--chunk N] [--quiet]

The conditions come from the study's ``[dataset]`` table (:class:`geardyn.io.dataset_table.
DatasetTable`): ``[[dataset.faults]]`` (``kind = "healthy"`` or a fault of the study's gears),
speeds (in the study model's speed unit: a spur pair's ``params.speed_unit``, a planetary set's
or a train's input speed in rpm), torques [N m], seeds, signal length, sample rate, noise,
step, sensor settings. The model is the study's (:data:`STUDY_FAULTS`: a ``spur_pair``, a
``planetary`` set built from ``[params.geometry]`` or a ``train``, the study models that declare
a ``dataset``, :data:`geardyn.io.study_models.STUDY_MODELS`) with each condition's fault in
place of the study's own faults (:func:`geardyn.study.faulted_model`). A rerun with the same
study resumes from the store (the chunks it holds are read back, not computed again). A
progress bar is drawn when stderr is a terminal.
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from pydantic import ValidationError
from rich.markup import escape

from geardyn.cli.common import QuietOption, load_study_source, make_parents
from geardyn.errors import ParameterError, StudyError
from geardyn.io.study_models import STUDY_MODELS, StudyModel

__all__ = ["STUDY_FAULTS", "StudyFaultBuilder", "dataset_command", "fault_conditions",
           "register"]

#: The studies ``geardyn dataset`` takes: model -> the table of the study's own faults, which
#: each condition's fault replaces (``StudyModel.dataset``).
STUDY_FAULTS = {k: m.dataset.table for k, m in STUDY_MODELS.items() if m.dataset is not None}


def _kind(study: Any) -> StudyModel:
    """The study's model kind (``[study].model``), if ``geardyn dataset`` takes it; else a
    StudyError."""
    kind = STUDY_MODELS[study.study.model]
    if kind.dataset is None:
        *head, last = STUDY_FAULTS
        raise StudyError(f"study {study.study.name!r}: geardyn dataset takes a "
                         f"{', '.join(head)} or {last} study (model = {kind.name!r})")
    target: Any = study
    for part in kind.dataset.needs.split(".") if kind.dataset.needs else ():
        target = getattr(target, part)
    if target is None:
        raise StudyError(f"study {study.study.name!r}: {kind.dataset.refusal}")
    return kind


class StudyFaultBuilder:
    """``faults -> model``: the study's model with ``faults`` (at most one fault object of
    ``conditions``, the conditions' own) in place of the study's faults (:data:`STUDY_FAULTS`)."""

    def __init__(self, study: Any, conditions: list[tuple[Any, dict[str, Any] | None]]):
        self.study = study
        self.kind = _kind(study).name
        self.tables = {id(f): t for f, t in conditions if f is not None}
        self._built: dict[str, Any] = {}

    def __call__(self, faults: tuple[Any, ...]) -> Any:
        return self.model([self.tables[id(f)] for f in faults])

    def model(self, tables: list[dict[str, Any]]) -> Any:
        """The study's model with the fault tables ``tables`` (``[]``: healthy), built once
        (:func:`fault_conditions` builds a planetary set's or a train's to check the fault)."""
        key = repr(tables)
        if key not in self._built:
            self._built[key] = self._model(tables)
        return self._built[key]

    def _model(self, tables: list[dict[str, Any]]) -> Any:
        from geardyn.study import faulted_model

        return faulted_model(self.study, tables)


def _spur_pair_check(study: Any, table: dict[str, Any], where: tuple) -> None:
    """The fault ``table`` against the pair's gears (its stiffness inputs)."""
    from geardyn.io._tables import study_error
    from geardyn.io.toml import FaultTable

    try:
        study.model_copy(update={"faults": [FaultTable(**table)]}).stiffness_inputs()
    except ValidationError as exc:
        err = exc.errors(include_url=False)[0]
        raise study_error(where + tuple(err["loc"][2:]), err.get("input"),
                          str(err["msg"]).removeprefix("Value error, ")) from None


#: The field a planetary set or a train names for its one fault (the study's fault table).
_OWN_FAULT = re.compile(r"^(params\.geometry\.|train\.)faults\[0\]")


def _built_check(builder: StudyFaultBuilder, table: dict[str, Any], where: tuple) -> None:
    """The model with the fault ``table`` built (a planetary set, a train): what it refuses
    in the fault names ``where`` and the field."""
    from geardyn.io._tables import study_error

    try:
        builder.model([table])
    except ParameterError as exc:
        if not _OWN_FAULT.match(exc.field):
            raise
        rest = _OWN_FAULT.sub("", exc.field).lstrip(".")
        raise study_error(where + ((rest,) if rest else ()), exc.value, exc.reason) from None
    except ValidationError as exc:
        err = exc.errors(include_url=False)[0]
        loc = tuple(err["loc"])
        if loc[:3] != ("train", "faults", 0):
            raise
        raise study_error(where + loc[3:], err.get("input"),
                          str(err["msg"]).removeprefix("Value error, ")) from None


def fault_conditions(study: Any, builder: StudyFaultBuilder | None = None
                     ) -> list[tuple[Any, dict[str, Any] | None]]:
    """(fault object or None, its table) of every ``[[dataset.faults]]``, each built and
    checked against the study's gears (a planetary set's or a train's model built by
    ``builder``, which keeps it); an error names ``dataset.faults[<i>].<field>``."""
    from geardyn.io.dataset_table import HEALTHY
    from geardyn.io.toml import FaultTable

    builder = builder if builder is not None else StudyFaultBuilder(study, [])
    out: list[tuple[Any, dict[str, Any] | None]] = []
    for i, table in enumerate(study.dataset.faults):
        where = ("dataset", "faults", i)
        if table["kind"] == HEALTHY:
            out.append((None, None))
            continue
        fault = FaultTable(**table).build(where)
        if STUDY_MODELS[builder.kind].dataset.check == "gears":  # type: ignore[union-attr]
            _spur_pair_check(study, table, where)
        else:
            _built_check(builder, table, where)
        out.append((fault, table))
    return out


#: Sensor settings that are angles (numbers in rad or unit strings such as "90 deg").
_ANGLES = ("sensor_angle", "width")


def _sensor(settings: dict[str, Any]) -> dict[str, Any]:
    """``[dataset].sensor`` with its angles in rad."""
    from geardyn.units import si_value

    return {k: si_value(f"sensor.{k}", v, "angle") if k in _ANGLES and isinstance(v, str)
            else v for k, v in settings.items()}


def dataset_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    store: Annotated[Path | None, typer.Option(
        help="The Zarr store to write or resume (default: dataset.store).")] = None,
    workers: Annotated[int | None, typer.Option(
        help="Local processes (default: dataset.workers, else every core).")] = None,
    chunk: Annotated[int | None, typer.Option(
        help="Conditions per chunk (default: dataset.chunk, else about 20 per process).")
    ] = None,
    quiet: QuietOption = False,
) -> None:
    """Labelled fault data: the study's model (a spur pair, a planetary set built from
    geometry, a gear train) over [dataset]'s faults x speeds x torques x noise seeds, the
    sensor signals (white noise added) and their labels in a chunked Zarr store that
    xarray.open_zarr opens; a rerun resumes."""
    from geardyn.analysis.fault_dataset import FaultDatasetSpec, fault_dataset
    from geardyn.cli.bifurcation import _progress_bar, _stderr_is_terminal

    s = load_study_source(study)
    table = s.dataset
    if table is None:
        raise StudyError(f"study {s.study.name!r} has no [dataset] table")
    _kind(s)
    path = store if store is not None else (Path(table.store) if table.store else None)
    if path is None:
        raise ParameterError("--store", None, "not given, and dataset has no store")
    for option, value in (("--workers", workers), ("--chunk", chunk)):
        if value is not None and value < 1:
            raise ParameterError(option, value, "must be a whole number >= 1")
    builder = StudyFaultBuilder(s, [])
    conditions = fault_conditions(s, builder)
    builder.tables = {id(f): t for f, t in conditions if f is not None}
    try:
        spec = FaultDatasetSpec(
            builder, [f for f, _ in conditions], speeds=table.speeds,
            torques=table.torques, seeds=table.seed_list(), snr_db=table.snr(),
            duration=table.duration, sample_rate=table.sample_rate, transient=table.transient,
            steps_per_period=table.steps_per_period, steps_per_mode=table.steps_per_mode,
            chunk=chunk if chunk is not None else table.chunk, sensor=_sensor(table.sensor))
    except ParameterError as exc:
        raise ParameterError(f"dataset.{exc.field}", exc.value, exc.reason) from None
    make_parents(path)
    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _progress_bar(show_bar, escape(f"{s.study.name}: dataset")) as callback:
        try:
            ds = fault_dataset(spec, store=path, progress=callback,
                               workers=workers if workers is not None else table.workers)
        except ParameterError as exc:  # checked before any work: the table's fields
            if exc.field == "build":  # the study's model lacks an input or its signal
                raise StudyError(f"study {s.study.name!r}: its model ({exc.value}) "
                                 f"{exc.reason.removeprefix('returns a model that ')}") from None
            if not exc.field.startswith(("sensor", "faults[")):
                raise
            raise ParameterError(f"dataset.{exc.field}", exc.value, exc.reason) from None
    elapsed = time.perf_counter() - t0
    typer.echo(f"{s.study.name}: {ds.attrs['n_conditions']} conditions, "
               f"{ds.attrs['n_signals']} signals of {spec.duration:g} s at "
               f"{spec.sample_rate:g} Hz, diverged {ds.attrs['diverged']}, {elapsed:.1f} s; "
               f"wrote {path}")


def register(app: typer.Typer) -> None:
    """Add ``geardyn dataset`` to the command line ``app``."""
    app.command("dataset")(dataset_command)
