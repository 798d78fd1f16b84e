"""RigidBody: principal moments, attitude (a Quaternion) and body angular velocity.

Conventions (shared by the whole ``rigid`` package):

* The body frame is the principal-axis frame.  ``attitude`` is a unit
  :class:`hamilton_orbits.Quaternion` ``q`` that carries body-frame vectors to
  space, ``v_space = q.rotate(v_body) = q v q^-1``.
* ``omega = (p, q, r)`` is the angular velocity in the body frame (Cayley's
  letters; the ``q`` clashes with the quaternion only in name).  The kinematics
  is ``dq/dt = q * (0, omega) / 2``.
* ``moments = (A, B, C)`` in the order of the body axes; Euler's equations read
  ``A p' + (C - B) q r = N_x`` and cyclically (Cayley 1843).

Units: a body built from Quantities (kg m^2 for the inertia, rad/s for omega, any
units of those dimensions) answers in Quantities: ``moments``, ``omega`` and every
derived quantity, and the functions that take it (``free_motion``, ``integrate``,
``poinsot``, Sylvester's functions) answer in Quantities too, and refuse plain
numbers for its times and rates.  A body built from plain floats is SI (kg m^2,
rad/s, s) and answers in floats; given Quantity times it answers in Quantities.
Inside, everything runs on SI floats.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import (
    ANGULAR_SPEED,
    DIMENSIONLESS,
    INERTIA,
    require_consistent,
    time_quantity,
)
from hamilton_orbits.validation import as_float_array, first_index, fmt_index
from rigid._shared import pow2

__all__ = ["BodySI", "RigidBody"]  # check_*, call_units, unit_quaternion: shared inside rigid

_EPS = np.finfo(np.float64).eps
_I_UNIT = u.kg * u.m**2  # moment of inertia
_W_UNIT = u.rad / u.s  # angular velocity
_L_UNIT = u.kg * u.m**2 / u.s  # angular momentum
# Slack for the symmetry and the triangle-inequality checks: a tensor built by
# rotating a diagonal one in floating point is symmetric / flat only to a few
# ulp of its largest entry, and a flat disk (C = A + B, Sylvester's limit case)
# must pass.  64 ulp of the largest moment is far below any physical tolerance.
_SLACK = 64.0 * _EPS
# Smallest ratio of two moments: the free-motion kernel squares the ratios of the
# moments and of the rates, so below ~1e-150 they would underflow.  (A body with
# A / C < 1e-150 is a line, not a rigid body one can build.)
_MIN_RATIO = 1e-150


def check_moments(name: str, moments: np.ndarray) -> np.ndarray:
    """Require principal moments: shape (3,), each > 0, and the triangle inequality.

    ``A + B >= C`` for every permutation, Sylvester (1866): "each must be not
    greater than the sum of the other two" (with a slack of 64 ulp of the sum, so
    that a flat disk ``C = A + B`` built in floating point passes).

    Raises
    ------
    ValueError
        Naming the argument, the index and the value.

    Examples
    --------
    >>> check_moments("moments", np.array([-1.0, 2.0, 3.0]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `moments` > 0, got -1.0 at index 0
    """
    if moments.shape != (3,):
        raise ValueError(f"Expected `{name}` to have shape (3,), got {moments.shape}")
    bad = ~(moments > 0.0)
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(f"Expected `{name}` > 0, got {float(moments[k])!r} at index {k}")
    check_triangle(name, moments)
    big = float(np.max(moments))
    k = int(np.argmin(moments))
    if moments[k] / big < _MIN_RATIO:
        raise ValueError(
            f"Expected `{name}` within a ratio of {1 / _MIN_RATIO:.0e} of each other, got "
            f"{float(moments[k])!r} at index {k} beside {big!r}"
        )
    return moments


def check_triangle(name: str, moments: np.ndarray) -> np.ndarray:
    """Require positive principal moments ``(..., 3)`` to satisfy ``A + B >= C`` for
    every permutation (Sylvester 1866, as :func:`check_moments`, with its slack),
    naming the argument, the index and the value.

    Examples
    --------
    >>> check_triangle("moments", np.array([[1.0, 2.0, 3.0], [1.0, 1.0, 3.0]]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `moments` to satisfy A + B >= C, got 3.0 at index (1, 2) > 2.0
    """
    # compared on moments / max, so that the sum cannot overflow
    scaled = moments / np.max(moments, axis=-1, keepdims=True)
    total = np.sum(scaled, axis=-1, keepdims=True)
    bad = scaled > (total - scaled) + _SLACK * total
    if np.any(bad):
        index = first_index(bad)
        raise ValueError(
            f"Expected `{name}` to satisfy A + B >= C, got {float(moments[index])!r}"
            f"{fmt_index(index)} > {_sum_others(moments[index[:-1]], index[-1])!r}"
        )
    return moments


def _sum_others(moments: np.ndarray, k: int) -> float:
    with np.errstate(over="ignore"):
        return float(moments[(k + 1) % 3]) + float(moments[(k + 2) % 3])


def _principal(name: str, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """Return ``(moments, axes)``; ``axes`` is None for a (3,) input.

    ``axes`` (3, 3) is a proper rotation whose columns are the principal
    directions expressed in the frame the tensor was given in.
    """
    if inertia.shape == (3,):
        moments = inertia.copy()
        axes = None
    elif inertia.shape == (3, 3):
        scale = float(np.max(np.abs(inertia)))
        if scale == 0.0:
            raise ValueError(f"Expected `{name}` to be positive definite, got a zero tensor")
        asym = np.abs(inertia - inertia.T) / scale
        if np.any(asym > _SLACK):
            i, j = (int(k) for k in np.argwhere(asym > _SLACK)[0])
            raise ValueError(
                f"Expected `{name}` to be a symmetric (3, 3) tensor, got "
                f"{name}[{i}, {j}] = {inertia[i, j]!r} != {name}[{j}, {i}] = {inertia[j, i]!r}"
            )
        # eigh on the tensor / scale: homogeneous, and safe from over- and underflow
        sym = 0.5 * (inertia + inertia.T) / scale
        moments, axes = np.linalg.eigh(sym)
        moments = moments * scale
        if np.linalg.det(axes) < 0.0:
            axes[:, 2] = -axes[:, 2]
        if not np.all(moments > 0.0):
            k = int(np.argmin(moments))
            raise ValueError(
                f"Expected `{name}` to be positive definite, got eigenvalue "
                f"{float(moments[k])!r} at index {k}"
            )
    else:
        raise ValueError(f"Expected `{name}` to have shape (3,) or (3, 3), got {inertia.shape}")
    return check_moments(name, moments), axes


def unit_quaternion(name: str, attitude: Any) -> np.ndarray:
    """A unit quaternion (4,) from a Quaternion or a dimensionless array_like.

    The norm is taken of ``q / max|q_i|`` so that neither ``[1e300, 1e300, 0, 0]``
    overflows nor ``[1e-300, 0, 0, 0]`` underflows.

    Raises
    ------
    ValueError
        For a wrong shape, NaN / inf or a zero quaternion, naming the argument.
    astropy.units.UnitConversionError
        For a Quantity that is not dimensionless.

    Examples
    --------
    >>> unit_quaternion("attitude", [1e300, 1e300, 0.0, 0.0])
    array([0.70710678, 0.70710678, 0.        , 0.        ])
    """
    if attitude is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    if isinstance(attitude, Quaternion):
        arr = as_float_array(name, attitude.as_array())
    else:
        arr = DIMENSIONLESS(name, attitude)
    if arr.shape != (4,):
        raise ValueError(f"Expected `{name}` to have shape (4,), got {arr.shape}")
    big = float(np.max(np.abs(arr)))
    if big == 0.0:
        raise ValueError(f"Expected `{name}` to be a nonzero quaternion, got {arr.tolist()}")
    arr = arr / big
    return arr / np.sqrt(np.sum(arr * arr))


def call_units(body: RigidBody, names: tuple[str, ...], values: tuple[Any, ...]) -> bool:
    """Whether a call on ``body`` with dimensional ``values`` answers in Quantities.

    The values must not mix Quantities and plain numbers
    (:func:`hamilton_orbits.units.require_consistent`); a body built from
    Quantities needs Quantities (a plain time beside it has no unit); a body of
    plain floats is SI and accepts either.  ``None`` values are ignored; an astropy
    ``TimeDelta`` counts as the Quantity in days it holds
    (:func:`hamilton_orbits.units.time_quantity`), as the time kind converts it.

    Examples
    --------
    >>> import astropy.units as u
    >>> call_units(RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2), ("t",), (2.0,))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `t` to be a Quantity like `body` ([1. 2. 3.] m2 kg), got the plain ...
    """
    values = tuple(time_quantity(v) for v in values)
    quantity = require_consistent(names, values)
    if body._quantity:
        require_consistent(("body", *names), (body.moments, *values))
        return True
    return quantity


def _finite_result(what: str, scaled: Any, scale: tuple[float, ...], si: BodySI) -> Any:
    """``scaled`` times each factor of ``scale``, or a ValueError beyond float64."""
    out = np.asarray(scaled)
    with np.errstate(over="ignore"):
        for factor in scale:
            out = out * factor
    if not np.all(np.isfinite(out)):
        raise ValueError(
            f"Expected `omega` and `inertia` with a representable {what}, got moments "
            f"{si.moments.tolist()} and omega {si.omega.tolist()} (beyond float64)"
        )
    return out


class BodySI(NamedTuple):
    """A rigid body's state as SI floats: the documented float view :attr:`RigidBody.si`.

    For code on plain floats (kernels, integrators, Sylvester's relations): the
    same state as the :class:`RigidBody` it came from, whether that answers in
    Quantities or not.  The arrays are copies.

    Attributes
    ----------
    moments : ndarray, shape (3,), kg m^2
        Principal moments ``(A, B, C)``.
    attitude : ndarray, shape (4,)
        Unit attitude quaternion, scalar first, body to space.
    omega : ndarray, shape (3,), rad/s
        Body-frame angular velocity ``(p, q, r)``.

    Notes
    -----
    The derived quantities are computed on ``moments / sm`` and ``omega / sw``
    (``sm, sw`` exact powers of two, :meth:`scales`) and scaled back, so nothing
    under- or overflows inside; a result beyond float64 raises ``ValueError``.

    Examples
    --------
    >>> import astropy.units as u
    >>> si = RigidBody([1.0, 2.0, 3.0] * u.g * u.m**2, omega=[0.0, 0.0, 2.0] * u.rad / u.s).si
    >>> print(si.moments, si.omega, si.attitude)
    [0.001 0.002 0.003] [0. 0. 2.] [1. 0. 0. 0.]
    >>> print(si.kinetic_energy, si.angular_momentum_body, si.angular_momentum_norm)
    0.006 [0.    0.    0.006] 0.006
    """

    moments: np.ndarray
    attitude: np.ndarray
    omega: np.ndarray

    def scales(self) -> tuple[float, float]:
        """``(sm, sw)``: the powers of two at or below ``max moments`` and ``max|omega|``
        (1 for zero omega), exact scales for homogeneous computations."""
        return pow2(self.moments), pow2(self.omega)

    @property
    def angular_momentum_body(self) -> np.ndarray:
        """``L = (A p, B q, C r)`` in the body frame, shape (3,), kg m^2/s."""
        sm, sw = self.scales()
        return _finite_result("angular momentum", (self.moments / sm) * (self.omega / sw),
                              (sm, sw), self)

    @property
    def angular_momentum_space(self) -> np.ndarray:
        """``q L q^-1``, Cayley's ``(g, g', g'')``, shape (3,), kg m^2/s."""
        sm, sw = self.scales()
        lb = (self.moments / sm) * (self.omega / sw)
        big = pow2(lb)
        ls = np.asarray(Quaternion(self.attitude).rotate(lb / big), dtype=np.float64)
        return _finite_result("angular momentum", ls, (big, sm, sw), self)

    @property
    def kinetic_energy(self) -> float:
        """``T = (A p^2 + B q^2 + C r^2) / 2``, J."""
        sm, sw = self.scales()
        w = self.omega / sw
        half = 0.5 * np.sum((self.moments / sm) * w * w)
        return float(_finite_result("kinetic energy", half, (sm, sw, sw), self))

    @property
    def angular_momentum_norm(self) -> float:
        """``|L|``, kg m^2/s."""
        sm, sw = self.scales()
        lb = (self.moments / sm) * (self.omega / sw)
        return float(_finite_result("angular momentum", np.sqrt(np.sum(lb * lb)), (sm, sw),
                                    self))


def check_body(body: Any, name: str = "body") -> RigidBody:
    """Require a :class:`RigidBody` (``ValueError`` naming the argument otherwise).

    Examples
    --------
    >>> check_body(None)
    Traceback (most recent call last):
    ...
    ValueError: Expected `body` to be a RigidBody, got None
    """
    if not isinstance(body, RigidBody):
        got = "None" if body is None else f"{type(body).__name__} {body!r}"
        raise ValueError(f"Expected `{name}` to be a RigidBody, got {got[:80]}")
    return body


class RigidBody:
    """A rigid body: principal moments, attitude quaternion, body angular velocity.

    Parameters
    ----------
    inertia : array_like or Quantity, shape (3,) or (3, 3), kg m^2
        Principal moments ``(A, B, C)`` in the order of the body axes, or a full
        symmetric inertia tensor in some body-fixed frame.  A tensor is
        diagonalised with :func:`numpy.linalg.eigh` (moments ascending) and the
        given ``attitude`` and ``omega`` are re-expressed in the principal frame
        (the principal frame is right-handed).
    attitude : Quaternion or array_like, shape (4,), optional
        Scalar-first quaternion carrying body-frame vectors to space
        (``v_space = q v_body q^-1``).  Normalised on input (any nonzero finite
        size).  Dimensionless.  Default identity.
    omega : array_like or Quantity, shape (3,), rad/s, optional
        Angular velocity ``(p, q, r)`` in the body frame in which ``inertia`` was
        given.  Default zero.  A Quantity exactly when ``inertia`` is one.

    Attributes
    ----------
    moments : ndarray or Quantity, shape (3,), kg m^2
        Principal moments: a Quantity (kg m^2) for a body built from
        Quantities, else plain floats (SI).
    attitude : Quaternion
        Unit attitude quaternion, body (principal) frame to space.
    omega : ndarray or Quantity, shape (3,), rad/s
        Angular velocity in the principal frame (rad/s as a Quantity for a body
        built from Quantities).
    si : BodySI
        The same state as SI floats (moments, attitude array, omega and the
        derived integrals), for code on plain floats.
    quantity : bool
        Whether the body answers in Quantities.

    Raises
    ------
    ValueError
        For a wrong shape, NaN or inf, a non-symmetric or non-positive-definite
        tensor, a non-positive moment, a violation of the triangle inequality
        (``A + B >= C`` for every permutation, Sylvester 1866: "each must be not
        greater than the sum of the other two"), a zero quaternion, or a plain
        ``omega`` beside a Quantity ``inertia`` (or the reverse).
    astropy.units.UnitConversionError
        For a Quantity of the wrong dimension (an attitude in metres, ...).

    References
    ----------
    A. Cayley, "On the motion of rotation of a solid body", Camb. Math. J. 3
    (1843) 224-232.  J. J. Sylvester, "On the motion of a rigid body acted on by
    no external forces", Phil. Trans. R. Soc. 156 (1866) 757-779.

    Examples
    --------
    >>> import astropy.units as u
    >>> body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.1, 0.0, 1.0] * u.rad / u.s)
    >>> print(body)
    RigidBody: moments [1. 2. 3.] m2 kg, omega [0.1 0.  1. ] rad / s, attitude [1. 0. 0. 0.]
    >>> print(round(body.kinetic_energy, 4))
    1.505 J
    >>> print(body.angular_momentum_space.round(3))
    [0.1 0.  3. ] m2 kg / s
    >>> print(RigidBody([1.0, 2.0, 3.0], omega=[0.1, 0.0, 1.0]).kinetic_energy)  # floats
    1.505
    >>> RigidBody([1.0, 1.0, 3.0])
    Traceback (most recent call last):
    ...
    ValueError: Expected `inertia` to satisfy A + B >= C, got 3.0 at index 2 > 2.0
    """

    __slots__ = ("_moments", "_omega", "_quantity", "attitude")

    def __init__(self, inertia: Any, attitude: Any = None, omega: Any = None) -> None:
        self._build(inertia, attitude, omega)

    def _build(self, inertia: Any, attitude: Any, omega: Any, name: str = "inertia") -> None:
        """Set the body up (``name``: what the caller calls ``inertia``)."""
        quantity = require_consistent((name, "omega"), (inertia, omega))
        inertia_arr = INERTIA(name, inertia)
        omega_arr = np.zeros(3) if omega is None else ANGULAR_SPEED("omega", omega)
        if omega_arr.shape != (3,):
            raise ValueError(f"Expected `omega` to have shape (3,), got {omega_arr.shape}")
        q = unit_quaternion("attitude", attitude)
        moments, axes = _principal(name, inertia_arr)
        if axes is not None:
            # v_given = axes @ v_principal, so omega_principal = axes^T omega_given and
            # the new attitude composes q (given -> space) with axes (principal -> given).
            omega_arr = axes.T @ omega_arr
            qa = Quaternion.from_rotation_matrix(axes).as_array()
            q = unit_quaternion("attitude", (Quaternion(q) * Quaternion(qa)).as_array())
        self._moments: np.ndarray = np.asarray(moments, dtype=np.float64)
        self._omega: np.ndarray = np.asarray(omega_arr, dtype=np.float64).copy()
        self.attitude: Quaternion = Quaternion(q)
        self._quantity: bool = bool(quantity)

    @classmethod
    def from_si(
        cls, moments: Any, attitude: Any = None, omega: Any = None, *, quantity: bool = False
    ) -> RigidBody:
        """A body from SI floats, validated like the constructor.

        Parameters
        ----------
        moments : array_like, shape (3,) or (3, 3), kg m^2
            Plain floats (principal moments or a tensor, as for :class:`RigidBody`).
        attitude : Quaternion or array_like, shape (4,), optional
        omega : array_like, shape (3,), rad/s, optional
            Plain floats.
        quantity : bool, optional
            Whether the new body answers in Quantities (kg m^2, rad/s, ...), as a
            body built from Quantities does.  Default False.

        Examples
        --------
        >>> RigidBody.from_si([1.0, 2.0, 3.0], omega=[0.0, 0.0, 2.0], quantity=True).omega
        <Quantity [0., 0., 2.] rad / s>
        """
        if not isinstance(quantity, bool | np.bool_):  # (any text would be true)
            raise ValueError(f"Expected `quantity` to be True or False, got {quantity!r}")
        body = cls.__new__(cls)
        body._build(moments, attitude, omega, name="moments")
        body._quantity = bool(quantity)
        return body

    @property
    def quantity(self) -> bool:
        """Whether the body answers in Quantities (it was built from Quantities, or by
        :meth:`from_si` with ``quantity=True``)."""
        return self._quantity

    @property
    def si(self) -> BodySI:
        """The state as SI floats (:class:`BodySI`: ``moments``, ``attitude``, ``omega``
        and the derived integrals), whatever the body answers in.

        Examples
        --------
        >>> import astropy.units as u
        >>> RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2).si.moments
        array([1., 2., 3.])
        """
        return BodySI(self._moments.copy(), self.attitude.as_array().astype(np.float64),
                      self._omega.copy())

    @property
    def moments(self) -> Any:
        """Principal moments ``(A, B, C)``, shape (3,) (kg m^2 as a Quantity for a body
        built from Quantities)."""
        return self._out(self._moments.copy(), _I_UNIT)

    @property
    def omega(self) -> Any:
        """Body-frame angular velocity ``(p, q, r)``, shape (3,) (rad/s as a Quantity
        for a body built from Quantities)."""
        return self._out(self._omega.copy(), _W_UNIT)

    def __repr__(self) -> str:
        q = self.attitude.as_array().tolist()
        if self._quantity:
            return (
                f"RigidBody({self._moments.tolist()} * u.Unit('{_I_UNIT}'), attitude={q}, "
                f"omega={self._omega.tolist()} * u.Unit('{_W_UNIT}'))"
            )
        return f"RigidBody({self._moments.tolist()}, attitude={q}, omega={self._omega.tolist()})"

    def __str__(self) -> str:
        with np.printoptions(precision=6, suppress=False):
            m, w = np.array2string(self._moments), np.array2string(self._omega)
            q = np.array2string(self.attitude.as_array())
        if self._quantity:
            return f"RigidBody: moments {m} {_I_UNIT}, omega {w} {_W_UNIT}, attitude {q}"
        return (
            f"RigidBody: moments {m}, omega {w} (plain floats, SI: {_I_UNIT}, {_W_UNIT}), "
            f"attitude {q}"
        )

    def with_state(self, attitude: Any = None, omega: Any = None) -> RigidBody:
        """A body with the same moments and a new attitude and/or omega.

        Parameters
        ----------
        attitude : Quaternion or array_like, shape (4,), optional
            The new attitude (dimensionless; default the body's).
        omega : array_like or Quantity, shape (3,), optional
            The new angular velocity in the body frame (default the body's): a
            Quantity (any angular speed) exactly when the body was built from
            Quantities, plain numbers (rad/s, SI) exactly when it was not.

        Raises
        ------
        ValueError
            For a plain ``omega`` for a body of Quantities, or a Quantity for a body
            of plain numbers (its unit is the body's: no other is guessed), and
            for the checks of :class:`RigidBody` (naming the argument, index and
            value).

        Examples
        --------
        >>> b = RigidBody([1.0, 2.0, 3.0]).with_state(omega=[0.0, 0.0, 2.0])
        >>> print(b.omega)
        [0. 0. 2.]
        """
        if omega is None:
            w = self._omega
        else:
            if isinstance(omega, u.Quantity) != self._quantity:
                kind = "a Quantity" if self._quantity else "plain floats"
                raise ValueError(
                    f"Expected `omega` as {kind} like the body's moments, got {omega!r}"
                )
            w = ANGULAR_SPEED("omega", omega)
        return RigidBody.from_si(
            self._moments, self.attitude if attitude is None else attitude, w,
            quantity=self._quantity,
        )

    # ------------------------------------------------------------ derived
    # Computed by the float view (BodySI): on moments / sm and omega / sw (exact
    # powers of two) and scaled back, so that nothing under- or overflows inside;
    # a result beyond float64 raises.
    def _out(self, value, unit: u.UnitBase):
        return u.Quantity(value, unit) if self._quantity else value

    @property
    def angular_momentum_body(self) -> np.ndarray:
        """Angular momentum ``(A p, B q, C r)`` in the body frame, shape (3,)
        (kg m^2/s as a Quantity if the body was built from Quantities)."""
        return self._out(self.si.angular_momentum_body, _L_UNIT)

    @property
    def angular_momentum_space(self) -> np.ndarray:
        """Angular momentum in space, ``q (A p, B q, C r) q^-1``, shape (3,).

        Constant in torque-free motion; equal to Cayley's ``(g, g', g'')``.
        """
        return self._out(self.si.angular_momentum_space, _L_UNIT)

    @property
    def cayley_g(self) -> np.ndarray:
        """Cayley's integrals ``(g, g', g'')`` (Cayley 1843, the free-body integrals).

        ``kappa g = A p (1 + lambda^2 - mu^2 - nu^2) + 2 B q (lambda mu - nu)
        + 2 C r (nu lambda + mu)`` and cyclically, with Cayley's
        ``(lambda, mu, nu)`` = the Gibbs vector of ``attitude`` and
        ``kappa = 1 + lambda^2 + mu^2 + nu^2``.  These are the components of the
        angular momentum in space; ``g^2 + g'^2 + g''^2 = A^2 p^2 + B^2 q^2 + C^2 r^2``.

        Examples
        --------
        >>> body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 1.0, 1.0])
        >>> print(body.cayley_g)
        [1. 2. 3.]
        """
        return self.angular_momentum_space

    @property
    def kinetic_energy(self) -> float:
        """Kinetic energy ``T = (A p^2 + B q^2 + C r^2) / 2`` (J as a Quantity if the
        body was built from Quantities)."""
        return self._out(self.si.kinetic_energy, u.J)

    @property
    def angular_momentum_norm(self) -> float:
        """``|L|``, the magnitude of the angular momentum (kg m^2/s as a Quantity if
        the body was built from Quantities)."""
        return self._out(self.si.angular_momentum_norm, _L_UNIT)

    @property
    def invariable_plane(self) -> np.ndarray:
        """Unit normal of the invariable plane, ``L / |L|`` in space, shape (3,).

        Raises
        ------
        ValueError
            If the body is at rest (``L = 0``): the plane is then undefined.

        Examples
        --------
        >>> print(RigidBody([1.0, 2.0, 3.0], omega=[0.0, 0.0, 5.0]).invariable_plane)
        [0. 0. 1.]
        """
        sm, sw = pow2(self._moments), pow2(self._omega)
        lb = (self._moments / sm) * (self._omega / sw)
        big = pow2(lb)
        lvec = np.asarray(self.attitude.rotate(lb / big), dtype=np.float64)
        norm = float(np.sqrt(np.sum(lvec * lvec)))
        if norm == 0.0:
            raise ValueError(
                "Expected `omega` to be nonzero: a body at rest has no invariable plane, "
                f"got omega = {self._omega.tolist()}"
            )
        return lvec / norm
