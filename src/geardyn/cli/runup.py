"""``geardyn runup``: a run-up (or run-down) of a study through a speed range, its waterfall.

::

    geardyn runup STUDY.toml [--param Omega|input_speed|mesh_frequency|speed]
                  [--start A] [--stop B] [--rate R | --duration D] [--transient T]
                  [--sample-rate FS] [--outputs x,F] [--steps-per-period N]
                  [--output F] [--window W] [--harmonics K] [--interpretation ...]
                  [--quiet] [--out runup.nc] [--plot waterfall.png] [--order-map orders.png]

Unset options come from the study's ``[runup]`` table (:class:`geardyn.io.runup_table.
RunupTable`); ``--start`` and ``--stop`` are in ``--param``'s units (rpm for ``input_speed``),
``--rate`` in them per model time unit. Without a sample rate the run is sampled fast enough
for the drawn harmonics (4 samples per period of mesh harmonic ``harmonics + 1`` at the top
speed).
A progress bar is drawn when stderr is a terminal.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from geardyn.cli.common import (
    InterpretationOption,
    NetCDFOutOption,
    PlotOption,
    QuietOption,
    check_plot_path,
    load_study_source,
    make_parents,
    runup_option,
    write_outputs,
)
from geardyn.errors import ParameterError, StudyError
from geardyn.study import build_model

__all__ = ["register", "runup_command"]

#: Samples per period of the highest frequency drawn when no sample rate is given.
SAMPLES_PER_TOP_PERIOD = 4.0


def _float_option(help_: str) -> Any:
    return Annotated[float | None, typer.Option(help=help_)]


def runup_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    param: Annotated[str | None, typer.Option(help="The ramped frequency: Omega, or "
                                                   "input_speed [rpm], mesh_frequency [rad/s] "
                                                   "or a spur pair's speed (default: "
                                                   "runup.param, else Omega).")] = None,
    start: _float_option("Start value of --param (default: runup.start).") = None,
    stop: _float_option("Stop value of --param (default: runup.stop).") = None,
    rate: _float_option("Ramp rate: --param per model time unit (or --duration).") = None,
    duration: runup_option("duration", "or --rate") = None,
    transient: runup_option("transient", "default: runup.transient, else 0") = None,
    sample_rate: runup_option("sample_rate", "default: runup.sample_rate, else enough for the "
                                             "drawn harmonics") = None,
    outputs: Annotated[str | None, typer.Option(help="Comma-separated states and observables "
                                                     "recorded (default: all).")] = None,
    steps_per_period: runup_option("steps_per_period", "default: the step rule") = None,
    output: Annotated[str | None, typer.Option(help="The output the waterfall analyses "
                                                    "(default: the first mesh force, else "
                                                    "the first state).")] = None,
    window: _float_option("Waterfall window [model time units] (default: 1/32 of the run).")
    = None,
    harmonics: Annotated[int | None, typer.Option(help="Order rays drawn (default 4).")] = None,
    interpretation: InterpretationOption = None,
    quiet: QuietOption = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
    order_map: Annotated[Path | None, typer.Option(
        help="Order map figure to write (.png, .pdf or .svg).")] = None,
) -> None:
    """A run-up (or run-down): the speed ramped through a range, the forcing phase its integral;
    writes the time history (NetCDF) and its waterfall with the mesh orders and natural
    frequencies (Campbell-style figure)."""
    from geardyn.analysis.orders import order_spectrum, waterfall
    from geardyn.analysis.runup import frequency_scale, runup
    from geardyn.cli.bifurcation import _progress_bar, _stderr_is_terminal

    s = load_study_source(study)
    table = s.runup
    check_plot_path("--plot", plot)
    check_plot_path("--order-map", order_map)
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")

    def pick(value: Any, key: str, default: Any = None) -> Any:
        """The option's value, else the study's [runup] value, else ``default``."""
        if value is not None:
            return value
        written = getattr(table, key) if table is not None else None
        return default if written is None else written

    name = pick(param, "param", "Omega")
    a, b = pick(start, "start"), pick(stop, "stop")
    for option, v in (("--start", a), ("--stop", b)):
        if v is None:
            why = "the study has no [runup]" if table is None else "runup has none"
            raise StudyError(f"{option}: not given, and {why}")
    if rate is not None or duration is not None:  # the command line's ramp wins whole
        ramp_rate, ramp_time = rate, duration
    else:
        ramp_rate, ramp_time = pick(None, "rate"), pick(None, "duration")
    n_harm = pick(harmonics, "harmonics", 4)
    if isinstance(n_harm, bool) or not isinstance(n_harm, int) or not 1 <= n_harm <= 40:
        raise ParameterError("--harmonics", n_harm, "must be an integer from 1 to 40")
    interp = interpretation.value if interpretation is not None else None
    model = build_model(s, interpretation=interp)
    per = _omega_per_unit(model, name, float(a), float(b))
    wanted = outputs.split(",") if outputs is not None else pick(None, "outputs")
    fs = pick(sample_rate, "sample_rate")
    top = max(a, b) * per
    if fs is None:
        fs = SAMPLES_PER_TOP_PERIOD * (n_harm + 1) * frequency_scale(model)[1] * top / (
            2.0 * math.pi)
    settings = _settings(
        start=a * per, stop=b * per,
        rate=None if ramp_rate is None else _number("--rate", ramp_rate) * per,
        duration=ramp_time, transient=pick(transient, "transient", 0.0),
        sample_rate=fs, outputs=None if wanted is None else tuple(wanted),
        steps_per_period=pick(steps_per_period, "steps_per_period"))
    plotted = pick(output, "output") or _default_output(model, settings.outputs)
    recorded = settings.outputs or (*model.state_names, *model.observable_names)
    if plotted not in recorded:
        raise ParameterError("--output", plotted, f"not a recorded output (recorded: "
                             f"{', '.join(recorded)})")
    make_parents(out, plot, order_map)
    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _progress_bar(show_bar, escape(f"{s.study.name}: run-up")) as callback:
        ds = runup(model, settings, progress=callback)
    elapsed = time.perf_counter() - t0
    diverged = ds.attrs["status"] != 0
    if diverged:  # the run is kept (marked by its status); its spectra have no meaning
        plot = order_map = None
    wf = waterfall(ds, plotted, window=pick(window, "window")) if plot is not None else None

    def draw(path: Path) -> None:
        from geardyn.plotting.orders import plot_waterfall

        plot_waterfall(wf, ds, harmonics=n_harm, path=path)

    wrote = write_outputs(ds, out, plot, draw, study=s.study.name,
                          wall_time_s=round(elapsed, 3))
    if order_map is not None:
        from geardyn.plotting.orders import plot_order_map

        plot_order_map(order_spectrum(ds, plotted), path=order_map,
                       max_order=(n_harm + 0.5) * ds.attrs["mesh_order"])
        wrote += f", {order_map}" if "wrote" in wrote else f"; wrote {order_map}"
    state = f"diverged at t = {_diverged_at(ds):.6g}, no figure" if diverged else "ok"
    typer.echo(f"{s.study.name}: run-up of {name} {a:g} -> {b:g} (Omega {settings.start:.6g}"
               f" -> {settings.stop:.6g}) over {settings.ramp_duration:.6g} time units, "
               f"{ds.sizes['time']} samples, {state}, {elapsed:.1f} s{wrote}")


def _number(option: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ParameterError(option, value, "must be a finite number")
    return float(value)


def _settings(**kw: Any):
    """:class:`RunupSettings` from the options, its errors naming the option."""
    from geardyn.analysis.runup import RunupSettings

    try:
        return RunupSettings(**kw)
    except ParameterError as exc:
        option = "--" + exc.field.replace("_", "-")
        raise ParameterError(option, exc.value, exc.reason) from None


def _omega_per_unit(model, name: str, a: float, b: float) -> float:
    """Omega per unit of ``name`` (1 for Omega), the same at both ends (Omega proportional to
    it), else a one-line error naming --param."""
    if name == "Omega":
        return 1.0
    try:
        ratios = [model.with_params(**{name: v}).omega / v for v in (a, b) if v > 0]
    except KeyError as err:
        raise ParameterError("--param", name, f"{model.name} has no such parameter ({err})") \
            from None
    if not ratios or (len(ratios) == 2 and abs(ratios[0] / ratios[1] - 1.0) > 1e-9):
        raise ParameterError("--param", name, "Omega is not proportional to it; ramp Omega")
    return float(ratios[0])


def _default_output(model, outputs) -> str:
    names = outputs or (*model.state_names, *model.observable_names)
    forces = [o for o in names if o in model.observable_names]
    return forces[0] if forces else names[0]


def _diverged_at(ds) -> float:
    import numpy as np

    bad = np.flatnonzero(~np.isfinite(ds[ds.attrs["outputs"].split(",")[0]].values))
    return float(ds["time"].values[bad[0]]) if bad.size else float("nan")


def register(app: typer.Typer) -> None:
    """Add ``geardyn runup`` to the command line ``app``."""
    app.command("runup")(runup_command)
