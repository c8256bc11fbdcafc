"""Settings objects for continuation, Newton shooting and Lyapunov exponents beside RunSettings:
validated at construction (the message names the field), passed whole as ``settings=``; their
fields as keyword arguments still work for one deprecation cycle, with one DeprecationWarning
naming the replacement and the same result; old homes of moved names warn once."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn import ContinuationSettings, LyapunovSettings, NewtonSettings
from geardyn.core.settings import SettingsError, SettingsTypeError

PAIR = dict(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.0)


@pytest.mark.parametrize(("kind", "field", "value", "error"), [
    (ContinuationSettings, "ds", -0.01, SettingsError),
    (ContinuationSettings, "ds_max", float("nan"), SettingsError),
    (ContinuationSettings, "max_points", 0, SettingsError),
    (ContinuationSettings, "max_points", 2.5, SettingsTypeError),
    (ContinuationSettings, "tol", "1e-8", SettingsTypeError),
    (ContinuationSettings, "p_scale", 0.0, SettingsError),
    (NewtonSettings, "tol", 0.0, SettingsError),
    (NewtonSettings, "max_iter", 0, SettingsError),
    (LyapunovSettings, "duration", float("inf"), SettingsError),
    (LyapunovSettings, "n_blocks", 1, SettingsError),
    (LyapunovSettings, "renorm_every", True, SettingsTypeError),
    (LyapunovSettings, "dt", -1.0, SettingsError),
])
def test_bad_field_is_named_at_construction(kind, field, value, error):
    with pytest.raises(error, match=rf"^{field} must"):
        kind(**{field: value})


def test_settings_are_frozen_and_normalised():
    s = ContinuationSettings(ds_max=1, max_points=10.0)
    assert (type(s.ds_max), type(s.max_points)) == (float, int)
    with pytest.raises(AttributeError):
        s.ds = 0.1
    assert s.replace(ds=0.05).ds == 0.05
    with pytest.raises(TypeError, match="no field 'step'"):
        s.replace(step=1.0)


def test_step_order_is_checked_across_fields():
    with pytest.raises(SettingsError, match="ds must lie in"):
        ContinuationSettings(ds=0.5, ds_max=0.2)


def _one_deprecation(record, replacement: str) -> None:
    deprecations = [w for w in record if issubclass(w.category, DeprecationWarning)]
    assert len(deprecations) == 1, [str(w.message) for w in deprecations]
    assert replacement in str(deprecations[0].message)
    assert deprecations[0].filename == __file__  # points at the caller


def test_continuation_keywords_warn_once_and_agree():
    g = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05)
    new = geardyn.continuation(g, "Omega", 0.5, 0.6,
                               settings=ContinuationSettings(max_points=4, ds=0.02))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        old = geardyn.continuation(g, "Omega", 0.5, 0.6, max_points=4, ds=0.02)
    _one_deprecation(record, "settings=geardyn.ContinuationSettings(max_points=4, ds=0.02)")
    xr.testing.assert_identical(old, new)
    with pytest.raises(TypeError, match="not both"):
        geardyn.continuation(g, "Omega", 0.5, 0.6, settings=ContinuationSettings(), ds=0.02)


def test_periodic_orbit_keywords_warn_once_and_agree():
    g = geardyn.GearPair(**PAIR)
    new = geardyn.periodic_orbit(g, omega=1.2, settings=NewtonSettings(tol=1e-9, max_iter=30))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        old = geardyn.periodic_orbit(g, omega=1.2, tol=1e-9, max_iter=30)
    _one_deprecation(record, "settings=geardyn.NewtonSettings(tol=1e-09, max_iter=30)")
    np.testing.assert_array_equal(old.x, new.x)
    assert old.iterations == new.iterations


def test_lyapunov_keywords_warn_once_and_agree():
    g = geardyn.GearPair(**PAIR).with_omega(1.2)
    run = geardyn.RunSettings(transient=50.0)
    new = geardyn.lyapunov(g, run=run, settings=LyapunovSettings(duration=200.0, n_blocks=4))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        old = geardyn.lyapunov(g, run=run, duration=200.0, n_blocks=4)
    _one_deprecation(record, "settings=geardyn.LyapunovSettings(duration=200.0, n_blocks=4)")
    assert old == new
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")  # run and Lyapunov keywords: one warning naming both
        both = geardyn.lyapunov(g, transient=50.0, duration=200.0, n_blocks=4)
    _one_deprecation(record, "lyapunov(transient=, duration=, n_blocks=) is deprecated: pass "
                     "run=geardyn.RunSettings(transient=50.0), "
                     "settings=geardyn.LyapunovSettings(duration=200.0, n_blocks=4)")
    assert both == new
    with pytest.raises(TypeError, match="unexpected keyword argument 'durations'"):
        geardyn.lyapunov(g, run=run, durations=200.0)


def _bitwise(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()


def test_lyapunov_lanes_keywords_warn_once_and_agree():
    """lyapunov_lanes takes run= and settings= as lyapunov does: the old keywords give bitwise
    the same lanes, the LyapunovSettings fields and the run fields each with one
    DeprecationWarning; both is a TypeError; without run, transient is 100 time units
    (LYAPUNOV_DEFAULTS)."""
    g = geardyn.GearPair(**PAIR)
    P = g.lane_params("Omega", [0.6, 1.2, 1.5])
    y0 = np.array([[0.5, 0.0], [0.5, 0.0], [1e9, 0.0]])  # the last lane diverges
    run = geardyn.RunSettings(transient=50.0, steps_per_period=32)
    ls = LyapunovSettings(duration=200.0, n_blocks=4)
    new = geardyn.lyapunov_lanes(g, P, y0, run, settings=ls, with_status=True)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        old = geardyn.lyapunov_lanes(g, P, y0, transient=50.0, steps_per_period=32,
                                     duration=200.0, n_blocks=4, with_status=True)
    deprecations = sorted(str(w.message) for w in record
                          if issubclass(w.category, DeprecationWarning))
    assert deprecations == [  # one warning naming both replacements
        "lyapunov_lanes(transient=, steps_per_period=, duration=, n_blocks=) is deprecated: "
        "pass run=geardyn.RunSettings(transient=50.0, steps_per_period=32), "
        "settings=geardyn.LyapunovSettings(duration=200.0, n_blocks=4)"]
    assert {w.filename for w in record} == {__file__}
    _bitwise(old, new)
    assert np.all(np.isfinite(new[0][:2])) and np.isnan(new[0][2])
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")  # the run keywords alone: deprecated too
        same = geardyn.lyapunov_lanes(g, P, y0, transient=50.0, steps_per_period=32,
                                      settings=ls, with_status=True)
    _one_deprecation(record, "run=geardyn.RunSettings(transient=50.0, steps_per_period=32)")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # neither keywords nor run: no warning
        default = geardyn.lyapunov_lanes(g, P[:2], settings=ls, with_error=True)
        hundred = geardyn.lyapunov_lanes(g, P[:2], run=geardyn.RunSettings(transient=100.0),
                                         settings=ls, with_error=True)
    _bitwise(same, new)
    _bitwise(default, hundred)
    with pytest.raises(TypeError, match="not both"):
        geardyn.lyapunov_lanes(g, P, settings=ls, duration=200.0)
    with pytest.raises(TypeError, match="not both"):
        geardyn.lyapunov_lanes(g, P, run=run, transient=50.0)
    with pytest.raises(TypeError, match="lyapunov_lanes.*unexpected keyword argument 'samples'"):
        geardyn.lyapunov_lanes(g, P, samples=10)


def test_lyapunov_lanes_use_the_run_as_lyapunov_does():
    """Each lane of lyapunov_lanes is lyapunov's one-lane kernel on the same run, also with
    locate_edges=False (the edges integrated across), which changes an impacting exponent."""
    g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
    omegas = [0.92, 1.15]
    ls = LyapunovSettings(duration=300.0)
    lanes = {}
    for locate in (True, False):
        run = geardyn.RunSettings(transient=100.0, steps_per_period=64, locate_edges=locate)
        lanes[locate] = geardyn.lyapunov_lanes(g, g.lane_params("Omega", omegas), run=run,
                                               settings=ls)
        one = [geardyn.lyapunov(g.with_omega(om), run=run, settings=ls) for om in omegas]
        np.testing.assert_allclose(lanes[locate], one, rtol=1e-12, atol=1e-14)
    assert np.all(np.abs(lanes[True] - lanes[False]) > 1e-6)


#: Names that moved: (old home, name, new home or ``new home:new name``).
MOVED = [
    ("geardyn.models.base", "Model", "geardyn.core.model"),
    ("geardyn.models.base", "unique_rows", "geardyn.core.model"),
    ("geardyn.solvers.simulate", "MIN_STEPS_PER_PERIOD", "geardyn.core.plan"),
    ("geardyn.solvers.simulate", "STEPS_PER_FASTEST_MODE", "geardyn.core.plan"),
    ("geardyn.solvers.simulate", "STEPS_PER_OTHER_FORCING", "geardyn.core.plan"),
    ("geardyn.solvers.simulate", "steps_per_period_rule", "geardyn.core.plan"),
    ("geardyn.solvers.simulate", "default_steps_per_period", "geardyn.core.plan"),
    ("geardyn.solvers.simulate", "DEFAULT_BOUND", "geardyn.core.settings"),
    ("geardyn.solvers.ensemble", "_LADDER", "geardyn.core.plan"),
    ("geardyn.solvers.ensemble", "ladder_steps", "geardyn.core.plan"),
    ("geardyn.solvers.ensemble", "lane_steps_per_period", "geardyn.core.plan"),
    ("geardyn.analysis.lyapunov", "DEFAULT_DT", "geardyn.core.settings:LYAPUNOV_DT"),
    ("geardyn.analysis.lyapunov", "DEFAULT_RENORM_EVERY",
     "geardyn.core.settings:LYAPUNOV_RENORM_EVERY"),
    ("geardyn.analysis.lyapunov", "DEFAULT_BLOCKS", "geardyn.core.settings:LYAPUNOV_BLOCKS"),
    ("geardyn.analysis.periodicity", "DEFAULT_MAX_PERIOD", "geardyn.core.settings"),
    ("geardyn.analysis.periodicity", "DEFAULT_TOL", "geardyn.core.settings"),
    ("geardyn.analysis.periodicity", "MAX_COMMON_PERIODS", "geardyn.core.section"),
    ("geardyn.analysis.periodicity", "common_section", "geardyn.core.section"),
    ("geardyn.io.netcdf", "netcdf_attrs", "geardyn.files"),
    *(("geardyn.reproduction.motion", name, "geardyn.analysis.motion") for name in (
        "CHAOTIC", "LYAPUNOV_FLOOR", "LYAPUNOV_Z", "NONPERIODIC", "QUASI_PERIODIC", "UNBOUNDED",
        "UNRESOLVED", "period_label")),
]

_OLD_HOMES = """
import importlib, json, sys, warnings
warnings.simplefilter("always")
import geardyn
out = []
for old, name, new in json.loads(sys.argv[1]):
    home, _, new_name = new.partition(":")
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        same = getattr(importlib.import_module(old), name) is getattr(
            importlib.import_module(home), new_name or name)
        getattr(importlib.import_module(old), name)
    out.append([same, [(w.category.__name__, str(w.message)) for w in record]])
print(json.dumps(out))
"""


def test_old_homes_warn_once_and_nothing_uses_them():
    """In a fresh interpreter (``import geardyn`` itself warns nothing), each old home gives the
    moved object with one DeprecationWarning naming the new home, however often it is asked;
    src/, docs/, examples/, tests/ and bench/ import nothing from an old home."""
    import json
    import os
    import re
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root / "src")}
    out = subprocess.run([sys.executable, "-c", _OLD_HOMES, json.dumps(MOVED)], env=env,
                         capture_output=True, text=True, timeout=300, check=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert "DeprecationWarning" not in out.stderr  # import geardyn: nothing deprecated used
    for (old, name, new), (same, record) in zip(MOVED, got, strict=True):
        home, _, new_name = new.partition(":")
        as_ = f" as {new_name}" if new_name else ""
        assert same
        assert record == [["DeprecationWarning", f"{old}.{name} is deprecated: import it "
                                                 f"from {home}{as_}"]]
    files = [p for d in ("src", "docs", "examples", "tests", "bench") for p in (root / d).rglob("*")
             if p.suffix in (".py", ".md", ".rst") and p.name != Path(__file__).name]
    for old, name, _ in MOVED:
        pattern = re.compile(rf"from {re.escape(old)} import[^\n]*\b{name}\b|"
                             rf"{re.escape(old)}\.{name}\b")
        users = [str(p.relative_to(root)) for p in files if pattern.search(p.read_text())]
        assert users == [], f"{old}.{name} used in {users}"
