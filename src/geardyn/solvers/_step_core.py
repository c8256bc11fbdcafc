"""A model's step machinery: the shared machinery of :mod:`._split_core` bound to the model's
functions, and the lane-tuple helpers of the fused loops, sized to the model.

This is template text: :func:`geardyn.solvers.kernels.kernels_for` writes it, with the model's
functions at its ``MODEL-IMPORT`` line and their adapters at ``MODEL-ADAPTERS``, as the model's
generated core module, which the model's other kernel modules import (see the templates'
``CORE-IMPORT`` line). As it stands it is a valid module bound to the test oscillator of
:mod:`geardyn.solvers._template_model`.

The model's array-form ``rhs`` and ``events`` are compiled here as C callbacks; the split step,
the root finders and the rows of a lane (:mod:`._split_core`, compiled once for every model) call
them through their addresses (:mod:`.model_calls`). The wrappers below give those functions their
model-bound signatures. What else a model compiles (its sweep, Lyapunov and monodromy kernels,
with its functions inlined) is in the templates.
"""

from __future__ import annotations

import numba as nb
from numba import carray

from geardyn.core.kernel_source import FORM_GENERAL
from geardyn.solvers import _split_core as _shared
from geardyn.solvers._split_core import (  # noqa: F401 - the templates import them from here
    _INLINE,
    BLOCK,
    BRACKET_TOL,
    CONFIRM_TOL,
    GBUF_ROWS,
    GRAZE_BOUND,
    GRAZE_BOUND_STEP,
    GRAZE_ROW,
    GRAZE_TOL,
    MAX_SPLITS,
    NO_PHASE,
    ROOT_TOL,
    SIMD_SLOTS,
    SIMULTANEOUS,
    SMALL_ANGLE,
    STATUS_DIVERGED,
    STATUS_OK,
    STATUS_SPLIT_LIMIT,
    _healthy,
    _keep_start,
    _leaves_side,
    _padded,
    _phase_at,
    _side,
    cubic_extrema,
    event_buffer,
    phase_increments,
    phase_rotate,
    phase_table,
)
from geardyn.solvers._template_model import events, rhs  # MODEL-IMPORT
from geardyn.solvers.model_calls import FORM_SIG, addresses

_CACHE = True
_JIT = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False}
# MODEL-ADAPTERS (a user's plain functions are adapted to the kernel interface here)
# The model's functions inlined (numba IR inlining) where the templates call them in a loop: a
# call with array arguments would otherwise cost reference counting on every stage of every step.
_rhs_i = nb.njit(**_INLINE)(rhs.py_func)
_events_i = nb.njit(**_INLINE)(events.py_func)
_CFUNC = {"cache": _CACHE, "error_model": "numpy", "boundscheck": False}


@nb.cfunc(FORM_SIG, **_CFUNC)
def _rhs_c(t, y, ny, out, nout, p, n_p, s, c):
    """The model's rhs as a C callback (:data:`.model_calls.FORM_SIG`)."""
    _rhs_i(t, carray(y, ny), carray(out, nout), carray(p, n_p), s, c)


@nb.cfunc(FORM_SIG, **_CFUNC)
def _events_c(t, y, ny, out, nout, p, n_p, s, c):
    """The model's events as a C callback (:data:`.model_calls.FORM_SIG`)."""
    _events_i(t, carray(y, ny), carray(out, nout), carray(p, n_p), s, c)


#: () -> (address of rhs, address of events): the ``fn`` of :mod:`._split_core`.
_fn = addresses(_rhs_c, _events_c)


@nb.njit(inline="always", **_JIT)
def _split_step(i, t0, y, y_trial, p, h, omega, n_per, sa, ca, s_end, c_end, side, g1, ncross,
                work, ybuf, gbuf):
    """:func:`._split_core._split_step` of this model."""
    return _shared._split_step(_fn(), i, t0, y, y_trial, p, h, omega, n_per, sa, ca, s_end,
                               c_end, side, g1, ncross, work, ybuf, gbuf)


@nb.njit(inline="always", **_JIT)
def _rows_step(i, t0, Y, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1, SIDE, G0, G1, W,
               gbuf, NCR, UNRES):
    """:func:`._split_core._rows_step` of this model."""
    _shared._rows_step(_fn(), i, t0, Y, p, h, omega, n_per, s_tab, c_tab, n_ev, K, TMP, Y1,
                       SIDE, G0, G1, W, gbuf, NCR, UNRES)


@nb.njit(**_JIT)
def _rk4(t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, k4, tmp, out, have_k1):
    """:func:`._split_core._rk4` of this model."""
    _shared._rk4(_fn(), t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, k4, tmp, out, have_k1)


@nb.njit(**_JIT)
def interpolant_events(y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """:func:`._split_core.interpolant_events` of this model."""
    _shared.interpolant_events(_fn(), y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc)


@nb.njit(**_JIT)
def _locate(j, side_j, g0j, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """:func:`._split_core._locate` of this model."""
    return _shared._locate(_fn(), j, side_j, g0j, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, gbuf,
                           pc)


@nb.njit(**_JIT)
def first_crossing(j, side_j, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """:func:`._split_core.first_crossing` of this model."""
    return _shared.first_crossing(_fn(), j, side_j, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf,
                                  pc)


# ---------------------------------------------------------------------------------------------
# The fused step loop, for a model with lane-scalar functions (``rhs_lane``, ``events_lane``,
# ``observe_lane``, ``rhs_lane_form``; see :mod:`geardyn.core.kernel_source`): one loop over the
# slots does a slot's whole grid step, the four RK4 stages with the model's rhs inlined and the
# state, stages and coefficients in local variables (registers), the events, the side test, the
# commit, the clocks and the statistics; nothing but the block's state goes through memory, and
# LLVM vectorises the loop over slots. Slots whose step was flagged (a side left or a possible
# graze) or that have bookkeeping due (a period's start, a sample, the end) are finished out of
# line (:func:`_slot_out`), their statistics there too. The arithmetic of every lane is that of
# the scalar kernel, operation for operation (no fastmath), so results are bitwise those of the
# other paths. The tuple helpers below are written out per tuple length when numba types them.


def _tuple_source(args, lines, scope=None):
    """A Python function ``f(args)`` with the body ``lines`` (for the overloads below)."""
    text = f"def _f({args}):\n" + "".join(f"    {line}\n" for line in lines)
    env = dict(scope or {})
    exec(compile(text, "<geardyn-lane-tuples>", "exec"), env)
    return env["_f"]


def _t_load(Y, k):
    """(Y[0, k], .., Y[LANE_NS - 1, k])."""


def _t_store(Y, k, y, keep, cond):
    """Y[q, k] = y[q] if cond else keep[q]."""


def _t_axpy(y, a, x):
    """y + a x, elementwise."""


def _t_comb(y, h6, k1, k2, k3, k4):
    """The RK4 combination y + h6 (k1 + 2 k2 + 2 k3 + k4), elementwise."""


def _t_screen(g1, GS, GP, SIDE, GR, k, locate):
    """:func:`_lanes_screen` of slot k for the events g1 at the trial step's end; the history
    shifted in place (GP[:, k] = GS[:, k], GS[:, k] = g1). True when the step is flagged."""


def _t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, g, o, stat):
    """The statistics of slot k at a grid point (events g, observables o), where ``stat``."""


def _t_side(GS, SIDE, k, g):
    """A lane's start: the events g into GS[:, k], their sides into SIDE[:, k]."""


def _t_healthy(y, bound):
    """:func:`_healthy_lane` of the state tuple y, branch-free."""


@nb.njit(**_JIT)
def _pick(cond, a, b):
    """a if cond else b, a select (a call, inlined by LLVM: numba's inliner would leave the
    generated tuple helpers with phi variables it then warns about)."""
    return a if cond else b


@nb.njit(inline="always", **_JIT)
def _screen_one(g1, s, g0, gp, locate):
    """One event of :func:`_lanes_screen`: (graze, flagged)."""
    d2 = g1 - 2.0 * g0 + gp
    crossed = (1.0 if g1 > 0.0 else -1.0) != s
    near = not min(abs(g0), abs(g1)) > GRAZE_BOUND * abs(d2)
    graze = locate & (crossed | (not s * d2 < 0.0)) & near
    return graze, crossed | graze


def _ix(arr, name, row):
    """Source text of element (row, k) of a block array: ``name[row, k]``, or of its flat view
    (rows of BLOCK slots: constant offsets, so that LLVM sees rows that cannot overlap)."""
    return f"{name}[{row}, k]" if arr.ndim == 2 else f"{name}[{row * BLOCK} + k]"


def _ov_t_load(Y, k):
    n = globals()["LANE_NS"]
    return _tuple_source("Y, k", ["return (" + "".join(f"{_ix(Y, 'Y', q)}, " for q in range(n))
                                  + ")"])


def _ov_t_store(Y, k, y, keep, cond):
    return _tuple_source("Y, k, y, keep, cond",
                         [f"{_ix(Y, 'Y', q)} = _pick(cond, y[{q}], keep[{q}])"
                          for q in range(len(y))] or ["pass"], {"_pick": _pick})


def _ov_t_axpy(y, a, x):
    return _tuple_source("y, a, x",
                         ["return (" + "".join(f"y[{q}] + a * x[{q}], " for q in range(len(y)))
                          + ")"])


def _ov_t_comb(y, h6, k1, k2, k3, k4):
    terms = "".join(f"y[{q}] + h6 * (k1[{q}] + 2.0 * k2[{q}] + 2.0 * k3[{q}] + k4[{q}]), "
                    for q in range(len(y)))
    return _tuple_source("y, h6, k1, k2, k3, k4", [f"return ({terms})"])


def _ov_t_screen(g1, GS, GP, SIDE, GR, k, locate):
    lines = ["hit = False"]
    for j in range(len(g1)):
        gs, gp = _ix(GS, "GS", j), _ix(GP, "GP", j)
        lines += [f"g0 = {gs}",
                  f"gr, fl = _screen_one(g1[{j}], {_ix(SIDE, 'SIDE', j)}, g0, {gp}, locate)",
                  f"{_ix(GR, 'GR', j)} = _pick(gr, 1.0, 0.0)", f"{gp} = g0", f"{gs} = g1[{j}]",
                  "hit = hit | fl"]
    return _tuple_source("g1, GS, GP, SIDE, GR, k, locate", [*lines, "return hit"],
                         {"_screen_one": _screen_one, "_pick": _pick})


def _ov_t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, g, o, stat):
    lines = ["pass"]
    for j in range(len(g)):
        for name, op in (("GMIN", "min"), ("GMAX", "max")):
            e = _ix(GMIN, name, j)
            lines.append(f"{e} = _pick(stat, {op}({e}, g[{j}]), {e})")
    for j in range(len(o)):
        lines.append(f"v = o[{j}]")
        for name, op in (("OMAX", "max"), ("OMIN", "min")):
            e = _ix(OMAX, name, j)
            lines.append(f"{e} = _pick(stat, {op}({e}, v), {e})")
        e = _ix(OSQ, "OSQ", j)
        lines.append(f"{e} = _pick(stat, {e} + v * v, {e})")
    return _tuple_source("GMIN, GMAX, OMAX, OMIN, OSQ, k, g, o, stat", lines, {"_pick": _pick})


def _ov_t_healthy(y, bound):
    terms = " & ".join(f"(abs(y[{q}]) <= bound)" for q in range(len(y))) or "True"
    return _tuple_source("y, bound", [f"return {terms}"])


def _ov_t_side(GS, SIDE, k, g):
    lines = ["pass"]
    for j in range(len(g)):
        lines += [f"{_ix(GS, 'GS', j)} = g[{j}]",
                  f"{_ix(SIDE, 'SIDE', j)} = _pick(g[{j}] > 0.0, 1.0, -1.0)"]
    return _tuple_source("GS, SIDE, k, g", lines, {"_pick": _pick})


if "rhs_lane" in globals():  # the model's lane-scalar functions (see .kernels)
    FUSED = True
    _rhs_l = rhs_lane  # noqa: F821
    _events_l = events_lane  # noqa: F821
    _observe_l = observe_lane  # noqa: F821
    _lane_form = rhs_lane_form  # noqa: F821
    #: The state size of the model's lane-scalar functions (``<rhs>_lane_states``).
    LANE_NS = int(_rhs_l.py_func.__globals__[_rhs_l.py_func.__name__ + "_states"])
    for _stub, _impl in ((_t_load, _ov_t_load), (_t_store, _ov_t_store), (_t_axpy, _ov_t_axpy),
                         (_t_comb, _ov_t_comb), (_t_screen, _ov_t_screen),
                         (_t_stats, _ov_t_stats), (_t_side, _ov_t_side),
                         (_t_healthy, _ov_t_healthy)):
        nb.extending.overload(_stub, inline="always")(_impl)
else:
    FUSED = False
    LANE_NS = 0
    _rhs_l = _events_l = _observe_l = None

    @nb.njit(**_JIT)
    def _lane_form(PT, k):
        return FORM_GENERAL


@nb.njit(inline="always", **_JIT)
def _flat(arrays):
    """Flat views of a tuple of five block arrays (rows of BLOCK slots)."""
    a, b, c, d, e = arrays
    return (a.reshape(a.size), b.reshape(b.size), c.reshape(c.size), d.reshape(d.size),
            e.reshape(e.size))


class _NoAliasCompiler(nb.core.compiler.Compiler):
    """numba's pipeline with the function's array arguments declared ``noalias`` (LLVM), so
    that the fused loop needs no runtime overlap checks of its ~30 block arrays (there are too
    many: LLVM would not vectorise it). The caller guarantees it: no two array arguments of
    a function compiled with it (the sweep's ``_block_run_form*``, the Lyapunov kernel's
    ``_lyap_run_form*``) that it touches share memory (``blk``'s views ``PH``,
    ``HW`` and ``FL`` of ``PH6``, ``HW3`` and the state arrays are used there, not those)."""

    def define_pipelines(self):
        self.state.flags.noalias = True
        return super().define_pipelines()
