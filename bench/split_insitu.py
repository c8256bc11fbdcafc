"""The batched split (bench/split_block.py) inside the sweep: the paper workload
(bench/bifurcation.py's) run through a variant of the generated kernel module whose flagged
slots wait (parked) until ``--pending`` of them are flagged, then the largest multiple of
eight of them are split together, eight at a time (all of them where every running lane of
the block is parked, and before the block compacts); against the kernel as it is,
alternating in one process, CPU time of one thread, median of ``--repeat``; and whether the
two give bitwise the same dataset.

A flagged slot is parked out of line (``_slots_out``): its trial end, events and their
history, graze flags, phase and clock are kept in block rows the fused loop does not use (K1,
K2, K3, K4, TMP, G1; so the model needs n_events <= n_states) and it is made inactive, so the
fused loop leaves its state alone (it runs its lane, commits nothing and flags nothing). When
enough are parked (and before the block compacts) they are restored and split together
(``split_block``; the lanes that fall back by ``_finish_flagged``), then their bookkeeping is
done as before (``_slot_out``). The fused loop is unchanged. The wait costs the parked slots'
vector lanes in the fused loop. ``--freeze``: the fused loop itself keeps an inactive slot's
clock, phase, trial end, events' history and graze flags (selects), so that parking and
restoring a slot copies nothing (a free slot's clock then stays too). ``--nosplit``: each
variant also without any split (bench/fused_loop.py's ``nosplit``: wrong results), so that
the split's share and the parking's can be told apart.

    .venv/bin/python bench/split_insitu.py [--pending 8,4] [--repeat 5] [--points 1000]
                                           [--form quiet] [--short] [--freeze] [--nosplit]
                                           [--gear-pair]
"""

from __future__ import annotations

import argparse
import re
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
import split_block  # noqa: E402
from bifurcation import SAMPLES, TRANSIENT, device  # noqa: E402

NV = split_block.NV

SLOTS_OUT_OLD = """    gone = 0
    for m in range(n):
        if _slot_out(marked[m], G1, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
            gone += 1
    return gone
"""
SLOTS_OUT_NEW = """    gone = 0
    parked = 0
    locate = cfg[3]
    FLAG = blk[19]
    for m in range(n):
        k = marked[m]
        if locate and FLAG[k] != 0.0:
            _park(k, blk, slots)
            parked += 1
        elif _slot_out(k, G1, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
            gone += 1
    return gone + 4096 * parked
"""
RUN_OLD = """        if n_out > 0:
            gone = _slots_out(min(nl, nv), GS, SE, CE, (S_TAB, C_TAB), lanes, cfg, out, blk,
                              slots, scratch)
            if gone > 0:
                ended = True
                n_act -= gone
"""
FLUSH_CALL = """            gone = _flush(min(nl, nv), GS, SE, CE, (S_TAB, C_TAB), lanes, cfg, out,
                          blk, slots, scratch, FORCE)
            n_pend -= gone // 4096
            gone = gone % 4096
            if gone > 0:
                ended = True
                n_act -= gone
"""
RUN_NEW = """        if n_out > 0:
            gone = _slots_out(min(nl, nv), GS, SE, CE, (S_TAB, C_TAB), lanes, cfg, out, blk,
                              slots, scratch)
            n_pend += gone // 4096
            gone = gone % 4096
            if gone > 0:
                ended = True
                n_act -= gone
        if n_pend > 0 and (n_pend >= PEND_T or n_pend >= n_act):
""" + FLUSH_CALL.replace("FORCE", "n_pend >= n_act")
COMPACT_OLD = """        if nxt >= q1 and _padded(n_act) < nv:  # the queue is out"""
COMPACT_NEW = """        if n_pend > 0 and nxt >= q1 and _padded(n_act) < nv:
""" + FLUSH_CALL.replace("FORCE", "True") + COMPACT_OLD
INIT_OLD = "    n_act = np.int64(0)"
INIT_NEW = "    n_pend = np.int64(0)\n    n_act = np.int64(0)"
SCRATCH_OLD = "    scratch = (ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, marked)\n"
SCRATCH_NEW = ("    scratch = (ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, marked,\n"
               "               np.zeros(SB_ROWS * 8), np.zeros((P.shape[1], 8)))\n")
UNPACK_OLD = "    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf, _ = scratch\n"
UNPACK_NEW = "    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf = scratch[:10]\n"

BLK = ("(R, D, Y, Y1, K1, K2, K3, K4, TMP, PT, SC, PH6, PH, TT, GP, GS, G1, GR, SIDE, FLAG, "
       "GMIN, GMAX, O, OMAX, OMIN, OSQ, HW3, FL, HW) = blk")
SLOTS = ("(STAT, MSK, ACT, END, LANE, STEP, PHASE, NPER, OFF, HB, T0B, n_end, n_tr, "
         "next_sample, DUE, n_stat, n_ring) = slots")


#: ``--freeze``: the fused loop leaves an inactive slot's clock, phase, trial end, events'
#: history and graze flags as they are (selects), so that parking copies nothing.
FREEZE_LOOP = [
    ("        hit = _t_screen(g1, GS, GP, SIDE, GR, k, locate)\n",
     "        hit = _t_screen_act(g1, GS, GP, SIDE, GR, k, locate, ACT[k])\n"),
    ("        _t_store(Y1, k, y1, y1, True)\n",
     "        _t_store(Y1, k, y1, _t_load(Y1, k), act)\n"),
    ("        SE[k] = se\n        CE[k] = ce\n",
     "        SE[k] = _pick(act, se, SE[k])\n        CE[k] = _pick(act, ce, CE[k])\n"),
    ("        STEP[k] = st1\n        PHASE[k] = ph1\n",
     "        STEP[k] = _pick(act, st1, st)\n        PHASE[k] = _pick(act, ph1, ph)\n"),
]
FREEZE_SCREEN = '''

def _t_screen_act(g1, GS, GP, SIDE, GR, k, locate, act):
    """_t_screen, the history and graze flags kept where not ``act``."""


def _ov_t_screen_act(g1, GS, GP, SIDE, GR, k, locate, act):
    lines = ["hit = False"]
    for j in range(len(g1)):
        gs, gp, gr = _ix(GS, "GS", j), _ix(GP, "GP", j), _ix(GR, "GR", j)
        lines += ["g0 = " + gs,
                  f"gr, fl = screen_grid(g1[{j}], {_ix(SIDE, 'SIDE', j)}, g0, {gp}, locate)",
                  f"{gr} = _pick(act, _pick(gr, 1.0, 0.0), {gr})",
                  f"{gp} = _pick(act, g0, {gp})", f"{gs} = _pick(act, g1[{j}], g0)",
                  "hit = hit | fl"]
    return _tuple_source("g1, GS, GP, SIDE, GR, k, locate, act", [*lines, "return hit"],
                         {"screen_grid": screen_grid, "_pick": _pick})


nb.extending.overload(_t_screen_act, inline="always")(_ov_t_screen_act)
'''


def helpers(rows: dict, small: float, pending: int, freeze: bool = False) -> str:
    """The park and flush functions (text for the kernel module)."""

    def r(name):
        return rows[name][0] * NV

    return f'''
PEND_T = {pending}
FB_ROW = {r("FB")}


@nb.njit(inline="always", **_JIT)
def _park(k, blk, slots):
    """Park flagged slot k: its trial end, events, history, graze flags, phase, clock kept."""
    {BLK}
    {SLOTS}
    if {freeze}:
        ACT[k] = False
        SC[2, k] = 1.0
        return
    for q in range(Y1.shape[0]):
        K1[q, k] = Y1[q, k]
    for j in range(GS.shape[0]):
        G1[j, k] = GS[j, k]
        K2[j, k] = GP[j, k]
        K3[j, k] = GR[j, k]
    TMP[0, k] = PH[2][k]
    TMP[1, k] = PH[3][k]
    K4[0, k] = float(STEP[k])
    K4[1, k] = float(PHASE[k])
    ACT[k] = False
    SC[2, k] = 1.0


@nb.njit(_nrt=False, **_JIT)
def _flush(nl, GSx, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch, force):
    """Restore the parked slots (all where ``force``, else a multiple of eight: the rest stay
    parked), split them together (eight at a time), do their bookkeeping (_slot_out); returns
    the number of lanes that ended + 4096 x the number of slots restored."""
    {BLK}
    {SLOTS}
    P, Y0, H, OMEGA, T0, n_transient, n_transient_max, sample_every = lanes
    ncross = out[5]
    unresolved = out[9]
    ys, y1s, dbuf, sides, g1s, gb, ob, work, ybuf, gbuf = scratch[:10]
    marked = scratch[10]
    W = scratch[11]
    PTB = scratch[12]
    S_TAB, C_TAB = TABS
    ns = Y.shape[0]
    ne = GS.shape[0]
    n = 0
    n_all = 0
    for k in range(nl):
        n_all += 1 if SC[2, k] != 0.0 else 0
    take = n_all if force else n_all // 8 * 8
    for k in range(nl):
        if SC[2, k] != 0.0 and n < take:
            SC[2, k] = 0.0
            ACT[k] = True
            marked[n] = k
            n += 1
            if {freeze}:
                continue
            for q in range(ns):
                Y1[q, k] = K1[q, k]
            for j in range(ne):
                GS[j, k] = G1[j, k]
                GP[j, k] = K2[j, k]
                GR[j, k] = K3[j, k]
            PH[2][k] = TMP[0, k]
            PH[3][k] = TMP[1, k]
            STEP[k] = np.int64(K4[0, k])
            PHASE[k] = np.int64(K4[1, k])
    for b0 in range(0, n, 8):
        nb_ = min(8, n - b0)
        for mm in range(8):
            k = marked[b0 + (mm if mm < nb_ else 0)]
            for q in range(ns):
                W[{r("Y")} + q * 8 + mm] = Y[q, k]
                W[{r("YT")} + q * 8 + mm] = Y1[q, k]
            for j in range(ne):
                W[{r("SD")} + j * 8 + mm] = SIDE[j, k]
                W[{r("G1")} + j * 8 + mm] = GS[j, k]
                W[{r("GR")} + j * 8 + mm] = GR[j, k]
                W[{r("NC")} + j * 8 + mm] = 0.0
            for j in range(PT.shape[0]):
                PTB[j, mm] = PT[j, k]
            i = STEP[k] - 1
            j0 = OFF[k] + 2 * (i % NPER[k])
            h = HB[k]
            wh = OMEGA[LANE[k]] * h
            W[{r("T0")} + mm] = T0B[k]
            W[{r("FI")} + mm] = float(i)
            W[{r("FI1")} + mm] = float(i + 1)
            W[{r("H")} + mm] = h
            W[{r("WH")} + mm] = wh
            W[{r("SA")} + mm] = S_TAB[j0]
            W[{r("CA")} + mm] = C_TAB[j0]
            W[{r("SE")} + mm] = S_TAB[j0 + 2]
            W[{r("CE")} + mm] = C_TAB[j0 + 2]
            W[{r("S0")} + mm] = S_TAB[j0]
            W[{r("C0")} + mm] = C_TAB[j0]
            W[{r("U")} + mm] = 0.0
            go = mm < nb_ and abs(wh) <= {small!r}
            W[{r("ACT")} + mm] = 1.0 if go else 0.0
            W[{r("FB")} + mm] = 0.0 if (go or mm >= nb_) else 1.0
        split_block(8, W, PTB)
        for mm in range(nb_):
            k = marked[b0 + mm]
            if W[{r("FB")} + mm] != 0.0:
                _finish_flagged_i(k, STEP[k] - 1, NPER, Y, Y1, GS, GR, SIDE, P, LANE, HB, T0B,
                                  OMEGA, True, ncross, unresolved, ys, y1s, sides, g1s, work,
                                  ybuf, gbuf, TABS, OFF)
            else:
                lane = LANE[k]
                for q in range(ns):
                    Y[q, k] = W[{r("Y")} + q * 8 + mm]
                for j in range(ne):
                    SIDE[j, k] = W[{r("SD")} + j * 8 + mm]
                    GS[j, k] = W[{r("G1")} + j * 8 + mm]
                    ncross[lane, j] += np.int64(W[{r("NC")} + j * 8 + mm])
    gone = 0
    for m in range(n):
        k = marked[m]
        FLAG[k] = 0.0
        if _slot_out(k, GS, SE, CE, TABS, lanes, cfg, out, blk, slots, scratch):
            gone += 1
    return gone + 4096 * n
'''


def variant_source(source: str, ns: int, ne: int, pending: int, short: bool, form: str,
                   freeze: bool = False) -> str:
    """The kernel module's text with the batched split and the parking of flagged slots."""
    text, rows = split_block.source(ns, ne, short, form)
    small = 0.1 if short else 0.8
    n_rows = max(v[0] + v[1] for v in rows.values())
    block = (
        "\n\n# ---- the batched split (bench/split_insitu.py) ----\n"
        "import math\n"
        "from geardyn.core.kernel_source import FORM_QUIET\n"
        "from geardyn.solvers._step_shared import (BRACKET_TOL, CONFIRM_TOL, GRAZE_TOL, "
        "HALLEY_TOL, _cubic_at, _cubic_coeffs, _forced, _hermite_weights, _pick)\n"
        f"SB_ROWS = {n_rows}\n" + text + helpers(rows, small, pending, freeze)
        + (FREEZE_SCREEN if freeze else ""))
    edits = [(SLOTS_OUT_OLD, SLOTS_OUT_NEW), (RUN_OLD, RUN_NEW), (COMPACT_OLD, COMPACT_NEW),
             (INIT_OLD, INIT_NEW), (SCRATCH_OLD, SCRATCH_NEW), *(FREEZE_LOOP if freeze else [])]
    out = source
    for old, new in edits:
        if out.count(old) != 1:
            raise SystemExit(f"edit not unique in the kernel: {old.strip()[:60]!r}")
        out = out.replace(old, new)
    if out.count(UNPACK_OLD) != 2:
        raise SystemExit("scratch unpacking changed")
    out = out.replace(UNPACK_OLD, UNPACK_NEW)
    # the helpers before _slots_out's definition (they call _slot_out, _finish_flagged_i: both
    # resolved as globals at compile time)
    mark = "@nb.njit(_nrt=False, **_JIT)\ndef _slots_out("
    out = out.replace(mark, block + "\n\n" + mark)
    return out


def nosplit(text: str, kind: str) -> str:
    """``text`` with no split: a flagged step committed, its crossings counted at its end
    (bench/fused_loop.py's ``nosplit``; parked slots so too, by ``_finish_flagged``)."""
    for old, new in fused_loop.EDITS["nosplit"]:
        if old not in text:
            raise SystemExit("nosplit: the kernel changed")
        text = text.replace(old, new)
    if kind != "base":
        for old, new in (("        split_block(8, W, PTB)\n",
                          "        for mm in range(8):\n            W[FB_ROW + mm] = 1.0\n"),
                         ("OMEGA, True, ncross", "OMEGA, False, ncross")):
            if text.count(old) != 1:
                raise SystemExit("nosplit: the variant changed")
            text = text.replace(old, new)
    return text


def module(text: str, name: str, folder: Path):
    text = text.replace("_CACHE = True", "_CACHE = False")
    return fused_loop.variant_module(text, "base", folder) if name == "base" else _load(
        text, name, folder)


def _load(text: str, name: str, folder: Path):
    import importlib.util
    mod_name = "splitvar_" + re.sub(r"\W", "_", name)
    path = folder / f"{mod_name}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(mod_name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[mod_name] = mod
    spec.loader.exec_module(mod)
    return mod


def same(a, b) -> bool:
    """Every data variable bitwise equal (NaN where NaN)."""
    for k in a.data_vars:
        x, y = np.asarray(a[k].values), np.asarray(b[k].values)
        if x.dtype.kind == "f":
            if not np.array_equal(x.view(np.int64) if x.dtype == np.float64 else x,
                                  y.view(np.int64) if y.dtype == np.float64 else y):
                return False
        elif not np.array_equal(x, y):
            return False
    return True


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pending", default="8,4")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--form", default="general", choices=("general", "quiet"),
                    help="the batched split's rhs lane form (quiet: FORM_QUIET, the paper "
                         "lanes' form; general: the scalar split's FORM_GENERAL)")
    ap.add_argument("--short", action="store_true",
                    help="the phase's short polynomials alone (lanes with |Omega h| > 0.1 "
                         "fall back)")
    ap.add_argument("--gear-pair", action="store_true")
    ap.add_argument("--freeze", action="store_true",
                    help="the fused loop keeps an inactive slot's clock, phase, trial end and "
                         "events (selects), so that parking a slot copies nothing")
    ap.add_argument("--nosplit", action="store_true",
                    help="each variant also without the split (a flagged step committed, its "
                         "crossings counted at its end: wrong results, for the cost split)")
    args = ap.parse_args()
    numba.set_num_threads(1)
    if args.gear_pair:
        model = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
        values = np.linspace(0.2, 3.0, args.points)
        run = geardyn.RunSettings(transient=1570.8, samples=100)
    else:
        model = device()
        values = np.linspace(0.1, 4.0, args.points)
        run = geardyn.RunSettings(transient=TRANSIENT, samples=SAMPLES)
    ns = model.initial_state().size
    ne = model.n_events
    if ne > ns:
        raise SystemExit("the parked slot's rows need n_events <= n_states")
    source = Path(kernels_for(model.kernel).__file__).read_text()
    form = {"general": "FORM_GENERAL", "quiet": "FORM_QUIET"}[args.form]
    names = ["base"] + [f"pending{p}" for p in args.pending.split(",")]
    if args.nosplit:
        names += [f"{n}+nosplit" for n in names]
    mods, res = {}, {}
    t0 = time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            kind = name.split("+")[0]
            text = source if kind == "base" else variant_source(
                source, ns, ne, int(kind[7:]), args.short, form, args.freeze)
            if name.endswith("+nosplit"):
                text = nosplit(text, kind)
            mods[name] = module(text, name, Path(tmp))
            ens.kernels_for = lambda kernel, m=mods[name]: m
            geardyn.bifurcation(model, "Omega", values[:8], run=geardyn.RunSettings(
                transient=20.0, samples=2))
        print(f"# compiled in {time.process_time() - t0:.0f} s CPU", flush=True)
        times = {name: [] for name in names}
        for _ in range(args.repeat):
            for name in names:
                ens.kernels_for = lambda kernel, m=mods[name]: m
                t = time.process_time()
                res[name] = geardyn.bifurcation(model, "Omega", values, run=run)
                times[name].append(time.process_time() - t)
    base = statistics.median(times["base"])
    print(f"# {'gear pair' if args.gear_pair else 'paper workload'}, {args.points} points, "
          f"batched split form {args.form}{', short phase' if args.short else ''}, CPU s of "
          f"one thread, median of {args.repeat}")
    for name in names:
        med = statistics.median(times[name])
        print(f"{name:12s} {med:.3f} s ({med / base:.3f}x base; "
              f"{', '.join(f'{t:.2f}' for t in times[name])}); bitwise base: "
              f"{same(res[name], res['base'])}", flush=True)


if __name__ == "__main__":
    main()
