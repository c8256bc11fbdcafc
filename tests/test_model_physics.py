"""The physics the paper leaves inconsistent (docs/model.md): the package's numbers against
hand computations from Tables 1 and 2, and the documented numbers against the package."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import geardyn

DOC = Path(__file__).resolve().parents[1] / "docs" / "model.md"

# Tables 1 and 2 and the model notes (solid steel discs at the pitch radius, J_s = J_p)
N, J_C, R_C1, R_C2 = 4, 7.58e-3, 0.105, 0.210
J_Q, J_P, R_BQ, R_BP, R_BS = 7.13e-4, 0.002, 0.04229, 0.05638, 0.05638
ARM = R_BS * math.cos(math.radians(20.0))
DISC = 7850.0 * math.pi * 0.015
M_Q, M_P = DISC * 0.045**2, DISC * 0.060**2
T_D, A1, A2 = 1500.0, 600.0, 900.0
J_C_EFF = {"consistent": J_C + N * (M_P * R_C2**2 + M_Q * R_C1**2), "carrier-only": J_C,
           "as-printed": J_C + N * (M_P * R_C2 + M_Q * R_C1)}


def by_hand(interpretation: str, t_d: float = T_D) -> tuple[float, float, float]:
    """Carrier acceleration and static mesh forces of the rigidly turning device: Eq. (1) with
    theta_q'' = alpha r_c1/r_bq and theta_p'' = alpha r_c1/r_bp (constant deflections)."""
    inertia = J_C_EFF[interpretation] + N * ARM * R_C1 * (J_Q / R_BQ**2 + J_P / R_BP**2)
    alpha = (t_d - A2 - N * ARM * A1 / R_BP) / inertia
    f_pq = (A1 + J_P * alpha * R_C1 / R_BP) / R_BP
    f_sq = f_pq + J_Q * alpha * R_C1 / R_BQ**2
    return alpha, f_sq, f_pq


@pytest.mark.parametrize("interpretation", list(geardyn.INTERPRETATIONS))
def test_table2_torques_do_not_balance(interpretation):
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), interpretation=interpretation)
    alpha, f_sq, f_pq = by_hand(interpretation)
    assert m.carrier_acceleration() == pytest.approx(alpha, rel=1e-9)
    np.testing.assert_allclose(m.static_mesh_forces(), [f_sq, f_pq], rtol=1e-9)
    # balanced torques: no acceleration, and the forces A1/r_bp whatever the interpretation
    t_bal = A2 + N * ARM * A1 / R_BP
    bal = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(T_D=t_bal),
                             interpretation=interpretation)
    assert abs(bal.carrier_acceleration()) < 1e-9 * abs(alpha)
    np.testing.assert_allclose(bal.static_mesh_forces(), [A1 / R_BP] * 2, rtol=1e-9)


def _sci(x: float) -> str:
    mant, exp = f"{x:.2e}".split("e")
    return f"{mant}e{int(exp)}"


def test_documented_numbers_are_the_packages():
    text = DOC.read_text()
    section = text[text.index("## Physics the paper leaves inconsistent"):
                   text.index("## Raw coefficients")]
    for interp in geardyn.INTERPRETATIONS:
        m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), interpretation=interp)
        assert re.search(rf"\| {interp} \| {re.escape(_sci(m.carrier_acceleration()))} \|",
                         section), interp
        assert f"{m.omega_n:,.0f}".replace(",", " ") in section
    m = geardyn.CATTDevice(geardyn.PlanetaryParams.paper())
    for km in (0.5e9, 1.6e9):
        assert f"{m.with_params(Km_sq=km).omega_n:,.0f}".replace(",", " ") in section
    arm = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(derived={"arm": R_C1}))
    assert _sci(arm.carrier_acceleration()) in section
    assert f"{1e3 * m.derived.arm:.2f} mm" in section
    assert f"= {A2 + N * ARM * A1 / R_BP:.0f} N m" in section
    assert f"{A1 / R_BP:.0f} N" in section
