"""``geardyn dynamic-factor``: a study's dynamic factor beside ISO 6336-1 K_v (method B).

::

    geardyn dynamic-factor STUDY.toml --f-pb UM --f-falpha UM [--y-alpha UM] [--tip-relief UM]
                [--ka K_A] [--stiffness iso|model] [--range START:STOP:NUM] [--torque T ...]
                [--transient T] [--converge TOL] [--samples N] [--out df.nc] [--plot df.png]

The study's model must be built from geometry (``spur_pair``, ``planetary`` with
``[params.geometry]``, or a train whose meshed gears have geometry). ``--range`` is the input
speed in rpm (the pinion's, the planetary stage's input member's, the train's driven body's;
default the study's ``[sweep]`` of ``speed`` or ``input_speed``), ``--torque`` the input torque
[N m] (repeatable; default the study's). Unset
run options come from the study's ``[run]`` table.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from geardyn.cli.common import (
    ConvergeOption,
    NetCDFOutOption,
    PlotOption,
    check_plot_path,
    load_study_source,
    make_parents,
    run_option,
    run_options,
    study_run_settings,
    write_outputs,
)
from geardyn.errors import ParameterError, StudyError
from geardyn.study import build_model

__all__ = ["dynamic_factor_command", "register"]

_UM = "[um]"


def dynamic_factor_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    f_pb: Annotated[float, typer.Option("--f-pb", help=f"Base pitch deviation f_pb {_UM}.")],
    f_falpha: Annotated[float, typer.Option("--f-falpha",
                                            help=f"Profile form deviation f_falpha {_UM}.")],
    y_alpha: Annotated[float, typer.Option("--y-alpha", help=f"Running-in allowance y_p = y_f "
                                                             f"{_UM}.")] = 0.0,
    tip_relief: Annotated[float, typer.Option("--tip-relief", help=f"Tip relief C_a "
                                                                   f"{_UM}.")] = 0.0,
    ka: Annotated[float, typer.Option("--ka", help="Application factor K_A.")] = 1.0,
    stiffness: Annotated[str, typer.Option(help="c' and c_gamma_alpha: 'iso' (ISO 6336-1 "
                                                "method B) or 'model' (its mean stiffness).")
                         ] = "iso",
    range_: Annotated[
        str | None, typer.Option("--range", help="START:STOP:NUM input speed [rpm] (default: "
                                                 "the study's [sweep] of its speed).")
    ] = None,
    torque: Annotated[list[float] | None, typer.Option(
        help="Input (pinion, sun or driven body) torque [N m]; repeatable (default: the "
             "study's).")] = None,
    transient: run_option("transient", "default: run.transient") = None,
    converge: ConvergeOption = None,
    samples: run_option("samples", "default: the study's") = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No summary line.")] = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
) -> None:
    """Dynamic factor (peak dynamic mesh force / static) against input speed and torque,
    beside ISO 6336-1 K_v (method B) and its resonance speed N_M."""
    import numpy as np

    from geardyn.analysis.dynamic_factor import dynamic_factor_sweep
    from geardyn.cli.bifurcation import parse_range

    s = load_study_source(study)
    model = build_model(s)
    if not model.capabilities.dynamic_factor:
        raise ParameterError("STUDY", study, "the model must be built from geometry (a "
                             "spur_pair, a planetary study with [params.geometry], or a train)")
    speed_param, one_rpm = model.input_speed_sweep(np.array([1.0]))
    to_rpm = 1.0 / float(one_rpm[0])
    if range_ is not None:
        start, stop, num = parse_range(range_)
    elif s.sweep is not None and s.sweep.param == speed_param:
        start, stop, num = (s.sweep.start * to_rpm, s.sweep.stop * to_rpm, s.sweep.num)
    else:
        raise StudyError(f"--range: not given, and the study has no [sweep] of {speed_param}")
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")
    check_plot_path("--plot", plot)
    rpm = np.linspace(start, stop, num)
    if not np.all(rpm > 0.0):
        raise ParameterError("--range", f"{start:g}:{stop:g}", "input speeds must be > 0 rpm")
    lowest = model.with_params(**{speed_param: float(rpm.min()) / to_rpm}).omega
    run = study_run_settings(
        s, run_options(transient=transient, samples=samples, converge=converge), sweep=True,
        omega=lowest)
    make_parents(out, plot)
    t0 = time.perf_counter()
    ds = dynamic_factor_sweep(model, rpm, torque or None, run, base_pitch_deviation=f_pb,
                              profile_form_deviation=f_falpha, pitch_running_in=y_alpha,
                              profile_running_in=y_alpha, tip_relief=tip_relief,
                              application_factor=ka, stiffness=stiffness)
    elapsed = time.perf_counter() - t0

    def draw(path: Path) -> None:
        from geardyn.plotting.dynamic_factor import plot_dynamic_factor

        plot_dynamic_factor(ds, path)

    wrote = write_outputs(ds, out, plot, draw, study=s.study.name, wall_time_s=round(elapsed, 3))
    if not quiet:
        parts = []
        for j, t1 in enumerate(ds["torque"].values):
            for g in ds["group"].values:
                row = ds.sel(group=g).isel(torque=j)
                df = row["dynamic_factor"].values
                top = float(np.max(df[np.isfinite(df)])) if np.isfinite(df).any() else np.nan
                parts.append(f"{t1:g} N m {g}: model max {top:.2f}, K_v max "
                             f"{float(row['K_v'].max()):.2f}, N_M "
                             f"{float(row['resonance_speed']):.0f} rpm")
        typer.echo(f"{s.study.name}: {num} input speeds {start:g}..{stop:g} rpm, {elapsed:.1f} "
                   f"s; " + "; ".join(parts) + wrote)


def register(app: typer.Typer) -> None:
    """Add ``geardyn dynamic-factor`` to the command line ``app``."""
    app.command("dynamic-factor")(dynamic_factor_command)
