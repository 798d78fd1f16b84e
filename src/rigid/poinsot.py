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


def _plane_panel(ax: Any, points: np.ndarray, joined: bool, colour: str,
                 labels: tuple[str, str], title: str) -> None:
    """A flat panel of ``points`` (n, 2): over a stated power of ten where small
    (:func:`_exponent`), equal aspect, no offset text."""
    e = _exponent(points)
    _curve(ax, points / 10.0**e, joined, colour)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(labels[0] + _over(e), fontsize=8)
    ax.set_ylabel(labels[1] + _over(e), fontsize=8)
    ax.set_title(title + _unjoined(joined, len(points)), fontsize=10)
    ax.ticklabel_format(useOffset=False, style="plain")


def _exponent(values: np.ndarray) -> int:
    """``e`` with the largest magnitude of ``values`` / 10**e in [1, 10); 0 when that
    magnitude is already of order one (0.01 to 1000), zero or not finite."""
    top = float(np.max(np.abs(values))) if values.size else 0.0
    if top == 0.0 or not np.isfinite(top) or 1e-2 <= top < 1e3:
        return 0
    return int(np.floor(np.log10(top)))


def _over(e: int) -> str:
    """The ``/ 10^e`` of an axis label whose numbers are the quantity over 10**e."""
    return "" if e == 0 else f" / $10^{{{e}}}$"


def _joinable(xy: np.ndarray) -> bool:
    """Whether every step of the path ``xy`` (n, 2) turns less than 30 degrees about
    the origin, so that a straight line between the points follows the curve."""
    if len(xy) < 2:
        return False
    turn = np.arctan2(xy[:-1, 0] * xy[1:, 1] - xy[:-1, 1] * xy[1:, 0],
                      np.sum(xy[:-1] * xy[1:], axis=-1))
    return bool(np.all(np.abs(turn) < np.pi / 6))


def _unjoined(joined: bool, n: int) -> str:
    """The title's note on a path drawn as its points."""
    if joined:
        return ""
    return "\n(one time: its point)" if n == 1 else "\n(points: the times too far apart to join)"


def _circled_axis(si: Any) -> int:
    """The principal axis the polhode goes round: the largest moment's if
    ``L^2 / 2T`` is at least the middle moment, else the smallest's."""
    sm, sw = si.scales()
    m, w = si.moments / sm, si.omega / sw
    ratio = float(np.sum((m * w) ** 2) / np.sum(m * w**2))  # L^2 / 2T, over sm
    return int(np.argmax(m)) if ratio >= float(np.sort(m)[1]) else int(np.argmin(m))


def _curve(ax: Any, xy: np.ndarray, joined: bool, color: str) -> None:
    """A path as a line if ``joined``, else as its points; its first point marked."""
    if joined:
        ax.plot(*xy.T, color=color, linewidth=1.0)
    else:
        ax.plot(*xy.T, ".", color=color, ms=2)
    ax.plot(*xy[0], "o", color="k", ms=5, label="first time")


def plot_poinsot(body: RigidBody, t: Any, *, fig: Any = None) -> Any:
    """Plot the polhode on the inertia ellipsoid, framed on itself, and the herpolhode.

    Needs matplotlib (the ``plot`` extra), imported only here.

    Three panels: the polhode on the inertia ellipsoid (body frame, 3-D); the
    polhode seen along the principal axis it goes round, framed on the curve (for
    a nearly symmetric body such as the Earth it is tiny beside the ellipsoid);
    the herpolhode in the invariable plane, about the foot of its normal.  The
    coordinates are the ellipsoid's ``x . I x = 1`` times ``sqrt(C)``, ``C`` the
    largest moment: numbers free of units and of order one on the ellipsoid
    (its semi-axes are ``sqrt(C / I)``), whatever the body's units; ``C`` is
    stated in the figure's title, in kg m^2 for a body of Quantities and in the
    caller's units for one of plain numbers.  Where the curves are small, a
    panel's numbers are its coordinates over a power of ten written in the axis
    label (``/ 10^-6``): no offset texts.

    A curve whose consecutive points are more than 30 degrees apart about its
    centre (times too far apart for the motion) is drawn as its points, not
    joined by chords.  The first time's point is marked on every panel, so that
    one time (or a body spinning about a principal axis, whose polhode is a
    point) shows as that point.

    Parameters
    ----------
    body, t
        As for :func:`poinsot`; ``t`` of one or more times.
    fig : matplotlib.figure.Figure, optional
        Drawn into (a new figure if not given).

    Returns
    -------
    matplotlib.figure.Figure
    """
    paths = poinsot(body, t)  # validates first: bad input fails before matplotlib loads

    import matplotlib.pyplot as plt  # lazy: optional dependency

    si = body.si
    big = float(np.max(si.moments))
    root_c = np.sqrt(big)  # the coordinates' factor sqrt(C) (x . I x = 1 -> of order one)
    polhode = np.asarray(getattr(paths.polhode, "value", paths.polhode)).reshape(-1, 3)
    polhode = polhode * root_c
    herpolhode = np.asarray(getattr(paths.herpolhode, "value", paths.herpolhode))
    herpolhode = herpolhode.reshape(-1, 2) * root_c
    distance = float(getattr(paths.distance, "value", paths.distance)) * root_c
    if isinstance(body.moments, u.Quantity):
        scale = f"{big:.4g} kg m$^2$"
    else:
        scale = f"{big:.4g} in the caller's units"

    if fig is None:
        fig = plt.figure(figsize=(15, 4.8))
    ax1 = fig.add_subplot(1, 3, 1, projection="3d")
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
    semi = np.sqrt(big / si.moments)
    ax1.plot_wireframe(semi[0] * np.cos(uu) * np.sin(vv), semi[1] * np.sin(uu) * np.sin(vv),
                       semi[2] * np.cos(vv), color="0.8", linewidth=0.4)
    k = _circled_axis(si)
    i, j = (k + 1) % 3, (k + 2) % 3  # (i, j, k) right-handed: seen from +k
    seen = polhode[:, [i, j]]
    joined = _joinable(seen)
    _curve(ax1, polhode, joined, "C3")
    ax1.set_box_aspect(semi)  # (the ellipsoid's own shape, not a sphere's)
    for n, set_label in enumerate((ax1.set_xlabel, ax1.set_ylabel, ax1.set_zlabel)):
        set_label(f"body axis {n + 1}, $\\rho_{n + 1}\\sqrt{{C}}$", fontsize=8)
    ax1.set_title("polhode on the inertia ellipsoid (body)", fontsize=10)

    ax2 = fig.add_subplot(1, 3, 2)
    _plane_panel(ax2, seen, joined, "C3", (f"body axis {i + 1}, $\\rho_{i + 1}\\sqrt{{C}}$",
                                          f"body axis {j + 1}, $\\rho_{j + 1}\\sqrt{{C}}$"),
                 f"polhode seen along body axis {k + 1}")
    ax3 = fig.add_subplot(1, 3, 3)
    _plane_panel(ax3, herpolhode, _joinable(herpolhode), "C0",
                 ("along e1 in the invariable plane, $x\\sqrt{C}$", "along e2, $y\\sqrt{C}$"),
                 f"herpolhode (invariable plane at $d\\sqrt{{C}}$ = {distance:.6g})")
    ax3.legend(loc="lower left", fontsize=7)
    fig.suptitle("Poinsot's construction: the inertia ellipsoid $x \\cdot I x = 1$ in "
                 f"coordinates times $\\sqrt{{C}}$ (C, the largest moment, = {scale})", fontsize=10)
    fig.tight_layout()
    return fig
