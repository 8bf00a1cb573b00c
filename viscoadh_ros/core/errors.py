"""Errors raised by the core for bad input.

Both are :class:`ValueError` subclasses so callers that only know the standard library
can still catch them. Messages always name the offending parameter with its full dotted
key (for example ``finger.material.kelvin_viscosities[1] must be > 0 (got -3.0)``), so a
user can find it in the scene file without reading a traceback.
"""

from __future__ import annotations

import numpy


class ConfigError(ValueError):
    """A scene configuration is malformed: unknown key, wrong type, out-of-range value."""


class InputError(ValueError):
    """A numerical input to the core is invalid: NaN/inf, negative modulus, time going
    backwards, mismatched array lengths, a non-monotonic profile table, ..."""


def require_finite(name: str, value: float) -> float:
    """Return ``value`` as a float, or raise :class:`InputError` naming ``name`` if it is
    not a finite real number. Text (``"0.01"``, ``b"0.01"``) and booleans are not numbers
    here, though ``float`` takes them."""
    if isinstance(value, (str, bytes, bytearray, bool, numpy.bool_)):
        raise InputError(f"{name} must be a number (got {value!r})")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number (got {value!r})") from None
    if number != number or number in (float("inf"), float("-inf")):
        raise InputError(f"{name} must be finite (got {number!r})")
    return number


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as a finite float > 0, else raise :class:`InputError` naming ``name``."""
    number = require_finite(name, value)
    if number <= 0.0:
        raise InputError(f"{name} must be > 0 (got {number!r})")
    return number


def require_positive_array(name: str, values: object) -> numpy.ndarray:
    """Return ``values`` as a 1-D float64 array of finite numbers > 0; the error names the
    first bad element as ``name[i]``."""
    try:
        array = numpy.asarray(values, dtype=numpy.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a list of numbers (got {values!r})") from None
    for index, number in enumerate(array):
        require_positive(f"{name}[{index}]", number)
    return array
