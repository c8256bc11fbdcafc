"""The Lyapunov lane blocks of the pointer kernel path: the inlined lane blocks' text with the
model's parts called through their addresses, compiled once for every model.

The pointer path's Lyapunov module (:func:`._pointer_kernels.hooked_text`) is the text of
:mod:`._lyapunov_template` bound to the pointer model (:mod:`._pointer_model`: its array forms
and the tangent form of its rhs, ``rhs_tangent``, call the model's C callbacks) with the text
below the ``POINTER-HOOKS`` line appended: its definitions replace the template's of the same
names, so that the variational lane blocks (``lyapunov_lanes``, ``lyapunov_block_lanes`` with
``variational``: their workers, block start, time loop, books and the flagged lanes: the split
step with the tangent carried through the sub-steps, the difference rows where that is
ill-posed) are the template's own text, and only these differ:

* ``_var_steps``: the grid steps of every lane of the block, state and tangent vector, up to
  the next flagged step or bookkeeping, are the model's own (its inlined ``"lyapunov"``
  module's ``_var_steps`` in its lane form, compiled with the model as a C callback,
  :func:`._pointer_kernels.lyapunov_part_text`), called through its address once per such
  run of steps (up to the renormalisation interval's steps a call; one step a call where a
  block's tangent vectors take several passes);
* ``_n_switching``: the model's number of switching functions (the size of the graze flags'
  rows), read from the coefficients.

A flagged lane's split step evaluates the model through its array forms and its tangent form,
one call each (as the trajectory's split step does on the pointer path). The count and the
callbacks' addresses are the last :data:`~._pointer_calls.N_LYAPUNOV` +
:data:`~._pointer_calls.N_ADDRESSES` entries of every coefficient row
(:class:`._pointer_kernels.PointerLyapunov`). The operations are those of the inlined lane
blocks, in the same order: the exponents are bitwise the same. Above the line, the imports make
this file a valid module on its own; those below are of modules compiled once for every model.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn.solvers._step_core import _JIT

# isort: split
# POINTER-HOOKS: the text below is appended to the template's (see the module docstring)
from geardyn.solvers._pointer_calls import N_ADDRESSES, N_LYAPUNOV, call_flat

#: Where the pointer path's Lyapunov entries start, counted from the end of a coefficient row.
_LYAPUNOV_AT = N_ADDRESSES + N_LYAPUNOV


@nb.njit(inline="always", **_JIT)
def _n_switching(Z0, PT):
    """The model's number of switching functions (the first of the Lyapunov entries of the
    coefficients, lane 0's column of PT)."""
    return np.int64(PT[PT.shape[0] - _LYAPUNOV_AT, 0])


@nb.njit(inline="always", **_JIT)
def _var_steps(form, i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L,
               PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL):
    """The model's variational steps of every lane of the block (its ``_var_steps`` in its
    lane form, the arguments flattened: :data:`._pointer_calls.VAR_STEP_ARGS`: the steps up to
    the next flagged one or bookkeeping), called through its address (the second Lyapunov
    entry of lane 0's coefficients: every lane of a block is of the one model); the last step
    done."""
    addr = np.int64(PT[PT.shape[0] - _LYAPUNOV_AT + 1, 0])
    return call_flat(addr, (i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL,
                            H6L) + PH + (IDX, ENDL, ACT, FLAG, GR, Y1F, NPL))

