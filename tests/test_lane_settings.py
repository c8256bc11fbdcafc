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
