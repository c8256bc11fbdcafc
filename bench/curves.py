"""Benchmark of two-parameter bifurcation curves (:func:`geardyn.curve`) of the gear pair, warm.

Two curves, each timed ``--repeat`` times after one warm-up call (kernels compiled and cached),
the median reported with its points and the time per point:

* fold: the softening gear pair (zeta 0.05, Fm 0.1, kappa 0) from its first fold in Omega at
  Fa = 0.05, in Fa down round the cusp and back up to the other fold (about 100 points);
* period doubling: the gear pair kept in contact (zeta 0.02, Fm 1, Fa 0, kappa 0.3: the damped
  Mathieu equation) from the principal zone's left edge in kappa round its tip to the right edge.

The speed target is a 100-point curve in <= 10 s warm: the figure recorded is the slower
curve's time per point x 100.

    .venv/bin/python bench/curves.py [--repeat 5] [--write]
"""

from __future__ import annotations

import argparse
import statistics
import time

import _results as results
import geardyn

TARGET_S = 10.0


def cases() -> list[tuple[str, geardyn.Model, object, int, str, float]]:
    fold_model = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05, kappa=0.0)
    fold_branch = geardyn.continuation(fold_model, "Omega", 0.6, 1.4)
    pd_model = geardyn.GearPair(zeta=0.02, Fm=1.0, Fa=0.0, kappa=0.3)
    pd_branch = geardyn.continuation(pd_model, "Omega", 1.6, 2.4)
    first_fold = list(fold_branch["bifurcation_kind"].values).index("fold")
    return [("fold", fold_model, fold_branch, first_fold, "Fa", 0.0),
            ("period doubling", pd_model, pd_branch, 0, "kappa", 0.0)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--write", action="store_true",
                    help="record the figure in bench/RESULTS.md's current-figures table")
    args = ap.parse_args()
    rows = []
    for name, model, branch, index, y, y_stop in cases():
        geardyn.curve(model, branch, index, y, y_stop)  # warm-up
        walls = []
        for _ in range(args.repeat):
            t = time.perf_counter()
            c = geardyn.curve(model, branch, index, y, y_stop)
            walls.append(time.perf_counter() - t)
        wall = statistics.median(walls)
        points = c.sizes["point"]
        rows.append((name, points, wall, wall / points, c.attrs["message"],
                     c["special_kind"].values.tolist()))
        print(f"{name}: {points} points, median {wall:.3f} s ({1e3 * wall / points:.2f} ms per "
              f"point) of {args.repeat}; {c.attrs['message']}; special {rows[-1][5]}")
    per100 = 100 * max(r[3] for r in rows)
    print(f"100 points of the slower curve: {per100:.2f} s (target {TARGET_S:g} s)")
    if args.write:
        measured = "; ".join(f"{r[0]} {r[1]} points {r[2]:.2f} s ({1e3 * r[3]:.1f} ms/point)"
                             for r in rows)
        results.record(
            "curve-100", "a 100-point fold or period-doubling curve of the gear pair <= 10 s warm",
            f"{per100:.2f} s per 100 points ({measured}; medians of {args.repeat})",
            results.against(per100, TARGET_S),
            f".venv/bin/python bench/curves.py --repeat {args.repeat} --write")


if __name__ == "__main__":
    main()
