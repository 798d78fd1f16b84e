"""Sylvester (1866): confocal and contrafocal bodies, the equivalent disk, time.

Sylvester's theorem (seed, the theorem after "we derive the following theorem"):
bodies whose reciprocal moments of inertia differ by a constant ``lam``, started
parallel with the same impulsive couple ``L``, keep their principal axes equally
inclined to the invariable line, and differ only by a uniform rotation
``L lam t`` about it.  For contrafocal bodies (the *sums* of the reciprocal
moments constant) the couple is contrary and the inclinations supplementary.
"""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import ANGULAR_SPEED, TIME, Kind, wrap
from rigid._kernels import free as _fk
from rigid._shared import free_scale, free_setup_scaled, pow2
from rigid.body import RigidBody, call_units, check_body, check_moments

__all__ = ["confocal", "confocal_rotation", "contrafocal", "disk_equivalent", "time_between"]


_RECIP = Kind("a reciprocal moment of inertia", 1 / (u.kg * u.m**2))
_RECIP_UNIT = 1 / (u.kg * u.m**2)
_W_UNIT = u.rad / u.s


def _lam(body: RigidBody, lam: Any, extra: tuple[tuple[str, Any], ...] = ()) -> tuple[float, bool]:
    """``lam`` as a float in 1/(kg m^2) (SI) and whether the call is in Quantities."""
    names = ("lam", *(n for n, _ in extra))
    quantity = call_units(body, names, (lam, *(v for _, v in extra)))
    value = _RECIP("lam", lam)
    if value.shape != ():
        raise ValueError(f"Expected `lam` to be a scalar, got shape {value.shape}")
    return float(value), quantity


def _reciprocals(moments: np.ndarray, lam: float, sign: float) -> np.ndarray:
    """``1/A + lam`` (``sign`` +1, confocal) or ``lam - 1/A`` (``sign`` -1, contrafocal).

    Raises
    ------
    ValueError
        If a reciprocal moment (``1/A`` or the sum) is beyond float64 (positive),
        naming ``lam``, the index and the values.
    """
    with np.errstate(over="ignore"):  # beyond float64: refused below (-inf: not positive)
        inv = 1.0 / moments
        recip = inv + lam if sign > 0.0 else lam - inv
    bad = recip == np.inf
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected `lam` to keep the reciprocal moments within float64, got 1/A'[{k}] ="
            f" {'1/A + lam' if sign > 0.0 else 'lam - 1/A'} beyond it at index {k}, with "
            f"A = {float(moments[k])!r} and lam = {lam!r}"
        )
    return recip


def _related(body: RigidBody, recip: np.ndarray, ell: np.ndarray, quantity: bool) -> RigidBody:
    """The body with reciprocal moments ``recip`` and body angular momentum ``ell``."""
    bad = ~(recip > 0.0)
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected `lam` to leave every reciprocal moment positive, got 1/A'[{k}] = "
            f"{float(recip[k])!r} at index {k}"
        )
    with np.errstate(over="ignore", divide="ignore"):
        moments = 1.0 / recip
    if not np.all(np.isfinite(moments)):
        k = int(np.argwhere(~np.isfinite(moments))[0][0])
        raise ValueError(
            f"Expected `lam` to give finite moments, got 1/A'[{k}] = {float(recip[k])!r}"
        )
    try:
        check_moments("moments", moments)
    except ValueError as exc:
        raise ValueError(f"Expected `lam` to give a realisable body: {exc}") from None
    with np.errstate(over="ignore"):
        omega = ell / moments
    if not np.all(np.isfinite(omega)):
        raise ValueError(f"Expected `lam` to give a finite omega, got moments {moments.tolist()}")
    return RigidBody.from_si(moments, body.attitude, omega, quantity=quantity)


def confocal(body: RigidBody, lam: Any) -> RigidBody:
    """The body confocal to ``body``: ``1/A' = 1/A + lam`` (and B, C), same couple.

    Parameters
    ----------
    body : RigidBody
    lam : float or Quantity, 1/(kg m^2)
        Difference of the reciprocal moments (a Quantity for a body with units).

    Returns
    -------
    RigidBody
        Same attitude, same body-frame angular momentum ``L``, so the initial
        angular velocity is ``omega' = L / moments' = omega + lam L``.  In space
        ``omega'_space = omega_space + lam L_space``: the related body turns
        about the invariable line at the extra uniform rate ``lam |L|``
        (:func:`confocal_rotation`).

    Raises
    ------
    ValueError
        If a reciprocal moment becomes non-positive or leaves float64 (``1/A + lam``
        beyond 1.8e308), or the new moments break the triangle inequality (not a
        realisable body); the same for :func:`contrafocal`.

    Notes
    -----
    Sylvester (1866), the confocal theorem: "the parallelism of the axes may be
    restored by turning B1 ... about the axis of the couple through angles ...
    L lambda_1 t".  With our sign of ``lam`` (``1/A' = 1/A + lam``) the related
    body is ahead by ``+lam |L| t`` in the positive sense about ``L``.

    Examples
    --------
    >>> b = RigidBody([1.0, 2.0, 2.5], omega=[1.0, 0.5, 0.2])
    >>> print(confocal(b, 0.1).omega.round(6))
    [1.1  0.6  0.25]
    """
    body = check_body(body)
    lam, quantity = _lam(body, lam)
    si = body.si
    return _related(body, _reciprocals(si.moments, lam, 1.0), si.angular_momentum_body,
                    quantity)


def contrafocal(body: RigidBody, lam: Any) -> RigidBody:
    """The contrafocal body: ``1/A' = lam - 1/A`` (and B, C), with the contrary couple.

    Returns
    -------
    RigidBody
        Same attitude, body angular momentum ``-L``, so ``omega' = omega - lam L``.
        Its principal axes make, at every time, the same angles with the invariable
        line ``L`` of ``body`` as ``body``'s axes do (supplementary angles with its
        own line ``-L``: Sylvester's "equal but contrary"), and it differs from
        ``body`` by the uniform rotation ``-lam |L| t`` about ``L``.

    Notes
    -----
    Sylvester (1866), the contrafocal case: "two equal and coaxial but contrary
    impulsive couples ... their principal axes will continue ... to make equal
    but contrary angles with the invariable line".

    Examples
    --------
    >>> b = RigidBody([1.0, 2.0, 2.5], omega=[1.0, 0.5, 0.2])
    >>> print(contrafocal(b, 2.0).moments.round(6))  # 1 / (2 - 1/A) ...
    [1.       0.666667 0.625   ]
    """
    body = check_body(body)
    lam, quantity = _lam(body, lam)
    si = body.si
    return _related(body, _reciprocals(si.moments, lam, -1.0), -si.angular_momentum_body,
                    quantity)


def confocal_rotation(body: RigidBody, lam: Any, t: Any) -> Quaternion:
    """The rotation ``exp(lam |L| t L_hat / 2)`` taking ``body``'s attitude to its confocal one.

    ``confocal_att(t) = confocal_rotation(body, lam, t) * att(t)``; for the
    contrafocal body use ``-lam``.

    Parameters
    ----------
    body : RigidBody
    lam : float or Quantity, 1/(kg m^2)
        The constant of the confocal relation (:func:`confocal`).
    t : array_like or Quantity, s
        Times (Quantities if ``body`` was built from Quantities).

    Returns
    -------
    Quaternion, shape t.shape
        Identity for a body at rest.

    Examples
    --------
    >>> b = RigidBody([1.0, 2.0, 2.5], omega=[0.0, 0.0, 1.0])
    >>> print(confocal_rotation(b, 0.1, 2.0).as_array().round(6))
    [0.968912 0.       0.       0.247404]
    """
    body = check_body(body)
    lam_f, _ = _lam(body, lam, (("t", t),))
    t_s = TIME("t", t)
    ell = body.si.angular_momentum_space
    big = float(np.max(np.abs(ell)))
    if big == 0.0:
        return Quaternion(np.broadcast_to([1.0, 0.0, 0.0, 0.0], t_s.shape + (4,)).copy())
    norm = big * float(np.linalg.norm(ell / big))
    with np.errstate(over="ignore", invalid="ignore"):
        angle = lam_f * norm * t_s
    # NaN only as inf x 0: lam |L| beyond float64 at t = 0, where the angle is 0
    angle = np.where(np.isnan(angle), 0.0, angle)
    bad = ~np.isfinite(angle)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(np.atleast_1d(bad))[0]) if t_s.ndim else ()
        raise ValueError(
            f"Expected `lam` |L| `t` to be finite (the angle), got t = "
            f"{float(t_s[idx])!r} with lam = {lam_f!r} and |L| = {norm!r}"
        )
    return Quaternion.from_axis_angle(ell / norm, angle)


def _disk_lams(moments: np.ndarray) -> list[tuple[str, float]]:
    out = []
    r = 1.0 / moments
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        a, b, c = r[i], r[j], r[k]
        disc = (c - a) * (c - b)
        if disc < 0.0:
            continue
        for sgn in (1.0, -1.0):
            out.append(("confocal", -c + sgn * np.sqrt(disc)))
            out.append(("contrafocal", c + sgn * np.sqrt(disc)))
    return out


def disk_equivalent(body: RigidBody) -> tuple[RigidBody, str, Any, Any]:
    """Sylvester's reduction of a free body to an equivalent flat disk (``C' = A' + B'``).

    Returns
    -------
    disk : RigidBody
        The disk (one moment equals the sum of the other two).
    relation : str
        ``"confocal"`` (Sylvester's direct reduction) or ``"contrafocal"``
        (his supplemental reduction).
    lam : float or Quantity, 1/(kg m^2)
        The constant of the relation (see :func:`confocal`, :func:`contrafocal`);
        a Quantity for a body built from Quantities.
    delta : float or Quantity, (rad/s)^2
        The constant ``|omega_disk|^2 - |omega_body|^2`` along the motion:
        ``lam (4T + lam L^2)`` (confocal, ``omega' = omega + lam L``) or
        ``lam (lam L^2 - 4T)`` (contrafocal, ``omega' = omega - lam L``), using
        ``omega . L = 2T``.  Sylvester (1866) states that this difference of the
        squared velocities is "constant throughout the motion".

    Notes
    -----
    For the disk axis on body axis ``k`` (reciprocal moments a, b, c with c on
    axis k), ``1/(c + lam) = 1/(a + lam) + 1/(b + lam)`` gives
    ``lam = -c +- sqrt((c - a)(c - b))`` (confocal) and the contrafocal
    ``lam = c +- sqrt((c - a)(c - b))``.  Sylvester uses the direct reduction when
    ``L^2 / 2T > B`` and the supplemental one otherwise; we follow his choice
    when it gives positive moments and otherwise take any valid root.

    Examples
    --------
    >>> disk, rel, lam, delta = disk_equivalent(RigidBody([1.0, 2.0, 2.5], omega=[1, 0.5, 0.2]))
    >>> m = np.sort(disk.moments)
    >>> print(rel, bool(abs(m[2] - m[0] - m[1]) < 1e-12 * m[2]))
    contrafocal True
    """
    body = check_body(body)
    # On moments / sm and omega / sw (powers of two): lam = lam_s / sm and
    # delta = sw^2 delta_s, so nothing under- or overflows on the way.
    si = body.si
    sm, sw = si.scales()
    moments = si.moments / sm
    lb = moments * (si.omega / sw)
    ell2 = float(np.sum(lb * lb))
    t2 = float(np.sum(lb * (si.omega / sw)))
    mid = float(np.sort(moments)[1])
    prefer = "confocal" if ell2 > t2 * mid else "contrafocal"
    valid = []
    for rel, lam in _disk_lams(moments):
        recip = 1.0 / moments + lam if rel == "confocal" else lam - 1.0 / moments
        if np.all(recip > 0.0):
            valid.append((rel != prefer, rel, float(lam)))
    if not valid:  # pragma: no cover - a real root always exists (Sylvester 1866)
        raise ValueError(f"Expected `body` to admit a disk reduction, got moments {moments}")
    valid.sort()
    _, rel, lam_s = valid[0]
    q = body.quantity
    sign = 1.0 if rel == "confocal" else -1.0
    recip = sign / moments + lam_s if rel == "confocal" else lam_s - 1.0 / moments
    with np.errstate(over="ignore"):
        disk_moments = (1.0 / recip) * sm
        lam = lam_s / sm
        delta = lam_s * (sign * 2.0 * t2 + lam_s * ell2) * sw * sw
    # lam = 0 from a lam_s != 0 is an underflow; lam_s = 0 is a body that is a disk
    # already (C = A + B in floats): its own disk equivalent, confocal with lam = 0
    if not (np.all(np.isfinite(disk_moments)) and np.isfinite(lam) and np.isfinite(delta)
            and (lam != 0.0 or lam_s == 0.0)):
        raise ValueError(
            f"Expected `body` to have a disk equivalent within float64, got moments "
            f"{si.moments.tolist()} and omega {si.omega.tolist()}"
        )
    disk = RigidBody.from_si(disk_moments, body.attitude,
                             sign * si.angular_momentum_body / disk_moments, quantity=q)
    return disk, rel, wrap(lam, _RECIP_UNIT, q), wrap(delta, _W_UNIT**2, q)


def time_between(body: RigidBody, omega1: Any, omega2: Any) -> Any:
    """Time for ``body`` to pass from angular velocity ``omega1`` to ``omega2``.

    Both must lie on the same polhode (same ``T`` and ``|L|`` with the body's
    moments).  The answer is the elliptic integral of the first kind
    ``t = [F(phi2 | m) - F(phi1 | m)] / lambda`` (mod the period ``4K/lambda``),
    ``sn(phi) = omega_2 / b``, ``cn(phi) = omega_1 / a`` in the working frame,
    which is Sylvester's "time as an elliptic integral" (Sylvester 1866).

    Parameters
    ----------
    body : RigidBody
    omega1, omega2 : array_like or Quantity, shape (3,), rad/s
        Body-frame angular velocities (Quantities for a body with units).

    Returns
    -------
    float or Quantity, s
        ``0 <= t < period`` (a Quantity in s when the call was in Quantities).

    Raises
    ------
    ValueError
        If the two states are not on one polhode (relative mismatch of ``T`` or
        ``|L|`` above 1e-10), or the motion is steady or on the separatrix beyond
        reach (``omega2`` not after ``omega1``, or on another of its heteroclinic
        arcs: one of them is never reached from another).

    Examples
    --------
    >>> from rigid.free import free_motion_arrays
    >>> body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])
    >>> _, w = free_motion_arrays(body.moments, [1, 0, 0, 0], body.omega, 2.5)
    >>> print(round(time_between(body, body.omega, w), 12))
    2.5
    """
    body = check_body(body)
    quantity = call_units(body, ("omega1", "omega2"), (omega1, omega2))
    w1 = ANGULAR_SPEED("omega1", omega1)
    w2 = ANGULAR_SPEED("omega2", omega2)
    for name, w in (("omega1", w1), ("omega2", w2)):
        if w.shape != (3,):
            raise ValueError(f"Expected `{name}` to have shape (3,), got {w.shape}")
    if not np.any(w1):  # (its T and |L| are 0: no polhode to measure time along)
        raise ValueError(f"Expected `omega1` nonzero (a body at rest stays at rest: no time "
                         f"leads from it to another state), got {omega1!r}")
    # homogeneous: moments / sm and omega / sw (powers of two), times scale by 1 / sw
    sm = pow2(body.si.moments)
    sw = max(pow2(w1), pow2(w2))
    mom = body.si.moments / sm
    w1s = w1 / sw
    w2s = w2 / sw
    e1, e2 = np.sum(mom * w1s * w1s), np.sum(mom * w2s * w2s)
    l1, l2 = np.sum((mom * w1s) ** 2), np.sum((mom * w2s) ** 2)
    if abs(e1 - e2) > 1e-10 * e1 or abs(l1 - l2) > 1e-10 * l1:
        raise ValueError(  # (relative differences: the same for the body as for the
            # scaled problem, whose values would not be the body's)
            f"Expected `omega2` on the polhode of `omega1` (the same T and |L|, to 1e-10), "
            f"got its 2T {float(e2 / e1 - 1):+.3g} and its L^2 {float(l2 / l1 - 1):+.3g} "
            f"(relative) off those of `omega1`"
        )
    # one scale for both states (the kernel's rates and phases must compare), lifted
    # when a thin body needs larger rates than max|omega| / sw (see free_scale)
    sw *= min(free_scale(body.si.moments, w, f"`{n}`") / pow2(w)
              for n, w in (("omega1", w1), ("omega2", w2)))
    q = np.array([1.0, 0.0, 0.0, 0.0])
    p1, _ = free_setup_scaled(body.si.moments, q, w1, "`omega1`", sw)
    p2, _ = free_setup_scaled(body.si.moments, q, w2, "`omega2`", sw)
    kind = p1[_fk.KIND]
    if kind == 0.0:
        raise ValueError(
            f"Expected a non-steady motion for `omega1`, got a steady rotation {omega1!r}"
        )
    same_frame = np.array_equal(p1[_fk.P : _fk.P + 9], p2[_fk.P : _fk.P + 9])
    if p2[_fk.KIND] != kind or not same_frame:
        raise ValueError(
            f"Expected `omega2` on the same branch of the polhode as `omega1`, got "
            f"omega1 = {omega1!r}, omega2 = {omega2!r}"
        )
    du = p2[_fk.U0] - p1[_fk.U0]
    if kind == 1.0:
        dt = float(np.mod(du, 4.0 * p1[_fk.K]) / p1[_fk.LAM])
    elif np.sign(p2[_fk.A]) != np.sign(p1[_fk.A]):
        # the separatrix is four heteroclinic arcs; on each omega_W1 = a sech(u) keeps
        # the sign of a (Landau & Lifshitz, Mechanics §37): the other arc is never reached
        raise ValueError(
            f"Expected `omega2` on the arc of the separatrix of `omega1` (reached from it), "
            f"got {omega2!r} on another arc, never reached from `omega1` = {omega1!r}"
        )
    elif du < 0.0:
        raise ValueError(
            f"Expected `omega2` after `omega1` on the separatrix, got it before ({omega2!r})"
        )
    else:
        dt = float(du / p1[_fk.LAM])
    return wrap(np.float64(dt / sw), u.s, quantity)
