"""Each name of the step machinery is imported from the module that defines it: the templates
and the model's core (:mod:`geardyn.solvers._step_core`) take the model-independent parts from
:mod:`geardyn.solvers._step_shared`, and no solver module passes on a name it only imports."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _defined(module: str) -> set[str]:
    """The names a module binds itself (functions, classes, assignments at any depth of its
    top-level statements, e.g. in an ``if`` branch), not those it imports."""
    tree = ast.parse((ROOT / "src" / (module.replace(".", "/") + ".py")).read_text())
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            out.add(node.name)
        elif isinstance(node, ast.Assign | ast.AnnAssign | ast.AugAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            out.update(n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name))
    return out


def _private_solver_imports():
    """(file, module, name) of every ``from geardyn.solvers._x import name`` in src and tests."""
    for path in sorted([*(ROOT / "src").rglob("*.py"), *(ROOT / "tests").rglob("*.py")]):
        text = path.read_text()
        if "geardyn.solvers._" not in text:  # no such import: nothing to parse
            continue
        for node in ast.walk(ast.parse(text)):
            if (isinstance(node, ast.ImportFrom) and node.module
                    and node.module.startswith("geardyn.solvers._")
                    and (ROOT / "src" / (node.module.replace(".", "/") + ".py")).exists()):
                for alias in node.names:
                    yield path.relative_to(ROOT), node.module, alias.name


def test_names_are_imported_from_where_they_are_defined():
    defined: dict[str, set[str]] = {}
    passed_on = [f"{path}: {name} from {module}" for path, module, name in
                 _private_solver_imports()
                 if name not in defined.setdefault(module, _defined(module))]
    assert not passed_on, passed_on


def test_the_core_imports_only_what_it_uses():
    """``_step_core`` keeps no import for others (the templates once took shared names from
    it): every name it imports from ``_step_shared`` is used in its own text."""
    src = (ROOT / "src/geardyn/solvers/_step_core.py").read_text()
    tree = ast.parse(src)
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    imported = [a.name for node in tree.body if isinstance(node, ast.ImportFrom)
                and node.module == "geardyn.solvers._step_shared" for a in node.names]
    assert imported and not [name for name in imported if name not in used]
