"""Per-lane-step cost of the sweep kernel on one thread (issue 11, "fast"): the paper's reference
workload (every ``--stride``-th of its 1000 Omega, transient 2000, 200 samples, default steps),
through ``run_lanes``, with and without edge location; median of ``--repeat`` warm runs.
``--study NAME`` takes that built-in study's model instead (e.g. ``paper_fig13``: the load
fluctuation, which the fused loop runs in its general form).

    .venv/bin/python bench/step_cost.py [--stride 4] [--repeat 3] [--threads 1] [--study NAME]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np

import geardyn
from geardyn.solvers.ensemble import run_lanes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--stride", type=int, default=4)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--study", default=None, help="a built-in study's model (default: the "
                    "paper's device, xi1 = xi2 = 0.05)")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    if args.study:
        from geardyn.io.toml import builtin_study

        model = geardyn.build_model(builtin_study(args.study))
    else:
        model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    omegas = np.linspace(0.1, 4.0, 1000)[::args.stride]
    P = model.lane_params("Omega", omegas)
    y0 = model.initial_state()
    run_lanes(model, P[:4], y0, run=geardyn.RunSettings(transient=20.0, samples=2))  # load
    out = {}
    for locate in (True, False):
        times = []
        for _ in range(args.repeat):
            t = time.process_time()
            r = run_lanes(model, P, y0, run=geardyn.RunSettings(transient=2000.0, samples=200,
                                                                locate_edges=locate))
            times.append(time.process_time() - t)
        n = r.steps_per_period.astype(np.int64)
        steps = int(np.sum((r.transient_periods + 200 * r.sample_every) * n))
        out[locate] = (statistics.median(times), steps, r)
    (t1, steps, r1), (t0, _, _) = out[True], out[False]
    per = args.threads * 1e9 / steps
    cross = int(np.sum(r1.crossings))
    print(f"threads {args.threads}, {omegas.size} lanes, {steps:.3e} lane-steps: "
          f"edges {t1:.3f} s = {t1 * per:.1f} ns/lane-step; none {t0:.3f} s = "
          f"{t0 * per:.1f} ns/lane-step; checksum {np.nansum(r1.samples):.17g} "
          f"crossings {cross}")


if __name__ == "__main__":
    main()
