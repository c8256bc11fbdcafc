"""Curves over the explorer's diagram: where each given two-parameter curve (a ``"curve"``
dataset: grazing, fold, period-doubling) crosses the line the diagram sweeps, i.e. the swept
parameter's values where the curve meets the current value of its other parameter. The diagram
marks them as vertical lines in the curve kind's colour (those of
:mod:`geardyn.plotting.envelope`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from geardyn.plotting.envelope import CURVE_STYLES

__all__ = ["curve_marks"]


def _label(ds: Any) -> str:
    kind = ds.attrs.get("curve_kind", "curve")
    return f"grazing {ds.attrs.get('flank', 'drive')}" if kind == "grazing" else str(kind)


def curve_marks(curves: Sequence[Any], param: str, value_of: Callable[[str], Any]
                ) -> dict[str, list]:
    """``{"x": [...], "label": [...], "color": [...]}``: for each curve with ``param`` as one of
    its two parameters, the values of ``param`` where its polyline crosses the other parameter's
    current value ``value_of(name)`` (a number; a curve whose other value is not one, or is
    unknown, gives none)."""
    out: dict[str, list] = {"x": [], "label": [], "color": []}
    for ds in curves:
        names = (ds.attrs.get("x"), ds.attrs.get("y"))
        if param not in names or ds.sizes.get("point", 0) < 2:
            continue
        other = names[1] if names[0] == param else names[0]
        try:
            v = float(value_of(other))
        except (KeyError, AttributeError, TypeError, ValueError):
            continue
        if not math.isfinite(v):
            continue
        p, o = ds[param].values, ds[other].values - v
        label = _label(ds)
        colour = CURVE_STYLES.get(label, ("grey", ":", label))[0]
        for i in range(p.size - 1):
            a, b = o[i], o[i + 1]
            if a == 0.0 or a * b < 0.0:
                out["x"].append(float(p[i] + (p[i + 1] - p[i]) * (a / (a - b))))
                out["label"].append(label)
                out["color"].append(colour)
    return out
