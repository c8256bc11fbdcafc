"""``geardyn frc``: frequency-response curves of a study by up and down sweeps.

::

    geardyn frc STUDY.toml [--range 0.5:1.5:201]
                [--param Omega|mesh_frequency|input_speed|speed]
                [--transient T] [--continued-transient T]
                [--converge TOL] [--samples N] [--steps-per-period N] [--mesh NAME]
                [--branch branch.nc ...] [--interpretation ...] [--quiet] [--yes]
                [--out frc.nc] [--plot frc.png]

Unset options come from the study's ``[sweep]`` (param, start, stop, num, samples; the sweep must
be of Omega, mesh_frequency, input_speed or a spur pair's speed, which are turned into Omega
point by point) and
``[run]`` tables (transient or transient_periods, converge, transient_max, continued_transient,
max_period, period_tol, steps_per_period). A progress bar is drawn when stderr is a terminal.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from geardyn.cli.common import (
    ESTIMATE_POINTS,
    ContinuedTransientOption,
    ConvergeOption,
    InterpretationOption,
    NetCDFOutOption,
    PlotOption,
    QuietOption,
    StepsOption,
    YesOption,
    check_count,
    check_plot_path,
    check_run_cost,
    load_study_source,
    make_parents,
    run_option,
    run_options,
    study_run_settings,
    write_outputs,
)
from geardyn.core.settings import check_omega
from geardyn.errors import ParameterError, StudyError
from geardyn.study import build_model

__all__ = ["frc_command", "register"]

#: The parameters ``geardyn frc`` sweeps: the forcing frequency and its physical forms (a spur
#: pair's ``speed``: the pinion speed in its ``speed_unit``).
FREQUENCY_PARAMS = ("Omega", "mesh_frequency", "input_speed", "speed")


def frc_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    range_: Annotated[
        str | None, typer.Option("--range", help="START:STOP:NUM of --param (default: the "
                                                 "study's [sweep]).")
    ] = None,
    param: Annotated[
        str | None, typer.Option(help="The swept frequency: Omega, or mesh_frequency [rad/s] "
                                      "or input_speed [rpm] of a model that has them, or a "
                                      "spur pair's speed (in its speed_unit) (default: "
                                      "the study's sweep.param when it is one of these, else "
                                      "Omega).")
    ] = None,
    transient: run_option("transient", "of the first point; default: run.transient") = None,
    continued_transient: ContinuedTransientOption = None,
    converge: ConvergeOption = None,
    samples: run_option("samples", "default: the study's") = None,
    steps_per_period: StepsOption = None,
    mesh: Annotated[str | None, typer.Option(help="Mesh drawn (default: the first).")] = None,
    branch: Annotated[
        list[Path] | None, typer.Option(help="A continuation branch (NetCDF: dim 'point', "
                                             "Omega, dte_rms, ..., stable) drawn over the "
                                             "curves; repeatable.")
    ] = None,
    interpretation: InterpretationOption = None,
    quiet: QuietOption = False,
    yes: YesOption = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
) -> None:
    """Frequency-response curves: RMS and peak dynamic transmission error and dynamic factor
    against Omega (and mesh frequency, input speed), sweeping up and down; the jumps located."""
    import numpy as np

    from geardyn.analysis.frc import frequency_response
    from geardyn.cli.bifurcation import _progress_bar, _stderr_is_terminal, parse_range

    s = load_study_source(study)
    sweep = s.sweep
    swept = sweep.param if sweep is not None and sweep.param in FREQUENCY_PARAMS else None
    name = param or swept or "Omega"
    if name not in FREQUENCY_PARAMS:
        raise ParameterError("--param", name, "must be a frequency: "
                             + ", ".join(FREQUENCY_PARAMS))
    if range_ is not None:
        start, stop, num = parse_range(range_)
    elif sweep is not None and sweep.param == name:
        start, stop, num = sweep.start, sweep.stop, sweep.num
    else:
        why = "the study has no [sweep]" if sweep is None else f"the study sweeps {sweep.param}"
        raise StudyError(f"--range: not given, and {why}, not {name}")
    check_omega([start, stop], "--range")
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")
    check_plot_path("--plot", plot)
    interp = interpretation.value if interpretation is not None else None
    model = build_model(s, interpretation=interp)
    values = np.linspace(start, stop, num)
    omegas_all = values if name == "Omega" else _omegas(model, name, values)
    start, stop = float(omegas_all[0]), float(omegas_all[-1])
    if not model.meshes:
        raise ParameterError("STUDY", study, f"{model.name} has no backlash mesh")
    names = [m[0] for m in model.meshes]
    if mesh is not None and mesh not in names:
        raise ParameterError("--mesh", mesh, f"not a mesh of the model; meshes: "
                             f"{', '.join(names)}")
    run = study_run_settings(
        s, run_options(transient=transient, samples=samples, steps_per_period=steps_per_period,
                       converge=converge, continued_transient=continued_transient),
        sweep=True, omega=min(start, stop), least={"samples": (2, "the period needs two")})
    tr, n_samples, spp = run.transient, run.samples, run.steps_per_period
    check_count("--samples", n_samples)
    omegas = np.linspace(start, stop, min(num, ESTIMATE_POINTS))  # Omega, evenly spaced
    check_run_cost(model, 2 * num, omegas,
                   tr if run.converge is None else run.transient_limit, n_samples, spp,
                   False, yes=yes, option="--range/--samples/--transient",
                   value=f"{start:g}:{stop:g}:{num}, {n_samples} samples, transient {tr:g}",
                   what="frequency response")
    branches = [_load_branch(p) for p in branch or []]
    make_parents(out, plot)
    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _progress_bar(show_bar, escape(f"{s.study.name}: up and down")) as callback:
        ds = frequency_response(model, omegas_all, run, progress=callback)
    elapsed = time.perf_counter() - t0

    def draw(path: Path) -> None:
        from geardyn.plotting.frc import plot_frc

        plot_frc(ds, path=path, mesh=mesh, branches=branches)

    wrote = write_outputs(ds, out, plot, draw, study=s.study.name,
                          wall_time_s=round(elapsed, 3))
    span = f"[{start:g}, {stop:g}]" if name == "Omega" else (
        f"{name} [{values[0]:g}, {values[-1]:g}] (Omega [{start:g}, {stop:g}])")
    typer.echo(f"{s.study.name}: {num} values of Omega in {span} up and down, "
               f"{elapsed:.1f} s: {_summary(ds)}{wrote}")


def _omegas(model, name: str, values):
    """The dimensionless forcing frequencies Omega of ``values`` of ``name`` (mesh_frequency
    [rad/s] or input_speed [rpm]), each through ``model.with_params`` as a sweep sets them; a
    model without that parameter is a one-line error naming --param."""
    import numpy as np

    try:
        return np.array([model.with_params(**{name: float(v)}).omega for v in values])
    except KeyError as err:
        raise ParameterError("--param", name, f"{model.name} has no such parameter ({err})") \
            from None


def _load_branch(path: Path):
    """A continuation branch to draw: a NetCDF dataset with the dimension ``point``."""
    from geardyn.io.netcdf import load_dataset

    if not path.exists():
        raise FileNotFoundError(2, "No such file", str(path))
    try:
        b = load_dataset(path)
    except (OSError, ValueError, KeyError) as exc:
        raise ParameterError("--branch", str(path), f"cannot read it as NetCDF ({exc})") \
            from None
    if "point" not in b.dims:
        raise ParameterError("--branch", str(path), "not a branch (no dimension 'point')")
    return b


def _summary(ds) -> str:
    n = ds.sizes["jump"]
    if not n:
        return "no jumps"
    parts = [f"{ds['jump_sweep'].values[j]} jump ({ds['jump_mesh'].values[j]}) at Omega "
             f"{float(ds['jump_lo'].values[j]):.6g}..{float(ds['jump_hi'].values[j]):.6g}"
             for j in range(n)]
    return f"{n} jump{'s' if n > 1 else ''}: " + ", ".join(parts)


def register(app: typer.Typer) -> None:
    """Add ``geardyn frc`` to the command line ``app``."""
    app.command("frc")(frc_command)
