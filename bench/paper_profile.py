"""Where the paper workload's time goes: the reference workload of bench/bifurcation.py with and
without edge location, on the given numbers of threads (median of 2 warm runs each).

    .venv/bin/python bench/paper_profile.py 2 1
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np

import geardyn

sys.path.insert(0, str(Path(__file__).parent))
from bifurcation import SAMPLES, TRANSIENT, device  # noqa: E402


def _median_time(model, values, **kw) -> float:
    times = []
    for _ in range(2):
        t0 = time.perf_counter()
        geardyn.bifurcation(model, "Omega", values,
                            run=geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES, **kw))
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    model = device()
    values = np.linspace(0.1, 4.0, 1000)
    geardyn.bifurcation(model, "Omega", values[:4],
                        run=geardyn.RunSettings(transient=20.0, samples=2))  # compile/load
    for threads in [int(a) for a in sys.argv[1:]] or [numba.config.NUMBA_NUM_THREADS]:
        numba.set_num_threads(threads)
        with_edges = _median_time(model, values)
        without = _median_time(model, values, locate_edges=False)
        print(f"threads {threads}: edge location {with_edges:.2f} s, none {without:.2f} s")


if __name__ == "__main__":
    main()
