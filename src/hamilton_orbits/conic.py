"""Hamilton's geometry of the conic (seed eqs. 15-65) and the hodograph.

A :class:`Conic` is fixed by the semi-parameter ``p``, the eccentricity ``e``,
the reciprocal semi-major axis ``1/a`` (0 for the parabola; using ``1/a``
keeps every formula finite in the parabolic limit), the unit vector towards
periapsis and the unit normal of the plane.  Hamilton's epsilon is
``-e * periapsis_direction`` (it points to the apoapsis, eq. 13); the second
focus is ``2 a epsilon`` and the centre ``a epsilon`` (eqs. 28-36): for the
ellipse (a > 0) on the apoapsis side, for the hyperbola (a < 0) beyond the
periapsis, on the far side of the vertex.

At a point at distance ``r`` from the focus the second focal distance is
``r' = 2a - r`` (eq. 53; negative for the hyperbola, infinite for the
parabola), and the normal N, focal half-chord of curvature C and radius of
curvature R are (eqs. 61-65), in forms finite for every conic,

    C = r r'/a = r (2 - r/a),   N = sqrt(p C),   R = C^2 / N = C sqrt(C / p),

so that sqrt(R N) = C and R/C = C/N = N/p.

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some
dynamical questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from hamilton_orbits._columns import CLASSICAL
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits._orbit_build import clamp_inc, raise_at
from hamilton_orbits.twobody import STATE_UNITS, check_state, classical_columns
from hamilton_orbits.units import (
    ANGLE,
    DIMENSIONLESS,
    GM,
    LENGTH,
    Kind,
    as_quantity,
    is_quantity,
    require_consistent,
    wrap,
)
from hamilton_orbits.validation import (
    as_flag,
    as_float_array,
    broadcast,
    check_positive,
    check_trailing,
    first_index,
    fmt_index,
)

__all__ = ["Conic"]

u = LazyModule("astropy.units", globals(), "u")  # imported on first use

# internal units of a conic built from Quantities (those of KeplerOrbit)
_L, _V, _MU = STATE_UNITS


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def _in_range(method):
    """A conic formula evaluated without floating-point warnings; a NaN or an
    infinity the formula does not document (a parabola's r') means the value is
    beyond float64 for this input: ValueError naming the argument."""

    @functools.wraps(method)
    def guarded(self, *args, **kwargs):
        x = args[0] if args else next(iter(kwargs.values()), None)
        with np.errstate(all="ignore"):
            out = method(self, *args, **kwargs)
        for part in out if isinstance(out, tuple) else (out,):
            raw = part.value if is_quantity(part) else np.asarray(part)
            ok = np.isfinite(raw)
            if method.__name__ == "second_focal_distance":
                ok |= np.isposinf(raw) & np.broadcast_to(self._inv_a == 0, raw.shape)
            if not np.all(ok):
                arg = "nu" if method.__name__ == "radius" else "r"
                raise ValueError(
                    f"Expected `{arg}` for which `{method.__name__}` fits in float64, "
                    f"got {np.asarray(x).tolist() if not is_quantity(x) else x}"
                )
        return out

    return guarded


_ELEMENTS = ("p", "e", "inv_a", "inc", "lan", "argp", "mu")
# |(1 - e^2) - p/a| allowed, in units of eps max(1, e)^2 (the elements of a state,
# twobody.classical_columns, stay within 4 over the contract's magnitudes)
_CONSISTENT = 64.0 * np.finfo(float).eps


def _check_shape(p: np.ndarray, e: np.ndarray, inv_a: np.ndarray,
                 given: tuple[Any, Any, Any] = (None, None, None)) -> None:
    """Refuse ``p``, ``e`` and ``1/a`` (broadcast together) that are not one conic's:
    ``p >= 0`` (0 only for the radial orbit, ``e == 1``), ``e >= 0``, ``1/a`` of the
    sign of ``1 - e`` and equal to ``(1 - e^2)/p`` to 64 eps ``max(1, e)^2``.
    ``given``: ``p``, ``e`` and ``inv_a`` as the caller wrote them, the values quoted
    as a Quantity there has them ("got -1.0 AU", not the km of ``p``)."""
    gp, ge, gi = given
    raise_at("p", ~(p >= 0), p, ">= 0", gp)
    raise_at("e", ~(e >= 0), e, ">= 0", ge)
    raise_at("p", (p == 0) & (e != 1), p, "> 0 for e != 1 (p = 0 is a radial orbit, e = 1)",
             gp)
    raise_at("inv_a", (e < 1) & ~(inv_a > 0), inv_a, "> 0 for e < 1 (inv_a and e inconsistent)",
             gi)
    raise_at("inv_a", (e > 1) & ~(inv_a < 0), inv_a, "< 0 for e > 1 (inv_a and e inconsistent)",
             gi)
    m = np.maximum(e, 1.0)
    with np.errstate(all="ignore"):  # (scaled by max(1, e)^2; an overflow here is inconsistent)
        off = np.abs((1.0 - e) / m * ((1.0 + e) / m) - (p / m) * (inv_a / m)) > _CONSISTENT
        if np.any(off):
            i = first_index(np.atleast_1d(off)) if off.ndim else ()
            want, got = f"{float((1.0 - e[i]) * (1.0 + e[i]) / p[i])!r}", f"{float(inv_a[i])!r}"
            if is_quantity(gi):  # (in the unit of the inv_a given, as given)
                unit = gi.unit
                want = f"{float((float(want) / u.Unit(_L)).to_value(unit))!r} {unit.to_string()}"
                got = f"{float(np.broadcast_to(gi.value, off.shape)[i])!r} {unit.to_string()}"
            raise ValueError(
                f"Expected `inv_a` = (1 - e^2)/p = {want} (inv_a, p and e "
                f"inconsistent), got {got}{fmt_index(i if off.size > 1 else ())}"
            )


def _checked_elements(*values: Any) -> tuple[list[np.ndarray], bool]:
    """The arguments ``p, e, inv_a, inc, lan, argp, mu`` of :meth:`Conic.from_elements`
    as float arrays (their own shapes), and whether they came as Quantities, refused as
    :meth:`KeplerOrbit.from_elements <hamilton_orbits.KeplerOrbit.from_elements>`
    refuses its own: each finite, ``e >= 0``, ``inc`` in [0, pi], ``mu > 0``; and
    ``p >= 0`` (0 only for the radial orbit, ``e == 1``), ``1/a`` of the sign of
    ``1 - e`` and equal to ``(1 - e^2)/p`` to rounding.  Quantities are converted to
    the conic's units (km, 1/km, km^3/s^2, rad; :func:`_element_floats`).  ValueError
    naming the argument, the first bad index and the value."""
    arrays, quantity, given = _element_floats(values)
    arrays[3] = clamp_inc(arrays[3])  # (180 degrees in mas: an ulp above pi)
    p, e, inv_a, inc, _, _, mu = broadcast(_ELEMENTS, *arrays)
    gp, ge, gi, ginc, _, _, gmu = given
    _check_shape(p, e, inv_a, (gp, ge, gi))
    raise_at("inc", ~((inc >= 0) & (inc <= np.pi)), inc, "in [0, pi] rad", ginc)
    if is_quantity(gmu):
        raise_at("mu", ~(mu > 0), mu, "> 0", gmu)
    check_positive("mu", mu)
    return arrays, quantity


#: the kind of ``inv_a`` (1/a), converted to the conic's 1/km
_INV_LENGTH = Kind("a reciprocal length", "1 / km")


def _element_floats(values: Any) -> tuple[list[np.ndarray], bool, list[Any]]:
    """The elements ``p, e, inv_a, inc, lan, argp, mu`` as float arrays, whether
    ``p``, ``inv_a`` and ``mu`` are Quantities (all three or none: a unit cannot be
    guessed), and the values as given (a list of Quantities joined), for messages.
    Quantities are converted to the units of a conic of Quantities (those of
    :class:`~hamilton_orbits.orbit.KeplerOrbit`: km, 1/km, km^3/s^2), angles of any
    unit to radians (a plain float angle is radians), ``e`` a dimensionless Quantity or
    a number; a list of Quantities is the one Quantity it joins into
    (:func:`~hamilton_orbits.units.as_quantity`).  Plain floats are taken as given.
    The wrong dimension raises astropy's UnitConversionError (a ValueError) naming the
    argument."""
    p, e, inv_a, inc, lan, argp, mu = (as_quantity(n, x) for n, x in
                                       zip(_ELEMENTS, values, strict=True))
    quantity = require_consistent(("p", "inv_a", "mu"), (p, inv_a, mu))
    arrays = [LENGTH("p", p, _L), DIMENSIONLESS("e", e), _INV_LENGTH("inv_a", inv_a),
              ANGLE("inc", inc), ANGLE("lan", lan), ANGLE("argp", argp), GM("mu", mu, _MU)]
    return arrays, quantity, [p, e, inv_a, inc, lan, argp, mu]


#: how far from unit length and from orthogonal the axes given to :class:`Conic` may
#: be (|P.P - 1|, |n.n - 1|, |P.n|: those of :meth:`Conic.from_elements`, made of
#: sines and cosines, are within a few eps)
_AXES = 64.0 * np.finfo(float).eps

#: ``cos(x/2)`` at the float ``x = pi``: a parabola's ``nu`` no farther from an odd
#: multiple of pi than the float pi is (``|cos(nu/2)|`` at most this) is on its
#: asymptote (:meth:`Conic.radius`)
_COS_HALF_PI = float(np.cos(0.5 * np.pi))


def _checked_attributes(p: Any, e: Any, inv_a: Any, periapsis: Any, normal: Any,
                        mu: Any) -> tuple[np.ndarray, ...]:
    """The attributes given to :class:`Conic` as float arrays (their own shapes),
    refused as :meth:`Conic.from_elements` refuses its elements (``p``, ``e``,
    ``inv_a``, ``mu``), and the axes unless each is of shape ``(..., 3)``, finite,
    of unit length and the two orthogonal (to :data:`_AXES`)."""
    names = ("p", "e", "inv_a", "periapsis_direction", "normal", "mu")
    arrays = _plain_floats(names, (p, e, inv_a, periapsis, normal, mu), "km and km^3/s^2")
    for k in (3, 4):
        check_trailing(names[k], arrays[k], 3)
    pp, ee, ia, mm = broadcast(names[:3] + names[5:], *arrays[:3], arrays[5])
    _check_shape(pp, ee, ia)
    check_positive("mu", mm)
    big, n = broadcast(names[3:5], arrays[3], arrays[4])
    broadcast(names, *(a[..., 0] if k in (3, 4) else a for k, a in enumerate(arrays)))
    for name, x in ((names[3], _dot(big, big) - 1.0), (names[4], _dot(n, n) - 1.0)):
        _refuse_beyond(x, lambda i, at, name=name, x=x: (
            f"Expected `{name}` of unit length, got the length {float(np.sqrt(x[i] + 1.0))!r}"
            f"{at}"))
    cos = _dot(big, n)
    _refuse_beyond(cos, lambda i, at: (
        f"Expected `periapsis_direction` orthogonal to `normal`, got their dot product "
        f"{float(cos[i])!r}{at}"))
    return tuple(arrays)


def _plain_floats(names: tuple[str, ...], values: Any, units: str) -> list[np.ndarray]:
    """``values`` as finite float arrays (their own shapes), a Quantity refused by the
    name of its argument (the conic's numbers are in ``units`` with ``quantity=True``)."""
    arrays = []
    for name, x in zip(names, values, strict=True):
        if is_quantity(x):
            raise ValueError(f"Expected `{name}` as plain floats ({units} with "
                             f"`quantity=True`), got the Quantity {x}")
        arrays.append(as_float_array(name, x))
    return arrays


def _frozen(x: np.ndarray) -> np.ndarray:
    """A read-only float64 copy of ``x``: a conic keeps its own attributes, so that
    neither the caller's arrays (``p`` given to :meth:`Conic.from_elements`, an
    orbit's columns) nor in-place arithmetic on an attribute read back (``c.e``,
    ``c.p``) can change it."""
    out = np.array(x, dtype=np.float64)
    out.flags.writeable = False
    return out


def _refuse_beyond(x: np.ndarray, message: Any) -> None:
    """A ValueError of ``message(index, " at index ...")`` at the first element of
    ``x`` beyond :data:`_AXES` in magnitude (no index where ``x`` holds one value)."""
    bad = np.abs(x) > _AXES
    if np.any(bad):
        i = first_index(np.atleast_1d(bad)) if bad.ndim else ()
        raise ValueError(message(i, fmt_index(i if bad.size > 1 else ())))


class Conic:
    """Hamilton's conic section, vectorised over leading dimensions.

    Build from an orbit (``KeplerOrbit.conic``), with :meth:`from_state` or
    :meth:`from_elements`, or from its attributes.  Plain floats in the
    orbit's internal units (km, km/s for Quantity orbits).  The attributes are
    checked as :meth:`from_elements` checks its elements, and the two axes must be
    of unit length and orthogonal (to 64 eps): a ValueError names the attribute,
    the first offending index and the value.  The conic's shape is that of its
    attributes broadcast together (the axes' without their last axis); the
    methods taking a point (``nu``, ``r``) refuse one whose shape does not
    broadcast against it, naming the argument and both shapes.

    Attributes
    ----------
    p, e, inv_a : ndarray, shape (...)
        Semi-parameter (eq. 16), eccentricity (eq. 17), 1/a (0: parabola).
    periapsis_direction, normal : ndarray, shape (..., 3)
        Unit vectors: towards periapsis; along Hamilton's beta (eq. 3).
    mu : ndarray, shape (...)
        Gravitational parameter (for the hodograph).

    The conic keeps read-only copies of what it is given (an array written
    afterwards by the caller does not change it).

    Examples
    --------
    >>> c = Conic.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)
    >>> c
    Conic(p=1.44, e=0.44, inv_a=0.56)
    >>> round(float(c.a), 12), round(float(c.b), 12)
    (1.785714285714, 1.603567451475)
    >>> [round(float(x), 12) + 0.0 for x in c.second_focus]
    [-1.571428571429, 0.0, 0.0]
    """

    def __init__(
        self, p, e, inv_a, periapsis_direction, normal, mu, quantity: bool = False
    ) -> None:
        values = _checked_attributes(p, e, inv_a, periapsis_direction, normal, mu)
        self._set(*values, as_flag("quantity", quantity))

    def _set(self, p: np.ndarray, e: np.ndarray, inv_a: np.ndarray, periapsis: np.ndarray,
             normal: np.ndarray, mu: np.ndarray, quantity: bool) -> None:
        p, e, inv_a, mu, periapsis, normal = (
            _frozen(x) for x in (p, e, inv_a, mu, periapsis, normal))
        self._p, self.e, self._inv_a, self._mu = p, e, inv_a, mu
        self.periapsis_direction, self.normal = periapsis, normal
        self._quantity = quantity

    def __setstate__(self, state: dict[str, Any]) -> None:
        """A pickled or deep-copied conic: its arrays read-only again (numpy's pickle
        does not keep the flag, and a write would leave the conic inconsistent)."""
        self.__dict__.update(state)
        for name in ("_p", "e", "_inv_a", "_mu", "periapsis_direction", "normal"):
            self.__dict__[name] = _frozen(self.__dict__[name])

    def __repr__(self) -> str:
        def fmt(x: np.ndarray) -> str:
            return np.array2string(np.asarray(x), precision=6, threshold=6)

        unit = f" ({_L})" if self._quantity else ""
        return f"Conic(p={fmt(self._p)}, e={fmt(self.e)}, inv_a={fmt(self._inv_a)}){unit}"

    # ---------------------------------------------------------------- units
    def _in(self, name: str, value: Any, unit: u.UnitBase, vector: bool = False) -> np.ndarray:
        """A length (or, ``vector``, positions of shape (..., 3)) in the conic's units,
        broadcasting against the conic's shape (:meth:`_against`); no unit mixing."""
        if is_quantity(value) != self._quantity:
            kind = "a Quantity" if self._quantity else "plain floats"
            raise ValueError(
                f"Expected `{name}` as {kind} like the orbit this conic came from, "
                f"got {type(value).__name__}"
            )
        x = LENGTH(name, value, unit)
        return self._against(name, check_trailing(name, x, 3) if vector else x, vector)

    def _against(self, name: str, x: np.ndarray, vector: bool = False) -> np.ndarray:
        """``x``, refused unless its shape (its leading dimensions for a ``vector`` of
        shape (..., 3)) broadcasts against the conic's, that of its attributes
        broadcast together (the axes' without their last axis): ValueError naming
        the argument and both shapes."""
        mine = np.broadcast_shapes(self._p.shape, self.e.shape, self._inv_a.shape,
                                   self._mu.shape, self.periapsis_direction.shape[:-1],
                                   self.normal.shape[:-1])
        try:
            np.broadcast_shapes(mine, x.shape[:-1] if vector else x.shape)
        except ValueError:
            what = "of shape (..., 3) with leading dimensions" if vector else "of a shape"
            raise ValueError(
                f"Expected `{name}` {what} broadcasting against the conic's shape {mine}, "
                f"got shape {x.shape}"
            ) from None
        return x

    def _out(self, value: np.ndarray, unit: u.UnitBase):
        return wrap(value, unit, self._quantity)

    @property
    def p(self):
        """Semi-parameter (semi-latus rectum) ``p = -beta^2 / M`` (eq. 16)."""
        return self._out(self._p, _L)

    @property
    def inv_a(self):
        """``1/a`` (0 for the parabola)."""
        return self._out(self._inv_a, "1 / km")

    @property
    def mu(self):
        """Gravitational parameter (Hamilton's M)."""
        return self._out(self._mu, _MU)

    @classmethod
    def from_elements(
        cls, p: Any, e: Any, inv_a: Any, inc: Any, lan: Any, argp: Any, mu: Any, *,
        quantity: bool = False,
    ) -> Conic:
        """The conic of classical elements, given as floats or as Quantities.

        Parameters
        ----------
        p, e, inv_a : array_like or Quantity, shape (...)
            Semi-parameter (a length), eccentricity (a number) and 1/a (a reciprocal
            length; 0 for the parabola), as
            :class:`~hamilton_orbits.orbit.KeplerOrbit` computes them: finite,
            ``e >= 0``, ``p > 0`` (``p = 0`` only for a radial orbit, ``e = 1``),
            ``1/a`` of the sign of ``1 - e`` and ``p/a = 1 - e^2`` to rounding
            (64 eps ``max(1, e)^2``).
        inc, lan, argp : array_like or Quantity (angle), shape (...)
            Inclination in [0, pi] (``inc == pi``, the float, is exactly
            retrograde; up to two ulp above it is pi: 180 degrees in mas),
            longitude of the ascending node, argument of periapsis, finite; a
            plain number is in radians (beside Quantity lengths too), a Quantity
            of any angular unit (``30 * u.deg``).
        mu : array_like or Quantity, shape (...)
            Gravitational parameter, finite and > 0.
        quantity : bool, optional
            Whether plain floats are in km and km^3/s^2 and the conic's lengths
            and speeds are to be Quantities (as for a Quantity orbit).  Given
            as Quantities (``p``, ``inv_a`` and ``mu`` all three, a list of
            Quantities being the one Quantity it joins into), the elements are
            converted to km, 1/km and km^3/s^2 and the conic is one of
            Quantities whatever ``quantity`` says.

        Returns
        -------
        Conic
            With the periapsis direction ``P = cos(argp) n + sin(argp) m`` and
            the normal ``(sin inc sin lan, -sin inc cos lan, cos inc)``, where
            ``n = (cos lan, sin lan, 0)`` points to the ascending node and
            ``m`` is the normal times ``n``.

        Raises
        ------
        ValueError
            For an argument outside that domain, the arguments not broadcasting
            together, or ``p``, ``inv_a`` and ``mu`` not all Quantities or all
            plain floats, naming the argument, the first offending index and the
            value as given (a Quantity in its own unit: "got -1.0 AU", "got 200.0
            deg").
        astropy.units.UnitConversionError
            (a ValueError) For a Quantity of the wrong dimension (``p`` in
            seconds, an angle for ``e``, a mass for ``mu``), naming the argument.

        Examples
        --------
        >>> c = Conic.from_elements(1.44, 0.44, 0.56, 0.0, 0.0, 0.0, 1.0)
        >>> c.periapsis_direction.tolist(), c.normal.tolist(), float(c.a)
        ([1.0, 0.0, 0.0], [0.0, -0.0, 1.0], 1.7857142857142856)
        >>> Conic.from_elements(1.44, [0.44, -0.5], 0.56, 0.0, 0.0, 0.0, 1.0)
        Traceback (most recent call last):
        ...
        ValueError: Expected `e` >= 0, got -0.5 at index 1
        >>> c = Conic.from_elements(1.0 * u.au, 0.0, 1.0 / u.au, 90 * u.deg, 0.0, 0.0,
        ...                         1.32712440041e20 * u.m**3 / u.s**2)
        >>> c.p, c.normal.round(12).tolist()
        (<Quantity 1.49597871e+08 km>, [0.0, -1.0, 0.0])
        """
        values, quantities = _checked_elements(p, e, inv_a, inc, lan, argp, mu)
        p, e, inv_a, inc, lan, argp, mu = values
        quantity = as_flag("quantity", quantity) or quantities
        inc, lan, argp = np.broadcast_arrays(inc, lan, argp)  # (checked: they broadcast)
        cl, sl = np.cos(lan), np.sin(lan)
        ci = np.where(inc == np.pi, -1.0, np.cos(inc))
        si = np.where(inc == np.pi, 0.0, np.sin(inc))
        cw, sw = np.cos(argp), np.sin(argp)
        P = np.stack([cw * cl - sw * ci * sl, cw * sl + sw * ci * cl, sw * si], axis=-1)
        h = np.stack([si * sl, -si * cl, ci], axis=-1)
        conic = cls.__new__(cls)  # (checked above: the axes are unit and orthogonal)
        conic._set(p, e, inv_a, P, h, mu, quantity)
        return conic

    @classmethod
    def from_state(cls, r: Any, v: Any, mu: Any) -> Conic:
        """The conic through the state ``(r, v)`` about ``mu``.

        The state is checked as :meth:`KeplerOrbit.from_state
        <hamilton_orbits.KeplerOrbit.from_state>` checks it
        (``hamilton_orbits.twobody.check_state``; Quantities in give a
        conic of Quantities), and the elements are the orbit's
        (``hamilton_orbits.twobody.classical_columns``).

        Examples
        --------
        >>> round(float(Conic.from_state([1.0, 0, 0], [0, 1.0, 0], 1.0).e), 12)
        0.0
        """
        state, quantity = check_state(r, v, mu)
        c, _ = classical_columns(state)
        p, e, inv_a, inc, lan, argp = (
            c[CLASSICAL.index(n)] for n in ("p", "e", "inv_a", "inc", "lan", "argp")
        )
        return cls.from_elements(p, e, inv_a, inc, lan, argp, state[..., 6], quantity=quantity)

    # ---------------------------------------------------------------- shape
    @property
    def a(self) -> np.ndarray:
        """Semi-major axis ``p / (1 - e^2)`` (eq. 29); inf for the parabola.

        Raises
        ------
        ValueError
            Where ``1/inv_a`` is beyond float64 (``inv_a`` subnormal), naming
            ``inv_a``, the first such index and its value.
        """
        safe = np.where(self._inv_a == 0, 1.0, self._inv_a)
        with np.errstate(all="ignore"):
            a = 1.0 / safe
        self._refuse_beyond_float("a", a)
        return self._out(np.where(self._inv_a == 0, np.inf, a), _L)

    @property
    def b(self) -> np.ndarray:
        """Semi-minor axis ``a sqrt(1 - e^2) = sqrt(a p)`` (eq. 43) for the ellipse;
        for the hyperbola the length ``|a| sqrt(e^2 - 1)`` of the imaginary
        (conjugate) semi-axis, Hamilton's "vector with a positive square" (eq. 42);
        inf for the parabola.  ``sqrt(p / |inv_a|)``, or ``sqrt(p) / sqrt(|inv_a|)``
        where ``p / |inv_a|`` alone is beyond float64 or below its normal range (``b``
        fits where ``a`` may not).

        Raises
        ------
        ValueError
            Where ``b`` itself is beyond float64, naming ``inv_a``, the index and value.
        """
        ia = np.abs(np.where(self._inv_a == 0, 1.0, self._inv_a))
        with np.errstate(all="ignore"):
            ratio = self._p / ia
            # (p / |inv_a| beyond float64, or below its normal range, where it loses
            # digits: p = 1e-165 gave b = 0; then each root apart)
            whole = np.isfinite(ratio) & (ratio >= np.finfo(np.float64).tiny)
            b = np.where(whole, np.sqrt(ratio), np.sqrt(self._p) / np.sqrt(ia))
        self._refuse_beyond_float("b", b)
        return self._out(np.where(self._inv_a == 0, np.inf, b), _L)

    def _refuse_beyond_float(self, name: str, x: np.ndarray, vector: bool = False) -> None:
        """Refuse ``x`` (attribute ``name``, of the conic's shape, or (..., 3) with
        ``vector``) where it is not finite outside the parabola: ValueError naming
        ``inv_a``, index and value (the attributes of a conic broadcast: ``x`` may have
        more dimensions than ``inv_a``)."""
        bad = ~np.isfinite(x)
        if vector:
            bad = np.any(bad, axis=-1)
        bad = bad & (self._inv_a != 0)
        if np.any(bad):
            i = first_index(np.atleast_1d(bad)) if bad.ndim else ()
            value = float(np.broadcast_to(self._inv_a, bad.shape)[i])
            raise ValueError(
                f"Expected a conic for which `{name}` fits in float64, got inv_a={value!r}"
                f"{fmt_index(i if bad.size > 1 else ())}"
            )

    @property
    def hamilton_epsilon(self) -> np.ndarray:
        """Hamilton's epsilon = -e * periapsis direction (eq. 13), towards apoapsis."""
        return -self.e[..., None] * self.periapsis_direction

    def _times_a(self, what: str, x: np.ndarray) -> np.ndarray:
        """``a x`` (``x`` of shape (..., 3)), as ``x / inv_a``; refused for the parabola
        and where a component is beyond float64 (``inv_a`` subnormal)."""
        parabola = self._inv_a == 0
        if np.any(parabola):
            i = first_index(np.atleast_1d(parabola)) if parabola.ndim else ()
            raise ValueError(f"Expected a conic with a centre for `{what}`, got a parabola "
                             "(e = 1, inv_a = 0.0: the centre and second focus are at "
                             f"infinity){fmt_index(i if parabola.size > 1 else ())}")
        with np.errstate(all="ignore"):
            out = x / self._inv_a[..., None]
        self._refuse_beyond_float(what, out, vector=True)
        return out

    @property
    def centre(self) -> np.ndarray:
        """Vector of the centre from the focus, ``a epsilon`` (eq. 36)."""
        return self._out(self._times_a("centre", self.hamilton_epsilon), _L)

    @property
    def second_focus(self) -> np.ndarray:
        """Vector of the second focus, ``2 a epsilon`` (eq. 31)."""
        return self._out(self._times_a("second_focus", 2.0 * self.hamilton_epsilon), _L)

    @property
    def directrix_distance(self) -> np.ndarray:
        """Distance ``p / e`` from the focus to the directrix (on the periapsis
        side); inf for the circle."""
        safe = np.where(self.e == 0, 1.0, self.e)
        return self._out(np.where(self.e == 0, np.inf, self._p / safe), _L)

    # ------------------------------------------------------ at a point
    @_in_range
    def radius(self, nu: Any) -> np.ndarray:
        """Focal distance ``r = p / (1 + e cos nu)`` (eq. 20).

        The denominator is evaluated as ``(1 - e) + 2 e cos^2(nu/2)``, the same
        number: for ``e <= 1`` a sum of two terms >= 0 (``1 - e`` is exact for
        ``1/2 <= e <= 2``), where ``1 + e cos nu`` cancels near ``nu = pi``
        (8e-4 relative for the parabola at ``pi - 1e-7``, 5e-9 for ``e = 1 - 1e-12``
        at ``pi - 1e-4``).  The radius is then good to a few ulp times the
        condition number ``(|1 - e| + 2 e cos^2(nu/2)) / (1 + e cos nu)`` of that
        sum: 1 for the closed conics and the parabola, large only near a
        hyperbola's asymptote.  The same denominator decides a hyperbola's
        asymptote: ``nu`` is refused exactly where it is not positive (the
        parabola refuses the float pi alone, below).

        Parameters
        ----------
        nu : array_like or Quantity (angle)
            True anomaly (modulo 2 pi), broadcasting against the conic's shape;
            for an open conic strictly inside the asymptotes:
            ``|nu| < arccos(-1/e)`` for the hyperbola, ``|nu| < pi`` for the
            parabola (every float but the float pi, 1.2e-16 below pi, which is
            taken as pi, its asymptote, as
            :meth:`KeplerOrbit.from_elements <hamilton_orbits.KeplerOrbit.from_elements>`
            takes it).

        Raises
        ------
        ValueError
            For ``nu`` on or beyond an asymptote, naming the value and the range,
            or of a shape not broadcasting against the conic's, naming both shapes.

        Examples
        --------
        >>> c = Conic.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)
        >>> round(float(c.radius(np.pi)), 12)  # apoapsis p / (1 - e)
        2.571428571429
        >>> parabola = Conic.from_elements(2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # q = 1
        >>> float(parabola.radius(np.pi - 1e-7))  # that of the float nu to 1 ulp
        400000000329546.0
        >>> Conic.from_state([1.0, 0, 0], [0, 2.0, 0], 1.0).radius(np.pi)
        Traceback (most recent call last):
        ...
        ValueError: Expected `nu` inside the asymptotes, |nu| < arccos(-1/e) = 1.9106332362490186 rad (e = 3.0), got 3.141592653589793
        """  # noqa: E501
        nu = self._against("nu", ANGLE("nu", nu))
        e = self.e
        c = np.cos(0.5 * nu)
        den = (1.0 - e) + 2.0 * e * (c * c)  # 1 + e cos nu
        bad = ~(den > 0.0) | ((e == 1.0) & ~(np.abs(c) > _COS_HALF_PI))
        if np.any(bad):
            e_b = np.broadcast_to(e, bad.shape)
            nu_b = np.broadcast_to(nu, bad.shape)
            i = first_index(np.atleast_1d(bad)) if bad.ndim else ()
            e_i = float(e_b[i])
            limit = "|nu| < pi"  # (the parabola; a closed conic refuses no nu)
            if e_i > 1.0:
                # arccos(-1/e) as 2 atan(sqrt((e + 1)/(e - 1))), to an ulp or two (arccos
                # of the rounded -1/e was 3e-15 off for e = 1 + 1e-6, inside the limit)
                lim = 2.0 * math.atan2(math.sqrt(e_i + 1.0), math.sqrt(e_i - 1.0))
                limit = f"|nu| < arccos(-1/e) = {lim!r} rad"
            raise ValueError(
                f"Expected `nu` inside the asymptotes, {limit} (e = {e_i!r}), "
                f"got {float(nu_b[i])!r}{fmt_index(i)}"
            )
        return self._out(self._p / den, _L)

    def _on_conic(self, r: np.ndarray) -> np.ndarray:
        """Refuse a focal distance off the conic: ``q <= r <= Q`` (periapsis and
        apoapsis distances; ``Q = inf`` for open conics), to 16 eps of rounding."""
        q = self._p / (1.0 + self.e)
        safe = np.where(self._inv_a > 0, self._inv_a, 1.0)
        big = np.where(self._inv_a > 0, 2.0 / safe - q, np.inf)
        tol = 16.0 * np.finfo(float).eps
        bad = ~((r >= q * (1.0 - tol)) & (r <= big * (1.0 + tol)) & (r > 0.0))
        if np.any(bad):
            q_b, big_b, r_b = np.broadcast_arrays(q, big, r)
            i = first_index(np.atleast_1d(bad)) if bad.ndim else ()
            unit = f" {_L}" if self._quantity else ""
            raise ValueError(
                f"Expected `r` on the conic, q <= r <= Q with the periapsis distance "
                f"q = {float(q_b[i]):.17g} and the apoapsis distance Q = {float(big_b[i]):.17g}"
                f"{unit}, got {float(r_b[i])!r}{unit}{fmt_index(i)}"
            )
        return r

    def _chord(self, r: np.ndarray) -> np.ndarray:
        # >= 0 on the conic; a rounding-level excursion beyond the apoapsis is 0
        return np.maximum(r * (2.0 - r * self._inv_a), 0.0)

    @_in_range
    def focal_half_chord(self, r: Any) -> np.ndarray:
        """C = r r'/a = r (2 - r/a) (eq. 63), at focal distance ``r`` (``q <= r <= Q``).

        Examples
        --------
        >>> c = Conic.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)
        >>> round(float(c.focal_half_chord(1.0)), 12)
        1.44
        >>> c.normal_length(10.0)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: Expected `r` on the conic, q <= r <= Q with ..., got 10.0
        """
        return self._out(self._chord(self._on_conic(self._in("r", r, _L))), _L)

    @_in_range
    def second_focal_distance(self, r: Any) -> np.ndarray:
        """``r' = 2a - r`` (eq. 53): negative for the hyperbola, inf for the parabola."""
        r = self._on_conic(self._in("r", r, _L))
        safe = np.where(self._inv_a == 0, 1.0, self._inv_a)
        return self._out(np.where(self._inv_a == 0, np.inf, 2.0 / safe - r), _L)

    @_in_range
    def normal_length(self, r: Any) -> np.ndarray:
        """N = sqrt(p r r'/a) (eq. 65), the normal between the curve and the axis."""
        c = self._chord(self._on_conic(self._in("r", r, _L)))
        return self._out(np.sqrt(self._p) * np.sqrt(c), _L)  # (p c overflows beyond 1e154)

    @_in_range
    def radius_of_curvature(self, r: Any) -> np.ndarray:
        """R = C^2 / N = C sqrt(C / p) (eqs. 63-64); ``q <= r <= Q`` and ``p > 0``."""
        c = self._chord(self._on_conic(self._in("r", r, _L)))
        self._require_areal("radius_of_curvature")
        return self._out(c * np.sqrt(c / self._p), _L)

    @_in_range
    def radial_speed_squared(self, r: Any) -> np.ndarray:
        """``(dr/dt)^2 = M (2/r - 1/a - p/r^2)`` (eq. 66), at ``q <= r <= Q``."""
        r = self._on_conic(self._in("r", r, _L))
        w = self._mu * (2.0 / r - self._inv_a - self._p / r / r)  # (r r overflows)
        return self._out(np.maximum(w, 0.0), "km2 / s2")  # a rounding-level negative is 0

    def _require_areal(self, what: str) -> None:
        if np.any(~(self._p > 0)):
            raise ValueError(
                f"Expected a conic with angular momentum (p > 0) for `{what}`, got a radial "
                "orbit (p = 0: the conic is a segment of a line)"
            )

    @_in_range
    def hodograph(self, r: Any) -> tuple[np.ndarray, np.ndarray]:
        """Hamilton's decomposition of the velocity at position ``r`` (after eq. 65).

        Returns ``(rotating, fixed)``: ``rotating = (mu/h) normal x r/|r|``, of
        constant magnitude ``mu/h``, perpendicular to the radius vector;
        ``fixed = (mu/h) normal x (e periapsis_direction)``, constant, of
        magnitude ``e mu/h`` and parallel to the velocity at perihelion.  Their
        sum is the velocity (it is eq. 12, ``dalpha/dt = iota M/beta + const``).

        Parameters
        ----------
        r : array_like, shape (..., 3)
            A position on the orbit, its leading dimensions broadcasting against
            the conic's shape.

        Examples
        --------
        >>> c = Conic.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)
        >>> rot, fix = c.hodograph([1.0, 0, 0])
        >>> (rot + fix + 0.0).round(12).tolist()
        [0.0, 1.2, 0.0]
        """
        r = self._in("r", r, _L, vector=True)
        nonzero = np.any(r != 0, axis=-1)
        if not np.all(nonzero):
            i = first_index(np.atleast_1d(~nonzero)) if nonzero.ndim else ()
            raise ValueError(
                f"Expected `r` a nonzero position (the direction of the radius vector), "
                f"got {r[i].tolist()}{fmt_index(i)}"
            )
        self._require_areal("hodograph")
        big = np.max(np.abs(r), axis=-1, keepdims=True)  # |r| without under/overflow
        r = r / big
        h = np.sqrt(self._mu * self._p)
        k = (self._mu / h)[..., None]
        rhat = r / np.sqrt(_dot(r, r))[..., None]
        rot = k * np.cross(self.normal, rhat)
        fix = k * np.cross(self.normal, self.e[..., None] * self.periapsis_direction)
        return self._out(rot, _V), self._out(fix, _V)
