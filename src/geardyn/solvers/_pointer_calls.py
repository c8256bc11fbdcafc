"""Calls of a model's compiled part through its address (the ``"pointer"`` kernel path).

A model on the pointer path compiles its functions alone, as C callbacks (``numba.cfunc``,
:mod:`._pointer_parts`); the step machinery that calls them is compiled once for every model
(:mod:`._pointer_model`, :mod:`._pointer_template`) and calls them through addresses that
travel as data (the last :data:`N_ADDRESSES` entries of every coefficient row, whole numbers
held exactly as float64), so that its cached code holds no address of a process. The two
intrinsics here are the calls: :func:`call_array` (one lane, the array form) and
:func:`call_trial` (a block of slots' fused trial step); each costs one indirect call and no
inlining, and gives bitwise the results of the model's functions inlined (the same
arithmetic).
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.extending import intrinsic

__all__ = ["ARRAY_SIG", "N_ADDRESSES", "SPLIT_ARGS", "TRIAL_ROWS", "TRIAL_SIG", "call_array",
           "call_flat", "call_trial", "flat_signature"]

_F8P = types.CPointer(types.float64)
#: The C signature of a model function in array form ``f(t, y, out, p, s, c)``, its arrays as
#: (data pointer, length): ``(t, y, ny, out, nout, p, np, s, c) -> None``.
ARRAY_SIG = types.void(types.float64, _F8P, types.intp, _F8P, types.intp, _F8P, types.intp,
                       types.float64, types.float64)
#: The C signature of a model's fused trial step on a block of slots (``_trial_block`` of
#: :mod:`._pointer_kernels`' generated part), its arrays C-contiguous blocks of ``ld`` slots:
#: ``(X, Y, Y1, G1, O, PT, ld, npt, nl) -> None``; X: the slots' times, step and phases
#: (:data:`TRIAL_ROWS` rows), Y the start states, Y1, G1, O: the trial's end state, events and
#: observables there, PT: ``npt`` coefficient rows.
TRIAL_SIG = types.void(_F8P, _F8P, _F8P, _F8P, _F8P, _F8P, types.intp, types.intp, types.intp)
#: The rows of a trial's X: start, middle and end time, h, h / 6, sin and cos of the forcing
#: phase at the start, middle and end.
TRIAL_ROWS = 11
#: The addresses at the end of a coefficient row: the array forms of rhs, events, observe,
#: the fused trial step, the split step (:data:`SPLIT_ARGS`).
N_ADDRESSES = 5
#: The numba types of the split step's arguments (``_split_step`` of a model's core module,
#: :mod:`._step_core`), which its C callback takes flattened (:func:`flat_signature`).
SPLIT_ARGS = (types.int64, types.float64, types.float64[::1], types.float64[::1],
              types.float64[::1], types.float64, types.float64, types.int64, types.float64,
              types.float64, types.float64, types.float64, types.int64[::1], types.float64[::1],
              types.int64[::1], types.float64[:, ::1], types.float64[::1], types.float64[:, ::1])


def _is_c(ty: Any, ndim: int) -> bool:
    return (isinstance(ty, types.Array) and ty.ndim == ndim and ty.dtype == types.float64
            and ty.layout == "C")


def _data(context, builder, ty, value):
    return context.make_array(ty)(context, builder, value)


@intrinsic
def call_array(typingctx, addr, t, y, out, p, s, c):
    """Call the :data:`ARRAY_SIG` callback at ``addr`` (an integer) as ``f(t, y, out, p, s,
    c)``; y, out, p: C-contiguous 1-d float64 arrays (a typing error otherwise)."""
    if not isinstance(addr, types.Integer) or not all(_is_c(a, 1) for a in (y, out, p)):
        return None
    sig = types.void(addr, t, y, out, p, s, c)

    def codegen(context, builder, signature, args):
        a, tt, yy, oo, pp, ss, cc = args
        d = ir.DoubleType()
        n = context.get_value_type(types.intp)
        fty = ir.FunctionType(ir.VoidType(), [d, d.as_pointer(), n, d.as_pointer(), n,
                                              d.as_pointer(), n, d, d])
        flat = []
        for ty, value in zip(signature.args[2:5], (yy, oo, pp), strict=True):
            arr = _data(context, builder, ty, value)
            flat += [arr.data, builder.extract_value(arr.shape, 0)]
        scal = [context.cast(builder, v, signature.args[k], types.float64)
                for k, v in ((1, tt), (5, ss), (6, cc))]
        a64 = context.cast(builder, a, signature.args[0], types.int64)
        builder.call(builder.inttoptr(a64, fty.as_pointer()),
                     [scal[0], *flat, scal[1], scal[2]])
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def call_trial(typingctx, addr, X, Y, Y1, G1, O, PT, nl):
    """Call the :data:`TRIAL_SIG` callback at ``addr`` as ``f(X, Y, Y1, G1, O, PT, nl)``:
    2-d C-contiguous float64 arrays of the same slots (their last dimension, Y's, is the
    block's ``ld``)."""
    if not isinstance(addr, types.Integer) or not isinstance(nl, types.Integer):
        return None
    if not all(_is_c(a, 2) for a in (X, Y, Y1, G1, O, PT)):
        return None
    sig = types.void(addr, X, Y, Y1, G1, O, PT, nl)

    def codegen(context, builder, signature, args):
        ty = signature.args
        dp = ir.DoubleType().as_pointer()
        ip = context.get_value_type(types.intp)
        fty = ir.FunctionType(ir.VoidType(), [dp] * 6 + [ip, ip, ip])
        arrs = [_data(context, builder, ty[k], args[k]) for k in range(1, 7)]
        ld = builder.extract_value(arrs[1].shape, 1)
        npt = builder.extract_value(arrs[5].shape, 0)
        nn = context.cast(builder, args[7], ty[7], types.intp)
        a64 = context.cast(builder, args[0], ty[0], types.int64)
        builder.call(builder.inttoptr(a64, fty.as_pointer()),
                     [a.data for a in arrs] + [ld, npt, nn])
        return context.get_dummy_value()

    return sig, codegen


def flat_signature(arg_types: tuple) -> Any:
    """The C signature (int64 result) of a function of numba types ``arg_types`` called by
    :func:`call_flat`: an integer as int64, a float as float64, a C-contiguous array as its data
    pointer and then its shape (intp each)."""
    flat: list = []
    for ty in arg_types:
        if isinstance(ty, types.Array):
            flat += [types.CPointer(ty.dtype)] + [types.intp] * ty.ndim
        elif isinstance(ty, types.Integer | types.Boolean):
            flat.append(types.int64)
        else:
            flat.append(types.float64)
    return types.int64(*flat)


@intrinsic
def call_flat(typingctx, addr, args):
    """Call the C callback at ``addr`` with the tuple ``args`` flattened
    (:func:`flat_signature`: C-contiguous arrays as data pointer and shape); returns its int64
    result."""
    if not isinstance(addr, types.Integer) or not isinstance(args, types.BaseTuple):
        return None
    for ty in args:
        if isinstance(ty, types.Array) and ty.layout != "C":
            return None
    sig = types.int64(addr, args)
    csig = flat_signature(tuple(args))

    def codegen(context, builder, signature, llargs):
        a, tup = llargs
        fty = ir.FunctionType(context.get_value_type(types.int64),
                              [context.get_value_type(t) for t in csig.args])
        values = []
        for k, ty in enumerate(signature.args[1]):
            v = builder.extract_value(tup, k)
            if isinstance(ty, types.Array):
                arr = _data(context, builder, ty, v)
                values.append(arr.data)
                values += [builder.extract_value(arr.shape, d) for d in range(ty.ndim)]
            elif isinstance(ty, types.Integer | types.Boolean):
                values.append(context.cast(builder, v, ty, types.int64))
            else:
                values.append(context.cast(builder, v, ty, types.float64))
        a64 = context.cast(builder, a, signature.args[0], types.int64)
        return builder.call(builder.inttoptr(a64, fty.as_pointer()), values)

    return sig, codegen
