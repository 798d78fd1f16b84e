"""Hamilton's quaternions on arrays of shape ``(..., 4)``, scalar first.

A quaternion q = w + x i + y j + z k is stored as ``[w, x, y, z]``; leading
dimensions broadcast as in numpy.  Hamilton's operations on a quaternion q
(Hamilton 1845; his S, V, T, U) are :attr:`Quaternion.scalar`,
:attr:`Quaternion.vector`, :meth:`Quaternion.norm` and :meth:`Quaternion.unit`.
For two pure quaternions ("vectors") alpha, beta the Hamilton product is
alpha beta = -alpha.beta + alpha x beta, so alpha^2 = -|alpha|^2.

Rotations
---------
A nonzero quaternion q represents the *active* rotation v -> q v q^-1
(:meth:`Quaternion.rotate`).  Policy for non-unit quaternions used as rotations:
the scale cancels, so every rotation method (``rotate``, ``as_rotation_matrix``,
``as_axis_angle``, ``as_gibbs``, ``as_mrp``, geodesic distances) acts as if the
quaternion had been normalised first; it is not normalised in place.  The zero
quaternion is no rotation and raises ``ValueError``.  q and -q are the same
rotation: rotations compare by geodesic distance (:meth:`Quaternion.rotation_distance`)
and :meth:`Quaternion.canonical` picks the representative with w >= 0.

Cayley's (1843) Rodrigues parameters (lambda, mu, nu) = tan(theta/2) * axis are
the Gibbs vector q_vec / q_w of this module (:meth:`Quaternion.as_gibbs`); his
direction cosines alpha, alpha', alpha'' ... are the *columns* of
:meth:`Quaternion.as_rotation_matrix` (see ``docs/quaternion.md``).

Units and magnitudes
--------------------
Quaternion components, axes, Rodrigues parameters and powers are dimensionless
(:data:`~hamilton_orbits.units.DIMENSIONLESS`: a Quantity must be dimensionless,
an angle is refused); angles go through :data:`~hamilton_orbits.units.ANGLE`
(any angular unit, plain floats are radians).  :meth:`Quaternion.rotate` keeps
the unit of Quantity vectors.  Every operation is exact in scale: operands are
scaled by powers of two (exact) before products, norms and rotations, so finite
input of any magnitude gives full relative precision; a result that is itself
too large for a float (``exp`` of w = 1000, the product of two 1e200
quaternions) raises ``ValueError`` naming the argument, never returns inf or NaN.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.units import ANGLE, DIMENSIONLESS, is_quantity
from hamilton_orbits.validation import (
    as_float_array,
    broadcast_shapes,
    check_finite_result,
    check_trailing,
    first_index,
)

# numba and astropy are imported on first use (hamilton_orbits._lazy)
_kq = LazyModule("hamilton_orbits._kernels.quaternion", globals(), "_kq")
u = LazyModule("astropy.units", globals(), "u")

__all__ = ["Quaternion", "slerp"]

# Below this angle the series for sin(t)/t and atan(t)/t are exact to rounding:
# the first neglected terms are t^8/9! and t^6/7 relative, < 1e-50 for t < 1e-8.
_SERIES = 1e-8
# Rows whose largest component is inside these bounds need no scaling (_scaled).
_SAFE_LO = 1e-140
_SAFE_HI = 1e140
_NO_SCALE = np.zeros((), dtype=np.int64)
_CONJ = np.array([1.0, -1.0, -1.0, -1.0])


def _sinc(t: np.ndarray) -> np.ndarray:
    """sin(t)/t, exact to rounding for every t >= 0 including 0 and 1e-300."""
    small = t < _SERIES
    t2 = np.where(small, t, 0.0) ** 2  # no overflow warning from the unused branch
    with np.errstate(invalid="ignore", divide="ignore"):
        direct = np.sin(t) / t
    return np.where(small, 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0), direct)


def _raise_zero(name: str, n: np.ndarray, what: str) -> None:
    bad = n == 0
    if np.any(bad):
        index = first_index(np.atleast_1d(bad)) if n.ndim else ()
        where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
        raise ValueError(f"Expected `{name}` to be a nonzero quaternion{where}: {what}")


def _dimensionless(name: str, value: Any, size: int | None = None) -> np.ndarray:
    """Float64 array of a dimensionless argument, optionally of shape (..., size)."""
    a = DIMENSIONLESS(name, value)
    return a if size is None else check_trailing(name, a, size)


def _scaled(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    if np.all((m > _SAFE_LO) & (m < _SAFE_HI)):
        return a, _NO_SCALE, np.sqrt(np.sum(a * a, axis=-1))
    e = np.frexp(m)[1]
    b = np.ldexp(a, -e[..., None])
    return b, e, np.sqrt(np.sum(b * b, axis=-1))


def _norm_last(a: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis without spurious overflow or underflow.

    Only a norm that is itself above the largest float is inf (callers check).
    """
    _, e, nb = _scaled(a)
    if e is _NO_SCALE:
        return nb
    with np.errstate(over="ignore"):
        return np.ldexp(nb, e)


def _unit_last(name: str, a: np.ndarray, what: str) -> np.ndarray:
    """``a / |a|`` over the last axis for any magnitude; a zero row raises."""
    b, _, nb = _scaled(a)
    _raise_zero(name, nb, what)
    return b / nb[..., None]


def _exponent_wide(a: np.ndarray) -> np.ndarray:
    """Binary exponent of the largest component of each row (0 for a zero row)."""
    return np.frexp(np.max(np.abs(a), axis=-1))[1]


def _product(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, bool]:
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
    ea, eb = _exponent_wide(a), _exponent_wide(b)
    scaled = _kq.qmul_gufunc(np.ldexp(a, -ea[..., None]), np.ldexp(b, -eb[..., None]))
    with np.errstate(over="ignore"):
        out = np.ldexp(scaled, (ea + eb)[..., None])
    return out, bool(np.isfinite(out).all())


def _exp(a: np.ndarray, name: str, value: Callable[[], np.ndarray]) -> np.ndarray:
    """exp(w) (cos|v|, sin|v| v/|v|) of components ``a`` (..., 4), finite or raising.

    Where exp(w) alone overflows (w > 709.78) but a component of the result is
    representable (a small cos|v|, say), exp(w) is split as exp(w/2)^2.  A
    result that is not representable raises, naming ``name`` and the values
    ``value()`` (built only then).
    """
    w = a[..., 0]
    v = a[..., 1:]
    t = _norm_last(v)
    _finite(name, t[..., None], "the angle |V q| of the exponential", value)
    c = np.cos(t)
    sc = _sinc(t)
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
    return _finite(name, out, "the exponential", value)


def _finite(name: str, out: np.ndarray, what: str, value: Any) -> np.ndarray:
    """``out`` if finite, else the named error; ``value()`` builds the quoted values lazily."""
    if np.isfinite(out).all():
        return out
    return check_finite_result(name, out, what, value())


def _with_unit(value: np.ndarray, unit: Any) -> Any:
    return value if unit is None else u.Quantity(value, unit, copy=False)


def _check_quaternion(name: str, value: Any) -> Quaternion:
    if not isinstance(value, Quaternion):
        raise ValueError(f"Expected `{name}` to be a Quaternion, got {type(value).__name__}")
    return value


class Quaternion:
    """Hamilton's quaternions on arrays of shape ``(..., 4)``, scalar first.

    Parameters
    ----------
    array : array_like, shape (..., 4)
        Components ``[w, x, y, z]``; finite, real, dimensionless (a Quantity
        must be dimensionless).

    Raises
    ------
    ValueError
        If the trailing dimension is not 4, or a component is NaN, infinite,
        complex or not a number (the message names the index).
    astropy.units.UnitConversionError
        If ``array`` is a Quantity with a unit (``[1, 0, 0, 0] * u.m``).

    Notes
    -----
    ``*`` is the Hamilton product (broadcasting), ``p / q`` is ``p q^-1``, a real
    number or array multiplies componentwise, and ``q + s`` adds a real ``s`` to
    the scalar part (Hamilton's quaternion as scalar plus vector).  Shapes that do
    not broadcast, a non-numeric operand (``q * None``) and a result too large
    for a float raise ``ValueError`` naming the operand.  Products and rotations run as
    compiled generalised ufuncs, never per-element Python.

    Examples
    --------
    >>> i, j, k = Quaternion.from_array(np.eye(4)[1:])
    >>> (i * j).as_array()
    array([0., 0., 0., 1.])
    >>> (i * j * k).as_array()
    array([-1.,  0.,  0.,  0.])
    """

    __slots__ = ("_a",)
    __array_priority__ = 1000  # ndarray * Quaternion defers to __rmul__
    # numpy (and astropy's Quantity) binary operators defer to our reflected ones,
    # so that ``array * q`` and ``(2 * u.m) * q`` reach __rmul__ and its checks
    __array_ufunc__ = None

    def __init__(self, array: Any) -> None:
        if isinstance(array, Quaternion):
            self._a = array._a
            return
        self._a = _dimensionless("array", array, 4)

    @classmethod
    def _wrap(cls, a: np.ndarray) -> Quaternion:
        """Wrap an already validated float array without copying or checking."""
        obj = object.__new__(cls)
        obj._a = a
        return obj

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_array(cls, array: Any) -> Quaternion:
        """Quaternions from components ``[w, x, y, z]`` of shape (..., 4).

        Examples
        --------
        >>> Quaternion.from_array([1.0, 2.0, 3.0, 4.0]).vector
        array([2., 3., 4.])
        """
        return cls(array)

    @classmethod
    def from_vector(cls, vector: Any) -> Quaternion:
        """Hamilton's vector: the pure quaternion ``(0, v)`` of ``v`` (..., 3).

        Examples
        --------
        >>> a = Quaternion.from_vector([1.0, 2.0, 2.0])
        >>> (a * a).as_array()          # alpha^2 = -|alpha|^2
        array([-9.,  0.,  0.,  0.])
        """
        v = _dimensionless("vector", vector, 3)
        a = np.zeros(v.shape[:-1] + (4,))
        a[..., 1:] = v
        return cls._wrap(a)

    @classmethod
    def from_axis_angle(cls, axis: Any, angle: Any, *, degrees: bool = False) -> Quaternion:
        """Rotation by ``angle`` (right-handed) about ``axis``.

        Parameters
        ----------
        axis : array_like, shape (..., 3)
            Rotation axis, dimensionless; need not be unit (any magnitude), must
            be nonzero.
        angle : Quantity or array_like, shape (...)
            Rotation angle: a Quantity in any angular unit, or plain radians
            (degrees if ``degrees=True``, for plain numbers only).  The shapes
            of ``axis[..., 0]`` and ``angle`` broadcast.

        Returns
        -------
        Quaternion
            ``(cos(angle/2), sin(angle/2) axis/|axis|)``.

        Raises
        ------
        ValueError
            For a zero axis, non-finite input, shapes that do not broadcast, or
            ``degrees=True`` with a Quantity angle (its unit already says).
        astropy.units.UnitConversionError
            If ``angle`` is a Quantity that is not an angle, or ``axis`` has a unit.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 2.0], 90.0, degrees=True)
        >>> np.round(q.rotate([1.0, 0.0, 0.0]), 15) + 0.0
        array([0., 1., 0.])
        >>> import astropy.units as u
        >>> p = Quaternion.from_axis_angle([0, 0, 1], 90 * u.deg)
        >>> float(p.rotation_distance(q))
        0.0
        """
        if degrees and is_quantity(angle):
            raise ValueError(
                f"Expected `angle` to be a plain number with degrees=True, got the Quantity "
                f"{angle!r}: its unit already says how to read it (drop degrees=True)"
            )
        ax = _dimensionless("axis", axis, 3)
        ang = ANGLE("angle", angle)
        if degrees:
            ang = np.deg2rad(ang)
        shape = broadcast_shapes(("axis", "angle"), ax.shape[:-1], ang.shape)
        unit_axis = _unit_last("axis", ax, "a rotation axis must have nonzero length")
        half = 0.5 * ang
        a = np.empty(shape + (4,))
        a[..., 0] = np.cos(half)
        a[..., 1:] = np.sin(half)[..., None] * unit_axis
        return cls._wrap(a)

    @classmethod
    def from_rotation_matrix(cls, matrix: Any) -> Quaternion:
        """Unit quaternion (w >= 0) of a rotation matrix, shape (..., 3, 3).

        Shepperd's method; ``R @ v == q.rotate(v)``.  A matrix that is not a
        rotation (determinant <= 0, or far from orthogonal) raises.

        Raises
        ------
        ValueError
            If the shape is not (..., 3, 3), an entry is not finite, or
            ``|R^T R - I| > 1e-6`` or ``det R <= 0`` at some index.

        Examples
        --------
        >>> q = Quaternion.from_rotation_matrix(np.diag([1.0, -1.0, -1.0]))
        >>> q.as_array() + 0.0
        array([0., 1., 0., 0.])
        """
        m = _dimensionless("matrix", matrix)
        if m.ndim < 2 or m.shape[-2:] != (3, 3):
            raise ValueError(f"Expected `matrix` to have shape (..., 3, 3), got {m.shape}")
        with np.errstate(all="ignore"):  # huge entries: inf/nan err, refused just below
            err = np.abs(np.swapaxes(m, -1, -2) @ m - np.eye(3)).max(axis=(-1, -2))
            det = np.linalg.det(m)
        bad = ~(err <= 1e-6) | ~(det > 0)
        if np.any(bad):
            index = first_index(np.atleast_1d(bad)) if bad.ndim else ()
            where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
            raise ValueError(
                f"Expected `matrix` to be a rotation matrix{where}: "
                f"|R^T R - I| = {float(np.atleast_1d(err)[index or 0]):.3g}, "
                f"det = {float(np.atleast_1d(det)[index or 0]):.6g}"
            )
        flat = np.ascontiguousarray(m.reshape(-1, 3, 3))
        out = np.empty((flat.shape[0], 4))
        _kq.from_matrix_flat(flat, out)
        return cls._wrap(out.reshape(m.shape[:-2] + (4,)))

    @classmethod
    def from_gibbs(cls, gibbs: Any) -> Quaternion:
        """Unit quaternion from Cayley's Rodrigues parameters (lambda, mu, nu).

        (lambda, mu, nu) = tan(theta/2) * axis (Cayley 1843), so
        q = (1, lambda, mu, nu) / sqrt(kappa) with kappa = 1 + lambda^2 + mu^2 + nu^2.

        Parameters of any finite magnitude are accepted (a Gibbs vector of 1e300
        is a half-turn to rounding).

        Examples
        --------
        >>> float(Quaternion.from_gibbs([0.0, 0.0, 1.0]).as_axis_angle()[1] / np.pi)
        0.5
        """
        g = _dimensionless("gibbs", gibbs, 3)
        a = np.empty(g.shape[:-1] + (4,))
        a[..., 0] = 1.0
        a[..., 1:] = g
        return cls._wrap(_unit_last("gibbs", a, "unreachable"))

    @classmethod
    def from_mrp(cls, mrp: Any) -> Quaternion:
        """Unit quaternion from modified Rodrigues parameters sigma = tan(theta/4) axis.

        q = (1 - |sigma|^2, 2 sigma) / (1 + |sigma|^2).  For |sigma| > 1 the same
        formula is evaluated in r = 1/|sigma| and the unit direction,
        q = (r^2 - 1, 2 r sigma/|sigma|) / (r^2 + 1), which cannot overflow: a
        huge sigma is a turn by nearly 2 pi, q -> -1.

        Examples
        --------
        >>> q = Quaternion.from_mrp([0.0, 0.0, 1.0])   # a half-turn about z
        >>> q.as_array() + 0.0
        array([0., 0., 0., 1.])
        >>> Quaternion.from_mrp([1e200, 0.0, 0.0]).as_array()
        array([-1.e+000,  2.e-200,  0.e+000,  0.e+000])
        """
        s = _dimensionless("mrp", mrp, 3)
        a = np.empty(s.shape[:-1] + (4,))
        if s.size == 0 or np.max(np.abs(s)) < _SAFE_HI:  # |sigma|^2 cannot overflow
            s2 = np.sum(s * s, axis=-1)
            a[..., 0] = (1.0 - s2) / (1.0 + s2)
            a[..., 1:] = (2.0 / (1.0 + s2))[..., None] * s
            return cls._wrap(a)
        b, e, nb = _scaled(s)
        with np.errstate(all="ignore"):  # each branch is used only where it is finite
            n = np.ldexp(nb, e)
            s2 = np.sum(s * s, axis=-1)
            r = np.ldexp(1.0 / nb, -e)
            r2 = r * r
            big = n > 1.0
            a[..., 0] = np.where(big, (r2 - 1.0) / (r2 + 1.0), (1.0 - s2) / (1.0 + s2))
            a[..., 1:] = np.where(
                big[..., None],
                (2.0 * r / (1.0 + r2))[..., None] * (b / nb[..., None]),
                (2.0 / (1.0 + s2))[..., None] * s,
            )
        return cls._wrap(a)

    # ------------------------------------------------------------ exporters
    def as_array(self) -> np.ndarray:
        """The components ``[w, x, y, z]`` as an ndarray of shape (..., 4)."""
        return self._a

    def _unit_or_raise(self, what: str) -> np.ndarray:
        return _unit_last("self", self._a, what)

    def as_rotation_matrix(self) -> np.ndarray:
        """Rotation matrices (..., 3, 3) with ``R @ v == q.rotate(v)``.

        Any nonzero scale is divided out; the zero quaternion raises.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([1, 0, 0], np.pi / 2)
        >>> np.round(q.as_rotation_matrix(), 12) + 0.0
        array([[ 1.,  0.,  0.],
               [ 0.,  0., -1.],
               [ 0.,  1.,  0.]])
        """
        flat = np.ascontiguousarray(self._a.reshape(-1, 4))
        out = np.empty((flat.shape[0], 3, 3))
        if _kq.to_matrix_flat(flat, out) >= 0:
            _raise_zero("self", _norm_last(self._a), "the zero quaternion is no rotation")
        return out.reshape(self.shape + (3, 3))

    def as_axis_angle(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit axis (..., 3) and angle (...) in [0, pi] of the rotation.

        The angle is 2 atan2(|v|, |w|) (accurate at every angle, unlike acos).
        For the identity the axis is [1, 0, 0] by convention.

        Examples
        --------
        >>> axis, angle = Quaternion.from_axis_angle([0, 1, 0], -1.0).as_axis_angle()
        >>> axis + 0.0, float(angle)
        (array([ 0., -1.,  0.]), 1.0)
        """
        u = self.canonical()._unit_or_raise("the zero quaternion is no rotation")
        vn = _norm_last(u[..., 1:])
        angle = 2.0 * np.arctan2(vn, u[..., 0])
        safe = np.where(vn > 0, vn, 1.0)
        axis = np.where((vn > 0)[..., None], u[..., 1:] / safe[..., None], [1.0, 0.0, 0.0])
        return axis, angle

    def as_gibbs(self) -> np.ndarray:
        """Cayley's Rodrigues parameters (lambda, mu, nu) = q_vec / q_w, shape (..., 3).

        Policy near a half-turn: the Gibbs vector tan(theta/2) * axis grows like
        1 / (pi - theta) but keeps full relative accuracy while it is finite, so
        it is returned as computed; where it is infinite (an exact half-turn,
        w == 0, or overflow) a ``ValueError`` names the index and points to
        :meth:`as_mrp`, which is bounded.

        Examples
        --------
        >>> g = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2).as_gibbs()
        >>> np.round(g, 15) + 0.0
        array([0., 0., 1.])
        """
        self._unit_or_raise("the zero quaternion is no rotation")
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            g = self._a[..., 1:] / self._a[..., :1]  # scale-free: one rounding
        bad = ~np.all(np.isfinite(g), axis=-1)
        if np.any(bad):
            index = first_index(np.atleast_1d(bad)) if bad.ndim else ()
            where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
            raise ValueError(
                f"Expected `self` not to be a half-turn: its Gibbs vector (Cayley's lambda, mu, "
                f"nu) is infinite{where}: w = 0, or so small that |V q / S q| overflows. "
                "Use `as_mrp()`, which stays bounded (|sigma| <= 1)."
            )
        return g

    def as_mrp(self) -> np.ndarray:
        """Modified Rodrigues parameters sigma = v / (1 + w), shadow set: |sigma| <= 1.

        The quaternion is normalised and given the sign w >= 0 first, which
        selects the shadow set with |sigma| <= 1 (|sigma| = 1 at a half-turn).

        Examples
        --------
        >>> s = Quaternion.from_axis_angle([1, 0, 0], 1.5 * np.pi).as_mrp()
        >>> np.round(s, 12) + 0.0       # -tan(pi/8) about x: the short way round
        array([-0.41421356,  0.        ,  0.        ])
        """
        u = self.canonical()._unit_or_raise("the zero quaternion is no rotation")
        return u[..., 1:] / (1.0 + u[..., 0])[..., None]

    # ------------------------------------------------------------ Hamilton's S, V, T, U
    @property
    def scalar(self) -> np.ndarray:
        """Hamilton's S q: the scalar part w, shape (...)."""
        return self._a[..., 0]

    @property
    def vector(self) -> np.ndarray:
        """Hamilton's V q: the vector part (x, y, z), shape (..., 3)."""
        return self._a[..., 1:]

    @property
    def w(self) -> np.ndarray:
        """Scalar component."""
        return self._a[..., 0]

    @property
    def x(self) -> np.ndarray:
        """i component."""
        return self._a[..., 1]

    @property
    def y(self) -> np.ndarray:
        """j component."""
        return self._a[..., 2]

    @property
    def z(self) -> np.ndarray:
        """k component."""
        return self._a[..., 3]

    def norm(self) -> np.ndarray:
        """Hamilton's tensor T q = |q| = sqrt(w^2 + x^2 + y^2 + z^2), without overflow.

        Examples
        --------
        >>> float(Quaternion.from_array([1e300, 1e300, 1e300, 1e300]).norm())
        2e+300
        """
        return _finite("self", _norm_last(self._a)[..., None], "the norm", lambda: self._a)[..., 0]

    def unit(self) -> Quaternion:
        """Hamilton's versor U q = q / |q|; the zero quaternion raises.

        Examples
        --------
        >>> Quaternion.from_array([0.0, 3.0, 0.0, 4.0]).unit().as_array()
        array([0. , 0.6, 0. , 0.8])
        """
        return Quaternion._wrap(self._unit_or_raise("it has no unit (versor)"))

    # ------------------------------------------------------------ algebra
    def conj(self) -> Quaternion:
        """Conjugate K q = S q - V q."""
        a = self._a.copy()
        a[..., 1:] *= -1.0
        return Quaternion._wrap(a)

    def inverse(self) -> Quaternion:
        """Reciprocal q^-1 = K q / |q|^2; the zero quaternion raises.

        Examples
        --------
        >>> q = Quaternion.from_array([1.0, 2.0, 3.0, 4.0])
        >>> np.round((q * q.inverse()).as_array(), 15) + 0.0
        array([1., 0., 0., 0.])
        """
        return Quaternion._wrap(
            _finite("self", self._inverse_array(), "the inverse", lambda: self._a)
        )

    def _inverse_array(self) -> np.ndarray:
        """K q / |q|^2 from the exactly scaled q = b 2^e: K b / |b|^2 2^-e (may be inf)."""
        b, e, nb = _scaled(self._a)
        _raise_zero("self", nb, "it has no inverse")
        inv = (b * _CONJ) / (nb * nb)[..., None]
        if e is _NO_SCALE:
            return inv
        with np.errstate(over="ignore"):
            return np.ldexp(inv, -e[..., None])

    def _real(self, other: Any) -> np.ndarray:
        """A real operand as a float array broadcastable against the leading shape."""
        s = _dimensionless("other", other)
        if s.ndim:
            broadcast_shapes(("self", "other"), self.shape, s.shape)
        return s

    def __mul__(self, other: Any) -> Quaternion:
        if isinstance(other, Quaternion):
            if self._a.shape != other._a.shape:
                broadcast_shapes(("self", "other"), self.shape, other.shape)
            out, finite = _product(self._a, other._a)
            if finite:
                return Quaternion._wrap(out)
            value = lambda: np.broadcast_to(other._a, out.shape)  # noqa: E731
        else:
            s = self._real(other)
            with np.errstate(over="ignore"):
                out = self._a * s[..., None]
            value = lambda: np.broadcast_to(s, out.shape[:-1])  # noqa: E731
        return Quaternion._wrap(_finite("other", out, "the product", value))

    def __rmul__(self, other: Any) -> Quaternion:
        return self * other  # a real factor commutes with every quaternion

    def __truediv__(self, other: Any) -> Quaternion:
        if isinstance(other, Quaternion):
            broadcast_shapes(("self", "other"), self.shape, other.shape)
            b, e, nb = _scaled(other._a)
            _raise_zero("other", nb, "division by the zero quaternion")
            inv_scaled = (b * _CONJ) / (nb * nb)[..., None]  # (other / 2^e)^-1
            with np.errstate(over="ignore"):
                out = _product(self._a, inv_scaled)[0]
                if e is not _NO_SCALE:
                    out = np.ldexp(out, -e[..., None])
            value = lambda: np.broadcast_to(other._a, out.shape)  # noqa: E731
        else:
            s = self._real(other)
            _raise_zero("other", np.abs(s), "division by zero")
            with np.errstate(over="ignore"):
                out = self._a / s[..., None]
            value = lambda: np.broadcast_to(s, out.shape[:-1])  # noqa: E731
        return Quaternion._wrap(_finite("other", out, "the quotient", value))

    def __rtruediv__(self, other: Any) -> Quaternion:
        s = self._real(other)
        inv = self._inverse_array()
        with np.errstate(over="ignore", invalid="ignore"):
            out = s[..., None] * inv
        value = lambda: np.broadcast_to(self._a, out.shape)  # noqa: E731
        return Quaternion._wrap(_finite("self", out, "the quotient", value))

    def _sum(self, other: Any, sign: float) -> Quaternion:
        if isinstance(other, Quaternion):
            if self._a.shape != other._a.shape:
                broadcast_shapes(("self", "other"), self.shape, other.shape)
            with np.errstate(over="ignore"):
                out = self._a + sign * other._a
            value = lambda: np.broadcast_to(other._a, out.shape)  # noqa: E731
        else:
            s = self._real(other)
            shape = np.broadcast_shapes(self.shape, s.shape)
            out = np.array(np.broadcast_to(self._a, shape + (4,)))
            with np.errstate(over="ignore"):
                out[..., 0] += sign * s
            value = lambda: np.broadcast_to(s, shape)  # noqa: E731
        what = "the sum" if sign > 0 else "the difference"
        return Quaternion._wrap(_finite("other", out, what, value))

    def __add__(self, other: Any) -> Quaternion:
        return self._sum(other, 1.0)

    def __radd__(self, other: Any) -> Quaternion:
        return self._sum(other, 1.0)

    def __sub__(self, other: Any) -> Quaternion:
        return self._sum(other, -1.0)

    def __rsub__(self, other: Any) -> Quaternion:
        return (-self)._sum(other, 1.0)

    def __neg__(self) -> Quaternion:
        return Quaternion._wrap(-self._a)

    def exp(self) -> Quaternion:
        """Exponential: exp(w) (cos|v|, sin|v| v/|v|), exact to rounding for tiny |v|.

        Raises
        ------
        ValueError
            Where the exponential is too large for a float (w above about
            709.78, e.g. ``Quaternion([1e3, 0, 0, 0]).exp()``: e^1000 is not
            representable), naming ``self``, the index and the quaternion.
            Components that are representable although exp(w) alone is not
            (exp(710) cos|v| with a small cosine) are computed.

        Examples
        --------
        >>> q = Quaternion.from_vector([0.0, 0.0, 1e-300]).exp()
        >>> q.as_array()
        array([1.e+000, 0.e+000, 0.e+000, 1.e-300])
        """
        return Quaternion._wrap(_exp(self._a, "self", lambda: self._a))

    def log(self) -> Quaternion:
        """Principal logarithm (log|q|, atan2(|v|, w) v/|v|); the zero quaternion raises.

        Accurate at angles down to 1e-300 (series for atan(t)/t) and near pi
        (atan2 is well conditioned there).  For a negative real q the direction
        is undefined and the i axis is used by convention: log(-1) = pi i.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 1], 1e-300)
        >>> q.log().as_array()
        array([0.e+000, 0.e+000, 0.e+000, 5.e-301])
        """
        b, e, nb = _scaled(self._a)  # q = b 2^e exactly: everything below is scale-free
        _raise_zero("self", nb, "its logarithm is undefined")
        w = self._a[..., 0]
        v = self._a[..., 1:]
        wb = b[..., 0]
        # |v| 2^-e; squares negligible next to wb^2 may underflow, which only
        # touches terms below the rounding of atan2(vb, wb) or of the series
        vb = np.sqrt(np.sum(b[..., 1:] ** 2, axis=-1))
        # the unit direction of v from v scaled by its own power of two (exact
        # even for subnormal v); zero where v = 0
        uv, _, nv = _scaled(v)
        has_v = nv > 0
        direction = uv / np.where(has_v, nv, 1.0)[..., None]
        # atan2(|v|, w)/|v|: for |v| << w use the series of atan(x)/x, x = |v|/w,
        # applied to v/w of the original components (no scaling round-off).
        small = (vb <= _SERIES * wb) & (wb > 0)
        w_s = np.where(small, w, 1.0)
        x2 = (np.where(small, vb, 0.0) / np.where(small, wb, 1.0)) ** 2
        a = np.empty(self._a.shape)
        a[..., 1:] = np.where(
            small[..., None],
            (1.0 - x2 / 3.0)[..., None] * (v / w_s[..., None]),
            np.arctan2(vb, wb)[..., None] * direction,
        )
        # log|q| = log(|b| 2^e), or log|b| + e log 2 where 2^e is beyond the floats
        if e is _NO_SCALE:
            a[..., 0] = np.log(nb)
        elif np.all(np.abs(e) < 900):
            a[..., 0] = np.log(np.ldexp(nb, e))
        else:
            direct = np.log(np.ldexp(nb, np.clip(e, -900, 900)))
            a[..., 0] = np.where(np.abs(e) < 900, direct, np.log(nb) + e * np.log(2.0))
        negative_real = ~has_v & (w < 0)
        a[..., 1] = np.where(negative_real, np.pi, a[..., 1])
        return Quaternion._wrap(a)

    def __pow__(self, t: Any) -> Quaternion:
        """Real power q^t = exp(t log q), broadcasting ``t`` over leading dimensions.

        ``t`` is dimensionless.  Where t log q or its exponential is too large
        for a float, a ``ValueError`` names ``t``.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 1], 0.5)
        >>> float((q ** 3).as_axis_angle()[1])
        1.5
        """
        t = _dimensionless("t", t)
        shape = broadcast_shapes(("self", "t"), self.shape, t.shape)
        lg = self.log()._a
        def tb() -> np.ndarray:
            return np.broadcast_to(t, shape)

        with np.errstate(over="ignore", invalid="ignore"):
            p = lg * t[..., None]
        _finite("t", p, "t log q", tb)
        return Quaternion._wrap(_exp(p, "t", tb))

    # ------------------------------------------------------------ rotations
    def rotate(self, vectors: Any) -> np.ndarray:
        """Apply the rotation: q v q^-1 for vectors of shape (..., 3).

        Non-unit quaternions rotate exactly as their versor (the scale cancels);
        the zero quaternion raises.  Quaternions and vectors of any finite
        magnitude keep full precision (exact power-of-two scaling in the kernel).

        Parameters
        ----------
        vectors : Quantity or array_like, shape (..., 3)
            Vectors in any unit; a Quantity comes back in its own unit.  The
            leading shape broadcasts against the quaternions'.

        Returns
        -------
        ndarray or Quantity, shape (broadcast, 3)

        Raises
        ------
        ValueError
            For the zero quaternion, non-finite or complex vectors, shapes that
            do not broadcast, or a rotated vector too large for a float (a
            vector longer than the largest float), naming the argument and index.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2)
        >>> np.round(q.rotate([[1.0, 0, 0], [0, 1.0, 0]]), 15) + 0.0
        array([[ 0.,  1.,  0.],
               [-1.,  0.,  0.]])
        """
        unit = vectors.unit if is_quantity(vectors) else None
        raw = vectors.value if unit is not None else vectors
        # complex and non-numeric input refused here; finiteness checked in the kernel
        v = check_trailing("vectors", as_float_array("vectors", raw, finite=False), 3)
        if v.shape[:-1] == self.shape:
            # the common case: one vector per quaternion; validate in the same pass
            flat_q = np.ascontiguousarray(self._a.reshape(-1, 4))
            flat_v = np.ascontiguousarray(v.reshape(-1, 3))
            out = np.empty(flat_v.shape)
            if _kq.rotate_flat(flat_q, flat_v, out) == -1:
                return _with_unit(out.reshape(v.shape), unit)
        broadcast_shapes(("self", "vectors"), self.shape, v.shape[:-1])
        as_float_array("vectors", v)
        if not np.all(np.any(self._a != 0, axis=-1)):
            _raise_zero("self", _norm_last(self._a), "the zero quaternion is no rotation")
        with np.errstate(over="ignore", invalid="ignore"):  # overflow: refused just below
            out = _kq.qrot_gufunc(self._a, v)
        _finite("vectors", out, "the rotated vector", lambda: np.broadcast_to(v, out.shape))
        return _with_unit(out, unit)

    def canonical(self) -> Quaternion:
        """The same rotation with the sign chosen so that w > 0 (or, if w == 0,
        the first nonzero component is positive).

        Examples
        --------
        >>> Quaternion.from_array([-1.0, 0.0, 0.0, 0.0]).canonical().as_array() + 0.0
        array([1., 0., 0., 0.])
        """
        a = self._a
        nz = a != 0
        first = np.argmax(nz, axis=-1)
        lead = np.take_along_axis(a, first[..., None], axis=-1)[..., 0]
        return Quaternion._wrap(np.where((lead < 0)[..., None], -a, a))

    def rotation_distance(self, other: Quaternion) -> np.ndarray:
        """Geodesic distance (the rotation angle of self^-1 other) in [0, pi].

        q and -q are at distance 0.  Computed as 2 atan2(|V d|, |S d|) of
        d = U(self)^-1 U(other), accurate for tiny and near-pi angles.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([1, 1, 0], 0.3)
        >>> float(q.rotation_distance(-q))
        0.0
        """
        other = _check_quaternion("other", other)
        broadcast_shapes(("self", "other"), self.shape, other.shape)
        p = Quaternion._wrap(self._unit_or_raise("the zero quaternion is no rotation"))
        q = Quaternion._wrap(_unit_last("other", other._a, "the zero quaternion is no rotation"))
        d = (p.conj() * q)._a
        return 2.0 * np.arctan2(_norm_last(d[..., 1:]), np.abs(d[..., 0]))

    def allclose(self, other: Quaternion, *, rtol: float = 1e-13, atol: float = 0.0) -> bool:
        """Componentwise closeness (as quaternions, so q and -q differ)."""
        other = _check_quaternion("other", other)
        broadcast_shapes(("self", "other"), self.shape, other.shape)
        return bool(np.allclose(self._a, other._a, rtol=rtol, atol=atol))

    def rotation_allclose(self, other: Quaternion, *, atol: float = 1e-13) -> bool:
        """True if every pair of rotations is within ``atol`` radians (q ~ -q)."""
        return bool(np.all(self.rotation_distance(other) <= atol))

    # ------------------------------------------------------------ container protocol
    @property
    def shape(self) -> tuple[int, ...]:
        """Leading (broadcast) shape, without the trailing 4."""
        return self._a.shape[:-1]

    @property
    def ndim(self) -> int:
        """Number of leading dimensions."""
        return self._a.ndim - 1

    def __len__(self) -> int:
        if self._a.ndim == 1:
            raise TypeError("len() of a single (0-d) Quaternion")
        return self._a.shape[0]

    def __getitem__(self, key: Any) -> Quaternion:
        key = key if isinstance(key, tuple) else (key,)
        if any(k is Ellipsis for k in key):
            return Quaternion._wrap(self._a[(*key, slice(None))])
        if len(key) > self.ndim:
            raise IndexError(
                f"too many indices for Quaternion of shape {self.shape}: {len(key)} given"
            )
        return Quaternion._wrap(self._a[(*key, Ellipsis)])

    def __iter__(self):
        for i in range(len(self)):
            yield self[i]

    def __eq__(self, other: object) -> Any:  # componentwise, like numpy
        if not isinstance(other, Quaternion):
            return NotImplemented
        return np.all(self._a == other._a, axis=-1)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        """One quaternion: its components (round-trip exact); a batch: shape and ranges.

        Examples
        --------
        >>> Quaternion.from_array([1.0, 0.0, -0.5, 0.25])
        Quaternion([1.0, 0.0, -0.5, 0.25])
        >>> Quaternion.from_axis_angle([0, 0, 1], [0.0, 0.5, 1.0])
        Quaternion(shape=(3,), w in [0.877583, 1], x in [0, 0], y in [0, 0], z in [0, 0.479426])
        """
        if self._a.ndim == 1:
            return "Quaternion([" + ", ".join(repr(float(c)) for c in self._a) + "])"
        if self._a.size == 0:
            return f"Quaternion(shape={self.shape})"
        lo = self._a.reshape(-1, 4).min(axis=0)
        hi = self._a.reshape(-1, 4).max(axis=0)
        ranges = ", ".join(
            f"{name} in [{a:.6g}, {b:.6g}]" for name, a, b in zip("wxyz", lo, hi, strict=True)
        )
        return f"Quaternion(shape={self.shape}, {ranges})"


def slerp(q0: Quaternion, q1: Quaternion, t: Any) -> Quaternion:
    """Spherical linear interpolation q0 (q0^-1 q1)^t along the shorter arc.

    Parameters
    ----------
    q0, q1 : Quaternion
        End rotations (normalised internally); shapes broadcast.
    t : array_like
        Interpolation parameter(s), dimensionless; 0 gives q0, 1 gives q1 (up to
        sign).  The shapes of q0, q1 and t broadcast.

    Raises
    ------
    ValueError
        If q0 or q1 is not a Quaternion or is zero, ``t`` is not finite, the
        shapes do not broadcast, or t is so large that t times the angle overflows.

    Examples
    --------
    >>> q0 = Quaternion.from_array([1.0, 0, 0, 0])
    >>> q1 = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2)
    >>> round(float(slerp(q0, q1, 0.5).as_axis_angle()[1] / np.pi), 15)
    0.25
    """
    q0 = _check_quaternion("q0", q0)
    q1 = _check_quaternion("q1", q1)
    t = _dimensionless("t", t)
    broadcast_shapes(("q0", "q1", "t"), q0.shape, q1.shape, t.shape)
    p = Quaternion._wrap(_unit_last("q0", q0._a, "the zero quaternion is no rotation"))
    p1 = Quaternion._wrap(_unit_last("q1", q1._a, "the zero quaternion is no rotation"))
    d = (p.conj() * p1).canonical()
    return p * (d**t)
