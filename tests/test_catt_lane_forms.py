"""The reduced CATT device's lane forms (see :data:`geardyn.core.kernel_source.LANE_FORMS`;
generated from its one form, :mod:`geardyn.models.catt_reduced`): the sweep kernel runs a queue
of quiet lanes, of lanes with the load fluctuating, of several stiffness harmonics or a mixture,
each in its own compiled copy of the fused loop, and every lane's result is bitwise that of the
one-lane path (``simulate``). The load's sine (:func:`~geardyn.models.catt_kernels.load_sin`)
is checked against libm's."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import FORM_GENERAL, FORM_LOAD, FORM_QUIET
from geardyn.core.plan import LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.models import catt_kernels as ck
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
    """The paper's device with the paper's parameters ``changes``; ``harmonics``: the terms of
    both meshes' stiffness series (of a rectangular ``waveform``)."""
    harmonics = changes.pop("harmonics", None)
    params = geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1, **changes)
    if harmonics is not None:
        data = params.model_dump()
        for mesh in ("sun_mesh", "planet_mesh"):
            data[mesh]["harmonics"] = harmonics
        params = geardyn.PlanetaryParams.model_validate(data)
    return geardyn.CATTDevice(params)


_LOAD = {"B1": "100 N m", "B2": "100 N m", "Lambda": 0.1}
#: A rectangular stiffness waveform of 3 harmonics: a series of several terms written out, its
#: own one form (the default 25 terms compile about eight times the code of each lane-scalar
#: function; tests/test_lyapunov_lanes.py checks their lane-block functions).
_RECT = {"waveform": "rectangular", "harmonics": 3}


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
    """Quiet lanes take FORM_QUIET, fluctuating ones FORM_LOAD, with any number of stiffness
    harmonics (a rectangular waveform's, :data:`_RECT`: its own one form, the series written
    out). The fused loop is the same template for every one form; the rectangular device's own
    functions (every layout, each lane form) are compared bit for bit with the general model's
    array form in tests/test_catt_one_form.py, without compiling its kernels here."""
    quiet, load = _device(), _device(**_LOAD)
    rect = _device(**_RECT)
    assert (_form(quiet), _form(load), _form(rect)) == (FORM_QUIET, FORM_LOAD, FORM_QUIET)
    _assert_lanes_equal_simulate([load], _OMEGAS)
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


def _lane_calls(gen, form):
    """Four rhs calls and an observation at the constant lane form ``form`` of the generated
    functions ``gen``, as a kernel's fused loop."""
    rhs_lane, observe_lane = gen.rhs_lane, gen.observe_lane

    @nb.njit
    def calls(y, PT, s, c):
        a = rhs_lane(0.1, y, PT, 0, s, c, form)
        b = rhs_lane(0.2, a, PT, 0, s, c, form)
        return b, observe_lane(0.2, b, PT, 0, s, c, form)

    return calls


def _model_functions_typed(gen, fn, *args):
    """The names of the generated module's compiled functions that numba typed in compiling
    ``fn`` (those inlined into it and those it calls)."""
    fn(*args)
    (ov,) = fn.overloads.values()
    return {t.dispatcher.py_func.__name__ for t in ov.type_annotation.typemap.values()
            if isinstance(t, nb.core.types.Dispatcher)
            and t.dispatcher.py_func.__module__ == gen.__name__}


@pytest.mark.parametrize(("form", "own"), [(FORM_QUIET, "quiet"), (FORM_LOAD, "loud"),
                                           (FORM_GENERAL, "general")])
def test_a_constant_lane_form_compiles_that_forms_code_only(form, own):
    """A kernel's compile time goes with the code numba inlines and types: a call site of a
    constant form holds that form's functions only (no other form's: no load sine where the
    load is quiet, no test of the load where it fluctuates)."""
    gen = _gen(_device())
    P = np.ascontiguousarray(_device().lane_params("Omega", _OMEGAS[:1]).T)
    typed = _model_functions_typed(gen, _lane_calls(gen, form), (0.01, 0.0, -0.02, 0.0), P, 0.3,
                                   math.sqrt(0.91))
    assert typed == {"rhs_lane", "observe_lane", f"_rhs_lane_{own}", f"_observe_lane_{own}"}


def _at_form(gen):
    """The generated ``rhs_lane`` at t = 0.7 of lane 0 in a lane form given at run time."""
    rhs_lane = gen.rhs_lane

    @nb.njit
    def at_form(y, PT, s, c, form):
        return rhs_lane(0.7, y, PT, 0, s, c, form)

    return at_form


def test_every_form_of_a_quiet_lane_equals_the_array_form_with_form_a_variable():
    """``form`` need not be a constant: each form of a quiet lane gives the bits of the general
    model's array form :func:`catt_rhs` with one planet set; a lane with the load on gives them
    in its forms (FORM_LOAD, FORM_GENERAL)."""
    for changes, forms in (({}, (FORM_QUIET, FORM_LOAD, FORM_GENERAL)),
                           (_LOAD, (FORM_LOAD, FORM_GENERAL))):
        m = _device(**changes)
        at_form = _at_form(_gen(m))
        p = m.lane_params("Omega", _OMEGAS[1:2])[0]
        PT = np.ascontiguousarray(p[:, None])
        y, s, c = np.array([2e-3, -0.1, -1e-3, 0.05]), 0.6, 0.8
        ref = np.empty(4)
        ck.catt_rhs(0.7, y, ref, p, s, c)
        for form in forms:
            np.testing.assert_array_equal(np.array(at_form(tuple(y), PT, s, c, form)), ref)
