"""Tooth faults of a gear train (:class:`~geardyn.trains.GearTrain` ``faults``): where they sit,
which meshes they touch, and those meshes' potential-energy stiffness over the faulty gear's
revolution.

A fault (:mod:`geardyn.gears.faults`) sits on tooth ``tooth`` of ``gear``, the name of a
:class:`~geardyn.trains.Gear` of the train. All the faults of a train lie on one gear f (Z_f
teeth), whose meshes all take their stiffness from the potential-energy method: a spur gear's
from :func:`~geardyn.gears.potential_energy_stiffness`, a helical gear's from
:func:`~geardyn.gears.helical_stiffness` (the slices and angles of the mesh's healthy table),
where a crack, uniform wear and a missing tooth act across the whole face width and a spall or
Archard wear is refused (as there).

Tooth numbers: tooth j of f passes the pitch point of f's first mesh m_0 (in the train's order)
j mesh cycles after tooth 0, which passes it at the mesh's phase origin (the stiffness table's
angle 0, moved by the mesh's ``mesh_phase`` psi_0 of :class:`~geardyn.trains.TrainModel`: at
c = -psi_0 / 2 pi mesh cycles). The same tooth passes the pitch point of another mesh m of f
D_m mesh cycles later (the unreduced passage step across f,
:meth:`~geardyn.trains.TrainModel.tooth_passage_step`, from the geometry); on m's table, whose
pairs pass at c = -psi_m / 2 pi + whole cycles, it is tooth (j + round(D_m + (psi_m - psi_0) /
2 pi)) mod Z_f of f: exact with ``mesh_phase="geometry"``, the passage nearest the geometric one
with other phases. A mesh whose gear a turns in the negative sense relative to its frame reads
its tables backwards in time (:meth:`~geardyn.trains.TrainModel.backward_meshes`): the tooth
passing its pitch point at c = j is its table's tooth -j. A tooth passes with its drive flank
(below; a ring's clockwise-facing one), so on a planetary stage ring tooth j is the
:class:`~geardyn.PlanetaryGearSet`'s ring tooth j
(:func:`~geardyn.models.planetary_faults.ring_origin`).

Flanks: a fault's ``flank`` ``"drive"`` is the flank in contact at a positive deflection of f's
meshes. A train's mesh rows make that the same flank of f's teeth in every mesh (the
counter-clockwise-facing flank of an external gear, the clockwise-facing one of a ring: the e of
:meth:`~geardyn.trains.TrainModel.geometry_phases`), so a spall or wear acts on the drive
contacts of every mesh of f. Archard wear on a gear of several meshes is the wear of one
revolution of f (:func:`shared_wear_profiles`): each mesh wears the flank it loads under the
model's mean torques, its Archard rate weighted by its load per unit face width, so an idler's
or a planet's flank takes the wear of the one mesh that loads it. A crack weakens the contacts
of both flanks; a missing tooth takes out both (its meshes' series then ring below 0 about the
gap, which the kernels clip).

The stiffness over the revolution (:func:`revolution_series`): a faulty mesh's table over Z_f
mesh cycles, the fault on its tooth, becomes the Fourier series in the revolution angle Theta =
2 pi c / Z_f with H Z_f harmonics (every sideband up to mesh harmonic H): the healthy one-cycle
series embedded at harmonics l Z_f plus the series of the difference faulty - healthy (the
same series, linear in the table). A fault of zero size leaves the difference exactly 0 and the
series bitwise the embedded healthy one.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from geardyn.errors import ParameterError
from geardyn.gears.faults import BrokenTooth, RootCrack, Spall, Wear, listed_faults
from geardyn.models.planetary_faults import LOAD_RTOL
from geardyn.models.planetary_stiffness import FlankSeries, embedded, flank_series
from geardyn.trains.elements import Gear, pair_geometry

_KINDS = (RootCrack, Spall, Wear, BrokenTooth)


@dataclass(frozen=True)
class TrainFaults:
    """The faults of a train: the faulty ``gear`` (its name), its ``teeth`` Z_f (the mesh
    cycles of one of its revolutions relative to its meshes' frame), the ``faults`` as given
    and the ``meshes`` the gear takes part in (train order; the first numbers the teeth)."""

    gear: str
    teeth: int
    faults: tuple[Any, ...]
    meshes: tuple[str, ...]

    @property
    def missing_tooth(self) -> bool:
        """Whether a tooth is missing (the faulty meshes' stiffness falls to 0 over a gap)."""
        return any(isinstance(f, BrokenTooth) for f in self.faults)

    def describe(self) -> str:
        """One line for the datasets' attrs."""
        return "; ".join(f.describe() for f in self.faults)

    def on_mesh(self, role: str, offset: int, backward: bool = False) -> tuple[Any, ...]:
        """The faults as a pair's table takes them: on its ``role`` (``"pinion"``,
        ``"wheel"``), each tooth moved by ``offset`` (mod Z_f); ``backward`` (a table read
        backwards in time): on the table's tooth -(tooth + offset) (mod Z_f)."""
        sign = -1 if backward else 1
        return tuple(replace(f, gear=role, tooth=sign * (f.tooth + offset) % self.teeth)
                     for f in self.faults)


def place_train_faults(train: Any, faults: object) -> TrainFaults | None:
    """The :class:`TrainFaults` of ``faults`` (one fault or a sequence) on ``train`` (a
    :class:`~geardyn.trains.GearTrain` whose bodies, meshes and mesh data are set), None without
    faults. Errors name the fault's field (``crack.gear``: no gear of the train; ``crack.tooth``:
    beyond its teeth; ``spall.gear``: a spall on a helical gear; ``wear.profile``: Archard wear
    on a helical gear), ``faults`` (not a fault, faults on two
    gears, a faulty gear without meshes) or the faulty gear's mesh (``<mesh>.stiffness``: not
    the potential-energy method)."""
    listed = listed_faults(faults)
    if not listed:
        return None
    gears = [name for name, b in train.bodies.items() if isinstance(b, Gear)]
    for fault in listed:
        if not isinstance(fault, _KINDS):
            raise ParameterError("faults", fault,
                                 "must be RootCrack, Spall, Wear or BrokenTooth objects")
        if fault.gear not in gears:
            raise ParameterError(f"{fault.kind}.gear", fault.gear,
                                 f"names no gear of the train ({', '.join(gears)})")
    names = sorted({f.gear for f in listed})
    if len(names) > 1:
        raise ParameterError("faults", ", ".join(names), "faults on more than one gear: the "
                             "forcing period is one revolution of the one faulty gear")
    gear = names[0]
    body = train.bodies[gear]
    z = body.teeth
    for fault in listed:
        if z is None or not 0 <= fault.tooth < z:
            raise ParameterError(f"{fault.kind}.tooth", fault.tooth,
                                 f"must lie in [0, {(z or 1) - 1}] ({gear} has {z} teeth)")
    meshes = tuple(m for m in train.meshes if gear in (m.a, m.b))
    if not meshes:
        raise ParameterError("faults", gear, "the faulty gear takes part in no mesh")
    for m in meshes:
        if train.mesh_data[m.name].table is None:
            raise ParameterError(f"{m.name}.stiffness", m.stiffness,
                                 f"a fault on {gear} needs the potential-energy stiffness of its"
                                 " meshes (stiffness='potential_energy')")
    if body.helical:
        for fault in listed:
            if isinstance(fault, Spall):
                raise ParameterError(f"{fault.kind}.gear", gear, "a spall on a helical gear is not "
                                     "modelled: Spall does not place it across the face width "
                                     "(helical_stiffness refuses it)")
            if isinstance(fault, Wear) and fault.profile != "uniform":
                raise ParameterError("wear.profile", fault.profile, f"{gear} is helical: a "
                                     "helical pair takes uniform wear only (Archard's profile "
                                     "is the spur pair's load share); give uniform wear")
    return TrainFaults(gear, z, listed, tuple(m.name for m in meshes))


def shared_wear_profiles(train: Any, placement: TrainFaults, loads: Mapping[str, float],
                         force_scale: float) -> dict[Any, Any]:
    """The depth along the flank of each Archard :class:`~geardyn.gears.Wear` of
    ``placement`` (keyed by the fault as given) on a gear of several meshes: the wear of one
    revolution of the gear, every mesh wearing the flank it loads
    (:func:`~geardyn.gears.potential_energy.combined_wear_profile`), weighted by its load per
    unit face width on the worn flank, max(F_m, 0) / b_m on the drive flank, max(-F_m, 0) /
    b_m on the coast flank (``loads``: F_m [N] by mesh name, positive on the drive flank). An
    idler's or a planet's two meshes load opposite flanks, so each flank takes the wear of one
    of them; a gear that drives or is driven by several meshes takes their sum. {} on a gear of
    one mesh (its own profile, as a pair's) or without Archard wear. ``force_scale`` [N]: the
    applied torques' force scale, max abs(T) over the bodies / the largest base radius of the
    train's gears. Error ``wear.flank``: no mesh loads the worn flank by more than
    :data:`~geardyn.models.planetary_faults.LOAD_RTOL` x ``force_scale`` (a smaller force is
    round-off)."""
    from geardyn.gears.potential_energy import combined_wear_profile, prepare_pair

    wears = [f for f in placement.faults if isinstance(f, Wear) and f.profile == "archard"]
    if len(placement.meshes) < 2 or not wears:
        return {}
    cache = train.__dict__.setdefault("_shared_wear", {})
    meshes = {m.name: m for m in train.meshes}
    out = {}
    for wear in wears:
        sign = 1.0 if wear.flank == "drive" else -1.0
        raw = [max(sign * float(loads[m]), 0.0) for m in placement.meshes]
        if not max(raw) > LOAD_RTOL * force_scale:
            raise ParameterError("wear.flank", wear.flank, f"no mesh of {placement.gear} "
                                 f"loads its {wear.flank} flank under the mean torques "
                                 f"(static mesh forces {dict(loads)} N, round-off below "
                                 f"{LOAD_RTOL:g} x {force_scale:.6g} N, the torques' force "
                                 "scale): Archard wear on a gear of several meshes follows "
                                 "the meshes that load the worn flank")
        # relative to the largest, to 12 digits: the same profile at every torque scale
        weights = tuple(round(w / max(raw), 12) for w in raw)
        key = (wear, weights)
        if key not in cache:
            parts = []
            for name, w in zip(placement.meshes, weights, strict=True):
                mesh = meshes[name]
                pair = prepare_pair(pair_geometry(mesh, train.bodies[mesh.a],
                                               train.bodies[mesh.b]),
                                    bore_radius=mesh.bore_radius)
                role = "pinion" if placement.gear == mesh.a else "wheel"
                parts.append((pair, role, w / pair.face_width))
            cache[key] = combined_wear_profile(parts, wear.depth)
        out[wear] = cache[key]
    return out


def faulty_table(train: Any, mesh: Any, pair: Any, faults: tuple[Any, ...],
                 cycles: int, wear_profiles: Mapping[Any, Any] | None = None) -> Any:
    """The potential-energy stiffness Dataset of train ``mesh`` (its gears' pair ``pair``) over
    ``cycles`` mesh cycles with ``faults`` on the pair's pinion or wheel (the mesh's own inputs,
    as its healthy one-cycle table; ``wear_profiles``: the depth along the flank of its
    Archard wear, :func:`shared_wear_profiles`), kept on the train for the models rebuilt from
    it."""
    from geardyn.gears.helical import HelicalMesh, helical_stiffness
    from geardyn.gears.potential_energy import potential_energy_stiffness

    cache = train.__dict__.setdefault("_fault_tables", {})
    shared = dict(wear_profiles or {})
    key = (mesh.name, faults, cycles, tuple(shared.items()))
    if key not in cache:
        if isinstance(pair, HelicalMesh):
            healthy = train.mesh_data[mesh.name].table
            cache[key] = helical_stiffness(pair, bore_radius=mesh.bore_radius,
                                           angles=int(healthy.sizes["angle"]),
                                           slices=int(healthy.attrs["slices"]),
                                           faults=faults, cycles=cycles)
        else:
            cache[key] = potential_energy_stiffness(pair, bore_radius=mesh.bore_radius,
                                                    faults=faults, cycles=cycles,
                                                    wear_profiles=shared)
    return cache[key]


def revolution_series(healthy: np.ndarray, faulty: np.ndarray, harmonics: int,
                      teeth: int) -> FlankSeries:
    """The series in the revolution angle of a flank's ``faulty`` table over ``teeth`` mesh
    cycles (the same angles per cycle as the one-cycle ``healthy`` table), ``harmonics`` mesh
    harmonics (``harmonics`` x ``teeth`` in all): the healthy series embedded plus the
    difference's, k1 = k0 + d0, a = a_0 k0 / k1 + 2 Re(D_h) / k1, b = b_0 k0 / k1 - 2 Im(D_h) /
    k1 (D the difference's discrete Fourier transform over its length, d0 its mean)."""
    h = np.asarray(healthy, dtype=float)
    f = np.asarray(faulty, dtype=float)
    if f.size != h.size * teeth:
        raise ParameterError("faults", f.size, f"the faulty table must span {teeth} mesh "
                             f"cycles of {h.size} angles")
    n_h = harmonics * teeth
    base = embedded(flank_series(h, harmonics), teeth, n_h)
    D = np.fft.rfft(f - np.tile(h, teeth)) / f.size
    k1 = base.mean + float(D[0].real)
    if not k1 > 0.0:
        raise ParameterError("faults", k1, "the faulty mesh's mean stiffness must be > 0")
    scale = base.mean / k1
    return FlankSeries(k1, base.a * scale + 2.0 * D[1:n_h + 1].real / k1,
                       base.b * scale - 2.0 * D[1:n_h + 1].imag / k1)
