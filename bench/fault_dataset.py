"""Cost of labelled fault data (geardyn.fault_dataset): the 19/48 SpurPair of the
cracked-tooth literature (potential-energy stiffness over a pinion revolution, its default
harmonics, the step rule), healthy and three faults x ``--speeds`` speeds in [1000, 3000] rpm
x ``--torques`` torques in [20, 100] N m x ``--seeds`` noise seeds, ``--duration`` s signals at
``--rate`` Hz; here (one process) or on a Dask LocalCluster of ``--workers`` single-threaded
processes. Prints seconds per condition (one simulation) and per signal, the step and
harmonics, and the time that 10 000 one-second signals would take at the same rate.

    .venv/bin/python bench/fault_dataset.py [--speeds 5] [--torques 2] [--seeds 10]
        [--duration 1.0] [--rate 20000] [--workers 0] [--harmonics H]
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time

import numpy as np

import geardyn
from geardyn.gears import BrokenTooth, GearMesh, RootCrack, Spall, SpurGear, Wear

MESH = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=int, default=5)
    ap.add_argument("--torques", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--rate", type=float, default=20_000.0)
    ap.add_argument("--workers", type=int, default=0)
    ap.add_argument("--harmonics", type=int, default=None)
    a = ap.parse_args()

    def build(faults):
        return geardyn.SpurPair.from_geometry(
            MESH, bore_radius=(0.012, 0.035), speed=1000, torque=50.0, faults=faults,
            inertia=(4.3659e-4, 8.3602e-3), backlash=10e-6, speed_unit="rpm",
            harmonics=a.harmonics)

    faults = (None, RootCrack("1.5 mm"), Spall("2 mm", "8 mm", "0.1 mm"), Wear("20 um"),
              BrokenTooth("pinion", 0))[:4]
    spec = geardyn.FaultDatasetSpec(
        build, faults, speeds=np.linspace(1000.0, 3000.0, a.speeds).tolist(),
        torques=np.linspace(20.0, 100.0, a.torques).tolist(), seeds=range(a.seeds),
        duration=a.duration, sample_rate=a.rate)
    client = None
    if a.workers:
        from dask.distributed import Client, LocalCluster

        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
        client.run(lambda: __import__("geardyn"))  # import (and cache load) off the clock
    m = build(())
    one = geardyn.RunSettings(transient=0.0, samples=1)
    steps = geardyn.simulate(m.with_params(speed=3000.0), run=one).attrs["steps_per_period"]
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        ds = geardyn.fault_dataset(spec, store=f"{tmp}/d.zarr", client=client)
        wall = time.perf_counter() - t0
    n_cond, n_sig = ds.attrs["n_conditions"], ds.attrs["n_signals"]
    err = float(ds["stiffness_error_drive_max"].max())
    print(f"SpurPair 19/48, harmonics {m.n_harmonics}, steps/period {steps} at 3000 rpm, "
          f"stiffness error max {err:.3f} (relative)")
    print(f"{n_cond} conditions, {n_sig} signals of {a.duration} s at {a.rate:g} Hz, "
          f"workers {a.workers or 'none (one process)'}: {wall:.1f} s; "
          f"{wall / n_cond * 1e3:.0f} ms per condition, {wall / n_sig * 1e3:.1f} ms per signal; "
          f"10 000 signals ({a.seeds} seeds each condition): {wall / n_sig * 1e4 / 60:.1f} min; "
          f"10 000 conditions: {wall / n_cond * 1e4 / 60:.1f} min; diverged {ds.attrs['diverged']}")


if __name__ == "__main__":
    main()
