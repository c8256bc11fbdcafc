"""Stand-ins for models without switching functions or observables."""

from __future__ import annotations

import numba as nb

from geardyn._jit_target import WidthCompiler


@nb.njit(cache=True, pipeline_class=WidthCompiler)
def no_events(t, y, g, p, s, c):
    pass


@nb.njit(cache=True, pipeline_class=WidthCompiler)
def no_observables(t, y, out, p, s, c):
    pass


@nb.njit(cache=True, pipeline_class=WidthCompiler)
def no_observables_plain(t, y, out, p):
    pass
