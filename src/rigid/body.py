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

Units: Quantities are accepted (kg m^2 for the inertia, rad/s for omega).  Inside,
and in every attribute, the values are plain SI floats (or the caller's own
consistent units when plain floats were given).
"""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits._validation import as_float_array
from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import strip

__all__ = ["RigidBody"]

_EPS = np.finfo(np.float64).eps
_L_UNIT = u.kg * u.m**2 / u.s  # angular momentum
# Slack for the symmetry and the triangle-inequality checks: a tensor built by
# rotating a diagonal one in floating point is symmetric / flat only to a few
# ulp of its largest entry, and a flat disk (C = A + B, Sylvester's limit case)
# must pass.  64 ulp of the largest moment is far below any physical tolerance.
_SLACK = 64.0 * _EPS


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
        asym = np.abs(inertia - inertia.T)
        if np.any(asym > _SLACK * scale):
            i, j = (int(k) for k in np.argwhere(asym > _SLACK * scale)[0])
            raise ValueError(
                f"Expected `{name}` to be a symmetric (3, 3) tensor, got "
                f"{name}[{i}, {j}] = {inertia[i, j]!r} != {name}[{j}, {i}] = {inertia[j, i]!r}"
            )
        sym = 0.5 * (inertia + inertia.T)
        moments, axes = np.linalg.eigh(sym)
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
    bad = ~(moments > 0.0)
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(f"Expected `{name}` > 0, got {float(moments[k])!r} at index {k}")
    total = float(np.sum(moments))
    for k in range(3):
        others = total - moments[k]
        if moments[k] > others + _SLACK * total:
            raise ValueError(
                f"Expected `{name}` to satisfy A + B >= C, got {float(moments[k])!r} "
                f"at index {k} > {float(others)!r}"
            )
    return moments, axes


def _as_quaternion_array(name: str, attitude: Any) -> np.ndarray:
    if attitude is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    arr = attitude.as_array() if isinstance(attitude, Quaternion) else attitude
    arr = as_float_array(name, arr)
    if arr.shape != (4,):
        raise ValueError(f"Expected `{name}` to have shape (4,), got {arr.shape}")
    norm = float(np.sqrt(np.sum(arr * arr)))
    if norm == 0.0:
        raise ValueError(f"Expected `{name}` to be a nonzero quaternion, got {arr!r}")
    return arr / norm


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
        (``v_space = q v_body q^-1``).  Normalised on input.  Default identity.
    omega : array_like or Quantity, shape (3,), rad/s, optional
        Angular velocity ``(p, q, r)`` in the body frame in which ``inertia`` was
        given.  Default zero.

    Attributes
    ----------
    moments : ndarray, shape (3,)
        Principal moments (SI floats, or the caller's consistent units).  The
        state (``moments``, ``omega``) is kept as floats; the derived quantities
        (angular momenta, kinetic energy) come back as Quantities when the body
        was built from Quantities.
    attitude : Quaternion
        Unit attitude quaternion, body (principal) frame to space.
    omega : ndarray, shape (3,)
        Angular velocity in the principal frame.

    Raises
    ------
    ValueError
        For a wrong shape, NaN or inf, a non-symmetric or non-positive-definite
        tensor, a non-positive moment, a violation of the triangle inequality
        (``A + B >= C`` for every permutation, Sylvester 1866: "each must be not
        greater than the sum of the other two"), or a zero quaternion.

    References
    ----------
    A. Cayley, "On the motion of rotation of a solid body", Camb. Math. J. 3
    (1843) 224-232.  J. J. Sylvester, "On the motion of a rigid body acted on by
    no external forces", Phil. Trans. R. Soc. 156 (1866) 757-779.

    Examples
    --------
    >>> import astropy.units as u
    >>> body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.1, 0.0, 1.0] * u.rad / u.s)
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

    __slots__ = ("_quantity", "attitude", "moments", "omega")

    def __init__(self, inertia: Any, attitude: Any = None, omega: Any = None) -> None:
        inertia_arr = strip("inertia", inertia, u.kg * u.m**2)
        omega_arr = (
            np.zeros(3) if omega is None else strip("omega", omega, u.rad / u.s)
        )
        if omega_arr.shape != (3,):
            raise ValueError(f"Expected `omega` to have shape (3,), got {omega_arr.shape}")
        q = _as_quaternion_array("attitude", attitude)
        moments, axes = _principal("inertia", inertia_arr)
        if axes is not None:
            # v_given = axes @ v_principal, so omega_principal = axes^T omega_given and
            # the new attitude composes q (given -> space) with axes (principal -> given).
            omega_arr = axes.T @ omega_arr
            qa = Quaternion.from_rotation_matrix(axes).as_array()
            q = (Quaternion(q) * Quaternion(qa)).as_array()
            q = q / np.sqrt(np.sum(q * q))
        self.moments: np.ndarray = np.asarray(moments, dtype=np.float64)
        self.omega: np.ndarray = np.asarray(omega_arr, dtype=np.float64).copy()
        self.attitude: Quaternion = Quaternion(q)
        # derived quantities come back as Quantities when the body was built from them
        self._quantity = isinstance(inertia, u.Quantity) or isinstance(omega, u.Quantity)

    def __repr__(self) -> str:
        return (
            f"RigidBody(moments={self.moments.tolist()}, "
            f"attitude={self.attitude.as_array().tolist()}, omega={self.omega.tolist()})"
        )

    def with_state(self, attitude: Any = None, omega: Any = None) -> RigidBody:
        """A body with the same moments and a new attitude and/or omega.

        Examples
        --------
        >>> b = RigidBody([1.0, 2.0, 3.0]).with_state(omega=[0.0, 0.0, 2.0])
        >>> print(b.omega)
        [0. 0. 2.]
        """
        body = RigidBody(
            self.moments,
            self.attitude if attitude is None else attitude,
            self.omega if omega is None else omega,
        )
        body._quantity = self._quantity or isinstance(omega, u.Quantity)
        return body

    # ------------------------------------------------------------ derived (floats)
    def _l_body(self) -> np.ndarray:
        return self.moments * self.omega

    def _l_space(self) -> np.ndarray:
        return np.asarray(self.attitude.rotate(self._l_body()), dtype=np.float64)

    def _energy(self) -> float:
        return float(0.5 * np.sum(self.moments * self.omega * self.omega))

    def _l_norm(self) -> float:
        return float(np.sqrt(np.sum(self._l_body() ** 2)))

    def _out(self, value, unit: u.UnitBase):
        return u.Quantity(value, unit) if self._quantity else value

    @property
    def angular_momentum_body(self) -> np.ndarray:
        """Angular momentum ``(A p, B q, C r)`` in the body frame, shape (3,)
        (kg m^2/s as a Quantity if the body was built from Quantities)."""
        return self._out(self._l_body(), _L_UNIT)

    @property
    def angular_momentum_space(self) -> np.ndarray:
        """Angular momentum in space, ``q (A p, B q, C r) q^-1``, shape (3,).

        Constant in torque-free motion; equal to Cayley's ``(g, g', g'')``.
        """
        return self._out(self._l_space(), _L_UNIT)

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
        return self._out(self._energy(), u.J)

    @property
    def angular_momentum_norm(self) -> float:
        """``|L|``, the magnitude of the angular momentum (kg m^2/s as a Quantity if
        the body was built from Quantities)."""
        return self._out(self._l_norm(), _L_UNIT)

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
        lvec = self._l_space()
        norm = float(np.sqrt(np.sum(lvec * lvec)))
        if norm == 0.0:
            raise ValueError(
                "Expected `omega` to be nonzero: a body at rest has no invariable plane, "
                f"got omega = {self.omega.tolist()}"
            )
        return lvec / norm
