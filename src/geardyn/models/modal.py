"""What the linear models' modal analyses share: repeated natural frequencies grouped."""

from __future__ import annotations

import numpy as np

__all__ = ["MULTIPLICITY_RTOL", "frequency_groups"]

#: Relative tolerance within which two natural frequencies count as one repeated frequency.
MULTIPLICITY_RTOL = 1e-6


def frequency_groups(f: np.ndarray) -> list[list[int]]:
    """Indices of the ascending frequencies ``f`` grouped into repeated values (within
    :data:`MULTIPLICITY_RTOL`, relative; near 0 relative to 1e-3 of the largest)."""
    scale = max(float(np.max(f)), 1e-300) if f.size else 1.0
    groups: list[list[int]] = []
    for i, v in enumerate(f):
        if groups and abs(v - f[groups[-1][0]]) <= MULTIPLICITY_RTOL * max(v, 1e-3 * scale):
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups
