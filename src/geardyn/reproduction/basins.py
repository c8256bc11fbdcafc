"""Basins of attraction where a case's up and down sweeps disagree (``geardyn reproduce
--basins N``).

For each case result the frequency is the grid point nearest the middle of the widest interval
where both sweeps are periodic but follow different attractors (the report's "coexisting orbits
of the same period", else its "hysteresis" intervals where both sweeps have a period). There the
basins of the plotted coordinate and its velocity are computed on an N x N grid
(:func:`geardyn.basins`) spanning both sweeps' section points with a margin, the other states at
the model's initial state; each attractor is matched to the periodic orbits that Newton shooting
(:func:`geardyn.periodic_orbit`) finds from the up and the down sweep's section points, so the
report says which attractor each sweep follows and what share of initial conditions reach it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from geardyn.reproduction.cases import Case
from geardyn.reproduction.evidence import Branch, hysteresis

__all__ = ["MARGIN", "basin_omega", "case_basins", "summary"]

#: The grid spans the sweeps' section points widened by this fraction of their span (and by at
#: least 0.5, in the model's scaled units) on each side.
MARGIN = 0.5


def _both_periodic(ds: xr.Dataset, j: int) -> bool:
    k = ds["period"].values[:, j]
    return bool(np.all(k > 0) and np.all(ds["status"].values[:, j] == 0))


def basin_omega(ds: xr.Dataset) -> float | None:
    """The frequency at which to draw a case's basins (see the module docs), or None when the
    sweeps never disagree while both are periodic."""
    runs = hysteresis(ds)
    omega = ds["Omega"].values
    for key in ("orbit", "class"):
        found = runs.get(key) or []
        for lo, hi, _n in sorted(found, key=lambda r: -r[2]):
            inside = np.flatnonzero((omega >= lo) & (omega <= hi))
            inside = [j for j in inside if _both_periodic(ds, j)]
            if inside:
                mid = 0.5 * (lo + hi)
                return float(omega[min(inside, key=lambda j: abs(omega[j] - mid))])
    return None


def _velocity(names: list[str], state: str) -> str:
    """The velocity paired with ``state`` (``X_sq`` -> ``V_sq``; else the next state)."""
    if state.startswith("X_") and "V_" + state[2:] in names:
        return "V_" + state[2:]
    return names[(names.index(state) + 1) % len(names)]


def _axis(points: np.ndarray, n: int) -> tuple[float, float, int]:
    lo, hi = float(np.nanmin(points)), float(np.nanmax(points))
    pad = max(MARGIN * (hi - lo), 0.5)
    return lo - pad, hi + pad, n


def case_basins(case: Case, interpretation: str, ds: xr.Dataset, n: int,
                transient: float | None = None) -> xr.Dataset | None:
    """The basins of ``case`` under ``interpretation`` at :func:`basin_omega` of its result
    ``ds`` on an ``n`` x ``n`` grid (None where the sweeps never disagree while periodic);
    ``transient``: the least transient (default the case's), each cell running on until its
    section point settles (to 1e-8) or ten times that."""
    from geardyn.analysis.basins import basins, basins_run
    from geardyn.analysis.orbits import periodic_orbit
    from geardyn.study import build_model

    om = basin_omega(ds)
    if om is None:
        return None
    model = build_model(case.study, interpretation=interpretation, omega=om)
    names = list(model.state_names)
    state = Branch.from_dataset(ds, "up").state
    vel = _velocity(names, state)
    at = ds.sel(Omega=om)
    pts = at["poincare"].sel(state=[state, vel]).values.reshape(-1, 2)
    tr = float(ds.attrs.get("transient", 4000.0) if transient is None else transient)
    j = int(np.argmin(np.abs(ds["Omega"].values - om)))
    orbits = [periodic_orbit(model, om, period=int(ds["period"].values[s, j]),
                             guess=at["poincare"].values[s, -1])
              for s in range(ds.sizes["sweep"])]
    out = basins(model, om, (state, *_axis(pts[:, 0], n)), (vel, *_axis(pts[:, 1], n)),
                 run=basins_run(transient=tr, transient_max=10 * tr), orbits=orbits)
    out.attrs.update(case=str(ds.attrs.get("case", case.name)), interpretation=interpretation,
                     study=f"{ds.attrs.get('figure', case.figure)} ({interpretation})",
                     sweeps=", ".join(str(s) for s in ds["sweep"].values),
                     orbit_stability=", ".join(o.stability for o in orbits),
                     orbit_names=", ".join(f"the {s} sweep's orbit"
                                           for s in ds["sweep"].values))
    return out


def summary(b: xr.Dataset) -> str:
    """One line: the frequency, each attractor's period, share and the sweeps it carries, and
    the shares of diverged and unresolved cells."""
    sweeps = str(b.attrs.get("sweeps", "up, down")).split(", ")
    parts = []
    for a in range(b.sizes["attractor"]):
        k = int(b["attractor_period"].values[a])
        orbit = int(b["attractor_orbit"].values[a])
        follow = f" (the {sweeps[orbit]} sweep's orbit)" if 0 <= orbit < len(sweeps) else ""
        parts.append(f"#{a} {'period-' + str(k) if k > 0 else 'no period'} "
                     f"{100 * float(b['attractor_fraction'].values[a]):.1f}%{follow}")
    parts.append(f"diverged {100 * float(b.attrs['diverged_fraction']):.1f}%")
    parts.append(f"unresolved {100 * float(b.attrs.get('unresolved_fraction', 0.0)):.1f}%")
    return (f"basins of attraction at Omega = {float(b.attrs['Omega']):.4g} "
            f"({b.sizes[b.attrs['x']]} x {b.sizes[b.attrs['y']]} initial "
            f"{b.attrs['x']}, {b.attrs['y']}): " + "; ".join(parts))


def write_basins(b: xr.Dataset, out: Path, stem: str) -> dict[str, Path]:
    """Write a case's basins: NetCDF data and a PNG figure."""
    from geardyn.io.netcdf import save_dataset
    from geardyn.plotting.basins import plot_basins

    data = save_dataset(b, out / f"basins-{stem}.nc")
    figure = out / f"basins-{stem}.png"
    plot_basins(b, path=figure)
    return {"data": data, "figure": figure}
