"""Pseudo-arclength continuation of periodic orbits in any parameter, with their bifurcations.

A branch is a curve of zeros of G(x, p) = P^k(x; p) - x, the shooting residual of
:mod:`geardyn.analysis.orbits` (P the section map at the coefficient vector of parameter value
p), followed in the arclength of the scaled unknowns z = (x / state_scale, p / p_scale):

* **predictor** z + ds t, t the unit tangent (the null vector of [M - I, dG/dp], oriented
  along the previous tangent);
* **corrector** Newton on G(z) = 0 together with t . (z - z_pred) = 0 (Keller's bordered
  system): dG/dx = M - I from the monodromy kernel, dG/dp by a central difference of the
  residual (step 1e-6 (1 + |p|));
* **step control** the step grows after a corrector of at most 2 iterations, shrinks after a
  slow one, is halved after a failure or a turn of the tangent by more than ~25 degrees, and
  the branch ends when it would fall below ``ds_min``.

Test functions on each step between two accepted points (see ``docs/continuation.md``):

* fold: the p component of the tangent changes sign (a real multiplier through +1);
* period doubling: det(M + I) changes sign (a real multiplier through -1);
* Neimark-Sacker: prod_{i<j} (mu_i mu_j - 1) changes sign with the critical pair complex;
* contact change: the edge crossings per orbit period of a mesh change.

Each is located on the step by regula falsi (Illinois; bisection for the integer contact test)
on the arclength between the two points, each trial corrected onto the branch, until the
parameter is known to ``locate_tol``.
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
    shooting_problem,
)
from geardyn.core.model import Model
from geardyn.core.plan import default_steps_per_period
from geardyn.core.settings import RunSettings
from geardyn.core.status import Status

#: Corrector tolerance: max |G / state_scale| <= tol (1 + max |x / state_scale|).
CORRECTOR_TOL = 1e-10
#: Most corrector iterations per step.
CORRECTOR_MAX_ITER = 12
#: The step grows after a corrector of at most this many iterations, shrinks after one of at
#: least SHRINK_ITER (chord iterations: each costs one period map).
GROW_ITER = 5
SHRINK_ITER = 9
#: Relative step of the central difference dG/dp.
DP_REL = 1e-6
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
#: Default location tolerance in the parameter.
LOCATE_TOL = 1e-7
#: Most trials of a location.
LOCATE_MAX_ITER = 60
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
    """A located bifurcation: ``kind`` (fold, period-doubling, neimark-sacker, contact),
    parameter value ``value`` with ``error`` (a bound on the distance to the true switch point
    of the test function), ``index`` (the branch point before it), ``branch`` (the branch's
    number), ``x`` (the section point there), ``multiplier`` (the critical multiplier; NaN for
    contact), ``detail`` (words), ``monodromy`` and ``period`` (k of the branch)."""

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
        self.fixed_steps = steps_per_period or (run.steps_per_period if run else None)
        self.tol, self.max_iter = tol, max_iter
        self.base = shooting_problem(model, None, period, run, self.fixed_steps or None)
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
        if self.param == "Omega":
            if not p > 0:
                raise _Invalid(f"Omega must be > 0 (got {p:.8g})")
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
        h = DP_REL * (1.0 + abs(p))
        x = self.x_of(z)
        up = self.problem_at(p + h).evaluate(x, jacobian=False)
        dn = self.problem_at(p - h).evaluate(x, jacobian=False)
        if up.status != Status.OK or dn.status != Status.OK:
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
                if ev.status != Status.OK:
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
def _tests(pt: _Point) -> dict[str, Any]:
    """The test functions at a point: fold (p component of the tangent), pd (det(M + I)),
    ns (prod over pairs of mu_i mu_j - 1), contact (crossings per orbit period per mesh)."""
    M = pt.ev.monodromy
    mu = pt.mu
    prod = np.prod([mu[i] * mu[j] - 1.0 for i in range(mu.size) for j in range(i + 1, mu.size)])
    ns = float(np.real(prod)) if mu.size > 1 else 1.0
    c = pt.ev.crossings
    meshes = pt.problem.model.meshes
    return {"fold": float(pt.tangent[-1]), "pd": float(np.linalg.det(M + np.eye(M.shape[0]))),
            "ns": ns, "contact": tuple(int(c[i] + c[j]) for _, i, j in meshes)}


def _spectrum_moved(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a multiplier of ``b`` to the nearest of ``a``."""
    return float(np.max(np.min(np.abs(b[:, None] - a[None, :]), axis=1)))


def _critical(kind: str, mu: np.ndarray) -> complex:
    """The multiplier that a bifurcation of ``kind`` is about."""
    if kind == "fold":
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
        tests = _tests(cur)
        while True:
            if len(self.points) >= st.max_points:
                return BranchStatus.MAX_POINTS, (f"stopped after {st.max_points} points at "
                                                 f"{tr.param}={tr.p_of(cur.z):.8g}")
            nxt, fail = None, None
            while nxt is None:
                z_pred = cur.z + ds * cur.tangent
                got = tr.correct(z_pred, cur.tangent, cur.jac)
                if isinstance(got, _Point):
                    got.tangent = tr.tangent(got.jac, cur.tangent)
                    turn = got.tangent @ cur.tangent < MIN_COS
                    moved = _spectrum_moved(cur.mu, got.mu) > MAX_MU_MOVE and ds > MU_MOVE_DS
                    if not (turn or moved) or ds <= st.ds_min:
                        nxt = got
                        break
                    got = _Failure(BranchStatus.NOT_CONVERGED, f"the tangent turned sharply "
                                   f"at {tr.param}={tr.p_of(got.z):.8g}")
                fail = got
                if ds <= st.ds_min:
                    return fail.status, (f"{fail.status.message}: {fail.message} (step "
                                         f"{ds:.3g}); the branch ends at "
                                         f"{tr.param}={tr.p_of(cur.z):.8g}")
                ds = max(st.ds_min, ds / 2)
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
            if nxt.iterations <= GROW_ITER:
                ds = min(st.ds_max, ds * 1.6)
            elif nxt.iterations >= SHRINK_ITER:
                ds = max(st.ds_min, ds * 0.6)
            tr.renew_steps(p_new)
            cur, tests = nxt, new_tests

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

    # -- detection and location
    def _detect(self, a: _Point, b: _Point, ta: dict, tb: dict) -> None:
        found: list[BifurcationPoint] = []
        for kind, key in (("fold", "fold"), ("period-doubling", "pd"),
                          ("neimark-sacker", "ns")):
            if np.sign(ta[key]) != np.sign(tb[key]) and ta[key] != 0 and tb[key] != 0:
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
        monodromy and tangent when ``final``)."""
        tr = self.tr
        z_pred = a.z + sigma * (b.z - a.z)
        t = b.z - a.z
        t = t / np.linalg.norm(t)
        got = tr.correct(z_pred, t, a.jac, final=final)
        if not isinstance(got, _Point):  # e.g. at a graze: Newton with fresh Jacobians
            got = tr.correct(z_pred, t, None, 3 * tr.max_iter, final=final)
        if not isinstance(got, _Point):
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

    def _locate(self, a: _Point, b: _Point, kind: str, key: str, mesh: int | None
                ) -> BifurcationPoint | None:
        """Regula falsi (Illinois) on the arclength fraction between a and b for the zero of
        the test function (bisection for the contact count), each trial corrected."""
        tr = self.tr
        fa, fb = self._value(a, key, mesh), self._value(b, key, mesh)
        ca, cb = fa, fb
        if key == "contact":  # an integer: bisect on the side it is on
            fa, fb = -1.0, 1.0
        sa, sb = 0.0, 1.0
        pa, pb = tr.p_of(a.z), tr.p_of(b.z)
        best, best_f, side = None, math.inf, 0
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
                sa, fa, pa = sig, f, p
                if side == -1 and key != "contact":
                    fb *= 0.5
                side = -1
            else:
                sb, fb, pb = sig, f, p
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
        if best is None:
            return None
        p = tr.p_of(best.z)
        err = max(abs(pa - p), abs(pb - p))
        crit = _critical(kind, best.mu) if key != "contact" else complex(np.nan)
        if kind == "neimark-sacker" and not np.isfinite(crit.real):
            return None  # a neutral saddle (a real pair mu, 1/mu), not a bifurcation
        if kind == "contact":
            detail = f"{int(ca)} -> {int(cb)} edge crossings per orbit period"
        elif kind == "neimark-sacker":
            detail = f"complex pair |mu| = 1, angle {math.degrees(abs(np.angle(crit))):.4g} deg"
        else:
            detail = f"multiplier {crit.real:.6g}"
        M = best.ev.monodromy if key != "contact" else np.full_like(a.ev.monodromy, np.nan)
        return BifurcationPoint(kind, p, err, len(self.points) - 1, self.number, tr.x_of(best.z),
                           crit, detail, M.copy(), tr.period)


# ----------------------------------------------------------------------------- the API
def continuation(model: Model, param: str = "Omega", start: float | None = None,
                 stop: float | None = None, period: int = 1, guess: np.ndarray | None = None,
                 run: RunSettings | None = None, *, ds: float = 0.01, ds_min: float = 1e-7,
                 ds_max: float = 0.2, max_points: int = 2000,
                 tol: float = CORRECTOR_TOL, locate_tol: float = LOCATE_TOL,
                 switch: bool | Callable[[BifurcationPoint], bool] = False, max_period: int = 16,
                 steps_per_period: int | None = None, p_scale: float | None = None,
                 progress: Callable[[int, float], None] | None = None) -> xr.Dataset:
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
    ds, ds_min, ds_max
        First, least and greatest arclength step in the scaled unknowns (x / state_scale,
        p / p_scale; ``p_scale`` default ``abs(stop - start)``).
    tol, locate_tol
        Corrector tolerance (scaled residual) and the location tolerance in the parameter.
    switch
        At each located period doubling start the period-2k branch: True for every one, or a
        function of the :class:`BifurcationPoint` saying whether to; recursively (a cascade) while
        2k <= ``max_period``.
    steps_per_period
        RK4 steps per forcing period, fixed (default: :data:`BRANCH_STEP_FACTOR` times the step
        rule, re-derived along the branch).
    progress
        Called as ``progress(points, value)`` after each accepted point.

    Returns a Dataset (``geardyn_kind = "continuation"``; see ``docs/continuation.md``): the
    points of every branch along ``point``, the bifurcations along ``bifurcation``, one entry
    per branch along ``branch_id``. A failure is not an exception: it ends its branch with
    ``branch_status`` and ``branch_message`` naming the parameter value, keeping its points.
    """
    if start is None:  # a coefficient's current value (a KeyError naming the known ones)
        start = float(model.params[model._param_index(param)])
    if stop is None:
        raise ValueError("stop: give the other end of the parameter range")
    start, stop = float(start), float(stop)
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ValueError(f"start and stop must be finite and different (got {start}, {stop})")
    if not 0 < ds_min <= ds <= ds_max:
        raise ValueError("need 0 < ds_min <= ds <= ds_max")
    pscale = float(p_scale) if p_scale else abs(stop - start)
    st = _Settings(min(start, stop), max(start, stop), ds, ds_min, ds_max, int(max_points),
                   float(locate_tol), progress)
    try:  # an unknown name: the model's KeyError naming the known ones
        at_start = model.with_params(**{param: start})
    except ValueError as err:
        if isinstance(err, KeyError):  # UnknownParameterError is both
            raise
        raise ValueError(f"{param}={start:g} is outside the model's valid region: {err}"
                         ) from err
    tracer = _Tracer(at_start, param, period, pscale, run, steps_per_period, tol,
                     CORRECTOR_MAX_ITER)
    tracer.n = tracer.steps_for(start)
    runs: list[BranchRun] = []
    first_run = _first_branch(tracer, st, start, stop, guess, run)
    runs.append(first_run)
    _switch_all(model if param == "Omega" else at_start, param, runs, st, run,
                steps_per_period, tol, switch, max_period, pscale)
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
    at = model.with_params(**{param: b.value})
    tracer = _Tracer(at, param, k2, pscale, run, steps_per_period, tol, CORRECTOR_MAX_ITER)
    tracer.n = tracer.steps_for(b.value)
    mu, V = np.linalg.eig(b.monodromy)
    v = np.real(V[:, int(np.argmin(np.abs(mu + 1.0)))]) / tracer.scale
    v /= np.linalg.norm(v)
    t0 = np.concatenate([v, [0.0]])
    z0 = tracer.z_of(b.x, b.value)
    msg = ""
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
        return BranchRun(k2, runner.points, runner.bifs, status, message)
    return BranchRun(k2, [], [], BranchStatus.START_FAILED,
                     f"no period-{k2} orbit found next to the period doubling at "
                     f"{param}={b.value:.8g}: {msg}")

