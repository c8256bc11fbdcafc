"""Helical meshes in a gear train's linear model: the line of action inclined by the base helix
angle, ISO 6336-1 stiffness of helical pairs, and the errors of meshes that cannot be."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, HelicalGear, HelicalMesh, SpurGear, iso6336_stiffness
from geardyn.trains import Bearing, Gear, GearTrain, Mesh

I1, I2 = 9.0, 390.0  # kg m^2


def _helical(teeth: int, shift: float, beta: str = "10 deg", name: str = "gear") -> HelicalGear:
    return HelicalGear(teeth, "14 mm", "20 deg", beta, "360 mm", profile_shift=shift, name=name)


def _pair(geometry=None, **mesh) -> GearTrain:
    g1 = geometry[0] if geometry else None
    g2 = geometry[1] if geometry else None
    gears = [Gear("pinion", I1, geometry=g1, **({} if g1 else {"base_radius": 0.16})),
             Gear("wheel", I2, geometry=g2, **({} if g2 else {"base_radius": 0.63}))]
    return GearTrain(gears, bearings=[Bearing("b1", "pinion", math.inf),
                                      Bearing("b2", "wheel", math.inf)],
                     meshes=[Mesh("m", "pinion", "wheel", **mesh)], free=True)


def _torsional(k_transverse: float, r1: float, r2: float) -> float:
    """Closed form [Hz]: two inertias on a spring k along the transverse line of action."""
    m_e = I1 * I2 / (I1 * r2 ** 2 + I2 * r1 ** 2)
    return math.sqrt(k_transverse / m_e) / (2 * math.pi)


def test_given_stiffness_is_along_the_inclined_line_of_action():
    """k_n along a line inclined by beta_b: the torsional mode sees k_n cos^2(beta_b), with
    beta_b = atan(tan(beta) cos(alpha))."""
    beta, alpha, k = math.radians(15.0), math.radians(20.0), 5e9
    train = _pair(stiffness=k, helix_angle=beta)
    beta_b = math.atan(math.tan(beta) * math.cos(alpha))
    f = train.natural_frequencies()[1]
    assert f == pytest.approx(_torsional(k * math.cos(beta_b) ** 2, 0.16, 0.63), rel=1e-12)
    assert train.mesh_data["m"].base_helix_angle == pytest.approx(beta_b, rel=1e-15)
    spur = _pair(stiffness=k).natural_frequencies()[1]
    assert f < spur


def test_iso_helical_pair_resonance_is_iso_6336_1_resonance_speed():
    """ISO 6336-1 (clause 6) puts the pair's resonance at n_E1 = 30000 / (pi z1)
    sqrt(c_gamma_alpha / m_red) [rpm], m_red = m1* m2* / (m1* + m2*) per mm of face width with
    m* = J / (b r_b^2) (transverse base radii): the train's torsional mode with stiffness "iso"
    is that mesh frequency n_E1 z1 / 60."""
    p, w = _helical(24, 0.48, name="pinion"), _helical(95, 0.669, name="wheel")
    train = _pair((p, w), stiffness="iso")
    iso = iso6336_stiffness(HelicalMesh(p, w))
    b_mm = iso.face_width * 1e3
    r1, r2 = p.transverse.base_radius, w.transverse.base_radius
    m1, m2 = I1 / (b_mm * r1 ** 2), I2 / (b_mm * r2 ** 2)  # kg per mm of face width
    m_red = m1 * m2 / (m1 + m2)
    n_e1 = 30000.0 / (math.pi * 24) * math.sqrt(iso.c_gamma_alpha / m_red)
    assert train.natural_frequencies()[1] == pytest.approx(n_e1 * 24 / 60.0, rel=1e-12)


def test_iso_helical_uses_virtual_teeth_and_cos_beta():
    """The helical pair's q' takes z_n = z / (cos^2(beta_b) cos(beta)), and c' the factor
    cos(beta) (ISO 6336-1 method B); at beta = 0 it is the spur pair's value exactly."""
    p, w = _helical(24, 0.48), _helical(95, 0.669)
    iso = iso6336_stiffness(HelicalMesh(p, w))
    beta = math.radians(10.0)
    alpha_t = math.atan(math.tan(math.radians(20.0)) / math.cos(beta))
    beta_b = math.atan(math.tan(beta) * math.cos(alpha_t))
    assert iso.z_n1 == pytest.approx(24 / (math.cos(beta_b) ** 2 * math.cos(beta)), rel=1e-12)
    assert iso.z_n2 == pytest.approx(95 / (math.cos(beta_b) ** 2 * math.cos(beta)), rel=1e-12)
    assert iso.cos_beta == pytest.approx(math.cos(beta), rel=1e-15)
    assert iso.contact_ratio == HelicalMesh(p, w).transverse_contact_ratio
    flat = iso6336_stiffness(HelicalMesh(_helical(24, 0.48, "0 deg"), _helical(95, 0.669, "0 deg")))
    spur = iso6336_stiffness(GearMesh(SpurGear(24, "14 mm", "20 deg", "360 mm", 0.48),
                                      SpurGear(95, "14 mm", "20 deg", "360 mm", 0.669)))
    assert flat.as_dict() == spur.as_dict()


def test_helical_mesh_takes_its_centre_distance_from_the_transverse_sections():
    """The NREL 5 MW gearbox's third stage (24/95 teeth, m_n 14 mm, beta 10 deg, x 0.480 and
    0.669) has the published centre distance of 861 mm (Nejad et al. 2016, Table V)."""
    train = _pair((_helical(24, 0.48), _helical(95, 0.669)), stiffness=1e9)
    gm = HelicalMesh(_helical(24, 0.48), _helical(95, 0.669))
    assert gm.centre_distance == pytest.approx(0.861, abs=5e-4)
    assert train.mesh_data["m"].pressure_angle == gm.transverse.operating_pressure_angle


@pytest.mark.parametrize(("case", "field"), [
    ("spur_with_helical", "m.b"),
    ("helix_differs", "m.helix_angle"),
    ("module_differs", "m.wheel.module"),
])
def test_bad_helical_meshes_are_refused_naming_the_field(case, field):
    p = _helical(24, 0.48, name="pinion")
    w = {"spur_with_helical": SpurGear(95, "14 mm", "20 deg", "360 mm", 0.669, name="wheel"),
         "helix_differs": _helical(95, 0.669, name="wheel"),
         "module_differs": HelicalGear(95, "16 mm", "20 deg", "10 deg", "360 mm",
                                       profile_shift=0.669, name="wheel")}[case]
    extra = {"helix_angle": "12 deg"} if case == "helix_differs" else {}
    with pytest.raises(ParameterError) as err:
        _pair((p, w), stiffness=1e9, **extra)
    assert err.value.field == field


def test_potential_energy_helical_mesh_is_the_sliced_transverse_mean():
    """A helical pair on "potential_energy": the transverse stiffness k_n cos^2(beta_b)
    is the mean of geardyn.gears.helical_stiffness over a mesh cycle (transverse), so the
    torsional mode is the closed form on that mean."""
    from geardyn.gears import helical_stiffness

    p = HelicalGear(19, "3.2 mm", "20 deg", "20 deg", "16 mm", name="pinion")
    w = HelicalGear(48, "3.2 mm", "20 deg", "20 deg", "16 mm", name="wheel")
    train = _pair((p, w), stiffness="potential_energy", bore_radius="12 mm")
    mean = float(helical_stiffness(HelicalMesh(p, w), bore_radius="12 mm")["mesh_stiffness"]
                 .mean())
    assert train.mesh_data["m"].method == "potential_energy"
    f = train.natural_frequencies()[1]
    assert f == pytest.approx(_torsional(mean, p.transverse.base_radius,
                                         w.transverse.base_radius), rel=1e-12)


def test_helical_pair_on_flexible_bearings_matches_a_hand_assembled_matrix():
    """Six coordinates (theta, x, y of each gear): K written out from the mesh's transverse
    line of action s (at phi + 90 deg - alpha, phi = 0 here) and cos(beta_b), plus isotropic
    bearings; the eigenvalues of (K, M) are the train's."""
    from scipy.linalg import eigh

    k, kb, beta, alpha = 4e9, 2e9, math.radians(12.0), math.radians(20.0)
    r1, r2, m1, m2 = 0.16, 0.63, 170.0, 3700.0
    train = GearTrain(
        [Gear("pinion", I1, mass=m1, base_radius=r1), Gear("wheel", I2, mass=m2,
                                                           base_radius=r2)],
        bearings=[Bearing("b1", "pinion", kb), Bearing("b2", "wheel", kb)],
        meshes=[Mesh("m", "pinion", "wheel", k, helix_angle=beta, pressure_angle=alpha)],
        free=True)
    cb = math.cos(math.atan(math.tan(beta) * math.cos(alpha)))
    sx, sy = math.cos(math.pi / 2 - alpha), math.sin(math.pi / 2 - alpha)
    v = cb * np.array([r1, sx, sy, r2, -sx, -sy])
    K = k * np.outer(v, v) + np.diag([0.0, kb, kb, 0.0, kb, kb])
    M = np.diag([I1, m1, m1, I2, m2, m2])
    lam = np.clip(eigh(K, M, eigvals_only=True), 0.0, None)
    expected = np.sqrt(lam) / (2 * math.pi)
    expected[0] = 0.0
    assert train.dof_names() == ("pinion.theta", "pinion.x", "pinion.y", "wheel.theta",
                                 "wheel.x", "wheel.y")
    np.testing.assert_allclose(train.natural_frequencies(), expected, rtol=1e-9, atol=1e-6)
