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
unused fields never loaded. The lane-scalar forms of ``rhs`` and ``observe`` (and the tangent
form ``rhs_lane_tangent``) call one compiled function per lane form (``_rhs_lane_one``; with
``quiet`` coefficients one per form, see :func:`_forms`), which LLVM inlines where it is called
(``forceinline``): numba types the one form once for them, not at every call site.

Every lane takes the lane form FORM_QUIET: the fused loop vectorises wherever the functions call
no libm routine per lane (a model precomputes cos/sin of a coefficient as coefficients of its
own: derived coefficients declared with their function, filled by the coefficient layout; see
:mod:`geardyn.core.coefficients` and :class:`geardyn.models.gear_pair.GearPair`). A model whose
physics has a dear term switched off by coefficients (the CATT device's load fluctuation) names
them ``OneForm.quiet`` and takes the term under ``if loud(p):`` (:func:`loud`: any of them
non-zero), a plain branch of the scalar code. The lane's named tuple says which lane form it is
in (its class, see :func:`coefficient_type`), and ``loud(p)`` is a constant where the form
fixes it: a lane where the quiet coefficients are all 0 takes FORM_QUIET, where ``loud(p)`` is
False (the term is dead code) and those coefficients are the constant 0.0 (the compiler folds
what they multiply: the same values, bitwise, as the lane's own zeros give); any other lane
takes FORM_LOAD, where ``loud(p)`` is True (the term taken with no test: it vectorises).
FORM_GENERAL (the split path, a queue mixing the two), the array form and the lane-block forms
test the coefficients per lane (the scalar paths skip the term where it is off); the lane-block
forms run their loop in FORM_QUIET where every lane of the block is quiet.

This module belongs to the core: it imports nothing of geardyn outside :mod:`geardyn.core`.
"""

from __future__ import annotations

import collections
import keyword
from dataclasses import dataclass
from typing import Any

from numba.core import errors
from numba.extending import overload

from geardyn.core.coefficients import Derivations

__all__ = ["Derivations", "OneForm", "adapters", "call_tuple", "coefficient_type", "loud",
           "tangent_adapters"]

_TYPE_PREFIX = "Coefficients_"
#: The lane forms a coefficient type of a one form with ``quiet`` coefficients is made for
#: (:func:`coefficient_type`) and the prefix of its class name.
MODES = {"general": "CoefficientsGeneral_", "quiet": "CoefficientsQuiet_",
         "loud": "CoefficientsLoud_"}


@dataclass(frozen=True)
class OneForm:
    """The sizes and coefficient names of a model written in the one form."""

    coefficients: tuple[str, ...]
    n_states: int
    n_events: int = 0
    n_observables: int = 0
    #: Coefficients whose zeros switch a term off: lanes with all of them 0 take FORM_QUIET,
    #: where the functions see them as the constant 0.0 (see the module docstring).
    quiet: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        check_names(self.coefficients)
        unknown = [n for n in self.quiet if n not in self.coefficients]
        if unknown or len(set(self.quiet)) != len(self.quiet):
            raise ValueError(f"quiet names distinct coefficients of the one form "
                             f"(got {', '.join(map(repr, self.quiet))})")
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


def _type_name(names: tuple[str, ...], quiet: tuple[str, ...] = (),
               mode: str = "general") -> str:
    if not quiet:
        return _TYPE_PREFIX + ",".join(names).encode().hex()
    return MODES[mode] + (",".join(quiet) + ";" + ",".join(names)).encode().hex()


def coefficient_type(names: tuple[str, ...], quiet: tuple[str, ...] = (),
                     mode: str = "general") -> type:
    """The named tuple of a lane's coefficients with fields ``names`` (one class per tuple of
    names, an attribute of this module, so that it pickles by reference: numba's cache index
    keeps the argument types of the functions it caches). For a one form with ``quiet``
    coefficients, one class per lane form ``mode`` (:data:`MODES`), which :func:`loud` reads:
    ``"general"`` (tested per lane), ``"quiet"`` (False), ``"loud"`` (True)."""
    names, quiet = tuple(names), tuple(quiet)
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)} (got {mode!r})")
    attr = _type_name(names, quiet, mode)
    cls = globals().get(attr)
    if cls is None:
        check_names(names)
        if any(n not in names for n in quiet):
            raise ValueError(f"quiet names coefficients of the tuple (got {quiet!r})")
        cls = collections.namedtuple("Coefficients", names)
        cls.__module__ = __name__
        cls.__qualname__ = attr
        cls.quiet_fields = quiet
        cls.lane_form = mode if quiet else None
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
    for mode, prefix in MODES.items():
        if attr.startswith(prefix):
            try:
                quiet, names = bytes.fromhex(attr[len(prefix):]).decode().split(";")
            except ValueError:
                raise AttributeError(attr) from None
            return coefficient_type(tuple(names.split(",")), tuple(quiet.split(",")), mode)
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


def loud(p: Any) -> bool:
    """Whether the term a one form switches by its ``quiet`` coefficients is on in the lane of
    the coefficients ``p``: any of them non-zero (NaN counts as on). In a lane form that fixes
    it (a constant: False in FORM_QUIET, True in FORM_LOAD) and tested per lane elsewhere; see
    the module docstring. The one form writes the term under ``if loud(p):``."""
    quiet = getattr(type(p), "quiet_fields", ())
    if not quiet:
        raise TypeError("loud(p): the coefficients' one form declares no quiet coefficients")
    mode = type(p).lane_form
    if mode != "general":
        return mode == "loud"
    return not all(getattr(p, n) == 0.0 for n in quiet)


@overload(loud, inline="always")
def _loud(p):
    cls = getattr(p, "instance_class", None)
    quiet = getattr(cls, "quiet_fields", ())
    if not quiet:
        raise errors.TypingError("loud(p): p must be the coefficients of a one form that "
                                 f"declares quiet coefficients (got {p})")
    if cls.lane_form == "quiet":
        return lambda p: False
    if cls.lane_form == "loud":
        return lambda p: True
    test = " & ".join(f"(p.{n} == 0.0)" for n in quiet)
    scope: dict[str, Any] = {}
    exec(f"def impl(p):\n    return not ({test})\n", scope)  # noqa: S102 (names checked)
    return scope["impl"]


def call_tuple(fn: Any, names: tuple[str, ...], t: float, y: Any, p: Any, s: float,
               c: float, quiet: tuple[str, ...] = ()) -> tuple:
    """``fn(t, y, p, s, c)`` of a one-form function from arrays (``y`` and ``p`` as tuples),
    for tests and checks outside the kernels (``quiet``: the form's quiet coefficients, tested
    per lane)."""
    coef = coefficient_type(names, quiet)(*(float(v) for v in p))
    return fn(float(t), tuple(float(v) for v in y), coef, float(s), float(c))


# ---------------------------------------------------------------------------------------------
# the generated layouts

def _tuple_text(fmt: str, n: int) -> str:
    return "(" + "".join(fmt.format(q=q) + ", " for q in range(n)) + ")"


def _stores(target: str, n: int) -> list[str]:
    return [f"{target.format(q=q)} = v[{q}]" for q in range(n)] or ["pass"]


#: The decorator of a lane function compiled once and inlined by LLVM where it is called
#: (``forceinline``); compiled code calls it, never C (no C entry point: it cost compile time).
_LANE_DECO = "@nb.njit(forceinline=True, no_cfunc_wrapper=True, **_JIT)"


def _fn(head: str, body: list[str], inline: bool = False) -> str:
    deco = "@nb.njit(inline=\"always\", **_JIT)" if inline else "@nb.njit(**_JIT)"
    return f"\n\n{deco}\ndef {head}:\n" + "".join(f"    {line}\n" for line in body)


def _quiet_tuple(names: tuple[str, ...], quiet: tuple[str, ...], row: str) -> str:
    """The coefficient tuple's text with the ``quiet`` fields the constant 0.0."""
    return "(" + "".join(("0.0" if n in quiet else row.format(q=q)) + ", "
                         for q, n in enumerate(names)) + ")"


def _quiet_test(form: OneForm, row: str) -> str:
    """The text of the test that the lane's ``quiet`` coefficients are all 0."""
    return " & ".join(f"({row.format(q=form.coefficients.index(n))} == 0.0)"
                      for n in form.quiet)


def adapters(form: OneForm) -> str:
    """Python source defining the kernel interface's functions (every layout, see the module
    docstring) from the one form's ``one_rhs``, ``one_events`` and ``one_observe`` (names the
    generated module imports), for a model of ``form``'s sizes and coefficients."""
    ns, ne, no = form.n_states, form.n_events, form.n_observables
    nc = len(form.coefficients)
    quiet = bool(form.quiet)
    type_args = repr(tuple(form.coefficients)) + (f", {tuple(form.quiet)!r}" if quiet else "")
    out = [
        "\n# The model's one form (geardyn.core.one_form): every layout generated from it.",
        "from geardyn.core.kernel_source import FORM_QUIET as _ONE_FORM",
        "from geardyn.core.one_form import coefficient_type as _coefficient_type",
        f"_Coef = _coefficient_type({type_args})",
        "from geardyn._jit_target import WidthCompiler as _WidthCompiler",
        "_ONE_INLINE = {\"inline\": \"always\", \"error_model\": \"numpy\", "
        "\"boundscheck\": False, \"pipeline_class\": _WidthCompiler}",
    ]
    if quiet:
        out += ["from geardyn.core.kernel_source import FORM_LOAD as _ONE_LOUD",
                f"_CoefQuiet = _coefficient_type({type_args}, \"quiet\")",
                f"_CoefLoud = _coefficient_type({type_args}, \"loud\")"]
    for name, n in (("rhs", ns), ("events", ne), ("observe", no)):
        if name == "rhs" or n > 0:
            out.append(f"_one_{name} = nb.njit(**_ONE_INLINE)(one_{name}.py_func)")
    text = "\n".join(out) + "\n"
    text += _fn("_coef(p)", [f"return _Coef{_tuple_text('p[{q}]', nc)}"], inline=True)
    text += _fn("_coef_lane(PT, k)", [f"return _Coef{_tuple_text('PT[{q}, k]', nc)}"],
                inline=True)
    if quiet:
        text += _fn("_coef_quiet(PT, k)", [
            f"return _CoefQuiet{_quiet_tuple(form.coefficients, form.quiet, 'PT[{q}, k]')}"],
            inline=True)
        text += _fn("_coef_loud(PT, k)", [
            f"return _CoefLoud{_tuple_text('PT[{q}, k]', nc)}"], inline=True)
        text += _forms(form)
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
            blk_body = _block_loop(call, y_blk, blk, n, "_coef_lane")
            if quiet and name != "events":
                blk_body = ["quiet = True", "for k in range(nl):",
                            f"    quiet &= {_quiet_test(form, 'PT[{q}, k]')}",
                            "if quiet:",
                            *("    " + line for line in _block_loop(call, y_blk, blk, n,
                                                                    "_coef_quiet")),
                            "    return",
                            *blk_body]
            lane_body = [f"return {call}(t, y, _coef_lane(PT, k), s, c)"]
            if not quiet and name != "events":  # compiled once (see _forms)
                text += (f"\n\n{_LANE_DECO}\ndef _{name}_lane_one"
                         f"(t, y, PT, k, s, c):\n"
                         f"    return {call}(t, y, _coef_lane(PT, k), s, c)\n")
                lane_body = [f"return _{name}_lane_one(t, y, PT, k, s, c)"]
            if quiet and name != "events":  # the form's own compiled function (see _forms)
                lane_body = ["if form == _ONE_FORM:",
                             f"    return _{name}_lane_quiet(t, y, PT, k, s, c)",
                             "if form == _ONE_LOUD:",
                             f"    return _{name}_lane_loud(t, y, PT, k, s, c)",
                             # FORM_GENERAL (the split path, a mixed queue): tested by lane
                             f"return _{name}_lane_general(t, y, PT, k, s, c)"]
        text += _fn(f"{name}(t, y, {arr}, p, s, c)", body)
        text += _fn(f"{name}_lanes(T, Y, {blk}, PT, nl, S, C{sc})", blk_body)
        form_arg = "" if name == "events" else ", form"
        text += _fn(f"{name}_lane(t, y, PT, k, s, c{form_arg})", lane_body, inline=True)
    text += f"\n\n#: The state size of the lane-scalar forms.\nrhs_lane_states = {ns}\n"
    text += (f"#: The number of switching functions (the size of ``events_lane``'s tuple).\n"
             f"events_lane_count = {form.n_events}\n")
    if quiet:
        text += _fn("rhs_lane_form(PT, k)", [
            f"if {_quiet_test(form, 'PT[{q}, k]')}:", "    return _ONE_FORM",
            "return _ONE_LOUD"])
    else:
        text += _fn("rhs_lane_form(PT, k)", ["return _ONE_FORM"])
    return text


def _forms(form: OneForm) -> str:
    """The lane-scalar functions of a model with ``quiet`` coefficients, one compiled function
    per lane form (``_rhs_lane_quiet``: :func:`loud` False, the quiet coefficients constant
    zeros; ``_rhs_lane_loud``: :func:`loud` True; ``_rhs_lane_general``: tested) and so for
    ``observe``. Each is compiled once and inlined by LLVM where it is called (``forceinline``:
    the fused loops still vectorise); ``rhs_lane(..., form)``, which numba inlines, calls the
    one of ``form``, so that a kernel's copy of its fused loop for a constant form types that
    call alone."""
    text = ""
    for name, n in (("rhs", form.n_states), ("observe", form.n_observables)):
        if name != "rhs" and n == 0:
            continue
        kinds = (("quiet", "_coef_quiet"), ("loud", "_coef_loud"), ("general", "_coef_lane"))
        for kind, coef in kinds:
            text += f"\n\n{_LANE_DECO}\ndef _{name}_lane_{kind}" \
                    f"(t, y, PT, k, s, c):\n    return _one_{name}(t, y, {coef}(PT, k), s, c)\n"
    return text


def _block_loop(call: str, y_blk: str, blk: str, n: int, coef: str) -> list[str]:
    """The lane-block form's loop over lanes 0..nl-1, the coefficients by ``coef``."""
    return ["for k in range(nl):",
            f"    v = {call}(T[k], {y_blk}, {coef}(PT, k), S[k], C[k])",
            *("    " + line for line in _stores(blk + "[{q}, k]", n))]


def tangent_adapters(form: OneForm) -> str:
    """Python source defining the tangent forms of the one form's ``rhs`` (for the variational
    Lyapunov kernel; spliced after :func:`adapters`' text, whose names it uses): the array form
    ``rhs_tangent(t, y, v, dy, dv, p, s, c)`` (dy = f(t, y), dv = J(t, y) v, J the Jacobian in
    the state) and the lane-scalar form ``rhs_lane_tangent(t, y, v, PT, k, s, c, form)`` (the
    tuples (f, J v)). Both call the one form's ``rhs`` with the state a tuple of duals
    (:mod:`geardyn.core.dual`): the same physics, differentiated exactly; f bitwise that of
    ``rhs``. Every compiled function's arguments and results are floats (the duals live
    inside)."""
    ns = form.n_states
    quiet = bool(form.quiet)
    duals = "(" + "".join(f"_dual(y[{q}], v[{q}]), " for q in range(ns)) + ")"
    out = ("\n# The tangent forms of the one form's rhs (geardyn.core.one_form.tangent_adapters).\n"
           "from geardyn.core.dual import dual as _dual\n"
           "from geardyn.core.dual import tangent_of as _tangent_of\n"
           "from geardyn.core.dual import value_of as _value_of\n")
    out += _fn("_tangent_parts(d)", [
        "return (" + _tuple_text("_value_of(d[{q}])", ns) + ", "
        + _tuple_text("_tangent_of(d[{q}])", ns) + ")"], inline=True)
    # a quiet term is tested per lane (``loud``) in the array form, as in ``rhs``
    body = [f"d = _one_rhs(t, {duals}, _coef(p), s, c)", "f, w = _tangent_parts(d)",
            *(f"dy[{q}] = f[{q}]" for q in range(ns)), *(f"dv[{q}] = w[{q}]" for q in range(ns))]
    # compiled once and inlined by LLVM where it is called (as the array form ``rhs`` is in
    # the kernels' step core: ``_rhs_i``)
    out += _fn("rhs_tangent(t, y, v, dy, dv, p, s, c)", body).replace(
        "@nb.njit(**_JIT)", "@nb.njit(forceinline=True, _nrt=False, **_JIT)")
    if quiet:
        for kind, coef in (("quiet", "_coef_quiet"), ("loud", "_coef_loud"),
                           ("general", "_coef_lane")):
            out += (f"\n\n{_LANE_DECO}\ndef _rhs_tangent_lane_{kind}"
                    f"(t, y, v, PT, k, s, c):\n    return _tangent_parts(_one_rhs(t, {duals}, "
                    f"{coef}(PT, k), s, c))\n")
        # the lane forms as in ``rhs_lane`` (FORM_GENERAL: ``loud`` tested by lane)
        lane_body = ["if form == _ONE_FORM:",
                     "    return _rhs_tangent_lane_quiet(t, y, v, PT, k, s, c)",
                     "if form == _ONE_LOUD:",
                     "    return _rhs_tangent_lane_loud(t, y, v, PT, k, s, c)",
                     "return _rhs_tangent_lane_general(t, y, v, PT, k, s, c)"]
    else:  # compiled once and inlined by LLVM where it is called (as ``rhs_lane``)
        out += (f"\n\n{_LANE_DECO}\ndef _rhs_tangent_lane_one"
                f"(t, y, v, PT, k, s, c):\n    return _tangent_parts(_one_rhs(t, {duals}, "
                f"_coef_lane(PT, k), s, c))\n")
        lane_body = ["return _rhs_tangent_lane_one(t, y, v, PT, k, s, c)"]
    out += _fn("rhs_lane_tangent(t, y, v, PT, k, s, c, form)", lane_body, inline=True)
    return out
