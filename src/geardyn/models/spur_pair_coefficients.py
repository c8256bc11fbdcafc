"""The SI spur pair's coefficients, declared once (:mod:`geardyn.core.coefficients`): the header
of :class:`~geardyn.SpurPair`'s vector, then the drive and the coast flank's stiffness as Fourier
series in the forcing phase (:func:`series_block`, one per flank, of the model's length)."""

from __future__ import annotations

import math

from geardyn.core.coefficients import Coefficient, CoefficientBlock

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
))


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
