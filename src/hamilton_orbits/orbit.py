"""Two-body orbits: state vectors <-> orbital elements for every conic.

:class:`KeplerOrbit` stores the state ``(r, v, mu)`` as plain floats and derives
all elements in one compiled pass (``hamilton_orbits._kernels.elements``), the
first time one is asked for.  Hamilton's integrals are also available exactly
as the seed writes them, as quaternion products: :func:`hamilton_beta`
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
import math
from functools import cached_property
from typing import Any

import numpy as np

from hamilton_orbits import _columns
from hamilton_orbits import kepler as _kepler
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits._validation import (
    ConvergenceError,
    broadcast,
    check_positive,
    check_trailing,
    first_index,
    fmt_index,
)
from hamilton_orbits.quaternion import Quaternion
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
_L = "km"
_T = "s"
_V = "km / s"
_MU = "km3 / s2"
_RAD = "rad"

# _elements: the CLASSICAL columns (p, e, inv_a, inc, lan, argp, nu, a);
# _full: all COLUMNS (u, the anomaly, M and tau too), computed when one is asked
# for; _kind: the kind column derived from the classical ones (_columns.kind_of)
_CI = {name: i for i, name in enumerate(_columns.CLASSICAL)}
_COL = {name: i for i, name in enumerate(_columns.COLUMNS)}
_F64 = np.dtype(np.float64)
_SHAPE3 = (3,)
_TWO_PI = 2.0 * math.pi
_f64 = np.float64  # one orbit's elements are read as float64 scalars
_A1 = _CI["a"]  # the last column


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


def _check_state(r_in: Any, v_in: Any, mu_in: Any):
    """Validate (r, v, mu); return float arrays broadcast to a common shape."""
    q = [is_quantity(x) for x in (r_in, v_in, mu_in)]
    if any(q) and not all(q):
        raise ValueError(
            "Expected `r`, `v`, `mu` to be all Quantities or all plain floats, got a mix"
        )
    quantity = all(q)
    r = check_trailing("r", LENGTH("r", r_in, _L), 3)
    v = check_trailing("v", SPEED("v", v_in, _V), 3)
    mu = GM("mu", mu_in, _MU)
    check_positive("mu", mu)
    lead = broadcast(("r", "v", "mu"), r[..., 0], v[..., 0], mu)[0].shape
    r = np.broadcast_to(r, (*lead, 3))
    v = np.broadcast_to(v, (*lead, 3))
    mu = np.broadcast_to(mu, lead)
    bad = ~np.any(r != 0, axis=-1)  # not |r| > 0: |r|^2 underflows at 1e-170
    if np.any(bad):
        index = first_index(np.atleast_1d(bad)) if bad.ndim else ()
        raise ValueError(f"Expected `r` to be nonzero, got {r[index].tolist()}{fmt_index(index)}")
    return r, v, mu, quantity


def _plain_float_array(x: Any) -> np.ndarray | None:
    """``x`` as a float64 ndarray if it is a plain real ndarray, list or tuple
    (no Quantity, complex, bool, object or ragged input), else None."""
    t = type(x)
    if t is np.ndarray:
        if x.dtype == np.float64:
            return x
    elif t is list or t is tuple:
        try:
            x = np.asarray(x)
        except (ValueError, TypeError, OverflowError):
            return None
    else:
        return None
    return x.astype(np.float64) if x.dtype.kind in "fiu" else None


def _three(x: Any) -> list | tuple | None:
    """``x`` as three Python floats if it is a float64 array of shape (3,) or a
    list/tuple of three Python floats, else None."""
    t = type(x)
    if t is np.ndarray:
        # dtype identity: the native float64 (any other dtype takes the general path)
        if x.dtype is _F64 and x.shape == _SHAPE3:
            return x.tolist()
        return None
    if (t is list or t is tuple) and len(x) == 3:
        a, b, c = x
        if type(a) is float and type(b) is float and type(c) is float:
            return x
    return None


def _one_state(r: Any, v: Any, mu: Any) -> tuple[float, ...] | None:
    """One orbit in plain floats (``r``, ``v`` lists/tuples of three floats or
    float64 arrays of shape (3,), ``mu`` a float) as 7 floats, if finite with
    ``mu > 0`` and ``r != 0``; else None (the general path then decides)."""
    if type(mu) is not float:
        return None
    r = _three(r)
    v = _three(v)
    if r is None or v is None:
        return None
    rx, ry, rz = r
    vx, vy, vz = v
    s = rx + ry + rz + vx + vy + vz + mu  # inf or NaN if any is (or on overflow: then
    if s - s != 0.0 or not mu > 0.0 or not (rx or ry or rz):  # the general path decides)
        return None
    return rx, ry, rz, vx, vy, vz, mu


def _check_copy_state_fast(r_in: Any, v_in: Any, mu_in: Any):
    """The common case of :func:`_check_state` plus the copies ``KeplerOrbit``
    keeps, in one compiled pass: ``r`` and ``v`` float64 arrays of one shape
    ``(..., 3)`` and ``mu`` a number or a float64 array of the leading shape.
    Returns ``(r, v, mu)`` (fresh C-contiguous arrays, as ``__init__`` makes),
    or None when the input is of another kind or invalid; the caller then takes
    the general path, which names the first bad argument and index."""
    r_in = _plain_float_array(r_in)
    v_in = _plain_float_array(v_in)
    if r_in is None or v_in is None:
        return None
    shape = r_in.shape
    if v_in.shape != shape or len(shape) == 0 or shape[-1] != 3:
        return None
    lead = shape[:-1]
    if isinstance(mu_in, (float, int)) and not isinstance(mu_in, bool):
        try:
            mu_flat = np.full(1, float(mu_in))
        except OverflowError:
            return None
    elif (
        type(mu_in) is np.ndarray and mu_in.dtype == np.float64
        and (mu_in.shape == lead or mu_in.shape == ())
    ):
        mu_flat = mu_in.reshape(-1)
    else:
        return None
    n = r_in.size // 3
    r_out = np.empty(shape)
    v_out = np.empty(shape)
    mu_out = np.empty(lead)
    if n == 0:
        return r_out, v_out, mu_out
    bad = _el.check_copy_state(
        r_in.reshape(-1, 3), v_in.reshape(-1, 3), mu_flat,
        r_out.reshape(-1, 3), v_out.reshape(-1, 3), mu_out.reshape(-1),
    )
    return None if bad else (r_out, v_out, mu_out)


def _in_range(prop):
    """Derived attribute computed without floating-point warnings; a NaN, or an
    infinity where the attribute is not documented to be infinite (``a`` of a
    parabola, ``period`` of an unbound orbit, ``n`` of a radial parabola), means
    the value is beyond the float64 range for this state and raises ValueError
    naming ``r``, ``v``, ``mu``."""
    name = prop.__name__.removeprefix("_").removesuffix("_general")  # _a_general: a

    @functools.wraps(prop)
    def guarded(self):
        with np.errstate(all="ignore"):
            value = prop(self)
        raw = value.value if is_quantity(value) else np.asarray(value)
        finite = np.isfinite(raw)
        if not np.all(finite):
            kind = self._col("kind")
            allowed = {
                "a": (kind == _el.PARABOLA) | (kind == _el.RADIAL_PARABOLA),
                "period": ~((kind == _el.ELLIPSE) | (kind == _el.RADIAL_ELLIPSE)),
                "n": kind == _el.RADIAL_PARABOLA,
            }.get(name, np.zeros(kind.shape, dtype=bool))
            if raw.ndim > kind.ndim:
                allowed = allowed[..., None]
            bad = ~finite & ~(np.isinf(raw) & allowed)
            if np.any(bad):
                i = first_index(np.atleast_1d(bad))[: kind.ndim] if kind.ndim else ()
                r, v = self._r[i], self._v[i]
                raise ValueError(
                    f"Expected `r`, `v`, `mu` for which `{name}` fits in float64, got "
                    f"r={r.tolist()}, v={v.tolist()}, mu={float(self._mu[i])!r}"
                    f"{fmt_index(i)}"
                )
        return value

    return guarded


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

    Examples
    --------
    >>> o = KeplerOrbit.from_state([1.0, 0.0, 0.0], [0.0, 1.2, 0.0], 1.0)
    >>> round(float(o.e), 12), round(float(o.a), 12), round(float(o.p), 12)
    (0.44, 1.785714285714, 1.44)
    >>> [round(float(x), 12) + 0.0 for x in o.hamilton_epsilon]
    [-0.44, 0.0, 0.0]
    """


    # one orbit built from plain floats: its 7 floats (r, v, mu), else None; the
    # arrays _r, _v, _mu (instance attributes otherwise) are then made on demand
    _one: tuple[float, ...] | None = None
    _r = cached_property(lambda self: np.array(self._one[:3]))
    _v = cached_property(lambda self: np.array(self._one[3:6]))
    _mu = cached_property(lambda self: np.array(self._one[6]))
    # one orbit from plain floats, once its elements are asked for: the tuple of
    # _el.classical_one (the CLASSICAL columns), so that reading an element is
    # an index into it (as a float64 scalar, like the general path's)
    _c1: tuple[float, ...] | None = None

    def _one_classical(self) -> np.ndarray | None:
        """The row ``_c1`` of a single orbit built from plain floats (computed
        once, in one kernel call that flags any value beyond float64), or None
        for a batch, a Quantity orbit or a flagged state (the general path then
        computes the attribute or names the arguments)."""
        one = self._one
        if one is None:
            return None
        c = _el.classical_one(*one)
        if c[_A1] != c[_A1]:  # NaN: beyond float64
            return None
        self._c1 = c
        return c

    def __init__(self, r: np.ndarray, v: np.ndarray, mu: np.ndarray, quantity: bool) -> None:
        # np.array, not ascontiguousarray (which turns 0-d into 1-d)
        self._r = np.array(r, dtype=np.float64, order="C")
        self._v = np.array(v, dtype=np.float64, order="C")
        self._mu = np.array(mu, dtype=np.float64, order="C")
        self._quantity = quantity

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
        of two inside the kernels, which is exact).

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
        one = _one_state(r, v, mu)
        if one is not None:
            obj = object.__new__(cls)
            obj._quantity = False
            obj._one = one  # _r, _v, _mu are made from it when first needed
            return obj
        fast = _check_copy_state_fast(r, v, mu)
        if fast is not None:
            obj = cls.__new__(cls)
            obj._r, obj._v, obj._mu = fast
            obj._quantity = False
            return obj
        r_, v_, mu_, quantity = _check_state(r, v, mu)
        return cls(r_, v_, mu_, quantity)

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
        sizes = [x is not None for x in (a, p, q)]
        if sum(sizes) != 1:
            raise ValueError("Expected exactly one of `a`, `p`, `q`")
        if (nu is None) == (M is None):
            raise ValueError("Expected exactly one of `nu`, `M`")
        given = {"a": a, "p": p, "q": q}
        lname = next(k for k, x in given.items() if x is not None)
        lval = given[lname]
        aname = "nu" if nu is not None else "M"
        aval = nu if nu is not None else M
        inputs = {"e": e, "inc": inc, "lan": lan, "argp": argp, "mu": mu, lname: lval, aname: aval}
        qs = {k: is_quantity(x) for k, x in inputs.items()}
        quantity = qs[lname] or qs["mu"]
        if quantity and not (qs[lname] and qs["mu"]):
            raise ValueError(
                f"Expected `{lname}` and `mu` to be both Quantities or both plain floats"
            )
        e_ = DIMENSIONLESS("e", e)
        inc_ = ANGLE("inc", inc)
        lan_ = ANGLE("lan", lan)
        argp_ = ANGLE("argp", argp)
        mu_ = GM("mu", mu, _MU)
        len_ = LENGTH(lname, lval, _L)
        ang_ = ANGLE(aname, aval)
        e_, inc_, lan_, argp_, mu_, len_, ang_ = broadcast(
            ("e", "inc", "lan", "argp", "mu", lname, aname),
            e_, inc_, lan_, argp_, mu_, len_, ang_,
        )
        shape = e_.shape
        _raise_at("e", ~(e_ >= 0), e_, ">= 0")
        check_positive("mu", mu_)
        _raise_at("inc", ~((inc_ >= 0) & (inc_ <= np.pi)), inc_, "in [0, pi]")
        radial = np.zeros(shape, dtype=bool)
        inv_a = np.zeros(shape)
        if lname == "a":
            _raise_at("a", len_ == 0, len_, "nonzero")
            _raise_at("a", (len_ > 0) & (e_ > 1), len_, "< 0 for e > 1 (a and e inconsistent)")
            _raise_at("a", (len_ < 0) & (e_ < 1), len_, "> 0 for e < 1 (a and e inconsistent)")
            radial = e_ == 1.0
            p_ = len_ * (1.0 - e_) * (1.0 + e_)
            inv_a = np.where(radial, 1.0 / len_, (1.0 - e_) * (1.0 + e_) / np.where(radial, 1, p_))
        else:
            _raise_at(lname, ~(len_ > 0), len_, "> 0")
            p_ = len_ if lname == "p" else len_ * (1.0 + e_)
            inv_a = (1.0 - e_) * (1.0 + e_) / p_
        if aname == "nu":
            _raise_at(
                "nu", radial, ang_, "to be replaced by `M` for a radial orbit (e == 1, a given)"
            )
            anom = np.asarray(_kk.anomaly_from_nu_ufunc(ang_, e_))
            _raise_at("nu", ~np.isfinite(anom), ang_, "inside the asymptotes (1 + e cos nu > 0)")
        else:
            with np.errstate(invalid="ignore"):
                anom = np.asarray(_kk.solve_ufunc(ang_, np.where(radial, 0.0, e_)))
            bad = ~np.isfinite(anom) & ~radial
            if np.any(bad):
                index = first_index(np.atleast_1d(bad))
                raise ConvergenceError(
                    f"Kepler's equation not solved for `M` = "
                    f"{float(np.atleast_1d(ang_)[index])!r}{fmt_index(index if bad.ndim else ())}"
                )
        el = np.stack(
            [p_ * 1.0, e_ * 1.0, inv_a * 1.0, inc_, lan_, argp_, np.where(radial, 0.0, anom)],
            axis=-1,
        ).reshape(-1, 7)
        flat_mu = np.ascontiguousarray(mu_.reshape(-1), dtype=np.float64)
        r_out = np.empty((el.shape[0], 3))
        v_out = np.empty((el.shape[0], 3))
        el[:, 0] = np.where(radial.reshape(-1), 0.0, el[:, 0])
        _el.elements_to_state(np.ascontiguousarray(el), flat_mu, r_out, v_out)
        if np.any(radial):
            _radial_from_mean(el, flat_mu, ang_.reshape(-1), radial.reshape(-1), r_out, v_out)
        r_out = r_out.reshape((*shape, 3))
        v_out = v_out.reshape((*shape, 3))
        bad = ~np.all(np.isfinite(r_out) & np.isfinite(v_out), axis=-1)
        _raise_at(lname, bad, len_, "to give a finite state (check the elements)")
        return cls(r_out, v_out, mu_, quantity)

    # --------------------------------------------------------------- elements
    @cached_property
    def _elements(self) -> np.ndarray:
        # the CLASSICAL columns (_el.classical_one), shape (..., NCLASSICAL)
        one = self._one
        if one is not None:  # one orbit from plain floats: no arrays for the kernel
            row = np.array(self._c1 or _el.classical_one(*one))
            if not math.isfinite(row[:_A1].sum()):
                _refuse_beyond_range(row[None, :_A1], np.array([one[:3]]),
                                     np.array([one[3:6]]), np.array([one[6]]), ())
            return row
        flat_r = self._r.reshape(-1, 3)
        flat_v = self._v.reshape(-1, 3)
        flat_mu = self._mu.reshape(-1)
        out = np.empty((flat_r.shape[0], _columns.NCLASSICAL))
        bad = _el.state_to_elements_classical(flat_r, flat_v, flat_mu, out)
        if bad:  # a NaN a: a row beyond float64 is refused here, naming the first;
            # else a is beyond float64 somewhere, refused when it is read (a)
            _refuse_beyond_range(out[:, :_A1], flat_r, flat_v, flat_mu, self._mu.shape)
        self.__dict__["_a_bad"] = bad
        return out.reshape((*self._mu.shape, _columns.NCLASSICAL))

    @cached_property
    def _full(self) -> np.ndarray:
        # every column of COLUMNS (the classical ones bit for bit as in _elements)
        one = self._one
        if one is not None:
            out = np.array(_el.state_to_elements_row(*one, True))[None]
        else:
            out = np.empty((self._mu.size, _columns.NCOL))
            _el.state_to_elements(
                self._r.reshape(-1, 3), self._v.reshape(-1, 3), self._mu.reshape(-1), out
            )
        _refuse_beyond_range(out, self._r.reshape(-1, 3), self._v.reshape(-1, 3),
                             self._mu.reshape(-1), self._mu.shape)
        return out.reshape((*self._mu.shape, _columns.NCOL))

    @cached_property
    def _kind(self) -> np.ndarray:
        # _columns.kind_of on every orbit (the kind column of _full, bit for bit)
        p, e, inv_a, nu = (self._col(n) for n in ("p", "e", "inv_a", "nu"))
        radial = np.where(
            inv_a > 0.0, _el.RADIAL_ELLIPSE, np.where(inv_a < 0.0, _el.RADIAL_HYPERBOLA, np.where(
                (p == 0.0) & (nu == math.pi), _el.RADIAL_PARABOLA, _el.PARABOLA)))
        return np.where(e < 1.0, _el.ELLIPSE, np.where(e > 1.0, _el.HYPERBOLA, radial))

    def _col(self, name: str) -> np.ndarray:
        if name == "kind":
            kind = self.__dict__.get("_kind")
            if kind is None:
                kind = self.__dict__["_kind"] = KeplerOrbit._kind.func(self)
            return kind
        i = _CI.get(name)
        if i is not None:
            el = self.__dict__.get("_elements")
            if el is None:  # as self._elements, without cached_property's lock (3.11)
                el = self.__dict__["_elements"] = KeplerOrbit._elements.func(self)
            return el[i] if el.ndim == 1 else el[..., i]
        full = self.__dict__.get("_full")
        if full is None:
            full = self.__dict__["_full"] = KeplerOrbit._full.func(self)
        i = _COL[name]
        return full[i] if full.ndim == 1 else full[..., i]

    def _out(self, value: np.ndarray, unit: u.UnitBase | None):
        if not self._quantity:
            if type(value) is np.float64:
                return value
            return value[()] if value.ndim == 0 else value
        if unit is not None:
            # a 0-d array, not a numpy scalar: Quantity(copy=False) rejects those
            return wrap(np.array(value, dtype=np.float64), unit, True)
        return _scalar(np.asarray(value))

    @property
    def shape(self) -> tuple[int, ...]:
        """Leading shape (number of orbits in each dimension)."""
        return self._mu.shape

    def __len__(self) -> int:
        if not self.shape:
            raise TypeError("len() of a single KeplerOrbit")
        return self.shape[0]

    def __getitem__(self, key: Any) -> KeplerOrbit:
        if not self.shape:
            raise IndexError("a single KeplerOrbit cannot be indexed")
        return KeplerOrbit(self._r[key], self._v[key], self._mu[key], self._quantity)

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

    @property
    def e(self):
        """Eccentricity (0 below 4 eps; exactly 1 for parabolic and radial orbits)."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[1])
        return self._out(self._col("e"), None)

    @property
    def p(self):
        """Semi-latus rectum ``p = h^2/mu`` (Hamilton's ``-beta^2/M``, eq. 16)."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[0])
        return self._out(self._col("p"), _L)

    @property
    def _inv_a(self) -> np.ndarray:
        return self._col("inv_a")

    @property
    def a(self):
        """Semi-major axis ``1/(2/r - v^2/mu)``; ``inf`` for the parabola, < 0 if hyperbolic."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[_A1])
        a = self._col("a")
        if self.__dict__.get("_a_bad") == 0:  # the kernel's a is finite (or a parabola's inf)
            return self._out(a, _L)
        return self._a_general

    @property
    @_in_range
    def _a_general(self):
        with np.errstate(divide="ignore"):  # inv_a is +0.0 exactly for the parabola: a = +inf
            return self._out(1.0 / self._inv_a, _L)

    @property
    def q(self):
        """Periapsis distance ``p / (1 + e)`` (0 for radial orbits)."""
        return self._out(self._col("p") / (1.0 + self._col("e")), _L)

    @property
    def inc(self):
        """Inclination in [0, pi] (rad)."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[3])
        return self._out(self._col("inc"), _RAD)

    @property
    def lan(self):
        """Longitude of the ascending node in [0, 2 pi); 0 when ``inc`` is 0 or pi."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[4])
        return self._out(self._col("lan"), _RAD)

    @property
    def argp(self):
        """Argument of periapsis in [0, 2 pi); 0 when ``e = 0``."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[5])
        return self._out(self._col("argp"), _RAD)

    @property
    def nu(self):
        """True anomaly in (-pi, pi] (Hamilton's v, eq. 18)."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            return _f64(c[6])
        return self._out(self._col("nu"), _RAD)

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

    @property
    def _n(self) -> np.ndarray:
        kind = self._col("kind")
        inv = np.abs(self._inv_a)
        p = self._col("p")
        e = self._col("e")
        q = np.where(p > 0, p / (1.0 + e), 1.0)
        n = np.where(
            kind == _el.PARABOLA,
            np.sqrt(self._mu / (2.0 * q**3)),
            np.sqrt(self._mu) * inv * np.sqrt(inv),
        )
        return np.where(kind == _el.RADIAL_PARABOLA, np.inf, n)

    def _n_one(self) -> float | None:
        """Mean motion of one orbit from plain floats, in Python floats (the
        formula of ``_n``, bit for bit); None for a batch, a parabola or a value
        beyond float64 (the general path then answers or names the state)."""
        c = self._c1
        if c is None and (c := self._one_classical()) is None:
            return None
        kind = _columns.kind_of(c[0], c[1], c[2], c[6])
        if kind == _columns.PARABOLA or kind == _columns.RADIAL_PARABOLA:
            return None
        inv = abs(c[2])
        n = math.sqrt(self._one[6]) * inv * math.sqrt(inv)
        return n if 0.0 < n < math.inf else None

    @property
    def n(self):
        """Mean motion ``sqrt(mu/|a|^3)``; parabola ``sqrt(mu / (2 q^3))``; radial parabola inf."""
        n = self._n_one()
        return self._n_general if n is None else _f64(n)

    @property
    @_in_range
    def _n_general(self):
        return self._out(self._n, "rad / s")

    @property
    def period(self):
        """Orbital period ``2 pi / n`` (inf for unbound orbits)."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            kind = _columns.kind_of(c[0], c[1], c[2], c[6])
            if kind != _columns.ELLIPSE and kind != _columns.RADIAL_ELLIPSE:
                return _f64(math.inf)
            n = self._n_one()
            if n is not None and (t := 2.0 * math.pi / n) < math.inf:
                return _f64(t)
        return self._period_general

    @property
    @_in_range
    def _period_general(self):
        kind = self._col("kind")
        bound = (kind == _el.ELLIPSE) | (kind == _el.RADIAL_ELLIPSE)
        n = np.where(bound, self._n, 1.0)
        return self._out(np.where(bound, 2.0 * np.pi / n, np.inf), _T)

    @property
    def energy(self):
        """Specific orbital energy ``-mu / (2 a)`` (0 for the parabola)."""
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            w = -0.5 * self._one[6] * c[2]
            if abs(w) < math.inf:
                return _f64(w)
        return self._energy_general

    @property
    @_in_range
    def _energy_general(self):
        return self._out(-0.5 * self._mu * self._inv_a, "km2 / s2")

    @cached_property
    def _tau(self) -> np.ndarray:
        flat_r = self._r.reshape(-1, 3)
        flat_v = self._v.reshape(-1, 3)
        flat_mu = self._mu.reshape(-1)
        out = np.empty(flat_r.shape[0])
        _el.state_to_time_since_periapsis(flat_r, flat_v, flat_mu, out)
        _refuse_beyond_range(out[:, None], flat_r, flat_v, flat_mu, self._mu.shape)
        return out.reshape(self._mu.shape)

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
        c = self._c1
        if c is not None or (c := self._one_classical()) is not None:
            y = (c[4] + (1.0 if c[3] <= 0.5 * math.pi else -1.0) * c[5]) % _TWO_PI  # as _wrap2pi
            return _f64(0.0 if y >= _TWO_PI else y)
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
        kind = self._col("kind")
        bound = (kind == _el.ELLIPSE) | (kind == _el.RADIAL_ELLIPSE)
        return self._out(np.where(bound, _wrap2pi(ml), ml), _RAD)

    @property
    def areal_vector(self):
        """Hamilton's beta = r x v (seed eq. 3), normal to the plane, twice the areal velocity."""
        one = self._one
        if one is not None:  # Python floats, as np.cross computes them
            rx, ry, rz, vx, vy, vz, _ = one
            h = (ry * vz - rz * vy, rz * vx - rx * vz, rx * vy - ry * vx)
            if abs(h[0] + h[1] + h[2]) < math.inf:
                return np.array(h)
        return self._areal_vector_general

    @property
    @_in_range
    def _areal_vector_general(self):
        return self._out(np.cross(self._r, self._v), "km2 / s")

    @property
    def eccentricity_vector(self):
        """Modern eccentricity vector ``((v^2 - mu/r) r - (r.v) v)/mu``, towards periapsis."""
        e = self._ecc_vector_one()
        return self._eccentricity_vector_general if e is None else np.array(e)

    @property
    @_in_range
    def _eccentricity_vector_general(self):
        return self._out(_ecc_vector(self._r, self._v, self._mu), None)

    @property
    def hamilton_epsilon(self):
        """Hamilton's epsilon ``iota - v beta / M`` (eq. 13) = -eccentricity_vector, to apoapsis."""
        e = self._ecc_vector_one()
        return self._hamilton_epsilon_general if e is None else -np.array(e)

    @property
    @_in_range
    def _hamilton_epsilon_general(self):
        return self._out(-_ecc_vector(self._r, self._v, self._mu), None)

    def _ecc_vector_one(self) -> tuple[float, float, float] | None:
        """:func:`_ecc_vector` of one orbit from plain floats in Python floats (the
        same operations in the same order), or None (a batch, a Quantity orbit,
        or a value beyond float64: the general path then answers or names it)."""
        one = self._one
        if one is None:
            return None
        rx, ry, rz, vx, vy, vz, m = one
        rn = math.sqrt(rx * rx + ry * ry + rz * rz)
        f = vx * vx + vy * vy + vz * vz - m / rn
        rv = rx * vx + ry * vy + rz * vz
        e = ((f * rx - rv * vx) / m, (f * ry - rv * vy) / m, (f * rz - rv * vz) / m)
        return e if abs(e[0] + e[1] + e[2]) < math.inf else None

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

        By universal variables (:func:`hamilton_orbits.kepler.propagate`).

        Parameters
        ----------
        dt : array_like or Quantity (time), shape (...)

        Returns
        -------
        KeplerOrbit

        Examples
        --------
        >>> o = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.1, lan=0.2, argp=0.3,
        ...                               M=0.5, mu=1.0)
        >>> round(float(o.propagate(2.0).M), 12)
        2.5
        """
        fast = self._propagate_fast(dt)
        if fast is not None:
            return fast
        if is_quantity(dt) != self._quantity:
            raise ValueError("Expected `dt` to be a Quantity exactly when the orbit has units")
        dt_ = TIME("dt", dt, _T)
        r, v = _kepler.propagate(self._r, self._v, self._mu, dt_)
        mu = np.broadcast_to(self._mu, np.shape(r)[:-1])
        return KeplerOrbit(r, v, mu, self._quantity)

    def _propagate_fast(self, dt: Any) -> KeplerOrbit | None:
        """:meth:`propagate` for plain floats: ``dt`` a finite number or a float64
        array of the orbit's shape; the state was validated when the orbit was
        built.  None for anything else or on failure (the general path then
        names the argument)."""
        if self._quantity:
            return None
        one = self._one
        if one is not None and type(dt) is float and math.isfinite(dt):
            *state, ok = _kk.propagate_one(*one, dt)
            if not ok or not (state[0] or state[1] or state[2]):
                return None
            obj = KeplerOrbit.__new__(KeplerOrbit)
            obj._quantity = False
            obj._one = (*state, one[6])
            return obj
        lead = self._mu.shape
        n = self._mu.size
        if type(dt) is float or (type(dt) is int and -(2**53) <= dt <= 2**53):
            if not math.isfinite(dt):
                return None
            dtb = np.full(n, dt, dtype=np.float64)
        elif (
            type(dt) is np.ndarray and dt.dtype == np.float64 and dt.shape in (lead, ())
            and bool(np.isfinite(dt).all())
        ):
            dtb = np.ascontiguousarray(np.broadcast_to(dt, lead)).reshape(n)
        else:
            return None
        r_out = np.empty((n, 3))
        v_out = np.empty((n, 3))
        if n and _kk.propagate_batch(
            self._r.reshape(-1, 3), self._v.reshape(-1, 3), self._mu.reshape(-1), dtb,
            r_out, v_out,
        ) >= 0:
            return None
        obj = KeplerOrbit.__new__(KeplerOrbit)
        obj._r = r_out.reshape((*lead, 3))
        obj._v = v_out.reshape((*lead, 3))
        obj._mu = self._mu  # never written to
        obj._quantity = False
        return obj

    @property
    def conic(self):
        """Hamilton's geometry of the orbit, a :class:`hamilton_orbits.conic.Conic`."""
        from hamilton_orbits.conic import Conic

        return Conic._from_orbit(self)


def _refuse_beyond_range(out, r, v, mu, shape) -> None:
    """Raise if a kernel row is not finite: the state's elements do not fit in
    float64 (``|r| |v|^2 / mu``, ~e, beyond 2^450, or ``p``, ``1/a`` or the time
    beyond the float range).  One fast reduction in the common case."""
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(out.sum()):
            return
    rows = ~np.all(np.isfinite(out), axis=-1)
    if not np.any(rows):
        return
    i = int(np.flatnonzero(rows)[0])
    where = fmt_index(tuple(int(k) for k in np.unravel_index(i, shape))) if shape else ""
    raise ValueError(
        f"Expected `r`, `v`, `mu` whose elements fit in float64 (|r| |v|^2 / mu ~ e below "
        f"2^450 ~ 3e135, p and a below 1e308), got r={r[i].tolist()}, v={v[i].tolist()}, "
        f"mu={float(mu[i])!r}{where}"
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
