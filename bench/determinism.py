"""Reproducer: are the reproduction's continued sweeps bitwise the same from run to run?

Runs the continued sweeps of the paper's eleven distinct figure cases (consistent
interpretation, ``--num`` Omega points each, up and down, all together as in
``geardyn reproduce``; the Lyapunov exponents are left out) in ``--runs`` fresh processes
and compares every variable bit for bit against the first run, and against a run on one numba
thread. On 2026-12-02 (session 10) this found Fig. 3's upward sweep differing between runs on
2 threads (from its 41st point: other transients, Poincare points, periods), with the kernels
of both ``ed920c2`` and its successor; one thread gave the same result twice, and so did one
of three 2-thread runs. The cause (session 11): a worker's second lane-form pass continued
lane 0's chain (Fig. 3 up, points 1-63) a second time from slots that had held no lane, in the
other worker too, and the two runs raced on the points' outputs (one run's ``converged`` flag
cut the other's transient short). Fixed in the sweep template (``_fused_run``); since then
every run here is bitwise equal to the first and to the 1-thread run.

    .venv/bin/python bench/determinism.py [--num 150] [--runs 3]
"""

from __future__ import annotations

import argparse
import os
import pickle
import subprocess
import sys
import tempfile

import numpy as np

CASES = "fig3,fig4,fig5,fig9,fig11,fig13,fig14,fig15a,fig15b,fig15c,fig15d"


def one(num: int, path: str) -> None:
    import geardyn.reproduction.runner as runner
    from geardyn.reproduction.cases import get_case

    def no_lyapunov(model, values, y0, need, *args, **kwargs):
        return np.full(len(values), np.nan), np.full(len(values), np.nan)

    runner.branch_lyapunov = no_lyapunov
    tasks = [(get_case(c), "consistent", d) for c in CASES.split(",") for d in ("up", "down")]
    out = runner._sweeps(tasks, runner.ReproductionSettings(num=num))
    data = {f"{c.name} {d}": {v: ds[v].values for v in ds.data_vars}
            for (c, _, d), ds in zip(tasks, out, strict=True)}
    with open(path, "wb") as fh:
        pickle.dump(data, fh)


def differences(a: dict, b: dict) -> list[str]:
    out = []
    for key in a:
        bad = [v for v in a[key] if not np.array_equal(
            a[key][v], b[key][v], equal_nan=a[key][v].dtype.kind == "f")]
        if bad:
            first = np.flatnonzero(np.any(np.atleast_2d(
                a[key]["transient_periods"] != b[key]["transient_periods"]), axis=0))
            out.append(f"{key}: {', '.join(bad)} (transients differ at points {first[:5]})")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--num", type=int, default=150)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--one", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(args.num, args.one)
        return 0
    tmp = tempfile.mkdtemp()
    results = {}
    for name, threads in [(f"run {i + 1}", None) for i in range(args.runs)] + [("1 thread", 1)]:
        env = dict(os.environ)
        if threads:
            env["NUMBA_NUM_THREADS"] = str(threads)
        path = os.path.join(tmp, name.replace(" ", "_") + ".pk")
        subprocess.run([sys.executable, __file__, "--num", str(args.num), "--one", path],
                       check=True, env=env)
        with open(path, "rb") as fh:
            results[name] = pickle.load(fh)
    ref = results["run 1"]
    same = True
    for name, res in results.items():
        diff = differences(ref, res)
        same &= not diff
        print(f"{name}: " + ("bitwise equal to run 1" if not diff else "; ".join(diff)))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
