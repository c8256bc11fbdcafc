"""A copied or moved geardyn cache is reused: a model's generated kernels, copied with the rest of
``$GEARDYN_CACHE_DIR`` to another folder (a Docker image, a CI cache, a Dask worker's folder),
with or without their files' times, load from the copy in a new process instead of compiling
again (numba keeps their entries below the cache's root, and their stamp names their files
relative to the folders that move with them: :func:`geardyn._cache.stamp_name`)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numba
from numba.core import config

import geardyn
from geardyn import _cache
from geardyn._cache import GeardynCacheLocator
from geardyn.solvers import kernels
from shared_models import oscillator

TESTS = Path(__file__).resolve().parent


def _model() -> geardyn.UserModel:
    """A model the suite already compiles (its trajectory kernel: tests/warm_kernels.py)."""
    return oscillator(zeta=0.05, F=0.5)


def _simulate() -> None:
    geardyn.simulate(_model(), run=geardyn.RunSettings(samples=3))


#: In a fresh process (the cache of its environment): the simulation of :func:`_model`, then
#: numba's cache hits and misses of every generated kernel module's functions.
_SCRIPT = """
import json, sys
import numba
from test_cache_move import _simulate
_simulate()
stats = {}
for name, module in list(sys.modules.items()):
    if not name.startswith("geardyn_"):
        continue
    for value in list(vars(module).values()):
        if isinstance(value, numba.core.registry.CPUDispatcher) and (
                value.py_func.__module__ == name):
            stats[f"{name}.{value.py_func.__name__}"] = (
                sum(value.stats.cache_hits.values()), sum(value.stats.cache_misses.values()))
print(json.dumps(stats))
"""


def _cache_files(module) -> list[tuple[Path, Path]]:  # noqa: ANN001 (a generated module)
    """(file, its path relative to the cache's root) of a generated kernel module's file and of
    its entries in numba's cache, as a copy of the whole cache folder would place them."""
    root, numba_root = _cache.cache_root(), Path(config.CACHE_DIR or _cache.numba_cache_dir())
    source = Path(module.__file__)
    out = [(source, source.relative_to(root))]
    folders = {Path(v._cache._cache_path) for v in vars(module).values()
               if isinstance(v, numba.core.registry.CPUDispatcher)
               and v.py_func.__module__ == module.__name__}
    for folder in folders:
        for entry in folder.glob(f"{module.__name__}.*"):
            if entry.suffix in (".nbi", ".nbc"):
                out.append((entry, Path("numba") / entry.relative_to(numba_root)))
    return out


def _copy(files: list[tuple[Path, Path]], dest: Path, keep_times: bool) -> None:
    for src, rel in files:
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        (shutil.copy2 if keep_times else shutil.copyfile)(src, dest / rel)


def _entries(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*") if p.suffix in (".nbi", ".nbc")}


def test_a_copied_cache_loads_the_kernels_it_holds(tmp_path):
    """The model's kernels, compiled into this process's cache (or loaded: the suite's warm-up
    compiles them), are copied to a new cache folder as ``cp -r`` copies them (new paths, new
    times); a new process on the copy loads every kernel function it calls from it: no cache
    miss, no new cache entry. (A copy that keeps the times, ``shutil.copytree`` or ``cp -a``,
    differs from it only in the files' modified times, which no stamp reads.)"""
    _simulate()
    files = [f for template in (kernels.CORE, "rk4")
             for f in _cache_files(kernels.kernels_for(_model().kernel, template))]
    assert any(rel.suffix == ".nbc" for _, rel in files)
    dest = tmp_path / "copy"
    _copy(files, dest, keep_times=False)
    before = _entries(dest)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(GEARDYN_CACHE_DIR=str(dest), GEARDYN_COMPILE_AHEAD="0", PYTHONPATH=os.pathsep.join(
        [str(Path(geardyn.__file__).resolve().parents[1]), str(TESTS), env.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", _SCRIPT], env=env, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    stats = json.loads(out.stdout.strip().splitlines()[-1])
    assert {k: m for k, (_, m) in stats.items() if m} == {}
    assert stats and sum(h for h, _ in stats.values()) >= 1, stats
    assert _entries(dest) == before


def _locator_path(py_file: Path) -> Path:
    def f():
        pass

    return Path(GeardynCacheLocator(f, str(py_file)).get_cache_path())


def test_kernel_entries_are_kept_below_the_caches_root(tmp_path, monkeypatch):
    """A generated kernel module's entries: ``numba/kernels`` in the cache folder, or
    ``kernels`` in ``NUMBA_CACHE_DIR`` where it is set (shared by every geardyn cache that
    uses it: a kernel module's name is a hash of its code); the package's functions' are kept
    by their folder's path, as numba keeps them."""
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "g"))
    monkeypatch.setattr(config, "CACHE_DIR", "")
    kernel = tmp_path / "g" / "kernels" / "geardyn_rk4_0123.py"
    assert _locator_path(kernel) == tmp_path / "g" / "numba" / "kernels"
    package_file = _cache.PACKAGE_DIR / "solvers" / "_step_shared.py"
    folder = _locator_path(package_file)
    assert folder.parent == tmp_path / "g" / "numba" and folder.name.startswith("solvers_")
    assert folder.name == GeardynCacheLocator.get_suitable_cache_subpath(str(package_file))
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path / "n"))
    assert _locator_path(kernel) == tmp_path / "n" / "kernels"
    assert _locator_path(package_file) == tmp_path / "n" / folder.name
