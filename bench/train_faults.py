"""Run-time cost of a gear train's potential-energy stiffness and of a tooth fault (issue 35).

The built-in ``two_stage_train`` study (19/61, 23/71, 8 coordinates, 3000 rpm) built four ways:
as shipped (ISO 6336-1 mean stiffness, a 25 % sine: 1 harmonic), on the potential-energy
stiffness (both meshes' tables over a mesh cycle, ``harmonics`` 9), and with a 1 mm root crack
on tooth 3 of g1 (the forcing period one revolution of g1: stage 1's series 9 x 19 = 171
harmonics, every mesh's block padded to them) or of g4 (9 x 71 = 639). Prints per build the
time to build the model (the first build of a train computes its tables; the faulty table over
the revolution is kept on the train), and a simulate of at least ``--cycles`` stage-1 mesh
cycles (whole forcing periods, transient 0, default steps): steps per stage-1 mesh cycle, the
wall time (median of ``--repeat`` warm runs) and ns per step, and the ratio to the
potential-energy healthy build's.

    .venv/bin/python bench/train_faults.py [--repeat 3] [--cycles 200]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import geardyn
from geardyn.io.toml import builtin_study_text, load_study

CRACK = '\n[[train.faults]]\nkind = "crack"\ngear = "{}"\ntooth = 3\ndepth = "1 mm"\n'


def builds() -> dict[str, str]:
    """The study texts of the four builds."""
    iso = builtin_study_text("two_stage_train")
    pe = iso.replace('stiffness = "iso"', 'stiffness = "potential_energy"\n'
                     'bore_radius = "10 mm"').replace("stiffness_fluctuation = 0.25\n", "")
    return {"ISO, sine": iso, "potential energy": pe,
            "crack on g1 tooth 3": pe + CRACK.format("g1"),
            "crack on g4 tooth 3": pe + CRACK.format("g4")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cycles", type=float, default=200.0)
    args = ap.parse_args()
    rows = []
    for name, text in builds().items():
        geardyn.build_model(load_study(text))  # warm (imports, compiled helpers)
        t0 = time.perf_counter()
        model = geardyn.build_model(load_study(text))  # a new train: its tables computed
        build_s = time.perf_counter() - t0
        per_period = float(model.mesh_order)  # stage-1 mesh cycles per forcing period
        samples = max(1, math.ceil(args.cycles / per_period))
        run = geardyn.RunSettings(transient=0.0, samples=samples)
        geardyn.simulate(model, run=run)  # warm
        walls = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            ds = geardyn.simulate(model, run=run)
            walls.append(time.perf_counter() - t0)
        steps = ds.sizes["time"] - 1
        wall = statistics.median(walls)
        rows.append((name, model.fourier.shape[1] // 2, build_s, steps / (samples * per_period),
                     wall, 1e9 * wall / steps))
    base = next(r for r in rows if r[0] == "potential energy")[5]
    print("| build | harmonics | build [s] | steps per stage-1 cycle | simulate [s] | "
          "ns per step | ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, nh, build_s, per_cycle, wall, ns in rows:
        print(f"| {name} | {nh} | {build_s:.2f} | {per_cycle:.0f} | {wall:.3f} | {ns:.0f} | "
              f"{ns / base:.2f}x |")


if __name__ == "__main__":
    main()
