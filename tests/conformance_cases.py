"""The built-in models (and one user model) that the conformance and code-generation tests run:
each case is a model and a start state that makes a short run cross dead-zone edges where the
model has them."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numba
import numpy as np

import geardyn

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
from gear_pair_model import gear_pair  # noqa: E402 - the gear pair as a one-form user model

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}
#: The user model's coefficients: backlash half-width, damping ratio, force amplitude,
#: stiffness, forcing frequency.
USER_PARAMS = ("b", "zeta", "F", "k", "Omega")


@numba.njit(**_JIT)
def dead_zone_rhs(t, y, dy, p):
    """A forced oscillator with a dead zone, in the plain user interface."""
    x = y[0]
    b = p[0]
    g = x - b if x > b else (x + b if x < -b else 0.0)
    dy[0] = y[1]
    dy[1] = -2.0 * p[1] * y[1] - p[3] * g + p[2] * math.cos(p[4] * t)


@numba.njit(**_JIT)
def dead_zone_events(t, y, g, p):
    g[0] = y[0] - p[0]
    g[1] = y[0] + p[0]


@numba.njit(**_JIT)
def dead_zone_observe(t, y, out, p):
    x = y[0]
    b = p[0]
    out[0] = p[3] * (x - b if x > b else (x + b if x < -b else 0.0))


def user_model(k: float = 1.0, natural_frequency: bool = True, **kw) -> geardyn.UserModel:
    """The dead-zone oscillator as a :class:`geardyn.UserModel` (stiffness k)."""
    args = dict(n_states=2, params=[0.5, 0.05, 0.6, k, 1.2], param_names=USER_PARAMS,
                state_names=("x", "v"), events=dead_zone_events, n_events=2,
                observe=dead_zone_observe, observable_names=("F",), name="dead-zone oscillator",
                natural_frequency=(lambda p: math.sqrt(p[3])) if natural_frequency else None)
    args.update(kw)
    return geardyn.UserModel(dead_zone_rhs, **args)


def _catt(**params) -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(error="10 um", **params)
                              ).with_omega(1.1)


def _kicked(m: geardyn.Model, kick: list[float]) -> np.ndarray:
    return m.initial_state() + np.resize(np.asarray(kick), m.n_states)


def planetary() -> geardyn.PlanetaryGearSet:
    """A small planetary gear set (N = 3, unequally spaced planets, so that no coupling
    cancels to rounding residue) with backlash, stiffness fluctuation and transmission error,
    balanced torques."""
    M = geardyn.Member
    a = 24.6 * math.pi / 180
    return geardyn.PlanetaryGearSet(
        n_planets=3, sun_pressure_angle=a, ring_pressure_angle=a,
        sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
        carrier=M(5.43, 6.29, 1e8, 0.0, radius=0.08), planet=M(0.66, 0.61, 1e8),
        sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8,
        planet_angles=["0 deg", "110 deg", "235 deg"], sun_torque=100.0,
        carrier_torque=-2 * math.cos(a) * 100 / 0.03 * 0.08, sun_backlash=10e-6,
        ring_backlash=10e-6, sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
        sun_mesh_error=5e-6, ring_mesh_error=5e-6, mesh_frequency=2 * math.pi * 1500)


def spur_pair() -> geardyn.SpurPair:
    """The 19/48 spur pair with a cracked pinion tooth on its potential-energy stiffness (SI),
    a short series (H = 2 z1) and a 10 um backlash half-width."""
    from geardyn.gears import GearMesh, RootCrack, SpurGear, potential_energy_stiffness
    mesh = GearMesh(SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                    SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    table = potential_energy_stiffness(mesh, bore_radius=(0.012, 0.035), angles=32, cycles=19,
                                       faults=RootCrack("1.5 mm"))
    return geardyn.SpurPair(mesh, table, speed="1000 rpm", torque="50 N m",
                            inertia=(4.3659e-4, 8.3602e-3), backlash="10 um", error="1 um",
                            harmonics=38)


def train() -> geardyn.Model:
    """A spur pair as a gear train (:class:`geardyn.trains.TrainModel`): the pinion on a
    flexible bearing with a 15 um clearance (two contacts besides the mesh), the wheel on a
    rigid one, 10 um backlash, a 30 % stiffness fluctuation; the wheel's torque balances the
    pinion's (a free rigid-body rotation)."""
    from geardyn.trains import Bearing, Gear, GearTrain, Mesh, TrainModel

    rb = [0.5 * 3e-3 * z * math.cos(math.radians(20.0)) for z in (19, 48)]
    gears = [Gear("p", 2e-4, base_radius=rb[0], n_teeth=19, mass=0.6),
             Gear("w", 6e-3, base_radius=rb[1], n_teeth=48)]
    t = GearTrain(gears, bearings=[Bearing("bp", "p", 1e8, clearance="15 um", damping=100.0),
                                   Bearing("bw", "w", math.inf)],
                  meshes=[Mesh("mesh", "p", "w", 3e8, damping=100.0)], driven="p", free=True)
    return TrainModel(t, torques={"p": 2.0}, load="w", backlash="10 um",
                      stiffness_fluctuation=0.3, input_speed=5500.0)


def cases() -> dict[str, tuple[geardyn.Model, np.ndarray]]:
    """Case id -> (model, start state)."""
    reduced = _catt()
    general = reduced.general()
    dim = reduced.dimensional()
    pair = geardyn.GearPair(Omega=1.3, kappa=0.2, Fa=0.2)
    user = user_model()
    gs = planetary()
    tm = train()
    kick = np.random.default_rng(1).normal(0.0, 1.0, gs.n_states) * np.r_[[3.0] * 18, [1.0] * 18]
    return {
        "CATTDevice-reduced": (reduced, _kicked(reduced, [0.3, 0.1, -0.2, 0.05])),
        "CATTDevice-general": (general, _kicked(general, [0.3, 0.1, -0.2, 0.05])),
        "DimensionalCATT": (dim, dim.initial_state()),
        "GearPair": (pair, np.zeros(2)),
        "UserModel": (user, np.array([1.0, 0.0])),
        "UserModel-one-form": (gear_pair(Omega=1.3, kappa=0.2, Fa=0.2), np.zeros(2)),
        "PlanetaryGearSet": (gs, gs.initial_state() + kick),
        "SpurPair": (spur_pair(), np.array([-3e-5, 0.0])),  # coast contact: crosses the zone
        "TrainModel": (tm, tm.initial_state() + np.r_[0.0, 20.0, -20.0, 0.0, 0.0, 0.0, 0.0,
                                                      0.0]),
    }


IDS = ("CATTDevice-reduced", "CATTDevice-general", "DimensionalCATT", "GearPair", "UserModel",
       "UserModel-one-form", "PlanetaryGearSet", "SpurPair", "TrainModel")
