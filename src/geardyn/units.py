"""Physical quantities: SI floats or unit strings such as ``"50 um"`` or ``"0.825e9 N/m"``.

Every parameter is stored as a float in SI units. A plain number is taken to be SI already; a
string is parsed with pint and converted to the field's SI unit, so ``"1500 N m"``, ``"1.5 kN*m"``
and ``1500`` are the same input torque.
"""

from __future__ import annotations

from functools import lru_cache

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
    "dimensionless": "",
    "frequency": "rad/s",
}


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The unit registry shared by geardyn (created once, on first use)."""
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
        return float(value)
    if not isinstance(value, str):
        raise ValueError(f"expected a number or a quantity string in {unit or 'no unit'}")
    text = value.strip()
    if not text:
        raise ValueError("empty quantity string")
    ureg = registry()
    try:
        q = ureg.Quantity(text)
    except Exception as exc:  # pint raises several types for bad strings
        raise ValueError(f"cannot read {text!r} as a quantity ({type(exc).__name__})") from None
    if not isinstance(q, pint.Quantity):  # a bare number parsed from a string
        return float(q)
    try:
        magnitude = q.to(unit).magnitude if unit else q.to("dimensionless").magnitude
    except pint.DimensionalityError:
        raise ValueError(
            f"{text!r} has units of {q.units:~} but {unit or 'a dimensionless number'} is needed"
        ) from None
    # Unit conversion multiplies by powers of ten; rounding to 15 significant digits removes the
    # last-bit noise ("50 um" -> 5e-05, not 4.9999999999999996e-05).
    return float(f"{float(magnitude):.15g}")
