"""Continuation benchmark (issue 12): the period-1 branch of the paper's Fig. 3 case.

Workload: the paper's device (Tables 1-2, consistent interpretation, reduced model, xi1 = xi2 =
0.05), ``geardyn.continuation(device, "Omega", 0.1, 4.0)`` at its defaults: pseudo-arclength
continuation of the period-1 orbit with every fold, period doubling, Neimark-Sacker point and
contact change located (to 1e-7 in Omega). One cold call compiles (or loads) the kernels; the
warm wall time is the median of ``--repeat`` calls. Reports the points, the corrector's period
maps, the bifurcations found, and the target (<= 10 s warm).

    .venv/bin/python bench/continuation.py [--repeat 3] [--lo 0.1] [--hi 4.0]
"""

from __future__ import annotations

import argparse
import platform
import statistics
import time
from collections import Counter

import numba

import geardyn

TARGET_S = 10.0


def device() -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05),
                              interpretation="consistent")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--lo", type=float, default=0.1)
    ap.add_argument("--hi", type=float, default=4.0)
    a = ap.parse_args()
    m = device()
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, "
          f"{numba.get_num_threads()} threads, {platform.machine()}")
    t = time.perf_counter()
    geardyn.continuation(m, "Omega", 1.0, 1.1)
    print(f"cold call (compile or load kernels): {time.perf_counter() - t:.2f} s")
    times, cpu, ds = [], [], None
    for _ in range(a.repeat):
        t, c = time.perf_counter(), time.process_time()
        ds = geardyn.continuation(m, "Omega", a.lo, a.hi)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    assert ds is not None
    med = statistics.median(times)
    print(f"period-1 branch, Omega in [{a.lo:g}, {a.hi:g}]: warm wall time median {med:.2f} s "
          f"of [{', '.join(f'{x:.2f}' for x in times)}]; CPU time median "
          f"{statistics.median(cpu):.2f} s (one thread: the continuation is serial)")
    print(f"points: {ds.sizes['point']}, arclength {float(ds['arclength'][-1]):.1f}, "
          f"status: {ds.attrs['message']}")
    kinds = Counter(str(k) for k in ds["bifurcation_kind"].values)
    print("bifurcations: " + ", ".join(f"{k} {n}" for k, n in sorted(kinds.items())))
    for k, v, e in zip(ds["bifurcation_kind"].values, ds["bifurcation_value"].values,
                       ds["bifurcation_error"].values, strict=True):
        if k != "contact":
            print(f"  {k:16s} Omega = {v:.7f} (+- {e:.1e})")
    print(f"max location error: {float(ds['bifurcation_error'].max()):.1e}")
    print(f"target <= {TARGET_S:g} s warm: {'met' if med <= TARGET_S else 'NOT met'} "
          f"(wall time; on a loaded machine compare the CPU time)")


if __name__ == "__main__":
    main()
