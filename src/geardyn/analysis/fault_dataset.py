"""Labelled fault data at scale: sensor signals over speed x torque x fault x noise seed.

Every condition (fault, speed, torque) is one lane of a chunked run
(:func:`~geardyn.execution.executor.run_chunks`): the model built for the fault, at that speed
and torque, integrated at that constant speed by
:func:`~geardyn.analysis.runup.steady_record` (its transient, then the signal's duration), the
sensor signal taken at the sample times k / ``sample_rate`` (grid points: the step divides the
sample interval) and one noisy copy per seed added. Lanes are independent and deterministic, so
the chunks may run here, on local processes (``workers``) or on a Dask cluster, be resumed from
a Zarr store, and give the same bits.

What a model needs for it is declared by its class (``capabilities.fault_dataset``, a
:class:`~geardyn.core.capabilities.FaultDatasetInputs`): the ``with_params`` names of its speed
and torque inputs, their units, its sensor signal and whether it reports its stiffness series'
truncation error. The sensor signals (see ``docs/datasets.md``):

* ``"ring_sensor"`` (a :class:`~geardyn.PlanetaryGearSet` built from geometry): the ring sensor
  signal of :func:`~geardyn.analysis.sensor.sensor_signal` (the ring-planet mesh forces through
  the planet-pass window), in N;
* ``"mesh_force"`` (a :class:`~geardyn.SpurPair`, a :class:`~geardyn.trains.TrainModel`): the
  stand-in is the dynamic force of one of the model's meshes (elastic and damping, its
  observable; ``sensor={"mesh": name}``, default the first), the force that a bearing and the
  housing carry to a sensor.

Measurement noise is white Gaussian with standard deviation sigma = rms / 10^(snr_db / 20), rms
the clean signal's RMS about its mean, drawn from ``numpy.random.default_rng([seed, fault,
speed, torque])`` (indices into the spec's lists): the same seed gives the same bits.
"""

from __future__ import annotations

import copy
import functools
import hashlib
import math
import multiprocessing
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.runup import SteadyRecord, steady_record
from geardyn.core.capabilities import FaultDatasetInputs
from geardyn.core.model import Model
from geardyn.core.plan import MIN_STEPS_PER_PERIOD, default_steps_per_period
from geardyn.core.results import finish
from geardyn.core.settings import RunSettings
from geardyn.core.status import Status, status_attrs
from geardyn.errors import ParameterError
from geardyn.execution.executor import run_chunks
from geardyn.gears.faults import FAULT_KINDS

__all__ = ["FaultDatasetSpec", "clean_signal", "dataset_inputs", "default_workers",
           "fault_dataset", "fault_labels", "lane_noise", "lane_steps", "seconds_per_time_unit"]


def _whole_list(name: str, values: Sequence[Any]) -> tuple[int, ...]:
    out = tuple(values)
    if not out:
        raise ParameterError(name, values, "needs at least one value")
    for v in out:
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
            raise ParameterError(name, v, "must be whole numbers >= 0")
    if len(set(out)) != len(out):
        raise ParameterError(name, values, "must not repeat a value")
    return tuple(int(v) for v in out)


def _real_list(name: str, values: Sequence[Any]) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ParameterError(name, values, "must be a list of numbers") from None
    if not out:
        raise ParameterError(name, values, "needs at least one value")
    if not all(math.isfinite(v) for v in out):
        raise ParameterError(name, values, "must be finite numbers")
    if len(set(out)) != len(out):
        raise ParameterError(name, values, "must not repeat a value")
    return out


def _positive(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be a number") from None
    if not (math.isfinite(v) and v > 0.0):
        raise ParameterError(name, value, "must be a finite number > 0")
    return v


@dataclass(frozen=True)
class FaultDatasetSpec:
    """What a fault dataset holds.

    ``build(faults)`` returns the model for a tuple of faults (``()``: healthy), e.g.
    ``lambda f: geardyn.SpurPair.from_geometry(mesh, bore_radius=..., speed=0, torque=0,
    faults=f)``; ``faults`` lists the conditions, each ``None`` (healthy) or a fault object of
    :mod:`geardyn.gears.faults`; ``speeds`` in the model's declared speed input
    (``capabilities.fault_dataset``: SpurPair ``speed`` in its ``speed_unit``, a planetary
    set's or a train's ``input_speed`` in rpm); ``torques`` [N m] in its declared torque input
    (SpurPair ``torque``, a planetary set's ``sun_torque``, a train's ``input_torque``);
    ``seeds`` the noise seeds; ``snr_db`` the
    signal-to-noise ratio [dB] (``inf``: no noise); ``duration`` [s] and ``sample_rate`` [Hz] of
    each signal; ``transient`` [s] discarded first (rounded up to whole forcing periods);
    ``steps_per_period`` RK4 steps per forcing period, or ``steps_per_mode`` steps per period
    of the fastest natural mode (the model's ``fastest_natural_frequency``), at most one (both
    None: the step rule, 100 per mode); the step is then shortened to divide the sample
    interval; ``chunk`` conditions per chunk (None: the executor's default); ``sensor`` the
    settings of the model's sensor signal (:data:`~geardyn.core.capabilities.DATASET_SIGNALS`:
    a mesh force's ``mesh``, a ring sensor's ``sensor_angle``, ``width``, ``window``)."""

    build: Callable[[tuple[Any, ...]], Model]
    faults: Sequence[Any]
    speeds: Sequence[float]
    torques: Sequence[float]
    seeds: Sequence[int] = (0,)
    snr_db: float = 20.0
    duration: float = 1.0
    sample_rate: float = 10_000.0
    transient: float = 0.0
    steps_per_period: int | None = None
    steps_per_mode: float | None = None
    chunk: int | None = None
    sensor: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not callable(self.build):
            raise ParameterError("build", self.build, "must be a function faults -> model")
        object.__setattr__(self, "faults", tuple(self.faults))
        if not self.faults:
            raise ParameterError("faults", self.faults, "needs at least one condition "
                                 "(None for healthy)")
        kinds = tuple(FAULT_KINDS.values())
        for f in self.faults:
            if f is not None and not isinstance(f, kinds):
                raise ParameterError("faults", f, "must be None (healthy) or a fault of "
                                     f"geardyn.gears ({', '.join(k.__name__ for k in kinds)})")
        object.__setattr__(self, "speeds", _real_list("speeds", self.speeds))
        object.__setattr__(self, "torques", _real_list("torques", self.torques))
        object.__setattr__(self, "seeds", _whole_list("seeds", self.seeds))
        snr = float(self.snr_db)
        if math.isnan(snr) or snr == -math.inf:
            raise ParameterError("snr_db", self.snr_db, "must be a number or inf (no noise)")
        object.__setattr__(self, "snr_db", snr)
        object.__setattr__(self, "duration", _positive("duration", self.duration))
        object.__setattr__(self, "sample_rate", _positive("sample_rate", self.sample_rate))
        tr = float(self.transient)
        if not (math.isfinite(tr) and tr >= 0.0):
            raise ParameterError("transient", self.transient, "must be a time >= 0 [s]")
        object.__setattr__(self, "transient", tr)
        if self.chunk is not None and (isinstance(self.chunk, bool) or int(self.chunk) < 1):
            raise ParameterError("chunk", self.chunk, "must be a whole number >= 1")
        RunSettings(steps_per_period=self.steps_per_period)  # names the field when bad
        if self.steps_per_mode is not None:
            if self.steps_per_period is not None:
                raise ParameterError("steps_per_mode", self.steps_per_mode,
                                     "give steps_per_period or steps_per_mode, not both")
            n = _positive("steps_per_mode", self.steps_per_mode)
            if n < 8.0:
                raise ParameterError("steps_per_mode", self.steps_per_mode,
                                     "must be >= 8 (RK4 is unstable near 2.8 / (omega h))")
            object.__setattr__(self, "steps_per_mode", n)

    @property
    def n_samples(self) -> int:
        """Samples per signal: round(duration x sample_rate)."""
        return max(1, round(self.duration * self.sample_rate))

    def settings(self) -> dict[str, Any]:
        """Every setting but the model builder, JSON-able (the dataset's attributes)."""
        return {"faults": [_describe(f) for f in self.faults], "speeds": list(self.speeds),
                "torques": list(self.torques), "seeds": list(self.seeds),
                "snr_db": self.snr_db, "duration": self.duration,
                "sample_rate": self.sample_rate, "transient": self.transient,
                "steps_per_period": self.steps_per_period,
                "steps_per_mode": self.steps_per_mode, "sensor": dict(self.sensor)}


def _describe(fault: Any) -> str:
    return "healthy" if fault is None else fault.describe()


def fault_labels(fault: Any) -> dict[str, Any]:
    """kind, size [m] (the fault's declared ``size``: crack depth, spall length, wear depth;
    NaN for healthy or a broken tooth), gear and tooth (-1 for healthy) of one fault
    condition."""
    if fault is None:
        return {"kind": "healthy", "size": math.nan, "gear": "none", "tooth": -1}
    return {"kind": str(fault.kind), "size": float(fault.size), "gear": str(fault.gear),
            "tooth": int(fault.tooth)}


def _declared(model: Model) -> FaultDatasetInputs:
    """The model class's declaration; a ParameterError naming ``build`` where it has none."""
    decl = model.capabilities.fault_dataset
    if decl is None:
        raise ParameterError("build", type(model).__name__,
                             "returns a model that does not declare the fault_dataset "
                             "capability (its class's Capabilities(fault_dataset="
                             "FaultDatasetInputs(...))): missing its speed input, its torque "
                             "input and its sensor signal")
    return decl


def dataset_inputs(model: Model, sensor: dict[str, Any] | None = None) -> FaultDatasetInputs:
    """The fault-dataset inputs ``model``'s class declares
    (:class:`~geardyn.core.capabilities.FaultDatasetInputs`), checked against this model and
    the sensor settings ``sensor``: a model that lacks the declaration, or a declared input or
    the sensor signal, is a :class:`~geardyn.errors.ParameterError` naming ``build`` and
    listing what is missing; a bad sensor setting one naming ``sensor.<setting>``."""
    decl = _declared(model)
    name = type(model).__name__
    takes = set(model.physical_names) | set(model.param_names)
    missing = [f"its {what} input {input_name!r} (not an input of this {name})"
               for what, input_name in (("speed", decl.speed), ("torque", decl.torque))
               if input_name not in takes]
    if decl.speed_unit is None and not isinstance(getattr(model, "speed_unit", None), str):
        missing.append("the unit of its speed input (declared as the model's speed_unit)")
    why = _signal_missing(model, decl)
    if why:
        missing.append(f"its {decl.signal} signal ({why})")
    if missing:
        raise ParameterError("build", name, "returns a model that lacks what a fault dataset "
                             f"needs: {'; '.join(missing)}")
    settings = dict(sensor or {})
    unknown = sorted(set(settings) - set(decl.sensor_settings))
    if unknown:
        takes_text = ", ".join(decl.sensor_settings) or "none"
        raise ParameterError(f"sensor.{unknown[0]}", settings[unknown[0]],
                             f"not a setting of {name}'s {decl.signal} signal (it takes "
                             f"{takes_text})")
    try:
        clean_signal(_probe_record(model), model, settings)
    except ParameterError as exc:
        field = exc.field if exc.field.startswith("sensor") else f"sensor.{exc.field}"
        raise ParameterError(field, exc.value, exc.reason) from None
    return decl


def _signal_missing(model: Model, decl: FaultDatasetInputs) -> str:
    """Why ``model`` cannot give its declared signal ("" where it can)."""
    if decl.signal == "ring_sensor":
        from geardyn.analysis.sensor import carrier_angle

        try:
            carrier_angle(model, np.zeros(1), 0.0)
        except ParameterError as exc:
            return exc.reason
        return ""
    if not model.meshes:
        return "the model has no meshes"
    return ""


def _probe_record(model: Model) -> SteadyRecord:
    """A one-sample record of zeros: the signal's settings are checked on it before any
    work."""
    return SteadyRecord(time=np.zeros(1), states=np.zeros((1, model.n_states)),
                        observables=np.zeros((1, len(model.observable_names))),
                        status=0, unresolved=0, step=1.0, stride=1)


def speed_unit(model: Model) -> str:
    """The unit of the model's declared speed input (a model declaring None: its own
    ``speed_unit``)."""
    decl = _declared(model)
    return str(model.speed_unit) if decl.speed_unit is None else decl.speed_unit


def seconds_per_time_unit(model: Model) -> float:
    """Seconds per unit of the model's time: 1 for a model in seconds, 1 / omega_0 for a
    planetary set's dimensionless time tau = omega_0 t."""
    if model.time_unit == "s":
        return 1.0
    return 1.0 / float(model.time_scale)


def lane_steps(model: Model, spec: FaultDatasetSpec) -> int:
    """RK4 steps per forcing period of one condition before the shortening to the sample
    interval: ``spec.steps_per_period``, else ``spec.steps_per_mode`` per period of the
    model's fastest natural mode (at least ``MIN_STEPS_PER_PERIOD``), else the step rule."""
    if spec.steps_per_period is not None:
        return int(spec.steps_per_period)
    if spec.steps_per_mode is None:
        return default_steps_per_period(model)
    w = float(np.asarray(model.fastest_natural_frequency(), dtype=float).ravel()[0])
    return max(MIN_STEPS_PER_PERIOD, math.ceil(spec.steps_per_mode * w / float(model.omega)))


def clean_signal(rec: SteadyRecord, model: Model, sensor: dict[str, Any] | None = None
                 ) -> np.ndarray:
    """The sensor signal of the steady record ``rec`` of ``model`` at its sample times, the
    signal its class declares (``capabilities.fault_dataset.signal``): ``"ring_sensor"``, the
    planetary ring sensor (``sensor``: :func:`~geardyn.analysis.sensor.sensor_signal`'s
    sensor_angle, width, window); ``"mesh_force"``, the force observable of the mesh
    ``sensor["mesh"]`` (default the first)."""
    decl = _declared(model)
    settings = dict(sensor or {})
    names = list(model.observable_names)
    if decl.signal == "mesh_force":
        meshes = [m[0] for m in model.meshes]
        mesh = settings.get("mesh", meshes[0] if meshes else None)
        if mesh not in meshes:
            raise ParameterError("sensor.mesh", mesh, f"must be a mesh of the model "
                                 f"({', '.join(meshes)})")
        return np.array(rec.observables[:, meshes.index(mesh)], dtype=float)
    from geardyn.analysis.sensor import carrier_angle, sensor_signal

    forces = np.stack([rec.observables[:, names.index(f"F_r{n + 1}")]
                       for n in range(model.n_planets)], axis=-1)
    phi = carrier_angle(model, rec.time, float(model.omega))
    return sensor_signal(forces, phi, np.asarray(model.psi, dtype=float), **settings)


def _signal_meaning(model: Model, sensor: dict[str, Any]) -> str:
    decl = _declared(model)
    if decl.signal == "ring_sensor":
        return "ring sensor signal sum_n w(phi + psi_n - theta_s) F_rn"
    meshes = [m[0] for m in model.meshes]
    index = meshes.index(sensor.get("mesh", meshes[0]))
    return f"dynamic mesh force {model.observable_names[index]}"


def lane_noise(clean: np.ndarray, snr_db: float, seed: int, key: Sequence[int]
               ) -> tuple[np.ndarray, float]:
    """(noise, sigma): white Gaussian noise of sigma = rms / 10^(snr_db / 20) (rms of ``clean``
    about its mean), from ``default_rng([seed, *key])``; zeros for ``snr_db = inf``."""
    if snr_db == math.inf:
        return np.zeros_like(clean), 0.0
    rms = float(np.sqrt(np.mean((clean - clean.mean()) ** 2)))
    sigma = rms / 10.0 ** (snr_db / 20.0)
    rng = np.random.default_rng([int(seed), *(int(k) for k in key)])
    return sigma * rng.standard_normal(clean.shape), sigma


def _dataset_task(model: Model, head: np.ndarray, y0: np.ndarray, steps: np.ndarray,
                  unit: np.ndarray, key: np.ndarray, *, spec: dict[str, Any]
                  ) -> dict[str, np.ndarray]:
    """The lane task: per condition, its coefficient vector (the fault's ``bases`` row with the
    columns ``cols`` from ``head``), the steady record (seconds per model time unit ``unit``:
    a planetary set's time scale is its own), the sensor signal, each seed's noise."""
    n, seeds = int(spec["n_samples"]), spec["seeds"]
    bases, cols = spec["bases"], spec["cols"]
    out_signal = np.zeros((head.shape[0], len(seeds), n))
    status = np.zeros(head.shape[0], dtype=np.int8)
    unresolved = np.zeros(head.shape[0], dtype=np.int64)
    sigma = np.zeros(head.shape[0])
    for i in range(head.shape[0]):
        m = copy.copy(model)
        p = np.array(bases[int(key[i, 0])], dtype=float)
        p[cols] = head[i]
        m.params = p
        rec = steady_record(m, n, spec["sample_rate"] * unit[i],
                            transient=spec["transient"] / unit[i],
                            steps_per_period=int(steps[i]), y0=y0[i])
        status[i], unresolved[i] = rec.status, rec.unresolved
        if status[i] != Status.OK:
            out_signal[i] = np.nan
            sigma[i] = np.nan
            continue
        clean = clean_signal(rec, m, spec["sensor"])
        for j, seed in enumerate(seeds):
            noise, sigma[i] = lane_noise(clean, spec["snr_db"], seed, key[i])
            out_signal[i, j] = clean + noise
    return {"signal": out_signal, "status": status, "unresolved": unresolved, "sigma": sigma}


@dataclass
class _Conditions:
    """Every condition of a spec, compact: ``bases`` (fault, coefficient) each fault's
    vector; per condition (fault, speed, torque; C order) the columns ``cols`` that speed and
    torque set (``head``), its initial state ``y0``, steps per period ``steps``, seconds per
    model time unit ``unit`` and indices ``key``; per fault the stiffness truncation errors
    ``errors`` (where the model has them)."""

    model: Model
    bases: np.ndarray
    cols: np.ndarray
    head: np.ndarray
    y0: np.ndarray
    steps: np.ndarray
    unit: np.ndarray
    key: np.ndarray
    errors: dict[str, list[float]]


def _conditions(spec: FaultDatasetSpec) -> _Conditions:
    """The conditions of ``spec`` (:class:`_Conditions`). A fault the model refuses raises
    here, before any work."""
    bases, changes, y0, steps, unit, key = [], [], [], [], [], []
    errors: dict[str, list[float]] = {}
    first = None
    for fi, fault in enumerate(spec.faults):
        try:
            base = spec.build(() if fault is None else (fault,))
        except ParameterError as err:
            raise ParameterError(f"faults[{fi}]", _describe(fault), str(err)) from err
        decl = dataset_inputs(base, spec.sensor)
        speed_name, torque_name = decl.speed, decl.torque
        if first is None:
            first = base
        elif type(base) is not type(first) or base.params.size != first.params.size:
            hint = ("; a model with a fault may run over a revolution of the faulty gear: give"
                    " the healthy condition as a zero-size fault on that gear (e.g. a 0 mm "
                    "crack)") if (fault is None) != (spec.faults[0] is None) else ""
            raise ParameterError(f"faults[{fi}]", _describe(fault),
                                 "builds a model of another kind or size than faults[0]: every"
                                 f" condition must share one kernel layout{hint}")
        for name, value in (base.stiffness_error() if decl.stiffness_error else {}).items():
            errors.setdefault(name, []).append(float(value))
        b = np.asarray(base.params, dtype=float)
        bases.append(b)
        for si, speed in enumerate(spec.speeds):
            for ti, torque in enumerate(spec.torques):
                m = base.with_params(**{speed_name: speed, torque_name: torque})
                p = np.asarray(m.params, dtype=float)
                changed = np.flatnonzero(p != b)
                changes.append((changed, p[changed]))
                y0.append(np.asarray(m.initial_state(), dtype=float))
                steps.append(lane_steps(m, spec))
                unit.append(seconds_per_time_unit(m))
                key.append((fi, si, ti))
    assert first is not None
    B = np.array(bases)
    cols = np.unique(np.concatenate([c for c, _ in changes] + [np.zeros(0, np.int64)]))
    K = np.array(key, dtype=np.int64)
    head = B[K[:, 0]][:, cols]
    for i, (c, v) in enumerate(changes):
        head[i, np.searchsorted(cols, c)] = v
    return _Conditions(first, B, cols.astype(np.int64), head, np.array(y0),
                       np.array(steps, dtype=np.int64), np.array(unit), K, errors)


def default_workers() -> int:
    """Processes a local run uses by default: the cores this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def fault_dataset(spec: FaultDatasetSpec, store: Any = None, client: Any = None,
                  progress: Callable[[int, int], None] | None = None,
                  workers: int | None = None) -> xr.Dataset:
    """The labelled dataset of ``spec``: ``signal`` (fault, speed, torque, seed, time) [N], the
    noisy sensor signals; ``status`` and ``unresolved`` (fault, speed, torque) of every
    condition (a diverged condition is kept, its signal NaN); ``noise_std`` [N]; ``steps`` the
    RK4 steps per sample interval. Coordinates the labels (``fault_kind``, ``fault_size``,
    ``fault_gear``, ``fault_tooth``, ``fault_description`` on ``fault``; ``speed``,
    ``torque``, ``seed``, ``time`` [s]), attributes every setting.

    ``store``: a Zarr path; the conditions' results are kept there chunk by chunk as they finish
    (a rerun resumes, computing only the missing chunks) and the dataset is written to it at the
    end (``xarray.open_zarr(store)`` opens it). ``client``: a ``dask.distributed.Client`` (one
    task per chunk) or None (this machine). ``workers``: without a client, the local processes
    (None: :func:`default_workers`, every core; 1: this process only); each integrates one
    condition at a time, so more than one is how a local run uses several cores (the processes
    are spawned: a script calling this needs the ``if __name__ == "__main__":`` guard).
    ``progress(done, total)`` after each chunk. Every way gives the same bits."""
    from geardyn.execution.zarr_store import save_zarr_dataset

    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ParameterError("workers", workers, "must be a whole number >= 1 (or None)")
    c = _conditions(spec)
    settings = spec.settings()
    task_spec = {**{k: settings[k] for k in ("seeds", "snr_db", "sample_rate", "transient",
                                             "sensor")},
                 "n_samples": spec.n_samples, "bases": c.bases, "cols": c.cols,
                 "bases_sha256": hashlib.sha256(c.bases.tobytes()).hexdigest()}
    task = functools.partial(_dataset_task, spec=task_spec)
    inputs = {"head": c.head, "y0": c.y0, "steps": c.steps, "unit": c.unit, "key": c.key}
    n_workers = min(default_workers() if workers is None else workers, c.key.shape[0])
    meta = {"kind": "fault-dataset", **settings}
    if client is not None or n_workers == 1:
        out = run_chunks(task, c.model, inputs, chunk=spec.chunk, client=client, store=store,
                         progress=progress, meta=meta)
    else:
        from concurrent.futures import ProcessPoolExecutor

        chunk = spec.chunk or _local_chunk(c.key.shape[0], n_workers)
        with ProcessPoolExecutor(n_workers, mp_context=multiprocessing.get_context("spawn")
                                 ) as pool:
            out = run_chunks(task, c.model, inputs, chunk=chunk, client=pool, store=store,
                             progress=progress, meta=meta)
    ds = _assemble(spec, c.model, out, c.errors, c.steps)
    if store is not None:
        save_zarr_dataset(ds, store)
    return ds


def _local_chunk(n_conditions: int, workers: int) -> int:
    """Conditions per chunk on local processes: about 20 chunks per process (the progress
    bar's grain; the last chunks' wait short), at least one condition."""
    return max(1, math.ceil(n_conditions / (20 * workers)))


def _assemble(spec: FaultDatasetSpec, model: Model, out: dict[str, np.ndarray],
              errors: dict[str, list[float]], steps: np.ndarray) -> xr.Dataset:
    nf, ns, nt = len(spec.faults), len(spec.speeds), len(spec.torques)
    shape = (nf, ns, nt)
    labels = [fault_labels(f) for f in spec.faults]
    decl = _declared(model)
    speed_name, torque_name = decl.speed, decl.torque
    dims = ("fault", "speed", "torque")
    ds = xr.Dataset(
        {"signal": ((*dims, "seed", "time"),
                    out["signal"].reshape(*shape, len(spec.seeds), spec.n_samples),
                    {"units": decl.signal_units,
                     "long_name": "sensor signal with measurement noise",
                     "meaning": _signal_meaning(model, spec.sensor)}),
         "status": (dims, out["status"].reshape(shape), status_attrs()),
         "unresolved": (dims, out["unresolved"].reshape(shape),
                        {"meaning": "integration steps that reached the split limit"}),
         "noise_std": (dims, out["sigma"].reshape(shape),
                       {"units": decl.signal_units,
                        "long_name": "measurement noise standard deviation"}),
         "steps_per_period": (dims, steps.reshape(shape), {
             "long_name": "RK4 steps per forcing period asked for (the step is then shortened "
                          "to divide the sample interval)"})},
        coords={
            "fault": ("fault", np.arange(nf)),
            "fault_kind": ("fault", [lb["kind"] for lb in labels]),
            "fault_size": ("fault", [lb["size"] for lb in labels], {"units": "m"}),
            "fault_gear": ("fault", [lb["gear"] for lb in labels]),
            "fault_tooth": ("fault", [lb["tooth"] for lb in labels]),
            "fault_description": ("fault", [_describe(f) for f in spec.faults]),
            "speed": ("speed", np.array(spec.speeds), {"units": speed_unit(model),
                                                       "long_name": speed_name}),
            "torque": ("torque", np.array(spec.torques), {"units": decl.torque_unit,
                                                          "long_name": torque_name}),
            "seed": ("seed", np.array(spec.seeds)),
            "time": ("time", np.arange(spec.n_samples) / spec.sample_rate,
                     {"units": "s", "long_name": "time after the transient"})})
    settings = spec.settings()
    ds.attrs.update(model=model.name, time_unit="s", speed_input=speed_name,
                    speed_unit=speed_unit(model), torque_input=torque_name,
                    torque_unit=decl.torque_unit, signal=decl.signal, snr_db=spec.snr_db,
                    duration=spec.duration,
                    sample_rate=spec.sample_rate, transient=spec.transient,
                    step_choice=("steps_per_period" if spec.steps_per_period is not None
                                 else "steps_per_mode" if spec.steps_per_mode is not None
                                 else "the step rule"),
                    steps_per_mode=("none" if spec.steps_per_mode is None
                                    else spec.steps_per_mode),
                    integrator="RK4, fixed step dividing the sample interval; forcing phase "
                               "Omega t (geardyn.analysis.runup.steady_record)",
                    sensor=str(settings["sensor"]),
                    noise="white Gaussian, sigma = rms about the mean / 10^(snr_db/20), "
                          "default_rng([seed, fault, speed, torque])",
                    sampling="the integration grid's points k / sample_rate (no "
                             "interpolation)",
                    n_conditions=nf * ns * nt, n_signals=nf * ns * nt * len(spec.seeds),
                    diverged=int(np.count_nonzero(out["status"] != Status.OK)))
    for name, values in errors.items():
        ds[f"stiffness_error_{name}"] = ("fault", np.array(values), {
            "units": "1", "long_name": f"stiffness series truncation error ({name}), relative"})
    return finish(ds, "fault-dataset")
