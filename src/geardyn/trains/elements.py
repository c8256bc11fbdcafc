"""The elements a gear train is described from: bodies, shafts, bearings and meshes.

Each element is a frozen dataclass with a ``name``; its inputs are SI numbers or unit strings
(:func:`geardyn.units.si_value`; damping coefficients plain SI numbers), validated and stored
as SI floats when the element is made.
An error is a :class:`~geardyn.ParameterError` naming the element and the field
(``"stage1.stiffness"``). Bodies are joined by name; :data:`GROUND` is the fixed frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from geardyn.errors import ParameterError
from geardyn.gears.geometry import GearMesh, SpurGear
from geardyn.gears.helical import HelicalGear, HelicalMesh
from geardyn.units import si_value

#: The name of the fixed frame: a shaft or bearing whose other end is ``GROUND`` is held by it.
GROUND = "ground"

#: How a mesh's mean stiffness may be obtained besides a number [N/m].
STIFFNESS_METHODS = ("iso", "potential_energy")


def _name(kind: str, name: object) -> str:
    if not isinstance(name, str) or not name.strip():
        raise ParameterError(f"{kind}.name", name, "must be a non-empty string")
    if name == GROUND:
        raise ParameterError(f"{name}.name", name, f"{GROUND!r} is the fixed frame's name")
    return name


def _set(obj: object, attr: str, value: object) -> None:
    object.__setattr__(obj, attr, value)


def _si(obj: Any, attr: str, kind: str, minimum: float | None = 0.0, strict: bool = False,
        allow_inf: bool = False) -> None:
    """Store ``obj.<attr>`` as an SI float; errors name ``<obj.name>.<attr>``."""
    value = getattr(obj, attr)
    field = f"{obj.name}.{attr}"
    if allow_inf and (value == math.inf or value == "inf"):
        _set(obj, attr, math.inf)
        return
    _set(obj, attr, si_value(field, value, kind, minimum, strict))


def _body_ref(obj: Any, attr: str, ground: bool = False) -> None:
    value = getattr(obj, attr)
    if not isinstance(value, str) or not value:
        raise ParameterError(f"{obj.name}.{attr}", value, "must name a body")
    if value == GROUND and not ground:
        raise ParameterError(f"{obj.name}.{attr}", value, "must name a body, not the ground")


@dataclass(frozen=True)
class Inertia:
    """A rigid body that turns about its axis: rotational inertia ``inertia`` [kg m^2] and,
    for lateral (x, y) degrees of freedom on a flexible bearing, its ``mass`` [kg] (None: no
    lateral motion of its own)."""

    name: str
    inertia: Any
    mass: Any = None

    def __post_init__(self) -> None:
        _name(type(self).__name__, self.name)
        _si(self, "inertia", "inertia", strict=True)
        if self.mass is not None:
            _si(self, "mass", "mass", strict=True)

    @property
    def teeth(self) -> int | None:
        """Tooth count (None: not a gear)."""
        return None

    @property
    def radius(self) -> float | None:
        """Base radius [m] (None: not a gear)."""
        return None


@dataclass(frozen=True)
class Gear(Inertia):
    """A gear body: an :class:`Inertia` with a base radius [m] and tooth count, or with a
    :class:`~geardyn.gears.SpurGear` or :class:`~geardyn.gears.HelicalGear` ``geometry`` that
    gives both (a helical gear: its transverse base radius) and lets a mesh take its stiffness
    from ISO 6336-1 or the potential-energy method. ``teeth`` is needed only for the mesh
    orders of a Campbell diagram."""

    base_radius: Any = None
    geometry: SpurGear | HelicalGear | None = None
    n_teeth: int | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        g = self.geometry
        if g is not None:
            if not isinstance(g, SpurGear | HelicalGear):
                raise ParameterError(f"{self.name}.geometry", g,
                                     "must be a geardyn.gears.SpurGear or HelicalGear")
            spur = g.transverse if isinstance(g, HelicalGear) else g
            for attr, value in (("base_radius", spur.base_radius), ("n_teeth", g.teeth)):
                given = getattr(self, attr)
                if given is not None and not math.isclose(float(given), value, rel_tol=1e-9):
                    raise ParameterError(f"{self.name}.{attr}", given,
                                         f"differs from the geometry's {value:.6g}")
            _set(self, "base_radius", spur.base_radius)
            _set(self, "n_teeth", g.teeth)
        if self.base_radius is None:
            raise ParameterError(f"{self.name}.base_radius", None,
                                 "a gear needs a base radius or a geometry")
        _si(self, "base_radius", "length", strict=True)
        z = self.n_teeth
        if z is not None and (isinstance(z, bool) or not isinstance(z, int) or z < 1):
            raise ParameterError(f"{self.name}.n_teeth", z, "must be a whole number >= 1")

    @property
    def teeth(self) -> int | None:
        """Tooth count (None: not given)."""
        return self.n_teeth

    @property
    def helical(self) -> bool:
        """Whether the geometry is a helical gear."""
        return isinstance(self.geometry, HelicalGear)

    @property
    def radius(self) -> float | None:
        """Base radius [m]."""
        return self.base_radius


@dataclass(frozen=True)
class Shaft:
    """A torsional spring between bodies ``a`` and ``b`` (``b`` may be :data:`GROUND`):
    ``stiffness`` [N m/rad] and ``damping`` [N m s/rad] on the twist theta_a - theta_b.
    ``math.inf`` (or ``"inf"``): a rigid joint, the two bodies turn as one (the two gears of a
    compound planet); it has no damping. A coupling is a shaft: ``backlash`` [rad] its
    torsional play (a spline's, a gear coupling's), in the nonlinear model
    (:class:`~geardyn.trains.TrainModel`) a dead zone of that half-width on the twist; the
    linear model ignores it."""

    name: str
    a: str
    b: str
    stiffness: Any
    damping: Any = 0.0
    backlash: Any = 0.0

    def __post_init__(self) -> None:
        _name("Shaft", self.name)
        _body_ref(self, "a")
        _body_ref(self, "b", ground=True)
        if self.a == self.b:
            raise ParameterError(f"{self.name}.b", self.b, "a shaft joins two different bodies")
        _si(self, "stiffness", "torque", strict=True, allow_inf=True)  # N m/rad
        _si(self, "damping", "dimensionless")  # N m s/rad, a number
        if self.rigid and self.damping != 0.0:
            raise ParameterError(f"{self.name}.damping", self.damping,
                                 "a rigid shaft (infinite stiffness) has no damping")
        _si(self, "backlash", "angle")
        if self.rigid and self.backlash > 0.0:
            raise ParameterError(f"{self.name}.backlash", self.backlash, "a rigid joint has no "
                                 "play: give the shaft a finite stiffness")

    @property
    def rigid(self) -> bool:
        """Whether the shaft is a rigid joint (infinite stiffness)."""
        return math.isinf(self.stiffness)


@dataclass(frozen=True)
class Bearing:
    """The bearing of ``body`` on ``host`` (:data:`GROUND`, or a carrier body): isotropic
    radial ``stiffness`` [N/m] (``math.inf``: rigid) and ``damping`` [N s/m].

    On a carrier, the bearing's pin sits at ``radius`` [m] and ``angle`` [rad] from the
    carrier's axis, so the carrier's rotation moves it tangentially by radius * theta_carrier.
    ``clearance`` [m]: the radial play c of a flexible bearing, in the nonlinear model
    (:class:`~geardyn.trains.TrainModel`) a circular dead zone on the journal's deflection
    (x, y) relative to its host: no force for r = sqrt(x^2 + y^2) <= c, k (1 - c / r) (x, y)
    beyond (the journal touches at radius c in every direction); ``damping`` acts on the
    deflection rate at all times, inside the clearance too. The linear model ignores it
    (bearing in contact). A finite stiffness gives ``body`` lateral
    degrees of freedom (x, y), which need its mass; a rigid bearing carries the body with the
    host and has no clearance.
    """

    name: str
    body: str
    stiffness: Any
    host: str = GROUND
    damping: Any = 0.0
    radius: Any = 0.0
    angle: Any = 0.0
    clearance: Any = 0.0

    def __post_init__(self) -> None:
        _name("Bearing", self.name)
        _body_ref(self, "body")
        _body_ref(self, "host", ground=True)
        if self.body == self.host:
            raise ParameterError(f"{self.name}.host", self.host, "a body cannot bear on itself")
        _si(self, "stiffness", "stiffness", strict=True, allow_inf=True)
        _si(self, "damping", "dimensionless")  # N s/m, a number
        _si(self, "radius", "length")
        _si(self, "angle", "angle", None)
        _si(self, "clearance", "length")
        if self.rigid and self.clearance > 0.0:
            raise ParameterError(f"{self.name}.clearance", self.clearance, "a rigid bearing has "
                                 "no play: give the bearing a finite stiffness")

    @property
    def rigid(self) -> bool:
        """Whether the bearing is rigid (infinite stiffness)."""
        return math.isinf(self.stiffness)


@dataclass(frozen=True)
class Mesh:
    """The mesh of gear ``a`` with gear ``b`` (``internal=True``: ``b`` is the ring).

    ``stiffness``: the mean mesh stiffness [N/m] along the line of action, or ``"iso"`` (ISO
    6336-1 method B, :func:`~geardyn.gears.iso6336_stiffness`) or ``"potential_energy"``
    (the mean of :func:`~geardyn.gears.potential_energy_stiffness`, or of
    :func:`~geardyn.gears.helical_stiffness`, over a mesh cycle; ``bore_radius`` [m] needed:
    one radius for both gears or the pair (a's bore, b's bore; on an internal mesh b's is the
    ring's outer rim radius), stored as the pair; :class:`~geardyn.trains.TrainModel` takes
    the waveform of both flanks from the same table, and tooth faults act through it), both
    from the two gears' geometries. A
    helical mesh's line of action is inclined by the base helix angle beta_b to the transverse
    plane and ``stiffness`` is along it (the normal stiffness k_n); the planar model sees k_n
    cos^2(beta_b) on the transverse deflection.
    ``helix_angle`` [rad] (None: from the geometries, else 0) gives beta of a mesh without
    geometry, beta_b = atan(tan(beta) cos(alpha)) with alpha its pressure angle.

    ``angle`` [rad] is the direction of the line from a's centre to b's centre;
    ``pressure_angle`` [rad] the operating (transverse) pressure angle (None: from the
    geometries, else 20 deg). ``centre_distance`` [m] (None: the zero-backlash one of the
    geometries) is checked against the geometries. The line of action is that of the flank on
    which ``a`` turning in the positive sense drives ``b``.

    Recorded for the nonlinear model, unused by the linear one: ``backlash`` [m] per flank
    (drive, coast), a number for both, and the transmission-error amplitude ``error`` [m].
    ``damping`` [N s/m] acts on the mesh deflection rate.
    """

    name: str
    a: str
    b: str
    stiffness: Any
    internal: bool = False
    angle: Any = 0.0
    pressure_angle: Any = None
    centre_distance: Any = None
    bore_radius: Any = None
    damping: Any = 0.0
    backlash: Any = 0.0
    error: Any = 0.0
    helix_angle: Any = None

    def __post_init__(self) -> None:
        _name("Mesh", self.name)
        _body_ref(self, "a")
        _body_ref(self, "b")
        if self.a == self.b:
            raise ParameterError(f"{self.name}.b", self.b, "a mesh joins two different gears")
        if not isinstance(self.internal, bool):
            raise ParameterError(f"{self.name}.internal", self.internal, "must be True or False")
        if isinstance(self.stiffness, str) and self.stiffness in STIFFNESS_METHODS:
            if self.stiffness == "potential_energy" and self.bore_radius is None:
                raise ParameterError(f"{self.name}.bore_radius", None,
                                     "the potential-energy stiffness needs the bore radius")
        else:
            _si(self, "stiffness", "stiffness", strict=True)
        _si(self, "angle", "angle", None)
        if self.pressure_angle is not None:
            _si(self, "pressure_angle", "angle", strict=True)
            if not self.pressure_angle < math.pi / 2:
                raise ParameterError(f"{self.name}.pressure_angle", self.pressure_angle,
                                     "must be below 90 deg")
        if self.centre_distance is not None:
            _si(self, "centre_distance", "length", strict=True)
        if self.bore_radius is not None:
            self._bores()
        if self.helix_angle is not None:
            _si(self, "helix_angle", "angle")
            if not self.helix_angle < math.pi / 2:
                raise ParameterError(f"{self.name}.helix_angle", self.helix_angle,
                                     "must be below 90 deg")
        _si(self, "damping", "dimensionless")  # N s/m, a number
        _si(self, "error", "length")
        self._backlash()

    def _bores(self) -> None:
        """``bore_radius`` as the pair (a's bore, b's bore or rim radius) [m]; errors name
        ``<mesh>.bore_radius`` and the gear."""
        value = self.bore_radius
        field = f"{self.name}.bore_radius"
        if isinstance(value, tuple | list):
            if len(value) != 2:
                raise ParameterError(field, value, f"one radius for both gears or two ({self.a}"
                                     f"'s bore, {self.b}'s {self._b_radius})")
            pair = tuple(value)
        else:
            pair = (value, value)
        out = []
        for gear, what, v in ((self.a, "bore", pair[0]), (self.b, self._b_radius, pair[1])):
            try:
                out.append(si_value(field, v, "length", 0.0, strict=True))
            except ParameterError as exc:
                raise ParameterError(field, v, f"{gear}'s {what}: {exc.reason}") from None
        _set(self, "bore_radius", tuple(out))

    @property
    def _b_radius(self) -> str:
        return "rim radius" if self.internal else "bore"

    def _backlash(self) -> None:
        value = self.backlash
        pair = tuple(value) if isinstance(value, tuple | list) else (value, value)
        if len(pair) != 2:
            raise ParameterError(f"{self.name}.backlash", value,
                                 "one value or two (drive flank, coast flank)")
        _set(self, "backlash", tuple(si_value(f"{self.name}.backlash", v, "length", 0.0)
                                     for v in pair))


def pair_geometry(mesh: Mesh, ga: Gear, gb: Gear) -> Any:
    """The :class:`~geardyn.gears.GearMesh` (or :class:`~geardyn.gears.HelicalMesh`) of two
    gears with geometry; its errors re-raised naming the mesh."""
    if ga.helical != gb.helical:
        spur = mesh.a if gb.helical else mesh.b
        raise ParameterError(f"{mesh.name}.{'a' if spur == mesh.a else 'b'}", spur,
                             f"is a spur gear and {mesh.b if spur == mesh.a else mesh.a} a"
                             " helical one: they cannot mesh")
    if ga.helical and mesh.internal:
        raise ParameterError(f"{mesh.name}.internal", True,
                             "an internal helical mesh is not covered")
    try:
        if ga.helical:
            return HelicalMesh(pinion=ga.geometry, wheel=gb.geometry,
                               centre_distance=mesh.centre_distance)
        return GearMesh(pinion=ga.geometry, wheel=gb.geometry,
                        centre_distance=mesh.centre_distance, internal=mesh.internal)
    except ParameterError as exc:
        raise ParameterError(f"{mesh.name}.{exc.field}", exc.value,
                             f"{exc.reason} (mesh of {mesh.a} with {mesh.b})") from None
