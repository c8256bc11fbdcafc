"""The explorer's overlay of two-parameter curves: where a curve crosses the line the diagram
sweeps (the swept parameter at the other parameter's current value)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from geardyn.cli.errors import format_error
from geardyn.core.results import finish
from geardyn.explore.compute import compute_diagram
from geardyn.explore.overlay import curve_marks
from geardyn.explore.state import ExplorerState
from geardyn.io.toml import load_study
from test_explore import STUDY  # the explorer tests' tiny gear-pair study


def _curve(kind: str, omega: np.ndarray, fa: np.ndarray, **attrs) -> xr.Dataset:
    n = omega.size
    ds = xr.Dataset(coords={"point": np.arange(n), "Omega": ("point", omega),
                            "Fa": ("point", fa), "state": ["x", "v"], "multiplier": [0, 1],
                            "special": np.arange(0)})
    ds["section_point"] = (("point", "state"), np.zeros((n, 2)))
    ds["multiplier_real"] = (("point", "multiplier"), np.zeros((n, 2)))
    ds["multiplier_imag"] = (("point", "multiplier"), np.zeros((n, 2)))
    ds["period_time"] = ("point", 2 * np.pi / omega, {"units": "1"})
    ds["special_kind"] = ("special", np.zeros(0, dtype=str), {"meaning": "-"})
    for name in ("special_x", "special_y", "special_error"):
        ds[name] = ("special", np.zeros(0))
    ds.attrs.update(curve_kind=kind, x="Omega", y="Fa", period=1, status=0, message="",
                    status_meaning="0 completed", time_unit="1", **attrs)
    return finish(ds, "curve")


#: A parabola Fa = (Omega - 2)^2 + 0.05: it crosses Fa = 0.1 at Omega = 2 -+ sqrt(0.05).
PARABOLA = _curve("grazing", np.linspace(1.5, 2.5, 41),
                  (np.linspace(1.5, 2.5, 41) - 2.0) ** 2 + 0.05, flank="drive")


def test_marks_are_where_the_curve_meets_the_other_parameters_value():
    marks = curve_marks([PARABOLA], "Omega", {"Fa": 0.1}.__getitem__)
    exact = [2.0 - np.sqrt(0.05), 2.0 + np.sqrt(0.05)]
    # the polyline's chord: within the parabola's sagitta over one segment (0.025^2 / 4)
    np.testing.assert_allclose(sorted(marks["x"]), exact, atol=2e-4)
    assert marks["label"] == ["grazing drive"] * 2 and marks["color"] == ["black"] * 2


def test_a_curve_in_another_plane_or_an_unknown_value_gives_no_mark():
    assert curve_marks([PARABOLA], "zeta", {"Fa": 0.1}.__getitem__)["x"] == []
    assert curve_marks([PARABOLA], "Omega", {}.__getitem__)["x"] == []
    assert curve_marks([PARABOLA], "Omega", {"Fa": 5.0}.__getitem__)["x"] == []
    # the swept parameter as the curve's y: read the other way round
    marks = curve_marks([PARABOLA], "Fa", {"Omega": 2.0}.__getitem__)
    assert marks["x"] == pytest.approx([0.05])


def test_the_page_marks_the_curves_over_the_diagram(tmp_path):
    from bokeh.document import Document

    from geardyn.explore import app

    state = ExplorerState(load_study(STUDY), "gp.toml", save_dir=tmp_path,
                          describe_error=format_error, curves=[PARABOLA])
    page = app.ExplorerSession(Document(), state, compute_diagram(state.diagram_request()),
                               format_error)
    try:
        assert sorted(page.curve_source.data["x"]) == pytest.approx(
            [2.0 - np.sqrt(0.05), 2.0 + np.sqrt(0.05)], abs=2e-4)
    finally:
        page.runner.shutdown()


def test_explore_refuses_a_missing_curve_file_in_one_line(capsys):
    from geardyn.cli.main import main

    with pytest.raises(SystemExit) as stop:
        main(["explore", "paper_fig3", "--curve", "missing.nc"])
    assert stop.value.code == 2
    assert capsys.readouterr().err.strip() == "error: --curve: no such file (got 'missing.nc')"
