"""The exact torque-free motion of a rigid body (Euler-Poinsot case).

The angular velocity is given by Jacobi's elliptic functions, the attitude by the
angular-momentum frame plus the precession angle about the invariable line, an
elliptic integral of the third kind evaluated through Carlson's ``R_J``.  The
derivation with all signs, the branches (both polhode families, the exact
separatrix, the axisymmetric body, the sphere) and the treatment near the
separatrix are in ``docs/free_rigid_body.md``.

For ``A < B < C`` and ``L^2 > 2 T B`` (the polhode encircles the C axis), with
``T`` the kinetic energy and ``L = |L|``:

    p = a cn(u),  q = b sn(u),  r = c dn(u),  u = u0 + lambda t,
    a^2 = (2TC - L^2) / (A (C - A)),   b^2 = (2TC - L^2) / (B (C - B)),
    c^2 = (L^2 - 2TA) / (C (C - A)),   lambda^2 = (C - B)(L^2 - 2TA) / (ABC),
    m = (B - A)(2TC - L^2) / ((C - B)(L^2 - 2TA)),
    1 - m = (C - A)(L^2 - 2TB) / ((C - B)(L^2 - 2TA)).

The other family (``L^2 < 2 T B``) is the same with the roles of A and C
exchanged in a right-handed relabelling of the axes.  On the separatrix
(``L^2 = 2 T B``, ``m = 1``) sn, cn, dn become tanh, sech, sech.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import (
    ANGULAR_SPEED,
    INERTIA,
    TIME,
    require_consistent,
    time_quantity,
    wrap,
)
from rigid._kernels import free as _fk
from rigid._shared import free_flow_scaled, free_setup_scaled
from rigid.body import RigidBody, call_units, check_body, check_moments, unit_quaternion

__all__ = ["FreeMotion", "FreeParameters", "free_motion", "free_motion_arrays",
           "free_parameters"]

_RATE = 1 / u.s


def _check_state(
    moments: Any, q0: Any, omega0: Any, names: tuple[str, str, str] = ("moments", "q0", "omega0")
) -> tuple[np.ndarray, ...]:
    moments = check_moments(names[0], INERTIA(names[0], moments))
    q0 = unit_quaternion(names[1], q0)
    omega0 = ANGULAR_SPEED(names[2], omega0)
    if omega0.shape != (3,):
        raise ValueError(f"Expected `{names[2]}` to have shape (3,), got {omega0.shape}")
    return np.ascontiguousarray(moments), np.ascontiguousarray(q0), omega0.copy()


def free_motion_arrays(
    moments: Any, q0: Any, omega0: Any, t: Any
) -> tuple[np.ndarray, np.ndarray]:
    """Exact torque-free motion on plain arrays (the kernel-level entry point).

    Parameters
    ----------
    moments : array_like or Quantity, shape (3,), kg m^2
        Principal moments in the order of the body axes (any order of sizes),
        each > 0, with ``A + B >= C`` for every permutation.
    q0 : array_like, shape (4,)
        Initial attitude, scalar first, body to space; normalised on input.
    omega0 : array_like or Quantity, shape (3,), rad/s
        Initial body-frame angular velocity.
    t : array_like, Quantity or TimeDelta, shape (n,) or any shape, s
        Times since the initial state (plain floats: the time unit of ``omega0``;
        a TimeDelta: the Quantity in days it holds).

    Returns
    -------
    q : ndarray, shape t.shape + (4,)
        Unit attitude quaternions.  The sign is continuous in time.
    omega : ndarray or Quantity, shape t.shape + (3,)
        Body-frame angular velocities (rad/s if the call was in Quantities).

    Raises
    ------
    ValueError
        For wrong shapes, NaN / inf, complex input, a non-positive moment, moments
        that break the triangle inequality, a zero quaternion, ``|omega0| t``
        beyond float64, an angular velocity along the motion beyond float64, a
        needle too thin for rates this uneven (the polhode beyond float64), or a
        mix of Quantities and plain numbers.
    astropy.units.UnitConversionError
        For a Quantity of the wrong dimension, naming the argument.

    Notes
    -----
    The problem is homogeneous: the kernel runs on ``moments / sm``,
    ``omega0 / sw`` and ``t sw`` (``sm, sw`` powers of two), so magnitudes from
    1e-300 to 1e300 neither under- nor overflow.

    Examples
    --------
    >>> moments = np.array([1.0, 2.0, 3.0])
    >>> q, w = free_motion_arrays(moments, [1, 0, 0, 0], [1.0, 0.3, 0.8], [0.0, 1.0, 100.0])
    >>> print(w.round(6))
    [[ 1.        0.3       0.8     ]
     [ 0.550187  0.887296  0.638411]
     [ 0.568352 -0.875772  0.643694]]
    >>> print((moments * w**2).sum(axis=-1).round(14))  # 2T is conserved
    [3.1 3.1 3.1]
    """
    t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
    quantity = require_consistent(("moments", "omega0", "t"), (moments, omega0, t))
    moments, q0, omega0 = _check_state(moments, q0, omega0)
    t_arr = TIME("t", t)
    flat = np.ascontiguousarray(t_arr.reshape(-1))
    out_q, out_w = free_flow_scaled(moments, q0, omega0, flat, "t")
    w = out_w.reshape(t_arr.shape + (3,))
    return out_q.reshape(t_arr.shape + (4,)), wrap(w, u.rad / u.s, quantity)


class FreeMotion(NamedTuple):
    """The result of :func:`free_motion`: ``attitude, omega = free_motion(body, t)``.

    Attributes
    ----------
    attitude : Quaternion, shape t.shape
        Body-to-space attitude at each time.
    omega : ndarray or Quantity, shape t.shape + (3,)
        Body-frame angular velocity at each time (rad/s as a Quantity when the
        call was in Quantities).

    Examples
    --------
    >>> motion = free_motion(RigidBody([1.0, 2.0, 3.0], omega=[0.0, 0.0, 2.0]), [0.0, 1.0])
    >>> print(motion.omega[-1], motion.attitude.as_array()[-1].round(6))
    [0. 0. 2.] [0.540302 0.       0.       0.841471]
    """

    attitude: Quaternion
    omega: Any


def free_motion(body: RigidBody, t: Any) -> FreeMotion:
    """The exact torque-free motion of ``body``, vectorised over ``t``.

    Parameters
    ----------
    body : RigidBody
        Moments, initial attitude and initial body angular velocity.
    t : array_like, Quantity or TimeDelta, any shape, s
        Times since the body's state.  A Quantity (or a TimeDelta, the Quantity
        in days it holds) gives omega in rad/s back.

    Returns
    -------
    FreeMotion
        A named tuple ``(attitude, omega)``: ``attitude`` (Quaternion, shape
        t.shape), the body-to-space attitude at each time; ``omega`` (ndarray or
        Quantity, shape t.shape + (3,), rad/s), the body-frame angular velocity.

    Raises
    ------
    ValueError
        If ``body`` is not a RigidBody, ``t`` has NaN / inf or ``|omega| t`` is
        beyond float64, or the motion is beyond float64 (see
        :func:`free_motion_arrays`).

    Notes
    -----
    Angular velocity from Jacobi's ``sn, cn, dn`` (module docstring); the attitude
    is ``q(t) = q0 qP qa(0) exp(Psi(t) e3 / 2) qa(t)^-1 qP^-1`` with ``qa`` the
    shortest arc from the polar body axis to ``L_body / |L|`` and

        Psi(t) = (L/J3) t + L (J3 - J1) / (J1 J3 lambda) [Pi(n; am u) - Pi(n; am u0)]
                 - (alpha(t) - alpha(0)),   n = -J3 (J2 - J1) / (J1 (J3 - J2)),

    ``alpha`` the azimuth of ``L_body`` about the polar axis.  ``Pi`` is
    accumulated as ``2 k Pi(n|m) + Pi(n; am r)`` with ``u = 2 k K + r``, so the
    precession stays exact over any number of periods.  The integral of the
    precession is Cayley's invariable-plane quadrature (Cayley 1843, the
    ``4 tan^-1 nu_0`` integral) in closed form.

    References
    ----------
    A. Cayley (1843), Camb. Math. J. 3, 224-232.  B. C. Carlson (1995),
    Numer. Algorithms 10, 13-26.  E. Celledoni, F. Fasso, N. Safstrom, A. Zanna
    (2008), BIT 48, 753-783 (exact free rigid body; our signs are derived anew and
    tested against numerical integration, see docs/free_rigid_body.md).

    Examples
    --------
    >>> import astropy.units as u
    >>> body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[1.0, 0.3, 0.8] * u.rad / u.s)
    >>> att, w = free_motion(body, [0.0, 10.0] * u.s)
    >>> print(w.round(6))
    [[1.       0.3      0.8     ]
     [0.685247 0.787678 0.680579]] rad / s
    >>> print(att.rotate((body.moments * w).value).round(12))  # L in space is constant
    [[1.  0.6 2.4]
     [1.  0.6 2.4]]
    """
    body = check_body(body)
    t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
    quantity = call_units(body, ("t",), (t,))
    t_arr = TIME("t", t)
    flat = np.ascontiguousarray(t_arr.reshape(-1))
    si = body.si
    q, w = free_flow_scaled(si.moments, si.attitude, si.omega, flat, "t", "`body`")
    q = q.reshape(t_arr.shape + (4,))
    w = w.reshape(t_arr.shape + (3,))
    return FreeMotion(Quaternion(q), wrap(w, u.rad / u.s, quantity))


@dataclass(frozen=True)
class FreeParameters:
    """Elliptic parameters of a torque-free motion (see :func:`free_parameters`).

    Attributes
    ----------
    kind : str
        ``"steady"`` (sphere, rest, rotation about a principal axis),
        ``"periodic"`` or ``"separatrix"``.
    polar_axis : int
        Body axis the polhode encircles (largest moment if ``L^2 > 2 T B``,
        smallest if ``L^2 < 2 T B``); -1 for steady motion.
    m, m1 : float
        Parameter and complementary parameter ``m1 = 1 - m`` (computed directly).
    K : float
        Complete elliptic integral ``K(m)`` (inf on the separatrix).
    lam : float or Quantity
        Rate ``lambda`` of the argument ``u = u0 + lambda t`` (1/s; a Quantity
        for a body built from Quantities, as are the two times below).
    period : float or Quantity
        Period of omega in the body, ``4 K / lambda`` (inf on the separatrix), s.
    flip_interval : float or Quantity
        Half the period, ``2 K / lambda``: the time between two successive
        reversals of the middle-axis component (the Dzhanibekov flip), s.
    n : float
        Characteristic of the third-kind integral, ``-J3 (J2 - J1) / (J1 (J3 - J2))``.
    """

    kind: str
    polar_axis: int
    m: float
    m1: float
    K: float
    lam: Any
    period: Any
    flip_interval: Any
    n: float


def free_parameters(body: RigidBody) -> FreeParameters:
    """Elliptic parameters ``m, 1 - m, K, lambda`` and the period of ``body``'s motion.

    Parameters
    ----------
    body : RigidBody

    Returns
    -------
    FreeParameters
        ``lam`` in 1/s, ``period`` and ``flip_interval`` in s: Quantities for a
        body built from Quantities, else plain SI floats.

    Raises
    ------
    ValueError
        If ``body`` is not a RigidBody, or its motion's rate ``lam`` or its polhode
        is beyond float64 (see :func:`free_motion_arrays`).

    Examples
    --------
    >>> p = free_parameters(RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8]))
    >>> # by hand: 2T = 3.1, L^2 = 7.12, m = (2T C - L^2) / (L^2 - 2T A) = 2.18 / 4.02
    >>> print(p.kind, p.polar_axis, round(p.m, 6), round(p.period, 6))
    periodic 2 0.542289 9.244135
    """
    body = check_body(body)
    # homogeneous: the kernel sees moments / sm and omega / sw; rates scale back by sw
    si = body.si
    prm, sw = free_setup_scaled(si.moments, si.attitude, si.omega, "`body`")
    kind = int(prm[_fk.KIND])
    q = body.quantity
    inf = float("inf")
    if kind == 0:
        return FreeParameters("steady", -1, 0.0, 1.0, np.pi / 2, wrap(0.0, _RATE, q),
                              wrap(inf, u.s, q), wrap(inf, u.s, q), 0.0)
    pmat = prm[_fk.P : _fk.P + 9].reshape(3, 3)
    polar = int(np.argmax(np.abs(pmat[:, 2])))
    lam = float(prm[_fk.LAM]) * sw  # (a Python float: beyond float64 it is inf, no warning)
    if not math.isfinite(lam):
        raise ValueError(
            f"Expected `body` with the rate of its polhode within float64, got lambda = "
            f"{float(prm[_fk.LAM])!r} x {sw!r} rad/s for omega {si.omega.tolist()}"
        )
    if kind == 1:
        kk = float(prm[_fk.K])
        return FreeParameters(
            "periodic", polar, float(prm[_fk.M]), float(prm[_fk.M1]), kk,
            wrap(lam, _RATE, q), wrap(4.0 * kk / lam, u.s, q), wrap(2.0 * kk / lam, u.s, q),
            float(prm[_fk.N]),
        )
    return FreeParameters("separatrix", polar, 1.0, 0.0, inf, wrap(lam, _RATE, q),
                          wrap(inf, u.s, q), wrap(inf, u.s, q), float(prm[_fk.N]))
