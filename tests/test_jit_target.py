"""The kernels' vector width (:mod:`geardyn._jit_target`): the setting, that it reaches geardyn's
compiled functions (LLVM's ``"prefer-vector-width"``, 512-bit zmm registers in their machine
code where asked for) and nothing else in the process, that it survives numba's on-disk cache,
and that results do not depend on it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn import _jit_target as jt


def _has_avx512() -> bool:
    import llvmlite.binding as ll

    return "+avx512f" in ll.get_host_cpu_features().flatten().split(",")


#: A CPU whose LLVM tuning prefers 256-bit vectors although it has AVX-512 (Skylake-SP, as
#: most Intel server CPUs): on any AVX-512 host it shows what the setting does against it.
INTEL_TUNED = "skylake-avx512"


def _fresh(code: str, *args: str, timeout: float = 600.0, **env: str) -> dict:
    """Run ``code`` (which prints one JSON line last) in a fresh interpreter with ``env``,
    within ``timeout`` seconds."""
    full = {k: v for k, v in os.environ.items()
            if k not in (jt.ENV, "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NUMBA_CACHE_DIR")}
    full.update(env)
    out = subprocess.run([sys.executable, "-c", code, *args], env=full, capture_output=True,
                         text=True, timeout=timeout)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


#: A vectorisable loop in a module of geardyn's (a file in its generated-kernels folder: geardyn's
#: cache locator keeps its code), compiled with geardyn's pipeline and cached.
_GEARDYN_MODULE = """
import numba
from geardyn._jit_target import WidthCompiler


@numba.njit(cache=True, pipeline_class=WidthCompiler)
def axpy(a, b):
    for i in range(a.size):
        a[i] = 1.5 * a[i] + b[i]
"""

#: In a fresh interpreter, where numba compiled before geardyn was imported: numba's CPU
#: settings before and after ``import geardyn``, the same loop compiled by geardyn (argv[1]: the
#: folder of :data:`_GEARDYN_MODULE`) and by plain numba, whether geardyn's came from the cache,
#: its LLVM IR (when compiled here) and whether its machine code, as numba's cache file holds
#: it, and plain numba's use zmm registers.
_PROBE = """
import json, shutil, subprocess, sys, tempfile
import numba
import numpy as np
from numba.core import config

numba.njit(lambda x: x + 1)(1)  # numba's CPU target set up before geardyn is imported
before = (config.CPU_NAME, config.CPU_FEATURES)
import geardyn
after_import = (config.CPU_NAME, config.CPU_FEATURES)
sys.path.insert(0, sys.argv[1])
import width_probe


@numba.njit
def plain(a, b):
    for i in range(a.size):
        a[i] = 1.5 * a[i] + b[i]


a = np.ones(64)
width_probe.axpy(a, a)
plain(a, a)
d = width_probe.axpy
sig = d.signatures[0]
hit = sum(d.stats.cache_hits.values()) > 0
# the object code of sig in numba's cache file (numba's own reader of it)
state = d._cache._cache_file.load(d._cache._index_key(sig, d.targetctx.codegen()))
obj = state[0][2][0]
tool = shutil.which("objdump") or shutil.which("llvm-objdump")
zmm = None
if tool:
    with tempfile.NamedTemporaryFile(suffix=".o") as f:
        f.write(obj)
        f.flush()
        zmm = "zmm" in subprocess.run([tool, "-d", f.name], capture_output=True, text=True,
                                      check=True).stdout
print(json.dumps({"settings_kept": before == after_import == (config.CPU_NAME,
                                                            config.CPU_FEATURES),
                  "hit": hit, "ir": "" if hit else d.inspect_llvm(sig),
                  "asm_zmm": None if hit else "zmm" in d.inspect_asm(sig),
                  "cached_zmm": zmm, "plain_zmm": "zmm" in plain.inspect_asm(plain.signatures[0]),
                  "cache": d._cache.cache_path}))
"""


def _probe(cache: Path, mode: str, cpu: str | None = None, **env: str) -> dict:
    kernels = cache / "kernels"
    kernels.mkdir(parents=True, exist_ok=True)
    (kernels / "width_probe.py").write_text(_GEARDYN_MODULE)
    if cpu:
        env["NUMBA_CPU_NAME"] = cpu
    return _fresh(_PROBE, str(kernels), GEARDYN_CACHE_DIR=str(cache), **{jt.ENV: mode}, **env)


def test_the_mode_is_read_from_the_environment_and_checked():
    assert jt.mode_from_env({}) == "512"
    assert jt.mode_from_env({jt.ENV: " Native "}) == "native"
    assert jt.mode_from_env({jt.ENV: "256"}) == "256"
    with pytest.raises(ValueError, match="GEARDYN_SIMD_WIDTH='1024': must be one of 512, 256"):
        jt.mode_from_env({jt.ENV: "1024"})


def test_each_mode_names_its_attribute():
    assert jt.attribute_for("512") == '"prefer-vector-width"="512"'
    assert jt.attribute_for("256") == '"prefer-vector-width"="256"'
    assert jt.attribute_for("native") is None


def _check_width(got: dict, mode: str, cpu: str | None) -> None:
    """What a probe that compiled geardyn's function (no cache hit) shows for ``mode`` on the
    CPU tuning ``cpu``: ``import geardyn`` left numba's CPU settings alone; geardyn's function
    carries the attribute of the mode; with AVX-512 its machine code has zmm registers at 512
    bits, none at 256, and at ``native`` what plain numba's has, and plain numba's code keeps
    LLVM's choice for the CPU."""
    assert got["settings_kept"] and not got["hit"]
    attribute = jt.attribute_for(mode)
    if attribute is None:
        assert "prefer-vector-width" not in got["ir"]
    else:
        assert attribute in got["ir"]
    if _has_avx512():
        if cpu == INTEL_TUNED:  # what makes the case: LLVM keeps this CPU's code to 256 bits
            assert not got["plain_zmm"]
        expected = {"512": True, "256": False}.get(mode, got["plain_zmm"])
        assert got["asm_zmm"] == expected


#: The (mode, CPU tuning) pairs probed on their own; 512 and 256 bits on Intel's tuning are
#: probed by the cache test below, whose first two runs on an empty cache compile them.
_WIDTH_CASES = [("512", None), ("256", None), ("native", None), ("native", INTEL_TUNED)]


@pytest.mark.parametrize(("mode", "cpu"), _WIDTH_CASES)
def test_geardyns_functions_get_the_width_and_nothing_else_does(tmp_path, mode, cpu):
    """In a fresh interpreter, with this CPU's own tuning and with Intel's (``prefer-256-bit``),
    numba used before geardyn: see :func:`_check_width`."""
    if cpu and not _has_avx512():
        pytest.skip("the Intel tuning needs an AVX-512 host")
    _check_width(_probe(tmp_path, mode, cpu), mode, cpu)


@pytest.mark.parametrize("numba_cache_dir", [False, True])
def test_cached_code_keeps_its_width_and_each_width_has_its_own_entries(tmp_path,
                                                                        numba_cache_dir):
    """Two widths take turns on one cache (geardyn's, or numba's ``NUMBA_CACHE_DIR``): each
    compiles its own code the first time (with the width of :func:`_check_width`, on Intel's
    tuning) and loads it the second, and the code loaded from the cache has zmm registers at
    512 bits and none at 256 (Intel's tuning: 256 bits otherwise)."""
    if not _has_avx512():
        pytest.skip("needs an AVX-512 host")
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "numba-own")} if numba_cache_dir else {}
    runs = [(mode, _probe(tmp_path, mode, INTEL_TUNED, **env))
            for mode in ("512", "256", "512", "256")]
    assert [r["hit"] for _, r in runs] == [False, False, True, True]
    for mode, got in runs[:2]:
        _check_width(got, mode, INTEL_TUNED)
    if numba_cache_dir:
        assert Path(runs[0][1]["cache"]).is_relative_to(tmp_path / "numba-own")
    names = sorted(p.name for p in Path(runs[0][1]["cache"]).glob("width_probe.axpy-*.nbi"))
    assert [n.split("-")[2].split(".")[0] for n in names] == ["simd256", "simd512"]
    if shutil.which("objdump") or shutil.which("llvm-objdump"):
        assert [r["cached_zmm"] for _, r in runs] == [mode == "512" for mode, _ in runs]


_SWEEP = """
import json
import numpy as np
import geardyn
from geardyn.solvers.ensemble import run_lanes
m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
P = m.lane_params("Omega", np.linspace(0.3, 3.9, 40))
r = run_lanes(m, P, m.initial_state(), run=geardyn.RunSettings(transient=300.0, samples=16))
print(json.dumps({"samples": r.samples.tobytes().hex(), "crossings": r.crossings.tolist(),
                  "rms": r.obs_rms.tobytes().hex()}))
"""


@pytest.mark.slow
def test_results_are_bitwise_the_same_at_every_vector_width():
    """The reduced CATT device's lanes (edges located, 40 lanes of 12 step counts: full and
    partial vectors) at 512 and 256 bits: each compiles its own kernels (the cache of
    geardyn's functions is keyed by the width)."""
    # a cold compile of the sweep kernels takes minutes (over 600 s on a loaded 2-core machine)
    wide = _fresh(_SWEEP, timeout=1500.0, **{jt.ENV: "512"})
    narrow = _fresh(_SWEEP, timeout=1500.0, **{jt.ENV: "256"})
    assert np.sum(wide["crossings"]) > 0
    assert wide == narrow
