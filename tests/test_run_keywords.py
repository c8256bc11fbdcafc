"""Run settings reach every part of an analysis, and the old run keywords are deprecated.

- The Lyapunov column of ``bifurcation`` / ``map2d`` integrates with the run's own
  ``locate_edges``, ``bound`` and step (not RunSettings' defaults).
- A ``steps_per_period=`` keyword beside ``run=`` (periodic orbits, continuation) is an error,
  not a silent override of the run's.
- Bare run keywords warn once (DeprecationWarning) and give bitwise the run= result.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn import LyapunovSettings, RunSettings
from geardyn.analysis import bifurcation as bif_module
from geardyn.analysis import lyapunov as lyap_module
from geardyn.analysis.bifurcation import LYAPUNOV_ALIGN
from geardyn.analysis.lyapunov import lyapunov_lanes


def _pair() -> geardyn.GearPair:
    """A gear pair whose backlash is crossed every period (contact loss) at Omega 0.92,
    chaotic there (tests/test_lyapunov.py), period 1 at 0.5."""
    return geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)


#: A short run integrated across the edges (no location), few steps per period.
UNLOCATED = RunSettings(transient=60.0, samples=12, steps_per_period=64, locate_edges=False,
                        bound=1.0e5)


# ------------------------------------------------------------------ 1. Lyapunov sees the run
def test_bifurcation_lyapunov_uses_the_runs_locate_edges_and_bound():
    """The Lyapunov column equals lyapunov_lanes run with the sweep's own run (its aligning
    transient), and differs from the run with located edges: locate_edges reached it."""
    g, values = _pair(), np.array([0.5, 0.92])
    ds = geardyn.bifurcation(g, "Omega", values, run=UNLOCATED, lyapunov=True)
    lanes = geardyn.bifurcation(g, "Omega", values, run=UNLOCATED)
    P = g.lane_params("Omega", values)
    start = np.stack([ds["poincare"].values[j, -1] for j in range(values.size)])
    duration = UNLOCATED.samples * float(np.mean(2 * np.pi / values))
    align = UNLOCATED.replace(transient=min(UNLOCATED.transient, LYAPUNOV_ALIGN))
    direct = lyapunov_lanes(g, P, start, align, settings=LyapunovSettings(duration=duration),
                            t0=lanes["final_time"].values)
    np.testing.assert_array_equal(ds["lyapunov"].values, direct)
    located = lyapunov_lanes(g, P, start, align.replace(locate_edges=True),
                             settings=LyapunovSettings(duration=duration),
                             t0=lanes["final_time"].values)
    assert np.all(np.isfinite(direct)) and not np.array_equal(direct, located)


def _spy(monkeypatch) -> list[RunSettings]:
    """Record the run each lyapunov_lanes call gets (and compute nothing)."""
    seen: list[RunSettings] = []

    def fake(model, P, y0=None, run=None, **_kw):
        seen.append(run)
        L = np.atleast_2d(P).shape[0]
        return np.zeros(L), np.zeros(L), np.zeros(L, np.int64), np.zeros(L, np.int64)

    monkeypatch.setattr(lyap_module, "lyapunov_lanes", fake)
    return seen


@pytest.mark.parametrize("analysis", ["bifurcation", "bifurcation-down", "map2d"])
def test_lyapunov_call_gets_the_runs_fields(monkeypatch, analysis):
    """Every RunSettings field lyapunov_lanes reads (step, locate_edges, bound; transient:
    the map's, the sweep's capped at LYAPUNOV_ALIGN) is the analysis's run's."""
    seen = _spy(monkeypatch)
    g = _pair()
    run = RunSettings(transient=30.0, samples=4, steps_per_period=48, locate_edges=False,
                      bound=2.0e4)
    if analysis == "map2d":
        geardyn.map2d(g, ("Omega", [0.5, 0.6]), ("zeta", [0.02]), run=run, lyapunov=True)
        want_transient = run.transient
    else:
        cont = "down" if analysis.endswith("down") else None
        bif_module.bifurcation(g, "Omega", [0.5, 0.6], run=run, lyapunov=True,
                               continuation=cont)
        want_transient = min(run.transient, LYAPUNOV_ALIGN)
    (got,) = seen
    for field in lyap_module.LYAPUNOV_FIELDS:
        want = want_transient if field == "transient" else getattr(run, field)
        assert getattr(got, field) == want, field


def test_map2d_lyapunov_uses_the_runs_locate_edges():
    """map2d's Lyapunov column equals lyapunov_lanes with the map's run, and it differs from
    the one with located edges."""
    g, omegas = _pair(), np.array([0.5, 0.92])
    ds = geardyn.map2d(g, ("Omega", omegas), ("zeta", [0.02]), run=UNLOCATED, lyapunov=True)
    sweep = geardyn.bifurcation(g, "Omega", omegas, run=UNLOCATED)
    P = g.lane_params("Omega", omegas)
    start = np.stack([sweep["poincare"].values[j, -1] for j in range(omegas.size)])
    settings = LyapunovSettings(duration=ds.attrs["lyapunov_duration"])
    direct = lyapunov_lanes(g, P, start, UNLOCATED, settings=settings,
                            t0=sweep["final_time"].values)
    np.testing.assert_array_equal(ds["lyapunov"].values[0], direct)
    located = lyapunov_lanes(g, P, start, UNLOCATED.replace(locate_edges=True),
                             settings=settings, t0=sweep["final_time"].values)
    assert not np.array_equal(direct, located)


def _identical(a: xr.Dataset, b: xr.Dataset) -> None:
    xr.testing.assert_identical(a, b)
