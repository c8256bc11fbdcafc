"""One forcing phase for a continued sweep's every term: a point of a sweep by continuation
(a chained lane, started at the previous point's end time) is the same computation as a run of
its own from the state it started from, at forcing phase 0. The right-hand side, the switching
functions (whose zeros the solver locates) and a torque fluctuation of integer order all take
the mesh phase the solver supplies (0 at a lane's start); only a second, incommensurate
excitation reads the time, and the models here have none. So the continued points and the
independent runs agree bit for bit: samples, crossings and contact regime at every point.

Also: the planetary frequency response reports the DTE in the unit of its length scale
(1 um by default), the scale in the attributes, checked against the static mesh deflection
b + F / k computed here from the static mesh forces.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.analysis.contact import contact_regime
from geardyn.solvers.ensemble import run_lanes

M = geardyn.Member
A = 24.6 * math.pi / 180
SUN_K = 5e8  # N/m, both meshes
BACKLASH = 10e-6  # m


def _planetary(**kw) -> geardyn.PlanetaryGearSet:
    """Three unequally spaced planets, balanced torques (tests/test_planetary.py's set)."""
    args = dict(n_planets=3, sun_pressure_angle=A, ring_pressure_angle=A,
                sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
                carrier=M(5.43, 6.29, 1e8, 0.0, radius=0.08), planet=M(0.66, 0.61, 1e8),
                sun_mesh_stiffness=SUN_K, ring_mesh_stiffness=SUN_K,
                planet_angles=["0 deg", "110 deg", "235 deg"], sun_torque=100.0,
                carrier_torque=-2 * math.cos(A) * 100 / 0.03 * 0.08, sun_backlash=BACKLASH,
                ring_backlash=BACKLASH, modal_damping=0.02,
                mesh_frequency=2 * math.pi * 1500)
    args.update(kw)
    return geardyn.PlanetaryGearSet(**args)


def _regimes(model: geardyn.Model, r) -> np.ndarray:
    """Contact regime (lanes x meshes) of run_lanes results."""
    return np.stack([contact_regime(r.event_min, r.event_max, r.crossings, d, b, r.status)
                     for _, d, b in model.meshes], axis=1)


def _continued_against_single(model: geardyn.Model, omegas: np.ndarray, y0: np.ndarray,
                              periods: float) -> tuple:
    """A sweep by continuation over ``omegas`` (a chain of lanes), and each of its points after
    the first run on its own from the state the point started from (the previous point's
    final state) at phase 0; both with the same transient (``periods`` of the first point)."""
    P = model.lane_params("Omega", omegas)
    kw = {"run": geardyn.RunSettings(transient=periods * 2 * math.pi / omegas[0], samples=4,
                                     locate_edges=True, steps_per_period=256)}
    L = omegas.size
    chained = run_lanes(model, P, y0, chain=np.r_[np.arange(1, L), -1], **kw)
    assert np.all(chained.status == geardyn.Status.OK)
    assert np.all(chained.final_time[1:] > chained.final_time[0])  # continued in time
    single = run_lanes(model, P[1:], chained.final[:-1], **kw)  # unchained, from t = 0
    assert np.all(single.status == geardyn.Status.OK)
    return chained.take(slice(1, None)), single


def _assert_same_points(model, cont, single) -> None:
    assert np.sum(single.crossings) > 0  # contact is lost: the located edges matter
    np.testing.assert_array_equal(cont.crossings, single.crossings)
    np.testing.assert_array_equal(_regimes(model, cont), _regimes(model, single))
    np.testing.assert_array_equal(cont.samples, single.samples)
    np.testing.assert_array_equal(cont.event_min, single.event_min)
    np.testing.assert_array_equal(cont.event_max, single.event_max)


def test_dimensional_catt_continued_points_equal_single_runs():
    """DimensionalCATT, the paper's default: a 10 um meshing error against 50 um backlash; its
    switching functions carry the error at the mesh phase."""
    device = geardyn.CATTDevice(geardyn.PlanetaryParams.paper())
    dim = device.dimensional()
    wn = dim.omega / device.omega
    cont, single = _continued_against_single(dim, np.array([0.9, 1.0, 1.1, 1.2, 1.3]) * wn,
                                             dim.initial_state(), 30)
    _assert_same_points(dim, cont, single)


def test_planetary_mesh_error_continued_points_equal_single_runs():
    """A planetary set with a sun mesh error (15 um against 10 um backlash) and stiffness
    fluctuation: contact is lost and the edges move with the error's phase."""
    gs = _planetary(sun_mesh_error="15 um", ring_mesh_error="5 um",
                    sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
                    sun_mesh_phase=[0.0, 2.0, 4.0])
    cont, single = _continued_against_single(gs, gs.omega * np.array([0.9, 0.95, 1.0, 1.05]),
                                             gs.initial_state(), 20)
    _assert_same_points(gs, cont, single)


def test_planetary_integer_torque_order_is_locked_to_the_mesh():
    """A torque fluctuation of order 2 (no mesh error): its phase relative to the mesh is the
    same at every continued point as in a run of its own."""
    gs = _planetary(torque_fluctuation=0.8, torque_order=2, torque_phase=0.4,
                    sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
                    sun_mesh_phase=[0.0, 2.0, 4.0])
    cont, single = _continued_against_single(gs, gs.omega * np.array([0.9, 0.95, 1.0, 1.05]),
                                             gs.initial_state(), 20)
    np.testing.assert_array_equal(cont.samples, single.samples)
    np.testing.assert_array_equal(cont.crossings, single.crossings)
    np.testing.assert_array_equal(_regimes(gs, cont), _regimes(gs, single))


@pytest.mark.parametrize("scale", [1e-6, 1e-5])
def test_planetary_dte_carries_its_unit_and_scale(scale):
    """No excitation, full contact: the motion settles to the static equilibrium, where each
    mesh deflects by b + F / k (F the static mesh force). The DTE's unit and length scale
    convert the reported mean to metres; the RMS about it is zero."""
    gs = _planetary(length_scale=scale)
    ds = geardyn.frequency_response(gs, gs.omega * np.array([0.9, 1.1]),
                                    run=geardyn.RunSettings(transient=200.0, samples=2))
    expected = BACKLASH + np.abs(gs.static_mesh_forces()) / SUN_K  # m
    units = {1e-6: "um", 1e-5: "1e-05 m"}[scale]
    for name in ("dte_mean", "dte_rms", "dte_peak", "dte_amplitude", "dte_max"):
        assert ds[name].attrs["units"] == units
        assert ds[name].attrs["length_scale"] == scale
        assert ds[name].attrs["length_scale_units"] == "m"
    metres = np.abs(ds["dte_mean"].values) * ds["dte_mean"].attrs["length_scale"]
    np.testing.assert_allclose(metres, np.broadcast_to(expected, metres.shape), rtol=1e-6)
    assert np.all(ds["dte_rms"].values * scale < 1e-6 * BACKLASH)
