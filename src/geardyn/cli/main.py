"""The ``geardyn`` command line.

::

    geardyn params show [STUDY.toml] [--interpretation consistent|carrier-only|as-printed]
    geardyn params save OUT.toml
    geardyn simulate STUDY.toml --omega 1.1 [--transient T] [--periods P]
                     [--steps-per-period N] [--out run.nc] [--plot run.png]
    geardyn bifurcation STUDY.toml [--param Omega] [--range 0.1:4:1000]
                     [--continuation none|up|down] [--lyapunov] [--out out.nc] [--plot out.png]
    geardyn plot RESULT.nc [--out fig.png|fig.pdf] [--state X_sq]
    geardyn basins STUDY.toml --omega W --x X_sq:LO:HI:N --y V_sq:LO:HI:N [--out b.nc]
                   [--plot b.png]
    geardyn frc STUDY.toml [--range 0.5:1.5:201] [--branch b.nc] [--out frc.nc] [--plot frc.png]
    geardyn continue STUDY.toml --param Omega --range 0.5:4 [--period K] [--switch]
                     [--over bifurcation.nc] [--out branch.nc] [--plot branch.png]
    geardyn stiffness STUDY.toml [-o stiffness.nc] [--plot] [--figure stiffness.png] [--yes]
    geardyn dynamic-factor STUDY.toml --f-pb UM --f-falpha UM [--range 2000:44000:85]
                     [--torque T ...] [--out df.nc] [--plot df.png]
    geardyn runup STUDY.toml [--start A --stop B --rate R] [--out runup.nc] [--plot wf.png]
    geardyn dataset STUDY.toml [--store faults.zarr] [--workers N] [--chunk N]

A STUDY argument is a TOML file or the name of a built-in study (``paper_fig3``). Every expected
error (bad parameters, missing files, invalid TOML, bad values) and every usage error ends the
program with one line ``error: ...`` on stderr and exit status 2 (:class:`OneLineErrorGroup`),
however it is invoked. Shared helpers live in :mod:`geardyn.cli.common`.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from geardyn.cli.bifurcation import register as _register_bifurcation
from geardyn.cli.common import (
    EXIT_ERROR,
    EXPECTED_ERRORS,
    MAX_COUNT,
    Interpretation,
    InterpretationOption,
    NetCDFOutOption,
    OneLineErrorGroup,
    PlotOption,
    StepsOption,
    YesOption,
    check_count,
    check_plot_path,
    check_run_cost,
    load_study_source,
    make_parents,
    run_option,
    run_options,
    stderr_console,
    study_run_settings,
)
from geardyn.core.settings import check_omega
from geardyn.core.status import Status
from geardyn.errors import ParameterError, StudyError
from geardyn.io.study_models import study_model
from geardyn.study import build_model, study_omega

__all__ = ["EXIT_ERROR", "EXPECTED_ERRORS", "app", "main"]

app = typer.Typer(
    name="geardyn",
    cls=OneLineErrorGroup,
    help="Nonlinear dynamics of gear trains: the CATT planetary gear train processing device.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help is plain text: units in brackets ("[rad/s]", "[sweep]") stay
)
params_app = typer.Typer(
    help="Show the device's derived quantities, or write its parameters to a TOML file.",
    no_args_is_help=True,
    rich_markup_mode=None,
)
app.add_typer(params_app, name="params")


def _stdout() -> Console:
    # Wide tables when writing to a file or pipe; the terminal's width otherwise.
    return Console() if sys.stdout.isatty() else Console(width=130)


_stderr = stderr_console
#: A STUDY argument: a file, a built-in study name, or None for the paper's device.


def _version(value: bool) -> None:
    if value:
        from geardyn._version import __version__

        typer.echo(f"geardyn {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version."),
    ] = False,
) -> None:
    """Nonlinear dynamics of gear trains: backlash, time-varying mesh stiffness, bifurcation and
    chaos (the CATT planetary gear train processing device, and a single gear pair)."""


# ---------------------------------------------------------------------------- helpers
def _fmt(value: float) -> str:
    return f"{value + 0.0:.6g}"  # + 0.0 turns -0.0 into 0.0


def _fmt_value(value) -> str:
    import numpy as np

    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.size == 1:
        return _fmt(float(arr[0]))
    if np.all(arr == arr[0]):
        return f"{_fmt(float(arr[0]))} (each of {arr.size})"
    return ", ".join(_fmt(float(v)) for v in arr)


# ---------------------------------------------------------------------------- params
@params_app.command("show")
def params_show(
    study: Annotated[
        str | None,
        typer.Argument(help="Study TOML file or built-in study name (default: the paper's)."),
    ] = None,
    interpretation: Annotated[
        Interpretation | None,
        typer.Option(help="How to read the paper's ambiguous formulas (default: the study's)."),
    ] = None,
) -> None:
    """Print every derived quantity and dimensionless coefficient, omega_n and the natural
    frequencies."""
    s = load_study_source(study)
    interp = interpretation.value if interpretation is not None else None
    model = build_model(s, interpretation=interp)
    out = _stdout()
    out.print(f"[bold]study[/bold] {escape(s.study.name)}: "
              f"{escape(s.study.description or s.study.model)}")
    PARAMS_VIEWS[study_model(s.study.model).params_view](out, s, model)


def _show_coefficients(out: Console, s, model) -> None:
    """A model's declared dimensionless coefficients (the gear pair's)."""
    kind = study_model(s.study.model)
    table = Table(title=f"{kind.label} parameters (dimensionless)")
    table.add_column("name")
    table.add_column("value", justify="right")
    table.add_column("unit")
    table.add_column("meaning")
    block = kind.coefficients
    vocabulary = block.vocabulary() if block is not None else {}
    for name, value in model.coefficient_values().items():
        c = vocabulary.get(name)
        table.add_row(name, _fmt(float(value)), escape(c.unit if c else ""),
                      escape(c.meaning if c else ""))
    out.print(table)
    out.print("natural frequency (in contact): 1 (unit of dimensionless time)")


def _show_modes(out: Console, s, model, orders: bool = False) -> None:
    """A model's time and length scales, (with ``orders``) its meshes' orders over the reference
    mesh, its linear natural frequencies and the parameters a sweep takes."""
    out.print(f"{escape(repr(model))}: time scale omega_0 = {_fmt(model.time_scale)} rad/s, "
              f"length scale L = {_fmt(model.length_scale)} m")
    if orders:
        text = ", ".join(f"{m} {_fmt(r)}" for m, r in zip(model.mesh_names, model.orders,
                                                           strict=True))
        out.print(f"mesh orders over {model.reference_mesh}: {escape(text)} "
                  f"({model.dataset_attrs()['forcing']} forcing)")
    modes = model.modes()
    kinds = "type" in modes
    table = Table(title="Natural frequencies (linear model, mean stiffness)")
    for col in ("f [Hz]", "multiplicity", *(("type",) if kinds else ())):
        table.add_column(col, justify="right")
    for k in range(modes.sizes["mode"]):
        table.add_row(_fmt(float(modes["frequency"][k])), str(int(modes["multiplicity"][k])),
                      *((str(modes["type"].values[k]),) if kinds else ()))
    out.print(table)
    _show_swept(out, model)


def _show_paper(out: Console, s, model) -> None:
    """The paper's device: its derived quantities, the coefficients of Eq. (10), omega_n, the
    natural frequencies and the static mesh forces."""
    from geardyn.models.derived import COEFFICIENT_FORMULAS, DERIVED_FORMULAS

    out.print(f"[bold]interpretation[/bold] {model.interpretation}")
    table = Table(title="Derived quantities (SI)")
    table.add_column("name", no_wrap=True)
    table.add_column("value", justify="right")
    table.add_column("unit", no_wrap=True)
    table.add_column("formula")
    values = model.derived.as_dict()
    overridden = set(s.planetary_params.derived)
    for name, (unit, formula) in DERIVED_FORMULAS.items():
        note = " [overridden]" if name in overridden else ""
        table.add_row(name, _fmt_value(values[name]), escape(unit), escape(formula + note))
    out.print(table)

    table = Table(title="Dimensionless coefficients of Eq. (10)")
    table.add_column("name", no_wrap=True)
    table.add_column("value", justify="right")
    table.add_column("formula")
    for name, formula in COEFFICIENT_FORMULAS.items():
        table.add_row(name, _fmt_value(model.coefficients[name]), escape(formula))
    out.print(table)

    omega_n = model.omega_n
    out.print(
        f"omega_n = {_fmt(omega_n)} rad/s  (f_n = {_fmt(omega_n / (2 * math.pi))} Hz;"
        " the unit of dimensionless time tau = omega_n t)"
    )
    table = Table(title="Natural frequencies of the linearised device (mean stiffness, b = 0)")
    table.add_column("mode", justify="right")
    table.add_column("omega / omega_n", justify="right")
    table.add_column(escape("omega [rad/s]"), justify="right")
    table.add_column(escape("f [Hz]"), justify="right")
    for k, w in enumerate(model.natural_frequencies(), start=1):
        table.add_row(str(k), _fmt(w), _fmt(w * omega_n), _fmt(w * omega_n / (2 * math.pi)))
    out.print(table)
    forces = model.static_mesh_forces()
    names = ", ".join(
        f"{n} = {_fmt(f)} N" for n, f in zip(model.observable_names, forces, strict=True)
    )
    out.print(f"static mesh forces under the mean loads: {names}")


def _show_swept(out: Console, model) -> None:
    """The parameters a sweep of ``model`` takes (``--param``) with their units and meanings,
    from its declared inputs (:func:`geardyn.cli.bifurcation.sweep_vocabulary`), and the value
    the model holds (empty: none given, the default or derived)."""
    from geardyn.cli.bifurcation import sweep_vocabulary
    from geardyn.core.inputs import by_name

    declared = by_name(model.input_declarations)
    table = Table(title="Swept parameters (--param)")
    for col in ("name", "value", "unit", "meaning"):
        table.add_column(col)
    for name, unit in sweep_vocabulary(model):
        value = model.omega if name == "Omega" else model.inputs.get(name)
        if name == "Omega":
            meaning = "forcing frequency / time scale omega_0"
        elif name in declared:
            meaning = declared[name].meaning
        else:
            meaning = model.param_attrs(name).get("meaning", "")
        text = ("" if value is None else _fmt(value) if isinstance(value, int | float)
                else str(value))
        table.add_row(name, escape(text), escape(unit), escape(meaning))
    out.print(table)


def _show_spur_pair(out: Console, model) -> None:
    """The spur pair's inputs and derived coefficients (SI; the stiffness series summarised),
    its natural frequency and the series' truncation error."""
    from geardyn.models.spur_pair_coefficients import HEADER

    out.print(escape(repr(model)))
    table = Table(title="SpurPair coefficients (SI)")
    for col in ("name", "value", "unit", "meaning"):
        table.add_column(col, justify="right" if col == "value" else "left")
    values = model.coefficient_values()
    for c in HEADER.entries:
        table.add_row(c.name, _fmt(float(values.get(c.name, model.params[HEADER.offset(
            c.name)]))), escape(c.unit), escape(c.meaning))
    out.print(table)
    wn = float(model.natural_frequencies()[0])
    err = model.stiffness_error()
    i1, i2 = model.inertia
    out.print(f"pinion speed {_fmt(model.speed)} rad/s = {_fmt(model.speed * 30 / math.pi)} "
              f"rpm; mesh frequency {_fmt(model.mesh_frequency / (2 * math.pi))} Hz; "
              f"{model.cycles} mesh cycles per forcing period")
    out.print(f"inertias I1 = {_fmt(i1)}, I2 = {_fmt(i2)} kg m^2; natural frequency in "
              f"contact sqrt(k_mean / m) = {_fmt(wn)} rad/s ({_fmt(wn / (2 * math.pi))} Hz)")
    out.print(f"stiffness series: {model.n_harmonics} harmonics of Omega per flank; error "
              f"against the table (of k_mean) rms {err['drive_rms']:.3g}, max "
              f"{err['drive_max']:.3g} (drive)")


#: What ``geardyn params show`` prints per view of a study model
#: (:data:`geardyn.io.study_models.PARAMS_VIEWS`, its ``params_view``): ``(console, study,
#: model)``.
PARAMS_VIEWS = {
    "paper": _show_paper,
    "coefficients": _show_coefficients,
    "spur_pair": lambda out, s, model: _show_spur_pair(out, model),
    "modes": _show_modes,
    "train": lambda out, s, model: _show_modes(out, s, model, orders=True),
}


@params_app.command("save")
def params_save(
    out: Annotated[Path, typer.Argument(help="The TOML file to write.")],
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
) -> None:
    """Write the paper's parameters in full form (SI units) as a study file: a template."""
    from geardyn.io.toml import paper_study, save_study

    if out.exists() and not force:
        raise ParameterError("OUT", str(out), "file exists (use --force to overwrite)")
    save_study(paper_study(), out)
    typer.echo(f"wrote {out}")


# ---------------------------------------------------------------------------- simulate

@app.command()
def simulate(
    study: Annotated[str, typer.Argument(help="Study TOML file or built-in study name.")],
    omega: Annotated[
        float | None,
        typer.Option(help="Forcing frequency Omega, dimensionless (the mesh frequency over the "
                          "model's frequency scale, or a revolution's where a tooth fault sets "
                          "the forcing period: the dataset's Omega attributes say which; "
                          "default: the study's run.omega; a spur_pair study's: from its "
                          "params.speed)."),
    ] = None,
    transient: run_option("transient", "default: run.transient") = None,
    periods: run_option("samples", "forcing periods recorded; default: run.periods",
                         option="--periods") = None,
    steps_per_period: StepsOption = None,
    interpretation: InterpretationOption = None,
    state: Annotated[
        str | None, typer.Option(help="Coordinate to plot (default: the study's plot_state).")
    ] = None,
    yes: YesOption = False,
    out: NetCDFOutOption = None,
    plot: PlotOption = None,
) -> None:
    """Simulate a study at one forcing frequency; save the time history and a figure."""
    from geardyn.io.netcdf import save_dataset
    from geardyn.plotting.simulation import count_distinct
    from geardyn.solvers.simulate import simulate as run_simulation

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
    check_plot_path("--plot", plot)
    run = study_run_settings(s, {**run_options(transient=transient,
                                               steps_per_period=steps_per_period),
                                 "samples": ("--periods", periods)}, omega=om)
    tr, n_periods, spp = run.transient, run.samples, run.steps_per_period
    if n_periods > MAX_COUNT:
        raise ParameterError("--periods", n_periods, f"must be >= 1 and <= {MAX_COUNT}")
    if spp is not None:
        check_count("--steps-per-period", spp)
    plot_state = state or s.plot_state
    model = base if base is not None else build_model(s, interpretation=interp, omega=om)
    known = (*model.state_names, *model.observable_names)
    if plot is not None and plot_state not in known and f"{plot_state}1" not in known:
        raise ParameterError("--state" if state else "study.plot_state", plot_state,
                             f"not a coordinate of {model.name}; known: {', '.join(known)}")
    check_run_cost(model, 1, [om], tr, n_periods, spp, False, yes=yes,
                   option="--omega/--periods/--transient/--steps-per-period",
                   value=f"Omega {om:g}, {n_periods} periods, transient {tr:g}, "
                         f"{spp or 'automatic'} steps/period",
                   what="simulation", record_columns=1 + len(known), blocks=False)
    make_parents(out, plot)

    err = _stderr()
    with err.status(f"simulating {escape(s.study.name)} at Omega = {om:g} (the first run "
                    "compiles)"):
        ds = run_simulation(model, omega=om, run=run)
    ds.attrs["study"] = s.study.name
    ds.attrs["plot_state"] = plot_state
    written = []
    if out is not None:
        save_dataset(ds, out)
        written.append(str(out))
    if plot is not None:
        from geardyn.plotting.simulation import plot_simulation

        with err.status("plotting"):
            plot_simulation(ds, state=plot_state, path=plot)
        written.append(str(plot))

    status = int(ds.attrs["status"])
    distinct = count_distinct(ds["poincare"].values, tol=1e-6)
    n_points = ds.sizes["sample"]
    summary = (
        f"{s.study.name}: Omega = {om:g}, status {Status(status).name.lower()}, "
        f"{distinct} distinct Poincaré point{'s' if distinct != 1 else ''} of {n_points} "
        f"(tol 1e-6), {ds.attrs['steps_per_period']} steps/period"
    )
    summary += f"; wrote {', '.join(written)}" if written else "; nothing written"
    typer.echo(summary)


# ---------------------------------------------------------------------------- bifurcation, plot
_register_bifurcation(app)  # geardyn bifurcation, geardyn plot (cli/bifurcation.py)


# ---------------------------------------------------------------------------- entry point
def main(argv: list[str] | None = None) -> int:
    """Run the command line; expected errors print one line ``error: ...`` and exit with 2."""
    args = sys.argv[1:] if argv is None else list(argv)
    app(args=args or ["--help"], prog_name="geardyn")  # exits (OneLineErrorGroup)
    return 0


__import__("geardyn.cli.map", fromlist=["register"]).register(app)  # geardyn map (cli/map.py)
__import__("geardyn.cli.reproduce", fromlist=["register"]).register(app)  # cli/reproduce.py
__import__("geardyn.cli.basins", fromlist=["register"]).register(app)  # cli/basins.py
__import__("geardyn.cli.frc", fromlist=["register"]).register(app)  # cli/frc.py
__import__("geardyn.cli.continuation", fromlist=["register"]).register(app)  # cli/continuation.py
__import__("geardyn.cli.explore", fromlist=["register"]).register(app)  # cli/explore.py
__import__("geardyn.cli.stiffness", fromlist=["register"]).register(app)  # cli/stiffness.py
__import__("geardyn.cli.modes", fromlist=["register"]).register(app)  # cli/modes.py
__import__("geardyn.cli.dynamic_factor", fromlist=["register"]).register(app)  # dynamic-factor
__import__("geardyn.cli.envelope", fromlist=["register"]).register(app)  # cli/envelope.py
__import__("geardyn.cli.runup", fromlist=["register"]).register(app)  # cli/runup.py
__import__("geardyn.cli.dataset", fromlist=["register"]).register(app)  # cli/dataset.py

if __name__ == "__main__":
    main()
