"""The plain numba RK4 peer of bench/peers.py integrates the same equations as geardyn's
GearPair: checked against the reference integrator (DOP853, rtol 1e-12, edges located)."""

from __future__ import annotations

import importlib.util
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import geardyn
from geardyn.solvers.reference import reference_solution

PEERS = Path(__file__).resolve().parents[1] / "bench" / "peers.py"


@pytest.fixture(scope="module")
def peers():
    spec = importlib.util.spec_from_file_location("bench_peers", PEERS)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_peers"] = module
    spec.loader.exec_module(module)
    return module


def test_plain_rk4_matches_reference(peers):
    # coefficients other than the benchmark's (backlash not 1) and a period-2 impacting motion
    model = geardyn.GearPair(zeta=0.08, kappa=0.3, Fm=0.15, Fa=0.2, backlash=0.8, Omega=1.06)
    coef = np.array([0.08, 0.3, 0.15, 0.2, 0.8])
    y0 = np.asarray(model.initial_state(), float)
    om, n_tr, samples = 1.06, 6, 4
    T = 2.0 * math.pi / om
    times = (n_tr + np.arange(1, samples + 1)) * T
    ref = reference_solution(model, y0, times)
    fine = reference_solution(model, y0, np.linspace(T, times[-1], 400))
    assert fine[:, 0].min() < 0.8 < fine[:, 0].max()  # the teeth separate: both branches of g

    def points(n, kernel):
        out = np.full((1, samples, 2), np.nan)
        kernel(np.array([om]), np.array([n_tr]), samples, n, coef, y0, out)
        return out[0]

    errs = {n: np.max(np.abs(points(n, peers.rk4_lanes) - ref)) for n in (128, 1024)}
    assert errs[1024] < 1e-6
    assert errs[1024] < errs[128] / 8  # it converges (second order or better)
    table = points(1024, peers.rk4_lanes_table)
    assert np.max(np.abs(table - ref)) < 1e-6


def test_write_section_replaces_only_peers(peers, tmp_path):
    path = tmp_path / "RESULTS.md"
    path.write_text("# Benchmark results\n\n## bifurcation\n\nkeep 1\n\n## Peers\n\nold\n\n"
                    "## map\n\nkeep 2\n")
    peers.write_section("## Peers\n\nnew table\n", path)
    text = path.read_text()
    assert "old" not in text and "new table" in text
    assert text.index("keep 1") < text.index("new table") < text.index("## map")
    assert "keep 2" in text
    peers.write_section("## Peers\n\nnewer\n", path)  # replaces again, appends nothing
    assert path.read_text().count("## Peers") == 1 and "newer" in path.read_text()


def test_current_figures_row_is_replaced_alone_with_date_and_commit(tmp_path):
    spec = importlib.util.spec_from_file_location("bench_results", PEERS.with_name("_results.py"))
    results = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(results)
    path = tmp_path / "RESULTS.md"
    path.write_text("# Benchmark results\n\nintro\n\n## Peers\n\nkeep\n")
    results.record("lyapunov", "<= 30 ns", "68.8 ns", "2.29x over", "bench/lyapunov.py", path)
    results.record("paper-workload", "<= 0.3 s", "1.18 s", "3.93x over", "bench/bif.py", path)
    results.record("lyapunov", "<= 30 ns", "25.0 | ns", "met", "bench/lyapunov.py", path)
    text = path.read_text()
    rows = [line for line in text.splitlines() if line.startswith("| ")][1:]
    assert [r.split("|")[1].strip() for r in rows] == ["paper-workload", "lyapunov"]
    cells = [c.strip() for c in rows[1].strip("|").split("|")]
    assert cells[2:4] == ["25.0 / ns", "met"]  # a pipe in a figure cannot break the table
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", cells[4]) and cells[5]
    assert "68.8" not in text and text.count(results.BEGIN) == 1
    assert text.index(results.BEGIN) < text.index("intro") < text.index("## Peers")  # on top
    assert "keep" in text
    assert results.against(1.18, 0.3) == "3.93x over" and results.against(0.2, 0.3) == "met"
    assert results.against(4.0, 5.0, lower_is_better=False) == "1.25x under"


@pytest.mark.parametrize("script", ["peers", "crossing", "fused_loop"])
def test_bench_scripts_leave_geardyn_its_vector_width(script):
    # the bench scripts define numba functions of their own, and import geardyn in any order:
    # the width is set on geardyn's own functions (geardyn._jit_target), whatever numba did
    # before, and the scripts report the width geardyn's kernels run at
    code = (f"import sys; sys.path.insert(0, {str(PEERS.parent)!r}); import {script}; "
            "import geardyn; print(geardyn._jit_target.APPLIED)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env={**os.environ, "GEARDYN_SIMD_WIDTH": "256"})
    assert out.stdout.strip().startswith("256:"), out.stdout + out.stderr
