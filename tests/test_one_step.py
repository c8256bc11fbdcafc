"""One stepping machinery: the RK4 combination and its weight h / 6 written once
(:mod:`geardyn.solvers._step_shared`) and used by every kernel, the parameter difference step
declared once, and the one-lane-at-a-time Lyapunov reference kept with the tests."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from geardyn.core import settings
from geardyn.solvers import _step_shared

SRC = Path(__file__).resolve().parent.parent / "src" / "geardyn"
#: An RK4 combination written out (``k1 + 2.0 * k2 + 2.0 * k3 + k4`` in any layout) and a step
#: divided by 6 (``h / 6.0``, ``H[lane] / 6.0``; not a constant such as ``1.0 / 6.0``).
COMBINATION = re.compile(r"2\.0 \* [\w\[\]{}, ]+ \+ 2\.0 \*")
SIXTH = re.compile(r"[A-Za-z_\]] / 6\.0\b")


def _hits(pattern: re.Pattern[str]) -> list[str]:
    return [f"{path.relative_to(SRC)}: {line.strip()}"
            for path in sorted(SRC.rglob("*.py"))
            for line in path.read_text().splitlines()
            if pattern.search(line)]


def test_the_rk4_combination_is_written_once():
    assert _hits(COMBINATION) == ["solvers/_step_shared.py: return rk4_update(y, h6, "
                                  "k1 + 2.0 * k2 + 2.0 * k3 + k4)"]
    assert _hits(SIXTH) == ["solvers/_step_shared.py: return h / 6.0"]
    # the patterns find what they look for (the kernels' former spellings)
    for line in ("Y1[k, q] = Y[k, q] + h6 * (K1[k, q] + 2.0 * K2[k, q] + 2.0 * K3[k, q])",
                 "Y1f[m] = Yf[m] + H6f[m] * (K1f[m] + 2.0 * K2f[m] + 2.0 * K3f[m] + K4f[m])",
                 'f"y[{q}] + h6 * (k1[{q}] + 2.0 * k2[{q}] + 2.0 * k3[{q}] + k4[{q}]), "'):
        assert COMBINATION.search(line), line
    for line in ("h6 = h / 6.0", "HW3[2, q, k] = H[lane] / 6.0", "H6[k] = HB[k] / 6.0"):
        assert SIXTH.search(line), line
    assert not SIXTH.search("sn = d * (1.0 + d2 * (-1.0 / 6.0 + d2))")


def test_rk4_combination_sums_left_to_right():
    # the order of the additions decides the last bit: ((k1 + 2 k2) + 2 k3) + k4, then y + h6 s
    rng = np.random.default_rng(3)
    y, h, k1, k2, k3, k4 = rng.standard_normal((6, 2000)) * np.logspace(-8, 8, 2000)
    h6 = h / 6.0
    ref = y + h6 * (((k1 + 2.0 * k2) + 2.0 * k3) + k4)
    other = y + h6 * (k1 + (2.0 * k2 + (2.0 * k3 + k4)))
    comb = _step_shared.rk4_comb.py_func
    got = np.array([comb(*a) for a in zip(y, h6, k1, k2, k3, k4, strict=True)])
    np.testing.assert_array_equal(got, ref)
    assert np.any(got != other)  # an order that rounds differently is told apart
    assert [_step_shared.rk4_sixth.py_func(v) for v in h[:50]] == list(h6[:50])


def test_parameter_difference_step_is_declared_once():
    from geardyn.analysis import branch, curve_systems, grazing

    for mod in (branch, curve_systems, grazing):
        assert mod.PARAM_STEP_REL is settings.PARAM_STEP_REL
        assert not {"DP_REL", "PARAM_REL", "FD_PARAM"} & set(vars(mod))
        assert "PARAM_STEP_REL * (1.0 + abs(" in Path(mod.__file__).read_text()


def test_lyapunov_rows_reference_is_in_the_tests():
    assert _hits(re.compile(r"lyapunov_lanes_rows|_lanes_rows\b")) == []
