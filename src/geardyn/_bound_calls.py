"""Calls of big callees bound to one copy of their machine code per process.

numba links the optimised LLVM IR of every function a caller calls into the caller's module
(``linkonce_odr``), so each caller optimises the callee's body again and emits its own copy of
its machine code. A geardyn function whose own optimised function is big
(:data:`MIN_INSTRUCTIONS`) is instead declared in its geardyn callers' modules, with the
function, return and argument attributes of its optimised definition (what the linked copy
told the caller's optimisation), and the call is bound by numba's engine (MCJIT resolves
symbols across the modules added to it) to the callee's one compiled copy, emitted before the
caller's (:mod:`geardyn._lazy_code` defers it until then).

numba's cache: a caller's object code then references the callee's symbol, so the caller's
``reload_init`` (callables numba runs before it loads the code of a cached function) holds a
:class:`Loader` of every bound symbol its module declares: the callee's object code, loaded
unless the process defines the symbol already (the callee's own entry loaded or compiled
first: geardyn numbers its symbols per process, so the same symbol is the same code). A
callee loaded from the cache as numba's deferred ``bitcode`` kind is bound too
(:func:`_register`); one cached as object code is linked (:func:`register_loaded`).

A bound callee's module is optimised twice (:data:`REOPTIMISE`), as a linked copy is (once in
its own module, once more in each caller's): optimised once, the reduced CATT device's sweep
block ran the paper workload 1.19x slower. A cold callee marked by :func:`optimise_once` (the
sweep's out-of-line slot work) is optimised once: its second optimisation cost compile time
for no measurable speed.

Only geardyn's functions are changed (:func:`prepare`, called by
:class:`geardyn._jit_target.VectorWidthPass` on each library it creates; no process-wide
patch); a plain numba function calling a geardyn function links it as numba does.
``GEARDYN_BIND=0`` (environment, read at import) switches the binding off and
``GEARDYN_BIND_MIN`` sets :data:`MIN_INSTRUCTIONS` (the benchmarks' and tests' knobs).
"""

from __future__ import annotations

import ctypes
import os
import re
from typing import Any

import llvmlite.binding as ll

from geardyn import _lazy_code

#: A callee's own function with at least this many LLVM instructions (after its own
#: optimisation) is bound, not linked. In the gear pair's and the planetary set's compiles LLVM
#: called, never inlined, every geardyn function that big; below it, it inlined some (the
#: planetary set's ``_rhs_body``, 1017 instructions, into its one caller: LLVM inlines a
#: ``linkonce_odr`` function with one call whatever its size).
MIN_INSTRUCTIONS = int(os.environ.get("GEARDYN_BIND_MIN", "1100"))
#: A bound callee's module is optimised twice (``GEARDYN_BIND_REOPT=0``: once).
REOPTIMISE = os.environ.get("GEARDYN_BIND_REOPT", "1") != "0"
#: ``GEARDYN_BIND=0`` switches the binding off (A/B measurements).
ENABLED = os.environ.get("GEARDYN_BIND", "1") != "0"

#: The attribute of a Python function whose compiled code, bound, is optimised once
#: (:func:`optimise_once`).
ONCE = "_geardyn_optimise_once"


def optimise_once(dispatcher: Any) -> Any:
    """Mark ``dispatcher`` (a numba function, cold: called out of a hot loop's line) to be
    optimised once where it is bound, not twice (:data:`REOPTIMISE`); returns it."""
    setattr(dispatcher.py_func, ONCE, True)
    return dispatcher


#: The attribute of a Python function whose compiled code is bound whatever its size
#: (:func:`always_bind`).
ALWAYS = "_geardyn_always_bind"


def always_bind(dispatcher: Any) -> Any:
    """Mark ``dispatcher`` (a numba function) to be bound in its callers whatever its size, not
    linked into each (where it is below :data:`MIN_INSTRUCTIONS`): a function called at few
    sites, rarely (a loop called once per run of steps), that several callers would otherwise
    each optimise again; returns it."""
    setattr(dispatcher.py_func, ALWAYS, True)
    _ALWAYS_NAMES.add(dispatcher.py_func.__qualname__)
    return dispatcher


#: The names of the functions marked by :func:`always_bind` (numba names a function's library
#: by them: a library loaded from numba's cache has no compile to say it).
_ALWAYS_NAMES: set[str] = set()


def _always(library: Any) -> bool:
    """Whether ``library``'s function is bound whatever its size (:func:`always_bind`)."""
    return getattr(library, "_geardyn_always", library.name in _ALWAYS_NAMES)


#: symbol -> (return attributes, function attributes, [attributes per argument])
DECLS: dict[str, tuple[list[str], list[str], list[list[str]]]] = {}

_DEFINE = re.compile(r"^define\s+(.*?)\s+i32\s+@")
_LINKAGE = {"internal", "private", "external", "linkonce_odr", "linkonce", "weak", "weak_odr",
            "dso_local", "hidden", "protected", "default", "available_externally"}


def _at_least(fn: Any, count: int) -> bool:
    """Whether ``fn`` (a defined llvmlite binding function) has ``count`` instructions."""
    n = 0
    for block in fn.blocks:
        for _ in block.instructions:
            n += 1
            if n >= count:
                return True
    return False


def _declaration(fn: Any) -> tuple[list[str], list[str], list[list[str]]]:
    """The attributes of ``fn`` (a defined llvmlite binding function) for a declaration."""
    text = str(fn)
    fattrs: list[str] = []
    ret: list[str] = []
    for line in text.splitlines():
        if line.startswith("; Function Attrs:"):
            fattrs = [line[len("; Function Attrs:"):].strip()]
        elif line.startswith("define"):
            m = _DEFINE.match(line)
            if m:
                words = m.group(1).split()
                while words and words[0] in _LINKAGE:
                    words.pop(0)
                ret = [" ".join(words)] if words else []
            break
    args = [[a.decode() for a in arg.attributes] for arg in fn.arguments]
    return ret, fattrs, args


def _big(module: Any, linkage: Any, always: bool = False) -> list:
    """The functions ``module`` defines with ``linkage`` (wrappers left out) that are big
    enough to be bound (any size with ``always``: :func:`always_bind`); not those marked to be
    inlined at every call site (numba's ``forceinline``: LLVM's ``alwaysinline``), which their
    callers link and inline."""
    return [fn for fn in module.functions
            if not fn.is_declaration and fn.linkage == linkage
            and not fn.name.startswith(("cpython.", "cfunc.", "_ZN7cpython", "_ZN5cfunc"))
            and not any(b"alwaysinline" in attrs.split() for attrs in fn.attributes)
            and (always or _at_least(fn, MIN_INSTRUCTIONS))]


def _bind(library: Any, fn: Any, entry: Any) -> None:
    DECLS[fn.name] = _declaration(fn)
    library._geardyn_bound = True
    library._geardyn_symbols = (*getattr(library, "_geardyn_symbols", ()), fn.name)
    _BOUND.setdefault(fn.name, entry)


def _register(library: Any) -> None:
    """If ``library``'s own function (its final module's) is big, record its declaration and
    mark it bound: its callers bind to it."""
    if hasattr(library, "_geardyn_bound"):
        return
    library._geardyn_bound = False
    for fn in (_big(library._final_module, ll.Linkage.external, _always(library)) if ENABLED
               else ()):
        _bind(library, fn, library)


def register_loaded(library: Any) -> None:
    """``library`` was loaded from numba's cache as object code (numba's ``object`` kind: a
    function compiled as the outermost one, optimised once, such as the split step compiled
    ahead in a helper process): its callers link it, as numba does, and optimise it once more
    (bound, its code would be the once-optimised one)."""
    library._geardyn_bound = False


def _envs(module: Any) -> tuple:
    """The numba environments ``module`` defines (numba's ``_find_referenced_environments``)."""
    from numba.core.environment import lookup_environment

    out = []
    for gv in module.global_variables:
        if gv.name.startswith("_ZN08NumbaEnv") and not gv.is_declaration:
            env = lookup_environment(gv.name)
            if env is not None and env.can_cache():
                out.append(env)
    return tuple(out)


def _apply(ir_module: Any) -> None:
    """Put the recorded attributes on the declarations of bound callees in ``ir_module``."""
    for fn in ir_module.functions:
        if fn.blocks:
            continue
        decl = DECLS.get(fn.name)
        if decl is None:
            continue
        ret, fattrs, args = decl
        for a in ret:
            set.add(fn.return_value.attributes, a)
        for a in fattrs:
            set.add(fn.attributes, a)
        for arg, attrs in zip(fn.args, args, strict=True):
            for a in attrs:
                set.add(arg.attributes, a)


class Loader:
    """Makes a bound callee's machine code exist in numba's engine before a caller compiled
    against it is loaded from numba's cache (in the caller's ``reload_init``, which numba runs
    before it loads the caller's object code): the callee's code as numba serialises it (its
    object code), loaded unless the process already defines its symbol, after the bound
    callees it calls in turn."""

    def __init__(self, symbol: str, state: tuple, deps: tuple, envs: tuple) -> None:
        self.symbol, self.state, self.deps, self.envs = symbol, state, deps, envs

    def __call__(self) -> None:
        for dep in self.deps:
            dep()
        from numba.core.compiler_lock import global_compiler_lock
        from numba.core.registry import cpu_target

        with global_compiler_lock:
            _BOUND.setdefault(self.symbol, self)
            codegen = cpu_target.target_context.codegen()
            engine = codegen._engine
            if engine.is_symbol_defined(self.symbol):
                return
            _LOADED.append(_lazy_code._ORIGINAL_UNSERIALIZE(codegen, self.state))
            _BOUND[self.symbol] = self  # the copy bound to (a library of it is not emitted)
            for env in self.envs:  # as numba sets a loaded function's environments
                address = engine.get_global_value_address(env.env_name)
                if address:
                    (ctypes.c_void_p * 1).from_address(address)[0] = ctypes.c_void_p(id(env))

    def __hash__(self) -> int:
        return hash(self.symbol)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Loader) and other.symbol == self.symbol


#: Bound symbols of this process: symbol -> its library (machine code emitted or deferred) or
#: its :class:`Loader`.
_BOUND: dict[str, Any] = {}
#: Libraries loaded by a :class:`Loader` (kept alive: their code is bound to).
_LOADED: list = []


def _loader(symbol: str) -> Loader:
    """The :class:`Loader` of bound ``symbol`` (its machine code exists in this process)."""
    entry = _BOUND[symbol]
    if isinstance(entry, Loader):
        return entry
    _emit(entry)
    deps = tuple(_loader(name) for name in _bound_declarations(entry._final_module))
    loader = Loader(symbol, entry.serialize_using_object_code(), deps,
                    _envs(entry._final_module))
    _BOUND[symbol] = loader
    return loader


def _bound_declarations(module: Any) -> list[str]:
    """The bound symbols ``module`` declares (calls, not defines)."""
    return [fn.name for fn in module.functions if fn.is_declaration and fn.name in _BOUND]


def _emit(library: Any) -> None:
    """Emit a bound callee's machine code (once per symbol in the process)."""
    if _lazy_code.is_pending(library):
        _lazy_code._materialise(library)


def _finalize(library: Any, reload_init: list) -> None:
    """numba's ``finalize`` with bound callees declared, not linked, and emitted first; the
    :class:`Loader` of every bound symbol the final module declares in its ``reload_init`` and
    in its compile's ``reload_init`` list (what numba's cache saves: a ``cfunc`` is finalized
    after its compile result took that list, when the cache serialises it)."""
    keep = []
    for lib in library._linking_libraries:
        lib._ensure_finalized()
        if getattr(lib, "_geardyn_bound", False):
            library._reload_init.update(lib._reload_init)
            _emit(lib)
        else:
            keep.append(lib)
    library._linking_libraries = keep
    type(library).finalize(library)
    if (REOPTIMISE and not getattr(library, "_geardyn_once", False)
            and _lazy_code.is_pending(library)
            and _big(library._final_module, ll.Linkage.external, _always(library))):
        # a callee (its code not emitted yet) that will be bound: optimised once more, as
        # numba's linking optimises a linked copy once more in each caller
        library._optimize_final_module()
    for name in _bound_declarations(library._final_module):
        library._reload_init.add(_loader(name))
    reload_init.extend(f for f in library._reload_init if f not in reload_init)
    _register(library)


def prepare(library: Any, reload_init: list, func: Any = None) -> None:
    """Make ``library`` (a geardyn function's numba code library) declare its bound callees;
    ``reload_init`` is its compile's list of numba's reload callables (``state.reload_init``),
    ``func`` the Python function compiled (marked by :func:`optimise_once`,
    :func:`always_bind` or not)."""
    library._geardyn_once = bool(getattr(func, ONCE, False))
    library._geardyn_always = bool(getattr(func, ALWAYS, False))
    add = library.add_ir_module

    def add_ir_module(ir_module: Any) -> None:
        _apply(ir_module)
        add(ir_module)

    library.add_ir_module = add_ir_module
    library.finalize = lambda: _finalize(library, reload_init)


_lazy_code.ON_LOADED[0] = register_loaded
_lazy_code.ON_DEFERRED[0] = _register
