"""Quaternions as rotations, to and from the rotation's other forms: a
:class:`~hamilton_orbits.quaternion.Quaternion` from an axis and angle, a rotation
matrix, Cayley's Rodrigues parameters (the Gibbs vector) or modified Rodrigues
parameters, and back; and the rotation of vectors (``rotate``).

:class:`RotationForms` holds these methods; ``Quaternion`` inherits them.  A
nonzero quaternion used as a rotation acts as its versor (the scale cancels); the
zero quaternion is no rotation and raises (the policy of
:mod:`hamilton_orbits.quaternion`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from hamilton_orbits._lazy import LazyModule
from hamilton_orbits._quaternion_arrays import (
    SAFE_HI,
    dimensionless,
    finite_or_raise,
    norm_last,
    raise_zero,
    scale_exactly,
    unit_last,
    with_unit,
)
from hamilton_orbits.units import ANGLE, is_quantity
from hamilton_orbits.validation import (
    as_flag,
    as_float_array,
    broadcast_shapes,
    check_trailing,
    first_index,
)

if TYPE_CHECKING:  # pragma: no cover
    from hamilton_orbits.quaternion import Quaternion

# numba is imported on first use (hamilton_orbits._lazy)
_kq = LazyModule("hamilton_orbits._kernels.quaternion", globals(), "_kq")

__all__ = ["RotationForms"]


class RotationForms:
    """A quaternion's rotation and its other forms (axis and angle, matrix, Gibbs
    vector, modified Rodrigues parameters), both ways: the part of
    :class:`~hamilton_orbits.quaternion.Quaternion` that reads its components
    ``_a`` (..., 4) as a rotation."""

    __slots__ = ()

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
        >>> from hamilton_orbits import Quaternion
        >>> q = Quaternion.from_axis_angle([0, 0, 2.0], 90.0, degrees=True)
        >>> np.round(q.rotate([1.0, 0.0, 0.0]), 15) + 0.0
        array([0., 1., 0.])
        >>> import astropy.units as u
        >>> p = Quaternion.from_axis_angle([0, 0, 1], 90 * u.deg)
        >>> float(p.rotation_distance(q))
        0.0
        """
        degrees = as_flag("degrees", degrees)  # ("False" or 0.5 read 90 as degrees)
        if degrees and is_quantity(angle):
            raise ValueError(
                f"Expected `angle` to be a plain number with degrees=True, got the Quantity "
                f"{angle!r}: its unit already says how to read it (drop degrees=True)"
            )
        ax = dimensionless("axis", axis, 3)
        ang = ANGLE("angle", angle)
        if degrees:
            ang = np.deg2rad(ang)
        shape = broadcast_shapes(("axis", "angle"), ax.shape[:-1], ang.shape)
        unit_axis = unit_last("axis", ax, "a rotation axis must have nonzero length",
                              "vector")
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
        >>> from hamilton_orbits import Quaternion
        >>> q = Quaternion.from_rotation_matrix(np.diag([1.0, -1.0, -1.0]))
        >>> q.as_array() + 0.0
        array([0., 1., 0., 0.])
        """
        m = dimensionless("matrix", matrix)
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
        >>> from hamilton_orbits import Quaternion
        >>> float(Quaternion.from_gibbs([0.0, 0.0, 1.0]).as_axis_angle()[1] / np.pi)
        0.5
        """
        g = dimensionless("gibbs", gibbs, 3)
        a = np.empty(g.shape[:-1] + (4,))
        a[..., 0] = 1.0
        a[..., 1:] = g
        return cls._wrap(unit_last("gibbs", a, "unreachable"))

    @classmethod
    def from_mrp(cls, mrp: Any) -> Quaternion:
        """Unit quaternion from modified Rodrigues parameters sigma = tan(theta/4) axis.

        q = (1 - |sigma|^2, 2 sigma) / (1 + |sigma|^2).  For |sigma| > 1 the same
        formula is evaluated in r = 1/|sigma| and the unit direction,
        q = (r^2 - 1, 2 r sigma/|sigma|) / (r^2 + 1), which cannot overflow: a
        huge sigma is a turn by nearly 2 pi, q -> -1.

        Examples
        --------
        >>> from hamilton_orbits import Quaternion
        >>> q = Quaternion.from_mrp([0.0, 0.0, 1.0])   # a half-turn about z
        >>> q.as_array() + 0.0
        array([0., 0., 0., 1.])
        >>> Quaternion.from_mrp([1e200, 0.0, 0.0]).as_array()
        array([-1.e+000,  2.e-200,  0.e+000,  0.e+000])
        """
        s = dimensionless("mrp", mrp, 3)
        a = np.empty(s.shape[:-1] + (4,))
        if s.size == 0 or np.max(np.abs(s)) < SAFE_HI:  # |sigma|^2 cannot overflow
            s2 = np.sum(s * s, axis=-1)
            a[..., 0] = (1.0 - s2) / (1.0 + s2)
            a[..., 1:] = (2.0 / (1.0 + s2))[..., None] * s
            return cls._wrap(a)
        b, e, nb = scale_exactly(s)
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

    def _unit_or_raise(self, what: str) -> np.ndarray:
        return unit_last("self", self._a, what)

    def as_rotation_matrix(self) -> np.ndarray:
        """Rotation matrices (..., 3, 3) with ``R @ v == q.rotate(v)``.

        Any nonzero scale is divided out; the zero quaternion raises.

        Examples
        --------
        >>> from hamilton_orbits import Quaternion
        >>> q = Quaternion.from_axis_angle([1, 0, 0], np.pi / 2)
        >>> np.round(q.as_rotation_matrix(), 12) + 0.0
        array([[ 1.,  0.,  0.],
               [ 0.,  0., -1.],
               [ 0.,  1.,  0.]])
        """
        flat = np.ascontiguousarray(self._a.reshape(-1, 4))
        out = np.empty((flat.shape[0], 3, 3))
        if _kq.to_matrix_flat(flat, out) >= 0:
            raise_zero("self", norm_last(self._a), "the zero quaternion is no rotation")
        return out.reshape(self.shape + (3, 3))

    def as_axis_angle(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit axis (..., 3) and angle (...) in [0, pi] of the rotation.

        The angle is 2 atan2(|v|, |w|) (accurate at every angle, unlike acos).
        For the identity the axis is [1, 0, 0] by convention.

        Examples
        --------
        >>> from hamilton_orbits import Quaternion
        >>> axis, angle = Quaternion.from_axis_angle([0, 1, 0], -1.0).as_axis_angle()
        >>> axis + 0.0, float(angle)
        (array([ 0., -1.,  0.]), 1.0)
        """
        u = self.canonical()._unit_or_raise("the zero quaternion is no rotation")
        vn = norm_last(u[..., 1:])
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
        >>> from hamilton_orbits import Quaternion
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
        >>> from hamilton_orbits import Quaternion
        >>> s = Quaternion.from_axis_angle([1, 0, 0], 1.5 * np.pi).as_mrp()
        >>> np.round(s, 12) + 0.0       # -tan(pi/8) about x: the short way round
        array([-0.41421356,  0.        ,  0.        ])
        """
        u = self.canonical()._unit_or_raise("the zero quaternion is no rotation")
        return u[..., 1:] / (1.0 + u[..., 0])[..., None]

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
        >>> from hamilton_orbits import Quaternion
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
                return with_unit(out.reshape(v.shape), unit)
        broadcast_shapes(("self", "vectors"), self.shape, v.shape[:-1])
        as_float_array("vectors", v)
        if not np.all(np.any(self._a != 0, axis=-1)):
            raise_zero("self", norm_last(self._a), "the zero quaternion is no rotation")
        with np.errstate(over="ignore", invalid="ignore"):  # overflow: refused just below
            out = _kq.qrot_gufunc(self._a, v)
        finite_or_raise("vectors", out, "the rotated vector", lambda: np.broadcast_to(v, out.shape))
        return with_unit(out, unit)
