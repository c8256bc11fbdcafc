"""The sweep of the pointer kernel path: the inlined sweep's text with the model's parts called
through their addresses, compiled once for every model.

The pointer path's sweep module (:func:`._pointer_kernels.sweep_text`) is the text of
:mod:`._kernel_template` bound to the pointer model (:mod:`._pointer_model`, whose functions call
the callbacks a coefficient row names) with the text below the ``POINTER-HOOKS`` line appended:
its definitions replace the template's of the same names, so that the block loop
(``_fused_run``), the bookkeeping of the marked slots (``_slots_out``, ``_slot_out``,
``_finish_flagged``), the lane loading and the workers are the template's own text, and only
these differ:

* ``_fused_steps``: a grid step of every slot is the model's own fused step (its inlined
  ``"rk4"`` module's ``_fused_steps``, compiled with the model as a C callback, see
  :mod:`._pointer_kernels`), called through its address once per block step;
* ``_split_step``: a flagged step's split is the model's own (its core module's), called
  through its address;
* ``_start_sides``, ``_slot_observe``: the events at a lane's start and the observables at a
  grid point out of line through the model's array forms (the pointer model's);
* ``_slots_out``: the template's, inlined in the block loop instead of called. A call passes
  its ~80 arrays by value (~620 words pushed); after the callback, those pushes took ~1.2 us
  a call (~0.14 us in the inlined sweep, the same count; the cause is not measured: perf
  samples only, no hardware counters), ~3 ns per lane-step of bench/pointer_path.py's sweep,
  where ~15% of the block steps call it. The block loop's hot part is the callback here, so
  the inlined bookkeeping crowds nothing; inlined in the template's own block loop, where the
  fused step is inlined too, it made the paper workload 2.9x slower (bench/ab_paper.py, one run;
  GearPair's sweep 0.84-0.88x its time, the one form inlined 1.06-1.09x), so the template
  calls it;
* ``FUSED``: the sweep takes the fused block loop.

The generated module is the same text for every model; its operations are those of the inlined
sweep, in the same order: the results are bitwise the same. Above the line, the imports make
this file a valid module on its own (bound to the template's test oscillator); those below
are of modules compiled once for every model.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn.solvers._kernel_template import _slots_out
from geardyn.solvers._step_core import _JIT
from geardyn.solvers._template_model import events, observe

# isort: split
# POINTER-HOOKS: the text below is appended to the template's (see the module docstring)
from geardyn.solvers._pointer_calls import N_ADDRESSES, call_flat
from geardyn.solvers._step_shared import _pick, stat_max, stat_min, stat_square

#: The sweep takes the fused block loop (:func:`_fused_steps` below: the model's).
FUSED = True


@nb.njit(inline="always", **_JIT)
def _fused_steps(form, nl, locate, bound, Y, Y1, PT, SE, CE, H6, FLAG, G, ST, slots, ROT, PH):
    """The model's fused step of every slot (its ``_fused_steps``, the arguments flattened:
    :data:`._pointer_calls.STEP_ARGS`), called through its address (row N_ADDRESSES - 2 from
    the end of the coefficients; slot 0's: every lane of a sweep is of the one model, and
    slot 0 holds one from the block's start). Returns (marked, marked): the model's returns
    the slots marked (flagged or with bookkeeping due) only."""
    addr = np.int64(PT[PT.shape[0] - N_ADDRESSES + 3, 0])
    n_out = call_flat(addr, (nl, locate, bound, Y, Y1, PT, SE, CE, H6, FLAG) + G + ST + slots
                      + ROT + PH)
    return n_out, n_out


#: The bookkeeping of the marked slots (the template's ``_slots_out``) inlined in the block loop
#: (see the module docstring).
_slots_out = nb.njit(inline="always", **_JIT)(_slots_out.py_func)


@nb.njit(inline="always", **_JIT)
def _split_step(i, t0, y, y1, p, h, omega, n_per, sa, ca, se, ce, side, g1, ncross, work, ybuf,
                gbuf):
    """The model's split step (its core module's ``_split_step``), called through its address
    (the last of the coefficient row p)."""
    return call_flat(np.int64(p[p.size - N_ADDRESSES + 4]), (
        i, t0, y, y1, p, h, omega, n_per, sa, ca, se, ce, side, g1, ncross, work, ybuf, gbuf))


@nb.njit(inline="always", **_JIT)
def _start_sides(k, lane, TT, Y, PT, GS, SIDE, SE, CE, lanes, cfg, scratch):
    """The template's ``_start_sides`` through the model's array form of ``events``."""
    n_ev = cfg[5]
    if n_ev > 0:
        ybuf, gb = scratch[8], scratch[5]
        for q in range(Y.shape[0]):
            ybuf[q] = Y[q, k]
        events(TT[k], ybuf, gb, lanes[0][lane], SE[k], CE[k])
        for j in range(n_ev):
            GS[j, k] = gb[j]
            SIDE[j, k] = _pick(gb[j] > 0.0, 1.0, -1.0)


@nb.njit(inline="always", **_JIT)
def _slot_observe(k, t, s, c, Y, PT, ST, lanes, cfg, slots, scratch):
    """The template's ``_slot_observe`` through the model's array form of ``observe``."""
    n_obs = cfg[6]
    if n_obs > 0:
        GMIN, GMAX, OMAX, OMIN, OSQ = ST
        ybuf, ob = scratch[8], scratch[6]
        for q in range(Y.shape[0]):
            ybuf[q] = Y[q, k]
        observe(t, ybuf, ob, lanes[0][slots[4][k]], s, c)
        for j in range(n_obs):
            v = ob[j]
            OMAX[j, k] = stat_max(OMAX[j, k], v, True)
            OMIN[j, k] = stat_min(OMIN[j, k], v, True)
            OSQ[j, k] = stat_square(OSQ[j, k], v, True)
