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


#: Axis labels and SI units of the swept parameters of the CATT device (the paper's names);
#: every parameter of the other models is dimensionless.
PARAM_LABELS: dict[str, tuple[str, str]] = {
    "Omega": (r"$\Omega = \omega/\omega_n$", "1"),
    "Lambda": (r"$\Lambda = \omega_l/\omega_n$", "1"),
    "xi": (r"$\xi_1 = \xi_2$", "1"),
    "xi1": (r"$\xi_1$", "1"),
    "xi2": (r"$\xi_2$", "1"),
    "backlash": ("backlash $b$", "m"),
    "b_sq": (r"backlash $b_{sq}$", "m"),
    "b_pq": (r"backlash $b_{pq}$", "m"),
    "error": ("meshing error $E$", "m"),
    "E_sq": (r"meshing error $E_{sq}$", "m"),
    "E_pq": (r"meshing error $E_{pq}$", "m"),
    "Km_sq": (r"$K_{m,sq}$", "N/m"),
    "Km_pq": (r"$K_{m,pq}$", "N/m"),
    "Ka": (r"$K_a$", "N/m"),
    "Ka_sq": (r"$K_{a,sq}$", "N/m"),
    "Ka_pq": (r"$K_{a,pq}$", "N/m"),
    "T_D": (r"input torque $T_D$", "N m"),
    "A1": (r"$A_1$", "N m"),
    "A2": (r"$A_2$", "N m"),
    "B1": (r"$B_1$", "N m"),
    "B2": (r"$B_2$", "N m"),
    "psi1": (r"$\psi_1$", "rad"),
    "psi2": (r"$\psi_2$", "rad"),
    "b_c": (r"$b_c$", "m"),
    "zeta": (r"$\zeta$", "1"),
    "kappa": (r"$\kappa$", "1"),
    "Fm": (r"$F_m$", "1"),
    "Fa": (r"$F_a$", "1"),
}


def param_label(name: str, model: str = "CATTDevice", units: str | None = None) -> str:
    """Axis label of a swept parameter with its unit: SI units for the CATT device's paper
    names, ``[–]`` for every other model's parameters (they are dimensionless); ``units``, when
    given (a coordinate's ``units`` attribute), wins."""
    label, si = PARAM_LABELS.get(name, (name, "1"))
    if name == "Omega":
        return f"{label} {unit_text(units or '1')}"
    if units is None:
        units = si if model == "CATTDevice" else "1"
    return f"{label} {unit_text(units)}"


def time_unit_label(unit: str | None) -> str:
    """The time unit of an axis label: tau for dimensionless time."""
    return r"$\tau$" if unit in (None, "", "1") else str(unit)
