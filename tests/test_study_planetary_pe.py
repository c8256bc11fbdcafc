"""A planetary study built from geometry on the potential-energy stiffness
(``[params.geometry] stiffness = "potential_energy"`` with ``stiffness_options``)."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import geardyn
from geardyn.errors import ParameterError
from geardyn.io.toml import builtin_study_text, load_study_dict
from geardyn.study import build_model
from planetary_example_set import planetary_by_hand

OPTIONS = {"sun_bore_radius": "10 mm", "planet_bore_radius": "8 mm",
           "ring_rim_radius": "85 mm", "angles": 64}


def _doc(**geometry: object) -> dict:
    doc = tomllib.loads(builtin_study_text("planetary_example"))
    doc["params"]["geometry"].update(geometry)
    return doc


def _by_hand() -> geardyn.PlanetaryGearSet:
    """The example study's set, built from the API with the same literal inputs."""
    return planetary_by_hand(tomllib.loads(builtin_study_text("planetary_example")),
                             stiffness="potential_energy", stiffness_options=OPTIONS)


def test_study_equals_the_api_bitwise():
    doc = _doc(stiffness="potential_energy", stiffness_options=OPTIONS, transition=0.0)
    model = build_model(load_study_dict(doc))
    hand = _by_hand().with_omega(float(model.params[model.omega_index]))  # the study's run
    assert model.stiffness_method == "potential_energy"
    assert np.array_equal(model.params, hand.params)
    iso = build_model(load_study_dict(_doc(transition=0.0)))
    assert iso.stiffness_method == "iso"
    assert not np.array_equal(model.params, iso.params)


@pytest.mark.parametrize(("geometry", "field"), [
    ({"stiffness": "fem"}, "params.geometry.stiffness"),
    ({"stiffness": "potential_energy", "stiffness_options": {**OPTIONS, "bore": 1.0},
      "transition": 0.0}, "params.geometry.stiffness_options.bore"),
    ({"stiffness": "potential_energy",
      "stiffness_options": {k: v for k, v in OPTIONS.items() if k != "ring_rim_radius"},
      "transition": 0.0}, "params.geometry.stiffness_options.ring_rim_radius"),
    ({"stiffness": "potential_energy", "stiffness_options": OPTIONS},
     "params.geometry.transition"),
    ({"stiffness_options": OPTIONS}, "params.geometry.stiffness_options"),
])
def test_bad_stiffness_input_names_the_field(geometry, field):
    with pytest.raises(ParameterError) as info:
        build_model(load_study_dict(_doc(**geometry)))
    assert info.value.field == field, info.value


# ---------------------------------------------------------------------------------------------
# tooth faults: [[params.geometry.faults]]

CRACK_TABLE = {"kind": "crack", "gear": "planet2", "tooth": 4, "depth": "1 mm"}


def test_study_faults_equal_the_api_bitwise():
    from geardyn.gears import RootCrack

    doc = _doc(stiffness="potential_energy", stiffness_options=OPTIONS, transition=0.0,
               faults=[CRACK_TABLE])
    model = build_model(load_study_dict(doc))
    assert model.faults.gear == "planet2" and model.mesh_order == 23
    base = _by_hand()
    hand = geardyn.PlanetaryGearSet.from_geometry(
        base.geometry, stiffness="potential_energy", stiffness_options=OPTIONS,
        faults=[RootCrack(depth="1 mm", gear="planet2", tooth=4)],
        **{n: base.inputs[n] for n in ("sun", "ring", "carrier", "planet")},
        **{k: base.inputs[k] for k in ("sun_backlash", "ring_backlash", "mesh_damping",
                                       "modal_damping", "sun_torque")},
        harmonics=15).with_omega(float(model.params[model.omega_index]))
    assert np.array_equal(model.params, hand.params)
    from geardyn.io.toml import study_to_toml

    again = build_model(load_study_dict(tomllib.loads(study_to_toml(load_study_dict(doc)))))
    assert np.array_equal(again.params, model.params)  # a saved study keeps its faults


@pytest.mark.parametrize(("fault", "field"), [
    ({"tooth": 23}, "params.geometry.faults[0].tooth"),
    ({"gear": "planet9"}, "params.geometry.faults[0].gear"),
    ({"gear": "moon"}, "params.geometry.faults[0].gear"),
    ({"depth": "-1 mm"}, "params.geometry.faults[0].depth"),
    ({"kind": "dent"}, "params.geometry.faults[0].kind"),
    ({"size": 1.0}, "params.geometry.faults[0].size"),
])
def test_bad_fault_table_names_the_field(fault, field):
    doc = _doc(stiffness="potential_energy", stiffness_options=OPTIONS, transition=0.0,
               faults=[{**CRACK_TABLE, **fault}])
    with pytest.raises(ParameterError) as info:
        build_model(load_study_dict(doc))
    assert info.value.field == field, info.value
