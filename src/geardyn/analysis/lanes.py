"""What a sweep reports per lane: period class, contact-loss regime, mesh forces.

One function, :func:`lane_variables`, turns the raw results of
:func:`~geardyn.solvers.ensemble.run_lanes` into the per-lane variables that
:func:`~geardyn.bifurcation` and :func:`~geardyn.map2d` both report.
"""

from __future__ import annotations

import numpy as np

from geardyn.analysis.contact import REGIMES, UNBOUNDED_LABEL, contact_regime
from geardyn.analysis.periodicity import classify_period
from geardyn.core.model import Model
from geardyn.core.settings import DEFAULT_MAX_PERIOD, DEFAULT_TOL
from geardyn.solvers.ensemble import LaneResults

__all__ = ["CONTACT_LABELS", "has_mesh_forces", "lane_periods", "lane_variables", "variable_attrs",
           "variable_dims"]

#: Every contact-regime label, in code order (``contact`` is stored as codes in Zarr chunks).
CONTACT_LABELS: tuple[str, ...] = (*REGIMES, UNBOUNDED_LABEL)


def has_mesh_forces(model: Model) -> bool:
    """True when the model declares its observables to be its meshes' forces
    (:attr:`~geardyn.core.capabilities.Capabilities.mesh_forces`): peak/RMS forces and the
    dynamic factor are reported (the latter needs the static mesh forces)."""
    return model.capabilities.mesh_forces


def variable_dims(model: Model) -> dict[str, tuple[str, ...]]:
    """Dimensions (beyond the lane's) of each variable :func:`lane_variables` returns."""
    dims: dict[str, tuple[str, ...]] = {
        "period": (), "steps_per_period": (), "transient_periods": (), "unresolved_steps": (),
        "section_periods": (), "converged": ()}
    if model.meshes:
        dims["contact"] = ("mesh",)
    if has_mesh_forces(model):
        dims.update(force_peak=("mesh",), force_rms=("mesh",), dynamic_factor=("mesh",))
    return dims


def variable_attrs(model: Model, max_period: int = DEFAULT_MAX_PERIOD, tol: float = DEFAULT_TOL
                   ) -> dict[str, dict]:
    """Attributes (meaning, units) of each variable :func:`lane_variables` returns."""
    return {
        "period": {"long_name": "period in forcing periods",
                   "meaning": "k>=1 period-k, 0 no period <= max_period found (chaotic, "
                              "quasi-periodic, a longer period or not settled: see "
                              "geardyn.analysis.motion), -1 unbounded; with a second "
                              "excitation at an irrational frequency ratio, 0 (no periodic "
                              "motion exists)",
                   "tolerance": tol, "max_period": max_period},
        "section_periods": {"long_name": "forcing periods between Poincare samples",
                            "meaning": "the common period of the excitations when their "
                                       "frequencies are commensurate (else 1 and not a true "
                                       "section)"},
        "converged": {"long_name": "transient ended by convergence of the Poincare points",
                      "meaning": "1 converged, 0 reached the longest transient, -1 fixed "
                                 "transient"},
        "steps_per_period": {}, "transient_periods": {},
        "unresolved_steps": {"long_name": "grid steps that reached the edge-split limit",
                             "meaning": "steps with more dead-zone edge crossings than the "
                                        "split limit (MAX_SPLITS), integrated unsplit there "
                                        "(every start; 0 expected)"},
        "contact": {"meaning": "none: teeth never separate; single: separation, no back-flank "
                               "contact; double: back-flank contact; unbounded: diverged"},
        "force_peak": {"units": model.observable_units},
        "force_rms": {"units": model.observable_units},
        "dynamic_factor": {"long_name": "peak dynamic mesh force / static mesh force"},
    }


def lane_periods(r: LaneResults, max_period: int = DEFAULT_MAX_PERIOD, tol: float = DEFAULT_TOL
                 ) -> np.ndarray:
    """Period of each lane in forcing periods: :func:`classify_period` of its Poincare samples
    times the section interval; 0 where a second excitation is incommensurate."""
    k = classify_period(r.samples, max_period, tol)
    period = np.where(k > 0, k * r.sample_every, k)
    return np.where(r.commensurate | (period < 0), period, 0)


def lane_variables(model: Model, r: LaneResults, static: np.ndarray | None = None,
                   max_period: int = DEFAULT_MAX_PERIOD, tol: float = DEFAULT_TOL
                   ) -> dict[str, np.ndarray]:
    """Per-lane variables of one :func:`run_lanes` result, each lane-first (dimensions in
    :func:`variable_dims`): ``period`` (:func:`classify_period` of the Poincare samples, in
    forcing periods: section periods times the section's interval; 0 for a lane forced at
    incommensurate frequencies), ``section_periods``, ``converged``,
    ``contact`` (regime label per mesh), ``force_peak``, ``force_rms`` and ``dynamic_factor``
    (peak over ``static``, the static mesh force per lane and mesh; omitted when ``static`` is
    None) when the model observes its mesh forces, and the lanes' step counts."""
    out = {
        "period": lane_periods(r, max_period, tol),
        "section_periods": r.sample_every,
        "converged": r.converged,
        "steps_per_period": r.steps_per_period,
        "transient_periods": r.transient_periods,
        "unresolved_steps": r.unresolved,
    }
    if model.meshes:
        out["contact"] = np.stack([contact_regime(r.event_min, r.event_max, r.crossings, d, b,
                                                  r.status) for _, d, b in model.meshes], axis=1)
    if has_mesh_forces(model):
        peak = np.maximum(np.abs(r.obs_max), np.abs(r.obs_min))
        out["force_peak"] = peak
        out["force_rms"] = r.obs_rms
        if static is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                out["dynamic_factor"] = peak / np.abs(static)
    return out
