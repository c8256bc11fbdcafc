"""Continued branches of periodic orbits (:func:`geardyn.continuation`): the branch against its
parameter, alone or over a brute-force bifurcation diagram (:func:`geardyn.bifurcation`), stable
parts solid and unstable ones dashed, the located bifurcations marked and labelled (LP fold, BP
branch point, PD period doubling, NS Neimark-Sacker, CC contact change; a '?' after the label:
not located, marked at the middle of its bracket); beside it the Floquet multipliers on the
unit circle, coloured by the parameter."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.plotting.style import RC, param_label, state_label, unit_text

__all__ = ["BIFURCATION_LABELS", "QUANTITIES", "plot_branch", "stability_segments"]

#: Label, marker and colour of each bifurcation kind (``bifurcation_kind``).
BIFURCATION_LABELS: dict[str, tuple[str, str, str, str]] = {
    "fold": ("LP", "fold (limit point)", "o", "#d62728"),
    "branch point": ("BP", "branch point", "v", "#8c564b"),
    "period-doubling": ("PD", "period doubling", "s", "#2ca02c"),
    "neimark-sacker": ("NS", "Neimark–Sacker", "D", "#9467bd"),
    "contact": ("CC", "contact change", "^", "#ff7f0e"),
}
#: What the branch panel can show: the section coordinate of a state, or a variable along
#: ``point`` (per mesh where it has the ``mesh`` dimension).
QUANTITIES = ("section", "deflection_max", "deflection_rms", "deflection_amplitude",
              "dynamic_factor", "force_peak", "force_rms", "orbit_norm")
#: Colours of the branches by their period k (1, 2, 4, 8, ...; others cycle).
BRANCH_COLORS = ("black", "#1f77b4", "#17becf", "#8c564b", "#e377c2")
#: Offsets (points) of a bifurcation's label from its marker: the first, then where labels of
#: nearby bifurcations already sit.
LABEL_OFFSETS = ((3, 4), (3, -11), (-15, 4), (-15, -11), (3, 14), (-15, 14))
#: Multipliers beyond this modulus are outside the unit-circle panel (counted in its title).
MU_VIEW = 2.5


def stability_segments(ds: xr.Dataset) -> list[tuple[int, bool, np.ndarray]]:
    """(branch number, stable, point indices) of every run of equally stable points of every
    branch, in order; a run also takes the next run's first point so the drawn line is
    unbroken. Stable: ``stability == "stable"``; unstable, marginal and unknown are not."""
    if ds.sizes.get("point", 0) == 0:
        return []
    ids = ds["branch"].values
    stable = ds["stability"].values.astype(str) == "stable"
    out = []
    for b in dict.fromkeys(ids.tolist()):
        idx = np.flatnonzero(ids == b)
        cuts = np.flatnonzero(np.diff(stable[idx].astype(np.int8))) + 1
        starts = np.concatenate([[0], cuts])
        stops = np.concatenate([cuts, [idx.size]])
        for s0, s1 in zip(starts, stops, strict=True):
            out.append((int(b), bool(stable[idx[s0]]), idx[s0:min(s1 + 1, idx.size)]))
    return out


def _branch_state(ds: xr.Dataset, state: str | None) -> str:
    states = [str(s) for s in ds["state"].values]
    wanted = [state] if state is not None else [ds.attrs.get("plot_state"), "X_sq", "x"]
    for name in wanted:
        for candidate in (name, f"{name}1") if name else ():
            if candidate in states:
                return candidate
    if state is not None:
        raise ValueError(f"state: {state!r} is not a state of the branch; known: "
                         f"{', '.join(states)}")
    return states[0]


def _values(ds: xr.Dataset, quantity: str, state: str, mesh: str | None
            ) -> tuple[np.ndarray, str]:
    """The branch's y values along ``point`` and the axis label."""
    if quantity == "section":
        da = ds["section_point"].sel(state=state)
        units = ds["section_point"].attrs.get("units")
        return da.values, f"{state_label(state)} {unit_text(units)} (section point)"
    if quantity not in ds:
        raise ValueError(f"quantity: {quantity!r} is not in the branch dataset; shown can be "
                         f"{', '.join(q for q in QUANTITIES if q == 'section' or q in ds)}")
    da = ds[quantity]
    extra = ""
    if "mesh" in da.dims:
        meshes = [str(m) for m in ds["mesh"].values]
        mesh = meshes[0] if mesh is None else mesh
        if mesh not in meshes:
            raise ValueError(f"mesh: {mesh!r} is not a mesh of the branch; meshes: "
                             f"{', '.join(meshes)}")
        da = da.sel(mesh=mesh)
        extra = f", mesh {mesh}" if len(meshes) > 1 else ""
    if set(da.dims) != {"point"}:
        raise ValueError(f"quantity: {quantity!r} is not one value per point")
    label = quantity.replace("_", " ") + extra
    return da.values.astype(float), f"{label} {unit_text(da.attrs.get('units'))}"


def _bifurcation_y(ds: xr.Dataset, y: np.ndarray, j: int, quantity: str, state: str) -> float:
    """Where bifurcation ``j`` sits on the branch: its own section point, else the branch's
    values interpolated in the parameter between the points either side (their mean at a
    fold, where the parameter turns)."""
    if quantity == "section":
        return float(ds["bifurcation_section_point"].sel(state=state).values[j])
    param = str(ds.attrs["param"])
    i = int(ds["bifurcation_point"].values[j])
    p = ds[param].values
    if i + 1 >= p.size or ds["branch"].values[i + 1] != ds["branch"].values[i]:
        return float(y[i])
    v = float(ds["bifurcation_value"].values[j])
    lo, hi = p[i], p[i + 1]
    if lo != hi and min(lo, hi) <= v <= max(lo, hi):
        w = (v - lo) / (hi - lo)
        return float((1 - w) * y[i] + w * y[i + 1])
    return float(0.5 * (y[i] + y[i + 1]))


def _draw_over(ax, over: xr.Dataset, param: str, quantity: str, state: str,
               mesh: str | None) -> str:
    """The brute-force diagram under the branch (grey points); returns its legend text."""
    if over.attrs.get("geardyn_kind", "bifurcation") != "bifurcation" or "poincare" not in over:
        raise ValueError("over: not a brute-force bifurcation dataset (geardyn.bifurcation)")
    oparam = str(over.attrs.get("param", over["poincare"].dims[0]))
    if oparam != param:
        raise ValueError(f"over: the diagram sweeps {oparam}, the branch follows {param}")
    x = over[param].values.astype(float)
    if quantity == "section":
        if state not in [str(s) for s in over["state"].values]:
            raise ValueError(f"over: the diagram has no state {state!r}")
        y = over["poincare"].sel(state=state).transpose(param, "sample").values
        what = "Poincaré points"
    elif quantity in over and set(over[quantity].dims) <= {param, "mesh"}:
        da = over[quantity]
        if "mesh" in da.dims:
            da = da.sel(mesh=mesh) if mesh is not None else da.isel(mesh=0)
        y = da.transpose(param).values[:, None]
        what = quantity.replace("_", " ")
    else:
        raise ValueError(f"over: a brute-force diagram has no {quantity!r} (draw the branch's "
                         "section coordinate, quantity='section', or the dynamic factor)")
    xx = np.broadcast_to(x[:, None], y.shape)
    keep = np.isfinite(y)
    ax.scatter(xx[keep], y[keep], s=6, c="0.6", linewidths=0, rasterized=True, zorder=1)
    return f"brute-force sweep ({what})"


def _draw_branch(ax, ds: xr.Dataset, x: np.ndarray, y: np.ndarray) -> list:
    """One line per stability segment (stable solid, unstable dashed), coloured by the branch's
    period; returns legend handles."""
    from matplotlib.lines import Line2D

    periods = ds["branch_period"].values if "branch_period" in ds else np.ones(1, int)
    colors: dict[int, str] = {}
    for k in sorted(set(int(p) for p in periods)):
        colors[k] = BRANCH_COLORS[min(len(colors), len(BRANCH_COLORS) - 1)]
    for b, stable, idx in stability_segments(ds):
        k = int(periods[b]) if b < periods.size else 1
        ax.plot(x[idx], y[idx], ls="-" if stable else "--", lw=1.3, color=colors.get(k, "k"),
                gid="branch-stable" if stable else "branch-unstable", zorder=3)
    handles = [Line2D([], [], color="0.3", ls="-", lw=1.3, label="stable"),
               Line2D([], [], color="0.3", ls="--", lw=1.3, label="unstable")]
    if len(colors) > 1:
        handles += [Line2D([], [], color=c, lw=2, label=f"period-{k} branch")
                    for k, c in colors.items()]
    return handles


def _draw_bifurcations(ax, ds: xr.Dataset, y: np.ndarray, quantity: str, state: str) -> list:
    """A marker and a label (LP, BP, PD, NS, CC; '?' appended where not located) per
    bifurcation; legend handles."""
    from matplotlib.lines import Line2D

    kinds = ds["bifurcation_kind"].values.astype(str)
    seen: dict[str, Line2D] = {}
    placed: list[tuple[float, float]] = []
    finite = y[np.isfinite(y)]
    x_span = abs(float(ds.attrs["stop"]) - float(ds.attrs["start"])) or 1.0
    y_span = float(np.ptp(finite)) if finite.size else 1.0
    for j, kind in enumerate(kinds):
        short, long, marker, color = BIFURCATION_LABELS.get(kind, (kind, kind, "*", "k"))
        v = float(ds["bifurcation_value"].values[j])
        yj = _bifurcation_y(ds, y, j, quantity, state)
        ax.plot([v], [yj], ls="", marker=marker, ms=6, mfc=color, mec="k", mew=0.5,
                gid="bifurcation", zorder=5)
        # labels of neighbouring points go round their markers, not on top of each other
        near = sum(abs(v - a) < 0.03 * x_span and abs(yj - b) < 0.06 * (y_span or 1.0)
                   for a, b in placed)
        placed.append((v, yj))
        first = 1 if kind == "contact" else 0  # contact labels below, the others above
        located = ("bifurcation_located" not in ds
                   or bool(ds["bifurcation_located"].values[j]))
        ax.annotate(short if located else f"{short}?", (v, yj),
                    xytext=LABEL_OFFSETS[(first + near) % len(LABEL_OFFSETS)],
                    textcoords="offset points", fontsize=7, color=color, fontweight="bold",
                    gid="bifurcation-label", zorder=6)
        if kind not in seen:
            seen[kind] = Line2D([], [], ls="", marker=marker, ms=6, mfc=color, mec="k", mew=0.5,
                                label=f"{short}: {long}")
    return list(seen.values())


def _draw_multipliers(fig, ax, ds: xr.Dataset, param: str) -> None:
    """The multipliers of every point on the complex plane, coloured by the parameter, with
    the unit circle and the critical multiplier of each located bifurcation."""
    t = np.linspace(0.0, 2 * np.pi, 361)
    ax.plot(np.cos(t), np.sin(t), color="k", lw=0.8, gid="unit-circle")
    mu = ds["multiplier_real"].values + 1j * ds["multiplier_imag"].values
    p = np.broadcast_to(ds[param].values[:, None], mu.shape)
    ok = np.isfinite(mu)
    inside = ok & (np.abs(mu) <= MU_VIEW)
    sc = ax.scatter(mu.real[inside], mu.imag[inside], c=p[inside], s=4, cmap="viridis",
                    linewidths=0, zorder=3)
    if inside.any():
        fig.colorbar(sc, ax=ax, shrink=0.8, label=param_label(
            param, str(ds.attrs.get("model", "")), ds[param].attrs.get("units")))
    for j, kind in enumerate(ds["bifurcation_kind"].values.astype(str)):
        c = complex(ds["bifurcation_multiplier_real"].values[j],
                    ds["bifurcation_multiplier_imag"].values[j])
        if kind == "contact" or not np.isfinite(c):
            continue
        short, _long, marker, color = BIFURCATION_LABELS.get(kind, (kind, kind, "*", "k"))
        for z in {c, c.conjugate()} if kind == "neimark-sacker" else {c}:
            ax.plot([z.real], [z.imag], ls="", marker=marker, ms=6, mfc=color, mec="k",
                    mew=0.5, zorder=5)
    lim = MU_VIEW * 1.02
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel(r"Re $\mu$")
    ax.set_ylabel(r"Im $\mu$")
    outside = int(np.count_nonzero(ok & ~inside))
    ax.set_title("Floquet multipliers" + (f" ({outside} with |μ| > {MU_VIEW:g} not shown)"
                                          if outside else ""))


def _title(ds: xr.Dataset, param: str) -> str:
    who = ds.attrs.get("study") or ds.attrs.get("model", "model")
    periods = sorted(set(int(k) for k in ds["branch_period"].values)) if "branch_period" in ds \
        else [int(ds.attrs.get("period", 1))]
    text = (f"{who}: period-{'/'.join(str(k) for k in periods)} branch"
            f"{'es' if ds.sizes.get('branch_id', 1) > 1 else ''} continued in {param}")
    from geardyn.analysis.branch_data import COMPLETE

    ended = [f"branch {b}: {ds['branch_message'].values[b]}"
             for b in range(ds.sizes.get("branch_id", 0))
             if int(ds["branch_status"].values[b]) not in COMPLETE]
    return text + ("\nended early: " + "; ".join(ended) if ended else "")


def plot_branch(ds: xr.Dataset, path: str | os.PathLike | None = None, *,
                over: xr.Dataset | None = None, quantity: str = "section",
                state: str | None = None, mesh: str | None = None, multipliers: bool = True):
    """Figure of a :func:`geardyn.continuation` dataset.

    Parameters
    ----------
    over
        A :func:`geardyn.bifurcation` dataset of the same parameter drawn under the branch (its
        Poincaré points in grey; with ``quantity="dynamic_factor"`` its dynamic factor).
    quantity
        ``"section"`` (the orbit's section point, state ``state``: default the dataset's
        ``plot_state``, else ``X_sq`` or ``x``) or a variable along ``point``:
        ``deflection_max``, ``deflection_rms``, ``deflection_amplitude``, ``dynamic_factor``,
        ... (mesh ``mesh``, default the first). A period-k branch shows one of its k section
        points.
    multipliers
        Add the panel of the Floquet multipliers on the unit circle.
    path
        Where to save the figure (.png, .pdf, .svg). None: only return it.

    Returns a matplotlib Figure (no pyplot): the first axes hold the branch, one line per
    stability segment (stable solid, unstable and marginal dashed; gid ``branch-stable`` /
    ``branch-unstable``) and one marker (gid ``bifurcation``) with its label (LP, BP, PD, NS, CC)
    per located bifurcation.
    """
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    if ds.attrs.get("geardyn_kind") != "continuation":
        raise ValueError("not a continuation result (attrs['geardyn_kind'])")
    param = str(ds.attrs["param"])
    if quantity not in QUANTITIES and quantity not in ds:
        raise ValueError(f"quantity: {quantity!r}; one of {', '.join(QUANTITIES)}")
    name = _branch_state(ds, state)
    x = ds[param].values.astype(float)
    y, ylabel = _values(ds, quantity, name, mesh)
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(12.0 if multipliers else 8.0, 5.0), layout="constrained")
        if multipliers:
            ax, ax_mu = fig.subplots(1, 2, width_ratios=[1.6, 1.0])
        else:
            ax, ax_mu = fig.subplots(1, 1), None
        handles = []
        if over is not None:
            text = _draw_over(ax, over, param, quantity, name, mesh)
            handles.append(Line2D([], [], ls="", marker="o", ms=3, color="0.6", label=text))
        handles += _draw_branch(ax, ds, x, y)
        handles += _draw_bifurcations(ax, ds, y, quantity, name)
        ax.legend(handles=handles, loc="best", fontsize=7)
        ax.set_xlabel(param_label(param, str(ds.attrs.get("model", "")),
                                  ds[param].attrs.get("units")))
        ax.set_ylabel(ylabel)
        lo, hi = sorted((float(ds.attrs["start"]), float(ds.attrs["stop"])))
        ax.set_xlim(lo, hi)
        if ax_mu is not None:
            _draw_multipliers(fig, ax_mu, ds, param)
        fig.suptitle(_title(ds, param))
        if path is not None:
            fig.savefig(Path(path))
    return fig
