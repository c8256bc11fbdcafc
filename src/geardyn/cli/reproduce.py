"""``geardyn reproduce``: the seed paper's figure cases, swept up and down, and the claims report.

::

    geardyn reproduce fig3 [--interpretation ...] [--resolution N] [--out out/reproduce]
    geardyn reproduce --all [--interpretation consistent|carrier-only|as-printed|all]
                      [--resolution N] [--transient T] [--samples S] [--jobs N]
                      [--out out/reproduce] [--verdicts docs/reproduction-verdicts.md]
                      [--no-figures] [--basins N]

Writes, under ``--out``, ``CASE-INTERPRETATION.nc`` (data), ``CASE-INTERPRETATION.png`` and
``...-down.png`` (the diagrams swept up and down), ``report.md``, a self-contained
``report.html`` and ``verdicts.md`` (every claim's verdict per interpretation; ``--verdicts``
writes it to another path too); with ``--basins N`` also ``basins-CASE-INTERPRETATION.nc|png``
(the basins of attraction where a case's sweeps disagree while periodic, see
:mod:`geardyn.reproduction.basins`). See ``docs/reproduction.md``.
"""

from __future__ import annotations

import contextlib
import shutil
import time
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from geardyn.cli.common import (
    QuietOption,
    run_option,
    run_options,
    settings_from_options,
    stderr_console,
)
from geardyn.errors import ParameterError

__all__ = ["register", "reproduce_command"]


class InterpretationChoice(StrEnum):
    consistent = "consistent"
    carrier_only = "carrier-only"
    as_printed = "as-printed"
    all = "all"


@contextlib.contextmanager
def _progress(show: bool):
    """A rich progress bar on stderr fed by ``callback(stage, done, total)``."""
    if not show:
        yield None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn())
    with Progress(*columns, console=stderr_console(), transient=True) as bar:
        task = bar.add_task("starting (the first run compiles)", total=None)

        def callback(stage: str, done: int, total: int) -> None:
            bar.update(task, description=stage, completed=done, total=total)

        yield callback


def reproduce_command(
    case: Annotated[str | None, typer.Argument(
        help="A figure case: fig3 ... fig14, fig15a ... fig15d (or give --all).")] = None,
    all_cases: Annotated[bool, typer.Option("--all", help="Run every figure case.")] = False,
    interpretation: Annotated[InterpretationChoice, typer.Option(
        help="How to read the paper's ambiguous formulas, or all three.")] = (
        InterpretationChoice.consistent),
    resolution: Annotated[int | None, typer.Option(
        help="Omega points per sweep (default: the study's, the paper's resolution).")] = None,
    transient: run_option("transient", "the longest per point: each point stops earlier once "
                           "its Poincare point settles; default: the study's") = None,
    samples: run_option("samples", "mesh periods; default: the study's") = None,
    jobs: Annotated[int | None, typer.Option(
        help="Worker processes, each continuing its share of the sweeps with one thread, then "
        "drawing its share of the figures "
        "(default: one per core; 1: all sweeps together in this process, on every core).")] = None,
    out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out/reproduce"),
    verdicts: Annotated[Path | None, typer.Option(
        help="Also write the verdict table (verdicts.md) to this file, e.g. "
        "docs/reproduction-verdicts.md (with --all --interpretation all).")] = None,
    figures: Annotated[bool, typer.Option(
        "--figures/--no-figures", help="Draw the diagrams (PNG, embedded in report.html); "
        "without them only the data, the report and the verdict table are written.")] = True,
    basins: Annotated[int, typer.Option(
        help="Also the basins of attraction (N x N initial conditions) where a case's up and "
             "down sweeps disagree while periodic (0: none).")] = 0,
    quiet: QuietOption = False,
) -> None:
    """Recompute the paper's bifurcation diagrams (swept up and down) and write a report that
    checks every claim of the paper against the data."""
    import os
    import sys

    from geardyn.models.derived import INTERPRETATIONS
    from geardyn.reproduction import (
        ReproductionSettings,
        evaluate,
        get_case,
        paper_cases,
        run_cases,
        write_report,
    )
    from geardyn.reproduction.runner import worker_pool

    if all_cases == (case is not None):
        raise ParameterError("CASE", case, "give one figure case or --all, not both or neither")
    cases = paper_cases() if all_cases else [get_case(case)]  # type: ignore[arg-type]
    interps = (list(INTERPRETATIONS) if interpretation == InterpretationChoice.all
               else [interpretation.value])
    if not 0 <= basins <= 1000:
        raise ParameterError("--basins", basins, "must be a grid size in 0..1000")
    if jobs is not None and jobs < 1:
        raise ParameterError("--jobs", jobs, "must be >= 1")
    workers = jobs or os.cpu_count() or 1
    settings = settings_from_options(ReproductionSettings, {
        "num": ("--resolution", resolution), **run_options(transient=transient, samples=samples)})
    out.mkdir(parents=True, exist_ok=True)

    with worker_pool(workers) as pool:  # the sweeps' processes then write the case files
        start = time.perf_counter()
        with _progress(not quiet and sys.stderr.isatty()) as callback:
            results = run_cases(cases, interps, settings, callback, workers=workers, pool=pool)
        swept = time.perf_counter() - start
        command = "geardyn reproduce " + ("--all" if all_cases else cases[0].name) + (
            f" --interpretation {interpretation.value}"
            + (f" --resolution {resolution}" if resolution else "")
            + (f" --transient {transient:g}" if transient is not None else "")
            + (f" --samples {samples}" if samples else "")
            + (f" --basins {basins}" if basins else "")
            + (f" --verdicts {verdicts}" if verdicts is not None else ""))
        with stderr_console().status("writing figures, data and the report"
                                     + (" (and the basins of attraction)" if basins else "")):
            paths = write_report(results, out, command=command, figures=figures,
                                 basins=basins, jobs=workers, pool=pool)
    for interp in interps:
        found = evaluate({c: ds for (c, i), ds in results.items() if i == interp})
        counts: dict[str, int] = {}
        for v in found.values():
            counts[v.status] = counts.get(v.status, 0) + 1
        typer.echo(f"{interp}: " + ", ".join(f"{n} {s}" for s, n in counts.items()))
    written = [paths["markdown"], paths["html"], paths["verdicts"]]
    if verdicts is not None:
        verdicts.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(paths["verdicts"], verdicts)
        written.append(verdicts)
    typer.echo(f"{len(results)} case results in {swept:.1f} s ({workers} processes); wrote "
               + ", ".join(str(p) for p in written))


def register(app: typer.Typer) -> None:
    """Add ``geardyn reproduce`` to the command line ``app``."""
    app.command("reproduce")(reproduce_command)
