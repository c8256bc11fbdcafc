"""Where a cold compile spends its CPU time: numba's passes and LLVM's phases, exclusive.

Runs ``bench/compile.py``'s analyses of one model (a conformance case) in this process on an
empty private cache, with timers around each numba compiler pass (``PassManager._runPass``)
and around the LLVM work numba does inside the lowering pass: the LLVM IR's parse and
function-level passes (``add_ir_module``), the linking of callee libraries into a caller
(``finalize``'s ``link_in``), the module passes (cheap, then full O3), machine code
(``finalize_object``), the CPython and C wrappers' lowering, and the cache's writes. Each
phase's figure is exclusive: the time of phases nested in it (a callee compiled during a
caller's type inference) is its own. CPU seconds of the process (``time.process_time``).

    GEARDYN_CACHE_DIR=/tmp/empty PYTHONPATH=src python bench/compile_phases.py GearPair [--top 30]
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import json
import os
import re
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))

TOTALS: dict[str, list] = defaultdict(lambda: [0.0, 0])
_STACK: list[list] = []


def _timed(key):
    def wrap(fn):
        @functools.wraps(fn)
        def inner(*a, **k):
            name = key(*a, **k) if callable(key) else key
            _STACK.append([time.process_time(), 0.0])
            try:
                return fn(*a, **k)
            finally:
                t0, child = _STACK.pop()
                total = time.process_time() - t0
                TOTALS[name][0] += total - child
                TOTALS[name][1] += 1
                if _STACK:
                    _STACK[-1][1] += total
        return inner
    return wrap


BYLIB: dict[str, list] = defaultdict(lambda: [0.0, 0])


def _kind(library) -> str:
    return "|" + library.name


#: With ``--asm-emitted``: per function (its name without geardyn's per-process number), the
#: digests of its machine code in every module numba's engine emitted.
EMITTED: dict[str, set] = defaultdict(set)
_UID = re.compile(r"B[0-9]+v[0-9]+")


def _record_emitted(finalize):
    """Wrap ``_finalize_final_module`` (numba emits the module's machine code there): each
    function's assembly, from a clone of the module (the emission changes the module's IR)."""
    @functools.wraps(finalize)
    def inner(self):
        from numba.core import codegen

        asm = str(self._codegen._tm.emit_assembly(self._final_module.clone()))
        if isinstance(self, codegen.JITCodeLibrary):
            for name, body in _functions(asm):
                lines = [_LOCAL.sub(r".\1", _SYMBOL.sub("SYM", s)) for s in body]
                digest = hashlib.sha256("\n".join(lines).encode()).hexdigest()[:20]
                EMITTED[_UID.sub("Bv", name)].add(digest)
        return finalize(self)
    return inner


def install(emitted: bool = False) -> None:
    from numba.core import caching, codegen, compiler_machinery, lowering

    pm = compiler_machinery.PassManager
    pm._runPass = _timed(lambda self, index, pss, state: f"pass {pss.name()}")(pm._runPass)
    lib = codegen.CPUCodeLibrary
    lib.add_ir_module = _timed("llvm add_ir_module (other)")(lib.add_ir_module)
    lib._optimize_functions = _timed("llvm function passes")(lib._optimize_functions)
    codegen.ll.parse_assembly = _timed("llvm parse_assembly")(codegen.ll.parse_assembly)
    mod = codegen.llvmir.Module
    mod.__repr__ = _timed("llvm IR to text")(mod.__repr__)
    lib._optimize_final_module = _timed(
        lambda self: f"llvm module passes (cheap + full) {_kind(self)}")(
        lib._optimize_final_module)
    lib._finalize_final_module = _timed(
        lambda self: f"llvm machine code (finalize_object) {_kind(self)}")(
        _record_emitted(lib._finalize_final_module) if emitted else lib._finalize_final_module)
    lib._get_module_for_linking = _timed("llvm clone for linking")(lib._get_module_for_linking)
    ll_mod = type(codegen.ll.parse_assembly(""))
    orig_link = ll_mod.link_in

    def link_in(self, other, preserve=False):
        return orig_link(self, other, preserve)
    ll_mod.link_in = _timed("llvm link_in")(link_in)
    lib.serialize_using_object_code = _timed("cache serialize")(lib.serialize_using_object_code)
    lw = lowering.Lower
    lw.lower = _timed("lower (numba IR -> LLVM IR)")(lw.lower)
    lw.create_cpython_wrapper = _timed("lower cpython wrapper")(lw.create_cpython_wrapper)
    lw.create_cfunc_wrapper = _timed("lower cfunc wrapper")(lw.create_cfunc_wrapper)
    caching.Cache.save_overload = _timed("cache save_overload")(caching.Cache.save_overload)
    caching.Cache.load_overload = _timed("cache load_overload")(caching.Cache.load_overload)


def _record_overloads() -> list:
    """Every (dispatcher, compile result) compiled from here on."""
    from numba.core import dispatcher

    seen: list = []
    add = dispatcher.Dispatcher.add_overload

    def add_overload(self, cres):
        seen.append((self, cres))
        return add(self, cres)
    dispatcher.Dispatcher.add_overload = add_overload
    return seen


_SYMBOL = re.compile(r"\.bytes\.-?[0-9]+|_ZN[0-9A-Za-z_$.]*"
                     r"|[0-9A-Za-z_$.]*geardyn[0-9A-Za-z_$.<>]*")
_LOCAL = re.compile(r"\.(LBB|LCPI|Lfunc_end|Ltmp|LJTI)[0-9]+")
_TYPE = re.compile(r"^\s*\.type\s+([^,]+),@function")


def _functions(asm: str) -> list[tuple[str, list[str]]]:
    """The assembly's functions: (name, lines), numba's CPython and C wrappers left out."""
    out: list[tuple[str, list[str]]] = []
    name, body = None, []
    for line in asm.splitlines():
        m = _TYPE.match(line)
        if m:
            if name is not None:
                out.append((name, body))
            name, body = m.group(1).strip('"'), []
        elif name is not None and line.strip() and not line.lstrip().startswith(".file"):
            body.append(line)
    if name is not None:
        out.append((name, body))
    return [(n, b) for n, b in out if not n.startswith(("cpython.", "cfunc."))]


def _asm_digests(compiled: list, dump: Path | None = None) -> dict[str, list]:
    """Per geardyn function and signature: the instructions of its library's functions (the
    CPython and C wrappers left out) and a digest of them with every symbol name and local
    label number replaced (geardyn numbers its symbols per process)."""
    out: dict[str, list] = {}
    for disp, cres in compiled:
        mod = getattr(disp.py_func, "__module__", "") or ""
        if not mod.startswith("geardyn") or cres.library is None:
            continue
        lines = []
        for _, body in _functions(cres.library.get_asm_str()):
            lines += [_LOCAL.sub(r".\1", _SYMBOL.sub("SYM", s)) for s in body]
        key = f"{mod}.{disp.py_func.__qualname__}{cres.signature}"
        n = 0
        while f"{key}#{n}" in out:
            n += 1
        out[f"{key}#{n}"] = [len(lines), hashlib.sha256("\n".join(lines).encode()).hexdigest()]
        if dump is not None:
            name = hashlib.sha256(f"{key}#{n}".encode()).hexdigest()[:16]
            (dump / f"{name}.s").write_text(f"; {key}#{n}\n" + "\n".join(lines))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("case")
    ap.add_argument("--top", type=int, default=40)
    ap.add_argument("--asm", type=Path, default=None,
                    help="write each compiled geardyn function's assembly digest here (JSON; "
                         "symbol names left out), to compare two trees' machine code")
    ap.add_argument("--asm-dump", type=Path, default=None,
                    help="with --asm: also write each function's assembly (names replaced) here")
    ap.add_argument("--asm-emitted", type=Path, default=None,
                    help="write the digests of each function's machine code as numba's engine "
                         "emitted it, in whichever module (JSON; slows the compile), for "
                         "bench/bound_calls.py")
    ap.add_argument("--analyses", nargs="*", default=None,
                    help="only these of bench/compile.py's analyses (default: all)")
    args = ap.parse_args(argv)
    if "GEARDYN_CACHE_DIR" not in os.environ:
        os.environ["GEARDYN_CACHE_DIR"] = tempfile.mkdtemp(prefix="gdc_phases_")
    os.environ["GEARDYN_COMPILE_AHEAD"] = "0"
    install(emitted=args.asm_emitted is not None)
    compiled = _record_overloads()
    t0 = time.process_time()
    import compile as cb

    if args.analyses:
        runs = cb._runs

        def only(model, y0):
            return {k: v for k, v in runs(model, y0).items() if k in args.analyses}
        cb._runs = only
    rows = cb.child(args.case)
    total = time.process_time() - t0
    print(f"{args.case}: {total:.1f} s CPU in all; per analysis: "
          + ", ".join(f"{k} {v[0]:.1f}" for k, v in rows.items()))
    merged: dict[str, list] = defaultdict(lambda: [0.0, 0])
    lib_rows: dict[str, list] = defaultdict(lambda: [0.0, 0])
    for name, (s, n) in TOTALS.items():
        phase, _, lib = name.partition(" |")
        merged[phase][0] += s
        merged[phase][1] += n
        if lib:
            lib_rows[lib][0] += s
            lib_rows[lib][1] += n
    for name, (s, n) in sorted(merged.items(), key=lambda kv: -kv[1][0])[:args.top]:
        print(f"{s:8.2f} s {n:6d}  {name}")
    print("LLVM module passes + machine code per library name:")
    for name, (s, n) in sorted(lib_rows.items(), key=lambda kv: -kv[1][0])[:args.top]:
        print(f"{s:8.2f} s {n:6d}  {name}")
    print(f"{sum(v[0] for v in TOTALS.values()):8.2f} s in the phases above")
    if args.asm_emitted is not None:
        args.asm_emitted.write_text(json.dumps({k: sorted(v) for k, v in EMITTED.items()},
                                               indent=1, sort_keys=True))
    if args.asm is not None:
        dump = None
        if args.asm_dump is not None:
            dump = args.asm_dump
            dump.mkdir(parents=True, exist_ok=True)
        args.asm.write_text(json.dumps(_asm_digests(compiled, dump), indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
