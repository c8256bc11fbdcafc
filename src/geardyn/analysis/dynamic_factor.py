"""The dynamic factor of a model built from gear geometry against ISO 6336-1 K_v (method B).

:func:`iso_inputs` turns a :class:`~geardyn.SpurPair` or a :class:`~geardyn.PlanetaryGearSet`
built from geometry (its gears, inertias and input torque) and the accuracy-grade inputs into
:class:`~geardyn.gears.iso6336_kv.DynamicFactorInputs`, one per mesh group (the pair's mesh;
a planetary stage's sun-planet and ring-planet meshes). :func:`dynamic_factor_sweep` sweeps
the input speed (one :func:`~geardyn.bifurcation` per torque) and returns the model's dynamic
factor (peak dynamic mesh force over the static one, the largest over a group's meshes) beside
K_v for the same gears, with the standard's resonance speed N_M. See
``docs/dynamic-factor.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn.analysis.bifurcation import bifurcation
from geardyn.analysis.lanes import CONTACT_LABELS
from geardyn.core.model import Model
from geardyn.core.results import finish
from geardyn.core.settings import RunSettings
from geardyn.errors import ParameterError
from geardyn.gears.iso6336 import N_PER_MM_UM, iso6336_stiffness
from geardyn.gears.iso6336_kv import (
    REGIMES,
    DynamicFactorInputs,
    dynamic_factor_iso,
    lower_resonance_limit,
    planetary_reduced_masses,
    reduced_mass,
    resonance_ratio,
    resonance_speed,
)
from geardyn.models.planetary import PlanetaryGearSet
from geardyn.models.spur_pair import SpurPair
from geardyn.models.spur_pair_coefficients import SPEED_UNITS
from geardyn.models.spur_pair_kernels import TORQUE

__all__ = ["STIFFNESS_SOURCES", "dynamic_factor_sweep", "iso_inputs", "linear_resonance_speed"]

#: Where c' and c_gamma_alpha of K_v come from: ISO 6336-1 method B (clause 9), or the model's
#: own mean drive stiffness (c_gamma_alpha = k_mean / b, c' = c_gamma_alpha / (0.75 eps + 0.25)).
STIFFNESS_SOURCES = ("iso", "model")
_RPM = SPEED_UNITS["rpm"]


@dataclass(frozen=True)
class _Group:
    """A mesh group of the model: ISO's inputs, the model's meshes (indices) and gear 1's
    speed per input speed (both rpm)."""

    inputs: DynamicFactorInputs
    meshes: tuple[int, ...]
    per_input: float


def _torque(model: Model, torque: float | None) -> float:
    if torque is None:
        t = float(model.params[TORQUE]) if isinstance(model, SpurPair) \
            else abs(float(model.torques["sun"]))
    else:
        t = float(torque)
    if not (math.isfinite(t) and t > 0.0):
        raise ParameterError("torque", torque, "K_v needs a positive input (pinion or sun) "
                             "torque [N m]")
    return t


def _mesh_inputs(mesh, width: float, load: float, mass: float, stiffness: str,
                 model_k: float, z1: int, accuracy: dict) -> DynamicFactorInputs:
    """ISO inputs of one mesh at the line load ``load`` [N/m], reduced mass [kg/mm]."""
    iso = iso6336_stiffness(mesh, line_load=load)
    eps = iso.contact_ratio
    if stiffness == "iso":
        c_prime, c_gamma = iso.c_prime, iso.c_gamma_alpha
    else:
        c_gamma = model_k / width / N_PER_MM_UM
        c_prime = c_gamma / (0.75 * eps + 0.25)
    return DynamicFactorInputs(pinion_teeth=z1, reduced_mass=mass, single_stiffness=c_prime,
                               mesh_stiffness=c_gamma, line_load=load * 1e-3,
                               contact_ratio=eps, **accuracy)


def _groups(model: Model, *, torque: float | None, application_factor: float, stiffness: str,
            **accuracy: float) -> dict[str, _Group]:
    if stiffness not in STIFFNESS_SOURCES:
        raise ParameterError("stiffness", stiffness, f"must be one of {STIFFNESS_SOURCES}")
    k_a = float(application_factor)
    if not (math.isfinite(k_a) and k_a >= 1.0):
        raise ParameterError("application_factor", application_factor, "K_A must be >= 1")
    t1 = _torque(model, torque)
    if isinstance(model, SpurPair):
        mesh = model.mesh
        b = min(mesh.pinion.face_width, mesh.wheel.face_width)
        load = t1 / mesh.pinion.reference_radius * k_a / b  # N/m
        i1, i2 = model.inertia
        m_red = reduced_mass(i1, i2, mesh.pinion.base_radius, mesh.wheel.base_radius, b)
        inputs = _mesh_inputs(mesh, b, load, m_red, stiffness, float(model.drive_series[0]),
                              mesh.pinion.teeth, accuracy)
        return {"mesh": _Group(inputs, (0,), 1.0)}
    if isinstance(model, PlanetaryGearSet) and model.geometry is not None:
        geo, n = model.geometry, model.n_planets
        sun, planet, ring = geo.sun, geo.planet, geo.ring
        per_input = model.mesh_frequency_per_input_speed()
        f_t = t1 / (sun.reference_radius * n)  # tangential force per planet, sun circle
        k_mean = model.mesh_stiffnesses()
        out = {}
        for name, mesh, z1, other in (("sun", geo.sun_mesh, sun.teeth, sun),
                                      ("ring", geo.ring_mesh, planet.teeth, ring)):
            b = min(planet.face_width, other.face_width)
            m_sp, m_rp = planetary_reduced_masses(
                model.members["sun"].inertia_over_r2 * sun.base_radius ** 2,
                model.members["planet"].inertia_over_r2 * planet.base_radius ** 2,
                sun.base_radius, planet.base_radius, n, b)
            # the ring-planet force equals the sun-planet force (planet in moment balance)
            idx = tuple(range(n)) if name == "sun" else tuple(range(n, 2 * n))
            inputs = _mesh_inputs(mesh, b, f_t * k_a / b, m_sp if name == "sun" else m_rp,
                                  stiffness, float(np.mean(k_mean[list(idx)])), z1, accuracy)
            out[name] = _Group(inputs, idx, per_input / z1)
        return out
    raise ParameterError("model", type(model).__name__, "must be a geardyn.SpurPair or a "
                         "PlanetaryGearSet built from geometry (from_geometry)")


def iso_inputs(model: Model, *, base_pitch_deviation: float, profile_form_deviation: float,
               pitch_running_in: float = 0.0, profile_running_in: float = 0.0,
               tip_relief: float = 0.0, application_factor: float = 1.0,
               torque: float | None = None, stiffness: str = "iso"
               ) -> dict[str, DynamicFactorInputs]:
    """ISO 6336-1 method B inputs of each mesh group of ``model`` at the input ``torque`` [N m]
    (default the model's pinion torque, or the magnitude of its sun torque).

    A :class:`~geardyn.SpurPair`: one group, ``"mesh"``; z1 the pinion's teeth, F_t = T1 / r1
    (r1 the pinion's reference radius), m_red from the model's inertias
    (:func:`~geardyn.gears.iso6336_kv.reduced_mass`). A :class:`~geardyn.PlanetaryGearSet`
    built from geometry: ``"sun"`` (z1 the sun's teeth) and ``"ring"`` (z1 the planet's teeth,
    speeds relative to the carrier), F_t = T_s / (r_s N) per planet, m_red of clause 6.5.9
    (:func:`~geardyn.gears.iso6336_kv.planetary_reduced_masses`, the members' I/r^2 on their
    base radii). The line load F_t K_A / b with K_A = ``application_factor``; c', c_gamma_alpha
    and eps_alpha by ISO 6336-1 method B at that load (``stiffness="iso"``) or from the model's
    mean drive stiffness (``"model"``). The deviations, running-in allowances and tip relief
    [um] as :class:`~geardyn.gears.iso6336_kv.DynamicFactorInputs`."""
    groups = _groups(model, torque=torque, application_factor=application_factor,
                     stiffness=stiffness, base_pitch_deviation=base_pitch_deviation,
                     profile_form_deviation=profile_form_deviation,
                     pitch_running_in=pitch_running_in, profile_running_in=profile_running_in,
                     tip_relief=tip_relief)
    return {name: g.inputs for name, g in groups.items()}


def linear_resonance_speed(model: SpurPair) -> float:
    """The pinion speed [rpm] at which the mesh frequency meets the model's linear natural
    frequency sqrt(k_mean / m) (drive flanks in contact)."""
    return float(model.natural_frequencies()[0]) / model.mesh.pinion.teeth / _RPM


def _sweep_axis(model: Model, rpm: np.ndarray) -> tuple[str, np.ndarray, str]:
    """The swept parameter, its values for ``rpm`` input speeds, and the torque input."""
    if isinstance(model, SpurPair):
        return "speed", rpm * _RPM / SPEED_UNITS[model.speed_unit], "torque"
    return "input_speed", rpm, "sun_torque"


def dynamic_factor_sweep(model: Model, speeds: Sequence[float] | np.ndarray,
                         torques: Sequence[float] | np.ndarray | None = None,
                         run: RunSettings | None = None, *, base_pitch_deviation: float,
                         profile_form_deviation: float, pitch_running_in: float = 0.0,
                         profile_running_in: float = 0.0, tip_relief: float = 0.0,
                         application_factor: float = 1.0, stiffness: str = "iso",
                         **sweep: object) -> xr.Dataset:
    """The model's dynamic factor and ISO 6336-1 K_v over input ``speeds`` [rpm] (a spur
    pair's pinion, a planetary stage's input member) and ``torques`` [N m] (the pinion's or the
    sun's; default the model's).

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
    ``mesh_stiffness`` [N/(mm um)]; coordinate ``mesh_frequency`` [Hz]; attributes the inputs,
    the stiffness source and, for a spur pair, ``linear_resonance_speed`` [rpm] (the model's),
    for a planetary stage ``natural_speeds`` [rpm] (the input speeds at which the mesh
    frequency meets each natural frequency of the linear model).
    """
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
    param, values, torque_name = _sweep_axis(model, rpm)
    severity = {label: k for k, label in enumerate(CONTACT_LABELS)}
    rows, per_torque = [], []
    for t1 in loads:
        groups = _groups(model, torque=float(t1), application_factor=application_factor,
                         stiffness=stiffness, **accuracy)
        ds = bifurcation(model.with_params(**{torque_name: float(t1)}), param, values,
                         run or RunSettings(), **sweep)
        df_all, contact_all = ds["dynamic_factor"].values, ds["contact"].values.astype(str)
        cols: dict[str, list[np.ndarray]] = {k: [] for k in (
            "dynamic_factor", "contact", "K_v", "resonance_ratio", "iso_range")}
        scalars = []
        for g in groups.values():
            idx = list(g.meshes)
            cols["dynamic_factor"].append(np.max(df_all[:, idx], axis=1))
            codes = np.vectorize(severity.get)(contact_all[:, idx])
            cols["contact"].append(np.array(CONTACT_LABELS)[np.max(codes, axis=1)])
            kv, regime = dynamic_factor_iso(g.inputs, rpm * g.per_input)
            cols["K_v"].append(kv)
            cols["resonance_ratio"].append(resonance_ratio(g.inputs, rpm * g.per_input))
            cols["iso_range"].append(regime)
            scalars.append((resonance_speed(g.inputs) / g.per_input,
                            lower_resonance_limit(g.inputs.line_load), g.inputs.line_load,
                            g.inputs.single_stiffness, g.inputs.mesh_stiffness))
        rows.append(xr.Dataset(
            {k: (("speed", "group"), np.stack(v, axis=1)) for k, v in cols.items()}
            | {"period": ("speed", ds["period"].values, dict(ds["period"].attrs))}))
        per_torque.append(scalars)
    out = xr.concat(rows, dim="torque")
    table = np.array(per_torque)  # torque, group, quantity
    for j, name in enumerate(("resonance_speed", "lower_resonance_limit", "line_load",
                              "single_stiffness", "mesh_stiffness")):
        out[name] = (("torque", "group"), table[:, :, j])
    per_mesh_hz = (float(groups["mesh"].per_input) * model.mesh.pinion.teeth
                   if isinstance(model, SpurPair) else model.mesh_frequency_per_input_speed())
    out = out.assign_coords(
        group=("group", list(groups)),
        speed=("speed", rpm, {"units": "rpm", "long_name": "input speed"}),
        torque=("torque", loads, {"units": "N m", "long_name": "input torque"}),
        mesh_frequency=("speed", rpm * per_mesh_hz / 60.0,
                        {"units": "Hz", "long_name": "mesh frequency"}))
    _describe(out)
    out.attrs.update(model=repr(model), stiffness_source=stiffness, iso_ranges=", ".join(REGIMES),
                     standard="ISO 6336-1:2006 clause 6.5 (method B)",
                     application_factor=float(application_factor),
                     **{k: float(v) for k, v in accuracy.items()})
    if isinstance(model, SpurPair):
        out.attrs["linear_resonance_speed"] = linear_resonance_speed(model)
    else:
        f = np.asarray(model.natural_frequencies(), dtype=float)
        out.attrs["natural_speeds"] = np.unique(np.round(f[f > 0.0] * 60.0 / per_mesh_hz, 3))
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
