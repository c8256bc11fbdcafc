"""Single-tooth and mesh stiffness of spur and helical gears by ISO 6336-1, method B.

ISO 6336-1:2006, clause 9 (tooth stiffness parameters c' and c_gamma), method B:

* q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1^2 + C9 x2^2,
  the minimum flexibility of a tooth pair [mm um/N], with z_n = z / (cos^2 beta_b cos beta)
  (z_n = z for spur gears), gear 1 the pinion (the gear with fewer teeth) and, for an internal
  pair, z_n2 = infinity;
* c'_th = 1 / q' (theoretical single stiffness) [N/(mm um)];
* c' = c'_th C_M C_R C_B cos(beta) (single stiffness), C_M = 0.8, C_R = 1 for solid blanks
  (1 + ln(b_s/b) / (5 exp(s_R / (5 m_n))) for a web of width b_s and a rim of thickness s_R),
  C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_Pn)] (basic rack), and the factor
  (F_t K_A / b / 100 N/mm)^0.25 when the specific load F_t K_A / b is below 100 N/mm;
* c_gamma_alpha = c' (0.75 eps_alpha + 0.25) (mean mesh stiffness) [N/(mm um)].

1 N/(mm um) = 1e9 N/m per metre of face width. The internal gear's profile shift enters q' in
the sign convention of ISO 21771 (x_ISO = -x of :mod:`geardyn.gears.geometry`).

A helical pair (:class:`~geardyn.gears.HelicalMesh`) enters with its normal-section values
(z_n, the normal profile shifts x_n, the basic rack's normal dedendum and pressure angle), the
factor cos(beta) and the transverse contact ratio eps_alpha. ISO 6336-1 uses c_gamma_alpha
with the transverse base radii (the reduced mass of the resonance speed, clause 6): the
stiffness is referred to the transverse line of action.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from geardyn.errors import ParameterError
from geardyn.gears.geometry import GearMesh
from geardyn.gears.helical import HelicalMesh

#: ISO 6336-1 method B coefficients C1..C9 of q' [mm um/N].
C_COEFFS: tuple[float, ...] = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193,
                               -0.24188, 0.00529, 0.00182)
#: Theoretical correction factor C_M for solid disc gears.
C_M = 0.8
#: N/(mm um) in SI (N/m per metre of face width).
N_PER_MM_UM = 1e9


@dataclass(frozen=True)
class ISOStiffness:
    """The intermediate and final quantities of ISO 6336-1 method B (stiffness per unit face
    width in N/(mm um), the ISO unit; SI totals in N/m)."""

    z_n1: float
    z_n2: float  # inf for an internal pair
    x1: float
    x2: float  # ISO 21771 sign
    q_prime: float  # mm um / N
    c_th: float  # theoretical single stiffness c'_th
    C_M: float
    C_R: float
    C_B: float
    cos_beta: float
    load_factor: float  # (F_t K_A / b / 100)^0.25, or 1
    c_prime: float  # single stiffness c'
    contact_ratio: float
    c_gamma_alpha: float  # mean mesh stiffness
    face_width: float  # m
    single_stiffness: float  # c' b, N/m
    mesh_stiffness: float  # c_gamma_alpha b, N/m

    def as_dict(self) -> dict[str, float]:
        """All quantities by name."""
        return asdict(self)


def flexibility_q(z_n1: float, z_n2: float, x1: float, x2: float) -> float:
    """q' [mm um/N] (ISO 6336-1 method B); ``z_n2=inf`` for an internal pair."""
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = C_COEFFS
    inv2 = 0.0 if math.isinf(z_n2) else 1.0 / z_n2
    return (c1 + c2 / z_n1 + c3 * inv2 + c4 * x1 + c5 * x1 / z_n1 + c6 * x2 + c7 * x2 * inv2
            + c8 * x1 ** 2 + c9 * x2 ** 2)


def basic_rack_factor(dedendum: float, pressure_angle: float) -> float:
    """C_B = [1 + 0.5 (1.2 - h_fP/m)] [1 - 0.02 (20 - alpha_Pn/deg)]."""
    return (1.0 + 0.5 * (1.2 - dedendum)) * (1.0 - 0.02 * (20.0 - math.degrees(pressure_angle)))


def blank_factor(web_ratio: float | None, rim_ratio: float | None) -> float:
    """C_R = 1 + ln(b_s/b) / (5 exp(s_R/(5 m_n))); 1 for solid blanks (either ratio None)."""
    if web_ratio is None or rim_ratio is None:
        return 1.0
    if not 0.2 <= web_ratio <= 1.2:
        raise ParameterError("web_ratio", web_ratio, "b_s/b must lie in [0.2, 1.2]")
    if not rim_ratio >= 1.0:
        raise ParameterError("rim_ratio", rim_ratio, "s_R/m_n must be >= 1")
    return 1.0 + math.log(web_ratio) / (5.0 * math.exp(rim_ratio / 5.0))


def iso6336_stiffness(mesh: GearMesh | HelicalMesh, *, line_load: float | None = None,
                      web_ratio: float | None = None,
                      rim_ratio: float | None = None) -> ISOStiffness:
    """Single stiffness c' and mesh stiffness c_gamma_alpha of a spur or helical mesh, ISO
    6336-1 method B (a helical pair: the module docstring).

    ``line_load`` is F_t K_A / b [N/m] (None: >= 100 N/mm, no load correction); ``web_ratio``
    b_s/b and ``rim_ratio`` s_R/m_n describe a webbed blank (None: solid). The face width is the
    smaller of the two gears'. Gear 1 of the q' formula (z_n1, x1) is ISO's pinion, the gear
    with fewer teeth, whichever of ``mesh.pinion`` and ``mesh.wheel`` that is (a planetary set's
    sun may have more teeth than its planets); of an internal pair, the external gear.
    """
    helical = isinstance(mesh, HelicalMesh)
    internal = False if helical else mesh.internal
    p, w = mesh.pinion, mesh.wheel
    if not internal and w.teeth < p.teeth:
        p, w = w, p  # ISO's gear 1 is the pinion: the gear with fewer teeth, driving or not
    cos_beta, virtual = 1.0, 1.0
    if helical:
        cos_beta = math.cos(mesh.helix_angle)
        virtual = 1.0 / (math.cos(mesh.base_helix_angle) ** 2 * cos_beta)  # z_n / z
    z1 = p.teeth * virtual
    z2 = math.inf if internal else w.teeth * virtual
    x1 = p.profile_shift
    x2 = -w.profile_shift if internal else w.profile_shift
    q = flexibility_q(z1, z2, x1, x2)
    c_th = 1.0 / q
    c_b = 0.5 * (basic_rack_factor(p.dedendum, p.pressure_angle)
                 + basic_rack_factor(w.dedendum, w.pressure_angle))
    c_r = blank_factor(web_ratio, rim_ratio)
    load = 1.0
    if line_load is not None:
        if not line_load > 0.0:
            raise ParameterError("line_load", line_load, "must be > 0")
        per_mm = line_load * 1e-3  # N/m -> N/mm
        load = (per_mm / 100.0) ** 0.25 if per_mm < 100.0 else 1.0
    c_prime = c_th * C_M * c_r * c_b * cos_beta * load
    eps = mesh.transverse_contact_ratio if helical else mesh.contact_ratio
    c_ga = c_prime * (0.75 * eps + 0.25)
    b = min(p.face_width, w.face_width)
    return ISOStiffness(
        z_n1=z1, z_n2=z2, x1=x1, x2=x2, q_prime=q, c_th=c_th, C_M=C_M, C_R=c_r, C_B=c_b,
        cos_beta=cos_beta, load_factor=load, c_prime=c_prime, contact_ratio=eps,
        c_gamma_alpha=c_ga, face_width=b, single_stiffness=c_prime * N_PER_MM_UM * b,
        mesh_stiffness=c_ga * N_PER_MM_UM * b)
