"""The planetary gear set's compiled kernels: the structure section (sparse Kt and mesh rows)
against the dense formula, the lane-block forms (with their stiffness cache) against the per-lane
functions, and raw overrides outside the structure refused."""

from __future__ import annotations

import numpy as np
import pytest

import geardyn
from geardyn.models import planetary_kernels as pk
from geardyn.solvers.ensemble import run_lanes

#: A short run of the lane tests: 30 time units discarded, 3 samples, 64 steps per period.
_RUN = geardyn.RunSettings(transient=30.0, samples=3, steps_per_period=64)

M = geardyn.Member


def busy_set(**kw) -> geardyn.PlanetaryGearSet:
    """Every term of the right-hand side on: errors, torque fluctuation, modal damping,
    rectangular stiffness waves, unequal spacing."""
    args = dict(
        n_planets=4, planet_angles=[0.0, 1.4, 3.3, 4.6],
        sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
        carrier=M(5.43, 6.29, 1e8, 0.0), planet=M(0.66, 0.61, 1e8),
        sun_mesh_stiffness=5e8, ring_mesh_stiffness=6e8, sun_backlash="2 um",
        ring_backlash="3 um", sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.1,
        waveform="rectangular", harmonics=5, sun_mesh_phase=[0.0, 0.5, 1.0, 1.5],
        sun_mesh_error="1 um", ring_mesh_error="0.5 um", modal_damping=0.02,
        sun_torque=50.0, torque_fluctuation=0.3, torque_order=2.0)
    args.update(kw)
    return geardyn.PlanetaryGearSet(**args)


def dense_rhs(gs: geardyn.PlanetaryGearSet, t: float, y: np.ndarray) -> np.ndarray:
    """X'' from the dense parts of the coefficient vector (numpy, independent of the kernel)."""
    p, lay = gs.params, gs._layout
    n, nm, nh = (int(p[i]) for i in (pk.N_DOF, pk.N_MESH, pk.N_HARM))
    X, V = y[:n], y[n:]
    om = p[pk.OMEGA]
    Kt = p[lay["Kt"]:lay["Kt"] + n * n].reshape(n, n)
    Ct = p[lay["Ct"]:lay["Ct"] + n * n].reshape(n, n)
    fl = np.sin(p[pk.TORQUE_ORDER] * om * t + p[pk.TORQUE_PHASE])
    acc = p[lay["F0"]:lay["F0"] + n] + p[lay["F1"]:lay["F1"] + n] * fl - Kt @ X - Ct @ V
    G = gs.rotating_frame_matrices()[0]  # the Coriolis term, from the model's G
    acc -= gs.carrier_omega() / gs.time_scale * (G / np.diag(gs.mass_matrix())[:, None]) @ V
    h = np.arange(1, nh + 1)
    for m in range(nm):
        b = p[lay["mesh"] + m * lay["block"]:][:lay["block"]]
        f = pk.MESH_FIXED
        k = 1.0 + b[f:f + 2 * nh:2] @ np.cos(h * om * t) + b[f + 1:f + 2 * nh:2] @ np.sin(
            h * om * t)
        W, G = b[f + 2 * nh:f + 2 * nh + n], b[f + 2 * nh + n:f + 2 * nh + 2 * n]
        e = b[pk.M_ES] * np.sin(om * t) + b[pk.M_EC] * np.cos(om * t)
        de = om * (b[pk.M_ES] * np.cos(om * t) - b[pk.M_EC] * np.sin(om * t))
        d = W @ X - e
        g = d - np.clip(d, -b[pk.M_B], b[pk.M_B])
        acc -= (b[pk.M_KF] * k * g + b[pk.M_CF] * (W @ V - de)) * G
    return np.concatenate([V, acc])


SPINNING = {"carrier": M(5.43, 6.29, 1e8, 0.0, radius=0.08), "carrier_speed": 900.0}


@pytest.mark.parametrize("kw", [{}, {"rotational_only": True}, {"fixed": ("ring",)}, SPINNING,
                                {**SPINNING, "fixed": ("carrier",)}])
def test_rhs_matches_the_dense_formula(kw):
    gs = busy_set(**kw)
    rng = np.random.default_rng(3)
    n = len(gs.state_names)
    for _ in range(5):
        t, y = rng.uniform(0.0, 50.0), rng.normal(size=n) * 5.0
        dy = np.zeros(n)
        om = gs.params[pk.OMEGA]
        pk.planetary_rhs(t, y, dy, gs.params, np.sin(om * t), np.cos(om * t))
        np.testing.assert_allclose(dy, dense_rhs(gs, t, y), rtol=1e-12,
                                   atol=1e-12 * np.max(np.abs(dy)))


def test_lanes_reproduce_single_simulations_bitwise():
    """The sweep's lane-block forms (and their stiffness cache) give each lane exactly the
    per-lane functions' result: run_lanes equals simulate."""
    gs = busy_set()
    omegas = np.array([0.4, 0.9, 0.55, 1.3, 0.7])
    r = run_lanes(gs, gs.lane_params("Omega", omegas), gs.initial_state(), run=_RUN)
    assert np.all(r.status == 0)
    for j in (0, 3):
        ds = geardyn.simulate(gs, omega=omegas[j],
                              run=geardyn.RunSettings(transient=30.0, samples=3,
                                                      steps_per_period=64))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])


def test_lanes_with_different_damping_reproduce_single_simulations_bitwise():
    """Lanes whose modal damping differs (each its own Ct, not the block's shared copy)."""
    gs = busy_set()
    zetas = [0.01, 0.04, 0.02]
    r = run_lanes(gs, gs.lane_params("modal_damping", zetas), gs.initial_state(), run=_RUN)
    for j in (0, 1):
        ds = geardyn.simulate(gs.with_params(modal_damping=zetas[j]),
                              run=geardyn.RunSettings(transient=30.0, samples=3,
                                                      steps_per_period=64))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])


@pytest.mark.parametrize(("name", "values"), [
    ("Omega", [0.4, 0.9, 0.55]),                   # carrier speed following Omega: w_c per lane
    ("carrier_speed", [0.0, 700.0, 1500.0]),       # one lane standing still in a spinning block
])
def test_rotating_lanes_reproduce_single_simulations_bitwise(name, values):
    gs = busy_set(carrier=M(5.43, 6.29, 1e8, 0.0, radius=0.08), carrier_speed_ratio=1 / 71)
    if name == "carrier_speed":
        gs = busy_set(carrier=M(5.43, 6.29, 1e8, 0.0, radius=0.08), carrier_speed=1.0)
    P = gs.lane_params(name, values)
    r = run_lanes(gs, P, gs.initial_state(), run=_RUN)
    assert np.all(r.status == 0)
    assert len({row[gs._layout["gyro"]] for row in P}) == 3  # the lanes' speeds differ
    for j in range(3):
        ds = geardyn.simulate(gs.with_params(**{name: values[j]}),
                              run=geardyn.RunSettings(transient=30.0, samples=3,
                                                      steps_per_period=64), y0=gs.initial_state())
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])


@pytest.mark.parametrize("kw", [{}, {"sun_coast_stiffness": 3e8, "ring_coast_stiffness": 4e8}])
def test_lane_block_functions_equal_the_per_lane_functions_bitwise(kw):
    """rhs_lanes, events_lanes and observe_lanes on a block of lanes (Omega differs per lane;
    states on both sides of the dead zones, the coast flank in contact where there is one)
    give each lane exactly what the per-lane functions give it: two separate codes (the
    lane-block mesh work shared by the right-hand side and the observables, the per-lane mesh
    forces shared by theirs)."""
    gs = busy_set(**kw)
    P = gs.lane_params("Omega", gs.params[pk.OMEGA] * np.array([0.7, 1.0, 1.3, 1.9, 2.2]))
    nl = P.shape[0]
    rng = np.random.default_rng(11)
    Y = np.ascontiguousarray(gs.initial_state()[:, None]
                             + rng.normal(0.0, 5.0, (gs.initial_state().size, nl)))
    T = rng.uniform(0.0, 40.0, nl)
    S, C = np.sin(P[:, pk.OMEGA] * T), np.cos(P[:, pk.OMEGA] * T)
    nm = int(P[0, pk.N_MESH])
    PT = np.ascontiguousarray(P.T)
    DY, G, O = np.empty_like(Y), np.empty((2 * nm, nl)), np.empty((nm, nl))
    pk.planetary_rhs_lanes(T, Y, DY, PT, nl, S, C, np.zeros((8, nl)))
    pk.planetary_events_lanes(T, Y, G, PT, nl, S, C)
    pk.planetary_observe_lanes(T, Y, O, PT, nl, S, C, np.zeros((8, nl)))
    assert np.any(G[1::2] < 0.0) and np.any(G[0::2] > 0.0)  # both sides of the dead zones
    assert (P[0, pk.TWO_FLANK] != 0.0) == bool(kw)
    for k in range(nl):
        p, y = P[k].copy(), Y[:, k].copy()
        dy, g, o = np.empty_like(y), np.empty(2 * nm), np.empty(nm)
        pk.planetary_rhs(T[k], y, dy, p, S[k], C[k])
        pk.planetary_events(T[k], y, g, p, S[k], C[k])
        pk.planetary_observe(T[k], y, o, p, S[k], C[k])
        np.testing.assert_array_equal(DY[:, k], dy)
        np.testing.assert_array_equal(G[:, k], g)
        np.testing.assert_array_equal(O[:, k], o)


def test_raw_override_outside_the_structure_is_refused():
    gs = busy_set()
    names = gs.dof_names()
    inside = f"Kt_{names[0]}_{names[0]}"
    out = gs.with_params(**{inside: 2.0 * gs.params[gs.param_index(inside)]})
    lay = out._layout
    st = lay["structure"]
    nk = int(out.params[st])
    assert 2.0 * gs.params[gs.param_index(inside)] in out.params[st + 1 + 2 * nk:][:nk]
    with pytest.raises(ValueError, match="outside the gear set's structure"):
        gs.with_params(**{f"Kt_{names[0]}_u_s": 1.0})
    with pytest.raises(ValueError, match="outside the gear set's structure"):
        gs.lane_params(f"s1_W_{names[3]}", [0.5, 1.0])
