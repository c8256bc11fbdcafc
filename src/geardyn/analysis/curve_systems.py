"""Minimally augmented defining systems of fold, period-doubling and Neimark-Sacker curves.

A curve of codimension-1 bifurcations of period-k orbits in two parameters (x, y) is a curve of
zeros of H(z) = (G(u, x, y), g(u, x, y)) in the scaled unknowns z = (u / state_scale,
x / x_scale, y / y_scale): G = P^k(u) - u the shooting residual of
:mod:`geardyn.analysis.orbits` (scaled by the state scale) and g the bordered test function of a
matrix A that is singular at the bifurcation, all in scaled state coordinates
(M = S^-1 dP^k/du S, S = diag(state_scale)):

* fold: A = M - I (a multiplier +1);
* period doubling: A = M + I (a multiplier -1);
* Neimark-Sacker: A = M (.) M - I, M (.) M the second compound matrix of M (its eigenvalues are
  the products mu_i mu_j, i < j), singular where two multipliers have product 1: a complex pair
  on the unit circle (Neimark-Sacker) or a real pair mu, 1/mu (a neutral saddle, not a
  bifurcation; the curve passes from one to the other at a 1:1 or 1:2 resonance).

g solves the bordered system [[A, b], [c^T, 0]] [v; g] = [0; 1], with b and c near the left and
right null vectors of A (reset at every accepted point of the curve; the zero set of g does not
depend on them). Its derivative is g_z = -w^T A_z v, w from the transposed system; A_z comes
from central differences of the monodromy: for fold and period doubling one difference along v
in the state (D^2 P (v, .) is symmetric: step :data:`STATE_STEP` in the scaled state) and one per
parameter (step :data:`~geardyn.core.settings.PARAM_STEP_REL` (1 + |p|)); for Neimark-Sacker one
per state coordinate and parameter. The same parameter differences give dG/dx and dG/dy. A
Jacobian thus costs 1 + 2 + 4 period maps with monodromy for fold and period doubling, 1 + 2 n + 4
for Neimark-Sacker.

The steps per forcing period stay fixed along a curve (the residual is then one smooth
function of z).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from itertools import combinations

import numpy as np

from geardyn.analysis.arclength import OutsideDomain
from geardyn.analysis.orbits import ShootingEval, ShootingProblem, problem_with_steps
from geardyn.core.model import Model
from geardyn.core.settings import PARAM_STEP_REL, RunSettings
from geardyn.core.status import Status

#: The curve kinds (``curve_kind``) this module defines, in words.
CURVE_KINDS = {
    "fold": "a real multiplier +1 (limit point of the orbit branch)",
    "period_doubling": "a real multiplier -1",
    "neimark_sacker": "two multipliers with product 1: a complex pair on the unit circle "
                      "(a real pair mu, 1/mu where the curve continues as a neutral saddle)",
}
#: Central-difference step of the monodromy along v, in the scaled state.
STATE_STEP = 1e-5


def compound2(M: np.ndarray) -> np.ndarray:
    """The second compound matrix of M (its 2 x 2 minors over index pairs i < j, in
    lexicographic order): its eigenvalues are mu_i mu_j, i < j."""
    n = M.shape[0]
    pairs = list(combinations(range(n), 2))
    out = np.empty((len(pairs), len(pairs)))
    for r, (i, j) in enumerate(pairs):
        for c, (k, m) in enumerate(pairs):
            out[r, c] = M[i, k] * M[j, m] - M[i, m] * M[j, k]
    return out


def singular_matrix(kind: str, M: np.ndarray) -> np.ndarray:
    """The matrix A of ``kind`` that is singular on the curve (see the module docstring)."""
    if kind == "fold":
        return M - np.eye(M.shape[0])
    if kind == "period_doubling":
        return M + np.eye(M.shape[0])
    if kind == "neimark_sacker":
        C = compound2(M)
        return C - np.eye(C.shape[0])
    raise ValueError(f"curve kind must be one of {', '.join(CURVE_KINDS)} (got {kind!r})")


def null_vectors(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(left, right) singular vectors of the least singular value of A: the bordering vectors
    b and c of a start point."""
    U, _s, Vt = np.linalg.svd(A)
    return U[:, -1].copy(), Vt[-1].copy()


def bordered(A: np.ndarray, b: np.ndarray, c: np.ndarray
             ) -> tuple[float, np.ndarray, np.ndarray]:
    """(g, v, w): [[A, b], [c^T, 0]] [v; g] = [0; 1] and its transpose [w; g]. Raises
    :class:`FloatingPointError` where the bordered matrix is singular."""
    m = A.shape[0]
    K = np.zeros((m + 1, m + 1))
    K[:m, :m], K[:m, m], K[m, :m] = A, b, c
    rhs = np.zeros(m + 1)
    rhs[m] = 1.0
    try:
        right = np.linalg.solve(K, rhs)
        left = np.linalg.solve(K.T, rhs)
    except np.linalg.LinAlgError as err:
        raise FloatingPointError("singular bordered matrix of the test function") from err
    return float(right[m]), right[:m], left[:m]


@dataclass
class CurveInfo:
    """What a residual evaluation returns with a point: the evaluation (with the monodromy),
    its problem, the scaled monodromy ``M``, the multipliers ``mu`` (decreasing modulus), the
    test function ``g`` and the bordered system's ``v`` and ``w``."""

    ev: ShootingEval
    problem: ShootingProblem
    M: np.ndarray
    mu: np.ndarray
    g: float
    v: np.ndarray
    w: np.ndarray


class CurveSystem:
    """H(z) = (G, g) of one curve kind of ``model``'s period-``period`` orbits in the parameters
    ``x`` and ``y`` (scales ``x_scale``, ``y_scale``), ``steps_per_period`` RK4 steps per
    forcing period (bound and section limit from ``run``)."""

    def __init__(self, model: Model, kind: str, x: str, y: str, period: int,
                 steps_per_period: int, x_scale: float, y_scale: float,
                 run: RunSettings | None = None):
        singular_matrix(kind, np.eye(2))  # the kind's ValueError
        self.model, self.kind, self.x, self.y = model, kind, x, y
        self.period = int(period)
        self.x_scale, self.y_scale = float(x_scale), float(y_scale)
        self.base = problem_with_steps(model, None, period, run, int(steps_per_period))
        self.scale = np.asarray(self.base.scale, dtype=float)
        self.n = model.n_states
        self.b: np.ndarray | None = None
        self.c: np.ndarray | None = None
        self._cache: dict[tuple[float, float], ShootingProblem] = {}

    # -- unknowns
    def z_of(self, u: np.ndarray, px: float, py: float) -> np.ndarray:
        return np.concatenate([np.asarray(u, dtype=float) / self.scale,
                               [px / self.x_scale, py / self.y_scale]])

    def state(self, z: np.ndarray) -> np.ndarray:
        return z[: self.n] * self.scale

    def xy(self, z: np.ndarray) -> tuple[float, float]:
        return float(z[self.n] * self.x_scale), float(z[self.n + 1] * self.y_scale)

    def where(self, z: np.ndarray) -> str:
        px, py = self.xy(z)
        return f"{self.x}={px:.8g}, {self.y}={py:.8g}"

    # -- problems
    def problem_at(self, px: float, py: float) -> ShootingProblem:
        """The shooting problem at (x, y) = (px, py); :class:`OutsideDomain` where the model
        refuses the values or the section changes."""
        key = (px, py)
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        if not (math.isfinite(px) and math.isfinite(py)):
            raise OutsideDomain(f"{self.x}={px!r}, {self.y}={py!r} is not finite")
        try:
            P = self.model.lane_params_grid(self.x, [px], self.y, [py])[0]
            pr = self.base.with_params(P)
        except KeyError:
            raise
        except ValueError as err:
            raise OutsideDomain(f"at {self.x}={px:.8g}, {self.y}={py:.8g}: {err}") from err
        if pr.sections != self.base.sections:
            raise OutsideDomain(f"at {self.x}={px:.8g}, {self.y}={py:.8g} the common period of "
                                f"the forcings changes from {self.base.sections} to "
                                f"{pr.sections} forcing periods (another section map)")
        pr = replace(pr, steps_per_period=self.base.steps_per_period)
        if len(self._cache) > 64:
            self._cache.clear()
        self._cache[key] = pr
        return pr

    def _eval(self, pr: ShootingProblem, u: np.ndarray, jacobian: bool = True) -> ShootingEval:
        ev = pr.evaluate(u, jacobian=jacobian)
        if not ev.ok or not np.all(np.isfinite(ev.end)) or (
                jacobian and not np.all(np.isfinite(ev.monodromy))):
            raise FloatingPointError(f"the period map diverged ({Status(int(ev.status)).message})")
        return ev

    def scaled_monodromy(self, ev: ShootingEval) -> np.ndarray:
        s = self.scale
        return ev.monodromy * s[None, :] / s[:, None]

    def set_border(self, info: CurveInfo) -> None:
        """Border the test function with the null vectors ``w`` and ``v`` of ``info``."""
        self.b = info.w / np.linalg.norm(info.w)
        self.c = info.v / np.linalg.norm(info.v)

    def border_at(self, M: np.ndarray) -> None:
        """Border with the least singular vectors of A at the scaled monodromy ``M``."""
        self.b, self.c = null_vectors(singular_matrix(self.kind, M))

    # -- the residual
    def residual(self, z: np.ndarray, jacobian: bool) -> tuple[np.ndarray, np.ndarray | None,
                                                                CurveInfo]:
        """(H, dH/dz or None, :class:`CurveInfo`) at z (the arclength follower's residual)."""
        px, py = self.xy(z)
        u = self.state(z)
        pr = self.problem_at(px, py)
        ev = self._eval(pr, u)
        M = self.scaled_monodromy(ev)
        if self.b is None:
            self.border_at(M)
        A = singular_matrix(self.kind, M)
        g, v, w = bordered(A, self.b, self.c)
        mu = np.linalg.eigvals(ev.monodromy)
        mu = mu[np.argsort(-np.abs(mu), kind="stable")]
        info = CurveInfo(ev, pr, M, mu, g, v, w)
        H = np.concatenate([ev.residual / self.scale, [g]])
        if not jacobian:
            return H, None, info
        return H, self._jacobian(z, info), info

    def _jacobian(self, z: np.ndarray, info: CurveInfo) -> np.ndarray:
        n, s = self.n, self.scale
        px, py = self.xy(z)
        u = self.state(z)
        v, w = info.v, info.w
        J = np.zeros((n + 1, n + 2))
        J[:n, :n] = info.M - np.eye(n)
        if self.kind == "neimark_sacker":  # A_z v per state coordinate
            for j in range(n):
                h = STATE_STEP
                e = np.zeros(n)
                e[j] = h * s[j]
                Ap = singular_matrix(self.kind, self.scaled_monodromy(
                    self._eval(info.problem, u + e)))
                Am = singular_matrix(self.kind, self.scaled_monodromy(
                    self._eval(info.problem, u - e)))
                J[n, j] = -w @ ((Ap - Am) @ v) / (2 * h)
        else:  # D^2 P (v, e_j) = d/de M(u + e v) e_j
            h = STATE_STEP / max(float(np.linalg.norm(v)), 1e-300)
            Mp = self.scaled_monodromy(self._eval(info.problem, u + h * s * v))
            Mm = self.scaled_monodromy(self._eval(info.problem, u - h * s * v))
            J[n, :n] = -(w @ (Mp - Mm)) / (2 * h)
        for col, (p, ps) in enumerate(((px, self.x_scale), (py, self.y_scale))):
            h = PARAM_STEP_REL * (1.0 + abs(p))
            at = (p + h, py) if col == 0 else (px, p + h)
            bt = (p - h, py) if col == 0 else (px, p - h)
            up = self._eval(self.problem_at(*at), u)
            dn = self._eval(self.problem_at(*bt), u)
            J[:n, n + col] = (up.residual - dn.residual) / (2 * h) * ps / s
            dA = (singular_matrix(self.kind, self.scaled_monodromy(up))
                  - singular_matrix(self.kind, self.scaled_monodromy(dn))) / (2 * h)
            J[n, n + col] = -(w @ (dA @ v)) * ps
        return J

    # -- maps for the normal forms
    def period_map(self, pr: ShootingProblem, u_scaled: np.ndarray) -> np.ndarray:
        """P^k at the scaled state ``u_scaled``, scaled."""
        return self._eval(pr, u_scaled * self.scale, jacobian=False).end / self.scale

    def directions(self, info: CurveInfo, target: complex) -> tuple[np.ndarray, np.ndarray]:
        """(p, q): left and right eigenvectors of the scaled monodromy for its real eigenvalue
        nearest ``target`` (+1 or -1), q unit, p^T q = 1."""
        M = info.M
        lam, V = np.linalg.eig(M)
        i = int(np.argmin(np.abs(lam - target)))
        q = np.real(V[:, i])
        q /= np.linalg.norm(q)
        lamT, W = np.linalg.eig(M.T)
        p = np.real(W[:, int(np.argmin(np.abs(lamT - target)))])
        return p / (p @ q), q

