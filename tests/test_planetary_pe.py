"""PlanetaryGearSet.from_geometry with the potential-energy mesh stiffness.

The compiled kernel's mesh stiffness (its mesh force at unit deflection, the observable) is
compared with the discrete Fourier series of the potential-energy table computed here by direct
sums, and with the table itself as the harmonics grow; the natural frequencies with an
eigenproblem assembled here with the table's mean stiffnesses; the ISO default with the set
built directly from the ISO waves.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError

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
    assert gs.dataset_attrs() == {"mesh_stiffness_method": "potential_energy"}
    assert gs.k_s == pytest.approx(k[0].mean(), rel=1e-12)
    assert gs.k_r == pytest.approx(k[4].mean(), rel=1e-12)


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
    every jump (where a tooth pair enters or leaves contact: there the series overshoots by
    about a tenth of the jump, Gibbs, whatever H) fall; at H = 160 the rms is below 1.5 % of
    the mean stiffness (it falls as 1/sqrt(H), the jumps' share), the error away from the
    jumps below 0.5 % (it falls as 1/H)."""
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


def test_iso_default_is_the_iso_waves_bitwise(geo):
    """The default (and stiffness="iso") builds the set from the ISO waves exactly as a direct
    construction from the waves here does."""
    gs = geardyn.PlanetaryGearSet.from_geometry(geo, **MEMBERS, **KW)
    iso = geardyn.PlanetaryGearSet.from_geometry(geo, stiffness="iso", **MEMBERS, **KW)
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
    assert gs.dataset_attrs() == {"mesh_stiffness_method": "iso"}


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
