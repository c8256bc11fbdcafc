"""Tip relief and the loaded contact (geardyn.gears.tip_relief) against independent solves."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from geardyn.errors import ParameterError
from geardyn.gears import GearMesh
from geardyn.gears.potential_energy import potential_energy_stiffness
from geardyn.gears.tip_relief import TipRelief, loaded_contact
from pair_19_48 import ALPHA, BORES, Z1, Z2, M, pair_mesh


@pytest.fixture(scope="module")
def mesh() -> GearMesh:
    return pair_mesh()


@pytest.fixture(scope="module")
def stiffness(mesh: GearMesh):
    return potential_energy_stiffness(mesh, bore_radius=BORES, angles=90)


def _path(mesh: GearMesh) -> tuple[float, float]:
    """(g_f, g_a) of the unshifted pair from the tip circles (h_a = 1)."""
    out = []
    for z_tip in (Z2, Z1):
        r = M * z_tip / 2.0
        rb, ra = r * math.cos(ALPHA), r + M
        out.append(math.sqrt(ra ** 2 - rb ** 2) - rb * math.tan(ALPHA))
    return out[0], out[1]


RELIEFS = [(TipRelief(20e-6, 3e-3, "linear", "pinion"),),
           (TipRelief(15e-6, 2.5e-3, "parabolic", "wheel"),),
           (TipRelief(20e-6, 3e-3, "parabolic", "pinion"),
            TipRelief(10e-6, 4e-3, "linear", "wheel"))]


def test_zero_relief_is_the_unmodified_stiffness_bitwise(mesh, stiffness) -> None:
    for relief in ((), (TipRelief(0.0, 3e-3),)):
        ds = loaded_contact(mesh, stiffness, 2000.0, relief)
        np.testing.assert_array_equal(ds.tangent_stiffness.values,
                                      stiffness.mesh_stiffness.values)
        np.testing.assert_allclose(ds.transmission_error.values,
                                   2000.0 / stiffness.mesh_stiffness.values, rtol=1e-14)
        assert np.all(ds.unloaded_transmission_error.values == 0.0)


@pytest.mark.parametrize("relief", RELIEFS)
@pytest.mark.parametrize("force", [50.0, 1500.0, 3e4])
def test_force_balance_and_brentq(mesh, stiffness, relief, force) -> None:
    """delta against brentq on the force balance with the gaps written out here."""
    g_f, g_a = _path(mesh)
    ds = loaded_contact(mesh, stiffness, force, relief)
    s = stiffness.position.values
    e = np.zeros(s.shape)
    for r in relief:
        p = 1 if r.shape == "linear" else 2
        t = ((s - g_a + r.length) if r.gear == "pinion" else (r.length - g_f - s)) / r.length
        e += r.amount * np.clip(t, 0.0, None) ** p
    k = stiffness.pair_stiffness.values
    for i in range(s.shape[0]):
        def balance(d: float, i: int = i) -> float:
            return float(np.sum(k[i] * np.clip(d - e[i], 0.0, None))) - force
        ref = brentq(balance, 0.0, 1e-2, xtol=1e-18, rtol=1e-15)
        assert ds.transmission_error.values[i] == pytest.approx(ref, rel=1e-12, abs=1e-18)
        total = ds.pair_force.values[i].sum()
        assert abs(total - force) <= 1e-10 * force
    inside = stiffness.in_contact.values
    np.testing.assert_allclose(ds.gap.values[inside], e[inside], rtol=1e-13, atol=1e-18)


def test_relief_effect_vanishes_as_the_load_grows(mesh, stiffness) -> None:
    relief = RELIEFS[2]
    k0 = stiffness.mesh_stiffness.values
    err = []
    for force in (1e2, 1e3, 1e4, 1e5, 1e6):
        ds = loaded_contact(mesh, stiffness, force, relief)
        err.append(np.max(np.abs(ds.secant_stiffness.values / k0 - 1.0)))
        assert np.all(ds.secant_stiffness.values <= k0 * (1 + 1e-12))
    assert all(b < a for a, b in zip(err, err[1:], strict=False))
    assert err[0] > 0.05 and err[-1] < 3e-3
    # every pair loaded: 1/k_sec = 1/K + (sum k e / K - e_min) / F exactly
    big = loaded_contact(mesh, stiffness, 1e6, relief)
    k, e = stiffness.pair_stiffness.values, np.nan_to_num(big.gap.values)
    e_min = big.gap.min("pair").values
    expect = 1.0 / (1.0 / k0 + ((k * e).sum(axis=1) / k0 - e_min) / 1e6)
    np.testing.assert_allclose(big.secant_stiffness.values, expect, rtol=1e-9)
    # at a light load a relieved pair near the tip carries less than without relief
    light = loaded_contact(mesh, stiffness, 1e2, relief)
    plain = loaded_contact(mesh, stiffness, 1e2)
    tip = (stiffness.position.values > _path(mesh)[1] - 1e-3) & stiffness.in_contact.values
    assert np.all(light.pair_force.values[tip] < plain.pair_force.values[tip])


def test_unloaded_transmission_error_is_the_smallest_gap(mesh, stiffness) -> None:
    ds = loaded_contact(mesh, stiffness, 10.0, RELIEFS[2])
    np.testing.assert_array_equal(ds.unloaded_transmission_error.values,
                                  ds.gap.min("pair").values)
    assert ds.transmission_error.attrs["units"] == "m"


@pytest.mark.parametrize("kwargs, field", [
    (dict(amount=-1e-6, length=1e-3), "relief.amount"),
    (dict(amount=1e-6, length=0.0), "relief.length"),
    (dict(amount=1e-6, length=1e-3, shape="cubic"), "relief.shape"),
    (dict(amount=1e-6, length=1e-3, gear="ring"), "relief.gear"),
    (dict(amount="1 kg", length=1e-3), "relief.amount"),
])
def test_bad_relief_names_the_field(kwargs, field) -> None:
    with pytest.raises(ParameterError) as err:
        TipRelief(**kwargs)
    assert err.value.field == field


def test_bad_load_and_long_relief_name_the_field(mesh, stiffness) -> None:
    with pytest.raises(ParameterError) as err:
        loaded_contact(mesh, stiffness, -1.0)
    assert err.value.field == "force"
    with pytest.raises(ParameterError) as err:
        loaded_contact(mesh, stiffness, 1.0, (TipRelief(1e-6, 0.1),))
    assert err.value.field == "relief.length"
