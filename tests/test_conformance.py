"""Model conformance: every built-in model keeps the model contract (the numbered rules of
:class:`geardyn.Model`), checked by :func:`geardyn.testing.check_model`; and each check fails,
naming its rule, on a model built to break that rule."""

from __future__ import annotations

import copy
import math
import re

import numba
import numpy as np
import pytest

import geardyn
from conformance_cases import IDS, cases, dead_zone_events, dead_zone_rhs, user_model
from geardyn.core.capabilities import Capabilities
from geardyn.core.kernel_source import KernelSource
from geardyn.testing import RULES, ModelContractError, check_model
from shared_models import oscillator

# ---------------------------------------------------------------------------------------------
# the built-in models keep the contract


@pytest.fixture(scope="module")
def all_cases():
    return cases()


@pytest.mark.parametrize("case", IDS)
def test_builtin_model_keeps_the_contract(all_cases, case):
    model, y0 = all_cases[case]
    report = check_model(model, y0=y0)
    assert [r.status for r in report.results] == ["ok"] * len(RULES), str(report)
    if model.n_events:  # the run really crossed edges, so rule 10 tested their location
        ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0.0, samples=2), y0=y0)
        assert int(ds["edge_crossings"].sum()) > 0


def test_contract_rules_match_the_model_docstring():
    """The numbered rules of Model's docstring are those check_model checks, in order."""
    doc = geardyn.Model.__doc__
    found = re.findall(r"^\s*(\d+)\. \*\*(.+?)\*\*", doc, flags=re.M)
    assert [(int(n), name) for n, name in found] == [(r.number, r.name) for r in RULES]


# ---------------------------------------------------------------------------------------------
# deliberately broken models: the check names the broken rule

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}


@numba.njit(**_JIT)
def _rhs_short(t, y, dy, p):  # leaves dy[1] unset
    dy[0] = y[1]


@numba.njit(**_JIT)
def _rhs_outside(t, y, dy, p):  # writes one entry past dy
    dead_zone_rhs(t, y, dy, p)
    dy[2] = 0.0


@numba.njit(**_JIT)
def _rhs_changes_y(t, y, dy, p):
    dead_zone_rhs(t, y, dy, p)
    y[0] += 1e-3


@numba.njit(**_JIT)
def _rhs_random(t, y, dy, p):
    dead_zone_rhs(t, y, dy, p)
    dy[1] += 1e-9 * np.random.random()  # noqa: NPY002


@numba.njit(**_JIT)
def _rhs_log(t, y, dy, p):  # -inf at x = 0, NaN below
    dead_zone_rhs(t, y, dy, p)
    dy[1] += math.log(y[0])


@numba.njit(**_JIT)
def _events_shifted(t, y, g, p):  # zeros at +-2b, but the kinks are at +-b
    g[0] = y[0] - 2.0 * p[0]
    g[1] = y[0] + 2.0 * p[0]


@numba.njit(**_JIT)
def _events_three_args(t, y, g):
    g[0] = y[0]


@numba.njit(**_JIT)
def _observe_outside(t, y, out, p):
    out[0] = y[0]
    out[1] = y[1]


@numba.njit(**_JIT)
def _rhs_jump(t, y, dy, p):  # a jump in t (square-wave forcing) that no event locates
    dead_zone_rhs(t, y, dy, p)
    dy[1] += 0.5 if math.sin(p[4] * t) > 0.0 else -0.5


def _plain_rhs(t, y, dy, p):
    dy[0] = y[1]
    dy[1] = -y[0]


def _with(model: geardyn.Model, **attrs) -> geardyn.Model:
    out = copy.copy(model)
    for k, v in attrs.items():
        setattr(out, k, v)
    return out


def _user(rhs, **kw) -> geardyn.UserModel:
    """The dead-zone oscillator's coefficients and events with another rhs."""
    good = user_model()
    return geardyn.UserModel(rhs, n_states=2, params=good.params, param_names=good.param_names,
                             events=dead_zone_events, n_events=2, **kw)


class _WrongInitialState(geardyn.UserModel):
    def initial_state(self) -> np.ndarray:
        return np.zeros(3)


def _broken(name: str) -> geardyn.Model:
    """A model that breaks exactly one rule (named in the test's parameter)."""
    good = user_model()
    ks = good.kernel
    if name == "duplicate state names":
        return _with(good, state_names=("x", "x"))
    if name == "mesh names a missing event":
        return _with(good, meshes=(("mesh", 0, 5),))
    if name == "non-finite coefficient":
        return _with(good, params=np.array([0.5, 0.05, np.nan, 1.0, 1.2]))
    if name == "param_names of the wrong length":
        return _with(good, param_names=("b", "zeta"))
    if name == "initial state of the wrong length":
        return _WrongInitialState(dead_zone_rhs, n_states=2, params=[0.5, 0.05, 0.6, 1.0, 1.2],
                                  param_names=("b", "zeta", "F", "k", "Omega"))
    if name == "rhs not compiled":
        return _with(good, kernel=KernelSource(_plain_rhs, plain=True), event_names=(),
                     observable_names=(), meshes=())
    if name == "events with three arguments":
        return _with(good, kernel=KernelSource(ks.rhs, _events_three_args, ks.observe,
                                               plain=True))
    if name == "events without event names":
        return _with(good, event_names=(), meshes=())
    if name == "derivative shape":
        return _user(_rhs_short)
    if name == "state names of the wrong length":
        return user_model(n_states=3, state_names=("x", "v", "w"))
    if name == "rhs writes outside dy":
        return _user(_rhs_outside)
    if name == "observe writes outside its output":
        return user_model(observe=_observe_outside)
    if name == "rhs modifies y":
        return _user(_rhs_changes_y)
    if name == "rhs is random":
        return _user(_rhs_random)
    if name == "non-finite rhs":
        return _user(_rhs_log)
    if name == "events not zero at the kinks":
        return user_model(events=_events_shifted)
    if name == "kinks without events":
        return user_model(events=None, n_events=0)
    if name == "jump in time":
        return _user(_rhs_jump)
    if name == "negative natural frequency":
        return _user(dead_zone_rhs, natural_frequency=lambda p: -1.0)
    if name.startswith("static mesh forces"):
        return _static_forces(name)
    raise KeyError(name)


def _static_forces(name: str) -> geardyn.Model:
    """The dead-zone oscillator (observable F, its mesh force) giving static mesh forces: with
    no mesh, with a mesh whose force it does not declare, or with the wrong count."""
    good = user_model()
    one, two = (lambda: np.array([0.6])), (lambda: np.array([0.6, 0.6]))
    mesh = (("mesh", 0, 1),)
    if name == "static mesh forces without meshes":
        return _with(good, static_mesh_forces=one)
    if name == "static mesh forces of a mesh without its force":
        return _with(good, meshes=mesh, static_mesh_forces=one)
    if name == "static mesh forces of the wrong count":
        return _with(good, meshes=mesh, capabilities=Capabilities(mesh_forces=True),
                     static_mesh_forces=two)
    raise KeyError(name)


BROKEN = [
    ("duplicate state names", 1),
    ("mesh names a missing event", 1),
    ("non-finite coefficient", 2),
    ("param_names of the wrong length", 2),
    ("initial state of the wrong length", 3),
    ("rhs not compiled", 4),
    ("events with three arguments", 4),
    ("events without event names", 4),
    ("derivative shape", 5),
    ("state names of the wrong length", 5),
    ("rhs writes outside dy", 6),
    ("observe writes outside its output", 6),
    ("rhs modifies y", 6),
    ("rhs is random", 6),
    ("non-finite rhs", 7),
    ("events not zero at the kinks", 8),
    ("kinks without events", 8),
    ("jump in time", 8),
    ("negative natural frequency", 9),
    ("static mesh forces without meshes", 1),
    ("static mesh forces of a mesh without its force", 1),
    ("static mesh forces of the wrong count", 1),
]


@pytest.mark.parametrize(("name", "rule"), BROKEN, ids=[b[0] for b in BROKEN])
def test_check_names_the_broken_rule(name, rule):
    model = _broken(name)
    with pytest.raises(ModelContractError) as err:
        check_model(model, run=False)
    assert err.value.rules == (rule,), str(err.value)
    broken = next(r for r in RULES if r.number == rule)
    assert f"rule {rule} ({broken.name}): failed" in str(err.value)


def test_static_mesh_forces_with_their_declared_meshes_keep_rule_1():
    """The same model declaring its mesh and its force (the observable F) keeps rule 1; the
    broken forms name static_mesh_forces."""
    good = _with(user_model(), meshes=(("mesh", 0, 1),),
                 capabilities=Capabilities(mesh_forces=True),
                 static_mesh_forces=lambda: np.array([0.6]))
    report = check_model(good, run=False, raise_on_failure=False)
    assert report.results[0].status == "ok", str(report)
    for name in ("static mesh forces without meshes",
                 "static mesh forces of a mesh without its force"):
        text = str(check_model(_broken(name), run=False, raise_on_failure=False))
        assert "static_mesh_forces() gives 1 mesh forces but the model declares" in text, text


def test_check_names_a_run_that_misses_the_reference():
    """A stiff model (natural frequency 20 Omega) that does not declare its fast mode gets the
    default 64 steps per period, too coarse: only the run against the reference shows it."""
    model = user_model(k=400.0, natural_frequency=False)
    with pytest.raises(ModelContractError) as err:
        check_model(model, y0=np.array([1.0, 0.0]))
    assert err.value.rules == (10,), str(err.value)
    # declaring it makes the default step resolve the mode, and the model conform
    fixed = user_model(k=400.0)
    assert check_model(fixed, y0=np.array([1.0, 0.0])).ok


def test_report_without_raising():
    report = check_model(_broken("kinks without events"), run=False, raise_on_failure=False)
    assert not report.ok
    assert [r.rule.number for r in report.failed] == [8]
    assert report.results[-1].status == "skipped"
    assert "rule 8 (kinks on event zeros): failed" in str(report)


def test_smooth_nonlinear_model_has_no_kinks():
    """The kink scan does not mistake strong smooth nonlinearity for a kink."""
    # strongly nonlinear but smooth: a cubic and a sharp tanh step,
    # x'' + 2 zeta x' + x + 5 x^3 - 0.5 tanh(x / 0.05) = F cos(Omega t)
    model = oscillator(zeta=0.05, beta=5.0, a=-0.5, w=0.05, Omega=1.3, F=2.0,
                       natural_frequency=4.0)
    report = check_model(model, y0=np.array([1.5, 0.0]), run=False)
    assert report.ok


def test_autonomous_model_keeps_the_contract():
    """A model without forcing frequency (omega_index None): no Omega to set, and the run is
    checked over two time units."""
    model = user_model(params=[0.5, 0.05, 0.0, 1.0, 0.0], param_names=("b", "zeta", "F", "k", "w"))
    assert model.omega_index is None
    report = check_model(model, y0=np.array([1.5, 0.0]))
    assert report.ok, str(report)


def test_rectangular_stiffness_is_smooth_to_the_kink_scan():
    """The rectangular mesh stiffness (25 Fourier harmonics with Lanczos factors) is smooth in
    time: the scan over a forcing period does not take its steep flanks for kinks."""
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(waveform="rectangular")).with_omega(0.9)
    assert int(m.params[3]) > 10  # n_harmonics
    assert check_model(m, run=False).ok
