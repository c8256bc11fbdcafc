"""geardyn.core: run settings validated once, the lane plan's step counts, the status codes,
and the core importing nothing above it."""

from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn import RunSettings, Status
from geardyn.core.plan import LanePlan, LaneSettings, default_steps_per_period
from geardyn.core.settings import SettingsError
from geardyn.core.status import status_meaning
from geardyn.solvers.ensemble import run_lanes

CORE = Path(geardyn.__file__).parent / "core"


# ---------------------------------------------------------------------------- RunSettings
@pytest.mark.parametrize("field,value,error,message", [
    ("transient", -1.0, ValueError, r"transient must be a finite time >= 0 \(got -1.0\)"),
    ("transient", math.nan, ValueError, r"transient must be a number, not NaN"),
    ("transient", math.inf, ValueError, r"transient must be a finite time >= 0 \(got inf\)"),
    ("transient", "100", TypeError, r"transient must be a number \(got '100'\)"),
    ("samples", 0, ValueError, r"samples must be >= 1 \(got 0\)"),
    ("samples", 2.5, TypeError, r"samples must be a whole number \(got 2.5\)"),
    ("samples", True, TypeError, r"samples must be a whole number \(got True\)"),
    ("steps_per_period", 2, ValueError, r"steps_per_period must be >= 4 \(got 2\)"),
    ("steps_per_period", -8, ValueError, r"steps_per_period must be >= 4 \(got -8\)"),
    ("steps_per_period", math.nan, TypeError, r"steps_per_period must be a whole number"),
    ("locate_edges", "yes", TypeError, r"locate_edges must be True or False"),
    ("bound", -1.0, ValueError, r"bound must be > 0 \(got -1.0\)"),
    ("bound", math.nan, ValueError, r"bound must be a number, not NaN"),
    ("converge", 0.0, ValueError, r"converge must be a positive tolerance or None \(got 0.0\)"),
    ("converge", -1e-8, ValueError, r"converge must be a positive tolerance"),
    ("converge", math.nan, ValueError, r"converge must be a number, not NaN"),
    ("transient_max", -5.0, ValueError, r"transient_max must be a finite time >= 0"),
    ("continued_transient", math.inf, ValueError, r"continued_transient must be a finite"),
    ("max_period", 0, ValueError, r"max_period must be >= 1 \(got 0\)"),
    ("period_tol", 0.0, ValueError, r"period_tol must be a finite tolerance > 0"),
    ("period_tol", None, TypeError, r"period_tol must be a number \(got None\)"),
    ("max_section_periods", 0, ValueError, r"max_section_periods must be >= 1 \(got 0\)"),
])
def test_run_settings_name_the_bad_field(field, value, error, message):
    with pytest.raises(error, match=message) as info:
        RunSettings(**{field: value})
    assert isinstance(info.value, SettingsError)  # a ValueError, for the API's error handling
    with pytest.raises(error, match=message):  # replace validates anew
        RunSettings().replace(**{field: value})


def test_run_settings_immutable_and_normalised():
    run = RunSettings(transient=np.float64(100), samples=np.int64(8), steps_per_period=32.0)
    assert (type(run.transient), type(run.samples), type(run.steps_per_period)) == (
        float, int, int)
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.samples = 3  # type: ignore[misc]
    changed = run.replace(samples=16)
    assert (run.samples, changed.samples, changed.transient) == (8, 16, 100.0)
    with pytest.raises(TypeError, match="no field 'periods'"):
        run.replace(periods=3)
    assert run.transient_limit == 1000.0 and run.replace(transient_max=50.0).transient_limit == 50
    assert run.converge_tol == 0.0 and run.replace(converge=1e-8).converge_tol == 1e-8


def test_run_settings_attrs_are_netcdf_safe():
    attrs = RunSettings(converge=1e-8, max_section_periods=8).attrs()
    assert attrs["transient_max"] == 40000.0 and attrs["converge"] == 1e-8
    assert attrs["locate_edges"] == 1 and attrs["max_section_periods"] == 8
    assert all(isinstance(v, (int, float, str)) and not isinstance(v, bool)
               for v in attrs.values())


# ---------------------------------------------------------------------------- the lane plan
class _Forced:
    """A duck-typed model: Omega in column 0, a second forcing in column 1 (NaN: none), the
    fastest natural frequency in column 2."""

    omega_index = 0
    params = np.array([1.3, np.nan, 1.0])

    @staticmethod
    def other_frequencies(P):
        return np.atleast_2d(P)[:, 1:2]

    @staticmethod
    def fastest_natural_frequency(P):
        return np.atleast_2d(P)[:, 2]


def _ladder_by_hand(n: float) -> int:
    """Smallest 2 ceil(8 2^(k/4)) (k = 0, 1, ...) that is >= n."""
    k = 0
    while 2 * math.ceil(8 * 2.0 ** (k / 4)) < n:
        k += 1
    return 2 * math.ceil(8 * 2.0 ** (k / 4))


def test_lane_plan_step_counts_by_hand():
    P = np.array([[1.3, np.nan, 1.0],  # Omega 1.3 alone, slow natural mode
                  [1.3, 0.65, 1.0],  # a second forcing at Omega / 2: sections of 2 periods
                  [0.4, np.nan, 10.0]])  # a fast natural mode: the step rule refines
    run = RunSettings(transient=100.0, samples=5, transient_max=300.0)
    plan = LanePlan.build(_Forced(), P, run, LaneSettings(steps_per_period=[32, 32, 0]))
    T = 2 * math.pi / np.array([1.3, 1.3, 0.4])
    assert plan.period.tolist() == T.tolist()
    n3 = _ladder_by_hand(math.ceil(100 * 10.0 / 0.4))  # 100 steps per natural period
    assert plan.steps_per_period.tolist() == [32, 32, n3]
    assert plan.step.tolist() == (T / [32, 32, n3]).tolist()
    assert plan.sample_every.tolist() == [1, 2, 1]
    assert plan.commensurate.tolist() == [True, True, True]
    tr = math.ceil(100 * 1.3 / (2 * math.pi))  # 21 periods
    assert tr == 21
    tr3 = math.ceil(100 * 0.4 / (2 * math.pi))
    assert plan.transient_periods.tolist() == [21, 22, tr3]  # whole sections of 2 periods
    assert plan.transient_steps.tolist() == [21 * 32, 22 * 32, tr3 * n3]
    mx = math.floor(300 * 1.3 / (2 * math.pi))  # 62, already a whole number of sections
    assert mx == 62
    assert plan.transient_max_periods.tolist() == [mx, mx, math.floor(300 * 0.4 / (2 * math.pi))]
    assert plan.sample_steps.tolist() == [32, 64, n3]
    assert plan.total_periods.tolist() == [21 + 5, 22 + 10, tr3 + 5]


def test_lane_plan_incommensurate_section_and_bad_lanes():
    P = np.array([[1.0, math.sqrt(2.0), 1.0]])
    plan = LanePlan.build(_Forced(), P, RunSettings(transient=0.0, steps_per_period=16))
    assert plan.sample_every.tolist() == [1] and plan.commensurate.tolist() == [False]
    assert plan.transient_periods.tolist() == [0]
    with pytest.raises(ValueError, match="Omega: must be a positive finite number"):
        LanePlan.build(_Forced(), np.array([[0.0, np.nan, 1.0]]), RunSettings())
    with pytest.raises(ValueError, match=r"steps_per_period must be >= 4 \(got 3\)"):
        LanePlan.build(_Forced(), P, RunSettings(), LaneSettings(steps_per_period=[3]))
    with pytest.raises(ValueError, match="transient must be a finite time >= 0 in every lane"):
        LanePlan.build(_Forced(), P, RunSettings(), LaneSettings(transient=[-1.0]))


def test_default_steps_per_period_rule_by_hand():
    m = _Forced()
    assert default_steps_per_period(m, 1.3) == 77  # ceil(100 x 1 / 1.3): 100 steps per mode
    assert default_steps_per_period(m, 4.0) == 64  # the floor


# ---------------------------------------------------------------------------- status
def test_status_codes_equal_the_kernel_constants():
    from geardyn.solvers import _step_shared

    assert Status.OK == _step_shared.STATUS_OK == 0
    assert Status.DIVERGED == _step_shared.STATUS_DIVERGED == 1
    assert Status.SPLIT_LIMIT == _step_shared.STATUS_SPLIT_LIMIT == 2
    assert status_meaning().startswith("0 ok, 1 diverged")
    assert Status.DIVERGED.message.startswith("diverged")


# ---------------------------------------------------------------------------- the API
@pytest.fixture(scope="module")
def device():
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1))


def test_old_keywords_equal_run_settings_bitwise(device):
    om = np.array([0.7, 1.1, 1.9])
    with pytest.warns(DeprecationWarning, match=r"bifurcation\(transient=, samples="):
        old = geardyn.bifurcation(device, "Omega", om, transient=60.0, samples=4, tol=1e-4,
                                  converge=1e-8, transient_max=120.0)
    run = RunSettings(transient=60.0, samples=4, period_tol=1e-4, converge=1e-8,
                      transient_max=120.0)
    new = geardyn.bifurcation(device, "Omega", om, run)
    xr.testing.assert_identical(old, new)
    assert new.attrs["period_tol"] == 1e-4 and new["status"].attrs["meaning"].startswith("0 ok")
    with pytest.warns(DeprecationWarning, match=r"simulate\(transient=, periods=\)"):
        sim_old = geardyn.simulate(device, omega=1.1, transient=20.0, periods=2)
    sim_new = geardyn.simulate(device, 1.1, RunSettings(transient=20.0, samples=2))
    xr.testing.assert_identical(sim_old, sim_new)
    P = device.lane_params("Omega", om)
    with pytest.warns(DeprecationWarning, match=r"run_lanes\(transient=, samples=, "):
        a = run_lanes(device, P, device.initial_state(), 60.0, 4, converge_tol=1e-8,
                      transient_max=120.0)
    b = run_lanes(device, P, device.initial_state(), run=run)
    assert np.array_equal(a.samples, b.samples) and np.array_equal(a.final_time, b.final_time)


def test_run_and_keywords_together_is_an_error(device):
    with pytest.raises(TypeError, match=r"not both \(got run= and transient=\)"):
        geardyn.bifurcation(device, "Omega", [1.0], RunSettings(), transient=10.0)
    with pytest.raises(TypeError, match="not both"):
        geardyn.simulate(device, 1.0, RunSettings(), periods=3)
    with pytest.raises(TypeError, match="unknown run setting 'transients'"):
        geardyn.map2d(device, ("Omega", [1.0]), ("xi1", [0.1]), transients=10.0)
    with pytest.raises(ValueError, match=r"samples must be >= 1 \(got 0\)"):
        geardyn.bifurcation(device, "Omega", [1.0], samples=0)


# ---------------------------------------------------------------------------- layering
def _geardyn_imports(path: Path) -> list[str]:
    names = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names.append("." * node.level + (node.module or ""))
    return [n for n in names if n.startswith(("geardyn", "."))]


#: The base modules below the core (they import nothing of geardyn; see tests/test_layers.py),
#: ``_jit_target`` among them: the compiler pipeline of geardyn's numba functions.
_BASE = {"geardyn.errors", "geardyn.units", "geardyn._version", "geardyn._jit_target"}


def test_core_imports_nothing_above_it():
    modules = sorted(CORE.glob("*.py"))
    assert {p.stem for p in modules} >= {"settings", "status", "plan", "section", "model",
                                         "kernel_source"}
    for path in modules:
        for name in _geardyn_imports(path):
            assert name in _BASE or name == "geardyn.core" or name.startswith("geardyn.core."), (
                f"{path.name} imports {name}")


def test_continued_sweeps_run_equals_keywords(device):
    with pytest.warns(DeprecationWarning, match=r"ContinuedSweep\(transient="):
        sweep = geardyn.ContinuedSweep(device, "Omega", [0.8, 1.0, 1.2], "down",
                                       transient=80.0, continued_transient=20.0)
    with pytest.warns(DeprecationWarning, match=r"continued_sweeps\(samples="):
        (old,) = geardyn.continued_sweeps([sweep], samples=3, converge=1e-8, tol=1e-4)
    (new,) = geardyn.continued_sweeps([sweep], RunSettings(samples=3, converge=1e-8,
                                                           period_tol=1e-4))
    xr.testing.assert_identical(old, new)
    assert new.attrs["continued_transient"] == 20.0 and new.attrs["transient"] == 80.0


def test_continued_sweep_takes_run_settings(device):
    """A sweep's transients and step come from its RunSettings or, equally, the old keywords,
    validated once when the sweep is made."""
    with pytest.warns(DeprecationWarning, match=r"ContinuedSweep\(transient="):
        old = geardyn.ContinuedSweep(device, "Omega", [0.8, 1.0], "down", transient=80.0,
                                     continued_transient=20.0, steps_per_period=64)
    run = RunSettings(transient=80.0, continued_transient=20.0, steps_per_period=64)
    new = geardyn.ContinuedSweep(device, "Omega", [0.8, 1.0], "down", run=run)
    assert new.run == old.run == run
    assert (new.transient, new.continued_transient, new.steps_per_period) == (80.0, 20.0, 64)
    with pytest.raises(TypeError, match=r"not both \(got run= and transient=\)"):
        geardyn.ContinuedSweep(device, "Omega", [0.8], run=run, transient=10.0)
    with pytest.raises(SettingsError, match="transient"):
        geardyn.ContinuedSweep(device, "Omega", [0.8], transient=-1.0)


def test_continued_sweeps_shared_run_reaches_sweeps_without_their_own(device):
    """A sweep made without a run takes its transients and step from continued_sweeps' run
    (bitwise bifurcation's continuation with that run), and a sweep's own run differing in a
    shared field is a TypeError naming both values."""
    run = RunSettings(transient=60.0, continued_transient=20.0, samples=3,
                      steps_per_period=48)
    (ds,) = geardyn.continued_sweeps([geardyn.ContinuedSweep(device, "Omega", [0.8, 1.0])], run)
    alone = geardyn.bifurcation(device, "Omega", [0.8, 1.0], run, continuation="up")
    xr.testing.assert_identical(ds, alone)
    assert (ds.attrs["transient"], ds.attrs["continued_transient"]) == (60.0, 20.0)
    own = geardyn.ContinuedSweep(device, "Omega", [0.8], run=run.replace(samples=4))
    with pytest.raises(TypeError, match=r"samples=4 \(the sweep's run\) and samples=3"):
        geardyn.continued_sweeps([own], run)


def test_study_run_table_builds_run_settings():
    from geardyn.io import builtin_study

    study = builtin_study("paper_fig3")
    run = study.run_settings(sweep=True, converge=1e-8, transient=None)
    assert isinstance(run, RunSettings)
    assert run.transient == study.run.transient and run.converge == 1e-8
    assert run.samples == (study.sweep.samples or study.run.periods)
    assert study.run_settings().samples == study.run.periods
    with pytest.raises(SettingsError, match=r"samples must be >= 1 \(got 0\)"):
        study.run_settings(samples=0)


def test_cli_run_settings_name_the_option():
    from geardyn.cli.common import run_settings
    from geardyn.errors import ParameterError

    with pytest.raises(ParameterError, match=r"^--steps-per-period: must be >= 4 \(got 2\)$"):
        run_settings({"transient": ("--transient", 10.0),
                      "steps_per_period": ("--steps-per-period", 2)})
    run = run_settings({"transient": ("--transient", 10.0), "converge": ("--converge", None)})
    assert run == RunSettings(transient=10.0)
