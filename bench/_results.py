"""The "Current figures" table at the top of bench/RESULTS.md, written by the bench scripts.

Each row is one speed target, keyed by a short id: what is measured, the target, the figure,
where it stands against the target, the date (UTC) and commit of the measurement, and the
command that produced it. A bench script run with ``--write`` replaces its own rows and leaves
the others, so the table always holds the latest figure of every target, each with its own
date and commit. The commit is ``git describe --always --dirty`` of the working tree (a
``-dirty`` suffix: uncommitted changes were measured).
"""

from __future__ import annotations

import datetime
import subprocess
from pathlib import Path

RESULTS = Path(__file__).with_name("RESULTS.md")
BEGIN = "<!-- current-figures:begin (written by bench/_results.py; do not edit by hand) -->"
END = "<!-- current-figures:end -->"
HEADER = ("| id | target | measured | against it | date | commit | command |\n"
          "|---|---|---|---|---|---|---|")

#: The rows' order in the table (ids not listed here follow, sorted).
ORDER = ("paper-workload", "gear-pair-vs-rk4", "equal-accuracy", "lyapunov", "crossing",
         "map-500", "reproduce")


def commit() -> str:
    """The working tree's commit, ``-dirty`` when it has uncommitted changes."""
    try:
        out = subprocess.run(["git", "describe", "--always", "--dirty", "--abbrev=7"],
                             cwd=RESULTS.parent, capture_output=True, text=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return out.stdout.strip()


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "/")


def _rows(text: str) -> dict[str, str]:
    """The table's rows by id (the text between the markers, header excluded)."""
    if BEGIN not in text or END not in text:
        return {}
    body = text.split(BEGIN, 1)[1].split(END, 1)[0]
    rows = {}
    for line in body.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and cells[0] not in ("id", "---"):
            rows[cells[0]] = line.strip()
    return rows


def record(key: str, target: str, measured: str, verdict: str, command: str,
           path: Path = RESULTS) -> None:
    """Replace (or add) row ``key`` of the current-figures table in ``path``, dated today
    (UTC) and stamped with the working tree's commit."""
    text = path.read_text() if path.exists() else "# Benchmark results\n"
    rows = _rows(text)
    date = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d")
    cells = [key, target, measured, verdict, date, commit(), f"`{command}`"]
    rows[key] = "| " + " | ".join(_cell(c) for c in cells) + " |"
    order = [k for k in ORDER if k in rows] + sorted(k for k in rows if k not in ORDER)
    table = "\n".join([BEGIN, HEADER, *(rows[k] for k in order), END])
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        text = head + table + rest.split(END, 1)[1]
    else:
        first, _, rest = text.partition("\n")
        text = f"{first}\n\n{table}\n{rest}"
    path.write_text(text)


def against(value: float, target: float, lower_is_better: bool = True) -> str:
    """Where ``value`` stands against ``target``: "met" or "N.NNx over" ("N.NNx under" where
    higher is better)."""
    ratio = value / target if lower_is_better else target / value
    if ratio <= 1.0:
        return "met"
    return f"{ratio:.2f}x {'over' if lower_is_better else 'under'}"
