"""The rattle-free envelope: the regions of a parameter plane drawn from its curves.

:func:`envelope` finds the grazing curves of a mesh's two flanks in the box
(:func:`geardyn.analysis.grazing.grazing_curve`, started where a scan of the orbit in y at a few
values of x, or in x at a few values of y, sees the flank's extremum change sign:
:func:`find_starts`) and labels the plane:

* the contact regime from the grazing curves: each flank's curves cut the plane into regions,
  and a region's side of them comes from the curves' normals (``kept_x``, ``kept_y``: towards
  the side where the orbit keeps off that flank's edge) at its cells next to a curve, or, for
  a region no curve of the flank bounds, from the orbit at one of its points
  (:func:`kept_regions`). Contact kept (``none``) where the drive flank's edge is kept off,
  else double-sided impacts where the back flank's is crossed, else single-sided impacts;
* coexisting responses inside fold curves, period doubled inside period-doubling curves (the
  ``"curve"`` datasets of ``geardyn.curve`` given as ``curves``, each closed between its ends);
* chaotic (no period <= max_period) where a brute-force map is given (``period == 0``).

The labels are those of the curves' periodic orbit (period k), stable or not: a brute-force map
shows the attractor a start falls on, which may be another one where responses coexist.

:func:`intersect_curves` locates where two curves cross (e.g. a grazing curve and a fold
curve: the codimension-2 point ``grazing-fold``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from geardyn.analysis.arclength import ArclengthSettings, OutsideDomain
from geardyn.analysis.grazing import FLANKS, GrazingProblem, _flank_event, _range, grazing_curve
from geardyn.analysis.grazing_crossing import LOCATED_KINDS, Crossing, locate_crossing
from geardyn.analysis.orbits import (
    ORBIT_STEP_FACTOR,
    OrbitStatus,
    default_guess,
    newton_shooting,
    problem_with_steps,
)
from geardyn.core.plan import default_steps_per_period
from geardyn.core.results import finish
from geardyn.core.settings import RunSettings

if TYPE_CHECKING:
    from geardyn.core.model import Model

__all__ = ["CONTACT_REGIONS", "Envelope", "contact_codes", "envelope", "find_starts",
           "intersect_curves", "kept_regions"]

#: The contact regions' codes (``Envelope.contact``), in order.
CONTACT_REGIONS = ("none", "single", "double")
#: The names a crossing of a grazing curve with another curve kind gets (``special_kind``).
CROSSING_KINDS = {"fold": "grazing-fold", "period_doubling": "grazing-period-doubling",
                  "neimark_sacker": "grazing-neimark-sacker", "grazing": "grazing-grazing"}


# ----------------------------------------------------------------------------- intersections
def _polyline(ds: xr.Dataset, x: str, y: str, sx: float, sy: float) -> np.ndarray:
    for name in (x, y):
        if name not in ds.coords:
            raise ValueError(f"curve: a {ds.attrs.get('curve_kind', '?')} curve in "
                             f"({ds.attrs.get('x')}, {ds.attrs.get('y')}) has no {name!r}")
    return np.column_stack([ds[x].values / sx, ds[y].values / sy])


def _sagitta(P: np.ndarray, i: int) -> float:
    """How far the polyline's segment [i, i + 1] may lie from the smooth curve: a quarter of
    the second difference at its ends (the chord's sagitta for equal steps, 1/8, doubled)."""
    out = 0.0
    for j in (i, i + 1):
        if 1 <= j < len(P) - 1:
            out = max(out, float(np.linalg.norm(P[j - 1] - 2 * P[j] + P[j + 1])) / 4.0)
    return out


def intersect_curves(a: xr.Dataset, b: xr.Dataset, kind: str | None = None, *,
                     model: Model | None = None) -> xr.Dataset:
    """``a`` with the points where it crosses ``b`` (two ``"curve"`` datasets in the same
    plane) appended along ``special``: ``special_kind`` (``kind``, default from the curves'
    kinds, e.g. ``"grazing-fold"``), ``special_x``, ``special_y``, ``special_error``,
    ``special_located``, ``special_detail`` and ``special_section_point`` (NaN where not
    known).

    The crossing is first that of the two polylines (segments' intersection, in the plane
    scaled by ``a``'s ``x_scale`` and ``y_scale``, default the spans of the two curves), its
    error a bound on its distance from the smooth curves' crossing in that scaled plane: the
    sagittas of the two segments (a quarter of the polylines' second differences there) over
    the sine of the angle between them (``special_located`` 0). Given the ``model`` of the
    curves, a grazing curve's crossing with a fold or period-doubling curve is then located on
    that curve from the side where the orbit keeps off the edge
    (:func:`geardyn.analysis.grazing_crossing.locate_crossing`; ``special_located`` 1, its error
    that of the extrapolation; 0 with the polyline's where that fails, ``special_detail`` says
    why)."""
    for name, ds in (("a", a), ("b", b)):
        if ds.attrs.get("geardyn_kind") != "curve":
            raise ValueError(f"{name}: not a curve dataset (geardyn_kind "
                             f"{ds.attrs.get('geardyn_kind')!r})")
    x, y = a.attrs["x"], a.attrs["y"]
    if {b.attrs["x"], b.attrs["y"]} != {x, y}:
        raise ValueError(f"b: its plane ({b.attrs['x']}, {b.attrs['y']}) is not a's ({x}, {y})")
    if kind is None:
        ka, kb = a.attrs["curve_kind"], b.attrs["curve_kind"]
        kind = CROSSING_KINDS.get(kb, f"{ka}-{kb}") if ka == "grazing" else (
            CROSSING_KINDS.get(ka, f"{kb}-{ka}") if kb == "grazing" else f"{ka}-{kb}")
    both = np.concatenate([a[x].values, b[x].values]), np.concatenate([a[y].values, b[y].values])
    sx = float(a.attrs.get("x_scale") or np.ptp(both[0]) or 1.0)
    sy = float(a.attrs.get("y_scale") or np.ptp(both[1]) or 1.0)
    P, Q = _polyline(a, x, y, sx, sy), _polyline(b, x, y, sx, sy)
    found: list[tuple[float, float, float, int, int]] = []
    for i in range(len(P) - 1):
        p, r = P[i], P[i + 1] - P[i]
        for j in range(len(Q) - 1):
            q, s = Q[j], Q[j + 1] - Q[j]
            den = r[0] * s[1] - r[1] * s[0]
            if den == 0.0:
                continue
            d = q - p
            t = (d[0] * s[1] - d[1] * s[0]) / den
            u = (d[0] * r[1] - d[1] * r[0]) / den
            if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
                c = p + t * r
                sine = abs(den) / (np.linalg.norm(r) * np.linalg.norm(s))
                err = (_sagitta(P, i) + _sagitta(Q, j)) / max(sine, 1e-12)
                found.append((float(c[0] * sx), float(c[1] * sy), err, i, j))
    n = a.sizes["state"]
    old = [Crossing(float(u), float(v), float(e), p, bool(ok), str(d))
           for u, v, e, p, ok, d in zip(
               a["special_x"].values, a["special_y"].values, a["special_error"].values,
               _special(a, "special_section_point", np.full((a.sizes["special"], n), np.nan)),
               _special(a, "special_located", np.ones(a.sizes["special"], np.int64)),
               _special(a, "special_detail", np.full(a.sizes["special"], "")), strict=True)]
    new = [_crossing(model, a, b, *f, (sx, sy)) for f in found]
    kinds = [str(k) for k in a["special_kind"].values] + [kind] * len(new)
    out = a.drop_dims("special")
    out = out.assign_coords(special=("special", np.arange(len(kinds))))
    rows = [(k, r.x, r.y, r.error) for k, r in zip(kinds, old + new, strict=True)]
    out["special_kind"] = ("special", np.array([r[0] for r in rows], dtype=str),
                           a["special_kind"].attrs)
    out["special_x"] = ("special", np.array([r[1] for r in rows], float), {
        "long_name": f"{x} at the codimension-2 point"})
    out["special_y"] = ("special", np.array([r[2] for r in rows], float), {
        "long_name": f"{y} at the codimension-2 point"})
    out["special_error"] = ("special", np.array([r[3] for r in rows], float), {
        "long_name": "location error in the plane scaled by x_scale, y_scale (a crossing: "
                     "see geardyn.analysis.envelope.intersect_curves)"})
    out["special_located"] = ("special", np.array([int(r.located) for r in old + new],
                                                   np.int64),
                              {"meaning": "1 located; 0 not located (special_detail says why)"})
    out["special_detail"] = ("special", np.array([r.detail for r in old + new], dtype=str))
    out["special_section_point"] = (("special", "state"), np.array(
        [r.section_point for r in old + new], float).reshape(len(rows), n), {
        "units": a["section_point"].attrs.get("units", ""),
        "long_name": "section point at the codimension-2 point (NaN: not known)"})
    return finish(out, "curve")


def _special(ds: xr.Dataset, name: str, default: np.ndarray) -> np.ndarray:
    return ds[name].values if name in ds else default


def _crossing(model: Model | None, a: xr.Dataset, b: xr.Dataset, x: float, y: float,
              err: float, i: int, j: int, scales: tuple[float, float]) -> Crossing:
    """The polylines' crossing (x, y, err) on a's segment i and b's segment j, located where
    the pair is a grazing curve and a fold or period-doubling curve and ``model`` is given."""
    n = a.sizes["state"]
    ka, kb = a.attrs["curve_kind"], b.attrs["curve_kind"]
    if model is not None and ka == "grazing" and kb in LOCATED_KINDS:
        return locate_crossing(model, a, b, j, (x, y, err), scales)
    if model is not None and kb == "grazing" and ka in LOCATED_KINDS:
        return locate_crossing(model, b, a, i, (x, y, err), scales)
    return Crossing(x, y, err, np.full(n, np.nan), False,
                    "the polylines' crossing (not located: no model, or a pair of curve "
                    "kinds the locator does not take)")


# ----------------------------------------------------------------------------- starts
#: Where the plane is scanned by default: these fractions of each range (x scanned in y, y in
#: x).
SCAN_AT = (0.125, 0.375, 0.625, 0.875)

def _margin(gp: GrazingProblem, pr: Any, x0: np.ndarray) -> float:
    """How far the orbit keeps off the flank's edge (negative: it crosses it), over the
    orbit's range of h: min h where the orbit's mean h is >= 0, else -max h."""
    ev = pr.evaluate(x0, jacobian=False, stride=1)
    if not np.all(np.isfinite(ev.states)):
        return math.nan
    h = gp.h_along(pr, ev.states[:-1])
    span = max(float(np.ptp(h)), 1e-300)
    return (float(np.min(h)) if np.mean(h) >= 0 else -float(np.max(h))) / span


def find_starts(model: Model, x: str, y: str, at: float, y_values: Sequence[float], *,
                mesh: str | None = None, flank: str = "drive", period: int = 1,
                run: RunSettings | None = None
                ) -> list[tuple[float, float, np.ndarray]]:
    """Where the period-k orbit at ``x = at`` starts or stops crossing the ``flank`` edge of
    ``mesh`` as y runs over ``y_values``: (the bracket's two values of y, the mean of the
    orbit's section points there) per sign change of the orbit's margin (:func:`_margin`).
    The orbit is followed from each value to the next (Newton shooting from the last section
    point; from a transient run where that fails)."""
    mesh, event = _flank_event(model, mesh, flank)
    yv = np.asarray(y_values, dtype=float)
    base_model = model.with_params(**{x: float(at), y: float(yv[0])})
    steps = run.steps_per_period if run is not None and run.steps_per_period else (
        ORBIT_STEP_FACTOR * default_steps_per_period(base_model))
    base = problem_with_steps(base_model, None, period, run, steps)
    gp = GrazingProblem(base_model, x, y, event, base, 1.0, 1.0)
    out: list[tuple[float, float, np.ndarray]] = []
    last: tuple[float, float, np.ndarray] | None = None
    guess: np.ndarray | None = None
    for v in yv:
        try:
            pr = gp.problem_at(float(at), float(v))
        except OutsideDomain:
            last = None
            continue
        res = newton_shooting(pr, guess) if guess is not None else None
        if res is None or res.status != OrbitStatus.CONVERGED:
            res = newton_shooting(pr, default_guess(
                pr, transient=None if run is None else run.transient))
        if res.status != OrbitStatus.CONVERGED:
            last, guess = None, None
            continue
        guess = res.x
        m = _margin(gp, pr, res.x)
        if last is not None and np.isfinite(m) and np.sign(m) != np.sign(last[1]):
            out.append((last[0], float(v), 0.5 * (last[2] + res.x)))
        last = (float(v), m, res.x)
    return out


def _passes(ds: xr.Dataset, axis: str, at: float, lo: float, hi: float) -> bool:
    """Whether the curve's polyline crosses the segment ``axis`` = ``at``, the other
    parameter in [lo, hi] (a scan's bracket: the start it gave is on this curve)."""
    other = ds.attrs["y"] if axis == ds.attrs["x"] else ds.attrs["x"]
    ca, cb = ds[axis].values, ds[other].values
    for i in range(ca.size - 1):
        a, b = ca[i] - at, ca[i + 1] - at
        if a * b > 0 or a == b:
            continue
        v = cb[i] + (cb[i + 1] - cb[i]) * (a / (a - b))
        if lo <= v <= hi:
            return True
    return False


def _segment_distance(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Distance of each point of P (n, 2) to the polyline Q (m, 2)."""
    if len(Q) == 1:
        return np.hypot(*(P - Q[0]).T)
    a, b = Q[:-1], Q[1:]
    ab = b - a
    t = np.einsum("pmk,mk->pm", P[:, None, :] - a[None], ab) / np.maximum(
        np.einsum("mk,mk->m", ab, ab), 1e-300)
    c = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.min(np.hypot(*(P[:, None, :] - c).transpose(2, 0, 1)), axis=1)


#: A curve with 90 % of its points within this distance (plane scaled by the box) of a curve
#: already found is that curve again (its ends, past the box, may differ).
SAME_CURVE = 1e-3


def _known(ds: xr.Dataset, found: list[xr.Dataset]) -> bool:
    """Whether ``ds`` retraces a curve of its flank in ``found``."""
    x, y = ds.attrs["x"], ds.attrs["y"]
    sx, sy = float(ds.attrs["x_scale"]), float(ds.attrs["y_scale"])
    P = np.column_stack([ds[x].values / sx, ds[y].values / sy])
    for c in found:
        if c.attrs["flank"] != ds.attrs["flank"] or c.sizes["point"] == 0:
            continue
        Q = np.column_stack([c[x].values / sx, c[y].values / sy])
        if np.quantile(_segment_distance(P, Q), 0.9) < SAME_CURVE:
            return True
    return False


# ----------------------------------------------------------------------------- regions
@dataclass
class Envelope:
    """The curves of a plane and its regions on a grid (``xv`` by ``yv``): ``contact`` codes
    into :data:`CONTACT_REGIONS` (-1 unknown: no grazing curve of the drive flank found),
    ``coexisting``, ``period_doubled`` and ``chaotic`` masks (y, x) (``chaotic`` all False
    without a map), and the map when given."""

    model_name: str
    x: str
    y: str
    x_range: tuple[float, float]
    y_range: tuple[float, float]
    curves: list[xr.Dataset]
    xv: np.ndarray
    yv: np.ndarray
    contact: np.ndarray
    coexisting: np.ndarray
    period_doubled: np.ndarray
    chaotic: np.ndarray
    map: xr.Dataset | None = None
    axes: dict[str, Any] = field(default_factory=dict)

    def grazing(self, flank: str | None = None) -> list[xr.Dataset]:
        """The grazing curves (of ``flank`` only when given)."""
        return [c for c in self.curves if c.attrs["curve_kind"] == "grazing"
                and (flank is None or c.attrs["flank"] == flank)]

    def contact_at(self, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
        """The contact codes at points (X, Y) (any shape): those of the nearest grid point."""
        ix = np.abs(np.asarray(X, float)[..., None] - self.xv).argmin(axis=-1)
        iy = np.abs(np.asarray(Y, float)[..., None] - self.yv).argmin(axis=-1)
        return self.contact[iy, ix]


def _side(curves: list[xr.Dataset], X: np.ndarray, Y: np.ndarray, sx: float, sy: float
          ) -> tuple[np.ndarray, np.ndarray]:
    """(side, distance): +1 on the kept side of the nearest point of the nearest curve, -1
    beyond it, 0 where there is no curve; the distance to that point in the plane scaled by
    (sx, sy)."""
    out = np.zeros(X.shape)
    best = np.full(X.shape, np.inf)
    for c in curves:
        cx, cy = c[c.attrs["x"]].values, c[c.attrs["y"]].values
        nx, ny = c["kept_x"].values, c["kept_y"].values
        ok = np.isfinite(nx) & np.isfinite(ny)
        if not np.any(ok):
            continue
        cx, cy, nx, ny = cx[ok], cy[ok], nx[ok], ny[ok]
        # the normals are in the curve's own scaled plane
        csx, csy = float(c.attrs["x_scale"]), float(c.attrs["y_scale"])
        dx = (X[..., None] - cx) / sx
        dy = (Y[..., None] - cy) / sy
        d = np.hypot(dx, dy)
        k = np.argmin(d, axis=-1)
        dk = np.take_along_axis(d, k[..., None], axis=-1)[..., 0]
        s = np.sign(np.take_along_axis(dx * sx / csx, k[..., None], axis=-1)[..., 0] * nx[k]
                    + np.take_along_axis(dy * sy / csy, k[..., None], axis=-1)[..., 0] * ny[k])
        closer = dk < best
        out[closer] = np.where(s[closer] == 0, 1.0, s[closer])
        best[closer] = dk[closer]
    return out, best


def _barrier(curves: list[xr.Dataset], xv: np.ndarray, yv: np.ndarray) -> np.ndarray:
    """The grid cells (y, x) the curves' polylines pass through (sampled at a quarter cell)."""
    out = np.zeros((yv.size, xv.size), dtype=bool)
    hx, hy = xv[1] - xv[0], yv[1] - yv[0]
    for c in curves:
        px, py = c[c.attrs["x"]].values, c[c.attrs["y"]].values
        for i in range(px.size - 1):
            n = int(np.ceil(4 * max(abs(px[i + 1] - px[i]) / hx,
                                    abs(py[i + 1] - py[i]) / hy))) + 1
            t = np.linspace(0.0, 1.0, n)
            ix = np.rint((px[i] + t * (px[i + 1] - px[i]) - xv[0]) / hx).astype(int)
            iy = np.rint((py[i] + t * (py[i + 1] - py[i]) - yv[0]) / hy).astype(int)
            ok = (ix >= 0) & (ix < xv.size) & (iy >= 0) & (iy < yv.size)
            out[iy[ok], ix[ok]] = True
    return out


#: Cells within this many grid steps of a curve take its side by the normal there.
NEAR_CELLS = 3.0
#: A region takes the curves' side where its cells next to them agree this well (the mean of
#: their +-1 sides); else (curves of different orbits around one region) the probe decides.
AGREE = 0.8

#: ``probe(flank, x, y)``: whether the orbit at (x, y) keeps off the flank's edge (None:
#: unknown), for a region of the plane no curve of the flank bounds.
Probe = Callable[[str, float, float], "bool | None"]


def kept_regions(curves: Sequence[xr.Dataset], xv: np.ndarray, yv: np.ndarray,
                 probe: Probe | None = None) -> dict[str, np.ndarray]:
    """Per flank, +1 where the orbit keeps off the flank's edge, -1 where it crosses it, 0
    unknown, on the grid (y, x) ``yv`` x ``xv``.

    The curves of the flank cut the grid into connected regions (the cells they pass through
    are borders); each region takes the side, by the curves' ``kept`` normals, of its cells
    within :data:`NEAR_CELLS` grid steps of a curve where they agree (:data:`AGREE`), else (no
    curve bounds it, or curves of different orbits disagree about it) ``probe``'s verdict at
    its cell nearest its centre (0: unknown without one); border cells take their own side."""
    from scipy import ndimage

    X, Y = np.meshgrid(xv, yv)
    sx, sy = float(xv[-1] - xv[0]), float(yv[-1] - yv[0])
    near = NEAR_CELLS * max((xv[1] - xv[0]) / sx, (yv[1] - yv[0]) / sy)
    out: dict[str, np.ndarray] = {}
    for flank in FLANKS:
        mine = [c for c in curves if c.attrs["curve_kind"] == "grazing"
                and c.attrs["flank"] == flank and c.sizes["point"] >= 2]
        side, dist = _side(mine, X, Y, sx, sy)
        border = _barrier(mine, xv, yv)
        regions, count = ndimage.label(~border)
        kept = np.zeros(X.shape)
        for r in range(1, count + 1):
            cells = regions == r
            close = cells & (dist <= near)
            agree = abs(float(np.mean(side[close]))) if np.any(close) else 0.0
            if agree >= AGREE:
                kept[cells] = 1.0 if np.sum(side[close]) >= 0 else -1.0
            elif probe is not None:
                iy, ix = np.nonzero(cells)
                j = int(np.argmin((ix - ix.mean()) ** 2 + (iy - iy.mean()) ** 2))
                verdict = probe(flank, float(xv[ix[j]]), float(yv[iy[j]]))
                kept[cells] = 0.0 if verdict is None else (1.0 if verdict else -1.0)
        kept[border] = side[border]
        out[flank] = kept
    return out


def contact_codes(kept: dict[str, np.ndarray]) -> np.ndarray:
    """Contact codes (:data:`CONTACT_REGIONS`; -1 unknown) from :func:`kept_regions`: contact
    kept where the drive flank's edge is kept off, else two-sided impacts where the back
    flank's is crossed, else one-sided impacts."""
    drive, back = kept["drive"], kept["back"]
    out = np.where(back < 0, 2, 1)
    out = np.where(drive > 0, 0, out)
    return np.where(drive == 0, -1, out).astype(np.int64)


def _inside(curves: Sequence[xr.Dataset], kind: str, x: str, X: np.ndarray, Y: np.ndarray
            ) -> np.ndarray:
    """Whether (X, Y) lies inside a ``kind`` curve closed between its ends (a curve with
    the envelope's x as its y is read transposed)."""
    from matplotlib.path import Path

    out = np.zeros(X.shape, dtype=bool)
    pts = np.column_stack([X.ravel(), Y.ravel()])
    for c in curves:
        if c.attrs["curve_kind"] != kind or c.sizes["point"] < 3:
            continue
        xs, ys = c[c.attrs["x"]].values, c[c.attrs["y"]].values
        poly = Path(np.column_stack([xs, ys] if c.attrs["x"] == x else [ys, xs]))
        out |= poly.contains_points(pts).reshape(X.shape)
    return out


def _curve_in(ds: xr.Dataset, x: str, y: str) -> xr.Dataset:
    """A given curve in the envelope's plane (x and y in either order)."""
    if ds.attrs.get("geardyn_kind") != "curve":
        raise ValueError(f"curves: not a curve dataset (geardyn_kind "
                         f"{ds.attrs.get('geardyn_kind')!r})")
    if {ds.attrs["x"], ds.attrs["y"]} != {x, y}:
        raise ValueError(f"curves: a {ds.attrs['curve_kind']} curve in ({ds.attrs['x']}, "
                         f"{ds.attrs['y']}), not in ({x}, {y})")
    return ds


def envelope(model: Model, x: str, y: str, x_range: tuple[float, float],
             y_range: tuple[float, float], *, mesh: str | None = None,
             flanks: Sequence[str] = FLANKS, starts: Sequence[float] | None = None,
             y_starts: Sequence[float] | None = None,
             scan: int = 24, period: int = 1, curves: Sequence[xr.Dataset] = (),
             map: xr.Dataset | None = None, resolution: int = 200,
             run: RunSettings | None = None, settings: ArclengthSettings | None = None,
             progress: Callable[[str, int, float, float], None] | None = None) -> Envelope:
    """The envelope of ``model`` in the plane (``x``, ``y``) over the box ``x_range`` x
    ``y_range`` (see the module docs).

    Parameters
    ----------
    mesh, flanks
        The mesh (default the model's first) and the flanks whose grazing curves are followed.
    starts, y_starts
        The values of x where the orbit is scanned in y for starting points, and of y where
        it is scanned in x (default each at the fractions :data:`SCAN_AT` of its range; a
        curve nearly parallel to one axis is found by the scans along the other).
    scan
        Values per scan, evenly over the other parameter's range.
    period
        k of the orbits.
    curves
        Other curves of the plane (``"curve"`` datasets: fold, period-doubling,
        Neimark-Sacker) to draw and label regions by.
    map
        A :func:`geardyn.map2d` of the same plane (chaotic cells, and drawn beneath).
    resolution
        Grid points per axis of the region labels.
    run, settings
        As for :func:`~geardyn.analysis.grazing.grazing_curve`.
    progress
        ``progress(stage, points, x, y)`` after each curve point (stage: ``"drive curve"``...)
        and each scan (``"scan"``).
    """
    if x == y:
        raise ValueError(f"x and y must be different parameters (both {x!r})")
    xr_, yr_ = _range("x_range", x_range), _range("y_range", y_range)
    for f in flanks:
        _flank_event(model, mesh, f)
    if int(scan) < 2:
        raise ValueError(f"scan: at least 2 values of y (got {scan!r})")
    if int(resolution) < 2:
        raise ValueError(f"resolution: at least 2 grid points per axis (got {resolution!r})")
    given = [_curve_in(c, x, y) for c in curves]
    scans: list[tuple[str, float]] = []
    for name, axis, given_at, box in (("starts", x, starts, xr_), ("y_starts", y, y_starts, yr_)):
        values = given_at if given_at is not None else [box[0] + f * (box[1] - box[0])
                                                        for f in SCAN_AT]
        for v in values:
            if not box[0] <= float(v) <= box[1]:
                raise ValueError(f"{name}: {axis}={v!r} lies outside {box}")
            scans.append((axis, float(v)))
    found: list[xr.Dataset] = []
    for flank in flanks:
        for k, (axis, v) in enumerate(scans):
            other, other_box = (y, yr_) if axis == x else (x, xr_)
            values = np.linspace(other_box[0], other_box[1], int(scan))
            for lo, hi, x0 in find_starts(model, axis, other, v, values, mesh=mesh,
                                          flank=flank, period=period, run=run):
                w = 0.5 * (lo + hi)
                X0, Y0 = (v, w) if axis == x else (w, v)
                if progress is not None:
                    progress("scan", k + 1, X0, Y0)
                if any(c.attrs["flank"] == flank and _passes(c, axis, v, min(lo, hi),
                                                             max(lo, hi)) for c in found):
                    continue

                def step(points: int, X: float, Y: float, flank: str = flank) -> None:
                    if progress is not None:
                        progress(f"{flank} curve", points, X, Y)

                ds = grazing_curve(model, x, y, xr_, yr_, mesh=mesh, flank=flank,
                                   period=period, at=(X0, Y0), hold=axis, guess=x0, run=run,
                                   settings=settings, progress=step)
                if ds.sizes["point"] and not _known(ds, found):
                    found.append(ds)
    for i, g in enumerate(found):
        for c in given:
            if c.attrs["curve_kind"] in CROSSING_KINDS:
                found[i] = g = intersect_curves(g, c, model=model)
    all_curves = found + given
    xv = np.linspace(xr_[0], xr_[1], int(resolution))
    yv = np.linspace(yr_[0], yr_[1], int(resolution))
    X, Y = np.meshgrid(xv, yv)
    contact = contact_codes(kept_regions(all_curves, xv, yv, _prober(
        model, x, y, mesh, period, run)))
    chaotic = np.zeros(X.shape, dtype=bool)
    if map is not None:
        chaotic = _map_chaotic(map, x, y, X, Y)
    axes = _physical(model, x, y)
    return Envelope(model.name, x, y, xr_, yr_, all_curves, xv, yv, contact,
                    _inside(all_curves, "fold", x, X, Y),
                    _inside(all_curves, "period_doubling", x, X, Y), chaotic, map, axes)


def _prober(model: Model, x: str, y: str, mesh: str | None, period: int,
            run: RunSettings | None) -> Probe:
    """A :data:`Probe`: the period-k orbit at (x, y) by Newton shooting from a transient run,
    and whether its margin (:func:`_margin`) from the flank's edge is positive (None where no
    orbit converges)."""
    def probe(flank: str, X: float, Y: float) -> bool | None:
        _, event = _flank_event(model, mesh, flank)
        try:
            at = model.with_params(**{x: X, y: Y})
        except (ValueError, KeyError):
            return None
        steps = run.steps_per_period if run is not None and run.steps_per_period else (
            ORBIT_STEP_FACTOR * default_steps_per_period(at))
        pr = problem_with_steps(at, None, period, run, steps)
        res = newton_shooting(pr, default_guess(pr, transient=None if run is None
                                                else run.transient))
        if res.status != OrbitStatus.CONVERGED:
            return None
        gp = GrazingProblem(at, x, y, event, pr, 1.0, 1.0)
        m = _margin(gp, pr, res.x)
        return None if not np.isfinite(m) else bool(m > 0)

    return probe


def _map_chaotic(mp: xr.Dataset, x: str, y: str, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Cells of the map without a period (``period == 0``), nearest map cell per grid point."""
    if mp.attrs.get("x") != x or mp.attrs.get("y") != y:
        raise ValueError(f"map: a map of ({mp.attrs.get('x')}, {mp.attrs.get('y')}), not of "
                         f"({x}, {y})")
    mx, my = mp[x].values, mp[y].values
    ix = np.abs(X[..., None] - mx).argmin(axis=-1)
    iy = np.abs(Y[..., None] - my).argmin(axis=-1)
    return np.asarray(mp["period"].values)[iy, ix] == 0


def _physical(model: Model, x: str, y: str) -> dict[str, Any]:
    """Linear physical axes of Omega (input speed [rpm], else mesh frequency [Hz]) where the
    model gives them: {"x" or "y": (factor, label)}."""
    from geardyn.analysis.frc import physical_axes

    out: dict[str, Any] = {}
    for key, name in (("x", x), ("y", y)):
        if name != "Omega":
            continue
        axes = physical_axes(model, np.array([1.0]))
        if not axes:
            continue
        pick = "input_speed" if "input_speed" in axes else next(iter(axes))
        values, attrs = axes[pick]
        out[key] = (float(np.asarray(values)[0]),
                    f"{attrs.get('long_name', pick)} [{attrs.get('units', '')}]")
    return out
