"""The explorer's server logic without a browser: the view state (window, history, overrides
validated as study files are), the computations (a window's diagram, one orbit), the reproducing
command, saving, and the worker where a new request supersedes the running one."""

from __future__ import annotations

import shlex
import threading

import numpy as np
import pytest

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
    assert state.main_params() == ("backlash", "Fa", "kappa")  # the swept one left out
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
