"""The stroboscopic section of a lane: how many forcing periods apart its samples are."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

#: Largest denominator q of a ratio Lambda / Omega = p / q treated as commensurate.
MAX_COMMON_PERIODS = 32


def common_section(omega: np.ndarray, others: np.ndarray, max_periods: int = MAX_COMMON_PERIODS,
                   rtol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Sampling interval of a stroboscopic section, in forcing periods, per lane.

    ``omega`` (lanes,) is the forcing frequency and ``others`` (lanes, m) further excitation
    frequencies (NaN: absent). When every ratio other / omega is p / q with q <= max_periods
    (to ``rtol``), the motion is forced with the common period q T, and sampling every q periods
    gives a true Poincare section: returns (q, True). Otherwise (1, False): the once-per-period
    samples of a quasi-periodically forced system, where a period test does not apply.
    """
    omega = np.asarray(omega, dtype=float)
    others = np.asarray(others, dtype=float).reshape(omega.size, -1)
    every = np.ones(omega.size, np.int64)
    ok = np.ones(omega.size, bool)
    for lane in range(omega.size):
        q_all = 1
        for f in others[lane]:
            if not np.isfinite(f):
                continue
            r = abs(f) / omega[lane]
            q = Fraction(r).limit_denominator(max_periods).denominator
            p = round(r * q)
            if p == 0 or abs(r - p / q) > rtol * r:
                ok[lane] = False
                break
            q_all = q_all * q // math.gcd(q_all, q)
        if ok[lane] and q_all <= max_periods:
            every[lane] = q_all
        else:
            ok[lane] = False
    return every, ok
