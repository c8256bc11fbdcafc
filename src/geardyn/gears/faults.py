"""Tooth faults of a spur pair for the potential-energy mesh stiffness.

Each fault sits on tooth ``tooth`` of ``gear`` ("pinion" or "wheel" of a pair, tooth 0 passing
the pitch point at pinion angle 0, tooth j j mesh cycles later; "sun", "ring", "planet1",
"planet2", ... of a planetary set, :data:`PLANETARY_GEARS` and
:mod:`geardyn.models.planetary_faults`; or the name of a gear of a
:class:`~geardyn.trains.GearTrain`, :mod:`geardyn.trains.faults`) and is built from keyword
arguments whose
names are its fields; lengths and angles may be unit strings (:func:`geardyn.units.to_si`).
What a fault does to the stiffness is in :mod:`geardyn.gears.potential_energy` and
docs/gears.md; the checks that need the mesh (a crack past the centre line, a spall off the
active flank, a tooth index beyond the tooth count) are made when the pair is prepared.

* :class:`RootCrack` (``depth``, ``angle``): a straight crack at the root of the drive flank;
  its faces are taken open under the load of either flank.
* :class:`Spall` (``length``, ``width``, ``depth``, ``position``, ``flank``): a rectangular spall
  or pit on the drive or the coast flank.
* :class:`Wear` (``depth``, ``profile``, ``flank``): uniform or Archard wear of the active
  profile of the drive or the coast flank.
* :class:`BrokenTooth`: the tooth is missing.

``flank`` (:data:`FLANKS`): "drive" (the default), the flank loaded when the pinion drives
forwards, or "coast", the back flank, loaded on reversal and in the backlash's rattle. The
tooth is symmetric, so a fault on the coast flank acts on the coast contacts as the same fault
on the drive flank acts on the drive contacts, mirrored along the coast line of action. One
fault a tooth, or a spall or wear on each of its flanks.

Errors name the field as ``<kind>.<field>`` (``spall.position``), with the kind of
:data:`FAULT_KINDS` (``crack`` for a root crack).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from geardyn.errors import ParameterError
from geardyn.units import to_si

GEARS = ("pinion", "wheel")
#: The gears of a planetary set a fault may sit on: "sun", "ring" or "planet<n>" (n = 1 .. N,
#: the planet at the n-th planet angle; checked against N where the set is built).
PLANETARY_GEARS = ("sun", "ring", "planet<n>")
_GEAR_NAMES = ("'pinion' or 'wheel' (a pair), 'sun', 'ring', 'planet1', 'planet2', ... (a"
               " planetary set), or a gear train's gear name")


def planet_number(gear: object) -> int | None:
    """n of a gear name "planet<n>" (n >= 1, no leading zeros), else None."""
    if not isinstance(gear, str) or not gear.startswith("planet"):
        return None
    digits = gear[len("planet"):]
    if not digits.isdigit() or not digits.isascii() or digits.startswith("0"):
        return None
    return int(digits)


def _check_gear(gear: object, kind: str) -> None:
    """``gear`` a gear's name: a non-empty string (error ``<kind>.gear``). Which names are
    valid depends on where the fault is placed, which checks it: a pair's ``"pinion"`` or
    ``"wheel"``, a planetary set's gears, a gear train's gears."""
    if isinstance(gear, str) and gear.strip():
        return
    raise ParameterError(f"{kind}.gear", gear, f"must be {_GEAR_NAMES}")
#: The flanks a :class:`Spall` or :class:`Wear` may lie on.
FLANKS = ("drive", "coast")


def _place(fault: object, kind: str) -> None:
    """Check the ``gear`` and ``tooth`` fields of ``fault`` (errors ``<kind>.gear`` ...)."""
    tooth = fault.tooth  # type: ignore[attr-defined]
    _check_gear(fault.gear, kind)  # type: ignore[attr-defined]
    if isinstance(tooth, bool) or not isinstance(tooth, numbers.Integral) or tooth < 0:
        raise ParameterError(f"{kind}.tooth", tooth, "must be a whole number >= 0")
    object.__setattr__(fault, "tooth", int(tooth))


def _flank(fault: object, kind: str) -> None:
    """Check the ``flank`` field of ``fault`` (error ``<kind>.flank``)."""
    flank = fault.flank  # type: ignore[attr-defined]
    if not isinstance(flank, str) or flank not in FLANKS:
        raise ParameterError(f"{kind}.flank", flank, f"must be one of {', '.join(FLANKS)}")


def _on(fault: object) -> str:
    """"" on the drive flank, else " the coast flank of" (for :meth:`describe`)."""
    return "" if fault.flank == "drive" else " the coast flank of"  # type: ignore[attr-defined]


def _length(fault: object, kind: str, name: str, *, signed: bool = False) -> None:
    """Convert field ``name`` of ``fault`` to metres: finite, and >= 0 unless ``signed``."""
    value = getattr(fault, name)
    try:
        v = to_si(value, "length")
    except ValueError as exc:
        raise ParameterError(f"{kind}.{name}", value, str(exc)) from None
    if not math.isfinite(v) or (not signed and v < 0.0):
        raise ParameterError(f"{kind}.{name}", value,
                             "must be a finite length" + ("" if signed else " >= 0"))
    object.__setattr__(fault, name, v)


@dataclass(frozen=True)
class RootCrack:
    """A straight crack at the root of one tooth's drive flank (Tian 2004; Wu, Zuo & Parey
    2008; Chen & Shao 2011): ``depth`` q [m] along the crack, ``angle`` v [rad] between the crack
    and the tooth's centre line (q sin v is its reach across the tooth), on tooth ``tooth`` of
    ``gear`` ("pinion" or "wheel"; tooth 0 passes the pitch point at pinion angle 0, tooth j
    j mesh cycles later). Quantities may be unit strings. The crack's faces are taken open
    under either flank's load (the coast load, which presses them together, sees the same
    thinner sections), so the model has no crack side to choose: no ``flank`` field."""

    depth: float
    angle: float = math.radians(45.0)
    gear: str = "pinion"
    tooth: int = 0

    kind = "crack"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        try:
            set_(self, "depth", to_si(self.depth, "length"))
            set_(self, "angle", to_si(self.angle, "angle"))
        except ValueError as exc:
            raise ParameterError("crack", self, str(exc)) from None
        if not (math.isfinite(self.depth) and self.depth >= 0.0):
            raise ParameterError("crack.depth", self.depth, "must be a finite length >= 0")
        if not 0.0 < self.angle <= 0.5 * math.pi * (1.0 + 1e-12):  # "90 deg" in float
            raise ParameterError("crack.angle", self.angle, "must lie in (0, 90 deg]")
        _check_gear(self.gear, "crack")
        if isinstance(self.tooth, bool) or not isinstance(self.tooth, numbers.Integral):
            raise ParameterError("crack.tooth", self.tooth, "must be a whole number")

    @property
    def size(self) -> float:
        """The crack's size in a fault dataset's labels: its depth q [m]."""
        return self.depth

    @property
    def reach(self) -> float:
        """q sin v [m]: how far the crack tip lies inside the flank, across the tooth."""
        return self.depth * math.sin(self.angle)

    @property
    def is_null(self) -> bool:
        """True for a zero-depth crack (the healthy tooth)."""
        return self.depth == 0.0

    def describe(self) -> str:
        """One line for the Dataset's attrs."""
        return (f"root crack on {self.gear} tooth {self.tooth}: depth {self.depth:.6g} m, angle"
                f" {math.degrees(self.angle):.6g} deg (Tian's crack limit line; fillet"
                " foundation healthy)")


@dataclass(frozen=True)
class Spall:
    """A rectangular spall (or pit) on flank ``flank`` ("drive" or "coast") of one tooth:
    ``length`` [m] along the involute profile, ``width`` [m] across the face (less than the face
    width), ``depth`` [m] into the tooth across its section, centred ``position`` [m] along the
    profile from the reference (standard pitch) circle, positive towards the tip; on tooth
    ``tooth`` of ``gear``. The spall must lie on the flank's active profile (checked with the
    mesh). A spall of zero length, width or depth is the healthy tooth."""

    length: float
    width: float
    depth: float
    position: float = 0.0
    gear: str = "pinion"
    tooth: int = 0
    flank: str = "drive"

    kind = "spall"

    def __post_init__(self) -> None:
        for name in ("length", "width", "depth"):
            _length(self, "spall", name)
        _length(self, "spall", "position", signed=True)
        _place(self, "spall")
        _flank(self, "spall")

    @property
    def size(self) -> float:
        """The spall's size in a fault dataset's labels: its length along the profile [m]."""
        return self.length

    @property
    def is_null(self) -> bool:
        """True when the spall removes no material."""
        return self.length == 0.0 or self.width == 0.0 or self.depth == 0.0

    def describe(self) -> str:
        """One line for the Dataset's attrs."""
        return (f"spall on{_on(self)} {self.gear} tooth {self.tooth}: {self.length:.6g} m along"
                f" the profile"
                f" x {self.width:.6g} m across the face x {self.depth:.6g} m deep, centred"
                f" {self.position:.6g} m from the reference circle")


#: The wear profiles along the flank (see :class:`Wear`).
WEAR_PROFILES = ("uniform", "archard")


@dataclass(frozen=True)
class Wear:
    """Wear of the active profile of flank ``flank`` ("drive" or "coast") of one tooth, on
    tooth ``tooth`` of ``gear``: ``profile`` "uniform" removes ``depth`` [m] everywhere on it,
    "archard" follows Archard's law along the flank (the sliding distance times the load, zero
    at the pitch point) with ``depth`` [m] its largest value (on the coast flank the mirror of
    the drive flank's: the same slip and load share at the mirrored contact). The tooth's
    sections thin by the local depth and the flank's contacts open a gap of it (the unloaded
    transmission error, ``fault_gap`` or ``fault_gap_coast``, see
    :func:`geardyn.gears.loaded_contact`). Zero depth is the healthy tooth."""

    depth: float
    gear: str = "pinion"
    tooth: int = 0
    profile: str = "uniform"
    flank: str = "drive"

    kind = "wear"

    def __post_init__(self) -> None:
        _length(self, "wear", "depth")
        _place(self, "wear")
        if self.profile not in WEAR_PROFILES:
            raise ParameterError("wear.profile", self.profile,
                                 f"must be one of {', '.join(WEAR_PROFILES)}")
        _flank(self, "wear")

    @property
    def size(self) -> float:
        """The wear's size in a fault dataset's labels: its (largest) depth [m]."""
        return self.depth

    @property
    def is_null(self) -> bool:
        """True for zero wear."""
        return self.depth == 0.0

    def describe(self) -> str:
        """One line for the Dataset's attrs."""
        size = "" if self.profile == "uniform" else " at most"
        return (f"{self.profile} wear on{_on(self)} {self.gear} tooth {self.tooth}:{size}"
                f" {self.depth:.6g} m over the active profile")


@dataclass(frozen=True)
class BrokenTooth:
    """Tooth ``tooth`` of ``gear`` is missing (broken off at the root): a pair holding it
    carries nothing while it would be in contact."""

    gear: str = "pinion"
    tooth: int = 0

    kind = "broken_tooth"

    def __post_init__(self) -> None:
        _place(self, "broken_tooth")

    @property
    def size(self) -> float:
        """A missing tooth has no size in a fault dataset's labels: NaN."""
        return math.nan

    @property
    def is_null(self) -> bool:
        """A missing tooth is never the healthy tooth."""
        return False

    def describe(self) -> str:
        """One line for the Dataset's attrs."""
        return f"{self.gear} tooth {self.tooth} missing"


Fault = RootCrack | Spall | Wear | BrokenTooth

#: The fault classes by kind (the ``kind`` of a study file's fault table).
FAULT_KINDS: dict[str, type] = {"crack": RootCrack, "spall": Spall, "wear": Wear,
                                "broken_tooth": BrokenTooth}


def listed_faults(faults: object) -> tuple[Any, ...]:
    """``faults`` as a tuple: None gives (), one fault a 1-tuple, a sequence its items."""
    if faults is None:
        return ()
    if isinstance(faults, Sequence) and not isinstance(faults, str):
        return tuple(faults)
    return (faults,)
