"""Basins of attraction: the attractor reached from every initial condition of a grid.

Every grid cell is one lane of the sweep engine (:func:`~geardyn.solvers.ensemble.run_lanes`),
all at the same coefficient vector (one forcing frequency), each from its own initial state: the
model's initial state with two of its states set to the cell's values, at time 0 (forcing phase
zero). After the transient each lane records ``samples`` section points; its attractor is then
identified from them:

* periodic (period k <= ``max_period`` sections, :func:`~geardyn.classify_period`): the
  attractor is the set of its k section points. Two lanes reach the same attractor when their
  periods agree and, for some cyclic shift, every point of one is within ``match_tol`` of the
  other's (scaled by the model's ``state_scale``, relative to ``max(1, |x|)``);
* not periodic (period 0: chaotic, quasi-periodic, a longer period or not settled): lanes are
  grouped by the bounding box of their section points, boxes within ``chaos_tol`` (relative to
  the box's size and ``max(1, |x|)``) being the same attractor. This is a heuristic (two
  chaotic attractors with overlapping boxes are one), stated in the result's attributes;
* diverged lanes (|state| > bound): attractor id -1, never dropped, counted separately;
* unresolved lanes: attractor id -2, never part of an attractor, counted separately: the
  transient by convergence reached ``transient_max`` without the section point settling
  (``converged`` 0), or grid steps reached the edge-split limit and were integrated unsplit
  across an edge (``unresolved_steps`` > 0; status SPLIT_LIMIT), so the section points the lane
  recorded are not trusted to identify its attractor.

The attractors get ids 0, 1, ... in decreasing order of the share of the grid they attract.
Where :class:`~geardyn.PeriodicOrbit` objects are given (from :func:`geardyn.periodic_orbit` at
the same frequency), each periodic attractor is matched to the orbit whose section points it
reproduces (within ``match_tol``): the attractor's ``orbit`` is that orbit's index.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.dataset import model_attrs
from geardyn.analysis.lanes import CONTACT_LABELS, has_mesh_forces, lane_variables
from geardyn.analysis.periodicity import APERIODIC, UNBOUNDED, classify_period
from geardyn.core.model import Model
from geardyn.core.results import finish
from geardyn.core.settings import RunSettings, check_omega, resolve_run
from geardyn.core.status import Status, status_attrs
from geardyn.execution.executor import default_chunk, run_chunks
from geardyn.solvers.ensemble import run_lanes

__all__ = ["CHAOS_TOL", "CONVERGE", "DIVERGED", "MATCH_TOL", "UNRESOLVED", "basins",
           "basins_run", "grid_axis", "match_cycles", "match_orbits"]

#: Attractor id of a diverged cell.
DIVERGED = -1
#: Attractor id of an unresolved cell (transient not settled, or steps at the split limit).
UNRESOLVED = -2
#: Default tolerance of matching periodic attractors (relative, scaled states).
MATCH_TOL = 1e-3
#: Default tolerance of grouping non-periodic lanes by their section points' bounding boxes.
CHAOS_TOL = 0.1
#: Default transient by convergence of the basins (lanes near a basin boundary linger next to
#: the saddle orbit between the basins: a fixed transient would leave them unsettled).
CONVERGE = 1e-8
#: Default samples per lane: enough to classify periods up to max_period twice over.
SAMPLES_PER_PERIOD = 2

Axis = tuple[str, float, float, int] | tuple[str, Sequence[float] | np.ndarray]


def _default_fields(max_period: Any) -> dict[str, Any]:
    """basins' own defaults where no ``run`` is given: samples 2 max_period + 2, converge."""
    return {"samples": SAMPLES_PER_PERIOD * int(max_period) + 2, "converge": CONVERGE}


def basins_run(**fields: Any) -> RunSettings:
    """The :class:`~geardyn.RunSettings` :func:`basins` uses without ``run``: ``samples``
    2 ``max_period`` + 2 and ``converge`` :data:`CONVERGE`, then ``fields``."""
    mp = fields.get("max_period", RunSettings().max_period)
    return RunSettings(**{**_default_fields(mp), **fields})


# ---------------------------------------------------------------------------- the grid
def grid_axis(axis: Axis, label: str, names: Sequence[str]) -> tuple[str, np.ndarray]:
    """``(state, lo, hi, n)`` or ``(state, values)`` -> (state name, values); ValueError naming
    ``label`` for an unknown state or bad values."""
    if not isinstance(axis, tuple | list) or len(axis) not in (2, 4):
        raise ValueError(f"{label}: give (state, lo, hi, n) or (state, values)")
    name = axis[0]
    if name not in names:
        raise ValueError(f"{label}: {name!r} is not a state of the model; states: "
                         f"{', '.join(names)}")
    if len(axis) == 4:
        lo, hi, n = float(axis[1]), float(axis[2]), axis[3]
        if not isinstance(n, int | np.integer) or n < 1:
            raise ValueError(f"{label}: n must be a whole number >= 1 (got {n!r})")
        values = np.linspace(lo, hi, int(n))
    else:
        values = np.asarray(axis[1], dtype=float).ravel()
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError(f"{label}: the values of {name} must be finite, at least one")
    return str(name), values


def _grid_states(base: np.ndarray, ix: int, xv: np.ndarray, iy: int, yv: np.ndarray
                 ) -> np.ndarray:
    """Initial states of the grid (ny * nx, n_states), y-major: ``base`` with state ``ix`` set
    to the column's x and ``iy`` to the row's y."""
    Y0 = np.tile(base, (yv.size * xv.size, 1))
    Y0[:, ix] = np.tile(xv, yv.size)
    Y0[:, iy] = np.repeat(yv, xv.size)
    return Y0


# ---------------------------------------------------------------------------- the lane task
def _basin_task(model: Model, P: np.ndarray, y0: np.ndarray, *, run: RunSettings,
                keep: int) -> dict[str, np.ndarray]:
    """One chunk: run the lanes and reduce each to what identifies its attractor (the section
    period, the last ``keep`` section points, the bounding box of all of them, the contact
    regime, mesh forces, status)."""
    r = run_lanes(model, P, y0, run=run)
    var = lane_variables(model, r, None, run.max_period, run.period_tol)
    out = {"section_period": classify_period(r.samples, run.max_period, run.period_tol),
           "period": var["period"], "status": r.status, "converged": r.converged,
           "unresolved_steps": r.unresolved,
           "last": r.samples[:, -keep:], "box_min": np.min(r.samples, axis=1),
           "box_max": np.max(r.samples, axis=1), "final_time": r.final_time}
    if "contact" in var:
        codes = {label: k for k, label in enumerate(CONTACT_LABELS)}
        out["contact"] = np.vectorize(codes.__getitem__, otypes=[np.int8])(var["contact"])
    if has_mesh_forces(model):
        out["force_rms"] = var["force_rms"]
        out["force_peak"] = var["force_peak"]
    return out


# ---------------------------------------------------------------------------- matching
def _scale(points: np.ndarray) -> np.ndarray:
    """max(1, max |x|) per lane of ``points`` (lanes, ..., states)."""
    flat = np.abs(points.reshape(points.shape[0], -1))
    return np.maximum(1.0, np.max(flat, axis=1))


def match_cycles(cycles: np.ndarray, ref: np.ndarray, tol: float) -> np.ndarray:
    """Distance of each cycle in ``cycles`` (lanes, k, states; scaled) to the cycle ``ref``
    (k, states): the least, over cyclic shifts, of the largest state difference, relative to
    max(1, |x|). A cycle within ``tol`` is the same periodic attractor."""
    k = ref.shape[0]
    best = np.full(cycles.shape[0], np.inf)
    for s in range(k):
        d = np.max(np.abs(cycles - np.roll(ref, s, axis=0)[None]), axis=(1, 2))
        best = np.minimum(best, d)
    scale = np.maximum(_scale(cycles), max(1.0, float(np.max(np.abs(ref)))))
    return best / scale / tol


def _cluster(features: np.ndarray, distance: Callable[[np.ndarray, np.ndarray], np.ndarray]
             ) -> np.ndarray:
    """Greedy clustering: the first unlabelled lane founds a group of every lane within
    distance <= 1 of it; returns a group index per lane (0, 1, ... in order of foundation)."""
    label = np.full(features.shape[0], -1, np.int64)
    group = 0
    while np.any(label < 0):
        first = int(np.argmax(label < 0))
        free = label < 0
        near = np.zeros_like(free)
        near[free] = distance(features[free], features[first]) <= 1.0
        near[first] = True
        label[near] = group
        group += 1
    return label


def _box_distance(tol: float) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    def distance(boxes: np.ndarray, ref: np.ndarray) -> np.ndarray:
        size = np.maximum(np.max(ref[1] - ref[0]), max(1.0, float(np.max(np.abs(ref)))))
        return np.max(np.abs(boxes - ref[None]), axis=(1, 2)) / (tol * size)
    return distance


def _identify(section_period: np.ndarray, last: np.ndarray, boxes: np.ndarray,
              match_tol: float, chaos_tol: float) -> np.ndarray:
    """Attractor label per lane (0, 1, ... unordered; -1 diverged), from its section period,
    its last section points (scaled) and the bounding box of its section points (scaled)."""
    labels = np.full(section_period.size, DIVERGED, np.int64)
    nxt = 0
    for k in np.unique(section_period):
        if k == UNBOUNDED:
            continue
        lanes = np.flatnonzero(section_period == k)
        if k == APERIODIC:
            g = _cluster(boxes[lanes], _box_distance(chaos_tol))
        else:
            cycles = last[lanes, -int(k):]
            g = _cluster(cycles, lambda c, ref: match_cycles(c, ref, match_tol))
        labels[lanes] = g + nxt
        nxt += int(g.max()) + 1
    return labels


def _orbit_matches(orbits: Sequence[Any], period: np.ndarray, points: list[np.ndarray],
                   scale: np.ndarray, omega: float, match_tol: float) -> np.ndarray:
    """Index into ``orbits`` of the orbit each attractor reproduces (-1 none)."""
    out = np.full(period.size, -1, np.int64)
    for j, orb in enumerate(orbits):
        if not np.isclose(float(orb.omega), omega, rtol=1e-12, atol=0.0):
            raise ValueError(f"orbits[{j}] is at Omega = {orb.omega:g}, the basins at {omega:g}")
        if not orb.converged:
            continue
        k = int(orb.least_period)
        ref = orb.section_points[:k] / scale
        for a in range(period.size):
            if out[a] < 0 and period[a] == k and match_cycles(points[a][None], ref,
                                                              match_tol)[0] <= 1.0:
                out[a] = j
    return out


# ---------------------------------------------------------------------------- the analysis
def basins(
    model: Model,
    omega: float | None,
    x: Axis,
    y: Axis,
    run: RunSettings | None = None,
    *,
    base: np.ndarray | Sequence[float] | None = None,
    orbits: Sequence[Any] = (),
    match_tol: float = MATCH_TOL,
    chaos_tol: float = CHAOS_TOL,
    chunk: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    **settings: Any,
) -> xr.Dataset:
    """The attractor reached from every initial condition of a grid of two states.

    Parameters
    ----------
    omega
        Forcing frequency (None: the model's).
    x, y
        The grid's axes: ``(state, lo, hi, n)`` (n evenly spaced values) or ``(state, values)``,
        a state name of the model (``model.state_names``, e.g. ``"X_sq"``, ``"V_sq"`` for the
        CATT device, ``"x"``, ``"v"`` for the gear pair), in the model's state units.
    run
        :class:`~geardyn.RunSettings` (its fields as keywords: deprecated, one
        DeprecationWarning naming the equivalent ``run=``): ``transient`` (time before the
        attractor is read), ``samples`` (default 2 ``max_period`` + 2 when not given),
        ``max_period``, ``period_tol``, ``converge`` (default :data:`CONVERGE` when ``run`` is
        not given: each lane runs on, up to ``transient_max``, until its section point
        settles), ``steps_per_period``, ``bound``; :func:`basins_run` builds a run with these
        defaults.
    base
        The other states of every initial condition (default ``model.initial_state()``).
    orbits
        :class:`~geardyn.PeriodicOrbit` objects at the same ``omega``: each attractor is matched
        to the one whose section points it reproduces (``attractor_orbit``).
    match_tol, chaos_tol
        Tolerances of the matching (see the module docs).
    chunk, progress
        Lanes per kernel call; ``progress(cells_done, cells_total)`` after each chunk.

    Returns
    -------
    xarray.Dataset (``geardyn_kind = "basins"``) with dims (y, x) of the grid and
    ``attractor`` (the table's rows): ``attractor_id`` per cell (-1 diverged, -2 unresolved),
    ``unresolved`` (1 where the cell's transient did not settle or steps reached the
    edge-split limit), ``unresolved_steps``, ``period`` (in forcing periods, as the sweeps),
    ``status``, ``converged``, ``contact`` per mesh; the table
    ``attractor_period``, ``attractor_point`` (attractor, point, state: its section points,
    NaN-padded; for a non-periodic attractor its last section point), ``attractor_fraction``,
    ``attractor_cells``, ``attractor_orbit`` (-1 none), ``attractor_start`` (the first grid
    cell that reaches it), ``attractor_contact``, ``attractor_force_rms``; settings,
    ``diverged_fraction``, ``diverged_cells``, ``unresolved_fraction`` and ``unresolved_cells``
    in ``attrs``.
    """
    defaults: dict[str, Any] = {}
    if run is None:  # basins' own defaults of samples and converge (basins_run)
        defaults = _default_fields(settings.get("max_period", RunSettings().max_period))
    run = resolve_run(run, settings, defaults, aliases={"tol": "period_tol"}, where="basins")
    if model.omega_index is None:
        raise ValueError(f"{model.name} is not periodically forced: basins need a section")
    if run.samples < 2:
        raise ValueError(f"samples must be >= 2 to classify periods (got {run.samples})")
    if not (match_tol > 0 and chaos_tol > 0):
        raise ValueError("match_tol and chaos_tol must be > 0")
    om = float(model.omega if omega is None else omega)
    check_omega(om, "omega")
    m = model.with_omega(om)
    names = list(m.state_names)
    xn, xv = grid_axis(x, "x", names)
    yn, yv = grid_axis(y, "y", names)
    if xn == yn:
        raise ValueError(f"y: must be another state than x ({xn!r})")
    b = np.asarray(m.initial_state() if base is None else base, dtype=float).ravel()
    if b.shape != (m.n_states,) or not np.all(np.isfinite(b)):
        raise ValueError(f"base must be {m.n_states} finite states ({', '.join(names)})")
    Y0 = _grid_states(b, names.index(xn), xv, names.index(yn), yv)
    L = Y0.shape[0]
    P = np.tile(m.params, (L, 1))
    keep = min(run.max_period, run.samples)
    size = int(chunk) if chunk else default_chunk(L)
    out = run_chunks(functools.partial(_basin_task, run=run, keep=keep), m, {"P": P, "y0": Y0},
                     chunk=size, progress=progress, meta={"analysis": "basins"})
    scale = np.asarray(m.state_scale, dtype=float)
    diverged, unresolved = _outcomes(out)
    sec = np.where(diverged | unresolved, UNBOUNDED, out["section_period"])
    raw = _identify(sec, out["last"] / scale, np.stack([out["box_min"], out["box_max"]], 1)
                    / scale, match_tol, chaos_tol)
    raw[unresolved] = UNRESOLVED
    labels, table = _table(raw, sec, out, Y0, scale)
    ds = _dataset(m, (yn, yv), (xn, xv), labels, out, table, keep)
    ds.attrs.update(run.attrs())
    ds.attrs.update(
        model=m.name, x=xn, y=yn, Omega=om, time_unit=m.time_unit,
        match_tol=match_tol, chaos_tol=chaos_tol, chunk=size, n_orbits=0,
        base_state=b, state_scale=scale, n_attractors=int(table["period"].size),
        diverged_fraction=float(np.mean(labels == DIVERGED)),
        diverged_cells=int(np.sum(labels == DIVERGED)),
        unresolved_fraction=float(np.mean(labels == UNRESOLVED)),
        unresolved_cells=int(np.sum(labels == UNRESOLVED)),
        start="each cell from the base state with its two grid states, at time 0 (phase 0)",
        aperiodic_matching="non-periodic lanes grouped by the bounding boxes of their section "
                           "points (chaos_tol): a heuristic",
    )
    ds.attrs.update(model_attrs(m))
    return finish(match_orbits(ds, orbits) if len(orbits) else ds, "basins")


def match_orbits(ds: xr.Dataset, orbits: Sequence[Any]) -> xr.Dataset:
    """``ds`` (a :func:`basins` result) with ``attractor_orbit`` set: per attractor, the index
    of the first of ``orbits`` (:class:`~geardyn.PeriodicOrbit`, at the basins' Omega) whose
    section points the attractor's reproduce within the basins' ``match_tol`` (-1 none); an
    orbit that did not converge matches nothing."""
    scale = np.asarray(ds.attrs["state_scale"], dtype=float)
    pts = ds["attractor_point"].values
    k = ds["section_period"].values if "section_period" in ds else (
        ds["attractor_period"].values)
    points = [pts[a, : max(int(k[a]), 1)] / scale for a in range(k.size)]
    found = _orbit_matches(orbits, k, points, scale, float(ds.attrs["Omega"]),
                           float(ds.attrs["match_tol"]))
    ds = ds.copy()
    ds["attractor_orbit"] = ("attractor", found, ds["attractor_orbit"].attrs)
    ds.attrs["n_orbits"] = len(orbits)
    ds.attrs.setdefault("orbit_names", ", ".join(f"orbit {j}" for j in range(len(orbits))))
    return ds


def _outcomes(out: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(diverged, unresolved) per lane: diverged where the status is neither OK nor
    SPLIT_LIMIT; unresolved where not diverged and the transient did not settle (``converged``
    0) or steps reached the edge-split limit (``unresolved_steps`` > 0 or status SPLIT_LIMIT)."""
    status = np.asarray(out["status"])
    diverged = (status != Status.OK) & (status != Status.SPLIT_LIMIT)
    unresolved = ~diverged & ((np.asarray(out["converged"]) == 0)
                              | (np.asarray(out["unresolved_steps"]) > 0)
                              | (status == Status.SPLIT_LIMIT))
    return diverged, unresolved


def _table(raw: np.ndarray, sec: np.ndarray, out: dict[str, np.ndarray], Y0: np.ndarray,
           scale: np.ndarray) -> tuple[np.ndarray, dict[str, Any]]:
    """Relabel attractors by decreasing share of the grid; their table (one entry each)."""
    ids = [a for a in np.unique(raw) if a >= 0]
    counts = np.array([np.sum(raw == a) for a in ids], np.int64)
    order = [ids[i] for i in np.argsort(-counts, kind="stable")]
    labels = np.where(raw < 0, raw, DIVERGED).astype(np.int64)
    first = []
    for new, a in enumerate(order):
        where = raw == a
        labels[where] = new
        first.append(int(np.argmax(where)))
    first_arr = np.array(first, np.int64)
    k = sec[first_arr] if first else np.zeros(0, np.int64)
    points = [out["last"][j][-int(kk):] if kk > 0 else out["last"][j][-1:]
              for j, kk in zip(first_arr, k, strict=True)]
    table = {"section_period": k, "period": out["period"][first_arr], "point": points,
             "cells": np.array([np.sum(labels == a) for a in range(len(order))], np.int64),
             "start": Y0[first_arr], "first": first_arr}
    return labels, table


def _dataset(m: Model, y: tuple[str, np.ndarray], x: tuple[str, np.ndarray], labels: np.ndarray,
             out: dict[str, np.ndarray], table: dict[str, Any], keep: int) -> xr.Dataset:
    """The labelled basins dataset (without the settings)."""
    (yn, yv), (xn, xv) = y, x
    shape = (yv.size, xv.size)
    A = table["period"].size
    ds = xr.Dataset(coords={yn: (yn, yv, {"long_name": f"initial {yn}"}),
                            xn: (xn, xv, {"long_name": f"initial {xn}"}),
                            "attractor": ("attractor", np.arange(A)),
                            "point": ("point", np.arange(keep)),
                            "state": ("state", list(m.state_names))})
    if m.meshes:
        ds = ds.assign_coords(mesh=("mesh", [mm[0] for mm in m.meshes]))
    grid = (yn, xn)
    ds["attractor_id"] = (grid, labels.reshape(shape), {
        "long_name": "attractor reached from the cell's initial state",
        "meaning": "index into the attractor table (dim 'attractor'); -1 diverged, "
                   "-2 unresolved (see 'unresolved')"})
    ds["unresolved"] = (grid, (labels == UNRESOLVED).reshape(shape).astype(np.int8), {
        "long_name": "cell without a trusted attractor (attractor_id -2)",
        "meaning": "1: the transient by convergence reached transient_max unsettled (converged "
                   "0) or grid steps reached the edge-split limit (unresolved_steps > 0); "
                   "0 otherwise"})
    ds["unresolved_steps"] = (grid, out["unresolved_steps"].reshape(shape), {
        "long_name": "grid steps that reached the edge-split limit"})
    ds["period"] = (grid, out["period"].reshape(shape), {
        "long_name": "period in forcing periods",
        "meaning": "k>=1 period-k, 0 no period <= max_period found, -1 unbounded"})
    ds["status"] = (grid, out["status"].reshape(shape), status_attrs())
    ds["converged"] = (grid, out["converged"].reshape(shape), {
        "meaning": "1 converged, 0 reached the longest transient, -1 fixed transient"})
    if "contact" in out:
        ds["contact"] = ((*grid, "mesh"), np.array(CONTACT_LABELS)[out["contact"]].reshape(
            *shape, -1), {"meaning": "contact regime per mesh over the sampled stretch"})
    pts = np.full((A, keep, m.n_states), np.nan)
    for a, p in enumerate(table["point"]):
        pts[a, : p.shape[0]] = p
    n = labels.size
    ds["attractor_period"] = ("attractor", table["period"], {
        "long_name": "attractor's period in forcing periods",
        "meaning": "k>=1 period-k, 0 not periodic (chaotic, quasi-periodic, longer, unsettled)"})
    ds["attractor_point"] = (("attractor", "point", "state"), pts, {
        "long_name": "the attractor's section points (states at forcing phase 0)",
        "meaning": "period-k: its k section points, NaN after; not periodic: the last "
                   "section point of its first cell"})
    ds["attractor_cells"] = ("attractor", table["cells"])
    ds["section_period"] = ("attractor", table["section_period"], {
        "long_name": "attractor's period in sections (forcing periods per section: the "
                     "sweeps' section_periods)"})
    ds["attractor_fraction"] = ("attractor", table["cells"] / n, {
        "long_name": "share of the grid's cells attracted",
        "meaning": "sum over attractors + diverged_fraction + unresolved_fraction = 1"})
    ds["attractor_orbit"] = ("attractor", np.full(A, -1, np.int64), {
        "meaning": "index of the given PeriodicOrbit the attractor reproduces; -1 none"})
    ds["attractor_start"] = (("attractor", "state"), table["start"].reshape(A, m.n_states), {
        "long_name": "initial state of the first cell reaching the attractor"})
    first = table["first"]
    n_mesh = len(m.meshes)
    if "contact" in out:
        ds["attractor_contact"] = (("attractor", "mesh"), np.array(CONTACT_LABELS)[
            out["contact"][first]].reshape(A, n_mesh))
    if "force_rms" in out:
        ds["attractor_force_rms"] = (("attractor", "mesh"), out["force_rms"][first].reshape(
            A, n_mesh), {"units": m.observable_units})
        ds["attractor_force_peak"] = (("attractor", "mesh"), out["force_peak"][first].reshape(
            A, n_mesh), {"units": m.observable_units})
    return ds
