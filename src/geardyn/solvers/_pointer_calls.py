"""Calls of a model's compiled part through its address (the ``"pointer"`` kernel path).

A model on the pointer path compiles its functions alone, as C callbacks (``numba.cfunc``,
:mod:`._pointer_kernels`); the step machinery that calls them is compiled once for every model
(:mod:`._pointer_model`, :mod:`._pointer_template`) and calls them through addresses that
travel as data (the last :data:`N_ADDRESSES` entries of every coefficient row, whole numbers
held exactly as float64), so that its cached code holds no address of a process. The two
intrinsics here are the calls: :func:`call_array` (one lane, the array form) and
:func:`call_flat` (any arguments flattened: the fused step of a block of slots, the split
step); each costs one indirect call and no inlining, and gives bitwise the results of the
model's functions inlined (the same arithmetic).
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["ARRAY_SIG", "N_ADDRESSES", "N_LYAPUNOV", "SPLIT_ARGS", "STEP_ARGS", "TANGENT_ARGS",
           "VAR_STEP_ARGS", "c_array", "call_array", "call_flat", "flat_signature"]

_F8P = types.CPointer(types.float64)
#: The C signature of a model function in array form ``f(t, y, out, p, s, c)``, its arrays as
#: (data pointer, length): ``(t, y, ny, out, nout, p, np, s, c) -> None``.
ARRAY_SIG = types.void(types.float64, _F8P, types.intp, _F8P, types.intp, _F8P, types.intp,
                       types.float64, types.float64)
#: The addresses at the end of a coefficient row: the array forms of rhs, events, observe,
#: the fused step (:data:`STEP_ARGS`), the split step (:data:`SPLIT_ARGS`).
N_ADDRESSES = 5
#: The numba types of the split step's arguments (``_split_step`` of a model's core module,
#: :mod:`._step_core`), which its C callback takes flattened (:func:`flat_signature`).
SPLIT_ARGS = (types.int64, types.float64, types.float64[::1], types.float64[::1],
              types.float64[::1], types.float64, types.float64, types.int64, types.float64,
              types.float64, types.float64, types.float64, types.int64[::1], types.float64[::1],
              types.int64[::1], types.float64[:, ::1], types.float64[::1], types.float64[:, ::1])
_F, _I, _B = types.float64[::1], types.int64[::1], types.boolean[::1]
#: The numba types of the fused step's arguments (``_fused_steps`` of a model's ``"rk4"``
#: kernel module, :mod:`._kernel_template`), its tuples unpacked, which its C callback takes
#: flattened: nl, locate, bound, Y, Y1, PT, SE, CE, H6, FLAG; the events (GS, GP, GR, SIDE),
#: the statistics (GMIN, GMAX, OMAX, OMIN, OSQ), the slots (STAT, MSK, ACT, END, LANE, STEP,
#: PHASE, NPER, OFF, HB, T0B, n_end, n_tr, next_sample, DUE, n_stat, n_ring), the phase
#: increments (4) and phases (4); the block arrays as their flat views (see ``_fused_run``).
STEP_ARGS = (types.int64, types.boolean, types.float64, _F, _F, types.float64[:, ::1],
             *(_F,) * 4, *(_F,) * 4, *(_F,) * 5, *(_B,) * 4, *(_I,) * 5, _F, _F, *(_I,) * 6,
             *(_F,) * 4, *(_F,) * 4)

#: The entries before the :data:`N_ADDRESSES` at the end of a coefficient row of the pointer
#: path's Lyapunov lane blocks (:mod:`._pointer_lyapunov`): the model's number of switching
#: functions, the addresses of its variational step of a block of lanes
#: (:data:`VAR_STEP_ARGS`) and of the tangent form of its rhs (:data:`TANGENT_ARGS`).
N_LYAPUNOV = 3
#: The numba types of the variational steps' arguments (``_var_steps`` of a model's
#: ``"lyapunov"`` kernel module, :mod:`._lyapunov_template`, in its lane form: without
#: ``form``), its tuple of phases unpacked: i, stop, n_adv, nl, locate, commit, Z0, Z1, S, IS,
#: PT, T0L, HL, HHL, H6L, the phases and their increments (6), IDX, ENDL, ACT, FLAG, GR, Y1F,
#: NPL.
VAR_STEP_ARGS = (*(types.int64,) * 4, types.boolean, types.boolean, *(_F,) * 4,
                 types.float64[:, ::1], *(_F,) * 4, *(_F,) * 6, _I, _I, _B, _F, _F, _F, _I)
#: The numba types of the arguments of a model's tangent form of its rhs, ``rhs_tangent(t, y, v,
#: dy, dv, p, s, c)`` (:func:`geardyn.core.one_form.tangent_adapters`).
TANGENT_ARGS = (types.float64, *(_F,) * 5, types.float64, types.float64)

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


@intrinsic
def c_array(typingctx, ptr, shape):
    """The C-contiguous array of the data pointer ``ptr`` and ``shape`` (an integer, or a
    tuple of them), owned by no one: ``numba.carray`` without its call and without reference
    counting, so that a callback compiled with ``_nrt=False`` rebuilds its array arguments at
    no cost (with reference counting, the ~40 arrays of the fused step cost more than a block
    step of a model's arithmetic)."""
    if not isinstance(ptr, types.CPointer):
        return None
    dims = [shape] if isinstance(shape, types.Integer) else list(shape)
    if not dims or not all(isinstance(d, types.Integer) for d in dims):
        return None
    aty = types.Array(ptr.dtype, len(dims), "C")

    def codegen(context, builder, signature, args):
        p, sh = args
        vals = [sh] if len(dims) == 1 else cgutils.unpack_tuple(builder, sh, len(dims))
        intp = context.get_value_type(types.intp)
        shapes = [context.cast(builder, v, d, types.intp) for v, d in zip(vals, dims, strict=True)]
        size = context.get_abi_sizeof(context.get_data_type(ptr.dtype))
        itemsize = ir.Constant(intp, size)
        strides = [itemsize]
        for n in reversed(shapes[1:]):
            strides.insert(0, builder.mul(strides[0], n))
        arr = context.make_array(aty)(context, builder)
        context.populate_array(arr, data=builder.bitcast(p, arr.data.type), shape=shapes,
                               strides=strides, itemsize=itemsize, meminfo=None)
        return arr._getvalue()

    return aty(ptr, shape), codegen
