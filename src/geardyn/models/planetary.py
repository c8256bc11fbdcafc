"""The lumped-parameter planetary gear set of Lin & Parker (J. Vib. Acoust. 121, 1999, 316-321).

Carrier c, ring r, sun s and N planets, each with three degrees of freedom in the carrier frame
(a frame that turns with the carrier's mean speed): the carrier, ring and sun translations x, y
and rotations u = r theta (r: the base radius of the sun and ring, the radius of the planet
centres for the carrier), and per planet n its radial and tangential translations zeta_n, eta_n
and rotation u_n = r_p theta_n. Planet n sits at the angle psi_n. Mesh deflections along the lines
of action (``docs/planetary.md``)::

    delta_sn = -x_s sin psi_sn + y_s cos psi_sn - zeta_n sin a_s - eta_n cos a_s + u_s + u_n
    delta_rn = -x_r sin psi_rn + y_r cos psi_rn + zeta_n sin a_r - eta_n cos a_r + u_r - u_n

with psi_sn = psi_n - a_s, psi_rn = psi_n + a_r. Planet bearings deflect by
x_c cos psi_n + y_c sin psi_n - zeta_n (radial) and -x_c sin psi_n + y_c cos psi_n - eta_n + u_c
(tangential). Each mesh spring acts through a dead zone (backlash) with a time-varying stiffness
and a transmission error. With a carrier speed the rotating frame's gyroscopic and centripetal
terms act on the translations (``carrier_speed``; ``docs/planetary.md``, "Rotating carrier");
without one they are omitted (the carrier-frame model at low carrier speed).
"""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from types import SimpleNamespace
from typing import Any

import numpy as np

from geardyn.core.capabilities import Capabilities, FaultDatasetInputs
from geardyn.core.coefficients import CoefficientLayout
from geardyn.core.inputs import PhysicalInput, by_name, one_value, swept
from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model, unique_rows
from geardyn.core.plan import MIN_STEPS_PER_PERIOD, STEPS_PER_FASTEST_MODE
from geardyn.errors import ParameterError
from geardyn.gears.faults import BrokenTooth
from geardyn.gears.iso6336_kv import KvMeshGroup, planetary_reduced_masses
from geardyn.models import planetary_kernels as pk
from geardyn.models.elements import dead_zone
from geardyn.models.modal import frequency_groups
from geardyn.models.planetary_coefficients import (
    CARRIER_SPEED,
    CENTRAL,
    FORCES,
    HARMONICS,
    HEADER,
    INPUTS,
    MATRICES,
    MESH,
    MESH_ROW,
    N_PLANETS,
    coast_harmonics_block,
    harmonics_block,
    structure_entry,
    workspace_entry,
)
from geardyn.models.planetary_faults import place_faults, planet_wear_profiles
from geardyn.models.planetary_stiffness import (
    coast_flank,
    flank_series,
    mirrored,
    potential_energy_options,
    potential_energy_tables,
    reversed_in_time,
    revolution_stiffness,
    series_error,
    stiffness_method,
    table_in_time,
)
from geardyn.models.stiffness import evaluate, fourier_coefficients
from geardyn.units import si_value

_KERNEL = KernelSource(pk.planetary_rhs, pk.planetary_events, pk.planetary_observe)


@functools.lru_cache(maxsize=8)
def _swept(inputs: tuple[PhysicalInput, ...]) -> dict[str, PhysicalInput]:
    return swept(inputs)


@functools.lru_cache(maxsize=32)
def planetary_layout(dofs: tuple[str, ...], mesh_names: tuple[str, ...], nh: int,
                     kt_entries: tuple[tuple[int, int], ...], gyro: tuple[tuple[int, int], ...]
                     ) -> CoefficientLayout:
    """The coefficient vector of a gear set (:func:`planetary_kernels.layout`): parameters,
    then the structure the kernels read (sparse indices and counts: structure; their copies of
    the Kt, W and G values: workspace), the stiffness cache (workspace), the gyroscopic section
    (the carrier speed a parameter, the M^-1 G pattern structure), the own-phase cache
    (workspace)."""
    out = CoefficientLayout.of(HEADER, model="PlanetaryGearSet")
    for c in FORCES.entries:
        for d in dofs:
            out.extend((c,), f"_{d}")
    for c in MATRICES.entries:
        for a in dofs:
            for b in dofs:
                out.extend((c,), f"_{a}_{b}")
    harmonics, coast = harmonics_block(nh), coast_harmonics_block(nh)
    for m in mesh_names:
        out.extend(MESH.entries + harmonics.entries, prefix=f"{m}_")
        for c in MESH_ROW.entries:
            for d in dofs:
                out.extend((c,), f"_{d}", prefix=f"{m}_")
        out.extend(coast.entries, prefix=f"{m}_")
    index = structure_entry("structure", "sparse index or count of the kernel's structure")
    copy_ = workspace_entry("structure copy", "the kernel's copy of a structural value "
                            "(written from the dense entries)")
    for name in pk.structure_names(dofs, mesh_names, list(kt_entries)):
        copy = "_nz_W" in name or "_nz_G" in name or name.startswith("Kt_nz_")
        out.place((name,), copy_ if copy else index)
    cache = workspace_entry("cache", "relative-stiffness cache of the lane-block functions")
    out.place(pk.cache_entries(len(mesh_names))[0], cache)
    gyro_names = pk.gyro_names(dofs, list(gyro))
    out.place(gyro_names[:1], CARRIER_SPEED)
    pattern = structure_entry("gyro", "the Coriolis pattern M^-1 G (rows, columns, values; "
                              "every lane alike)")
    out.place(gyro_names[1:], pattern)
    own = workspace_entry("own-phase cache", "of the lane-block functions (meshes whose "
                          "order differs from 1)")
    out.place(pk.own_cache_names(len(mesh_names)), own)
    return out


#: Newton steps of :meth:`PlanetaryGearSet.static_state` with a radial contact, and the step
#: (relative to the largest coordinate) at which it has converged.
STATIC_ITERATIONS = 50
STATIC_STEP_TOL = 1e-13
_SHORT = {"carrier": "c", "ring": "r", "sun": "s"}


def _si(field: str, value: object, kind: str, minimum: float | None = 0.0,
        strict: bool = False) -> float:
    """:func:`~geardyn.units.si_value`, at least 0 unless told otherwise."""
    return si_value(field, value, kind, minimum, strict)


@dataclass(frozen=True)
class Member:
    """One member of a planetary gear set (SI inputs; numbers or unit strings).

    mass [kg]; inertia_over_r2 [kg] the rotational inertia over the squared radius r of its
    rotation coordinate u = r theta (base radius of sun and ring, planet-centre radius for the
    carrier, base radius of a planet); bearing_stiffness [N/m] of its translational bearing (a
    planet's: its bearing on the carrier); torsional_stiffness [N/m] of its torsional support,
    acting on u (0: free; a planet has none); radius [m] of u, needed only to turn a torque on
    the member into a force on u.
    """

    mass: float
    inertia_over_r2: float
    bearing_stiffness: float
    torsional_stiffness: float = 0.0
    radius: float | None = None

    def checked(self, name: str) -> Member:
        """A copy with SI floats, validated; errors name ``<name>.<field>``."""
        radius = None if self.radius is None else _si(f"{name}.radius", self.radius, "length",
                                                      strict=True)
        return Member(
            mass=_si(f"{name}.mass", self.mass, "mass", strict=True),
            inertia_over_r2=_si(f"{name}.inertia_over_r2", self.inertia_over_r2, "mass",
                                strict=True),
            bearing_stiffness=_si(f"{name}.bearing_stiffness", self.bearing_stiffness,
                                  "stiffness"),
            torsional_stiffness=_si(f"{name}.torsional_stiffness", self.torsional_stiffness,
                                    "stiffness"),
            radius=radius)


#: PlanetaryGearSet inputs that :meth:`PlanetaryGearSet.from_geometry` takes from the geometry.
_FROM_GEOMETRY = ("n_planets", "planet_angles", "sun_pressure_angle", "ring_pressure_angle",
                  "sun_mesh_stiffness", "ring_mesh_stiffness", "waveform", "contact_ratio",
                  "sun_stiffness_fluctuation", "ring_stiffness_fluctuation", "sun_mesh_phase",
                  "ring_mesh_phase")
#: The coast-flank inputs :meth:`PlanetaryGearSet.from_geometry` sets (``coast="mirror"``: the
#: mirrored ISO waves or the potential-energy tables' coast flank; ``"symmetric"``: none, one
#: stiffness on both flanks).
_COAST_FROM_GEOMETRY = ("sun_coast_stiffness", "ring_coast_stiffness", "coast_waveform")


#: Attributes :meth:`PlanetaryGearSet.from_geometry` attaches, kept by ``with_params``.
_FROM_BUILD = ("geometry", "stiffness_waveforms", "stiffness_tables", "stiffness_method", "held",
               "coast_flank", "faults", "mesh_tables")
#: The declared per-planet inputs but the stiffnesses (read by their declared kinds; the mesh
#: stiffnesses are read on their own, the coast ones where the coast flank is built).
_PER_PLANET = {i.name: i.kind for i in INPUTS if i.form == "per_planet" and i.kind != "stiffness"}
#: The sweep parameter of a set built from geometry: the input member's speed [rpm].
INPUT_SPEED = "input_speed"


def _rpm(field: str, value: object) -> float:
    """A speed in rpm: a plain number is rpm, a unit string (``"3000 rpm"``, ``"300 rad/s"``)
    is converted; finite and >= 0."""
    if isinstance(value, str):
        return _si(field, value, "frequency") * 60.0 / (2.0 * math.pi)
    return _si(field, value, "dimensionless")


def _with_radius(name: str, member: Member, radius: float) -> Member:
    """``member`` with ``radius`` set from the geometry; a given radius must agree with it."""
    if member.radius is None:
        return replace(member, radius=radius)
    given = _si(f"{name}.radius", member.radius, "length", strict=True)
    if abs(given - radius) > 1e-9 * radius:
        raise ParameterError(f"{name}.radius", member.radius,
                             f"differs from the geometry's {radius:.6g} m (leave it None)")
    return member


def _stiffness(field: str, value: Any, n: int) -> float | np.ndarray:
    """A mean mesh stiffness [N/m] > 0: a float for a scalar, else one per planet."""
    if isinstance(value, str | int | float) and not isinstance(value, bool):
        return _si(field, value, "stiffness", strict=True)
    out = _per_planet(field, value, n, "stiffness")
    for i, k in enumerate(out):
        if not k > 0.0:
            raise ParameterError(f"{field}[{i}]", k, "must be > 0")
    return out


def _per_planet(field: str, value: Any, n: int, kind: str, minimum: float | None = 0.0
                ) -> np.ndarray:
    """A scalar or a sequence of n values, in SI."""
    if isinstance(value, str | int | float) and not isinstance(value, bool):
        return np.full(n, _si(field, value, kind, minimum))
    vals = list(value)
    if len(vals) != n:
        raise ParameterError(field, value, f"needs one value per planet ({n}) or a scalar")
    return np.array([_si(f"{field}[{i}]", v, kind, minimum) for i, v in enumerate(vals)])


def _series_inputs(contact_ratio: Any, harmonics: Any) -> tuple[float, int]:
    """The rectangular waveform's contact ratio (1 < eps < 2) and its series' harmonics
    (:data:`~geardyn.models.planetary_coefficients.HARMONICS`), checked: a
    :class:`~geardyn.ParameterError` naming the input (every model with a rectangular stiffness
    waveform reads them here)."""
    if not isinstance(contact_ratio, int | float) or not 1.0 < contact_ratio < 2.0:
        raise ParameterError("contact_ratio", contact_ratio, "must be between 1 and 2")
    return float(contact_ratio), _harmonics(harmonics)


def _harmonics(harmonics: Any) -> int:
    """The harmonics of a stiffness series, within the declared range of :data:`HARMONICS` (a
    :class:`~geardyn.ParameterError` naming ``harmonics`` for any other)."""
    return HARMONICS.count(harmonics)


def _waveform(field: str, waveform: Any, rel: np.ndarray, phase: np.ndarray, contact_ratio: float,
              harmonics: int, order: int = 1) -> np.ndarray:
    """Relative Fourier coefficients (meshes, 2 nh) [a_1, b_1, a_2, ...] of k(theta) - 1 per
    mesh, for the forcing phase theta + phase_m / ``order`` (``phase`` in rad of the mesh cycle,
    ``order`` mesh cycles per forcing period)."""
    if isinstance(waveform, str) and order != 1:
        raise ParameterError(field, waveform, f"is a wave over one mesh cycle; with mesh_order "
                             f"{order} give the relative Fourier coefficients in the forcing "
                             "angle")
    if isinstance(waveform, str):
        if waveform not in ("sine", "rectangular"):
            raise ParameterError(field, waveform, "must be 'sine', 'rectangular' or a pair "
                                 "(a, b) of relative Fourier coefficients")
        nh = 1 if waveform == "sine" else harmonics
        out = np.zeros((rel.size, 2 * nh))
        for m in range(rel.size):
            mesh = SimpleNamespace(waveform=waveform, stiffness_amplitude=rel[m],
                                   mean_stiffness=1.0, stiffness_phase=phase[m],
                                   contact_ratio=contact_ratio, harmonics=harmonics)
            a, b = fourier_coefficients(mesh, nh)  # type: ignore[arg-type]
            out[m, 0::2], out[m, 1::2] = a, b
        return out
    try:
        a0, b0 = (np.asarray(v, dtype=float).ravel() for v in waveform)
    except (TypeError, ValueError):
        raise ParameterError(field, waveform, "must be 'sine', 'rectangular' or a pair (a, b) "
                             "of relative Fourier coefficients") from None
    if a0.size != b0.size or a0.size == 0 or not np.all(np.isfinite(a0) & np.isfinite(b0)):
        raise ParameterError(field, waveform, "a and b must be finite, of equal length >= 1")
    h = np.arange(1, a0.size + 1)
    out = np.zeros((rel.size, 2 * a0.size))
    for m in range(rel.size):  # shifted by phase_m / order: harmonic h turns by h phase_m / order
        turn = h * phase[m] if order == 1 else h * (phase[m] / order)
        cs, sn = np.cos(turn), np.sin(turn)
        out[m, 0::2] = a0 * cs + b0 * sn
        out[m, 1::2] = b0 * cs - a0 * sn
    return out


def _waveforms(field: str, waveform: Any, rel: np.ndarray, phase: np.ndarray,
               contact_ratio: float, harmonics: int, order: int = 1) -> np.ndarray:
    """:func:`_waveform`, or for a mapping ``{"sun": (a, b), "ring": (a, b)}`` one pair of
    relative Fourier coefficients per mesh group, for a mapping ``{"s1": (a, b), ..., "rN":
    (a, b)}`` one per mesh (the shorter padded with zeros)."""
    if not isinstance(waveform, Mapping):
        return _waveform(field, waveform, rel, phase, contact_ratio, harmonics, order)
    n = rel.size // 2
    meshes = [f"s{i + 1}" for i in range(n)] + [f"r{i + 1}" for i in range(n)]
    if set(waveform) == set(meshes):
        groups = [(m, slice(i, i + 1)) for i, m in enumerate(meshes)]
    elif set(waveform) == {"sun", "ring"}:
        groups = [("sun", slice(0, n)), ("ring", slice(n, None))]
    else:
        raise ParameterError(field, dict(waveform), "a mapping needs exactly the keys 'sun' "
                             "and 'ring', or one per mesh ('s1' .. 'rN'), each a pair (a, b) "
                             "of relative Fourier coefficients")
    parts = [_waveform(f"{field}.{g}", waveform[g], rel[sl], phase[sl], contact_ratio,
                       harmonics, order) for g, sl in groups]
    width = max(p.shape[1] for p in parts)
    return np.vstack([np.pad(p, ((0, 0), (0, width - p.shape[1]))) for p in parts])


def _flank_index(lay: dict[str, int], n: int, nm: int, nh: int, coast: bool) -> np.ndarray:
    """Indices into the coefficient vector of every mesh's flank entries: KF and the 2 nh
    harmonics of the drive flank, or KF_coast and the coast harmonics (``coast``), mesh by
    mesh in the same order."""
    first = pk.MESH_FIXED + 2 * nh + 2 * n if coast else pk.MESH_FIXED
    out = []
    for m in range(nm):
        o = lay["mesh"] + m * lay["block"]
        out += [o + (pk.M_KFC if coast else pk.M_KF)] + list(range(o + first,
                                                                    o + first + 2 * nh))
    return np.array(out, dtype=np.intp)


def _clean(A: np.ndarray, rel: float = 1e-12) -> np.ndarray:
    """``A`` with entries below ``rel`` times its largest magnitude set to 0: the rounding
    residue of trigonometric sums (cos(pi/2) = 6e-17), which would couple coordinates that
    the model leaves uncoupled."""
    A = np.array(A, dtype=float)
    big = float(np.max(np.abs(A))) if A.size else 0.0
    A[np.abs(A) < rel * big] = 0.0
    return A


def _minimum_relative_stiffness(coef: np.ndarray) -> float:
    """The least relative stiffness 1 + sum a_h cos(h theta) + b_h sin(h theta) of any mesh
    (rows of ``coef``: a_1, b_1, ...) at max(2048, 4 nh) uniform phases (one inverse FFT)."""
    if coef.size == 0:
        return 1.0
    nh = coef.shape[1] // 2
    n = max(2048, 4 * nh)
    spectrum = np.zeros((coef.shape[0], n // 2 + 1), dtype=complex)
    spectrum[:, 1:nh + 1] = 0.5 * n * (coef[:, 0::2] - 1j * coef[:, 1::2])
    return float(1.0 + np.fft.irfft(spectrum, n, axis=1).min())


class PlanetaryGearSet(Model):
    """The Lin & Parker (1999) rotational-translational planetary gear model, nonlinear.

    Inputs are SI (numbers or unit strings, e.g. ``"24.6 deg"``, ``"5e8 N/m"``). The model
    integrates a dimensionless form: displacements over ``length_scale`` L (default 1 um) and
    time tau = omega_0 t with ``time_scale`` omega_0 [rad/s] (default
    sqrt(sun_mesh_stiffness / planet.inertia_over_r2)); ``Omega`` = mesh_frequency / omega_0 is
    the dimensionless mesh frequency. Both scales stay fixed under :meth:`with_params`, so a
    sweep in any parameter keeps the meaning of Omega and of the states.

    Parameters
    ----------
    n_planets, planet_angles
        N and the planet angles psi_n [rad] (default equally spaced, psi_n = 2 pi (n - 1) / N).
    sun_pressure_angle, ring_pressure_angle
        Pressure angles a_s, a_r of the sun-planet and ring-planet meshes.
    sun, ring, carrier, planet
        :class:`Member` data (the planet's ``bearing_stiffness`` is its bearing on the carrier).
    sun_mesh_stiffness, ring_mesh_stiffness
        Mean mesh stiffnesses [N/m], scalar or one per planet.
    sun_stiffness_fluctuation, ring_stiffness_fluctuation
        Relative amplitude of the stiffness fluctuation (half peak-to-peak over the mean, as in
        :class:`~geardyn.Mesh`); ``waveform`` ``"sine"``, ``"rectangular"`` (``contact_ratio``,
        ``harmonics``) or a pair (a, b) of relative Fourier coefficients of k/k_mean - 1 (then
        the fluctuations are ignored), or a mapping {"sun": (a, b), "ring": (a, b)} of one
        pair per mesh group (:meth:`from_geometry`), or {"s1": (a, b), ..., "rN": (a, b)} of
        one pair per mesh. Mesh m's stiffness is k_m (1 + w(Omega tau + phase_m / mesh_order)).
    sun_coast_stiffness, ring_coast_stiffness, coast_waveform
        The coast (back) flank, acting where a mesh's deflection leaves the dead zone on the other
        side (x < -b): its mean stiffness [N/m], scalar or per planet (None: the drive flank's),
        and relative Fourier
        coefficients, a pair (a, b) or a mapping {"sun": (a, b), "ring": (a, b)} as ``waveform``
        (None: the drive flank's), shifted by the same mesh phases. All None (default): one
        stiffness on both flanks.
    sun_mesh_phase, ring_mesh_phase
        Mesh phases [rad of the mesh cycle], scalar or one per planet (e.g. Parker & Lin 2004):
        mesh m's stiffness is delayed by -phase_m / (2 pi) mesh cycles.
    sun_backlash, ring_backlash
        Backlash half-width b of each mesh [m] (dead zone), scalar or per planet.
    sun_mesh_error, ring_mesh_error, sun_error_phase, ring_error_phase
        Transmission error e_m = E sin(Omega tau + phase_m + error_phase) [m] of each mesh (at
        the mesh frequency: only with ``mesh_order`` 1).
    mesh_damping, modal_damping
        Viscous damping: per mesh ratio zeta_m (c_m = 2 zeta_m sqrt(k_m m_e), m_e the equivalent
        rotational mass of the mesh's two gears; acting on the deflection rate, also in the
        backlash) and/or a modal damping ratio of every mode of the linear model at mean
        stiffness.
    sun_torque, ring_torque, carrier_torque
        Mean external torques [N m] on the members (need the member's ``radius``).
    torque_fluctuation, torque_order, torque_phase
        The sun (input) torque fluctuates as T_s (1 + A sin(order Omega tau + phase)) (the
        order counts the forcing frequency Omega: mesh orders times ``mesh_order``). An
        integer order is locked to the mesh phase (the phase the mesh stiffness and error take,
        0 at the start of a run or of a continued sweep's point); a non-integer order is a
        second excitation whose phase runs with the time of the run (or of the sweep's chain).
    mesh_frequency
        Mesh frequency [rad/s]; the forcing frequency is mesh_frequency / ``mesh_order``;
        default omega_0 (Omega = 1 / ``mesh_order``).
    mesh_order
        Mesh cycles per forcing period (default 1: the forcing period is one mesh cycle).
        :meth:`from_geometry` with ``faults`` sets it to the faulty gear's teeth Z_f: the forcing
        period is then one revolution of that gear relative to the carrier, Omega = mesh
        frequency / (Z_f omega_0), and the waveforms are series in that revolution's angle.
    rotational_only
        The purely torsional model: member centres fixed, planets carried rigidly by the
        carrier (eta_n = u_c, zeta_n = 0).
    fixed
        Members held fixed (all their coordinates removed), e.g. ``("ring",)``.
    carrier_speed, carrier_speed_ratio
        The carrier's speed Omega_c [rad/s, or a unit string such as ``"300 rpm"``], positive in
        the sense of psi and u: the model then carries the rotating frame's gyroscopic (Coriolis)
        and centripetal terms, M q'' + Omega_c G q' + (K - Omega_c^2 K_Omega) q = T (Lin &
        Parker 1999; ``docs/planetary.md``, "Rotating carrier"). Or ``carrier_speed_ratio``:
        Omega_c / mesh_frequency, so that the carrier speed follows the mesh frequency in a
        sweep; :meth:`from_geometry` sets it from the tooth counts with
        ``carrier_speed="kinematic"``. Both None (default): the terms are omitted (the
        carrier-frame model at low carrier speed). Not with ``rotational_only`` (no
        translations to act on).
    stiffness_gaps
        False (default): a mesh stiffness series that falls to 0 or below is refused. True: a
        mesh may have no pair in contact over part of the period (a missing tooth,
        :meth:`from_geometry` sets it): the series' ringing below 0 about such a gap is clipped
        at 0 (the kernels clip every series at 0; a positive one is unchanged, bitwise).
    centrifugal_preload
        With a carrier speed: True (default) adds the planets' centrifugal load
        m_p Omega_c^2 r_c on their bearings (needs ``carrier.radius`` r_c) and lets it turn
        with the carrier: a planet's tangential centripetal term acts on its bearing's
        tangential deflection eta_n - u_c (the expansion about the preloaded state), so a rigid
        rotation of the gear train stays a zero-frequency mode; False: Lin & Parker's published
        terms (on eta_n; a free rotation then diverges at any carrier speed).
    """

    name = "PlanetaryGearSet"
    time_unit = "1"
    state_units = "1"
    observable_units = "N"
    capabilities = Capabilities(physical_inputs=True, physical_axes=True, mesh_forces=True,
                                dynamic_factor=True, natural_frequencies="Hz",
                                stiffness_tables="meshes",
                                fault_dataset=FaultDatasetInputs(
                                    "input_speed", "sun_torque", "ring_sensor",
                                    stiffness_error=True))
    raw_overrides_allowed = True
    input_declarations = INPUTS
    #: Raw coefficients set by name through ``with_params`` (name -> value), applied again on
    #: top of a rebuild from changed inputs.
    raw_overrides: dict[str, float] = {}
    #: The stage a set built by :meth:`from_geometry` came from (None otherwise).
    geometry: Any = None
    #: The member a set built by :meth:`from_geometry` holds fixed (None otherwise).
    held: str | None = None
    #: How a set built by :meth:`from_geometry` got its mesh stiffness (``"iso"``,
    #: ``"potential_energy"``; None otherwise).
    stiffness_method: str | None = None
    #: The coast flank of a set built by :meth:`from_geometry` (``"mirror"``, ``"symmetric"``;
    #: None otherwise).
    coast_flank: str | None = None
    #: The ISO 6336-1 waves (sun, ring) of a set built from geometry with ``stiffness="iso"``.
    stiffness_waveforms: Any = None
    #: The potential-energy Datasets (sun, ring) of a set built with
    #: ``stiffness="potential_energy"`` over one mesh cycle, healthy (None otherwise).
    stiffness_tables: Any = None
    #: Every mesh's potential-energy table (sun-planet meshes, then ring-planet; with faults
    #: the faulty meshes' over the faulty gear's revolution), None without them.
    mesh_tables: Any = None
    #: The :class:`~geardyn.models.planetary_faults.FaultPlacement` of a set built with faults.
    faults: Any = None

    def __init__(self, n_planets: int = 3, sun_pressure_angle: Any = "24.6 deg",
                 ring_pressure_angle: Any = "24.6 deg", *, sun: Member, ring: Member,
                 carrier: Member, planet: Member, sun_mesh_stiffness: Any,
                 ring_mesh_stiffness: Any, planet_angles: Sequence[Any] | None = None,
                 sun_stiffness_fluctuation: Any = 0.0, ring_stiffness_fluctuation: Any = 0.0,
                 waveform: Any = "sine", contact_ratio: float = 1.6, harmonics: int = 9,
                 sun_coast_stiffness: Any = None, ring_coast_stiffness: Any = None,
                 coast_waveform: Any = None,
                 sun_mesh_phase: Any = 0.0, ring_mesh_phase: Any = 0.0,
                 sun_backlash: Any = 0.0, ring_backlash: Any = 0.0,
                 sun_mesh_error: Any = 0.0, ring_mesh_error: Any = 0.0,
                 sun_error_phase: Any = 0.0, ring_error_phase: Any = 0.0,
                 mesh_damping: Any = 0.05, modal_damping: float = 0.0,
                 sun_torque: Any = 0.0, ring_torque: Any = 0.0, carrier_torque: Any = 0.0,
                 torque_fluctuation: float = 0.0, torque_order: float = 1.0,
                 torque_phase: float = 0.0, mesh_frequency: Any = None,
                 mesh_order: int = 1, rotational_only: bool = False, fixed: Sequence[str] = (),
                 carrier_speed: Any = None, carrier_speed_ratio: Any = None,
                 centrifugal_preload: bool = True, time_scale: Any = None,
                 length_scale: Any = 1e-6, stiffness_gaps: bool = False):
        self.inputs: dict[str, Any] = {k: v for k, v in locals().items()
                                       if k not in ("self", "__class__")}
        n = N_PLANETS.count(n_planets)
        fixed = tuple(fixed)
        for f in fixed:
            if f not in CENTRAL:
                raise ParameterError("fixed", fixed, f"{f!r} is not one of {', '.join(CENTRAL)}")
        self.n_planets = n
        self.rotational_only = bool(rotational_only)
        self.fixed = fixed
        self.members = {k: m.checked(k) if isinstance(m, Member) else None
                        for k, m in (("sun", sun), ("ring", ring), ("carrier", carrier),
                                     ("planet", planet))}
        for k, m in self.members.items():
            if m is None:
                raise ParameterError(k, self.inputs[k], "must be a geardyn.Member")
        if self.members["planet"].torsional_stiffness != 0.0:
            raise ParameterError("planet.torsional_stiffness", planet.torsional_stiffness,
                                 "a planet has no torsional support; must be 0")
        self._carrier_inputs(carrier_speed, carrier_speed_ratio, centrifugal_preload)
        self.alpha_s = _si("sun_pressure_angle", sun_pressure_angle, "angle")
        self.alpha_r = _si("ring_pressure_angle", ring_pressure_angle, "angle")
        for f, a in (("sun_pressure_angle", self.alpha_s), ("ring_pressure_angle", self.alpha_r)):
            if not a < math.pi / 2:
                raise ParameterError(f, a, "must be below 90 deg")
        if planet_angles is None:
            self.psi = 2.0 * math.pi * np.arange(n) / n
        else:
            self.psi = _per_planet("planet_angles", planet_angles, n, "angle", None)
        if isinstance(mesh_order, bool) or not isinstance(mesh_order, int | np.integer) \
                or mesh_order < 1:
            raise ParameterError("mesh_order", mesh_order, "must be a whole number >= 1")
        self.mesh_order = int(mesh_order)
        self.k_s = _stiffness("sun_mesh_stiffness", sun_mesh_stiffness, n)
        self.k_r = _stiffness("ring_mesh_stiffness", ring_mesh_stiffness, n)
        per = {}
        for f, kind in _PER_PLANET.items():
            minimum = 0.0 if kind in ("length", "dimensionless") else None
            per[f] = _per_planet(f, self.inputs[f], n, kind, minimum)
        both = lambda f: np.concatenate([per[f"sun_{f}"], per[f"ring_{f}"]])  # noqa: E731
        contact_ratio, harmonics = _series_inputs(contact_ratio, harmonics)
        self.mesh_phase = both("mesh_phase")
        self.fourier = _waveforms("waveform", waveform, both("stiffness_fluctuation"),
                                 self.mesh_phase, contact_ratio, harmonics,
                                 self.mesh_order)
        if not isinstance(stiffness_gaps, bool):
            raise ParameterError("stiffness_gaps", stiffness_gaps, "must be true or false")
        self.stiffness_gaps = stiffness_gaps
        if not stiffness_gaps and _minimum_relative_stiffness(self.fourier) <= 0.0:
            if not isinstance(waveform, str):
                raise ParameterError("waveform", "(coefficients)", "makes a mesh stiffness "
                                     "negative; it must stay > 0")
            raise ParameterError("sun_stiffness_fluctuation", sun_stiffness_fluctuation,
                                 "the stiffness fluctuation makes a mesh stiffness negative; "
                                 "it must stay > 0")
        self._coast_inputs(sun_coast_stiffness, ring_coast_stiffness, coast_waveform,
                           float(contact_ratio), harmonics)
        self.backlash = both("backlash")
        self.error = both("mesh_error")
        if self.mesh_order != 1 and np.any(self.error != 0.0):
            field = "sun_mesh_error" if np.any(per["sun_mesh_error"] != 0.0) else \
                "ring_mesh_error"
            raise ParameterError(field, self.inputs[field], "acts at the forcing frequency; "
                                 f"with mesh_order {self.mesh_order} (the forcing period a "
                                 "revolution, not a mesh cycle) it must be 0")
        self.error_phase = both("error_phase") + self.mesh_phase
        self.mesh_damping = per["mesh_damping"]
        self.modal_damping = _si("modal_damping", modal_damping, "dimensionless")
        self.torques = {k: _si(f"{k}_torque", self.inputs[f"{k}_torque"], "torque", None)
                        for k in ("sun", "ring", "carrier")}
        for k, t in self.torques.items():
            if t != 0.0 and self.members[k].radius is None:
                raise ParameterError(f"{k}.radius", None, f"needed to apply {k}_torque")
        self.torque_fluctuation = _si("torque_fluctuation", torque_fluctuation, "dimensionless")
        self.torque_order = _si("torque_order", torque_order, "dimensionless", strict=True)
        self.torque_phase = _si("torque_phase", torque_phase, "angle", None)
        self.length_scale = _si("length_scale", length_scale, "length", strict=True)
        default_w0 = math.sqrt(float(np.max(self.k_s)) / self.members["planet"].inertia_over_r2)
        self.time_scale = (default_w0 if time_scale is None
                           else _si("time_scale", time_scale, "frequency", strict=True))
        mf = self.time_scale if mesh_frequency is None else _si("mesh_frequency",
                                                                mesh_frequency, "frequency")
        self._build(mf / (self.time_scale * self.mesh_order))

    def _coast_inputs(self, sun_k: Any, ring_k: Any, waveform: Any, contact_ratio: float,
                      harmonics: int) -> None:
        """The coast flank's mean stiffnesses ``k_s_coast``, ``k_r_coast`` [N/m] and relative
        Fourier coefficients ``fourier_coast`` (meshes, 2 nh; ``fourier`` padded with zeros to
        the same width where the two differ), see the class doc."""
        n = self.n_planets
        self.k_s_coast = self.k_s if sun_k is None else _stiffness("sun_coast_stiffness",
                                                                   sun_k, n)
        self.k_r_coast = self.k_r if ring_k is None else _stiffness("ring_coast_stiffness",
                                                                    ring_k, n)
        if waveform is None:
            self.fourier_coast = self.fourier
            return
        if isinstance(waveform, str):
            raise ParameterError("coast_waveform", waveform, "must be a pair (a, b) of relative "
                                 "Fourier coefficients or a mapping {'sun': (a, b), 'ring': "
                                 "(a, b)} (None: the drive flank's)")
        zero = np.zeros(self.mesh_phase.size)
        coast = _waveforms("coast_waveform", waveform, zero, self.mesh_phase, contact_ratio,
                           harmonics, self.mesh_order)
        if not self.stiffness_gaps and _minimum_relative_stiffness(coast) <= 0.0:
            raise ParameterError("coast_waveform", "(coefficients)", "makes a coast-flank "
                                 "stiffness negative; it must stay > 0")
        width = max(coast.shape[1], self.fourier.shape[1])
        self.fourier = np.pad(self.fourier, ((0, 0), (0, width - self.fourier.shape[1])))
        self.fourier_coast = np.pad(coast, ((0, 0), (0, width - coast.shape[1])))

    def coast_stiffnesses(self) -> np.ndarray:
        """Mean coast-flank stiffness [N/m] of every mesh (sun-planet meshes, then
        ring-planet)."""
        n = self.n_planets
        return np.concatenate([np.full(n, self.k_s_coast, dtype=float),
                               np.full(n, self.k_r_coast, dtype=float)])

    def _carrier_inputs(self, speed: Any, ratio: Any, preload: Any) -> None:
        """Validate the rotating carrier's inputs (see the class doc)."""
        if isinstance(speed, str) and speed.strip().lower() == "kinematic":
            raise ParameterError("carrier_speed", speed, "'kinematic' needs the tooth counts: "
                                 "build the set with PlanetaryGearSet.from_geometry (or "
                                 "[params.geometry] in a study), or give the speed")
        if speed is not None and ratio is not None:
            raise ParameterError("carrier_speed_ratio", ratio, "give carrier_speed or "
                                 "carrier_speed_ratio, not both")
        if not isinstance(preload, bool | np.bool_):
            raise ParameterError("centrifugal_preload", preload, "must be true or false")
        self.carrier_speed = None if speed is None else _si("carrier_speed", speed,
                                                            "frequency", None)
        self.carrier_speed_ratio = None if ratio is None else _si(
            "carrier_speed_ratio", ratio, "dimensionless", None)
        self.centrifugal_preload = bool(preload)
        spinning = (self.carrier_speed or 0.0) != 0.0 or (self.carrier_speed_ratio or 0.0) != 0.0
        field = "carrier_speed" if speed is not None else "carrier_speed_ratio"
        if spinning and self.rotational_only:
            raise ParameterError(field, speed if speed is not None else ratio,
                                 "the rotational-only model has no translations for the "
                                 "gyroscopic and centripetal terms to act on; leave it None")
        if spinning and self.centrifugal_preload and self.members["carrier"].radius is None:
            raise ParameterError("carrier.radius", None, "needed for the planets' centrifugal "
                                 "load at a carrier speed (or centrifugal_preload=false)")

    def carrier_omega(self, mesh_frequency: float | None = None) -> float:
        """The carrier speed Omega_c [rad/s] at ``mesh_frequency`` [rad/s] (default the model's):
        ``carrier_speed``, or ``carrier_speed_ratio`` times the mesh frequency; 0 when omitted."""
        if self.carrier_speed is not None:
            return self.carrier_speed
        if self.carrier_speed_ratio is None:
            return 0.0
        mf = self.mesh_frequency if mesh_frequency is None else mesh_frequency
        return self.carrier_speed_ratio * mf

    @property
    def mesh_frequency(self) -> float:
        """The mesh frequency [rad/s]: ``mesh_order`` Omega omega_0."""
        return self.omega * self.time_scale * self.mesh_order

    @property
    def omega_is_entry(self) -> bool:
        """False when the carrier speed follows the mesh frequency (``carrier_speed_ratio``):
        then Omega moves Kt and Ct too, and a lane's Omega is set through :meth:`lane_params`."""
        return not self.carrier_speed_ratio

    def rotating_frame_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """G [kg], K_Omega [kg] and the centrifugal force per Omega_c^2 f [kg m] in the model's
        coordinates: the gyroscopic term is Omega_c G q', the centripetal one -Omega_c^2
        K_Omega q, the load Omega_c^2 f (Lin & Parker 1999: G = [[0, -2m], [2m, 0]] and
        diag(m, m) on every member's two carrier-frame translations; with
        ``centrifugal_preload`` a planet's tangential entry acts on its bearing's tangential
        deflection eta_n - u_c, and f is the planets' radial load m_p r_c; see
        ``docs/planetary.md``, "Rotating carrier")."""
        nf = 9 + 3 * self.n_planets
        G = np.zeros((nf, nf))
        K = np.zeros((nf, nf))
        f = np.zeros(nf)
        for j, k in enumerate((*CENTRAL,) + ("planet",) * self.n_planets):
            m = self.members[k].mass
            G[3 * j, 3 * j + 1], G[3 * j + 1, 3 * j] = -2.0 * m, 2.0 * m
            K[3 * j, 3 * j] = K[3 * j + 1, 3 * j + 1] = m
        if self.centrifugal_preload:  # on the bearing's tangential deflection eta_n - u_c
            mp = self.members["planet"].mass
            rc = self.members["carrier"].radius
            for i in range(self.n_planets):
                e = 9 + 3 * i + 1
                K[e, 2] -= mp
                K[2, e] -= mp
                K[2, 2] += mp
                if rc is not None:
                    f[e - 1] = mp * rc
        T = self.constraint()
        return T.T @ G @ T, T.T @ K @ T, T.T @ f

    @classmethod
    def from_geometry(cls, geometry: Any, *, sun: Member, ring: Member, carrier: Member,
                      planet: Member, harmonics: int = 9,
                      waveform_options: Mapping[str, Any] | None = None,
                      held: str | None = None, stiffness: str = "iso",
                      stiffness_options: Mapping[str, Any] | None = None,
                      coast: str = "mirror", faults: object = (),
                      **kw: Any) -> PlanetaryGearSet:
        """The gear set of a :class:`geardyn.gears.PlanetaryGeometry` (see ``docs/planetary.md``,
        "From gear geometry" and "Tooth faults").

        From the geometry: ``n_planets`` and ``planet_angles``; the operating pressure angles
        of the sun-planet and ring-planet meshes; the mean mesh stiffnesses (the means of the
        ISO 6336-1 single/double contact waves, ``geometry.waveforms(**waveform_options)``);
        their relative Fourier coefficients (``harmonics`` terms, exact: no smoothing beyond
        the waves' ``transition`` ramps) as ``waveform={"sun": ..., "ring": ...}``; the Parker &
        Lin phases gamma as ``sun_mesh_phase``/``ring_mesh_phase`` = -2 pi gamma (mesh n's
        stiffness is k(theta - 2 pi gamma_n); the input turning in the sense of psi, so with
        the sun held the sun turns against psi relative to the carrier and a planet with it, the
        phases are ``geometry.phases_turning(-1)``, else ``geometry.phases``, and every mesh
        reads its wave or table backwards in time, k(-(theta - 2 pi gamma_n)), both flanks, its
        faults on the table's tooth -j: ``docs/planetary.md``, "Which way a mesh meets its
        teeth"); the members' ``radius``
        where None (base radius of sun, ring and planet, the carrier's: the centre distance);
        ``sun_backlash`` and ``ring_backlash`` where not given: half the geometry's normal
        backlash j cos(alpha_w) / 2 of each mesh [m] (0 at the default, tight centre distance).
        ``kw`` are the other :class:`PlanetaryGearSet` inputs (damping, torques, errors, ...);
        ``carrier_speed="kinematic"`` sets ``carrier_speed_ratio`` from the tooth counts and
        ``held`` (:func:`_kinematic_ratio`), so the carrier speed follows the input speed.
        ``held``: the member held still in the kinematics of :attr:`input_speed` (``"ring"``,
        ``"carrier"`` or ``"sun"``; default the one member in ``fixed``, else the ring).

        ``stiffness="potential_energy"``: the mean mesh stiffnesses and their relative Fourier
        coefficients come instead from :func:`geardyn.gears.potential_energy_stiffness` of
        ``geometry.sun_mesh`` and ``geometry.ring_mesh`` over one mesh cycle (the discrete Fourier
        series of the tables, :mod:`geardyn.models.planetary_stiffness`), the phases as above; and
        so do the coast flank's (``sun_coast_stiffness``, ``ring_coast_stiffness``,
        ``coast_waveform``: the tables' ``mesh_stiffness_coast`` at the same angles, so their phase,
        ``coast_phase_cycles``, is in the coefficients), acting where a mesh's deflection leaves the
        dead zone on the other side. ``stiffness_options``: ``sun_bore_radius``,
        ``planet_bore_radius``, ``ring_rim_radius`` [m] (needed), ``young`` [Pa], ``poisson``,
        ``angles`` (points per mesh cycle, default 360, > 2 ``harmonics``), ``nodes``,
        ``root_segment``. The tables are kept as :attr:`stiffness_tables` (sun, ring; as
        computed, in gear a's rotation; each mesh's as it meets it in time, read backwards with
        the sun held, attrs ``read_backward``, as :attr:`mesh_tables`), the method as
        :attr:`stiffness_method`.

        ``coast``: the coast (back) flank. ``"mirror"`` (default): its own stiffness, for
        symmetric teeth the mirror image of the drive flank's, K_coast(theta) = K_drive(2 pi phi -
        theta) with phi = :func:`geardyn.gears.potential_energy.coast_phase` of the mesh (from the
        geometry alone); with the ISO waves ``coast_waveform`` is the drive series mirrored
        exactly (:func:`~geardyn.models.planetary_stiffness.mirrored`; the same mean, so
        ``sun_coast_stiffness``/``ring_coast_stiffness`` stay None and follow the drive flank's),
        with the potential-energy method the tables' own coast flank (above). ``"symmetric"``: the
        drive flank's stiffness on both flanks (no coast inputs). The choice is kept as
        :attr:`coast_flank`.

        ``faults`` (with ``stiffness="potential_energy"``): one fault or a sequence
        (:class:`~geardyn.gears.RootCrack`, :class:`~geardyn.gears.Spall`,
        :class:`~geardyn.gears.Wear`, :class:`~geardyn.gears.BrokenTooth`: a missing tooth
        leaves no pair in contact over part of its passage, where the stiffness is 0; the set
        is then built with ``stiffness_gaps=True``, its series clipped at 0),
        all on one gear, its
        ``gear`` ``"sun"``, ``"ring"`` or ``"planet<n>"`` (n = 1 .. N) and ``tooth`` numbered as
        in :mod:`geardyn.models.planetary_faults` (which also says which meshes and flanks a
        faulty tooth takes part in). The forcing period is then one revolution of the faulty
        gear relative to the carrier, Z_f mesh cycles (``mesh_order`` = Z_f, Omega = mesh
        frequency / (Z_f omega_0); ``mesh_frequency``, ``input_speed`` and the sweeps' speed
        axes stay the mesh frequency and the input speed), and every mesh's stiffness is the
        Fourier series of its potential-energy table over that revolution in the revolution's
        angle, ``harmonics`` x Z_f harmonics (every sideband up to mesh harmonic
        ``harmonics``): the faulty gear's meshes from the tables with the fault, the others'
        the healthy one-cycle series at harmonics l Z_f, each shifted by its tooth passages
        (mesh phases in rad of the mesh cycle, unreduced for the faulty meshes). Mean
        stiffnesses are per planet. :meth:`stiffness_error` gives the truncation error; the
        tables are kept as :attr:`mesh_tables`, the placement as :attr:`faults`. A static
        transmission error (``*_mesh_error``) is refused with faults (it would act once per
        revolution). Archard wear on a planet follows the mesh that loads the worn flank under
        the mean torques (the static mesh forces of the healthy set:
        :func:`~geardyn.models.planetary_faults.planet_wear_profiles`); a flank no mesh loads
        (no torques, or forces of round-off against max abs(T_k) / r_k, as with a held sun without
        support) is refused (``wear.flank``).
        """
        from geardyn.gears import PlanetaryGeometry

        if not isinstance(geometry, PlanetaryGeometry):
            raise ParameterError("geometry", type(geometry).__name__,
                                 "must be a geardyn.gears.PlanetaryGeometry")
        for f in _FROM_GEOMETRY + _COAST_FROM_GEOMETRY:
            if f in kw:
                raise ParameterError(f, kw[f], "comes from the geometry; change the gears "
                                     "(or build PlanetaryGearSet directly)")
        method = stiffness_method(stiffness, stiffness_options)
        coast = coast_flank(coast)
        if "mesh_order" in kw:
            raise ParameterError("mesh_order", kw["mesh_order"], "comes from the faults (the "
                                 "faulty gear's teeth)")
        placement = place_faults(faults, geometry)
        if placement is not None and method != "potential_energy":
            raise ParameterError("faults", placement.describe(), "need stiffness="
                                 "'potential_energy' (the ISO waves know no teeth)")
        _harmonics(harmonics)  # before the geometry's stiffness is computed with it
        held_member = _held(held, tuple(kw.get("fixed", ())))
        phases = geometry.phases_turning(_sun_turns(held_member))
        revolution = None
        if placement is None:
            inputs, tables, waves = _geometry_stiffness(geometry, method, stiffness_options,
                                                        waveform_options, harmonics, coast)
            if _sun_turns(held_member) < 0:  # every mesh reads its tables backwards in time
                for key in ("waveform", "coast_waveform"):
                    if key in inputs:
                        inputs[key] = {g: reversed_in_time(w) for g, w in inputs[key].items()}
                tables_met = None if tables is None else tuple(
                    table_in_time(t, True) for t in tables)
            else:
                tables_met = tables
            inputs["sun_mesh_phase"] = [-2.0 * math.pi * float(g) for g in phases.sun]
            inputs["ring_mesh_phase"] = [-2.0 * math.pi * float(g) for g in phases.ring]
        else:
            opts = potential_energy_options(stiffness_options, geometry, harmonics)
            shared = {}
            if placement.planet_archard:  # the static mesh forces of the healthy set
                healthy = cls.from_geometry(
                    geometry, sun=sun, ring=ring, carrier=carrier, planet=planet,
                    harmonics=harmonics, waveform_options=waveform_options, held=held,
                    stiffness=stiffness, stiffness_options=stiffness_options, coast=coast,
                    **kw)
                scale = max((abs(t) / healthy.members[k].radius
                             for k, t in healthy.torques.items() if t != 0.0), default=0.0)
                shared = planet_wear_profiles(placement, geometry, opts,
                                              healthy.static_mesh_forces(), scale)
            revolution = revolution_stiffness(geometry, opts, placement, harmonics,
                                              _sun_turns(held_member), shared)
            inputs, waves = revolution.inputs(geometry.n_planets, coast), None
            tables = tables_met = revolution.healthy
        meshes = {"sun": geometry.sun_mesh, "ring": geometry.ring_mesh}
        radii = {"sun": geometry.sun.base_radius, "ring": geometry.ring.base_radius,
                 "carrier": geometry.sun_mesh.centre_distance,
                 "planet": geometry.planet.base_radius}
        members = {}
        for name, m in (("sun", sun), ("ring", ring), ("carrier", carrier), ("planet", planet)):
            if not isinstance(m, Member):
                raise ParameterError(name, m, "must be a geardyn.Member")
            members[name] = _with_radius(name, m, radii[name])
        if isinstance(kw.get("carrier_speed"), str) \
                and kw["carrier_speed"].strip().lower() == "kinematic":
            kw.pop("carrier_speed")
            if kw.get("carrier_speed_ratio") is not None:
                raise ParameterError("carrier_speed_ratio", kw["carrier_speed_ratio"],
                                     "carrier_speed = 'kinematic' sets it; give one of them")
            kw["carrier_speed_ratio"] = _kinematic_ratio(held_member, geometry)
        for g, mesh in meshes.items():
            kw.setdefault(f"{g}_backlash",
                          0.5 * max(mesh.backlash, 0.0) * math.cos(mesh.operating_pressure_angle))
        if placement is not None and any(isinstance(f, BrokenTooth) for f in placement.faults):
            kw["stiffness_gaps"] = True
        try:
            model = cls(
                n_planets=geometry.n_planets, planet_angles=list(geometry.planet_angles),
                sun_pressure_angle=meshes["sun"].operating_pressure_angle,
                ring_pressure_angle=meshes["ring"].operating_pressure_angle,
                **inputs, harmonics=harmonics, **members, **kw)
        except ParameterError as exc:
            if exc.field not in ("waveform", "coast_waveform"):
                raise
            if placement is None:
                raise ParameterError("harmonics", harmonics, "the series of a mesh's "
                                     "stiffness falls to 0 or below; keep more") from None
            raise ParameterError("faults", placement.describe(), "the stiffness series of a "
                                 "faulty mesh falls to 0 or below; keep more harmonics"
                                 ) from None
        model.geometry = geometry
        model.stiffness_waveforms = waves
        model.stiffness_tables = tables
        model.stiffness_method = method
        model.coast_flank = coast
        model.held = _held(held, model.fixed)
        model.faults = placement
        if revolution is not None:
            model.mesh_tables = revolution.tables
        elif tables_met is not None:
            n = geometry.n_planets
            model.mesh_tables = (tables_met[0],) * n + (tables_met[1],) * n
        return model

    def dataset_attrs(self) -> dict[str, object]:
        """A set built from geometry records its mesh stiffness method (``"iso"``: ISO 6336-1
        waves; ``"potential_energy"``: the potential-energy tables) and its coast flank
        (``"mirror"``, ``"symmetric"``)."""
        if self.geometry is None:
            return {}
        out: dict[str, object] = {"mesh_stiffness_method": self.stiffness_method,
                                  "mesh_coast_flank": self.coast_flank}
        if self.faults is not None:
            err = self.stiffness_error()
            out.update(
                faults=self.faults.describe(), faulty_gear=self.faults.gear,
                mesh_cycles_per_period=self.mesh_order,
                forcing_period=f"one revolution of {self.faults.gear} relative to the carrier "
                               f"({self.mesh_order} mesh cycles)",
                Omega_meaning=f"mesh frequency / ({self.mesh_order} time_scale)",
                stiffness_harmonics=self.fourier.shape[1] // 2,
                stiffness_rms_error_rel=max(err["drive_rms"], err["coast_rms"]))
        return out

    def stiffness_error(self) -> dict[str, float]:
        """A potential-energy set's stiffness series against its tables at the tables' angles
        (every mesh, relative to its mean stiffness, by
        ``geardyn.models.planetary_stiffness.series_error``): ``drive_max``, ``drive_rms``,
        ``coast_max``, ``coast_rms`` (the coast flank's with ``coast="mirror"``, else 0), the
        largest over the meshes. The maximum sits at the tables' jumps (a tooth pair entering or
        leaving contact), the rms falls as the harmonics grow."""
        if self.mesh_tables is None:
            raise ParameterError("stiffness_method", self.stiffness_method,
                                 "the series error needs the potential-energy tables")
        out = {"drive_max": 0.0, "drive_rms": 0.0, "coast_max": 0.0, "coast_rms": 0.0}
        flanks = [("drive", "mesh_stiffness", self.fourier, self.mesh_stiffnesses())]
        if self.coast_flank == "mirror":
            flanks.append(("coast", "mesh_stiffness_coast", self.fourier_coast,
                           self.coast_stiffnesses()))
        for flank, var, coef, mean in flanks:
            for m, table in enumerate(self.mesh_tables):
                cyc = table["cycle"].values
                cycles = int(round(float(cyc[-1] + cyc[1] - cyc[0])))
                e = series_error(table[var].values, cycles, float(mean[m]), coef[m],
                                 -self.mesh_phase[m] / (2.0 * math.pi), self.mesh_order)
                out[f"{flank}_max"] = max(out[f"{flank}_max"],
                                          float(np.max(np.abs(e))) / float(mean[m]))
                out[f"{flank}_rms"] = max(out[f"{flank}_rms"],
                                          float(np.sqrt(np.mean(e * e))) / float(mean[m]))
        return out

    def period_stiffness(self, flank: str = "drive"
                         ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Every mesh's stiffness over one forcing period, of a set built with the
        potential-energy tables (:attr:`mesh_tables`): per mesh (:attr:`mesh_names` order) the
        mesh cycles c from t = 0 (ascending in [0, ``mesh_order``)), its table at them (repeated
        over the period and delayed by the mesh's phase: K(c) = T(c + mesh_phase / 2 pi)) and
        the model's series k_m (1 + sum a_h cos(h Theta) + b_h sin(h Theta), clipped at 0 as in
        the kernels) at Theta = 2 pi c
        / ``mesh_order`` [N/m]. ``flank``: ``"drive"`` or ``"coast"`` (with ``coast =
        "symmetric"`` the coast flank is the drive flank's table and series)."""
        if self.mesh_tables is None:
            raise ParameterError("stiffness_method", self.stiffness_method,
                                 "the stiffness over the period needs the potential-energy tables")
        if flank not in ("drive", "coast"):
            raise ParameterError("flank", flank, "must be 'drive' or 'coast'")
        coast = flank == "coast"
        var = "mesh_stiffness_coast" if coast and self.coast_flank == "mirror" \
            else "mesh_stiffness"
        coef, mean = ((self.fourier_coast, self.coast_stiffnesses()) if coast
                      else (self.fourier, self.mesh_stiffnesses()))
        out = []
        for m, table in enumerate(self.mesh_tables):
            cyc = np.asarray(table["cycle"].values, dtype=float)
            cycles = int(round(float(cyc[-1] + cyc[1] - cyc[0])))
            reps = self.mesh_order // cycles
            c = np.concatenate([cyc + r * cycles for r in range(reps)])
            c = (c - self.mesh_phase[m] / (2.0 * math.pi)) % self.mesh_order
            k = np.tile(np.asarray(table[var].values, dtype=float), reps)
            order = np.argsort(c, kind="stable")
            c, k = c[order], k[order]
            series = float(mean[m]) * np.maximum(evaluate(
                coef[m, 0::2], coef[m, 1::2], 2.0 * math.pi * c / self.mesh_order), 0.0)
            out.append((c, k, series))
        return out

    # ------------------------------------------------------------------ input speed
    @property
    def input_member(self) -> str:
        """The member whose speed :attr:`input_speed` is: the sun, or the carrier when the
        sun is held."""
        return "carrier" if self.held == "sun" else "sun"

    # ------------------------------------------------------------------ ISO 6336-1 K_v
    @property
    def input_torque(self) -> float:
        """The magnitude of the sun's torque [N m]."""
        return abs(float(self.torques["sun"]))

    def at_input_torque(self, torque: float) -> PlanetaryGearSet:
        """The set with the sun's torque of magnitude ``torque`` [N m] (its sign kept)."""
        return self.with_params(sun_torque=math.copysign(float(torque), self.torques["sun"]))

    def kv_groups(self, torque: float) -> tuple[KvMeshGroup, ...]:
        """A set built from geometry: ``"sun"`` (the sun-planet meshes, gear 1 the sun) and
        ``"ring"`` (the planet-ring meshes, gear 1 the planet, speeds relative to the carrier),
        F_t = T_s / (r_s N) per planet at the sun's reference radius r_s (the ring-planet force
        equals the sun-planet force, the planet in moment balance), m_red of clause 6.5.9 from
        the members' I / r^2 on their base radii
        (:func:`~geardyn.gears.iso6336_kv.planetary_reduced_masses`)."""
        geo = self.geometry
        if geo is None:
            raise ParameterError("model", self.name, "K_v needs a PlanetaryGearSet built from "
                                 "geometry (from_geometry or [params.geometry])")
        n, sun, planet, ring = self.n_planets, geo.sun, geo.planet, geo.ring
        per_input = self.mesh_frequency_per_input_speed()
        f_t = float(torque) / (sun.reference_radius * n)
        k_mean = self.mesh_stiffnesses()
        out = []
        for name, mesh, z1, other in (("sun", geo.sun_mesh, sun.teeth, sun),
                                      ("ring", geo.ring_mesh, planet.teeth, ring)):
            b = min(planet.face_width, other.face_width)
            m_sp, m_rp = planetary_reduced_masses(
                self.members["sun"].inertia_over_r2 * sun.base_radius ** 2,
                self.members["planet"].inertia_over_r2 * planet.base_radius ** 2,
                sun.base_radius, planet.base_radius, n, b)
            idx = tuple(range(n)) if name == "sun" else tuple(range(n, 2 * n))
            out.append(KvMeshGroup(name, mesh, idx, f_t, m_sp if name == "sun" else m_rp,
                                   per_input / z1, float(np.mean(k_mean[list(idx)]))))
        return tuple(out)

    def input_speed_sweep(self, rpm: np.ndarray) -> tuple[str, np.ndarray]:
        """``input_speed`` [rpm] itself."""
        return INPUT_SPEED, np.asarray(rpm, dtype=float)

    def mesh_frequency_per_input_speed(self) -> float:
        """Mesh frequency over input speed (both rad/s) of a set built from geometry. The mesh
        frequency is Z_s times the sun's speed relative to the carrier: Z_s Z_r / (Z_s + Z_r)
        with the ring held (sun input), Z_s with the carrier held (sun input) or with the sun
        held (carrier input). A set without geometry raises :class:`ParameterError`."""
        geo = self.geometry
        if geo is None:
            raise ParameterError(INPUT_SPEED, None, "needs a gear set built from geometry "
                                 "(from_geometry or [params.geometry]: the tooth counts); sweep "
                                 "mesh_frequency [rad/s] instead")
        zs, zr = geo.sun.teeth, geo.ring.teeth
        return zs * zr / (zs + zr) if self.held == "ring" else float(zs)

    @property
    def input_speed(self) -> float:
        """The input member's speed [rpm] at the model's mesh frequency (set from geometry)."""
        w = self.mesh_frequency / self.mesh_frequency_per_input_speed()
        return w * 60.0 / (2.0 * math.pi)

    def param_attrs(self, name: str) -> dict[str, str]:
        """Attributes of a swept parameter's axis: ``units`` (SI, rpm for ``input_speed``)
        and, for the speeds, ``long_name``; empty for a name without a known unit."""
        if name == INPUT_SPEED:
            held = self.held
            return {"units": "rpm", "long_name": f"input ({self.input_member}) speed",
                    "meaning": f"mesh frequency / {self.mesh_frequency_per_input_speed():.6g} "
                               f"({held} held), in rpm"}
        declared = self.swept_inputs().get(name)
        if name == "mesh_frequency":
            return {"units": declared.axis_unit, "long_name": "mesh frequency"}
        if name == "Omega":
            if self.mesh_order == 1:
                return {}
            return {"units": "1", "long_name": "forcing frequency / time_scale",
                    "meaning": f"mesh frequency / ({self.mesh_order} time_scale): one forcing "
                               f"period is {self.mesh_order} mesh cycles"}
        return {} if declared is None else {"units": declared.axis_unit}

    def speed_axes(self, omega: np.ndarray) -> dict[str, tuple[np.ndarray, dict]]:
        """Mesh frequency [Hz] and, for a set built from geometry, input speed [rpm] at the
        dimensionless mesh frequencies ``omega`` (coordinates along Omega)."""
        w = np.asarray(omega, dtype=float) * self.time_scale * self.mesh_order
        out = {"mesh_frequency": (w / (2.0 * math.pi),
                                  {"units": "Hz", "long_name": "mesh frequency"})}
        if self.geometry is not None:
            attrs = self.param_attrs(INPUT_SPEED)
            out[INPUT_SPEED] = (w / self.mesh_frequency_per_input_speed() * 60.0
                                / (2.0 * math.pi), attrs)
        return out

    # ------------------------------------------------------------------ assembly (SI)
    def full_dof_names(self) -> tuple[str, ...]:
        """Coordinates of the full model: x, y, u of carrier, ring, sun; zeta, eta, u per
        planet."""
        names = [f"{v}_{_SHORT[m]}" for m in CENTRAL for v in ("x", "y", "u")]
        for i in range(self.n_planets):
            names += [f"zeta_{i + 1}", f"eta_{i + 1}", f"u_{i + 1}"]
        return tuple(names)

    def _full_mass(self) -> np.ndarray:
        d = []
        for k in (*CENTRAL,) + ("planet",) * self.n_planets:
            m = self.members[k]
            d += [m.mass, m.mass, m.inertia_over_r2]
        return np.diag(d)

    def _full_support_stiffness(self) -> np.ndarray:
        """Bearings, torsional supports and planet bearings [N/m] (full coordinates)."""
        nf = 9 + 3 * self.n_planets
        K = np.zeros((nf, nf))
        for j, k in enumerate(CENTRAL):
            m = self.members[k]
            K[3 * j, 3 * j] += m.bearing_stiffness
            K[3 * j + 1, 3 * j + 1] += m.bearing_stiffness
            K[3 * j + 2, 3 * j + 2] += m.torsional_stiffness
        kp = self.members["planet"].bearing_stiffness
        for i, psi in enumerate(self.psi):
            o = 9 + 3 * i
            for row in (self._row({0: math.cos(psi), 1: math.sin(psi), o: -1.0}),
                        self._row({0: -math.sin(psi), 1: math.cos(psi), 2: 1.0, o + 1: -1.0})):
                K += kp * np.outer(row, row)
        return _clean(K)

    def _row(self, entries: dict[int, float]) -> np.ndarray:
        r = np.zeros(9 + 3 * self.n_planets)
        for j, v in entries.items():
            r[j] += v
        return r

    def full_mesh_rows(self) -> np.ndarray:
        """Mesh deflection rows (2N, full coordinates): sun-planet meshes, then ring-planet."""
        a_s, a_r = self.alpha_s, self.alpha_r
        rows = []
        for i, psi in enumerate(self.psi):
            o = 9 + 3 * i
            ps = psi - a_s
            rows.append(self._row({6: -math.sin(ps), 7: math.cos(ps), 8: 1.0,
                                   o: -math.sin(a_s), o + 1: -math.cos(a_s), o + 2: 1.0}))
        for i, psi in enumerate(self.psi):
            o = 9 + 3 * i
            pr = psi + a_r
            rows.append(self._row({3: -math.sin(pr), 4: math.cos(pr), 5: 1.0,
                                   o: math.sin(a_r), o + 1: -math.cos(a_r), o + 2: -1.0}))
        return _clean(np.array(rows))

    def constraint(self) -> np.ndarray:
        """T (full dofs x model dofs): full coordinates = T @ model coordinates."""
        names = self.full_dof_names()
        nf = len(names)
        keep: list[int] = []
        for j, k in enumerate(CENTRAL):
            if k in self.fixed:
                continue
            keep += [3 * j + 2] if self.rotational_only else [3 * j, 3 * j + 1, 3 * j + 2]
        for i in range(self.n_planets):
            o = 9 + 3 * i
            keep += [o + 2] if self.rotational_only else [o, o + 1, o + 2]
        T = np.zeros((nf, len(keep)))
        for col, j in enumerate(keep):
            T[j, col] = 1.0
        if self.rotational_only and "carrier" not in self.fixed:
            uc = keep.index(2)
            for i in range(self.n_planets):
                T[9 + 3 * i + 1, uc] = 1.0  # eta_n = u_c: planets carried by the carrier
        self._kept = keep
        return T

    def dof_names(self) -> tuple[str, ...]:
        """The model's coordinates (the full ones kept by :meth:`constraint`)."""
        self.constraint()
        full = self.full_dof_names()
        return tuple(full[j] for j in self._kept)

    def mass_matrix(self) -> np.ndarray:
        """M [kg] in the model's coordinates."""
        T = self.constraint()
        return T.T @ self._full_mass() @ T

    def mesh_rows(self) -> np.ndarray:
        """Mesh deflection rows (2N, model coordinates)."""
        return self.full_mesh_rows() @ self.constraint()

    def mesh_stiffnesses(self) -> np.ndarray:
        """Mean stiffness [N/m] of every mesh (sun-planet meshes, then ring-planet)."""
        n = self.n_planets
        return np.concatenate([np.full(n, self.k_s, dtype=float),
                               np.full(n, self.k_r, dtype=float)])

    def stiffness_matrix(self, meshes: bool = True) -> np.ndarray:
        """K [N/m] in the model's coordinates at mean mesh stiffness (no backlash); without the
        mesh springs when ``meshes`` is False."""
        T = self.constraint()
        K = T.T @ self._full_support_stiffness() @ T
        if meshes:
            W = self.mesh_rows()
            K = K + W.T @ (self.mesh_stiffnesses()[:, None] * W)
        return K

    def _eig(self) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues (rad/s)^2 ascending and mass-normalised shapes of K phi = lam M phi."""
        from scipy.linalg import eigh

        lam, phi = eigh(self.stiffness_matrix(), self.mass_matrix())
        big = float(np.max(np.abs(lam))) if lam.size else 0.0
        return np.where(lam > 1e-12 * big, lam, 0.0), phi  # a rigid-body mode: exactly 0

    def _damping_matrix(self) -> np.ndarray:
        """Viscous damping [N s/m]: modal (M Phi diag(2 zeta w) Phi^T M) plus nothing per mesh
        (mesh damping acts in the mesh force)."""
        M = self.mass_matrix()
        if self.modal_damping == 0.0:
            return np.zeros_like(M)
        lam, phi = self._eig()
        return _clean(M @ phi @ np.diag(2.0 * self.modal_damping * np.sqrt(lam)) @ phi.T @ M)

    def _mesh_damping(self) -> np.ndarray:
        """c_m = 2 zeta_m sqrt(k_m m_e) [N s/m] of every mesh."""
        jp = self.members["planet"].inertia_over_r2
        out = []
        for k, gear in ((self.k_s, "sun"), (self.k_r, "ring")):
            jg = self.members[gear].inertia_over_r2
            out.append(np.full(self.n_planets, 2.0 * np.sqrt(k * jg * jp / (jg + jp))))
        return np.concatenate(out) * np.tile(self.mesh_damping, 2)

    def _forces(self) -> np.ndarray:
        """Mean generalised forces [N] on the model's coordinates, and the fluctuating part."""
        F = np.zeros(9 + 3 * self.n_planets)
        Fl = np.zeros_like(F)
        for j, k in enumerate(CENTRAL):
            if self.torques[k] != 0.0:
                F[3 * j + 2] = self.torques[k] / self.members[k].radius
        Fl[8] = F[8] * self.torque_fluctuation
        T = self.constraint()
        return np.stack([T.T @ F, T.T @ Fl])

    # ------------------------------------------------------------------ coefficient vector
    def _build(self, omega: float) -> None:
        names = self.dof_names()
        n = len(names)
        nm = 2 * self.n_planets
        nh = self.fourier.shape[1] // 2
        kt_entries, mesh_dofs = self._kernel_structure()
        M = self.mass_matrix()
        Minv = np.diag(1.0 / np.diag(M))
        G, K_omega, f = self.rotating_frame_matrices()
        G_unit = _clean(Minv @ G)  # M^-1 G (structural: the gyro section)
        gyro = [(int(i), int(j)) for i, j in zip(*np.nonzero(G_unit), strict=True)]
        lay = pk.layout(n, nm, nh, len(kt_entries), len(gyro))
        L, w0 = self.length_scale, self.time_scale
        p = np.zeros(lay["size"])
        p[pk.OMEGA] = omega
        p[pk.N_DOF], p[pk.N_MESH], p[pk.N_HARM] = n, nm, nh
        F = self._forces()
        K, C = self.stiffness_matrix(False), self._damping_matrix()
        wc = self.carrier_omega(omega * w0 * self.mesh_order)
        if wc != 0.0:  # the rotating carrier (see rotating_frame_matrices); G: the gyro section
            K = _clean(K - wc * wc * K_omega)
            F = F.copy()
            F[0] = F[0] + wc * wc * f
        p[pk.TORQUE_ON] = float(np.any(F[1] != 0.0))
        p[pk.TORQUE_ORDER], p[pk.TORQUE_PHASE] = self.torque_order, self.torque_phase
        p[lay["F0"]:lay["F0"] + n] = Minv @ F[0] / (L * w0 * w0)
        p[lay["F1"]:lay["F1"] + n] = Minv @ F[1] / (L * w0 * w0)
        p[lay["Kt"]:lay["Kt"] + n * n] = (Minv @ K).ravel() / w0**2
        p[lay["Ct"]:lay["Ct"] + n * n] = (Minv @ C).ravel() / w0
        p[pk.DAMPED] = float(np.any(p[lay["Ct"]:lay["Ct"] + n * n] != 0.0))
        W = self.mesh_rows()
        k, c = self.mesh_stiffnesses(), self._mesh_damping()
        kc = self.coast_stiffnesses()
        for m in range(nm):
            o = lay["mesh"] + m * lay["block"]
            self._fill_mesh_block(p[o:o + lay["block"]], m, L, w0, k[m], c[m], kc[m], 1.0, W[m],
                                  Minv @ W[m] / (L * w0 * w0))
        self._layout = lay
        self._coast_given = any(self.inputs[k] is not None for k in (
            "sun_coast_stiffness", "ring_coast_stiffness", "coast_waveform"))
        self._coast_built = p[_flank_index(lay, n, nm, nh, True)].copy()
        p[pk.TWO_FLANK] = self._two_flank(p[None, :])[0]
        self._structure = (kt_entries, mesh_dofs)
        pk.fill_structure(p, kt_entries, mesh_dofs)
        p[lay["cache"]:lay["gyro"]] = pk.cache_entries(nm)[1]
        g, ng = lay["gyro"], len(gyro)
        p[g], p[g + 1] = wc / w0, ng
        p[g + 2:g + 2 + ng] = [i for i, _ in gyro]
        p[g + 2 + ng:g + 2 + 2 * ng] = [j for _, j in gyro]
        p[g + 2 + 2 * ng:g + 2 + 3 * ng] = [G_unit[i, j] for i, j in gyro]
        self.coefficient_layout = planetary_layout(names, self.mesh_names, nh, tuple(kt_entries),
                                                   tuple(gyro))
        if self.coefficient_layout.size != p.size:
            raise RuntimeError("the declared coefficient layout does not match the kernel's")
        self.params = p
        self.omega_index = pk.OMEGA
        self.kernel = _KERNEL
        self.state_names = names + tuple(f"d{d}" for d in names)
        self.observable_names = tuple(f"F_{m}" for m in self.mesh_names)
        self.event_names = tuple(f"x_{m}{s}b_{m}" for m in self.mesh_names for s in "-+")
        self.meshes = tuple((m, 2 * i, 2 * i + 1) for i, m in enumerate(self.mesh_names))
        self._layout = lay

    def _fill_mesh_block(self, blk: np.ndarray, m: int, L: float, w0: float, drive: float,
                         damping: float, coast: float, order: float, row: np.ndarray,
                         force_row: np.ndarray) -> None:
        """Mesh m's block of the coefficient vector (:mod:`~geardyn.models.planetary_kernels`'s
        mesh block): its backlash, error, drive and coast force per deflection ``drive``,
        ``coast`` [N/m] and per rate ``damping`` [N s/m], ``order``, Fourier coefficients,
        deflection ``row`` and ``force_row`` (M^-1 W^T / (L omega_0^2)); ``L`` [m], ``w0``
        [rad/s] the length and frequency scales."""
        blk[pk.M_B] = self.backlash[m] / L
        blk[pk.M_ES] = self.error[m] * math.cos(self.error_phase[m]) / L
        blk[pk.M_EC] = self.error[m] * math.sin(self.error_phase[m]) / L
        blk[pk.M_KF] = drive * L
        blk[pk.M_CF] = damping * L * w0
        blk[pk.M_KFC] = coast * L
        blk[pk.M_ORDER] = order
        nh, n = self.fourier.shape[1] // 2, row.size
        f = pk.MESH_FIXED
        blk[f:f + 2 * nh] = self.fourier[m]
        blk[f + 2 * nh:f + 2 * nh + n] = row
        blk[f + 2 * nh + n:f + 2 * nh + 2 * n] = force_row
        blk[f + 2 * nh + 2 * n:] = self.fourier_coast[m]

    def _kernel_structure(self) -> tuple[list[tuple[int, int]], list[list[int]]]:
        """The entries of Kt that the supports can make non-zero (row-major) and the model dofs
        each mesh row touches (ascending), from the structure alone (not the values), so the
        same for every lane of a sweep; see :func:`planetary_kernels.fill_structure`."""
        nf = 9 + 3 * self.n_planets
        Tf = self.constraint()
        Sm = np.eye(Tf.shape[1], dtype=bool)  # bearings and supports of the members
        rows_s, rows_r = [], []
        for i, psi in enumerate(self.psi):  # a planet bearing: one stiffness, two directions
            o = 9 + 3 * i
            c, s = math.cos(psi), math.sin(psi)
            Kn = sum(np.outer(r, r) for r in (self._row({0: c, 1: s, o: -1.0}),
                                              self._row({0: -s, 1: c, 2: 1.0, o + 1: -1.0})))
            Sm |= _clean(Tf.T @ Kn @ Tf) != 0.0
            rows_s.append([6, 7, 8, o, o + 1, o + 2])
            rows_r.append([3, 4, 5, o, o + 1, o + 2])
        T = (Tf != 0.0).astype(int)
        kt = [(int(i), int(j)) for i, j in zip(*np.nonzero(Sm), strict=True)]
        dofs = []
        for keys in rows_s + rows_r:
            r = np.zeros(nf, dtype=int)
            r[keys] = 1
            dofs.append([int(j) for j in np.nonzero(r @ T)[0]])
        return kt, dofs

    def swept_inputs(self) -> dict[str, PhysicalInput]:
        """The declared inputs a sweep takes by name (``swept``, :attr:`input_declarations`),
        in declared order."""
        return _swept(type(self).input_declarations)

    @property
    def physical_names(self) -> tuple[str, ...]:
        """The swept inputs (:meth:`swept_inputs`: e.g. ``sun_backlash``, ``mesh_frequency``,
        ``sun_torque``; SI) given as one value for every planet, and ``input_speed`` [rpm] of
        a set built from geometry (raw coefficients are in ``param_names``)."""
        names = tuple(k for k in self.swept_inputs() if k in self.inputs
                      and one_value(self.inputs[k]))
        return names + ((INPUT_SPEED,) if self.geometry is not None else ())

    @property
    def mesh_names(self) -> tuple[str, ...]:
        """``s1..sN`` (sun-planet meshes), then ``r1..rN`` (ring-planet meshes)."""
        n = self.n_planets
        return tuple(f"s{i + 1}" for i in range(n)) + tuple(f"r{i + 1}" for i in range(n))

    # ------------------------------------------------------------------ parameters by name
    def with_params(self, **values: float) -> PlanetaryGearSet:
        """A copy with parameters changed by name: constructor inputs (``sun_mesh_stiffness``,
        ``sun_backlash``, ``mesh_frequency``, ``sun_torque``, ...) rebuild the model with the
        same length and time scales; ``Omega`` (dimensionless mesh frequency) and raw
        coefficients (``param_names``) set that entry of the vector. ``input_speed`` (a set
        built from geometry; rpm, or a unit string such as ``"3000 rpm"``) sets the mesh
        frequency (:meth:`mesh_frequency_per_input_speed`)."""
        if "Omega" in values and not self.omega_is_entry:  # Omega moves the carrier speed
            values = dict(values)
            om = float(values.pop("Omega"))
            if "mesh_frequency" in values or INPUT_SPEED in values:
                raise ParameterError("Omega", om, "sets the mesh frequency: give it, "
                                     "mesh_frequency or input_speed, one of them")
            out = self.with_params(mesh_frequency=om * self.time_scale * self.mesh_order,
                                   **values)
            out.params[pk.OMEGA] = om
            return out
        if INPUT_SPEED in values:
            values = dict(values)
            rpm = _rpm(INPUT_SPEED, values.pop(INPUT_SPEED))
            if "mesh_frequency" in values or "Omega" in values:
                raise ParameterError(INPUT_SPEED, rpm, "sets the mesh frequency: give it, "
                                     "mesh_frequency or Omega, one of them")
            values["mesh_frequency"] = (rpm * 2.0 * math.pi / 60.0
                                        * self.mesh_frequency_per_input_speed())
        physical = {k: v for k, v in values.items() if k in self.inputs}
        rest = {k: float(v) for k, v in values.items() if k not in physical}
        for name, value in rest.items():  # unknown, structure, workspace: refused first
            self._raw_target(name, value)
        raw = self.raw_overrides
        if physical:
            kw = {**self.inputs, "time_scale": self.time_scale,
                  "length_scale": self.length_scale, **physical}
            if "mesh_frequency" not in physical:
                kw["mesh_frequency"] = self.mesh_frequency
            out = type(self)(**kw)
            if "mesh_frequency" not in physical:  # Omega as it was, not (Omega w0) / w0
                out.params[pk.OMEGA] = self.omega
            for name in _FROM_BUILD:  # what from_geometry attached (the inputs came from it)
                if name in self.__dict__:
                    setattr(out, name, self.__dict__[name])
            rest = {**raw, **rest}
        else:
            out = copy.copy(self)
        if rest:
            out = Model._with_raw(out, rest)
            out._refresh_workspace(out.params)  # the flags and copies follow the raw entries
            out.raw_overrides = {**raw, **{k: v for k, v in rest.items() if k != "Omega"}}
        return out

    def lane_params(self, name: str, values: Sequence[float] | np.ndarray) -> np.ndarray:
        """Coefficient vectors (lanes x n_params) with ``name`` set to ``values`` (a physical
        input re-derives every coefficient, as :meth:`with_params`); a declared input that is
        not swept (:meth:`swept_inputs`: a count, a choice, a table, a list, a scale) is a
        :class:`~geardyn.errors.ParameterError` naming it."""
        if name in self.inputs and name not in self.swept_inputs():
            declared = by_name(self.input_declarations)[name]
            raise ParameterError(name, values, f"not swept ({declared.kind} input of "
                                 f"{self.name}: set it with with_params or in the study); "
                                 f"swept: {', '.join(('Omega', *self.physical_names))}")
        if name in self.inputs or name == INPUT_SPEED or (name == "Omega"
                                                           and not self.omega_is_entry):
            vals = np.asarray(values, dtype=float).ravel()
            rows = [self.with_params(**{name: float(v)}).params for v in vals]
            if len({r.size for r in rows}) != 1:
                raise ValueError(f"sweeping {name!r} changes the model's size")
            return np.array(rows)
        P = Model.lane_params(self, name, values)
        self._refresh_workspace(P)
        return P

    def _refresh_workspace(self, P: np.ndarray) -> None:
        """Write the kernel's flags (``damped``, ``torque_on``) and its copy of Kt, W, G in
        every row of ``P`` (in place) from the row's own coefficients."""
        P = np.atleast_2d(P)
        lay, n = self._layout, int(P[0, pk.N_DOF])
        P[:, pk.DAMPED] = np.any(P[:, lay["Ct"]:lay["Ct"] + n * n] != 0.0, axis=1)
        P[:, pk.TORQUE_ON] = np.any(P[:, lay["F1"]:lay["F1"] + n] != 0.0, axis=1)
        P[:, pk.TWO_FLANK] = self._two_flank(P)
        P[:, pk.MULTI_ORDER] = self._multi_order(P)
        pk.fill_structure(P, *self._structure)

    def _multi_order(self, P: np.ndarray) -> np.ndarray:
        """The kernel's ``MULTI_ORDER`` of every row of ``P``: 1.0 where a mesh's order differs
        from 1, else 0.0."""
        lay = self._layout
        nm = int(P[0, pk.N_MESH])
        idx = [lay["mesh"] + m * lay["block"] + pk.M_ORDER for m in range(nm)]
        return np.any(P[:, idx] != 1.0, axis=1).astype(float)

    def _two_flank(self, P: np.ndarray) -> np.ndarray:
        """The kernel's ``TWO_FLANK`` of every row of ``P``: 1.0 where a coast flank was given
        and differs from its drive flank, or where a coast entry was set (a raw override) away
        from its built value; else 0.0 (a set built without a coast flank: one stiffness on
        both flanks, also after a raw override of the drive entries)."""
        lay = self._layout
        n, nm, nh = (int(P[0, i]) for i in (pk.N_DOF, pk.N_MESH, pk.N_HARM))
        coast = P[:, _flank_index(lay, n, nm, nh, True)]
        out = np.any(coast != self._coast_built, axis=1)
        if self._coast_given:
            out |= np.any(coast != P[:, _flank_index(lay, n, nm, nh, False)], axis=1)
        return out.astype(float)

    # ------------------------------------------------------------------ linear analysis
    def _lane_matrix(self, P: np.ndarray, stiffest: bool = False) -> np.ndarray:
        """Dimensionless mean-stiffness matrices A (lanes, n, n) of X'' = -A X from ``P``: the
        drive flanks' mean stiffness, or with ``stiffest`` each mesh's stiffer flank's (where a
        lane has two flanks)."""
        lay = self._layout
        n, nm, nh = int(P[0, pk.N_DOF]), int(P[0, pk.N_MESH]), int(P[0, pk.N_HARM])
        A = P[:, lay["Kt"]:lay["Kt"] + n * n].reshape(-1, n, n).copy()
        f = pk.MESH_FIXED + 2 * nh
        for m in range(nm):
            o = lay["mesh"] + m * lay["block"]
            W = P[:, o + f:o + f + n]
            G = P[:, o + f + n:o + f + 2 * n]
            kf = P[:, o + pk.M_KF]
            if stiffest:
                kf = np.where(P[:, pk.TWO_FLANK] != 0.0, np.maximum(kf, P[:, o + pk.M_KFC]), kf)
            A += kf[:, None, None] * G[:, :, None] * W[:, None, :]
        return A

    def _gyro_ct(self, P: np.ndarray) -> np.ndarray:
        """The Coriolis part w_c M^-1 G of X'' (lanes, n, n) of every row of ``P`` (the gyro
        section: see :func:`planetary_kernels._gyro_offset`)."""
        n, g = len(self.dof_names()), self._layout["gyro"]
        ng = int(P[0, g + 1])
        out = np.zeros((P.shape[0], n, n))
        rows = P[0, g + 2:g + 2 + ng].astype(int)
        cols = P[0, g + 2 + ng:g + 2 + 2 * ng].astype(int)
        out[:, rows, cols] = P[:, g, None] * P[:, g + 2 + 2 * ng:g + 2 + 3 * ng]
        return out

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """Fastest natural frequency [omega_0] of the linear model at mean stiffness in every
        lane of ``P`` (from the lane's coefficients; one eigenproblem per distinct row), each
        mesh at its stiffer flank's mean stiffness (so that the step resolves either flank)."""
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        rows, inverse = unique_rows(P)
        A = self._lane_matrix(rows, stiffest=True)
        if self.carrier_speed is None and self.carrier_speed_ratio is None:
            return self._mesh_floor(P, np.sqrt(np.max(np.abs(np.linalg.eigvals(A)),
                                                      axis=1))[inverse])
        # a rotating carrier: |lambda| of the first-order matrix with Ct (gyroscopic, damping)
        n, lay = A.shape[1], self._layout
        Ct = rows[:, lay["Ct"]:lay["Ct"] + n * n].reshape(-1, n, n) + self._gyro_ct(rows)
        Z, eye = np.zeros_like(A), np.broadcast_to(np.eye(n), A.shape)
        first = np.concatenate([np.concatenate([Z, eye], 2), np.concatenate([-A, -Ct], 2)], 1)
        return self._mesh_floor(P, np.max(np.abs(np.linalg.eigvals(first)), axis=1)[inverse])

    def _mesh_floor(self, P: np.ndarray, w: np.ndarray) -> np.ndarray:
        """``w``, or with ``mesh_order`` > 1 at least the frequency that gives every mesh cycle
        as many steps as a one-mesh-cycle period gets at the least (MIN_STEPS_PER_PERIOD): the
        step then resolves the mesh harmonics as in the set built over one mesh cycle."""
        if self.mesh_order == 1:
            return w
        floor = (self.mesh_order * P[:, pk.OMEGA] * MIN_STEPS_PER_PERIOD
                 / STEPS_PER_FASTEST_MODE)
        return np.maximum(w, floor)

    def other_frequencies(self, P: np.ndarray) -> np.ndarray:
        """The torque fluctuation's frequency order * Omega where it acts and differs from the
        mesh frequency, else NaN (one column)."""
        P = np.atleast_2d(P)
        on = (P[:, pk.TORQUE_ON] != 0.0) & (P[:, pk.TORQUE_ORDER] != 1.0)
        return np.where(on, P[:, pk.TORQUE_ORDER] * P[:, pk.OMEGA], np.nan)[:, None]

    def _rotating_eig(self) -> tuple[np.ndarray, np.ndarray]:
        """One eigenvalue lambda [rad/s] per mode (Im >= 0, ascending abs(Im)) and complex shapes
        (phi^H M phi = 1, largest entry real; abs(lambda) below 1e-6 of the largest: 0, a
        rigid-body mode; abs(Re lambda) below 1e-9 of it: 0, rounding) of the undamped
        rotating-carrier problem (lambda^2 M + lambda Omega_c G + K - Omega_c^2 K_Omega) phi = 0,
        from its first-order form. Its spectrum is symmetric about both axes: each mode is a
        pair lambda, conj or -lambda, of which the one with the larger imaginary part (and then
        real part) is kept."""
        from scipy.linalg import eig

        wc = self.carrier_omega()
        G, K_omega, _ = self.rotating_frame_matrices()
        M = self.mass_matrix()
        K = self.stiffness_matrix() - wc * wc * K_omega
        n = M.shape[0]
        Minv = np.diag(1.0 / np.diag(M))
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -wc * (Minv @ G)]])
        lam, V = eig(A)
        scale = max(float(np.max(np.abs(lam))), 1e-300)
        im = np.where(np.abs(lam.imag) <= 1e-9 * scale, 0.0, lam.imag)
        order = np.lexsort((-lam.real, -im, np.abs(im)))
        keep = order[0::2]  # the first of each pair: the larger Im, then the larger Re
        keep = keep[np.argsort(np.abs(im[keep]), kind="stable")]
        phi = V[:n, keep]
        norm = np.sqrt(np.real(np.einsum("ik,i,ik->k", phi.conj(), np.diag(M), phi)))
        phi = phi / norm
        big = phi[np.argmax(np.abs(phi), axis=0), np.arange(phi.shape[1])]
        phi = phi * (np.abs(big) / big)
        re = np.where(np.abs(lam.real) <= 1e-9 * scale, 0.0, lam.real)  # rounding: stable
        out = re[keep] + 1j * np.abs(im[keep])
        # a rigid-body mode is a double zero, split by rounding to ~sqrt(eps): exactly 0
        return np.where(np.abs(out) <= 1e-6 * scale, 0.0, out), phi

    def natural_frequencies(self) -> np.ndarray:
        """Natural frequencies [Hz] of the linear model at mean stiffness, ascending, each
        repeated by its multiplicity (a rigid-body mode gives 0). With a carrier speed: the
        frequencies abs(Im lambda) / 2 pi of the rotating-carrier problem in the carrier frame
        (:meth:`modes` has its growth rates)."""
        if self.carrier_omega() != 0.0:
            return np.abs(self._rotating_eig()[0].imag) / (2.0 * math.pi)
        lam, _ = self._eig()
        return np.sqrt(lam) / (2.0 * math.pi)

    def modes(self):
        """Natural frequencies and mode shapes, classified (xarray Dataset over ``mode``).

        Variables: ``frequency`` [Hz], ``multiplicity`` (of the frequency, within
        :data:`~geardyn.trains.MULTIPLICITY_RTOL`), ``type`` (``"rotational"``: no member
        centre moves;
        ``"translational"``: the carrier, ring and sun do not rotate; ``"planet"``: only the
        planets move; ``"mixed"`` otherwise, e.g. unequal spacing), ``shape`` (mode, dof):
        mass-normalised shapes [kg^-1/2] in the model's coordinates. A repeated frequency's
        shapes span its eigenspace and are classified together. With a carrier speed: the
        modes of the gyroscopic problem (:meth:`natural_frequencies`), complex shapes
        (phi^H M phi = 1) classified by their energy shares, and ``growth_rate`` [1/s], Re
        lambda (> 0: the linear model is unstable at that speed, divergence or flutter).
        """
        import xarray as xr

        extra = {}
        if self.carrier_omega() != 0.0:
            lam, phi = self._rotating_eig()
            f = np.abs(lam.imag) / (2.0 * math.pi)
            extra["growth_rate"] = ("mode", lam.real, {"units": "1/s"})
        else:
            lam, phi = self._eig()
            f = np.sqrt(lam) / (2.0 * math.pi)
        groups = frequency_groups(f)
        names = self.dof_names()
        mult = np.zeros(f.size, int)
        kind = np.empty(f.size, object)
        for g in groups:
            mult[g] = len(g)
            kind[g] = self._classify(phi[:, g], names)
        return xr.Dataset(
            {"frequency": ("mode", f, {"units": "Hz"}),
             "multiplicity": ("mode", mult),
             "type": ("mode", kind.astype(str)),
             "shape": (("mode", "dof"), phi.T, {"units": "kg^-1/2"}), **extra},
            coords={"mode": np.arange(f.size), "dof": list(names)},
            attrs={"model": self.name, "n_planets": self.n_planets,
                   "rotational_only": int(self.rotational_only),
                   "carrier_speed": self.carrier_omega(),
                   "carrier_speed_units": "rad/s",
                   "centrifugal_preload": int(self.centrifugal_preload)})

    def _classify(self, shapes: np.ndarray, names: tuple[str, ...], tol: float = 1e-6) -> str:
        """Kind of the eigenspace spanned by ``shapes`` (dofs x k), from the energy of its parts
        (basis-independent: sums over the space)."""
        M = np.diag(self.mass_matrix())
        e = np.sum(M[:, None] * np.abs(shapes)**2, axis=1)  # kinetic-energy share per dof
        total = e.sum()
        central = np.array([d.endswith(("_c", "_r", "_s")) for d in names])
        trans = central & np.array([d[0] in "xy" for d in names])
        rot = central & np.array([d[0] == "u" for d in names])
        if e[central].sum() <= tol * total:
            return "planet"
        if e[trans].sum() <= tol * total and self._planets_alike(shapes, names, tol):
            return "rotational"
        if e[rot].sum() <= tol * total:
            return "translational"
        return "mixed"

    def _planets_alike(self, shapes: np.ndarray, names: tuple[str, ...], tol: float) -> bool:
        """Every planet moves alike (in its own frame) in every shape."""
        n = self.n_planets
        per = [[j for j, d in enumerate(names) if d.endswith(f"_{i + 1}")] for i in range(n)]
        first = shapes[per[0]]
        scale = max(float(np.max(np.abs(shapes))), 1e-300)
        return all(np.max(np.abs(shapes[p] - first)) <= math.sqrt(tol) * scale for p in per[1:])

    # ------------------------------------------------------------------ static state
    def static_state(self) -> np.ndarray:
        """Dimensionless coordinates X of the quasi-static state under the mean torques (mean
        stiffness, no error), each loaded mesh on its loaded flank: A X = F0 + sum kf b s G,
        the flank signs s iterated (a mesh on its coast flank, s < 0, with the coast flank's
        mean stiffness); least squares where a rigid-body mode leaves A singular. With a
        radial contact (:mod:`~geardyn.models.planetary_kernels`): :meth:`_radial_static`."""
        lay = self._layout
        n, nm, nh = int(self.params[pk.N_DOF]), int(self.params[pk.N_MESH]), \
            int(self.params[pk.N_HARM])
        A = self._lane_matrix(self.params[None, :])[0]
        F0 = self.params[lay["F0"]:lay["F0"] + n]
        f = pk.MESH_FIXED + 2 * nh
        blocks = [self.params[lay["mesh"] + m * lay["block"]:][:lay["block"]] for m in range(nm)]
        if any(b[pk.M_RADIAL] != 0.0 for b in blocks):
            return self._radial_static(A, F0, blocks, f, n)
        sign = np.zeros(nm)
        X = np.zeros(n)
        two = self.params[pk.TWO_FLANK] != 0.0
        for _ in range(4):
            kf = [b[pk.M_KFC] if two and sign[m] < 0.0 else b[pk.M_KF]
                  for m, b in enumerate(blocks)]
            if two:  # each mesh's flank stiffness in A
                A = self.params[lay["Kt"]:lay["Kt"] + n * n].reshape(n, n).copy()
                for m, b in enumerate(blocks):
                    A += kf[m] * b[f + n:f + 2 * n, None] * b[None, f:f + n]
            rhs = F0 + sum(kf[m] * b[pk.M_B] * sign[m] * b[f + n:f + 2 * n]
                           for m, b in enumerate(blocks))
            X = _clean(np.linalg.lstsq(A, rhs, rcond=None)[0])
            d = np.array([b[f:f + n] @ X for b in blocks])
            new = np.sign(d)
            if np.array_equal(new, sign):
                break
            sign = new
        return X

    def _radial_static(self, A0: np.ndarray, F0: np.ndarray, blocks: list[np.ndarray], f: int,
                       n: int) -> np.ndarray:
        """:meth:`static_state` with radial contacts (x row m, y row m + 1): in A X = F0 + sum
        kf b s G, s of a radial row is its deflection over max(r, b) (kf (1 - b / r) (x, y) in
        contact, no force inside the clearance), a dead zone's s its sign. Every contact starts
        in contact along the linear state's deflection (one step of the sign iteration), then
        Newton's method (least squares) until the step is below ``STATIC_STEP_TOL`` of X with
        the signs settled."""
        W = np.array([b[f:f + n] for b in blocks])
        G = np.array([b[f + n:f + 2 * n] for b in blocks])
        kind = np.array([b[pk.M_RADIAL] for b in blocks])
        kfd = np.array([b[pk.M_KF] for b in blocks])
        kfc = np.array([b[pk.M_KFC] for b in blocks])
        half = np.array([b[pk.M_B] for b in blocks])
        lay = self._layout
        Kt = self.params[lay["Kt"]:lay["Kt"] + n * n].reshape(n, n)
        two = self.params[pk.TWO_FLANK] != 0.0
        xs = np.flatnonzero(kind > 0.0)

        def shares(X: np.ndarray, start: bool) -> tuple[np.ndarray, np.ndarray]:
            """s of every contact at X and the dead zones' signs (``start``: every radial
            contact in contact along its deflection)."""
            d = W @ X
            s = np.sign(d)
            for m in xs:
                r = math.hypot(d[m], d[m + 1])
                scale = r if start else max(r, half[m])
                s[m:m + 2] = d[m:m + 2] / scale if scale > 0.0 else 0.0
            return s, np.sign(d)

        def matrix(sign: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            kf = np.where(two & (sign < 0.0) & (kind == 0.0), kfc, kfd)
            return (Kt + (kf[:, None] * G).T @ W if two else A0), kf

        X = _clean(np.linalg.lstsq(A0, F0, rcond=None)[0])
        s, sign = shares(X, True)
        A, kf = matrix(sign)
        X = np.linalg.lstsq(A, F0 + (kf * half * s) @ G, rcond=None)[0]
        for _ in range(STATIC_ITERATIONS):
            s, new = shares(X, False)
            A, kf = matrix(new)
            J = A.copy()
            d = W @ X
            for m in xs:
                x, y = d[m], d[m + 1]
                r = math.hypot(x, y)
                if r > half[m]:  # d(x / r) / dX and d(y / r) / dX
                    gx = (y * y * W[m] - x * y * W[m + 1]) / r**3
                    gy = (x * x * W[m + 1] - x * y * W[m]) / r**3
                else:  # d / b
                    gx, gy = W[m] / half[m], W[m + 1] / half[m]
                J -= kf[m] * half[m] * (np.outer(G[m], gx) + np.outer(G[m + 1], gy))
            step = np.linalg.lstsq(J, A @ X - F0 - (kf * half * s) @ G, rcond=None)[0]
            X = X - step
            if np.max(np.abs(step)) <= STATIC_STEP_TOL * np.max(np.abs(X)) \
                    and np.array_equal(new, sign):
                return _clean(X)
            sign = new
        raise ParameterError("static_state", None, "the quasi-static state with a radial "
                             f"contact did not converge in {STATIC_ITERATIONS} Newton steps")

    def bearing_forces(self, y: np.ndarray) -> dict[str, np.ndarray]:
        """Bearing forces [N] at states ``y`` (..., n_states; e.g. stacked from a
        :func:`~geardyn.simulate` result): ``F_<c|r|s>_x``, ``F_<c|r|s>_y`` (the bearing spring
        forces k_b x, k_b y of carrier, ring and sun, where they have coordinates) and per planet
        ``F_p<n>_radial``, ``F_p<n>_tangential`` (k_p times the planet bearing's radial and
        tangential deflections, see ``docs/planetary.md``). Not observables of the kernel, so
        that sweeps keep one observable per mesh (and the dynamic factors)."""
        y = np.asarray(y, dtype=float)
        n = len(self.dof_names())
        q = self.length_scale * (y[..., :n] @ self.constraint().T)  # full coordinates [m]
        out: dict[str, np.ndarray] = {}
        for j, k in enumerate(CENTRAL):
            if k in self.fixed or self.rotational_only:
                continue
            kb = self.members[k].bearing_stiffness
            out[f"F_{_SHORT[k]}_x"] = kb * q[..., 3 * j]
            out[f"F_{_SHORT[k]}_y"] = kb * q[..., 3 * j + 1]
        kp = self.members["planet"].bearing_stiffness
        for i, psi in enumerate(self.psi):
            o = 9 + 3 * i
            c, s = math.cos(psi), math.sin(psi)
            radial = c * q[..., 0] + s * q[..., 1] - q[..., o]
            tangential = -s * q[..., 0] + c * q[..., 1] - q[..., o + 1] + q[..., 2]
            if not self.rotational_only:
                out[f"F_p{i + 1}_radial"] = kp * radial
                out[f"F_p{i + 1}_tangential"] = kp * tangential
        return out

    def initial_state(self) -> np.ndarray:
        """The quasi-static state (:meth:`static_state`), at rest."""
        return np.concatenate([self.static_state(), np.zeros(len(self.state_names) // 2)])

    def static_mesh_forces(self) -> np.ndarray:
        """Static mesh forces [N] of the quasi-static state, in the order of the meshes."""
        lay = self._layout
        n, nm, nh = (int(self.params[i]) for i in (pk.N_DOF, pk.N_MESH, pk.N_HARM))
        X = self.static_state()
        f = pk.MESH_FIXED + 2 * nh
        out = np.empty(nm)
        for m in range(nm):
            b = self.params[lay["mesh"] + m * lay["block"]:][:lay["block"]]
            d = b[f:f + n] @ X
            two = self.params[pk.TWO_FLANK] != 0.0
            kf = b[pk.M_KFC] if two and d < -b[pk.M_B] else b[pk.M_KF]
            out[m] = kf * dead_zone.py_func(d, b[pk.M_B])  # plain Python: nothing to compile
            j = int(b[pk.M_RADIAL])
            if j:  # a radial contact: its component of kf (1 - b / r) (x, y)
                other = self.params[lay["mesh"] + (m + j) * lay["block"]:][:lay["block"]]
                r = math.hypot(d, other[f:f + n] @ X)
                out[m] = b[pk.M_KF] * (1.0 - b[pk.M_B] / r) * d if r > b[pk.M_B] else 0.0
        return out

    def __repr__(self) -> str:
        form = "rotational-only" if self.rotational_only else "rotational-translational"
        return (f"PlanetaryGearSet(N={self.n_planets}, {form}, dofs={len(self.dof_names())}, "
                f"Omega={self.omega:g})")


def _geometry_stiffness(geometry: Any, method: str, options: Mapping[str, Any] | None,
                        waveform_options: Mapping[str, Any] | None, harmonics: int,
                        coast: str) -> tuple[dict[str, Any], Any, Any]:
    """The stiffness inputs of the set (``*_mesh_stiffness``, ``waveform`` and with ``coast =
    "mirror"`` the coast flank's: ``coast_waveform``, the ISO series mirrored about each mesh's
    coast phase, or ``*_coast_stiffness`` and ``coast_waveform`` from the potential-energy
    tables); the potential-energy tables (or None) and the ISO waves (or None)."""
    if method == "iso":
        from geardyn.gears.potential_energy import coast_phase

        w_sun, w_ring = geometry.waveforms(**dict(waveform_options or {}))
        drive = {"sun": w_sun.fourier(harmonics), "ring": w_ring.fourier(harmonics)}
        out: dict[str, Any] = {"sun_mesh_stiffness": w_sun.mean,
                               "ring_mesh_stiffness": w_ring.mean, "waveform": drive}
        if coast == "mirror":
            out["coast_waveform"] = {
                g: mirrored(*drive[g], coast_phase(mesh))
                for g, mesh in (("sun", geometry.sun_mesh), ("ring", geometry.ring_mesh))}
        return out, None, (w_sun, w_ring)
    if waveform_options:
        raise ParameterError("waveform_options", dict(waveform_options),
                             "only with stiffness='iso' (the ISO waves)")
    opts = potential_energy_options(options, geometry, harmonics)
    tables = potential_energy_tables(geometry, opts)
    out = {"waveform": {}, "coast_waveform": {}}
    for g, table in zip(("sun", "ring"), tables, strict=True):
        series = flank_series(table["mesh_stiffness"].values, harmonics)
        out[f"{g}_mesh_stiffness"], out["waveform"][g] = series.mean, series.pair
        series = flank_series(table["mesh_stiffness_coast"].values, harmonics)
        out[f"{g}_coast_stiffness"], out["coast_waveform"][g] = series.mean, series.pair
    if coast == "symmetric":
        for key in _COAST_FROM_GEOMETRY:
            out.pop(key)
    return out, tables, None


def _held(held: str | None, fixed: tuple[str, ...]) -> str:
    """The member held in the input-speed kinematics: ``held``, else the one member in
    ``fixed``, else the ring."""
    if held is None:
        return fixed[0] if len(fixed) == 1 else "ring"
    if held not in CENTRAL:
        raise ParameterError("held", held, f"must be one of {', '.join(CENTRAL)}")
    return held


def _sun_turns(held: str) -> int:
    """The sense of the sun's rotation relative to the carrier, the input member turning in the
    sense of psi and u: +1 with the ring or carrier held (sun input), -1 with the sun held
    (carrier input; the sun then turns backwards relative to the carrier)."""
    return -1 if held == "sun" else 1


def _kinematic_ratio(held: str, geometry: Any) -> float:
    """Carrier speed over mesh frequency from the tooth counts: 1/Z_r with the ring held,
    1/Z_s with the sun held, 0 with the carrier held (the mesh frequency is Z_r abs(w_r - w_c) =
    Z_s abs(w_s - w_c))."""
    return {"ring": 1.0 / geometry.ring.teeth, "sun": 1.0 / geometry.sun.teeth,
            "carrier": 0.0}[held]
