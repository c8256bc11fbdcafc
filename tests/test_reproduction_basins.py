"""The reproduction's basins (geardyn reproduce --basins N): where a case's up and down sweeps
follow different periodic orbits, the frequency chosen and the report's line. Synthetic case
results (no kernel compiled); tests/test_basins.py checks geardyn.basins itself."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from geardyn.analysis.basins import basins_run
from geardyn.reproduction.basins import _velocity, basin_omega, summary


def _case(up_x: np.ndarray, down_x: np.ndarray, period_down: np.ndarray) -> xr.Dataset:
    """A two-sweep case result over 8 Omega values: period-1 up everywhere, the down sweep's
    plotted coordinate ``down_x`` and period ``period_down``."""
    om = np.linspace(0.4, 0.75, 8)
    n = om.size
    poincare = np.zeros((2, n, 4, 4))
    poincare[0, :, :, 0] = up_x[:, None]
    poincare[1, :, :, 0] = down_x[:, None]
    period = np.stack([np.ones(n, int), period_down])
    motion = np.where(period > 0, np.char.add("period-", period.astype(str)), "chaotic")
    ds = xr.Dataset(coords={"sweep": ["up", "down"], "Omega": om, "sample": np.arange(4),
                            "state": ["X_sq", "V_sq", "X_pq", "V_pq"], "mesh": ["sq", "pq"]})
    ds["poincare"] = (("sweep", "Omega", "sample", "state"), poincare)
    ds["period"] = (("sweep", "Omega"), period)
    ds["status"] = (("sweep", "Omega"), np.zeros((2, n), int))
    ds["motion"] = (("sweep", "Omega"), motion)
    ds["contact"] = (("sweep", "Omega", "mesh"), np.full((2, n, 2), "single"))
    ds.attrs.update(case="fig3", plot_state="X_sq", static_deflection=[1.2, 1.0],
                    interpretation="consistent", Lambda=0.0)
    return ds


def test_the_frequency_is_in_the_middle_of_the_widest_coexistence():
    up = np.full(8, 6.0)
    down = up.copy()
    down[1:2] = 0.8   # one point of coexisting period-1 orbits
    down[4:7] = 0.8   # three points: the widest, middle at index 5
    ds = _case(up, down, np.ones(8, int))
    assert basin_omega(ds) == ds["Omega"].values[5]
    # the same orbit up and down: no disagreement, no basins
    assert basin_omega(_case(up, up.copy(), np.ones(8, int))) is None
    # disagreeing only where the down sweep has no period: no periodic coexistence
    period = np.ones(8, int)
    period[4:7] = 0
    only = up.copy()
    only[4:7] = 0.8
    assert basin_omega(_case(up, only, period)) is None
    # ... but with a periodic coexistence elsewhere, that one
    only[1] = 0.8
    assert basin_omega(_case(up, only, period)) == ds["Omega"].values[1]


def test_velocity_pairs_and_the_report_line():
    names = ["X_sq", "V_sq", "X_pq", "V_pq"]
    assert _velocity(names, "X_pq") == "V_pq" and _velocity(["x", "v"], "x") == "v"
    b = xr.Dataset(coords={"V_sq": [0.0, 1.0], "X_sq": [0.0, 1.0, 2.0],
                           "attractor": [0, 1]})
    b["attractor_period"] = ("attractor", [1, 1])
    b["attractor_fraction"] = ("attractor", [0.75, 0.25])
    b["attractor_orbit"] = ("attractor", [1, -1])
    b.attrs.update(Omega=0.4865, x="X_sq", y="V_sq", diverged_fraction=0.0, sweeps="up, down")
    line = summary(b)
    assert "Omega = 0.4865" in line and "3 x 2 initial X_sq, V_sq" in line
    assert "#0 period-1 75.0% (the down sweep's orbit)" in line
    assert "#1 period-1 25.0%;" in line and "diverged 0.0%" in line
    b.attrs.update(unresolved_fraction=1 / 6)
    assert "unresolved 16.7%" in summary(b)


def test_reproduce_with_basins_writes_them_into_the_report(tmp_path, capsys, monkeypatch):
    """The plumbing of ``--basins N``: each case's basins (here a stand-in computed on the gear
    pair, cheap) written beside the case and shown in the report with its line. One process
    (``--jobs 1``, as tests/test_reproduction.py's pipeline test): the basins are computed in
    the command's own process whatever the jobs (the worker processes' sweeps:
    tests/test_reproduction.py)."""
    import geardyn
    import geardyn.reproduction.basins as rb
    from geardyn.cli.main import main

    asked = []

    def fake(case, interpretation, ds, n, transient=None):
        asked.append((case.name, interpretation, n))
        b = geardyn.basins(geardyn.GearPair(Fm=2.0, Fa=0.02), omega=1.3, x=("x", 2.0, 4.0, n),
                           y=("v", -0.5, 0.5, n),
                           run=basins_run(transient=100.0, samples=4, max_period=2))
        b.attrs.update(sweeps="up, down", study=f"{case.figure} ({interpretation})")
        return b

    monkeypatch.setattr(rb, "case_basins", fake)
    out = tmp_path / "rep"
    with pytest.raises(SystemExit) as info:
        main(["reproduce", "fig5", "--resolution", "3", "--transient", "300", "--samples", "8",
              "--out", str(out), "--quiet", "--basins", "3", "--jobs", "1"])
    assert info.value.code == 0, capsys.readouterr().err
    assert asked == [("fig5", "consistent", 3)]
    assert (out / "basins-fig5-consistent.png").exists()
    b = geardyn.io.netcdf.load_dataset(out / "basins-fig5-consistent.nc")
    geardyn.testing.assert_result(b, "basins")
    md = (out / "report.md").read_text()
    assert "basins of attraction at Omega = 1.3 (3 x 3 initial x, v): #0 period-1 100.0%" in md
    assert "basins-fig5-consistent.png" in md
