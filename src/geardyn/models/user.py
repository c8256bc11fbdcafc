"""A user's own model: any numba-compiled right-hand side, through the same solvers and analyses.

The way to write one is the one form (:meth:`UserModel.from_one_form`, see
:mod:`geardyn.core.one_form`): the physics once, per lane, as tuple-valued functions that read
the coefficients by name; it runs on the same vectorised path as the built-in models and may
declare its meshes. The constructor's plain ``rhs(t, y, dydt, p)`` (writing dydt in place) is
the legacy form: it runs on the generic per-lane path, several times slower on a sweep (a
:class:`~geardyn.errors.SlowPathWarning` says so once; a sweep's ``kernel_path`` attribute
records it).

A one-form model declares its coefficients as a built-in does (``coefficients=``: a
:class:`~geardyn.core.coefficients.Coefficient` per parameter, with unit, meaning and range):
``model.coefficient_layout``, ``with_params`` (range checks naming the field), the explorer's
help and a sweep's axis attributes (``units``, ``long_name``) read them.

A one-form model with force meshes and static forces may declare the dynamic factor against
ISO 6336-1 K_v (``dynamic_factor=``: a :class:`DynamicFactorDeclaration`): then
:func:`~geardyn.dynamic_factor_sweep` takes it as it takes a built-in model built from geometry.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn.core.capabilities import Capabilities
from geardyn.core.coefficients import Coefficient, CoefficientBlock, CoefficientLayout
from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model, unique_rows
from geardyn.core.one_form import Derivations, OneForm, check_names, coefficient_type
from geardyn.errors import ParameterError
from geardyn.gears.iso6336_kv import KvMeshGroup

#: A mesh of :meth:`UserModel.from_one_form`: (name, drive event, back event) or (name, drive
#: event, back event, force observable), events and observables by name or index.
MeshSpec = tuple[str, str | int, str | int] | tuple[str, str | int, str | int, str | int]


@dataclass(frozen=True)
class DynamicFactorDeclaration:
    """What a one-form model declares for its dynamic factor against ISO 6336-1 K_v
    (:func:`~geardyn.dynamic_factor_sweep`, the ``dynamic_factor`` capability of
    :class:`~geardyn.core.capabilities.Capabilities`): how its coefficients follow the physical
    input speed and torque, the mesh groups K_v treats and the natural frequencies.

    ``speed``
        (coefficient, its value per rpm of input speed): the coefficient an input speed sets,
        in proportion (``("Omega", z1 * 2 pi / 60)`` for a model in seconds forced at the mesh
        frequency of a pinion of z1 teeth; over the time scale for a dimensionless one).
    ``torque``
        (coefficient, its value per N m of input torque): the coefficient an input torque sets,
        in proportion (``("torque", 1.0)``; a dimensionless mean load: its value per N m).
    ``groups``
        ``groups(p, torque)``: the mesh groups (:class:`~geardyn.gears.iso6336_kv.KvMeshGroup`:
        geometry, mesh indices, tangential force, reduced mass, mean stiffness) at an input
        torque [N m], from the coefficients ``p`` (named tuple); the first group's mesh is the
        reference mesh (its mesh frequency: gear 1's speed times its teeth).
    ``natural_frequencies``
        ``natural_frequencies(p)``: the linearised model's natural frequencies [Hz],
        ascending.
    ``time_scale``
        omega_0 [rad/s]: the model's time unit is 1 / omega_0 (1: the model runs in seconds).
    """

    speed: tuple[str, float]
    torque: tuple[str, float]
    groups: Callable[[Any, float], Sequence[KvMeshGroup]]
    natural_frequencies: Callable[[Any], Sequence[float]]
    time_scale: float = 1.0

    def __post_init__(self) -> None:
        for field, unit in (("speed", "rpm"), ("torque", "N m")):
            spec = getattr(self, field)
            if not (isinstance(spec, tuple) and len(spec) == 2 and isinstance(spec[0], str)):
                raise ParameterError(f"dynamic_factor.{field}", spec,
                                     f"give (coefficient name, its value per {unit})")
            _positive(f"dynamic_factor.{field}", spec[1])
        for field in ("groups", "natural_frequencies"):
            if not callable(getattr(self, field)):
                raise ParameterError(f"dynamic_factor.{field}", getattr(self, field),
                                     "must be a function of the coefficients")
        _positive("dynamic_factor.time_scale", self.time_scale)


def _positive(field: str, value: object) -> None:
    """ParameterError naming ``field`` unless ``value`` is a finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not (math.isfinite(value) and value > 0.0):
        raise ParameterError(field, value, "must be a finite number > 0")


class UserModel(Model):
    """A user's model. Write it in the one form with :meth:`from_one_form` (the fast path);
    the constructor wraps a compiled ``rhs(t, y, dydt, p)`` (writing dydt in place: the legacy
    form, on the generic, slower sweep path).

    Parameters
    ----------
    rhs
        ``numba.njit`` function ``rhs(t, y, dydt, p)``. Define it in an importable module (not
        ``__main__``) and its kernels are cached on disk; otherwise they are compiled once per
        process.
    n_states, params, state_names, param_names
        State size, coefficient vector (passed to ``rhs`` as ``p``) and names.
    period
        Forcing period of a periodically forced model, or None for an autonomous one. When
        ``param_names`` contains ``"Omega"`` the period is 2 pi / Omega instead and sweeps over
        ``"Omega"`` work.
    events
        Optional compiled ``events(t, y, g, p)``: switching functions whose zero crossings are
        kinks of ``rhs`` (e.g. ``x - b`` and ``x + b`` for a dead zone); the solvers locate them.
        ``events(t, y, g, p, s, c)`` takes the forcing phase too (sin and cos, as the solver
        gives it to the built-in models; see :mod:`geardyn.core.model`).
    n_events, observe, observable_names
        Number of switching functions; optional compiled ``observe(t, y, out, p)``.
    natural_frequency
        The fastest natural frequency of the linearised model (rad per time unit), which the
        default step resolves (``STEPS_PER_FASTEST_MODE`` steps per its period): a number, or a
        function of the coefficient vector ``p`` giving it (called once per distinct lane of a
        sweep, so that a sweep over a stiffness refines the step where it is stiffer). Default
        None: unknown, and the default step is ``MIN_STEPS_PER_PERIOD`` per forcing period,
        which is accurate only for modes slower than about Omega / 1.5; give it (or
        ``steps_per_period``) for a stiffer model.
    """

    #: A user model's capabilities follow what it declares (:meth:`from_one_form`).
    capabilities_per_instance = True

    def __init__(
        self,
        rhs: Callable,
        n_states: int,
        params: Sequence[float] | np.ndarray = (),
        period: float | None = None,
        state_names: Sequence[str] | None = None,
        param_names: Sequence[str] | None = None,
        events: Callable | None = None,
        n_events: int = 0,
        observe: Callable | None = None,
        observable_names: Sequence[str] = (),
        name: str = "UserModel",
        natural_frequency: float | Callable[[np.ndarray], float] | None = None,
    ):
        _check_compiled(rhs, events, observe)
        self._setup(n_states, params, period, state_names, param_names, name, natural_frequency)
        if events is not None and n_events < 1:
            raise ValueError("events given: set n_events to the number of switching functions")
        self.event_names = tuple(f"event{j}" for j in range(n_events if events else 0))
        self.observable_names = tuple(observable_names) if observe is not None else ()
        self.kernel = KernelSource(rhs, events, observe, plain=True)

    def _setup(self, n_states: int, params: Sequence[float] | np.ndarray, period: float | None,
               state_names: Sequence[str] | None, param_names: Sequence[str] | None,
               name: str, natural_frequency: float | Callable[[np.ndarray], float] | None
               ) -> None:
        """Sizes, names, coefficients and forcing, as the constructor documents them."""
        if n_states < 1:
            raise ValueError(f"n_states must be >= 1 (got {n_states})")
        p = np.asarray(params, dtype=float).ravel()
        if not np.all(np.isfinite(p)):
            raise ValueError("params must be finite")
        self.name = name
        self.state_names = tuple(state_names or (f"y{i}" for i in range(n_states)))
        if len(self.state_names) != n_states:
            raise ValueError(f"state_names has {len(self.state_names)} names for {n_states} states")
        names = list(param_names or (f"p{i}" for i in range(p.size)))
        if len(names) != p.size:
            raise ValueError(f"param_names has {len(names)} names for {p.size} parameters")
        if "Omega" in names:
            self.omega_index = names.index("Omega")
        elif period is not None:
            if not (period > 0 and math.isfinite(period)):
                raise ValueError(f"period must be > 0 (got {period!r})")
            names.append("Omega")  # hidden forcing frequency, after the user's parameters
            p = np.append(p, 2.0 * math.pi / period)
            self.omega_index = p.size - 1
        else:
            self.omega_index = None
        self.param_names = tuple(names)
        self.params = p
        if natural_frequency is not None and not callable(natural_frequency) and not (
                math.isfinite(natural_frequency) and natural_frequency > 0):
            raise ValueError(f"natural_frequency must be > 0 or a function of p "
                             f"(got {natural_frequency!r})")
        self.natural_frequency = natural_frequency
        self._declared: frozenset[str] = frozenset()
        self._static_forces: Callable[[Any], Sequence[float]] | None = None
        self._dynamic_factor: DynamicFactorDeclaration | None = None
        self._initial: Sequence[float] | Callable[[Any], Sequence[float]] | None = None

    @classmethod
    def from_one_form(
        cls,
        rhs: Callable,
        params: Mapping[str, float],
        states: Sequence[str],
        *,
        events: Callable | None = None,
        event_names: Sequence[str] = (),
        observe: Callable | None = None,
        observable_names: Sequence[str] = (),
        meshes: Sequence[MeshSpec] = (),
        static_forces: Callable[[Any], Sequence[float]] | None = None,
        dynamic_factor: DynamicFactorDeclaration | None = None,
        derived: Derivations | None = None,
        coefficients: Sequence[Coefficient] = (),
        initial_state: Sequence[float] | Callable[[Any], Sequence[float]] | None = None,
        period: float | None = None,
        name: str = "UserModel",
        natural_frequency: float | Callable[[np.ndarray], float] | None = None,
        kernel_path: str = "pointer",
    ) -> UserModel:
        """A model written in the one form (:mod:`geardyn.core.one_form`).

        Parameters
        ----------
        rhs
            ``numba.njit`` function ``rhs(t, y, p, s, c)`` returning dy/dt as a tuple: ``y``
            the state (a tuple), ``p`` the coefficients by name (``p.zeta``), ``s, c`` sin and
            cos of the forcing phase Omega (t - t0) (0 and 1 for an autonomous model). Define
            it in an importable module (not ``__main__``) and its kernels are cached on disk.
        params
            The coefficients by name, in order: ``{"Omega": 1.2, "zeta": 0.05, ...}``. With
            ``"Omega"`` among them the model is forced at that frequency (sweeps over
            ``"Omega"`` work); else ``period`` forces it (a hidden ``Omega`` is appended), or
            it is autonomous. Names are Python identifiers.
        states
            The state names (their number is the state size).
        events, event_names
            Optional ``events(t, y, p, s, c)`` returning the switching functions (zeros at the
            kinks of ``rhs``, e.g. ``x - b`` and ``x + b`` of a dead zone) and their names.
        observe, observable_names
            Optional ``observe(t, y, p, s, c)`` returning the observables, and their names.
        meshes
            Backlash meshes ``(name, drive event, back event)`` (``x - b`` and ``x + b``), by
            event name or index: contact regimes are reported for them. A fourth entry names
            the mesh's force observable; then every mesh names one, the observables are these
            forces in mesh order, and peak/RMS forces are reported (and the dynamic factor
            where ``static_forces`` is given).
        static_forces
            ``static_forces(p)``: the static force of each mesh from the coefficients (named
            tuple), for the dynamic factor.
        dynamic_factor
            The dynamic factor against ISO 6336-1 K_v
            (:class:`DynamicFactorDeclaration`: input speed and torque coefficients, mesh
            groups, natural frequencies, time scale), for
            :func:`~geardyn.dynamic_factor_sweep`; needs meshes that name their forces and
            ``static_forces``.
        derived
            Derived coefficients: ``{"cos_phi": ("phi", math.cos)}``; each is a coefficient
            (after ``params``) that follows its parameter (computed once per value with the
            Python function) and cannot be set itself. Use it for a cos/sin of a coefficient,
            so that ``rhs`` calls no libm routine per step and the sweep vectorises. (Short for
            ``Coefficient("cos_phi", kind="derived", derived_from=("phi",),
            derive=math.cos)`` in ``coefficients``.)
        coefficients
            Declarations (:class:`~geardyn.core.coefficients.Coefficient`) of some or all of
            the parameters, by name: unit, meaning and admissible range
            (``Coefficient("k", "N/m", "mesh stiffness", exclusive_minimum=0.0)``), as the
            built-in models declare theirs. ``params`` and ``with_params`` are checked against
            them (a ParameterError naming the field), and ``model.coefficient_layout``, a
            sweep's axis (``units``, ``long_name``) and the explorer read them. A derived
            coefficient with its function (``kind="derived"``, ``derived_from=(name,)``,
            ``derive=fn``) is placed after ``params``. An undeclared parameter is an input of
            unit "1".
        initial_state
            The default start state: a sequence, or a function of the coefficients (default
            zeros).
        period, name, natural_frequency
            As in the constructor.
        kernel_path
            ``"pointer"`` (default): the trajectory and sweep kernels and the variational
            Lyapunov lane blocks are compiled once for every model and call the model's
            functions, compiled alone as C callbacks, through their addresses (a model's own
            compile about a third of the inlined path's, ``bench/pointer_path.py``;
            :mod:`geardyn.solvers._pointer_kernels`); the other analyses
            (the difference tangent, the monodromy of periodic orbits and continuation, the
            run-up) compile with the model's functions inlined. ``"lane-form"``: every kernel
            compiled with the model's functions inlined (tens of seconds of compile per model;
            the results are bitwise the same). Recorded as a sweep's ``kernel_path``
            attribute.
        """
        if kernel_path not in ("lane-form", "pointer"):
            raise ParameterError("kernel_path", kernel_path, "'lane-form' or 'pointer'")
        _check_compiled(rhs, events, observe)
        entries = _declarations(params, derived or {}, coefficients)
        names = [c.name for c in entries]
        values = [float(v) for v in params.values()] + [0.0] * (len(entries) - len(params))
        check_names(tuple(names))
        event_names = tuple(event_names) if events is not None else ()
        if events is not None and not event_names:
            raise ValueError("events given: name the switching functions (event_names)")
        if observe is not None and not observable_names:
            raise ValueError("observe given: name the observables (observable_names)")
        model = cls.__new__(cls)
        model._setup(len(states), values, period, states, names, name, natural_frequency)
        if len(model.param_names) > len(entries):  # the hidden forcing frequency of ``period``
            entries.append(Coefficient("Omega", meaning="forcing frequency (2 pi / period)"))
        model.coefficient_layout = CoefficientLayout.of(CoefficientBlock(tuple(entries)),
                                                        model=name)
        model.coefficient_layout.validate({k: float(v) for k, v in params.items()})
        model.coefficient_layout.fill_derived(model.params)
        model.omega_is_entry = all(src != "Omega" for src, _ in model.derived.values())
        model._declared = frozenset(c.name for c in coefficients)
        model.event_names = event_names
        model.observable_names = tuple(observable_names) if observe is not None else ()
        model.meshes, forces = _meshes(meshes, model.event_names, model.observable_names)
        model._static_forces = static_forces
        model.capabilities = Capabilities(mesh_forces=forces)
        if dynamic_factor is not None:
            model._declare_dynamic_factor(dynamic_factor)
        model._initial = initial_state
        model.kernel = KernelSource(rhs, events, observe, one_form=OneForm(
            model.param_names, model.n_states, model.n_events, model.n_observables),
            path=None if kernel_path == "lane-form" else kernel_path)
        return model

    def coefficients(self, p: np.ndarray | None = None) -> Any:
        """The coefficients ``p`` (default the model's) as the one form's named tuple."""
        row = self.params if p is None else np.asarray(p, dtype=float)
        return coefficient_type(self.param_names)(*(float(v) for v in row))

    @property
    def derived(self) -> Derivations:
        """The derived coefficients declared with their function: name -> (the parameter it
        follows, the function), read from :attr:`coefficient_layout`."""
        return self.coefficient_layout.derivations()

    def param_attrs(self, name: str) -> dict[str, str]:
        """Attributes of a swept parameter's axis from its declaration (``coefficients`` of
        :meth:`from_one_form`): ``units`` and ``long_name`` (its meaning); empty for a
        parameter declared nowhere."""
        return super().param_attrs(name) if name in self._declared else {}

    def initial_state(self) -> np.ndarray:
        """The declared start state (``initial_state`` of :meth:`from_one_form`), else zeros."""
        init = self._initial
        if init is None:
            return np.zeros(self.n_states)
        y = np.asarray(init(self.coefficients()) if callable(init) else init, dtype=float)
        if y.shape != (self.n_states,):
            raise ValueError(f"initial_state has shape {y.shape}; the model has "
                             f"{self.n_states} states")
        return y

    def static_mesh_forces(self) -> np.ndarray | None:
        """The declared static mesh forces (``static_forces`` of :meth:`from_one_form`), or
        None."""
        if self._static_forces is None:
            return None
        f = np.asarray(self._static_forces(self.coefficients()), dtype=float).ravel()
        if f.size != len(self.meshes):
            raise ValueError(f"static_forces gives {f.size} values for {len(self.meshes)} "
                             f"meshes")
        return f

    # ------------------------------------------------------------------ ISO 6336-1 K_v
    def _declare_dynamic_factor(self, spec: DynamicFactorDeclaration) -> None:
        """Take ``spec`` (``dynamic_factor`` of :meth:`from_one_form`): ParameterError naming
        the field for a declaration the model cannot serve."""
        if not isinstance(spec, DynamicFactorDeclaration):
            raise ParameterError("dynamic_factor", spec, "a geardyn.models.user."
                                 "DynamicFactorDeclaration")
        if not self.capabilities.mesh_forces:
            raise ParameterError("meshes", self.meshes, "the dynamic factor needs meshes that "
                                 "name their force observables (name, drive, back, force)")
        if self._static_forces is None:
            raise ParameterError("static_forces", None, "the dynamic factor needs the static "
                                 "mesh forces (static_forces(p))")
        inputs = [n for n in self.param_names if n not in self.derived]
        for field in ("speed", "torque"):
            name = getattr(spec, field)[0]
            if name not in inputs:
                raise ParameterError(f"dynamic_factor.{field}", name,
                                     f"not an input coefficient ({', '.join(inputs)})")
        self._dynamic_factor = spec
        self.time_scale = float(spec.time_scale)
        self.capabilities = Capabilities(mesh_forces=True, dynamic_factor=True,
                                         natural_frequencies="Hz")

    def _kv(self) -> DynamicFactorDeclaration:
        """The declaration, or a ParameterError naming what is missing."""
        if self._dynamic_factor is None:
            raise ParameterError("dynamic_factor", None, f"{self.name} declares no dynamic "
                                 "factor: give UserModel.from_one_form(..., dynamic_factor="
                                 "DynamicFactorDeclaration(...))")
        return self._dynamic_factor

    @property
    def input_torque(self) -> float:
        """The input torque [N m]: the declared torque coefficient over its value per N m."""
        name, per = self._kv().torque
        return float(self.params[self.param_index(name)]) / per

    def at_input_torque(self, torque: float) -> UserModel:
        """The model at the input torque ``torque`` [N m]."""
        name, per = self._kv().torque
        return self.with_params(**{name: float(torque) * per})

    def kv_groups(self, torque: float) -> tuple[KvMeshGroup, ...]:
        """The declared mesh groups at the input torque ``torque`` [N m]."""
        groups = tuple(self._kv().groups(self.coefficients(), float(torque)))
        if not groups:
            raise ParameterError("dynamic_factor.groups", groups, "gives no mesh group")
        for g in groups:
            if not isinstance(g, KvMeshGroup):
                raise ParameterError("dynamic_factor.groups", g, "gives geardyn.gears."
                                     "iso6336_kv.KvMeshGroup entries")
            if not g.meshes or any(not 0 <= k < len(self.meshes) for k in g.meshes):
                raise ParameterError(f"dynamic_factor.groups[{g.name!r}].meshes", g.meshes,
                                     f"indices of the model's {len(self.meshes)} meshes")
        return groups

    def input_speed_sweep(self, rpm: np.ndarray) -> tuple[str, np.ndarray]:
        """The declared speed coefficient and its values at input speeds ``rpm``."""
        name, per = self._kv().speed
        return name, np.asarray(rpm, dtype=float) * per

    def mesh_frequency_per_input_speed(self) -> float:
        """The reference mesh's (the first group's) cycles per input revolution: gear 1's
        speed over the input speed times its teeth."""
        g = self.kv_groups(self.input_torque)[0]
        return float(g.speed_per_input) * g.pinion_teeth

    def natural_frequencies(self) -> np.ndarray:
        """The declared natural frequencies [Hz] at the model's coefficients."""
        return np.asarray(self._kv().natural_frequencies(self.coefficients()),
                          dtype=float).ravel()

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """``natural_frequency`` in every lane of ``P`` (NaN when it was not given; see the
        class docstring)."""
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        w = self.natural_frequency
        if w is None:
            return Model.fastest_natural_frequency(self, P)
        if not callable(w):
            return np.full(P.shape[0], float(w))
        rows, inverse = unique_rows(P)
        return np.array([float(w(r)) for r in rows])[inverse]


def _declarations(params: Mapping[str, float], derived: Derivations,
                  coefficients: Sequence[Coefficient]) -> list[Coefficient]:
    """The declared coefficients in vector order: one per parameter of ``params`` (its entry of
    ``coefficients``, else an input of unit "1"), then the derived ones (``derived``, then those
    of ``coefficients``). ValueError naming the field for anything else."""
    if isinstance(coefficients, Coefficient | str | Mapping):
        raise ValueError(f"coefficients: a sequence of geardyn.core.coefficients.Coefficient "
                         f"(got {coefficients!r})")
    declared: dict[str, Coefficient] = {}
    for k, c in enumerate(coefficients):
        if not isinstance(c, Coefficient):
            raise ValueError(f"coefficients[{k}]: a geardyn.core.coefficients.Coefficient "
                             f"(got {c!r})")
        if c.name in declared:
            raise ValueError(f"coefficients: {c.name!r} is declared twice")
        declared[c.name] = c
    shorthand: dict[str, Coefficient] = {}
    for key, spec in derived.items():
        if not (isinstance(spec, tuple) and len(spec) == 2 and callable(spec[1])):
            raise ValueError(f"derived {key!r}: needs (parameter, function) (got {spec!r})")
        if key in declared:
            raise ValueError(f"coefficients: {key!r} is declared in derived too")
        shorthand[key] = Coefficient(key, kind="derived", derived_from=(spec[0],),
                                     derive=spec[1])
    inputs = [_input(name, declared.pop(name, None)) for name in params]
    followers = [*shorthand.values(), *declared.values()]
    for c in followers:
        _check_derived(c, params)
    return [*inputs, *followers]


def _input(name: str, c: Coefficient | None) -> Coefficient:
    """The declaration of the parameter ``name`` (an input of unit "1" where none is given)."""
    if c is None:
        return Coefficient(name)
    if c.kind != "input":
        raise ValueError(f"coefficients: {name!r} has a value in params, so it is an input "
                         f"(declared kind {c.kind!r})")
    return c


def _check_derived(c: Coefficient, params: Mapping[str, float]) -> None:
    """ValueError naming ``c`` unless it is a derived coefficient with its function, of a
    parameter in ``params``."""
    if c.kind != "derived":
        raise ValueError(f"coefficients: {c.name!r} is not among params "
                         f"({', '.join(params)}) nor a derived coefficient")
    if c.derive is None:
        raise ValueError(f"coefficients: {c.name!r} is derived; give derive= (the function of "
                         f"its input's value that gives it)")
    if c.derived_from[0] not in params:
        raise ValueError(f"derived {c.name!r}: derived from {c.derived_from[0]!r}, which is not "
                         f"among params ({', '.join(params)})")


def _check_compiled(rhs: Callable, events: Callable | None, observe: Callable | None) -> None:
    for fn, label in ((rhs, "rhs"), (events, "events"), (observe, "observe")):
        if (fn is not None or label == "rhs") and not hasattr(fn, "py_func"):
            raise TypeError(f"{label} must be a numba.njit-compiled function")


def _index(kind: str, ref: str | int, names: tuple[str, ...]) -> int:
    if isinstance(ref, str):
        if ref not in names:
            raise ValueError(f"mesh: {ref!r} is not one of the {kind} ({', '.join(names)})")
        return names.index(ref)
    if not 0 <= int(ref) < len(names):
        raise ValueError(f"mesh: {kind} index {ref!r} out of range ({len(names)} {kind})")
    return int(ref)


def _meshes(specs: Sequence[MeshSpec], events: tuple[str, ...], observables: tuple[str, ...]
            ) -> tuple[tuple[tuple[str, int, int], ...], bool]:
    """The meshes as (name, drive event index, back event index), and whether they name force
    observables (these must then be the observables in mesh order: the forces the analyses
    read)."""
    out, forces = [], []
    for spec in specs:
        if len(spec) not in (3, 4):
            raise ValueError(f"mesh {spec!r}: (name, drive event, back event[, force])")
        out.append((str(spec[0]), _index("events", spec[1], events),
                    _index("events", spec[2], events)))
        if len(spec) == 4:
            forces.append(_index("observables", spec[3], observables))
    if forces and forces != list(range(len(out))) or (forces and len(observables) != len(out)):
        raise ValueError("meshes: where meshes name force observables, every mesh names one "
                         "and the observables are exactly these forces, in mesh order (got "
                         f"observables {observables!r})")
    names = [m[0] for m in out]
    if len(set(names)) != len(names):
        raise ValueError(f"meshes: names repeat ({', '.join(names)})")
    return tuple(out), bool(forces)
