"""Periodic orbits of the stroboscopic map by Newton shooting, with their Floquet multipliers.

A period-k orbit is a fixed point of P^k, P the stroboscopic (section) map over one section
period T_s (the forcing period T, or the common period q T of the forcing and a second
excitation, as the sweeps sample: :func:`geardyn.core.plan.lane_section`). It is found by
Newton's method on F(x) = phi_{k T_s}(x) - x, whose Jacobian is M - I with M the monodromy
matrix (the Jacobian of the period map).

The monodromy
-------------
M is the Jacobian of the *discrete* period map that the package integrates (fixed-step RK4 on
the forcing-aligned grid, every step split at the located dead-zone edges), built step by step
by the ``monodromy`` kernel (:mod:`geardyn.solvers._monodromy_template`): the columns of M are
tangent vectors advanced by central differences of each grid step's map, the perturbed states
locating their own edge crossings. Why this method:

* it is the exact derivative (to the difference's O(e^2), e ~ 1e-6 of the state scale, and
  rounding ~1e-10 per step) of the map whose fixed point Newton seeks, so Newton converges
  quadratically and the multipliers belong to the orbit that was found;
* it needs no Jacobian from the model (any :class:`~geardyn.Model`, a user's too), and it
  switches exactly at each edge since the perturbed states cross it themselves; the dead-zone
  force is continuous, so the flow is C^1 and no saltation (jump) matrix is needed;
* one call returns P(x) and M together (cost: 2 n + 1 integrations of the period for n
  states), with no finite difference over a whole period (whose error would grow with the
  orbit's instability).

The multipliers are those of the RK4 map, so their error is the integrator's (4th order in
the step); the default step of an orbit is :data:`ORBIT_STEP_FACTOR` times the sweeps' step
rule, which puts the monodromy of the tests' cases within ~1e-9 of the variational equations'
(``docs/periodic-orbits.md``).

Liouville's formula: det M = exp(integral over the period of the trace of the Jacobian of the
vector field). For the built-in models the trace is minus the sum of the damping coefficients
(a constant; stiffness and dead zone act on displacements only); :func:`jacobian_trace`
computes it for any model by central differences of the right-hand side.

Lower level, for continuation: :class:`ShootingProblem` (``evaluate(x)`` gives the residual and
the Jacobian for a state at a coefficient vector; ``with_params(p)`` moves the parameters) and
:func:`newton_shooting`.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace
from enum import IntEnum
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from geardyn.analysis.contact import contact_regime
from geardyn.analysis.lanes import has_mesh_forces, variable_attrs
from geardyn.core.plan import default_steps_per_period, forcing_period, lane_section
from geardyn.core.results import finish
from geardyn.core.settings import (
    DEFAULT_BOUND,
    INTEGRATOR,
    NEWTON_MAX_ITER,
    NEWTON_TOL,
    NewtonSettings,
    RunSettings,
    check_omega,
    resolve_settings,
)
from geardyn.core.status import Status, status_meaning
from geardyn.solvers.kernels import kernels_for

if TYPE_CHECKING:
    from geardyn.core.model import Model

#: The orbit's default step: this many times the sweeps' step rule
#: (:func:`geardyn.core.plan.default_steps_per_period`), for multipliers to ~1e-9.
ORBIT_STEP_FACTOR = 4
#: Default transient of the default guess, in section periods.
GUESS_PERIODS = 200
#: NEWTON_TOL, NEWTON_MAX_ITER (from core.settings, NewtonSettings' defaults): converged where
#: max |F(x) / state_scale| <= tol (1 + max |x / state_scale|), in at most max_iter iterations.
#: Smallest damping factor of a Newton step before it counts as failed.
MIN_DAMPING = 2.0**-10
#: A multiplier within this of the unit circle makes the verdict "marginal".
MARGINAL = 1e-6
#: Most grid points recorded along an orbit (every grid point up to this many; else every
#: n-th, n the least that keeps the count below it).
MAX_ORBIT_POINTS = 200_000
#: Most points of the orbit at which the trace of the Jacobian is evaluated (Liouville).
TRACE_POINTS = 256


class OrbitStatus(IntEnum):
    """Outcome of the Newton shooting."""

    CONVERGED = 0
    NOT_CONVERGED = 1
    DIVERGED = 2
    SINGULAR = 3

    @property
    def message(self) -> str:
        return _ORBIT_MESSAGES[self]


_ORBIT_MESSAGES = {
    OrbitStatus.CONVERGED: "converged",
    OrbitStatus.NOT_CONVERGED: "Newton did not converge",
    OrbitStatus.DIVERGED: "the integration diverged (|state| > bound or not finite)",
    OrbitStatus.SINGULAR: "M - I is singular (a multiplier at +1: a fold or a symmetry)",
}


def orbit_status_meaning() -> str:
    """The orbit status codes as one attribute string."""
    return ", ".join(f"{int(s)} {s.message}" for s in OrbitStatus)


# ----------------------------------------------------------------------------- the problem
@dataclass(frozen=True)
class ShootingEval:
    """One evaluation of the period map at x: ``end`` = P^k(x), ``residual`` = end - x,
    ``monodromy`` = dP^k/dx (NaN when not asked), ``states`` (the state at every recorded grid
    point, from x to end), ``crossings`` (edge crossings of the state, per event),
    ``status`` (:class:`~geardyn.Status`), ``unresolved`` (steps at the split limit)."""

    x: np.ndarray
    end: np.ndarray
    monodromy: np.ndarray
    states: np.ndarray
    crossings: np.ndarray
    status: Status
    unresolved: int

    @property
    def ok(self) -> bool:
        """Whether the integration ended cleanly (:attr:`~geardyn.Status.OK`)."""
        return self.status == Status.OK

    @property
    def residual(self) -> np.ndarray:
        return self.end - self.x

    @property
    def jacobian(self) -> np.ndarray:
        """The Jacobian of the residual, M - I."""
        return self.monodromy - np.eye(self.x.size)


@dataclass(frozen=True)
class ShootingProblem:
    """The period-k map of one model at one coefficient vector, on a fixed grid.

    ``params``: the coefficient vector; ``omega``: the forcing frequency (from ``params``);
    ``sections``: forcing periods per section (q); ``period``: sections per orbit (k);
    ``steps_per_period``: RK4 steps per forcing period; ``t0``: start time (forcing phase zero);
    ``section_limit``: the longest common period taken as a section (None: the default).
    ``model`` holds ``params`` (a copy of the model's, set by :meth:`with_params`).
    """

    model: Any
    params: np.ndarray
    omega: float
    period: int
    sections: int
    steps_per_period: int
    bound: float = DEFAULT_BOUND
    t0: float = 0.0
    scale: np.ndarray = field(default=None)  # type: ignore[assignment]
    section_limit: int | None = None

    def __post_init__(self) -> None:
        if self.scale is None:
            object.__setattr__(self, "scale", np.asarray(self.model.state_scale, dtype=float))

    @property
    def forcing_periods(self) -> int:
        """Forcing periods in one orbit period, k q."""
        return self.period * self.sections

    @property
    def n_steps(self) -> int:
        return self.forcing_periods * self.steps_per_period

    @property
    def step(self) -> float:
        return forcing_period(self.omega) / self.steps_per_period

    @property
    def duration(self) -> float:
        """The orbit's period in model time, k q T."""
        return self.forcing_periods * forcing_period(self.omega)

    def with_params(self, params: np.ndarray) -> ShootingProblem:
        """The same problem at another coefficient vector (Omega read from it, the section
        re-derived; the same steps per forcing period), e.g. for a continuation step. Raises
        ValueError where the forcings have no common period."""
        p = np.ascontiguousarray(params, dtype=float).copy()
        om = float(p[self.model.omega_index])
        check_omega(om)
        every, ok = lane_section(self.model, p[None, :], np.array([om]), self.section_limit)
        if not ok[0]:
            raise ValueError(f"at Omega={om:g} the forcings have no common period")
        model = copy.copy(self.model)  # derived quantities (static forces) follow params
        model.params = p
        return replace(self, model=model, params=p, omega=om, sections=int(every[0]))

    def evaluate(self, x: np.ndarray, jacobian: bool = True, stride: int | None = None
                 ) -> ShootingEval:
        """P^k(x), with the monodromy when ``jacobian``; the states every ``stride`` grid
        steps (default: only the ends)."""
        x = np.ascontiguousarray(x, dtype=float)
        k = kernels_for(self.model.kernel, "monodromy")
        stride = self.n_steps if stride is None else int(stride)
        end, M, Y, nc, st, unres = k.period_map(
            self.params, x, np.ascontiguousarray(self.scale), self.t0, self.step, self.omega,
            self.steps_per_period, self.n_steps, self.model.n_events, self.bound, stride,
            bool(jacobian))
        return ShootingEval(x.copy(), end, M, Y, np.asarray(nc), Status(int(st)), int(unres))


def orbit_steps(run: RunSettings | None, steps_per_period: int | None, where: str
                ) -> int | None:
    """The fixed step of an orbit analysis (None: its default): ``run.steps_per_period``, or
    the keyword ``steps_per_period`` of a call without ``run`` (the run-less defaults of the
    guess have no RunSettings equivalent, so the keyword stays for that call). Both together
    raise a TypeError naming both values, as
    :func:`~geardyn.core.settings.resolve_run` refuses ``run=`` beside a run keyword."""
    if not steps_per_period:
        return None if run is None else run.steps_per_period
    if run is not None:
        raise TypeError(f"{where}: give the step either as run=RunSettings(steps_per_period="
                        f"...) or as steps_per_period=, not both (got run.steps_per_period="
                        f"{run.steps_per_period!r} and steps_per_period={steps_per_period!r})")
    return steps_per_period


def shooting_problem(model: Model, omega: float | None = None, period: int = 1,
                     run: RunSettings | None = None, steps_per_period: int | None = None
                     ) -> ShootingProblem:
    """The :class:`ShootingProblem` of ``model`` at ``omega`` (default the model's): period-k
    orbits of the section map (the common period of the forcings where there are two,
    :func:`geardyn.core.plan.lane_section`), with ``run.steps_per_period`` or, without
    ``run``, ``steps_per_period`` (not both, see :func:`orbit_steps`; default
    :data:`ORBIT_STEP_FACTOR` times the step rule)."""
    steps = orbit_steps(run, steps_per_period, "shooting_problem")
    return problem_with_steps(model, omega, period, run, steps)


def problem_with_steps(model: Model, omega: float | None, period: int,
                       run: RunSettings | None, steps: int | None) -> ShootingProblem:
    """:func:`shooting_problem` with the step already resolved (``steps``; None: the
    default), the rest (bound, section limit) from ``run``."""
    if omega is not None:
        model = model.with_omega(float(omega))
    om = model.omega
    if model.omega_index is None:
        raise ValueError("periodic_orbit needs a periodically forced model")
    check_omega(om)
    if isinstance(period, bool) or int(period) != period or period < 1:
        raise ValueError(f"period must be a whole number >= 1 (got {period!r})")
    P = np.atleast_2d(model.params)
    limit = None if run is None else run.max_section_periods
    every, commensurate = lane_section(model, P, np.array([om]), limit)
    if not commensurate[0]:
        raise ValueError(f"{model.name} at Omega={om:g}: the forcings have no common period "
                         f"(quasi-periodic forcing), so there is no periodic orbit to find")
    n = steps
    if n is None:
        n = ORBIT_STEP_FACTOR * default_steps_per_period(model, om)
    bound = DEFAULT_BOUND if run is None else run.bound
    return ShootingProblem(model, np.ascontiguousarray(model.params, dtype=float).copy(), om,
                           int(period), int(every[0]), int(n), bound, section_limit=limit)


# ----------------------------------------------------------------------------- Newton
@dataclass(frozen=True)
class NewtonResult:
    """The outcome of :func:`newton_shooting`: the last iterate ``x``, its evaluation (with the
    monodromy), the iterations, the residual norm (scaled, max norm) after each, the status
    and a message."""

    x: np.ndarray
    evaluation: ShootingEval
    iterations: int
    residuals: tuple[float, ...]
    status: OrbitStatus
    message: str


def _fold_hint(M: np.ndarray) -> str:
    """A note for a failed Newton whose last monodromy has a real multiplier near +1 (within
    0.05): past a fold the orbit may not exist at this parameter."""
    if not np.all(np.isfinite(M)):
        return ""
    mu = np.linalg.eigvals(M)
    d = np.abs(mu - 1.0)
    k = int(np.argmin(d))
    if d[k] < 0.05:
        return (f"; a multiplier near +1 ({mu[k].real:.4g}): near a fold (turning point) the "
                f"orbit may not exist here (continue in arclength)")
    return ""


def _fmt(x: np.ndarray) -> str:
    """A state for a message (6 significant digits, at most 8 entries shown)."""
    return np.array2string(np.asarray(x), precision=6, threshold=8, edgeitems=4,
                           max_line_width=10_000)


def _norm(v: np.ndarray, scale: np.ndarray) -> float:
    return float(np.max(np.abs(v / scale))) if v.size else 0.0


def _accepted_trial(problem: ShootingProblem, x: np.ndarray, r: float
                    ) -> ShootingEval | None:
    """The evaluation with monodromy at the Newton trial ``x`` where it lowers the scaled
    residual below ``r`` (and its monodromy is finite), else None. The trial is first run
    without the monodromy: the state is stepped the same either way, so a rejected trial costs
    one integration of the state, not the 2 n + 1 rows of the difference monodromy."""
    s = problem.scale
    cheap = problem.evaluate(x, jacobian=False)
    if not (cheap.ok and _norm(cheap.residual, s) < r):
        return None
    trial = problem.evaluate(x)
    return trial if trial.ok and _norm(trial.residual, s) < r else None


def newton_shooting(problem: ShootingProblem, x0: np.ndarray, tol: float = NEWTON_TOL,
                    max_iter: int = NEWTON_MAX_ITER) -> NewtonResult:
    """Damped Newton on F(x) = P^k(x) - x with Jacobian M - I.

    A full step is taken when it lowers the scaled residual max |F / state_scale|, else it is
    halved down to :data:`MIN_DAMPING`. Converged when the residual is at most
    ``tol (1 + max |x / state_scale|)``. Never raises on a numerical failure: the status says
    what happened (:class:`OrbitStatus`) and the message where."""
    s = problem.scale
    x = np.asarray(x0, dtype=float).copy()
    nan = np.full((x.size, x.size), np.nan)
    ev = ShootingEval(x, np.full(x.size, np.nan), nan, np.full((1, x.size), np.nan),
                      np.zeros(problem.model.n_events, np.int64), Status.DIVERGED, 0)
    history: list[float] = []
    if not np.all(np.isfinite(x)):
        return NewtonResult(x, ev, 0, (), OrbitStatus.DIVERGED,
                            f"the starting state is not finite ({_fmt(x)}): the guess's "
                            f"transient run diverged?")
    ev = problem.evaluate(x)

    def done(status: OrbitStatus, msg: str) -> NewtonResult:
        if status == OrbitStatus.NOT_CONVERGED:
            msg += _fold_hint(ev.monodromy)
        return NewtonResult(x, ev, len(history) - 1 if history else 0, tuple(history), status,
                            msg)

    for it in range(max_iter + 1):
        if not ev.ok:
            return done(OrbitStatus.DIVERGED, f"the period map diverged from x={_fmt(x)} "
                                              f"(iteration {it})")
        r = _norm(ev.residual, s)
        history.append(r)
        if r <= tol * (1.0 + _norm(x, s)):
            return done(OrbitStatus.CONVERGED, f"converged: residual {r:.3g} after {it} "
                                               f"iterations")
        if it == max_iter:
            break
        J = ev.jacobian
        try:
            dx = np.linalg.solve(J, -ev.residual)
        except np.linalg.LinAlgError:
            return done(OrbitStatus.SINGULAR, f"M - I is singular at x={_fmt(x)} "
                                              f"(iteration {it})")
        if not np.all(np.isfinite(dx)) or np.linalg.cond(J) > 1e14:
            return done(OrbitStatus.SINGULAR, f"M - I is numerically singular at "
                                              f"x={_fmt(x)} (iteration {it})")
        lam = 1.0
        while True:
            trial = _accepted_trial(problem, x + lam * dx, r)
            if trial is not None:
                x, ev = trial.x, trial
                break
            lam *= 0.5
            if lam < MIN_DAMPING:
                return done(OrbitStatus.NOT_CONVERGED,
                            f"Newton stalled at iteration {it}: no step down to "
                            f"{MIN_DAMPING:g} of the Newton step lowers the residual "
                            f"{r:.3g} (x={_fmt(x)})")
    return done(OrbitStatus.NOT_CONVERGED, f"Newton did not converge in {max_iter} iterations: "
                                           f"residual {history[-1]:.3g} (tolerance {tol:g})")


# ----------------------------------------------------------------------------- Liouville
def jacobian_trace(model: Model, t: float, y: np.ndarray, params: np.ndarray | None = None,
                   rel: float = 1e-6) -> float:
    """The trace of the Jacobian of the model's vector field at (t, y), by central differences
    of ``rhs`` (per unit model time). For the built-in models it is constant, minus the sum of
    the damping coefficients; Liouville: det M = exp(integral of it over the period)."""
    k = kernels_for(model.kernel)
    p = np.ascontiguousarray(model.params if params is None else params, dtype=float)
    om = float(p[model.omega_index]) if model.omega_index is not None else 0.0
    s, c = math.sin(om * t), math.cos(om * t)
    scale = np.asarray(model.state_scale, dtype=float)
    y = np.asarray(y, dtype=float)
    up, dn = np.empty(y.size), np.empty(y.size)
    tr = 0.0
    for q in range(y.size):
        e = rel * scale[q] * (1.0 + abs(y[q] / scale[q]))
        a, b = y.copy(), y.copy()
        a[q] += e
        b[q] -= e
        k.rhs(t, a, up, p, s, c)
        k.rhs(t, b, dn, p, s, c)
        tr += (up[q] - dn[q]) / (2.0 * e)
    return tr


# ----------------------------------------------------------------------------- the result
@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of the section map and its stability (see :func:`periodic_orbit`).

    ``x``: the section point (state at time ``t0``, forcing phase zero); ``times`` and
    ``states``: the orbit at every grid point of one orbit period (k q forcing periods, both
    ends included; every n-th where there would be more than :data:`MAX_ORBIT_POINTS`);
    ``observables``: the model's outputs (mesh forces) there; ``multipliers``
    (sorted by decreasing modulus) and ``eigenvectors`` (columns) of ``monodromy``;
    ``crossings``: edge crossings of the orbit per event over one orbit period;
    ``trace_integral``: the integral of the Jacobian's trace over the period (Liouville:
    prod(multipliers) = exp(trace_integral)); ``status``/``message``: the Newton outcome."""

    model: Any
    problem: ShootingProblem
    x: np.ndarray
    times: np.ndarray
    states: np.ndarray
    observables: np.ndarray
    monodromy: np.ndarray
    multipliers: np.ndarray
    eigenvectors: np.ndarray
    crossings: np.ndarray
    residual: float
    iterations: int
    residuals: tuple[float, ...]
    status: OrbitStatus
    message: str
    integration_status: Status
    unresolved: int
    trace_integral: float
    #: Least and greatest value of each switching function at the orbit's grid points.
    event_min: np.ndarray = field(default_factory=lambda: np.zeros(0))
    event_max: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def converged(self) -> bool:
        """Whether Newton's iteration converged (``status`` is ``CONVERGED``)."""
        return self.status == OrbitStatus.CONVERGED

    @property
    def omega(self) -> float:
        """The forcing frequency Omega of the orbit."""
        return self.problem.omega

    @property
    def period(self) -> int:
        """k: the orbit is a fixed point of the k-th iterate of the section map."""
        return self.problem.period

    @property
    def duration(self) -> float:
        """The orbit's period in model time."""
        return self.problem.duration

    @property
    def stability(self) -> str:
        """'stable' (every ``abs(multiplier) < 1``), 'unstable' (one > 1), 'marginal' (the largest
        within :data:`MARGINAL` of 1) or 'unknown' (not converged or not finite)."""
        if not self.converged or not np.all(np.isfinite(self.multipliers)):
            return "unknown"
        rho = float(np.max(np.abs(self.multipliers)))
        if rho > 1.0 + MARGINAL:
            return "unstable"
        return "stable" if rho < 1.0 - MARGINAL else "marginal"

    @property
    def stable(self) -> bool:
        """Whether ``stability`` is ``'stable'``."""
        return self.stability == "stable"

    @property
    def section_points(self) -> np.ndarray:
        """The orbit's k section points (states at the starts of its sections), (k, n)."""
        n = self.states.shape[0] - 1  # recorded intervals over the orbit
        every = n // self.period
        return self.states[: self.period * every : every]

    @property
    def least_period(self) -> int:
        """The least period in sections: the smallest divisor d of k with the section point
        back (to ``1e-6 (1 + abs(x))``, scaled) after d sections (a period-k search can find an
        orbit of a divisor of k); 0 when not converged."""
        if not self.converged:
            return 0
        pts = self.section_points / self.problem.scale
        x = pts[0]
        for d in range(1, self.period):
            if self.period % d == 0 and np.max(np.abs(pts[d] - x)) <= 1e-6 * (
                    1.0 + np.max(np.abs(x))):
                return d
        return self.period

    @property
    def liouville_error(self) -> float:
        """``abs(prod(multipliers) / exp(trace_integral) - 1)``: how well the monodromy keeps
        Liouville's formula (the integrator's error in the phase-space volume)."""
        det = float(np.real(np.prod(self.multipliers)))
        return abs(det / math.exp(self.trace_integral) - 1.0)

    def contact(self) -> dict[str, str]:
        """The contact regime of each mesh over the orbit (``none``, ``single``, ``double``,
        ``unbounded``), as the sweeps classify it (``geardyn.analysis.contact
        .contact_regime``, from the events' extremes and the located crossings)."""
        st = np.array([int(self.integration_status)])
        return {name: str(contact_regime(self.event_min[None, :], self.event_max[None, :],
                                         self.crossings[None, :], i, j, st)[0])
                for name, i, j in self.model.meshes}

    def mesh_forces(self) -> dict[str, np.ndarray] | None:
        """Per mesh over the orbit: ``force_peak`` (``max abs(F)``), ``force_rms`` and
        ``dynamic_factor`` (peak / static mesh force, where the model gives it), or None when
        the model does not observe one force per mesh."""
        m = self.model
        if not has_mesh_forces(m):
            return None
        F = self.observables[:-1]  # one period: the last point repeats the first
        out = {"force_peak": np.max(np.abs(F), axis=0),
               "force_rms": np.sqrt(np.mean(F * F, axis=0))}
        static = m.static_mesh_forces()
        if static is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                out["dynamic_factor"] = out["force_peak"] / np.abs(np.asarray(static))
        return out

    def mesh_crossings(self) -> dict[str, int]:
        """Edge crossings per orbit period of each mesh (both edges of its dead zone)."""
        return {name: int(self.crossings[i] + self.crossings[j])
                for name, i, j in self.model.meshes}

    def to_dataset(self) -> xr.Dataset:
        """The orbit as a labelled Dataset (``geardyn_kind = "periodic-orbit"``)."""
        return orbit_dataset(self)


def orbit_dataset(orb: PeriodicOrbit) -> xr.Dataset:
    """The dataset of a :class:`PeriodicOrbit`: dims ``time`` (the orbit's grid), ``state``,
    ``state_in`` (monodromy columns), ``multiplier``, ``event``."""
    m = orb.model
    n = m.n_states
    ds = xr.Dataset(coords={
        "time": ("time", orb.times, {"units": m.time_unit, "long_name": "time"}),
        "state": ("state", list(m.state_names)),
        "state_in": ("state_in", list(m.state_names)),
        "multiplier": ("multiplier", np.arange(n)),
    })
    for j, name in enumerate(m.state_names):
        ds[name] = ("time", orb.states[:, j], {"units": m.state_units})
    for j, name in enumerate(m.observable_names):
        ds[name] = ("time", orb.observables[:, j], {"units": m.observable_units,
                                                    "long_name": f"dynamic mesh force {name}"})
    ds["section_point"] = ("state", orb.x, {"units": m.state_units, "long_name":
                                            "state at the section (forcing phase zero)"})
    ds["monodromy"] = (("state", "state_in"), orb.monodromy, {
        "units": "1", "long_name": "Jacobian of the period map d x_end / d x_start"})
    mu = orb.multipliers
    ds["multiplier_real"] = ("multiplier", mu.real, {"units": "1"})
    ds["multiplier_imag"] = ("multiplier", mu.imag, {"units": "1"})
    ds["multiplier_abs"] = ("multiplier", np.abs(mu), {
        "units": "1", "long_name": "|Floquet multiplier|"})
    ds["eigenvector_real"] = (("state", "multiplier"), orb.eigenvectors.real, {"units": "1"})
    ds["eigenvector_imag"] = (("state", "multiplier"), orb.eigenvectors.imag, {"units": "1"})
    if m.n_events:
        ds = ds.assign_coords(event=("event", list(m.event_names)))
        ds["edge_crossings"] = ("event", orb.crossings, {
            "long_name": "dead-zone edge crossings per orbit period", "units": "1"})
    if m.meshes:
        ds = ds.assign_coords(mesh=("mesh", [name for name, _, _ in m.meshes]))
        attrs = variable_attrs(m)
        ds["contact"] = ("mesh", list(orb.contact().values()), attrs["contact"])
        for name, values in (orb.mesh_forces() or {}).items():
            ds[name] = ("mesh", values, attrs[name])
    pr = orb.problem
    ds.attrs.update(
        model=m.name,
        Omega=pr.omega,
        period=pr.period,
        least_period=orb.least_period,
        section_periods=pr.sections,
        forcing_periods=pr.forcing_periods,
        duration=pr.duration,
        integrator=INTEGRATOR,
        monodromy_method="central differences of each located RK4 step (tangent step map)",
        steps_per_period=pr.steps_per_period,
        step=pr.step,
        bound=pr.bound,
        converged=int(orb.converged),
        orbit_status=int(orb.status),
        orbit_status_meaning=orbit_status_meaning(),
        message=orb.message,
        residual=orb.residual,
        iterations=orb.iterations,
        stability=orb.stability,
        trace_integral=orb.trace_integral,
        liouville_error=orb.liouville_error,
        status=int(orb.integration_status),
        status_meaning=status_meaning(),
        unresolved_steps=orb.unresolved,
        time_unit=m.time_unit,
    )
    if m.capabilities.interpretation:
        ds.attrs["interpretation"] = m.dataset_attrs()["interpretation"]
    return finish(ds, "periodic-orbit")


# ----------------------------------------------------------------------------- the API
def default_guess(problem: ShootingProblem, y0: np.ndarray | None = None,
                  transient: float | None = None, converge: float | None = None,
                  transient_max: float | None = None) -> np.ndarray:
    """The section point after a transient run at the problem's coefficients (default
    :data:`GUESS_PERIODS` section periods from ``model.initial_state()``).

    With ``converge`` the transient is a minimum: the run goes on, one orbit period
    (``problem.sections`` forcing periods) at a time, until two consecutive section points
    differ by at most ``converge (1 + max |y|)`` or the time reaches ``transient_max``
    (default 10 x the transient); Newton shooting then corrects what is left either way."""
    m = problem.model
    k = kernels_for(m.kernel)
    T_s = problem.sections * forcing_period(problem.omega)
    n_sec = GUESS_PERIODS if transient is None else max(1, math.ceil(transient / T_s - 1e-9))
    n = problem.steps_per_period
    y = np.asarray(m.initial_state() if y0 is None else y0, dtype=float)

    def run_sections(y: np.ndarray, count: int) -> np.ndarray:
        steps = count * problem.sections * n
        Y = k.trajectory(problem.params, y, problem.step, problem.omega, n, 0, steps, steps,
                         True, problem.bound, m.n_events, m.n_observables)[0]
        return Y[-1].copy()

    y = run_sections(y, n_sec)
    if converge is None:
        return y
    limit = 10.0 * n_sec * T_s if transient_max is None else float(transient_max)
    extra = max(0, math.floor(limit / T_s + 1e-9) - n_sec)
    for _ in range(extra):
        if not np.all(np.isfinite(y)):
            break
        y_next = run_sections(y, 1)
        settled = np.max(np.abs(y_next - y)) <= converge * (1.0 + np.max(np.abs(y_next)))
        y = y_next
        if settled:
            break
    return y


def periodic_orbit(model: Model, omega: float | None = None, period: int = 1,
                   guess: np.ndarray | None = None, run: RunSettings | None = None, *,
                   settings: NewtonSettings | None = None,
                   steps_per_period: int | None = None, **legacy: Any) -> PeriodicOrbit:
    """A period-``period`` orbit of ``model``'s stroboscopic map at ``omega`` by Newton shooting.

    Parameters
    ----------
    omega
        Forcing frequency (default the model's).
    period
        k: the orbit closes after k sections (a section is one forcing period, or the common
        period of the forcings where the model has a second excitation).
    guess
        A state near the orbit's section point (at forcing phase zero). Default: the state
        after a transient run from ``model.initial_state()`` (``run.transient`` when ``run``
        is given, else :data:`GUESS_PERIODS` sections).
    run
        :class:`~geardyn.RunSettings`: ``steps_per_period``, ``bound``, ``transient``,
        ``converge`` and ``transient_max`` (of the default guess, see :func:`default_guess`),
        ``max_section_periods``.
    settings
        :class:`~geardyn.NewtonSettings`: the Newton tolerance ``tol`` (scaled max norm,
        relative to ``1 + abs(x)``) and most iterations ``max_iter``. Its fields given as
        keyword arguments are deprecated (a DeprecationWarning).
    steps_per_period
        RK4 steps per forcing period of a call without ``run`` (with ``run``, give
        ``run.steps_per_period``: both together are a TypeError naming both values); default
        :data:`ORBIT_STEP_FACTOR` times the step rule.

    Returns a :class:`PeriodicOrbit`. A Newton that does not converge is not an exception:
    ``status``/``message`` say what happened and the last iterate is kept.
    """
    newton = resolve_settings(NewtonSettings, settings, legacy, "periodic_orbit")
    steps = orbit_steps(run, steps_per_period, "periodic_orbit")
    problem = problem_with_steps(model, omega, period, run, steps)
    if guess is None:
        guess = default_guess(problem, transient=None if run is None else run.transient,
                              converge=None if run is None else run.converge,
                              transient_max=None if run is None else run.transient_max)
    guess = np.asarray(guess, dtype=float)
    if guess.shape != (problem.model.n_states,):
        raise ValueError(f"guess must have {problem.model.n_states} entries "
                         f"({', '.join(problem.model.state_names)})")
    res = newton_shooting(problem, guess, newton.tol, newton.max_iter)
    return build_orbit(problem, res)


def build_orbit(problem: ShootingProblem, res: NewtonResult) -> PeriodicOrbit:
    """The :class:`PeriodicOrbit` of a Newton result (the orbit integrated once more from its
    last iterate, every grid point recorded)."""
    m = problem.model
    stride = max(1, math.ceil(problem.n_steps / MAX_ORBIT_POINTS))
    while problem.n_steps % stride:
        stride += 1
    ev = _orbit_evaluation(problem, res, stride)
    n = m.n_states
    if ev.ok:
        mu, V = np.linalg.eig(ev.monodromy)
        order = np.argsort(-np.abs(mu), kind="stable")
        mu, V = mu[order], V[:, order]
    else:
        mu, V = np.full(n, np.nan + 0j), np.full((n, n), np.nan + 0j)
    times = problem.t0 + np.arange(ev.states.shape[0]) * (stride * problem.step)
    obs = _observables(m, problem, times, ev.states)
    trace = _trace_integral(m, problem, times, ev.states)
    G = _events_along(m, problem, times, ev.states)
    return PeriodicOrbit(
        model=m, problem=problem, x=res.x.copy(), times=times, states=ev.states,
        observables=obs, monodromy=ev.monodromy, multipliers=mu, eigenvectors=V,
        crossings=ev.crossings, residual=float(res.residuals[-1]) if res.residuals else np.nan,
        iterations=res.iterations, residuals=res.residuals, status=res.status,
        message=res.message, integration_status=ev.status, unresolved=ev.unresolved,
        trace_integral=trace, event_min=np.min(G, axis=0), event_max=np.max(G, axis=0))


def _orbit_evaluation(problem: ShootingProblem, res: NewtonResult, stride: int
                      ) -> ShootingEval:
    """The evaluation at the Newton result's last iterate with the states every ``stride``
    grid steps. Where the result's own evaluation is at that iterate and ended cleanly, its
    monodromy, crossings and counts are kept and only the state is integrated again (the
    state's row is stepped the same with or without the monodromy's rows)."""
    if not np.all(np.isfinite(res.x)):
        return res.evaluation
    own = res.evaluation
    if own.ok and np.array_equal(own.x, res.x):
        return replace(own, states=problem.evaluate(res.x, jacobian=False, stride=stride).states)
    return problem.evaluate(res.x, jacobian=True, stride=stride)


def _observables(m: Model, problem: ShootingProblem, times: np.ndarray, Y: np.ndarray
                 ) -> np.ndarray:
    out = np.full((times.size, m.n_observables), np.nan)
    if not m.n_observables:
        return out
    k = kernels_for(m.kernel)
    o = np.empty(m.n_observables)
    for i, t in enumerate(times):
        if np.all(np.isfinite(Y[i])):
            ph = problem.omega * (t - problem.t0)
            k.observe(t, Y[i], o, problem.params, math.sin(ph), math.cos(ph))
            out[i] = o
    return out


def _events_along(m: Model, problem: ShootingProblem, times: np.ndarray, Y: np.ndarray
                  ) -> np.ndarray:
    """The switching functions at the recorded points, (points, n_events) (NaN rows where the
    state is not finite; one NaN row when there are no points)."""
    out = np.full((max(times.size, 1), m.n_events), np.nan)
    if not m.n_events:
        return out
    k = kernels_for(m.kernel)
    g = np.empty(m.n_events)
    for i, t in enumerate(times):
        if np.all(np.isfinite(Y[i])):
            ph = problem.omega * (t - problem.t0)
            k.events(t, Y[i], g, problem.params, math.sin(ph), math.cos(ph))
            out[i] = g
    return out


def _trace_integral(m: Model, problem: ShootingProblem, times: np.ndarray, Y: np.ndarray
                    ) -> float:
    """Integral of the Jacobian's trace along the orbit (trapezoid on at most
    :data:`TRACE_POINTS` of the recorded points; exact for a constant trace, as in the built-in
    models)."""
    if not np.all(np.isfinite(Y)):
        return float("nan")
    idx = np.unique(np.linspace(0, times.size - 1, min(times.size, TRACE_POINTS)).astype(int))
    tr = np.array([jacobian_trace(m, times[i], Y[i], problem.params) for i in idx])
    t = times[idx]
    return float(np.sum(0.5 * (tr[1:] + tr[:-1]) * np.diff(t)))
