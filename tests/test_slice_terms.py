"""The helical slices' terms from Chebyshev interpolants (geardyn.gears.slice_terms) against
their direct evaluation by quadrature (``helical_stiffness(..., exact=True)`` and
``PotentialEnergyPair.terms``): within the stated tolerance (1e-12 relative) for varied
geometries, faulty teeth by quadrature, and quadrature (recorded in the attrs) where the
interpolants miss their check."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn.gears.helical as helical_module
from geardyn.gears import HelicalGear, HelicalMesh, RootCrack, Wear, helical_stiffness
from geardyn.gears.potential_energy import prepare_pair
from geardyn.gears.slice_terms import TOLERANCE, ChebyshevTerms

DEG = math.pi / 180.0

#: (z1, z2, m_n, beta, b, x_n1, x_n2, bores, extra keywords): the 19/48 teeth, a small shifted
#: pinion at a large helix angle, a shifted pair at a centre distance with backlash and the
#: cantilever from the base circle, a coarse quadrature.
CASES = [
    (19, 48, 0.0032, 20 * DEG, 0.016, 0.0, 0.0, (0.012, 0.035), {}),
    (12, 60, 0.003, 30 * DEG, 0.03, 0.1, 0.0, (0.008, 0.06), {}),
    (22, 53, 0.0025, 15 * DEG, 0.03, 0.2, -0.1, (0.012, 0.04),
     {"root_segment": False, "centre_distance": 0.0976}),
    (31, 75, 0.002, 10 * DEG, 0.025, 0.0, 0.0, (0.015, 0.05), {"nodes": 16}),
]


def _mesh(z1, z2, m, beta, b, x1, x2, centre_distance=None) -> HelicalMesh:
    return HelicalMesh(HelicalGear(z1, m, 20 * DEG, beta, b, x1, name="pinion"),
                       HelicalGear(z2, m, 20 * DEG, beta, b, x2, name="wheel"),
                       centre_distance=centre_distance)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a - b| / |b| where b is finite and non-zero (same NaN/inf pattern asserted)."""
    assert np.array_equal(np.isfinite(a), np.isfinite(b))
    m = np.isfinite(b) & (b != 0.0)
    return float(np.max(np.abs(a[m] - b[m]) / np.abs(b[m]))) if m.any() else 0.0


@pytest.mark.parametrize("case", CASES, ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_interpolated_slices_equal_quadrature_within_the_tolerance(case):
    z1, z2, m, beta, b, x1, x2, bores, extra = case
    extra = dict(extra)
    mesh = _mesh(z1, z2, m, beta, b, x1, x2, extra.pop("centre_distance", None))
    kw = dict(bore_radius=bores, angles=97, slices=13, cycles=2, **extra)
    fast, direct = helical_stiffness(mesh, **kw), helical_stiffness(mesh, exact=True, **kw)
    assert fast.attrs["slice_terms"].startswith("healthy pairs: Chebyshev")
    assert direct.attrs["slice_terms"] == "quadrature at every contact"
    for name, var in direct.data_vars.items():
        if var.dtype.kind == "f":
            assert _relative(fast[name].values, var.values) <= TOLERANCE, name
        else:
            np.testing.assert_array_equal(fast[name].values, var.values, err_msg=name)


@pytest.mark.parametrize("case", CASES, ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_every_term_off_the_check_points(case):
    """At 2000 random positions on the path (none a node or check point), each term's
    compliance within the tolerance of the pair's, the pair stiffness relative."""
    z1, z2, m, beta, b, x1, x2, bores, extra = case
    extra = dict(extra)
    mesh = _mesh(z1, z2, m, beta, b, x1, x2, extra.pop("centre_distance", None)).transverse
    pair = prepare_pair(mesh, bore_radius=bores, **extra)
    table = ChebyshevTerms.build(pair)
    assert table.error <= TOLERANCE
    s = np.random.default_rng(7).uniform(-mesh.approach_length, mesh.recess_length, 2000)
    got, want = table.terms(s), pair.terms(s)
    assert list(got) == list(want)
    total = 1.0 / want["pair"]
    for name in want:
        if name not in ("hertz", "pair"):
            assert np.max(np.abs(1.0 / got[name] - 1.0 / want[name]) / total) <= TOLERANCE
    assert _relative(got["pair"], want["pair"]) <= TOLERANCE
    np.testing.assert_array_equal(got["hertz"], want["hertz"])


def test_faulty_teeth_are_integrated_directly():
    """A cracked and a worn tooth: their slices bitwise the quadrature's, the rest within the
    tolerance."""
    mesh = _mesh(19, 48, 0.0032, 20 * DEG, 0.016, 0.0, 0.0)
    faults = (RootCrack("2 mm", tooth=1), Wear("5 um", gear="wheel", tooth=2))
    kw = dict(bore_radius=(0.012, 0.035), angles=60, slices=10, cycles=4, faults=faults)
    fast, direct = helical_stiffness(mesh, **kw), helical_stiffness(mesh, exact=True, **kw)
    faulty = ((fast.tooth_pinion == 1) | (fast.tooth_wheel == 2)).values[..., None] \
        & fast.slice_in_contact.values
    assert faulty.any()
    k, k_direct = fast.slice_stiffness.values, direct.slice_stiffness.values
    np.testing.assert_array_equal(k[faulty], k_direct[faulty])
    assert _relative(k[~faulty], k_direct[~faulty]) <= TOLERANCE
    assert _relative(fast.mesh_stiffness.values, direct.mesh_stiffness.values) <= TOLERANCE


def test_spur_teeth_and_one_slice_stay_quadrature():
    """beta = 0 (every slice at the spur contacts) and one slice: quadrature, bitwise."""
    for beta, slices in ((0.0, 8), (20 * DEG, 1)):
        mesh = _mesh(19, 48, 0.0032, beta, 0.016, 0.0, 0.0)
        kw = dict(bore_radius=(0.012, 0.035), angles=50, slices=slices)
        ds = helical_stiffness(mesh, **kw)
        assert ds.attrs["slice_terms"] == "quadrature at every contact"
        np.testing.assert_array_equal(ds.mesh_stiffness.values,
                                      helical_stiffness(mesh, exact=True, **kw)
                                      .mesh_stiffness.values)


def test_a_missed_check_falls_back_to_quadrature_and_says_so(monkeypatch):
    monkeypatch.setattr(helical_module, "TOLERANCE", 1e-30)
    mesh = _mesh(19, 48, 0.0032, 20 * DEG, 0.016, 0.0, 0.0)
    kw = dict(bore_radius=(0.012, 0.035), angles=50, slices=6)
    ds = helical_stiffness(mesh, **kw)
    assert "quadrature at every contact (the Chebyshev interpolants' error" in \
        ds.attrs["slice_terms"]
    np.testing.assert_array_equal(ds.slice_stiffness.values,
                                  helical_stiffness(mesh, exact=True, **kw)
                                  .slice_stiffness.values)
    low = ChebyshevTerms.build(prepare_pair(mesh.transverse, bore_radius=(0.012, 0.035)),
                               degree=6)
    assert low.error > TOLERANCE
