"""Helical pairs: normal and transverse sections, overlap ratio, and the potential-energy mesh
stiffness by thin slices across the face width.

A helical gear is given in its normal section (the basic rack's): normal module m_n, normal
pressure angle alpha_n, normal profile shift x_n and the addendum and dedendum factors in m_n,
with the helix angle beta on the reference cylinder (its magnitude: the two gears of an
external pair have opposite hands). Its transverse section is a spur gear (ISO 21771):

    m_t = m_n / cos(beta),   tan(alpha_t) = tan(alpha_n) / cos(beta),
    x_t = x_n cos(beta),     h_a,t = h_a cos(beta),   h_f,t = h_f cos(beta)

(the radial profile shift x_n m_n and the tooth depths are the same in both sections), so the
pair's centre distance, operating transverse pressure angle alpha_wt, transverse contact ratio
eps_alpha and backlash are those of the spur pair of the transverse sections
(:class:`~geardyn.gears.GearMesh`). The base helix angle is tan(beta_b) = tan(beta) cos(alpha_t);
the overlap ratio eps_beta = b sin(beta) / (pi m_n) = b tan(beta_b) / p_bt (b: the smaller face
width, p_bt the transverse base pitch) and the total contact ratio eps_gamma = eps_alpha +
eps_beta.

The slice model (the "slicing" or "accumulated potential energy" method of the helical
potential-energy literature): the face width is cut into S slices of width b/S, slice j centred
at y_j = (j + 1/2) b/S - b/2 from the face centre. Slice j is the spur pair of the transverse
sections, of width b/S, whose contact lines lie y_j tan(beta_b) further along the transverse
line of action than those of the face centre: eps_beta y_j / b mesh cycles ahead. Every term of
the slice (Hertz, bending, shear, axial, fillet foundation) is that of the transverse tooth of
width b/S (:mod:`geardyn.gears.potential_energy`); the slices act in parallel at equal approach
along the transverse line of action, so the mesh stiffness is the sum over the slices in
contact of all pairs. The slices do not interact (no shear coupling between neighbouring
slices, no load spreading along the contact line), the contact force of a slice is taken in the
transverse plane (no axial bending by the axial force component), and a slice is in or out of
contact as a whole: at S slices the stiffness carries steps of 1/S of a slice's jump, which
vanish as S grows.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, replace

import numpy as np
import xarray as xr

from geardyn.errors import ParameterError
from geardyn.gears.faults import Spall, Wear
from geardyn.gears.geometry import GearMesh, SpurGear
from geardyn.gears.potential_energy import (
    DEFAULT_NODES,
    STEEL_POISSON,
    STEEL_YOUNG,
    PotentialEnergyPair,
    _attrs,
    _cycle_grid,
    _fault_codes,
    _fault_tuple,
    _terms_on_grid,
    _wear_gap,
    coast_phase,
    prepare_pair,
)
from geardyn.gears.slice_terms import DEGREE, TOLERANCE, ChebyshevTerms
from geardyn.units import si_value

#: Largest helix angle accepted [rad].
MAX_HELIX_ANGLE = math.radians(45.0)
#: Slices across the face width unless told.
DEFAULT_SLICES = 20

#: Units of the stiffness Dataset's variables other than stiffnesses (N/m).
_UNITS = {"pairs_in_contact": "", "teeth_in_contact": "", "in_contact": "",
          "contact_fraction": "", "tooth_pinion": "", "tooth_wheel": "", "slice_in_contact": "",
          "position": "m", "slice_position": "m", "fault_gap": "m"}


@dataclass(frozen=True)
class HelicalGear:
    """One external helical gear in its normal section: teeth z, normal module m_n [m],
    normal pressure angle alpha_n [rad], helix angle beta [rad] (0 <= beta <= 45 deg; 0 is a
    spur gear), face width b [m], normal profile shift x_n, addendum and dedendum factors of
    the basic rack (times m_n). Quantities may be unit strings (``"15 deg"``).

    ``transverse`` is the spur gear of its transverse section (module docstring); the checks
    of :class:`~geardyn.gears.SpurGear` are made on it, the undercut one (``check_undercut``)
    in normal terms: x_n >= h_a - z sin^2(alpha_t) / (2 cos beta)."""

    teeth: int
    module: float
    pressure_angle: float
    helix_angle: float
    face_width: float
    profile_shift: float = 0.0
    addendum: float = 1.0
    dedendum: float = 1.25
    name: str = field(default="gear", compare=False)
    check_undercut: bool = field(default=True, compare=False)
    transverse: SpurGear = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n, set_ = self.name, object.__setattr__
        beta = si_value(f"{n}.helix_angle", self.helix_angle, "angle", 0.0)
        if not beta <= MAX_HELIX_ANGLE * (1.0 + 1e-12):  # "45 deg" in float
            raise ParameterError(f"{n}.helix_angle", self.helix_angle,
                                 "must lie in [0, 45 deg]")
        set_(self, "helix_angle", beta)
        for attr in ("module", "face_width"):
            set_(self, attr, si_value(f"{n}.{attr}", getattr(self, attr), "length", 0.0,
                                      strict=True))
        alpha = si_value(f"{n}.pressure_angle", self.pressure_angle, "angle", 0.0, strict=True)
        if not alpha < math.radians(45.0):
            raise ParameterError(f"{n}.pressure_angle", self.pressure_angle,
                                 "must lie between 0 and 45 deg")
        set_(self, "pressure_angle", alpha)
        for attr in ("profile_shift", "addendum", "dedendum"):
            set_(self, attr, si_value(f"{n}.{attr}", getattr(self, attr), "dimensionless"))
        try:  # the spur checks (teeth, widths, pointed tips) on the transverse section
            set_(self, "transverse", self._transverse_gear())
        except ParameterError as exc:
            if exc.field != f"{n}.profile_shift":
                raise
            raise ParameterError(exc.field, self.profile_shift, exc.reason) from None
        if self.check_undercut and self.profile_shift < self.min_profile_shift:
            raise ParameterError(
                f"{n}.profile_shift", self.profile_shift,
                f"the tooth is undercut when generated by the basic rack: {self.teeth} teeth at"
                f" helix angle {math.degrees(beta):.6g} deg need a normal profile shift >="
                f" {self.min_profile_shift:.4f}")

    def _transverse_gear(self) -> SpurGear:
        """The spur gear of the transverse section (the gear itself at beta = 0)."""
        if self.helix_angle == 0.0:
            return SpurGear(self.teeth, self.module, self.pressure_angle, self.face_width,
                            self.profile_shift, self.addendum, self.dedendum, name=self.name,
                            check_undercut=False)
        c = math.cos(self.helix_angle)
        return SpurGear(self.teeth, self.module / c, self.transverse_pressure_angle,
                        self.face_width, self.profile_shift * c, self.addendum * c,
                        self.dedendum * c, name=self.name, check_undercut=False)

    @property
    def transverse_module(self) -> float:
        """m_t = m_n / cos(beta) [m]."""
        return self.module / math.cos(self.helix_angle)

    @property
    def transverse_pressure_angle(self) -> float:
        """alpha_t = atan(tan(alpha_n) / cos(beta)) [rad]."""
        if self.helix_angle == 0.0:
            return self.pressure_angle
        return math.atan(math.tan(self.pressure_angle) / math.cos(self.helix_angle))

    @property
    def base_helix_angle(self) -> float:
        """beta_b = atan(tan(beta) cos(alpha_t)) [rad]."""
        return math.atan(math.tan(self.helix_angle) * math.cos(self.transverse_pressure_angle))

    @property
    def min_profile_shift(self) -> float:
        """Smallest normal profile shift without undercut, h_a - z sin^2(alpha_t) / (2 cos
        beta)."""
        return (self.addendum - 0.5 * self.teeth * math.sin(self.transverse_pressure_angle) ** 2
                / math.cos(self.helix_angle))


@dataclass(frozen=True)
class HelicalMesh:
    """An external pair of helical gears of equal normal module, normal pressure angle and helix
    angle (opposite hands), the pinion driving. ``centre_distance`` and ``max_backlash`` as for
    :class:`~geardyn.gears.GearMesh` (on the transverse sections, the backlash limit in
    transverse modules): ``transverse`` is that spur mesh of the transverse sections, which
    holds the centre distance, alpha_wt, the path of contact and eps_alpha (>= 1 required)."""

    pinion: HelicalGear
    wheel: HelicalGear
    centre_distance: float | None = None
    max_backlash: float | None = None
    transverse: GearMesh = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        p, w = self.pinion, self.wheel
        for role, g in (("pinion", p), ("wheel", w)):
            if not isinstance(g, HelicalGear):
                raise ParameterError(role, g, "must be a HelicalGear")
        for attr in ("helix_angle", "module", "pressure_angle"):
            if abs(getattr(p, attr) - getattr(w, attr)) > 1e-12 * abs(getattr(p, attr)):
                raise ParameterError(f"wheel.{attr}", getattr(w, attr),
                                     f"differs from the pinion's {getattr(p, attr)}")
        object.__setattr__(self, "transverse", GearMesh(
            p.transverse, w.transverse, centre_distance=self.centre_distance,
            max_backlash=self.max_backlash))
        object.__setattr__(self, "centre_distance", self.transverse.centre_distance)

    @property
    def helix_angle(self) -> float:
        """beta [rad]."""
        return self.pinion.helix_angle

    @property
    def base_helix_angle(self) -> float:
        """beta_b [rad]."""
        return self.pinion.base_helix_angle

    @property
    def face_width(self) -> float:
        """b: the smaller face width [m]."""
        return min(self.pinion.face_width, self.wheel.face_width)

    @property
    def transverse_contact_ratio(self) -> float:
        """eps_alpha of the transverse sections."""
        return self.transverse.contact_ratio

    @property
    def overlap_ratio(self) -> float:
        """eps_beta = b sin(beta) / (pi m_n)."""
        return self.face_width * math.sin(self.helix_angle) / (math.pi * self.pinion.module)

    @property
    def total_contact_ratio(self) -> float:
        """eps_gamma = eps_alpha + eps_beta."""
        return self.transverse_contact_ratio + self.overlap_ratio

    def summary(self) -> dict[str, float]:
        """The transverse mesh's derived quantities and the helical ones (SI, radians)."""
        out = self.transverse.summary()
        out.update(helix_angle=self.helix_angle, base_helix_angle=self.base_helix_angle,
                   transverse_module=self.pinion.transverse_module,
                   transverse_pressure_angle=self.pinion.transverse_pressure_angle,
                   overlap_ratio=self.overlap_ratio,
                   total_contact_ratio=self.total_contact_ratio)
        return out


def _helical_faults(faults: object) -> tuple[object, ...]:
    """The faults of a helical pair: root cracks, uniform wear and missing teeth act on the
    whole face; spalls and Archard wear are refused (naming the field)."""
    out = _fault_tuple(faults, None, "helical_stiffness")
    for fault in out:
        if isinstance(fault, Spall):
            raise ParameterError("faults", fault, "a spall on a helical pair is not modelled"
                                 " (its place across the face is not part of Spall)")
        if isinstance(fault, Wear) and fault.profile != "uniform":
            raise ParameterError("wear.profile", fault.profile, "a helical pair takes uniform"
                                 " wear only (Archard's profile is the spur pair's load share)")
    return out


def _slices(slices: object, face_width: float) -> np.ndarray:
    """y_j [m]: the slice centres from the face centre."""
    if isinstance(slices, bool) or not isinstance(slices, numbers.Integral) or slices < 1:
        raise ParameterError("slices", slices, "must be a whole number >= 1")
    s = int(slices)
    return ((np.arange(s) + 0.5) / s - 0.5) * face_width


def _flank(pair: PotentialEnergyPair, piece: PotentialEnergyPair, n: np.ndarray,
           frac: np.ndarray, shift: np.ndarray, *, coast: bool,
           terms_of: PotentialEnergyPair | ChebyshevTerms | None = None
           ) -> dict[str, np.ndarray]:
    """The slices of one flank over (angle, pair, slice): the pair indices ``ks``, contact
    positions [m], contact mask, tooth indices, each slice's terms (``piece``: the pair of one
    slice's width; evaluated by ``terms_of``, default ``piece``) and the wear gap; slice j lies
    ``shift[j]`` mesh cycles ahead of the face centre. Drive: pair k holds pinion and wheel
    tooth (n - k), its slice in contact from the start of the path (included) to its end.
    Coast (as in potential_energy._coast): pinion tooth (n - k), wheel tooth (n - k + 1), in
    contact from the end of the path (included) to its start."""
    mesh = pair.mesh
    p_b = mesh.base_pitch
    start, end = -mesh.approach_length / p_b, mesh.recess_length / p_b
    lo, hi = float(shift.min()), float(shift.max())
    if coast:
        phi = coast_phase(mesh)
        ks = np.arange(math.floor(phi - end - hi), math.ceil(phi - start - lo) + 1)
        centre = phi - frac[:, None] - ks[None, :]
        u = centre[:, :, None] - shift
        inside = (u > start) & (u <= end)
    else:
        ks = np.arange(math.floor(start - hi), math.floor(end - lo) + 1)
        centre = frac[:, None] + ks[None, :]
        u = centre[:, :, None] + shift
        inside = (u >= start) & (u < end)
    passage = n.astype(np.int64)[:, None] - ks[None, :]
    tooth_p = passage % mesh.pinion.teeth
    tooth_w = (passage + int(coast)) % mesh.wheel.teeth
    fp, fw, gone = _fault_codes(pair, tooth_p, tooth_w)
    inside &= ~gone[:, :, None]
    position = u * p_b
    fp3, fw3 = (np.broadcast_to(x[:, :, None], u.shape) for x in (fp, fw))
    terms = _terms_on_grid(terms_of or piece, position, inside, fp3, fw3,  # type: ignore[arg-type]
                           coast=coast)
    gap = _wear_gap(piece, position, inside, tooth_p[:, :, None], tooth_w[:, :, None],
                    coast=coast)
    return {"ks": ks, "centre": centre * p_b, "position": position, "inside": inside,
            "tooth_p": tooth_p, "tooth_w": tooth_w, "terms": terms, "gap": gap}


def helical_stiffness(mesh: HelicalMesh, *, bore_radius: object, angles: object = 360,
                      slices: int = DEFAULT_SLICES, young: object = STEEL_YOUNG,
                      poisson: object = STEEL_POISSON, root_segment: bool = True,
                      nodes: int = DEFAULT_NODES, faults: object = (),
                      cycles: int = 1, exact: bool = False) -> xr.Dataset:
    """Mesh stiffness of the helical ``mesh`` by ``slices`` thin slices (module docstring),
    each the potential-energy spur pair of the transverse sections
    (:func:`~geardyn.gears.potential_energy_stiffness`: ``bore_radius``, ``angles``,
    ``young``, ``poisson``, ``root_segment``, ``nodes`` and ``cycles`` as there; the pinion
    angle is that of the face centre's transverse section).

    Over ``angle``: ``mesh_stiffness`` [N/m], ``pairs_in_contact`` (the sum over the tooth pairs
    of the fraction of the face width in contact; its mean over a cycle is eps_alpha),
    ``teeth_in_contact`` (the pairs in contact anywhere on the face; its mean tends to
    eps_alpha + eps_beta (1 - 1/S)). Over (``angle``, ``pair``), pair k as in the spur Dataset
    for the face centre: ``in_contact`` (anywhere on the face), ``contact_fraction``,
    ``position`` (the face centre's contact position [m] on the transverse line of action from
    the pitch point; it may lie off the path), ``tooth_pinion``, ``tooth_wheel``,
    ``pair_stiffness`` [N/m] (summed over the slices). Over (``angle``, ``pair``, ``slice``):
    ``slice_in_contact``, ``slice_position`` [m], ``slice_stiffness`` [N/m] (0 out of
    contact), ``fault_gap`` [m] and the terms ``k_hertz``, ... ``k_fillet_wheel`` [N/m] of each
    slice (NaN out of contact); coordinate ``axial_position`` [m] (y_j) over ``slice``. The coast
    flank likewise (``mesh_stiffness_coast``, ``pairs_in_contact_coast``,
    ``in_contact_coast``, ``tooth_pinion_coast``, ``tooth_wheel_coast``,
    ``pair_stiffness_coast``, ``slice_in_contact_coast``, ``slice_position_coast``,
    ``slice_stiffness_coast``, ``fault_gap_coast`` over ``pair_coast``), each slice's coast
    flank shifted as its drive flank.

    ``faults``: :class:`~geardyn.gears.RootCrack`, uniform :class:`~geardyn.gears.Wear` and
    :class:`~geardyn.gears.BrokenTooth` act on the whole face width of their tooth (a crack
    across the whole face); a :class:`~geardyn.gears.Spall` (field ``faults``) and Archard wear
    (``wear.profile``) are refused. At beta = 0 with one slice the result is
    :func:`~geardyn.gears.potential_energy_stiffness`'s bitwise.

    Evaluation: where the slices' contacts differ (beta > 0, more than one slice) and not
    ``exact``, the healthy pairs' terms come from Chebyshev interpolants along the path of
    contact (:class:`~geardyn.gears.slice_terms.ChebyshevTerms`, used where its check against
    quadrature is within :data:`~geardyn.gears.slice_terms.TOLERANCE`), the faulty teeth's
    from quadrature; else every contact by quadrature. Attr ``slice_terms`` says which."""
    if not isinstance(mesh, HelicalMesh):
        raise ParameterError("mesh", mesh, "must be a HelicalMesh")
    fault_list = _helical_faults(faults)
    pair = prepare_pair(mesh.transverse, bore_radius=bore_radius, young=young, poisson=poisson,
                        root_segment=root_segment, nodes=nodes, faults=fault_list)
    axial = _slices(slices, pair.face_width)
    count = axial.size
    piece = replace(pair, face_width=pair.face_width / count)
    shift = mesh.overlap_ratio * (axial / pair.face_width)  # mesh cycles ahead of the centre
    cyc, n, frac = _cycle_grid(mesh.transverse, angles, cycles)
    terms_of, how = _slice_evaluation(piece, count, mesh.overlap_ratio, exact)
    drive = _flank(pair, piece, n, frac, shift, coast=False, terms_of=terms_of)
    coast = _flank(pair, piece, n, frac, shift, coast=True, terms_of=terms_of)
    data = _flank_variables(drive, count, "")
    data.update(_flank_variables(coast, count, "_coast"))
    data["fault_gap"] = (("angle", "pair", "slice"), drive["gap"])
    data["fault_gap_coast"] = (("angle", "pair_coast", "slice"), coast["gap"])
    drive["terms"].pop("pair")
    for name, k in drive["terms"].items():
        data[f"k_{name}"] = (("angle", "pair", "slice"), np.where(drive["inside"], k, np.nan))
    ds = xr.Dataset(data, coords={
        "angle": cyc * (360.0 / mesh.pinion.teeth), "cycle": ("angle", cyc),
        "pair": drive["ks"], "pair_coast": coast["ks"], "slice": np.arange(count),
        "axial_position": ("slice", axial)})
    for name in ds.data_vars:
        base = name.removesuffix("_coast")
        ds[name].attrs["units"] = _UNITS.get(base, "N/m")
    ds["angle"].attrs.update(units="deg", long_name="pinion rotation (face centre)")
    ds["cycle"].attrs.update(units="", long_name="mesh cycles")
    ds["axial_position"].attrs.update(units="m", long_name="slice centre from the face centre")
    ds.attrs.update(_helical_attrs(mesh, pair, root_segment, count))
    ds.attrs["slice_terms"] = how
    return ds


def _slice_evaluation(piece: PotentialEnergyPair, count: int, overlap: float,
                      exact: bool) -> tuple[PotentialEnergyPair | ChebyshevTerms, str]:
    """What evaluates the slices' terms (the pair of one slice's width ``piece`` by
    quadrature, or its Chebyshev interpolants where the slices' contacts differ and they pass
    their check) and the attr ``slice_terms`` saying so."""
    if exact or count == 1 or overlap == 0.0:
        return piece, "quadrature at every contact"
    table = ChebyshevTerms.build(piece)
    if table.error <= TOLERANCE:
        return table, (f"healthy pairs: Chebyshev interpolants of degree {DEGREE} along the"
                       f" path of contact (largest error at the check points {table.error:.2g}"
                       " of the pair's compliance); faulty teeth: quadrature")
    return piece, (f"quadrature at every contact (the Chebyshev interpolants' error"
                   f" {table.error:.2g} exceeds {TOLERANCE:g})")


def _flank_variables(flank: dict[str, np.ndarray], count: int,
                     suffix: str) -> dict[str, tuple]:
    """The Dataset variables of one flank (``suffix`` "" or "_coast")."""
    inside = flank["inside"]
    k_slice = np.where(inside, flank["terms"]["pair"], 0.0)
    k_pair = k_slice.sum(axis=2)
    pair_dim = "pair" + suffix
    dims2, dims3 = ("angle", pair_dim), ("angle", pair_dim, "slice")
    fraction = inside.sum(axis=2) / count
    return {f"mesh_stiffness{suffix}": (("angle",), k_pair.sum(axis=1)),
           f"pairs_in_contact{suffix}": (("angle",), fraction.sum(axis=1)),
           f"teeth_in_contact{suffix}": (("angle",), inside.any(axis=2).sum(axis=1)),
           f"in_contact{suffix}": (dims2, inside.any(axis=2)),
           f"contact_fraction{suffix}": (dims2, fraction),
           f"position{suffix}": (dims2, flank["centre"]),
           f"tooth_pinion{suffix}": (dims2, flank["tooth_p"]),
           f"tooth_wheel{suffix}": (dims2, flank["tooth_w"]),
           f"pair_stiffness{suffix}": (dims2, k_pair),
           f"slice_in_contact{suffix}": (dims3, inside),
           f"slice_position{suffix}": (dims3, flank["position"]),
           f"slice_stiffness{suffix}": (dims3, k_slice)}


def _helical_attrs(mesh: HelicalMesh, pair: PotentialEnergyPair, root_segment: bool,
                   count: int) -> dict[str, object]:
    """The Dataset's attributes: the method, material, width (the whole face), faults, bores
    and the helical geometry."""
    out = _attrs(pair, root_segment, "rigid")  # pair.mesh: the transverse section's pair
    out["method"] = f"{out['method']}, per slice"
    return out | {
        "slice_model": "thin slices across the face width, each the potential-energy spur pair"
                       " of the transverse sections of width b/S shifted by y tan(beta_b) along"
                       " the line of action; slices in parallel, no coupling between them",
        "helix_angle_deg": math.degrees(mesh.helix_angle),
        "base_helix_angle_deg": math.degrees(mesh.base_helix_angle),
        "normal_module_m": mesh.pinion.module,
        "transverse_module_m": mesh.pinion.transverse_module,
        "transverse_pressure_angle_deg": math.degrees(mesh.pinion.transverse_pressure_angle),
        "transverse_contact_ratio": mesh.transverse_contact_ratio,
        "overlap_ratio": mesh.overlap_ratio, "total_contact_ratio": mesh.total_contact_ratio,
        "slices": count,
    }
