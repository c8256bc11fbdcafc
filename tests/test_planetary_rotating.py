"""The planetary gear set with a rotating carrier (``carrier_speed``): the gyroscopic and
centripetal terms against the rotating-frame equation assembled here (Lin & Parker 1999's G and
K_Omega, and the preloaded form), against the kinematics of a rotating frame (a sun on its
bearing, seen from the carrier), the forced response of the linear set, and the rigid rotation
that must stay neutral."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eig, eigh, solve

import geardyn
from geardyn.errors import ParameterError
from test_planetary import LP, _linear_set, _linear_set_matrices, gear_set, lp_matrices

M = geardyn.Member
RC = 0.08  # radius of the planet centres [m]


def rotating_terms(n: int, masses: dict, preload: bool, rc: float = RC
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """G, K_Omega and the centrifugal load per Omega_c^2 of the full model (x, y, u of c, r, s,
    then zeta, eta, u per planet), written out: Lin & Parker's G_j = [[0, -2m, 0], [2m, 0, 0],
    [0, 0, 0]], K_Omega_j = diag(m, m, 0); preloaded: a planet's tangential term on eta_n - u_c
    and its radial load m_p r_c."""
    nd = 9 + 3 * n
    G, K, f = np.zeros((nd, nd)), np.zeros((nd, nd)), np.zeros(nd)
    for b, name in enumerate(("carrier", "ring", "sun") + ("planet",) * n):
        m = masses[name]
        G[3 * b:3 * b + 3, 3 * b:3 * b + 3] = [[0, -2 * m, 0], [2 * m, 0, 0], [0, 0, 0]]
        K[3 * b:3 * b + 3, 3 * b:3 * b + 3] = np.diag([m, m, 0.0])
    if preload:
        mp = masses["planet"]
        for i in range(n):
            eta = 9 + 3 * i + 1
            w = np.zeros(nd)
            w[eta], w[2] = 1.0, -1.0
            K[eta, eta] -= mp  # replace the eta_n term by one on eta_n - u_c
            K += mp * np.outer(w, w)
            f[eta - 1] = mp * rc
    return G, K, f


MASSES = {k: LP[k].mass for k in ("carrier", "ring", "sun", "planet")}


def spinning(wc: float, preload: bool = True, **kw) -> geardyn.PlanetaryGearSet:
    return gear_set(4, carrier=M(5.43, 6.29, 1e8, 0.0, radius=RC), carrier_speed=wc,
                    centrifugal_preload=preload, **kw)


def reference_modes(wc: float, preload: bool) -> np.ndarray:
    """Eigenvalues [rad/s] of (lambda^2 M + lambda wc G + K - wc^2 K_Omega) phi = 0, assembled
    here, one per mode (Im >= 0)."""
    Mm, K = lp_matrices(4)
    G, KO, _ = rotating_terms(4, MASSES, preload)
    n = Mm.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-solve(Mm, K - wc * wc * KO), -wc * solve(Mm, G)]])
    lam = eig(A, right=False)
    return lam[np.argsort(np.abs(lam.imag))][1::2]  # each pair once


@pytest.mark.parametrize("preload", [True, False])
@pytest.mark.parametrize("wc", [50.0, 800.0])
def test_modes_match_the_rotating_frame_eigenproblem(wc, preload):
    gs = spinning(wc, preload)
    ref = reference_modes(wc, preload)
    f_ref = np.sort(np.abs(ref.imag)) / (2 * math.pi)
    f = gs.natural_frequencies()
    np.testing.assert_allclose(f[1:], f_ref[1:], rtol=1e-9)
    ds = gs.modes()
    growth = ds["growth_rate"].values
    # the one real pair of the published form: the free rotation diverges at rate sigma
    sigma = np.max(np.abs(ref.real))
    if preload:  # a rigid rotation of the train stays neutral (a double zero: sqrt(eps) split)
        assert f[0] == 0.0 and np.max(np.abs(growth)) == 0.0
        assert sigma < 1e-6 * np.max(np.abs(ref))
    else:
        assert sigma > 1e-3 * wc
        assert growth.max() == pytest.approx(sigma, rel=1e-6)
    # the stationary pairs split: no translational pair stays degenerate
    pairs = ds["multiplicity"].values[ds["type"].values == "translational"]
    assert pairs.size and np.all(pairs == 1)
    assert set(ds["type"].values) >= {"rotational", "translational", "planet"}


def test_low_carrier_speed_tends_to_the_stationary_modes():
    f0 = gear_set(4).natural_frequencies()
    f = spinning(1e-3).natural_frequencies()
    np.testing.assert_allclose(f[1:], f0[1:], rtol=1e-6)


def test_a_sun_on_its_bearing_seen_from_the_rotating_carrier():
    """The rotating frame's kinematics, independent of Lin & Parker's matrices: a sun on an
    isotropic bearing, its meshes soft (1e-2 N/m), released at rest in the ground frame at
    x = A, oscillates along a fixed line there, x_I = A cos(w_n t); in the carrier frame turning
    at Omega_c that is z = x + i y = A cos(w_n t) exp(-i Omega_c t)."""
    ms, kb, wc = 0.4, 1e8, 3000.0
    wn = math.sqrt(kb / ms)
    gs = geardyn.PlanetaryGearSet(
        n_planets=3, sun=M(ms, 0.39, kb, 0.0), ring=M(2.35, 3.0, 1e8, 1e9),
        carrier=M(5.43, 6.29, 1e8, 0.0), planet=M(0.66, 0.61, 1e8), sun_mesh_stiffness=1e-2,
        ring_mesh_stiffness=1e-2, mesh_damping=0.0, fixed=("ring", "carrier"),
        carrier_speed=wc, centrifugal_preload=False, time_scale=wn, mesh_frequency=wn / 2)
    names = gs.dof_names()
    n, L, w0 = len(names), gs.length_scale, gs.time_scale
    A = 1e-6
    y0 = np.zeros(2 * n)
    y0[names.index("x_s")] = A / L
    y0[n + names.index("y_s")] = -wc * A / (L * w0)  # at rest in the ground frame
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=0.0, samples=3), y0=y0)
    t = ds["time"].values / w0
    z = (ds["x_s"].values + 1j * ds["y_s"].values) * L
    np.testing.assert_allclose(z, A * np.cos(wn * t) * np.exp(-1j * wc * t), rtol=0, atol=1e-5 * A)


def test_linear_forced_response_with_a_rotating_carrier():
    """Zero backlash, constant stiffness, carrier at 600 rad/s, preloaded: a run started on
    q = q_s + Im(Q e^{iwt}) stays on it, with (K - wc^2 K_Omega) q_s = wc^2 f (the planets'
    centrifugal load) and (K - wc^2 K_Omega - w^2 M + i w (C + wc G)) Q = sum_m w_m k_m e_m,
    all assembled here (C: the modal damping of the stationary set)."""
    wc, w = 600.0, 2 * math.pi * 1300
    gs = _linear_set(mesh_frequency=w, carrier_speed=f"{wc * 60 / (2 * math.pi)} rpm")
    assert gs.members["carrier"].radius == RC
    assert gs.carrier_omega() == pytest.approx(wc, rel=1e-12)
    Mm, K, C = _linear_set_matrices()
    G, KO, f = rotating_terms(4, MASSES, True)
    Ke = K - wc * wc * KO
    W = gs.full_mesh_rows()  # checked against the blocks in test_planetary
    E = np.r_[[2e-6] * 4, [1e-6] * 4]
    phase = np.r_[[0.0, 0.5, 1.0, 1.5], [0.3, 0.2, 0.1, 0.0]] + np.r_[[0.4] * 4, [0.0] * 4]
    Q = solve(Ke - w * w * Mm + 1j * w * (C + wc * G), W.T @ (5e8 * E * np.exp(1j * phase)))
    qs = solve(Ke, wc * wc * f)
    L, w0 = gs.length_scale, gs.time_scale
    y0 = np.r_[qs + Q.imag, (1j * w * Q).imag / w0] / L
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=0.0, samples=3), y0=y0)
    tau = ds["time"].values
    X = np.stack([ds[nm].values for nm in gs.state_names[:21]], axis=1)
    q = (qs[None, :] + (Q[None, :] * np.exp(1j * w * tau[:, None] / w0)).imag) / L
    assert np.max(np.abs(X - q)) < 1e-6 * np.max(np.abs(q))
    # the static state is the centrifugal deflection (no torque on the set)
    np.testing.assert_allclose(gs.static_state(), qs / L, rtol=1e-9, atol=1e-9 * np.max(qs / L))


def test_kinematic_carrier_speed_follows_the_input_speed():
    """carrier_speed = "kinematic": with the ring held the carrier turns at Z_s / (Z_s + Z_r) of
    the sun's speed, in every lane of a sweep in input speed or Omega."""
    from geardyn.gears import PlanetaryGeometry, SpurGear

    geo = PlanetaryGeometry(SpurGear(25, 2e-3, "20 deg", 0.03), SpurGear(23, 2e-3, "20 deg", 0.03),
                            SpurGear(71, 2e-3, "20 deg", 0.03, internal=True), n_planets=4)
    mem = dict(sun=M(0.4, 0.39, 1e8, 0.0), ring=M(2.35, 3.0, 1e8, 1e9),
               carrier=M(5.43, 6.29, 1e8, 0.0), planet=M(0.66, 0.61, 1e8))
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, carrier_speed="kinematic", **mem)
    for rpm in (1500.0, 6000.0):
        lane = gs.with_params(input_speed=rpm)
        assert lane.carrier_omega() == pytest.approx(rpm * 2 * math.pi / 60 * 25 / 96, rel=1e-12)
    P = gs.lane_params("Omega", [0.5, 1.5])
    for row, om in zip(P, (0.5, 1.5), strict=True):
        ref = gs.with_params(mesh_frequency=om * gs.time_scale)
        assert row[gs.omega_index] == om
        np.testing.assert_allclose(row, ref.params, rtol=1e-14, atol=0)
    assert not gs.omega_is_entry and gear_set(4).omega_is_entry
    held = geardyn.PlanetaryGearSet.from_geometry(geo, carrier_speed="kinematic", held="carrier",
                                                  **mem)
    assert held.carrier_omega() == 0.0


@pytest.mark.parametrize(("kw", "field"), [
    (dict(carrier_speed=100.0), "carrier.radius"),
    (dict(carrier_speed="kinematic"), "carrier_speed"),
    (dict(carrier_speed="100 N"), "carrier_speed"),
    (dict(carrier_speed=100.0, carrier_speed_ratio=0.01), "carrier_speed_ratio"),
    (dict(carrier_speed=100.0, rotational_only=True), "carrier_speed"),
    (dict(carrier_speed=100.0, centrifugal_preload="yes"), "centrifugal_preload"),
])
def test_bad_carrier_input_names_the_field(kw, field):
    with pytest.raises(ParameterError) as err:
        gear_set(3, **kw)
    assert err.value.field == field


def test_eigen_shapes_are_mass_normalised_solutions():
    gs = spinning(400.0)
    lam, phi = gs._rotating_eig()
    G, KO, _ = gs.rotating_frame_matrices()
    Mm, K = gs.mass_matrix(), gs.stiffness_matrix() - 400.0**2 * KO
    for k in range(lam.size):
        r = (lam[k] ** 2 * Mm + lam[k] * 400.0 * G + K) @ phi[:, k]
        assert np.linalg.norm(r) <= 1e-7 * np.linalg.norm(K) * np.linalg.norm(phi[:, k])
        assert np.real(phi[:, k].conj() @ Mm @ phi[:, k]) == pytest.approx(1.0)
    w_stat = eigh(gs.stiffness_matrix(), Mm, eigvals_only=True)
    assert lam.size == w_stat.size


def test_a_rotating_set_with_contact_loss_keeps_the_model_contract():
    """The conformance suite (a short run with located edges against the reference integrator
    among its rules) on the conformance set with its carrier at 1000 rad/s."""
    from conformance_cases import planetary
    from geardyn.testing import RULES, check_model

    base = planetary()
    gs = base.with_params(carrier_speed=1000.0)
    assert gs.carrier_omega() == 1000.0 and base.carrier_omega() == 0.0
    kick = np.random.default_rng(1).normal(0.0, 1.0, gs.n_states) * np.r_[[3.0] * 18, [1.0] * 18]
    report = check_model(gs, y0=gs.initial_state() + kick)
    assert [r.status for r in report.results] == ["ok"] * len(RULES), str(report)
    ds = geardyn.simulate(gs,
                          run=geardyn.RunSettings(transient=0.0, samples=2),
                          y0=gs.initial_state() + kick)
    assert int(ds["edge_crossings"].sum()) > 0


def test_study_file_sets_the_kinematic_carrier_speed():
    """planetary_example with ``carrier_speed = "kinematic"``: the carrier follows the input
    speed (ring held: Z_s / (Z_s + Z_r) of the sun's); without [params.geometry] the key names
    params.carrier_speed; a study written back keeps it."""
    from pathlib import Path

    from geardyn.io import load_study
    from geardyn.io.toml import study_to_toml
    from geardyn.study import build_model

    text = (Path(geardyn.__file__).parent / "studies" / "planetary_example.toml").read_text()
    spun = text.replace("[params]\n", '[params]\ncarrier_speed = "kinematic"\n', 1)
    gs = build_model(load_study(spun)).with_params(input_speed=12000.0)
    assert gs.carrier_omega() == pytest.approx(12000 * 2 * math.pi / 60 * 25 / 96, rel=1e-12)
    assert build_model(load_study(text)).carrier_omega() == 0.0
    again = build_model(load_study(study_to_toml(load_study(spun))))
    assert again.carrier_speed_ratio == pytest.approx(1 / 71, rel=1e-15)
    start = text.index("[params.geometry]")
    without = spun[:spun.index("[params.geometry]")] + text[text.index("[params.sun]"):]
    assert start > 0
    without = without.replace("[params]\n", '[params]\nsun_mesh_stiffness = 5e8\n'
                              'ring_mesh_stiffness = 5e8\n', 1)
    with pytest.raises(ParameterError) as e:
        build_model(load_study(without))
    assert e.value.field == "params.carrier_speed"


def test_a_grid_over_omega_keeps_the_kinematic_carrier_speed():
    """map2d's grid with Omega on y and a physical input on x (planetary_example, kinematic
    carrier speed): every row keeps its Omega exactly (a rebuild does not round it: 9 of these
    57 values came back rounded before) and the carrier speed that goes with it."""
    from geardyn.io.toml import builtin_study
    from geardyn.study import build_model

    study = builtin_study("planetary_example")
    gs = build_model(study.model_copy(update={"params": study.params.model_copy(
        update={"carrier_speed": "kinematic"})}))
    om = np.linspace(0.05, 1.2, 57)
    P = gs.lane_params_grid("sun_torque", [10.0, 20.0], "Omega", om)
    assert np.array_equal(P[:, gs.omega_index], np.repeat(om, 2))
    for row, v in zip(P[::2], om, strict=True):
        ref = gs.with_params(Omega=float(v), sun_torque=10.0)
        assert ref.omega == v
        np.testing.assert_array_equal(row, ref.params)
