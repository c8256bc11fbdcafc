"""The planetary set's lane blocks (and the paper workload), old kernels against new in one run.

The planetary set (the built-in study ``planetary_example``, N = 4, 42 states) is the model
whose lane-block functions (``rhs_lanes``, ``events_lanes``) the kernels use: the sweep's block
loop and the Lyapunov row blocks. The old kernels are the sweep or Lyapunov template, step core
and lane-block functions of git revision ``--old`` (``bench/kernel.py``'s ``old_kernels``); the
new ones the working tree's. Both run the same workload through the public API (the generated
module's entry point swapped), alternating, in this process; reported: the CPU seconds of each
(median of ``--repeat``, after a first round that compiles) and whether the results are
bitwise equal. Workloads: ``sweep``, 20 Omega in [0.05, 1.2] (every 20th of
``bench/planetary.py``'s 400), 50 mesh periods of transient at the lowest, 32 samples;
``lanes``, the largest Lyapunov exponent of 24 Omega in [0.3, 1.1], transient 20, duration 200;
``paper``, for scale, ``bench/bifurcation.py``'s workload (the reduced CATT device, 1000 Omega,
transient 2000, 200 samples: its fused sweep loop).

    .venv/bin/python bench/lane_blocks.py [--old REV] [--repeat 5] [--what sweep lanes paper]
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import geardyn
from geardyn.analysis.lyapunov import lyapunov_lanes
from geardyn.io.toml import builtin_study
from geardyn.solvers import kernels as kmod

sys.path.insert(0, str(Path(__file__).resolve().parent))
from kernel import old_kernels  # noqa: E402


def workload(model, what: str):
    """(template, entry point name, run: a function returning the results as one array)."""
    if what == "paper":
        values = np.linspace(0.1, 4.0, 1000)
        run = geardyn.RunSettings(transient=2000.0, samples=200)
        return "rk4", "sweep", lambda: geardyn.bifurcation(model, "Omega", values,
                                                           run)["poincare"].values
    if what == "sweep":
        omegas = np.linspace(0.05, 1.2, 400)[::20]
        run = geardyn.RunSettings(transient=50 * 2 * math.pi / omegas.min(), samples=32)
        return "rk4", "sweep", lambda: geardyn.bifurcation(model, "Omega", omegas,
                                                           run)["poincare"].values
    P = np.ascontiguousarray(model.lane_params("Omega", np.linspace(0.3, 1.1, 24)))

    def lanes():
        lam, err = lyapunov_lanes(model, P, run=geardyn.RunSettings(transient=20.0),
                                  settings=geardyn.LyapunovSettings(duration=200.0),
                                  with_error=True)
        return np.concatenate([lam, err])

    return "lyapunov", "lyapunov_lanes", lanes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", default="54378d3")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--what", nargs="*", default=["sweep", "lanes"],
                    choices=["sweep", "lanes", "paper"])
    args = ap.parse_args()
    planetary = geardyn.build_model(builtin_study("planetary_example"))
    paper = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    print(f"# old kernels {args.old} against the working tree; CPU s, median of {args.repeat}")
    for what in args.what:
        model = paper if what == "paper" else planetary
        template, entry, run = workload(model, what)
        new = kmod.kernels_for(model.kernel, template)
        fns = {"old": getattr(old_kernels(model.kernel, args.old, template), entry),
               "new": getattr(new, entry)}
        times = {k: [] for k in fns}
        results = {}
        for rep in range(args.repeat + 1):  # the first round compiles
            for k, fn in fns.items():
                setattr(new, entry, fn)
                try:
                    c0 = time.process_time()
                    results[k] = run()
                    if rep:
                        times[k].append(time.process_time() - c0)
                finally:
                    setattr(new, entry, fns["new"])
        med = {k: statistics.median(t) for k, t in times.items()}
        same = np.array_equal(results["old"], results["new"], equal_nan=True)
        print(f"{what}: old {med['old']:.3f} s, new {med['new']:.3f} s, new/old "
              f"{med['new'] / med['old']:.3f}; bitwise equal: {same}")


if __name__ == "__main__":
    main()
