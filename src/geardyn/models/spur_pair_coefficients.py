"""The SI spur pair's coefficients, declared once (:mod:`geardyn.core.coefficients`): the header
of :class:`~geardyn.SpurPair`'s vector, then the drive and the coast flank's stiffness, as
Fourier series in the forcing phase (:func:`series_block`, one per flank, of the model's length)
or as tables over the forcing period (:func:`table_block`)."""

from __future__ import annotations

import math

from geardyn.core.coefficients import Coefficient, CoefficientBlock
from geardyn.core.inputs import REQUIRED as REQUIRED  # the default of a required input
from geardyn.core.inputs import PhysicalInput, rederived, unit_kind

_GEOMETRY = ("mesh_stiffness",)

#: The header: eight inputs, the cos and sin of the error phase (derived with their function, so
#: that no lane calls libm per step), then the structure (the same in every lane).
HEADER = CoefficientBlock((
    Coefficient("Omega", "rad/s", "rotation frequency of the gear whose revolution is the "
                "forcing period (the pinion's speed for a period of one pinion revolution)",
                minimum=0.0),
    Coefficient("mass", "kg", "equivalent mass of the pair on the line of action, "
                "I1 I2 / (I1 r_b2^2 + I2 r_b1^2)", exclusive_minimum=0.0),
    Coefficient("torque", "N m", "pinion torque (the mean mesh force is torque / r_b1)"),
    Coefficient("zeta", "1", "damping ratio, c = 2 zeta sqrt(k_mean mass)", minimum=0.0),
    Coefficient("backlash", "m", "backlash half-width b along the line of action", minimum=0.0),
    Coefficient("error", "m", "static transmission error amplitude at the mesh frequency",
                constant="ERROR"),
    Coefficient("error_phase", "rad", "phase of the static transmission error",
                constant="PHI_E"),
    Coefficient("k_mean", "N/m", "mean drive-flank mesh stiffness (sets the damping)",
                kind="derived", derived_from=_GEOMETRY, exclusive_minimum=0.0),
    Coefficient("cos_error_phase", "1", "cos of the error phase", kind="derived",
                derived_from=("error_phase",), derive=math.cos, constant="COS_E"),
    Coefficient("sin_error_phase", "1", "sin of the error phase", kind="derived",
                derived_from=("error_phase",), derive=math.sin, constant="SIN_E"),
    Coefficient("base_radius", "m", "pinion base radius r_b1", kind="structure",
                constant="R_B1"),
    Coefficient("mesh_order", "1", "mesh cycles per forcing period (the mesh frequency is "
                "mesh_order Omega)", kind="structure"),
    Coefficient("n_harmonics", "1", "harmonics H of each flank's stiffness series",
                kind="structure", constant="N_HARM"),
    Coefficient("stiffness_form", "1", "how the kernels evaluate each flank's stiffness: "
                "0 its Fourier series, 1 its table, linear between the angles",
                kind="structure"),
    Coefficient("table_points", "1", "angles per forcing period of each flank's table (the "
                "table form; 0 for the Fourier form)", kind="structure"),
))

#: ``stiffness_form`` values: the names of :class:`~geardyn.SpurPair`'s ``stiffness_form``.
STIFFNESS_FORMS = {"fourier": 0.0, "table": 1.0}


def series_block(flank: str, harmonics: int) -> CoefficientBlock:
    """One flank's stiffness k(theta) = k0 + sum_h a_h cos(h theta) + b_h sin(h theta), h = 1..H
    (theta the forcing phase: ``{flank}0``, ``{flank}_a1``, ``{flank}_b1``, ...), in N/m."""
    what = {"kd": "drive", "kc": "coast"}[flank]
    entries = [Coefficient(f"{flank}0", "N/m", f"mean {what}-flank mesh stiffness",
                           kind="derived", derived_from=_GEOMETRY)]
    for h in range(1, harmonics + 1):
        for ab, trig in (("a", "cos"), ("b", "sin")):
            entries.append(Coefficient(
                f"{flank}_{ab}{h}", "N/m", f"{trig} part of harmonic {h} of the {what}-flank "
                "mesh stiffness", kind="derived", derived_from=_GEOMETRY))
    return CoefficientBlock(tuple(entries))


def table_block(flank: str, points: int) -> CoefficientBlock:
    """One flank's stiffness at the ``points`` angles theta_j = 2 pi j / points of the forcing
    period (``{flank}_t0``, ``{flank}_t1``, ...), in N/m; the kernels interpolate linearly."""
    what = {"kd": "drive", "kc": "coast"}[flank]
    return CoefficientBlock(tuple(
        Coefficient(f"{flank}_t{j}", "N/m", f"{what}-flank mesh stiffness at angle {j} of the "
                    "table", kind="derived", derived_from=_GEOMETRY) for j in range(points)))


#: Units of the pinion speed a SpurPair reads plain numbers in (``speed_unit``): rad/s per unit,
#: exact (the factor the unit's numbers are multiplied by, once, to give rad/s).
SPEED_UNITS: dict[str, float] = {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0, "Hz": 2.0 * math.pi}
#: The forcing periods of :meth:`SpurPair.from_geometry`: one revolution of the pinion or of
#: the wheel, or one mesh cycle.
PERIODS = ("pinion", "wheel", "mesh")
#: The physical inputs of :class:`~geardyn.SpurPair` (and of ``from_geometry``) beyond the gears
#: (:class:`~geardyn.core.inputs.PhysicalInput`), declared once: its ``with_params`` reads unit
#: strings by their kinds, a sweep takes the swept ones (``speed`` re-derives Omega; the others
#: are the header's coefficients of their names), the explorer offers the ``explore`` ones, and
#: the ``[params]`` table of a ``spur_pair`` study is generated from them
#: (:func:`geardyn.io.toml.spur_pair_table`).
INPUTS: tuple[PhysicalInput, ...] = (
    PhysicalInput("speed", "frequency", "pinion speed: a number in speed_unit, or a unit "
                  "string (\"3000 rpm\")", minimum=0.0, swept=True),
    PhysicalInput("torque", "torque", "pinion torque [N m] (> 0 loads the drive flanks)",
                  coefficient=HEADER["torque"], swept=True, explore=True),
    PhysicalInput("inertia", "pair", "(I1, I2) of pinion and wheel [kg m^2]; default solid "
                  "steel discs of the reference radius, face width and bore", None,
                  unit_kind="inertia"),
    PhysicalInput("zeta", "dimensionless", HEADER["zeta"].meaning, 0.05,
                  coefficient=HEADER["zeta"], swept=True, explore=True),
    PhysicalInput("backlash", "length", "backlash half-width b along the line of action [m]; "
                  "default half the mesh's backlash on the line of action", None,
                  coefficient=HEADER["backlash"], swept=True, explore=True),
    PhysicalInput("error", "length", HEADER["error"].meaning + " [m]", 0.0,
                  coefficient=HEADER["error"], swept=True, explore=True),
    PhysicalInput("error_phase", "angle", HEADER["error_phase"].meaning + " [rad]", 0.0,
                  coefficient=HEADER["error_phase"], swept=True),
    PhysicalInput("harmonics", "count", "harmonics of Omega in each flank's stiffness series "
                  "(default 16 per mesh cycle of the period)", None, minimum=1, explore=True),
    PhysicalInput("stiffness_form", "choice", "how the kernels evaluate the stiffness: its "
                  "Fourier series (\"fourier\") or its table, linear between the angles "
                  "(\"table\")", "fourier", choices=("fourier", "table")),
    PhysicalInput("period", "choice", "forcing period: one pinion or wheel revolution or one "
                  "mesh cycle (default: that of the faulty gear, else the pinion)", None,
                  choices=PERIODS, of="from_geometry"),
    PhysicalInput("speed_unit", "choice", "unit of a plain number of speed, of a sweep of "
                  "speed and of its axis", "rad/s", choices=tuple(SPEED_UNITS)),
)
#: The inputs the coefficients are re-derived from (:func:`~geardyn.core.inputs.rederived`):
#: ``SpurPair.physical_names``.
PHYSICAL_NAMES: tuple[str, ...] = rederived(INPUTS)
#: The unit kind of each input coefficient of the header (Omega, mass and the inputs set
#: directly), by its declared unit: ``with_params`` reads unit strings of that kind.
UNIT_KINDS: dict[str, str] = {c.name: unit_kind(c.unit) for c in HEADER.entries
                              if c.kind == "input"}
#: The constructor's arguments that are no physical input: the structure the model is built on
#: (the gear mesh of ``[gears]`` and its stiffness table).
BUILT_ON = ("mesh", "stiffness")
