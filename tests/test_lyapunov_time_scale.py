"""The default Lyapunov duration scales with the model: 2000 time units of a dimensionless
model (its results bitwise those of an explicit ``duration=2000``), 200 forcing periods of a
model in seconds (``SpurPair``: 2000 s would be ~10^5-10^6 forcing periods, hours)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn import LyapunovSettings, RunSettings
from geardyn.analysis.lyapunov import lyapunov, lyapunov_lanes
from geardyn.core.settings import LYAPUNOV_PERIODS
from geardyn.io.toml import builtin_study
from geardyn.study import build_model


@pytest.fixture(scope="module")
def spur():
    return build_model(builtin_study("spur_pair_cracked"))


def test_spur_pair_default_is_200_forcing_periods(spur):
    period = 2.0 * math.pi / spur.omega  # one pinion revolution at 18000 rpm: 3.3 ms
    # the declared scale first: a model without it (the old default of 2000 s) fails here,
    # before a run of hours
    assert spur.lyapunov_duration() == (None, f"default: {LYAPUNOV_PERIODS} forcing periods")
    est = lyapunov(spur, with_error=True)
    assert LYAPUNOV_PERIODS == 200
    assert est.duration == pytest.approx(200 * period, rel=1e-12)
    assert est.duration_rule == "default: 200 forcing periods"
    # the same window given explicitly (199.5 periods round up to 200), the default transient
    # of 20 forcing periods too: the same bits
    explicit = lyapunov(spur, run=RunSettings(transient=19.5 * period),
                        settings=LyapunovSettings(duration=199.5 * period), with_error=True)
    assert explicit.value == est.value and explicit.stderr == est.stderr
    assert explicit.duration_rule == "LyapunovSettings.duration"
    # decays at about the damping rate zeta omega_n of the contact (period-1, in contact)
    rate = 0.05 * spur.natural_frequencies()[0]
    assert -1.5 * rate < est.value < -0.5 * rate


def test_spur_pair_lanes_default_to_each_lanes_periods(spur):
    """Two lanes at 14000 and 18000 rpm: each averages over 200 of its own periods, as with
    its own duration given."""
    P = spur.lane_params("speed", [14000.0, 18000.0])
    got = lyapunov_lanes(spur, P, run=RunSettings(transient=0.01), with_error=True)
    for k in range(2):
        T = 2.0 * math.pi / P[k, spur.omega_index]
        one = lyapunov_lanes(spur, P[k:k + 1], run=RunSettings(transient=0.01),
                             settings=LyapunovSettings(duration=199.5 * T), with_error=True)
        assert got[0][k] == one[0][0] and got[1][k] == one[1][0]


@pytest.mark.parametrize("omega", [0.92, 1.6])
def test_dimensionless_models_are_unchanged_bitwise(omega):
    """The gear pair (time unit 1 / omega_n): the default is 2000 time units, bitwise the
    result of main's default given explicitly (duration=2000), one lane and several."""
    gp = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3, Omega=omega)
    run = RunSettings(transient=100.0, steps_per_period=64)
    default = lyapunov(gp, run=run, with_error=True)
    given = lyapunov(gp, run=run, settings=LyapunovSettings(duration=2000.0), with_error=True)
    assert default.value == given.value and default.stderr == given.stderr
    assert default.duration_rule == "default: 2000 time units"
    periods = math.ceil(2000.0 / (2 * math.pi / omega) - 1e-9)
    assert default.duration == pytest.approx(periods * 2 * math.pi / omega, rel=1e-12)
    no_run = lyapunov(gp)  # the default transient of 100 time units as before
    assert no_run == lyapunov(gp, run=RunSettings(transient=100.0),
                              settings=LyapunovSettings(duration=2000.0))
    P = gp.lane_params("Omega", [omega, omega * 1.1])
    a = lyapunov_lanes(gp, P, run=run, with_error=True)
    b = lyapunov_lanes(gp, P, run=run, settings=LyapunovSettings(duration=2000.0),
                       with_error=True)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
