"""Per-model compiled kernels: the RK4 template specialised to a model's right-hand side.

numba cannot cache a kernel that receives the right-hand side as an argument (the function's type
is tied to the process), so geardyn writes, once per model, a copy of
:mod:`geardyn.solvers._kernel_template` whose import line names the model's functions, into
``$GEARDYN_CACHE_DIR/kernels`` (default ``~/.cache/geardyn/kernels``), and imports it. The file name
is a hash of the template and of the model's source, so an edited model gets a new kernel (the
model's step machinery, :mod:`._step_core`, is one such module per model, ``core``, which the
model's other kernel modules import: compiled once per model, not once per template; what does
not depend on the model, :data:`SHARED_MODULES`, is ordinary modules, compiled once for every
model); numba
caches the compiled code in ``$NUMBA_CACHE_DIR`` (default ``$GEARDYN_CACHE_DIR/numba``; the
kernels' in its ``kernels`` folder, whatever the cache's path, see :mod:`geardyn._cache`), and a
second run, or a run on a copy of the cache folder, does not recompile. Functions that cannot be
imported by name (defined in ``__main__`` or a notebook) get an in-memory kernel, compiled once per
process.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import importlib.util
import inspect
import itertools
import os
import secrets
import sys
import tempfile
import types
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numba
import numba.core.bytecode
from numba.core.compiler_lock import global_compiler_lock

from geardyn._cache import cache_root
from geardyn._frame_room import call_with_room
from geardyn._scoped_patch import scoped_patch
from geardyn.core.kernel_source import KernelSource
from geardyn.core.one_form import adapters as one_form_adapters
from geardyn.core.one_form import tangent_adapters
from geardyn.solvers import _pointer_calls, compile_share
from geardyn.solvers import _pointer_kernels as pointer
from geardyn.solvers._compile_gc import young_collections
from geardyn.solvers._inline_copy import block_copy, overload_keys

_IMPORT_MARK = "# MODEL-IMPORT"
_CORE_MARK = "# CORE-IMPORT"
_PLAIN_ADAPTERS = """

@nb.njit(**_JIT)
def rhs(t, y, dy, p, s, c):
    user_rhs(t, y, dy, p)


@nb.njit(**_JIT)
def observe(t, y, out, p, s, c):
    user_observe(t, y, out, p)
"""

_EVENTS_ADAPTER = """

@nb.njit(**_JIT)
def events(t, y, g, p, s, c):
    user_events(t, y, g, p)
"""

_LOADED: dict[tuple, types.ModuleType] = {}

#: numba's warnings silenced while geardyn's generated kernels compile: its internal pedantic check
#: (NumbaIRAssumptionWarning, "please report") and its debug-line notes (NumbaDebugInfoWarning)
#: fire hundreds of times on the inlined tuple helpers and say nothing about a model or a result.
QUIET_WARNINGS = (numba.core.errors.NumbaIRAssumptionWarning,
                  numba.core.errors.NumbaDebugInfoWarning)


#: Serialises the scoped filters of :func:`_quiet_compile`: ``warnings.catch_warnings`` saves
#: and restores the process's filter list, so two threads compiling at once (the sweep's workers
#: start on threads) would interleave and could leave a filter installed. It is numba's own
#: re-entrant compiler lock (numba compiles under it anyway, so this costs no parallelism, and
#: one lock cannot be taken in two orders by a compile that calls another).
_COMPILE_LOCK = global_compiler_lock


#: geardyn's own numbering of the functions it compiles: (pid, counter from a random base).
_UIDS: list = [None, None]


def _uid_counter() -> itertools.count:
    """This process's counter (a new random base after a fork)."""
    if _UIDS[0] != os.getpid():
        _UIDS[:] = [os.getpid(), itertools.count(secrets.randbits(47) << 16)]
    return _UIDS[1]


@scoped_patch
def unique_names() -> Iterator[None]:
    """Number the functions compiled inside (numba's ``FunctionIdentity`` ids, part of every
    compiled symbol's and environment's name) from a random base of this process, and restore
    numba's own numbering afterwards (re-entrant); to be entered under numba's compiler lock.
    numba counts from 1 in every process, so the same function compiled early in two processes
    gets the same names; cached kernels from several processes, loaded into one, would define
    the same symbols, and the entry of a shared function called from Python can read another
    copy's environment (numba's "'descr' is NULL"). From a random base per process, code
    compiled in different processes shares no name."""
    ident = numba.core.bytecode.FunctionIdentity
    saved, ident._unique_ids = ident._unique_ids, _uid_counter()
    yield
    ident._unique_ids = saved


def _quiet_compile(dispatcher: Any, cached: bool = False) -> None:
    """Make ``dispatcher`` compile with :data:`QUIET_WARNINGS` ignored; the warning filters are
    restored when its compile returns (nothing is filtered outside geardyn's compiles), as are
    the garbage collector's thresholds (:func:`._compile_gc.young_collections`). A
    ``cached`` module's functions compile under their lock (:mod:`.compile_share`): one process
    compiles a function, the others load it from the cache."""
    compile_ = compile_share.shared(dispatcher, dispatcher.compile) if cached else (
        dispatcher.compile)

    def compile(sig: Any) -> Any:
        with _compiling():
            return call_with_room(compile_, sig)

    dispatcher.compile = compile


@contextlib.contextmanager
def _compiling() -> Iterator[None]:
    """The context of geardyn's compiles: the compiler lock, this process's function names
    (:func:`unique_names`), the block copy (:func:`._inline_copy.block_copy`), overload
    implementations kept per inherited flags (:func:`._inline_copy.overload_keys`), the collector's
    thresholds (:func:`._compile_gc.young_collections`), :data:`QUIET_WARNINGS` ignored."""
    with (_COMPILE_LOCK, unique_names(), block_copy(), overload_keys(), young_collections(),
          warnings.catch_warnings()):
        for category in QUIET_WARNINGS:
            warnings.filterwarnings("ignore", category=category)
        yield


def _quiet_module(module: types.ModuleType) -> None:
    """:func:`_quiet_compile` for every numba function ``module`` defines (the entry points; the
    functions they call compile inside their compile)."""
    cached = getattr(module, "__file__", None) is not None
    for value in list(vars(module).values()):
        if (isinstance(value, numba.core.registry.CPUDispatcher)
                and value.py_func.__module__ == module.__name__):
            _quiet_compile(value, cached)


def cache_dir() -> Path:
    """Where generated kernels live: ``kernels/`` in geardyn's cache folder
    (:func:`geardyn._cache.cache_root`: $GEARDYN_CACHE_DIR, default ~/.cache/geardyn)."""
    return cache_root() / "kernels"


def _importable(fn: Any) -> bool:
    py = getattr(fn, "py_func", fn)
    mod = sys.modules.get(py.__module__)
    return (
        mod is not None
        and py.__module__ != "__main__"
        and getattr(mod, "__file__", None) is not None
        and getattr(mod, py.__name__, None) is fn
    )


#: Kernel templates by name: module path of a file with a ``MODEL-IMPORT`` line.
TEMPLATES: dict[str, str] = {
    "rk4": "geardyn.solvers._kernel_template",
    "lyapunov": "geardyn.solvers._lyapunov_template",
    "monodromy": "geardyn.solvers._monodromy_template",
    "runup": "geardyn.solvers._runup_template",
}


def _core_text(adapters: str) -> str:
    """The shared step machinery (:mod:`._step_core`) as text to splice into a template, with
    ``adapters`` (definitions of the model interface names) at its ``MODEL-ADAPTERS`` line."""
    lines = inspect.getsource(importlib.import_module("geardyn.solvers._step_core")).splitlines()
    out = []
    for line in lines:
        if line.startswith("from __future__"):
            continue
        if line.startswith("# MODEL-ADAPTERS"):
            out.append(adapters)
        out.append(line)
    return "\n".join(out)


def _splice_core(text: str, adapters: str = "") -> str:
    """Replace the template's ``CORE-IMPORT`` statement (one line, or a parenthesised import
    starting on the marked line) by the shared core's text (see :func:`_core_text`)."""
    return _splice(text, _core_text(adapters))


def _adapters(source: KernelSource | None, user_events: bool) -> str:
    """Definitions of the kernel interface's names for a model's functions: every layout of a
    one-form model (:func:`geardyn.core.one_form.adapters`), or a plain model's adapters."""
    if source is not None and source.one_form is not None:
        return one_form_adapters(source.one_form)
    plain = source is not None and source.plain
    return (_PLAIN_ADAPTERS if plain else "") + (_EVENTS_ADAPTER if user_events else "")


def _template_text(template: str, source: KernelSource | None = None,
                   user_events: bool = False, core: str | None = None) -> str:
    """A template's text with the shared core: imported from the model's generated core module
    ``core`` (see :func:`_core_import`), or without one spliced in as text, with the model's
    adapters (:func:`_adapters`)."""
    if template not in TEMPLATES:
        raise KeyError(f"unknown kernel template {template!r}; known: {', '.join(TEMPLATES)}")
    adapters = _adapters(source, user_events)
    if template == CORE:
        return _core_text(adapters) + "\n"
    text = inspect.getsource(importlib.import_module(TEMPLATES[template]))
    if source is not None and source.one_form is not None and _TANGENT_MARK in text:
        text = _splice_tangent(text, tangent_adapters(source.one_form))
    if core is not None:
        return _splice(text, _core_import(core))
    return _splice_core(text, adapters)


_TANGENT_MARK = "# TANGENT-ADAPTERS"
#: Modules whose source a generated module's hash covers where its text imports them (numba's
#: cache of the generated module holds code inlined from them and checks only its own file).
_DIGEST_IMPORTS = ("geardyn.core.dual",)


def _splice_tangent(text: str, adapters: str) -> str:
    """The template's ``TANGENT-ADAPTERS`` line replaced by a one-form model's tangent forms
    (:func:`geardyn.core.one_form.tangent_adapters`: the variational Lyapunov kernel's; only
    that template has the line, so the model's other kernels do not change with them)."""
    lines = text.splitlines()
    out = [adapters if line.startswith(_TANGENT_MARK) else line for line in lines]
    return "\n".join(out) + "\n"


# The model's step machinery (:mod:`._step_core` with the model's functions: the split step,
# the tangent rows, the phase table, ...) is one generated module per model, ``core``, which
# the model's other kernel modules import, so that each of its functions is compiled (and
# cached) once per model, not once per template.
CORE = "core"
TEMPLATES[CORE] = "geardyn.solvers._step_core"


def _core_import(core: str) -> str:
    """The statement that gives a template module every name of the model's core module (as
    splicing the core's text in would)."""
    return (f"import {core} as _core_module  # noqa: E402\n"
            "globals().update({k: v for k, v in vars(_core_module).items()"
            " if not k.startswith('__')})")


def _splice(text: str, statement: str) -> str:
    """Replace the template's ``CORE-IMPORT`` statement (one line, or a parenthesised import
    starting on the marked line) by ``statement``."""
    lines = text.splitlines()
    for k, line in enumerate(lines):
        if line.rstrip().endswith(_CORE_MARK):
            end = k
            if "(" in line and ")" not in line:
                while ")" not in lines[end]:
                    end += 1
            return "\n".join([*lines[:k], statement, *lines[end + 1 :]]) + "\n"
    raise RuntimeError("kernel template has lost its CORE-IMPORT line")


def _import_line(funcs: dict[str, Any]) -> str:
    parts = []
    for alias, fn in funcs.items():
        py = fn.py_func
        parts.append(f"from {py.__module__} import {py.__name__} as {alias}")
    return "; ".join(parts) + "  " + _IMPORT_MARK


def _source_digest(text: str, funcs: dict[str, Any]) -> str:
    """The hash that names a generated module: its text, numba's version, the sources of the
    model's modules and of :data:`SHARED_MODULES` (numba's cache of the generated module holds
    their compiled code too, and checks only the generated file)."""
    h = hashlib.sha256(text.encode())
    h.update(numba.__version__.encode())
    paths = [sys.modules[fn.py_func.__module__].__file__ for fn in funcs.values()]
    paths += [importlib.import_module(name).__file__ for name in SHARED_MODULES]
    paths += [importlib.import_module(name).__file__ for name in _DIGEST_IMPORTS
              if f"from {name} import" in text]
    for path in paths:
        h.update(Path(path).read_bytes())
    return h.hexdigest()[:20]


def _replace_import(text: str, new_line: str) -> str:
    """Replace every ``MODEL-IMPORT`` line (the spliced core's and the template's)."""
    lines = text.splitlines()
    marked = [k for k, line in enumerate(lines) if line.rstrip().endswith(_IMPORT_MARK)]
    if not marked:
        raise RuntimeError("kernel template has lost its MODEL-IMPORT line")
    for k in marked:
        lines[k] = new_line
    return "\n".join(lines) + "\n"


def load_generated(name: str, code: str) -> types.ModuleType:
    """The generated module ``name`` of text ``code``: written to the kernel cache folder (once;
    atomically, so that concurrent processes never see half a file), imported and registered in
    ``sys.modules`` (so that another generated module can import it by name; not where its
    import fails)."""
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.py"
    if not path.exists():
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "w") as fh:
            fh.write(code)
        os.replace(tmp, path)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:  # (a C callback that does not compile): no half-made module kept
        del sys.modules[name]
        raise
    return module


def kernels_for(source: KernelSource, template: str = "rk4") -> Any:
    """The kernel module of ``template`` for a model's functions (built, written and imported on
    first use, then kept for the process). A model that declares the ``"pointer"`` path
    (:mod:`._pointer_kernels`) gets the trajectory and sweep kernels, the variational
    Lyapunov lane blocks and the period map compiled once for every model, bound to its
    callbacks' addresses (:func:`_pointer_path`, :func:`_pointer_lyapunov`,
    :func:`_pointer_monodromy`), and its functions inlined in the other templates."""
    if "geardyn.core.dual" not in sys.modules:
        # the dual numbers' overloads, installed (numba's typing refreshed) before a kernel
        # compiles, under numba's compiler lock (no compile of another thread sees them
        # half-registered); here, not at import: a process that runs no kernel (a command-line
        # error, ``--help``) does not pay numba's target set-up
        with global_compiler_lock:
            import geardyn.core.dual  # noqa: F401

    if source.path == "pointer":
        if template == "rk4":
            return _pointer_path(source)
        if template == "lyapunov":
            return _pointer_lyapunov(source)
        if template == "monodromy":
            return _pointer_monodromy(source)
        source = dataclasses.replace(source, path=None)
    funcs = source.functions()
    key = (template, source.plain, source.one_form, *funcs, *(id(f) for f in funcs.values()))
    if key in _LOADED:
        return _LOADED[key]
    core = kernels_for(source, CORE).__name__ if template != CORE else None
    text = _template_text(template, source, "user_events" in funcs, core)
    module = _generated(f"geardyn_{template}", text, funcs)
    _quiet_module(module)
    _LOADED[key] = module
    _quiet_shared()
    if template != CORE:
        # the split step (every template's scalar path) compiles in a helper process meanwhile
        compile_share.compile_ahead(sys.modules[core], AHEAD)
    return module


def _generated(prefix: str, text: str, funcs: dict[str, Any], reuse: bool = False
               ) -> types.ModuleType:
    """The generated module of a template's ``text`` for a model's functions ``funcs``:
    ``<prefix>_<digest>``, written to the cache folder and imported with their import line
    (:func:`load_generated`; ``reuse``: the module of that name already imported, if any), or,
    where a function cannot be imported by name, ``<prefix>_inmemory_<n>``, built in memory with
    the functions in its namespace and numba's cache off (compiled once per process). Either is
    registered in ``sys.modules`` (the model's other kernel modules import its core)."""
    if all(_importable(f) for f in funcs.values()):
        code = _replace_import(text, _import_line(funcs))
        name = f"{prefix}_{_source_digest(code, funcs)}"
        if reuse and name in sys.modules:
            return sys.modules[name]
        return load_generated(name, code)
    code = _replace_import(text, "pass  " + _IMPORT_MARK).replace("_CACHE = True",
                                                                   "_CACHE = False")
    module = types.ModuleType(f"{prefix}_inmemory_{len(_LOADED)}")
    sys.modules[module.__name__] = module
    module.__dict__.update(funcs)
    exec(compile(code, module.__name__, "exec"), module.__dict__)
    return module


def _pointer_path(source: KernelSource) -> pointer.PointerKernels:
    """The :class:`._pointer_kernels.PointerKernels` of a one-form model on the pointer path
    (kept for the process): the ``"rk4"`` kernels of :data:`._pointer_kernels.SOURCE`, the
    pointer sweep (:func:`_pointer_hooked`) and the model's part, whose C callbacks compile as
    it is imported (or load from numba's cache)."""
    if source.one_form is None:
        raise ValueError("the pointer kernel path needs a model in the one form")
    funcs = source.functions()
    key = ("pointer", source.one_form, *funcs, *(id(f) for f in funcs.values()))
    if key in _LOADED:
        return _LOADED[key]
    inlined = dataclasses.replace(source, path=None)
    text = pointer.part_text(source, kernels_for(inlined, CORE).__name__,
                             kernels_for(inlined).__name__)
    with _compiling():
        part = _generated("geardyn_pointer", text, funcs, reuse=True)
    from geardyn.solvers import _pointer_template

    shared = kernels_for(pointer.SOURCE)
    _LOADED[key] = pointer.PointerKernels(shared, _pointer_hooked("rk4", _pointer_template),
                                          part, lambda: kernels_for(inlined))
    return _LOADED[key]


def _pointer_lyapunov(source: KernelSource) -> pointer.PointerLyapunov:
    """The :class:`._pointer_kernels.PointerLyapunov` of a one-form model on the pointer path
    (kept for the process): the variational lane blocks of the pointer path's Lyapunov module
    (:func:`_pointer_hooked`: the tangent form and the array forms of :mod:`._pointer_model`)
    and the model's part (:func:`._pointer_kernels.lyapunov_part_text`: its C callbacks compile
    as it is imported, on first use), its other Lyapunov kernels inlined."""
    funcs = source.functions()
    key = ("pointer-lyapunov", source.one_form, *funcs, *(id(f) for f in funcs.values()))
    if key in _LOADED:
        return _LOADED[key]
    inlined = dataclasses.replace(source, path=None)

    def part() -> types.ModuleType:
        text = pointer.lyapunov_part_text(source, kernels_for(inlined, CORE).__name__,
                                          kernels_for(inlined, "lyapunov").__name__)
        with _compiling():
            return _generated("geardyn_pointer_lyapunov_part", text, funcs, reuse=True)

    from geardyn.solvers import _pointer_lyapunov as hooks

    _LOADED[key] = pointer.PointerLyapunov(_pointer_hooked("lyapunov", hooks), part,
                                           lambda: kernels_for(inlined, "lyapunov"))
    return _LOADED[key]


def _pointer_monodromy(source: KernelSource) -> pointer.PointerMonodromy:
    """The :class:`._pointer_kernels.PointerMonodromy` of a one-form model on the pointer path
    (kept for the process): the ``"monodromy"`` module of :data:`._pointer_kernels.SOURCE`
    with the addresses of the model's part (:func:`_pointer_path`'s), its other monodromy
    names inlined."""
    funcs = source.functions()
    key = ("pointer-monodromy", source.one_form, *funcs, *(id(f) for f in funcs.values()))
    if key not in _LOADED:
        inlined = dataclasses.replace(source, path=None)
        _LOADED[key] = pointer.PointerMonodromy(
            kernels_for(pointer.SOURCE, "monodromy"), _pointer_path(source),
            lambda: kernels_for(inlined, "monodromy"))
    return _LOADED[key]


def compile_tangent(source: KernelSource, signature: Any) -> None:
    """Compile a one-form model's tangent form of its rhs as its variational Lyapunov kernels
    take it (numba's TypingError where its one form does not take dual numbers): a pointer
    model's Lyapunov callbacks (:func:`_pointer_lyapunov`, which its lane blocks call), any
    other model's ``rhs_tangent`` alone, of ``signature``."""
    kern = kernels_for(source, "lyapunov")
    if isinstance(kern, pointer.PointerLyapunov):
        kern.part  # noqa: B018 - imported: its callbacks compiled
    elif tuple(signature) not in kern.rhs_tangent.overloads:  # (compiled: no compile's locks)
        kern.rhs_tangent.compile(signature)


def _pointer_hooked(template: str, hooks: types.ModuleType) -> types.ModuleType:
    """The pointer path's module of ``template`` (:func:`._pointer_kernels.hooked_text`): the
    template's module of :data:`._pointer_kernels.SOURCE` with the ``hooks`` module's hooks;
    its name hashes the text, numba's version and the sources of :mod:`._pointer_calls`,
    :mod:`._pointer_model` and :data:`SHARED_MODULES`."""
    funcs = pointer.SOURCE.functions()
    core = kernels_for(pointer.SOURCE, CORE).__name__
    text = _template_text(template, pointer.SOURCE, "user_events" in funcs, core)
    if _TANGENT_MARK in text:  # the pointer model's tangent form: the model's through its address
        text = _splice_tangent(text, pointer.TANGENT_IMPORT)
    code = pointer.hooked_text(_replace_import(text, _import_line(funcs)), hooks)
    h = hashlib.sha256(code.encode())
    h.update(numba.__version__.encode())
    for mod in (_pointer_calls, pointer.SOURCE_MODULE,
                *map(importlib.import_module, SHARED_MODULES)):
        h.update(Path(mod.__file__).read_bytes())
    prefix = "sweep" if template == "rk4" else template
    name = f"geardyn_pointer_{prefix}_{h.hexdigest()[:20]}"
    if name not in sys.modules:
        _quiet_module(load_generated(name, code))
    return sys.modules[name]


#: The core functions :func:`kernels_for` has compiled ahead (:func:`.compile_share.compile_ahead`)
#: when it first loads one of a model's templates: name -> the signature every template calls
#: it with (``tests/test_compile_share.py`` checks that the templates compile no other).
AHEAD = {"_split_step": "(int64, float64, float64[::1], float64[::1], float64[::1], float64, "
                        "float64, int64, float64, float64, float64, float64, int64[::1], "
                        "float64[::1], int64[::1], float64[:, ::1], float64[::1], "
                        "float64[:, ::1])"}
#: The modules of kernel functions that do not depend on the model: ordinary modules, compiled
#: and cached once for every model.
SHARED_MODULES = ("geardyn.solvers._step_shared", "geardyn.solvers._sweep_books",
                  "geardyn.solvers._lyapunov_books")
_QUIETED: list[bool] = []


def _quiet_shared() -> None:
    """On the first call, the functions of every module of :data:`SHARED_MODULES` compile
    quietly and under their locks, like a generated module's (:func:`_quiet_module`)."""
    if not _QUIETED:
        for name in SHARED_MODULES:
            _quiet_module(importlib.import_module(name))
        _QUIETED.append(True)
