"""A user's model on the fast path: the gear pair written as a one-form ``UserModel``
(examples/gear_pair_model.py; its default kernel path, the pointer path) against the built-in
``GearPair``, in ns per lane-step of a sweep.

Workload: bench/peers.py's sweep (``GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)``, 400
values of Omega in [0.2, 3], a transient of 500 pi time units rounded up to whole periods, 100
sampled periods) at 128 steps per period with edges located, through
:func:`geardyn.solvers.ensemble.run_lanes` (the sweep kernel). Rows: ``GearPair``, the one-form
``UserModel`` on its default kernel path (with ``--inlined`` also with its functions inlined,
``kernel_path="lane-form"``) and, with ``--legacy``, the same equations as a legacy plain
``UserModel`` (``rhs(t, y, dy, p)``, the generic path; its kernels compile in this process).
Wall time: the median of ``--repeat`` warm runs, the rows timed round-robin; ns per lane-step =
wall time x threads / grid steps integrated (``steps`` of the result). The Poincare points of
the rows are compared bit for bit with GearPair's.

    .venv/bin/python bench/user_model.py [--repeat 5] [--points 400] [--legacy] [--inlined]
                                         [--write]

On a tree without ``UserModel.from_one_form`` only the GearPair row runs (the figure to compare
an older tree with).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

import geardyn
from geardyn.solvers.ensemble import run_lanes

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))

import _results as results  # noqa: E402

COEFFS = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
TRANSIENT = 500.0 * math.pi
SAMPLES = 100
STEPS = 128


@nb.njit(cache=True)
def _legacy_rhs(t, y, dy, p):
    """The gear pair in the legacy plain form (phases 0): p = GearPair's coefficients."""
    x = y[0]
    b = p[7]
    g = x - min(max(x, -b), b)
    c = math.cos(p[0] * t)
    dy[0] = y[1]
    dy[1] = p[3] + p[4] * p[0] * p[0] * c - 2.0 * p[1] * y[1] - (1.0 + p[2] * c) * g


@nb.njit(cache=True)
def _legacy_events(t, y, g, p):
    g[0] = y[0] - p[7]
    g[1] = y[0] + p[7]


def _models(legacy: bool, inlined: bool = False) -> dict[str, geardyn.Model]:
    pair = geardyn.GearPair(**COEFFS)
    out: dict[str, geardyn.Model] = {"GearPair": pair}
    if hasattr(geardyn.UserModel, "from_one_form"):
        from gear_pair_model import gear_pair
        out["UserModel (one form)"] = gear_pair(**COEFFS)
        if inlined:
            out["UserModel (lane-form)"] = gear_pair(**COEFFS, kernel_path="lane-form")
    if legacy:
        out["UserModel (legacy plain)"] = geardyn.UserModel(
            _legacy_rhs, 2, pair.params[:8], param_names=pair.param_names[:8],
            events=_legacy_events, n_events=2, natural_frequency=1.0)
    return out


def _run(model: geardyn.Model, omegas: np.ndarray):
    P = model.lane_params("Omega", omegas)
    return run_lanes(model, P, model.initial_state(), run=geardyn.RunSettings(
        transient=TRANSIENT, samples=SAMPLES, steps_per_period=STEPS))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--points", type=int, default=400)
    ap.add_argument("--legacy", action="store_true")
    ap.add_argument("--inlined", action="store_true",
                    help="also the one form with its functions inlined (kernel_path='lane-form')")
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args()
    omegas = np.linspace(0.2, 3.0, a.points)
    models = _models(a.legacy, a.inlined)
    threads = nb.get_num_threads()
    first = {}
    for name, m in models.items():  # compile (or load) and keep the first run's results
        t = time.perf_counter()
        first[name] = _run(m, omegas)
        print(f"{name}: first run {time.perf_counter() - t:.1f} s", flush=True)
    walls: dict[str, list[float]] = {name: [] for name in models}
    for _ in range(a.repeat):
        for name, m in models.items():
            t = time.perf_counter()
            _run(m, omegas)
            walls[name].append(time.perf_counter() - t)
    ref = first["GearPair"]
    per = {}
    for name in models:
        steps = float(np.sum(first[name].steps))
        wall = statistics.median(walls[name])
        per[name] = wall * threads / steps * 1e9
        same = np.array_equal(first[name].samples, ref.samples, equal_nan=True)
        dev = float(np.nanmax(np.abs(first[name].samples - ref.samples)))
        print(f"{name:26s} {wall:7.3f} s  {per[name]:6.2f} ns/lane-step  "
              f"points bitwise equal to GearPair: {same} (max dev {dev:.1e}; kernel path "
              f"{models[name].kernel.kernel_path})")
    if "UserModel (one form)" in per:
        ratio = per["UserModel (one form)"] / per["GearPair"]
        print(f"one-form UserModel / GearPair: {ratio:.3f}")
        if "UserModel (lane-form)" in per:
            print(f"one-form UserModel inlined / GearPair: "
                  f"{per['UserModel (lane-form)'] / per['GearPair']:.3f}")
        if "UserModel (legacy plain)" in per:
            print(f"legacy UserModel / GearPair: "
                  f"{per['UserModel (legacy plain)'] / per['GearPair']:.2f}")
        if a.write:
            same = np.array_equal(first["UserModel (one form)"].samples, ref.samples,
                                  equal_nan=True)
            results.record(
                "user-model", "one-form UserModel within 1.3x of GearPair (ns per lane-step)",
                f"{ratio:.3f}x ({per['UserModel (one form)']:.2f} vs {per['GearPair']:.2f} ns "
                f"per lane-step, {a.points} points, median of {a.repeat}, {threads} threads); "
                f"points bitwise equal: {same}", results.against(ratio, 1.3),
                f".venv/bin/python bench/user_model.py --repeat {a.repeat} --write")


if __name__ == "__main__":
    main()
