"""The explorer's server logic without a browser: the view state (window, history, overrides
validated as study files are), the computations (a window's diagram, one orbit), the reproducing
command, saving, and the worker where a new request supersedes the running one."""

from __future__ import annotations

import shlex
import threading

import numpy as np
import pytest

import geardyn
from geardyn.cli.errors import format_error
from geardyn.explore.compute import (
    compute_diagram,
    compute_orbit,
    diagram_view,
    orbit_request,
)
from geardyn.explore.runner import Runner
from geardyn.explore.state import ExplorerState, Window
from geardyn.io.toml import builtin_study, load_study

#: A tiny gear-pair study: few points, short runs (the kernels are the warmed GearPair ones).
STUDY = """
[study]
name = "gp"
model = "gear_pair"
[params]
zeta = 0.1
kappa = 0.2
Fa = 0.1
[run]
transient = 200.0
[sweep]
param = "Omega"
start = 1.6
stop = 2.4
num = 6
samples = 8
"""


@pytest.fixture()
def state(tmp_path):
    study = load_study(STUDY)
    return ExplorerState(study, "gp.toml", save_dir=tmp_path / "saved",
                         describe_error=format_error)


def test_the_first_window_is_the_studys_sweep(state):
    assert state.param == "Omega"
    assert state.window == Window(1.6, 2.4, 6)
    assert state.continuation == "none" and state.history == []


def test_zoom_keeps_the_number_of_points_and_back_returns(state):
    assert state.zoom(1.9, 1.7000000001) is None  # ends sorted, rounded to the width
    assert state.window == Window(1.7, 1.9, 6)
    assert state.zoom(1.75, 1.8) is None
    assert len(state.history) == 2
    assert state.back() and state.window == Window(1.7, 1.9, 6)
    assert state.back() and state.window == Window(1.6, 2.4, 6)
    assert not state.back()


@pytest.mark.parametrize("ends", [(1.7, 1.7), (-1.0, 1.0), (float("nan"), 2.0)])
def test_an_invalid_zoom_says_why_and_changes_nothing(state, ends):
    before = state.snapshot()
    msg = state.zoom(*ends)
    assert msg is not None and msg.startswith("window:")
    assert state.snapshot() == before


def test_an_invalid_parameter_shows_the_validation_message_and_changes_nothing(state):
    model = state.model
    msg = state.set_override("zeta", "-0.5")
    assert msg == "params.zeta: Input should be greater than or equal to 0 (got -0.5)"
    assert state.overrides == {} and state.model is model
    assert state.set_override("kappa", "1.5").startswith("params.kappa: ")
    assert state.set_override("Fm", "1") == "Fm: not a parameter of this explorer"
    assert state.model is model


def test_a_valid_parameter_changes_the_model_as_the_study_file_would(state):
    from geardyn.study import build_model

    assert state.set_override("zeta", "0.08") is None
    assert state.overrides == {"zeta": 0.08}
    expected = build_model(load_study(STUDY.replace("zeta = 0.1", "zeta = 0.08")))
    np.testing.assert_array_equal(state.model.params, expected.params)
    assert state.current_value("zeta") == 0.08 and state.current_value("Fa") == 0.1


#: A new value of each study kind's first main parameter: the control's text and its SI value.
_FIRST_CONTROL = {"xi1": ("0.07", 0.07), "zeta": ("0.07", 0.07), "torque": ("25", 25.0),
                  "sun_backlash": ("12 um", 12e-6), "backlash": ("25 um", 25e-6)}


def _kind_study(kind: str):
    from geardyn.io.study_models import STUDY_MODELS

    example = STUDY_MODELS[kind].example
    return load_study(example) if "\n" in example else builtin_study(example)


def _explore(study) -> ExplorerState:
    window = Window(0.9, 1.1, 3) if study.sweep is None else None
    return ExplorerState(study, "x.toml", window=window, describe_error=format_error)


@pytest.mark.parametrize("kind", ["catt", "gear_pair", "spur_pair", "planetary", "train"])
def test_every_study_kind_takes_a_main_parameter_as_with_params_does(kind):
    """A main parameter's control rebuilds the model as ``with_params`` of that input does, for
    every registered study kind (the kind's declarations say where the value goes in
    ``[params]``: by name, or as a change of the paper's device)."""
    from geardyn.io.study_models import STUDY_MODELS
    from geardyn.study import build_model

    assert set(STUDY_MODELS) == {"catt", "gear_pair", "spur_pair", "planetary", "train"}
    study = _kind_study(kind)
    state = _explore(study)
    name = state.main_params()[0]
    text, value = _FIRST_CONTROL[name]
    assert state.set_override(name, text) is None
    base = build_model(study)
    expected = base.with_params(**{name: value}).params
    assert not np.array_equal(base.params, expected)
    np.testing.assert_array_equal(state.model.params, expected)


def test_the_full_device_parameters_take_a_main_parameter():
    """A ``catt`` study whose ``[params]`` is the device's PlanetaryParams in full (not
    ``base = "paper"``): a control changes that field."""
    from geardyn.io.toml import Study

    doc = builtin_study("paper_fig3").to_toml_dict()
    doc["params"] = geardyn.PlanetaryParams.paper().model_dump(exclude_none=True)
    study = Study.model_validate(doc)
    state = _explore(study)
    assert state.set_override("xi1", "0.07") is None
    expected = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.07))
    np.testing.assert_array_equal(state.model.params, expected.params)


def test_device_parameters_take_paper_names_and_unit_strings():
    state = ExplorerState(builtin_study("paper_fig3"), "paper_fig3",
                          describe_error=format_error)
    assert state.main_params() == ("xi1", "xi2", "backlash", "error", "B1", "Lambda")
    assert state.set_override("backlash", "30 um") is None
    p = state.effective_study.planetary_params
    assert p.sun_mesh.backlash == pytest.approx(30e-6)
    assert p.planet_mesh.backlash == pytest.approx(30e-6)
    assert state.current_value("xi1") == 0.05
    msg = state.set_override("xi1", "0.1 m")
    assert msg is not None and "xi1" in msg and state.overrides == {"backlash": "30 um"}
    assert state.set_interpretation("as-printed") is None
    assert state.model.interpretation == "as-printed"
    assert state.set_interpretation("other").startswith("interpretation: must be one of")
    assert state.set_continuation("sideways").startswith("continuation: must be one of")
    assert state.set_continuation("up") is None and state.continuation == "up"
    cmd = shlex.split(state.command())
    assert cmd[:3] == ["geardyn", "bifurcation", str(state.study_file())]
    assert cmd[cmd.index("--interpretation") + 1] == "as-printed"
    assert cmd[cmd.index("--continuation") + 1] == "up"


def test_the_orbit_shows_the_diagrams_point_and_its_floquet_multipliers(state):
    req = state.diagram_request()
    reports = []
    ds = compute_diagram(req, lambda done, total: reports.append((done, total)))
    assert reports and reports[-1] == (6, 6)
    view = diagram_view(ds)
    assert view.x.size == 6 * 8 and set(view.contact) == {"mesh"}
    period = ds["period"].values
    assert np.any(period == 1), period  # the test needs a period-1 point
    i = int(np.flatnonzero(period == 1)[0])
    value = float(ds["Omega"].values[i])
    orbit = compute_orbit(orbit_request(req, ds, value + 0.01))  # nearest value
    assert orbit.value == value and orbit.period == 1 and orbit.status == "ok"
    # simulate (the trajectory kernel; its first section point is the transient's end) gives
    # the Poincare points the sweep kernel gave
    np.testing.assert_allclose(orbit.section_x[-8:], ds["poincare"].sel(state="x").values[i],
                               rtol=1e-9, atol=1e-12)
    assert orbit.time.size == orbit.x.size == orbit.v.size > 8
    assert "Ω" in [label for _, _, label in orbit.peaks]
    # the attractor found by simulation is a stable period-1 orbit: multipliers inside the
    # unit circle, their product exp(-2 zeta * T) for x'' + 2 zeta x' + ... (Liouville)
    assert orbit.multipliers is not None and orbit.stability == "stable"
    assert np.all(np.abs(orbit.multipliers) < 1)
    period_time = 2 * np.pi / value
    assert np.prod(orbit.multipliers).real == pytest.approx(np.exp(-2 * 0.1 * period_time),
                                                            rel=1e-6)
    assert "Floquet multipliers (stable)" in orbit.summary()


def test_the_command_line_reproduces_the_saved_view(state, tmp_path):
    from geardyn.cli.main import main
    from geardyn.io.netcdf import load_dataset

    assert state.set_override("zeta", "0.12") is None
    assert state.zoom(1.8, 2.2) is None
    ds = compute_diagram(state.diagram_request())
    paths = state.save(ds)
    names = sorted(p.name for p in paths)
    assert names == ["gp-explore.toml", "gp_Omega_1.8-2.2_6.command.txt",
                     "gp_Omega_1.8-2.2_6.nc", "gp_Omega_1.8-2.2_6.png"]
    saved = load_dataset(state.save_dir / "gp_Omega_1.8-2.2_6.nc")
    command = shlex.split(saved.attrs["command"])
    assert command[:3] == ["geardyn", "bifurcation", str(state.study_file())]
    out, plot = tmp_path / "cli.nc", tmp_path / "cli.png"
    args = command[1:command.index("--out")] + ["--quiet", "--out", str(out), "--plot", str(plot)]
    with pytest.raises(SystemExit) as stop:
        main(args)
    assert stop.value.code == 0
    again = load_dataset(out)
    np.testing.assert_array_equal(again["poincare"].values, saved["poincare"].values)
    np.testing.assert_array_equal(again["Omega"].values, np.linspace(1.8, 2.2, 6))
    assert plot.stat().st_size > 0


def test_a_new_request_supersedes_the_running_one():
    runner = Runner()
    started, release = threading.Event(), threading.Event()
    done, errors = [], []

    def slow(progress):
        started.set()
        release.wait(10)
        progress(1, 2)  # superseded by now: stops here
        return "first"

    runner.submit(slow, done.append, errors.append, key="diagram")
    assert started.wait(10)
    runner.submit(lambda progress: "orbit", done.append, errors.append, key="orbit")
    runner.submit(lambda progress: "second", done.append, errors.append, key="diagram")
    release.set()
    runner.wait(10)
    assert done == ["orbit", "second"] and errors == []


def test_a_failure_is_reported_and_nothing_else():
    runner = Runner(describe_error=lambda exc: f"failed: {exc}")
    done, errors = [], []

    def fails(progress):
        raise ValueError("no good")

    gen = runner.submit(fails, done.append, errors.append)
    runner.wait(10)
    assert done == [] and errors == ["failed: no good"] and runner.current(gen)


def test_only_a_non_local_address_is_warned_about(tmp_path):
    from geardyn.explore.server import host_warning

    assert host_warning("127.0.0.1", tmp_path) is None
    assert host_warning("localhost", tmp_path) is None
    warning = host_warning("0.0.0.0", tmp_path)
    assert warning.startswith("warning: serving on 0.0.0.0") and str(tmp_path) in warning


def test_explore_refuses_a_bad_range_in_one_line(capsys):
    from geardyn.cli.main import main

    with pytest.raises(SystemExit) as stop:
        main(["explore", "paper_fig3", "--range", "1:1:10"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: --range: START and STOP must differ (got '1:1:10')"]


# ---------------------------------------------------------------------- the page, without browser
@pytest.fixture()
def session(state, monkeypatch):
    """The page's session on a plain Bokeh document; results are applied at once (no server
    loop), from the worker thread."""
    from bokeh.document import Document

    from geardyn.explore import app

    ds = compute_diagram(state.diagram_request())
    page = app.ExplorerSession(Document(), state, ds, format_error)
    monkeypatch.setattr(page, "_later", lambda fn, *args: fn(*args))
    yield page
    page.runner.shutdown()


def _points(page) -> list:
    return sorted((float(x), float(y)) for src in page.point_sources.values()
                  for x, y in zip(src.data["x"], src.data["y"], strict=True))


def test_the_page_shows_the_diagram_and_refuses_an_invalid_value(session):
    before = _points(session)
    assert len(before) == 6 * 8
    assert session.band_sources["mesh"].data["color"]  # the contact bands
    assert "--range 1.6:2.4:6" in session.command.text
    session._on_param("zeta", "value", "0.1", "-1")
    assert "params.zeta: Input should be greater than or equal to 0" in \
        session.input_messages["zeta"].text
    assert session.state.overrides == {} and session._pending is None  # nothing recomputed
    assert _points(session) == before


def test_a_failed_computation_keeps_the_last_good_view(session, monkeypatch):
    from geardyn.explore import app

    before = _points(session)

    def fails(request, progress=None):
        raise ValueError("the kernel refused")

    monkeypatch.setattr(app, "compute_diagram", fails)
    session._on_param("zeta", "value", "0.1", "0.2")
    session.runner.wait(30)
    assert "computation failed: the kernel refused; the last good view is kept" in \
        session.message.text
    assert _points(session) == before and session.progress.text.startswith("ready")
    # the state and the controls are back at the view shown
    assert session.state.overrides == {} and session.inputs["zeta"].value == "0.1"
    session._zoom(1.7, 1.9, session.window_message)
    session.runner.wait(30)
    assert session.state.window == Window(1.6, 2.4, 6) and session.state.history == []
    assert "--range 1.6:2.4:6" in session.command.text


def test_a_new_window_supersedes_the_running_computation(session, monkeypatch):
    from geardyn.explore import app

    started, release, calls = threading.Event(), threading.Event(), []
    real = app.compute_diagram

    def slow_first(request, progress=None):
        calls.append(request.window)
        if len(calls) == 1:
            started.set()
            release.wait(30)
        return real(request, progress)

    monkeypatch.setattr(app, "compute_diagram", slow_first)
    session._zoom(1.7, 2.3, session.window_message)
    assert started.wait(30)
    session._zoom(1.8, 2.0, session.window_message)  # while the first runs
    release.set()
    session.runner.wait(60)
    assert calls[0] == Window(1.7, 2.3, 6)  # started, stopped at its first progress report
    assert session.request.window == Window(1.8, 2.0, 6)
    xs = sorted({x for x, _ in _points(session)})
    np.testing.assert_allclose(xs, np.linspace(1.8, 2.0, 6))
    assert "--range 1.8:2:6" in session.command.text


def test_a_click_fills_the_orbit_panels(session):
    from types import SimpleNamespace

    session._on_tap(SimpleNamespace(x=2.05))
    session.runner.wait(60)
    assert session.marker.data["x"] == [pytest.approx(2.08)]  # nearest of 1.6, 1.76, ..., 2.4
    assert session.orbit_text.text.startswith("Omega = 2.08: ")
    for name in ("time", "phase", "section", "spectrum", "peaks"):
        assert len(next(iter(session.orbit_sources[name].data.values()))) > 0, name
    assert "Ω" in session.orbit_sources["peaks"].data["label"]


def test_another_parameter_is_swept_at_the_studys_omega():
    study = load_study(STUDY.replace("[run]", "[run]\nomega = 2.0"))
    state = ExplorerState(study, "gp.toml", "zeta", Window(0.05, 0.15, 3),
                          describe_error=format_error)
    assert state.main_params() == ("kappa", "Fa", "backlash")  # the swept one left out
    req = state.diagram_request()
    ds = compute_diagram(req)
    np.testing.assert_allclose(ds["zeta"].values, [0.05, 0.1, 0.15])
    orbit = compute_orbit(orbit_request(req, ds, 0.11))
    assert orbit.param == "zeta" and orbit.value == pytest.approx(0.1) and orbit.omega == 2.0
    # the orbit's model is the study's with zeta = 0.1: the diagram's point at 0.1
    np.testing.assert_allclose(orbit.section_x[-8:], ds["poincare"].sel(state="x").values[1],
                               rtol=1e-9, atol=1e-12)
    with pytest.raises(Exception, match="--param"):
        ExplorerState(load_study(STUDY), "gp.toml", "zeta", Window(0.05, 0.15, 3))


def test_unbounded_values_are_marked_on_top_of_the_diagram():
    import xarray as xr

    values = np.array([1.0, 2.0, 3.0])
    poincare = np.array([[[0.1], [0.2]], [[np.nan], [np.nan]], [[0.5], [0.3]]])
    ds = xr.Dataset(
        {"poincare": (("Omega", "sample", "state"), poincare),
         "period": ("Omega", [1, -1, 0]),
         "contact": (("Omega", "mesh"), [["none"], ["unbounded"], ["single"]])},
        coords={"Omega": values, "state": ["x"], "mesh": ["mesh"]}, attrs={"param": "Omega"})
    view = diagram_view(ds)
    assert sorted(zip(view.x, view.y, view.period_class, strict=True)) == [
        (1.0, 0.1, 1), (1.0, 0.2, 1), (2.0, 0.5, -1), (3.0, 0.3, 0), (3.0, 0.5, 0)]
    assert list(view.contact["mesh"]) == ["none", "unbounded", "single"]


def test_an_override_keeps_a_transient_in_forcing_periods(tmp_path):
    """A study that gives run.transient_periods: an override rebuilds it as the file says
    (transient_periods alone), not with the table's default transient beside it."""
    study = load_study(STUDY.replace("transient = 200.0", "transient_periods = 30"))
    st = ExplorerState(study, "gp.toml", save_dir=tmp_path, describe_error=format_error)
    assert st.set_override("zeta", "0.08") is None
    assert st.effective_study.run.transient_periods == 30
    assert st.run_settings().transient == pytest.approx(30 * 2 * np.pi / 1.6, rel=1e-15)


# ---------------------------------------------------------------------- a model built from geometry
#: The shipped cracked 19/48 spur pair at small sizes: 16 angles per mesh cycle, 38 harmonics,
#: short runs; the window is 3 speeds in rpm.
SPUR_WINDOW = Window(16000.0, 20000.0, 3)
RPM = 2.0 * np.pi / 60.0


def _spur_study():
    from geardyn.io.toml import builtin_study_text

    text = builtin_study_text("spur_pair_cracked")
    for old, new in (("angles = 64", "angles = 16"), ("harmonics = 76", "harmonics = 38"),
                     ("transient_periods = 20", "transient_periods = 5"),
                     ("periods = 32", "periods = 4")):
        assert old in text, old
        text = text.replace(old, new)
    return load_study(text)


@pytest.fixture()
def spur(tmp_path):
    return ExplorerState(_spur_study(), "spur_pair_cracked", window=SPUR_WINDOW,
                         save_dir=tmp_path / "saved", describe_error=format_error)


def _spur_by_hand(*faults, pinion_bore="12 mm"):
    """The study's pair from its literal values (not through the study or the explorer):
    19/48, m 3.2 mm, 20 deg, b 16 mm, bores 12 (or ``pinion_bore``) and 35 mm, steel; 16
    angles per mesh cycle over one pinion revolution (19 mesh cycles)."""
    import geardyn.gears as g

    mesh = g.GearMesh(g.SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                      g.SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
    kw = {"bore_radius": (pinion_bore, "35 mm"), "angles": 16, "young": "206.8 GPa",
          "poisson": 0.3, "faults": faults}
    return mesh, kw


def _spur_model_by_hand(*faults, pinion_bore="12 mm"):
    import geardyn

    mesh, kw = _spur_by_hand(*faults, pinion_bore=pinion_bore)
    return geardyn.SpurPair.from_geometry(
        mesh, **kw, speed=18000.0, speed_unit="rpm", torque=20.0, zeta=0.05, backlash=10e-6,
        harmonics=38)


def test_a_geometry_model_offers_its_faults_and_bores_as_controls(spur):
    """The controls of the cracked pair: the bores, then the crack's gear and numeric fields
    (from the RootCrack dataclass: depth, angle, tooth), by their study-file keys, with the
    study's values; a gear-pair study has none."""
    assert spur.geometry_params() == ("gears.pinion.bore_radius", "gears.wheel.bore_radius",
                                      "faults[0].kind", "faults[0].gear", "faults[0].depth",
                                      "faults[0].angle", "faults[0].tooth")
    assert spur.choices("faults[0].gear") == ("pinion", "wheel")
    assert spur.current_value("faults[0].depth") == "2 mm"
    assert spur.current_value("faults[0].tooth") == 9
    assert spur.current_value("gears.pinion.bore_radius") == pytest.approx(0.012, rel=1e-15)
    assert "harmonics" in spur.main_params()
    assert "harmonics" in spur.param_help("harmonics")
    assert "crack on the pinion" in spur.param_help("faults[0].depth")
    assert ExplorerState(load_study(STUDY), "gp.toml").geometry_params() == ()


def test_a_crack_depth_rebuilds_the_model_as_from_geometry_by_hand(spur):
    """A new crack depth through the explorer's state: the model's coefficients are those of
    SpurPair.from_geometry of the pair built here with that crack (bitwise), the diagram is the
    one geardyn.bifurcation gives on that model, and it differs from the healthy pair's."""
    import geardyn
    import geardyn.gears as g

    assert spur.set_override("faults[0].depth", "1.5 mm") is None
    crack = g.RootCrack("1.5 mm", "45 deg", gear="pinion", tooth=9)
    by_hand = _spur_model_by_hand(crack)
    assert spur.model.params.tobytes() == by_hand.params.tobytes()
    req = spur.diagram_request()
    cracked = compute_diagram(req)
    speeds = SPUR_WINDOW.values()
    api = geardyn.bifurcation(by_hand, "speed", speeds, req.run)
    assert cracked["poincare"].values.tobytes() == api["poincare"].values.tobytes()
    healthy_model = _spur_model_by_hand()
    assert not np.array_equal(healthy_model.params, by_hand.params)
    healthy = geardyn.bifurcation(healthy_model, "speed", speeds, req.run)
    assert np.all(np.isfinite(cracked["poincare"].values))
    assert not np.allclose(cracked["poincare"].values, healthy["poincare"].values,
                           rtol=1e-6, atol=0.0)
    # a zero-depth crack is the healthy pair, bitwise
    assert spur.set_override("faults[0].depth", "0 mm") is None
    assert spur.model.params.tobytes() == healthy_model.params.tobytes()


def test_an_invalid_geometry_value_names_its_field_and_changes_nothing(spur):
    model = spur.model
    msg = spur.set_override("faults[0].depth", "5 mm")  # reach 3.5 mm > root half thickness
    assert msg.startswith("faults[0].depth: the crack reaches 0.003536 m across the tooth, "
                          "past its centre line"), msg
    assert spur.set_override("faults[0].depth", "-1").startswith("faults[0].depth: must be")
    assert spur.set_override("gears.pinion.bore_radius", "30 mm").startswith(
        "gears.pinion.bore_radius: must lie between 0 and the root radius")
    assert spur.set_override("faults[1].depth", "1 mm") == \
        "faults[1].depth: not a parameter of this explorer"
    assert spur.overrides == {} and spur.model is model


def test_the_stiffness_panel_is_the_potential_energy_stiffness(spur):
    """The panel's tables are potential_energy_stiffness of the same geometry (computed here),
    its series a direct Fourier sum of them cut after the model's harmonics."""
    import geardyn.gears as g
    from geardyn.explore.compute import stiffness_view

    assert spur.set_override("faults[0].depth", "1 mm") is None
    assert spur.set_override("gears.pinion.bore_radius", "15 mm") is None
    view = stiffness_view(spur.model).meshes[0]
    crack = g.RootCrack("1 mm", "45 deg", gear="pinion", tooth=9)
    mesh, kw = _spur_by_hand(crack, pinion_bore="15 mm")
    table = g.potential_energy_stiffness(mesh, **kw, cycles=19)
    np.testing.assert_array_equal(view.cycle, table["cycle"].values)
    np.testing.assert_array_equal(view.drive, table["mesh_stiffness"].values)
    np.testing.assert_array_equal(view.coast, table["mesh_stiffness_coast"].values)
    whole = stiffness_view(spur.model)
    assert whole.harmonics == 38 and "root crack on pinion tooth 9" in whole.faults
    assert view.faulty
    theta = 2 * np.pi * view.cycle / 19
    h = np.arange(1, 39)[:, None]
    for k, series in ((view.drive, view.drive_series), (view.coast, view.coast_series)):
        a = 2 * np.mean(k * np.cos(h * theta), axis=1)
        b = 2 * np.mean(k * np.sin(h * theta), axis=1)
        direct = np.mean(k) + a @ np.cos(h * theta) + b @ np.sin(h * theta)
        np.testing.assert_allclose(series, direct, rtol=0, atol=1e-10 * np.mean(k))
    # the crack is felt: the panel changes with its depth, and a gear pair has no panel
    assert spur.set_override("faults[0].depth", "2 mm") is None
    deeper = stiffness_view(spur.model).meshes[0]
    assert np.min(deeper.drive) < np.min(view.drive)
    assert stiffness_view(ExplorerState(load_study(STUDY), "gp.toml").model) is None


def test_save_writes_the_changed_geometry_into_the_study_file(spur, tmp_path):
    """Save's study file holds the new crack depth, tooth and bore: loaded back with the study
    loader it builds the explorer's model bitwise, and its command reproduces the view."""
    from geardyn.cli.main import main
    from geardyn.io.netcdf import load_dataset
    from geardyn.study import build_model

    for key, text in (("faults[0].depth", "1.2 mm"), ("faults[0].tooth", "4"),
                      ("gears.pinion.bore_radius", "0.014")):
        assert spur.set_override(key, text) is None, key
    assert spur.overrides["faults[0].tooth"] == 4  # a whole number, as the fault takes it
    ds = compute_diagram(spur.diagram_request())
    paths = spur.save(ds)
    study_file = spur.save_dir / "spur_pair_cracked-explore.toml"
    assert study_file in paths
    again = load_study(study_file)
    assert again.faults[0].fields()["depth"] == "1.2 mm"
    assert again.faults[0].fields()["tooth"] == 4
    assert build_model(again).params.tobytes() == spur.model.params.tobytes()
    saved = next(p for p in paths if p.suffix == ".nc")
    command = shlex.split(load_dataset(saved).attrs["command"])
    assert command[:3] == ["geardyn", "bifurcation", str(study_file)]
    out = tmp_path / "cli.nc"
    args = command[1:command.index("--out")] + ["--quiet", "--out", str(out)]
    with pytest.raises(SystemExit) as stop:
        main(args)
    assert stop.value.code == 0
    assert load_dataset(out)["poincare"].values.tobytes() == ds["poincare"].values.tobytes()


def test_the_page_shows_the_stiffness_and_a_fault_control(spur):
    """The page of a geometry model: a control per geometry key; a refused depth shows its
    message next to the control and changes nothing; a valid one updates the stiffness panel
    and recomputes the diagram."""
    from bokeh.document import Document

    from geardyn.explore import app

    ds = compute_diagram(spur.diagram_request())
    page = app.ExplorerSession(Document(), spur, ds, format_error)
    page._later = lambda fn, *args: fn(*args)
    try:
        assert set(spur.geometry_params()) <= set(page.inputs)
        source = page.stiffness_sources["mesh"]
        drive = np.array(source.data["drive"])
        page._on_param("faults[0].depth", "value", "2 mm", "5 mm")
        assert page.input_messages["faults[0].depth"].text.count("faults[0].depth: the crack")
        assert page._pending is None and spur.overrides == {}
        page._on_param("faults[0].depth", "value", "5 mm", "0.5 mm")
        page.runner.wait(60)
        assert page.input_messages["faults[0].depth"].text == ""
        assert np.min(source.data["drive"]) > np.min(drive)  # shallower crack
        assert "depth 0.0005 m" in page.stiffness_faults.text
        assert page.request.model is spur.model
    finally:
        page.runner.shutdown()


def test_every_fault_kind_gets_its_numeric_fields_as_controls(tmp_path):
    """A spall and a wear table: their controls are the numeric fields of Spall and Wear
    (the text fields gear and profile are not controls); a spall off the flank is refused naming
    faults[0].position; new wear depth gives SpurPair.from_geometry of the pair by hand."""
    import geardyn.gears as g
    from geardyn.io.toml import builtin_study_text

    crack = 'kind = "crack"\ngear = "pinion"\ntooth = 9\ndepth = "2 mm"\nangle = "45 deg"'
    faults = ('kind = "spall"\ngear = "pinion"\ntooth = 9\nlength = "1 mm"\nwidth = "4 mm"\n'
              'depth = "0.2 mm"\n\n[[faults]]\nkind = "wear"\ngear = "pinion"\ntooth = 3\n'
              'depth = "10 um"')
    text = builtin_study_text("spur_pair_cracked")
    assert crack in text
    text = text.replace(crack, faults).replace("angles = 64", "angles = 16").replace(
        "harmonics = 76", "harmonics = 38")
    st = ExplorerState(load_study(text), "spur.toml", save_dir=tmp_path,
                       describe_error=format_error)
    assert st.geometry_params()[2:] == (
        "faults[0].kind", "faults[0].gear", "faults[0].length", "faults[0].width",
        "faults[0].depth", "faults[0].position", "faults[0].tooth", "faults[1].kind",
        "faults[1].gear", "faults[1].depth", "faults[1].tooth")
    assert st.current_value("faults[0].position") == 0.0  # Spall's default
    model = st.model
    msg = st.set_override("faults[0].position", "20 mm")
    assert msg.startswith("faults[0].position: off the active flank of pinion"), msg
    assert st.overrides == {} and st.model is model
    assert st.set_override("faults[1].depth", "20 um") is None
    spall = g.Spall("1 mm", "4 mm", "0.2 mm", gear="pinion", tooth=9)
    wear = g.Wear("20 um", gear="pinion", tooth=3)
    assert st.model.params.tobytes() == _spur_model_by_hand(spall, wear).params.tobytes()


def test_a_fault_changes_kind_through_its_control(spur):
    """The crack's kind is a choice: as a spall it keeps its gear and tooth, starts at zero
    size (the healthy tooth: the crack's depth is dropped) and offers Spall's fields, whose
    values then give SpurPair of the pair with that spall built here; as a missing tooth it
    has no size; an unknown kind is refused naming the control, the state kept."""
    import geardyn.gears as g

    assert spur.choices("faults[0].kind") == ("crack", "spall", "wear", "broken_tooth")
    assert spur.current_value("faults[0].kind") == "crack"
    assert spur.set_override("faults[0].depth", "1 mm") is None
    assert spur.set_override("faults[0].kind", "spall") is None
    assert spur.geometry_params()[2:] == (
        "faults[0].kind", "faults[0].gear", "faults[0].length", "faults[0].width",
        "faults[0].depth", "faults[0].position", "faults[0].tooth")
    assert spur.current_value("faults[0].length") == 0.0  # zero size until set
    assert spur.current_value("faults[0].depth") == 0.0  # not the crack's
    assert spur.current_value("faults[0].tooth") == 9
    assert "spall on the pinion" in spur.param_help("faults[0].width")
    zero = g.Spall(0.0, 0.0, 0.0, gear="pinion", tooth=9)
    assert spur.model.params.tobytes() == _spur_model_by_hand(zero).params.tobytes()
    for key, text in (("faults[0].length", "1 mm"), ("faults[0].width", "4 mm"),
                      ("faults[0].depth", "0.1 mm")):
        assert spur.set_override(key, text) is None, key
    spall = g.Spall("1 mm", "4 mm", "0.1 mm", gear="pinion", tooth=9)
    assert spur.model.params.tobytes() == _spur_model_by_hand(spall).params.tobytes()
    assert spur.effective_study.faults[0].kind == "spall"
    assert spur.set_override("faults[0].kind", "broken_tooth") is None
    assert spur.geometry_params()[2:] == ("faults[0].kind", "faults[0].gear",
                                          "faults[0].tooth")
    assert set(spur.overrides) == {"faults[0].kind"}  # the spall's sizes went with it
    missing = g.BrokenTooth(gear="pinion", tooth=9)
    assert spur.model.params.tobytes() == _spur_model_by_hand(missing).params.tobytes()
    model = spur.model
    msg = spur.set_override("faults[0].kind", "dent")
    assert msg.startswith("faults[0].kind"), msg
    assert spur.model is model and spur.overrides == {"faults[0].kind": "broken_tooth"}


def test_the_page_rebuilds_the_fault_controls_for_a_new_kind(spur):
    """Choosing wear for the crack on the page: the controls are Wear's fields (no angle)."""
    from bokeh.document import Document

    from geardyn.explore import app

    ds = compute_diagram(spur.diagram_request())
    page = app.ExplorerSession(Document(), spur, ds, format_error)
    page._later = lambda fn, *args: fn(*args)
    try:
        assert "faults[0].angle" in page.inputs
        page._on_param("faults[0].kind", "value", "crack", "wear")
        page.runner.wait(60)
        assert page.input_messages["faults[0].kind"].text == ""
        assert "faults[0].angle" not in page.inputs and "faults[0].depth" in page.inputs
        titles = [c.children[0].title for c in page.geometry_row.children]
        assert titles == list(spur.geometry_params())
        assert "wear on pinion tooth 9" in page.stiffness_faults.text
    finally:
        page.runner.shutdown()


# ------------------------------------------------------------- a planetary set from geometry
#: The shipped planetary stage (25/23/71, four planets) on the potential-energy stiffness with a
#: root crack on planet 2, at small sizes: 16 angles per mesh cycle, 3 mesh harmonics, short
#: runs; the window is 2 input speeds in rpm.
PLANETARY_WINDOW = Window(8000.0, 9000.0, 2)
PLANETARY_HARMONICS = 3
PLANETARY_OPTIONS = {"sun_bore_radius": "10 mm", "planet_bore_radius": "8 mm",
                     "ring_rim_radius": "85 mm", "angles": 16}
PLANETARY_CRACK = {"kind": "crack", "gear": "planet2", "tooth": 4, "depth": "1 mm"}


def _planetary_doc() -> dict:
    import tomllib

    from geardyn.io.toml import builtin_study_text

    doc = tomllib.loads(builtin_study_text("planetary_example"))
    doc["params"]["geometry"].update(stiffness="potential_energy", transition=0.0,
                                     stiffness_options=dict(PLANETARY_OPTIONS),
                                     faults=[dict(PLANETARY_CRACK)])
    doc["params"]["harmonics"] = PLANETARY_HARMONICS
    doc["run"].update(transient_periods=1, periods=2)  # short: the checks compare runs
    doc["run"].pop("converge")
    return doc


@pytest.fixture()
def planetary(tmp_path):
    from geardyn.io.toml import load_study_dict

    return ExplorerState(load_study_dict(_planetary_doc()), "planetary.toml",
                         window=PLANETARY_WINDOW, save_dir=tmp_path / "saved",
                         describe_error=format_error)


def _planetary_by_hand(*faults, coast="mirror", **options):
    """The study's set from its literal values through PlanetaryGearSet.from_geometry (not
    through the study or the explorer), at the study's [run].omega."""
    from planetary_example_set import planetary_by_hand

    doc = _planetary_doc()
    model = planetary_by_hand(doc, stiffness="potential_energy",
                              stiffness_options={**PLANETARY_OPTIONS, **options}, coast=coast,
                              faults=list(faults))
    return model.with_omega(doc["run"]["omega"])


def test_a_planetary_geometry_offers_its_stiffness_and_fault_controls(planetary):
    """The controls of a set built from [params.geometry]: the stiffness method and coast flank
    (choices), the bores and the ring's rim, then the fault's gear (sun, planet<n>, ring) and
    the crack's numeric fields, by their study-file keys, with the study's values."""
    assert planetary.geometry_params() == (
        "params.geometry.stiffness", "params.geometry.coast",
        "params.geometry.stiffness_options.sun_bore_radius",
        "params.geometry.stiffness_options.planet_bore_radius",
        "params.geometry.stiffness_options.ring_rim_radius",
        "params.geometry.faults[0].kind", "params.geometry.faults[0].gear",
        "params.geometry.faults[0].depth", "params.geometry.faults[0].angle",
        "params.geometry.faults[0].tooth")
    assert planetary.choices("params.geometry.faults[0].kind") == (
        "crack", "spall", "wear", "broken_tooth")
    assert planetary.current_value("params.geometry.faults[0].kind") == "crack"
    assert planetary.choices("params.geometry.stiffness") == ("iso", "potential_energy")
    assert planetary.choices("params.geometry.coast") == ("mirror", "symmetric")
    assert planetary.choices("params.geometry.faults[0].gear") == (
        "sun", "planet1", "planet2", "planet3", "planet4", "ring")
    assert planetary.choices("params.geometry.faults[0].depth") == ()
    assert planetary.current_value("params.geometry.stiffness") == "potential_energy"
    assert planetary.current_value("params.geometry.faults[0].gear") == "planet2"
    assert planetary.current_value("params.geometry.faults[0].tooth") == 4
    assert planetary.current_value("params.geometry.stiffness_options.ring_rim_radius") == \
        "85 mm"
    assert "crack on the planet2" in planetary.param_help("params.geometry.faults[0].depth")
    # the shipped example (ISO waves, no faults) offers the set's controls without faults
    plain = ExplorerState(builtin_study("planetary_example"), "planetary_example")
    assert plain.geometry_params() == planetary.geometry_params()[:5]
    assert plain.current_value("params.geometry.stiffness_options.sun_bore_radius") == ""


def test_planetary_controls_rebuild_the_set_as_from_geometry_by_hand(planetary):
    """New fault gear, tooth and depth, bore and coast flank through the explorer's state: the
    model's coefficients are PlanetaryGearSet.from_geometry's of the set built here with them
    (bitwise), and the diagram is geardyn.bifurcation's on that model."""
    import geardyn
    import geardyn.gears as g

    for key, text in (("params.geometry.faults[0].gear", "sun"),
                      ("params.geometry.faults[0].tooth", "7"),
                      ("params.geometry.faults[0].depth", "1.5 mm"),
                      ("params.geometry.stiffness_options.planet_bore_radius", "9 mm"),
                      ("params.geometry.coast", "symmetric")):
        assert planetary.set_override(key, text) is None, key
    assert planetary.overrides["params.geometry.faults[0].tooth"] == 7
    crack = g.RootCrack("1.5 mm", gear="sun", tooth=7)
    by_hand = _planetary_by_hand(crack, coast="symmetric", planet_bore_radius="9 mm")
    model = planetary.model
    assert model.faults.gear == "sun" and model.coast_flank == "symmetric"
    assert model.params.tobytes() == by_hand.params.tobytes()
    req = planetary.diagram_request()
    ds = compute_diagram(req)
    api = geardyn.bifurcation(by_hand, "input_speed", PLANETARY_WINDOW.values(), req.run)
    assert np.all(np.isfinite(ds["poincare"].values))
    assert ds["poincare"].values.tobytes() == api["poincare"].values.tobytes()


def test_a_zero_size_planetary_fault_is_the_healthy_set(planetary):
    """A crack of depth 0 on planet 2: every mesh's stiffness over the revolution, table and
    series, is the healthy set's (from_geometry without faults) repeated every mesh cycle; the
    means are equal (to round-off: a mean over 23 cycles of the same values)."""
    from geardyn.explore.compute import stiffness_view

    assert planetary.set_override("params.geometry.faults[0].depth", "0 mm") is None
    zero = stiffness_view(planetary.model)
    healthy_model = _planetary_by_hand()
    healthy = stiffness_view(healthy_model)
    assert healthy_model.mesh_order == 1 and planetary.model.mesh_order == 23
    np.testing.assert_allclose(planetary.model.mesh_stiffnesses(),
                               healthy_model.mesh_stiffnesses(), rtol=1e-14, atol=0)
    for z, h in zip(zero.meshes, healthy.meshes, strict=True):
        assert z.mesh == h.mesh
        first = z.cycle < 1.0 - 1e-9  # the revolution's first mesh cycle
        np.testing.assert_allclose(z.cycle[first], h.cycle, rtol=0, atol=1e-9)
        scale = float(np.mean(h.drive))
        for name in ("drive", "coast", "drive_series", "coast_series"):
            period = getattr(z, name).reshape(23, -1)  # every mesh cycle the same
            np.testing.assert_allclose(period, np.broadcast_to(getattr(h, name), period.shape),
                                       rtol=0, atol=1e-9 * scale, err_msg=f"{z.mesh} {name}")


@pytest.mark.parametrize(("key", "text", "message"), [
    ("params.geometry.faults[0].depth", "-1 mm", "params.geometry.faults[0].depth: must be"),
    ("params.geometry.faults[0].gear", "moon", "params.geometry.faults[0].gear: must be"),
    ("params.geometry.faults[0].tooth", "30", "params.geometry.faults[0].tooth: must lie in"),
    ("params.geometry.stiffness_options.sun_bore_radius", "30 mm",
     "params.geometry.stiffness_options.sun_bore_radius: must lie inside"),
    ("params.geometry.stiffness", "iso",
     "params.geometry.stiffness_options: only with stiffness='potential_energy'"),
    ("params.geometry.coast", "both", "params.geometry.coast: "),
    ("params.geometry.faults[1].depth", "1 mm",
     "params.geometry.faults[1].depth: not a parameter of this explorer"),
])
def test_a_bad_planetary_value_names_its_field_and_changes_nothing(planetary, key, text,
                                                                   message):
    model = planetary.model
    msg = planetary.set_override(key, text)
    assert msg is not None and msg.startswith(message), msg
    assert "\n" not in msg and "Traceback" not in msg
    assert planetary.overrides == {} and planetary.model is model


def test_the_planetary_stiffness_panel_marks_the_faulty_meshes(planetary):
    """The panel has every mesh over the revolution (23 mesh cycles of planet 2); planet 2's
    two meshes are the faulty ones, then the sun's four after the gear control moves the crack
    there; each mesh's series is a direct Fourier sum of its table in the revolution's angle,
    cut after the model's harmonics (3 x 23)."""
    from geardyn.explore.compute import stiffness_view

    view = stiffness_view(planetary.model)
    assert [m.mesh for m in view.meshes] == ["s1", "s2", "s3", "s4", "r1", "r2", "r3", "r4"]
    assert [m.mesh for m in view.meshes if m.faulty] == ["s2", "r2"]
    assert view.harmonics == PLANETARY_HARMONICS * 23
    assert "root crack on planet2 tooth 4" in view.faults
    h = np.arange(1, view.harmonics + 1)[:, None]
    for mesh in view.meshes:
        assert mesh.cycle.size == 16 * 23 and np.all(np.diff(mesh.cycle) > 0)
        theta = 2 * np.pi * mesh.cycle / 23
        for k, series in ((mesh.drive, mesh.drive_series), (mesh.coast, mesh.coast_series)):
            a = 2 * np.mean(k * np.cos(h * theta), axis=1)
            b = 2 * np.mean(k * np.sin(h * theta), axis=1)
            direct = np.mean(k) + a @ np.cos(h * theta) + b @ np.sin(h * theta)
            np.testing.assert_allclose(series, direct, rtol=0, atol=1e-9 * np.mean(k),
                                       err_msg=mesh.mesh)
    s2 = view.meshes[1]
    assert np.min(s2.drive) < np.min(view.meshes[0].drive)  # the crack is felt
    assert planetary.set_override("params.geometry.faults[0].gear", "sun") is None
    moved = stiffness_view(planetary.model)
    assert [m.mesh for m in moved.meshes if m.faulty] == ["s1", "s2", "s3", "s4"]
    assert view.meshes[1].mesh == "s2" and moved.meshes[0].cycle.size == 16 * 25


def test_the_planetary_page_offers_choices_and_highlights_the_faulty_meshes(planetary, tmp_path):
    """The page of a planetary set from geometry: choices for the method, coast flank and
    fault gear; a refused tooth shows its message; a new gear thickens that gear's meshes; the
    saved study file holds the change and builds the same model."""
    from bokeh.document import Document
    from bokeh.models import Select

    from geardyn.explore import app
    from geardyn.study import build_model

    ds = compute_diagram(planetary.diagram_request())
    page = app.ExplorerSession(Document(), planetary, ds, format_error)
    page._later = lambda fn, *args: fn(*args)
    gear = "params.geometry.faults[0].gear"
    try:
        assert isinstance(page.inputs[gear], Select)
        assert page.inputs[gear].options[-1] == "ring"
        assert isinstance(page.inputs["params.geometry.stiffness"], Select)
        width = {m: lines[0].glyph.line_width for m, lines in page.stiffness_lines.items()}
        assert width == {"s1": 1, "s2": 3, "s3": 1, "s4": 1, "r1": 1, "r2": 3, "r3": 1, "r4": 1}
        page._on_param("params.geometry.faults[0].tooth", "value", "4", "30")
        assert "faults[0].tooth: must lie in" in page.input_messages[
            "params.geometry.faults[0].tooth"].text
        assert page._pending is None and planetary.overrides == {}
        page._on_param(gear, "value", "planet2", "planet3")
        page.runner.wait(120)
        assert page.input_messages[gear].text == ""
        width = {m: lines[0].glyph.line_width for m, lines in page.stiffness_lines.items()}
        assert [m for m, w in width.items() if w == 3] == ["s3", "r3"]
        assert "faulty meshes: s3, r3" in page.stiffness_faults.text
        assert page.request.model is planetary.model
        saved = planetary.save(page.ds, tmp_path / "view")
        again = load_study(saved[0])
        assert again.params.geometry.faults[0].fields()["gear"] == "planet3"
        assert build_model(again).params.tobytes() == planetary.model.params.tobytes()
    finally:
        page.runner.shutdown()


def test_the_page_of_a_planetary_set_on_the_iso_waves(tmp_path):
    """The shipped planetary example (ISO waves, no faults): its stiffness panel says it has no
    tables; the coast flank is a choice whose new value rebuilds the set with it; switching the
    method is refused naming the field that the other method refuses (its transition)."""
    from bokeh.document import Document

    from geardyn.explore import app
    from geardyn.io.toml import builtin_study_text

    text = builtin_study_text("planetary_example")
    short = {"periods = 32": "periods = 2", "transient_periods = 20": "transient_periods = 1",
             "converge = 1e-6": ""}  # a short run: the checks are of the page's controls
    for line, other in short.items():
        assert line in text, line
        text = text.replace(line, other)
    st = ExplorerState(load_study(text),
                       "planetary_example", window=PLANETARY_WINDOW, save_dir=tmp_path,
                       describe_error=format_error)
    ds = compute_diagram(st.diagram_request())
    page = app.ExplorerSession(Document(), st, ds, format_error)
    page._later = lambda fn, *args: fn(*args)
    try:
        assert "no potential-energy stiffness tables" in page.stiffness_faults.text
        page._on_param("params.geometry.stiffness", "value", "iso", "potential_energy")
        assert page.input_messages["params.geometry.stiffness"].text.count(
            "params.geometry.transition: shapes the ISO waves")
        assert st.overrides == {}
        page._on_param("params.geometry.coast", "value", "mirror", "symmetric")
        page.runner.wait(120)
        assert page.message.text == "" and page.request.model is st.model
        assert st.model.coast_flank == "symmetric" and st.model.stiffness_method == "iso"
    finally:
        page.runner.shutdown()


def test_a_train_offers_its_fault_controls():
    """The two_stage_train study on the potential-energy stiffness with a crack on g1: the
    fault's kind, gear (a choice of the train's gears) and the crack's fields as controls; the
    crack moved to g4 and made a missing tooth gives the model of the study file written so."""
    import geardyn.gears as g
    from geardyn.io.toml import builtin_study_text
    from geardyn.study import build_model

    text = builtin_study_text("two_stage_train").replace(
        'stiffness = "iso"', 'stiffness = "potential_energy"\nbore_radius = "10 mm"').replace(
        "stiffness_fluctuation = 0.25\n", "").replace(
        "[run]\n", "[run]\nomega = 0.07\nperiods = 2\n")
    crack = '\n[[train.faults]]\nkind = "crack"\ngear = "g1"\ntooth = 3\ndepth = "1 mm"\n'
    st = ExplorerState(load_study(text + crack), "two.toml", param="Omega",
                       window=Window(0.07, 0.075, 2), describe_error=format_error)
    assert st.geometry_params() == (
        "train.faults[0].kind", "train.faults[0].gear", "train.faults[0].depth",
        "train.faults[0].angle", "train.faults[0].tooth")
    assert st.choices("train.faults[0].gear") == ("g1", "g2", "g3", "g4")
    assert st.current_value("train.faults[0].depth") == "1 mm"
    assert st.model.faults.gear == "g1" and st.model.mesh_order == 19
    assert st.set_override("train.faults[0].gear", "g4") is None
    assert st.set_override("train.faults[0].kind", "broken_tooth") is None
    assert st.model.faults.gear == "g4"
    assert st.model.faults.faults == (g.BrokenTooth(gear="g4", tooth=3),)
    by_hand = build_model(load_study(
        text + '\n[[train.faults]]\nkind = "broken_tooth"\ngear = "g4"\ntooth = 3\n'),
        omega=0.07)
    assert st.model.params.tobytes() == by_hand.params.tobytes()
    msg = st.set_override("train.faults[0].gear", "g9")
    assert msg.startswith("train.faults[0].gear") and "g9" in msg, msg


def test_a_train_study_is_explored_in_input_speed():
    from geardyn.explore.compute import compute_diagram, compute_orbit, orbit_request

    st = ExplorerState(builtin_study("two_stage_train"), "two_stage_train",
                       window=Window(1500.0, 2500.0, 3))
    assert st.param == "input_speed"
    assert {"mesh_damping", "backlash", "modal_damping"} <= set(st.main_params())
    assert st.set_override("mesh_damping", "0.08") is None
    assert "backlash" in st.set_override("backlash", "-1")
    req = st.diagram_request()
    # transient_periods count periods of the window's lowest speed, as the CLI counts them
    low = st.model.with_params(input_speed=1500.0).omega
    assert req.run == st.effective_study.run_settings(sweep=True, omega=low)
    ds = compute_diagram(req)
    cli = geardyn.bifurcation(geardyn.build_model(st.effective_study), "input_speed",
                              [1500.0, 2000.0, 2500.0], req.run)
    np.testing.assert_array_equal(ds["poincare"].values, cli["poincare"].values)
    view = compute_orbit(orbit_request(req, ds, 2000.0))
    assert view.status == "ok" and view.value == 2000.0
    nrel = builtin_study("nrel_5mw_gearbox_sweep")  # per-mesh backlash: not a control
    assert "backlash" not in ExplorerState(nrel, "nrel", window=Window(10.0, 12.0, 2)
                                           ).main_params()
