"""The vector width of geardyn's compiled kernels, set on geardyn's own functions only.

LLVM tunes code for most Intel server CPUs with AVX-512 (Skylake-SP to Emerald Rapids) to
prefer 256-bit vectors (``prefer-256-bit``, against the clock drop of 512-bit code on the
first of them), while for AMD Zen 4 and Zen 5 it prefers 512 bits. geardyn's fused step loops
are vector code over lanes and gain from the wider registers (the figures are in
``bench/RESULTS.md``). The kernels are compiled without fastmath, every lane's arithmetic is
elementwise, so results are bitwise the same at any width (``tests/test_jit_target.py``).

``GEARDYN_SIMD_WIDTH`` (environment, read at ``import geardyn``) chooses:

``512`` (default)
    512-bit vectors where the CPU has them (AVX-512), whatever LLVM's tuning for the CPU.
``256``
    256-bit vectors at most, on any CPU.
``native``
    LLVM's own choice for this CPU (numba's default).

geardyn compiles its numba functions with its own compiler pipeline, :class:`WidthCompiler`
(numba's ``pipeline_class``, in the ``_JIT`` options of geardyn's modules and generated
kernels), which puts LLVM's function attribute ``"prefer-vector-width"`` (:data:`ATTRIBUTE`)
on every function it lowers, their Python and C wrappers included. The x86 backend reads it
per function, over the CPU's tuning: the width the loop and SLP vectorisers aim at and whether
512-bit registers are used. A model function inlined into a kernel (a user's own, too) is
vectorised at the kernel's width. Nothing process-wide is changed: numba's CPU target, its
configuration and every numba function of other code keep LLVM's choice for the CPU, whether
numba was used before ``import geardyn`` or not, and numba's own ``NUMBA_CPU_NAME`` /
``NUMBA_CPU_FEATURES`` still choose the CPU (the attribute only sets the width within it).

The same pass makes the function's code library skip numba's cheap module pipeline before the
full one (:func:`_full_only`); the full pipeline runs as numba runs it (``tests/test_full_only.py``
checks which pipelines run and the results against numpy). A function compiled inside another
geardyn compile gets its machine code when first needed (:mod:`geardyn._lazy_code`, whose
guard :class:`WidthCompiler` enters); the outermost one, as numba does.

The width is part of the cache key of geardyn's functions (:func:`cache_tag`, in the name of
their cache files, :mod:`geardyn._cache`): kernels compiled at one width are never loaded at
another.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from numba.core import config
from numba.core.compiler import Compiler
from numba.core.compiler_machinery import LoweringPass, register_pass
from numba.core.runtime.nrtopt import remove_redundant_nrt_refct
from numba.core.typed_passes import AnnotateTypes

from geardyn import _bound_calls, _lazy_code
from geardyn._tuple_alias import tuple_aliases

#: The environment variable that chooses the vector width.
ENV = "GEARDYN_SIMD_WIDTH"
#: Its values (see above) and the preferred vector width in bits each sets (None: no attribute).
MODES: dict[str, int | None] = {"512": 512, "256": 256, "native": None}
DEFAULT = "512"


def mode_from_env(environ: Mapping[str, str]) -> str:
    """The vector-width mode ``environ`` asks for (``ENV``, default ``DEFAULT``); a clear
    error naming the variable for any other value."""
    value = environ.get(ENV, DEFAULT).strip().lower() or DEFAULT
    if value not in MODES:
        raise ValueError(f"{ENV}={environ.get(ENV)!r}: must be one of "
                         f"{', '.join(MODES)} (unset: {DEFAULT})")
    return value


def attribute_for(mode: str) -> str | None:
    """The LLVM function attribute for ``mode`` (``"prefer-vector-width"="<bits>"``), or None
    for ``native``."""
    bits = MODES[mode]
    return None if bits is None else f'"prefer-vector-width"="{bits}"'


#: The mode of this process (``GEARDYN_SIMD_WIDTH`` at import).
MODE: str = mode_from_env(os.environ)
#: The attribute geardyn's functions are compiled with (None: ``native``).
ATTRIBUTE: str | None = attribute_for(MODE)


def cache_tag() -> str:
    """The width's part of the cache key of geardyn's functions (``simd512``, ``simd256``,
    ``simdnative``)."""
    return f"simd{MODE}"


def _mark(library: Any, attribute: str) -> None:
    """Make ``library`` (a numba code library) put ``attribute`` on every function defined in
    an LLVM IR module added to it (the function, its wrappers); other libraries are untouched."""
    add = library.add_ir_module

    def add_ir_module(ir_module: Any) -> None:
        for fn in ir_module.functions:
            if fn.blocks:
                # llvmlite's FunctionAttributes checks names against LLVM's enum attributes; a
                # string attribute is printed into the function's definition as it is
                set.add(fn.attributes, attribute)
        add(ir_module)

    library.add_ir_module = add_ir_module


def _full_only(library: Any) -> None:
    """Make ``library`` (a numba code library) run only numba's full module pipeline when it is
    finalised, not the cheap one numba runs before it (O0 inlining, loop rotation, instruction
    combining, jump threading: it gathers reference-count operations into one function for
    numba's pruner, which the full pipeline also runs, after its own inlining). Other libraries
    are untouched."""
    codegen = library._codegen

    def optimize_final_module() -> None:
        if not config.LLVM_REFPRUNE_PASS:
            library._final_module = remove_redundant_nrt_refct(library._final_module)
        pm, pb = codegen._module_pass_manager()
        with library._recorded_timings.record("Module passes (full optimization)", pb):
            pm.run(library._final_module, pb)

    library._optimize_final_module = optimize_final_module


@register_pass(mutates_CFG=False, analysis_only=False)
class VectorWidthPass(LoweringPass):
    """Before numba's lowering: the function's code library (created here, as numba's
    lowering would) puts :data:`ATTRIBUTE` on the functions lowered into it and runs numba's
    full module pipeline alone (:func:`_full_only`)."""

    _name = "geardyn_vector_width"

    def __init__(self) -> None:
        LoweringPass.__init__(self)

    def run_pass(self, state: Any) -> bool:
        if state.library is None:
            state.library = state.targetctx.codegen().create_library(
                state.func_id.func_qualname)
            state.library.enable_object_caching()
        if _lazy_code.scope.depth == 1:  # the outermost geardyn function: called from Python
            _lazy_code.mark_outermost(state.library)
        _full_only(state.library)
        _bound_calls.prepare(state.library, state.reload_init, state.func_id.func)
        if ATTRIBUTE is not None:
            _mark(state.library, ATTRIBUTE)
        return True


class WidthCompiler(Compiler):
    """numba's pipeline with :class:`VectorWidthPass` before the lowering: the compiled
    function gets geardyn's vector width (``pipeline_class=WidthCompiler``). It runs with
    numba's alias analysis following tuples (:func:`geardyn._tuple_alias.tuple_aliases`), so
    that its dead-code elimination keeps the stores into arrays passed in tuples."""

    def _compile_core(self) -> Any:
        with tuple_aliases(), _lazy_code.scope():
            return super()._compile_core()

    def define_pipelines(self) -> list:
        pipelines = super().define_pipelines()
        for pm in pipelines:
            if any(pss is AnnotateTypes for pss, _ in pm.passes):  # nopython pipelines
                pm.add_pass_after(VectorWidthPass, AnnotateTypes)
                pm.finalize()
        return pipelines


#: What geardyn's kernels are compiled with (the mode and how, for the benchmarks' reports).
APPLIED: str = (f"{MODE}: {ATTRIBUTE} on geardyn's compiled functions" if ATTRIBUTE else
                f"{MODE}: LLVM's default vector width for this CPU")
