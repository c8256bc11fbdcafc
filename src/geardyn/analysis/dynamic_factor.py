"""The dynamic factor of a spur pair model against ISO 6336-1 K_v (method B).

:func:`iso_inputs` turns a :class:`~geardyn.SpurPair` (its geometry, inertias and torque) and
the accuracy-grade inputs into :class:`~geardyn.gears.iso6336_kv.DynamicFactorInputs`;
:func:`dynamic_factor_sweep` sweeps the pinion speed (one :func:`~geardyn.bifurcation` per
torque) and returns the model's dynamic factor (peak dynamic mesh force over the static
T1 / r_b1) beside K_v for the same gears, with the standard's resonance speed N_M (n_E1) and
the model's own linear resonance speed. See ``docs/dynamic-factor.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import xarray as xr

from geardyn.analysis.bifurcation import bifurcation
from geardyn.core.settings import RunSettings
from geardyn.errors import ParameterError
from geardyn.gears.iso6336 import N_PER_MM_UM, iso6336_stiffness
from geardyn.gears.iso6336_kv import (
    REGIMES,
    DynamicFactorInputs,
    dynamic_factor_iso,
    lower_resonance_limit,
    reduced_mass,
    resonance_ratio,
    resonance_speed,
)
from geardyn.models.spur_pair import SpurPair
from geardyn.models.spur_pair_coefficients import SPEED_UNITS
from geardyn.models.spur_pair_kernels import TORQUE

__all__ = ["STIFFNESS_SOURCES", "dynamic_factor_sweep", "iso_inputs", "linear_resonance_speed"]

#: Where c' and c_gamma_alpha of K_v come from: ISO 6336-1 method B (clause 9), or the model's
#: own mean drive stiffness (c_gamma_alpha = k_mean / b, c' = c_gamma_alpha / (0.75 eps + 0.25)).
STIFFNESS_SOURCES = ("iso", "model")
_RPM = SPEED_UNITS["rpm"]


def _face_width(model: SpurPair) -> float:
    return min(model.mesh.pinion.face_width, model.mesh.wheel.face_width)


def iso_inputs(model: SpurPair, *, base_pitch_deviation: float, profile_form_deviation: float,
               pitch_running_in: float = 0.0, profile_running_in: float = 0.0,
               tip_relief: float = 0.0, application_factor: float = 1.0,
               torque: float | None = None, stiffness: str = "iso") -> DynamicFactorInputs:
    """ISO 6336-1 method B inputs of ``model``'s mesh at the pinion ``torque`` [N m] (default
    the model's): z1 the pinion's teeth; the line load F_t K_A / b [N/mm] with F_t = T1 / r1
    (r1 the pinion's reference radius) and K_A = ``application_factor``; m_red from the model's
    inertias (:func:`~geardyn.gears.iso6336_kv.reduced_mass`); c', c_gamma_alpha and eps_alpha
    by ISO 6336-1 method B at that line load (``stiffness="iso"``) or from the model's mean
    drive stiffness (``"model"``). The deviations, running-in allowances and tip relief [um]
    as :class:`~geardyn.gears.iso6336_kv.DynamicFactorInputs`."""
    if not isinstance(model, SpurPair):
        raise ParameterError("model", type(model).__name__, "must be a geardyn.SpurPair")
    if stiffness not in STIFFNESS_SOURCES:
        raise ParameterError("stiffness", stiffness, f"must be one of {STIFFNESS_SOURCES}")
    t1 = float(model.params[TORQUE]) if torque is None else float(torque)
    if not (math.isfinite(t1) and t1 > 0.0):
        raise ParameterError("torque", torque, "K_v needs a positive pinion torque [N m]")
    k_a = float(application_factor)
    if not (math.isfinite(k_a) and k_a >= 1.0):
        raise ParameterError("application_factor", application_factor, "K_A must be >= 1")
    mesh, b = model.mesh, _face_width(model)
    load = t1 / mesh.pinion.reference_radius * k_a / b  # N/m
    iso = iso6336_stiffness(mesh, line_load=load)
    eps = iso.contact_ratio
    if stiffness == "iso":
        c_prime, c_gamma = iso.c_prime, iso.c_gamma_alpha
    else:
        c_gamma = float(model.drive_series[0]) / b / N_PER_MM_UM
        c_prime = c_gamma / (0.75 * eps + 0.25)
    i1, i2 = model.inertia
    return DynamicFactorInputs(
        pinion_teeth=mesh.pinion.teeth,
        reduced_mass=reduced_mass(i1, i2, mesh.pinion.base_radius, mesh.wheel.base_radius, b),
        single_stiffness=c_prime, mesh_stiffness=c_gamma, line_load=load * 1e-3,
        base_pitch_deviation=base_pitch_deviation, profile_form_deviation=profile_form_deviation,
        pitch_running_in=pitch_running_in, profile_running_in=profile_running_in,
        tip_relief=tip_relief, contact_ratio=eps)


def linear_resonance_speed(model: SpurPair) -> float:
    """The pinion speed [rpm] at which the mesh frequency meets the model's linear natural
    frequency sqrt(k_mean / m) (drive flanks in contact)."""
    return float(model.natural_frequencies()[0]) / model.mesh.pinion.teeth / _RPM


def dynamic_factor_sweep(model: SpurPair, speeds: Sequence[float] | np.ndarray,
                         torques: Sequence[float] | np.ndarray | None = None,
                         run: RunSettings | None = None, *, base_pitch_deviation: float,
                         profile_form_deviation: float, pitch_running_in: float = 0.0,
                         profile_running_in: float = 0.0, tip_relief: float = 0.0,
                         application_factor: float = 1.0, stiffness: str = "iso",
                         **sweep: object) -> xr.Dataset:
    """The model's dynamic factor and ISO 6336-1 K_v over pinion ``speeds`` [rpm] and
    ``torques`` [N m] (default the model's torque).

    For each torque, :func:`~geardyn.bifurcation` of the pinion speed (``run``, ``sweep``: its
    other keywords, e.g. ``continuation="up"``) gives the steady response; K_v comes from
    :func:`~geardyn.gears.iso6336_kv.dynamic_factor_iso` with :func:`iso_inputs` (the
    accuracy inputs [um], ``application_factor``, ``stiffness``) at that torque.

    Returns a Dataset over (``torque``, ``speed``): ``dynamic_factor`` (model: peak dynamic
    mesh force / T1 / r_b1), ``force_peak`` [N], ``contact`` (the model's contact regime),
    ``period``, ``K_v``, ``resonance_ratio`` N and ``iso_range`` (index into ``iso_ranges``
    attribute: subcritical, main resonance, intermediate, supercritical); over ``torque``:
    ``resonance_speed`` (ISO's n_E1 = N_M, rpm), ``lower_resonance_limit`` N_S, ``line_load``
    [N/mm], ``single_stiffness`` and ``mesh_stiffness`` [N/(mm um)]; coordinate
    ``mesh_frequency`` [Hz]; attributes ``linear_resonance_speed`` [rpm] (the model's), the
    inputs and the stiffness source.
    """
    rpm = np.asarray(speeds, dtype=float).ravel()
    if rpm.size < 1 or not np.all(np.isfinite(rpm)) or np.any(rpm <= 0.0):
        raise ParameterError("speeds", speeds, "give one or more pinion speeds > 0 rpm")
    loads = (np.array([float(model.params[TORQUE])]) if torques is None
             else np.asarray(torques, dtype=float).ravel())
    if loads.size < 1 or not np.all(np.isfinite(loads)) or np.any(loads <= 0.0):
        raise ParameterError("torques", torques, "give one or more pinion torques > 0 N m")
    accuracy = dict(base_pitch_deviation=base_pitch_deviation,
                    profile_form_deviation=profile_form_deviation,
                    pitch_running_in=pitch_running_in, profile_running_in=profile_running_in,
                    tip_relief=tip_relief, application_factor=application_factor,
                    stiffness=stiffness)
    in_unit = rpm * _RPM / SPEED_UNITS[model.speed_unit]
    rows, per_torque = [], []
    for t1 in loads:
        inputs = iso_inputs(model, torque=float(t1), **accuracy)
        m = model.with_params(torque=float(t1))
        ds = bifurcation(m, "speed", in_unit, run or RunSettings(), **sweep)
        kv, regime = dynamic_factor_iso(inputs, rpm)
        rows.append(xr.Dataset({
            "dynamic_factor": ("speed", ds["dynamic_factor"].values[:, 0]),
            "force_peak": ("speed", ds["force_peak"].values[:, 0]),
            "contact": ("speed", ds["contact"].values[:, 0]),
            "period": ("speed", ds["period"].values),
            "K_v": ("speed", kv),
            "resonance_ratio": ("speed", resonance_ratio(inputs, rpm)),
            "iso_range": ("speed", regime),
        }))
        per_torque.append((resonance_speed(inputs), lower_resonance_limit(inputs.line_load),
                           inputs.line_load, inputs.single_stiffness, inputs.mesh_stiffness))
    out = xr.concat(rows, dim="torque")
    cols = np.array(per_torque)
    for j, name in enumerate(("resonance_speed", "lower_resonance_limit", "line_load",
                              "single_stiffness", "mesh_stiffness")):
        out[name] = ("torque", cols[:, j])
    out = out.assign_coords(
        speed=("speed", rpm, {"units": "rpm", "long_name": "pinion speed"}),
        torque=("torque", loads, {"units": "N m", "long_name": "pinion torque"}),
        mesh_frequency=("speed", rpm * model.mesh.pinion.teeth / 60.0,
                        {"units": "Hz", "long_name": "mesh frequency"}))
    _describe(out)
    out.attrs.update(
        model=repr(model), stiffness_source=stiffness,
        linear_resonance_speed=linear_resonance_speed(model),
        iso_ranges=", ".join(REGIMES), standard="ISO 6336-1:2006 clause 6.5 (method B)",
        **{k: float(v) for k, v in accuracy.items() if k != "stiffness"})
    return out


def _describe(ds: xr.Dataset) -> None:
    meta = {
        "dynamic_factor": {"long_name": "model dynamic factor",
                           "meaning": "peak dynamic mesh force / static mesh force T1 / r_b1"},
        "force_peak": {"units": "N", "long_name": "peak dynamic mesh force"},
        "contact": {"meaning": "none: teeth never separate; single: separation, no back-flank "
                               "contact; double: back-flank contact; unbounded: diverged"},
        "period": {"long_name": "period in forcing periods"},
        "K_v": {"long_name": "ISO 6336-1 dynamic factor K_v (method B)"},
        "resonance_ratio": {"long_name": "resonance ratio N = n1 / n_E1"},
        "iso_range": {"meaning": "0 subcritical, 1 main resonance, 2 intermediate, "
                                 "3 supercritical"},
        "resonance_speed": {"units": "rpm", "long_name": "ISO resonance speed n_E1 (N_M)"},
        "lower_resonance_limit": {"long_name": "N_S, lower limit of the main resonance range"},
        "line_load": {"units": "N/mm", "long_name": "F_t K_A / b"},
        "single_stiffness": {"units": "N/(mm um)", "long_name": "c'"},
        "mesh_stiffness": {"units": "N/(mm um)", "long_name": "c_gamma_alpha"},
    }
    for name, attrs in meta.items():
        ds[name].attrs.update(attrs)
