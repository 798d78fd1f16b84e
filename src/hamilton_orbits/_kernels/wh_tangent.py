"""The Wisdom-Holman map with its exact tangent map (``variational=True``).

The same splittings and steps as :mod:`hamilton_orbits._kernels.wh` (democratic
heliocentric, Jacobi; Kepler ``dt/2``, kick ``dt``, Kepler ``dt/2``, the Kepler
halves of consecutive steps merged and the state synchronised at the end of a
call), each part carrying the tangent vectors through its own derivative (Rein &
Tamayo 2016, section 2.3):

- the Kepler drift by :func:`hamilton_orbits._kernels.variational.kepler_tangent`
  (the derivative of the two-body flow), the barycentre's drift linearly;
- the jump ``|sum m_i u_i|^2 / (2 m_0)`` by ``delta Q_i += tau sum m_j delta u_j / m_0``;
- the interaction kick by the Jacobian of the interaction (and of the listed
  effects) at the kick's positions: ``delta u_i += h sum_j (da_i/dQ_j) delta Q_j``.

Each is the derivative of a symplectic map, so the tangent map is symplectic too.
MEGNO is updated from tangent vector 0 in inertial coordinates after every kick
(the middle of the step: its tangent vector is that of the synchronised map
conjugated by a half drift, a bounded near-identity map, so the limits of MEGNO
and of the Lyapunov exponent are the same; WHFast instead synchronises every
step, a second Kepler solve per body) and at the end of the call.  Tangent
vectors: rows ``m n + i`` of ``(dq, du)`` (k n, 3) in the splitting's coordinates;
``dcom`` (k, 6) the barycentre's (democratic heliocentric).  No astropy here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels import kepler as _kepler
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._kernels.entry import entry
from hamilton_orbits._kernels.jacobians import newtonian_jvp, tangent_at
from hamilton_orbits._kernels.signatures import ADDRESSES, F1, F2, accel_at, set_clock
from hamilton_orbits._kernels.variational import kepler_tangent, megno_map_step, renormalise
from hamilton_orbits._kernels.wh import (
    caller_gm,
    jacobi_factors,
    jacobi_to_inertial_pos,
    step_length,
)

_I1 = types.int64[::1]

__all__ = ["advance_dh", "advance_jacobi"]


@njit(cache=True, error_model="numpy")
def _kepler_drift(q, u, mu, tau, dq, du, xa, va):  # pragma: no cover - compiled
    """Every body ``i >= 1`` on its Kepler orbit about ``mu[i]`` for ``tau``, with
    its tangent vectors; returns the first failing body, else -1.  The Kepler
    solver called, not inlined (:func:`hamilton_orbits._kernels.kepler.propagate_uv`,
    compiled once and shared with the other Wisdom-Holman kernels: its inlined copy
    cost 0.4-2 s of compilation per entry; the steps, with the tangent's work per
    body beside it, no slower, measured; the same bits)."""
    n = q.shape[0]
    for i in range(1, n):
        for c in range(3):
            xa[c] = q[i, c]
            va[c] = u[i, c]
        x, y, z, vx, vy, vz = _kepler.propagate_uv(
            xa[0], xa[1], xa[2], va[0], va[1], va[2], mu[i], tau)
        if not math.isfinite(x + y + z + vx + vy + vz):
            return i
        q[i, 0], q[i, 1], q[i, 2] = x, y, z
        u[i, 0], u[i, 1], u[i, 2] = vx, vy, vz
        kepler_tangent(xa, va, q[i], u[i], mu[i], tau, dq, du, i, n)
    return -1


@njit(cache=True, inline="always", error_model="numpy")
def _jump(q, u, dq, du, gm, tau):  # pragma: no cover - compiled
    """The jump drift of the ``Q_i`` and its (linear) tangent."""
    n = q.shape[0]
    f = tau / gm[0]
    for blk in range(dq.shape[0] // n + 1):
        x = q if blk == 0 else dq[(blk - 1) * n:blk * n]
        w = u if blk == 0 else du[(blk - 1) * n:blk * n]
        for c in range(3):
            s = 0.0
            for i in range(1, n):
                s += gm[i] * w[i, c]
            for i in range(1, n):
                x[i, c] += f * s


@njit(cache=True, error_model="numpy")
def _inertial_dh(q, u, com, gm, m_tot, r_in, v_in):  # pragma: no cover - compiled
    """Inertial positions and velocities from heliocentric positions, barycentric
    velocities and the barycentre ``com`` (6,): ``r_0 = R - sum m_i Q_i / M``."""
    n = q.shape[0]
    for c in range(3):
        s_q = 0.0
        s_u = 0.0
        for i in range(1, n):
            s_q += gm[i] * q[i, c]
            s_u += gm[i] * u[i, c]
        r_in[0, c] = com[c] - s_q / m_tot
        v_in[0, c] = com[3 + c] - s_u / gm[0]
        for i in range(1, n):
            r_in[i, c] = q[i, c] + r_in[0, c]
            v_in[i, c] = u[i, c] + com[3 + c]


@njit(cache=True, error_model="numpy")
def _in_order(extra, tangent, p, r, v, dr, dv, acc, da, perm):  # pragma: no cover - compiled
    """The effects' accelerations (``extra``, into ``acc``) and the tangent
    right-hand side ``tangent`` (into ``da``) at the rows
    of a splitting (row ``i`` is body ``order[i]``), evaluated with the bodies in
    the caller's order, whose indices the effects' parameters use: ``perm =
    (order, gm_c, r_c, v_c, acc_c, dr_c, dv_c, da_c)`` (``gm_c`` the caller's ``G
    m``, the others work arrays).  ``acc`` and ``da`` are zeroed first.  Copies
    only: with the central body first, the bits of calls on ``r`` ... directly."""
    order, gm_c, r_c, v_c, acc_c, dr_c, dv_c, da_c = perm
    n = r.shape[0]
    for blk in range(dr.shape[0] // n + 1):
        x = r if blk == 0 else dr[(blk - 1) * n:blk * n]
        w = v if blk == 0 else dv[(blk - 1) * n:blk * n]
        xc = r_c if blk == 0 else dr_c[(blk - 1) * n:blk * n]
        wc = v_c if blk == 0 else dv_c[(blk - 1) * n:blk * n]
        for i in range(n):
            j = order[i]
            for c in range(3):
                xc[j, c] = x[i, c]
                wc[j, c] = w[i, c]
    acc_c[:, :] = 0.0
    da_c[:, :] = 0.0
    extra(r_c, v_c, gm_c, acc_c, p)
    tangent(r_c, v_c, gm_c, dr_c, dv_c, da_c, p)
    for blk in range(dr.shape[0] // n + 1):
        a = acc if blk == 0 else da[(blk - 1) * n:blk * n]
        ac = acc_c if blk == 0 else da_c[(blk - 1) * n:blk * n]
        for i in range(n):
            j = order[i]
            for c in range(3):
                a[i, c] = ac[j, c]


@njit(cache=True, error_model="numpy")
def _perm(has_extra, order, gm, kn):  # pragma: no cover - compiled
    """The ``perm`` of :func:`_in_order` (its work arrays empty without effects)."""
    n = gm.shape[0] if has_extra else 0
    k = kn if has_extra else 0
    return (order, caller_gm(gm, order), np.empty((n, 3)), np.zeros((n, 3)), np.empty((n, 3)),
            np.empty((k, 3)), np.zeros((k, 3)), np.empty((k, 3)))


@njit(cache=True, inline="always", error_model="numpy")
def _kick_dh(extra, tangent_extra, p, has_extra, q, u, com, dq, du, dcom, gm, gm_p, idx, h,
             m_tot, w, perm):  # pragma: no cover - compiled
    """Jump h/2, interaction kick h (and the effects), jump h/2, with tangents.
    ``w``: work arrays (acc, da, r_in, v_in, acc_x, dr_in, dv_in, da_x); ``perm``:
    the bodies in the caller's order for the effects (:func:`_in_order`)."""
    acc, da, r_in, v_in, acc_x, dr_in, dv_in, da_x = w
    n = q.shape[0]
    k = dq.shape[0] // n
    _jump(q, u, dq, du, gm, 0.5 * h)
    _nbody.newtonian_rows(q, gm_p, idx, 1, acc)
    newtonian_jvp(q, u, gm_p, dq, du, da)
    for i in range(1, n):
        for c in range(3):
            u[i, c] += h * acc[i, c]
    for m in range(k):
        for i in range(1, n):
            for c in range(3):
                du[m * n + i, c] += h * da[m * n + i, c]
    if has_extra:
        _inertial_dh(q, u, com, gm, m_tot, r_in, v_in)
        for m in range(k):
            _inertial_dh(dq[m * n:(m + 1) * n], du[m * n:(m + 1) * n], dcom[m], gm, m_tot,
                         dr_in[m * n:(m + 1) * n], dv_in[m * n:(m + 1) * n])
        _in_order(extra, tangent_extra, p, r_in, v_in, dr_in, dv_in, acc_x, da_x, perm)
        for blk in range(k + 1):
            a = acc_x if blk == 0 else da_x[(blk - 1) * n:blk * n]
            uu = u if blk == 0 else du[(blk - 1) * n:blk * n]
            cc = com if blk == 0 else dcom[blk - 1]
            for c in range(3):
                a_cm = 0.0
                for i in range(n):
                    a_cm += gm[i] * a[i, c]
                a_cm /= m_tot
                cc[3 + c] += h * a_cm
                for i in range(1, n):
                    uu[i, c] += h * (a[i, c] - a_cm)
    _jump(q, u, dq, du, gm, 0.5 * h)


@njit(cache=True, inline="always", error_model="numpy")
def _drift_dh(q, u, com, dq, du, dcom, mu, tau, xa, va):  # pragma: no cover - compiled
    """Kepler drift of the bodies and uniform drift of the barycentre, with tangents."""
    bad = _kepler_drift(q, u, mu, tau, dq, du, xa, va)
    for c in range(3):
        com[c] += tau * com[3 + c]
        for m in range(dcom.shape[0]):
            dcom[m, c] += tau * dcom[m, 3 + c]
    return bad


@njit(cache=True, error_model="numpy")
def _ln_delta_dh(dq, du, dcom, gm, m_tot, r0, v0):  # pragma: no cover - compiled
    """``ln |delta|`` of tangent vector 0 in inertial coordinates."""
    n = r0.shape[0]
    _inertial_dh(dq[:n], du[:n], dcom[0], gm, m_tot, r0, v0)
    s = 0.0
    for i in range(n):
        for c in range(3):
            s += r0[i, c] * r0[i, c] + v0[i, c] * v0[i, c]
    return 0.5 * math.log(s) if s > 0.0 else -math.inf


@entry(types.Tuple((types.int64, types.int64))(
    ADDRESSES, ADDRESSES, F1, types.boolean, _I1, F2, F2, F1, F1, F1, F2, F2, F2,
    types.float64, types.int64, types.float64, types.float64, F1), cache=True,
    error_model="numpy")
def advance_dh(extra_addr, tangent_extra_addr, p, has_extra, order, q, u, gm, gm_p, com, dq, du,
               dcom, dt, n_steps, dt_last, t0, ms):  # pragma: no cover - compiled
    """``n_steps`` democratic-heliocentric steps (the last of length ``dt_last``) from
    ``t0``, synchronised at both ends, with the tangent vectors ``(dq, du, dcom)``;
    the coordinates (and ``order``) as :func:`hamilton_orbits._kernels.wh.advance_dh`
    takes them.
    Returns ``(steps, bad)``, ``bad`` a body whose Kepler step failed or -1."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    tangent_extra = tangent_at(tangent_extra_addr[0], tangent_extra_addr[1])
    n = q.shape[0]
    kn = dq.shape[0]
    w = (np.empty((n, 3)), np.empty((kn, 3)), np.empty((n, 3)), np.empty((n, 3)),
         np.empty((n, 3)), np.empty((kn, 3)), np.empty((kn, 3)), np.empty((kn, 3)))
    xa, va = np.empty(3), np.empty(3)
    perm = _perm(has_extra, order, gm, kn)
    m_tot = 0.0
    for i in range(n):
        m_tot += gm[i]
    idx = _nbody.massive_indices(gm_p)
    mu = np.full(n, gm[0])
    t = t0  # the start of the step
    t_last = t0  # the time of the last MEGNO sample
    h = 0.0
    for s in range(-1, n_steps):  # (s = -1: the first half drift; one call site of
        if s < 0:  # the drift and of the kick, inlined: see _drift_dh)
            tau = 0.5 * step_length(0, n_steps, dt, dt_last)
        else:
            h = step_length(s, n_steps, dt, dt_last)
            set_clock(p, t + 0.5 * h)  # (the kick: the middle of the step)
            _kick_dh(extra, tangent_extra, p, has_extra, q, u, com, dq, du, dcom, gm, gm_p, idx,
                     h, m_tot, w, perm)
            megno_map_step(ms, _ln_delta_dh(dq, du, dcom, gm, m_tot, w[2], w[3]), t + 0.5 * h,
                           t + 0.5 * h - t_last)
            f = renormalise(ms, dq, du, n)
            if f != 1.0:
                for c in range(6):
                    dcom[0, c] *= f
            t_last = t + 0.5 * h
            h_next = step_length(s + 1, n_steps, dt, dt_last)
            tau = 0.5 * (h + h_next)
        bad = _drift_dh(q, u, com, dq, du, dcom, mu, tau, xa, va)
        if bad >= 0:
            return max(s, 0), bad
        t += h
    megno_map_step(ms, _ln_delta_dh(dq, du, dcom, gm, m_tot, w[2], w[3]), t, t - t_last)
    return n_steps, -1


@njit(cache=True, error_model="numpy")
def _to_jacobi_acc(a, gm, inv, aj):  # pragma: no cover - compiled
    """Jacobi accelerations ``aj_i = a_i - (sum_{j<i} m_j a_j) / eta_(i-1)``, i >= 1."""
    n = a.shape[0]
    for c in range(3):
        s = gm[0] * a[0, c]
        for i in range(1, n):
            aj[i, c] = a[i, c] - s * inv[i - 1]
            s += gm[i] * a[i, c]


@njit(cache=True, inline="always", error_model="numpy")
def _kick_jacobi(extra, tangent, p, has_extra, qj, uj, dq, du, gm, idx, eta, ratio, inv, h, w,
                 perm):  # pragma: no cover - compiled
    """The interaction kick in Jacobi coordinates (as
    :mod:`hamilton_orbits._kernels.wh`) with its tangent: the inertial Jacobian
    (Newtonian and effects) at the inertial positions, in Jacobi form, plus the
    derivative of ``G eta_i qj_i / |qj_i|^3``,
    ``eta_i (e / |q|^3 - 3 (q.e) q / |q|^5)``.  With effects, they and the
    Jacobian see the bodies in the caller's order (``perm``: :func:`_in_order`)."""
    acc, da, r_in, v_in, acc_x, dr_in, dv_in, aj = w
    n = qj.shape[0]
    k = dq.shape[0] // n
    m_tot = eta[n - 1]
    jacobi_to_inertial_pos(qj, gm, eta, ratio, inv, r_in)
    for m in range(k):
        jacobi_to_inertial_pos(dq[m * n:(m + 1) * n], gm, eta, ratio, inv,
                               dr_in[m * n:(m + 1) * n])
    _nbody.newtonian_rows(r_in, gm, idx, 0, acc)
    if not has_extra:
        tangent(r_in, v_in, gm, dr_in, dv_in, da, p)
    else:
        _in_order(extra, tangent, p, r_in, v_in, dr_in, dv_in, acc_x, da, perm)
        for i in range(n):
            for c in range(3):
                acc[i, c] += acc_x[i, c]
    for blk in range(k + 1):
        a = acc if blk == 0 else da[(blk - 1) * n:blk * n]
        uu = uj if blk == 0 else du[(blk - 1) * n:blk * n]
        if has_extra:  # the effects' net force moves the barycentre
            for c in range(3):
                a_cm = 0.0
                for i in range(n):
                    a_cm += gm[i] * a[i, c]
                uu[0, c] += h * a_cm / m_tot
        _to_jacobi_acc(a, gm, inv, aj)
        for i in range(1, n):
            d2 = qj[i, 0] * qj[i, 0] + qj[i, 1] * qj[i, 1] + qj[i, 2] * qj[i, 2]
            f = eta[i] / (d2 * math.sqrt(d2))
            if blk == 0:
                for c in range(3):
                    uu[i, c] += h * (aj[i, c] + f * qj[i, c])
            else:
                e = dq[(blk - 1) * n + i]
                qe = 3.0 * (qj[i, 0] * e[0] + qj[i, 1] * e[1] + qj[i, 2] * e[2]) / d2
                for c in range(3):
                    uu[i, c] += h * (aj[i, c] + f * (e[c] - qe * qj[i, c]))


@njit(cache=True, inline="always", error_model="numpy")
def _drift_jacobi(qj, uj, dq, du, eta, tau, xa, va):  # pragma: no cover - compiled
    """Kepler drift of the bodies about ``eta_i`` and the barycentre (row 0)."""
    n = qj.shape[0]
    bad = _kepler_drift(qj, uj, eta, tau, dq, du, xa, va)
    for c in range(3):
        qj[0, c] += tau * uj[0, c]
    for m in range(dq.shape[0] // n):
        for c in range(3):
            dq[m * n, c] += tau * du[m * n, c]
    return bad


@njit(cache=True, error_model="numpy")
def _ln_delta_jacobi(dq, du, gm, eta, ratio, inv, r0, v0):  # pragma: no cover - compiled
    """``ln |delta|`` of tangent vector 0 in inertial coordinates."""
    n = r0.shape[0]
    jacobi_to_inertial_pos(dq[:n], gm, eta, ratio, inv, r0)
    jacobi_to_inertial_pos(du[:n], gm, eta, ratio, inv, v0)
    tot = 0.0
    for i in range(n):
        for c in range(3):
            tot += r0[i, c] * r0[i, c] + v0[i, c] * v0[i, c]
    return 0.5 * math.log(tot) if tot > 0.0 else -math.inf


@entry(types.Tuple((types.int64, types.int64))(
    ADDRESSES, ADDRESSES, F1, types.boolean, _I1, F2, F2, F1, F1, F2, F2, types.float64,
    types.int64, types.float64, types.float64, F1), cache=True, error_model="numpy")
def advance_jacobi(extra_addr, tangent_addr, p, has_extra, order, qj, uj, gm, eta, dq, du, dt,
                   n_steps, dt_last, t0, ms):  # pragma: no cover - compiled
    """As :func:`advance_dh` in Jacobi coordinates (``qj``, ``uj``, row 0 the
    barycentre; ``eta_i = sum_{j<=i} G m_j``), ``tangent`` the whole tangent
    right-hand side (Newtonian and effects).  Returns ``(steps, bad)``."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    tangent = tangent_at(tangent_addr[0], tangent_addr[1])
    n = qj.shape[0]
    kn = dq.shape[0]
    w = (np.empty((n, 3)), np.empty((kn, 3)), np.empty((n, 3)), np.zeros((n, 3)),
         np.empty((n, 3)), np.empty((kn, 3)), np.zeros((kn, 3)), np.empty((n, 3)))
    xa, va = np.empty(3), np.empty(3)
    idx = _nbody.massive_indices(gm)
    ratio, inv = jacobi_factors(eta)
    r0, v0 = np.empty((n, 3)), np.empty((n, 3))
    perm = _perm(has_extra, order, gm, kn)
    t = t0
    t_last = t0
    h = 0.0
    for s in range(-1, n_steps):  # (s = -1: the first half drift; one call site of
        if s < 0:  # the drift and of the kick, inlined: see _drift_dh)
            tau = 0.5 * step_length(0, n_steps, dt, dt_last)
        else:
            h = step_length(s, n_steps, dt, dt_last)
            set_clock(p, t + 0.5 * h)  # (the kick: the middle of the step)
            _kick_jacobi(extra, tangent, p, has_extra, qj, uj, dq, du, gm, idx, eta, ratio, inv,
                         h, w, perm)
            megno_map_step(ms, _ln_delta_jacobi(dq, du, gm, eta, ratio, inv, r0, v0),
                           t + 0.5 * h, t + 0.5 * h - t_last)
            renormalise(ms, dq, du, n)
            t_last = t + 0.5 * h
            h_next = step_length(s + 1, n_steps, dt, dt_last)
            tau = 0.5 * (h + h_next)
        bad = _drift_jacobi(qj, uj, dq, du, eta, tau, xa, va)
        if bad >= 0:
            return max(s, 0), bad
        t += h
    megno_map_step(ms, _ln_delta_jacobi(dq, du, gm, eta, ratio, inv, r0, v0), t, t - t_last)
    return n_steps, -1

