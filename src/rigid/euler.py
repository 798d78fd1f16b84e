"""Euler's equations with torques, and the quaternion kinematics.

Conventions of the ``rigid`` package: the body frame is the principal-axis frame;
the attitude ``q`` carries body vectors to space, v_s = q v_b q^-1;
omega = (p, q, r) is the angular velocity in the body frame (Cayley's letters).

* Euler's equations (Cayley 1843, the equations after "eliminating"):
  A dp/dt + (C - B) q r = N_x, B dq/dt + (A - C) r p = N_y,
  C dr/dt + (B - A) p q = N_z, with N the body-frame torque.
* Kinematics: dq/dt = q (0, omega) / 2 (Hamilton product, omega pure).

Torques are small immutable objects (:class:`BodyTorque`, :class:`SpaceTorque`,
:class:`GravityGradientTorque`) that encode themselves for the compiled time
loops of ``rigid.integrators``; ``torque_on`` evaluates any of them on
arrays of attitudes.  All of them depend on (t, attitude) only, not on omega.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import (
    ANGLE,
    ANGULAR_SPEED,
    DIMENSIONLESS,
    INERTIA,
    TIME,
    TORQUE,
    Kind,
    is_quantity,
    require_consistent,
    time_quantity,
    wrap,
)
from hamilton_orbits.validation import check_positive, check_trailing
from rigid._kernels import euler as _k
from rigid.body import check_triangle

__all__ = [
    "BodyTorque",
    "GravityGradientTorque",
    "SpaceTorque",
    "euler_equations",
    "quaternion_rate",
    "torque_on",
]

_TORQUE = u.N * u.m
_RATE = u.rad / u.s
_GM_OVER_R3 = Kind("a squared rate GM / r^3", u.s**-2, u.dimensionless_angles, no_hertz=True)


def _moments(moments: Any) -> np.ndarray:
    m = check_trailing("moments", INERTIA("moments", moments), 3)
    return check_triangle("moments", check_positive("moments", m))


def _quat_array(name: str, attitude: Any) -> np.ndarray:
    if isinstance(attitude, Quaternion):
        a = attitude.as_array()
    else:
        a = check_trailing(name, DIMENSIONLESS(name, attitude), 4)
    zero = ~(np.max(np.abs(a), axis=-1) > 0.0)  # (the max avoids overflow in |q|^2)
    if np.any(zero):
        index = tuple(int(i) for i in np.argwhere(np.atleast_1d(zero))[0]) if a.ndim > 1 else ()
        raise ValueError(
            f"Expected `{name}` to be a nonzero quaternion, got {a[index].tolist()}"
            + (f" at index {index}" if index else "")
        )
    return a


def _finite(what: str, out: np.ndarray, names: tuple[str, ...]) -> None:
    """A result beyond float64 (finite input) is refused, naming the arguments."""
    bad = ~np.isfinite(out)
    if np.any(bad):
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        args = ", ".join(f"`{n}`" for n in names)
        raise ValueError(
            f"Expected {args} with a representable {what}, got {float(out[index])!r} at "
            f"index {index} (beyond float64)"
        )


class _Torque:
    """Base class: ``kind`` and ``params`` encode the torque for the kernels."""

    kind: int = _k.TORQUE_NONE
    #: the arguments with a dimension (a Quantity, or plain SI numbers)
    _dimensional: tuple[str, ...] = ()

    def encode(self) -> tuple[int, np.ndarray]:
        """(kind, params) for the compiled kernels (plain SI floats)."""
        raise NotImplementedError  # pragma: no cover


@dataclass(frozen=True)
class _ConstantTorque(_Torque):
    """A constant 3-vector torque (N m); subclasses fix the frame by ``kind``."""

    torque: Any
    _params: np.ndarray = field(init=False, repr=False, compare=False)
    _dimensional = ("torque",)

    def __post_init__(self) -> None:
        t = TORQUE("torque", self.torque)
        if t.shape != (3,):
            raise ValueError(f"Expected `torque` to have shape (3,), got {t.shape}")
        object.__setattr__(self, "_params", t.copy())

    def encode(self) -> tuple[int, np.ndarray]:
        return self.kind, self._params.copy()


@dataclass(frozen=True)
class BodyTorque(_ConstantTorque):
    """A torque constant in the body frame.

    Parameters
    ----------
    torque : array_like or Quantity, shape (3,)
        Body-frame torque: a Quantity (any unit of torque), or plain numbers in N m
        (SI).  Plain numbers (but zeros) are refused beside a body or moments of
        Quantities (``check_torque_units``): their unit cannot be guessed.

    Examples
    --------
    >>> BodyTorque([0.0, 0.0, 1.0]).encode()
    (1, array([0., 0., 1.]))
    """

    kind = _k.TORQUE_BODY


@dataclass(frozen=True)
class SpaceTorque(_ConstantTorque):
    """A torque constant in the space frame (acting on the body as q^-1 N q).

    Parameters
    ----------
    torque : array_like or Quantity, shape (3,)
        Space-frame torque: a Quantity (any unit of torque), or plain numbers in N m
        (SI).  Plain numbers (but zeros) are refused beside a body or moments of
        Quantities (``check_torque_units``): their unit cannot be guessed.

    Examples
    --------
    >>> q = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2)
    >>> np.round(torque_on(SpaceTorque([1.0, 0.0, 0.0]), [1.0, 1.0, 1.0], q), 12) + 0.0
    array([ 0., -1.,  0.])
    """

    kind = _k.TORQUE_SPACE


@dataclass(frozen=True)
class GravityGradientTorque(_Torque):
    """Gravity-gradient torque of a point mass seen on a circular orbit.

    N = 3 (GM / R^3) c x (I c), with c the unit vector from the body to the
    primary expressed in the body frame and I = diag(A, B, C) (e.g. Hughes 1986,
    *Spacecraft Attitude Dynamics*, ch. 8; Schaub & Junkins, *Analytical
    Mechanics of Space Systems*, sec. 4.7).  In space the direction turns
    uniformly in the plane of ``e1``, ``e2``:
    c_s(t) = cos(n t + phase) e1 + sin(n t + phase) e2.

    Parameters
    ----------
    gm_over_r3 : float or Quantity
        GM / R^3 (1/s^2 for a plain number), the square of the orbital mean motion
        on a Kepler orbit; set independently to study a fixed direction
        (``mean_motion=0``).
    mean_motion : float or Quantity, optional
        Rate n at which the direction turns (rad/s for a plain number).  Default 0.
        ``gm_over_r3`` and ``mean_motion`` are both Quantities or both plain
        numbers (a mix is refused: the plain one's unit cannot be guessed), but for
        a plain zero, which is zero in every unit (the default).
    phase : float or Quantity, optional
        Angle of the direction at t = 0.  Default 0.  A plain number is radians,
        beside Quantities too (as every angle of the package:
        ``hamilton_orbits.units.ANGLE``); ``30 * u.deg`` for degrees.
    e1, e2 : array_like, shape (3,), optional
        Orthonormal space-frame vectors spanning the orbit plane; default the
        x and y axes.

    Raises
    ------
    ValueError
        If ``gm_over_r3`` is negative, ``e1``, ``e2`` are not orthonormal, or one of
        ``gm_over_r3`` and ``mean_motion`` is a Quantity and the other a nonzero
        plain number (naming it and its value).

    Examples
    --------
    Long axis (smallest moment) off the local vertical: the torque pulls it back.

    >>> gg = GravityGradientTorque(1.0)
    >>> q = Quaternion.from_axis_angle([0, 0, 1], 0.1)
    >>> np.round(torque_on(gg, [1.0, 2.0, 2.5], q), 6) + 0.0
    array([ 0.      ,  0.      , -0.298004])
    """

    gm_over_r3: Any
    mean_motion: Any = 0.0
    phase: Any = 0.0
    e1: Any = (1.0, 0.0, 0.0)
    e2: Any = (0.0, 1.0, 0.0)
    _params: np.ndarray = field(init=False, repr=False, compare=False)
    _dimensional = ("gm_over_r3", "mean_motion")

    def __post_init__(self) -> None:
        require_consistent(self._dimensional, tuple(
            None if _plain_zero(v) else v for v in (self.gm_over_r3, self.mean_motion)))
        k = _GM_OVER_R3("gm_over_r3", self.gm_over_r3)
        check_positive("gm_over_r3", k, strict=False)
        n = ANGULAR_SPEED("mean_motion", self.mean_motion)
        ph = ANGLE("phase", self.phase)
        e1 = DIMENSIONLESS("e1", self.e1)
        e2 = DIMENSIONLESS("e2", self.e2)
        for name, e in (("e1", e1), ("e2", e2)):
            if e.shape != (3,):
                raise ValueError(f"Expected `{name}` to have shape (3,), got {e.shape}")
            if abs(float(e @ e) - 1.0) > 1e-12:
                raise ValueError(f"Expected `{name}` to be a unit vector, got |{name}|^2 = "
                                 f"{float(e @ e)!r}")
        if abs(float(e1 @ e2)) > 1e-12:
            raise ValueError(f"Expected `e1`, `e2` orthogonal, got e1.e2 = {float(e1 @ e2)!r}")
        for name, v in (("gm_over_r3", k), ("mean_motion", n), ("phase", ph)):
            if v.shape != ():
                raise ValueError(f"Expected `{name}` to be a scalar, got shape {v.shape}")
        params = np.concatenate([[float(k), float(n), float(ph)], e1, e2])
        object.__setattr__(self, "_params", params)

    def encode(self) -> tuple[int, np.ndarray]:
        return _k.TORQUE_GRAVITY_GRADIENT, self._params.copy()


def _plain_zero(value: Any) -> bool:
    """Whether ``value`` is plain numbers, all zero (zero in every unit)."""
    if is_quantity(value):
        return False
    try:
        return bool(np.all(np.asarray(value, dtype=np.float64) == 0.0))
    except (TypeError, ValueError):  # (refused by name where it is converted)
        return False


def check_torque_units(torque: Any, quantity: bool, like: str) -> None:
    """Refuse a torque of plain numbers for a body or moments of Quantities.

    A body built from Quantities takes Quantities (its times, its rates: a plain
    number beside it has no unit that could be guessed), and so does its torque:
    ``BodyTorque([0, 0, 1])`` is not read as N m beside it.  Zeros are taken (zero
    in every unit), and a body of plain numbers (SI) takes either.

    Parameters
    ----------
    torque : BodyTorque, SpaceTorque, GravityGradientTorque or None
        The torque model (anything else is left to :func:`encode_torque`).
    quantity : bool
        Whether the body (or the moments) is in Quantities.
    like : str
        The body's argument and its value, for the message.

    Raises
    ------
    ValueError
        Naming the torque's argument, the index and the value of its first
        nonzero plain number.

    Examples
    --------
    >>> check_torque_units(BodyTorque([0.0, 0.0, 1.0]), True, "`body`")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected BodyTorque's `torque` to be a Quantity like `body`, got ... at index 2
    >>> check_torque_units(BodyTorque([0.0, 0.0, 1.0]), False, "`body`")  # SI: taken
    """
    if not quantity or not isinstance(torque, _Torque):
        return
    for name in torque._dimensional:
        value = getattr(torque, name)
        if is_quantity(value) or _plain_zero(value):
            continue
        arr = np.asarray(value, dtype=np.float64)  # (checked numeric when built)
        k = tuple(int(i) for i in np.argwhere(arr != 0.0)[0])
        where = f" at index {k[0] if len(k) == 1 else k}" if k else ""
        raise ValueError(f"Expected {type(torque).__name__}'s `{name}` to be a Quantity like "
                         f"{like}, got the plain number {float(arr[k])!r}{where}")


def encode_torque(torque: Any) -> tuple[int, np.ndarray]:
    """``(kind, params)`` of ``torque`` for the compiled kernels (shared inside ``rigid``).

    Parameters
    ----------
    torque : BodyTorque, SpaceTorque, GravityGradientTorque or None

    Raises
    ------
    ValueError
        For anything else, naming the argument and the type.

    Examples
    --------
    >>> encode_torque(None)
    (0, array([0.]))
    >>> encode_torque([1.0, 0.0, 0.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `torque` to be None, BodyTorque, ... or GravityGradientTorque, got list
    """
    if torque is None:
        return _k.TORQUE_NONE, np.zeros(1)
    if isinstance(torque, _Torque):
        return torque.encode()
    raise ValueError(
        "Expected `torque` to be None, BodyTorque, SpaceTorque or GravityGradientTorque, "
        f"got {type(torque).__name__}"
    )


def torque_on(torque: Any, moments: Any, attitude: Any, t: Any = None) -> np.ndarray:
    """Body-frame torque of a torque object for arrays of attitudes.

    Parameters
    ----------
    torque : BodyTorque, SpaceTorque, GravityGradientTorque or None
        The torque model.  Beside ``moments`` of Quantities its dimensional values
        (a ``BodyTorque``'s or ``SpaceTorque``'s ``torque``, a gravity gradient's
        ``gm_over_r3`` and ``mean_motion``) are Quantities too: a plain non-zero
        number is refused, its unit not guessed (zeros are taken;
        ``check_torque_units``).
    moments : array_like or Quantity, shape (..., 3)
        Principal moments (A, B, C) (kg m^2 when a Quantity).
    attitude : Quaternion or array_like, shape (..., 4)
        Body-to-space attitude (any nonzero scale).
    t : float, Quantity or TimeDelta, shape (...), optional
        Time (s when a float).  Default 0.  A Quantity (or an astropy TimeDelta, the
        Quantity in days it holds) if ``moments`` is one.

    Returns
    -------
    ndarray or Quantity, shape (..., 3)
        The torque in the body frame (N m if ``moments`` was a Quantity).

    Raises
    ------
    ValueError
        For NaN, wrong shapes, a zero attitude, a non-positive moment or moments of
        no body (one greater than the sum of the other two, A + B >= C, as
        :class:`~rigid.RigidBody` refuses them); for a torque of plain non-zero
        numbers beside ``moments`` of Quantities
        (``torque_on(SpaceTorque([1.0, 0, 0]), [1, 2, 3] * u.kg * u.m**2, q)``),
        naming the torque's argument, the index and the value.

    Examples
    --------
    >>> torque_on(BodyTorque([1.0, 2.0, 3.0]), [1.0, 1.0, 1.0], Quaternion([1, 0, 0, 0]))
    array([1., 2., 3.])
    >>> import astropy.units as u
    >>> torque_on(SpaceTorque([1.0, 0.0, 0.0]), [1.0, 2.0, 3.0] * u.kg * u.m**2,
    ...           Quaternion([1, 0, 0, 0]))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected SpaceTorque's `torque` to be a Quantity like `moments` ...at index 0
    """
    t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
    quantity = require_consistent(("moments", "t"), (moments, t))
    m = _moments(moments)
    check_torque_units(torque, is_quantity(moments), f"`moments` ({moments})")
    q = _quat_array("attitude", attitude)
    tt = np.zeros(()) if t is None else TIME("t", t)
    kind, params = encode_torque(torque)
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            out = _k.torque_gufunc(m, q, tt, kind, params)
    except ValueError as exc:
        raise ValueError(
            f"Expected `moments`, `attitude`, `t` to broadcast together, got shapes "
            f"{m.shape}, {q.shape}, {tt.shape}"
        ) from exc
    _finite("torque", out, ("moments", "attitude", "torque"))
    return wrap(out, _TORQUE, quantity)


def euler_equations(moments: Any, omega: Any, torque: Any = None) -> np.ndarray:
    """Angular acceleration from Euler's equations.

    A dp/dt + (C - B) q r = N_x, B dq/dt + (A - C) r p = N_y,
    C dr/dt + (B - A) p q = N_z (Cayley 1843, p. 230, the three equations
    "after eliminating", with the right-hand sides from the force function V
    written as the body-frame torque N).

    Parameters
    ----------
    moments : array_like or Quantity, shape (..., 3)
        Principal moments (A, B, C) (kg m^2).
    omega : array_like or Quantity, shape (..., 3)
        Body-frame angular velocity (p, q, r) (rad/s).
    torque : array_like or Quantity, shape (..., 3), optional
        Body-frame torque (N m).  Default 0.  ``moments``, ``omega`` and
        ``torque`` are all Quantities or all plain numbers.

    Returns
    -------
    ndarray or Quantity, shape (..., 3)
        d omega / dt (rad/s^2 when any input was a Quantity).

    Raises
    ------
    ValueError
        For NaN / inf, wrong shapes (a number for ``torque``: a torque is a
        3-vector), non-positive moments, moments of no body (A + B >= C, as
        :class:`~rigid.RigidBody`), or shapes that do not broadcast (naming the
        argument and index).

    Examples
    --------
    >>> np.round(euler_equations([1.0, 2.0, 3.0], [1.0, 1.0, 1.0]), 6)
    array([-1.      ,  1.      , -0.333333])
    """
    quantity = require_consistent(("moments", "omega", "torque"), (moments, omega, torque))
    m = _moments(moments)
    w = check_trailing("omega", ANGULAR_SPEED("omega", omega), 3)
    n = np.zeros(3) if torque is None else TORQUE("torque", torque)
    check_trailing("torque", n, 3)  # (a number is no torque vector: refused)
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            out = _k.euler_gufunc(m, w, n)
    except ValueError as exc:
        raise ValueError(
            f"Expected `moments`, `omega`, `torque` to broadcast together, got shapes "
            f"{m.shape}, {w.shape}, {n.shape}"
        ) from exc
    _finite("angular acceleration", out, ("moments", "omega", "torque"))
    return wrap(out, _RATE / u.s, quantity)


def quaternion_rate(attitude: Any, omega: Any) -> Quaternion:
    """Quaternion kinematics dq/dt = q (0, omega) / 2.

    Parameters
    ----------
    attitude : Quaternion or array_like, shape (..., 4)
        Body-to-space attitude q.
    omega : array_like or Quantity, shape (..., 3)
        Body-frame angular velocity (rad/s when a Quantity; the rate is then
        per second).

    Returns
    -------
    Quaternion, shape (...)
        dq/dt.  For a unit q it is orthogonal to q (|q| is conserved).

    Raises
    ------
    ValueError
        For NaN, wrong shapes, a zero attitude, or shapes that do not broadcast.

    Examples
    --------
    >>> quaternion_rate(Quaternion([1.0, 0.0, 0.0, 0.0]), [0.0, 0.0, 2.0]).as_array()
    array([0., 0., 0., 1.])
    """
    q = _quat_array("attitude", attitude)
    w = check_trailing("omega", ANGULAR_SPEED("omega", omega), 3)
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            out = _k.qdot_gufunc(q, w)
    except ValueError as exc:
        raise ValueError(
            f"Expected `attitude`, `omega` to broadcast together, got shapes "
            f"{q.shape}, {w.shape}"
        ) from exc
    _finite("quaternion rate", out, ("attitude", "omega"))
    return Quaternion(out)
