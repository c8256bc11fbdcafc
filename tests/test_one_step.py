"""One stepping machinery: the RK4 combination and its weight h / 6 written once
(:mod:`geardyn.solvers._step_shared`) and used by every kernel, the parameter difference step
declared once, the one-lane-at-a-time Lyapunov reference kept with the tests, and the sweep's
slot move touching only the arrays the fused loop reads (its arguments are ``noalias``)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from geardyn.core import settings
from geardyn.solvers import _step_shared, _sweep_books

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


def _block(ns=3, nw=16, n_par=4, depth=2):
    """A block of the sweep (``blk``, ``slots``) with distinct values everywhere, its views PH
    and HW separate arrays (not rows of PH6, HW3), PH6 and HW3 NaN."""
    rng = np.random.default_rng(7)

    def r(*shape):
        return rng.standard_normal(shape)

    Y, Y1, K1, K2, K3, K4, TMP = (r(ns, nw) for _ in range(7))
    PH6, HW3 = np.full((4, nw), np.nan), np.full((3, ns, nw), np.nan)
    PH = tuple(r(nw) for _ in range(4))
    HW = tuple(r(ns * nw) for _ in range(3))
    FL = tuple(a.reshape(ns * nw) for a in (Y, Y1, K1, K2, K3, K4, TMP))
    blk = (r(nw, depth, ns), r(nw, 3 * depth, depth), Y, Y1, K1, K2, K3, K4, TMP, r(n_par, nw),
           r(8, nw), PH6, PH, r(nw), r(2, nw), r(2, nw), r(2, nw), r(2, nw), r(2, nw), r(nw),
           r(2, nw), r(2, nw), r(1, nw), r(1, nw), r(1, nw), r(1, nw), HW3, FL, HW)
    flags = [np.ones(nw, np.bool_) for _ in range(4)]
    ints = [rng.integers(0, 100, nw) for _ in range(11)]
    slots = (*flags, *ints[:5], r(nw), r(nw), *ints[5:])
    return blk, slots


def test_slot_move_touches_only_the_views_the_fused_loop_reads():
    # _block_run_form* take blk's arrays as noalias arguments: of PH6 and its rows PH (HW3 and
    # its flat rows HW) only one may be touched there. The fused loop reads PH and HW, so the
    # compaction (_compact -> _move_slot) moves a slot's phases and step weights through them.
    blk, slots = _block()
    PH, HW = blk[12], blk[28]
    before = [a.copy() for a in (*PH, *HW)]
    src, dst = 13, 2
    _sweep_books._move_slot.py_func(src, dst, blk, slots)
    assert np.all(np.isnan(blk[11])) and np.all(np.isnan(blk[26]))  # PH6, HW3 untouched
    ns, nw = blk[2].shape
    for old, new in zip(before[:4], PH, strict=True):
        assert new[dst] == old[src]
        np.testing.assert_array_equal(np.delete(new, dst), np.delete(old, dst))
    for old, new in zip(before[4:], HW, strict=True):
        for q in range(ns):
            assert new[q * nw + dst] == old[q * nw + src]
    assert not slots[2][src] and not slots[3][src]  # src freed (ACT, END)
