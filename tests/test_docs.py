"""The documentation site's promises that need no Sphinx: every public name has a docstring and a
place in the API reference (docs/api/index.rst), and every gallery example has a title."""

from __future__ import annotations

import ast
import inspect
import re
from pathlib import Path
from types import ModuleType

import pytest

import geardyn
import geardyn.gears
import geardyn.testing
import geardyn.trains

ROOT = Path(__file__).resolve().parent.parent
PUBLIC: tuple[ModuleType, ...] = (geardyn, geardyn.gears, geardyn.testing, geardyn.trains)


def _public() -> list[tuple[ModuleType, str]]:
    return [(mod, name) for mod in PUBLIC for name in mod.__all__]


def _own_doc(obj: object) -> str:
    """A class's or module's own docstring (not one inherited from a base), else getdoc."""
    if inspect.isclass(obj) or inspect.ismodule(obj):
        return (vars(obj).get("__doc__") or "").strip()
    return (inspect.getdoc(obj) or "").strip()


def _data_doc_comment(mod: ModuleType, name: str) -> str:
    """The ``#:`` comment above a module-level constant, found where ``mod`` imports it from."""
    source = inspect.getsource(mod)
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module and any(
                (a.asname or a.name) == name for a in node.names):
            import importlib

            return _data_doc_comment(importlib.import_module(node.module), name)
    lines = source.splitlines()
    for i, line in enumerate(lines):
        if re.match(rf"{name}\s*(:[^=]*)?=", line):
            comment = []
            while i > 0 and lines[i - 1].lstrip().startswith("#:"):
                i -= 1
                comment.insert(0, lines[i].lstrip()[2:].strip())
            return " ".join(comment)
    return ""


@pytest.mark.parametrize(("mod", "name"), _public(), ids=lambda v: getattr(v, "__name__", v))
def test_public_name_has_a_docstring(mod: ModuleType, name: str):
    obj = getattr(mod, name)
    if inspect.isclass(obj) or inspect.isroutine(obj) or inspect.ismodule(obj):
        assert _own_doc(obj), f"{mod.__name__}.{name} has no docstring"
    else:  # a constant: documented by a '#:' comment above its assignment (Sphinx autodata)
        assert _data_doc_comment(mod, name), f"{mod.__name__}.{name} has no '#:' doc comment"


def test_public_methods_have_docstrings():
    """Public methods and properties of public classes (inherited docstrings count, as in
    autodoc)."""
    missing = []
    for mod, name in _public():
        cls = getattr(mod, name)
        if not inspect.isclass(cls):
            continue
        for attr, value in vars(cls).items():
            if attr.startswith("_") or attr.startswith("model_"):
                continue
            routine = isinstance(value, property | staticmethod | classmethod)
            if (routine or inspect.isfunction(value)) and not (
                    inspect.getdoc(getattr(cls, attr, value)) or "").strip():
                missing.append(f"{mod.__name__}.{name}.{attr}")
    assert not missing, f"no docstring: {missing}"


def test_api_reference_lists_every_public_name():
    text = (ROOT / "docs" / "api" / "index.rst").read_text(encoding="utf-8")
    listed = set(re.findall(r"^\s+(\w+)\s*$", text, re.M))
    listed |= set(re.findall(r"^\.\. (?:autodata|automodule|autofunction|autoclass):: "
                             r"(?:geardyn\.(?:\w+\.)*)?(\w+)", text, re.M))
    missing = [f"{mod.__name__}.{name}" for mod, name in _public()
               if name not in listed and not (mod is geardyn and name in ("gears", "testing"))]
    assert not missing, f"not in docs/api/index.rst: {missing}"


def test_gallery_examples_have_a_title_and_a_figure():
    examples = sorted((ROOT / "examples").glob("plot_*.py"))
    assert len(examples) >= 6
    for path in examples:
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
        assert doc and re.search(r"^=+$", doc, re.M), f"{path.name}: no title in its docstring"
        assert "fig" in path.read_text(encoding="utf-8"), f"{path.name} draws no figure"


def test_user_guide_study_file_is_valid():
    """The TOML study shown in the user guide reads, validates and builds its model."""
    from geardyn.io import load_study

    text = (ROOT / "docs" / "guide" / "studies.md").read_text(encoding="utf-8")
    toml = re.search(r"```toml\n(.*?)```", text, re.S)
    assert toml, "no TOML study in docs/guide/studies.md"
    model = geardyn.build_model(load_study(toml.group(1)))
    assert isinstance(model, geardyn.CATTDevice)
    by_api = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.02, xi2=0.02,
                                                              backlash="50 um"))
    assert list(model.params) == pytest.approx(list(by_api.params), rel=1e-12)


# ----------------------------------------------------------------------------------- README
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _readme_blocks(lang: str) -> list[str]:
    """The README's fenced code blocks of language ``lang`` ("" for unlabelled ones)."""
    return [m.group(2) for m in re.finditer(r"^```(\w*)\n(.*?)^```", README, re.S | re.M)
            if m.group(1) == lang]


def _readme_command_lines(program: str) -> list[str]:
    """Every ``program ...`` command of the README: lines of its shell and plain code blocks
    (backslash continuations joined, ``#`` comments dropped) and inline code spans."""
    lines = []
    for block in _readme_blocks("sh") + _readme_blocks(""):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.split(" #")[0].strip()
            if line.startswith(program + " "):
                lines.append(line)
    prose = re.sub(r"^```.*?^```", "", README, flags=re.S | re.M)
    lines += [s for s in re.findall(r"`([^`\n]+)`", prose) if s.startswith(program + " ")]
    return lines


def _cli_options() -> dict[str, set[str]]:
    """The options each ``geardyn`` (sub)command's --help lists, by command path ("" for the
    program itself, "params show" for a subcommand of a group)."""
    import click
    import typer

    from geardyn.cli.main import app

    found: dict[str, set[str]] = {}

    def walk(cmd: click.Command, path: str) -> None:
        found[path] = {opt for p in cmd.params if not getattr(p, "hidden", False)
                       for opt in (*p.opts, *p.secondary_opts) if opt.startswith("--")}
        found[path].add("--help")
        for name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, f"{path} {name}".strip())

    walk(typer.main.get_command(app), "")
    return found


def test_readme_command_lines_use_options_that_exist():
    """Every ``geardyn SUBCOMMAND ... --option`` of the README names a subcommand and options
    that its --help lists (the README's command summary, its examples and its prose)."""
    commands = _cli_options()
    lines = _readme_command_lines("geardyn")
    assert len(lines) >= 20, lines  # the command summary and the examples were all found
    wrong = []
    for line in lines:
        words = line.split()[1:]
        path = ""
        while words and f"{path} {words[0]}".strip() in commands:
            path = f"{path} {words.pop(0)}".strip()
        if path == "" and words and not words[0].startswith("-"):
            wrong.append(f"{line}: no subcommand {words[0]!r}")
            continue
        wrong += [f"{line}: {path or 'geardyn'} has no {opt}"
                  for opt in re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", line)
                  if opt not in commands[path]]
    assert not wrong, "\n".join(wrong)


def test_readme_make_targets_exist():
    targets = set(re.findall(r"^([a-z][\w-]*):", (ROOT / "Makefile").read_text(), re.M))
    named = set(re.findall(r"make ([a-z][\w-]*)", README))
    assert named and named <= targets, named - targets


def test_readme_names_the_cache_every_entry_point_uses(monkeypatch):
    """The README names $GEARDYN_CACHE_DIR and its default, which is where geardyn puts the
    kernels when nothing is set."""
    from geardyn._cache import cache_root

    for var in ("GEARDYN_CACHE_DIR", "XDG_CACHE_HOME"):
        monkeypatch.delenv(var, raising=False)
    default = re.search(r"`\$GEARDYN_CACHE_DIR` \(default `([^`]+)`[;)]", README)
    assert default, "the README does not name the kernel cache and its default"
    assert Path(default.group(1)).expanduser() == cache_root()


def _current_figure(row_id: str) -> str:
    """The measured column of the current-figures row ``row_id`` of bench/RESULTS.md."""
    for line in (ROOT / "bench" / "RESULTS.md").read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) > 2 and cells[0] == row_id:
            return cells[2]
    raise AssertionError(f"bench/RESULTS.md has no current figure {row_id!r}")


#: The README's compile and demo figures: (what it says, with the figure as a group; the
#: bench/RESULTS.md row; the figure in that row's measured column).
README_FIGURES = [
    (r"`make demo` on a fresh clone took (\d+) s end to end", "demo", r"^(\d+) s wall"),
    (r"the point with their first compile (\d+) s", "demo", r"first compile (\d+) s"),
    (r"every analysis of the gear pair: (\d+) s of CPU", "compile-GearPair", r"^(\d+) s CPU"),
    (r"`SpurPair`: (\d+) s", "compile-SpurPair", r"^(\d+) s CPU"),
    (r"shares already cached by an earlier one: (\d+) s", "compile-UserModel-one-form-own",
     r"^(\d+) s CPU"),
]


@pytest.mark.parametrize(("said", "row", "measured"), README_FIGURES,
                         ids=[f"{row}-{i}" for i, (_, row, _) in enumerate(README_FIGURES)])
def test_readme_figures_are_the_benchmarks_current_ones(said, row, measured):
    """A compile or demo figure the README states is the one bench/RESULTS.md holds now (the
    row its command writes), so that a new measurement cannot leave the README behind."""
    text = " ".join(README.split())
    got = re.search(said, text)
    assert got, f"the README no longer says {said!r}"
    figure = re.search(measured, _current_figure(row))
    assert figure, (row, _current_figure(row))
    assert got.group(1) == figure.group(1), (
        f"README: {got.group(0)!r}; bench/RESULTS.md {row}: {figure.group(0)!r}")


def test_readme_python_snippet_runs(tmp_path, monkeypatch):
    """The README's Python blocks run as printed (in a scratch folder: they write files)."""
    blocks = _readme_blocks("python")
    assert blocks, "no ```python block in README.md"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    for k, block in enumerate(blocks):
        exec(compile(block, f"README.md:python-block-{k}", "exec"), {"__name__": "__readme__"})
    assert (tmp_path / "run.nc").exists() and (tmp_path / "bif.pdf").exists()


def test_license_file_matches_pyproject():
    import tomllib

    license_ = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert license_ == {"text": "MIT"} and text.startswith("MIT License")
    assert "Permission is hereby granted, free of charge" in text
