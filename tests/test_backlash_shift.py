"""A change of backlash is a shift of the coordinate while the back flanks never touch.

The dead zone g(X, b) = X - b for X > -b, and the viscous mesh force does not depend on b, so
as long as X > -b the CATT equations depend on X - b only: the motion at backlash b2 from the
initial state shifted by b2 - b1 is the motion at b1 shifted, to round-off. This is why the
reproduction report marks the backlash claims (C14-C18) "by construction". The identity must
break as soon as the back flanks touch: then b enters the force on its own.
"""

from __future__ import annotations

import numpy as np

import geardyn
from geardyn import CATTDevice, PlanetaryParams
from geardyn.reproduction.evidence import back_flank_contact

#: Fig. 4's parameters (xi1 = xi2 = 0.1, E = 10 um); the paper's backlash is 50 um, b_c 10 um.
PARAMS = PlanetaryParams.paper(xi=0.1)
B_C = 10e-6


def _pair(b2: float) -> tuple[CATTDevice, CATTDevice, np.ndarray]:
    """The device at b = 50 um and at ``b2``, and the shift of the state [b_c] between them."""
    m1 = CATTDevice(PARAMS.replace(backlash=50e-6), "consistent")
    m2 = CATTDevice(PARAMS.replace(backlash=b2), "consistent")
    d = (50e-6 - b2) / B_C
    return m1, m2, np.array([d, 0.0, d, 0.0])


def _history(m: CATTDevice, omega: float, y0: np.ndarray, periods: int) -> np.ndarray:
    ds = geardyn.simulate(m, omega=omega,
                          run=geardyn.RunSettings(transient=0.0, samples=periods), y0=y0)
    assert ds.attrs["status"] == 0
    return np.stack([ds[s].values for s in m.state_names], axis=1)


def test_backlash_change_is_a_coordinate_shift_without_back_flank_contact():
    m1, m2, shift = _pair(30e-6)  # Figs. 4 and 9
    # the quasi-static initial states are shifted alike
    np.testing.assert_allclose(m2.initial_state(), m1.initial_state() - shift, atol=1e-12)
    for omega in (1.0, 1.6):
        y1 = _history(m1, omega, m1.initial_state(), 150)
        y2 = _history(m2, omega, m1.initial_state() - shift, 150)
        # the teeth separate (the dead zone matters) but the back flanks never touch
        assert np.min(y1[:, 0] - 5.0) < -1.0 and np.min(y2[:, 0] + 3.0) > 0.0
        assert np.min(y2[:, 2] + 3.0) > 0.0
        assert np.max(np.abs((y1 - shift) - y2)) < 1e-11, omega


def test_the_shift_fails_once_the_back_flanks_touch():
    m1, m2, shift = _pair(20e-6)  # the back flank 4 b_c behind the drive flank, not 10
    y1 = _history(m1, 2.0, m1.initial_state(), 20)
    y2 = _history(m2, 2.0, m1.initial_state() - shift, 20)
    touch = (y2[:, 0] + 2.0 < 0.0) | (y2[:, 2] + 2.0 < 0.0)
    assert touch.any() and np.all(y1[:, 0] + 5.0 > 0.0)  # b = 20 um only touches
    first = int(np.argmax(touch))
    diff = np.max(np.abs((y1 - shift) - y2), axis=1)
    assert np.max(diff[:first]) < 1e-11  # the same motion up to the first back-flank contact
    assert np.max(diff[first:]) > 0.1  # then another one


def test_sweep_data_show_where_the_shift_holds():
    """The check the report makes on case data: the back-flank contact read from a sweep's
    contact regimes marks exactly the point where the shifted sweeps differ."""
    m1, m2, shift = _pair(20e-6)
    values = np.array([1.6, 2.0])
    # no transient: the sampled stretch holds the first back-flank contact at Omega = 2
    ds1 = geardyn.bifurcation(m1, "Omega", values,
                              run=geardyn.RunSettings(transient=0.0, samples=16))
    ds2 = geardyn.bifurcation(m2, "Omega", values,
                              run=geardyn.RunSettings(transient=0.0, samples=16),
                              y0=m1.initial_state() - shift)
    assert list(back_flank_contact(ds1)) == [False, False]
    assert list(back_flank_contact(ds2)) == [False, True]
    diff = np.max(np.abs(ds1["poincare"].values - shift - ds2["poincare"].values), axis=(1, 2))
    assert diff[0] < 1e-11 and diff[1] > 1e-3
