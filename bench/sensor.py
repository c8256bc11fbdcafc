"""Cost of the fixed-sensor transfer (geardyn.analysis.sensor.sensor_signal): ``--lanes``
signals of ``--samples`` samples from ``--planets`` planets' mesh forces at once (one numpy
call, the batch the labelled-dataset generator hands it), and the order spectrum of each
(sensor_spectrum). Random forces, a uniform carrier angle; median of ``--repeat`` runs; prints
ms per batch and microseconds per lane.

    .venv/bin/python bench/sensor.py [--lanes 100] [--samples 20000] [--planets 4]
        [--repeat 5]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from geardyn.analysis.sensor import sensor_signal, sensor_spectrum


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lanes", type=int, default=100)
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--planets", type=int, default=4)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    rng = np.random.default_rng(0)
    forces = rng.normal(size=(a.lanes, a.samples, a.planets))
    phi = np.linspace(0.0, 2.0 * math.pi * 4, a.samples, endpoint=False)
    psi = 2.0 * math.pi * np.arange(a.planets) / a.planets
    sensor_signal(forces, phi, psi)  # warm caches
    t_sig, t_spec = [], []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        s = sensor_signal(forces, phi, psi, 0.0, math.pi / 2, "hann")
        t1 = time.perf_counter()
        for lane in s:
            sensor_spectrum(lane, 4)
        t2 = time.perf_counter()
        t_sig.append(t1 - t0)
        t_spec.append(t2 - t1)
    sig, spec = statistics.median(t_sig), statistics.median(t_spec)
    print(f"{a.lanes} lanes x {a.samples} samples x {a.planets} planets: sensor_signal "
          f"{sig * 1e3:.1f} ms ({sig / a.lanes * 1e6:.0f} us per lane), sensor_spectrum "
          f"{spec * 1e3:.1f} ms ({spec / a.lanes * 1e6:.0f} us per lane)")


if __name__ == "__main__":
    main()
