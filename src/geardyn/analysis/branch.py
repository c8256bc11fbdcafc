"""Pseudo-arclength continuation of periodic orbits in any parameter, with their bifurcations.

A branch is a curve of zeros of G(x, p) = P^k(x; p) - x, the shooting residual of
:mod:`geardyn.analysis.orbits` (P the section map at the coefficient vector of parameter value
p), followed in the arclength of the scaled unknowns z = (x / state_scale, p / p_scale):

* **predictor** z + ds t, t the unit tangent (the null vector of [M - I, dG/dp], oriented
  along the previous tangent);
* **corrector** Newton on G(z) = 0 together with t . (z - z_pred) = 0 (Keller's bordered
  system): dG/dx = M - I from the monodromy kernel, dG/dp by a central difference of the
  residual (step :data:`~geardyn.core.settings.PARAM_STEP_REL` (1 + |p|));
* **step control** the step grows after a corrector of at most 2 iterations, shrinks after a
  slow one, is halved after a failure or a turn of the tangent by more than ~25 degrees, and
  the branch ends when it would fall below ``ds_min``.

Test functions on each step between two accepted points (see ``docs/continuation.md``):

* fold: the p component of the tangent and det(M - I) both change sign (a real multiplier
  through +1 where the parameter turns);
* branch point: exactly one of the two changes sign: det(M - I) without a turn (a real
  multiplier through +1, another branch crosses), or a turn without det(M - I) (the branch
  meets another and turns back onto itself, e.g. a period-2k branch its period-k orbit);
* period doubling: det(M + I) changes sign (a real multiplier through -1);
* Neimark-Sacker: prod_{i<j} (mu_i mu_j - 1) changes sign and a complex-conjugate pair has
  ||mu| - 1| <= :data:`NS_MODULUS_TOL` at the located point (a real pair's product through 1
  is not one);
* contact change: the edge crossings per orbit period of a mesh change.

Each is located on the step by regula falsi (Illinois; bisection for the integer contact test)
on the arclength between the two points, each trial corrected onto the branch, until the
parameter is known to ``locate_tol``. A location that fails keeps the bifurcation, not located,
with the bracket it changed sign in. A branch that returns onto its own points ends
(:attr:`BranchStatus.RETRACED`).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.branch_data import (
    BIFURCATION_KINDS as BIFURCATION_KINDS,
)
from geardyn.analysis.branch_data import (
    BranchPoint,
    BranchStatus,
    branch_dataset,
    orbit_summary,
)
from geardyn.analysis.branch_data import (
    branch_status_meaning as branch_status_meaning,
)
from geardyn.analysis.orbits import (
    GUESS_PERIODS,
    OrbitStatus,
    ShootingEval,
    ShootingProblem,
    default_guess,
    newton_shooting,
    orbit_steps,
    problem_with_steps,
)
from geardyn.core.model import Model
from geardyn.core.plan import default_steps_per_period
from geardyn.core.settings import (
    OMEGA_RULE,
    PARAM_STEP_REL,
    ContinuationSettings,
    RunSettings,
    resolve_settings,
    usable_omega,
)

#: Most corrector iterations per step.
CORRECTOR_MAX_ITER = 12
#: The step grows after a corrector of at most this many iterations, shrinks after one of at
#: least SHRINK_ITER (chord iterations: each costs one period map).
GROW_ITER = 5
SHRINK_ITER = 9
#: Least cosine between successive tangents for a step to be accepted.
MIN_COS = 0.9
#: Most movement of any Floquet multiplier (to the nearest of the last point's) in a step:
#: beyond it the step is halved (down to MU_MOVE_DS), so that a multiplier does not cross the
#: unit circle twice unseen within a step.
MAX_MU_MOVE = 0.3
MU_MOVE_DS = 1e-3
#: The default guess at the start: a transient of GUESS_PERIODS section periods, at most
#: GUESS_TIME time units.
GUESS_TIME = 2000.0
#: Most trials of a location.
LOCATE_MAX_ITER = 60
#: A corrected point farther than this many step lengths from its predictor (the step ds of a
#: continuation step, the chord of the step for a location trial) is rejected: the corrector
#: jumped (e.g. onto another branch); the step is halved / the trial fails.
MAX_CORRECTION = 3.0
#: A Neimark-Sacker point needs a complex-conjugate pair with ||mu| - 1| at most this at the
#: located point.
NS_MODULUS_TOL = 1e-4
#: A multiplier within this of +1 at both ends of a step is a neutral direction of the model:
#: det(M - I) is round-off there and no branch point is sought.
NEUTRAL_TOL = 1e-9
#: A multiplier is complex where |Im mu| > COMPLEX_TOL (1 + |mu|).
COMPLEX_TOL = 1e-8
#: A new point within RETRACE_TOL segment lengths of a segment between two earlier points of
#: its branch (of their section points shifted by 0..k-1 section periods), its tangent along
#: the segment (cosine >= MIN_COS either way), and for the unshifted points at least
#: RETRACE_GAP segment lengths of arclength behind it, ends the branch: it retraces itself.
RETRACE_TOL = 0.15
RETRACE_GAP = 3.0
#: The default step of a branch: this many times the sweeps' step rule (multipliers to ~1e-8;
#: :data:`~geardyn.analysis.orbits.ORBIT_STEP_FACTOR` for a lone orbit).
BRANCH_STEP_FACTOR = 2
#: The steps per forcing period are re-derived at an accepted point where the step rule's
#: count leaves this ratio of the current one.
STEP_RATIO = 1.25


class _Invalid(ValueError):
    """A parameter value outside the model's valid region."""


@dataclass
class _Failure:
    """Why a corrector failed: ``status`` (a :class:`BranchStatus`) and a message."""

    status: BranchStatus
    message: str


@dataclass
class _Point:
    """A converged point: scaled unknowns ``z``, its evaluation (with the monodromy), the
    problem it was evaluated with, the scaled Jacobian [dG/dx, dG/dp] and the tangent."""

    z: np.ndarray
    ev: ShootingEval
    problem: ShootingProblem
    jac: np.ndarray
    tangent: np.ndarray = field(default_factory=lambda: np.zeros(0))
    iterations: int = 0
    _mu: np.ndarray | None = None

    @property
    def mu(self) -> np.ndarray:
        if self._mu is None:
            mu = np.linalg.eigvals(self.ev.monodromy)
            self._mu = mu[np.argsort(-np.abs(mu), kind="stable")]
        return self._mu


@dataclass
class BifurcationPoint:
    """A detected bifurcation: ``kind`` (one of :data:`BIFURCATION_KINDS`), parameter value
    ``value`` with ``error`` (a bound on the distance to the true switch point of the test
    function), ``index`` (the branch point before it), ``branch`` (the branch's number), ``x``
    (the section point there), ``multiplier`` (the critical multiplier; NaN for contact),
    ``detail`` (words), ``monodromy`` and ``period`` (k of the branch). ``located`` False: the
    location failed; ``value`` +- ``error`` is the bracket the test function changed sign in,
    ``x`` and ``monodromy`` are those of the bracket's end at parameter ``section_value``."""

    kind: str
    value: float
    error: float
    index: int
    branch: int
    x: np.ndarray
    multiplier: complex
    detail: str
    monodromy: np.ndarray
    period: int
    located: bool = True
    section_value: float = math.nan

    @property
    def at(self) -> float:
        """The parameter value of ``x`` and ``monodromy``."""
        return self.value if self.located else self.section_value


@dataclass
class BranchRun:
    """One continued branch: its points, bifurcations, period k, status and message, and the
    bifurcation it was switched from (-1: none)."""

    period: int
    points: list[BranchPoint]
    bifurcations: list[BifurcationPoint]
    status: BranchStatus
    message: str
    parent: int = -1


# ----------------------------------------------------------------------------- the tracer
class _Tracer:
    """Evaluations of one period's residual in the scaled unknowns z = (x / s, p / p_scale)."""

    def __init__(self, model: Model, param: str, period: int, pscale: float,
                 run: RunSettings | None, steps_per_period: int | None, tol: float,
                 max_iter: int):
        self.model, self.param, self.period = model, param, int(period)
        self.pscale = pscale
        self.fixed_steps = steps_per_period  # resolved with the run (orbit_steps)
        self.tol, self.max_iter = tol, max_iter
        self.base = problem_with_steps(model, None, period, run, self.fixed_steps)
        self.scale = self.base.scale
        self.n = self.base.steps_per_period
        self._cache: dict[float, np.ndarray] = {}
        self._renewed_at = math.nan
        # Omega alone moves and no other forcing acts: the section stays one forcing period
        others = model.other_frequencies(np.atleast_2d(model.params))
        self._one_section = param == "Omega" and bool(np.all(np.isnan(others)))

    # -- parameters
    def params_at(self, p: float) -> np.ndarray:
        """The coefficient vector at parameter value p; raises :class:`_Invalid` outside the
        model's valid region."""
        hit = self._cache.get(p)
        if hit is not None:
            return hit
        if not math.isfinite(p):
            raise _Invalid(f"{self.param} is not finite")
        if self.param == "Omega" and not usable_omega(p):
            raise _Invalid(f"Omega {OMEGA_RULE} (got {p:.8g})")
        if self.param == "Omega" and self.model.omega_is_entry:
            P = self.model.params.astype(float).copy()
            P[self.model.omega_index] = p
        else:
            try:
                self.model.with_params(**{self.param: p})
                P = np.asarray(self.model.lane_params(self.param, [p])[0], dtype=float)
            except (ValueError, KeyError) as err:
                raise _Invalid(str(err)) from err
        if len(self._cache) > 64:
            self._cache.clear()
        self._cache[p] = P
        return P

    def problem_at(self, p: float, n: int | None = None) -> ShootingProblem:
        """The shooting problem at p with ``n`` (default the current) steps per period."""
        if self._one_section:  # as ShootingProblem.with_params, without re-deriving the section
            P = self.params_at(p)
            model = copy.copy(self.base.model)
            model.params = P
            return replace(self.base, model=model, params=P, omega=p, sections=1,
                           steps_per_period=int(n or self.n))
        try:
            pr = self.base.with_params(self.params_at(p))
        except _Invalid:
            raise
        except ValueError as err:
            raise _Invalid(str(err)) from err
        if pr.sections != self.base.sections:
            raise _Invalid(f"the common period of the forcings changes from {self.base.sections}"
                           f" to {pr.sections} forcing periods (another section map)")
        return replace(pr, steps_per_period=int(n or self.n))

    def steps_for(self, p: float) -> int:
        """The default steps per forcing period at p (:data:`BRANCH_STEP_FACTOR` times the step
        rule), or the fixed count asked for."""
        if self.fixed_steps:
            return int(self.fixed_steps)
        P = self.params_at(p)
        return BRANCH_STEP_FACTOR * default_steps_per_period(self.model, params=P)

    def renew_steps(self, p: float) -> None:
        """Re-derive the steps per period at p where the rule's count left the ratio
        :data:`STEP_RATIO` of the current one (asked only after p moved by 2 %)."""
        if abs(p - self._renewed_at) <= 0.02 * abs(p):
            return
        self._renewed_at = p
        want = self.steps_for(p)
        if not (self.n / STEP_RATIO <= want <= self.n * STEP_RATIO):
            self.n = want

    # -- conversions
    def z_of(self, x: np.ndarray, p: float) -> np.ndarray:
        return np.concatenate([np.asarray(x, dtype=float) / self.scale, [p / self.pscale]])

    def x_of(self, z: np.ndarray) -> np.ndarray:
        return z[:-1] * self.scale

    def p_of(self, z: np.ndarray) -> float:
        return float(z[-1] * self.pscale)

    # -- evaluations
    def evaluate(self, z: np.ndarray, jacobian: bool = True
                 ) -> tuple[np.ndarray, ShootingEval, ShootingProblem]:
        """(scaled residual, evaluation, problem) at z; raises :class:`_Invalid`."""
        pr = self.problem_at(self.p_of(z))
        ev = pr.evaluate(self.x_of(z), jacobian=jacobian)
        return ev.residual / self.scale, ev, pr

    def jacobian(self, z: np.ndarray, ev: ShootingEval) -> np.ndarray:
        """The scaled Jacobian [dG/dx, dG/dp] (n x n+1) at z, dG/dp by a central difference."""
        p = self.p_of(z)
        h = PARAM_STEP_REL * (1.0 + abs(p))
        x = self.x_of(z)
        up = self.problem_at(p + h).evaluate(x, jacobian=False)
        dn = self.problem_at(p - h).evaluate(x, jacobian=False)
        if not (up.ok and dn.ok):
            raise FloatingPointError("the period map diverged in the parameter difference")
        gp = (up.residual - dn.residual) / (2.0 * h)
        s = self.scale
        Jx = (ev.jacobian * s[None, :]) / s[:, None]
        return np.column_stack([Jx, gp * self.pscale / s])

    def converged(self, r: np.ndarray, z: np.ndarray) -> bool:
        return float(np.max(np.abs(r))) <= self.tol * (1.0 + float(np.max(np.abs(z[:-1]))))

    def correct(self, z_pred: np.ndarray, t: np.ndarray, J0: np.ndarray | None = None,
                max_iter: int | None = None, final: bool = True) -> _Point | _Failure:
        """Newton on G(z) = 0, t . (z - z_pred) = 0 from z_pred: a chord method on the
        Jacobian ``J0`` (e.g. the last point's) while the residual falls by half per iteration,
        else with the Jacobian at the iterate; the point's own Jacobian and monodromy at the end
        (``final``; else the point keeps the last Jacobian used and no monodromy)."""
        z, J = z_pred.copy(), J0
        last = math.inf
        max_iter = self.max_iter if max_iter is None else max_iter
        self.iterates: list[tuple[np.ndarray, np.ndarray]] = []
        for it in range(max_iter + 1):
            fresh = J is None
            try:
                r, ev, pr = self.evaluate(z, jacobian=fresh)
                self.iterates.append((z, ev.crossings))
                if not ev.ok:
                    return _Failure(BranchStatus.DIVERGED, f"the period map diverged at "
                                                           f"{self.param}={self.p_of(z):.8g}")
                done = self.converged(r, z)
                if done and not fresh and final:
                    r, ev, pr = self.evaluate(z, jacobian=True)
                    fresh = True
                if fresh:
                    if not np.all(np.isfinite(ev.monodromy)):
                        return _Failure(BranchStatus.DIVERGED, f"the monodromy is not finite at "
                                        f"{self.param}={self.p_of(z):.8g}")
                    J = self.jacobian(z, ev)
            except _Invalid as err:
                return _Failure(BranchStatus.INVALID, f"at {self.param}={self.p_of(z):.8g}: "
                                                      f"{err}")
            except FloatingPointError as err:
                return _Failure(BranchStatus.DIVERGED, f"at {self.param}={self.p_of(z):.8g}: "
                                                       f"{err}")
            if done:
                return _Point(z, ev, pr, J, iterations=it)
            norm = float(np.max(np.abs(r)))
            if not fresh and norm > 0.5 * last:  # the chord stalls: a fresh Jacobian next
                J, last = None, math.inf
                continue
            last = norm
            if it == max_iter:
                break
            A = np.vstack([J, t])
            rhs = -np.concatenate([r, [t @ (z - z_pred)]])
            try:
                dz = np.linalg.solve(A, rhs)
            except np.linalg.LinAlgError:
                return _Failure(BranchStatus.NOT_CONVERGED, f"singular bordered Jacobian at "
                                                            f"{self.param}={self.p_of(z):.8g}")
            z = z + dz
        return _Failure(BranchStatus.NOT_CONVERGED,
                        f"the corrector did not converge in {max_iter} iterations near "
                        f"{self.param}={self.p_of(z):.8g}")

    def tangent(self, J: np.ndarray, ref: np.ndarray) -> np.ndarray:
        """The unit null vector of J, oriented along ``ref``."""
        A = np.vstack([J, ref])
        rhs = np.zeros(J.shape[1])
        rhs[-1] = 1.0
        try:
            t = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:
            t = np.linalg.svd(J)[2][-1]
        t /= np.linalg.norm(t)
        return t if t @ ref >= 0 else -t


def _null_tangent(J: np.ndarray, direction: float) -> np.ndarray:
    """The unit null vector of J with its p component of the sign of ``direction``."""
    t = np.linalg.svd(J)[2][-1]
    t = t / np.linalg.norm(t)
    return -t if t[-1] * direction < 0 else t


# ----------------------------------------------------------------------------- test functions
def monitor_functions(M: np.ndarray, mu: np.ndarray, tangent_p: float) -> dict[str, float]:
    """The test functions of a point with monodromy ``M``, multipliers ``mu`` and tangent
    p component ``tangent_p``: fold (tangent_p), bp (det(M - I)), pd (det(M + I)), ns (prod over
    pairs of mu_i mu_j - 1), one (the distance of the nearest multiplier to +1)."""
    prod = np.prod([mu[i] * mu[j] - 1.0 for i in range(mu.size) for j in range(i + 1, mu.size)])
    ns = float(np.real(prod)) if mu.size > 1 else 1.0
    eye = np.eye(M.shape[0])
    return {"fold": float(tangent_p), "bp": float(np.linalg.det(M - eye)),
            "pd": float(np.linalg.det(M + eye)), "ns": ns,
            "one": float(np.min(np.abs(mu - 1.0))) if mu.size else math.inf}


def _tests(pt: _Point) -> dict[str, Any]:
    """:func:`monitor_functions` at a point, with contact (crossings per orbit period per mesh)."""
    c = pt.ev.crossings
    meshes = pt.problem.model.meshes
    out: dict[str, Any] = monitor_functions(pt.ev.monodromy, pt.mu, pt.tangent[-1])
    out["contact"] = tuple(int(c[i] + c[j]) for _, i, j in meshes)
    return out


def _changed(ta: dict, tb: dict, key: str) -> bool:
    return bool(ta[key] != 0 and tb[key] != 0 and np.sign(ta[key]) != np.sign(tb[key]))


def detected(ta: dict, tb: dict) -> list[tuple[str, str]]:
    """(kind, test function to locate) of each bifurcation that the test functions ``ta`` and
    ``tb`` of two points show between them (not contact). A turn (fold test) with det(M - I)
    is a fold; either alone is a branch point; a Neimark-Sacker candidate still needs its
    complex pair on the unit circle (:func:`neimark_sacker_pair`). Where a multiplier stays
    within :data:`NEUTRAL_TOL` of +1 at both points (a neutral direction of the model, det(M - I)
    at round-off) det(M - I) is not used: a turn is a fold."""
    out = []
    turn, through_one = _changed(ta, tb, "fold"), _changed(ta, tb, "bp")
    if max(ta["one"], tb["one"]) < NEUTRAL_TOL:
        through_one = turn
    if turn and through_one:
        out.append(("fold", "fold"))
    elif through_one:
        out.append(("branch point", "bp"))
    elif turn:
        out.append(("branch point", "fold"))
    if _changed(ta, tb, "pd"):
        out.append(("period-doubling", "pd"))
    if _changed(ta, tb, "ns"):
        out.append(("neimark-sacker", "ns"))
    return out


def _complex(mu: np.ndarray) -> np.ndarray:
    return np.abs(mu.imag) > COMPLEX_TOL * (1.0 + np.abs(mu))


def neimark_sacker_pair(mu: np.ndarray, tol: float = NS_MODULUS_TOL) -> complex | None:
    """The multiplier (Im > 0) of the complex-conjugate pair of ``mu`` nearest the unit circle
    where it is within ``tol`` of it, else None."""
    cand = mu[_complex(mu) & (mu.imag > 0)]
    if cand.size == 0:
        return None
    c = complex(cand[np.argmin(np.abs(np.abs(cand) - 1.0))])
    if abs(abs(c) - 1.0) > tol or np.min(np.abs(mu - c.conjugate())) > 1e-6 * (1 + abs(c)):
        return None
    return c


def _complex_outside(mu: np.ndarray) -> int:
    """How many complex multipliers lie outside the unit circle."""
    return int(np.count_nonzero(_complex(mu) & (np.abs(mu) > 1.0)))


def _spectrum_moved(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a multiplier of ``b`` to the nearest of ``a``."""
    return float(np.max(np.min(np.abs(b[:, None] - a[None, :]), axis=1)))


def _critical(kind: str, mu: np.ndarray) -> complex:
    """The multiplier that a bifurcation of ``kind`` is about."""
    if kind in ("fold", "branch point"):
        return complex(mu[np.argmin(np.abs(mu - 1.0))])
    if kind == "period-doubling":
        return complex(mu[np.argmin(np.abs(mu + 1.0))])
    if kind == "neimark-sacker":
        cand = mu[np.abs(mu.imag) > 1e-12]
        if cand.size == 0:
            return complex(np.nan)
        return complex(cand[np.argmin(np.abs(np.abs(cand) - 1.0))])
    return complex(np.nan)


# ----------------------------------------------------------------------------- one branch
@dataclass
class _Settings:
    lo: float
    hi: float
    ds: float
    ds_min: float
    ds_max: float
    max_points: int
    locate_tol: float
    progress: Callable[[int, float], None] | None = None


class _BranchRunner:
    """Continues one branch from a converged first point, detecting and locating."""

    def __init__(self, tracer: _Tracer, st: _Settings, number: int):
        self.tr, self.st, self.number = tracer, st, number
        self.points: list[BranchPoint] = []
        self.bifs: list[BifurcationPoint] = []
        self._copies: list[np.ndarray] = []  # per point: (k, n + 1) shifted section points
        self._arc: list[float] = []
        self._trial_failure = ""

    def record(self, pt: _Point, s: float) -> None:
        tr = self.tr
        self.points.append(orbit_summary(pt.problem, tr.x_of(pt.z), tr.p_of(pt.z), s, pt.mu,
                                         pt.ev.crossings, pt.iterations, self.number))
        if self.st.progress is not None:
            self.st.progress(len(self.points), tr.p_of(pt.z))

    def run(self, first: _Point, ds: float) -> tuple[BranchStatus, str]:
        """Continue from ``first`` (converged, with its tangent) with first step ``ds`` until
        the branch ends; returns how it ended."""
        tr, st = self.tr, self.st
        cur, s = first, 0.0
        self.record(cur, s)
        self._remember(cur, s)
        tests = _tests(cur)
        while True:
            if len(self.points) >= st.max_points:
                return BranchStatus.MAX_POINTS, (f"stopped after {st.max_points} points at "
                                                 f"{tr.param}={tr.p_of(cur.z):.8g}")
            got_step = self._step(cur, ds)
            if isinstance(got_step, tuple) and isinstance(got_step[0], BranchStatus):
                return got_step
            nxt, ds = got_step
            p_new = tr.p_of(nxt.z)
            end = None
            if p_new > st.hi or p_new < st.lo:
                end = st.hi if p_new > st.hi else st.lo
                nxt = self._at_bound(cur, nxt, end)
                if nxt is None:
                    return BranchStatus.COMPLETED, (f"left the range at {tr.param}="
                                                    f"{end:.8g} (last point not corrected "
                                                    f"onto the bound)")
            new_tests = _tests(nxt)
            self._detect(cur, nxt, tests, new_tests)
            s += float(np.linalg.norm(nxt.z - cur.z))
            self.record(nxt, s)
            if end is not None:
                return BranchStatus.COMPLETED, f"reached {tr.param}={end:.8g}"
            back = self._retraced(nxt, s)
            if back:
                return BranchStatus.RETRACED, back
            self._remember(nxt, s)
            if nxt.iterations <= GROW_ITER:
                ds = min(st.ds_max, ds * 1.6)
            elif nxt.iterations >= SHRINK_ITER:
                ds = max(st.ds_min, ds * 0.6)
            tr.renew_steps(p_new)
            cur, tests = nxt, new_tests

    def _step(self, cur: _Point, ds: float
              ) -> tuple[_Point, float] | tuple[BranchStatus, str]:
        """The next point from ``cur`` (predictor, corrector, step control) and the step it
        took; (status, message) where the branch ends."""
        tr, st = self.tr, self.st
        while True:
            z_pred = cur.z + ds * cur.tangent
            got = tr.correct(z_pred, cur.tangent, cur.jac)
            if isinstance(got, _Point):
                far = float(np.linalg.norm(got.z - z_pred))
                if far > MAX_CORRECTION * ds:
                    got = _Failure(BranchStatus.NOT_CONVERGED, (
                        f"the corrector moved {far / ds:.3g} step lengths from the predictor "
                        f"(most {MAX_CORRECTION:g}) to {tr.param}={tr.p_of(got.z):.8g}"))
            if isinstance(got, _Point):
                got.tangent = tr.tangent(got.jac, cur.tangent)
                turn = got.tangent @ cur.tangent < MIN_COS
                moved = _spectrum_moved(cur.mu, got.mu) > MAX_MU_MOVE and ds > MU_MOVE_DS
                if not (turn or moved) or ds <= st.ds_min:
                    return got, ds
                got = _Failure(BranchStatus.NOT_CONVERGED, f"the tangent turned sharply "
                               f"at {tr.param}={tr.p_of(got.z):.8g}")
            if ds <= st.ds_min:
                return got.status, (f"{got.status.message}: {got.message} (step "
                                    f"{ds:.3g}); the branch ends at "
                                    f"{tr.param}={tr.p_of(cur.z):.8g}")
            ds = max(st.ds_min, ds / 2)

    def _at_bound(self, cur: _Point, nxt: _Point, bound: float) -> _Point | None:
        """The branch's point at the parameter value ``bound`` between ``cur`` and ``nxt`` (the
        corrector with the constraint p = bound)."""
        tr = self.tr
        p0, p1 = tr.p_of(cur.z), tr.p_of(nxt.z)
        w = (bound - p0) / (p1 - p0) if p1 != p0 else 1.0
        z = cur.z + w * (nxt.z - cur.z)
        z[-1] = bound / tr.pscale
        e = np.zeros(z.size)
        e[-1] = 1.0
        got = tr.correct(z, e, nxt.jac)
        if not isinstance(got, _Point):
            return None
        got.tangent = tr.tangent(got.jac, nxt.tangent)
        return got

    # -- retracing
    def _remember(self, pt: _Point, s: float) -> None:
        """Keep the point's section points (scaled, with p), all k of them, for
        :meth:`_retraced`."""
        self._copies.append(self._shifted(pt))
        self._arc.append(s)

    def _shifted(self, pt: _Point) -> np.ndarray:
        """(k, n + 1): the point's z with its section point moved on by 0..k-1 sections."""
        k = pt.problem.period
        if k == 1:
            return pt.z[None, :].copy()
        pr = pt.problem
        x = self.tr.x_of(pt.z)
        ev = pr.evaluate(x, jacobian=False, stride=pr.sections * pr.steps_per_period)
        Y = np.asarray(ev.states)[:k] / self.tr.scale
        return np.column_stack([Y, np.full(k, pt.z[-1])])

    def _retraced(self, pt: _Point, s: float) -> str:
        """Why ``pt`` (at arclength ``s``) lies on the branch already computed ('' if not):
        within :data:`RETRACE_TOL` segment lengths of a segment between two earlier points (or
        of their section points shifted by r sections), along it (tangent cosine >= MIN_COS
        either way) and, unshifted, at least :data:`RETRACE_GAP` segment lengths behind."""
        if len(self._copies) < 3:
            return ""
        Z = np.stack(self._copies)  # (m, k, n + 1)
        arc = np.asarray(self._arc)
        z, t = pt.z, pt.tangent
        for r in range(Z.shape[1]):
            A, B = Z[:-1, r], Z[1:, r]
            D = B - A
            L = np.linalg.norm(D, axis=1)
            with np.errstate(invalid="ignore", divide="ignore"):
                w = np.clip(np.einsum("ij,ij->i", z - A, D) / L**2, 0.0, 1.0)
                dist = np.linalg.norm(A + w[:, None] * D - z, axis=1)
                along = np.abs(D @ t) / L
            hit = (L > 0) & (dist <= RETRACE_TOL * L) & (along >= MIN_COS)
            if r == 0:
                hit &= s - arc[1:] >= RETRACE_GAP * L
            if np.any(hit):
                j = int(np.flatnonzero(hit)[0])
                shift = f", section points shifted by {r} of {Z.shape[1]}" if r else ""
                return (f"the branch returned onto its own points at {self.tr.param}="
                        f"{self.tr.p_of(z):.8g} (between its points {j} and {j + 1}{shift}): it "
                        f"retraces itself")
        return ""

    # -- detection and location
    def _detect(self, a: _Point, b: _Point, ta: dict, tb: dict) -> None:
        found: list[BifurcationPoint] = []
        for kind, key in detected(ta, tb):
            bif = self._locate(a, b, kind, key, None)
            if bif is not None:
                found.append(bif)
        for m, (name, _i, _j) in enumerate(a.problem.model.meshes):
            if ta["contact"][m] != tb["contact"][m]:
                bif = self._locate(a, b, "contact", "contact", m)
                if bif is not None:
                    bif.detail = f"{name}: {bif.detail}"
                    found.append(bif)
        found.sort(key=lambda f: abs(f.value - self.tr.p_of(a.z)))
        self.bifs += found

    def _trial(self, a: _Point, b: _Point, sigma: float, final: bool = True) -> _Point | None:
        """The branch point at the arclength fraction ``sigma`` from a to b (with its
        monodromy and tangent when ``final``); None (why in ``_trial_failure``) where the
        corrector fails or lands more than :data:`MAX_CORRECTION` chords from the chord."""
        tr = self.tr
        z_pred = a.z + sigma * (b.z - a.z)
        t = b.z - a.z
        chord = float(np.linalg.norm(t))
        t = t / chord
        got = tr.correct(z_pred, t, a.jac, final=final)
        if not isinstance(got, _Point):  # e.g. at a graze: Newton with fresh Jacobians
            got = tr.correct(z_pred, t, None, 3 * tr.max_iter, final=final)
        if not isinstance(got, _Point):
            self._trial_failure = got.message
            return None
        far = float(np.linalg.norm(got.z - z_pred))
        if far > MAX_CORRECTION * chord:
            self._trial_failure = (f"the corrector moved {far / chord:.3g} chords from the "
                                   f"trial's predictor to {tr.param}={tr.p_of(got.z):.8g}")
            return None
        if final:
            got.tangent = tr.tangent(got.jac, a.tangent)
        return got

    def _value(self, pt: _Point, key: str, mesh: int | None) -> float:
        if key == "contact":
            _name, i, j = pt.problem.model.meshes[mesh]
            return float(pt.ev.crossings[i] + pt.ev.crossings[j])
        return float(_tests(pt)[key])

    def _straddle(self, a: _Point, mesh: int, ca: float
                  ) -> tuple[_Point, float, float] | None:
        """Where a contact trial's corrector cannot converge because the period map jumps
        (by the integrator's error) where the crossing count changes, its iterates alternate
        between the two counts on the same arclength hyperplane: the change lies between them.
        Returns (a point there, the bracket's ends) or None."""
        _name, i, j = a.problem.model.meshes[mesh]
        its = self.tr.iterates[-6:]
        on = [self.tr.p_of(z) for z, c in its if c[i] + c[j] == ca]
        off = [self.tr.p_of(z) for z, c in its if c[i] + c[j] != ca]
        if not on or not off:
            return None
        z = its[-1][0]
        every = on + off
        return _Point(z, a.ev, a.problem, a.jac), min(every), max(every)

    def _search(self, a: _Point, b: _Point, key: str, mesh: int | None
                ) -> tuple[_Point | None, float, float, _Point, _Point]:
        """Regula falsi (Illinois) on the arclength fraction between a and b for the zero of
        the test function (bisection for the contact count), each trial corrected: (the trial
        nearest the zero or None, the final bracket in p, the points at its ends)."""
        tr = self.tr
        fa, fb = self._value(a, key, mesh), self._value(b, key, mesh)
        ca = fa
        if key == "contact":  # an integer: bisect on the side it is on
            fa, fb = -1.0, 1.0
        sa, sb = 0.0, 1.0
        pa, pb = tr.p_of(a.z), tr.p_of(b.z)
        end_a, end_b = a, b
        best, best_f, side = None, math.inf, 0
        self._trial_failure = ""
        for _ in range(LOCATE_MAX_ITER):
            if key == "contact":
                sig = 0.5 * (sa + sb)
            else:
                sig = (sa * fb - sb * fa) / (fb - fa)
                lo_, hi_ = sa + 0.02 * (sb - sa), sb - 0.02 * (sb - sa)
                sig = min(max(sig, lo_), hi_)
            pt = self._trial(a, b, sig, final=key != "contact")
            if pt is None and key == "contact":
                got = self._straddle(a, mesh, ca)
                if got is not None:
                    best, pa, pb = got
            if pt is None:
                break
            f = self._value(pt, key, mesh)
            p = tr.p_of(pt.z)
            if key == "contact":
                f = -1.0 if f == ca else 1.0
            if abs(f) < best_f or key == "contact":
                best, best_f = pt, abs(f)
            if np.sign(f) == np.sign(fa):
                sa, fa, pa, end_a = sig, f, p, pt
                if side == -1 and key != "contact":
                    fb *= 0.5
                side = -1
            else:
                sb, fb, pb, end_b = sig, f, p, pt
                if side == 1 and key != "contact":
                    fa *= 0.5
                side = 1
            pf = p
            if max(abs(pa - pf), abs(pb - pf)) <= self.st.locate_tol and (
                    key != "fold" or abs(sb - sa) < 1e-3):
                break
            if f == 0.0:
                pa = pb = pf
                break
        return best, pa, pb, end_a, end_b

    def _step_range(self, a: _Point, b: _Point) -> tuple[float, float]:
        """The parameter range the branch can cover between a and b: their values, widened by
        the chord (in the parameter) where the parameter turns in the step."""
        tr = self.tr
        lo, hi = sorted((tr.p_of(a.z), tr.p_of(b.z)))
        if np.sign(a.tangent[-1]) != np.sign(b.tangent[-1]):
            w = float(np.linalg.norm(b.z - a.z)) * tr.pscale
            lo, hi = lo - w, hi + w
        return lo, hi

    def _locate(self, a: _Point, b: _Point, kind: str, key: str, mesh: int | None
                ) -> BifurcationPoint | None:
        """The bifurcation ``kind`` whose test function ``key`` changes sign between a and b,
        located (:meth:`_search`), or kept as not located with its bracket; None for a
        Neimark-Sacker candidate without a complex pair through the unit circle."""
        tr = self.tr
        best, pa, pb, end_a, end_b = self._search(a, b, key, mesh)
        lo, hi = self._step_range(a, b)
        slack = self.st.locate_tol
        why = ""
        if best is None:
            why = f"the first trial failed: {self._trial_failure or 'no corrector'}"
        elif not lo - slack <= tr.p_of(best.z) <= hi + slack:
            why = (f"the located value {tr.p_of(best.z):.8g} lies outside the step "
                   f"[{lo:.8g}, {hi:.8g}]")
            pa, pb, end_a, end_b = tr.p_of(a.z), tr.p_of(b.z), a, b
        if kind == "neimark-sacker":
            if _complex_outside(a.mu) == _complex_outside(b.mu) and (
                    why or neimark_sacker_pair(best.mu) is None):
                return None  # a real pair's product through 1 (e.g. a neutral saddle)
            if not why and neimark_sacker_pair(best.mu) is None:
                why = (f"no complex pair within {NS_MODULUS_TOL:g} of the unit circle at "
                       f"{tr.p_of(best.z):.8g}")
        if why:
            return self._not_located(a, b, kind, key, mesh, (pa, pb), (end_a, end_b), why)
        p = tr.p_of(best.z)
        err = max(abs(pa - p), abs(pb - p))
        crit = _critical(kind, best.mu) if key != "contact" else complex(np.nan)
        detail = self._detail(kind, key, mesh, a, b, crit)
        M = best.ev.monodromy if key != "contact" else np.full_like(a.ev.monodromy, np.nan)
        return BifurcationPoint(kind, p, err, len(self.points) - 1, self.number, tr.x_of(best.z),
                                crit, detail, M.copy(), tr.period)

    def _detail(self, kind: str, key: str, mesh: int | None, a: _Point, b: _Point,
                crit: complex) -> str:
        if kind == "contact":
            ca, cb = self._value(a, key, mesh), self._value(b, key, mesh)
            return f"{int(ca)} -> {int(cb)} edge crossings per orbit period"
        if kind == "neimark-sacker":
            return f"complex pair |mu| = 1, angle {math.degrees(abs(np.angle(crit))):.4g} deg"
        if kind == "branch point" and key == "fold":
            return (f"the parameter turns with no multiplier through +1 (multiplier "
                    f"{crit.real:.6g}): another branch meets this one (e.g. a period-2k branch "
                    f"its period-k orbit at a period doubling)")
        if kind == "branch point":
            return f"multiplier {crit.real:.6g} through +1 without a turn: another branch crosses"
        return f"multiplier {crit.real:.6g}"

    def _not_located(self, a: _Point, b: _Point, kind: str, key: str, mesh: int | None,
                     bracket: tuple[float, float], ends: tuple[_Point, _Point], why: str
                     ) -> BifurcationPoint:
        """The bifurcation kept though not located: value the bracket's midpoint, error its
        half-width (widened by the step's chord where the parameter turns), x and monodromy of
        the bracket's end where the test function is smaller."""
        tr = self.tr
        lo, hi = sorted(bracket)
        if key == "fold":  # the turning value lies beyond both ends, within the chord
            w = float(np.linalg.norm(b.z - a.z)) * tr.pscale
            lo, hi = lo - w, hi + w
        if key == "contact":
            end = ends[0]
            crit = complex(np.nan)
        else:
            fa, fb = (abs(self._value(e, key, mesh)) for e in ends)
            end = ends[0] if fa <= fb else ends[1]
            crit = _critical(kind, end.mu)
        detail = self._detail(kind, key, mesh, a, b, crit) if key == "contact" else (
            f"multiplier {crit:.6g} at {tr.p_of(end.z):.8g}")
        detail = (f"not located ({why}): the test function changed sign in "
                  f"[{lo:.8g}, {hi:.8g}]; {detail}")
        M = end.ev.monodromy if key != "contact" else np.full_like(a.ev.monodromy, np.nan)
        return BifurcationPoint(kind, 0.5 * (lo + hi), 0.5 * (hi - lo), len(self.points) - 1,
                                self.number, tr.x_of(end.z), crit, detail, M.copy(), tr.period,
                                located=False, section_value=tr.p_of(end.z))


# ----------------------------------------------------------------------------- the API
def continuation(model: Model, param: str = "Omega", start: float | None = None,
                 stop: float | None = None, period: int = 1, guess: np.ndarray | None = None,
                 run: RunSettings | None = None, *, settings: ContinuationSettings | None = None,
                 switch: bool | Callable[[BifurcationPoint], bool] = False,
                 steps_per_period: int | None = None,
                 progress: Callable[[int, float], None] | None = None,
                 **legacy: Any) -> xr.Dataset:
    """Follow the period-``period`` orbit of ``model`` in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    param
        ``"Omega"`` or any name the model's ``with_params``/``lane_params`` accept (as
        :func:`geardyn.bifurcation` sweeps it).
    start, stop
        The parameter range (``start`` default the model's value). The branch starts at
        ``start`` and heads towards ``stop``; it ends where it leaves [min, max] of the two.
    period
        k: orbits of the k-th iterate of the section map.
    guess
        A state near the orbit at ``start`` (default: the end of a transient run there, 200
        section periods but at most :data:`GUESS_TIME` time units; ``run.transient`` if given).
    run
        :class:`~geardyn.RunSettings` (``steps_per_period``, ``bound``; ``transient``,
        ``converge`` and ``transient_max`` of the default guess, see
        :func:`~geardyn.analysis.orbits.default_guess`).
    settings
        :class:`~geardyn.ContinuationSettings`: the arclength steps ``ds``, ``ds_min``,
        ``ds_max`` (in the scaled unknowns x / state_scale, p / p_scale; ``p_scale`` default
        ``abs(stop - start)``), ``max_points``, the corrector tolerance ``tol``, the location
        tolerance ``locate_tol`` and the switching limit ``max_period``. Its fields given as
        keyword arguments are deprecated (a DeprecationWarning).
    switch
        At each located period doubling start the period-2k branch: True for every one, or a
        function of the :class:`BifurcationPoint` saying whether to; recursively (a cascade) while
        2k <= ``settings.max_period``.
    steps_per_period
        RK4 steps per forcing period, fixed, of a call without ``run`` (with ``run``, give
        ``run.steps_per_period``: both together are a TypeError naming both values); default
        :data:`BRANCH_STEP_FACTOR` times the step rule, re-derived along the branch.
    progress
        Called as ``progress(points, value)`` after each accepted point.

    Returns a Dataset (``geardyn_kind = "continuation"``; see ``docs/continuation.md``): the
    points of every branch along ``point``, the bifurcations along ``bifurcation``, one entry
    per branch along ``branch_id``. A failure is not an exception: it ends its branch with
    ``branch_status`` and ``branch_message`` naming the parameter value, keeping its points.
    """
    cs = resolve_settings(ContinuationSettings, settings, legacy, "continuation")
    steps_per_period = orbit_steps(run, steps_per_period, "continuation")
    if start is None:  # a coefficient's current value (a KeyError naming the known ones)
        start = float(model.params[model._param_index(param)])
    if stop is None:
        raise ValueError("stop: give the other end of the parameter range")
    start, stop = float(start), float(stop)
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ValueError(f"start and stop must be finite and different (got {start}, {stop})")
    pscale = cs.p_scale if cs.p_scale is not None else abs(stop - start)
    st = _Settings(min(start, stop), max(start, stop), cs.ds, cs.ds_min, cs.ds_max,
                   cs.max_points, cs.locate_tol, progress)
    try:  # an unknown name: the model's KeyError naming the known ones
        at_start = model.with_params(**{param: start})
    except ValueError as err:
        if isinstance(err, KeyError):  # UnknownParameterError is both
            raise
        raise ValueError(f"{param}={start:g} is outside the model's valid region: {err}"
                         ) from err
    tracer = _Tracer(at_start, param, period, pscale, run, steps_per_period, cs.tol,
                     CORRECTOR_MAX_ITER)
    tracer.n = tracer.steps_for(start)
    runs: list[BranchRun] = []
    first_run = _first_branch(tracer, st, start, stop, guess, run)
    runs.append(first_run)
    _switch_all(model if param == "Omega" else at_start, param, runs, st, run,
                steps_per_period, cs.tol, switch, cs.max_period, pscale)
    return branch_dataset(model, param, start, stop, runs, tracer)


def _first_branch(tracer: _Tracer, st: _Settings, start: float, stop: float,
                  guess: np.ndarray | None, run: RunSettings | None) -> BranchRun:
    """Converge the orbit at ``start`` and continue it towards ``stop``."""
    pr = tracer.problem_at(start)
    if guess is None:
        T_s = pr.sections * 2 * math.pi / pr.omega
        transient = min(GUESS_PERIODS * T_s, GUESS_TIME) if run is None else run.transient
        guess = default_guess(pr, transient=transient,
                              converge=None if run is None else run.converge,
                              transient_max=None if run is None else run.transient_max)
    guess = np.asarray(guess, dtype=float)
    if guess.shape != (pr.model.n_states,):
        raise ValueError(f"guess must have {pr.model.n_states} entries")
    res = newton_shooting(pr, guess, tracer.tol)
    if res.status != OrbitStatus.CONVERGED:
        return BranchRun(tracer.period, [], [], BranchStatus.START_FAILED,
                         f"no orbit at {tracer.param}={start:.8g}: {res.message}")
    z = tracer.z_of(res.x, start)
    ev = res.evaluation
    try:
        J = tracer.jacobian(z, ev)
    except (_Invalid, FloatingPointError) as err:
        return BranchRun(tracer.period, [], [], BranchStatus.START_FAILED,
                         f"no branch from {tracer.param}={start:.8g}: next to it {err}")
    pt = _Point(z, ev, pr, J, iterations=res.iterations)
    pt.tangent = _null_tangent(J, stop - start)
    runner = _BranchRunner(tracer, st, 0)
    status, msg = runner.run(pt, st.ds)
    return BranchRun(tracer.period, runner.points, runner.bifs, status, msg)


def _switch_all(model: Model, param: str, runs: list[BranchRun], st: _Settings,
                run: RunSettings | None, steps_per_period: int | None, tol: float,
                switch: bool | Callable[[BifurcationPoint], bool], max_period: int,
                pscale: float) -> None:
    """Branch switching at the period doublings of ``runs`` (growing the list: a cascade)."""
    if switch is False:
        return
    i = 0
    while i < len(runs):
        for b in runs[i].bifurcations:
            if b.kind != "period-doubling" or 2 * b.period > max_period:
                continue
            if callable(switch) and not switch(b):
                continue
            runs.append(_switched(model, param, b, len(runs), st, run, steps_per_period, tol,
                                  pscale))
            runs[-1].parent = _bif_number(runs, b)
        i += 1


def _bif_number(runs: list[BranchRun], b: BifurcationPoint) -> int:
    """The index of ``b`` in the concatenated bifurcation table of ``runs``."""
    k = 0
    for r in runs:
        for c in r.bifurcations:
            if c is b:
                return k
            k += 1
    return -1


def _switched(model: Model, param: str, b: BifurcationPoint, number: int, st: _Settings,
              run: RunSettings | None, steps_per_period: int | None, tol: float,
              pscale: float) -> BranchRun:
    """The period-2k branch from the period doubling ``b``: predictor along the eigenvector of
    the multiplier -1 at fixed parameter, the corrector on the doubled map."""
    k2 = 2 * b.period
    at = model.with_params(**{param: b.at})
    tracer = _Tracer(at, param, k2, pscale, run, steps_per_period, tol, CORRECTOR_MAX_ITER)
    tracer.n = tracer.steps_for(b.at)
    mu, V = np.linalg.eig(b.monodromy)
    v = np.real(V[:, int(np.argmin(np.abs(mu + 1.0)))]) / tracer.scale
    v /= np.linalg.norm(v)
    t0 = np.concatenate([v, [0.0]])
    z0 = tracer.z_of(b.x, b.at)
    msg = ""
    where = "" if b.located else (f" (not located: started from the bracket's end at "
                                  f"{param}={b.at:.8g})")
    for h in (0.02, 0.05, 0.01, 0.1, 0.005):
        got = tracer.correct(z0 + h * t0, t0)
        if not isinstance(got, _Point):
            msg = got.message
            continue
        x = tracer.x_of(got.z)
        half = replace(got.problem, period=b.period).evaluate(x, jacobian=False)
        if float(np.max(np.abs(half.residual / tracer.scale))) < 1e-6 * h:
            msg = "the corrector went back to the period-k orbit"
            continue
        got.tangent = tracer.tangent(got.jac, t0)
        runner = _BranchRunner(tracer, st, number)
        status, message = runner.run(got, min(st.ds, h))
        return BranchRun(k2, runner.points, runner.bifs, status, message + where)
    return BranchRun(k2, [], [], BranchStatus.START_FAILED,
                     f"no period-{k2} orbit found next to the period doubling at "
                     f"{param}={b.value:.8g}{where}: {msg}")

