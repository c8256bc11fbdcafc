"""``geardyn modes``: natural frequencies, energy shares and Campbell diagram of a gear train.

::

    geardyn modes STUDY [-o modes.nc] [--plot shares.png]
                        [--speed "0..1500 rpm" [--points 401] [--harmonics 3]
                         [--campbell campbell.png]]

The train is the study's ``[train]`` table (:mod:`geardyn.io.train_table`); the results are
:meth:`geardyn.trains.GearTrain.modes` (with ``--speed`` also
:meth:`~geardyn.trains.GearTrain.campbell` over that input-speed range), printed as a table
(frequency, multiplicity, mode class where the train has planets, the elements holding most of
the strain energy), written as NetCDF with ``--out`` and drawn with ``--plot`` (energy shares)
and ``--campbell``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from geardyn.cli.common import check_plot_path, load_study_source, make_parents
from geardyn.errors import ParameterError

__all__ = ["modes_command", "register", "speed_range"]

#: Elements listed per mode in the printed table (the largest energy shares).
SHOWN_SHARES = 3
#: Most speeds of a Campbell diagram, and the speeds unless told.
MAX_POINTS = 100_000
DEFAULT_POINTS = 401
#: Most mesh-frequency harmonics, and the harmonics unless told.
MAX_HARMONICS = 100
DEFAULT_HARMONICS = 3


def speed_range(text: str, points: int) -> np.ndarray:
    """``points`` input speeds [rpm] evenly over ``"A..B UNIT"`` (UNIT: rpm, Hz, rad/s, ...;
    none: rad/s, as every plain speed); a ParameterError names ``--speed``."""
    from geardyn.units import to_si

    low, sep, high = text.partition("..")
    parts = high.strip().split(maxsplit=1)
    if not sep or not low.strip() or not parts:
        raise ParameterError("--speed", text, 'must be a range "A..B UNIT", e.g. "0..1500 rpm"')
    unit = parts[1] if len(parts) > 1 else "rad/s"
    try:
        ends = [to_si(f"{value} {unit}", "frequency") * 60.0 / (2.0 * math.pi)
                for value in (low.strip(), parts[0])]
    except ValueError as exc:
        raise ParameterError("--speed", text, str(exc)) from None
    if not (0.0 <= ends[0] < ends[1] and math.isfinite(ends[1])):
        raise ParameterError("--speed", text, "must run from a speed >= 0 up to a larger one")
    if not 2 <= points <= MAX_POINTS:
        raise ParameterError("--points", points, f"must be in 2..{MAX_POINTS}")
    return np.linspace(ends[0], ends[1], points)


def modes_command(
    study: Annotated[str, typer.Argument(help="Study TOML file with a [train] table, or a "
                                              "built-in study name.")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="NetCDF file to write (.nc):"
                                             " the modes (and with --speed the Campbell data).")
                   ] = None,
    plot: Annotated[Path | None, typer.Option(help="Figure of the energy shares (.png, .pdf or"
                                              " .svg).")] = None,
    speed: Annotated[str | None, typer.Option(help='Input-speed range of the Campbell diagram,'
                                              ' "A..B UNIT" (e.g. "0..1500 rpm").')] = None,
    points: Annotated[int | None, typer.Option(help="Speeds in the range (default 401).")
                      ] = None,
    harmonics: Annotated[int | None, typer.Option(help="Mesh-frequency harmonics (default 3)."
                                                  )] = None,
    campbell: Annotated[Path | None, typer.Option(help="Campbell diagram to write (.png, .pdf"
                                                  " or .svg; needs --speed).")] = None,
) -> None:
    """Natural frequencies and mode shapes of a gear train (linear, mean mesh stiffness), the
    strain-energy share of every mesh, shaft and bearing, and its Campbell diagram."""
    s = load_study_source(study, model=False)
    if s.train is None:
        raise ParameterError("STUDY", study, "has no [train] table (the gear train whose"
                             " modes to compute)")
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")
    check_plot_path("--plot", plot)
    check_plot_path("--campbell", campbell)
    if speed is None:
        for option, value in (("--campbell", campbell), ("--points", points),
                              ("--harmonics", harmonics)):
            if value is not None:
                raise ParameterError(option, str(value), "needs the speed range (--speed)")
    if harmonics is not None and not 1 <= harmonics <= MAX_HARMONICS:
        raise ParameterError("--harmonics", harmonics, f"must be in 1..{MAX_HARMONICS}")
    rpm = speed_range(speed, DEFAULT_POINTS if points is None else points) if speed else None
    train = s.gear_train
    if rpm is not None and train.driven is None:
        raise ParameterError("train.driven", None, "the Campbell diagram (--speed) needs the"
                             " input body: give driven in the study's [train] table")
    ds = train.modes()
    cds = None
    if rpm is not None:
        cds = train.campbell(rpm, harmonics=DEFAULT_HARMONICS if harmonics is None
                             else harmonics)
    make_parents(out, plot, campbell)
    written = []
    if out is not None:
        from geardyn.io.netcdf import save_dataset

        result = ds if cds is None else ds.merge(cds.drop_vars("mode"))
        result.attrs.update(study=s.study.name)
        save_dataset(result, out)
        written.append(str(out))
    if plot is not None:
        from geardyn.plotting.modes import plot_energy_shares

        plot_energy_shares(ds, plot)
        written.append(str(plot))
    if campbell is not None:
        from geardyn.plotting.campbell import plot_campbell

        plot_campbell(cds, campbell)
        written.append(str(campbell))
    _print_table(s.study.name, train, ds)
    tail = f"; wrote {', '.join(written)}" if written else "; nothing written"
    crossings = ""
    if cds is not None:
        n = int(np.isfinite(cds["crossing_speed"].values).sum())
        crossings = (f"; {n} crossing{'s' if n != 1 else ''} of mesh-frequency harmonics"
                     f" with natural frequencies in {rpm[0]:.6g}..{rpm[-1]:.6g} rpm")
    typer.echo(f"{s.study.name}: {train!r}, {ds.sizes['mode']} modes{crossings}{tail}")


def _print_table(name: str, train, ds) -> None:
    """The modes as a table on stdout."""
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    console = Console() if sys.stdout.isatty() else Console(width=130)
    table = Table(title=f"{escape(name)}: natural frequencies (linear, mean mesh stiffness)")
    columns = ["mode", "f [Hz]", "mult."] + (["type"] if "type" in ds else []) + [
        "largest strain-energy shares"]
    for col in columns:
        table.add_column(col, justify="left" if col.startswith(("type", "largest")) else "right")
    elements = [str(e) for e in ds["element"].values]
    for k in range(ds.sizes["mode"]):
        share = ds["energy_share"].values[k]
        if bool(ds["rigid_body"].values[k]):
            shares = "rigid-body mode"
        else:
            top = np.argsort(share)[::-1][:SHOWN_SHARES]
            shares = ", ".join(f"{elements[j]} {100 * share[j]:.0f}%" for j in top
                               if share[j] >= 0.005)
        row = [str(k), f"{float(ds['frequency'].values[k]):.6g}",
               str(int(ds["multiplicity"].values[k]))]
        row += [str(ds["type"].values[k])] if "type" in ds else []
        table.add_row(*row, escape(shares))
    console.print(table)


def register(app: typer.Typer) -> None:
    """Add ``geardyn modes`` to the command line ``app``."""
    app.command("modes")(modes_command)
