"""TOML parameter and study files, built-in studies, NetCDF results."""

from __future__ import annotations

import math
import os
import tomllib
from importlib import resources

import numpy as np
import pytest
import xarray as xr
from pydantic import ValidationError

from geardyn import CATTDevice, GearPair, PlanetaryParams, PlanetOverride, StudyError
from geardyn.cli.errors import format_error
from geardyn.files import netcdf_attrs
from geardyn.io.netcdf import load_dataset, save_dataset
from geardyn.io.toml import (
    GearPairParams,
    PaperBase,
    RunSettings,
    Study,
    StudyInfo,
    SweepSettings,
    builtin_study,
    builtin_study_names,
    load_params,
    load_study,
    save_params,
    save_study,
    study_to_toml,
)
from geardyn.study import build_model

# --------------------------------------------------------------------------- parameters


def _odd_params() -> PlanetaryParams:
    """Paper parameters with awkward floats, per-planet overrides and a derived override."""
    planets = [PlanetOverride() for _ in range(4)]
    planets[2] = PlanetOverride(
        sun_mesh={"stiffness_phase": 0.1 + 0.2, "backlash": "33.3 um"},
        inside_planet={"mass": 1.0 / 3.0},
    )
    return PlanetaryParams.paper(
        xi1=0.05 + 1e-17 + 0.1 / 3.0,
        psi1="17 deg",
        B1=math.pi,
        planets=planets,
        derived={"r_bc": 0.1 + 1e-16},
    )


@pytest.mark.parametrize("make", [PlanetaryParams.paper, _odd_params])
def test_params_round_trip_is_lossless(tmp_path, make):
    p = make()
    path = save_params(p, tmp_path / "p.toml")
    q = load_params(path)
    assert q == p
    assert q.model_dump() == p.model_dump()
    # the file is plain SI: angles in rad, no unit strings
    doc = tomllib.loads(path.read_text())
    assert doc["sun"]["pressure_angle"] == p.sun.pressure_angle
    assert doc["sun_mesh"]["backlash"] == 5e-5


def test_load_params_from_text_with_units():
    import tomli_w

    p = PlanetaryParams.paper()
    data = p.model_dump(exclude_none=True)
    data["sun_mesh"]["backlash"] = "30 um"
    data["sun"]["pressure_angle"] = "20 deg"
    text = tomli_w.dumps(data)
    q = load_params(text)
    assert q.sun_mesh.backlash == 3e-5
    assert q.sun.pressure_angle == p.sun.pressure_angle


def test_load_params_from_params_table():
    q = load_params('[params]\nbase = "paper"\n[params.changes]\nxi1 = 0.1\n')
    assert q == PlanetaryParams.paper(xi1=0.1)


def test_unknown_key_in_toml_is_named(tmp_path):
    path = save_params(PlanetaryParams.paper(), tmp_path / "p.toml")
    text = path.read_text().replace("[carrier]\n", "[carrier]\nfriction = 0.3\n")
    path.write_text(text)
    with pytest.raises(ValidationError) as info:
        load_params(path)
    line = format_error(info.value)
    assert line.startswith("carrier.friction: unknown key")
    assert "(got 0.3)" in line


def test_missing_file_and_bad_toml(tmp_path):
    with pytest.raises(FileNotFoundError) as info:
        load_study(tmp_path / "nope.toml")
    assert format_error(info.value) == f"file not found: {tmp_path / 'nope.toml'}"
    bad = tmp_path / "bad.toml"
    bad.write_text("[params\nx = 1\n")
    with pytest.raises(StudyError) as info2:
        load_study(bad)
    line = format_error(info2.value)
    assert str(bad) in line and "invalid TOML" in line and "line 1" in line


# --------------------------------------------------------------------------- studies
STUDY_TEXT = """
[study]
name = "t"
interpretation = "carrier-only"
[params]
base = "paper"
[params.changes]
xi1 = 0.1
backlash = "30 um"
B1 = "100 N m"
[run]
omega = 1.5
periods = 8
"""


def test_study_base_and_changes():
    s = load_study(STUDY_TEXT)
    assert isinstance(s.params, PaperBase)
    assert s.planetary_params == PlanetaryParams.paper(xi1=0.1, backlash=3e-5, B1=100.0)
    m = build_model(s)
    assert isinstance(m, CATTDevice)
    assert m.interpretation == "carrier-only" and m.omega == 1.5
    assert build_model(s, interpretation="as-printed", omega=2.0).interpretation == "as-printed"
    assert s.run.periods == 8 and s.run.transient == 4000.0
    assert s.plot_state == "X_sq"


def test_study_full_params_and_gear_pair():
    full = Study(study=StudyInfo(name="f"), params=PlanetaryParams.paper(N=3))
    assert build_model(full).params_in.n_planets == 3
    gp = load_study('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.1\nFa = 0.2\n')
    assert isinstance(gp.params, GearPairParams)
    model = build_model(gp, omega=1.3)
    assert isinstance(model, GearPair) and model.omega == 1.3
    assert gp.plot_state == "x"
    with pytest.raises(StudyError):
        _ = gp.planetary_params


@pytest.mark.parametrize(
    "study",
    [
        Study(
            study=StudyInfo(name="a", description="d", plot_state="X_pq"),
            params=PaperBase(base="paper", changes={"xi1": 0.1, "backlash": "30 um", "N": 3}),
            run=RunSettings(omega=1.1, transient=123.5, periods=7, steps_per_period=200),
            sweep=SweepSettings(start=0.1, stop=4.0, num=1000, continuation="down",
                                samples=100, lyapunov=True),
        ),
        Study(study=StudyInfo(name="b", interpretation="as-printed"), params=_odd_params()),
        Study(study=StudyInfo(name="c", model="gear_pair"), params=GearPairParams(kappa=0.2)),
    ],
    ids=["paper-changes", "full", "gear-pair"],
)
def test_study_round_trip_is_lossless(tmp_path, study):
    path = save_study(study, tmp_path / "s.toml")
    back = load_study(path)
    assert back == study
    assert back.model_dump() == study.model_dump()


@pytest.mark.parametrize(
    ("text", "start"),
    [
        ('[params]\nbase = "paper"\n[params.changes]\nxi1 = -0.1\n',
         "params.changes.xi1: Input should be greater than or equal to 0 (got -0.1)"),
        ('[params]\nbase = "paper"\n[params.changes]\nxi9 = 0.1\n',
         "params.changes.xi9: unknown parameter name"),
        ('[params]\nbase = "paper"\n[params.changes]\nbacklash = "5 N"\n',
         "params.changes.backlash: '5 N' has units of N but m is needed (got '5 N')"),
        ('[params]\nbase = "paper"\n[params.changes]\nKm_sq = nan\n',
         "params.changes.Km_sq: Input should be a finite number (got nan)"),
        ('[params]\nbase = "papr"\n', "params.base: Input should be 'paper' (got 'papr')"),
        ('[params]\nbase = "paper"\n[runs]\nperiods = 3\n', "runs: unknown key"),
        ('[params]\nbase = "paper"\n[run]\nperiod = 3\n', "run.period: unknown key"),
        ('[params]\nbase = "paper"\n[run]\nperiods = 0\n', "run.periods: Input should be"),
        ('[study]\ninterpretation = "printed"\n[params]\nbase = "paper"\n',
         "study.interpretation: Input should be"),
        ('[study]\nmodel = "gear_pair"\n[params]\nkappa = 1.5\n', "params.kappa: Input should"),
        ('[study]\nmodel = "gear_pair"\n[params]\nbase = "paper"\n', "params.base: unknown key"),
        ('[params]\nbase = "paper"\n[sweep]\nstart = 0.1\nstop = 4.0\nnum = 1\n',
         "sweep.num: Input should be greater than or equal to 2 (got 1)"),
        ('[params]\nbase = "paper"\n[sweep]\nstart = 1\nstop = 4\nnum = 3\n'
         'continuation = "sideways"\n',
         "sweep.continuation: must be one of none, up, down (got 'sideways')"),
        ('[params]\nbase = "paper"\n[sweep]\nstart = 1\nstop = 4\nnum = 3\nsamples = 1\n',
         "sweep.samples: Input should be greater than or equal to 2 (got 1)"),
        ('[params]\nbase = "paper"\n[sweep]\nstart = 1\nstop = 1\nnum = 3\n',
         "sweep: start and stop must differ (got 1.0 twice)"),
        ('[params]\nbase = "paper"\n[run]\ntransient = 10\ntransient_periods = 20\n',
         "run: give the transient either as transient (time) or as transient_periods"),
        ('[params]\nbase = "paper"\n[run]\ntransient_periods = 0\n',
         "run.transient_periods: Input should be greater than 0 (got 0)"),
        ('[params]\nbase = "paper"\n[run]\nconverge = 1.5\n',
         "run.converge: Input should be less than 1 (got 1.5)"),
        ('[params]\nbase = "paper"\n[run]\ntransient_max = 9000\n',
         "run: transient_max is the limit of a transient by convergence: set converge"),
        ('[params]\nbase = "paper"\n[run]\nconverge = 1e-6\ntransient_max = 9\n',
         "run: transient_max (9) must be >= transient (4000)"),
        ('[params]\nbase = "paper"\n[run]\nmax_period = 0\n',
         "run.max_period: Input should be greater than or equal to 1 (got 0)"),
        ('[params]\nbase = "paper"\n[run]\nperiod_tol = "tight"\n',
         "run.period_tol: Input should be a valid number"),
    ],
)
def test_bad_study_errors_name_field(text, start):
    with pytest.raises(ValidationError) as info:
        load_study(text)
    line = format_error(info.value)
    assert line.startswith(start), line
    assert "\n" not in line


def test_run_table_settings_and_transient_in_periods():
    """[run] sets every RunSettings field it names; transient_periods is that many periods of
    the lowest forcing frequency given, and is written back without a transient."""
    text = ('[params]\nbase = "paper"\n[run]\ntransient_periods = 20\nconverge = 1e-7\n'
            "transient_max = 50000\ncontinued_transient = 100\nmax_period = 8\n"
            "period_tol = 1e-4\nperiods = 16\nsteps_per_period = 64\n")
    study = load_study(text)
    run = study.run_settings(omega=0.5)
    assert run.transient == pytest.approx(20 * 2 * math.pi / 0.5)
    assert (run.converge, run.transient_max, run.continued_transient) == (1e-7, 50000, 100)
    assert (run.max_period, run.period_tol, run.samples, run.steps_per_period) == (
        8, 1e-4, 16, 64)
    assert study.run_settings(omega=0.5, transient=7.0, max_period=3).transient == 7.0
    with pytest.raises(StudyError, match="run.transient_periods"):
        study.run_settings()
    again = load_study(study_to_toml(study))
    assert again.run == study.run and "\ntransient =" not in study_to_toml(study)
    assert load_study('[params]\nbase = "paper"\n').run_settings().transient == 4000.0


@pytest.mark.parametrize(("value", "expected"), [
    ('"none"', "none"), ('"up"', "up"), ('"down"', "down"), ("true", "up"), ("false", "none"),
])
def test_sweep_continuation_choices(value, expected):
    text = ('[params]\nbase = "paper"\n[sweep]\nstart = 1\nstop = 4\nnum = 3\n'
            f"continuation = {value}\n")
    sweep = load_study(text).sweep
    assert sweep.continuation == expected
    assert (sweep.samples, sweep.lyapunov) == (None, False)


def test_full_study_error_names_nested_field(tmp_path):
    s = Study(study=StudyInfo(name="x"), params=PlanetaryParams.paper())
    path = save_study(s, tmp_path / "s.toml")
    path.write_text(path.read_text().replace("inertia = 0.002\n", "inertia = -0.002\n"))
    with pytest.raises(ValidationError) as info:
        load_study(path)
    assert format_error(info.value) == (
        "params.outside_planet.inertia: Input should be greater than 0 (got -0.002)"
    )


def test_builtin_fig3_study():
    assert "paper_fig3" in builtin_study_names()
    res = resources.files("geardyn.studies") / "paper_fig3.toml"
    assert res.is_file()
    s = builtin_study("paper_fig3")
    assert s.planetary_params == PlanetaryParams.paper(xi1=0.05, xi2=0.05)
    assert s.plot_state == "X_sq"
    assert (s.run.transient, s.run.periods) == (4000.0, 64)
    assert s.sweep is not None
    assert (s.sweep.param, s.sweep.start, s.sweep.stop, s.sweep.num) == ("Omega", 0.1, 4.0, 1000)
    assert s.sweep.continuation == "none"
    with pytest.raises(StudyError, match="no built-in study"):
        builtin_study("fig99")


# --------------------------------------------------------------------------- NetCDF
def _dataset() -> xr.Dataset:
    t = np.linspace(0.0, 1.0, 11)
    ds = xr.Dataset(
        {
            "X_sq": ("time", np.sin(t), {"units": "1", "flag": True}),
            "poincare": (("sample", "state"), np.arange(6.0).reshape(3, 2)),
            "edge_crossings": ("event", np.array([1, 0, 3], dtype=np.int64)),
        },
        coords={
            "time": ("time", t, {"units": "1"}),
            "sample": np.arange(3),
            "state": ["X_sq", "V_sq"],
            "event": ["a-b", "a+b", "c"],
        },
        attrs={
            "Omega": 1.1,
            "steps_per_period": 90,
            "locate_edges": True,
            "note": None,
            "settings": {"a": 1, "b": [1.0, 2.0]},
            "integrator": "RK4",
        },
    )
    return ds


def test_netcdf_round_trip_identical(tmp_path):
    ds = _dataset()
    path = save_dataset(ds, tmp_path / "run.nc")
    assert path.exists()
    assert not [f for f in os.listdir(tmp_path) if f.endswith(".tmp")]  # no temp file left
    back = load_dataset(path)
    expected = ds.copy()
    expected.attrs = netcdf_attrs(ds.attrs)
    expected["X_sq"].attrs = netcdf_attrs(ds["X_sq"].attrs)
    xr.testing.assert_identical(back, expected)
    assert back.attrs["locate_edges"] == 1
    assert "note" not in back.attrs
    assert back.attrs["settings"] == '{"a": 1, "b": [1.0, 2.0]}'
    os.remove(path)  # the file is closed: nothing holds it
    assert float(back["X_sq"][3]) == pytest.approx(math.sin(0.3))


def test_netcdf_simulation_round_trip(tmp_path):
    import geardyn

    ds = geardyn.simulate(GearPair(Fa=0.2), omega=1.2,
                          run=geardyn.RunSettings(transient=20.0, samples=4))
    back = load_dataset(save_dataset(ds, tmp_path / "gp.nc"))
    xr.testing.assert_identical(back, ds)


def test_netcdf_overwrites_atomically(tmp_path):
    path = tmp_path / "run.nc"
    save_dataset(_dataset(), path)
    ds2 = _dataset().assign_attrs(Omega=2.0)
    save_dataset(ds2, path)
    assert load_dataset(path).attrs["Omega"] == 2.0


def test_netcdf_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_dataset(tmp_path / "none.nc")
    with pytest.raises(FileNotFoundError):
        save_dataset(_dataset(), tmp_path / "no" / "dir" / "x.nc")


@pytest.mark.parametrize("kind", ["catt", "gear-pair-starts-lyapunov"])
def test_netcdf_bifurcation_round_trip_identical(tmp_path, kind):
    """A real sweep, with the string variable ``contact``, the sample/state/mesh coordinates,
    the attributes the CLI adds and (gear pair) several starts and Lyapunov exponents."""
    import geardyn

    if kind == "catt":
        m = CATTDevice(PlanetaryParams.paper(xi1=0.05, xi2=0.05))
        ds = geardyn.bifurcation(m, values=[0.6, 1.1, 2.5],
                                 run=geardyn.RunSettings(transient=50.0, samples=4,
                                                         steps_per_period=64))
    else:
        g = GearPair(zeta=0.05, kappa=0.2, Fa=0.2)
        ds = geardyn.bifurcation(g, values=[0.5, 0.95, 1.3],
                                 run=geardyn.RunSettings(transient=50.0, samples=4),
                                 starts=2, lyapunov=True)
    ds.attrs.update(study="fig3", plot_state=str(ds["state"].values[0]), wall_time_s=1.25)
    back = load_dataset(save_dataset(ds, tmp_path / "bif.nc"))
    xr.testing.assert_identical(back, ds)
    assert back["contact"].dtype.kind == "U" and back["state"].dtype.kind == "U"
    assert set(np.unique(back["contact"].values)) <= {"none", "single", "double", "unbounded"}
    assert back.attrs["continuation"] == "none" and back.attrs["param"] == "Omega"
