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


#: The graze bound of an edge screen written out (``min(abs(g0), abs(g1)) > ...``, any names).
SCREEN = re.compile(r"min\(abs\([^()]+\), abs\([^()]+\)\) > GRAZE_BOUND")


def test_the_edge_screen_is_written_once():
    assert _hits(SCREEN) == [
        "solvers/_step_shared.py: near = not min(abs(g0), abs(g1)) > GRAZE_BOUND * abs(d2)",
        "solvers/_step_shared.py: graze = not min(abs(g0), abs(g1)) > GRAZE_BOUND_STEP * "
        "abs(ge - g1)"]
    # the pattern finds the kernels' former spellings
    for line in ("if (crossed or not s * d2 < 0.0) and not min(abs(g0), abs(g1)) > GRAZE_BOUND "
                 "* abs(d2):",
                 "if not min(abs(G0[r, j]), abs(g1)) > GRAZE_BOUND_STEP * abs(gbuf[1, j] - g1):",
                 'f"graze = not min(abs(a), abs(b)) > GRAZE_BOUND_STEP * abs(ge[{j}] - b)",'):
        assert SCREEN.search(line), line
    # every kernel layout screens through them
    solvers = SRC / "solvers"
    for name, calls in (("_step_shared.py", ("screen_grid(",)),
                        ("_step_core.py", ("screen_grid(", "screen_lone(")),
                        ("_kernel_template.py", ("screen_grid(",)),
                        ("_lyapunov_template.py", ("screen_lone(",))):
        text = (solvers / name).read_text()
        for call in calls:
            assert text.count(call) >= (2 if name == "_step_shared.py" else 1), (name, call)


def _dipping_quadratics(rng, n):
    """Quadratics g(s) = c0 + c1 s + c2 s^2 that stay positive at s = 0 and s = 1 and dip below
    zero in between (an edge grazed within a step, no sign change at its ends)."""
    out = []
    while len(out) < n:
        c2 = 10.0 ** rng.uniform(-6, 3)
        s_min = rng.uniform(0.02, 0.98)
        depth = -c2 * rng.uniform(1e-6, 1.0) * min(s_min, 1.0 - s_min) ** 2
        c1 = -2.0 * c2 * s_min
        c0 = depth + c2 * s_min**2
        g0, g1 = c0, c0 + c1 + c2
        if g0 > 0.0 and g1 > 0.0:
            out.append((c0, c1, c2))
    return out


def test_grid_screen_flags_every_graze_between_grid_points():
    # a quadratic event sampled on the grid s = -1, 0, 1 that dips across the edge in (0, 1)
    # without leaving its side at the grid points: the screen must flag the step (locate), and
    # a sign change at the end is always flagged
    screen = _step_shared.screen_grid.py_func
    rng = np.random.default_rng(34)
    for c0, c1, c2 in _dipping_quadratics(rng, 2000):
        gp, g0, g1 = c0 - c1 + c2, c0, c0 + c1 + c2
        assert screen(g1, 1.0, g0, gp, True) == (True, True)
        assert screen(g1, 1.0, g0, gp, False) == (False, False)
        assert screen(-g1, -1.0, -g0, -gp, True) == (True, True)  # the mirror image
        assert screen(-g1, 1.0, g0, gp, False) == (False, True)
    # far from the edge and bending away from it: nothing flagged
    assert screen(5.0, 1.0, 4.0, 3.5, True) == (False, False)
    assert screen(-5.0, -1.0, -4.0, -3.5, True) == (False, False)


def test_lone_step_screen_flags_every_graze_within_the_step():
    # the same quadratics over a lone step s in [0, 1]: ge = g(0) + g'(0) (the event at the Euler
    # point, exact for an event linear in the state) must flag each of them
    screen = _step_shared.screen_lone.py_func
    rng = np.random.default_rng(35)
    for c0, c1, c2 in _dipping_quadratics(rng, 2000):
        g0, g1, ge = c0, c0 + c1 + c2, c0 + c1
        assert screen(g1, 1.0, g0, ge) == (True, True)
        assert screen(-g1, -1.0, -g0, -ge) == (True, True)
        assert screen(-g1, 1.0, g0, ge)[1]
    # a straight event far from the edge: nothing flagged
    assert screen(3.0, 1.0, 2.0, 3.0) == (False, False)
