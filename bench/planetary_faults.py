"""Run-time cost of a planetary set with a tooth fault (issue 35): the forcing period one revolution
of the faulty gear relative to the carrier, every mesh a Fourier series of harmonics x Z_f terms,
against the healthy set built over one mesh cycle.

The stage of docs/planetary.md (25/23/71 teeth, m 2 mm, 4 planets, potential-energy stiffness,
``--harmonics`` mesh harmonics, default 9, and 120 angles per mesh cycle), healthy and with a
1 mm root crack on sun tooth 3 (H = 9 x 25 = 225 per mesh), on tooth 3 of planet 2 (207) and on
ring tooth 3 (639). The same physical run for every build: a short simulate of ``--cycles``
mesh cycles (100) and a sweep of ``--lanes`` input speeds (8, 2000-6000 rpm) with a transient
and samples of ``--cycles`` mesh cycles each (a faulty build: whole revolutions, at least one;
the sweep at least two samples),
default steps per period (at least 64 steps a mesh cycle in every build). Prints per build the
steps per mesh cycle, the wall time (median of ``--repeat`` warm runs) and ns per lane-step, and
the ratio to the healthy build's. Single-threaded (``NUMBA_NUM_THREADS`` as set; the sweep's
threads with ``--threads``). ``--write`` records the ratios in bench/RESULTS.md (row
``planetary-faults``, no target).

    .venv/bin/python bench/planetary_faults.py [--repeat 3] [--cycles 100] [--lanes 8]
        [--harmonics 9] [--threads 1] [--write]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import time

import numba
import numpy as np

import geardyn
import geardyn.gears as g
from geardyn.core.plan import LanePlan

M = geardyn.Member
MEMBERS = dict(
    sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8),
    ring=M(mass=2.35, inertia_over_r2=3.0, bearing_stiffness=1e8, torsional_stiffness=1e9),
    carrier=M(mass=5.43, inertia_over_r2=6.29, bearing_stiffness=1e8, torsional_stiffness=1e9),
    planet=M(mass=0.66, inertia_over_r2=0.61, bearing_stiffness=1e8))
OPTIONS = dict(sun_bore_radius="12 mm", planet_bore_radius="10 mm", ring_rim_radius="85 mm",
               angles=120)


def stage() -> g.PlanetaryGeometry:
    def gear(z: int, name: str, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, "2 mm", "20 deg", "20 mm", internal=internal, name=name)
    return g.PlanetaryGeometry(gear(25, "sun"), gear(23, "planet"),
                               gear(71, "ring", internal=True), n_planets=4)


def build(geo, fault, harmonics: int) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=harmonics, stiffness="potential_energy", stiffness_options=OPTIONS,
        faults=() if fault is None else [fault], sun_backlash="10 um", ring_backlash="10 um",
        sun_torque=100.0, mesh_damping=0.05, **MEMBERS)


def timed(fn, repeat: int) -> float:
    fn()  # warm
    walls = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        walls.append(time.perf_counter() - t)
    return statistics.median(walls)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cycles", type=int, default=100)
    ap.add_argument("--lanes", type=int, default=8)
    ap.add_argument("--harmonics", type=int, default=9)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--write", action="store_true", help="record in bench/RESULTS.md")
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    geo = stage()
    crack = dict(depth="1 mm")
    builds = [("healthy (one mesh cycle)", None),
              ("crack on sun tooth 3", g.RootCrack(**crack, gear="sun", tooth=3)),
              ("crack on planet2 tooth 3", g.RootCrack(**crack, gear="planet2", tooth=3)),
              ("crack on ring tooth 3", g.RootCrack(**crack, gear="ring", tooth=3))]
    speeds = np.linspace(2000.0, 6000.0, args.lanes)
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, {args.threads} threads,"
          f" {platform.machine()}, {os.cpu_count()} cpus, load {os.getloadavg()[0]:.1f}")
    print("build | Z_f | H per mesh | steps per mesh cycle | simulate s | ns/step | "
          "sweep s | ns/lane-step | ratio sim | ratio sweep")
    base = None
    summary = []
    for name, fault in builds:
        t = time.perf_counter()
        model = build(geo, fault, args.harmonics).with_params(input_speed=3000.0)
        built = time.perf_counter() - t
        z = model.mesh_order
        periods = max(1, math.ceil(args.cycles / z))
        n = int(LanePlan.build(model, model.params[None, :], geardyn.RunSettings(
            transient=0.0, samples=periods)).steps_per_period[0])
        run = geardyn.RunSettings(transient=0.0, samples=periods)
        sim = timed(lambda m=model, r=run: geardyn.simulate(m, run=r), args.repeat)
        sim_ns = sim / (periods * n) * 1e9
        period = 2.0 * math.pi / model.omega
        sweep_run = geardyn.RunSettings(transient=periods * period * 3000.0 / speeds.min(),
                                        samples=max(2, periods))
        P = model.lane_params("input_speed", speeds)
        plan = LanePlan.build(model, P, sweep_run)
        lane_steps = int(np.sum(plan.transient_steps + sweep_run.samples * plan.sample_steps))
        sweep = timed(lambda m=model, r=sweep_run: geardyn.bifurcation(
            m, "input_speed", speeds, run=r), args.repeat)
        sweep_ns = sweep / lane_steps * 1e9
        if base is None:
            base = (sim_ns, sweep_ns)
        print(f"{name} | {z} | {model.fourier.shape[1] // 2} | {n / z:.0f} | {sim:.3f} | "
              f"{sim_ns:.0f} | {sweep:.3f} | {sweep_ns:.0f} | {sim_ns / base[0]:.2f} | "
              f"{sweep_ns / base[1]:.2f}   (built in {built:.2f} s)")
        summary.append(f"{name.split(' (')[0]} (H {model.fourier.shape[1] // 2}): "
                       f"{sim_ns:.0f} / {sweep_ns:.0f} ns, {sim_ns / base[0]:.1f}x / "
                       f"{sweep_ns / base[1]:.1f}x")
    if args.write:
        import sys

        sys.path.insert(0, os.path.dirname(__file__))
        from _results import record

        record("planetary-faults", "planetary set (25/23/71, N = 4) with a cracked tooth: ns "
               "per step of a simulate / per lane-step of a sweep against the healthy "
               "one-mesh-cycle build (no target)",
               "; ".join(summary) + f" (median of {args.repeat}, {args.threads} thread)",
               "no target",
               "`.venv/bin/python bench/planetary_faults.py " + " ".join(sys.argv[1:]) + "`")


if __name__ == "__main__":
    main()
