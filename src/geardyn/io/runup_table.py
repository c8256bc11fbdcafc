"""The ``[runup]`` table of a study: how ``geardyn runup`` ramps the speed and what it records
(command-line options win over it)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator

from geardyn.models.params import Real, Whole

__all__ = ["RunupTable"]


class RunupTable(BaseModel):
    """``[runup]``: ``start`` and ``stop`` of ``param`` (``"Omega"``, or a frequency the model
    takes by name and that Omega is proportional to: ``input_speed`` [rpm],
    ``mesh_frequency`` [rad/s], a spur pair's ``speed``); ``rate`` (``param`` per model time
    unit) or ``duration`` (model time units): exactly one; ``transient`` (time held at the
    start speed, not recorded); ``sample_rate`` (samples per time unit); ``outputs`` (states
    and observables recorded; default all); ``steps_per_period`` (at the highest speed);
    ``output`` (the one the waterfall analyses; default the first mesh force, else the first
    state); ``window`` (the waterfall's window, time units) and ``harmonics`` (order rays
    drawn)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    param: str = Field("Omega", min_length=1, description="the ramped frequency")
    start: Real = Field(ge=0, description="start value of param")
    stop: Real = Field(ge=0, description="stop value of param")
    rate: Real | None = Field(None, gt=0, description="param per time unit")
    duration: Real | None = Field(None, gt=0, description="time of the ramp")
    transient: Real = Field(0.0, ge=0, description="time held at start first")
    sample_rate: Real | None = Field(None, gt=0, description="samples per time unit")
    outputs: list[str] | None = Field(None, min_length=1, description="recorded outputs")
    steps_per_period: Whole | None = Field(None, ge=8, description="RK4 steps per period at "
                                           "the highest speed")
    output: str | None = Field(None, min_length=1, description="output of the waterfall")
    window: Real | None = Field(None, gt=0, description="waterfall window [time units]")
    harmonics: Whole = Field(4, ge=1, le=40, description="order rays drawn")

    @model_validator(mode="after")
    def _one_ramp(self) -> RunupTable:
        if self.start == self.stop:
            raise ValueError(f"start and stop must differ (got {self.start!r} twice)")
        if (self.rate is None) == (self.duration is None):
            raise ValueError("give exactly one of rate and duration")
        return self
