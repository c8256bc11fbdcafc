"""Physical inputs declared once (geardyn.core.inputs): each model's declaration agrees with its
constructor's signature (read with inspect, both ways, so the two cannot drift apart), the
``[params]`` tables generated from the declarations agree with both, accept every built-in study
and refuse an unknown key naming it."""

from __future__ import annotations

import dataclasses
import inspect
import tomllib

import numpy as np
import pytest
from pydantic import ValidationError

import geardyn
from geardyn.core.inputs import REQUIRED, PhysicalInput, by_name
from geardyn.io.toml import (
    PlanetaryGearSetParams,
    SpurPairParams,
    TrainModelParams,
    builtin_study,
    builtin_study_names,
    builtin_study_text,
    load_study,
    load_study_dict,
    study_to_toml,
)
from geardyn.models import planetary_coefficients, spur_pair_coefficients
from geardyn.trains import TrainModel
from geardyn.trains import inputs as train_inputs

#: model -> (its declared inputs, its builders by name, the constructor's non-input arguments,
#: the generated study table, the study kind)
MODELS = {
    "SpurPair": (spur_pair_coefficients.INPUTS,
                 {"__init__": geardyn.SpurPair.__init__,
                  "from_geometry": geardyn.SpurPair.from_geometry},
                 spur_pair_coefficients.BUILT_ON, SpurPairParams, "spur_pair"),
    "PlanetaryGearSet": (planetary_coefficients.INPUTS,
                         {"__init__": geardyn.PlanetaryGearSet.__init__,
                          "from_geometry": geardyn.PlanetaryGearSet.from_geometry},
                         (), PlanetaryGearSetParams, "planetary"),
    "TrainModel": (train_inputs.INPUTS, {"__init__": TrainModel.__init__},
                   train_inputs.BUILT_ON, TrainModelParams, "train"),
}


def signature_disagreements(inputs, builders, built_on) -> list[str]:
    """Where the declared inputs and the builders' signatures disagree, one line each."""
    declared = by_name(inputs)
    out = []
    for i in declared.values():
        params = inspect.signature(builders[i.of]).parameters
        if i.name not in params:
            out.append(f"{i.name}: declared, no parameter of {i.of}")
            continue
        p = params[i.name]
        default = REQUIRED if p.default is inspect.Parameter.empty else p.default
        if default != i.default:
            out.append(f"{i.name}: declared default {i.default!r}, {i.of} has {default!r}")
    for name, p in inspect.signature(builders["__init__"]).parameters.items():
        if name == "self" or name in built_on or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        if name not in declared:
            out.append(f"{name}: a constructor parameter, not declared")
    return out


@pytest.mark.parametrize("model", list(MODELS))
def test_declared_inputs_are_the_constructor_keywords(model):
    """Every declared input is a keyword of its builder with the declared default, and every
    constructor keyword (but the structure the model is built on) is declared."""
    inputs, builders, built_on, _, _ = MODELS[model]
    assert signature_disagreements(inputs, builders, built_on) == []


def test_a_drifted_declaration_is_caught():
    """The comparison fails on a changed default, an input the constructor lacks and a
    constructor keyword left undeclared."""
    inputs, builders, built_on, _, _ = MODELS["PlanetaryGearSet"]
    named = by_name(inputs)
    drifted = [dataclasses.replace(named["mesh_damping"], default=0.02),
               PhysicalInput("gear_ratio", "number", "not a keyword", 1.0),
               *(i for i in inputs if i.name not in ("mesh_damping", "modal_damping"))]
    assert signature_disagreements(drifted, builders, built_on) == [
        "mesh_damping: declared default 0.02, __init__ has 0.05",
        "gear_ratio: declared, no parameter of __init__",
        "modal_damping: a constructor parameter, not declared"]


@pytest.mark.parametrize("model", list(MODELS))
def test_study_table_is_the_declared_inputs(model):
    """One field per input a study takes, in declared order, with the builder's default (None
    where the study may give an alternative instead, an empty list for an empty sequence) and
    the declared meaning; the inputs a study does not take are constructor keywords that
    another input (the geometry) sets."""
    inputs, builders, _, table, _ = MODELS[model]
    fields = table.model_fields
    assert list(fields) == [i.name for i in inputs if i.study]
    for i in inputs:
        if not i.study:
            assert i.name not in fields
            continue
        f = fields[i.name]
        sig = inspect.signature(builders[i.of]).parameters[i.name]
        if sig.default is inspect.Parameter.empty and i.alternative:
            assert not f.is_required() and f.default is None, i.name
        elif sig.default is inspect.Parameter.empty:
            assert f.is_required(), i.name
        elif sig.default == ():
            assert f.default_factory() == [], i.name
        else:
            assert f.default == sig.default, i.name
        assert f.description == i.meaning


BUILTIN = [(name, tomllib.loads(builtin_study_text(name))) for name in builtin_study_names()]
TABLES = {kind: table for _, _, _, table, kind in MODELS.values()}


@pytest.mark.parametrize(("name", "doc"), [b for b in BUILTIN
                                           if b[1]["study"].get("model") in TABLES],
                         ids=lambda v: v if isinstance(v, str) else "")
def test_study_tables_read_every_builtin_study(name, doc):
    """The generated table reads the built-in study's [params] (values as given or in SI, as
    the table declares), a study reads back equal from its TOML, and an unknown key is refused
    naming it."""
    kind = doc["study"]["model"]
    study = builtin_study(name)
    assert isinstance(study.params, TABLES[kind])
    assert study.params == TABLES[kind].model_validate(doc["params"])
    assert set(doc["params"]) <= set(study.params.model_fields_set)
    again = load_study(study_to_toml(study))  # (a train study's built train: a new object)
    assert again.params == study.params and again.to_toml_dict() == study.to_toml_dict()
    bad = {**doc, "params": {**doc["params"], "gear_ratio": 2.0}}
    with pytest.raises(ValidationError) as err:
        load_study_dict(bad)
    assert [e["loc"] for e in err.value.errors()] == [("params", "gear_ratio")]
    assert err.value.errors()[0]["type"] == "extra_forbidden"


def test_every_study_kind_has_a_builtin_study():
    """Each generated table is read by at least one built-in study (so the test above runs for
    all three)."""
    assert {d["study"].get("model") for _, d in BUILTIN} >= set(TABLES)


@pytest.mark.parametrize(("kw", "message"), [
    ({"kind": "velocity"}, "kind must be one of"),
    ({"kind": "number", "form": "per_gear"}, "form must be one of"),
    ({"kind": "choice"}, "declares its choices"),
    ({"kind": "choice", "choices": ("a", "b"), "default": "c"}, "not one of the choices"),
    ({"kind": "table"}, "names its table"),
    ({"kind": "pair"}, "declares its unit_kind"),
    ({"kind": "pair", "unit_kind": "colour"}, "unit_kind must be one of"),
])
def test_a_malformed_declaration_is_refused(kw, message):
    with pytest.raises(ValueError, match=message):
        PhysicalInput("x", meaning="an input", **kw)


def test_a_name_declared_twice_is_refused():
    with pytest.raises(ValueError, match="'zeta' is declared twice"):
        by_name((*spur_pair_coefficients.INPUTS, spur_pair_coefficients.INPUTS[3]))


def test_a_planetary_study_takes_one_mesh_stiffness_per_planet():
    """The per-planet form the declaration gives sun_mesh_stiffness (the constructor's): a list
    in the study is the set's per-planet stiffness."""
    from geardyn.study import build_model

    doc = tomllib.loads(builtin_study_text("planetary_example"))
    params = {k: v for k, v in doc["params"].items()
              if k not in ("geometry", "held", "carrier_speed") and not k.endswith("torque")}
    params.update(n_planets=3, sun_mesh_stiffness=["5e8 N/m", 5e8, "0.55 GN/m"],
                  ring_mesh_stiffness=6e8)
    model = build_model(load_study_dict({**doc, "params": params}))
    assert np.asarray(model.k_s).tolist() == [5e8, 5e8, 5.5e8]
    assert np.broadcast_to(model.k_r, 3).tolist() == [6e8] * 3
