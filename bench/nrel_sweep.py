"""Benchmark of the NREL 5 MW gearbox's speed sweep: a 200-point bifurcation diagram in rotor
speed of the built-in study ``nrel_5mw_gearbox_sweep`` (16 bodies, 13 nonlinear meshes, 34
coordinates, quasi-periodic forcing: three mesh frequencies), target <= 2 min warm on 2 cores
(issue 36).

Workload: the study's model, 200 rotor speeds in [2, 25] rpm (``input_speed``), no
continuation, through ``geardyn.bifurcation``, a transient of ``--transient-periods`` (200)
stage-3 mesh periods at the lowest speed in every lane (more at higher speeds), ``--samples``
(16) Poincare points, default steps per period. Prints the workload (lane-steps), the median of
``--repeat`` warm runs (wall and process CPU time), ns per lane-step, the meshes' contact
regimes and a checksum of the Poincare points; ``--write`` records the median in the
current-figures table of bench/RESULTS.md (row ``nrel-sweep``).

    .venv/bin/python bench/nrel_sweep.py [--threads 2] [--repeat 1] [--transient-periods 200]
        [--samples 16] [--write]
"""

from __future__ import annotations

import collections

import numpy as np

import geardyn
from _speed_sweep import arguments, timed_sweep
from geardyn.io.toml import builtin_study

TARGET_S = 120.0


def main() -> None:
    args = arguments(__doc__, repeat=1, samples=16).parse_args()
    model = geardyn.build_model(builtin_study("nrel_5mw_gearbox_sweep"))
    ds = timed_sweep(model, "nrel_5mw_gearbox_sweep", np.linspace(2.0, 25.0, 200), args,
                     "nrel-sweep", TARGET_S, "nrel_sweep.py")
    for name in ds["mesh"].values:
        print(f"contact {name}: {dict(collections.Counter(ds['contact'].sel(mesh=name).values))}")


if __name__ == "__main__":
    main()
