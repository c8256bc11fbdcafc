"""Lyapunov exponents from the tangent (variational) equations, specialised per model.

This file is a template, like :mod:`geardyn.solvers._kernel_template`:
:func:`geardyn.solvers.kernels.kernels_for` (template ``"lyapunov"``) copies it with the import
line marked ``MODEL-IMPORT`` replaced by the model's compiled functions. As it stands it is a valid
module bound to the small test oscillator of :mod:`geardyn.solvers._template_model`.

Numerics
--------
* The state y is advanced on the main solver's grid (``n_per`` RK4 steps of ``h`` per forcing
  period, forcing phase from the same half-step table; an autonomous model has ``omega = 0`` and
  any ``h``), with the crossings of the ``n_ev`` switching functions located inside a step and
  the step split there, as in :mod:`geardyn.solvers._kernel_template` (shared
  :mod:`._step_core`).
* The tangent vectors live in the scaled coordinates z = y / s, s the model's characteristic
  scale of each state (:attr:`geardyn.Model.state_scale`, ones by default): a tangent vector v
  (in z) is advanced by the derivative of that step map Phi, by a central difference:
  ``(Phi(y + e s v) - Phi(y - e s v)) / (2 e s)`` (componentwise products and quotient) with
  ``e |v| = FD_DELTA (1 + min(|y / s|, FD_NORM_CAP))`` (Euclidean norms, FD_DELTA = 2^-20 ~
  1e-6, FD_NORM_CAP = 2^10), so that the perturbation is ~1e-6 of each state's own scale, not
  of its unit (in SI body angles 1e-6 rad would be ~0.1 % of a backlash). The term |y / s|
  keeps the perturbation above the rounding of y (relative error ~ eps / FD_DELTA); the cap
  keeps it small where a state drifts far from its scale without changing the dynamics (the
  rigid rotation of a device in body angles: |y / s| ~ 1e5 after 4000 tau of an unbalanced
  carrier), at a rounding error ~ eps |y / s| / (FD_DELTA FD_NORM_CAP) (2e-7 at 1e6).
  Exponents do not change under a constant linear change of coordinates, and with s = 1 every
  operation is the unscaled one (multiplying by 1.0 is exact): below the cap results are
  bitwise those of the unscaled kernel. For a smooth field this is RK4 applied to the
  variational equation v' = J(t, y) v (to O(e^2)); the perturbed states locate their own edge
  crossings, so a step in which one of them crosses an edge is differentiated correctly and the
  exponent keeps the solver's order. It is exact for affine step maps
  (linear models) up to rounding (~ eps / FD_DELTA ~ 1e-10 relative per step). The vector
  field is continuous across the dead-zone edges, so the flow is C^1 there and no saltation
  matrix is needed.
* Variational tangent (``variational``; a model written in the one form, whose kernel modules
  get the tangent forms of its rhs, :func:`geardyn.core.one_form.tangent_adapters`): the state
  and each tangent vector w = S v are stepped together, the RK4 stages of the pair from f and
  J w (dual numbers through the one form's rhs, :mod:`geardyn.core.dual`). That is the exact
  derivative of the RK4 step map (not a difference quotient of it), and the state is bitwise
  the difference rows' state row. A step whose state leaves a side of an edge (or may graze
  one) is split at the crossing, the state as :func:`_split_step` splits it (the same
  operations), and each tangent vector follows the state's sub-steps by the variational RK4,
  every stage's J w taken on the sides of its sub-step (a stage point that lies beyond the
  edge, by the O(h^3) of a crossing found on the trial step's interpolant, moved back onto its
  side along f); at each split point x the tangent is moved to where the numerical orbit
  crosses the edge, w -= (g(x) / g'(x)) (J_before - J_after) w (g the edge crossed, g' its rate
  along the orbit, J on either side of it): without that the tangent switches sides O(h^3)
  early or late at every crossing and the exponent is O(h^3), with it O(h^4)
  (``bench/split_tangent_order.py``, ``tests/test_lyapunov_variational.py``). A split step
  where that is ill-posed (two edges crossed at once, a point that cannot be put on its side
  within a quarter step, the split limit) is taken by the difference rows above (each row
  split at its own crossing) and counted (``fd_steps``). No saltation term is needed across
  an edge: the vector field is continuous there (the dead zone), so the flow is C^1, and
  ``min``/``max`` in the model give the derivative of the side they pick.
* Every ``renorm_every`` steps (and at the end of the transient and of the run) the tangent
  vectors are re-orthonormalised by modified Gram-Schmidt (a QR factorisation); the logs of the
  diagonal of R are summed over the measuring window (Benettin et al. 1980; Shimada & Nagashima
  1979). The transient advances the tangent vectors too (renormalised, not summed) so that they
  are aligned when measuring starts.
* Start time: the state y0 is given at time t0, where the forcing phase is zero (grid step i
  runs from t0 + i h, forcing phase from the table at i mod n_per; the time passed to ``rhs``,
  e.g. for a load fluctuation at Lambda, is t0 + i h), exactly as the sweep kernel runs a lane
  started at T0. A sweep's final state lies at forcing phase zero of its lane, so started at
  the lane's final time the exponent continues the lane in both forcing phases.
* Uncertainty: the measuring window is cut into up to ``n_blocks`` blocks of whole forcing
  periods (as equal as they divide); the log stretch of each block (the renormalisations in it,
  plus, where a block ends between two, the stretch so far, taken from a copy of the tangent
  vectors) over its time gives a block rate, and the spread of the rates the standard error
  (:func:`_block_stderr`). The exponent itself is summed as before, untouched.
* A lane whose state leaves ``|y| <= bound`` (checked at each renormalisation) or whose tangent
  vectors stop being finite is marked diverged (status 1) and its exponents are NaN.
* Cost per step: (2 k + 1) RK4 steps for k tangent vectors by the difference rows; k RK4 steps
  of the state and a tangent vector (f and J w in one inlined call) by the variational tangent.
  They are independent integrations of one grid step, so they run as the rows of one lockstep
  block (their RK4 stages interleaved, the model's functions inlined once), which overlaps
  their dependency chains; each row's arithmetic is that of a lone step, so the result does not
  depend on it.
* Every run is lanes of the lane blocks (:func:`lyapunov_block_lanes`: one lane for
  :func:`geardyn.lyapunov`, its spectrum with k = n tangent vectors); there is no one-lane
  kernel. The tests' reference steps one lane at a time by the scalar steps
  (``tests/_lyapunov_rows.py``), against which the blocks are bitwise.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn._bound_calls import always_bind, optimise_once
from geardyn.core.kernel_source import FORM_GENERAL, FORM_LOAD, FORM_QUIET
from geardyn.solvers._lyapunov_books import (  # compiled once for every model
    _DUE,
    _LAST,
    _NBK,
    _NST,
    _block_tables,
    _lane_books,
    _lane_books_core,
    _lane_books_inline,
    _lane_books_one,
    _lane_result,
    _lanes_init,
)
from geardyn.solvers._parallel import run_workers
from geardyn.solvers._step_core import (  # CORE-IMPORT
    _JIT,
    _JIT_NOALIAS,
    FUSED,
    GRAZE_ROW,
    _events_columns,
    _events_i,
    _events_l,
    _lane_form,
    _rhs_columns,
    _rhs_l,
    _split_copy,
    _split_rhs,
    _split_run,
    _split_step,
    _t_axpy,
    _t_comb,
    _t_load,
    _t_store,
    _tangent_step,
    _tuple_source,
)
from geardyn.solvers._step_shared import (
    BLOCK,
    GBUF_ROWS,
    INNER,
    OUTER,
    STATUS_DIVERGED,
    STATUS_OK,
    STATUS_SPLIT_LIMIT,
    _padded,
    _phase_at,
    _pick,
    _side,
    fd_rows,
    fd_scale,
    fd_size,
    fd_tangent,
    phase_increments,
    phase_rotate,
    phase_table,
    rk4_comb,
    rk4_sixth,
    screen_lone,
)
from geardyn.solvers._template_model import events, observe, rhs  # MODEL-IMPORT

# TANGENT-ADAPTERS (a one-form model's tangent forms of its rhs: see .kernels)

# the model interface names are part of the template's namespace (the generated copy re-binds
# them); only rhs and events are used here
__all__ = ["BLOCK_ROWS", "events", "lyapunov_block_lanes", "lyapunov_lanes", "observe",
           "phase_table", "rhs"]


#: Whether the model has the tangent forms of its rhs (a one-form model: ``rhs_tangent``,
#: ``rhs_lane_tangent``, see :func:`geardyn.core.one_form.tangent_adapters`), so that its
#: tangent vectors can be stepped by the variational RK4 (:func:`_var_trial`).
VARIATIONAL = "rhs_tangent" in globals()


if VARIATIONAL:
    _rhs_t = rhs_tangent  # noqa: F821

    @nb.njit(forceinline=False, _nrt=False, **_JIT, **INNER)
    def _rhs_t_call(t, y, v, dy, dv, p, s, c):
        """The rhs's tangent form called, not inlined (``rhs_tangent`` is compiled to be inlined
        by LLVM where it is called): the split step's sites, rarely run, take one copy of it,
        not one each (LLVM's time on the callers). The same operations, bitwise."""
        _rhs_t(t, y, v, dy, dv, p, s, c)

    @nb.njit(inline="always", **_JIT)
    def _var_trial(t, hh, h, y, w, p, s0, c0, s1, c1, s2, c2, KS, KV, TMP, TV, y1, w1):
        """The variational RK4 trial of one grid step: the state y into y1 and the tangent w
        (in y) into w1 = (dPhi/dy) w, Phi the RK4 step map (the stages of the pair (y, w) by
        the rhs's tangent form: f and J w at each stage); KS[0] is the state's k1. y1 is
        bitwise :func:`_rows_step`'s trial (the same operations)."""
        _var_trial_of(_rhs_t, t, hh, h, y, w, p, s0, c0, s1, c1, s2, c2, KS, KV, TMP, TV, y1,
                      w1)

    @nb.njit(inline="always", **_JIT)
    def _var_trial_of(rhs_t, t, hh, h, y, w, p, s0, c0, s1, c1, s2, c2, KS, KV, TMP, TV, y1,
                      w1):
        """:func:`_var_trial` with the rhs's tangent form ``rhs_t`` (``_rhs_t``, inlined, or
        ``_rhs_t_call``, called)."""
        ns = y.size
        for st in range(4):  # one call site of the rhs's tangent form (an inlined copy each)
            yi = y
            wi = w
            ts = t
            ss = s0
            cs = c0
            if st > 0:
                a = h if st == 3 else hh
                for q in range(ns):
                    TMP[q] = y[q] + a * KS[st - 1, q]
                    TV[q] = w[q] + a * KV[st - 1, q]
                yi = TMP
                wi = TV
                ts = t + hh
                ss = s1
                cs = c1
                if st == 3:
                    ts = t + h
                    ss = s2
                    cs = c2
            rhs_t(ts, yi, wi, KS[st], KV[st], p, ss, cs)
        h6 = rk4_sixth(h)
        for q in range(ns):
            y1[q] = rk4_comb(y[q], h6, KS[0, q], KS[1, q], KS[2, q], KS[3, q])
            w1[q] = rk4_comb(w[q], h6, KV[0, q], KV[1, q], KV[2, q], KV[3, q])

    # A split step's tangent: the state is split at its crossings by the split step itself
    # (:func:`_split_run`, :func:`_split_step`'s body, with this tangent's hooks: the same
    # operations, the same state, bitwise) and each tangent vector w follows its sub-steps by
    # the variational RK4 (:func:`_var_sub`), the Jacobian of every stage taken on the sides of
    # the sub-step (forced: a stage point that lies beyond an edge, by the O(h^3) of the crossing
    # found on the trial step's interpolant, is moved back onto its side along the orbit,
    # :func:`_side_point`); at each split point x, where the orbit's numerical crossing lies
    # g(x) / g'(x) before or after x (g the edge crossed, g' its rate along the orbit), the
    # tangent is moved to it: w -= (g / g') (J_before - J_after) w (:func:`_var_correct`).
    # Together O(h^4), as the unsplit steps (bench/split_tangent_order.py). A step where this
    # is ill-posed (two edges crossed at once, a point that cannot be moved onto its side within
    # FORCE_SPAN, the split limit) is taken by the difference rows (:func:`_tangent_step`) and
    # counted. Scratch VX (9 + 7 (m - 1) rows of the state's size): 0 the state, 1 its trial,
    # 2 a stage point, 3 a forced point, 4 a discarded f, 5-8 the stages' f, then per tangent
    # vector j from 9 + 7 j: w, its trial, a stage's w, the stages' J w; VG (3 rows of the
    # events' size): events, events, each event's margin.

    #: A point moved onto a side lies there by FORCE_MARGIN max(|g0|, |g1|) (g0, g1 the event at
    #: the grid step's start and trial end).
    FORCE_MARGIN = 2.0 ** -30
    #: The step along f, as a fraction of the grid step, of an event's rate along the orbit.
    RATE_STEP = 2.0 ** -18
    #: The furthest a point is moved along the orbit onto a side, and the longest shift g / g'
    #: of a split point, as fractions of the grid step; beyond, the difference rows.
    FORCE_SPAN = 0.25

    @nb.njit(inline="always", **_JIT)
    def _off_sides(ts, ys, ss, cs, p, side, M, g):
        """The number of events off their sides ``side`` at the point ys (time ts, phase ss,
        cs; the events into g; M: one entry per event)."""
        _events_i(ts, ys, g, p, ss, cs)
        n = 0
        for j in range(M.size):
            n += 1 if _side(g[j]) != side[j] else 0
        return n

    @nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
    def _side_point(ts, ys, fs, ss, cs, p, side, jx, want_x, M, h, g, g2, TP):
        """A point near the stage point ys (time ts, phase ss, cs, f(ys) = fs) on the sides
        ``side`` of every event (event jx, where >= 0, on side want_x instead) into TP: ys
        itself where it lies there, else ys + tau fs, the one event off its side moved to
        within its margin M (tau from the event's rate along fs). Returns (ok, moved); not ok
        where two events lie off their sides or tau exceeds FORCE_SPAN h."""
        ns = ys.size
        _events_i(ts, ys, g, p, ss, cs)
        bad = -1
        nbad = 0
        for j in range(M.size):
            want = want_x if j == jx else side[j]
            if _side(g[j]) != want:
                bad = j
                nbad += 1
        if nbad == 0:
            for q in range(ns):
                TP[q] = ys[q]
            return True, False
        if nbad > 1:
            return False, False
        want = want_x if bad == jx else side[bad]
        tau0 = RATE_STEP * h
        for q in range(ns):
            TP[q] = ys[q] + tau0 * fs[q]
        _events_i(ts, TP, g2, p, ss, cs)
        tau = (want * M[bad] - g[bad]) / ((g2[bad] - g[bad]) / tau0)
        if not abs(tau) <= FORCE_SPAN * h:
            return False, False
        for q in range(ns):
            TP[q] = ys[q] + tau * fs[q]
        _events_i(ts, TP, g2, p, ss, cs)
        for j in range(M.size):
            want = want_x if j == jx else side[j]
            if _side(g2[j]) != want:
                return False, False
        return True, True

    @nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
    def _var_sub(tan, ys, k1, hs, t, tm, sm, cm, te, se, ce, s1, c1, p, side, h, trial, out,
                 work):
        """The split step's sub-step hook (:func:`_split_run`) of the variational tangent
        ``tan`` = (m1, VX, VG): one RK4 sub-step of size hs from ys (time t, phase s1, c1,
        f(ys) = k1; middle stages at tm, sm, cm, the last at te, se, ce) of the state, as
        :func:`_rk4_stages` takes it (the same operations), into out, and of each of the m1
        tangent vectors (VX[9 + 7 j]) into its trial row (``trial``) or in place, every stage's
        J w on the sides ``side`` (:func:`_side_point`). Returns False where a stage could not
        be put on its sides."""
        m1, VX, VG = tan
        ns = ys.size
        TMP = VX[2]
        TP = VX[3]
        FB = VX[4]
        KS = VX[5:9]
        g = VG[0]
        g2 = VG[1]
        M = VG[2]
        hh = 0.5 * hs
        ok = True
        # one call site of the rhs's tangent form for the tangent vectors, one for a stage's f
        # (called, :func:`_rhs_t_call`); stage 0 at ys (its w copied to the stage row)
        for q in range(ns):
            KS[0, q] = k1[q]
        for st in range(4):
            a = hs if st == 3 else hh
            ts = t
            ss = s1
            cs = c1
            if st == 3:
                ts = te
                ss = se
                cs = ce
            elif st > 0:
                ts = tm
                ss = sm
                cs = cm
            pt = ys
            j_lo = 0
            if st == 0:
                for j in range(m1):
                    b = 9 + 7 * j
                    for q in range(ns):
                        VX[b + 2, q] = VX[b, q]
            else:
                for q in range(ns):
                    TMP[q] = ys[q] + a * KS[st - 1, q]
                for j in range(m1):
                    b = 9 + 7 * j
                    for q in range(ns):
                        VX[b + 2, q] = VX[b, q] + a * VX[b + 2 + st, q]
                _rhs_t_call(ts, TMP, VX[11], KS[st], VX[12 + st], p, ss, cs)
                pt = TMP
                j_lo = 1  # tangent 0's J w at TMP came with the stage's f
            if _off_sides(ts, pt, ss, cs, p, side, M, g) != 0:
                # np.int64: literal arguments would compile _side_point once more
                ok_s, moved = _side_point(ts, pt, KS[st], ss, cs, p, side, np.int64(-1),
                                          np.int64(0), M, h, g, g2, TP)
                ok = ok & ok_s
                pt = TP
                j_lo = 0
            for j in range(j_lo, m1):
                b = 9 + 7 * j
                _rhs_t_call(ts, pt, VX[b + 2], FB, VX[b + 3 + st], p, ss, cs)
        h6 = rk4_sixth(hs)
        for q in range(ns):
            out[q] = rk4_comb(ys[q], h6, KS[0, q], KS[1, q], KS[2, q], KS[3, q])
        for j in range(m1):
            b = 9 + 7 * j
            wo = VX[b + 1] if trial else VX[b]
            for q in range(ns):
                wo[q] = rk4_comb(VX[b, q], h6, VX[b + 3, q], VX[b + 4, q], VX[b + 5, q],
                                 VX[b + 6, q])
        return ok

    @nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
    def _var_correct(t, x, f, u, s, c, p, side, jx, m1, h, pc, VX, VG):
        """Each tangent vector (VX[9 + 7 j]) moved from the split point x (time t, the fraction
        u of grid step, phase s, c, f(x) = f) to the orbit's crossing of event jx (just
        crossed: side[jx] is the side after it): w -= (g / g') (J_before - J_after) w, g the
        event at x, g' its rate along the orbit (a forward difference over RATE_STEP h, the
        phase by angle addition), J_before and J_after at x on either side of the edge
        (:func:`_side_point`). Returns False where |g / g'| > FORCE_SPAN h or a side cannot
        be forced."""
        sa, ca, wh, i_mod = pc
        ns = x.size
        TMP = VX[2]
        TP = VX[3]
        FB = VX[4]
        g = VG[0]
        g2 = VG[1]
        M = VG[2]
        _events_i(t, x, g, p, s, c)
        gx = g[jx]
        tau0 = RATE_STEP * h
        for q in range(ns):
            TMP[q] = x[q] + tau0 * f[q]
        s2, c2 = _phase_at(sa, ca, wh, i_mod, u + RATE_STEP)
        _events_i(t + tau0, TMP, g2, p, s2, c2)
        shift = gx / ((g2[jx] - gx) / tau0)
        if not abs(shift) <= FORCE_SPAN * h:
            return False
        after = side[jx]
        for sd in range(2):  # J_before w into VX[b + 2], then J_after w into VX[b + 3]
            ok, moved = _side_point(t, x, f, s, c, p, side, jx, after if sd else -after, M, h,
                                    g, g2, TP)
            if not ok:
                return False
            for j in range(m1):
                b = 9 + 7 * j
                _rhs_t_call(t, TP, VX[b], FB, VX[b + 2 + sd], p, s, c)
                if sd:
                    for q in range(ns):
                        VX[b, q] = VX[b, q] - shift * (VX[b + 2, q] - VX[b + 3, q])
        return True

    @nb.njit(inline="always", **_JIT)
    def _var_at_split(tan, t, y, k1, u, s, c, p, side, jx, h, pc, fresh):
        """The split step's correction hook (:func:`_split_run`) of the variational tangent
        ``tan`` = (m1, VX, VG): :func:`_var_correct` at the split point y just after the
        crossing of event jx (``fresh``: k1 = f(y) computed first)."""
        m1, VX, VG = tan
        if fresh:
            _split_rhs(t, y, k1, p, s, c)
        # np.int64: a literal would compile _var_correct once more
        return _var_correct(t, y, k1, u, s, c, p, side, np.int64(jx), m1, h, pc, VX, VG)

    @nb.njit(inline="always", **_JIT)
    def _var_finish(tan, u, ok, y, y_trial):
        """The split step's end hook (:func:`_split_run`) of the variational tangent ``tan`` =
        (m1, VX, VG) on the trial of the (sub-)step from the fraction u: 2 where no crossing was
        found (u = 0: the step is its unsplit trial, VX[1], y untouched); else the state and
        the tangent vectors from their trial rows (the rest of the step after the crossing,
        its tangent forced onto the sides after it), 0, or 1 where that sub-step refused."""
        if u == 0.0:
            return 2
        if not ok:
            return 1
        m1, VX, VG = tan
        _split_copy(y, y_trial)
        for j in range(m1):
            b = 9 + 7 * j
            for q in range(y.size):
                VX[b, q] = VX[b + 1, q]
        return 0

    @optimise_once  # cold: optimised once where bound (see geardyn._bound_calls)
    @nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
    def _var_split(i, t0, m1, p, h, omega, n_per, sa, ca, s_end, c_end, side, g1, ncross, work,
                   gbuf, VX, VG):
        """:func:`_split_step` of the state in VX[0] (its unsplit trial in VX[1], the tangent
        vectors' unforced trials in their trial rows): the same split step
        (:func:`_split_run`, operation for operation) with the m1 tangent vectors carried
        through its sub-steps (:func:`_var_sub`) and moved at each split point
        (:func:`_var_at_split`; see above). Returns 0 when done (state and tangent vectors in
        VX[0] and their rows), 1 where the step is to be taken by the difference rows (a split
        point that crosses more than one edge, a hook that refused, the split limit), 2 where
        no crossing was found (the step is its unsplit trial, VX[1])."""
        return _split_run(i, t0, VX[0], VX[1], p, h, omega, n_per, sa, ca, s_end, c_end, side,
                          g1, ncross, work, work[8], gbuf, (m1, VX, VG), _var_sub,
                          _var_at_split, _var_finish, True)

    @optimise_once  # cold: optimised once where bound (see geardyn._bound_calls)
    @nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting
    def _var_split_lane(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP,
                        Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VX, VG):
        """Grid step i of one lane (state Z[0], tangent vectors Z[1..] in z = y / S) whose
        variational trial leaves a side of an edge or may graze one (the caller's screen: the
        state's trial in VX[1], the events at the step's start and the trial's end in G0[0],
        G1[0], their sides at the start in SIDE[0], the graze flags in gbuf[GRAZE_ROW]): the
        state split at its crossings and the tangent vectors carried through the sub-steps
        (:func:`_var_split`); where that is ill-posed, the step by the difference rows
        (:func:`_tangent_step`). Returns 1 where the step took the difference rows, else 0.
        Scratch: one lane's difference rows (:func:`_tangent_step`), VX, VG (see above)."""
        m, ns = Z.shape
        m1 = m - 1
        t = t0 + i * h
        hh = 0.5 * h
        j0 = 2 * (i % n_per)
        y = VX[0]
        for q in range(ns):
            y[q] = Z[0, q]
        for j in range(m1):
            b = 9 + 7 * j
            for q in range(ns):
                VX[b, q] = S[q] * Z[j + 1, q]
        for j in range(n_ev):
            VG[2, j] = FORCE_MARGIN * max(abs(G0[0, j]), abs(G1[0, j]))
        code = _var_split(i, t0, m1, p, h, omega, n_per, s_tab[j0], c_tab[j0], s_tab[j0 + 2],
                          c_tab[j0 + 2], SIDE[0], G1[0], NCR[0], W, gbuf, VX, VG)
        if code == 2:  # the unsplit trial: the tangent vectors by the variational trial
            for j in range(m1):
                b = 9 + 7 * j
                _var_trial_of(_rhs_t_call, t, hh, h, y, VX[b], p, s_tab[j0], c_tab[j0],
                              s_tab[j0 + 1], c_tab[j0 + 1], s_tab[j0 + 2], c_tab[j0 + 2],
                              VX[5:9], VX[b + 3:b + 7], VX[2], VX[b + 2], VX[1], VX[b + 1])
                for q in range(ns):
                    VX[b, q] = VX[b + 1, q]
            for q in range(ns):
                y[q] = VX[1, q]
            code = 0
        if code:
            _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K,
                          TMP, Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES)
            return 1
        for j in range(m1):
            b = 9 + 7 * j
            for q in range(ns):
                Z[j + 1, q] = VX[b, q] * IS[q]
        for q in range(ns):
            Z[0, q] = y[q]
        return 0

else:
    @nb.njit(**_JIT, **INNER)
    def _var_split_lane(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP,
                        Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VX, VG):
        """A model without tangent forms has no variational step (its callers refuse)."""
        if n_ev >= 0:
            raise ValueError("this model has no tangent form of its rhs (no one form)")
        return 0


# ---------------------------------------------------------------------------------------------
# Lane blocks, structure of arrays: the integrations of several lanes (each lane's state row and its
# 2 k perturbed rows) advance as the rows of one block, state Y[q, r] with the row index r innermost
# and contiguous, the block's width a runtime value, so that the RK4 stages, the side test, the
# finite-difference set-up and its combination are loops over rows without calls, which LLVM
# vectorises; the model's lane-block functions (``rhs_lanes``, ``events_lanes``; see
# :mod:`.kernels`) are such loops too, called once per stage of a block step (compiled once per
# model, shared with the sweep kernel: inlined at each of the seven call sites they would be typed
# and compiled seven times). Row r = slot nl + l holds slot ``slot`` of lane l of the block (slots
# 2 j - 2, 2 j - 1: tangent j's y + e s v and y - e s v; slot 2 k: the state), so that a lane's rows
# lie nl apart. Each row gets its own coefficients (PT[:, r]), times and forcing phase (SP[r],
# CP[r]). A row whose trial step leaves a side of an edge (or may graze one) is finished on the
# scalar path (:func:`_split_step`). Gram-Schmidt, the block statistics and the health check run per
# lane, at its renormalisations, on a gathered copy with the one-lane functions of the books. Every
# row's arithmetic is that of :func:`_rows_step`, operation for operation (no fastmath), so results
# are bitwise those of one lane stepped alone, whatever the blocking, position or thread.

#: The path of a block of one lane of fewer rows than ROW_PAD (:func:`_lyap_block_one`),
#: beside the lane forms' paths (FORM_GENERAL: the row block, FORM_QUIET, FORM_LOAD).
PATH_ONE = 3
#: Most rows of a lane block (lanes of 2 k + 1 rows each; at least one lane).
BLOCK_ROWS = 64
#: The rows of a block are padded to a multiple of this (see :func:`_lyap_block`): LLVM
#: vectorises the row loops 8 wide, interleaved 4 times, and runs a remainder of up to 31 rows
#: scalar (the model's lane functions cost about three times as much per row scalar as
#: vectorised). Only where the model has lane-block functions (else 1).
ROW_PAD = 1


if "rhs_lanes" in globals():  # the model's lane-block functions (see .kernels), called
    ROW_PAD = 32

    @nb.njit(inline="always", **_JIT)
    def _rows_rhs(T, Y, DY, PT, P, LANE, nr, SP, CP, SC, ybuf, dbuf):
        rhs_lanes(T, Y, DY, PT, nr, SP, CP, SC)  # noqa: F821

    @nb.njit(inline="always", **_JIT)
    def _rows_events(T, Y, G, PT, P, LANE, nr, SP, CP, ybuf, gb):
        events_lanes(T, Y, G, PT, nr, SP, CP)  # noqa: F821

else:
    _rows_rhs = _rhs_columns
    _rows_events = _events_columns


@nb.njit(inline="always", **_JIT)
def _fill_phase(nr, IDX, S_TAB, C_TAB, PH):
    """The rows' forcing phases of a grid step from their tables: sin and cos at the step's
    start, middle and end (IDX[r]: the start's index in S_TAB, C_TAB) into rows 0-5 of PH."""
    for d in range(3):
        for r in range(nr):
            j = IDX[r] + d
            PH[2 * d, r] = S_TAB[j]
            PH[2 * d + 1, r] = C_TAB[j]


@nb.njit(inline="always", **_JIT)
def _fd_setup(nl, m, ZT, S, IS, Y, E, OK, NY):
    """The rows of a grid step from the lanes' states and tangent vectors (ZT[j, q, l]), as in
    :func:`_tangent_step`: slot 2 k the state, slots 2 j - 2 and 2 j - 1 y +- e S v_j
    (:func:`fd_scale`, :func:`fd_size`, :func:`fd_rows`); E[j, l] = e (NaN for a lost vector,
    whose rows follow the state; OK[j, l] False)."""
    ns = ZT.shape[1]
    last = 2 * (m - 1)
    for l in range(nl):
        NY[l] = 0.0
    for q in range(ns):
        for l in range(nl):
            zq = ZT[0, q, l] * IS[q]
            NY[l] += zq * zq
    for l in range(nl):
        NY[l] = fd_scale(NY[l])  # the perturbation's size
    for q in range(ns):
        for l in range(nl):
            Y[q, last * nl + l] = ZT[0, q, l]
    for j in range(1, m):
        for l in range(nl):
            E[j, l] = 0.0
        for q in range(ns):
            for l in range(nl):
                E[j, l] += ZT[j, q, l] * ZT[j, q, l]
        for l in range(nl):
            E[j, l], OK[j, l] = fd_size(NY[l], E[j, l])
        for q in range(ns):
            sq = S[q]
            for l in range(nl):
                Y[q, (2 * j - 2) * nl + l], Y[q, (2 * j - 1) * nl + l] = fd_rows(
                    ZT[0, q, l], E[j, l], sq, ZT[j, q, l], OK[j, l])


@nb.njit(inline="always", **_JIT)
def _fd_combine(nl, m, ZT, IS, Y, E, ACT):
    """The active lanes' new tangent vectors (Phi(y + e S v) - Phi(y - e S v)) / (2 e S) and
    states from the stepped rows, as in :func:`_tangent_step` (NaN for a lost vector)."""
    ns = ZT.shape[1]
    last = 2 * (m - 1)
    for j in range(1, m):
        for q in range(ns):
            iq = IS[q]
            for l in range(nl):
                v = fd_tangent(Y[q, (2 * j - 2) * nl + l], Y[q, (2 * j - 1) * nl + l], E[j, l],
                               iq)
                ZT[j, q, l] = v if ACT[l] else ZT[j, q, l]
    for q in range(ns):
        for l in range(nl):
            ZT[0, q, l] = Y[q, last * nl + l] if ACT[l] else ZT[0, q, l]


@nb.njit(inline="always", **_JIT)
def _rows_rk4(nr, Y, Y1, K1, K2, K3, K4, TMP, TS, TM, TE, HR, HH, H6, PT, P, LANE, PH, SC, ybuf,
              dbuf):
    """One RK4 trial step of every row into Y1 (the arithmetic of :func:`_rows_step`); PH:
    the rows' forcing phases (sin, cos) at the step's start, middle and end (rows 0-5)."""
    ns = Y.shape[0]
    _rows_rhs(TS, Y, K1, PT, P, LANE, nr, PH[0], PH[1], SC, ybuf, dbuf)
    for q in range(ns):
        for r in range(nr):
            TMP[q, r] = Y[q, r] + HH[r] * K1[q, r]
    _rows_rhs(TM, TMP, K2, PT, P, LANE, nr, PH[2], PH[3], SC, ybuf, dbuf)
    for q in range(ns):
        for r in range(nr):
            TMP[q, r] = Y[q, r] + HH[r] * K2[q, r]
    _rows_rhs(TM, TMP, K3, PT, P, LANE, nr, PH[2], PH[3], SC, ybuf, dbuf)
    for q in range(ns):
        for r in range(nr):
            TMP[q, r] = Y[q, r] + HR[r] * K3[q, r]
    _rows_rhs(TE, TMP, K4, PT, P, LANE, nr, PH[4], PH[5], SC, ybuf, dbuf)
    for q in range(ns):
        for r in range(nr):
            Y1[q, r] = rk4_comb(Y[q, r], H6[r], K1[q, r], K2[q, r], K3[q, r], K4[q, r])


@nb.njit(inline="always", **_JIT)
def _rows_screen(nr, G0, G1, GE, GR, FLAG):
    """:func:`screen_lone` for every row and event, vectorised: FLAG[r] != 0 where row r's trial
    step ends on another side of an edge than it started (G0, G1: events at the ends) or may
    graze one (GR[j, r] = 1; GE: events at y + h f(t, y))."""
    for r in range(nr):
        FLAG[r] = 0.0
    for j in range(G1.shape[0]):
        for r in range(nr):
            g0 = G0[j, r]
            graze, flagged = screen_lone(G1[j, r], 1.0 if g0 > 0.0 else -1.0, g0, GE[j, r])
            GR[j, r] = 1.0 if graze else 0.0
            FLAG[r] += 1.0 if flagged else 0.0


@nb.njit(inline="always", **_JIT)
def _rows_commit(i, nr, NPR, Y, Y1, G0, G1, GR, FLAG, ACTR, P, LANE, T0R, HR, OMEGA, ys,
                 y1s, sides, g1s, ncross, W, gbuf, UNRR, PH):
    """Take the trial step of the active lanes' rows: the unflagged ones vectorised, the flagged
    ones one by one with the crossings located (:func:`_split_step`; a step of row r that
    reaches the split limit is counted in UNRR[r]). PH: the rows' phases of the step
    (:func:`_fill_phase`), the start's and end's passed to the split."""
    ns = Y.shape[0]
    n_ev = G1.shape[0]
    for q in range(ns):
        for r in range(nr):
            Y[q, r] = Y1[q, r] if ACTR[r] & (FLAG[r] == 0.0) else Y[q, r]
    n_split = 0  # (no short-circuit operators: the row loops stay branch-free and vectorise)
    for r in range(nr):
        n_split += 1 if ACTR[r] & (FLAG[r] != 0.0) else 0
    if n_split == 0:
        return
    for r in range(nr):
        if FLAG[r] == 0.0 or not ACTR[r]:
            continue
        lane = LANE[r]
        for q in range(ns):
            ys[q] = Y[q, r]
            y1s[q] = Y1[q, r]
        for j in range(n_ev):
            sides[j] = _side(G0[j, r])
            g1s[j] = G1[j, r]
            gbuf[GRAZE_ROW, j] = GR[j, r]
        UNRR[r] += _split_step(i, T0R[r], ys, y1s, P[lane], HR[r], OMEGA[lane], NPR[r],
                               PH[0, r], PH[1, r], PH[4, r], PH[5, r], sides, g1s, ncross, W,
                               W[8], gbuf)
        for q in range(ns):
            Y[q, r] = ys[q]


@nb.njit(inline="always", **_JIT)
def _set_column(r, lane, P, T0, H, NPER, OFF, PT, T0R, HR, HH, H6, NPR, IDX, END):
    """Column r of a block's per-row (or per-lane) arrays from lane ``lane``: coefficients,
    start time, step, half and sixth step, steps per period, phase-table index and end."""
    for j in range(P.shape[1]):
        PT[j, r] = P[lane, j]
    T0R[r] = T0[lane]
    HR[r] = H[lane]
    HH[r] = 0.5 * H[lane]
    H6[r] = rk4_sixth(H[lane])
    NPR[r] = NPER[lane]
    IDX[r] = OFF[lane]
    END[r] = OFF[lane] + 2 * NPER[lane]


@nb.njit(**_JIT, **INNER)
def _lyap_one(first, max_total, due, renorm, bound, P, S, IS, T0, H, OMEGA, NPER, S_TAB, C_TAB,
              OFF, n_ev, ZT, IST, ENDS, BLK, ACC, ACT, ACTR, Zl, Cl, logs, status, W, gbuf):
    """:func:`_lyap_block`'s time loop for one lane (ZT[:, :, 0], nl = 1): its 2 k + 1 rows
    by the scalar rows step (:func:`_tangent_step`, as the monodromy steps its rows; the
    arithmetic of the block's rows), its bookkeeping where due (:func:`_lane_books_core`,
    inlined: :func:`_lyap_one_loop`). Returns the steps of its rows that reached the split
    limit."""
    m, ns = Zl.shape
    k = m - 1
    nr = 2 * k + 1
    ne = gbuf.shape[1]
    rows = (ZT.reshape((m, ns)), np.zeros((nr, ns)), np.zeros(m), np.zeros((4, nr, ns)),
            np.zeros((nr, ns)), np.zeros((nr, ns)), np.ones((nr, ne), np.int64),
            np.zeros((nr, ne)), np.zeros((nr, ne)), np.zeros((nr, ne), np.int64),
            np.zeros(nr, np.int64))
    return _lyap_one_loop(first, max_total, due, renorm, bound, P, S, IS, T0, H, OMEGA, NPER,
                          S_TAB[OFF[first]:], C_TAB[OFF[first]:], n_ev, ZT, IST, ENDS, BLK, ACC,
                          ACT, ACTR, Zl, Cl, logs, status, W, gbuf, rows)


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _lyap_one_loop(first, max_total, due, renorm, bound, P, S, IS, T0, H, OMEGA, NPER, s_tab,
                   c_tab, n_ev, ZT, IST, ENDS, BLK, ACC, ACT, ACTR, Zl, Cl, logs, status, W,
                   gbuf, rows):
    """:func:`_lyap_one`'s loop (rows: Z, the lane's rows as ZT's view, and the scratch of
    :func:`_tangent_step`)."""
    Z, YP, E, K, TMP, Y1, SIDE, G0, G1, NCR, UNRES = rows
    k = Z.shape[0] - 1
    p = P[first]
    t0, h, omega, n_per = T0[first], H[first], OMEGA[first], NPER[first]
    for i in range(max_total):
        if not ACT[0]:
            break
        _tangent_step(i, t0, Z, S, IS, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP,
                      Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES)
        step = i + 1
        if step >= due:
            due = _lane_books_inline(step, first, 1, k, renorm, bound, ZT, Zl, Cl, logs, IST,
                                     ENDS, BLK, ACC, ACT, ACTR, status)
    return UNRES.sum()


@nb.njit(**_JIT, **INNER)
def _lyap_block(first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF, n_transient,
                n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used, status, unres,
                fd_steps):
    """:func:`_lyap_block_rows` for any block."""
    _lyap_block_rows(FORM_GENERAL, first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                     n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                     status, unres, fd_steps)


@nb.njit(**_JIT, **INNER)
def _lyap_block_one(first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF, n_transient,
                    n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used, status, unres,
                    fd_steps):
    """:func:`_lyap_block_rows` for a block of one lane of fewer rows than ROW_PAD (or of a
    model without lane-block functions): :func:`_lyap_one`'s scalar rows only, without the row
    block's loop (not compiled)."""
    _lyap_block_rows(PATH_ONE, first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                     n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                     status, unres, fd_steps)


@nb.njit(inline="always", **_JIT)
def _lyap_block_rows(path, first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                     n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                     status, unres, fd_steps):
    """The k leading exponents of lanes first..first+nl-1 (lane with NPER[lane] steps per
    period, its phase table at S_TAB, C_TAB[OFF[lane]:]), their rows in one block (see above);
    per lane the exponents of its difference rows, into out[lane], err[lane], used[lane],
    status[lane], unres[lane]. (A block of a model's lane form takes the fused loop instead:
    :func:`_block_path`.)"""
    ns = Y0.shape[1]
    m = k + 1
    nr = (2 * k + 1) * nl
    # the rows' arrays padded to a multiple of ROW_PAD (rows nr.. copy lane 0's coefficients
    # and never commit a step), so that the row loops have no scalar remainder
    nrp = (nr + ROW_PAD - 1) // ROW_PAD * ROW_PAD
    IS = np.empty(ns)
    for q in range(ns):
        IS[q] = 1.0 / S[q]
    ZT = np.zeros((m, ns, nl))
    Y = np.zeros((ns, nrp))  # padded rows: a state at zero
    Y1 = np.empty((ns, nrp))
    K1 = np.empty((ns, nrp))
    K2 = np.empty((ns, nrp))
    K3 = np.empty((ns, nrp))
    K4 = np.empty((ns, nrp))
    TMP = np.empty((ns, nrp))
    PT = np.empty((P.shape[1], nrp))
    LANE = np.empty(nrp, np.int64)
    T0R = np.empty(nrp)
    HR = np.empty(nrp)
    HH = np.empty(nrp)
    H6 = np.empty(nrp)
    TS = np.empty(nrp)
    TM = np.empty(nrp)
    TE = np.empty(nrp)
    HD = np.empty(nrp)
    PH = np.empty((6, nrp))  # the rows' forcing phases in a step (see _fill_phase)
    IDX = np.empty(nrp, np.int64)  # the index of a row's phase at the step's start in S_TAB
    NPR = np.empty(nrp, np.int64)  # a row's steps per period
    END = np.empty(nrp, np.int64)  # the index of a row's phase table's last period start + 2
    SC = np.zeros((8, nrp))
    ne = max(n_ev, 1)
    G0 = np.zeros((ne, nrp))
    G1 = np.zeros((ne, nrp))
    GE = np.zeros((ne, nrp))
    GR = np.zeros((ne, nrp))
    FLAG = np.zeros(nrp)
    UNRR = np.zeros(nrp, np.int64)  # each row's steps that reached the split limit
    E = np.zeros((m, nl))
    OK = np.zeros((m, nl), np.bool_)
    NY = np.zeros(nl)
    # per lane
    ACT = np.zeros(nl, np.bool_)
    ACTR = np.zeros(nrp, np.bool_)  # ACT of each row's lane
    ys = np.zeros(ns)
    y1s = np.zeros(ns)
    ybuf = np.zeros(ns)
    dbuf = np.zeros(ns)
    gb = np.zeros(ne)
    sides = np.ones(ne, np.int64)
    g1s = np.zeros(ne)
    ncross = np.zeros(ne, np.int64)
    W = np.zeros((9, ns))
    gbuf = np.zeros((GBUF_ROWS, ne))
    renorm = max(renorm_every, 1)
    IST, ENDS, BLK, ACC, Zl, Cl, logs, max_total = _lanes_init(first, nl, k, Y0, NPER,
                                                                n_transient, n_steps,
                                                                renorm_every, n_blocks, out,
                                                                err, used, status, ZT, ACT)
    for r in range(nrp):
        l = r % nl if r < nr else 0
        lane = first + l
        LANE[r] = lane
        _set_column(r, lane, P, T0, H, NPER, OFF, PT, T0R, HR, HH, H6, NPR, IDX, END)
        ACTR[r] = ACT[l] and r < nr
    due = max_total
    for l in range(nl):
        if ACT[l]:
            due = min(due, IST[l, _DUE])
    # one lane of fewer rows than ROW_PAD (or a model without lane-block functions, whose rows
    # the block evaluates one by one): its rows by the scalar rows step (:func:`_lyap_one`),
    # not a block mostly of padding
    # (``path`` PATH_ONE, a constant: the caller's block is such a lane, the loop below is
    # not compiled)
    if path == PATH_ONE:
        one = True
        u_one = _lyap_one(first, max_total, due, renorm, bound, P, S, IS, T0, H, OMEGA, NPER,
                          S_TAB, C_TAB, OFF, n_ev, ZT, IST, ENDS, BLK, ACC, ACT, ACTR, Zl, Cl,
                          logs, status, W, gbuf)
    else:  # (never such a lane: :func:`_block_paths` gives it PATH_ONE)
        one = False
        u_one = 0
        for i in range(max_total):
            live = False
            for l in range(nl):
                live = live or ACT[l]
            if not live:
                break
            _fd_setup(nl, m, ZT, S, IS, Y, E, OK, NY)
            for r in range(nrp):
                t = T0R[r] + i * HR[r]
                TS[r] = t
                TM[r] = t + HH[r]
                TE[r] = t + HR[r]
                HD[r] = TE[r] - t
            _fill_phase(nrp, IDX, S_TAB, C_TAB, PH)
            if n_ev > 0:
                _rows_events(TS, Y, G0, PT, P, LANE, nrp, PH[0], PH[1], ybuf, gb)
            _rows_rk4(nrp, Y, Y1, K1, K2, K3, K4, TMP, TS, TM, TE, HR, HH, H6, PT, P, LANE, PH, SC,
                      ybuf, dbuf)
            if n_ev > 0:
                _rows_events(TE, Y1, G1, PT, P, LANE, nrp, PH[4], PH[5], ybuf, gb)
                for q in range(ns):
                    for r in range(nrp):
                        TMP[q, r] = Y[q, r] + HD[r] * K1[q, r]
                _rows_events(TE, TMP, GE, PT, P, LANE, nrp, PH[4], PH[5], ybuf, gb)
                _rows_screen(nrp, G0, G1, GE, GR, FLAG)
            _rows_commit(i, nrp, NPR, Y, Y1, G0, G1, GR, FLAG, ACTR, P, LANE, T0R, HR, OMEGA, ys,
                         y1s, sides, g1s, ncross, W, gbuf, UNRR, PH)
            _fd_combine(nl, m, ZT, IS, Y, E, ACT)
            for r in range(nrp):  # the next step's phase index: 2 (i + 1 mod n_per) from the start
                IDX[r] = IDX[r] + 2 if IDX[r] + 2 < END[r] else IDX[r] + 2 - 2 * NPR[r]
            step = i + 1
            if step >= due:
                due = _lane_books(step, first, nl, k, renorm, bound, ZT, Zl, Cl, logs, IST,
                                  ENDS, BLK, ACC, ACT, ACTR, H, out, err, used, status)
    if one and status[first] != STATUS_DIVERGED:
        _lane_result(0, first, k, IST[0, _NST], H[first], ENDS, IST[0, _NBK], BLK, ACC, out, err,
                     used)
    for l in range(nl):  # the split-limit steps of each lane's rows (slots nl apart)
        lane = first + l
        u = 0
        for slot in range(2 * k + 1):
            u += UNRR[slot * nl + l]
        u += u_one
        unres[lane] = u
        fd_steps[lane] = IST[l, _LAST]  # the steps run (each by the difference rows)
        if u > 0 and status[lane] == STATUS_OK:
            status[lane] = STATUS_SPLIT_LIMIT


# ---------------------------------------------------------------------------------------------
# The fused Lyapunov block (k = 1, a model with lane-scalar functions in a vectorising form,
# see :data:`geardyn.core.kernel_source.LANE_FORMS`): one loop over the block's lanes per grid
# step does what the row loops above do for each lane's three rows (the state, y + e S v and
# y - e S v): the finite-difference set-up, the RK4 trials with the model's rhs inlined and
# the states in registers, the events and the side test, and, where no row of the lane is
# flagged, the commit and the new tangent vector. A lane with a flagged row is finished out of
# line (:func:`_lyap_flagged`: the flagged rows' split steps, then its combination). The
# arithmetic of each row is that of :func:`_rows_rk4` and of the one-lane kernel, operation for
# operation, so the exponents are bitwise the same (tests/test_lyapunov_lanes.py). The block's
# arrays are BLOCK lanes wide (rows at constant offsets) and the loop's function is compiled
# with its arrays ``noalias``, as the sweep's fused loop (see its template).


def _t_dot_scaled(y, IS):
    """sum_q (y_q IS[q])^2, summed from 0.0 in the order of q (as :func:`_fd_setup`)."""


def _t_dot(y):
    """sum_q y_q^2, summed from 0.0 in the order of q."""


def _t_fd_rows(z0, v, S, e, ok):
    """The two perturbed rows z0 + e (S v) and z0 - e (S v) (z0 where not ok), as tuples
    (:func:`fd_rows` elementwise)."""


def _t_fd_tangent(ya, yb, e, IS):
    """The new tangent vector from the rows' ends ya, yb (:func:`fd_tangent` elementwise)."""


def _ov_t_dot_scaled(y, IS):
    body = ["acc = 0.0"] + [f"z = y[{q}] * IS[{q}]\n    acc += z * z" for q in range(len(y))]
    return _tuple_source("y, IS", [*body, "return acc"])


def _ov_t_dot(y):
    body = ["acc = 0.0"] + [f"acc += y[{q}] * y[{q}]" for q in range(len(y))]
    return _tuple_source("y", [*body, "return acc"])


def _ov_t_fd_rows(z0, v, S, e, ok):
    n = len(z0)
    lines = [f"a{q}, b{q} = fd_rows(z0[{q}], e, S[{q}], v[{q}], ok)" for q in range(n)]
    plus = "".join(f"a{q}, " for q in range(n))
    minus = "".join(f"b{q}, " for q in range(n))
    return _tuple_source("z0, v, S, e, ok", [*lines, f"return ({plus}), ({minus})"],
                         {"fd_rows": fd_rows})


def _ov_t_fd_tangent(ya, yb, e, IS):
    terms = "".join(f"fd_tangent(ya[{q}], yb[{q}], e, IS[{q}]), " for q in range(len(ya)))
    return _tuple_source("ya, yb, e, IS", [f"return ({terms})"], {"fd_tangent": fd_tangent})


if FUSED:
    for _stub, _impl in ((_t_dot_scaled, _ov_t_dot_scaled), (_t_dot, _ov_t_dot),
                         (_t_fd_rows, _ov_t_fd_rows), (_t_fd_tangent, _ov_t_fd_tangent)):
        nb.extending.overload(_stub, inline="always")(_impl)


@nb.njit(inline="always", **_JIT)
def _row_trial(form, y, PT, l, ts, tm, te, hh, h, h6, hd, ph):
    """One row's RK4 trial (as :func:`_rows_rk4`) and its events at the start, the end and
    y + hd f (the graze predictor): (y1, g0, g1, ge)."""
    s0, c0, s1, c1, s2, c2 = ph
    k1 = _rhs_l(ts, y, PT, l, s0, c0, form)
    k2 = _rhs_l(tm, _t_axpy(y, hh, k1), PT, l, s1, c1, form)
    k3 = _rhs_l(tm, _t_axpy(y, hh, k2), PT, l, s1, c1, form)
    k4 = _rhs_l(te, _t_axpy(y, h, k3), PT, l, s2, c2, form)
    y1 = _t_comb(y, h6, k1, k2, k3, k4)
    return (y1, _events_l(ts, y, PT, l, s0, c0), _events_l(te, y1, PT, l, s2, c2),
            _events_l(te, _t_axpy(y, hd, k1), PT, l, s2, c2))


@nb.njit(inline="always", **_JIT)
def _lyap_fused_steps(form, i, nl, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L, PH, ACT, ROWS, EV,
                      FLAG, EL):
    """Grid step i of every lane of the block (see above). Z0, Z1: the state and the tangent
    vector (flat rows of BLOCK lanes, committed where the lane is active and unflagged); PH:
    the sin, cos at the step's start, middle and end (six rows); ROWS: each row's start and
    trial (six arrays: start +, -, state; trial +, -, state); EV: each row's events at the
    start, at the end and its graze flags (nine arrays); FLAG[l] = 1 where a row of lane l is
    flagged (an active lane), EL[l] its e. Returns the number of flagged lanes.

    Three passes over the lanes: the rows' starts; each row's trial (one lane loop per row,
    so the model's functions are inlined once, not once per row); the commit. Each row's
    arithmetic is that of a lone step."""
    YA, YB, YC, Y1A, Y1B, Y1C = ROWS
    G0A, G0B, G0C, G1A, G1B, G1C, GRA, GRB, GRC = EV
    P0, P1, P2, P3, P4, P5 = PH
    for l in range(nl):  # the rows' starts: the state and its neighbours z0 +- e S v
        z0 = _t_load(Z0, l)
        v = _t_load(Z1, l)
        e, ok = fd_size(fd_scale(_t_dot_scaled(z0, IS)), _t_dot(v))
        ya, yb = _t_fd_rows(z0, v, S, e, ok)
        _t_store(YA, l, ya, ya, True)
        _t_store(YB, l, yb, yb, True)
        _t_store(YC, l, z0, z0, True)
        EL[l] = e
        FLAG[l] = 0.0
    for r in range(3):  # each row's trial and screen
        Y = YA if r == 0 else (YB if r == 1 else YC)
        Y1 = Y1A if r == 0 else (Y1B if r == 1 else Y1C)
        G0 = G0A if r == 0 else (G0B if r == 1 else G0C)
        G1 = G1A if r == 0 else (G1B if r == 1 else G1C)
        GR = GRA if r == 0 else (GRB if r == 1 else GRC)
        for l in range(nl):
            y = _t_load(Y, l)
            h = HL[l]
            ts = T0L[l] + i * h
            hh = HHL[l]
            tm = ts + hh
            te = ts + h
            hd = te - ts
            ph = (P0[l], P1[l], P2[l], P3[l], P4[l], P5[l])
            y1, g0, g1, ge = _row_trial(form, y, PT, l, ts, tm, te, hh, h, H6L[l], hd, ph)
            hit = _t_screen_rows(g0, g1, ge, GR, l)
            _t_store(Y1, l, y1, y1, True)
            _t_store(G0, l, g0, g0, True)
            _t_store(G1, l, g1, g1, True)
            FLAG[l] = _pick(hit, 1.0, FLAG[l])
    n_flag = 0
    for l in range(nl):  # the commit of the active, unflagged lanes
        act = ACT[l]
        flagged = act & (FLAG[l] != 0.0)
        keep = act & (not flagged)
        v = _t_load(Z1, l)
        _t_store(Z1, l, _t_fd_tangent(_t_load(Y1A, l), _t_load(Y1B, l), EL[l], IS), v, keep)
        _t_store(Z0, l, _t_load(Y1C, l), _t_load(YC, l), keep)
        FLAG[l] = 1.0 if flagged else 0.0
        n_flag += 1 if flagged else 0
    return n_flag


def _t_screen_rows(g0, g1, ge, GR, l):
    """:func:`_rows_screen` of one row: its graze flags into GR[:, l]; True when flagged."""


def _ov_t_screen_rows(g0, g1, ge, GR, l):
    lines = ["hit = False"]
    for j in range(len(g0)):
        lines += [f"a = g0[{j}]",
                  f"graze, fl = screen_lone(g1[{j}], 1.0 if a > 0.0 else -1.0, a, ge[{j}])",
                  f"GR[{j * BLOCK} + l] = _pick(graze, 1.0, 0.0)", "hit = hit | fl"]
    return _tuple_source("g0, g1, ge, GR, l", [*lines, "return hit"],
                         {"_pick": _pick, "screen_lone": screen_lone})


if FUSED:
    nb.extending.overload(_t_screen_rows, inline="always")(_ov_t_screen_rows)


@nb.njit(_nrt=False, **_JIT, **INNER)
def _lyap_flagged(i, nl, first, P, Z0, Z1, IS, T0L, HL, OMEGA, NPL, ACT, ROWS, EV, FLAG, EL,
                  UNRR, PH, scratch):
    """The flagged lanes of step i out of line: each row whose trial is flagged finished on the
    scalar path (:func:`_split_step`), then the lane's commit and tangent vector from its rows
    (as :func:`_rows_commit` and :func:`_fd_combine`). PH: the lanes' phases of the step
    (start, middle, end), the start's and end's passed to the split."""
    ys, y1s, sides, g1s, ncross, W, gbuf = scratch
    ns = ys.size
    n_ev = g1s.size
    for l in range(nl):
        if FLAG[l] == 0.0:
            continue
        lane = first + l
        for r in range(3):
            Y, Y1 = ROWS[r], ROWS[3 + r]
            G0, G1, GR = EV[r], EV[3 + r], EV[6 + r]
            hit = False
            for j in range(n_ev):
                a = G0[j * BLOCK + l]
                hit = hit or _side(G1[j * BLOCK + l]) != _side(a) or GR[j * BLOCK + l] != 0.0
            if not hit:
                for q in range(ns):
                    Y[q * BLOCK + l] = Y1[q * BLOCK + l]
                continue
            for q in range(ns):
                ys[q] = Y[q * BLOCK + l]
                y1s[q] = Y1[q * BLOCK + l]
            for j in range(n_ev):
                sides[j] = _side(G0[j * BLOCK + l])
                g1s[j] = G1[j * BLOCK + l]
                gbuf[GRAZE_ROW, j] = GR[j * BLOCK + l]
            UNRR[r * BLOCK + l] += _split_step(i, T0L[l], ys, y1s, P[lane], HL[l], OMEGA[lane],
                                               NPL[l], PH[0][l], PH[1][l], PH[4][l], PH[5][l],
                                               sides, g1s, ncross, W, W[8], gbuf)
            for q in range(ns):
                Y[q * BLOCK + l] = ys[q]
        e = EL[l]
        for q in range(ns):
            Z1[q * BLOCK + l] = fd_tangent(ROWS[0][q * BLOCK + l], ROWS[1][q * BLOCK + l], e,
                                           IS[q])
        for q in range(ns):
            Z0[q * BLOCK + l] = ROWS[2][q * BLOCK + l]


@nb.njit(inline="always", **_JIT)
def _lyap_fused_run(form, first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                    lanes, rows, books, out, err, used, status, scratch):
    """The time loop of a fused Lyapunov block (see above): every grid step of the block's
    lanes, their flagged lanes out of line, their bookkeeping where due (:func:`_lane_books`)."""
    (Z0, Z1, ZT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, EL, UNRR) = lanes
    ROWS, EV = rows
    IST, ENDS, BLK, ACC, Zl, Cl, logs = books
    S_TAB, C_TAB = scratch[0], scratch[1]
    nv = _padded(nl)  # the fused loop's lanes: nl and idle ones (never active)
    for i in range(max_total):
        live = False
        for l in range(nl):
            live = live | ACT[l]
        if not live:
            break
        for l in range(nl):  # the phase gathers (scalar), apart: the fused loop reads rows
            j = IDX[l]
            for d in range(3):
                PH[2 * d][l] = S_TAB[j + d]
                PH[2 * d + 1][l] = C_TAB[j + d]
        n_flag = _lyap_fused_steps(form, i, nv, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L, PH, ACT,
                                   ROWS, EV, FLAG, EL)
        if n_flag > 0:
            _lyap_flagged(i, nl, first, P, Z0, Z1, IS, T0L, HL, OMEGA, NPL, ACT, ROWS, EV, FLAG,
                          EL, UNRR, PH, scratch[2:])
        for l in range(nl):  # the next step's phase index: 2 (i + 1 mod n_per) from the start
            IDX[l] = IDX[l] + 2 if IDX[l] + 2 < ENDL[l] else IDX[l] + 2 - 2 * NPL[l]
        step = i + 1
        if step >= due:
            due = _lane_books_core(step, first, nl, 1, renorm, bound, ZT, Zl, Cl, logs, IST,
                                   ENDS, BLK, ACC, ACT, ACTR, status)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_run_form1(first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT, lanes,
                    rows, books, out, err, used, status, scratch):
    """:func:`_lyap_fused_run` in the lane form FORM_QUIET (compiled on its own, noalias)."""
    _lyap_fused_run(FORM_QUIET, first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                    PT, lanes, rows, books, out, err, used, status, scratch)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_run_form2(first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT, lanes,
                    rows, books, out, err, used, status, scratch):
    """:func:`_lyap_fused_run` in the lane form FORM_LOAD."""
    _lyap_fused_run(FORM_LOAD, first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                    PT, lanes, rows, books, out, err, used, status, scratch)


@nb.njit(**_JIT, **INNER)
def _block_form(P, first, nl):
    """The lane form every lane of the block takes (``rhs_lane_form``), else FORM_GENERAL."""
    PTq = P.T
    form = _lane_form(PTq, first)
    for l in range(1, nl):
        if _lane_form(PTq, first + l) != form:
            return FORM_GENERAL
    return form


@optimise_once  # cold: optimised once where bound (see geardyn._bound_calls)
@nb.njit(**_JIT, **INNER)
def _fused_block_start(first, nl, k, P, Y0, S, T0, H, NPER, OFF, n_transient, n_steps,
                       renorm_every, n_blocks, out, err, used, status):
    """The start of a fused Lyapunov block of k tangent vectors (:func:`_lyap_block_fused`,
    k = 1; :func:`_lyap_block_var`; nl <= BLOCK lanes): the inverse scale IS, the state and
    tangent columns (ZT and its rows Z0, Z1: the state and the first tangent vector), the lanes'
    coefficients, clocks, phase-table indices and phases, the activity and flag columns, the
    lanes' books (:func:`_lanes_init`), the renormalisation interval and the first due step.
    Compiled on its own (not inlined in each worker: numba's compile time grows faster than a
    function's size), once for both fused blocks and every lane form (integer arguments
    int64, not literals)."""
    ns = Y0.shape[1]
    IS = np.empty(ns)
    for q in range(ns):
        IS[q] = 1.0 / S[q]
    ZT = np.zeros((k + 1, ns, BLOCK))
    Z0 = ZT[0].reshape(ns * BLOCK)
    Z1 = ZT[1].reshape(ns * BLOCK)
    PT = np.zeros((P.shape[1], BLOCK))
    T0L = np.zeros(BLOCK)
    HL = np.zeros(BLOCK)
    HHL = np.zeros(BLOCK)
    H6L = np.zeros(BLOCK)
    IDX = np.zeros(BLOCK, np.int64)
    NPL = np.ones(BLOCK, np.int64)
    ENDL = np.zeros(BLOCK, np.int64)
    PH6 = np.zeros((6, BLOCK))
    PH = (PH6[0], PH6[1], PH6[2], PH6[3], PH6[4], PH6[5])
    ACT = np.zeros(BLOCK, np.bool_)
    ACTR = np.zeros((2 * k + 1) * nl, np.bool_)  # (written by _lane_books; unused here)
    FLAG = np.zeros(BLOCK)
    IST, ENDS, BLK, ACC, Zl, Cl, logs, max_total = _lanes_init(first, nl, k, Y0, NPER,
                                                                n_transient, n_steps,
                                                                renorm_every, n_blocks, out,
                                                                err, used, status, ZT, ACT)
    for l in range(nl):
        _set_column(l, first + l, P, T0, H, NPER, OFF, PT, T0L, HL, HHL, H6L, NPL, IDX, ENDL)
    renorm = max(renorm_every, 1)
    due = max_total
    for l in range(nl):
        if ACT[l]:
            due = min(due, IST[l, _DUE])
    return (IS, ZT, Z0, Z1, PT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, IST, ENDS,
            BLK, ACC, Zl, Cl, logs, max_total, renorm, due)


@nb.njit(inline="always", **_JIT)
def _lyap_block_fused(form, first, nl, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps):
    """:func:`_lyap_block` with k = 1 in the fused loop of lane form ``form`` (FORM_QUIET or
    FORM_LOAD, a constant: one form compiled per caller; nl <= BLOCK lanes): the same
    results, bitwise."""
    ns = Y0.shape[1]
    (IS, ZT, Z0, Z1, PT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, IST, ENDS, BLK,
     ACC, Zl, Cl, logs, max_total, renorm, due) = _fused_block_start(
        np.int64(first), np.int64(nl), np.int64(1), P, Y0, S, T0, H, NPER, OFF, n_transient,
        n_steps, renorm_every, n_blocks, out, err, used, status)
    EL = np.zeros(BLOCK)
    UNRR = np.zeros(3 * BLOCK, np.int64)
    R6 = np.zeros((6, ns * BLOCK))
    ROWS = (R6[0], R6[1], R6[2], R6[3], R6[4], R6[5])
    E9 = np.zeros((9, max(n_ev, 1) * BLOCK))
    EV = (E9[0], E9[1], E9[2], E9[3], E9[4], E9[5], E9[6], E9[7], E9[8])
    ne = max(n_ev, 1)
    scratch = (S_TAB, C_TAB, np.zeros(ns), np.zeros(ns), np.ones(ne, np.int64), np.zeros(ne),
               np.zeros(ne, np.int64), np.zeros((9, ns)), np.zeros((GBUF_ROWS, ne)))
    lanes = (Z0, Z1, ZT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, EL, UNRR)
    books = (IST, ENDS, BLK, ACC, Zl, Cl, logs)
    if form == FORM_LOAD:
        _lyap_run_form2(first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                        lanes, (ROWS, EV), books, out, err, used, status, scratch)
    else:
        _lyap_run_form1(first, nl, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                        lanes, (ROWS, EV), books, out, err, used, status, scratch)
    for l in range(nl):  # the results of the lanes that ended well (deferred, see above)
        lane = first + l
        if status[lane] != STATUS_DIVERGED:
            _lane_result(l, lane, 1, IST[l, _NST], H[lane], ENDS, IST[l, _NBK], BLK, ACC, out,
                         err, used)
    for l in range(nl):
        lane = first + l
        u = UNRR[l] + UNRR[BLOCK + l] + UNRR[2 * BLOCK + l]
        unres[lane] = u
        fd_steps[lane] = IST[l, _LAST]  # the steps run (each by the difference rows)
        if u > 0 and status[lane] == STATUS_OK:
            status[lane] = STATUS_SPLIT_LIMIT




@nb.njit(**_JIT, **INNER)
def _lyap_block_form1(first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF, n_transient,
                      n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used, status, unres,
                      fd_steps):
    """:func:`_lyap_block_fused` in the lane form FORM_QUIET (k = 1)."""
    _lyap_block_fused(FORM_QUIET, first, nl, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps)


@nb.njit(**_JIT, **INNER)
def _lyap_block_form2(first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF, n_transient,
                      n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used, status, unres,
                      fd_steps):
    """:func:`_lyap_block_fused` in the lane form FORM_LOAD (k = 1)."""
    _lyap_block_fused(FORM_LOAD, first, nl, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps)


@nb.njit(inline="always", **_JIT)
def _lyap_block_local(form, lo, hi, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps):
    """:func:`_lyap_block` (``form`` FORM_GENERAL), or the fused loop of lane form ``form``
    (a constant), for lanes lo..hi-1 on copies of their inputs and outputs, so that
    the block's thread touches no shared array while it steps (the reference counts of arrays
    shared by threads would bounce between the cores' caches)."""
    n = hi - lo
    o = np.full((n, k), np.nan)
    e = np.full((n, k), np.nan)
    u = np.zeros(n, np.int64)
    st = np.zeros(n, np.int64)
    un = np.zeros(n, np.int64)
    fs = np.zeros(n, np.int64)
    Pb, Y0b, Sb, T0b = P[lo:hi].copy(), Y0[lo:hi].copy(), S.copy(), T0[lo:hi].copy()
    Hb, OMb, NPb, OFb = H[lo:hi].copy(), OMEGA[lo:hi].copy(), NPER[lo:hi].copy(), OFF[lo:hi].copy()
    STb, CTb = S_TAB.copy(), C_TAB.copy()
    NTb, NSb = n_transient[lo:hi].copy(), n_steps[lo:hi].copy()
    if form == FORM_QUIET:
        _lyap_block_form1(0, n, k, Pb, Y0b, Sb, T0b, Hb, OMb, NPb, STb, CTb, OFb, NTb, NSb,
                          renorm_every, bound, n_ev, n_blocks, o, e, u, st, un, fs)
    elif form == FORM_LOAD:
        _lyap_block_form2(0, n, k, Pb, Y0b, Sb, T0b, Hb, OMb, NPb, STb, CTb, OFb, NTb, NSb,
                          renorm_every, bound, n_ev, n_blocks, o, e, u, st, un, fs)
    elif form == PATH_ONE:
        _lyap_block_one(0, n, k, Pb, Y0b, Sb, T0b, Hb, OMb, NPb, STb, CTb, OFb, NTb, NSb,
                        renorm_every, bound, n_ev, n_blocks, o, e, u, st, un, fs)
    else:
        _lyap_block(0, n, k, Pb, Y0b, Sb, T0b, Hb, OMb, NPb, STb, CTb, OFb, NTb, NSb,
                    renorm_every, bound, n_ev, n_blocks, o, e, u, st, un, fs)
    for i in range(n):
        for j in range(k):
            out[lo + i, j] = o[i, j]
            err[lo + i, j] = e[i, j]
        used[lo + i] = u[i]
        status[lo + i] = st[i]
        unres[lo + i] = un[i]
        fd_steps[lo + i] = fs[i]


# ---------------------------------------------------------------------------------------------
# The variational block (a model with the tangent forms of its rhs: :data:`VARIATIONAL`):
# one loop over the block's lanes per grid step advances each lane's state and its tangent
# vector together, the RK4 stages of the pair (y, w = S v) from the lane-scalar tangent form
# ``rhs_lane_tangent`` (f and J w in one inlined call; :func:`_var_row_trial`), then screens the
# state's trial as the fused loop does and commits the unflagged lanes. A flagged lane (its state
# leaves a side of an edge or may graze one) is finished out of line, split with its tangent
# through the sub-steps (:func:`_var_split_lane`, as one lane's variational step does it; the
# difference rows where that is ill-posed). Each lane's arithmetic is
# that of one lane's variational step, operation for operation: the exponents are bitwise those
# of the lane stepped alone (the tests' reference). With k tangent vectors the loop's slots are
# pairs of a lane and one of its tangent vectors, so that a grid step is one pass of the loop over
# nl k slots (:func:`_lyap_var_run`).


def _t_scale(v, S):
    """(v_q S[q]), elementwise."""


def _ov_t_scale(v, S):
    return _tuple_source("v, S", ["return (" + "".join(f"S[{q}] * v[{q}], "
                                                       for q in range(len(v))) + ")"])


def _t_unscale(w, IS):
    """(w_q IS[q]), elementwise."""


def _ov_t_unscale(w, IS):
    return _tuple_source("w, IS", ["return (" + "".join(f"w[{q}] * IS[{q}], "
                                                        for q in range(len(w))) + ")"])


if VARIATIONAL:
    nb.extending.overload(_t_scale, inline="always")(_ov_t_scale)
    nb.extending.overload(_t_unscale, inline="always")(_ov_t_unscale)
    _rhs_lt = rhs_lane_tangent  # noqa: F821

    @nb.njit(inline="always", **_JIT)
    def _var_row_trial(form, y, w, PT, l, ts, tm, te, hh, h, h6, hd, ph):
        """One lane's variational RK4 trial (as :func:`_var_trial`) and its state's events at
        the start, the end and y + hd f (the graze predictor): (y1, w1, g0, g1, ge)."""
        s0, c0, s1, c1, s2, c2 = ph
        k1, q1 = _rhs_lt(ts, y, w, PT, l, s0, c0, form)
        k2, q2 = _rhs_lt(tm, _t_axpy(y, hh, k1), _t_axpy(w, hh, q1), PT, l, s1, c1, form)
        k3, q3 = _rhs_lt(tm, _t_axpy(y, hh, k2), _t_axpy(w, hh, q2), PT, l, s1, c1, form)
        k4, q4 = _rhs_lt(te, _t_axpy(y, h, k3), _t_axpy(w, h, q3), PT, l, s2, c2, form)
        y1 = _t_comb(y, h6, k1, k2, k3, k4)
        w1 = _t_comb(w, h6, q1, q2, q3, q4)
        return (y1, w1, _events_l(ts, y, PT, l, s0, c0), _events_l(te, y1, PT, l, s2, c2),
                _events_l(te, _t_axpy(y, hd, k1), PT, l, s2, c2))

    @nb.njit(inline="always", **_JIT)
    def _var_fused_steps(form, i, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L, PH,
                         IDX, ENDL, ACT, FLAG, GR, Y1F):
        """Grid step i of every lane of the block (see above): Z0, Z1 the state and a tangent
        vector (flat rows of BLOCK lanes), the tangent vector committed where the lane is
        active and its state's trial unflagged, the state too where ``commit`` (the last
        tangent vector of the step; ``locate``: the edges screened; GR: the graze flags, a row
        of BLOCK per switching function of the model); FLAG[l] = 1 where an active lane is
        flagged, the state's trial into Y1F (as Z0) for :func:`_var_flagged`. Returns the
        number of flagged lanes. PH: each lane's forcing phase at the step's start (sin, cos)
        and its increments (:func:`_var_phases`): the phases at the step's middle and end are
        the start's rotated (:func:`phase_rotate`), the period's end (IDX + 2 = ENDL) exactly
        (0, 1), as the lane's phase table has them, bitwise, without gathers from the tables;
        the end becomes the next step's start where ``commit``."""
        PS, PC, AH, BH, AD, BD = PH
        n_flag = 0
        for l in range(nl):
            y = _t_load(Z0, l)
            v = _t_load(Z1, l)
            h = HL[l]
            ts = T0L[l] + i * h
            hh = HHL[l]
            tm = ts + hh
            te = ts + h
            hd = te - ts
            s0 = PS[l]
            c0 = PC[l]
            s1, c1 = phase_rotate(s0, c0, AH[l], BH[l])
            s2, c2 = phase_rotate(s0, c0, AD[l], BD[l])
            end = IDX[l] + 2 == ENDL[l]  # the period's end, as in the table
            s2 = _pick(end, 0.0, s2)
            c2 = _pick(end, 1.0, c2)
            PS[l] = _pick(commit, s2, s0)
            PC[l] = _pick(commit, c2, c0)
            ph = (s0, c0, s1, c1, s2, c2)
            y1, w1, g0, g1, ge = _var_row_trial(form, y, _t_scale(v, S), PT, l, ts, tm, te, hh,
                                                h, H6L[l], hd, ph)
            hit = _t_screen_rows(g0, g1, ge, GR, l) & locate  # (no branch in the lane loop)
            act = ACT[l]
            flagged = act & hit
            keep = act & (not hit)
            _t_store(Z1, l, _t_unscale(w1, IS), v, keep)
            _t_store(Z0, l, y1, y, keep & commit)
            _t_store(Y1F, l, y1, y1, True)
            FLAG[l] = 1.0 if flagged else 0.0
            n_flag += 1 if flagged else 0
        return n_flag


@nb.njit(inline="always", **_JIT)
def _var_steps(form, i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L,
               PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL):
    """Grid steps i, i + 1, .. of every lane of the block (:func:`_var_fused_steps`, its
    arguments from nl on) up to the first with a flagged lane or step stop - 1, the phase
    indices IDX of lanes 0..n_adv-1 advanced after each step but that last one; returns that
    last step (its flagged lanes in FLAG). Steps stop - 1 at the latest: the caller's
    bookkeeping, due at step stop, and a lane's end change nothing here (ACT)."""
    j = i
    while True:
        n_flag = _var_fused_steps(form, j, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL,
                                  H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F)
        if n_flag > 0 or j + 1 >= stop:
            return j
        for l in range(n_adv):
            IDX[l] = IDX[l] + 2 if IDX[l] + 2 < ENDL[l] else IDX[l] + 2 - 2 * NPL[l]
        j += 1


@always_bind  # one copy for every time loop (see geardyn._bound_calls)
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _var_steps_form0(i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L,
                     PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL):
    """:func:`_var_steps` in the lane form FORM_GENERAL (compiled on its own, noalias)."""
    return _var_steps(FORM_GENERAL, i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L,
                      HL, HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL)


@always_bind  # one copy for every time loop (see geardyn._bound_calls)
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _var_steps_form1(i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L,
                     PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL):
    """:func:`_var_steps` in the lane form FORM_QUIET."""
    return _var_steps(FORM_QUIET, i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L,
                      HL, HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL)


@always_bind  # one copy for every time loop (see geardyn._bound_calls)
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _var_steps_form2(i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L,
                     PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL):
    """:func:`_var_steps` in the lane form FORM_LOAD."""
    return _var_steps(FORM_LOAD, i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L,
                      HL, HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL)


@nb.njit(inline="always", **_JIT)
def _var_steps_of(form, i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL, HHL,
                  H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL):
    """:func:`_var_steps` of lane form ``form`` (a constant), compiled on its own
    (:func:`_var_steps_form1`, ...): the time loops of one tangent vector and of a spectrum
    call the same compiled fused loop, and each time loop compiles apart from it (numba's
    compile time grows faster than a function's size)."""
    if form == FORM_QUIET:
        return _var_steps_form1(i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL,
                                HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL)
    if form == FORM_LOAD:
        return _var_steps_form2(i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL,
                                HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL)
    return _var_steps_form0(i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS, PT, T0L, HL,
                            HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F, NPL)


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing: no reference counting of its views
def _var_flagged(i, nl, first, n_ev, P, ZT, S, IS, T0L, HL, OMEGA, NPL, IDX, S_TAB, C_TAB,
                 FLAG, UNRR, FDL, GR, Y1F, fd):
    """The flagged lanes of step i (:func:`_var_fused_steps`: their states and tangent vectors
    in ZT[:, :, l] still at the step's start), each split with its tangent vectors through the
    sub-steps (:func:`_var_split_lane`; the split-limit steps of the difference rows it may
    fall back to into UNRR[l], such a step counted in FDL[l])."""
    Zl, YP, E, K, TMP, Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VX, VG = fd
    m, ns = Zl.shape
    for l in range(nl):
        if FLAG[l] == 0.0:
            continue
        lane = first + l
        for j in range(m):
            for q in range(ns):
                Zl[j, q] = ZT[j, q, l]
        off = IDX[l] - 2 * (i % NPL[l])  # the lane's phase table in S_TAB, C_TAB
        for r in range(UNRES.size):
            UNRES[r] = 0
        # the screen of the fused loop's trial (as one lane's variational step screens it)
        p = P[lane]
        h = HL[l]
        t = T0L[l] + i * h
        j0 = IDX[l]
        _events_i(t, Zl[0], G0[0], p, S_TAB[j0], C_TAB[j0])
        for j in range(n_ev):
            SIDE[0, j] = _side(G0[0, j])
            gbuf[GRAZE_ROW, j] = GR[j * BLOCK + l]
        for q in range(ns):
            VX[1, q] = Y1F[q * BLOCK + l]
        _events_i(t + h, VX[1], G1[0], p, S_TAB[j0 + 2], C_TAB[j0 + 2])
        fd_l = _var_split_lane(i, T0L[l], Zl, S, IS, P[lane], HL[l], OMEGA[lane], NPL[l],
                               S_TAB[off:], C_TAB[off:], n_ev, YP, E, K, TMP, Y1, SIDE, G0, G1,
                               W, gbuf, NCR, UNRES, VX, VG)
        for j in range(m):
            for q in range(ns):
                ZT[j, q, l] = Zl[j, q]
        UNRR[l] += UNRES.sum()
        FDL[l] += fd_l


#: :func:`_var_flagged` inlined into the k = 1 time loop (:func:`_lyap_var_run1`), not compiled
#: on its own (a function of its own is linked, and optimised once more, into each caller's
#: module: the time loop's and its worker's).
_var_flagged_inline = nb.njit(inline="always", _nrt=False, **_JIT)(_var_flagged.py_func)


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _var_load(ZT, Z1, nl, j_lo, kk):
    """Tangent vectors j_lo + 1 .. j_lo + kk of the block's lanes into the fused loop's slots:
    vector j_lo + 1 + jj of lane l (ZT[j_lo + 1 + jj, :, l]) at slot s = jj nl + l of the
    tangent row Z1, and the lane's state (ZT[0, :, l]) copied to slot s of the state row ZT[0]
    (slots 0..nl-1 are the lanes' own)."""
    ns = ZT.shape[1]
    for jj in range(kk):
        for q in range(ns):
            for l in range(nl):
                s = jj * nl + l
                Z1[q * BLOCK + s] = ZT[j_lo + 1 + jj, q, l]
                ZT[0, q, s] = ZT[0, q, l]


@nb.njit(_nrt=False, **_JIT, **INNER)  # it allocates nothing
def _var_store(ZT, Z1, nl, j_lo, kk):
    """The fused loop's slots back into tangent vectors j_lo + 1 .. j_lo + kk of the block's
    lanes (:func:`_var_load`)."""
    ns = ZT.shape[1]
    for jj in range(kk):
        for q in range(ns):
            for l in range(nl):
                ZT[j_lo + 1 + jj, q, l] = Z1[q * BLOCK + jj * nl + l]


@nb.njit(inline="always", **_JIT)
def _lyap_var_run(form, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                  lanes, books, out, err, used, status, scratch, fd):
    """The time loop of a variational block (see above): every grid step of the block's lanes,
    their flagged lanes out of line, their bookkeeping where due (:func:`_lane_books`). With k
    tangent vectors (ZT[1..k]) the fused loop's slots are pairs of a lane and one of its
    tangent vectors (slot jj nl + l: lane l with tangent vector j_lo + 1 + jj, its state
    copied there, :func:`_var_load`), kp = min(k, BLOCK // nl) vectors per pass, so that a
    lane's k vectors advance together in one pass (more passes only where nl k > BLOCK; the
    last commits the states): each slot computes its lane's state trial, the same operations,
    as one lane's RK4 step of the state and one tangent vector does. The slots' columns (PT,
    clocks, phases, ACT) are their lanes' (:func:`_lyap_block_var`)."""
    (Z0, Z1, ZT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, GR, UNRR, FDL,
     Y1F, ZX) = lanes
    k = ZT.shape[0] - 1
    kp = min(k, BLOCK // nl)
    n_pass = (k + kp - 1) // kp
    n_slot = nl * kp
    nv = _padded(n_slot)  # (a last pass of fewer vectors runs the others' slots idly again)
    IST, ENDS, BLK, ACC, Zl, Cl, logs = books
    S_TAB, C_TAB = scratch
    locate = n_ev > 0
    i = np.int64(0)  # (not a literal 0: one typing of the flagged lanes' split chain)
    while i < max_total:
        live = False
        for l in range(nl):
            live = live | ACT[l]
        if not live:
            break
        # one pass: the steps up to the next flagged one or bookkeeping in one call (each slot
        # steps its own copy of its lane's state, the same operations); several: one step
        stop = min(max_total, max(due, i + 1)) if n_pass == 1 else i + 1
        last = i
        for g in range(n_pass):  # one call site of the fused loop
            j_lo = g * kp
            kk = min(kp, k - j_lo)
            if k > 1:
                _var_load(ZT, ZX, nl, j_lo, kk)
            last = _var_steps_of(form, i, stop, n_slot, nv, locate, g == n_pass - 1, Z0, ZX,
                                 S, IS, PT, T0L, HL, HHL, H6L, PH, IDX, ENDL, ACT, FLAG, GR, Y1F,
                                 NPL)
            if k > 1:
                _var_store(ZT, ZX, nl, j_lo, kk)
        i = last
        n_flag = 0
        for l in range(nl):
            n_flag += 1 if FLAG[l] != 0.0 else 0
        if n_flag > 0:
            _var_flagged(i, nl, first, n_ev, P, ZT, S, IS, T0L, HL, OMEGA, NPL, IDX, S_TAB,
                         C_TAB, FLAG, UNRR, FDL, GR, Y1F, fd)
        for l in range(n_slot):
            IDX[l] = IDX[l] + 2 if IDX[l] + 2 < ENDL[l] else IDX[l] + 2 - 2 * NPL[l]
        step = i + 1
        if step >= due:
            due = _lane_books_core(step, first, nl, k, renorm, bound, ZT, Zl, Cl, logs, IST,
                                   ENDS, BLK, ACC, ACT, ACTR, status)
            for s in range(nl, n_slot):
                ACT[s] = ACT[s % nl]
        i = step


@nb.njit(inline="always", **_JIT)
def _lyap_var_run1(form, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                   lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run` with one tangent vector (k = 1): the lanes are the fused loop's
    slots, their tangent row ZT[1] itself, one call of the fused loop per grid step, the state
    committed with it (no passes, no slots of other tangent vectors)."""
    (Z0, Z1, ZT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, GR, UNRR, FDL,
     Y1F, ZX) = lanes
    IST, ENDS, BLK, ACC, Zl, Cl, logs = books
    S_TAB, C_TAB = scratch
    nv = _padded(nl)
    locate = n_ev > 0
    # np.int64: a literal 0 (the loop's index before type inference unifies it) would compile
    # the flagged lanes' split chain (_var_flagged .. _rows_step) once more
    i = np.int64(0)
    while i < max_total:
        live = False
        for l in range(nl):
            live = live | ACT[l]
        if not live:
            break
        # the steps up to the next flagged one or bookkeeping, in one call
        # (np.bool_: a literal True would compile the fused loop apart from the spectrum's)
        i = _var_steps_of(form, i, min(max_total, max(due, i + 1)), nl, nv, locate,
                          np.bool_(True), Z0, Z1, S, IS, PT, T0L, HL, HHL, H6L, PH, IDX, ENDL,
                          ACT, FLAG, GR, Y1F, NPL)
        n_flag = 0
        for l in range(nl):
            n_flag += 1 if FLAG[l] != 0.0 else 0
        if n_flag > 0:
            _var_flagged_inline(i, nl, first, n_ev, P, ZT, S, IS, T0L, HL, OMEGA, NPL, IDX, S_TAB,
                                C_TAB, FLAG, UNRR, FDL, GR, Y1F, fd)
        for l in range(nl):
            IDX[l] = IDX[l] + 2 if IDX[l] + 2 < ENDL[l] else IDX[l] + 2 - 2 * NPL[l]
        step = i + 1
        if step >= due:  # (inlined, on Z0 and Z1: no call of ~100 words at most steps)
            due = _lane_books_one(step, first, nl, renorm, bound, Z0, Z1, Zl, Cl, logs, IST,
                                  ENDS, BLK, ACC, ACT, status)
        i = step


@optimise_once  # its own code runs per flagged step or bookkeeping (see _bound_calls)
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_var1_form0(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                     lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run1` in the lane form FORM_GENERAL (a block of mixed forms)."""
    _lyap_var_run1(FORM_GENERAL, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H,
                   S, IS, PT, lanes, books, out, err, used, status, scratch, fd)


@optimise_once  # its own code runs per flagged step or bookkeeping (see _bound_calls)
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_var1_form1(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                     lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run1` in the lane form FORM_QUIET."""
    _lyap_var_run1(FORM_QUIET, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H,
                   S, IS, PT, lanes, books, out, err, used, status, scratch, fd)


@optimise_once  # its own code runs per flagged step or bookkeeping (see _bound_calls)
@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_var1_form2(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                     lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run1` in the lane form FORM_LOAD."""
    _lyap_var_run1(FORM_LOAD, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H,
                   S, IS, PT, lanes, books, out, err, used, status, scratch, fd)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_var_form0(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                    lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run` in the lane form FORM_GENERAL (a block of mixed forms)."""
    _lyap_var_run(FORM_GENERAL, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S,
                  IS, PT, lanes, books, out, err, used, status, scratch, fd)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_var_form1(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                    lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run` in the lane form FORM_QUIET."""
    _lyap_var_run(FORM_QUIET, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S,
                  IS, PT, lanes, books, out, err, used, status, scratch, fd)


@nb.njit(_nrt=False, **_JIT_NOALIAS, **INNER)
def _lyap_var_form2(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS, PT,
                    lanes, books, out, err, used, status, scratch, fd):
    """:func:`_lyap_var_run` in the lane form FORM_LOAD."""
    _lyap_var_run(FORM_LOAD, first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S,
                  IS, PT, lanes, books, out, err, used, status, scratch, fd)


@nb.njit(inline="always", **_JIT)
def _var_phases(n, IDX, NPL, S_TAB, C_TAB, PH):
    """The variational loop's phase rows PH (:func:`_var_fused_steps`) of slots 0..n-1 at their
    start (phase-table index IDX): sin and cos there, and the increments of half a grid step and
    of a whole one (:func:`phase_increments` of the slot's steps per period; zero where the
    tables are unforced, (0, 1) throughout, which the rotation keeps)."""
    PS, PC, AH, BH, AD, BD = PH
    for l in range(n):
        j = IDX[l]
        PS[l] = S_TAB[j]
        PC[l] = C_TAB[j]
        ah, bh, ad, bd = 0.0, 0.0, 0.0, 0.0
        if S_TAB[j + 1] != 0.0:  # a forced table (its half step is off zero)
            ah, bh, ad, bd = phase_increments(NPL[l])
        AH[l] = ah
        BH[l] = bh
        AD[l] = ad
        BD[l] = bd


#: The model's number of switching functions where its lane forms state it (a one form's
#: ``events_lane_count``, :func:`geardyn.core.one_form.adapters`), else None.
_N_SWITCHING = _events_l.py_func.__globals__.get("events_lane_count") if FUSED else None


# POINTER-HOOK: the pointer path (:mod:`._pointer_lyapunov`) replaces this definition
if _N_SWITCHING is None:
    @nb.njit(inline="always", **_JIT)
    def _n_switching(Z0, PT):
        """The model's number of switching functions (of its lane form's events)."""
        return len(_events_l(0.0, _t_load(Z0, 0), PT, 0, 0.0, 1.0))
else:
    @nb.njit(inline="always", **_JIT)
    def _n_switching(Z0, PT):
        """The model's number of switching functions (its lane forms' count: the events are
        not inlined here to count them)."""
        return np.int64(_N_SWITCHING)


@nb.njit(inline="always", **_JIT)
def _lyap_block_var(form, one, first, nl, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                    n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                    status, unres, fd_steps):
    """:func:`_lyap_block` (k tangent vectors) by the variational block of lane form ``form``
    (nl <= BLOCK lanes; ``one``: k = 1, a constant of each worker, so that a worker compiles
    the k = 1 time loop or the spectrum's, not both): per lane the exponents of the
    variational RK4 (tangent vectors through the split sub-steps); the lanes' steps by the
    difference rows (split steps where carrying the tangent through the sub-steps is
    ill-posed) into fd_steps[lane]."""
    ns = Y0.shape[1]
    (IS, ZT, Z0, Z1, PT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, IST, ENDS, BLK,
     ACC, Zl, Cl, logs, max_total, renorm, due) = _fused_block_start(
        np.int64(first), np.int64(nl), np.int64(k), P, Y0, S, T0, H, NPER, OFF, n_transient,
        n_steps, renorm_every, n_blocks, out, err, used, status)
    m, nr = k + 1, 2 * k + 1
    ne = max(n_ev, 1)
    UNRR = np.zeros(BLOCK, np.int64)
    FDL = np.zeros(BLOCK, np.int64)
    # the graze flags of every switching function of the model (screened even where n_ev = 0,
    # then ignored: no branch in the lane loop)
    GR = np.zeros(max(_n_switching(Z0, PT), 1) * BLOCK)
    # one lane's scratch (:func:`_var_flagged`): its state and tangent vectors, the 2 k + 1
    # difference rows (:func:`_tangent_step`), the split's VX and VG (:func:`_var_split`)
    fd = (np.zeros((m, ns)), np.zeros((nr, ns)), np.zeros(m), np.zeros((4, nr, ns)),
          np.zeros((nr, ns)), np.zeros((nr, ns)), np.ones((nr, ne), np.int64),
          np.zeros((nr, ne)), np.zeros((nr, ne)), np.zeros((9, ns)), np.zeros((GBUF_ROWS, ne)),
          np.zeros((nr, ne), np.int64), np.zeros(nr, np.int64), np.zeros((9 + 7 * k, ns)),
          np.zeros((3, ne)))
    Y1F = np.zeros(ns * BLOCK)  # the states' trials (flat rows of BLOCK slots, as Z0)
    # the slots' tangent row: ZT[1] itself where k = 1, else its own (:func:`_var_load`)
    ZX = Z1 if k == 1 else np.zeros(ns * BLOCK)
    for s in range(nl, nl * min(k, BLOCK // nl)):  # the slots of tangent vectors 2..: lane s % nl
        _set_column(s, first + s % nl, P, T0, H, NPER, OFF, PT, T0L, HL, HHL, H6L, NPL, IDX,
                    ENDL)
        ACT[s] = ACT[s % nl]
    _var_phases(nl * min(k, BLOCK // nl), IDX, NPL, S_TAB, C_TAB, PH)
    lanes = (Z0, Z1, ZT, T0L, HL, HHL, H6L, IDX, NPL, ENDL, PH, ACT, ACTR, FLAG, GR, UNRR, FDL,
             Y1F, ZX)
    books = (IST, ENDS, BLK, ACC, Zl, Cl, logs)
    scratch = (S_TAB, C_TAB)
    # the arguments written out at each call: a tuple of them unpacked by *args would add
    # numba's reference counting and unpacking of its ~50 arrays to the worker's IR
    if one:  # the k = 1 time loop: one fused-loop call per step, no passes
        if form == FORM_QUIET:
            _lyap_var1_form1(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                             PT, lanes, books, out, err, used, status, scratch, fd)
        elif form == FORM_LOAD:
            _lyap_var1_form2(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                             PT, lanes, books, out, err, used, status, scratch, fd)
        else:
            _lyap_var1_form0(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                             PT, lanes, books, out, err, used, status, scratch, fd)
    elif form == FORM_QUIET:
        _lyap_var_form1(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                        PT, lanes, books, out, err, used, status, scratch, fd)
    elif form == FORM_LOAD:
        _lyap_var_form2(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                        PT, lanes, books, out, err, used, status, scratch, fd)
    else:
        _lyap_var_form0(first, nl, n_ev, max_total, due, renorm, bound, P, OMEGA, H, S, IS,
                        PT, lanes, books, out, err, used, status, scratch, fd)
    for l in range(nl):
        lane = first + l
        if status[lane] != STATUS_DIVERGED:
            _lane_result(l, lane, k, IST[l, _NST], H[lane], ENDS, IST[l, _NBK], BLK, ACC, out,
                         err, used)
        unres[lane] = UNRR[l]
        fd_steps[lane] = FDL[l]
        if UNRR[l] > 0 and status[lane] == STATUS_OK:
            status[lane] = STATUS_SPLIT_LIMIT


@nb.njit(inline="always", **_JIT)
def _lyap_var_worker(b, n_blk, k, form, one, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                     n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                     status, unres, fd_steps):
    """Block b of n_blk of :func:`lyapunov_block_lanes` with ``variational`` (lanes lo..hi-1,
    :func:`_block_lanes`), on copies of its inputs and outputs (as :func:`_lyap_block_local`);
    ``form``: the lane form of the block (:func:`_block_form`), ``one``: k = 1, constants of
    each worker below, so that a worker compiles its form's fused loop and time loop alone."""
    lo, hi = _block_lanes(b, n_blk, Y0.shape[0])
    n = hi - lo
    if n <= 0:
        return
    o = np.full((n, k), np.nan)
    e = np.full((n, k), np.nan)
    u = np.zeros(n, np.int64)
    st = np.zeros(n, np.int64)
    un = np.zeros(n, np.int64)
    fs = np.zeros(n, np.int64)
    _lyap_block_var(form, one, 0, n, k, P[lo:hi].copy(), Y0[lo:hi].copy(), S.copy(),
                    T0[lo:hi].copy(), H[lo:hi].copy(), OMEGA[lo:hi].copy(), NPER[lo:hi].copy(),
                    S_TAB.copy(), C_TAB.copy(), OFF[lo:hi].copy(), n_transient[lo:hi].copy(),
                    n_steps[lo:hi].copy(), renorm_every, bound, n_ev, n_blocks, o, e, u, st, un,
                    fs)
    for i in range(n):
        for j in range(k):
            out[lo + i, j] = o[i, j]
            err[lo + i, j] = e[i, j]
        used[lo + i] = u[i]
        status[lo + i] = st[i]
        unres[lo + i] = un[i]
        fd_steps[lo + i] = fs[i]


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_var_worker_form0(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_var_worker` with k = 1 in the lane form FORM_GENERAL."""
    _lyap_var_worker(b, n_blk, k, FORM_GENERAL, True, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                     OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                     used, status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_var_worker_form1(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_var_worker` with k = 1 in the lane form FORM_QUIET."""
    _lyap_var_worker(b, n_blk, k, FORM_QUIET, True, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                     OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                     used, status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_var_worker_form2(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_var_worker` with k = 1 in the lane form FORM_LOAD."""
    _lyap_var_worker(b, n_blk, k, FORM_LOAD, True, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                     OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                     used, status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_spec_worker_form0(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_var_worker` with k > 1 tangent vectors in the lane form FORM_GENERAL."""
    _lyap_var_worker(b, n_blk, k, FORM_GENERAL, False, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                     OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                     used, status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_spec_worker_form1(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_var_worker` with k > 1 tangent vectors in the lane form FORM_QUIET."""
    _lyap_var_worker(b, n_blk, k, FORM_QUIET, False, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                     OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                     used, status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_spec_worker_form2(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_var_worker` with k > 1 tangent vectors in the lane form FORM_LOAD."""
    _lyap_var_worker(b, n_blk, k, FORM_LOAD, False, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                     OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                     used, status, unres, fd_steps)


#: The variational block workers by the lane form of their block, each compiled on its first
#: call.
_VAR_WORKERS = {FORM_GENERAL: _lyap_var_worker_form0, FORM_QUIET: _lyap_var_worker_form1,
                FORM_LOAD: _lyap_var_worker_form2}
#: The same for k > 1 tangent vectors (a spectrum).
_SPEC_WORKERS = {FORM_GENERAL: _lyap_spec_worker_form0, FORM_QUIET: _lyap_spec_worker_form1,
                 FORM_LOAD: _lyap_spec_worker_form2}


@nb.njit(**_JIT, **OUTER)
def _var_block_forms(P, n_blk):
    """The lane form of each block of :func:`lyapunov_block_lanes` (:func:`_block_form`)."""
    forms = np.full(n_blk, FORM_GENERAL, np.int64)
    for b in range(n_blk):
        lo, hi = _block_lanes(b, n_blk, P.shape[0])
        if hi > lo:
            forms[b] = _block_form(P, lo, hi - lo)
    return forms


def lyapunov_block_lanes(P, Y0, scale, T0, H, OMEGA, NPER, n_transient, n_steps, renorm_every, k,
                         bound, out, err, used, status, unres, n_ev=0, n_blocks=16,
                         block_rows=BLOCK_ROWS, min_blocks=1, variational=False, fd_steps=None):
    """The k leading exponents of every lane (row of P, Y0; NPER[lane] steps per period: lanes
    of different grids may share a block), the lanes' rows in blocks of at most ``block_rows``
    rows (2 k + 1 per lane, at least one lane), consecutive lanes in a block, blocks in
    parallel (threads, :func:`geardyn.solvers._parallel.run_workers`). Other arguments as in
    :func:`lyapunov_lanes`; fills out[L, k], err[L, k] (NaN where diverged), used[L] (blocks
    of the standard error), status[L] (STATUS_OK, STATUS_DIVERGED, or STATUS_SPLIT_LIMIT where
    a step of any of the lane's rows reached the split limit, the exponents kept) and unres[L]
    (such steps). Each lane's result is bitwise that of the lane stepped alone, whatever the
    lanes beside it, ``block_rows`` and ``min_blocks`` (see :func:`_block_count`).
    ``variational`` (a model with :data:`VARIATIONAL`): the tangent vectors by the variational
    block. ``fd_steps[L]``, where given: the grid steps each lane took by the difference rows
    (every step it ran, or with ``variational`` the split steps where carrying the tangent
    through the sub-steps is ill-posed)."""
    if variational and not VARIATIONAL:
        raise ValueError("the variational tangent needs a model with the tangent forms of its "
                         "rhs (a one-form model)")
    # writable contiguous copies and int64 casts: a read-only array or another integer type
    # would compile the block kernel once more for each such caller
    i64 = np.int64
    P_w, Y0_w = np.array(P, float, order="C"), np.array(Y0, float, order="C")
    scale_w = np.array(scale, float, order="C")
    S_TAB, C_TAB, OFF, n_blk = _block_tables(OMEGA, NPER, i64(k), i64(block_rows),
                                             i64(min_blocks))
    args = (i64(n_blk), i64(k), P_w, Y0_w, scale_w, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
            n_transient, n_steps, renorm_every, bound, i64(n_ev), i64(n_blocks), out, err, used,
            status, unres)
    fds = np.zeros(P_w.shape[0], np.int64) if fd_steps is None else fd_steps
    if variational:
        forms = _var_block_forms(P_w, i64(n_blk))
        workers = _VAR_WORKERS if k == 1 else _SPEC_WORKERS

        def var_block(b, *rest):
            workers[int(forms[b])](b, *rest, fds)

        run_workers(var_block, int(n_blk), args)
        return
    paths = _block_paths(P_w, n_blk, i64(k), i64(n_ev))

    def block(b, *args):
        _BLOCK_WORKERS[int(paths[b])](b, *args, fds)

    run_workers(block, int(n_blk), args)


@nb.njit(inline="always", **_JIT)
def _block_lanes(b, n_blk, L):
    """Lanes lo..hi-1 of block b of n_blk (b L // n_blk to (b + 1) L // n_blk)."""
    return np.int64(b * L // n_blk), np.int64((b + 1) * L // n_blk)


@nb.njit(**_JIT, **OUTER)
def _block_paths(P, n_blk, k, n_ev):
    """The path of each block of :func:`lyapunov_block_lanes`: the fused loop of the lane form
    its lanes all take (FORM_QUIET, FORM_LOAD: a model with lane-scalar functions, k = 1,
    switching functions, at most BLOCK lanes), else PATH_ONE (one lane of fewer rows than
    ROW_PAD, :func:`_lyap_block_one`) or FORM_GENERAL (the row block, :func:`_lyap_block`)."""
    paths = np.full(n_blk, FORM_GENERAL, np.int64)
    for b in range(n_blk):
        lo, hi = _block_lanes(b, n_blk, P.shape[0])
        if hi - lo == 1 and (ROW_PAD == 1 or 2 * k + 1 < ROW_PAD):
            paths[b] = PATH_ONE
    if not FUSED:
        return paths
    for b in range(n_blk):
        lo, hi = _block_lanes(b, n_blk, P.shape[0])
        if k == 1 and n_ev > 0 and 0 < hi - lo <= BLOCK:
            form = _block_form(P, lo, hi - lo)
            if form == FORM_QUIET or form == FORM_LOAD:
                paths[b] = form
    return paths


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_block_worker(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF, n_transient,
                       n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used, status,
                       unres, fd_steps):
    """Block b of n_blk of :func:`lyapunov_block_lanes` (:func:`_block_lanes`) through the row
    block (:func:`_lyap_block_local`)."""
    lo, hi = _block_lanes(b, n_blk, Y0.shape[0])
    if hi > lo:
        _lyap_block_local(FORM_GENERAL, lo, hi, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB,
                          OFF, n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out,
                          err, used, status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_block_worker_form1(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                             n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                             used, status, unres, fd_steps):
    """:func:`_lyap_block_worker` through the fused loop in the lane form FORM_QUIET."""
    lo, hi = _block_lanes(b, n_blk, Y0.shape[0])
    _lyap_block_local(FORM_QUIET, lo, hi, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_block_worker_form2(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                             n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                             used, status, unres, fd_steps):
    """:func:`_lyap_block_worker` through the fused loop in the lane form FORM_LOAD."""
    lo, hi = _block_lanes(b, n_blk, Y0.shape[0])
    _lyap_block_local(FORM_LOAD, lo, hi, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps)


@nb.njit(nogil=True, **_JIT, **OUTER)
def _lyap_block_worker_one(b, n_blk, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                           n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err,
                           used, status, unres, fd_steps):
    """:func:`_lyap_block_worker` for a block of one lane of few rows (PATH_ONE)."""
    lo, hi = _block_lanes(b, n_blk, Y0.shape[0])
    _lyap_block_local(PATH_ONE, lo, hi, k, P, Y0, S, T0, H, OMEGA, NPER, S_TAB, C_TAB, OFF,
                      n_transient, n_steps, renorm_every, bound, n_ev, n_blocks, out, err, used,
                      status, unres, fd_steps)


#: The Lyapunov block workers by path (:func:`_block_paths`), each compiled on its first call.
_BLOCK_WORKERS = {FORM_GENERAL: _lyap_block_worker, FORM_QUIET: _lyap_block_worker_form1,
                  FORM_LOAD: _lyap_block_worker_form2, PATH_ONE: _lyap_block_worker_one}


def lyapunov_lanes(P, Y0, scale, T0, H, OMEGA, n_per, n_transient, n_steps, renorm_every, bound,
                   out, err, n_ev=0, n_blocks=16, unresolved=None, status=None,
                   variational=False, fd_steps=None):
    """Largest exponent of every lane (row of P, Y0), the lanes in blocks in parallel
    (:func:`lyapunov_block_lanes` with k = 1, lanes ordered by their step count so that a
    block's lanes end together; bitwise each lane stepped alone, as the tests' one-lane
    reference, ``tests/_lyapunov_rows.py``, shows).

    scale: the state scale (one vector for all lanes); T0: start time (forcing phase zero
    there) per lane; H, OMEGA: step and forcing frequency per lane; n_per: steps per period,
    one for all lanes or one per lane; n_transient, n_steps: per-lane step counts (int arrays);
    n_ev: the model's number of switching functions located inside a step (0: none); n_blocks:
    the blocks of the measuring window for the standard error. Fills out[L] and err[L] (the
    standard error; NaN for diverged lanes) and, where given, unresolved[L], status[L] and
    fd_steps[L] (see :func:`lyapunov_block_lanes`). ``variational``: the tangent vectors by
    the variational block.
    """
    L = Y0.shape[0]
    nper = np.ascontiguousarray(np.broadcast_to(np.asarray(n_per, np.int64), (L,)))
    order = np.argsort(np.asarray(n_transient) + np.asarray(n_steps), kind="stable")
    o2 = np.full((L, 1), np.nan)
    e2 = np.full((L, 1), np.nan)
    used = np.zeros(L, np.int64)
    st2 = np.zeros(L, np.int64)
    un2 = np.zeros(L, np.int64)
    fd2 = np.zeros(L, np.int64)
    if L > 0:
        p_, y_, t_, h_, w_, n_, tr_, st_ = (
            np.ascontiguousarray(np.asarray(a)[order])
            for a in (P, Y0, T0, H, OMEGA, nper, n_transient, n_steps))
        lyapunov_block_lanes(p_, y_, scale, t_, h_, w_, n_, tr_, st_, renorm_every, 1, bound, o2,
                             e2, used, st2, un2, n_ev, n_blocks, BLOCK_ROWS, nb.get_num_threads(),
                             variational, fd2)
    ok = st2 != STATUS_DIVERGED
    out[order] = np.where(ok, o2[:, 0], np.nan)
    err[order] = np.where(ok, e2[:, 0], np.nan)
    if unresolved is not None:
        unresolved[order] = un2
    if status is not None:
        status[order] = st2
    if fd_steps is not None:
        fd_steps[order] = fd2
