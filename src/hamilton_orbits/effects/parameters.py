"""The parameters of the effects: one rule for body names, units and DE440's defaults.

Every built-in effect's parameter builder (``params(system, mapping) ->
ndarray``) reads its mapping with these helpers, so that a body name, a speed of
light or a length is read, refused and reported the same way by every effect:

- :func:`source_index`, :func:`body_index`, :func:`optional_body_index`: the
  index of the body a parameter names;
- :func:`parameter_value`, ``parameter_array``, :func:`scalar_parameter`,
  :func:`speed_of_light`: numbers with a dimension (:data:`SYSTEM_UNITS`);
- DE440's defaults (the solar-system effects): :func:`require_de440_units`,
  :func:`finite_floats`, :func:`unit_vector`, :func:`axes_frame`,
  :func:`body_pole`, :func:`de440_c_au_per_day`.

The unit rule (``docs/effects.md``)
-----------------------------------
A parameter with a dimension (a length, a speed, a time, a GM, a rotation rate,
a spin: the effect's ``parameter_kinds``) is

- for a system of Quantities: a Quantity of that dimension, or a string that
  reads as one (``"299792.458 km/s"``), converted to the system's internal
  units (au, au/day, day, au^3/day^2, rad/day, au^2/day); a bare number is
  refused (``c = 1.0`` cannot say whether it is au/day or km/s: it was once read
  as au/day, and a radius of 6378 as 6378 au);
- for a system of plain floats: a bare number in the system's own units (those
  of its positions, velocities and GMs); a Quantity is refused (the system has
  no unit to convert it to);
- a dimensionless parameter (J2, C22, Love numbers, PPN beta and gamma) is a
  bare number; an angle named ``..._deg`` is a bare number of degrees or a
  Quantity of any angular unit.

Every value must be finite; a refusal names the effect, its index in the list,
the parameter, the value and the unit expected.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits.units import (
    ACCELERATION,
    ANGLE,
    ANGULAR_SPEED,
    DIMENSIONLESS,
    GM,
    LENGTH,
    SPEED,
    TIME,
    Kind,
    is_quantity,
    time_quantity,
)

__all__ = [
    "C_AU_PER_DAY",
    "FRAME_PARAMETER",
    "PARK_2021",
    "SPECIFIC_ANGULAR_MOMENTUM",
    "SYSTEM_UNITS",
    "axes_frame",
    "body_index",
    "body_list",
    "body_pole",
    "de440_c_au_per_day",
    "distinct_bodies",
    "finite_floats",
    "optional_body_index",
    "parameter_array",
    "parameter_value",
    "require_de440_units",
    "scalar_parameter",
    "source_index",
    "speed_of_light",
    "unit_example",
    "unit_vector",
    "with_units",
]

C_AU_PER_DAY = 299792458.0 * 86400.0 / 149597870700.0  # IAU 2012 au, SI c and day


def source_index(system: Any, params: Mapping[str, Any], key: str, effect: str) -> int:
    """The index of the body that mapping ``params`` names under ``key`` (default: the
    most massive), refusing a name not in ``system`` and a massless body.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 2.0, [1, 0, 0], [0, 0, 0])])
    >>> source_index(s, {}, "source", "gr"), source_index(s, {"source": "a"}, "source", "gr")
    (1, 0)
    """
    name = params.get(key)
    gm = system.as_arrays().gm
    if name is None:
        return int(np.argmax(gm))
    if not isinstance(name, str):
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be the name of a body, got "
                         f"{name!r}; bodies: {', '.join(system.names)}")
    if name not in system.names:  # (the closest names suggested, as for the others)
        raise _not_a_body(system, key, name, effect)
    idx = system.names.index(name)
    if not gm[idx] > 0:
        raise ValueError(f"Effect {effect!r}: body {name!r} is massless (gm = 0)")
    return idx


#: A spin: an angular momentum per unit mass (``lense_thirring``'s ``spin``).
SPECIFIC_ANGULAR_MOMENTUM = Kind("an angular momentum per unit mass", "m2 / s", no_hertz=True)

#: The internal unit of each dimension for a system of Quantities
#: (:mod:`hamilton_orbits.nbody`: au and days), to which a Quantity parameter is
#: converted; a system of plain floats takes bare numbers in its own units.
SYSTEM_UNITS: dict[Kind, str] = {
    LENGTH: "au", SPEED: "au / d", TIME: "d", GM: "au3 / d2", ANGULAR_SPEED: "rad / d",
    SPECIFIC_ANGULAR_MOMENTUM: "au2 / d", ACCELERATION: "au / d2",
}


def _shown(value: Any) -> str:
    text = repr(value) if not is_quantity(value) else str(value)
    return text if len(text) <= 60 else text[:57] + "..."


def with_units(value: Any, key: str, where: str, kind: Kind) -> Any:
    """``value`` with a string read as a Quantity (``"6378 km"``), an astropy
    TimeDelta as the time Quantity in days it holds
    (:func:`~hamilton_orbits.units.time_quantity`), and a list holding Quantities,
    TimeDeltas or strings as one Quantity array; anything else as given.

    The one reader of the unit strings that the mappings of effects, events and
    ``small_bodies.propagate(nongrav=...)`` take; the caller then converts the
    result as it converts a Quantity (its dimension checked there: a TimeDelta given
    for a length is refused as the time it is).

    Parameters
    ----------
    value : Any
        The value given.
    key : str
        Its name, for messages.
    where : str
        What the messages begin with (``"Effect 'gr'"``).
    kind : Kind
        The kind expected, for the example in a message.

    Returns
    -------
    Any
        A Quantity for a string, a TimeDelta or a list holding strings, TimeDeltas
        or Quantities, else ``value``.

    Raises
    ------
    ValueError
        For a string that is not a number with a unit, and a list of values that
        do not join into one Quantity, naming ``where``, the key and the value.

    Examples
    --------
    >>> with_units("0.1 au", "distance", "Event 0", LENGTH)
    <Quantity 0.1 AU>
    >>> with_units("0.1 auu", "distance", "Event 0", LENGTH)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Event 0: cannot read `distance` = '0.1 auu' as a number with a unit (e.g. ...)
    """
    import astropy.units as u

    def one(x: Any) -> Any:
        if not isinstance(x, str):
            return time_quantity(x)  # (a TimeDelta: the Quantity in days it holds)
        try:
            return u.Quantity(x)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: cannot read `{key}` = {value!r} as a number "
                             f"with a unit (e.g. '{unit_example(kind)}')") from None

    if not isinstance(value, (list, tuple)):
        return one(value)
    if any(isinstance(x, str) or is_quantity(one(x)) for x in value):
        try:
            return u.Quantity([one(x) for x in value])
        except (TypeError, ValueError):  # UnitConversionError included
            raise ValueError(f"{where}: expected `{key}` to be values of one "
                             f"dimension, each with its unit, got {_shown(value)}") from None
    return value


def parameter_array(system: Any, params: Mapping[str, Any], key: str, effect: str,
                    kind: Kind) -> np.ndarray | None:
    """Parameter ``key`` of mapping ``params`` as a float array in ``system``'s own
    units, or None if it is not given (the unit rule of the module's notes).

    One rule for every dimensioned parameter of every effect: a Quantity of
    ``kind`` (or a string that reads as one) for a Quantity system, converted to
    :data:`SYSTEM_UNITS`; a bare number in the caller's own units for a system of
    plain floats; a bare number for a Quantity system and a Quantity for a system
    of plain floats are refused (a unit cannot be guessed, nor dropped).  A
    dimensionless parameter takes a bare number; an angle (``kind`` ANGLE) a bare
    number of degrees or an angle Quantity, for either system.

    Raises
    ------
    ValueError
        For the wrong kind of value or a value that is not finite, naming the
        effect, the parameter and the value.
    astropy.units.UnitConversionError
        For a Quantity of the wrong dimension.

    Examples
    --------
    >>> import astropy.units as u
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0 * u.au**3 / u.d**2, [0, 0, 0] * u.au, [0, 0, 0] * u.au / u.d)])
    >>> parameter_array(s, {"tau": ["0.5 d", 12 * u.h]}, "tau", "earth_tides", TIME).tolist()
    [0.5, 0.5]
    """
    if key not in params:
        return None
    value = params[key]
    if kind is not DIMENSIONLESS:
        value = with_units(value, key, f"Effect {effect!r}", kind)
    if kind is ANGLE:
        unit = "deg"  # the parameter's name says degrees (inclination_deg)
    elif kind is DIMENSIONLESS:
        unit = ""
    else:
        if system.quantity and not is_quantity(value):
            raise ValueError(
                f"Effect {effect!r}: expected `{key}` as a Quantity ({kind.name}, convertible "
                f"to {kind.unit}; e.g. a string such as '{unit_example(kind)}') for a system of "
                f"Quantities, got the plain number {_shown(value)}")
        if not system.quantity and is_quantity(value):
            given = params[key]
            shown = (f"the string {given!r} (read as a Quantity)" if isinstance(given, str)
                     else f"the Quantity {_shown(value)}")
            raise ValueError(
                f"Effect {effect!r}: expected `{key}` as a plain number in the units of the "
                f"system (a system of plain floats), got {shown}")
        unit = SYSTEM_UNITS[kind] if system.quantity else None
    try:
        return kind(key, value, unit)
    except ValueError as exc:  # UnitConversionError included
        raise type(exc)(f"Effect {effect!r}: {exc}") from None


def unit_example(kind: Kind) -> str:
    """A value of ``kind`` with its unit, for messages (``"6378.1366 km"``).

    Examples
    --------
    >>> unit_example(SPEED)
    '299792.458 km/s'
    """
    return {LENGTH: "6378.1366 km", SPEED: "299792.458 km/s", TIME: "0.5 d",
            GM: "398600.4418 km3/s2", ANGULAR_SPEED: "7.292115e-5 rad/s",
            SPECIFIC_ANGULAR_MOMENTUM: "1e-7 au2/d", ANGLE: "1.5424 deg"}.get(
                kind, f"1 {kind.unit}")


def parameter_value(system: Any, params: Mapping[str, Any], key: str, effect: str,
                    kind: Kind) -> float | None:
    """The scalar parameter ``key`` of mapping ``params`` in ``system``'s own units,
    or None if it is not given (see ``parameter_array``).

    Raises
    ------
    ValueError
        As ``parameter_array`` (an ``astropy.units.UnitConversionError``
        for the wrong dimension), and for more than one number.

    Examples
    --------
    >>> import astropy.units as u
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> parameter_value(s, {"c": 10.0}, "c", "gr", SPEED)
    10.0
    >>> parameter_value(s, {"c": 3e5 * u.km / u.s}, "c", "gr", SPEED)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'gr': expected `c` as a plain number in the units of the system ...
    """
    if isinstance(params.get(key), (bool, np.bool_)):  # (True is not c = 1)
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be a number, got "
                         f"{params[key]!r}")
    arr = parameter_array(system, params, key, effect, kind)
    if arr is None:
        return None
    if arr.shape != ():
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be one number, got "
                         f"{_shown(params[key])} (shape {arr.shape})")
    return float(arr)


def scalar_parameter(system: Any, params: Mapping[str, Any], key: str, effect: str,
                     kind: Kind, default: float, *, positive: bool = False,
                     nonnegative: bool = False) -> float:
    """:func:`parameter_value`, ``default`` when not given (in the system's units),
    refusing a value that is not > 0 (``positive``) or not >= 0 (``nonnegative``).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("moon", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> scalar_parameter(s, {"radius": -1.0}, "radius", "moon_figure", LENGTH, 1.0,
    ...                  positive=True)
    Traceback (most recent call last):
    ...
    ValueError: Effect 'moon_figure': expected `radius` > 0, got -1.0
    """
    value = parameter_value(system, params, key, effect, kind)
    if value is None:
        return float(default)
    if (positive and not value > 0) or (nonnegative and not value >= 0):
        raise ValueError(f"Effect {effect!r}: expected `{key}` {'>' if positive else '>='} 0, "
                         f"got {_shown(params[key])}")
    return value


def speed_of_light(system: Any, params: Mapping[str, Any], effect: str) -> float:
    """The speed of light in ``system``'s units from mapping ``params`` (key ``"c"``;
    default c in au/day for a Quantity system); see :func:`parameter_value`.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> speed_of_light(s, {"c": 10.0}, "gr")
    10.0
    """
    c = parameter_value(system, params, "c", effect, SPEED)
    if c is None:
        if system.quantity:
            return C_AU_PER_DAY
        raise ValueError(
            f"Effect {effect!r}: a system of plain floats needs the speed of light `c` in "
            "its own units, e.g. {'name': 'gr', 'c': 10065.32}"
        )
    if not c > 0:
        raise ValueError(f"Effect {effect!r}: expected `c` > 0, got {params['c']!r}")
    return c


# ----------------------------------------------------------------------------------
# DE440's defaults: the solar-system effects (eih, lense_thirring, zonal, moon_figure,
# earth_tides, kuiper_ring) default to DE440's constants in au and days.

#: The source of DE440's models and constants.
PARK_2021 = "Park et al. (2021), AJ 161, 105"

#: What the ``frame`` parameter of the solar-system effects is (:func:`axes_frame`).
FRAME_PARAMETER = ("the system's axes, 'icrs' or 'ecliptic' (default: a scene's [initial] "
                   "frame, else recognised from DE440's poles, else 'icrs')")


def _not_a_body(system: Any, key: str, name: Any, effect: str) -> ValueError:
    import difflib

    close = difflib.get_close_matches(str(name), system.names, n=3)
    if not close:
        close = [n for n in system.names if n.lower() == str(name).lower()]
    hint = f" (did you mean {', '.join(map(repr, close))}?)" if close else ""
    return ValueError(f"Effect {effect!r}: `{key}` names body {name!r}, which is not in the "
                      f"system{hint}; bodies: {', '.join(system.names)}")


def body_index(system: Any, params: Mapping[str, Any], key: str, default: str,
               effect: str, massive: bool = False) -> int:
    """The index of the body that mapping ``params`` names under ``key`` (default:
    the body named ``default``), refusing a name not in ``system`` (and with
    ``massive`` a massless body: an effect whose field is its, pushing back on it
    by ``gm_i / gm_body``).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("moon", 0.0, [1, 0, 0],
    ...                                                           [0, 1, 0])])
    >>> body_index(s, {}, "moon", "moon", "moon_figure")
    1
    """
    name = params.get(key, default)
    if not isinstance(name, str) or name not in system.names:
        raise _not_a_body(system, key, name, effect)
    idx = system.names.index(name)
    if massive and not system.as_arrays().gm[idx] > 0:
        raise ValueError(f"Effect {effect!r}: `{key}` names body {name!r}, which is "
                         f"massless (gm = 0): the effect's field is that body's")
    return idx


def optional_body_index(system: Any, params: Mapping[str, Any], key: str, default: str,
                        effect: str) -> int:
    """The index of the body that mapping ``params`` names under ``key``, or -1 for
    none: given as None or ``"none"``, or not given and no body is named ``default``.
    A name given that is not in ``system`` is refused (``earth_tides``'s ``sun =
    "Sun"`` once dropped the solar tide without a word).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("earth", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> optional_body_index(s, {}, "sun", "sun", "earth_tides")
    -1
    >>> optional_body_index(s, {"sun": "Sun"}, "sun", "sun", "earth_tides")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'earth_tides': `sun` names body 'Sun', which is not in the system; ...
    """
    if key not in params:
        return system.names.index(default) if default in system.names else -1
    name = params[key]
    if name is None or name == "none":
        return -1
    return body_index(system, params, key, default, effect)


def body_list(system: Any, params: Mapping[str, Any], key: str, effect: str) -> list[int]:
    """The indices of the bodies that mapping ``params`` lists under ``key`` (a list
    of distinct names, at least one; none given: an empty list).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("vesta", 1e-10, [1, 0, 0],
    ...                                                           [0, 1, 0])])
    >>> body_list(s, {"bodies": ["vesta"]}, "bodies", "semi_active")
    [1]
    >>> body_list(s, {"bodies": "vesta"}, "bodies", "semi_active")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'semi_active': expected `bodies` to be a list of body names, got 'vesta'
    """
    if key not in params:
        return []
    names = params[key]
    if not isinstance(names, (list, tuple)) or not all(isinstance(x, str) for x in names):
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be a list of body names, "
                         f"got {names!r}")
    if not names:
        raise ValueError(f"Effect {effect!r}: `{key}` is empty")
    for k, name in enumerate(names):
        if name in names[:k]:
            raise ValueError(f"Effect {effect!r}: `{key}` names {name!r} twice (at index {k})")
    return [body_index(system, {key: x}, key, "", effect) for x in names]


def distinct_bodies(system: Any, indices: Mapping[str, int], effect: str) -> None:
    """Refuse one body named by two of an effect's parameters (``indices``: parameter
    -> body index, -1 for none).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("earth", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> distinct_bodies(s, {"earth": 0, "moon": 0}, "earth_tides")
    Traceback (most recent call last):
    ...
    ValueError: Effect 'earth_tides': `earth` and `moon` name one body, 'earth'
    """
    seen: dict[int, str] = {}
    for key, b in indices.items():
        if b >= 0 and b in seen:
            raise ValueError(f"Effect {effect!r}: `{seen[b]}` and `{key}` name one body, "
                             f"{system.names[b]!r}")
        seen.setdefault(b, key)


def require_de440_units(system: Any, params: Mapping[str, Any], effect: str,
                        keys: tuple[str, ...]) -> None:
    """Defaults are DE440's constants in au and days: a plain-float system must give
    every length and time itself (``keys``), else a ``ValueError`` names them."""
    if system.quantity:
        return
    missing = [k for k in keys if k not in params]
    if missing:
        raise ValueError(
            f"Effect {effect!r}: a system of plain floats needs {', '.join(missing)} in "
            "its own units (the defaults are DE440's in au and days)"
        )


def finite_floats(name: str, value: Any, size: int | None, effect: str) -> np.ndarray:
    """``value`` as a 1-d array of finite floats (of length ``size`` if given).

    Examples
    --------
    >>> finite_floats("k2", [0.3, 0.3, 0.3], 3, "earth_tides").tolist()
    [0.3, 0.3, 0.3]
    >>> finite_floats("k2", ["a", 0.3, 0.3], 3, "earth_tides")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'earth_tides': Expected `k2` to be numeric...
    """
    try:  # a string or a Quantity with a dimension: named, not "could not convert"
        arr = np.atleast_1d(DIMENSIONLESS(name, value, finite=False))
    except ValueError as exc:  # UnitConversionError included
        raise type(exc)(f"Effect {effect!r}: {exc}") from None
    if arr.ndim != 1 or (size is not None and arr.shape[0] != size) or not np.all(
            np.isfinite(arr)):
        raise ValueError(f"Effect {effect!r}: expected `{name}` to be "
                         f"{size or 'some'} finite number(s), got {_shown(value)}")
    return arr


def unit_vector(name: str, value: Any, effect: str) -> np.ndarray:
    """``value`` (three finite numbers, not all zero) divided by its norm.

    Examples
    --------
    >>> unit_vector("pole", [0, 0, 2], "zonal").tolist()
    [0.0, 0.0, 1.0]
    """
    k = finite_floats(name, value, 3, effect)
    norm = float(np.linalg.norm(k))
    if not norm > 0:
        raise ValueError(f"Effect {effect!r}: expected `{name}` to be nonzero, got {value!r}")
    return k / norm


def _frame_of_poles(system: Any) -> str | None:
    """The frame recognised from a pole :meth:`System.from_ephemeris` gives the Sun,
    the Earth or the Moon (:func:`hamilton_orbits.ephemeris.pole` in that frame), or
    None.  A pole along z is the Earth's in ICRS axes, and also what any body given
    ``j2`` and no pole has: it is not taken for ICRS axes where the system has the
    Sun and its orbits lie near its x-y plane (:func:`_ecliptic_tilt`: a hand-built
    Earth in ecliptic axes was taken for an ICRS one, the effects' directions 23.4
    degrees off)."""
    for name in ("sun", "earth", "moon"):
        if name in system.names and system[name].pole is not None:
            if tuple(system[name].pole) == (0.0, 0.0, 1.0) and "sun" in system.names \
                    and _ecliptic_tilt(system) is not None:
                continue
            pole = np.array(system[name].pole)
            for frame in ("icrs", "ecliptic"):
                if np.allclose(pole, de.pole(name, frame), rtol=0, atol=1e-12):
                    return frame
    return None


def _refuse_ecliptic_looking(system: Any, effect: str) -> None:
    """Refuse to take as ICRS axes a system whose orbits lie near its x-y plane (its
    angular momentum about the barycentre within 10 degrees of z, nearer z than the
    ICRS's ecliptic pole; with one massive body, the mean normal of the test
    particles' orbits about it): such axes are ecliptic ones, or the system is not
    the solar system, and the effect's default directions (the ecliptic pole, the
    Sun's and the Earth's poles) would be wrong by the obliquity."""
    to_z = _ecliptic_tilt(system)
    if to_z is not None:
        raise ValueError(
            f"Effect {effect!r}: expected `frame` ('icrs' or 'ecliptic'): the system's axes "
            f"are not known (no DE440 pole of the Sun, the Earth or the Moon to recognise "
            f"them by), and its orbits lie {to_z:.1f} deg from its x-y plane, as in "
            "ecliptic axes, not the ICRS's that the effect would take by default")


def _ecliptic_tilt(system: Any) -> float | None:
    """The angle in degrees of the system's angular momentum about its barycentre
    from z (with one massive body, of the mean normal of the test particles' orbits)
    where it is within 10 degrees of z and nearer z than the ICRS's ecliptic pole (the
    axes look ecliptic, see :func:`_refuse_ecliptic_looking`); else None."""
    arrays = system.as_arrays()
    gm = arrays.gm
    if not gm.sum() > 0:
        return None
    r = arrays.r - gm @ arrays.r / gm.sum()
    v = arrays.v - gm @ arrays.v / gm.sum()
    each = np.cross(r, v)
    h = gm @ each
    if not float(np.linalg.norm(h)) > 0:  # (one massive body: the orbits are the test
        # particles', which carry no angular momentum: their planes' mean normal)
        sizes = np.linalg.norm(each, axis=1, keepdims=True)
        h = np.sum(np.divide(each, sizes, out=np.zeros_like(each), where=sizes > 0)[gm == 0],
                   axis=0)
    norm = float(np.linalg.norm(h))
    if not (np.isfinite(norm) and norm > 0):
        return None
    k = h / norm
    to_z = float(np.degrees(np.arccos(np.clip(k[2], -1.0, 1.0))))
    to_ecliptic = float(np.degrees(np.arccos(np.clip(k @ de.ecliptic_pole("icrs"), -1.0, 1.0))))
    return to_z if to_z < 10.0 and to_z < to_ecliptic else None


def axes_frame(system: Any, params: Mapping[str, Any], effect: str) -> str:
    """The frame of the system's axes, for an effect's default directions.

    ``params["frame"]``; else recognised from a pole :meth:`System.from_ephemeris`
    sets (the Sun's, the Earth's or the Moon's, :func:`hamilton_orbits.ephemeris.pole`
    in that frame); else ``"icrs"``, unless the system's orbits lie near its x-y
    plane (its angular momentum within 10 degrees of z): those are not ICRS axes
    (the ecliptic is inclined 23.4 degrees to the ICRS's x-y plane), and a
    ``ValueError`` asks for ``frame``.  A scene passes its ``[initial] frame``.

    Examples
    --------
    >>> from hamilton_orbits import System
    >>> axes_frame(System.from_ephemeris(bodies=["earth", "moon"], frame="ecliptic"), {},
    ...            "moon_figure")
    'ecliptic'
    """
    frame = given_frame(params, effect)
    if frame is None:
        frame = _frame_of_poles(system)
        if frame is None:
            _refuse_ecliptic_looking(system, effect)
            frame = "icrs"
    return frame


def given_frame(params: Mapping[str, Any], effect: str) -> str | None:
    """``params["frame"]`` checked (``"icrs"`` or ``"ecliptic"``), or None when not
    given: checked even where the effect's directions are all given and the frame
    is not used, so that a wrong one is never taken silently.

    Examples
    --------
    >>> given_frame({"frame": "ecliptic"}, "zonal"), given_frame({}, "zonal")
    ('ecliptic', None)
    """
    frame = params.get("frame")
    if frame is not None and (not isinstance(frame, str) or frame not in ("icrs", "ecliptic")):
        raise ValueError(f"Effect {effect!r}: expected `frame` 'icrs' or 'ecliptic', "
                         f"got {frame!r}")
    return frame


def de440_c_au_per_day() -> float:
    """DE440's speed of light ``CLIGHT`` in au/day (its own au).

    Examples
    --------
    >>> round(de440_c_au_per_day(), 3)
    173.145
    """
    return de.constant("CLIGHT") * 86400.0 / de.constant("AU")


def body_pole(system: Any, b: int, params: Mapping[str, Any], effect: str) -> np.ndarray:
    """The pole of body ``b``: ``params["pole"]`` (normalised), else the Body's pole,
    else the z axis of the ICRS in the system's frame (:func:`axes_frame`)."""
    given_frame(params, effect)
    if "pole" in params:
        return unit_vector("pole", params["pole"], effect)
    pole = system.bodies[b].pole
    if pole is not None:
        return np.array(pole)
    return de.frame_rotation(axes_frame(system, params, effect)) @ [0.0, 0.0, 1.0]


#: ``pole`` of an effect about the Earth's pole of date
POLE_OF_DATE = "IAU2006"
POLE_PARAMETER = ("the Earth's pole: a vector (default the Body's pole), or 'IAU2006' for "
                  "its pole of date by the IAU 2006 precession (IERS Conventions 2010, eq. "
                  "5.16, without nutation; needs a Quantity system, its time in days)")
EPOCH_PARAMETER = ("with pole = 'IAU2006': the TDB of the simulation's time 0, an astropy "
                   "Time or a date (default 'J2000')")


def pole_of_date(system: Any, b: int, params: Mapping[str, Any], effect: str) -> np.ndarray:
    """The numbers that lead the ``p`` of a kernel about the Earth's pole of date
    (:data:`hamilton_orbits._kernels.figures.OF_DATE`: 1, the days from J2000 TDB
    of the system's time 0, then the rotation from the ICRS to the system's axes),
    followed by the pole of body ``b`` at time 0: for ``params["pole"] ==
    "IAU2006"``; else 0, 0 and the identity, then :func:`body_pole`.

    Raises
    ------
    ValueError
        Naming ``effect``: ``"IAU2006"`` for a system of plain floats (its time unit
        unknown), another text, or an ``epoch`` without it.

    Examples
    --------
    >>> from hamilton_orbits import System
    >>> s = System.from_ephemeris(bodies=["earth", "moon"])
    >>> lead = pole_of_date(s, 0, {"pole": "IAU2006", "epoch": "J2000"}, "zonal")
    >>> lead[:2].tolist(), lead[2:11].tolist() == np.eye(3).ravel().tolist(), lead.shape
    ([1.0, 0.0], True, (14,))
    """
    from hamilton_orbits._kernels.figures import precessed_pole

    pole = params.get("pole")
    if not isinstance(pole, str):
        if "epoch" in params:
            raise ValueError(f"Effect {effect!r}: `epoch` is the time of the pole of date; "
                             f"give it with pole = {POLE_OF_DATE!r}, got pole {pole!r}")
        return np.array([0.0, 0.0, *np.eye(3).ravel(), *body_pole(system, b, params, effect)])
    if pole != POLE_OF_DATE:
        raise ValueError(f"Effect {effect!r}: expected `pole` to be a vector or "
                         f"{POLE_OF_DATE!r}, got {pole!r}")
    if not system.quantity:
        raise ValueError(f"Effect {effect!r}: pole = {POLE_OF_DATE!r} needs a system of "
                         "Quantities (its time in days); this one is of plain floats")
    try:
        days = de.epoch_jd(params.get("epoch", "J2000")) - de.J2000_JD
    except ValueError as exc:
        raise ValueError(f"Effect {effect!r}: {exc}") from None
    rotation = de.frame_rotation(axes_frame(system, params, effect))
    k = np.empty(3)
    precessed_pole(days / 36525.0, k)
    return np.array([1.0, days, *rotation.ravel(), *(rotation @ k)])
