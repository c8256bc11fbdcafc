"""Design measurement: a model-independent step core that calls the model through a pointer.

Every model compiles its own copy of the step machinery that evaluates it (the split step, the
sweep's block loop, the Lyapunov and monodromy kernels) with the model's functions inlined
(``bench/compile.py``: most of a model's compile). The alternative measured here: the machinery
compiled once (cached, for every model) and the model's part compiled alone as ``numba.cfunc``
functions called through their address, which travels as an integer argument (so the cached core
holds no process-specific address).

Two measurements, each on the gear pair's equations (2 states, dead zone, forced stiffness),
the model inlined into the loop against the model called through its pointer:

* ``fused``: the sweep's fused trial step over a block of slots (state in registers, slots
  innermost), one call per grid step for the whole block;
* ``stages``: the structure-of-arrays RK4, one call per stage for the block.

At the granularity of one lane (the split step's calls of the model) the pointer costs much
more: the split step compiled once with the model called so (commit 12f11bb) made a located
crossing 1.47x (gear pair) to 1.67x (reduced CATT) dearer, ``bench/crossing.py --old``.

Both sides compute the same arithmetic; the results must be bitwise equal (printed). The last
lines time the cold compile of the model's part alone and check that the core, compiled in this
process for one model, serves a second model without another compile.

    .venv/bin/python bench/indirect_call.py [--repeat 7] [--write]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np
from llvmlite import ir
from numba import carray, types
from numba.extending import intrinsic

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _results as results  # noqa: E402

F8P = types.CPointer(types.float64)
#: The model's block function: (Y, Y1 or DY, P, leading dimension, slots, S, C, h) -> None.
BLOCK_SIG = types.void(F8P, F8P, F8P, types.intp, types.intp, F8P, F8P, types.float64)


def _data(context, builder, ty, value):
    return context.make_array(ty)(context, builder, value).data


@intrinsic
def call_block(typingctx, addr, Y, OUT, P, nl, S, C, h):
    """Call the block function at address ``addr`` (int64) with the arrays' data pointers."""
    sig = types.void(addr, Y, OUT, P, nl, S, C, h)

    def codegen(context, builder, signature, args):
        a, y, out, p, n, s, c, hh = args
        ty = signature.args
        dp = ir.DoubleType().as_pointer()
        ip = context.get_value_type(types.intp)
        fnty = ir.FunctionType(ir.VoidType(), [dp, dp, dp, ip, ip, dp, dp, ir.DoubleType()])
        ld = builder.extract_value(context.make_array(ty[1])(context, builder, y).shape, 1)
        builder.call(builder.inttoptr(a, fnty.as_pointer()),
                     [_data(context, builder, ty[1], y), _data(context, builder, ty[2], out),
                      _data(context, builder, ty[3], p), ld, n,
                      _data(context, builder, ty[5], s), _data(context, builder, ty[6], c), hh])
        return context.get_dummy_value()

    return sig, codegen


# ----------------------------------------------------------------------------- the model
@nb.njit(inline="always")
def _dead_zone(x, b):
    return x - b if x > b else (x + b if x < -b else 0.0)


@nb.njit(inline="always")
def _rhs(y0, y1, zeta, eps, f, b, s, c):
    return y1, f + 0.3 * s - 2.0 * zeta * y1 - (1.0 + eps * c) * _dead_zone(y0, b)


@nb.njit(inline="always")
def _trial(Y, Y1, P, nl, S, C, h):
    for k in range(nl):
        y0, y1 = Y[0, k], Y[1, k]
        zeta, eps, f, b, s, c = P[0, k], P[1, k], P[2, k], P[3, k], S[k], C[k]
        a0, a1 = _rhs(y0, y1, zeta, eps, f, b, s, c)
        b0, b1 = _rhs(y0 + 0.5 * h * a0, y1 + 0.5 * h * a1, zeta, eps, f, b, s, c)
        c0, c1 = _rhs(y0 + 0.5 * h * b0, y1 + 0.5 * h * b1, zeta, eps, f, b, s, c)
        d0, d1 = _rhs(y0 + h * c0, y1 + h * c1, zeta, eps, f, b, s, c)
        Y1[0, k] = y0 + h / 6 * (a0 + 2 * b0 + 2 * c0 + d0)
        Y1[1, k] = y1 + h / 6 * (a1 + 2 * b1 + 2 * c1 + d1)


@nb.njit(inline="always")
def _stage(Y, DY, P, nl, S, C):
    for k in range(nl):
        DY[0, k], DY[1, k] = _rhs(Y[0, k], Y[1, k], P[0, k], P[1, k], P[2, k], P[3, k],
                                  S[k], C[k])


def _model_part():
    """The model's compiled part (cfuncs), and the seconds its cold compile took."""
    t0 = time.process_time()

    @nb.cfunc(BLOCK_SIG, boundscheck=False, error_model="numpy")
    def trial(y, y1, p, ld, nl, s, c, h):
        _trial(carray(y, (2, ld)), carray(y1, (2, ld)), carray(p, (4, ld)), nl, carray(s, ld),
               carray(c, ld), h)

    @nb.cfunc(BLOCK_SIG, boundscheck=False, error_model="numpy")
    def stage(y, dy, p, ld, nl, s, c, h):
        _stage(carray(y, (2, ld)), carray(dy, (2, ld)), carray(p, (4, ld)), nl, carray(s, ld),
               carray(c, ld))


    return (trial, stage), time.process_time() - t0


# ----------------------------------------------------------------------------- the loops
#: The forcing phase, tabulated (the engine gathers it from a table too).
ST = np.sin(2 * np.pi * np.arange(1024) / 1024)
CT = np.cos(2 * np.pi * np.arange(1024) / 1024)

def _fused_loop(step):
    @nb.njit(boundscheck=False)
    def run(Y, P, h, n, addr):
        ns, nl = Y.shape
        Y1 = np.empty((ns, nl))
        S = np.empty(nl)
        C = np.empty(nl)
        for i in range(n):
            for k in range(nl):
                S[k] = ST[(i + k) & 1023]
                C[k] = CT[(i + k) & 1023]
            step(addr, Y, Y1, P, nl, S, C, h)
            for q in range(ns):
                for k in range(nl):
                    Y[q, k] = Y1[q, k]
    return run


def _stage_loop(stage):
    @nb.njit(boundscheck=False)
    def run(Y, P, h, n, addr):
        ns, nl = Y.shape
        K = np.empty((4, ns, nl))
        TMP = np.empty((ns, nl))
        S = np.empty(nl)
        C = np.empty(nl)
        for i in range(n):
            for k in range(nl):
                S[k] = ST[(i + k) & 1023]
                C[k] = CT[(i + k) & 1023]
            for st in range(4):
                stage(addr, Y if st == 0 else TMP, K[st], P, nl, S, C, h)
                if st == 3:
                    break
                w = h if st == 2 else 0.5 * h
                for q in range(ns):
                    for k in range(nl):
                        TMP[q, k] = Y[q, k] + w * K[st, q, k]
            for q in range(ns):
                for k in range(nl):
                    Y[q, k] += h / 6 * (K[0, q, k] + 2 * K[1, q, k] + 2 * K[2, q, k] + K[3, q, k])
    return run


@nb.njit(inline="always")
def _fused_inline(addr, Y, Y1, P, nl, S, C, h):
    _trial(Y, Y1, P, nl, S, C, h)


@nb.njit(inline="always")
def _stage_inline(addr, Y, DY, P, nl, S, C, h):
    _stage(Y, DY, P, nl, S, C)


LOOPS = {
    "fused": (_fused_loop(_fused_inline), _fused_loop(call_block), 0),
    "stages": (_stage_loop(_stage_inline), _stage_loop(call_block), 1),
}


def _time(run, Y0, P, n, addr, repeat):
    Y = Y0.copy()
    run(Y, P, 0.01, 2, addr)  # compile
    times = []
    for _ in range(repeat):
        Y = Y0.copy()
        t0 = time.perf_counter()
        run(Y, P, 0.01, n, addr)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), Y


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--slots", type=int, default=64, help="block width (the engine's BLOCK)")
    ap.add_argument("--write", action="store_true", help="record in bench/RESULTS.md")
    args = ap.parse_args(argv)
    funcs, model_compile = _model_part()
    nl = args.slots
    P = np.empty((4, nl))
    P[0], P[1], P[2], P[3] = 0.05, 0.2, 0.1, 1.0
    Y0 = np.random.default_rng(1).normal(size=(2, nl))
    n = max(2000, 2_000_000 // nl)
    ratios = {}
    for name, (inline, indirect, which) in LOOPS.items():
        t_in, y_in = _time(inline, Y0, P, n, 0, args.repeat)
        t_ind, y_ind = _time(indirect, Y0, P, n, funcs[which].address, args.repeat)
        ns_in, ns_ind = (t / (n * nl) * 1e9 for t in (t_in, t_ind))
        ratios[name] = ns_ind / ns_in
        print(f"{name:7s} inlined {ns_in:6.2f} ns/lane-step   through the pointer {ns_ind:6.2f}"
              f"   ratio {ns_ind / ns_in:5.3f}   bitwise equal: {np.array_equal(y_in, y_ind)}")
    (trial2, _), _ = _model_part()  # a second model's part: new addresses
    before = len(LOOPS["fused"][1].signatures)
    _time(LOOPS["fused"][1], Y0, P, 2, trial2.address, 1)
    reused = len(LOOPS["fused"][1].signatures) == before
    print(f"model part (2 cfuncs) cold compile: {model_compile:.2f} s CPU; "
          f"core reused for a second model without a compile: {reused}")
    if args.write:
        results.record(
            "indirect-call",
            "design: model called through a pointer from a shared core, fused block <= 1.05x",
            f"fused block {ratios['fused']:.3f}x, SoA stages {ratios['stages']:.3f}x of the "
            f"inlined loop "
            f"({nl} slots, median of {args.repeat}); model part compiles in "
            f"{model_compile:.1f} s CPU; core reused: {reused}",
            "met" if ratios["fused"] <= 1.05 else "over",
            f"`.venv/bin/python bench/indirect_call.py --repeat {args.repeat} --write`")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
