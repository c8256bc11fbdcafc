"""Machine code of a function compiled inside a geardyn compile emitted when first needed.

numba compiles a function called by another numba function (a callee, compiled while its caller
is typed: geardyn's split step and slot work, numba's own helpers such as ``np.empty``'s) into a
code library of its own, emits that library's machine code (LLVM's code generator) and makes
its Python entry point; the caller then links the callee's optimised LLVM IR into its own
library and emits its own machine code, with its own copy of the callee. A callee's own machine
code serves a call from Python, and a call that LLVM did not inline in a caller emitted later
in the same process (numba's engine binds it to the first definition of the symbol; in a
process that loads the caller from the cache, to the caller's own copy). A big callee is
declared in its callers instead, and bound to its own machine code (:mod:`geardyn._bound_calls`).

Inside a geardyn compile (:func:`scope`, entered by :class:`geardyn._jit_target.WidthCompiler`)
every function compiled for it except the outermost one (:func:`mark_outermost`, the one Python
calls) is deferred (:func:`defer`): its library is linked and optimised as numba does it, ready
to be linked into callers, and stops before the machine code, which is emitted on first need
(:func:`_materialise`):

* its Python entry point is a stand-in of numba's kind (a compiled wrapper calling
  :func:`_resolve`) until it is first called from Python, which emits the machine code and
  calls the function's own wrapper from then on;
* its environment (numba's per-function object, read by the function's code and by every
  caller's inlined copy of it) is put in place before any code compiled with it can run, in a
  module that defines the environment symbols of the compile's deferred functions
  (:func:`_flush_envs`), so that callers read it as numba's own code would;
* numba's cache stores the library as numba's ``bitcode`` kind (the optimised module; numba
  emits its machine code when it loads it) until its machine code exists, then as numba's
  ``object`` kind; a ``bitcode`` entry loaded inside a geardyn compile is deferred again.

Callers are compiled from the same optimised IR as before, so their machine code is the same;
their calls that LLVM did not inline bind to their own copy, as in a process that loads them
from the cache. numba's CPU context and codegen are patched only inside :func:`scope` (a
:func:`geardyn._scoped_patch.scoped_patch` guard); the deferred libraries carry their own
methods.
"""

from __future__ import annotations

import ctypes
from collections.abc import Iterator
from typing import Any

import llvmlite.binding as ll
from numba._dynfunc import make_function
from numba.core import codegen as _codegen
from numba.core import cpu as _cpu
from numba.core.compiler_lock import global_compiler_lock

from geardyn._scoped_patch import scoped_patch

_ORIGINAL_GET_EXECUTABLE = _cpu.CPUContext.get_executable
_ORIGINAL_UNSERIALIZE = _codegen.JITCPUCodegen.unserialize_library
_FINALIZE_FINAL_MODULE = _codegen.CPUCodeLibrary._finalize_final_module
_GET_POINTER = _codegen.JITCodeLibrary.get_pointer_to_function
_SERIALIZE_OBJECT = _codegen.CPUCodeLibrary.serialize_using_object_code

#: Per stand-in entry point (keyed by ``id`` of its ``__self__``): what :func:`_resolve` needs.
_ENTRIES: dict[int, list] = {}
#: Environment symbols to define and set (:func:`_flush_envs`): name -> (codegen, environment).
_PENDING_ENVS: dict[str, tuple] = {}


def _ignore(library: Any) -> None:
    """No-op: the default of :data:`ON_LOADED` and :data:`ON_DEFERRED`."""


#: Called with each library loaded from numba's cache as object code, and with each loaded as
#: deferred optimised IR (one-item lists, so that :mod:`geardyn._bound_calls`, which imports
#: this module, sets them at its import: its ``register_loaded`` and ``_register``).
ON_LOADED: list = [_ignore]
ON_DEFERRED: list = [_ignore]
#: The libraries defining environment symbols ahead of their function's machine code.
_ENV_LIBRARIES: list = []
#: The stand-in wrapper's machine code (its library and address), made on first use.
_STUB: list = []


def defer(library: Any) -> None:
    """Make ``library`` (a numba JIT code library not yet finalised) stop before its machine
    code when finalised, and emit it when first needed (see the module docstring)."""
    library._geardyn_pending = False

    def finalize_final_module() -> None:
        # what numba's _finalize_final_module does before handing the module to the engine
        library._finalize_dynamic_globals()
        library._verify_declare_only_symbols()
        library._finalized = True
        library._geardyn_pending = True

    def get_pointer_to_function(name: str) -> int:
        _materialise(library)
        return _GET_POINTER(library, name)

    def serialize_using_object_code() -> tuple:
        if library._geardyn_pending:
            return library.serialize_using_bitcode()
        return _SERIALIZE_OBJECT(library)

    def get_compiled_object() -> bytes:
        _materialise(library)
        return type(library)._get_compiled_object(library)

    library._finalize_final_module = finalize_final_module
    library.get_pointer_to_function = get_pointer_to_function
    library.serialize_using_object_code = serialize_using_object_code
    library._get_compiled_object = get_compiled_object


def mark_outermost(library: Any) -> None:
    """``library`` is the outermost function of a geardyn compile (called from Python): its
    machine code is emitted at once, as numba does."""
    library._geardyn_outermost = True


def is_pending(library: Any) -> bool:
    """Whether ``library``'s machine code is deferred and not yet emitted."""
    return bool(getattr(library, "_geardyn_pending", False))


def _materialise(library: Any) -> None:
    """Emit ``library``'s machine code now (numba's own last step of finalising), once."""
    with global_compiler_lock:
        if library._geardyn_pending:
            library._geardyn_pending = False
            symbols = getattr(library, "_geardyn_symbols", ())
            if symbols and all(map(library.codegen._engine.is_symbol_defined, symbols)):
                return  # its code loaded already (geardyn._bound_calls.Loader): that copy serves
            library._dynamic_globals = []  # numba's step collects them again
            _FINALIZE_FINAL_MODULE(library)


def _set_env(codegen: Any, name: str, env: Any) -> None:
    """numba's ``set_env``: the environment symbol ``name`` points to ``env``. A symbol that no
    module in the engine defines yet waits for :func:`_flush_envs`."""
    address = codegen._engine.get_global_value_address(name)
    if address:
        (ctypes.c_void_p * 1).from_address(address)[0] = ctypes.c_void_p(id(env))
    else:
        _PENDING_ENVS[name] = (codegen, env)


def _flush_envs() -> None:
    """Define the environment symbols waiting since :func:`_set_env` in one module of their
    own (numba's ``common`` globals: a module emitted later that defines one binds to it, and a
    module emitted earlier keeps its own, which is then the one set) and set them. Runs before
    any code compiled meanwhile can run: when the outermost compile returns, and before a call
    through a stand-in entry point."""
    with global_compiler_lock:
        if not _PENDING_ENVS:
            return
        items = list(_PENDING_ENVS.items())
        _PENDING_ENVS.clear()
        codegen = items[0][1][0]
        library = codegen.create_library(f"geardyn_envs_{len(_ENV_LIBRARIES)}")
        module = ll.parse_assembly("".join(f'@"{name}" = common global i8* null\n'
                                           for name, _ in items))
        module.name = library.name
        library.add_llvm_module(module)
        library.finalize()
        _ENV_LIBRARIES.append(library)
        for name, (owner, env) in items:
            _set_env(owner, name, env)


def _resolve(closure: Any, args: tuple) -> Any:
    """Called by a stand-in entry point (``closure`` its ``__self__``): emit the function's
    machine code, make its own entry point (once) and call it with ``args``."""
    entry = _ENTRIES[id(closure)]
    if entry[4] is None:
        context, library, fndesc, env = entry[:4]
        entry[4] = _ORIGINAL_GET_EXECUTABLE(context, library, fndesc, env)
    _flush_envs()
    return entry[4](*args)


def _stub_address() -> int:
    """The address of the stand-in wrapper: ``PyObject *f(self, args, kws)`` returning
    ``_resolve(self, args)`` (numba's wrappers take the arguments as a tuple; keywords are
    folded into it before the call)."""
    if not _STUB:
        ir = (
            "declare i8* @PyObject_CallFunctionObjArgs(i8*, ...)\n"
            "define i8* @geardyn_lazy_entry(i8* %self, i8* %args, i8* %kws) {\n"
            "entry:\n"
            f"  %r = call i8* (i8*, ...) @PyObject_CallFunctionObjArgs(i8* inttoptr "
            f"(i64 {id(_resolve)} to i8*), i8* %self, i8* %args, i8* null)\n"
            "  ret i8* %r\n"
            "}\n")
        from numba.core.registry import cpu_target

        with global_compiler_lock:
            library = cpu_target.target_context.codegen().create_library("geardyn_lazy_entry")
            module = ll.parse_assembly(ir)
            module.name = "geardyn_lazy_entry"
            library.add_llvm_module(module)
            library.finalize()
            _STUB[:] = [library, library.get_pointer_to_function("geardyn_lazy_entry")]
    return _STUB[1]


def _get_executable(self: Any, library: Any, fndesc: Any, env: Any) -> Any:
    """numba's ``CPUContext.get_executable``; for a deferred library, a stand-in entry point
    (its machine code not emitted) and the environment in place."""
    if (not library._finalized and not getattr(library, "_geardyn_outermost", False)
            and not hasattr(library, "_geardyn_pending")):
        defer(library)  # a callee of the geardyn compile under way
    library._ensure_finalized()
    if not is_pending(library):
        return _ORIGINAL_GET_EXECUTABLE(self, library, fndesc, env)
    doc = f"compiled wrapper for {fndesc.qualname!r} (machine code on first call)"
    cfunc = make_function(fndesc.lookup_module(), fndesc.qualname.split(".")[-1], doc,
                          _stub_address(), env, (library,))
    _ENTRIES[id(cfunc.__self__)] = [self, library, fndesc, env, None, cfunc]
    _set_env(library.codegen, self.get_env_name(fndesc), env)
    return cfunc


def _set_env_method(self: Any, env_name: str, env: Any) -> None:
    _set_env(self, env_name, env)


def _unserialize_library(self: Any, serialized: tuple) -> Any:
    """numba's ``unserialize_library``; a ``bitcode`` entry (a deferred library, see
    :func:`defer`) is deferred again."""
    name, kind, data = serialized
    if kind != "bitcode":
        library = _ORIGINAL_UNSERIALIZE(self, serialized)
        ON_LOADED[0](library)
        return library
    library = self.create_library(name)
    library.enable_object_caching()
    defer(library)
    library._final_module = ll.parse_bitcode(data)
    library._finalize_final_module()
    ON_DEFERRED[0](library)
    return library


@scoped_patch
def scope() -> Iterator[None]:
    """numba's CPU context and codegen with the deferral's steps while geardyn compiles
    (re-entrant; :attr:`scope.depth` > 1 inside a nested geardyn compile)."""
    context, jit = _cpu.CPUContext, _codegen.JITCPUCodegen
    saved = context.get_executable, jit.unserialize_library, jit.set_env
    context.get_executable = _get_executable
    jit.unserialize_library = _unserialize_library
    jit.set_env = _set_env_method
    yield
    _flush_envs()
    context.get_executable, jit.unserialize_library, jit.set_env = saved
