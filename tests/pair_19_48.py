"""The 19/48 spur pair of the potential-energy and cracked-tooth literature (m 3.2 mm, 20 deg,
b 16 mm, steel E 206.8 GPa, nu 0.3; bores 12 and 35 mm), shared by the stiffness tests."""

from __future__ import annotations

import math

from geardyn.gears import GearMesh, SpurGear

E, NU, B = 2.068e11, 0.3, 0.016
M, Z1, Z2, ALPHA = 3.2e-3, 19, 48, math.radians(20.0)
BORES = (0.012, 0.035)


def pair_mesh() -> GearMesh:
    """The pair, at the centre distance of zero backlash."""
    return GearMesh(SpurGear(Z1, M, ALPHA, B, name="pinion"),
                    SpurGear(Z2, M, ALPHA, B, name="wheel"))
