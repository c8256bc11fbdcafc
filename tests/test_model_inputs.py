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
from geardyn.core.inputs import REQUIRED, PhysicalInput, by_name, unit_kind
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


def coefficient_disagreements(inputs) -> list[str]:
    """Where an input declared with a coefficient (whose range applies) disagrees with it: a
    kind other than the kind of the coefficient's unit."""
    out = []
    for i in inputs:
        c = i.coefficient
        if c is not None and unit_kind(c.unit) != i.kind:
            out.append(f"{i.name}: declared {i.kind}, coefficient {c.name} in {c.unit!r}")
    return out


@pytest.mark.parametrize("model", list(MODELS))
def test_an_input_with_a_coefficient_has_the_kind_of_its_unit(model):
    assert coefficient_disagreements(MODELS[model][0]) == []


def test_a_drifted_coefficient_kind_is_caught():
    inputs = by_name(spur_pair_coefficients.INPUTS)
    drifted = [dataclasses.replace(inputs["torque"], kind="force"), inputs["zeta"]]
    assert coefficient_disagreements(drifted) == ["torque: declared force, coefficient torque "
                                                  "in 'N m'"]
    with pytest.raises(ValueError, match="'N\\*m' is none of"):
        unit_kind("N*m")


def test_the_spur_pairs_unit_kinds_are_its_input_coefficients():
    """with_params reads a unit string of every input coefficient by the kind of its declared
    unit (pint's conversion: "80 N m" is 80, "5 percent" 0.05, "20 um" 2e-5)."""
    model = build_model_of("spur_pair_cracked")
    assert set(spur_pair_coefficients.UNIT_KINDS) == {
        c.name for c in spur_pair_coefficients.HEADER.entries if c.kind == "input"}
    for name, text, value in (("torque", "80 N m", 80.0), ("zeta", "5 percent", 0.05),
                              ("backlash", "20 um", 2e-5), ("error_phase", "90 deg", np.pi / 2),
                              ("mass", "2 kg", 2.0), ("Omega", "60 rpm", 2 * np.pi)):
        got = model.with_params(**{name: text}).params[model.param_index(name)]
        assert got == pytest.approx(value, rel=1e-15), name


def build_model_of(study: str):
    from geardyn.study import build_model

    return build_model(builtin_study(study))


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


def _field(params, path):
    for part in path:
        params = getattr(params, part)
    return params


def paper_disagreements(inputs) -> list[str]:
    """Where the CATT device's declared paper names disagree with ``PlanetaryParams.replace``:
    a name that does not set every field of its paths to the value; a swept one whose unit
    string in its axis unit (``"<v> m"``, a dimensionless one in percent) is not the plain
    number (pint's conversion); a choice whose choices are not taken."""
    from geardyn.models.params import PAPER_NAMES, PlanetaryParams

    paper = PlanetaryParams.paper()
    out = []
    for i in inputs:
        paths = PAPER_NAMES[i.name]
        try:
            if i.kind == "choice":
                for c in i.choices:
                    got = paper.replace(**{i.name: c})
                    if any(_field(got, p) != c for p in paths):
                        out.append(f"{i.name}: {c!r} not set")
                continue
            value = _field(paper, paths[0])
            v = 3 if i.kind == "count" else 1.5 * value if value else 0.25
            got = paper.replace(**{i.name: v})
            if any(_field(got, p) != v for p in paths):
                out.append(f"{i.name}: {v!r} not set at every path")
            if i.swept:
                text = (f"{v * 100!r} percent" if i.kind == "dimensionless"
                        else f"{v!r} {i.axis_unit}")
                read = paper.replace(**{i.name: text})
                if any(_field(read, p) != pytest.approx(v, rel=1e-12) for p in paths):
                    out.append(f"{i.name}: {text!r} is not {v!r}")
        except ValidationError as exc:
            out.append(f"{i.name}: {exc.errors()[0]['msg']}")
    return out


def test_the_paper_names_are_the_declared_inputs_of_the_catt_device():
    """PAPER_NAMES and PAPER_INPUTS name the same inputs in one order, each a keyword of
    PlanetaryParams.replace (its fields set, a unit string of its kind read by pint); the
    device's physical_names are the swept ones and its controls the explored ones."""
    from geardyn.models.params import PAPER_INPUTS, PAPER_NAMES, PlanetaryParams

    assert list(PAPER_NAMES) == [i.name for i in PAPER_INPUTS]
    assert {i.of for i in PAPER_INPUTS} == {"replace"}
    assert paper_disagreements(PAPER_INPUTS) == []
    device = geardyn.CATTDevice(PlanetaryParams.paper())
    assert device.physical_names == tuple(i.name for i in PAPER_INPUTS if i.swept)
    assert device.explorer_names == ("xi1", "xi2", "backlash", "error", "B1", "Lambda")


def test_a_drifted_paper_name_is_caught():
    from geardyn.models.params import PAPER_INPUTS

    named = by_name(PAPER_INPUTS)
    drifted = [dataclasses.replace(named["b_c"], kind="angle"), named["xi1"]]
    found = paper_disagreements(drifted)
    assert len(found) == 1 and found[0].startswith("b_c: ")


@pytest.mark.parametrize("study", ["paper_fig3", "planetary_example", "spur_pair_cracked",
                                   "two_stage_train", "gear_pair"])
def test_the_explorers_controls_are_the_declared_ones(study):
    """The explorer's controls of each model kind are the inputs its declarations flag
    ``explore``, in declared order (MAIN_PARAMS, the same from the declaration modules); a
    train's those its study gives one value for every mesh."""
    from geardyn.explore.state import MAIN_PARAMS, ExplorerState, Window

    if study == "gear_pair":
        st = load_study('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.1\n[sweep]\n'
                        'param = "Omega"\nstart = 1.6\nstop = 2.4\nnum = 6\n')
    else:
        st = builtin_study(study)
    state = ExplorerState(st, study, "Omega", Window(1.0, 2.0, 2)) \
        if st.sweep is None or st.sweep.param != "Omega" and st.run.omega is None \
        else ExplorerState(st, study)
    model = state.model
    declared = (model.input_declarations
                or [model.coefficient_layout.slot(n).coefficient for n in model.param_names])
    flagged = tuple(d.name for d in declared if d.explore)
    assert model.explorer_names == flagged == MAIN_PARAMS[state.kind]
    assert len(flagged) >= 4
    offered = tuple(n for n in flagged if n != state.param)
    if state.kind == "train":
        offered = tuple(n for n in offered if n in model.physical_names)
    assert state.main_params() == offered
