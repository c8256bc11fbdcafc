"""The ``[envelope]`` table of a study: the defaults of ``geardyn envelope`` (command-line
options win)::

    [envelope]
    x = "Omega"                    # the plane: two parameters the model sweeps
    y = "Fa"
    x_range = [0.5, 2.0]           # the box (low, high) of each
    y_range = [0.0, 1.5]
    flanks = ["drive", "back"]     # the grazing curves followed (default both)
    # mesh = "mesh"                # default the model's first mesh
    # starts = [0.875, 1.25]       # x values scanned in y for starting points (default 3)
    scan = 24                      # y values per scan
    period = 1                     # k of the orbits
    resolution = 200               # grid points per axis of the regions
    map = [16, 12]                 # optional: a brute-force map beneath, x and y points

An unknown key or a bad value is an error naming ``envelope.<field>``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from geardyn.models.params import Real, Whole

__all__ = ["EnvelopeTable"]


class EnvelopeTable(BaseModel):
    """The ``[envelope]`` table (see the module docs)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    x: str = Field("Omega", min_length=1, description="the plane's x parameter")
    y: str | None = Field(None, min_length=1, description="the plane's y parameter")
    x_range: tuple[Real, Real] | None = Field(None, description="(low, high) of x")
    y_range: tuple[Real, Real] | None = Field(None, description="(low, high) of y")
    mesh: str | None = Field(None, min_length=1, description="the mesh (default the first)")
    flanks: tuple[Literal["drive", "back"], ...] = Field(
        ("drive", "back"), min_length=1, description="flanks whose grazing curves are followed")
    starts: tuple[Real, ...] | None = Field(None, min_length=1,
                                            description="x values scanned for starting points")
    scan: Whole = Field(24, ge=2, description="y values per scan")
    period: Whole = Field(1, ge=1, description="k: period of the orbits in section periods")
    resolution: Whole = Field(200, ge=2, le=4000, description="grid points per axis")
    map: tuple[Whole, Whole] | None = Field(None, description="brute-force map: x, y points")

    @field_validator("x_range", "y_range")
    @classmethod
    def _low_high(cls, r: tuple[float, float] | None) -> tuple[float, float] | None:
        if r is not None and not r[0] < r[1]:
            raise ValueError(f"low < high (got {list(r)})")
        return r

    @field_validator("map")
    @classmethod
    def _map_points(cls, n: tuple[int, int] | None) -> tuple[int, int] | None:
        if n is not None and min(n) < 2:
            raise ValueError(f"at least 2 points per axis (got {list(n)})")
        return n

    @field_validator("flanks")
    @classmethod
    def _once(cls, flanks: tuple[str, ...]) -> tuple[str, ...]:
        if len(set(flanks)) != len(flanks):
            raise ValueError(f"each flank at most once (got {list(flanks)})")
        return flanks

    @model_validator(mode="after")
    def _distinct(self) -> EnvelopeTable:
        if self.y is not None and self.x == self.y:
            raise ValueError(f"x and y must be different parameters (both {self.x!r})")
        return self
