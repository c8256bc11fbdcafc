"""The Lyapunov lane blocks of the pointer kernel path: the inlined lane blocks' text with the
model's parts called through their addresses, compiled once for every model.

The pointer path's Lyapunov module (:func:`._pointer_kernels.hooked_text`) is the text of
:mod:`._lyapunov_template` bound to the pointer model (:mod:`._pointer_model`) with the text
below the ``POINTER-HOOKS`` line appended: its definitions replace the template's of the same
names, so that the variational lane blocks (``lyapunov_lanes``, ``lyapunov_block_lanes`` with
``variational``: their workers, block start, time loop and books) are the template's own text,
and only these differ:

* ``VARIATIONAL``: the model has the tangent forms of its rhs (in its callbacks);
* ``_var_fused_steps``: a grid step of every lane of the block, state and tangent vector, is the
  model's own (its inlined ``"lyapunov"`` module's ``_var_fused_steps`` in its lane form,
  compiled with the model as a C callback, :func:`._pointer_kernels.lyapunov_part_text`),
  called through its address once per block step;
* ``_var_flagged``: the flagged lanes of a step are the model's own (its ``_var_flagged``: the
  split step with the tangent carried through the sub-steps, the difference rows where that is
  ill-posed), called through its address;
* ``_n_switching``: the model's number of switching functions (the size of the graze flags'
  rows), read from the coefficients.

The callbacks' addresses and the count are the last :data:`~._pointer_calls.N_LYAPUNOV` entries
of every coefficient row (:class:`._pointer_kernels.PointerLyapunov`). The operations are those
of the inlined lane blocks, in the same order: the exponents are bitwise the same. Above the
line, the imports make this file a valid module on its own; those below are of modules compiled
once for every model.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn.solvers._step_core import _JIT

# isort: split
# POINTER-HOOKS: the text below is appended to the template's (see the module docstring)
from geardyn.solvers._pointer_calls import N_LYAPUNOV, call_flat

#: The model's tangent forms are in its callbacks (the template's test is of its own names).
VARIATIONAL = True


@nb.njit(inline="always", **_JIT)
def _n_switching(Z0, PT):
    """The model's number of switching functions (entry N_LYAPUNOV from the end of the
    coefficients, lane 0's column of PT)."""
    return np.int64(PT[PT.shape[0] - N_LYAPUNOV, 0])


@nb.njit(inline="always", **_JIT)
def _var_fused_steps(form, i, nl, locate, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L, PH, ACT,
                     FLAG, GR, Y1F):
    """The model's variational step of every lane of the block (its ``_var_fused_steps`` in
    its lane form, the arguments flattened: :data:`._pointer_calls.VAR_STEP_ARGS`), called
    through its address (entry N_LYAPUNOV - 1 from the end of lane 0's coefficients: every
    lane of a block is of the one model); the number of flagged lanes."""
    addr = np.int64(PT[PT.shape[0] - N_LYAPUNOV + 1, 0])
    return call_flat(addr, (i, nl, locate, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L) + PH
                     + (ACT, FLAG, GR, Y1F))


@nb.njit(inline="always", **_JIT)
def _var_flagged(i, nl, first, n_ev, P, Z0, Z1, S, IS, T0L, HL, OMEGA, NPL, IDX, S_TAB, C_TAB,
                 FLAG, UNRR, FDL, GR, Y1F, fd):
    """The model's flagged lanes of step i (its ``_var_flagged``, the arguments flattened:
    :data:`._pointer_calls.VAR_FLAGGED_ARGS`), called through its address (the last entry of
    the coefficient row of the block's first lane)."""
    call_flat(np.int64(P[first, P.shape[1] - 1]), (
        i, nl, first, n_ev, P, Z0, Z1, S, IS, T0L, HL, OMEGA, NPL, IDX, S_TAB, C_TAB, FLAG,
        UNRR, FDL, GR, Y1F) + fd)
