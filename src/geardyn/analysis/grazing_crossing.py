"""Where a grazing curve meets a fold or period-doubling curve: the point located on the other
curve, from the side where the orbit keeps off the edge.

The fold or period-doubling curve C (a ``"curve"`` dataset of :func:`geardyn.curve`) is followed
by its own defining system (:mod:`geardyn.analysis.curve_systems`) towards the zero of the
grazing flank's margin m: the orbit's extremum of the switching function towards the edge, times
+1 for a minimum and -1 for a maximum (positive where the orbit keeps off the edge). On that
side the orbit's period map is smooth, and so are C and m along it; beyond the edge the map has
the grazing's fractional-power terms, and within a band of m about zero (of the order of the
step's fourth power) the monodromy of the fixed-step map is not that of a smooth map: the
central differences of a grid step straddle the edge. So the point is not sought by Newton's
method at m = 0. Instead:

* from C's point before the crossing on the kept side (margin m_a > 0), the crossing's
  arclength s_0 along C's tangent t there is estimated by the secant through C's next point;
* :data:`SAMPLES` points of C are corrected on the hyperplanes t . (z - z_a) = s_j (s the
  arclength coordinate), spaced so that their margins fall from :data:`SAMPLE_MARGINS` x m_a
  to :data:`FLOOR` x (the orbit's range of the switching function), above the band; a sample
  whose margin falls below half that floor moves the estimate back, and the samples are redone
  (at most :data:`TRIES` times);
* the zero s* of the cubic through the samples' (s, m), and x, y at s* on the cubics through
  theirs, give the point; the quadratic through the three samples nearest it gives it again,
  and the location error (``special_error``, in the plane scaled as :func:`intersect_curves`
  scales it) is the larger of the differences in x / x_scale and y / y_scale.

The section point at the crossing is the cubic's too. The error does not hold the
discretisation error of C's fixed step (C's own, e.g. a period-doubling edge off by
O(step^4)).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from geardyn.analysis.arclength import ArclengthSettings, CurvePoint, OutsideDomain, correct
from geardyn.analysis.curve_systems import CurveSystem
from geardyn.analysis.grazing import GrazingProblem

if TYPE_CHECKING:
    from geardyn.core.model import Model

#: The curve kinds whose crossing with a grazing curve is located here.
LOCATED_KINDS = ("fold", "period_doubling")
#: Samples on the kept side, and the lowest margin sampled (a share of the orbit's range of
#: the switching function; far above the band where the fixed-step monodromy is unsmooth:
#: ~5e-5 of it for the gear pair at a branch's default step, docs/envelope.md).
SAMPLES, FLOOR = 4, 1e-3
#: The highest sample margin, a share of the kept end's margin.
SAMPLE_MARGINS = 0.5
#: Most attempts at a sample set.
TRIES = 6
#: The corrector of the samples (on C's defining system; the tolerance of CurveSettings).
SAMPLE_SETTINGS = ArclengthSettings(tol=1e-9, max_iter=15)


@dataclass
class Crossing:
    """A located crossing: ``x``, ``y``, ``error`` (scaled plane), the ``section_point`` on the
    other curve, ``located`` False where it failed (then x, y and error are the polyline's) and
    ``detail`` in words."""

    x: float
    y: float
    error: float
    section_point: np.ndarray
    located: bool
    detail: str


def _system(model: Model, curve: xr.Dataset) -> CurveSystem:
    a = curve.attrs
    return CurveSystem(model, str(a["curve_kind"]), str(a["x"]), str(a["y"]), int(a["period"]),
                       int(a["steps_per_period"]), float(a["x_scale"]), float(a["y_scale"]))


def _grazing(model: Model, grazing: xr.Dataset, sys: CurveSystem) -> GrazingProblem:
    a = grazing.attrs
    names = list(model.event_names)
    if str(a["event"]) not in names:
        raise ValueError(f"grazing: its event {a['event']!r} is not one of {model.name}'s "
                         f"({', '.join(names)})")
    return GrazingProblem(model, sys.x, sys.y, names.index(str(a["event"])), sys.base, 1.0,
                          1.0, sense=1.0 if a["extremum"] == "min" else -1.0)


class _Margin:
    """The margin of C's orbit at z (see the module docstring) and the orbit's range of h."""

    def __init__(self, sys: CurveSystem, gp: GrazingProblem):
        self.sys, self.gp = sys, gp

    def __call__(self, z: np.ndarray) -> tuple[float, float]:
        px, py = self.sys.xy(z)
        pr = self.sys.problem_at(px, py)
        ev = pr.evaluate(self.sys.state(z), jacobian=False, stride=1)
        if not np.all(np.isfinite(ev.states)):
            raise FloatingPointError("the orbit's integration diverged")
        h, _ = self.gp.extremum(pr, ev.states)
        span = float(np.ptp(self.gp.h_along(pr, ev.states[:-1])))
        return self.gp.sense * h, span


def locate_crossing(model: Model, grazing: xr.Dataset, curve: xr.Dataset, segment: int,
                    polyline: tuple[float, float, float], scales: tuple[float, float]
                    ) -> Crossing:
    """The crossing of ``grazing`` with ``curve`` (fold or period doubling, of ``model``) whose
    polyline estimate ``(x, y, error)`` lies on ``curve``'s segment [``segment``,
    ``segment`` + 1]; ``scales`` the plane's (x_scale, y_scale) for the error (module
    docstring). Not located (the polyline's estimate) where the segment's ends are not on
    both sides of the edge (e.g. the curves are of different coexisting orbits) or a sample's
    corrector fails."""
    missing = [k for k in ("steps_per_period", "x_scale", "y_scale") if k not in curve.attrs]
    missing += [k for k in ("event", "extremum", "flank") if k not in grazing.attrs]
    if missing:
        return Crossing(*polyline, np.full(curve.sizes["state"], np.nan), False,
                        f"not located (the curves lack the attrs {', '.join(missing)} of "
                        f"geardyn.curve and grazing_curve results): the polylines' crossing")
    sys = _system(model, curve)
    gp = _grazing(model, grazing, sys)
    margin = _Margin(sys, gp)
    xs, ys = curve[sys.x].values, curve[sys.y].values
    zs = [sys.z_of(curve["section_point"].values[i], xs[i], ys[i])
          for i in (segment, segment + 1)]

    def failed(why: str) -> Crossing:
        return Crossing(*polyline, np.full(sys.n, np.nan), False,
                        f"not located ({why}): the polylines' crossing")

    try:
        (ma, span), (mb, _) = margin(zs[0]), margin(zs[1])
        ends = [segment, segment + 1]
        if ma <= 0 < mb:
            zs, (ma, mb), ends = zs[::-1], (mb, ma), ends[::-1]
        if not (ma > 0 >= mb):
            where = "keeps off" if ma > 0 else "crosses"
            return failed(f"the {sys.kind} curve's orbit {where} the "
                          f"{grazing.attrs['flank']} flank's edge at both ends of the "
                          f"segment (margins {ma:.3g}, {mb:.3g}): the two curves are of "
                          f"different orbits there, or cross within the step")
        floor = FLOOR * span
        step = ends[0] - ends[1]
        i = ends[0]
        while ma <= 2 * floor:  # back along C to a point clear of the sampling floor
            i += step
            if not 0 <= i < xs.size:
                return failed(f"no point of the {sys.kind} curve has a margin above twice "
                              f"the sampling floor {floor:.3g} on the kept side")
            zs[0] = sys.z_of(curve["section_point"].values[i], xs[i], ys[i])
            ma, _ = margin(zs[0])
    except (FloatingPointError, OutsideDomain) as err:
        return failed(str(err))
    za = zs[0]
    try:
        _, J, info = sys.residual(za, True)  # bordered with A's least singular vectors there
    except (FloatingPointError, OutsideDomain) as err:
        return failed(str(err))
    sys.set_border(info)
    t = _unit_tangent(J, zs[1] - za)
    s_b = float(t @ (zs[1] - za))
    s0 = s_b * ma / (ma - mb)  # secant estimate of the crossing
    for _ in range(TRIES):
        slope = ma / s0
        margins = np.linspace(SAMPLE_MARGINS * ma, floor, SAMPLES)
        s_samples = s0 - margins / slope
        rows = []
        for s in s_samples:
            pt = correct(sys.residual, za + s * t, t, SAMPLE_SETTINGS, J)
            if not isinstance(pt, CurvePoint):
                return failed(f"a sample on the {sys.kind} curve: {pt.message}")
            try:
                m, _ = margin(pt.z)
            except (FloatingPointError, OutsideDomain) as err:
                return failed(str(err))
            rows.append((float(t @ (pt.z - za)), m, pt.z))
        ms = np.array([r[1] for r in rows])
        if ms.min() >= 0.5 * floor:
            break
        s0 = _root([r[0] for r in rows if r[1] >= 0.5 * floor] + [0.0],
                   [r[1] for r in rows if r[1] >= 0.5 * floor] + [ma], s0)
    else:
        return failed(f"no {SAMPLES} samples with margins above {0.5 * floor:.3g}")
    s_arr = np.array([r[0] for r in rows])
    Z = np.array([r[2] for r in rows])
    s_star = _root(s_arr, ms, s0)
    z3 = np.array([np.polyval(np.polyfit(s_arr, Z[:, k], SAMPLES - 1), s_star)
                   for k in range(Z.shape[1])])
    near = np.argsort(np.abs(s_arr - s_star))[:3]
    s2 = _root(s_arr[near], ms[near], s_star, degree=2)
    z2 = np.array([np.polyval(np.polyfit(s_arr[near], Z[near, k], 2), s2)
                   for k in range(Z.shape[1])])
    (x3, y3), (x2, y2) = sys.xy(z3), sys.xy(z2)
    err = max(abs(x3 - x2) / scales[0], abs(y3 - y2) / scales[1])
    return Crossing(x3, y3, err, sys.state(z3), True,
                    f"located on the {sys.kind} curve from the side the orbit keeps off the "
                    f"{grazing.attrs['flank']} flank's edge (samples at margins "
                    f"{ms.max():.3g} to {ms.min():.3g}, extrapolated by a cubic)")


def _unit_tangent(J: np.ndarray, towards: np.ndarray) -> np.ndarray:
    t = np.linalg.svd(J)[2][-1]
    return t if t @ towards >= 0 else -t


def _root(s: list[float] | np.ndarray, m: list[float] | np.ndarray, guess: float,
          degree: int | None = None) -> float:
    """The real zero nearest ``guess`` of the polynomial through (s, m) (degree: one less than
    the points, at most 3)."""
    s, m = np.asarray(s, float), np.asarray(m, float)
    deg = min(len(s) - 1, 3) if degree is None else degree
    roots = np.roots(np.polyfit(s, m, deg))
    real = roots[np.abs(roots.imag) <= 1e-9 * (1.0 + np.abs(roots.real))].real
    if real.size == 0:
        return guess
    return float(real[np.argmin(np.abs(real - guess))])


__all__ = ["LOCATED_KINDS", "Crossing", "locate_crossing"]
