"""Physical quantities: SI floats or unit strings such as ``"50 um"`` or ``"0.825e9 N/m"``.

Every parameter is stored as a float in SI units. A plain number is taken to be SI already; a
string is parsed with pint and converted to the field's SI unit, so ``"1500 N m"``, ``"1.5 kN*m"``
and ``1500`` are the same input torque.

Frequencies and speeds (kind ``"frequency"``, SI unit rad/s) are angular: a plain number is
rad/s, and a unit string must say whether it counts radians or cycles. ``"10 rad/s"``,
``"5 deg/s"`` and ``"3000 rpm"`` (= 3000 * 2 pi / 60 rad/s) carry an angle; ``"50 Hz"`` and
``"2 kHz"`` count cycles, 1 Hz = 2 pi rad/s. A bare inverse time (``"1/s"``, ``"s^-1"``,
``"1/min"``) says neither and is refused as ambiguous (pint itself takes the radian as
dimensionless and would read 1 Hz as 1 rad/s).
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pint

#: The SI unit of each kind of quantity geardyn accepts (pint notation).
SI_UNITS: dict[str, str] = {
    "length": "m",
    "angle": "rad",
    "stiffness": "N/m",
    "inertia": "kg*m**2",
    "mass": "kg",
    "density": "kg/m**3",
    "torque": "N*m",
    "force": "N",
    "pressure": "Pa",
    "dimensionless": "",
    "frequency": "rad/s",
}


#: Longest quantity string accepted (longer input is a mistake, or an attack on the parser).
MAX_QUANTITY_CHARS = 100
#: Most powers (``**`` or ``^``) in one quantity string; each exponent is a literal of at most
#: two digits, so the parser's exact integer arithmetic cannot explode ("10**10**10 m").
MAX_POWERS = 2
_ALLOWED = re.compile(r"[\w\s.+\-*/^()%°]*")
_POWER = re.compile(r"(\*\*|\^)\s*")
_SMALL_EXPONENT = re.compile(r"[+-]?\d{1,2}(\.\d{1,2})?(?![\d.eE]|\s*(\*\*|\^))")


def _check_quantity_text(text: str) -> None:
    """Refuse strings the unit parser would need unbounded time or memory for."""
    if len(text) > MAX_QUANTITY_CHARS:
        raise ValueError(f"quantity string longer than {MAX_QUANTITY_CHARS} characters")
    if not _ALLOWED.fullmatch(text):
        raise ValueError(f"cannot read {text!r} as a quantity (unexpected characters)")
    powers = list(_POWER.finditer(text))
    if len(powers) > MAX_POWERS:
        raise ValueError(f"cannot read {text!r} as a quantity (more than {MAX_POWERS} powers)")
    for match in powers:
        if not _SMALL_EXPONENT.match(text, match.end()):
            raise ValueError(f"cannot read {text!r} as a quantity (an exponent must be a number"
                             " of at most two digits, e.g. m**2)")


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The unit registry shared by geardyn (created once, on first use; pint is imported then, so
    that a process that parses no unit string does not pay its import)."""
    import pint

    return pint.UnitRegistry()


def to_si(value: object, kind: str) -> float:
    """Convert ``value`` (a number in SI, or a unit string) to a float in the SI unit of ``kind``.

    Raises ``ValueError`` with a message naming the expected unit when the string cannot be
    parsed or has the wrong dimension; pydantic turns it into an error naming the field.
    """
    unit = SI_UNITS[kind]
    if isinstance(value, bool):
        raise ValueError(f"expected a number or a quantity in {unit or 'no unit'}, not a boolean")
    if isinstance(value, int | float):
        try:
            return float(value)
        except OverflowError:  # an int beyond the float range
            raise ValueError("an integer too large for a float") from None
    if not isinstance(value, str):
        raise ValueError(f"expected a number or a quantity string in {unit or 'no unit'}")
    text = value.strip()
    if not text:
        raise ValueError("empty quantity string")
    _check_quantity_text(text)
    ureg = registry()
    import pint

    try:
        q = ureg.Quantity(text)
    except Exception as exc:  # pint raises several types for bad strings
        raise ValueError(f"cannot read {text!r} as a quantity ({type(exc).__name__})") from None
    if not isinstance(q, pint.Quantity):  # a bare number parsed from a string: as it is
        return _real(q, text, unit)
    magnitude = _magnitude(q, text, unit)
    if kind == "frequency":
        return _angular(q, text, magnitude)
    return magnitude


def si_value(field: str, value: object, kind: str, minimum: float | None = None,
             strict: bool = False) -> float:
    """``value`` (a number in SI or a unit string, :func:`to_si`) as a finite float, at least
    (``strict``: above) ``minimum``; else a :class:`~geardyn.ParameterError` naming ``field``."""
    from geardyn.errors import ParameterError

    try:
        v = to_si(value, kind)
    except ValueError as exc:
        raise ParameterError(field, value, str(exc)) from None
    if not math.isfinite(v):
        raise ParameterError(field, value, "must be finite")
    if minimum is not None and (v <= minimum if strict else v < minimum):
        raise ParameterError(field, value, f"must be {'>' if strict else '>='} {minimum:g}")
    return v


def _magnitude(q: pint.Quantity, text: str, unit: str) -> float:
    """``q`` in ``unit`` (pint's conversion), rounded to 15 significant digits."""
    import pint

    try:
        magnitude = _real(q.to(unit or "dimensionless").magnitude, text, unit)
    except pint.DimensionalityError:
        has = f"units of {q.units:~}" if f"{q.units:~}" else "no unit"
        raise ValueError(f"{text!r} has {has} but {unit or 'a dimensionless number'} is"
                         " needed") from None
    except ValueError:
        raise
    except Exception as exc:  # offset units (degC) and the like
        raise ValueError(f"cannot convert {text!r} to {unit or 'a dimensionless number'}"
                         f" ({type(exc).__name__})") from None
    # Unit conversion multiplies by powers of ten; rounding to 15 significant digits removes the
    # last-bit noise ("50 um" -> 5e-05, not 4.9999999999999996e-05).
    return float(f"{magnitude:.15g}")


#: Units that count cycles per unit time (1 Hz = 2 pi rad/s), by pint's base name.
_CYCLE_UNITS = ("hertz",)


def _angular(q: pint.Quantity, text: str, magnitude: float) -> float:
    """An angular frequency [rad/s] from a quantity of dimension 1/time whose conversion to rad/s
    gave ``magnitude``: as it is when the units carry an angle (rad/s, deg/s, rpm), 2 pi times
    it when they count cycles (Hz); a bare inverse time (1/s) or a mix is refused."""
    ureg = registry()
    cycles = 0.0
    for name, exponent in q.unit_items():
        if any(base in _CYCLE_UNITS for _, base, _ in ureg.parse_unit_name(name)):
            cycles += exponent
    base = dict(q.to_base_units().unit_items())
    angle = base.pop("radian", 0)
    base.pop("second", None)
    if base or (cycles, angle) not in ((0, 1), (1, 0)):
        why = ("a bare inverse time: write rad/s for an angular frequency, or Hz or rpm for"
               " cycles" if (cycles, angle) == (0, 0) and not base
               else "its units mix cycles, angles or counts")
        raise ValueError(f"{text!r} is ambiguous as an angular frequency in rad/s ({why})")
    if cycles:
        return 2.0 * math.pi * magnitude
    return magnitude


def _real(value: object, text: str, unit: str) -> float:
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"cannot read {text!r} as a real number in {unit or 'no unit'}") \
            from None
