"""The gear pair's coefficients, declared once (:mod:`geardyn.core.coefficients`): the vector
layout of :class:`~geardyn.GearPair` (in ``param_names`` order), with units, meanings, defaults
and admissible ranges; the ``gear_pair`` study table (:class:`geardyn.io.toml.GearPairParams`)
is generated from its inputs."""

from __future__ import annotations

import math

from geardyn.core.coefficients import Coefficient, CoefficientBlock

#: The gear pair's coefficient vector: eight inputs, then the cos and sin of the two phases
#: (derived, each with its function: the layout fills them from the phases wherever a phase is
#: set, so that no lane calls libm per step); the explorer offers the ``explore`` ones as
#: controls; dimensionless (time in units of
#: 1 / the natural frequency in contact, x in units of the backlash scale).
GEAR_PAIR = CoefficientBlock((
    Coefficient("Omega", "1", "mesh frequency", default=1.0, minimum=0.0),
    Coefficient("zeta", "1", "damping ratio", default=0.05, minimum=0.0, explore=True),
    Coefficient("kappa", "1", "relative stiffness variation", default=0.0,
                exclusive_minimum=-1.0, exclusive_maximum=1.0, explore=True),
    Coefficient("Fm", "1", "mean load", default=0.1, constant="FM"),
    Coefficient("Fa", "1", "transmission-error amplitude", default=0.05, constant="FA",
                explore=True),
    Coefficient("kappa_phase", "rad", "phase of the stiffness variation", default=0.0,
                constant="PHI_K"),
    Coefficient("error_phase", "rad", "phase of the transmission error", default=0.0,
                constant="PHI_E"),
    Coefficient("backlash", "1", "backlash half-width", default=1.0, minimum=0.0,
                explore=True),
    Coefficient("cos_kappa_phase", "1", "cos of the stiffness phase", kind="derived",
                derived_from=("kappa_phase",), derive=math.cos, constant="COS_K"),
    Coefficient("sin_kappa_phase", "1", "sin of the stiffness phase", kind="derived",
                derived_from=("kappa_phase",), derive=math.sin, constant="SIN_K"),
    Coefficient("cos_error_phase", "1", "cos of the error phase", kind="derived",
                derived_from=("error_phase",), derive=math.cos, constant="COS_E"),
    Coefficient("sin_error_phase", "1", "sin of the error phase", kind="derived",
                derived_from=("error_phase",), derive=math.sin, constant="SIN_E"),
))
#: The study file's fields: the inputs.
INPUTS = tuple(c.name for c in GEAR_PAIR.entries if c.kind == "input")
