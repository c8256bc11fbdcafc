"""Mesh stiffness over the pinion angle (a :func:`geardyn.gears.potential_energy_stiffness`
or :func:`geardyn.gears.helical_stiffness` dataset): the drive and the coast flank's mesh
stiffness, optionally a healthy pair's drive stiffness under a faulty one, and the pairs in
contact on each flank (a helical pair: the face fraction in contact summed over the pairs);
with the loaded contact's variables (:func:`geardyn.study.mesh_stiffness` under a load) the
unloaded and loaded transmission error and the tangent and secant mesh stiffness under the
load; mesh cycles on top."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC

__all__ = ["fault_text", "plot_mesh_stiffness"]

#: (variable, label, colour) of each flank.
FLANKS = (("", "drive flank", "#1f77b4"), ("_coast", "coast flank", "#d62728"))


def fault_text(ds: xr.Dataset) -> str:
    """The dataset's faults in short (``attrs["faults"]``, or ``attrs["crack"]`` of a root
    crack alone), without their parenthesised model notes; "none" without."""
    text = str(ds.attrs.get("faults", ds.attrs.get("crack", "none")))
    return re.sub(r" \([^()]*\)", "", text)


def _is_stiffness(ds: xr.Dataset) -> bool:
    return all(f"{v}{s}" in ds for v in ("mesh_stiffness", "pairs_in_contact")
               for s, _, _ in FLANKS)


def _cycles_per_degree(ds: xr.Dataset) -> float | None:
    """Mesh cycles per degree of pinion rotation (z1 / 360), from the coordinates."""
    deg, cyc = ds["angle"].values, ds["cycle"].values
    nonzero = np.flatnonzero(deg != 0.0)
    return None if nonzero.size == 0 else float(cyc[nonzero[0]] / deg[nonzero[0]])


def plot_mesh_stiffness(ds: xr.Dataset, path: str | os.PathLike | None = None, *,
                        healthy: xr.Dataset | None = None):
    """Figure of a potential-energy stiffness dataset: ``mesh_stiffness`` and
    ``mesh_stiffness_coast`` [N/m] against the pinion angle [deg] (top), ``pairs_in_contact``
    and ``pairs_in_contact_coast`` (below; a helical pair's summed face fraction);
    ``healthy`` (the same pair without its fault, on the same angles) drawn dashed under the
    drive flank. A dataset with ``transmission_error`` (a loaded contact) adds two panels:
    ``unloaded_transmission_error`` and ``transmission_error`` [um], and ``mesh_stiffness``,
    ``tangent_stiffness`` and ``secant_stiffness`` under the load. Saved to ``path`` (.png,
    .pdf, .svg) when given. Returns a matplotlib Figure (no pyplot)."""
    import matplotlib
    from matplotlib.figure import Figure

    if not _is_stiffness(ds):
        raise ValueError("not a mesh stiffness result (needs mesh_stiffness[_coast] and "
                         "pairs_in_contact[_coast])")
    deg = ds["angle"].values
    if healthy is not None and not np.array_equal(healthy["angle"].values, deg):
        raise ValueError("healthy: not on the same pinion angles")
    loaded = "transmission_error" in ds
    helical = "slices" in ds.attrs
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(7.2, 8.0 if loaded else 4.6), layout="constrained")
        axes = fig.subplots(4 if loaded else 2, 1, sharex=True,
                            height_ratios=(3, 1, 2, 2) if loaded else (3, 1))
        ax_k, ax_n = axes[0], axes[1]
        top = max(float(np.max(ds[f"mesh_stiffness{s}"].values)) for s, _, _ in FLANKS)
        power = int(np.floor(np.log10(top))) if np.isfinite(top) and top > 0 else 0
        scale = 10.0 ** power
        if healthy is not None:
            ax_k.plot(deg, healthy["mesh_stiffness"].values / scale, color="0.55", ls="--",
                      lw=0.8, label="drive flank, healthy")
        for suffix, label, colour in FLANKS:
            ax_k.plot(deg, ds[f"mesh_stiffness{suffix}"].values / scale, color=colour,
                      label=label)
            ax_n.step(deg, ds[f"pairs_in_contact{suffix}"].values, where="post", color=colour,
                      label=label)
        ax_k.set_ylabel(f"mesh stiffness [$10^{{{power}}}$ N/m]")
        ax_k.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        ax_n.set_ylabel("face in contact\n[pairs]" if helical else "pairs in\ncontact")
        if not helical:
            ax_n.set_yticks(np.unique(np.concatenate(
                [ds[f"pairs_in_contact{s}"].values for s, _, _ in FLANKS])))
        if loaded:
            _loaded_panels(ds, axes[2], axes[3], deg, power)
        axes[-1].set_xlabel("pinion rotation [deg]")
        per_degree = _cycles_per_degree(ds)
        if per_degree:
            sec = ax_k.secondary_xaxis("top", functions=(lambda d: d * per_degree,
                                                         lambda c: c / per_degree))
            sec.set_xlabel("mesh cycles")
        name = ds.attrs.get("study", "")
        faults = fault_text(ds)
        kind = (f"\nhelical, {ds.attrs['slices']} slices, overlap ratio"
                f" {float(ds.attrs['overlap_ratio']):.4f}" if helical else "")
        fig.suptitle(f"{name + ': ' if name else ''}potential-energy mesh stiffness, contact"
                     f" ratio {float(ds.attrs.get('contact_ratio', np.nan)):.4f}{kind}"
                     + ("" if faults == "none" else f"\n{faults}"))
        if path is not None:
            fig.savefig(Path(path))
    return fig


#: (variable, label, colour, line style) of the loaded contact's panels.
TRANSMISSION_ERROR = (("unloaded_transmission_error", "unloaded", "0.45", "--"),
                      ("transmission_error", "loaded", "#2ca02c", "-"))
LOADED_STIFFNESS = (("mesh_stiffness", "unmodified (drive)", "0.55", "--"),
                    ("tangent_stiffness", "tangent", "#9467bd", "-"),
                    ("secant_stiffness", "secant", "#ff7f0e", "-"))


def _loaded_panels(ds: xr.Dataset, ax_e, ax_l, deg: np.ndarray, power: int) -> None:
    """The transmission error [um] and the loaded mesh stiffness [10^power N/m] panels."""
    for name, label, colour, style in TRANSMISSION_ERROR:
        ax_e.plot(deg, ds[name].values * 1e6, color=colour, ls=style, label=label)
    force = float(ds.attrs.get("force_N", np.nan))
    ax_e.set_ylabel("transmission\nerror [µm]")
    ax_e.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False,
                title=f"F = {force:.4g} N")
    for name, label, colour, style in LOADED_STIFFNESS:
        ax_l.plot(deg, ds[name].values / 10.0 ** power, color=colour, ls=style, label=label)
    ax_l.set_ylabel(f"loaded stiffness\n[$10^{{{power}}}$ N/m]")
    ax_l.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
