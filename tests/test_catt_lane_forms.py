"""The CATT model's lane forms (see :data:`geardyn.core.kernel_source.LANE_FORMS`): the reduced
device is written once (:mod:`geardyn.models.catt_reduced`, the one form); lanes with the load
quiet take FORM_QUIET (the load term compiled away), lanes with it fluctuating FORM_LOAD, each
in its own compiled copy of the fused loop, any number of stiffness harmonics; every lane's
result is bitwise that of the one-lane path (``simulate``) and every generated layout gives the
bits of the general model's hand-written array form (:func:`~geardyn.models.catt_kernels.catt_rhs`
with one planet set). The load's sine (:func:`~geardyn.models.catt_kernels.load_sin`) is checked
against libm's."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import FORM_GENERAL, FORM_LOAD, FORM_QUIET
from geardyn.core.one_form import OneForm
from geardyn.core.plan import LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.models import catt_kernels as ck
from geardyn.models.catt_reduced import coefficient_names
from geardyn.models.elements import harmonic_factors
from geardyn.solvers.ensemble import run_lanes
from geardyn.solvers.kernels import kernels_for

_OMEGAS = np.array([0.7, 1.3, 2.2, 3.1, 0.45])


@nb.njit(cache=True)
def _load_sin_array(x, out):
    for i in range(x.size):
        out[i] = ck.load_sin(x[i])


@pytest.mark.parametrize("limit", [4.0, 1e3, 1e6])
def test_load_sin_is_within_two_ulp_of_libm(limit):
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.uniform(-limit, limit, 200_000),
                        np.arange(-40, 41) * math.pi / 4])  # the quadrant boundaries
    got = np.empty_like(x)
    _load_sin_array(x, got)
    ref = np.array([math.sin(v) for v in x])
    assert np.max(np.abs(got - ref)) <= 2 * np.spacing(1.0) / 2  # |sin| <= 1: 2 ulp of 1 / 2
    big = np.abs(ref) > 1e-3
    ulp = np.abs(got - ref)[big] / np.spacing(np.abs(ref[big]))
    assert np.max(ulp) <= 2.0
    assert ck.LOAD_SIN_EXACT_BELOW >= limit


def test_load_sin_beyond_the_exact_range_errs_by_the_arguments_own_rounding():
    """A long continuation's time grows with its chain (Lambda t ~ 1e8): there the reduction
    rounds, by about ulp(x), which is the rounding of the argument Lambda t + psi itself."""
    x = np.random.default_rng(2).uniform(1e6, 1e8, 100_000)
    got = np.empty_like(x)
    _load_sin_array(x, got)
    ref = np.array([math.sin(v) for v in x])
    assert np.all(np.abs(got - ref) <= 2 * np.spacing(x) + 4 * np.spacing(1.0))


def _device(**changes):
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1, **changes))


_LOAD = {"B1": "100 N m", "B2": "100 N m", "Lambda": 0.1}


def _assert_lanes_equal_simulate(models, omegas, steps=48):
    """run_lanes of the stacked lanes of ``models`` (one model's layout) against simulate."""
    P = np.vstack([m.lane_params("Omega", omegas) for m in models])
    first = models[0]
    r = run_lanes(first, P, first.initial_state(),
                  run=RunSettings(transient=200.0, samples=3, steps_per_period=steps),
                  lanes=LaneSettings(sample_every=1))
    assert np.all(r.status == 0)
    for j in range(P.shape[0]):
        m = models[j // omegas.size]
        ds = geardyn.simulate(m, omega=float(omegas[j % omegas.size]),
                              run=geardyn.RunSettings(transient=200.0, samples=3,
                                                      steps_per_period=steps))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:], err_msg=str(j))


def _gen(model):
    """The model's generated functions (the kernels' shared core, compiled on first call)."""
    return kernels_for(model.kernel, "core")


def _form(model):
    P = np.ascontiguousarray(model.lane_params("Omega", _OMEGAS[:1]).T)
    return _gen(model).rhs_lane_form(P, 0)


def test_each_lane_form_equals_the_one_lane_path_bitwise():
    quiet, load = _device(), _device(**_LOAD)
    rect = _device(waveform="rectangular")
    assert (_form(quiet), _form(load), _form(rect)) == (FORM_QUIET, FORM_LOAD, FORM_QUIET)
    _assert_lanes_equal_simulate([load], _OMEGAS)
    _assert_lanes_equal_simulate([rect], _OMEGAS[:3])
    # quiet and fluctuating lanes in one queue run in the general form: still the same results
    _assert_lanes_equal_simulate([quiet, load], _OMEGAS[:3])


def test_the_load_changes_the_motion():
    """(So that the test above compares lanes that take the load's branch-free form.)"""
    quiet, load = _device(), _device(**_LOAD)
    P = np.vstack([quiet.lane_params("Omega", _OMEGAS[:2]), load.lane_params("Omega", _OMEGAS[:2])])
    r = run_lanes(quiet, P, quiet.initial_state(),
                  run=RunSettings(transient=200.0, samples=3, steps_per_period=48))
    assert np.max(np.abs(r.samples[:2] - r.samples[2:])) > 1e-3


def test_chains_mixing_forms_run_in_the_general_form_and_equal_lane_by_lane_runs():
    """A chain (a sweep by continuation) whose lanes take different forms runs in the general
    form, the uniform chains and lone lanes in theirs, one pass per form in the same block; each
    chained lane equals the lane run alone from its predecessor's final state and time."""
    quiet, load = _device(), _device(**_LOAD)
    omega = np.array([1.3])
    rows = [quiet, load, quiet, load, load, quiet, load]  # chains 0 -> 1 -> 2 and 3 -> 4
    P = np.vstack([m.lane_params("Omega", omega) for m in rows])
    chain = np.array([1, 2, -1, 4, -1, -1, -1])
    y0 = quiet.initial_state()
    run = RunSettings(transient=100.0, samples=3, steps_per_period=48)
    r = run_lanes(quiet, P, y0, run=run, lanes=LaneSettings(sample_every=1), chain=chain)
    assert np.all(r.status == 0)
    for head in (0, 3, 5, 6):
        lane, start, t0 = head, y0, np.zeros(1)
        while lane >= 0:
            alone = run_lanes(quiet, P[[lane]], start, run=run,
                              lanes=LaneSettings(t0=t0, sample_every=1))
            np.testing.assert_array_equal(r.samples[lane], alone.samples[0], err_msg=str(lane))
            np.testing.assert_array_equal(r.final[lane], alone.final[0])
            start, t0, lane = alone.final[0], alone.final_time[:1], chain[lane]
    # each lane ran once: its grid steps are its transient and its samples, no more
    np.testing.assert_array_equal(r.steps, _planned_steps(r, 3))


def _planned_steps(r, samples):
    """A lane's transient plus ``samples`` sections, in grid steps."""
    return r.steps_per_period * (r.transient_periods + samples * r.sample_every)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_later_form_pass_runs_no_chain_again(workers):
    """A worker's queue with a quiet chain and load lanes runs two passes of the fused loop
    (quiet, then load). A slot that held no lane in the first pass, or held a chain that has
    run, must not read as holding one in the second: until 2026-12-02 the loop advanced free
    slots' clocks, so the second pass continued lane 0's chain (LANE 0) a second time, in
    another worker too, racing with the first run on its outputs (bench/determinism.py found
    the reproduction's Fig. 3 sweep differing between runs). Each lane is run exactly once."""
    from geardyn.core.plan import LanePlan
    from geardyn.solvers.ensemble import run_plan

    quiet, load = _device(), _device(**_LOAD)
    omega = np.linspace(1.1, 1.4, 4)
    P = np.vstack([quiet.lane_params("Omega", omega), load.lane_params("Omega", omega[:3])])
    chain = np.array([1, 2, 3, -1, -1, -1, -1])  # a quiet chain 0 -> 3, three lone load lanes
    run = RunSettings(samples=3, transient=60.0, steps_per_period=48)
    plan = LanePlan.build(quiet, P, run, LaneSettings(sample_every=1))
    r = run_plan(quiet, P, quiet.initial_state(), plan, chain=chain, workers=workers)
    assert np.all(r.status == 0)
    np.testing.assert_array_equal(r.steps, plan.steps_per_period * plan.total_periods)
    lone = run_plan(quiet, P[4:], quiet.initial_state(),
                    LanePlan.build(quiet, P[4:], run, LaneSettings(sample_every=1)))
    np.testing.assert_array_equal(r.samples[4:], lone.samples)


def test_a_chain_stops_at_a_lane_that_did_not_end_well_and_says_so():
    """After a lane that diverges the rest of its chain is not run: those lanes report
    Status.NOT_RUN and no steps (not the 'ok' of an array as allocated); the diverged lane
    reports the steps it took."""
    from geardyn.core.status import Status

    quiet = _device()
    P = quiet.lane_params("Omega", np.array([1.2, 1.25, 1.3]))
    r = run_lanes(quiet, P, quiet.initial_state(),
                  run=RunSettings(transient=50.0, samples=3, steps_per_period=48, bound=1e-3),
                  lanes=LaneSettings(sample_every=1), chain=np.array([1, 2, -1]))
    assert r.status[0] == Status.DIVERGED
    assert 0 < r.steps[0] < _planned_steps(r, 3)[0]
    assert list(r.status[1:]) == [Status.NOT_RUN, Status.NOT_RUN]
    assert list(r.steps[1:]) == [0, 0]


_DEVICES = {"quiet": {}, "load": _LOAD, "rectangular": {"waveform": "rectangular"},
            "rectangular-load": {"waveform": "rectangular", **_LOAD},
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
    """A quiet lane's copy holds no load sine (its floor is the marker), the general one does:
    the one form's ``quiet`` coefficients are constant zeros in the quiet copy."""
    gen = _gen(_device())
    assert "llvm.floor" not in _llvm_of_lane_call(gen, FORM_QUIET)
    assert "llvm.floor" in _llvm_of_lane_call(gen, FORM_LOAD)
    assert "llvm.floor" in _llvm_of_lane_call(gen, FORM_GENERAL)


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
