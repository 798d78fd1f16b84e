"""The unit boundary: Quantity in -> plain floats -> Quantity out.

Public functions accept either astropy Quantities or plain floats.  Plain floats
are taken in the caller's own consistent units; Quantities are converted to the
internal unit of the argument, and results come back as Quantities in that
system.  Kernels never see astropy.
"""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits._validation import as_float_array


def is_quantity(value: Any) -> bool:
    """True if ``value`` is an astropy Quantity.

    Examples
    --------
    >>> is_quantity(1.0 * u.km), is_quantity(1.0)
    (True, False)
    """
    return isinstance(value, u.Quantity)


def strip(name: str, value: Any, unit: u.UnitBase | None, *, finite: bool = True) -> np.ndarray:
    """Return ``value`` as float64 in ``unit`` (Quantities) or as given (floats).

    Parameters
    ----------
    name : str
        Argument name for error messages.
    value : Quantity or array_like
        The input.
    unit : astropy unit or None
        Internal unit a Quantity is converted to; ``None`` requires a plain
        number or a dimensionless Quantity.

    Raises
    ------
    astropy.units.UnitConversionError
        If a Quantity's unit cannot be converted to ``unit``.
    ValueError
        For NaN / inf, naming the argument and the index.

    Examples
    --------
    >>> strip("r", 2.0 * u.km, u.m)
    array(2000.)
    >>> strip("r", [1.0, 2.0], u.m)
    array([1., 2.])
    """
    if isinstance(value, u.Quantity):
        target = u.dimensionless_unscaled if unit is None else unit
        try:
            value = value.to_value(target, equivalencies=u.dimensionless_angles())
        except u.UnitConversionError as exc:
            raise u.UnitConversionError(
                f"Expected `{name}` in units convertible to {target}, got {value.unit}"
            ) from exc
    return as_float_array(name, value, finite=finite)


def wrap(value: np.ndarray, unit: u.UnitBase | None, quantity: bool):
    """Attach ``unit`` if the call came in with Quantities, else return floats.

    Examples
    --------
    >>> wrap(np.array(3.0), u.s, True)
    <Quantity 3. s>
    >>> float(wrap(np.array(3.0), u.s, False))
    3.0
    """
    if quantity and unit is not None:
        return u.Quantity(value, unit)
    return value
