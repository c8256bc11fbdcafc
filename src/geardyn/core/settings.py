"""The settings of a run, validated once where they enter (API, CLI, study file, reproduction).

:class:`RunSettings` is immutable; everything downstream (the lane plan, the kernels, the
dataset attributes) takes it as given and does not check it again. ``replace`` returns a
changed copy, validated anew.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from geardyn.core.moved import warn_once

#: States beyond this magnitude count as diverged.
DEFAULT_BOUND = 1.0e6
#: Default relative tolerance of the period classifier (see geardyn.analysis.periodicity).
DEFAULT_TOL = 1.0e-5
#: Default longest period (in sections) the classifier looks for.
DEFAULT_MAX_PERIOD = 16
#: Fewest RK4 steps per forcing period a run accepts.
MIN_STEPS = 4
#: How the integration is described in the datasets.
INTEGRATOR = "RK4, fixed step aligned to the forcing period"


#: What a forcing frequency Omega must be (:func:`usable_omega`): the rule of the study file's
#: ``[run].omega`` and of every command's ``--omega``.
OMEGA_RULE = "must be a positive finite number (with a finite period)"


def usable_omega(value: float) -> bool:
    """True for a forcing frequency that is positive, finite, and whose period 2 pi / Omega is
    finite too (5e-324 is positive, but its period overflows)."""
    return math.isfinite(value) and value > 0 and math.isfinite(2 * math.pi / value)


def check_omega(value: Any, name: str = "Omega") -> None:
    """A :class:`~geardyn.errors.ParameterError` (a ValueError) naming ``name`` and the first
    value (of a number or an array of them) that is not :func:`usable_omega`."""
    from geardyn.errors import ParameterError

    for w in _as_floats(value):
        if not usable_omega(w):
            raise ParameterError(name, w, OMEGA_RULE)


#: The directions a sweep by continuation goes in the swept parameter.
SWEEP_DIRECTIONS: tuple[str, ...] = ("up", "down")
#: Where each point of a parameter sweep starts: "none", every point from the same start;
#: "up"/"down", each from the previous point's final state (``[sweep].continuation``,
#: ``--continuation``, the explorer, :func:`geardyn.bifurcation`).
SWEEP_CONTINUATIONS: tuple[str, ...] = ("none", *SWEEP_DIRECTIONS)
#: What a sweep's continuation must be (:func:`check_continuation`).
CONTINUATION_RULE = "must be one of " + ", ".join(SWEEP_CONTINUATIONS)


def check_continuation(value: Any, name: str = "continuation") -> str:
    """``value`` where it is one of :data:`SWEEP_CONTINUATIONS`; else a
    :class:`~geardyn.errors.ParameterError` (a ValueError) naming ``name``."""
    from geardyn.errors import ParameterError

    if not (isinstance(value, str) and value in SWEEP_CONTINUATIONS):
        raise ParameterError(name, value, CONTINUATION_RULE)
    return value


def _as_floats(value: Any) -> list[float]:
    if isinstance(value, numbers.Real):
        return [float(value)]
    import numpy as np

    values = np.asarray(value, dtype=float).ravel().tolist()
    if not values:
        raise ValueError("Omega: no values given")
    return values


class SettingsError(ValueError):
    """An invalid run setting; the message names the field and the value."""


class SettingsTypeError(SettingsError, TypeError):
    """A run setting of the wrong type (also a ValueError, like every invalid setting)."""


def _real(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise SettingsTypeError(f"{name} must be a number (got {value!r})")
    value = float(value)
    if math.isnan(value):
        raise SettingsError(f"{name} must be a number, not NaN (got {value!r})")
    return value


def _time(name: str, value: Any) -> float:
    value = _real(name, value)
    if not (math.isfinite(value) and value >= 0):
        raise SettingsError(f"{name} must be a finite time >= 0 (got {value!r})")
    return value


def _whole(name: str, value: Any, least: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise SettingsTypeError(f"{name} must be a whole number (got {value!r})")
    value = int(value)
    if value < least:
        raise SettingsError(f"{name} must be >= {least} (got {value!r})")
    return value


def _flag(name: str, value: Any) -> bool:
    if isinstance(value, bool) or (isinstance(value, numbers.Integral) and value in (0, 1)):
        return bool(value)
    raise SettingsTypeError(f"{name} must be True or False (got {value!r})")


@dataclass(frozen=True)
class RunSettings:
    """How every lane of a run is integrated and sampled (times in model time units, tau for
    the dimensionless models).

    transient
        Time discarded first, rounded up to whole sampling intervals (>= 0).
    samples
        Poincare points recorded after the transient, one per section (>= 1; period
        classification needs 2). :func:`~geardyn.simulate` records this many forcing periods.
    steps_per_period
        RK4 steps per forcing period (>= 4), or None: the step rule of each lane
        (:func:`geardyn.core.plan.steps_per_period_rule`).
    locate_edges
        Locate dead-zone edge crossings inside steps (keeps 4th order).
    bound
        States beyond this magnitude count as diverged (> 0).
    converge
        Transient by convergence: a tolerance (> 0) to which the section point must settle
        before sampling starts, ``transient`` then being a minimum; None: a fixed transient.
    transient_max
        Longest transient by convergence (default 10 x transient).
    continued_transient
        Continuation: the (minimum) transient of a continued point (default ``transient``).
    max_period
        Longest period (in sections) the classifier looks for (>= 1).
    period_tol
        Relative tolerance of the period classifier (> 0).
    max_section_periods
        The longest common period of two forcings (in forcing periods) taken as a section
        (>= 1; None: :data:`geardyn.core.section.MAX_COMMON_PERIODS`).
    """

    transient: float = dataclasses.field(default=4000.0, metadata={
        "help": "Discarded time before sampling (model time units, tau when dimensionless)"})
    samples: int = dataclasses.field(default=200, metadata={
        "help": "Poincare points (sections) sampled per point"})
    steps_per_period: int | None = dataclasses.field(default=None, metadata={
        "help": "RK4 steps per forcing period"})
    locate_edges: bool = dataclasses.field(default=True, metadata={
        "help": "Locate dead-zone edge crossings inside steps (keeps 4th order)"})
    bound: float = dataclasses.field(default=DEFAULT_BOUND, metadata={
        "help": "States beyond this magnitude count as diverged"})
    converge: float | None = dataclasses.field(default=None, metadata={
        "help": "Transient by convergence: run on past --transient (a minimum) until the "
                "section point settles to this relative tolerance"})
    transient_max: float | None = None
    continued_transient: float | None = dataclasses.field(default=None, metadata={
        "help": "Least discarded time of a continued point, which starts next to its "
                "attractor (a minimum with --converge)"})
    max_period: int = DEFAULT_MAX_PERIOD
    period_tol: float = DEFAULT_TOL
    max_section_periods: int | None = dataclasses.field(default=None, metadata={
        "help": "Longest common period of two forcings (in forcing periods) taken as a "
                "section"})

    def __post_init__(self) -> None:
        put = object.__setattr__
        put(self, "transient", _time("transient", self.transient))
        put(self, "samples", _whole("samples", self.samples, 1))
        if self.steps_per_period is not None:
            put(self, "steps_per_period",
                _whole("steps_per_period", self.steps_per_period, MIN_STEPS))
        put(self, "locate_edges", _flag("locate_edges", self.locate_edges))
        bound = _real("bound", self.bound)
        if not bound > 0:
            raise SettingsError(f"bound must be > 0 (got {bound!r})")
        put(self, "bound", bound)
        if self.converge is not None:
            tol = _real("converge", self.converge)
            if not (math.isfinite(tol) and tol > 0):
                raise SettingsError(
                    f"converge must be a positive tolerance or None (got {tol!r})")
            put(self, "converge", tol)
        for name in ("transient_max", "continued_transient"):
            if getattr(self, name) is not None:
                put(self, name, _time(name, getattr(self, name)))
        put(self, "max_period", _whole("max_period", self.max_period, 1))
        ptol = _real("period_tol", self.period_tol)
        if not (math.isfinite(ptol) and ptol > 0):
            raise SettingsError(f"period_tol must be a finite tolerance > 0 (got {ptol!r})")
        put(self, "period_tol", ptol)
        if self.max_section_periods is not None:
            put(self, "max_section_periods",
                _whole("max_section_periods", self.max_section_periods, 1))

    # ------------------------------------------------------------------ derived values
    @property
    def converge_tol(self) -> float:
        """The convergence tolerance as the kernels take it (0.0: off)."""
        return 0.0 if self.converge is None else self.converge

    @property
    def transient_limit(self) -> float:
        """The longest transient: ``transient_max``, default 10 x ``transient``."""
        return 10.0 * self.transient if self.transient_max is None else self.transient_max

    # ------------------------------------------------------------------ changes
    def replace(self, **changes: Any) -> RunSettings:
        """A copy with ``changes`` (field names), validated anew."""
        unknown = sorted(set(changes) - set(FIELDS))
        if unknown:
            raise TypeError(f"RunSettings has no field {unknown[0]!r} "
                            f"(fields: {', '.join(FIELDS)})")
        return dataclasses.replace(self, **changes)

    def attrs(self) -> dict[str, Any]:
        """The settings as dataset attributes (NetCDF-safe: numbers and strings only)."""
        out: dict[str, Any] = dict(
            transient=self.transient, samples=self.samples, converge=self.converge_tol,
            transient_max=self.transient_limit, integrator=INTEGRATOR,
            locate_edges=int(self.locate_edges), bound=self.bound, period_tol=self.period_tol,
            max_period=self.max_period, steps_per_period_setting=int(self.steps_per_period or 0))
        if self.max_section_periods is not None:
            out["max_section_periods"] = self.max_section_periods
        return out


#: The field names of :class:`RunSettings`.
FIELDS = tuple(f.name for f in dataclasses.fields(RunSettings))


def resolve_run(run: RunSettings | None, legacy: Mapping[str, Any],
                defaults: Mapping[str, Any] | None = None,
                aliases: Mapping[str, str] | None = None, where: str | None = None,
                stacklevel: int = 3) -> RunSettings:
    """The settings of a public function that takes ``run=`` and, for compatibility, the old
    keyword arguments: ``legacy`` holds those the caller gave (name -> value), ``aliases`` maps
    an old name onto a field (``tol`` -> ``period_tol``), ``defaults`` the function's own
    defaults where they differ from RunSettings' (``simulate``'s transient 0). Giving ``run``
    and an old keyword together raises a TypeError naming the keyword; an unknown keyword
    raises a TypeError too. ``where`` (the function's name): the old keywords are deprecated,
    one DeprecationWarning naming the equivalent ``run=geardyn.RunSettings(...)``
    (``stacklevel``: the public function's caller, seen from here)."""
    aliases = dict(aliases or {})
    given = {aliases.get(k, k): v for k, v in legacy.items()}
    unknown = sorted(set(given) - set(FIELDS))
    if unknown:
        raise TypeError(f"unknown run setting {unknown[0]!r}")
    if run is not None:
        if not isinstance(run, RunSettings):
            raise TypeError(f"run must be a RunSettings (got {type(run).__name__})")
        if given:
            name = next(k for k, v in legacy.items() if aliases.get(k, k) in given)
            raise TypeError(f"give the run settings either as run=RunSettings(...) or as keyword "
                            f"arguments, not both (got run= and {name}=)")
        return run
    fields = {**dict(defaults or {}), **given}
    out = RunSettings(**fields)
    if where is not None and given:
        warn_deprecated(where, legacy, [replacement("run", RunSettings, fields)], stacklevel)
    return out


def settings_from_named(kind: type, named: Mapping[str, tuple[str, Any]]) -> Any:
    """The ``kind`` settings built once from ``named`` (field -> (where the value comes from:
    an option such as ``--transient`` or a study key such as ``run.periods``, value); ``None``
    values take the default). An invalid value is a one-line
    :class:`~geardyn.errors.ParameterError` naming where it came from."""
    from geardyn.errors import ParameterError

    given = {field: value for field, (_, value) in named.items() if value is not None}
    try:
        return kind(**given)
    except (TypeError, ValueError) as exc:
        field, _, reason = str(exc).partition(" ")
        if field not in named or named[field][0] == field:  # unknown, or named as the field
            raise
        where, value = named[field]
        raise ParameterError(where, value, reason.rsplit(" (got ", 1)[0]) from None


def replacement(param: str, kind: type, fields: Mapping[str, Any], home: str = "geardyn"
                ) -> str:
    """The text ``param=geardyn.Kind(a=1, ...)`` naming the settings that replace keywords
    (``home``: the module that exports ``Kind``; an array value is written as its length)."""
    args = ", ".join(f"{k}={_shown(v)}" for k, v in fields.items())
    return f"{param}={home}.{kind.__name__}({args})"


def _shown(value: Any) -> str:
    """``value`` as a deprecation message writes it: its repr, an array as ``<n values>``, a
    zero-dimensional one as its number."""
    shape = getattr(value, "shape", None)
    if shape is None:
        return repr(value)
    return f"<{math.prod(shape)} values>" if shape else repr(value.item())


def warn_deprecated(where: str, keywords: Iterable[str], replacements: Sequence[str],
                    stacklevel: int) -> None:
    """One DeprecationWarning, once per process for each function and set of keywords
    (:func:`geardyn.core.moved.warn_once`): ``where``'s ``keywords`` are deprecated, pass the
    ``replacements`` (``stacklevel``: the public function's caller, seen from the caller of
    this function)."""
    keywords = tuple(keywords)
    warn_once(("keywords", where, keywords),
              f"{where}({', '.join(f'{k}=' for k in keywords)}) is deprecated: pass "
              f"{', '.join(replacements)}", stacklevel=stacklevel + 1)


# ----------------------------------------------------------------------------- analyses
def _positive(name: str, value: Any) -> float:
    value = _real(name, value)
    if not (math.isfinite(value) and value > 0):
        raise SettingsError(f"{name} must be a finite number > 0 (got {value!r})")
    return value


def _validate(obj: Any) -> None:
    """Check and normalise every field of a settings dataclass by its metadata ``kind``
    (``positive``, ``whole`` with ``least``, ``optional-positive``, ``optional-whole``)."""
    for f in dataclasses.fields(obj):
        value, kind = getattr(obj, f.name), f.metadata.get("kind")
        if value is None and kind is not None and kind.startswith("optional-"):
            continue
        if kind in ("positive", "optional-positive"):
            value = _positive(f.name, value)
        elif kind in ("whole", "optional-whole"):
            value = _whole(f.name, value, f.metadata.get("least", 1))
        object.__setattr__(obj, f.name, value)


def _field(default: Any, kind: str, help: str, least: int = 1) -> Any:
    """A settings field: its default, its check (see :func:`_validate`) and its help text (the
    CLI's, where it has an option)."""
    return dataclasses.field(default=default,
                             metadata={"kind": kind, "least": least, "help": help})


class _AnalysisSettings:
    """What the analysis settings share: validation at construction and ``replace``."""

    def __post_init__(self) -> None:
        _validate(self)
        self._check()

    def _check(self) -> None:
        """Checks across fields (none by default)."""

    def replace(self, **changes: Any) -> Any:
        """A copy with ``changes`` (field names), validated anew."""
        names = [f.name for f in dataclasses.fields(self)]
        unknown = sorted(set(changes) - set(names))
        if unknown:
            raise TypeError(f"{type(self).__name__} has no field {unknown[0]!r} "
                            f"(fields: {', '.join(names)})")
        return dataclasses.replace(self, **changes)


#: Defaults of Newton shooting: tolerance (scaled residual) and most iterations.
NEWTON_TOL = 1e-10
NEWTON_MAX_ITER = 40


@dataclass(frozen=True)
class NewtonSettings(_AnalysisSettings):
    """Newton shooting of a periodic orbit (:func:`geardyn.periodic_orbit`).

    tol
        Converged when ``max |F / state_scale| <= tol (1 + max |x / state_scale|)`` (> 0).
    max_iter
        Most Newton iterations (>= 1).
    """

    tol: float = _field(NEWTON_TOL, "positive", "Newton tolerance (scaled residual)")
    max_iter: int = _field(NEWTON_MAX_ITER, "whole", "most Newton iterations")


#: Defaults of the continuation corrector and of bifurcation location.
CORRECTOR_TOL = 1e-10
LOCATE_TOL = 1e-7
#: Relative step of every central difference in a model parameter p (the continuation's dG/dp,
#: the bifurcation and grazing curves' parameter columns): p +- PARAM_STEP_REL (1 + |p|).
PARAM_STEP_REL = 1e-6


@dataclass(frozen=True)
class ContinuationSettings(_AnalysisSettings):
    """Pseudo-arclength continuation of periodic orbits (:func:`geardyn.continuation`).

    ds, ds_min, ds_max
        First, least and greatest arclength step in the scaled unknowns (x / state_scale,
        p / p_scale); 0 < ds_min <= ds <= ds_max.
    max_points
        Most points of a branch (>= 1).
    tol
        Corrector tolerance (> 0): converged where
        ``max |G / state_scale| <= tol (1 + max |x / state_scale|)``.
    locate_tol
        Location tolerance of a bifurcation in the parameter (> 0).
    max_period
        Branch switching at period doublings goes on (a cascade) while 2k <= max_period.
    p_scale
        The parameter's scale in the arclength (> 0; None: ``abs(stop - start)``).
    """

    ds: float = _field(0.01, "positive", "first arclength step")
    ds_min: float = _field(1e-7, "positive", "least arclength step")
    ds_max: float = _field(0.2, "positive", "greatest arclength step")
    max_points: int = _field(2000, "whole", "most points per branch")
    tol: float = _field(CORRECTOR_TOL, "positive", "corrector tolerance (scaled residual)")
    locate_tol: float = _field(LOCATE_TOL, "positive",
                               "location tolerance of a bifurcation in the parameter")
    max_period: int = _field(16, "whole", "longest period of a switched branch (2k <= N)")
    p_scale: float | None = _field(None, "optional-positive",
                                   "the parameter's scale in the arclength")

    def _check(self) -> None:
        if not self.ds_min <= self.ds <= self.ds_max:
            raise SettingsError(f"ds must lie in [ds_min, ds_max] (got ds_min={self.ds_min!r}, "
                                f"ds={self.ds!r}, ds_max={self.ds_max!r})")


#: Defaults of the Lyapunov estimate: the time averaged over in a model of dimensionless time
#: (time unit "1"), and in a model of physical time (seconds) that many forcing periods, and
#: its default transient (where no run is given) in forcing periods.
LYAPUNOV_DURATION = 2000.0
LYAPUNOV_PERIODS = 200
LYAPUNOV_TRANSIENT_PERIODS = 20
LYAPUNOV_DT = 0.01
LYAPUNOV_RENORM_EVERY = 10
LYAPUNOV_BLOCKS = 16
#: How the tangent vectors are advanced (:attr:`LyapunovSettings.tangent`).
LYAPUNOV_TANGENTS = ("auto", "variational", "difference")


@dataclass(frozen=True)
class LyapunovSettings(_AnalysisSettings):
    """How Lyapunov exponents are measured (:func:`geardyn.lyapunov`,
    :func:`geardyn.lyapunov_lanes`); the transient, steps and bound are the run's.

    duration
        Time averaged over, in the model's time unit, rounded up to whole forcing periods
        (> 0). None (default): the model's own scale, :meth:`geardyn.Model.lyapunov_duration`:
        :data:`LYAPUNOV_DURATION` time units for a model of dimensionless time, and
        :data:`LYAPUNOV_PERIODS` forcing periods for one of physical time (a spur pair in
        seconds).
    dt
        Step of an autonomous model (> 0; None: :data:`LYAPUNOV_DT`); not for a forced model,
        whose grid has the run's steps per period.
    renorm_every
        RK4 steps between re-orthonormalisations (>= 1).
    n_blocks
        Blocks of the measuring window for the standard error (>= 2).
    tangent
        How the tangent vectors are advanced: ``"variational"``, the exact derivative of the
        RK4 step map from the model's one form (dual numbers through its rhs; a step split at
        an edge crossing by the difference rows; a model written in the one form only),
        ``"difference"``, central differences of the step map at every step (every model), or
        ``"auto"`` (default): variational where the model has a one form.
    """

    duration: float | None = _field(None, "optional-positive", "time averaged over (default: "
                                    "the model's scale)")
    dt: float | None = _field(None, "optional-positive",
                              f"step of an autonomous model (default {LYAPUNOV_DT})")
    renorm_every: int = _field(LYAPUNOV_RENORM_EVERY, "whole",
                               "RK4 steps between re-orthonormalisations")
    n_blocks: int = _field(LYAPUNOV_BLOCKS, "whole", "blocks for the standard error", least=2)
    tangent: str = _field("auto", "choice", "tangent vectors: variational, difference or auto")

    def _check(self) -> None:
        if self.tangent not in LYAPUNOV_TANGENTS:
            raise SettingsError(f"tangent must be one of {', '.join(LYAPUNOV_TANGENTS)} "
                                f"(got {self.tangent!r})")


def resolve_settings(kind: type, settings: Any, legacy: Mapping[str, Any], where: str,
                     stacklevel: int = 3, warn: bool = True) -> Any:
    """The ``kind`` settings of a public function that takes ``settings=`` and, for one
    deprecation cycle, their fields as keyword arguments (``legacy``: those given): one
    DeprecationWarning naming the replacement (``stacklevel``: the public function's caller,
    seen from here; ``warn`` False: the caller warns); giving both is a TypeError."""
    if settings is not None and not isinstance(settings, kind):
        raise TypeError(f"settings must be a {kind.__name__} (got {type(settings).__name__})")
    if not legacy:
        return kind() if settings is None else settings
    if settings is not None:
        raise TypeError(f"{where}: give settings={kind.__name__}(...) or keyword arguments, "
                        f"not both (got settings= and {next(iter(legacy))}=)")
    out = kind(**legacy)
    if warn:
        warn_deprecated(where, legacy, [replacement("settings", kind, legacy)], stacklevel)
    return out
