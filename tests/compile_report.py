"""Which tests compile kernels, and what: numba's compile events recorded per test.

With ``GEARDYN_COMPILE_REPORT=DIR`` set, every test process (each pytest-xdist worker) writes
``DIR/compiles-<pid>.jsonl``: one line per test that compiled anything, with the wall seconds
of its outermost compiles and the functions compiled (qualified name and module, wall seconds
inclusive of the functions they compile in turn). Kernels a test compiles are those the
warm-up (``tests/warm_kernels.py``) did not: a test-specific model, another lane form, other
argument types. Without the variable nothing is recorded. Compiles in subprocesses a test
starts are not seen.

    GEARDYN_COMPILE_REPORT=out/compiles python -m pytest -n 2 -q
    python tests/compile_report.py out/compiles [--top 40]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections import defaultdict
from pathlib import Path

ENV = "GEARDYN_COMPILE_REPORT"


class CompileRecorder:
    """numba ``numba:compile`` listener: outermost compile wall seconds and every function's."""

    def __init__(self) -> None:
        import numba.core.event as ev

        class _Listener(ev.Listener):
            def on_start(inner, event):  # noqa: N805 - the recorder is the state
                self._stack.append(time.perf_counter())

            def on_end(inner, event):  # noqa: N805
                t0 = self._stack.pop()
                seconds = time.perf_counter() - t0
                fn = getattr(event.data["dispatcher"], "py_func", None)
                name = (f"{fn.__module__}.{fn.__qualname__}" if fn is not None else "?")
                self._functions[name] += seconds
                if not self._stack:
                    self._outer += seconds

        self._ev = ev
        self._listener = _Listener()
        self._stack: list[float] = []
        self._functions: dict[str, float] = defaultdict(float)
        self._outer = 0.0

    def __enter__(self) -> CompileRecorder:
        self._ev.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc: object) -> None:
        self._ev.unregister("numba:compile", self._listener)

    def record(self) -> dict:
        top = sorted(self._functions.items(), key=lambda kv: -kv[1])
        return {"compile_s": round(self._outer, 3),
                "functions": [[n, round(s, 3)] for n, s in top]}


def directory() -> Path | None:
    """The report folder ``$GEARDYN_COMPILE_REPORT``, or None (no recording)."""
    value = os.environ.get(ENV, "").strip()
    return Path(value) if value else None


def write(folder: Path, nodeid: str, record: dict) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / f"compiles-{os.getpid()}.jsonl", "a") as fh:
        fh.write(json.dumps({"test": nodeid, **record}) + "\n")


def summary(folder: Path, top: int) -> str:
    """Tests by compile seconds (largest first), each with its dearest functions."""
    rows = []
    for path in sorted(folder.glob("compiles-*.jsonl")):
        rows += [json.loads(line) for line in path.read_text().splitlines() if line]
    rows.sort(key=lambda r: -r["compile_s"])
    total = sum(r["compile_s"] for r in rows)
    lines = [f"{len(rows)} tests compiled, {total:.0f} s wall of compile in all"]
    for r in rows[:top]:
        names = ", ".join(f"{n.rsplit('.', 2)[-2]}.{n.rsplit('.', 1)[-1]} {s:.0f}"
                          for n, s in r["functions"][:4])
        lines.append(f"{r['compile_s']:8.1f} s  {r['test']}\n            {names}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--top", type=int, default=40)
    args = ap.parse_args(argv)
    print(summary(args.folder, args.top))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
