"""Gear geometry, ISO 6336-1 and potential-energy mesh stiffness (spur, and helical by thin
slices), the ISO 6336-1 dynamic factor K_v (method B), tip relief and lead crowning, stiffness
waveforms and planetary mesh phasing.

Pure numpy: everything here produces plain numbers, arrays and callables that a model's mesh
takes (mean stiffness, Fourier coefficients, phases); the potential-energy stiffness comes as a
labelled xarray Dataset. See docs/gears.md.
"""

from geardyn.gears.crowning import LeadCrowning, crowning_gap, helical_loaded_contact
from geardyn.gears.faults import FAULT_KINDS, BrokenTooth, Spall, Wear
from geardyn.gears.geometry import GearMesh, SpurGear, inverse_involute, involute
from geardyn.gears.helical import HelicalGear, HelicalMesh, helical_stiffness
from geardyn.gears.iso6336 import ISOStiffness, iso6336_stiffness
from geardyn.gears.iso6336_kv import (
    DynamicFactorInputs,
    KvMeshGroup,
    dynamic_factor_iso,
    group_inputs,
    group_reduced_mass,
    planetary_reduced_masses,
    reduced_mass,
    resonance_speed,
)
from geardyn.gears.phasing import (
    MeshPhases,
    PlanetaryGeometry,
    equally_spaced,
    mesh_phases,
    sun_ring_phase,
    surviving_harmonics,
)
from geardyn.gears.potential_energy import (
    PotentialEnergyPair,
    RootCrack,
    ToothModel,
    coast_phase,
    hertz_stiffness,
    potential_energy_stiffness,
    prepare_pair,
    ring_tooth_model,
    tooth_compliances,
    tooth_model,
)
from geardyn.gears.tip_relief import TipRelief, loaded_contact, relief_gap
from geardyn.gears.waveform import StiffnessWaveform, double_contact_centre, mesh_stiffness_waveform

__all__ = [
    "FAULT_KINDS",
    "BrokenTooth",
    "DynamicFactorInputs",
    "KvMeshGroup",
    "GearMesh",
    "HelicalGear",
    "HelicalMesh",
    "ISOStiffness",
    "LeadCrowning",
    "MeshPhases",
    "PlanetaryGeometry",
    "PotentialEnergyPair",
    "RootCrack",
    "Spall",
    "SpurGear",
    "StiffnessWaveform",
    "TipRelief",
    "ToothModel",
    "Wear",
    "coast_phase",
    "crowning_gap",
    "double_contact_centre",
    "dynamic_factor_iso",
    "group_inputs",
    "group_reduced_mass",
    "equally_spaced",
    "helical_loaded_contact",
    "helical_stiffness",
    "hertz_stiffness",
    "involute",
    "inverse_involute",
    "iso6336_stiffness",
    "loaded_contact",
    "mesh_phases",
    "mesh_stiffness_waveform",
    "planetary_reduced_masses",
    "potential_energy_stiffness",
    "prepare_pair",
    "reduced_mass",
    "relief_gap",
    "resonance_speed",
    "ring_tooth_model",
    "sun_ring_phase",
    "surviving_harmonics",
    "tooth_compliances",
    "tooth_model",
]
