"""The kernels' vector width (:mod:`geardyn._jit_target`): the setting, what it does to numba's
CPU target in a fresh interpreter, and that results do not depend on it."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from geardyn import _jit_target as jt


def _has_avx512() -> bool:
    import llvmlite.binding as ll

    return "+avx512f" in ll.get_host_cpu_features().flatten().split(",")


def _fresh(code: str, timeout: float = 600.0, **env: str) -> dict:
    """Run ``code`` (which prints one JSON line last) in a fresh interpreter with ``env``,
    within ``timeout`` seconds."""
    full = {k: v for k, v in os.environ.items()
            if k not in (jt.ENV, "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES")}
    full.update(env)
    out = subprocess.run([sys.executable, "-c", code], env=full, capture_output=True,
                         text=True, timeout=timeout)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


#: A vectorisable loop compiled by numba; ``asm`` its assembly.
_AXPY = """
import numba, numpy as np
@numba.njit
def axpy(a, b):
    for i in range(a.size):
        a[i] = 1.5 * a[i] + b[i]
a = np.ones(64)
axpy(a, a)
asm = axpy.inspect_asm(axpy.signatures[0])
"""

_STATE = """
import json, warnings
warnings.simplefilter("error", RuntimeWarning)
{pre}
import geardyn
from numba.core import config
""" + _AXPY.replace("{", "{{").replace("}", "}}") + """
print(json.dumps({{"applied": geardyn._jit_target.APPLIED, "features": config.CPU_FEATURES,
                  "zmm": "zmm" in asm}}))
"""


#: The same loop compiled by numba without geardyn (numba's own CPU target).
_NUMBA_ALONE = "import json" + _AXPY + 'print(json.dumps({"zmm": "zmm" in asm}))'


def test_the_mode_is_read_from_the_environment_and_checked():
    assert jt.mode_from_env({}) == "512"
    assert jt.mode_from_env({jt.ENV: " Native "}) == "native"
    assert jt.mode_from_env({jt.ENV: "256"}) == "256"
    with pytest.raises(ValueError, match="GEARDYN_SIMD_WIDTH='1024': must be one of 512, 256"):
        jt.mode_from_env({jt.ENV: "1024"})


def test_the_feature_string_is_the_hosts_with_the_tuning_appended():
    assert jt.features_for("+avx2,+fma", "512") == "+avx2,+fma,-prefer-256-bit"
    assert jt.features_for("+avx2,+fma", "256") == "+avx2,+fma,+prefer-256-bit"
    assert jt.features_for("+avx2,+fma", "native") is None


@pytest.mark.parametrize("mode", ["512", "256", "native"])
def test_each_mode_sets_numbas_cpu_target_in_a_fresh_interpreter(mode):
    import llvmlite.binding as ll

    got = _fresh(_STATE.format(pre=""), **{jt.ENV: mode})
    assert got["applied"].startswith(mode)
    assert got["features"] == jt.features_for(ll.get_host_cpu_features().flatten(), mode)
    if _has_avx512():  # the setting has its effect: 512-bit registers where asked for, none
        # at 256, and at "native" what numba alone chooses for this CPU (LLVM prefers 256-bit
        # code on most Intel server CPUs and 512-bit code on AMD Zen 4)
        expected = {"512": True, "256": False}.get(mode)
        if expected is None:
            expected = _fresh(_NUMBA_ALONE)["zmm"]
        assert got["zmm"] == expected


def test_numbas_own_settings_and_an_early_numba_target_are_left_alone():
    got = _fresh(_STATE.format(pre=""), NUMBA_CPU_NAME="generic")
    assert got["applied"].startswith("numba:") and "prefer-256-bit" not in got["features"]
    early = "import numba\n@numba.njit\ndef f(x):\n    return x\nf(1.0)"
    got = _fresh(_STATE.format(pre=early))
    assert got["applied"].startswith("too late") and not got["features"]
    with pytest.raises(AssertionError, match="not applied: numba's CPU target was set up"):
        _fresh(_STATE.format(pre=early), **{jt.ENV: "512"})  # asked for: a warning (an error)


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
    partial vectors) at 512 and 256 bits: each compiles its own kernels (numba's cache is keyed
    by the CPU features)."""
    # a cold compile of the sweep kernels takes minutes (over 600 s on a loaded 2-core machine)
    wide = _fresh(_SWEEP, timeout=1500.0, **{jt.ENV: "512"})
    narrow = _fresh(_SWEEP, timeout=1500.0, **{jt.ENV: "256"})
    assert np.sum(wide["crossings"]) > 0
    assert wide == narrow
