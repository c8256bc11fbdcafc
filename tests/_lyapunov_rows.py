"""The one-lane Lyapunov kernel, the tests' reference of the lane blocks: one lane's state and k
tangent vectors stepped one grid step at a time by the model's scalar steps (the difference rows,
``_tangent_step``, or the variational step below, ``_var_step``: the variational RK4 trial
``_var_trial``, the state's screen ``_leaves_side_step`` and, where it leaves a side,
``_var_split_lane``), re-orthonormalised and measured by the books' one-lane functions. None of
the lane blocks' code (their rows, fused loops, lane books) is in it, so that a block's results
equal to these, bitwise, show that the blocking, position and thread change nothing.

Built for a model's Lyapunov kernel module (``kernels_for(model.kernel, "lyapunov")``) from its
step functions: :func:`reference_for` writes the source below, bound to that module, beside the
generated kernels and imports it (numba caches it like them), or for an in-memory kernel module
executes it in memory. ``lyapunov_single`` (one lane, k exponents) and :func:`rows_for` (the
kernel module's ``lyapunov_lanes``, one lane at a time)."""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import types
from pathlib import Path

import numba as nb
import numpy as np

_HEAD = '''
import numba as nb
import numpy as np

import {kern} as _kernel_module  # noqa: E402
globals().update({{k: v for k, v in vars(_kernel_module).items() if not k.startswith('__')}})

from geardyn.solvers._lyapunov_books import (_block_bounds, _block_stderr, _orthonormalise,
                                              _stretch_logs)
from geardyn.solvers._step_shared import _healthy
'''

_SOURCE = '''
_JIT_REF = {**_JIT, "cache": CACHE_REF}

if VARIATIONAL:
    @nb.njit(_nrt=False, **_JIT_REF)
    def _var_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP,
                  Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VW, VX, VG):
        """Advance the state y (row 0 of Z) by grid step i and each tangent vector v (rows 1..,
        in z = y / S) by the variational RK4 (w = S v); a step whose state leaves a side of an
        edge (or may graze one) split with the tangent vectors through its sub-steps
        (_var_split_lane). Returns 1 where the step took the difference rows, else 0."""
        m, ns = Z.shape
        t = t0 + i * h
        hh = 0.5 * h
        j0 = 2 * (i % n_per)
        last = 2 * (m - 1)
        y = YP[last]
        for q in range(ns):
            y[q] = Z[0, q]
        KS = VW[0:4]
        KV = VW[4:8]
        TV = VW[8]
        w = VW[9]
        WN = VW[10:10 + m]
        for j in range(1, m):
            for q in range(ns):
                w[q] = S[q] * Z[j, q]
            _var_trial(t, hh, h, y, w, p, s_tab[j0], c_tab[j0], s_tab[j0 + 1], c_tab[j0 + 1],
                       s_tab[j0 + 2], c_tab[j0 + 2], KS, KV, TMP[last], TV, Y1[last], WN[j])
        if n_ev > 0:
            for q in range(ns):
                K[0, last, q] = KS[0, q]
            _events_i(t, y, G0[last], p, s_tab[j0], c_tab[j0])
            for j in range(n_ev):
                SIDE[last, j] = _side(G0[last, j])
            _events_i(t + h, Y1[last], G1[last], p, s_tab[j0 + 2], c_tab[j0 + 2])
            if _leaves_side_step(last, t, t + h, YP, K[0], G0, G1, SIDE, p, W[8], gbuf,
                                 s_tab[j0 + 2], c_tab[j0 + 2]):
                for q in range(ns):
                    VX[1, q] = Y1[last, q]
                for j in range(n_ev):
                    G0[0, j] = G0[last, j]
                    G1[0, j] = G1[last, j]
                    SIDE[0, j] = SIDE[last, j]
                return _var_split_lane(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab,
                                       n_ev, YP, E, K, TMP, Y1, SIDE, G0, G1, W, gbuf, NCR,
                                       UNRES, VX, VG)
        for j in range(1, m):
            for q in range(ns):
                Z[j, q] = WN[j, q] * IS[q]
        for q in range(ns):
            Z[0, q] = Y1[last, q]
        return 0
else:
    @nb.njit(**_JIT_REF)
    def _var_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP,
                  Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VW, VX, VG):
        if n_ev >= 0:
            raise ValueError("this model has no tangent form of its rhs (no one form)")
        return 0


@nb.njit(**_JIT_REF)
def _run(p, y0, S, t0, h, omega, n_per, s_tab, c_tab, n_transient, n_steps, renorm_every, k,
         bound, n_ev, n_blocks, variational):
    """(exponents[k], stderr[k], blocks, status, unresolved, fd_steps) of one lane started at
    t0 (forcing phase zero there), tangent vectors in y / S, by _var_step (variational) or the
    difference rows (_tangent_step) at every step."""
    ns = y0.size
    IS = np.empty(ns)
    for q in range(ns):
        IS[q] = 1.0 / S[q]
    m = k + 1
    Z = np.zeros((m, ns))
    W = np.zeros((9, ns))
    nr = 2 * k + 1
    YP = np.zeros((nr, ns))
    E = np.zeros(m)
    K = np.zeros((4, nr, ns))
    TMP = np.zeros((nr, ns))
    Y1 = np.zeros((nr, ns))
    ne = max(n_ev, 1)
    SIDE = np.ones((nr, ne), np.int64)
    G0 = np.zeros((nr, ne))
    G1 = np.zeros((nr, ne))
    gbuf = np.zeros((GBUF_ROWS, ne))
    NCR = np.zeros((nr, ne), np.int64)
    UNRES = np.zeros(nr, np.int64)
    acc = np.zeros(k)
    logs = np.zeros(k)
    ends = _block_bounds(max(n_steps, 1), n_per, n_blocks)
    nbk = ends.size
    blk = np.zeros((nbk, k))
    C = np.zeros((m, ns))
    VW = np.zeros((10 + m, ns))
    VX = np.zeros((9 + 7 * k, ns))
    VG = np.zeros((3, ne))
    n_fd = 0
    out = np.full(k, np.nan)
    err = np.full(k, np.nan)
    for q in range(ns):
        Z[0, q] = y0[q]
    for j in range(1, m):  # generic, orthonormalised start vectors: e_j + 0.1 (1, ..., 1)
        for q in range(ns):
            Z[j, q] = 0.1 + (1.0 if q == j - 1 else 0.0)
    _orthonormalise(Z, logs, False)
    renorm = max(renorm_every, 1)
    total = n_transient + n_steps
    since = 0
    cur = 0
    for i in range(total):
        if variational:
            n_fd += _var_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K,
                              TMP, Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VW, VX, VG)
        else:
            _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K,
                          TMP, Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES)
            n_fd += 1
        since += 1
        step = i + 1
        measure = step > n_transient
        if since == renorm or step == n_transient or step == total:
            since = 0
            if not _healthy(Z[0], bound):
                return out, err, 0, STATUS_DIVERGED, UNRES.sum(), n_fd
            if not _orthonormalise(Z, logs, measure):
                return out, err, 0, STATUS_DIVERGED, UNRES.sum(), n_fd
            if measure:
                for j in range(k):
                    acc[j] += logs[j]
                    blk[cur, j] += logs[j]
            if measure and step - n_transient == ends[cur]:
                cur += 1
        elif measure and step - n_transient == ends[cur]:
            _stretch_logs(Z, C, logs)
            for j in range(k):
                blk[cur, j] += logs[j]
                blk[cur + 1, j] -= logs[j]
            cur += 1
    unres = UNRES.sum()
    status = STATUS_SPLIT_LIMIT if unres > 0 else STATUS_OK
    if n_steps <= 0:
        return out, err, 0, status, unres, n_fd
    tm = n_steps * h
    for j in range(k):
        out[j] = acc[j] / tm
    _block_stderr(blk, ends, h, err)
    return out, err, nbk, status, unres, n_fd


def lyapunov_single(p, y0, scale, t0, h, omega, n_per, n_transient, n_steps, renorm_every, k,
                    bound, n_ev=0, n_blocks=16, variational=False):
    """The k leading exponents of one lane (see _run): (exponents, stderr, blocks, status,
    unresolved, fd_steps)."""
    if variational and not VARIATIONAL:
        raise ValueError("the variational tangent needs a model with the tangent forms of its rhs")
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    # copies and int64 casts: one compiled signature for every caller
    return _run(np.array(p, float), np.array(y0, float), np.array(scale, float), float(t0),
                float(h), float(omega), np.int64(n_per), s_tab, c_tab, np.int64(n_transient),
                np.int64(n_steps), np.int64(renorm_every), np.int64(k), float(bound),
                np.int64(n_ev), np.int64(n_blocks), bool(variational))
'''

_BOUND: dict[str, types.ModuleType] = {}


def reference_for(kern: types.ModuleType) -> types.ModuleType:
    """The reference module bound to the kernel module ``kern`` (built once per process)."""
    if kern.__name__ in _BOUND:
        return _BOUND[kern.__name__]
    cached = getattr(kern, "__file__", None) is not None
    text = (_HEAD.format(kern=kern.__name__) + f"\nCACHE_REF = {cached}\n" + _SOURCE)
    if cached:
        from geardyn.solvers import kernels

        h = hashlib.sha256(text.encode() + nb.__version__.encode())
        for shared in kernels.SHARED_MODULES:  # numba's cache checks only the module's own file
            h.update(Path(importlib.import_module(shared).__file__).read_bytes())
        # written atomically to the kernel cache folder and imported, as the kernels are
        module = kernels.load_generated(f"geardyn_lyapref_{h.hexdigest()[:20]}", text)
    else:
        module = types.ModuleType(f"{kern.__name__}_lyapref")
        exec(compile(text, module.__name__, "exec"), module.__dict__)
    from geardyn.solvers import kernels

    kernels._quiet_module(module)  # compiled as geardyn's kernels are (names, lock, warnings)
    _BOUND[kern.__name__] = module
    return module


def rows_for(kern: types.ModuleType):
    """``kern.lyapunov_lanes`` (same arguments, same outputs) one lane at a time, each by the
    reference's ``_run`` with k = 1 (:func:`reference_for`)."""
    ref = reference_for(kern)

    def lyapunov_lanes_rows(P, Y0, scale, T0, H, OMEGA, n_per, n_transient, n_steps,
                            renorm_every, bound, out, err, n_ev=0, n_blocks=16, unresolved=None,
                            status=None, variational=False, fd_steps=None):
        L = Y0.shape[0]
        nper = np.broadcast_to(np.asarray(n_per, np.int64), (L,))
        for lane in range(L):
            ex, er, _nb, st, un, fd = ref.lyapunov_single(
                P[lane], Y0[lane], scale, T0[lane], H[lane], OMEGA[lane], nper[lane],
                n_transient[lane], n_steps[lane], renorm_every, 1, bound, n_ev, n_blocks,
                variational)
            ok = st != kern.STATUS_DIVERGED
            out[lane] = ex[0] if ok else np.nan
            err[lane] = er[0] if ok else np.nan
            if fd_steps is not None:
                fd_steps[lane] = fd
            if unresolved is not None:
                unresolved[lane] = un
            if status is not None:
                status[lane] = st

    return lyapunov_lanes_rows


def one_lane(kern: types.ModuleType, p, y0, scale, t0, h, omega, n_per, n_transient, n_steps,
             renorm_every, k, bound, n_ev=0, n_blocks=16, variational=False):
    """One lane of the kernel module's lane blocks (``kern.lyapunov_block_lanes``, as
    ``geardyn.lyapunov`` runs it), returned as the reference's ``lyapunov_single`` returns it:
    (exponents[k], stderr[k], blocks, status, unresolved, fd_steps)."""
    ex, er = np.full((1, k), np.nan), np.full((1, k), np.nan)
    used, status, unres, fd = (np.zeros(1, np.int64) for _ in range(4))
    kern.lyapunov_block_lanes(
        np.array(p, float)[None, :], np.array(y0, float)[None, :], np.array(scale, float),
        np.array([float(t0)]), np.array([float(h)]), np.array([float(omega)]),
        np.array([n_per], np.int64), np.array([n_transient], np.int64),
        np.array([n_steps], np.int64), int(renorm_every), int(k), float(bound), ex, er, used,
        status, unres, int(n_ev), int(n_blocks), kern.BLOCK_ROWS, 1, bool(variational), fd)
    return ex[0], er[0], int(used[0]), int(status[0]), int(unres[0]), int(fd[0])
