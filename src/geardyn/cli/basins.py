"""``geardyn basins``: the basins of attraction of a study at one forcing frequency.

::

    geardyn basins STUDY.toml --omega W --x X_sq:LO:HI:N --y V_sq:LO:HI:N
                   [--transient T] [--samples N] [--converge TOL] [--steps-per-period N]
                   [--orbit-period K] [--interpretation ...] [--quiet] [--yes]
                   [--out basins.nc] [--plot basins.png]

An axis is ``STATE:LO:HI:N``: N evenly spaced initial values of one of the model's states (the
other states start at the model's initial state). ``--orbit-period K`` also computes the
period-1..K orbits by Newton shooting from each attractor's section point and matches them
(``attractor_orbit``). A progress bar is drawn when stderr is a terminal.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from geardyn.cli.common import (
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
from geardyn.io.study_models import study_model
from geardyn.study import build_model, study_omega

__all__ = ["basins_command", "register"]


def _state_axis(text: str, option: str, names: tuple[str, ...]) -> tuple[str, float, float, int]:
    from geardyn.cli.map import parse_axis

    name, lo, hi, n = parse_axis(text, option)
    if name not in names:
        raise ParameterError(option, name, f"not a state of the model; known: {', '.join(names)}")
    return name, lo, hi, n


def basins_command(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    x: Annotated[str, typer.Option("--x", help="x axis STATE:LO:HI:N, e.g. X_sq:-2:2:200")],
    y: Annotated[str, typer.Option("--y", help="y axis STATE:LO:HI:N, e.g. V_sq:-2:2:200")],
    omega: Annotated[
        float | None, typer.Option(help="Mesh frequency Omega (default: the study's run.omega; "
                                        "a spur_pair study's: from its params.speed).")
    ] = None,
    transient: run_option("transient", "the least per cell; default: run.transient") = None,
    samples: run_option("samples", "per cell; default: 2 max_period + 2") = None,
    converge: run_option("converge", "default 1e-8") = None,
    steps_per_period: StepsOption = None,
    orbit_period: Annotated[
        int, typer.Option(help="Match the attractors to Newton-shooting orbits of period <= K "
                               "(0: none).")
    ] = 0,
    interpretation: InterpretationOption = None,
    quiet: QuietOption = False,
    yes: YesOption = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
) -> None:
    """The attractor reached from every initial condition of a grid of two states; save the
    basins (NetCDF) and draw them."""
    from geardyn.analysis.basins import CONVERGE, SAMPLES_PER_PERIOD, basins
    from geardyn.cli.bifurcation import _progress_bar, _stderr_is_terminal

    s = load_study_source(study)
    interp = interpretation.value if interpretation is not None else None
    om = omega if omega is not None else s.run.omega
    base = None
    if om is None and study_model(s.study.model).omega_from_params:
        base = build_model(s, interpretation=interp)
        om = study_omega(s, base)
    if om is None:
        raise StudyError("--omega: not given, and the study has no run.omega")
    check_omega(om, "--omega")
    if out is not None and out.suffix.lower() != ".nc":
        raise ParameterError("--out", str(out), "suffix must be .nc (NetCDF)")
    check_plot_path("--plot", plot)
    if orbit_period < 0:
        raise ParameterError("--orbit-period", orbit_period, "must be >= 0")
    model = base if base is not None else build_model(s, interpretation=interp, omega=om)
    x_axis = _state_axis(x, "--x", model.state_names)
    y_axis = _state_axis(y, "--y", model.state_names)
    if x_axis[0] == y_axis[0]:
        raise ParameterError("--y", y, "must name another state than --x")
    if samples is not None:
        check_count("--samples", samples)
    # basins' own defaults: convergence CONVERGE, samples enough for the longest period
    options = run_options(transient=transient, samples=samples,
                          steps_per_period=steps_per_period, converge=converge)
    first = study_run_settings(s, options, omega=om, defaults={"converge": CONVERGE})
    run = study_run_settings(s, options, omega=om, defaults={
        "converge": CONVERGE, "samples": SAMPLES_PER_PERIOD * first.max_period + 2},
        least={"samples": (2, "the period needs two")})
    tr, n_samples, spp = run.transient, run.samples, run.steps_per_period
    lanes = x_axis[3] * y_axis[3]
    check_run_cost(model, lanes, [om], 10 * tr, n_samples, spp, False, yes=yes,
                   option="--x/--y/--transient", value=f"{x} x {y}, transient {tr:g}",
                   what="basins")
    make_parents(out, plot)

    show_bar = not quiet and _stderr_is_terminal()
    t0 = time.perf_counter()
    with _progress_bar(show_bar, escape(f"{s.study.name}: basins")) as callback:
        ds = basins(model, om, x_axis, y_axis, run, progress=callback)
    if orbit_period:
        ds = _with_orbits(model, om, ds, orbit_period)
    elapsed = time.perf_counter() - t0

    def draw(path: Path) -> None:
        from geardyn.plotting.basins import plot_basins

        plot_basins(ds, path=path)

    wrote = write_outputs(ds, out, plot, draw, study=s.study.name,
                          wall_time_s=round(elapsed, 3))
    typer.echo(f"{s.study.name}: basins at Omega = {om:g}, {lanes} cells, {elapsed:.1f} s: "
               f"{_summary(ds)}{wrote}")


def _with_orbits(model, om, ds, k_max: int):
    """The basins matched to the orbits found by Newton shooting from each periodic
    attractor's section point (period <= k_max)."""
    from geardyn.analysis.basins import match_orbits
    from geardyn.analysis.orbits import periodic_orbit

    orbits = []
    for a in range(ds.sizes["attractor"]):
        k = int(ds["section_period"].values[a])  # sections, as periodic_orbit counts
        if 1 <= k <= k_max:
            orbits.append(periodic_orbit(model, om, period=k,
                                         guess=ds["attractor_point"].values[a, 0]))
    return match_orbits(ds, orbits)


def _summary(ds) -> str:
    parts = []
    for a in range(ds.sizes["attractor"]):
        k = int(ds["attractor_period"].values[a])
        orbit = int(ds["attractor_orbit"].values[a])
        parts.append(f"#{a} {'period-' + str(k) if k > 0 else 'no period'} "
                     f"{100 * float(ds['attractor_fraction'].values[a]):.1f}%"
                     + (f" (Newton orbit {orbit})" if orbit >= 0 else ""))
    parts.append(f"diverged {100 * float(ds.attrs['diverged_fraction']):.1f}%")
    parts.append(f"unresolved {100 * float(ds.attrs.get('unresolved_fraction', 0.0)):.1f}% "
                 "(transient unsettled or steps at the split limit)")
    return ", ".join(parts)


def register(app: typer.Typer) -> None:
    """Add ``geardyn basins`` to the command line ``app``."""
    app.command("basins")(basins_command)
