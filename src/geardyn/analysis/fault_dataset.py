"""Labelled fault data at scale: sensor signals over speed x torque x fault x noise seed.

Every condition (fault, speed, torque) is one lane of a chunked run
(:func:`~geardyn.execution.executor.run_chunks`): the model built for the fault, at that speed
and torque, integrated by :func:`~geardyn.simulate` (its transient, then whole forcing periods
covering ``duration``), its sensor signal taken and sampled at ``sample_rate``, and one noisy
copy per seed added. Lanes are independent and deterministic, so the chunks may run here or on
a Dask cluster, be resumed from a Zarr store, and give the same bits.

The sensor signal (see ``docs/datasets.md``):

* a :class:`~geardyn.PlanetaryGearSet` built from geometry: the ring sensor signal of
  :func:`~geardyn.analysis.sensor.sensor_signal` (the ring-planet mesh forces through the
  planet-pass window), in N;
* a :class:`~geardyn.SpurPair`: the stand-in is the dynamic mesh force F [N] (elastic and
  damping), the force that a bearing and the housing carry to a sensor.

Each signal is taken at the model's grid times (every integration step) and sampled at the
times k / ``sample_rate`` after the transient by linear interpolation. Measurement noise is
white Gaussian with standard deviation sigma = rms / 10^(snr_db / 20), rms the clean signal's
RMS about its mean, drawn from ``numpy.random.default_rng([seed, fault, speed, torque])``
(indices into the spec's lists): the same seed gives the same bits.
"""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from geardyn.core.model import Model
from geardyn.core.results import finish
from geardyn.core.settings import RunSettings
from geardyn.core.status import Status, status_attrs
from geardyn.errors import ParameterError
from geardyn.execution.executor import run_chunks

__all__ = ["FaultDatasetSpec", "clean_signal", "fault_dataset", "fault_labels", "lane_noise",
           "lane_run", "record_periods", "seconds_per_time_unit"]

#: Speed and torque inputs of each model kind (with_params names, units).
_INPUTS = {"SpurPair": ("speed", "torque"), "PlanetaryGearSet": ("input_speed", "sun_torque")}


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
    :mod:`geardyn.gears.faults`; ``speeds`` in the model's speed input (SpurPair ``speed`` in its
    ``speed_unit``, a planetary set's ``input_speed`` in rpm); ``torques`` [N m] (SpurPair
    ``torque``, a planetary set's ``sun_torque``); ``seeds`` the noise seeds; ``snr_db`` the
    signal-to-noise ratio [dB] (``inf``: no noise); ``duration`` [s] and ``sample_rate`` [Hz] of
    each signal; ``transient`` [s] discarded first (rounded up to whole forcing periods);
    ``steps_per_period`` (None: the step rule); ``chunk`` conditions per chunk (None: the
    executor's default)."""

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
    chunk: int | None = None
    sensor: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not callable(self.build):
            raise ParameterError("build", self.build, "must be a function faults -> model")
        object.__setattr__(self, "faults", tuple(self.faults))
        if not self.faults:
            raise ParameterError("faults", self.faults, "needs at least one condition "
                                 "(None for healthy)")
        for f in self.faults:
            if f is not None and not hasattr(f, "kind"):
                raise ParameterError("faults", f, "must be None (healthy) or a fault of "
                                     "geardyn.gears (RootCrack, Spall, Wear, BrokenTooth)")
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
                "steps_per_period": self.steps_per_period, "sensor": dict(self.sensor)}


def _describe(fault: Any) -> str:
    return "healthy" if fault is None else fault.describe()


def fault_labels(fault: Any) -> dict[str, Any]:
    """kind, size [m] (crack depth, spall length, wear depth; NaN for healthy or a broken
    tooth), gear and tooth (-1 for healthy) of one fault condition."""
    if fault is None:
        return {"kind": "healthy", "size": math.nan, "gear": "none", "tooth": -1}
    size = next((float(getattr(fault, a)) for a in ("depth", "length") if hasattr(fault, a)
                 and not (fault.kind == "spall" and a == "depth")), math.nan)
    return {"kind": str(fault.kind), "size": size, "gear": str(fault.gear),
            "tooth": int(fault.tooth)}


def _model_kind(model: Model) -> str:
    for kind in _INPUTS:
        if type(model).__name__ == kind:
            return kind
    raise ParameterError("build", type(model).__name__,
                         f"must return one of {', '.join(_INPUTS)} (models with a sensor "
                         "signal)")


def seconds_per_time_unit(model: Model) -> float:
    """Seconds per unit of the model's time: 1 for a model in seconds, 1 / omega_0 for a
    planetary set's dimensionless time tau = omega_0 t."""
    if model.time_unit == "s":
        return 1.0
    return 1.0 / float(model.time_scale)


def record_periods(duration: float, period: float) -> int:
    """Forcing periods recorded to cover ``duration`` (both in the model's time unit), plus one
    so the last sample time lies inside the record."""
    return int(math.ceil(duration / period)) + 1


def clean_signal(ds: xr.Dataset, model: Model, n_samples: int, sample_rate: float,
                 sensor: dict[str, Any] | None = None) -> np.ndarray:
    """The sensor signal of the :func:`~geardyn.simulate` run ``ds`` of ``model`` at the times
    k / ``sample_rate`` (k < ``n_samples``) after its start [N]: the planetary ring sensor
    (``sensor``: :func:`~geardyn.analysis.sensor.sensor_signal`'s sensor_angle, width,
    window) or the pair's mesh force F, linearly interpolated from the grid."""
    from geardyn.analysis.sensor import carrier_angle, sensor_signal

    t = np.asarray(ds["time"].values, dtype=float)
    if _model_kind(model) == "SpurPair":
        s = np.asarray(ds["F"].values, dtype=float)
    else:
        forces = np.stack([np.asarray(ds[f"F_r{n + 1}"].values, dtype=float)
                           for n in range(model.n_planets)], axis=-1)
        phi = carrier_angle(model, t, float(ds.attrs["Omega"]))
        s = sensor_signal(forces, phi, np.asarray(model.psi, dtype=float), **(sensor or {}))
    seconds = (t - t[0]) * seconds_per_time_unit(model)
    return np.interp(np.arange(n_samples) / sample_rate, seconds, s)


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


def _dataset_task(model: Model, P: np.ndarray, y0: np.ndarray, key: np.ndarray, *,
                  spec: dict[str, Any]) -> dict[str, np.ndarray]:
    """The lane task: per condition, simulate, take the sensor signal, add each seed's noise."""
    from geardyn.solvers.simulate import simulate

    n, seeds = int(spec["n_samples"]), spec["seeds"]
    out_signal = np.zeros((P.shape[0], len(seeds), n))
    status = np.zeros(P.shape[0], dtype=np.int8)
    unresolved = np.zeros(P.shape[0], dtype=np.int64)
    sigma = np.zeros(P.shape[0])
    for i in range(P.shape[0]):
        m = copy.copy(model)
        m.params = np.array(P[i], dtype=float)
        run = lane_run(m, spec["duration"], spec["transient"], spec["steps_per_period"])
        ds = simulate(m, run=run, y0=y0[i])
        status[i], unresolved[i] = int(ds.attrs["status"]), int(ds.attrs["unresolved_steps"])
        if status[i] != Status.OK:
            out_signal[i] = np.nan
            sigma[i] = np.nan
            continue
        clean = clean_signal(ds, m, n, spec["sample_rate"], spec["sensor"])
        for j, seed in enumerate(seeds):
            noise, sigma[i] = lane_noise(clean, spec["snr_db"], seed, key[i])
            out_signal[i, j] = clean + noise
    return {"signal": out_signal, "status": status, "unresolved": unresolved, "sigma": sigma}


def lane_run(model: Model, duration: float, transient: float,
             steps_per_period: int | None) -> RunSettings:
    """The :class:`~geardyn.RunSettings` of one condition: ``transient`` [s] and enough whole
    forcing periods to cover ``duration`` [s] (:func:`record_periods`)."""
    unit = seconds_per_time_unit(model)
    period = 2.0 * math.pi / float(model.omega)
    return RunSettings(transient=transient / unit,
                       samples=record_periods(duration / unit, period),
                       steps_per_period=steps_per_period)


def _conditions(spec: FaultDatasetSpec
                ) -> tuple[Model, np.ndarray, np.ndarray, np.ndarray, dict[str, list[float]]]:
    """The first model, per fault its stiffness series' truncation error (the model's
    ``stiffness_error()``, where it has one) and, per condition (fault, speed, torque; C
    order), its coefficient vector, initial state and indices. A fault the model refuses
    raises here, before any work."""
    P, y0, key = [], [], []
    errors: dict[str, list[float]] = {}
    first = None
    for fi, fault in enumerate(spec.faults):
        try:
            base = spec.build(() if fault is None else (fault,))
        except ParameterError as err:
            raise ParameterError(f"faults[{fi}]", _describe(fault), str(err)) from err
        kind = _model_kind(base)
        speed_name, torque_name = _INPUTS[kind]
        if first is None:
            first = base
        elif type(base) is not type(first) or base.params.size != first.params.size:
            raise ParameterError(f"faults[{fi}]", _describe(fault),
                                 "builds a model of another kind or size than faults[0]: every"
                                 " condition must share one kernel layout")
        err = getattr(base, "stiffness_error", None)
        for name, value in (err() if callable(err) else {}).items():
            errors.setdefault(name, []).append(float(value))
        for si, speed in enumerate(spec.speeds):
            for ti, torque in enumerate(spec.torques):
                m = base.with_params(**{speed_name: speed, torque_name: torque})
                P.append(np.asarray(m.params, dtype=float))
                y0.append(np.asarray(m.initial_state(), dtype=float))
                key.append((fi, si, ti))
    assert first is not None
    return first, np.array(P), np.array(y0), np.array(key, dtype=np.int64), errors


def fault_dataset(spec: FaultDatasetSpec, store: Any = None, client: Any = None,
                  progress: Callable[[int, int], None] | None = None) -> xr.Dataset:
    """The labelled dataset of ``spec``: ``signal`` (fault, speed, torque, seed, time) [N], the
    noisy sensor signals; ``status`` and ``unresolved`` (fault, speed, torque) of every
    condition (a diverged condition is kept, its signal NaN); ``noise_std`` [N]. Coordinates
    the labels (``fault_kind``, ``fault_size``, ``fault_gear``, ``fault_tooth``,
    ``fault_description`` on ``fault``; ``speed``, ``torque``, ``seed``, ``time`` [s]),
    attributes every setting.

    ``store``: a Zarr path; the conditions' results are kept there chunk by chunk as they finish
    (a rerun resumes, computing only the missing chunks) and the dataset is written to it at the
    end (``xarray.open_zarr(store)`` opens it). ``client``: a ``dask.distributed.Client`` (one
    task per chunk) or None (here). ``progress(done, total)`` after each chunk."""
    from geardyn.execution.zarr_store import save_zarr_dataset

    model, P, y0, key, errors = _conditions(spec)
    settings = spec.settings()
    task_spec = {**{k: settings[k] for k in ("seeds", "snr_db", "duration", "sample_rate",
                                             "transient", "steps_per_period", "sensor")},
                 "n_samples": spec.n_samples}
    task = functools.partial(_dataset_task, spec=task_spec)
    out = run_chunks(task, model, {"P": P, "y0": y0, "key": key}, chunk=spec.chunk,
                     client=client, store=store, progress=progress,
                     meta={"kind": "fault-dataset", **settings})
    ds = _assemble(spec, model, out, errors)
    if store is not None:
        save_zarr_dataset(ds, store)
    return ds


def _assemble(spec: FaultDatasetSpec, model: Model, out: dict[str, np.ndarray],
              errors: dict[str, list[float]]) -> xr.Dataset:
    nf, ns, nt = len(spec.faults), len(spec.speeds), len(spec.torques)
    shape = (nf, ns, nt)
    labels = [fault_labels(f) for f in spec.faults]
    kind = _model_kind(model)
    speed_name, torque_name = _INPUTS[kind]
    dims = ("fault", "speed", "torque")
    ds = xr.Dataset(
        {"signal": ((*dims, "seed", "time"),
                    out["signal"].reshape(*shape, len(spec.seeds), spec.n_samples),
                    {"units": "N", "long_name": "sensor signal with measurement noise",
                     "meaning": ("ring sensor signal sum_n w(phi + psi_n - theta_s) F_rn"
                                 if kind != "SpurPair" else "dynamic mesh force F")}),
         "status": (dims, out["status"].reshape(shape), status_attrs()),
         "unresolved": (dims, out["unresolved"].reshape(shape),
                        {"meaning": "integration steps that reached the split limit"}),
         "noise_std": (dims, out["sigma"].reshape(shape),
                       {"units": "N", "long_name": "measurement noise standard deviation"})},
        coords={
            "fault": ("fault", np.arange(nf)),
            "fault_kind": ("fault", [lb["kind"] for lb in labels]),
            "fault_size": ("fault", [lb["size"] for lb in labels], {"units": "m"}),
            "fault_gear": ("fault", [lb["gear"] for lb in labels]),
            "fault_tooth": ("fault", [lb["tooth"] for lb in labels]),
            "fault_description": ("fault", [_describe(f) for f in spec.faults]),
            "speed": ("speed", np.array(spec.speeds), {"long_name": speed_name}),
            "torque": ("torque", np.array(spec.torques), {"units": "N m",
                                                          "long_name": torque_name}),
            "seed": ("seed", np.array(spec.seeds)),
            "time": ("time", np.arange(spec.n_samples) / spec.sample_rate,
                     {"units": "s", "long_name": "time after the transient"})})
    settings = spec.settings()
    ds.attrs.update(model=model.name, time_unit="s", speed_input=speed_name,
                    torque_input=torque_name, snr_db=spec.snr_db, duration=spec.duration,
                    sample_rate=spec.sample_rate, transient=spec.transient,
                    steps_per_period=("rule" if spec.steps_per_period is None
                                      else spec.steps_per_period),
                    sensor=str(settings["sensor"]),
                    noise="white Gaussian, sigma = rms about the mean / 10^(snr_db/20), "
                          "default_rng([seed, fault, speed, torque])",
                    sampling="linear interpolation of the integration grid at k / sample_rate",
                    n_conditions=nf * ns * nt, n_signals=nf * ns * nt * len(spec.seeds),
                    diverged=int(np.count_nonzero(out["status"] != Status.OK)))
    for name, values in errors.items():
        ds[f"stiffness_error_{name}"] = ("fault", np.array(values), {
            "units": "1", "long_name": f"stiffness series truncation error ({name}), relative"})
    return finish(ds, "fault-dataset")
