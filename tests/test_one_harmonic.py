"""One dead zone and one stiffness series: the harmonics' angle-addition recurrence, the series'
clip at 0 and the backlash dead zone are written once, in :mod:`geardyn.models.elements`, and
every model's kernels use them; the series' three access forms (1-D vector, lane column,
tuple) against numpy's sum of a_j cos(j theta) + b_j sin(j theta)."""

from __future__ import annotations

import re
from pathlib import Path

import numba as nb
import numpy as np
import pytest

from geardyn.models.elements import harmonic_factor, harmonic_factor_lane, harmonic_factors

SRC = Path(__file__).resolve().parent.parent / "src" / "geardyn"
_OPERAND = r"[\w{}]+(?:\[[^\]=]*\])?"
#: The first half of a rotation A * C - B * S (source without white space but between two
#: words, :func:`_flat`); its second half
#: B * C + A * S must follow within :data:`_WINDOW` characters.
_ROTATION = re.compile(rf"({_OPERAND})\*({_OPERAND})-({_OPERAND})\*({_OPERAND})")
#: A series' clip at 0: v if v > 0.0 else 0.0 (assigned, returned or an argument).
_CLIP = re.compile(rf"(?:[=(,\"]|return )({_OPERAND}) if \1>0\.0 else 0\.0")
#: The dead zone, branch-free (x - min(max(x, -b), b)) or branching (x - b if x > b else ..).
_DEAD_ZONE = (re.compile(rf"(\w+)-min\(max\(\1,-({_OPERAND})\),\2\)"),
              re.compile(rf"(\w+)-({_OPERAND}) if \1>\2 else\(?\1\+\2 if \1<-\2"))
_WINDOW = 200


def _flat(text: str) -> str:
    """``text`` without white space, but one blank between two words (``return x``)."""
    text = re.sub(r"(?<=[\w{}])\s+(?=[\w{}])", "\x01", text)
    return re.sub(r"\s+", "", text).replace("\x01", " ")


def _rotations(flat: str) -> list[str]:
    out = []
    for m in _ROTATION.finditer(flat):
        a, c, b, s = m.groups()
        if f"{b}*{c}+{a}*{s}" in flat[m.end():m.end() + _WINDOW]:
            out.append(m.group(0))
    return out


def _clips(flat: str) -> list[str]:
    return [m.group(0) for m in _CLIP.finditer(flat)]


def _dead_zones(flat: str) -> list[str]:
    return [m.group(0) for pattern in _DEAD_ZONE for m in pattern.finditer(flat)]


def _hits(find) -> list[str]:  # noqa: ANN001 (one of the finders above)
    return [f"{path.relative_to(SRC)}: {hit}" for path in sorted(SRC.rglob("*.py"))
            for hit in find(_flat(path.read_text()))]


def test_the_recurrence_clip_and_dead_zone_are_written_once():
    assert _hits(_rotations) == ["models/elements.py: ch*c-sh*s"]
    assert _hits(_clips) == ["models/elements.py: return v if v>0.0 else 0.0"]
    assert _hits(_dead_zones) == ["models/elements.py: x-min(max(x,-b),b)"]


@pytest.mark.parametrize("line", [
    "ch, sh = ch * c - sh * s, sh * c + ch * s",
    "SC[0, k] = ch * C[k] - sh * S[k]\n            SC[1, k] = sh * C[k] + ch * S[k]",
    "PT[x, k] = ch * PT[rc, k] - sh * PT[rs, k]\n PT[x + 1, k] = sh * PT[rc, k] + ch * PT[rs, k]",
    "ca, sa = ca * c4 - sa * s4, sa * c4 + ca * s4",
    "rc, rs = rc * bc - rs * bs, rs * bc + rc * bs",
    'lines.append("    ch, sh = ch * c - sh * s, sh * c + ch * s")',
])
def test_the_scan_finds_the_former_spellings_of_the_recurrence(line):
    assert _rotations(_flat(line))


@pytest.mark.parametrize("line", [
    "v = 1.0 + acc\n    return v if v > 0.0 else 0.0",
    "v = 1.0 + PT[rb + m, k]\n            PT[rb + m, k] = v if v > 0.0 else 0.0",
    'lines += [f"    v{j} = 1.0 + a{j}" for j in range(m)]\n'
    '        lines.append("    return (" + "".join(f"v{j} if v{j} > 0.0 else 0.0, "',
])
def test_the_scan_finds_the_former_spellings_of_the_clip(line):
    assert _clips(_flat(line))


@pytest.mark.parametrize("line", [
    "g = x - b if x > b else (x + b if x < -b else 0.0)",
    "out[m] = kf * (d - min(max(d, -b[pk.M_B]), b[pk.M_B]))",
])
def test_the_scan_finds_the_former_spellings_of_the_dead_zone(line):
    assert _dead_zones(_flat(line))


def test_the_scan_passes_other_clamps_and_rotations_by():
    for line in ("sig = min(max(sig, lo_), hi_)", "s = d / scale if scale > 0.0 else 0.0",
                 "return s - (alpha * s - beta * c), c - (alpha * c + beta * s)",
                 "v -= om * (p[o + M_ES] * c - p[o + M_EC] * s)"):
        assert not (_rotations(_flat(line)) or _clips(_flat(line))
                    or _dead_zones(_flat(line))), line


@nb.njit
def _tuple_form(h, s, c):
    return harmonic_factors(h, 1, s, c)[0]


def _numpy_series(a, b, theta):
    """1 + sum_j a_j cos(j theta) + b_j sin(j theta), clipped at 0, by numpy's cos and sin."""
    j = np.arange(1, a.size + 1)
    return np.maximum(1.0 + (np.cos(np.outer(theta, j)) @ a + np.sin(np.outer(theta, j)) @ b),
                      0.0)


@pytest.mark.parametrize("nh", range(7))
def test_the_series_forms_are_the_fourier_sum_clipped_at_zero(nh):
    rng = np.random.default_rng(30 + nh)
    a = 0.1 * rng.standard_normal(nh)
    b = 0.1 * rng.standard_normal(nh)
    if nh:
        a[0] = 1.5  # 1 + 1.5 cos(theta) + small terms: below 0 near theta = pi, clipped
    theta = np.linspace(-np.pi, np.pi, 61)
    want = _numpy_series(a, b, theta)
    if nh:
        assert np.any(want == 0.0) and np.any(want > 1.0)
    f = 2
    p = np.concatenate([rng.standard_normal(f), np.column_stack([a, b]).ravel(), [7.0]])
    PT = np.column_stack([rng.standard_normal(p.size), p])  # lane 1 holds p
    h = tuple(p[f:f + 2 * nh])
    for th, w in zip(theta, want, strict=True):
        s, c = np.sin(th), np.cos(th)
        got = harmonic_factor(p, f, nh, s, c)
        assert got == pytest.approx(w, rel=1e-13, abs=1e-13)
        assert harmonic_factor_lane(PT, 1, f, nh, s, c) == got  # bitwise
        assert _tuple_form(h, s, c) == got
