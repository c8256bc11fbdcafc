"""Bifurcation detection of geardyn.continuation against independent results: branch points
(det(M - I)) at the harmonic instability zone of the damped Mathieu equation (zone boundaries by
DOP853 and brentq), no Neimark-Sacker point where only a real pair's product passes 1 (DOP853
monodromy; spectator multipliers known in closed form), a period-2 bubble that ends when it
retraces itself (the damped Mathieu zone with amplitude-dependent damping), a failed or
misplaced location kept with its bracket (the Mathieu-Hill zone boundaries), and a corrector
jump rejected (the analytic response)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import geardyn
import geardyn.testing
from branch_cases import duffing_with_spectators
from geardyn import BranchStatus
from geardyn.plotting.branch import plot_branch
from shared_models import oscillator


def _monodromy(f, n: int, T: float, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(end state, monodromy) of y' = f(t, y) over [0, T] from x0 by DOP853 (rtol 1e-12) on
    the state and its variational equation, the Jacobian by central differences of f."""
    def rhs(t, w):
        y, Phi = w[:n], w[n:].reshape(n, n)
        J = np.empty((n, n))
        for q in range(n):
            e = np.zeros(n)
            e[q] = 1e-6
            J[:, q] = (np.asarray(f(t, y + e)) - np.asarray(f(t, y - e))) / 2e-6
        return np.concatenate([f(t, y), (J @ Phi).ravel()])

    w = solve_ivp(rhs, (0.0, T), np.concatenate([x0, np.eye(n).ravel()]), method="DOP853",
                  rtol=1e-12, atol=1e-13).y[:, -1]
    return w[:n], w[n:].reshape(n, n)


# ----------------------------------------------------------------------------- test functions
def _block(mu_real: list[float], pairs: list[complex]) -> np.ndarray:
    """A monodromy with the real multipliers ``mu_real`` and the complex pairs ``pairs``."""
    blocks = [np.array([[m]]) for m in mu_real]
    blocks += [np.array([[c.real, -c.imag], [c.imag, c.real]]) for c in pairs]
    n = sum(b.shape[0] for b in blocks)
    M, k = np.zeros((n, n)), 0
    for b in blocks:
        M[k:k + b.shape[0], k:k + b.shape[0]] = b
        k += b.shape[0]
    return M


def _monitors(M: np.ndarray, tangent_p: float = 1.0) -> dict:
    from geardyn.analysis.branch import monitor_functions

    mu = np.linalg.eigvals(M)
    return monitor_functions(M, mu[np.argsort(-np.abs(mu), kind="stable")], tangent_p)


def test_constructed_multipliers_real_pair_product_through_one_is_not_neimark_sacker():
    from geardyn.analysis.branch import NS_MODULUS_TOL, detected, neimark_sacker_pair

    spectator = 0.6 * np.exp(1j)  # a complex pair well inside the unit circle
    # a real multiplier grows from 1.5 to 2.5 next to 0.5: their product passes 1 at 2
    a, b = _block([1.5, 0.5], [spectator]), _block([2.5, 0.5], [spectator])
    assert ("neimark-sacker", "ns") in detected(_monitors(a), _monitors(b))  # the candidate
    at = np.linalg.eigvals(_block([2.0, 0.5], [spectator]))  # where the product is 1
    assert neimark_sacker_pair(at) is None
    # a complex pair through the unit circle is one, at |mu| within the tolerance
    a, b = _block([0.5, 0.3], [0.9 * np.exp(1j)]), _block([0.5, 0.3], [1.1 * np.exp(1j)])
    assert ("neimark-sacker", "ns") in detected(_monitors(a), _monitors(b))
    c = neimark_sacker_pair(np.linalg.eigvals(_block([0.5, 0.3], [np.exp(1j)])))
    assert c is not None and abs(c - np.exp(1j)) < 1e-12
    near = np.linalg.eigvals(_block([0.5], [(1 + 0.5 * NS_MODULUS_TOL) * np.exp(1j)]))
    far = np.linalg.eigvals(_block([0.5], [(1 + 2 * NS_MODULUS_TOL) * np.exp(1j)]))
    assert neimark_sacker_pair(near) is not None and neimark_sacker_pair(far) is None
    # +1: with a turn a fold; without one (or a turn alone) a branch point
    one_a, one_b = _block([0.9, 0.5], []), _block([1.1, 0.5], [])
    assert detected(_monitors(one_a, 1.0), _monitors(one_b, -1.0)) == [("fold", "fold")]
    assert detected(_monitors(one_a, 1.0), _monitors(one_b, 1.0)) == [("branch point", "bp")]
    assert detected(_monitors(one_a, 1.0), _monitors(one_a, -1.0)) == [
        ("branch point", "fold")]
    # a neutral multiplier (exactly +1 at both points): det(M - I) is round-off, a turn a fold
    neutral_a, neutral_b = _block([1.0 - 1e-12, 0.5], []), _block([1.0 + 1e-12, 0.6], [])
    assert detected(_monitors(neutral_a, 1.0), _monitors(neutral_b, -1.0)) == [("fold", "fold")]
    assert detected(_monitors(neutral_a, 1.0), _monitors(neutral_b, 1.0)) == []
    # -1: a period doubling
    assert detected(_monitors(_block([-0.9, 0.5], [])), _monitors(_block([-1.1, 0.5], []))
                    ) == [("period-doubling", "pd")]


# ----------------------------------------------------------------------------- NS
DUFFING = dict(zeta=0.05, beta=0.2, F=0.3, c=0.05, zu=0.1)


def _duffing(om: float):
    p = DUFFING

    def f(t, y):
        return [y[1], -2 * p["zeta"] * y[1] - y[0] - p["beta"] * y[0] ** 3
                + p["F"] * math.cos(om * t), -p["c"] * y[2], y[4],
                -2 * p["zu"] * y[4] - y[3]]
    return f


@pytest.mark.slow  # ~2.5 min, mostly its five-state model's compile; CI runs it (make test-slow)
def test_real_pair_product_through_one_is_not_a_neimark_sacker_point():
    """A hardening Duffing oscillator with two uncoupled linear spectators: y' = -c y (the real
    multiplier exp(-c T)) and a damped oscillator (the complex pair exp((-zu +- i sqrt(1 -
    zu^2)) T), |mu| = exp(-zu T) ~ 0.6). On the unstable branch between the folds the Duffing
    multiplier passes exp(c T), so the product test prod (mu_i mu_j - 1) changes sign while a
    complex pair exists: no Neimark-Sacker point (the DOP853 monodromy there has no multiplier
    on the unit circle but the real product 1)."""
    p = DUFFING
    m = geardyn.UserModel(duffing_with_spectators, n_states=5,
                          params=[0.8, p["zeta"], p["beta"], p["F"], p["c"], p["zu"]],
                          param_names=["Omega", "zeta", "beta", "F", "c", "zu"],
                          natural_frequency=1.0)
    ds = geardyn.continuation(m, "Omega", 0.8, 2.0)
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    kinds = list(ds["bifurcation_kind"].values)
    assert kinds == ["fold", "fold"], kinds
    om = ds["Omega"].values
    T = 2 * math.pi / om
    mu = ds["multiplier_real"].values + 1j * ds["multiplier_imag"].values
    w = math.sqrt(1 - p["zu"] ** 2)
    for want in (np.exp(-p["c"] * T), np.exp((-p["zu"] + 1j * w) * T),
                 np.exp((-p["zu"] - 1j * w) * T)):
        assert np.max(np.min(np.abs(mu - want[:, None]), axis=1)) < 1e-6
    # the largest (Duffing) multiplier times exp(-c T) passes 1 on the middle branch
    g = np.abs(mu[:, 0]) * np.exp(-p["c"] * T) - 1.0
    cross = np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))
    assert cross.size == 2
    j = int(cross[0]) + int(abs(g[cross[0] + 1]) < abs(g[cross[0]]))
    x = ds["section_point"].values[j]
    end, M = _monodromy(_duffing(float(om[j])), 5, float(T[j]), x)
    assert np.max(np.abs(end - x)) < 1e-6
    ref = np.linalg.eigvals(M)
    assert np.max(np.abs(np.sort_complex(ref) - np.sort_complex(mu[j]))) < 1e-5
    cplx = ref[np.abs(ref.imag) > 1e-6]
    assert cplx.size == 2 and abs(abs(cplx[0]) - 1) > 0.3  # the pair far from the circle
    real = np.sort(ref[np.abs(ref.imag) <= 1e-6].real)
    assert abs(real[-1] * math.exp(-p["c"] * T[j]) - 1) < 0.05  # the real product ~ 1


# ----------------------------------------------------------------------------- branch points
def _mathieu_det(om: float, zeta: float, kappa: float, sign: float) -> float:
    """det(M + sign I) of x'' + 2 zeta x' + (1 + kappa cos(Omega t)) x = 0 over one period
    (DOP853): zero where a multiplier is -sign (sign -1: a boundary of the harmonic zone, +1:
    of the principal one)."""
    def f(t, z):
        J = np.array([[0.0, 1.0], [-(1.0 + kappa * math.cos(om * t)), -2.0 * zeta]])
        return (J @ z.reshape(2, 2)).ravel()

    M = solve_ivp(f, (0.0, 2 * math.pi / om), np.eye(2).ravel(), method="DOP853", rtol=1e-12,
                  atol=1e-14).y[:, -1].reshape(2, 2)
    return float(np.linalg.det(M + sign * np.eye(2)))


def test_trivial_mathieu_branch_has_branch_points_at_the_harmonic_zone_boundaries():
    """x = 0 is a periodic orbit of the damped Mathieu equation at every Omega; near Omega = 1
    (the harmonic zone) a real multiplier passes +1 and back with no turn of the parameter:
    two branch points, where det(M - I) of the DOP853 monodromy vanishes."""
    zeta, kappa = 0.002, 0.4
    m = _parametric(zeta, kappa)
    ds = geardyn.continuation(m, "Omega", 0.9, 1.1, guess=np.zeros(2))
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    grid = np.linspace(0.9, 1.1, 21)
    f = [_mathieu_det(o, zeta, kappa, -1.0) for o in grid]
    edges = [brentq(_mathieu_det, grid[i], grid[i + 1], args=(zeta, kappa, -1.0), xtol=1e-13)
             for i in range(grid.size - 1) if np.sign(f[i]) != np.sign(f[i + 1])]
    assert len(edges) == 2
    assert list(ds["bifurcation_kind"].values) == ["branch point"] * 2
    assert np.all(ds["bifurcation_located"].values == 1)
    assert np.max(np.abs(ds["bifurcation_value"].values - edges)) < 1e-6
    assert np.max(ds["bifurcation_error"].values) < 1e-6
    crit = ds["bifurcation_multiplier_real"].values + 1j * ds["bifurcation_multiplier_imag"]
    assert np.max(np.abs(crit - 1.0)) < 1e-5
    om, st = ds["Omega"].values, ds["stability"].values
    assert set(st[(om > edges[0]) & (om < edges[1])]) == {"unstable"}
    assert set(st[(om < edges[0]) | (om > edges[1])]) == {"stable"}
    geardyn.testing.assert_result(ds, "continuation")


ZETA, KAPPA = 0.05, 0.4


@pytest.fixture(scope="module")
def zone() -> list[float]:
    """The principal zone's boundaries (multiplier -1), DOP853 + brentq."""
    return [brentq(_mathieu_det, a, b, args=(ZETA, KAPPA, 1.0), xtol=1e-12)
            for a, b in ((1.5, 2.0), (2.0, 2.6))]


# ----------------------------------------------------------------------------- retrace
def _parametric(zeta: float, kappa: float, mu: float = 1.0) -> geardyn.UserModel:
    """x'' + 2 zeta x' + mu x^2 x' + (1 + kappa cos(Omega t)) x = 0 (mu: the oscillator's
    Rayleigh damping rho)."""
    return oscillator(Omega=1.5, zeta=zeta, kappa=kappa, rho=mu, natural_frequency=1.0)


def test_period_two_bubble_rejoins_at_the_second_doubling_and_ends_there(zone):
    """x'' + 2 zeta x' + mu x^2 x' + (1 + kappa cos(Omega t)) x = 0: x = 0 doubles its period
    at both boundaries of the principal zone (det(M + I) = 0 of the damped Mathieu equation,
    DOP853 + brentq); the amplitude-dependent damping closes the period-2 branch into a bubble
    between them. Each switched branch records a branch point at the other boundary, where it
    meets x = 0 and turns back onto its own orbits, and ends there as retracing; its points
    are fixed points of the DOP853 twice-iterated map."""
    ds = geardyn.continuation(_parametric(ZETA, KAPPA), "Omega", 1.6, 2.4, guess=np.zeros(2),
                              switch=True,
                              settings=geardyn.ContinuationSettings(max_period=2, max_points=200))
    kind, value = ds["bifurcation_kind"].values, ds["bifurcation_value"].values
    on = ds["bifurcation_branch"].values
    assert list(kind[on == 0]) == ["period-doubling"] * 2
    assert np.max(np.abs(value[on == 0] - zone)) < 1e-6
    assert ds.sizes["branch_id"] == 3
    for b, other in ((1, zone[1]), (2, zone[0])):
        pts = ds["branch"].values == b
        assert np.all(ds["period"].values[pts] == 2) and pts.sum() < 100
        assert "retraces itself" in str(ds["branch_message"].values[b])
        assert ds["branch_status"].values[b] == 6  # BranchStatus.RETRACED
        assert list(kind[on == b]) == ["branch point"]
        assert abs(value[on == b][0] - other) < 1e-5
        om = ds["Omega"].values[pts]
        assert om.min() > zone[0] - 1e-5 and om.max() < zone[1] + 1e-5
        x = ds["section_point"].values[pts]
        k = int(np.argmax(np.abs(x[:, 0])))
        w = float(om[k])
        T = 2 * math.pi / w

        def f(t, y, w=w):
            return [y[1], -2 * ZETA * y[1] - y[0] ** 2 * y[1]
                    - (1 + KAPPA * math.cos(w * t)) * y[0]]

        ends = solve_ivp(f, (0.0, 2 * T), x[k], method="DOP853", rtol=1e-12, atol=1e-13,
                         t_eval=[T, 2 * T]).y.T
        assert np.max(np.abs(ends[1] - x[k])) < 1e-6 < 1e-2 < np.max(np.abs(ends[0] - x[k]))
    geardyn.testing.assert_result(ds, "continuation")
    fig = plot_branch(ds)
    labels = sorted(t.get_text() for t in fig.axes[0].texts if t.get_gid() == "bifurcation-label")
    assert labels == ["BP", "BP", "PD", "PD"]
    assert "ended early" not in fig.get_suptitle()  # retracing completes a branch


def test_retrace_check_ends_a_closed_curve_after_one_round_not_at_its_turns():
    """The retrace check on points of a circle in (x, p) (two turns of the parameter) with
    steps of 0.2 rad: silent over the first round, folds included, and it fires once the points
    come round onto the first ones."""
    from types import SimpleNamespace

    from geardyn.analysis import branch

    tracer = SimpleNamespace(param="p", p_of=lambda z: float(z[-1]))
    runner = branch._BranchRunner(tracer, None, 0)
    h = 0.2
    fired = []
    for i, a in enumerate(np.arange(0.0, 2.5 * math.pi, h)):
        z = np.array([math.cos(a), math.sin(a)])  # (x, p)
        pt = SimpleNamespace(z=z, tangent=np.array([-math.sin(a), math.cos(a)]))
        s = i * h
        why = runner._retraced(pt, s)
        if why:
            fired.append(a)
        runner._copies.append(z[None, :])
        runner._arc.append(s)
    assert fired and 2 * math.pi < fired[0] < 2 * math.pi + 2 * h
    assert "retraces itself" in runner._retraced(pt, s + h)


# ----------------------------------------------------------------------------- location
def _hill() -> geardyn.GearPair:
    return geardyn.GearPair(zeta=ZETA, kappa=KAPPA, Fm=1.0, Fa=0.0)


def test_failed_location_keeps_the_bifurcation_with_its_bracket(monkeypatch, zone):
    """Every location trial fails: the two period doublings of the Mathieu-Hill gear pair are
    kept, not located, each with the step it was seen in as its bracket (containing the zone
    boundary); switching at them is still tried from the bracket's end, or its failure
    recorded."""
    from geardyn.analysis import branch

    def fail(self, a, b, sigma, final=True):
        self._trial_failure = "no corrector (test)"
        return None

    monkeypatch.setattr(branch._BranchRunner, "_trial", fail)
    ds = geardyn.continuation(_hill(), "Omega", 1.5, 2.6, switch=True,
                              settings=geardyn.ContinuationSettings(max_period=2, max_points=30))
    on = ds["bifurcation_branch"].values == 0
    assert list(ds["bifurcation_kind"].values[on]) == ["period-doubling"] * 2
    assert np.all(ds["bifurcation_located"].values[on] == 0)
    v, e = ds["bifurcation_value"].values[on], ds["bifurcation_error"].values[on]
    assert np.all((v - e <= zone) & (zone <= v + e))
    assert np.all((e > 0) & (e < 0.1))
    for j in np.flatnonzero(on):
        assert "not located" in str(ds["bifurcation_detail"].values[j])
        # the bracket is the step between two consecutive points
        k = int(ds["bifurcation_point"].values[j])
        ends = np.sort(ds["Omega"].values[k:k + 2])
        assert np.allclose([v[j] - e[j], v[j] + e[j]], ends, atol=1e-12)
    labels = [t.get_text() for t in plot_branch(ds).axes[0].texts
              if t.get_gid() == "bifurcation-label"]
    assert labels.count("PD?") >= 2 and "PD" not in labels
    assert ds.sizes["branch_id"] == 3
    for b in (1, 2):
        assert ds["branch_parent"].values[b] in np.flatnonzero(on)
        if ds["branch_status"].values[b] == BranchStatus.START_FAILED:
            assert "not located" in str(ds["branch_message"].values[b])
        else:
            assert np.all(ds["period"].values[ds["branch"].values == b] == 2)


def test_location_outside_its_step_is_not_kept_as_located(monkeypatch, zone):
    """Location trials that land beyond the step (here: moved 1.5 chords on) give a value
    outside the step: the period doublings are kept as not located, with the step as their
    bracket, which contains the zone boundary."""
    from geardyn.analysis import branch

    trial = branch._BranchRunner._trial

    def beyond(self, a, b, sigma, final=True):
        return trial(self, a, b, sigma + 1.5, final)

    monkeypatch.setattr(branch._BranchRunner, "_trial", beyond)
    ds = geardyn.continuation(_hill(), "Omega", 1.5, 2.6)
    kinds = ds["bifurcation_kind"].values
    assert list(kinds) == ["period-doubling"] * 2
    v, e = ds["bifurcation_value"].values, ds["bifurcation_error"].values
    assert np.all((v - e <= zone) & (zone <= v + e)), (v, e, zone)
    for j, k in enumerate(ds["bifurcation_point"].values):  # in the step it was seen in
        lo, hi = np.sort(ds["Omega"].values[k:k + 2])
        assert lo <= v[j] <= hi
    assert np.all(ds["bifurcation_located"].values == 0)
    assert all("outside the step" in str(d) for d in ds["bifurcation_detail"].values)


def test_corrector_far_from_its_predictor_is_rejected(monkeypatch):
    """A corrector that lands far along the branch (here: forced once to start 0.3 on) is
    rejected and the step halved. The gear pair in contact continued in Fa: a straight branch
    (the response is linear in Fa, the multipliers do not move), so no other guard sees the
    jump; the points keep the analytic response."""
    from geardyn.analysis import branch

    correct = branch._Tracer.correct
    calls = []

    def jumpy(self, z_pred, t, J0=None, max_iter=None, final=True):
        calls.append(1)
        if len(calls) == 4:
            return correct(self, z_pred + 0.3 * t, t, J0, max_iter, final)
        return correct(self, z_pred, t, J0, max_iter, final)

    monkeypatch.setattr(branch._Tracer, "correct", jumpy)
    zeta, om = 0.05, 0.8
    m = geardyn.GearPair(zeta=zeta, kappa=0.0, Fm=2.0, Fa=0.01, Omega=om)
    ds = geardyn.continuation(m, "Fa", 0.01, 0.05)
    assert ds.attrs["status"] == BranchStatus.COMPLETED, ds.attrs["message"]
    assert len(calls) > 4
    # a step's chord is about its length ds <= ds_max = 0.2; the jump would add 0.3
    assert np.max(np.diff(ds["arclength"].values)) < 0.21
    A = ds["Fa"].values * om**2 / abs(1.0 - om**2 + 2j * zeta * om)
    assert np.max(np.abs(ds["deflection_amplitude"].values[:, 0] - A)) < 1e-4 * A.max()
