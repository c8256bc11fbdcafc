"""Verification of the CATT device model against independent computations.

Every expected value here is computed in the test from the paper's equations (Eq. 1 in the body
angles, free-body statics, Floquet theory), never copied from geardyn's own output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

import geardyn

# ---------------------------------------------------------------------------------------------
# helpers


def theta_from_mesh(m: geardyn.CATTDevice, x0: np.ndarray) -> np.ndarray:
    """Body angles (Eq. 1 state: theta_c, theta_c', then theta_q, theta_q', theta_p, theta_p'
    per set) at t = 0 whose mesh coordinates (Eq. 8, 9) are x0; carrier at rest at angle 0."""
    prm, d = m.params_in, m.derived
    bc, wn, w = prm.b_c, d.omega_n, m.omega * d.omega_n
    n = prm.n_planets
    y = np.zeros(2 + 4 * n)
    for i in range(n):
        sq, pq, _, _ = prm.planet_set(i)
        xs, vs, xp, vp = x0[4 * i : 4 * i + 4]
        e_sq, de_sq = sq.error * math.sin(sq.error_phase), sq.error * w * math.cos(sq.error_phase)
        e_pq, de_pq = pq.error * math.sin(pq.error_phase), pq.error * w * math.cos(pq.error_phase)
        tq = (y[0] * prm.carrier.r_c1 - xs * bc - e_sq) / d.r_bq[i]
        wq = (y[1] * prm.carrier.r_c1 - vs * bc * wn - de_sq) / d.r_bq[i]
        tp = (tq * d.r_bq[i] - xp * bc - e_pq) / d.r_bp[i]
        wp = (wq * d.r_bq[i] - vp * bc * wn - de_pq) / d.r_bp[i]
        y[2 + 4 * i : 6 + 4 * i] = (tq, wq, tp, wp)
    return y


def compare_theta_and_mesh(m: geardyn.CATTDevice, x0: np.ndarray, tau: np.ndarray):
    """Integrate the mesh form from x0 and Eq. (1) from the matching body angles; return the
    mesh-form states and the mapped body-angle states at tau."""
    dm = m.dimensional().with_omega(m.omega * m.omega_n)
    y0 = theta_from_mesh(m, x0)
    # the library's map back to mesh coordinates must invert ours
    np.testing.assert_allclose(dm.mesh_coordinates(0.0, y0), x0, rtol=0, atol=1e-11)
    x_ref = geardyn.reference_solution(m, x0, tau, rtol=1e-13, atol=1e-13)
    t = tau / m.omega_n
    th = geardyn.reference_solution(dm, y0, t, rtol=1e-13, atol=1e-16)
    return x_ref, dm.mesh_coordinates(t, th)


def rel_diff(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def crossings(m, x0, periods):
    ds = geardyn.simulate(m, run=geardyn.RunSettings(transient=0.0, samples=periods), y0=x0)
    return int(ds["edge_crossings"].sum())


MISTUNED = [
    {"sun_mesh": {"stiffness_phase": 0.4, "error_phase": 0.3}},
    {"planet_mesh": {"stiffness_phase": -0.5}, "inside_planet": {"inertia": 8.0e-4}},
    {"outside_planet": {"inertia": 0.0023}},
    {"sun_mesh": {"error_phase": 1.1}},
]


# ---------------------------------------------------------------------------------------------
# 1. Dimensional theta form (Eq. 1) vs dimensionless mesh form (Eq. 10)


@pytest.mark.parametrize("interpretation", ["consistent", "carrier-only"])
@pytest.mark.parametrize("regime", ["contact", "contact-loss"])
def test_theta_form_matches_mesh_form(interpretation, regime):
    loss = regime == "contact-loss"
    p = geardyn.PlanetaryParams.paper(
        B1=100.0, B2=100.0, Lambda=0.3, error="10 um" if loss else "0.1 um"
    )
    m = geardyn.CATTDevice(p, interpretation=interpretation).general().with_omega(1.1)
    kick = np.tile([0.3, 0.1, -0.2, 0.05] if loss else [0.03, 0.01, -0.02, 0.005], 4)
    x0 = m.initial_state() + kick
    tau = np.linspace(0.0, 60.0, 13)
    # the regime really is what it claims (the simulation counts dead-zone edge crossings)
    n_cross = crossings(m, x0, periods=10)
    assert (n_cross > 0) if loss else (n_cross == 0)
    x_ref, x_theta = compare_theta_and_mesh(m, x0, tau)
    assert rel_diff(x_theta, x_ref) < 1e-8


def test_theta_form_matches_mesh_form_mistuned_planets():
    base = geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1)
    p = geardyn.PlanetaryParams.model_validate({**base.model_dump(), "planets": MISTUNED})
    m = geardyn.CATTDevice(p).with_omega(1.3)
    assert not m.reduced
    x0 = m.initial_state() + np.linspace(-0.2, 0.2, m.n_states)
    assert crossings(m, x0, periods=10) > 0
    x_ref, x_theta = compare_theta_and_mesh(m, x0, np.linspace(0.0, 50.0, 11))
    assert rel_diff(x_theta, x_ref) < 1e-8
    # planet sets really move differently
    assert np.ptp(x_ref[-1, 0::4]) > 1e-2


def test_as_printed_carrier_damping_typo():
    """'as-printed' keeps Eq. (10)'s carrier damping term with 1/omega_n^2 (a typo kept on
    purpose): without damping the two forms agree, with damping they must differ."""
    tau = np.linspace(0.0, 60.0, 13)
    kick = np.tile([0.02, 0.01, -0.02, 0.005], 4)
    for xi, agree in ((0.0, True), (0.05, False)):
        p = geardyn.PlanetaryParams.paper(error="0.1 um", xi1=xi, xi2=xi)
        m = geardyn.CATTDevice(p, interpretation="as-printed").general().with_omega(1.6)
        x0 = m.initial_state() + kick
        assert crossings(m, x0, periods=10) == 0
        x_ref, x_theta = compare_theta_and_mesh(m, x0, tau)
        if agree:
            assert rel_diff(x_theta, x_ref) < 1e-8
        else:
            assert rel_diff(x_theta, x_ref) > 1e-4


# ---------------------------------------------------------------------------------------------
# 2. General 4N-state model with identical planets vs the reduced 4-state model


@pytest.mark.parametrize(
    ("error", "omega", "locate"),
    [("0.1 um", 1.1, True), ("10 um", 1.1, False), ("10 um", 3.5, False)],
)
def test_general_model_equals_reduced(error, omega, locate):
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(error=error))
    g = m.general()
    assert m.reduced and not g.reduced and g.n_states == 4 * m.n_states
    a = geardyn.simulate(m, omega=omega,
                         run=geardyn.RunSettings(transient=0.0, samples=100, locate_edges=locate))
    b = geardyn.simulate(g, omega=omega,
                         run=geardyn.RunSettings(transient=0.0, samples=100, locate_edges=locate),
                         y0=m.expand_state(m.initial_state()))
    assert a.attrs["steps_per_period"] == b.attrs["steps_per_period"]
    A = a["poincare"].values
    B = b["poincare"].values.reshape(A.shape[0], g.params_in.n_planets, 4)
    assert np.max(np.abs(B - A[:, None, :])) < 1e-10
    if error == "10 um":
        assert int(a["edge_crossings"].sum()) > 0


@pytest.mark.parametrize("omega", [1.1, 3.5])
def test_general_model_equals_reduced_with_edge_location(omega):
    """Identical planet sets cross their edges at the same instant; the kernel takes such
    crossings together, so the general model splits its steps exactly where the reduced one
    does and the two agree to rounding, with no step left unresolved."""
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper())
    g = m.general()
    a = geardyn.simulate(m, omega=omega, run=geardyn.RunSettings(transient=0.0, samples=100))
    b = geardyn.simulate(g, omega=omega,
                         run=geardyn.RunSettings(transient=0.0, samples=100),
                         y0=m.expand_state(m.initial_state()))
    A = a["poincare"].values
    B = b["poincare"].values.reshape(A.shape[0], 4, 4)
    assert np.max(np.abs(B - B[:, :1, :])) == 0.0  # the sets stay identical
    assert np.max(np.abs(B - A[:, None, :])) < 1e-10
    assert a.attrs["unresolved_steps"] == 0 and b.attrs["unresolved_steps"] == 0
    assert int(a["edge_crossings"].sum()) > 0


# ---------------------------------------------------------------------------------------------
# 3. Linear limit: statics by free-body analysis, natural frequencies from Eq. (1)


def _linear_params(planets=None, backlash=0.0):
    p = geardyn.PlanetaryParams.paper(backlash=backlash, Ka=0.0, error=0.0)
    if planets is not None:
        p = geardyn.PlanetaryParams.model_validate({**p.model_dump(), "planets": planets})
    return p


def free_body_statics(m: geardyn.CATTDevice) -> np.ndarray:
    """Mesh forces of the quasi-static state from Eq. (1).

    Constant mesh deflections (X'' = 0 in Eq. 8) force every body to share the carrier's
    rigid-body acceleration a_c: theta_q'' r_bq = theta_c'' r_c1 = theta_p'' r_bp. Eq. (1)
    then reads, per planet set i (damping forces vanish at constant deflection)::

        J_q a_c r_c1 / r_bq = (F_sq - F_pq) r_bq
        J_p a_c r_c1 / r_bp = F_pq r_bp - A1
        J_c a_c             = T_D - A2 - arm sum_i F_sq

    Unknowns (F_sq_1, F_pq_1, ..., F_sq_N, F_pq_N, a_c). Returns the forces [N], shape (N, 2).
    """
    prm, d = m.params_in, m.derived
    n = prm.n_planets
    rc1, ld = prm.carrier.r_c1, prm.loads
    M = np.zeros((2 * n + 1, 2 * n + 1))
    rhs = np.zeros(2 * n + 1)
    a = 2 * n  # index of a_c
    for i in range(n):
        s, q = 2 * i, 2 * i + 1
        # inside planet: (F_sq - F_pq) r_bq - J_q r_c1 / r_bq a_c = 0
        M[s, s], M[s, q], M[s, a] = d.r_bq[i], -d.r_bq[i], -d.J_q[i] * rc1 / d.r_bq[i]
        # outside planet: F_pq r_bp - J_p r_c1 / r_bp a_c = A1
        M[q, q], M[q, a] = d.r_bp[i], -d.J_p[i] * rc1 / d.r_bp[i]
        rhs[q] = ld.A1
        # carrier
        M[a, s] = d.arm
    M[a, a] = d.J_c_eff
    rhs[a] = ld.T_D - ld.A2
    sol = np.linalg.solve(M, rhs)
    return sol[: 2 * n].reshape(n, 2)


@pytest.mark.parametrize("planets", [None, MISTUNED[1:] + [{}]])
@pytest.mark.parametrize("backlash", [0.0, 5.0e-5])
@pytest.mark.parametrize("interpretation", ["consistent", "carrier-only"])
def test_static_deflection_free_body(planets, backlash, interpretation):
    p = _linear_params(planets, backlash)
    m = geardyn.CATTDevice(p, interpretation=interpretation)
    F = free_body_statics(m)
    km = np.array([[s[0].mean_stiffness, s[1].mean_stiffness]
                   for s in (p.planet_set(i) for i in range(p.n_planets))])
    defl = F / km + np.sign(F) * backlash  # loaded flank: the dead zone adds to the deflection
    x_bar = defl / p.b_c
    expected = np.zeros((x_bar.shape[0], 4))
    expected[:, 0], expected[:, 2] = x_bar[:, 0], x_bar[:, 1]
    y = m.initial_state()
    np.testing.assert_allclose(y, expected[: m.n_sets].ravel(), rtol=1e-12, atol=1e-12)
    if planets is None:
        assert m.reduced and np.allclose(F, F[0])


@pytest.mark.parametrize("planets", [None, MISTUNED[1:] + [{}]])
def test_static_mesh_forces_free_body(planets):
    m = geardyn.CATTDevice(_linear_params(planets))
    F = free_body_statics(m)
    np.testing.assert_allclose(m.static_mesh_forces(), F[: m.n_sets].ravel(), rtol=1e-10)


@pytest.mark.parametrize("planets", [None, MISTUNED[1:] + [{}]])
def test_damped_simulation_settles_on_the_static_state(planets):
    p = _linear_params(planets, backlash=5.0e-5)
    m = geardyn.CATTDevice(p)
    F = free_body_statics(m)
    km = np.array([p.planet_set(i)[0].mean_stiffness for i in range(p.n_planets)])
    start = m.initial_state() + 0.5
    start[1::2] = 0.0
    ds = geardyn.simulate(m, omega=1.0,
                          run=geardyn.RunSettings(transient=3000.0, samples=1), y0=start)
    mean_x_sq = ds["poincare"].values[-1, 0::4]  # no forcing: the state is constant
    expected = (F[: m.n_sets, 0] / km[: m.n_sets] + 5.0e-5) / p.b_c
    np.testing.assert_allclose(mean_x_sq, expected, rtol=1e-9)
    np.testing.assert_allclose(ds["X_sq" if m.reduced else "X_sq1"].mean(), expected[0],
                               rtol=1e-9)
    # the recorded dynamic mesh forces [N] settle on the free-body forces
    names = ("F_sq", "F_pq") if m.reduced else ("F_sq1", "F_pq1")
    np.testing.assert_allclose([float(ds[k].mean()) for k in names], F[0], rtol=1e-9)


def theta_form_matrices(m: geardyn.CATTDevice):
    """Mass and (mean) stiffness matrices of Eq. (1) linearised (b = 0, Ka = 0) in the body
    angles (theta_c, theta_q1, theta_p1, ...). The carrier sees each sun-mesh force through the
    arm r_bs cos(alpha) while the mesh deflects by r_c1 theta_c, so K is not symmetric."""
    prm, d = m.params_in, m.derived
    n = prm.n_planets
    rc1 = prm.carrier.r_c1
    M = np.zeros((2 * n + 1, 2 * n + 1))
    K = np.zeros_like(M)
    M[0, 0] = d.J_c_eff
    for i in range(n):
        sq, pq, _, _ = prm.planet_set(i)
        ks, kp = sq.mean_stiffness, pq.mean_stiffness
        q, pp = 1 + 2 * i, 2 + 2 * i
        rq, rp = d.r_bq[i], d.r_bp[i]
        M[q, q], M[pp, pp] = d.J_q[i], d.J_p[i]
        # F_sq = ks (rc1 th_c - rq th_q), F_pq = kp (rq th_q - rp th_p)
        # carrier: J_c th_c'' + arm F_sq = 0
        K[0, 0] += d.arm * ks * rc1
        K[0, q] -= d.arm * ks * rq
        # inside planet: J_q th_q'' - rq (F_sq - F_pq) = 0
        K[q, 0] -= rq * ks * rc1
        K[q, q] += rq * (ks * rq + kp * rq)
        K[q, pp] -= rq * kp * rp
        # outside planet: J_p th_p'' - rp F_pq = 0
        K[pp, q] -= rp * kp * rq
        K[pp, pp] += rp * kp * rp
    return M, K


@pytest.mark.parametrize("interpretation", list(geardyn.INTERPRETATIONS))
@pytest.mark.parametrize("planets", [None, [{"inside_planet": {"inertia": 9.0e-4}}, {}, {}, {}],
                                     MISTUNED])
def test_natural_frequencies_from_theta_form(interpretation, planets):
    p = _linear_params(planets)
    m = geardyn.CATTDevice(p, interpretation=interpretation)
    M, K = theta_form_matrices(m)
    lam = scipy.linalg.eig(K, M, right=False)
    assert np.max(np.abs(lam.imag)) < 1e-9 * np.max(np.abs(lam.real))
    lam = np.sort(lam.real)
    # one rigid-body mode (theta_c r_c1 = theta_q r_bq = theta_p r_bp): zero eigenvalue
    assert abs(lam[0]) < 1e-10 * lam[-1]
    rigid = np.concatenate([[1.0], np.ravel([[p.carrier.r_c1 / m.derived.r_bq[i],
                                              p.carrier.r_c1 / m.derived.r_bp[i]]
                                             for i in range(p.n_planets)])])
    assert np.max(np.abs(K @ rigid)) < 1e-6 * np.max(np.abs(K))
    expected = np.sqrt(lam[1:]) / m.omega_n
    np.testing.assert_allclose(m.natural_frequencies(), expected, rtol=1e-10)
    if planets is not None:
        # the changed inertias really move the frequencies
        tuned = geardyn.CATTDevice(_linear_params(), interpretation=interpretation)
        assert np.max(np.abs(expected - tuned.natural_frequencies())) > 1e-3


# ---------------------------------------------------------------------------------------------
# 4. Parametric resonance: Floquet multipliers of the linear time-periodic system


def _parametric_device():
    p = geardyn.PlanetaryParams.paper(T_D=0.0, A1=0.0, A2=0.0, backlash=0.0, error=0.0,
                                      xi1=0.0, xi2=0.0)
    return geardyn.CATTDevice(p)


def floquet_multipliers(m: geardyn.CATTDevice, omega: float) -> np.ndarray:
    """Multipliers of X'' = -A(tau) X (reduced 2-coordinate model), A assembled from the
    coefficients of Eq. (10) with K(tau)/Km = 1 + (Ka/Km) sin(Omega tau) on each mesh."""
    prm, co = m.params_in, m.coefficients
    n = prm.n_planets
    rs = prm.sun_mesh.stiffness_amplitude / prm.sun_mesh.mean_stiffness
    rp = prm.planet_mesh.stiffness_amplitude / prm.planet_mesh.mean_stiffness
    a_s = np.array([[n * co["k_sq_c"][0] + co["k_sq_q"][0], 0.0], [-co["k_sq_q"][0], 0.0]])
    a_p = np.array([[0.0, -co["k_pq_q"][0]], [0.0, co["k_pq_q"][0] + co["k_pq_p"][0]]])

    def f(tau, z):
        Z = z.reshape(4, 4)
        A = a_s * (1 + rs * math.sin(omega * tau)) + a_p * (1 + rp * math.sin(omega * tau))
        return np.vstack([Z[2:], -A @ Z[:2]]).ravel()

    sol = solve_ivp(f, (0.0, 2 * math.pi / omega), np.eye(4).ravel(), method="DOP853",
                    rtol=1e-12, atol=1e-14)
    return np.linalg.eigvals(sol.y[:, -1].reshape(4, 4))


def test_parametric_resonance_floquet_and_simulation():
    m = _parametric_device()
    co = m.coefficients
    # in-phase (reduced) modes: the lowest general-model mode is a planet mode that a symmetric
    # start does not excite
    a0 = np.array([[4 * co["k_sq_c"][0] + co["k_sq_q"][0], -co["k_pq_q"][0]],
                   [-co["k_sq_q"][0], co["k_pq_q"][0] + co["k_pq_p"][0]]])
    w_reduced = np.sort(np.sqrt(np.linalg.eigvals(a0).real))
    inside, outside = 2.0 * w_reduced[0], 1.2  # principal zone of the lowest mode; outside it
    mu_in = floquet_multipliers(m, inside)
    mu_out = floquet_multipliers(m, outside)
    assert np.max(np.abs(mu_in)) > 1.15
    np.testing.assert_allclose(np.abs(mu_out), 1.0, atol=1e-6)
    assert abs(np.prod(mu_in) - 1.0) < 1e-8  # Liouville: no damping, det = 1

    y0 = np.array([1e-3, 0.0, 1e-3, 0.0])
    grow = geardyn.simulate(m, omega=inside,
                            run=geardyn.RunSettings(transient=0.0, samples=80), y0=y0)
    stay = geardyn.simulate(m, omega=outside,
                            run=geardyn.RunSettings(transient=0.0, samples=80), y0=y0)
    amp_in = np.max(np.abs(grow["poincare"].values[:, [0, 2]]), axis=1)
    amp_out = np.max(np.abs(stay["poincare"].values[:, [0, 2]]), axis=1)
    assert grow.attrs["status"] == 0 and stay.attrs["status"] == 0
    assert amp_in[-1] / amp_in[0] > 100.0
    assert np.max(amp_out) / amp_out[0] < 10.0
    # late growth per period equals the dominant Floquet multiplier
    P = grow["poincare"].values
    rate = (np.linalg.norm(P[80]) / np.linalg.norm(P[60])) ** (1 / 20)
    assert rate == pytest.approx(np.max(np.abs(mu_in)), rel=1e-3)
