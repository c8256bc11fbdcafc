"""Physics shared by the models' compiled functions (numba, inlined where they are called)."""

from __future__ import annotations

import numba as nb

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}


@nb.njit(inline="always", **_JIT)
def dead_zone(x, b):
    """The backlash dead zone g(x, b): x - b above b, x + b below -b, 0 between (branch-free;
    the same values as the branching form, 0 included)."""
    return x - min(max(x, -b), b)
