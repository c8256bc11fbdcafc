"""Cost of a located edge crossing alone, old step core against new in one run (issue 11).

Records, for a few lanes of a workload, every grid step that the sweep's side test hands to the
split path (start state, trial end, sides, end events, graze flags), by a one-lane stepping loop
that mirrors the trajectory kernel; then replays exactly those calls of ``_split_step`` many
times, for the old revision's step core (``--old``) and the working tree's, alternating, and
reports the median over the rounds (CPU time of this process, so that other processes on a
shared machine do not count; the calls made without reference counting, as the kernels make
them): ns per split call, ns per located crossing (crossings the
calls located), the working tree's ns per call of the calls with an edge flagged as a possible
graze and of the others, and, for scale, ns per scalar evaluation of the model's ``rhs`` and
``events``.
The largest difference of the states after the split, old against new, is printed too (the
located crossing moves by round-off, not more).

    .venv/bin/python bench/crossing.py [--rounds 7] [--old REV] [--lanes 16]
"""

from __future__ import annotations

import argparse
import inspect
import math
import statistics
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

import geardyn
from geardyn.core.plan import lane_steps_per_period
from geardyn.solvers import kernels as kmod

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import _results as results  # noqa: E402
from _reference_step import step_pieces  # noqa: E402
from kernel import old_kernels  # noqa: E402


@nb.njit(inline="always")
def load_record(r, recs_y, recs_g, y, y1, side, g1, gbuf, graze_row):
    """Recorded split call ``r`` into the split step's arguments: the state before and after
    the trial step (``y``, ``y1``), the event sides, end events and the graze row."""
    for q in range(recs_y.shape[2]):
        y[q] = recs_y[r, 0, q]
        y1[q] = recs_y[r, 1, q]
    for j in range(recs_g.shape[2]):
        side[j] = int(recs_g[r, 0, j])
        g1[j] = recs_g[r, 1, j]
        gbuf[graze_row, j] = recs_g[r, 2, j]


def drivers(mod):
    """(record, replay, rhs_loop) njit functions bound to a kernel module's step core."""
    rhs, events = mod.rhs, mod.events
    split, keep, leaves = mod._split_step, mod._keep_start, mod._leaves_side
    if hasattr(mod, "_rk4"):  # a step core that had its own one-step RK4 (old kernels)
        rk4 = mod._rk4
    else:  # the kernels' RK4 (_rk4_stages), wrapped on the test side
        piece = step_pieces(mod).rk4

        @nb.njit(inline="always")
        def rk4(t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, k4, tmp, out, have_k1):
            piece(t, y, h, p, s0, c0, s1, c1, s2, c2, k1, k2, k3, tmp, out)
    phase_table, event_buffer, graze_row = mod.phase_table, mod.event_buffer, mod.GRAZE_ROW
    # the split takes the step's start and end phase (sin, cos) from the caller since the
    # session-15 step core; before, it computed them (libm)
    takes_phase = "sa" in inspect.signature(split.py_func).parameters
    if takes_phase:
        @nb.njit(inline="always")
        def split_call(i, y, y1, p, h, omega, n_per, ph, side, g1, ncross, work, ybuf, gbuf):
            return split(i, 0.0, y, y1, p, h, omega, n_per, ph[0], ph[1], ph[2], ph[3], side,
                         g1, ncross, work, ybuf, gbuf)
    else:
        @nb.njit(inline="always")
        def split_call(i, y, y1, p, h, omega, n_per, ph, side, g1, ncross, work, ybuf, gbuf):
            return split(i, 0.0, y, y1, p, h, omega, n_per, side, g1, ncross, work, ybuf, gbuf)

    @nb.njit
    def record(p, y0, h, omega, n_per, n_skip, n_steps, n_ev, recs_y, recs_g, recs_i,
               recs_ph):
        """Integrate one lane; record the inputs of every split call after n_skip steps."""
        ns = y0.size
        s_tab, c_tab = phase_table(n_per, True)
        y = y0.copy()
        y1 = np.zeros(ns)
        work = np.zeros((9, ns))
        ybuf = np.zeros(ns)
        gbuf = event_buffer(1, n_ev)
        G = np.zeros((1, n_ev))
        SIDE = np.ones((1, n_ev), np.int64)
        ncross = np.zeros(n_ev, np.int64)
        active = np.ones(1, np.bool_)
        events(0.0, y, G[0], p, s_tab[0], c_tab[0])
        for j in range(n_ev):
            SIDE[0, j] = 1 if G[0, j] > 0.0 else -1
        n = 0
        ph = np.zeros(4)
        for i in range(n_steps):
            j0 = 2 * (i % n_per)
            ph[0], ph[1], ph[2], ph[3] = s_tab[j0], c_tab[j0], s_tab[j0 + 2], c_tab[j0 + 2]
            rk4(i * h, y, h, p, s_tab[j0], c_tab[j0], s_tab[j0 + 1], c_tab[j0 + 1],
                s_tab[j0 + 2], c_tab[j0 + 2], work[0], work[1], work[2], work[3], work[4], y1,
                False)
            keep(i, 1, active, G, gbuf)
            events((i + 1) * h, y1, G[0], p, s_tab[j0 + 2], c_tab[j0 + 2])
            if leaves(i, 0, G, SIDE, True, gbuf):
                if i >= n_skip and n < recs_i.shape[0]:
                    recs_i[n] = i
                    recs_y[n, 0] = y
                    recs_y[n, 1] = y1
                    for j in range(n_ev):
                        recs_g[n, 0, j] = SIDE[0, j]
                        recs_g[n, 1, j] = G[0, j]
                        recs_g[n, 2, j] = gbuf[graze_row, j]
                    recs_ph[n] = ph
                    n += 1
                split_call(i, y, y1, p, h, omega, n_per, ph, SIDE[0], G[0], ncross, work, ybuf,
                           gbuf)
            else:
                y[:] = y1
        return n

    @nb.njit(_nrt=False)
    def replay_calls(P, H, OM, NPER, lane, recs_i, recs_y, recs_g, recs_ph, n_rep, out, y, y1,
                     side, g1, ncross, work, ybuf, gbuf):
        """The split calls of :func:`replay`, without reference counting, as the kernels call
        the split (their ``_finish_flagged``, ``_lyap_flagged``: ``_nrt=False``); with it, the
        views passed (``P[k]``, ``recs_ph[r]``) cost four atomic counter updates a call, about
        85 ns here, which the kernels do not pay."""
        ns = recs_y.shape[2]
        unres = 0
        for _ in range(n_rep):
            for r in range(recs_i.size):
                k = lane[r]
                load_record(r, recs_y, recs_g, y, y1, side, g1, gbuf, graze_row)
                unres += split_call(recs_i[r], y, y1, P[k], H[k], OM[k], NPER[k], recs_ph[r],
                                    side, g1, ncross, work, ybuf, gbuf)
                for q in range(ns):
                    out[r, q] = y[q]
        return unres

    @nb.njit
    def replay(P, H, OM, NPER, lane, recs_i, recs_y, recs_g, recs_ph, n_rep, out):
        """Call the split on every record n_rep times; returns (crossings, unresolved)."""
        ns = recs_y.shape[2]
        n_ev = recs_g.shape[2]
        work = np.zeros((9, ns))
        ybuf = np.zeros(ns)
        gbuf = event_buffer(0, n_ev)
        y = np.zeros(ns)
        y1 = np.zeros(ns)
        side = np.ones(n_ev, np.int64)
        g1 = np.zeros(n_ev)
        ncross = np.zeros(n_ev, np.int64)
        unres = replay_calls(P, H, OM, NPER, lane, recs_i, recs_y, recs_g, recs_ph, n_rep, out,
                             y, y1, side, g1, ncross, work, ybuf, gbuf)
        return ncross.sum(), unres

    @nb.njit
    def rhs_loop(p, y, n, ev):
        """n evaluations of rhs (ev False; phase inputs precomputed) or of events."""
        dy = np.zeros(y.size)
        g = np.zeros(64)
        sc = np.zeros((2, 64))
        for m in range(64):
            sc[0, m] = math.sin(0.1 * m)
            sc[1, m] = math.cos(0.1 * m)
        acc = 0.0
        for m in range(n):
            y[0] += 1e-12
            if ev:
                events(0.1 * m, y, g, p, sc[0, m % 64], sc[1, m % 64])
                acc += g[0]
            else:
                rhs(0.1 * m, y, dy, p, sc[0, m % 64], sc[1, m % 64])
                acc += dy[1]
        return acc

    return record, replay, rhs_loop


def collect(model, omegas, periods_skip, periods, n_ev, per_lane, record):
    P = model.lane_params("Omega", omegas)
    nper = lane_steps_per_period(model, P)
    H = 2 * np.pi / omegas / nper
    ns = model.initial_state().size
    ri, ry, rg, rph, lane = [], [], [], [], []
    for k in range(len(omegas)):
        recs_y = np.zeros((per_lane, 2, ns))
        recs_g = np.zeros((per_lane, 3, n_ev))
        recs_i = np.zeros(per_lane, np.int64)
        recs_ph = np.zeros((per_lane, 4))
        n = record(P[k], model.initial_state(), H[k], omegas[k], int(nper[k]),
                   periods_skip * int(nper[k]), (periods_skip + periods) * int(nper[k]), n_ev,
                   recs_y, recs_g, recs_i, recs_ph)
        ri.append(recs_i[:n])
        ry.append(recs_y[:n])
        rg.append(recs_g[:n])
        rph.append(recs_ph[:n])
        lane.append(np.full(n, k))
    return (P, H, omegas, nper.astype(np.int64), np.concatenate(lane), np.concatenate(ri),
            np.concatenate(ry), np.concatenate(rg), np.concatenate(rph))


def by_kind(replay, data, n_rep: int, rounds: int) -> dict[str, float]:
    """ns per split call (median of ``rounds``) of the recorded calls with an edge flagged as a
    possible graze and of the others (a crossing only where an end's side differs)."""
    graze = np.any(data[7][:, 2] != 0.0, axis=1)
    out = {}
    for kind, sel in (("graze-flagged", graze), ("not graze-flagged", ~graze)):
        idx = np.flatnonzero(sel)
        if idx.size == 0:
            continue
        sub = [*data[:4], *(np.ascontiguousarray(a[idx]) for a in data[4:9])]
        res = np.zeros((idx.size, data[6].shape[2]))
        reps = max(1, n_rep * data[5].size // idx.size // 2)
        times = []
        for _ in range(rounds):
            t = time.process_time()
            replay(*sub, reps, res)
            times.append(time.process_time() - t)
        out[kind] = statistics.median(times) / (idx.size * reps) * 1e9
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--old", default="e8ac560")
    ap.add_argument("--lanes", type=int, default=16)
    ap.add_argument("--write", action="store_true",
                    help="record the figure in bench/RESULTS.md's current-figures table")
    args = ap.parse_args()
    located = {}
    cases = [
        ("reduced CATT, paper (xi 0.05), default steps",
         geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)),
         np.linspace(0.3, 4.0, args.lanes)),
        ("gear pair (zeta 0.05, kappa 0.2, Fm 0.1, Fa 0.2)",
         geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2),
         np.linspace(0.2, 3.0, args.lanes)),
    ]
    print(f"# old step core {args.old}, new: working tree; median of {args.rounds} rounds")
    print("| case | core | split calls | crossings | ns/call | ns/located crossing "
          "| unresolved |")
    print("|---|---|---|---|---|---|---|")
    for name, model, omegas in cases:
        n_ev = model.n_events
        mods = {"old": old_kernels(model.kernel, args.old), "new": kmod.kernels_for(model.kernel)}
        drv = {k: drivers(m) for k, m in mods.items()}
        data = collect(model, omegas, 100, 20, n_ev, 4000, drv["new"][0])
        n_rec = data[5].size
        grazing = int(np.sum(np.any(data[7][:, 2] != 0.0, axis=1)))
        n_rep = max(1, 200_000 // max(n_rec, 1))
        outs = {k: np.zeros((n_rec, data[6].shape[2])) for k in mods}
        times = {k: [] for k in mods}
        trhs = {k: [] for k in ("rhs", "events")}
        res = {}
        y = model.initial_state().astype(float)
        for k in mods:  # compile
            drv[k][1](*data[:9], 1, outs[k])
            drv[k][2](data[0][0], y.copy(), 10, False)
            drv[k][2](data[0][0], y.copy(), 10, True)
        for _ in range(args.rounds):
            for k in mods:
                t = time.process_time()
                res[k] = drv[k][1](*data[:9], n_rep, outs[k])
                times[k].append(time.process_time() - t)
            for ev, key in ((False, "rhs"), (True, "events")):
                t = time.process_time()
                drv["new"][2](data[0][0], y.copy(), 100_000, ev)
                trhs[key].append(time.process_time() - t)
        for k in mods:
            t = statistics.median(times[k])
            n_cross = int(res[k][0])
            print(f"| {name} | {k} | {n_rec} | {n_cross // n_rep} | "
                  f"{t / (n_rec * n_rep) * 1e9:.0f} | {t / max(n_cross, 1) * 1e9:.0f} | "
                  f"{int(res[k][1]) // n_rep} |")
        located[name.split(",")[0].split(" (")[0]] = (
            statistics.median(times["new"]) / max(int(res["new"][0]), 1) * 1e9)
        ratio = statistics.median(times["new"]) / statistics.median(times["old"])
        diff = np.max(np.abs(outs["new"] - outs["old"])) / np.max(np.abs(outs["old"]))
        t_rhs, t_ev = (statistics.median(trhs[key]) / 100_000 * 1e9 for key in trhs)
        print(f"| {name} | new/old | | | {ratio:.3f} | | |")
        print(f"|  {grazing} of the {n_rec} calls have an edge flagged as a possible graze |")
        print("|  new, by kind: " + "; ".join(
            f"{kind} {ns:.0f} ns/call" for kind, ns in by_kind(drv["new"][1], data, n_rep,
                                                               args.rounds).items()) + " |")
        print(f"|  scale: one scalar rhs {t_rhs:.1f} ns, one events {t_ev:.1f} ns; max rel. "
              f"state difference after the split, new - old: {diff:.1e} |")
    if args.write:
        results.record(
            "crossing", "located crossing <= 100 ns",
            "; ".join(f"{v:.0f} ns {k}" for k, v in located.items())
            + f" (replayed split calls, CPU, median of {args.rounds} rounds)",
            results.against(max(located.values()), 100.0),
            f".venv/bin/python bench/crossing.py --old {args.old} --rounds {args.rounds} --write")


if __name__ == "__main__":
    main()
