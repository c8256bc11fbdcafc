"""Mesh stiffness of an external or internal spur pair by the potential-energy method.

Each tooth is a cantilever of variable section on its involute flank (Yang & Lin 1987; Tian
2004; Wu, Zuo & Parey 2008; Chaari, Fakhfakh & Haddar 2009), of face width b and Young's
modulus E (shear modulus G = E / (2 (1 + nu))). In the tooth's own frame (x along the centre
line from the gear centre, y across it) the involute point whose tangent touches the base circle
(radius r_b) at angle alpha from the centre line is

    x(alpha) = r_b [cos alpha - (alpha_2 - alpha) sin alpha]
    h(alpha) = r_b [sin alpha + (alpha_2 - alpha) cos alpha]     (half thickness)
    dx = r_b (alpha_2 - alpha) cos alpha dalpha

with alpha_2 the half angular thickness of the tooth on the base circle. A contact whose roll
angle is tan(alpha_c) = s / r_b (s: distance from the gear's tangent point on the line of action)
lies at alpha = -alpha_1, alpha_1 = s / r_b - alpha_2: alpha_1 is the angle between the contact
force F and the normal to the centre line, so F splits into F cos alpha_1 (bending, shear) and
F sin alpha_1 (axial compression). With x_c, h_c the contact point's coordinates, the energies
F^2 / (2 k) give the compliances

    1/k_b = int [cos a1 (x_c - x) - sin a1 h_c]^2 / (E I) dx,   I = (2/3) h^3 b
    1/k_s = int 1.2 cos^2 a1 / (G A) dx,                       A = 2 h b
    1/k_a = int sin^2 a1 / (E A) dx

integrated from the root section to the contact point (alpha from -alpha_1 to the root) by a
fixed Gauss-Legendre rule, vectorised over contact positions. The root section:

* root circle below the base circle (r_f < r_b, fewer than about 42 teeth at 20 deg): the
  flank between the root and base circles is the straight radial line of half thickness
  h_b = r_b sin alpha_2 (Chen & Shao 2011; Ma et al. 2014; Liang, Zuo & Pandey 2014), a
  section of constant h from x = r_f cos alpha_3 (sin alpha_3 = h_b / r_f) to x = r_b cos
  alpha_2, whose integrals are closed forms. ``root_segment=False`` leaves it out: the
  cantilever then starts at the base circle (Tian 2004; Wu, Zuo & Parey 2008);
* root circle above the base circle: the cantilever starts at the root circle, alpha_3 =
  alpha_2 - sqrt(r_f^2 / r_b^2 - 1) (the involute below r_f is not material).

The fillet (trochoid) is not modelled in the cantilever; the gear body's deflection below the
root circle is the fillet-foundation term of Sainsot, Velex & Duverger (2004):

    1/k_f = cos^2 a1 / (E b) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2 a1)]

with u_f the distance along the centre line from the root circle to where the line of the force
crosses it (x_c - h_c tan a1 - r_f), S_f = 2 r_f theta_f the chord of the tooth at the root circle
(theta_f: its half angle there), and X* = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f +
E h_fi + F, h_fi = r_f / r_int (r_int: the bore radius), the published polynomial fits (their
range of validity is not checked here). The Hertz term of a line contact of two equal
materials is load-independent, k_h = pi E b / (4 (1 - nu^2)) (Yang & Lin 1987). One pair:

    1/k = 1/k_h + sum over both gears (1/k_b + 1/k_s + 1/k_a + 1/k_f)

and the mesh stiffness is the sum over the pairs in contact (pairs act in parallel, load
sharing by equal deflection); b is the smaller face width.

Internal pairs (a pinion in a ring; the ring's tooth after Chen & Shao 2013 and Liang, Zuo & Feng
2015, who model it as a variable-section cantilever on its involute fixed at the root circle):
the ring's flank is the involute of its base circle on the other branch, the same x(alpha),
h(alpha) at alpha = alpha_2 + t (t >= 0 its roll angle, alpha_2 = pi/z2 less the space's half
angle on the base circle, negative for large z2), so dx = r_b (alpha - alpha_2) cos alpha dalpha
> 0: the root circle (alpha_root = alpha_2 + sqrt(r_f^2/r_b^2 - 1)) lies outside the contact
and the tooth thickens towards it. A contact at distance s_2 from the ring's tangent point T2
(T2 beyond the pinion's T1 on the same side of the pitch point: s_2 = r_b2 tan alpha_w + s) lies
at alpha_1 = alpha_2 + s_2 / r_b2; the force along the line of action splits into F cos alpha_1
across the tooth and F sin alpha_1 along its centre line towards the root, so

    1/k_b = int [cos a1 (x - x_c) - sin a1 h_c]^2 / (E I) dx     (x from x_c out to the root)

with the shear and axial integrals as above, integrated over alpha from alpha_1 to alpha_root.
The ring body under the teeth is rigid (``ring_foundation="rigid"``; Sainsot's fit describes an
external gear's body and does not apply), which needs a rim at least as thick as the teeth. A
root crack on a ring tooth narrows the sections between Tian's crack limit line and the root
circle as on an external tooth; a spall or wear thins the sections under it and narrows its
flank's contacts as on an external tooth, its flank points at roll t at alpha = alpha_2 + t
(``position`` along the profile positive towards the ring's tip, inwards; the active profile
from the tip to the deepest contact, at the end of the path).

The coast (back) flanks of symmetric teeth mesh on the mirror image of the line of action
(Guo & Parker 2014, back-side contact): a coast contact at the same distance from the pitch point
loads both teeth at the same load angles, so the coast pair stiffness is the drive one at that
position; the coast contacts travel the path of contact backwards, and a pinion tooth's coast
flank passes the pitch point phi = s_w1 / p_w1 mesh cycles after its drive flank (see
:func:`coast_phase`), so K_coast(c) = K_drive(phi - c) in mesh cycles c of the pinion, each
flank taken in its own contact (the relative rotation between the two is the backlash).

Faults (:mod:`geardyn.gears.faults`), each on its own tooth (or a spall or wear on each flank
of one): a :class:`RootCrack` narrows the sections below Tian's crack limit line, a
:class:`Spall` the sections under it and the Hertz contact on it, :class:`Wear` the sections
of the active profile (and opens a gap, the ``fault_gap`` that
:func:`~geardyn.gears.loaded_contact` adds to the tip relief's), and a :class:`BrokenTooth`
takes its pairs out of contact (see :func:`tooth_compliances` and
:meth:`PotentialEnergyPair.terms`); the tooth indices of each pair follow the pitch-point
passages. A spall or wear lies on the drive or the coast flank (``flank``): the sections it
thins are the tooth's, felt by the contacts of both flanks; its contact-width loss (spall) or
gap (wear, ``fault_gap_coast`` on the coast flank) only by its own flank's contacts, at the same
load angles on either flank. A root crack lies at the drive flank's root, its faces open under
either load.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np
import xarray as xr

from geardyn.core.settings import warn_deprecated
from geardyn.errors import ParameterError
from geardyn.gears.faults import BrokenTooth, Fault, RootCrack, Spall, Wear
from geardyn.gears.geometry import GearMesh, SpurGear
from geardyn.units import si_value, to_si

#: Young's modulus [Pa] and Poisson ratio of the steel of the 19/48 literature pair.
STEEL_YOUNG = 2.068e11
STEEL_POISSON = 0.3
#: Gauss-Legendre nodes of the tooth integrals (relative error below 1e-10 for spur teeth).
DEFAULT_NODES = 32

#: Sainsot, Velex & Duverger (2004): coefficients (A, B, C, D, E, F) of
#: X* = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F.
SAINSOT_COEFFS: dict[str, tuple[float, ...]] = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}

#: Degree of the Chebyshev interpolant of Archard's wear rate on each smooth stretch of the
#: flank (the interpolation error is below 1e-10 of the largest depth for spur teeth).
ARCHARD_DEGREE = 40

#: The energy terms of one tooth, in the order of the compliance sum.
TOOTH_TERMS = ("bending", "shear", "axial", "fillet")


def sainsot_coefficient(name: str, h_fi: float, theta_f: float) -> float:
    """Sainsot's fitted coefficient ``name`` (L, M, P or Q) at h_fi = r_f / r_int and the
    half angle theta_f [rad] of the tooth at the root circle."""
    a, b, c, d, e, f = SAINSOT_COEFFS[name]
    return (a / theta_f ** 2 + b * h_fi ** 2 + c * h_fi / theta_f + d / theta_f + e * h_fi + f)


@dataclass(frozen=True)
class ToothModel:
    """One gear's tooth as the potential-energy method sees it (SI units, radians).

    ``top`` is the upper limit of the involute parameter alpha (the root end of the involute
    cantilever), ``tip`` its value at the tip circle; ``segment`` is (x_root, x_base, h_b) of
    the straight part between the root and base circles, or None; ``fillet`` holds Sainsot's
    (L*, M*, P*, Q*). ``pitch_roll`` is the roll angle tan(alpha) of the reference circle and
    ``start_roll`` that of the lowest contact of the flank in its mesh (the start of the active
    profile; 0, the base circle, until the mesh is known: :func:`prepare_pair` sets it). A flank
    point at roll angle t lies at alpha = half_base_angle - t, r_b t^2 / 2 along the involute
    from the base circle.

    ``internal``: a ring's tooth (:func:`ring_tooth_model`): the same x(alpha), h(alpha) on the
    other branch of the involute, alpha = half_base_angle + t, with ``half_base_angle`` the
    tooth's half angle on the base circle (pi/z less half the space's), ``top`` the root circle's
    alpha, ``bore_radius`` the ring's outer (rim) radius, no straight segment and no fillet
    foundation (``fillet`` all zero: the ring body is rigid)."""

    name: str
    base_radius: float
    root_radius: float
    half_base_angle: float
    top: float
    tip: float
    segment: tuple[float, float, float] | None
    theta_f: float
    bore_radius: float
    fillet: tuple[float, float, float, float]
    pitch_roll: float = math.nan
    start_roll: float = 0.0
    internal: bool = False

    @property
    def h_fi(self) -> float:
        """r_f / r_int."""
        return self.root_radius / self.bore_radius


def tooth_model(gear: SpurGear, bore_radius: float, *, root_segment: bool = True,
                role: str | None = None, ring_foundation: str = "rigid") -> ToothModel:
    """The cantilever and fillet-foundation description of ``gear``'s tooth on a bore of radius
    ``bore_radius`` [m] (an internal gear: :func:`ring_tooth_model`, ``bore_radius`` its outer
    rim radius); ``role`` names the gear in errors."""
    role = role or gear.name
    if gear.internal:
        return ring_tooth_model(gear, bore_radius, role=role, foundation=ring_foundation)
    if gear.profile_shift < gear.min_profile_shift - 1e-12:
        raise ParameterError(f"{role}.profile_shift", gear.profile_shift,
                             "undercut teeth: the tooth model needs the whole involute flank"
                             f" (profile shift >= {gear.min_profile_shift:.4f})")
    r_b, r_f = gear.base_radius, gear.root_radius
    if not 0.0 < bore_radius < r_f:
        raise ParameterError(f"{role}.bore_radius", bore_radius,
                             f"must lie between 0 and the root radius {r_f:.6g} m")
    a2 = 0.5 * gear.angular_thickness(r_b)
    segment = None
    if r_f <= r_b:
        h_b = r_b * math.sin(a2)
        a3 = math.asin(h_b / r_f)
        top, theta_f = a2, a3
        if root_segment and r_f < r_b:
            segment = (r_f * math.cos(a3), r_b * math.cos(a2), h_b)
    else:
        top = a2 - math.sqrt((r_f / r_b) ** 2 - 1.0)
        phi = a2 - top
        theta_f = math.atan2(math.sin(top) + phi * math.cos(top),
                             math.cos(top) - phi * math.sin(top))
    h_fi = r_f / bore_radius
    fillet = tuple(sainsot_coefficient(n, h_fi, theta_f) for n in "LMPQ")
    tip = a2 - math.sqrt((gear.tip_radius / r_b) ** 2 - 1.0)
    return ToothModel(name=role, base_radius=r_b, root_radius=r_f, half_base_angle=a2,
                      top=top, tip=tip, segment=segment, theta_f=theta_f, bore_radius=bore_radius,
                      fillet=fillet,  # type: ignore[arg-type]
                      pitch_roll=math.tan(gear.pressure_angle))


#: The treatments of the ring body under its teeth that :func:`ring_tooth_model` accepts.
RING_FOUNDATIONS = ("rigid",)


def ring_tooth_model(gear: SpurGear, rim_radius: float, *, role: str | None = None,
                     foundation: str = "rigid") -> ToothModel:
    """The cantilever of an internal gear's (ring's) tooth, its rim's outer radius
    ``rim_radius`` [m] (module docstring). The flanks are involutes of the base circle whose
    roll angle t grows from the tip (inside) to the root circle (outside), at alpha =
    alpha_2 + t; the cantilever is fixed at the root circle, alpha_root = alpha_2 +
    sqrt(r_f^2 / r_b^2 - 1). ``foundation`` (:data:`RING_FOUNDATIONS`): ``"rigid"``, the ring
    body outside the root circle does not deflect (no fillet-foundation term), which needs a
    rim at least as thick as the teeth are high (r_rim - r_f >= r_f - r_a; refused otherwise)."""
    role = role or gear.name
    if foundation not in RING_FOUNDATIONS:
        raise ParameterError("ring_foundation", foundation,
                             f"must be one of {', '.join(RING_FOUNDATIONS)}")
    r_b, r_f, r_a = gear.base_radius, gear.root_radius, gear.tip_radius
    height = r_f - r_a
    if not (math.isfinite(rim_radius) and rim_radius - r_f >= height):
        raise ParameterError(f"{role}.bore_radius", rim_radius,
                             f"the ring's outer (rim) radius must be at least the root radius"
                             f" {r_f:.6g} m plus the tooth height {height:.6g} m (a rim thinner"
                             f" than the teeth is not a rigid body): >= {r_f + height:.6g} m")
    a2 = math.pi / gear.teeth - 0.5 * gear.angular_thickness(r_b)
    t_f = math.sqrt((r_f / r_b) ** 2 - 1.0)
    t_a = math.sqrt((r_a / r_b) ** 2 - 1.0)
    return ToothModel(name=role, base_radius=r_b, root_radius=r_f, half_base_angle=a2,
                      top=a2 + t_f, tip=a2 + t_a, segment=None,
                      theta_f=a2 + t_f - math.atan(t_f), bore_radius=rim_radius,
                      fillet=(0.0, 0.0, 0.0, 0.0), pitch_roll=math.tan(gear.pressure_angle),
                      internal=True)


@lru_cache(maxsize=8)
def _gauss(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(nodes)
    return x, w


def contact_point(tooth: ToothModel, alpha1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x_c, h_c) [m] of the contact at load angle ``alpha1`` [rad] in the tooth's frame (the
    flank point at alpha = -alpha1, or alpha = alpha1 on a ring's tooth)."""
    r_b, a2 = tooth.base_radius, tooth.half_base_angle
    if tooth.internal:
        roll = alpha1 - a2
        return (r_b * (np.cos(alpha1) + roll * np.sin(alpha1)),
                r_b * (np.sin(alpha1) - roll * np.cos(alpha1)))
    roll = alpha1 + a2
    return (r_b * (np.cos(alpha1) + roll * np.sin(alpha1)),
            r_b * (roll * np.cos(alpha1) - np.sin(alpha1)))


def root_half_thickness(tooth: ToothModel) -> float:
    """Half thickness h_r [m] of the cantilever's root section (where a root crack starts)."""
    phi = tooth.half_base_angle - tooth.top
    return tooth.base_radius * (math.sin(tooth.top) + phi * math.cos(tooth.top))


def crack_limit(tooth: ToothModel, h_q: float) -> float:
    """alpha_c: the involute parameter above which (towards the root) the flank's half thickness
    exceeds h_q, the crack tip's distance from the centre line (Tian's crack limit line runs
    from the tip parallel to the centre line until it meets the flank); the tooth tip's alpha if
    the line reaches the tip. h(alpha) rises with alpha for alpha < 0 (external tooth) and for
    alpha > 0 (a ring's tooth, up to its root circle)."""
    r_b, a2 = tooth.base_radius, tooth.half_base_angle

    def h(a: float) -> float:
        return r_b * (math.sin(a) + (a2 - a) * math.cos(a))

    if h(tooth.tip) >= h_q:
        return tooth.tip
    lo, hi = tooth.tip, (tooth.top if tooth.internal else 0.0)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if h(mid) < h_q:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15:
            break
    return hi


#: (I, A) of a faulty section from its healthy half thickness h and involute parameter alpha.
Section = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def _crack_section(h_q: float, b: float) -> Section:
    """(I, A) of sections cut by a crack limit line h_q from the centre line: h + h_q thick."""
    return lambda h, al: ((h + h_q) ** 3 * b / 12.0, (h + h_q) * b)


def _spall_section(width: float, depth: float, b: float) -> Section:
    """(I, A) of the 2h x b section less a ``depth`` x ``width`` rectangle at the spalled flank
    (either: the section is the same mirrored), I about the reduced section's own centroid
    (shifted by y_c towards the other flank)."""
    cut = width * depth

    def section(h: np.ndarray, al: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        area = 2.0 * h * b - cut
        y_c = -cut * (h - 0.5 * depth) / area
        inertia = ((2.0 / 3.0) * h ** 3 * b + 2.0 * h * b * y_c ** 2
                   - width * depth ** 3 / 12.0 - cut * (h - 0.5 * depth - y_c) ** 2)
        return inertia, area

    return section


def _wear_section(depth: float, b: float) -> Section:
    """(I, A) of sections thinned by ``depth`` at the worn flank: 2h - depth thick."""
    return lambda h, al: ((2.0 * h - depth) ** 3 * b / 12.0, (2.0 * h - depth) * b)


def _profile_section(profile: WearProfile, roll: Callable, b: float) -> Section:
    """(I, A) of sections thinned by the wear depth ``profile`` at their flank point (``roll``:
    its roll angle from alpha, :func:`alpha_roll`)."""

    def section(h: np.ndarray, al: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        t = 2.0 * h - profile.depth_at(roll(al))
        return t ** 3 * b / 12.0, t * b

    return section


def _involute_piece(tooth: ToothModel, a1: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                    section: Section | None, young: float, face_width: float,
                    nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """(int M^2/(E I) dx / F^2, int dx / A) over alpha in [lower, upper] of the involute
    cantilever; the section is 2h wide, or ``section(h, alpha)`` gives (I, A) of a faulty
    one."""
    r_b, a2, b, e = tooth.base_radius, tooth.half_base_angle, face_width, young
    xg, wg = _gauss(nodes)
    half = 0.5 * (upper - lower)[..., None]
    al = 0.5 * (upper + lower)[..., None] + half * xg
    phi = a2 - al
    cos_al, sin_al = np.cos(al), np.sin(al)
    h = r_b * (sin_al + phi * cos_al)
    x = r_b * (cos_al - phi * sin_al)
    x_c, h_c = contact_point(tooth, a1)
    cos1, sin1 = np.cos(a1), np.sin(a1)
    if tooth.internal:  # the root lies outside the contact: x > x_c, dx/dalpha > 0
        dx = -r_b * phi * cos_al * half * wg
        arm = cos1[..., None] * (x - x_c[..., None]) - (sin1 * h_c)[..., None]
    else:
        dx = r_b * phi * cos_al * half * wg
        arm = cos1[..., None] * (x_c[..., None] - x) - (sin1 * h_c)[..., None]
    if section is None:
        inertia, area = (2.0 / 3.0) * h ** 3 * b, 2.0 * h * b
    else:
        inertia, area = section(h, al)
    return (np.sum(arm ** 2 / (e * inertia) * dx, axis=-1), np.sum(dx / area, axis=-1))


def profile_roll(tooth: ToothModel, position: float) -> float:
    """The roll angle of the flank point ``position`` [m] along the involute from the reference
    circle (positive towards the tip: outwards on an external tooth, inwards on a ring's); NaN
    below the base circle."""
    toward_tip = -position if tooth.internal else position
    s = 0.5 * tooth.base_radius * tooth.pitch_roll ** 2 + toward_tip
    return math.sqrt(2.0 * s / tooth.base_radius) if s >= 0.0 else math.nan


def spall_rolls(tooth: ToothModel, spall: Spall) -> tuple[float, float]:
    """(t_lo, t_hi): the roll angles of ``spall``'s edges, ascending (the root- and the tip-side
    edge on an external tooth, the other way round on a ring's)."""
    edges = (profile_roll(tooth, spall.position - 0.5 * spall.length),
             profile_roll(tooth, spall.position + 0.5 * spall.length))
    return min(edges), max(edges)


def half_thickness(tooth: ToothModel, alpha: float) -> float:
    """h(alpha) [m] of the involute flank."""
    a2 = tooth.half_base_angle
    return tooth.base_radius * (math.sin(alpha) + (a2 - alpha) * math.cos(alpha))


def roll_alpha(tooth: ToothModel, roll: Any) -> Any:
    """The involute parameter alpha of the flank point at roll angle ``roll``: alpha_2 - t on an
    external tooth, alpha_2 + t on a ring's (the other branch); its own inverse up to the sign
    of alpha_2 (:func:`alpha_roll`)."""
    a2 = tooth.half_base_angle
    return a2 + roll if tooth.internal else a2 - roll


def alpha_roll(tooth: ToothModel, alpha: Any) -> Any:
    """The roll angle of the flank point at involute parameter ``alpha`` (:func:`roll_alpha`'s
    inverse)."""
    a2 = tooth.half_base_angle
    return alpha - a2 if tooth.internal else a2 - alpha


def tip_roll(tooth: ToothModel) -> float:
    """The roll angle of the tooth's tip."""
    return float(alpha_roll(tooth, tooth.tip))


def active_rolls(tooth: ToothModel) -> tuple[float, float]:
    """(lo, hi): the roll angles of the active profile's ends, ascending (from ``start_roll`` to
    the tip on an external tooth; from the tip to ``start_roll``, the deepest contact, on a
    ring's)."""
    ends = (tooth.start_roll, tip_roll(tooth))
    return min(ends), max(ends)


@dataclass(frozen=True)
class WearProfile:
    """The wear depth along the worn flank of a tooth: ``depth_at(t)`` [m] at the flank's
    roll angles t [rad] on its active profile, smooth between the roll angles ``rolls``
    (ascending, from the start of the active profile to the tip)."""

    rolls: tuple[float, ...]
    depth_at: Callable[[np.ndarray], np.ndarray]


def _section_loss(tooth: ToothModel, fault: Spall | Wear, face_width: float,
                  profile: WearProfile | None) -> tuple[list[float], Section]:
    """(breaks, section): the involute parameters (ascending) from where ``fault`` thins the
    sections to where it stops, the section smooth between them, and its (I, A)."""
    def alphas(rolls: Sequence[float]) -> list[float]:
        return sorted(float(roll_alpha(tooth, t)) for t in rolls)

    if isinstance(fault, Spall):
        return (alphas(spall_rolls(tooth, fault)),
                _spall_section(fault.width, fault.depth, face_width))
    if fault.profile == "uniform":  # from the tip to the lowest (deepest) contact
        return (sorted([tooth.tip, float(roll_alpha(tooth, tooth.start_roll))]),
                _wear_section(fault.depth, face_width))
    if profile is None:
        raise ParameterError("wear.profile", fault.profile,
                             "Archard's profile needs the mesh: pass wear_profile="
                             "PotentialEnergyPair.wear_profile(wear)")
    return alphas(profile.rolls), _profile_section(
        profile, lambda al: alpha_roll(tooth, al), face_width)


def _removal(tooth: ToothModel, fault: Spall | Wear, face_width: float,
              profile: WearProfile | None) -> tuple[list[float], float, float, Callable]:
    """(breaks, lo, hi, cut): the involute parameters (ascending) where ``fault``'s section loss
    is not smooth, the range [lo, hi] of alpha it covers, and ``cut(al) -> (w, d)``: the width
    and depth [m] of the rectangle it removes at its flank's face at alpha ``al``."""
    if isinstance(fault, Spall):
        lo, hi = sorted(float(roll_alpha(tooth, t)) for t in spall_rolls(tooth, fault))
        w, d = fault.width, fault.depth
        return [lo, hi], lo, hi, lambda al: (w, np.full(np.shape(al), d))
    breaks, _ = _section_loss(tooth, fault, face_width, profile)
    if fault.profile == "uniform":
        depth = fault.depth
        return breaks, breaks[0], breaks[-1], lambda al: (face_width,
                                                          np.full(np.shape(al), depth))
    return (breaks, breaks[0], breaks[-1],  # type: ignore[union-attr]
            lambda al: (face_width, profile.depth_at(alpha_roll(tooth, al))))


def _two_flank_section(cuts: list[tuple[float, np.ndarray]], b: float, h: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """(I, A) of the 2h x b section less a w x d rectangle at each face, ``cuts`` [(w, d) at
    the drive face, (w, d) at the coast face] (w = 0: nothing cut there), I about the reduced
    section's centroid."""
    (w1, d1), (w2, d2) = cuts
    area = 2.0 * h * b - w1 * d1 - w2 * d2
    arm1, arm2 = h - 0.5 * d1, h - 0.5 * d2  # the rectangles' centres from the centre line
    y_c = (w2 * d2 * arm2 - w1 * d1 * arm1) / area
    inertia = ((2.0 / 3.0) * h ** 3 * b - w1 * d1 ** 3 / 12.0 - w1 * d1 * arm1 ** 2
               - w2 * d2 ** 3 / 12.0 - w2 * d2 * arm2 ** 2 - area * y_c ** 2)
    return inertia, area


def _two_flank_loss(tooth: ToothModel, faults: tuple[Spall | Wear, Spall | Wear],
                    face_width: float, profiles: tuple[WearProfile | None, ...]
                    ) -> tuple[list[float], list[Section | None]]:
    """(breaks, sections): a drive- and a coast-flank fault on one tooth, the involute
    parameters (ascending) between which the section is smooth and, between each two, its
    (I, A), or None where neither fault thins it."""
    removals = [_removal(tooth, f, face_width, p) for f, p in zip(faults, profiles, strict=True)]
    if faults[0].flank == "coast":
        removals = removals[::-1]
    breaks = sorted({x for r in removals for x in r[0]})
    sections: list[Section | None] = []
    for lo, hi in zip(breaks, breaks[1:], strict=False):
        mid = 0.5 * (lo + hi)
        on = [r[1] <= mid <= r[2] for r in removals]
        if not any(on):
            sections.append(None)
            continue

        def section(h: np.ndarray, al: np.ndarray, on: list[bool] = on
                    ) -> tuple[np.ndarray, np.ndarray]:
            cuts = [r[3](al) if r_on else (0.0, np.zeros(np.shape(al)))
                    for r, r_on in zip(removals, on, strict=True)]
            return _two_flank_section(cuts, face_width, h)

        sections.append(section)
    return breaks, sections


def _one_fault(fault: object, crack: object, where: str) -> object:
    """``fault``, or the deprecated ``crack`` keyword's value (one DeprecationWarning)."""
    if crack is None:
        return fault
    if fault is not None:
        raise TypeError(f"{where}: give fault= only (crack= is its deprecated spelling)")
    warn_deprecated(where, ["crack"], ["fault=geardyn.gears.RootCrack(...)"], stacklevel=3)
    return crack


def _piecewise(tooth: ToothModel, a1: np.ndarray, lower: np.ndarray, top: np.ndarray,
               breaks: list[float], sections: list[Section | None], young: float,
               face_width: float, nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_involute_piece` from ``lower`` to ``top``, split at ``breaks`` (clipped to
    that range), ``sections[i]`` between breaks i and i + 1, healthy outside them."""
    cuts = [np.minimum(np.maximum(lower, x), top) for x in breaks]
    bending, inv_area = _involute_piece(tooth, a1, lower, cuts[0], None, young, face_width,
                                        nodes)
    pieces = [(lo, hi, sec) for lo, hi, sec in zip(cuts, cuts[1:], sections, strict=False)]
    for lo, hi, sec in [*pieces, (cuts[-1], top, None)]:
        piece = _involute_piece(tooth, a1, lo, hi, sec, young, face_width, nodes)
        bending, inv_area = bending + piece[0], inv_area + piece[1]
    return bending, inv_area


def tooth_compliances(tooth: ToothModel, alpha1: np.ndarray, *, young: float, poisson: float,
                      face_width: float, nodes: int = DEFAULT_NODES,
                      fault: Fault | tuple[Spall | Wear, Spall | Wear] | None = None,
                      wear_profile: WearProfile | tuple[WearProfile | None, ...] | None = None,
                      crack: RootCrack | None = None) -> dict[str, np.ndarray]:
    """Compliances 1/k_b, 1/k_s, 1/k_a, 1/k_f [m/N] of ``tooth`` loaded at the load angles
    ``alpha1`` [rad] (any shape), by name (:data:`TOOTH_TERMS`), with ``fault`` (its gear and
    tooth index are not looked at here; a fault of zero size is the healthy tooth):

    * :class:`RootCrack`: every section below Tian's crack limit line narrows to h + h_q,
      h_q = h_r - q sin v (h_r: the root section's half thickness), bending arm unchanged; the
      fillet term stays healthy (Chen & Shao 2011). Cracks reaching past the centre line
      (q sin v >= h_r) are refused.
    * :class:`Spall`: the sections whose flank point lies on the spall lose a depth x width
      rectangle at the spalled flank: A = 2hb - w d, I about the reduced section's centroid
      (after Saxena, Parey & Chouksey 2016; Liang, Zhang, Liu & Zuo 2016); bending arm and
      fillet unchanged. The
      contact width (Hertz) is the pair's: see :class:`PotentialEnergyPair`.
    * :class:`Wear`: the sections of the active profile (from ``tooth.start_roll`` to the tip)
      thin to 2h - h_w (Chen, Lei, Fu & Hou 2021), h_w the uniform depth or, for Archard's
      profile, ``wear_profile``'s depth at the section's flank point
      (:meth:`PotentialEnergyPair.wear_profile`); fillet unchanged.

    The symmetric tooth's sections are the same whichever flank a spall or wear is on, and the
    same under either flank's load at the same ``alpha1``: ``fault.flank`` is not looked at
    here.

    ``fault`` may also be a tuple (drive-flank fault, coast-flank fault) of a spall or wear
    on each flank of the tooth (``wear_profile`` then a tuple of their profiles): each section
    loses a rectangle at each face (a spall's w x d, wear's b x h_w) where that fault lies, I
    about the reduced section's centroid.

    ``crack=`` is the deprecated spelling of ``fault=`` for a root crack. A
    :class:`BrokenTooth` has no compliance (refused). A ring's tooth (``tooth.internal``) is
    integrated from alpha = alpha1 to its root circle, takes a root crack (as above, the
    crack limit line running from the crack tip towards the ring's tooth tip), a spall or wear
    (the sections of its flank points, alpha = alpha_2 + t), and its fillet term is 0 (rigid
    ring body)."""
    fault = _one_fault(fault, crack, "tooth_compliances")
    a1 = np.asarray(alpha1, dtype=float)
    if tooth.internal:
        return _ring_compliances(tooth, a1, young=young, poisson=poisson,
                                 face_width=face_width, nodes=nodes, fault=fault,
                                 wear_profile=wear_profile)
    lower = -a1
    if np.any(lower >= tooth.top):
        raise ParameterError(f"{tooth.name}.dedendum", None,
                             "a contact lies at or below the root section of the tooth")
    b, e = face_width, young
    g = young / (2.0 * (1.0 + poisson))
    top = np.full(a1.shape, tooth.top)
    h_q: float | None = None
    if isinstance(fault, BrokenTooth):
        raise ParameterError("fault", fault, "a missing tooth has no compliance")
    if isinstance(fault, tuple):
        if not (len(fault) == 2 and all(isinstance(f, (Spall, Wear)) for f in fault)
                and {f.flank for f in fault} == {"drive", "coast"}):
            raise ParameterError("fault", fault, "a tuple of faults must be a spall or wear on"
                                 " each flank (flank='drive' and flank='coast')")
        breaks, sections = _two_flank_loss(tooth, fault, b, wear_profile or (None, None))
        bending, inv_area = _piecewise(tooth, a1, lower, top, breaks, sections, e, b, nodes)
    elif fault is None or fault.is_null:
        bending, inv_area = _involute_piece(tooth, a1, lower, top, None, e, b, nodes)
    elif isinstance(fault, RootCrack):
        h_r = root_half_thickness(tooth)
        if not fault.reach < h_r:
            raise ParameterError("crack.depth", fault.depth,
                                 f"the crack reaches {fault.reach:.4g} m across the tooth, past"
                                 f" its centre line (root half thickness {h_r:.4g} m)")
        h_q = h_r - fault.reach
        split = np.maximum(lower, crack_limit(tooth, h_q))
        bend_h, area_h = _involute_piece(tooth, a1, lower, split, None, e, b, nodes)
        bend_c, area_c = _involute_piece(tooth, a1, split, top, _crack_section(h_q, b), e, b,
                                         nodes)
        bending, inv_area = bend_h + bend_c, area_h + area_c
    elif isinstance(fault, (Spall, Wear)):
        breaks, section = _section_loss(tooth, fault, b, wear_profile)
        bending, inv_area = _piecewise(tooth, a1, lower, top, breaks,
                                       [section] * (len(breaks) - 1), e, b, nodes)
    else:
        raise ParameterError("fault", fault, "must be a RootCrack, Spall, Wear or None")
    cos1, sin1 = np.cos(a1), np.sin(a1)
    shear = 1.2 * cos1 ** 2 / g * inv_area
    axial = sin1 ** 2 / e * inv_area
    if tooth.segment is not None:
        x_r, x_b, h_b = tooth.segment
        x_c, h_c = contact_point(tooth, a1)
        if h_q is None:
            inertia, area = (2.0 / 3.0) * h_b ** 3 * b, 2.0 * h_b * b
        else:
            inertia, area = (h_b + h_q) ** 3 * b / 12.0, (h_b + h_q) * b
        length = x_b - x_r
        u_r = cos1 * (x_c - x_r) - sin1 * h_c
        u_b = cos1 * (x_c - x_b) - sin1 * h_c
        bending = bending + (u_r ** 3 - u_b ** 3) / (3.0 * cos1 * e * inertia)
        shear = shear + 1.2 * cos1 ** 2 * length / (g * area)
        axial = axial + sin1 ** 2 * length / (e * area)
    return {"bending": bending, "shear": shear, "axial": axial,
            "fillet": fillet_compliance(tooth, a1, young=young, face_width=face_width)}


def _ring_compliances(tooth: ToothModel, a1: np.ndarray, *, young: float, poisson: float,
                      face_width: float, nodes: int, fault: Fault | tuple | None,
                      wear_profile: Any = None) -> dict[str, np.ndarray]:
    """:func:`tooth_compliances` of a ring's tooth: healthy, or with a :class:`RootCrack`
    (Tian's crack limit line from the crack tip towards the tip; sections towards the root
    beyond it h + h_q thick), or a :class:`Spall` or :class:`Wear` (or one on each flank):
    the sections under it thinned as on an external tooth, integrated from the contact out to
    the root circle."""
    crack = isinstance(fault, RootCrack) and not fault.is_null
    if isinstance(fault, BrokenTooth):
        raise ParameterError("fault", fault, "a missing tooth has no compliance")
    if np.any(a1 >= tooth.top):
        raise ParameterError(f"{tooth.name}.dedendum", None,
                             "a contact lies at or beyond the root circle of the ring's tooth")
    g = young / (2.0 * (1.0 + poisson))
    top = np.full(a1.shape, tooth.top)
    if isinstance(fault, tuple) or (isinstance(fault, (Spall, Wear)) and not fault.is_null):
        if isinstance(fault, tuple):
            breaks, sections = _two_flank_loss(tooth, fault, face_width,
                                               wear_profile or (None, None))
        else:
            breaks, section = _section_loss(tooth, fault, face_width, wear_profile)
            sections = [section] * (len(breaks) - 1)
        bending, inv_area = _piecewise(tooth, a1, a1, top, breaks, sections, young,
                                       face_width, nodes)
    elif crack:
        _check_crack(fault, tooth)  # type: ignore[arg-type]
        h_q = root_half_thickness(tooth) - fault.reach  # type: ignore[union-attr]
        split = np.maximum(a1, crack_limit(tooth, h_q))
        bend_h, area_h = _involute_piece(tooth, a1, a1, split, None, young, face_width, nodes)
        bend_c, area_c = _involute_piece(tooth, a1, split, top, _crack_section(h_q, face_width),
                                         young, face_width, nodes)
        bending, inv_area = bend_h + bend_c, area_h + area_c
    else:
        bending, inv_area = _involute_piece(tooth, a1, a1, top, None, young, face_width, nodes)
    cos1, sin1 = np.cos(a1), np.sin(a1)
    return {"bending": bending, "shear": 1.2 * cos1 ** 2 / g * inv_area,
            "axial": sin1 ** 2 / young * inv_area,
            "fillet": fillet_compliance(tooth, a1, young=young, face_width=face_width)}


def fillet_compliance(tooth: ToothModel, alpha1: np.ndarray, *, young: float,
                      face_width: float) -> np.ndarray:
    """Sainsot's fillet-foundation compliance 1/k_f [m/N] at the load angles ``alpha1``; 0 on a
    ring's tooth (rigid ring body)."""
    a1 = np.asarray(alpha1, dtype=float)
    if tooth.internal:
        return np.zeros(a1.shape)
    x_c, h_c = contact_point(tooth, a1)
    u_f = x_c - h_c * np.tan(a1) - tooth.root_radius
    s_f = 2.0 * tooth.root_radius * tooth.theta_f
    ratio = u_f / s_f
    lf, mf, pf, qf = tooth.fillet
    return (np.cos(a1) ** 2 / (young * face_width)
            * (lf * ratio ** 2 + mf * ratio + pf * (1.0 + qf * np.tan(a1) ** 2)))


def hertz_stiffness(young: float, poisson: float, face_width: float) -> float:
    """k_h = pi E b / (4 (1 - nu^2)) [N/m] (Yang & Lin 1987, equal materials)."""
    return math.pi * young * face_width / (4.0 * (1.0 - poisson ** 2))


@dataclass(frozen=True)
class PotentialEnergyPair:
    """A spur mesh prepared for the potential-energy method: both teeth, material, width and
    the ``faults`` (each on its own tooth; zero-size ones included)."""

    mesh: GearMesh
    pinion: ToothModel
    wheel: ToothModel
    young: float
    poisson: float
    face_width: float
    nodes: int
    faults: tuple[Fault, ...] = ()
    wear_profiles: tuple[tuple[Wear, WearProfile], ...] = ()

    @property
    def hertz(self) -> float:
        """k_h [N/m]."""
        return hertz_stiffness(self.young, self.poisson, self.face_width)

    def load_angles(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """alpha_1 [rad] of pinion and wheel tooth for contacts at ``position`` [m] along the
        line of action from the pitch point (positive towards the pinion's tip)."""
        mesh = self.mesh
        s1 = self.pinion.base_radius * math.tan(mesh.operating_pressure_angle) + position
        a_p = s1 / self.pinion.base_radius - self.pinion.half_base_angle
        if mesh.internal:  # the ring's tangent point lies beyond the pinion's, on the same side
            s2 = self.wheel.base_radius * math.tan(mesh.operating_pressure_angle) + position
            return a_p, s2 / self.wheel.base_radius + self.wheel.half_base_angle
        s2 = mesh.line_of_action_length - s1
        return (a_p, s2 / self.wheel.base_radius - self.wheel.half_base_angle)

    def _flank(self, gear: str) -> tuple[Callable, Callable]:
        """(position of roll, roll of position): the line-of-action position s [m] of the contact
        at roll angle t of ``gear``'s drive flank, and back."""
        mesh = self.mesh
        s_p = mesh.pinion.base_radius * math.tan(mesh.operating_pressure_angle)
        if gear == "pinion":
            r_b = mesh.pinion.base_radius
            return (lambda t: r_b * t - s_p), (lambda s: (s + s_p) / r_b)
        r_b, length = mesh.wheel.base_radius, mesh.line_of_action_length
        if mesh.internal:
            s_w = r_b * math.tan(mesh.operating_pressure_angle)
            return (lambda t: r_b * t - s_w), (lambda s: (s + s_w) / r_b)
        return (lambda t: length - s_p - r_b * t), (lambda s: (length - s_p - s) / r_b)

    def archard_rate(self, gear: str, position: np.ndarray) -> np.ndarray:
        """Archard's wear per mesh passage of ``gear``'s flank point in contact at ``position``
        [m], up to the wear coefficient over the face width: the load share q = k / sum k of the
        healthy pairs in contact (equal approach) times the slip abs(v_1 - v_2) / v of the point
        (v = omega rho, rho the radius of curvature, the distance from the gear's tangent point
        on the line of action). Archard (1953): wear depth = k_w x pressure x sliding distance;
        Flodin & Andersson (1997) integrate it along spur flanks in the same way."""
        mesh = self.mesh
        s = np.asarray(position, dtype=float)
        p_b, g_f, g_a = mesh.base_pitch, mesh.approach_length, mesh.recess_length
        k = self.terms(s)["pair"]
        total = k.copy()
        for m in (-2, -1, 1, 2):
            other = s + m * p_b
            inside = (other >= -g_f) & (other < g_a)
            if inside.any():
                total[inside] += self.terms(other[inside])["pair"]
        rho1 = mesh.pinion.base_radius * math.tan(mesh.operating_pressure_angle) + s
        rho2 = (mesh.wheel.base_radius * math.tan(mesh.operating_pressure_angle) + s
                if mesh.internal else mesh.line_of_action_length - rho1)
        ratio = mesh.pinion.teeth / mesh.wheel.teeth  # omega_2 / omega_1
        slip = (np.abs(1.0 - ratio * rho2 / rho1) if gear == "pinion"
                else np.abs(1.0 - rho1 / (ratio * rho2)))
        return k / total * slip

    def wear_profile(self, wear: Wear) -> WearProfile:
        """The depth of ``wear`` along its flank (module docstring of
        :mod:`geardyn.gears.faults`): uniform, or Archard's h(t) = depth r(s(t)) / max r,
        r = :meth:`archard_rate` (one wear step on the healthy mesh), its maximum taken over 129
        points of each smooth stretch of the path of contact (ends included). Within each
        stretch (between the path's ends, the single-contact ends and the pitch point) r is
        smooth and is evaluated by its Chebyshev interpolant of degree
        :data:`ARCHARD_DEGREE` in the roll angle."""
        tooth = self.pinion if wear.gear == "pinion" else self.wheel
        depth = wear.depth
        if wear.profile == "uniform":
            return WearProfile(active_rolls(tooth), lambda t: np.full(np.shape(t), depth))
        mesh = self.mesh
        p_b, g_f, g_a = mesh.base_pitch, mesh.approach_length, mesh.recess_length
        at, roll = self._flank(wear.gear)
        ends = sorted({-g_f, g_a - p_b, 0.0, p_b - g_f, g_a})
        ends = [x for x in ends if -g_f <= x <= g_a]
        nudge = 1e-9 * p_b  # the one-sided limits at the ends of each stretch
        grid = np.concatenate([np.linspace(lo + nudge, hi - nudge, 129)
                               for lo, hi in zip(ends, ends[1:], strict=False)])
        scale = depth / float(np.max(self.archard_rate(wear.gear, grid)))
        rolls = tuple(sorted(float(roll(x)) for x in ends))
        gear = wear.gear
        pieces = []
        for lo, hi in zip(rolls, rolls[1:], strict=False):
            mid, half = 0.5 * (hi + lo), 0.5 * (hi - lo)

            def rate(x: np.ndarray, mid: float = mid, half: float = half) -> np.ndarray:
                return scale * self.archard_rate(gear, at(mid + half * x))

            pieces.append((mid, half, np.polynomial.chebyshev.chebinterpolate(
                rate, ARCHARD_DEGREE)))
        return WearProfile(rolls, _piecewise_depth(rolls, pieces))

    def archard_rolls(self, gear: str) -> tuple[float, ...]:
        """The roll angles [rad] of ``gear``'s flank, ascending, between which
        :meth:`archard_rate` is smooth: the contacts at the path's ends, the single-contact
        ends and the pitch point."""
        mesh = self.mesh
        p_b, g_f, g_a = mesh.base_pitch, mesh.approach_length, mesh.recess_length
        roll = self._flank(gear)[1]
        ends = [x for x in sorted({-g_f, g_a - p_b, 0.0, p_b - g_f, g_a}) if -g_f <= x <= g_a]
        return tuple(sorted(float(roll(x)) for x in ends))

    def profile_of(self, fault: Fault | tuple | None
                   ) -> WearProfile | tuple[WearProfile | None, ...] | None:
        """The :class:`WearProfile` of a :class:`Wear` of this pair's ``faults``, else None (a
        tuple of faults on one tooth: a tuple of theirs)."""
        if isinstance(fault, tuple):
            return tuple(self.profile_of(f) for f in fault)  # type: ignore[misc]
        for wear, profile in self.wear_profiles:
            if wear is fault:
                return profile
        return None

    def _lost_width(self, tooth: ToothModel, fault: Fault | tuple | None, a1: np.ndarray,
                    flank: str) -> np.ndarray | None:
        """The face width [m] a spall takes from contacts at load angles ``a1`` on ``flank``
        (0 off the spall), or None without a spall on that flank (``fault``: one fault, or the
        faults on the tooth's two flanks)."""
        if isinstance(fault, tuple):
            fault = next((f for f in fault if f.flank == flank), None)
        if not isinstance(fault, Spall) or fault.is_null or fault.flank != flank:
            return None
        t_lo, t_hi = spall_rolls(tooth, fault)
        roll = a1 - tooth.half_base_angle if tooth.internal else a1 + tooth.half_base_angle
        return np.where((roll >= t_lo) & (roll <= t_hi), fault.width, 0.0)

    def terms(self, position: np.ndarray, pinion: Fault | tuple | None = None,
              wheel: Fault | tuple | None = None, *, coast: bool = False
              ) -> dict[str, np.ndarray]:
        """Stiffness [N/m] of each energy term (``hertz``, ``bending_pinion``, ...,
        ``fillet_wheel``) and of the pair (``pair``) for contacts at ``position`` [m] between a
        pinion tooth with the fault ``pinion`` and a wheel tooth with ``wheel`` (None:
        healthy; a tuple: a drive- and a coast-flank fault on that tooth). ``coast``: the
        contacts are on the coast flanks (``position`` on the coast line of action, the same
        load angles as on the drive flank there). A spall on the loaded flank (``flank``
        "drive", or "coast" with ``coast``) narrows the Hertz contact to b - w where the
        contact lies on it (Chaari, Baccar, Abbes & Haddar 2008; the wider spall where both
        teeth have one there); a spall on the other flank only thins the sections. A ring's
        ``fillet_wheel`` is inf (rigid ring body)."""
        pos = np.asarray(position, dtype=float)
        a_p, a_w = self.load_angles(pos)
        kw = dict(young=self.young, poisson=self.poisson, face_width=self.face_width,
                  nodes=self.nodes)
        out = {"hertz": np.full(pos.shape, self.hertz)}
        flank = "coast" if coast else "drive"
        lost = [w for w in (self._lost_width(self.pinion, pinion, a_p, flank),
                            self._lost_width(self.wheel, wheel, a_w, flank)) if w is not None]
        if lost:
            width = self.face_width - np.maximum.reduce(lost)
            out["hertz"] = np.where(width < self.face_width,
                                    hertz_stiffness(self.young, self.poisson, width),
                                    self.hertz)
        compliance = 1.0 / out["hertz"]
        for role, tooth, a1, fault in (("pinion", self.pinion, a_p, pinion),
                                       ("wheel", self.wheel, a_w, wheel)):
            comp = tooth_compliances(tooth, a1, fault=fault, wear_profile=self.profile_of(fault),
                                     **kw)
            for term, c in comp.items():
                rigid = tooth.internal and term == "fillet"  # the ring body: c = 0
                out[f"{term}_{role}"] = np.full(c.shape, np.inf) if rigid else 1.0 / c
                compliance = compliance + c
        out["pair"] = 1.0 / compliance
        return out


def _piecewise_depth(rolls: Sequence[float], pieces: Sequence[tuple[float, float, np.ndarray]]
                     ) -> Callable[[np.ndarray], np.ndarray]:
    """depth_at(t) of a :class:`WearProfile`: on each stretch between the ``rolls`` its
    Chebyshev series (mid, half, coefficients) in (t - mid) / half."""
    inner = np.array(rolls[1:-1])

    def depth_at(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        which = np.searchsorted(inner, t, side="right")
        out = np.zeros(t.shape)
        for i, (mid, half, coef) in enumerate(pieces):
            mask = which == i
            if mask.any():
                out[mask] = np.polynomial.chebyshev.chebval((t[mask] - mid) / half, coef)
        return out

    return depth_at


def combined_wear_profile(parts: Sequence[tuple[PotentialEnergyPair, str, float]],
                          depth: float) -> WearProfile:
    """Archard's depth along the flank of one gear's tooth that several meshes wear, ``parts``
    (pair, gear, w): the gear is ``gear`` ("pinion" or "wheel") of each ``pair`` and w >= 0
    the weight of that mesh's wear (its load on the flank per unit face width: a passage wears
    k_w F / b r). h(t) = depth R(t) / max R at the flank's roll angle t [rad], R(t) = sum of
    w r(t) over the parts whose path of contact reaches t, r = the pair's
    :meth:`~PotentialEnergyPair.archard_rate` (one passage of the tooth through each mesh: the
    wear of one revolution of the gear). The stretches lie between all the parts'
    :meth:`~PotentialEnergyPair.archard_rolls` (those closer than 1e-9 of the whole span
    merged): the maximum over 129 points of each (its ends nudged in), each interpolated by
    its Chebyshev series of degree :data:`ARCHARD_DEGREE`, as
    :meth:`~PotentialEnergyPair.wear_profile`."""
    own = [(pair, gear, float(w), pair.archard_rolls(gear), pair._flank(gear)[0])
           for pair, gear, w in parts]
    breaks = sorted(t for *_, rolls, _ in own for t in rolls)
    span = breaks[-1] - breaks[0]
    rolls = [breaks[0]]
    for t in breaks[1:]:
        if t - rolls[-1] > 1e-9 * span:
            rolls.append(t)
    stretches = list(zip(rolls, rolls[1:], strict=False))

    def rate_on(lo: float, hi: float) -> Callable[[np.ndarray], np.ndarray]:
        mid = 0.5 * (lo + hi)
        live = [(pair, gear, w, at) for pair, gear, w, r, at in own
                if w > 0.0 and r[0] < mid < r[-1]]

        def rate(t: np.ndarray) -> np.ndarray:
            out = np.zeros(np.shape(t))
            for pair, gear, w, at in live:
                out = out + w * pair.archard_rate(gear, at(t))
            return out

        return rate

    nudge = 1e-9 * span
    peak = max(float(np.max(rate_on(lo, hi)(np.linspace(lo + nudge, hi - nudge, 129))))
               for lo, hi in stretches)
    if not peak > 0.0:
        raise ParameterError("wear.flank", peak, "no mesh wears the flank (every weight 0)")
    scale = depth / peak
    pieces = []
    for lo, hi in stretches:
        mid, half, rate = 0.5 * (hi + lo), 0.5 * (hi - lo), rate_on(lo, hi)

        def scaled(x: np.ndarray, mid: float = mid, half: float = half,
                   rate: Callable = rate) -> np.ndarray:
            return scale * rate(mid + half * x)

        pieces.append((mid, half, np.polynomial.chebyshev.chebinterpolate(scaled,
                                                                          ARCHARD_DEGREE)))
    return WearProfile(tuple(rolls), _piecewise_depth(rolls, pieces))


def _bores(bore_radius: object) -> tuple[object, object]:
    if isinstance(bore_radius, str) or not isinstance(bore_radius, Sequence):
        return bore_radius, bore_radius
    if len(bore_radius) != 2:
        raise ParameterError("bore_radius", bore_radius,
                             "give one radius or two (pinion, wheel)")
    return bore_radius[0], bore_radius[1]


def _fault_tuple(faults: object, crack: object, where: str) -> tuple[object, ...]:
    """``faults`` (one fault or a sequence) as a tuple, with the deprecated ``crack`` keyword's
    value (one DeprecationWarning pointing at the public function's caller)."""
    if faults is None:
        out: tuple[object, ...] = ()
    elif isinstance(faults, Sequence) and not isinstance(faults, str):
        out = tuple(faults)
    else:
        out = (faults,)
    if crack is None:
        return out
    if out:
        raise TypeError(f"{where}: give the faults as faults=(...) only (crack= is the"
                        " deprecated spelling of one root crack)")
    warn_deprecated(where, ["crack"], ["faults=(geardyn.gears.RootCrack(...),)"], stacklevel=3)
    return (crack,)


def prepare_pair(mesh: GearMesh, *, bore_radius: object, young: object = STEEL_YOUNG,
                 poisson: object = STEEL_POISSON, root_segment: bool = True,
                 nodes: int = DEFAULT_NODES, faults: object = (),
                 crack: RootCrack | None = None,
                 ring_foundation: str = "rigid",
                 wear_profiles: Mapping[Wear, WearProfile] | None = None
                 ) -> PotentialEnergyPair:
    """Validate the inputs of :func:`potential_energy_stiffness` and build both teeth (their
    ``start_roll`` at the mesh's lowest contacts). ``crack=`` is the deprecated spelling of
    ``faults=(crack,)``. ``wear_profiles``: the depth along the flank of Archard
    :class:`Wear` faults of ``faults`` (keys equal to them) in place of this mesh's own
    (:meth:`PotentialEnergyPair.wear_profile`): the wear of a gear that several meshes wear
    (:func:`combined_wear_profile`)."""
    fault_list = _fault_tuple(faults, crack, "prepare_pair")
    e = si_value("young", young, "pressure", 0.0, strict=True)
    try:
        nu = to_si(poisson, "dimensionless")
    except ValueError as exc:
        raise ParameterError("poisson", poisson, str(exc)) from None
    if not 0.0 <= nu < 0.5:
        raise ParameterError("poisson", poisson, "must lie in [0, 0.5)")
    if isinstance(nodes, bool) or not isinstance(nodes, numbers.Integral) or not nodes >= 4:
        raise ParameterError("nodes", nodes, "must be a whole number >= 4")
    bp, bw = _bores(bore_radius)
    teeth = []
    for role, gear, bore in (("pinion", mesh.pinion, bp), ("wheel", mesh.wheel, bw)):
        r = si_value(f"{role}.bore_radius", bore, "length", 0.0, strict=True)
        teeth.append(tooth_model(gear, r, root_segment=root_segment, role=role,
                                 ring_foundation=ring_foundation))
    # the lowest contacts: the pinion's at the start of the path, the wheel's at its end
    s1 = mesh.pinion.base_radius * math.tan(mesh.operating_pressure_angle)
    if mesh.internal:  # the ring's deepest contact (nearest its root) at the end of the path
        s2 = mesh.wheel.base_radius * math.tan(mesh.operating_pressure_angle)
        wheel_start = (s2 + mesh.recess_length) / mesh.wheel.base_radius
    else:
        wheel_start = ((mesh.line_of_action_length - s1 - mesh.recess_length)
                       / mesh.wheel.base_radius)
    starts = ((s1 - mesh.approach_length) / mesh.pinion.base_radius, wheel_start)
    teeth = [replace(t, start_roll=max(start, 0.0)) for t, start in zip(teeth, starts,
                                                                         strict=True)]
    width = min(mesh.pinion.face_width, mesh.wheel.face_width)
    _check_faults(fault_list, mesh, teeth, width)
    pair = PotentialEnergyPair(mesh=mesh, pinion=teeth[0], wheel=teeth[1], young=e,
                               poisson=nu, face_width=width, nodes=int(nodes),
                               faults=fault_list)  # type: ignore[arg-type]
    wears = [f for f in fault_list if isinstance(f, Wear)]
    given = dict(wear_profiles or {})
    for wear, profile in given.items():
        if not (isinstance(wear, Wear) and wear.profile == "archard" and wear in wears
                and isinstance(profile, WearProfile)):
            raise ParameterError("wear_profiles", wear, "must map Archard Wear faults of "
                                 "faults to their WearProfile")
    if not wears:
        return pair
    return replace(pair, wear_profiles=tuple(
        (w, given[w] if w in given else pair.wear_profile(w)) for w in wears))


def _check_faults(faults: tuple[object, ...], mesh: GearMesh, teeth: list[ToothModel],
                  width: float) -> None:
    """Each fault a fault object, on a tooth that exists, one fault a tooth (or a spall or
    wear on each flank), and fitting its tooth (errors name the fault's field)."""
    seen: dict[tuple[str, int], object] = {}
    for fault in faults:
        if not isinstance(fault, (RootCrack, Spall, Wear, BrokenTooth)):
            raise ParameterError("faults", fault,
                                 "must be RootCrack, Spall, Wear or BrokenTooth objects")
        kind = fault.kind
        if fault.gear not in ("pinion", "wheel"):
            raise ParameterError(f"{kind}.gear", fault.gear, "a pair's faults lie on the "
                                 "'pinion' or the 'wheel' (sun, ring and planets: "
                                 "PlanetaryGearSet.from_geometry)")
        z = (mesh.pinion if fault.gear == "pinion" else mesh.wheel).teeth
        if not 0 <= fault.tooth < z:
            raise ParameterError(f"{kind}.tooth", fault.tooth, f"must lie in [0, {z - 1}]")
        key = (fault.gear, fault.tooth)
        if key in seen:
            _second_fault(fault, seen[key])
            seen[key] = (seen[key], fault)
        else:
            seen[key] = fault
        tooth = teeth[0] if fault.gear == "pinion" else teeth[1]
        if isinstance(fault, RootCrack):
            _check_crack(fault, tooth)
        elif isinstance(fault, Spall):
            _check_spall(fault, tooth, width)
        elif isinstance(fault, Wear):
            h_tip = half_thickness(tooth, tooth.tip)
            if not fault.depth < h_tip:
                raise ParameterError("wear.depth", fault.depth,
                                     f"must be less than the half thickness at the tip,"
                                     f" {h_tip:.4g} m")


def _second_fault(fault: object, first: object) -> None:
    """Refuse ``fault`` on a tooth that already has ``first`` unless they are a spall or wear
    on each flank (error ``faults``)."""
    flank_faults = (Spall, Wear)
    if (isinstance(fault, flank_faults) and isinstance(first, flank_faults)
            and fault.flank != first.flank):
        return
    where = f"{getattr(fault, 'gear', '?')} tooth {getattr(fault, 'tooth', '?')}"
    raise ParameterError("faults", fault, f"{where} already has {first!r}: one fault a tooth,"
                         " or a spall or wear on each of its two flanks (flank='drive' and"
                         " flank='coast')")


def _check_crack(crack: RootCrack, tooth: ToothModel) -> None:
    h_r = root_half_thickness(tooth)
    if not crack.reach < h_r:
        raise ParameterError("crack.depth", crack.depth,
                             f"the crack reaches {crack.reach:.4g} m across the tooth, past its"
                             f" centre line (root half thickness {h_r:.4g} m)")


def _check_spall(spall: Spall, tooth: ToothModel, width: float) -> None:
    """The spall narrower than the face and on the active profile, its depth short of the
    centre line."""
    if not spall.width < width:
        raise ParameterError("spall.width", spall.width,
                             f"must be less than the face width {width:.6g} m")
    r_b = tooth.base_radius
    t_start, t_end = active_rolls(tooth)
    sign = -1.0 if tooth.internal else 1.0  # towards the tip: inwards on a ring's tooth

    def along(t: float) -> float:  # from the reference circle along the involute [m]
        return sign * 0.5 * r_b * (t * t - tooth.pitch_roll ** 2)

    lo, hi = sorted((along(t_start), along(t_end)))
    active = f"[{lo:.6g}, {hi:.6g}] m from the reference circle"
    if not lo <= spall.position <= hi:
        raise ParameterError("spall.position", spall.position,
                             f"off the active flank of {tooth.name}: the active profile lies"
                             f" {active}")
    t_lo, t_hi = spall_rolls(tooth, spall)
    if not (t_lo >= t_start * (1.0 - 1e-12) and t_hi <= t_end * (1.0 + 1e-12)):
        raise ParameterError("spall.length", spall.length,
                             f"the spall reaches off the active flank of {tooth.name}: the"
                             f" active profile lies {active}")
    tip_side = t_lo if tooth.internal else t_hi
    h_min = half_thickness(tooth, float(roll_alpha(tooth, tip_side)))
    if not spall.depth < h_min:
        raise ParameterError("spall.depth", spall.depth,
                             f"must be less than the half thickness {h_min:.4g} m at the"
                             " spall's tip-side edge")


def _cycle_grid(mesh: GearMesh, angles: object,
                cycles: object) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mesh cycles, whole cycles n, fraction of the cycle) of the pinion angles: ``angles``
    points per mesh cycle over ``cycles`` mesh cycles (the fractions of every cycle the same
    floats), or the given angles [deg]."""
    if isinstance(cycles, bool) or not isinstance(cycles, numbers.Integral) or cycles < 1:
        raise ParameterError("cycles", cycles, "must be a whole number >= 1")
    if isinstance(angles, numbers.Integral) and not isinstance(angles, bool):
        if angles < 1:
            raise ParameterError("angles", angles, "must be >= 1 points per mesh cycle")
        i = np.arange(int(angles) * int(cycles))
        whole, frac = (i // int(angles)).astype(float), (i % int(angles)) / int(angles)
        return whole + frac, whole, frac
    try:
        grid = np.asarray(angles, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError("angles", angles, "give a number of points or angles in deg")\
            from None
    if grid.size == 0 or not np.all(np.isfinite(grid)):
        raise ParameterError("angles", angles, "must be finite pinion angles in deg")
    cyc = grid * mesh.pinion.teeth / 360.0
    whole = np.floor(cyc)
    return cyc, whole, cyc - whole


def _units(name: str) -> str:
    unitless = ("pairs_in_contact", "in_contact", "tooth_pinion", "tooth_wheel")
    return "" if name.removesuffix("_coast") in unitless else "N/m"


def coast_phase(mesh: GearMesh) -> float:
    """phi [mesh cycles]: the pinion rotation, in mesh cycles, from the passage of a pinion
    tooth's drive flank through the pitch point to that of its coast flank, s_w1 / p_w1 (the
    tooth thickness over the pitch on the operating pitch circle; 1/2 for unshifted teeth at
    the zero-backlash centre distance)."""
    r_w1 = mesh.operating_pitch_radii[0]
    return mesh.pinion.angular_thickness(r_w1) * mesh.pinion.teeth / (2.0 * math.pi)


def _tooth_faults(pair: PotentialEnergyPair) -> list[tuple[str, int, Fault | tuple]]:
    """(gear, tooth, fault) of each faulty tooth in the order of ``pair.faults``, zero-size
    faults and missing teeth left out; a tooth with a fault on each flank holds the tuple
    (drive fault, coast fault)."""
    found: dict[tuple[str, int], list] = {}
    for fault in pair.faults:
        if not isinstance(fault, BrokenTooth) and not fault.is_null:
            found.setdefault((fault.gear, fault.tooth), []).append(fault)
    out = []
    for (gear, tooth), faults in found.items():
        if len(faults) == 1:
            out.append((gear, tooth, faults[0]))
        else:
            out.append((gear, tooth, tuple(sorted(faults, key=lambda f: f.flank != "drive"))))
    return out


def _fault_codes(pair: PotentialEnergyPair, tooth_p: np.ndarray,
                 tooth_w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pair slot: the index into :func:`_tooth_faults` of the pinion and the wheel tooth's
    fault (-1: none, or of zero size), and whether either tooth is missing."""
    mesh = pair.mesh
    luts = {"pinion": np.full(mesh.pinion.teeth, -1), "wheel": np.full(mesh.wheel.teeth, -1)}
    gone = {"pinion": np.zeros(mesh.pinion.teeth, bool),
            "wheel": np.zeros(mesh.wheel.teeth, bool)}
    for fault in pair.faults:
        if isinstance(fault, BrokenTooth):
            gone[fault.gear][fault.tooth] = True
    for i, (gear, tooth, _) in enumerate(_tooth_faults(pair)):
        luts[gear][tooth] = i
    return (luts["pinion"][tooth_p], luts["wheel"][tooth_w],
            gone["pinion"][tooth_p] | gone["wheel"][tooth_w])


def _wear_gap(pair: PotentialEnergyPair, position: np.ndarray, inside: np.ndarray,
              tooth_p: np.ndarray, tooth_w: np.ndarray, *, coast: bool = False) -> np.ndarray:
    """The gap [m] the worn teeth open at the drive (``coast``: coast) contacts ``inside`` (0
    elsewhere): the wear depth at each contact's point of the worn flank, both teeth's added;
    only wear on the flank of the contacts opens one."""
    gap = np.zeros(position.shape)
    flank = "coast" if coast else "drive"
    for wear, profile in pair.wear_profiles:
        if wear.is_null or wear.flank != flank:
            continue
        mask = inside & ((tooth_p if wear.gear == "pinion" else tooth_w) == wear.tooth)
        if mask.any():
            where, inverse = np.unique(position[mask], return_inverse=True)
            gap[mask] += profile.depth_at(pair._flank(wear.gear)[1](where))[inverse]
    return gap


def _coast(pair: PotentialEnergyPair, n: np.ndarray,
           frac: np.ndarray) -> tuple[dict[str, tuple], np.ndarray]:
    """The coast-flank variables (``*_coast``) over the grid, and the coast pair indices.

    Coast pair k' holds the pinion tooth whose coast flank passed the pitch point k' mesh cycles
    before the start of cycle n, (n - k') mod z1, against wheel tooth (n - k' + 1) mod z2 (the
    wheel tooth behind it); its contact lies (phi - frac - k') p_b from the pitch point towards
    the pinion tip on the coast line of action and moves towards the pinion root. A pair is in
    contact from the end of the path (included) to its start (excluded), unless one of its
    teeth is missing."""
    mesh = pair.mesh
    p_b, phi = mesh.base_pitch, coast_phase(mesh)
    start, end = -mesh.approach_length / p_b, mesh.recess_length / p_b
    ks = np.arange(math.floor(phi - end), math.ceil(phi - start) + 1)
    u = phi - frac[:, None] - ks[None, :]
    inside = (u > start) & (u <= end)
    position = u * p_b
    passage = n.astype(np.int64)[:, None] - ks[None, :]
    tooth_p, tooth_w = passage % mesh.pinion.teeth, (passage + 1) % mesh.wheel.teeth
    fp, fw, gone = _fault_codes(pair, tooth_p, tooth_w)
    inside &= ~gone
    k_pair = np.where(inside, _terms_on_grid(pair, position, inside, fp, fw, coast=True)["pair"],
                      0.0)
    gap = _wear_gap(pair, position, inside, tooth_p, tooth_w, coast=True)
    dims = ("angle", "pair_coast")
    return {"mesh_stiffness_coast": (("angle",), k_pair.sum(axis=1)),
            "pairs_in_contact_coast": (("angle",), inside.sum(axis=1)),
            "in_contact_coast": (dims, inside), "position_coast": (dims, position),
            "tooth_pinion_coast": (dims, tooth_p), "tooth_wheel_coast": (dims, tooth_w),
            "pair_stiffness_coast": (dims, k_pair), "fault_gap_coast": (dims, gap)}, ks


def potential_energy_stiffness(mesh: GearMesh, *, bore_radius: object, angles: object = 360,
                               young: object = STEEL_YOUNG, poisson: object = STEEL_POISSON,
                               root_segment: bool = True, nodes: int = DEFAULT_NODES,
                               faults: object = (), cycles: int = 1,
                               crack: RootCrack | None = None,
                               ring_foundation: str = "rigid",
                               wear_profiles: Mapping[Wear, WearProfile] | None = None
                               ) -> xr.Dataset:
    """Mesh stiffness of the spur ``mesh`` (external, or a pinion in a ring) over pinion angles
    by the potential-energy method (module docstring): a Dataset over ``angle`` (pinion
    rotation [deg]; an int ``angles`` is that many points per mesh cycle, 360/z1 deg, over
    ``cycles`` mesh cycles from the passage of pinion tooth 0 and wheel tooth 0 through the
    pitch point; or give the angles)
    with coordinates ``cycle`` (mesh cycles) and ``pair`` (pair k passes the pitch point k mesh
    cycles before the start of the current cycle n = floor(cycle): its contact lies
    (cycle - n + k) p_b beyond the pitch point, between pinion tooth (n - k) mod z1 and wheel
    tooth (n - k) mod z2: variables ``tooth_pinion``, ``tooth_wheel``).

    Variables: ``mesh_stiffness`` [N/m], ``pairs_in_contact``; per pair ``in_contact``,
    ``position`` (along the line of action from the pitch point [m]), ``pair_stiffness`` [N/m]
    (0 out of contact), ``fault_gap`` [m] (the gap the teeth's wear opens, 0 without) and each
    energy term's stiffness ``k_hertz``, ``k_bending_pinion``, ... ``k_fillet_wheel`` [N/m]
    (NaN out of contact). A pair is in contact from the start of the path of contact (included)
    to its end (excluded), unless one of its teeth is missing. ``bore_radius`` [m]: one radius
    or (pinion, wheel); ``young`` [Pa], ``poisson``; ``nodes``: Gauss-Legendre nodes.
    ``faults``: one fault or a sequence (:class:`RootCrack`, :class:`Spall`, :class:`Wear`,
    :class:`BrokenTooth`), each on its own tooth, or a spall or wear on each flank of one
    (see :func:`tooth_compliances` and :class:`PotentialEnergyPair`); a pinion tooth returns
    every z1 mesh cycles, a wheel tooth every z2 (the hunting period: lcm(z1, z2) cycles).
    ``crack=`` is the deprecated spelling of ``faults=(crack,)``.

    The coast flank: ``mesh_stiffness_coast`` [N/m], ``pairs_in_contact_coast`` and per coast
    pair (dimension ``pair_coast``) ``in_contact_coast``, ``position_coast`` [m] (on the coast
    line of action from the pitch point, positive towards the pinion tip),
    ``tooth_pinion_coast``, ``tooth_wheel_coast``, ``pair_stiffness_coast`` [N/m],
    ``fault_gap_coast`` [m], at the same pinion angles with the pinion turned onto its coast
    flanks (see ``_coast``); attrs ``coast_phase_cycles`` (phi), ``backlash_m`` and
    ``backlash_cycles`` (j / p_w1, the dead zone between the flanks). A crack (at the drive
    flank's root, faces taken open), a spall or wear thins the tooth's sections under either
    flank's load; a spall's contact-width loss and wear's gap act on the contacts of its own
    ``flank`` ("drive" or "coast") only; a missing tooth carries on neither.

    An internal ``mesh`` (``mesh.internal``): the wheel is the ring, its terms (``*_wheel``)
    the ring tooth's (:func:`ring_tooth_model`); ``bore_radius``'s second value is the ring's
    outer (rim) radius; ``ring_foundation`` (:data:`RING_FOUNDATIONS`) treats the ring body
    (``"rigid"``: ``k_fillet_wheel`` is inf). Every fault is modelled on the ring's teeth too
    (module docstring). ``wear_profiles``: see :func:`prepare_pair`.
    """
    fault_list = _fault_tuple(faults, crack, "potential_energy_stiffness")
    pair = prepare_pair(mesh, bore_radius=bore_radius, young=young, poisson=poisson,
                        root_segment=root_segment, nodes=nodes, faults=fault_list,
                        ring_foundation=ring_foundation, wear_profiles=wear_profiles)
    cyc, n, frac = _cycle_grid(mesh, angles, cycles)
    deg = cyc * (360.0 / mesh.pinion.teeth)
    p_b = mesh.base_pitch
    start, end = -mesh.approach_length / p_b, mesh.recess_length / p_b
    ks = np.arange(math.floor(start), math.floor(end) + 1)
    u = frac[:, None] + ks[None, :]  # contact position in base pitches
    inside = (u >= start) & (u < end)
    position = u * p_b
    passage = n.astype(np.int64)[:, None] - ks[None, :]  # the pair's pitch-point cycle
    tooth_p, tooth_w = passage % mesh.pinion.teeth, passage % mesh.wheel.teeth
    fp, fw, gone = _fault_codes(pair, tooth_p, tooth_w)
    inside &= ~gone
    gap = _wear_gap(pair, position, inside, tooth_p, tooth_w)
    terms = _terms_on_grid(pair, position, inside, fp, fw)
    k_pair = np.where(inside, terms.pop("pair"), 0.0)
    coast, ks_c = _coast(pair, n, frac)
    data = {"mesh_stiffness": (("angle",), k_pair.sum(axis=1)),
            "pairs_in_contact": (("angle",), inside.sum(axis=1)),
            "in_contact": (("angle", "pair"), inside),
            "position": (("angle", "pair"), position),
            "tooth_pinion": (("angle", "pair"), tooth_p),
            "tooth_wheel": (("angle", "pair"), tooth_w),
            "pair_stiffness": (("angle", "pair"), k_pair),
            "fault_gap": (("angle", "pair"), gap)}
    for name, k in terms.items():
        data[f"k_{name}"] = (("angle", "pair"), np.where(inside, k, np.nan))
    data.update(coast)
    ds = xr.Dataset(data, coords={"angle": deg, "cycle": ("angle", cyc), "pair": ks,
                                  "pair_coast": ks_c})
    for name in ds.data_vars:
        ds[name].attrs["units"] = ("m" if name.startswith(("position", "fault_gap"))
                                   else _units(name))
    ds["angle"].attrs.update(units="deg", long_name="pinion rotation")
    ds["cycle"].attrs.update(units="", long_name="mesh cycles")
    ds.attrs.update(_attrs(pair, root_segment, ring_foundation))
    return ds


def _terms_on_grid(pair: PotentialEnergyPair, position: np.ndarray, inside: np.ndarray,
                   fp: np.ndarray, fw: np.ndarray, *, coast: bool = False) -> dict[str, np.ndarray]:
    """Every term at the contacts ``inside`` (0 elsewhere), each distinct position evaluated
    once (a grid over many mesh cycles repeats the positions of one cycle exactly), then again
    for each combination (``fp``, ``fw``: indices into :func:`_tooth_faults`) of faults on the
    teeth in contact that occurs."""
    where, inverse = np.unique(position[inside], return_inverse=True)
    healthy = pair.terms(where, coast=coast)
    out = {}
    for name, values in healthy.items():
        out[name] = np.zeros(position.shape)
        out[name][inside] = values[inverse]
    faulty = inside & ((fp >= 0) | (fw >= 0))
    if faulty.any():
        entries = [f for _, _, f in _tooth_faults(pair)]
        for ip, iw in np.unique(np.stack([fp[faulty], fw[faulty]], axis=1), axis=0):
            mask = faulty & (fp == ip) & (fw == iw)
            where, inverse = np.unique(position[mask], return_inverse=True)
            values = pair.terms(where, entries[ip] if ip >= 0 else None,
                                entries[iw] if iw >= 0 else None, coast=coast)
            for name, v in values.items():
                out[name][mask] = v[inverse]
    return out


def _attrs(pair: PotentialEnergyPair, root_segment: bool,
           ring_foundation: str) -> dict[str, object]:
    mesh = pair.mesh
    out: dict[str, object] = {
        "method": "potential energy (Yang & Lin 1987; Tian 2004; Chaari et al. 2009) with the"
                  " fillet foundation of Sainsot, Velex & Duverger 2004",
        "root": ("straight flank from the root to the base circle" if root_segment
                 else "cantilever from the base circle (or the root circle above it)"),
        "young_Pa": pair.young, "poisson": pair.poisson, "face_width_m": pair.face_width,
        "hertz_stiffness_N_per_m": pair.hertz, "contact_ratio": mesh.contact_ratio,
        "base_pitch_m": mesh.base_pitch, "quadrature_nodes": pair.nodes,
        "coast_phase_cycles": coast_phase(mesh), "backlash_m": mesh.backlash,
        "backlash_cycles": mesh.backlash / (2.0 * math.pi * mesh.operating_pitch_radii[0]
                                            / mesh.pinion.teeth),
        "faults": "; ".join(f.describe() for f in pair.faults) or "none",
        "faulty_gears": ",".join(sorted({f.gear for f in pair.faults})),
    }
    if mesh.internal:
        out["internal"] = 1
        out["ring_foundation"] = ring_foundation
        out["method"] = (f"{out['method']}; the ring's tooth a cantilever on its involute from"
                         " its root circle (Chen & Shao 2013; Liang, Zuo & Feng 2015), its body"
                         f" {ring_foundation}")
    for role, tooth in (("pinion", pair.pinion), ("wheel", pair.wheel)):
        out[f"{role}_bore_radius_m"] = tooth.bore_radius
        out[f"{role}_h_fi"] = tooth.h_fi
        out[f"{role}_theta_f_rad"] = tooth.theta_f
        out[f"{role}_root_below_base"] = int(tooth.root_radius < tooth.base_radius)
    return out
