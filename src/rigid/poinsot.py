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

import numpy as np

from rigid.body import RigidBody
from rigid.free import free_motion

__all__ = ["PoinsotPaths", "plot_poinsot", "poinsot"]


@dataclass(frozen=True)
class PoinsotPaths:
    """Arrays of Poinsot's construction, all for the times ``t`` (n,).

    Attributes
    ----------
    t : ndarray (n,)
    polhode : ndarray (n, 3)
        ``rho = omega / sqrt(2T)`` in the body frame (on the inertia ellipsoid).
    contact : ndarray (n, 3)
        The same point in space (the point of contact with the invariable plane).
    herpolhode : ndarray (n, 2)
        Its coordinates in the invariable plane, about the foot of the normal,
        in the basis ``(e1, e2)``.
    plane_normal : ndarray (3,)
        ``L_hat`` in space.
    plane_basis : ndarray (2, 3)
        ``e1, e2``: an orthonormal basis of the plane with ``e1 x e2 = L_hat``.
    distance : float
        ``sqrt(2T) / |L|``, the distance from the centre to the invariable plane.
    """

    t: np.ndarray
    polhode: np.ndarray
    contact: np.ndarray
    herpolhode: np.ndarray
    plane_normal: np.ndarray
    plane_basis: np.ndarray
    distance: float


def poinsot(body: RigidBody, t: Any) -> PoinsotPaths:
    """Polhode, herpolhode and contact points of ``body``'s free motion at times ``t``.

    Parameters
    ----------
    body : RigidBody
        Not at rest.
    t : array_like (n,) or Quantity, s

    Returns
    -------
    PoinsotPaths

    Raises
    ------
    ValueError
        If the body is at rest (no invariable plane).

    Examples
    --------
    >>> paths = poinsot(RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8]), [0.0, 5.0])
    >>> print(round(paths.distance, 9), (paths.contact @ paths.plane_normal).round(8))
    0.659843359 [0.65984336 0.65984336]
    >>> print(round(float(np.sqrt(3.1 / 7.12)), 9))  # by hand: sqrt(2T) / |L|
    0.659843359
    """
    if not isinstance(body, RigidBody):
        raise ValueError(f"Expected `body` to be a RigidBody, got {type(body).__name__}")
    normal = body.invariable_plane
    att, w = free_motion(body, t)
    w = np.asarray(getattr(w, "value", w))
    t_arr = np.asarray(getattr(t, "value", t), dtype=float)
    scale = 1.0 / np.sqrt(2.0 * body._energy())
    rho = w * scale
    contact = np.asarray(att.rotate(rho))
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    e1 = np.cross(helper, normal)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    herp = np.stack([contact @ e1, contact @ e2], axis=-1)
    dist = np.sqrt(2.0 * body._energy()) / body._l_norm()
    return PoinsotPaths(t_arr, rho, contact, herp, normal, np.stack([e1, e2]), float(dist))


def plot_poinsot(body: RigidBody, t: Any, *, fig: Any = None) -> Any:
    """Plot the polhode on the inertia ellipsoid and the herpolhode in the plane.

    Needs matplotlib (the ``plot`` extra), imported only here.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt  # lazy: optional dependency

    paths = poinsot(body, t)
    if fig is None:
        fig = plt.figure(figsize=(10, 4.5))
    ax1 = fig.add_subplot(1, 2, 1, projection="3d")
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
    semi = 1.0 / np.sqrt(body.moments)
    ax1.plot_wireframe(semi[0] * np.cos(uu) * np.sin(vv), semi[1] * np.sin(uu) * np.sin(vv),
                       semi[2] * np.cos(vv), color="0.8", linewidth=0.4)
    ax1.plot(*paths.polhode.T, color="C3", linewidth=1.5)
    ax1.set_title("polhode on the inertia ellipsoid (body)")
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.plot(*paths.herpolhode.T, color="C0", linewidth=0.8)
    ax2.set_aspect("equal")
    ax2.set_title(f"herpolhode (invariable plane at d = {paths.distance:.4g})")
    fig.tight_layout()
    return fig
