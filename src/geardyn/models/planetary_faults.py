"""Tooth faults of a planetary gear set built from its geometry
(:meth:`geardyn.PlanetaryGearSet.from_geometry` with ``faults``): where a faulty tooth meets
which mesh, and when.

A fault (:mod:`geardyn.gears.faults`) sits on tooth ``tooth`` of ``gear``: ``"sun"``,
``"ring"`` or ``"planet<n>"`` (n = 1 .. N, the planet at the n-th planet angle psi_n). All the
faults of a set lie on one gear, whose revolution relative to the carrier, Z_f mesh cycles
(Z_f its teeth), is then the forcing period: every mesh's stiffness is a Fourier series in that
revolution's angle Theta = 2 pi c / Z_f (c: mesh cycles since the start), mesh harmonic l at
harmonic l Z_f, its sidebands between.

Tooth numbers (the carrier frame; s = +1 when the sun turns in the sense of psi relative to the
carrier, -1 when against it; rel_n = psi_n - psi_1; gamma: the Parker & Lin phases of
:func:`geardyn.gears.mesh_phases`):

* sun tooth j passes the pitch point of the sun-planet mesh of planet 1 at c = j, of planet n
  at c = j + s Z_s rel_n / (2 pi) (mod Z_s);
* ring tooth j passes the pitch point of the ring-planet mesh of planet 1 at c = gamma_T + j,
  of planet n at c = gamma_T + j - s Z_r rel_n / (2 pi) (mod Z_r), a ring tooth numbered by
  its clockwise-facing flank (the flank the planet-ring table calls drive; the drive flank of
  a gear train's ring mesh, :mod:`geardyn.trains.faults`), ring tooth 0 the first to pass in
  [0, 1): gamma_T = (-s (Z_p / 2 - Z_p (psi_r - psi_s) / (4 pi))) mod 1 (a planet tooth's
  counter-clockwise-facing flank carried from the sun-side pitch point to the ring side); the
  ring mesh's table (its tooth j at the pitch point at c = delta + j) then lies delta = gamma_rs
  + round(gamma_T + s (1 - phi_r) - gamma_rs) (:func:`ring_origin`; gamma_rs of the turning
  sun, phi_r the ring mesh's coast phase);
* tooth j of planet n passes the sun-side pitch point at c = gamma_sn + j and the ring-side one
  s D mesh cycles later (mod Z_p), D = Z_p / 2 - Z_p (psi_s + psi_r) / (4 pi) (half a planet
  turn less half the tooth's angular thicknesses psi_s, psi_r at its two operating pitch radii:
  the sun loads the tooth's trailing flank, the tooth the ring with its leading one; D mod 1 is
  gamma_rs; with s = -1 the planet turns the other way, Z_p - D, half a turn and the two half
  thicknesses).

With s = -1 every mesh reads its tables backwards in time
(:func:`~geardyn.models.planetary_stiffness.table_in_time`): the tooth passing a pitch point at
the times above is the table's tooth -j (mod the gear's teeth).

Reduced mod 1 these (the ring's: its table's delta) are the Parker & Lin phases, so a healthy
set built over the revolution is the one-mesh-cycle set.

Which meshes a faulty tooth takes part in: a sun tooth meets every sun-planet mesh, a ring tooth
every ring-planet mesh (each once per revolution, at the times above), a tooth of planet n the
sun-planet and the ring-planet mesh of planet n. A planet tooth meets the sun with one flank
and the ring with the other: in forward drive the sun loads its trailing flank (the sun-planet
mesh's drive flank) and the tooth loads the ring with its leading flank (the ring-planet mesh's
drive flank, which is the sun-planet mesh's coast flank). So

* a root crack (its faces open under either flank's load) weakens both of planet n's meshes
  (a missing tooth takes out both, and leaves no pair in contact over part of its passage: a
  zero stiffness there, the series clipped at 0);
* a spall or wear on the planet tooth's ``flank`` ``"drive"`` (the flank the sun drives; the
  ring meets it on reversal, the ring-planet mesh's coast flank) narrows the contacts and opens
  the gap of that flank only: the sun-planet mesh's drive contacts and the ring-planet mesh's
  coast contacts; ``"coast"`` the other flank (the sun-planet mesh's coast contacts and the
  ring-planet mesh's drive contacts). The thinned sections of the tooth soften the contacts of
  both flanks, so both meshes feel them (as on a pair's tooth, :mod:`geardyn.gears.faults`);
* Archard wear on a planet is the wear of one revolution of the planet in which each of its
  meshes wears the flank it loads under the mean torques (:func:`planet_wear_profiles`, the
  convention of :func:`geardyn.trains.faults.shared_wear_profiles`): in forward drive the sun
  mesh wears the ``"drive"`` flank and the ring mesh the ``"coast"`` flank, each by its own
  sliding, and both meshes' tables take that one depth along the flank;
* on the sun the flanks are the sun-planet mesh's, on the ring the ring-planet mesh's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from geardyn.errors import ParameterError
from geardyn.gears.faults import (
    BrokenTooth,
    RootCrack,
    Spall,
    Wear,
    listed_faults,
    planet_number,
)

_KINDS = (RootCrack, Spall, Wear, BrokenTooth)
_OTHER_FLANK = {"drive": "coast", "coast": "drive"}
LOAD_RTOL = 1e-9
"""A mesh loads a worn flank when its static force on it exceeds this fraction of the applied
torques' force scale (:func:`planet_wear_profiles`); smaller forces are round-off."""


@dataclass(frozen=True)
class FaultPlacement:
    """The faults of a set on one gear: ``member`` (``"sun"``, ``"planet"``, ``"ring"``),
    ``planet`` (0-based index of the faulty planet, None otherwise), ``teeth`` Z_f (mesh cycles
    per forcing period), the faults as given and as the pair tables take them: ``sun_faults``
    on the sun-planet mesh (pinion the sun, wheel the planet), ``ring_faults`` on the
    planet-ring mesh (pinion the planet, wheel the ring)."""

    member: str
    planet: int | None
    teeth: int
    faults: tuple[Any, ...]
    sun_faults: tuple[Any, ...]
    ring_faults: tuple[Any, ...]

    @property
    def planet_archard(self) -> bool:
        """Whether Archard wear lies on a planet (its depth then follows the loads:
        :func:`planet_wear_profiles`)."""
        return self.planet is not None and any(
            isinstance(f, Wear) and f.profile == "archard" for f in self.faults)

    @property
    def gear(self) -> str:
        """The faulty gear's name as the faults give it (``"sun"``, ``"planet2"``, ...)."""
        return self.member if self.planet is None else f"planet{self.planet + 1}"

    def describe(self) -> str:
        """One line for the model's attrs."""
        return "; ".join(f.describe() for f in self.faults)

    def meshes(self, n_planets: int) -> tuple[str, ...]:
        """The meshes the faulty teeth take part in, by the set's mesh names (``s1`` ..
        ``sN``, ``r1`` .. ``rN``): every sun-planet mesh for the sun, every ring-planet mesh
        for the ring, planet n's two meshes for planet n."""
        planets = range(n_planets) if self.planet is None else (self.planet,)
        return (tuple(f"s{i + 1}" for i in planets if self.sun_faults)
                + tuple(f"r{i + 1}" for i in planets if self.ring_faults))


def place_faults(faults: object, geometry: Any) -> FaultPlacement | None:
    """The :class:`FaultPlacement` of ``faults`` (one fault or a sequence) on the gears of
    ``geometry`` (a :class:`~geardyn.gears.PlanetaryGeometry`), None without faults. Errors name
    the fault's field: ``<kind>.gear`` (not a gear of the set, a planet beyond N),
    ``<kind>.tooth`` (beyond the gear's teeth), or ``faults`` (not a fault, faults on more than
    one gear)."""
    listed = listed_faults(faults)
    if not listed:
        return None
    n = geometry.n_planets
    where: dict[str, Any] = {}
    for fault in listed:
        if not isinstance(fault, _KINDS):
            raise ParameterError("faults", fault,
                                 "must be RootCrack, Spall, Wear or BrokenTooth objects")
        kind, gear = fault.kind, fault.gear
        number = planet_number(gear)
        if gear not in ("sun", "ring") and number is None:
            raise ParameterError(f"{kind}.gear", gear, "must be 'sun', 'ring' or 'planet1' .. "
                                 f"'planet{n}' (a gear of the set)")
        if number is not None and not 1 <= number <= n:
            raise ParameterError(f"{kind}.gear", gear, f"the set has {n} planets: 'planet1' .."
                                 f" 'planet{n}'")
        z = {"sun": geometry.sun, "ring": geometry.ring}.get(gear, geometry.planet).teeth
        if not 0 <= fault.tooth < z:
            raise ParameterError(f"{kind}.tooth", fault.tooth,
                                 f"must lie in [0, {z - 1}] ({gear} has {z} teeth)")
        where[gear] = fault
    if len(where) > 1:
        raise ParameterError("faults", ", ".join(sorted(where)),
                             "faults on more than one gear: the forcing period is one "
                             "revolution of the one faulty gear")
    gear = next(iter(where))
    number = planet_number(gear)
    if gear == "sun":
        sun = tuple(replace(f, gear="pinion") for f in listed)
        return FaultPlacement("sun", None, geometry.sun.teeth, listed, sun, ())
    if gear == "ring":
        ring = tuple(replace(f, gear="wheel") for f in listed)
        return FaultPlacement("ring", None, geometry.ring.teeth, listed, (), ring)
    sun = tuple(replace(f, gear="wheel") for f in listed)
    ring = tuple(replace(f, gear="pinion", flank=_OTHER_FLANK[f.flank])
                 if isinstance(f, (Spall, Wear)) else replace(f, gear="pinion")
                 for f in listed)
    return FaultPlacement("planet", number - 1, geometry.planet.teeth, listed, sun, ring)


def planet_passage_delay(geometry: Any) -> float:
    """D [mesh cycles]: how long after a planet tooth passes the sun-side pitch point it passes
    the ring-side one, Z_p / 2 - Z_p (psi_s + psi_r) / (4 pi) (module docstring; D mod 1 is
    gamma_rs)."""
    planet = geometry.planet
    psi_s = planet.angular_thickness(geometry.sun_mesh.operating_pitch_radii[1])
    psi_r = planet.angular_thickness(geometry.ring_mesh.operating_pitch_radii[0])
    z = planet.teeth
    return 0.5 * z - z * (psi_s + psi_r) / (4.0 * math.pi)


def ring_origin(geometry: Any, sun_turns: int) -> float:
    """When ring tooth 0 meets planet 1's ring mesh [mesh cycles]: the shift of that mesh's
    table (whose tooth j then passes at c = origin + j) numbering the ring's teeth as a gear
    train does (:mod:`geardyn.trains.faults`), by the passage of the ring flank the planet-ring
    table calls drive (its clockwise-facing flank), ring tooth 0 the first to pass in [0, 1):
    at gamma_T = (-s (Z_p / 2 - Z_p (psi_r - psi_s) / (4 pi))) mod 1, the planet's
    counter-clockwise-facing flank carried from the sun-side pitch point (at c = 0) to the ring
    side (the step of :meth:`geardyn.trains.TrainModel.geometry_phases`). The set's mesh of
    shift origin puts its table's tooth j (read forwards, the table's mirror image, s = +1;
    backwards, the sun held, s = -1: its tooth -j) at the pitch point at c = origin + j, where
    that flank of the ring tooth passes at c = origin + j - s (1 - phi_r) (phi_r the ring
    mesh's coast phase: the table's coast flank of wheel tooth j passes 1 - phi_r before its
    drive pair), so origin = gamma_rs + round(gamma_T + s (1 - phi_r) - gamma_rs) (gamma_rs
    the set's ring phase, ``sun_ring`` of ``phases_turning(s)``; the rounded number is whole
    to round-off)."""
    from geardyn.gears.potential_energy import coast_phase

    planet = geometry.planet
    psi_s = planet.angular_thickness(geometry.sun_mesh.operating_pitch_radii[1])
    psi_r = planet.angular_thickness(geometry.ring_mesh.operating_pitch_radii[0])
    z = planet.teeth
    gamma_t = (-sun_turns * (0.5 * z - z * (psi_r - psi_s) / (4.0 * math.pi))) % 1.0
    if math.isclose(gamma_t, 1.0, abs_tol=1e-9):
        gamma_t = 0.0
    base = float(geometry.phases_turning(sun_turns).sun_ring)
    lead = sun_turns * (1.0 - coast_phase(geometry.ring_mesh))
    return base + round(gamma_t + lead - base)


def mesh_shifts(geometry: Any, sun_turns: int, placement: FaultPlacement | None
                ) -> tuple[np.ndarray, np.ndarray]:
    """The shifts delta [mesh cycles] of every sun-planet and ring-planet mesh: mesh m's
    stiffness is K_m(c) = T_m(c - delta_m), T_m its table (tooth 0 of either gear at the pitch
    point at c = 0). Without faults the Parker & Lin phases gamma; a faulty gear's meshes take
    the unreduced passage times of the module docstring (mod Z_f)."""
    ph = geometry.phases_turning(sun_turns)
    sun, ring = np.array(ph.sun, dtype=float), np.array(ph.ring, dtype=float)
    if placement is None:
        return sun, ring
    rel = np.asarray(geometry.planet_angles, dtype=float) - geometry.planet_angles[0]
    z = placement.teeth
    if placement.member == "sun":
        sun = np.mod(sun_turns * geometry.sun.teeth * rel / (2.0 * math.pi), z)
    elif placement.member == "ring":
        ring = np.mod(ring_origin(geometry, sun_turns)
                      - sun_turns * geometry.ring.teeth * rel / (2.0 * math.pi), z)
    else:
        p = placement.planet
        ring[p] = (sun[p] + sun_turns * planet_passage_delay(geometry)) % z
    return sun, ring


def planet_wear_profiles(placement: FaultPlacement, geometry: Any, opts: Any,
                         forces: np.ndarray, force_scale: float) -> dict[Any, Any]:
    """The depth along the flank of each Archard :class:`~geardyn.gears.Wear` of a planet's
    ``placement`` (keyed by the fault as given): the wear of one planet revolution, each of its
    two meshes wearing the flank it loads (:func:`~geardyn.gears.potential_energy.
    combined_wear_profile`), weighted by its load per unit face width on the worn flank.
    ``forces``: the set's static mesh forces [N] (sun-planet meshes, then ring-planet; positive
    on the drive flank); the planet's ``"drive"`` flank is the sun-planet mesh's drive flank
    and the ring-planet mesh's coast flank. ``opts``: the
    :class:`~geardyn.models.planetary_stiffness.PotentialEnergyOptions` of the tables.
    ``force_scale`` [N]: the applied torques' force scale, max abs(T_k) / r_k over the members
    (torque T_k, radius r_k). {} without Archard wear on a planet. Error ``wear.flank``: no
    mesh loads the worn flank by more than :data:`LOAD_RTOL` x ``force_scale`` (a smaller
    force is round-off, as in a set whose sun has no support)."""
    from geardyn.gears.potential_energy import combined_wear_profile, prepare_pair

    if not placement.planet_archard:
        return {}
    n, p = geometry.n_planets, placement.planet
    f_sun, f_ring = float(forces[p]), float(forces[n + p])
    common = dict(young=opts.young, poisson=opts.poisson, nodes=opts.nodes,
                  root_segment=opts.root_segment)
    pairs = (prepare_pair(geometry.sun_mesh, bore_radius=(opts.sun_bore_radius,
                                                          opts.planet_bore_radius), **common),
             prepare_pair(geometry.ring_mesh, bore_radius=(opts.planet_bore_radius,
                                                           opts.ring_rim_radius),
                          ring_foundation="rigid", **common))
    out = {}
    for wear in placement.faults:
        if not (isinstance(wear, Wear) and wear.profile == "archard"):
            continue
        sign = 1.0 if wear.flank == "drive" else -1.0
        raw = (max(sign * f_sun, 0.0), max(-sign * f_ring, 0.0))
        if not max(raw) > LOAD_RTOL * force_scale:
            raise ParameterError("wear.flank", wear.flank, f"no mesh of {placement.gear} loads "
                                 f"its {wear.flank} flank under the mean torques (static mesh "
                                 f"forces {f_sun:.6g} N sun-side, {f_ring:.6g} N ring-side, "
                                 f"round-off below {LOAD_RTOL:g} x {force_scale:.6g} N, the "
                                 "torques' force scale): Archard wear on a planet follows the "
                                 "mesh that loads the worn flank")
        parts = [(pair, role, w / max(raw) / pair.face_width)
                 for pair, role, w in zip(pairs, ("wheel", "pinion"), raw, strict=True)]
        out[wear] = combined_wear_profile(parts, wear.depth)
    return out
