"""Checks for geardyn's own tests and for users: does a model keep the model contract, and is a
dataset a well-formed geardyn result?

:func:`assert_result` checks a result dataset against what its kind (``attrs["geardyn_kind"]``,
one of :data:`KINDS`) promises: coordinates, variables and their dimensions, units and meaning
attributes, and status codes among :class:`geardyn.Status`. It raises :class:`AssertionError`
naming everything missing.

:func:`check_model` runs one check per numbered rule of the model contract (the rules are
written out in :class:`geardyn.Model`'s docstring and listed in :data:`RULES`) and raises
:class:`ModelContractError` naming every broken rule::

    import geardyn
    from geardyn.testing import check_model

    report = check_model(my_model)   # raises ModelContractError if a rule is broken
    print(report)

Rules 1-9 call the model's compiled functions directly (no kernel is compiled); rule 10 runs the
compiled RK4 kernel for a short stretch and compares it with the reference integrator
(:func:`geardyn.reference_solution`), so it takes one kernel compilation (tens of seconds the
first time; numba caches it). It runs only when rules 1-9 hold.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geardyn.core import results
from geardyn.core.kernel_source import events_take_phase
from geardyn.core.model import Model
from geardyn.solvers.kernels import TEMPLATES, KernelSource, kernels_for

__all__ = [
    "KINDS",
    "RULES",
    "ModelContractError",
    "ModelReport",
    "Rule",
    "RuleResult",
    "assert_result",
    "check_model",
]


@dataclass(frozen=True)
class Rule:
    """One numbered rule of the model contract."""

    number: int
    name: str
    text: str


#: The model contract, one check per rule (the same numbers and names as in the docstring of
#: :class:`geardyn.Model`).
RULES: tuple[Rule, ...] = (
    Rule(1, "names", "state_names is a non-empty tuple of distinct strings; event_names, "
         "observable_names and param_names are tuples of distinct strings; every mesh names "
         "two events that exist; mesh forces go with their meshes: capabilities.mesh_forces "
         "means one observable per mesh, and static_mesh_forces() is None or one finite force "
         "per mesh of a model that declares its mesh forces"),
    Rule(2, "coefficients", "params is a 1-D float array of finite numbers laid out as "
         "coefficient_layout declares (param_names: its parameters); omega_index is None "
         "(autonomous) or the index of a finite Omega >= 0"),
    Rule(3, "initial state", "initial_state() is a finite float vector of n_states entries"),
    Rule(4, "kernel functions", "kernel is a KernelSource of numba-compiled functions with the "
         "interface's arguments; events is given exactly when event_names is non-empty, "
         "observe exactly when observable_names is; every kernel template builds for it"),
    Rule(5, "outputs filled", "rhs writes every entry of dy (n_states), events every entry of "
         "g (n_events), observe every entry of o (n_observables)"),
    Rule(6, "confined and pure", "each function writes only its output array, leaves y and p "
         "untouched, reads nothing outside y and p, and gives the same output for the same "
         "inputs"),
    Rule(7, "finite", "rhs, events and observe give finite values near the initial state"),
    Rule(8, "kinks on event zeros", "the right-hand side is smooth in t and y wherever no "
         "switching function changes sign: every kink or jump lies on a zero of an event"),
    Rule(9, "copies and lanes", "with_omega and lane_params set Omega and leave the model "
         "alone; fastest_natural_frequency(P) has one positive or NaN value per lane, "
         "other_frequencies(P) one row per lane"),
    Rule(10, "run matches reference", "a short run of the compiled RK4 kernel (default step, "
         "edges located) ends ok and matches the reference integrator (DOP853, rtol 1e-12) in "
         "the states and the observables"),
)
_RULE = {r.number: r for r in RULES}


@dataclass(frozen=True)
class RuleResult:
    """Outcome of one rule's check: ``status`` is "ok", "failed" or "skipped"."""

    rule: Rule
    status: str
    detail: str = ""

    def __str__(self) -> str:
        text = f"rule {self.rule.number} ({self.rule.name}): {self.status}"
        return f"{text}: {self.detail}" if self.detail else text


@dataclass(frozen=True)
class ModelReport:
    """Every rule's outcome for one model."""

    model: str
    results: tuple[RuleResult, ...]

    @property
    def failed(self) -> tuple[RuleResult, ...]:
        """The rules that failed."""
        return tuple(r for r in self.results if r.status == "failed")

    @property
    def ok(self) -> bool:
        """Whether no rule failed (skipped rules do not count)."""
        return not self.failed

    def __str__(self) -> str:
        return "\n".join([f"model contract of {self.model}:", *(f"  {r}" for r in self.results)])


class ModelContractError(AssertionError):
    """A model breaks numbered rules of the model contract (``rules``: their numbers)."""

    def __init__(self, report: ModelReport):
        self.report = report
        self.rules: tuple[int, ...] = tuple(r.rule.number for r in report.failed)
        lines = [f"{report.model} breaks the model contract:"]
        lines += [f"  {r}" for r in report.failed]
        super().__init__("\n".join(lines))


class _Broken(Exception):
    """Raised inside a check: the rule is broken (message: how)."""


# ---------------------------------------------------------------------------------------------
# calling the model's compiled functions with guarded buffers

_GUARD = 8  # guard cells either side of every array handed to a model function
_SENTINELS = (1.0e300 * math.pi, -7.25e299)  # output fill values: never a real output
_IN_GUARDS = (0.0, 1.0e3 * math.e)  # values around y and p: an output must not depend on them


@dataclass
class _Fn:
    """One of the model's functions with its output size and the call that adapts it."""

    label: str
    size: int
    call: Callable[[float, np.ndarray, np.ndarray, np.ndarray], None]


def _functions(model: Model) -> list[_Fn]:
    """rhs, events and observe (those present) as calls ``f(t, y, out, p)`` (the forcing phase
    sin/cos(Omega t) filled in from t)."""
    ks: KernelSource = model.kernel
    om = model.omega
    if ks.one_form is not None:  # the generated array form of the one form (see core.one_form)
        gen = kernels_for(ks)
        ks = KernelSource(gen.rhs, gen.events if ks.events is not None else None,
                          gen.observe if ks.observe is not None else None)

    def with_phase(fn: Any) -> Callable:
        if ks.plain:
            return lambda t, y, out, p: fn(t, y, out, p)
        return lambda t, y, out, p: fn(t, y, out, p, math.sin(om * t), math.cos(om * t))

    out = [_Fn("rhs", model.n_states, with_phase(ks.rhs))]
    if ks.events is not None:
        out.append(_Fn("events", model.n_events, _events_call(ks.events, om)))
    if ks.observe is not None:
        out.append(_Fn("observe", model.n_observables, with_phase(ks.observe)))
    return out


def _events_call(events: Any, om: float) -> Callable:
    """``events`` as a call ``f(t, y, g, p)`` (the forcing phase from t where it takes it)."""
    if not events_take_phase(events):
        return lambda t, y, g, p: events(t, y, g, p)
    return lambda t, y, g, p: events(t, y, g, p, math.sin(om * t), math.cos(om * t))


def _guarded(values: np.ndarray, guard: float) -> tuple[np.ndarray, np.ndarray]:
    """(buffer with guard cells, the view of ``values`` inside it)."""
    buf = np.full(values.size + 2 * _GUARD, guard)
    view = buf[_GUARD : _GUARD + values.size]
    view[:] = values
    return buf, view


@dataclass
class _Call:
    out: np.ndarray  # the output view
    out_buf: np.ndarray
    y_buf: np.ndarray
    p_buf: np.ndarray
    fill: float
    guard: float


def _call(fn: _Fn, t: float, y: np.ndarray, p: np.ndarray, k: int) -> _Call:
    """Call ``fn`` with guarded y, p and output; ``k`` (0 or 1) picks the fill and guard values."""
    y_buf, yv = _guarded(y, _IN_GUARDS[k])
    p_buf, pv = _guarded(p, _IN_GUARDS[k])
    out_buf, ov = _guarded(np.full(fn.size, _SENTINELS[k]), _SENTINELS[1 - k])
    fn.call(float(t), yv, ov, pv)
    return _Call(ov, out_buf, y_buf, p_buf, _SENTINELS[k], _SENTINELS[1 - k])


def _probe_points(model: Model, y0: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """(t, y) points near the initial state for the pointwise rules."""
    rng = np.random.default_rng(12345)
    scale = np.maximum(np.abs(y0), 1e-3 * max(float(np.max(np.abs(y0))), 1.0))
    t1 = 0.37 * (model.period or 1.0)
    pts = [(0.0, y0), (t1, y0)]
    for _ in range(2):
        pts.append((t1 * rng.uniform(), y0 + 1e-2 * scale * rng.standard_normal(y0.size)))
    return pts


# ---------------------------------------------------------------------------------------------
# the checks, one per rule


def _distinct_strings(label: str, names: Any, nonempty: bool = False) -> None:
    if not isinstance(names, tuple) or not all(isinstance(n, str) and n for n in names):
        raise _Broken(f"{label} must be a tuple of non-empty strings (got {names!r})")
    if nonempty and not names:
        raise _Broken(f"{label} is empty")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise _Broken(f"{label} repeats {', '.join(dup)}")


def _check_names(model: Model) -> None:
    _distinct_strings("state_names", model.state_names, nonempty=True)
    for label in ("event_names", "observable_names", "param_names"):
        _distinct_strings(label, getattr(model, label))
    for mesh in model.meshes:
        if len(mesh) != 3 or not all(0 <= j < model.n_events for j in mesh[1:]):
            raise _Broken(f"mesh {mesh!r} does not name two of the {model.n_events} events")
    _check_mesh_forces(model)


def _check_mesh_forces(model: Model) -> None:
    """Mesh forces only with their meshes: a model declaring them (``capabilities.mesh_forces``)
    has one observable per mesh, and ``static_mesh_forces()`` is None or one finite force per
    mesh of a model that declares its mesh forces (else the dynamic factor and the peak/RMS
    forces would silently be left out of every sweep)."""
    meshes = len(model.meshes)
    declared = model.capabilities.mesh_forces
    if declared and not (meshes and model.n_observables == meshes):
        raise _Broken(f"capabilities.mesh_forces: the observables must be the forces of the "
                      f"{meshes} meshes (got {model.n_observables} observables)")
    where = ("declares no meshes" if not meshes else
             f"declares {meshes} meshes but not their forces (capabilities.mesh_forces: no "
             "mesh names its force observable)" if not declared else
             f"declares {meshes} meshes with their forces")
    try:
        static = model.static_mesh_forces()
    except Exception as exc:  # noqa: BLE001 - any failure is the finding
        raise _Broken(f"static_mesh_forces() raised {exc!r}; the model {where}") from exc
    if static is None:
        return
    f = np.asarray(static, dtype=float).ravel()
    if not declared:
        raise _Broken(f"static_mesh_forces() gives {f.size} mesh forces but the model {where}: "
                      "declare each mesh with its force observable, or return None")
    if f.size != meshes or not np.all(np.isfinite(f)):
        raise _Broken(f"static_mesh_forces() gives {f.size} values "
                      f"{np.array2string(f, precision=4)}; expected one finite force per mesh "
                      f"(the model {where})")


def _check_coefficients(model: Model) -> None:
    p = model.params
    if not isinstance(p, np.ndarray) or p.ndim != 1 or p.dtype != np.float64:
        raise _Broken(f"params must be a 1-D float64 array (got {type(p).__name__} "
                      f"{getattr(p, 'dtype', '')} {getattr(p, 'shape', '')})")
    if not np.all(np.isfinite(p)):
        raise _Broken(f"params has non-finite entries at {np.flatnonzero(~np.isfinite(p))}")
    layout = model.coefficient_layout  # declared, or one input per param_names entry
    if layout.size != p.size:
        raise _Broken(f"{len(model.param_names)} param_names (a layout of {layout.size} "
                      f"entries) for {p.size} params")
    if tuple(model.param_names) != layout.names:
        raise _Broken("param_names are not the parameters of the coefficient layout")
    k = model.omega_index
    if k is not None:
        if not isinstance(k, int | np.integer) or not 0 <= k < p.size:
            raise _Broken(f"omega_index {k!r} is not an index of params ({p.size} entries)")
        if not p[k] >= 0.0:
            raise _Broken(f"Omega = params[{k}] = {p[k]!r} must be >= 0")


def _check_initial_state(model: Model, y0: np.ndarray | None) -> np.ndarray:
    y = np.asarray(model.initial_state() if y0 is None else y0)
    if y.shape != (model.n_states,) or not np.issubdtype(y.dtype, np.floating):
        raise _Broken(f"initial_state() has shape {y.shape} and dtype {y.dtype}; expected "
                      f"({model.n_states},) floats (one per state name)")
    if not np.all(np.isfinite(y)):
        raise _Broken("initial_state() is not finite")
    return y.astype(float)


def _arity(fn: Any) -> int:
    return len(inspect.signature(fn.py_func).parameters)


def _check_kernel(model: Model) -> None:
    ks = model.kernel
    if not isinstance(ks, KernelSource):
        raise _Broken(f"kernel must be a KernelSource (got {type(ks).__name__})")
    phase = 4 if ks.plain else (5 if ks.one_form is not None else 6)
    for label, fn, n in (("rhs", ks.rhs, (phase,)),
                         ("events", ks.events, (5,) if ks.one_form is not None else (6, 4)),
                         ("observe", ks.observe, (phase,))):
        if fn is None:
            continue
        if not hasattr(fn, "py_func"):
            raise _Broken(f"{label} is not numba-compiled (decorate it with numba.njit)")
        if _arity(fn) not in n:
            raise _Broken(f"{label} takes {_arity(fn)} arguments; the interface has "
                          f"{' or '.join(map(str, n))}")
    if ks.rhs is None:
        raise _Broken("kernel has no rhs")
    if (ks.events is not None) != (model.n_events > 0):
        raise _Broken(f"events is {'given' if ks.events is not None else 'missing'} but the "
                      f"model has {model.n_events} event_names")
    if (ks.observe is not None) != (model.n_observables > 0):
        raise _Broken(f"observe is {'given' if ks.observe is not None else 'missing'} but the "
                      f"model has {model.n_observables} observable_names")
    for template in TEMPLATES:
        try:
            kernels_for(ks, template)
        except Exception as exc:  # noqa: BLE001 - any failure to build is the finding
            raise _Broken(f"the {template!r} kernel does not build: {exc!r}") from exc


def _pointwise(model: Model, y0: np.ndarray) -> dict[int, list[str]]:
    """Rules 5, 6 and 7 at the probe points: problems found, by rule."""
    found: dict[int, list[str]] = {5: [], 6: [], 7: []}
    p = np.ascontiguousarray(model.params, dtype=float)
    for fn in _functions(model):
        for t, y in _probe_points(model, y0):
            a = _call(fn, t, y, p, 0)
            b = _call(fn, t, y, p, 1)
            again = _call(fn, t, y, p, 0)
            where = f"{fn.label} at t={t:.6g}"
            unset = (a.out == a.fill) & (b.out == b.fill)
            if unset.any():
                found[5].append(f"{where} leaves entries {np.flatnonzero(unset).tolist()} of "
                                f"its {fn.size}-entry output unset")
            for c in (a, b):
                guards = np.concatenate([c.out_buf[:_GUARD], c.out_buf[-_GUARD:]])
                if np.any(guards != c.guard):
                    found[6].append(f"{where} writes outside its {fn.size}-entry output")
                    break
            for c in (a, b):
                if not (np.array_equal(c.y_buf[_GUARD:-_GUARD], y)
                        and np.array_equal(c.p_buf[_GUARD:-_GUARD], p)):
                    found[6].append(f"{where} modifies y or p")
                    break
            written = ~unset
            if not np.array_equal(a.out[written], b.out[written], equal_nan=True):
                found[6].append(f"{where} reads outside y or p (its output depends on what "
                                "lies next to them)")
            if not np.array_equal(a.out, again.out, equal_nan=True):
                found[6].append(f"{where} gives different outputs for the same inputs")
            bad = written & ~np.isfinite(a.out)
            if bad.any():
                found[7].append(f"{where} gives non-finite entries {np.flatnonzero(bad).tolist()}")
    return found


# ---- rule 8: kinks of the right-hand side only where an event changes sign

_SCAN_POINTS = 256
_ZOOM_POINTS = 64
#: A fourth difference above this fraction of the largest first difference nearby is a kink.
KINK_RATIO = 0.05


def _eval_path(model: Model, fns: list[_Fn], t: np.ndarray, Y: np.ndarray,
               p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rhs and side of every event (+1 above zero, -1 else) along the points (t[k], Y[k])."""
    rhs = fns[0]
    ev = next((f for f in fns if f.label == "events"), None)
    F = np.empty((t.size, rhs.size))
    S = np.ones((t.size, max(model.n_events, 0)))
    g = np.empty(model.n_events)
    for k in range(t.size):
        rhs.call(float(t[k]), Y[k], F[k], p)
        if ev is not None:
            ev.call(float(t[k]), Y[k], g, p)
            S[k] = np.where(g > 0.0, 1.0, -1.0)
    return F, S


def _kink_ratio(F: np.ndarray) -> np.ndarray:
    """Per interior point i (2 .. n-3), the largest |fourth difference| over components relative
    to the largest first difference of that component on the path (and rounding)."""
    D4 = F[:-4] - 4 * F[1:-3] + 6 * F[2:-2] - 4 * F[3:-1] + F[4:]
    D1 = np.max(np.abs(np.diff(F, axis=0)), axis=0)
    floor = 64 * np.finfo(float).eps * np.max(np.abs(F), axis=0) + 1e-300
    return np.max(np.abs(D4) / (D1 + floor), axis=1)


def _unexplained_kink(model: Model, fns: list[_Fn], p: np.ndarray, path: Callable,
                      a: float, b: float, n: int, depth: int) -> float | None:
    """Where on the path (parameter in [a, b]) the rhs has a kink with no event sign change
    within its stencil (confirmed on a zoomed scan ``depth`` times), or None."""
    s = np.linspace(a, b, n)
    t, Y = path(s)
    F, S = _eval_path(model, fns, t, Y, p)
    ok = np.all(np.isfinite(F), axis=1)
    ratio = _kink_ratio(F)
    change = np.any(S[1:] != S[:-1], axis=1) if S.shape[1] else np.zeros(n - 1, bool)
    for i in np.argsort(-ratio):
        if ratio[i] <= KINK_RATIO:
            return None
        c = i + 2  # the stencil's centre
        lo, hi = max(c - 3, 0), min(c + 3, n - 1)
        if change[lo:hi].any() or not ok[lo : hi + 1].all():
            continue
        if depth == 0:
            return float(s[c])
        found = _unexplained_kink(model, fns, p, path, s[lo], s[hi], _ZOOM_POINTS, depth - 1)
        if found is not None:
            return found
    return None


def _scan_paths(model: Model, y0: np.ndarray,
                probes: Sequence[np.ndarray]) -> list[tuple[str, Callable]]:
    """Paths through (t, y) space to scan: one forcing period at y0, straight lines from y0 to
    -y0, along each state coordinate, and to every given probe state."""
    T = model.period or 1.0
    t_mid = 0.29 * T
    paths: list[tuple[str, Callable]] = [
        ("t over one period at the initial state",
         lambda s: (s * T, np.broadcast_to(y0, (s.size, y0.size)).copy())),
    ]

    def line(ya: np.ndarray, yb: np.ndarray) -> Callable:
        return lambda s: (np.full(s.size, t_mid), ya + s[:, None] * (yb - ya))

    big = float(np.max(np.abs(y0))) if np.any(y0) else 1.0
    if np.any(y0):
        paths.append(("y from y0 to -y0", line(y0, -y0)))
    for q, name in enumerate(model.state_names):
        r = 2.0 * max(abs(float(y0[q])), 0.5 * big)
        e = np.zeros(y0.size)
        e[q] = r
        paths.append((f"{name} over y0 +- {r:.3g}", line(y0 - e, y0 + e)))
    for k, yp in enumerate(probes):
        paths.append((f"y from y0 to probe {k}", line(y0, np.asarray(yp, dtype=float))))
    return paths


def _check_kinks(model: Model, y0: np.ndarray, probes: Sequence[np.ndarray]) -> None:
    fns = _functions(model)
    p = np.ascontiguousarray(model.params, dtype=float)
    for label, path in _scan_paths(model, y0, probes):
        s = _unexplained_kink(model, fns, p, path, 0.0, 1.0, _SCAN_POINTS, depth=2)
        if s is not None:
            t, Y = path(np.array([s]))
            raise _Broken(f"rhs has a kink (or jump) where no event changes sign: on the path "
                          f"{label}, at t={t[0]:.6g}, y={np.array2string(Y[0], precision=5)}")


# ---- rule 9: copies and lanes


def _check_lanes(model: Model) -> None:
    P = np.tile(model.params, (3, 1))
    w = np.asarray(model.fastest_natural_frequency(P), dtype=float)
    if w.shape != (3,) or not np.all(np.isnan(w) | (w > 0)):
        raise _Broken(f"fastest_natural_frequency of 3 lanes gave {w!r}; expected 3 values, "
                      "each > 0 or NaN")
    f = np.asarray(model.other_frequencies(P))
    if f.ndim != 2 or f.shape[0] != 3:
        raise _Broken(f"other_frequencies of 3 lanes has shape {f.shape}; expected (3, m)")
    if model.omega_index is None:
        return
    before = model.params.copy()
    om = model.omega
    new = om * 1.25 + 0.5
    copy_ = model.with_omega(new)
    if copy_.omega != new or model.omega != om or not np.array_equal(model.params, before):
        raise _Broken(f"with_omega({new}) gave Omega {copy_.omega} and left the model at "
                      f"{model.omega} (expected {new} and {om})")
    vals = np.array([0.5 * om + 0.1, new])
    L = np.asarray(model.lane_params("Omega", vals))
    if L.shape != (2, model.params.size) or not np.array_equal(L[:, model.omega_index], vals):
        raise _Broken(f"lane_params('Omega', {vals.tolist()}) gave shape {L.shape} and Omega "
                      f"column {L[:, model.omega_index] if L.ndim == 2 else L}")
    if not np.array_equal(model.params, before):
        raise _Broken("lane_params changed the model's own params")


# ---- rule 10: a short kernel run against the reference integrator

#: Rule 10 allows ``rtol`` per this many periods of the model's fastest natural mode (at the
#: default step, 100 steps per such period, RK4's relative error grows about 1e-6 per period).
FAST_PERIODS_PER_RTOL = 4.0


def _check_run(model: Model, y0: np.ndarray, periods: int, steps_per_period: int | None,
               rtol: float) -> str:
    from geardyn.core.settings import RunSettings
    from geardyn.core.status import Status
    from geardyn.solvers.reference import reference_solution
    from geardyn.solvers.simulate import simulate

    kw = {} if model.omega_index is not None and model.omega > 0 else {"sample_interval": 1.0}
    run = RunSettings(transient=0.0, samples=periods, steps_per_period=steps_per_period)
    ds = simulate(model, run=run, y0=y0, **kw)
    if ds.attrs["status"] != Status.OK:
        raise _Broken(f"the kernel run did not end ok (status {ds.attrs['status']}: "
                      f"{ds.attrs.get('status_meaning', '')}) in {periods} periods at "
                      f"{ds.attrs['steps_per_period']} steps per period")
    t = ds["time"].values
    idx = np.unique(np.linspace(0, t.size - 1, 4 * periods + 1).round().astype(int))
    Y = np.stack([ds[n].values[idx] for n in model.state_names], axis=1)
    ref = reference_solution(model, y0, t[idx])
    scale = np.max(np.abs(ref), axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    err = np.max(np.abs(Y - ref), axis=0) / scale
    q = int(np.argmax(err))
    # RK4's error at the default step grows with the number of periods of the fastest mode run
    w = float(np.nan_to_num(model.fastest_natural_frequency(model.params[None, :])[0]))
    n_fast = (t[-1] - t[0]) * w / (2.0 * math.pi)
    tol = rtol * max(1.0, n_fast / FAST_PERIODS_PER_RTOL)
    if not err[q] <= tol:
        raise _Broken(f"the kernel run differs from the reference integrator by {err[q]:.3g} "
                      f"(relative, state {model.state_names[q]}) > {tol:.3g} after {periods} "
                      f"periods at {ds.attrs['steps_per_period']} steps per period (is the "
                      "model's fastest_natural_frequency right?)")
    detail = f"state error {err[q]:.2g} at {ds.attrs['steps_per_period']} steps per period"
    if model.n_observables:
        obs = next(f for f in _functions(model) if f.label == "observe")
        p = np.ascontiguousarray(model.params, dtype=float)
        O_ref = np.empty((idx.size, model.n_observables))
        for r, k in enumerate(idx):
            obs.call(float(t[k]), ref[r], O_ref[r], p)
        O = np.stack([ds[n].values[idx] for n in model.observable_names], axis=1)
        oscale = np.max(np.abs(O_ref), axis=0)
        oerr = np.max(np.abs(O - O_ref), axis=0) / np.where(oscale > 0, oscale, 1.0)
        j = int(np.argmax(oerr))
        if not oerr[j] <= tol:
            raise _Broken(f"the kernel run's observable {model.observable_names[j]} differs "
                          f"from observe at the reference states by {oerr[j]:.3g} (relative)")
        detail += f", observable error {oerr[j]:.2g}"
    return detail


# ---------------------------------------------------------------------------------------------


@dataclass
class _Runner:
    results: list[RuleResult] = field(default_factory=list)

    def run(self, number: int, check: Callable[[], Any], needs: Sequence[int] = ()) -> Any:
        rule = _RULE[number]
        blocked = [n for n in needs if not self.passed(n)]
        if blocked:
            self.results.append(RuleResult(rule, "skipped", "needs rules "
                                           + ", ".join(map(str, blocked))))
            return None
        try:
            value = check()
        except _Broken as exc:
            self.results.append(RuleResult(rule, "failed", str(exc)))
            return None
        except Exception as exc:  # noqa: BLE001 - a crash inside a check breaks its rule
            self.results.append(RuleResult(rule, "failed", f"raised {exc!r}"))
            return None
        self.results.append(RuleResult(rule, "ok", value if isinstance(value, str) else ""))
        return value

    def record(self, number: int, problems: list[str]) -> None:
        rule = _RULE[number]
        if problems:
            self.results.append(RuleResult(rule, "failed", "; ".join(dict.fromkeys(problems))))
        else:
            self.results.append(RuleResult(rule, "ok"))

    def passed(self, number: int) -> bool:
        return any(r.rule.number == number and r.status == "ok" for r in self.results)


def check_model(
    model: Model,
    *,
    y0: np.ndarray | None = None,
    probes: Sequence[np.ndarray] = (),
    periods: int = 2,
    steps_per_period: int | None = None,
    rtol: float = 1e-5,
    run: bool = True,
    raise_on_failure: bool = True,
) -> ModelReport:
    """Check ``model`` against every rule of the model contract (:data:`RULES`, the numbered
    rules in :class:`geardyn.Model`'s docstring).

    Parameters
    ----------
    y0
        State the checks start from (default ``model.initial_state()``).
    probes
        Further states: the kink scan (rule 8) also runs along the straight line from y0 to
        each; give states on the far side of every kink of a model whose kinks the default
        paths (y0 to -y0, each coordinate over ``y0 +- 2 abs(y0)``) do not reach.
    periods, steps_per_period, rtol
        Rule 10: forcing periods run (time units for an autonomous model), steps per period
        (default: the model's default step) and the largest difference allowed from the
        reference integrator, per state, relative to the state's largest magnitude (scaled up
        by the number of periods of the model's fastest natural mode in the run over
        :data:`FAST_PERIODS_PER_RTOL`, where that is more than 1).
    run
        Run rule 10 (compiles the model's RK4 kernel the first time); False skips it.
    raise_on_failure
        Raise :class:`ModelContractError` when a rule is broken (default); else only report.

    Returns a :class:`ModelReport` with one :class:`RuleResult` per rule. A rule whose check
    needs earlier rules to hold is "skipped" when they do not.
    """
    r = _Runner()
    r.run(1, lambda: _check_names(model))
    r.run(2, lambda: _check_coefficients(model))
    state = r.run(3, lambda: _check_initial_state(model, y0), needs=(1,))
    r.run(4, lambda: _check_kernel(model), needs=(1,))
    basics = (1, 2, 3, 4)
    if all(r.passed(n) for n in basics):
        try:
            found = _pointwise(model, state)
        except Exception as exc:  # noqa: BLE001
            found = {5: [f"calling the model's functions raised {exc!r}"], 6: [], 7: []}
        for n in (5, 6, 7):
            r.record(n, found[n])
    else:
        for n in (5, 6, 7):
            r.run(n, lambda: None, needs=basics)
    r.run(8, lambda: _check_kinks(model, state, probes), needs=(*basics, 5, 6, 7))
    r.run(9, lambda: _check_lanes(model), needs=(1, 2))
    if run:
        r.run(10, lambda: _check_run(model, state, periods, steps_per_period, rtol),
              needs=tuple(range(1, 10)))
    else:
        r.results.append(RuleResult(_RULE[10], "skipped", "run=False"))
    report = ModelReport(getattr(model, "name", type(model).__name__), tuple(r.results))
    if raise_on_failure and not report.ok:
        raise ModelContractError(report)
    return report


# ------------------------------------------------------------------------------ result datasets
#: The kinds of result dataset, as recorded in ``attrs["geardyn_kind"]`` (the registry
#: :data:`geardyn.core.results.SCHEMAS`): what :func:`geardyn.simulate`,
#: :func:`geardyn.bifurcation`, :func:`geardyn.map2d`, the reproduction (``geardyn reproduce``,
#: one case under one interpretation), :func:`geardyn.periodic_orbit`
#: (``PeriodicOrbit.to_dataset()``), :func:`geardyn.continuation`, :func:`geardyn.basins` and
#: :func:`geardyn.frequency_response` return.
KINDS = results.KINDS


def _continuation_problems(ds: Any) -> list[str]:
    """Unknown bifurcation kinds and branch status codes of a continuation result."""
    from geardyn.analysis.branch_data import BIFURCATION_KINDS, BranchStatus

    problems = []
    if "bifurcation_kind" in ds.variables:
        bad = sorted(set(map(str, ds["bifurcation_kind"].values)) - set(BIFURCATION_KINDS))
        if bad:
            problems.append(f"bifurcation_kind: {bad} are not of {list(BIFURCATION_KINDS)}")
    if "branch_status" in ds.variables:
        codes = np.asarray(ds["branch_status"].values).astype(np.int64)
        bad = np.setdiff1d(codes, [int(s) for s in BranchStatus])
        if bad.size:
            problems.append(f"branch_status: codes {bad.tolist()} are not BranchStatus codes")
    return problems


def assert_result(ds: Any, kind: str) -> None:
    """Assert that ``ds`` is a well-formed geardyn result of ``kind`` (one of :data:`KINDS`).

    Checks, against the kind's schema in :data:`geardyn.core.results.SCHEMAS` (the one the
    builders fill), ``attrs["geardyn_kind"] == kind``; the kind's required attributes,
    coordinates and variables, each with its dimensions; the units or meaning attributes the
    kind promises (``status`` and ``period`` a ``meaning``, times their ``units``); that every
    status code is a :class:`geardyn.Status` code; for a continuation, that every bifurcation
    kind is one of :data:`geardyn.analysis.branch_data.BIFURCATION_KINDS` and every branch
    status a
    :class:`~geardyn.analysis.branch_data.BranchStatus` code. Raises :class:`AssertionError`
    naming every problem found."""
    problems = results.problems(ds, kind)  # the schema of the kind (an unknown kind: named)
    if kind == "continuation":
        problems += _continuation_problems(ds)
    if problems:
        raise AssertionError(f"not a geardyn {kind} result: " + "; ".join(problems))
