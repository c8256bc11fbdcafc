"""The command line's settings options are generated from the settings' fields: every option of
every command that sets a RunSettings, ContinuationSettings or RunupSettings field has the
field's name (with dashes; ``simulate --periods`` is the one other name), its type and its help,
declared once in the settings."""

from __future__ import annotations

import dataclasses
import typing

import pytest
import typer

from geardyn.analysis.runup import RunupSettings
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
#: The run-up's options that set its settings' fields as they are (--start, --stop and --rate
#: are in the unit of --param, converted by the command).
RUNUP = (RunupSettings, {"duration": "--duration", "transient": "--transient",
                         "sample_rate": "--sample-rate", "steps_per_period": "--steps-per-period"})

def _commands() -> dict:
    from geardyn.cli.main import app

    return dict(typer.main.get_command(app).commands)


def _cases():
    for name, (kind, fields) in [*COMMANDS.items(), ("continue", CONTINUE), ("runup", RUNUP)]:
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
    helps = {f.metadata["help"] for kind in (RunSettings, ContinuationSettings, RunupSettings)
             for f in dataclasses.fields(kind) if "help" in f.metadata}
    for path in folder.glob("*.py"):
        text = path.read_text()
        for h in helps:
            assert h not in text, f"{path.name} repeats the help of a settings field"


@pytest.mark.parametrize(("command", "kind", "field", "option"), list(_cases()))
def test_a_commands_options_name_its_generated_option(command, kind, field, option):
    """``named_options`` (what a command hands the settings, so that an error names the option
    it came from) names each field's option as the generated option itself is named."""
    from geardyn.cli.common import named_options

    if option == "--periods":  # simulate's other name for samples, given by hand
        return
    assert named_options(kind, **{field: 3}) == {field: (option, 3)}


def test_named_options_refuse_a_field_without_an_option():
    from geardyn.cli.common import named_options, run_options

    with pytest.raises(KeyError, match="no command-line field bogus"):
        run_options(transient=1.0, bogus=2)
    with pytest.raises(KeyError, match="ContinuationSettings"):
        named_options(ContinuationSettings, transient=1.0)


def test_settings_option_names_are_spelled_nowhere_else():
    """No command module maps a settings field to its option's name by hand
    (``{"transient": ("--transient", transient)}``): ``run_options``/``named_options`` name
    them from the fields; simulate's ``--periods`` (samples) is the one other name."""
    import re
    from pathlib import Path

    import geardyn.cli
    from geardyn.cli.common import option_name

    folder = Path(geardyn.cli.__file__).parent
    names = {option_name(f.name) for kind in (RunSettings, ContinuationSettings, RunupSettings)
             for f in dataclasses.fields(kind) if "help" in f.metadata}
    pattern = re.compile(r":\s*\(\s*(?:\"(--[a-z-]+)\"|option_name\()")
    for path in folder.glob("*.py"):
        if path.name == "common.py":  # where run_options and named_options name them
            continue
        for m in pattern.finditer(path.read_text()):
            assert m.group(1) is not None and m.group(1) not in names, (path.name, m.group(0))


def _options_named(option: str) -> dict[str, typer.core.click.Option]:
    """Every command's option whose long name is ``option`` (command -> option)."""
    out = {}
    for name, command in _commands().items():
        for p in command.params:
            if option in getattr(p, "opts", ()):
                out[name] = p
    return out


def test_the_shared_switches_are_declared_once():
    """``--quiet`` (no progress bar) and ``--yes`` mean the same on every command that has
    them: one name, short form and help each (``geardyn dynamic-factor --quiet``, which drops
    a summary line, has its own help)."""
    from geardyn.cli.common import QuietOption, YesOption

    quiet = typing.get_args(QuietOption)[1]
    yes = typing.get_args(YesOption)[1]
    found = _options_named("--quiet")
    assert len(found) >= 8
    for name, p in found.items():
        assert p.opts + p.secondary_opts == ["--quiet", "-q"], name
        if name != "dynamic-factor":
            assert p.help == quiet.help, name
    found = _options_named("--yes")
    assert {"map", "basins", "frc", "bifurcation"} <= set(found)
    for name, p in found.items():
        assert p.opts == ["--yes"] and p.help == yes.help, name
