"""The physical inputs of :class:`~geardyn.trains.TrainModel`, declared once
(:mod:`geardyn.core.inputs`): the model runs on the planetary gear set's coefficients
(:mod:`geardyn.models.planetary_coefficients`); these are what a user gives beside the train,
the keywords of its constructor, from which the ``[params]`` table of a ``train`` study is
generated (:data:`geardyn.io.toml.TrainModelParams`)."""

from __future__ import annotations

from dataclasses import replace

from geardyn.core.inputs import PhysicalInput
from geardyn.models.planetary_coefficients import HARMONICS, WAVEFORMS
from geardyn.models.planetary_stiffness import COAST_FLANKS

#: The inputs (SI numbers or unit strings; "per mesh": one value for every mesh or
#: ``{mesh = value}``). The train itself is the study's ``[train]`` table.
INPUTS: tuple[PhysicalInput, ...] = (
    PhysicalInput("reference_mesh", "name", "the mesh whose mesh frequency is the forcing "
                  "Omega (default: the first mesh of the driven body, else the train's first "
                  "mesh)", None),
    PhysicalInput("input_speed", "frequency", "driven body's speed (rpm, or a unit string)",
                  None, unit="rpm", swept=True),
    PhysicalInput("mesh_frequency", "frequency", "the reference mesh's frequency [rad/s] "
                  "(instead of input_speed; default omega_0: Omega = 1)", None, swept=True),
    PhysicalInput("torques", "torque", "mean torques [N m] on bodies by name (each acts on "
                  "the body's rotation)", None, form="by_name"),
    PhysicalInput("load", "name", "a body whose torque balances the others on the train's "
                  "rigid-body mode (the output load for a given input torque)", None),
    PhysicalInput("backlash", "length", "backlash half-width b [m] of every mesh, or per "
                  "mesh", 0.0, form="per_mesh", swept=True, explore=True),
    PhysicalInput("mesh_damping", "dimensionless", "damping ratio zeta_m of every mesh, or "
                  "per mesh (added to the mesh element's own damping)", 0.0, form="per_mesh",
                  swept=True, explore=True),
    PhysicalInput("modal_damping", "number", "modal damping ratio of every mode of the linear "
                  "model at mean stiffness", 0.0, swept=True, explore=True),
    PhysicalInput("stiffness_fluctuation", "dimensionless", "relative amplitude of the "
                  "stiffness fluctuation of every mesh, or per mesh", 0.0, form="per_mesh",
                  swept=True, explore=True),
    PhysicalInput("waveform", "choice", "shape of the stiffness fluctuation: \"sine\" or "
                  "\"rectangular\" (contact_ratio, harmonics)", "sine", choices=WAVEFORMS),
    PhysicalInput("contact_ratio", "number", "contact ratio of the rectangular waveform", 1.6,
                  swept=True),
    replace(HARMONICS, meaning="harmonics of the stiffness series"),
    PhysicalInput("mesh_phase", "angle", "rad of the mesh cycle, per mesh or \"geometry\"; "
                  "default: from the geometry where every meshing gear has it, else 0", None,
                  form="per_mesh", swept=True),
    PhysicalInput("mesh_error", "length", "transmission error amplitude E_m [m] of every "
                  "mesh, or per mesh", 0.0, form="per_mesh", swept=True, explore=True),
    PhysicalInput("error_phase", "angle", "transmission error phase [rad] of every mesh, or "
                  "per mesh", 0.0, form="per_mesh", swept=True),
    PhysicalInput("torque_fluctuation", "number", "relative amplitude A of the driven body's "
                  "torque fluctuation T (1 + A sin(order Omega tau + phase))", 0.0, swept=True,
                  explore=True),
    PhysicalInput("torque_order", "number", "order of the driven body's torque fluctuation",
                  1.0, swept=True),
    PhysicalInput("torque_phase", "angle", "phase of the driven body's torque fluctuation "
                  "[rad]", 0.0, swept=True),
    PhysicalInput("coast", "choice", "the coast flank of a mesh whose gears have geometry: "
                  "\"mirror\" (the drive flank's mirror image) or \"symmetric\" (the drive "
                  "flank's stiffness)", "mirror", choices=COAST_FLANKS),
    PhysicalInput("time_scale", "frequency", "time scale omega_0 [rad/s] (default "
                  "sqrt(k_ref / m_e,ref) of the reference mesh)", None),
    PhysicalInput("length_scale", "length", "length scale L [m] of the dimensionless "
                  "displacements", 1e-6),
)
#: The constructor's arguments that are no physical input: the structure the model is built
#: on (the study's ``[train]`` table).
BUILT_ON = ("train",)
