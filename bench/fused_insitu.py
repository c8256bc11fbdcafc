"""What parts of the fused loop cost inside the sweep: the paper workload (bench/bifurcation.py's)
run through variants of the generated kernel module (bench/fused_loop.py's edits), the
variants' runs alternating in one process, CPU time of one thread, median of ``--repeat``.

Unlike bench/fused_loop.py (the step loop alone) this counts what a variant changes out of the
loop too: e.g. ``noscreen`` (nothing flagged) without edge location leaves every state as it is
(an unlocated flagged step commits its trial step) and saves the side test and graze screen
*and* the out-of-line handling of the ~1.5 million flagged steps (their crossings not counted:
the crossing counts and contact statistics differ, not the Poincare points). Each variant is
compiled afresh (minutes on a loaded machine).

    .venv/bin/python bench/fused_insitu.py [--variants base,noscreen] [--edges] [--repeat 5]

What edge location's parts cost (``bench/flag_census.py`` counts the flagged steps by kind):
``--edges --variants base,nograze,nosplit,nosplit+loopcommit,screenonly,noscreen``: base -
nosplit the splits, nosplit - screenonly the out-of-line handling of the flagged slots
(nosplit - nosplit+loopcommit of it: their state written out of line), screenonly -
noscreen the screen in the loop, base - nograze what the graze flags cost.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import geardyn
import geardyn.solvers.ensemble as ens
from geardyn.solvers.kernels import kernels_for

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fused_loop  # noqa: E402
from bifurcation import SAMPLES, TRANSIENT, device  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", default="base,noscreen")
    ap.add_argument("--edges", action="store_true", help="with edge location")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--points", type=int, default=1000)
    args = ap.parse_args()
    numba.set_num_threads(1)
    model = device()
    values = np.linspace(0.1, 4.0, args.points)
    source = Path(kernels_for(model.kernel).__file__).read_text()
    names = args.variants.split(",")
    run = geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES, locate_edges=args.edges)
    mods = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:  # compiled and loaded
            mods[name] = fused_loop.variant_module(source, name, Path(tmp))
            ens.kernels_for = lambda kernel, m=mods[name]: m
            geardyn.bifurcation(model, "Omega", values[:8], run=geardyn.RunSettings(
                transient=20.0, samples=2, locate_edges=args.edges))
        times = {name: [] for name in names}
        for _ in range(args.repeat):
            for name in names:
                ens.kernels_for = lambda kernel, m=mods[name]: m
                t0 = time.process_time()
                geardyn.bifurcation(model, "Omega", values, run=run)
                times[name].append(time.process_time() - t0)
    base = statistics.median(times[names[0]])
    print(f"# paper workload, {args.points} points, edge location "
          f"{'on' if args.edges else 'off'}, CPU s of one thread, median of {args.repeat}")
    for name in names:
        med = statistics.median(times[name])
        print(f"{name:28s} {med:.3f} s ({med / base:.3f}x {names[0]}; "
              f"{', '.join(f'{t:.2f}' for t in times[name])})")


if __name__ == "__main__":
    main()
