"""Poinsot's construction: polhode, herpolhode and the rolling inertia ellipsoid.

The inertia ellipsoid ``x . I x = 1`` (body frame) carries the point
``rho = omega / sqrt(2T)`` on its surface; its tangent plane there has normal
``I rho`` parallel to ``L`` and lies at the constant distance
``d = rho . L_hat = sqrt(2T) / |L|`` from the fixed centre: the ellipsoid rolls
without slipping on this invariable plane.  The polhode is the path of ``rho`` in
the body, the herpolhode its path in space, a curve in the invariable plane
(Poinsot 1834; Sylvester 1866, "Poinsot's ellipsoid with time put in evidence").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import TIME, time_quantity, wrap
from rigid._shared import free_flow_scaled
from rigid.body import RigidBody, call_units, check_body

_RHO_UNIT = (u.kg * u.m**2) ** -0.5  # x . I x = 1 on the inertia ellipsoid

__all__ = ["PoinsotPaths", "plot_poinsot", "poinsot"]


@dataclass(frozen=True)
class PoinsotPaths:
    """Arrays of Poinsot's construction, all for the times ``t`` (n,).

    The lengths (``polhode``, ``contact``, ``herpolhode``, ``distance``) live in
    the space of the inertia ellipsoid ``x . I x = 1``, so their unit is
    ``(kg m^2)^(-1/2)``; they are Quantities in that unit when the call was in
    Quantities, else plain floats.

    Attributes
    ----------
    t : ndarray or Quantity (n,)
        The times as given (a Quantity keeps its unit).
    polhode : ndarray or Quantity (n, 3)
        ``rho = omega / sqrt(2T)`` in the body frame (on the inertia ellipsoid).
    contact : ndarray or Quantity (n, 3)
        The same point in space (the point of contact with the invariable plane).
    herpolhode : ndarray or Quantity (n, 2)
        Its coordinates in the invariable plane, about the foot of the normal,
        in the basis ``(e1, e2)``.
    plane_normal : ndarray (3,)
        ``L_hat`` in space.
    plane_basis : ndarray (2, 3)
        ``e1, e2``: an orthonormal basis of the plane with ``e1 x e2 = L_hat``.
    distance : float or Quantity
        ``sqrt(2T) / |L|``, the distance from the centre to the invariable plane.
    """

    t: Any
    polhode: Any
    contact: Any
    herpolhode: Any
    plane_normal: np.ndarray
    plane_basis: np.ndarray
    distance: Any


def poinsot(body: RigidBody, t: Any) -> PoinsotPaths:
    """Polhode, herpolhode and contact points of ``body``'s free motion at times ``t``.

    Parameters
    ----------
    body : RigidBody
        Not at rest.
    t : array_like (n,), Quantity or TimeDelta, s
        A Quantity if ``body`` was built from Quantities (a TimeDelta is the
        Quantity in days it holds).

    Returns
    -------
    PoinsotPaths
        In Quantities when ``body`` or ``t`` is (``t`` kept in its own unit).

    Raises
    ------
    ValueError
        If ``body`` is not a RigidBody or is at rest (no invariable plane), or
        ``t`` is not finite or is a plain number beside a body with units.
    astropy.units.UnitConversionError
        If ``t`` is not a time.

    Examples
    --------
    >>> paths = poinsot(RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8]), [0.0, 5.0])
    >>> print(round(paths.distance, 9), (paths.contact @ paths.plane_normal).round(8))
    0.659843359 [0.65984336 0.65984336]
    >>> print(round(float(np.sqrt(3.1 / 7.12)), 9))  # by hand: sqrt(2T) / |L|
    0.659843359
    """
    body = check_body(body)
    t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
    quantity = call_units(body, ("t",), (t,))
    normal = body.invariable_plane
    t_s = TIME("t", t)  # validated, in seconds for the computation
    t_unit = t.unit if isinstance(t, u.Quantity) else u.s
    t_given = np.array(t.value, dtype=np.float64) if isinstance(t, u.Quantity) else t_s
    flat = np.ascontiguousarray(t_s.reshape(-1))
    si = body.si
    q, w = free_flow_scaled(si.moments, si.attitude, si.omega, flat, "t", "`body`")
    # rho = omega / sqrt(2T) on moments / sm and omega / sw (no under- or overflow):
    # rho = (omega / sw) / sqrt(2T / (sm sw^2)) / sqrt(sm)
    sm, sw = si.scales()
    two_t = float(np.sum((si.moments / sm) * (si.omega / sw) ** 2))
    rho = (w / sw) / np.sqrt(two_t) / np.sqrt(sm)
    rho = rho.reshape(t_given.shape + (3,))
    contact = np.asarray(Quaternion(q.reshape(t_given.shape + (4,))).rotate(rho))
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    e1 = np.cross(helper, normal)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    herp = np.stack([contact @ e1, contact @ e2], axis=-1)
    l_scaled = float(np.linalg.norm((si.moments / sm) * (si.omega / sw)))
    dist = np.sqrt(two_t) / l_scaled / np.sqrt(sm)
    return PoinsotPaths(
        wrap(t_given, t_unit, quantity), wrap(rho, _RHO_UNIT, quantity),
        wrap(contact, _RHO_UNIT, quantity), wrap(herp, _RHO_UNIT, quantity), normal,
        np.stack([e1, e2]), wrap(np.float64(dist), _RHO_UNIT, quantity),
    )


def plot_poinsot(body: RigidBody, t: Any, *, fig: Any = None) -> Any:
    """Plot the polhode on the inertia ellipsoid and the herpolhode in the plane.

    Needs matplotlib (the ``plot`` extra), imported only here.

    Returns
    -------
    matplotlib.figure.Figure
    """
    paths = poinsot(body, t)  # validates first: bad input fails before matplotlib loads

    import matplotlib.pyplot as plt  # lazy: optional dependency

    if fig is None:
        fig = plt.figure(figsize=(10, 4.5))
    ax1 = fig.add_subplot(1, 2, 1, projection="3d")
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
    semi = 1.0 / np.sqrt(body.si.moments)
    polhode = np.asarray(getattr(paths.polhode, "value", paths.polhode))
    herpolhode = np.asarray(getattr(paths.herpolhode, "value", paths.herpolhode))
    distance = float(getattr(paths.distance, "value", paths.distance))
    ax1.plot_wireframe(semi[0] * np.cos(uu) * np.sin(vv), semi[1] * np.sin(uu) * np.sin(vv),
                       semi[2] * np.cos(vv), color="0.8", linewidth=0.4)
    ax1.plot(*polhode.T, color="C3", linewidth=1.5)
    ax1.set_box_aspect(semi)  # (the ellipsoid's own shape, not a sphere's)
    unit = "[(kg m$^2$)$^{-1/2}$]"  # (x . I x = 1 on the inertia ellipsoid)
    for k, set_label in enumerate((ax1.set_xlabel, ax1.set_ylabel, ax1.set_zlabel)):
        set_label(f"body axis {k + 1} {unit}", fontsize=8)
    ax1.set_title("polhode on the inertia ellipsoid (body)", fontsize=10)
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.plot(*herpolhode.T, color="C0", linewidth=0.8)
    ax2.set_aspect("equal")
    ax2.set_xlabel(f"along e1 in the invariable plane {unit}", fontsize=8)
    ax2.set_ylabel(f"along e2 {unit}", fontsize=8)
    ax2.set_title(f"herpolhode (invariable plane at d = {distance:.4g} {unit})", fontsize=10)
    fig.tight_layout()
    return fig
