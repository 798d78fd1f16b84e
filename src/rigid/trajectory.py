"""The result of :func:`rigid.integrate`: :class:`RigidTrajectory`.

A :class:`~hamilton_orbits.trajectory.TrajectoryBase` like the n-body
``Trajectory``: output times ``t``, ``steps``, ``wall_time``, ``method`` and how
well the free body's integrals were kept, Cayley's (1843) integrals of the
motion: the kinetic energy ``T = (A p^2 + B q^2 + C r^2) / 2``
(``energy_error``) and the angular momentum in space ``(g, g', g'')``
(``angular_momentum_error``).  With a torque these are the changes the torque
made (plus the integration error), not errors.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.trajectory import TrajectoryBase, relative_change
from hamilton_orbits.units import wrap
from rigid._shared import pow2

__all__ = ["RigidTrajectory", "integral_errors"]

_L_UNIT = u.kg * u.m**2 / u.s


@dataclass(frozen=True, eq=False, kw_only=True)
class RigidTrajectory(TrajectoryBase):
    """The states of a rigid body at the output times, with Cayley's integrals.

    Attributes
    ----------
    t : ndarray or Quantity, shape (n,)
        Output times from the body's state, ``t[0] = 0`` (a Quantity in the unit
        of the ``t`` given when the call used Quantities, else s).  Fixed-step
        methods output at the step nearest each time asked for: ``t`` holds the
        times reached.
    steps : int
        Steps taken (accepted steps for ``"dop853"``).
    wall_time : float
        Seconds of wall-clock time of the integration proper.
    method : str
        Integrator name.
    energy_error : ndarray, shape (n,)
        ``(T(t) - T(0)) / T(0)``, ``T = (A p^2 + B q^2 + C r^2) / 2`` (the
        absolute change ``T(t) - T(0)`` for a body at rest, in the units of the
        moments times those of omega squared: J for Quantity calls).
    angular_momentum_error : ndarray, shape (n,)
        ``|L_s(t) - L_s(0)| / |L_s(0)|``, ``L_s = q (A p, B q, C r) q^-1``
        Cayley's ``(g, g', g'')`` (the absolute change ``|L_s(t) - L_s(0)|`` for
        a body at rest, kg m^2/s for Quantity calls).
    attitude : Quaternion, shape (n,)
        Unit body-to-space attitudes.
    omega : ndarray or Quantity, shape (n, 3)
        Body-frame angular velocities (rad/s when the call used Quantities).
    moments : ndarray or Quantity, shape (3,)
        Principal moments (A, B, C) (kg m^2 when the call used Quantities).
    n_recentre : int
        Re-centrings of Cayley's parameters (``"cayley_rk4"`` only, else 0).
    norm_drift : float
        ``max | |q| - 1 |`` before the output normalisation (0 for ``"exact_kick"``,
        which renormalises every step).
    nfev : int
        Right-hand-side evaluations (``"dop853"`` only, else 0).

    Examples
    --------
    >>> from rigid import RigidBody, integrate
    >>> tr = integrate(RigidBody([1.0, 2.0, 3.0], omega=[0.1, 1.0, 0.1]), [5.0, 10.0],
    ...                dt=0.01, method="exact_kick")
    >>> print(tr)  # doctest: +ELLIPSIS
    RigidTrajectory(3 outputs, t = 0 .. 10 s, method='exact_kick', steps=1000, max |dT/T| = ...)
    >>> tr.t, tr.steps
    (array([ 0.,  5., 10.]), 1000)
    >>> bool(np.max(np.abs(tr.energy_error)) < 1e-13)  # exact for the free body: rounding
    True
    """

    t: Any
    steps: int
    wall_time: float
    method: str
    energy_error: np.ndarray
    angular_momentum_error: np.ndarray
    attitude: Quaternion
    omega: Any
    moments: Any
    n_recentre: int = 0
    norm_drift: float = 0.0
    nfev: int = 0

    def __repr__(self) -> str:
        t = self.t
        unit = str(t.unit) if isinstance(t, u.Quantity) else "s"
        end = float(t[-1].value if isinstance(t, u.Quantity) else t[-1])
        return (
            f"RigidTrajectory({self.n_outputs} outputs, t = 0 .. {end:g} {unit}, "
            f"method={self.method!r}, steps={self.steps}, "
            f"max |dT/T| = {np.max(np.abs(self.energy_error)):.3g}, "
            f"max |dL|/|L| = {np.max(self.angular_momentum_error):.3g})"
        )

    @property
    def n_steps(self) -> int:
        """Deprecated: use ``steps``."""
        warnings.warn("`RigidTrajectory.n_steps` is deprecated; use `steps`",
                      DeprecationWarning, stacklevel=2)
        return self.steps

    def _quantity(self) -> bool:
        return isinstance(self.t, u.Quantity)

    def _omega_f(self) -> np.ndarray:
        w = self.omega
        return w.to_value(u.rad / u.s) if isinstance(w, u.Quantity) else np.asarray(w)

    def _moments_f(self) -> np.ndarray:
        m = self.moments
        return m.to_value(u.kg * u.m**2) if isinstance(m, u.Quantity) else np.asarray(m)

    @property
    def angular_momentum_body(self) -> Any:
        """L = I omega in the body frame, shape (n, 3) (kg m^2/s for Quantity calls)."""
        return wrap(self._moments_f() * self._omega_f(), _L_UNIT, self._quantity())

    @property
    def angular_momentum_space(self) -> Any:
        """q L q^-1, Cayley's (g, g', g''), shape (n, 3) (kg m^2/s for Quantity calls)."""
        ell = self.attitude.rotate(self._moments_f() * self._omega_f())
        return wrap(np.asarray(ell), _L_UNIT, self._quantity())

    @property
    def kinetic_energy(self) -> Any:
        """T = (A p^2 + B q^2 + C r^2) / 2, shape (n,) (J for Quantity calls)."""
        w = self._omega_f()
        return wrap(0.5 * np.sum(self._moments_f() * w * w, axis=-1), u.J, self._quantity())


def integral_errors(
    moments: np.ndarray, q: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(energy_error, angular_momentum_error)`` of a run, from SI floats.

    The relative change of ``T = (A p^2 + B q^2 + C r^2) / 2`` and of
    ``L_s = q (A p, B q, C r) q^-1`` from the first output
    (:func:`hamilton_orbits.trajectory.relative_change`), computed on
    ``moments / sm`` and ``omega / sw`` (exact powers of two: the ratios are
    those of the unscaled integrals, and nothing under- or overflows).  For a
    body at rest at the first output (``omega[0] = 0``) the absolute changes
    ``T(t) - T(0)`` and ``|L_s(t) - L_s(0)|``, in the units of ``moments`` and
    ``omega`` (the scaled ones multiplied back by ``sm sw^2`` and ``sm sw``, exact
    but for an overflow, which the caller refuses).

    Parameters
    ----------
    moments : ndarray, shape (3,)
    q : ndarray, shape (n, 4)
        Unit attitudes.
    omega : ndarray, shape (n, 3)

    Examples
    --------
    >>> q = np.array([[1.0, 0, 0, 0], [0.0, 0, 0, 1]])
    >>> de, dl = integral_errors(np.array([1.0, 2.0, 3.0]), q, np.array([[1.0, 0, 0]] * 2))
    >>> de.tolist(), dl.tolist()  # a half turn about z reverses L_s = (1, 0, 0)
    ([0.0, 0.0], [0.0, 2.0])
    >>> de, dl = integral_errors(np.array([1.0, 2.0, 3.0]), q, np.array([[0.0, 0, 0],
    ...                                                                 [0, 0, 1.0]]))
    >>> de.tolist(), dl.tolist()  # from rest: T = 3 / 2, |L_s| = 3
    ([0.0, 1.5], [0.0, 3.0])
    """
    sm, sw = pow2(moments), pow2(omega)
    ms = moments / sm
    ws = omega / sw
    energy = 0.5 * np.sum(ms * ws * ws, axis=-1)
    ell = np.asarray(Quaternion(q).rotate(ms * ws), dtype=np.float64)
    de, dl = relative_change(energy), relative_change(ell)
    if not np.any(omega[0]):  # at rest: the absolute changes, in the caller's units
        de, dl = de * (sm * sw * sw), dl * (sm * sw)
    return de, dl
