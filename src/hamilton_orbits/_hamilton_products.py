"""Hamilton's two-body integrals exactly as he writes them, as quaternion products:
the areal vector beta (:func:`hamilton_beta`, seed eq. 3), the eccentricity vector
epsilon (:func:`hamilton_epsilon_from_products`, eq. 13, towards the apoapsis) and
the semi-parameter p (:func:`hamilton_p`, eq. 16).

Documented and imported as ``hamilton_orbits.orbit.hamilton_beta`` and so on.

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some
dynamical questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits._lazy import LazyModule
from hamilton_orbits._orbit_build import raise_at
from hamilton_orbits._quaternion_arrays import NO_SCALE, scale_exactly
from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.twobody import STATE_UNITS
from hamilton_orbits.units import GM, LENGTH, SPEED, require_consistent, wrap
from hamilton_orbits.validation import broadcast_shapes, check_positive, check_trailing

# astropy is imported on first use (hamilton_orbits._lazy)
u = LazyModule("astropy.units", globals(), "u")

__all__ = ["hamilton_beta", "hamilton_epsilon_from_products", "hamilton_p"]

# internal units when Quantities come in
_L, _V, _MU = STATE_UNITS


def _hamilton_args(r: Any, v: Any, *mu: Any):
    """(r, v, mu) of Hamilton's integrals as floats (km, km/s, km^3/s^2 for
    Quantities) and whether the call was in Quantities (no mixing)."""
    quantity = require_consistent(("r", "v", "mu")[: 2 + len(mu)], (r, v, *mu))
    r_ = check_trailing("r", LENGTH("r", r, _L), 3)
    v_ = check_trailing("v", SPEED("v", v, _V), 3)
    mu_ = check_positive("mu", GM("mu", mu[0], _MU)) if mu else None
    broadcast_shapes(("r", "v", "mu")[: 2 + len(mu)], r_.shape[:-1], v_.shape[:-1],
                     *((np.shape(mu_),) if mu else ()))
    return r_, v_, mu_, quantity


def _finite_or_raise(f, r: np.ndarray, v: np.ndarray, name: str) -> np.ndarray:
    """``f(r, v)`` without floating-point warnings; a result beyond float64
    raises ValueError naming ``r`` and ``v`` (and Hamilton's ``name``)."""
    with np.errstate(all="ignore"):
        try:
            out = np.asarray(f(r, v))
        except ValueError:  # a quaternion product beyond float64 inside f
            out = np.asarray(np.inf)
    if not np.all(np.isfinite(out)):
        raise ValueError(
            f"Expected `r`, `v` (and `mu`) for which Hamilton's {name} fits in float64, "
            f"got r={r.tolist()}, v={v.tolist()}"
        )
    return out


def _beta_scaled(r: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(b, k)`` with beta = ``b 2**k``: beta of ``r`` and ``v`` each scaled by a
    power of two (exact), so that the scalar part of ``alpha alpha'`` (``-r . v``),
    which beta does not keep, cannot overflow (r, v of 1e160 gave no beta of 1e60)."""
    rs, er, _ = scale_exactly(r)
    vs, ev, _ = scale_exactly(v)
    alpha = Quaternion.from_vector(rs)
    dalpha = Quaternion.from_vector(vs)
    beta = ((alpha * dalpha - dalpha * alpha) * 0.5).vector
    if er is NO_SCALE and ev is NO_SCALE:
        return beta, NO_SCALE
    return beta, np.broadcast_to(er + ev, beta.shape[:-1])


def _beta(r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """beta of ``r`` and ``v``, scaled back from :func:`_beta_scaled`."""
    beta, k = _beta_scaled(r, v)
    if k is NO_SCALE:
        return beta
    return np.ldexp(beta, k[..., None])


def _p(r: np.ndarray, v: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """``-beta^2 / M`` with beta and M scaled by powers of two (exact) and the result
    scaled back once: beta^2 formed unscaled under- or overflowed (-0.0 for a true p
    of 1e-170, a refusal of a p of 1e150 that fits); +0 for a radial state."""
    beta, k = _beta_scaled(r, v)
    b, kb, _ = scale_exactly(beta)  # (b safe to square)
    mu_m, mu_e = np.frexp(mu)  # mu = mu_m 2**mu_e, mu_m in [1/2, 1)
    bq = Quaternion.from_vector(b)
    q = -(bq * bq).scalar / mu_m
    return np.ldexp(q, 2 * (k + kb) - mu_e) + 0.0  # (+0.0: no -0.0 where beta = 0)


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
    return wrap(_finite_or_raise(_beta, r_, v_, "beta"), "km2 / s", quantity)


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
    raise_at("r", ~(big > 0), big, "nonzero (|r| > 0)")
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

    return wrap(_finite_or_raise(eps_of, r_, v_, "epsilon"), "", quantity)


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
        return _p(r_, v_, mu_)

    return wrap(_finite_or_raise(p_of, r_, v_, "p"), _L, quantity)
