"""``geardyn dataset``: labelled fault data of a spur-pair study, written to a Zarr store.

::

    geardyn dataset STUDY.toml [--store faults.zarr] [--workers N] [--chunk N] [--quiet]

The conditions come from the study's ``[dataset]`` table (:class:`geardyn.io.dataset_table.
DatasetTable`): ``[[dataset.faults]]`` (``kind = "healthy"`` or a fault of the study's gears),
speeds (in ``params.speed_unit``), torques [N m], seeds, signal length, sample rate, noise,
step; the model is the study's ``spur_pair`` with each fault in place of its
``[[faults]]``. A rerun with the same study resumes from the store (the chunks it holds are read
back, not computed again). A progress bar is drawn when stderr is a terminal.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Any

import typer
from pydantic import ValidationError
from rich.markup import escape

from geardyn.cli.common import load_study_source, make_parents
from geardyn.errors import ParameterError, StudyError

__all__ = ["StudyFaultBuilder", "dataset_command", "register"]


class StudyFaultBuilder:
    """``faults -> SpurPair``: the study's model with ``faults`` (at most one fault object of
    ``tables``, the conditions' own) in place of its ``[[faults]]``."""

    def __init__(self, study: Any, conditions: list[tuple[Any, dict[str, Any] | None]]):
        self.study = study
        self.tables = {id(f): t for f, t in conditions if f is not None}

    def __call__(self, faults: tuple[Any, ...]) -> Any:
        from geardyn.io.toml import FaultTable
        from geardyn.study import spur_pair_model

        tables = [FaultTable(**self.tables[id(f)]) for f in faults]
        return spur_pair_model(self.study.model_copy(update={"faults": tables or None}))


def fault_conditions(study: Any) -> list[tuple[Any, dict[str, Any] | None]]:
    """(fault object or None, its table) of every ``[[dataset.faults]]``, each built and
    checked against the study's gears; an error names ``dataset.faults[<i>].<field>``."""
    from geardyn.io._tables import study_error
    from geardyn.io.dataset_table import HEALTHY
    from geardyn.io.toml import FaultTable

    out: list[tuple[Any, dict[str, Any] | None]] = []
    for i, table in enumerate(study.dataset.faults):
        where = ("dataset", "faults", i)
        if table["kind"] == HEALTHY:
            out.append((None, None))
            continue
        fault = FaultTable(**table).build(where)
        try:
            study.model_copy(update={"faults": [FaultTable(**table)]}).stiffness_inputs()
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            raise study_error(where + tuple(err["loc"][2:]), err.get("input"),
                              str(err["msg"]).removeprefix("Value error, ")) from None
        out.append((fault, table))
    return out


def dataset_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    store: Annotated[Path | None, typer.Option(
        help="The Zarr store to write or resume (default: dataset.store).")] = None,
    workers: Annotated[int | None, typer.Option(
        help="Local processes (default: dataset.workers, else every core).")] = None,
    chunk: Annotated[int | None, typer.Option(
        help="Conditions per chunk (default: dataset.chunk, else about 20 per process).")
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Labelled fault data: the study's spur pair over [dataset]'s faults x speeds x torques x
    noise seeds, the sensor signals (the mesh force with white noise) and their labels in a
    chunked Zarr store that xarray.open_zarr opens; a rerun resumes."""
    from geardyn.analysis.fault_dataset import FaultDatasetSpec, fault_dataset
    from geardyn.cli.bifurcation import _progress_bar, _stderr_is_terminal
    from geardyn.io.toml import SpurPairParams

    s = load_study_source(study)
    table = s.dataset
    if table is None:
        raise StudyError(f"study {s.study.name!r} has no [dataset] table")
    if not isinstance(s.params, SpurPairParams):
        raise StudyError(f"study {s.study.name!r}: geardyn dataset takes a spur_pair study "
                         f"(model = {s.study.model!r})")
    path = store if store is not None else (Path(table.store) if table.store else None)
    if path is None:
        raise ParameterError("--store", None, "not given, and dataset has no store")
    for option, value in (("--workers", workers), ("--chunk", chunk)):
        if value is not None and value < 1:
            raise ParameterError(option, value, "must be a whole number >= 1")
    conditions = fault_conditions(s)
    try:
        spec = FaultDatasetSpec(
            StudyFaultBuilder(s, conditions), [f for f, _ in conditions], speeds=table.speeds,
            torques=table.torques, seeds=table.seed_list(), snr_db=table.snr(),
            duration=table.duration, sample_rate=table.sample_rate, transient=table.transient,
            steps_per_period=table.steps_per_period, steps_per_mode=table.steps_per_mode,
            chunk=chunk if chunk is not None else table.chunk)
    except ParameterError as exc:
        raise ParameterError(f"dataset.{exc.field}", exc.value, exc.reason) from None
    make_parents(path)
    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _progress_bar(show_bar, escape(f"{s.study.name}: dataset")) as callback:
        ds = fault_dataset(spec, store=path, progress=callback,
                           workers=workers if workers is not None else table.workers)
    elapsed = time.perf_counter() - t0
    typer.echo(f"{s.study.name}: {ds.attrs['n_conditions']} conditions, "
               f"{ds.attrs['n_signals']} signals of {spec.duration:g} s at "
               f"{spec.sample_rate:g} Hz, diverged {ds.attrs['diverged']}, {elapsed:.1f} s; "
               f"wrote {path}")


def register(app: typer.Typer) -> None:
    """Add ``geardyn dataset`` to the command line ``app``."""
    app.command("dataset")(dataset_command)
