"""``geardyn map``: a two-parameter map of a study, locally or on a Dask cluster, resumable.

::

    geardyn map STUDY.toml --x Omega:0.1:4:400 --y xi:0.01:0.3:200 [--lyapunov]
                [--scheduler tcp://host:8786] [--chunk N] [--yes] --out map.nc|map.zarr
                [--plot map.png]

An axis is ``NAME:START:STOP:NUM`` (NUM evenly spaced values, SI units for the device's physical
parameters). Before anything is built the command estimates memory and run time; a map above
:data:`MEMORY_FRACTION` of this machine's memory or :data:`TIME_LIMIT_S` is refused with the
estimate unless ``--yes`` is given. With ``--out map.zarr`` finished chunks are kept in the store
as they complete and the same command, run again after an interruption, computes only the rest;
the finished map is at the store's root (``xarray.open_zarr("map.zarr")`` opens it).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from geardyn.cli.common import (
    ESTIMATE_POINTS,
    MAX_COUNT,
    MEMORY_FRACTION,  # noqa: F401 (documented here: the limits a map is refused above)
    TIME_LIMIT_S,  # noqa: F401
    StepsOption,
    YesOption,
    check_count,
    load_study_source,
    refuse_if_costly,
    run_option,
    run_options,
    run_settings,
    study_run_settings,
)
from geardyn.core.settings import check_omega
from geardyn.errors import ParameterError, StudyError
from geardyn.study import build_model

__all__ = ["map_command", "parse_axis", "register"]

_OUT_SUFFIXES = (".nc", ".zarr")
_PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def parse_axis(text: str, option: str) -> tuple[str, float, float, int]:
    """``NAME:START:STOP:NUM`` -> (name, start, stop, num); a one-line error otherwise."""
    parts = text.split(":")
    if len(parts) != 4 or not parts[0].strip():
        raise ParameterError(option, text, "expected NAME:START:STOP:NUM, e.g. Omega:0.1:4:400")
    name = parts[0].strip()
    try:
        start, stop = float(parts[1]), float(parts[2])
    except ValueError:
        raise ParameterError(option, text, "START and STOP must be numbers") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise ParameterError(option, text, "START and STOP must be finite")
    try:
        num = int(parts[3])
    except ValueError:
        raise ParameterError(option, text, "NUM must be a whole number of values") from None
    if not 1 <= num <= MAX_COUNT:
        raise ParameterError(option, text, f"NUM must be >= 1 and <= 2**53 = {MAX_COUNT}")
    return name, start, stop, num


def _connect(address: str):
    try:
        from dask.distributed import Client
    except ImportError:
        raise ParameterError("--scheduler", address, "needs dask[distributed] installed") from None
    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise ParameterError("--scheduler", address, f"cannot connect: {reason}") from None


def map_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    x: Annotated[str, typer.Option("--x", help="x axis NAME:START:STOP:NUM, e.g. Omega:0.1:4:400")],
    y: Annotated[str, typer.Option("--y", help="y axis NAME:START:STOP:NUM, e.g. xi:0.01:0.3:200")],
    out: Annotated[Path, typer.Option(help="Result: map.nc (NetCDF) or map.zarr (resumable).")],
    plot: Annotated[Path | None, typer.Option(help="Figure (.png, .pdf or .svg).")] = None,
    transient: run_option("transient", "default: run.transient") = None,
    samples: run_option("samples", "default: run.periods") = None,
    steps_per_period: StepsOption = None,
    lyapunov: Annotated[
        bool, typer.Option("--lyapunov", help="Also the largest Lyapunov exponent per point.")
    ] = False,
    interpretation: Annotated[
        str | None, typer.Option(help="consistent, carrier-only or as-printed (default: study's).")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Dask scheduler address (tcp://host:port): run there.")
    ] = None,
    chunk: Annotated[int | None, typer.Option(help="Grid points per task (default: auto).")] = None,
    yes: YesOption = False,
) -> None:
    """Map the steady motion (period, contact-loss regime, Lyapunov exponent) over two
    parameters; save it (NetCDF, or a resumable Zarr store) and plot it."""
    from rich.console import Console

    from geardyn.analysis.map2d import check_steps, estimate_map, map2d, measure_ns_per_lane_step
    from geardyn.cli.errors import format_error

    x_axis, y_axis = parse_axis(x, "--x"), parse_axis(y, "--y")
    if x_axis[0] == y_axis[0]:
        raise ParameterError("--y", y, "must name another parameter than --x")
    if out.suffix.lower() not in _OUT_SUFFIXES:
        raise ParameterError("--out", str(out), f"suffix must be one of {_OUT_SUFFIXES}")
    if plot is not None and plot.suffix.lower() not in _PLOT_SUFFIXES:
        raise ParameterError("--plot", str(plot), f"suffix must be one of {_PLOT_SUFFIXES}")
    if chunk is not None and chunk < 1:
        raise ParameterError("--chunk", chunk, "must be >= 1")
    for option, count in (("--chunk", chunk), ("--samples", samples),
                          ("--steps-per-period", steps_per_period)):
        if count is not None:
            check_count(option, count)
    run_settings(run_options(transient=transient, steps_per_period=steps_per_period))
    s = load_study_source(study)
    model = build_model(s, interpretation=interpretation)
    # the names and both ends of each axis must be valid before anything grid-sized is built
    forcing: list[tuple[float, float, int]] = []  # the Omega ends of axes that move Omega
    for (name, start, stop, num), option in ((x_axis, "--x"), (y_axis, "--y")):
        try:
            with np.errstate(all="ignore"):
                ends = model.lane_params(name, [start, stop])
        except KeyError as exc:
            raise ParameterError(option, name, str(exc.args[0]) if exc.args else "unknown") \
                from None
        except (ArithmeticError, ValueError) as exc:
            raise ParameterError(option, f"{name}:{start}:{stop}", format_error(exc)) from None
        if model.omega_index is None:
            raise ParameterError("study", s.study.name, "a map needs a forced model")
        if name == "Omega":
            check_omega(ends[:, model.omega_index], option)
        if not np.all(np.isfinite(ends)):
            raise ParameterError(option, f"{name}:{start}:{stop}", "an end of the axis makes the"
                                 " model's coefficients infinite (a value is too extreme)")
        w = ends[:, model.omega_index]
        if name == "Omega" or np.any(w != model.omega):  # Omega, or a speed that sets it
            forcing.append((float(w[0]), float(w[1]), num))

    # the transient: --transient, [run].transient, or transient_periods of the lowest Omega
    low = [min(a[0], a[1]) for a in forcing]
    run = study_run_settings(s, run_options(transient=transient, samples=samples,
                                            steps_per_period=steps_per_period),
                             omega=low[0] if low else model.omega,
                             least={"samples": (2, "a map classifies periods")})
    tr, n_samples, spp = run.transient, run.samples, run.steps_per_period
    lanes = x_axis[3] * y_axis[3]
    omega_axis = forcing[0] if forcing else None
    omegas = (np.linspace(omega_axis[0], omega_axis[1], min(omega_axis[2], ESTIMATE_POINTS))
              if omega_axis else np.array([model.omega]))
    try:
        check_steps(model, omegas, tr, n_samples, spp)
    except (ValueError, OverflowError) as exc:  # add the settings given to the quantities named
        raise StudyError(f"{exc or 'Omega/transient: too many steps per point'} (--transient "
                         f"{tr:g}, --samples {n_samples}, --steps-per-period "
                         f"{spp or 'automatic'})") from None
    err = Console(stderr=True)
    estimate = estimate_map(model, lanes, omegas, tr, n_samples, spp, lyapunov, chunk)
    refuse_if_costly(estimate, "--x/--y", f"{x} x {y}", yes, "map", time_too=False)
    client = _connect(scheduler) if scheduler else None
    try:
        parallel = 1.0
        if client is not None:
            threads = sum(client.nthreads().values())
            parallel = max(threads, 1) / (os.cpu_count() or 1)
        with err.status("estimating the run time (the first run compiles the kernels)"):
            ns = measure_ns_per_lane_step(model, float(np.median(omegas)), spp)
        estimate = estimate_map(model, lanes, omegas, tr, n_samples, spp, lyapunov, chunk,
                                ns_per_lane_step=ns, parallel=parallel)
        refuse_if_costly(estimate, "--x/--y", f"{x} x {y}", yes, "map")
        err.print(f"map: {estimate.describe()}")
        ds = _run(map2d, model, x_axis, y_axis, run, lyapunov, client, out,
                  chunk, err)
    finally:
        if client is not None:
            client.close()
    ds.attrs["study"] = s.study.name
    _save(ds, out, plot, err)


def _run(map2d, model, x_axis, y_axis, run, lyapunov, client, out, chunk, err):
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    xv = np.linspace(x_axis[1], x_axis[2], x_axis[3])
    yv = np.linspace(y_axis[1], y_axis[2], y_axis[3])
    store = out if out.suffix.lower() == ".zarr" else None
    if store is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
    columns = ("[progress.description]{task.description}", BarColumn(), MofNCompleteColumn(),
               TimeRemainingColumn())
    with Progress(*columns, console=err, transient=False) as bar:
        task = bar.add_task("points", total=xv.size * yv.size)

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        return map2d(model, (x_axis[0], xv), (y_axis[0], yv), run, lyapunov=lyapunov,
                     client=client, store=store, chunk=chunk, progress=progress)


def _save(ds, out: Path, plot: Path | None, err) -> None:
    from geardyn.analysis.periodicity import APERIODIC, UNBOUNDED
    from geardyn.execution.zarr_store import save_zarr_dataset
    from geardyn.io.netcdf import save_dataset

    for path in (out, plot):
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
    if out.suffix.lower() == ".zarr":
        save_zarr_dataset(ds, out)
    else:
        save_dataset(ds, out)
    written = [str(out)]
    if plot is not None:
        from geardyn.plotting.map2d import plot_map

        with err.status("plotting"):
            plot_map(ds, path=plot)
        written.append(str(plot))
    p = ds["period"].values
    n = p.size
    typer.echo(
        f"{ds.attrs['study']}: {ds.attrs['y']} x {ds.attrs['x']} map of {n} points: "
        f"{np.sum(p >= 1)} periodic, {np.sum(p == APERIODIC)} without a period <= "
        f"{ds['period'].attrs.get('max_period', 16)}, "
        f"{np.sum(p == UNBOUNDED)} unbounded; wrote {', '.join(written)}"
    )


def register(app: typer.Typer) -> None:
    """Add ``geardyn map`` to the command line ``app``."""
    app.command("map")(map_command)
