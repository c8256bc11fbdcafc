"""Building blocks: a planetary stage's planets, pins and meshes from its members."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from geardyn.errors import ParameterError
from geardyn.models.planetary_coefficients import N_PLANETS
from geardyn.trains.elements import Bearing, Gear, Inertia, Mesh, Shaft
from geardyn.trains.train import resolve_mesh
from geardyn.units import si_value


@dataclass(frozen=True)
class PlanetaryStage:
    """The elements of one planetary stage: ``bodies`` (sun, ring, carrier, planets, then a
    compound stage's ring-side planet gears), ``bearings`` (the planets' pins on the carrier,
    then the ring-side gears' rigid hubs on their planets), ``meshes`` (sun-planet, then
    planet-ring) and ``shafts`` (a compound stage's rigid joints of each planet's two gears).
    ``planets`` names the planets, ``compound`` the ring-side gears. The central members' own
    bearings and shafts are the train's to add."""

    bodies: tuple[Inertia, ...]
    bearings: tuple[Bearing, ...]
    meshes: tuple[Mesh, ...]
    planets: tuple[str, ...]
    carrier_radius: float
    shafts: tuple[Shaft, ...] = ()
    compound: tuple[str, ...] = ()


def planetary_stage(*, sun: Gear, ring: Gear, carrier: Inertia, planet: Gear, n_planets: int,
                    pin_stiffness: Any, sun_mesh_stiffness: Any, ring_mesh_stiffness: Any,
                    planet_angles: Sequence[Any] | None = None, carrier_radius: Any = None,
                    sun_pressure_angle: Any = None, ring_pressure_angle: Any = None,
                    pin_damping: Any = 0.0, mesh_damping: Any = 0.0,
                    ring_planet: Gear | None = None, sun_bore_radius: Any = None,
                    planet_bore_radius: Any = None, ring_rim_radius: Any = None,
                    ring_planet_bore_radius: Any = None,
                    centre_distance: Any = None) -> PlanetaryStage:
    """A single planetary stage as elements (Lin & Parker 1999): ``n_planets`` copies of
    ``planet`` named ``<planet.name>1`` ..., each on a pin of ``pin_stiffness`` [N/m]
    (``math.inf``: rigid) on ``carrier`` at ``carrier_radius`` [m] and angle psi_n [rad]
    (default equally spaced, 2 pi (n - 1) / N), meshing with ``sun`` (external) and ``ring``
    (internal). Mesh stiffnesses are numbers [N/m] or a method (``"iso"``, ...) as
    :class:`Mesh`; pressure angles None take the geometries' operating ones (else 20 deg).
    ``carrier_radius`` None: ``centre_distance`` where given, else (r_b,sun + r_b,planet) /
    cos(alpha_sun), the centre distance of the sun-planet mesh.

    ``centre_distance`` [m]: the centre distance of every mesh (each planet's two meshes about
    its pin, as :class:`~geardyn.gears.PlanetaryGeometry`'s ``centre_distance``; a widened stage
    of shifted gears, its meshes with backlash and their contact ratios at that distance); a
    ``carrier_radius`` given with it must equal it. None: each mesh at its own gears'
    zero-backlash distance (:class:`Mesh`), whatever the carrier radius.

    ``ring_planet``: a compound stage (Kiracofe & Parker 2007). Each planet then carries a
    copy of this second gear (``<ring_planet.name>1`` ...), joined to it rigidly (a rigid hub
    ``<name>_hub`` at the planet's centre and a rigid shaft ``<name>_joint``): the planet
    meshes the sun, the second gear the ring.

    Bore radii [m], for a mesh stiffness ``"potential_energy"`` (needed by the meshes that take
    it): ``sun_bore_radius``, ``planet_bore_radius``, ``ring_rim_radius`` (the ring's outer
    radius) and, in a compound stage, ``ring_planet_bore_radius``; the sun-planet meshes take
    (sun's, planet's), the planet-ring meshes (planet's or ring planet's, ring's) as their
    ``bore_radius`` pair."""
    n_planets = N_PLANETS.count(n_planets)
    if planet_angles is None:
        psi = [2.0 * math.pi * i / n_planets for i in range(n_planets)]
    else:
        psi = [si_value(f"planet_angles[{i}]", a, "angle") for i, a in enumerate(planet_angles)]
        if len(psi) != n_planets:
            raise ParameterError("planet_angles", planet_angles, f"needs {n_planets} angles")
    if ring_planet is not None and not isinstance(ring_planet, Gear):
        raise ParameterError("ring_planet", ring_planet, "must be a Gear")
    if ring_planet is None and ring_planet_bore_radius is not None:
        raise ParameterError("ring_planet_bore_radius", ring_planet_bore_radius,
                             "only a compound stage (ring_planet) has a ring planet")
    sun_bores = _bores(sun_mesh_stiffness, (("sun_bore_radius", sun_bore_radius),
                                            ("planet_bore_radius", planet_bore_radius)))
    ring_side = (("ring_planet_bore_radius", ring_planet_bore_radius) if ring_planet
                 else ("planet_bore_radius", planet_bore_radius))
    ring_bores = _bores(ring_mesh_stiffness, (ring_side, ("ring_rim_radius", ring_rim_radius)))
    a_w = None if centre_distance is None else si_value("centre_distance", centre_distance,
                                                        "length", 0.0, strict=True)
    first = Mesh("sun_mesh", sun.name, planet.name, sun_mesh_stiffness,
                 pressure_angle=sun_pressure_angle, bore_radius=sun_bores, centre_distance=a_w)
    alpha_s = resolve_mesh(first, sun, planet).pressure_angle
    if carrier_radius is None:
        rc = (sun.base_radius + planet.base_radius) / math.cos(alpha_s) if a_w is None else a_w
    else:
        rc = si_value("carrier_radius", carrier_radius, "length", 0.0, strict=True)
        if a_w is not None and not math.isclose(rc, a_w, rel_tol=1e-9):
            raise ParameterError("carrier_radius", carrier_radius, f"differs from the stage's "
                                 f"centre_distance {a_w:.6g} m: the planets' pins sit at the "
                                 "meshes' centre distance (give one of them)")
    planets, bearings, sun_meshes, ring_meshes = [], [], [], []
    seconds, hubs, joints = [], [], []
    for i, angle in enumerate(psi):
        p = replace(planet, name=f"{planet.name}{i + 1}")
        planets.append(p)
        bearings.append(Bearing(f"{p.name}_pin", p.name, pin_stiffness, host=carrier.name,
                                damping=pin_damping, radius=rc, angle=angle))
        sun_meshes.append(Mesh(f"{sun.name}_{p.name}", sun.name, p.name, sun_mesh_stiffness,
                               angle=angle, pressure_angle=sun_pressure_angle,
                               centre_distance=a_w, damping=mesh_damping,
                               bore_radius=sun_bores))
        q = p
        if ring_planet is not None:
            q = replace(ring_planet, name=f"{ring_planet.name}{i + 1}")
            seconds.append(q)
            hubs.append(Bearing(f"{q.name}_hub", q.name, math.inf, host=p.name))
            joints.append(Shaft(f"{q.name}_joint", q.name, p.name, math.inf))
        ring_meshes.append(Mesh(f"{q.name}_{ring.name}", q.name, ring.name, ring_mesh_stiffness,
                                internal=True, angle=angle + math.pi,
                                pressure_angle=ring_pressure_angle, centre_distance=a_w,
                                damping=mesh_damping, bore_radius=ring_bores))
    return PlanetaryStage(bodies=(sun, ring, carrier, *planets, *seconds),
                          bearings=(*bearings, *hubs), meshes=(*sun_meshes, *ring_meshes),
                          planets=tuple(p.name for p in planets), carrier_radius=rc,
                          shafts=tuple(joints), compound=tuple(q.name for q in seconds))


def _bores(stiffness: Any, radii: tuple[tuple[str, Any], tuple[str, Any]]
           ) -> tuple[float, float] | None:
    """A stage mesh's ``bore_radius`` pair from its two gears' radii ``(name, value)``, each
    checked as a length [m] naming its parameter. The potential-energy stiffness needs both;
    another stiffness takes them only when both are given (else None: it does not use them)."""
    if stiffness != "potential_energy" and any(v is None for _, v in radii):
        return None
    out = []
    for name, value in radii:
        if value is None:
            raise ParameterError(name, None, "needed by the potential-energy stiffness of the "
                                 "stage's meshes that gear takes part in")
        out.append(si_value(name, value, "length", 0.0, strict=True))
    return out[0], out[1]
