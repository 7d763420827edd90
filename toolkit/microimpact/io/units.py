"""Units accepted in lab-data files and their conversion to the toolkit's internal units.

There is ONE table, :data:`UNITS`: for each dimension, every accepted spelling of a unit and the
factor that converts a value in that unit to the internal unit of the dimension. Internal units are
SI (m, m/s, rad/s, [1]) except angles, which the toolkit keeps in degrees in columns whose name ends in
``_deg`` (as in :func:`microimpact.model.kinematics.incident_velocity`).

Unit spellings are matched exactly after removing spaces (``m / s`` is ``m/s``); they are
case-sensitive because ``mm`` and ``Mm`` are different units.
"""

from __future__ import annotations

import math
import re
from types import MappingProxyType

import numpy as np

__all__ = [
    "UNITS",
    "INTERNAL_UNIT",
    "UnitError",
    "accepted_units",
    "conversion_factor",
    "to_internal",
    "parse_header_field",
]

_DEG = 180.0 / math.pi

#: dimension -> {unit spelling: factor to the internal unit of that dimension}
UNITS: MappingProxyType = MappingProxyType(
    {
        "length": MappingProxyType(
            {
                "m": 1.0,
                "mm": 1e-3,
                "um": 1e-6,
                "\u00b5m": 1e-6,  # MICRO SIGN
                "\u03bcm": 1e-6,  # GREEK SMALL LETTER MU
                "micron": 1e-6,
                "microns": 1e-6,
                "nm": 1e-9,
            }
        ),
        "speed": MappingProxyType({"m/s": 1.0, "cm/s": 1e-2, "mm/s": 1e-3}),
        "angle": MappingProxyType({"deg": 1.0, "degree": 1.0, "degrees": 1.0, "\u00b0": 1.0, "rad": _DEG}),
        "dimensionless": MappingProxyType({"1": 1.0, "-": 1.0}),
        "angular_speed": MappingProxyType({"rad/s": 1.0, "1/s": 1.0, "rpm": 2.0 * math.pi / 60.0}),
    }
)

#: dimension -> internal unit written in docs, messages and NetCDF ``units`` attributes
INTERNAL_UNIT: MappingProxyType = MappingProxyType(
    {"length": "m", "speed": "m/s", "angle": "deg", "dimensionless": "1", "angular_speed": "rad/s"}
)


class UnitError(ValueError):
    """A unit that is not in :data:`UNITS` for the dimension asked for.

    Examples
    --------
    >>> to_internal([1.0], "furlong", "length")
    Traceback (most recent call last):
    ...
    microimpact.io.units.UnitError: unit 'furlong' is not accepted for a length;
    accepted units: m, mm, um, ...
    """


def _normalise(unit: str) -> str:
    return re.sub(r"\s+", "", unit)


def accepted_units(dimension: str) -> tuple[str, ...]:
    """The accepted spellings of units of ``dimension`` ('length', 'speed', 'angle', 'dimensionless', 'angular_speed').

    Examples
    --------
    >>> accepted_units("length")[:3]
    ('m', 'mm', 'um')
    """
    return tuple(UNITS[dimension])


def conversion_factor(unit: str, dimension: str) -> float:
    """Factor that converts a value in ``unit`` to the internal unit of ``dimension``.

    Parameters
    ----------
    unit : str
        Unit as written, e.g. ``"um"``, ``"cm/s"``, ``"rad"``; spaces are ignored.
    dimension : str
        One of the keys of :data:`UNITS`.

    Returns
    -------
    float
        Multiply a value in ``unit`` by this to get it in ``INTERNAL_UNIT[dimension]``.

    Raises
    ------
    UnitError
        If ``unit`` is not accepted for ``dimension``; the message lists the accepted units.

    Examples
    --------
    >>> conversion_factor("um", "length")
    1e-06
    """
    table = UNITS[dimension]
    try:
        return table[_normalise(unit)]
    except KeyError:
        raise UnitError(
            f"unit {unit!r} is not accepted for a {dimension}; accepted units: {', '.join(table)}"
        ) from None


def to_internal(values, unit: str, dimension: str) -> np.ndarray:
    """``values`` given in ``unit`` converted to the internal unit of ``dimension``.

    Parameters
    ----------
    values : array_like
        Numbers in ``unit``.
    unit : str
        Unit of ``values``.
    dimension : str
        One of the keys of :data:`UNITS`.

    Returns
    -------
    numpy.ndarray
        ``values * conversion_factor(unit, dimension)`` as float64. [internal unit]

    Examples
    --------
    >>> to_internal([1.0, 2.0], "um", "length").tolist()
    [1e-06, 2e-06]
    """
    return np.asarray(values, dtype=float) * conversion_factor(unit, dimension)


_HEADER = re.compile(r"^\s*(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?\s*$")


def parse_header_field(field: str) -> tuple[str, str | None]:
    """Split a CSV header field ``"name [unit]"`` into ``(name, unit)``.

    The name is lower-cased and stripped; the unit is stripped, or None when there are no
    brackets. A field that does not match the pattern (e.g. nested brackets) is returned whole
    as the name with no unit, which then fails as an unknown column or a column without a unit.

    Examples
    --------
    >>> parse_header_field("radius [um]")
    ('radius', 'um')
    """
    m = _HEADER.match(field)
    if m is None:
        return field.strip().lower(), None
    unit = m.group("unit")
    return m.group("name").strip().lower(), (unit.strip() if unit is not None else None)
