"""Numerical outcomes of an integration, as one enumeration shared by the kernels and Python.

The compiled kernels write these codes (their constants ``STATUS_OK``, ``STATUS_DIVERGED`` and
``STATUS_SPLIT_LIMIT`` in ``solvers/_step_shared.py`` equal the values here; a test checks it).
Steps that reached the edge-location split limit are always counted (``unresolved``); the
Lyapunov kernels also mark such a lane :attr:`Status.SPLIT_LIMIT` (its exponent is kept but
rests on steps integrated unsplit across an edge), while a sweep lane keeps its status and
reports the count in ``unresolved_steps``.
"""

from __future__ import annotations

from enum import IntEnum


class Status(IntEnum):
    """Outcome of one integration (one lane)."""

    OK = 0
    DIVERGED = 1
    SPLIT_LIMIT = 2
    NOT_RUN = 3

    @property
    def message(self) -> str:
        """What the code means, in words."""
        return _MESSAGES[self]


_MESSAGES = {
    Status.OK: "ok",
    Status.DIVERGED: "diverged (|state| > bound or not finite)",
    Status.SPLIT_LIMIT: "split limit reached (steps integrated unsplit across an edge)",
    Status.NOT_RUN: "not run (a continuation chain's lane after one that did not end well)",
}


def status_meaning(suffix: str = "") -> str:
    """The codes and their messages as one attribute string, e.g. ``"0 ok, 1 diverged (...)"``;
    ``suffix`` is appended to the last message (e.g. ``" in at least one start"``)."""
    text = ", ".join(f"{int(s)} {s.message}" for s in Status)
    return text + suffix


def status_attrs(suffix: str = "") -> dict[str, str]:
    """Attributes of a ``status`` variable: ``{"meaning": status_meaning(suffix)}`` (not CF
    ``flag_meanings``, which the Zarr store reads as a categorical variable's labels)."""
    return {"meaning": status_meaning(suffix)}

