"""The parameters of the effects: one rule for body names, units and DE440's defaults.

Every built-in effect's parameter builder (``params(system, mapping) ->
ndarray``) reads its mapping with these helpers, so that a body name, a speed of
light or a length is read, refused and reported the same way by every effect:

- :func:`source_index`, :func:`body_index`: the index of the body a parameter names;
- :func:`parameter_value`, :func:`speed_of_light`: a scalar with a dimension, a
  Quantity for a Quantity system and a plain number in the system's own units
  otherwise;
- DE440's defaults (the solar-system effects): :func:`require_de440_units`,
  :func:`finite_floats`, :func:`unit_vector`, :func:`axes_frame`,
  :func:`body_pole`, :func:`de440_c_au_per_day`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits.units import DIMENSIONLESS, LENGTH, SPEED, Kind, is_quantity

__all__ = [
    "C_AU_PER_DAY",
    "PARK_2021",
    "axes_frame",
    "body_index",
    "body_pole",
    "de440_c_au_per_day",
    "finite_floats",
    "parameter_value",
    "require_de440_units",
    "source_index",
    "speed_of_light",
    "unit_vector",
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
    if name not in system.names:
        raise ValueError(
            f"Effect {effect!r}: `{key}` names body {name!r}, which is not in the system; "
            f"bodies: {', '.join(system.names)}"
        )
    idx = system.names.index(name)
    if not gm[idx] > 0:
        raise ValueError(f"Effect {effect!r}: body {name!r} is massless (gm = 0)")
    return idx


# the internal units of a Quantity system (hamilton_orbits.nbody: au, day)
_SYSTEM_UNITS = {LENGTH: "au", SPEED: "au / d", DIMENSIONLESS: ""}


def parameter_value(system: Any, params: Mapping[str, Any], key: str, effect: str,
                    kind: Kind) -> float | None:
    """The scalar parameter ``key`` of mapping ``params`` in ``system``'s own units,
    or None if it is not given.

    One rule for every dimensioned parameter of every effect: a Quantity of
    ``kind`` for a Quantity system (converted to au, au/day), a plain number in
    the caller's own units for a system of plain floats; a plain number for a
    Quantity system and a Quantity for a system of plain floats are refused (a
    unit cannot be guessed, nor dropped).  A dimensionless parameter takes either.

    Raises
    ------
    ValueError
        For the wrong kind of value, a value that is not one finite number,
        naming the effect, the parameter and the value.
    astropy.units.UnitConversionError
        For a Quantity of the wrong dimension.

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
    if key not in params:
        return None
    value = params[key]
    if kind is not DIMENSIONLESS:
        if system.quantity and not is_quantity(value):
            raise ValueError(
                f"Effect {effect!r}: expected `{key}` as a Quantity ({kind.name}, convertible "
                f"to {kind.unit}) for a system of Quantities, got the plain number {value!r}")
        if not system.quantity and is_quantity(value):
            raise ValueError(
                f"Effect {effect!r}: expected `{key}` as a plain number in the units of the "
                f"system (a system of plain floats), got the Quantity {value}")
    unit = _SYSTEM_UNITS[kind] if system.quantity else None
    try:
        arr = kind(key, value, unit)
    except ValueError as exc:  # UnitConversionError included
        raise type(exc)(f"Effect {effect!r}: {exc}") from None
    if arr.shape != ():
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be one number, got "
                         f"{value!r} (shape {arr.shape})")
    return float(arr)


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


def body_index(system: Any, params: Mapping[str, Any], key: str, default: str,
               effect: str) -> int:
    """The index of the body that mapping ``params`` names under ``key`` (default:
    the body named ``default``), refusing a name not in ``system``.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("moon", 0.0, [1, 0, 0],
    ...                                                           [0, 1, 0])])
    >>> body_index(s, {}, "moon", "moon", "moon_figure")
    1
    """
    name = params.get(key, default)
    if name not in system.names:
        raise ValueError(
            f"Effect {effect!r}: `{key}` names body {name!r}, which is not in the system; "
            f"bodies: {', '.join(system.names)}"
        )
    return system.names.index(name)


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
    """
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.ndim != 1 or (size is not None and arr.shape[0] != size) or not np.all(
            np.isfinite(arr)):
        raise ValueError(f"Effect {effect!r}: expected `{name}` to be "
                         f"{size or 'some'} finite number(s), got {value!r}")
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


def axes_frame(system: Any, params: Mapping[str, Any], effect: str) -> str:
    """The frame of the system's axes: ``params["frame"]``, else recognised from the
    Sun's pole that :meth:`System.from_ephemeris` sets (IAU pole in that frame), else
    ``"icrs"``."""
    frame = params.get("frame")
    if frame is None:
        frame = "icrs"
        if "sun" in system.names and system["sun"].pole is not None:
            pole = np.array(system["sun"].pole)
            if np.allclose(pole, de.sun_pole("ecliptic"), rtol=0, atol=1e-12):
                frame = "ecliptic"
    if frame not in ("icrs", "ecliptic"):
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
    if "pole" in params:
        return unit_vector("pole", params["pole"], effect)
    pole = system.bodies[b].pole
    if pole is not None:
        return np.array(pole)
    return de.frame_rotation(axes_frame(system, params, effect)) @ [0.0, 0.0, 1.0]
