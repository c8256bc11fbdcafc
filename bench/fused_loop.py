"""The sweep kernel's fused step loop alone (``_fused_steps``), in ns per slot-step, with parts
of it taken out: what each part costs, and what is vectorised.

One block of 64 slots of the paper's device (xi = 0.05; 64 Omega of [0.1, 4], 19 step counts,
each slot its own phase increments), every slot active and sampling, the loop called ``--steps``
times by a driver compiled like the kernel's (``noalias`` arrays, no reference counting), one
thread; the variants' calls alternate, median of ``--repeat`` (CPU time of this process, so
that other processes on a shared machine count as little as possible). Nothing out of line runs: a
flagged slot keeps its state (the loop's cost does not depend on the values), so the numbers
are a floor for the loop, not a model of a sweep. A variant is the generated kernel's source
with lines replaced (checked, so a template change that moves them fails loudly):

``base``: the loop as it is; ``nostats``: without the observables and statistics;
``noscreen``: without the side test and graze screen (nothing flagged); ``nobook``: without the
health check and due test; ``fission``: the statistics in a loop of their own before the
step loop; ``phasefuse``: the phase rotations in the step loop (no loop of their own);
``alwaysout``: the out-of-line call at every block step; ``screenonly``: the screen
computed and stored, nothing flagged; ``nograze`` (with edge location): the graze screen off,
only a side left at a step's end flagged; ``nosplit``: a flagged step committed, its
crossings counted at its end (no split); ``loopcommit`` (with ``nosplit``): that commit in
the loop, none out of line (these five for bench/fused_insitu.py, where the out-of-line path
runs);
``norotate``: the slots' phase rotations left out (wrong phases, the loads and stores kept);
``nochain``: the RK4 stages made independent of
each other (wrong results, the same operations: is the loop latency-bound?); ``+``-joined
names combine them. ``--gear-pair``: bench/peers.py's gear pair instead of the paper's device.
``--form load``: the device with the load fluctuating (Fig. 13's B1 = B2 = 100 N m, Lambda =
0.1) in the lane form FORM_LOAD; ``--form general``: those lanes in FORM_GENERAL.

``--asm`` counts the zmm / ymm instructions of the driver and, of its hot loop (the loop with
the most zmm instructions: the fused loop's vector body), the instructions, the zmm ones, the
memory operands (loads and stores), the calls and each opcode (``--asm-ops``), so that two
versions of a model's code can be compared instruction by instruction where timings are noisy.

    .venv/bin/python bench/fused_loop.py [--variants base,nostats,noscreen] [--steps 20000]
                                         [--repeat 9] [--asm [--asm-ops]] [--check]
                                         [--form quiet|load|general]

``--check``: whether each variant leaves the block's arrays (state, phase, events, statistics)
bitwise as the first variant does after ``--steps`` loop calls (an exact rewrite: True).

The vector width is geardyn's (``GEARDYN_SIMD_WIDTH``, see ``geardyn._jit_target``), the
driver's too (compiled with the kernels' pipeline).
"""

from __future__ import annotations

import argparse
import collections
import importlib.util
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numba as nb
import numpy as np

import geardyn
from geardyn.core.plan import lane_steps_per_period
from geardyn.solvers.ensemble import _phase_tables
from geardyn.solvers.kernels import kernels_for

#: variant part -> (line of the generated kernel, its replacement)
EDITS = {
    "nostats": [("        o = _observe_l(t0b + st * h, y, PT, k, SE[k], CE[k], form)\n", ""),
                ("        _t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, _t_like(GS, k, g1), o, pend)\n",
                 "")],
    "noscreen": [("        hit = _t_screen(g1, GS, GP, SIDE, GR, k, locate)\n",
                  "        hit = False\n")],
    "nobook": [("        due = act & (((ph1 == 0) & (not _t_healthy(y1, bound))) | "
                "(st1 >= DUE[k]))\n", "        due = False\n")],
    # the statistics in a loop of their own before the step loop (the loop-fission layout; the
    # events from GS, the state from Y, the phase from SE, CE: the step's start)
    "fission": [("        o = _observe_l(t0b + st * h, y, PT, k, SE[k], CE[k], form)\n"
                 "        _t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, _t_like(GS, k, g1), o, pend)\n",
                 ""),
                ("    n_flag = 0\n    n_out = 0\n",
                 "    for k in range(nl):\n"
                 "        pend = STAT[k] & ACT[k]\n"
                 "        o = _observe_l(T0B[k] + STEP[k] * HB[k], _t_load(Y, k), PT, k, SE[k], "
                 "CE[k], form)\n"
                 "        _t_stats(GMIN, GMAX, OMAX, OMIN, OSQ, k, _t_like(GS, k, "
                 "_events_l(0.0, _t_load(Y, k), PT, k, SE[k], CE[k])), o, pend)\n"
                 "    n_flag = 0\n    n_out = 0\n")],
    # the slots' phase rotations left out (the phase at the step's start used throughout:
    # wrong results, the loads and stores kept): what rotating a phase per slot costs
    "norotate": [("        sb, cb = phase_rotate(s0, c0, AH[k], BH[k])\n"
                  "        se, ce = phase_rotate(s0, c0, AD[k], BD[k])\n",
                  "        sb, cb = s0, c0\n        se, ce = s0, c0\n")],
    # the phase rotations in the step loop (no loop of their own, no rows SB, CB, SN, CN;
    # exact: the same arithmetic)
    "phasefuse": [("    for k in range(nl):\n        s0 = SE[k]\n        c0 = CE[k]\n"
                   "        sb, cb = phase_rotate(s0, c0, AH[k], BH[k])\n"
                   "        se, ce = phase_rotate(s0, c0, AD[k], BD[k])\n"
                   "        end = PHASE[k] + 1 == NPER[k]  # the period's end, as in the table\n"
                   "        SB[k] = sb\n        CB[k] = cb\n        SN[k] = 0.0 if end else se\n"
                   "        CN[k] = 1.0 if end else ce\n", ""),
                  ("        sb = SB[k]\n        cb = CB[k]\n        se = SN[k]\n"
                   "        ce = CN[k]\n",
                   "        s0 = SE[k]\n        c0 = CE[k]\n"
                   "        sb, cb = phase_rotate(s0, c0, AH[k], BH[k])\n"
                   "        se, ce = phase_rotate(s0, c0, AD[k], BD[k])\n"
                   "        end = ph + 1 == NPER[k]\n"
                   "        se = 0.0 if end else se\n        ce = 1.0 if end else ce\n")],
    # edge location (bench/fused_insitu.py --edges): the graze screen off (only a side left at
    # the step's end is flagged; grazes missed): what the graze flags cost, false alarms included
    "nograze": [("        hit = _t_screen(g1, GS, GP, SIDE, GR, k, locate)\n",
                 "        hit = _t_screen(g1, GS, GP, SIDE, GR, k, False)\n")],
    # the side test and graze screen computed (the events' history and graze flags stored),
    # nothing flagged: the screen's cost in the loop (with noscreen: what flagging costs)
    "screenonly": [("        hit = _t_screen(g1, GS, GP, SIDE, GR, k, locate)\n",
                    "        hit = _t_screen(g1, GS, GP, SIDE, GR, k, locate) & False\n")],
    # the out-of-line call made at every block step (with noscreen: what a call costs where
    # it has nothing or little to do)
    "alwaysout": [("        if n_out > 0:\n", "        if n_out >= 0:\n")],
    # a flagged step committed, its crossings counted at its end (no split): what the split
    # costs beyond the out-of-line handling of a flagged slot
    "nosplit": [("                          locate, ncross, unresolved, ys, y1s, sides, g1s, "
                 "work, ybuf, gbuf,\n",
                 "                          False, ncross, unresolved, ys, y1s, sides, g1s, "
                 "work, ybuf, gbuf,\n")],
    # (with nosplit) a flagged slot's trial step committed in the loop, not out of line: the
    # out-of-line path writes no state the next loop step loads as a vector (a store that
    # cannot be forwarded to the wider load)
    "loopcommit": [("        _t_store(Y, k, y1, y, act & (not hit))\n",
                    "        _t_store(Y, k, y1, y, act)\n"),
                   ("                NCROSS[lane, j] += 1\n        for q in range(ns):\n"
                    "            Y[q, k] = Y1[q, k]\n        return\n",
                    "                NCROSS[lane, j] += 1\n        return\n")],
    "nochain": [("_t_axpy(y, hh, k1)", "_t_axpy(y, hh, y)"),
                ("_t_axpy(y, hh, k2)", "_t_axpy(y, hh, y)"),
                ("_t_axpy(y, h, k3)", "_t_axpy(y, h, y)")],
}
BLOCK = 64


def variant_module(source: str, name: str, folder: Path):
    """The kernel module with the edits of variant ``name``, imported from ``folder``."""
    text = source.replace("_CACHE = True", "_CACHE = False")  # nothing cached from a temp dir
    for part in name.split("+"):
        if part == "base":
            continue
        for old, new in EDITS[part]:
            if old not in text:
                raise SystemExit(f"variant {part}: the line {old.strip()!r} is not in the kernel")
            text = text.replace(old, new)
    mod_name = "fused_" + re.sub(r"\W", "_", name)
    path = folder / f"{mod_name}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(mod_name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[mod_name] = module
    spec.loader.exec_module(module)
    return module


def block_arrays(m, model, omegas):
    """The arguments of ``_fused_steps`` for one block of len(omegas) active slots."""
    P = np.ascontiguousarray(model.lane_params("Omega", omegas))
    nper = lane_steps_per_period(model, P)
    nw, ns, n_g, n_o = BLOCK, len(model.state_names), len(model.event_names), \
        len(model.observable_names)
    _, _, lane_tab = _phase_tables(nper)
    rot = np.array([m.phase_increments(int(n)) for n in nper]).T
    Y = np.repeat(np.asarray(model.initial_state(), float)[:, None], nw, axis=1)
    HB = 2 * np.pi / omegas / nper
    i64 = np.int64
    far = 1 << 60
    slots = (np.zeros(nw, np.bool_), np.zeros(nw, np.bool_), np.ones(nw, np.bool_),
             np.zeros(nw, np.bool_), np.arange(nw, dtype=i64), np.zeros(nw, i64),
             np.zeros(nw, i64), nper.astype(i64), lane_tab,
             HB, np.zeros(nw), np.full(nw, far, i64), np.zeros(nw, i64), np.full(nw, far, i64),
             np.full(nw, far, i64), np.zeros(nw, i64), np.zeros(nw, i64))
    G = (np.zeros(n_g * nw), np.full(n_g * nw, np.nan), np.zeros(n_g * nw), np.ones(n_g * nw))
    ST = (np.full(n_g * nw, np.inf), np.full(n_g * nw, -np.inf), np.full(n_o * nw, -np.inf),
          np.full(n_o * nw, np.inf), np.zeros(n_o * nw))
    ROT = tuple(np.ascontiguousarray(r) for r in rot)
    PH = tuple(np.zeros(nw) for _ in range(4))
    return (Y.reshape(-1), np.zeros(ns * nw), np.ascontiguousarray(P.T), np.zeros(nw),
            np.ones(nw), HB / 6.0, np.zeros(nw), G, ST, slots, ROT, PH)


def driver(m, form_name="quiet"):
    """A compiled caller of module m's fused loop in the lane form ``form_name``."""
    form = getattr(m, f"FORM_{form_name.upper()}")
    steps = m._fused_steps

    def drive(n, nv, locate, bound, Yf, Y1f, PT, SE, CE, H6, FLAG, G, ST, slots, ROT, PH):
        flagged = 0
        for _ in range(n):
            nf, _no = steps(form, nv, locate, bound, Yf, Y1f, PT, SE, CE, H6, FLAG, G, ST,
                            slots, ROT, PH)
            flagged += nf
        return flagged

    return nb.njit(_nrt=False, pipeline_class=m._JIT_NOALIAS["pipeline_class"],
                   boundscheck=False, error_model="numpy")(drive)


def hot_loop(asm: list[str]) -> list[str]:
    """The instructions of the loop with the most zmm instructions in the assembly ``asm``
    (a label and the backward jump to it)."""
    labels = {}
    spans = []
    for i, line in enumerate(asm):
        if m := re.match(r"^(\.LBB\S+):", line):
            labels[m.group(1)] = i
        elif (m := re.match(r"^\s+j\w+\s+(\.LBB\S+)", line)) and m.group(1) in labels:
            spans.append((labels[m.group(1)], i))
    if not spans:
        return []
    a, b = max(spans, key=lambda ab: sum("zmm" in s for s in asm[ab[0]:ab[1] + 1]))
    return [s.strip() for s in asm[a:b + 1]
            if s.startswith("\t") and not s.strip().startswith((".", "#"))]


def _memory(ins: str) -> bool:
    return "(" in ins and not ins.startswith(("lea", "nop"))


def opcodes(loop: list[str]) -> collections.Counter:
    """Opcode counts of ``loop``: ``{k}`` marks a masked one, ``[mem]`` a memory operand."""
    out: collections.Counter = collections.Counter()
    for ins in loop:
        op = ins.split()[0] + ("{k}" if "{%k" in ins else "") + ("[mem]" if _memory(ins) else "")
        out[op] += 1
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--variants", default="base,nostats,noscreen,nobook")
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--asm", action="store_true", help="count zmm / ymm instructions, and "
                    "the hot loop's")
    ap.add_argument("--asm-ops", action="store_true", help="with --asm: the hot loop's opcodes")
    ap.add_argument("--form", choices=("quiet", "load", "general"), default="quiet",
                    help="the lane form (load, general: the paper's device with Fig. 13's load)")
    ap.add_argument("--check", action="store_true",
                    help="compare each variant's end state bitwise with the first variant's")
    ap.add_argument("--gear-pair", action="store_true", help="bench/peers.py's gear pair "
                    "(Omega in [0.2, 3]) instead of the paper's device")
    args = ap.parse_args()
    if args.gear_pair:
        import peers

        model, omegas = peers.model(), peers.workload().omega[::6]
    else:
        load = {} if args.form == "quiet" else {"B1": "100 N m", "B2": "100 N m", "Lambda": 0.1}
        model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05, **load))
        omegas = np.linspace(0.1, 4.0, 1000)[::15]
    omegas = omegas[:BLOCK]
    source = Path(kernels_for(model.kernel).__file__).read_text()
    names = args.variants.split(",")
    print(f"# geardyn {geardyn.__version__}, numba {nb.__version__}, SIMD "
          f"{geardyn._jit_target.APPLIED.split(':')[0]}; one block of {BLOCK} slots, "
          f"{args.steps} loop calls, median of {args.repeat}")
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            m = variant_module(source, name, Path(tmp))
            d = driver(m, args.form)
            d(2, BLOCK, True, 1e6, *block_arrays(m, model, omegas))
            runs[name] = (d, m)
        times = {n: [] for n in names}
        for _ in range(args.repeat):
            for name in names:
                d, m = runs[name]
                a = block_arrays(m, model, omegas)
                t0 = time.process_time()
                d(args.steps, BLOCK, True, 1e6, *a)
                times[name].append((time.process_time() - t0) * 1e9 / (args.steps * BLOCK))
        ends = {}
        if args.check:
            for name in names:
                d, m = runs[name]
                a = block_arrays(m, model, omegas)
                d(args.steps, BLOCK, True, 1e6, *a)
                ends[name] = [np.array(x) for x in (a[0], a[3], a[4], *a[7], *a[8])]
    base = statistics.median(times[names[0]])
    for name in names:
        med = statistics.median(times[name])
        line = f"{name:32s} {med:7.2f} ns/slot-step ({med / base:.2f}x {names[0]})"
        if args.asm:
            d, _ = runs[name]
            asm = d.inspect_asm(d.signatures[0]).splitlines()
            loop = hot_loop(asm)
            line += (f"; zmm {sum('zmm' in s for s in asm)}, ymm {sum('ymm' in s for s in asm)}"
                     f" instructions; hot loop {len(loop)} instructions, zmm "
                     f"{sum('zmm' in s for s in loop)}, memory operands "
                     f"{sum(_memory(s) for s in loop)}, calls "
                     f"{sum(s.startswith('call') for s in loop)}")
            if args.asm_ops:
                line += "\n  " + ", ".join(f"{k} {v}" for k, v in sorted(opcodes(loop).items()))
        if args.check:
            same = all(np.array_equal(x, y, equal_nan=True)
                       for x, y in zip(ends[name], ends[names[0]], strict=True))
            line += f"; end state bitwise as {names[0]}'s: {same}"
        print(line)


if __name__ == "__main__":
    main()
