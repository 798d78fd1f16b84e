"""Kepler's equation, the anomalies, and universal-variable propagation.

One convention for every conic, by eccentricity ``e``:

=========  =======================  ==============================
``e``      anomaly                  Kepler's equation
=========  =======================  ==============================
``e < 1``  eccentric E (rad)        ``M = E - e sin E``
``e == 1`` parabolic D = tan(nu/2)  ``M = D + D**3/3`` (Barker)
``e > 1``  hyperbolic F             ``M = e sinh F - F``
=========  =======================  ==============================

The mean anomaly is ``M = n (t - T)``, with ``n = sqrt(mu/|a|^3)`` for
``e != 1`` and ``n = sqrt(mu/(2 q^3))`` for the parabola (periapsis distance q),
so Barker's equation reads ``t - T = sqrt(2 q^3/mu) (D + D^3/3)``.

The orbit itself is Hamilton's conic ``r = p/(1 + e cos v)`` (Hamilton 1845,
equation 15, with p = -beta^2/M of equation 16); the radial-velocity law (66)
``(dr/dt)^2 = M (2/r - 1/a - p/r^2)`` is the derivative of Kepler's equation
along it.  Everything here is evaluated without cancellation; see
``docs/kepler.md`` for the formulations and the accuracy evidence.

The two-body state that :class:`~hamilton_orbits.orbit.KeplerOrbit` and
:class:`~hamilton_orbits.conic.Conic` are built on is checked once by
:func:`hamilton_orbits.twobody.check_state` (and its classical elements computed by
:func:`hamilton_orbits.twobody.classical_columns`); the names ``check_state``,
``classical_columns``, ``refuse_beyond_range`` and ``STATE_UNITS`` still answer
here, with a ``DeprecationWarning``.

The compiled kernels live in :mod:`hamilton_orbits._kernels.kepler`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.deprecation import moved_name
from hamilton_orbits.units import (
    ANGLE,
    DIMENSIONLESS,
    GM,
    LENGTH,
    SPEED,
    TIME,
    is_quantity,
    time_quantity,
    wrap,
)
from hamilton_orbits.validation import (
    ConvergenceError,
    broadcast,
    check_positive,
    check_trailing,
)

# numba and astropy are imported on first use (hamilton_orbits._lazy)
_k = LazyModule("hamilton_orbits._kernels.kepler", globals(), "_k")
u = LazyModule("astropy.units", globals(), "u")

__all__ = [
    "ConvergenceError",
    "anomaly_from_true",
    "mean_anomaly",
    "propagate",
    "solve_kepler",
    "true_from_anomaly",
]


def _index(shape: tuple[int, ...], flat: int) -> str:
    if len(shape) == 0:
        return ""
    idx = np.unravel_index(flat, shape)
    idx = tuple(int(i) for i in idx)
    return " at index " + (str(idx[0]) if len(idx) == 1 else str(idx))


def _angle_pair(
    name: str, x: Any, e: Any
) -> tuple[np.ndarray, np.ndarray, bool]:
    quantity = is_quantity(x)
    xa = ANGLE(name, x)
    ea = DIMENSIONLESS("e", e)
    check_positive("e", ea, strict=False)
    xa, ea = broadcast((name, "e"), xa, ea)
    return xa, ea, quantity


def _out(value: np.ndarray, quantity: bool):
    if quantity:
        return wrap(value, "rad", True)
    return value[()] if value.ndim == 0 else value


def _solved(ufunc: Any, name: str, x: Any, e: Any,
            refuse: Callable[[float, float, str], Exception]) -> Any:
    """``ufunc(x, e)`` on the angle pair (``name`` the angle's argument name), refusing
    the first NaN it returns with ``refuse(x_i, e_i, " at index ...")``."""
    xa, ea, quantity = _angle_pair(name, x, e)
    out = np.asarray(ufunc(xa, ea), dtype=np.float64)
    i = _first_nan(out)
    if i is not None:
        raise refuse(float(xa.ravel()[i]), float(ea.ravel()[i]), _index(out.shape, i))
    return _out(out, quantity)


def _first_nan(out: np.ndarray) -> int | None:
    """Flat index of the first NaN a kernel returned (its failure flag), else None."""
    bad = np.isnan(out.ravel())
    return int(np.flatnonzero(bad)[0]) if bad.any() else None


def solve_kepler(M: Any, e: Any):
    """Solve Kepler's equation for the anomaly, for every eccentricity ``e >= 0``.

    Parameters
    ----------
    M : array_like or Quantity (angle), shape (...)
        Mean anomaly (any size; elliptic M is reduced modulo 2 pi internally and
        the revolution count is kept, so the result is monotone in M).
    e : array_like, shape (...)
        Eccentricity, ``e >= 0``; broadcast against ``M``.

    Returns
    -------
    anomaly : ndarray or Quantity (rad), shape of the broadcast inputs
        Eccentric anomaly E (``e < 1``), parabolic anomaly ``D = tan(nu/2)``
        (``e == 1``) or hyperbolic anomaly F (``e > 1``).  A Quantity in rad if
        ``M`` was a Quantity (D, a pure number, is then carried in rad too).

    Raises
    ------
    ValueError
        If ``e < 0``, any input is NaN or infinite, or the shapes do not
        broadcast; the message names the argument, the index and the value.
    ConvergenceError
        If the iteration fails to converge (never seen in the test grids).

    Notes
    -----
    Elliptic: ``M = (1-e) E + e (E - sin E)`` solved by safeguarded Halley
    iteration from the cubic ``(1-e) E + e E^3/6 = M`` (a lower bound);
    parabolic: Barker's cubic in closed form ``D = 2 sinh(asinh(3M/2)/3)``;
    hyperbolic: ``M = (e-1) sinh F + (sinh F - F)``, safeguarded Halley from
    ``asinh`` / cubic bounds (M up to 1e12 and beyond).  The residual
    ``|M(anomaly) - M|`` is within a few ulp of ``max(1, |M|)`` plus the
    unavoidable half-ulp of the anomaly times ``dM/d(anomaly)``, and a tiny M
    keeps full relative precision.

    References
    ----------
    Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. (2013),
    Algorithms 2-4 (KepEqtnE, KepEqtnP, KepEqtnH).  Danby, *Fundamentals of
    Celestial Mechanics*, 2nd ed. (1988), section 6.6.

    Examples
    --------
    >>> E = solve_kepler(1.0, 0.5)
    >>> round(float(E), 12), round(float(E - 0.5 * np.sin(E)), 12)
    (1.498701133518, 1.0)
    >>> [f"{x:.10g}" for x in solve_kepler([1e-12, 2.0], [1.0, 3.0])]  # D, then F
    ['1e-12', '0.8441608952']
    """
    return _solved(_k.solve_ufunc, "M", M, e, lambda m, e_, at: ConvergenceError(
        f"solve_kepler did not converge for M={m!r}, e={e_!r}{at}"))


def mean_anomaly(anomaly: Any, e: Any):
    """Mean anomaly from the eccentric, parabolic or hyperbolic anomaly.

    Parameters
    ----------
    anomaly : array_like or Quantity (angle), shape (...)
        E (``e < 1``), ``D = tan(nu/2)`` (``e == 1``) or F (``e > 1``).
    e : array_like, shape (...)
        Eccentricity ``>= 0``.

    Returns
    -------
    M : ndarray or Quantity (rad)
        ``(1-e) E + e (E - sin E)``, ``D + D^3/3`` or
        ``(e-1) sinh F + (sinh F - F)``: each a sum of two terms of one sign,
        with ``E - sin E`` and ``sinh F - F`` summed as series near zero, so
        there is no cancellation for small anomalies or e near 1.

    Raises
    ------
    ValueError
        ``e < 0``, NaN / inf, or shapes that do not broadcast.

    References
    ----------
    Vallado (2013), section 2.2 (Kepler's equation; Barker's equation).

    Examples
    --------
    Near periapsis of a near-parabolic ellipse the textbook form loses 4 digits:

    >>> E, e = 1e-8, 1.0 - 2.0**-40
    >>> exact = 2.0**-40 * E + e * E**3 / 6  # + O(E^5), below 1e-16 relative here
    >>> naive = E - e * np.sin(E)
    >>> round(float(mean_anomaly(E, e)) / exact - 1, 15), bool(abs(naive / exact - 1) > 1e-6)
    (0.0, True)
    """
    xa, ea, quantity = _angle_pair("anomaly", anomaly, e)
    with np.errstate(over="ignore"):  # e sinh F beyond float64: refused below
        out = np.asarray(_k.mean_from_anomaly_ufunc(xa, ea), dtype=np.float64)
    if not np.all(np.isfinite(out)):
        i = int(np.flatnonzero(~np.isfinite(out).ravel())[0])
        raise ValueError(
            f"Expected `anomaly` small enough for a finite mean anomaly, got "
            f"{float(xa.ravel()[i])!r} with e={float(ea.ravel()[i])!r}"
            f"{_index(out.shape, i)}"
        )
    return _out(out, quantity)


def anomaly_from_true(nu: Any, e: Any):
    """Eccentric, parabolic or hyperbolic anomaly from the true anomaly.

    Parameters
    ----------
    nu : array_like or Quantity (angle), shape (...)
        True anomaly; for ``e >= 1`` it must lie strictly between the
        asymptotes, ``1 + e cos nu > 0``.
    e : array_like, shape (...)
        Eccentricity ``>= 0``.

    Returns
    -------
    anomaly : ndarray or Quantity (rad)
        ``E = 2 atan2(sqrt(1-e) sin(nu/2), sqrt(1+e) cos(nu/2))`` (the
        revolution count of nu is kept), ``D = tan(nu/2)``, or
        ``F = 2 atanh(sqrt((e-1)/(e+1)) tan(nu/2))``.

    Raises
    ------
    ValueError
        ``e < 0``, NaN / inf, incompatible shapes, or an open orbit's ``nu``
        beyond the asymptote (naming the index and the values).

    References
    ----------
    Vallado (2013), Algorithm 5 (nu2anomaly).

    Examples
    --------
    >>> round(float(anomaly_from_true(np.pi / 2, 0.5)), 12)  # cos E = e
    1.047197551197
    >>> round(float(anomaly_from_true(np.pi / 2, 1.0)), 12)  # D = tan(pi/4)
    1.0
    """
    return _solved(_k.anomaly_from_nu_ufunc, "nu", nu, e, lambda x, e_, at: ValueError(
        f"Expected `nu` inside the asymptotes (1 + e cos nu > 0), got {x!r} with e={e_!r}{at}"))


def true_from_anomaly(anomaly: Any, e: Any):
    """True anomaly from the eccentric, parabolic or hyperbolic anomaly.

    Parameters
    ----------
    anomaly : array_like or Quantity (angle), shape (...)
        E, D or F according to ``e``.
    e : array_like, shape (...)
        Eccentricity ``>= 0``.

    Returns
    -------
    nu : ndarray or Quantity (rad)
        ``2 atan2(sqrt(1+e) sin(E/2), sqrt(1-e) cos(E/2))`` (revolution count
        kept), ``2 atan(D)``, or ``2 atan2(sqrt(e+1) tanh(F/2), sqrt(e-1))``
        (no overflow for any finite F).

    Raises
    ------
    ValueError
        ``e < 0``, NaN / inf, or incompatible shapes.

    References
    ----------
    Vallado (2013), Algorithm 6 (anomaly2nu).

    Examples
    --------
    >>> round(float(true_from_anomaly(np.pi / 3, 0.5)), 12)  # cos nu = 0
    1.570796326795
    """
    xa, ea, quantity = _angle_pair("anomaly", anomaly, e)
    out = np.asarray(_k.nu_from_anomaly_ufunc(xa, ea), dtype=np.float64)
    return _out(out, quantity)


_M = "m"
_MS = "m / s"
_MU = "m3 / s2"


def propagate(r: Any, v: Any, mu: Any, dt: Any, *, threads: bool = True) -> tuple[Any, Any]:
    """Two-body state after a time ``dt``, by universal variables.

    Parameters
    ----------
    r : array_like or Quantity (length), shape (..., 3)
        Position relative to the attracting centre (nonzero).
    v : array_like or Quantity (length/time), shape (..., 3)
        Velocity.
    mu : array_like or Quantity (length^3/time^2), shape (...)
        Gravitational parameter ``G (m1 + m2) > 0`` (Hamilton's M).
    dt : array_like, Quantity (time) or TimeDelta, shape (...)
        Time step, any sign and size (a bound orbit's dt is reduced modulo the
        exact period first, so 1e6 periods cost the same as one); a TimeDelta is
        the Quantity in days it holds.
    threads : bool
        Share many rows (from 65536) among threads (the default); False: one
        thread whatever the rows, so the threaded kernel is never compiled (worth
        it for a few calls, such as a figure's points).  The results are the same.

    Either all four are Quantities or all are plain floats in one consistent
    unit system.  Leading dimensions broadcast.

    Returns
    -------
    r, v : ndarray or Quantity, shape (broadcast leading dims) + (3,)
        The state at ``t + dt`` (Quantities in the units of ``r`` and ``v``).

    Raises
    ------
    ValueError
        NaN / inf, wrong trailing shape, ``mu <= 0``, ``r = 0``, mixed
        Quantity / float input, or shapes that do not broadcast.
    ConvergenceError
        If the universal Kepler equation cannot be solved, or the orbit is
        radial and lands exactly on the collision (infinite velocity).

    Notes
    -----
    The universal Kepler equation ``sqrt(mu) dt = r0 U1 + sigma0 U2 + U3``
    with ``U_k = chi^k c_k(alpha chi^2)`` (Stumpff functions), solved by
    Laguerre's method inside a bracket, then Lagrange's f and g.  Moving
    towards periapsis the equation is anchored at periapsis (no cancellation);
    the transverse velocity is ``h x r / r^2`` with the constant areal vector
    ``h = r0 x v0`` (Hamilton 1845, eq. 3: beta), so r x v and the energy are
    conserved to rounding.  A radial orbit (h = 0) that reaches r = 0 is
    continued as the regularised bounce (it returns along the same line).

    References
    ----------
    Vallado (2013), Algorithm 8 (KEPLER) and section 2.3; Curtis, *Orbital
    Mechanics for Engineering Students*, 3rd ed. (2014), Algorithm 3.4;
    Conway, Celest. Mech. 39, 199 (1986) for Laguerre's method.

    Examples
    --------
    A circular orbit of unit radius (mu = 1) after a quarter period:

    >>> r, v = propagate([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, np.pi / 2)
    >>> np.round(r, 12) + 0.0, np.round(v, 12) + 0.0
    (array([0., 1., 0.]), array([-1.,  0.,  0.]))
    """
    dt = time_quantity(dt)  # (a TimeDelta: the Quantity in days it holds)
    flags = [is_quantity(x) for x in (r, v, mu, dt)]
    quantity = all(flags)
    if any(flags) and not quantity:
        names = ", ".join(n for n, f in zip(("r", "v", "mu", "dt"), flags, strict=True) if not f)
        raise ValueError(
            f"Expected `r`, `v`, `mu`, `dt` to be all Quantities or all plain floats, "
            f"got plain floats for {names}"
        )
    if quantity:
        r_unit, v_unit = r.unit, v.unit
    ra = LENGTH("r", r, _M)
    va = SPEED("v", v, _MS)
    mua = GM("mu", mu, _MU)
    dta = TIME("dt", dt, "s")
    check_trailing("r", ra, 3)
    check_trailing("v", va, 3)
    check_positive("mu", mua)
    try:
        lead = np.broadcast_shapes(ra.shape[:-1], va.shape[:-1], mua.shape, dta.shape)
    except ValueError:
        broadcast(("r", "v", "mu", "dt"), ra[..., 0], va[..., 0], mua, dta)  # raises, naming
        raise
    n = math.prod(lead)
    # views where possible: the kernel takes strided (even stride-0) inputs
    rb = np.broadcast_to(ra, (*lead, 3)).reshape(n, 3)
    vb = np.broadcast_to(va, (*lead, 3)).reshape(n, 3)
    mub = np.broadcast_to(mua, lead).reshape(n)
    dtb = np.broadcast_to(dta, lead).reshape(n)
    r_out = np.empty((n, 3))
    v_out = np.empty((n, 3))
    if not isinstance(threads, bool):
        raise ValueError(f"Expected `threads` to be True or False, got {threads!r}")
    batch = _k.propagate_batch if threads else _k.propagate_batch.serial
    bad = batch(rb, vb, mub, dtb, r_out, v_out)
    if bad >= 0:
        if not np.any(rb[bad]):
            raise ValueError(
                f"Expected `r` nonzero, got {rb[bad].tolist()!r}{_index(lead, bad)}"
            )
        # |r| |v|^2 / mu (~ e) beyond the kernels' range, or a state beyond float64
        big_r = float(np.max(np.abs(rb[bad])))
        big_v = float(np.max(np.abs(vb[bad])))
        if math.log2(big_r) + 2 * math.log2(max(big_v, 1e-300)) - math.log2(mub[bad]) > 440:
            raise ValueError(
                f"Expected `v` with |r| |v|^2 / mu (~ e) below 2^450 ~ 3e135, got "
                f"r={rb[bad].tolist()!r}, v={vb[bad].tolist()!r}, mu={mub[bad].tolist()!r}"
                f"{_index(lead, bad)}"
            )
        raise ConvergenceError(
            f"propagate failed for r={rb[bad].tolist()!r}, v={vb[bad].tolist()!r}, "
            f"mu={mub[bad].tolist()!r}, dt={dtb[bad].tolist()!r}{_index(lead, bad)}"
        )
    r_out = r_out.reshape((*lead, 3))
    v_out = v_out.reshape((*lead, 3))
    if quantity:
        return wrap(r_out, _M, True).to(r_unit), wrap(v_out, _MS, True).to(v_unit)
    return r_out, v_out


def __getattr__(name: str) -> Any:
    """The names that moved to :mod:`hamilton_orbits.twobody` (with a DeprecationWarning)."""
    return moved_name(__name__, _MOVED, name)


_MOVED = dict.fromkeys(("STATE_UNITS", "check_state", "classical_columns",
                        "refuse_beyond_range"), "hamilton_orbits.twobody")
