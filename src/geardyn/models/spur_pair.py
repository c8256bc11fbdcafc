"""A spur gear pair built from its geometry, in SI units, with the potential-energy mesh stiffness.

One degree of freedom, the mesh deflection x [m] along the line of action (x = r_b1 theta_1 -
r_b2 theta_2 - e(t), the dynamic transmission error less the static one), time t [s]:

    m x'' + c x' + f(x, theta) = T1 / r_b1 + m e_a (N Omega)^2 cos(N theta + phi_e)

    f = k_d(theta) (x - b)   x > b    (drive flanks in contact)
        0                    |x| <= b (the dead zone of the backlash, 2b wide)
        k_c(theta) (x + b)   x < -b   (coast flanks in contact)

m the equivalent mass I1 I2 / (I1 r_b2^2 + I2 r_b1^2), c = 2 zeta sqrt(k_mean m) (k_mean the mean
drive stiffness; the damping acts in and out of contact), T1 the pinion torque, e_a cos(N theta
+ phi_e) the static transmission error at the mesh frequency. theta = Omega t is the forcing
phase: the rotation angle of the gear whose revolution is the forcing period (the pinion, or the
wheel for a fault on the wheel; or one mesh cycle, N = 1), N the mesh cycles per period (the
gear's teeth). At theta = 0 tooth 0 of either gear passes the pitch point (the stiffness table's
angle 0, see :func:`~geardyn.gears.potential_energy_stiffness`).

The flanks' stiffnesses k_d, k_c [N/m] are the potential-energy mesh stiffness of the drive and
the coast flanks over one forcing period, as truncated Fourier series in theta,

    k(theta) = k0 + sum_{h=1..H} a_h cos(h theta) + b_h sin(h theta),

the discrete Fourier series of the table (uniform in the pinion angle) cut after H harmonics of
Omega (default H = ``DEFAULT_MESH_HARMONICS`` N: every sideband up to the 16th mesh harmonic).
The series is smooth in time, so fixed-step RK4 keeps its order between the dead-zone edges (the
events x - b and x + b); the table's jumps where a tooth pair enters or leaves contact are
rounded over about 1/H of the period (the truncation error is largest there: see
:meth:`SpurPair.stiffness_error`). A tooth fault on one tooth of the periodic gear is then felt
once per forcing period.

``stiffness_form="table"`` evaluates the table itself instead, linear between its angles
(theta_j = 2 pi j / n over the period): O(1) per evaluation instead of O(H), and the jumps stay
jumps one table interval wide (no Gibbs ringing), exact at the table's angles. The step rule
then resolves the contact mode only (the series' top harmonic sets no step); RK4 loses its
order across a jump, so its error is set by the step there (a step-convergence study in
``docs/datasets.md``).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence

import numpy as np
import xarray as xr

from geardyn.core.capabilities import Capabilities, FaultDatasetInputs
from geardyn.core.coefficients import CoefficientLayout
from geardyn.core.model import Model
from geardyn.core.plan import STEPS_PER_FASTEST_MODE, STEPS_PER_OTHER_FORCING
from geardyn.errors import ParameterError
from geardyn.gears.geometry import GearMesh
from geardyn.gears.iso6336_kv import KvMeshGroup, reduced_mass
from geardyn.gears.potential_energy import (
    DEFAULT_NODES,
    STEEL_POISSON,
    STEEL_YOUNG,
    potential_energy_stiffness,
)
from geardyn.models.spur_pair_coefficients import (
    HEADER,
    INPUTS,
    PERIODS,
    PHYSICAL_NAMES,
    SPEED_UNITS,
    STIFFNESS_FORMS,
    UNIT_KINDS,
    series_block,
    table_block,
)
from geardyn.models.spur_pair_kernels import (
    BACKLASH,
    K_MEAN,
    KERNEL,
    MASS,
    OMEGA,
    R_B1,
    TORQUE,
)
from geardyn.units import si_value

__all__ = ["DEFAULT_MESH_HARMONICS", "STEEL_DENSITY", "SpurPair", "disc_inertia"]

#: Harmonics of the mesh frequency each flank's series keeps by default (H = this times the
#: mesh cycles per period).
DEFAULT_MESH_HARMONICS = 16
#: Density of steel [kg/m^3] of the default (solid disc) inertias.
STEEL_DENSITY = 7850.0
#: rad/s per rpm.
_RPM = SPEED_UNITS["rpm"]


# ---------------------------------------------------------------------------------------------
# the table -> the series

def period_cycles(mesh: GearMesh, period: str) -> int:
    """The mesh cycles of one forcing ``period`` (:data:`PERIODS`) of ``mesh``."""
    if period not in PERIODS:
        raise ParameterError("period", period, f"must be one of {', '.join(PERIODS)}")
    return {"pinion": mesh.pinion.teeth, "wheel": mesh.wheel.teeth, "mesh": 1}[period]


def disc_inertia(gear_radius: float, face_width: float, bore_radius: float,
                 density: float = STEEL_DENSITY) -> float:
    """Polar moment of inertia [kg m^2] of a disc of ``gear_radius`` with a bore of
    ``bore_radius`` [m], ``face_width`` [m] thick: pi rho b (r^4 - r_i^4) / 2."""
    return 0.5 * math.pi * density * face_width * (gear_radius ** 4 - bore_radius ** 4)


def _period_cycles(stiffness: xr.Dataset) -> int:
    """The whole number of mesh cycles the table spans (uniform in the angle from 0)."""
    if "cycle" not in stiffness.coords or "mesh_stiffness" not in stiffness:
        raise ParameterError("stiffness", type(stiffness).__name__,
                             "must be a potential_energy_stiffness dataset (mesh_stiffness over"
                             " cycle)")
    cyc = np.asarray(stiffness["cycle"].values, dtype=float)
    step = cyc[1] - cyc[0] if cyc.size > 1 else 0.0
    span = cyc.size * step
    if (cyc.size < 8 or cyc[0] != 0.0 or not step > 0
            or not np.allclose(np.diff(cyc), step, rtol=1e-9, atol=0.0)
            or abs(span - round(span)) > 1e-9 * span):
        raise ParameterError("stiffness", f"{cyc.size} angles",
                             "the table must be uniform in the angle from cycle 0 over a whole "
                             "number of mesh cycles (potential_energy_stiffness with an integer"
                             " angles)")
    return int(round(span))


def _faulty_gear(stiffness: xr.Dataset) -> str | None:
    """The gear the table's faults sit on (its ``faulty_gears`` attribute), None if healthy;
    faults on both gears repeat only over the hunting period, which one gear's revolution does
    not span."""
    gears = [g for g in str(stiffness.attrs.get("faulty_gears", "")).split(",") if g]
    if len(gears) > 1:
        raise ParameterError("stiffness", stiffness.attrs.get("faults"),
                             "faults on both gears: SpurPair's period is one revolution of the"
                             " one faulty gear")
    return gears[0] if gears else None


def fourier_series(table: np.ndarray, harmonics: int) -> np.ndarray:
    """(k0, a1, b1, ..., aH, bH) of the table's discrete Fourier series, cut after ``harmonics``
    (the samples uniform over one period from phase 0)."""
    F = np.fft.rfft(np.asarray(table, dtype=float)) / table.size
    out = np.empty(1 + 2 * harmonics)
    out[0] = F[0].real
    out[1::2] = 2.0 * F[1:harmonics + 1].real
    out[2::2] = -2.0 * F[1:harmonics + 1].imag
    return out


def evaluate_series(series: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """k(theta) of a series (k0, a1, b1, ...) at the phases ``theta`` [rad]."""
    th = np.asarray(theta, dtype=float)
    h = np.arange(1, (series.size - 1) // 2 + 1)
    arg = h[:, None] * th.reshape(-1)[None, :]
    k = series[0] + series[1::2] @ np.cos(arg) + series[2::2] @ np.sin(arg)
    return k.reshape(th.shape)


def _harmonics(value: object, cycles: int, samples: int) -> int:
    if value is None:
        value = DEFAULT_MESH_HARMONICS * cycles
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise ParameterError("harmonics", value, "must be a whole number >= 1")
    if 2 * int(value) >= samples:
        raise ParameterError("harmonics", value,
                             f"the table has {samples} angles per period: at most "
                             f"{(samples - 1) // 2} harmonics (give more angles per mesh cycle)")
    return int(value)


class SpurPair(Model):
    """A spur gear pair in SI units whose mesh stiffness is the potential-energy stiffness of its
    geometry, drive and coast flank (module docstring for the equation).

    Build it with :meth:`from_geometry` (the stiffness computed here) or from a stiffness table of
    :func:`~geardyn.gears.potential_energy_stiffness` over whole mesh cycles (``angles`` an
    integer): the forcing period is the table's span, ``cycles`` mesh cycles (the pinion's teeth
    for one pinion revolution). State x [m], v [m/s]; time [s]; the observable F [N] is the mesh
    force (elastic and damping). The forcing frequency ``Omega`` [rad/s] is the rotation
    frequency of the gear whose revolution is the period (mesh frequency / cycles); ``speed``
    (the pinion's speed, a number in ``speed_unit`` or a unit string) sets it through
    ``with_params`` and sweeps. The physical inputs are declared once,
    :data:`~geardyn.models.spur_pair_coefficients.INPUTS` (the ``spur_pair`` study table is
    generated from them).

    Parameters
    ----------
    mesh
        The :class:`~geardyn.gears.GearMesh` the table was computed for.
    stiffness
        The potential-energy stiffness table (``mesh_stiffness`` and ``mesh_stiffness_coast``
        [N/m] over ``cycle``).
    speed
        Pinion speed: a number in ``speed_unit``, or a unit string (``"1500 rpm"``).
    torque
        Pinion torque [N m] (or ``"200 N m"``); > 0 loads the drive flanks.
    inertia
        (I1, I2) [kg m^2] of pinion and wheel; default solid steel discs of the reference radius,
        the face width and the bore of the table (:func:`disc_inertia`).
    zeta
        Damping ratio (c = 2 zeta sqrt(k_mean m)).
    backlash
        Backlash half-width b [m] along the line of action (the dead zone is 2b wide); default
        half the mesh's backlash on the line of action, j cos(alpha_w) / 2.
    error, error_phase
        Static transmission error amplitude [m] at the mesh frequency, and its phase [rad].
    harmonics
        Harmonics H of Omega in each flank's series (default ``DEFAULT_MESH_HARMONICS`` times
        the mesh cycles per period); fewer than half the table's angles. The Fourier form's
        only (the table form refuses it).
    stiffness_form
        How the kernels evaluate each flank's stiffness: ``"fourier"`` (default) its series of
        ``harmonics`` harmonics, smooth in time, the table's jumps rounded over 1/H of the
        period; ``"table"`` the table, linear between its angles (jumps one angle wide, O(1) per
        evaluation: several times faster, see ``docs/datasets.md``).
    speed_unit
        The unit of a plain number of ``speed`` (here, in ``with_params`` and in
        ``lane_params``/sweeps of ``speed``) and of a sweep's ``speed`` axis: ``"rad/s"``
        (default), ``"rpm"`` or ``"Hz"`` (:data:`SPEED_UNITS`); each number is converted to rad/s
        once, by the unit's exact factor.
    """

    name = "SpurPair"
    state_names = ("x", "v")
    state_units = "m, m/s"
    time_unit = "s"
    event_names = ("x-b", "x+b")
    observable_names = ("F",)
    observable_units = "N"
    meshes = (("mesh", 0, 1),)
    capabilities = Capabilities(mesh_forces=True, physical_axes=True, dynamic_factor=True,
                                natural_frequencies="rad/time", stiffness_tables="pair",
                                fault_dataset=FaultDatasetInputs(
                                    "speed", "torque", "mesh_force", speed_unit=None,
                                    stiffness_error=True))
    input_declarations = INPUTS
    #: ``speed`` (it re-derives Omega); the other swept inputs are coefficients of their names
    #: (:data:`~geardyn.models.spur_pair_coefficients.PHYSICAL_NAMES`).
    physical_names = PHYSICAL_NAMES

    def __init__(self, mesh: GearMesh, stiffness: xr.Dataset, *, speed: object,
                 torque: object, inertia: Sequence[object] | None = None, zeta: object = 0.05,
                 backlash: object = None, error: object = 0.0, error_phase: object = 0.0,
                 harmonics: int | None = None, speed_unit: str = "rad/s",
                 stiffness_form: str = "fourier"):
        if not isinstance(mesh, GearMesh):
            raise ParameterError("mesh", mesh, "must be a geardyn.gears.GearMesh")
        if mesh.internal:
            raise ParameterError("mesh.internal", True, "SpurPair takes an external pair")
        cycles = _period_cycles(stiffness)
        faulty = _faulty_gear(stiffness)
        if faulty is not None:
            z = (mesh.pinion if faulty == "pinion" else mesh.wheel).teeth
            if cycles % z:
                raise ParameterError("stiffness", f"{cycles} mesh cycles",
                                     f"a fault on the {faulty} returns every {z} mesh cycles;"
                                     " the table must span whole revolutions of that gear")
        if stiffness_form not in STIFFNESS_FORMS:
            raise ParameterError("stiffness_form", stiffness_form,
                                 f"must be one of {', '.join(STIFFNESS_FORMS)}")
        if stiffness_form == "table" and harmonics is not None:
            raise ParameterError("harmonics", harmonics, "sets the Fourier form's series; the"
                                 " table form evaluates the table itself (leave it out)")
        self.stiffness_form = stiffness_form
        n_h = (0 if stiffness_form == "table"  # no series: its mean k0 only
               else _harmonics(harmonics, cycles, int(stiffness.sizes["angle"])))
        if speed_unit not in SPEED_UNITS:
            raise ParameterError("speed_unit", speed_unit,
                                 f"must be one of {', '.join(SPEED_UNITS)}")
        self.speed_unit = speed_unit
        self.mesh, self.stiffness, self.cycles = mesh, stiffness, cycles
        self.drive_series = fourier_series(stiffness["mesh_stiffness"].values, n_h)
        self.coast_series = fourier_series(stiffness["mesh_stiffness_coast"].values, n_h)
        if stiffness_form == "fourier":
            self._check_positive()
        b = (0.5 * max(mesh.backlash, 0.0) * math.cos(mesh.operating_pressure_angle)
             if backlash is None else si_value("backlash", backlash, "length"))
        values = {
            "Omega": self._omega_of_speed(self._speed_si(speed)),
            "mass": self._mass(inertia),
            "torque": si_value("torque", torque, "torque"),
            "zeta": si_value("zeta", zeta, "dimensionless"),
            "backlash": b,
            "error": si_value("error", error, "length"),
            "error_phase": si_value("error_phase", error_phase, "angle"),
            "k_mean": float(self.drive_series[0]),
            "cos_error_phase": 0.0, "sin_error_phase": 0.0,
            "base_radius": mesh.pinion.base_radius, "mesh_order": float(cycles),
            "n_harmonics": float(n_h),
            "stiffness_form": STIFFNESS_FORMS[stiffness_form],
        }
        if stiffness_form == "table":
            n_t = int(stiffness.sizes["angle"])
            values["table_points"] = float(n_t)
            layout = CoefficientLayout.of(HEADER, table_block("kd", n_t), table_block("kc", n_t),
                                          model=self.name)
            for flank, var in (("kd", "mesh_stiffness"), ("kc", "mesh_stiffness_coast")):
                for j, v in enumerate(np.asarray(stiffness[var].values, dtype=float)):
                    values[f"{flank}_t{j}"] = float(v)
        else:
            values["table_points"] = 0.0
            layout = CoefficientLayout.of(HEADER, series_block("kd", n_h),
                                          series_block("kc", n_h), model=self.name)
            for flank, series in (("kd", self.drive_series), ("kc", self.coast_series)):
                values[f"{flank}0"] = float(series[0])
                for h in range(1, n_h + 1):
                    values[f"{flank}_a{h}"] = float(series[2 * h - 1])
                    values[f"{flank}_b{h}"] = float(series[2 * h])
        inputs = ("Omega", "mass", "torque", "zeta", "backlash", "error", "error_phase")
        layout.validate({k: values[k] for k in inputs})
        self.coefficient_layout = layout
        self.params = layout.fill_derived(layout.build(values))
        self.omega_index = OMEGA
        self.kernel = KERNEL

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_geometry(cls, mesh: GearMesh, *, bore_radius: object, speed: object,
                      torque: object, faults: object = (), period: str | None = None,
                      angles: int = 256, young: object = STEEL_YOUNG,
                      poisson: object = STEEL_POISSON, root_segment: bool = True,
                      nodes: int = DEFAULT_NODES, **dynamics: object) -> SpurPair:
        """The pair with the potential-energy stiffness of ``mesh``
        (:func:`~geardyn.gears.potential_energy_stiffness` with ``bore_radius``, ``young``,
        ``poisson``, ``root_segment``, ``nodes``, ``faults`` (one fault object or several, all
        on one gear), ``angles`` per mesh cycle) over one
        ``period``: ``"pinion"`` (one pinion revolution, the default for a healthy pair or faults
        on the pinion: a faulty tooth is felt once per period), ``"wheel"`` (one wheel
        revolution; the default for faults on the wheel) or ``"mesh"`` (one mesh cycle, a
        healthy pair only). ``dynamics``: the constructor's other keywords (inertia, zeta,
        backlash, error, error_phase, harmonics, speed_unit)."""
        if not isinstance(mesh, GearMesh):
            raise ParameterError("mesh", mesh, "must be a geardyn.gears.GearMesh")
        listed = tuple(faults) if isinstance(faults, (list, tuple)) else (faults,)
        gears = sorted({getattr(f, "gear", None) for f in listed} - {None})
        for f in listed:
            if getattr(f, "gear", "pinion") not in ("pinion", "wheel"):
                raise ParameterError(f"{f.kind}.gear", f.gear, "a pair's faults lie on the "
                                     "'pinion' or the 'wheel'")
        if len(gears) > 1:
            raise ParameterError("faults", faults, "faults on both gears: SpurPair's period is"
                                 " one revolution of the one faulty gear")
        if period is None:
            period = gears[0] if gears else "pinion"
        cycles = period_cycles(mesh, period)
        if gears and period != gears[0]:
            raise ParameterError("period", period, f"the faults are on the {gears[0]}: the "
                                 f"period must be one {gears[0]} revolution")
        table = potential_energy_stiffness(mesh, bore_radius=bore_radius, angles=angles,
                                           young=young, poisson=poisson, faults=faults,
                                           cycles=cycles, root_segment=root_segment,
                                           nodes=nodes)
        return cls(mesh, table, speed=speed, torque=torque, **dynamics)

    def _speed_si(self, value: object) -> float:
        """The pinion speed [rad/s] of ``value``: a unit string, or a number in
        ``speed_unit`` (times its exact factor, once)."""
        if isinstance(value, str):
            return si_value("speed", value, "frequency")
        return si_value("speed", value, "frequency") * SPEED_UNITS[self.speed_unit]

    def _omega_of_speed(self, speed: float) -> float:
        """Omega [rad/s] at the pinion speed ``speed`` [rad/s]: mesh frequency / cycles."""
        if not speed >= 0.0:
            raise ParameterError("speed", speed, "must be >= 0")
        return speed * self.mesh.pinion.teeth / self.cycles

    def _mass(self, inertia: Sequence[object] | None) -> float:
        mesh, attrs = self.mesh, self.stiffness.attrs
        if inertia is None:
            width = attrs.get("face_width_m", min(mesh.pinion.face_width, mesh.wheel.face_width))
            i1 = disc_inertia(mesh.pinion.reference_radius, width,
                              float(attrs.get("pinion_bore_radius_m", 0.0)))
            i2 = disc_inertia(mesh.wheel.reference_radius, width,
                              float(attrs.get("wheel_bore_radius_m", 0.0)))
        else:
            if isinstance(inertia, str) or len(inertia) != 2:
                raise ParameterError("inertia", inertia, "give (I1, I2) of pinion and wheel")
            i1, i2 = (si_value(f"inertia[{k}]", v, "inertia") for k, v in enumerate(inertia))
            for k, v in enumerate((i1, i2)):
                if not v > 0.0:
                    raise ParameterError(f"inertia[{k}]", v, "must be > 0")
        self.inertia = (i1, i2)
        r1, r2 = mesh.pinion.base_radius, mesh.wheel.base_radius
        return i1 * i2 / (i1 * r2 * r2 + i2 * r1 * r1)

    def _check_positive(self) -> None:
        """A flank whose table is positive at every angle must keep a positive series there
        (else more harmonics are needed). A table that falls to 0 (a missing tooth: no pair in
        contact over part of its passage) is taken: the kernels clip the series at 0
        (:meth:`stiffness_at`), so its ringing below 0 about the gap carries no force."""
        theta = self.table_phase()
        for name, series, var in (("drive", self.drive_series, "mesh_stiffness"),
                                  ("coast", self.coast_series, "mesh_stiffness_coast")):
            if float(np.min(self.stiffness[var].values)) <= 0.0:
                continue
            low = float(np.min(evaluate_series(series, theta)))
            if not low > 0.0:
                raise ParameterError("harmonics", (series.size - 1) // 2,
                                     f"the {name}-flank series falls to {low:.4g} N/m <= 0 on "
                                     "the table's angles; keep more harmonics")

    # ------------------------------------------------------------------ parameters
    def with_params(self, **values: object) -> SpurPair:
        """As :meth:`Model.with_params`; ``speed`` (the pinion's, a number in
        ``speed_unit`` or a unit string such as ``"3000 rpm"``) sets Omega, and the inputs
        take unit strings (``torque="80 N m"``, ``backlash="20 um"``)."""
        return super().with_params(**{k: self._si(k, v) for k, v in values.items()})

    def _si(self, name: str, value: object) -> object:
        """``value`` in SI (speed in rad/s) where ``name`` is an input that takes a unit
        string (:data:`~geardyn.models.spur_pair_coefficients.UNIT_KINDS`)."""
        if name == "speed":
            return self._speed_si(value)
        if isinstance(value, str) and name in UNIT_KINDS:
            return si_value(name, value, UNIT_KINDS[name])
        return value

    def _with_physical(self, values: dict[str, float]) -> SpurPair:
        out = copy.copy(self)
        p = self.params.copy()
        p[OMEGA] = self._omega_of_speed(float(values["speed"]))
        out.params = p
        return out

    def lane_params(self, name: str, values: Sequence[float] | np.ndarray) -> np.ndarray:
        """Coefficient vectors with ``name`` set to ``values`` (``speed``: the pinion speed in
        ``speed_unit`` sets Omega)."""
        if name == "speed":
            speeds = np.asarray(values, dtype=float).ravel()
            omegas = [self._omega_of_speed(self._speed_si(float(v))) for v in speeds]
            return Model.lane_params(self, "Omega", omegas)
        return Model.lane_params(self, name, values)

    def param_attrs(self, name: str) -> dict[str, str]:
        if name == "speed":
            return {"units": self.speed_unit, "long_name": "pinion speed"}
        return super().param_attrs(name)

    # ------------------------------------------------------------------ physics
    @property
    def n_harmonics(self) -> int:
        """H: harmonics of Omega in each flank's stiffness series (0 in the table form)."""
        return (self.drive_series.size - 1) // 2

    @property
    def speed(self) -> float:
        """The pinion speed [rad/s] at the model's Omega."""
        return self.omega * self.cycles / self.mesh.pinion.teeth

    @property
    def mesh_frequency(self) -> float:
        """The mesh frequency [rad/s]: cycles times Omega."""
        return self.omega * self.cycles

    def mean_force(self) -> float:
        """The mean mesh force T1 / r_b1 [N]."""
        return float(self.params[TORQUE] / self.params[R_B1])

    def static_mesh_forces(self) -> np.ndarray:
        """The static mesh force T1 / r_b1 [N] (the dynamic factor's reference)."""
        return np.array([self.mean_force()])

    # ------------------------------------------------------------------ ISO 6336-1 K_v
    @property
    def input_torque(self) -> float:
        """The pinion torque T1 [N m]."""
        return float(self.params[TORQUE])

    def at_input_torque(self, torque: float) -> SpurPair:
        """The pair at pinion torque ``torque`` [N m]."""
        return self.with_params(torque=float(torque))

    def kv_groups(self, torque: float) -> tuple[KvMeshGroup, ...]:
        """One group, ``"mesh"``: F_t = T1 / r1 (r1 the pinion's reference radius), m_red from
        the model's inertias (:func:`~geardyn.gears.iso6336_kv.reduced_mass`), gear 1 the
        pinion."""
        mesh = self.mesh
        b = min(mesh.pinion.face_width, mesh.wheel.face_width)
        i1, i2 = self.inertia
        m_red = reduced_mass(i1, i2, mesh.pinion.base_radius, mesh.wheel.base_radius, b)
        return (KvMeshGroup("mesh", mesh, (0,), float(torque) / mesh.pinion.reference_radius,
                            m_red, 1.0, float(self.drive_series[0])),)

    def input_speed_sweep(self, rpm: np.ndarray) -> tuple[str, np.ndarray]:
        """``speed`` in the model's ``speed_unit`` at pinion speeds ``rpm``."""
        return "speed", np.asarray(rpm, dtype=float) * SPEED_UNITS["rpm"] \
            / SPEED_UNITS[self.speed_unit]

    def mesh_frequency_per_input_speed(self) -> float:
        """The mesh order: the pinion's teeth."""
        return float(self.mesh.pinion.teeth)

    def natural_frequencies(self) -> np.ndarray:
        """sqrt(k_mean / m) [rad/s]: the natural frequency in drive-flank contact."""
        return np.array([math.sqrt(self.params[K_MEAN] / self.params[MASS])])

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """The fastest frequency the step resolves [rad/s], per lane of ``P``: the natural
        frequency at the tabulated peak stiffness of either flank, sqrt(k_max / m), or, where
        faster, the top stiffness harmonic H Omega scaled so that its period gets at least
        ``STEPS_PER_OTHER_FORCING`` steps (the Fourier form only)."""
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        k_max = max(float(self.stiffness["mesh_stiffness"].max()),
                    float(self.stiffness["mesh_stiffness_coast"].max()))
        if self.stiffness_form == "table":  # no series: the contact mode alone
            return np.sqrt(k_max / P[:, MASS])
        top = self.n_harmonics * P[:, OMEGA] * (STEPS_PER_OTHER_FORCING
                                                / STEPS_PER_FASTEST_MODE)
        return np.maximum(np.sqrt(k_max / P[:, MASS]), top)

    def initial_state(self) -> np.ndarray:
        """Static deflection under the mean force at the mean stiffness of the loaded flank, at
        rest."""
        f, b = self.mean_force(), float(self.params[BACKLASH])
        if f == 0.0:
            return np.zeros(2)
        k = self.drive_series[0] if f > 0 else self.coast_series[0]
        return np.array([f / k + math.copysign(b, f), 0.0])

    @property
    def state_scale(self) -> np.ndarray:
        """[m, m/s]: the static deflection under the mean force (or the backlash half-width
        where larger), and that times the natural frequency."""
        d = max(abs(self.mean_force()) / float(self.params[K_MEAN]), float(self.params[BACKLASH]),
                1e-9)
        return np.array([d, d * float(self.natural_frequencies()[0])])

    def speed_axes(self, omega: np.ndarray) -> dict[str, tuple[np.ndarray, dict]]:
        """Mesh frequency [Hz] and pinion speed [rpm] at the forcing frequencies ``omega``
        [rad/s]."""
        w = np.asarray(omega, dtype=float)
        return {"mesh_frequency": (w * self.cycles / (2.0 * math.pi),
                                   {"units": "Hz", "long_name": "mesh frequency"}),
                "input_speed": (w * self.cycles / self.mesh.pinion.teeth / _RPM,
                                {"units": "rpm", "long_name": "pinion speed"})}

    def dataset_attrs(self) -> dict[str, object]:
        """The period and the stiffness series' truncation, recorded with every result."""
        err = self.stiffness_error()
        return {"mesh_cycles_per_period": self.cycles, "stiffness_form": self.stiffness_form,
                "stiffness_harmonics": self.n_harmonics,
                "mesh_frequency_rad_s": self.mesh_frequency, "speed_rpm": self.speed / _RPM,
                "stiffness_rms_error_rel": max(err["drive_rms"], err["coast_rms"]),
                "faults": str(self.stiffness.attrs.get("faults", "none"))}

    # ------------------------------------------------------------------ the stiffness series
    def table_phase(self) -> np.ndarray:
        """The forcing phase theta [rad] of every angle of the stiffness table."""
        cyc = np.asarray(self.stiffness["cycle"].values, dtype=float)
        return 2.0 * math.pi * cyc / self.cycles

    def stiffness_at(self, theta: np.ndarray, flank: str = "drive") -> np.ndarray:
        """The stiffness k(theta) [N/m] of the ``"drive"`` or ``"coast"`` flank that the
        kernels use: the series, clipped at 0 (only a table that falls to 0, a missing tooth,
        gives a series below 0); in the table form the table, linear between its angles."""
        if self.stiffness_form == "table":
            var = {"drive": "mesh_stiffness", "coast": "mesh_stiffness_coast"}[flank]
            table = np.asarray(self.stiffness[var].values, dtype=float)
            u = np.mod(np.asarray(theta, dtype=float) / (2.0 * math.pi), 1.0) * table.size
            return np.interp(u, np.arange(table.size + 1), np.append(table, table[0]))
        series = {"drive": self.drive_series, "coast": self.coast_series}[flank]
        return np.maximum(evaluate_series(series, theta), 0.0)

    def stiffness_error(self) -> dict[str, float]:
        """The series against the table at its angles, relative to the mean drive stiffness:
        ``drive_max``, ``drive_rms``, ``coast_max``, ``coast_rms``. The maximum sits at the
        table's jumps (a tooth pair entering or leaving contact: about half the jump, the Gibbs
        overshoot), the rms falls as 1/sqrt(H). The table form is the table at its angles
        (every error 0)."""
        if "_error" not in self.__dict__:  # the series and the table never change
            self._error = self._series_error()
        return dict(self._error)

    def _series_error(self) -> dict[str, float]:
        theta, k0 = self.table_phase(), float(self.drive_series[0])
        out = {}
        for flank, var in (("drive", "mesh_stiffness"), ("coast", "mesh_stiffness_coast")):
            e = self.stiffness_at(theta, flank) - self.stiffness[var].values
            out[f"{flank}_max"] = float(np.max(np.abs(e)) / k0)
            out[f"{flank}_rms"] = float(np.sqrt(np.mean(e * e)) / k0)
        return out

    def __repr__(self) -> str:
        return (f"SpurPair({self.mesh.pinion.teeth}/{self.mesh.wheel.teeth}, "
                f"{self.speed / _RPM:g} rpm, {float(self.params[TORQUE]):g} N m, "
                + (f"H={self.n_harmonics}" if self.stiffness_form == "fourier" else "table")
                + f", faults={self.stiffness.attrs.get('faults', 'none')!r})")
