"""Benchmark of a gear train's speed sweep: a 400-point bifurcation diagram in input speed of the
built-in study ``two_stage_train`` (two parallel spur stages, 8 coordinates, 16 states,
quasi-periodic forcing: stage 2 meshes at 23/61 of stage 1's frequency), target <= 10 s warm on
2 cores.

Workload: the study's model, 400 input speeds in [1000, 6000] rpm (``input_speed``, which sets
Omega alone), no continuation, through ``geardyn.bifurcation``, a transient of
``--transient-periods`` (200) stage-1 mesh periods at the lowest speed in every lane (more
periods at higher speeds), ``--samples`` (32) Poincare points, default steps per period. Prints
the workload (lane-steps), the median of ``--repeat`` warm runs (wall and process CPU time), ns
per lane-step and a checksum of the Poincare points; ``--write`` records the median in the
current-figures table of bench/RESULTS.md (row ``train-sweep``). ``--order-one`` sets stage 2's
order to 1 (one mesh frequency: the planetary kernels' shared-phase path) to show what the
second frequency costs; not with ``--write``.

    .venv/bin/python bench/train.py [--threads 2] [--repeat 3] [--transient-periods 200]
        [--samples 32] [--order-one] [--write]
"""

from __future__ import annotations

import numpy as np

import geardyn
from _speed_sweep import arguments, timed_sweep
from geardyn.io.toml import builtin_study

TARGET_S = 10.0


def main() -> None:
    ap = arguments(__doc__, repeat=3, samples=32)
    ap.add_argument("--order-one", action="store_true",
                    help="stage 2's order set to 1 (one mesh frequency), for comparison")
    args = ap.parse_args()
    if args.order_one and args.write:
        ap.error("--order-one is a comparison, not the benchmark: not with --write")
    model = geardyn.build_model(builtin_study("two_stage_train"))
    if args.order_one:
        model = model.with_params(stage2_order=1.0)
    timed_sweep(model, "two_stage_train", np.linspace(1000.0, 6000.0, 400), args, "train-sweep",
                TARGET_S, "train.py")


if __name__ == "__main__":
    main()
