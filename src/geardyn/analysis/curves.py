"""Two-parameter curves of fold, period-doubling and Neimark-Sacker points of periodic orbits.

:func:`curve` starts from a bifurcation located by :func:`geardyn.continuation` and follows it in
the branch's parameter x and a second parameter y by pseudo-arclength continuation
(:mod:`geardyn.analysis.arclength`) of its minimally augmented defining system
(:mod:`geardyn.analysis.curve_systems`), detecting and locating codimension-2 points on the way
(:mod:`geardyn.analysis.codim2`). The result is a ``"curve"`` dataset
(:data:`geardyn.core.results.SCHEMAS`). From a contact change it follows the grazing curve
(:func:`geardyn.analysis.grazing.grazing_curve`, the lower-level function with the box, mesh
and flank as arguments).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn.analysis.arclength import (
    ArclengthSettings,
    CurvePoint,
    CurveRun,
    correct,
    follow,
    start,
    tangent,
)
from geardyn.analysis.branch import BRANCH_STEP_FACTOR
from geardyn.analysis.branch_data import BranchStatus, branch_status_meaning
from geardyn.analysis.codim2 import SPECIAL_KINDS, TESTS, Special, detect_and_locate, special_tests
from geardyn.analysis.curve_systems import CURVE_KINDS, CurveSystem
from geardyn.analysis.grazing import grazing_curve, nearest_flank
from geardyn.analysis.orbits import problem_with_steps
from geardyn.core.model import Model
from geardyn.core.plan import default_steps_per_period
from geardyn.core.results import finish
from geardyn.core.settings import LOCATE_TOL, RunSettings

#: The bifurcation kinds of a continuation result that start a curve, and the curve's kind.
STARTS = {"fold": "fold", "period-doubling": "period_doubling",
          "neimark-sacker": "neimark_sacker"}


@dataclass(frozen=True)
class CurveSettings(ArclengthSettings):
    """:class:`~geardyn.analysis.arclength.ArclengthSettings` (steps in the scaled unknowns
    z = (state / state_scale, x / x_scale, y / y_scale)) with the location tolerance of a
    codimension-2 point (``locate_tol``, in z) and the parameter scales (None: x_scale the
    branch's ``p_scale``, y_scale ``abs(y_stop - y_start)``). The corrector's ``tol`` stays at
    1e-9: the test function, from the monodromy, carries round-off of ~1e-10 (the event
    location), below which its Newton correction cannot go."""

    locate_tol: float = LOCATE_TOL
    x_scale: float | None = None
    y_scale: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if not (math.isfinite(self.locate_tol) and self.locate_tol > 0):
            raise ValueError(f"locate_tol must be a positive number (got {self.locate_tol!r})")
        for name in ("x_scale", "y_scale"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a positive number or None (got {v!r})")


def curve(model: Model, branch: xr.Dataset, bifurcation: int, y: str, y_stop: float, *,
          y_start: float | None = None, x_range: tuple[float, float] | None = None,
          settings: CurveSettings | None = None, run: RunSettings | None = None,
          progress: Callable[[int, float, float], None] | None = None) -> xr.Dataset:
    """Follow the bifurcation number ``bifurcation`` of the continuation result ``branch`` in
    the branch's parameter x and the parameter ``y``.

    Parameters
    ----------
    model
        The model ``branch`` was computed with (its parameters other than x and y stay).
    branch
        A :func:`geardyn.continuation` result.
    bifurcation
        Index along its ``bifurcation`` dimension of a fold, period doubling, Neimark-Sacker or
        contact-change point. A contact change is followed as the grazing curve of the edge its
        orbit grazes (the mesh and flank whose switching function's extremum lies nearest zero
        there, :func:`~geardyn.analysis.grazing.nearest_flank`) by
        :func:`~geardyn.analysis.grazing.grazing_curve` in the box ``x_range`` (default the
        branch's range of x) by [y_start, y_stop], both ways from the start.
    y, y_stop
        The second parameter (any name the model's ``with_params``/``lane_params`` accept) and
        the value the curve heads for; it ends where y leaves [y_start, y_stop].
    y_start
        The value of y at the bifurcation (default: the model's coefficient ``y``).
    x_range
        (lo, hi): the curve also ends where x leaves it (default: no bound).
    settings
        :class:`CurveSettings` (for a contact change: default the grazing curve's
        :data:`~geardyn.analysis.grazing.GRAZING_SETTINGS`; its scales are the box's spans and
        ``locate_tol``, ``x_scale``, ``y_scale`` must be left unset).
    run
        ``run.steps_per_period`` fixes the step (default: the branch's at the bifurcation),
        ``bound`` and ``max_section_periods`` as for the shooting problem.
    progress
        Called as ``progress(points, x, y)`` after each accepted point.

    Returns a ``"curve"`` dataset (see ``docs/continuation.md``): the points along ``point``
    with x and y, the section point, multipliers, orbit period and the test functions
    ``test_<name>`` of the codimension-2 points, which are listed along ``special``; how the
    curve ended in ``status`` (a :class:`~geardyn.BranchStatus` code) and ``message``. A
    failure along the curve is not an exception. For a contact change: the grazing curve's
    dataset (``curve_kind = "grazing"``, see :func:`~geardyn.analysis.grazing.grazing_curve`).
    """
    if branch.attrs.get("model") not in (None, model.name):
        raise ValueError(f"model is a {model.name}, the branch was computed with a "
                         f"{branch.attrs['model']}")
    if _is_contact(branch, bifurcation):
        return _contact_curve(model, branch, int(bifurcation), y, y_stop, y_start, x_range,
                              settings, run, progress)
    kind, x, px, u0, period, steps, x_scale = _bifurcation(branch, bifurcation)
    return _follow(model, kind, x, px, u0, period, steps, x_scale, y, y_stop, y_start,
                   x_range, settings, run, progress)


def curve_at(model: Model, kind: str, x: str, x_value: float, guess: np.ndarray, y: str,
             y_stop: float, *, period: int = 1, y_start: float | None = None,
             x_range: tuple[float, float] | None = None, settings: CurveSettings | None = None,
             run: RunSettings | None = None,
             progress: Callable[[int, float, float], None] | None = None) -> xr.Dataset:
    """:func:`curve` without a continuation result: the ``kind`` (``"fold"``,
    ``"period_doubling"``, ``"neimark_sacker"``) curve of ``model``'s period-``period`` orbits in
    ``x`` and ``y``, its first point converged at y = ``y_start`` from ``x_value`` and the
    section point ``guess`` (both near a bifurcation of that kind, e.g. read from a brute-force
    map). The step is ``run.steps_per_period`` or twice the step rule at ``x_value`` (as a
    branch's); x_scale default ``max(abs(x_value), 1)``. The other arguments are
    :func:`curve`'s."""
    if kind not in CURVE_KINDS:
        raise ValueError(f"kind must be one of {', '.join(CURVE_KINDS)} (got {kind!r})")
    px = float(x_value)
    if not math.isfinite(px):
        raise ValueError(f"x_value must be finite (got {x_value!r})")
    at = model.with_params(**{x: px})  # an unknown x: the model's KeyError naming the known
    u0 = np.asarray(guess, dtype=float)
    if u0.shape != (model.n_states,) or not np.all(np.isfinite(u0)):
        raise ValueError(f"guess must be {model.n_states} finite numbers (got shape "
                         f"{u0.shape})")
    if isinstance(period, bool) or int(period) != period or period < 1:
        raise ValueError(f"period must be a whole number >= 1 (got {period!r})")
    steps = BRANCH_STEP_FACTOR * default_steps_per_period(at)
    return _follow(model, kind, x, px, u0, int(period), steps, max(abs(px), 1.0), y, y_stop,
                   y_start, x_range, settings, run, progress)


def _y_span(model: Model, y: str, y_start: float | None, y_stop: float, where: str
            ) -> tuple[float, float]:
    """(y_start, y_stop) of a curve: y_start default the model's coefficient ``y`` (a KeyError
    asking for it where ``y`` is a physical input), both finite and different."""
    if y_start is None:
        try:
            y_start = float(model.params[model.param_index(y)])
        except KeyError as err:
            raise KeyError(f"y={y!r}: {err.args[0] if err.args else err}; a physical input "
                           f"needs y_start (its value at the {where})") from err
    y0, y1 = float(y_start), float(y_stop)
    if not (math.isfinite(y0) and math.isfinite(y1)) or y0 == y1:
        raise ValueError(f"y_stop must be finite and differ from y_start (got y_start={y0!r}, "
                         f"y_stop={y1!r})")
    return y0, y1


def _follow(model: Model, kind: str, x: str, px: float, u0: np.ndarray, period: int,
            steps: int, x_scale: float, y: str, y_stop: float, y_start: float | None,
            x_range: tuple[float, float] | None, settings: CurveSettings | None,
            run: RunSettings | None, progress: Callable[[int, float, float], None] | None
            ) -> xr.Dataset:
    """The curve from (u0, px) at y_start (see :func:`curve`)."""
    st = settings if settings is not None else CurveSettings()
    if y == x:
        raise ValueError(f"y must differ from x (both {y!r})")
    y0, y1 = _y_span(model, y, y_start, y_stop, "bifurcation")
    model.with_params(**{y: y0})  # an unknown y: the model's KeyError naming the known ones
    if x_range is not None:
        lo, hi = sorted(float(v) for v in x_range)
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi and lo <= px <= hi):
            raise ValueError(f"x_range must be a finite interval around {x}={px:.8g} (got "
                             f"{x_range!r})")
        x_box = (lo, hi)
    else:
        x_box = (-math.inf, math.inf)
    if run is not None and run.steps_per_period:
        steps = int(run.steps_per_period)
    sys = CurveSystem(model, kind, x, y, period, steps,
                      st.x_scale if st.x_scale is not None else x_scale,
                      st.y_scale if st.y_scale is not None else abs(y1 - y0), run)
    y_box = (min(y0, y1), max(y0, y1))
    z0 = sys.z_of(u0, px, y0)
    d = np.zeros(z0.size)
    d[-1] = math.copysign(1.0, y1 - y0)
    first = start(sys.residual, z0, d, st)
    if not isinstance(first, CurvePoint):
        cr = CurveRun([], BranchStatus.START_FAILED,
                      f"{BranchStatus.START_FAILED.message}: no {kind} point at "
                      f"{x}={px:.8g}, {y}={y0:.8g}: {first.message}")
        return curve_dataset(sys, cr, [], [], y0, y1)
    sys.set_border(first.info)

    accepted = [0]

    def on_point(pt: CurvePoint) -> None:
        sys.set_border(pt.info)
        accepted[0] += 1
        if progress is not None:
            progress(accepted[0], *sys.xy(pt.z))

    def stop(_prev: CurvePoint, new: CurvePoint) -> str | None:
        nx, ny = sys.xy(new.z)
        if not y_box[0] <= ny <= y_box[1]:
            return f"left the range of {y} at {y}={ny:.8g}"
        if not x_box[0] <= nx <= x_box[1]:
            return f"left the range of {x} at {x}={nx:.8g}"
        return None

    cr = follow(sys.residual, first, st, where=sys.where, stop=stop, on_point=on_point)
    if cr.status == BranchStatus.COMPLETED and len(cr.points) > 1:
        cr = _onto_bound(sys, cr, st, x_box, y_box)
    tests = [special_tests(sys, p.info, p.z) for p in cr.points]
    specials = detect_and_locate(sys, cr.points, tests, st, st.locate_tol)
    return curve_dataset(sys, cr, tests, specials, y0, y1)


def _bifurcation(branch: xr.Dataset, index: int
                 ) -> tuple[str, str, float, np.ndarray, int, int, float]:
    """(curve kind, x name, x value, section point, period k, steps per period, x scale) of
    the bifurcation ``index`` of a continuation result; a ValueError naming what is wrong."""
    if branch.attrs.get("geardyn_kind") != "continuation":
        raise ValueError(f"branch must be a geardyn.continuation result (got geardyn_kind="
                         f"{branch.attrs.get('geardyn_kind')!r})")
    count = int(branch.sizes.get("bifurcation", 0))
    if isinstance(index, bool) or int(index) != index or not 0 <= int(index) < count:
        raise ValueError(f"bifurcation={index!r} is not an index of the branch's {count} "
                         f"bifurcations")
    i = int(index)
    found = str(branch["bifurcation_kind"].values[i])
    if found not in STARTS:
        raise ValueError(f"bifurcation={i} is a {found!r}: a curve starts from a "
                         f"{', '.join(STARTS)} or contact point")
    x = str(branch.attrs["param"])
    pt = int(branch["bifurcation_point"].values[i])
    return (STARTS[found], x, float(branch["bifurcation_value"].values[i]),
            np.asarray(branch["bifurcation_section_point"].values[i], dtype=float),
            int(branch["bifurcation_period"].values[i]),
            int(branch["steps_per_period"].values[pt]), float(branch.attrs["p_scale"]))


def _is_contact(branch: xr.Dataset, index: int) -> bool:
    """Whether ``index`` names a contact change of a continuation result (any other index:
    :func:`_bifurcation` checks it)."""
    if branch.attrs.get("geardyn_kind") != "continuation" or isinstance(index, bool):
        return False
    kinds = branch["bifurcation_kind"].values if "bifurcation_kind" in branch else []
    return (isinstance(index, int | np.integer) and 0 <= int(index) < len(kinds)
            and str(kinds[int(index)]) == "contact")


def _contact_curve(model: Model, branch: xr.Dataset, index: int, y: str, y_stop: float,
                   y_start: float | None, x_range: tuple[float, float] | None,
                   settings: CurveSettings | None, run: RunSettings | None,
                   progress: Callable[[int, float, float], None] | None) -> xr.Dataset:
    """The grazing curve of the contact change ``index`` (see :func:`curve`)."""
    x = str(branch.attrs["param"])
    if y == x:
        raise ValueError(f"y must differ from x (both {y!r})")
    if settings is not None and (settings.x_scale is not None or settings.y_scale is not None
                                 or settings.locate_tol != LOCATE_TOL):
        raise ValueError("settings: a contact change's grazing curve takes the box's spans as "
                         "its scales and locates no points; leave x_scale, y_scale and "
                         "locate_tol unset")
    y0, y1 = _y_span(model, y, y_start, y_stop, "contact change")
    px = float(branch["bifurcation_value"].values[index])
    if x_range is None:
        values = branch[x].values
        x_range = (float(np.nanmin(values)), float(np.nanmax(values)))
    at = model.with_params(**{x: px, y: y0})
    pt = int(branch["bifurcation_point"].values[index])
    steps = (run.steps_per_period if run is not None and run.steps_per_period
             else int(branch["steps_per_period"].values[pt]))
    problem = problem_with_steps(at, None, int(branch["bifurcation_period"].values[index]),
                                 run, steps)
    mesh, flank = nearest_flank(at, problem,
                                branch["bifurcation_section_point"].values[index])
    return grazing_curve(model, x, y, x_range, (min(y0, y1), max(y0, y1)), mesh=mesh,
                         flank=flank, at=(px, y0), branch=branch, bifurcation=index, run=run,
                         settings=settings, progress=progress)


def _onto_bound(sys: CurveSystem, cr: CurveRun, st: CurveSettings,
                x_box: tuple[float, float], y_box: tuple[float, float]) -> CurveRun:
    """The run with its last point (outside the box) replaced by the curve's point on the
    bound it crossed (the corrector with that parameter fixed); kept, the message saying so,
    where that fails."""
    a, b = cr.points[-2], cr.points[-1]
    (ax, ay), (bx, by) = sys.xy(a.z), sys.xy(b.z)
    if not y_box[0] <= by <= y_box[1]:
        col, bound, va, vb, scale = -1, y_box[0] if by < y_box[0] else y_box[1], ay, by, sys.y_scale
    else:
        col, bound, va, vb, scale = -2, x_box[0] if bx < x_box[0] else x_box[1], ax, bx, sys.x_scale
    w = (bound - va) / (vb - va) if vb != va else 1.0
    z = a.z + w * (b.z - a.z)
    z[col] = bound / scale
    e = np.zeros(z.size)
    e[col] = 1.0
    got = correct(sys.residual, z, e, st, b.jac)
    if not isinstance(got, CurvePoint):
        cr.message += " (last point not corrected onto the bound)"
        return cr
    got.tangent = tangent(got.jac, b.tangent)
    cr.points[-1] = got
    cr.message = f"reached {sys.where(got.z)}"
    return cr


# ----------------------------------------------------------------------------- the dataset
def curve_dataset(sys: CurveSystem, cr: CurveRun, tests: list[dict[str, tuple[float, float]]],
                  specials: list[Special], y_start: float, y_stop: float) -> xr.Dataset:
    """The ``"curve"`` dataset of a followed curve."""
    m, n = sys.model, sys.n
    pts = cr.points
    L = len(pts)
    xs = np.array([sys.xy(p.z)[0] for p in pts], float)
    ys = np.array([sys.xy(p.z)[1] for p in pts], float)
    mu = np.full((L, n), np.nan + 0j)
    for i, p in enumerate(pts):
        mu[i, : p.info.mu.size] = p.info.mu
    arc = np.concatenate([[0.0], np.cumsum([np.linalg.norm(pts[i + 1].z - pts[i].z)
                                            for i in range(L - 1)])]) if L else np.zeros(0)
    ds = xr.Dataset(coords={
        "point": ("point", np.arange(L)),
        sys.x: ("point", xs, {**m.param_attrs(sys.x), "long_name": f"first parameter {sys.x}"}),
        sys.y: ("point", ys, {**m.param_attrs(sys.y), "long_name": f"second parameter {sys.y}"}),
        "state": ("state", list(m.state_names)),
        "multiplier": ("multiplier", np.arange(n)),
        "special": ("special", np.arange(len(specials))),
    })
    ds["section_point"] = (("point", "state"),
                           np.array([sys.state(p.z) for p in pts]).reshape(L, n),
                           {"units": m.state_units,
                            "long_name": "state at the section (forcing phase 0)"})
    ds["multiplier_real"] = (("point", "multiplier"), mu.real, {"units": "1"})
    ds["multiplier_imag"] = (("point", "multiplier"), mu.imag, {"units": "1"})
    ds["period_time"] = ("point", np.array([p.info.problem.duration for p in pts], float), {
        "units": m.time_unit, "long_name": "orbit period k q T"})
    ds["arclength"] = ("point", arc, {"units": "1", "long_name": "arclength in the scaled "
                                      "unknowns (state / state_scale, x / x_scale, y / y_scale)"})
    ds["test_function"] = ("point", np.array([p.info.g for p in pts], float), {
        "long_name": f"bordered test function of the {sys.kind} (zero on the curve)"})
    for name in TESTS[sys.kind]:
        ds[f"test_{name}"] = ("point", np.array([t[name][0] for t in tests], float), {
            "long_name": f"test function of the {name.replace('_', ' ')} point: "
                         f"{SPECIAL_KINDS[name]}"})
        ds[f"test_{name}_error"] = ("point", np.array([t[name][1] for t in tests], float), {
            "long_name": f"error estimate of test_{name} (0: exact up to round-off)"})
    ds["special_kind"] = ("special", np.array([s.kind for s in specials], dtype=str), {
        "meaning": "; ".join(f"{k}: {v}" for k, v in SPECIAL_KINDS.items())})
    ds["special_x"] = ("special", np.array([s.x for s in specials], float),
                       {"long_name": f"{sys.x} of the codimension-2 point"})
    ds["special_y"] = ("special", np.array([s.y for s in specials], float),
                       {"long_name": f"{sys.y} of the codimension-2 point"})
    ds["special_error"] = ("special", np.array([s.error for s in specials], float), {
        "long_name": "bound on the location error in the scaled parameters (x / x_scale, "
                     "y / y_scale) on the discretised system: the distance in the scaled "
                     "unknowns to the bracket's farther end, plus the test function's error "
                     "estimate over its slope (geardyn.analysis.codim2)"})
    ds["special_section_point"] = (("special", "state"), np.array(
        [sys.state(sp.z) for sp in specials]).reshape(len(specials), n), {
        "units": m.state_units, "long_name": "section point at the codimension-2 point"})
    ds["special_point"] = ("special", np.array([s.index for s in specials], np.int64),
                           {"long_name": "index of the curve point before it"})
    ds["special_located"] = ("special", np.array([int(s.located) for s in specials], np.int64),
                             {"meaning": "1 located; 0 not located (special_detail says why)"})
    ds["special_detail"] = ("special", np.array([s.detail for s in specials], dtype=str))
    ds.attrs.update(
        curve_kind=sys.kind, curve_meaning=CURVE_KINDS[sys.kind], x=sys.x, y=sys.y,
        period=sys.period, status=int(cr.status), message=cr.message,
        status_meaning=branch_status_meaning(), time_unit=m.time_unit, model=m.name,
        y_start=y_start, y_stop=y_stop, x_scale=sys.x_scale, y_scale=sys.y_scale,
        steps_per_period=int(sys.base.steps_per_period),
        method="pseudo-arclength continuation of the minimally augmented shooting system "
               "(bordered test function; its derivatives by central differences of the "
               "monodromy)")
    return finish(ds, "curve")
