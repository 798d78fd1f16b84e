"""Cayley's (1843) Rodrigues parameters (lambda, mu, nu): kinematics and composition.

Correspondence with the quaternion core
---------------------------------------
Cayley's direction cosines alpha, alpha', alpha'' are the cosines of the body
axis x_1 with the fixed axes x, y, z, i.e. the body x_1 axis expressed in space
(likewise beta..., gamma... for y_1, z_1).  His rational forms

    kappa alpha = 1 + lambda^2 - mu^2 - nu^2,   kappa alpha' = 2 (lambda mu + nu), ...

are the entries R[0, 0], R[1, 0], ... of the rotation matrix of the *active*
rotation v -> q v q^-1 of the unit quaternion q = (1, lambda, mu, nu) / sqrt(kappa)
(e.g. R[1, 0] = 2 (x y + w z) = 2 (lambda mu + nu) / kappa).  So Cayley's
(lambda, mu, nu) is the Gibbs vector q_vec / q_w of *our attitude itself* (body
to space, not its inverse), the columns of R are his (alpha, alpha', alpha''),
(beta, ...), (gamma, ...), and his p = gamma dbeta/dt + ... = z_1 . d y_1 / dt is
the body-frame angular velocity component along x_1.  With this identification
his kinematic equations are exactly dq/dt = q (0, omega) / 2 written for
g = q_vec / q_w (see :func:`gibbs_rate`).

Composition (Cayley's Pi formulas): of (l, m, n) and (l_1, m_1, n_1), as he
writes them, Pi = 1 - l l_1 - m m_1 - n n_1, Pi lambda = l + l_1 + n_1 m - n m_1,
...; this is the Hamilton product (1, g_a)(1, g_b) = (1 - g_a.g_b, g_a + g_b +
g_a x g_b), so :func:`compose_gibbs` (g_a, g_b) is the Gibbs vector of q_a q_b:
the active rotation g_b applied first, then g_a (R(q_a q_b) = R(q_a) R(q_b)).  His P_0 system
(the end of the paper) writes the general solution of the kinematics as the
composition of arbitrary constants (l, m, n) with a particular solution
(lambda_0, mu_0, nu_0): q(t) = q_lmn q_0(t).  This is what re-centring uses: the
Gibbs vector is infinite at a half-turn, so when |g_0| passes a threshold the
constant offset absorbs it and g_0 restarts at zero
(:func:`cayley_propagate`).  The offset is kept in homogeneous form
(P_0, P_0 lambda, P_0 mu, P_0 nu), i.e. as a unit quaternion, so that the
offset itself may pass any half-turn.

A printed sign: the inverse system in the closing *Note* of the seed reads
(1 + lambda lambda_0 + ...) l = lambda - lambda_0 + nu_0 mu - nu mu_0; solving the
P_0 system (or using his own P_1 formulas) gives instead
lambda - lambda_0 + nu mu_0 - mu nu_0 (the cross term has the opposite sign).
:func:`relative_gibbs` implements the derived form, and the test suite checks
it inverts the P_0 system.
"""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.units import (
    ANGULAR_SPEED,
    DIMENSIONLESS,
    Kind,
    is_quantity,
    time_quantity,
    wrap,
)
from hamilton_orbits.validation import check_trailing, first_index
from rigid._kernels import euler as _k
from rigid.integrators import integrate

__all__ = [
    "cayley_propagate",
    "compose_gibbs",
    "direction_cosines",
    "gibbs_rate",
    "omega_from_gibbs_rate",
    "relative_gibbs",
]


#: a rate of Cayley's parameters (pure numbers) per unit of time
_PER_TIME = Kind("a rate (per unit of time)", u.s**-1)


def _vec(name: str, value: Any) -> np.ndarray:
    return check_trailing(name, DIMENSIONLESS(name, value), 3)


def _guarded(names: tuple[str, ...], what: str, compute: Any) -> np.ndarray:
    """``compute()`` without floating-point warnings; a result beyond float64 raises."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        out = np.asarray(compute())
    bad = ~np.isfinite(out)
    if np.any(bad):
        index = tuple(int(i) for i in np.argwhere(np.atleast_1d(bad))[0])
        args = ", ".join(f"`{n}`" for n in names)
        raise ValueError(
            f"Expected {args} with a representable {what}, got "
            f"{float(np.atleast_1d(out)[index])!r} at index {index} (beyond float64)"
        )
    return out


def _pair(names: tuple[str, str], a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    try:
        a2, b2 = np.broadcast_arrays(a, b)
    except ValueError as exc:
        raise ValueError(
            f"Expected `{names[0]}`, `{names[1]}` to broadcast together, got shapes "
            f"{a.shape}, {b.shape}"
        ) from exc
    return a2, b2


def gibbs_rate(gibbs: Any, omega: Any) -> np.ndarray:
    """Cayley's kinematic equations: d(lambda, mu, nu)/dt from the body rates (p, q, r).

    2 lambda' = (1 + lambda^2) p + (lambda mu - nu) q + (nu lambda + mu) r,
    2 mu'     = (lambda mu + nu) p + (1 + mu^2) q + (mu nu - lambda) r,
    2 nu'     = (nu lambda - mu) p + (mu nu + lambda) q + (1 + nu^2) r
    (Cayley 1843, p. 228), i.e. g' = (omega + g x omega + g (g . omega)) / 2.

    Parameters
    ----------
    gibbs : array_like, shape (..., 3)
        Cayley's (lambda, mu, nu) = q_vec / q_w of the body-to-space attitude.
    omega : array_like or Quantity, shape (..., 3)
        Body-frame angular velocity (p, q, r) (rad/s when a Quantity).

    Returns
    -------
    ndarray or Quantity, shape (..., 3)
        d(lambda, mu, nu)/dt (1/s when ``omega`` was a Quantity).

    Raises
    ------
    ValueError
        For NaN / inf, wrong shapes or shapes that do not broadcast.

    Examples
    --------
    >>> gibbs_rate([0.0, 0.0, 0.0], [0.2, 0.4, 0.6])
    array([0.1, 0.2, 0.3])
    """
    g = _vec("gibbs", gibbs)
    w = check_trailing("omega", ANGULAR_SPEED("omega", omega), 3)
    g, w = _pair(("gibbs", "omega"), g, w)
    out = _guarded(("gibbs", "omega"), "Gibbs rate", lambda: _k.gibbs_dot_gufunc(g, w))
    return wrap(out, 1 / u.s, is_quantity(omega))


def omega_from_gibbs_rate(gibbs: Any, gibbs_dot: Any) -> np.ndarray:
    """Body rates from Cayley's parameters and their rates.

    kappa p = 2 (lambda' + nu mu' - nu' mu), kappa q = 2 (-nu lambda' + mu' + nu' lambda),
    kappa r = 2 (mu lambda' - lambda mu' + nu'), kappa = 1 + lambda^2 + mu^2 + nu^2
    (Cayley 1843, p. 228).  The inverse of :func:`gibbs_rate`.

    Parameters
    ----------
    gibbs : array_like, shape (..., 3)
        (lambda, mu, nu).
    gibbs_dot : array_like or Quantity, shape (..., 3)
        d(lambda, mu, nu)/dt (1/time; a Quantity as :func:`gibbs_rate` gives it).

    Returns
    -------
    ndarray or Quantity, shape (..., 3)
        (p, q, r) in the same time unit (rad/s when ``gibbs_dot`` was a Quantity).

    Raises
    ------
    ValueError
        For NaN / inf, wrong shapes or shapes that do not broadcast.

    Examples
    --------
    >>> omega_from_gibbs_rate([0.0, 0.0, 1.0], [0.0, 0.0, 1.0])
    array([0., 0., 1.])
    """
    g = _vec("gibbs", gibbs)
    quantity = is_quantity(gibbs_dot)
    d = check_trailing("gibbs_dot", _PER_TIME("gibbs_dot", gibbs_dot), 3) if quantity else _vec(
        "gibbs_dot", gibbs_dot)
    g, d = _pair(("gibbs", "gibbs_dot"), g, d)
    out = _guarded(("gibbs", "gibbs_dot"), "omega", lambda: _k.gibbs_omega_gufunc(g, d))
    return wrap(out, u.rad / u.s, quantity)


def direction_cosines(gibbs: Any) -> np.ndarray:
    """Cayley's direction cosines as rational functions of (lambda, mu, nu).

    kappa alpha = 1 + lambda^2 - mu^2 - nu^2, kappa alpha' = 2 (lambda mu + nu),
    kappa alpha'' = 2 (nu lambda - mu), kappa beta = 2 (lambda mu - nu), ...
    (Cayley 1843, p. 225).  Returned as the matrix whose columns are
    (alpha, alpha', alpha''), (beta, beta', beta''), (gamma, gamma', gamma''):
    the body axes in space, i.e. the rotation matrix of the body-to-space
    attitude (equal to ``Quaternion.from_gibbs(gibbs).as_rotation_matrix()``).

    Parameters
    ----------
    gibbs : array_like, shape (..., 3)
        (lambda, mu, nu).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    ValueError
        For NaN / inf or a wrong shape.

    Examples
    --------
    A quarter turn about z: lambda = mu = 0, nu = tan(pi/4) = 1.

    >>> np.round(direction_cosines([0.0, 0.0, 1.0]), 15) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    g = _vec("gibbs", gibbs)
    # Homogeneous of degree 0 in (1, lambda, mu, nu): divide all four by
    # s = max(1, |lambda|, |mu|, |nu|) so that nothing overflows for large Gibbs
    # vectors (near a half-turn); w = 1/s stands for Cayley's 1.
    sc = np.maximum(1.0, np.max(np.abs(g), axis=-1))
    w = 1.0 / sc
    lam, mu, nu = g[..., 0] / sc, g[..., 1] / sc, g[..., 2] / sc
    kap = w * w + lam * lam + mu * mu + nu * nu
    ww = w * w
    r = np.empty(g.shape[:-1] + (3, 3))
    # column 0: alpha, alpha', alpha''
    r[..., 0, 0] = ww + lam * lam - mu * mu - nu * nu
    r[..., 1, 0] = 2.0 * (lam * mu + w * nu)
    r[..., 2, 0] = 2.0 * (nu * lam - w * mu)
    # column 1: beta, beta', beta''
    r[..., 0, 1] = 2.0 * (lam * mu - w * nu)
    r[..., 1, 1] = ww + mu * mu - nu * nu - lam * lam
    r[..., 2, 1] = 2.0 * (mu * nu + w * lam)
    # column 2: gamma, gamma', gamma''
    r[..., 0, 2] = 2.0 * (nu * lam + w * mu)
    r[..., 1, 2] = 2.0 * (mu * nu - w * lam)
    r[..., 2, 2] = ww + nu * nu - lam * lam - mu * mu
    return r / kap[..., None, None]


def _check_pi(pi: np.ndarray, what: str, names: tuple[str, str]) -> None:
    bad = ~(np.abs(pi) > 0.0)
    if np.any(bad):
        index = first_index(np.atleast_1d(bad)) if bad.ndim else ()
        where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
        raise ValueError(
            f"Expected `{names[0]}`, `{names[1]}` whose {what} is not a half-turn, got "
            f"Cayley's Pi = {float(np.atleast_1d(pi)[index] if index else pi)!r}{where}: its "
            "Gibbs vector is infinite. Compose quaternions (Quaternion.from_gibbs) instead."
        )


def compose_gibbs(first: Any, second: Any) -> np.ndarray:
    """Cayley's composition of two displacements (his Pi formulas).

    Pi = 1 - l l_1 - m m_1 - n n_1, Pi lambda = l + l_1 + n_1 m - n m_1,
    Pi mu = m + m_1 + l_1 n - l n_1, Pi nu = n + n_1 + m_1 l - m l_1
    (Cayley 1843, p. 226, with the cross terms as in his P_0 system; the
    transcription's Pi mu line prints "l m_1" for "l n_1").  The result is the
    Gibbs vector of q(first) q(second) (Hamilton product): as active rotations,
    ``second`` is applied first, then ``first`` (``R(q(first) q(second)) =
    R(q(first)) R(q(second))``; the names follow Cayley's order of writing).

    Parameters
    ----------
    first, second : array_like, shape (..., 3)
        (l, m, n) and (l_1, m_1, n_1): the rotation applied second, and the one
        applied first.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    ValueError
        For NaN / inf, wrong shapes, or if the composition is an exact half-turn
        (Pi = 0), naming the index.

    Examples
    --------
    A quarter turn about y, then one about x (tan(pi/4) = 1; z goes to x under
    the first, and x stays under the second):

    >>> compose_gibbs([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    array([1., 1., 1.])
    """
    a = _vec("first", first)
    b = _vec("second", second)
    a, b = _pair(("first", "second"), a, b)
    (a, sa), (b, sb) = _homogeneous(a), _homogeneous(b)
    with np.errstate(over="ignore", invalid="ignore"):
        pi = sa * sb - np.sum(a * b, axis=-1)
    _check_pi(pi, "composition", ("first", "second"))
    return _guarded(("first", "second"), "composition",
                    lambda: (sb[..., None] * a + sa[..., None] * b + np.cross(a, b))
                    / pi[..., None])


def _homogeneous(g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(g s, s)``: the homogeneous form ``s (1, g)`` of Gibbs vectors, ``s`` a power
    of two taking a row beyond 1e150 to order 1 (exact), else 1 (the same bits as
    ``(g, 1)``): Cayley's Pi and its cross products of such rows cannot overflow
    (the composition of two of 1e155, an ordinary quarter turn, raised "nan")."""
    big = np.max(np.abs(g), axis=-1) > 1e150
    if not np.any(big):
        return g, np.ones(g.shape[:-1])
    e = np.where(big, np.frexp(np.max(np.abs(g), axis=-1))[1], 0)
    return np.ldexp(g, -e[..., None]), np.ldexp(1.0, -e)


def relative_gibbs(gibbs: Any, gibbs0: Any) -> np.ndarray:
    """The constants (l, m, n) of Cayley's P_0 system: compose_gibbs(l, g0) == g.

    (1 + lambda lambda_0 + mu mu_0 + nu nu_0) l = lambda - lambda_0 + nu mu_0 - mu nu_0,
    and cyclically (derived from the P_0 system and Cayley's P_1 formulas; the
    seed's Note prints the cross term with the opposite sign, see the module
    docstring).  This is the Gibbs vector of q(g) q(g0)^-1.

    Parameters
    ----------
    gibbs, gibbs0 : array_like, shape (..., 3)
        (lambda, mu, nu) and the particular solution (lambda_0, mu_0, nu_0).

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    ValueError
        For NaN / inf, wrong shapes, or a half-turn between them (the
        denominator is 0).

    Examples
    --------
    >>> g0 = np.array([0.1, -0.2, 0.3])
    >>> l = relative_gibbs([0.4, 0.5, -0.6], g0)
    >>> np.round(compose_gibbs(l, g0), 12) + 0.0
    array([ 0.4,  0.5, -0.6])
    """
    g = _vec("gibbs", gibbs)
    g0 = _vec("gibbs0", gibbs0)
    g, g0 = _pair(("gibbs", "gibbs0"), g, g0)
    (g, s), (g0, s0) = _homogeneous(g), _homogeneous(g0)
    with np.errstate(over="ignore", invalid="ignore"):
        den = s * s0 + np.sum(g * g0, axis=-1)
    _check_pi(den, "relative rotation", ("gibbs", "gibbs0"))
    return _guarded(("gibbs", "gibbs0"), "relative rotation",
                    lambda: (s0[..., None] * g - s[..., None] * g0 - np.cross(g, g0))
                    / den[..., None])


def cayley_propagate(
    body: Any,
    t_end: Any,
    dt: Any,
    *,
    n_out: int = 101,
    torque: Any = None,
    recentre: float = 1.0,
):
    """Integrate Euler's equations with the kinematics in Cayley's parameters.

    Classical fourth-order Runge-Kutta on (lambda_0, mu_0, nu_0, p, q, r) with
    re-centring by Cayley's P_0 system: the attitude is off (1, g_0)/sqrt(kappa_0)
    with a constant offset; when a step takes |g_0| above ``recentre``
    (tan(theta/2), so 1.0 means a quarter turn from the current centre) the
    offset absorbs g_0 (Cayley's Pi composition in homogeneous form) and g_0
    restarts at zero.  The Gibbs vector therefore stays bounded and the motion
    passes half-turns without loss.  This is a demonstration of Cayley's form;
    for production use :func:`rigid.integrators.integrate`.

    Parameters
    ----------
    body : RigidBody
        Initial state (moments, attitude, omega).
    t_end : float, array_like, Quantity or TimeDelta
        Time span (s when plain numbers; an astropy TimeDelta is the Quantity in
        days it holds), or an array of output times as ``t`` of
        :func:`rigid.integrators.integrate`.
    dt : float, Quantity or TimeDelta
        Step (rounded so that a whole number of steps spans ``t_end``).
    n_out : int, optional
        Number of equally spaced output times (including 0 and ``t_end``) for an
        end time ``t_end``.  Default 101.
    torque : torque object or None, optional
        See :mod:`rigid.euler`.
    recentre : float, optional
        Threshold on |g_0| (> 0).  Default 1.0.

    Returns
    -------
    RigidTrajectory
        With ``n_recentre`` the number of re-centrings performed.

    Raises
    ------
    ValueError
        For bad input (see :func:`rigid.integrators.integrate`) or
        ``recentre <= 0``.

    Examples
    --------
    A sphere spinning at 1 rad/s about z for 4 s turns by 4 rad, past a half-turn.

    >>> from rigid import RigidBody
    >>> b = RigidBody([1.0, 1.0, 1.0], omega=[0.0, 0.0, 1.0])
    >>> tr = cayley_propagate(b, 4.0, 0.01, n_out=2)
    >>> round(float(tr.attitude[-1].as_axis_angle()[1]), 9), tr.n_recentre
    (2.283185307, 2)
    """
    r = DIMENSIONLESS.scalar("recentre", recentre)
    if not r > 0.0:
        raise ValueError(f"Expected `recentre` > 0, got {r!r}")
    t_end = time_quantity(t_end)  # (a TimeDelta: the Quantity in days it holds)
    return integrate(body, _output_grid(t_end, n_out), dt=dt, method="cayley_rk4",
                     torque=torque, recentre=r)


def _output_grid(t_end: Any, n_out: Any) -> Any:
    """``n_out`` equally spaced times from 0 to an end time ``t_end`` (an array of
    times passes as it is)."""
    if np.ndim(getattr(t_end, "value", t_end)) != 0:
        return t_end
    ok = isinstance(n_out, (int, np.integer)) and not isinstance(n_out, bool)
    if not ok or not 2 <= n_out <= 1e9:
        raise ValueError(f"Expected `n_out` to be an integer in [2, 1e9], got {n_out!r}")
    return np.linspace(0.0 * t_end, t_end, int(n_out))
