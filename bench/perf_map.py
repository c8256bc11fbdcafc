"""Where a geardyn workload's time goes, by compiled function: ``perf record`` (software clock,
so it works in a VM without hardware counters) with a JIT symbol map of numba's functions.

numba's machine code has no symbols perf can see. This script records the object code of the
libraries numba loads from its cache (so the kernels must be cached: run the workload once
before), writes ``/tmp/perf-<pid>.map`` (perf's JIT map format: start, size, name) from their
symbols (``nm``) and load addresses, runs the workload under ``perf record -p <pid>``, and
prints ``perf report``'s top symbols.

    .venv/bin/python bench/perf_map.py [--points 1000] [--threads 1] [--top 25]
                                       [--annotate _split_step] [--dump DIR]

``--dump DIR``: each hot function's disassembly with its samples per instruction, and the
words pushed onto the stack at each of its call sites with the samples they take.

Workload: bench/bifurcation.py's paper reference workload (``--points`` values of Omega), or
with ``--gear-pair`` bench/peers.py's (the gear pair at 128 steps per period, 400 Omega).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import geardyn

sys.path.insert(0, str(Path(__file__).parent))
from bifurcation import SAMPLES, TRANSIENT, device  # noqa: E402

_LOADED: list = []  # (library, object code) of every library numba loads from its cache


def _record_cache_loads() -> None:
    """Keep the object code of each library numba loads from its cache (its symbols)."""
    cls = numba.core.codegen.CPUCodeLibrary
    orig = cls._unserialize.__func__

    def _unserialize(klass, codegen, state):
        lib = orig(klass, codegen, state)
        if state[1] == "object":
            _LOADED.append((lib, state[2][0]))
        return lib

    cls._unserialize = classmethod(_unserialize)


def _short(symbol: str) -> str:
    """A mangled numba symbol's function name (``_ZN<len>module<len>name...``)."""
    name = symbol
    i = name.find("_ZN")
    if i < 0:
        return name
    j = i + 3
    names = []
    while j < len(name) and name[j].isdigit():
        k = j
        while name[k].isdigit():
            k += 1
        n = int(name[j:k])
        names.append(name[k:k + n])
        j = k + n
    return ".".join(names[-2:]) if names else name


def _code_mappings() -> list[tuple[int, int]]:
    """(start, size) of this process's anonymous executable mappings (JIT code)."""
    rows = []
    for line in Path(f"/proc/{os.getpid()}/maps").read_text().splitlines():
        parts = line.split()
        if len(parts) == 5 and parts[1].startswith("r-x"):
            lo, hi = (int(x, 16) for x in parts[0].split("-"))
            rows.append((lo, hi - lo))
    return rows


def write_map(path: Path) -> dict:
    """The JIT map of every function of the cache-loaded libraries; returns its rows, address
    -> (size, name, object code, offset in it).

    A library's code section (``.ltext``, numba's large code model) is loaded at the start
    of an executable anonymous mapping of its size (rounded up to pages); the symbols lie at
    their offsets from there. A library whose size matches no mapping, or several, is left
    out (and said)."""
    maps = _code_mappings()
    rows = {}
    for lib, obj in _LOADED:
        with tempfile.NamedTemporaryFile(suffix=".o") as f:
            f.write(obj)
            f.flush()
            nm = subprocess.run(["nm", "-S", "--defined-only", f.name], capture_output=True,
                                text=True).stdout
            sections = subprocess.run(["readelf", "-S", "-W", f.name], capture_output=True,
                                      text=True).stdout
        size = next((int(ln.split()[-6], 16) for ln in sections.splitlines()
                     if " .ltext " in ln), 0)
        pages = (size + 4095) // 4096 * 4096
        starts = [lo for lo, n in maps if n == pages]
        if len(starts) != 1:
            print(f"library {lib.name}: {len(starts)} mappings of its size {size}, left out")
            continue
        for line in nm.splitlines():
            parts = line.split()
            if len(parts) == 4 and parts[2] in "tTwW":
                rows[starts[0] + int(parts[0], 16)] = (int(parts[1], 16), _short(parts[3]),
                                                       obj, int(parts[0], 16))
    with path.open("w") as f:
        for addr in sorted(rows):
            size, name = rows[addr][:2]
            f.write(f"{addr:x} {size:x} {name}\n")
    return rows


def annotate(rows: dict, data: Path, needle: str, top: int) -> None:
    """The hottest instructions of the first mapped function whose name contains ``needle``:
    the samples' addresses (``perf script``) against the function's disassembly
    (``objdump`` of its library's object code), each with its share of the function."""
    hit = next(((a, r) for a, r in sorted(rows.items()) if needle in r[1]), None)
    if hit is None:
        print(f"no function matching {needle!r}")
        return
    start, (size, name, obj, off) = hit
    ips = subprocess.run(["perf", "script", "-i", str(data), "-F", "ip"], capture_output=True,
                         text=True).stdout.split()
    counts: dict[int, int] = {}
    for ip in ips:
        a = int(ip, 16)
        if start <= a < start + size:
            counts[a - start + off] = counts.get(a - start + off, 0) + 1
    total = sum(counts.values())
    with tempfile.NamedTemporaryFile(suffix=".o") as f:
        f.write(obj)
        f.flush()
        dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", f"--start-address={off}",
                              f"--stop-address={off + size}", f.name], capture_output=True,
                             text=True).stdout
    text = {}
    for line in dis.splitlines():
        head, _, ins = line.partition(":")
        if ins and head.strip() and all(c in "0123456789abcdef" for c in head.strip()):
            text[int(head.strip(), 16)] = " ".join(ins.split())
    print(f"\n{name}: {total} samples, {len(text)} instructions; hottest {top}:")
    for a, n in sorted(counts.items(), key=lambda x: -x[1])[:top]:
        print(f"  {100 * n / total:5.1f}%  +{a - off:#07x}  {text.get(a, '?')}")
    kinds: dict[str, int] = {}
    for a, n in counts.items():
        ins = text.get(a, "?")
        kind = "zmm" if "zmm" in ins else "ymm" if "ymm" in ins else "xmm" if "xmm" in ins \
            else "other"
        kinds[kind] = kinds.get(kind, 0) + n
    print("  by register kind: " + ", ".join(f"{k} {100 * v / total:.1f}%"
                                              for k, v in sorted(kinds.items())))


def dump(rows: dict, data: Path, folder: Path, least: float = 0.5) -> None:
    """Each mapped function with at least ``least`` % of the samples, disassembled into
    ``folder/<name>.s`` with each instruction's samples (``perf script``) in front, and per call
    site the words its arguments push onto the stack and the samples from the last branch
    before it to the call (what a call with many arguments costs the caller)."""
    ips = [int(ip, 16) for ip in subprocess.run(
        ["perf", "script", "-i", str(data), "-F", "ip"], capture_output=True,
        text=True).stdout.split()]
    folder.mkdir(parents=True, exist_ok=True)
    for start, (size, name, obj, off) in sorted(rows.items()):
        counts: dict[int, int] = {}
        for a in ips:
            if start <= a < start + size:
                counts[a - start + off] = counts.get(a - start + off, 0) + 1
        total = sum(counts.values())
        if not ips or 100 * total / len(ips) < least:
            continue
        with tempfile.NamedTemporaryFile(suffix=".o") as f:
            f.write(obj)
            f.flush()
            dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn",
                                  f"--start-address={off}", f"--stop-address={off + size}",
                                  f.name], capture_output=True, text=True).stdout
        lines = []
        for line in dis.splitlines():
            head, _, ins = line.partition(":")
            h = head.strip()
            if ins and h and all(c in "0123456789abcdef" for c in h):
                ins = re.sub(r"<_ZN[^>]*>", "<...>", " ".join(ins.split()))
                lines.append((counts.get(int(h, 16), 0), int(h, 16) - off, ins))
        short = name.split(".")[-1]
        (folder / f"{short}.s").write_text(
            "\n".join(f"{n:6d} {a:6x}  {ins}" for n, a, ins in lines) + "\n")
        print(f"{short}: {total} samples ({100 * total / len(ips):.1f} %) -> {folder}/{short}.s")
        for i, (_, a, ins) in enumerate(lines):
            if not ins.startswith("call"):
                continue
            j = i - 1
            while j >= 0 and not lines[j][2].startswith(("j", "ret")):
                j -= 1
            pushes = sum(ins2.startswith("push") for _, _, ins2 in lines[j + 1:i])
            if pushes > 4:
                n = sum(c for c, _, _ in lines[j + 1:i + 1])
                print(f"  call at +{a:#x}: {pushes} words pushed, {n} samples "
                      f"({100 * n / max(total, 1):.1f} % of the function)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--no-edges", action="store_true")
    ap.add_argument("--gear-pair", action="store_true", help="bench/peers.py's workload")
    ap.add_argument("--annotate", action="append", default=[],
                    help="the hottest instructions of the function whose name contains this")
    ap.add_argument("--dump", type=Path, default=None,
                    help="folder for each hot function's disassembly with its samples")
    args = ap.parse_args()
    _record_cache_loads()
    numba.set_num_threads(args.threads)
    kw = {"locate_edges": False} if args.no_edges else {}
    if args.gear_pair:
        import peers

        model, values = peers.model(), peers.workload().omega
        kw.update(transient=peers.TRANSIENT, samples=peers.SAMPLES,
                  steps_per_period=peers.STEPS)
    else:
        model, values = device(), np.linspace(0.1, 4.0, args.points)
        kw.update(transient=TRANSIENT, samples=SAMPLES)
    # a first run loads every kernel the workload uses (the map is written after it)
    geardyn.bifurcation(model, "Omega", values, run=geardyn.RunSettings(**kw))
    rows = write_map(Path(f"/tmp/perf-{os.getpid()}.map"))
    print(f"{len(rows)} functions in /tmp/perf-{os.getpid()}.map")
    data = Path(f"/tmp/perf-{os.getpid()}.data")
    rec = subprocess.Popen(["perf", "record", "-e", "cpu-clock", "-F", "2000", "-o", str(data),
                            "-p", str(os.getpid())], stderr=subprocess.DEVNULL)
    time.sleep(0.5)
    t0 = time.perf_counter()
    geardyn.bifurcation(model, "Omega", values, run=geardyn.RunSettings(**kw))
    wall = time.perf_counter() - t0
    rec.send_signal(2)
    rec.wait()
    print(f"workload {wall:.2f} s wall on {args.threads} thread(s)")
    rep = subprocess.run(["perf", "report", "-i", str(data), "--stdio", "--no-children",
                          "--sort", "sym", "--percent-limit", "0.3"],
                         capture_output=True, text=True)
    lines = [ln for ln in rep.stdout.splitlines() if ln.strip() and not ln.startswith("#")]
    print("\n".join(lines[: args.top]))
    for needle in args.annotate:
        annotate(rows, data, needle, args.top)
    if args.dump is not None:
        dump(rows, data, args.dump)


if __name__ == "__main__":
    main()
