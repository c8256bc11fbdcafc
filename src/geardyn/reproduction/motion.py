"""Motion classes of a bifurcation sweep, from the period classifier and Lyapunov exponents.

The labels and the rule are those of :mod:`geardyn.analysis.motion` (``period-k``, ``chaotic``,
``quasi-periodic``, ``unresolved``, ``unbounded``, ``non-periodic``): an exponent is positive or
negative only beyond its uncertainty u = max(z x standard error, c / T).

The Lyapunov exponent is only needed (and only computed) where the period classifier finds no
period. With a load fluctuation at a Lambda incommensurate with Omega no stroboscopic section
shows the motion's period (``period`` is 0 there, ``section`` False), so the exponent alone
separates chaos from quasi-periodic motion.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geardyn.analysis import motion as _motion
from geardyn.core.moved import moved, warn_once

__all__ = ["intervals", "is_nonperiodic", "motion_labels"]

# The labels and the rule live in :mod:`geardyn.analysis.motion`; their names here answer for
# one deprecation cycle.
_moved = moved(__name__, dict.fromkeys(
    ("CHAOTIC", "LYAPUNOV_FLOOR", "LYAPUNOV_Z", "NONPERIODIC", "QUASI_PERIODIC", "UNBOUNDED",
     "UNRESOLVED", "period_label"), "geardyn.analysis.motion"))
#: Names that no label uses any more, with their values and why, answered for one deprecation
#: cycle: ``LYAPUNOV_CHAOS``, the former fixed chaos threshold [1/tau] (the exponent's
#: uncertainty decides, :mod:`geardyn.analysis.motion`).
_RETIRED: dict[str, tuple[float, str]] = {
    "LYAPUNOV_CHAOS": (2.0e-3, "no label uses a fixed chaos threshold: the exponent's "
                               "uncertainty decides (geardyn.analysis.motion)")}


def __getattr__(name: str) -> Any:
    """A moved or retired name, with one DeprecationWarning per name."""
    if name not in _RETIRED:
        return _moved(name)
    value, why = _RETIRED[name]
    warn_once(("retired", __name__, name), f"{__name__}.{name} is deprecated: {why}",
              stacklevel=2)
    return value


def motion_labels(period: np.ndarray, lyapunov: np.ndarray, *,
                  lyapunov_err: np.ndarray | None, duration: np.ndarray | float,
                  section: np.ndarray | bool = True, z: float = _motion.LYAPUNOV_Z,
                  floor: float = _motion.LYAPUNOV_FLOOR) -> np.ndarray:
    """Label per point: :func:`geardyn.analysis.motion.motion_classes` (``period`` k >= 1, 0
    none found, -1 unbounded; exponent, its standard error and averaging time ``duration``;
    ``section`` False where a second excitation is incommensurate)."""
    return _motion.motion_classes(period, lyapunov, lyapunov_err, duration, section, z, floor)


def is_nonperiodic(labels: np.ndarray) -> np.ndarray:
    """No period found: chaotic, quasi-periodic, unresolved or without an exponent (the paper's
    diagrams show these as clouds of points)."""
    labels = np.asarray(labels)
    return np.isin(labels, (_motion.CHAOTIC, _motion.QUASI_PERIODIC, _motion.UNRESOLVED,
                            _motion.NONPERIODIC))


def intervals(x: np.ndarray, mask: np.ndarray) -> list[tuple[float, float, int]]:
    """Maximal runs of consecutive points (in ascending ``x``) where ``mask`` holds:
    (first x, last x, number of points)."""
    x = np.asarray(x, dtype=float)
    mask = np.asarray(mask, dtype=bool)
    order = np.argsort(x, kind="stable")
    xs, ms = x[order], mask[order]
    out: list[tuple[float, float, int]] = []
    start = None
    for i, m in enumerate(ms):
        if m and start is None:
            start = i
        if start is not None and (not m or i == ms.size - 1):
            end = i if m else i - 1
            out.append((float(xs[start]), float(xs[end]), end - start + 1))
            start = None
    return out
