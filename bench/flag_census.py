"""What the edge screen flags in the paper workload (bench/bifurcation.py's, edge location on):
how many flagged steps end on another side of an edge, how many do not (flagged by the graze
screen alone), and of those how many hold a located graze (the rest: false alarms, whose
split commits the trial step unchanged).

The generated kernel module with a census in ``_finish_flagged`` (bench/fused_loop.py's
variant mechanism; compiled afresh, not cached), counts in the lanes' ``unresolved`` entries
(checked: no field full, no step at the split limit). One thread.

    .venv/bin/python bench/flag_census.py [--points 1000] [--calls]

``--calls``: instead, how many block steps of the fused loop there are and how many of them
call out of line (``_slots_out``: a slot flagged or with bookkeeping due), one or more slots.
"""

from __future__ import annotations

import argparse
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

SPLIT = """    UNRES[lane] += _split_step(i, T0B[k], ys, y1s, P[lane], HB[k], OMEGA[lane], NPER[k],
                               S_TAB[j0], C_TAB[j0], S_TAB[j0 + 2], C_TAB[j0 + 2], sides, g1s,
                               NCROSS[lane], work, ybuf, gbuf)
"""
# Counts (15 bits each; the paper's lanes flag at most ~4500 steps): bits 0-14 a side left at
# the step's end, 15-29 none, 30-44 of those a crossing located (a graze), 45-59 a side left
# and a graze flag set (the split looks for more crossings in the step).


def census_edit() -> list[tuple[str, str]]:
    """The edit of ``_finish_flagged`` that counts its calls by kind (see above)."""
    new = ("    zc0 = 0\n    zx = 0\n    zf = 0\n    for j in range(n_ev):\n"
           "        zc0 += NCROSS[lane, j]\n"
           "        zx += 1 if (1 if g1s[j] > 0.0 else -1) != sides[j] else 0\n"
           "        zf += 1 if gbuf[GRAZE_ROW, j] != 0.0 else 0\n"
           + SPLIT.replace("    UNRES[lane] += _split_step(", "    zu = _split_step(") +
           "    zc1 = 0\n    for j in range(n_ev):\n        zc1 += NCROSS[lane, j]\n"
           "    zci = 1 if zx > 0 else 0\n    zg = 1 if zc1 > zc0 else 0\n"
           "    zgf = 1 if zf > 0 else 0\n"
           "    UNRES[lane] += (zci + ((1 - zci) << 15) + (((1 - zci) * zg) << 30)\n"
           "                    + ((zci * zgf) << 45) + (zu << 60))\n")
    return [(SPLIT, new)]


# --calls: per block step of the fused loop, into the unresolved entry of the lane in slot 0
# (21 bits each): bits 0-20 block steps, 21-41 those with a marked slot (a call of _slots_out),
# 42-62 those with two or more marked slots.
CALLS = ("        if n_out > 0:\n",
         "        out[9][LANE[0]] += (1 + ((1 if n_out > 0 else 0) << 21)\n"
         "                            + ((1 if n_out > 1 else 0) << 42))\n"
         "        if n_out > 0:\n")


def calls(u: np.ndarray, out) -> None:
    """Print the --calls census (see CALLS) of the lanes' unresolved entries ``u``."""
    steps, called, several = (int(((u >> s) & 0x1FFFFF).sum()) for s in (0, 21, 42))
    print(f"block steps {steps}, with a marked slot (a call out of line) {called} "
          f"({called / steps:.3f}), with two or more {several} ({several / steps:.3f}); "
          f"lane-steps {int(out.steps.sum())} ({int(out.steps.sum()) / steps:.1f} per block step)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--calls", action="store_true",
                    help="count the block steps and the calls out of line instead")
    args = ap.parse_args()
    numba.set_num_threads(1)
    model = device()
    source = Path(kernels_for(model.kernel).__file__).read_text()
    fused_loop.EDITS["census"] = [CALLS] if args.calls else census_edit()
    with tempfile.TemporaryDirectory() as tmp:
        mod = fused_loop.variant_module(source, "census", Path(tmp))
        ens.kernels_for = lambda kernel: mod
        P = model.lane_params("Omega", np.linspace(0.1, 4.0, args.points))
        run = geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES, locate_edges=True)
        t0 = time.process_time()
        out = ens.run_lanes(model, P, model.initial_state(), run=run)
        cpu = time.process_time() - t0
    u = out.unresolved
    if args.calls:
        calls(u, out)
        return
    if np.any(u >> 60):
        raise SystemExit("a step reached the split limit: the counts are not separable")
    fields = [(u >> s) & 0x7FFF for s in (0, 15, 30, 45)]
    if max(int(f.max()) for f in fields) >= 0x7FFF:
        raise SystemExit("a lane's count fills its 15 bits: the counts are not separable")
    crossed, other, graze, crossed_gr = (int(f.sum()) for f in fields)
    flagged = crossed + other
    if flagged == 0 and out.crossings.any():  # every crossing is located by a flagged step
        raise SystemExit("crossings located but no flagged step counted: the counts were lost")
    steps = int(out.steps.sum())
    print(f"# paper workload, {args.points} points, edge location on, one thread "
          f"(census run, compile included: {cpu:.1f} s CPU)")
    print(f"lane-steps {steps}, flagged {flagged} ({flagged / steps:.4f} of them)")
    print(f"  a side left at the step's end      {crossed:9d} ({crossed / flagged:.3f})")
    print(f"    of those with a graze flag       {crossed_gr:9d} ({crossed_gr / flagged:.3f})")
    print(f"  no side left (graze screen alone)  {other:9d} ({other / flagged:.3f})")
    print(f"    of those a graze located         {graze:9d} ({graze / flagged:.4f})")
    print(f"    false alarms                     {other - graze:9d} "
          f"({(other - graze) / flagged:.3f})")
    print(f"crossings counted over the sampled stretch: {int(out.crossings.sum())}")


if __name__ == "__main__":
    main()
