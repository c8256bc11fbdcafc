"""Tip relief and the loaded static transmission error of a spur pair.

A tip relief removes material near a gear's tip: ``amount`` C [m] at the tip, over a roll
``length`` L [m] measured along the line of action from the tip end of the path of contact, of
``shape`` linear (p = 1) or parabolic (p = 2). A contact at position s on the line of action
(from the pitch point, positive towards the pinion tip; path from -g_f to g_a) then meets a gap

    e(s) = C ((s - (g_a - L)) / L)^p      for s > g_a - L   (pinion relief)
    e(s) = C ((-g_f + L - s) / L)^p       for s < -g_f + L  (wheel relief)

and e = 0 elsewhere; reliefs on both gears add, and so does the wear depth of a worn tooth
(:class:`~geardyn.gears.Wear`, the stiffness Dataset's ``fault_gap``) on its pairs. A relief
shorter than the path of contact is required (L in (0, g_a + g_f]).

The loaded contact (the "unloaded transmission error and load-dependent contact" of the
potential-energy literature, e.g. Ma, Song, Pang, Chen and co-workers on tip relief with the
potential-energy stiffness; Velex & Maatar 1996 for contacts with gaps from shape
deviations): at each pinion angle the pairs in contact i, of stiffness k_i
(:func:`~geardyn.gears.potential_energy_stiffness`) and gap e_i, share the transmitted normal
force F by equal approach delta of the two gears along the line of action,

    sum_i k_i max(0, delta - e_i) = F,

solved exactly (the left side is piecewise linear and increasing in delta: the pairs are taken
in order of rising gap until the next gap lies above the delta of the pairs so far). The
unloaded transmission error is min_i e_i (the first pair to touch), the loaded static
transmission error delta, the tangent mesh stiffness the sum of k_i over the loaded pairs and
the secant mesh stiffness F / (delta - min_i e_i). The drive flank only; the gaps are rigid
(no Hertz or bending interaction between neighbouring pairs beyond their series stiffness).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import xarray as xr

from geardyn.errors import ParameterError
from geardyn.gears.geometry import GearMesh
from geardyn.units import to_si

_POWER = {"linear": 1, "parabolic": 2}


@dataclass(frozen=True)
class TipRelief:
    """A tip relief of ``amount`` [m] at the tip of ``gear`` ("pinion" or "wheel") over a roll
    ``length`` [m] along the line of action, ``shape`` "linear" or "parabolic". Quantities may
    be unit strings."""

    amount: float
    length: float
    shape: Literal["linear", "parabolic"] = "linear"
    gear: str = "pinion"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        for field in ("amount", "length"):
            try:
                set_(self, field, to_si(getattr(self, field), "length"))
            except ValueError as exc:
                raise ParameterError(f"relief.{field}", getattr(self, field), str(exc)) from None
        if not (math.isfinite(self.amount) and self.amount >= 0.0):
            raise ParameterError("relief.amount", self.amount, "must be a finite length >= 0")
        if not (math.isfinite(self.length) and self.length > 0.0):
            raise ParameterError("relief.length", self.length, "must be a finite length > 0")
        if self.shape not in _POWER:
            raise ParameterError("relief.shape", self.shape, "must be 'linear' or 'parabolic'")
        if self.gear not in ("pinion", "wheel"):
            raise ParameterError("relief.gear", self.gear, "must be 'pinion' or 'wheel'")

    def gap(self, mesh: GearMesh, position: np.ndarray) -> np.ndarray:
        """e(s) [m] of this relief at contact ``position`` s [m] (module docstring)."""
        g_a, g_f = mesh.recess_length, mesh.approach_length
        if self.length > g_a + g_f:
            raise ParameterError("relief.length", self.length,
                                 f"longer than the path of contact {g_a + g_f:.6g} m")
        s = np.asarray(position, dtype=float)
        if self.gear == "pinion":
            t = (s - (g_a - self.length)) / self.length
        else:
            t = (-g_f + self.length - s) / self.length
        return self.amount * np.maximum(t, 0.0) ** _POWER[self.shape]


def relief_gap(mesh: GearMesh, position: np.ndarray, relief: tuple[TipRelief, ...]) -> np.ndarray:
    """The total gap [m] of the ``relief`` tuple at ``position`` [m] (0 without relief)."""
    gap = np.zeros(np.shape(position))
    for r in relief:
        if not isinstance(r, TipRelief):
            raise ParameterError("relief", r, "must be TipRelief objects")
        gap = gap + r.gap(mesh, position)
    return gap


def _solve(k: np.ndarray, e: np.ndarray, force: float) -> tuple[np.ndarray, np.ndarray]:
    """delta [m] and the loaded-pair mask per row of k [N/m], e [m] (k = 0: not in contact)."""
    order = np.argsort(np.where(k > 0.0, e, np.inf), axis=1, kind="stable")
    ks = np.take_along_axis(k, order, axis=1)
    es = np.take_along_axis(e, order, axis=1)
    es = np.where(ks > 0.0, es, np.inf)
    cum_k = np.cumsum(ks, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cum_ke = np.cumsum(np.where(ks > 0.0, ks * es, 0.0), axis=1)
        trial = (force + cum_ke) / cum_k  # delta with the first m pairs loaded
    nxt = np.concatenate([es[:, 1:], np.full((k.shape[0], 1), np.inf)], axis=1)
    ok = (cum_k > 0.0) & (trial <= nxt)
    m = np.argmax(ok, axis=1)
    delta = trial[np.arange(k.shape[0]), m]
    return delta, (k > 0.0) & (e < delta[:, None])


def force_value(force: object) -> float:
    """``force`` [N] as a finite float > 0, else a ParameterError naming ``force``."""
    try:
        f = float(force)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError("force", force, "must be a number of newtons") from None
    if not (math.isfinite(f) and f > 0.0):
        raise ParameterError("force", force, "must be a finite force > 0 N")
    return f


def load_sharing(k: np.ndarray, inside: np.ndarray, e: np.ndarray,
                 force: float) -> dict[str, np.ndarray]:
    """The contacts of each row (one pinion angle) of k [N/m] (0 out of contact), ``inside``
    and gaps e [m] sharing the normal force ``force`` [N] by equal approach (module
    docstring): ``delta`` [m], ``loaded`` (mask), ``force`` [N] per contact, ``e_min`` [m] (the
    unloaded transmission error), ``tangent`` and ``secant`` [N/m]. A row without contact is
    refused (field ``stiffness``)."""
    if not inside.any(axis=1).all():
        raise ParameterError("stiffness", None, "an angle has no pair in contact (a missing"
                             " tooth in single contact leaves the gears free there)")
    delta, loaded = _solve(k, e, force)
    e_min = np.min(np.where(inside, e, np.inf), axis=1)
    return {"delta": delta, "loaded": loaded,
            "force": np.where(loaded, k * (delta[:, None] - e), 0.0), "e_min": e_min,
            "tangent": np.where(loaded, k, 0.0).sum(axis=1), "secant": force / (delta - e_min)}


def loaded_contact(mesh: GearMesh, stiffness: xr.Dataset, force: float,
                   relief: tuple[TipRelief, ...] = ()) -> xr.Dataset:
    """The loaded static transmission error and mesh stiffness of ``stiffness`` (a Dataset of
    :func:`~geardyn.gears.potential_energy_stiffness` for ``mesh``) under the normal force
    ``force`` [N] along the line of action with the tip ``relief`` (module docstring); the gaps
    of worn teeth (its ``fault_gap``) add to the relief's.

    Variables over ``angle``: ``unloaded_transmission_error`` [m], ``transmission_error`` [m]
    (delta), ``tangent_stiffness`` and ``secant_stiffness`` [N/m], ``pairs_loaded``; over
    (``angle``, ``pair``): ``gap`` [m] (NaN out of contact), ``pair_force`` [N]. Without relief
    the tangent stiffness is ``mesh_stiffness`` bitwise."""
    f = force_value(force)
    relief = tuple(relief)
    k = stiffness["pair_stiffness"].values
    inside = stiffness["in_contact"].values
    e = relief_gap(mesh, stiffness["position"].values, relief)
    if "fault_gap" in stiffness:
        e = e + stiffness["fault_gap"].values
    out = load_sharing(k, inside, e, f)
    dims = ("angle", "pair")
    ds = xr.Dataset(
        {"unloaded_transmission_error": (("angle",), out["e_min"]),
         "transmission_error": (("angle",), out["delta"]),
         "tangent_stiffness": (("angle",), out["tangent"]),
         "secant_stiffness": (("angle",), out["secant"]),
         "pairs_loaded": (("angle",), out["loaded"].sum(axis=1)),
         "gap": (dims, np.where(inside, e, np.nan)),
         "pair_force": (dims, out["force"])},
        coords={c: stiffness.coords[c] for c in ("angle", "cycle", "pair")})
    units = {"unloaded_transmission_error": "m", "transmission_error": "m", "gap": "m",
             "tangent_stiffness": "N/m", "secant_stiffness": "N/m", "pairs_loaded": "",
             "pair_force": "N"}
    for name, unit in units.items():
        ds[name].attrs["units"] = unit
    ds.attrs.update(force_N=f, relief="; ".join(
        f"{r.shape} on {r.gear}: {r.amount:.6g} m over {r.length:.6g} m" for r in relief)
        or "none")
    return ds
