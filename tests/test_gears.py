"""geardyn.gears: geometry, ISO 6336-1 stiffness, stiffness waves and planetary mesh phasing,
each checked against an independent computation or a published value."""

from __future__ import annotations

import ast
import io
import math
import re
import tokenize
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import geardyn
from geardyn.cli.errors import format_error
from geardyn.errors import ParameterError
from geardyn.gears import (
    GearMesh,
    PlanetaryGeometry,
    SpurGear,
    StiffnessWaveform,
    iso6336_stiffness,
    mesh_phases,
    mesh_stiffness_waveform,
    sun_ring_phase,
    surviving_harmonics,
)
from geardyn.models import stiffness
from geardyn.models.params import Mesh

DEG = math.pi / 180.0


def gear(z, x=0.0, m=4e-3, b=0.04, **kw):
    return SpurGear(z, m, 20 * DEG, b, x, **kw)


# -- geometry ---------------------------------------------------------------------------------

def test_public_module():
    assert "gears" in geardyn.__all__ and geardyn.gears.SpurGear is SpurGear
    assert callable(geardyn.gears.mesh_phases)


def test_khk_profile_shifted_external_pair():
    """The profile-shifted spur pair of the KHK Gear Technical Reference (z1 = 12, z2 = 24,
    m = 3, alpha = 20 deg, x1 = 0.6, x2 = 0.36), as tabulated in "Profile Shifted External Spur
    Gears", bolsover.com/utilitiesforalibre/profile-shifted-external-spur-gears.html: working
    centre distance 56.500 mm, working pressure angle 26.0888 deg (from a = 56.500; a computed
    from the shifts is 56.4999 mm), outside diameters 44.840 and 79.400 mm, contact ratio
    1.202."""
    mesh = GearMesh(gear(12, 0.6, m=3e-3), gear(24, 0.36, m=3e-3))
    assert math.degrees(mesh.operating_pressure_angle) == pytest.approx(26.0888, abs=3e-4)
    assert mesh.centre_distance * 1e3 == pytest.approx(56.500, abs=5e-4)
    # KHK shortens both tips to keep the standard clearance at the widened centre distance
    # (addendum (1 + y - x_other) m, y = 0.8333): an addendum factor of 1 - (x1 + x2 - y)
    ha = 1.0 - (0.6 + 0.36 - (56.5 - 54.0) / 3.0)
    short = GearMesh(gear(12, 0.6, m=3e-3, addendum=ha), gear(24, 0.36, m=3e-3, addendum=ha))
    assert 2e3 * short.pinion.tip_radius == pytest.approx(44.840, abs=1e-3)
    assert 2e3 * short.wheel.tip_radius == pytest.approx(79.400, abs=1e-3)
    assert short.contact_ratio == pytest.approx(1.202, abs=5e-4)


def test_khk_profile_shifted_internal_pair():
    """KHK Gear Technical Reference, profile shifted internal gear example (z1 = 16, z2 = 24,
    m = 3, alpha = 20 deg, x1 = 0, x2 = +0.5): alpha_w = 31.0937 deg, a = 13.1683 mm. (The
    ring's addendum is cut to 0.8 m here: KHK's tip circle is at the limit of involute
    interference, which does not change alpha_w and a.)"""
    pinion = gear(16, 0.0, m=3e-3, check_undercut=False)
    ring = gear(24, 0.5, m=3e-3, internal=True, addendum=0.8)
    mesh = GearMesh(pinion, ring, internal=True)
    assert math.degrees(mesh.operating_pressure_angle) == pytest.approx(31.0937, abs=1e-4)
    assert mesh.centre_distance * 1e3 == pytest.approx(13.1683, abs=1e-4)


def test_din_example_against_an_independent_implementation():
    """DIN 3990 example m_n = 4, z = (19, 104), x = (0.5, 0.15): the values of the independent
    implementation github.com/hanslhansl/din3990 (tests/test_1.py, geometry by DIN 21771):
    a_w = 248.506843355171 mm, alpha_wt = 21.531902292465457 deg, eps_alpha = 1.53632359458323."""
    mesh = GearMesh(gear(19, 0.5), gear(104, 0.15))
    assert mesh.centre_distance * 1e3 == pytest.approx(248.506843355171, rel=1e-12)
    assert math.degrees(mesh.operating_pressure_angle) == pytest.approx(21.531902292465457,
                                                                        rel=1e-12)
    assert mesh.contact_ratio == pytest.approx(1.5363235945832296, rel=1e-12)


def _contact_ratio_by_construction(mesh: GearMesh) -> float:
    """Place the pinion at the origin and the wheel (or ring) centre at (a, 0), find the common
    tangent of the base circles (the line of action) by root finding, intersect it with the tip
    circles numerically and measure the active part around the pitch point."""
    p, w = mesh.pinion, mesh.wheel
    a = mesh.centre_distance
    o1, o2 = np.zeros(2), np.array([a, 0.0])
    sgn = -1.0 if mesh.internal else 1.0
    # the line {y : n.y = rb1} touches the pinion's base circle; the wheel's centre lies at
    # distance rb2 on the other side (external) or the same side (internal)
    theta = brentq(lambda t: a * math.cos(t) - p.base_radius - sgn * w.base_radius, 0.0, math.pi)
    n = np.array([math.cos(theta), math.sin(theta)])
    t_dir = np.array([-n[1], n[0]])
    foot = p.base_radius * n  # tangent point T1

    def chord(centre, radius):
        """Line parameters s where it crosses the circle (roots either side of the nearest
        point)."""
        s0 = float(np.dot(centre - foot, t_dir))
        f = lambda s: np.linalg.norm(foot + s * t_dir - centre) - radius  # noqa: E731
        big = 10.0 * (a + radius)
        return brentq(f, s0 - big, s0), brentq(f, s0, s0 + big)

    z1, z2 = p.teeth, w.teeth
    pitch_point = (np.array([-a * z1 / (z2 - z1), 0.0]) if mesh.internal
                   else np.array([a * z1 / (z1 + z2), 0.0]))
    assert abs(np.dot(pitch_point, n) - p.base_radius) < 1e-12  # it lies on the line
    pitch = float(np.dot(pitch_point - foot, t_dir))
    lo1, hi1 = chord(o1, p.tip_radius)
    lo2, hi2 = chord(o2, w.tip_radius)
    if mesh.internal:  # inside the pinion's tip circle, outside the ring's (teeth point inwards)
        left = max([s for s in (lo2, hi2) if s <= pitch] + [lo1])
        right = min([s for s in (lo2, hi2) if s >= pitch] + [hi1])
    else:
        left, right = max(lo1, lo2), min(hi1, hi2)
    assert left < pitch < right
    return (right - left) / (math.pi * p.module * math.cos(p.pressure_angle))


@pytest.mark.parametrize("pinion, wheel, internal, a", [
    (gear(19, 0.5), gear(104, 0.15), False, None),
    (gear(18), gear(40), False, None),
    (gear(23, 0.2), gear(61, -0.1), False, 0.16866),  # a little backlash
    (gear(20), gear(70, internal=True), True, None),
    (gear(24, 0.3), gear(72, 0.2, internal=True), True, None),
])
def test_contact_ratio_by_construction(pinion, wheel, internal, a):
    mesh = GearMesh(pinion, wheel, centre_distance=a, internal=internal)
    assert mesh.contact_ratio == pytest.approx(_contact_ratio_by_construction(mesh), rel=1e-9)


@pytest.mark.parametrize("build, field, reason", [
    (lambda: gear(4), "gear.teeth", ">= 5"),
    (lambda: gear(12, 0.0), "gear.profile_shift", "undercut"),
    (lambda: gear(20, 1.4), "gear.profile_shift", "pointed"),
    (lambda: GearMesh(gear(20, addendum=0.5), gear(30, addendum=0.5)), "contact_ratio", ">= 1"),
    (lambda: GearMesh(gear(20), gear(30), centre_distance=0.0995), "centre_distance",
     "overlap"),
    (lambda: GearMesh(gear(20), gear(30), centre_distance=0.103), "centre_distance",
     "inconsistent"),
    (lambda: GearMesh(gear(20), gear(30), centre_distance=0.05), "centre_distance", "exceed"),
    (lambda: GearMesh(gear(16, check_undercut=False), gear(24, 0.5, internal=True),
                      internal=True), "wheel.profile_shift", "interference"),
    (lambda: gear(26, internal=True), "gear.profile_shift", "no involute"),
    (lambda: GearMesh(gear(14, 0.4), gear(150, 0.0, addendum=1.6)), "wheel.teeth",
     "interference"),
    (lambda: PlanetaryGeometry(gear(24, m=2e-3), gear(24, m=2e-3), gear(72, m=2e-3, internal=True),
                               n_planets=6), "planet_angles", "collide"),
    (lambda: mesh_phases(24, 72, 5), "planet_angles[1]", "assembled"),
    (lambda: mesh_phases(25, 71, 4, sun_turns=0), "sun_turns", "sense"),
])
def test_bad_geometry_names_the_field(build, field, reason):
    with pytest.raises(ParameterError, match=reason) as info:
        build()
    assert info.value.field == field
    assert format_error(info.value).startswith(f"{field}: ")  # the CLI's line (exit 2)


def test_inverse_involute_round_trip():
    alpha = np.linspace(0.01, 1.45, 50)
    back = [geardyn.gears.inverse_involute(geardyn.gears.involute(a)) for a in alpha]
    assert np.allclose(back, alpha, rtol=0, atol=1e-13)


def test_unit_strings():
    g = SpurGear(20, "3 mm", "20 deg", "25 mm", 0.1)
    assert g.module == pytest.approx(3e-3) and g.pressure_angle == pytest.approx(20 * DEG)


# -- ISO 6336-1 method B ------------------------------------------------------------------------

#: The two spur planetary stages of the NREL 5 MW reference gearbox: gear data from Nejad,
#: Guo, Gao & Moan, "Development of a 5 MW reference gearbox for offshore wind turbines", Wind
#: Energy 19 (2016) 1089-1106, doi:10.1002/we.1884; the stiffnesses as KISSsoft 03/2017
#: (ISO 6336:2006 method B) reports them for those stages, computed by G. F. S. Rebouças (NTNU)
#: and published in github.com/gfsReboucas/Drivetrain, @NREL_5MW/stage_01.rtf and stage_02.rtf
#: ("Singular tooth stiffness c'", "Meshing stiffness cgalf", "Transverse contact ratio").
#: Every gear: alpha_n = 20 deg, basic rack h_aP* 1.0, h_fP* 1.25 (so C_B = 0.975), C_M 0.8,
#: webbed blanks b_s/b = 0.25 with C_R printed as 0.862 (s_R/m_n = 3.5 gives 0.86232), line
#: load above 100 N/mm (519.8 and 1587.5 N/mm). Profile shifts in ISO 21771's sign (an
#: internal gear's x is -x of geardyn's convention); tip alteration k m_n of the external gears
#: (-1.750 mm and -10.861 mm) as the addendum factor 1 + k.
#: (stage, mesh): (module, (z1, x1, k1), (z2, x2_iso, k2), internal, c', c_gamma_alpha, eps_a)
NREL_5MW = {
    ("stage 2", "sun-planet"): (21e-3, (18, 0.3890, -1.75 / 21), (36, 0.5039, -1.75 / 21),
                                False, 12.240, 15.640, 1.370),
    ("stage 2", "planet-ring"): (21e-3, (36, 0.5039, -1.75 / 21), (93, 0.1171, 0.0),
                                 True, 14.053, 20.563, 1.618),
    ("stage 1", "sun-planet"): (45e-3, (19, 0.6170, -10.861 / 45), (17, 0.8021, -10.861 / 45),
                                False, 12.362, 13.426, 1.115),
    ("stage 1", "planet-ring"): (45e-3, (17, 0.8021, -10.861 / 45), (56, -0.5013, 0.0),
                                 True, 13.289, 16.063, 1.278),
}


@pytest.mark.parametrize("case", list(NREL_5MW), ids=" ".join)
def test_iso_stiffness_against_kisssoft_for_the_nrel_5mw_gearbox(case):
    """c', c_gamma_alpha and eps_alpha against the independent KISSsoft figures (printed to 3
    decimals: 6e-4 covers their rounding). Stage 1's sun (19 teeth) is larger than its planets
    (17): ISO's gear 1 is then the planet, and taking the sun as gear 1 gives c' = 12.665,
    2.4 % off; the ring's profile shift enters with ISO's sign (the other sign gives 13.81
    instead of 13.289)."""
    m, (z1, x1, k1), (z2, x2, k2), internal, c_ref, c_ga_ref, eps_ref = NREL_5MW[case]
    first = SpurGear(z1, m, 20 * DEG, 0.5, x1, addendum=1 + k1)
    second = SpurGear(z2, m, 20 * DEG, 0.5, -x2 if internal else x2, addendum=1 + k2,
                      internal=internal)
    iso = iso6336_stiffness(GearMesh(first, second, internal=internal), web_ratio=0.25,
                            rim_ratio=3.5)
    assert iso.C_B == pytest.approx(0.975) and iso.C_R == pytest.approx(0.862, abs=5e-4)
    assert iso.contact_ratio == pytest.approx(eps_ref, abs=6e-4)
    assert iso.c_prime == pytest.approx(c_ref, abs=6e-4)
    assert iso.c_gamma_alpha == pytest.approx(c_ga_ref, abs=6e-4)
    assert iso.z_n1 == (z1 if internal else min(z1, z2))


def test_iso_single_and_mesh_stiffness_by_hand():
    """ISO 6336-1:2006 clause 9, method B, by hand with the standard's numbers written out, for
    the DIN 3990 example pair z = (19, 104), x = (0.5, 0.15), basic rack h_fP = 1.25 m,
    alpha_Pn = 20 deg, solid blanks, F_t K_A / b >= 100 N/mm, b = 48.64 mm."""
    mesh = GearMesh(gear(19, 0.5, b=48.64e-3), gear(104, 0.15, b=48.64e-3))
    iso = iso6336_stiffness(mesh)
    q = (0.04723 + 0.15551 / 19 + 0.25791 / 104 - 0.00635 * 0.5 - 0.11654 * 0.5 / 19
         - 0.00193 * 0.15 - 0.24188 * 0.15 / 104 + 0.00529 * 0.5 ** 2 + 0.00182 * 0.15 ** 2)
    c_b = (1 + 0.5 * (1.2 - 1.25)) * (1 - 0.02 * (20 - 20))
    c_prime = (1 / q) * 0.8 * 1.0 * c_b * 1.0
    eps = 1.5363235945832296  # hanslhansl/din3990, see above
    assert iso.q_prime == pytest.approx(q, rel=1e-12)
    assert iso.C_B == pytest.approx(0.975)
    assert iso.c_prime == pytest.approx(c_prime, rel=1e-12)
    assert iso.c_gamma_alpha == pytest.approx(c_prime * (0.75 * eps + 0.25), rel=1e-12)
    assert iso.mesh_stiffness == pytest.approx(c_prime * (0.75 * eps + 0.25) * 1e9 * 48.64e-3)
    # the standard's round values for solid steel spur gears on a standard basic rack
    # (c' ~ 14, c_gamma ~ 20 N/(mm um))
    assert iso.c_prime == pytest.approx(14.0, rel=0.1)
    assert iso.c_gamma_alpha == pytest.approx(20.0, rel=0.1)
    assert set(iso.as_dict()) >= {"q_prime", "c_th", "C_M", "C_R", "C_B", "c_prime"}


def test_iso_corrections_internal_load_and_blank():
    mesh = GearMesh(gear(20), gear(70, internal=True), internal=True)
    iso = iso6336_stiffness(mesh)
    assert math.isinf(iso.z_n2)
    assert iso.q_prime == pytest.approx(0.04723 + 0.15551 / 20)  # z_n2 = inf, x = 0
    low = iso6336_stiffness(mesh, line_load=50e3)  # 50 N/mm
    assert low.c_prime == pytest.approx(iso.c_prime * 0.5 ** 0.25)
    assert iso6336_stiffness(mesh, line_load=150e3).c_prime == pytest.approx(iso.c_prime)
    webbed = iso6336_stiffness(mesh, web_ratio=0.5, rim_ratio=3.0)
    assert webbed.C_R == pytest.approx(1 + math.log(0.5) / (5 * math.exp(0.6)))
    with pytest.raises(ParameterError, match="b_s/b"):
        iso6336_stiffness(mesh, web_ratio=0.1, rim_ratio=3.0)


# -- stiffness waveform -------------------------------------------------------------------------

def test_waveform_mean_is_iso_mesh_stiffness_and_double_contact_fraction():
    mesh = GearMesh(gear(19, 0.5), gear(104, 0.15))
    wave = mesh_stiffness_waveform(mesh)
    theta = np.linspace(0, 2 * np.pi, 200_000, endpoint=False)
    k = wave(theta)
    assert k.mean() == pytest.approx(iso6336_stiffness(mesh).mesh_stiffness, rel=1e-4)
    assert np.mean(k > 0.5 * (k.min() + k.max())) == pytest.approx(mesh.contact_ratio - 1,
                                                                 abs=1e-4)


@pytest.mark.parametrize("internal", [False, True])
def test_waveform_phase_by_counting_pairs_on_the_line_of_action(internal):
    """Pairs one base pitch apart move along the path of contact [0, g_alpha]; one passes the
    pitch point (at g_f) at phase 0. The wave is high exactly where two pairs are in contact."""
    wheel = gear(72, 0.2, internal=True) if internal else gear(61, -0.1)
    mesh = GearMesh(gear(23, 0.2), wheel, internal=internal)
    wave = mesh_stiffness_waveform(mesh)
    u = np.linspace(0, 1, 5001)[:-1] + 1e-5  # cycles after a pitch-point crossing
    pos = mesh.approach_length + (u[:, None] + np.arange(-3, 4)[None, :]) * mesh.base_pitch
    pairs = np.sum((pos >= 0) & (pos <= mesh.path_of_contact), axis=1)
    high = wave(2 * np.pi * u) > 0.5 * (wave.single + wave.double)
    assert set(pairs) == {1, 2}
    assert np.array_equal(high, pairs == 2)


def test_fourier_coefficients_match_fft_and_mesh_model():
    wave = StiffnessWaveform(single=4e8, double=7e8, contact_ratio=1.63, centre=0.21,
                             transition=0.05)
    n = 4096
    theta = 2 * np.pi * np.arange(n) / n
    spec = np.fft.rfft(wave(theta, phase=0.3) / wave.mean) / n
    a, b = wave.fourier(40, phase=0.3)
    assert np.allclose(a, 2 * spec.real[1:41], atol=2e-6)
    assert np.allclose(b, -2 * spec.imag[1:41], atol=2e-6)
    # geardyn.Mesh's rectangular wave: the same coefficients times its Lanczos factors
    rect = StiffnessWaveform(single=4e8, double=7e8, contact_ratio=1.63, centre=0.21)
    m = Mesh(**rect.mesh_fields(phase=0.3, harmonics=40), backlash=0.0, error=0.0,
             damping_ratio=0.05)
    am, bm = stiffness.fourier_coefficients(m, 40)
    a0, b0 = rect.fourier(40, phase=0.3)
    sigma = np.sinc(np.arange(1, 41) / 41)
    assert np.allclose(am, a0 * sigma, atol=1e-14) and np.allclose(bm, b0 * sigma, atol=1e-14)
    assert m.mean_stiffness == pytest.approx(rect.mean)
    with pytest.raises(ParameterError, match="ramp"):
        wave.mesh_fields()


# -- planetary mesh phasing ---------------------------------------------------------------------

def _rect(u, duty=0.6317):  # off the sample grid
    """A rectangular mesh force over the cycle fraction u (test's own, pure numpy)."""
    return 1.0 + (((u + 0.01234) % 1.0) < duty)


@pytest.mark.parametrize("z_s, z_r, n_planets", [(24, 72, 4), (25, 71, 4), (24, 71, 5),
                                                 (21, 69, 3)])
def test_net_sun_force_shows_the_harmonics_the_rules_predict(z_s, z_r, n_planets):
    """Net torque and net force on the sun (and ring) from N equally spaced planets, each mesh
    force k(t - gamma_n T) along its line of action; FFT over 8 mesh periods."""
    ph = mesh_phases(z_s, z_r, n_planets)
    per, periods = 60 * n_planets, 8
    t = np.arange(per * periods) / per  # mesh cycles
    for teeth, gammas, c in ((z_s, ph.sun, 0.35), (z_r, ph.ring, -0.35)):
        forces = np.array([_rect(t - g) for g in gammas])
        directions = np.exp(1j * (ph.planet_angles + c))
        torque = np.fft.fft(forces.sum(axis=0)) / t.size
        force = np.fft.fft((forces * directions[:, None]).sum(axis=0)) / t.size
        rules = surviving_harmonics(teeth, n_planets, 10)
        for ell in range(1, 11):
            k = ell * periods
            f_amp = max(abs(force[k]), abs(force[-k]))
            assert (abs(torque[k]) > 1e-3) == rules[ell]["torque"], (teeth, ell)
            assert (f_amp > 1e-3) == rules[ell]["force"], (teeth, ell)
            # independent statement of the rule
            assert rules[ell]["torque"] == (ell * teeth % n_planets == 0)
            if not rules[ell]["torque"]:
                assert abs(torque[k]) < 1e-12
            if not rules[ell]["force"]:
                assert f_amp < 1e-12


def test_in_phase_and_sequential_phasing():
    in_phase = mesh_phases(24, 72, np.int64(4))
    assert np.allclose(in_phase.sun, 0) and np.allclose(in_phase.ring, 0)
    seq = mesh_phases(25, 71, 4)
    assert np.allclose(seq.sun, [0, 0.25, 0.5, 0.75])
    assert np.allclose(seq.ring, [0, 0.25, 0.5, 0.75])  # -71/4 = 0.25 (mod 1)
    uneven = mesh_phases(25, 71, np.array([0.0, 90.0, 187.5, 277.5]) * DEG)
    assert np.allclose(uneven.sun, (25 * uneven.planet_angles / (2 * np.pi)) % 1)


@pytest.mark.parametrize("z_p, expected", [(23, 0.0), (24, 0.5)])
def test_sun_ring_phase_of_standard_gears_by_symmetry(z_p, expected):
    """Unshifted gears roll on their reference circles, where tooth and space are equally wide:
    with an odd tooth count a tooth faces a space across the planet, so the sun-side and
    ring-side flanks reach their pitch points together (gamma_rs = 0); with an even count half a
    pitch apart (gamma_rs = 1/2)."""
    sun, ring = gear(25, m=2e-3), gear(25 + 2 * z_p, m=2e-3, internal=True)
    planet = gear(z_p, m=2e-3)
    g = sun_ring_phase(GearMesh(sun, planet), GearMesh(planet, ring, internal=True))
    gap = abs(g - expected)
    assert min(gap, 1 - gap) < 1e-12


def test_planetary_geometry_ties_the_meshes_together():
    pg = PlanetaryGeometry(gear(25, m=2e-3), gear(23, m=2e-3), gear(71, m=2e-3, internal=True),
                           n_planets=4)
    assert pg.ring_mesh.centre_distance == pg.sun_mesh.centre_distance == pytest.approx(0.048)
    assert pg.phases.sun_ring == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(pg.phases.ring, [0, 0.25, 0.5, 0.75])
    k_sun, k_ring = pg.stiffness()
    assert k_ring.c_prime > k_sun.c_prime  # an internal mesh is stiffer
    w_sun, w_ring = pg.waveforms()
    assert w_sun.mean == pytest.approx(k_sun.mesh_stiffness)


@pytest.mark.parametrize("z_s, z_r, angles_deg", [(25, 71, [0, 90, 180, 270]),
                                                  (25, 71, [0, 90, 187.5, 277.5]),
                                                  (21, 69, [0, 120, 240])])
@pytest.mark.parametrize("sun_turns", [1, -1])
def test_phases_by_following_the_teeth(z_s, z_r, angles_deg, sun_turns):
    """Carrier frame: the sun's teeth turn in the sense ``sun_turns`` of psi, the ring's the
    other way; a mesh event is a tooth passing the planet's direction psi_n. The first event
    after t = 0 at each planet, relative to planet 1's, in mesh cycles."""
    psi = np.radians(angles_deg)
    ph = mesh_phases(z_s, z_r, psi, sun_turns=sun_turns)

    def first_event(teeth, direction, offset):
        # tooth j at angle offset + direction * t + 2 pi j / teeth (t in mesh cycles: one
        # cycle turns the gear by one pitch); the first t >= 0 at which one sits at psi_n
        pitch = 2 * np.pi / teeth
        return np.array([((p - offset) * direction / pitch) % 1.0 for p in psi])

    sun = first_event(z_s, sun_turns, 0.123)
    ring = first_event(z_r, -sun_turns, 0.456)
    gap_s = np.abs((sun - sun[0]) % 1.0 - ph.sun)
    assert np.all(np.minimum(gap_s, 1 - gap_s) < 1e-9)
    ring_rel = (ring - ring[0]) % 1.0
    expected = (ph.ring - ph.ring[0]) % 1.0
    gap = np.abs(ring_rel - expected)
    assert np.all(np.minimum(gap, 1 - gap) < 1e-9)


def test_angular_thickness_against_a_parametric_involute():
    """Build the tooth's flank point by point (the involute unwound from the base circle,
    turned so that its width on the reference circle is m (pi/2 + 2 x tan alpha)) and measure
    its angular width at other radii."""
    g = gear(23, 0.3, m=2e-3)
    rb = g.base_radius

    def flank_angle(r):  # polar angle of the standard involute at radius r (numerically)
        u = brentq(lambda u: rb * math.hypot(1.0, u) - r, 0.0, 10.0)
        x, y = rb * (math.cos(u) + u * math.sin(u)), rb * (math.sin(u) - u * math.cos(u))
        return math.atan2(y, x)

    s_ref = g.module * (math.pi / 2 + 2 * 0.3 * math.tan(g.pressure_angle))
    beta0 = s_ref / (2 * g.reference_radius) + flank_angle(g.reference_radius)
    for r in (rb * 1.001, g.reference_radius, 0.5 * (g.reference_radius + g.tip_radius),
              g.tip_radius):
        assert g.angular_thickness(r) == pytest.approx(2 * (beta0 - flank_angle(r)), abs=1e-12)


# -- the documented example ----------------------------------------------------------------------

DOCS = Path(__file__).resolve().parents[1] / "docs"
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_HARMONIC = re.compile(r"(\d+): (force|torque|none)")


def _documented(comment: str) -> tuple[object, float] | None:
    """The value a ``# ...`` comment documents, and half a unit of its last digit shown: the
    longest prefix of whitespace-separated words that is a Python literal; None if none is."""
    words = comment.split()
    for n in range(len(words), 0, -1):
        text = " ".join(words[:n])
        try:
            value = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            continue
        digits = [Decimal(t).as_tuple().exponent for t in _NUMBER.findall(text)]
        return value, 0.5 * 10.0 ** min(digits) if digits else 0.0
    return None


def _run_documented_block(path: Path) -> list[tuple[str, object, object, float]]:
    """Run the first python block of ``path`` statement by statement; for every expression
    whose comment documents a value: (source, value returned, value documented, tolerance)."""
    text = path.read_text()
    code = text.split("```python\n", 1)[1].split("```", 1)[0]
    comments = {tok.start[0]: tok.string[1:].strip()
                for tok in tokenize.generate_tokens(io.StringIO(code).readline)
                if tok.type == tokenize.COMMENT}
    ns: dict = {}
    checks = []
    for node in ast.parse(code).body:
        comment = comments.get(node.end_lineno, "")
        if not isinstance(node, ast.Expr):
            exec(compile(ast.Module([node], []), str(path), "exec"), ns)
            continue
        value = eval(compile(ast.Expression(node.value), str(path), "eval"), ns)
        harmonics = _HARMONIC.findall(comment)
        if harmonics:  # {1: force, 2: none, ...}: the harmonics that survive
            want = {int(h): {"torque": k == "torque", "force": k == "force"}
                    for h, k in harmonics}
            checks.append((ast.get_source_segment(code, node), value, want, 0.0))
            continue
        doc = _documented(comment)
        if doc is not None:
            checks.append((ast.get_source_segment(code, node), value, *doc))
    return checks


def test_gears_doc_example_numbers_are_what_the_code_returns():
    """docs/gears.md's example: every number in a comment equals the code's value to the
    digits shown (contact ratios, ISO c' and c_gamma_alpha, mesh stiffness, phases, harmonics)."""
    checks = _run_documented_block(DOCS / "gears.md")
    assert len(checks) >= 9  # the block's documented values are all found
    for source, value, want, tol in checks:
        if isinstance(want, dict):
            assert value == want, source
            continue
        got = np.atleast_1d(np.asarray(value, dtype=float))
        assert got.shape == np.atleast_1d(np.asarray(want, dtype=float)).shape, source
        assert np.all(np.abs(got - np.asarray(want, dtype=float)) <= tol * (1 + 1e-9)), \
            f"{source}: the code gives {value}, docs/gears.md says {want}"
