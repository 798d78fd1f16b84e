"""The free wobble of the rigid Earth: its pole path, integrated or exact.

:func:`simulate_wobble` spins the rigid Earth of :mod:`rigid.earth.constants`
(:func:`~rigid.earth.constants.rigid_body`) with :func:`rigid.integrate` or the
exact :func:`rigid.free_motion` and returns the rotation pole in the body frame
as a :class:`PolePath`; :func:`pole_path` turns any body-frame angular velocity
into the pole ``m = m1 + i m2`` (IERS: ``x_p = m1``, ``y_p = -m2``).  A free
wobble of an axisymmetric rigid Earth is ``m(t) = m0 exp(i sigma_E t)``,
prograde, with the Euler frequency ``sigma_E = OMEGA (C - A) / A`` (Euler 1765);
:meth:`PolePath.period` fits its period (``rigid.earth.wobble_fit.free_period``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.units import ANGULAR_SPEED, TIME, time_quantity
from rigid.earth.constants import A_AXIS_LONGITUDE, rigid_body
from rigid.earth.wobble_fit import free_period
from rigid.free import free_motion
from rigid.integrators import integrate

__all__ = ["WOBBLE_TOLERANCE", "PolePath", "pole_path", "simulate_wobble"]


def pole_path(omega: Any) -> np.ndarray:
    """The rotation pole in the body frame, ``m = (omega_x + i omega_y) / omega_z``.

    Parameters
    ----------
    omega : array_like or Quantity, shape (..., 3)
        Body-frame angular velocity (rad/s if a Quantity).

    Returns
    -------
    ndarray, complex, shape (...)
        ``m = m1 + i m2`` in radians (IERS: ``x_p = m1``, ``y_p = -m2``).

    Examples
    --------
    >>> pole_path([[1e-6, 0.0, 1.0], [0.0, -2e-6, 1.0]])
    array([1.e-06+0.e+00j, 0.e+00-2.e-06j])
    """
    w = ANGULAR_SPEED("omega", omega, finite=False)  # (SI floats as they are)
    if w.shape[-1:] != (3,):
        raise ValueError(f"Expected `omega` to have shape (..., 3), got {w.shape}")
    bad = ~np.isfinite(w).all(axis=-1) | (w[..., 2] == 0.0)
    if bad.any():
        at = tuple(int(k) for k in np.argwhere(bad)[0])
        raise ValueError(f"Expected `omega` finite with omega_z != 0 (the pole is "
                         f"omega_xy / omega_z), got {w[at]!r} at index {at}")
    return (w[..., 0] + 1j * w[..., 1]) / w[..., 2]


@dataclass(frozen=True)
class PolePath:
    """A simulated pole path (see :func:`simulate_wobble`).

    Attributes
    ----------
    t : Quantity, shape (n,), day
        Output times.
    m : ndarray, complex, shape (n,)
        ``m1 + i m2`` in radians, in the terrestrial frame (x towards Greenwich:
        the body frame's pole turned by ``A_AXIS_LONGITUDE``, the A axis's).
    method : str
        The integrator (``"splitting4"``, ``"exact"``, ...).
    error : float
        The largest distance of ``m`` from the exact free motion's pole
        (:func:`rigid.free_motion`) over the path, as a fraction of the exact
        pole's largest offset (0 for ``"exact"``).
    """

    t: u.Quantity
    m: np.ndarray
    method: str
    error: float = 0.0

    @property
    def x(self) -> u.Quantity:
        """``x_p = m1`` in arcsec."""
        return (self.m.real * u.rad).to(u.arcsec)

    @property
    def y(self) -> u.Quantity:
        """``y_p = -m2`` in arcsec."""
        return (-self.m.imag * u.rad).to(u.arcsec)

    def period(self) -> u.Quantity:
        """The wobble period fitted to the path (see ``rigid.earth.wobble_fit.free_period``).

        Examples
        --------
        >>> from rigid.earth import euler_period
        >>> path = simulate_wobble(2 * u.yr, method="exact", triaxial=False)
        >>> bool(abs(path.period() / euler_period() - 1) < 1e-10)
        True
        """
        return free_period(self.t, self.m)


def simulate_wobble(
    duration: Any = 100 * u.yr,
    *,
    wobble: Any = 0.2 * u.arcsec,
    dt: Any = 1 * u.hour,
    method: str = "splitting4",
    triaxial: bool = True,
) -> PolePath:
    """Integrate the free rigid Earth and return its pole path with daily output.

    Parameters
    ----------
    duration : Quantity or TimeDelta
        Time span (default 100 years; an astropy TimeDelta is the Quantity in days
        it holds).
    wobble : Quantity
        Initial angle between the rotation and figure axes (default 0.2 arcsec).
    dt : Quantity or TimeDelta
        Step of the fixed-step integrator (default 1 hour; ignored for
        ``"exact"`` and ``"dop853"``).  All three are Quantities: a bare number
        is refused (it could mean days, radians or seconds).
    method : str
        A method of :func:`rigid.integrate`, or ``"exact"`` for
        :func:`rigid.free_motion`.
    triaxial : bool
        Triaxial (default) or axisymmetric Earth.

    Warns
    -----
    RuntimeWarning
        When the simulated pole departs from the exact free motion's by more than
        ``WOBBLE_TOLERANCE`` (1e-4) of the wobble (its distance kept in
        ``PolePath.error``): ``"splitting4y"`` at the default step of an hour put
        the period 12% short (267.5 d), ``"splitting2"`` lost the pole.

    Examples
    --------
    >>> path = simulate_wobble(3 * u.yr, method="exact")
    >>> print(f"{path.period():.1f}")
    303.6 d
    """
    duration, dt = time_quantity(duration), time_quantity(dt)  # (a TimeDelta: days)
    for name, value, like in (("duration", duration, "100 * u.yr"),
                              ("wobble", wobble, "0.2 * u.arcsec"), ("dt", dt, "1 * u.hour")):
        if value is None and name == "dt" and method in ("exact", "dop853"):
            continue  # (not used: documented as ignored)
        if not isinstance(value, u.Quantity):  # (three units a bare number could mean)
            raise ValueError(f"Expected `{name}` to be a Quantity (such as {like}), got the "
                             f"bare number {value!r}")
    t_end = TIME("duration", duration, u.day)
    if t_end.shape != ():
        raise ValueError(f"Expected `duration` to be one time, got {duration!r} of shape "
                         f"{t_end.shape}")
    if not float(t_end) >= 1.0:
        raise ValueError(f"Expected `duration` >= 1 day, got {duration!r}")
    n_out = int(np.floor(float(t_end))) + 1
    body = rigid_body(wobble, triaxial=triaxial)
    t = np.arange(n_out) * 86400.0 * u.s
    if method == "exact":
        _, omega = free_motion(body, t)
    elif method == "dop853":  # adaptive: outputs at the days themselves
        omega = integrate(body, t, method=method).omega
    else:
        step = TIME("dt", dt, u.s)
        if step.shape != () or not 0.0 < float(step) <= 86400.0:
            raise ValueError(f"Expected `dt` > 0 and at most 1 day (the outputs are "
                             f"daily), got {dt!r}")
        # a whole number of steps per day so that the output falls on whole days
        per_day = int(np.ceil(86400.0 / float(step)))
        with warnings.catch_warnings():  # (the pole's own error is said below: the
            # attitude's, |q|'s drift, would say the same twice, from in here)
            warnings.filterwarnings("ignore", "integrate: the attitude quaternion's norm",
                                    RuntimeWarning)
            tr = integrate(body, t, dt=86400.0 / per_day * u.s, method=method)
        t, omega = tr.t, tr.omega
    # (the body frame's x is the A axis, 14.93 deg west: turned to Greenwich's, so that
    # x and y are the IERS x_p and y_p; a pole along A read 200 mas in x_p, 0 in y_p,
    # where it is at 193.25 and 51.52 mas)
    turn = np.exp(1j * A_AXIS_LONGITUDE.to_value(u.rad))
    m = pole_path(omega) * turn
    error = 0.0 if method == "exact" else _error(m, pole_path(free_motion(body, t)[1]) * turn)
    if error > WOBBLE_TOLERANCE:
        why = (f"{method} splits the Earth's spin itself (docs/pole_wander.md): use "
               f"splitting4, or a step of about a minute" if method in _PLAIN_SPLITS
               else "give a shorter dt")
        warnings.warn(f"simulate_wobble: the {method} pole departs from the exact free "
                      f"motion by {error:.2g} of the wobble (dt = {dt}); {why}",
                      RuntimeWarning, stacklevel=2)
    return PolePath(t=u.Quantity(t, u.s).to(u.day), m=m, method=method, error=error)


#: the largest departure of a simulated pole from the exact one, as a fraction of the
#: wobble, that :func:`simulate_wobble` passes without a warning: 20 uas of its
#: default 0.2 arcsec, below the IERS C04 pole's precision (some 30 uas)
WOBBLE_TOLERANCE = 1e-4
#: the methods that split the free body as T1 + T2 + T3 (the spin split too)
_PLAIN_SPLITS = ("splitting2", "splitting4y")


def _error(m: np.ndarray, exact: np.ndarray) -> float:
    """``max |m - exact| / max |exact|`` (0 for a path without wobble followed
    exactly, inf for one that left it)."""
    off, scale = float(np.max(np.abs(m - exact))), float(np.max(np.abs(exact)))
    if scale == 0.0:
        return 0.0 if off == 0.0 else math.inf
    return off / scale
