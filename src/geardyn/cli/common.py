"""What every ``geardyn`` command shares: how a STUDY argument is read, the interpretation choice,
figure suffixes, and the rule that an expected error is one line on stderr with exit status 2.

This module imports nothing heavy (no numpy, numba or matplotlib), so ``geardyn --help`` stays
fast; command modules import it instead of :mod:`geardyn.cli.main`.
"""

from __future__ import annotations

import os
import sys
import tomllib
import warnings
from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer
from pydantic import ValidationError
from rich.console import Console
from typer.core import TyperGroup

from geardyn.errors import GeardynError, ParameterError

EXIT_ERROR = 2
#: Exceptions that are the user's input, not a bug: one line on stderr, exit status 2.
EXPECTED_ERRORS: tuple[type[BaseException], ...] = (
    ValidationError,
    GeardynError,
    ValueError,
    KeyError,
    OSError,
    tomllib.TOMLDecodeError,
)
PLOT_SUFFIXES = (".png", ".pdf", ".svg")
#: A run whose estimated memory exceeds this fraction of the machine's memory is refused.
MEMORY_FRACTION = 0.5
#: A run whose estimated run time exceeds this is refused (seconds).
TIME_LIMIT_S = 3600.0
#: Values of Omega a run's cost is estimated from (an Omega axis or range subsampled).
ESTIMATE_POINTS = 257
#: The largest count an option takes (grid points, samples, steps): 2**53, beyond which a float
#: no longer holds every whole number (and far beyond anything that could run).
MAX_COUNT = 2**53


class Interpretation(StrEnum):
    consistent = "consistent"
    carrier_only = "carrier-only"
    as_printed = "as-printed"


def option_name(field: str) -> str:
    """The command-line option of a settings field: ``--`` and its name with dashes."""
    return "--" + field.replace("_", "-")


def settings_option(kind: type, field: str, default: str, option: str | None = None) -> Any:
    """The typer option of the settings dataclass ``kind``'s ``field``, generated from it: named
    :func:`option_name` (or ``option``), its type the field's (None: unset, the study's or the
    settings' default applies), its help the field's ``help`` metadata and ``default`` (what
    applies when the option is not given, which the command decides)."""
    import dataclasses
    import typing

    f = next((f for f in dataclasses.fields(kind) if f.name == field), None)
    if f is None or "help" not in f.metadata:
        raise KeyError(f"{kind.__name__}.{field} has no command-line help")
    hint = typing.get_type_hints(kind)[field]
    base = next(t for t in (typing.get_args(hint) or (hint,)) if t is not type(None))
    return Annotated[base | None, typer.Option(option or option_name(field),
                                               help=f"{f.metadata['help']} ({default}).")]


def named_options(kind: type, **values: Any) -> dict[str, tuple[str, Any]]:
    """The ``options`` of :func:`settings_from_options` (field -> (option name, value)) for
    values of the options :func:`settings_option` generates from ``kind``'s fields: each named
    :func:`option_name` of its field, as the option itself is. A field without command-line
    help is a ``KeyError`` naming it."""
    import dataclasses

    fields = {f.name for f in dataclasses.fields(kind) if "help" in f.metadata}
    unknown = sorted(set(values) - fields)
    if unknown:
        raise KeyError(f"{kind.__name__} has no command-line field {', '.join(unknown)}")
    return {field: (option_name(field), value) for field, value in values.items()}


def run_options(**values: Any) -> dict[str, tuple[str, Any]]:
    """:func:`named_options` of :class:`~geardyn.RunSettings`: the run settings a command got
    as the options :func:`run_option` declares, e.g. ``run_options(transient=transient)``."""
    from geardyn.core.settings import RunSettings

    return named_options(RunSettings, **values)


def run_option(field: str, default: str, option: str | None = None) -> Any:
    from geardyn.core.settings import RunSettings

    return settings_option(RunSettings, field, default, option)


def runup_option(field: str, default: str) -> Any:
    from geardyn.analysis.runup import RunupSettings

    return settings_option(RunupSettings, field, default)


def continuation_option(field: str, default: str) -> Any:
    from geardyn.core.settings import ContinuationSettings

    return settings_option(ContinuationSettings, field, default)


# Options that several commands share, declared once; the settings options are generated from
# the settings' fields (see settings_option).
InterpretationOption = Annotated[
    Interpretation | None, typer.Option(help="Interpretation (default: the study's).")
]
StepsOption = run_option("steps_per_period", "default: automatic")
TransientOption = run_option("transient", "default: run.transient or run.transient_periods")
SamplesOption = run_option("samples", "default: sweep.samples, else run.periods")
ConvergeOption = run_option("converge", "default: run.converge")
ContinuedTransientOption = run_option("continued_transient", "default: --transient")
MaxPointsOption = continuation_option("max_points", "default 2000")
MaxPeriodOption = continuation_option("max_period", "default 16")
YesOption = Annotated[
    bool, typer.Option("--yes", help="Run even when the estimated memory or time exceeds the "
                                      "limits.")
]
QuietOption = Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")]
NetCDFOutOption = Annotated[Path | None, typer.Option(help="NetCDF file to write (.nc).")]
PlotOption = Annotated[Path | None, typer.Option(help="Figure to write (.png, .pdf or .svg).")]


def load_study_source(source: str | None, *, model: bool = True):
    """A study from a file, a built-in study name, or (None) the paper's device; with ``model``
    (the commands that run one) a study of gears alone is refused before any option is read."""
    from geardyn.io.toml import builtin_study, builtin_study_names, load_study, paper_study
    from geardyn.study import require_model

    if source is None:
        return paper_study()
    if "\x00" in source or not source.strip():
        raise ParameterError("STUDY", source, "not a file name or built-in study name")
    path = Path(source)
    if path.exists() or path.suffix == ".toml" or "/" in source:
        study = load_study(path)
    elif source in builtin_study_names():
        study = builtin_study(source)
    else:
        raise FileNotFoundError(2, "No such file or built-in study", source)
    if model:
        require_model(study)
    return study


def stderr_console() -> Console:
    return Console(stderr=True)


def check_plot_path(option: str, path: Path | None) -> None:
    """A figure path must end in one of :data:`PLOT_SUFFIXES`."""
    if path is not None and path.suffix.lower() not in PLOT_SUFFIXES:
        raise ParameterError(option, str(path), f"suffix must be one of {PLOT_SUFFIXES}")


def continuation_option(help: str) -> Any:
    """``--continuation``: its choices are :data:`geardyn.core.settings.SWEEP_CONTINUATIONS`,
    checked in the command by :func:`check_continuation` (the rule of every entry point)."""
    from geardyn.core.settings import SWEEP_CONTINUATIONS

    return typer.Option("--continuation", metavar="[" + "|".join(SWEEP_CONTINUATIONS) + "]",
                        help=help)


def check_continuation(value: str | None) -> str | None:
    """``--continuation``'s value (None: not given), refused as every entry point refuses it
    (:func:`geardyn.core.settings.check_continuation`)."""
    from geardyn.core.settings import check_continuation as rule

    return None if value is None else rule(value, "--continuation")


def run_settings(options: dict[str, tuple[str, Any]]):
    """The :class:`~geardyn.RunSettings` of command-line options alone (see
    :func:`settings_from_options`); a command that reads a study takes
    :func:`study_run_settings`."""
    from geardyn.core.settings import RunSettings

    return settings_from_options(RunSettings, options)


def study_run_settings(study, options: dict[str, tuple[str, Any]], *, sweep: bool = False,
                       omega: float | Callable[[], float | None] | None = None,
                       defaults: dict[str, Any] | None = None,
                       least: dict[str, tuple[int, str]] | None = None):
    """The :class:`~geardyn.RunSettings` of a command that runs a study: every field from the
    command-line ``options`` (field -> (option name, value or None)), else the study's
    ``[run]`` table, else the command's ``defaults``, as
    :meth:`geardyn.io.toml.Study.run_settings` reads them (``sweep``, ``omega``: there). An
    invalid value is a one-line error naming the option or the study key it came from; so is a
    value below what the command needs (``least``: field -> (least value, why), e.g. a period
    classification's two samples)."""
    run = study.run_settings(sweep=sweep, omega=omega, given=options, defaults=defaults)
    for field, (minimum, why) in (least or {}).items():
        value = getattr(run, field)
        if value < minimum:
            sources = study.run_sources(options, sweep=sweep, omega=omega, defaults=defaults)
            where = sources.get(field, (field, value))[0]
            raise ParameterError(where, value, f"must be >= {minimum}" + (f" ({why})" * bool(why)))
    return run


def settings_from_options(kind: type, options: dict[str, tuple[str, Any]]):
    """The ``kind`` settings of a command, built once from ``options`` (field -> (option name,
    value); ``None`` values take the default); an invalid value is a one-line
    :class:`ParameterError` naming the option
    (:func:`geardyn.core.settings.settings_from_named`)."""
    from geardyn.core.settings import settings_from_named

    return settings_from_named(kind, options)


def check_count(option: str, value: int) -> None:
    """A one-line error naming ``option`` when ``value`` exceeds :data:`MAX_COUNT`."""
    if value > MAX_COUNT:
        raise ParameterError(option, value, f"must be at most 2**53 = {MAX_COUNT}")


def memory_limit() -> float:
    """Bytes a run may take: :data:`MEMORY_FRACTION` of this machine's memory."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        total = 8 * 2**30
    return MEMORY_FRACTION * total


def refuse_if_costly(estimate, option: str, value: object, yes: bool, what: str,
                     time_too: bool = True) -> None:
    """A one-line error naming ``option`` and ``value`` and quoting ``estimate`` (a
    :class:`~geardyn.analysis.map2d.MapEstimate`) when it exceeds :func:`memory_limit` or (with
    ``time_too``) :data:`TIME_LIMIT_S`, unless ``yes``."""
    if yes:
        return
    limit = memory_limit()
    if estimate.memory_bytes > limit:
        raise ParameterError(option, value, f"{what} too large: {estimate.describe()}; limit "
                             f"{limit / 2**30:.3g} GiB (pass --yes to run anyway)")
    if time_too and estimate.seconds > TIME_LIMIT_S:
        raise ParameterError(option, value, f"{what} too long: {estimate.describe()}; limit "
                             f"{TIME_LIMIT_S / 60:.3g} min (pass --yes to run anyway)")


def check_run_cost(model, lanes: int, omegas, transient: float, samples: int,
                   steps_per_period: int | None, lyapunov: bool, *, option: str, value: object,
                   yes: bool, what: str, chunk: int | None = None, record_columns: int = 0,
                   blocks: bool = True):
    """Estimate a run of ``lanes`` integrations with :func:`~geardyn.analysis.map2d.estimate_map`
    before anything of its size is built, and refuse it (:func:`refuse_if_costly`) when it is
    too large or too long. The time is first estimated at a default speed and, only when that
    exceeds the limit, at this machine's measured speed. ``record_columns``: values kept per
    step over the ``samples`` periods (a time history at ``omegas[0]``), which the estimate adds
    to its memory. ``blocks``: the lanes run in the sweep kernels' blocks (False: one lane on
    its own, a simulation; see :func:`~geardyn.analysis.map2d.estimate_map`). Returns the
    estimate."""
    import dataclasses

    import numpy as np

    from geardyn.analysis.map2d import check_steps, estimate_map, measure_ns_per_lane_step
    from geardyn.core.plan import default_steps_per_period

    omegas = np.asarray(omegas, dtype=float)
    try:
        check_steps(model, omegas, transient, samples, steps_per_period)
        n = steps_per_period or default_steps_per_period(model, float(omegas[0]))
    except OverflowError:  # more steps per period than a float holds
        raise ParameterError(option, value, "a point would need more RK4 steps than can be "
                             "counted; check Omega, transient and samples") from None
    except ValueError as exc:  # too many steps: name the options, not only the quantities
        raise ParameterError(option, value, str(exc)) from None
    history = 2 * 8.0 * record_columns * (float(samples) * n + 1)

    def estimate(**speed):
        est = estimate_map(model, lanes, omegas, transient, samples, steps_per_period, lyapunov,
                           chunk, blocks=blocks, **speed)
        return dataclasses.replace(est, memory_bytes=est.memory_bytes + history)

    est = estimate()
    refuse_if_costly(est, option, value, yes, what, time_too=False)
    if est.seconds > TIME_LIMIT_S and not yes:
        ns = measure_ns_per_lane_step(model, float(np.median(omegas)), steps_per_period)
        est = estimate(ns_per_lane_step=ns)
        refuse_if_costly(est, option, value, yes, what)
    return est


def make_parents(*paths: Path | None) -> None:
    for path in paths:
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)


def write_outputs(ds: Any, out: Path | None, plot: Path | None,
                  draw: Callable[[Path], None], **attrs: Any) -> str:
    """Record ``attrs`` (study name, wall time, ...) on the result ``ds``, save it to ``out``
    (NetCDF) and ``draw(plot)`` where given; returns the tail of the command's summary line
    ("; wrote A, B" or "; nothing written")."""
    ds.attrs.update(attrs)
    written = []
    if out is not None:
        from geardyn.io.netcdf import save_dataset

        save_dataset(ds, out)
        written.append(str(out))
    if plot is not None:
        draw(plot)
        written.append(str(plot))
    return f"; wrote {', '.join(written)}" if written else "; nothing written"


def run_reporting_errors(call: Callable[[], Any]) -> int:
    """Run ``call`` (a click main in non-standalone mode) and return the exit status; expected
    errors print one line ``error: ...`` on stderr and give status 2."""
    from geardyn.cli.errors import format_error

    with warnings.catch_warnings(record=True) as caught:
        try:
            rv = _run_reporting_errors(call, format_error)
        except BaseException:
            _replay(caught)
            raise
    if rv in (0, None):  # floating-point or other warnings of a successful run are shown;
        _replay(caught)  # an error is one line, without them
    return rv


def _replay(caught: list[warnings.WarningMessage]) -> None:
    for w in caught:
        warnings.showwarning(w.message, w.category, w.filename, w.lineno, w.file, w.line)


def _run_reporting_errors(call: Callable[[], Any], format_error: Callable) -> int:
    try:
        rv = call()
        return rv if isinstance(rv, int) else 0
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        print("error: aborted", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except typer.TyperException as exc:  # usage errors: bad options or arguments
        ctx = getattr(exc, "ctx", None)
        hint = f" (try '{ctx.command_path} --help')" if ctx is not None else ""
        message = " ".join(exc.format_message().split())
        print(f"error: {message}{hint}", file=sys.stderr)
        return getattr(exc, "exit_code", EXIT_ERROR) or EXIT_ERROR
    except EXPECTED_ERRORS as exc:
        print(f"error: {format_error(exc)}", file=sys.stderr)
        return EXIT_ERROR


class OneLineErrorGroup(TyperGroup):
    """The root command group: however it is invoked (console script, :func:`main`, typer's
    ``CliRunner``), expected errors and usage errors end in one line on stderr and status 2."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True,
             **extra):
        args = (sys.argv[1:] if args is None else list(args)) or ["--help"]
        code = run_reporting_errors(lambda: super(OneLineErrorGroup, self).main(
            args, prog_name, complete_var, standalone_mode=False, **extra))
        if standalone_mode:
            sys.exit(code)
        return code
