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

Where the parts live: the rotation forms (``from_axis_angle``,
``from_rotation_matrix``, ``from_gibbs``, ``from_mrp``, the ``as_*`` exporters and
``rotate``) in :mod:`hamilton_orbits._quaternion_rotations` (``Quaternion``
inherits them), the exact-scale array helpers in
:mod:`hamilton_orbits._quaternion_arrays`; here the algebra (S, V, T, U, products,
quotients, sums, ``exp``, ``log``, ``**``), the rotation distances, the container
protocol and :func:`slerp`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits._quaternion_arrays import (
    CONJ,
    NO_SCALE,
    SERIES,
    dimensionless,
    exp_components,
    finite_or_raise,
    norm_last,
    product,
    raise_zero,
    scale_exactly,
    unit_last,
)
from hamilton_orbits._quaternion_rotations import RotationForms
from hamilton_orbits.validation import as_float_array, broadcast_shapes, check_positive

__all__ = ["Quaternion", "slerp"]


def _check_quaternion(name: str, value: Any) -> Quaternion:
    if not isinstance(value, Quaternion):
        raise ValueError(f"Expected `{name}` to be a Quaternion, got {type(value).__name__}")
    return value


def _tolerance(name: str, value: Any) -> float:
    """A tolerance of :meth:`Quaternion.allclose`: one finite number >= 0."""
    arr = as_float_array(name, value)
    if arr.shape != ():
        raise ValueError(f"Expected `{name}` to be one number, got shape {arr.shape}")
    check_positive(name, arr, strict=False)
    return float(arr)


class Quaternion(RotationForms):
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
        a = dimensionless("array", array, 4)
        if not isinstance(array, list | tuple) and np.may_share_memory(a, np.asarray(array)):
            a = a.copy()  # (the caller's buffer, refilled, changed checked components: an
            # ndarray, array.array, memoryview, a pandas Series ...)
        self._a = a

    @classmethod
    def _wrap(cls, a: np.ndarray) -> Quaternion:
        """Wrap an already validated float array without copying or checking (one
        this module made or took as its own: the accessors give read-only views)."""
        obj = object.__new__(cls)
        obj._a = a
        return obj

    def _view(self, key: Any) -> np.ndarray:
        """A read-only view of the components ``key`` (the quaternion's own, checked
        once: written through, they would change it)."""
        out = self._a[key]
        out.flags.writeable = False
        return out

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
        v = dimensionless("vector", vector, 3)
        a = np.zeros(v.shape[:-1] + (4,))
        a[..., 1:] = v
        return cls._wrap(a)

    # ------------------------------------------------------------ exporters
    def as_array(self) -> np.ndarray:
        """The components ``[w, x, y, z]`` as an ndarray of shape (..., 4) (read-only:
        the quaternion's own; copy it to change it)."""
        return self._view(...)

    # ------------------------------------------------------------ Hamilton's S, V, T, U
    @property
    def scalar(self) -> np.ndarray:
        """Hamilton's S q: the scalar part w, shape (...)."""
        return self._view((..., 0))

    @property
    def vector(self) -> np.ndarray:
        """Hamilton's V q: the vector part (x, y, z), shape (..., 3)."""
        return self._view((..., slice(1, None)))

    @property
    def w(self) -> np.ndarray:
        """Scalar component."""
        return self._view((..., 0))

    @property
    def x(self) -> np.ndarray:
        """i component."""
        return self._view((..., 1))

    @property
    def y(self) -> np.ndarray:
        """j component."""
        return self._view((..., 2))

    @property
    def z(self) -> np.ndarray:
        """k component."""
        return self._view((..., 3))

    def norm(self) -> np.ndarray:
        """Hamilton's tensor ``T q = |q| = sqrt(w^2 + x^2 + y^2 + z^2)``, without overflow.

        Examples
        --------
        >>> float(Quaternion.from_array([1e300, 1e300, 1e300, 1e300]).norm())
        2e+300
        """
        norm = norm_last(self._a)[..., None]
        return finite_or_raise("self", norm, "the norm", lambda: self._a)[..., 0]

    def unit(self) -> Quaternion:
        """Hamilton's versor ``U q = q / |q|``; the zero quaternion raises.

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
        """Reciprocal ``q^-1 = K q / |q|^2``; the zero quaternion raises.

        Examples
        --------
        >>> q = Quaternion.from_array([1.0, 2.0, 3.0, 4.0])
        >>> np.round((q * q.inverse()).as_array(), 15) + 0.0
        array([1., 0., 0., 0.])
        """
        return Quaternion._wrap(
            finite_or_raise("self", self._inverse_array(), "the inverse", lambda: self._a)
        )

    def _inverse_array(self) -> np.ndarray:
        """K q / |q|^2 from the exactly scaled q = b 2^e: K b / |b|^2 2^-e (may be inf)."""
        b, e, nb = scale_exactly(self._a)
        raise_zero("self", nb, "it has no inverse")
        inv = (b * CONJ) / (nb * nb)[..., None]
        if e is NO_SCALE:
            return inv
        with np.errstate(over="ignore"):
            return np.ldexp(inv, -e[..., None])

    def _real(self, other: Any) -> np.ndarray:
        """A real operand as a float array broadcastable against the leading shape."""
        s = dimensionless("other", other)
        if s.ndim:
            broadcast_shapes(("self", "other"), self.shape, s.shape)
        return s

    def __mul__(self, other: Any) -> Quaternion:
        if isinstance(other, Quaternion):
            if self._a.shape != other._a.shape:
                broadcast_shapes(("self", "other"), self.shape, other.shape)
            out, finite = product(self._a, other._a)
            if finite:
                return Quaternion._wrap(out)
            value = lambda: np.broadcast_to(other._a, out.shape)  # noqa: E731
        else:
            s = self._real(other)
            with np.errstate(over="ignore"):
                out = self._a * s[..., None]
            value = lambda: np.broadcast_to(s, out.shape[:-1])  # noqa: E731
        return Quaternion._wrap(finite_or_raise("other", out, "the product", value))

    def __rmul__(self, other: Any) -> Quaternion:
        return self * other  # a real factor commutes with every quaternion

    def __truediv__(self, other: Any) -> Quaternion:
        if isinstance(other, Quaternion):
            broadcast_shapes(("self", "other"), self.shape, other.shape)
            b, e, nb = scale_exactly(other._a)
            raise_zero("other", nb, "division by the zero quaternion")
            inv_scaled = (b * CONJ) / (nb * nb)[..., None]  # (other / 2^e)^-1
            a, ea, _ = scale_exactly(self._a)  # (both scaled: 1.7e308 / 1e300 is 1.7e8)
            with np.errstate(over="ignore"):
                out = product(a, inv_scaled)[0]
                if e is not NO_SCALE or ea is not NO_SCALE:
                    out = np.ldexp(out, np.broadcast_to(ea - e, out.shape[:-1])[..., None])
            value = lambda: np.broadcast_to(other._a, out.shape)  # noqa: E731
        else:
            s = self._real(other)
            raise_zero("other", np.abs(s), "division by zero")
            with np.errstate(over="ignore"):
                out = self._a / s[..., None]
            value = lambda: np.broadcast_to(s, out.shape[:-1])  # noqa: E731
        return Quaternion._wrap(finite_or_raise("other", out, "the quotient", value))

    def __rtruediv__(self, other: Any) -> Quaternion:
        s = self._real(other)
        b, e, nb = scale_exactly(self._a)  # (s times the scaled inverse, then its scale:
        raise_zero("self", nb, "it has no inverse")  # 1e-10 / 1e-310 is 1e300, 0 / it 0)
        with np.errstate(over="ignore", invalid="ignore"):
            out = s[..., None] * ((b * CONJ) / (nb * nb)[..., None])
            if e is not NO_SCALE:
                out = np.ldexp(out, np.broadcast_to(-e, out.shape[:-1])[..., None])
        value = lambda: np.broadcast_to(self._a, out.shape)  # noqa: E731
        return Quaternion._wrap(finite_or_raise("self", out, "the quotient", value))

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
        return Quaternion._wrap(finite_or_raise("other", out, what, value))

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
        """Exponential: ``exp(w) (cos|v|, sin|v| v/|v|)``, exact to rounding for tiny ``|v|``.

        Raises
        ------
        ValueError
            Where the exponential is too large for a float (w above about
            709.78, e.g. ``Quaternion([1e3, 0, 0, 0]).exp()``: e^1000 is not
            representable), naming ``self``, the index and the quaternion.
            Components that are representable although exp(w) alone is not
            (``exp(710) cos|v|`` with a small cosine) are computed.

        Examples
        --------
        >>> q = Quaternion.from_vector([0.0, 0.0, 1e-300]).exp()
        >>> q.as_array()
        array([1.e+000, 0.e+000, 0.e+000, 1.e-300])
        """
        return Quaternion._wrap(exp_components(self._a, "self", lambda: self._a))

    def log(self) -> Quaternion:
        """Principal logarithm ``(log|q|, atan2(|v|, w) v/|v|)``; the zero quaternion raises.

        Accurate at angles down to 1e-300 (series for atan(t)/t) and near pi
        (atan2 is well conditioned there).  For a negative real q the direction
        is undefined and the i axis is used by convention: log(-1) = pi i.

        Examples
        --------
        >>> q = Quaternion.from_axis_angle([0, 0, 1], 1e-300)
        >>> q.log().as_array()
        array([0.e+000, 0.e+000, 0.e+000, 5.e-301])
        """
        b, e, nb = scale_exactly(self._a)  # q = b 2^e exactly: everything below is scale-free
        raise_zero("self", nb, "its logarithm is undefined")
        w = self._a[..., 0]
        v = self._a[..., 1:]
        wb = b[..., 0]
        # |v| 2^-e; squares negligible next to wb^2 may underflow, which only
        # touches terms below the rounding of atan2(vb, wb) or of the series
        vb = np.sqrt(np.sum(b[..., 1:] ** 2, axis=-1))
        # the unit direction of v from v scaled by its own power of two (exact
        # even for subnormal v); zero where v = 0
        uv, _, nv = scale_exactly(v)
        has_v = nv > 0
        direction = uv / np.where(has_v, nv, 1.0)[..., None]
        # atan2(|v|, w)/|v|: for |v| << w use the series of atan(x)/x, x = |v|/w,
        # applied to v/w of the original components (no scaling round-off).
        small = (vb <= SERIES * wb) & (wb > 0)
        w_s = np.where(small, w, 1.0)
        x2 = (np.where(small, vb, 0.0) / np.where(small, wb, 1.0)) ** 2
        a = np.empty(self._a.shape)
        a[..., 1:] = np.where(
            small[..., None],
            (1.0 - x2 / 3.0)[..., None] * (v / w_s[..., None]),
            np.arctan2(vb, wb)[..., None] * direction,
        )
        # log|q| = log(|b| 2^e), or log|b| + e log 2 where 2^e is beyond the floats
        if e is NO_SCALE:
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
        t = dimensionless("t", t)
        shape = broadcast_shapes(("self", "t"), self.shape, t.shape)
        lg = self.log()._a
        def tb() -> np.ndarray:
            return np.broadcast_to(t, shape)

        with np.errstate(over="ignore", invalid="ignore"):
            p = lg * t[..., None]
        finite_or_raise("t", p, "t log q", tb)
        return Quaternion._wrap(exp_components(p, "t", tb))

    # ------------------------------------------------------------ rotations
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

        q and -q are at distance 0.  Computed as ``2 atan2(|V d|, |S d|)`` of
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
        q = Quaternion._wrap(unit_last("other", other._a, "the zero quaternion is no rotation"))
        d = (p.conj() * q)._a
        return 2.0 * np.arctan2(norm_last(d[..., 1:]), np.abs(d[..., 0]))

    def allclose(self, other: Quaternion, *, rtol: float = 1e-13, atol: float = 0.0) -> bool:
        """Componentwise closeness (as quaternions, so q and -q differ)."""
        other = _check_quaternion("other", other)
        broadcast_shapes(("self", "other"), self.shape, other.shape)
        rtol, atol = _tolerance("rtol", rtol), _tolerance("atol", atol)
        return bool(np.allclose(self._a, other._a, rtol=rtol, atol=atol))

    def rotation_allclose(self, other: Quaternion, *, atol: float = 1e-13) -> bool:
        """True if every pair of rotations is within ``atol`` radians (q ~ -q)."""
        atol = _tolerance("atol", atol)
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
        if sum(k is not None for k in key) > self.ndim:  # (None, a new axis, takes none)
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
        if self._a.shape != other._a.shape:  # (numpy's message names no operand)
            broadcast_shapes(("self", "other"), self.shape, other.shape)
        return np.all(self._a == other._a, axis=-1)

    def __ne__(self, other: object) -> Any:  # (not ``not ==``: a batch has no one truth)
        if not isinstance(other, Quaternion):
            return NotImplemented
        if self._a.shape != other._a.shape:
            broadcast_shapes(("self", "other"), self.shape, other.shape)
        return np.any(self._a != other._a, axis=-1)

    def __bool__(self) -> bool:
        raise TypeError("The truth value of a Quaternion is ambiguous: compare it (==, "
                        "allclose) or its norm")

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
    t = dimensionless("t", t)
    broadcast_shapes(("q0", "q1", "t"), q0.shape, q1.shape, t.shape)
    p = Quaternion._wrap(unit_last("q0", q0._a, "the zero quaternion is no rotation"))
    p1 = Quaternion._wrap(unit_last("q1", q1._a, "the zero quaternion is no rotation"))
    d = (p.conj() * p1).canonical()
    # d^t of the unit d as exp(t (0, angle axis)): its log|d| of an ulp or so, times a
    # large t, shrank the result (|slerp| 0.33 at t = 1e16, 0 at 1e20)
    lg = d.log().as_array().copy()
    lg[..., 0] = 0.0
    shape = broadcast_shapes(("q0", "q1", "t"), lg.shape[:-1], t.shape)
    with np.errstate(over="ignore", invalid="ignore"):
        turn = lg * t[..., None]
    finite_or_raise("t", turn, "t times the angle", lambda: np.broadcast_to(t, shape))
    return p * Quaternion._wrap(exp_components(turn, "t", lambda: np.broadcast_to(t, shape)))
