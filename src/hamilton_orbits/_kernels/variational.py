"""Tangent maps and chaos indicators, as compiled kernels on plain floats.

- :func:`megno_update`, :func:`megno_map_step`: MEGNO and the Lyapunov exponent
  as rebound computes them (Cincotta & Simo 2000; Rein & Tamayo 2016), from the
  growth of one tangent vector; the state vector ``ms`` is laid out in
  :data:`MEGNO_FIELDS`.
- :func:`kepler_tangent`: the exact derivative of a Kepler drift (universal
  variables), applied to every tangent vector of one body: the tangent map of the
  Wisdom-Holman drift.
- :func:`advance_leapfrog`: drift-kick-drift with its exact tangent map.

Tangent vectors are ``(dr, dv)`` arrays of shape (k n, 3), row ``m n + i`` the
displacement of body ``i`` in tangent vector ``m`` (see
:mod:`hamilton_orbits._kernels.jacobians`).  No astropy here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels import kepler as _kepler
from hamilton_orbits._kernels.entry import entry
from hamilton_orbits._kernels.jacobians import tangent_at
from hamilton_orbits._kernels.signatures import ADDRESSES, F1, F2, accel_at, set_clock

__all__ = [
    "LN_RESCALE",
    "MEGNO_FIELDS",
    "advance_leapfrog",
    "kepler_tangent",
    "log_norm",
    "megno_map_step",
    "megno_update",
    "renormalise",
    "stumpff_c4c5",
]

#: The fields of the MEGNO state ``ms`` (float64, one per field): the start time,
#: the running sums of ``Y`` and of ``<Y>``, the number of updates, the running
#: means of ``t`` and ``<Y>``, the running covariance of ``(t, <Y>)`` and variance
#: of ``t``, and ``ln |delta|`` at the last update (fixed-step maps).
MEGNO_FIELDS = ("t0", "Ys", "Yss", "count", "mean_t", "mean_Y", "cov_Yt", "var_t", "ln_delta")


@njit(cache=True, error_model="numpy")
def megno_update(ms, dy, t, dt):  # pragma: no cover - compiled
    """Add one step's ``dY = 2 int t (delta' . delta / |delta|^2) dt`` to the MEGNO
    state ``ms`` (:data:`MEGNO_FIELDS`) at the step's end ``t``, ``dt`` its length.

    With ``s = t - t0``: ``Ys += dY``, ``Y(t) = Ys / s`` (Cincotta & Simo 2000,
    eq. 2: ``Y(t) = 2/t int_0^t (delta'.delta/|delta|^2) t' dt'``), ``Yss += Y dt``
    so that ``<Y>(t) = Yss / s`` is its time average; and the running covariance
    of ``(s, <Y>)`` and variance of ``s``, one sample per step, whose ratio is the
    slope of the least-squares line ``<Y> ~ a + b s`` (Cincotta & Simo 2000,
    eq. 24), rebound's ``lyapunov()``.  The same running updates as rebound's
    ``reb_tools_megno_update`` (its means are updated before the products).
    """
    s = t - ms[0]
    if not s > 0.0:
        return
    ms[1] += dy
    y = ms[1] / s
    ms[2] += y * dt
    ms[3] += 1.0
    nn = ms[3]
    ms[4] += (s - ms[4]) / nn
    mean_y = ms[2] / s
    ms[5] += (mean_y - ms[5]) / nn
    w = (nn - 1.0) / nn
    ms[6] += w * (s - ms[4]) * (mean_y - ms[5])
    ms[7] += w * (s - ms[4]) * (s - ms[4])


@njit(cache=True, error_model="numpy")
def log_norm(dr, dv, n, m):  # pragma: no cover - compiled
    """``ln |delta|`` of tangent vector ``m``: the Euclidean norm over its 6n
    position and velocity components."""
    s = 0.0
    for i in range(m * n, (m + 1) * n):
        for c in range(3):
            s += dr[i, c] * dr[i, c] + dv[i, c] * dv[i, c]
    return 0.5 * math.log(s) if s > 0.0 else -math.inf


@njit(cache=True, error_model="numpy")
def megno_map_step(ms, lnd, t, dt):  # pragma: no cover - compiled
    """The MEGNO update after one step of a map: ``dY = 2 (t - dt/2 - t0)
    (ln |delta(t)| - ln |delta(t - dt)|)``, the midpoint rule for
    ``2 int t d(ln |delta|)`` over the step (``delta'.delta/|delta|^2 = d ln|delta|/dt``;
    Cincotta, Giordano & Simo 2003 use this form for maps), then
    :func:`megno_update`.  ``lnd`` is ``ln |delta(t)|``."""
    dy = 2.0 * (t - 0.5 * dt - ms[0]) * (lnd - ms[8])
    ms[8] = lnd
    megno_update(ms, dy, t, dt)


#: ``ln |delta|`` above which MEGNO's tangent vector is scaled back to unit length
#: inside the kernels (|delta| ~ 1e100; it grows like exp(lambda t) on a chaotic
#: orbit, and faster through a close encounter; MEGNO depends on its direction).
LN_RESCALE = 230.0


@njit(cache=True, error_model="numpy")
def renormalise(ms, dr, dv, n):  # pragma: no cover - compiled
    """Scale tangent vector 0 (rows ``0 .. n-1`` of ``dr``, ``dv``) to unit length when
    ``ln |delta|`` (``ms[8]``, just updated) exceeds :data:`LN_RESCALE`; returns the
    factor (1.0 when left alone).  The tangent dynamics are linear: the scaled
    vector evolves as the original divided by the factor, and ``ms[8]`` is reduced
    by its logarithm, so MEGNO's increments are unchanged."""
    if not ms[8] > LN_RESCALE:
        return 1.0
    f = math.exp(-ms[8])
    for i in range(n):
        for c in range(3):
            dr[i, c] *= f
            dv[i, c] *= f
    ms[8] = 0.0
    return f


# 1 / (2j + 4)! and 1 / (2j + 5)!, j = 0 .. 9: the series of c4 and c5
_C4 = np.array([1.0 / math.factorial(2 * j + 4) for j in range(10)])
_C5 = np.array([1.0 / math.factorial(2 * j + 5) for j in range(10)])


@njit(cache=True, error_model="numpy")
def stumpff_c4c5(psi, c2, c3):  # pragma: no cover - compiled
    """``c4(psi) = (1/2 - c2)/psi`` and ``c5(psi) = (1/6 - c3)/psi`` (their series
    ``sum_j (-psi)^j / (2j + k)!`` in Horner form for |psi| < 1, where the
    quotients cancel; the terms left out are below 1e-18 of the sum: 4 of them
    for |psi| < 0.01, 6 below 0.1, 9 below 1)."""
    apsi = abs(psi)
    if apsi < 1.0:
        top = (4 if apsi < 0.01 else 6) if apsi < 0.1 else 9
        z = -psi
        c4 = _C4[top]
        c5 = _C5[top]
        for j in range(top - 1, -1, -1):
            c4 = _C4[j] + z * c4
            c5 = _C5[j] + z * c5
        return c4, c5
    return (0.5 - c2) / psi, (1.0 / 6.0 - c3) / psi


@njit(cache=True, error_model="numpy")
def kepler_tangent(x0, v0, x1, v1, mu, dt, dq, du, i, n):  # pragma: no cover - compiled
    """Map the tangent vectors of body ``i`` (rows ``m n + i`` of ``dq``, ``du``)
    through the Kepler drift that took ``(x0, v0)`` (3,) to ``(x1, v1)`` about ``mu``
    in ``dt``: the exact derivative of the two-body flow.

    In universal variables (``U_k(chi; alpha)``, ``sigma = r.v / sqrt(mu)``,
    ``alpha = 2/r0 - v0^2/mu``) the drift is ``x1 = f x0 + g v0``,
    ``v1 = fdot x0 + gdot v0`` with ``f = 1 - U2/r0``, ``g = dt - U3/sqrt(mu)``,
    ``fdot = -sqrt(mu) U1/(r r0)``, ``gdot = 1 - U2/r`` and Kepler's equation
    ``sqrt(mu) dt = r0 U1 + sigma0 U2 + U3``.  Its variation is

        delta x1 = f delta x0 + g delta v0 + (delta f) x0 + (delta g) v0   (and v1 alike),

    where the scalars vary through ``r0``, ``sigma0``, ``alpha`` and ``chi``:
    ``delta chi = -(U1 delta r0 + U2 delta sigma0 + F_alpha delta alpha) / r``
    (implicit differentiation of Kepler's equation), ``dU_k/dchi = U_(k-1)``
    (``dU0/dchi = -alpha U1``) and ``dU_k/dalpha = (k U_(k+2) - chi U_(k+1))/2``.
    ``chi`` itself is recovered without a solve from the two states,
    ``chi = alpha sqrt(mu) dt + sigma1 - sigma0``, so the derivative is that of the
    whole drift even when the position was computed modulo the period.
    """
    smu = math.sqrt(mu)
    r0 = math.sqrt(x0[0] * x0[0] + x0[1] * x0[1] + x0[2] * x0[2])
    r = math.sqrt(x1[0] * x1[0] + x1[1] * x1[1] + x1[2] * x1[2])
    s0 = (x0[0] * v0[0] + x0[1] * v0[1] + x0[2] * v0[2]) / smu
    s1 = (x1[0] * v1[0] + x1[1] * v1[1] + x1[2] * v1[2]) / smu
    v02 = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]
    alpha = 2.0 / r0 - v02 / mu
    chi = alpha * smu * dt + s1 - s0
    chi2 = chi * chi
    psi = alpha * chi2
    c2, c3 = _kepler.stumpff_c2c3(psi)
    c4, c5 = stumpff_c4c5(psi, c2, c3)
    u0 = 1.0 - psi * c2
    u1 = chi * (1.0 - psi * c3)
    u2 = chi2 * c2
    u3 = chi2 * chi * c3
    u4 = chi2 * chi2 * c4
    u5 = chi2 * chi2 * chi * c5
    a0 = -0.5 * chi * u1  # dU_k / dalpha
    a1 = 0.5 * (u3 - chi * u2)
    a2 = 0.5 * (2.0 * u4 - chi * u3)
    a3 = 0.5 * (3.0 * u5 - chi * u4)
    f_alpha = r0 * a1 + s0 * a2 + a3
    ir0 = 1.0 / r0
    ir = 1.0 / r
    ismu = 1.0 / smu
    f = 1.0 - u2 * ir0
    g = dt - u3 * ismu
    fd = -smu * u1 * ir * ir0
    gd = 1.0 - u2 * ir
    c_al = 2.0 / mu
    k = dq.shape[0] // n
    for m in range(k):
        row = m * n + i
        ex, ey, ez = dq[row, 0], dq[row, 1], dq[row, 2]
        ux, uy, uz = du[row, 0], du[row, 1], du[row, 2]
        d_r0 = (x0[0] * ex + x0[1] * ey + x0[2] * ez) * ir0
        d_s0 = (ex * v0[0] + ey * v0[1] + ez * v0[2] + x0[0] * ux + x0[1] * uy
                + x0[2] * uz) * ismu
        d_al = -2.0 * d_r0 * ir0 * ir0 - c_al * (v0[0] * ux + v0[1] * uy + v0[2] * uz)
        d_chi = -(u1 * d_r0 + u2 * d_s0 + f_alpha * d_al) * ir
        d_u0 = -alpha * u1 * d_chi + a0 * d_al
        d_u1 = u0 * d_chi + a1 * d_al
        d_u2 = u1 * d_chi + a2 * d_al
        d_u3 = u2 * d_chi + a3 * d_al
        d_r = d_r0 * u0 + r0 * d_u0 + d_s0 * u1 + s0 * d_u1 + d_u2
        d_f = (u2 * d_r0 * ir0 - d_u2) * ir0
        d_g = -d_u3 * ismu
        d_fd = -smu * (d_u1 - u1 * (d_r * ir + d_r0 * ir0)) * ir * ir0
        d_gd = (u2 * d_r * ir - d_u2) * ir
        dq[row, 0] = f * ex + g * ux + d_f * x0[0] + d_g * v0[0]
        dq[row, 1] = f * ey + g * uy + d_f * x0[1] + d_g * v0[1]
        dq[row, 2] = f * ez + g * uz + d_f * x0[2] + d_g * v0[2]
        du[row, 0] = fd * ex + gd * ux + d_fd * x0[0] + d_gd * v0[0]
        du[row, 1] = fd * ey + gd * uy + d_fd * x0[1] + d_gd * v0[1]
        du[row, 2] = fd * ez + gd * uz + d_fd * x0[2] + d_gd * v0[2]


@njit(cache=True, inline="always", error_model="numpy")
def _drift(r, v, dr, dv, h):  # pragma: no cover - compiled
    """``r += h v`` and its tangent ``dr += h dv``."""
    for i in range(r.shape[0]):
        for c in range(3):
            r[i, c] += h * v[i, c]
    for a in range(dr.shape[0]):
        for c in range(3):
            dr[a, c] += h * dv[a, c]


@entry(types.int64(ADDRESSES, ADDRESSES, F1, F2, F2, F1, F2, F2, types.float64,
                  types.float64, types.float64, F1, types.int64),
      cache=True, error_model="numpy")
def advance_leapfrog(accel_addr, tangent_addr, p, r, v, gm, dr, dv, t0, t1, dt, ms, max_steps):
    # pragma: no cover - compiled
    """Leapfrog steps of at most ``dt`` from ``t0`` to exactly ``t1`` (as
    :func:`hamilton_orbits._kernels.leapfrog.advance`) with the exact tangent map
    of each step: ``delta r += h/2 delta v``; ``delta v += h J(r) delta r`` (the
    Jacobian at the kick's position); ``delta r += h/2 delta v``.  A product of
    linear symplectic maps when the force derives from a potential, so the tangent
    flow is symplectic too (Rein & Tamayo 2016).  After every step the MEGNO state
    ``ms`` is updated from tangent vector 0 (:func:`megno_map_step`).  Returns the
    steps taken: ``max_steps`` of them, at ``t0 + max_steps h``, when fewer than
    the ``n_steps`` to ``t1`` (a slice, as the plain kernel's ``STATUS_SLICE``:
    call again from there)."""
    accel = accel_at(accel_addr[0], accel_addr[1])
    tangent = tangent_at(tangent_addr[0], tangent_addr[1])
    n_steps = int(np.ceil((t1 - t0) / dt - 1e-12))
    if n_steps < 1:
        n_steps = 1
    h = (t1 - t0) / n_steps
    n = r.shape[0]
    acc = np.empty_like(r)
    da = np.empty_like(dr)
    for s in range(n_steps):
        _drift(r, v, dr, dv, 0.5 * h)
        set_clock(p, t0 + s * h + 0.5 * h)  # (the plain kernel's kick time)
        accel(r, v, gm, acc, p)
        tangent(r, v, gm, dr, dv, da, p)
        for i in range(n):
            for c in range(3):
                v[i, c] += h * acc[i, c]
        for a in range(dr.shape[0]):
            for c in range(3):
                dv[a, c] += h * da[a, c]
        _drift(r, v, dr, dv, 0.5 * h)
        megno_map_step(ms, log_norm(dr, dv, n, 0), t0 + (s + 1) * h, h)
        renormalise(ms, dr, dv, n)
        if s + 1 >= max_steps and s + 1 < n_steps:
            return s + 1
    return n_steps
