"""The model of the pointer kernel path: one set of functions for every model on that path.

These functions are a model in the kernel interface (:class:`~geardyn.core.kernel_source.
KernelSource`: the array forms ``rhs``, ``events``, ``observe``) that evaluate whatever
model's C callbacks the coefficient row names: its last :data:`~._pointer_calls.N_ADDRESSES`
entries are their addresses (:mod:`._pointer_kernels`). The kernel templates bound to them
(:func:`geardyn.solvers.kernels.kernels_for`: the trajectory, the split step) are thus the
same text for every model: compiled and cached once, for all.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn._jit_target import WidthCompiler
from geardyn.solvers._pointer_calls import N_ADDRESSES, call_array

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
