"""The unit boundary: Quantity in -> plain floats -> Quantity out.

Public functions accept either astropy Quantities or plain floats.  Plain floats
are taken in the caller's own consistent units; Quantities are converted to the
internal unit of the argument, and results come back as Quantities in that
system.  Kernels never see astropy.

There is one boundary per *kind* of argument (docs/design.md): a
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

import datetime
import functools
import sys
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.validation import as_float_array

# astropy.units is imported on first use: a caller that has not imported it
# cannot have passed a Quantity (is_quantity), so plain-float calls never need it
u = LazyModule("astropy.units", globals(), "u")

__all__ = [
    "ACCELERATION",
    "ANGLE",
    "ANGULAR_MOMENTUM",
    "ANGULAR_SPEED",
    "DIMENSIONLESS",
    "ENERGY",
    "GM",
    "GM_NAME",
    "INERTIA",
    "LENGTH",
    "MASS",
    "SPEED",
    "TIME",
    "TORQUE",
    "Kind",
    "UnitLike",
    "any_quantity",
    "as_quantity",
    "is_quantity",
    "refuse_epoch",
    "require_consistent",
    "shown",
    "strip",
    "time_quantity",
    "wrap",
]


UnitLike = Any
"""An astropy unit, or its name as a string (parsed, and astropy imported, on first use)."""


@functools.lru_cache(maxsize=256)
def _parse_unit(text: str):
    return u.Unit(text)


def as_unit(unit: UnitLike):
    """``unit`` as an astropy unit (a string is parsed, once).

    Unit constants inside the package are strings (``"km / s"``), so that
    defining them does not import astropy.

    Examples
    --------
    >>> as_unit("km3 / s2") == u.km**3 / u.s**2
    True
    >>> as_unit(u.deg)
    Unit("deg")
    """
    return _parse_unit(unit) if isinstance(unit, str) else unit


def _quantity_class() -> type | None:
    """astropy's Quantity if astropy.units is imported, else None."""
    units = sys.modules.get("astropy.units")
    return None if units is None else getattr(units, "Quantity", None)


def is_quantity(value: Any) -> bool:
    """True if ``value`` is an astropy Quantity (False, without importing astropy,
    when astropy.units has not been imported: then no Quantity exists).

    Examples
    --------
    >>> is_quantity(1.0 * u.km), is_quantity(1.0)
    (True, False)
    """
    q = _quantity_class()
    return q is not None and isinstance(value, q)


def any_quantity(*values: Any) -> bool:
    """True if any of ``values`` is a Quantity (the call then answers in Quantities).

    Examples
    --------
    >>> any_quantity(1.0, 2.0 * u.s), any_quantity(1.0, None)
    (True, False)
    """
    q = _quantity_class()
    return q is not None and any(isinstance(v, q) for v in values)


def as_quantity(name: str, value: Any, *, vector: bool = False) -> Any:
    """``value`` with the other forms an astropy user gives one Quantity in made one.

    A list or tuple holding Quantities (nested or not) is joined by ``u.Quantity``
    (compatible units converted to the first one's: ``[7000 * u.km, 1 * u.Mm]`` is
    ``[7000, 1000] km``); for a ``vector`` argument, an astropy coordinate
    representation is its Cartesian coordinates (``get_xyz(xyz_axis=-1)``: the three
    last, as a vector argument takes them) and a ``CartesianDifferential`` its
    ``get_d_xyz(xyz_axis=-1)``.  The caller then checks the result as any Quantity.
    Another differential (a ``SphericalDifferential``, ...) is refused: its
    components are Cartesian only with the position they are taken at, which a
    vector argument alone does not have.

    Parameters
    ----------
    name : str
        The argument's name, for messages.
    value : Any
        What the caller gave.
    vector : bool, optional
        Whether the argument is a vector of three coordinates (last axis), which a
        representation can stand for.

    Returns
    -------
    Any
        One Quantity for the forms above; anything else as given.

    Raises
    ------
    ValueError
        For a list whose items do not join into one Quantity (another dimension, a
        plain number or a string beside a Quantity), or a ``vector`` argument given
        as a differential other than a ``CartesianDifferential``, naming the
        argument and the value (and, for the differential, how to make it Cartesian).

    Examples
    --------
    >>> as_quantity("a", [7000 * u.km, 1 * u.Mm])
    <Quantity [7000., 1000.] km>
    >>> as_quantity("a", [1.0, 2.0])
    [1.0, 2.0]
    >>> as_quantity("a", [7000 * u.km, 2.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `a` to be values of one dimension, each with its unit, got [...]
    """
    if isinstance(value, list | tuple) and _holds_quantity(value):
        try:
            return _joined(value)
        except (TypeError, ValueError):  # UnitConversionError included
            raise ValueError(f"Expected `{name}` to be values of one dimension, each with "
                             f"its unit, got {value!r}") from None
    coordinates = sys.modules.get("astropy.coordinates") if vector else None
    if coordinates is not None:  # (not imported: no representation was given)
        if isinstance(value, coordinates.BaseRepresentation):
            return value.to_cartesian().get_xyz(xyz_axis=-1)
        if isinstance(value, coordinates.CartesianDifferential):
            return value.get_d_xyz(xyz_axis=-1)
        if isinstance(value, coordinates.BaseDifferential):
            raise ValueError(_not_cartesian(name, value))
    return value


def _not_cartesian(name: str, value: Any) -> str:
    """Why a differential other than a CartesianDifferential is refused for ``name``."""
    kind = type(value).__name__
    shown = " ".join(repr(value).split())
    return (f"Expected `{name}` to be Cartesian (a Quantity of shape (..., 3), a coordinate "
            f"representation or a CartesianDifferential), got a {kind} {shown}: its "
            f"components ({', '.join(value.components)}) are Cartesian only with the "
            f"position they are taken at; give `{name}.to_cartesian(base=position)` (a "
            f"CartesianRepresentation), or `{name}.represent_as(CartesianDifferential, "
            f"base=position)`")


def _holds_quantity(items: list | tuple) -> bool:
    """Whether a list or tuple holds a Quantity, at any depth."""
    return any(is_quantity(x) or (isinstance(x, list | tuple) and _holds_quantity(x))
               for x in items)


def _joined(items: list | tuple):
    """One Quantity of nested lists (``u.Quantity`` joins one level only)."""
    return u.Quantity([_joined(x) if isinstance(x, list | tuple) else x for x in items])


#: Types that are never a TimeDelta (:func:`time_quantity`'s quick answer; not
#: astropy's Quantity: naming it here would import astropy with the package)
_NOT_TIME_DELTA = frozenset({float, int, np.float64, np.ndarray, list, tuple, type(None)})


def time_quantity(value: Any) -> Any:
    """``value``, an astropy TimeDelta made the time Quantity in days it holds (a
    numpy duration the Quantity in its unit).

    A duration is taken as a time Quantity or as astropy's own duration type, a
    :class:`~astropy.time.TimeDelta` (scalar or array): the public functions that
    take a duration pass it through here first, once, so that a TimeDelta is then
    accepted, converted and refused exactly as the Quantity in days it equals
    (refused beside a system of plain floats, as a Quantity is).  ``value.to(u.day)``
    keeps its precision (the sum of its two doubles of days, rounded once).  A numpy
    ``timedelta64`` (scalar or array; pandas' ``Timedelta`` and its Series, Python's
    ``datetime.timedelta``) is the time Quantity in its own unit
    (:func:`numpy_duration`): read as a number, it was its count (a minute as 1).

    Parameters
    ----------
    value : Any
        What the caller gave for a duration.

    Returns
    -------
    Any
        A TimeDelta as a Quantity in days; anything else as given (without importing
        astropy.time: a caller that has not imported it cannot have given a TimeDelta).

    Examples
    --------
    >>> from astropy.time import TimeDelta
    >>> time_quantity(TimeDelta(1800.0, format="sec"))
    <Quantity 0.02083333 d>
    >>> time_quantity(TimeDelta([0.0, 1.5], format="jd"))
    <Quantity [0. , 1.5] d>
    >>> time_quantity(2.0)
    2.0
    """
    kind = type(value)
    if kind in _NOT_TIME_DELTA:  # (plain types at once: an isinstance
        # against astropy's TimeDelta costs 0.3 us of every call)
        return numpy_duration(value) if kind is np.ndarray and value.dtype.kind == "m" else value
    time = sys.modules.get("astropy.time")
    delta = None if time is None else getattr(time, "TimeDelta", None)
    if delta is not None and isinstance(value, delta):
        return value.to(u.day)
    if isinstance(value, datetime.timedelta):  # (pandas' Timedelta too, to the ns)
        to64 = getattr(value, "to_timedelta64", None)
        a = np.asarray(to64() if to64 is not None else np.timedelta64(value))
    else:
        dtype = getattr(value, "dtype", None)  # (numpy's scalar, pandas' Series, Index)
        if not (isinstance(dtype, np.dtype) and dtype.kind == "m") or np.ma.is_masked(value):
            return value  # (masked: refused by the argument's check, not read unmasked)
        a = np.asarray(value)
    out = numpy_duration(a)
    return value if out is a else out  # (as given where it is refused: named so)


def refuse_epoch(name: str, value: Any) -> None:
    """Refuse an astropy :class:`~astropy.time.Time` given for the duration ``name``:
    a Time is an epoch, not a duration (subtract an epoch from it, or give a TimeDelta
    or a time Quantity), naming the argument and quoting the value.

    Examples
    --------
    >>> from astropy.time import Time
    >>> refuse_epoch("dt", 2.0)  # not an epoch: nothing to say
    >>> refuse_epoch("dt", Time("2020-01-01"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `dt` to be a duration, got the epoch <Time ...2020-01-01 00:00:00.000>: ...
    """
    if type(value) in _NOT_TIME_DELTA:  # (plain types at once)
        return
    time = sys.modules.get("astropy.time")  # (not imported: no Time was made)
    if time is not None and isinstance(value, time.Time):
        raise ValueError(
            f"Expected `{name}` to be a duration, got the epoch {value!r}: an astropy Time "
            "is an epoch; subtract the epoch the state is at (t - t0, a TimeDelta), or "
            "give a TimeDelta or a time Quantity")


def shown(value: Any) -> str:
    """``value`` as a message quotes it: a Quantity as its number(s) and unit, a string
    with how to read it as a Quantity, anything else as its repr (cut at 60 characters).

    Examples
    --------
    >>> shown(2.0 * u.day), shown("30 min"), shown(1.5)
    ('2 d', "'30 min' (a string: u.Quantity('30 min') reads it)", '1.5')
    """
    if is_quantity(value):
        return _short(value)
    text = repr(value)
    text = text if len(text) <= 60 else text[:57] + "..."
    return f"{text} (a string: u.Quantity({text}) reads it)" if isinstance(value, str) else text


#: numpy's time units of a fixed length, as astropy's (a year or a month of numpy's
#: calendar is not one: refused)
_NUMPY_TIME_UNITS = {"W": "wk", "D": "d", "h": "h", "m": "min", "s": "s", "ms": "ms",
                     "us": "us", "ns": "ns", "ps": "ps", "fs": "fs", "as": "as"}


def numpy_duration(value: np.ndarray) -> Any:
    """A numpy ``timedelta64`` array as the time Quantity it is, in its own unit (its
    counts exact in a float64 below 2**53); ``NaT`` a NaN, which the argument's check
    then refuses by its name and index.  A timedelta64 of no unit, of years or of
    months (numpy's calendar units: not a fixed duration) is returned as given,
    for that check to refuse.

    Examples
    --------
    >>> numpy_duration(np.array([90, 120], dtype="timedelta64[m]"))
    <Quantity [ 90., 120.] min>
    """
    unit, count = np.datetime_data(value.dtype)
    if unit not in _NUMPY_TIME_UNITS:
        return value
    counts = np.where(np.isnat(value), np.nan, value.astype(np.int64) * float(count))
    return counts * u.Unit(_NUMPY_TIME_UNITS[unit])


class Kind:
    """One kind of physical argument: its dimension and default internal unit.

    Parameters
    ----------
    name : str
        What the kind is called in messages ("an angle", "a length", ...).
    unit : astropy unit or str
        The default internal unit a Quantity is converted to (a string is
        parsed on first use; the attribute ``unit`` is always an astropy unit).
    equivalencies : list or callable, optional
        Unit equivalencies this kind allows (a callable returning the list is
        called on first use), e.g. ``u.dimensionless_angles`` for the rates.

    Calling a kind, ``KIND(name, value, unit=None, finite=True)``, returns a
    float64 array: Quantities are converted to ``unit`` (default: the kind's
    unit), plain numbers pass as they are.  An astropy ``TimeDelta`` is the
    Quantity in days it holds (:func:`time_quantity`), to the bit, so that every
    time argument converted here takes one (a caller whose plain numbers are in
    some other unit of its own refuses a Quantity, and so a TimeDelta passed
    through :func:`time_quantity` first, before this call).

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
    >>> LENGTH("a", 1.0 * u.s)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    astropy...UnitConversionError: Expected `a` to be a length (convertible to m), got 1 s
    """

    def __init__(
        self, name: str, unit: UnitLike, equivalencies: list | Callable[[], list] | None = None,
        *, no_hertz: bool = False
    ) -> None:
        self.name = name
        self._unit = unit
        self._equivalencies = [] if equivalencies is None else equivalencies
        #: a unit holding the hertz refused: a frequency in cycles per second, which
        #: the equivalencies would read as radians per second (2 pi off)
        self.no_hertz = no_hertz

    @property
    def unit(self):
        """The default internal unit (an astropy unit)."""
        return as_unit(self._unit)

    @property
    def equivalencies(self) -> list:
        """The unit equivalencies this kind allows."""
        eq = self._equivalencies
        return eq() if callable(eq) else eq

    def __repr__(self) -> str:
        return f"Kind({self.name!r}, {str(self._unit)!r})"

    def __call__(
        self, name: str, value: Any, unit: UnitLike | None = None, *, finite: bool = True
    ) -> np.ndarray:
        value = time_quantity(value)  # (a TimeDelta: the Quantity in days it holds)
        if is_quantity(value):
            target = self.unit if unit is None else as_unit(unit)
            if self is DIMENSIONLESS and value.unit.physical_type == "angle":
                raise u.UnitConversionError(
                    f"Expected `{name}` to be dimensionless, got {_short(value)} (an angle)"
                )
            if self.no_hertz and _hertz(value.unit):
                raise u.UnitConversionError(self._no_hertz(name, value.unit))
            try:
                value = value.to_value(target, equivalencies=self.equivalencies)
            except u.UnitConversionError as exc:
                if self is DIMENSIONLESS:
                    what = "dimensionless"
                else:
                    what = f"{self.name} (convertible to {target})"
                got = (_short(value) if str(value.unit)
                       else f"{_short(value)}(a number without a unit)")
                raise u.UnitConversionError(
                    f"Expected `{name}` to be {what}, got {got}{self._hint(value)}"
                ) from exc
        return as_float_array(name, value, finite=finite)

    def _hint(self, value: Any) -> str:
        """What to give instead, where a common mistake is plain: a mass for a GM."""
        if self.name == GM_NAME and value.unit.physical_type == "mass":
            return "; a mass: give G times it (astropy.constants.G * m), or the GM itself"
        return ""

    def _no_hertz(self, name: str, unit: Any) -> str:
        """Why ``unit``, holding the hertz (or a count of decays), is refused."""
        head = f"Expected `{name}` to be {self.name}, got {unit}: "
        if not _holds(unit, (u.Hz,)):
            return (head + "a count of decays per second, not of radians; give "
                    f"{self.unit:generic}")
        turns = " (cycle / s for turns per second)" if self._equivalencies else ""
        return (head + "the hertz counts cycles, 2 pi rad each (ISO 80000-3 gives angular "
                f"speeds no hertz); give {self.unit:generic} counting radians{turns}")

    def scalar(self, name: str, value: Any, unit: UnitLike | None = None) -> float:
        """One number of this kind, as a float (a Quantity converted to ``unit``).

        Raises as calling the kind does, and ``ValueError`` for an array,
        naming the argument and its shape.

        Examples
        --------
        >>> DIMENSIONLESS.scalar("tol", 1e-9)
        1e-09
        >>> DIMENSIONLESS.scalar("tol", 1e-9 * u.s)
        Traceback (most recent call last):
        ...
        astropy.units.errors.UnitConversionError: Expected `tol` to be dimensionless, got 1e-09 s
        >>> LENGTH.scalar("radius", [1.0, 2.0])
        Traceback (most recent call last):
        ...
        ValueError: Expected `radius` to be one number, got shape (2,)
        """
        arr = self(name, value, unit)
        if arr.shape != ():
            raise ValueError(f"Expected `{name}` to be one number, got shape {arr.shape}")
        return float(arr)


def _short(q: u.Quantity) -> str:
    """A Quantity in a message: its value (up to 6 numbers) and unit."""
    if q.isscalar:
        return f"{q.value:g} {q.unit}"
    if q.size <= 6:
        values = ", ".join(f"{x:g}" for x in np.ravel(q.value))
        return f"[{values}] {q.unit}"
    return f"{q.unit} values"


def _hertz(unit: Any) -> bool:
    """Whether ``unit`` holds the hertz (or the becquerel, or the curie), prefixed or
    not (kHz, daHz, rad Hz, MBq): astropy finds them equal to 1/s (the curie to
    3.7e10/s), which is not refused."""
    return _holds(unit, (u.Hz, u.Bq, u.Ci))  # (counts of cycles, of decays, per second)


def _holds(unit: Any, units: tuple[Any, ...]) -> bool:
    """Whether ``unit`` holds one of ``units``, prefixed or not, by identity (astropy's
    ``==`` finds the hertz and the becquerel equal)."""
    def one(x: Any) -> bool:
        return any(x is c for c in units)

    return any(one(base) or (isinstance(base, u.PrefixUnit)
                             and any(one(x) for x in base.represents.bases))
               for base in getattr(unit, "bases", [unit]))


def _dimensionless_angles() -> list:
    return u.dimensionless_angles()


ANGLE = Kind("an angle", "rad")
LENGTH = Kind("a length", "m")
TIME = Kind("a time", "s")
SPEED = Kind("a speed", "m / s")
ACCELERATION = Kind("an acceleration", "m / s2")
#: the name of the kind of a gravitational parameter (a mass given for it is hinted at)
GM_NAME = "a gravitational parameter GM"
GM = Kind(GM_NAME, "m3 / s2")
MASS = Kind("a mass", "kg")
DIMENSIONLESS = Kind("dimensionless", "")
INERTIA = Kind("a moment of inertia", "kg m2")
ANGULAR_SPEED = Kind("an angular speed", "rad / s", _dimensionless_angles, no_hertz=True)
ANGULAR_MOMENTUM = Kind("an angular momentum", "kg m2 / s", _dimensionless_angles,
                        no_hertz=True)
ENERGY = Kind("an energy", "J", _dimensionless_angles)
TORQUE = Kind("a torque", "N m", _dimensionless_angles)


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
    quantities = [(n, v) for n, v in given if is_quantity(v)]
    if not quantities:
        return False
    qname, qvalue = quantities[0]
    for n, v in given:
        if not is_quantity(v):
            if isinstance(v, list | tuple) and any(is_quantity(x) for x in v):
                raise ValueError(f"Expected `{n}` to be a Quantity like `{qname}` ({qvalue}), "
                                 f"got a {type(v).__name__} of Quantities {v!r}: make it one "
                                 f"Quantity (u.Quantity({n}))")
            what = ("the plain number" if isinstance(v, int | float | complex | np.number
                                                     | np.ndarray | list | tuple)
                    else f"a {type(v).__name__}")  # (a TimeDelta is no plain number)
            raise ValueError(
                f"Expected `{n}` to be a Quantity like `{qname}` ({qvalue}), got {what} {v!r}"
            )
    return True


def strip(name: str, value: Any, unit: UnitLike | None, *, finite: bool = True) -> np.ndarray:
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
    if not is_quantity(value):  # plain numbers: the kind cannot matter
        return as_float_array(name, value, finite=finite)
    unit = None if unit is None else as_unit(unit)
    if unit is None or unit.physical_type == "dimensionless":
        return DIMENSIONLESS(name, value, unit, finite=finite)
    if unit.physical_type == "angle":
        return ANGLE(name, value, unit, finite=finite)
    if unit.physical_type == "angular speed":
        return ANGULAR_SPEED(name, value, unit, finite=finite)
    return Kind("a quantity", unit)(name, value, finite=finite)


def wrap(value: np.ndarray, unit: UnitLike | None, quantity: bool):
    """Attach ``unit`` if the call came in with Quantities, else return floats.

    Examples
    --------
    >>> wrap(np.array(3.0), u.s, True)
    <Quantity 3. s>
    >>> float(wrap(np.array(3.0), u.s, False))
    3.0
    """
    if quantity and unit is not None:
        return u.Quantity(value, as_unit(unit))
    return value
