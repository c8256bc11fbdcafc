"""The dynamic factor K_v of ISO 6336-1, method B (ISO 6336-1:2006, clause 6.5).

Resonance running speed of the pinion (gear 1, tooth number z1), Eq. (6):

    n_E1 = 30 000 / (pi z1) sqrt(c_gamma_alpha / m_red)   [min^-1]

with c_gamma_alpha the mean mesh stiffness [N/(mm um)] and m_red the reduced mass of the pair
per unit face width [kg/mm], Eq. (30): m_red = m1* m2* / (m1* + m2*), m* = J* / r_b^2 (J* the
polar moment of inertia per unit face width, r_b the base radius). n_E1 z1 / 60 is the natural
frequency sqrt(c_gamma_alpha b / (m_red b)) / (2 pi) of the two inertias coupled by the mesh
spring: the resonance ratio N = n1 / n_E1 (Eq. 9) is the mesh frequency over that natural
frequency. For a planetary stage clause 6.5.9 takes, for the sun-planet mesh,
m_red = m_P* m_S* / (n_P m_P* + m_S*) (n_P planets) and for the ring-planet mesh the planet's
m_P* alone (the ring taken as infinitely heavy): :func:`planetary_reduced_masses`.

Ranges of N (clause 6.5.3): subcritical N <= N_S, main resonance N_S < N <= 1.15,
intermediate 1.15 < N < 1.5, supercritical N >= 1.5, with the lower limit (Eqs. 11, 12)

    N_S = 0.5 + 0.35 sqrt(F_t K_A / b / 100 N/mm)   (F_t K_A / b < 100 N/mm),  else 0.85.

With B_p = c' f_pb,eff / (F_t K_A / b), B_f = c' f_f,eff / (F_t K_A / b) and
B_k = abs(1 - c' C_a / (F_t K_A / b)) (Eqs. 15-17; f_pb,eff = f_pb - y_p,
f_f,eff = f_falpha - y_f, the deviations less their running-in allowances; C_a the tip
relief) the factor is

* subcritical (6.5.4, Eqs. 13, 14): K_v = N (C_v1 B_p + C_v2 B_f + C_v3 B_k) + 1;
* main resonance (6.5.5, Eq. 20): K_v = C_v1 B_p + C_v2 B_f + C_v4 B_k + 1;
* supercritical (6.5.6, Eq. 21): K_v = C_v5 B_p + C_v6 B_f + C_v7;
* intermediate (6.5.7, Eq. 22): linear in N between K_v(1.15) of the main resonance range and
  K_v(1.5) of the supercritical range, K_v = K_v(1.5) + (K_v(1.15) - K_v(1.5)) (1.5 - N) / 0.35.

K_v is continuous at N = 1.15 and N = 1.5 (by Eq. 22); at N_S it jumps (the subcritical value
N_S K + 1 against the main-resonance value), as the standard has it. The factors C_v1 .. C_v7
depend on the total contact ratio eps_gamma (Table 8): :func:`cv_factors`. The equations were
compared with an independent implementation of the same clauses (MATISO_6336 of the GitHub
repository gfsReboucas/Drivetrain, MATLAB, ISO 6336-1:2006 equation numbers); the standard's own
text was not at hand.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from geardyn.core.inputs import N_PLANETS
from geardyn.errors import ParameterError
from geardyn.gears.helical import HelicalMesh
from geardyn.gears.iso6336 import N_PER_MM_UM, iso6336_stiffness

__all__ = ["REGIMES", "DynamicFactorInputs", "KvMeshGroup", "cv_factors", "dynamic_factor_iso",
           "group_inputs", "group_reduced_mass", "lower_resonance_limit",
           "planetary_reduced_masses", "reduced_mass", "resonance_ratio", "resonance_speed"]

#: Where c' and c_gamma_alpha of K_v come from: ISO 6336-1 method B (clause 9), or the model's
#: own mean drive stiffness (c_gamma_alpha = k_mean / b, c' = c_gamma_alpha / (0.75 eps + 0.25)).
STIFFNESS_SOURCES = ("iso", "model")

#: The ranges of the resonance ratio N, in code order (the ``regime`` of
#: :func:`dynamic_factor_iso`).
REGIMES: tuple[str, ...] = ("subcritical", "main resonance", "intermediate", "supercritical")
#: Upper end of the main resonance range and lower end of the supercritical range (6.5.3).
N_MAIN_END, N_SUPER = 1.15, 1.5
#: N_S at line loads of 100 N/mm and more (Eq. 12).
N_S_FULL_LOAD = 0.85


def _positive(field: str, value: object, allow_zero: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise ParameterError(field, value, "must be a number")
    v = float(value)
    ok = v >= 0.0 if allow_zero else v > 0.0
    if not (math.isfinite(v) and ok):
        raise ParameterError(field, value, "must be >= 0" if allow_zero else "must be > 0")
    return v


@dataclass(frozen=True)
class DynamicFactorInputs:
    """The inputs of ISO 6336-1 method B for one mesh, in the standard's units.

    Attributes
    ----------
    pinion_teeth
        z1, the teeth of gear 1 (the gear whose speed n1 the resonance speed is of).
    reduced_mass
        m_red [kg/mm]: reduced mass per unit face width (:func:`reduced_mass`).
    single_stiffness
        c' [N/(mm um)], the single stiffness.
    mesh_stiffness
        c_gamma_alpha [N/(mm um)], the mean mesh stiffness.
    line_load
        F_t K_A / b [N/mm]: nominal tangential force at the reference circle times the
        application factor over the face width.
    base_pitch_deviation, profile_form_deviation
        f_pb and f_falpha [um] (the larger of the two gears', from the accuracy grade).
    pitch_running_in, profile_running_in
        y_p and y_f [um], the running-in allowances (ISO 6336-1 takes y_p = y_f = y_alpha).
    tip_relief
        C_a [um] (without tip relief the running-in amount C_ay).
    contact_ratio
        eps_gamma, the total contact ratio (> 1).
    """

    pinion_teeth: int
    reduced_mass: float
    single_stiffness: float
    mesh_stiffness: float
    line_load: float
    base_pitch_deviation: float
    profile_form_deviation: float
    pitch_running_in: float = 0.0
    profile_running_in: float = 0.0
    tip_relief: float = 0.0
    contact_ratio: float = 1.6

    def __post_init__(self) -> None:
        z = self.pinion_teeth
        if isinstance(z, bool) or not isinstance(z, int | np.integer) or z < 1:
            raise ParameterError("pinion_teeth", z, "must be a whole number >= 1")
        for f in ("reduced_mass", "single_stiffness", "mesh_stiffness", "line_load"):
            _positive(f, getattr(self, f))
        for f in ("base_pitch_deviation", "profile_form_deviation", "pitch_running_in",
                  "profile_running_in", "tip_relief"):
            _positive(f, getattr(self, f), allow_zero=True)
        if self.pitch_running_in > self.base_pitch_deviation:
            raise ParameterError("pitch_running_in", self.pitch_running_in,
                                 f"exceeds base_pitch_deviation ({self.base_pitch_deviation} um)"
                                 ": f_pb,eff = f_pb - y_p would be negative")
        if self.profile_running_in > self.profile_form_deviation:
            raise ParameterError("profile_running_in", self.profile_running_in,
                                 f"exceeds profile_form_deviation "
                                 f"({self.profile_form_deviation} um)")
        eps = _positive("contact_ratio", self.contact_ratio)
        if not eps > 1.0:
            raise ParameterError("contact_ratio", eps, "eps_gamma must be > 1")

    def as_dict(self) -> dict[str, float]:
        """Every input by name (for dataset attributes)."""
        return {k: float(v) for k, v in asdict(self).items()}

    @property
    def B_p(self) -> float:
        """c' f_pb,eff / (F_t K_A / b) (Eq. 15)."""
        return self.single_stiffness * (self.base_pitch_deviation - self.pitch_running_in) \
            / self.line_load

    @property
    def B_f(self) -> float:
        """c' f_f,eff / (F_t K_A / b) (Eq. 16)."""
        return self.single_stiffness * (self.profile_form_deviation - self.profile_running_in) \
            / self.line_load

    @property
    def B_k(self) -> float:
        """abs(1 - c' C_a / (F_t K_A / b)) (Eq. 17)."""
        return abs(1.0 - self.single_stiffness * self.tip_relief / self.line_load)


def reduced_mass(inertia_1: float, inertia_2: float, base_radius_1: float,
                 base_radius_2: float, face_width: float) -> float:
    """m_red [kg/mm] of two gears of polar inertias I [kg m^2] on base radii r_b [m], per mm of
    ``face_width`` [m] (Eq. 30 with J* = I / b): I1 I2 / (I1 r_b2^2 + I2 r_b1^2) / (1000 b)."""
    i1, i2 = _positive("inertia_1", inertia_1), _positive("inertia_2", inertia_2)
    r1, r2 = _positive("base_radius_1", base_radius_1), _positive("base_radius_2", base_radius_2)
    b = _positive("face_width", face_width)
    return i1 * i2 / (i1 * r2 * r2 + i2 * r1 * r1) / (1000.0 * b)


def planetary_reduced_masses(sun_inertia: float, planet_inertia: float, sun_base_radius: float,
                             planet_base_radius: float, n_planets: int, face_width: float
                             ) -> tuple[float, float]:
    """(sun-planet, ring-planet) m_red [kg/mm] of a planetary stage (6.5.9): m_S* = I_S / r_bS^2
    and m_P* = I_P / r_bP^2 per mm of ``face_width`` [m]; sun-planet m_P* m_S* / (n_P m_P* +
    m_S*), ring-planet m_P* (the ring infinitely heavy)."""
    b = 1000.0 * _positive("face_width", face_width)
    ms = _positive("sun_inertia", sun_inertia) / _positive("sun_base_radius", sun_base_radius) ** 2
    mp = _positive("planet_inertia", planet_inertia) \
        / _positive("planet_base_radius", planet_base_radius) ** 2
    n_planets = N_PLANETS.count(n_planets)
    return mp * ms / (n_planets * mp + ms) / b, mp / b


def group_reduced_mass(common_inertia: float, other_inertia: float, common_base_radius: float,
                       other_base_radius: float, n_meshes: int, face_width: float,
                       internal: bool) -> float:
    """m_red [kg/mm] of ``n_meshes`` equal meshes that share one gear (the common member, e.g. a
    sun) with ``n_meshes`` equal other gears (e.g. planets): external meshes m_O* m_C* /
    (n m_O* + m_C*), clause 6.5.9's sun-planet rule, which for one mesh is Eq. 30; internal
    meshes the external gear's m* alone (the internal gear taken as infinitely heavy, 6.5.9's
    ring-planet rule). ``internal``: the common gear or the other is the internal one; then
    ``other_*`` must be the external gear's."""
    b = 1000.0 * _positive("face_width", face_width)
    mo = _positive("other_inertia", other_inertia) \
        / _positive("other_base_radius", other_base_radius) ** 2
    if internal:
        return mo / b
    mc = _positive("common_inertia", common_inertia) \
        / _positive("common_base_radius", common_base_radius) ** 2
    if isinstance(n_meshes, bool) or not isinstance(n_meshes, int | np.integer) or n_meshes < 1:
        raise ParameterError("n_meshes", n_meshes, "must be a whole number >= 1")
    return mo * mc / (n_meshes * mo + mc) / b


@dataclass(frozen=True)
class KvMeshGroup:
    """Meshes of a model that K_v treats as one (a gear pair's mesh; a planetary stage's
    sun-planet or ring-planet meshes), as a model gives them at one input torque.

    Attributes
    ----------
    name
        The group's label (e.g. ``"mesh"``, ``"sun"``, a train mesh's name).
    mesh
        The pair's geometry (:class:`~geardyn.gears.GearMesh` or
        :class:`~geardyn.gears.HelicalMesh`), gear 1 its pinion.
    meshes
        Indices of the group's meshes among the model's meshes.
    tangential_force
        F_t [N], the nominal tangential force per mesh at gear 1's reference circle.
    reduced_mass
        m_red [kg/mm] (:func:`reduced_mass`, :func:`group_reduced_mass`).
    speed_per_input
        Gear 1's speed over the model's input speed (a planet's relative to its carrier).
    model_stiffness
        The model's mean drive-flank stiffness of one of the group's meshes [N/m], along the
        transverse line of action (the ``"model"`` stiffness source).
    """

    name: str
    mesh: Any
    meshes: tuple[int, ...]
    tangential_force: float
    reduced_mass: float
    speed_per_input: float
    model_stiffness: float

    @property
    def face_width(self) -> float:
        """b [m]: the narrower gear's face width."""
        return min(self.mesh.pinion.face_width, self.mesh.wheel.face_width)

    @property
    def pinion_teeth(self) -> int:
        """z1, gear 1's teeth."""
        return int(self.mesh.pinion.teeth)


def group_inputs(group: KvMeshGroup, *, application_factor: float = 1.0, stiffness: str = "iso",
                 **accuracy: float) -> DynamicFactorInputs:
    """The method B inputs of ``group``: the line load F_t K_A / b, c', c_gamma_alpha and
    eps_alpha by ISO 6336-1 method B at that load (``stiffness="iso"``) or from the group's
    ``model_stiffness`` (``"model"``: c_gamma_alpha = k / b, c' = c_gamma_alpha / (0.75
    eps_alpha + 0.25)); eps_gamma = eps_alpha + eps_beta (a helical pair's overlap ratio); the
    accuracy inputs [um] (``base_pitch_deviation``, ...) as :class:`DynamicFactorInputs`."""
    if stiffness not in STIFFNESS_SOURCES:
        raise ParameterError("stiffness", stiffness, f"must be one of {STIFFNESS_SOURCES}")
    k_a = float(application_factor)
    if not (math.isfinite(k_a) and k_a >= 1.0):
        raise ParameterError("application_factor", application_factor, "K_A must be >= 1")
    b = group.face_width
    load = _positive("tangential_force", group.tangential_force) * k_a / b  # N/m
    iso = iso6336_stiffness(group.mesh, line_load=load)
    eps_alpha = iso.contact_ratio
    if stiffness == "iso":
        c_prime, c_gamma = iso.c_prime, iso.c_gamma_alpha
    else:
        c_gamma = group.model_stiffness / b / N_PER_MM_UM
        c_prime = c_gamma / (0.75 * eps_alpha + 0.25)
    eps_gamma = (group.mesh.total_contact_ratio if isinstance(group.mesh, HelicalMesh)
                 else eps_alpha)
    return DynamicFactorInputs(pinion_teeth=group.pinion_teeth, reduced_mass=group.reduced_mass,
                               single_stiffness=c_prime, mesh_stiffness=c_gamma,
                               line_load=load * 1e-3, contact_ratio=eps_gamma, **accuracy)


def resonance_speed(inputs: DynamicFactorInputs) -> float:
    """n_E1 [rpm] of gear 1 (Eq. 6): 30 000 / (pi z1) sqrt(c_gamma_alpha / m_red)."""
    return 30000.0 / (math.pi * inputs.pinion_teeth) \
        * math.sqrt(inputs.mesh_stiffness / inputs.reduced_mass)


def resonance_ratio(inputs: DynamicFactorInputs, speed: np.ndarray | float) -> np.ndarray:
    """N = n1 / n_E1 (Eq. 9) at the gear-1 speeds ``speed`` [rpm]."""
    n = np.asarray(speed, dtype=float)
    if not np.all(np.isfinite(n)) or np.any(n < 0.0):
        raise ParameterError("speed", speed, "speeds must be finite and >= 0 rpm")
    return n / resonance_speed(inputs)


def lower_resonance_limit(line_load: float) -> float:
    """N_S (Eqs. 11, 12): 0.5 + 0.35 sqrt(line_load / 100) below 100 N/mm, else 0.85."""
    w = _positive("line_load", line_load)
    return 0.5 + 0.35 * math.sqrt(w / 100.0) if w < 100.0 else N_S_FULL_LOAD


def cv_factors(contact_ratio: float) -> dict[str, float]:
    """C_v1 .. C_v7 of Table 8 at the total contact ratio eps_gamma (> 1)."""
    e = _positive("contact_ratio", contact_ratio)
    if not e > 1.0:
        raise ParameterError("contact_ratio", e, "eps_gamma must be > 1")
    if e <= 2.0:
        cv2, cv3, cv4, cv6 = 0.34, 0.23, 0.90, 0.47
    else:
        cv2, cv3 = 0.57 / (e - 0.3), 0.096 / (e - 1.56)
        cv4, cv6 = (0.57 - 0.05 * e) / (e - 1.44), 0.12 / (e - 1.74)
    if e <= 1.5:
        cv7 = 0.75
    elif e <= 2.5:
        cv7 = 0.125 * math.sin(math.pi * (e - 2.0)) + 0.875
    else:
        cv7 = 1.0
    return {"C_v1": 0.32, "C_v2": cv2, "C_v3": cv3, "C_v4": cv4, "C_v5": 0.47, "C_v6": cv6,
            "C_v7": cv7}


def dynamic_factor_iso(inputs: DynamicFactorInputs, speed: np.ndarray | float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """K_v by ISO 6336-1 method B at the gear-1 speeds ``speed`` [rpm], and the range of each
    (an index into :data:`REGIMES`); arrays of the shape of ``speed``."""
    N = resonance_ratio(inputs, speed)
    c = cv_factors(inputs.contact_ratio)
    bp, bf, bk = inputs.B_p, inputs.B_f, inputs.B_k
    n_s = lower_resonance_limit(inputs.line_load)
    main = c["C_v1"] * bp + c["C_v2"] * bf + c["C_v4"] * bk + 1.0
    sup = c["C_v5"] * bp + c["C_v6"] * bf + c["C_v7"]
    sub = N * (c["C_v1"] * bp + c["C_v2"] * bf + c["C_v3"] * bk) + 1.0
    mid = sup + (main - sup) * (N_SUPER - N) / (N_SUPER - N_MAIN_END)
    regime = np.select([N <= n_s, N <= N_MAIN_END, N < N_SUPER], [0, 1, 2], 3)
    kv = np.choose(regime, [sub, np.broadcast_to(main, N.shape), mid,
                            np.broadcast_to(sup, N.shape)])
    return np.asarray(kv, dtype=float), regime.astype(np.int8)
