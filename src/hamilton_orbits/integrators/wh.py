"""Wisdom-Holman map in democratic-heliocentric (default) or Jacobi coordinates.

Wisdom & Holman (1991), AJ 102, 1528, in the democratic-heliocentric form of
Duncan, Levison & Lee (1998), AJ 116, 2067, section 3: with heliocentric
positions ``Q_i = r_i - r_0`` and barycentric velocities ``u_i`` of the bodies
``i >= 1`` (the central body is the one of largest GM), the Hamiltonian splits
into

- the Kepler part, each body on a Kepler orbit about ``G M_0`` (advanced
  exactly by the universal-variable kernel
  :func:`hamilton_orbits._kernels.kepler.propagate_uv`, shared, not copied:
  the drift loop inlines its body, ``propagate_uv_inline``);
- the interaction part, the mutual attraction of the bodies ``i >= 1``
  (Hamilton's equation (B) without the central body), a kick of the ``u_i``;
- the "jump" ``|sum_i m_i u_i|^2 / (2 m_0)``, a drift of every ``Q_i`` by
  ``dt sum_i G m_i u_i / (G m_0)``;

and the barycentre moves uniformly.  One step is the second-order symmetric
composition that rebound's WHFast uses for these coordinates (Rein & Tamayo
2015, MNRAS 452, 376): Kepler dt/2, jump dt/2, interaction dt, jump dt/2,
Kepler dt/2; the Kepler halves of consecutive steps are merged, so each step
costs one Kepler solve per body and one force evaluation.  Effects listed in
the right-hand side (``rhs.extra``, velocity-independent only) are added to
the interaction kick, evaluated at the inertial positions; their net
acceleration of the barycentre moves the barycentre.

With ``coordinates="jacobi"`` (Wisdom & Holman 1991) body ``i`` moves on a
Kepler orbit about the total mass ``eta_i`` of the bodies up to it, about the
barycentre of the bodies before it; the kick is the inertial acceleration in
Jacobi form plus ``G eta_i r'_i / |r'_i|^3`` (the part the Kepler step already
took), and there is no jump.

Velocity-dependent effects are refused (the kick would not be symplectic).
With Jacobi coordinates the third-order symplectic corrector of Wisdom,
Holman & Touma (1996) is available (``corrector=3``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels import kepler as _kepler
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._validation import ConvergenceError
from hamilton_orbits.integrators import _setup

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "COORDINATES", "NAME", "default_step", "run"]

NAME = "wh"
ACCEPTS_VELOCITY_DEPENDENT = False
COORDINATES = ("democratic_heliocentric", "jacobi")

_F1 = types.float64[::1]
_F2 = types.float64[:, ::1]


@njit(cache=True)
def _no_extra(r, v, gm, acc):  # pragma: no cover - compiled
    """Placeholder for ``rhs.extra`` when no effect is listed (never called)."""
    return


@njit(cache=True)
def _kepler_all(q, u, mu, tau):  # pragma: no cover - compiled
    """Advance every body ``i >= 1`` on its Kepler orbit about ``mu[i]`` by ``tau``
    (the shared kernel inlined: the bodies' solves overlap in the processor).

    Returns the index of the first failure (NaN from the kernel), else -1."""
    for i in range(1, q.shape[0]):
        x, y, z, vx, vy, vz = _kepler.propagate_uv_inline(
            q[i, 0], q[i, 1], q[i, 2], u[i, 0], u[i, 1], u[i, 2], mu[i], tau
        )
        if not math.isfinite(x + y + z + vx + vy + vz):
            return i
        q[i, 0] = x
        q[i, 1] = y
        q[i, 2] = z
        u[i, 0] = vx
        u[i, 1] = vy
        u[i, 2] = vz
    return -1


@njit(cache=True, inline="always")
def _jump(q, u, gm, tau):  # pragma: no cover - compiled
    """The drift of the ``Q_i`` under ``|sum m_i u_i|^2 / (2 m_0)`` for a time ``tau``."""
    n = q.shape[0]
    px = 0.0
    py = 0.0
    pz = 0.0
    for i in range(1, n):
        px += gm[i] * u[i, 0]
        py += gm[i] * u[i, 1]
        pz += gm[i] * u[i, 2]
    f = tau / gm[0]
    for i in range(1, n):
        q[i, 0] += f * px
        q[i, 1] += f * py
        q[i, 2] += f * pz


@njit(
    types.Tuple((types.int64, types.int64))(
        _setup.ACCEL_TYPE,
        types.boolean,
        _F2,
        _F2,
        _F1,
        _F1,
        _F1,
        types.float64,
        types.int64,
        types.float64,
    ),
    cache=True,
)
def _advance(
    extra, has_extra, q, u, gm, gm_p, com, dt, n_steps, dt_last
):  # pragma: no cover - compiled
    """``n_steps`` steps (the last of length ``dt_last``) from and to synchronised
    coordinates, in place.  ``q``, ``u``: heliocentric positions and
    barycentric velocities (row 0 unused); ``gm_p``: ``gm`` with ``gm_p[0] = 0``;
    ``com``: barycentre position and velocity (6,).  Returns ``(steps, bad)``
    with ``bad`` the index of a body whose Kepler step failed, else -1."""
    n = q.shape[0]
    gm0 = gm[0]
    acc = np.empty((n, 3))
    r_in = np.empty((n, 3))
    v_in = np.empty((n, 3))
    acc_x = np.empty((n, 3))
    m_tot = 0.0
    for i in range(n):
        m_tot += gm[i]
    # the planets' mutual pulls: massive rows >= 1 (found once, not per step);
    # row 0 (unused here) is left out of the interaction
    idx = _nbody.massive_indices(gm_p)
    mu = np.full(n, gm0)
    h = dt if n_steps > 1 else dt_last
    bad = _kepler_all(q, u, mu, 0.5 * h)
    if bad >= 0:
        return 0, bad
    for k in range(3):
        com[k] += 0.5 * h * com[3 + k]
    for s in range(n_steps):
        h = dt if s < n_steps - 1 else dt_last
        _jump(q, u, gm, 0.5 * h)
        _nbody.newtonian_rows(q, gm_p, idx, 1, acc)
        for i in range(1, n):
            for k in range(3):
                u[i, k] += h * acc[i, k]
        if has_extra:
            # inertial state for the effects: r_0 = R - sum m_i Q_i / M
            for k in range(3):
                s_q = 0.0
                s_u = 0.0
                for i in range(1, n):
                    s_q += gm[i] * q[i, k]
                    s_u += gm[i] * u[i, k]
                r_in[0, k] = com[k] - s_q / m_tot
                v_in[0, k] = com[3 + k] - s_u / gm0
                for i in range(1, n):
                    r_in[i, k] = q[i, k] + r_in[0, k]
                    v_in[i, k] = u[i, k] + com[3 + k]
                for i in range(n):
                    acc_x[i, k] = 0.0
            extra(r_in, v_in, gm, acc_x)
            for k in range(3):
                a_cm = 0.0
                for i in range(n):
                    a_cm += gm[i] * acc_x[i, k]
                a_cm /= m_tot
                com[3 + k] += h * a_cm
                for i in range(1, n):
                    u[i, k] += h * (acc_x[i, k] - a_cm)
        _jump(q, u, gm, 0.5 * h)
        if s < n_steps - 1:
            h_next = dt if s + 1 < n_steps - 1 else dt_last
            tau = 0.5 * (h + h_next)
        else:
            tau = 0.5 * h
        bad = _kepler_all(q, u, mu, tau)
        if bad >= 0:
            return s, bad
        for k in range(3):
            com[k] += tau * com[3 + k]
    return n_steps, -1


@njit(cache=True)
def _jacobi_factors(eta):  # pragma: no cover - compiled
    """``(ratio, inv)`` with ``ratio_i = eta_{i-1} / eta_i`` (``ratio_0 = 1``) and
    ``inv_i = 1 / eta_i``: the divisions of the coordinate changes, formed once
    per run instead of every step."""
    n = eta.shape[0]
    ratio = np.ones(n)
    inv = np.empty(n)
    for i in range(n):
        inv[i] = 1.0 / eta[i]
        if i > 0:
            ratio[i] = eta[i - 1] / eta[i]
    return ratio, inv


@njit(cache=True, inline="always")
def _jacobi_to_inertial_pos(qj, gm, eta, ratio, inv, r):  # pragma: no cover - compiled
    """Inertial positions ``r`` from Jacobi positions ``qj`` (row 0: the barycentre);
    ``ratio``, ``inv`` from :func:`_jacobi_factors`.

    With ``S_i = sum_{j<=i} m_j r_j``: ``S_{n-1} = eta_{n-1} qj_0`` and, going
    down, ``S_{i-1} = (S_i - m_i qj_i) eta_{i-1} / eta_i``,
    ``r_i = qj_i + S_{i-1} / eta_{i-1}``, ``r_0 = S_0 / m_0``."""
    n = qj.shape[0]
    # the three coordinates side by side (three independent recurrences)
    sx = eta[n - 1] * qj[0, 0]
    sy = eta[n - 1] * qj[0, 1]
    sz = eta[n - 1] * qj[0, 2]
    for i in range(n - 1, 0, -1):
        gi = gm[i]
        ri = ratio[i]
        ie = inv[i - 1]
        sx = (sx - gi * qj[i, 0]) * ri
        sy = (sy - gi * qj[i, 1]) * ri
        sz = (sz - gi * qj[i, 2]) * ri
        r[i, 0] = qj[i, 0] + sx * ie
        r[i, 1] = qj[i, 1] + sy * ie
        r[i, 2] = qj[i, 2] + sz * ie
    r[0, 0] = sx / gm[0]
    r[0, 1] = sy / gm[0]
    r[0, 2] = sz / gm[0]


@njit(cache=True, inline="always")
def _inertial_to_jacobi_acc(a, gm, inv, aj):  # pragma: no cover - compiled
    """Jacobi accelerations ``aj_i = a_i - (sum_{j<i} m_j a_j) / eta_{i-1}``, i >= 1
    (``inv_i = 1 / eta_i``)."""
    n = a.shape[0]
    sx = gm[0] * a[0, 0]
    sy = gm[0] * a[0, 1]
    sz = gm[0] * a[0, 2]
    for i in range(1, n):
        ie = inv[i - 1]
        aj[i, 0] = a[i, 0] - sx * ie
        aj[i, 1] = a[i, 1] - sy * ie
        aj[i, 2] = a[i, 2] - sz * ie
        gi = gm[i]
        sx += gi * a[i, 0]
        sy += gi * a[i, 1]
        sz += gi * a[i, 2]


@njit(cache=True, inline="always")
def _kick_jacobi(
    extra, has_extra, qj, uj, gm, idx, eta, ratio, inv, h, move_com, acc, accj, acc_x, r_in, v_in
):  # pragma: no cover - compiled
    """The interaction kick of length ``h`` in Jacobi coordinates (``idx``: the
    massive indices of ``gm``; ``ratio``, ``inv``: :func:`_jacobi_factors`)."""
    n = qj.shape[0]
    _jacobi_to_inertial_pos(qj, gm, eta, ratio, inv, r_in)
    _nbody.newtonian_rows(r_in, gm, idx, 0, acc)
    if has_extra:
        for i in range(n):
            for k in range(3):
                acc_x[i, k] = 0.0
        extra(r_in, v_in, gm, acc_x)
        m_tot = eta[n - 1]
        for k in range(3):
            a_cm = 0.0
            for i in range(n):
                a_cm += gm[i] * acc_x[i, k]
                acc[i, k] += acc_x[i, k]
            if move_com:
                # the effects' net force moves the barycentre
                uj[0, k] += h * a_cm / m_tot
    _inertial_to_jacobi_acc(acc, gm, inv, accj)
    for i in range(1, n):
        d2 = qj[i, 0] * qj[i, 0] + qj[i, 1] * qj[i, 1] + qj[i, 2] * qj[i, 2]
        f = eta[i] / (d2 * math.sqrt(d2))
        for k in range(3):
            uj[i, k] += h * (accj[i, k] + f * qj[i, k])


# Third-order symplectic corrector (Wisdom, Holman & Touma 1996, table 1 as
# used by WHFast, Rein & Tamayo 2015): a = sqrt(7/40), b = -sqrt(10/7) / 48.
_CORR_A = math.sqrt(7.0 / 40.0)
_CORR_B = -math.sqrt(10.0 / 7.0) / 48.0


@njit(
    types.int64(_setup.ACCEL_TYPE, types.boolean, _F2, _F2, _F1, _F1, types.float64, types.float64),
    cache=True,
)
def _corrector_jacobi(extra, has_extra, qj, uj, gm, eta, dt, sign):  # pragma: no cover
    """Apply the third-order corrector (``sign = 1``) or its inverse (``-1``):
    ``Z(a dt, -sign b dt) Z(-a dt, sign b dt)`` with ``Z(a, b)`` = Kepler a,
    kick -b, Kepler -2a, kick b, Kepler a.  Returns a failing index or -1."""
    n = qj.shape[0]
    acc = np.empty((n, 3))
    accj = np.empty((n, 3))
    acc_x = np.empty((n, 3))
    r_in = np.empty((n, 3))
    v_in = np.zeros((n, 3))
    idx = _nbody.massive_indices(gm)
    ratio, inv = _jacobi_factors(eta)
    for a, b in ((_CORR_A * dt, -sign * _CORR_B * dt), (-_CORR_A * dt, sign * _CORR_B * dt)):
        bad = _kepler_all(qj, uj, eta, a)
        if bad >= 0:
            return bad
        _kick_jacobi(
            extra, has_extra, qj, uj, gm, idx, eta, ratio, inv, -b, False,
            acc, accj, acc_x, r_in, v_in,
        )
        bad = _kepler_all(qj, uj, eta, -2.0 * a)
        if bad >= 0:
            return bad
        _kick_jacobi(
            extra, has_extra, qj, uj, gm, idx, eta, ratio, inv, b, False,
            acc, accj, acc_x, r_in, v_in,
        )
        bad = _kepler_all(qj, uj, eta, a)
        if bad >= 0:
            return bad
    return -1


@njit(
    types.Tuple((types.int64, types.int64))(
        _setup.ACCEL_TYPE,
        types.boolean,
        _F2,
        _F2,
        _F1,
        _F1,
        types.float64,
        types.int64,
        types.float64,
    ),
    cache=True,
)
def _advance_jacobi(
    extra, has_extra, qj, uj, gm, eta, dt, n_steps, dt_last
):  # pragma: no cover - compiled
    """As :func:`_advance` in Jacobi coordinates (Wisdom & Holman 1991): ``qj``,
    ``uj`` Jacobi positions and velocities, row 0 the barycentre; ``eta_i =
    sum_{j<=i} G m_j``.  Kick: the inertial accelerations (all pairs, and the
    listed effects) in Jacobi form plus ``G eta_i qj_i / |qj_i|^3``, which
    removes the part the Kepler step already accounts for."""
    n = qj.shape[0]
    acc = np.empty((n, 3))
    accj = np.empty((n, 3))
    acc_x = np.empty((n, 3))
    r_in = np.empty((n, 3))
    v_in = np.zeros((n, 3))
    idx = _nbody.massive_indices(gm)
    ratio, inv = _jacobi_factors(eta)
    h = dt if n_steps > 1 else dt_last
    bad = _kepler_all(qj, uj, eta, 0.5 * h)
    if bad >= 0:
        return 0, bad
    for k in range(3):
        qj[0, k] += 0.5 * h * uj[0, k]
    for s in range(n_steps):
        h = dt if s < n_steps - 1 else dt_last
        _kick_jacobi(
            extra, has_extra, qj, uj, gm, idx, eta, ratio, inv, h, True,
            acc, accj, acc_x, r_in, v_in,
        )
        if s < n_steps - 1:
            h_next = dt if s + 1 < n_steps - 1 else dt_last
            tau = 0.5 * (h + h_next)
        else:
            tau = 0.5 * h
        bad = _kepler_all(qj, uj, eta, tau)
        if bad >= 0:
            return s, bad
        for k in range(3):
            qj[0, k] += tau * uj[0, k]
    return n_steps, -1


def default_step(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, tol: float | None = None) -> float:
    """The step ``run`` takes when ``dt`` is not given.

    ``P_min / 20`` with ``P_min`` the shortest Kepler period of a bound body
    about the central one; with ``tol``, ``P_min min(1/20, sqrt(tol / eps))``
    where ``eps`` is the largest mass ratio to the central body, from the
    Wisdom-Holman energy error ``~ eps (dt / P)^2`` (Wisdom & Holman 1991).

    Examples
    --------
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    >>> v0 = np.array([[0.0, 0, 0], [0.0, 1, 0]])
    >>> round(default_step(r0, v0, np.array([1.0, 0.0])) * 20 / (2 * np.pi), 12)
    1.0
    """
    c = int(np.argmax(gm))
    mu = gm[c]
    rel_r = np.delete(r0 - r0[c], c, axis=0)
    rel_v = np.delete(v0 - v0[c], c, axis=0)
    others = np.delete(gm, c)
    d = np.linalg.norm(rel_r, axis=1)
    inv_a = 2.0 / d - np.sum(rel_v**2, axis=1) / (mu + others)
    bound = inv_a > 0.0
    if not np.any(bound):
        raise ValueError("wh needs `dt`: no body is bound to the central body")
    period = float(np.min(2.0 * np.pi / np.sqrt((mu + others[bound]) * inv_a[bound] ** 3)))
    frac = 1.0 / 20.0
    if tol is not None:
        eps = float(np.max(others / mu)) if others.size else 0.0
        if eps > 0.0:
            frac = min(frac, math.sqrt(tol / eps))
    return period * frac


def run(
    rhs: Any,
    r0: np.ndarray,
    v0: np.ndarray,
    gm: np.ndarray,
    t_out: np.ndarray,
    *,
    dt: float | None = None,
    tol: float | None = None,
    on_output: Callable[[int, int], None] | None = None,
    coordinates: str = "democratic_heliocentric",
    corrector: int = 0,
) -> tuple[np.ndarray, np.ndarray, int]:
    """Integrate with the Wisdom-Holman map (democratic-heliocentric or Jacobi).

    Parameters
    ----------
    rhs : RHS
        The compiled right-hand side; its Newtonian part is split as above and
        ``rhs.extra`` (the listed effects) joins the kick.  Velocity-dependent
        effects raise ``ValueError``.
    r0, v0 : ndarray, shape (n, 3)
        Initial inertial positions and velocities (internal units).
    gm : ndarray, shape (n,)
        ``G m >= 0``; the body of largest GM is the central one.
    t_out : ndarray, shape (n_t,)
        Increasing output times; ``t_out[0]`` is the initial time.
    dt : float, optional
        The step; the last step before an output time is shortened to land on
        it.  Default: :func:`default_step`.
    tol : float, optional
        Used only without ``dt``, to choose it (see :func:`default_step`).
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i`` is reached.
    coordinates : {"democratic_heliocentric", "jacobi"}, optional
        The splitting: democratic-heliocentric (default; Duncan, Levison & Lee
        1998) or Jacobi (Wisdom & Holman 1991; the central body first, then the
        others in the order given, each on a Kepler orbit about the total mass
        inside it).  Both are WHFast's maps of the same names.
    corrector : {0, 3}, optional
        With Jacobi coordinates, 3 applies the third-order symplectic corrector
        of Wisdom, Holman & Touma (1996) before the steps of each output
        interval and its inverse after them (so outputs are in true
        coordinates); it removes the leading O(eps dt^2) error term.

    Returns
    -------
    r, v : ndarray, shape (n_t, n, 3)
        Inertial states at ``t_out`` (row 0 the initial state).
    steps : int
        Steps taken.

    Raises
    ------
    ValueError
        Bad input (naming the argument), a velocity-dependent effect, or no
        massive central body.
    ConvergenceError
        If a Kepler step fails (a body on a collision orbit with the centre).

    Examples
    --------
    Two planets on circular orbits; after 100 steps the energy is kept to
    about (dt / P)^2 times the planet-to-star mass ratio:

    >>> import numpy as np
    >>> from hamilton_orbits.effects import newtonian_rhs
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 2.0, 0]])
    >>> v0 = np.array([[0.0, 0, 0], [0.0, 1.0, 0], [-0.5**0.5, 0, 0]])
    >>> r, v, steps = run(newtonian_rhs(), r0, v0, np.array([1.0, 1e-3, 1e-3]),
    ...                   np.array([0.0, 10.0]), dt=0.1)
    >>> steps
    100
    """
    if rhs.velocity_dependent:
        raise ValueError(
            f"wh is a symplectic map and refuses velocity-dependent effects; listed: "
            f"{', '.join(rhs.effects)}.  Use method='radau15' (or 'dop853') for them"
        )
    r0, v0, gm, t_out = _setup.check_inputs(r0, v0, gm, t_out)
    dt_f, tol_f = _setup.check_dt_tol(dt, tol)
    if coordinates not in COORDINATES:
        raise ValueError(
            f"Expected `coordinates` to be one of {', '.join(map(repr, COORDINATES))}, "
            f"got {coordinates!r}"
        )
    if corrector not in (0, 3):
        raise ValueError(f"Expected `corrector` to be 0 or 3, got {corrector!r}")
    if corrector and coordinates != "jacobi":
        raise ValueError(
            f"Expected coordinates='jacobi' with `corrector` = {corrector}, got {coordinates!r} "
            "(the corrector is defined for the Jacobi splitting)"
        )
    n = r0.shape[0]
    c = int(np.argmax(gm))
    if not gm[c] > 0.0:
        raise ValueError("wh needs a central body with `gm` > 0; all `gm` are 0")
    if dt_f is None:
        dt_f = default_step(r0, v0, gm, tol_f)
    # the central body first
    order = np.concatenate([[c], np.delete(np.arange(n), c)])
    g = np.ascontiguousarray(gm[order])
    r = r0[order]
    v = v0[order]
    m_tot = g.sum()
    jacobi = coordinates == "jacobi"
    if jacobi:
        eta = np.cumsum(g)
        ratio, inv_eta = _jacobi_factors(eta)
        s_r = np.cumsum(g[:, None] * r, axis=0)
        s_v = np.cumsum(g[:, None] * v, axis=0)
        q = np.empty_like(r)
        u = np.empty_like(v)
        q[0] = s_r[-1] / eta[-1]
        u[0] = s_v[-1] / eta[-1]
        q[1:] = r[1:] - s_r[:-1] / eta[:-1, None]
        u[1:] = v[1:] - s_v[:-1] / eta[:-1, None]
    else:
        com = np.concatenate([(g @ r) / m_tot, (g @ v) / m_tot])
        q = np.ascontiguousarray(r - r[0])
        u = np.ascontiguousarray(v - com[3:])
        g_p = g.copy()
        g_p[0] = 0.0
    extra = _setup.accel_arg(rhs.extra if rhs.extra is not None else _no_extra)
    nt = t_out.shape[0]
    r_out = np.empty((nt, n, 3))
    v_out = np.empty((nt, n, 3))
    r_out[0] = r0
    v_out[0] = v0
    total = 0
    inv = np.argsort(order)
    for i in range(1, nt):
        span = t_out[i] - t_out[i - 1]
        n_steps = max(1, math.ceil(span / dt_f * (1.0 - 1e-12)))
        last = span - (n_steps - 1) * dt_f
        if jacobi:
            has_extra = rhs.extra is not None
            bad = -1
            if corrector:
                bad = _corrector_jacobi(extra, has_extra, q, u, g, eta, dt_f, 1.0)
            steps = 0
            if bad < 0:
                steps, bad = _advance_jacobi(extra, has_extra, q, u, g, eta, dt_f, n_steps, last)
            if bad < 0 and corrector:
                bad = _corrector_jacobi(extra, has_extra, q, u, g, eta, dt_f, -1.0)
        else:
            steps, bad = _advance(
                extra, rhs.extra is not None, q, u, g, g_p, com, dt_f, n_steps, last
            )
        total += steps
        if bad >= 0:
            raise ConvergenceError(
                f"wh: the Kepler step of body {int(order[bad])} failed between "
                f"t_out[{i - 1}] = {float(t_out[i - 1])!r} and t_out[{i}] = {float(t_out[i])!r}"
            )
        # back to inertial coordinates
        if jacobi:
            rr = np.empty_like(q)
            vv = np.empty_like(u)
            _jacobi_to_inertial_pos(q, g, eta, ratio, inv_eta, rr)
            _jacobi_to_inertial_pos(u, g, eta, ratio, inv_eta, vv)
        else:
            r0_in = com[:3] - (g[1:] @ q[1:]) / m_tot
            v0_in = com[3:] - (g[1:] @ u[1:]) / g[0]
            rr = q + r0_in
            rr[0] = r0_in
            vv = u + com[3:]
            vv[0] = v0_in
        r_out[i] = rr[inv]
        v_out[i] = vv[inv]
        if on_output is not None:
            on_output(i, total)
    return r_out, v_out, total
