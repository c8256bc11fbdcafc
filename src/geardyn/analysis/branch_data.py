"""The points of a continued branch (orbit summaries) and the branch dataset.

A branch point summarises one periodic orbit: its section point, an orbit norm, per mesh the
deflection X = (g_drive + g_back) / 2 (the mesh's dynamic transmission error; g the dead-zone
switching functions X - b and X + b) and the dynamic mesh force over the orbit, its multipliers
and stability, and its contact regime (crossings per orbit period per mesh).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from geardyn.analysis.contact import contact_regime
from geardyn.analysis.lanes import has_mesh_forces, variable_attrs
from geardyn.analysis.orbits import MARGINAL, ShootingProblem
from geardyn.core.results import finish
from geardyn.core.settings import INTEGRATOR
from geardyn.solvers.kernels import kernels_for

if TYPE_CHECKING:
    from geardyn.core.model import Model

class BranchStatus(IntEnum):
    """How a branch ended."""

    COMPLETED = 0
    MAX_POINTS = 1
    NOT_CONVERGED = 2
    INVALID = 3
    DIVERGED = 4
    START_FAILED = 5
    RETRACED = 6

    @property
    def message(self) -> str:
        """What the status means, in words."""
        return _BRANCH_MESSAGES[self]


_BRANCH_MESSAGES = {
    BranchStatus.COMPLETED: "reached an end of the parameter range",
    BranchStatus.MAX_POINTS: "reached the most points",
    BranchStatus.NOT_CONVERGED: "the corrector did not converge at the least step",
    BranchStatus.INVALID: "the parameter left the model's valid region",
    BranchStatus.DIVERGED: "the integration diverged",
    BranchStatus.START_FAILED: "no periodic orbit found at the start",
    BranchStatus.RETRACED: "the branch returned onto its own points (it retraces itself, "
                           "e.g. a period-2k branch that rejoins its period-k orbit)",
}


#: The bifurcation kinds (``bifurcation_kind``), in words.
BIFURCATION_KINDS = {
    "fold": "real multiplier through +1 where the parameter turns (limit point)",
    "branch point": "real multiplier through +1 without a turn, or a turn without a "
                    "multiplier through +1 (another branch meets this one)",
    "period-doubling": "real multiplier through -1",
    "neimark-sacker": "complex pair through the unit circle",
    "contact": "edge crossings per orbit period change",
}


#: The statuses of a complete branch: it reached an end of the range, or returned onto its own
#: points (any other status: it ended early).
COMPLETE = (BranchStatus.COMPLETED, BranchStatus.RETRACED)


def branch_status_meaning() -> str:
    """The branch status codes as one attribute string."""
    return ", ".join(f"{int(s)} {s.message}" for s in BranchStatus)


#: Most recorded points per orbit for the summaries (every grid point up to this many).
SUMMARY_POINTS = 4096


@dataclass(frozen=True)
class BranchPoint:
    """One accepted point of a branch (see the module docstring)."""

    value: float
    arclength: float
    x: np.ndarray
    norm: float
    multipliers: np.ndarray
    stability: str
    crossings: np.ndarray  # per mesh
    contact: tuple[str, ...]
    deflection_max: np.ndarray
    deflection_rms: np.ndarray
    deflection_amplitude: np.ndarray
    forces: dict[str, np.ndarray] | None
    iterations: int
    steps_per_period: int
    branch: int
    period: int


def _stride(n_steps: int) -> int:
    s = max(1, math.ceil(n_steps / SUMMARY_POINTS))
    while n_steps % s:
        s += 1
    return s


def stability_of(mu: np.ndarray) -> str:
    """'stable' / 'unstable' / 'marginal' (the largest |mu| within MARGINAL of 1)."""
    if not np.all(np.isfinite(mu)):
        return "unknown"
    rho = float(np.max(np.abs(mu)))
    if rho > 1.0 + MARGINAL:
        return "unstable"
    return "stable" if rho < 1.0 - MARGINAL else "marginal"


def orbit_summary(problem: ShootingProblem, x: np.ndarray, value: float, arclength: float,
                  mu: np.ndarray, crossings: np.ndarray, iterations: int, branch: int
                  ) -> BranchPoint:
    """The :class:`BranchPoint` of the orbit through ``x`` (integrated once more, recording at
    most :data:`SUMMARY_POINTS` grid points)."""
    m = problem.model
    k = kernels_for(m.kernel)
    n = problem.n_steps
    Y, O, G, _nc, status, _unres, _done = k.trajectory(
        problem.params, np.ascontiguousarray(x, dtype=float), problem.step, problem.omega,
        problem.steps_per_period, 0, n, _stride(n), True, problem.bound, m.n_events,
        m.n_observables)
    Y, O, G = Y[:-1], O[:-1, : m.n_observables], G[:-1, : m.n_events]  # one period
    Ys = Y / problem.scale
    norm = float(np.sqrt(np.mean(np.sum(Ys * Ys, axis=1))))
    meshes = m.meshes
    nm = len(meshes)
    dmax, drms, damp = np.zeros(nm), np.zeros(nm), np.zeros(nm)
    per_mesh = np.zeros(nm, np.int64)
    contact = []
    st = np.array([int(status)])
    gmin, gmax = G.min(axis=0)[None, :], G.max(axis=0)[None, :]
    for q, (_name, i, j) in enumerate(meshes):
        X = 0.5 * (G[:, i] + G[:, j])
        dmax[q] = float(np.max(np.abs(X)))
        drms[q] = float(np.sqrt(np.mean((X - X.mean()) ** 2)))
        damp[q] = 0.5 * float(X.max() - X.min())
        per_mesh[q] = int(crossings[i] + crossings[j])
        contact.append(str(contact_regime(gmin, gmax, np.asarray(crossings)[None, :], i, j,
                                          st)[0]))
    forces = None
    if has_mesh_forces(m):
        forces = {"force_peak": np.max(np.abs(O), axis=0),
                  "force_rms": np.sqrt(np.mean(O * O, axis=0))}
        static = m.static_mesh_forces()
        if static is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                forces["dynamic_factor"] = forces["force_peak"] / np.abs(np.asarray(static))
    return BranchPoint(value, arclength, np.asarray(x, dtype=float).copy(), norm,
                       np.asarray(mu), stability_of(mu), per_mesh, tuple(contact), dmax, drms,
                       damp, forces, iterations, problem.steps_per_period, branch,
                       problem.period)


# ----------------------------------------------------------------------------- the dataset
def _point_variables(model: Model, pts: list[BranchPoint], n: int) -> dict[str, Any]:
    """The variables along ``point`` (and their other dims) of the branch points."""
    L = len(pts)
    nm = len(model.meshes)

    def stack(get, shape, dtype=float):
        out = np.full((L, *shape), np.nan if dtype is float else 0, dtype=dtype)
        for i, p in enumerate(pts):
            out[i] = get(p)
        return out

    mu = np.full((L, n), np.nan + 0j)
    for i, p in enumerate(pts):
        mu[i, : p.multipliers.size] = p.multipliers
    attrs = variable_attrs(model)
    v: dict[str, Any] = {
        "arclength": ("point", stack(lambda p: p.arclength, ()), {
            "long_name": "arclength in the scaled unknowns (x / state_scale, p / p_scale)",
            "units": "1"}),
        "branch": ("point", stack(lambda p: p.branch, (), np.int64), {
            "long_name": "branch number (see the branch dimension)"}),
        "period": ("point", stack(lambda p: p.period, (), np.int64), {
            "long_name": "period of the orbit in section periods (k)",
            "meaning": "k: the orbit closes after k section periods (the branch's k)"}),
        "section_point": (("point", "state"), stack(lambda p: p.x, (n,)), {
            "units": model.state_units, "long_name": "state at the section (forcing phase 0)"}),
        "orbit_norm": ("point", stack(lambda p: p.norm, ()), {
            "units": "1", "long_name": "RMS over the orbit of |state / state_scale|"}),
        "multiplier_real": (("point", "multiplier"), mu.real, {"units": "1"}),
        "multiplier_imag": (("point", "multiplier"), mu.imag, {"units": "1"}),
        "multiplier_abs": (("point", "multiplier"), np.abs(mu), {
            "units": "1", "long_name": "|Floquet multiplier|, in decreasing order"}),
        "stability": ("point", np.array([p.stability for p in pts], dtype=str), {
            "meaning": f"stable: all |mu| < 1 - {MARGINAL:g}; unstable: one > 1 + "
                       f"{MARGINAL:g}; marginal: between"}),
        "iterations": ("point", stack(lambda p: p.iterations, (), np.int64), {
            "long_name": "corrector iterations"}),
        "steps_per_period": ("point", stack(lambda p: p.steps_per_period, (), np.int64), {
            "long_name": "RK4 steps per forcing period"}),
    }
    if nm:
        v["mesh_crossings"] = (("point", "mesh"), stack(lambda p: p.crossings, (nm,), np.int64),
                               {"long_name": "dead-zone edge crossings per orbit period "
                                             "(both edges): the contact regime"})
        v["contact"] = (("point", "mesh"),
                        np.array([list(p.contact) for p in pts], dtype=str).reshape(L, nm),
                        attrs["contact"])
        for name, what in (("deflection_max", "max |X| over the orbit"),
                           ("deflection_rms", "RMS of X - mean(X) over the orbit"),
                           ("deflection_amplitude", "(max X - min X) / 2 over the orbit")):
            v[name] = (("point", "mesh"), stack(lambda p, name=name: getattr(p, name), (nm,)),
                       {"units": model.state_units, "long_name": f"mesh deflection {what}"})
        if has_mesh_forces(model):
            for name in ("force_peak", "force_rms", "dynamic_factor"):
                if pts and pts[0].forces is not None and name in pts[0].forces:
                    v[name] = (("point", "mesh"), stack(
                        lambda p, name=name: p.forces[name], (nm,)), attrs[name])
    return v


def _bifurcation_variables(runs: list[Any], n: int, offsets: list[int]
                           ) -> dict[str, Any]:
    bifs = [(r, b) for r in runs for b in r.bifurcations]
    B = len(bifs)
    kind = np.array([b.kind for _, b in bifs], dtype=str) if B else np.zeros(0, dtype=str)
    x = np.array([b.x for _, b in bifs]) if B else np.zeros((0, n))
    mu = np.array([b.multiplier for _, b in bifs], dtype=complex)
    return {
        "bifurcation_kind": ("bifurcation", kind, {
            "meaning": "; ".join(f"{k}: {v}" for k, v in BIFURCATION_KINDS.items())}),
        "bifurcation_located": ("bifurcation", np.array([int(b.located) for _, b in bifs],
                                                        np.int64), {
            "meaning": "1 located (value +- error); 0 not located: the test function changed "
                       "sign in [value - error, value + error], bifurcation_detail says why"}),
        "bifurcation_value": ("bifurcation", np.array([b.value for _, b in bifs], float), {
            "long_name": "located parameter value"}),
        "bifurcation_error": ("bifurcation", np.array([b.error for _, b in bifs], float), {
            "long_name": "bound on the location error in the parameter"}),
        "bifurcation_point": ("bifurcation", np.array(
            [offsets[b.branch] + b.index for _, b in bifs], np.int64), {
            "long_name": "index of the branch point before the bifurcation"}),
        "bifurcation_branch": ("bifurcation", np.array([b.branch for _, b in bifs], np.int64),
                               {"long_name": "branch number"}),
        "bifurcation_period": ("bifurcation", np.array([b.period for _, b in bifs], np.int64),
                               {"long_name": "period k of the branch"}),
        "bifurcation_multiplier_real": ("bifurcation", mu.real, {"units": "1"}),
        "bifurcation_multiplier_imag": ("bifurcation", mu.imag, {"units": "1"}),
        "bifurcation_section_point": (("bifurcation", "state"), x, {
            "long_name": "section point at the bifurcation"}),
        "bifurcation_detail": ("bifurcation", np.array([b.detail for _, b in bifs], dtype=str)
                               if B else np.zeros(0, dtype=str), {}),
    }


def branch_dataset(model: Model, param: str, start: float, stop: float,
                   runs: list[Any], tracer: Any) -> xr.Dataset:
    """The continuation dataset (``geardyn_kind = "continuation"``) of the branches ``runs``."""
    n = model.n_states
    pts = [p for r in runs for p in r.points]
    offsets, k = [], 0
    for r in runs:
        offsets.append(k)
        k += len(r.points)
    coords: dict[str, Any] = {
        "point": ("point", np.arange(len(pts))),
        param: ("point", np.array([p.value for p in pts], float), {
            **model.param_attrs(param), "long_name": f"continuation parameter {param}"}),
        "state": ("state", list(model.state_names)),
        "multiplier": ("multiplier", np.arange(n)),
        "branch_id": ("branch_id", np.arange(len(runs))),
    }
    if model.meshes:
        coords["mesh"] = ("mesh", [name for name, _, _ in model.meshes])
    ds = xr.Dataset(coords=coords)
    for name, val in _point_variables(model, pts, n).items():
        ds[name] = val
    for name, val in _bifurcation_variables(runs, n, offsets).items():
        ds[name] = val
    ds["branch_status"] = ("branch_id", np.array([int(r.status) for r in runs], np.int64),
                           {"meaning": branch_status_meaning()})
    ds["branch_message"] = ("branch_id", np.array([r.message for r in runs], dtype=str))
    ds["branch_period"] = ("branch_id", np.array([r.period for r in runs], np.int64))
    ds["branch_parent"] = ("branch_id", np.array([r.parent for r in runs], np.int64), {
        "long_name": "the bifurcation (index) the branch was switched from; -1 none"})
    ds["branch_start"] = ("branch_id", np.array(offsets, np.int64), {
        "long_name": "index of the branch's first point"})
    first = runs[0]
    ds.attrs.update(
        model=model.name, param=param, start=start, stop=stop,
        period=int(first.period), status=int(first.status), message=first.message,
        status_meaning=branch_status_meaning(), integrator=INTEGRATOR,
        method="pseudo-arclength continuation of Newton shooting on the located RK4 period "
               "map; dG/dp by central differences",
        p_scale=float(tracer.pscale), time_unit=model.time_unit,
        corrector_tol=float(tracer.tol))
    return finish(ds, "continuation")
