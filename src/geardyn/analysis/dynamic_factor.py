"""The dynamic factor of a model built from gear geometry against ISO 6336-1 K_v (method B).

A model with the ``dynamic_factor`` capability (:class:`~geardyn.core.capabilities.
Capabilities`: :class:`~geardyn.SpurPair`, :class:`~geardyn.PlanetaryGearSet` built from
geometry, :class:`~geardyn.trains.TrainModel`, a :class:`~geardyn.UserModel` that declares it
with :class:`~geardyn.DynamicFactorDeclaration`) gives its mesh groups at an input
torque (:class:`~geardyn.gears.iso6336_kv.KvMeshGroup`); :func:`iso_inputs` turns them and the
accuracy-grade inputs into :class:`~geardyn.gears.iso6336_kv.DynamicFactorInputs`.
:func:`dynamic_factor_sweep` sweeps the input speed (one :func:`~geardyn.bifurcation` per
torque) and returns the model's dynamic factor (peak dynamic mesh force over the static one,
the largest over a group's meshes) beside K_v for the same gears, with the standard's resonance
speed N_M. See ``docs/dynamic-factor.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import xarray as xr

from geardyn.analysis.bifurcation import bifurcation
from geardyn.analysis.lanes import CONTACT_LABELS
from geardyn.core.model import Model
from geardyn.core.results import finish
from geardyn.core.settings import RunSettings
from geardyn.errors import ParameterError
from geardyn.gears.iso6336_kv import (
    REGIMES,
    STIFFNESS_SOURCES,
    DynamicFactorInputs,
    KvMeshGroup,
    dynamic_factor_iso,
    group_inputs,
    lower_resonance_limit,
    resonance_ratio,
    resonance_speed,
)
from geardyn.models.spur_pair import SpurPair

__all__ = ["STIFFNESS_SOURCES", "dynamic_factor_sweep", "iso_inputs", "linear_resonance_speed"]


def _checked(model: Model) -> Model:
    if not model.capabilities.dynamic_factor:
        raise ParameterError("model", model.name, "K_v needs the dynamic_factor capability: a "
                             "model built from gear geometry under load (SpurPair, "
                             "PlanetaryGearSet.from_geometry, a TrainModel), or a "
                             "UserModel.from_one_form that declares it (dynamic_factor="
                             "DynamicFactorDeclaration(...): its input speed and torque "
                             "coefficients, mesh groups and natural frequencies)")
    return model


def _torque(model: Model, torque: float | None) -> float:
    t = float(model.input_torque) if torque is None else float(torque)
    if not (math.isfinite(t) and t > 0.0):
        raise ParameterError("torque", torque, "K_v needs a positive input torque [N m]")
    return t


def _groups(model: Model, torque: float | None) -> tuple[KvMeshGroup, ...]:
    return _checked(model).kv_groups(_torque(model, torque))


def iso_inputs(model: Model, *, base_pitch_deviation: float, profile_form_deviation: float,
               pitch_running_in: float = 0.0, profile_running_in: float = 0.0,
               tip_relief: float = 0.0, application_factor: float = 1.0,
               torque: float | None = None, stiffness: str = "iso"
               ) -> dict[str, DynamicFactorInputs]:
    """ISO 6336-1 method B inputs of each mesh group of ``model`` at the input ``torque`` [N m]
    (default the model's ``input_torque``), by group name.

    The groups come from the model (``kv_groups``): a :class:`~geardyn.SpurPair` has one,
    ``"mesh"`` (F_t = T1 / r1, m_red from its inertias); a :class:`~geardyn.PlanetaryGearSet`
    built from geometry ``"sun"`` and ``"ring"`` (clause 6.5.9); a train one per mesh or per
    planetary group. The line load F_t K_A / b with K_A = ``application_factor``; c',
    c_gamma_alpha and eps_alpha by ISO 6336-1 method B at that load (``stiffness="iso"``) or from
    the model's mean drive stiffness (``"model"``); eps_gamma adds a helical pair's overlap
    ratio. The deviations, running-in allowances and tip relief [um] as
    :class:`~geardyn.gears.iso6336_kv.DynamicFactorInputs`
    (:func:`~geardyn.gears.iso6336_kv.group_inputs`)."""
    accuracy = dict(base_pitch_deviation=base_pitch_deviation,
                    profile_form_deviation=profile_form_deviation,
                    pitch_running_in=pitch_running_in, profile_running_in=profile_running_in,
                    tip_relief=tip_relief)
    return {g.name: group_inputs(g, application_factor=application_factor, stiffness=stiffness,
                                 **accuracy) for g in _groups(model, torque)}


def linear_resonance_speed(model: SpurPair) -> float:
    """The pinion speed [rpm] at which the mesh frequency meets the model's linear natural
    frequency sqrt(k_mean / m) (drive flanks in contact)."""
    return float(model.natural_frequencies()[0]) / model.mesh.pinion.teeth \
        * 60.0 / (2.0 * math.pi)


def _natural_speeds(model: Model) -> np.ndarray:
    """Input speeds [rpm] at which the reference mesh's frequency meets each natural
    frequency (rad/s read as such: a model with this capability runs in seconds or gives
    Hz)."""
    f = np.asarray(model.natural_frequencies(), dtype=float)
    if model.capabilities.natural_frequencies == "rad/time":
        f = f / (2.0 * math.pi)
    return np.unique(np.round(f[f > 0.0] * 60.0 / model.mesh_frequency_per_input_speed(), 3))


def dynamic_factor_sweep(model: Model, speeds: Sequence[float] | np.ndarray,
                         torques: Sequence[float] | np.ndarray | None = None,
                         run: RunSettings | None = None, *, base_pitch_deviation: float,
                         profile_form_deviation: float, pitch_running_in: float = 0.0,
                         profile_running_in: float = 0.0, tip_relief: float = 0.0,
                         application_factor: float = 1.0, stiffness: str = "iso",
                         **sweep: object) -> xr.Dataset:
    """The model's dynamic factor and ISO 6336-1 K_v over input ``speeds`` [rpm] (a spur
    pair's pinion, a planetary stage's input member, a train's driven body) and ``torques``
    [N m] (the model's ``input_torque``: the pinion's, the sun's, the driven body's; default
    the model's own).

    For each torque, :func:`~geardyn.bifurcation` of the input speed (``run``; ``sweep``: its
    other keywords, e.g. ``continuation="up"``) gives the steady response; K_v comes from
    :func:`~geardyn.gears.iso6336_kv.dynamic_factor_iso` with :func:`iso_inputs` (the
    accuracy inputs [um], ``application_factor``, ``stiffness``) at that torque.

    Returns a Dataset over (``torque``, ``speed``, ``group``) (the mesh groups of
    :func:`iso_inputs`): ``dynamic_factor`` (model: peak dynamic mesh force / static mesh
    force, the largest over the group's meshes), ``contact`` (the most severe contact regime
    of the group's meshes), ``period``, ``K_v``, ``resonance_ratio`` N and ``iso_range`` (0
    subcritical, 1 main resonance, 2 intermediate, 3 supercritical); over (``torque``,
    ``group``): ``resonance_speed`` (ISO's N_M as an input speed, rpm: gear 1 at n_E1),
    ``lower_resonance_limit`` N_S, ``line_load`` [N/mm], ``single_stiffness`` and
    ``mesh_stiffness`` [N/(mm um)]; coordinate ``mesh_frequency`` [Hz] (the reference mesh's);
    attributes the inputs, the stiffness source and ``natural_speeds`` [rpm] (the input speeds
    at which the reference mesh's frequency meets each natural frequency of the linear
    model).
    """
    _checked(model)
    rpm = np.asarray(speeds, dtype=float).ravel()
    if rpm.size < 1 or not np.all(np.isfinite(rpm)) or np.any(rpm <= 0.0):
        raise ParameterError("speeds", speeds, "give one or more input speeds > 0 rpm")
    loads = (np.array([_torque(model, None)]) if torques is None
             else np.asarray(torques, dtype=float).ravel())
    if loads.size < 1 or not np.all(np.isfinite(loads)) or np.any(loads <= 0.0):
        raise ParameterError("torques", torques, "give one or more input torques > 0 N m")
    accuracy = dict(base_pitch_deviation=base_pitch_deviation,
                    profile_form_deviation=profile_form_deviation,
                    pitch_running_in=pitch_running_in, profile_running_in=profile_running_in,
                    tip_relief=tip_relief)
    param, values = model.input_speed_sweep(rpm)
    severity = {label: k for k, label in enumerate(CONTACT_LABELS)}
    rows, per_torque = [], []
    for t1 in loads:
        groups = _groups(model, float(t1))
        inputs = [group_inputs(g, application_factor=application_factor, stiffness=stiffness,
                               **accuracy) for g in groups]
        ds = bifurcation(model.at_input_torque(float(t1)), param, values,
                         run or RunSettings(), **sweep)
        df_all, contact_all = ds["dynamic_factor"].values, ds["contact"].values.astype(str)
        cols: dict[str, list[np.ndarray]] = {k: [] for k in (
            "dynamic_factor", "contact", "K_v", "resonance_ratio", "iso_range")}
        scalars = []
        for g, inp in zip(groups, inputs, strict=True):
            idx = list(g.meshes)
            cols["dynamic_factor"].append(np.max(df_all[:, idx], axis=1))
            codes = np.vectorize(severity.get)(contact_all[:, idx])
            cols["contact"].append(np.array(CONTACT_LABELS)[np.max(codes, axis=1)])
            kv, regime = dynamic_factor_iso(inp, rpm * g.speed_per_input)
            cols["K_v"].append(kv)
            cols["resonance_ratio"].append(resonance_ratio(inp, rpm * g.speed_per_input))
            cols["iso_range"].append(regime)
            scalars.append((resonance_speed(inp) / g.speed_per_input,
                            lower_resonance_limit(inp.line_load), inp.line_load,
                            inp.single_stiffness, inp.mesh_stiffness))
        rows.append(xr.Dataset(
            {k: (("speed", "group"), np.stack(v, axis=1)) for k, v in cols.items()}
            | {"period": ("speed", ds["period"].values, dict(ds["period"].attrs))}))
        per_torque.append(scalars)
    out = xr.concat(rows, dim="torque")
    table = np.array(per_torque)  # torque, group, quantity
    for j, name in enumerate(("resonance_speed", "lower_resonance_limit", "line_load",
                              "single_stiffness", "mesh_stiffness")):
        out[name] = (("torque", "group"), table[:, :, j])
    per_mesh_hz = model.mesh_frequency_per_input_speed()
    out = out.assign_coords(
        group=("group", [g.name for g in groups]),
        speed=("speed", rpm, {"units": "rpm", "long_name": "input speed"}),
        torque=("torque", loads, {"units": "N m", "long_name": "input torque"}),
        mesh_frequency=("speed", rpm * per_mesh_hz / 60.0,
                        {"units": "Hz", "long_name": "mesh frequency"}))
    _describe(out)
    out.attrs.update(model=repr(model), stiffness_source=stiffness, iso_ranges=", ".join(REGIMES),
                     standard="ISO 6336-1:2006 clause 6.5 (method B)",
                     application_factor=float(application_factor),
                     natural_speeds=_natural_speeds(model),
                     **{k: float(v) for k, v in accuracy.items()})
    return finish(out, "dynamic-factor")


def _describe(ds: xr.Dataset) -> None:
    meta = {
        "dynamic_factor": {"long_name": "model dynamic factor",
                           "meaning": "peak dynamic mesh force / static mesh force (largest "
                                      "over the group's meshes)"},
        "contact": {"meaning": "the most severe regime of the group's meshes: none (teeth never"
                               " separate), single (separation), double (back-flank contact),"
                               " unbounded (diverged)"},
        "period": {"long_name": "period in forcing periods"},
        "K_v": {"long_name": "ISO 6336-1 dynamic factor K_v (method B)"},
        "resonance_ratio": {"long_name": "resonance ratio N = n1 / n_E1"},
        "iso_range": {"meaning": "0 subcritical, 1 main resonance, 2 intermediate, "
                                 "3 supercritical"},
        "resonance_speed": {"units": "rpm",
                            "long_name": "ISO resonance speed N_M as an input speed"},
        "lower_resonance_limit": {"long_name": "N_S, lower limit of the main resonance range"},
        "line_load": {"units": "N/mm", "long_name": "F_t K_A / b"},
        "single_stiffness": {"units": "N/(mm um)", "long_name": "c'"},
        "mesh_stiffness": {"units": "N/(mm um)", "long_name": "c_gamma_alpha"},
    }
    for name, attrs in meta.items():
        ds[name].attrs.update(attrs)
