"""One lane on the pointer kernel path against ``GearPair`` and the one form inlined.

The gear pair written as a one-form user model (examples/gear_pair_model.py) on the pointer path
(the default), on the lane-form path (its functions inlined) and ``geardyn.GearPair`` with the
same coefficients (Omega 1.3, impacting): ``simulate`` of 2000 forcing periods recorded (128
steps per period, edges located), ``lyapunov`` of the largest exponent and of the spectrum
(30000 time units after 100 of transient). One thread, CPU seconds, median of ``--repeat``, the
three alternating; each row's ratio to ``GearPair`` and a hash of its result (the same hash:
bitwise the same). A JSON line, for runs of two source trees alternated (``PYTHONPATH``).

    PYTHONPATH=src .venv/bin/python bench/pointer_lane.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import sys
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
COEFFS = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2, Omega=1.3)
KINDS = ("simulate", "lyapunov", "spectrum")


def _job(geardyn, kind: str, model):
    if kind == "simulate":
        run = geardyn.RunSettings(transient=0.0, samples=2000, steps_per_period=128)
        return geardyn.simulate(model, run=run)
    run = geardyn.RunSettings(transient=100.0, steps_per_period=128)
    settings = geardyn.LyapunovSettings(duration=30000.0)
    return geardyn.lyapunov(model, run=run, settings=settings, spectrum=kind == "spectrum")


def _hash(np, kind: str, result) -> str:
    if kind == "simulate":
        data = b"".join(np.ascontiguousarray(result[n].values).tobytes()
                        for n in ("x", "v", "F", "poincare", "edge_crossings"))
    else:
        data = np.asarray(result).tobytes()
    return hashlib.sha1(data).hexdigest()[:10]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args(argv)
    import numba

    numba.set_num_threads(1)
    import numpy as np

    import geardyn

    sys.path.insert(0, str(EXAMPLES))
    from gear_pair_model import gear_pair

    models = {"GearPair": geardyn.GearPair(**COEFFS),
              "lane-form": gear_pair(**COEFFS, kernel_path="lane-form"),
              "pointer": gear_pair(**COEFFS, kernel_path="pointer")}
    rows = {}
    for kind in KINDS:
        first = {name: _job(geardyn, kind, m) for name, m in models.items()}
        cpu: dict[str, list[float]] = {name: [] for name in models}
        for _ in range(args.repeat):
            for name, m in models.items():
                c = time.process_time()
                _job(geardyn, kind, m)
                cpu[name].append(time.process_time() - c)
        base = statistics.median(cpu["GearPair"])
        for name in models:
            med = statistics.median(cpu[name])
            rows[f"{kind} {name}"] = [round(med * 1e3, 2), round(med / base, 3),
                                      _hash(np, kind, first[name])]
    print(json.dumps({"load": os.getloadavg(), "rows": rows}))


if __name__ == "__main__":
    main()
