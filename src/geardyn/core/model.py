"""The one interface every solver and analysis accepts: a model is data plus compiled functions.

A model has a state vector (``state_names``), a coefficient vector (``params``, named by
``param_names``) and compiled functions in the kernel interface (:class:`KernelSource`):

* ``rhs(t, y, dy, p, s, c)`` writes dy/dt at time t; ``s, c`` are sin and cos of the forcing
  phase, supplied by the solver (``Omega = p[omega_index]``; 0 for autonomous models).
* ``events(t, y, g, p, s, c)`` (optional) writes switching functions whose zero crossings are
  kinks of the right-hand side, at the same forcing phase; the solver locates them inside a
  step. An ``events(t, y, g, p)`` whose switching functions do not depend on the forcing is
  accepted too (the kernel adapts it).
* ``observe(t, y, o, p, s, c)`` (optional) writes derived outputs, e.g. mesh forces.

**One forcing phase.** The phase theta with sin/cos ``s, c`` is Omega times the time since the
start of the run, or of the lane: a point of a sweep by continuation starts at the previous
point's end time t0 at phase 0 (its Omega is not the previous point's), so theta = Omega (t -
t0), not Omega t. Every term whose frequency is an integer multiple of Omega (stiffness,
transmission error in the right-hand side and in the switching functions, observables, a
torque fluctuation of integer order) takes its phase from ``s, c``; only a second,
incommensurate excitation (the CATT load fluctuation Lambda, a planetary torque fluctuation
of non-integer order) reads ``t``, which runs on through a chain of continued points.

Built-in models (:class:`~geardyn.CATTDevice`, :class:`~geardyn.GearPair`) and a user's own
(:class:`~geardyn.UserModel`) all subclass :class:`Model`. The rules a model keeps are numbered in
:class:`Model`'s docstring (the model contract); :func:`geardyn.testing.check_model` checks them.
This module belongs to the core: it imports nothing of geardyn outside :mod:`geardyn.core`
(its earlier home ``geardyn.models.base`` answers with a DeprecationWarning).
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Sequence

import numpy as np

from geardyn.core.capabilities import DYNAMIC_FACTOR_MEMBERS, Capabilities
from geardyn.core.coefficients import CoefficientLayout
from geardyn.core.inputs import PhysicalInput, explored
from geardyn.core.kernel_source import KernelSource
from geardyn.core.plan import forcing_period
from geardyn.errors import ParameterError


def unique_rows(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of a 2-D array and, per row, the index of its distinct row (as
    ``np.unique(A, axis=0, return_inverse=True)``, by a lexicographic sort: much faster)."""
    A = np.atleast_2d(A)
    if A.shape[0] == 0 or A.shape[1] == 0:
        return A[:1], np.zeros(A.shape[0], np.int64)
    order = np.lexsort(A.T[::-1])
    S = A[order]
    new = np.concatenate([[True], np.any(S[1:] != S[:-1], axis=1)])
    inverse = np.empty(A.shape[0], np.int64)
    inverse[order] = np.cumsum(new) - 1
    return S[new], inverse


@functools.lru_cache(maxsize=256)
def _plain_layout(names: tuple[str, ...], model: str) -> CoefficientLayout:
    """The layout of a model that declares none: every entry an input named by ``names``."""
    return CoefficientLayout.plain(names, model)


class Model:
    """Base class of geardyn models. Subclasses set the attributes in ``__init__``.

    Notes
    -----
    **The model contract.** Every solver, sweep and analysis relies on these rules, and
    :func:`geardyn.testing.check_model` checks each (one check per number; a broken rule is
    reported by its number and name). ``n_states = len(state_names)``; the compiled functions
    are those of :attr:`kernel` (:class:`~geardyn.core.kernel_source.KernelSource`).

    1. **names** -- ``state_names`` is a non-empty tuple of distinct strings, one per state;
       ``event_names``, ``observable_names`` and ``param_names`` are tuples of distinct strings;
       every entry ``(name, i, j)`` of ``meshes`` names two events that exist; a model whose
       ``capabilities.mesh_forces`` is set has one observable per mesh (its force); and
       ``static_mesh_forces()`` is None, or one finite force per mesh of a model whose
       ``capabilities.mesh_forces`` is set (mesh forces without their meshes are refused).
    2. **coefficients** -- ``params`` is a 1-D float64 array of finite numbers laid out as
       :attr:`coefficient_layout` declares (:mod:`geardyn.core.coefficients`); ``param_names``
       are the layout's parameters (structure and workspace entries are not parameters: index
       ``params`` by :meth:`param_index`, not by ``param_names.index``); ``omega_index`` is None
       (an autonomous model) or the index of the forcing frequency Omega >= 0 in ``params``.
    3. **initial state** -- ``initial_state()`` is a finite float vector of ``n_states`` entries.
    4. **kernel functions** -- ``kernel.rhs``, ``kernel.events`` and ``kernel.observe`` are
       ``numba.njit`` functions with the interface's arguments: ``rhs(t, y, dy, p, s, c)``,
       ``events(t, y, g, p, s, c)`` (or ``events(t, y, g, p)``), ``observe(t, y, o, p, s, c)``
       (``rhs(t, y, dy, p)`` and ``observe(t, y, o, p)`` when ``kernel.plain``; in the one
       form, ``kernel.one_form`` set, tuple-valued ``rhs(t, y, p, s, c)``, ``events`` and
       ``observe`` alike, from which the engine generates this interface, see
       :mod:`geardyn.core.one_form`); ``s, c`` are
       sin and cos of the forcing phase (above), supplied by the solver (0 and 1 for an
       autonomous model). ``events`` is
       given exactly when ``event_names`` is non-empty, ``observe`` exactly when
       ``observable_names`` is, and every kernel template
       (:data:`~geardyn.solvers.kernels.TEMPLATES`) builds for them.
    5. **outputs filled** -- ``rhs`` writes every entry of ``dy`` (dy/dt, ``n_states``
       entries), ``events`` every entry of ``g`` (``n_events``), ``observe`` every entry of
       ``o`` (``n_observables``): the kernels reuse these arrays and never clear them.
    6. **confined and pure** -- each function writes only its output array, leaves ``y`` and
       ``p`` untouched, reads nothing beyond ``y`` and ``p`` (the kernels hand it rows of larger
       arrays and skip bounds checks), and gives the same output for the same inputs (no hidden
       state, no randomness): lanes must not depend on one another.
    7. **finite** -- ``rhs``, ``events`` and ``observe`` give finite values near the initial
       state (a non-finite state counts as diverged, never as a result).
    8. **kinks on event zeros** -- the right-hand side is smooth (at least four times
       differentiable) in ``t`` and ``y`` wherever no switching function changes sign: every
       kink or jump (a dead-zone edge) lies on a zero of an event, so that the solver, which
       splits a step at every located zero, keeps RK4's 4th order.
    9. **copies and lanes** -- ``with_omega`` and ``lane_params`` set Omega in a copy and leave
       the model alone; ``fastest_natural_frequency(P)`` gives one value per lane (row of
       ``P``), > 0 or NaN (unknown), and ``other_frequencies(P)`` one row per lane.
    10. **run matches reference** -- a short run of the compiled RK4 kernel at the default step
        (:func:`~geardyn.core.plan.default_steps_per_period`, which resolves
        ``fastest_natural_frequency``), with edges located, ends ok and matches the reference
        integrator (:func:`~geardyn.reference_solution`, DOP853 at rtol 1e-12) in the states
        and the observables.

    Characteristic scales (not a numbered rule; optional): :attr:`state_scale` gives, per
    state, the size of a physically significant change of that state, in the state's own units
    (e.g. the rad that moves a mesh by the nominal displacement b_c). It must be a float vector
    of ``n_states`` finite positive entries (default: ones, for a model whose states are already
    of order one in its units). The Lyapunov kernel measures tangent vectors in y / state_scale
    and sizes its finite-difference perturbation there (``docs/lyapunov.md``): exponents do not
    depend on it, but their accuracy does when states have very different units.
    """

    name: str = "model"
    state_names: tuple[str, ...] = ()
    state_units: str = "1"
    time_unit: str = "1"
    param_names: tuple[str, ...] = ()
    params: np.ndarray
    event_names: tuple[str, ...] = ()
    observable_names: tuple[str, ...] = ()
    observable_units: str = "1"
    omega_index: int | None = None
    kernel: KernelSource
    #: Meshes with a backlash dead zone: (name, index of event X - b, index of event X + b).
    meshes: tuple[tuple[str, int, int], ...] = ()
    #: Omega is one entry of ``params`` and no other coefficient depends on it, so a lane's
    #: Omega may be set by writing that entry; False where Omega moves other coefficients (set
    #: it through ``lane_params``/``with_params``).
    omega_is_entry: bool = True
    #: What the model offers beyond the interface (frequency scale, dataset attributes, ...):
    #: analyses read this declaration, never probe attributes.
    capabilities: Capabilities = Capabilities()
    #: Each instance declares its own ``capabilities`` as it is built (a user model's follow
    #: what it declares): the class-level checks of ``__init_subclass__`` are then the
    #: instance's builder's to make. Set on the class itself; its subclasses are checked.
    capabilities_per_instance: bool = False
    #: ``with_params`` may set a derived coefficient directly (a raw override) instead of
    #: refusing it; such a model records them in ``raw_overrides``.
    raw_overrides_allowed: bool = False
    #: Names that ``with_params`` takes as physical inputs (they re-derive the coefficients).
    physical_names: tuple[str, ...] = ()
    #: The model's physical inputs, declared once (:mod:`geardyn.core.inputs`), where it
    #: declares them: the names a sweep takes (``swept``), their units and meanings.
    input_declarations: tuple[PhysicalInput, ...] = ()
    #: Length [m] of one unit of the model's displacement states, where it integrates lengths
    #: over a scale (None: none declared).
    length_scale: float | None = None

    def __init_subclass__(cls, **kwargs: object) -> None:
        """A class that defines ``natural_frequencies()`` declares their unit in its
        capabilities (analyses read the declaration, never probe the method); a class that
        declares a capability defines what it needs (``dynamic_factor``: the members of
        ``DYNAMIC_FACTOR_MEMBERS``; a ``fault_dataset`` with ``stiffness_error``: that
        method). A class that sets :attr:`capabilities_per_instance` itself (its instances
        declare their own) is left to its builder; its subclasses are checked."""
        super().__init_subclass__(**kwargs)
        if vars(cls).get("capabilities_per_instance"):
            return
        if "natural_frequencies" in vars(cls) and not cls.capabilities.natural_frequencies:
            raise TypeError(f"{cls.__name__} defines natural_frequencies(): declare their unit "
                            "in its capabilities (Capabilities(natural_frequencies='rad/time' "
                            "or 'Hz'))")
        caps = cls.capabilities
        if caps.dynamic_factor:
            missing = [m for m in DYNAMIC_FACTOR_MEMBERS if not hasattr(cls, m)]
            if missing:
                raise TypeError(f"{cls.__name__} declares the dynamic_factor capability but "
                                f"lacks {', '.join(missing)}")
        if caps.fault_dataset is not None and caps.fault_dataset.stiffness_error \
                and not callable(getattr(cls, "stiffness_error", None)):
            raise TypeError(f"{cls.__name__} declares the fault dataset's stiffness_error but "
                            "defines no stiffness_error()")

    # ------------------------------------------------------------------ sizes
    @property
    def n_states(self) -> int:
        """Length of the state vector."""
        return len(self.state_names)

    @property
    def n_events(self) -> int:
        """Number of switching functions (events)."""
        return len(self.event_names)

    @property
    def n_observables(self) -> int:
        """Number of observables (outputs such as mesh forces)."""
        return len(self.observable_names)

    @property
    def state_scale(self) -> np.ndarray:
        """Characteristic scale of each state, in the state's own units (``state_units``):
        ``n_states`` positive numbers, the size of a significant change of that state. Default
        ones. The Lyapunov kernel works in the coordinates y / state_scale (see the contract)."""
        return np.ones(self.n_states)

    # ------------------------------------------------------------------ forcing
    @property
    def omega(self) -> float:
        """Forcing frequency (0 for an autonomous model)."""
        return 0.0 if self.omega_index is None else float(self.params[self.omega_index])

    @property
    def period(self) -> float | None:
        """Forcing period 2 pi / Omega, or None for an autonomous model."""
        return None if self.omega == 0.0 else forcing_period(self.omega)

    # ------------------------------------------------------------------ parameters
    def initial_state(self) -> np.ndarray:
        """Default initial state (zeros; models override with something physical)."""
        return np.zeros(self.n_states)

    @property
    def coefficient_layout(self) -> CoefficientLayout:
        """The declared layout of ``params`` (:mod:`geardyn.core.coefficients`); a model that
        declares none has every entry an input coefficient named by ``param_names``."""
        layout = self.__dict__.get("_coefficient_layout")
        if layout is None:
            return _plain_layout(tuple(self.param_names), self.name)
        return layout

    @coefficient_layout.setter
    def coefficient_layout(self, layout: CoefficientLayout) -> None:
        self._coefficient_layout = layout
        self.param_names = layout.names

    def param_index(self, name: str) -> int:
        """The index in ``params`` of the parameter ``name`` (``"Omega"``: the forcing
        frequency). An unknown name, or a structure or workspace entry, is an
        :class:`~geardyn.errors.UnknownParameterError` (a ``KeyError``) listing the parameters."""
        if name == "Omega" and self.omega_index is not None:
            return self.omega_index
        return self.coefficient_layout.index(name)

    _param_index = param_index

    def coefficient_values(self, p: np.ndarray | None = None) -> dict[str, float]:
        """The parameters of ``p`` (default ``params``) by name (structure and workspace left
        out)."""
        return self.coefficient_layout.read(self.params if p is None else p)

    def _is_physical(self, name: str) -> bool:
        """Whether ``with_params`` takes ``name`` as a physical input (re-derives)."""
        return name in self.physical_names

    def _raw_target(self, name: str, value: object = None) -> int:
        """The index ``with_params``/``lane_params`` set for the coefficient ``name``: an
        unknown name or a structure or workspace entry is an
        :class:`~geardyn.errors.UnknownParameterError`; a derived coefficient a
        :class:`~geardyn.errors.ParameterError` naming what it derives from, unless the model
        takes raw overrides (:attr:`raw_overrides_allowed`)."""
        if name == "Omega" and self.omega_index is not None:
            return self.omega_index
        idx = self.coefficient_layout.index(name, value)
        decl = self.coefficient_layout.slot(name).coefficient
        if decl.kind == "derived" and not self.raw_overrides_allowed:
            raise ParameterError(name, value, f"derived from {', '.join(decl.derived_from)}; "
                                 f"{self.name} sets it from those, change them instead")
        return idx

    def _checked_raw(self, values: dict[str, float]) -> dict[int, float]:
        """``values`` (coefficients by name) as index -> value, each name checked by
        :meth:`_raw_target` and each value against its declaration (finite, in range)."""
        layout = self.coefficient_layout
        out = {}
        for name, value in values.items():
            idx = self._raw_target(name, value)
            out[idx] = layout.at(idx).coefficient.check(name, value)
        return out

    def _with_physical(self, values: dict[str, float]) -> Model:
        """A copy with physical inputs changed (models with :attr:`physical_names`)."""
        raise NotImplementedError(f"{self.name} has no physical inputs")

    def _with_raw(self, values: dict[str, float]) -> Model:
        """A copy with coefficients set by name (checked by :meth:`_checked_raw`), the derived
        coefficients declared with their function following them."""
        out = copy.copy(self)
        p = self.params.copy()
        for idx, value in self._checked_raw(values).items():
            p[idx] = value
        out.params = self.coefficient_layout.fill_derived(p)
        return out

    def lane_params(self, name: str, values: Sequence[float] | np.ndarray) -> np.ndarray:
        """Coefficient vectors (lanes x n_params) with the parameter ``name`` set to ``values``.

        The base implementation sets one entry of ``params`` by name (``"Omega"`` is the forcing
        frequency), by the rules of :meth:`with_params` (a coefficient declared the same in
        every lane cannot be swept), the derived coefficients declared with their function
        following it; physical models override it to re-derive every coefficient.
        """
        self._refuse_unswept(name, values)
        values = np.asarray(values, dtype=float).ravel()
        idx = self._raw_target(name)
        if not self.coefficient_layout.at(idx).coefficient.per_lane and values.size > 1:
            raise ParameterError(name, values[0], f"the same in every lane of {self.name}; "
                                 "it cannot be swept")
        P = np.tile(self.params, (values.size, 1))
        P[:, idx] = values
        return self.coefficient_layout.fill_derived(P)

    @property
    def explorer_names(self) -> tuple[str, ...]:
        """The inputs the explorer offers as controls, in declared order: the declared inputs
        flagged ``explore`` (:attr:`input_declarations`), or, for a model whose inputs are its
        coefficients (none declared), the input coefficients flagged ``explore``."""
        if self.input_declarations:
            return explored(self.input_declarations)
        layout = self.coefficient_layout
        return tuple(n for n in layout.names if layout.slot(n).coefficient.explore)

    def _refuse_unswept(self, name: str, values: object) -> None:
        """A :class:`~geardyn.errors.ParameterError` naming ``name`` where it is a declared
        input (:attr:`input_declarations`) that a sweep does not take (not ``swept``)."""
        declared = next((i for i in self.input_declarations if i.name == name), None)
        if declared is not None and not declared.swept:
            swept = [i.name for i in self.input_declarations if i.swept]
            raise ParameterError(name, values, f"not swept ({declared.kind} input of "
                                 f"{self.name}: set it with with_params or in the study); "
                                 f"swept: {', '.join(('Omega', *swept))}")

    def lane_params_grid(self, x: str, x_values: Sequence[float] | np.ndarray, y: str,
                         y_values: Sequence[float] | np.ndarray) -> np.ndarray:
        """Coefficient vectors of a two-parameter grid, ``(len(y_values) * len(x_values),
        n_params)``, row-major over (y, x): lane ``j * nx + i`` has ``y = y_values[j]`` and
        ``x = x_values[i]``.

        Row j is ``self.with_params(y=y_values[j]).lane_params(x, x_values)``, so each name means
        what it means to ``with_params`` and ``lane_params`` (a physical parameter re-derives every
        coefficient). Raises ValueError when the x sweep would undo the y setting (a raw
        coefficient as ``y`` with a physical parameter as ``x``: swap the axes).
        """
        if x == y:
            raise ValueError(f"x and y must be different parameters (both {x!r})")
        xv = np.asarray(x_values, dtype=float).ravel()
        yv = np.asarray(y_values, dtype=float).ravel()
        if y == "Omega" and self.omega_is_entry:  # one entry of every vector: set it on x rows
            row = self.lane_params(x, xv)
            P = np.tile(row, (yv.size, 1))
            P[:, self._param_index("Omega")] = np.repeat(yv, xv.size)
            return P
        P = np.concatenate([self.with_params(**{y: float(v)}).lane_params(x, xv) for v in yv])
        # the coefficients y moves (and x does not) must keep y's values in every row
        Py, Px = self.lane_params(y, yv), self.lane_params(x, xv)
        only_y = np.any(Py != Py[:1], axis=0) & ~np.any(Px != Px[:1], axis=0)
        blocks = P.reshape(yv.size, xv.size, -1)
        lost = any(not np.array_equal(Py[j], Py[0]) and np.array_equal(blocks[j], blocks[0])
                   for j in range(1, yv.size))
        if lost or not np.array_equal(P[:, only_y], np.repeat(Py[:, only_y], xv.size, axis=0)):
            raise ValueError(f"sweeping x={x!r} undoes y={y!r} in this model; swap the axes")
        return P

    def with_params(self, **values: float) -> Model:
        """A copy of the model with parameters changed by name, the same rules for every model:

        * a physical input (:attr:`physical_names`) re-derives the coefficients;
        * an input coefficient (or ``"Omega"``) sets its entry, checked against its declaration
          (finite, in range: else a :class:`~geardyn.errors.ParameterError` naming it); the
          derived coefficients declared with their function (``derive``) follow it;
        * a derived coefficient is refused naming what it derives from, unless the model takes
          raw overrides (:attr:`raw_overrides_allowed`);
        * a structure or workspace entry, or an unknown name, is an
          :class:`~geardyn.errors.UnknownParameterError` (a ``KeyError``) listing the parameters.
        """
        physical = {k: v for k, v in values.items() if self._is_physical(k)}
        raw = {k: v for k, v in values.items() if k not in physical}
        for name, value in raw.items():  # refuse before any rebuild
            self._raw_target(name, value)
        out = self._with_physical(physical) if physical else copy.copy(self)
        return out._with_raw(raw) if raw else out

    def other_frequencies(self, P: np.ndarray) -> np.ndarray:
        """Frequencies (rad per model time unit) of forcings other than Omega that act in each
        lane of ``P``, shape ``(lanes, m)``; NaN where one does not act. None here; a model with
        a second excitation (the CATT device's load fluctuation Lambda) overrides it, so that
        sweeps can sample at the common period (see
        :func:`geardyn.core.section.common_section`)."""
        return np.zeros((np.atleast_2d(P).shape[0], 0))

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """Fastest natural frequency (rad per model time unit) of the linearised model (mean
        stiffness, no backlash) in each lane of the coefficient matrix ``P`` (default: this
        model's own coefficients), shape ``(lanes,)``; NaN where it is not known.

        The default step (:func:`~geardyn.core.plan.default_steps_per_period`) resolves
        this frequency in every lane. The default here: a model that declares
        ``capabilities.natural_frequencies = "rad/time"`` is asked for ``natural_frequencies()``
        once per distinct row of ``P`` (a copy of the model holding that row), so it must
        compute them from ``self.params``; any other model gets NaN (unknown: the step then
        follows only the forcing frequencies, at least ``MIN_STEPS_PER_PERIOD`` per period).
        Built-in models override it with a vectorised computation from the coefficients.
        """
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        if self.capabilities.natural_frequencies != "rad/time":
            return np.full(P.shape[0], np.nan)
        fn = type(self).natural_frequencies
        rows, inverse = unique_rows(P)
        out = np.empty(rows.shape[0])
        for k, row in enumerate(rows):
            lane = copy.copy(self)
            lane.params = row.copy()
            w = np.asarray(fn(lane), dtype=float)
            out[k] = float(np.max(w)) if w.size else np.nan
        return out[inverse]

    def with_omega(self, omega: float) -> Model:
        """A copy with the forcing frequency set to ``omega``."""
        return self.with_params(Omega=omega)

    @property
    def dimensionless_time(self) -> bool:
        """Whether the model's time is dimensionless (``time_unit`` "1", e.g. tau = omega_n t)
        rather than physical (seconds)."""
        return self.time_unit in ("1", "")

    def lyapunov_duration(self) -> tuple[float | None, str]:
        """The default time a Lyapunov estimate averages over, in the model's time unit, and
        the rule that gave it: :data:`~geardyn.core.settings.LYAPUNOV_DURATION` (2000) time
        units for a model of dimensionless time; for one of physical time
        :data:`~geardyn.core.settings.LYAPUNOV_PERIODS` forcing periods (None: that many
        periods of each lane's own Omega); an autonomous model of physical time has no
        scale to count (a ValueError: give ``LyapunovSettings(duration=...)``)."""
        from geardyn.core.settings import LYAPUNOV_DURATION, LYAPUNOV_PERIODS

        if self.dimensionless_time:
            return LYAPUNOV_DURATION, f"default: {LYAPUNOV_DURATION:g} time units"
        if self.omega_index is None:
            raise ValueError(f"{self.name} is autonomous in {self.time_unit}: no forcing period"
                             " to scale the Lyapunov duration by; give "
                             "LyapunovSettings(duration=...)")
        return None, f"default: {LYAPUNOV_PERIODS} forcing periods"

    def dataset_attrs(self) -> dict[str, object]:
        """Attributes every dataset of this model records (none here; e.g. the CATT device's
        ``interpretation`` and ``omega_n``)."""
        return {}

    def param_attrs(self, name: str) -> dict[str, str]:
        """Attributes of the axis of a sweep in ``name``: ``units`` and ``long_name`` (its
        meaning) from the coefficient's declaration, where the model declares its layout;
        none for a name it does not declare."""
        layout = self.__dict__.get("_coefficient_layout")
        if layout is None or name not in layout.names:
            return {}
        c = layout.slot(name).coefficient
        return {"units": c.unit, **({"long_name": c.meaning} if c.meaning else {})}

    def static_mesh_forces(self) -> np.ndarray | None:
        """Static mesh forces (one per mesh, observable units) for the dynamic factor, or None."""
        return None

    def __repr__(self) -> str:
        return f"{type(self).__name__}(states={list(self.state_names)}, omega={self.omega:g})"
