"""What the state of a :class:`~hamilton_orbits.orbit.KeplerOrbit` gives: its elements,
the quantities derived from them, and its conic.

:class:`OrbitElements` is the part of ``KeplerOrbit`` that reads the orbit's state
``_state`` (a float64 array (..., 7), ``[rx, ry, rz, vx, vy, vz, mu]``), whether it
was built from Quantities (``_quantity``) and its classical columns once known
(``_classical``): the elements are computed in compiled passes
(``hamilton_orbits._kernels.elements``) the first time one is asked for, and
every attribute is returned in one way for one orbit and for many.  Conventions:
``docs/elements.md``.
"""

from __future__ import annotations

import functools
from functools import cached_property

import numpy as np

from hamilton_orbits import _columns
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.conic import Conic
from hamilton_orbits.twobody import STATE_UNITS, classical_columns, refuse_beyond_range
from hamilton_orbits.units import is_quantity, wrap
from hamilton_orbits.validation import first_index, fmt_index

# numba is imported on first use (hamilton_orbits._lazy)
_el = LazyModule("hamilton_orbits._kernels.elements", globals(), "_el")

__all__ = ["OrbitElements"]

# internal units when Quantities come in
_L, _V, _MU = STATE_UNITS
_T = "s"
_RAD = "rad"

# the rows of an orbit's element columns: _CI for the CLASSICAL columns (computed
# first, in one pass), _COL for all COLUMNS (u, the anomaly, M too, when asked)
_CI = {name: i for i, name in enumerate(_columns.CLASSICAL)}
_COL = {name: i for i, name in enumerate(_columns.COLUMNS)}
_TAU = _COL["tau"]  # (the last column)
_P, _E, _INV_A, _INC, _LAN, _ARGP, _NU, _A = (
    _CI[n] for n in ("p", "e", "inv_a", "inc", "lan", "argp", "nu", "a")
)


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
    """A classical element as a property of :class:`~hamilton_orbits.orbit.KeplerOrbit`,
    read from the orbit's element columns (computed on first use): a float64 for one orbit,
    an array of the leading shape for many, a Quantity in ``unit`` for an
    orbit built from Quantities.  ``a`` where it alone is beyond float64 (NaN
    in its column) names the state."""
    i = _CI[name]
    is_a = name == "a"

    def read(orbit: OrbitElements):
        c = orbit._classical
        if c is None:
            c = orbit._elements()
        if is_a and orbit._a_beyond:
            orbit._refuse_not_finite("a", c[i] == c[i])
        return orbit._out(c[i], unit)

    read.__name__ = name
    return property(read, doc=doc)


class OrbitElements:
    """The elements of an orbit's state and what derives from them (the attributes
    of :class:`~hamilton_orbits.orbit.KeplerOrbit`, which inherits them)."""

    # the number of orbits whose a alone is beyond float64 (NaN in its column),
    # set when the classical columns are computed
    _a_beyond = 0

    # views of the state
    _r = property(lambda self: self._state[..., :3])
    _v = property(lambda self: self._state[..., 3:6])
    _mu = property(lambda self: self._state[..., 6])

    @property
    def shape(self) -> tuple[int, ...]:
        """Leading shape (number of orbits in each dimension)."""
        return self._state.shape[:-1]

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
        _el.state_to_elements(*_el.row_columns(rows), out)
        # every column but tau, the last (read from :attr:`_tau`, which refuses it by
        # name): a tau beyond float64 (a = 1e250) blocked the angles, M and u
        refuse_beyond_range(out[:, :_TAU], rows, self.shape)
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
        """A float result as returned: a float64 for one orbit, an array of its own
        for many (a copy: the orbit's columns and state are never handed out, so
        that in-place arithmetic on an attribute cannot change the orbit), a
        Quantity in ``unit`` (if not None) for an orbit of Quantities."""
        value = np.asarray(value)
        if value.ndim == 0 and (not self._quantity or unit is None):
            return value[()]
        out = np.array(value, dtype=np.float64)  # (a copy; 0-d for a Quantity, which
        # Quantity(copy=False) takes where it rejects a numpy scalar)
        return wrap(out, unit, True) if self._quantity and unit is not None else out

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
            _parabola_mean_motion(q, self._mu),
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
        _el.state_to_time_since_periapsis(*_el.row_columns(rows), out)
        tau = out.reshape(self.shape)
        self._refuse_not_finite("time_since_periapsis", np.isfinite(tau))
        return tau

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
        varpi = _wrap2pi(self._col("lan") + self._sign * self._col("argp"))  # (as
        # longitude_of_periapsis gives it: an open orbit's M is added to it unwrapped)
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

    @property
    def conic(self) -> Conic:
        """Hamilton's geometry of the orbit, a :class:`hamilton_orbits.conic.Conic`.

        Examples
        --------
        >>> from hamilton_orbits import KeplerOrbit
        >>> KeplerOrbit.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0).conic
        Conic(p=1.44, e=0.44, inv_a=0.56)
        """
        c = self._elements()
        return Conic.from_elements(
            c[_P], c[_E], c[_INV_A], c[_INC], c[_LAN], c[_ARGP], self._mu, quantity=self._quantity
        )


def _even_frexp(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(m, k)`` with ``x = m 2**k`` exactly, ``k`` even and ``m`` in [1/2, 2)."""
    m, k = np.frexp(x)
    odd = (k % 2) != 0
    return np.where(odd, 2.0 * m, m), np.where(odd, k - 1, k)


def _parabola_mean_motion(q: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """The parabola's ``n = sqrt(mu / (2 q^3))`` with ``q`` and ``mu`` scaled by even
    powers of two (exact) and the result scaled back once: ``q**3`` over- and
    underflowed from ``q`` ~ 6e102 (n was 0) and below ~1e-103 (n was refused),
    while ``n`` fits.  The roundings are those of the formula (the scalings are
    exact): within 1 ulp of mpmath's n, as before, in the float range."""
    qm, kq = _even_frexp(q)
    mm, km = _even_frexp(mu)
    return np.ldexp(np.sqrt(mm / (2.0 * qm**3)), (km - 3 * kq) // 2)


def _wrap2pi(x: np.ndarray) -> np.ndarray:
    y = np.mod(x, 2.0 * np.pi)
    return np.where(y >= 2.0 * np.pi, 0.0, y)


def _ecc_vector(r: np.ndarray, v: np.ndarray, mu: np.ndarray) -> np.ndarray:
    # |r| by the largest component (r . r overflows from |r| ~ 1e154 and underflows
    # below 1e-154: mu / |r| was then 0, or off, and the vector with it)
    big = np.max(np.abs(r), axis=-1, keepdims=True)
    unit = r / big
    rn = big * np.sqrt(np.einsum("...i,...i->...", unit, unit))[..., None]
    v2 = np.einsum("...i,...i->...", v, v)[..., None]
    rv = np.einsum("...i,...i->...", r, v)[..., None]
    m = mu[..., None]
    return ((v2 - m / rn) * r - rv * v) / m
