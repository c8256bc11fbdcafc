"""The shipped planetary stage (the study ``planetary_example``: 25/23/71, four planets) built
from its study document's literal values through the API, not through the study loader: the
reference the study and explorer tests compare with."""

from __future__ import annotations

from typing import Any

import geardyn
from geardyn.gears import PlanetaryGeometry, SpurGear

#: The example's dynamics inputs besides the members (its ``[params]`` keys).
DYNAMICS = ("sun_backlash", "ring_backlash", "mesh_damping", "modal_damping", "sun_torque",
            "harmonics")


def planetary_by_hand(doc: dict[str, Any], **kw: Any) -> geardyn.PlanetaryGearSet:
    """PlanetaryGearSet.from_geometry of the stage, members and dynamics of ``doc`` (the
    example's TOML tables, possibly changed); ``kw``: from_geometry's stiffness inputs
    (``stiffness``, ``stiffness_options``, ``coast``, ``faults``), which win over ``doc``."""
    p, g = doc["params"], doc["params"]["geometry"]
    gears = {n: SpurGear(g[n]["teeth"], g["module"], g["pressure_angle"], g["face_width"],
                         internal=n == "ring", name=f"geometry.{n}")
             for n in ("sun", "planet", "ring")}
    stage = PlanetaryGeometry(gears["sun"], gears["planet"], gears["ring"],
                              n_planets=p["n_planets"])
    members = {n: geardyn.Member(**p[n]) for n in ("sun", "ring", "carrier", "planet")}
    return geardyn.PlanetaryGearSet.from_geometry(
        stage, **members, **{k: p[k] for k in DYNAMICS}, **kw)
