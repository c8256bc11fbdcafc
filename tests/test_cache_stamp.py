"""numba's stamp of geardyn's cached functions covers the geardyn modules they import: an edit
to a helper they inline (the dead zone) or to a module whose constants they freeze in
(coefficient offsets) recompiles them; comments and docstrings do not."""

from __future__ import annotations

import textwrap
from pathlib import Path

import geardyn._cache as gc
from geardyn._cache import GeardynCacheLocator, dependency_files, source_stamp


def _package(root: Path) -> Path:
    """A package tree like geardyn's: kernels.py imports helpers.py, which imports consts.py."""
    pkg = root / "geardyn"
    (pkg / "models").mkdir(parents=True)
    (pkg / "__init__.py").write_text("from geardyn.models import kernels\n")
    (pkg / "models" / "__init__.py").write_text("")
    (pkg / "models" / "kernels.py").write_text(textwrap.dedent('''\
        from geardyn.models.helpers import dead_zone


        def rhs(x):
            return dead_zone(x)
        '''))
    (pkg / "models" / "helpers.py").write_text(textwrap.dedent('''\
        """Helpers."""
        from geardyn.models import consts


        def dead_zone(x):
            return x - consts.B
        '''))
    (pkg / "models" / "consts.py").write_text("B = 1.0  # the backlash\n")
    return pkg


def test_dependencies_of_a_model_kernel_module():
    files = {p.relative_to(gc.PACKAGE_DIR).as_posix()
             for p in dependency_files(gc.PACKAGE_DIR / "models" / "catt_kernels.py")}
    assert {"models/elements.py", "models/derived.py", "core/coefficients.py"} <= files
    assert "__init__.py" not in files  # the package's __init__ (every layer) is none


def test_stamp_follows_imported_modules(tmp_path, monkeypatch):
    pkg = _package(tmp_path)
    monkeypatch.setattr(gc, "PACKAGE_DIR", pkg)
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    kernels = pkg / "models" / "kernels.py"
    namespace: dict = {}
    exec(compile("def rhs(x):\n    return x\n", str(kernels), "exec"), namespace)
    locator = GeardynCacheLocator.from_function(namespace["rhs"], str(kernels))
    assert locator is not None
    names = {p.name for p in dependency_files(kernels)}
    assert names == {"kernels.py", "helpers.py", "consts.py", "__init__.py"}  # models/__init__
    stamps = [locator.get_source_stamp()]
    assert stamps[0] == source_stamp(kernels)

    consts = pkg / "models" / "consts.py"
    consts.write_text("B = 1.0  # the backlash, in backlash units\n\n")  # comment, layout
    stamps.append(locator.get_source_stamp())
    helpers = pkg / "models" / "helpers.py"
    helpers.write_text(helpers.read_text().replace('"""Helpers."""', '"""The helpers."""'))
    stamps.append(locator.get_source_stamp())
    assert stamps[1] == stamps[0] == stamps[2]  # comments and docstrings change nothing

    consts.write_text("B = 2.0\n")  # a constant frozen into compiled code, two imports away
    stamps.append(locator.get_source_stamp())
    helpers.write_text(helpers.read_text().replace("x - consts.B", "x + consts.B"))
    stamps.append(locator.get_source_stamp())
    assert len(set(stamps[2:])) == 3  # each code edit: a new stamp
