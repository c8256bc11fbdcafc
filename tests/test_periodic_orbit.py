"""Periodic orbits by Newton shooting and their Floquet multipliers, against independent results:
the analytic steady state of the linear forced oscillator, expm of its constant Jacobian, the
variational equations integrated by DOP853, the reference integrator's section points and its
period map, and Liouville's formula."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import geardyn
import geardyn.io
from geardyn.analysis.orbits import (
    OrbitStatus,
    build_orbit,
    jacobian_trace,
    newton_shooting,
    shooting_problem,
)
from geardyn.testing import assert_result
from shared_models import oscillator


def _sorted(mu: np.ndarray) -> np.ndarray:
    mu = np.asarray(mu, dtype=complex)
    return mu[np.lexsort((mu.imag, mu.real))]


def _linear_response(m: geardyn.GearPair, om: float) -> complex:
    """Complex amplitude A of x = b + Fm + Re(A e^{i Omega t}) for the gear pair in contact with
    constant stiffness: x'' + 2 zeta x' + x - b = Fm + Fa Omega^2 cos(Omega t)."""
    p = dict(zip(m.param_names, m.params, strict=True))
    return p["Fa"] * om**2 / (1.0 - om**2 + 2j * p["zeta"] * om)


def _reference_period_map(m, x: np.ndarray, T: float) -> np.ndarray:
    return geardyn.reference_solution(m, x, np.array([T]))[0]


def _reference_monodromy(m, x: np.ndarray, T: float, d: float = 1e-5) -> np.ndarray:
    """Central differences of the reference integrator's period map (DOP853, rtol 1e-12): with
    d = 1e-5 the rounding of the map (~1e-12 / d ~ 1e-7) and the truncation (~d^2 ~ 1e-10) are
    both below the 1e-5 the tests ask."""
    n = x.size
    M = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = d
        M[:, j] = (_reference_period_map(m, x + e, T) - _reference_period_map(m, x - e, T)) / (
            2 * d)
    return M


def test_linear_orbit_matches_the_analytic_steady_state_and_expm():
    om = 0.8
    m = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=2.0, Fa=0.02).with_omega(om)
    orb = geardyn.periodic_orbit(m)
    assert orb.converged, orb.message
    assert orb.residual < 1e-12
    assert np.all(orb.crossings == 0)  # always in contact: the linear system
    A = _linear_response(m, om)
    x = 1.0 + 2.0 + np.real(A * np.exp(1j * om * orb.times))
    v = np.real(1j * om * A * np.exp(1j * om * orb.times))
    assert np.max(np.abs(orb.states[:, 0] - x)) < 1e-9
    assert np.max(np.abs(orb.states[:, 1] - v)) < 1e-9
    J = np.array([[0.0, 1.0], [-1.0, -0.1]])
    M = expm(J * 2 * math.pi / om)
    assert np.max(np.abs(orb.monodromy - M)) < 1e-8
    assert np.max(np.abs(_sorted(orb.multipliers) - _sorted(np.linalg.eigvals(M)))) < 1e-8
    assert orb.stability == "stable"
    # eigenvectors: M v = mu v
    for k in range(2):
        vk = orb.eigenvectors[:, k]
        assert np.allclose(M @ vk, orb.multipliers[k] * vk, atol=1e-8)


def test_default_guess_with_converge_runs_on_until_the_section_point_settles():
    """The guess's transient by convergence (``run.converge``, as ``geardyn continue`` takes
    it from a study's [run]): the linear pair's free motion decays by exp(-zeta T) ~ 0.68 a
    period, so after 5 periods the section point is ~5e-3 from the analytic steady state; with
    converge = 1e-9 the run goes on until consecutive points agree to 1e-9 (1 + |y|) ~ 4e-9,
    which leaves at most 4e-9 x 0.68 / (1 - 0.68) ~ 9e-9; a limit (transient_max) stops it
    earlier."""
    from geardyn.analysis.orbits import default_guess

    om, zeta = 0.8, 0.05
    m = geardyn.GearPair(zeta=zeta, kappa=0.0, Fm=2.0, Fa=0.02).with_omega(om)
    pr = shooting_problem(m)
    A = _linear_response(m, om)
    exact = np.array([1.0 + 2.0 + A.real, -om * A.imag])
    T = 2 * math.pi / om

    def error(y):
        return np.max(np.abs(y - exact))

    short = default_guess(pr, transient=5 * T)
    settled = default_guess(pr, transient=5 * T, converge=1e-9)
    capped = default_guess(pr, transient=5 * T, converge=1e-9, transient_max=20 * T)
    assert error(short) > 1e-3
    assert error(settled) < 2e-8
    assert error(short) > error(capped) > error(settled)
    assert error(capped) == pytest.approx(
        error(default_guess(pr, transient=20 * T)), rel=1e-6)


def test_time_varying_stiffness_multipliers_match_the_variational_equations():
    om, zeta, kappa = 1.3, 0.05, 0.3
    m = geardyn.GearPair(zeta=zeta, kappa=kappa, Fm=2.0, Fa=0.02).with_omega(om)
    orb = geardyn.periodic_orbit(m)
    assert orb.converged and np.all(orb.crossings == 0)
    T = 2 * math.pi / om

    def variational(t, z):  # z: the 2 x 2 monodromy, row-major; J written out
        J = np.array([[0.0, 1.0], [-(1.0 + kappa * math.cos(om * t)), -2.0 * zeta]])
        return (J @ z.reshape(2, 2)).ravel()

    sol = solve_ivp(variational, (0.0, T), np.eye(2).ravel(), method="DOP853", rtol=1e-12,
                    atol=1e-14)
    M = sol.y[:, -1].reshape(2, 2)
    assert np.max(np.abs(orb.monodromy - M)) < 1e-8
    assert np.max(np.abs(_sorted(orb.multipliers) - _sorted(np.linalg.eigvals(M)))) < 1e-8
    # the section point is a fixed point of the reference integrator's period map
    assert np.max(np.abs(_reference_period_map(m, orb.x, T) - orb.x)) < 1e-8


def test_orbit_with_contact_loss_against_the_reference_integrator(tmp_path):
    om, zeta = 0.9, 0.05
    m = geardyn.GearPair(zeta=zeta, Fm=0.1, Fa=0.05).with_omega(om)
    orb = geardyn.periodic_orbit(m)
    assert orb.converged, orb.message
    assert orb.residual < 1e-10
    assert orb.crossings.sum() > 0  # the teeth separate once per period
    T = 2 * math.pi / om
    # Liouville: prod(mu) = exp(-2 zeta T), the trace being -2 zeta (from the equation)
    det = np.real(np.prod(orb.multipliers))
    assert abs(det / math.exp(-2 * zeta * T) - 1) < 1e-8
    assert abs(orb.trace_integral / (-2 * zeta * T) - 1) < 1e-9  # the differenced trace
    # a long reference run from the model's initial state settles onto the section point
    times = T * np.arange(60, 64)
    ref = geardyn.reference_solution(m, m.initial_state(), times)
    assert np.max(np.abs(ref - orb.x)) < 1e-7
    assert orb.stability == "stable"  # consistent with the run settling
    # the multipliers against finite differences of the reference period map
    Mref = _reference_monodromy(m, orb.x, T)
    assert np.max(np.abs(_sorted(orb.multipliers) - _sorted(np.linalg.eigvals(Mref)))) < 1e-5
    ds = orb.to_dataset()
    assert_result(ds, "periodic-orbit")
    assert ds.attrs["converged"] == 1 and ds.attrs["stability"] == "stable"
    assert int(ds["edge_crossings"].sum()) == int(orb.crossings.sum())
    assert orb.mesh_crossings() == {"mesh": int(orb.crossings.sum())}
    # the orbit over the period, its mesh force and contact regime, against the reference
    Y = geardyn.reference_solution(m, orb.x, orb.times)
    assert np.max(np.abs(Y - orb.states)) < 1e-7
    x, v = Y[:, 0], Y[:, 1]
    F = np.where(x > 1, x - 1, np.where(x < -1, x + 1, 0.0)) + 2 * zeta * v
    assert abs(orb.mesh_forces()["force_peak"][0] - np.max(np.abs(F))) < 1e-7
    assert abs(orb.mesh_forces()["dynamic_factor"][0] - np.max(np.abs(F)) / 0.1) < 1e-6
    assert x.min() < 1 and x.min() > -1  # separates, never touches the back flank
    assert orb.contact() == {"mesh": "single"}
    assert list(ds["contact"].values) == ["single"]
    geardyn.io.save_dataset(ds, tmp_path / "orbit.nc")
    assert geardyn.io.load_dataset(tmp_path / "orbit.nc").identical(ds)


def test_unstable_period_one_orbit_past_a_period_doubling():
    om, zeta = 1.7, 0.02
    m = geardyn.GearPair(zeta=zeta, Fm=0.1, Fa=0.1, kappa=0.2).with_omega(om)
    A = _linear_response(geardyn.GearPair(zeta=zeta, Fm=0.1, Fa=0.1), om)
    guess = np.array([1.1 + A.real, -om * A.imag])  # linear response, constant stiffness
    orb = geardyn.periodic_orbit(m, guess=guess)
    assert orb.converged, orb.message
    assert orb.crossings.sum() > 0
    assert orb.stability == "unstable"
    assert np.min(orb.multipliers.real) < -1.05  # a multiplier beyond -1
    T = 2 * math.pi / om
    assert abs(np.real(np.prod(orb.multipliers)) / math.exp(-2 * zeta * T) - 1) < 1e-8
    # the reference integrator agrees: a fixed point of its period map, with its multipliers
    assert np.max(np.abs(_reference_period_map(m, orb.x, T) - orb.x)) < 1e-7
    Mref = _reference_monodromy(m, orb.x, T)
    assert np.max(np.abs(_sorted(orb.multipliers) - _sorted(np.linalg.eigvals(Mref)))) < 1e-5
    # and a reference run started next to it leaves it (period 2 is what a long run shows)
    away = geardyn.reference_solution(m, orb.x + np.array([1e-6, 0.0]), T * np.arange(1, 61))
    assert np.max(np.abs(away[-4:] - orb.x)) > 1e-3


def test_newton_failures_are_reported_not_raised():
    m = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05).with_omega(0.9)
    orb = geardyn.periodic_orbit(m, guess=np.array([3.0, 2.0]),
                                 settings=geardyn.NewtonSettings(max_iter=1))
    assert orb.status == OrbitStatus.NOT_CONVERGED and not orb.converged
    assert "did not converge" in orb.message or "stalled" in orb.message
    assert orb.stability == "unknown"
    ds = orb.to_dataset()
    assert ds.attrs["converged"] == 0 and ds.attrs["message"] == orb.message
    bad = geardyn.periodic_orbit(m, guess=np.array([3.0, 2.0]),
                                 run=geardyn.RunSettings(bound=2.0))
    assert bad.status == OrbitStatus.DIVERGED and "diverged" in bad.message


def test_a_shooting_evaluation_says_whether_it_ended_cleanly():
    """``ShootingEval.ok``: the integration's status is OK; a start past the state bound
    (|x| > 2 at the start) diverges and is not ok, with the status saying so."""
    m = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05).with_omega(0.9)
    ev = shooting_problem(m).evaluate(np.array([1.0, 0.1]), jacobian=False)
    assert ev.ok and ev.status == geardyn.Status.OK
    far = shooting_problem(m, run=geardyn.RunSettings(bound=2.0)).evaluate(
        np.array([3.0, 2.0]), jacobian=False)
    assert not far.ok and far.status == geardyn.Status.DIVERGED


def test_shooting_problem_gives_residual_and_jacobian_for_continuation():
    m = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05).with_omega(0.9)
    prob = shooting_problem(m)
    x = np.array([1.0, 0.1])
    ev = prob.evaluate(x)
    d = 1e-6
    for j in range(2):  # the Jacobian is that of the residual it returns
        e = np.zeros(2)
        e[j] = d
        col = (prob.evaluate(x + e, jacobian=False).residual
               - prob.evaluate(x - e, jacobian=False).residual) / (2 * d)
        assert np.allclose(ev.jacobian[:, j], col, atol=1e-7)
    p2 = m.lane_params("Omega", [0.95])[0]
    moved = prob.with_params(p2)
    assert moved.omega == 0.95 and moved.model.omega == 0.95 and prob.model.omega == 0.9
    assert moved.duration == pytest.approx(2 * math.pi / 0.95)
    orb = build_orbit(moved, newton_shooting(moved, geardyn.periodic_orbit(m).x))
    assert orb.converged and orb.omega == 0.95
    with pytest.raises(ValueError, match="period"):
        shooting_problem(m, period=0)


def test_catt_device_orbit_keeps_liouville():
    """The paper's device (reduced and general forms, with a load fluctuation at Lambda = Omega:
    common period one forcing period): the trace of the Jacobian is minus the sum of the damping
    coefficients, read from the coefficient vector."""
    base = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    om = 0.5
    m = base.with_omega(om)
    c = m.coefficient_values()
    trace = -(c["c_sq_q"] + c["c_sq_c"] + c["c_pq_q"] + c["c_pq_p"])
    assert abs(jacobian_trace(m, 0.3, m.initial_state()) - trace) < 1e-8 * abs(trace)
    orb = geardyn.periodic_orbit(m)
    assert orb.converged, orb.message
    T = orb.duration
    assert abs(np.real(np.prod(orb.multipliers)) / math.exp(trace * T) - 1) < 1e-8
    g = m.general()
    orb_g = geardyn.periodic_orbit(g, guess=m.expand_state(orb.x))
    assert orb_g.converged, orb_g.message
    assert np.max(np.abs(orb_g.x - m.expand_state(orb.x))) < 1e-8
    assert orb_g.stability == orb.stability
    # Liouville for the 16 states, the trace by differences of the general model's rhs (checked
    # on the reduced model above); the RK4 error of the 16-state map at its default step is
    # larger than the reduced model's (measured 4.5e-8)
    trace_g = jacobian_trace(g, 0.3, g.initial_state())
    assert abs(np.real(np.prod(orb_g.multipliers)) / math.exp(trace_g * T) - 1) < 1e-7


def test_period_two_orbit_after_the_doubling():
    """Past the period doubling above, the period-2 orbit: a fixed point of the twice-iterated
    map that is not the period-1 orbit, stable, where a reference run settles."""
    om, zeta = 1.7, 0.02
    m = geardyn.GearPair(zeta=zeta, Fm=0.1, Fa=0.1, kappa=0.2).with_omega(om)
    orb = geardyn.periodic_orbit(m, period=2)
    assert orb.converged, orb.message
    T = 2 * math.pi / om
    assert orb.duration == pytest.approx(2 * T)
    n = orb.problem.steps_per_period
    x1 = orb.states[n]  # the other section point
    assert np.max(np.abs(x1 - orb.x)) > 1e-3  # a true period 2
    assert orb.stability == "stable"
    assert abs(np.real(np.prod(orb.multipliers)) / math.exp(-4 * zeta * T) - 1) < 1e-8
    ref = geardyn.reference_solution(m, m.initial_state(), T * np.arange(400, 402))
    d = min(np.max(np.abs(ref[0] - orb.x)), np.max(np.abs(ref[0] - x1)))
    assert d < 1e-6
    assert np.max(np.abs(ref[1] - ref[0])) > 1e-3


def test_smooth_nonlinear_multipliers_match_the_variational_equations():
    """A user's Duffing oscillator: the monodromy against DOP853 (rtol 1e-12) of the orbit and
    its variational equation, the Jacobian written out here, to 1e-8."""
    om, delta, beta, gamma = 1.2, 0.1, 0.5, 0.3
    # x'' + delta x' + x + beta x^3 = gamma cos(Omega t)
    m = oscillator(Omega=om, zeta=delta / 2, beta=beta, F=gamma, natural_frequency=1.6)
    orb = geardyn.periodic_orbit(m)
    assert orb.converged, orb.message
    T = 2 * math.pi / om

    def augmented(t, z):
        x, v = z[0], z[1]
        J = np.array([[0.0, 1.0], [-1.0 - 3 * beta * x * x, -delta]])
        f = [v, -delta * v - x - beta * x**3 + gamma * math.cos(om * t)]
        return np.concatenate([f, (J @ z[2:].reshape(2, 2)).ravel()])

    sol = solve_ivp(augmented, (0.0, T), np.concatenate([orb.x, np.eye(2).ravel()]),
                    method="DOP853", rtol=1e-12, atol=1e-14)
    assert np.max(np.abs(sol.y[:2, -1] - orb.x)) < 1e-8  # an orbit of the exact flow
    M = sol.y[2:, -1].reshape(2, 2)
    assert np.max(np.abs(orb.monodromy - M)) < 1e-8
    assert np.max(np.abs(_sorted(orb.multipliers) - _sorted(np.linalg.eigvals(M)))) < 1e-8
    assert abs(np.real(np.prod(orb.multipliers)) / math.exp(-delta * T) - 1) < 1e-8


def test_paper_device_period_doubled_orbit_with_contact_loss():
    """Fig. 3's device at Omega = 1.2, where the sweep shows period 2: the period-1 orbit
    exists, loses contact, and is unstable through a multiplier below -1; its multipliers agree
    with differences of the reference integrator's period map, and Liouville holds."""
    base = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05),
                              interpretation="consistent")
    om = 1.2
    m = base.with_omega(om)
    guess = geardyn.periodic_orbit(base, omega=1.0).x  # the stable orbit nearby
    orb = geardyn.periodic_orbit(m, guess=guess)
    assert orb.converged, orb.message
    assert orb.crossings.sum() > 0
    assert orb.stability == "unstable" and np.min(orb.multipliers.real) < -1.1
    c = m.coefficient_values()
    trace = -(c["c_sq_q"] + c["c_sq_c"] + c["c_pq_q"] + c["c_pq_p"])
    T = 2 * math.pi / om
    assert abs(np.real(np.prod(orb.multipliers)) / math.exp(trace * T) - 1) < 1e-8
    assert np.max(np.abs(_reference_period_map(m, orb.x, T) - orb.x)) < 1e-6
    Mref = _reference_monodromy(m, orb.x, T)
    assert np.max(np.abs(_sorted(orb.multipliers) - _sorted(np.linalg.eigvals(Mref)))) < 1e-4
    two = geardyn.periodic_orbit(m, period=2)  # what the sweep shows
    assert two.converged and two.least_period == 2 and two.stability == "stable"
    assert orb.least_period == 1


def test_body_angle_model_has_no_periodic_orbit_and_says_so():
    """The SI body-angle form turns as a whole (its angles grow): no periodic orbit of its
    states exists; the result is a failure with a message, not an orbit."""
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)).dimensional()
    orb = geardyn.periodic_orbit(m, omega=0.5 * m.device.omega_n,
                                 settings=geardyn.NewtonSettings(max_iter=5))  # in rad/s
    assert not orb.converged and orb.message
    assert orb.stability == "unknown"


def test_load_fluctuation_orbit_on_the_common_section():
    """Fig. 14's device (load fluctuation at Lambda = 2): at Omega = 3 the forcings share the
    period 3 T (Lambda / Omega = 2 / 3), the section the sweeps use; the orbit closes there in
    the reference integrator and keeps Liouville."""
    from geardyn.io import builtin_study

    m = geardyn.build_model(builtin_study("paper_fig14")).with_omega(3.0)
    orb = geardyn.periodic_orbit(m)
    assert orb.converged, orb.message
    assert orb.problem.sections == 3 and orb.duration == pytest.approx(3 * 2 * math.pi / 3.0)
    assert orb.crossings.sum() > 0
    assert np.max(np.abs(_reference_period_map(m, orb.x, orb.duration) - orb.x)) < 1e-8
    c = m.coefficient_values()
    trace = -(c["c_sq_q"] + c["c_sq_c"] + c["c_pq_q"] + c["c_pq_p"])
    det = np.real(np.prod(orb.multipliers))
    assert abs(det / math.exp(trace * orb.duration) - 1) < 2e-8  # RK4's error in the volume
