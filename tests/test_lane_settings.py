"""run_lanes takes its settings one way: ``run=RunSettings(...)`` and the per-lane values as one
``lanes=LaneSettings(...)`` (validated at construction). The old separate arguments (positional
or keyword) still work for one deprecation cycle: bitwise the same lanes, one DeprecationWarning
per process naming the new spelling, pointing at the caller."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import geardyn
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.solvers.ensemble import LaneResults, run_lanes
from test_lyapunov import lorenz_model

PAIR = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
OMEGAS = np.array([0.6, 0.9, 1.3])


def _bitwise(a: LaneResults, b: LaneResults) -> None:
    for name in LaneResults.__dataclass_fields__:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), name


def _deprecations(record) -> list[warnings.WarningMessage]:
    return [w for w in record if issubclass(w.category, DeprecationWarning)]


def _calls():
    """(old spelling, new spelling, the old call's keywords, text of the replacement)."""
    P = PAIR.lane_params("Omega", OMEGAS)
    y0 = PAIR.initial_state()
    T = 2 * math.pi / OMEGAS
    t0 = 3 * T  # whole periods: the forcing phase is zero there
    return {
        "positional": (
            lambda: run_lanes(PAIR, P, y0, 40.0, 4, 64),
            lambda: run_lanes(PAIR, P, y0,
                              run=RunSettings(transient=40.0, samples=4, steps_per_period=64)),
            "transient=, samples=, steps_per_period=",
            "run=geardyn.RunSettings(transient=40.0, samples=4, steps_per_period=64)"),
        "per lane": (
            lambda: run_lanes(PAIR, P, y0, transient=np.array([20.0, 30.0, 40.0]), samples=3,
                              steps_per_period=np.array([64, 0, 96]), t0=t0, sample_every=2,
                              locate_edges=False),
            lambda: run_lanes(PAIR, P, y0, run=RunSettings(samples=3, locate_edges=False),
                              lanes=LaneSettings(t0=t0, transient=[20.0, 30.0, 40.0],
                                                 steps_per_period=[64, 0, 96], sample_every=2)),
            "transient=, samples=, steps_per_period=, t0=, sample_every=, locate_edges=",
            "run=geardyn.RunSettings(samples=3, locate_edges=False), lanes=geardyn.core."
            "LaneSettings(t0=<3 values>, transient=<3 values>, steps_per_period=<3 values>, "
            "sample_every=2)"),
        "convergence": (
            lambda: run_lanes(PAIR, P, y0, 30.0, 4, converge_tol=1e-8, transient_max=400.0,
                              converge_depth=8, bound=1e4),
            lambda: run_lanes(PAIR, P, y0, converge_depth=8, run=RunSettings(
                transient=30.0, samples=4, converge=1e-8, transient_max=400.0, bound=1e4)),
            "transient=, samples=, converge_tol=, transient_max=, bound=",  # converge_depth=
            "run=geardyn.RunSettings(transient=30.0, samples=4, converge=1e-08, "  # stays
            "transient_max=400.0, bound=10000.0)"),
        "all positional": (
            lambda: run_lanes(PAIR, P, y0, 30.0, 4, 0, 1, True, 1e4, None, 400.0, 1e-8, 8, 2),
            lambda: run_lanes(PAIR, P, y0, converge_depth=8, run=RunSettings(
                transient=30.0, samples=4, converge=1e-8, transient_max=400.0, bound=1e4,
                locate_edges=True, max_section_periods=2), lanes=LaneSettings(sample_every=1)),
            "transient=, samples=, steps_per_period=, sample_every=, locate_edges=, bound=, "
            "transient_max=, converge_tol=, converge_depth=, max_section_periods=",
            "run=geardyn.RunSettings(transient=30.0, samples=4, locate_edges=True, "
            "bound=10000.0, transient_max=400.0, converge=1e-08, max_section_periods=2), "
            "lanes=geardyn.core.LaneSettings(sample_every=1), converge_depth=8"),
        "beside run": (
            lambda: run_lanes(PAIR, P, y0, run=RunSettings(transient=30.0, samples=3),
                              t0=t0, transient_max=np.array([60.0, 60.0, 90.0])),
            lambda: run_lanes(PAIR, P, y0, run=RunSettings(transient=30.0, samples=3),
                              lanes=LaneSettings(t0=t0, transient_max=[60.0, 60.0, 90.0])),
            "t0=, transient_max=",
            "lanes=geardyn.core.LaneSettings(t0=<3 values>, transient_max=<3 values>)"),
    }


@pytest.mark.parametrize("case", ["positional", "per lane", "convergence", "all positional",
                                  "beside run"])
def test_old_arguments_warn_once_and_give_the_same_lanes(case):
    old, new, keywords, replacement = _calls()[case]
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        a = old()
        again = old()  # the same deprecation again: no second warning in this process
    (w,) = _deprecations(record)
    assert str(w.message) == f"run_lanes({keywords}) is deprecated: pass {replacement}"
    assert w.filename == __file__  # points at the caller
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new spelling warns nothing
        b = new()
    _bitwise(a, b)
    _bitwise(again, b)
    assert np.all(b.status == geardyn.Status.OK)


def test_the_per_lane_values_reach_the_lanes():
    """Each lane of one call with per-lane values equals a lone lane run with those values as
    the run's own settings (so the values are not just accepted but used, lane by lane)."""
    P = PAIR.lane_params("Omega", OMEGAS)
    y0 = PAIR.initial_state()
    transient, steps = np.array([20.0, 35.0, 50.0]), np.array([64, 80, 96])
    r = run_lanes(PAIR, P, y0, run=RunSettings(samples=3),
                  lanes=LaneSettings(transient=transient, steps_per_period=steps))
    assert r.steps_per_period.tolist() == steps.tolist()
    for j in range(OMEGAS.size):
        one = run_lanes(PAIR, P[j:j + 1], y0, run=RunSettings(
            samples=3, transient=float(transient[j]), steps_per_period=int(steps[j])))
        np.testing.assert_array_equal(r.samples[j], one.samples[0])
        assert r.transient_periods[j] == math.ceil(transient[j] * OMEGAS[j] / (2 * math.pi))


@pytest.mark.parametrize(("fields", "message"), [
    ({"transient": [1.0, -2.0]}, r"transient must be a finite time >= 0 in every lane"),
    ({"transient_max": np.inf}, r"transient_max must be a finite time >= 0"),
    ({"t0": [0.0, np.nan]}, r"t0 must be finite in every lane"),
    ({"steps_per_period": [64, 3]}, r"steps_per_period must be >= 4 \(got 3\)"),
    ({"sample_every": 0}, r"sample_every must be >= 1 \(got 0\)"),
    ({"sample_every": "every"}, r"sample_every must be 'auto' or >= 1"),
    ({"transient": [[1.0]]}, r"transient must be one value or one per lane"),
])
def test_lane_settings_are_checked_where_they_enter(fields, message):
    with pytest.raises(ValueError, match=message):
        LaneSettings(**fields)


def test_lane_settings_are_frozen_copies_and_their_length_is_checked():
    t0 = np.zeros(3)
    lanes = LaneSettings(t0=t0)
    t0[0] = 5.0  # the caller's array is not the settings'
    assert lanes.t0.tolist() == [0.0, 0.0, 0.0] and not lanes.t0.flags.writeable
    with pytest.raises(AttributeError):
        lanes.t0 = None
    P = PAIR.lane_params("Omega", OMEGAS[:2])
    with pytest.raises(ValueError, match=r"t0 must have one value per lane \(2\), got 3"):
        LanePlan.build(PAIR, P, RunSettings(), lanes)


def test_both_spellings_at_once_are_errors():
    P = PAIR.lane_params("Omega", OMEGAS)
    y0 = PAIR.initial_state()
    with pytest.raises(TypeError, match=r"not both \(got run= and samples=\)"):
        run_lanes(PAIR, P, y0, samples=3, run=RunSettings())
    with pytest.raises(TypeError, match=r"not both \(got lanes= and t0=\)"):
        run_lanes(PAIR, P, y0, t0=np.zeros(3), lanes=LaneSettings())
    with pytest.raises(TypeError, match="unexpected keyword argument 'sample'"):
        run_lanes(PAIR, P, y0, sample=3)
    with pytest.raises(TypeError, match="multiple values for argument 'transient'"):
        run_lanes(PAIR, P, y0, 30.0, transient=30.0)
    with pytest.raises(TypeError, match=r"takes its settings as keywords: .*run=RunSettings"):
        run_lanes(PAIR, P, y0, RunSettings())
    with pytest.raises(TypeError, match="run must be a RunSettings"):
        run_lanes(PAIR, P, y0, run={"samples": 3})


def test_lane_plan_keywords_warn_once():
    """LanePlan.build's per-lane keywords: the same plan as LaneSettings, one warning."""
    P = PAIR.lane_params("Omega", OMEGAS)
    run = RunSettings(transient=30.0, samples=3)
    new = LanePlan.build(PAIR, P, run, LaneSettings(steps_per_period=[64, 0, 96],
                                                    sample_every=1))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for _ in range(2):
            old = LanePlan.build(PAIR, P, run, steps_per_period=np.array([64, 0, 96]),
                                 sample_every=1)
    (w,) = _deprecations(record)
    assert str(w.message) == ("LanePlan.build(steps_per_period=, sample_every=) is deprecated: "
                              "pass lanes=geardyn.core.LaneSettings(steps_per_period=<3 values>, "
                              "sample_every=1)")
    assert w.filename == __file__
    for name in ("steps_per_period", "step", "transient_periods", "transient_max_periods",
                 "sample_every", "t0"):
        np.testing.assert_array_equal(getattr(old, name), getattr(new, name), err_msg=name)
    with pytest.raises(TypeError, match="not both"):
        LanePlan.build(PAIR, P, run, LaneSettings(), t0=np.zeros(3))


# ------------------------------------------------------------------ simulate and lyapunov
@pytest.mark.parametrize("omega", [0.45, 0.92, 1.7])
def test_simulate_is_the_sweeps_lane_planned_without_the_ladder(omega):
    """simulate plans its run as a one-lane LanePlan (the step rule's own count): its
    Poincare points are bitwise the sweep's lane with ladder=False, and its step counts those
    of the plan; the sweep's default (the ladder) rounds the same rule up."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
    run = RunSettings(transient=37.0, samples=6)
    ds = geardyn.simulate(g, omega, run)
    P = g.lane_params("Omega", [omega])
    plan = LanePlan.build(g, P, run, LaneSettings(ladder=False, sample_every=1))
    n = geardyn.default_steps_per_period(g, omega)
    assert ds.attrs["steps_per_period"] == plan.steps_per_period[0] == n
    assert ds.attrs["step"] == plan.step[0] == 2 * math.pi / omega / n
    assert ds.attrs["transient_periods"] == plan.transient_periods[0] == math.ceil(
        37.0 * omega / (2 * math.pi))
    lane = run_lanes(g, P, g.initial_state(), run=run,
                     lanes=LaneSettings(ladder=False, sample_every=1))
    np.testing.assert_array_equal(lane.samples[0], ds["poincare"].values[1:])
    np.testing.assert_array_equal(lane.final[0], ds["poincare"].values[-1])
    laddered = LanePlan.build(g, P, run, LaneSettings(sample_every=1))
    assert laddered.steps_per_period[0] >= n


def test_autonomous_lanes_take_an_interval():
    """An unforced lane (interval in place of the forcing period): the step is the interval
    over the steps, the transient whole intervals; sample_every and too few steps refused."""
    lor = lorenz_model()
    run = RunSettings(transient=1.0, samples=4)
    plan = LanePlan.build(lor, lor.params[None], run, LaneSettings(interval=0.37, ladder=False))
    assert plan.omega.tolist() == [0.0] and plan.period.tolist() == [0.37]
    assert plan.steps_per_period.tolist() == [64]  # the rule's floor: no forcing, no modes
    assert plan.step[0] == 0.37 / 64 and plan.transient_periods.tolist() == [3]
    ds = geardyn.simulate(lor, run=run, sample_interval=0.37)
    assert ds.attrs["step"] == plan.step[0] and ds.attrs["transient_periods"] == 3
    one = LanePlan.build(lor, lor.params[None], run, LaneSettings(interval=0.01,
                                                                 steps_per_period=1))
    assert one.transient_steps.tolist() == [100] and one.window_steps(0.5).tolist() == [50]
    with pytest.raises(ValueError, match="sample_every applies to forced lanes"):
        LaneSettings(interval=0.1, sample_every=2)
    with pytest.raises(ValueError, match=r"steps_per_period must be >= 4 \(got 1\)"):
        LaneSettings(steps_per_period=1)
    with pytest.raises(ValueError, match="interval must be a finite time > 0"):
        LaneSettings(interval=0.0)


def test_lyapunov_is_the_lanes_exponent_on_the_same_plan():
    """lyapunov's one lane and lyapunov_lanes' lane agree when both plan the same steps: the
    single run's default (the rule's count) given to the lanes as the run's steps."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
    ls = geardyn.LyapunovSettings(duration=120.0, n_blocks=4)
    omega = 0.92
    n = geardyn.default_steps_per_period(g, omega)
    one = geardyn.lyapunov(g.with_omega(omega), run=RunSettings(transient=40.0), settings=ls,
                           with_error=True)
    lanes = geardyn.lyapunov_lanes(g, g.lane_params("Omega", [omega]),
                                   run=RunSettings(transient=40.0, steps_per_period=n),
                                   settings=ls, with_status=True)
    np.testing.assert_allclose(lanes[0][0], one.value, rtol=1e-12, atol=1e-14)
    assert lanes[3][0] == one.status



def test_every_deprecated_keyword_warns_once_per_process():
    """warn_deprecated serves every deprecated keyword (simulate's here): the first call
    warns, the same keywords again do not (other values alike), other keywords do; after
    forget_deprecations (what tests/conftest.py does before each test) it warns again."""
    from geardyn.core.moved import forget_deprecations

    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        geardyn.simulate(g, 0.8, periods=2, steps_per_period=64)
        geardyn.simulate(g, 0.9, periods=3, steps_per_period=64)
        geardyn.simulate(g, 0.8, periods=2)
        forget_deprecations()
        geardyn.simulate(g, 0.8, periods=2)
    assert [str(w.message).split(" is ")[0] for w in _deprecations(record)] == [
        "simulate(periods=, steps_per_period=)", "simulate(periods=)", "simulate(periods=)"]
