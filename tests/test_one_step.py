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


def _solver_hits(pattern: re.Pattern[str]) -> set[str]:
    """The solver modules (kernel templates and their shared parts) with a line that matches."""
    return {path.name for path in sorted((SRC / "solvers").glob("*.py"))
            if any(pattern.search(line) for line in path.read_text().splitlines())}


#: A statistics update written out: a running minimum or maximum of a statistic's array element
#: (or of a generated element ``{e}``, or of lo / hi) and a running sum of squares ``x + v * v``.
EXTREME = re.compile(r"(?:\b(?:min|max)|\{op\})\((?:[A-Z]{4}\[|\{e\}|lo,|hi,)")
SQUARE = re.compile(r"\+ (\w+) \* \1\b")


def test_the_statistics_update_is_written_once():
    assert _solver_hits(EXTREME) == {"_step_shared.py"}
    assert _solver_hits(SQUARE) == {"_step_shared.py"}
    # the patterns find the kernels' former spellings
    for line in ("GMIN[j, k] = min(GMIN[j, k], g) if STAT[k] else GMIN[j, k]",
                 "OMAX[j, k] = max(OMAX[j, k], v) if STAT[k] else OMAX[j, k]",
                 "GMAX[j, k] = max(GMAX[j, k], g)",
                 'lines.append(f"{e} = _pick(stat, {op}({e}, g[{j}]), {e})")'):
        assert EXTREME.search(line), line
    for line in ("OSQ[j, k] = OSQ[j, k] + v * v if STAT[k] else OSQ[j, k]",
                 'lines.append(f"{e} = _pick(stat, {e} + v * v, {e})")'):
        assert SQUARE.search(line), line
    # every layout updates through them: the fused loop's generated helper, the block loop, the
    # out-of-line slot
    solvers = SRC / "solvers"
    assert (solvers / "_step_core.py").read_text().count('"stat_') >= 3
    text = (solvers / "_kernel_template.py").read_text()
    assert text.count("stat_min(") >= 3 and text.count("stat_max(") >= 3
    assert text.count("stat_square(") >= 1


#: A finite-difference tangent step written out: the perturbation's size (``FD_DELTA * ...``),
#: a row's offset e (s v) and the difference quotient's 0.5 / e.
FD_SIZE = re.compile(r"FD_DELTA \*")
FD_OFFSET = re.compile(r"\* \((?:S\[[^\]]*\]|sq|s) \* ")
FD_QUOTIENT = re.compile(r"\b0\.5 / [A-Za-z]")


def test_the_tangent_step_is_written_once():
    for pattern in (FD_SIZE, FD_OFFSET, FD_QUOTIENT):
        assert _solver_hits(pattern) == {"_step_shared.py"}, pattern
    # the patterns find the kernels' former spellings
    assert FD_SIZE.search("NY[l] = FD_DELTA * (1.0 + min(math.sqrt(NY[l]), FD_NORM_CAP))")
    for line in ("d = e * (S[q] * Z[j, q])", "d = E[j, l] * (sq * ZT[j, q, l])",
                 'lines = [f"d{q} = e * (S[{q}] * v[{q}])" for q in range(n)]'):
        assert FD_OFFSET.search(line), line
    for line in ("inv = 0.5 / E[j]", "v = ((ya - yb) * (0.5 / e)) * iq"):
        assert FD_QUOTIENT.search(line), line
    # the one-lane step (Lyapunov, monodromy), the row blocks, the fused lanes and the flagged
    # lanes build and read back their rows through them
    solvers = SRC / "solvers"
    core = (solvers / "_step_core.py").read_text()
    lyap = (solvers / "_lyapunov_template.py").read_text()
    for name in ("fd_scale(", "fd_size(", "fd_rows(", "fd_tangent("):
        assert core.count(name) >= 1 and lyap.count(name) >= 2, name
    assert "_tangent_step(" in (solvers / "_monodromy_template.py").read_text()


def _shared_py(name):
    """A compiled function of :mod:`._step_shared` as Python, its calls of ``_pick`` too (the
    compiled functions are not called from Python, see :func:`phase_table_values`)."""
    fn = getattr(_step_shared, name).py_func
    glb = dict(fn.__globals__, _pick=_step_shared._pick.py_func)
    return type(fn)(fn.__code__, glb, fn.__name__, fn.__defaults__, fn.__closure__)


def test_statistics_update_matches_numpy():
    rng = np.random.default_rng(36)
    v = rng.standard_normal(500) * np.logspace(-3, 3, 500)
    stat = rng.random(500) < 0.7
    lo, hi, sq = np.inf, -np.inf, 0.0
    smin, smax, ssq = (_shared_py(n) for n in ("stat_min", "stat_max", "stat_square"))
    for x, s in zip(v, stat, strict=True):
        lo, hi, sq = smin(lo, x, s), smax(hi, x, s), ssq(sq, x, s)
    assert lo == v[stat].min() and hi == v[stat].max()
    assert np.isclose(sq, np.sum(v[stat] ** 2), rtol=1e-13)
    assert smin(1.0, -2.0, False) == 1.0 and smax(1.0, 2.0, False) == 1.0
    assert ssq(1.0, 2.0, False) == 1.0


def test_tangent_rows_difference_a_linear_map_exactly():
    # rows y +- e s v (fd_scale, fd_size, fd_rows) stepped by a linear map A and read back
    # (fd_tangent): A v, to the rounding of the difference (~eps / FD_DELTA)
    scale, size, rows, tangent = (_shared_py(n) for n in ("fd_scale", "fd_size", "fd_rows",
                                                          "fd_tangent"))
    rng = np.random.default_rng(37)
    for _ in range(200):
        n = int(rng.integers(1, 6))
        A = rng.standard_normal((n, n))
        s = 10.0 ** rng.uniform(-2, 2, n)
        y = rng.standard_normal(n) * s
        v = rng.standard_normal(n)
        e, ok = size(scale(float(np.sum((y / s) ** 2))), float(np.sum(v * v)))
        assert ok and np.isclose(e * np.linalg.norm(v),
                                 _step_shared.FD_DELTA * (1.0 + np.linalg.norm(y / s)))
        pairs = [rows(y[q], e, s[q], v[q], ok) for q in range(n)]
        ya = A @ np.array([a for a, _ in pairs])
        yb = A @ np.array([b for _, b in pairs])
        got = np.array([tangent(ya[q], yb[q], e, 1.0 / s[q]) for q in range(n)])
        want = (A @ (s * v)) / s
        assert np.allclose(got, want, rtol=1e-7, atol=1e-7 * np.abs(want).max())
    # a lost vector (zero or not finite): no perturbation, a NaN tangent
    for vv in (0.0, np.inf, np.nan):
        with np.errstate(divide="ignore", invalid="ignore"):  # (compiled: no check, as numpy)
            e, ok = size(np.float64(1e-6), vv)
        assert not ok and np.isnan(e)
        assert rows(2.0, e, 1.0, 1.0, ok) == (2.0, 2.0)
        assert np.isnan(tangent(1.0, 0.5, e, 1.0))
