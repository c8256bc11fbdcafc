"""A model's functions called through their address, from machinery compiled once for every model.

The step machinery that does not depend on the model (the split step and its root finders, the
tangent rows: :mod:`._split_core`) is compiled and cached once, for all models; it calls the
model's ``rhs`` and ``events`` through function pointers that travel as a tuple of integers
(``fn``), so its compiled code holds no address of this process. A model's generated core module
(:mod:`._step_core`) compiles its array-form functions as C callbacks (``numba.cfunc`` with
:data:`FORM_SIG`) and hands their addresses to the shared machinery with :func:`addresses`.

The call costs an indirect call and no inlining (``bench/indirect_call.py`` measures it against
the inlined loop); results are bitwise those of the inlined function, the same arithmetic.
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["FORM_SIG", "addresses", "call_form"]

_F8P = types.CPointer(types.float64)
#: The C signature of a model function in array form, ``f(t, y, out, p, s, c)`` with its arrays
#: as (pointer, length): ``(t, y, ny, out, nout, p, np, s, c) -> None``.
FORM_SIG = types.void(types.float64, _F8P, types.intp, _F8P, types.intp, _F8P, types.intp,
                      types.float64, types.float64)


def _form_type(context: Any) -> ir.FunctionType:
    d = ir.DoubleType()
    n = context.get_value_type(types.intp)
    return ir.FunctionType(ir.VoidType(), [d, d.as_pointer(), n, d.as_pointer(), n,
                                           d.as_pointer(), n, d, d])


def _contiguous_f8(ty: Any) -> bool:
    return isinstance(ty, types.Array) and ty.ndim == 1 and ty.dtype == types.float64 and (
        ty.layout == "C")


@intrinsic
def call_form(typingctx, addr, t, y, out, p, s, c):
    """Call the model function at ``addr`` (int64, a :data:`FORM_SIG` callback) as
    ``f(t, y, out, p, s, c)``; y, out and p: contiguous 1-d float64 arrays (passed as data
    pointer and length)."""
    if not isinstance(addr, types.Integer):
        return None
    if not all(_contiguous_f8(a) for a in (y, out, p)):
        return None
    sig = types.void(addr, t, y, out, p, s, c)

    def codegen(context, builder, signature, args):
        a, tt, yy, oo, pp, ss, cc = args
        fty = _form_type(context)
        flat = []
        for ty, value in zip(signature.args[2:5], (yy, oo, pp), strict=True):
            arr = context.make_array(ty)(context, builder, value)
            flat += [arr.data, builder.extract_value(arr.shape, 0)]
        tv = context.cast(builder, tt, signature.args[1], types.float64)
        sv = context.cast(builder, ss, signature.args[5], types.float64)
        cv = context.cast(builder, cc, signature.args[6], types.float64)
        builder.call(builder.inttoptr(a, fty.as_pointer()), [tv, *flat, sv, cv])
        return context.get_dummy_value()

    return sig, codegen


def addresses(*callbacks: Any) -> Any:
    """An intrinsic ``() -> UniTuple(int64, n)``: the addresses of the C callbacks
    ``callbacks`` (compiled ``numba.cfunc`` objects of :data:`FORM_SIG`), their code linked
    into the function that calls it. The cached code of that function refers to them by
    symbol, not by this process's address, so it stays valid in another process."""
    names = [cb.native_name for cb in callbacks]
    libraries = [cb._library for cb in callbacks]  # numba's CFunc keeps its code library here

    @intrinsic
    def _addresses(typingctx):
        ret = types.UniTuple(types.int64, len(names))

        def codegen(context, builder, signature, args):
            fty = _form_type(context)
            context.add_linking_libs(libraries)
            values = [builder.ptrtoint(cgutils.get_or_insert_function(builder.module, fty, name),
                                       ir.IntType(64)) for name in names]
            return context.make_tuple(builder, ret, values)

        return ret(), codegen

    return _addresses
