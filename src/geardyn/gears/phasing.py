"""Planetary mesh phasing (Parker & Lin, J. Mech. Des. 126 (2004) 365-370) and the planetary
gear geometry that ties the sun-planet and ring-planet meshes together.

Frame: the carrier. Planet n sits at angle psi_n, measured in the sense in which the sun turns
relative to the carrier; the sun drives. A mesh's phase is the fraction of a mesh cycle by which
its tooth pairs pass the pitch point later than those of the first sun-planet mesh, so its
stiffness is k(t - gamma T_m). Then

* gamma_sn = Z_s psi_n / (2 pi)  (mod 1),
* gamma_rn = gamma_rs - Z_r psi_n / (2 pi)  (mod 1),

where gamma_rs is the ring-planet phase relative to the sun-planet phase of the same planet.
When the sun turns against psi relative to the carrier (the sun held and the carrier driven in
the sense of psi) the planets turn the other way too: the same flanks pass the pitch points
(those of the first case), gamma_sn = -Z_s psi_n / (2 pi), gamma_rn = -gamma_rs + Z_r psi_n /
(2 pi) (mod 1), the planet turning pi + (psi_s + psi_r) / 2 from the one flank's sun-side
passage to the other's ring-side one where it turned pi - (psi_s + psi_r) / 2. A
planet can be assembled only where (Z_s + Z_r) psi_n / (2 pi) is a whole number, which makes
the two expressions agree for every planet. gamma_rs follows from the planet's tooth thickness:
the sun loads one flank of a planet tooth at the sun-side pitch point, the ring the opposite
flank at the ring-side pitch point, half a turn away, so
gamma_rs = Z_p / 2 - Z_p (psi_s + psi_r) / (4 pi)  (mod 1), psi_s and psi_r being the planet
tooth's angular thickness at its operating pitch radius in the sun and ring mesh.

For equally spaced planets the net excitation of harmonic l of the mesh frequency (Parker,
J. Sound Vib. 236 (2000) 561-573): the torque on the sun survives where l Z_s / N is whole, the
net translational force where l Z_s = +-1 (mod N); otherwise both cancel (the same with Z_r for
the ring).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from geardyn.core.inputs import N_PLANETS
from geardyn.errors import ParameterError
from geardyn.gears.geometry import GearMesh, SpurGear
from geardyn.gears.iso6336 import ISOStiffness, iso6336_stiffness
from geardyn.gears.waveform import StiffnessWaveform, mesh_stiffness_waveform

#: Tolerance on (Z_s + Z_r) psi_n / (2 pi) being a whole number.
ASSEMBLY_TOL = 1e-6


def equally_spaced(n_planets: int) -> np.ndarray:
    """psi_n = 2 pi (n - 1) / N [rad]; ``n_planets`` within :data:`~geardyn.core.inputs.N_PLANETS`'s
    range."""
    n_planets = N_PLANETS.count(n_planets)
    return 2.0 * np.pi * np.arange(n_planets) / n_planets


@dataclass(frozen=True)
class MeshPhases:
    """Phases (fractions of a mesh cycle in [0, 1)) relative to the first sun-planet mesh."""

    sun: np.ndarray  # gamma_sn, one per planet
    ring: np.ndarray  # gamma_rn
    sun_ring: float  # gamma_rs
    planet_angles: np.ndarray  # psi_n [rad]


def _check_assembly(sun_teeth: int, ring_teeth: int, angles: np.ndarray) -> None:
    turns = (sun_teeth + ring_teeth) * (angles - angles[0]) / (2.0 * np.pi)
    bad = np.abs(turns - np.round(turns)) > ASSEMBLY_TOL
    if bad.any():
        k = int(np.argmax(bad))
        raise ParameterError(
            f"planet_angles[{k}]", float(angles[k]),
            f"the planet cannot be assembled: (Z_s + Z_r) psi / 2pi = {turns[k]:.6g} must be"
            f" a whole number (Z_s + Z_r = {sun_teeth + ring_teeth})")


def mesh_phases(sun_teeth: int, ring_teeth: int, planet_angles: np.ndarray | int,
                sun_ring_phase: float = 0.0, sun_turns: int = 1) -> MeshPhases:
    """Phases of every sun-planet and ring-planet mesh (Parker & Lin 2004).

    ``planet_angles`` [rad] or a planet count (equally spaced). ``sun_ring_phase`` is gamma_rs
    (see :func:`sun_ring_phase`; :class:`PlanetaryGeometry` computes it from the teeth).
    ``sun_turns``: +1 when the sun turns in the sense of psi relative to the carrier, -1 when
    against it (the planets' flanks then meet the ring -gamma_rs after the sun: the module
    doc); ``MeshPhases.sun_ring`` is the one used.
    """
    if sun_turns not in (1, -1) or isinstance(sun_turns, bool):
        raise ParameterError("sun_turns", sun_turns, "must be +1 or -1 (the sense in which "
                             "the sun turns relative to the carrier)")
    angles = (equally_spaced(planet_angles) if isinstance(planet_angles, numbers.Integral)
              else np.asarray(planet_angles, dtype=float).ravel())
    for name, z in (("sun_teeth", sun_teeth), ("ring_teeth", ring_teeth)):
        if isinstance(z, bool) or not isinstance(z, numbers.Integral) or z < 5:
            raise ParameterError(name, z, "must be a whole number >= 5")
    if not N_PLANETS.minimum <= angles.size <= N_PLANETS.maximum:
        raise ParameterError("planet_angles", planet_angles,
                             f"need {N_PLANETS.minimum:g} to {N_PLANETS.maximum:g} planets")
    _check_assembly(sun_teeth, ring_teeth, angles)
    rel = sun_turns * (angles - angles[0])
    sun_ring = sun_turns * sun_ring_phase  # the planet turning the other way: -gamma_rs
    gamma_s = (sun_teeth * rel / (2.0 * np.pi)) % 1.0
    gamma_r = (sun_ring - ring_teeth * rel / (2.0 * np.pi)) % 1.0
    # whole cycles come out as 1 - 1e-16: fold them to 0
    gamma_s[np.isclose(gamma_s, 1.0, atol=1e-9)] = 0.0
    gamma_r[np.isclose(gamma_r, 1.0, atol=1e-9)] = 0.0
    return MeshPhases(sun=gamma_s, ring=gamma_r, sun_ring=float(sun_ring % 1.0),
                      planet_angles=angles)


def sun_ring_phase(sun_mesh: GearMesh, ring_mesh: GearMesh) -> float:
    """gamma_rs of one planet from its tooth thickness at its two operating pitch radii."""
    planet = sun_mesh.wheel
    psi_s = planet.angular_thickness(sun_mesh.operating_pitch_radii[1])
    psi_r = planet.angular_thickness(ring_mesh.operating_pitch_radii[0])
    z = planet.teeth
    return (0.5 * z - z * (psi_s + psi_r) / (4.0 * math.pi)) % 1.0


def surviving_harmonics(teeth: int, n_planets: int, harmonics: int) -> dict[int, dict[str, bool]]:
    """For equally spaced planets, which harmonics l = 1..``harmonics`` of the mesh frequency
    survive in the net torque and in the net translational force on the sun (``teeth`` = Z_s)
    or ring (Z_r)."""
    equally_spaced(n_planets)  # validates the count
    out = {}
    for ell in range(1, harmonics + 1):
        r = (ell * teeth) % n_planets
        out[ell] = {"torque": r == 0, "force": r in (1 % n_planets, (-1) % n_planets)}
    return out


@dataclass(frozen=True)
class PlanetaryGeometry:
    """Sun, planets and ring of one stage: the two meshes, their phases and stiffnesses.

    ``planet_angles`` [rad] (None: ``n_planets`` equally spaced); ``centre_distance`` the carrier
    radius [m] (None: the sun-planet zero-backlash distance). Checks coaxiality (both meshes at
    one centre distance, via :class:`GearMesh`), assembly and that neighbouring planets' tip
    circles stay ``min_planet_gap`` [m] apart.
    """

    sun: SpurGear
    planet: SpurGear
    ring: SpurGear
    n_planets: int = 3
    planet_angles: tuple[float, ...] | None = None
    centre_distance: float | None = None
    min_planet_gap: float = 0.0

    def __post_init__(self) -> None:
        if not self.ring.internal:
            raise ParameterError("ring.internal", False, "the ring must be an internal gear")
        angles = (equally_spaced(self.n_planets) if self.planet_angles is None
                  else np.asarray(self.planet_angles, dtype=float).ravel())
        object.__setattr__(self, "planet_angles", tuple(float(a) for a in angles))
        object.__setattr__(self, "n_planets", len(angles))
        self._check_spacing()
        _ = self.ring_mesh, self.phases  # validate now

    @cached_property
    def sun_mesh(self) -> GearMesh:
        """The sun (pinion) - planet (wheel) mesh."""
        return GearMesh(self.sun, self.planet, centre_distance=self.centre_distance)

    @cached_property
    def ring_mesh(self) -> GearMesh:
        """The planet (pinion) - ring (internal wheel) mesh at the same centre distance. A ring
        that does not fit it is an error naming the ring's ``teeth`` (Z_r != Z_s + 2 Z_p) or
        its ``profile_shift``."""
        a = self.sun_mesh.centre_distance
        try:
            return GearMesh(self.planet, self.ring, centre_distance=a, internal=True)
        except ParameterError as exc:
            if exc.field != "centre_distance":
                raise
            zs, zp, zr = self.sun.teeth, self.planet.teeth, self.ring.teeth
            name = self.ring.name
            field, value = ((f"{name}.teeth", zr) if zr != zs + 2 * zp
                            else (f"{name}.profile_shift", self.ring.profile_shift))
            raise ParameterError(field, value, f"the ring does not mesh with the planets at the "
                                 f"sun mesh's centre distance {a:.6g} m ({exc.reason}); without "
                                 f"profile shifts Z_r = Z_s + 2 Z_p = {zs + 2 * zp}") from None

    @cached_property
    def phases(self) -> MeshPhases:
        """Parker & Lin mesh phases, gamma_rs from the planet's teeth, the sun turning in the
        sense of psi relative to the carrier (ring or carrier held, sun input)."""
        return self.phases_turning(1)

    def phases_turning(self, sun_turns: int) -> MeshPhases:
        """The mesh phases with the sun turning in the sense of psi relative to the carrier
        (``sun_turns`` = +1) or against it (-1: the sun held, the carrier driven)."""
        return mesh_phases(self.sun.teeth, self.ring.teeth, np.asarray(self.planet_angles),
                           sun_ring_phase(self.sun_mesh, self.ring_mesh), sun_turns)

    def _check_spacing(self) -> None:
        a = self.sun_mesh.centre_distance
        angles = np.sort(np.mod(self.planet_angles, 2.0 * np.pi))
        gaps = np.diff(np.append(angles, angles[0] + 2.0 * np.pi))
        if angles.size < 2:
            return
        chord = 2.0 * a * np.sin(0.5 * gaps.min())
        need = 2.0 * self.planet.tip_radius + self.min_planet_gap
        if chord < need:
            raise ParameterError(
                "planet_angles", self.planet_angles,
                f"neighbouring planets collide: their centres are {chord:.4g} m apart, their tip"
                f" circles need {need:.4g} m")

    def stiffness(self) -> tuple[ISOStiffness, ISOStiffness]:
        """ISO 6336-1 method B of the sun-planet and ring-planet meshes."""
        return iso6336_stiffness(self.sun_mesh), iso6336_stiffness(self.ring_mesh)

    def waveforms(self, **options: float) -> tuple[StiffnessWaveform, StiffnessWaveform]:
        """Stiffness waves of the sun-planet and ring-planet meshes (phase 0 = pitch point)."""
        return (mesh_stiffness_waveform(self.sun_mesh, **options),
                mesh_stiffness_waveform(self.ring_mesh, **options))
