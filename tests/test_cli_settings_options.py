"""The command line's settings options are generated from the settings' fields: every option of
every command that sets a RunSettings or ContinuationSettings field has the field's name (with
dashes; ``simulate --periods`` is the one other name), its type and its help, declared once in
the settings."""

from __future__ import annotations

import dataclasses
import typing

import pytest
import typer

from geardyn.core.settings import ContinuationSettings, RunSettings

#: Which settings each command's options set (command -> (kind, field -> option)).
COMMANDS: dict[str, tuple[type, dict[str, str]]] = {
    "simulate": (RunSettings, {"transient": "--transient", "samples": "--periods",
                               "steps_per_period": "--steps-per-period"}),
    "bifurcation": (RunSettings, {"transient": "--transient", "samples": "--samples",
                                  "steps_per_period": "--steps-per-period",
                                  "converge": "--converge",
                                  "continued_transient": "--continued-transient"}),
    "frc": (RunSettings, {"transient": "--transient", "samples": "--samples",
                          "steps_per_period": "--steps-per-period", "converge": "--converge",
                          "continued_transient": "--continued-transient"}),
    "map": (RunSettings, {"transient": "--transient", "samples": "--samples",
                          "steps_per_period": "--steps-per-period"}),
    "basins": (RunSettings, {"transient": "--transient", "samples": "--samples",
                             "steps_per_period": "--steps-per-period", "converge": "--converge"}),
    "reproduce": (RunSettings, {"transient": "--transient", "samples": "--samples"}),
    "continue": (RunSettings, {"transient": "--transient",
                               "steps_per_period": "--steps-per-period"}),
}
CONTINUE = (ContinuationSettings, {"max_points": "--max-points", "max_period": "--max-period"})

def _commands() -> dict:
    from geardyn.cli.main import app

    return dict(typer.main.get_command(app).commands)


def _cases():
    for name, (kind, fields) in [*COMMANDS.items(), ("continue", CONTINUE)]:
        for field, option in fields.items():
            yield pytest.param(name, kind, field, option, id=f"{name}{option}")


@pytest.mark.parametrize(("command", "kind", "field", "option"), list(_cases()))
def test_option_is_generated_from_its_field(command, kind, field, option):
    params = {p.opts[0]: p for p in _commands()[command].params if p.opts}
    assert option in params, f"geardyn {command} has no {option}"
    p = params[option]
    f = next(f for f in dataclasses.fields(kind) if f.name == field)
    hint = typing.get_type_hints(kind)[field]
    base = next(t for t in (typing.get_args(hint) or (hint,)) if t is not type(None))
    assert p.help.startswith(f.metadata["help"] + " ("), (p.help, f.metadata.get("help"))
    assert p.type_descriptor.annotation is base
    assert p.default is None  # unset: the study's value or the settings' default applies


def test_settings_options_are_declared_nowhere_else():
    """No command module spells a settings option's help itself: each is generated (one
    ``typer.Option`` in cli/common.py builds them all)."""
    from pathlib import Path

    import geardyn.cli

    folder = Path(geardyn.cli.__file__).parent
    helps = {f.metadata["help"] for kind in (RunSettings, ContinuationSettings)
             for f in dataclasses.fields(kind) if "help" in f.metadata}
    for path in folder.glob("*.py"):
        text = path.read_text()
        for h in helps:
            assert h not in text, f"{path.name} repeats the help of a settings field"
