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
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits._kernels.quaternion import (
    from_matrix_flat,
    qmul_gufunc,
    qrot_gufunc,
    rotate_flat,
    to_matrix_flat,
)
from hamilton_orbits._validation import _first_index, as_float_array, check_trailing

__all__ = ["Quaternion", "slerp"]

# Below this angle the series for sin(t)/t and atan(t)/t are exact to rounding:
# the first neglected terms are t^8/9! and t^6/7 relative, < 1e-50 for t < 1e-8.
_SERIES = 1e-8


def _sinc(t: np.ndarray) -> np.ndarray:
    """sin(t)/t, exact to rounding for every t >= 0 including 0 and 1e-300."""
    small = t < _SERIES
    t2 = t * t
    with np.errstate(invalid="ignore", divide="ignore"):
        direct = np.sin(t) / t
    return np.where(small, 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0), direct)


def _norm_last(a: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis without overflow or underflow."""
    scale = np.max(np.abs(a), axis=-1)
    safe = np.where(scale > 0, scale, 1.0)
    return scale * np.sqrt(np.sum((a / safe[..., None]) ** 2, axis=-1))


def _raise_zero(name: str, n: np.ndarray, what: str) -> None:
    bad = n == 0
    if np.any(bad):
        index = _first_index(np.atleast_1d(bad)) if n.ndim else ()
        where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
        raise ValueError(f"Expected `{name}` to be a nonzero quaternion{where}: {what}")


class Quaternion:
    """Hamilton's quaternions on arrays of shape ``(..., 4)``, scalar first.

    Parameters
    ----------
    array : array_like, shape (..., 4)
        Components ``[w, x, y, z]``; must be finite.

    Raises
    ------
    ValueError
        If the trailing dimension is not 4, or a component is NaN or infinite
        (the message names the index).

    Notes
    -----
    ``*`` is the Hamilton product (broadcasting), ``p / q`` is ``p q^-1``, a real
    number or array multiplies componentwise.  Products and rotations run as
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

    def __init__(self, array: Any) -> None:
        if isinstance(array, Quaternion):
            self._a = array._a
            return
        a = as_float_array("array", array)
        self._a = check_trailing("array", a, 4)

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
        v = check_trailing("vector", as_float_array("vector", vector), 3)
        a = np.zeros(v.shape[:-1] + (4,))
        a[..., 1:] = v
        return cls._wrap(a)

    @classmethod
    def from_axis_angle(cls, axis: Any, angle: Any, *, degrees: bool = False) -> Quaternion:
        """Rotation by ``angle`` (right-handed) about ``axis``.

        Parameters
        ----------
        axis : array_like, shape (..., 3)
            Rotation axis; need not be unit, must be nonzero.
        angle : array_like, shape (...)
            Rotation angle in radians (degrees if ``degrees=True``).

        Returns
        -------
        Quaternion
            ``(cos(angle/2), sin(angle/2) axis/|axis|)``.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 2.0], 90.0, degrees=True)
        >>> np.round(q.rotate([1.0, 0.0, 0.0]), 15) + 0.0
        array([0., 1., 0.])
        """
        ax = check_trailing("axis", as_float_array("axis", axis), 3)
        ang = as_float_array("angle", angle)
        if degrees:
            ang = np.deg2rad(ang)
        n = _norm_last(ax)
        _raise_zero("axis", n, "a rotation axis must have nonzero length")
        half = 0.5 * ang
        s = np.sin(half)
        a = np.empty(np.broadcast_shapes(ax.shape[:-1], ang.shape) + (4,))
        a[..., 0] = np.cos(half)
        a[..., 1:] = (s / n)[..., None] * ax
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
        m = as_float_array("matrix", matrix)
        if m.ndim < 2 or m.shape[-2:] != (3, 3):
            raise ValueError(f"Expected `matrix` to have shape (..., 3, 3), got {m.shape}")
        err = np.abs(np.swapaxes(m, -1, -2) @ m - np.eye(3)).max(axis=(-1, -2))
        det = np.linalg.det(m)
        bad = (err > 1e-6) | (det <= 0)
        if np.any(bad):
            index = _first_index(np.atleast_1d(bad)) if bad.ndim else ()
            where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
            raise ValueError(
                f"Expected `matrix` to be a rotation matrix{where}: "
                f"|R^T R - I| = {float(np.atleast_1d(err)[index or 0]):.3g}, "
                f"det = {float(np.atleast_1d(det)[index or 0]):.6g}"
            )
        flat = np.ascontiguousarray(m.reshape(-1, 3, 3))
        out = np.empty((flat.shape[0], 4))
        from_matrix_flat(flat, out)
        return cls._wrap(out.reshape(m.shape[:-2] + (4,)))

    @classmethod
    def from_gibbs(cls, gibbs: Any) -> Quaternion:
        """Unit quaternion from Cayley's Rodrigues parameters (lambda, mu, nu).

        (lambda, mu, nu) = tan(theta/2) * axis (Cayley 1843), so
        q = (1, lambda, mu, nu) / sqrt(kappa) with kappa = 1 + lambda^2 + mu^2 + nu^2.

        Examples
        --------
        >>> float(Quaternion.from_gibbs([0.0, 0.0, 1.0]).as_axis_angle()[1] / np.pi)
        0.5
        """
        g = check_trailing("gibbs", as_float_array("gibbs", gibbs), 3)
        a = np.empty(g.shape[:-1] + (4,))
        a[..., 0] = 1.0
        a[..., 1:] = g
        return cls._wrap(a / _norm_last(a)[..., None])

    @classmethod
    def from_mrp(cls, mrp: Any) -> Quaternion:
        """Unit quaternion from modified Rodrigues parameters sigma = tan(theta/4) axis.

        q = (1 - |sigma|^2, 2 sigma) / (1 + |sigma|^2).

        Examples
        --------
        >>> q = Quaternion.from_mrp([0.0, 0.0, 1.0])   # a half-turn about z
        >>> q.as_array() + 0.0
        array([0., 0., 0., 1.])
        """
        s = check_trailing("mrp", as_float_array("mrp", mrp), 3)
        s2 = np.sum(s * s, axis=-1)
        a = np.empty(s.shape[:-1] + (4,))
        a[..., 0] = (1.0 - s2) / (1.0 + s2)
        a[..., 1:] = (2.0 / (1.0 + s2))[..., None] * s
        return cls._wrap(a)

    # ------------------------------------------------------------ exporters
    def as_array(self) -> np.ndarray:
        """The components ``[w, x, y, z]`` as an ndarray of shape (..., 4)."""
        return self._a

    def _unit_or_raise(self, what: str) -> np.ndarray:
        n = _norm_last(self._a)
        _raise_zero("self", n, what)
        return self._a / n[..., None]

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
        if to_matrix_flat(flat, out) >= 0:
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
        w = self._a[..., 0]
        _raise_zero("self", _norm_last(self._a), "the zero quaternion is no rotation")
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            g = self._a[..., 1:] / w[..., None]
        bad = ~np.all(np.isfinite(g), axis=-1)
        if np.any(bad):
            index = _first_index(np.atleast_1d(bad)) if bad.ndim else ()
            where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
            raise ValueError(
                f"The Gibbs vector (Cayley's lambda, mu, nu) is infinite{where}: the rotation "
                "is a half-turn (w = 0). Use `as_mrp()`, which stays bounded (|sigma| <= 1)."
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
        return _norm_last(self._a)

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
        n = _norm_last(self._a)
        _raise_zero("self", n, "it has no inverse")
        return Quaternion._wrap(self.conj()._a / n[..., None] / n[..., None])

    def __mul__(self, other: Any) -> Quaternion:
        if isinstance(other, Quaternion):
            return Quaternion._wrap(qmul_gufunc(self._a, other._a))
        s = np.asarray(other, dtype=np.float64)
        return Quaternion._wrap(self._a * s[..., None])

    def __rmul__(self, other: Any) -> Quaternion:
        s = np.asarray(other, dtype=np.float64)
        return Quaternion._wrap(s[..., None] * self._a)

    def __truediv__(self, other: Any) -> Quaternion:
        if isinstance(other, Quaternion):
            return self * other.inverse()
        s = np.asarray(other, dtype=np.float64)
        return Quaternion._wrap(self._a / s[..., None])

    def __add__(self, other: Any) -> Quaternion:
        if not isinstance(other, Quaternion):
            return NotImplemented
        return Quaternion._wrap(self._a + other._a)

    def __sub__(self, other: Any) -> Quaternion:
        if not isinstance(other, Quaternion):
            return NotImplemented
        return Quaternion._wrap(self._a - other._a)

    def __neg__(self) -> Quaternion:
        return Quaternion._wrap(-self._a)

    def exp(self) -> Quaternion:
        """Exponential: exp(w) (cos|v|, sin|v| v/|v|), exact to rounding for tiny |v|.

        Examples
        --------
        >>> q = Quaternion.from_vector([0.0, 0.0, 1e-300]).exp()
        >>> q.as_array()
        array([1.e+000, 0.e+000, 0.e+000, 1.e-300])
        """
        v = self._a[..., 1:]
        t = _norm_last(v)
        ew = np.exp(self._a[..., 0])
        a = np.empty(self._a.shape)
        a[..., 0] = ew * np.cos(t)
        a[..., 1:] = (ew * _sinc(t))[..., None] * v
        return Quaternion._wrap(a)

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
        n = _norm_last(self._a)
        _raise_zero("self", n, "its logarithm is undefined")
        w = self._a[..., 0]
        v = self._a[..., 1:]
        vn = _norm_last(v)
        # atan2(|v|, w)/|v|: for |v| << w use the series of atan(x)/x, x = |v|/w.
        small = (vn <= _SERIES * w) & (w > 0)
        w_s = np.where(small, w, 1.0)
        x2 = (np.where(small, vn, 0.0) / w_s) ** 2
        safe_vn = np.where(vn > 0, vn, 1.0)
        factor = np.where(small, (1.0 - x2 / 3.0) / w_s, np.arctan2(vn, w) / safe_vn)
        a = np.empty(self._a.shape)
        a[..., 0] = np.log(n)
        a[..., 1:] = factor[..., None] * v
        negative_real = (vn == 0) & (w < 0)
        a[..., 1] = np.where(negative_real, np.pi, a[..., 1])
        return Quaternion._wrap(a)

    def __pow__(self, t: Any) -> Quaternion:
        """Real power q^t = exp(t log q), broadcasting ``t`` over leading dimensions."""
        t = as_float_array("t", t)
        lg = self.log()
        return Quaternion._wrap(lg._a * t[..., None]).exp()

    # ------------------------------------------------------------ rotations
    def rotate(self, vectors: Any) -> np.ndarray:
        """Apply the rotation: q v q^-1 for vectors of shape (..., 3).

        Non-unit quaternions rotate exactly as their versor (the scale cancels);
        the zero quaternion raises.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2)
        >>> np.round(q.rotate([[1.0, 0, 0], [0, 1.0, 0]]), 15) + 0.0
        array([[ 0.,  1.,  0.],
               [-1.,  0.,  0.]])
        """
        v = np.asarray(vectors, dtype=np.float64)
        if v.shape[:-1] == self.shape and v.ndim >= 1 and v.shape[-1] == 3:
            # the common case: one vector per quaternion; validate in the same pass
            flat_q = np.ascontiguousarray(self._a.reshape(-1, 4))
            flat_v = np.ascontiguousarray(v.reshape(-1, 3))
            out = np.empty(flat_v.shape)
            if rotate_flat(flat_q, flat_v, out) < 0:
                return out.reshape(v.shape)
        v = check_trailing("vectors", as_float_array("vectors", vectors), 3)
        if not np.all(np.any(self._a != 0, axis=-1)):
            _raise_zero("self", _norm_last(self._a), "the zero quaternion is no rotation")
        return qrot_gufunc(self._a, v)

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
        p = Quaternion._wrap(self._unit_or_raise("the zero quaternion is no rotation"))
        q = Quaternion._wrap(other._unit_or_raise("the zero quaternion is no rotation"))
        d = (p.conj() * q)._a
        return 2.0 * np.arctan2(_norm_last(d[..., 1:]), np.abs(d[..., 0]))

    def allclose(self, other: Quaternion, *, rtol: float = 1e-13, atol: float = 0.0) -> bool:
        """Componentwise closeness (as quaternions, so q and -q differ)."""
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
        body = np.array2string(self._a, separator=", ", prefix="Quaternion(")
        return f"Quaternion({body})"


def slerp(q0: Quaternion, q1: Quaternion, t: Any) -> Quaternion:
    """Spherical linear interpolation q0 (q0^-1 q1)^t along the shorter arc.

    Parameters
    ----------
    q0, q1 : Quaternion
        End rotations (normalised internally); shapes broadcast.
    t : array_like
        Interpolation parameter(s); 0 gives q0, 1 gives q1 (up to sign).

    Examples
    --------
    >>> q0 = Quaternion.from_array([1.0, 0, 0, 0])
    >>> q1 = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2)
    >>> float(slerp(q0, q1, 0.5).as_axis_angle()[1] / np.pi)
    0.25
    """
    if not isinstance(q0, Quaternion) or not isinstance(q1, Quaternion):
        raise ValueError("Expected `q0` and `q1` to be Quaternion instances")
    p = q0.unit()
    d = (p.conj() * q1.unit()).canonical()
    return p * (d**t)
