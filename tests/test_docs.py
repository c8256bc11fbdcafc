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

ROOT = Path(__file__).resolve().parent.parent
PUBLIC: tuple[ModuleType, ...] = (geardyn, geardyn.gears, geardyn.testing)


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
