"""The lane plan: every lane's forcing frequency, step and step counts, derived once.

This module is the one place that converts time to forcing periods to steps, and the one place
with the step rule (how many RK4 steps a forcing period gets). :class:`LanePlan` holds the
result for the lanes of a run; the kernels are fed from it.

The model is duck-typed: the plan calls only ``model.omega_index``, ``model.params``,
``model.other_frequencies(P)`` and ``model.fastest_natural_frequency(P)``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn.core.kernel_source import warn_slow_path
from geardyn.core.section import MAX_COMMON_PERIODS, common_section
from geardyn.core.settings import MIN_STEPS, RunSettings, check_omega, replacement, warn_deprecated

#: Fewest RK4 steps per forcing period of the step rule.
MIN_STEPS_PER_PERIOD = 64
#: Default largest step as a fraction of the period of the model's fastest natural mode.
STEPS_PER_FASTEST_MODE = 100
#: Fewest steps per period of a forcing other than Omega (the CATT load fluctuation Lambda):
#: at 8 the error of a response forced at Lambda = 40 (far above every natural frequency) is
#: about 1e-7 of the motion, like that of the natural-mode rule (docs/numerics.md).
STEPS_PER_OTHER_FORCING = 8
#: Slack of the rounding of a time to whole periods (a time of exactly k periods is k periods).
ROUNDING_SLACK = 1e-9

#: Automatic steps per period of a lane run are rounded up to this geometric ladder (ratio
#: 2^(1/4)), so that a sweep over Omega needs only a few kernel calls.
_LADDER = np.unique(np.ceil(8 * 2.0 ** (np.arange(0, 60) / 4.0)).astype(int) * 2)


# ---------------------------------------------------------------------------- time -> periods
def forcing_period(omega: Any) -> Any:
    """The forcing period 2 pi / Omega (a float, or an array for an array of frequencies)."""
    return 2.0 * math.pi / omega


def periods_covering(time: Any, period: Any) -> Any:
    """Whole periods that cover ``time`` (rounded up; an array for arrays, else an int)."""
    if np.ndim(time) or np.ndim(period):
        return np.ceil(time / period - ROUNDING_SLACK)
    return math.ceil(time / period - ROUNDING_SLACK)


def periods_within(time: Any, period: Any) -> Any:
    """Whole periods that fit in ``time`` (rounded down; as :func:`periods_covering`)."""
    if np.ndim(time) or np.ndim(period):
        return np.floor(time / period + ROUNDING_SLACK)
    return math.floor(time / period + ROUNDING_SLACK)


def whole_multiples(periods: np.ndarray, every: np.ndarray) -> np.ndarray:
    """Periods rounded up to whole multiples of ``every`` (int64)."""
    return (np.ceil(periods / every) * every).astype(np.int64)


# ---------------------------------------------------------------------------- the step rule
def ladder_steps(n: int) -> int:
    """The smallest value of the step ladder that is >= n."""
    idx = np.searchsorted(_LADDER, n)
    return int(_LADDER[min(idx, _LADDER.size - 1)]) if idx < _LADDER.size else int(n)


def steps_per_period_rule(model: Any, P: np.ndarray, omega: np.ndarray,
                          others: np.ndarray | None = None) -> np.ndarray:
    """The step rule for every lane (row) of the coefficient matrix ``P`` at the forcing
    frequencies ``omega`` (one per lane), vectorised: at least ``MIN_STEPS_PER_PERIOD``, a step
    at most 1/``STEPS_PER_FASTEST_MODE`` of the lane's fastest natural period, and at least
    ``STEPS_PER_OTHER_FORCING`` per period of every other forcing acting (``others``, shape
    ``(lanes, m)``, NaN where one does not act; default ``model.other_frequencies(P)``).
    Returns whole numbers as floats (inf where Omega is too small for any count)."""
    P = np.atleast_2d(np.asarray(P, dtype=float))
    om = np.broadcast_to(np.asarray(omega, dtype=float), (P.shape[0],))
    n = np.full(P.shape[0], float(MIN_STEPS_PER_PERIOD))
    forced = np.isfinite(om) & (om != 0.0)
    w = np.asarray(model.fastest_natural_frequency(P), dtype=float)
    ok = forced & np.isfinite(w) & (w > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        n = np.where(ok, np.maximum(n, np.ceil(STEPS_PER_FASTEST_MODE * w / om)), n)
        f = model.other_frequencies(P) if others is None else others
        f = np.abs(np.asarray(f, dtype=float).reshape(P.shape[0], -1))
        f = np.where(np.isfinite(f), f, 0.0)
        fmax = f.max(axis=1) if f.shape[1] else np.zeros(P.shape[0])
        act = forced & (fmax > 0)
        n = np.where(act, np.maximum(n, np.ceil(STEPS_PER_OTHER_FORCING * fmax / om)), n)
    return n


def default_steps_per_period(model: Any, omega: float | None = None,
                             others: np.ndarray | None = None,
                             params: np.ndarray | None = None) -> int:
    """Steps per forcing period of one run by the step rule
    (:func:`steps_per_period_rule`), for the coefficients ``params`` (default the model's own)
    at ``omega`` (default the model's), ``others``: the other forcings (default the model's).
    See ``docs/numerics.md`` for the accuracy."""
    p = np.array(model.params if params is None else params, dtype=float).ravel()
    omega = (float(p[model.omega_index]) if model.omega_index is not None else 0.0) \
        if omega is None else float(omega)
    if model.omega_index is not None:
        p[model.omega_index] = omega
    f = model.other_frequencies(p[None, :]) if others is None else others
    n = float(steps_per_period_rule(model, p[None, :], np.array([omega]), f)[0])
    return math.ceil(n)  # an OverflowError when it is not finite


def default_steps_at(model: Any, omegas: np.ndarray) -> np.ndarray:
    """:func:`default_steps_per_period` of the model's own coefficients at each of the
    frequencies ``omegas`` (int64), all at once."""
    omegas = np.asarray(omegas, dtype=float).ravel()
    rule = steps_per_period_rule(model, model.lane_params("Omega", omegas), omegas)
    if not np.all(np.isfinite(rule)):
        raise OverflowError("steps per period do not fit an integer; check Omega")
    return np.ceil(rule).astype(np.int64)


def lane_steps_per_period(model: Any, P: np.ndarray) -> np.ndarray:
    """Default steps per forcing period of each lane (row of ``P``), rounded up to the ladder:
    the step rule with the lane's own Omega, other forcings and fastest natural frequency (from
    the lane's coefficients, so a sweep over a stiffness or a mass refines the step where the
    device is stiffer)."""
    P = np.atleast_2d(P)
    n = steps_per_period_rule(model, P, P[:, model.omega_index])
    if not np.all(np.isfinite(n)) or np.any(n >= 2.0**62):
        raise OverflowError("steps per period do not fit an integer; check Omega")
    idx = np.searchsorted(_LADDER, n)  # as ladder_steps, for every lane at once
    return np.where(idx < _LADDER.size, _LADDER[np.minimum(idx, _LADDER.size - 1)],
                    n).astype(np.int64)


def lane_steps(model: Any, P: np.ndarray, steps_per_period: Any = None) -> np.ndarray:
    """Steps per period of each lane: ``steps_per_period`` (one, or one per lane; None or
    <= 0: the lane's step rule, :func:`lane_steps_per_period`)."""
    L = P.shape[0]
    given = np.broadcast_to(np.asarray(0 if steps_per_period is None else steps_per_period,
                                       dtype=np.int64), (L,))
    small = (given > 0) & (given < MIN_STEPS)
    if np.any(small):
        raise ValueError(f"steps_per_period must be >= {MIN_STEPS} (got {given[small][0]})")
    n = given.copy()
    auto = n <= 0
    if np.any(auto):
        n[auto] = lane_steps_per_period(model, P[auto])
    return n


def lane_section(model: Any, P: np.ndarray, omega: np.ndarray,
                 max_section_periods: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The section of each lane: (forcing periods between samples, commensurate) of
    :func:`~geardyn.core.section.common_section` over the model's forcings."""
    limit = MAX_COMMON_PERIODS if max_section_periods is None else int(max_section_periods)
    return common_section(omega, model.other_frequencies(P), max_periods=limit)


def lane_omega(model: Any, P: np.ndarray) -> np.ndarray:
    """Omega of each lane (a copy of its column of ``P``); ValueError unless every lane is
    periodically forced at a usable frequency (:func:`~geardyn.core.settings.check_omega`)."""
    if model.omega_index is None:
        raise ValueError("run_lanes needs a periodically forced model (it samples once a period)")
    omega = P[:, model.omega_index].copy()
    check_omega(omega)
    return omega


def _lane_times(name: str, times: np.ndarray) -> np.ndarray:
    """``times`` (an array), checked: finite and >= 0."""
    bad = ~(np.isfinite(times) & (times >= 0))
    if np.any(bad):
        raise ValueError(f"{name} must be a finite time >= 0 in every lane (got {times[bad][0]!r})")
    return times


# ---------------------------------------------------------------------------- per lane
#: The fields of :class:`LaneSettings` that are times (finite, >= 0).
_LANE_TIMES = ("transient", "transient_max")


@dataclass(frozen=True, eq=False)
class LaneSettings:
    """What the lanes of one run have of their own beside their coefficients, validated at
    construction. Each field is one value for every lane or one per lane (a 1-D sequence, its
    length checked against the lanes by :meth:`LanePlan.build`); None: the run's setting
    (:class:`~geardyn.core.settings.RunSettings`). Arrays are kept as read-only copies.

    t0
        Start times (model time units; the forcing phase is zero there), default 0.
    transient, transient_max
        Times (>= 0) in place of the run's ``transient`` and ``transient_max``.
    steps_per_period
        RK4 steps per forcing period in place of the run's (>= 4, >= 1 with ``interval``;
        <= 0: the lane's step rule).
    sample_every
        Forcing periods between samples (>= 1), or ``"auto"``: the common period of the
        model's forcings (:func:`lane_section`).
    ladder
        The step rule's count rounded up to the step ladder (:func:`lane_steps_per_period`,
        as a sweep takes it) or, False, the rule's own count (:func:`default_steps_per_period`,
        as a single run takes it).
    interval
        Unforced lanes (an autonomous model): the time (> 0) that takes the place of the
        forcing period, sampled once; None: lanes forced at their Omega.
    """

    t0: Any = None
    transient: Any = None
    transient_max: Any = None
    steps_per_period: Any = None
    sample_every: Any = "auto"
    ladder: bool = True
    interval: float | None = None

    def __post_init__(self) -> None:
        put = object.__setattr__
        if self.t0 is not None:
            t0 = _lane_array("t0", self.t0, float)
            bad = ~np.isfinite(t0)
            if np.any(bad):
                raise ValueError(f"t0 must be finite in every lane (got {t0[bad][0]!r})")
            put(self, "t0", t0)
        for name in _LANE_TIMES:
            if getattr(self, name) is not None:
                put(self, name, _lane_times(name, _lane_array(name, getattr(self, name), float)))
        if self.interval is not None:
            interval = float(self.interval)
            if not (math.isfinite(interval) and interval > 0):
                raise ValueError(f"interval must be a finite time > 0 (got {self.interval!r})")
            put(self, "interval", interval)
        if self.steps_per_period is not None:
            n = _lane_array("steps_per_period", self.steps_per_period, np.int64)
            least = MIN_STEPS if self.interval is None else 1
            small = (n > 0) & (n < least)
            if np.any(small):
                raise ValueError(f"steps_per_period must be >= {least} (got {n[small][0]})")
            put(self, "steps_per_period", n)
        put(self, "ladder", bool(self.ladder))
        if isinstance(self.sample_every, str):
            if self.sample_every != "auto":
                raise ValueError(f"sample_every must be 'auto' or >= 1 "
                                 f"(got {self.sample_every!r})")
        else:
            every = _lane_array("sample_every", self.sample_every, np.int64)
            if np.any(every < 1):
                raise ValueError(f"sample_every must be >= 1 (got {every[every < 1][0]})")
            put(self, "sample_every", every)
        if self.interval is not None and not (isinstance(self.sample_every, str)
                                              or np.all(self.sample_every == 1)):
            raise ValueError("sample_every applies to forced lanes (an interval is sampled "
                             "once)")

    def per_lane(self, name: str, lanes: int) -> np.ndarray | None:
        """The field ``name`` with one value per lane (``lanes`` of them; a read-only view),
        or None where it is not set; a ValueError where its length is not ``lanes``."""
        value = getattr(self, name)
        if value is None:
            return None
        if value.ndim and value.shape != (lanes,):
            raise ValueError(f"{name} must have one value per lane ({lanes}), got "
                             f"{value.shape[0]}")
        return np.broadcast_to(value, (lanes,))

    def fields(self) -> dict[str, Any]:
        """The fields that are set (not their defaults), by name."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if not _is_default(getattr(self, f.name), f.default)}


def _is_default(value: Any, default: Any) -> bool:
    return value is default or (isinstance(value, str) and value == default)


def _lane_array(name: str, value: Any, dtype: Any) -> np.ndarray:
    """``value`` (one number or a 1-D sequence) as a read-only array of ``dtype``."""
    out = np.array(value, dtype=dtype)
    if out.ndim > 1:
        raise ValueError(f"{name} must be one value or one per lane (got shape {out.shape})")
    out.flags.writeable = False
    return out


def _rule_steps(model: Any, P: np.ndarray, omega: np.ndarray, steps: Any) -> np.ndarray:
    """Steps per period of each lane: ``steps`` (one, or one per lane; None or <= 0: the
    step rule's own count at the lane's ``omega``, not rounded to the ladder)."""
    L = P.shape[0]
    n = np.broadcast_to(np.asarray(0 if steps is None else steps, dtype=np.int64), (L,)).copy()
    auto = n <= 0
    if np.any(auto):
        rule = steps_per_period_rule(model, P[auto], omega[auto])
        if not np.all(np.isfinite(rule)) or np.any(rule >= 2.0**62):
            raise OverflowError("steps per period do not fit an integer; check Omega")
        n[auto] = np.ceil(rule).astype(np.int64)
    return n


def _legacy_lanes(where: str, lanes: LaneSettings | None, overrides: dict[str, Any],
                  stacklevel: int) -> LaneSettings:
    """The :class:`LaneSettings` of ``overrides`` (its fields as deprecated keyword arguments
    of ``where``), with one DeprecationWarning per process naming the replacement; beside
    ``lanes`` a TypeError."""
    if lanes is not None:
        raise TypeError(f"{where}: give lanes=LaneSettings(...) or keyword arguments, not both "
                        f"(got lanes= and {next(iter(overrides))}=)")
    out = LaneSettings(**overrides)
    warn_deprecated(where, overrides, [replacement("lanes", LaneSettings, out.fields(),
                                                   home="geardyn.core")], stacklevel)
    return out


# ---------------------------------------------------------------------------- the plan
@dataclass(frozen=True)
class LanePlan:
    """Every lane's integration, in steps: derived once by :meth:`build`, read by the kernels.

    Arrays are per lane (index = row of ``P``); periods are forcing periods of the lane (of
    unforced lanes: the ``interval`` of their :class:`LaneSettings`)."""

    settings: RunSettings
    omega: np.ndarray  # (L,) forcing frequency (0: unforced)
    period: np.ndarray  # (L,) forcing period 2 pi / Omega (unforced: the interval)
    steps_per_period: np.ndarray  # (L,) int64
    step: np.ndarray  # (L,) RK4 step h = period / steps_per_period
    sample_every: np.ndarray  # (L,) int64 forcing periods between samples (the section)
    commensurate: np.ndarray  # (L,) bool; False: a second forcing at an irrational ratio
    transient_periods: np.ndarray  # (L,) int64 (minimum) transient, whole sections
    transient_max_periods: np.ndarray  # (L,) int64 longest transient by convergence
    t0: np.ndarray  # (L,) start time

    @classmethod
    def build(cls, model: Any, P: np.ndarray, settings: RunSettings,
              lanes: LaneSettings | None = None, **overrides: Any) -> LanePlan:
        """The plan of the lanes ``P`` (coefficient vectors, one row per lane) under
        ``settings``, with the per-lane values ``lanes`` (:class:`LaneSettings`: start times,
        transients, steps, sampling). ``overrides``: the fields of ``lanes`` as keyword
        arguments, deprecated (one DeprecationWarning naming ``lanes=LaneSettings(...)``)."""
        if overrides:
            lanes = _legacy_lanes("LanePlan.build", lanes, overrides, stacklevel=3)
        lanes = LaneSettings() if lanes is None else lanes
        if not isinstance(lanes, LaneSettings):
            raise TypeError(f"lanes must be a LaneSettings (got {type(lanes).__name__})")
        P = np.atleast_2d(P)
        L = P.shape[0]
        if L > 1:
            warn_slow_path(model)
        if lanes.interval is not None:
            omega, period = np.zeros(L), np.full(L, lanes.interval)
            every, commensurate = np.ones(L, np.int64), np.ones(L, bool)
        else:
            omega = lane_omega(model, P)
            period = forcing_period(omega)
            if isinstance(lanes.sample_every, str):
                every, commensurate = lane_section(model, P, omega,
                                                   settings.max_section_periods)
            else:
                every, commensurate = lanes.per_lane("sample_every", L), np.ones(L, bool)
        every = np.broadcast_to(np.asarray(every, dtype=np.int64), (L,)).copy()
        steps = lanes.per_lane("steps_per_period", L)
        steps = settings.steps_per_period if steps is None else steps
        if lanes.ladder and lanes.interval is None:
            n = lane_steps(model, P, steps)
        else:
            n = _rule_steps(model, P, omega, steps)
        tr = lanes.per_lane("transient", L)
        tr = np.full(L, settings.transient) if tr is None else tr
        n_tr = whole_multiples(periods_covering(tr, period), every)
        tmax = lanes.per_lane("transient_max", L)
        if tmax is None:
            tmax = (10.0 * tr if settings.transient_max is None
                    else np.full(L, settings.transient_max))
        n_max = np.maximum(whole_multiples(periods_within(tmax, period), every), n_tr)
        start = lanes.per_lane("t0", L)
        start = np.zeros(L) if start is None else start.copy()
        return cls(settings=settings, omega=omega, period=period, steps_per_period=n,
                   step=period / n, sample_every=every, commensurate=np.asarray(commensurate,
                                                                                bool),
                   transient_periods=n_tr, transient_max_periods=n_max, t0=start)

    # ------------------------------------------------------------------ in steps
    def window_steps(self, time: float) -> np.ndarray:
        """Steps of the whole periods that cover ``time`` (at least one) in each lane."""
        periods = np.maximum(1, periods_covering(time, self.period))
        return (periods * self.steps_per_period).astype(np.int64)

    @property
    def lanes(self) -> int:
        return int(self.omega.size)

    @property
    def samples(self) -> int:
        return self.settings.samples

    @property
    def transient_steps(self) -> np.ndarray:
        return (self.transient_periods * self.steps_per_period).astype(np.int64)

    @property
    def transient_max_steps(self) -> np.ndarray:
        return (self.transient_max_periods * self.steps_per_period).astype(np.int64)

    @property
    def sample_steps(self) -> np.ndarray:
        """Steps between two samples (a section period)."""
        return (self.sample_every * self.steps_per_period).astype(np.int64)

    @property
    def total_periods(self) -> np.ndarray:
        """Forcing periods of the (minimum) transient plus the sampled stretch."""
        return self.transient_periods + self.samples * self.sample_every

    def final_time(self, transient_periods: np.ndarray, t0: np.ndarray | None = None
                   ) -> np.ndarray:
        """Model time at the last sample, given the transient each lane used (in periods) and
        its start time (default the plan's ``t0``; chained lanes start when the one before
        them ended)."""
        start = self.t0 if t0 is None else t0
        return start + (transient_periods + self.samples * self.sample_every) * self.period
