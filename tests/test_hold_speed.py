"""Sweeps at a fixed physical speed (``bifurcation(..., hold="speed")``): Omega and Lambda are
relative to an omega_n that moves with Km_sq, so each point gets its own Omega (issue 10)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn
from geardyn.study import build_model

KM_SQ = np.array([0.5e9, 0.825e9, 1.6e9])


@pytest.fixture(scope="module")
def device():
    p = geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1, B1=10.0, B2=10.0, Lambda=0.55)
    return geardyn.CATTDevice(p, omega=1.1)


def omega_n_by_hand(m: geardyn.CATTDevice, km_sq: float) -> float:
    """omega_n = sqrt(Km_sq (1/M_s + 1/M_c)) ("consistent") from Table 1 and the notes:
    M = J / r_b^2, J_s = J_p, J_c,eff = J_c + N (m_p r_c2^2 + m_q r_c1^2), solid discs."""
    disc = 7850.0 * math.pi * 0.015
    m_q, m_p = disc * (0.003 * 30 / 2) ** 2, disc * (0.003 * 40 / 2) ** 2
    j_c = 7.58e-3 + 4 * (m_p * 0.210**2 + m_q * 0.105**2)
    M_s, M_c = 0.002 / 0.05638**2, j_c / 0.105**2
    return math.sqrt(km_sq * (1.0 / M_s + 1.0 / M_c))


def test_sweep_at_fixed_speed_equals_each_point_built_by_hand(device):
    kw = dict(run=geardyn.RunSettings(transient=40.0, samples=4))
    ds = geardyn.bifurcation(device, "Km_sq", KM_SQ, hold="speed", **kw)
    assert ds.attrs["hold"] == "speed"
    wn = np.array([omega_n_by_hand(device, v) for v in KM_SQ])
    speed = 1.1 * omega_n_by_hand(device, 0.825e9)
    assert ds.attrs["omega_phys"] == pytest.approx(speed, rel=1e-12)
    np.testing.assert_allclose(ds["Omega"].values, speed / wn, rtol=1e-12)
    np.testing.assert_allclose(ds["Lambda"].values, 0.55 * speed / (1.1 * wn), rtol=1e-12)
    assert ds["Omega"].values[0] > 1.1 > ds["Omega"].values[-1]
    for k, v in enumerate(KM_SQ):
        lane = device.with_params(Km_sq=v, Omega=float(ds["Omega"].values[k]),
                                  Lambda=float(ds["Lambda"].values[k]))
        assert lane.omega * lane.omega_n == pytest.approx(speed, rel=1e-12)
        one = geardyn.bifurcation(lane, "Omega", [lane.omega], **kw)
        np.testing.assert_array_equal(ds["poincare"].values[k], one["poincare"].values[0])
    held = geardyn.bifurcation(device, "Km_sq", KM_SQ[:1], **kw)  # the default holds Omega
    assert held.attrs["hold"] == "Omega" and "Omega" not in held.coords
    assert not np.array_equal(held["poincare"].values[0], ds["poincare"].values[0])


def test_continued_sweep_at_fixed_speed_records_the_lane_omegas(device):
    ds = geardyn.bifurcation(device, "Km_sq", KM_SQ, hold="speed",
                             run=geardyn.RunSettings(transient=20.0, samples=2),
                             continuation="down")
    wn = np.array([omega_n_by_hand(device, v) for v in KM_SQ])
    np.testing.assert_allclose(ds["Omega"].values * wn, 1.1 * omega_n_by_hand(device, 0.825e9),
                               rtol=1e-12)


def test_hold_speed_is_refused_where_it_means_nothing(device):
    with pytest.raises(ValueError, match="hold must be one of"):
        geardyn.bifurcation(device, "Km_sq", KM_SQ, hold="torque")
    with pytest.raises(ValueError, match="is a speed itself"):
        geardyn.bifurcation(device, "Omega", [1.0], hold="speed")
    with pytest.raises(ValueError, match="no physical|has none"):
        geardyn.bifurcation(geardyn.GearPair(), "Fm", [0.1], hold="speed")


def test_cli_hold_speed_writes_what_the_api_computes(tmp_path):
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.io.netcdf import load_dataset
    from geardyn.io.toml import builtin_study

    nc = tmp_path / "km.nc"
    args = ["bifurcation", "paper_fig3", "--param", "Km_sq", "--range", "0.5e9:1.6e9:3",
            "--omega", "1.1", "--hold", "speed", "--transient", "20", "--samples", "3",
            "--quiet", "--out", str(nc), "--plot", str(tmp_path / "km.png")]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    saved = load_dataset(nc)
    model = build_model(builtin_study("paper_fig3"), omega=1.1)
    direct = geardyn.bifurcation(model, "Km_sq", np.linspace(0.5e9, 1.6e9, 3),
                                 run=geardyn.RunSettings(transient=20.0, samples=3), hold="speed")
    assert saved.attrs["hold"] == "speed"
    np.testing.assert_array_equal(saved["Omega"].values, direct["Omega"].values)
    np.testing.assert_array_equal(saved["poincare"].values, direct["poincare"].values)
    bad = CliRunner().invoke(app, args[:-4] + ["--hold", "slow"])
    assert bad.exit_code == 2 and "--hold" in bad.output
