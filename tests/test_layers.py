"""Layers one way: every module of geardyn imports only its own layer and the layers below it,
and neither the packages nor the modules import each other in a cycle.

Imports are read from the source with :mod:`ast` (imports inside functions and under
``TYPE_CHECKING`` count, so does a constant name given to ``importlib.import_module`` or
``importlib.resources.files``); nothing is imported. The kernel templates are ordinary modules
here, and the source the code generator splices from them is checked as well.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

import geardyn

ROOT = Path(geardyn.__file__).resolve().parent

#: The layers, lowest first: a module may import its own layer and those before it, never one
#: after it. Each entry names the modules (or packages, with everything in them) of the layer.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    # modules with no geardyn imports: exceptions, unit parsing, the version, file primitives
    # (atomic writes, attribute encoding), the packaged study files (data only), the kernels'
    # vector width (their compiler pipeline), the cache folder (keyed by that width), the guard of
    # the process-wide patches held during geardyn's compiles, the deferred machine code of nested
    # callees, the calls of big callees bound to one copy
    ("base", ("geardyn._version", "geardyn.errors", "geardyn.files", "geardyn.units",
              "geardyn.studies", "geardyn._jit_target", "geardyn._tuple_alias",
              "geardyn._scoped_patch", "geardyn._lazy_code", "geardyn._bound_calls",
              "geardyn._frame_room", "geardyn._cache")),
    # the model interface, the kernel source, run settings, the lane plan, the section, status
    ("core", ("geardyn.core",)),
    # gear geometry, ISO 6336 stiffness, stiffness waves, planetary mesh phasing (pure numpy)
    ("gears", ("geardyn.gears",)),
    # the models: CATT device, gear pair, user models, parameter records
    ("models", ("geardyn.models",)),
    # gear trains from elements: their linear model (built on gears and models)
    ("trains", ("geardyn.trains",)),
    # numerics: the kernel generator and templates, lane ensembles, simulate, the reference
    ("solvers", ("geardyn.solvers",)),
    # chunking, Dask, the resumable Zarr store
    ("execution", ("geardyn.execution",)),
    # sweeps, maps, continuation, Lyapunov exponents, periodicity, spectra, result datasets
    ("analysis", ("geardyn.analysis",)),
    # the model contract's checks and assert_result
    ("testing", ("geardyn.testing",)),
    # files <-> plain data: TOML study/parameter files, NetCDF results
    ("io", ("geardyn.io",)),
    ("plotting", ("geardyn.plotting",)),
    # study files turned into models
    ("study", ("geardyn.study",)),
    ("reproduction", ("geardyn.reproduction",)),
    # the browser explorer: its state, computations (public API calls) and Bokeh page
    ("explore", ("geardyn.explore",)),
    ("cli", ("geardyn.cli",)),
    # the package itself: the public names (geardyn.simulate, ...)
    ("api", ("geardyn",)),
)
_RANK = {name: k for k, (name, _) in enumerate(LAYERS)}
_DYNAMIC = {("importlib", "import_module"), ("resources", "files")}


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


ALL = modules()


def layer_of(module: str) -> str:
    """The layer of ``module``: the one naming it or its closest enclosing package."""
    best, size = None, -1
    for name, members in LAYERS:
        for m in members:
            if (module == m or module.startswith(m + ".")) and len(m) > size:
                best, size = name, len(m)
    if best is None:
        raise AssertionError(f"{module} belongs to no layer: add it to LAYERS")
    return best


def _target(name: str) -> str:
    """The geardyn module an import names: ``a.b`` if it is a module, else its package."""
    while name and name not in ALL:
        name = name.rpartition(".")[0]
    return name


def _dynamic_name(node: ast.Call) -> str | None:
    """The constant module name of ``importlib.import_module("...")`` or
    ``resources.files("...")``, else None."""
    f = node.func
    if not (isinstance(f, ast.Attribute) and node.args and isinstance(node.args[0], ast.Constant)):
        return None
    owner = f.value.attr if isinstance(f.value, ast.Attribute) else getattr(f.value, "id", "")
    if (owner, f.attr) in _DYNAMIC or f.attr == "import_module":
        value = node.args[0].value
        return value if isinstance(value, str) else None
    return None


def imports_of(module: str, source: str) -> set[str]:
    """The geardyn modules ``module`` (whose text is ``source``) imports, anywhere in it."""
    package = module if ALL[module].name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join([*up, base] if base else up)
            names = [f"{base}.{a.name}" if f"{base}.{a.name}" in ALL else base
                     for a in node.names]
        elif isinstance(node, ast.Call):
            names = [n for n in [_dynamic_name(node)] if n]
        found |= {_target(n) for n in names if n == "geardyn" or n.startswith("geardyn.")}
    found.discard(module)
    return found


@functools.cache
def import_graph() -> dict[str, set[str]]:
    """Module -> the geardyn modules it imports (read when a test first needs it, not at
    collection: each test worker collects this file, one runs its tests)."""
    return {m: imports_of(m, p.read_text(encoding="utf-8")) for m, p in ALL.items()}


def test_every_module_has_a_layer():
    for module in ALL:
        layer_of(module)


def test_no_module_imports_a_higher_layer():
    upward = [
        f"{m} ({layer_of(m)}) imports {t} ({layer_of(t)})"
        for m, targets in import_graph().items() for t in sorted(targets)
        if _RANK[layer_of(t)] > _RANK[layer_of(m)]
    ]
    assert not upward, "imports against the layer order:\n" + "\n".join(upward)


def test_core_is_the_core():
    """The issue's core: the model interface, the kernel source, settings, plan, status."""
    for name in ("model", "kernel_source", "settings", "plan", "status"):
        assert layer_of(f"geardyn.core.{name}") == "core"


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` (a list of nodes, first repeated last), or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt):], nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        state[node] = 2
        stack.pop()
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def _package(module: str) -> str:
    """``geardyn.<first part>``: the top-level package (or module) a module belongs to."""
    return ".".join(module.split(".")[:2])


def test_packages_import_each_other_without_cycle():
    graph: dict[str, set[str]] = {}
    for m, targets in import_graph().items():
        graph.setdefault(_package(m), set()).update(
            _package(t) for t in targets if _package(t) != _package(m))
    assert _cycle(graph) is None, " -> ".join(_cycle(graph) or [])


def test_modules_import_each_other_without_cycle():
    # a package's __init__ re-exports its modules; an import of the package stands for them
    assert _cycle(import_graph()) is None, " -> ".join(_cycle(import_graph()) or [])


@pytest.mark.parametrize("template", ["rk4", "lyapunov"])
def test_spliced_kernel_source_stays_in_the_numerics(template):
    """The text the code generator writes for a template (the shared step core spliced in)
    imports nothing above the solvers."""
    from geardyn.solvers import kernels

    text = kernels._template_text(template)
    module = kernels.TEMPLATES[template]
    above = [t for t in imports_of(module, text) if _RANK[layer_of(t)] > _RANK["solvers"]]
    assert not above, above


def test_the_check_can_fail():
    """An upward import, an unknown module and a cycle are all caught."""
    assert "geardyn.analysis.map2d" in imports_of(
        "geardyn.core.plan", "def f():\n    from geardyn.analysis import map2d\n")
    assert "geardyn.cli.main" in imports_of(
        "geardyn.io.toml", "import importlib\nimportlib.import_module('geardyn.cli.main')\n")
    assert _RANK[layer_of("geardyn.analysis.map2d")] > _RANK[layer_of("geardyn.core.plan")]
    with pytest.raises(AssertionError, match="no layer"):
        layer_of("numpy")
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
