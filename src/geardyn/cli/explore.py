"""``geardyn explore``: the interactive bifurcation explorer in the browser (Bokeh server).

::

    geardyn explore STUDY.toml [--param Omega] [--range a:b:n] [--port 5006]
                    [--host 127.0.0.1] [--continuation none|up|down] [--interpretation ...]
                    [--save-dir out/explore] [--show] [--curve curve.nc ...]
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from geardyn.cli.common import (
    InterpretationOption,
    check_continuation,
    continuation_option,
    load_study_source,
)

__all__ = ["explore_command", "register"]


def explore_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    param: Annotated[
        str | None, typer.Option(help="Swept parameter (default: the study's sweep.param).")
    ] = None,
    range_: Annotated[
        str | None, typer.Option("--range", help="First window START:STOP:NUM (default: the "
                                                 "study's sweep); zoomed windows keep NUM.")
    ] = None,
    port: Annotated[int, typer.Option(help="Port to serve on.", min=1, max=65535)] = 5006,
    host: Annotated[
        str, typer.Option(help="Address to bind (default: this machine only; anything else "
                               "makes the explorer reachable from the network).")
    ] = "127.0.0.1",
    continuation: Annotated[
        str | None, continuation_option("Where each point starts (default: the study's).")
    ] = None,
    interpretation: InterpretationOption = None,
    save_dir: Annotated[
        Path, typer.Option(help="Folder the Save button writes to.")
    ] = Path("out/explore"),
    show: Annotated[bool, typer.Option("--show", help="Open a browser tab.")] = False,
    curve: Annotated[list[Path] | None, typer.Option(
        "--curve", help="A two-parameter curve (.nc, e.g. from geardyn envelope) marked where "
                        "it crosses the diagram (repeatable).")] = None,
) -> None:
    """Explore a study's bifurcation diagram in the browser: zoom into windows, click orbits,
    change parameters (a local Bokeh server; prints its address)."""
    from geardyn.cli.bifurcation import parse_range
    from geardyn.cli.errors import format_error
    from geardyn.explore.server import serve
    from geardyn.explore.state import ExplorerState, Window

    check_continuation(continuation)
    s = load_study_source(study)
    window = Window(*parse_range(range_)) if range_ is not None else None
    interp = interpretation.value if interpretation is not None else None
    from geardyn.cli.envelope import load_curve

    curves = [load_curve(p) for p in (curve or [])]

    def make_state() -> ExplorerState:
        return ExplorerState(s, study, param, window, interpretation=interp,
                             continuation=continuation, save_dir=save_dir,
                             describe_error=format_error, curves=curves)

    make_state()  # a bad study, parameter or range fails here, as one line
    serve(make_state, port=port, host=host, show=show, describe_error=format_error,
          echo=typer.echo)


def register(app: typer.Typer) -> None:
    """Add ``geardyn explore`` to the command line ``app``."""
    app.command("explore")(explore_command)
