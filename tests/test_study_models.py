"""The registry of study model kinds (:data:`geardyn.io.study_models.STUDY_MODELS`): every kind
builds its model from its example study and survives a write and a read; an unknown kind is a
one-line error naming the known ones; the tables keyed by kind in the layers above (builders,
``params show`` views, ``plot`` redraws) cover the registries they read."""

from __future__ import annotations

import typing

import pytest

from geardyn.cli import bifurcation as cli_bifurcation
from geardyn.cli import main as cli_main
from geardyn.core.results import SCHEMAS
from geardyn.errors import ParameterError
from geardyn.io import study_models
from geardyn.io.study_models import STUDY_MODELS, study_model
from geardyn.io.toml import (
    Model,
    builtin_study,
    builtin_study_names,
    load_study,
    params_class,
    params_kind,
    study_to_toml,
)
from geardyn.study import BUILDERS, FAULTED, build_model, study_omega

#: The model class each kind's study builds, written out here (not read from the registry).
MODEL_CLASSES = {"catt": "CATTDevice", "gear_pair": "GearPair", "spur_pair": "SpurPair",
                 "planetary": "PlanetaryGearSet", "train": "TrainModel"}
#: The kinds whose ``[params]`` set the forcing frequency (a speed), written out here.
OMEGA_FROM_PARAMS = {"spur_pair", "train"}


def _example(kind: str):
    text = STUDY_MODELS[kind].example
    return builtin_study(text) if text in builtin_study_names() else load_study(text)


def test_the_registry_names_the_kinds_a_study_file_takes():
    assert set(STUDY_MODELS) == set(MODEL_CLASSES)
    assert typing.get_args(Model) == tuple(sorted(MODEL_CLASSES))


@pytest.mark.parametrize("kind", list(MODEL_CLASSES))
def test_each_kind_round_trips_from_its_example(kind):
    """The example study is of the kind, its ``[params]`` of the kind's table class, its model
    of the kind's class; written and read back, it is the same study and builds a model with
    the same coefficients, initial state and forcing frequency."""
    study = _example(kind)
    assert study.study.model == kind
    assert params_kind(study.params).name == kind
    if kind != "catt" or type(study.params).__name__ != "PaperBase":
        assert type(study.params) is params_class(kind)
    model = build_model(study)
    assert type(model).__name__ == MODEL_CLASSES[kind]
    again = load_study(study_to_toml(study))
    assert again.model_dump() == study.model_dump()
    rebuilt = build_model(again)
    assert type(rebuilt) is type(model)
    assert rebuilt.coefficient_values() == model.coefficient_values()
    assert list(rebuilt.initial_state()) == list(model.initial_state())
    assert rebuilt.omega == model.omega
    # Omega from [params] (a speed) where the kind declares it, else only from [run].omega
    without_run = again.model_copy(update={"run": again.run.model_copy(update={"omega": None})})
    expected = model.omega if kind in OMEGA_FROM_PARAMS else None
    assert study_omega(without_run, rebuilt) == expected


def test_an_unknown_kind_is_one_error_naming_the_known_ones():
    with pytest.raises(ParameterError) as info:
        study_model("spur")
    text = str(info.value)
    assert len(text.splitlines()) == 1
    assert text.startswith("study.model:") and "'spur'" in text
    assert all(k in text for k in MODEL_CLASSES)


def test_an_unknown_kind_in_a_study_file_is_a_one_line_cli_error(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('[study]\nmodel = "spur"\n[params]\nbase = "paper"\n')
    with pytest.raises(SystemExit) as info:
        cli_main.main(["params", "show", str(path)])
    err = capsys.readouterr().err.strip()
    assert info.value.code == 2
    assert len(err.splitlines()) == 1 and err.startswith("error: ")
    assert "study.model" in err and "spur" in err
    assert all(f"'{k}'" in err for k in MODEL_CLASSES), err


def test_every_kind_has_a_builder_and_a_view():
    assert set(BUILDERS) == set(STUDY_MODELS)
    assert set(FAULTED) == {k for k, m in STUDY_MODELS.items() if m.dataset is not None}
    assert set(cli_main.PARAMS_VIEWS) == set(study_models.PARAMS_VIEWS)


def test_plot_redraws_the_registered_result_kinds():
    """Every redraw is of a registered result kind (by its name) or a mesh stiffness dataset;
    a registered kind without one (a periodic orbit) is refused naming it."""
    names = {s.name for s in SCHEMAS.values()}
    assert set(cli_bifurcation.REDRAWS) - names == {"mesh stiffness"}
    assert cli_bifurcation._PLOT_KIND == {
        "simulation": "simulation", "bifurcation": "bifurcation", "map2d": "map",
        "reproduction-case": "reproduction", "basins": "basins",
        "frequency-response": "frequency response", "continuation": "continuation",
        "runup": "run-up", "dynamic-factor": "dynamic factor", "curve": "curve"}
    xr = pytest.importorskip("xarray")
    ds = xr.Dataset(attrs={"geardyn_kind": "periodic-orbit"})
    with pytest.raises(ParameterError, match="unknown result kind 'periodic-orbit'"):
        cli_bifurcation._dataset_kind(ds)


def test_faulted_model_replaces_the_study_faults_or_refuses_the_kind():
    """A spur pair with no fault tables is the study's pair built without its [[faults]]; a
    kind that takes no faults is refused naming those that do."""
    from geardyn.errors import StudyError
    from geardyn.study import faulted_model

    study = _example("spur_pair")
    assert study.faults  # the example is a cracked pair
    healthy = build_model(study.model_copy(update={"faults": None}))
    assert faulted_model(study, []).coefficient_values() == healthy.coefficient_values()
    assert faulted_model(study, []).coefficient_values() != build_model(
        study).coefficient_values()
    with pytest.raises(StudyError, match="spur_pair, planetary, train"):
        faulted_model(_example("catt"), [])
