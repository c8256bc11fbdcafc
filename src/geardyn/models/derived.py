"""Derived quantities of the CATT device and the dimensionless coefficients of Eq. (10).

The paper leaves some quantities undisclosed and prints others wrongly (``shared/model-notes.md``).
Three *interpretations* resolve this, each a documented choice:

``consistent`` (default)
    omega_n = sqrt(Km_sq (1/M_s + 1/M_c)) (a frequency); carrier inertia
    J_c + sum(m_p r_c2^2 + m_q r_c1^2); carrier damping term with 1/omega_n.
``carrier-only``
    as ``consistent`` but the carrier's effective inertia is J_c alone.
``as-printed``
    every formula exactly as printed: omega_n = sqrt(Km_sq / (1/M_s + 1/M_c)) (units kg/s, used as
    if rad/s), J_c + sum(m_p r_c2 + m_q r_c1) (SI numbers, dimensionally inconsistent), and the
    carrier damping term of Eq. (10) with 1/omega_n^2 instead of 1/omega_n.

Every quantity in :data:`DERIVED_FORMULAS` can be overridden by name through
``PlanetaryParams.derived``; per-planet quantities then take the value for every planet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Literal, get_args

import numpy as np

from geardyn.core.coefficients import Coefficient, CoefficientBlock

# DERIVED_FORMULAS is defined with the parameters (which check overrides by name), shown here
from geardyn.models.params import DERIVED_FORMULAS as DERIVED_FORMULAS
from geardyn.models.params import PlanetaryParams

Interpretation = Literal["consistent", "carrier-only", "as-printed"]
#: The names of the three interpretations of the paper's formulas (docs/model.md), the default
#: first.
INTERPRETATIONS: tuple[str, ...] = get_args(Interpretation)


def _d(name: str, meaning: str, *inputs: str, unit: str = "1",
       constant: str | None = None) -> Coefficient:
    return Coefficient(name, unit, meaning, "derived", inputs, constant=constant)


def _structure(name: str, meaning: str, constant: str | None = None) -> Coefficient:
    return Coefficient(name, "1", meaning, "structure", constant=constant)


#: The header of the mesh-coordinate model's coefficient vector (offsets: the kernel constants
#: of :mod:`geardyn.models.catt_kernels`).
CATT_HEADER = CoefficientBlock((
    Coefficient("Omega", "1", "mesh frequency omega / omega_n"),
    Coefficient("Lambda", "1", "load-fluctuation frequency / omega_n"),
    _structure("n_blocks", "number of planet-set blocks (the vector's layout)"),
    _structure("n_harmonics", "number of stiffness harmonics (the vector's layout)",
               constant="N_HARM"),
    _d("f_c0", "r_c1 (T_D - A2) / (M_c r_bc^2 omega_n^2 b_c)  (net mean torque on the carrier)",
       "T_D", "A2", "r_c1", "M_c", "r_bc", "omega_n", "b_c"),
    _d("f_c1", "-r_c1 B2 / (M_c r_bc^2 omega_n^2 b_c)",
       "B2", "r_c1", "M_c", "r_bc", "omega_n", "b_c"),
    Coefficient("psi1", "rad", "phase of the outside-planet load fluctuation"),
    Coefficient("psi2", "rad", "phase of the carrier load fluctuation"),
))

#: One planet set's block (then its 4 nh stiffness harmonics, :func:`catt_harmonics`).
CATT_BLOCK = CoefficientBlock((
    _d("k_sq_c", "r_c1 arm Km_sq / (M_c r_bc^2 omega_n^2)  (sun mesh stiffness on the carrier)",
       "Km_sq", "r_c1", "arm", "M_c", "r_bc", "omega_n"),
    _d("c_sq_c", "gamma r_c1 arm C_sq / (M_c r_bc^2 omega_n)  (sun mesh damping on the carrier)",
       "xi1", "Km_sq", "r_c1", "arm", "M_c", "r_bc", "omega_n"),
    _d("k_sq_q", "Km_sq / (M_q omega_n^2)", "Km_sq", "M_q", "omega_n"),
    _d("c_sq_q", "C_sq / (M_q omega_n)", "xi1", "Km_sq", "M_q", "omega_n"),
    _d("k_pq_q", "Km_pq / (M_q omega_n^2)", "Km_pq", "M_q", "omega_n"),
    _d("c_pq_q", "C_pq / (M_q omega_n)", "xi2", "Km_pq", "M_q", "omega_n"),
    _d("k_pq_p", "Km_pq / (M_p omega_n^2)", "Km_pq", "M_p", "omega_n"),
    _d("c_pq_p", "C_pq / (M_p omega_n)", "xi2", "Km_pq", "M_p", "omega_n"),
    _d("b_sq", "b_sq / b_c  (dimensionless backlash)", "b_sq", "b_c"),
    _d("b_pq", "b_pq / b_c", "b_pq", "b_c"),
    _d("E_sq_s", "E_sq cos(phase) / b_c  (meshing error, sine part)", "E_sq", "b_c"),
    _d("E_sq_c", "E_sq sin(phase) / b_c  (meshing error, cosine part)", "E_sq", "b_c"),
    _d("E_pq_s", "E_pq cos(phase) / b_c", "E_pq", "b_c"),
    _d("E_pq_c", "E_pq sin(phase) / b_c", "E_pq", "b_c"),
    _d("f_p0", "A1 / (M_p r_bp omega_n^2 b_c)  (mean load on the outside planet)",
       "A1", "M_p", "r_bp", "omega_n", "b_c"),
    _d("f_p1", "B1 / (M_p r_bp omega_n^2 b_c)", "B1", "M_p", "r_bp", "omega_n", "b_c"),
    _d("force_scale", "b_c omega_n^2 M_q  (mesh force per unit dimensionless deflection)",
       "b_c", "omega_n", "M_q", unit="N"),
    _structure("spare", "an unused slot of the coefficient vector"),
))


def catt_harmonics(n_harmonics: int) -> CoefficientBlock:
    """The relative-stiffness Fourier coefficients of one planet set's two meshes: ksq_a1,
    ksq_b1, ..., then kpq_a1, ... (cosine and sine parts of k(theta) / Km - 1)."""
    return CoefficientBlock(tuple(
        _d(f"{m}_{ab}{h}", f"{'cosine' if ab == 'a' else 'sine'} part of harmonic {h} of the "
           f"relative {m[1:]} mesh stiffness", "waveform", f"Ka_{m[1:]}", f"Km_{m[1:]}")
        for m in ("ksq", "kpq") for h in range(1, n_harmonics + 1) for ab in "ab"))


def _t(name: str, unit: str, meaning: str, constant: str, *inputs: str) -> Coefficient:
    kind = "derived" if inputs else "input"
    return Coefficient(name, unit, meaning, kind, inputs, constant=f"T_{constant}")


#: The header of the body-angle model's coefficient vector (SI).
THETA_HEADER = CoefficientBlock((
    _t("omega", "rad/s", "mesh frequency", "OMEGA"),
    _t("omega_L", "rad/s", "load-fluctuation frequency", "OMEGA_L"),
    Coefficient("n_sets", "1", "number of planet sets", "structure", constant="T_N"),
    Coefficient("n_harmonics", "1", "number of stiffness harmonics", "structure",
                constant="T_NH"),
    _t("T_D", "N m", "driving torque on the carrier", "TD"),
    _t("A1", "N m", "mean load torque on the outside planets", "A1"),
    _t("B1", "N m", "fluctuation of the outside planets' load torque", "B1"),
    _t("psi1", "rad", "phase of the outside-planet load fluctuation", "PSI1"),
    _t("A2", "N m", "mean load torque on the carrier", "A2"),
    _t("B2", "N m", "fluctuation of the carrier's load torque", "B2"),
    _t("psi2", "rad", "phase of the carrier load fluctuation", "PSI2"),
    _t("J_c", "kg m^2", "effective carrier inertia", "JC", "J_c", "m_q", "m_p", "r_c1", "r_c2"),
    _t("r_c1", "m", "carrier radius of the inside planets", "RC1"),
    _t("arm", "m", "lever arm of the sun mesh force on the carrier", "ARM", "r_bs",
       "pressure_angle"),
))
#: One planet set's block of the body-angle model (then its stiffness harmonics).
THETA_BLOCK = CoefficientBlock((
    _t("J_q", "kg m^2", "inside planet inertia", "JQ"),
    _t("J_p", "kg m^2", "outside planet inertia", "JP"),
    _t("r_bq", "m", "inside planet base radius", "RBQ", "pitch_radius", "pressure_angle"),
    _t("r_bp", "m", "outside planet base radius", "RBP", "pitch_radius", "pressure_angle"),
    _t("Km_sq", "N/m", "sun-inside mean mesh stiffness", "KM_SQ"),
    _t("Km_pq", "N/m", "inside-outside mean mesh stiffness", "KM_PQ"),
    _t("C_sq", "N s/m", "sun-inside mesh damping", "C_SQ", "xi1", "Km_sq", "M_s", "M_q"),
    _t("C_pq", "N s/m", "inside-outside mesh damping", "C_PQ", "xi2", "Km_pq", "M_p", "M_q"),
    _t("b_sq", "m", "sun-inside backlash half-width", "B_SQ"),
    _t("b_pq", "m", "inside-outside backlash half-width", "B_PQ"),
    _t("E_sq_s", "m", "sun-inside meshing error, sine part", "E_SQ_S", "E_sq", "error_phase"),
    _t("E_sq_c", "m", "sun-inside meshing error, cosine part", "E_SQ_C", "E_sq", "error_phase"),
    _t("E_pq_s", "m", "inside-outside meshing error, sine part", "E_PQ_S", "E_pq",
       "error_phase"),
    _t("E_pq_c", "m", "inside-outside meshing error, cosine part", "E_PQ_C", "E_pq",
       "error_phase"),
))


#: The dimensionless coefficients of Eq. (10), per planet set i, with their formulas (the
#: error amplitudes E_sq, E_pq enter the vector as sine and cosine parts).
COEFFICIENT_FORMULAS: dict[str, str] = {
    **{c.name: c.meaning for c in CATT_BLOCK.entries[:10]},
    "E_sq": "E_sq / b_c  (dimensionless meshing error)",
    "E_pq": "E_pq / b_c",
    **{c.name: c.meaning for c in CATT_BLOCK.entries[14:16]},
    **{c.name: c.meaning for c in CATT_HEADER.entries[4:6]},
}

_PER_PLANET = {"r_bq", "r_bp", "m_q", "m_p", "J_q", "J_p", "M_q", "M_p", "C_sq", "C_pq"}


@dataclass(frozen=True)
class Derived:
    """Derived quantities (SI); per-planet ones are arrays of length N."""

    r_bs: float
    r_bq: np.ndarray
    r_bp: np.ndarray
    m_s: float
    m_q: np.ndarray
    m_p: np.ndarray
    J_s: float
    J_q: np.ndarray
    J_p: np.ndarray
    M_s: float
    M_q: np.ndarray
    M_p: np.ndarray
    r_bc: float
    J_c_eff: float
    M_c: float
    arm: float
    omega_n: float
    C_sq: np.ndarray
    C_pq: np.ndarray
    gamma: float

    def as_dict(self) -> dict[str, float | np.ndarray]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def _disc_mass(gear) -> float:
    return gear.density * math.pi * gear.pitch_radius**2 * gear.face_width


def _base_radius(gear) -> float:
    if gear.base_radius is not None:
        return gear.base_radius
    return gear.pitch_radius * math.cos(gear.pressure_angle)


def derive(params: PlanetaryParams, interpretation: Interpretation = "consistent") -> Derived:
    """Compute every derived quantity, applying ``params.derived`` overrides on the way."""
    if interpretation not in INTERPRETATIONS:
        raise ValueError(
            f"interpretation must be one of {', '.join(INTERPRETATIONS)}; got {interpretation!r}"
        )
    n = params.n_planets
    sets = [params.planet_set(i) for i in range(n)]
    ov = params.derived
    values: dict[str, float | np.ndarray] = {}

    def put(name: str, value):
        if name in ov:
            value = np.full(n, ov[name]) if name in _PER_PLANET else float(ov[name])
        values[name] = value
        return value

    def per_planet(fn) -> np.ndarray:
        return np.array([fn(*s) for s in sets], dtype=float)

    sun = params.sun
    r_bs = put("r_bs", _base_radius(sun))
    r_bq = put("r_bq", per_planet(lambda sq, pq, q, p: _base_radius(q)))
    r_bp = put("r_bp", per_planet(lambda sq, pq, q, p: _base_radius(p)))
    put("m_s", sun.mass if sun.mass is not None else _disc_mass(sun))
    m_q = put("m_q", per_planet(lambda sq, pq, q, p: q.mass if q.mass else _disc_mass(q)))
    m_p = put("m_p", per_planet(lambda sq, pq, q, p: p.mass if p.mass else _disc_mass(p)))
    for label, gear in (("J_q", "inside planet"), ("J_p", "outside planet")):
        missing = [i for i, s in enumerate(sets) if s[2 if label == "J_q" else 3].inertia is None]
        if missing and label not in ov:
            raise ValueError(f"{gear} inertia is not given (planet set {missing[0] + 1})")
    J_q = put("J_q", per_planet(lambda sq, pq, q, p: q.inertia or math.nan))
    J_p = put("J_p", per_planet(lambda sq, pq, q, p: p.inertia or math.nan))
    J_s = put("J_s", sun.inertia if sun.inertia is not None else float(J_p[0]))
    M_s = put("M_s", J_s / r_bs**2)
    M_q = put("M_q", J_q / r_bq**2)
    M_p = put("M_p", J_p / r_bp**2)
    car = params.carrier
    r_bc = put("r_bc", car.r_bc if car.r_bc is not None else car.r_c1)
    if interpretation == "consistent":
        J_c_eff = car.inertia + float(np.sum(m_p * car.r_c2**2 + m_q * car.r_c1**2))
    elif interpretation == "carrier-only":
        J_c_eff = car.inertia
    else:
        J_c_eff = car.inertia + float(np.sum(m_p * car.r_c2 + m_q * car.r_c1))
    J_c_eff = put("J_c_eff", J_c_eff)
    M_c = put("M_c", J_c_eff / r_bc**2)
    put("arm", r_bs * math.cos(sun.pressure_angle))
    km_sq = np.array([s[0].mean_stiffness for s in sets])
    km_pq = np.array([s[1].mean_stiffness for s in sets])
    inv = 1.0 / M_s + 1.0 / M_c
    omega_n = math.sqrt(km_sq[0] * inv) if interpretation != "as-printed" else math.sqrt(
        km_sq[0] / inv
    )
    omega_n = put("omega_n", omega_n)
    xi1 = np.array([s[0].damping_ratio for s in sets])
    xi2 = np.array([s[1].damping_ratio for s in sets])
    put("C_sq", 2.0 * xi1 * np.sqrt(km_sq / (1.0 / M_s + 1.0 / M_q)))
    put("C_pq", 2.0 * xi2 * np.sqrt(km_pq / (1.0 / M_p + 1.0 / M_q)))
    put("gamma", 1.0 / omega_n if interpretation == "as-printed" else 1.0)
    return Derived(**values)  # type: ignore[arg-type]


def coefficients(params: PlanetaryParams, d: Derived) -> dict[str, np.ndarray | float]:
    """The dimensionless coefficients of Eq. (10) (see :data:`COEFFICIENT_FORMULAS`)."""
    n = params.n_planets
    sets = [params.planet_set(i) for i in range(n)]
    wn2 = d.omega_n**2
    car = params.carrier
    lever = car.r_c1 * d.arm / (d.M_c * d.r_bc**2)
    km_sq = np.array([s[0].mean_stiffness for s in sets])
    km_pq = np.array([s[1].mean_stiffness for s in sets])
    loads = params.loads
    bc = params.b_c
    torque_c = car.r_c1 / (d.M_c * d.r_bc**2 * wn2 * bc)
    torque_p = 1.0 / (d.M_p * d.r_bp * wn2 * bc)
    return {
        "k_sq_c": lever * km_sq / wn2,
        "c_sq_c": d.gamma * lever * d.C_sq / d.omega_n,
        "k_sq_q": km_sq / (d.M_q * wn2),
        "c_sq_q": d.C_sq / (d.M_q * d.omega_n),
        "k_pq_q": km_pq / (d.M_q * wn2),
        "c_pq_q": d.C_pq / (d.M_q * d.omega_n),
        "k_pq_p": km_pq / (d.M_p * wn2),
        "c_pq_p": d.C_pq / (d.M_p * d.omega_n),
        "b_sq": np.array([s[0].backlash for s in sets]) / bc,
        "b_pq": np.array([s[1].backlash for s in sets]) / bc,
        "E_sq": np.array([s[0].error for s in sets]) / bc,
        "E_pq": np.array([s[1].error for s in sets]) / bc,
        "f_p0": loads.A1 * torque_p,
        "f_p1": loads.B1 * torque_p,
        "f_c0": (loads.T_D - loads.A2) * torque_c,
        "f_c1": -loads.B2 * torque_c,
    }
