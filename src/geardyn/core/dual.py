"""Forward-mode dual numbers for compiled code: a value and one tangent (derivative) component.

A one-form function (:mod:`geardyn.core.one_form`) is compiled by numba for the types of its
arguments; called with the state ``y`` a tuple of duals ``dual(y_q, v_q)``, its results are the
duals ``(f_q(y), (J(y) v)_q)``: the directional derivative of the model's physics, exact (no
difference quotient), from the same source. The primal part of every operation is the float
operation itself (``a.value * b.value``, the same libm call), so the values are bitwise those of
the float function; after inlining, LLVM keeps one copy of the primal work.

Operations: ``+ - * /`` (also in place), unary ``- +``, ``**`` by a float or an integer, the
comparisons (by value), ``min``/``max`` of two arguments (Python's choice of argument, so the
derivative is that of the side chosen: at a tie the first argument's), ``abs``, ``math.sqrt``,
``sin``, ``cos``, ``exp``, ``log``, ``tanh``; each mixes duals with floats and integers (a float
is a dual with tangent 0). A dual and a float unify to a dual (``x if c else 0.0``).
:func:`value_of` and :func:`tangent_of` read a dual or a plain number (tangent 0.0).
Compiled code only (numba); the functions here raise in Python.

This module belongs to the core: it imports nothing of geardyn.
"""

from __future__ import annotations

import math
import operator

from numba import njit
from numba.core import cgutils, types
from numba.core.typeconv import Conversion
from numba.extending import (
    intrinsic,
    lower_cast,
    make_attribute_wrapper,
    models,
    overload,
    register_model,
)

__all__ = ["DualType", "dual", "dual_type", "tangent_of", "value_of"]


class DualType(types.Type):
    """numba's type of a dual number (float64 value and tangent)."""

    def __init__(self) -> None:
        super().__init__(name="Dual")

    def unify(self, typingctx, other):
        if isinstance(other, types.Number) and not isinstance(other, types.Complex):
            return self
        return None

    def can_convert_from(self, typingctx, other):
        if isinstance(other, types.Number) and not isinstance(other, types.Complex):
            return Conversion.safe
        return None

    def __reduce__(self):  # pickled by reference (numba's cache index keeps argument types)
        return "dual_type"


#: The dual type (one instance).
dual_type = DualType()


@register_model(DualType)
class _DualModel(models.StructModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, [("value", types.float64), ("tangent", types.float64)])


make_attribute_wrapper(DualType, "value", "value")
make_attribute_wrapper(DualType, "tangent", "tangent")


@intrinsic
def _make(typingctx, value, tangent):
    """The dual (value, tangent) of two float64."""
    if not (isinstance(value, types.Float) and isinstance(tangent, types.Float)):
        return None
    sig = dual_type(types.float64, types.float64)

    def codegen(context, builder, signature, args):
        v, t = args
        v = context.cast(builder, v, signature.args[0], types.float64)
        t = context.cast(builder, t, signature.args[1], types.float64)
        d = cgutils.create_struct_proxy(dual_type)(context, builder)
        d.value = v
        d.tangent = t
        return d._getvalue()

    return sig, codegen


@lower_cast(types.Number, DualType)
def _number_to_dual(context, builder, fromty, toty, val):
    d = cgutils.create_struct_proxy(dual_type)(context, builder)
    d.value = context.cast(builder, val, fromty, types.float64)
    d.tangent = context.get_constant(types.float64, 0.0)
    return d._getvalue()


def dual(value, tangent):
    """The dual number ``value + tangent eps`` (compiled code only)."""
    raise NotImplementedError("geardyn.core.dual is compiled code's (numba) only")


def value_of(x):
    """The value of a dual, or the number itself (compiled code only)."""
    raise NotImplementedError("geardyn.core.dual is compiled code's (numba) only")


def tangent_of(x):
    """The tangent of a dual, 0.0 for a plain number (compiled code only)."""
    raise NotImplementedError("geardyn.core.dual is compiled code's (numba) only")


#: The overloads are inlined into the caller's IR (compiled with its flags: ``error_model``);
#: ``min``, ``max`` and ``abs`` (a select) are compiled apart, and inlined by LLVM.
_INLINE = {"inline": "always"}


def _is_dual(t) -> bool:
    return isinstance(t, DualType)


def _is_real(t) -> bool:
    return isinstance(t, types.Float | types.Integer | types.Boolean)


def _operands(a, b) -> bool:
    """Whether ``(a, b)`` is an operand pair of the dual overloads (a dual, and a dual or real)."""
    return (_is_dual(a) or _is_dual(b)) and all(_is_dual(x) or _is_real(x) for x in (a, b))


@overload(dual, **_INLINE)
def _ov_dual(value, tangent):
    if _is_real(value) and _is_real(tangent):
        def impl(value, tangent):
            return _make(float(value), float(tangent))
        return impl
    return None


@overload(value_of, **_INLINE)
def _ov_value_of(x):
    if _is_dual(x):
        return lambda x: x.value
    if _is_real(x):
        return lambda x: float(x)
    return None


@overload(tangent_of, **_INLINE)
def _ov_tangent_of(x):
    if _is_dual(x):
        return lambda x: x.tangent
    if _is_real(x):
        return lambda x: 0.0
    return None


def _ov_add(a, b):
    if not _operands(a, b):
        return None
    if _is_dual(a) and _is_dual(b):
        return lambda a, b: _make(a.value + b.value, a.tangent + b.tangent)
    if _is_dual(a):
        return lambda a, b: _make(a.value + b, a.tangent)
    return lambda a, b: _make(a + b.value, b.tangent)


def _ov_sub(a, b):
    if not _operands(a, b):
        return None
    if _is_dual(a) and _is_dual(b):
        return lambda a, b: _make(a.value - b.value, a.tangent - b.tangent)
    if _is_dual(a):
        return lambda a, b: _make(a.value - b, a.tangent)
    return lambda a, b: _make(a - b.value, -b.tangent)


def _ov_mul(a, b):
    if not _operands(a, b):
        return None
    if _is_dual(a) and _is_dual(b):
        return lambda a, b: _make(a.value * b.value, a.tangent * b.value + a.value * b.tangent)
    if _is_dual(a):
        return lambda a, b: _make(a.value * b, a.tangent * b)
    return lambda a, b: _make(a * b.value, a * b.tangent)


def _ov_div(a, b):
    if not _operands(a, b):
        return None
    if _is_dual(a) and _is_dual(b):
        def impl(a, b):
            q = a.value / b.value
            return _make(q, (a.tangent - q * b.tangent) / b.value)
        return impl
    if _is_dual(a):
        return lambda a, b: _make(a.value / b, a.tangent / b)

    def impl_rd(a, b):
        q = a / b.value
        return _make(q, -(q * b.tangent) / b.value)
    return impl_rd


def _ov_pow(a, b):
    if not (_is_dual(a) and _is_real(b)):
        return None

    def impl(a, b):
        return _make(a.value ** b, (b * a.value ** (b - 1)) * a.tangent)
    return impl


for _ops, _fn in (((operator.add, operator.iadd), _ov_add),
                  ((operator.sub, operator.isub), _ov_sub),
                  ((operator.mul, operator.imul), _ov_mul),
                  ((operator.truediv, operator.itruediv), _ov_div),
                  ((operator.pow, operator.ipow), _ov_pow)):
    for _op in _ops:
        overload(_op, **_INLINE)(_fn)


@overload(operator.neg, **_INLINE)
def _ov_neg(a):
    if _is_dual(a):
        return lambda a: _make(-a.value, -a.tangent)
    return None


@overload(operator.pos, **_INLINE)
def _ov_pos(a):
    if _is_dual(a):
        return lambda a: a
    return None


def _comparison(op):
    def ov(a, b):
        if not _operands(a, b):
            return None
        return lambda a, b: op(value_of(a), value_of(b))
    return ov


for _op in (operator.lt, operator.le, operator.gt, operator.ge, operator.eq, operator.ne):
    overload(_op, **_INLINE)(_comparison(_op))


@overload(max)
def _ov_max(a, b):
    # Python's (and numba's) max of two: b where b > a, else a
    if not _operands(a, b):
        return None

    def impl(a, b):
        av = value_of(a)
        bv = value_of(b)
        pick = bv > av
        return _make(bv if pick else av, tangent_of(b) if pick else tangent_of(a))
    return impl


@overload(min)
def _ov_min(a, b):
    # Python's (and numba's) min of two: b where b < a, else a
    if not _operands(a, b):
        return None

    def impl(a, b):
        av = value_of(a)
        bv = value_of(b)
        pick = bv < av
        return _make(bv if pick else av, tangent_of(b) if pick else tangent_of(a))
    return impl


@overload(abs)
def _ov_abs(a):
    if _is_dual(a):
        return lambda a: _make(abs(a.value), -a.tangent if a.value < 0.0 else a.tangent)
    return None


def _unary(fn, derivative):
    def ov(a):
        if not _is_dual(a):
            return None

        def impl(a):
            v = fn(a.value)
            return _make(v, derivative(a.value, v) * a.tangent)
        return impl
    return ov


@njit(inline="always")
def _d_sqrt(x, v):
    return 0.5 / v


@njit(inline="always")
def _d_sin(x, v):
    return math.cos(x)


@njit(inline="always")
def _d_cos(x, v):
    return -math.sin(x)


@njit(inline="always")
def _d_exp(x, v):
    return v


@njit(inline="always")
def _d_log(x, v):
    return 1.0 / x


@njit(inline="always")
def _d_tanh(x, v):
    return 1.0 - v * v


for _f, _d in ((math.sqrt, _d_sqrt), (math.sin, _d_sin), (math.cos, _d_cos),
               (math.exp, _d_exp), (math.log, _d_log), (math.tanh, _d_tanh)):
    overload(_f, **_INLINE)(_unary(_f, _d))


def _install() -> None:
    """Install the overloads above in numba's CPU typing and target contexts now. numba installs
    pending registrations at its next refresh, which may fall inside another function's compile
    (a callee's): a builtin such as ``math.sin`` then gets a new function type halfway through
    that function's typing, and unification fails. Under numba's compiler lock."""
    from numba.core.compiler_lock import global_compiler_lock
    from numba.core.registry import cpu_target

    with global_compiler_lock:
        cpu_target.typing_context.refresh()
        cpu_target.target_context.refresh()


_install()
