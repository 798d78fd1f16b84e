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

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some
dynamical questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l.
"""

from __future__ import annotations

import functools
from functools import cached_property
from typing import Any

import numpy as np

from hamilton_orbits import _columns
from hamilton_orbits import kepler as _kepler
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.conic import Conic
from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.twobody import (
    STATE_UNITS,
    check_state,
    classical_columns,
    refuse_beyond_range,
)
from hamilton_orbits.units import (
    ANGLE,
    DIMENSIONLESS,
    GM,
    LENGTH,
    SPEED,
    TIME,
    is_quantity,
    require_consistent,
    wrap,
)
from hamilton_orbits.validation import (
    ConvergenceError,
    broadcast,
    check_positive,
    check_trailing,
    first_index,
    fmt_index,
)

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
_RAD = "rad"

# the rows of an orbit's element columns: _CI for the CLASSICAL columns (computed
# first, in one pass), _COL for all COLUMNS (u, the anomaly, M too, when asked)
_CI = {name: i for i, name in enumerate(_columns.CLASSICAL)}
_COL = {name: i for i, name in enumerate(_columns.COLUMNS)}
_P, _E, _INV_A, _INC, _LAN, _ARGP, _NU, _A = (
    _CI[n] for n in ("p", "e", "inv_a", "inc", "lan", "argp", "nu", "a")
)
_F64 = np.dtype(np.float64)
_SHAPE3 = (3,)
_ONE_ORBIT_SIZE = _columns.ONE_ORBIT_SIZE


def _raise_at(name: str, mask: np.ndarray, values: np.ndarray, what: str) -> None:
    """Raise ValueError naming ``name``, the first index where ``mask`` and its value."""
    if np.any(mask):
        mask = np.atleast_1d(mask)
        values = np.broadcast_to(np.atleast_1d(values), mask.shape)
        index = first_index(mask)
        shown = index if np.ndim(mask) and mask.size > 1 else ()
        raise ValueError(
            f"Expected `{name}` {what}, got {float(values[index])!r}{fmt_index(shown)}"
        )


def _scalar(a: np.ndarray):
    return a[()] if isinstance(a, np.ndarray) and a.ndim == 0 else a


def _three(x: Any) -> np.ndarray | tuple | None:
    """``x`` if it is a float64 array of shape (3,), as a tuple if it is a list
    or tuple of three Python floats, else None (the general path then takes
    it): one orbit's ``r`` or ``v`` for :func:`hamilton_orbits._kernels.elements.one_orbit`."""
    t = type(x)
    if t is np.ndarray:
        # dtype identity: the native float64 (any other dtype takes the general path)
        return x if x.dtype is _F64 and x.shape == _SHAPE3 else None
    if (t is list or t is tuple) and len(x) == 3:
        a, b, c = x
        if type(a) is float and type(b) is float and type(c) is float:
            return (a, b, c)
    return None


def _in_range(prop):
    """Derived attribute computed without floating-point warnings; a NaN, or an
    infinity where the attribute is not documented to be infinite (``period``
    of an unbound orbit, ``n`` of a radial parabola), means the value is beyond
    the float64 range for this state and raises ValueError naming ``r``, ``v``,
    ``mu``."""
    name = prop.__name__

    @functools.wraps(prop)
    def guarded(self):
        with np.errstate(all="ignore"):
            value = prop(self)
        raw = value.value if is_quantity(value) else np.asarray(value)
        finite = np.isfinite(raw)
        if not finite.all():
            kind = self._kind
            allowed = {
                "period": ~((kind == _el.ELLIPSE) | (kind == _el.RADIAL_ELLIPSE)),
                "n": kind == _el.RADIAL_PARABOLA,
            }.get(name, np.zeros(np.shape(kind), dtype=bool))
            if raw.ndim > np.ndim(kind):
                allowed = allowed[..., None]
            self._refuse_not_finite(name, finite | (np.isinf(raw) & allowed))
        return value

    return guarded


def _element(name: str, unit: str | None, doc: str) -> property:
    """A classical element as a property of :class:`KeplerOrbit`, read from the
    orbit's element columns (computed on first use): a float64 for one orbit,
    an array of the leading shape for many, a Quantity in ``unit`` for an
    orbit built from Quantities.  ``a`` where it alone is beyond float64 (NaN
    in its column) names the state."""
    i = _CI[name]
    is_a = name == "a"

    def read(orbit: KeplerOrbit):
        c = orbit._classical
        if c is None:
            c = orbit._elements()
        if is_a and orbit._a_beyond:
            orbit._refuse_not_finite("a", c[i] == c[i])
        return orbit._out(c[i], unit) if orbit._quantity else c[i]

    read.__name__ = name
    return property(read, doc=doc)


class KeplerOrbit:
    """Two-body (Kepler) orbits, vectorised over leading dimensions.

    Build with :meth:`from_state` or :meth:`from_elements`.  The object keeps
    the state; elements are computed once, in one compiled pass, on first use.

    Attributes (shape = the leading dims; Quantities if built from Quantities)
    ----------
    a : semi-major axis (``inf`` for the parabola, negative for the hyperbola).
    e, p, q : eccentricity, semi-latus rectum (Hamilton's p, eq. 16), periapsis
        distance.
    inc, lan, argp, nu, M, anomaly : inclination, longitude of the ascending
        node, argument of periapsis, true anomaly, mean anomaly and the
        eccentric (e < 1), parabolic ``D = tan(nu/2)`` (e = 1) or hyperbolic
        (e > 1) anomaly.
    n, period, energy : mean motion (parabola: ``sqrt(mu / (2 q^3))``, so that
        ``M = n (t - t_peri)`` with Barker's ``M = D + D^3/3``), period (``inf``
        if unbound), specific orbital energy.
    varpi, argument_of_latitude, true_longitude, mean_longitude : the
        combinations that stay defined when ``e = 0`` or ``inc`` in {0, pi}.
    time_since_periapsis : ``M / n`` (for the radial parabola the time since
        the collision).
    areal_vector : Hamilton's beta = r x v (twice the areal velocity, eq. 3).
    eccentricity_vector : the modern eccentricity vector, towards periapsis.
    hamilton_epsilon : Hamilton's epsilon = -eccentricity_vector, towards
        apoapsis (eq. 13).

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

    # the number of orbits whose a alone is beyond float64 (NaN in its column),
    # set when the classical columns are computed
    _a_beyond = 0

    def __init__(
        self, state: np.ndarray, quantity: bool, classical: np.ndarray | None = None
    ) -> None:
        """Keep a checked state; build orbits with :meth:`from_state` or
        :meth:`from_elements`.

        ``state``: float64 array (..., 7), ``[rx, ry, rz, vx, vy, vz, mu]``
        (:func:`hamilton_orbits.twobody.check_state`), that the orbit keeps and
        never writes to; ``quantity``: whether it was built from Quantities;
        ``classical``: its ``CLASSICAL`` columns, shape (NCLASSICAL, ...), if
        already known."""
        self._state = state
        self._quantity = quantity
        self._classical = classical

    # views of the state
    _r = property(lambda self: self._state[..., :3])
    _v = property(lambda self: self._state[..., 3:6])
    _mu = property(lambda self: self._state[..., 6])

    # ------------------------------------------------------------------ build
    @classmethod
    def from_state(cls, r: Any, v: Any, mu: Any) -> KeplerOrbit:
        """Orbit through the state ``(r, v)`` about a centre of parameter ``mu``.

        Parameters
        ----------
        r : array_like or Quantity (length), shape (..., 3)
            Position relative to the attracting centre (nonzero).
        v : array_like or Quantity (length/time), shape (..., 3)
            Velocity.
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
        :func:`hamilton_orbits.twobody.check_state`; one orbit given as plain
        floats (``r``, ``v`` three floats each, ``mu`` a float) is checked and
        its classical elements computed in one kernel call instead
        (:func:`hamilton_orbits._kernels.elements.one_orbit`, the same rule and
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
            Inclination in [0, pi] (``inc == pi`` is exactly retrograde).
        lan, argp : array_like or Quantity (angle), shape (...)
            Longitude of the ascending node, argument of periapsis.
        nu, M : array_like or Quantity (angle), shape (...); exactly one
            True anomaly (inside the asymptotes for ``e >= 1``) or mean
            anomaly (Kepler's equation by :func:`hamilton_orbits.solve_kepler`).
            A radial orbit takes ``M``.
        mu : array_like or Quantity (length^3/time^2), shape (...)
            Gravitational parameter, ``> 0``.

        Returns
        -------
        KeplerOrbit

        Raises
        ------
        ValueError
            Naming the argument, index and value: ``e < 0``, ``a`` and ``e``
            inconsistent, ``p <= 0``, ``q <= 0``, ``mu <= 0``, ``inc`` outside
            [0, pi], ``nu`` beyond the asymptote, NaN / inf, incompatible
            shapes, not exactly one of a/p/q or nu/M.
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
        lname, length, aname, angle, e_, inc_, lan_, argp_, mu_, quantity = _element_inputs(
            {"a": a, "p": p, "q": q}, {"nu": nu, "M": M}, e, inc, lan, argp, mu
        )
        p_, inv_a, radial = _p_and_inv_a(lname, length, e_)
        anom = _anomaly_of(aname, angle, e_, radial)
        state = _state_of(p_, e_, inv_a, inc_, lan_, argp_, anom, radial, mu_, angle)
        bad = ~np.all(np.isfinite(state[..., :6]), axis=-1)
        _raise_at(lname, bad, length, "to give a finite state (check the elements)")
        return cls(state, quantity)

    # --------------------------------------------------------------- elements
    def _elements(self) -> np.ndarray:
        """The ``CLASSICAL`` columns, shape (NCLASSICAL, ...), computed on first use."""
        c = self._classical
        if c is None:
            c, self._a_beyond = classical_columns(self._state)
            self._classical = c
        return c

    @cached_property
    def _full(self) -> np.ndarray:
        """Every column of ``COLUMNS`` (the anomaly, M and u too), shape
        (NCOL, ...); the classical ones bit for bit those of :meth:`_elements`."""
        rows = self._state.reshape(-1, 7)
        out = np.empty((rows.shape[0], _columns.NCOL))
        _el.state_to_elements(rows[:, :3], rows[:, 3:6], rows[:, 6], out)
        refuse_beyond_range(out, rows, self.shape)
        return out.T.reshape((_columns.NCOL, *self.shape))  # a view

    @cached_property
    def _kind(self) -> np.ndarray:
        """The kind of every orbit (``_columns.kind_of`` of the classical
        columns: the kernel's kind column, without the full kernel)."""
        c = self._elements()
        return _columns.kind_of(c[_P], c[_E], c[_INV_A], c[_NU])

    def _col(self, name: str) -> np.ndarray:
        """The float column of element ``name`` (a ``COLUMNS`` name or ``a``)."""
        i = _CI.get(name)
        if i is not None:
            return self._elements()[i]
        return self._full[_COL[name]]

    def _out(self, value: np.ndarray, unit: str | None):
        """A float result as returned: a float64 for one orbit, an array for
        many, a Quantity in ``unit`` (if not None) for an orbit of Quantities."""
        if not self._quantity:
            return value[()] if type(value) is np.ndarray and value.ndim == 0 else value
        if unit is not None:
            # a 0-d array, not a numpy scalar: Quantity(copy=False) rejects those
            return wrap(np.array(value, dtype=np.float64), unit, True)
        return _scalar(np.asarray(value))

    def _refuse_not_finite(self, name: str, finite: np.ndarray) -> None:
        """Raise, if ``finite`` is not all true, naming ``r``, ``v``, ``mu`` of
        the first orbit where attribute ``name`` is beyond the float64 range."""
        if np.all(finite):
            return
        ndim = len(self.shape)
        i = first_index(np.atleast_1d(~finite))[:ndim] if ndim else ()
        raise ValueError(
            f"Expected `r`, `v`, `mu` for which `{name}` fits in float64, got "
            f"r={self._r[i].tolist()}, v={self._v[i].tolist()}, mu={float(self._mu[i])!r}"
            f"{fmt_index(i)}"
        )

    @property
    def shape(self) -> tuple[int, ...]:
        """Leading shape (number of orbits in each dimension)."""
        return self._state.shape[:-1]

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
        a = np.where(inv == 0, np.inf, 1.0 / np.where(inv == 0, 1.0, inv))
        q = col("p") / (1.0 + col("e"))
        length = "q" if np.all(inv == 0) else "a"
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

    @property
    def mu(self):
        """Gravitational parameter (length^3/time^2)."""
        return self._out(self._mu, _MU)

    e = _element(
        "e", None, "Eccentricity (0 below 4 eps; exactly 1 for parabolic and radial orbits)."
    )
    p = _element("p", _L, "Semi-latus rectum ``p = h^2/mu`` (Hamilton's ``-beta^2/M``, eq. 16).")
    inc = _element("inc", _RAD, "Inclination in [0, pi] (rad).")
    lan = _element(
        "lan", _RAD, "Longitude of the ascending node in [0, 2 pi); 0 when ``inc`` is 0 or pi."
    )
    argp = _element("argp", _RAD, "Argument of periapsis in [0, 2 pi); 0 when ``e = 0``.")
    nu = _element("nu", _RAD, "True anomaly in (-pi, pi] (Hamilton's v, eq. 18).")

    a = _element(
        "a", _L,
        "Semi-major axis ``1/(2/r - v^2/mu)``; ``inf`` for the parabola, < 0 if hyperbolic.",
    )

    @property
    def q(self):
        """Periapsis distance ``p / (1 + e)`` (0 for radial orbits)."""
        return self._out(self._col("p") / (1.0 + self._col("e")), _L)

    @property
    def anomaly(self):
        """Eccentric (e < 1), parabolic D = tan(nu/2) (e = 1) or hyperbolic (e > 1) anomaly.

        Radial orbits: E with ``r = a (1 - cos E)`` or F with ``r = |a| (cosh F - 1)``;
        0 for the radial parabola.
        """
        return self._out(self._col("anomaly"), _RAD)

    @property
    def M(self):
        """Mean anomaly: ``E - e sin E``, ``D + D^3/3`` (Barker) or ``e sinh F - F``."""
        return self._out(self._col("M"), _RAD)

    def _mean_motion(self) -> np.ndarray:
        """n as floats (callers guard the float range)."""
        kind = self._kind
        inv = np.abs(self._col("inv_a"))
        p = self._col("p")
        q = np.where(p > 0, p / (1.0 + self._col("e")), 1.0)
        n = np.where(
            kind == _el.PARABOLA,
            np.sqrt(self._mu / (2.0 * q**3)),
            np.sqrt(self._mu) * inv * np.sqrt(inv),
        )
        return np.where(kind == _el.RADIAL_PARABOLA, np.inf, n)

    @property
    @_in_range
    def n(self):
        """Mean motion ``sqrt(mu/|a|^3)``; parabola ``sqrt(mu / (2 q^3))``; radial parabola inf."""
        return self._out(self._mean_motion(), "rad / s")

    @property
    @_in_range
    def period(self):
        """Orbital period ``2 pi / n`` (inf for unbound orbits)."""
        kind = self._kind
        bound = (kind == _el.ELLIPSE) | (kind == _el.RADIAL_ELLIPSE)
        n = np.where(bound, self._mean_motion(), 1.0)
        return self._out(np.where(bound, 2.0 * np.pi / n, np.inf), _T)

    @property
    @_in_range
    def energy(self):
        """Specific orbital energy ``-mu / (2 a)`` (0 for the parabola)."""
        return self._out(-0.5 * self._mu * self._col("inv_a"), "km2 / s2")

    @cached_property
    def _tau(self) -> np.ndarray:
        rows = self._state.reshape(-1, 7)
        out = np.empty(rows.shape[0])
        _el.state_to_time_since_periapsis(rows[:, :3], rows[:, 3:6], rows[:, 6], out)
        refuse_beyond_range(out[:, None], rows, self.shape)
        return out.reshape(self.shape)

    @property
    def time_since_periapsis(self):
        """Time since periapsis (negative before it); for a radial orbit the time
        since the collision.

        It is ``M / n`` with the *true* mean anomaly of the state: computed with
        1 - e to the accuracy of 1 - e^2 = p/a, so it stays exact to the state's
        rounding for near-parabolic orbits and is continuous across e = 1.  The
        attribute ``M`` instead belongs to the element set as floats (computed
        with the float ``e``, so that ``(p, e, M)`` reproduce the state); the two
        differ by ~eps/|1 - e| relative, visible only near e = 1.
        """
        return self._out(self._tau, _T)

    @property
    def _sign(self) -> np.ndarray:
        return np.where(self._col("inc") <= 0.5 * np.pi, 1.0, -1.0)

    @property
    def varpi(self):
        """Longitude of periapsis ``lan + argp`` (``lan - argp`` for inc > pi/2), [0, 2 pi)."""
        return self._out(_wrap2pi(self._col("lan") + self._sign * self._col("argp")), _RAD)

    @property
    def argument_of_latitude(self):
        """``argp + nu`` in [0, 2 pi), from the position directly (defined when e = 0)."""
        return self._out(self._col("u"), _RAD)

    @property
    def true_longitude(self):
        """``lan + argp + nu`` (``lan - argp - nu`` for inc > pi/2), [0, 2 pi)."""
        return self._out(_wrap2pi(self._col("lan") + self._sign * self._col("u")), _RAD)

    @property
    def mean_longitude(self):
        """``varpi + M`` (``varpi - M`` for inc > pi/2); in [0, 2 pi) for bound orbits."""
        varpi = self._col("lan") + self._sign * self._col("argp")
        ml = varpi + self._sign * self._col("M")
        kind = self._kind
        bound = (kind == _el.ELLIPSE) | (kind == _el.RADIAL_ELLIPSE)
        return self._out(np.where(bound, _wrap2pi(ml), ml), _RAD)

    @property
    @_in_range
    def areal_vector(self):
        """Hamilton's beta = r x v (seed eq. 3), normal to the plane, twice the areal velocity."""
        return self._out(np.cross(self._r, self._v), "km2 / s")

    @property
    @_in_range
    def eccentricity_vector(self):
        """Modern eccentricity vector ``((v^2 - mu/r) r - (r.v) v)/mu``, towards periapsis."""
        return self._out(_ecc_vector(self._r, self._v, self._mu), None)

    @property
    @_in_range
    def hamilton_epsilon(self):
        """Hamilton's epsilon ``iota - v beta / M`` (eq. 13) = -eccentricity_vector, to apoapsis."""
        return self._out(-_ecc_vector(self._r, self._v, self._mu), None)

    # ----------------------------------------------------------------- methods
    def state(self) -> tuple[Any, Any]:
        """The state ``(r, v)``, shapes (..., 3) (Quantities in km, km/s if built from them).

        Examples
        --------
        >>> o = KeplerOrbit.from_state([1.0, 0, 0], [0, 1.0, 0], 1.0)
        >>> [x.tolist() for x in o.state()]
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        """
        return self._out(self._r.copy(), _L), self._out(self._v.copy(), _V)

    def propagate(self, dt: Any) -> KeplerOrbit:
        """The orbit after time ``dt`` (any sign; broadcast over the leading dims).

        By universal variables, the kernel of :func:`hamilton_orbits.kepler.propagate`
        on the orbit's state (checked when the orbit was built).

        Parameters
        ----------
        dt : array_like or Quantity (time), shape (...)

        Returns
        -------
        KeplerOrbit

        Raises
        ------
        ValueError
            NaN / inf, shapes that do not broadcast, a Quantity ``dt`` for an
            orbit of plain floats or the reverse.
        ConvergenceError
            As :func:`hamilton_orbits.kepler.propagate`.

        Examples
        --------
        >>> o = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.1, lan=0.2, argp=0.3,
        ...                               M=0.5, mu=1.0)
        >>> round(float(o.propagate(2.0).M), 12)
        2.5
        """
        if is_quantity(dt) != self._quantity:
            raise ValueError("Expected `dt` to be a Quantity exactly when the orbit has units")
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
                np.broadcast_to(self._state, (*lead, 7)))
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

    @property
    def conic(self) -> Conic:
        """Hamilton's geometry of the orbit, a :class:`hamilton_orbits.conic.Conic`.

        Examples
        --------
        >>> KeplerOrbit.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0).conic
        Conic(p=1.44, e=0.44, inv_a=0.56)
        """
        c = self._elements()
        return Conic.from_elements(
            c[_P], c[_E], c[_INV_A], c[_INC], c[_LAN], c[_ARGP], self._mu, quantity=self._quantity
        )


def _wrap2pi(x: np.ndarray) -> np.ndarray:
    y = np.mod(x, 2.0 * np.pi)
    return np.where(y >= 2.0 * np.pi, 0.0, y)


def _ecc_vector(r: np.ndarray, v: np.ndarray, mu: np.ndarray) -> np.ndarray:
    rn = np.sqrt(np.einsum("...i,...i->...", r, r))[..., None]
    v2 = np.einsum("...i,...i->...", v, v)[..., None]
    rv = np.einsum("...i,...i->...", r, v)[..., None]
    m = mu[..., None]
    return ((v2 - m / rn) * r - rv * v) / m


# ---------------------------------------------------------------------------
# the pieces of KeplerOrbit.from_elements
# ---------------------------------------------------------------------------


def _element_inputs(lengths: dict, anomalies: dict, e, inc, lan, argp, mu):
    """The arguments of :meth:`KeplerOrbit.from_elements` checked and as floats.

    ``lengths`` maps ``a``, ``p``, ``q`` and ``anomalies`` ``nu``, ``M`` to the
    values given (None if not); exactly one of each must be given.  Returns
    ``(lname, length, aname, angle, e, inc, lan, argp, mu, quantity)``: the
    name and value of the length and of the anomaly given, and every value as
    float arrays broadcast together (km and km^3/s^2 if ``quantity``), with
    ``e >= 0``, ``mu > 0`` and ``inc`` in [0, pi] checked."""
    if sum(x is not None for x in lengths.values()) != 1:
        raise ValueError("Expected exactly one of `a`, `p`, `q`")
    if sum(x is not None for x in anomalies.values()) != 1:
        raise ValueError("Expected exactly one of `nu`, `M`")
    lname, lval = next((k, x) for k, x in lengths.items() if x is not None)
    aname, aval = next((k, x) for k, x in anomalies.items() if x is not None)
    quantity = is_quantity(lval) or is_quantity(mu)
    if quantity and not (is_quantity(lval) and is_quantity(mu)):
        raise ValueError(
            f"Expected `{lname}` and `mu` to be both Quantities or both plain floats"
        )
    values = broadcast(
        ("e", "inc", "lan", "argp", "mu", lname, aname),
        DIMENSIONLESS("e", e), ANGLE("inc", inc), ANGLE("lan", lan), ANGLE("argp", argp),
        GM("mu", mu, _MU), LENGTH(lname, lval, _L), ANGLE(aname, aval),
    )
    e_, inc_, lan_, argp_, mu_, length, angle = values
    _raise_at("e", ~(e_ >= 0), e_, ">= 0")
    check_positive("mu", mu_)
    _raise_at("inc", ~((inc_ >= 0) & (inc_ <= np.pi)), inc_, "in [0, pi]")
    return lname, length, aname, angle, e_, inc_, lan_, argp_, mu_, quantity


def _p_and_inv_a(lname: str, length: np.ndarray, e: np.ndarray):
    """``(p, 1/a, radial)`` from ``a``, ``p`` or ``q`` (``lname``) and ``e``;
    ``radial`` where ``e == 1`` with ``a`` given (the rectilinear orbit of that
    energy).  Refuses ``a`` and ``e`` inconsistent, ``p`` or ``q`` <= 0."""
    if lname != "a":
        _raise_at(lname, ~(length > 0), length, "> 0")
        p = length if lname == "p" else length * (1.0 + e)
        return p, (1.0 - e) * (1.0 + e) / p, np.zeros(e.shape, dtype=bool)
    _raise_at("a", length == 0, length, "nonzero")
    _raise_at("a", (length > 0) & (e > 1), length, "< 0 for e > 1 (a and e inconsistent)")
    _raise_at("a", (length < 0) & (e < 1), length, "> 0 for e < 1 (a and e inconsistent)")
    radial = e == 1.0
    p = length * (1.0 - e) * (1.0 + e)
    inv_a = np.where(radial, 1.0 / length, (1.0 - e) * (1.0 + e) / np.where(radial, 1, p))
    return p, inv_a, radial


def _anomaly_of(aname: str, angle: np.ndarray, e: np.ndarray, radial: np.ndarray):
    """The anomaly (E, D or F by ``e``) from ``nu`` or ``M`` (``aname``); NaN
    for a radial orbit (its M is solved by :func:`_radial_from_mean`).
    Refuses ``nu`` for a radial orbit or beyond the asymptote, and a Kepler
    equation not solved (ConvergenceError)."""
    if aname == "nu":
        _raise_at(
            "nu", radial, angle, "to be replaced by `M` for a radial orbit (e == 1, a given)"
        )
        anom = np.asarray(_kk.anomaly_from_nu_ufunc(angle, e))
        _raise_at("nu", ~np.isfinite(anom), angle, "inside the asymptotes (1 + e cos nu > 0)")
        return anom
    with np.errstate(invalid="ignore"):
        anom = np.asarray(_kk.solve_ufunc(angle, np.where(radial, 0.0, e)))
    bad = ~np.isfinite(anom) & ~radial
    if np.any(bad):
        index = first_index(np.atleast_1d(bad))
        raise ConvergenceError(
            f"Kepler's equation not solved for `M` = "
            f"{float(np.atleast_1d(angle)[index])!r}{fmt_index(index if bad.ndim else ())}"
        )
    return anom


def _state_of(p, e, inv_a, inc, lan, argp, anom, radial, mu, m):
    """The state (..., 7) of the elements (one compiled pass; radial orbits
    from their mean anomaly ``m``)."""
    shape = e.shape
    el = np.stack(
        [p * 1.0, e * 1.0, inv_a * 1.0, inc, lan, argp, np.where(radial, 0.0, anom)],
        axis=-1,
    ).reshape(-1, 7)
    flat_mu = np.ascontiguousarray(mu.reshape(-1), dtype=np.float64)
    state = np.empty((*shape, 7))
    rows = state.reshape(-1, 7)
    rows[:, 6] = flat_mu
    r_out, v_out = rows[:, :3], rows[:, 3:6]
    el[:, 0] = np.where(radial.reshape(-1), 0.0, el[:, 0])
    _el.elements_to_state(np.ascontiguousarray(el), flat_mu, r_out, v_out)
    if np.any(radial):
        _radial_from_mean(el, flat_mu, m.reshape(-1), radial.reshape(-1), r_out, v_out)
    return state


def _radial_from_mean(el, mu, m, radial, r_out, v_out) -> None:
    """States of radial orbits from their mean anomaly (in place).

    Kepler's equation of the rectilinear orbit (e = 1, a finite),
    ``E - sin E = M`` or ``sinh F - F = M``, is solved directly
    (:func:`hamilton_orbits._kernels.kepler.solve_radial`), and the state is
    ``r = a (1 - cos E) = 2 a sin^2(E/2)`` (``|a| (cosh F - 1)``) on the line, so
    that a tiny M keeps full relative precision (E ~ (6 M)^(1/3)).
    """
    idx = np.flatnonzero(radial)
    mm = m[idx]
    rows = np.ascontiguousarray(el[idx])
    bound = rows[:, 2] > 0
    _raise_at("M", bound & ~((mm > -np.pi) & (mm <= np.pi)), mm, "in (-pi, pi] for a radial orbit")
    rows[:, 0] = 0.0
    rows[:, 6] = _kk.solve_radial_ufunc(mm, rows[:, 2])
    r1 = np.empty((idx.size, 3))
    v1 = np.empty((idx.size, 3))
    _el.elements_to_state(rows, np.ascontiguousarray(mu[idx]), r1, v1)
    r_out[idx] = r1
    v_out[idx] = v1


# ---------------------------------------------------------------------------
# Hamilton's integrals as quaternion products
# ---------------------------------------------------------------------------


def _hamilton_args(r: Any, v: Any, *mu: Any):
    """(r, v, mu) of Hamilton's integrals as floats (km, km/s, km^3/s^2 for
    Quantities) and whether the call was in Quantities (no mixing)."""
    quantity = require_consistent(("r", "v", "mu")[: 2 + len(mu)], (r, v, *mu))
    r_ = check_trailing("r", LENGTH("r", r, _L), 3)
    v_ = check_trailing("v", SPEED("v", v, _V), 3)
    mu_ = check_positive("mu", GM("mu", mu[0], _MU)) if mu else None
    return r_, v_, mu_, quantity


def _finite_or_raise(f, r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``f(r, v)`` without floating-point warnings; a result beyond float64
    raises ValueError naming ``r`` and ``v``."""
    with np.errstate(all="ignore"):
        try:
            out = np.asarray(f(r, v))
        except ValueError:  # a quaternion product beyond float64 inside f
            out = np.asarray(np.inf)
    if not np.all(np.isfinite(out)):
        raise ValueError(
            f"Expected `r`, `v` (and `mu`) for which Hamilton's {f.__name__.split('_')[0]} "
            f"fits in float64, got r={r.tolist()}, v={v.tolist()}"
        )
    return out


def _beta(r: np.ndarray, v: np.ndarray) -> np.ndarray:
    alpha = Quaternion.from_vector(r)
    dalpha = Quaternion.from_vector(v)
    return ((alpha * dalpha - dalpha * alpha) * 0.5).vector


def hamilton_beta(r: Any, v: Any):
    """Hamilton's areal vector ``beta = (alpha alpha' - alpha' alpha) / 2`` (seed eq. 3).

    Computed from two Hamilton products of the pure quaternions ``alpha = r``
    and ``alpha' = v``; equals ``r x v``.

    Parameters
    ----------
    r : array_like or Quantity (length), shape (..., 3)
        Position.
    v : array_like or Quantity (length/time), shape (..., 3)
        Velocity (plain floats: the units of ``r`` per unit time).

    Returns
    -------
    ndarray or Quantity (km^2/s), shape (..., 3)
        The vector part of the (pure) quaternion beta.

    Raises
    ------
    ValueError
        NaN / inf, trailing dimension not 3, or a mix of Quantities and floats.
    astropy.units.UnitConversionError
        For a Quantity of the wrong kind, naming the argument.

    Examples
    --------
    >>> hamilton_beta([1.0, 0, 0], [0, 2.0, 0]).tolist()
    [0.0, 0.0, 2.0]
    >>> hamilton_beta([1.0, 0, 0] * u.km, [0, 2.0, 0] * u.km / u.s)
    <Quantity [0., 0., 2.] km2 / s>
    """
    r_, v_, _, quantity = _hamilton_args(r, v)
    return wrap(_finite_or_raise(_beta, r_, v_), "km2 / s", quantity)


def hamilton_epsilon_from_products(r: Any, v: Any, mu: Any):
    """Hamilton's ``epsilon = iota - alpha' beta / M`` (seed eq. 13), by quaternion products.

    ``iota = alpha / r`` is the unit vector of the position; in Hamilton's
    algebra ``alpha' beta = -alpha'.beta + alpha' x beta = v x beta`` (as v is
    perpendicular to beta), so ``epsilon = r/|r| - v x (r x v)/mu``, the
    negative of the modern eccentricity vector: it points to the apoapsis.

    Parameters
    ----------
    r : array_like or Quantity (length), shape (..., 3)
        Position, nonzero.
    v : array_like or Quantity (length/time), shape (..., 3)
        Velocity.
    mu : array_like or Quantity (length^3/time^2), shape (...)
        Hamilton's M, ``> 0``.

    Returns
    -------
    ndarray or dimensionless Quantity, shape (..., 3)

    Raises
    ------
    ValueError
        NaN / inf, wrong shapes, ``mu <= 0``, ``r = 0``, or mixed Quantities and floats.
    astropy.units.UnitConversionError
        For a Quantity of the wrong kind, naming the argument.

    Examples
    --------
    >>> hamilton_epsilon_from_products([1.0, 0, 0], [0, 1.2, 0], 1.0).round(12).tolist()
    [-0.44, 0.0, 0.0]
    """
    r_, v_, mu_, quantity = _hamilton_args(r, v, mu)
    big = np.max(np.abs(r_), axis=-1)  # |r| without underflow of |r|^2 (r ~ 1e-170)
    _raise_at("r", ~(big > 0), big, "nonzero (|r| > 0)")
    with np.errstate(over="ignore", under="ignore"):
        rn = np.sqrt(np.einsum("...i,...i->...", r_, r_))
    tiny_or_huge = ~((big > 1e-150) & (big < 1e150))
    if np.any(tiny_or_huge):
        rs = r_ / big[..., None]
        rn = np.where(tiny_or_huge, big * np.sqrt(np.einsum("...i,...i->...", rs, rs)), rn)
    def eps_of(r_, v_):
        iota = Quaternion.from_vector(r_ / rn[..., None])
        dalpha = Quaternion.from_vector(v_)
        beta = Quaternion.from_vector(_beta(r_, v_))
        return (iota - (dalpha * beta) * (1.0 / mu_)).vector

    return wrap(_finite_or_raise(eps_of, r_, v_), "", quantity)


def hamilton_p(r: Any, v: Any, mu: Any):
    """Hamilton's semi-parameter ``p = -beta^2 / M`` (seed eq. 16), ``beta^2`` a quaternion square.

    Parameters
    ----------
    r : array_like or Quantity (length), shape (..., 3)
    v : array_like or Quantity (length/time), shape (..., 3)
    mu : array_like or Quantity (length^3/time^2), shape (...), ``> 0``

    Returns
    -------
    ndarray or Quantity (km), shape (...)

    Examples
    --------
    >>> float(hamilton_p([1.0, 0, 0], [0, 1.2, 0], 1.0).round(12))
    1.44
    """
    r_, v_, mu_, quantity = _hamilton_args(r, v, mu)

    def p_of(r_, v_):
        beta = Quaternion.from_vector(_beta(r_, v_))
        return -(beta * beta).scalar / mu_

    return wrap(_finite_or_raise(p_of, r_, v_), _L, quantity)
