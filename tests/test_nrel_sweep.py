"""The nonlinear NREL 5 MW gearbox study (``nrel_5mw_gearbox_sweep``): its train is the linear
study's, its inputs are the stated ones (rated torque from Jonkman et al. 2009, ISO/TR 10064-2
backlash)."""

from __future__ import annotations

import math
import tomllib
from importlib import resources

import numpy as np
import pytest

from geardyn.io.toml import builtin_study
from geardyn.units import si_value


def _table(name: str) -> dict:
    text = resources.files("geardyn.studies").joinpath(f"{name}.toml").read_text()
    return tomllib.loads(text)


def test_train_table_is_the_linear_studys():
    assert _table("nrel_5mw_gearbox_sweep")["train"] == _table("nrel_5mw_gearbox")["train"]


def test_rated_torque_is_5_mw_at_12_1_rpm():
    """Jonkman et al. 2009, Table 1-1: rated power 5 MW, rated rotor speed 12.1 rpm."""
    torque = si_value("rotor", builtin_study("nrel_5mw_gearbox_sweep").params.torques["rotor"],
                      "torque", 0.0)
    assert torque == pytest.approx(5e6 / (12.1 * 2.0 * math.pi / 60.0), rel=1e-3)


@pytest.mark.parametrize(("meshes", "centre_distance", "module"),
                         [(("sun1_pa1", "pa1_ring1"), 863.0, 45.0),
                          (("sun2_pb1", "pb1_ring2"), 584.0, 21.0), (("stage3",), 861.0, 14.0)])
def test_backlash_is_half_the_iso_minimum(meshes, centre_distance, module):
    """ISO/TR 10064-2: j_bn,min = 2/3 (0.06 + 0.0005 a + 0.03 m_n) mm; the model's backlash is
    the half-width of the dead zone."""
    backlash = builtin_study("nrel_5mw_gearbox_sweep").params.backlash
    j_bn = 2.0 / 3.0 * (0.06 + 0.0005 * centre_distance + 0.03 * module) * 1e-3
    for mesh in meshes:
        assert si_value(mesh, backlash[mesh], "length", 0.0) == pytest.approx(j_bn / 2.0, rel=0.01)


def test_stage2_resonance_is_at_its_campbell_crossing():
    """Near rated speed the planetary stage 2 meshes respond most where their mesh frequency
    crosses a natural frequency of the linear model (GearTrain.campbell: the eigenproblem at
    mean stiffness), within the sweep's resolution."""
    import geardyn

    study = builtin_study("nrel_5mw_gearbox_sweep")
    model = geardyn.build_model(study)
    rpm = np.arange(14.0, 16.21, 0.1)
    omega_min = float(model.lane_params("input_speed", rpm)[:, model.omega_index].min())
    run = geardyn.RunSettings(transient=200 * 2.0 * math.pi / omega_min, samples=8)
    ds = geardyn.bifurcation(model, "input_speed", rpm, run)
    peak = rpm[int(np.argmax(ds["dynamic_factor"].sel(mesh="sun2_pb1").values))]
    campbell = study.gear_train.campbell(rpm, harmonics=1)
    crossings = campbell["crossing_speed"].where(campbell["mesh"] == "sun2_pb1").values
    crossings = crossings[np.isfinite(crossings)]
    assert crossings.size >= 1
    assert np.min(np.abs(crossings - peak)) <= 0.1
