"""Lyapunov exponents from the tangent equations (geardyn.analysis.lyapunov)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

import geardyn
from geardyn import LyapunovSettings, RunSettings
from geardyn.analysis.lyapunov import lyapunov, lyapunov_lanes
from geardyn.io.toml import builtin_study
from geardyn.models import catt_kernels
from geardyn.study import build_model
from shared_models import lorenz, oscillator
from test_verification_catt import theta_from_mesh


@nb.njit(cache=True)
def drift_decay_rhs(t, y, dy, p):
    # x' = 1 (exponent 0), y' = -y (exponent -1); the events are levels of x
    dy[0] = 1.0
    dy[1] = -y[1]


@nb.njit(cache=True)
def levels_events(t, y, g, p):
    for j in range(g.size):
        g[j] = y[0] - p[j]


LORENZ = np.array([10.0, 28.0, 8.0 / 3.0])
#: Largest Lorenz exponent at sigma=10, rho=28, beta=8/3 (Viswanath 1998: 0.9056).
LORENZ_LAMBDA1 = 0.9056
#: A chaotic gear pair with backlash (found by a scan with lyapunov_lanes; chaos confirmed
#: independently in test_gear_pair_chaotic_positive by the divergence of nearby trajectories).
CHAOTIC = dict(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3, Omega=0.92)
#: A period-1 orbit with contact loss (two edge crossings per period) and real Floquet
#: multipliers, so its largest exponent differs from -zeta and depends on the impacts.
IMPACTING = dict(zeta=0.1, kappa=0.2, Fm=0.1, Fa=0.15, Omega=1.15)


def lorenz_model():
    return lorenz(*LORENZ)


def rk4_polynomial(Z):
    """The RK4 stability function R(Z) = I + Z + Z^2/2 + Z^3/6 + Z^4/24 (the exact step map of
    a linear system)."""
    out = np.eye(Z.shape[0])
    term = np.eye(Z.shape[0])
    for k in range(1, 5):
        term = term @ Z / k
        out = out + term
    return out


# ----------------------------------------------------------------------------- Lorenz
def test_lorenz_largest_exponent():
    lam = lyapunov(lorenz_model(), y0=[1.0, 1.0, 1.0], run=geardyn.RunSettings(transient=100.0),
                   settings=geardyn.LyapunovSettings(duration=2000.0))
    assert abs(lam - LORENZ_LAMBDA1) < 0.01 * LORENZ_LAMBDA1


def test_lorenz_spectrum():
    sigma, _rho, beta = LORENZ
    lam = lyapunov(lorenz_model(), y0=[1.0, 1.0, 1.0], run=geardyn.RunSettings(transient=100.0),
                   spectrum=True, settings=geardyn.LyapunovSettings(duration=2000.0))
    assert lam.shape == (3,)
    assert np.all(np.diff(lam) < 0)
    assert abs(lam[0] - LORENZ_LAMBDA1) < 0.01 * LORENZ_LAMBDA1
    assert abs(lam[1]) < 0.01  # the flow direction
    trace = -(sigma + 1.0 + beta)  # divergence of the Lorenz field, constant
    assert abs(lam.sum() - trace) < 0.01 * abs(trace)


# ----------------------------------------------------------------------------- linear
@pytest.mark.parametrize("which", ["gear_pair", "user"])
def test_linear_oscillator_spectrum(which):
    zeta, omega, n = 0.1, 0.7, 64
    if which == "gear_pair":  # backlash 0 makes the dead zone g(x) = x: linear
        model = geardyn.GearPair(zeta=zeta, kappa=0.0, backlash=0.0, Fm=0.1, Fa=0.05,
                                 Omega=omega)
    else:
        model = oscillator(zeta=zeta, F=0.3, Omega=omega)  # x'' + 2 zeta x' + x = F cos
    lam = lyapunov(model, y0=[0.3, 0.0], spectrum=True,
                   run=geardyn.RunSettings(transient=100.0, steps_per_period=n))
    # the sum is log|det| of the step map per unit time: exactly that of the RK4 polynomial of
    # h A, and -2 zeta (the trace) up to the O(h^4) error of RK4
    A = np.array([[0.0, 1.0], [-1.0, -2.0 * zeta]])
    h = 2.0 * math.pi / omega / n
    discrete = math.log(abs(np.linalg.det(rk4_polynomial(h * A)))) / h
    assert abs(lam.sum() - discrete) < 1e-9
    assert abs(lam.sum() + 2.0 * zeta) < 1e-5
    # underdamped: complex eigenvalues, both exponents -zeta (finite-time error ~ log(cond)/T)
    assert np.all(np.abs(lam + zeta) < 1e-4)


# ----------------------------------------------------------------------------- gear pair
def test_gear_pair_periodic_negative():
    model = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05, Omega=0.5)
    lam = lyapunov(model)
    assert lam < -0.01
    # a 2-state forced model: the exponents sum to the trace of J, -2 zeta, whatever the contact
    spec = lyapunov(model, spectrum=True)
    assert abs(spec.sum() + 2 * 0.05) < 1e-5
    assert abs(spec[0] - lam) < 1e-9


def test_gear_pair_chaotic_positive():
    model = geardyn.GearPair(**CHAOTIC)
    lam = lyapunov(model,
                   run=geardyn.RunSettings(transient=500.0),
                   settings=geardyn.LyapunovSettings(duration=5000.0))
    assert 0.04 < lam < 0.12
    spec = lyapunov(model, run=geardyn.RunSettings(transient=500.0), spectrum=True,
                    settings=geardyn.LyapunovSettings(duration=5000.0))
    assert abs(spec.sum() + 2 * CHAOTIC["zeta"]) < 1e-5  # trace of J, with impacts
    # independent signal: two trajectories started 1e-9 apart on the attractor separate to O(1)
    y_att = geardyn.simulate(model,
                             run=geardyn.RunSettings(transient=500.0,
                                                     samples=1))["poincare"].values[-1]
    a = geardyn.simulate(model, y0=y_att, run=geardyn.RunSettings(transient=0.0, samples=200))
    b = geardyn.simulate(model, y0=y_att + np.array([1e-9, 0.0]),
                         run=geardyn.RunSettings(transient=0.0, samples=200))
    sep = np.abs(a["poincare"].values[:, 0] - b["poincare"].values[:, 0])
    assert sep[:5].max() < 1e-6
    assert sep.max() > 0.1


def test_gear_pair_periodic_reference_not_diverging():
    # the opposite signal for the periodic case: nearby trajectories approach each other
    model = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05, Omega=0.5)
    y_att = geardyn.simulate(model,
                             run=geardyn.RunSettings(transient=500.0,
                                                     samples=1))["poincare"].values[-1]
    t = model.period * np.arange(40)
    a = geardyn.reference_solution(model, y_att, t)
    b = geardyn.reference_solution(model, y_att + np.array([1e-6, 0.0]), t)
    sep = np.abs(a - b).max(axis=1)
    assert sep[-1] < 1e-6 * 0.5


# ----------------------------------------------------------------------------- state scale
#: A chaotic CATT device (N = 4, light damping, large error; found by a scan of Omega with
#: lyapunov_lanes): exponents well above their errors, so the body-angle model's must match.
CHAOTIC_CATT = dict(error="30 um", xi1=0.02, xi2=0.02)


class _Scaled(geardyn.GearPair):
    """The gear pair with a chosen state scale."""

    def __init__(self, scale, **kw):
        super().__init__(**kw)
        self._scale = np.asarray(scale, dtype=float)

    @property
    def state_scale(self):
        return self._scale


def test_state_scale_default_and_checked():
    assert np.array_equal(geardyn.GearPair().state_scale, np.ones(2))
    assert np.array_equal(lorenz_model().state_scale, np.ones(3))
    for bad in ([1.0], [1.0, 0.0], [1.0, -2.0], [1.0, np.inf], [1.0, np.nan]):
        m = _Scaled(bad, **IMPACTING)
        with pytest.raises(ValueError, match="state_scale"):
            lyapunov(m,
                     run=geardyn.RunSettings(transient=1.0),
                     settings=geardyn.LyapunovSettings(duration=10.0))
        with pytest.raises(ValueError, match="state_scale"):
            lyapunov_lanes(m, m.lane_params("Omega", [1.0]), run=RunSettings(transient=1.0),
                           settings=LyapunovSettings(duration=10.0))


def test_exponent_does_not_depend_on_the_state_scale():
    # a constant linear change of coordinates z = y / s changes the norm by at most the factor
    # kappa = max(s) / min(s), so the finite-time exponent by at most 2 log(kappa) / duration
    # (both measured from aligned vectors), and the limit not at all
    scale, run = np.array([3.0, 0.25]), dict(transient=200.0, duration=500.0, steps_per_period=64)
    one = dict(run=RunSettings(transient=200.0, steps_per_period=64),
               settings=geardyn.LyapunovSettings(duration=run["duration"]))
    a = lyapunov(geardyn.GearPair(**IMPACTING), **one)
    b = lyapunov(_Scaled(scale, **IMPACTING), **one)
    assert a != b  # the scale reaches the kernel
    assert abs(a - b) < 2.0 * math.log(scale.max() / scale.min()) / run["duration"]
    P = geardyn.GearPair(**IMPACTING).params
    lanes = dict(run=RunSettings(transient=200.0, steps_per_period=64),
                 settings=LyapunovSettings(duration=run["duration"]))
    la = lyapunov_lanes(geardyn.GearPair(**IMPACTING), P, **lanes)
    lb = lyapunov_lanes(_Scaled(scale, **IMPACTING), P, **lanes)
    assert la[0] == pytest.approx(a, rel=1e-12) and lb[0] == pytest.approx(b, rel=1e-12)


def test_dimensional_catt_state_scale_is_the_mesh_coordinate_unit():
    # each body-angle state moved by its scale moves a mesh coordinate (Eq. 8, 9: X = x / b_c,
    # X' = dX/dtau) by exactly 1 and none by more
    dm = geardyn.CATTDevice(geardyn.PlanetaryParams.paper()).dimensional()
    s = dm.state_scale
    assert s.shape == (dm.n_states,) and np.all(s > 0)
    y0 = np.zeros(dm.n_states)
    base = dm.mesh_coordinates(0.0, y0)
    for q in range(dm.n_states):
        y = y0.copy()
        y[q] = s[q]
        np.testing.assert_allclose(np.max(np.abs(dm.mesh_coordinates(0.0, y) - base)), 1.0,
                                   rtol=1e-12)


def test_dimensional_catt_exponents_match_the_mesh_form():
    """Eq. (1) in SI body angles and the dimensionless mesh-coordinate form are one physics: the
    exponents per second are those per unit tau times omega_n. The body-angle model has two more
    states, the rigid rotation of the whole device (the mesh coordinates do not see it: two zero
    exponents), and with N = 4 identical planet sets the mesh form's spectrum is that of the
    general 16-state model, whose in-phase part is the reduced model's. Before the tangent
    vectors were measured in the state scale, the perturbation (1e-6 rad) was ~0.1 % of the
    backlash and the lower half of this spectrum was wrong (its sum +0.25 omega_n instead of the
    divergence -0.44 omega_n)."""
    c = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(**CHAOTIC_CATT)).with_omega(0.95)
    wn = c.omega_n
    x0 = c.expand_state(c.initial_state())
    dm = c.dimensional()
    y0 = theta_from_mesh(c, x0)
    np.testing.assert_allclose(dm.mesh_coordinates(0.0, y0), x0, atol=1e-11)
    run = dict(run=RunSettings(transient=1000.0),
               settings=geardyn.LyapunovSettings(duration=1000.0), with_error=True)
    red = lyapunov(c, **run)
    gen = lyapunov(c.general(), y0=x0, spectrum=True, **run)
    run = dict(run=RunSettings(transient=1000.0 / wn),
               settings=geardyn.LyapunovSettings(duration=1000.0 / wn), with_error=True)  # s
    dim1 = lyapunov(dm, y0=y0, **run)
    dim = lyapunov(dm, y0=y0, spectrum=True, **run)
    # the largest exponent: chaotic, and the same per unit tau within the stated errors
    assert red.value > 5.0 * red.stderr
    for d in (dim1, dim):
        lam, err = np.atleast_1d(d.value)[0] / wn, np.atleast_1d(d.stderr)[0] / wn
        assert abs(lam - red.value) < 4.0 * math.hypot(err, red.stderr), (lam, red)
    # the whole spectrum: the general model's and the two rigid-body zeros (their finite-time
    # values ~ log(1 + duration / transient) / duration ~ 7e-4)
    expected = np.sort(np.concatenate([gen.value, [0.0, 0.0]]))[::-1]
    expected_err = np.concatenate([gen.stderr, [0.0, 0.0]])[
        np.argsort(np.concatenate([gen.value, [0.0, 0.0]]), kind="stable")[::-1]]
    tol = 4.0 * np.hypot(dim.stderr / wn, expected_err) + 2e-3
    assert np.all(np.abs(dim.value / wn - expected) < tol), (dim.value / wn, expected, tol)


def _divergence(model, y) -> float:
    """Trace of the Jacobian of the model's rhs at y (t = 0) by central differences (exact for
    the CATT models: every derivative is linear in the velocities, which carry the damping)."""
    from geardyn.solvers.kernels import kernels_for

    rhs = kernels_for(model.kernel, "rk4").rhs
    p = np.ascontiguousarray(model.params)
    tr, f1, f2 = 0.0, np.empty(model.n_states), np.empty(model.n_states)
    for q in range(model.n_states):
        e = 1e-3 * max(abs(y[q]), 1.0)
        for f, d in ((f1, e), (f2, -e)):
            yy = y.copy()
            yy[q] += d
            rhs(0.0, yy, f, p, 0.0, 1.0)
        tr += (f1[q] - f2[q]) / (2 * e)
    return tr


def test_dimensional_catt_spectrum_sums_to_the_divergence_after_the_carrier_drifted():
    """Table 2's torques do not balance: the carrier accelerates (~5.5e3 rad/s^2), and after
    4000 tau its angle is ~1e5 of its scale b_c / r_c1. The rigid rotation does not change the
    dynamics, so the perturbation must not grow with it (the cap on |y / s|): the exponents
    still sum to the divergence of the field (without the cap: off by 6 %, with it 2e-7)."""
    c = geardyn.CATTDevice(geardyn.PlanetaryParams.paper()).with_omega(1.1)
    dm = c.dimensional()
    wn = c.omega_n
    assert abs(c.carrier_acceleration()) > 1e3
    y0 = theta_from_mesh(c, c.expand_state(c.initial_state()))
    lam = lyapunov(dm, y0=y0, run=geardyn.RunSettings(transient=4000.0 / wn), spectrum=True,
                   settings=geardyn.LyapunovSettings(duration=200.0 / wn))
    tr = _divergence(dm, y0)
    assert abs(lam.sum() - tr) < 1e-5 * abs(tr), (lam.sum(), tr)  # measured 2.3e-7


# ----------------------------------------------------------------------------- steps
def reference_floquet(model, y_guess, eps=1e-4, newton=4):
    """Fixed point y* of the period map P (one forcing period T) and the Floquet multipliers of
    the orbit through it, from the reference integrator (DOP853, rtol 1e-12, every backlash
    edge crossing located and restarted): Newton on P(y) - y, then the monodromy matrix
    dP/dy by central differences of step ``eps`` (the field is continuous across the edges, so
    P is C^1 there). Returns (y*, multipliers)."""
    T = model.period

    def P(y):
        return geardyn.reference_solution(model, y, [T])[0]

    def monodromy(y):
        n = y.size
        M = np.empty((n, n))
        for j in range(n):
            d = np.zeros(n)
            d[j] = eps
            M[:, j] = (P(y + d) - P(y - d)) / (2.0 * eps)
        return M

    y = np.asarray(y_guess, dtype=float)
    for _ in range(newton):
        y = y - np.linalg.solve(monodromy(y) - np.eye(y.size), P(y) - y)
    assert np.abs(P(y) - y).max() < 1e-9  # on the orbit
    return y, np.linalg.eigvals(monodromy(y))


@pytest.fixture(scope="module")
def impacting_floquet():
    """The impacting period-1 orbit's point y*, its largest Floquet exponent log|mu_max| / T
    from the reference integrator's monodromy matrix, and that reference's own
    finite-difference error (steps 1e-4 and 1e-5 compared)."""
    model = geardyn.GearPair(**IMPACTING)
    T = model.period
    guess = geardyn.simulate(model,
                             run=geardyn.RunSettings(transient=400.0,
                                                     samples=1))["poincare"].values[-1]
    y, mu = reference_floquet(model, guess)
    assert np.all(np.abs(mu.imag) == 0) and np.all(np.abs(mu) < 1)  # stable, real
    ref = math.log(np.abs(mu).max()) / T
    _, mu5 = reference_floquet(model, y, eps=1e-5, newton=0)
    ref_err = abs(math.log(np.abs(mu5).max()) / T - ref)
    assert abs(ref + IMPACTING["zeta"]) > 0.05  # the impacts matter: not the contact value
    return model, y, ref, ref_err


def test_impacting_orbit_matches_floquet_reference(impacting_floquet):
    # a period-1 orbit with contact loss (two edge crossings per period) and real Floquet
    # multipliers: its largest exponent log|mu_max| / T comes from the reference integrator's
    # monodromy matrix, independently of the tangent kernel. The kernel must match it within
    # its statistical error plus its discretisation error (estimated by step doubling) plus
    # the reference's own finite-difference error.
    model, y, ref, ref_err = impacting_floquet
    l1 = lyapunov(model, y0=y, run=geardyn.RunSettings(transient=50.0, steps_per_period=96),
                  with_error=True, settings=geardyn.LyapunovSettings(duration=500.0))
    l2 = lyapunov(model, y0=y, run=geardyn.RunSettings(transient=50.0, steps_per_period=192),
                  with_error=True, settings=geardyn.LyapunovSettings(duration=500.0))
    disc = abs(l1.value - l2.value)
    # with the edge crossings located inside a step the exponent converges fast: 96 and 192
    # steps agree to 1e-4 relative (measured 2e-6 relative; without location the error is
    # O(h) and depends on where the crossing falls in the step, see the next test)
    assert disc < 1e-4 * abs(ref)
    for est in (l1, l2):
        assert abs(est.value - ref) < 3.0 * est.stderr + 2.0 * disc + 2.0 * ref_err + 1e-9


def test_impacting_orbit_exponent_at_every_step_count(impacting_floquet):
    """From 64 to 4096 steps per period the exponent of the impacting orbit stays within 1e-6
    (6e-5 relative) of the Floquet reference: the edge crossings are located, so the error
    is RK4's and not O(h) (measured: 3.0e-7 at 64 steps, 3e-9 from 512 on). Integrated
    across the edges (locate_edges=False) the error at 96 steps exceeds 10 % (measured 22 %):
    the bound above tells the two apart."""
    model, y, ref, ref_err = impacting_floquet
    run = dict(y0=y, settings=geardyn.LyapunovSettings(duration=500.0))
    base = RunSettings(transient=50.0)
    for n in (64, 256, 1024, 4096):
        lam = lyapunov(model, run=base.replace(steps_per_period=n), **run)
        assert abs(lam - ref) < 1e-6 + 2.0 * ref_err, (n, lam, ref)
    across = lyapunov(model, run=base.replace(steps_per_period=96, locate_edges=False), **run)
    assert abs(across - ref) > 0.1 * abs(ref), (across, ref)


def test_contact_orbit_within_error_and_rotation_bias_of_floquet_reference():
    # a period-1 orbit in permanent contact has a complex pair of Floquet multipliers of modulus
    # exp(-zeta T) (two states, trace -2 zeta): one tangent vector never aligns but rotates,
    # its stretch over N periods lying within a factor kappa (condition number of the
    # eigenvectors of the monodromy matrix M) of |mu|^N. So the finite-time exponent may be off
    # by the bias log(kappa) / D on top of its statistical error (docs/lyapunov.md, Uncertainty).
    model = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05, Omega=0.5)
    T = model.period
    guess = geardyn.simulate(model,
                             run=geardyn.RunSettings(transient=400.0,
                                                     samples=1))["poincare"].values[-1]
    y, mu = reference_floquet(model, guess)
    assert np.all(mu.imag != 0)
    ref = math.log(np.abs(mu).max()) / T
    assert abs(ref + 0.05) < 1e-8  # the reference integrator agrees with the trace
    M = np.column_stack([(geardyn.reference_solution(model, y + d, [T])[0]
                          - geardyn.reference_solution(model, y - d, [T])[0]) / 2e-4
                         for d in 1e-4 * np.eye(2)])
    kappa = np.linalg.cond(np.linalg.eig(M)[1])
    for duration in (100.0, 300.0, 1000.0):
        est = lyapunov(model, y0=y, run=geardyn.RunSettings(transient=100.0), with_error=True,
                       settings=geardyn.LyapunovSettings(duration=duration))
        bias = math.log(kappa) / (math.ceil(duration / T - 1e-9) * T)
        assert abs(est.value - ref) < 3.0 * est.stderr + bias


def test_stderr_of_chaotic_exponent_matches_spread_of_repeats():
    # the standard error of one run (batch means over 16 blocks) must describe how much
    # independent runs of the same length scatter: 8 repeats started at points of one long
    # trajectory on the attractor, 1000 time units each (measured: spread 0.0071, mean stated
    # error 0.0069). With 8 repeats the sample spread itself is uncertain by ~27 %.
    model = geardyn.GearPair(**CHAOTIC)
    n_rep, duration = 8, 1000.0
    gap = math.ceil(duration / model.period) + 10  # periods between the starts
    points = geardyn.simulate(model,
                              run=geardyn.RunSettings(transient=500.0,
                                                      samples=n_rep * gap))["poincare"].values
    runs = [lyapunov(model, y0=points[j * gap], t0=j * gap * model.period,
                     run=geardyn.RunSettings(transient=50.0),
                     with_error=True, settings=geardyn.LyapunovSettings(duration=duration))
            for j in range(n_rep)]
    values = np.array([r.value for r in runs])
    errors = np.array([r.stderr for r in runs])
    assert np.all(values > 0) and all(r.n_blocks == 16 for r in runs)
    assert 0.4 < np.std(values, ddof=1) / errors.mean() < 2.5
    # a settled periodic orbit of the same length: its blocks (whole forcing periods) repeat,
    # so its error is orders of magnitude smaller
    periodic = geardyn.GearPair(**IMPACTING)
    y = geardyn.simulate(periodic,
                         run=geardyn.RunSettings(transient=1000.0,
                                                 samples=1))["poincare"].values[-1]
    reg = lyapunov(periodic, y0=y, run=geardyn.RunSettings(transient=50.0), with_error=True,
                   settings=geardyn.LyapunovSettings(duration=duration))
    assert reg.stderr < 1e-3 * errors.min()


def test_with_error_shapes_and_nan():
    g = geardyn.GearPair(**IMPACTING)
    spec = lyapunov(g, run=geardyn.RunSettings(transient=50.0), spectrum=True, with_error=True,
                    settings=geardyn.LyapunovSettings(duration=100.0))
    assert spec.value.shape == spec.stderr.shape == (2,) and spec.value[0] > spec.value[1]
    assert np.all(spec.stderr > 0)
    short = lyapunov(g, run=geardyn.RunSettings(transient=0.0), with_error=True,
                     settings=geardyn.LyapunovSettings(duration=g.period))
    assert short.n_blocks == 1 and math.isnan(short.stderr) and math.isfinite(short.value)
    few = lyapunov(g, run=geardyn.RunSettings(transient=0.0), with_error=True,
                   settings=geardyn.LyapunovSettings(duration=3 * g.period))
    assert few.n_blocks == 3 and math.isfinite(few.stderr)  # at most one block per period
    P = g.lane_params("Omega", [1.15, 0.6])
    lam, err = lyapunov_lanes(g, P, y0=np.array([[0.5, 0.0], [1e9, 0.0]]),
                              run=RunSettings(transient=10.0),
                              settings=LyapunovSettings(duration=50.0), with_error=True)
    assert np.isfinite(lam[0]) and np.isfinite(err[0]) and np.isnan(lam[1]) and np.isnan(err[1])
    with pytest.raises(ValueError):
        lyapunov(g, settings=geardyn.LyapunovSettings(n_blocks=1))
    with pytest.raises(ValueError):
        lyapunov(g, t0=math.nan)


def test_step_convergence_chaotic():
    # a chaotic exponent is a long-time average: at n and 2n the trajectories differ, so the
    # estimates agree only to their statistical error (~2% at duration 20000, measured)
    model = geardyn.GearPair(**CHAOTIC)
    settings = geardyn.LyapunovSettings(duration=20000.0)
    l1, l2, l4 = (lyapunov(model, run=RunSettings(transient=500.0, steps_per_period=n),
                           settings=settings) for n in (64, 128, 256))
    assert abs(l1 - l2) < 0.06 * abs(l2)
    assert abs(l4 - l2) < 0.06 * abs(l2)


# ----------------------------------------------------------------------------- lanes
def test_lanes_match_single():
    model = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3)
    omegas = np.array([0.5, 0.92, 1.15])
    P = model.lane_params("Omega", omegas)
    out = lyapunov_lanes(model, P, run=RunSettings(transient=300.0, steps_per_period=64),
                         settings=LyapunovSettings(duration=600.0))
    assert out.shape == (3,)
    for om, lam in zip(omegas, out, strict=True):
        single = lyapunov(model.with_omega(om),
                          run=geardyn.RunSettings(transient=300.0, steps_per_period=64),
                          settings=geardyn.LyapunovSettings(duration=600.0))
        assert lam == pytest.approx(single, rel=1e-12, abs=1e-14)
    assert out[0] < 0 < out[1]


def test_lanes_diverged_is_nan():
    model = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05)
    P = model.lane_params("Omega", [0.5, 0.6])
    out = lyapunov_lanes(model, P, y0=np.array([[1.1, 0.0], [1e9, 0.0]]),
                         run=RunSettings(transient=10.0), settings=LyapunovSettings(duration=20.0))
    assert np.isfinite(out[0]) and np.isnan(out[1])


def test_lanes_autonomous():
    u = lorenz_model()
    P = np.tile(LORENZ, (2, 1))
    P[1, 1] = 0.5  # rho < 1: the origin is a stable node
    out = lyapunov_lanes(u, P, y0=[1.0, 1.0, 1.0], run=RunSettings(transient=50.0),
                         settings=LyapunovSettings(duration=500.0))
    assert abs(out[0] - LORENZ_LAMBDA1) < 0.05
    # largest eigenvalue of the Jacobian at the origin: the slowest decay
    sigma, rho = LORENZ[0], 0.5
    slow = 0.5 * (-(sigma + 1.0) + math.sqrt((sigma + 1.0) ** 2 - 4.0 * sigma * (1.0 - rho)))
    assert abs(out[1] - slow) < 1e-3


# ----------------------------------------------------------------------------- errors
def test_bad_arguments():
    g = geardyn.GearPair()
    with pytest.raises(ValueError):
        lyapunov(g, settings=geardyn.LyapunovSettings(duration=0.0))
    with pytest.raises(ValueError):
        lyapunov(g, settings=geardyn.LyapunovSettings(dt=0.01))
    with pytest.raises(ValueError):
        lyapunov(lorenz_model(), run=geardyn.RunSettings(transient=100.0, steps_per_period=64))
    with pytest.raises(ValueError):
        lyapunov(g, y0=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError):
        lyapunov(g, settings=geardyn.LyapunovSettings(renorm_every=0))


# ----------------------------------------------------------------------------- start time
def test_sweep_exponent_continues_its_lane_in_both_forcing_phases():
    """Fig. 14's load fluctuation (Lambda = 2) at Omega = 2: the mesh and load forcings share one
    period, so the motion depends on their relative phase. A continued sweep restarts the mesh
    phase at each point but keeps the absolute time of the load, so the point Omega = 2 reached
    from Omega = 2 + d runs at the relative phase Lambda T0 of its start time T0. Its exponent
    must be that of this system: equal (bitwise) to geardyn.lyapunov from the same state at the
    same time, equal within the errors to an independent run of that system from the model's
    initial state (long transient), and clearly unlike the restart at time 0 (load phase 0),
    which the sweep's exponent used to be."""
    model = build_model(builtin_study("paper_fig14"))
    lam_load = model.params[catt_kernels.LAMBDA]
    assert lam_load == 2.0
    samples = 512
    for first in 2.0 + 0.002 * np.arange(1, 12):  # find a start whose load phase is far from 0
        values = np.array([first, 2.0])
        ds = geardyn.bifurcation(model, "Omega", values,
                                 run=geardyn.RunSettings(transient=600.0, samples=samples),
                                 continuation="down", lyapunov=True)
        t_final = float(ds["final_time"].values[1])
        if 2.6 < (lam_load * t_final) % (2.0 * math.pi) < 5.8:
            break
    else:
        pytest.fail("no continued sweep reached Omega = 2 at a load phase in (2.6, 5.8)")
    m = model.with_omega(2.0)
    # as bifurcation does: 200 time units to align, then as long as the sampling (mean period)
    duration = samples * float(np.mean(2.0 * math.pi / values))
    kw = dict(run=RunSettings(transient=200.0,
                              steps_per_period=int(ds["steps_per_period"].values[1])),
              settings=geardyn.LyapunovSettings(duration=duration), with_error=True)
    same = geardyn.lyapunov(m, y0=ds["poincare"].values[1, -1], t0=t_final, **kw)
    assert ds["lyapunov"].values[1] == same.value
    assert ds["lyapunov_err"].values[1] == same.stderr
    fresh = geardyn.lyapunov(m, t0=t_final,
                             run=geardyn.RunSettings(transient=1000.0), with_error=True,
                             settings=geardyn.LyapunovSettings(duration=duration))
    assert abs(fresh.value - same.value) < 3.0 * (fresh.stderr + same.stderr)
    zero = geardyn.lyapunov(m, y0=ds["poincare"].values[1, -1], t0=0.0, **kw)
    assert abs(zero.value - same.value) > 3.0 * (zero.stderr + same.stderr)


# ----------------------------------------------------------------------------- split limit
N_LEVELS = 20


def levels_model(n_cross: int) -> geardyn.UserModel:
    """x' = 1, y' = -y with N_LEVELS switching functions x - c_j (smooth field: only the edge
    location sees them), n_cross of the levels inside (0, 1) (crossed in the first step of
    dt = 1), the rest at -10 (never crossed)."""
    levels = np.full(N_LEVELS, -10.0)
    levels[:n_cross] = 0.05 + 0.9 * np.arange(n_cross) / N_LEVELS
    return geardyn.UserModel(drift_decay_rhs, 2, params=levels, events=levels_events,
                             n_events=N_LEVELS)


def test_split_limit_is_reported():
    """A grid step that crosses more distinct edges than the split limit (MAX_SPLITS = 16 located
    crossings per step) falls back unsplit: counted per row (the state and its 2 k
    finite-difference neighbours each cross all the levels in the first step) and the lane's
    status is SPLIT_LIMIT, in the one-lane and in the lane-block kernel; 10 levels are located
    cleanly. The field is smooth, so the exponents stay those of x' = 1, y' = -y."""
    from geardyn.solvers._step_shared import MAX_SPLITS

    assert 10 < MAX_SPLITS < N_LEVELS
    run = dict(y0=[0.0, 1.0], run=RunSettings(transient=0.0),
               settings=geardyn.LyapunovSettings(duration=5.0, dt=1.0))
    clean = lyapunov(levels_model(10), with_error=True, **run)
    assert clean.status == geardyn.Status.OK and clean.unresolved == 0 and clean.ok
    model = levels_model(N_LEVELS)
    est = lyapunov(model, with_error=True, **run)
    assert est.status == geardyn.Status.SPLIT_LIMIT and not est.ok
    assert est.unresolved == 3  # k = 1: three rows, one step each
    assert abs(est.value) < 2e-3  # x' = 1: exponent 0 (finite-time: log(cond) / T)
    spec = lyapunov(model, spectrum=True, with_error=True, **run)
    assert spec.unresolved == 5 and spec.status == geardyn.Status.SPLIT_LIMIT
    assert abs(spec.value[1] + 1.0) < 0.03
    with pytest.warns(RuntimeWarning, match="split limit"):
        assert lyapunov(model, **run) == est.value
    # the lane blocks: every lane reports it, the exponent kept (not NaN)
    P = np.tile(model.params, (3, 1))
    exps, errs, unres, status = lyapunov_lanes(model, P, y0=[0.0, 1.0],
                                               run=RunSettings(transient=0.0),
                                               settings=LyapunovSettings(duration=5.0, dt=1.0),
                                               with_status=True)
    assert np.array_equal(unres, [3, 3, 3])
    assert np.all(status == geardyn.Status.SPLIT_LIMIT)
    assert np.array_equal(exps, np.full(3, est.value))
    assert np.array_equal(errs, np.full(3, est.stderr))


def test_run_settings():
    """lyapunov(run=RunSettings(...)) is lyapunov with the same (deprecated) keywords; not
    both."""
    g = geardyn.GearPair(**IMPACTING)
    kw = dict(transient=60.0, steps_per_period=64, bound=1e5)
    with pytest.warns(DeprecationWarning, match=r"lyapunov\(transient=, steps_per_period=, "
                                                r"bound=\) is deprecated"):
        a = lyapunov(g, with_error=True, **kw, settings=geardyn.LyapunovSettings(duration=100.0))
    b = lyapunov(g, run=geardyn.RunSettings(**kw), with_error=True,
                 settings=geardyn.LyapunovSettings(duration=100.0))
    assert a == b
    # locate_edges=False: the edges are integrated across (a different exponent at this step)
    c = lyapunov(g, run=geardyn.RunSettings(locate_edges=False, **kw),
                 settings=geardyn.LyapunovSettings(duration=100.0))
    assert c != a.value and abs(c - a.value) < 0.05
    with pytest.raises(TypeError, match="not both"):
        lyapunov(g, run=geardyn.RunSettings(), transient=10.0)
    with pytest.raises(TypeError, match="samples"):
        lyapunov(g, samples=10)
    with pytest.raises(ValueError, match="steps_per_period"):
        lyapunov(g, run=geardyn.RunSettings(transient=100.0, steps_per_period=2))
