"""Cost of labelled fault data (geardyn.fault_dataset): the 19/48 SpurPair of the cracked-tooth
literature (potential-energy stiffness over a pinion revolution), healthy and three faults x
``--speeds`` speeds in [1000, 3000] rpm x ``--torques`` torques in [20, 100] N m x ``--seeds``
noise seeds, ``--duration`` s signals at ``--rate`` Hz. The stiffness in the ``--form`` given
(``fourier``, with ``--harmonics`` or the default; ``table``), the step by the rule or
``--per-mode`` steps per contact-mode period; run on ``--workers`` local processes or a Dask
LocalCluster of ``--dask`` single-threaded processes. ``--repeat`` runs, the median printed with
seconds per condition (one simulation) and per signal, and the time 10 000 one-second signals
would take at the same rate (10 000 distinct conditions, and 10 seeds per condition); and the
CPU time (this process and its finished children: the local worker processes) per condition,
which a machine shared with other jobs does not inflate as it does the wall time, with the wall
time it gives on two idle cores (CPU time / 2). Without ``--form``, ``--per-mode`` and
``--workers`` it runs on an older geardyn as well (the "before" of bench/RESULTS.md: run it with
that tree first on PYTHONPATH).

    .venv/bin/python bench/fault_dataset.py [--speeds 5] [--torques 2] [--seeds 10]
        [--duration 1.0] [--rate 20000] [--form table] [--per-mode 50] [--workers 2]
        [--dask 0] [--harmonics H] [--repeat 1]
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import statistics
import tempfile
import time

import numpy as np

import geardyn
from geardyn.gears import GearMesh, RootCrack, Spall, SpurGear, Wear

MESH = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))
FAULTS = (None, RootCrack("1.5 mm"), Spall("2 mm", "8 mm", "0.1 mm"), Wear("20 um"))


def build(faults, harmonics=None, form=None):
    kw = {} if form is None else {"stiffness_form": form}
    if harmonics is not None:
        kw["harmonics"] = harmonics
    return geardyn.SpurPair.from_geometry(
        MESH, bore_radius=(0.012, 0.035), speed=1000, torque=50.0, faults=faults,
        inertia=(4.3659e-4, 8.3602e-3), backlash=10e-6, speed_unit="rpm", **kw)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=int, default=5)
    ap.add_argument("--torques", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--rate", type=float, default=20_000.0)
    ap.add_argument("--form", choices=("fourier", "table"), default=None)
    ap.add_argument("--per-mode", type=float, default=None)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--dask", type=int, default=0)
    ap.add_argument("--harmonics", type=int, default=None)
    ap.add_argument("--repeat", type=int, default=1)
    a = ap.parse_args()

    spec_kw = {} if a.per_mode is None else {"steps_per_mode": a.per_mode}
    spec = geardyn.FaultDatasetSpec(
        _Build(a.harmonics, a.form), FAULTS, speeds=np.linspace(1000.0, 3000.0, a.speeds).tolist(),
        torques=np.linspace(20.0, 100.0, a.torques).tolist(), seeds=range(a.seeds),
        duration=a.duration, sample_rate=a.rate, **spec_kw)
    run_kw = {} if a.workers is None else {"workers": a.workers}
    client = None
    if a.dask:
        from dask.distributed import Client, LocalCluster

        cluster = LocalCluster(n_workers=a.dask, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
        client.run(lambda: __import__("geardyn"))  # import (and cache load) off the clock
    m = build((), a.harmonics, a.form)
    one = geardyn.RunSettings(transient=0.0, samples=1)
    steps = geardyn.simulate(m.with_params(speed=3000.0), run=one).attrs["steps_per_period"]
    walls, cpus = [], []
    for _ in range(a.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            c0, t0 = _cpu(), time.perf_counter()
            ds = geardyn.fault_dataset(spec, store=f"{tmp}/d.zarr", client=client, **run_kw)
            walls.append(time.perf_counter() - t0)
            cpus.append(_cpu() - c0)
    wall, cpu = statistics.median(walls), statistics.median(cpus)
    n_cond, n_sig = ds.attrs["n_conditions"], ds.attrs["n_signals"]
    err = float(ds["stiffness_error_drive_max"].max())
    form = a.form or "fourier"
    print(f"SpurPair 19/48, {form}" + (f" H {m.n_harmonics}" if form == "fourier" else "")
          + f", rule steps/period {steps} at 3000 rpm, per mode {a.per_mode or 'rule'}, "
          f"stiffness error max {err:.3f} (relative); load average "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    print(f"{n_cond} conditions, {n_sig} signals of {a.duration} s at {a.rate:g} Hz, "
          f"workers {a.workers or 'default'}, dask {a.dask}: median of {a.repeat} {wall:.2f} s "
          f"({' '.join(f'{w:.2f}' for w in walls)}); "
          f"{wall / n_cond * 1e3:.1f} ms per condition, {wall / n_sig * 1e3:.2f} ms per signal;"
          f" 10 000 signals ({a.seeds} seeds each condition): {wall / n_sig * 1e4 / 60:.2f} min; "
          f"10 000 conditions: {wall / n_cond * 1e4 / 60:.2f} min; diverged "
          f"{ds.attrs['diverged']}")
    print(f"CPU time: median {cpu:.2f} s ({' '.join(f'{c:.2f}' for c in cpus)}), "
          f"{cpu / n_cond * 1e3:.1f} ms per condition; 10 000 conditions on two idle cores: "
          f"{cpu / n_cond * 1e4 / 2 / 60:.2f} min")


def _cpu() -> float:
    """User + system CPU seconds of this process and its finished children."""
    own, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF,
                                                  resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


class _Build:
    """The model builder, picklable (a spec travels to Dask workers)."""

    def __init__(self, harmonics, form):
        self.harmonics, self.form = harmonics, form

    def __call__(self, faults):
        return build(faults, self.harmonics, self.form)


if __name__ == "__main__":
    main()
