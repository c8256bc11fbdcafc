"""Pseudo-arclength continuation of a curve H(z) = 0, H: R^(m+1) -> R^m, for any residual.

The curves of :mod:`geardyn.analysis` (a periodic orbit in one parameter, a bifurcation or a
contact-change point in two) are each such a curve in their own scaled unknowns z. This module
follows one from a converged point, knowing nothing of what z holds:

* **predictor** z + ds t, t the unit tangent (the null vector of the Jacobian dH/dz, oriented
  along the previous tangent);
* **corrector** Newton on H(z) = 0 together with t . (z - z_pred) = 0 (Keller's bordered
  system), a chord on the last Jacobian while the residual falls by half per iteration;
* **step control** the step grows (x :data:`GROW`) after a corrector of at most
  :data:`GROW_ITER` iterations, shrinks (x :data:`SHRINK`) after one of at least
  :data:`SHRINK_ITER`, is halved after a failure, a correction farther than
  :data:`MAX_CORRECTION` steps from the predictor or a turn of the tangent below
  :data:`MIN_COS`, and the curve ends where it would fall below ``ds_min``.

The residual is a callable ``residual(z, jacobian) -> (H, J, info)``: ``J`` (m x (m+1)) when
``jacobian`` is True, else None, and ``info`` anything the caller wants back with the point
(e.g. the multipliers). It raises :class:`OutsideDomain` where z leaves the problem's valid
region and :class:`FloatingPointError` where the evaluation diverged. How the curve ended is a
:class:`~geardyn.analysis.branch_data.BranchStatus` with a message; a failure is not an
exception.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geardyn.analysis.branch_data import BranchStatus

#: Step growth after an easy corrector, shrink after a slow one.
GROW, SHRINK = 1.6, 0.6
GROW_ITER, SHRINK_ITER = 3, 7
#: Least cosine between successive tangents of an accepted step.
MIN_COS = 0.9
#: A corrected point farther than this many step lengths from its predictor is rejected.
MAX_CORRECTION = 3.0

Residual = Callable[[np.ndarray, bool], tuple[np.ndarray, "np.ndarray | None", Any]]


class OutsideDomain(ValueError):
    """The residual cannot be evaluated at z: it lies outside the problem's valid region."""


@dataclass
class CurvePoint:
    """A converged point: ``z``, its unit ``tangent``, the Jacobian ``jac`` at z, the
    corrector's ``iterations`` and the residual's ``info``."""

    z: np.ndarray
    tangent: np.ndarray
    jac: np.ndarray
    iterations: int
    info: Any = None


@dataclass(frozen=True)
class ArclengthSettings:
    """Steps (in the scaled unknowns z), the most points and the corrector's tolerance:
    converged where ``max |H| <= tol (1 + max |z|)``, in at most ``max_iter`` iterations."""

    ds: float = 0.01
    ds_min: float = 1e-6
    ds_max: float = 0.2
    max_points: int = 200
    tol: float = 1e-9
    max_iter: int = 12

    def __post_init__(self) -> None:
        for name in ("ds", "ds_min", "ds_max", "tol"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number (got {value!r})")
        if not self.ds_min <= self.ds <= self.ds_max:
            raise ValueError(f"ds must lie in [ds_min, ds_max] (got ds_min={self.ds_min!r}, "
                             f"ds={self.ds!r}, ds_max={self.ds_max!r})")
        for name in ("max_points", "max_iter"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be >= 1 (got {getattr(self, name)!r})")


@dataclass
class CurveRun:
    """The points of a followed curve and how it ended."""

    points: list[CurvePoint] = field(default_factory=list)
    status: BranchStatus = BranchStatus.COMPLETED
    message: str = ""


@dataclass
class CurveFailure:
    """Why a correction failed: a status and a message."""

    status: BranchStatus
    message: str


def tangent(J: np.ndarray, ref: np.ndarray | None = None) -> np.ndarray:
    """The unit null vector of ``J`` (m x (m+1)), oriented along ``ref`` when given."""
    if ref is not None:
        try:
            t = np.linalg.solve(np.vstack([J, ref]), np.eye(J.shape[1])[-1])
        except np.linalg.LinAlgError:
            t = np.linalg.svd(J)[2][-1]
    else:
        t = np.linalg.svd(J)[2][-1]
    t = t / np.linalg.norm(t)
    return -t if ref is not None and t @ ref < 0 else t


def correct(residual: Residual, z_pred: np.ndarray, t: np.ndarray, settings: ArclengthSettings,
            J0: np.ndarray | None = None) -> CurvePoint | CurveFailure:
    """Newton on H(z) = 0, t . (z - z_pred) = 0 from ``z_pred`` (a chord on ``J0`` while the
    residual halves per iteration); the point with its own Jacobian, its tangent not yet set."""
    z, J = np.array(z_pred, dtype=float), J0
    last = math.inf
    for it in range(settings.max_iter + 1):
        fresh = J is None
        try:
            r, Jz, info = residual(z, fresh)
            done = bool(np.all(np.isfinite(r))) and (
                float(np.max(np.abs(r))) <= settings.tol * (1.0 + float(np.max(np.abs(z)))))
            if done and not fresh:
                r, Jz, info = residual(z, True)
                fresh = True
            if fresh:
                J = Jz
        except OutsideDomain as err:
            return CurveFailure(BranchStatus.INVALID, str(err))
        except FloatingPointError as err:
            return CurveFailure(BranchStatus.DIVERGED, str(err))
        if not np.all(np.isfinite(r)) or (fresh and not np.all(np.isfinite(J))):
            return CurveFailure(BranchStatus.DIVERGED, "the residual or its Jacobian is not finite")
        if done:
            return CurvePoint(z, np.zeros_like(z), J, it, info)
        norm = float(np.max(np.abs(r)))
        if not fresh and norm > 0.5 * last:
            J, last = None, math.inf
            continue
        last = norm
        if it == settings.max_iter:
            break
        try:
            dz = np.linalg.solve(np.vstack([J, t]), -np.concatenate([r, [t @ (z - z_pred)]]))
        except np.linalg.LinAlgError:
            return CurveFailure(BranchStatus.NOT_CONVERGED, "singular bordered Jacobian")
        z = z + dz
    return CurveFailure(BranchStatus.NOT_CONVERGED,
                    f"the corrector did not converge in {settings.max_iter} iterations")


def follow(residual: Residual, first: CurvePoint, settings: ArclengthSettings, *,
           where: Callable[[np.ndarray], str] = lambda z: f"z={z}",
           stop: Callable[[CurvePoint, CurvePoint], str | None] | None = None,
           on_point: Callable[[CurvePoint], None] | None = None) -> CurveRun:
    """Follow the curve from ``first`` (converged, its ``tangent`` the direction to go).

    ``where(z)`` words a point for the messages (e.g. ``"Omega=1.2, Fm=0.1"``);
    ``stop(previous, new)`` returns a message where the curve ends at ``new`` (e.g. it left
    the parameter box; status COMPLETED), else None; ``on_point`` is called with each
    accepted point (progress). The run ends there, at ``max_points``, or where the step
    would fall below ``ds_min`` (the last failure's status)."""
    out = CurveRun([first])
    if on_point is not None:
        on_point(first)
    cur, ds = first, settings.ds
    while len(out.points) < settings.max_points:
        z_pred = cur.z + ds * cur.tangent
        got = correct(residual, z_pred, cur.tangent, settings, cur.jac)
        if isinstance(got, CurvePoint):
            far = float(np.linalg.norm(got.z - z_pred))
            if far > MAX_CORRECTION * ds:
                got = CurveFailure(BranchStatus.NOT_CONVERGED,
                               f"the corrector moved {far / ds:.3g} step lengths from the "
                               f"predictor to {where(got.z)}")
            else:
                got.tangent = tangent(got.jac, cur.tangent)
                if got.tangent @ cur.tangent < MIN_COS and ds > settings.ds_min:
                    got = CurveFailure(BranchStatus.NOT_CONVERGED,
                                   f"the tangent turned sharply at {where(got.z)}")
        if isinstance(got, CurveFailure):
            if ds <= settings.ds_min:
                out.status = got.status
                out.message = (f"{got.status.message}: {got.message} (step {ds:.3g}); the "
                               f"curve ends at {where(cur.z)}")
                return out
            ds = max(settings.ds_min, ds / 2)
            continue
        out.points.append(got)
        if on_point is not None:
            on_point(got)
        ended = stop(cur, got) if stop is not None else None
        if ended is not None:
            out.status, out.message = BranchStatus.COMPLETED, ended
            return out
        if got.iterations <= GROW_ITER:
            ds = min(settings.ds_max, ds * GROW)
        elif got.iterations >= SHRINK_ITER:
            ds = max(settings.ds_min, ds * SHRINK)
        cur = got
    out.status = BranchStatus.MAX_POINTS
    out.message = f"stopped after {settings.max_points} points at {where(cur.z)}"
    return out


def start(residual: Residual, z0: np.ndarray, direction: np.ndarray,
          settings: ArclengthSettings) -> CurvePoint | CurveFailure:
    """Converge the first point from ``z0`` (corrected along ``direction``, i.e. with
    ``direction . (z - z0) = 0``) and give it the tangent oriented along ``direction``."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    got = correct(residual, np.asarray(z0, dtype=float), d, settings)
    if isinstance(got, CurvePoint):
        got.tangent = tangent(got.jac, d)
    return got
