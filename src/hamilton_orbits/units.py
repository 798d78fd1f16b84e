"""The unit boundary: Quantity in -> plain floats -> Quantity out.

Public functions accept either astropy Quantities or plain floats.  Plain floats
are taken in the caller's own consistent units; Quantities are converted to the
internal unit of the argument, and results come back as Quantities in that
system.  Kernels never see astropy.

There is one boundary per *kind* of argument (DESIGN.md, "Conventions"): a
:class:`Kind` knows its physical dimension and which unit equivalencies it
allows, so that

- an angle accepts any angular unit (``90 * u.deg`` is a quarter turn, never 90
  radians), and a plain float angle is radians;
- a dimensionless argument (an eccentricity, a Love number) refuses an angle:
  ``e = 5.7 * u.deg`` raises instead of being read as 0.0995;
- an angular rate (rad/s) accepts 1/s, the one place where astropy's
  ``dimensionless_angles`` equivalency is right;
- the wrong dimension raises :class:`astropy.units.UnitConversionError` naming
  the argument and the dimension it expects.

Every public function converts its arguments through these kinds, e.g.
``ANGLE("inc", inc)`` or ``LENGTH("r", r, u.km)``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits._validation import as_float_array

__all__ = [
    "ACCELERATION",
    "ANGLE",
    "ANGULAR_MOMENTUM",
    "ANGULAR_SPEED",
    "DIMENSIONLESS",
    "ENERGY",
    "GM",
    "INERTIA",
    "LENGTH",
    "MASS",
    "SPEED",
    "TIME",
    "TORQUE",
    "Kind",
    "any_quantity",
    "is_quantity",
    "require_consistent",
    "strip",
    "wrap",
]


def is_quantity(value: Any) -> bool:
    """True if ``value`` is an astropy Quantity.

    Examples
    --------
    >>> is_quantity(1.0 * u.km), is_quantity(1.0)
    (True, False)
    """
    return isinstance(value, u.Quantity)


def any_quantity(*values: Any) -> bool:
    """True if any of ``values`` is a Quantity (the call then answers in Quantities).

    Examples
    --------
    >>> any_quantity(1.0, 2.0 * u.s), any_quantity(1.0, None)
    (True, False)
    """
    return any(isinstance(v, u.Quantity) for v in values)


@dataclass(frozen=True)
class Kind:
    """One kind of physical argument: its dimension and default internal unit.

    Parameters
    ----------
    name : str
        What the kind is called in messages ("an angle", "a length", ...).
    unit : astropy unit
        The default internal unit a Quantity is converted to.
    equivalencies : list, optional
        Unit equivalencies this kind allows (only ``ANGULAR_SPEED`` has any).

    Calling a kind, ``KIND(name, value, unit=None, finite=True)``, returns a
    float64 array: Quantities are converted to ``unit`` (default: the kind's
    unit), plain numbers pass as they are.

    Raises
    ------
    astropy.units.UnitConversionError
        If a Quantity is not of this kind, naming the argument and the expected
        dimension.
    ValueError
        For non-numeric input, complex input, NaN or inf (with ``finite``),
        naming the argument, the index and the value.

    Examples
    --------
    >>> float(ANGLE("inc", 90 * u.deg))
    1.5707963267948966
    >>> float(ANGLE("inc", 0.5))                  # plain floats are radians
    0.5
    >>> DIMENSIONLESS("e", 5.7 * u.deg)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    astropy.units.errors.UnitConversionError: Expected `e` to be dimensionless, got 5.7 deg ...
    >>> LENGTH("a", 1.0 * u.au, u.km)
    array(1.49597871e+08)
    >>> LENGTH("a", 1.0 * u.s)
    Traceback (most recent call last):
    ...
    astropy.units.errors.UnitConversionError: Expected `a` to be a length (convertible to m), got s
    """

    name: str
    unit: u.UnitBase
    equivalencies: list = field(default_factory=list)

    def __call__(
        self, name: str, value: Any, unit: u.UnitBase | None = None, *, finite: bool = True
    ) -> np.ndarray:
        target = self.unit if unit is None else unit
        if isinstance(value, u.Quantity):
            if self is DIMENSIONLESS and value.unit.physical_type == "angle":
                raise u.UnitConversionError(
                    f"Expected `{name}` to be dimensionless, got {_short(value)} (an angle)"
                )
            try:
                value = value.to_value(target, equivalencies=self.equivalencies)
            except u.UnitConversionError as exc:
                if self is DIMENSIONLESS:
                    what = "dimensionless"
                else:
                    what = f"{self.name} (convertible to {target})"
                raise u.UnitConversionError(
                    f"Expected `{name}` to be {what}, got {value.unit}"
                ) from exc
        return as_float_array(name, value, finite=finite)


def _short(q: u.Quantity) -> str:
    if q.isscalar:
        return f"{q.value:g} {q.unit}"
    return f"{q.unit} values"


ANGLE = Kind("an angle", u.rad)
LENGTH = Kind("a length", u.m)
TIME = Kind("a time", u.s)
SPEED = Kind("a speed", u.m / u.s)
ACCELERATION = Kind("an acceleration", u.m / u.s**2)
GM = Kind("a gravitational parameter GM", u.m**3 / u.s**2)
MASS = Kind("a mass", u.kg)
DIMENSIONLESS = Kind("dimensionless", u.dimensionless_unscaled)
INERTIA = Kind("a moment of inertia", u.kg * u.m**2)
ANGULAR_SPEED = Kind("an angular speed", u.rad / u.s, u.dimensionless_angles())
ANGULAR_MOMENTUM = Kind("an angular momentum", u.kg * u.m**2 / u.s, u.dimensionless_angles())
ENERGY = Kind("an energy", u.J, u.dimensionless_angles())
TORQUE = Kind("a torque", u.N * u.m, u.dimensionless_angles())


def require_consistent(names: Sequence[str], values: Sequence[Any]) -> bool:
    """Refuse a call that mixes Quantities and plain numbers among dimensional arguments.

    A plain float next to a Quantity has no unit that could be guessed (a float
    ``dt`` beside ``t = 10 * u.s``: seconds? days?), so the mix is an error.
    ``None`` values (arguments left out) are ignored.

    Returns
    -------
    bool
        True if the call is in Quantities, False if in plain numbers.

    Raises
    ------
    ValueError
        Naming the plain argument and the Quantity argument.

    Examples
    --------
    >>> require_consistent(("t", "dt"), (10 * u.s, 0.1 * u.s))
    True
    >>> require_consistent(("t", "dt"), (10 * u.s, 0.1))
    Traceback (most recent call last):
    ...
    ValueError: Expected `dt` to be a Quantity like `t` (10.0 s), got the plain number 0.1
    """
    given = [(n, v) for n, v in zip(names, values, strict=True) if v is not None]
    quantities = [(n, v) for n, v in given if isinstance(v, u.Quantity)]
    if not quantities:
        return False
    qname, qvalue = quantities[0]
    for n, v in given:
        if not isinstance(v, u.Quantity):
            raise ValueError(
                f"Expected `{n}` to be a Quantity like `{qname}` ({qvalue}), "
                f"got the plain number {v!r}"
            )
    return True


def strip(name: str, value: Any, unit: u.UnitBase | None, *, finite: bool = True) -> np.ndarray:
    """Return ``value`` as float64 in ``unit`` (Quantities) or as given (floats).

    The kind is read off ``unit``: ``None`` or a dimensionless unit is
    :data:`DIMENSIONLESS` (angles refused), an angle unit is :data:`ANGLE`, a unit
    with radians in a rate is :data:`ANGULAR_SPEED`, anything else converts
    strictly (no equivalencies).  New code calls a :class:`Kind` directly.

    Parameters
    ----------
    name : str
        Argument name for error messages.
    value : Quantity or array_like
        The input.
    unit : astropy unit or None
        Internal unit a Quantity is converted to.

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
    if unit is None or unit.physical_type == "dimensionless":
        return DIMENSIONLESS(name, value, unit, finite=finite)
    if unit.physical_type == "angle":
        return ANGLE(name, value, unit, finite=finite)
    if unit.physical_type == "angular speed":
        return ANGULAR_SPEED(name, value, unit, finite=finite)
    return Kind("a quantity", unit)(name, value, finite=finite)


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
