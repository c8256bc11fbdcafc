"""numba's stamp of geardyn's cached functions covers the geardyn modules they import: an edit
to a helper they inline (the dead zone) or to a module whose constants they freeze in
(coefficient offsets) recompiles them; comments and docstrings do not."""

from __future__ import annotations

import os
import shutil
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


def test_each_files_facts_are_kept_in_the_cache_for_its_state(tmp_path, monkeypatch):
    """A file's digest and imports are kept in the cache (``stamps/``) for its state (times,
    size, inode), so that other processes read them instead of parsing the file: a memo is read
    while the file is as it was, and ignored once it is edited or another file is put in its
    place (even one of the same size with the same modified time); where the cache cannot be
    written, the stamp is computed all the same."""
    pkg = _package(tmp_path)
    monkeypatch.setattr(gc, "PACKAGE_DIR", pkg)
    kernels, consts = pkg / "models" / "kernels.py", pkg / "models" / "consts.py"

    def stamp_with(cache: str) -> bytes:
        """The stamp of kernels.py as a new process would take it, with the cache ``cache``."""
        monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / cache))
        gc._facts.cache_clear()
        return source_stamp(kernels)

    stamp = stamp_with("cache")
    memos = sorted((tmp_path / "cache" / "stamps").iterdir())
    assert {gc._memo_path(p) for p in dependency_files(kernels)} == set(memos)
    assert stamp_with("cache") == stamp
    # the memo is what another process reads: a forged digest in it changes the stamp
    memo = gc._memo_path(consts)
    data = memo.read_bytes()
    head = gc._memo_key() + f"{consts}\0{gc._state(consts.stat())}\0".encode()
    assert data.startswith(head)
    memo.write_bytes(head + bytes(32) + data[len(head) + 32:])
    assert stamp_with("cache") != stamp
    # another file put in its place, of the same size, its modified time kept: parsed again
    before = consts.stat()
    other = tmp_path / "consts.py"
    other.write_text("B = 3.0  # the backlash\n")
    os.utime(other, ns=(before.st_atime_ns, before.st_mtime_ns))
    other.replace(consts)
    assert (consts.stat().st_mtime_ns, consts.stat().st_size) == (before.st_mtime_ns,
                                                                  before.st_size)
    replaced = stamp_with("cache")
    assert replaced == stamp_with("fresh") != stamp
    # an edit: parsed again
    consts.write_text("B = 2.0\n")
    edited = stamp_with("cache")
    assert edited == stamp_with("fresh2") not in (stamp, replaced)
    # no writable cache (its folder would be below a file): computed, nothing kept
    (tmp_path / "file").write_text("")
    assert stamp_with("file/cache") == edited
    gc._facts.cache_clear()


def test_stamp_of_a_kernel_is_the_same_in_a_copy_and_follows_edits(tmp_path, monkeypatch):
    """A generated kernel module's stamp names its files relative to the folders that move with
    them (the kernel module relative to the kernels folder, the package's files relative to the
    package), so a copy of the cache and of the package at other paths, even with new file times
    (``cp -r``), has the same stamp; an edit in the copy, of the kernel module or of a package
    module it imports, changes it."""
    def stamp(where: str) -> bytes:
        """The stamp of the kernel module of the tree ``where``, as a new process takes it."""
        monkeypatch.setattr(gc, "PACKAGE_DIR", tmp_path / where / "geardyn")
        monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / where / "cache"))
        gc._facts.cache_clear()
        kernel = tmp_path / where / "cache" / "kernels" / "geardyn_rk4_0123.py"
        assert gc.is_geardyn_file(kernel)
        return source_stamp(kernel)

    _package(tmp_path / "one")
    kernels = tmp_path / "one" / "cache" / "kernels"
    kernels.mkdir(parents=True)
    (kernels / "geardyn_rk4_0123.py").write_text(
        "from geardyn.models.helpers import dead_zone\n\n\ndef f(x):\n    return dead_zone(x)\n")
    first = stamp("one")
    shutil.copytree(tmp_path / "one", tmp_path / "two", copy_function=shutil.copyfile)
    assert stamp("two") == first
    # the cache moved to a folder that sorts on the other side of the package's
    shutil.copytree(tmp_path / "one" / "cache", tmp_path / "z" / "cache")
    monkeypatch.setattr(gc, "PACKAGE_DIR", tmp_path / "one" / "geardyn")
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "z" / "cache"))
    gc._facts.cache_clear()
    assert source_stamp(tmp_path / "z" / "cache" / "kernels" / "geardyn_rk4_0123.py") == first
    helpers = tmp_path / "two" / "geardyn" / "models" / "helpers.py"
    helpers.write_text(helpers.read_text().replace("x - consts.B", "x + consts.B"))
    edited = stamp("two")
    assert edited != first
    kernel = tmp_path / "two" / "cache" / "kernels" / "geardyn_rk4_0123.py"
    kernel.write_text(kernel.read_text().replace("dead_zone(x)\n", "dead_zone(x) + 1.0\n"))
    assert stamp("two") not in (first, edited)
    assert stamp("one") == first
    gc._facts.cache_clear()
