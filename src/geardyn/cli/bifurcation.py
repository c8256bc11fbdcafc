"""``geardyn bifurcation`` (a study's sweep, saved and drawn) and ``geardyn plot`` (redraws a
saved result).

::

    geardyn bifurcation STUDY.toml [--param Omega] [--range 0.1:4:1000]
                        [--continuation none|up|down] [--lyapunov] [--transient T] [--samples N]
                        [--converge TOL] [--continued-transient T] [--steps-per-period N]
                        [--omega W] [--hold Omega|speed] [--interpretation ...] [--state X_sq]
                        [--quiet] [--yes] [--out out.nc] [--plot out.png]
    geardyn plot RESULT.nc|map.zarr [--out fig.png|fig.pdf] [--state X_sq] [--sweep up|down]

Unset options come from the study's ``[sweep]`` table (param, range, continuation, samples,
lyapunov) and ``[run]`` table (transient or transient_periods, steps_per_period, omega, converge,
transient_max, continued_transient, max_period, period_tol, and periods as the default number of
samples). A progress bar is drawn when stderr is a terminal (``--quiet``: never).
"""

from __future__ import annotations

import contextlib
import math
import sys
import time
from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from geardyn.cli.common import (
    ESTIMATE_POINTS,
    MAX_COUNT,
    InterpretationOption,
    NetCDFOutOption,
    PlotOption,
    QuietOption,
    SamplesOption,
    StepsOption,
    TransientOption,
    YesOption,
    check_continuation,
    check_count,
    check_plot_path,
    check_run_cost,
    continuation_option,
    load_study_source,
    make_parents,
    run_option,
    run_options,
    stderr_console,
    study_run_settings,
    write_outputs,
)
from geardyn.core.results import SCHEMAS
from geardyn.core.settings import OMEGA_RULE, SWEEP_DIRECTIONS, check_omega, usable_omega
from geardyn.errors import ParameterError, StudyError
from geardyn.study import build_model, study_omega

__all__ = ["bifurcation_command", "parse_range", "plot_command", "register"]


#: The sweep a reproduction case file's figure draws.
SweepDirection = StrEnum("SweepDirection", [(d, d) for d in SWEEP_DIRECTIONS])


def parse_range(text: str, option: str = "--range") -> tuple[float, float, int]:
    """``START:STOP:NUM`` -> (start, stop, num): NUM >= 2 evenly spaced values, START != STOP."""
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 3:
        raise ParameterError(option, text, "expected START:STOP:NUM, e.g. 0.1:4:1000")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise ParameterError(option, text, "START and STOP must be numbers") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise ParameterError(option, text, "START and STOP must be finite")
    if start == stop:
        raise ParameterError(option, text, "START and STOP must differ")
    try:
        num = int(parts[2])
    except ValueError:
        raise ParameterError(option, text, "NUM must be a whole number of values") from None
    if not 2 <= num <= MAX_COUNT:
        raise ParameterError(option, text, f"NUM must be >= 2 and <= 2**53 = {MAX_COUNT}")
    return start, stop, num


def _sweepable(model) -> list[str]:
    """Names a sweep of ``model`` accepts, for error messages: Omega and its physical names,
    then (a model that takes its input coefficients too, e.g. the spur pair's torque) its input
    coefficients."""
    if model.capabilities.physical_inputs:  # models with named physical inputs
        return ["Omega", *model.physical_names]
    layout = model.coefficient_layout
    return ["Omega", *model.physical_names,
            *(n for n in model.param_names
              if n != "Omega" and layout.slot(n).coefficient.kind == "input")]


def sweep_vocabulary(model) -> list[tuple[str, str]]:
    """The names a sweep of ``model`` takes (:func:`_sweepable`), each with the unit of its axis
    where the model declares its inputs (:attr:`~geardyn.core.model.Model.input_declarations`:
    ``("sun_backlash", "m")``); else the unit is empty."""
    declared = bool(model.input_declarations)
    return [(n, model.param_attrs(n).get("units", "") if declared and n != "Omega" else "")
            for n in _sweepable(model)]


def _check_param_name(model, param: str) -> None:
    """A one-line error naming ``--param`` unless ``model`` can sweep ``param`` (the known
    names listed with their units, :func:`sweep_vocabulary`)."""
    known = _sweepable(model)
    try:
        ok = param in known or model.lane_params(param, [1.0]).shape[0] == 1
    except KeyError:
        ok = False
    if not ok:
        names = ", ".join(f"{n} [{u}]" if u else n for n, u in sweep_vocabulary(model))
        raise ParameterError("--param", param, f"not a parameter of {model.name}; known: {names}")


def _check_param_values(model, param: str, ends: tuple[float, float], range_text: str) -> None:
    """A one-line error naming ``--range`` unless ``param`` accepts both ends of the range and
    they give finite coefficients (and a positive Omega)."""
    import numpy as np

    from geardyn.cli.errors import format_error

    for value in ends:
        try:
            with np.errstate(all="ignore"):
                P = model.lane_params(param, [value])
        except (ArithmeticError, ValueError) as exc:  # pydantic's ValidationError included
            raise StudyError(f"--range: {param} = {value:g} in {range_text!r}: "
                             f"{format_error(exc)}") from None
        if not np.all(np.isfinite(P)):
            raise StudyError(f"--range: {param} = {value:g} in {range_text!r} makes the model's"
                             " coefficients infinite (the value is too extreme)")
        w = P[0, model.omega_index] if model.omega_index is not None else 1.0
        if not usable_omega(w):
            what = "" if param == "Omega" else f" at {param} = {value:g}"
            raise ParameterError("--range", range_text, f"Omega = {w:g}{what}: {OMEGA_RULE}")


def _lowest_omega(model, param: str, ends: tuple[float, float], hold: str) -> float | None:
    """The lowest forcing frequency Omega at the ends of a sweep of ``param`` (what
    ``[run].transient_periods`` counts periods of); None for a model without one."""
    if model.omega_index is None:
        return None
    if param == "Omega":
        return min(ends)
    from geardyn.analysis.bifurcation import lane_params_held

    if hold != "speed" or not model.capabilities.frequency_scale:
        hold = "Omega"  # a bad --hold is refused with its own message below
    return float(min(lane_params_held(model, param, list(ends), hold)[:, model.omega_index]))


def _check_state(names, state: str, option: str) -> str:
    for candidate in (state, f"{state}1"):
        if candidate in names:
            return candidate
    raise ParameterError(option, state, f"not a state of the model; known: {', '.join(names)}")


def _stderr_is_terminal() -> bool:
    return sys.stderr.isatty()


@contextlib.contextmanager
def _progress_bar(show: bool, label: str):
    """A rich progress bar on stderr fed by ``callback(done, total)``; None when not shown."""
    if not show:
        yield None
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=stderr_console(), transient=True) as bar:
        task = bar.add_task(label, total=None)

        def callback(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        yield callback


def _summary(ds) -> str:
    import numpy as np

    period = ds["period"].values
    parts = [f"period-{k} {int(np.sum(period == k))}" for k in (1, 2, 3, 4)
             if np.any(period == k)]
    if np.any(period >= 5):
        parts.append(f"period>=5 {int(np.sum(period >= 5))}")
    parts.append(f"no period <= {ds['period'].attrs.get('max_period', 16)} "
                 f"{int(np.sum(period == 0))}")
    parts.append(f"unbounded {int(np.sum(period == -1))}")
    return ", ".join(parts)


def bifurcation_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    param: Annotated[
        str | None, typer.Option(help="Swept parameter: Omega or a parameter of the study's "
                                      "model (an unknown name lists them, with their units; "
                                      "default: sweep.param).")
    ] = None,
    range_: Annotated[
        str | None,
        typer.Option("--range", help="START:STOP:NUM, NUM evenly spaced values (default: the "
                                     "study's sweep table); SI units for the device's parameters,"
                                     " a spur pair's speed in its params.speed_unit."),
    ] = None,
    continuation: Annotated[
        str | None,
        continuation_option("none: every point from the same start; up/down: each from the "
                            "previous point's final state (default: sweep.continuation)."),
    ] = None,
    lyapunov: Annotated[
        bool | None,
        typer.Option("--lyapunov/--no-lyapunov", help="Largest Lyapunov exponent per point "
                                                      "(default: sweep.lyapunov)."),
    ] = None,
    transient: TransientOption = None,
    converge: run_option("converge", "up to 10x --transient, e.g. 1e-8; "
                          "default: run.converge") = None,
    continued_transient: run_option("continued_transient", "with --continuation; the first "
                                     "point gets --transient; default: --transient") = None,
    samples: SamplesOption = None,
    steps_per_period: StepsOption = None,
    omega: Annotated[
        float | None, typer.Option(help="The fixed Omega when sweeping another parameter "
                                        "(default: run.omega).")
    ] = None,
    hold: Annotated[
        str, typer.Option(help="What a sweep of another parameter holds fixed: Omega (the "
                               "dimensionless frequency) or speed (the physical mesh frequency "
                               "Omega omega_n of the study's device: each point runs at "
                               "Omega omega_n / omega_n(point), e.g. for Km_sq).")
    ] = "Omega",
    interpretation: InterpretationOption = None,
    state: Annotated[
        str | None, typer.Option(help="State drawn (default: the study's plot_state).")
    ] = None,
    quiet: QuietOption = False,
    yes: YesOption = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
) -> None:
    """Sweep one parameter of a study: bifurcation diagram, periods, contact loss.

    At every value: the Poincaré points, the period, the contact-loss regime of every mesh, the
    dynamic factor and, with --lyapunov, the largest Lyapunov exponent; saved as NetCDF and drawn.
    """
    import numpy as np

    check_continuation(continuation)
    s = load_study_source(study)
    sweep = s.sweep
    name = param or (sweep.param if sweep is not None else "Omega")
    if omega is not None:  # [run].omega: the same rule, when the study was read
        check_omega(omega, "--omega")
    om = omega if omega is not None else s.run.omega
    interp = interpretation.value if interpretation is not None else None
    model = build_model(s, interpretation=interp, omega=om)
    _check_param_name(model, name)
    om = study_omega(s, model, om)
    if range_ is not None:
        start, stop, num = parse_range(range_)
        range_text = range_
    elif sweep is not None and sweep.param == name:
        start, stop, num = sweep.start, sweep.stop, sweep.num
        range_text = f"{start:g}:{stop:g}:{num}"
    else:
        why = "the study has no [sweep]" if sweep is None else f"the study sweeps {sweep.param}"
        raise StudyError(f"--range: not given, and {why}")
    if name != "Omega" and om is None:
        raise StudyError(f"--omega: not given, and a sweep of {name} needs a fixed Omega "
                         "(or [run].omega in the study)")
    _check_param_values(model, name, (start, stop), range_text)
    cont = (continuation if continuation is not None
            else sweep.continuation if sweep is not None else "none")
    lyap = lyapunov if lyapunov is not None else bool(sweep is not None and sweep.lyapunov)
    run = study_run_settings(
        s, run_options(transient=transient, samples=samples, steps_per_period=steps_per_period,
                       converge=converge, continued_transient=continued_transient),
        sweep=True, omega=lambda: _lowest_omega(model, name, (start, stop), hold),
        least={"samples": (2, "the period needs two")})
    tr, n_samples, spp = run.transient, run.samples, run.steps_per_period
    if converge is not None and not converge < 1:
        raise ParameterError("--converge", converge, "must be a tolerance in (0, 1)")
    if continued_transient is not None and cont == "none":  # [run]'s: for continued sweeps
        raise ParameterError("--continued-transient", continued_transient,
                             "applies to --continuation up or down")
    if hold not in ("Omega", "speed"):
        raise ParameterError("--hold", hold, "must be Omega or speed")
    if hold == "speed" and name in ("Omega", "Lambda"):
        raise ParameterError("--hold", hold, f"speed holds the physical speed while another "
                             f"parameter is swept; {name} is a speed itself")
    if hold == "speed" and not model.capabilities.frequency_scale:
        raise ParameterError("--hold", hold, f"{model.name} has no physical frequency omega_n")
    check_count("--samples", n_samples)
    if spp is not None:
        check_count("--steps-per-period", spp)
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")
    check_plot_path("--plot", plot)
    plot_state = _check_state(model.state_names, state or s.plot_state,
                              "--state" if state else "study.plot_state")
    # the cost is estimated before anything of the sweep's size is built; with --converge the
    # transient may run to 10x --transient
    omegas = (np.linspace(start, stop, min(num, ESTIMATE_POINTS)) if name == "Omega"
              else [model.omega])
    check_run_cost(model, num, omegas, tr if run.converge is None else run.transient_limit,
                   n_samples, spp, lyap,
                   chunk=num, yes=yes, option="--range/--samples/--transient/--steps-per-period",
                   value=f"{range_text}, {n_samples} samples, transient {tr:g}, "
                         f"{spp or 'automatic'} steps/period", what="sweep")
    values = np.linspace(start, stop, num)
    make_parents(out, plot)

    from geardyn.analysis.bifurcation import bifurcation

    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _progress_bar(show_bar, escape(f"{s.study.name}: {name}")) as callback:
        ds = bifurcation(model, name, values, run,
                         continuation=None if cont == "none" else cont,
                         lyapunov=lyap, progress=callback, hold=hold)
    elapsed = time.perf_counter() - t0

    def draw(path: Path) -> None:
        from geardyn.plotting.bifurcation import plot_bifurcation

        plot_bifurcation(ds, state=plot_state, path=path)

    wrote = write_outputs(ds, out, plot, draw, study=s.study.name, plot_state=plot_state,
                          wall_time_s=round(elapsed, 3))
    typer.echo(
        f"{s.study.name}: {num} values of {name} in [{start:g}, {stop:g}], continuation {cont}, "
        f"{elapsed:.1f} s: {_summary(ds)}{wrote}"
    )


def _stateless(label: str, draw: Callable[[Any, Path], None], figure: str = ""
               ) -> Callable[..., str]:
    """The redraw of a figure of ``label`` that shows no state: ``draw(ds, path)``; a
    ``--state`` is refused naming the ``figure`` (default: a <label> figure)."""
    def redraw(ds: Any, target: Path, state: str | None, sweep: SweepDirection) -> str:
        if state is not None:
            raise ParameterError("--state", state, f"{figure or f'a {label} figure'} shows no"
                                 " state; leave it out")
        make_parents(target)
        draw(ds, target)
        return f"{label} dataset"
    return redraw


def _plot_map(ds: Any, path: Path) -> None:
    from geardyn.plotting.map2d import plot_map

    plot_map(ds, path=path)


def _plot_basins(ds: Any, path: Path) -> None:
    from geardyn.plotting.basins import plot_basins

    plot_basins(ds, path=path)


def _plot_frc(ds: Any, path: Path) -> None:
    from geardyn.plotting.frc import plot_frc

    plot_frc(ds, path=path)


def _plot_stiffness(ds: Any, path: Path) -> None:
    from geardyn.plotting.stiffness import plot_mesh_stiffness

    plot_mesh_stiffness(ds, path=path)


def _plot_dynamic_factor(ds: Any, path: Path) -> None:
    from geardyn.plotting.dynamic_factor import plot_dynamic_factor

    plot_dynamic_factor(ds, path=path)


def _plot_curve(ds: Any, path: Path) -> None:
    from geardyn.plotting.envelope import plot_curves

    plot_curves([ds], path=path)


def _plot_simulation(ds: Any, state: str, path: Path) -> None:
    from geardyn.plotting.simulation import plot_simulation

    plot_simulation(ds, state=state, path=path)


def _plot_bifurcation(ds: Any, state: str, path: Path) -> None:
    from geardyn.plotting.bifurcation import plot_bifurcation

    plot_bifurcation(ds, state=state, path=path)


def _redraw_runup(ds: Any, target: Path, state: str | None, sweep: SweepDirection) -> str:
    from geardyn.analysis.orders import waterfall
    from geardyn.plotting.orders import plot_waterfall

    recorded = ds.attrs["outputs"].split(",")
    forces = [o for o in ds.attrs.get("observables", "").split(",") if o]
    shown = _check_state(recorded, state or (forces or recorded)[0], "--state")
    make_parents(target)
    plot_waterfall(waterfall(ds, shown), ds, path=target)
    return f"run-up dataset ({shown})"


def _redraw_continuation(ds: Any, target: Path, state: str | None,
                         sweep: SweepDirection) -> str:
    from geardyn.plotting.branch import plot_branch

    names = [str(v) for v in ds["state"].values]
    shown = _check_state(names, state, "--state") if state is not None else None
    make_parents(target)
    plot_branch(ds, path=target, state=shown)
    return "continuation dataset"


def _of_state(label: str, draw: Callable[[Any, str, Path], None], sweeps: bool = False
              ) -> Callable[..., str]:
    """The redraw of a figure of one state, ``draw(ds, state, path)``: the state given, else
    the one the dataset names (``plot_state``), else X_sq or x, else its first; ``sweeps``: a
    reproduction case's, of the sweep ``--sweep``."""
    def redraw(ds: Any, target: Path, state: str | None, sweep: SweepDirection) -> str:
        if sweeps:
            attrs = dict(ds.attrs, continuation=sweep.value)
            ds = ds.sel(sweep=sweep.value, drop=True)
            ds.attrs = attrs
        names = [str(v) for v in ds["state"].values]
        default = ds.attrs.get("plot_state") or next(
            (n for n in ("X_sq", "x") if n in names), names[0])
        shown = _check_state(names, state or default, "--state")
        make_parents(target)
        draw(ds, shown, target)
        return f"{label} dataset"
    return redraw


#: How ``geardyn plot`` redraws each kind of result, by its name in messages (the result
#: schema's, :attr:`geardyn.core.results.ResultSchema.name`; ``"mesh stiffness"``, a dataset of
#: :func:`geardyn.gears.potential_energy_stiffness`, has no schema): ``(dataset, figure path,
#: --state, --sweep) -> what was drawn``.
REDRAWS: dict[str, Callable[..., str]] = {
    "simulation": _of_state("simulation", _plot_simulation),
    "bifurcation": _of_state("bifurcation", _plot_bifurcation),
    "reproduction": _of_state("reproduction", _plot_bifurcation, sweeps=True),
    "map": _stateless("map", _plot_map, figure="a map"),
    "basins": _stateless("basins", _plot_basins),
    "frequency response": _stateless("frequency response", _plot_frc),
    "mesh stiffness": _stateless("mesh stiffness", _plot_stiffness),
    "dynamic factor": _stateless("dynamic factor", _plot_dynamic_factor),
    "curve": _stateless("curve", _plot_curve),
    "run-up": _redraw_runup,
    "continuation": _redraw_continuation,
}

#: What ``geardyn plot`` calls each result kind it redraws (``attrs["geardyn_kind"]``).
_PLOT_KIND = {kind: s.name for kind, s in SCHEMAS.items() if s.name in REDRAWS}


def _dataset_kind(ds) -> str:
    """``"simulation"``, ``"bifurcation"``, ``"map"`` or ``"reproduction"`` (what
    :func:`geardyn.simulate`, :func:`geardyn.bifurcation`, :func:`geardyn.map2d` or
    ``geardyn reproduce`` wrote): the kind the dataset records (``attrs["geardyn_kind"]``),
    checked by :func:`geardyn.testing.assert_result`; for a file written before the kind was
    recorded, guessed from its variables; else a one-line error."""
    from geardyn.testing import assert_result

    source = ds.encoding.get("source", "?")
    kind = ds.attrs.get("geardyn_kind")
    if kind is None:
        return _guess_kind(ds, source)
    if kind not in _PLOT_KIND:
        raise ParameterError("RESULT", source, f"unknown result kind {kind!r}")
    try:
        assert_result(ds, kind)
    except AssertionError as exc:
        raise ParameterError("RESULT", source, str(exc)) from None
    return _PLOT_KIND[kind]


def _guess_kind(ds, source: str) -> str:
    """The kind of a result saved without ``attrs["geardyn_kind"]``, from its variables."""
    if "poincare" in ds and "time" in ds.dims:
        return "simulation"
    param = ds.attrs.get("param")
    if "poincare" in ds and "period" in ds and param in ds.dims:
        return "reproduction" if "sweep" in ds.dims else "bifurcation"
    if "period" in ds and "x" in ds.attrs and "y" in ds.attrs:
        return "map"
    if "mesh_stiffness" in ds and "mesh_stiffness_coast" in ds and "angle" in ds.dims:
        return "mesh stiffness"  # geardyn stiffness, geardyn.gears.potential_energy_stiffness
    raise ParameterError("RESULT", source, "not a geardyn simulation, bifurcation, map, "
                         "reproduction or mesh stiffness dataset (no attrs['geardyn_kind'], and "
                         "its variables match none)")


def _load_result(result: Path):
    """A saved result: a NetCDF file, or a map's Zarr store (a folder ending in .zarr)."""
    from geardyn.io.netcdf import load_dataset

    if result.suffix.lower() == ".zarr" and result.is_dir():
        from geardyn.execution.zarr_store import load_zarr_dataset

        reader, what = load_zarr_dataset, "a finished map's Zarr store"
    else:
        reader, what = load_dataset, "NetCDF"
    try:
        return reader(result)
    except FileNotFoundError:
        raise
    except (OSError, ValueError, KeyError) as exc:  # name the file, not only the reason
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise ParameterError("RESULT", str(result), f"cannot read it as {what} ({reason})") \
            from None


def plot_command(
    result: Annotated[Path, typer.Argument(help="A NetCDF file written by geardyn simulate, "
                                                "bifurcation, map, reproduce, basins, frc, "
                                                "continue, stiffness, runup, envelope or "
                                                "dynamic-factor, or a map's .zarr store.")],
    out: Annotated[
        Path | None, typer.Option(help="Figure to write, .png, .pdf or .svg (default: RESULT "
                                       "with .png).")
    ] = None,
    state: Annotated[
        str | None, typer.Option(help="State drawn (default: the one saved with the result).")
    ] = None,
    sweep: Annotated[
        SweepDirection, typer.Option(help="A reproduction case file: the sweep drawn.")
    ] = SweepDirection.up,
) -> None:
    """Redraw the figure of a saved simulation, bifurcation, map, reproduction case, basins,
    frequency response, continued branch, two-parameter curve, run-up, dynamic factor or mesh
    stiffness."""
    target = out if out is not None else result.with_suffix(".png")
    check_plot_path("--out", target)
    ds = _load_result(result)
    drawn = REDRAWS[_dataset_kind(ds)](ds, target, state, sweep)
    typer.echo(f"{result}: {drawn}; wrote {target}")


def register(app: typer.Typer) -> None:
    """Add ``geardyn bifurcation`` and ``geardyn plot`` to the command line ``app``."""
    app.command("bifurcation")(bifurcation_command)
    app.command("plot")(plot_command)
