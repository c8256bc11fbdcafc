"""The mesh stiffness of a planetary gear set built from its geometry
(:meth:`geardyn.PlanetaryGearSet.from_geometry`): ISO 6336-1 waves, or the potential-energy
stiffness (:func:`geardyn.gears.potential_energy_stiffness`) of the sun-planet and the
planet-ring mesh over one mesh cycle, drive and coast flank, as truncated Fourier series.

A table k(theta_j) [N/m], uniform over one mesh cycle (theta_j = 2 pi j / n from the passage
of a tooth pair through the pitch point, the phase origin of the ISO waves too), becomes its
discrete Fourier series k0 (1 + sum_h a_h cos(h theta) + b_h sin(h theta)), h = 1..H: the mean
k0 and the relative coefficients (a_h, b_h) the model's ``waveform`` takes.

The coast (back) flank (``coast``): ``"mirror"`` gives it its own stiffness, the mirror image of
the drive flank's about the coast phase phi (:func:`geardyn.gears.potential_energy.coast_phase`,
geometry only): K_coast(theta) = K_drive(2 pi phi - theta) (:func:`mirrored`) for the ISO waves,
the tables' own coast flank for the potential-energy method; ``"symmetric"`` the drive flank's
stiffness on both flanks.

A table is in gear a's rotation (the sun of a sun-planet mesh, the planet of a planet-ring mesh)
in the positive sense; the set takes the planet-ring table as its mirror image (its positive
deflection loads the flank the table calls coast), which is the mesh itself while the planet
turns in the negative sense relative to the carrier. With the sun held both turn the other
way and every mesh reads its tables backwards in time, T(-c) (:func:`reversed_in_time`,
:func:`table_in_time`; ``docs/planetary.md``, "Which way a mesh meets its teeth").
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from geardyn.errors import ParameterError
from geardyn.units import si_value

#: The stiffness methods of :meth:`geardyn.PlanetaryGearSet.from_geometry`.
STIFFNESS_METHODS = ("iso", "potential_energy")
#: Points per mesh cycle of the potential-energy tables by default.
DEFAULT_ANGLES = 360
#: The coast-flank choices of :meth:`geardyn.PlanetaryGearSet.from_geometry` (``coast``).
COAST_FLANKS = ("mirror", "symmetric")
_FIELD = "stiffness_options"
_REQUIRED = ("sun_bore_radius", "planet_bore_radius", "ring_rim_radius")
_OPTIONAL = ("young", "poisson", "angles", "nodes", "root_segment")


@dataclass(frozen=True)
class PotentialEnergyOptions:
    """The inputs of the potential-energy tables, SI: bore radii of sun and planet and the
    ring's outer (rim) radius [m], Young's modulus [Pa], Poisson's ratio, points per mesh cycle,
    Gauss-Legendre nodes, the root form (see :func:`~geardyn.gears.potential_energy_stiffness`)."""

    sun_bore_radius: float
    planet_bore_radius: float
    ring_rim_radius: float
    young: float
    poisson: float
    angles: int
    nodes: int
    root_segment: bool


@dataclass(frozen=True)
class FlankSeries:
    """One flank's stiffness series of one mesh group: mean k0 [N/m] and relative Fourier
    coefficients a, b (harmonics 1..H) of k / k0 - 1."""

    mean: float
    a: np.ndarray
    b: np.ndarray

    @property
    def pair(self) -> tuple[np.ndarray, np.ndarray]:
        """(a, b), the form of the model's ``waveform``."""
        return self.a, self.b


def stiffness_method(stiffness: Any, options: Mapping[str, Any] | None) -> str:
    """``stiffness`` checked (one of :data:`STIFFNESS_METHODS`); options only with
    ``"potential_energy"``."""
    if not isinstance(stiffness, str) or stiffness not in STIFFNESS_METHODS:
        raise ParameterError("stiffness", stiffness,
                             f"must be one of {', '.join(map(repr, STIFFNESS_METHODS))}")
    if stiffness == "iso" and options:
        raise ParameterError(_FIELD, dict(options), "only with stiffness='potential_energy' "
                             "(the ISO waves take waveform_options)")
    return stiffness


def coast_flank(coast: Any) -> str:
    """``coast`` checked: one of :data:`COAST_FLANKS`."""
    if not isinstance(coast, str) or coast not in COAST_FLANKS:
        raise ParameterError("coast", coast,
                             f"must be one of {', '.join(map(repr, COAST_FLANKS))}")
    return coast


def mirrored(a: np.ndarray, b: np.ndarray, phase_cycles: float) -> tuple[np.ndarray, np.ndarray]:
    """The relative Fourier coefficients of k(2 pi phi - theta) from those (a_h, b_h), h = 1..H,
    of k(theta) = k0 (1 + sum a_h cos(h theta) + b_h sin(h theta)), phi = ``phase_cycles``
    [mesh cycles]: a'_h = a_h cos(h Phi) + b_h sin(h Phi), b'_h = a_h sin(h Phi) - b_h cos(h Phi),
    Phi = 2 pi phi (the mean is unchanged)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    P = 2.0 * np.pi * np.arange(1, a.size + 1) * float(phase_cycles)
    c, s = np.cos(P), np.sin(P)
    return a * c + b * s, a * s - b * c


def _whole(field: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise ParameterError(field, value, f"must be a whole number >= {minimum}")
    return int(value)


def potential_energy_options(options: Mapping[str, Any] | None, geometry: Any,
                             harmonics: int) -> PotentialEnergyOptions:
    """``stiffness_options`` validated against the geometry (errors name
    ``stiffness_options.<key>``): the bores inside the sun's and the planet's root circles, the
    rim outside the ring's root circle, more than 2 ``harmonics`` angles per mesh cycle."""
    from geardyn.gears.potential_energy import DEFAULT_NODES, STEEL_POISSON, STEEL_YOUNG

    if not isinstance(options, Mapping | None):
        raise ParameterError(_FIELD, options, "must be a mapping (sun_bore_radius, ...)")
    opts = dict(options or {})
    for key in opts:
        if key not in _REQUIRED + _OPTIONAL:
            raise ParameterError(f"{_FIELD}.{key}", opts[key],
                                 f"unknown; known: {', '.join(_REQUIRED + _OPTIONAL)}")
    for key in _REQUIRED:
        if key not in opts:
            raise ParameterError(f"{_FIELD}.{key}", None,
                                 "needed for stiffness='potential_energy' [m]")
    radii = {k: si_value(f"{_FIELD}.{k}", opts[k], "length", 0.0, strict=True)
             for k in _REQUIRED}
    for key, gear, inside in (("sun_bore_radius", geometry.sun, True),
                              ("planet_bore_radius", geometry.planet, True),
                              ("ring_rim_radius", geometry.ring, False)):
        root = gear.root_radius
        if (radii[key] >= root) if inside else (radii[key] <= root):
            where = "inside" if inside else "outside"
            raise ParameterError(f"{_FIELD}.{key}", opts[key],
                                 f"must lie {where} the {gear.name}'s root circle "
                                 f"(radius {root:.6g} m)")
    young = si_value(f"{_FIELD}.young", opts.get("young", STEEL_YOUNG), "pressure", 0.0,
                     strict=True)
    poisson = si_value(f"{_FIELD}.poisson", opts.get("poisson", STEEL_POISSON),
                       "dimensionless", 0.0)
    if not poisson < 0.5:
        raise ParameterError(f"{_FIELD}.poisson", opts["poisson"], "must lie in [0, 0.5)")
    angles = _whole(f"{_FIELD}.angles", opts.get("angles", DEFAULT_ANGLES), 8)
    if angles <= 2 * harmonics:
        raise ParameterError(f"{_FIELD}.angles", angles,
                             f"must exceed 2 harmonics = {2 * harmonics} (the series of "
                             f"{harmonics} harmonics needs more points per mesh cycle)")
    root_segment = opts.get("root_segment", True)
    if not isinstance(root_segment, bool | np.bool_):
        raise ParameterError(f"{_FIELD}.root_segment", root_segment, "must be true or false")
    return PotentialEnergyOptions(
        **radii, young=young, poisson=poisson, angles=angles,
        nodes=_whole(f"{_FIELD}.nodes", opts.get("nodes", DEFAULT_NODES), 4),
        root_segment=bool(root_segment))


def potential_energy_tables(geometry: Any, opts: PotentialEnergyOptions) -> tuple[Any, Any]:
    """The potential-energy stiffness Datasets of the sun-planet and the planet-ring mesh over
    one mesh cycle (``opts.angles`` points; the ring's body rigid)."""
    from geardyn.gears.potential_energy import potential_energy_stiffness

    common = dict(angles=opts.angles, young=opts.young, poisson=opts.poisson,
                  nodes=opts.nodes, root_segment=opts.root_segment)
    sun = potential_energy_stiffness(
        geometry.sun_mesh, bore_radius=(opts.sun_bore_radius, opts.planet_bore_radius), **common)
    ring = potential_energy_stiffness(
        geometry.ring_mesh, bore_radius=(opts.planet_bore_radius, opts.ring_rim_radius),
        ring_foundation="rigid", **common)
    return sun, ring


def flank_series(table: np.ndarray, harmonics: int) -> FlankSeries:
    """The discrete Fourier series of ``table`` (uniform over one mesh cycle from phase 0), cut
    after ``harmonics``: mean and relative coefficients."""
    k = np.asarray(table, dtype=float)
    F = np.fft.rfft(k) / k.size
    k0 = float(F[0].real)
    if not k0 > 0.0:
        raise ParameterError("stiffness", k0, "the mean mesh stiffness must be > 0")
    a = 2.0 * F[1:harmonics + 1].real / k0
    b = -2.0 * F[1:harmonics + 1].imag / k0
    return FlankSeries(k0, a, b)



def reversed_in_time(pair: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The relative Fourier coefficients of k(-theta) from those (a, b) of k(theta): (a, -b)
    (the series of a table read backwards in time, T(-c))."""
    a, b = pair
    return np.asarray(a, dtype=float), -np.asarray(b, dtype=float)


def table_in_time(table: Any, backward: bool) -> Any:
    """A table uniform over its cycles (c_i = i / n per cycle, along ``angle``) as the mesh meets
    it in time: itself, or read backwards, every variable at c_i taken from the table's
    (-c_i) (index (-i) mod n; the coordinates kept), with attrs ``read_backward`` = 1."""
    if not backward:
        return table
    n = table.sizes["angle"]
    out = table.isel(angle=(-np.arange(n)) % n)
    out = out.assign_coords(angle=table["angle"].values, cycle=("angle", table["cycle"].values))
    out.attrs = {**table.attrs, "read_backward": 1}
    return out


def embedded(series: FlankSeries, order: int, harmonics: int) -> FlankSeries:
    """A one-mesh-cycle series as a series in the revolution angle of ``order`` mesh cycles:
    mesh harmonic l at harmonic l ``order``, ``harmonics`` (a multiple of ``order``) in all."""
    a, b = np.zeros(harmonics), np.zeros(harmonics)
    count = min(series.a.size, harmonics // order)
    a[order - 1::order][:count] = series.a[:count]
    b[order - 1::order][:count] = series.b[:count]
    return FlankSeries(series.mean, a, b)


@dataclass(frozen=True)
class RevolutionStiffness:
    """The potential-energy stiffness of a set with a faulty gear over one revolution of that
    gear relative to the carrier (:mod:`geardyn.models.planetary_faults`): per mesh (sun-planet
    meshes, then ring-planet) its table over ``order`` mesh cycles as the mesh meets it in time
    (``tables``, :func:`table_in_time`; a healthy mesh's one-cycle table repeated), its shift
    [mesh cycles] and its drive and coast series, unshifted,
    in the revolution angle (``harmonics`` = mesh harmonics x ``order``); ``healthy`` the healthy
    one-cycle tables (sun-planet, planet-ring)."""

    order: int
    harmonics: int
    tables: tuple[Any, ...]
    healthy: tuple[Any, Any]
    shifts: np.ndarray
    drive: tuple[FlankSeries, ...]
    coast: tuple[FlankSeries, ...]

    def inputs(self, n_planets: int, coast: str) -> dict[str, Any]:
        """The :class:`~geardyn.PlanetaryGearSet` inputs: per-planet mean stiffnesses, one
        series per mesh (``waveform``, ``coast_waveform`` keyed by mesh name), the shifts as
        mesh phases (-2 pi delta, in rad of the mesh cycle) and ``mesh_order``."""
        names = [f"s{i + 1}" for i in range(n_planets)] + [f"r{i + 1}" for i in
                                                            range(n_planets)]
        sun, ring = slice(0, n_planets), slice(n_planets, None)
        out: dict[str, Any] = {
            "mesh_order": self.order,
            "sun_mesh_stiffness": [s.mean for s in self.drive[sun]],
            "ring_mesh_stiffness": [s.mean for s in self.drive[ring]],
            "waveform": {m: s.pair for m, s in zip(names, self.drive, strict=True)},
            "sun_mesh_phase": list(-2.0 * np.pi * self.shifts[sun]),
            "ring_mesh_phase": list(-2.0 * np.pi * self.shifts[ring]),
        }
        if coast == "mirror":
            out["sun_coast_stiffness"] = [s.mean for s in self.coast[sun]]
            out["ring_coast_stiffness"] = [s.mean for s in self.coast[ring]]
            out["coast_waveform"] = {m: s.pair for m, s in zip(names, self.coast, strict=True)}
        return out


def revolution_stiffness(geometry: Any, opts: PotentialEnergyOptions, placement: Any,
                         harmonics: int, sun_turns: int,
                         wear_profiles: Mapping[Any, Any] | None = None) -> RevolutionStiffness:
    """The :class:`RevolutionStiffness` of ``geometry`` with the faults of ``placement`` (a
    :class:`~geardyn.models.planetary_faults.FaultPlacement`), ``harmonics`` mesh harmonics
    (every sideband up to the last: ``harmonics`` x Z_f in the revolution angle).
    ``wear_profiles``: the depth along the flank of Archard wear of ``placement.faults`` (keyed
    by the fault as given) in place of each mesh's own
    (:func:`~geardyn.models.planetary_faults.planet_wear_profiles`). ``sun_turns`` -1 (the sun
    held): every table read backwards in time, the faults on the tables' tooth -j."""
    from geardyn.gears.potential_energy import potential_energy_stiffness
    from geardyn.models.planetary_faults import mesh_shifts

    order = placement.teeth
    n_h = harmonics * order
    common = dict(angles=opts.angles, young=opts.young, poisson=opts.poisson,
                  nodes=opts.nodes, root_segment=opts.root_segment)
    bores = {"sun": (opts.sun_bore_radius, opts.planet_bore_radius),
             "ring": (opts.planet_bore_radius, opts.ring_rim_radius)}
    meshes = {"sun": geometry.sun_mesh, "ring": geometry.ring_mesh}
    extra = {"sun": {}, "ring": {"ring_foundation": "rigid"}}
    backward = sun_turns < 0  # every mesh reads its tables backwards in time
    faults = {"sun": _on_table(placement.sun_faults, placement.teeth, backward),
              "ring": _on_table(placement.ring_faults, placement.teeth, backward)}
    shared = dict(wear_profiles or {})
    profiles = {g: {on: shared[f] for f, on in zip(placement.faults, faults[g], strict=False)
                    if f in shared} for g in faults}
    n = geometry.n_planets
    tables, drive, coast, healthy_tables = [], [], [], []
    for g in ("sun", "ring"):
        table = potential_energy_stiffness(meshes[g], bore_radius=bores[g], **common,
                                           **extra[g])
        healthy_tables.append(table)
        healthy = table_in_time(table, backward)
        faulty = (table_in_time(potential_energy_stiffness(
            meshes[g], bore_radius=bores[g], faults=faults[g], cycles=order,
            wear_profiles=profiles[g], **common, **extra[g]), backward)
                  if faults[g] else None)
        for i in range(n):
            hit = faulty is not None and placement.planet in (None, i)
            if hit:
                tables.append(faulty)
                drive.append(flank_series(faulty["mesh_stiffness"].values, n_h))
                coast.append(flank_series(faulty["mesh_stiffness_coast"].values, n_h))
            else:
                tables.append(healthy)
                drive.append(embedded(flank_series(healthy["mesh_stiffness"].values,
                                                   harmonics), order, n_h))
                coast.append(embedded(flank_series(healthy["mesh_stiffness_coast"].values,
                                                   harmonics), order, n_h))
    sun, ring = mesh_shifts(geometry, sun_turns, placement)
    return RevolutionStiffness(order, n_h, tuple(tables), tuple(healthy_tables),
                               np.concatenate([sun, ring]), tuple(drive), tuple(coast))


def _on_table(faults: tuple[Any, ...], teeth: int, backward: bool) -> tuple[Any, ...]:
    """The faults as a table takes them: on their own tooth j, or on a table read backwards
    in time (the tooth passing the pitch point at c = j is the table's tooth -j) on (-j) mod
    ``teeth``."""
    if not backward:
        return faults
    return tuple(replace(f, tooth=(-f.tooth) % teeth) for f in faults)


def series_error(table: np.ndarray, cycles: int, mean: float, coefficients: np.ndarray,
                 shift: float, order: int) -> np.ndarray:
    """The mesh's series against its table [N/m] at the table's angles: ``table`` uniform over
    ``cycles`` mesh cycles (repeated to ``order`` cycles when shorter), the mesh's series k0 (1 +
    sum a_h cos(h Theta) + b_h sin(h Theta)) in the forcing angle Theta = 2 pi c / ``order``
    (``coefficients`` [a_1, b_1, ...], shifted by ``shift`` mesh cycles: K(c) = T(c - shift)),
    evaluated at c = shift + the table's cycles by one inverse FFT, clipped at 0 as the kernels
    clip it (a table with a gap, a missing tooth, rings below 0 about it)."""
    t = np.tile(np.asarray(table, dtype=float), order // cycles)
    n = t.size
    a, b = coefficients[0::2], coefficients[1::2]
    h = np.arange(1, a.size + 1)
    spectrum = np.zeros(n // 2 + 1, dtype=complex)
    spectrum[0] = mean * n
    turn = np.exp(1j * 2.0 * np.pi * h * shift / order)
    spectrum[1:a.size + 1] = 0.5 * n * mean * (a - 1j * b) * turn
    return np.maximum(np.fft.irfft(spectrum, n), 0.0) - t
