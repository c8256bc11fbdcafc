"""Gear trains described from elements: bodies, gears, shafts, bearings and meshes.

:class:`GearTrain` validates the description once (names, references, meshing geometry,
connectedness, rigid-body modes) and assembles the linear model at mean mesh stiffness: named
coordinates, M, K, C, natural frequencies, mode shapes with the strain-energy share of every
element, speed ratios, mesh orders and Campbell (interference) data; :class:`TrainModel`
is its nonlinear model (backlash, time-varying mesh stiffness,
transmission error, torques) on the planetary gear set's compiled kernels; tooth faults on a gear
of the train (:mod:`geardyn.trains.faults`) act in its potential-energy mesh stiffness over that
gear's revolution. Physics only: no files, no plots. See docs/trains.md.
"""

from geardyn.models.modal import MULTIPLICITY_RTOL
from geardyn.trains.elements import GROUND, STIFFNESS_METHODS, Bearing, Gear, Inertia, Mesh, Shaft
from geardyn.trains.faults import TrainFaults
from geardyn.trains.model import TrainModel
from geardyn.trains.stages import PlanetaryStage, planetary_stage
from geardyn.trains.train import (
    MODE_TYPE_TOL,
    RIGID_BODY_RTOL,
    GearTrain,
    MeshData,
    resolve_mesh,
)

__all__ = [
    "GROUND",
    "MODE_TYPE_TOL",
    "MULTIPLICITY_RTOL",
    "RIGID_BODY_RTOL",
    "STIFFNESS_METHODS",
    "Bearing",
    "Gear",
    "GearTrain",
    "Inertia",
    "Mesh",
    "MeshData",
    "PlanetaryStage",
    "Shaft",
    "TrainFaults",
    "TrainModel",
    "planetary_stage",
    "resolve_mesh",
]
