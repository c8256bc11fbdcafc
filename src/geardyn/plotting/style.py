"""Matplotlib set-up shared by geardyn's figures: the non-interactive Agg backend, one style."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg", force=False)  # never open a GUI window; figures go to files

RC: dict[str, object] = {
    "figure.dpi": 110,
    "savefig.dpi": 150,
    "font.size": 9,
    "axes.titlesize": 9,
    "axes.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "lines.linewidth": 0.8,
    "legend.fontsize": 8,
}

#: Readable labels of dimensionless state names (mathtext).
STATE_LABELS: dict[str, str] = {
    "X_sq": r"$\bar X_{sq}$",
    "V_sq": r"$\bar X_{sq}'$",
    "X_pq": r"$\bar X_{pq}$",
    "V_pq": r"$\bar X_{pq}'$",
    "F_sq": r"$F_{sq}$",
    "F_pq": r"$F_{pq}$",
    "x": r"$x$",
    "v": r"$x'$",
    "F": r"$F$",
}


def state_label(name: str) -> str:
    """Mathtext label of a state name (``X_sq2`` -> X_sq of planet set 2)."""
    if name in STATE_LABELS:
        return STATE_LABELS[name]
    base = name.rstrip("0123456789")
    if base != name and base in STATE_LABELS:
        return f"{STATE_LABELS[base]} (set {name[len(base):]})"
    return name


def unit_text(units: str | None) -> str:
    """Axis-label unit: ``[-]`` for dimensionless quantities."""
    if units is None or units in ("1", "", "dimensionless"):
        return "[–]"
    return f"[{units}]"
