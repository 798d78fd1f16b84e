"""The float arrays under :class:`~hamilton_orbits.quaternion.Quaternion`: exact
power-of-two scaling, the Hamilton product that retries an overflow on scaled
operands, the exponential, and the errors that name the operand.

Every function takes and returns plain float64 arrays of shape ``(..., 4)`` (or
``(..., 3)``, ``(...)``); operands are scaled by powers of two (exact) before
products, norms and reciprocals, so that finite input of any magnitude keeps full
relative precision and only a result that is itself beyond the floats raises.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.units import DIMENSIONLESS
from hamilton_orbits.validation import check_finite_result, check_trailing, first_index

# numba and astropy are imported on first use (hamilton_orbits._lazy)
_kq = LazyModule("hamilton_orbits._kernels.quaternion", globals(), "_kq")
u = LazyModule("astropy.units", globals(), "u")

__all__ = ["CONJ", "NO_SCALE", "SAFE_HI", "SAFE_LO", "SERIES", "dimensionless",
           "exp_components", "exponent_wide", "finite_or_raise", "norm_last", "product",
           "raise_zero", "scale_exactly", "sinc", "unit_last", "with_unit"]

# Below this angle the series for sin(t)/t and atan(t)/t are exact to rounding:
# the first neglected terms are t^8/9! and t^6/7 relative, < 1e-50 for t < 1e-8.
SERIES = 1e-8
# Rows whose largest component is inside these bounds need no scaling (scale_exactly).
SAFE_LO = 1e-140
SAFE_HI = 1e140
NO_SCALE = np.zeros((), dtype=np.int64)
CONJ = np.array([1.0, -1.0, -1.0, -1.0])


def sinc(t: np.ndarray) -> np.ndarray:
    """sin(t)/t, exact to rounding for every t >= 0 including 0 and 1e-300."""
    small = t < SERIES
    t2 = np.where(small, t, 0.0) ** 2  # no overflow warning from the unused branch
    with np.errstate(invalid="ignore", divide="ignore"):
        direct = np.sin(t) / t
    return np.where(small, 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0), direct)


def raise_zero(name: str, n: np.ndarray, what: str, kind: str = "quaternion") -> None:
    """Refuse a zero norm in ``n``, naming ``name`` (a ``kind``: quaternion, vector),
    the index and why (``what``)."""
    bad = n == 0
    if np.any(bad):
        index = first_index(np.atleast_1d(bad)) if n.ndim else ()
        where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
        raise ValueError(f"Expected `{name}` to be a nonzero {kind}{where}: {what}")


def dimensionless(name: str, value: Any, size: int | None = None) -> np.ndarray:
    """Float64 array of a dimensionless argument, optionally of shape (..., size)."""
    a = DIMENSIONLESS(name, value)
    return a if size is None else check_trailing(name, a, size)


def scale_exactly(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``a = b 2**e`` over the last axis, exactly, with |b| safe to square.

    Returns ``(b, e, |b|)``.  Where every row's largest component lies in
    (1e-140, 1e140) (the common case) ``b`` is ``a`` itself (not a copy: never
    modify it) and ``e = 0``: squares and their sums neither overflow nor lose
    anything that matters (an underflowing square is below 1e-280 eps times the
    largest).  Otherwise each row is scaled by a power of two (exact, up to
    components 2**-1074 below the largest) to max|b_i| in [1/2, 1), so norms,
    units and reciprocals computed from ``b`` neither overflow nor underflow,
    whatever the magnitude of ``a``; |b| is then in [1/2, 2] (0 for a zero row).
    """
    m = np.max(np.abs(a), axis=-1)
    if np.all((m > SAFE_LO) & (m < SAFE_HI)):
        return a, NO_SCALE, np.sqrt(np.sum(a * a, axis=-1))
    e = np.frexp(m)[1]
    b = np.ldexp(a, -e[..., None])
    return b, e, np.sqrt(np.sum(b * b, axis=-1))


def norm_last(a: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis without spurious overflow or underflow.

    Only a norm that is itself above the largest float is inf (callers check).
    """
    _, e, nb = scale_exactly(a)
    if e is NO_SCALE:
        return nb
    with np.errstate(over="ignore"):
        return np.ldexp(nb, e)


def unit_last(name: str, a: np.ndarray, what: str, kind: str = "quaternion") -> np.ndarray:
    """``a / |a|`` over the last axis for any magnitude; a zero row raises."""
    b, _, nb = scale_exactly(a)
    raise_zero(name, nb, what, kind)
    return b / nb[..., None]


def exponent_wide(a: np.ndarray) -> np.ndarray:
    """Binary exponent of the largest component of each row (0 for a zero row)."""
    return np.frexp(np.max(np.abs(a), axis=-1))[1]


def product(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, bool]:
    """Hamilton product a b and whether it is finite; overflow is retried on scaled operands.

    Every term a_i b_j is at most |a||b| in size, so the direct product can
    only overflow where |ab| = |a||b| is near or above the largest float; there
    the operands are scaled by powers of two and the product scaled back, so
    that only a component that is itself too large stays infinite.
    """
    if a.shape == b.shape:  # the common case: a compiled loop that reports overflow
        out = np.empty(a.shape)
        if _kq.qmul_flat(a.reshape(-1, 4), b.reshape(-1, 4), out.reshape(-1, 4)):
            return out, True
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            out = _kq.qmul_gufunc(a, b)
        if np.isfinite(out).all():
            return out, True
    ea, eb = exponent_wide(a), exponent_wide(b)
    scaled = _kq.qmul_gufunc(np.ldexp(a, -ea[..., None]), np.ldexp(b, -eb[..., None]))
    with np.errstate(over="ignore"):
        out = np.ldexp(scaled, (ea + eb)[..., None])
    return out, bool(np.isfinite(out).all())


def exp_components(a: np.ndarray, name: str, value: Callable[[], np.ndarray]) -> np.ndarray:
    """exp(w) (cos|v|, sin|v| v/|v|) of components ``a`` (..., 4), finite or raising.

    Where exp(w) alone overflows (w > 709.78) but a component of the result is
    representable (a small cos|v|, say), exp(w) is split as exp(w/2)^2.  A
    result that is not representable raises, naming ``name`` and the values
    ``value()`` (built only then).
    """
    w = a[..., 0]
    v = a[..., 1:]
    t = norm_last(v)
    finite_or_raise(name, t[..., None], "the angle |V q| of the exponential", value)
    c = np.cos(t)
    sc = sinc(t)
    with np.errstate(over="ignore", invalid="ignore"):
        ew = np.exp(w)
        out = np.empty(a.shape)
        out[..., 0] = ew * c
        out[..., 1:] = (ew * sc)[..., None] * v
        over = np.isinf(ew)
        if over.any():
            h = np.exp(0.5 * w)
            out[..., 0] = np.where(over, h * (h * c), out[..., 0])
            split = h[..., None] * ((h * sc)[..., None] * v)
            out[..., 1:] = np.where(over[..., None], split, out[..., 1:])
    return finite_or_raise(name, out, "the exponential", value)


def finite_or_raise(name: str, out: np.ndarray, what: str, value: Any) -> np.ndarray:
    """``out`` if finite, else the named error; ``value()`` builds the quoted values lazily."""
    if np.isfinite(out).all():
        return out
    return check_finite_result(name, out, what, value())


def with_unit(value: np.ndarray, unit: Any) -> Any:
    return value if unit is None else u.Quantity(value, unit, copy=False)
