"""Time-varying mesh stiffness: single and double tooth contact alternating with eps_alpha.

Over one mesh cycle (mesh phase theta in [0, 2 pi), one base pitch of travel along the line of
action) two tooth pairs are in contact for the fraction eps_alpha - 1 and one pair for the rest
(1 < eps_alpha < 2). With the single-pair stiffness k_s = c' b and the double-contact stiffness
k_d = 1.75 c' b the mean is exactly ISO 6336-1's c_gamma_alpha b = c' b (0.75 eps + 0.25):
k_s (2 - eps) + k_d (eps - 1) = c' (0.75 eps + 0.25) needs k_d / k_s = 1.75. This reading of the
ISO formula is geardyn's, not the standard's; ``double_to_single`` changes it.

Phase reference: theta = 0 when a tooth pair passes the pitch point (the reference of
:func:`geardyn.gears.phasing.mesh_phases`), so mesh n with phase gamma_n (fraction of a cycle)
has the stiffness k(theta - 2 pi gamma_n). The double-contact interval starts when a new pair
enters at the start of the path of contact, g_f / p_b cycles before a pair passes the pitch point
(the pinion drives).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geardyn.errors import ParameterError
from geardyn.gears.geometry import GearMesh
from geardyn.gears.iso6336 import iso6336_stiffness

#: k_double / k_single that makes the rectangular wave's mean ISO's c_gamma_alpha.
ISO_DOUBLE_TO_SINGLE = 1.75


@dataclass(frozen=True)
class StiffnessWaveform:
    """A rectangular (optionally trapezoidal) mesh stiffness over the mesh phase.

    ``single``/``double`` [N/m] are the stiffnesses in single and double contact,
    ``contact_ratio`` eps_alpha in (1, 2), ``centre`` the phase (fraction of a cycle) of the
    centre of the double-contact interval relative to the pitch-point crossing, ``transition``
    the width (fraction of a cycle) of the linear ramps replacing each jump (0: rectangular).
    """

    single: float
    double: float
    contact_ratio: float
    centre: float = 0.0
    transition: float = 0.0

    def __post_init__(self) -> None:
        if not 1.0 < self.contact_ratio < 2.0:
            raise ParameterError("contact_ratio", self.contact_ratio,
                                 "the single/double contact wave needs 1 < eps_alpha < 2")
        if not 0.0 < self.single <= self.double:
            raise ParameterError("double", self.double, "need 0 < single <= double stiffness")
        duty = self.contact_ratio - 1.0
        if not 0.0 <= self.transition <= min(duty, 1.0 - duty):
            raise ParameterError("transition", self.transition,
                                 f"must lie in [0, {min(duty, 1.0 - duty):.4g}] (the shorter"
                                 " of the single and double contact intervals)")

    @property
    def duty(self) -> float:
        """Fraction of a cycle in double contact, eps_alpha - 1."""
        return self.contact_ratio - 1.0

    @property
    def mean(self) -> float:
        """Time-average stiffness Km [N/m]."""
        return self.single + (self.double - self.single) * self.duty

    @property
    def amplitude(self) -> float:
        """Half the peak-to-peak variation, Ka = (k_d - k_s) / 2 [N/m] (``Mesh``'s
        ``stiffness_amplitude``)."""
        return 0.5 * (self.double - self.single)

    def __call__(self, theta: np.ndarray | float, phase: float = 0.0) -> np.ndarray:
        """Stiffness [N/m] at mesh phase ``theta`` [rad] of a mesh delayed by ``phase``
        (fraction of a cycle): k(theta - 2 pi phase)."""
        u = np.asarray(theta, dtype=float) / (2.0 * np.pi) - phase - self.centre
        d = (u + 0.5) % 1.0 - 0.5  # distance from the double-contact centre, in cycles
        half, w = 0.5 * self.duty, self.transition
        if w == 0.0:
            inside = (np.abs(d) < half).astype(float)
        else:
            inside = np.clip((half - np.abs(d)) / w + 0.5, 0.0, 1.0)
        return self.single + (self.double - self.single) * inside

    def fourier(self, n_harmonics: int, phase: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Relative coefficients (a_h, b_h), h = 1..n, of K/Km - 1 = sum a_h cos(h theta) +
        b_h sin(h theta) (the form of :mod:`geardyn.models.stiffness`), exact (no sigma
        factors); trapezoid ramps multiply harmonic h by sinc(h w)."""
        h = np.arange(1, n_harmonics + 1, dtype=float)
        height = (self.double - self.single) / self.mean
        mag = 2.0 * height * np.sin(h * np.pi * self.duty) / (h * np.pi)
        mag = mag * np.sinc(h * self.transition)
        shift = 2.0 * np.pi * h * (self.centre + phase)
        return mag * np.cos(shift), mag * np.sin(shift)

    def mesh_fields(self, phase: float = 0.0, harmonics: int = 25) -> dict[str, object]:
        """Keyword arguments for :class:`geardyn.Mesh` (``waveform="rectangular"``) giving this
        wave delayed by ``phase`` cycles (the Mesh's Lanczos smoothing applies there; a Mesh
        has no ramps, so a wave with ``transition > 0`` is refused)."""
        if self.transition:
            raise ParameterError("transition", self.transition,
                                 "geardyn.Mesh has no ramped rectangular wave; use"
                                 " fourier() for the ramped wave")
        return {"mean_stiffness": self.mean, "stiffness_amplitude": self.amplitude,
                "waveform": "rectangular", "contact_ratio": self.contact_ratio,
                "harmonics": harmonics,
                "stiffness_phase": float(-2.0 * math.pi * ((self.centre + phase) % 1.0))}


def double_contact_centre(mesh: GearMesh) -> float:
    """Phase (fraction of a cycle, in [0, 1)) of the centre of double contact after the
    pitch-point crossing: (eps - 1)/2 - g_f/p_b (mod 1)."""
    return (0.5 * (mesh.contact_ratio - 1.0) - mesh.approach_length / mesh.base_pitch) % 1.0


def mesh_stiffness_waveform(mesh: GearMesh | None = None, *, contact_ratio: float | None = None,
                            single_stiffness: float | None = None,
                            double_to_single: float = ISO_DOUBLE_TO_SINGLE,
                            transition: float = 0.0, centre: float | None = None,
                            **iso_options: float | None) -> StiffnessWaveform:
    """The mesh stiffness wave of ``mesh`` (contact ratio, ISO 6336-1 single stiffness c' b,
    double contact ``double_to_single`` times it), or of the given ``contact_ratio`` and
    ``single_stiffness`` [N/m] without a mesh. ``iso_options`` go to
    :func:`~geardyn.gears.iso6336.iso6336_stiffness`."""
    if mesh is not None:
        contact_ratio = mesh.contact_ratio if contact_ratio is None else contact_ratio
        if single_stiffness is None:
            single_stiffness = iso6336_stiffness(mesh, **iso_options).single_stiffness
        if centre is None:
            centre = double_contact_centre(mesh)
    if contact_ratio is None or single_stiffness is None:
        raise ParameterError("mesh", None, "give a GearMesh, or contact_ratio and"
                             " single_stiffness")
    return StiffnessWaveform(single=single_stiffness, double=double_to_single * single_stiffness,
                             contact_ratio=contact_ratio, centre=centre or 0.0,
                             transition=transition)
