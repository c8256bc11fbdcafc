"""Speed of a run-up: the gear pair's ramp through its resonances, and the planetary set's.

Workloads: the gear pair (``zeta`` 0.05, ``kappa`` 0.2, ``Fm`` 0.1, ``Fa`` 0.05) ramped in Omega
from 0.2 to 2.5 at 1e-4 per tau (23 000 tau, 64 steps per period at the top speed, sampled 4
per tau); the built-in ``planetary_example`` ramped from 1000 to 20 000 rpm over 3000 tau
(default step, sampled 2 per tau). Prints the median of ``--repeat`` warm runs (wall and
process CPU), the RK4 steps and ns of CPU per step.

    .venv/bin/python bench/runup.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

import geardyn
from geardyn.io.toml import builtin_study


def measure(model, settings, repeat: int) -> tuple[float, float, int]:
    ds = geardyn.runup(model, settings)  # warm: compile or load the kernel
    walls, cpus = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        ds = geardyn.runup(model, settings)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus), int(ds.attrs["steps_done"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    pair = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.05)
    gs = geardyn.build_model(builtin_study("planetary_example"))
    per_rpm = gs.with_params(input_speed=1000.0).omega / 1000.0
    cases = {
        "gear pair": (pair, geardyn.RunupSettings(start=0.2, stop=2.5, rate=1e-4,
                                                  steps_per_period=64, sample_rate=4.0)),
        "planetary_example": (gs, geardyn.RunupSettings(
            start=1000.0 * per_rpm, stop=20000.0 * per_rpm, duration=3000.0,
            sample_rate=2.0)),
    }
    for name, (model, settings) in cases.items():
        wall, cpu, steps = measure(model, settings, args.repeat)
        print(f"{name}: {steps} steps, median of {args.repeat}: {wall:.3f} s wall, "
              f"{cpu:.3f} s CPU, {cpu / steps * 1e9:.0f} ns CPU per step")


if __name__ == "__main__":
    main()
