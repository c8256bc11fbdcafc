"""Measurements on case results that the claim checks are built from.

A :class:`Branch` is one sweep direction of one case: the Omega grid, the motion label of every
point (:mod:`geardyn.reproduction.motion`), the stroboscopic samples of the case's plotted
coordinate, the contact regimes and where the back flanks touch. :class:`Evidence` holds the
branches of every case run under one interpretation.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import xarray as xr

from geardyn.analysis.motion import CHAOTIC, period_label
from geardyn.reproduction.motion import intervals, is_nonperiodic

__all__ = ["QUASI_STATIC", "Branch", "Evidence", "MissingCase", "back_flank_contact",
           "format_intervals"]

#: A load fluctuation counts as quasi-static when Lambda is at most this share of the lowest
#: natural frequency (dynamic amplification 1 / (1 - 0.25^2) = 1.07 at most).
QUASI_STATIC = 0.25


class MissingCase(LookupError):
    """A claim needs a case that was not run."""


def format_intervals(runs: list[tuple[float, float, int]], limit: int = 6) -> str:
    """``"1.02-1.28 (14 pts), 2.27-2.69 (22 pts)"``; "none" when empty."""
    if not runs:
        return "none"
    text = [f"{a:.3g}" if n == 1 else f"{a:.3g}-{b:.3g}" for a, b, n in runs[:limit]]
    text = [f"{t} ({n} pt{'s' if n > 1 else ''})" for t, (_, _, n) in zip(text, runs, strict=False)]
    more = f", ... ({len(runs) - limit} more)" if len(runs) > limit else ""
    return ", ".join(text) + more


@dataclass(frozen=True)
class Branch:
    """One sweep direction of one case (Omega ascending)."""

    case: str
    omega: np.ndarray
    motion: np.ndarray
    x: np.ndarray  # (Omega, sample): stroboscopic samples of the plotted coordinate
    contact: np.ndarray  # (Omega, mesh)
    mesh: tuple[str, ...]
    static_deflection: float  # dimensionless static mesh deflection of the plotted mesh
    state: str
    back: np.ndarray | None = None  # (Omega,): the back flanks touch (any mesh); see below
    params_json: str = ""  # the case's parameters (PlanetaryParams JSON), "" if unknown
    interpretation: str = ""

    @classmethod
    def from_dataset(cls, ds: xr.Dataset, direction: str = "up") -> Branch:
        d = ds.sel(sweep=direction)
        order = np.argsort(d["Omega"].values, kind="stable")
        state = str(ds.attrs.get("plot_state", "X_sq"))
        names = [str(s) for s in ds["state"].values]
        state = state if state in names else f"{state}1"
        mesh = tuple(str(m) for m in ds["mesh"].values)
        static = np.atleast_1d(ds.attrs.get("static_deflection", [np.nan] * len(mesh)))
        which = 1 if "pq" in state else 0
        return cls(
            case=str(ds.attrs.get("case", "?")),
            omega=d["Omega"].values[order],
            motion=d["motion"].values[order].astype(str),
            x=d["poincare"].sel(state=state).transpose("Omega", "sample").values[order],
            contact=d["contact"].transpose("Omega", "mesh").values[order].astype(str),
            mesh=mesh,
            static_deflection=float(static[min(which, static.size - 1)]),
            state=state,
            back=back_flank_contact(d),
            params_json=str(ds.attrs.get("params_json", "")),
            interpretation=str(ds.attrs.get("interpretation", "")),
        )

    # ------------------------------------------------------------------ masks
    @property
    def step(self) -> float:
        """Grid spacing in Omega."""
        return float(np.median(np.diff(self.omega))) if self.omega.size > 1 else 0.0

    def period(self, k: int) -> np.ndarray:
        return self.motion == period_label(k)

    @property
    def chaotic(self) -> np.ndarray:
        return self.motion == CHAOTIC

    @property
    def nonperiodic(self) -> np.ndarray:
        return is_nonperiodic(self.motion)

    @property
    def bifurcated(self) -> np.ndarray:
        """Anything but period-1 motion."""
        return ~self.period(1)

    def within(self, lo: float, hi: float) -> np.ndarray:
        return (self.omega >= lo - 1e-12) & (self.omega <= hi + 1e-12)

    # ------------------------------------------------------------------ measures
    def share(self, mask: np.ndarray, lo: float, hi: float) -> tuple[float, int]:
        """Share of the grid points in [lo, hi] where ``mask`` holds, and their number."""
        inside = self.within(lo, hi)
        n = int(np.count_nonzero(inside))
        return (float(np.mean(mask[inside])) if n else float("nan")), n

    def runs(self, mask: np.ndarray, min_points: int = 1) -> list[tuple[float, float, int]]:
        return [r for r in intervals(self.omega, mask) if r[2] >= min_points]

    def regions(self, mask: np.ndarray, min_width: float) -> list[tuple[float, float, int]]:
        """Runs of consecutive points where ``mask`` holds that span at least ``min_width`` in
        Omega (last minus first point; so never a single point)."""
        return [r for r in intervals(self.omega, mask)
                if r[2] > 1 and r[1] - r[0] >= min_width - 1e-9]

    def first_region(self, mask: np.ndarray, min_width: float) -> float | None:
        """The lowest Omega of a region (:meth:`regions`) where ``mask`` holds."""
        found = self.regions(mask, min_width)
        return found[0][0] if found else None

    def length(self, mask: np.ndarray) -> float:
        """Omega-length covered by ``mask`` (points times the grid spacing)."""
        return float(np.count_nonzero(mask)) * self.step

    def first(self, mask: np.ndarray) -> float | None:
        """The lowest Omega where ``mask`` holds."""
        idx = np.flatnonzero(mask)
        return float(self.omega[idx[0]]) if idx.size else None

    def describe(self, mask: np.ndarray) -> str:
        return format_intervals(self.runs(mask))

    @property
    def top(self) -> np.ndarray:
        """Largest stroboscopic value of the plotted coordinate at each Omega."""
        return np.nanmax(self.x, axis=1)

    @property
    def spread(self) -> np.ndarray:
        """Peak-to-peak of the stroboscopic values at each Omega."""
        return np.nanmax(self.x, axis=1) - np.nanmin(self.x, axis=1)

    @property
    def diverged(self) -> np.ndarray:
        """The integration diverged (contact regime ``unbounded`` in some mesh)."""
        return np.any(self.contact == "unbounded", axis=1)

    @property
    def back_contact(self) -> np.ndarray:
        """The back flanks touch at this Omega (see :func:`back_flank_contact`)."""
        if self.back is None:
            return np.any(self.contact == "double", axis=1)
        return self.back

    @cached_property
    def backlash(self) -> float:
        """Backlash of the plotted mesh in units of b_c (NaN when the parameters are unknown)."""
        p = self._params()
        if p is None:
            return float("nan")
        mesh = p.planet_mesh if "pq" in self.state else p.sun_mesh
        return float(mesh.backlash / p.b_c)

    @cached_property
    def quasi_static(self) -> tuple[float, float, float]:
        """The linear static response to the load fluctuation B1, B2 (loads A +- B through the
        static stiffness): ``(spread, Lambda, lowest natural frequency)``, where ``spread`` is
        the quasi-static peak-to-peak of the plotted coordinate [b_c] (NaN when the parameters
        are unknown). A fair estimate of the measured growth of the point spread only when
        Lambda <= :data:`QUASI_STATIC` x the lowest natural frequency."""
        p = self._params()
        if p is None or not self.interpretation:
            return float("nan"), float("nan"), float("nan")
        from geardyn.models.catt import CATTDevice

        loads = p.loads
        base = CATTDevice(p, self.interpretation)
        moved = CATTDevice(p.replace(A1=loads.A1 + loads.B1, A2=loads.A2 + loads.B2),
                           self.interpretation)
        which = 1 if "pq" in self.state else 0
        shift = float(moved.static_forces()[which] - base.static_forces()[which])
        lowest = float(np.min(base.natural_frequencies()))
        return 2.0 * abs(shift), float(loads.Lambda), lowest

    def _params(self):
        if not self.params_json:
            return None
        from geardyn.models.params import PlanetaryParams

        return PlanetaryParams.model_validate_json(self.params_json)

    @property
    def extent(self) -> float:
        """Peak-to-peak of every stroboscopic value of the whole diagram."""
        return float(np.nanmax(self.x) - np.nanmin(self.x))


def back_flank_contact(d: xr.Dataset) -> np.ndarray | None:
    """Where the back flanks touch, per point of one sweep ``d`` (dims Omega, mesh): the contact
    regime ``double`` (both flanks hit: the back-flank switching function X + b changed sign or
    crossed zero while sampling), or ``none`` with the mesh coordinate below zero (always on the
    back flank). None when ``d`` has no contact regimes. Read on the sampled motion of every
    point, after its transient."""
    if "contact" not in d or "mesh" not in d.dims:
        return None
    regime = d["contact"].transpose("Omega", "mesh").values.astype(str)
    order = np.argsort(d["Omega"].values, kind="stable")
    out = np.any(regime == "double", axis=1)
    names = [str(s) for s in d["state"].values] if "state" in d.coords else []
    for j, mesh in enumerate(str(m) for m in d["mesh"].values):
        state = f"X_{mesh}"
        if state not in names or "poincare" not in d:
            continue
        x = d["poincare"].sel(state=state).transpose("Omega", "sample").values
        behind = np.all(x < 0.0, axis=1)
        out |= (regime[:, j] == "none") & behind
    return out[order]


class Evidence:
    """Branches of the cases run under one interpretation, for one sweep direction."""

    def __init__(self, results: Mapping[str, xr.Dataset], direction: str = "up"):
        self.results = dict(results)
        self.direction = direction
        self._cache: dict[str, Branch] = {}

    def has(self, *cases: str) -> bool:
        return all(c in self.results for c in cases)

    def __getitem__(self, case: str) -> Branch:
        if case not in self.results:
            raise MissingCase(case)
        if case not in self._cache:
            self._cache[case] = Branch.from_dataset(self.results[case], self.direction)
        return self._cache[case]


#: Relative distance above which two period-k orbits of the same k count as different.
ORBIT_TOL = 1.0e-3


def hysteresis(ds: xr.Dataset) -> dict[str, list[tuple[float, float, int]] | None]:
    """Where the up and down sweeps of a case result disagree: ``"class"`` (the motion labels
    differ: coexisting attractors of different kinds, jumps) and ``"orbit"`` (both period-k
    with the same k, but on different orbits: the sorted stroboscopic values of the plotted
    coordinate differ by more than :data:`ORBIT_TOL` relative). Orbits are not compared under a
    load fluctuation (``"orbit"`` is then None): the two sweeps sample the load at different
    phases, so the same attractor shows different points."""
    up, down = Branch.from_dataset(ds, "up"), Branch.from_dataset(ds, "down")
    differ = up.motion != down.motion
    noise = float(ds.attrs.get("Lambda", 0.0)) > 0 and (
        float(ds.attrs.get("B1", 0.0)) != 0 or float(ds.attrs.get("B2", 0.0)) != 0)
    if noise:
        return {"class": up.runs(differ), "orbit": None}
    orbit = np.zeros(up.omega.size, dtype=bool)
    for i, label in enumerate(up.motion):
        if differ[i] or not label.startswith("period-"):
            continue
        k = int(label.split("-")[1])
        a, b = np.sort(up.x[i, :k]), np.sort(down.x[i, :k])
        scale = ORBIT_TOL * max(1.0, float(np.max(np.abs(a))))
        orbit[i] = bool(np.max(np.abs(a - b)) > scale)
    return {"class": up.runs(differ), "orbit": up.runs(orbit)}
