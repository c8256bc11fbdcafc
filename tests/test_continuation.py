"""Continuation: several branches continued together, short transients for continued points,
and the step rule for a fast second forcing."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn import ContinuedSweep, continued_sweeps
from geardyn.analysis.continuation import Branch
from geardyn.core.plan import STEPS_PER_OTHER_FORCING, LaneSettings, default_steps_per_period
from geardyn.solvers.ensemble import run_lanes

VARIABLES = ("poincare", "period", "converged", "transient_periods", "contact", "force_peak",
             "status")


@pytest.fixture(scope="module")
def device():
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1))


@pytest.mark.parametrize("segment", [2, 64])
def test_branches_continued_together_equal_each_alone(device, segment):
    """Sweeps continued together, ``segment`` points of each per kernel call, equal each sweep
    alone (bifurcation with continuation), whatever the segment."""
    om = np.linspace(0.6, 1.6, 7)
    stiffer = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.2, xi2=0.2))
    pair = geardyn.GearPair(zeta=0.05)  # another kernel: its own group
    sweeps = [ContinuedSweep(device, "Omega", om, "up",
                             run=geardyn.RunSettings(transient=300.0, transient_max=300.0,
                                                     continued_transient=30.0)),
              ContinuedSweep(device, "Omega", om, "down",
                             run=geardyn.RunSettings(transient=300.0, transient_max=300.0,
                                                     continued_transient=30.0)),
              ContinuedSweep(stiffer, "Omega", om[:4], "down",
                             run=geardyn.RunSettings(transient=200.0)),
              ContinuedSweep(pair, "Omega", om, "up", run=geardyn.RunSettings(transient=100.0))]
    calls = []
    together = continued_sweeps(sweeps, run=geardyn.RunSettings(samples=6, converge=1e-8),
                                segment=segment, progress=lambda d, t: calls.append(d))
    # progress before each kernel call and once at the end, in each of the two kernel groups
    assert len(calls) == 2 * (-(-om.size // segment) + 1)
    for sw, ds in zip(sweeps, together, strict=True):
        run = geardyn.RunSettings(transient=sw.transient, samples=6, converge=1e-8,
                                  transient_max=sw.transient_max,
                                  continued_transient=sw.continued_transient)
        alone = geardyn.bifurcation(sw.model, "Omega", sw.values, run=run,
                                    continuation=sw.direction)
        assert ds.attrs["continuation"] == sw.direction
        for name in VARIABLES:
            if name in alone:
                a, b = ds[name].values, alone[name].values
                assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name
    # the points come back in value order, whatever the direction
    assert together[1]["Omega"].values.tolist() == om.tolist()


def test_continued_points_with_short_transients_match_cold_starts(device):
    # period-1 region with one attractor: every continued point, after a short transient
    # ended by convergence, sits where a cold start ends after a long fixed transient
    om = np.linspace(0.3, 0.6, 6)
    cont = geardyn.bifurcation(device, "Omega", om,
                               run=geardyn.RunSettings(transient=1500.0, samples=4, converge=1e-9,
                                                       transient_max=1500.0,
                                                       continued_transient=20.0),
                               continuation="up")
    cold = geardyn.bifurcation(device, "Omega", om,
                               run=geardyn.RunSettings(transient=1500.0, samples=4))
    assert cont["converged"].values[1:].tolist() == [1] * 5  # the cold start: no room left
    periods = 2 * math.pi / om
    used = cont["transient_periods"].values * periods
    assert np.all(used[1:] < 1000.0)  # continued: shorter than the cold start's 1500
    assert used[0] >= 1500.0 - periods[0]
    scale = float(np.max(np.abs(cold["poincare"].values)))
    err = np.max(np.abs(cont["poincare"].values - cold["poincare"].values))
    assert err < 1e-6 * scale


def test_incommensurate_continued_points_run_the_short_transient():
    p = geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1, B1=10.0, B2=10.0, Lambda=0.3)
    m = geardyn.CATTDevice(p)
    om = np.array([0.3, 0.3 * math.sqrt(2.0), 0.6])  # Lambda/Omega = 1, irrational, 1/2
    P = m.lane_params("Omega", om)
    b = Branch(m, P, m.initial_state(), transient=400.0, continued_transient=50.0,
               transient_max=800.0)
    assert b.commensurate.tolist() == [True, False, True]
    assert b.transients(0, cold=True, converge=True) == (400.0, 800.0)
    assert b.transients(1, cold=True, converge=True) == (800.0, 800.0)  # untestable, cold
    assert b.transients(1, cold=False, converge=True) == (50.0, 50.0)
    assert b.transients(2, cold=False, converge=True) == (50.0, 800.0)
    ds = geardyn.bifurcation(m, "Omega", om,
                             run=geardyn.RunSettings(transient=400.0, samples=4, converge=1e-8,
                                                     transient_max=800.0, continued_transient=50.0),
                             continuation="up")
    conv = ds["converged"].values
    assert conv[1] == -1  # no section to test
    used = ds["transient_periods"].values[1] * 2 * math.pi / om[1]
    assert 50.0 <= used < 50.0 + 2 * math.pi / om[1]
    assert ds["period"].values[1] == 0


def test_fast_load_fluctuation_sets_the_step():
    p = geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1, B1=100.0, B2=100.0, Lambda=40.0)
    m = geardyn.CATTDevice(p, omega=1.0)
    quiet = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1), omega=1.0)
    n = default_steps_per_period(m, 1.0)
    assert n >= STEPS_PER_OTHER_FORCING * 40.0
    assert n > default_steps_per_period(quiet, 1.0)
    # the default step against DOP853 at rtol 1e-12: the response to the fast forcing is
    # resolved to the accuracy the natural-mode rule gives elsewhere
    r = run_lanes(m, m.lane_params("Omega", [1.0]), m.initial_state(),
                  run=geardyn.RunSettings(transient=60.0, samples=3))
    T = 2 * math.pi
    t_eval = (r.transient_periods[0] + np.arange(1, 4)) * T
    ref = geardyn.reference_solution(m, m.initial_state(), t_eval)
    assert np.max(np.abs(r.samples[0] - ref)) < 1e-6 * np.max(np.abs(ref))


@pytest.mark.parametrize("sweep,message", [
    (dict(direction="sideways"), "direction: must be one of up, down"),
    (dict(values=[]), "values: give at least one"),
    (dict(values=[0.5, float("nan")]), "values: must be finite"),
])
def test_continued_sweeps_bad_input_names_the_field(device, sweep, message):
    spec = dict(model=device, param="Omega", values=[0.5, 0.6], direction="up",
                run=geardyn.RunSettings(transient=10.0))
    spec.update(sweep)
    with pytest.raises(ValueError, match=message):
        continued_sweeps([ContinuedSweep(**spec)], run=geardyn.RunSettings(samples=2))
    with pytest.raises(ValueError, match="converge must be a positive tolerance"):
        continued_sweeps([ContinuedSweep(device, "Omega", [0.5],
                                         run=geardyn.RunSettings(transient=10.0))],
                         run=geardyn.RunSettings(samples=2, converge=-1.0))


def _point_by_point(branch: Branch, run: geardyn.RunSettings) -> list:
    """A branch continued the plain way, one run_lanes call per point from the final state
    and time of the point before (cold again after a point that did not end well): the
    reference the chained lanes of continue_branches must reproduce bit for bit."""
    y, t0, cold, out = branch.y0, 0.0, True, []
    for j in range(branch.P.shape[0]):
        lo, hi = branch.transients(j, cold, run.converge is not None)
        lanes = LaneSettings(t0=[t0], transient=[lo], transient_max=[hi],
                             steps_per_period=[branch.steps[j]])
        r = run_lanes(branch.model, branch.P[j:j + 1], y, run=run, lanes=lanes)
        out.append(r)
        if r.status[0] == geardyn.Status.OK:
            y, t0, cold = r.final[0], float(r.final_time[0]), False
        else:
            y, t0, cold = branch.y0, 0.0, True
    return out


@pytest.mark.parametrize("segment", [3, 64])
def test_chained_points_equal_the_point_by_point_continuation(segment):
    """continue_branches runs a branch's points as a chain of lanes (each starts in the slot
    where the one before ended): every field of every point is bitwise the plain
    point-by-point continuation's, for branches of different lengths and step counts, with
    convergence on, whatever the segment length; and where the amplitude passes the bound
    at Omega = 0.5 (status diverged) the branch restarts cold, as it does point by point."""
    from geardyn.analysis.continuation import continue_branches

    pair = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    up = np.linspace(0.5, 1.5, 9)
    branches = [Branch(pair, pair.lane_params("Omega", up), pair.initial_state(),
                       transient=200.0, continued_transient=30.0, transient_max=600.0),
                Branch(pair, pair.lane_params("Omega", up[::-1][:6]), pair.initial_state(),
                       transient=150.0, continued_transient=20.0, transient_max=500.0)]
    run = geardyn.RunSettings(transient=0.0, samples=4, converge=1e-8, bound=1.05)
    chained = continue_branches(branches, run, segment=segment)
    restarts = 0
    for b, got in zip(branches, chained, strict=True):
        ref = _point_by_point(b, run)
        assert got.status.size == len(ref)
        for j, r in enumerate(ref):
            for name in got.__dataclass_fields__:
                a, e = getattr(got, name)[j:j + 1], getattr(r, name)
                assert np.array_equal(a, e, equal_nan=a.dtype.kind == "f"), (name, j)
        s = got.status
        restarts += int(np.sum((s[:-1] == geardyn.Status.DIVERGED) & (s[1:] == geardyn.Status.OK)))
    assert restarts >= 1  # a diverged point, then a cold restart that ended well


def test_continue_branches_keywords_warn_once_and_agree():
    """continue_branches' settings as keyword arguments (or an int run: the samples) still work,
    bitwise as run=RunSettings(...), with one DeprecationWarning naming that replacement and
    pointing at the caller; run= and a keyword together is a TypeError."""
    import warnings

    from geardyn.analysis.continuation import continue_branches

    pair = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    branches = [Branch(pair, pair.lane_params("Omega", np.linspace(0.8, 1.2, 4)),
                       pair.initial_state(), transient=100.0, continued_transient=20.0)]
    new = continue_branches(branches, geardyn.RunSettings(samples=4, converge=1e-8))
    four = continue_branches(branches, geardyn.RunSettings(samples=4))
    for call, replacement, ref in [
            (dict(samples=4, converge=1e-8), "samples=4, converge=1e-08", new),
            (dict(run=4), "samples=4", four)]:
        with warnings.catch_warnings(record=True) as record:
            warnings.simplefilter("always")
            old = continue_branches(branches, **call)
        deprecations = [w for w in record if issubclass(w.category, DeprecationWarning)]
        assert [str(w.message) for w in deprecations] == [
            f"continue_branches({', '.join(k + '=' for k in call if k != 'run') or 'samples='})"
            f" is deprecated: pass run=geardyn.RunSettings({replacement})"]
        assert deprecations[0].filename == __file__
        for name in type(old[0]).__dataclass_fields__:
            a, b = getattr(old[0], name), getattr(ref[0], name)
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name
    with pytest.raises(TypeError, match="not both"):
        continue_branches(branches, geardyn.RunSettings(samples=4), samples=4)
