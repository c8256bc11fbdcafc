"""The variational tangent (dual numbers through a one-form model's rhs: the exact derivative of
the RK4 step map; a split step's tangent through the state's sub-steps, corrected at each split
point) against an independent computation: scipy's DOP853 of the gear pair's and the reduced CATT
device's state and variational equations (their Jacobians written by hand, every edge crossing
ended and restarted, rtol 1e-10), and against the finite-difference rows of the same kernel."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from _lyapunov_rows import one_lane, reference_for, rows_for
from geardyn.solvers.kernels import kernels_for

#: A period-1 orbit with contact loss (two crossings per period), and a chaotic one.
IMPACTING = dict(zeta=0.1, kappa=0.2, Fm=0.1, Fa=0.15, Omega=1.15)
CHAOTIC = dict(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3, Omega=0.92)


def _gear_pair_reference(pars, y0, v0, t_marks, b=1.0):
    """|v| at the times ``t_marks`` of the tangent v of the gear pair's variational equation
    v' = J(t, y) v along y' = f(t, y) from (y0, v0) at t = 0 (DOP853, rtol 1e-10; each segment
    between edge crossings integrated with the contact region fixed, so that f is smooth on it;
    v renormalised at each mark, the log stretches returned)."""
    zeta, kappa, fm, fa, om = (pars[k] for k in ("zeta", "kappa", "Fm", "Fa", "Omega"))

    def fun(t, u, reg):
        x, xd, w0, w1 = u
        g = (x - b) if reg == 1 else ((x + b) if reg == -1 else 0.0)
        gp = 1.0 if reg else 0.0
        k = 1.0 + kappa * math.cos(om * t)
        return [xd, fm + fa * om * om * math.cos(om * t) - 2 * zeta * xd - k * g,
                w1, -k * gp * w0 - 2 * zeta * w1]

    def edge(sign, direction):
        def ev(t, u, reg):
            return u[0] - sign * b
        ev.terminal = True
        ev.direction = direction
        return ev

    # the edges a region can be left by, and the region entered there
    leave = {0: [(edge(1.0, 1.0), 1), (edge(-1.0, -1.0), -1)], 1: [(edge(1.0, -1.0), 0)],
             -1: [(edge(-1.0, 1.0), 0)]}
    t = 0.0
    u = np.concatenate([y0, v0 / np.linalg.norm(v0)])
    x = u[0]
    reg = 1 if x > b else (-1 if x < -b else 0)
    logs = []
    for mark in t_marks:
        while t < mark:
            evs = leave[reg]
            sol = solve_ivp(fun, (t, mark), u, method="DOP853", rtol=1e-10, atol=1e-12,
                            args=(reg,), events=[e for e, _ in evs])
            t, u = sol.t[-1], sol.y[:, -1].copy()
            if sol.status == 1:
                hit = [j for j, te in enumerate(sol.t_events) if te.size]
                reg = evs[hit[0]][1]
        nv = np.linalg.norm(u[2:])
        logs.append(math.log(nv))
        u[2:] /= nv
    return np.array(logs)


def _kernel_exponent(model, n_per, n_tr_periods, n_periods, variational):
    kern = kernels_for(model.kernel, "lyapunov")
    om = model.params[model.omega_index]
    h = 2 * math.pi / om / n_per
    out = one_lane(kern, model.params, model.initial_state(), np.ones(2), 0.0, h, om, n_per,
                   n_tr_periods * n_per, n_periods * n_per, 10, 1, 1e6, 2, 16, variational)
    return out


#: (parameters, transient and measured forcing periods, {steps per period: tolerance}): the
#: difference rows' distance to the reference measured 1.67e-8 and 2.9e-9 (impacting, 128 and
#: 256 steps), 2.65e-6 and 1.36e-7 (chaotic, a short window: 256 and 512 steps); the variational
#: tangent's 2.0e-9 and 1.2e-10 (impacting), 2.65e-6 and 1.35e-7 (chaotic: the state's error).
CASES = {"impacting": (IMPACTING, 10, 40, {128: 5e-8, 256: 1e-8}),
         "chaotic": (CHAOTIC, 2, 10, {256: 8e-6, 512: 5e-7})}


@pytest.mark.parametrize("case", CASES)
def test_gear_pair_exponent_against_dop853_variational_equations(case):
    """The finite-time exponent of the same trajectory and start vector (e_1 + 0.1 (1, 1),
    normalised, as the kernel starts it) over the same window: both tangents within RK4's error
    of the DOP853 reference, and within it of each other (two methods); no step of the
    variational kernel fell back to the difference rows."""
    pars, n_tr, n_m, tols = CASES[case]
    model = geardyn.GearPair(**pars)
    T = model.period
    logs = _gear_pair_reference(pars, model.initial_state(), np.array([1.1, 0.1]),
                                [n_tr * T, (n_tr + n_m) * T])
    ref = logs[1] / (n_m * T)
    for n_per, tol in tols.items():
        var = _kernel_exponent(model, n_per, n_tr, n_m, True)
        fd = _kernel_exponent(model, n_per, n_tr, n_m, False)
        assert var[3] == 0 and fd[3] == 0  # status OK
        assert var[5] == 0  # split steps by the sub-steps' tangent, none by the rows
        assert fd[5] == (n_tr + n_m) * n_per
        lam_v, lam_f = var[0][0], fd[0][0]
        assert abs(lam_v - ref) < tol, (n_per, lam_v, ref)
        assert abs(lam_f - ref) < tol, (n_per, lam_f, ref)
        assert lam_v != lam_f
        assert abs(lam_v - lam_f) < tol


def _catt_reference(model, y0, v0, t_marks):
    """:func:`_gear_pair_reference` for the reduced CATT device (one stiffness harmonic per
    mesh, no load fluctuation): the state and the variational equation of Eq. (10) for one
    planet set, its Jacobian by hand, each segment between edge crossings with the contact
    regions of the two meshes (sun-inside X_sq, inside-outside X_pq) fixed."""
    P = dict(zip(model.kernel.one_form.coefficients, model.params, strict=True))
    assert P["f_c1"] == 0.0 and P["f_p1"] == 0.0 and P["n_harmonics"] == 1.0
    om, bs, bp = P["Omega"], P["b_sq"], P["b_pq"]

    def dead(x, r, b):
        return (x - b) if r == 1 else ((x + b) if r == -1 else 0.0)

    def accel(gs, vs, gp, vp):
        f_sq = P["k_sq_q"] * gs + P["c_sq_q"] * vs
        f_pq = P["k_pq_q"] * gp + P["c_pq_q"] * vp
        f_pp = P["k_pq_p"] * gp + P["c_pq_p"] * vp
        carrier = P["k_sq_c"] * gs + P["c_sq_c"] * vs
        return -f_sq + f_pq - carrier, f_sq - f_pq - f_pp

    def fun(t, u, rs, rp):
        xs, vs, xp, vp, w0, w1, w2, w3 = u
        s, c = math.sin(om * t), math.cos(om * t)
        ks = 1.0 + P["ksq_a1"] * c + P["ksq_b1"] * s  # positive: no clip
        kp = 1.0 + P["kpq_a1"] * c + P["kpq_b1"] * s
        a1, a3 = accel(ks * dead(xs, rs, bs), vs, kp * dead(xp, rp, bp), vp)
        j1, j3 = accel(ks * abs(rs) * w0, w1, kp * abs(rp) * w2, w3)
        om2 = om * om
        return [vs, a1 + om2 * (P["E_sq_s"] * s + P["E_sq_c"] * c) + P["f_c0"],
                vp, a3 + P["f_p0"] + om2 * (P["E_pq_s"] * s + P["E_pq_c"] * c), w1, j1, w3, j3]

    def region(x, b):
        return 1 if x > b else (-1 if x < -b else 0)

    def leave(q, r, b):
        """(event, region entered) by which the state q leaves its region r."""
        def edge(level, direction):
            def ev(t, u, rs, rp):
                return u[q] - level
            ev.terminal = True
            ev.direction = direction
            return ev
        if r == 0:
            return [(edge(b, 1.0), 1), (edge(-b, -1.0), -1)]
        return [(edge(r * b, -float(r)), 0)]

    t = 0.0
    u = np.concatenate([y0, v0 / np.linalg.norm(v0)])
    rs, rp = region(u[0], bs), region(u[2], bp)
    logs = []
    for mark in t_marks:
        while t < mark:
            evs = ([(e, 0, r) for e, r in leave(0, rs, bs)]
                   + [(e, 2, r) for e, r in leave(2, rp, bp)])
            sol = solve_ivp(fun, (t, mark), u, method="DOP853", rtol=1e-10, atol=1e-12,
                            args=(rs, rp), events=[e for e, _, _ in evs])
            t, u = sol.t[-1], sol.y[:, -1].copy()
            if sol.status == 1:
                _, q, r = evs[next(j for j, te in enumerate(sol.t_events) if te.size)]
                rs, rp = (r, rp) if q == 0 else (rs, r)
        nv = np.linalg.norm(u[4:])
        logs.append(math.log(nv))
        u[4:] /= nv
    return np.array(logs)


def _errors(model, reference, v0, n_tr, n_m, steps):
    """|exponent - reference| of the variational tangent and of the difference rows at each
    number of steps per period, and the variational kernel's difference-row steps."""
    T = model.period
    ref = reference(model.initial_state(), v0, [n_tr * T, (n_tr + n_m) * T])[1] / (n_m * T)
    kern = kernels_for(model.kernel, "lyapunov")
    om = model.params[model.omega_index]
    out = {}
    for n_per in steps:
        h = 2 * math.pi / om / n_per
        res = [one_lane(kern, model.params, model.initial_state(), np.ones(model.n_states), 0.0,
                        h, om, n_per, n_tr * n_per, n_m * n_per, 10, 1, 1e6, model.n_events, 16,
                        var)
               for var in (True, False)]
        assert res[0][3] == 0 and res[1][3] == 0
        out[n_per] = (abs(res[0][0][0] - ref), abs(res[1][0][0] - ref), res[0][5])
    return out


def _device(omega):
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)).with_params(
        Omega=omega)


#: Impacting orbits whose split steps carry the exponent's error (measured |exponent - DOP853| at
#: 128 and 256 steps per period, variational / difference rows): the gear pair 2.0e-9, 1.2e-10 /
#: 1.67e-8, 2.9e-9; the reduced paper device at Omega 1.0 5.5e-8, 3.0e-9 / 2.0e-7, 2.8e-8, at
#: Omega 3.0 1.3e-9, 5.3e-11 / 8.1e-9, 6.4e-10. The tangent carried through the sub-steps
#: without the correction at the split points is O(h^3) (gear pair 2.9e-7, 3.3e-8: ratio 8.8).
ORDER_CASES = {
    "gear pair": (lambda: geardyn.GearPair(**IMPACTING), np.array([1.1, 0.1]), 10, 40),
    "device 1.0": (lambda: _device(1.0), np.array([1.1, 0.1, 0.1, 0.1]), 10, 40),
    "device 3.0": (lambda: _device(3.0), np.array([1.1, 0.1, 0.1, 0.1]), 10, 40),
}


@pytest.mark.parametrize("case", ORDER_CASES)
def test_split_step_tangent_is_fourth_order(case):
    """The finite-time exponent's error against DOP853 of the state and variational equations
    falls at RK4's order through the split steps (128 -> 256 steps per period: by >= 10, 16 for
    4th order, 8 for 3rd) and lies below the difference rows' (each row split at its own
    crossing) at both; no step fell back to the difference rows."""
    make, v0, n_tr, n_m = ORDER_CASES[case]
    model = make()
    if isinstance(model, geardyn.GearPair):
        pars = dict(IMPACTING)

        def reference(y0, v, marks):
            return _gear_pair_reference(pars, y0, v, marks)
    else:
        def reference(y0, v, marks):
            return _catt_reference(model, y0, v, marks)
    err = _errors(model, reference, v0, n_tr, n_m, (128, 256))
    (v128, r128, f128), (v256, r256, f256) = err[128], err[256]
    assert f128 == 0 and f256 == 0
    assert v128 / v256 >= 10.0, err
    assert v128 < r128 and v256 < r256, err


def _lanes(model, oms, n_per, n_tr, n_st, variational, rows=False, n_ev=None):
    kern = kernels_for(model.kernel, "lyapunov")
    L = oms.size
    P = np.ascontiguousarray(model.lane_params("Omega", oms))
    H = 2 * np.pi / oms / n_per
    Y0 = np.ascontiguousarray(np.tile(model.initial_state(), (L, 1)))
    out, err = np.full(L, np.nan), np.full(L, np.nan)
    un, st, fd = (np.zeros(L, np.int64) for _ in range(3))
    fn = rows_for(kern) if rows else kern.lyapunov_lanes
    fn(P, Y0, np.ones(model.n_states), np.zeros(L), H, oms, np.full(L, n_per, np.int64),
       np.full(L, n_tr, np.int64), np.asarray(n_st, np.int64), 10, 1e6, out, err,
       model.n_events if n_ev is None else n_ev, 16, un, st, variational, fd)
    return P, Y0, H, out, err, un, st, fd


_STATES_SOURCE = """
@nb.njit(error_model="numpy", boundscheck=False)
def states(p, y0, h, omega, n_per, n_steps, n_ev):
    ns = y0.size
    ne = max(n_ev, 1)
    s_tab, c_tab = phase_table(n_per, omega != 0.0)
    Z = np.zeros((2, ns))
    R = np.zeros((2, ns))
    for q in range(ns):
        Z[0, q] = y0[q]
        R[0, q] = y0[q]
        Z[1, q] = 0.1 + (1.0 if q == 0 else 0.0)
        R[1, q] = Z[1, q]
    S = np.ones(ns)
    scratch = [(np.zeros((3, ns)), np.zeros(2), np.zeros((4, 3, ns)), np.zeros((3, ns)),
                np.zeros((3, ns)), np.ones((3, ne), np.int64), np.zeros((3, ne)),
                np.zeros((3, ne)), np.zeros((9, ns)), np.zeros((GBUF_ROWS, ne)),
                np.zeros((3, ne), np.int64), np.zeros(3, np.int64)) for _ in range(2)]
    VW = np.zeros((12, ns))
    VX = np.zeros((16, ns))
    VG = np.zeros((3, ne))
    YP, E, K, TMP, Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES = scratch[0]
    YPr, Er, Kr, TMPr, Y1r, SIDEr, G0r, G1r, Wr, gbufr, NCRr, UNRESr = scratch[1]
    apart = 0
    fd = 0
    for i in range(n_steps):
        fd += _var_step(i, 0.0, Z, S, S, p, h, omega, n_per, s_tab, c_tab, n_ev, YP, E, K, TMP,
                        Y1, SIDE, G0, G1, W, gbuf, NCR, UNRES, VW, VX, VG)
        _tangent_step(i, 0.0, R, S, S, p, h, omega, n_per, s_tab, c_tab, n_ev, YPr, Er, Kr,
                      TMPr, Y1r, SIDEr, G0r, G1r, Wr, gbufr, NCRr, UNRESr)
        for q in range(ns):
            if Z[0, q] != R[0, q]:
                apart += 1
                break
    return apart, NCR[0].sum(), NCRr[2].sum(), fd
"""


@pytest.mark.parametrize("case", ["gear pair", "device 1.0"])
def test_split_tangent_leaves_the_state_bitwise_the_rows(case):
    """The variational step (the state split as every kernel splits it, the tangent carried
    through the sub-steps) and the difference rows' state row give the same states, bitwise,
    at every grid step of a run with edge crossings."""
    model = ORDER_CASES[case][0]()
    kern = kernels_for(model.kernel, "lyapunov")
    env = {"nb": nb, "np": np}
    env.update({n: getattr(kern, n) for n in ("_tangent_step", "phase_table", "GBUF_ROWS")})
    env["_var_step"] = reference_for(kern)._var_step
    exec(compile(_STATES_SOURCE, "<split tangent states>", "exec"), env)
    om = model.params[model.omega_index]
    n_per = 64
    apart, crossings, crossings_rows, fd = env["states"](
        np.ascontiguousarray(model.params), model.initial_state(), 2 * math.pi / om / n_per, om,
        n_per, 30 * n_per, model.n_events)
    assert apart == 0 and fd == 0
    assert crossings == crossings_rows > 30


def test_variational_lanes_are_bitwise_the_one_lane_kernel():
    """The variational block (lanes of different lengths and grids side by side) and the
    one-lane-at-a-time rows give each lane's exponent, error, counts and status of
    ``lyapunov_single`` with ``variational``, bitwise."""
    model = geardyn.GearPair(**IMPACTING)
    oms = np.array([0.8, 1.15, 1.5, 0.92, 2.0])
    n_per, n_tr = 64, 10 * 64
    n_st = np.array([30, 40, 25, 35, 20]) * n_per
    P, Y0, H, out, err, un, st, fd = _lanes(model, oms, n_per, n_tr, n_st, True)
    rows = _lanes(model, oms, n_per, n_tr, n_st, True, rows=True)
    ref = reference_for(kernels_for(model.kernel, "lyapunov"))
    for lane in range(oms.size):
        ex, er, _, status, unres, n_fd = ref.lyapunov_single(
            P[lane].copy(), Y0[lane].copy(), np.ones(2), 0.0, H[lane], oms[lane], n_per, n_tr,
            int(n_st[lane]), 10, 1, 1e6, 2, 16, True)
        got = (out[lane], err[lane], un[lane], st[lane], fd[lane])
        assert got == (ex[0], er[0], unres, status, n_fd), lane
        assert tuple(a[lane] for a in rows[3:]) == got, lane
    assert np.all(fd == 0) and np.all(np.isfinite(out))
    # without edge location (n_ev = 0: no screen, no split) too
    P, Y0, H, out0, err0, un0, st0, fd0 = _lanes(model, oms, n_per, n_tr, n_st, True, n_ev=0)
    for lane in range(oms.size):
        ex, er, _, status, unres, n_fd = ref.lyapunov_single(
            P[lane].copy(), Y0[lane].copy(), np.ones(2), 0.0, H[lane], oms[lane], n_per, n_tr,
            int(n_st[lane]), 10, 1, 1e6, 0, 16, True)
        assert (out0[lane], err0[lane], un0[lane], st0[lane], fd0[lane]) == (
            ex[0], er[0], unres, status, n_fd) == (ex[0], er[0], 0, 0, 0), lane
    # the difference rows through the same blocks: another method, close (at 64 steps per
    # period the rows' error, 3.9e-7 against DOP853 in the impacting case, 3.4e-8 the
    # variational tangent's)
    diff = _lanes(model, oms, n_per, n_tr, n_st, False)
    np.testing.assert_allclose(out, diff[3], rtol=0, atol=2e-6)
    assert not np.array_equal(out, diff[3])


def test_tangent_setting_through_the_public_functions():
    g = geardyn.GearPair(**IMPACTING)
    run = geardyn.RunSettings(transient=50.0, steps_per_period=64)
    var = geardyn.LyapunovSettings(duration=200.0, tangent="variational")
    diff = var.replace(tangent="difference")
    auto = var.replace(tangent="auto")
    ev = geardyn.lyapunov(g, run=run, settings=var, with_error=True)
    ed = geardyn.lyapunov(g, run=run, settings=diff, with_error=True)
    assert ev.tangent.startswith("variational") and ed.tangent.startswith("difference")
    assert ev.difference_steps == 0 < ed.difference_steps
    assert abs(ev.value - ed.value) < 1e-6 and ev.value != ed.value  # the rows' error
    assert geardyn.lyapunov(g, run=run, settings=auto) == ev.value
    P = g.lane_params("Omega", [1.15, 1.3])
    lanes = geardyn.lyapunov_lanes(g, P, run=run, settings=var)
    assert lanes[0] == ev.value
    np.testing.assert_array_equal(geardyn.lyapunov_lanes(g, P, run=run, settings=auto), lanes)
    assert not np.array_equal(geardyn.lyapunov_lanes(g, P, run=run, settings=diff), lanes)


def test_tangent_setting_is_checked():
    with pytest.raises(ValueError, match="tangent"):
        geardyn.LyapunovSettings(tangent="exact")
    # a model without a one form (the general N-set CATT kernel) has no variational tangent
    dev = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), reduced=False)
    assert dev.kernel.one_form is None
    with pytest.raises(geardyn.errors.ParameterError, match="settings.tangent"):
        geardyn.lyapunov(dev, settings=geardyn.LyapunovSettings(tangent="variational"))
    with pytest.raises(geardyn.errors.ParameterError, match="settings.tangent"):
        geardyn.lyapunov_lanes(dev, dev.lane_params("Omega", [1.0]),
                               settings=geardyn.LyapunovSettings(tangent="variational"))


def test_the_tangent_follows_the_kernels_declared_one_form():
    """``lyapunov_variational`` reads ``model.kernel.one_form`` (declared by every
    KernelSource): a kernel that does not declare it is an error, not a silent fall back to
    the difference rows."""
    from types import SimpleNamespace

    from geardyn.analysis.lyapunov import lyapunov_variational

    pair = geardyn.GearPair(**IMPACTING)
    dev = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), reduced=False)
    diff = geardyn.LyapunovSettings(tangent="difference")
    assert pair.kernel.one_form is not None and lyapunov_variational(pair)
    assert not lyapunov_variational(pair, diff)
    assert dev.kernel.one_form is None and not lyapunov_variational(dev)
    with pytest.raises(AttributeError, match="one_form"):
        lyapunov_variational(SimpleNamespace(kernel=SimpleNamespace(rhs=None)))


@nb.njit(cache=True)
def atan_rhs(t, y, p, s, c):
    """A one-form rhs with an operation the dual numbers lack (atan2)."""
    return (y[1], -p.k * math.atan2(y[0], 1.0) - 0.1 * y[1] + p.F * c)


def test_a_rhs_the_duals_cannot_take_is_named(monkeypatch):
    """Refused naming ``settings.tangent``, numba's typing error (the operation) chained, by the
    tangent form alone: no function of the model's Lyapunov kernel or step core is compiled
    first (no compile-ahead helper: it would compile the core's split step meanwhile); on the
    inlined path (tests/test_pointer_path.py: the pointer path's)."""
    from geardyn.solvers.kernels import CORE

    monkeypatch.setenv("GEARDYN_COMPILE_AHEAD", "0")
    m = geardyn.UserModel.from_one_form(atan_rhs, params={"k": 1.0, "F": 0.2, "Omega": 1.1},
                                        states=("x", "v"), initial_state=(0.1, 0.0),
                                        kernel_path="lane-form")
    with pytest.raises(geardyn.errors.ParameterError, match="settings.tangent") as info:
        geardyn.lyapunov(m, settings=geardyn.LyapunovSettings(duration=20.0))
    assert "atan2" in str(info.value.__cause__)
    with pytest.raises(geardyn.errors.ParameterError, match="settings.tangent") as info:
        geardyn.lyapunov_lanes(m, m.lane_params("Omega", [1.1]),
                               settings=geardyn.LyapunovSettings(duration=20.0))
    assert "atan2" in str(info.value.__cause__)
    compiled = [f"{mod.__name__}.{name}" for mod in (kernels_for(m.kernel, "lyapunov"),
                                                     kernels_for(m.kernel, CORE))
                for name, fn in vars(mod).items()
                if isinstance(fn, nb.core.registry.CPUDispatcher)
                and fn.py_func.__module__ == mod.__name__ and fn.overloads]
    assert compiled == []


def test_split_limit_takes_the_difference_rows_counted():
    """A variational step that reaches the split limit (the levels model of
    tests/levels_model.py: 18 levels crossed within one grid step twice per forcing period, more
    than MAX_SPLITS) is taken by the difference rows and counted, never silently: from the
    analytic motion, 2 such steps per period run in ``difference_steps``, each of the rows
    (the state and its two neighbours) at the limit in ``unresolved``, the status SPLIT_LIMIT;
    in the one-lane kernel and in the fused lane blocks alike. x' does not depend on x, so the
    exponent is 0 (to the rows' rounding)."""
    from levels_model import RUN, levels_model

    model = levels_model()
    kern = kernels_for(model.kernel, "lyapunov")
    assert kern.VARIATIONAL and kern.FUSED
    n_per, n_tr, n_m = RUN.steps_per_period, 2, 10
    steps = 2 * (n_tr + n_m)
    om = 1.1
    p = np.ascontiguousarray(model.with_params(Omega=om).params)
    out = one_lane(kern, p, model.initial_state(), np.ones(1), 0.0, 2 * math.pi / om / n_per, om,
                   n_per, n_tr * n_per, n_m * n_per, 10, 1, 1e6, model.n_events, 16, True)
    assert (out[3], out[4], out[5]) == (2, 3 * steps, steps)  # STATUS_SPLIT_LIMIT
    assert abs(out[0][0]) < 5e-8
    oms = np.array([0.8, 1.1, 1.4])
    _, _, _, exps, _, unres, status, fd = _lanes(model, oms, n_per, n_tr * n_per,
                                                 np.full(3, n_m * n_per), True)
    assert fd.tolist() == [steps] * 3 and unres.tolist() == [3 * steps] * 3
    assert status.tolist() == [2] * 3 and np.all(np.abs(exps) < 5e-8)
