"""Validated parameters of the planetary gear train processing device (SI units).

Every physical field accepts a float in SI units or a unit string (``"50 um"``, ``"0.825e9 N/m"``,
``"20 deg"``). Unknown keys, NaN, infinities, wrong units and values outside the physical range
raise a :class:`pydantic.ValidationError` naming the field and the value.

Symbols follow the paper (Eqs. 1-14): ``sun_mesh`` is the sun-inside planet mesh (subscript sq),
``planet_mesh`` the inside-outside planet mesh (subscript pq). Backlash ``b`` is the half-width of
the dead zone of Eq. (3), so the total clearance is ``2 b``.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    create_model,
    model_validator,
)

from geardyn.core.inputs import PhysicalInput
from geardyn.errors import ParameterError, UnknownParameterError
from geardyn.models.planetary_coefficients import HARMONICS, N_PLANETS
from geardyn.units import to_si

_CONFIG = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, validate_default=True)


def _quantity(kind: str) -> BeforeValidator:
    return BeforeValidator(lambda v: to_si(v, kind) if v is not None else None)


def _not_boolean(v: Any) -> Any:
    if isinstance(v, bool):
        raise ValueError("expected a number, not a boolean")
    return v


#: Refuses ``true``/``false`` where a number is meant (pydantic would read them as 1 and 0).
NotBoolean = BeforeValidator(_not_boolean)
Whole = Annotated[int, NotBoolean]
Real = Annotated[float, NotBoolean]


def _acute(v: float) -> float:
    if not 0.0 < v < math.pi / 2:
        raise ValueError(
            f"pressure angle must lie strictly between 0 and 90 deg; {v!r} rad is outside"
            " (write e.g. '20 deg' for degrees)"
        )
    return v


Length = Annotated[float, _quantity("length"), Field(gt=0)]
Clearance = Annotated[float, _quantity("length"), Field(ge=0)]
Angle = Annotated[float, _quantity("angle")]
Stiffness = Annotated[float, _quantity("stiffness"), Field(gt=0)]
StiffnessAmplitude = Annotated[float, _quantity("stiffness"), Field(ge=0)]
Inertia = Annotated[float, _quantity("inertia"), Field(gt=0)]
Mass = Annotated[float, _quantity("mass"), Field(gt=0)]
Density = Annotated[float, _quantity("density"), Field(gt=0)]
Torque = Annotated[float, _quantity("torque")]
Ratio = Annotated[float, _quantity("dimensionless"), Field(ge=0)]


#: Every derived quantity of :mod:`geardyn.models.derived`, overridable by name through
#: ``PlanetaryParams.derived``: (unit, formula). Per-planet ones are arrays of length N.
DERIVED_FORMULAS: dict[str, tuple[str, str]] = {
    "r_bs": ("m", "sun base radius: given, else m z cos(alpha) / 2"),
    "r_bq": ("m", "inside planet base radius: given, else m z cos(alpha) / 2"),
    "r_bp": ("m", "outside planet base radius: given, else m z cos(alpha) / 2"),
    "m_s": ("kg", "sun mass: given, else density pi (m z/2)^2 face_width (solid disc)"),
    "m_q": ("kg", "inside planet mass: given, else solid disc at the pitch radius"),
    "m_p": ("kg", "outside planet mass: given, else solid disc at the pitch radius"),
    "J_s": ("kg m^2", "sun inertia: given, else J_p (same 40-tooth blank as the outside planet)"),
    "J_q": ("kg m^2", "inside planet inertia (Table 1)"),
    "J_p": ("kg m^2", "outside planet inertia (Table 1)"),
    "M_s": ("kg", "M_s = J_s / r_bs^2 (Eq. 11)"),
    "M_q": ("kg", "M_q = J_q / r_bq^2 (Eq. 11)"),
    "M_p": ("kg", "M_p = J_p / r_bp^2 (Eq. 11)"),
    "r_bc": ("m", "carrier reference radius: given, else r_c1"),
    "J_c_eff": (
        "kg m^2",
        "consistent: J_c + sum(m_p r_c2^2 + m_q r_c1^2); carrier-only: J_c;"
        " as-printed: J_c + sum(m_p r_c2 + m_q r_c1) (Eq. 1)",
    ),
    "M_c": ("kg", "M_c = J_c_eff / r_bc^2 (Eq. 11)"),
    "arm": ("m", "moment arm of each sun-planet mesh force on the carrier: r_bs cos(alpha)"),
    "omega_n": (
        "rad/s",
        "consistent, carrier-only: sqrt(Km_sq (1/M_s + 1/M_c));"
        " as-printed: sqrt(Km_sq / (1/M_s + 1/M_c)) (Eq. 9); Km_sq of planet set 1",
    ),
    "C_sq": ("N s/m", "C_sq = 2 xi1 sqrt(Km_sq / (1/M_s + 1/M_q)) (Eq. 6)"),
    "C_pq": ("N s/m", "C_pq = 2 xi2 sqrt(Km_pq / (1/M_p + 1/M_q)) (Eq. 6)"),
    "gamma": (
        "1",
        "factor on the carrier damping term of Eq. (10): 1; as-printed 1/omega_n (the typo)",
    ),
}

class Gear(BaseModel):
    """One gear blank. Base radius and mass are derived when not given (see ``derived``)."""

    model_config = _CONFIG

    teeth: Whole = Field(gt=0, description="number of teeth z")
    module: Length = Field(description="module m [m]")
    pressure_angle: Annotated[Angle, AfterValidator(_acute)] = Field(
        description="pressure angle alpha [rad]"
    )
    face_width: Length = Field(description="tooth (face) width [m]")
    base_radius: Length | None = Field(None, description="base radius r_b [m]; m z cos(alpha)/2")
    inertia: Inertia | None = Field(None, description="polar moment of inertia J [kg m^2]")
    mass: Mass | None = Field(None, description="mass [kg]; solid disc at the pitch radius")
    density: Density = Field(7850.0, description="material density [kg/m^3] (steel)")

    @property
    def pitch_radius(self) -> float:
        """Pitch radius m z / 2 [m]."""
        return self.module * self.teeth / 2.0


class Carrier(BaseModel):
    """The carrier: its own inertia and the radii of the planet-centre circles."""

    model_config = _CONFIG

    inertia: Inertia = Field(description="carrier inertia J_c [kg m^2]")
    r_c1: Length = Field(description="radius of the inside-planet centre circle [m]")
    r_c2: Length = Field(description="radius of the outside-planet centre circle [m]")
    r_bc: Length | None = Field(None, description="carrier reference radius r_bc [m]; r_c1")


class Mesh(BaseModel):
    """One tooth mesh: stiffness K(t) = Km + Ka w(wt + phi), backlash, error, damping ratio.

    ``waveform="sine"`` is Eq. (4) (w = sin). ``"rectangular"`` alternates between double and
    single tooth contact, the double-contact fraction of a mesh period being
    ``contact_ratio - 1``; it is represented by ``harmonics`` terms of its Fourier series with
    Lanczos sigma factors, so the right-hand side stays continuous in time. For both, Ka is half
    the peak-to-peak stiffness variation and Km the time average.
    """

    model_config = _CONFIG

    mean_stiffness: Stiffness = Field(description="mean mesh stiffness Km [N/m]")
    stiffness_amplitude: StiffnessAmplitude = Field(description="alternating stiffness Ka [N/m]")
    stiffness_phase: Angle = Field(0.0, description="stiffness phase varphi [rad]")
    waveform: Literal["sine", "rectangular"] = "sine"
    contact_ratio: Real = Field(1.6, gt=1.0, lt=2.0, description="contact ratio (rectangular)")
    harmonics: Whole = Field(25, **HARMONICS.bounds(),
                             description="Fourier terms of the rectangular wave")
    backlash: Clearance = Field(description="backlash half-width b [m]")
    error: Clearance = Field(description="meshing error amplitude E [m]")
    error_phase: Angle = Field(0.0, description="meshing error phase phi [rad]")
    damping_ratio: Ratio = Field(description="mesh damping ratio xi")

    @model_validator(mode="after")
    def _stiffness_stays_positive(self) -> Mesh:
        if self.waveform == "sine":
            k_min = self.mean_stiffness - self.stiffness_amplitude
        else:
            duty = self.contact_ratio - 1.0
            k_min = self.mean_stiffness - 2.0 * duty * self.stiffness_amplitude
        if k_min <= 0.0:
            raise ValueError(
                f"stiffness_amplitude {self.stiffness_amplitude:g} N/m makes the {self.waveform}"
                f" mesh stiffness negative (minimum {k_min:g} N/m); it must stay > 0"
            )
        return self


def _patch_model(name: str, base: type[BaseModel]) -> type[BaseModel]:
    """A model with the fields of ``base``, all optional: per-planet overrides."""
    fields: dict[str, Any] = {}
    for field_name, info in base.model_fields.items():
        typ = info.annotation
        if info.metadata:
            typ = Annotated[(typ, *info.metadata)]  # type: ignore[valid-type]
        fields[field_name] = (typ | None, None)
    return create_model(name, __config__=_CONFIG, **fields)


MeshPatch = _patch_model("MeshPatch", Mesh)
GearPatch = _patch_model("GearPatch", Gear)


class PlanetOverride(BaseModel):
    """What one planet set changes relative to the common values (mistuning, planet phasing)."""

    model_config = _CONFIG

    sun_mesh: MeshPatch = Field(default_factory=MeshPatch)  # type: ignore[valid-type]
    planet_mesh: MeshPatch = Field(default_factory=MeshPatch)  # type: ignore[valid-type]
    inside_planet: GearPatch = Field(default_factory=GearPatch)  # type: ignore[valid-type]
    outside_planet: GearPatch = Field(default_factory=GearPatch)  # type: ignore[valid-type]


class Loads(BaseModel):
    """Torques: input T_D; loads T_L1 = A1 + B1 sin(Lambda tau + psi1), T_L2 likewise (Eq. 14)."""

    model_config = _CONFIG

    T_D: Torque = Field(description="input torque on the carrier [N m]")
    A1: Torque = Field(description="mean load torque on each outside planet [N m]")
    B1: Torque = Field(0.0, description="fluctuating part of T_L1 [N m]")
    psi1: Angle = Field(0.0, description="phase of T_L1 [rad]")
    A2: Torque = Field(description="mean load torque on the carrier [N m]")
    B2: Torque = Field(0.0, description="fluctuating part of T_L2 [N m]")
    psi2: Angle = Field(0.0, description="phase of T_L2 [rad]")
    Lambda: Ratio = Field(0.0, description="load fluctuation frequency omega_l/omega_n")


def _paper(name: str, kind: str, meaning: str, paths: tuple[tuple[str, ...], ...],
           **kw: Any) -> tuple[PhysicalInput, tuple[tuple[str, ...], ...]]:
    """One of the paper's names: its declaration (a keyword of :meth:`PlanetaryParams.replace`
    and of a study's ``[params.changes]``, default the device's value) and the field paths it
    sets."""
    return PhysicalInput(name, kind, meaning, None, of="replace", **kw), paths


_SQ, _PQ = ("sun_mesh",), ("planet_mesh",)
#: The paper's names, declared once: each a physical input with the field paths it sets.
_PAPER = (
    _paper("xi1", "dimensionless", "damping ratio of the sun-planet meshes",
           (_SQ + ("damping_ratio",),), swept=True, explore=True),
    _paper("xi2", "dimensionless", "damping ratio of the planet-planet meshes",
           (_PQ + ("damping_ratio",),), swept=True, explore=True),
    _paper("xi", "dimensionless", "damping ratio of both meshes",
           (_SQ + ("damping_ratio",), _PQ + ("damping_ratio",)), swept=True),
    _paper("backlash", "length", "backlash half-width b of both meshes [m]",
           (_SQ + ("backlash",), _PQ + ("backlash",)), swept=True, explore=True),
    _paper("b_sq", "length", "backlash half-width of the sun-planet meshes [m]",
           (_SQ + ("backlash",),), swept=True),
    _paper("b_pq", "length", "backlash half-width of the planet-planet meshes [m]",
           (_PQ + ("backlash",),), swept=True),
    _paper("error", "length", "meshing error amplitude E of both meshes [m]",
           (_SQ + ("error",), _PQ + ("error",)), swept=True, explore=True),
    _paper("E_sq", "length", "meshing error amplitude of the sun-planet meshes [m]",
           (_SQ + ("error",),), swept=True),
    _paper("E_pq", "length", "meshing error amplitude of the planet-planet meshes [m]",
           (_PQ + ("error",),), swept=True),
    _paper("Km_sq", "stiffness", "mean stiffness of the sun-planet meshes [N/m]",
           (_SQ + ("mean_stiffness",),), swept=True),
    _paper("Km_pq", "stiffness", "mean stiffness of the planet-planet meshes [N/m]",
           (_PQ + ("mean_stiffness",),), swept=True),
    _paper("Ka", "stiffness", "alternating stiffness Ka of both meshes [N/m]",
           (_SQ + ("stiffness_amplitude",), _PQ + ("stiffness_amplitude",)), swept=True),
    _paper("Ka_sq", "stiffness", "alternating stiffness of the sun-planet meshes [N/m]",
           (_SQ + ("stiffness_amplitude",),), swept=True),
    _paper("Ka_pq", "stiffness", "alternating stiffness of the planet-planet meshes [N/m]",
           (_PQ + ("stiffness_amplitude",),), swept=True),
    _paper("waveform", "choice", "shape of both meshes' stiffness fluctuation",
           (_SQ + ("waveform",), _PQ + ("waveform",)), choices=("sine", "rectangular")),
    _paper("T_D", "torque", "input torque on the carrier [N m]", (("loads", "T_D"),),
           swept=True),
    _paper("A1", "torque", "mean load torque on each outside planet [N m]",
           (("loads", "A1"),), swept=True),
    _paper("A2", "torque", "mean load torque on the carrier [N m]", (("loads", "A2"),),
           swept=True),
    _paper("B1", "torque", "fluctuating part of the load torque T_L1 [N m]",
           (("loads", "B1"),), swept=True, explore=True),
    _paper("B2", "torque", "fluctuating part of the load torque T_L2 [N m]",
           (("loads", "B2"),), swept=True),
    _paper("psi1", "angle", "phase of T_L1 [rad]", (("loads", "psi1"),), swept=True),
    _paper("psi2", "angle", "phase of T_L2 [rad]", (("loads", "psi2"),), swept=True),
    _paper("Lambda", "dimensionless", "load fluctuation frequency omega_l / omega_n",
           (("loads", "Lambda"),), swept=True, explore=True),
    _paper("N", "count", "number of planet sets", (("n_planets",),)),
    _paper("b_c", "length", "nominal displacement b_c [m]", (("b_c",),), swept=True),
)
#: The device's physical inputs by the paper's symbols (:class:`PhysicalInput`), declared once:
#: ``CATTDevice.with_params`` re-derives the coefficients from them, a sweep takes the swept ones
#: (their axes in the declared kinds' SI units; not the choice waveform, nor the count N, whose
#: sweep is deprecated) and the explorer offers the ``explore`` ones.
PAPER_INPUTS: tuple[PhysicalInput, ...] = tuple(i for i, _ in _PAPER)
#: Names a user may use to change parameters (the paper's symbols), mapped to field paths.
PAPER_NAMES: dict[str, tuple[tuple[str, ...], ...]] = {i.name: paths for i, paths in _PAPER}


class PlanetaryParams(BaseModel):
    """All parameters of the CATT planetary gear train processing device (Tables 1 and 2).

    ``planets`` is empty (N identical planet sets) or holds one :class:`PlanetOverride` per
    planet set. ``derived`` overrides derived quantities by name (see
    :data:`geardyn.models.derived.DERIVED_FORMULAS`), e.g. ``{"omega_n": 3.0e4}``.
    """

    model_config = _CONFIG

    n_planets: Whole = Field(4, **N_PLANETS.bounds(), description="number of planet sets N")
    sun: Gear
    inside_planet: Gear
    outside_planet: Gear
    carrier: Carrier
    sun_mesh: Mesh
    planet_mesh: Mesh
    loads: Loads
    b_c: Length = Field(1.0e-5, description="nominal displacement b_c [m]")
    planets: list[PlanetOverride] = Field(default_factory=list)
    derived: dict[str, Annotated[Real, Field(gt=0)]] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _check_planets_and_overrides(self) -> PlanetaryParams:
        if self.planets and len(self.planets) != self.n_planets:
            raise ValueError(
                f"planets lists {len(self.planets)} planet sets but n_planets is {self.n_planets}"
            )
        unknown = sorted(set(self.derived) - set(DERIVED_FORMULAS))
        if unknown:
            raise ValueError(
                f"derived: unknown quantity {unknown[0]!r}; known: {', '.join(DERIVED_FORMULAS)}"
            )
        for i in range(len(self.planets)):
            self.planet_set(i)  # validates the merged values of every planet set
        return self

    # ----------------------------------------------------------------- planet sets
    def planet_set(self, i: int) -> tuple[Mesh, Mesh, Gear, Gear]:
        """The resolved (sun mesh, planet mesh, inside planet, outside planet) of planet set i."""
        if not self.planets:
            return self.sun_mesh, self.planet_mesh, self.inside_planet, self.outside_planet
        o = self.planets[i]
        merged = []
        for base, patch in (
            (self.sun_mesh, o.sun_mesh),
            (self.planet_mesh, o.planet_mesh),
            (self.inside_planet, o.inside_planet),
            (self.outside_planet, o.outside_planet),
        ):
            changes = patch.model_dump(exclude_none=True)
            merged.append(type(base).model_validate({**base.model_dump(), **changes}))
        return tuple(merged)  # type: ignore[return-value]

    @property
    def identical_planets(self) -> bool:
        """True when every planet set has the same parameters (the reduced model applies)."""
        first = self.planet_set(0)
        return all(self.planet_set(i) == first for i in range(1, self.n_planets))

    # ----------------------------------------------------------------- changes
    def replace(self, **changes: Any) -> PlanetaryParams:
        """A copy with parameters changed, by the paper's names (``xi1``, ``backlash``, ``B1``,
        ``Lambda``, ``N``, ...; see :data:`PAPER_NAMES`) or by field name at the top level.

        Common values change; per-planet overrides of the same field are kept.
        """
        data = self.model_dump()
        for name, value in changes.items():
            if name in PAPER_NAMES:
                paths = PAPER_NAMES[name]
            elif name in type(self).model_fields:
                paths = ((name,),)
            else:
                known = ", ".join(sorted(PAPER_NAMES))
                raise UnknownParameterError(name, value, f"unknown parameter; known names: {known}")
            for path in paths:
                target = data
                for key in path[:-1]:
                    target = target[key]
                if not isinstance(target, dict):  # the table itself was changed to a non-table
                    raise ParameterError(name, value, f"cannot change it when {path[0]} is "
                                         f"{target!r}, not a table")
                target[path[-1]] = value
        return type(self).model_validate(data)

    @classmethod
    def paper(cls, **changes: Any) -> PlanetaryParams:
        """Table 1 and Table 2 of the paper (xi1 = xi2 = 0.05, B1 = B2 = 0), then ``changes``.

        Undisclosed quantities (planet masses, sun inertia, r_bc) are derived as
        ``shared/model-notes.md`` describes: solid steel discs at the pitch radius, J_s = J_p,
        r_bc = r_c1.
        """
        gear = {"module": "3 mm", "pressure_angle": "20 deg", "face_width": "15 mm"}
        base = cls(
            n_planets=4,
            sun=Gear(teeth=40, base_radius="56.38 mm", **gear),
            inside_planet=Gear(teeth=30, base_radius="42.29 mm", inertia=7.13e-4, **gear),
            outside_planet=Gear(teeth=40, base_radius="56.38 mm", inertia=0.002, **gear),
            carrier=Carrier(inertia=7.58e-3, r_c1="105 mm", r_c2="210 mm"),
            sun_mesh=Mesh(
                mean_stiffness="0.825e9 N/m",
                stiffness_amplitude="0.2e9 N/m",
                backlash="0.05 mm",
                error="0.01 mm",
                damping_ratio=0.05,
            ),
            planet_mesh=Mesh(
                mean_stiffness="1.0e9 N/m",
                stiffness_amplitude="0.2e9 N/m",
                backlash="0.05 mm",
                error="0.01 mm",
                damping_ratio=0.05,
            ),
            loads=Loads(T_D="1500 N m", A1="600 N m", A2="900 N m"),
            b_c="0.01 mm",
        )
        return base.replace(**changes) if changes else base
