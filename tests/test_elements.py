"""geardyn.models.elements: the physics every model's kernels share, against direct formulas."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.models.elements import dead_zone, harmonic_factor, harmonic_factor_lane


@pytest.mark.parametrize("x", [-2.5, -1.0, -0.3, 0.0, 0.7, 1.0, 3.25])
def test_dead_zone_is_the_branching_form(x):
    b = 1.0
    assert dead_zone(x, b) == (x - b if x > b else x + b if x < -b else 0.0)


@pytest.mark.parametrize("nh", [0, 1, 4])
def test_harmonic_factor_is_the_fourier_sum_clipped_at_zero(nh):
    rng = np.random.default_rng(nh)
    f = 3
    p = rng.normal(size=f + 2 * nh + 2)
    for theta in (0.0, 0.4, 2.9, -1.3):
        h = np.arange(1, nh + 1)
        want = 1.0 + np.sum(p[f:f + 2 * nh:2] * np.cos(h * theta)
                            + p[f + 1:f + 2 * nh:2] * np.sin(h * theta))
        got = harmonic_factor(p, f, nh, np.sin(theta), np.cos(theta))
        assert got == pytest.approx(max(want, 0.0), rel=1e-13, abs=1e-13)
        PT = np.column_stack([rng.normal(size=p.size), p])  # lane 1 holds p
        assert harmonic_factor_lane(PT, 1, f, nh, np.sin(theta), np.cos(theta)) == got


def test_harmonic_factor_clips_a_negative_sum_and_keeps_a_positive_one():
    p = np.array([-1.5, 0.0])  # 1 - 1.5 cos(theta)
    assert harmonic_factor(p, 0, 1, 0.0, 1.0) == 0.0
    assert harmonic_factor(p, 0, 1, 0.0, -1.0) == 2.5
    assert harmonic_factor_lane(p[:, None], 0, 0, 1, 0.0, 1.0) == 0.0
