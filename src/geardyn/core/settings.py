"""The settings of a run, validated once where they enter (API, CLI, study file, reproduction).

:class:`RunSettings` is immutable; everything downstream (the lane plan, the kernels, the
dataset attributes) takes it as given and does not check it again. ``replace`` returns a
changed copy, validated anew.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

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

    transient: float = 4000.0
    samples: int = 200
    steps_per_period: int | None = None
    locate_edges: bool = True
    bound: float = DEFAULT_BOUND
    converge: float | None = None
    transient_max: float | None = None
    continued_transient: float | None = None
    max_period: int = DEFAULT_MAX_PERIOD
    period_tol: float = DEFAULT_TOL
    max_section_periods: int | None = None

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
                aliases: Mapping[str, str] | None = None) -> RunSettings:
    """The settings of a public function that takes ``run=`` and, for compatibility, the old
    keyword arguments: ``legacy`` holds those the caller gave (name -> value), ``aliases`` maps
    an old name onto a field (``tol`` -> ``period_tol``), ``defaults`` the function's own
    defaults where they differ from RunSettings' (``simulate``'s transient 0). Giving ``run``
    and an old keyword together raises a TypeError naming the keyword; an unknown keyword
    raises a TypeError too."""
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
    return RunSettings(**{**dict(defaults or {}), **given})
