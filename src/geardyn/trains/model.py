"""The nonlinear model of a gear train: its linear structure with every mesh nonlinear.

:class:`TrainModel` takes a :class:`~geardyn.trains.GearTrain` (M, K, C at mean stiffness, the
mesh deflection rows, speed ratios and mesh orders) and writes the coefficient vector of the
planetary gear set's compiled kernels (:mod:`geardyn.models.planetary_kernels`), which are a
general "linear structure + meshes" form: no kernel is compiled per train. Dimensionless as
there: X = q / L (q: the train's coordinates, rad and m), tau = omega_0 t::

    X'' = F0 + F1 sin(order Omega tau + phase) - Kt X - Ct X' - sum_m f_m G_m
    f_m = KF_m k_m(theta_m) g(W_m . X - e_m, b_m) + CF_m (W_m . X' - e_m')

with k_m the drive flank's relative stiffness where g > 0 and the coast flank's, kc_m, where
g < 0 (``coast="mirror"``, meshes whose two gears have geometry: the drive flank's mirror image
about the mesh's coast phase; else kc_m = k_m). A mesh on the potential-energy stiffness
(``stiffness="potential_energy"``) takes both flanks, means and waveforms, from its table over
the mesh cycle (the discrete Fourier series of ``mesh_stiffness`` and ``mesh_stiffness_coast``,
``harmonics`` terms; the coast flank with its own phase, the table's).

Kt = M^-1 K_s / omega_0^2 with K_s the shafts' and flexible bearings' stiffness (the meshes act
only through f_m), Ct = M^-1 C / omega_0 with C the shafts', bearings' and Rayleigh damping (the
meshes' own damping c_m acts in f_m, on the deflection rate, also inside the backlash), W_m the
mesh's deflection row along its line of action [m per model coordinate], G_m = M^-1 W_m^T /
(L omega_0^2), g the dead zone of half-width b_m (backlash), k_m the relative stiffness (a
Fourier series), e_m the transmission error. The forcing frequency Omega is the reference mesh's
mesh frequency over omega_0; mesh m turns at r_m = order_m / order_ref times it (the train's
:meth:`~geardyn.trains.GearTrain.mesh_orders`), theta_m = r_m Omega tau: a non-integer r_m makes
the forcing quasi-periodic (no common period; sections are then taken once per period of the
reference mesh, and periodic orbits and their continuation are refused).

Play besides the meshes (:meth:`TrainModel.play_elements`) is contacts after the meshes with
constant stiffness: a coupling's backlash a dead zone on its twist, a bearing's clearance c a
radial contact of two rows (x, y), force -k (1 - c / r) (x, y) for r = sqrt(x^2 + y^2) > c,
else 0, switching on r - c; the elements' damping stays linear, in Ct.

Tooth faults (the train's ``faults``, :mod:`geardyn.trains.faults`) on gear f (Z_f teeth, its
meshes at r_f) make the forcing period one revolution of f relative to its meshes' frame:
``mesh_order`` N = Z_f / r_f reference-mesh cycles, Omega = the reference mesh frequency / (N
omega_0). f's meshes' stiffness is the series of their tables over the revolution, in its angle
(``harmonics`` x Z_f terms, every sideband up to mesh harmonic ``harmonics``), so the fault acts
once per revolution; every other mesh's phase turns at r_m N Omega. A non-integer r_m N (f on
another stage than the reference mesh, or stages with a non-integer ratio) is quasi-periodic
forcing, as above, sections once per revolution of f.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from geardyn.core.capabilities import Capabilities, FaultDatasetInputs
from geardyn.core.inputs import by_name, one_value
from geardyn.errors import ParameterError
from geardyn.gears.iso6336_kv import KvMeshGroup, group_reduced_mass
from geardyn.gears.potential_energy import coast_phase
from geardyn.models import planetary_kernels as pk
from geardyn.models.planetary import (
    _KERNEL,
    PlanetaryGearSet,
    _clean,
    _flank_index,
    _minimum_relative_stiffness,
    _series_inputs,
    _waveform,
    planetary_layout,
)
from geardyn.models.planetary_stiffness import FlankSeries, coast_flank, flank_series, mirrored
from geardyn.trains.elements import pair_geometry
from geardyn.trains.faults import faulty_table, revolution_series, shared_wear_profiles
from geardyn.trains.inputs import INPUTS
from geardyn.trains.train import GearTrain
from geardyn.units import si_value

#: The sweep parameter of a train's input speed [rpm].
INPUT_SPEED = "input_speed"
#: The sweep parameter of a train's input torque [N m]: the driven body's mean torque, every
#: other mean torque scaled with it (the load's balance kept).
INPUT_TORQUE = "input_torque"
#: Relative distance of a mesh order ratio from a whole number within which it is that number
#: (speed ratios come from an SVD, so a stage's equal orders agree to about 1e-12).
ORDER_RTOL = 1e-9
#: Largest difference [relative stiffness] between a mirrored coast series and its drive series
#: that is round-off (a sine mirrored about half a mesh cycle): the mesh keeps one flank.
MIRROR_ATOL = 1e-12
#: The declared mean torques (``input_torque`` is in their unit).
_TORQUES = by_name(INPUTS)["torques"]


class PlayElement(NamedTuple):
    """An element with play besides the meshes (:meth:`TrainModel.play_elements`)."""

    #: The contact's name.
    name: str
    #: Its deflection row in the model's coordinates [m or rad per coordinate].
    row: np.ndarray
    #: Its stiffness [N/m or N m/rad].
    stiffness: float
    #: The dead zone's half-width, or the radial contact's radius [m or rad].
    half_width: float
    #: 0: a dead zone on the row's deflection; 1 or -1: the x or the y row of a radial
    #: contact whose other row is the next or the previous element.
    radial: int


def _per_mesh(field: str, value: Any, meshes: tuple[str, ...], kind: str,
              minimum: float | None = 0.0) -> np.ndarray:
    """A scalar for every mesh, or a mapping mesh name -> value (meshes not named: 0)."""
    if isinstance(value, Mapping):
        unknown = sorted(set(value) - set(meshes))
        if unknown:
            raise ParameterError(f"{field}.{unknown[0]}", value[unknown[0]],
                                 f"is not a mesh of the train ({', '.join(meshes)})")
        return np.array([si_value(f"{field}.{m}", value.get(m, 0.0), kind, minimum)
                         for m in meshes])
    return np.full(len(meshes), si_value(field, value, kind, minimum))


class TrainModel(PlanetaryGearSet):
    """The nonlinear model of a :class:`~geardyn.trains.GearTrain` (module doc), on the
    planetary gear set's kernels. Inputs are SI (numbers or unit strings).

    Parameters
    ----------
    train
        The gear train (its ``driven`` body and tooth counts give the mesh orders; without
        them every mesh turns at the forcing frequency).
    reference_mesh
        The mesh whose mesh frequency is the forcing Omega (default: the first mesh of the
        driven body, else the train's first mesh).
    input_speed, mesh_frequency
        The driven body's speed [rpm, or a unit string] or the reference mesh's frequency
        [rad/s]; one of them (default omega_0: Omega = 1).
    torques
        Mean torques [N m] on bodies by name (each acts on the body's rotation).
    load
        A body whose torque is set so that the torques balance on the train's rigid-body mode
        (a free train, one rigid-body mode): the output load for a given input torque.
    backlash
        Backlash half-width b [m] of every mesh (dead zone), scalar or {mesh: value}.
    mesh_damping
        Damping ratio zeta_m of every mesh, scalar or {mesh: value}: c_m = 2 zeta_m sqrt(k_m
        m_e), m_e = 1 / sum (w_j^2 / I_j) over the rotations the mesh row w touches; added to
        the mesh element's own ``damping`` [N s/m].
    modal_damping
        Modal damping ratio of every mode of the linear model at mean stiffness.
    stiffness_fluctuation, waveform, contact_ratio, harmonics, mesh_phase
        The relative stiffness k_m(theta) = 1 + w(theta + phase_m): ``waveform`` ``"sine"`` or
        ``"rectangular"`` of relative amplitude ``stiffness_fluctuation`` (scalar or per mesh;
        ``contact_ratio``, ``harmonics``), or a pair (a, b) of relative Fourier coefficients,
        or {mesh: (a, b)} (ISO 6336-1 waves' ``fourier(n)``); ``mesh_phase`` [rad of the mesh
        cycle], scalar or per mesh, or ``"geometry"``: -2 pi gamma_m of
        :meth:`geometry_phases`; default (None) ``"geometry"`` where the train has a driven
        body and every meshing gear has geometry, else 0 (a train of base radii and tooth
        counts has no tooth positions to phase from). A
        mesh on the potential-energy stiffness takes w from its table instead (``harmonics``
        terms over the mesh cycle, x Z_f over a faulty gear's revolution; at most half the
        table's angles per cycle), shifted by its ``mesh_phase``: a fluctuation or waveform
        given for it is refused (give the others' per mesh).
    mesh_error, error_phase
        Transmission error e_m = E_m sin(theta_m + phase_m + error_phase_m) [m] (refused on a
        faulty gear's meshes, whose phase is the revolution's).
    torque_fluctuation, torque_order, torque_phase
        The driven body's torque fluctuates as T (1 + A sin(order Omega tau + phase)).
    coast
        The coast (back) flank of a mesh whose two gears have geometry: ``"mirror"``
        (default) for symmetric teeth the mirror image of the drive flank's relative stiffness,
        kc(theta) = k0(2 pi phi - theta - phase) with k(theta) = k0(theta + phase), phi =
        :func:`geardyn.gears.potential_energy.coast_phase` of the gear pair (from the geometry
        alone; -phi on a mesh whose gear a turns in the negative sense, :meth:`backward_meshes`;
        :func:`~geardyn.models.planetary_stiffness.mirrored`), the same mean stiffness;
        ``"symmetric"``: the drive flank's stiffness on both flanks. A mesh with a gear
        without geometry has one stiffness on both flanks; a mesh on the potential-energy
        stiffness takes its table's coast flank with ``"mirror"`` (both flanks' tables read
        backwards in time on such a mesh). Kept as
        :attr:`coast_flank`.
    time_scale, length_scale
        omega_0 [rad/s] (default sqrt(k_ref / m_e,ref) of the reference mesh) and L [m].
    """

    name = "TrainModel"
    #: A fault dataset's signal is a mesh force (a train has no housing sensor model: the
    #: stand-in is the force the mesh's bearings carry), its inputs the driven body's speed
    #: [rpm] and torque [N m].
    capabilities = Capabilities(physical_inputs=True, physical_axes=True, mesh_forces=True,
                                dynamic_factor=True, natural_frequencies="Hz",
                                fault_dataset=FaultDatasetInputs(INPUT_SPEED, INPUT_TORQUE,
                                                                 "mesh_force"))
    input_declarations = INPUTS
    raw_overrides: dict[str, float] = {}
    carrier_speed = None
    carrier_speed_ratio = None
    centrifugal_preload = False
    rotational_only = False
    #: The forcing period in cycles of the reference mesh: 1, or with tooth faults one
    #: revolution of the faulty gear (:meth:`_forcing_period`).
    mesh_order: float = 1

    def __init__(self, train: Any, *, reference_mesh: str | None = None,
                 input_speed: Any = None, mesh_frequency: Any = None,
                 torques: Mapping[str, Any] | None = None, load: str | None = None,
                 backlash: Any = 0.0, mesh_damping: Any = 0.0, modal_damping: Any = 0.0,
                 stiffness_fluctuation: Any = 0.0, waveform: Any = "sine",
                 contact_ratio: float = 1.6, harmonics: int = 9, mesh_phase: Any = None,
                 mesh_error: Any = 0.0, error_phase: Any = 0.0, torque_fluctuation: Any = 0.0,
                 torque_order: Any = 1.0, torque_phase: Any = 0.0, coast: str = "mirror",
                 time_scale: Any = None, length_scale: Any = 1e-6):
        if not isinstance(train, GearTrain):
            raise ParameterError("train", type(train).__name__, "must be a GearTrain")
        if not train.meshes:
            raise ParameterError("train.meshes", (), "a train model needs at least one mesh")
        self.inputs: dict[str, Any] = {k: v for k, v in locals().items()
                                       if k not in ("self", "__class__")}
        self.train = train
        names = tuple(m.name for m in train.meshes)
        self._mesh_names = names
        self.reference_mesh = self._reference(reference_mesh)
        self._kinematic_orders = self._orders()
        self.fixed = tuple(train.fixed)
        contact_ratio, harmonics = _series_inputs(contact_ratio, harmonics)
        self.phase_source = "given"
        if mesh_phase is None:  # from the geometry where the train has it
            known = self._phases_known()
            mesh_phase = "geometry" if known else 0.0
            self.phase_source = "geometry" if known else "all meshes in phase (no geometry)"
        elif isinstance(mesh_phase, str) and mesh_phase == "geometry":
            self.phase_source = "geometry"
        if isinstance(mesh_phase, str) and mesh_phase == "geometry":
            gamma = self.geometry_phases()
            self.mesh_phase = np.array([-2.0 * math.pi * gamma[m] for m in names])
        else:
            self.mesh_phase = _per_mesh("mesh_phase", mesh_phase, names, "angle", None)
        self.coast_flank = coast_flank(coast)
        self.faults = train.faults
        self.mesh_order, self._phase_scale = self._forcing_period()
        self._phase_orders = self._snapped(self._kinematic_orders * self._phase_scale)
        self.torques = self._torques(torques, load)  # before the series: the wear's loads
        self._stiffness_series(self._fourier(waveform, stiffness_fluctuation,
                                             float(contact_ratio), harmonics), harmonics)
        self.backlash = _per_mesh("backlash", backlash, names, "length")
        self.error = _per_mesh("mesh_error", mesh_error, names, "length")
        if self.faults is not None:
            hit = [m for m in self.faults.meshes if self.error[names.index(m)] != 0.0]
            if hit:
                raise ParameterError(f"mesh_error.{hit[0]}", mesh_error, "a static transmission "
                                     f"error on a mesh of the faulty gear {self.faults.gear} "
                                     "would act once per revolution (its phase is the "
                                     "revolution's); leave it 0")
        self.error_phase = _per_mesh("error_phase", error_phase, names, "angle",
                                     None) + self.mesh_phase
        self.mesh_damping = _per_mesh("mesh_damping", mesh_damping, names, "dimensionless")
        self.modal_damping = si_value("modal_damping", modal_damping, "dimensionless", 0.0)
        self.torque_fluctuation = si_value("torque_fluctuation", torque_fluctuation,
                                           "dimensionless", 0.0)
        self.torque_order = si_value("torque_order", torque_order, "dimensionless", 0.0,
                                     True)
        self.torque_phase = si_value("torque_phase", torque_phase, "angle", None)
        if self.torque_fluctuation != 0.0 and train.driven is None:
            raise ParameterError("torque_fluctuation", torque_fluctuation,
                                 "fluctuates the driven body's torque: the train needs driven")
        self.length_scale = si_value("length_scale", length_scale, "length", 0.0, True)
        ref = names.index(self.reference_mesh)
        k_ref = train.mesh_data[self.reference_mesh].stiffness
        w0 = math.sqrt(k_ref / self._equivalent_masses()[ref])
        self.time_scale = w0 if time_scale is None else si_value("time_scale", time_scale,
                                                                 "frequency", 0.0, True)
        mf = self._mesh_frequency(input_speed, mesh_frequency)
        self.inputs["input_speed"], self.inputs["mesh_frequency"] = None, mf
        self._build(mf / (self.time_scale * self.mesh_order))

    # ------------------------------------------------------------------ inputs
    def _reference(self, name: str | None) -> str:
        names = self._mesh_names
        if name is not None:
            if name not in names:
                raise ParameterError("reference_mesh", name,
                                     f"is not a mesh of the train ({', '.join(names)})")
            return name
        driven = self.train.driven
        return next((m.name for m in self.train.meshes if driven in (m.a, m.b)), names[0])

    def _orders(self) -> np.ndarray:
        """r_m = order_m / order_ref of every mesh, whole numbers within ``ORDER_RTOL`` snapped
        to them; all 1 without a driven body."""
        if self.train.driven is None:
            return np.ones(len(self._mesh_names))
        orders = self.train.mesh_orders()
        ref = orders[self.reference_mesh]
        if not ref > 0.0:
            raise ParameterError("reference_mesh", self.reference_mesh,
                                 "does not turn with the input (mesh order 0)")
        r = np.array([orders[m] / ref for m in self._mesh_names])
        whole = np.round(r)
        snap = (whole > 0) & (np.abs(r - whole) <= ORDER_RTOL * r)
        if np.any(r <= 0.0):
            bad = self._mesh_names[int(np.argmax(r <= 0.0))]
            raise ParameterError(f"{bad}", 0.0, "the mesh does not turn with the input")
        return np.where(snap, whole, r)

    @staticmethod
    def _snapped(r: np.ndarray) -> np.ndarray:
        """``r`` with the entries within ``ORDER_RTOL`` of a whole number > 0 set to it."""
        whole = np.round(r)
        return np.where((whole > 0) & (np.abs(r - whole) <= ORDER_RTOL * r), whole, r)

    @property
    def _kernel_orders(self) -> np.ndarray:
        """Every mesh's phase frequency over Omega, as the coefficient vector holds it (so a raw
        override of ``<mesh>_order`` shows): r_m times the reference-mesh cycles per forcing
        period (``mesh_order``), over Z_f for the faulty gear's meshes (their series are in
        its revolution angle)."""
        lay = self._layout
        return np.array([self.params[lay["mesh"] + m * lay["block"] + pk.M_ORDER]
                         for m in range(len(self._mesh_names))])

    @property
    def orders(self) -> np.ndarray:
        """r_m of every mesh: its mesh frequency over the reference mesh's (from the
        coefficient vector's orders)."""
        return self._kernel_orders / self._phase_scale

    @property
    def quasi_periodic(self) -> bool:
        """Whether a mesh's phase does not turn a whole number of times per forcing period."""
        r = self._kernel_orders
        return bool(np.any(r != np.round(r)))

    def _forcing_period(self) -> tuple[float, np.ndarray]:
        """The reference-mesh cycles per forcing period N and every mesh's phase scale (its
        phase frequency over Omega is r_m times it). Healthy: 1 and 1. With tooth faults on gear
        f (Z_f teeth, its meshes at r_f): the period is one revolution of f relative to its
        meshes' frame, N = Z_f / r_f (a whole number within ``ORDER_RTOL`` snapped to it); the
        other meshes' phases turn at r_m N, f's meshes' series are in the revolution angle
        (scale N / Z_f, r_f N / Z_f = 1)."""
        scale = np.ones(len(self._mesh_names))
        placement = self.faults
        if placement is None:
            return 1, scale
        idx = [self._mesh_names.index(m) for m in placement.meshes]
        r = self._kinematic_orders[idx]
        if np.any(np.abs(r - r[0]) > ORDER_RTOL * r[0]):
            raise ParameterError("faults", placement.gear, "the faulty gear's meshes turn at "
                                 "different mesh frequencies (frames): one revolution is no "
                                 "common period")
        n = placement.teeth / float(r[0])
        whole = round(n)
        if abs(n - whole) <= ORDER_RTOL * n:
            n = whole
        scale[:] = n
        scale[idx] = n / placement.teeth
        return n, scale

    def _fourier(self, waveform: Any, amplitude: Any, contact_ratio: float,
                 harmonics: int) -> np.ndarray:
        names = self._mesh_names
        rel = _per_mesh("stiffness_fluctuation", amplitude, names, "dimensionless")
        teeth = [m for m in names if self.train.mesh_data[m].table is not None]
        if teeth and not isinstance(waveform, str | Mapping):
            raise ParameterError("waveform", "(coefficients)", f"mesh {teeth[0]} takes its "
                                 "waveform from the potential-energy method (its teeth); give "
                                 "the pairs per mesh ({mesh: (a, b)}) for the others")
        for m in teeth:
            reason = (f"mesh {m} takes its waveform from the potential-energy method (its "
                      "teeth); give the others theirs per mesh ({mesh: value})")
            if rel[names.index(m)] != 0.0:
                raise ParameterError("stiffness_fluctuation", amplitude, reason)
            if isinstance(waveform, Mapping) and m in waveform:
                raise ParameterError(f"waveform.{m}", "(coefficients)", reason)
        if isinstance(waveform, Mapping):
            unknown = sorted(set(waveform) - set(names))
            if unknown:
                raise ParameterError(f"waveform.{unknown[0]}", "(coefficients)",
                                     f"is not a mesh of the train ({', '.join(names)})")
            rows = [_waveform(f"waveform.{m}", waveform[m], rel[i:i + 1],
                              self.mesh_phase[i:i + 1], contact_ratio, harmonics)
                    if m in waveform else np.zeros((1, 2)) for i, m in enumerate(names)]
            width = max(r.shape[1] for r in rows)
            out = np.vstack([np.pad(r, ((0, 0), (0, width - r.shape[1]))) for r in rows])
        else:
            out = _waveform("waveform", waveform, rel, self.mesh_phase, contact_ratio,
                            harmonics)
        if _minimum_relative_stiffness(out) <= 0.0:
            raise ParameterError("stiffness_fluctuation", amplitude, "makes a mesh stiffness "
                                 "negative; it must stay > 0")
        return out

    def coast_phases(self) -> dict[str, float]:
        """phi [mesh cycles] of every mesh whose two gears have geometry:
        :func:`~geardyn.gears.potential_energy.coast_phase` of the pair (its transverse one
        for helical gears)."""
        out = {}
        for mesh in self.train.meshes:
            ga, gb = self.train.bodies[mesh.a], self.train.bodies[mesh.b]
            if getattr(ga, "geometry", None) is None or getattr(gb, "geometry", None) is None:
                continue
            pair = pair_geometry(mesh, ga, gb)
            out[mesh.name] = coast_phase(getattr(pair, "transverse", pair))
        return out

    def _phases_known(self) -> bool:
        """Whether :meth:`geometry_phases` applies: a driven body and the geometry of every
        meshing gear."""
        train = self.train
        return train.driven is not None and all(
            getattr(train.bodies[g], "geometry", None) is not None
            for m in train.meshes for g in (m.a, m.b))

    def geometry_phases(self) -> dict[str, float]:
        """gamma_m [mesh cycles, in [0, 1)] of every mesh: how much later than the first mesh
        of its group (meshes joined through shared gears) a tooth's drive flank (the one in
        contact at a positive mesh deflection) passes the mesh's pitch point. Two meshes on
        gear g (Z teeth, turning with sign sigma relative to the meshes' carrier, or the
        ground), their pitch points at angles beta_1, beta_2 from its centre, its loaded flank
        on the side e = +-1 (counter-clockwise: +) of a tooth of angular thickness s at each
        mesh's operating pitch radius: gamma_2 - gamma_1 = Z sigma [beta_2 - beta_1 -
        (e_2 s_2 - e_1 s_1) / 2] / (2 pi) (e: +1 on every mesh of an external gear, -1 on a
        ring's). Stages joined only by shafts are separate groups (their gears' clocking on
        the shaft is no input): each starts at 0. Needs the train's driven body and the
        geometry of every meshing gear."""
        train = self.train
        if train.driven is None:
            raise ParameterError("mesh_phase", "geometry", "needs the train's driven body (the "
                                 "gears' senses of rotation)")
        for m in train.meshes:
            ga, gb = train.bodies[m.a], train.bodies[m.b]
            if getattr(ga, "geometry", None) is None or getattr(gb, "geometry", None) is None:
                raise ParameterError("mesh_phase", "geometry", f"needs the geometry of both "
                                     f"gears of mesh {m.name} ({m.a}, {m.b})")
        gamma: dict[str, float] = {}
        for start in train.meshes:
            if start.name in gamma:
                continue
            gamma[start.name], todo = 0.0, [start]
            while todo:
                m1 = todo.pop()
                for m2 in train.meshes:
                    shared = {m1.a, m1.b} & {m2.a, m2.b}
                    if m2.name in gamma or not shared:
                        continue
                    step = self.tooth_passage_step(m1, m2, shared.pop())
                    g2 = (gamma[m1.name] + step) % 1.0
                    gamma[m2.name] = 0.0 if math.isclose(g2, 1.0, abs_tol=1e-9) else g2
                    todo.append(m2)
        return gamma

    def tooth_passage_step(self, first: Any, second: Any, gear: str) -> float:
        """D [mesh cycles, unreduced]: how much later a tooth of ``gear`` (a gear of both
        meshes) passes the pitch point of mesh ``second`` than that of mesh ``first``, Z sigma
        [beta_2 - beta_1 - (e_2 s_2 - e_1 s_1) / 2] / (2 pi) (:meth:`geometry_phases`). Needs the
        train's driven body and the geometry of both meshes' gears."""
        train = self.train
        if train.driven is None:
            raise ParameterError("driven", None, "the tooth passages between two meshes of "
                                 f"{gear} need the train's driven body (its sense of rotation)")
        ratios = train.speed_ratios()
        b1, e1, s1 = self._pitch_side(first, gear)
        b2, e2, s2 = self._pitch_side(second, gear)
        sigma = math.copysign(1.0, ratios[gear] - train.mesh_frame_ratio(first, ratios))
        z = train.bodies[gear].teeth
        return z * sigma * (b2 - b1 - 0.5 * (e2 * s2 - e1 * s1)) / (2.0 * math.pi)

    def _pitch_side(self, m: Any, g: str) -> tuple[float, float, float]:
        """beta [rad] (the direction of mesh m's pitch point from gear g's centre), e (the side
        of g's loaded flank) and s [rad] (g's tooth angular thickness at m's operating pitch
        radius) of gear g in mesh m."""
        ga, gb = self.train.bodies[m.a], self.train.bodies[m.b]
        pair = pair_geometry(m, ga, gb)
        pair, first = getattr(pair, "transverse", pair), g == m.a
        beta = m.angle if first and not m.internal else m.angle + math.pi
        e = -1.0 if (m.internal and not first) else 1.0
        gear = pair.pinion if first else pair.wheel
        r_w = pair.operating_pitch_radii[0 if first else 1]
        return beta, e, gear.angular_thickness(r_w)

    def _stiffness_series(self, user: np.ndarray, harmonics: int) -> None:
        """Every mesh's drive and coast flank: :attr:`fourier`, :attr:`fourier_coast`
        (meshes, 2 nh, zero-padded to the widest), the mean stiffnesses [N/m] of
        :meth:`mesh_stiffnesses` and :meth:`coast_stiffnesses`, and whether any coast flank
        differs from its drive flank by construction. The potential-energy meshes' from their
        tables (:meth:`_tooth_series`), the others' from ``user`` (the waveform given), the
        coast flank mirrored (:meth:`_coast_fourier`)."""
        names = self._mesh_names
        mean = np.array([self.train.mesh_data[m].stiffness for m in names])
        teeth = self._tooth_series(harmonics)
        width = max([user.shape[1]] + [r[0].size for r in teeth.values()])
        drive = np.pad(user, ((0, 0), (0, width - user.shape[1])))
        coast = drive.copy()
        coast_mean = mean.copy()
        for m, (d, c, kd, kc) in teeth.items():
            drive[m], mean[m] = np.pad(d, (0, width - d.size)), kd
            coast[m], coast_mean[m] = np.pad(c, (0, width - c.size)), kc
        gaps = self.faults.meshes if self.faults is not None and self.faults.missing_tooth \
            else ()
        for m in teeth:
            rows = (drive[m], coast[m]) if self.coast_flank == "mirror" else (drive[m],)
            if names[m] not in gaps and min(_minimum_relative_stiffness(r[None, :])
                                            for r in rows) <= 0.0:
                raise ParameterError("harmonics", harmonics, f"the series of mesh {names[m]}'s "
                                     "potential-energy stiffness falls to 0 or below; keep "
                                     "more")
        self.fourier = drive
        self._drive_mean = mean
        if self.coast_flank == "symmetric":
            self.fourier_coast, self._coast_mean, self._mirrored = drive, mean, False
            return
        self.fourier_coast, self._mirrored = self._coast_fourier(coast, set(teeth))
        self._coast_mean = coast_mean

    def _tooth_series(self, harmonics: int) -> dict[int, tuple[np.ndarray, np.ndarray,
                                                               float, float]]:
        """The potential-energy meshes' relative series (drive, coast; shifted by the mesh
        phase) and mean stiffnesses [N/m along the line of action] by mesh index: the discrete
        Fourier series of the one-cycle tables (``harmonics`` terms), a faulty gear's meshes
        over its revolution (:func:`~geardyn.trains.faults.revolution_series`, ``harmonics`` x
        Z_f terms in the revolution angle). A table is in the pinion's (gear a's) rotation in
        the positive sense; a mesh whose gear a turns in the negative sense relative to its
        frame (:meth:`backward_meshes`) reads it backwards, K(c) = T(-c), and a fault on the
        tooth passing its pitch point at c = j sits on the table's tooth -j."""
        out: dict[int, tuple[np.ndarray, np.ndarray, float, float]] = {}
        offsets = self._fault_offsets()
        backward = self.backward_meshes()
        shared = {} if self.faults is None else shared_wear_profiles(
            self.train, self.faults, self.static_loads(), self.torque_force_scale())
        self._fault_tables: dict[str, Any] = {}
        for i, mesh in enumerate(self.train.meshes):
            data = self.train.mesh_data[mesh.name]
            if data.table is None:
                continue
            angles = int(data.table.sizes["angle"])
            if 2 * harmonics >= angles:
                raise ParameterError("harmonics", harmonics, f"mesh {mesh.name}'s potential-"
                                     f"energy table has {angles} angles per mesh cycle: at "
                                     f"most {(angles - 1) // 2} harmonics")
            normal = 1.0 / math.cos(data.base_helix_angle) ** 2
            faulty = mesh.name in offsets
            flanks: list[FlankSeries] = []
            back = mesh.name in backward
            for var in ("mesh_stiffness", "mesh_stiffness_coast"):
                healthy = _in_time(data.table[var].values, back)
                if faulty:
                    z = self.faults.teeth
                    role = "pinion" if self.faults.gear == mesh.a else "wheel"
                    pair = pair_geometry(mesh, self.train.bodies[mesh.a],
                                      self.train.bodies[mesh.b])
                    on = self.faults.on_mesh(role, offsets[mesh.name], backward=back)
                    table = faulty_table(self.train, mesh, pair, on, z, {
                        f: shared[g] for f, g in zip(on, self.faults.faults, strict=True)
                        if g in shared})
                    self._fault_tables[mesh.name] = table
                    flanks.append(revolution_series(healthy, _in_time(table[var].values, back),
                                                    harmonics, z))
                else:
                    flanks.append(flank_series(healthy, harmonics))
            order = self.faults.teeth if faulty else 1
            rows = [_waveform(f"waveform.{mesh.name}", s.pair, np.zeros(1),
                              self.mesh_phase[i:i + 1], 1.6, harmonics, order)[0]
                    for s in flanks]
            out[i] = (rows[0], rows[1], flanks[0].mean * normal, flanks[1].mean * normal)
        return out

    def backward_meshes(self) -> tuple[str, ...]:
        """The meshes whose gear a turns in the negative sense relative to the mesh's frame
        (the carrier of a planet, else the ground) when the driven body turns in the positive
        sense: an idler's mesh with the gear it drives, where the idler is a; a planet's mesh
        with the ring. Their potential-energy tables, in gear a's positive rotation, are read
        backwards in time (:meth:`_tooth_series`). () without a driven body."""
        train = self.train
        if train.driven is None:
            return ()
        ratios = train.speed_ratios()
        return tuple(m.name for m in train.meshes
                     if ratios[m.a] - train.mesh_frame_ratio(m, ratios) < 0.0)

    def static_loads(self) -> dict[str, float]:
        """The static mesh forces [N] of the linear train at mean stiffness (no backlash)
        under the mean torques, by mesh: K q = F (least squares on the rigid-body modes), F_m
        = k_m w_m q; positive on the drive flank."""
        q = np.linalg.lstsq(self.train.stiffness_matrix(), self.torques, rcond=None)[0]
        return {name: k * float((W @ q)[0])
                for kind, name, W, k, _ in self.train.elements() if kind == "mesh"}

    def torque_force_scale(self) -> float:
        """The mean torques' force scale [N]: max abs(T) over the bodies / the largest base radius
        of the train's gears (0 without torques or gears)."""
        radius = max((b.radius for b in self.train.bodies.values() if b.radius is not None),
                     default=math.inf)
        return max((abs(t) for t in self.body_torques.values()), default=0.0) / radius

    def fault_tables(self) -> dict[str, Any]:
        """The potential-energy stiffness Datasets of the faulty gear's meshes over its
        revolution (Z_f mesh cycles, the faults on each mesh's teeth as placed), by mesh; {}
        without faults."""
        return dict(self._fault_tables)

    def _fault_offsets(self) -> dict[str, int]:
        """The tooth offset [teeth] of the faults on every mesh of the faulty gear, from its
        first mesh (:mod:`geardyn.trains.faults`): round(D_m + (psi_m - psi_0) / 2 pi), D_m
        the tooth passage step (:meth:`tooth_passage_step`)."""
        placement = self.faults
        if placement is None:
            return {}
        names = self._mesh_names
        meshes = {m.name: m for m in self.train.meshes}
        first = meshes[placement.meshes[0]]
        i0 = names.index(first.name)
        out = {first.name: 0}
        for name in placement.meshes[1:]:
            i = names.index(name)
            d = self.tooth_passage_step(first, meshes[name], placement.gear)
            out[name] = int(round(d + (self.mesh_phase[i] - self.mesh_phase[i0])
                                  / (2.0 * math.pi)))
        return out

    def _coast_fourier(self, coast: np.ndarray, own: set[int]) -> tuple[np.ndarray, bool]:
        """The coast flank's relative Fourier coefficients (meshes, 2 nh) and whether any
        mesh's differs from its drive flank's (``coast="mirror"``): the rows ``own`` (the
        potential-energy meshes) from ``coast``, every other mesh whose two gears have geometry
        the drive flank's mirror image about its coast phase phi (-phi on a mesh read
        backwards, :meth:`backward_meshes`)."""
        phases = self.coast_phases()
        backward = self.backward_meshes()
        out = self.fourier.copy()
        for m in own:
            out[m] = coast[m]
        for m, name in enumerate(self._mesh_names):
            if name in phases and m not in own:
                # k(theta) = k0(theta + psi): mirror about phi - psi / pi; a mesh read
                # backwards meets the coast flank phi before the drive flank: about -phi
                phi = (-1.0 if name in backward else 1.0) * phases[name] - (
                    self.mesh_phase[m] / math.pi)
                a, b = mirrored(self.fourier[m, 0::2], self.fourier[m, 1::2], phi)
                row = np.empty_like(out[m])
                row[0::2], row[1::2] = a, b
                if np.max(np.abs(row - out[m]), initial=0.0) > MIRROR_ATOL:
                    out[m] = row
        return out, not np.array_equal(out, self.fourier)

    def _torques(self, torques: Mapping[str, Any] | None, load: str | None) -> np.ndarray:
        """Mean generalised forces [N m, N] on the model's coordinates; with ``load`` its
        torque balancing the others on the rigid-body mode."""
        train = self.train
        full = {}
        for body, value in dict(torques or {}).items():
            if body not in train.bodies:
                raise ParameterError(f"torques.{body}", value, "is not a body of the train")
            full[body] = si_value(f"torques.{body}", value, "torque", None)
        F = self._torque_vector(full)
        lam, phi = train._eig()
        rigid = phi[:, lam == 0.0]
        if load is not None:
            if load not in train.bodies:
                raise ParameterError("load", load, "is not a body of the train")
            if rigid.shape[1] != 1:
                raise ParameterError("load", load, f"balances the torques on one rigid-body "
                                     f"mode; the train has {rigid.shape[1]}")
            unit = self._torque_vector({load: 1.0})
            per = float(unit @ rigid[:, 0])
            if per == 0.0:
                raise ParameterError("load", load, "does not turn in the rigid-body mode")
            full[load] = full.get(load, 0.0) - float(F @ rigid[:, 0]) / per
            F = self._torque_vector(full)
        if rigid.size:
            work = np.abs(F @ rigid)
            scale = max(sum(abs(v) for v in full.values()), 1e-300)
            if np.any(work > 1e-9 * scale * np.max(np.abs(rigid))):
                raise ParameterError("torques", dict(torques or {}), "do not balance on the "
                                     "train's rigid-body mode (the train would accelerate): "
                                     "name the output body as load")
        self.body_torques = full
        return F

    def _torque_vector(self, torques: Mapping[str, float]) -> np.ndarray:
        train = self.train
        full = np.zeros(3 * len(train.bodies))
        for body, t in torques.items():
            full[3 * train._index[body]] = t
        return train._T.T @ full

    def _mesh_frequency(self, input_speed: Any, mesh_frequency: Any) -> float:
        if input_speed is not None and mesh_frequency is not None:
            raise ParameterError(INPUT_SPEED, input_speed, "sets the mesh frequency: give it "
                                 "or mesh_frequency, one of them")
        if input_speed is not None:
            rpm = (si_value(INPUT_SPEED, input_speed, "frequency", 0.0) * 60.0 / (2 * math.pi)
                   if isinstance(input_speed, str)
                   else si_value(INPUT_SPEED, input_speed, "dimensionless", 0.0))
            return rpm * 2.0 * math.pi / 60.0 * self.mesh_frequency_per_input_speed()
        if mesh_frequency is None:
            return self.time_scale
        return si_value("mesh_frequency", mesh_frequency, "frequency", 0.0)

    def mesh_frequency_per_input_speed(self) -> float:
        """The reference mesh's order: its mesh frequency over the driven body's speed."""
        if self.train.driven is None:
            raise ParameterError(INPUT_SPEED, None, "needs the train's driven body (and tooth "
                                 "counts); sweep mesh_frequency [rad/s] instead")
        return float(self.train.mesh_orders()[self.reference_mesh])

    # ------------------------------------------------------------------ assembly (SI)
    def dof_names(self) -> tuple[str, ...]:
        return self.train.dof_names()

    def mass_matrix(self) -> np.ndarray:
        return self.train.mass_matrix()

    @property
    def mesh_names(self) -> tuple[str, ...]:
        return self._mesh_names

    def mesh_rows(self) -> np.ndarray:
        """Mesh deflection rows (meshes x model coordinates) [m per rad, 1 per m]."""
        return np.vstack([W for kind, _, W, _, _ in self.train.elements() if kind == "mesh"])

    def mesh_stiffnesses(self) -> np.ndarray:
        """Mean drive-flank stiffness [N/m] of every mesh: the train's, the mean of the
        potential-energy series (over the faulty gear's revolution for its meshes)."""
        return self._drive_mean.copy()

    def coast_stiffnesses(self) -> np.ndarray:
        """Mean coast-flank stiffness [N/m] of every mesh (the drive flank's but for the
        potential-energy meshes with ``coast="mirror"``: their coast tables')."""
        return self._coast_mean.copy()

    def stiffness_matrix(self, meshes: bool = True) -> np.ndarray:
        """K [N/m, N m/rad] at mean mesh stiffness; without the meshes when ``meshes`` is
        False."""
        if meshes:
            return self.train.stiffness_matrix()
        n = len(self.dof_names())
        K = np.zeros((n, n))
        for kind, _, W, k, _ in self.train.elements():
            if kind != "mesh":
                K += k * W.T @ W
        return K

    def _equivalent_masses(self) -> np.ndarray:
        """m_e of every mesh [kg]: 1 / m_e = sum w_j^2 / I_j over the rotations its row
        touches."""
        M = np.diag(self.mass_matrix())
        rot = np.array([d.endswith(".theta") for d in self.dof_names()])
        W = self.mesh_rows()
        return 1.0 / (W[:, rot] ** 2 / M[rot]).sum(axis=1)

    def _mesh_damping(self) -> np.ndarray:
        own = np.array([m.damping for m in self.train.meshes], dtype=float)
        return own + 2.0 * self.mesh_damping * np.sqrt(self.mesh_stiffnesses()
                                                        * self._equivalent_masses())

    def _damping_matrix(self) -> np.ndarray:
        """The shafts', bearings' and Rayleigh damping plus the modal damping [N s/m] (the
        meshes' own damping acts in the mesh force)."""
        train = self.train
        n = len(self.dof_names())
        C = np.zeros((n, n))
        for kind, _, W, _, c in train.elements():
            if kind != "mesh":
                C += c * W.T @ W
        a, b = train.rayleigh
        C += a * self.mass_matrix() + b * self.stiffness_matrix()
        if self.modal_damping:
            M = self.mass_matrix()
            lam, phi = self._eig()
            C += M @ phi @ np.diag(2.0 * self.modal_damping * np.sqrt(lam)) @ phi.T @ M
        return _clean(C)

    def _forces(self) -> np.ndarray:
        F = self.torques
        Fl = np.zeros_like(F)
        if self.torque_fluctuation != 0.0:
            t = self.body_torques.get(self.train.driven, 0.0)
            Fl = self._torque_vector({self.train.driven: t * self.torque_fluctuation})
        return np.stack([F, Fl])

    def _build(self, omega: float) -> None:
        names = self.dof_names()
        n, nm = len(names), len(self._mesh_names)
        nh = self.fourier.shape[1] // 2
        M = self.mass_matrix()
        Minv = np.linalg.inv(M)
        Minv[np.abs(Minv) < 1e-12 * np.max(np.abs(Minv))] = 0.0
        K, C = self.stiffness_matrix(False), self._damping_matrix()
        plays = self.play_elements()
        for _, row, k_play, _, _ in plays:  # acts through its dead zone instead
            K -= k_play * np.outer(row, row)
        Kt = _clean(Minv @ K)
        kt_entries = [(int(i), int(j)) for i, j in zip(*np.nonzero(Kt), strict=True)]
        W = self.mesh_rows()
        contacts = self._mesh_names + tuple(play.name for play in plays)
        rows = list(W) + [play.row for play in plays]
        mesh_dofs = []
        for m, row in enumerate(rows):
            touched = sorted({int(j) for j in np.nonzero(row)[0]}
                             | {int(j) for j in np.nonzero(_clean(Minv @ row))[0]})
            if len(touched) > pk.MESH_NZ:
                raise ParameterError(f"{contacts[m]}", len(touched),
                                     f"the element's row touches {len(touched)} coordinates; "
                                     f"the kernels take at most {pk.MESH_NZ} per contact")
            mesh_dofs.append(touched)
        nm_gears, nm = nm, len(contacts)
        lay = pk.layout(n, nm, nh, len(kt_entries), 0)
        L, w0 = self.length_scale, self.time_scale
        p = np.zeros(lay["size"])
        p[pk.OMEGA] = omega
        p[pk.N_DOF], p[pk.N_MESH], p[pk.N_HARM] = n, nm, nh
        F = self._forces()
        p[pk.TORQUE_ON] = float(np.any(F[1] != 0.0))
        p[pk.TORQUE_ORDER], p[pk.TORQUE_PHASE] = self.torque_order, self.torque_phase
        p[lay["F0"]:lay["F0"] + n] = _clean(Minv @ F[0]) / (L * w0 * w0)
        p[lay["F1"]:lay["F1"] + n] = _clean(Minv @ F[1]) / (L * w0 * w0)
        p[lay["Kt"]:lay["Kt"] + n * n] = Kt.ravel() / w0**2
        p[lay["Ct"]:lay["Ct"] + n * n] = _clean(Minv @ C).ravel() / w0
        p[pk.DAMPED] = float(np.any(p[lay["Ct"]:lay["Ct"] + n * n] != 0.0))
        k, c, kc = self.mesh_stiffnesses(), self._mesh_damping(), self.coast_stiffnesses()
        for m in range(nm_gears):
            o = lay["mesh"] + m * lay["block"]
            self._fill_mesh_block(p[o:o + lay["block"]], m, L, w0, k[m], c[m], kc[m],
                                  self._phase_orders[m], W[m],
                                  _clean(Minv @ W[m]) / (L * w0 * w0))
        for j, (_, row, k_play, half_width, radial) in enumerate(plays):
            o = lay["mesh"] + (nm_gears + j) * lay["block"]
            _fill_play_block(p[o:o + lay["block"]], nh, row, _clean(Minv @ row) / (L * w0 * w0),
                             k_play * L, half_width / L, radial)
        self._layout = lay
        self._coast_given = self._mirrored
        self._coast_built = p[_flank_index(lay, n, nm, nh, True)].copy()
        self._structure = (kt_entries, mesh_dofs)
        self._refresh_workspace(p)
        p[lay["cache"]:lay["gyro"]] = pk.cache_entries(nm)[1]
        self.coefficient_layout = planetary_layout(names, contacts, nh, tuple(kt_entries), ())
        self.params = p
        self.omega_index = pk.OMEGA
        self.kernel = _KERNEL
        self.state_names = names + tuple(f"d{d}" for d in names)
        self.observable_names = tuple(f"F_{m}" for m in contacts)
        self.event_names = tuple(f"x_{m}{s}b_{m}" for m in contacts for s in "-+")
        self.meshes = tuple((m, 2 * i, 2 * i + 1) for i, m in enumerate(contacts))

    def play_elements(self) -> list[PlayElement]:
        """The elements with play besides the meshes, as the kernels' contacts after the
        meshes (:class:`PlayElement`). A flexible bearing with a ``clearance`` c gives two,
        ``<bearing>_x`` and ``<bearing>_y``, the x and y rows of one radial contact (radial 1
        and -1): a circular dead zone of radius c on the journal's deflection (x, y) relative
        to its host, force k (1 - c / r) (x, y) for r = sqrt(x^2 + y^2) > c, else 0. A shaft
        (coupling) with ``backlash`` gives one, ``<shaft>``, a dead zone of that half-width on
        its twist (radial 0). The element's damping stays linear (it acts in the play too)."""
        train, out = self.train, []
        for b in train.bearings:
            if b.clearance > 0.0:
                rx, ry = train._bearing_rows(b) @ train._T
                out += [PlayElement(f"{b.name}_x", rx, b.stiffness, b.clearance, 1),
                        PlayElement(f"{b.name}_y", ry, b.stiffness, b.clearance, -1)]
        for s in train.shafts:
            if s.backlash > 0.0:
                row = (train._unit(s.a, 0) - train._unit(s.b, 0)) @ train._T
                out.append(PlayElement(s.name, row, s.stiffness, s.backlash, 0))
        return out

    # ------------------------------------------------------------------ sweeps and axes
    @property
    def physical_names(self) -> tuple[str, ...]:
        """The inputs a sweep takes by name: the swept inputs (:meth:`swept_inputs`) given as
        one value for every mesh, ``input_speed`` [rpm] only with a driven body,
        ``stiffness_fluctuation`` not where a mesh takes its waveform from its teeth; then
        ``input_torque`` [N m] where the driven body carries a torque."""
        teeth = any(d.table is not None for d in self.train.mesh_data.values())
        out = []
        for k in self.swept_inputs():
            if k == INPUT_SPEED:
                if self.train.driven is not None:
                    out.append(k)
            elif k == "stiffness_fluctuation" and teeth:
                continue
            elif one_value(self.inputs.get(k)):
                out.append(k)
        if self.train.driven is not None and self.body_torques.get(self.train.driven):
            out.append(INPUT_TORQUE)
        return tuple(out)

    def with_params(self, **values: Any) -> TrainModel:
        """A copy with inputs changed by name (:class:`~geardyn.PlanetaryGearSet`'s
        ``with_params``); ``input_torque`` [N m] scales every mean torque so that the driven
        body's has that magnitude (:meth:`at_input_torque`)."""
        if INPUT_TORQUE in values:
            values = dict(values)
            torque = si_value(INPUT_TORQUE, values.pop(INPUT_TORQUE), "torque", 0.0, True)
            if "torques" in values or "load" in values:
                raise ParameterError(INPUT_TORQUE, torque, "scales the torques: give it or "
                                     "torques, one of them")
            s = torque / self.input_torque
            values["torques"] = {k: v * s for k, v in self.body_torques.items()}
            values["load"] = None
        return PlanetaryGearSet.with_params(self, **values)

    def lane_params(self, name: str, values: Any) -> np.ndarray:
        """Coefficient vectors (lanes x n_params) with ``name`` set to ``values``; the speeds
        (``input_speed`` [rpm], ``mesh_frequency`` [rad/s]) set Omega alone."""
        if name == INPUT_TORQUE:
            vals = np.asarray(values, dtype=float).ravel()
            return np.array([self.with_params(**{name: float(v)}).params for v in vals])
        if name in (INPUT_SPEED, "mesh_frequency"):
            vals = np.asarray(values, dtype=float).ravel()
            if name == INPUT_SPEED:
                vals = vals * 2.0 * math.pi / 60.0 * self.mesh_frequency_per_input_speed()
            return PlanetaryGearSet.lane_params(self, "Omega",
                                                vals / (self.time_scale * self.mesh_order))
        return PlanetaryGearSet.lane_params(self, name, values)

    @property
    def input_speed(self) -> float:
        """The driven body's speed [rpm] at the model's Omega."""
        w = (self.omega * self.time_scale * self.mesh_order
             / self.mesh_frequency_per_input_speed())
        return w * 60.0 / (2.0 * math.pi)

    def param_attrs(self, name: str) -> dict[str, str]:
        """Attributes of a swept input's axis: its declared unit (``input_speed`` in rpm,
        ``input_torque`` in the torques' unit) and, for the speeds and the input torque,
        ``long_name`` and ``meaning``; empty for another name."""
        declared = self.swept_inputs().get(name)
        if name == INPUT_SPEED:
            unit = declared.axis_unit
            return {"units": unit, "long_name": f"input ({self.train.driven}) speed",
                    "meaning": f"mesh frequency of {self.reference_mesh} / "
                               f"{self.mesh_frequency_per_input_speed():.6g}, in {unit}"}
        if name == "mesh_frequency":
            return {"units": declared.axis_unit,
                    "long_name": f"mesh frequency of {self.reference_mesh}"}
        if name == INPUT_TORQUE:
            return {"units": _TORQUES.axis_unit,
                    "long_name": f"input ({self.train.driven}) torque",
                    "meaning": "the driven body's mean torque, every mean torque scaled with it"}
        if name == "Omega" and self.faults is not None:
            return {"units": "1", "long_name": "forcing frequency / time_scale",
                    "meaning": f"{self.faults.gear}'s revolution frequency: mesh frequency of "
                               f"{self.reference_mesh} / ({self.mesh_order:.12g} time_scale)"}
        return {} if declared is None else {"units": declared.axis_unit}

    def speed_axes(self, omega: np.ndarray) -> dict[str, tuple[np.ndarray, dict]]:
        """The reference mesh's frequency [Hz] and, with a driven body, the input speed [rpm]
        at the dimensionless forcing frequencies ``omega``."""
        w = np.asarray(omega, dtype=float) * self.time_scale * self.mesh_order
        out = {"mesh_frequency": (w / (2.0 * math.pi), {
            "units": "Hz", "long_name": f"mesh frequency of {self.reference_mesh}"})}
        if self.train.driven is not None:
            out[INPUT_SPEED] = (w / self.mesh_frequency_per_input_speed() * 60.0
                                / (2.0 * math.pi), self.param_attrs(INPUT_SPEED))
        return out

    def other_frequencies(self, P: np.ndarray) -> np.ndarray:
        """The torque fluctuation's frequency (as the planetary set's), then every mesh's
        r_m Omega where r_m differs from 1 (NaN where it does not)."""
        P = np.atleast_2d(P)
        torque = PlanetaryGearSet.other_frequencies(self, P)
        lay = self._layout
        idx = [lay["mesh"] + m * lay["block"] + pk.M_ORDER for m in range(len(self._mesh_names))]
        r = P[:, idx]
        return np.hstack([torque, np.where(r != 1.0, r * P[:, pk.OMEGA, None], np.nan)])

    def dataset_attrs(self) -> dict[str, object]:
        """The reference mesh, where the mesh phases come from (``mesh_phases``), every mesh's
        order over it, and the forcing: ``periodic`` or ``quasi-periodic`` (sections sampled
        once per period of the reference mesh)."""
        period = (f"revolution of {self.faults.gear}" if self.faults is not None
                  else f"mesh period of {self.reference_mesh}")
        section = (f"once per {period}" if self.quasi_periodic
                   else f"common period of the meshes, in {period}s")
        out: dict[str, object] = {
            "reference_mesh": self.reference_mesh, "mesh_phases": self.phase_source,
            "mesh_names": ",".join(self._mesh_names),
            "mesh_orders": ",".join(f"{r:.12g}" for r in self.orders),
            "forcing": "quasi-periodic" if self.quasi_periodic else "periodic",
            "section": section,
            "mesh_stiffness_methods": ",".join(self.train.mesh_data[m].method
                                               for m in self._mesh_names)}
        if self.faults is not None:
            out.update(faults=self.faults.describe(), faulty_gear=self.faults.gear,
                       faulty_meshes=",".join(self.faults.meshes),
                       mesh_cycles_per_period=self.faults.teeth,
                       forcing_period=f"one revolution of {self.faults.gear} relative to its "
                                      f"meshes' frame ({self.faults.teeth} of their mesh "
                                      f"cycles, {self.mesh_order:.12g} of "
                                      f"{self.reference_mesh})",
                       Omega_meaning=f"mesh frequency of {self.reference_mesh} / "
                                     f"({self.mesh_order:.12g} time_scale)",
                       stiffness_harmonics=self.fourier.shape[1] // 2)
        return out

    # ------------------------------------------------------------------ ISO 6336-1 K_v
    @property
    def input_torque(self) -> float:
        """The magnitude of the driven body's mean torque [N m]."""
        driven = self.train.driven
        if driven is None:
            raise ParameterError("driven", None, "the input torque is the driven body's: the "
                                 "train needs driven")
        t = abs(float(self.body_torques.get(driven, 0.0)))
        if t == 0.0:
            raise ParameterError(f"torques.{driven}", 0.0, "the driven body carries no torque")
        return t

    def at_input_torque(self, torque: float) -> TrainModel:
        """The train with every mean torque scaled so that the driven body's has magnitude
        ``torque`` [N m] (the load balancing it scaled alike)."""
        return self.with_params(**{INPUT_TORQUE: float(torque)})

    def kv_groups(self, torque: float) -> tuple[KvMeshGroup, ...]:
        """The meshes whose two gears have geometry, grouped as clause 6.5.9 groups a
        planetary stage's: meshes that share one gear (a sun, a ring) with equal other gears
        (the planets: same geometry and inertia) form one group named after the shared gear;
        every other mesh is a group of its own, named after it. Gear 1 is a group's gear
        ``a`` (a sun, a planet on a ring) or a single external pair's smaller gear, its speed
        relative to the mesh's frame (a planet's carrier). F_t = F_n cos(beta_b) r_b1 / r_1
        from the static mesh force F_n at ``torque`` (along the line of action, normal to a
        helical tooth); m_red of :func:`~geardyn.gears.iso6336_kv.group_reduced_mass` from the
        gears' own inertias (an internal gear taken as infinitely heavy)."""
        train = self.train
        names = self._mesh_names
        index = {m: k for k, m in enumerate(names)}
        geometric = [m for m in train.meshes if train.bodies[m.a].geometry is not None
                     and train.bodies[m.b].geometry is not None]
        if not geometric:
            raise ParameterError("train.meshes", names, "K_v needs meshes whose two gears have "
                                 "geometry")
        forces = np.abs(self.at_input_torque(torque).static_mesh_forces())
        orders = train.mesh_orders()

        def signature(mesh: Any, gear: str) -> tuple:
            g = train.bodies[gear]
            return (g.geometry, g.inertia, mesh.internal)

        groups: list[tuple[str, str, list[Any]]] = []  # (name, common gear, meshes)
        left = list(geometric)
        shared: dict[tuple[str, tuple], list[Any]] = {}
        for m in geometric:
            for common, other in ((m.b, m.a),) if m.internal else ((m.a, m.b), (m.b, m.a)):
                shared.setdefault((common, signature(m, other)), []).append(m)
        for (common, _), members in sorted(shared.items(), key=lambda kv: -len(kv[1])):
            members = [m for m in members if m in left]
            if len(members) > 1:
                groups.append((common, common, members))
                left = [m for m in left if m not in members]
        groups += [(m.name, m.b, [m]) for m in left]
        groups.sort(key=lambda g: min(index[m.name] for m in g[2]))
        out = []
        for name, common, members in groups:
            first = members[0]
            ga, gb = train.bodies[first.a], train.bodies[first.b]
            if len(members) == 1 and not first.internal \
                    and ga.geometry.teeth > gb.geometry.teeth:
                ga, gb = gb, ga  # ISO's gear 1 of a single pair: the pinion
            mesh = pair_geometry(first, ga, gb)
            transverse = getattr(mesh, "transverse", mesh)
            other = first.a if common == first.b else first.b
            gc, go = train.bodies[common], train.bodies[other]
            idx = tuple(index[m.name] for m in members)
            force = float(np.mean(forces[list(idx)]))
            if not force > 0.0:
                raise ParameterError(f"{first.name}.load", force, "the mesh carries no static "
                                     "load at this torque: K_v needs a loaded mesh")
            data = train.mesh_data[first.name]
            b = min(mesh.pinion.face_width, mesh.wheel.face_width)
            m_red = group_reduced_mass(gc.inertia, go.inertia, gc.base_radius, go.base_radius,
                                       len(members), b, first.internal)
            out.append(KvMeshGroup(
                name, mesh, idx,
                force * math.cos(data.base_helix_angle) * transverse.pinion.base_radius
                / transverse.pinion.reference_radius,
                m_red, orders[first.name] / mesh.pinion.teeth,
                data.stiffness * math.cos(data.base_helix_angle) ** 2))
        return tuple(out)

    def input_speed_sweep(self, rpm: np.ndarray) -> tuple[str, np.ndarray]:
        """``input_speed`` [rpm] itself."""
        return INPUT_SPEED, np.asarray(rpm, dtype=float)

    # ------------------------------------------------------------------ linear analysis
    def natural_frequencies(self) -> np.ndarray:
        return self.train.natural_frequencies()

    def modes(self):
        return self.train.modes()

    def bearing_forces(self, y: np.ndarray) -> dict[str, np.ndarray]:
        raise ParameterError("bearing_forces", None, "a train model has mesh forces as its "
                             "observables; its bearings' forces are not computed")

    def __repr__(self) -> str:
        kind = "quasi-periodic" if self.quasi_periodic else "periodic"
        return (f"TrainModel({len(self.train.bodies)} bodies, {len(self._mesh_names)} meshes, "
                f"dofs={len(self.dof_names())}, Omega={self.omega:g}, {kind} forcing)")


def _in_time(table: np.ndarray, backward: bool) -> np.ndarray:
    """A table uniform in gear a's rotation, c_i = i / n over its cycles, as the mesh meets it
    in time: itself, or read backwards, T(-c_i) = T[(-i) mod n]."""
    return np.roll(table[::-1], 1) if backward else table


def _fill_play_block(blk: np.ndarray, nh: int, row: np.ndarray, force_row: np.ndarray,
                     force_per_deflection: float, half_width: float, radial: int) -> None:
    """A play element's block of the coefficient vector (a mesh block of
    :mod:`~geardyn.models.planetary_kernels` with constant stiffness): its half-width (a
    radial contact's radius), force per dimensionless deflection on both flanks, order 1 and
    no harmonics (relative stiffness 1), its kind ``radial`` (0: a dead zone; 1, -1: the x, y
    row of a radial contact), its ``row`` and ``force_row``; no error, no own damping."""
    n = row.size
    f = pk.MESH_FIXED
    blk[pk.M_B] = half_width
    blk[pk.M_RADIAL] = radial
    blk[pk.M_KF] = blk[pk.M_KFC] = force_per_deflection
    blk[pk.M_ORDER] = 1.0
    blk[f + 2 * nh:f + 2 * nh + n] = row
    blk[f + 2 * nh + n:f + 2 * nh + 2 * n] = force_row
