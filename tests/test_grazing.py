"""Grazing contacts: an orbit that just touches a dead-zone edge crosses it twice, often inside
one RK4 step. Such a step must be split and counted like any other crossing, the first of several
crossings in a step must be the one located, and a step that cannot be resolved must show in the
results (``unresolved_steps``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from _reference_step import step_pieces
from geardyn.solvers import _step_core as core
from geardyn.solvers._step_shared import GBUF_ROWS, NO_PHASE
from geardyn.solvers.ensemble import run_lanes
from levels_model import B_BELOW, RUN, levels_model

ZETA, FM, B, OMEGA = 0.05, 0.1, 1.0, 0.8
PERIODS = 6


# --- the core function, on a step whose interpolant is given -----------------------------------

def _core_step(roots_of_x_minus_b, scale=1.0):
    """A step (dt = 1) whose cubic Hermite interpolant has x - b = -scale prod(theta - r) for the
    three roots r (the template oscillator's event 0 is x - b, b = p[1]). Returns the crossing
    the core function locates and the one the old end-to-end root finding located."""
    r1, r2, r3 = roots_of_x_minus_b
    c = np.array([1.0, -(r1 + r2 + r3), r1 * r2 + r1 * r3 + r2 * r3, -r1 * r2 * r3]) * -scale
    val, der = np.polyval(c, [0.0, 1.0]), np.polyval(np.polyder(c), [0.0, 1.0])
    b = 0.5
    p = np.array([1.0, b, 0.0, 0.0])
    y0, y1 = np.array([b + val[0], 0.0]), np.array([b + val[1], 0.0])
    f0, f1 = np.array([der[0], 0.0]), np.array([der[1], 0.0])
    ybuf, gbuf, g1 = np.zeros(2), np.zeros((GBUF_ROWS, 2)), np.zeros(2)
    core.events(1.0, y1, g1, p, 0.0, 1.0)
    pc = NO_PHASE
    step = step_pieces(core)
    step.interpolant_events(y0, f0, y1, f1, 1.0, 0.0, p, ybuf, gbuf, pc)
    side = 1 if gbuf[0, 0] > 0 else -1
    new = step.first_crossing(0, side, g1[0], y0, f0, y1, f1, 1.0, 0.0, p, ybuf, gbuf, pc)
    old = (step.illinois(0, side, gbuf[0, 0], 1.0, g1[0], y0, f0, y1, f1, 1.0, 0.0, p, ybuf,
                         gbuf[1], pc) if (g1[0] > 0) != (side > 0) else 2.0)
    return new, old


def test_core_finds_a_graze_inside_one_step():
    # x - b dips below the edge between theta = 0.3 and 0.45 and is back above it at the end
    # (third root outside the step): the ends agree, so the end test saw nothing
    new, old = _core_step((0.3, 0.45, 1.6), scale=-1.0)
    assert old == 2.0
    assert new == pytest.approx(0.3, abs=1e-12)


def test_core_locates_the_first_of_three_crossings():
    # three crossings in the step; root finding over the whole step converges to the last one
    new, old = _core_step((0.3, 0.35, 0.95))
    assert old == pytest.approx(0.95, abs=1e-12)
    assert new == pytest.approx(0.3, abs=1e-12)


def test_core_ignores_an_extremum_on_its_side():
    new, _ = _core_step((-0.3, 1.2, 1.5))  # an interior minimum above the edge
    assert new == 2.0


def test_cubic_extrema_of_a_known_cubic():
    # P(theta) = (theta - 0.25)^2 (theta - 2): stationary at 0.25 and 1.5 -> only 0.25 in (0, 1)
    c = np.polymul(np.polymul([1, -0.25], [1, -0.25]), [1, -2.0])
    v = np.polyval(c, [0, 1 / 3, 2 / 3, 1])
    th1, e1, th2, e2 = core.cubic_extrema(*v)
    assert th1 == pytest.approx(0.25, abs=1e-12) and e1 == pytest.approx(0.0, abs=1e-14)
    assert math.isnan(th2) and math.isnan(e2)



def test_inverse_cubic_of_a_known_inverse():
    # theta(v) = 0.4 + 1.1 v - 0.3 v^2 + 0.2 v^3 (monotone): the values v_i where it takes
    # theta = 0, 1/3, 2/3, 1 (numpy's roots); the zero of the inverse interpolant is theta(0)
    q = [0.2, -0.3, 1.1, 0.4]
    v = [next(r.real for r in np.roots(np.polysub(q, [th])) if abs(r.imag) < 1e-12)
         for th in (0.0, 1 / 3, 2 / 3, 1.0)]
    assert core._inverse_cubic(*v) == pytest.approx(0.4, abs=1e-14)
    # an edge function that is not monotone over the step: no zero inside the step's thirds
    assert not 0.0 < core._inverse_cubic(-1.0, 0.5, -0.2, 0.3) < 1.0 / 3.0

# --- a grazing orbit of the gear pair against DOP853 --------------------------------------------

def _steady(fa: float) -> np.ndarray:
    """The linear steady state at tau = 0 (teeth in contact, kappa = 0): x - b = Fm + Re(X
    e^{i Omega tau}), X = Fa Omega^2 / (1 - Omega^2 + 2 i zeta Omega). Its minimum Fm - |X|
    touches the edge at Fa = threshold()."""
    X = fa * OMEGA**2 / (1.0 - OMEGA**2 + 2j * ZETA * OMEGA)
    return np.array([B + FM + X.real, -OMEGA * X.imag])


def threshold() -> float:
    return FM * abs(1.0 - OMEGA**2 + 2j * ZETA * OMEGA) / OMEGA**2


def _rhs(fa: float):
    """The gear pair written out here: x'' + 2 zeta x' + g(x) = Fm + Fa Omega^2 cos(Omega tau)."""
    def f(t, y):
        x = y[0]
        g = x - B if x > B else (x + B if x < -B else 0.0)
        return [y[1], FM + fa * OMEGA**2 * math.cos(OMEGA * t) - 2 * ZETA * y[1] - g]
    return f


def _reference(fa: float, t_end: float) -> tuple[np.ndarray, list[tuple[float, float]]]:
    """Edge crossings of the orbit from _steady(fa) over [0, t_end] by DOP853 (rtol 1e-12),
    stopped at every edge crossing it detects and restarted there. The extrema of x (v = 0, a
    transversal event) are recorded too, since a shallow dip between two of the integrator's
    steps escapes its sign test: the crossings of an edge are the sign changes of x -/+ b over
    the start, the extrema and the end (x is monotone between extrema). Returns the counts
    (x - b, x + b) and, for each minimum of x below b, the times of its two crossings of x - b
    (from the local parabola, accurate enough to tell which grid step they fall in)."""
    f = _rhs(fa)

    def edge(k, side):
        def ev(t, y):
            return y[0] - B if k == 0 else y[0] + B
        ev.terminal, ev.direction = True, -side
        return ev

    def extremum(t, y):
        return y[1]

    t, y = 0.0, _steady(fa)
    sides = [1 if y[0] - B > 0 else -1, 1 if y[0] + B > 0 else -1]
    values = [[y[0] - B], [y[0] + B]]
    pairs = []
    while t < t_end:
        sol = solve_ivp(f, (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=[edge(0, sides[0]), edge(1, sides[1]), extremum])
        assert sol.status in (0, 1)
        for te, ye in zip(sol.t_events[2], sol.y_events[2], strict=True):
            values[0].append(ye[0] - B)
            values[1].append(ye[0] + B)
            if ye[0] < B and f(te, ye)[1] > 0:  # a minimum beyond the drive edge
                w = math.sqrt(2 * (B - ye[0]) / f(te, ye)[1])
                pairs.append((te - w, te + w))
        if sol.status == 1:
            k = min((k for k in (0, 1) if sol.t_events[k].size), key=lambda k: sol.t_events[k][0])
            t, y = float(sol.t_events[k][0]), sol.y_events[k][0].copy()
            sides[k] = -sides[k]
        else:
            t, y = t_end, sol.y[:, -1]
    values[0].append(y[0] - B)
    values[1].append(y[0] + B)
    counts = np.array([int(np.sum(np.diff(np.sign(v)) != 0)) for v in values])
    return counts, pairs


#: Fa / threshold - 1: below the edge, at it, and dipping 1e-8 ... 3e-3 (of Fm) beyond it; the
#: shallow dips last a fraction of a step (the default step is T / 125 here)
OFFSETS = (-1e-3, -1e-5, 1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 2e-5, 4e-5, 1e-4, 3e-4, 1e-3, 3e-3)


@pytest.fixture(scope="module")
def grazing_sweep():
    fas = threshold() * (1.0 + np.array(OFFSETS))
    model = geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=float(fas[0]), Omega=OMEGA)
    n = geardyn.default_steps_per_period(model)
    h = 2 * math.pi / OMEGA / n
    refs = [_reference(float(fa), PERIODS * 2 * math.pi / OMEGA) for fa in fas]
    return model, fas, n, h, refs


def test_grazing_sweep_contains_pairs_inside_one_step(grazing_sweep):
    """The sweep is a real test: at some points both crossings of a pair fall inside one grid
    step (the end-sign test missed them), at others they straddle grid points."""
    _, _, _, h, refs = grazing_sweep
    inside = straddle = 0
    for counts, pairs in refs:
        assert 2 * len(pairs) == counts[0]
        for a, b in pairs:
            if math.floor(a / h) == math.floor(b / h):
                inside += 1
            else:
                straddle += 1
    assert inside >= 2 * PERIODS and straddle >= 2 * PERIODS


def test_grazing_crossings_and_contact_agree_with_dop853(grazing_sweep):
    model, fas, n, _, refs = grazing_sweep
    expected = np.array([c for c, _ in refs])
    assert expected[0, 0] == 0 and expected[-1, 0] == 2 * PERIODS  # none ... a dip per period
    regime = np.where(expected[:, 0] > 0, "single", "none")
    Y0 = np.array([_steady(float(fa)) for fa in fas])
    # the trajectory kernel (simulate)
    got = np.array([geardyn.simulate(model.with_params(Fa=float(fa)),
                                     run=geardyn.RunSettings(transient=0.0, samples=PERIODS), y0=y0)
                    ["edge_crossings"].values for fa, y0 in zip(fas, Y0, strict=True)])
    np.testing.assert_array_equal(got, expected)
    # the sweep kernel: crossing counts of the lanes, and the contact regime of the sweep
    r = run_lanes(model, model.lane_params("Fa", fas), Y0,
                  run=geardyn.RunSettings(transient=0.0, samples=PERIODS, steps_per_period=n))
    np.testing.assert_array_equal(r.crossings, expected)
    assert np.all(r.unresolved == 0)
    ds = geardyn.bifurcation(model, "Fa", fas,
                             run=geardyn.RunSettings(transient=0.0, samples=PERIODS), y0=Y0)
    np.testing.assert_array_equal(ds["contact"].values[:, 0], regime)
    assert np.all(ds["unresolved_steps"].values == 0)


# --- a step the split limit cannot resolve shows in every result ---------------------------------

def test_unresolved_steps_reach_every_result():
    """The model of tests/levels_model.py crosses more levels than the split limit inside one
    grid step twice per forcing period (analytic motion), so each such step falls back unsplit;
    every result must say so, lane by lane: 2 per period run, 0 in a lane whose x stays below
    the levels (B_BELOW)."""
    model = levels_model()
    run = dataclasses.replace(RUN, transient=0.0, samples=2)
    per_run = 2 * run.samples  # two steps per period at the limit, samples periods run
    ds = geardyn.simulate(model.with_params(Omega=1.1), run=run)
    assert ds.attrs["transient_periods"] == 0 and ds.attrs["periods"] == run.samples
    assert ds.attrs["unresolved_steps"] == per_run
    sw = geardyn.bifurcation(model.with_params(Omega=1.1), "B", [0.0, B_BELOW], run=run)
    np.testing.assert_array_equal(sw["unresolved_steps"].values, [per_run, 0])
    two = geardyn.bifurcation(model.with_params(Omega=1.1), "B", [0.0], run=run, starts=2,
                              spread=0.0)
    assert int(two["unresolved_steps"].values[0]) == 2 * per_run  # both starts
    mp = geardyn.map2d(model, ("B", [0.0, B_BELOW]), ("Omega", [1.1]), run=run)
    np.testing.assert_array_equal(mp["unresolved_steps"].values, [[per_run, 0]])


def test_reproduction_report_counts_unresolved_steps(tmp_path):
    """The case file carries ``unresolved_steps``; the report gives it per case and warns when
    it is not 0."""
    from geardyn.reproduction import ReproductionSettings, get_case, run_case
    from geardyn.reproduction.report import build_report

    settings = ReproductionSettings(num=2, transient=20.0, samples=2, lyapunov_duration=5.0,
                                    lyapunov_screen=5.0, lyapunov_transient=1.0)
    ds = run_case(get_case("fig5"), "consistent", settings)
    assert ds["unresolved_steps"].dims == ("sweep", "Omega")
    assert ds.attrs["unresolved_steps"] == int(ds["unresolved_steps"].sum())
    clean = build_report({("fig5", "consistent"): ds}, {}, tmp_path).markdown(tmp_path)
    assert "unresolved steps" in clean and "Warning: unresolved steps" not in clean
    bad = ds.copy(deep=True)
    bad["unresolved_steps"][0, 1] = 3
    text = build_report({("fig5", "consistent"): bad}, {}, tmp_path).markdown(tmp_path)
    assert "**Warning: unresolved steps.** In fig5 (consistent): 3 grid steps" in text
    row = next(line for line in text.splitlines() if line.startswith("| fig5 | consistent |"))
    assert row.split("|")[5].strip() == "3"
