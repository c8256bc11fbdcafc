"""Lyapunov exponents of any geardyn model from its tangent (variational) equations.

The state and k tangent vectors are integrated by fixed-step RK4 on the main solver's grid. A
model written in the one form advances them by the exact derivative of the RK4 step map (dual
numbers through its one-form ``rhs``: the variational tangent); any other model, or
``LyapunovSettings(tangent="difference")``, by central differences of the step map
(:func:`lyapunov_variational`, :func:`lyapunov_tangent`). The vectors are re-orthonormalised
(modified Gram-Schmidt) every ``renorm_every`` steps and the logs of the stretching factors
averaged (Benettin et al. 1980). Each exponent has a standard error from
the spread of its block averages over the run. See ``docs/lyapunov.md`` and the kernel template
:mod:`geardyn.solvers._lyapunov_template`.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numba.core.errors
import numpy as np

from geardyn.core.model import Model
from geardyn.core.moved import moved
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.settings import (
    LYAPUNOV_BLOCKS,
    LYAPUNOV_DT,
    LYAPUNOV_PERIODS,
    LYAPUNOV_RENORM_EVERY,
    LYAPUNOV_TRANSIENT_PERIODS,
    LyapunovSettings,
    RunSettings,
    check_omega,
    replacement,
    resolve_run,
    resolve_settings,
    warn_deprecated,
)
from geardyn.core.status import Status
from geardyn.errors import ParameterError
from geardyn.solvers.compile_share import signature_types
from geardyn.solvers.kernels import compile_tangent, kernels_for

#: The defaults' earlier names here (deprecated): those of :mod:`geardyn.core.settings`.
__getattr__ = moved(__name__, {
    "DEFAULT_DT": "geardyn.core.settings:LYAPUNOV_DT",
    "DEFAULT_RENORM_EVERY": "geardyn.core.settings:LYAPUNOV_RENORM_EVERY",
    "DEFAULT_BLOCKS": "geardyn.core.settings:LYAPUNOV_BLOCKS"})

#: Defaults of :func:`lyapunov` where they differ from :class:`~geardyn.RunSettings`'.
LYAPUNOV_DEFAULTS = {"transient": 100.0}
#: The :class:`~geardyn.RunSettings` fields that :func:`lyapunov` uses (as keywords: deprecated).
LYAPUNOV_FIELDS = ("transient", "steps_per_period", "locate_edges", "bound")

__all__ = ["LYAPUNOV_DEFAULTS", "LyapunovEstimate", "lyapunov", "lyapunov_err_attrs",
           "lyapunov_lanes", "lyapunov_tangent", "lyapunov_unresolved_attrs",
           "lyapunov_variational"]


@dataclass(frozen=True)
class LyapunovEstimate:
    """A finite-time Lyapunov exponent with its statistical uncertainty.

    ``value``: the exponent (per unit model time; an array, descending, for a spectrum);
    ``stderr``: its 1-sigma standard error, std(block rates) / sqrt(n_blocks) over blocks of
    whole forcing periods of the measuring window (same shape; NaN with fewer than 2 blocks or
    when diverged);
    ``n_blocks``: the number of blocks used;
    ``unresolved``: grid steps (of the state or of a finite-difference neighbour) that reached
    the edge-location split limit and were integrated unsplit across an edge;
    ``status``: :attr:`~geardyn.Status.OK`, :attr:`~geardyn.Status.DIVERGED` (value NaN) or
    :attr:`~geardyn.Status.SPLIT_LIMIT` (``unresolved`` > 0: the value is kept, but it rests
    on steps that are not 4th order across an edge);
    ``duration``: the time averaged over (model time units, whole forcing periods) and
    ``duration_rule`` where it came from (``LyapunovSettings.duration``, or the model's default
    scale, :meth:`geardyn.Model.lyapunov_duration`);
    ``tangent``: how the tangent vectors were advanced (:func:`lyapunov_tangent`) and
    ``difference_steps`` the grid steps that took the finite-difference rows (all with
    ``"difference"``; with ``"variational"`` the split steps where carrying the tangent through
    the sub-steps is ill-posed: two edges crossed at once, the split limit, a stage that cannot
    be put on its side)."""

    value: float | np.ndarray
    stderr: float | np.ndarray
    n_blocks: int
    unresolved: int = 0
    status: Status = Status.OK
    duration: float = math.nan
    duration_rule: str = ""
    tangent: str = ""
    difference_steps: int = 0

    @property
    def ok(self) -> bool:
        """Whether the run ended cleanly (:attr:`~geardyn.Status.OK`)."""
        return self.status == Status.OK


def lyapunov_err_attrs(time_unit: str) -> dict[str, str]:
    """Attributes of a dataset's ``lyapunov_err`` variable (the standard error of ``lyapunov``)."""
    return {
        "long_name": "standard error of the largest Lyapunov exponent",
        "units": f"1/{time_unit}",
        "meaning": "1-sigma statistical error of the finite-time exponent per unit model time; "
                   "NaN where lyapunov is NaN",
        "method": f"batch means: the measuring window cut into n = {LYAPUNOV_BLOCKS} blocks of "
                  "whole forcing periods (fewer if shorter), std(block rates, ddof=1) / "
                  "sqrt(n); see docs/lyapunov.md, Uncertainty"}


def lyapunov_unresolved_attrs() -> dict[str, str]:
    """Attributes of a dataset's ``lyapunov_unresolved`` variable."""
    return {
        "long_name": "grid steps of the Lyapunov run that reached the edge-split limit",
        "units": "1",
        "meaning": "steps of the state or of a finite-difference neighbour integrated unsplit "
                   "across an edge (chattering); > 0: the exponent is kept but less accurate "
                   "(geardyn.Status.SPLIT_LIMIT)"}


def lyapunov_variational(model: Model, settings: LyapunovSettings | None = None) -> bool:
    """Whether the tangent vectors of ``model`` are advanced by the variational RK4 under
    ``settings.tangent`` (``"auto"``: where the model is written in the one form); a
    :class:`~geardyn.errors.ParameterError` naming ``settings.tangent`` where it asks for
    ``"variational"`` of a model without a one form."""
    tangent = (settings or LyapunovSettings()).tangent
    has = model.kernel.one_form is not None
    if tangent == "variational" and not has:
        raise ParameterError("settings.tangent", tangent,
                             f"{type(model).__name__} is not written in the one form (no rhs "
                             "to differentiate); give 'difference' or 'auto'")
    return has and tangent != "difference"


@contextmanager
def _dual_typing(variational: bool, ls: LyapunovSettings) -> Iterator[None]:
    """A ParameterError naming ``settings.tangent`` where the variational kernel does not
    compile because the model's one-form rhs does not take dual numbers (an operation that
    :mod:`geardyn.core.dual` lacks); numba's error chained."""
    try:
        yield
    except numba.core.errors.TypingError as exc:
        if not variational:
            raise
        raise ParameterError("settings.tangent", ls.tangent,
                             "the model's one-form rhs does not take dual numbers (an operation "
                             "geardyn.core.dual lacks: see the chained error); give "
                             "'difference'") from exc


#: The argument types the variational kernels' ``rhs_tangent`` (t, y, v, dy, dv, p, s, c; see
#: :func:`geardyn.core.one_form.tangent_adapters`) is called with in the Lyapunov kernel (a
#: tuple of types: numba keys its disk cache by the signature as given, so that a text would
#: miss the kernel's cached compile).
_TANGENT_SIGNATURE = signature_types("(float64, float64[::1], float64[::1], float64[::1], "
                                     "float64[::1], float64[::1], float64, float64)")


def _check_duals(model: Model, variational: bool, ls: LyapunovSettings) -> None:
    """Where the tangent is variational, the model's tangent form of its rhs compiled alone
    first (as the kernel calls it; cached like the kernel's functions; a pointer model's
    Lyapunov callbacks, :func:`geardyn.solvers.kernels.compile_tangent`), so that a one-form rhs
    the dual numbers cannot take is refused (:func:`_dual_typing`) before any kernel compiles."""
    if variational:
        with _dual_typing(True, ls):
            compile_tangent(model.kernel, _TANGENT_SIGNATURE)


def lyapunov_tangent(variational: bool) -> str:
    """The ``tangent`` attribute of a Lyapunov result: how its tangent vectors were advanced."""
    if variational:
        return ("variational: the exact derivative of the RK4 step map (dual numbers through "
                "the model's one form); a step split at an edge crossing through its sub-steps, "
                "moved to the orbit's crossing at each split point")
    return "difference: central differences of the RK4 step map at every step"


def _duration(model: Model, ls: LyapunovSettings) -> tuple[float | None, str]:
    """The time averaged over (None: :data:`LYAPUNOV_PERIODS` forcing periods of each lane)
    and its rule: ``ls.duration``, else the model's default scale."""
    if ls.duration is not None:
        return ls.duration, "LyapunovSettings.duration"
    return model.lyapunov_duration()


def _periods_transient(model: Model, run: RunSettings | None, keywords: dict[str, Any]
                       ) -> bool:
    """Whether the transient is the default in forcing periods
    (:data:`LYAPUNOV_TRANSIENT_PERIODS`): no run and no transient given, a forced model of
    physical time (its default of :data:`LYAPUNOV_DEFAULTS` is in dimensionless time)."""
    return (run is None and "transient" not in keywords and not model.dimensionless_time
            and model.omega_index is not None)


def _check_blocks(n_blocks: int) -> int:
    n = int(n_blocks)
    if n < 2:
        raise ValueError(f"n_blocks must be >= 2 (got {n_blocks!r})")
    return n


def _initial(model: Model, y0) -> np.ndarray:
    y = np.asarray(model.initial_state() if y0 is None else y0, dtype=float).ravel().copy()
    if y.shape != (model.n_states,):
        raise ValueError(f"y0 must have {model.n_states} entries ({', '.join(model.state_names)})")
    if not np.all(np.isfinite(y)):
        raise ValueError("y0 must be finite")
    return y


def _state_scale(model: Model) -> np.ndarray:
    """The model's characteristic state scale (:attr:`Model.state_scale`), checked: the
    tangent vectors of the Lyapunov kernel live in y / scale."""
    s = np.ascontiguousarray(np.asarray(model.state_scale, dtype=float).ravel())
    if s.shape != (model.n_states,) or not np.all(np.isfinite(s) & (s > 0)):
        raise ValueError(f"{type(model).__name__}.state_scale must hold {model.n_states} finite "
                         f"positive numbers (got {model.state_scale!r})")
    return s


#: The :class:`~geardyn.LyapunovSettings` fields (deprecated as keywords of :func:`lyapunov`).
SETTINGS_FIELDS = tuple(f.name for f in dataclasses.fields(LyapunovSettings))


def _autonomous_step(steps_per_period: int | None, dt: float | None) -> float:
    """The step of an autonomous model's Lyapunov run: ``dt`` (default
    :data:`~geardyn.core.settings.LYAPUNOV_DT`); a ValueError where the run gives steps per
    period instead."""
    if steps_per_period is not None:
        raise ValueError("steps_per_period applies to forced models; give dt instead")
    h = LYAPUNOV_DT if dt is None else float(dt)
    if not (h > 0 and math.isfinite(h)):
        raise ValueError(f"dt must be > 0 (got {dt!r})")
    return h


def _lyapunov_run(run: RunSettings | None, settings: LyapunovSettings | None,
                  keywords: dict[str, Any], where: str) -> tuple[RunSettings, LyapunovSettings]:
    """The run and Lyapunov settings of :func:`lyapunov` and :func:`lyapunov_lanes` (``where``:
    the function's name): ``run``, or the run keywords (``transient``, ``steps_per_period``,
    ``locate_edges``, ``bound``) on :data:`LYAPUNOV_DEFAULTS`, and ``settings`` (its fields as
    keywords: deprecated, one DeprecationWarning pointing at the public function's caller,
    naming both replacements where both kinds of keywords are given)."""
    extra = sorted(set(keywords) - set(LYAPUNOV_FIELDS) - set(SETTINGS_FIELDS))
    if extra:
        raise TypeError(f"{where}() got an unexpected keyword argument {extra[0]!r} (run "
                        f"settings it uses: {', '.join(LYAPUNOV_FIELDS)})")
    legacy = {k: v for k, v in keywords.items() if k in SETTINGS_FIELDS}
    given = {k: v for k, v in keywords.items() if k in LYAPUNOV_FIELDS}
    if not (legacy and given):
        return (resolve_run(run, given, LYAPUNOV_DEFAULTS, where=where, stacklevel=4),
                resolve_settings(LyapunovSettings, settings, legacy, where, stacklevel=4))
    out = (resolve_run(run, given, LYAPUNOV_DEFAULTS),  # where=None: no warning of its own
           resolve_settings(LyapunovSettings, settings, legacy, where, warn=False))
    warn_deprecated(where, [*given, *legacy],
                    [replacement("run", RunSettings, {**LYAPUNOV_DEFAULTS, **given}),
                     replacement("settings", LyapunovSettings, legacy)], stacklevel=3)
    return out


def lyapunov(
    model: Model,
    y0=None,
    run: RunSettings | None = None,
    *,
    settings: LyapunovSettings | None = None,
    spectrum: bool = False,
    t0: float = 0.0,
    with_error: bool = False,
    **keywords: Any,
) -> float | np.ndarray | LyapunovEstimate:
    """Largest Lyapunov exponent of ``model`` (or the whole spectrum), per unit model time.

    Parameters
    ----------
    run
        The run settings, :class:`~geardyn.RunSettings`; of its fields ``transient``,
        ``steps_per_period``, ``locate_edges`` and ``bound`` are used (the measuring window is
        ``duration``, not ``samples``). Those four as keyword arguments instead (not together
        with ``run``) are deprecated: one DeprecationWarning naming the equivalent
        ``run=geardyn.RunSettings(...)``. Without either, ``transient`` is 100 time units (not
        RunSettings' 4000; for a forced model of physical time
        :data:`~geardyn.core.settings.LYAPUNOV_TRANSIENT_PERIODS` forcing periods) and the rest
        RunSettings' defaults.
    y0
        Initial state (default: ``model.initial_state()``), at time ``t0``.
    t0
        Time of ``y0``, in the model's time unit (default 0). The forcing phase (Omega) is zero
        at t0, as in every solver of the package (a lane started at T0 samples its Poincare
        points at T0 + whole periods); every other time-dependent term, e.g. a load fluctuation
        sin(Lambda t), sees the absolute time, from t0 on. So a Poincare point of a run and
        its time (a sweep's ``final_time``) continue that run in both forcing phases, on its own
        attractor. A state at another forcing phase cannot be started (the phase is tabulated
        on the period-aligned grid from zero).
    settings
        :class:`~geardyn.LyapunovSettings`: ``duration`` (time averaged over; default the
        model's scale, :meth:`geardyn.Model.lyapunov_duration`: 2000 time units of a
        dimensionless model, 200 forcing periods of one in seconds), ``dt`` (step of
        an autonomous model), ``renorm_every``, ``n_blocks``, ``tangent`` (how the tangent
        vectors are advanced: ``"auto"``, variational where the model is written in the one
        form; see :class:`~geardyn.LyapunovSettings`). Its fields given as keyword
        arguments are deprecated (a DeprecationWarning).
    transient, duration
        Time discarded first (``run.transient``) and time averaged over (``settings.duration``),
        in the model's time unit. For a forced model both are rounded up to whole forcing
        periods.
    spectrum
        False: the largest exponent (one tangent vector), a float. True: all ``n_states``
        exponents, in descending order, as an array.
    dt
        ``settings.dt``: step of an autonomous model (``model.omega == 0``; default 0.01).
        Not used for a forced
        model, whose grid has ``run.steps_per_period`` steps per forcing period (default
        :func:`~geardyn.core.plan.default_steps_per_period`), as in ``simulate``.
    locate_edges
        ``run.locate_edges``: locate the model's edge crossings inside steps (default True;
        False integrates across them, as ``simulate`` does then).
    renorm_every
        ``settings.renorm_every``: RK4 steps between re-orthonormalisations (default 10).
    bound
        ``run.bound``: a state beyond this magnitude counts as diverged; the result is then NaN.
    with_error
        True: return a :class:`LyapunovEstimate` (value, stderr, n_blocks, unresolved, status)
        instead, the standard error from the spread of the rates over ``settings.n_blocks``
        blocks of
        the measuring window (see ``docs/lyapunov.md``, "Uncertainty"). Without it, a run with
        steps at the edge-split limit (status SPLIT_LIMIT) warns (RuntimeWarning).

    For a forced model the exponent of the flow's zero direction (along the forcing phase) is not
    included: the phase is not a state, so a forced model with n states has n exponents.
    """
    in_periods = _periods_transient(model, run, keywords)
    run, ls = _lyapunov_run(run, settings, keywords, "lyapunov")
    variational = lyapunov_variational(model, ls)
    _check_duals(model, variational, ls)
    steps_per_period, bound = run.steps_per_period, run.bound
    dt, renorm_every, n_blocks = ls.dt, ls.renorm_every, ls.n_blocks
    duration, rule = _duration(model, ls)
    y = _initial(model, y0)
    t0 = float(t0)
    if not math.isfinite(t0):
        raise ValueError(f"t0 must be finite (got {t0!r})")
    n_blk = _check_blocks(n_blocks)
    om = model.omega
    if om == 0.0:
        lanes = LaneSettings(t0=t0, ladder=False, interval=_autonomous_step(steps_per_period, dt),
                             steps_per_period=1)
    else:
        check_omega(om)
        if dt is not None:
            raise ValueError("dt applies to autonomous models; give steps_per_period instead")
        lanes = LaneSettings(t0=t0, ladder=False, sample_every=1)
    plan = LanePlan.build(model, np.asarray(model.params, dtype=float)[None, :], run, lanes)
    n_per, h = int(plan.steps_per_period[0]), float(plan.step[0])
    n_tr = LYAPUNOV_TRANSIENT_PERIODS * n_per if in_periods else int(plan.transient_steps[0])
    n_st = (LYAPUNOV_PERIODS * n_per if duration is None
            else int(plan.window_steps(duration)[0]))
    renorm = int(LYAPUNOV_RENORM_EVERY if renorm_every is None else renorm_every)
    if renorm < 1:
        raise ValueError(f"renorm_every must be >= 1 (got {renorm_every!r})")
    k = model.n_states if spectrum else 1
    kern = kernels_for(model.kernel, "lyapunov")
    p = np.ascontiguousarray(model.params, dtype=float)
    n_ev = model.n_events if run.locate_edges else 0
    scale = _state_scale(model)
    # one lane of the lane blocks (the kernels of lyapunov_lanes and bifurcation(...,
    # lyapunov=True)), with k tangent vectors
    ex, er = np.full((1, k), np.nan), np.full((1, k), np.nan)
    used, code, unres, n_fd = (np.zeros(1, np.int64) for _ in range(4))
    with _dual_typing(variational, ls):
        kern.lyapunov_block_lanes(
            p[None, :], y[None, :], scale, np.array([t0]), np.array([h]), np.array([float(om)]),
            np.array([n_per], np.int64), np.array([n_tr], np.int64), np.array([n_st], np.int64),
            renorm, k, float(bound), ex, er, used, code, unres, n_ev, n_blk, kern.BLOCK_ROWS, 1,
            variational, n_fd)
    ex, er, used, code, unres, n_fd = ex[0], er[0], used[0], code[0], unres[0], n_fd[0]
    status = Status(int(code))
    ex = np.asarray(ex, dtype=float)
    er = np.asarray(er, dtype=float)
    if spectrum:
        order = np.argsort(ex, kind="stable")[::-1]
        value, err = ex[order].copy(), er[order].copy()
    else:
        value, err = float(ex[0]), float(er[0])
    if with_error:
        return LyapunovEstimate(value, err, int(used), int(unres), status, n_st * h, rule,
                                lyapunov_tangent(variational), int(n_fd))
    if status == Status.SPLIT_LIMIT:
        warnings.warn(f"lyapunov: {int(unres)} grid steps reached the edge-split limit and were "
                      "integrated unsplit across an edge (status SPLIT_LIMIT); the exponent is "
                      "less accurate (with_error=True reports it)", RuntimeWarning, stacklevel=2)
    return value


def lyapunov_lanes(
    model: Model,
    P: np.ndarray,
    y0=None,
    run: RunSettings | None = None,
    *,
    settings: LyapunovSettings | None = None,
    t0: float | np.ndarray = 0.0,
    with_error: bool = False,
    with_status: bool = False,
    **keywords: Any,
) -> np.ndarray | tuple[np.ndarray, ...]:
    """Largest Lyapunov exponent for each row of the coefficient matrix ``P`` (lanes x n_params,
    e.g. from ``model.lane_params``), computed in parallel; NaN for diverged lanes.

    ``y0``: one initial state for all lanes, or one per lane (lanes x n_states); default
    ``model.initial_state()``. ``run`` and ``settings`` as in :func:`lyapunov`: of the
    :class:`~geardyn.RunSettings` ``transient``, ``steps_per_period``, ``locate_edges`` and
    ``bound`` are used (as keyword arguments, not together with ``run``: deprecated; without either,
    ``transient`` is 100 time units, or for a forced model of physical time
    :data:`~geardyn.core.settings.LYAPUNOV_TRANSIENT_PERIODS` forcing periods of each lane), of
    the :class:`~geardyn.LyapunovSettings` ``duration``, ``dt``, ``renorm_every``, ``n_blocks``
    and ``tangent`` (its fields as keyword arguments: deprecated, a DeprecationWarning).
    ``transient`` and ``duration`` are times, rounded up to whole forcing periods of each lane
    (lanes differ in Omega, so their step counts differ). The grid has
    ``steps_per_period`` steps per period (default: each lane's own
    :func:`default_steps_per_period`, rounded up to the sweep's step ladder, as in
    :func:`~geardyn.solvers.ensemble.run_lanes`); an autonomous model uses the step ``dt``
    (default 0.01).

    ``t0``: the time of ``y0``, one for all lanes or one per lane (model time units; forcing
    phase zero there, as in :func:`lyapunov`): a sweep's ``LaneResults.final_time`` continues
    each lane in both forcing phases. ``with_error``: return ``(exponents, stderr)``, the standard
    errors from ``n_blocks`` blocks as in :func:`lyapunov` (NaN where the exponent is NaN).
    ``with_status``: return ``(exponents, stderr, unresolved, status)`` (whatever
    ``with_error``): per lane the steps at the edge-split limit and the
    :class:`~geardyn.Status` code (as in :class:`LyapunovEstimate`; exponents kept where
    SPLIT_LIMIT, NaN where DIVERGED).
    """
    in_periods = _periods_transient(model, run, keywords)
    run, ls = _lyapunov_run(run, settings, keywords, "lyapunov_lanes")
    variational = lyapunov_variational(model, ls)
    _check_duals(model, variational, ls)
    steps_per_period, bound = run.steps_per_period, run.bound
    dt, renorm_every, n_blocks = ls.dt, ls.renorm_every, ls.n_blocks
    duration, _ = _duration(model, ls)
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    L = P.shape[0]
    if P.shape[1] != model.params.size:
        raise ValueError(f"P must have {model.params.size} columns (got {P.shape[1]})")
    if model.omega_index is not None:
        check_omega(P[:, model.omega_index])
    if not np.all(np.isfinite(P)):
        raise ValueError("P must be finite")
    if y0 is None:
        Y0 = np.tile(model.initial_state(), (L, 1))
    else:
        Y0 = np.asarray(y0, dtype=float)
        Y0 = np.tile(Y0, (L, 1)) if Y0.ndim == 1 else Y0.copy()
    if Y0.shape != (L, model.n_states):
        raise ValueError(f"y0 must have {model.n_states} entries or shape ({L}, {model.n_states})")
    Y0 = np.ascontiguousarray(Y0)
    T0 = np.ascontiguousarray(np.broadcast_to(np.asarray(t0, dtype=float), (L,)))
    if not np.all(np.isfinite(T0)):
        raise ValueError("t0 must be finite")
    n_blk = _check_blocks(n_blocks)
    if model.omega_index is None:
        lanes = LaneSettings(t0=T0, interval=_autonomous_step(steps_per_period, dt),
                             steps_per_period=1)
    else:
        if dt is not None:
            raise ValueError("dt applies to autonomous models; give steps_per_period instead")
        lanes = LaneSettings(t0=T0, sample_every=1)
    plan = LanePlan.build(model, P, run, lanes)
    OMEGA, H, n_per = plan.omega, plan.step, plan.steps_per_period
    n_tr = (LYAPUNOV_TRANSIENT_PERIODS * n_per).astype(np.int64) if in_periods else (
        plan.transient_steps)
    n_st = ((LYAPUNOV_PERIODS * n_per).astype(np.int64) if duration is None
            else plan.window_steps(duration))
    renorm = int(LYAPUNOV_RENORM_EVERY if renorm_every is None else renorm_every)
    if renorm < 1:
        raise ValueError(f"renorm_every must be >= 1 (got {renorm_every!r})")
    out = np.full(L, np.nan)
    err = np.full(L, np.nan)
    unres = np.zeros(L, np.int64)
    status = np.zeros(L, np.int64)
    if L > 0:
        scale = _state_scale(model)
        kern = kernels_for(model.kernel, "lyapunov")
        # lanes of every grid together (the kernel blocks them, whatever their steps)
        n_ev = model.n_events if run.locate_edges else 0
        with _dual_typing(variational, ls):
            kern.lyapunov_lanes(P, Y0, scale, T0, H, OMEGA, n_per, n_tr, n_st, renorm,
                                float(bound), out, err, n_ev, n_blk, unres, status, variational)
    if with_status:
        return out, err, unres, status
    return (out, err) if with_error else out
