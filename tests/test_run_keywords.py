"""Run settings reach every part of an analysis, and the old run keywords are deprecated.

- The Lyapunov column of ``bifurcation`` / ``map2d`` integrates with the run's own
  ``locate_edges``, ``bound`` and step (not RunSettings' defaults).
- A ``steps_per_period=`` keyword beside ``run=`` (periodic orbits, continuation) is an error,
  not a silent override of the run's.
- Bare run keywords warn once (DeprecationWarning) and give bitwise the run= result.
"""

from __future__ import annotations

import contextlib
import warnings

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


# ------------------------------------------------------------------ 2. the step: run or keyword
@pytest.mark.parametrize("call", ["periodic_orbit", "continuation", "shooting_problem"])
def test_steps_per_period_beside_run_is_an_error_naming_both(call):
    """A steps_per_period keyword beside run= no longer overrides the run's step silently: a
    TypeError naming both values (also when the run leaves the step to the default)."""
    from geardyn.analysis.orbits import shooting_problem

    g = geardyn.GearPair(Omega=0.5, zeta=0.05, kappa=0.2, Fa=0.2)
    for run_steps in (96, None):
        run = RunSettings(transient=20.0, steps_per_period=run_steps)
        with pytest.raises(TypeError, match=rf"not both.*steps_per_period={run_steps!r} and "
                                            r"steps_per_period=200"):
            if call == "periodic_orbit":
                geardyn.periodic_orbit(g, run=run, steps_per_period=200)
            elif call == "continuation":
                geardyn.continuation(g, "Omega", 0.5, 0.52, run=run, steps_per_period=200)
            else:
                shooting_problem(g, None, 1, run, 200)


def test_orbit_step_from_the_run_or_the_keyword():
    """The run's step and the keyword of a run-less call each reach the shooting problem."""
    from geardyn.analysis.orbits import shooting_problem

    g = geardyn.GearPair(Omega=0.5, zeta=0.05, kappa=0.2, Fa=0.2)
    assert shooting_problem(g, run=RunSettings(steps_per_period=96)).steps_per_period == 96
    assert shooting_problem(g, steps_per_period=200).steps_per_period == 200
    default = shooting_problem(g).steps_per_period
    assert shooting_problem(g, run=RunSettings()).steps_per_period == default


def test_cli_continue_gives_the_step_once(tmp_path, monkeypatch):
    """``geardyn continue --transient ... --steps-per-period ...`` puts the step in the run it
    builds and passes no keyword beside it; without a transient the keyword carries it."""
    from typer.testing import CliRunner

    import geardyn.analysis.branch as branch_module
    from geardyn.cli.main import app

    study = tmp_path / "soft.toml"
    study.write_text('[study]\nname = "soft"\nmodel = "gear_pair"\n[params]\nzeta = 0.05\n'
                     'kappa = 0.0\nFm = 0.1\nFa = 0.05\n[run]\nomega = 1.2\n')
    seen: list = []

    def recording(*args, **kwargs):
        seen.append((kwargs["run"], kwargs["steps_per_period"]))
        return real(*args, **kwargs)

    real = branch_module.continuation
    monkeypatch.setattr(branch_module, "continuation", recording)
    base = ["continue", str(study), "--range", "0.6:0.62", "--quiet", "--steps-per-period", "96"]
    for extra in (["--transient", "50"], []):
        r = CliRunner().invoke(app, base + extra)
        assert r.exit_code == 0, (r.exception, r.stdout)
    (with_run, keyword), (no_run, alone) = seen
    assert with_run.steps_per_period == 96 and keyword is None
    assert no_run is None and alone == 96


# ------------------------------------------------------------------ 3. bare run keywords warn
def _soft() -> geardyn.GearPair:
    return geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)


def _one_warning(record, where: str, keywords: str) -> str:
    """The one DeprecationWarning of a call: names the call's keywords and run=, and points at
    this file (the caller of the public function)."""
    deprecations = [w for w in record if issubclass(w.category, DeprecationWarning)]
    assert len(deprecations) == 1, [str(w.message) for w in deprecations]
    (w,) = deprecations
    text = str(w.message)
    assert text.startswith(f"{where}({keywords}) is deprecated: pass run=geardyn.RunSettings(")
    assert w.filename == __file__, w.filename
    return text


OMEGAS = np.array([0.6, 0.8, 1.0])
SHORT = RunSettings(transient=40.0, samples=4, steps_per_period=64)


def _kw_and_run(where: str):
    """(call with keywords, call with run=, keywords in the message) of each function."""
    g = _soft()
    P = g.lane_params("Omega", OMEGAS)
    ls = LyapunovSettings(duration=30.0)
    grid = (("x", -0.5, 0.5, 2), ("v", -0.5, 0.5, 2))

    def basins_run(**fields):
        from geardyn.analysis.basins import basins_run

        return basins_run(**fields)

    return {
        "simulate": (lambda: geardyn.simulate(g, 0.8, periods=4, steps_per_period=64),
                     lambda: geardyn.simulate(g, 0.8, RunSettings(transient=0.0, samples=4,
                                                                   steps_per_period=64)),
                     "periods=, steps_per_period="),
        "bifurcation": (lambda: geardyn.bifurcation(g, "Omega", OMEGAS, transient=40.0,
                                                    samples=4, steps_per_period=64, tol=1e-6),
                        lambda: geardyn.bifurcation(g, "Omega", OMEGAS,
                                                    SHORT.replace(period_tol=1e-6)),
                        "transient=, samples=, steps_per_period=, tol="),
        "map2d": (lambda: geardyn.map2d(g, ("Omega", OMEGAS), ("zeta", [0.05]), transient=40.0,
                                        samples=4, steps_per_period=64),
                  lambda: geardyn.map2d(g, ("Omega", OMEGAS), ("zeta", [0.05]), SHORT),
                  "transient=, samples=, steps_per_period="),
        "basins": (lambda: geardyn.basins(g, 0.8, *grid, transient=40.0, steps_per_period=64),
                   lambda: geardyn.basins(g, 0.8, *grid,
                                          run=basins_run(transient=40.0, steps_per_period=64)),
                   "transient=, steps_per_period="),
        "frequency_response": (
            lambda: geardyn.frequency_response(g, OMEGAS, transient=40.0, samples=4,
                                               steps_per_period=64),
            lambda: geardyn.frequency_response(g, OMEGAS, SHORT),
            "transient=, samples=, steps_per_period="),
        "continued_sweeps": (
            lambda: geardyn.continued_sweeps([geardyn.ContinuedSweep(g, "Omega", OMEGAS,
                                                                     run=SHORT)], samples=4),
            lambda: geardyn.continued_sweeps([geardyn.ContinuedSweep(g, "Omega", OMEGAS,
                                                                     run=SHORT)],
                                             RunSettings(samples=4)),
            "samples="),
        "ContinuedSweep": (
            lambda: geardyn.continued_sweeps([geardyn.ContinuedSweep(
                g, "Omega", OMEGAS, transient=40.0, steps_per_period=64)], RunSettings(samples=4)),
            lambda: geardyn.continued_sweeps([geardyn.ContinuedSweep(
                g, "Omega", OMEGAS, run=RunSettings(transient=40.0, steps_per_period=64))],
                RunSettings(samples=4)),
            "transient=, steps_per_period="),
        "lyapunov": (lambda: geardyn.lyapunov(g.with_omega(0.8), transient=20.0,
                                              steps_per_period=64, settings=ls),
                     lambda: geardyn.lyapunov(g.with_omega(0.8),
                                              run=RunSettings(transient=20.0,
                                                              steps_per_period=64),
                                              settings=ls),
                     "transient=, steps_per_period="),
        "lyapunov_lanes": (lambda: geardyn.lyapunov_lanes(g, P, locate_edges=False, settings=ls),
                           lambda: geardyn.lyapunov_lanes(g, P, run=RunSettings(
                               transient=100.0, locate_edges=False), settings=ls),
                           "locate_edges="),
    }[where]


WHERE = ("simulate", "bifurcation", "map2d", "basins", "frequency_response", "continued_sweeps",
         "ContinuedSweep", "lyapunov", "lyapunov_lanes")


@pytest.mark.parametrize("where", WHERE)
def test_run_keywords_warn_once_and_give_the_run_result(where):
    """The keyword form warns once, naming the keywords and the equivalent run (the function's
    own defaults included), pointing at the caller; the run= form does not warn; both give
    bitwise the same result."""
    with_keywords, with_run, keywords = _kw_and_run(where)
    with pytest.warns(DeprecationWarning) as record:
        old = with_keywords()
    text = _one_warning(record, where, keywords)
    with warnings_as_errors():
        new = with_run()
    if where == "simulate":
        assert "transient=0.0, samples=4, steps_per_period=64" in text
    if where == "lyapunov_lanes":
        assert "transient=100.0, locate_edges=False" in text
    if where == "basins":
        assert "samples=34, converge=1e-08, transient=40.0" in text
    if isinstance(old, list):
        for a, b in zip(old, new, strict=True):
            xr.testing.assert_identical(a, b)
    elif isinstance(old, xr.Dataset):
        xr.testing.assert_identical(old, new)
    else:
        np.testing.assert_array_equal(old, new)


@contextlib.contextmanager
def warnings_as_errors():
    """A context in which any DeprecationWarning is an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        yield


def test_no_internal_path_warns():
    """The analyses that call others (bifurcation with continuation and Lyapunov,
    frequency_response, the reproduction's basins) give them run=, never keywords."""
    g = _soft()
    with warnings_as_errors():
        geardyn.bifurcation(g, "Omega", OMEGAS, SHORT, continuation="down", lyapunov=True)
        geardyn.bifurcation(g, "Omega", OMEGAS, SHORT, lyapunov=True)
        geardyn.map2d(g, ("Omega", OMEGAS), ("zeta", [0.05]), SHORT, lyapunov=True)
        geardyn.frequency_response(g, OMEGAS, SHORT)
        geardyn.simulate(g)
        geardyn.lyapunov(g, settings=LyapunovSettings(duration=20.0))

