"""The Lyapunov kernel on lane blocks (rows of many lanes in one structure-of-arrays block)
against the tests' one-lane reference (``tests/_lyapunov_rows.py``: the model's scalar steps one
lane at a time): exponents, errors, blocks, status and counts bitwise equal."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from _lyapunov_rows import reference_for, rows_for
from geardyn.analysis import lyapunov as lyap_mod
from geardyn.solvers.kernels import kernels_for
from shared_models import lorenz_rhs as _lorenz  # one Lorenz kernel for the tests

#: Gear pair lanes: chaotic, period-1 with contact loss (two edge crossings per period).
CHAOTIC = dict(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
IMPACTING = dict(zeta=0.1, kappa=0.2, Fm=0.1, Fa=0.15)


def paper_device(**kw) -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05), **kw)


def _lanes(model, omegas, n_per, periods_tr, periods_st, y0, t0):
    """Kernel arguments for lanes with n_per steps per period (one for all or one per lane) and
    their own step counts; the last entry: n_per per lane."""
    n_per = np.broadcast_to(np.asarray(n_per, np.int64), omegas.shape).copy()
    P = np.ascontiguousarray(model.lane_params("Omega", omegas))
    H = 2.0 * np.pi / omegas / n_per
    n_tr = np.asarray(periods_tr, np.int64) * n_per
    n_st = np.asarray(periods_st, np.int64) * n_per
    # a writable copy: a read-only Y0 (np.broadcast_to of a full array) would compile the
    # one-lane kernel once more for that argument type
    Y0 = np.array(np.broadcast_to(y0, (omegas.size, model.n_states)), dtype=float, order="C")
    T0 = np.ascontiguousarray(t0, dtype=float)
    return P, Y0, T0, H, np.ascontiguousarray(omegas, dtype=float), n_tr, n_st, n_per


def _reference(kern, model, args, renorm, k, bound=1e6, variational=False):
    """Each lane through the tests' one-lane reference (``reference_for(kern).lyapunov_single``):
    (exponents, errors, blocks, status, unresolved, steps by the difference rows)."""
    P, Y0, T0, H, OM, n_tr, n_st, n_per = args
    scale = np.ones(model.n_states)
    single = reference_for(kern).lyapunov_single
    res = [single(P[i], Y0[i], scale, float(T0[i]), float(H[i]), float(OM[i]), int(n_per[i]),
                  int(n_tr[i]), int(n_st[i]), renorm, k, float(bound), model.n_events, 16,
                  bool(variational))
           for i in range(len(P))]
    return (np.array([r[0] for r in res]), np.array([r[1] for r in res]),
            np.array([r[2] for r in res]), np.array([r[3] for r in res]),
            np.array([r[4] for r in res]), np.array([r[5] for r in res]))


def _blocks(kern, model, args, renorm, k, block_rows, n_ev=None, bound=1e6, variational=False):
    P, Y0, T0, H, OM, n_tr, n_st, n_per = args
    L = len(P)
    out, err = np.full((L, k), -1.0), np.full((L, k), -1.0)
    used, status = np.full(L, -1, np.int64), np.full(L, -1, np.int64)
    unres, fd = np.full(L, -1, np.int64), np.full(L, -1, np.int64)
    kern.lyapunov_block_lanes(P, Y0, np.ones(model.n_states), T0, H, OM, n_per, n_tr, n_st,
                              renorm, k, bound, out, err, used, status, unres,
                              model.n_events if n_ev is None else n_ev, 16, block_rows, 2,
                              variational, fd)
    return out, err, used, status, unres, fd


def _assert_bitwise(got, ref):
    for g, r in zip(got, ref, strict=True):
        assert np.array_equal(g, r, equal_nan=True), (g, r)


@pytest.mark.parametrize(("k", "load", "variational"),
                         [(1, False, True), (4, False, False), (1, True, True),
                          (4, False, True)])
def test_catt_blocks_bitwise_equal_to_one_lane_kernel(k, load, variational):
    # the reduced paper device at Omegas with and without contact loss, lanes with their own
    # grid, transient, measuring window, start time and state; renorm 7 so that blocks of the
    # measuring window end between renormalisations. k = 1 runs the fused block (the model's
    # lane-scalar form: quiet, or with the load fluctuating) with the variational tangent (what
    # lyapunov() and lyapunov_lanes() run on this one-form model, whose kernels the warm-up
    # and the sweep's exponent test compile; the fused block of difference rows, the path of
    # ``tangent="difference"``, is the gear pair's test below, in FORM_QUIET), k = 4 the row
    # blocks; k = 4 with the variational tangent the spectrum of lyapunov(..., spectrum=True):
    # the variational block, a pass of its fused loop per tangent vector.
    model = (geardyn.CATTDevice(geardyn.PlanetaryParams.paper(
        xi1=0.05, xi2=0.05, B1="100 N m", B2="100 N m", Lambda=0.1)) if load
        else paper_device())
    assert model.n_events == 4
    kern = kernels_for(model.kernel, "lyapunov")
    assert hasattr(kern, "rhs_lanes")  # the model's lane-block functions are used
    assert kern.FUSED  # and its lane-scalar ones
    om = np.array([0.7, 1.05, 1.4, 1.8, 2.3, 2.9, 3.6])
    rng = np.random.default_rng(3)
    y0 = model.initial_state() + rng.uniform(-0.5, 0.5, (om.size, 4))
    # lanes of different grids share blocks (the kernel's per-row phase tables)
    args = _lanes(model, om, [48, 64, 48, 40, 64, 48, 56], [3, 0, 5, 2, 4, 1, 6],
                  [12, 9, 7, 16, 5, 11, 3], y0,
                  rng.uniform(0.0, 50.0, om.size))
    ref = _reference(kern, model, args, 7, k, variational=variational)
    assert np.all(ref[3] == 0) and np.all(np.isfinite(ref[0]))
    for rows in (64, 2 * k + 1, 1000):  # several lanes per block, one, all
        _assert_bitwise(_blocks(kern, model, args, 7, k, rows, variational=variational), ref)
    # edges matter in these lanes (contact is lost): without locating them the exponents differ
    plain = _blocks(kern, model, args, 7, k, 64, n_ev=0, variational=variational)
    assert not np.array_equal(plain[0], ref[0])
    # a lane that leaves the bound is marked diverged, the others untouched: lane 2 starts
    # far out (its first health check fails), the others stay within 50
    far = (args[0], args[1].copy(), *args[2:])
    far[1][2] *= 100.0
    ref = _reference(kern, model, far, 7, k, bound=50.0, variational=variational)
    assert ref[3][2] == 1 and np.all(np.delete(ref[3], 2) == 0), ref[3]
    _assert_bitwise(_blocks(kern, model, far, 7, k, 64, bound=50.0, variational=variational),
                    ref)


def test_gear_pair_blocks_bitwise_equal_with_a_diverged_lane():
    """The fused block of difference rows (k = 1, ``tangent="difference"``), in FORM_QUIET,
    with a diverged lane; the row blocks of k > 1 with a diverged lane: the reduced device's
    test above (k = 4, its ``far`` lanes)."""
    for kw in (CHAOTIC, IMPACTING):
        model = geardyn.GearPair(**kw)
        kern = kernels_for(model.kernel, "lyapunov")
        om = np.array([0.6, 0.92, 1.15, 1.3, 0.8])
        y0 = np.array([[0.5, 0.0], [1.2, 0.1], [1e9, 0.0], [0.9, -0.2], [1.5, 0.0]])
        args = _lanes(model, om, 32, [10, 20, 5, 0, 15], [40, 25, 30, 50, 20], y0,
                      [0.0, 3.0, 0.0, 7.5, 1.0])
        ref = _reference(kern, model, args, 10, 1)
        assert ref[3][2] == 1 and np.all(np.isnan(ref[0][2]))  # diverged
        for rows in (64, 5):
            _assert_bitwise(_blocks(kern, model, args, 10, 1, rows), ref)


def test_variational_spectrum_slots_bitwise_in_one_pass_and_several():
    # the variational block's slots are (lane, tangent vector) pairs: 40 lanes of k = 2 in one
    # block are 80 slots, more than a pass takes (64: two passes, the state committed by the
    # last), 12 lanes a block (24 slots, one pass), one lane a block (2 slots); a diverged lane
    # among them (its slots leave the pass with it)
    model = geardyn.GearPair(**IMPACTING)
    kern = kernels_for(model.kernel, "lyapunov")
    om = np.linspace(0.6, 2.2, 40)
    rng = np.random.default_rng(5)
    y0 = model.initial_state() + rng.uniform(-0.3, 0.3, (om.size, 2))
    y0[7] = [1e9, 0.0]
    args = _lanes(model, om, 32, rng.integers(0, 8, om.size), rng.integers(5, 20, om.size), y0,
                  rng.uniform(0.0, 5.0, om.size))
    ref = _reference(kern, model, args, 10, 2, variational=True)
    assert ref[3][7] == 1 and np.all(np.delete(ref[3], 7) == 0)
    assert np.all(np.isfinite(np.delete(ref[0], 7, axis=0)))
    for rows in (1000, 64, 5):
        _assert_bitwise(_blocks(kern, model, args, 10, 2, rows, variational=True), ref)


def test_generic_lane_path_general_catt_model():
    # the general CATT model has no lane-block functions: the rows are evaluated one by one
    model = paper_device(reduced=False)
    kern = kernels_for(model.kernel, "lyapunov")
    assert not hasattr(kern, "rhs_lanes")
    om = np.array([1.1, 1.6, 2.4])
    args = _lanes(model, om, 40, [2, 0, 3], [6, 8, 5], model.initial_state(), [0.0, 0.0, 2.0])
    ref = _reference(kern, model, args, 10, 1)
    _assert_bitwise(_blocks(kern, model, args, 10, 1, 64), ref)


def test_public_lanes_equal_one_lane_kernel(monkeypatch):
    # geardyn.lyapunov_lanes (lanes of several step ladders, an autonomous user model) against
    # the same call through the one-lane-at-a-time kernel
    cases = [(paper_device(), paper_device().lane_params("Omega", np.linspace(0.6, 3.0, 9)),
              dict(run=geardyn.RunSettings(transient=10.0),
                   settings=geardyn.LyapunovSettings(duration=40.0))),
             (geardyn.UserModel(_lorenz, n_states=3, params=np.array([10.0, 28.0, 8.0 / 3.0]),
                                period=None, state_names=["x", "y", "z"]),
              np.array([[10.0, 28.0, 8.0 / 3.0], [10.0, 0.5, 8.0 / 3.0]]),
              dict(y0=[1.0, 1.0, 1.0], run=geardyn.RunSettings(transient=2.0),
                   settings=geardyn.LyapunovSettings(duration=10.0)))]
    for model, P, run in cases:
        new = lyap_mod.lyapunov_lanes(model, P, with_error=True, **run)
        kern = kernels_for(model.kernel, "lyapunov")
        with monkeypatch.context() as mp:
            mp.setattr(kern, "lyapunov_lanes", rows_for(kern))
            old = lyap_mod.lyapunov_lanes(model, P, with_error=True, **run)
        _assert_bitwise(new, old)
        assert np.all(np.isfinite(new[0]))
    assert math.isfinite(new[0][0])


@pytest.mark.parametrize("waveform", ["sine", "rectangular"])
def test_lane_block_functions_take_a_phase_per_lane(waveform):
    # the reduced device's generated rhs_lanes / observe_lanes with S[k], C[k] per lane (25
    # stiffness harmonics for the rectangular waveform) against the general model's array
    # functions with one planet set
    from geardyn.models import catt_kernels as ck
    from geardyn.solvers.kernels import kernels_for

    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(waveform=waveform)).with_omega(0.9)
    gen = kernels_for(m.kernel, "core")
    nl, rng = 11, np.random.default_rng(0)
    PT = np.ascontiguousarray(np.tile(m.params[:, None], (1, nl)))
    Y, DY, O, SC = rng.uniform(-2, 2, (4, nl)), np.zeros((4, nl)), np.zeros((2, nl)), np.zeros(
        (8, nl))
    ph, T = rng.uniform(0, 2 * np.pi, nl), rng.uniform(0, 10, nl)
    S, C = np.sin(ph), np.cos(ph)
    gen.rhs_lanes(T, Y, DY, PT, nl, S, C, SC)
    gen.observe_lanes(T, Y, O, PT, nl, S, C, SC)
    for k in range(nl):
        dy, o = np.zeros(4), np.zeros(2)
        ck.catt_rhs(T[k], Y[:, k].copy(), dy, m.params, S[k], C[k])
        ck.catt_observe(T[k], Y[:, k].copy(), o, m.params, S[k], C[k])
        assert np.array_equal(dy, DY[:, k]) and np.array_equal(o, O[:, k])
