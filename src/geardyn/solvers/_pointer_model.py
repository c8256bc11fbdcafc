"""The model of the pointer kernel path: one set of functions for every model on that path.

These functions are a model in the kernel interface (:class:`~geardyn.core.kernel_source.
KernelSource`: the array forms ``rhs``, ``events``, ``observe``) that evaluate whatever
model's C callbacks the coefficient row names: its last :data:`~._pointer_calls.N_ADDRESSES`
entries are their addresses (:mod:`._pointer_kernels`). The kernel templates bound to them
(:func:`geardyn.solvers.kernels.kernels_for`: the trajectory, the split step) are thus the
same text for every model: compiled and cached once, for all. Its tangent forms
(``rhs_tangent``; ``rhs_lane_tangent``, which nothing calls) are those of the pointer path's
Lyapunov lane blocks (:mod:`._pointer_lyapunov`), whose coefficient rows carry the address of the
model's tangent callback too.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn._jit_target import WidthCompiler
from geardyn.solvers._pointer_calls import N_ADDRESSES, N_LYAPUNOV, call_array, call_flat

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}


@nb.njit(inline="always", **_JIT)
def _address(p, j):
    """Address j (0: rhs, 1: events, 2: observe) of the coefficient row p."""
    return np.int64(p[p.size - N_ADDRESSES + j])


@nb.njit(**_JIT)
def rhs(t, y, dy, p, s, c):
    call_array(_address(p, 0), t, y, dy, p, s, c)


@nb.njit(**_JIT)
def events(t, y, g, p, s, c):
    call_array(_address(p, 1), t, y, g, p, s, c)


@nb.njit(**_JIT)
def observe(t, y, out, p, s, c):
    call_array(_address(p, 2), t, y, out, p, s, c)


@nb.njit(forceinline=True, _nrt=False, **_JIT)  # as the one form's (its callers allocate nothing)
def rhs_tangent(t, y, v, dy, dv, p, s, c):
    """f(t, y) into dy and J(t, y) v into dv (:func:`geardyn.core.one_form.tangent_adapters`)
    through the model's callback (entry N_LYAPUNOV - 2 before the addresses at the end of the
    coefficient row p of the Lyapunov lane blocks)."""
    call_flat(np.int64(p[p.size - N_ADDRESSES - N_LYAPUNOV + 2]), (t, y, v, dy, dv, p, s, c))


@nb.njit(**_JIT)
def rhs_lane_tangent(t, y, v, PT, k, s, c, form):
    """The lane form of the tangent: the pointer path's lane blocks call the model's
    variational step of a block of lanes instead (:mod:`._pointer_lyapunov`)."""
    raise NotImplementedError("the pointer path steps a block of lanes in the model's callback")
