"""The one-lane-at-a-time Lyapunov lanes, the reference of the lane blocks: every lane by the
rows of ``lyapunov_single`` (the kernel module's ``_run``, k = 1), the lanes of each grid one
after the other. Built for a model's Lyapunov kernel module (``kernels_for(model.kernel,
"lyapunov")``) from its ``_run`` and ``phase_table``; the loop here is compiled once per kernel
module and process (not cached; a plain loop, as numba's parallel loop compiles several times
longer), ``_run`` is the module's own (cached there)."""

from __future__ import annotations

import types

import numba as nb
import numpy as np

_SOURCE = '''
@nb.njit(error_model="numpy", boundscheck=False)
def lanes_rows(P, Y0, scale, T0, H, OMEGA, n_per, n_transient, n_steps, renorm_every, bound,
               out, err, unres, status, fd_steps, n_ev, n_blocks, variational):
    """Largest exponent of every lane (row of P, Y0; n_per steps per period), one lane at a
    time (the rows of lyapunov_single); the arguments as the kernel
    module's lyapunov_lanes takes them, out, err, unres, status and fd_steps filled."""
    L, ns = Y0.shape
    forced = False
    for lane in range(L):
        if OMEGA[lane] != 0.0:
            forced = True
    s_tab, c_tab = phase_table(n_per, forced)
    for lane in range(L):
        ex, er, _nb, st, un, fd = _run(P[lane], Y0[lane], scale, T0[lane], H[lane],
                                       OMEGA[lane], n_per, s_tab, c_tab, n_transient[lane],
                                       n_steps[lane], renorm_every, np.int64(1), bound,
                                       np.int64(n_ev), np.int64(n_blocks), variational)
        fd_steps[lane] = fd
        out[lane] = ex[0] if st != STATUS_DIVERGED else np.nan
        err[lane] = er[0] if st != STATUS_DIVERGED else np.nan
        unres[lane] = un
        status[lane] = st
'''

_BOUND: dict[str, types.FunctionType] = {}


def _compiled(kern: types.ModuleType):
    if kern.__name__ not in _BOUND:
        env = {"nb": nb, "np": np}
        env.update({name: getattr(kern, name) for name in ("_run", "phase_table",
                                                            "STATUS_DIVERGED")})
        exec(compile(_SOURCE, f"<Lyapunov rows of {kern.__name__}>", "exec"), env)
        _BOUND[kern.__name__] = env["lanes_rows"]
    return _BOUND[kern.__name__]


def rows_for(kern: types.ModuleType):
    """``kern.lyapunov_lanes`` (same arguments, same outputs) one lane at a time: the lanes of
    each grid (n_per: one for all lanes or one per lane) one after the other, each by the rows of
    ``kern.lyapunov_single``."""
    lanes_rows = _compiled(kern)

    def lyapunov_lanes_rows(P, Y0, scale, T0, H, OMEGA, n_per, n_transient, n_steps,
                            renorm_every, bound, out, err, n_ev=0, n_blocks=16, unresolved=None,
                            status=None, variational=False, fd_steps=None):
        if variational and not kern.VARIATIONAL:
            raise ValueError("the variational tangent needs a model with the tangent forms of "
                             "its rhs (a one-form model)")
        L = Y0.shape[0]
        nper = np.broadcast_to(np.asarray(n_per, np.int64), (L,))
        for n in np.unique(nper):
            idx = np.nonzero(nper == n)[0]
            part, part_err = np.full(idx.size, np.nan), np.full(idx.size, np.nan)
            part_u, part_s = np.zeros(idx.size, np.int64), np.zeros(idx.size, np.int64)
            part_f = np.zeros(idx.size, np.int64)
            sel = [np.ascontiguousarray(np.asarray(a)[idx])
                   for a in (P, Y0, T0, H, OMEGA, n_transient, n_steps)]
            lanes_rows(sel[0], sel[1], scale, sel[2], sel[3], sel[4], int(n), sel[5], sel[6],
                       renorm_every, bound, part, part_err, part_u, part_s, part_f, n_ev,
                       n_blocks, bool(variational))
            out[idx], err[idx] = part, part_err
            if fd_steps is not None:
                fd_steps[idx] = part_f
            if unresolved is not None:
                unresolved[idx] = part_u
            if status is not None:
                status[idx] = part_s

    return lyapunov_lanes_rows
