"""Two-body orbits: state vectors <-> orbital elements for every conic.

:class:`KeplerOrbit` keeps the state ``(r, v, mu)`` as float arrays and derives
all elements from it in compiled passes (``hamilton_orbits._kernels.elements``),
the first time one is asked for.  Hamilton's integrals are also available
exactly as the seed writes them, as quaternion products: :func:`hamilton_beta`
(eq. 3), :func:`hamilton_epsilon_from_products` (eq. 13) and
:func:`hamilton_p` (eq. 16).

Conventions (``docs/elements.md``): angles in radians; ``lan``, ``argp``,
``argument_of_latitude`` and the longitudes in [0, 2 pi); ``nu``, ``anomaly``
and (for bound orbits) ``M`` in (-pi, pi]; undefined angles are 0; for orbits
with ``inc > pi/2`` the longitudes are measured backwards along the orbit
(``varpi = lan - argp``), so that they stay defined for ``inc -> pi``.
``eccentricity_vector`` is the modern one (towards periapsis);
``hamilton_epsilon`` is Hamilton's epsilon, its negative (towards apoapsis).

Where the parts live: the element attributes and the conic in
:mod:`hamilton_orbits._orbit_elements` (``KeplerOrbit`` inherits them), the pieces
of :meth:`KeplerOrbit.from_elements` in :mod:`hamilton_orbits._orbit_build`,
Hamilton's products in :mod:`hamilton_orbits._hamilton_products` (imported here),
the checked state in :mod:`hamilton_orbits.twobody`.

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some
dynamical questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits import _columns
from hamilton_orbits import kepler as _kepler
from hamilton_orbits._hamilton_products import (
    hamilton_beta,
    hamilton_epsilon_from_products,
    hamilton_p,
)
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits._orbit_build import (
    anomaly_of,
    element_inputs,
    p_and_inv_a,
    raise_at,
    refuse_unreadable,
    state_of,
)
from hamilton_orbits._orbit_elements import OrbitElements
from hamilton_orbits.twobody import STATE_UNITS, check_state
from hamilton_orbits.units import TIME, is_quantity, refuse_epoch, shown, time_quantity

# numba and astropy are imported on first use (hamilton_orbits._lazy)
_el = LazyModule("hamilton_orbits._kernels.elements", globals(), "_el")
_kk = LazyModule("hamilton_orbits._kernels.kepler", globals(), "_kk")
u = LazyModule("astropy.units", globals(), "u")

__all__ = [
    "KeplerOrbit",
    "hamilton_beta",
    "hamilton_epsilon_from_products",
    "hamilton_p",
]

# internal units when Quantities come in
_L, _V, _MU = STATE_UNITS
_T = "s"

_F64 = np.dtype(np.float64)
_SHAPE3 = (3,)
_ONE_ORBIT_SIZE = _columns.ONE_ORBIT_SIZE


def _three(x: Any) -> tuple | None:
    """``x`` as a tuple of three Python floats if it is a float64 array of shape (3,)
    or a list or tuple of three Python floats, else None (the general path then takes
    it): one orbit's ``r`` or ``v`` for ``hamilton_orbits._kernels.elements.one_orbit``.
    (Always a tuple: arrays, strided arrays and tuples were each a type of their own,
    and each pair of them compiled the kernel again, 2.5-3.8 s a time.)"""
    t = type(x)
    if t is np.ndarray:
        # dtype identity: the native float64 (any other dtype takes the general path)
        return tuple(x.tolist()) if x.dtype is _F64 and x.shape == _SHAPE3 else None
    if (t is list or t is tuple) and len(x) == 3:
        a, b, c = x
        if type(a) is float and type(b) is float and type(c) is float:
            return (a, b, c)
    return None


class KeplerOrbit(OrbitElements):
    """Two-body (Kepler) orbits, vectorised over leading dimensions.

    Build with :meth:`from_state` or :meth:`from_elements`.  The object keeps
    the state; elements are computed once, in one compiled pass, on first use.

    The attributes have the leading dimensions as their shape, and are Quantities
    if the orbit was built from Quantities.

    Attributes
    ----------
    a : ndarray or Quantity
        Semi-major axis (``inf`` for the parabola, negative for the hyperbola).
    e, p, q : ndarray or Quantity
        Eccentricity, semi-latus rectum (Hamilton's p, eq. 16), periapsis distance.
    inc, lan, argp, nu, M, anomaly : ndarray or Quantity
        Inclination, longitude of the ascending node, argument of periapsis, true
        anomaly, mean anomaly and the eccentric (e < 1), parabolic ``D = tan(nu/2)``
        (e = 1) or hyperbolic (e > 1) anomaly.
    n, period, energy : ndarray or Quantity
        Mean motion (parabola: ``sqrt(mu / (2 q^3))``, so that ``M = n (t -
        t_peri)`` with Barker's ``M = D + D^3/3``), period (``inf`` if unbound),
        specific orbital energy.
    varpi, argument_of_latitude, true_longitude, mean_longitude : ndarray or Quantity
        The combinations that stay defined when ``e = 0`` or ``inc`` in {0, pi}.
    time_since_periapsis, areal_vector, eccentricity_vector, hamilton_epsilon : ndarray
        ``M / n`` (for the radial parabola the time since the collision);
        Hamilton's beta = r x v (twice the areal velocity, eq. 3); the modern
        eccentricity vector, towards periapsis; Hamilton's epsilon =
        -eccentricity_vector, towards apoapsis (eq. 13).  The first two are
        Quantities if the orbit was built from Quantities; the two eccentricity
        vectors, dimensionless, are plain numbers then too (as ``e`` is).

    Notes
    -----
    One representation: the state as one float64 array (..., 7), ``[rx, ry,
    rz, vx, vy, vz, mu]`` (km, km/s, km^3/s^2 for Quantities), and, once
    computed, the element columns, one row per element (``columns[i]`` is an
    element of every orbit).  One orbit's elements are a numpy float64, many
    orbits' an array of their leading shape.  Every attribute is computed the
    same way for one orbit and for many; the one shortcut is in
    :meth:`from_state`: one orbit of plain floats is checked and its classical
    elements computed by one kernel call.

    Examples
    --------
    >>> o = KeplerOrbit.from_state([1.0, 0.0, 0.0], [0.0, 1.2, 0.0], 1.0)
    >>> round(float(o.e), 12), round(float(o.a), 12), round(float(o.p), 12)
    (0.44, 1.785714285714, 1.44)
    >>> [round(float(x), 12) + 0.0 for x in o.hamilton_epsilon]
    [-0.44, 0.0, 0.0]
    """

    def __init__(
        self, state: np.ndarray, quantity: bool, classical: np.ndarray | None = None
    ) -> None:
        """Keep a checked state; build orbits with :meth:`from_state` or
        :meth:`from_elements`.

        ``state``: float64 array (..., 7), ``[rx, ry, rz, vx, vy, vz, mu]``
        (``hamilton_orbits.twobody.check_state``), that the orbit keeps and
        never writes to; ``quantity``: whether it was built from Quantities;
        ``classical``: its ``CLASSICAL`` columns, shape (NCLASSICAL, ...), if
        already known."""
        self._state = state
        self._quantity = quantity
        self._classical = classical

    # ------------------------------------------------------------------ build
    @classmethod
    def from_state(cls, r: Any, v: Any, mu: Any) -> KeplerOrbit:
        """Orbit through the state ``(r, v)`` about a centre of parameter ``mu``.

        Parameters
        ----------
        r : array_like or Quantity (length), shape (..., 3)
            Position relative to the attracting centre (nonzero).  A list of
            Quantities is the one Quantity ``u.Quantity`` joins it into; an astropy
            representation (``CartesianRepresentation``, ...) its Cartesian
            coordinates.
        v : array_like or Quantity (length/time), shape (..., 3)
            Velocity (a list of Quantities, a representation or a
            ``CartesianDifferential`` as for ``r``).
        mu : array_like or Quantity (length^3/time^2), shape (...)
            ``G (m1 + m2) > 0`` (Hamilton's M).

        Returns
        -------
        KeplerOrbit
            Leading shape = broadcast of ``r[..., 0]``, ``v[..., 0]``, ``mu``.

        Raises
        ------
        ValueError
            NaN / inf, trailing dimension not 3, ``mu <= 0``, ``r = 0``,
            incompatible shapes, or a mix of Quantities and plain floats.
        astropy.units.UnitConversionError
            For a Quantity of the wrong kind.

        Notes
        -----
        The state is the representation; the elements are derived from it.  Any
        finite state is accepted at any scale (it is brought to order 1 by powers
        of two inside the kernels, which is exact).  The state is checked by
        ``hamilton_orbits.twobody.check_state``; one orbit given as plain
        floats (``r``, ``v`` three floats each, ``mu`` a float) is checked and
        its classical elements computed in one kernel call instead
        (``hamilton_orbits._kernels.elements.one_orbit``, the same rule and
        the same arithmetic).

        *Representation limit near a hyperbola's asymptote.*  Far out along an
        open orbit, ``r`` and ``v`` are nearly parallel and the rounding of the
        state itself leaves the areal vector ``h = r x v`` uncertain by about
        ``eps |r| |v| / h`` relative (the condition number; ~1e12 for the
        example below), and so ``p``, ``e - 1`` and ``nu`` near the asymptote
        ``nu_inf = arccos(-1/e)``.  The ``(e, nu)`` returned can then lie on or
        beyond the asymptote of the float ``e`` (``1 + e cos nu <= 0``), a pair
        that :meth:`from_elements` refuses with ``nu``.  The mean anomaly ``M``
        stays defined there: rebuild such an orbit with ``M`` (it reproduces the
        position to the precision the state fixes), or keep the state.

        >>> o = KeplerOrbit.from_state([-1.8881600011099116e16, -9735075058187862.0,
        ...                             -2032451813774641.8],
        ...                            [-0.00012134184429701539, -6.256206895793337e-05,
        ...                             -1.306146996988154e-05], 1.0)
        >>> bool(1 + o.e * np.cos(o.nu) <= 0)          # on the asymptote of the float e
        True
        >>> el = dict(p=o.p, e=o.e, inc=o.inc, lan=o.lan, argp=o.argp, mu=1.0)
        >>> KeplerOrbit.from_elements(nu=o.nu, **el)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: Expected `nu` inside the asymptotes (1 + e cos nu > 0), got 3.14157...
        >>> r, _ = KeplerOrbit.from_elements(M=o.M, **el).state()
        >>> bool(np.all(np.isfinite(r)))
        True

        Examples
        --------
        >>> o = KeplerOrbit.from_state([[1.0, 0, 0], [1.5, 0, 0]], [0, 1.0, 0], 1.0)
        >>> o.shape, [round(float(x), 12) for x in o.e]
        ((2,), [0.0, 0.5])
        """
        if type(mu) is float:
            r3 = _three(r)
            v3 = _three(v)
            if r3 is not None and v3 is not None:
                out = np.empty(_ONE_ORBIT_SIZE)
                status = _el.one_orbit(out, r3, v3, mu)
                if status:  # 2: an element beyond float64, computed again and named when read
                    return cls(out[:7], False, out[7:] if status == 1 else None)
        return cls(*check_state(r, v, mu))

    @classmethod
    def from_elements(
        cls,
        *,
        e: Any,
        inc: Any,
        lan: Any,
        argp: Any,
        mu: Any,
        a: Any = None,
        p: Any = None,
        q: Any = None,
        nu: Any = None,
        M: Any = None,
    ) -> KeplerOrbit:
        """Orbit from classical elements.

        Parameters
        ----------
        a, p, q : array_like or Quantity (length), shape (...); exactly one
            Semi-major axis (``a > 0`` with ``e < 1``, ``a < 0`` with
            ``e > 1``; with ``e == 1`` a finite ``a`` gives the radial orbit of
            that energy), semi-latus rectum ``p > 0`` or periapsis distance
            ``q > 0``.
        e : array_like, shape (...)
            Eccentricity, ``e >= 0``; ``e == 1`` exactly is the parabola.
        inc : array_like or Quantity (angle), shape (...)
            Inclination in [0, pi] (``inc == pi`` is exactly retrograde; up to
            two ulp above the float pi is pi: 180 degrees converted from
            another unit, 648 000 000 mas, rounds there).  An angle
            given as a plain number is in radians, beside Quantity lengths too
            (``lan=10`` is 10 rad, 573 deg: give ``10 * u.deg``).
        lan, argp : array_like or Quantity (angle), shape (...)
            Longitude of the ascending node, argument of periapsis.
        nu, M : array_like or Quantity (angle), shape (...); exactly one
            True anomaly (inside the asymptotes for ``e >= 1``) or mean
            anomaly (Kepler's equation by :func:`hamilton_orbits.solve_kepler`).
            A radial orbit takes ``M``.
        mu : array_like or Quantity (length^3/time^2), shape (...)
            Gravitational parameter, ``> 0``.  Each of these parameters may also
            be a list of Quantities, the one Quantity ``u.Quantity`` joins it into
            (``a=[7000 * u.km, 1 * u.Mm]``).

        Returns
        -------
        KeplerOrbit

        Raises
        ------
        ValueError
            Naming the argument, index and value: ``e < 0``, ``a`` and ``e``
            inconsistent, ``p <= 0``, ``q <= 0``, ``mu <= 0``, ``inc`` outside
            [0, pi], ``nu`` beyond the asymptote, NaN / inf, incompatible
            shapes, not exactly one of a/p/q or nu/M; ``M`` (or ``e``) whose state
            the elements kernel could not read back (``|r| |v|^2 / mu`` beyond 2^450
            ~ 3e135: ``|M|`` that large on a hyperbola, ``e`` that large).
        ConvergenceError
            If Kepler's equation cannot be solved.

        Notes
        -----
        The state is ``r = x P + y Q`` with perifocal ``x = a (cos E - e)``,
        ``y = sqrt(a p) sin E`` (and the hyperbolic / parabolic analogues), i.e.
        Hamilton's conic ``r = p / (1 + e cos v)`` (eq. 20) with ``p = a (1 - e^2)``
        (eq. 29).

        ``nu`` of an open orbit must satisfy ``1 + e cos nu > 0`` for the float
        ``e`` given.  Elements read off a state far out along a hyperbola's
        asymptote may not (the state's rounding leaves ``h = r x v``, hence
        ``e`` and ``nu``, uncertain there; see :meth:`from_state`): pass ``M``
        for such orbits.  Lengths and ``mu`` of any magnitude are accepted
        (scaled to order 1 by powers of two inside the kernel).

        Examples
        --------
        >>> o = KeplerOrbit.from_elements(a=1.0, e=0.5, inc=0.0, lan=0.0, argp=0.0,
        ...                               nu=0.0, mu=1.0)
        >>> r, v = o.state()
        >>> [round(float(x), 12) + 0.0 for x in r], [round(float(x), 12) + 0.0 for x in v]
        ([0.5, 0.0, 0.0], [0.0, 1.732050807569, 0.0])
        """
        lname, length, aname, angle, e_, inc_, lan_, argp_, mu_, quantity = element_inputs(
            {"a": a, "p": p, "q": q}, {"nu": nu, "M": M}, e, inc, lan, argp, mu
        )
        written = {"a": a, "p": p, "q": q, "nu": nu, "M": M}  # (for the messages)
        p_, inv_a, radial = p_and_inv_a(lname, length, e_, written[lname])
        anom = anomaly_of(aname, angle, e_, radial, inv_a, written[aname])
        state = state_of(p_, e_, inv_a, inc_, lan_, argp_, anom, radial, mu_, angle)
        bad = ~np.all(np.isfinite(state[..., :6]), axis=-1)
        raise_at(lname, bad, length, "to give a finite state (check the elements)",
                 written[lname])
        refuse_unreadable(state, e_, inv_a, aname, angle, e, written[aname])
        return cls(state, quantity)

    def __len__(self) -> int:
        if not self.shape:
            raise TypeError("len() of a single KeplerOrbit")
        return self.shape[0]

    def __getitem__(self, key: Any) -> KeplerOrbit:
        if not self.shape:
            raise IndexError("a single KeplerOrbit cannot be indexed")
        # the key indexes the leading dimensions (an Ellipsis in it too)
        key = (*key, slice(None)) if type(key) is tuple else (key, slice(None))
        return KeplerOrbit(self._state[key], self._quantity)

    def __repr__(self) -> str:
        """One orbit: its elements (with units if built from Quantities; angles
        then in degrees); a batch: its shape and the range of each element.

        Examples
        --------
        >>> KeplerOrbit.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)
        KeplerOrbit(a=1.785714, e=0.44, inc=0, lan=0, argp=0, nu=0, mu=1)
        >>> KeplerOrbit.from_elements(a=7000 * u.km, e=0.01, inc=98 * u.deg, lan=10 * u.deg,
        ...                           argp=20 * u.deg, nu=30 * u.deg,
        ...                           mu=398600.4418 * u.km**3 / u.s**2)
        KeplerOrbit(a=7000 km, e=0.01, inc=98 deg, lan=10 deg, argp=20 deg, nu=30 deg, mu=398600.4 km3 / s2)
        >>> KeplerOrbit.from_state([[1.0, 0, 0], [1.5, 0, 0]], [0, 1.0, 0], 1.0)
        KeplerOrbit(shape=(2,), a in [1, 3], e in [0, 0.5], inc in [0, 0], lan in [0, 0], argp in [0, 0], nu in [0, 0], mu in [1, 1])
        """  # noqa: E501
        if 0 in self.shape:
            return f"KeplerOrbit(shape={self.shape})"
        col = self._col
        inv = col("inv_a")
        with np.errstate(over="ignore"):  # (an a beyond float64: q is shown instead)
            a = np.where(inv == 0, np.inf, 1.0 / np.where(inv == 0, 1.0, inv))
        q = col("p") / (1.0 + col("e"))
        length = "q" if np.all(inv == 0) or not np.all(np.isfinite(a) | (inv == 0)) else "a"
        cols = [(length, q if length == "q" else a, str(_L)), ("e", col("e"), "")]
        scale, aunit = (180.0 / np.pi, "deg") if self._quantity else (1.0, "")
        for name in ("inc", "lan", "argp", "nu"):
            cols.append((name, col(name) * scale, aunit))
        cols.append(("mu", self._mu, str(_MU)))
        parts = []
        for name, x, unit in cols:
            unit = f" {unit}" if (unit and self._quantity) else ""
            if not self.shape:
                parts.append(f"{name}={float(x):.7g}{unit}")
            else:
                parts.append(f"{name} in [{np.min(x):.7g}, {np.max(x):.7g}]{unit}")
        head = "" if not self.shape else f"shape={self.shape}, "
        return f"KeplerOrbit({head}{', '.join(parts)})"

    # ----------------------------------------------------------------- methods
    def state(self) -> tuple[Any, Any]:
        """The state ``(r, v)``, shapes (..., 3) (Quantities in km, km/s if built from them).

        Examples
        --------
        >>> o = KeplerOrbit.from_state([1.0, 0, 0], [0, 1.0, 0], 1.0)
        >>> [x.tolist() for x in o.state()]
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        """
        return self._out(self._r, _L), self._out(self._v, _V)  # (copies)

    def propagate(self, dt: Any) -> KeplerOrbit:
        """The orbit after time ``dt`` (any sign; broadcast over the leading dims).

        By universal variables, the kernel of ``hamilton_orbits.kepler.propagate``
        on the orbit's state (checked when the orbit was built).

        Parameters
        ----------
        dt : array_like, Quantity (time) or TimeDelta, shape (...)
            A TimeDelta is the Quantity in days it holds.

        Returns
        -------
        KeplerOrbit

        Raises
        ------
        ValueError
            NaN / inf, shapes that do not broadcast, a Quantity ``dt`` for an
            orbit of plain floats or the reverse, an astropy Time (an epoch, not
            a duration).
        ConvergenceError
            As ``hamilton_orbits.kepler.propagate``.

        Examples
        --------
        >>> o = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.1, lan=0.2, argp=0.3,
        ...                               M=0.5, mu=1.0)
        >>> round(float(o.propagate(2.0).M), 12)
        2.5
        """
        refuse_epoch("dt", dt)  # (an astropy Time: an epoch, said so)
        dt = time_quantity(dt)  # (a TimeDelta: the Quantity in days it holds)
        if is_quantity(dt) != self._quantity:
            what = ("it has: give a time Quantity or a TimeDelta" if self._quantity else
                    "it has none: give a plain number, in the orbit's unit of time")
            raise ValueError("Expected `dt` to be a Quantity exactly when the orbit has "
                             f"units ({what}), got {shown(dt)}")
        dt_ = TIME("dt", dt, _T, finite=False)  # a NaN or inf dt: the kernel fails, named below
        shape = self.shape
        try:
            lead = shape if dt_.shape in (shape, ()) else np.broadcast_shapes(shape, dt_.shape)
        except ValueError:
            lead = None
        if lead is not None:
            # a copy of the state, propagated in place (the kernel reads a row before
            # it writes it)
            new = self._state.copy() if lead == shape else np.array(
                np.broadcast_to(self._state, (*lead, 7)), order="C")  # (C order: the
            # rows below a view of it; a broadcast's own order made them a copy, and the
            # orbits came back unpropagated)
            rows = new.reshape(-1, 7)
            r, v = rows[:, :3], rows[:, 3:6]
            if dt_.shape == lead:
                dts = dt_.reshape(-1)
            elif dt_.ndim == 0:  # one dt for every orbit
                dts = np.full(rows.shape[0], dt_)
            else:
                dts = np.broadcast_to(dt_, lead).reshape(-1)
            if rows.shape[0] and _kk.propagate_batch(r, v, rows[:, 6], dts, r, v) < 0:
                return KeplerOrbit(new, self._quantity)
        # dt not finite, shapes that do not broadcast, a state the kernel cannot
        # propagate, or no orbit at all: the public function names the bad value
        # (the same kernel, the same result)
        r, v = _kepler.propagate(self._r, self._v, self._mu, TIME("dt", dt, _T))
        mu = np.broadcast_to(self._mu, r.shape[:-1])[..., None]
        return KeplerOrbit(np.concatenate([r, v, mu], axis=-1), self._quantity)
