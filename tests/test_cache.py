"""One kernel cache for every entry point: ``import geardyn`` (the API, the ``geardyn`` command,
the tests) puts generated kernels and numba's compiled code in ``$GEARDYN_CACHE_DIR`` (default
``~/.cache/geardyn``), explicitly set variables win, and ``make`` does not move it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_CACHE_VARS = ("GEARDYN_CACHE_DIR", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME")

#: Run in a fresh interpreter: where geardyn's kernels and numba's cache go.
_PROBE = """
import json, sys
from pathlib import Path
if sys.argv[1] == "numba-first":
    import numba  # noqa: F401
import geardyn, numba
from geardyn.solvers.kernels import cache_dir
from geardyn.core._noop import no_events
numba_dir = Path(no_events._cache._cache_path).parent  # where numba keeps geardyn's code
print(json.dumps({"kernels": str(cache_dir()), "numba": str(numba_dir)}))
"""


def _probe(env: dict[str, str], order: str = "geardyn-first") -> dict:
    base = {k: v for k, v in os.environ.items() if k not in _CACHE_VARS}
    base["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), base.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, "-c", _PROBE, order], env={**base, **env},
                         capture_output=True, text=True, timeout=300, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("order", ["geardyn-first", "numba-first"])
def test_default_cache_holds_kernels_and_numba_code(tmp_path, order):
    """Nothing set: both under $XDG_CACHE_HOME/geardyn (~/.cache/geardyn), also where numba was
    imported before geardyn."""
    got = _probe({"XDG_CACHE_HOME": str(tmp_path)}, order)
    assert Path(got["kernels"]) == tmp_path / "geardyn" / "kernels"
    assert Path(got["numba"]) == tmp_path / "geardyn" / "numba"


def test_home_cache_is_the_default(tmp_path):
    got = _probe({"HOME": str(tmp_path)})
    assert Path(got["numba"]) == tmp_path / ".cache" / "geardyn" / "numba"


def test_set_variables_win(tmp_path):
    got = _probe({"GEARDYN_CACHE_DIR": str(tmp_path / "g")})
    assert Path(got["kernels"]) == tmp_path / "g" / "kernels"
    assert Path(got["numba"]) == tmp_path / "g" / "numba"
    got = _probe({"GEARDYN_CACHE_DIR": str(tmp_path / "g"), "NUMBA_CACHE_DIR": str(tmp_path / "n")})
    assert Path(got["kernels"]) == tmp_path / "g" / "kernels"
    assert Path(got["numba"]) == tmp_path / "n"


@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_make_does_not_move_the_cache():
    """``make demo`` / ``make test`` use the cache the plain ``geardyn`` command uses: the
    Makefile exports no cache folder of its own."""
    env = {k: v for k, v in os.environ.items() if k not in _CACHE_VARS}
    out = subprocess.run(
        ["make", "-s", "--no-print-directory", "-f", str(ROOT / "Makefile"), "--eval",
         'show-cache-env: ; @echo "[$$GEARDYN_CACHE_DIR][$$NUMBA_CACHE_DIR]"', "show-cache-env"],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "[][]"


@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_make_keeps_pythons_bytecode_cache():
    """``make test`` / ``make demo`` let Python write and read its bytecode cache even where the
    environment turns it off (PYTHONDONTWRITEBYTECODE=1): else every test worker and every
    subprocess compiles the source of numba, pandas and xarray again."""
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    out = subprocess.run(
        ["make", "-s", "--no-print-directory", "-f", str(ROOT / "Makefile"), "--eval",
         'show-bytecode-env: ; @echo "[$${PYTHONDONTWRITEBYTECODE-unset}]"', "show-bytecode-env"],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "[unset]"


def test_a_shared_modules_edit_renames_every_generated_kernel(tmp_path, monkeypatch):
    """numba's cache of a generated module holds the compiled code of the shared modules it
    imports and checks only the generated file: an edit of a shared module must give every
    generated module a new name (a new file, compiled anew), not load the old code."""
    from geardyn.solvers import kernels

    shared = tmp_path / "geardyn_fake_shared.py"
    shared.write_text("X = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(kernels, "SHARED_MODULES", (*kernels.SHARED_MODULES,
                                                    "geardyn_fake_shared"))
    before = kernels._source_digest("text", {})
    assert kernels._source_digest("text", {}) == before
    shared.write_text("X = 2\n")
    assert kernels._source_digest("text", {}) != before


_UID_SCRIPT = """
import json, numba
from geardyn.solvers import kernels
def f(x):
    return x + 1
d = numba.njit(f)
kernels._quiet_compile(d)
d(1)
print(json.dumps([o.fndesc.uid for o in d.overloads.values()]))
"""


def test_code_compiled_in_two_processes_shares_no_name(tmp_path):
    """The same function compiled first thing in two processes gets different names (numba
    numbers compiled functions from 1 in every process; geardyn's compiles from a random base),
    so cached kernels compiled by several processes define no symbol twice when one process
    loads them."""
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT / "src")}
    env.pop("NUMBA_CACHE_DIR", None)
    uids = [json.loads(subprocess.run([sys.executable, "-c", _UID_SCRIPT], env=env,
                                      capture_output=True, text=True, check=True).stdout)[0]
            for _ in range(2)]
    assert uids[0] != uids[1] and min(uids) >= 1 << 16


def test_numbas_own_numbering_is_restored_after_a_geardyn_compile():
    import numba
    from numba.core.bytecode import FunctionIdentity

    from geardyn.solvers import kernels

    before = FunctionIdentity._unique_ids
    d = numba.njit(lambda x: x * 2)
    kernels._quiet_compile(d)
    assert d(2) == 4
    assert FunctionIdentity._unique_ids is before
    assert next(iter(d.overloads.values())).fndesc.uid >= 1 << 16
