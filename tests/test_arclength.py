"""geardyn.analysis.arclength: the generic pseudo-arclength follower, on curves known in closed
form (no kernel compiled)."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.analysis.arclength import (
    ArclengthSettings,
    CurveFailure,
    CurvePoint,
    OutsideDomain,
    follow,
    start,
    tangent,
)
from geardyn.analysis.branch_data import BranchStatus


def _circle(z, jacobian):
    """x^2 + y^2 = 1: a curve that turns in both coordinates."""
    r = np.array([z[0] ** 2 + z[1] ** 2 - 1.0])
    return r, (np.array([[2 * z[0], 2 * z[1]]]) if jacobian else None), None


def _calls(fn):
    count = [0]

    def wrapped(z, jacobian):
        count[0] += 1
        return fn(z, jacobian)
    return wrapped, count


def test_the_circle_is_followed_round_its_turning_points():
    st = ArclengthSettings(ds=0.05, ds_max=0.1, max_points=400, tol=1e-12)
    first = start(_circle, np.array([1.05, 0.0]), np.array([0.0, 1.0]), st)
    assert isinstance(first, CurvePoint)
    assert first.z == pytest.approx([1.0, 0.0], abs=1e-10)
    assert first.tangent == pytest.approx([0.0, 1.0], abs=1e-10)

    def once_round(prev, new):  # back across the start from below
        return "round" if prev.z[1] < 0 <= new.z[1] and new.z[0] > 0 else None

    run = follow(_circle, first, st, stop=once_round)
    assert run.status == BranchStatus.COMPLETED and run.message == "round"
    z = np.array([p.z for p in run.points])
    assert np.max(np.abs(np.hypot(z[:, 0], z[:, 1]) - 1.0)) < 1e-10
    angle = np.unwrap(np.arctan2(z[:, 1], z[:, 0]))
    assert np.all(np.diff(angle) > 0)  # one way round, through x = -1 (a turn in y) and y = +-1
    assert angle[-1] - angle[0] == pytest.approx(2 * np.pi, abs=0.2)


def test_tangent_is_the_oriented_null_vector():
    J = np.array([[1.0, 2.0, 0.0], [0.0, 1.0, -1.0]])
    t = tangent(J, np.array([-1.0, 0.0, 0.0]))
    assert J @ t == pytest.approx([0.0, 0.0], abs=1e-14)
    assert np.linalg.norm(t) == pytest.approx(1.0) and t[0] < 0


def test_the_step_grows_on_an_easy_curve_and_the_run_stops_at_max_points():
    line, count = _calls(lambda z, j: (np.array([z[1] - 2 * z[0]]),
                                       np.array([[-2.0, 1.0]]) if j else None, None))
    st = ArclengthSettings(ds=0.01, ds_max=0.5, max_points=12)
    first = start(line, np.zeros(2), np.array([1.0, 2.0]), st)
    run = follow(line, first, st)
    assert run.status == BranchStatus.MAX_POINTS and len(run.points) == 12
    steps = np.linalg.norm(np.diff([p.z for p in run.points], axis=0), axis=1)
    assert steps[-1] == pytest.approx(0.5) and steps[0] == pytest.approx(0.01)


def test_leaving_the_domain_ends_the_curve_with_its_status_and_place():
    def bounded(z, jacobian):
        if z[0] > 0.5:
            raise OutsideDomain(f"x={z[0]:.3g} > 0.5")
        return _circle(z, jacobian)

    st = ArclengthSettings(ds=0.05, ds_max=0.1, max_points=400, ds_min=1e-4)
    first = start(bounded, np.array([0.0, 1.0]), np.array([1.0, 0.0]), st)
    run = follow(bounded, first, st, where=lambda z: f"x={z[0]:.4f}")
    assert run.status == BranchStatus.INVALID
    assert "> 0.5" in run.message and "the curve ends at x=0.4" in run.message
    assert max(p.z[0] for p in run.points) <= 0.5


def test_a_start_that_does_not_converge_is_a_failure_not_an_exception():
    def nowhere(z, jacobian):  # x^2 + 1 = 0 has no real root
        return np.array([z[0] ** 2 + 1.0]), np.array([[2 * z[0], 0.0]]) if jacobian else None, None

    got = start(nowhere, np.array([0.3, 0.0]), np.array([0.0, 1.0]), ArclengthSettings())
    assert isinstance(got, CurveFailure) and got.status in (BranchStatus.NOT_CONVERGED,)


@pytest.mark.parametrize("field,value", [("ds", -1.0), ("tol", float("nan")),
                                         ("max_points", 0)])
def test_bad_settings_name_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        ArclengthSettings(**{field: value})
