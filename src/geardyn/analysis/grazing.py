"""Contact-change (grazing) curves: where a periodic orbit just touches a mesh's dead-zone edge,
followed in two parameters.

A mesh's switching functions are ``h_drive = X - b`` (the drive flank's edge) and
``h_back = X + b`` (the back flank's); the regimes of :mod:`geardyn.analysis.contact` change
where the orbit's extremum of one of them passes through zero:

* drive flank, ``min h_drive = 0``: contact kept (``none``) / contact lost (``single``);
* back flank, ``min h_back = 0``: single-sided / double-sided impacts (``double``).

The extremum is the one towards the edge from the side the orbit stays on at the start (the
minimum where the orbit's mean of h is positive, the maximum where it is negative).

Defining system
---------------
Unknowns z = (x0 / state_scale, X / x_scale, Y / y_scale): the orbit's section point and the two
parameters. Equations (n + 1 of them, so z traces a curve)::

    (P^k(x0) - x0) / state_scale = 0          the period-k orbit (shooting)
    h(phi(t_g; x0)) / h_scale     = 0          its extremum of h is zero

where t_g, the grazing time, solves dh/dt(phi(t_g)) = 0: it is eliminated by locating the
extremum of h along the orbit at each evaluation (h at every RK4 grid point of the orbit, then
the extremum of h on the cubic Hermite interpolant of the state, built from the states and the
vector field at the grid points, in the two grid cells beside the extreme grid point; the
interpolant is C^1 in time, so the extremum is a continuous function of z). This is the
system (G = 0, h = 0, dh/dt = 0) in (x0, t_g, X, Y) with the last equation solved inside.

Jacobian: the monodromy M - I from :meth:`ShootingProblem.evaluate` for dG/dx0; the other
columns by finite differences: forward for dh/dx0 (step :data:`FD_STATE` in x0 / state_scale),
central for the parameters (step :data:`~geardyn.core.settings.PARAM_STEP_REL` (1 + abs(value))
in model units).

The curve is followed by :mod:`geardyn.analysis.arclength` from its first point both ways,
until it leaves the box ``x_range`` x ``y_range`` or fails (status and message, as a branch).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from geardyn.analysis.arclength import (
    ArclengthSettings,
    CurvePoint,
    CurveRun,
    OutsideDomain,
    follow,
    start,
)
from geardyn.analysis.branch_data import BranchStatus, branch_status_meaning
from geardyn.analysis.orbits import (
    ORBIT_STEP_FACTOR,
    OrbitStatus,
    ShootingEval,
    ShootingProblem,
    default_guess,
    newton_shooting,
    problem_with_steps,
)
from geardyn.core.plan import default_steps_per_period
from geardyn.core.results import finish
from geardyn.core.settings import OMEGA_RULE, PARAM_STEP_REL, RunSettings, usable_omega
from geardyn.solvers.kernels import kernels_for

if TYPE_CHECKING:
    from geardyn.core.model import Model

#: The flanks of a mesh: its first (drive, X - b) and second (back, X + b) switching function.
FLANKS = ("drive", "back")
#: Forward-difference step of dh/dx0, in x0 / state_scale.
FD_STATE = 1e-6
#: The curve's default arclength settings (steps in the scaled unknowns).
#: The tolerance is looser than a branch's: near the edge the located-edge RK4 map is smooth
#: only to about 1e-7 of the state at :data:`GRAZING_STEP_FACTOR` times the step rule (the
#: step that first splits at a grazing crossing, an O(h^5) change), so the corrector's
#: tolerance is a few times that (at 1e-7 it stalls on that noise: a curve of an impacting
#: orbit took 400 short steps where 3e-7 takes 168 to the box's edge).
GRAZING_SETTINGS = ArclengthSettings(ds=0.02, ds_min=1e-5, ds_max=0.1, max_points=400,
                                     tol=3e-7, max_iter=10)
#: The curve's default steps per forcing period: this many times the step rule at the start.
GRAZING_STEP_FACTOR = ORBIT_STEP_FACTOR
#: The codimension-2 points a grazing curve records (``special_kind``).
SPECIAL_MEANING = ("grazing-fold: the grazing curve meets a fold curve; grazing-period-doubling: "
                   "it meets a period-doubling curve; grazing-neimark-sacker: a Neimark-Sacker "
                   "curve (geardyn.analysis.envelope.intersect_curves)")
#: What a grazing curve separates, per flank (the contact labels on its two sides).
SEPARATES = {"drive": ("none", "single"), "back": ("single", "double")}


@dataclass
class GrazingInfo:
    """What one converged point of the curve holds besides z: the evaluation (multipliers),
    the grazing time (model time from the section) and the extremum of h."""

    ev: ShootingEval
    t_g: float
    h: float


@dataclass
class GrazingProblem:
    """The residual of a grazing curve of ``event`` (an index of the model's events) in the
    parameters ``x`` and ``y`` of ``model``, on the period-k shooting ``base`` problem."""

    model: Model
    x: str
    y: str
    event: int
    base: ShootingProblem
    x_scale: float
    y_scale: float
    sense: float = 1.0  # +1: the minimum of h; -1: its maximum
    h_scale: float = 1.0
    _params: dict[tuple[float, float], np.ndarray] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.kernel = kernels_for(self.model.kernel)
        self.scale = self.base.scale
        self.n = self.model.n_states

    # -- parameters and unknowns
    def params_at(self, X: float, Y: float) -> np.ndarray:
        """The coefficient vector at (X, Y); :class:`OutsideDomain` outside the model's valid
        region (the message names the parameter)."""
        key = (X, Y)
        hit = self._params.get(key)
        if hit is not None:
            return hit
        if not (math.isfinite(X) and math.isfinite(Y)):
            raise OutsideDomain(f"{self.x}={X!r}, {self.y}={Y!r} is not finite")
        for name, v in ((self.x, X), (self.y, Y)):
            if name == "Omega" and not usable_omega(v):
                raise OutsideDomain(f"Omega {OMEGA_RULE} (got {v:.8g})")
        try:
            P = np.asarray(self.model.lane_params_grid(self.x, [X], self.y, [Y])[0], float)
        except (ValueError, KeyError) as err:
            raise OutsideDomain(str(err)) from err
        if len(self._params) > 256:
            self._params.clear()
        self._params[key] = P
        return P

    def problem_at(self, X: float, Y: float) -> ShootingProblem:
        try:
            pr = self.base.with_params(self.params_at(X, Y))
        except OutsideDomain:
            raise
        except ValueError as err:
            raise OutsideDomain(str(err)) from err
        if pr.sections != self.base.sections:
            raise OutsideDomain(f"the common period of the forcings changes from "
                                f"{self.base.sections} to {pr.sections} forcing periods")
        return ShootingProblem(pr.model, pr.params, pr.omega, pr.period, pr.sections,
                               self.base.steps_per_period, pr.bound, pr.t0, self.scale,
                               pr.section_limit)

    def z_of(self, x0: np.ndarray, X: float, Y: float) -> np.ndarray:
        return np.concatenate([np.asarray(x0, float) / self.scale,
                               [X / self.x_scale, Y / self.y_scale]])

    def split(self, z: np.ndarray) -> tuple[np.ndarray, float, float]:
        """(x0, X, Y) of z."""
        return (z[: self.n] * self.scale, float(z[self.n] * self.x_scale),
                float(z[self.n + 1] * self.y_scale))

    def where(self, z: np.ndarray) -> str:
        _, X, Y = self.split(z)
        return f"{self.x}={X:.8g}, {self.y}={Y:.8g}"

    # -- the extremum of h along the orbit
    def h_along(self, pr: ShootingProblem, Y: np.ndarray) -> np.ndarray:
        """The switching function at the grid points of the orbit (rows of ``Y``)."""
        g = np.empty(self.model.n_events)
        out = np.empty(Y.shape[0])
        w, ev, p = pr.omega, self.event, pr.params
        for i in range(Y.shape[0]):
            ph = w * i * pr.step
            self.kernel.events(pr.t0 + i * pr.step, Y[i], g, p, math.sin(ph), math.cos(ph))
            out[i] = g[ev]
        return out

    def _rhs(self, pr: ShootingProblem, t: float, y: np.ndarray) -> np.ndarray:
        dy = np.empty(self.n)
        ph = pr.omega * (t - pr.t0)
        self.kernel.rhs(t, y, dy, pr.params, math.sin(ph), math.cos(ph))
        return dy

    def _h_at(self, pr: ShootingProblem, t: float, y: np.ndarray) -> float:
        g = np.empty(self.model.n_events)
        ph = pr.omega * (t - pr.t0)
        self.kernel.events(t, y, g, pr.params, math.sin(ph), math.cos(ph))
        return float(g[self.event])

    def extremum(self, pr: ShootingProblem, Y: np.ndarray) -> tuple[float, float]:
        """(h at the extremum, its time from the section) along the orbit whose grid states
        are ``Y`` (every grid point, the last one the end of the orbit period)."""
        if not np.all(np.isfinite(Y)):
            raise FloatingPointError("the orbit's integration diverged")
        from scipy.optimize import minimize_scalar  # here: import geardyn stays free of SciPy

        hs = self.sense * self.h_along(pr, Y[:-1])
        N = hs.size
        i = int(np.argmin(hs))
        dt = pr.step
        best = (float(hs[i]), i * dt)
        for a in ((i - 1) % N, i):  # the cells [a, a + 1] beside the extreme grid point
            ya, yb = Y[a], Y[a + 1]
            ta = pr.t0 + a * dt
            fa, fb = self._rhs(pr, ta, ya), self._rhs(pr, ta + dt, yb)

            def h_cell(s: float, ya=ya, yb=yb, fa=fa, fb=fb, ta=ta) -> float:
                s2, s3 = s * s, s * s * s  # cubic Hermite on [0, 1]
                y = ((2 * s3 - 3 * s2 + 1) * ya + (s3 - 2 * s2 + s) * dt * fa
                     + (-2 * s3 + 3 * s2) * yb + (s3 - s2) * dt * fb)
                return self.sense * self._h_at(pr, ta + s * dt, y)

            r = minimize_scalar(h_cell, bounds=(0.0, 1.0), method="bounded",
                                options={"xatol": 1e-10})
            if float(r.fun) < best[0]:
                best = (float(r.fun), (a + float(r.x)) * dt)
        return self.sense * best[0], best[1]

    # -- the residual
    def _parts(self, x0: np.ndarray, X: float, Y: float, jacobian: bool
               ) -> tuple[np.ndarray, float, float, ShootingEval]:
        pr = self.problem_at(X, Y)
        ev = pr.evaluate(x0, jacobian=jacobian, stride=1)
        if not ev.ok:
            raise FloatingPointError(f"the integration diverged at {self.x}={X:.8g}, "
                                     f"{self.y}={Y:.8g}")
        h, t_g = self.extremum(pr, ev.states)
        return ev.residual / self.scale, h / self.h_scale, t_g, ev

    def residual(self, z: np.ndarray, jacobian: bool
                 ) -> tuple[np.ndarray, np.ndarray | None, GrazingInfo]:
        """H(z) (n + 1), its Jacobian (n + 1 x n + 2) when asked, and the point's info."""
        x0, X, Y = self.split(z)
        G, h, t_g, ev = self._parts(x0, X, Y, jacobian)
        H = np.concatenate([G, [h]])
        info = GrazingInfo(ev, t_g, h * self.h_scale)
        if not jacobian:
            return H, None, info
        n = self.n
        J = np.empty((n + 1, n + 2))
        J[:n, :n] = (ev.monodromy - np.eye(n)) * self.scale[None, :] / self.scale[:, None]
        for j in range(n):  # dh / d(x0 / scale)
            xp = x0.copy()
            xp[j] += FD_STATE * self.scale[j]
            _, hp, _, _ = self._parts(xp, X, Y, False)
            J[n, j] = (hp - h) / FD_STATE
        for col, (v, sc) in enumerate(((X, self.x_scale), (Y, self.y_scale))):
            d = PARAM_STEP_REL * (1.0 + abs(v))
            ends = []
            for sign in (1.0, -1.0):
                XY = (X + sign * d, Y) if col == 0 else (X, Y + sign * d)
                Gs, hs, _, _ = self._parts(x0, *XY, False)
                ends.append(np.concatenate([Gs, [hs]]))
            J[:, n + col] = (ends[0] - ends[1]) / (2.0 * d) * sc
        return H, J, info


# ----------------------------------------------------------------------------- the API
def _flank_event(model: Model, mesh: str | None, flank: str) -> tuple[str, int]:
    if not model.meshes:
        raise ValueError(f"mesh: {model.name} has no meshes (no dead-zone switching functions)")
    names = [name for name, _, _ in model.meshes]
    if mesh is None:
        mesh = names[0]
    if mesh not in names:
        raise ValueError(f"mesh: {mesh!r} is not a mesh of {model.name} (one of "
                         f"{', '.join(names)})")
    if flank not in FLANKS:
        raise ValueError(f"flank: must be one of {', '.join(FLANKS)} (got {flank!r})")
    _, i, j = model.meshes[names.index(mesh)]
    return mesh, (i if flank == "drive" else j)


def nearest_flank(model: Model, problem: ShootingProblem, x0: np.ndarray) -> tuple[str, str]:
    """(mesh, flank) whose switching function's extremum towards its edge along the orbit from
    ``x0`` (the minimum where its mean is >= 0, else the maximum) lies nearest zero, over its
    range along the orbit: the edge a contact change of that orbit grazes."""
    if not model.meshes:
        raise ValueError(f"mesh: {model.name} has no meshes (no dead-zone switching functions)")
    ev = problem.evaluate(np.asarray(x0, float), jacobian=False, stride=1)
    if not np.all(np.isfinite(ev.states)):
        raise FloatingPointError("the orbit's integration diverged")
    best: tuple[float, str, str] | None = None
    for name, i, j in model.meshes:
        for flank, event in zip(FLANKS, (i, j), strict=True):
            gp = GrazingProblem(model, "Omega", "Omega", event, problem, 1.0, 1.0)
            h = gp.h_along(problem, ev.states[:-1])
            edge = float(np.min(h)) if float(np.mean(h)) >= 0.0 else float(np.max(h))
            share = abs(edge) / max(float(np.ptp(h)), 1e-300)
            if best is None or share < best[0]:
                best = (share, name, flank)
    assert best is not None
    return best[1], best[2]


def _range(name: str, value: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name}: give (low, high) (got {value!r})") from err
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"{name}: must be finite with low < high (got {value!r})")
    return lo, hi


def grazing_curve(model: Model, x: str, y: str, x_range: tuple[float, float],
                  y_range: tuple[float, float], *, mesh: str | None = None,
                  flank: str = "drive", period: int = 1,
                  at: tuple[float, float] | None = None, hold: str | None = None,
                  branch: xr.Dataset | None = None, bifurcation: int | None = None,
                  guess: np.ndarray | None = None, run: RunSettings | None = None,
                  settings: ArclengthSettings | None = None,
                  progress: Callable[[int, float, float], None] | None = None) -> xr.Dataset:
    """The contact-change (grazing) curve of ``mesh``'s ``flank`` in the plane (``x``, ``y``).

    Parameters
    ----------
    x, y
        ``"Omega"`` or any parameter ``model.lane_params_grid`` accepts (as :func:`geardyn.map2d`).
    x_range, y_range
        The box (low, high) of each parameter; the curve ends where it leaves it.
    mesh, flank
        The mesh (default the model's first) and its flank: ``"drive"`` (contact loss, the
        orbit's minimum of X - b is zero) or ``"back"`` (back-flank impacts begin, the
        minimum of X + b is zero).
    period
        k: orbits of the k-th iterate of the section map.
    at
        ``(x, y)``: start at this x, solving for y from this y (a guess: the orbit there should
        be close to grazing; else y is first approached by the secant method). Default the
        model's values (a physical input such as a torque must be given).
    hold
        The parameter held at its ``at`` value while the first point converges (default x;
        y where the curve is closer to parallel to the x axis there).
    branch, bifurcation
        Instead of ``at``: start from the contact point ``bifurcation`` (an index along
        ``bifurcation``) of a :func:`geardyn.continuation` dataset of ``model`` in ``x`` or
        ``y``: its value fixes that parameter, its section point is the guess, its period k.
    guess
        A state near the starting orbit's section point (default: after a transient run).
    run
        :class:`~geardyn.RunSettings`: ``steps_per_period`` (fixed along the curve; default
        :data:`GRAZING_STEP_FACTOR` times the step rule at the start), ``bound``, ``transient`` of
        the default guess.
    settings
        :class:`~geardyn.analysis.arclength.ArclengthSettings` (steps in the scaled unknowns;
        default :data:`GRAZING_SETTINGS`; ``max_points`` each way).
    progress
        Called as ``progress(points, x, y)`` after each accepted point.

    Returns a ``"curve"`` dataset (``curve_kind = "grazing"``, attrs ``mesh``, ``flank``,
    ``extremum`` ("min"/"max"), ``separates``), its points ordered along the curve, with
    ``grazing_time`` and ``grazing_value`` (the extremum of h, ~0) per point. A failure is
    not an exception: ``status`` and ``message`` say where the curve ended.
    """
    if x == y:
        raise ValueError(f"x and y must be different parameters (both {x!r})")
    x_lo, x_hi = _range("x_range", x_range)
    y_lo, y_hi = _range("y_range", y_range)
    mesh, event = _flank_event(model, mesh, flank)
    st = GRAZING_SETTINGS if settings is None else settings
    if hold not in (None, x, y):
        raise ValueError(f"hold: {x!r} or {y!r} (got {hold!r})")
    fixed = x if hold is None else hold
    if branch is not None:
        X0, Y0, guess, period, fixed = _from_branch(model, x, y, branch, bifurcation, at)
    else:
        if bifurcation is not None:
            raise ValueError("bifurcation: give it with branch= (a continuation dataset)")
        if at is None:
            at = (_current(model, x), _current(model, y))
        try:
            X0, Y0 = (float(v) for v in at)
        except (TypeError, ValueError) as err:
            raise ValueError(f"at: give ({x}, {y}) of the start (got {at!r})") from err
    if not (x_lo <= X0 <= x_hi and y_lo <= Y0 <= y_hi):
        raise ValueError(f"the start {x}={X0:g}, {y}={Y0:g} lies outside x_range {x_range} "
                         f"and y_range {y_range}")
    at_start = model.with_params(**{x: X0, y: Y0})
    steps = run.steps_per_period if run is not None and run.steps_per_period else (
        GRAZING_STEP_FACTOR * default_steps_per_period(at_start))
    base = problem_with_steps(at_start, None, period, run, steps)
    if guess is None:
        guess = default_guess(base, transient=None if run is None else run.transient)
    res = newton_shooting(base, np.asarray(guess, float))
    gp = GrazingProblem(at_start, x, y, event, base, x_hi - x_lo, y_hi - y_lo)
    if res.status != OrbitStatus.CONVERGED:
        return _dataset(gp, mesh, flank, [], BranchStatus.START_FAILED,
                        f"no period-{period} orbit at {x}={X0:.8g}, {y}={Y0:.8g}: "
                        f"{res.message}")
    ev = base.evaluate(res.x, jacobian=False, stride=1)
    h = gp.h_along(base, ev.states[:-1])
    gp.sense = 1.0 if float(np.mean(h)) >= 0.0 else -1.0
    gp.h_scale = max(float(np.ptp(h)), 1e-12 * (1.0 + float(np.max(np.abs(h)))))
    direction = np.zeros(gp.n + 2)
    direction[gp.n if fixed == x else gp.n + 1] = 1.0
    first = start(gp.residual, gp.z_of(res.x, X0, Y0), direction, st)
    if not isinstance(first, CurvePoint):  # far from grazing: approach it first
        z0 = _approach(gp, res.x, X0, Y0, fixed == x)
        if z0 is not None:
            first = start(gp.residual, z0, direction, st)
    if not isinstance(first, CurvePoint):
        return _dataset(gp, mesh, flank, [], BranchStatus.START_FAILED,
                        f"no grazing orbit of the {flank} flank of {mesh} found from "
                        f"{x}={X0:.8g}, {y}={Y0:.8g} ({first.message})")
    count = [0]

    def on_point(pt: CurvePoint) -> None:
        count[0] += 1
        if progress is not None:
            _, Xp, Yp = gp.split(pt.z)
            progress(count[0], Xp, Yp)

    def outside(prev: CurvePoint, new: CurvePoint) -> str | None:
        _, Xn, Yn = gp.split(new.z)
        if x_lo <= Xn <= x_hi and y_lo <= Yn <= y_hi:
            return None
        return f"left the box {x} in [{x_lo:g}, {x_hi:g}], {y} in [{y_lo:g}, {y_hi:g}] at " \
               f"{gp.where(new.z)}"

    ahead = follow(gp.residual, first, st, where=gp.where, stop=outside, on_point=on_point)
    back_first = CurvePoint(first.z, -first.tangent, first.jac, first.iterations, first.info)
    behind = follow(gp.residual, back_first, st, where=gp.where, stop=outside,
                    on_point=on_point)
    points = behind.points[:0:-1] + ahead.points
    status, message = _joined(behind, ahead)
    return _dataset(gp, mesh, flank, points, status, message)


#: Most secant steps of the approach to the grazing point, and the largest step (a share of
#: the free parameter's range).
APPROACH_STEPS, APPROACH_MAX_STEP = 40, 0.1


def _approach(gp: GrazingProblem, x0: np.ndarray, X: float, Y: float, x_fixed: bool
              ) -> np.ndarray | None:
    """A point near the curve: the secant method on the free parameter (y where ``x_fixed``,
    else x) for the orbit's extremum of h = 0, the orbit re-converged by Newton shooting at each
    value from the last one. Its z, or None where the orbit is lost."""
    span = gp.y_scale if x_fixed else gp.x_scale

    def h_of(v: float, guess: np.ndarray) -> tuple[float, np.ndarray] | None:
        try:
            pr = gp.problem_at(X, v) if x_fixed else gp.problem_at(v, Y)
        except OutsideDomain:
            return None
        res = newton_shooting(pr, guess)
        if res.status != OrbitStatus.CONVERGED:
            return None
        ev = pr.evaluate(res.x, jacobian=False, stride=1)
        return gp.extremum(pr, ev.states)[0] / gp.h_scale, res.x

    v0 = Y if x_fixed else X
    got = h_of(v0, x0)
    if got is None:
        return None
    h0, x0 = got
    v1 = v0 + 0.01 * span
    for _ in range(APPROACH_STEPS):
        got = h_of(v1, x0)
        if got is None:
            return None
        h1, x1 = got
        if abs(h1) < 1e-4:
            return gp.z_of(x1, X, v1) if x_fixed else gp.z_of(x1, v1, Y)
        step = -h1 * (v1 - v0) / (h1 - h0) if h1 != h0 else APPROACH_MAX_STEP * span
        step = float(np.clip(step, -APPROACH_MAX_STEP * span, APPROACH_MAX_STEP * span))
        v0, h0, x0, v1 = v1, h1, x1, v1 + step
    return None


def _current(model: Model, name: str) -> float:
    """The model's value of the coefficient ``name``; a ValueError naming ``at`` for a physical
    input (the model keeps only the coefficients derived from it)."""
    if name in model.physical_names:
        raise ValueError(f"at: give (x, y) of the start: {name} is a physical input of "
                         f"{model.name}, whose value the coefficients do not keep")
    return float(model.params[model.param_index(name)])


def _joined(behind: CurveRun, ahead: CurveRun) -> tuple[BranchStatus, str]:
    """One status for the curve's two ends (the worse one: any but COMPLETED), both messages."""
    status = ahead.status if ahead.status != BranchStatus.COMPLETED else behind.status
    return status, f"one end: {behind.message}; other end: {ahead.message}"


def _from_branch(model: Model, x: str, y: str, branch: xr.Dataset, bifurcation: int | None,
                 at: tuple[float, float] | None = None
                 ) -> tuple[float, float, np.ndarray, int, str]:
    """(X0, Y0, guess, period, the parameter the branch fixes) of a branch's contact point."""
    if branch.attrs.get("geardyn_kind") != "continuation":
        raise ValueError(f"branch: not a continuation dataset (geardyn_kind "
                         f"{branch.attrs.get('geardyn_kind')!r})")
    param = branch.attrs["param"]
    if param not in (x, y):
        raise ValueError(f"branch: continued in {param!r}, neither x={x!r} nor y={y!r}")
    kinds = [str(k) for k in branch["bifurcation_kind"].values]
    contacts = [i for i, k in enumerate(kinds) if k == "contact"]
    if bifurcation is None:
        if not contacts:
            raise ValueError("branch: it has no contact bifurcation")
        bifurcation = contacts[0]
    if not (isinstance(bifurcation, int | np.integer) and 0 <= bifurcation < len(kinds)):
        raise ValueError(f"bifurcation: an index in [0, {len(kinds)}) (got {bifurcation!r})")
    if kinds[bifurcation] != "contact":
        raise ValueError(f"bifurcation: entry {bifurcation} is a {kinds[bifurcation]!r}, not a "
                         f"contact change (contact entries: {contacts})")
    value = float(branch["bifurcation_value"].values[bifurcation])
    other = y if param == x else x
    v_other = _current(model, other) if at is None else float(at[0 if other == x else 1])
    X0, Y0 = (value, v_other) if param == x else (v_other, value)
    guess = np.asarray(branch["bifurcation_section_point"].values[bifurcation], float)
    period = int(branch["bifurcation_period"].values[bifurcation])
    return X0, Y0, guess, period, param


def kept_side(gp: GrazingProblem, J: np.ndarray) -> np.ndarray:
    """The unit normal to the curve, in the scaled plane (x / x_scale, y / y_scale), towards
    the side where the orbit's extremum moves off the edge: the gradient of ``sense h`` along
    the orbits (G = 0), dh/dp - dh/dx0 (M - I)^-1 dG/dp, from the point's Jacobian ``J``."""
    n = gp.n
    A, B = J[:n, :n], J[:n, n:]
    try:
        dx = -np.linalg.lstsq(A, B, rcond=None)[0]
    except np.linalg.LinAlgError:
        return np.full(2, np.nan)
    g = gp.sense * (J[n, n:] + J[n, :n] @ dx)
    norm = float(np.linalg.norm(g))
    return g / norm if norm > 0 else np.full(2, np.nan)


def _dataset(gp: GrazingProblem, mesh: str, flank: str, points: list[CurvePoint],
             status: BranchStatus, message: str) -> xr.Dataset:
    """The ``"curve"`` dataset of a grazing curve."""
    m = gp.model
    n = m.n_states
    X = np.array([gp.split(p.z)[1] for p in points])
    Y = np.array([gp.split(p.z)[2] for p in points])
    x0 = np.array([gp.split(p.z)[0] for p in points]).reshape(len(points), n)
    mus = []
    for p in points:
        M = p.info.ev.monodromy
        mu = np.linalg.eigvals(M) if np.all(np.isfinite(M)) else np.full(n, np.nan + 0j)
        mus.append(mu[np.argsort(-np.abs(mu), kind="stable")])
    mu = np.array(mus, dtype=complex).reshape(len(points), n)
    period_time = np.array([gp.problem_at(Xi, Yi).duration for Xi, Yi in zip(X, Y, strict=True)])
    ds = xr.Dataset(coords={
        "point": ("point", np.arange(len(points))),
        gp.x: ("point", X, m.param_attrs(gp.x)), gp.y: ("point", Y, m.param_attrs(gp.y)),
        "state": ("state", list(m.state_names)), "multiplier": ("multiplier", np.arange(n)),
        "special": ("special", np.arange(0))})
    ds["section_point"] = (("point", "state"), x0, {
        "units": m.state_units, "long_name": "state at the section (forcing phase 0)"})
    ds["multiplier_real"] = (("point", "multiplier"), mu.real, {"units": "1"})
    ds["multiplier_imag"] = (("point", "multiplier"), mu.imag, {"units": "1"})
    ds["period_time"] = ("point", period_time, {"units": m.time_unit,
                                                "long_name": "orbit period k q T"})
    ds["special_kind"] = ("special", np.zeros(0, dtype=str), {"meaning": SPECIAL_MEANING})
    for name in ("special_x", "special_y", "special_error"):
        ds[name] = ("special", np.zeros(0))
    ds.attrs.update(curve_kind="grazing", x=gp.x, y=gp.y, period=gp.base.period,
                    status=int(status), message=message,
                    status_meaning=branch_status_meaning(), time_unit=m.time_unit,
                    model=m.name)
    ds["grazing_time"] = ("point", np.array([p.info.t_g for p in points]), {
        "units": m.time_unit, "long_name": "time of the grazing extremum after the section"})
    ds["grazing_value"] = ("point", np.array([p.info.h for p in points]), {
        "units": m.state_units, "long_name": f"extremum of the {flank} flank's switching "
                                             f"function (zero on the curve)"})
    normal = np.array([kept_side(gp, p.jac) for p in points]).reshape(len(points), 2)
    ds["kept_x"] = ("point", normal[:, 0], {"units": "1", "long_name": (
        f"x component of the unit normal (in {gp.x} / x_scale, {gp.y} / y_scale) towards the "
        f"side where the orbit keeps off the {flank} flank's edge ({SEPARATES[flank][0]})")})
    ds["kept_y"] = ("point", normal[:, 1], {"units": "1", "long_name": "y component of it"})
    ds.attrs.update(x_scale=gp.x_scale, y_scale=gp.y_scale)
    ds.attrs.update(mesh=mesh, flank=flank, event=m.event_names[gp.event],
                    extremum="min" if gp.sense > 0 else "max",
                    separates=" / ".join(SEPARATES[flank]),
                    steps_per_period=gp.base.steps_per_period)
    return finish(ds, "curve")


__all__ = ["FLANKS", "GrazingProblem", "grazing_curve", "nearest_flank"]
