"""A gear train assembled from its elements, and its linear model at mean mesh stiffness.

Coordinates. Every body has a rotation theta [rad] (positive counter-clockwise) and a centre
displacement x, y [m] in the fixed frame. The model keeps theta of every body that is not fixed
(bodies joined by rigid shafts share one, the first one's; joined rigidly to the ground or a
fixed body, none), and x, y of a body on a flexible bearing (it then needs a mass); a body on a
rigid bearing on a carrier is carried by it (its centre moves with the carrier's pin), any other
body's centre is held. ``T`` maps the model's coordinates q to the full ones: full = T q.

Elements act through deflection rows w (full coordinates), each a spring k w w^T:

- shaft: theta_a - theta_b;
- bearing of body p on host h (pin at radius R, angle psi on h): x_p - x_h + R sin(psi) theta_h
  and y_p - y_h - R cos(psi) theta_h (the host's terms absent on the ground);
- mesh of a with b (Lin & Parker 1999; Kahraman 1994): delta = cos(beta_b) [s . (c_a - c_b)
  + r_a theta_a + sigma r_b theta_b], with c the centres, r the (transverse) base radii, sigma
  = +1 external, -1 internal (b the ring), s the unit vector of the transverse line of action:
  at angle phi + 90 deg - alpha of an external mesh, phi - 90 deg + alpha of an internal one
  (phi the direction from a's centre to b's, alpha the pressure angle), and beta_b the base
  helix angle (0 for spur gears): the deflection along a helical mesh's line of action, which
  is inclined by beta_b to the transverse plane, from the transverse motion. The axial part
  of that deflection is not modelled (no axial coordinates: the bodies are held axially).

M = T^T diag(I, m, m) T, K = T^T (sum k w w^T) T, C = T^T (sum c w w^T) T + a M + b K.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn.errors import ParameterError
from geardyn.models.modal import frequency_groups
from geardyn.trains.elements import (
    GROUND,
    Bearing,
    Gear,
    Inertia,
    Mesh,
    Shaft,
    pair_geometry,
)
from geardyn.trains.faults import place_train_faults
from geardyn.units import si_value

#: Relative size (to the largest eigenvalue) below which an eigenvalue is a rigid-body mode.
RIGID_BODY_RTOL = 1e-12
#: Share of a mode's kinetic energy below which a part of the train counts as still (mode
#: types).
MODE_TYPE_TOL = 1e-6


@dataclass(frozen=True)
class MeshData:
    """A mesh as the linear model uses it: mean ``stiffness`` [N/m] along the line of action,
    operating transverse ``pressure_angle`` [rad], base radii [m], the method the stiffness
    came from and the ``base_helix_angle`` [rad] (0: spur); with the potential-energy method
    its ``table`` (the Dataset of :func:`~geardyn.gears.potential_energy_stiffness`, or of
    :func:`~geardyn.gears.helical_stiffness`, over one mesh cycle: drive and coast flank along
    the transverse line of action), else None."""

    stiffness: float
    pressure_angle: float
    radius_a: float
    radius_b: float
    method: str
    base_helix_angle: float = 0.0
    table: Any = None


def _line_of_action(mesh: Mesh, alpha: float) -> tuple[float, float]:
    """Unit vector s of the mesh's line of action (module docstring)."""
    phi = mesh.angle
    beta = phi - math.pi / 2 + alpha if mesh.internal else phi + math.pi / 2 - alpha
    return math.cos(beta), math.sin(beta)


def _mesh_stiffness(mesh: Mesh, gear_mesh: Any, beta_b: float) -> tuple[float, str, Any]:
    """The mesh stiffness along the line of action [N/m], its method and the potential-energy
    table (None for the other methods). ISO 6336-1 and the sliced potential-energy method give
    it along the transverse line of action: divided by cos^2(beta_b) (a helical mesh) for the
    normal one."""
    if not isinstance(mesh.stiffness, str):
        return float(mesh.stiffness), "given", None
    if gear_mesh is None:
        raise ParameterError(f"{mesh.name}.stiffness", mesh.stiffness,
                             f"needs the geometry of both gears ({mesh.a}, {mesh.b})")
    normal = 1.0 / math.cos(beta_b) ** 2
    if mesh.stiffness == "iso":
        from geardyn.gears.iso6336 import iso6336_stiffness

        return iso6336_stiffness(gear_mesh).mesh_stiffness * normal, "iso", None
    from geardyn.gears.helical import HelicalMesh, helical_stiffness
    from geardyn.gears.potential_energy import potential_energy_stiffness

    method = helical_stiffness if isinstance(gear_mesh, HelicalMesh) else (
        potential_energy_stiffness)
    try:
        ds = method(gear_mesh, bore_radius=mesh.bore_radius)
    except ParameterError as exc:
        raise _gear_error(mesh, exc) from None
    return float(ds["mesh_stiffness"].mean()) * normal, "potential_energy", ds


def _gear_error(mesh: Mesh, exc: ParameterError) -> ParameterError:
    """``exc`` of a pair's table (its field ``pinion.<x>`` or ``wheel.<x>``) naming
    ``<mesh>.<x>`` and the gear (a the pinion, b the wheel); other errors as they are."""
    role, _, rest = exc.field.partition(".")
    if role not in ("pinion", "wheel") or not rest:
        return exc
    gear = mesh.a if role == "pinion" else mesh.b
    hint = ""
    if rest == "bore_radius" and mesh.bore_radius[0] == mesh.bore_radius[1]:
        hint = (f" (one bore_radius is both gears'; give two: {mesh.a}'s bore, {mesh.b}'s "
                f"{'rim radius' if mesh.internal else 'bore'})")
    what = rest
    if rest == "bore_radius":
        what = "rim radius" if role == "wheel" and mesh.internal else "bore"
    return ParameterError(f"{mesh.name}.{rest}", exc.value,
                          f"{gear}'s {what}: {exc.reason}{hint}")


def resolve_mesh(mesh: Mesh, ga: Gear, gb: Gear) -> MeshData:
    """Stiffness, pressure angle and radii of ``mesh`` between gears ``ga`` and ``gb``, checked
    against their geometries (modules, centre distance, pressure angle)."""
    sigma = -1.0 if mesh.internal else 1.0
    gear_mesh = None
    if ga.geometry is not None and gb.geometry is not None:
        gear_mesh = pair_geometry(mesh, ga, gb)
    elif mesh.internal and gb.geometry is not None and not gb.geometry.internal:
        raise ParameterError(f"{mesh.name}.internal", True, f"{mesh.b} is not an internal gear")
    alpha = mesh.pressure_angle
    if gear_mesh is not None:
        alpha_w = getattr(gear_mesh, "transverse", gear_mesh).operating_pressure_angle
        if alpha is not None and not math.isclose(alpha, alpha_w, rel_tol=1e-6):
            raise ParameterError(f"{mesh.name}.pressure_angle", alpha,
                                 f"differs from the geometries' operating {alpha_w:.6g} rad")
        alpha = alpha_w
    elif alpha is None:
        alpha = math.radians(20.0)
    if gear_mesh is None and mesh.centre_distance is not None:
        a0 = (gb.base_radius + sigma * ga.base_radius) / math.cos(alpha)
        if not math.isclose(mesh.centre_distance, a0, rel_tol=1e-6):
            raise ParameterError(f"{mesh.name}.centre_distance", mesh.centre_distance,
                                 f"inconsistent with the base radii and pressure angle"
                                 f" ({a0:.6g} m)")
    beta_b = _base_helix_angle(mesh, gear_mesh, alpha)
    k, method, table = _mesh_stiffness(mesh, gear_mesh, beta_b)
    return MeshData(k, alpha, ga.base_radius, gb.base_radius, method, beta_b, table)


def _base_helix_angle(mesh: Mesh, gear_mesh: Any, alpha: float) -> float:
    """beta_b [rad] of ``mesh``: the geometries' (a helical pair), checked against a given
    ``helix_angle``; else from ``helix_angle`` and the pressure angle; else 0."""
    beta = mesh.helix_angle
    if gear_mesh is not None:
        own = getattr(gear_mesh, "helix_angle", 0.0)
        if beta is not None and not math.isclose(beta, own, rel_tol=1e-9, abs_tol=1e-12):
            raise ParameterError(f"{mesh.name}.helix_angle", beta,
                                 f"differs from the geometries' {own:.6g} rad")
        return float(getattr(gear_mesh, "base_helix_angle", 0.0))
    if beta is None:
        return 0.0
    return math.atan(math.tan(beta) * math.cos(alpha))


class GearTrain:
    """A gear train from its elements, validated once, with its linear model.

    Parameters
    ----------
    bodies
        :class:`Inertia` and :class:`Gear` bodies (names unique).
    shafts, bearings, meshes
        :class:`Shaft`, :class:`Bearing` and :class:`Mesh` elements joining them by name.
    fixed
        Bodies held fixed (all their coordinates removed), e.g. a ring gear.
    driven
        The input body: speeds and mesh orders are relative to its speed.
    free
        Accept a free rigid-body mode (a drive train held by nothing): it is then listed in
        :meth:`modes` as such (frequency 0, ``rigid_body`` True). False (default): a train with
        one is refused.
    rayleigh
        (a [1/s], b [s]) of the Rayleigh damping a M + b K added to the elements' damping.
    faults
        Tooth faults (:class:`~geardyn.gears.RootCrack`, :class:`~geardyn.gears.Spall`,
        :class:`~geardyn.gears.Wear`, :class:`~geardyn.gears.BrokenTooth`), one or a sequence,
        all on one gear named by their ``gear`` (:mod:`geardyn.trains.faults`; its meshes need
        the potential-energy stiffness). They act in :class:`TrainModel`'s mesh stiffness over
        the faulty gear's revolution; the linear model here stays at the healthy mean
        stiffness. Kept as :attr:`faults` (a :class:`~geardyn.trains.faults.TrainFaults`, None
        without).
    """

    def __init__(self, bodies: Sequence[Inertia], shafts: Sequence[Shaft] = (),
                 bearings: Sequence[Bearing] = (), meshes: Sequence[Mesh] = (), *,
                 fixed: Sequence[str] = (), driven: str | None = None, free: bool = False,
                 rayleigh: tuple[float, float] = (0.0, 0.0), faults: Any = ()):
        body_list = _typed("bodies", bodies, Inertia)
        self.shafts = _typed("shafts", shafts, Shaft)
        self.bearings = _typed("bearings", bearings, Bearing)
        self.meshes = _typed("meshes", meshes, Mesh)
        _unique_names(body_list, self.shafts, self.bearings, self.meshes)
        self.bodies = {b.name: b for b in body_list}
        self.fixed = (fixed,) if isinstance(fixed, str) else tuple(fixed)
        self.driven = driven
        self.free = bool(free)
        if not isinstance(rayleigh, tuple | list) or len(rayleigh) != 2:
            raise ParameterError("rayleigh", rayleigh, "must be a pair (a, b)")
        self.rayleigh = tuple(si_value(f"rayleigh[{i}]", v, "dimensionless", 0.0)
                              for i, v in enumerate(rayleigh))
        self._check_references()
        self.mesh_data = {m.name: resolve_mesh(m, self.bodies[m.a], self.bodies[m.b])
                          for m in self.meshes}
        self._check_connected()
        self.faults = place_train_faults(self, faults)
        self._index = {name: i for i, name in enumerate(self.bodies)}
        self._turns_with = self._rigid_rotations()
        self._dofs, self._T = self._coordinates()
        self.rigid_body_modes = self._count_rigid_body_modes()

    # ------------------------------------------------------------------ validation
    def _body(self, field: str, name: str, ground: bool = False) -> None:
        if name == GROUND and ground:
            return
        if name not in self.bodies:
            raise ParameterError(field, name, "names no body of the train")

    def _check_references(self) -> None:
        for s in self.shafts:
            self._body(f"{s.name}.a", s.a)
            self._body(f"{s.name}.b", s.b, ground=True)
        for b in self.bearings:
            self._body(f"{b.name}.body", b.body)
            self._body(f"{b.name}.host", b.host, ground=True)
        for m in self.meshes:
            for end in ("a", "b"):
                name = getattr(m, end)
                self._body(f"{m.name}.{end}", name)
                if not isinstance(self.bodies[name], Gear):
                    raise ParameterError(f"{m.name}.{end}", name, "is not a Gear")
        for f in self.fixed:
            self._body("fixed", f)
        if self.driven is not None:
            self._body("driven", self.driven)
            if self.driven in self.fixed:
                raise ParameterError("driven", self.driven, "is held fixed")
        for name, body in self.bodies.items():
            rigid = [b for b in self.bearings if b.body == name and b.rigid]
            if len(rigid) > 1:
                raise ParameterError(f"{rigid[1].name}.stiffness", math.inf,
                                     f"{name} has two rigid bearings")
            flexible = any(b.body == name and not b.rigid for b in self.bearings)
            if flexible and not rigid and body.mass is None and name not in self.fixed:
                raise ParameterError(f"{name}.mass", None,
                                     "a body on a flexible bearing needs a mass")

    def _check_connected(self) -> None:
        parent = {name: name for name in [GROUND, *self.bodies]}

        def root(n: str) -> str:
            while parent[n] != n:
                n = parent[n]
            return n

        edges = ([(s.a, s.b) for s in self.shafts] + [(b.body, b.host) for b in self.bearings]
                 + [(m.a, m.b) for m in self.meshes] + [(f, GROUND) for f in self.fixed])
        touched = {n for e in edges for n in e}
        for name in self.bodies:
            if name not in touched:
                raise ParameterError(name, name, "is on no shaft, bearing or mesh and not fixed:"
                                     " it is not part of the train")
        for u, v in edges:
            parent[root(u)] = root(v)
        first = next(iter(self.bodies))
        for name in self.bodies:
            if root(name) != root(first):
                raise ParameterError(name, name, f"is connected neither to {first} nor to the"
                                     " ground: the train falls apart into separate pieces")

    # ------------------------------------------------------------------ coordinates
    def _rigid_rotations(self) -> dict[str, str | None]:
        """The body whose rotation each body shares through rigid shafts (the first of its
        group; None: held, by the ground or a fixed body)."""
        parent = {name: name for name in [GROUND, *self.bodies]}

        def root(n: str) -> str:
            while parent[n] != n:
                n = parent[n]
            return n

        for s in self.shafts:
            if s.rigid:
                parent[root(s.a)] = root(s.b)
        for f in self.fixed:
            parent[root(f)] = root(GROUND)
        first: dict[str, str] = {}
        for name in self.bodies:
            first.setdefault(root(name), name)
        held = root(GROUND)
        return {name: None if root(name) == held else first[root(name)]
                for name in self.bodies}

    def _coordinates(self) -> tuple[tuple[str, ...], np.ndarray]:
        names: list[str] = []
        for name in self.bodies:
            if name in self.fixed:
                continue
            if self._turns_with[name] == name:
                names.append(f"{name}.theta")
            if self._lateral(name):
                names += [f"{name}.x", f"{name}.y"]
        col = {n: j for j, n in enumerate(names)}
        T = np.zeros((3 * len(self.bodies), len(names)))
        for name in self.bodies:
            self._fill(T, name, col, ())
        return tuple(names), T

    def _lateral(self, name: str) -> bool:
        """Whether ``name`` has lateral coordinates of its own: a flexible bearing, no rigid
        one."""
        mine = [b for b in self.bearings if b.body == name]
        return bool(mine) and not any(b.rigid for b in mine)

    def _fill(self, T: np.ndarray, name: str, col: dict[str, int], chain: tuple[str, ...]) -> None:
        """Rows of body ``name`` in T (a rigidly carried body after its host)."""
        i = 3 * self._index[name]
        if name in self.fixed or T[i:i + 3].any():
            return
        turns = self._turns_with[name]
        if turns is not None:
            T[i, col[f"{turns}.theta"]] = 1.0
        if self._lateral(name):
            T[i + 1, col[f"{name}.x"]] = 1.0
            T[i + 2, col[f"{name}.y"]] = 1.0
            return
        rigid = [b for b in self.bearings if b.body == name and b.rigid and b.host != GROUND]
        if not rigid:
            return  # centre held
        b = rigid[0]
        if b.host in chain:
            raise ParameterError(f"{b.name}.host", b.host, "rigid bearings carry each other in a"
                                 " loop")
        self._fill(T, b.host, col, (*chain, name))
        h = 3 * self._index[b.host]
        T[i + 1] = T[h + 1] - b.radius * math.sin(b.angle) * T[h]
        T[i + 2] = T[h + 2] + b.radius * math.cos(b.angle) * T[h]

    def _unit(self, body: str, k: int) -> np.ndarray:
        e = np.zeros(3 * len(self.bodies))
        if body != GROUND:
            e[3 * self._index[body] + k] = 1.0
        return e

    def _bearing_rows(self, b: Bearing) -> np.ndarray:
        th, xh, yh = (self._unit(b.host, k) for k in range(3))
        rx = self._unit(b.body, 1) - xh + b.radius * math.sin(b.angle) * th
        ry = self._unit(b.body, 2) - yh - b.radius * math.cos(b.angle) * th
        return np.array([rx, ry])

    def _mesh_row(self, m: Mesh) -> np.ndarray:
        d = self.mesh_data[m.name]
        sx, sy = _line_of_action(m, d.pressure_angle)
        sigma = -1.0 if m.internal else 1.0
        u = self._unit
        return math.cos(d.base_helix_angle) * (
            sx * (u(m.a, 1) - u(m.b, 1)) + sy * (u(m.a, 2) - u(m.b, 2))
            + d.radius_a * u(m.a, 0) + sigma * d.radius_b * u(m.b, 0))[None, :]

    def elements(self) -> list[tuple[str, str, np.ndarray, float, float]]:
        """(kind, name, deflection rows in the model's coordinates, stiffness, damping) of every
        flexible element: meshes [N/m], shafts [N m/rad], flexible bearings [N/m]."""
        out = []
        for m in self.meshes:
            out.append(("mesh", m.name, self._mesh_row(m) @ self._T,
                        self.mesh_data[m.name].stiffness, float(m.damping)))
        for s in self.shafts:
            if s.rigid:
                continue
            row = (self._unit(s.a, 0) - self._unit(s.b, 0))[None, :]
            out.append(("shaft", s.name, row @ self._T, s.stiffness, s.damping))
        for b in self.bearings:
            if not b.rigid:
                out.append(("bearing", b.name, self._bearing_rows(b) @ self._T, b.stiffness,
                            b.damping))
        return out

    # ------------------------------------------------------------------ matrices
    def dof_names(self) -> tuple[str, ...]:
        """The model's coordinates: ``<body>.theta`` [rad], ``<body>.x``, ``<body>.y`` [m]."""
        return self._dofs

    def mass_matrix(self) -> np.ndarray:
        """M [kg m^2 on rotations, kg on translations] in the model's coordinates."""
        d = []
        for body in self.bodies.values():
            m = 0.0 if body.mass is None else body.mass
            d += [body.inertia, m, m]
        return self._T.T @ np.diag(d) @ self._T

    def stiffness_matrix(self) -> np.ndarray:
        """K at mean mesh stiffness (no backlash) in the model's coordinates."""
        n = len(self._dofs)
        K = np.zeros((n, n))
        for _, _, W, k, _ in self.elements():
            K += k * W.T @ W
        return K

    def damping_matrix(self) -> np.ndarray:
        """C: the elements' viscous damping plus the Rayleigh part a M + b K."""
        n = len(self._dofs)
        C = np.zeros((n, n))
        for _, _, W, _, c in self.elements():
            C += c * W.T @ W
        a, b = self.rayleigh
        return C + a * self.mass_matrix() + b * self.stiffness_matrix()

    def _eig(self) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues [(rad/s)^2] ascending (rigid-body modes exactly 0) and mass-normalised
        shapes of K phi = lambda M phi."""
        from scipy.linalg import eigh

        lam, phi = eigh(self.stiffness_matrix(), self.mass_matrix())
        big = float(np.max(np.abs(lam))) if lam.size else 0.0
        return np.where(lam > RIGID_BODY_RTOL * big, lam, 0.0), phi

    def _count_rigid_body_modes(self) -> int:
        lam, phi = self._eig()
        n = int(np.sum(lam == 0.0))
        if n and not self.free:
            moving = sorted({self._dofs[j] for j in np.argmax(np.abs(phi[:, :n]), axis=0)})
            raise ParameterError("fixed", self.fixed,
                                 f"the train has {n} free rigid-body mode(s) (moving"
                                 f" {', '.join(moving)}): hold a member, add a shaft to ground,"
                                 " or pass free=True to keep it")
        return n

    def natural_frequencies(self) -> np.ndarray:
        """Natural frequencies [Hz], ascending; a rigid-body mode gives 0."""
        return np.sqrt(self._eig()[0]) / (2.0 * math.pi)

    def modes(self) -> Any:
        """Natural frequencies, shapes and strain-energy shares (xarray Dataset over ``mode``).

        Variables: ``frequency`` [Hz]; ``multiplicity`` (of the frequency, within
        :data:`~geardyn.trains.MULTIPLICITY_RTOL`); ``rigid_body`` (a zero mode of a free
        train);
        ``shape`` (mode, dof), mass-normalised [kg^-1/2 on translations, (kg m^2)^-1/2 on
        rotations]; ``energy_share`` (mode, element): the part of the mode's strain energy
        phi^T K phi / 2 held by each mesh, shaft and flexible bearing (sums to 1 over the
        elements; NaN for a rigid-body mode). Coordinate ``element_kind``: mesh, shaft, bearing.
        A train with planets (bodies on bearings on a carrier) has ``type``, the classes of Lin
        & Parker (1999) (:meth:`mode_type`).
        """
        import xarray as xr

        lam, phi = self._eig()
        elements = self.elements()
        energy = np.array([[0.5 * k * float(np.sum((W @ phi[:, j]) ** 2))
                            for _, _, W, k, _ in elements] for j in range(lam.size)])
        total = energy.sum(axis=1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(lam[:, None] > 0.0, energy / total, np.nan)
        f = np.sqrt(lam) / (2.0 * math.pi)
        mult = np.zeros(f.size, int)
        kind = np.empty(f.size, object)
        for g in frequency_groups(f):
            mult[g] = len(g)
            kind[g] = self.mode_type(phi[:, g]) if self._planets() else ""
        extra = {"type": ("mode", kind.astype(str))} if self._planets() else {}
        return xr.Dataset(
            {"frequency": ("mode", f, {"units": "Hz"}),
             "multiplicity": ("mode", mult),
             "rigid_body": ("mode", lam == 0.0), **extra,
             "shape": (("mode", "dof"), phi.T),
             "energy_share": (("mode", "element"), share, {"units": "1"})},
            coords={"mode": np.arange(lam.size), "dof": list(self._dofs),
                    "element": [e[1] for e in elements],
                    "element_kind": ("element", [e[0] for e in elements])},
            attrs={"model": "GearTrain", "rigid_body_modes": self.rigid_body_modes})

    def _planets(self) -> dict[str, Bearing]:
        """The planets: bodies on a bearing on a carrier, with their pin on the carrier (a
        body carried by a planet, the second gear of a compound planet, with that planet's
        pin)."""
        return {b.body: self._pin(b.body) for b in self.bearings if b.host != GROUND}

    def _pin(self, body: str) -> Bearing:
        """The bearing on a carrier that carries ``body``, up the chain of bearings on
        bodies (a planet's own pin; a compound planet's second gear: the planet's pin)."""
        pin = next(b for b in self.bearings if b.body == body and b.host != GROUND)
        for _ in range(len(self.bearings)):
            up = next((b for b in self.bearings if b.body == pin.host and b.host != GROUND),
                      None)
            if up is None:
                break
            pin = up
        return pin

    def mode_type(self, shapes: np.ndarray, tol: float = MODE_TYPE_TOL) -> str:
        """Class of the eigenspace spanned by ``shapes`` (model dofs x k), as Lin & Parker
        (1999): ``"planet"`` (only the planets move), ``"rotational"`` (no centre of a body other
        than a planet moves and every planet of a carrier moves alike in that carrier's frame),
        ``"translational"`` (no body other than a planet turns), else ``"mixed"``. Judged by
        the kinetic energy of each part, summed over the space."""
        full = self._T @ shapes
        d = np.concatenate([[b.inertia, b.mass or 0.0, b.mass or 0.0]
                            for b in self.bodies.values()])
        weighted = np.sqrt(d)[:, None] * full  # coordinates scaled to sqrt(kinetic energy)
        e = np.sum(np.abs(weighted) ** 2, axis=1)
        planets = self._planets()
        central = np.array([name not in planets for name in self.bodies for _ in range(3)])
        rot = central & np.tile([True, False, False], len(self.bodies))
        total = e.sum()
        if e[central].sum() <= tol * total:
            return "planet"
        if e[central & ~rot].sum() <= tol * total and self._planets_alike(weighted, tol):
            return "rotational"
        if e[rot].sum() <= tol * total:
            return "translational"
        return "mixed"

    def _planets_alike(self, weighted: np.ndarray, tol: float) -> bool:
        """Every planet of each carrier moves alike in the carrier's frame (its radial,
        tangential and rotational coordinates) in every shape: the planets alike in inertia,
        mass and base radius (the copies of one planet; a compound planet's two gears are two
        such sets) are compared."""
        scale = max(float(np.max(np.abs(weighted))), 1e-300)
        by_carrier: dict[tuple, list[np.ndarray]] = {}
        for name, b in self._planets().items():
            i = 3 * self._index[name]
            c, s = math.cos(b.angle), math.sin(b.angle)
            x, y = weighted[i + 1], weighted[i + 2]
            body = self.bodies[name]
            key = (b.host, body.inertia, body.mass, body.radius)
            by_carrier.setdefault(key, []).append(
                np.array([weighted[i], c * x + s * y, -s * x + c * y]))
        return all(np.max(np.abs(p - group[0])) <= math.sqrt(tol) * scale
                   for group in by_carrier.values() for p in group[1:])

    # ------------------------------------------------------------------ kinematics
    def speed_ratios(self) -> dict[str, float]:
        """Speed of every body over the driven body's, with the meshes, shafts between bodies
        and bearings rigid (rigid kinematics; shafts to ground ignored)."""
        if self.driven is None:
            raise ParameterError("driven", None, "speed ratios need the driven (input) body")
        rows = [self._mesh_row(m)[0] for m in self.meshes]
        rows += [self._unit(s.a, 0) - self._unit(s.b, 0) for s in self.shafts
                 if s.b != GROUND or s.rigid]
        for b in self.bearings:
            rows += list(self._bearing_rows(b))
        for name in self.bodies:
            if not any(b.body == name for b in self.bearings):
                rows += [self._unit(name, 1), self._unit(name, 2)]
            if name in self.fixed:
                rows += [self._unit(name, k) for k in range(3)]
        A = np.array(rows)
        _, sv, vt = np.linalg.svd(A)
        sv = np.concatenate([sv, np.zeros(A.shape[1] - sv.size)])
        free = np.flatnonzero(sv <= 1e-9 * max(float(sv[0]), 1e-300))
        if free.size != 1:
            raise ParameterError("driven", self.driven,
                                 f"the rigid train has {free.size} kinematic degrees of freedom,"
                                 " not 1: its speeds do not follow from the input")
        v = vt[free[0]]
        v = v / v[3 * self._index[self.driven]]
        return {name: float(v[3 * i]) for name, i in self._index.items()}

    def mesh_orders(self) -> dict[str, float]:
        """Mesh frequency over the input speed of every mesh: z abs(ratio - ratio_arm) of gear a
        (or b, where a has no tooth count), the arm being the carrier on which one of the two
        gears' bearings sits (a planet's carrier; 0 where both bear on the ground)."""
        ratios = self.speed_ratios()
        out = {}
        for m in self.meshes:
            gear = next((g for g in (m.a, m.b) if self.bodies[g].teeth is not None), None)
            if gear is None:
                raise ParameterError(f"{m.a}.n_teeth", None,
                                     f"the order of mesh {m.name} needs a tooth count")
            arm = self.mesh_frame_ratio(m, ratios)
            out[m.name] = self.bodies[gear].teeth * abs(ratios[gear] - arm)
        return out

    def mesh_frame_ratio(self, mesh: Mesh, ratios: dict[str, float]) -> float:
        """Speed ratio of the frame ``mesh`` turns in: the carrier on which one of its gears'
        bearings sits (a planet's carrier), 0 where both bear on the ground."""
        hosts = [self._pin(b.body).host for b in self.bearings
                 if b.body in (mesh.a, mesh.b) and b.host != GROUND]
        return ratios[hosts[0]] if hosts else 0.0

    def campbell(self, speeds: Any, harmonics: int = 3) -> Any:
        """Campbell (interference) data over input speeds [rpm] (xarray Dataset).

        Excitations are every mesh's order (:meth:`mesh_orders`) times harmonics 1 ..
        ``harmonics``. Variables: ``natural_frequency`` (mode) [Hz];
        ``excitation_frequency`` (excitation, speed) [Hz] = harmonic * order * rpm / 60;
        ``crossing_speed`` (excitation, mode) [rpm] = 60 f_n / (harmonic * order), NaN outside
        the speed range or for a rigid-body mode; ``crossing_frequency`` (excitation, mode)
        [Hz], f_n where it crosses, else NaN. Coordinates: ``speed`` [rpm],
        ``input_frequency`` (speed) [Hz], and per excitation its ``mesh``, ``harmonic``,
        ``order``.
        """
        import xarray as xr

        rpm = np.asarray(speeds, dtype=float).ravel()
        if rpm.size == 0 or not np.all(np.isfinite(rpm)) or np.any(rpm < 0.0):
            raise ParameterError("speeds", speeds, "must be finite speeds >= 0 [rpm]")
        if isinstance(harmonics, bool) or not isinstance(harmonics, int) or harmonics < 1:
            raise ParameterError("harmonics", harmonics, "must be a whole number >= 1")
        orders = self.mesh_orders()
        exc = [(name, h, h * o) for name, o in orders.items() for h in range(1, harmonics + 1)]
        eff = np.array([e[2] for e in exc])
        f_n = self.natural_frequencies()
        with np.errstate(divide="ignore", invalid="ignore"):
            cross = 60.0 * f_n[None, :] / eff[:, None]
        inside = (cross >= rpm.min()) & (cross <= rpm.max()) & (f_n[None, :] > 0.0)
        return xr.Dataset(
            {"natural_frequency": ("mode", f_n, {"units": "Hz"}),
             "excitation_frequency": (("excitation", "speed"), eff[:, None] * rpm / 60.0,
                                      {"units": "Hz"}),
             "crossing_speed": (("excitation", "mode"), np.where(inside, cross, np.nan),
                                {"units": "rpm"}),
             "crossing_frequency": (("excitation", "mode"),
                                    np.where(inside, f_n[None, :], np.nan), {"units": "Hz"})},
            coords={"speed": ("speed", rpm, {"units": "rpm"}),
                    "input_frequency": ("speed", rpm / 60.0, {"units": "Hz"}),
                    "mode": np.arange(f_n.size),
                    "mesh": ("excitation", [e[0] for e in exc]),
                    "harmonic": ("excitation", [e[1] for e in exc]),
                    "order": ("excitation", [orders[e[0]] for e in exc])},
            attrs={"model": "GearTrain", "driven": str(self.driven)})

    def __repr__(self) -> str:
        return (f"GearTrain({len(self.bodies)} bodies, {len(self.meshes)} meshes, "
                f"{len(self.shafts)} shafts, {len(self.bearings)} bearings, "
                f"{len(self._dofs)} dofs)")


def _typed(field: str, items: Sequence[Any], cls: type) -> list[Any]:
    out = list(items)
    for i, item in enumerate(out):
        if not isinstance(item, cls):
            raise ParameterError(f"{field}[{i}]", item, f"must be a {cls.__name__}")
    return out


def _unique_names(*groups: Sequence[Any]) -> None:
    seen: set[str] = set()
    for group in groups:
        for item in group:
            if item.name in seen:
                raise ParameterError(f"{item.name}.name", item.name, "is used twice")
            seen.add(item.name)
