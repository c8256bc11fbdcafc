"""Results are bitwise the same on one numba thread and on two (docs/numerics.md, "the sweep
kernel": a lane's result does not depend on its worker or the thread count;
geardyn.solvers._parallel): a sweep with located edges, continued sweeps up and down (where a
race between the workers once made two-thread runs differ: bench/determinism.py), Lyapunov lane
blocks, a map with Lyapunov exponents and a basin grid, each on the gear pair (kernels the
warm-up compiles: tests/warm_kernels.py), compared variable by variable with np.array_equal.

On two threads the work is split over two workers (checked: the sweep's schedule gives both a
queue, the Lyapunov lanes fill more than one block), so a result that depended on which worker
ran a lane, on its neighbours or on a race between the workers would differ here."""

from __future__ import annotations

import numba
import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.analysis.basins import basins_run
from geardyn.solvers._lyapunov_template import BLOCK_ROWS
from geardyn.solvers.ensemble import LaneResults, _schedule, run_lanes

pytestmark = pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2,
                                reason="needs two numba threads (NUMBA_NUM_THREADS >= 2)")

#: The gear pair of the conformance case and tests/test_sweep_slots.py: contact lost over the
#: sweep (the basins below take the softening pair of tests/test_basins.py, two attractors).
PAIR = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
OMEGA = np.linspace(0.3, 3.0, 24)


@pytest.fixture
def threads():
    """Run a callable at a numba thread count; the count is restored afterwards."""
    before = numba.get_num_threads()

    def at(n: int, fn):
        numba.set_num_threads(n)
        try:
            return fn()
        finally:
            numba.set_num_threads(before)

    yield at
    numba.set_num_threads(before)


def _same(a, b, what: str) -> None:
    """Every variable and coordinate of two datasets (or two arrays) bit for bit (NaN where
    NaN)."""
    if isinstance(a, xr.Dataset):
        assert set(a.variables) == set(b.variables), what
        for name in a.variables:
            _same(a[name].values, b[name].values, f"{what}: {name}")
        return
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape and a.dtype == b.dtype, what
    nan = a.dtype.kind in "fc"
    assert np.array_equal(a, b, equal_nan=nan), f"{what} differs between 1 and 2 threads"


def _sweep():
    return geardyn.bifurcation(geardyn.GearPair(**PAIR), "Omega", OMEGA,
                               run=geardyn.RunSettings(transient=60.0, samples=8))


def test_a_sweep_and_continued_sweeps_are_bitwise_the_same_on_one_and_two_threads(threads):
    one, two = threads(1, _sweep), threads(2, _sweep)
    assert {"none", "single"} <= set(one["contact"].values.ravel())  # the teeth separate
    assert one.attrs["locate_edges"]  # the dead zone's edges located inside steps
    _same(one, two, "bifurcation")
    start, _ = threads(2, lambda: _schedule(np.ones(OMEGA.size)))
    assert np.all(np.diff(start) > 0) and start.size == 3  # two workers, each with lanes
    # the lanes' own records, edge crossings counted per lane and event among them
    g = geardyn.GearPair(**PAIR)

    def lanes():
        return run_lanes(g, g.lane_params("Omega", OMEGA), g.initial_state(),
                         run=geardyn.RunSettings(transient=60.0, samples=8))
    a, b = threads(1, lanes), threads(2, lanes)
    assert a.crossings.sum() > 0
    for name in LaneResults.__dataclass_fields__:
        _same(getattr(a, name), getattr(b, name), f"run_lanes {name}")

    om = np.linspace(0.6, 1.0, 12)

    def continued():
        return geardyn.continued_sweeps(
            [geardyn.ContinuedSweep(g, "Omega", om, "up"),
             geardyn.ContinuedSweep(g, "Omega", om, "down")],
            run=geardyn.RunSettings(transient=100.0, continued_transient=30.0, samples=8,
                                    converge=1e-6))
    for up_down, (a, b) in enumerate(zip(threads(1, continued), threads(2, continued),
                                         strict=True)):
        _same(a, b, f"continued sweep {('up', 'down')[up_down]}")


def test_lyapunov_lanes_are_bitwise_the_same_on_one_and_two_threads(threads):
    g = geardyn.GearPair(**PAIR)
    om = np.linspace(0.4, 2.8, 2 * BLOCK_ROWS + 6)  # more lanes than one block holds

    def run():
        return geardyn.lyapunov_lanes(g, g.lane_params("Omega", om),
                                      run=geardyn.RunSettings(transient=20.0),
                                      settings=geardyn.LyapunovSettings(duration=40.0),
                                      with_error=True, with_status=True)
    for k, (a, b) in enumerate(zip(threads(1, run), threads(2, run), strict=True)):
        _same(a, b, f"lyapunov_lanes output {k}")
    assert np.isfinite(threads(1, run)[0]).all()


def test_a_map_with_lyapunov_exponents_and_basins_are_bitwise_the_same(threads):
    g = geardyn.GearPair(**PAIR)

    def grid():
        return geardyn.map2d(g, ("Omega", np.linspace(0.5, 2.5, 10)),
                             ("Fa", np.linspace(0.05, 0.3, 8)),
                             run=geardyn.RunSettings(transient=40.0, samples=8),
                             lyapunov=True)
    one = threads(1, grid)
    assert one["lyapunov"].size > BLOCK_ROWS and np.isfinite(one["lyapunov"]).all()
    _same(one, threads(2, grid), "map2d")

    soft = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)

    def cells():
        return geardyn.basins(soft, omega=0.78, x=("x", -1.0, 3.0, 12), y=("v", -1.5, 1.5, 10),
                              run=basins_run(transient=150.0))
    b1 = threads(1, cells)
    assert int(b1.attrs["n_attractors"]) >= 2
    _same(b1, threads(2, cells), "basins")


def test_the_comparison_sees_a_one_ulp_change_of_one_lane(threads):
    """The check is not blind: a sweep whose last lane's Omega moved by one ulp differs from
    the sweep in bits (the same comparison that finds the two thread counts equal)."""
    one = threads(1, _sweep)
    om = OMEGA.copy()
    om[-1] = np.nextafter(om[-1], np.inf)
    moved = threads(2, lambda: geardyn.bifurcation(geardyn.GearPair(**PAIR), "Omega", om,
                                                   run=geardyn.RunSettings(transient=60.0,
                                                                           samples=8)))
    with pytest.raises(AssertionError, match="differs between"):
        _same(one.drop_vars("Omega"), moved.drop_vars("Omega"), "bifurcation")
