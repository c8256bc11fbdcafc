"""Stand-ins for models without switching functions or observables."""

from __future__ import annotations

import numba as nb


@nb.njit(cache=True)
def no_events(t, y, g, p, s, c):
    pass


@nb.njit(cache=True)
def no_observables(t, y, out, p, s, c):
    pass


@nb.njit(cache=True)
def no_observables_plain(t, y, out, p):
    pass
