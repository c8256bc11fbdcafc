"""geardyn.testing.assert_result: a result dataset checked against what its kind promises.

Cheap synthetic datasets (no kernel compiled) shaped like geardyn's results; the tests that
build real results call assert_result on them (test_bifurcation, test_map2d, test_reproduction,
test_cli)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from geardyn.core.status import status_attrs
from geardyn.testing import KINDS, assert_result

PERIOD = {"meaning": "k>=1 period-k"}


def _sweep(kind: str = "bifurcation") -> xr.Dataset:
    n = 3
    ds = xr.Dataset(coords={"Omega": ("Omega", [0.5, 1.0, 1.5]), "sample": ("sample", [0, 1]),
                            "state": ("state", ["x", "v"])})
    ds["poincare"] = (("Omega", "sample", "state"), np.zeros((n, 2, 2)))
    ds["period"] = ("Omega", np.ones(n, dtype=int), PERIOD)
    ds["status"] = ("Omega", np.array([0, 1, 0]), status_attrs())
    ds["final_time"] = ("Omega", np.ones(n), {"units": "tau"})
    ds.attrs.update(geardyn_kind=kind, param="Omega", time_unit="tau")
    return ds


def _map() -> xr.Dataset:
    ds = xr.Dataset(coords={"xi": ("xi", [0.1, 0.2]), "Omega": ("Omega", [1.0, 2.0, 3.0])})
    ds["period"] = (("xi", "Omega"), np.ones((2, 3), dtype=int), PERIOD)
    ds["status"] = (("xi", "Omega"), np.zeros((2, 3), dtype=int), status_attrs())
    ds.attrs.update(geardyn_kind="map2d", x="Omega", y="xi", time_unit="tau")
    return ds


def _simulation() -> xr.Dataset:
    t = np.arange(5.0)
    ds = xr.Dataset(coords={"time": ("time", t, {"units": "tau"}), "sample": ("sample", [0, 1]),
                            "state": ("state", ["x", "v"])})
    ds["x"] = ("time", np.sin(t), {"units": "1"})
    ds["v"] = ("time", np.cos(t), {"units": "1"})
    ds["poincare"] = (("sample", "state"), np.zeros((2, 2)))
    ds["poincare_time"] = ("sample", [0.0, 4.0], {"units": "tau"})
    ds.attrs.update(geardyn_kind="simulation", status=0, status_meaning="0 ok",
                    steps_per_period=4, time_unit="tau")
    return ds


def _case() -> xr.Dataset:
    ds = xr.concat([_sweep(), _sweep()], dim="sweep").assign_coords(sweep=["up", "down"])
    ds.attrs["geardyn_kind"] = "reproduction-case"
    return ds


def _orbit() -> xr.Dataset:
    t = np.arange(5.0)
    ds = xr.Dataset(coords={"time": ("time", t, {"units": "tau"}), "state": ("state", ["x", "v"]),
                            "state_in": ("state_in", ["x", "v"]),
                            "multiplier": ("multiplier", [0, 1])})
    ds["x"] = ("time", np.sin(t), {"units": "1"})
    ds["v"] = ("time", np.cos(t), {"units": "1"})
    ds["section_point"] = ("state", [0.0, 1.0])
    ds["monodromy"] = (("state", "state_in"), np.eye(2) * 0.5)
    ds["multiplier_real"] = ("multiplier", [0.5, 0.5])
    ds["multiplier_imag"] = ("multiplier", [0.0, 0.0])
    ds.attrs.update(geardyn_kind="periodic-orbit", status=0, status_meaning="0 ok",
                    steps_per_period=4, time_unit="tau", Omega=1.0, period=1, converged=1,
                    orbit_status=0, message="converged", residual=0.0, stability="stable")
    return ds


def _branch() -> xr.Dataset:
    n = 3
    ds = xr.Dataset(coords={"point": ("point", np.arange(n)),
                            "Omega": ("point", [0.5, 0.6, 0.7]), "state": ("state", ["x", "v"]),
                            "multiplier": ("multiplier", [0, 1]), "branch_id": ("branch_id", [0])})
    ds["section_point"] = (("point", "state"), np.zeros((n, 2)))
    ds["multiplier_real"] = (("point", "multiplier"), np.full((n, 2), 0.5))
    ds["multiplier_imag"] = (("point", "multiplier"), np.zeros((n, 2)))
    ds["stability"] = ("point", ["stable"] * n)
    ds["branch"] = ("point", np.zeros(n, dtype=int))
    ds["period"] = ("point", np.ones(n, dtype=int), PERIOD)
    ds["bifurcation_kind"] = ("bifurcation", ["fold", "branch point"], {"meaning": "kinds"})
    ds["bifurcation_value"] = ("bifurcation", [0.55, 0.65])
    ds["bifurcation_error"] = ("bifurcation", [1e-8, 0.05])
    ds["bifurcation_located"] = ("bifurcation", [1, 0], {"meaning": "1 located"})
    ds["branch_status"] = ("branch_id", [0])
    ds["branch_message"] = ("branch_id", ["reached Omega=0.7"])
    ds.attrs.update(geardyn_kind="continuation", param="Omega", start=0.5, stop=0.7, period=1,
                    status=0, message="reached Omega=0.7", status_meaning="0 completed",
                    time_unit="tau")
    return ds


def _curve() -> xr.Dataset:
    n = 3
    ds = xr.Dataset(coords={"point": ("point", np.arange(n)),
                            "Omega": ("point", [0.5, 0.6, 0.7]),
                            "torque": ("point", [10.0, 11.0, 12.5]),
                            "state": ("state", ["x", "v"]), "multiplier": ("multiplier", [0, 1]),
                            "special": ("special", [0])})
    ds["section_point"] = (("point", "state"), np.zeros((n, 2)))
    ds["multiplier_real"] = (("point", "multiplier"), np.full((n, 2), -1.0))
    ds["multiplier_imag"] = (("point", "multiplier"), np.zeros((n, 2)))
    ds["period_time"] = ("point", np.full(n, 2.0), {"units": "tau"})
    ds["special_kind"] = ("special", ["cusp"], {"meaning": "codimension-2 point"})
    ds["special_x"] = ("special", [0.6])
    ds["special_y"] = ("special", [11.0])
    ds["special_error"] = ("special", [1e-6])
    ds.attrs.update(geardyn_kind="curve", curve_kind="period_doubling", x="Omega", y="torque",
                    period=1, status=0, message="reached torque=12.5",
                    status_meaning="0 completed", time_unit="tau")
    return ds


def _basins() -> xr.Dataset:
    ds = xr.Dataset(coords={"v": ("v", [0.0, 1.0]), "x": ("x", [1.0, 2.0, 3.0]),
                            "attractor": ("attractor", [0, 1]), "point": ("point", [0]),
                            "state": ("state", ["x", "v"])})
    ds["attractor_id"] = (("v", "x"), np.array([[0, 0, 1], [1, -1, 0]]), {"meaning": "id"})
    ds["period"] = (("v", "x"), np.ones((2, 3), dtype=int), PERIOD)
    ds["status"] = (("v", "x"), np.zeros((2, 3), dtype=int), status_attrs())
    ds["attractor_period"] = ("attractor", [1, 1])
    ds["attractor_fraction"] = ("attractor", [0.5, 1 / 3], {"meaning": "share"})
    ds["attractor_point"] = (("attractor", "point", "state"), np.zeros((2, 1, 2)))
    ds["attractor_orbit"] = ("attractor", [-1, -1])
    ds["unresolved"] = (("v", "x"), np.zeros((2, 3), dtype=np.int8), {"meaning": "1: unresolved"})
    ds.attrs.update(geardyn_kind="basins", x="x", y="v", Omega=1.0, time_unit="tau",
                    diverged_fraction=1 / 6, unresolved_fraction=0.0, n_attractors=2)
    return ds


def _frc() -> xr.Dataset:
    ds = xr.Dataset(coords={"sweep": ("sweep", ["up", "down"]), "Omega": ("Omega", [0.5, 1.0]),
                            "mesh": ("mesh", ["mesh"]), "jump": ("jump", [0])})
    for name in ("dte_rms", "dte_peak", "dte_mean"):
        ds[name] = (("sweep", "Omega", "mesh"), np.ones((2, 2, 1)), {"units": "1"})
    ds["period"] = (("sweep", "Omega"), np.ones((2, 2), dtype=int), PERIOD)
    ds["status"] = (("sweep", "Omega"), np.zeros((2, 2), dtype=int), status_attrs())
    ds["hysteresis"] = ("Omega", [False, True])
    ds["jump_omega"] = ("jump", [0.75], {"meaning": "midpoint"})
    ds["jump_sweep"] = ("jump", ["up"])
    ds.attrs.update(geardyn_kind="frequency-response", param="Omega", time_unit="tau",
                    resolution=0.5)
    return ds


def _runup() -> xr.Dataset:
    t = np.arange(4.0)
    ds = xr.Dataset(coords={"time": ("time", t, {"units": "tau"})})
    ds["Omega"] = ("time", 0.5 + 0.1 * t)
    ds["phase"] = ("time", 0.5 * t + 0.05 * t * t, {"units": "rad"})
    ds["x"] = ("time", np.zeros(4))
    ds.attrs.update(geardyn_kind="runup", status=0, status_meaning="0 ok",
                    integrator="RK4", step=0.25, steps_per_period=64, time_unit="tau",
                    start=0.5, stop=0.8, rate=0.1, outputs="x")
    return ds


def _dynamic_factor() -> xr.Dataset:
    dims = ("torque", "speed", "group")
    ds = xr.Dataset(coords={"torque": ("torque", [20.0, 80.0]),
                            "speed": ("speed", [1000.0, 2000.0, 3000.0]),
                            "group": ("group", ["mesh"])})
    ds["dynamic_factor"] = (dims, np.ones((2, 3, 1)))
    ds["K_v"] = (dims, np.full((2, 3, 1), 1.1))
    ds["contact"] = (dims, np.full((2, 3, 1), "none"))
    ds["period"] = (("torque", "speed"), np.ones((2, 3), dtype=int), PERIOD)
    ds["resonance_speed"] = (("torque", "group"), np.full((2, 1), 2500.0))
    ds.attrs.update(geardyn_kind="dynamic-factor", standard="ISO 6336-1:2006",
                    stiffness_source="model")
    return ds


def _fault_dataset() -> xr.Dataset:
    dims = ("fault", "speed", "torque")
    ds = xr.Dataset(coords={"fault": ("fault", [0, 1]),
                            "fault_kind": ("fault", ["healthy", "crack"]),
                            "fault_size": ("fault", [np.nan, 1e-3]),
                            "fault_gear": ("fault", ["none", "pinion"]),
                            "fault_tooth": ("fault", [-1, 0]), "speed": ("speed", [1e3]),
                            "torque": ("torque", [50.0, 60.0]), "seed": ("seed", [0]),
                            "time": ("time", [0.0, 1e-4, 2e-4], {"units": "s"})})
    ds["signal"] = ((*dims, "seed", "time"), np.ones((2, 1, 2, 1, 3)), {"units": "N"})
    ds["status"] = (dims, np.zeros((2, 1, 2), dtype=np.int8), status_attrs())
    ds["unresolved"] = (dims, np.zeros((2, 1, 2), dtype=int), {"meaning": "steps"})
    ds["noise_std"] = (dims, np.full((2, 1, 2), 0.1), {"units": "N"})
    ds.attrs.update(geardyn_kind="fault-dataset", model="SpurPair", time_unit="s", snr_db=20.0,
                    duration=3e-4, sample_rate=1e4)
    return ds


BUILD = {"simulation": _simulation, "bifurcation": _sweep, "map2d": _map,
         "reproduction-case": _case, "periodic-orbit": _orbit, "continuation": _branch,
         "basins": _basins, "frequency-response": _frc, "curve": _curve,
         "runup": _runup, "dynamic-factor": _dynamic_factor, "fault-dataset": _fault_dataset}


@pytest.mark.parametrize("kind", KINDS)
def test_well_formed_results_pass(kind):
    assert_result(BUILD[kind](), kind)


@pytest.mark.parametrize("kind,name", [("simulation", "poincare"), ("simulation", "v"),
                                       ("bifurcation", "period"), ("bifurcation", "status"),
                                       ("map2d", "status"), ("reproduction-case", "poincare"),
                                       ("periodic-orbit", "monodromy"),
                                       ("continuation", "bifurcation_value"),
                                       ("curve", "special_error"),
                                       ("basins", "attractor_id"),
                                       ("frequency-response", "dte_rms"),
                                       ("runup", "phase")])
def test_a_removed_variable_is_named(kind, name):
    ds = BUILD[kind]().drop_vars(name)
    with pytest.raises(AssertionError, match=f"'{name}' missing"):
        assert_result(ds, kind)


@pytest.mark.parametrize("kind", KINDS)
def test_the_wrong_kind_fails(kind):
    other = next(k for k in KINDS if k != kind)
    with pytest.raises(AssertionError, match="geardyn_kind"):
        assert_result(BUILD[kind](), other)


def test_an_unknown_bifurcation_kind_or_branch_status_fails():
    ds = _branch()
    ds["bifurcation_kind"].values[1] = "pitchfork"
    ds["branch_status"].values[0] = 9
    with pytest.raises(AssertionError, match="'pitchfork'.*branch_status: codes \\[9\\]"):
        assert_result(ds, "continuation")


def test_a_missing_kind_attribute_fails():
    ds = _sweep()
    del ds.attrs["geardyn_kind"]
    with pytest.raises(AssertionError, match="attrs\\['geardyn_kind'\\] is None"):
        assert_result(ds, "bifurcation")


def test_wrong_dims_missing_meaning_and_unknown_status_are_named():
    ds = _sweep()
    ds["final_time"] = ("sample", [1.0, 2.0], {"units": "tau"})
    ds["period"].attrs.clear()
    ds["status"].values[1] = 7
    with pytest.raises(AssertionError) as info:
        assert_result(ds, "bifurcation")
    text = str(info.value)
    assert "'final_time' has dims ('sample',)" in text
    assert "'period' has no 'meaning'" in text
    assert "codes [7]" in text


def test_an_unknown_kind_is_refused():
    with pytest.raises(AssertionError, match="unknown result kind"):
        assert_result(_sweep(), "sweep")
