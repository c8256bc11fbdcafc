"""``geardyn continue``: pseudo-arclength continuation of a study's periodic orbit.

::

    geardyn continue STUDY.toml [--param Omega] [--range 0.5:4] [--period K] [--switch]
                     [--max-period N] [--omega W] [--transient T] [--steps-per-period N]
                     [--max-points N] [--over bifurcation.nc] [--quantity section|deflection_max|
                     deflection_rms|...] [--state X_sq] [--mesh NAME] [--interpretation ...]
                     [--quiet] [--out branch.nc] [--plot branch.png]

Unset options come from the study: ``--param`` and ``--range`` from its ``[sweep]`` (start, stop),
``--omega`` (the fixed Omega of a branch in another parameter), ``--steps-per-period`` and the
first orbit's transient (``transient`` or ``transient_periods``, ``converge``, ``transient_max``)
from ``[run]``. A branch that ends early (most points, corrector failure, the parameter leaving the
model's valid region, divergence, no orbit at the start) is still written, its status and
message in the file (``branch_status``, ``branch_message``) and printed on stderr; the exit
status is 0. A branch that reached the range's end or returned onto its own points (it retraces
itself) is complete. A progress bar (the parameter's way through the range) is drawn when stderr
is a terminal.
"""

from __future__ import annotations

import contextlib
import math
import time
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from geardyn.cli.common import (
    InterpretationOption,
    MaxPeriodOption,
    MaxPointsOption,
    NetCDFOutOption,
    PlotOption,
    QuietOption,
    StepsOption,
    check_count,
    check_plot_path,
    load_study_source,
    make_parents,
    named_options,
    run_option,
    run_options,
    settings_from_options,
    stderr_console,
    study_run_settings,
    write_outputs,
)
from geardyn.errors import ParameterError, StudyError
from geardyn.io.toml import RUN_FIELDS
from geardyn.study import build_model, study_omega

__all__ = ["continue_command", "parse_span", "register"]


def parse_span(text: str, option: str = "--range") -> tuple[float, float]:
    """``START:STOP`` -> (start, stop), finite and different (a third field, a sweep's NUM, is
    accepted and ignored: the continuation picks its own steps)."""
    parts = [p.strip() for p in text.split(":")]
    if len(parts) not in (2, 3):
        raise ParameterError(option, text, "expected START:STOP, e.g. 0.5:4")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise ParameterError(option, text, "START and STOP must be numbers") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise ParameterError(option, text, "START and STOP must be finite")
    if start == stop:
        raise ParameterError(option, text, "START and STOP must differ")
    return start, stop


@contextlib.contextmanager
def _continue_bar(show: bool, label: str, param: str, start: float, stop: float):
    """A rich progress bar on stderr fed by ``callback(points, value)``: how far the parameter
    is along [start, stop] (it may go back at a fold), and the points so far. None when not
    shown."""
    if not show:
        yield None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(),
               TextColumn("{task.fields[points]} points, " + escape(param) + " = "
                          "{task.fields[value]}"), TimeElapsedColumn())
    with Progress(*columns, console=stderr_console(), transient=True) as bar:
        task = bar.add_task(label, total=1000, points=0, value=f"{start:.6g}")
        span = abs(stop - start)

        def callback(points: int, value: float) -> None:
            done = min(1.0, max(0.0, abs(value - start) / span)) if span else 1.0
            bar.update(task, completed=round(1000 * done), points=points, value=f"{value:.6g}")

        yield callback


def _load_over(path: Path, param: str):
    """The brute-force diagram drawn under the branch: a :func:`geardyn.bifurcation` NetCDF
    file of the same parameter."""
    from geardyn.cli.bifurcation import _load_result

    if not path.exists():
        raise FileNotFoundError(2, "No such file", str(path))
    ds = _load_result(path)
    kind = ds.attrs.get("geardyn_kind", "bifurcation")
    if kind != "bifurcation" or "poincare" not in ds:
        raise ParameterError("--over", str(path), f"not a bifurcation diagram (a {kind} "
                             "result); write one with geardyn bifurcation")
    swept = str(ds.attrs.get("param", ""))
    if swept != param:
        raise ParameterError("--over", str(path), f"the diagram sweeps {swept}, the branch "
                             f"follows {param}")
    return ds


#: The ``[run]`` keys a branch does not read (the step travels as a keyword without a run): a
#: study writing only these keeps the continuation's own first guess.
_NOT_READ = ("periods", "steps_per_period", "continued_transient", "max_period", "period_tol")


def _guess_run(s, model, name: str, start: float,
               transient: float | None, spp: int | None):
    """The :class:`~geardyn.RunSettings` of the branch (its first orbit's transient, the
    bound, the section limit): the options and the study's ``[run]`` table as every command
    reads them (``transient_periods`` at the start's Omega); None (the continuation's own
    default guess: 200 periods, at most 2000 time units, and the step as a keyword)
    when neither ``--transient`` nor the study file sets a run setting the branch reads
    (:data:`_NOT_READ` aside)."""
    options = run_options(transient=transient, steps_per_period=spp)
    written = [key for key in (*RUN_FIELDS, "transient_periods")
               if key not in _NOT_READ and s.run.written(key)]
    if transient is None and not written:
        return None

    def start_omega() -> float:
        return start if name == "Omega" else model.with_params(**{name: start}).omega

    return study_run_settings(s, options, omega=start_omega)


def _summary(ds) -> str:
    import numpy as np

    param = ds.attrs["param"]
    parts = []
    for b in range(ds.sizes["branch_id"]):
        on = ds["branch"].values == b
        k = int(ds["branch_period"].values[b])
        vals = ds[param].values[on]
        span = f"{vals.min():.6g}..{vals.max():.6g}" if vals.size else "-"
        stable = int(np.sum(ds["stability"].values[on] == "stable"))
        parts.append(f"branch {b} period-{k}: {int(on.sum())} points ({stable} stable) in "
                     f"{param} {span}")
    kinds = [str(k) for k in ds["bifurcation_kind"].values]
    found = ", ".join(f"{kinds.count(k)} {k}" for k in dict.fromkeys(kinds)) or "none"
    if "bifurcation_located" in ds:
        lost = int(np.sum(ds["bifurcation_located"].values == 0))
        found += f" ({lost} not located)" if lost else ""
    return "; ".join(parts) + f"; bifurcations: {found}"


def continue_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    param: Annotated[
        str | None, typer.Option(help="Continued parameter: Omega or a parameter name "
                                      "(default: sweep.param, else Omega).")
    ] = None,
    range_: Annotated[
        str | None, typer.Option("--range", help="START:STOP: the branch starts at START and "
                                                 "heads for STOP (default: the study's "
                                                 "sweep table).")
    ] = None,
    period: Annotated[int, typer.Option(help="k: the period-k orbit (in forcing periods).")] = 1,
    switch: Annotated[
        bool, typer.Option("--switch", help="At each period doubling follow the period-2k "
                                            "branch too (a cascade, up to --max-period).")
    ] = False,
    max_period: MaxPeriodOption = None,
    omega: Annotated[
        float | None, typer.Option(help="The fixed Omega of a branch in another parameter "
                                        "(default: run.omega).")
    ] = None,
    transient: run_option("transient", "of the starting guess; default: 200 periods, at "
                           "most 2000 time units") = None,
    steps_per_period: StepsOption = None,
    max_points: MaxPointsOption = None,
    over: Annotated[
        Path | None, typer.Option(help="A brute-force bifurcation diagram (NetCDF from "
                                       "geardyn bifurcation, same parameter) drawn under the "
                                       "branch.")
    ] = None,
    quantity: Annotated[
        str, typer.Option(help="What the figure shows against the parameter: section (the "
                               "section point of --state), deflection_max, deflection_rms, "
                               "deflection_amplitude, dynamic_factor, orbit_norm.")
    ] = "section",
    state: Annotated[
        str | None, typer.Option(help="State drawn with --quantity section (default: the "
                                      "study's plot_state).")
    ] = None,
    mesh: Annotated[str | None, typer.Option(help="Mesh drawn (default: the first).")] = None,
    interpretation: InterpretationOption = None,
    quiet: QuietOption = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
) -> None:
    """Follow a periodic orbit in a parameter (pseudo-arclength continuation), stable or not;
    locate its folds, branch points, period doublings, Neimark-Sacker points and contact
    changes; save the branch (NetCDF) and draw it."""
    from geardyn.analysis.branch import continuation
    from geardyn.cli.bifurcation import (
        _check_param_name,
        _check_param_values,
        _check_state,
        _stderr_is_terminal,
    )
    from geardyn.core.settings import ContinuationSettings, check_omega
    from geardyn.plotting.branch import QUANTITIES

    s = load_study_source(study)
    sweep = s.sweep
    name = param or (sweep.param if sweep is not None else "Omega")
    if omega is not None:  # [run].omega: the same rule, when the study was read
        check_omega(omega, "--omega")
    om = omega if omega is not None else s.run.omega
    if range_ is not None:
        start, stop = parse_span(range_)
        range_text = range_
    elif sweep is not None and sweep.param == name:
        start, stop = sweep.start, sweep.stop
        range_text = f"{start:g}:{stop:g}"
    else:
        why = "the study has no [sweep]" if sweep is None else f"the study sweeps {sweep.param}"
        raise StudyError(f"--range: not given, and {why}")
    if period < 1:
        raise ParameterError("--period", period, "must be >= 1")
    cset = settings_from_options(ContinuationSettings, named_options(
        ContinuationSettings, max_period=max_period, max_points=max_points))
    if cset.max_period < period:
        raise ParameterError("--max-period", cset.max_period,
                             f"must be >= --period ({period})")
    check_count("--max-points", cset.max_points)
    if quantity not in QUANTITIES:
        raise ParameterError("--quantity", quantity, f"must be one of {', '.join(QUANTITIES)}")
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")
    check_plot_path("--plot", plot)
    interp = interpretation.value if interpretation is not None else None
    model = build_model(s, interpretation=interp, omega=om)
    _check_param_name(model, name)
    om = study_omega(s, model, om)
    if name != "Omega" and om is None:
        raise StudyError(f"--omega: not given, and a branch in {name} needs a fixed Omega "
                         "(or [run].omega in the study)")
    _check_param_values(model, name, (start,), range_text)  # the stop may end the branch
    plot_state = _check_state(model.state_names, state or s.plot_state,
                              "--state" if state else "study.plot_state")
    names = [m[0] for m in model.meshes]
    if mesh is not None and mesh not in names:
        raise ParameterError("--mesh", mesh, "not a mesh of the model; meshes: "
                             + (", ".join(names) or "none"))
    if quantity != "section" and not names:
        raise ParameterError("--quantity", quantity, f"{model.name} has no backlash mesh")
    spp = s.run.steps_per_period if steps_per_period is None else steps_per_period
    run = _guess_run(s, model, name, start, transient, steps_per_period)
    over_ds = _load_over(over, name) if over is not None else None
    if over_ds is not None and quantity != "section" and not (
            quantity in over_ds and set(over_ds[quantity].dims) <= {name, "mesh"}):
        raise ParameterError("--quantity", quantity, "the --over diagram has no such variable "
                             "(its Poincaré points go with --quantity section)")
    make_parents(out, plot)

    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _continue_bar(show_bar, escape(f"{s.study.name}: period-{period} branch"), name,
                       start, stop) as callback:
        # the step: in the run where there is one (it holds spp), else the keyword
        ds = continuation(model, name, start, stop, period=period, run=run, switch=switch,
                          settings=cset, steps_per_period=spp if run is None else None,
                          progress=callback)
    elapsed = time.perf_counter() - t0

    def draw(path: Path) -> None:
        from geardyn.plotting.branch import plot_branch

        plot_branch(ds, path=path, over=over_ds, quantity=quantity, state=plot_state,
                    mesh=mesh)

    wrote = write_outputs(ds, out, plot, draw, study=s.study.name, plot_state=plot_state,
                          wall_time_s=round(elapsed, 3))
    from geardyn.analysis.branch_data import COMPLETE

    err = stderr_console()
    for b in range(ds.sizes["branch_id"]):
        if int(ds["branch_status"].values[b]) not in COMPLETE:
            err.print(f"branch {b} (period {int(ds['branch_period'].values[b])}) ended early: "
                      f"{escape(str(ds['branch_message'].values[b]))}", highlight=False,
                      soft_wrap=True)
    typer.echo(f"{s.study.name}: {name} from {start:g} to {stop:g}, {elapsed:.1f} s: "
               f"{_summary(ds)}{wrote}")


def register(app: typer.Typer) -> None:
    """Add ``geardyn continue`` to the command line ``app``."""
    app.command("continue")(continue_command)
