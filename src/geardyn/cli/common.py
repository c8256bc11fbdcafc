"""What every ``geardyn`` command shares: how a STUDY argument is read, the interpretation choice,
figure suffixes, and the rule that an expected error is one line on stderr with exit status 2.

This module imports nothing heavy (no numpy, numba or matplotlib), so ``geardyn --help`` stays
fast; command modules import it instead of :mod:`geardyn.cli.main`.
"""

from __future__ import annotations

import sys
import tomllib
from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import Any

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


class Interpretation(StrEnum):
    consistent = "consistent"
    carrier_only = "carrier-only"
    as_printed = "as-printed"


def load_study_source(source: str | None):
    """A study from a file, a built-in study name, or (None) the paper's device."""
    from geardyn.io.toml import builtin_study, builtin_study_names, load_study, paper_study

    if source is None:
        return paper_study()
    path = Path(source)
    if path.exists() or path.suffix == ".toml" or "/" in source:
        return load_study(path)
    if source in builtin_study_names():
        return builtin_study(source)
    raise FileNotFoundError(2, "No such file or built-in study", source)


def stderr_console() -> Console:
    return Console(stderr=True)


def check_plot_path(option: str, path: Path | None) -> None:
    """A figure path must end in one of :data:`PLOT_SUFFIXES`."""
    if path is not None and path.suffix.lower() not in PLOT_SUFFIXES:
        raise ParameterError(option, str(path), f"suffix must be one of {PLOT_SUFFIXES}")


def make_parents(*paths: Path | None) -> None:
    for path in paths:
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)


def run_reporting_errors(call: Callable[[], Any]) -> int:
    """Run ``call`` (a click main in non-standalone mode) and return the exit status; expected
    errors print one line ``error: ...`` on stderr and give status 2."""
    from geardyn.io.toml import format_error

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
