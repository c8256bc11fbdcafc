"""The ``[dataset]`` table of a study: the labelled fault data of ``geardyn dataset``
(:func:`geardyn.fault_dataset` over the study's model; command-line options win)::

    [dataset]
    speeds = [1000, 2000, 3000]    # the model's speed input (a spur pair's params.speed_unit;
                                   # a planetary set's or a train's input speed [rpm])
    torques = [20, 60, 100]        # [N m]: a spur pair's torque, a planetary set's
                                   # sun_torque, a train's input_torque
    seeds = 10                     # noise seeds 0..9 (or a list: [0, 7, 11])
    snr_db = 20.0                  # signal-to-noise ratio [dB]; "inf": no noise
    duration = 1.0                 # each signal [s]
    sample_rate = 20000            # [Hz]
    transient = 0.0                # [s] discarded first
    steps_per_mode = 50            # RK4 steps per contact-mode period (or steps_per_period;
                                   # neither: the step rule)
    chunk = 50                     # conditions per chunk (the store's and the bar's grain)
    store = "faults.zarr"          # the Zarr store (relative to the working directory)
    workers = 2                    # local processes (default: every core)
    sensor = { width = 1.5708 }    # the model's sensor signal's settings (a planetary
                                   # set's ring sensor: sensor_angle, width [rad], window;
                                   # a spur pair's or a train's mesh force: mesh)

    [[dataset.faults]]             # one table per condition; kind "healthy" or a fault kind
    kind = "healthy"               # of geardyn.gears.FAULT_KINDS with that fault's fields

    [[dataset.faults]]
    kind = "crack"
    gear = "pinion"
    tooth = 0
    depth = "1.5 mm"

An unknown key or a bad value is an error naming ``dataset.<field>`` (a fault's
``dataset.faults[<i>].<field>``).
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from geardyn.models.params import Real, Whole

__all__ = ["HEALTHY", "DatasetTable"]

#: The ``kind`` of a healthy condition in ``[[dataset.faults]]``.
HEALTHY = "healthy"


class DatasetTable(BaseModel):
    """The ``[dataset]`` table (see the module docs). ``faults`` stay tables here: they are
    built against the study's gears by ``geardyn dataset``, which names
    ``dataset.faults[<i>].<field>`` for a bad one."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    faults: list[dict[str, Any]] = Field(min_length=1, description="the fault conditions")
    speeds: list[Real] = Field(min_length=1, description="speed input values")
    torques: list[Real] = Field(min_length=1, description="torques [N m]")
    seeds: Whole | list[Whole] = Field(1, description="noise seeds: a count or a list")
    snr_db: Real | str = Field(20.0, description="signal-to-noise ratio [dB] or \"inf\"")
    duration: Real = Field(1.0, gt=0, description="each signal [s]")
    sample_rate: Real = Field(20_000.0, gt=0, description="samples per second [Hz]")
    transient: Real = Field(0.0, ge=0, description="time discarded first [s]")
    steps_per_period: Whole | None = Field(None, ge=8, description="RK4 steps per period")
    steps_per_mode: Real | None = Field(None, ge=8, description="RK4 steps per mode period")
    chunk: Whole | None = Field(None, ge=1, description="conditions per chunk")
    store: str | None = Field(None, min_length=1, description="the Zarr store's path")
    workers: Whole | None = Field(None, ge=1, description="local processes")
    sensor: dict[str, Any] = Field(default_factory=dict,
                                   description="the sensor signal's settings")

    @field_validator("faults")
    @classmethod
    def _kinds(cls, faults: list[dict[str, Any]]) -> list[dict[str, Any]]:
        for i, f in enumerate(faults):
            if not isinstance(f.get("kind"), str):
                raise ValueError(f"faults[{i}]: needs a kind (\"{HEALTHY}\" or a fault kind)")
            if f["kind"] == HEALTHY and len(f) > 1:
                raise ValueError(f"faults[{i}]: a healthy condition has no other field (got "
                                 f"{', '.join(k for k in f if k != 'kind')})")
        return faults

    @field_validator("snr_db")
    @classmethod
    def _snr(cls, value: float | str) -> float | str:
        if isinstance(value, str) and value != "inf":
            raise ValueError(f"must be a number or \"inf\" (got {value!r})")
        return value

    @model_validator(mode="after")
    def _one_step(self) -> DatasetTable:
        if self.steps_per_period is not None and self.steps_per_mode is not None:
            raise ValueError("give steps_per_period or steps_per_mode, not both")
        return self

    def seed_list(self) -> list[int]:
        """The noise seeds: ``range(seeds)`` for a count, else the list."""
        return list(range(self.seeds)) if isinstance(self.seeds, int) else list(self.seeds)

    def snr(self) -> float:
        """``snr_db`` as a number (``inf`` for ``"inf"``)."""
        return float(self.snr_db)
