"""``geardyn stiffness``: the potential-energy mesh stiffness of a study's ``[gears]``.

::

    geardyn stiffness STUDY.toml [-o stiffness.nc] [--plot] [--figure stiffness.png] [--yes]

The pair comes from the study's ``[gears]`` (external or internal spur, or helical), the
faults on its teeth from ``[[faults]]``, the angles, cycles, quadrature, slices and load from
``[stiffness]``, tip reliefs and lead crowning from ``[[relief]]`` and ``[crowning]``
(:class:`~geardyn.io.toml.GearsTable`, :class:`~geardyn.io.toml.FaultTable`,
:class:`~geardyn.io.toml.StiffnessTable`, :class:`~geardyn.io.toml.ReliefTable`,
:class:`~geardyn.io.toml.CrowningTable`); the result is :func:`geardyn.study.mesh_stiffness`'s
Dataset (:func:`geardyn.gears.potential_energy_stiffness` or
:func:`geardyn.gears.helical_stiffness`, with a load the loaded contact's variables), written
as NetCDF (default ``<study name>_stiffness.nc``). ``--plot`` draws it (``--figure``, default
OUT with .png): drive and coast flank, pairs in contact, with a fault the healthy pair's drive
stiffness, with a load the transmission error and the loaded stiffness. A grid whose result
would not fit in half the machine's memory is refused unless ``--yes``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from geardyn.cli.common import (
    YesOption,
    check_plot_path,
    load_study_source,
    make_parents,
    memory_limit,
)
from geardyn.errors import ParameterError

__all__ = ["register", "stiffness_command"]

#: Bytes per pinion angle and variable row, peak while computing: an upper bound (the 19/48
#: pair, 10 rows, peaks at about 1.2 kB per angle against the 2 kB this gives).
BYTES_PER_VALUE = 200.0
#: Variable rows per slice and pair of a helical pair, relative to a spur pair's one per pair
#: (its per-slice variables: the terms, positions, masks, gaps and loaded forces).
SLICE_ROWS = 2


def stiffness_command(
    study: Annotated[str, typer.Argument(help="Study TOML file with a gears table, or a "
                                              "built-in study name.")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="NetCDF file to write (.nc; default: "
                                                      "<study name>_stiffness.nc).")
    ] = None,
    plot: Annotated[bool, typer.Option("--plot", help="Also draw the mesh stiffness.")] = False,
    figure: Annotated[
        Path | None, typer.Option(help="Figure to write with --plot (.png, .pdf or .svg; "
                                       "default: OUT with .png).")
    ] = None,
    yes: YesOption = False,
) -> None:
    """Mesh stiffness of a study's gear pair (spur, internal or helical) by the
    potential-energy method: drive and coast flank over the pinion angle, every energy term,
    the faults on its teeth, with a load the transmission error; NetCDF and a figure."""
    from geardyn.study import mesh_stiffness

    s = load_study_source(study, model=False)
    if s.gears is None:
        raise ParameterError("STUDY", study, "has no [gears] table (the pair whose mesh "
                             "stiffness to compute)")
    target = out if out is not None else Path(f"{s.study.name}_stiffness.nc")
    if target.suffix.lower() != ".nc":
        raise ParameterError("--out", str(target), "suffix must be .nc (NetCDF)")
    if figure is not None and not plot:
        raise ParameterError("--figure", str(figure), "draws nothing without --plot")
    drawn = (figure if figure is not None else target.with_suffix(".png")) if plot else None
    check_plot_path("--figure", drawn)
    _check_memory(s, yes)
    make_parents(target, drawn)
    ds = mesh_stiffness(s)
    from geardyn.io.netcdf import save_dataset

    save_dataset(ds, target)
    written = [str(target)]
    if drawn is not None:
        from geardyn.plotting.stiffness import plot_mesh_stiffness

        healthy = mesh_stiffness(s, faults=False, loaded=False) if s.faults else None
        plot_mesh_stiffness(ds, path=drawn, healthy=healthy)
        written.append(str(drawn))
    typer.echo(f"{_summary(s.study.name, ds)}; wrote {', '.join(written)}")


def _check_memory(study, yes: bool) -> None:
    """Refuse (unless ``yes``) a grid whose result would take more than
    :func:`~geardyn.cli.common.memory_limit`: about :data:`BYTES_PER_VALUE` per pinion angle
    and per variable row (the pairs of both flanks and the per-angle variables; a helical
    pair's rows are its pairs' slices, :data:`SLICE_ROWS` each)."""
    from geardyn.gears.helical import DEFAULT_SLICES

    mesh, kw = study.stiffness_inputs()
    angles = kw["angles"] * kw["cycles"]
    ratio = getattr(mesh, "total_contact_ratio", None)
    if ratio is None:
        rows = 2 * (math.ceil(mesh.contact_ratio) + 2) + 2
    else:
        rows = 2 * (math.ceil(ratio) + 2) * kw.get("slices", DEFAULT_SLICES) * SLICE_ROWS + 2
    need = float(angles) * rows * BYTES_PER_VALUE
    if need > memory_limit() and not yes:
        raise ParameterError("stiffness.angles", kw["angles"],
                             f"{angles} pinion angles ({kw['cycles']} mesh cycles) need about"
                             f" {need / 2**30:.3g} GiB, above the limit of"
                             f" {memory_limit() / 2**30:.3g} GiB (pass --yes to run anyway)")


def _summary(name: str, ds) -> str:
    """One line: the pair, the grid and the drive and coast mesh stiffness (a helical pair:
    its overlap ratio and slices; with a load: the transmission error and loaded stiffness)."""
    k, kc = ds["mesh_stiffness"].values, ds["mesh_stiffness_coast"].values
    c = ds["cycle"].values
    cycles = float(c[-1] - c[0] + (c[1] - c[0] if c.size > 1 else 0.0))
    from geardyn.plotting.stiffness import fault_text

    pair = f"contact ratio {ds.attrs['contact_ratio']:.5f}"
    if "slices" in ds.attrs:
        pair += (f", overlap ratio {ds.attrs['overlap_ratio']:.5f},"
                 f" {ds.attrs['slices']} slices")
    text = (f"{name}: {pair}, {k.size} pinion angles"
            f" over {cycles:.4g} mesh cycles; mesh stiffness drive {k.mean():.4g} N/m"
            f" ({k.min():.4g}..{k.max():.4g}), coast {kc.mean():.4g} N/m"
            f" ({kc.min():.4g}..{kc.max():.4g}); faults: {fault_text(ds)}")
    if "transmission_error" in ds:
        te, kt = ds["transmission_error"].values, ds["tangent_stiffness"].values
        text += (f"; under {ds.attrs['force_N']:.4g} N transmission error {te.mean() * 1e6:.4g}"
                 f" um (peak-to-peak {np.ptp(te) * 1e6:.4g} um), loaded stiffness"
                 f" {kt.mean():.4g} N/m")
    return text


def register(app: typer.Typer) -> None:
    """Add ``geardyn stiffness`` to the command line ``app``."""
    app.command("stiffness")(stiffness_command)
