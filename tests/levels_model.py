"""A one-form test model whose steps cross more levels than the split limit: the steps that
reach the limit (``unresolved``) in every path and result (tests/test_unresolved_count.py,
tests/test_grazing.py), one model so that its kernels compile once.

Its coordinate x = sin(Omega t) + B (1 - cos(Omega t)) (from x(0) = 0) crosses the 18 close
levels :data:`LEVELS` (switching functions x - L_j, L_j in [0.05, 0.07125]) within one grid
step of :data:`RUN` twice per forcing period: more distinct crossings than the split limit
(MAX_SPLITS = 16), so every such step falls back unsplit and counts once; from the analytic
motion (x' does not depend on x) the count is 2 per period run. B is a quiet coefficient (lanes
with B = 0 take FORM_QUIET); with B <= -10 x stays below 0.05 (its maximum sqrt(1 + B^2) - |B|
< 1 / (2 |B|)): no level is crossed.
"""

from __future__ import annotations

import dataclasses

import numba as nb

import geardyn
from geardyn.core.one_form import loud

#: The levels: closer than one grid step of x at the passages through them (x' = Omega there).
LEVELS = tuple(0.05 + 0.00125 * j for j in range(18))
L = LEVELS
#: 32 steps per period: each passage through the levels (Omega t within 0.08 of 0 or pi, B <=
#: 0.01) lies inside one grid step.
RUN = geardyn.RunSettings(transient=20.0, samples=6, steps_per_period=32, locate_edges=True)
#: A B whose lane crosses no level (see the module docstring).
B_BELOW = -20.0


@nb.njit(cache=True)
def levels_rhs(t, y, p, s, c):
    """x' = Omega (cos + B sin): x = sin(Omega t) + B (1 - cos(Omega t)) from x(0) = 0."""
    v = c
    if loud(p):
        v += p.B * s
    return (p.Omega * v,)


@nb.njit(cache=True)
def levels_events(t, y, p, s, c):
    x = y[0]
    return (x - L[0], x - L[1], x - L[2], x - L[3], x - L[4], x - L[5], x - L[6], x - L[7],
            x - L[8], x - L[9], x - L[10], x - L[11], x - L[12], x - L[13], x - L[14],
            x - L[15], x - L[16], x - L[17])


def levels_model() -> geardyn.UserModel:
    """The model above, B a quiet coefficient (lanes with B = 0 take FORM_QUIET; quiet
    coefficients take the lane forms of the inlined path, ``kernel_path="lane-form"``)."""
    model = geardyn.UserModel.from_one_form(
        levels_rhs, params={"Omega": 1.0, "B": 0.0}, states=("x",), events=levels_events,
        event_names=tuple(f"x-L{j}" for j in range(len(LEVELS))), name="levels",
        kernel_path="lane-form")
    form = dataclasses.replace(model.kernel.one_form, quiet=("B",))
    model.kernel = dataclasses.replace(model.kernel, one_form=form)
    return model
