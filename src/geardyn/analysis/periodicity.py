"""Period classification of stroboscopic (Poincare) samples.

A lane is period-k when its samples repeat after k forcing periods: for the smallest
k <= max_period, max_i |x[i + k] - x[i]| <= tol * max(1, max_i |x[i]|) over the recorded samples
(every state). Motion that repeats for no such k is labelled 0 (no period <= max_period found:
chaotic, quasi-periodic, a longer period or not settled; :mod:`geardyn.analysis.motion` tells
them apart with the Lyapunov exponent); a diverged lane (NaN samples) is -1.

Resolution: a period-2k orbit whose points split by s (the largest difference, over states and
over the orbit, between x[i + k] and x[i]) is read as period-2k exactly when
s > tol * max(1, max |x|), and as period-k when s <= that. Past a period doubling s grows as
sqrt(|Omega - Omega_flip|), so a band of Omega next to the flip, where s is still below
tol * max(1, |x|), reads period-k: for the gear pair of tests/test_convergence.py
(s = 3.0 sqrt(Omega - 0.90081), |x| < 1) a band of 1.1e-11 in Omega at the default tol. The
samples themselves must be settled to well below that splitting: the transient by convergence
(``converge``) stops only when the estimated distance to the orbit is below its tolerance
(docs/numerics.md), which must be smaller than tol.

The tolerance must exceed what is left of the transient (at xi = 0.05 the slowest mode of the
CATT device decays as exp(-0.015 tau)) and the integration noise; it must stay below the distance
between the points of a genuine period-k orbit. The default 1e-5 (relative) is tested on
synthetic orbits, on the gear pair and just past a period doubling (tests/test_convergence.py).
"""

from __future__ import annotations

import numpy as np

from geardyn.core.moved import moved
from geardyn.core.settings import DEFAULT_MAX_PERIOD as _MAX_PERIOD
from geardyn.core.settings import DEFAULT_TOL as _TOL

__all__ = ["APERIODIC", "UNBOUNDED", "classify_period", "distinct_points"]

__getattr__ = moved(__name__, {"DEFAULT_MAX_PERIOD": "geardyn.core.settings",
                               "DEFAULT_TOL": "geardyn.core.settings",
                               "MAX_COMMON_PERIODS": "geardyn.core.section",
                               "common_section": "geardyn.core.section"})

UNBOUNDED = -1
APERIODIC = 0
#: Lanes classified together (bounds the temporaries of a large map: a batch of 64 samples of
#: 4 states is 8 MB).
_BATCH = 4096


def classify_period(samples: np.ndarray, max_period: int = _MAX_PERIOD,
                    tol: float = _TOL) -> np.ndarray:
    """Period of each lane of ``samples`` (lanes, samples, states): k >= 1, 0 or -1 (see module)."""
    x = np.asarray(samples, dtype=float)
    if x.ndim == 2:
        return classify_period(x[None], max_period, tol)[0]
    lanes, n, _ = x.shape
    if n < 2:
        raise ValueError("period classification needs at least 2 samples per lane")
    k_max = min(max_period, n - 1)
    out = np.full(lanes, APERIODIC, dtype=np.int64)
    finite = np.all(np.isfinite(x), axis=(1, 2))
    out[~finite] = UNBOUNDED
    idx = np.flatnonzero(finite)
    for a in range(0, idx.size, _BATCH):  # the comparisons of one lane, for a batch of lanes
        rows = idx[a:a + _BATCH]
        xb = x[rows]
        scale = tol * np.maximum(1.0, np.max(np.abs(xb), axis=(1, 2)))
        period = np.full(rows.size, APERIODIC, dtype=np.int64)
        for k in range(1, k_max + 1):
            repeats = np.max(np.abs(xb[:, k:] - xb[:, :-k]), axis=(1, 2)) <= scale
            period[(period == APERIODIC) & repeats] = k  # the smallest k that repeats
        out[rows] = period
    return out


def distinct_points(samples: np.ndarray, tol: float = _TOL) -> int:
    """Number of distinct points among the samples of one lane (samples, states)."""
    x = np.asarray(samples, dtype=float)
    scale = tol * max(1.0, float(np.max(np.abs(x))))
    kept: list[np.ndarray] = []
    for row in x:
        if not any(np.max(np.abs(row - k)) <= scale for k in kept):
            kept.append(row)
    return len(kept)
