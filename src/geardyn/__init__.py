"""geardyn: nonlinear dynamics of gear trains.

The public API::

    import geardyn
    p = geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)
    m = geardyn.CATTDevice(p, interpretation="consistent")
    ds = geardyn.simulate(m, omega=1.1, run=geardyn.RunSettings(transient=4000.0, samples=64))
"""

# _cache (with _jit_target) before anything else: the cache locator of geardyn's numba functions,
# keyed by their vector width (their docstrings say why)
from geardyn import _cache, _jit_target, gears, testing  # noqa: F401
from geardyn._version import __version__ as __version__
from geardyn.analysis.basins import basins
from geardyn.analysis.bifurcation import ContinuedSweep, bifurcation, continued_sweeps
from geardyn.analysis.branch import BifurcationPoint, BranchStatus, continuation
from geardyn.analysis.curves import CurveSettings, curve, curve_at
from geardyn.analysis.dynamic_factor import dynamic_factor_sweep
from geardyn.analysis.envelope import Envelope, envelope, intersect_curves
from geardyn.analysis.fault_dataset import FaultDatasetSpec, fault_dataset
from geardyn.analysis.frc import frequency_response
from geardyn.analysis.grazing import grazing_curve
from geardyn.analysis.lyapunov import LyapunovEstimate, lyapunov, lyapunov_lanes
from geardyn.analysis.map2d import map2d
from geardyn.analysis.motion import motion_classes
from geardyn.analysis.orbits import PeriodicOrbit, periodic_orbit
from geardyn.analysis.orders import order_spectrum, waterfall
from geardyn.analysis.periodicity import classify_period
from geardyn.analysis.runup import RunupSettings, runup
from geardyn.analysis.sensor import planetary_sensor_signal, sensor_signal, sensor_spectrum
from geardyn.analysis.spectrum import amplitude_spectrum, label_peaks
from geardyn.core.model import Model
from geardyn.core.plan import default_steps_per_period
from geardyn.core.section import common_section
from geardyn.core.settings import (
    ContinuationSettings,
    LyapunovSettings,
    NewtonSettings,
    RunSettings,
)
from geardyn.core.status import Status
from geardyn.errors import GeardynError, ParameterError, StudyError
from geardyn.models.catt import CATTDevice, DimensionalCATT
from geardyn.models.derived import INTERPRETATIONS
from geardyn.models.gear_pair import GearPair
from geardyn.models.params import Carrier, Gear, Loads, Mesh, PlanetaryParams, PlanetOverride
from geardyn.models.planetary import Member, PlanetaryGearSet
from geardyn.models.spur_pair import SpurPair
from geardyn.models.user import DynamicFactorDeclaration, UserModel
from geardyn.solvers.reference import reference_solution
from geardyn.solvers.simulate import simulate
from geardyn.study import build_model

__all__ = [
    "INTERPRETATIONS",
    "BifurcationPoint",
    "BranchStatus",
    "CATTDevice",
    "Carrier",
    "ContinuationSettings",
    "ContinuedSweep",
    "CurveSettings",
    "DimensionalCATT",
    "DynamicFactorDeclaration",
    "Envelope",
    "GearPair",
    "GeardynError",
    "Gear",
    "Loads",
    "LyapunovEstimate",
    "LyapunovSettings",
    "Member",
    "Mesh",
    "Model",
    "NewtonSettings",
    "ParameterError",
    "PeriodicOrbit",
    "PlanetOverride",
    "PlanetaryGearSet",
    "PlanetaryParams",
    "RunSettings",
    "RunupSettings",
    "SpurPair",
    "Status",
    "StudyError",
    "UserModel",
    "amplitude_spectrum",
    "basins",
    "bifurcation",
    "build_model",
    "classify_period",
    "common_section",
    "continuation",
    "continued_sweeps",
    "curve",
    "curve_at",
    "dynamic_factor_sweep",
    "frequency_response",
    "gears",
    "label_peaks",
    "lyapunov",
    "lyapunov_lanes",
    "map2d",
    "motion_classes",
    "order_spectrum",
    "periodic_orbit",
    "planetary_sensor_signal",
    "default_steps_per_period",
    "envelope",
    "grazing_curve",
    "intersect_curves",
    "reference_solution",
    "sensor_signal",
    "FaultDatasetSpec",
    "fault_dataset",
    "sensor_spectrum",
    "runup",
    "simulate",
    "testing",
    "waterfall",
]
