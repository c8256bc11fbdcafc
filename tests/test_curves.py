"""Two-parameter curves of fold and period-doubling points (geardyn.curve) against independent
results: the damped Mathieu equation's instability boundary by an adaptive integrator, and the
hysteresis of up and down sweeps on a grid."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import geardyn
from geardyn import ContinuedSweep, continued_sweeps
from geardyn.analysis.curve_systems import compound2
from geardyn.testing import assert_result

ZETA = 0.02


@pytest.fixture(scope="module")
def mathieu():
    """The gear pair kept in contact (mean load 1, no transmission error): about its
    periodic orbit u = x - 1 obeys u'' + 2 zeta u' + (1 + kappa cos(Omega t)) u = Fm, whose
    variational equation is the damped Mathieu equation."""
    m = geardyn.GearPair(zeta=ZETA, Fm=1.0, Fa=0.0, kappa=0.3)
    br = geardyn.continuation(m, "Omega", 1.6, 2.4)
    return m, br


@pytest.fixture(scope="module")
def softening():
    """The gear pair with contact loss (a softening response with a hysteresis loop)."""
    m = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05, kappa=0.0)
    br = geardyn.continuation(m, "Omega", 0.6, 1.4)
    return m, br


def _mathieu_pd_test(omega: float, kappa: float) -> float:
    """det(M + I) of the damped Mathieu equation over one period 2 pi / Omega (DOP853, rtol
    1e-10): zero where a Floquet multiplier is -1."""
    T = 2 * math.pi / omega

    def f(t, y):
        return [y[1], -2 * ZETA * y[1] - (1 + kappa * math.cos(omega * t)) * y[0]]

    cols = [solve_ivp(f, (0.0, T), e, method="DOP853", rtol=1e-10, atol=1e-12).y[:, -1]
            for e in ([1.0, 0.0], [0.0, 1.0])]
    return float(np.linalg.det(np.column_stack(cols) + np.eye(2)))


def test_period_doubling_curve_is_the_mathieu_instability_boundary(mathieu):
    m, br = mathieu
    kinds = br["bifurcation_kind"].values.tolist()
    assert kinds == ["period-doubling", "period-doubling"]
    c = geardyn.curve(m, br, 0, "kappa", 0.0)
    assert_result(c, "curve")
    assert c.attrs["curve_kind"] == "period_doubling"
    # from one edge of the principal zone round its tip (kappa ~ 4 zeta) to the other edge
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert float(c["kappa"].min()) < 0.1
    assert float(c["Omega"][-1]) == pytest.approx(float(br["bifurcation_value"][1]), abs=1e-6)
    mu = c["multiplier_real"].values + 1j * c["multiplier_imag"].values
    assert np.all(np.min(np.abs(mu + 1.0), axis=1) < 1e-6)
    # the boundary by an independent integrator, root-found in Omega at the curve's kappa
    om, kap = c["Omega"].values, c["kappa"].values
    picks = [i for i in np.linspace(0, om.size - 1, 9).astype(int) if kap[i] > 0.12]
    assert {bool(om[i] < 2.0) for i in picks} == {True, False}  # both edges
    for i in picks:
        ref = brentq(lambda w, k=kap[i]: _mathieu_pd_test(w, k), om[i] - 0.01, om[i] + 0.01,
                     xtol=1e-12)
        assert abs(om[i] - ref) < 1e-6, (kap[i], om[i], ref)
    # contact kept along the curve (the Mathieu reduction holds): no crossings of an edge
    for i in picks[:2]:
        orb = geardyn.periodic_orbit(m.with_params(kappa=float(kap[i])), omega=float(om[i]))
        assert set(orb.mesh_crossings().values()) == {0}
    # a linear system's doubling is degenerate (c = 0 to round-off): no codimension-2 point
    assert c.sizes["special"] == 0


def test_fold_curves_meet_in_a_cusp_that_bounds_the_hysteresis(softening):
    m, br = softening
    folds = [i for i, k in enumerate(br["bifurcation_kind"].values) if k == "fold"]
    assert len(folds) == 2
    c = geardyn.curve(m, br, folds[0], "Fa", 0.0)
    assert_result(c, "curve")
    # down from one fold, round the cusp, up to the branch's other fold at Fa = 0.05
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert float(c["Fa"][-1]) == pytest.approx(0.05, abs=1e-12)
    assert float(c["Omega"][-1]) == pytest.approx(float(br["bifurcation_value"][folds[1]]),
                                                  abs=1e-6)
    kinds = c["special_kind"].values.tolist()
    assert kinds == ["cusp"]
    cusp_om, cusp_fa = float(c["special_x"][0]), float(c["special_y"][0])
    assert c["special_error"].values[0] < 1e-4
    # one-parameter continuation in Omega 0.5 % above the cusp folds twice near it, 0.5 % below
    # not at all
    for f, folds_wanted in ((cusp_fa * 1.005, 2), (cusp_fa * 0.995, 0)):
        near = geardyn.continuation(m.with_params(Fa=f), "Omega", 0.85, 1.1)
        got = near["bifurcation_value"].values[near["bifurcation_kind"].values == "fold"]
        assert got.size == folds_wanted, (f, got)
        assert np.all(np.abs(got - cusp_om) < 0.005)
    # the two arms of the curve, either side of its lowest Fa
    om, fa = c["Omega"].values, c["Fa"].values
    tip = int(np.argmin(fa))
    assert abs(fa[tip] - cusp_fa) < 1e-3 and abs(om[tip] - cusp_om) < 0.01
    arms = [(fa[: tip + 1][::-1], om[: tip + 1][::-1]), (fa[tip:], om[tip:])]
    for f, _ in arms:
        assert np.all(np.diff(f) > 0)
    # up and down sweeps on a grid: coexisting responses exactly between the fold curves
    grid = np.arange(0.60, 1.0001, 0.01)
    rows = [0.005, 0.01, 0.02, 0.03, 0.04, 0.05]
    run = geardyn.RunSettings(transient=400.0, continued_transient=100.0, converge=1e-8,
                              transient_max=1500.0, samples=2)
    sweeps = [ContinuedSweep(m.with_params(Fa=f), "Omega", grid, d, run=run)
              for f in rows for d in ("up", "down")]
    out = continued_sweeps(sweeps, run=run)
    for k, f in enumerate(rows):
        up, down = out[2 * k], out[2 * k + 1]
        assert up["converged"].values.min() == 1 and down["converged"].values.min() == 1
        both = np.max(np.abs(up["poincare"].values - down["poincare"].values), axis=(1, 2)) > 1e-3
        if f < cusp_fa:
            assert not both.any(), f
            continue
        lo, hi = sorted(float(np.interp(f, fa_arm, om_arm)) for fa_arm, om_arm in arms)
        inside = (grid > lo) & (grid < hi)
        near = np.minimum(np.abs(grid - lo), np.abs(grid - hi)) < 0.01
        assert both.any(), f
        assert np.array_equal(both[~near], inside[~near]), (f, lo, hi, both.astype(int))


def test_bad_input_names_the_value(softening):
    m, br = softening
    contact = int(np.flatnonzero(br["bifurcation_kind"].values == "contact")[0])
    fold = int(np.flatnonzero(br["bifurcation_kind"].values == "fold")[0])
    with pytest.raises(KeyError, match="nonsense"):
        geardyn.curve(m, br, fold, "nonsense", 1.0)
    with pytest.raises(ValueError, match="leave x_scale, y_scale and locate_tol unset"):
        geardyn.curve(m, br, contact, "Fa", 0.0, settings=geardyn.CurveSettings(x_scale=1.0))
    with pytest.raises(ValueError, match="y_stop must be finite"):
        geardyn.curve(m, br, contact, "Fa", 0.05)
    with pytest.raises(ValueError, match="bifurcation=17 is not an index"):
        geardyn.curve(m, br, 17, "Fa", 0.0)
    with pytest.raises(ValueError, match="y_stop=0.05"):
        geardyn.curve(m, br, fold, "Fa", 0.05)
    with pytest.raises(ValueError, match="'Omega'"):
        geardyn.curve(m, br, fold, "Omega", 1.0)
    with pytest.raises(ValueError, match="geardyn_kind='frequency-response'"):
        geardyn.curve(m, br.assign_attrs(geardyn_kind="frequency-response"), fold, "Fa", 0.0)
    with pytest.raises(ValueError, match="locate_tol"):
        geardyn.CurveSettings(locate_tol=-1.0)


def test_second_compound_matrix_has_the_pair_products():
    rng = np.random.default_rng(3)
    M = rng.normal(size=(4, 4))
    mu = np.linalg.eigvals(M)
    products = [mu[i] * mu[j] for i in range(4) for j in range(i + 1, 4)]
    got = np.linalg.eigvals(compound2(M))
    assert np.allclose(np.sort_complex(got), np.sort_complex(np.array(products)), atol=1e-10)


def test_neimark_sacker_curve_of_the_forced_van_der_pol_oscillator_and_its_1_1_points():
    """x'' - mu (1 - x^2) x' + x = F cos(Omega t): the entrained orbit loses stability to a
    torus as F falls (a complex pair through |mu| = 1). Its Neimark-Sacker curve in (F, Omega)
    ends, near Omega = 1 either side, at a 1:1 resonance (the pair at +1), where it goes on as
    a neutral saddle. Checked by DOP853 at rtol 1e-10 from the curve's section points: the
    orbit closes, det M = 1 with a complex pair on the curve, tr M = 2 at the 1:1 points."""
    from shared_models import oscillator

    mu, om0 = 0.2, 1.1
    m = oscillator(Omega=om0, mu=mu, F=0.5, natural_frequency=1.0)
    br = geardyn.continuation(m, "F", 0.5, 0.2)
    ns = [i for i, k in enumerate(br["bifurcation_kind"].values) if k == "neimark-sacker"]
    assert len(ns) == 1
    c = geardyn.curve(m, br, ns[0], "Omega", 0.9)
    assert_result(c, "curve")
    assert c.attrs["curve_kind"] == "neimark_sacker"
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert c["special_kind"].values.tolist() == ["resonance_1_1", "resonance_1_1"]
    sy = c["special_y"].values
    assert sy[0] > 1.0 > sy[1]

    def monodromy(x0, F, om):
        T = 2 * math.pi / om

        def f(t, y):
            x, v = y[0], y[1]
            Phi = y[2:].reshape(2, 2)
            A = np.array([[0.0, 1.0], [-1.0 - 2 * mu * x * v, mu * (1 - x * x)]])
            return np.concatenate([[v, mu * (1 - x * x) * v - x + F * math.cos(om * t)],
                                   (A @ Phi).ravel()])

        y = solve_ivp(f, (0.0, T), np.concatenate([x0, np.eye(2).ravel()]), method="DOP853",
                      rtol=1e-10, atol=1e-12).y[:, -1]
        return y[:2], y[2:].reshape(2, 2)

    F, om = c["F"].values, c["Omega"].values
    cos_theta = c["test_resonance_1_1"].values + 1.0
    on_ns = [i for i in range(0, F.size, 7) if abs(cos_theta[i]) < 0.99]
    assert len(on_ns) >= 3
    for i in on_ns:
        x0 = c["section_point"].values[i]
        end, M = monodromy(x0, F[i], om[i])
        assert np.max(np.abs(end - x0)) < 1e-6
        assert abs(np.linalg.det(M) - 1.0) < 1e-6
        assert np.trace(M) ** 2 < 4 * np.linalg.det(M)  # a complex pair
    for j in range(2):
        x0 = c["special_section_point"].values[j]
        end, M = monodromy(x0, float(c["special_x"][j]), float(sy[j]))
        assert np.max(np.abs(end - x0)) < 1e-6
        assert abs(np.linalg.det(M) - 1.0) < 1e-6 and abs(np.trace(M) - 2.0) < 1e-5


def test_curve_ends_on_the_x_bound_and_reports_progress(softening):
    m, br = softening
    fold = int(np.flatnonzero(br["bifurcation_kind"].values == "fold")[0])
    seen: list[tuple[int, float, float]] = []
    c = geardyn.curve(m, br, fold, "Fa", 0.0, x_range=(0.6, 0.9),
                      progress=lambda k, x, y: seen.append((k, x, y)))
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED)
    assert float(c["Omega"][-1]) == pytest.approx(0.9, abs=1e-12), c.attrs["message"]
    assert "reached Omega=0.9" in c.attrs["message"]
    assert [k for k, _, _ in seen] == list(range(1, c.sizes["point"] + 1))
    with pytest.raises(ValueError, match="x_range"):
        geardyn.curve(m, br, fold, "Fa", 0.0, x_range=(0.9, 1.0))


def test_generalised_period_doubling_of_the_mathieu_oscillator_with_cubic_damping():
    """x'' + 2 zeta x' + rho x^2 x' + (1 + kappa cos(Omega t)) x = 0: x = 0 doubles its period
    on the damped Mathieu equation's zone boundary whatever rho (a vertical curve in
    (Omega, rho)); rho alone makes the map cubic, so the normal-form coefficient c is exactly
    linear in rho: positive (supercritical) for rho > 0, zero at rho = 0, the generalised
    period doubling."""
    from shared_models import oscillator

    m = oscillator(Omega=1.6, zeta=ZETA, kappa=0.3, rho=0.5, natural_frequency=1.0)
    br = geardyn.continuation(m, "Omega", 1.6, 2.4, guess=np.zeros(2))
    assert br["bifurcation_kind"].values[0] == "period-doubling"
    c = geardyn.curve(m, br, 0, "rho", -0.5)
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    edge = brentq(lambda w: _mathieu_pd_test(w, 0.3), 1.8, 1.9, xtol=1e-12)
    assert np.max(np.abs(c["Omega"].values - edge)) < 1e-6
    assert c["special_kind"].values.tolist() == ["generalised_period_doubling"]
    assert abs(float(c["special_y"][0])) < 1e-6 and abs(float(c["special_x"][0]) - edge) < 1e-6
    rho, coef = c["rho"].values, c["test_generalised_period_doubling"].values
    far = np.abs(rho) > 0.05
    assert np.all(coef[far] * rho[far] > 0)
    ratio = coef[far] / rho[far]
    assert np.ptp(ratio) < 1e-3 * abs(ratio.mean())


def test_curve_at_from_a_guess_without_a_branch(mathieu):
    m, br = mathieu
    from_branch = geardyn.curve(m, br, 0, "kappa", 0.5)
    x0 = br["bifurcation_section_point"].values[0]
    om0 = float(br["bifurcation_value"][0])
    c = geardyn.curve_at(m, "period_doubling", "Omega", om0 + 0.01, x0 * 1.01, "kappa", 0.5)
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert float(c["Omega"][0]) == pytest.approx(om0, abs=1e-6)
    assert float(c["Omega"][-1]) == pytest.approx(float(from_branch["Omega"][-1]), abs=1e-6)
    with pytest.raises(ValueError, match="kind must be one of.*'flip'"):
        geardyn.curve_at(m, "flip", "Omega", om0, x0, "kappa", 0.5)
    with pytest.raises(ValueError, match="guess must be 2 finite numbers"):
        geardyn.curve_at(m, "fold", "Omega", om0, [1.0], "kappa", 0.5)
    lost = geardyn.curve_at(m, "fold", "Omega", om0, x0, "kappa", 0.5)  # no fold there
    assert lost.attrs["status"] == int(geardyn.BranchStatus.START_FAILED)
    assert lost.sizes["point"] == 0 and "no fold point at Omega=1.85" in lost.attrs["message"]
    assert_result(lost, "curve")


def test_a_curve_leaving_the_valid_region_ends_with_a_message(mathieu):
    m, br = mathieu
    c = geardyn.curve(m, br, 1, "kappa", 1.5)  # |kappa| < 1 keeps the stiffness positive
    assert c.attrs["status"] == int(geardyn.BranchStatus.INVALID)
    assert "kappa: must be < 1" in c.attrs["message"]
    assert 0.999 < float(c["kappa"].max()) < 1.0


def test_a_contact_change_gives_its_grazing_curve(softening):
    """geardyn.curve from a branch's contact change follows the edge its orbit grazes: for the
    softening pair's first one (contact lost), the drive flank's contact-loss curve, whose
    closed form for kappa = 0 is Fa = Fm |1 - Omega^2 + 2 i zeta Omega| / Omega^2 (see
    tests/test_grazing_curves.py)."""
    m, br = softening
    contacts = np.flatnonzero(br["bifurcation_kind"].values == "contact")
    first = int(contacts[0])
    seen: list[int] = []
    c = geardyn.curve(m, br, first, "Fa", 0.3, progress=lambda k, x, y: seen.append(k))
    assert_result(c, "curve")
    assert c.attrs["curve_kind"] == "grazing" and c.attrs["flank"] == "drive"
    om, fa = c["Omega"].values, c["Fa"].values
    inside = (fa >= 0.05) & (fa <= 0.3)
    assert inside.sum() > 5 and seen
    exact = 0.1 * np.abs(1 - om**2 + 2j * 0.05 * om) / om**2
    np.testing.assert_allclose(fa, exact, rtol=2e-5)
    at = float(br["bifurcation_value"][first])
    assert np.min(np.hypot(om - at, fa - 0.05)) < 1e-3
    # in the box the branch's range of Omega by [0.05, 0.3], left at both ends
    assert c.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), c.attrs["message"]
    assert c.attrs["message"].count("left the box Omega in [0.6, 1.4], Fa in [0.05, 0.3]") == 2
