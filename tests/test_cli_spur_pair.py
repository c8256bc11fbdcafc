"""The ``spur_pair`` study model: every command that runs a study's model runs the shipped
``spur_pair_cracked`` study (small sizes), writes its NetCDF and figure, and gives what the
Python API gives on the same pair built here by hand (``SpurPair.from_geometry`` of the same
literal inputs, speeds in rad/s, not through the study); the speed axis is labelled in the
study's unit (rpm)."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest
from pydantic import ValidationError

import geardyn
import geardyn.gears as g
from geardyn.cli.main import main
from geardyn.errors import ParameterError
from geardyn.io.netcdf import load_dataset
from geardyn.io.toml import builtin_study, load_study, load_study_dict, spur_pair_table
from geardyn.models.spur_pair_coefficients import INPUTS
from geardyn.study import build_model

STUDY = "spur_pair_cracked"
RPM = 2.0 * math.pi / 60.0  # rad/s per rpm
SPEED_RPM = 18000.0  # the study's params.speed
TRANSIENT_PERIODS = 20  # the study's run.transient_periods


@pytest.fixture(scope="module")
def by_hand() -> geardyn.SpurPair:
    """The shipped study's pair, from its literal values: 19/48, m 3.2 mm, 20 deg, b 16 mm,
    bores 12 and 35 mm, pinion tooth 9 cracked 2 mm at 45 deg, 64 angles per mesh cycle; 20 N m,
    zeta 0.05, b = 10 um, 76 harmonics; speed in rad/s."""
    mesh = g.GearMesh(g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                      g.SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    return geardyn.SpurPair.from_geometry(
        mesh, bore_radius=("12 mm", "35 mm"), speed=SPEED_RPM * RPM, torque=20.0, zeta=0.05,
        backlash=10e-6, harmonics=76, angles=64, young="206.8 GPa", poisson=0.3,
        faults=g.RootCrack("2 mm", "45 deg", gear="pinion", tooth=9))


def run(capsys, *args) -> subprocess.CompletedProcess:
    """``geardyn ARGS`` in this process (the console script's code path)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in args])
    out = capsys.readouterr()
    return subprocess.CompletedProcess(args, info.value.code, out.out, out.err)


def assert_same(got: np.ndarray, want: np.ndarray, name: str) -> None:
    """The same values: the same bytes for numbers (NaN where NaN), equal strings."""
    if want.dtype.kind in "US":
        assert np.array_equal(got.astype(str), want.astype(str)), name
    else:
        assert got.dtype == want.dtype and got.tobytes() == want.tobytes(), name


def transient(omega_low: float) -> float:
    """The study's transient: 20 forcing periods at the lowest Omega of the run."""
    return TRANSIENT_PERIODS * 2.0 * math.pi / omega_low


def test_the_study_builds_the_pair_by_hand(by_hand):
    model = build_model(builtin_study(STUDY))
    assert isinstance(model, geardyn.SpurPair)
    assert model.params.tobytes() == by_hand.params.tobytes()
    assert model.speed_unit == "rpm"
    assert model.omega == by_hand.omega == SPEED_RPM * RPM  # one pinion revolution per period
    assert model.drive_series.tobytes() == by_hand.drive_series.tobytes()


def test_simulate(tmp_path, capsys, by_hand):
    out, fig = tmp_path / "sim.nc", tmp_path / "sim.png"
    r = run(capsys, "simulate", STUDY, "--periods", 4, "--out", out, "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert fig.stat().st_size > 0
    om = by_hand.omega
    api = geardyn.simulate(by_hand, omega=om,
                           run=geardyn.RunSettings(transient=transient(om), samples=4))
    got = load_dataset(out)
    for name in ("x", "v", "F", "poincare"):
        assert_same(got[name].values, api[name].values, name)


def test_bifurcation_in_rpm(tmp_path, capsys, by_hand):
    """A speed sweep in rpm across the primary resonance: the axis in rpm as given, the
    contact lost inside the range and kept at its ends, the API's points bitwise."""
    out, fig = tmp_path / "bif.nc", tmp_path / "bif.png"
    rpm = np.linspace(14000.0, 24000.0, 6)
    r = run(capsys, "bifurcation", STUDY, "--range", "14000:24000:6", "--samples", 4,
            "--out", out, "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert fig.stat().st_size > 0
    got = load_dataset(out)
    assert got["speed"].attrs["units"] == "rpm"
    assert np.array_equal(got["speed"].values, rpm)
    api = geardyn.bifurcation(by_hand, "speed", rpm * RPM,
                              run=geardyn.RunSettings(transient=transient(rpm[0] * RPM),
                                                      samples=4))
    assert api["speed"].attrs["units"] == "rad/s"
    for name in ("poincare", "period", "contact", "dynamic_factor"):
        assert_same(got[name].values, api[name].values, name)
    contact = [str(c) for c in got["contact"].values[:, 0]]
    assert contact[0] == "none" and "single" in contact[1:-1], contact


def test_frc_over_speed(tmp_path, capsys, by_hand):
    out, fig = tmp_path / "frc.nc", tmp_path / "frc.png"
    rpm = np.linspace(14000.0, 24000.0, 6)
    r = run(capsys, "frc", STUDY, "--range", "14000:24000:6", "--samples", 4, "--out", out,
            "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert fig.stat().st_size > 0
    omegas = np.array([by_hand.with_params(speed=v * RPM).omega for v in rpm])
    api = geardyn.frequency_response(
        by_hand, omegas, geardyn.RunSettings(transient=transient(omegas[0]), samples=4))
    got = load_dataset(out)
    assert np.array_equal(got["input_speed"].values, api["input_speed"].values)
    assert got["input_speed"].attrs["units"] == "rpm"
    for name in ("dte_rms", "contact", "period"):
        assert_same(got[name].values, api[name].values, name)


def test_map_speed_by_torque(tmp_path, capsys, by_hand):
    out, fig = tmp_path / "map.nc", tmp_path / "map.png"
    r = run(capsys, "map", STUDY, "--x", "speed:14000:24000:3", "--y", "torque:10:30:2",
            "--samples", 4, "--out", out, "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert fig.stat().st_size > 0
    rpm = np.linspace(14000.0, 24000.0, 3)
    api = geardyn.map2d(by_hand, ("speed", rpm * RPM), ("torque", np.array([10.0, 30.0])),
                        geardyn.RunSettings(transient=transient(rpm[0] * RPM), samples=4))
    got = load_dataset(out)
    assert got["speed"].attrs["units"] == "rpm"
    assert np.array_equal(got["speed"].values, rpm)
    for name in ("period", "contact", "force_rms"):
        assert_same(got[name].values, api[name].values, name)


def test_basins(tmp_path, capsys, by_hand):
    """At the study's speed: every start of a small grid ends on one period-1 attractor, whose
    section point is the one simulate reaches from rest (an independent run, its own
    transient)."""
    out, fig = tmp_path / "bas.nc", tmp_path / "bas.png"
    r = run(capsys, "basins", STUDY, "--x", "x:-2e-5:4e-5:3", "--y", "v:-0.1:0.1:2",
            "--samples", 4, "--out", out, "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert fig.stat().st_size > 0
    got = load_dataset(out)
    assert got.sizes["attractor"] == 1 and int(got["attractor_period"].values[0]) == 1
    om = by_hand.omega
    sim = geardyn.simulate(by_hand, omega=om,
                           run=geardyn.RunSettings(transient=200 * 2 * math.pi / om, samples=2))
    ref = sim["poincare"].values[-1]
    point = got["attractor_point"].values[0, 0]
    assert np.allclose(point, ref, rtol=1e-6, atol=1e-6 * np.abs(ref))


def test_continue_over_speed(tmp_path, capsys, by_hand):
    """A short period-1 branch in speed (rpm): the axis in rpm, and its first orbit's section
    point is the one simulate reaches at that speed (the stable orbit, an independent run)."""
    out, fig = tmp_path / "br.nc", tmp_path / "br.png"
    r = run(capsys, "continue", STUDY, "--range", "14000:15000", "--max-points", 3,
            "--out", out, "--plot", fig)
    assert r.returncode == 0, r.stderr
    assert fig.stat().st_size > 0
    got = load_dataset(out)
    assert got["speed"].attrs["units"] == "rpm"
    assert got["speed"].values[0] == 14000.0
    om = by_hand.with_params(speed=14000.0 * RPM).omega
    sim = geardyn.simulate(by_hand, omega=om,
                           run=geardyn.RunSettings(transient=200 * 2 * math.pi / om, samples=2))
    ref = sim["poincare"].values[-1]
    assert np.allclose(got["section_point"].values[0], ref, rtol=1e-6,
                       atol=1e-6 * np.abs(ref))


# ---------------------------------------------------------------------------------------------
# the study table

def test_params_table_is_the_declared_inputs():
    """One field per declared input of SpurPair, and SpurPair.__init__ / from_geometry take
    each of them with the declared default."""
    import inspect

    table = spur_pair_table()
    assert list(table.model_fields) == [i.name for i in INPUTS]
    sig = {**inspect.signature(geardyn.SpurPair.__init__).parameters,
           **inspect.signature(geardyn.SpurPair.from_geometry).parameters}
    for i in INPUTS:
        assert i.name in sig, i.name
        assert sig[i.name].default == (inspect.Parameter.empty if i.required else i.default), \
            i.name


def _document(**params: object) -> dict:
    """The shipped study as a TOML document, with ``params`` changed."""
    import tomllib

    from geardyn.io.toml import builtin_study_text

    doc = tomllib.loads(builtin_study_text(STUDY))
    doc["params"].update(params)
    return doc


@pytest.mark.parametrize(("key", "value"), [
    ("stiffnes", 1.0), ("inertia", [1e-3]), ("harmonics", 0), ("period", "axle"),
    ("zeta", -0.1), ("torque", "20 N"), ("speed_unit", "rad/min"), ("speed", "50 N"),
    ("speed", -1.0), ("speed", "-3 rpm"), ("backlash", "-1 um"),
])
def test_bad_params_name_the_field(key, value):
    with pytest.raises(ValidationError) as err:
        load_study_dict(_document(**{key: value}))
    assert [e["loc"][:2] for e in err.value.errors()] == [("params", key)], err.value


def test_unit_strings_are_read():
    s = load_study_dict(_document(inertia=["4.3659e-4 kg m^2", "8.3602e-3 kg*m**2"],
                                  torque="0.02 kN m", backlash="0.01 mm"))
    model = build_model(s)
    assert model.inertia == (4.3659e-4, 8.3602e-3)
    assert model.mean_force() == 20.0 / model.mesh.pinion.base_radius
    assert model.coefficient_values()["backlash"] == 1e-5


def test_errors_when_building_name_the_field(tmp_path, capsys):
    import tomli_w

    doc = _document()
    doc["stiffness"]["cycles"] = 5
    path = tmp_path / "s.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    with pytest.raises(ParameterError, match="19 mesh cycles") as err:
        build_model(load_study(path))
    assert err.value.field == "stiffness.cycles"
    r = run(capsys, "simulate", path, "--periods", 2)
    assert r.returncode == 2 and "stiffness.cycles" in r.stderr


def test_a_spur_pair_study_needs_its_gears():
    with pytest.raises(ValidationError, match="gears"):
        load_study('[study]\nmodel = "spur_pair"\n[params]\nspeed = 100.0\ntorque = 10.0\n')


def test_params_show(capsys, by_hand):
    r = run(capsys, "params", "show", STUDY)
    assert r.returncode == 0, r.stderr
    wn = math.sqrt(by_hand.drive_series[0] / by_hand.coefficient_values()["mass"])
    assert f"sqrt(k_mean / m) = {wn:.6g} rad/s" in r.stdout
    assert "18000 rpm" in r.stdout and "19 mesh cycles per forcing period" in r.stdout


def test_default_transient_is_in_forcing_periods(by_hand):
    """Without [run], a spur pair study's transient is 50 forcing periods of the run's lowest
    Omega (not [run].transient's 4000, a dimensionless time: 4000 s here)."""
    doc = _document()
    del doc["run"]
    s = load_study_dict(doc)
    om = by_hand.omega
    assert s.run_settings(omega=om).transient == pytest.approx(50 * 2 * math.pi / om,
                                                               rel=1e-15)


def test_save_and_load_round_trip(tmp_path, by_hand):
    from geardyn.io.toml import save_study

    save_study(builtin_study(STUDY), tmp_path / "s.toml")
    again = load_study(tmp_path / "s.toml")
    assert build_model(again).params.tobytes() == by_hand.params.tobytes()


def test_explorer_overrides_and_sweeps_speed(tmp_path, by_hand):
    """The explorer on the study: a speed window in rpm without [run].omega, a torque override
    as the study file would give it, the diagram's axis in rpm."""
    from geardyn.cli.errors import format_error
    from geardyn.explore.compute import compute_diagram, diagram_view
    from geardyn.explore.state import ExplorerState, Window

    st = ExplorerState(builtin_study(STUDY), STUDY, window=Window(14000.0, 24000.0, 2),
                       save_dir=tmp_path, describe_error=format_error)
    assert "torque" in st.main_params()
    assert st.set_override("torque", "30 N m") is None
    assert st.model.params.tobytes() == by_hand.with_params(torque=30.0).params.tobytes()
    assert "N*m" in st.set_override("torque", "30 N")
    ds = compute_diagram(st.diagram_request())
    assert ds["speed"].attrs["units"] == "rpm"
    assert np.array_equal(ds["speed"].values, [14000.0, 24000.0])
    assert diagram_view(ds).x.size == 2 * ds.sizes["sample"]


def test_the_bifurcation_figure_labels_the_states_unit(tmp_path, by_hand):
    """x [m], not dimensionless: the sweep records the model's state units."""
    from geardyn.plotting.bifurcation import plot_bifurcation

    ds = geardyn.bifurcation(by_hand, "speed", np.array([14000.0, 15000.0]) * RPM,
                             run=geardyn.RunSettings(transient=0.01, samples=2))
    assert ds.attrs["state_units"] == "m, m/s"
    fig = plot_bifurcation(ds, state="v")
    assert "[m/s]" in fig.axes[0].get_ylabel()
