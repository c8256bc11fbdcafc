"""``geardyn envelope``: the contact regions of a study's model in a parameter plane, from its
grazing curves.

::

    geardyn envelope STUDY --x Omega:0.5:2 --y Fa:0:1.5 [--flank drive --flank back]
                     [--map 16:12] [--curve fold.nc ...] --out DIR [--plot envelope.png]

An axis is ``NAME`` or ``NAME:LOW:HIGH``; what is not given comes from the study's
``[envelope]`` table (:mod:`geardyn.io.envelope_table`). The grazing curves are written to
``DIR`` (``grazing_<flank>_<i>.nc``, ``"curve"`` datasets), the figure to ``--plot``.
``--curve`` adds curves computed elsewhere (fold, period-doubling: their regions and crossings);
``--map NX:NY`` computes a brute-force map of the box beneath (``run`` settings of the study).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from geardyn.cli.common import QuietOption, load_study_source, study_run_settings
from geardyn.errors import ParameterError

__all__ = ["envelope_command", "load_curve", "parse_plane_axis", "register"]

_PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def parse_plane_axis(text: str, option: str) -> tuple[str, tuple[float, float] | None]:
    """``NAME`` or ``NAME:LOW:HIGH`` -> (name, (low, high) or None); a one-line error
    otherwise."""
    parts = text.split(":")
    if not parts[0].strip() or len(parts) not in (1, 3):
        raise ParameterError(option, text, "expected NAME or NAME:LOW:HIGH, e.g. Omega:0.5:2")
    if len(parts) == 1:
        return parts[0].strip(), None
    try:
        lo, hi = float(parts[1]), float(parts[2])
    except ValueError:
        raise ParameterError(option, text, "LOW and HIGH must be numbers") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ParameterError(option, text, "LOW and HIGH must be finite with LOW < HIGH")
    return parts[0].strip(), (lo, hi)


def _map_points(text: str) -> tuple[int, int]:
    parts = text.split(":")
    try:
        nx, ny = (int(p) for p in parts)
    except ValueError:
        raise ParameterError("--map", text, "expected NX:NY, e.g. 16:12") from None
    if min(nx, ny) < 2 or max(nx, ny) > 2000:
        raise ParameterError("--map", text, "each of NX and NY must lie in [2, 2000]")
    return nx, ny


def envelope_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    out: Annotated[Path, typer.Option(help="Folder for the curves (NetCDF, one per curve).")],
    x: Annotated[str | None, typer.Option("--x", help="x axis NAME[:LOW:HIGH]")] = None,
    y: Annotated[str | None, typer.Option("--y", help="y axis NAME[:LOW:HIGH]")] = None,
    plot: Annotated[Path | None, typer.Option(help="Figure (.png, .pdf or .svg).")] = None,
    flank: Annotated[list[str] | None, typer.Option(
        "--flank", help="drive or back (repeat for both; default: [envelope].flanks)")] = None,
    mesh: Annotated[str | None, typer.Option(help="The mesh (default the model's first).")
                    ] = None,
    map_points: Annotated[str | None, typer.Option(
        "--map", help="A brute-force map beneath: NX:NY points (default: [envelope].map)")
    ] = None,
    curve: Annotated[list[Path] | None, typer.Option(
        "--curve", help="A curve dataset (.nc) to draw and label regions by (repeatable).")
    ] = None,
    resolution: Annotated[int | None, typer.Option(help="Grid points per axis of the regions.")
                          ] = None,
    quiet: QuietOption = False,
) -> None:
    """The contact regions (contact kept, one- and two-sided impacts) of a plane, from the
    grazing curves of a mesh's flanks; coexisting and period-doubled regions from given fold
    and period-doubling curves; optionally over a brute-force map."""
    import numpy as np

    from geardyn.io.envelope_table import EnvelopeTable
    from geardyn.study import build_model

    s = load_study_source(study)
    table = s.envelope or EnvelopeTable()
    xa = parse_plane_axis(x, "--x") if x else (table.x, None)
    ya = parse_plane_axis(y, "--y") if y else (table.y, None)
    if ya[0] is None:
        raise ParameterError("--y", None, "give the y parameter (or [envelope].y)")
    x_name, y_name = xa[0], str(ya[0])
    if x_name == y_name:
        raise ParameterError("--y", y_name, "must name another parameter than --x")
    x_range = xa[1] or table.x_range
    y_range = ya[1] or table.y_range
    if x_range is None:
        raise ParameterError("--x", x_name, "give its range NAME:LOW:HIGH (or [envelope]."
                             "x_range)")
    if y_range is None:
        raise ParameterError("--y", y_name, "give its range NAME:LOW:HIGH (or [envelope]."
                             "y_range)")
    flanks = tuple(flank) if flank else table.flanks
    for f in flanks:
        if f not in ("drive", "back"):
            raise ParameterError("--flank", f, "must be drive or back")
    if plot is not None and plot.suffix.lower() not in _PLOT_SUFFIXES:
        raise ParameterError("--plot", str(plot), f"suffix must be one of {_PLOT_SUFFIXES}")
    if resolution is not None and not 2 <= resolution <= 4000:
        raise ParameterError("--resolution", resolution, "must lie in [2, 4000]")
    points = _map_points(map_points) if map_points else table.map
    given = [load_curve(p) for p in (curve or [])]
    model = build_model(s)
    for name, ends, option in ((x_name, x_range, "--x"), (y_name, y_range, "--y")):
        try:  # the name, and both ends of its range, before anything runs
            model.lane_params(name, list(ends))
        except KeyError as exc:
            raise ParameterError(option, name, str(exc.args[0]) if exc.args else "unknown") \
                from None
        except (ArithmeticError, ValueError) as exc:
            raise ParameterError(option, f"{name}:{ends[0]:g}:{ends[1]:g}", str(exc)) from None
    run = study_run_settings(s, {}, omega=x_range[0] if x_name == "Omega" else None)
    mp = None
    if points is not None:
        from geardyn.analysis.map2d import map2d

        mp = map2d(model, (x_name, np.linspace(*x_range, points[0])),
                           (y_name, np.linspace(*y_range, points[1])),
                           run.replace(samples=max(run.samples, 16)))
    env = _run(model, x_name, y_name, x_range, y_range, table, flanks, mesh, given, mp,
               resolution or table.resolution, quiet)
    out.mkdir(parents=True, exist_ok=True)
    written = _save(env, out, s.study.name)
    if plot is not None:
        from geardyn.plotting.envelope import plot_envelope

        plot.parent.mkdir(parents=True, exist_ok=True)
        plot_envelope(env, plot, title=f"{s.study.name}: contact regions in "
                                       f"({x_name}, {y_name})")
        written.append(str(plot))
    counts = {f: len(env.grazing(f)) for f in flanks}
    typer.echo(f"{s.study.name}: grazing curves in ({x_name}, {y_name}): "
               + ", ".join(f"{n} {f}" for f, n in counts.items())
               + f"; wrote {', '.join(written)}")


def load_curve(path: Path):
    """A ``"curve"`` dataset from its NetCDF file; a one-line error naming ``--curve``."""
    from geardyn.io.netcdf import load_dataset

    if not path.exists():
        raise ParameterError("--curve", str(path), "no such file")
    ds = load_dataset(path)
    if ds.attrs.get("geardyn_kind") != "curve":
        raise ParameterError("--curve", str(path), f"not a curve dataset (geardyn_kind "
                             f"{ds.attrs.get('geardyn_kind')!r})")
    return ds


def _run(model, x, y, x_range, y_range, table, flanks, mesh, given, mp, resolution, quiet):
    from rich.console import Console
    from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from geardyn.analysis.envelope import envelope

    err = Console(stderr=True, quiet=quiet)
    columns = (SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn())
    with Progress(*columns, console=err, transient=True, disable=quiet) as bar:
        task = bar.add_task("scanning", total=None)

        def progress(stage: str, points: int, X: float, Y: float) -> None:
            bar.update(task, description=f"{stage}: {points} points, {x}={X:.5g}, {y}={Y:.5g}")

        return envelope(model, x, y, x_range, y_range, mesh=mesh or table.mesh, flanks=flanks,
                        starts=table.starts, scan=table.scan, period=table.period,
                        curves=given, map=mp, resolution=resolution, progress=progress)


def _save(env, out: Path, name: str) -> list[str]:
    from geardyn.io.netcdf import save_dataset

    written = []
    count: dict[str, int] = {}
    for c in env.grazing():
        f = c.attrs["flank"]
        i = count.get(f, 0)
        count[f] = i + 1
        path = out / f"grazing_{f}_{i}.nc"
        ds = c.copy()
        ds.attrs["study"] = name
        save_dataset(ds, path)
        written.append(str(path))
    return written


def register(app: typer.Typer) -> None:
    """Add ``geardyn envelope`` to the command line ``app``."""
    app.command("envelope")(envelope_command)
