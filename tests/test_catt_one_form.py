"""The reduced CATT device in the one form (:mod:`geardyn.models.catt_reduced`): every
generated layout gives the bits of the general model's hand-written array form
(:func:`~geardyn.models.catt_kernels.catt_rhs` with one planet set); lanes with the load quiet
take FORM_QUIET (the load term compiled away), lanes with it fluctuating FORM_LOAD (no test of
the load), any number of stiffness harmonics; every lane's result is bitwise that of the
one-lane path (``simulate``) and of the general model's array functions run lane by lane."""

from __future__ import annotations

import copy
import math
import pickle

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import FORM_GENERAL, FORM_LOAD, FORM_QUIET, KernelSource
from geardyn.core.one_form import OneForm, coefficient_type, loud
from geardyn.core.plan import LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.models import catt_kernels as ck
from geardyn.models.catt_reduced import coefficient_names
from geardyn.models.elements import harmonic_factors
from geardyn.solvers.ensemble import run_lanes
from geardyn.solvers.kernels import kernels_for
from test_catt_lane_forms import _LOAD, _RECT, _device

_OMEGAS = np.array([0.7, 1.3, 2.2, 3.1, 0.45])


def _gen(model):
    """The model's generated functions (the kernels' shared core, compiled on first call)."""
    return kernels_for(model.kernel, "core")


def test_the_one_form_runs_the_general_models_array_functions_lanes_bitwise():
    """Quiet and fluctuating lanes in one sweep (edges located), through the one form's fused
    loop, against each lane through the general model's array functions (:func:`ck.catt_rhs`
    with one planet set: no lane forms; its one-lane trajectory kernel, which the general
    device's ``simulate`` runs): samples, final state and located crossings bit for bit."""
    omega = np.array([0.6, 1.3, 2.7])
    run = RunSettings(transient=200.0, samples=3, steps_per_period=48, locate_edges=True)
    quiet, load = _device(), _device(**_LOAD)
    generic = copy.copy(quiet)
    generic.kernel = KernelSource(ck.catt_rhs, ck.catt_events, ck.catt_observe)
    assert kernels_for(quiet.kernel).FUSED and not kernels_for(generic.kernel).FUSED
    P = np.vstack([quiet.lane_params("Omega", omega), load.lane_params("Omega", omega)])
    out = run_lanes(quiet, P, quiet.initial_state(), run=run, lanes=LaneSettings(sample_every=1))
    assert np.all(out.status == 0) and np.sum(out.crossings) > 0
    for j, m in enumerate([quiet] * omega.size + [load] * omega.size):
        lane = copy.copy(m)
        lane.kernel = generic.kernel
        ds = geardyn.simulate(lane, omega=float(omega[j % omega.size]), run=run)
        assert ds.attrs["status"] == geardyn.Status.OK
        np.testing.assert_array_equal(out.samples[j], ds["poincare"].values[1:], err_msg=str(j))
        np.testing.assert_array_equal(out.final[j], ds["poincare"].values[-1])
        np.testing.assert_array_equal(out.crossings[j], ds["edge_crossings"].values)


def test_one_form_keyword_is_deprecated_and_chooses_nothing():
    m = _device()
    with pytest.warns(DeprecationWarning, match="one_form"):
        old = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1), one_form=False)
    assert old.kernel == m.kernel and m.kernel.one_form is not None
    np.testing.assert_array_equal(old.params, m.params)
    with pytest.warns(DeprecationWarning, match="one_form"):
        assert m.one_form and not m.general().one_form


_DEVICES = {"quiet": {}, "load": _LOAD, "rectangular": _RECT,
            "rectangular-load": {**_RECT, **_LOAD},
            "load-outside-only": {"B1": "100 N m", "Lambda": 0.3, "psi1": 0.4}}


@pytest.mark.parametrize("case", list(_DEVICES))
def test_every_generated_layout_equals_the_general_models_array_form(case):
    """The reduced device's generated layouts (array, lane-scalar in its form and in the general
    form, lane block) against the general model's own array form :func:`ck.catt_rhs` for one
    planet set (written separately, with harmonic_factor's loop and the load's branch), bit for
    bit, at random states, times and mesh phases; the forces likewise."""
    m = _device(**_DEVICES[case]).with_omega(1.3)
    gen = _gen(m)
    p = m.params
    nl = 3
    PT = np.ascontiguousarray(np.tile(p[:, None], (1, nl)))
    form = gen.rhs_lane_form(PT, 0)
    rng = np.random.default_rng(7)
    T, ph = rng.uniform(0.0, 80.0, nl), rng.uniform(-3.0, 3.0, nl)
    S, C = np.sin(ph), np.cos(ph)
    Y = rng.normal(0.0, 3.0, (4, nl))
    DY, O, SC = np.zeros((4, nl)), np.zeros((2, nl)), np.zeros((4, nl))
    gen.rhs_lanes(T, Y, DY, PT, nl, S, C, SC)
    gen.observe_lanes(T, Y, O, PT, nl, S, C, SC)
    for k in range(nl):
        y = Y[:, k].copy()
        ref, oref, dy = np.empty(4), np.empty(2), np.empty(4)
        ck.catt_rhs(T[k], y, ref, p, S[k], C[k])
        ck.catt_observe(T[k], y, oref, p, S[k], C[k])
        gen.rhs(T[k], y, dy, p, S[k], C[k])
        for got in (dy, DY[:, k], gen.rhs_lane(T[k], tuple(y), PT, k, S[k], C[k], form),
                    gen.rhs_lane(T[k], tuple(y), PT, k, S[k], C[k], FORM_GENERAL)):
            np.testing.assert_array_equal(np.asarray(got), ref, err_msg=case)
        np.testing.assert_array_equal(O[:, k], oref)
        np.testing.assert_array_equal(np.asarray(
            gen.observe_lane(T[k], tuple(y), PT, k, S[k], C[k], form)), oref)


def test_a_stiffness_series_below_zero_is_clipped_in_every_layout():
    """Where a mesh's stiffness series rings below 0 (a raw first harmonic of 1.8, at the phase
    where its cosine is -1) the mesh carries no stiffness force, in every layout, as the general
    model's array form (harmonic_factor's clip) gives it: the bits of the same state with that
    mesh's stiffness coefficients 0."""
    m = _device().with_params(ksq_a1=1.8).with_omega(1.3)
    stiff0 = m.with_params(k_sq_q=0.0, k_sq_c=0.0)
    gen = _gen(m)
    p = m.params
    PT = np.ascontiguousarray(p[:, None])
    b_sq, b_pq = p[ck.HEADER + ck.B_SQ], p[ck.HEADER + ck.B_PQ]
    y = np.array([3.5 + b_sq, 0.1, -3.3 - b_pq, 0.2])  # both meshes in contact
    s, c = 0.0, -1.0
    ref, ref0, dy, DY = np.empty(4), np.empty(4), np.empty(4), np.empty((4, 1))
    ck.catt_rhs(0.3, y, ref, p, s, c)
    ck.catt_rhs(0.3, y, ref0, stiff0.params, s, c)
    np.testing.assert_array_equal(ref, ref0)
    gen.rhs(0.3, y, dy, p, s, c)
    gen.rhs_lanes(np.array([0.3]), np.ascontiguousarray(y[:, None]), DY, PT, 1, np.array([s]),
                  np.array([c]), np.zeros((4, 1)))
    for got in (dy, DY[:, 0], *(gen.rhs_lane(0.3, tuple(y), PT, 0, s, c, form)
                                for form in (FORM_QUIET, FORM_GENERAL))):
        np.testing.assert_array_equal(np.asarray(got), ref)


def _llvm_of_lane_call(gen, form):
    """The optimised LLVM IR of a function that calls the generated ``rhs_lane`` in ``form``."""
    rhs_lane = gen.rhs_lane

    @nb.njit
    def call(y, PT, s, c):
        return rhs_lane(0.1, y, PT, 0, s, c, form)

    P = np.ascontiguousarray(_device().lane_params("Omega", _OMEGAS[:1]).T)
    call((0.01, 0.0, -0.02, 0.0), P, 0.3, 0.9)
    return next(iter(call.inspect_llvm().values()))


def test_the_quiet_form_compiles_the_load_term_away():
    """A quiet lane's copy holds no load sine (its floor is the marker), the load and general
    ones do; the load's copy has no test of the load (``loud(p)`` a constant True there)."""
    gen = _gen(_device())
    quiet, load, general = (_llvm_of_lane_call(gen, f) for f in (FORM_QUIET, FORM_LOAD,
                                                                   FORM_GENERAL))
    assert "llvm.floor" not in quiet
    assert "llvm.floor" in load and "llvm.floor" in general
    # the general form tests the load amplitudes (f_c1, f_p1 against 0), the load's form does
    # not: it has the general form's compares but those (the load sines' quadrant tests, the
    # dead zones, the stiffness factors' clip are alike)
    assert _fcmp(load) < _fcmp(general)


def _loud_of(p):
    return loud(p)


def test_loud_is_a_constant_where_the_lane_form_fixes_it():
    """``loud(p)``: any quiet coefficient non-zero (NaN too) where tested per lane; False and
    True in the coefficient types of FORM_QUIET and FORM_LOAD, compiled and in Python; the
    types pickle by name; a one form without quiet coefficients has no ``loud``."""
    names, quiet = ("a", "q1", "q2"), ("q1", "q2")
    general = coefficient_type(names, quiet)
    compiled = nb.njit(_loud_of)
    for q1, q2, on in ((0.0, 0.0, False), (-0.0, 0.0, False), (0.0, 2.0, True),
                       (1.0, 0.0, True), (math.nan, 0.0, True)):
        assert loud(general(1.0, q1, q2)) is on and compiled(general(1.0, q1, q2)) is on
    for mode, on in (("quiet", False), ("loud", True)):
        cls = coefficient_type(names, quiet, mode)
        assert cls is not general and pickle.loads(pickle.dumps(cls)) is cls
        p = cls(1.0, 3.0, 0.0)  # (a type of its own: a dispatcher of its own)
        assert loud(p) is on and nb.njit(_loud_of)(p) is on
    with pytest.raises(TypeError, match="quiet"):
        loud(coefficient_type(names)(1.0, 2.0, 3.0))
    with pytest.raises(nb.core.errors.TypingError, match="quiet"):
        nb.njit(_loud_of)(coefficient_type(names)(1.0, 2.0, 3.0))
    with pytest.raises(ValueError, match="mode"):
        coefficient_type(names, quiet, "loose")


def _fcmp(ir):
    """The number of floating-point compares in the LLVM IR ``ir``."""
    return sum(" fcmp " in line for line in ir.splitlines())


def test_a_quiet_coefficient_must_be_a_coefficient_of_the_form():
    with pytest.raises(ValueError, match="quiet"):
        OneForm(coefficient_names(1), 4, 4, 2, quiet=("f_c1", "B1"))
    with pytest.raises(ValueError, match="quiet"):
        OneForm(coefficient_names(1), 4, 4, 2, quiet=("f_c1", "f_c1"))


@nb.njit
def _three_meshes(h, s, c):
    return harmonic_factors(h, 3, s, c)


@pytest.mark.parametrize("nh", [1, 2, 7])
def test_harmonic_factors_sum_the_series_of_each_mesh(nh):
    """The written-out series of three meshes against numpy's cos(h theta), sin(h theta)
    (:func:`geardyn.models.stiffness.evaluate`), and bitwise against harmonic_factor's loop."""
    from geardyn.models.elements import harmonic_factor
    from geardyn.models.stiffness import evaluate

    rng = np.random.default_rng(nh)
    coef = rng.uniform(-0.3, 0.3, (3, nh, 2)) / nh
    flat = coef.reshape(-1)
    for theta in (0.0, 0.4, 2.9, -1.7):
        s, c = math.sin(theta), math.cos(theta)
        got = _three_meshes(tuple(flat), s, c)
        for m in range(3):
            ref = evaluate(coef[m, :, 0], coef[m, :, 1], np.array([theta]))[0]
            assert got[m] == pytest.approx(max(ref, 0.0), abs=1e-14)
            assert got[m] == harmonic_factor(flat, 2 * nh * m, nh, s, c)
