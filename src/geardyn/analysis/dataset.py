"""Labelled datasets from lane results: the sweep (:func:`geardyn.bifurcation`) and the map
(:func:`geardyn.map2d`) share their coordinates, per-lane variables (dims, units and meanings
from :mod:`geardyn.analysis.lanes`), status meanings and model attributes here.

Every builder ends with :func:`geardyn.core.results.finish`: the kind recorded in
``attrs["geardyn_kind"]`` and the dataset checked against the kind's schema, the registry
:func:`geardyn.testing.assert_result` reads too. (The simulation's dataset is built in
:mod:`geardyn.solvers.simulate`, a layer below analysis.)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from geardyn.analysis.lanes import (
    CONTACT_LABELS,
    lane_periods,
    lane_variables,
    variable_attrs,
    variable_dims,
)
from geardyn.analysis.lyapunov import lyapunov_err_attrs, lyapunov_unresolved_attrs
from geardyn.core.model import Model
from geardyn.core.results import finish
from geardyn.core.status import status_attrs
from geardyn.solvers.ensemble import LaneResults


def model_attrs(model: Model) -> dict[str, object]:
    """The attributes every sweep and map records about its model: ``interpretation`` and the
    natural frequency ``omega_n`` (rad/s), where the model has them, and the sweep kernels'
    ``kernel_path`` (:data:`~geardyn.core.kernel_source.KERNEL_PATHS`)."""
    return {**model.dataset_attrs(), "kernel_path": model.kernel.kernel_path}


def param_attrs(model: Model, name: str) -> dict[str, str]:
    """Attributes of the axis of swept parameter ``name`` (``units``, ...), where the model
    names them (``model.param_attrs``, e.g. the planetary set's ``mesh_frequency`` [rad/s] and
    ``input_speed`` [rpm]); else none."""
    return dict(model.param_attrs(name))


def _with_mesh(ds: xr.Dataset, model: Model) -> xr.Dataset:
    """``ds`` with the ``mesh`` coordinate (the meshes' names), where the model has meshes."""
    if model.meshes:
        ds = ds.assign_coords(mesh=("mesh", [m[0] for m in model.meshes]))
    return ds


def sweep_dataset(model: Model, param: str, values: np.ndarray, runs: Sequence[LaneResults],
                  max_period: int, tol: float, static: np.ndarray | None) -> xr.Dataset:
    """The sweep dataset of one or more starts' lane results along ``param`` (without the run
    settings): Poincare points, the per-lane variables, ``status`` (the worst over the starts)
    and ``final_time``; ``static`` the static mesh forces of each point (or None)."""
    first = runs[0]
    poincare = np.concatenate([r.samples for r in runs], axis=1)
    per_lane = lane_variables(model, first, static, max_period, tol)
    per_lane["unresolved_steps"] = np.sum([r.unresolved for r in runs], axis=0)  # every start
    status = np.max(np.stack([r.status for r in runs], axis=1), axis=1)
    ds = xr.Dataset(coords={
        param: (param, values, param_attrs(model, param)),
        "sample": ("sample", np.arange(poincare.shape[1])),
        "state": ("state", list(model.state_names)),
    })
    ds = _with_mesh(ds, model)
    ds["poincare"] = ((param, "sample", "state"), poincare, {
        "long_name": "Poincare points (states once per forcing period after the transient)"})
    dims, attrs = variable_dims(model), variable_attrs(model, max_period, tol)
    for name, data in per_lane.items():
        ds[name] = ((param, *dims[name]), data, attrs[name])
    if len(runs) > 1:
        samples = first.samples.shape[1]
        periods = np.stack([per_lane["period"]] + [lane_periods(r, max_period, tol)
                                                   for r in runs[1:]], axis=1)
        ds["period_by_start"] = ((param, "start"), periods)
        ds["start_of_sample"] = ("sample", np.repeat(np.arange(len(runs)), samples))
    ds["status"] = (param, status, status_attrs(" in at least one start"))
    ds["final_time"] = (param, first.final_time, {
        "long_name": "model time at the last Poincare sample (the final state)",
        "units": model.time_unit})
    ds.attrs.update(model=model.name, param=param, time_unit=model.time_unit,
                    state_units=model.state_units)
    ds.attrs.update(model_attrs(model))
    return finish(ds, "bifurcation")


def map_dataset(model: Model, y: tuple[str, np.ndarray], x: tuple[str, np.ndarray],
                out: dict[str, np.ndarray], max_period: int, tol: float) -> xr.Dataset:
    """The map dataset over the grid ``y`` x ``x`` (name, values) of the per-point results
    ``out`` (flat, y-major): the per-lane variables, ``status`` and, where computed,
    ``lyapunov``, ``lyapunov_err`` and ``lyapunov_unresolved``; ``contact`` codes become their
    labels. Without the run settings and the motion classes."""
    (yn, yv), (xn, xv) = y, x
    ny, nx = yv.size, xv.size
    ds = _with_mesh(xr.Dataset(coords={yn: (yn, yv, param_attrs(model, yn)),
                                       xn: (xn, xv, param_attrs(model, xn))}), model)
    dims, attrs = variable_dims(model), variable_attrs(model, max_period, tol)
    dims.update(status=(), lyapunov=(), lyapunov_err=(), lyapunov_unresolved=())
    attrs.update(status=status_attrs(),
                 lyapunov={"long_name": "largest Lyapunov exponent",
                           "units": f"1/{model.time_unit}",
                           "start": "each point's final state at its final time"},
                 lyapunov_err=lyapunov_err_attrs(model.time_unit),
                 lyapunov_unresolved=lyapunov_unresolved_attrs())
    for name in (*variable_dims(model), "status", "lyapunov", "lyapunov_err",
                 "lyapunov_unresolved"):
        if name not in out:
            continue
        data = out[name].reshape(ny, nx, *out[name].shape[1:])
        if name == "contact":
            data = np.array(CONTACT_LABELS)[data]
        ds[name] = ((yn, xn, *dims[name]), data, attrs[name])
    return ds
