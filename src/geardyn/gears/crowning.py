"""Lead crowning and the loaded contact of a sliced (helical or spur) pair.

A symmetric parabolic lead crowning of ``amount`` C_c [m] on a gear removes C_c (2 y / b)^2 at
the axial position y from the face centre (b: the pair's face width), measured along the
transverse line of action as the tip relief's amounts are: nothing at the face centre, C_c at
both face ends. In the slice model of :func:`~geardyn.gears.helical_stiffness` slice j (centre
y_j) meets the gap

    e_ij = sum over crownings C_c (2 y_j / b)^2 + e_relief(s_ij) + e_fault,ij

with s_ij its contact position on the transverse line of action (the tip relief of
:mod:`geardyn.gears.tip_relief`, applied in every transverse section) and e_fault the gap of a
worn tooth. The contacts i (every slice of every pair in contact) share the normal force F by
equal approach delta, sum_i k_i max(0, delta - e_i) = F, solved exactly by
:func:`~geardyn.gears.tip_relief.load_sharing` (the solver of
:func:`~geardyn.gears.loaded_contact`): the unloaded transmission error is min_i e_i, the loaded
one delta, the tangent stiffness the sum of the loaded k_i and the secant stiffness
F / (delta - min_i e_i). At beta = 0 this is a crowned spur pair.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn.errors import ParameterError
from geardyn.gears.helical import HelicalMesh
from geardyn.gears.tip_relief import TipRelief, force_value, load_sharing, relief_gap
from geardyn.units import to_si


@dataclass(frozen=True)
class LeadCrowning:
    """A symmetric parabolic lead crowning of ``amount`` [m] (at each face end) on ``gear``
    ("pinion" or "wheel"). The amount may be a unit string."""

    amount: float
    gear: str = "pinion"

    def __post_init__(self) -> None:
        try:
            value = to_si(self.amount, "length")
        except ValueError as exc:
            raise ParameterError("crowning.amount", self.amount, str(exc)) from None
        if not (math.isfinite(value) and value >= 0.0):
            raise ParameterError("crowning.amount", self.amount, "must be a finite length >= 0")
        object.__setattr__(self, "amount", value)
        if self.gear not in ("pinion", "wheel"):
            raise ParameterError("crowning.gear", self.gear, "must be 'pinion' or 'wheel'")

    def gap(self, axial_position: np.ndarray, face_width: float) -> np.ndarray:
        """C_c (2 y / b)^2 [m] at the axial positions y [m] from the face centre."""
        y = np.asarray(axial_position, dtype=float)
        return self.amount * (2.0 * y / face_width) ** 2


def crowning_gap(axial_position: np.ndarray, face_width: float,
                 crowning: tuple[LeadCrowning, ...]) -> np.ndarray:
    """The total gap [m] of the ``crowning`` tuple at the axial positions [m] (0 without)."""
    gap = np.zeros(np.shape(axial_position))
    for c in crowning:
        if not isinstance(c, LeadCrowning):
            raise ParameterError("crowning", c, "must be LeadCrowning objects")
        gap = gap + c.gap(axial_position, face_width)
    return gap


def helical_loaded_contact(mesh: HelicalMesh, stiffness: xr.Dataset, force: float,
                           relief: tuple[TipRelief, ...] = (),
                           crowning: tuple[LeadCrowning, ...] = ()) -> xr.Dataset:
    """The loaded static transmission error and mesh stiffness of ``stiffness`` (a Dataset of
    :func:`~geardyn.gears.helical_stiffness` for ``mesh``) under the normal force ``force`` [N]
    along the transverse line of action, with the tip ``relief`` and the lead ``crowning``
    (module docstring); the gaps of worn teeth (``fault_gap``) add.

    Variables over ``angle``: ``unloaded_transmission_error`` [m], ``transmission_error`` [m],
    ``tangent_stiffness`` and ``secant_stiffness`` [N/m], ``pairs_loaded`` (the loaded
    fraction of the face summed over the pairs); over (``angle``, ``pair``): ``pair_force`` [N];
    over (``angle``, ``pair``, ``slice``): ``gap`` [m] (NaN out of contact), ``slice_force``
    [N]. Without relief, crowning and wear the tangent stiffness equals ``mesh_stiffness`` to
    rounding (the slices summed in another order)."""
    if not isinstance(mesh, HelicalMesh):
        raise ParameterError("mesh", mesh, "must be a HelicalMesh")
    f = force_value(force)
    crowning = tuple(crowning)
    k3 = stiffness["slice_stiffness"].values
    inside3 = stiffness["slice_in_contact"].values
    e3 = (relief_gap(mesh.transverse, stiffness["slice_position"].values, tuple(relief))
          + crowning_gap(stiffness["axial_position"].values, mesh.face_width, crowning)
          + stiffness["fault_gap"].values)
    rows = k3.shape[0]
    out = load_sharing(k3.reshape(rows, -1), inside3.reshape(rows, -1), e3.reshape(rows, -1), f)
    slice_force = out["force"].reshape(k3.shape)
    count = k3.shape[2]
    dims3 = ("angle", "pair", "slice")
    ds = xr.Dataset(
        {"unloaded_transmission_error": (("angle",), out["e_min"]),
         "transmission_error": (("angle",), out["delta"]),
         "tangent_stiffness": (("angle",), out["tangent"]),
         "secant_stiffness": (("angle",), out["secant"]),
         "pairs_loaded": (("angle",), out["loaded"].sum(axis=1) / count),
         "pair_force": (("angle", "pair"), slice_force.sum(axis=2)),
         "gap": (dims3, np.where(inside3, e3, np.nan)),
         "slice_force": (dims3, slice_force)},
        coords={c: stiffness.coords[c] for c in ("angle", "cycle", "pair", "slice",
                                                  "axial_position")})
    units = {"unloaded_transmission_error": "m", "transmission_error": "m", "gap": "m",
             "tangent_stiffness": "N/m", "secant_stiffness": "N/m", "pairs_loaded": "",
             "pair_force": "N", "slice_force": "N"}
    for name, unit in units.items():
        ds[name].attrs["units"] = unit
    ds.attrs.update(
        force_N=f,
        relief="; ".join(f"{r.shape} on {r.gear}: {r.amount:.6g} m over {r.length:.6g} m"
                         for r in relief) or "none",
        crowning="; ".join(f"parabolic lead crowning on {c.gear}: {c.amount:.6g} m"
                           for c in crowning) or "none")
    return ds
