"""The one form of a model: its physics written once, as per-lane scalar functions.

A model of fixed state size may give its compiled functions as

* ``rhs(t, y, p, s, c) -> tuple``: dy/dt, ``n_states`` values;
* ``events(t, y, p, s, c) -> tuple``: the switching functions, ``n_events`` values;
* ``observe(t, y, p, s, c) -> tuple``: the observables, ``n_observables`` values;

where ``y`` is the state as a tuple, ``p`` the lane's coefficients as a named tuple whose fields
are the model's ``param_names`` (``p.zeta``, ``p.Omega``) and ``s, c`` sin and cos of the forcing
phase (see :mod:`geardyn.core.model`). :func:`adapters` writes, as text spliced into every
generated kernel module (see :mod:`geardyn.solvers.kernels`), every layout the kernel
templates take from it: the array form ``rhs(t, y, dy, p, s, c)`` (trajectory, split steps,
Lyapunov, monodromy), the lane-block form ``rhs_lanes(T, Y, DY, PT, nl, S, C, SC)`` (Lyapunov
row blocks) and the lane-scalar form ``rhs_lane(t, y, PT, k, s, c, form)`` (the sweep's fused
step loop), and so for ``events`` and ``observe``. The one form's functions are inlined into
each (numba IR inlining); a lane's named tuple is built from the coefficient vector there, its
unused fields never loaded.

Every lane takes the one form FORM_QUIET: the fused loop vectorises wherever the functions call
no libm routine per lane (a model precomputes cos/sin of a coefficient as coefficients of its
own: derived coefficients declared with their function, filled by the coefficient layout; see
:mod:`geardyn.core.coefficients` and :class:`geardyn.models.gear_pair.GearPair`).

This module belongs to the core: it imports nothing of geardyn outside :mod:`geardyn.core`.
"""

from __future__ import annotations

import collections
import keyword
from dataclasses import dataclass
from typing import Any

from geardyn.core.coefficients import Derivations

__all__ = ["Derivations", "OneForm", "adapters", "call_tuple", "coefficient_type"]

_TYPE_PREFIX = "Coefficients_"


@dataclass(frozen=True)
class OneForm:
    """The sizes and coefficient names of a model written in the one form."""

    coefficients: tuple[str, ...]
    n_states: int
    n_events: int = 0
    n_observables: int = 0

    def __post_init__(self) -> None:
        check_names(self.coefficients)
        if self.n_states < 1 or self.n_events < 0 or self.n_observables < 0:
            raise ValueError(f"one form sizes must be n_states >= 1, n_events >= 0, "
                             f"n_observables >= 0 (got {self.n_states}, {self.n_events}, "
                             f"{self.n_observables})")


def check_names(names: tuple[str, ...]) -> None:
    """ValueError unless ``names`` are distinct identifiers usable as named-tuple fields."""
    bad = [n for n in names if not isinstance(n, str) or not n.isidentifier()
           or keyword.iskeyword(n) or n.startswith("_")]
    if bad:
        raise ValueError(f"coefficient names must be Python identifiers not starting with '_' "
                         f"(got {', '.join(map(repr, bad))})")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"coefficient names repeat {', '.join(dup)}")


def _type_name(names: tuple[str, ...]) -> str:
    return _TYPE_PREFIX + ",".join(names).encode().hex()


def coefficient_type(names: tuple[str, ...]) -> type:
    """The named tuple of a lane's coefficients with fields ``names`` (one class per tuple of
    names, an attribute of this module, so that it pickles by reference: numba's cache index
    keeps the argument types of the functions it caches)."""
    names = tuple(names)
    attr = _type_name(names)
    cls = globals().get(attr)
    if cls is None:
        check_names(names)
        cls = collections.namedtuple("Coefficients", names)
        cls.__module__ = __name__
        cls.__qualname__ = attr
        globals()[attr] = cls
    return cls


def __getattr__(attr: str) -> type:
    """The coefficient types by their attribute name (made on demand, for unpickling)."""
    if attr.startswith(_TYPE_PREFIX):
        try:
            names = bytes.fromhex(attr[len(_TYPE_PREFIX):]).decode()
        except ValueError:
            raise AttributeError(attr) from None
        return coefficient_type(tuple(names.split(",")) if names else ())
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


def call_tuple(fn: Any, names: tuple[str, ...], t: float, y: Any, p: Any, s: float,
               c: float) -> tuple:
    """``fn(t, y, p, s, c)`` of a one-form function from arrays (``y`` and ``p`` as tuples),
    for tests and checks outside the kernels."""
    coef = coefficient_type(names)(*(float(v) for v in p))
    return fn(float(t), tuple(float(v) for v in y), coef, float(s), float(c))


# ---------------------------------------------------------------------------------------------
# the generated layouts

def _tuple_text(fmt: str, n: int) -> str:
    return "(" + "".join(fmt.format(q=q) + ", " for q in range(n)) + ")"


def _stores(target: str, n: int) -> list[str]:
    return [f"{target.format(q=q)} = v[{q}]" for q in range(n)] or ["pass"]


def _fn(head: str, body: list[str], inline: bool = False) -> str:
    deco = "@nb.njit(inline=\"always\", **_JIT)" if inline else "@nb.njit(**_JIT)"
    return f"\n\n{deco}\ndef {head}:\n" + "".join(f"    {line}\n" for line in body)


def adapters(form: OneForm) -> str:
    """Python source defining the kernel interface's functions (every layout, see the module
    docstring) from the one form's ``one_rhs``, ``one_events`` and ``one_observe`` (names the
    generated module imports), for a model of ``form``'s sizes and coefficients."""
    ns, ne, no = form.n_states, form.n_events, form.n_observables
    nc = len(form.coefficients)
    out = [
        "\n# The model's one form (geardyn.core.one_form): every layout generated from it.",
        "from geardyn.core.kernel_source import FORM_QUIET as _ONE_FORM",
        "from geardyn.core.one_form import coefficient_type as _coefficient_type",
        f"_Coef = _coefficient_type({tuple(form.coefficients)!r})",
        "from geardyn._jit_target import WidthCompiler as _WidthCompiler",
        "_ONE_INLINE = {\"inline\": \"always\", \"error_model\": \"numpy\", "
        "\"boundscheck\": False, \"pipeline_class\": _WidthCompiler}",
    ]
    for name, n in (("rhs", ns), ("events", ne), ("observe", no)):
        if name == "rhs" or n > 0:
            out.append(f"_one_{name} = nb.njit(**_ONE_INLINE)(one_{name}.py_func)")
    text = "\n".join(out) + "\n"
    text += _fn("_coef(p)", [f"return _Coef{_tuple_text('p[{q}]', nc)}"], inline=True)
    text += _fn("_coef_lane(PT, k)", [f"return _Coef{_tuple_text('PT[{q}, k]', nc)}"],
                inline=True)
    y_arr, y_blk = _tuple_text("y[{q}]", ns), _tuple_text("Y[{q}, k]", ns)
    specs = (("rhs", "dy", "DY", ns, ", SC"), ("events", "g", "G", ne, ""),
             ("observe", "out", "O", no, ", SC"))
    for name, arr, blk, n, sc in specs:
        call = f"_one_{name}" if n > 0 or name == "rhs" else None
        if call is None:
            body: list[str] = ["pass"]
            blk_body = ["pass"]
            lane_body = ["return ()"]
        else:
            body = [f"v = {call}(t, {y_arr}, _coef(p), s, c)", *_stores(arr + "[{q}]", n)]
            blk_body = ["for k in range(nl):",
                        f"    v = {call}(T[k], {y_blk}, _coef_lane(PT, k), S[k], C[k])",
                        *("    " + line for line in _stores(blk + "[{q}, k]", n))]
            lane_body = [f"return {call}(t, y, _coef_lane(PT, k), s, c)"]
        text += _fn(f"{name}(t, y, {arr}, p, s, c)", body)
        text += _fn(f"{name}_lanes(T, Y, {blk}, PT, nl, S, C{sc})", blk_body)
        form_arg = "" if name == "events" else ", form"
        text += _fn(f"{name}_lane(t, y, PT, k, s, c{form_arg})", lane_body, inline=True)
    text += f"\n\n#: The state size of the lane-scalar forms.\nrhs_lane_states = {ns}\n"
    text += _fn("rhs_lane_form(PT, k)", ["return _ONE_FORM"])
    return text
