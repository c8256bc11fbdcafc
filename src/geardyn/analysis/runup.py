"""Run-ups and run-downs: the forcing frequency ramped through a range, the phase its integral.

:func:`runup` integrates one model while its forcing frequency Omega moves linearly in time
from ``start`` to ``stop`` (a run-down when ``stop < start``). The forcing phase is the
integral of Omega, not ``Omega t`` (a non-stationary speed), and every coefficient that follows
Omega (its own entry; a carrier speed tied to it) follows it at every RK4 stage, on a compiled
path (:mod:`geardyn.solvers._runup_template`). The result is a labelled dataset (kind
``"runup"``) over ``time`` with the instantaneous ``Omega``, the ``phase``, the physical axes
(mesh frequency [Hz], input speed [rpm]) where the model has them, and the chosen outputs.

One call is one lane (one speed range, one model): a labelled-data generator calls it per
(speed range, torque, seed) lane. :func:`steady_record` is the same kernel at a constant speed
(zero acceleration), recording at a sample rate: the labelled fault data's integration.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.frc import physical_axes
from geardyn.core.model import Model
from geardyn.core.plan import default_steps_at
from geardyn.core.results import finish
from geardyn.core.settings import DEFAULT_BOUND, check_omega
from geardyn.core.status import Status, status_meaning
from geardyn.errors import ParameterError
from geardyn.solvers.kernels import kernels_for

__all__ = ["MIN_RUNUP_STEPS", "PROGRESS_PIECES", "RunupSettings", "SteadyRecord",
           "frequency_scale", "natural_frequencies", "phase_from_time", "runup",
           "speed_coefficients", "steady_record"]

#: Fewest RK4 steps per forcing period at the highest speed (the split path rotates the phase
#: by angle addition, exact in its small-angle form up to 2 pi / 8 per step).
MIN_RUNUP_STEPS = 8
#: Calls of the kernel a run-up with a progress callback is cut into.
PROGRESS_PIECES = 50
#: The integrator, as the datasets record it.
INTEGRATOR = "RK4, fixed step; forcing phase = integral of the ramped Omega"
#: Relative residual within which a coefficient counts as a quadratic in Omega.
QUADRATIC_RTOL = 1e-9


def _finite(field: str, value: Any, minimum: float | None = None, strict: bool = False,
            optional: bool = False) -> float | None:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not math.isfinite(value):
        raise ParameterError(field, value, "must be a finite number")
    if minimum is not None and (value <= minimum if strict else value < minimum):
        raise ParameterError(field, value, f"must be {'>' if strict else '>='} {minimum:g}")
    return float(value)


@dataclass(frozen=True)
class RunupSettings:
    """How a run-up is driven and recorded; validated where it is built (a bad value raises a
    :class:`~geardyn.errors.ParameterError` naming the field).

    ``start``, ``stop``: forcing frequency Omega at the ramp's ends (the model's units: Omega
    for the dimensionless models, rad/s for the SI spur pair); ``rate`` [Omega per time unit,
    > 0, the magnitude] or ``duration`` [time units, > 0]: exactly one; ``transient``: time held
    at ``start`` before the ramp, not recorded (>= 0); ``sample_rate``: samples per time unit
    (None: every RK4 step); ``outputs``: state and observable names recorded (None: all);
    ``steps_per_period``: RK4 steps per forcing period at the highest speed (None: the model's
    step rule there, :func:`~geardyn.core.plan.default_steps_per_period`; at least
    :data:`MIN_RUNUP_STEPS`); the step is then refined so that it divides the sample interval;
    ``locate_edges``, ``bound`` as in :class:`~geardyn.RunSettings`.
    """

    start: float
    stop: float
    rate: float | None = None
    duration: float | None = field(default=None, metadata={
        "help": "Ramp time [model time units]"})
    transient: float = field(default=0.0, metadata={
        "help": "Time held at the start speed first, not recorded"})
    sample_rate: float | None = field(default=None, metadata={
        "help": "Samples per model time unit"})
    outputs: tuple[str, ...] | None = None
    steps_per_period: int | None = field(default=None, metadata={
        "help": "RK4 steps in one forcing period of the top speed"})
    locate_edges: bool = True
    bound: float = DEFAULT_BOUND

    def __post_init__(self) -> None:
        start = _finite("start", self.start, 0.0)
        stop = _finite("stop", self.stop, 0.0)
        if start == stop:
            raise ParameterError("stop", self.stop, "must differ from start (a ramp)")
        if (self.rate is None) == (self.duration is None):
            raise ParameterError("rate", self.rate, "give exactly one of rate and duration")
        rate = _finite("rate", self.rate, 0.0, strict=True, optional=True)
        duration = _finite("duration", self.duration, 0.0, strict=True, optional=True)
        transient = _finite("transient", self.transient, 0.0)
        fs = _finite("sample_rate", self.sample_rate, 0.0, strict=True, optional=True)
        bound = _finite("bound", self.bound, 0.0, strict=True)
        n = self.steps_per_period
        if n is not None and (isinstance(n, bool) or not isinstance(n, int | np.integer)
                              or n < MIN_RUNUP_STEPS):
            raise ParameterError("steps_per_period", n,
                                 f"must be an integer >= {MIN_RUNUP_STEPS}")
        if not isinstance(self.locate_edges, bool):
            raise ParameterError("locate_edges", self.locate_edges, "must be true or false")
        outputs = self.outputs
        if outputs is not None:
            if isinstance(outputs, str) or not all(isinstance(o, str) for o in outputs) \
                    or not outputs:
                raise ParameterError("outputs", outputs, "must be a non-empty list of names")
            outputs = tuple(outputs)
        for name, value in (("start", start), ("stop", stop), ("rate", rate),
                            ("duration", duration), ("transient", transient),
                            ("sample_rate", fs), ("bound", bound), ("outputs", outputs)):
            object.__setattr__(self, name, value)

    @property
    def ramp_duration(self) -> float:
        """Time of the ramp from start to stop [time units]."""
        return self.duration if self.duration is not None else \
            abs(self.stop - self.start) / self.rate

    @property
    def acceleration(self) -> float:
        """dOmega/dt, signed (negative for a run-down)."""
        return (self.stop - self.start) / self.ramp_duration

    def replace(self, **changes: Any) -> RunupSettings:
        """A copy with fields changed, validated anew (``rate`` replaces ``duration`` and the
        other way round)."""
        if "rate" in changes and "duration" not in changes:
            changes["duration"] = None
        if "duration" in changes and "rate" not in changes:
            changes["rate"] = None
        return replace(self, **changes)


def _refuse(model: Model, why: str) -> ParameterError:
    return ParameterError("model", model.name, f"a run-up cannot drive it: {why}")


def _speeds(top: float) -> np.ndarray:
    """The forcing frequencies up to ``top`` at which a model's dependence on Omega is read."""
    return top * np.array([0.2, 0.45, 0.7, 0.85, 1.0])


def phase_from_time(model: Model, top: float) -> bool:
    """Whether the model reads a forcing at a non-whole order r of Omega from the time (r Omega
    t: a gear train's other stages, a torque fluctuation of non-whole order): the run-up then
    gives its functions the time theta / Omega, so that the phase is r theta, the integral of
    r Omega (:mod:`geardyn.solvers._runup_template`). A :class:`~geardyn.errors.ParameterError`
    naming the model where it also reads a forcing of a fixed frequency from the time (that
    one needs the true time)."""
    w = _speeds(top)
    others = np.asarray(model.other_frequencies(model.lane_params("Omega", w)),
                        dtype=float).reshape(w.size, -1)
    scaled = fixed = False
    for j in range(others.shape[1]):
        f = others[:, j]
        if not np.all(np.isfinite(f)):
            continue
        if np.ptp(f) == 0.0:
            fixed = fixed or f[0] != 0.0
            continue
        r = f / w
        if np.ptp(r) <= 1e-9 * abs(r[0]) and abs(r[0] - round(r[0])) > 1e-9:
            scaled = True
    if scaled and fixed:
        raise _refuse(model, "it has a forcing at a non-whole order of Omega and one of a "
                      "fixed frequency, both read from the time")
    return scaled


def speed_coefficients(model: Model, top: float) -> tuple[np.ndarray, np.ndarray]:
    """The coefficient entries that move with Omega and their quadratics in it: ``cols``
    (indices into ``params``) and ``coef`` (cols x 3: c0 + c1 Omega + c2 Omega^2), found from
    ``model.lane_params("Omega", ...)`` at five speeds up to ``top``. A
    :class:`~geardyn.errors.ParameterError` naming the model where one is not such a
    quadratic, or where the model is autonomous or plain (it reads ``Omega t`` itself)."""
    if model.omega_index is None:
        raise _refuse(model, "it is autonomous (no forcing frequency)")
    if model.kernel.plain:
        raise _refuse(model, "a plain UserModel computes its forcing from Omega t itself; "
                      "write it with (s, c), the sine and cosine of the forcing phase")
    w = _speeds(top)
    P = model.lane_params("Omega", w)
    cols = np.flatnonzero(np.any(P != P[:1], axis=0))
    if model.omega_index not in cols:
        cols = np.sort(np.append(cols, model.omega_index))
    V = np.vander(w, 3, increasing=True)
    coef = np.zeros((cols.size, 3))
    for k, c in enumerate(cols):
        sol = np.linalg.lstsq(V, P[:, c], rcond=None)[0]
        resid = np.max(np.abs(V @ sol - P[:, c]))
        if resid > QUADRATIC_RTOL * max(np.max(np.abs(P[:, c])), 1e-300):
            name = model.param_names[c] if c < len(model.param_names) else f"entry {c}"
            raise _refuse(model, f"its coefficient {name} moves with Omega other than as a "
                          "quadratic")
        coef[k] = sol
    k = int(np.flatnonzero(cols == model.omega_index)[0])
    coef[k] = (0.0, 1.0, 0.0)  # Omega's own entry, exactly
    return cols.astype(np.int64), coef


def natural_frequencies(model: Model) -> np.ndarray | None:
    """The model's linear natural frequencies (mean stiffness, no backlash) in the units of its
    Omega (rad per model time unit), zeros dropped; None where it has none. The planetary
    sets and trains give Hz over the time scale omega_0 (tau = omega_0 t); the others give
    rad per time unit (the unit each declares, ``capabilities.natural_frequencies``); a model
    that knows only its fastest one gives that."""
    unit = model.capabilities.natural_frequencies
    f: np.ndarray | None = None
    if unit:
        try:
            f = np.asarray(model.natural_frequencies(),  # type: ignore[attr-defined]
                           dtype=float).ravel()
        except (ValueError, np.linalg.LinAlgError):
            f = None
        if f is not None and unit == "Hz":  # rad/s; per time unit 1 / omega_0 where scaled
            f = 2.0 * math.pi * f
            if model.dimensionless_time:
                f = f / float(model.time_scale)  # type: ignore[attr-defined]
    if f is None:
        w = np.asarray(model.fastest_natural_frequency(), dtype=float).ravel()
        f = w if w.size and np.all(np.isfinite(w)) else None
    if f is None:
        return None
    f = np.unique(f[np.isfinite(f) & (f > 1e-9 * max(float(np.max(f, initial=0.0)), 1e-300))])
    return f if f.size else None


def frequency_scale(model: Model) -> tuple[float | None, float]:
    """(Hz of one rad per model time unit, or None without physical axes; the mesh order: the
    mesh frequency over the forcing frequency Omega). A model in seconds (the SI spur pair,
    whose Omega is a gear's rotation, its mesh ``cycles`` times faster) gives 1 / (2 pi) and
    its mesh order; a dimensionless one whose Omega is the mesh frequency (CATT device,
    planetary set) the physical mesh frequency per unit Omega and 1."""
    axes = physical_axes(model, np.array([1.0]))
    if not axes or "mesh_frequency" not in axes:
        return None, 1.0
    f_mesh = float(np.asarray(axes["mesh_frequency"][0])[0])  # Hz at Omega = 1
    if model.time_unit == "s":
        return 1.0 / (2.0 * math.pi), f_mesh * 2.0 * math.pi
    return f_mesh, 1.0


def _grid(model: Model, s: RunupSettings) -> tuple[float, int, int, int]:
    """(step h, transient steps, ramp steps, stride) of a run-up: the ramp's steps a whole
    number of sample intervals, so that the last sample is at the ramp's end or just after it
    (at the stop speed)."""
    top = max(s.start, s.stop)
    n = s.steps_per_period or max(int(default_steps_at(model, np.array([top]))[0]),
                                  MIN_RUNUP_STEPS)
    h = 2.0 * math.pi / (top * n)
    stride = 1
    if s.sample_rate is not None:
        dt = 1.0 / s.sample_rate
        stride = max(1, math.ceil(dt / h * (1.0 - 1e-12)))
        h = dt / stride
    n_tr = math.ceil(s.transient / h * (1.0 - 1e-12)) if s.transient > 0 else 0
    n_ramp = stride * math.ceil(s.ramp_duration / (h * stride) * (1.0 - 1e-12))
    return h, n_tr, n_ramp, stride


def _outputs(model: Model, wanted: Sequence[str] | None) -> list[str]:
    names = [*model.state_names, *model.observable_names]
    if wanted is None:
        return names
    unknown = [o for o in wanted if o not in names]
    if unknown:
        raise ParameterError("outputs", unknown[0], f"not a state or observable of "
                             f"{model.name} (known: {', '.join(names)})")
    return list(dict.fromkeys(wanted))


def runup(model: Model, settings: RunupSettings, *, y0: np.ndarray | None = None,
          progress: Callable[[int, int], None] | None = None) -> xr.Dataset:
    """Integrate ``model`` through a run-up (or run-down) of its forcing frequency.

    The forcing frequency is ``settings.start`` for the ``transient`` (not recorded), then moves
    linearly to ``settings.stop`` at ``settings.rate`` (or over ``duration``); the forcing
    phase is its integral. Integrator: classic RK4 with a fixed step ``h = 2 pi / (Omega_max
    n)``, ``n`` = ``steps_per_period`` at the highest speed (default: the model's step rule
    there), refined to divide the sample interval; backlash-edge crossings located inside
    steps (see :mod:`geardyn.solvers._runup_template`). Starts from ``y0`` (default the model's
    initial state) at time 0. ``progress(done, total)`` (steps) is called as the run goes; the
    run is then integrated in :data:`PROGRESS_PIECES` calls of the kernel, each going on with
    the edge sides and graze-screen history of the one before (bitwise the result of one
    call).

    Returns
    -------
    xarray.Dataset (kind ``"runup"``) over ``time`` (from the ramp's start): ``Omega`` (the
    instantaneous forcing frequency), ``phase`` [rad], the coordinates ``mesh_frequency``
    [Hz] and ``input_speed`` [rpm] where the model has physical axes, and one variable per
    output (states, mesh forces); attributes: the settings, ``integrator``, ``step``,
    ``steps_per_period`` (at the highest speed), ``status`` (:class:`~geardyn.Status`: 1 when
    the state left ``bound``; the rows after are NaN), ``unresolved_steps``, the model's
    natural frequencies (``natural_frequencies``, Omega's units) where it has them,
    ``mesh_order`` (the mesh frequency over Omega) and ``hz_per_rad`` (Hz of one rad per time
    unit, :func:`frequency_scale`) where it has physical axes.
    """
    if not isinstance(settings, RunupSettings):
        raise TypeError(f"settings must be a RunupSettings (got {type(settings).__name__})")
    s = settings
    outputs = _outputs(model, s.outputs)
    top = max(s.start, s.stop)
    cols, coef = speed_coefficients(model, top)
    time_phase = phase_from_time(model, top)
    h, n_tr, n_ramp, stride = _grid(model, s)
    y = np.asarray(model.initial_state() if y0 is None else y0, dtype=float).copy()
    if y.shape != (model.n_states,):
        raise ParameterError("y0", y0, f"must have {model.n_states} entries "
                             f"({', '.join(model.state_names)})")
    k = kernels_for(model.kernel, "runup")
    p = np.ascontiguousarray(model.params, dtype=float).copy()
    coef = np.ascontiguousarray(coef)
    t_on = n_tr * h
    t_off = t_on + s.ramp_duration
    total = n_tr + n_ramp
    pieces = 1 if progress is None else max(1, min(PROGRESS_PIECES, total // 1000))
    bounds = np.linspace(0, total, pieces + 1).round().astype(np.int64)
    parts: list[tuple] = []
    ncross = np.zeros(model.n_events, np.int64)
    status, unresolved, done = int(Status.OK), 0, 0
    hist = np.full((2, max(model.n_events, 1)), np.nan)
    side = np.ones(model.n_events, np.int64)
    for c in range(pieces):
        Y, O, W, TH, nc, st, un, dn, y, hist, side = k.runup_trajectory(
            p, np.ascontiguousarray(y), h, int(bounds[c]), int(bounds[c + 1]), n_tr, stride,
            c == pieces - 1, s.start, s.acceleration, t_on, t_off, cols, coef, s.locate_edges,
            s.bound, model.n_events, model.n_observables, c > 0, hist, side, time_phase)
        parts.append((Y, O, W, TH))
        ncross += nc
        unresolved += int(un)
        done += int(dn)
        status = int(st)
        if progress is not None:
            progress(int(bounds[c + 1]) if status == Status.OK else total, total)
        if status != Status.OK:
            break
    Y, O, W, TH = (np.concatenate([q[j] for q in parts]) for j in range(4))
    n_rec = n_ramp // stride + 1
    if W.size < n_rec:  # the run diverged in an earlier piece: the rows after it are NaN
        pad = n_rec - W.size
        Y = np.vstack([Y, np.full((pad, Y.shape[1]), np.nan)])
        O = np.vstack([O, np.full((pad, O.shape[1]), np.nan)])
        W, TH = (np.concatenate([a, np.full(pad, np.nan)]) for a in (W, TH))
    t = (np.arange(n_rec) * stride) * h
    W = np.where(np.isfinite(W), W, np.clip(s.start + s.acceleration * t, min(s.start, s.stop),
                                            top))
    return _dataset(model, s, outputs, t, W, TH, Y, O, h, stride, status, unresolved, done,
                    ncross, top)


def _dataset(model: Model, s: RunupSettings, outputs: list[str], t: np.ndarray,
             W: np.ndarray, TH: np.ndarray, Y: np.ndarray, O: np.ndarray, h: float,
             stride: int, status: int, unresolved: int, done: int, ncross: np.ndarray,
             top: float) -> xr.Dataset:
    ds = xr.Dataset(coords={"time": ("time", t, {"units": model.time_unit, "long_name":
                                                 "time from the ramp's start"})})
    ds["Omega"] = ("time", W, {"units": _omega_units(model), "long_name":
                               "forcing (mesh) frequency, instantaneous"})
    ds["phase"] = ("time", TH, {"units": "rad", "long_name":
                                "forcing phase: the integral of Omega from the start"})
    axes = physical_axes(model, W)
    if axes:
        for name, (values, attrs) in axes.items():
            ds = ds.assign_coords({name: ("time", np.asarray(values, dtype=float), attrs)})
    units = _state_units(model)
    for j, name in enumerate(model.state_names):
        if name in outputs:
            ds[name] = ("time", Y[:, j], {"units": units[j], "long_name": f"state {name}"})
    for j, name in enumerate(model.observable_names):
        if name in outputs:
            ds[name] = ("time", O[:, j], {"units": model.observable_units,
                                          "long_name": f"dynamic mesh force {name}"})
    if model.n_events:
        ds["edge_crossings"] = ("event", np.asarray(ncross), {
            "long_name": "dead-zone edge crossings during the run"})
        ds = ds.assign_coords(event=("event", list(model.event_names)))
    nat = natural_frequencies(model)
    ds.attrs.update(
        model=model.name, start=s.start, stop=s.stop, rate=abs(s.acceleration),
        acceleration=s.acceleration, ramp_duration=s.ramp_duration, transient=s.transient,
        sample_interval=stride * h, outputs=",".join(outputs),
        observables=",".join(o for o in outputs if o in model.observable_names),
        integrator=INTEGRATOR,
        step=h, steps_per_period=int(round(2.0 * math.pi / (top * h))),
        step_rule="fixed step: steps_per_period RK4 steps per forcing period at the highest "
                  "speed, refined to divide the sample interval",
        locate_edges=int(s.locate_edges), bound=s.bound, status=status,
        status_meaning=status_meaning(), unresolved_steps=unresolved, steps_done=done,
        time_unit=model.time_unit, omega_units=_omega_units(model))
    if nat is not None:
        ds.attrs["natural_frequencies"] = nat
    hz, mesh_order = frequency_scale(model)
    ds.attrs["mesh_order"] = mesh_order
    if hz is not None:
        ds.attrs["hz_per_rad"] = hz
    ds.attrs.update(model.dataset_attrs())
    return finish(ds, "runup")


def _omega_units(model: Model) -> str:
    return "rad/s" if model.time_unit == "s" else "1"


def _state_units(model: Model) -> list[str]:
    parts = model.state_units.split(", ")
    return parts if len(parts) == model.n_states else [model.state_units] * model.n_states



@dataclass(frozen=True)
class SteadyRecord:
    """What :func:`steady_record` returns: ``states`` (n, n_states) and ``observables`` (n,
    n_obs) at the sample times ``time`` (n,) [model time from the run's start, the transient
    included: the forcing phase there is Omega time];
    ``status`` (:class:`~geardyn.Status`; rows after a divergence NaN), ``unresolved`` (steps
    that reached the split limit), ``step`` and ``stride`` (steps per sample)."""

    time: np.ndarray
    states: np.ndarray
    observables: np.ndarray
    status: int
    unresolved: int
    step: float
    stride: int


def steady_record(model: Model, samples: int, sample_rate: float, *, transient: float = 0.0,
                  steps_per_period: int | None = None, y0: np.ndarray | None = None,
                  locate_edges: bool = True, bound: float = DEFAULT_BOUND) -> SteadyRecord:
    """Integrate ``model`` at its own constant forcing frequency and record its states and
    observables at the times k / ``sample_rate`` (k < ``samples``, model time units) after a
    ``transient`` (rounded up to whole steps, not recorded), from ``y0`` (default the model's
    initial state) at time 0: the run-up kernel at zero acceleration (forcing phase Omega t).
    The step is 2 pi / (Omega n), n = ``steps_per_period`` (None: the model's step rule),
    shortened to the largest step that divides the sample interval, so every sample is a grid
    point (no interpolation)."""
    om = float(model.omega)
    check_omega(om)
    n = steps_per_period or int(default_steps_at(model, np.array([om]))[0])
    h = 2.0 * math.pi / (om * n)
    dt = 1.0 / sample_rate
    stride = max(1, math.ceil(dt / h * (1.0 - 1e-12)))
    h = dt / stride
    n_tr = math.ceil(transient / h * (1.0 - 1e-12)) if transient > 0 else 0
    y = np.asarray(model.initial_state() if y0 is None else y0, dtype=float).copy()
    k = kernels_for(model.kernel, "runup")
    p = np.ascontiguousarray(model.params, dtype=float).copy()
    cols, coef = np.zeros(0, np.int64), np.zeros((0, 3))
    n_ev = model.n_events
    Y, O, _, _, _, status, unresolved, _, _, _, _ = k.runup_trajectory(
        p, y, h, 0, n_tr + (samples - 1) * stride, n_tr, stride, True, om, 0.0, 0.0, 0.0,
        cols, coef, locate_edges, bound, n_ev, model.n_observables, False,
        np.full((2, max(n_ev, 1)), np.nan), np.ones(n_ev, np.int64), False)  # t = theta/Omega
    t = (n_tr + np.arange(samples) * stride) * h
    return SteadyRecord(t, Y, O, int(status), int(unresolved), h, stride)
