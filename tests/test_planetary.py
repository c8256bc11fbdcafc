"""The Lin & Parker planetary gear set (geardyn.PlanetaryGearSet): the linear model against
matrices assembled here from Lin & Parker's published blocks, the structure of its modes, the
torsional model with a fixed ring against its closed form, the nonlinear kernel against the
linear forced response and against the reference integrator with contact loss."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh, solve

import geardyn
from geardyn.analysis.basins import basins_run
from geardyn.errors import ParameterError
from geardyn.testing import assert_result

M = geardyn.Member
DEG = math.pi / 180.0
#: Lin & Parker (1999), Table 1 (the issue's example set).
LP = dict(
    sun_pressure_angle="24.6 deg", ring_pressure_angle="24.6 deg",
    sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8, torsional_stiffness=0.0),
    ring=M(mass=2.35, inertia_over_r2=3.0, bearing_stiffness=1e8, torsional_stiffness=1e9),
    carrier=M(mass=5.43, inertia_over_r2=6.29, bearing_stiffness=1e8, torsional_stiffness=0.0),
    planet=M(mass=0.66, inertia_over_r2=0.61, bearing_stiffness=1e8),
    sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8)


def gear_set(n: int = 4, **kw) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet(n_planets=n, **{**LP, **kw})


# ---------------------------------------------------------------------------------------------
# Lin & Parker's stiffness blocks, written out here (J. Vib. Acoust. 121, 1999, Eq. 2-5)


def lin_parker_matrices(n: int, psi: np.ndarray, a_s: float, a_r: float, k_s: float,
                        k_r: float, kp: float, kb: dict, ku: dict, m: dict, j: dict
                        ) -> tuple[np.ndarray, np.ndarray]:
    """M and K of the full model, coordinates (x, y, u) of c, r, s, then (zeta, eta, u) per
    planet, from the published blocks K_c1, K_c2, K_c3, K_r1, K_r2, K_r3, K_s1, K_s2, K_s3."""
    nd = 9 + 3 * n
    K = np.zeros((nd, nd))
    c, r, s = slice(0, 3), slice(3, 6), slice(6, 9)
    sa, ca, sr, cr = math.sin(a_s), math.cos(a_s), math.sin(a_r), math.cos(a_r)
    for i in range(n):
        p = slice(9 + 3 * i, 12 + 3 * i)
        sp, cp = math.sin(psi[i]), math.cos(psi[i])
        ss, cs = math.sin(psi[i] - a_s), math.cos(psi[i] - a_s)
        sq, cq = math.sin(psi[i] + a_r), math.cos(psi[i] + a_r)
        Kc1 = kp * np.array([[1, 0, -sp], [0, 1, cp], [-sp, cp, 1]])
        Kc2 = kp * np.array([[-cp, sp, 0], [-sp, -cp, 0], [0, -1, 0]])
        Kc3 = kp * np.diag([1.0, 1.0, 0.0])
        Kr1 = k_r * np.array([[sq * sq, -sq * cq, -sq], [-sq * cq, cq * cq, cq], [-sq, cq, 1]])
        Kr2 = k_r * np.array([[-sq * sr, sq * cr, sq], [cq * sr, -cq * cr, -cq],
                              [sr, -cr, -1]])
        Kr3 = k_r * np.array([[sr * sr, -sr * cr, -sr], [-sr * cr, cr * cr, cr], [-sr, cr, 1]])
        Ks1 = k_s * np.array([[ss * ss, -ss * cs, -ss], [-ss * cs, cs * cs, cs], [-ss, cs, 1]])
        Ks2 = k_s * np.array([[ss * sa, ss * ca, -ss], [-cs * sa, -cs * ca, cs],
                              [-sa, -ca, 1]])
        Ks3 = k_s * np.array([[sa * sa, sa * ca, -sa], [sa * ca, ca * ca, -ca], [-sa, -ca, 1]])
        K[c, c] += Kc1
        K[c, p] += Kc2
        K[p, c] += Kc2.T
        K[r, r] += Kr1
        K[r, p] += Kr2
        K[p, r] += Kr2.T
        K[s, s] += Ks1
        K[s, p] += Ks2
        K[p, s] += Ks2.T
        K[p, p] += Kc3 + Kr3 + Ks3
    for q, name in enumerate(("carrier", "ring", "sun")):
        K[3 * q, 3 * q] += kb[name]
        K[3 * q + 1, 3 * q + 1] += kb[name]
        K[3 * q + 2, 3 * q + 2] += ku[name]
    mass = []
    for name in ("carrier", "ring", "sun") + ("planet",) * n:
        mass += [m[name], m[name], j[name]]
    return np.diag(mass), K


def lp_matrices(n: int, psi: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    psi = 2 * np.pi * np.arange(n) / n if psi is None else psi
    mem = {k: LP[k] for k in ("sun", "ring", "carrier", "planet")}
    return lin_parker_matrices(
        n, psi, 24.6 * DEG, 24.6 * DEG, 5e8, 5e8, 1e8,
        kb={k: mem[k].bearing_stiffness for k in ("carrier", "ring", "sun")},
        ku={k: mem[k].torsional_stiffness for k in ("carrier", "ring", "sun")},
        m={k: v.mass for k, v in mem.items()}, j={k: v.inertia_over_r2 for k, v in mem.items()})


@pytest.mark.parametrize("n", [3, 4])
def test_eigenvalues_match_the_published_blocks(n):
    Mm, K = lp_matrices(n)
    lam = eigh(K, Mm, eigvals_only=True)
    f_ref = np.sqrt(np.clip(lam, 0, None)) / (2 * math.pi)
    f = gear_set(n).natural_frequencies()
    assert f.shape == (3 * n + 9,)
    np.testing.assert_allclose(f[1:], f_ref[1:], rtol=1e-9)
    assert f[0] < 1e-3 * f[1] and f_ref[0] < 1e-3 * f_ref[1]  # the free rotation


def test_unequal_spacing_matches_the_published_blocks():
    psi = np.array([0.0, 80.0, 190.0, 270.0]) * DEG
    Mm, K = lp_matrices(4, psi)
    f_ref = np.sqrt(np.clip(eigh(K, Mm, eigvals_only=True), 0, None)) / (2 * math.pi)
    f = gear_set(4, planet_angles=["0 deg", "80 deg", "190 deg", "270 deg"]).natural_frequencies()
    np.testing.assert_allclose(f[1:], f_ref[1:], rtol=1e-9)


# ---------------------------------------------------------------------------------------------
# Lin & Parker's structured modes


def _parts(ds, n):
    names = list(ds.dof.values)
    central_t = [names.index(f"{v}_{m}") for m in "crs" for v in "xy"]
    central_u = [names.index(f"u_{m}") for m in "crs"]
    central = central_t + central_u
    return central_t, central_u, central


@pytest.mark.parametrize("n", [3, 4, 5])
def test_mode_structure(n):
    ds = gear_set(n).modes()
    shape = ds["shape"].values
    kinds = ds["type"].values
    mult = ds["multiplicity"].values
    f = ds["frequency"].values
    ct, cu, central = _parts(ds, n)
    scale = np.max(np.abs(shape), axis=1)
    # counts: 6 rotational, 6 translational pairs, 3 planet modes of multiplicity N - 3
    assert np.sum(kinds == "rotational") == 6
    assert np.sum(kinds == "translational") == 12
    assert np.sum(kinds == "planet") == 3 * (n - 3)
    assert "mixed" not in kinds
    for k in range(f.size):
        if kinds[k] == "rotational":  # no member centre moves
            assert np.max(np.abs(shape[k, ct])) < 1e-8 * scale[k]
            assert mult[k] == 1
        elif kinds[k] == "translational":  # degenerate pair, no rotation of c, r, s
            assert mult[k] == 2
            assert np.max(np.abs(shape[k, cu])) < 1e-8 * scale[k]
        else:  # planet mode: only the planets move
            assert mult[k] == n - 3
            assert np.max(np.abs(shape[k, central])) < 1e-8 * scale[k]
    # a degenerate pair really is one frequency, and distinct from its neighbours
    pairs = np.flatnonzero(kinds == "translational")[::2]
    np.testing.assert_allclose(f[pairs], f[pairs + 1], rtol=1e-9)


def test_unequal_spacing_breaks_the_pairs_but_keeps_planet_modes():
    """Lin & Parker (J. Sound Vib. 233, 2000): with unequally spaced planets the degenerate
    translational pairs split and rotational modes mix, while planet modes (the planets' net
    force and moment on every central member vanish: N - 3 conditions remain free) persist."""
    ds = gear_set(5, planet_angles=["0 deg", "80 deg", "190 deg", "270 deg", "300 deg"]).modes()
    kinds, mult = ds["type"].values, ds["multiplicity"].values
    assert "mixed" in kinds
    assert not np.any((kinds == "translational") & (mult == 2))
    assert np.sum(kinds == "planet") == 3 * 2 and np.all(mult[kinds == "planet"] == 2)
    shape = ds["shape"].values[kinds == "planet"]
    _, _, central = _parts(ds, 5)
    assert np.max(np.abs(shape[:, central])) < 1e-8 * np.max(np.abs(shape))


def test_torsional_model_with_fixed_ring_matches_closed_form():
    n = 4
    gs = gear_set(n, rotational_only=True, fixed=("ring",),
                  sun=M(0.4, 0.39, 1e8, torsional_stiffness=2e7),
                  carrier=M(5.43, 6.29, 1e8, torsional_stiffness=3e8))
    f = gs.natural_frequencies()
    assert f.size == n + 2
    a, k_s, k_r, mp = 24.6 * DEG, 5e8, 5e8, 0.61
    # N - 1 planet modes: sun and carrier at rest, sum of u_n = 0
    planet = math.sqrt((k_s + k_r) / mp) / (2 * math.pi)
    # the in-phase modes: (u_c, u_s, u_p) with u_n = u_p, eta_n = u_c
    ca = math.cos(a)
    Mr = np.diag([6.29 + n * 0.66, 0.39, n * mp])
    Kr = np.array([
        [n * (k_s + k_r) * ca * ca + 3e8, -n * k_s * ca, n * (k_r - k_s) * ca],
        [-n * k_s * ca, n * k_s + 2e7, n * k_s],
        [n * (k_r - k_s) * ca, n * k_s, n * (k_s + k_r)]])
    inphase = np.sqrt(eigh(Kr, Mr, eigvals_only=True)) / (2 * math.pi)
    np.testing.assert_allclose(f, np.sort(np.r_[inphase, [planet] * (n - 1)]), rtol=1e-10)
    kinds = gs.modes()["type"].values
    assert list(kinds).count("planet") == n - 1


# ---------------------------------------------------------------------------------------------
# the nonlinear kernel


def _linear_set(**kw) -> geardyn.PlanetaryGearSet:
    return gear_set(4, sun=M(0.4, 0.39, 1e8, 2e7, radius=0.03),
                    carrier=M(5.43, 6.29, 1e8, 3e8, radius=0.08),
                    mesh_damping=0.0, modal_damping=0.05,
                    sun_mesh_error="2 um", ring_mesh_error="1 um",
                    sun_mesh_phase=[0.0, 0.5, 1.0, 1.5], ring_mesh_phase=[0.3, 0.2, 0.1, 0.0],
                    sun_error_phase=0.4, **kw)


def _linear_set_matrices() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, K and C of :func:`_linear_set` from Lin & Parker's blocks: the sun's and carrier's
    torsional supports added, modal damping 0.05 on every mode."""
    Mm, K = lp_matrices(4)
    K[8, 8] += 2e7
    K[2, 2] += 3e8
    lam, phi = eigh(K, Mm)
    return Mm, K, Mm @ phi @ np.diag(2 * 0.05 * np.sqrt(lam)) @ phi.T @ Mm


def test_linear_forced_response():
    """Zero backlash and constant stiffness: the kernel run started on the harmonic solution of
    M q'' + C q' + K q = sum_m w_m k_m e_m(t) stays on it."""
    gs = _linear_set(mesh_frequency=2 * math.pi * 1300)
    Mm, K, C = _linear_set_matrices()
    # mesh deflection rows from the blocks' structure (sun mesh n, then ring mesh n)
    psi = 2 * np.pi * np.arange(4) / 4
    a = 24.6 * DEG
    rows = []
    for i in range(4):
        r = np.zeros(21)
        r[6:9] = [-math.sin(psi[i] - a), math.cos(psi[i] - a), 1.0]
        r[9 + 3 * i:12 + 3 * i] = [-math.sin(a), -math.cos(a), 1.0]
        rows.append(r)
    for i in range(4):
        r = np.zeros(21)
        r[3:6] = [-math.sin(psi[i] + a), math.cos(psi[i] + a), 1.0]
        r[9 + 3 * i:12 + 3 * i] = [math.sin(a), -math.cos(a), -1.0]
        rows.append(r)
    W = np.array(rows)
    # e_m = E_m sin(w t + phi_m): phases of the mesh plus the error phase
    w = 2 * math.pi * 1300
    E = np.r_[[2e-6] * 4, [1e-6] * 4]
    phase = np.r_[[0.0, 0.5, 1.0, 1.5], [0.3, 0.2, 0.1, 0.0]] + np.r_[[0.4] * 4, [0.0] * 4]
    rhs = W.T @ (5e8 * E * np.exp(1j * phase))
    Q = solve(K - w * w * Mm + 1j * w * C, rhs)
    L, w0 = gs.length_scale, gs.time_scale
    y0 = np.r_[Q.imag, (1j * w * Q).imag / w0] / L  # q = Im(Q e^{iwt}) at t = 0
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=0.0, samples=3), y0=y0)
    tau = ds["time"].values
    X = np.stack([ds[nm].values for nm in gs.state_names[:21]], axis=1)
    q = (Q[None, :] * np.exp(1j * w * tau[:, None] / w0)).imag / L
    assert np.max(np.abs(X - q)) < 1e-6 * np.max(np.abs(q))


def test_orbit_continuation_and_lyapunov_of_the_linear_set_match_its_eigenvalues():
    """The 42-state set through the orbit analyses: without backlash or stiffness fluctuation
    it is linear and time-invariant, x' = A x + f(t), with A assembled here from Lin &
    Parker's blocks and the modal damping. Its Floquet multipliers are exp(lambda T) for the
    eigenvalues lambda of A (periodic_orbit, and every point of a continuation in Omega, all
    stable, no bifurcation), and its largest Lyapunov exponent is max Re lambda."""
    from scipy.linalg import eigvals

    gs = _linear_set(mesh_frequency=2 * math.pi * 1300)
    Mm, K, C = _linear_set_matrices()
    n = 21
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-solve(Mm, K), -solve(Mm, C)]]) / gs.time_scale  # d/dtau
    ev = eigvals(A)

    def expected(omega: float) -> np.ndarray:
        return np.sort(np.abs(np.exp(ev * 2 * math.pi / omega)))

    spp = 256  # a third of the step rule's: RK4's exp(lambda h) of the fastest modes is then
    # ~5e-6 off, that of the slow modes (the largest multipliers) ~1e-10
    orb = geardyn.periodic_orbit(gs, steps_per_period=spp)
    assert orb.converged, orb.message
    assert np.max(np.abs(np.sort(np.abs(orb.multipliers)) - expected(gs.omega))) < 2e-5
    assert np.max(np.abs(orb.multipliers)) == pytest.approx(expected(gs.omega)[-1], abs=1e-9)
    assert orb.stability == "stable"
    br = geardyn.continuation(gs, "Omega", gs.omega, 1.05 * gs.omega,
                              steps_per_period=spp,
                              settings=geardyn.ContinuationSettings(max_points=40))
    assert int(br.attrs["status"]) == 0 and br["Omega"].values[-1] == pytest.approx(
        1.05 * gs.omega)
    assert br.sizes["bifurcation"] == 0 and set(br["stability"].values) == {"stable"}
    last = np.sort(br["multiplier_abs"].values[-1])
    assert np.max(np.abs(last - expected(float(br["Omega"].values[-1])))) < 2e-5
    largest = geardyn.lyapunov(gs, run=geardyn.RunSettings(transient=50.0),
                               settings=geardyn.LyapunovSettings(duration=2000.0))
    assert largest == pytest.approx(ev.real.max(), rel=0.03)


def test_basins_and_map2d_of_the_linear_set():
    """The sweep-engine analyses on the 42-state set, linear: from every cell of a basins grid
    the run ends on the one attractor, the Newton orbit; and a map2d over (Omega, sun torque)
    obeys superposition: the peak mesh forces at two torques differ by the difference of the
    static mesh forces, whatever the forcing frequency."""
    gs = _linear_set(mesh_frequency=2 * math.pi * 1300)
    orb = geardyn.periodic_orbit(gs, steps_per_period=256)
    u, x = orb.x[gs.state_names.index("u_s")], orb.x[gs.state_names.index("x_s")]
    b = geardyn.basins(gs, None, ("u_s", u - 2, u + 2, 2), ("x_s", x - 2, x + 2, 2),
                       run=basins_run(transient=1500.0), orbits=[orb], base=orb.x)
    assert_result(b, "basins")
    assert b.attrs["n_attractors"] == 1 and list(b["attractor_orbit"].values) == [0]
    om = [gs.omega, 1.05 * gs.omega]
    mp = geardyn.map2d(gs, ("Omega", om), ("sun_torque", [50.0, 100.0]),
                       run=geardyn.RunSettings(transient=1500.0, samples=4))
    assert_result(mp, "map2d")
    assert np.all(mp["period"].values == 1)
    d = mp["force_peak"].sel(sun_torque=100.0).values - mp["force_peak"].sel(
        sun_torque=50.0).values
    static = (gs.with_params(sun_torque=100.0).static_mesh_forces()
              - gs.with_params(sun_torque=50.0).static_mesh_forces())
    assert np.max(np.abs(d - static[None, :])) < 1e-9 * np.max(np.abs(static))


#: The carrier torque [N m] that balances 100 N m on the sun (base radius 0.03 m, carrier radius
#: 0.08 m, ring held): the rigid rotation has u_s = 2 cos(a) u_c, so F_c = -2 cos(a) F_s.
BALANCED_CARRIER_TORQUE = -2 * math.cos(24.6 * DEG) * 100 / 0.03 * 0.08


def _contact_loss_set() -> geardyn.PlanetaryGearSet:
    return gear_set(3, sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03),
                    carrier=M(5.43, 6.29, 1e8, 0.0, radius=0.08),
                    planet_angles=["0 deg", "110 deg", "235 deg"],
                    sun_torque="100 N m", carrier_torque=BALANCED_CARRIER_TORQUE,
                    sun_backlash="10 um", ring_backlash="10 um",
                    sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
                    sun_mesh_error="15 um", ring_mesh_error="5 um",
                    sun_mesh_phase=[0.0, 2.0, 4.0], mesh_frequency=2 * math.pi * 1500)


def test_contact_loss_matches_reference_integrator():
    gs = _contact_loss_set()
    y0 = gs.initial_state()
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=0.0, samples=4), y0=y0)
    assert ds.attrs["status"] == geardyn.Status.OK
    assert int(ds["edge_crossings"].sum()) > 0
    # contact loss: some mesh deflection inside its backlash
    F = np.stack([ds[f"F_{m}"].values for m in gs.mesh_names])
    assert np.any(np.abs(F) < 0.2 * np.max(np.abs(F)))
    t = ds["time"].values
    idx = np.linspace(0, t.size - 1, 17).round().astype(int)
    ref = geardyn.reference_solution(gs, y0, t[idx])
    Y = np.stack([ds[nm].values[idx] for nm in gs.state_names], axis=1)
    scale = np.max(np.abs(ref), axis=0)
    assert np.max(np.abs(Y - ref) / np.where(scale > 0, scale, 1.0)) < 1e-4


def test_rk4_keeps_fourth_order_through_contact_loss_and_the_step_rule_is_converged():
    """Step-size convergence of the 21-state set with backlash, fluctuating stiffness and
    contact loss: the largest section-point error (relative to each state's range) over 4
    periods against DOP853 (rtol 1e-12, restarted at every located edge) falls at fourth
    order as the steps per period double (edges located), the step rule's default lies on
    the converged side (within 1e-5 of the reference; measured 6.7e-7 at 787 steps per
    period), and stepping over the edges unlocated is >10x worse there."""
    gs = _contact_loss_set()
    y0 = gs.initial_state()
    T = 2 * math.pi / gs.omega
    periods = 4
    ref = geardyn.reference_solution(gs, y0, np.arange(periods + 1) * T)
    scale = np.max(np.abs(ref), axis=0)
    scale = np.where(scale > 0, scale, 1.0)

    def error(n: int | None, locate: bool = True) -> tuple[float, int]:
        run = geardyn.RunSettings(transient=0.0, samples=periods, steps_per_period=n,
                                  locate_edges=locate)
        ds = geardyn.simulate(gs, run=run, y0=y0)
        assert ds.attrs["status"] == geardyn.Status.OK
        return (float(np.max(np.abs(ds["poincare"].values - ref) / scale)),
                int(ds.attrs["steps_per_period"]))

    default, n_default = error(None)
    ns = [n_default // 4, n_default // 2, n_default]
    errs = [error(n)[0] for n in ns[:2]] + [default]
    p = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
    assert p > 3.5, (ns, errs)
    assert default < 1e-5
    # without the located edges the kinks cost the order: ~100x the error at the same step
    assert error(n_default, locate=False)[0] > 10 * default


def test_static_forces_balance_the_torque():
    gs = _contact_loss_set()
    F = gs.static_mesh_forces()
    # torque balance on the sun: sum of sun mesh forces times the base radius = T_s
    assert math.isclose(np.sum(F[:3]) * 0.03, 100.0, rel_tol=1e-9)


# ---------------------------------------------------------------------------------------------
# parameters


def test_with_params_keeps_scales_and_rebuilds():
    gs = _contact_loss_set()
    g2 = gs.with_params(sun_backlash=20e-6)
    assert g2.time_scale == gs.time_scale and g2.omega == gs.omega
    b = [g2.params[g2._param_index(f"s{i}_b")] for i in (1, 2, 3)]
    np.testing.assert_allclose(b, 20.0)
    P = gs.lane_params("sun_mesh_stiffness", [4e8, 6e8])
    w = gs.fastest_natural_frequency(P)
    assert w[0] < w[1]
    assert gs.with_params(Omega=2.0).omega == 2.0


@pytest.mark.parametrize(("kw", "field"), [
    (dict(sun=M(-1.0, 0.39, 1e8)), "sun.mass"),
    (dict(sun_mesh_stiffness="5e8 N"), "sun_mesh_stiffness"),
    (dict(planet=M(0.66, 0.61, 1e8, 1e6)), "planet.torsional_stiffness"),
    (dict(sun_torque=10.0), "sun.radius"),
    (dict(sun_stiffness_fluctuation=1.5), "sun_stiffness_fluctuation"),
    (dict(sun_backlash=[1e-6, 2e-6]), "sun_backlash"),
    (dict(n_planets=0), "n_planets"),
    (dict(fixed=("moon",)), "fixed"),
    (dict(sun_pressure_angle="95 deg"), "sun_pressure_angle"),
])
def test_bad_input_names_the_field(kw, field):
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet(**{**LP, "n_planets": 3, **kw})
    assert err.value.field == field


# ---------------------------------------------------------------------------------------------
# study files

STUDY = """
[study]
name = "lp4"
model = "planetary"
[params]
n_planets = 4
sun_pressure_angle = "24.6 deg"
ring_pressure_angle = "24.6 deg"
sun_mesh_stiffness = "5e8 N/m"
ring_mesh_stiffness = 5e8
sun_backlash = "10 um"
[params.sun]
mass = 0.4
inertia_over_r2 = 0.39
bearing_stiffness = 1e8
[params.ring]
mass = 2.35
inertia_over_r2 = 3.0
bearing_stiffness = 1e8
torsional_stiffness = 1e9
[params.carrier]
mass = 5.43
inertia_over_r2 = 6.29
bearing_stiffness = 1e8
[params.planet]
mass = "660 g"
inertia_over_r2 = 0.61
bearing_stiffness = 1e8
[run]
omega = 0.7
"""


def test_study_file_builds_the_gear_set():
    from geardyn.io.toml import load_study

    model = geardyn.build_model(load_study(STUDY))
    assert isinstance(model, geardyn.PlanetaryGearSet)
    assert model.omega == 0.7
    np.testing.assert_allclose(model.natural_frequencies(), gear_set(4).natural_frequencies(),
                               rtol=1e-12)
    assert model.backlash[0] == pytest.approx(10e-6)


@pytest.mark.parametrize(("old", "new", "field"), [
    ("mass = 0.4", "mass = -0.4", "params.sun.mass"),
    ('sun_mesh_stiffness = "5e8 N/m"', 'sun_mesh_stiffness = "5e8 kg"',
     "params.sun_mesh_stiffness"),
])
def test_study_file_bad_value_names_the_field(old, new, field):
    from geardyn.io.toml import load_study

    with pytest.raises(ParameterError) as err:
        geardyn.build_model(load_study(STUDY.replace(old, new, 1)))
    assert err.value.field == field


def test_study_file_unknown_key_is_refused():
    from pydantic import ValidationError

    from geardyn.io.toml import load_study

    with pytest.raises((ValidationError, geardyn.StudyError), match="params.sun.spin"):
        load_study(STUDY.replace("[params.sun]\n", "[params.sun]\nspin = 1\n"))


def test_sweep_in_a_physical_parameter_sees_contact_loss():
    """A bifurcation sweep of the gear set in a constructor input (lanes rebuilt by
    lane_params) ends ok in every lane, and its ring meshes lose contact."""
    gs = _contact_loss_set()
    ds = geardyn.bifurcation(gs, "ring_mesh_error", [4e-6, 5e-6, 6e-6],
                             run=geardyn.RunSettings(transient=50.0, samples=4))
    assert np.all(ds["status"].values == 0)
    assert list(ds["mesh"].values) == list(gs.mesh_names)
    contact = ds["contact"].sel(mesh=["r1", "r2", "r3"]).values
    assert np.all(contact != "none")
    assert np.all(np.isfinite(ds["dynamic_factor"].values))


def test_mesh_forces_follow_the_formula():
    """observe at a random state and time equals k_m [1 + A sin(w t + phi_m)] g(delta_m - e_m,
    b_m) + c_m (delta_m' - e_m') evaluated here in SI from the published-block rows."""
    n, a = 3, 24.6 * DEG
    psi = np.array([0.0, 110.0, 235.0]) * DEG
    gs = gear_set(n, planet_angles=["0 deg", "110 deg", "235 deg"],
                  sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=[0.1, 0.15, 0.05],
                  sun_mesh_phase=[0.0, 1.0, 2.0], ring_mesh_phase=0.5,
                  sun_backlash="3 um", ring_backlash=[1e-6, 2e-6, 4e-6],
                  sun_mesh_error="2 um", ring_mesh_error="1 um", ring_error_phase=0.3,
                  mesh_damping=[0.03, 0.05, 0.07], mesh_frequency=2 * math.pi * 900)
    rng = np.random.default_rng(3)
    X, V, tau = rng.normal(0, 5, 18), rng.normal(0, 3, 18), 7.3
    L, w0, w = gs.length_scale, gs.time_scale, 2 * math.pi * 900
    t, q, qd = tau / w0, L * X, L * w0 * V
    out = np.empty(2 * n)
    gs.kernel.observe(tau, np.r_[X, V], out, gs.params, math.sin(gs.omega * tau),
                      math.cos(gs.omega * tau))
    for m in range(2 * n):
        i, sun = m % n, m < n
        row = np.zeros(18)
        if sun:
            row[6:9] = [-math.sin(psi[i] - a), math.cos(psi[i] - a), 1.0]
            row[9 + 3 * i:12 + 3 * i] = [-math.sin(a), -math.cos(a), 1.0]
        else:
            row[3:6] = [-math.sin(psi[i] + a), math.cos(psi[i] + a), 1.0]
            row[9 + 3 * i:12 + 3 * i] = [math.sin(a), -math.cos(a), -1.0]
        k, amp = 5e8, (0.2 if sun else [0.1, 0.15, 0.05][i])
        phi = [0.0, 1.0, 2.0][i] if sun else 0.5
        b = 3e-6 if sun else [1e-6, 2e-6, 4e-6][i]
        E, phe = (2e-6, 0.0) if sun else (1e-6, 0.3)
        e = E * math.sin(w * t + phi + phe)
        ed = E * w * math.cos(w * t + phi + phe)
        x = row @ q - e
        g = x - b if x > b else (x + b if x < -b else 0.0)
        jg = 0.39 if sun else 3.0
        c = 2 * [0.03, 0.05, 0.07][i] * math.sqrt(k * jg * 0.61 / (jg + 0.61))
        F = k * (1 + amp * math.sin(w * t + phi)) * g + c * (row @ qd - ed)
        assert out[m] == pytest.approx(F, rel=1e-9), gs.mesh_names[m]


def test_fourier_waveform_input_matches_the_sine():
    """A waveform given as Fourier coefficients (the plug-in for geometry) with mesh phases
    gives the coefficients of the built-in sine with the same phases."""
    kw = dict(sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
              sun_mesh_phase=[0.0, 0.7, 1.9], ring_mesh_phase=[0.4, 0.1, 2.2])
    sine = gear_set(3, **kw)
    given = gear_set(3, waveform=([0.0], [0.2]), **kw)
    np.testing.assert_allclose(given.fourier, sine.fourier, atol=1e-15)
    assert np.any(sine.fourier != 0.0)


def test_cli_sweeps_a_planetary_study(tmp_path, capsys):
    from geardyn.cli.main import main

    path = tmp_path / "lp4.toml"
    path.write_text(STUDY)
    nc = tmp_path / "sweep.nc"
    with pytest.raises(SystemExit) as info:
        main(["bifurcation", str(path), "--param", "ring_mesh_error", "--range", "1e-6:3e-6:3",
              "--transient", "20", "--samples", "4", "--out", str(nc)])
    out = capsys.readouterr()
    assert info.value.code == 0, out.err
    assert nc.exists()
    with pytest.raises(SystemExit) as info:
        main(["bifurcation", str(path), "--param", "spin", "--range", "1:2:3", "--out",
              str(nc)])
    err = capsys.readouterr().err
    assert info.value.code == 2 and "sun_backlash" in err and "Kt_" not in err


def test_bearing_forces_balance_the_mesh_forces_on_a_planet():
    """Static equilibrium of planet n along eta_n: its bearing's tangential force equals
    -(F_sn cos a_s + F_rn cos a_r); along zeta_n the radial force equals
    -F_sn sin a_s + F_rn sin a_r."""
    gs = _contact_loss_set()
    y = gs.initial_state()
    fb = gs.bearing_forces(y)
    F = gs.static_mesh_forces()
    ca, sa = math.cos(24.6 * DEG), math.sin(24.6 * DEG)
    for i in range(3):
        fs, fr = F[i], F[3 + i]
        assert fb[f"F_p{i + 1}_tangential"] == pytest.approx(-(fs + fr) * ca, rel=1e-8)
        assert fb[f"F_p{i + 1}_radial"] == pytest.approx((fr - fs) * sa, rel=1e-6, abs=1e-6)
    assert set(fb) >= {"F_c_x", "F_c_y", "F_s_x", "F_s_y", "F_r_x", "F_r_y"}
