"""The study file's ``[run]`` table sets every :class:`geardyn.RunSettings` field, and every
command that runs lanes takes its run from it the same way (one reader,
``Study.run_settings``): each field written in ``[run]`` reaches the RunSettings the command
hands to its analysis, and a command-line option overrides it.

The commands are stopped where they call the analysis (nothing is integrated or compiled)."""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from typer.testing import CliRunner

from geardyn.cli.errors import format_error
from geardyn.cli.main import app
from geardyn.core.settings import FIELDS, RunSettings
from geardyn.io.toml import load_study

#: The [run] key of a RunSettings field where it is not the field's name.
RUN_TABLE_NAMES = {"samples": "periods"}

#: A value other than RunSettings' default (and than the base study's) for every field; a new
#: RunSettings field must be added here, and is then checked below.
VALUES: dict[str, Any] = {
    "transient": 123.0, "samples": 7, "steps_per_period": 48, "locate_edges": False,
    "bound": 1234.0, "converge": 1e-7, "transient_max": 5000.0, "continued_transient": 77.0,
    "max_period": 5, "period_tol": 1e-3, "max_section_periods": 3,
}
#: Keys a field needs beside it (transient_max limits a transient by convergence).
COMPANIONS: dict[str, dict[str, Any]] = {"transient_max": {"converge": 1e-7}}
#: The base study's run: an Omega, and a transient (so that ``continue`` builds a run rather
#: than its own first guess, see test_continue_keeps_its_own_guess_without_run_settings).
BASE_RUN: dict[str, Any] = {"omega": 1.2, "transient": 500.0}
BASE = {
    "study": {"name": "pair", "model": "gear_pair"},
    "params": {"zeta": 0.05, "kappa": 0.0, "Fm": 0.1, "Fa": 0.05},
    "sweep": {"param": "Omega", "start": 0.8, "stop": 1.2, "num": 3},
}


def _study_text(run: dict[str, Any]) -> str:
    return tomli_w.dumps({**BASE, "run": {**BASE_RUN, **run}})


def _run_table(field: str) -> dict[str, Any]:
    return {RUN_TABLE_NAMES.get(field, field): VALUES[field], **COMPANIONS.get(field, {})}


class _Stop(Exception):
    """Raised where a command hands its run to the analysis."""


def _recorder(seen: list) -> Any:
    def record(*args: Any, **kwargs: Any) -> None:
        run = kwargs.get("run") or next(a for a in args if isinstance(a, RunSettings))
        seen.append(run)
        raise _Stop

    return record


def _patch(monkeypatch, module: str, name: str, seen: list) -> None:
    monkeypatch.setattr(importlib.import_module(module), name, _recorder(seen))


#: command -> (the analysis it calls: module, name; its arguments after the study file).
COMMANDS: dict[str, tuple[str, str, tuple[str, ...]]] = {
    "simulate": ("geardyn.solvers.simulate", "simulate", ("--yes",)),
    "bifurcation": ("geardyn.analysis.bifurcation", "bifurcation", ("--quiet", "--yes")),
    "frc": ("geardyn.analysis.frc", "frequency_response", ("--quiet", "--yes")),
    "map": ("geardyn.analysis.map2d", "map2d",
            ("--x", "Omega:0.8:1.2:2", "--y", "zeta:0.04:0.06:2", "--yes")),
    "basins": ("geardyn.analysis.basins", "basins",
               ("--x", "x:-1:1:2", "--y", "v:-1:1:2", "--quiet", "--yes")),
    "continue": ("geardyn.analysis.branch", "continuation", ("--range", "0.8:1.0", "--quiet")),
}


def _command_run(monkeypatch, tmp_path: Path, command: str, run: dict[str, Any],
                 *options: str) -> RunSettings:
    """The RunSettings ``command`` hands to its analysis for a study with ``run`` in [run]."""
    module, name, args = COMMANDS[command]
    seen: list = []
    _patch(monkeypatch, module, name, seen)
    if command == "map":  # the estimate's timing run
        monkeypatch.setattr(importlib.import_module("geardyn.analysis.map2d"),
                            "measure_ns_per_lane_step", lambda *a, **k: 100.0)
        args = (*args, "--out", str(tmp_path / "map.nc"))
    study = tmp_path / "study.toml"
    study.write_text(_study_text(run))
    result = CliRunner().invoke(app, [command, str(study), *args, *options])
    assert isinstance(result.exception, _Stop), (result.output, result.exception)
    return seen[-1]


def test_every_run_setting_has_a_run_key():
    """Each RunSettings field is a key of [run] (``periods`` for ``samples``): written there,
    it is the study's run's value. A RunSettings field without a value in VALUES fails here."""
    assert set(VALUES) == set(FIELDS)
    for field in FIELDS:
        study = load_study(_study_text(_run_table(field)))
        assert getattr(study.run_settings(), field) == VALUES[field], field
    assert RunSettings().replace(**VALUES) != RunSettings()  # every value differs from default
    for field in FIELDS:
        assert getattr(RunSettings(), field) != VALUES[field], field


@pytest.mark.parametrize("field", FIELDS)
@pytest.mark.parametrize("command", list(COMMANDS))
def test_each_run_key_reaches_the_run_of_every_command(monkeypatch, tmp_path, command, field):
    run = _command_run(monkeypatch, tmp_path, command, _run_table(field))
    assert getattr(run, field) == VALUES[field]


@pytest.mark.parametrize("command", list(COMMANDS))
def test_the_option_overrides_the_study_in_every_command(monkeypatch, tmp_path, command):
    run = _command_run(monkeypatch, tmp_path, command,
                       {"steps_per_period": 48, "transient": 300.0},
                       "--steps-per-period", "96", "--transient", "40")
    assert (run.steps_per_period, run.transient) == (96, 40.0)
    # the other fields keep the study's values
    run = _command_run(monkeypatch, tmp_path, command, {"bound": 77.0, "locate_edges": False},
                       "--transient", "40")
    assert (run.bound, run.locate_edges, run.transient) == (77.0, False, 40.0)


@pytest.mark.parametrize("field", FIELDS)
def test_each_run_key_reaches_the_explorer_and_the_reproduction(field):
    from geardyn.explore.state import ExplorerState
    from geardyn.reproduction.cases import Case
    from geardyn.reproduction.runner import ReproductionSettings

    study = load_study(_study_text(_run_table(field)))
    assert getattr(ExplorerState(study, "study.toml").run_settings(), field) == VALUES[field]
    # the reproduction sets its transients, samples, convergence and section limit itself
    settings = ReproductionSettings(converge=None)
    own = {"transient", "samples", "continued_transient", "transient_max",
           "max_section_periods"}
    case = Case("fig3")
    case.__dict__["study"] = study
    run = settings.run_settings(case)
    if field not in own and not (field == "converge" and settings.converge is not None):
        assert getattr(run, field) == VALUES[field]


def test_continue_keeps_its_own_guess_without_run_settings(monkeypatch, tmp_path):
    """A study that writes no run setting a branch reads leaves ``continue`` its own first
    guess (no run); one that writes the bound gets a run with it."""
    seen: list = []

    def record(*args: Any, **kwargs: Any) -> None:
        seen.append(kwargs["run"])
        raise _Stop

    monkeypatch.setattr(importlib.import_module("geardyn.analysis.branch"), "continuation",
                        record)
    for run, expect_none in (({"max_period": 5, "periods": 8}, True), ({"bound": 99.0}, False)):
        study = tmp_path / "s.toml"
        study.write_text(tomli_w.dumps({**BASE, "run": {"omega": 1.2, **run}}))
        result = CliRunner().invoke(app, ["continue", str(study), "--range", "0.8:1.0", "-q"])
        assert isinstance(result.exception, _Stop), result.output
        assert (seen[-1] is None) == expect_none
    assert seen[-1].bound == 99.0 and seen[-1].transient == 4000.0


@pytest.mark.parametrize(("line", "start"), [
    ("bound = -1.0", "run.bound: must be > 0 (got -1.0)"),
    ("bound = 0", "run.bound: must be > 0"),
    ("locate_edges = 1", "run.locate_edges: Input should be a valid boolean"),
    ("max_section_periods = 0", "run.max_section_periods: must be >= 1 (got 0)"),
    ("max_section_periods = 1.5", "run.max_section_periods: Input should be a valid integer"),
])
def test_new_run_keys_are_checked_when_the_study_is_read(line, start):
    """The keys checked by RunSettings' own rules, where the study is read: one line naming
    run.<key>."""
    with pytest.raises(ValueError) as info:
        load_study(f'[params]\nbase = "paper"\n[run]\n{line}\n')
    assert format_error(info.value).startswith(start), format_error(info.value)


def test_the_table_declares_nothing_beside_the_settings():
    """The table's own additions (bounds, defaults, descriptions) are of RunSettings fields, and
    its keys are one per field plus omega and transient_periods."""
    from geardyn.io.toml import RUN_TABLE_EXTRAS, RUN_TABLE_OWN, RunTable

    assert set(RUN_TABLE_EXTRAS) <= set(FIELDS)
    keys = {RUN_TABLE_NAMES.get(f, f) for f in FIELDS} | set(RUN_TABLE_OWN)
    assert set(RunTable.model_fields) == keys
