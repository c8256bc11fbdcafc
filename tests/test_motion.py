"""Motion classes against the exponent's uncertainty (geardyn.analysis.motion)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.analysis.lyapunov import lyapunov
from geardyn.analysis.motion import (
    LYAPUNOV_FLOOR,
    LYAPUNOV_Z,
    exponent_sign,
    lyapunov_uncertainty,
    motion_classes,
)
from geardyn.reproduction.motion import is_nonperiodic
from shared_models import oscillator as shared_oscillator


def block_exponent(model, y0, block: float, n: int) -> tuple[float, float, float]:
    """Largest exponent over n blocks of ``block`` time from y0 (after 100 of alignment), its
    standard error from the spread of the block means, and the averaging time n * block.

    The block means come from one trajectory: the kernel is deterministic, so the exponent over
    j blocks times j * block is the log stretch up to the end of block j."""
    logs = [0.0] + [lyapunov(model, y0=y0, run=geardyn.RunSettings(transient=100.0),
                             settings=geardyn.LyapunovSettings(duration=j * block)) * j * block
                    for j in range(1, n + 1)]
    means = np.diff(logs) / block
    return logs[-1] / (n * block), float(means.std(ddof=1) / math.sqrt(n)), n * block


def settled(model, omega: float, max_period: int = 16, transient: float = 600.0):
    ds = geardyn.bifurcation(model, "Omega", [omega],
                             run=geardyn.RunSettings(transient=transient, samples=64,
                                                     max_period=max_period))
    return int(ds["period"].values[0]), ds["poincare"].values[0, -1]


# --------------------------------------------------------------------------- the rule
def test_uncertainty_is_the_larger_of_error_and_floor():
    u = lyapunov_uncertainty(np.array([1e-4, 1e-2, np.nan]), 1000.0)
    assert u == pytest.approx([LYAPUNOV_FLOOR / 1000.0, LYAPUNOV_Z * 1e-2, LYAPUNOV_FLOOR / 1e3])
    assert np.all(lyapunov_uncertainty(None, np.array([100.0, 1000.0]))
                  == LYAPUNOV_FLOOR / np.array([100.0, 1000.0]))
    with pytest.raises(ValueError, match="duration"):
        lyapunov_uncertainty(1e-3, 0.0)


def test_labels_from_period_exponent_and_error():
    period = np.array([2, -1, 0, 0, 0, 0, 0, 0, 0])
    lam = np.array([np.nan, np.nan, np.nan, 0.02, 0.004, -0.004, -0.02, -0.02, 0.02])
    err = np.array([np.nan, np.nan, np.nan, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-2])
    section = np.array([True] * 7 + [False, True])
    labels = motion_classes(period, lam, err, 1000.0, section)  # u = max(3 err, 5e-3)
    assert list(labels) == ["period-2", "unbounded", "non-periodic", "chaotic", "quasi-periodic",
                            "quasi-periodic", "unresolved", "quasi-periodic", "quasi-periodic"]
    # a short average widens the band: -0.02 over 200 is not clearly negative (floor 0.025)
    assert motion_classes(period[6:7], lam[6:7], err[6:7], 200.0)[0] == "quasi-periodic"
    assert list(exponent_sign(lam[3:7], err[3:7], 1000.0)) == [1, 0, 0, -1]
    assert is_nonperiodic(labels).tolist() == [False, False] + [True] * 7


# --------------------------------------------------------------------------- real motions
@pytest.fixture(scope="module")
def oscillator():
    # x'' + (2 zeta - mu (1 - x^2)) x' + x = F cos(Omega t) + G cos(Omega t / q): van der Pol
    # (zeta = 0, G = 0) or a damped linear oscillator with a subharmonic forcing (mu = 0)
    return shared_oscillator(zeta=0.0, mu=0.5, F=0.2, G=0.0, q=1.0, Omega=math.sqrt(2.0))


def test_torus_is_quasi_periodic(oscillator):
    """Forced van der Pol off every low-order locking tongue: a torus, whose neutral direction
    (along the limit cycle) gives a zero exponent."""
    model = oscillator
    period, y = settled(model, math.sqrt(2.0), max_period=64, transient=1000.0)
    assert period == 0  # no period <= 64: no low-order locking
    lam, err, duration = block_exponent(model, y, 40 * 2 * math.pi / math.sqrt(2.0), 8)
    assert abs(lam) < 0.1 * LYAPUNOV_FLOOR / duration  # zero, well inside the band
    assert motion_classes(np.array([period]), lam, err, duration)[0] == "quasi-periodic"


def test_long_period_is_unresolved_not_quasi_periodic(oscillator):
    """A damped linear oscillator forced at Omega and Omega / 20: a period-20 orbit (the
    classifier finds it with max_period 24) with the exponent -zeta (linear: exact)."""
    zeta, q, omega = 0.05, 20, 1.3
    model = oscillator.with_params(zeta=zeta, mu=0.0, F=0.5, G=0.5, q=q, Omega=omega)
    assert settled(model, omega, max_period=24, transient=1000.0)[0] == q
    period, y = settled(model, omega, transient=1000.0)
    assert period == 0
    lam, err, duration = block_exponent(model, y, 2 * q * 2 * math.pi / omega, 8)
    assert lam == pytest.approx(-zeta, rel=1e-3)
    assert motion_classes(np.array([period]), lam, err, duration)[0] == "unresolved"


def test_chaotic_gear_pair_is_chaotic():
    """tests/test_lyapunov.py shows this gear pair chaotic by the divergence of nearby
    trajectories."""
    omega = 0.92
    model = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3, Omega=omega)
    period, y = settled(model, omega, transient=500.0)
    assert period == 0
    lam, err, duration = block_exponent(model, y, 20 * 2 * math.pi / omega, 8)
    assert lam > 0.05
    assert motion_classes(np.array([period]), lam, err, duration)[0] == "chaotic"


def test_the_retired_chaos_threshold_warns_once_and_keeps_its_value():
    """``geardyn.reproduction.motion.LYAPUNOV_CHAOS`` (no label uses it) answers with its
    former value and one DeprecationWarning saying why."""
    import warnings

    import geardyn.reproduction.motion as rm

    with pytest.warns(DeprecationWarning, match="LYAPUNOV_CHAOS is deprecated: no label"):
        assert rm.LYAPUNOV_CHAOS == 2.0e-3
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert rm.LYAPUNOV_CHAOS == 2.0e-3  # warned once
    with pytest.raises(AttributeError, match="no attribute 'LYAPUNOV_CHAOTIC'"):
        rm.LYAPUNOV_CHAOTIC  # noqa: B018
