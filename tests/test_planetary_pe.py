"""PlanetaryGearSet.from_geometry with the potential-energy mesh stiffness.

The compiled kernel's mesh stiffness (its mesh force at unit deflection, the observable) is
compared with the discrete Fourier series of the potential-energy table computed here by direct
sums, and with the table itself as the harmonics grow; the natural frequencies with an
eigenproblem assembled here with the table's mean stiffnesses; the ISO default with the set
built directly from the ISO waves. The coast flank: the kernel's stiffness beyond the other edge
of the dead zone against the coast table's series, the static deflection under a negative
torque against b + F / k_c from the torque balance, the one-flank case against main's results.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.models import planetary_kernels as pk
from geardyn.solvers.ensemble import run_lanes

#: A short lane run: transient 10, 3 samples, 64 steps per period.
SHORT_RUN = geardyn.RunSettings(transient=10.0, samples=3, steps_per_period=64)

M = geardyn.Member
MEMBERS = dict(
    sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8),
    ring=M(mass=2.35, inertia_over_r2=3.0, bearing_stiffness=1e8, torsional_stiffness=1e9),
    carrier=M(mass=5.43, inertia_over_r2=6.29, bearing_stiffness=1e8, torsional_stiffness=1e9),
    planet=M(mass=0.66, inertia_over_r2=0.61, bearing_stiffness=1e8))
BORES = dict(sun_bore_radius="12 mm", planet_bore_radius="10 mm", ring_rim_radius="85 mm")
KW = dict(sun_backlash="10 um", ring_backlash="10 um", sun_torque=100.0, mesh_damping=0.05)


def stage() -> g.PlanetaryGeometry:
    """The example stage of docs/planetary.md (25/23/71 teeth, m 2 mm, 4 planets)."""
    def gear(z: int, name: str, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, "2 mm", "20 deg", "20 mm", internal=internal, name=name)
    return g.PlanetaryGeometry(gear(25, "sun"), gear(23, "planet"),
                               gear(71, "ring", internal=True), n_planets=4)


def pe_set(geo: g.PlanetaryGeometry, harmonics: int = 30, angles: int = 360,
           **kw) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=harmonics, stiffness="potential_energy",
        stiffness_options={**BORES, "angles": angles}, **{**MEMBERS, **KW, **kw})


def tables(geo: g.PlanetaryGeometry, angles: int = 360):
    """The potential-energy tables of the sun-planet and planet-ring meshes, computed here."""
    sun = g.potential_energy_stiffness(geo.sun_mesh, bore_radius=(0.012, 0.010), angles=angles)
    ring = g.potential_energy_stiffness(geo.ring_mesh, bore_radius=(0.010, 0.085),
                                        angles=angles, ring_foundation="rigid")
    return sun, ring


def series(k: np.ndarray, harmonics: int, theta: np.ndarray) -> np.ndarray:
    """The table's discrete Fourier series cut after ``harmonics``, at ``theta``, by direct
    sums over the table's uniform angles."""
    n = k.size
    th = 2.0 * math.pi * np.arange(n) / n
    h = np.arange(1, harmonics + 1)
    a = 2.0 / n * np.cos(np.outer(h, th)) @ k
    b = 2.0 / n * np.sin(np.outer(h, th)) @ k
    return k.mean() + a @ np.cos(np.outer(h, theta)) + b @ np.sin(np.outer(h, theta))


def kernel_stiffness(gs: geardyn.PlanetaryGearSet, thetas: np.ndarray,
                     sign: float = 1.0) -> np.ndarray:
    """k_m [N/m] of every mesh (columns) at the mesh phases ``thetas`` (rows) from the compiled
    observable: at a state with dimensionless deflection ``sign`` in every mesh, at rest, no
    backlash or error, the mesh force is sign k_m(theta) L."""
    gs = gs.with_params(sun_backlash=0.0, ring_backlash=0.0)
    W = gs.mesh_rows()
    X = np.linalg.lstsq(W, np.full(W.shape[0], sign), rcond=None)[0]
    assert np.allclose(W @ X, sign)
    y = np.r_[X, np.zeros_like(X)]
    out = np.empty((np.size(thetas), W.shape[0]))
    for i, theta in enumerate(np.ravel(thetas)):
        gs.kernel.observe(theta / gs.omega, y, out[i], gs.params, math.sin(theta),
                          math.cos(theta))
    return out / (sign * gs.length_scale)


@pytest.fixture(scope="module")
def geo():
    return stage()


@pytest.fixture(scope="module")
def pe_tables(geo):
    return tables(geo)


def test_kernel_stiffness_is_the_tables_fourier_series(geo, pe_tables):
    """Every mesh's stiffness at mesh phase theta is the table's truncated series at
    theta - 2 pi gamma_n (gamma: the Parker & Lin phases, as with the ISO waves)."""
    H = 30
    gs = pe_set(geo, harmonics=H)
    gam = np.concatenate([geo.phases.sun, geo.phases.ring])
    k = [pe_tables[0]["mesh_stiffness"].values] * 4 + [pe_tables[1]["mesh_stiffness"].values] * 4
    assert len(set(np.round(gam[:4], 9))) == 4  # the phases differ: the check has teeth
    thetas = np.linspace(0.0, 2.0 * math.pi, 23)
    for theta, got in zip(thetas, kernel_stiffness(gs, thetas), strict=True):
        for m in range(8):
            want = series(k[m], H, np.array([theta - 2.0 * math.pi * gam[m]]))[0]
            assert got[m] == pytest.approx(want, rel=1e-10)
    assert gs.stiffness_method == "potential_energy"
    assert gs.dataset_attrs() == {"mesh_stiffness_method": "potential_energy",
                                  "mesh_coast_flank": "mirror"}
    assert gs.k_s == pytest.approx(k[0].mean(), rel=1e-12)
    assert gs.k_r == pytest.approx(k[4].mean(), rel=1e-12)
    changed = gs.with_params(sun_backlash="5 um")  # rebuilt from the inputs, tables kept
    assert changed.stiffness_tables is gs.stiffness_tables
    assert changed.stiffness_method == "potential_energy"
    np.testing.assert_array_equal(kernel_stiffness(changed, thetas), kernel_stiffness(gs, thetas))


def _jump_distance(table, var: str) -> np.ndarray:
    """Distance [mesh cycles] of every table angle from the nearest jump of the table (where
    the number of pairs in contact changes)."""
    pc = table[var].values
    n = pc.size
    jumps = np.nonzero(pc != np.roll(pc, 1))[0] / n
    u = np.arange(n) / n
    return np.min(np.abs((u[:, None] - jumps[None, :] + 0.5) % 1.0 - 0.5), axis=1)


def test_series_converges_to_the_table_away_from_the_jumps(geo):
    """The kernel's stiffness at the table's angles approaches the table as the harmonics grow:
    the rms over the cycle and the largest error at the angles at least 0.05 mesh cycles from
    every jump (where a tooth pair enters or leaves contact: next to it the error stays near
    half the jump whatever H, the series passing through the jump's midpoint, Gibbs) fall; at H
    = 160 the rms is below 1.5 % of the mean stiffness (it falls as 1/sqrt(H), the jumps'
    share), the error away from the jumps below 0.5 % (it falls as 1/H)."""
    angles = 720  # H = 160 well below the table's Nyquist limit 360
    sun, ring = tables(geo, angles)
    theta = 2.0 * math.pi * np.arange(angles) / angles
    gam = {1: geo.phases.sun[1], 5: geo.phases.ring[1]}  # s2, r2: delayed meshes
    assert min(gam.values()) > 0.01
    errors = {1: [], 5: []}
    for H in (10, 40, 160):
        gs = pe_set(geo, harmonics=H, angles=angles)
        for m, table in ((1, sun), (5, ring)):
            k = table["mesh_stiffness"].values
            got = kernel_stiffness(gs, theta + 2.0 * math.pi * gam[m])[:, m]
            e = (got - k) / k.mean()
            away = _jump_distance(table, "pairs_in_contact") >= 0.05
            assert 0.1 < away.mean() < 0.95
            errors[m].append((float(np.sqrt(np.mean(e * e))), float(np.max(np.abs(e[away])))))
    for m in errors:
        rms, far = np.array(errors[m]).T
        assert np.all(np.diff(rms) < 0) and np.all(np.diff(far) < 0), errors[m]
        assert rms[-1] < 1.5e-2 and far[-1] < 5e-3, errors[m]
        assert far[0] > 1e-2  # the short series is visibly off: the check can fail


def test_iso_symmetric_is_the_iso_waves_bitwise(geo):
    """The ISO waves with coast="symmetric" (one stiffness on both flanks) build the set exactly
    as a direct construction from the waves here does; the default (stiffness="iso", coast
    "mirror") differs from it only in its coast flank (tests/test_planetary_iso_flanks.py)."""
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, coast="symmetric", **MEMBERS, **KW)
    iso = geardyn.PlanetaryGearSet.from_geometry(geo, stiffness="iso", coast="symmetric",
                                                 **MEMBERS, **KW)
    ws, wr = geo.waveforms()
    members = {k: m.__class__(**{**m.__dict__, "radius": r}) for (k, m), r in zip(
        MEMBERS.items(), (geo.sun.base_radius, geo.ring.base_radius,
                          geo.sun_mesh.centre_distance, geo.planet.base_radius), strict=True)}
    direct = geardyn.PlanetaryGearSet(
        n_planets=4, planet_angles=list(geo.planet_angles),
        sun_pressure_angle=geo.sun_mesh.operating_pressure_angle,
        ring_pressure_angle=geo.ring_mesh.operating_pressure_angle,
        sun_mesh_stiffness=ws.mean, ring_mesh_stiffness=wr.mean,
        waveform={"sun": ws.fourier(9), "ring": wr.fourier(9)}, harmonics=9,
        sun_mesh_phase=[-2.0 * math.pi * float(x) for x in geo.phases.sun],
        ring_mesh_phase=[-2.0 * math.pi * float(x) for x in geo.phases.ring], **members, **KW)
    np.testing.assert_array_equal(gs.params, direct.params)
    np.testing.assert_array_equal(iso.params, direct.params)
    assert gs.stiffness_method == "iso" and gs.stiffness_tables is None
    assert gs.dataset_attrs() == {"mesh_stiffness_method": "iso",
                                  "mesh_coast_flank": "symmetric"}
    mirror = geardyn.PlanetaryGearSet.from_geometry(geo, **MEMBERS, **KW)
    assert mirror.coast_flank == "mirror" and mirror.params[pk.TWO_FLANK] == 1.0


def test_natural_frequencies_follow_the_mean_stiffness(geo, pe_tables):
    """At mean stiffness the set's natural frequencies are those of K = K_b + W^T diag(k) W
    assembled here with the tables' means (the ISO set's matrices with its mesh stiffness
    replaced): they move from the ISO set's as the mean stiffness ratio says."""
    iso = geardyn.PlanetaryGearSet.from_geometry(geo, **MEMBERS, **KW)
    gs = pe_set(geo)
    ks, kr = (t["mesh_stiffness"].values.mean() for t in pe_tables)
    assert abs(kr / iso.k_r - 1.0) > 0.2  # the methods differ (ring mesh): the check can fail
    W = iso.mesh_rows()
    K = iso.stiffness_matrix(meshes=False) + W.T @ (np.r_[[ks] * 4, [kr] * 4][:, None] * W)
    lam = eigh(K, iso.mass_matrix(), eigvals_only=True)
    want = np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * math.pi)
    np.testing.assert_allclose(gs.natural_frequencies(), want, rtol=1e-9, atol=1e-6)
    assert np.max(np.abs(gs.natural_frequencies() / iso.natural_frequencies() - 1.0)) > 0.02


def test_simulate_and_bifurcation_run_on_it(geo):
    gs = pe_set(geo, harmonics=20)
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=2.0, samples=3))
    assert ds.attrs["status"] == geardyn.Status.OK
    assert np.all(np.isfinite(ds["poincare"].values))
    br = geardyn.bifurcation(gs, "input_speed", [2000.0, 3000.0],
                             run=geardyn.RunSettings(transient=2.0, samples=2))
    assert np.all(br["status"].values == 0)
    assert br.attrs["mesh_stiffness_method"] == "potential_energy"
    assert np.all(np.isfinite(br["poincare"].values))


@pytest.mark.parametrize(("options", "field"), [
    ({"sun_bore_radius": "12 mm", "planet_bore_radius": "10 mm"},
     "stiffness_options.ring_rim_radius"),
    ({**BORES, "sun_bore_radius": "30 mm"}, "stiffness_options.sun_bore_radius"),
    ({**BORES, "planet_bore_radius": -1.0}, "stiffness_options.planet_bore_radius"),
    ({**BORES, "ring_rim_radius": "70 mm"}, "stiffness_options.ring_rim_radius"),
    ({**BORES, "angles": 16}, "stiffness_options.angles"),
    ({**BORES, "poisson": 0.6}, "stiffness_options.poisson"),
    ({**BORES, "bore": 1.0}, "stiffness_options.bore"),
])
def test_bad_options_name_the_field(geo, options, field):
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet.from_geometry(geo, stiffness="potential_energy",
                                               stiffness_options=options, **MEMBERS)
    assert err.value.field == field


def test_bad_method_names_the_field(geo):
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet.from_geometry(geo, stiffness="fem", **MEMBERS)
    assert err.value.field == "stiffness"
    with pytest.raises(ParameterError) as err:
        geardyn.PlanetaryGearSet.from_geometry(geo, stiffness_options=BORES, **MEMBERS)
    assert err.value.field == "stiffness_options"


# ---------------------------------------------------------------------------------------------
# the back (coast) flank

def _conformance_case() -> tuple[geardyn.PlanetaryGearSet, np.ndarray]:
    from conformance_cases import planetary

    gs = planetary()
    kick = np.random.default_rng(1).normal(0.0, 1.0, gs.n_states) * np.r_[[3.0] * 18,
                                                                         [1.0] * 18]
    return gs, gs.initial_state() + kick


def test_two_flank_form_with_equal_flanks_is_the_one_flank_form_bitwise():
    """The kernels' two-flank form (TWO_FLANK 1) with the coast entries equal to the drive ones
    gives the one-flank form's numbers bitwise: the per-lane rhs and observables at random
    states (on both flanks and in the dead zone), and integrated lanes (run_lanes)."""
    gs, y0 = _conformance_case()
    p0 = gs.params
    p1 = p0.copy()
    p1[pk.TWO_FLANK] = 1.0
    n = gs.n_states
    rng = np.random.default_rng(7)
    W = gs.mesh_rows()
    coast = 0
    for _ in range(20):
        y, t = rng.normal(0.0, 20.0, n), rng.uniform(0.0, 30.0)
        s, c = math.sin(gs.omega * t), math.cos(gs.omega * t)
        d0, d1 = np.zeros(n), np.zeros(n)
        pk.planetary_rhs(t, y, d0, p0, s, c)
        pk.planetary_rhs(t, y, d1, p1, s, c)
        np.testing.assert_array_equal(d0, d1)
        o0, o1 = np.zeros(W.shape[0]), np.zeros(W.shape[0])
        pk.planetary_observe(t, y, o0, p0, s, c)
        pk.planetary_observe(t, y, o1, p1, s, c)
        np.testing.assert_array_equal(o0, o1)
        coast += int(np.sum(W @ y[:n // 2] < -10.0 - 5.0))  # below -b - |e|: the coast flank
    assert coast > 20
    P0 = gs.lane_params("Omega", [0.8, 1.1, 1.3])
    P1 = P0.copy()
    P1[:, pk.TWO_FLANK] = 1.0
    r0 = run_lanes(gs, P0, y0, run=SHORT_RUN)
    r1 = run_lanes(gs, P1, y0, run=SHORT_RUN)
    np.testing.assert_array_equal(r0.samples, r1.samples)


def test_coast_stiffness_is_the_coast_tables_series(geo, pe_tables):
    """Deflected onto the coast flank (x < -b) every mesh's stiffness is the series of the
    table's ``mesh_stiffness_coast`` at theta - 2 pi gamma_n; onto the drive flank still the
    drive table's."""
    H = 30
    gs = pe_set(geo, harmonics=H)
    assert gs.params[pk.TWO_FLANK] == 1.0
    gam = np.concatenate([geo.phases.sun, geo.phases.ring])
    thetas = np.linspace(0.0, 2.0 * math.pi, 17)
    for sign, var in ((-1.0, "mesh_stiffness_coast"), (1.0, "mesh_stiffness")):
        k = [pe_tables[0][var].values] * 4 + [pe_tables[1][var].values] * 4
        got = kernel_stiffness(gs, thetas, sign)
        for m in range(8):
            want = series(k[m], H, thetas - 2.0 * math.pi * gam[m])
            np.testing.assert_allclose(got[:, m], want, rtol=1e-10)
    drive = kernel_stiffness(gs, thetas, 1.0)
    assert np.max(np.abs(kernel_stiffness(gs, thetas, -1.0) / drive - 1.0)) > 0.1
    assert gs.k_s_coast == pytest.approx(pe_tables[0]["mesh_stiffness_coast"].values.mean())


def _loaded_set(torque: float) -> geardyn.PlanetaryGearSet:
    """Three equally spaced planets, constant mesh stiffness, coast flanks unlike the drive
    flanks, ring and carrier held by torsional springs, the sun loaded by ``torque`` [N m]."""
    a = 24.6 * math.pi / 180
    return geardyn.PlanetaryGearSet(
        n_planets=3, sun_pressure_angle=a, ring_pressure_angle=a,
        sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
        carrier=M(5.43, 6.29, 1e8, 1e9), planet=M(0.66, 0.61, 1e8),
        sun_mesh_stiffness=5e8, ring_mesh_stiffness=6e8, sun_coast_stiffness=2.5e8,
        ring_coast_stiffness=9e8, sun_backlash="10 um", ring_backlash="5 um",
        sun_torque=torque, mesh_damping=0.1, modal_damping=0.1)


@pytest.mark.parametrize("torque", [-100.0, 100.0])
def test_static_deflection_is_the_loaded_flanks(torque):
    """Integrated from rest at zero deflection to rest, the mesh deflections are
    +-(b + F / k) with k the loaded flank's stiffness: the coast flank's under a negative sun
    torque. F = T_s / (N r_s) in every sun and ring mesh (the sun's torque balance over three
    equal planets, the planets' own balance F_rn = F_sn)."""
    gs = _loaded_set(torque)
    F = abs(torque) / (3 * 0.03)
    flank = ({"s": 2.5e8, "r": 9e8} if torque < 0 else {"s": 5e8, "r": 6e8})
    b = {"s": 10e-6, "r": 5e-6}
    want = np.array([math.copysign(b[m[0]] + F / flank[m[0]], torque) for m in gs.mesh_names])
    n = len(gs.dof_names())
    ds = geardyn.simulate(gs, run=geardyn.RunSettings(transient=2000.0, samples=2),
                          y0=np.zeros(gs.n_states))
    X = np.array([ds[name].values[-1] for name in gs.state_names[:n]])
    got = gs.mesh_rows() @ X * gs.length_scale
    np.testing.assert_allclose(got, want, rtol=1e-7)
    static = gs.mesh_rows() @ gs.static_state() * gs.length_scale
    np.testing.assert_allclose(static, want, rtol=1e-9)
    np.testing.assert_allclose(gs.static_mesh_forces(), math.copysign(F, torque), rtol=1e-9)


def test_lanes_reproduce_single_simulations_bitwise_with_two_flanks(geo):
    """The lane-block forms with two flanks (the coast rows of the stiffness cache) give each
    lane the per-lane functions' result, with contact lost on both sides."""
    gs = pe_set(geo, harmonics=12, sun_mesh_error="15 um", ring_mesh_error="15 um")
    omegas = np.array([0.5, 0.8, 1.1])
    r = run_lanes(gs, gs.lane_params("Omega", omegas), gs.initial_state(), run=SHORT_RUN)
    assert np.all(r.status == 0)
    for j in (0, 2):
        ds = geardyn.simulate(gs, omega=omegas[j], y0=gs.initial_state(),
                              run=geardyn.RunSettings(transient=10.0, samples=3,
                                                      steps_per_period=64))
        np.testing.assert_array_equal(r.samples[j], ds["poincare"].values[1:])
    assert np.any(r.event_min[:, 1::2] < 0.0)  # x + b < 0 while sampling: the coast flank


def test_raw_overrides_and_the_flag():
    """A raw override of a drive entry of a one-flank set keeps one stiffness on both flanks (as
    before the coast flank existed); one of a coast entry makes the set two-flank."""
    gs, _ = _conformance_case()
    k = gs.params[gs.param_index("s1_KF")]
    assert gs.with_params(s1_KF=2 * k).params[pk.TWO_FLANK] == 0.0
    assert gs.with_params(s1_a1=0.1).params[pk.TWO_FLANK] == 0.0
    assert gs.with_params(s1_KF_coast=2 * k).params[pk.TWO_FLANK] == 1.0
    assert gs.with_params(r2_bc1=0.1).params[pk.TWO_FLANK] == 1.0
    two = _loaded_set(-1.0)
    assert two.params[pk.TWO_FLANK] == 1.0
    same = two.with_params(sun_coast_stiffness=5e8, ring_coast_stiffness=6e8)
    assert same.params[pk.TWO_FLANK] == 0.0  # given, but equal to the drive flank


@pytest.mark.parametrize(("kw", "field"), [
    ({"coast_waveform": "sine"}, "coast_waveform"),
    ({"coast_waveform": ([1.5], [0.0])}, "coast_waveform"),  # 1 + 1.5 cos < 0 somewhere
    ({"sun_coast_stiffness": -1.0}, "sun_coast_stiffness"),
    ({"ring_coast_stiffness": "5 m"}, "ring_coast_stiffness"),
])
def test_bad_coast_inputs_name_the_field(kw, field):
    with pytest.raises(ParameterError) as err:
        _loaded_set(1.0).with_params(**kw)
    assert err.value.field == field


def test_from_geometry_refuses_coast_inputs(geo):
    with pytest.raises(ParameterError) as err:
        pe_set(geo, sun_coast_stiffness=1e8)
    assert err.value.field == "sun_coast_stiffness"
