"""The compiled steps of the Wisdom-Holman map (driver and method:
:mod:`hamilton_orbits.integrators.wh`).

Democratic-heliocentric steps (:func:`advance_dh`), Jacobi steps
(:func:`advance_jacobi`) with the third-order corrector of Wisdom, Holman &
Touma (1996) (:func:`corrector_jacobi`), and the Jacobi coordinate changes.
The effects part of the right-hand side is a first-class function
``extra(r, v, gm, acc, p)`` (:data:`hamilton_orbits._kernels.signatures.ACCEL_TYPE`).
A drift of :data:`LANES_FROM` bodies or more solves their Kepler steps side by
side in vector lanes (:func:`hamilton_orbits._kernels.kepler.propagate_lanes`),
to the bits of the scalar kernel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import carray, njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from hamilton_orbits._kernels import events as _ev
from hamilton_orbits._kernels import kepler as _kepler
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._kernels.entry import entry
from hamilton_orbits._kernels.signatures import ADDRESSES, F1, F2, accel_at, set_clock

_I1 = types.int64[::1]

__all__ = [
    "STATUS_DRAIN",
    "STATUS_EVENT",
    "STATUS_OK",
    "advance_dh",
    "advance_dh_effects",
    "advance_dh_watched",
    "advance_jacobi",
    "advance_jacobi_effects",
    "advance_jacobi_watched",
    "caller_gm",
    "corrector_jacobi",
    "dh_from_inertial",
    "dh_to_inertial",
    "effects_in_order",
    "jacobi_factors",
    "jacobi_from_inertial",
    "jacobi_to_inertial",
    "jacobi_to_inertial_pos",
]


#: From this many bodies on (besides the central one or the barycentre) a drift
#: solves their Kepler steps side by side (:func:`_kepler_lanes`); below, one
#: after the other (measured: docs/nbody_integrators.md).
LANES_FROM = 4
#: The lanes of a vector (8 float64): the lane columns are a multiple of it long.
LANES = 8
#: The most lanes at a time (the bodies in blocks of as many): the work space,
#: :data:`_kepler.LANE_COLUMNS` float64 a lane, is on the stack (7.5 KB).
LANE_BLOCK = 64


@njit(cache=True, error_model="numpy")
def _kepler_all(q, u, mu, tau):  # pragma: no cover - compiled
    """Advance every body ``i >= 1`` on its Kepler orbit about ``mu[i]`` (``mu[0]``
    for all when ``mu`` has one element) by ``tau``: from :data:`LANES_FROM`
    bodies on side by side (:func:`_kepler_lanes`), else the shared kernel inlined
    (the bodies' solves overlap in the processor: with effects in the loop, a step
    of three bodies costs 15% more with it called, as :func:`_kepler_few` does).
    The same bits either way.

    Returns the index of the first failure (NaN from the kernel), else -1."""
    n = q.shape[0]
    if n - 1 >= LANES_FROM and tau != 0.0:
        return _kepler_lanes(q, u, mu, tau)
    one = mu.shape[0] == 1
    for i in range(1, n):
        state = _kepler.propagate_uv_inline(
            q[i, 0], q[i, 1], q[i, 2], u[i, 0], u[i, 1], u[i, 2], mu[0] if one else mu[i], tau
        )
        if not _store(q, u, i, state):
            return i
    return -1


@njit(cache=True, error_model="numpy")
def _kepler_few(q, u, mu, tau):  # pragma: no cover - compiled
    """:func:`_kepler_all` below :data:`LANES_FROM` bodies, the shared kernel called,
    not inlined (compiled once: a first run of a few bodies compiles neither its
    inlined copy nor the lanes; without effects a step costs the same).  The same
    bits."""
    one = mu.shape[0] == 1
    for i in range(1, q.shape[0]):
        state = _kepler.propagate_uv(
            q[i, 0], q[i, 1], q[i, 2], u[i, 0], u[i, 1], u[i, 2], mu[0] if one else mu[i], tau
        )
        if not _store(q, u, i, state):
            return i
    return -1


@njit(cache=True, error_model="numpy")
def _kepler_lanes(q, u, mu, tau):  # pragma: no cover - compiled
    """:func:`_kepler_all` in blocks of up to :data:`LANE_BLOCK` bodies side by side
    (:func:`_kepler.propagate_lanes`, lanes padded to a multiple of :data:`LANES`);
    the few bodies the lanes leave (a step towards periapsis to anchor, a long
    step, a solve that needs a second evaluation) by the shared kernel, called
    (one copy of it, not inlined)."""
    n = q.shape[0]
    m = min((n - 1 + LANES - 1) // LANES * LANES, LANE_BLOCK)
    lw = carray(_lane_scratch(), _kepler.LANE_COLUMNS * m)
    one = mu.shape[0] == 1
    for b0 in range(1, n, m):
        b1 = min(b0 + m, n)
        _to_lanes(q, u, mu, b0, b1, lw, m)
        _kepler.propagate_lanes(lw, m, tau)
        for i in range(b0, b1):
            a = i - b0
            if lw[14 * m + a] != 0.0:
                state = (lw[8 * m + a], lw[9 * m + a], lw[10 * m + a], lw[11 * m + a],
                         lw[12 * m + a], lw[13 * m + a])
            else:
                state = _kepler.propagate_uv(q[i, 0], q[i, 1], q[i, 2], u[i, 0], u[i, 1],
                                             u[i, 2], mu[0] if one else mu[i], tau)
            if not _store(q, u, i, state):
                return i
    return -1


@njit(cache=True, inline="always", error_model="numpy")
def _store(q, u, i, state):  # pragma: no cover - compiled
    """Row ``i`` of ``q``, ``u`` from a Kepler step's ``state`` (6 floats), if it is
    finite (else the row is left, and False)."""
    x, y, z, vx, vy, vz = state
    if not math.isfinite(x + y + z + vx + vy + vz):
        return False
    q[i, 0] = x
    q[i, 1] = y
    q[i, 2] = z
    u[i, 0] = vx
    u[i, 1] = vy
    u[i, 2] = vz
    return True


@njit(cache=True, inline="always", error_model="numpy")
def _to_lanes(q, u, mu, b0, b1, lw, m):  # pragma: no cover - compiled
    """Rows ``b0 .. b1 - 1`` into the ``m`` lanes of ``lw``, the lanes beyond them a
    copy of row ``b0``, with their ``mu`` and ``sqrt(mu)``."""
    one = mu.shape[0] == 1
    s0 = math.sqrt(mu[0])
    for a in range(m):
        i = b0 + a if b0 + a < b1 else b0
        for c in range(3):
            lw[c * m + a] = q[i, c]
            lw[(3 + c) * m + a] = u[i, c]
        lw[6 * m + a] = mu[0] if one else mu[i]
        lw[7 * m + a] = s0 if one else math.sqrt(mu[i])


@intrinsic
def _lane_scratch(typingctx):  # pragma: no cover - compiled
    """A pointer to ``LANE_COLUMNS * LANE_BLOCK`` float64 on the stack of the
    function that calls it (valid until it returns), aligned to 64 bytes (the
    widest vector); no allocation per drift."""

    def codegen(context, builder, signature, args):
        size = _kepler.LANE_COLUMNS * LANE_BLOCK + LANES
        with builder.goto_entry_block():  # a fixed frame slot, not filled
            raw = builder.alloca(context.get_value_type(types.float64),
                                 size=cgutils.intp_t(size))
        addr = builder.ptrtoint(raw, cgutils.intp_t)
        aligned = builder.and_(builder.add(addr, addr.type(63)), addr.type(-64))
        return builder.inttoptr(aligned, raw.type)

    return types.CPointer(types.float64)(), codegen


@njit(cache=True, inline="always", error_model="numpy")
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


#: Statuses of the stepping kernels (as radau15's): done, an event with an action
#: occurred (the state is at the end of the step it occurred in), or the event
#: buffer needs draining (the state is at a step end).
STATUS_OK = 0
STATUS_EVENT = 4
STATUS_DRAIN = 5


@njit(cache=True, inline="always", error_model="numpy")
def _drift(watched, q, u, mu, tau, jacobi, com, watch, ev_out, ev_count, ws, x0, v0, mu_s, g,
           jump, no_ab):  # pragma: no cover - compiled
    """One Kepler drift of ``tau`` with the barycentre; with events watched
    (``watch`` not None and ``watched``; ``watch`` None is decided at compile time:
    the loops without events have no trace of them), the drift is scanned on the Kepler arcs
    themselves (Jacobi turned into inertial positions; democratic heliocentric
    with the jumps around the drift spread over it, ``jump`` the one before it:
    :func:`hamilton_orbits._kernels.events._dh_constants`; ``g`` the rows' ``G m``).
    ``ws = [t, t_action, drain, row]``: the drift's start time (advanced here),
    the time and watch row of the first event with an action, and whether the
    buffer must be drained.  ``no_ab``: zero arrays (1,) and (7, 1) for the scan's
    unused arguments (see :func:`_no_ab`).  Returns a failing body or -1."""
    if watch is not None and watched:
        return _drift_watched(q, u, mu, tau, jacobi, com, watch, ev_out, ev_count, ws, x0, v0,
                              mu_s, g, jump, no_ab)
    bad = _kepler_all(q, u, mu, tau)
    if jacobi:
        for k in range(3):
            q[0, k] += tau * u[0, k]
    else:
        for k in range(3):
            com[k] += tau * com[3 + k]
    ws[0] += tau
    return bad


@njit(cache=True, inline="always", error_model="numpy")
def _drift_watched(q, u, mu, tau, jacobi, com, watch, ev_out, ev_count, ws, x0, v0, mu_s, g,
                   jump, no_ab):  # pragma: no cover - compiled
    """:func:`_drift` with its events scanned.  Inlined, at the one call site of
    :func:`_dh_steps` (and of :func:`_jacobi_steps`): called, it was a level of
    linking more, the scan optimised once more (1.3 s of compilation), and both
    branches on ``jacobi`` were compiled into every entry."""
    n_watch = watch.shape[0]
    _copy(q, u, x0, v0)
    bad = _kepler_all(q, u, mu, tau)
    for k in range(3):
        if jacobi:
            q[0, k] += tau * u[0, k]
        else:
            com[k] += tau * com[3 + k]
    if bad < 0:
        cm = np.zeros(9)
        if jacobi:  # escapes from the barycentre, Jacobi row 0
            for k in range(3):
                cm[k], cm[3 + k], cm[6 + k] = x0[0, k], v0[0, k], q[0, k]
            h, row = _ev.scan(watch, _ev.JACOBI, ws[0], tau, x0, v0, q, u, no_ab[0], no_ab[1],
                              mu_s, cm, ev_out, ev_count)
        else:  # the jump before the drift in cm[0], the masses in place of a0
            cm[0] = jump
            h, row = _ev.scan(watch, _ev.DH, ws[0], tau, x0, v0, q, u, g, no_ab[1], mu_s, cm,
                              ev_out, ev_count)
        if row >= 0 and ws[0] + h * tau < ws[1]:
            ws[1] = ws[0] + h * tau
            ws[3] = row
        if ev_count[0] + 2 * n_watch > ev_out.shape[0]:
            ws[2] = 1.0
    ws[0] += tau
    return bad


_ORIGIN = np.zeros(9)


@njit(cache=True, inline="always", error_model="numpy")
def step_length(k, n_steps, dt, dt_last):  # pragma: no cover - compiled
    """The length of step ``k`` of a call of ``n_steps`` steps: ``dt``, the last one
    ``dt_last``, 0 after the last (step 0 is never 0: a call's first half drift).
    The one rule of every Wisdom-Holman step loop, here and in ``wh_tangent``."""
    if k > 0 and k >= n_steps:
        return 0.0
    return dt if k < n_steps - 1 else dt_last


@njit(cache=True, inline="always", error_model="numpy")
def _no_ab():  # pragma: no cover - compiled
    """Zero arrays (1,) and (7, 1) for the arguments ``a0``, ``b`` of the events' scan
    that the Kepler arcs do not use: writable, as radau15's (global arrays are read-only
    to numba, another type), so that every caller shares one compiled scan (each
    type of them compiled it again: 15 s)."""
    return np.zeros(1), np.zeros((7, 1))


@njit(cache=True, inline="always", error_model="numpy")
def _copy(q, u, x, v):  # pragma: no cover - compiled
    """The drift's start state, kept for the scan."""
    for i in range(q.shape[0]):
        for k in range(3):
            x[i, k] = q[i, k]
            v[i, k] = u[i, k]


@njit(cache=True, inline="always", error_model="numpy")
def _stop_here(q, u, mu, h_back, jacobi, com, ws, t_end_step, ev_out, ev_count):
    # pragma: no cover - compiled
    """After a merged drift, go back ``h_back`` (exact: Kepler drifts reverse) to the
    end of the step, and forget the events the scan found beyond it (the next
    call finds them again).  Returns the status to report."""
    _kepler_all(q, u, mu, -h_back)
    for k in range(3):
        if jacobi:
            q[0, k] -= h_back * u[0, k]
        else:
            com[k] -= h_back * com[3 + k]
    ws[0] -= h_back
    kept = 0
    for e in range(ev_count[0]):
        if ev_out[e, 3] <= t_end_step:
            for c in range(ev_out.shape[1]):
                ev_out[kept, c] = ev_out[e, c]
            kept += 1
    ev_count[0] = kept
    return STATUS_EVENT if ws[1] <= t_end_step else STATUS_DRAIN


@njit(cache=True, inline="always", error_model="numpy")
def _kick_dh(extra, p, has_extra, q, u, gm, idx, com, h, m_tot, acc_m, r_in, v_in, acc_x,
             order, gm_c):  # pragma: no cover - compiled
    """Jump h/2, the interaction kick h (and the listed effects, whose net force
    moves the barycentre), jump h/2.  ``idx``: the massive rows >= 1 (row 0, the
    central body, is not in the interaction).  The effects see the bodies in the
    caller's order (row ``i`` is body ``order[i]``; ``gm_c`` the caller's ``G m``):
    their parameters name bodies by the caller's indices."""
    _jump(q, u, gm, 0.5 * h)
    _nbody.kick_rows(q, gm, idx, 1, h, u, acc_m)
    if has_extra:
        _effects_kick_dh(extra, p, q, u, gm, com, h, m_tot, r_in, v_in, acc_x, order, gm_c)
    _jump(q, u, gm, 0.5 * h)


@njit(cache=True, inline="always", error_model="numpy")
def _effects_kick_dh(extra, p, q, u, gm, com, h, m_tot, r_in, v_in, acc_x, order, gm_c):
    # pragma: no cover - compiled
    """The listed effects' kick ``h`` in democratic-heliocentric coordinates (their
    net force moves the barycentre), evaluated with the bodies in the caller's order
    (see :func:`_kick_dh`)."""
    n = q.shape[0]
    gm0 = gm[0]
    # inertial state for the effects: r_0 = R - sum m_i Q_i / M
    c = order[0]
    for k in range(3):
        s_q = 0.0
        s_u = 0.0
        for i in range(1, n):
            s_q += gm[i] * q[i, k]
            s_u += gm[i] * u[i, k]
        r_in[c, k] = com[k] - s_q / m_tot
        v_in[c, k] = com[3 + k] - s_u / gm0
        for i in range(1, n):
            r_in[order[i], k] = q[i, k] + r_in[c, k]
            v_in[order[i], k] = u[i, k] + com[3 + k]
        for i in range(n):
            acc_x[i, k] = 0.0
    extra(r_in, v_in, gm_c, acc_x, p)
    for k in range(3):
        a_cm = 0.0
        for i in range(n):
            a_cm += gm[i] * acc_x[order[i], k]
        a_cm /= m_tot
        com[3 + k] += h * a_cm
        for i in range(1, n):
            u[i, k] += h * (acc_x[order[i], k] - a_cm)


@njit(cache=True, error_model="numpy")
def caller_gm(gm, order):  # pragma: no cover - compiled
    """``G m`` in the caller's order from the rows of a splitting (row ``i`` is body
    ``order[i]``): what the effects' kernels index with their parameters."""
    out = np.empty(gm.shape[0])
    for i in range(gm.shape[0]):
        out[order[i]] = gm[i]
    return out


@njit(cache=True, inline="always", error_model="numpy")
def effects_in_order(extra, p, r, v, acc, perm):  # pragma: no cover - compiled
    """The effects' accelerations at the rows ``r``, ``v`` of a splitting (row ``i``
    is body ``order[i]``) into ``acc`` (zeroed first), evaluated with the bodies in
    the caller's order: ``perm = (order, gm_c, r_c, v_c, acc_c)``, ``gm_c`` from
    :func:`caller_gm`, the others work arrays (n, 3).  Copies only: with the
    central body first (``order`` the identity) the bits of a call on ``r``, ``v``."""
    order, gm_c, r_c, v_c, acc_c = perm
    n = r.shape[0]
    for i in range(n):
        j = order[i]
        for k in range(3):
            r_c[j, k] = r[i, k]
            v_c[j, k] = v[i, k]
            acc_c[i, k] = 0.0
    extra(r_c, v_c, gm_c, acc_c, p)
    for i in range(n):
        j = order[i]
        for k in range(3):
            acc[i, k] = acc_c[j, k]


@njit(cache=True, error_model="numpy")
def _perm(has_extra, order, gm):  # pragma: no cover - compiled
    """The ``perm`` of :func:`effects_in_order` (its work arrays empty without
    effects)."""
    m = gm.shape[0] if has_extra else 0
    return order, caller_gm(gm, order), np.empty((m, 3)), np.zeros((m, 3)), np.empty((m, 3))


@njit(cache=True, error_model="numpy")
def jacobi_factors(eta):  # pragma: no cover - compiled
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


@njit(cache=True, inline="always", error_model="numpy")
def jacobi_to_inertial_pos(qj, gm, eta, ratio, inv, r):  # pragma: no cover - compiled
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


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
def _kick_jacobi(
    extra, p, has_extra, qj, uj, gm, idx, eta, ratio, inv, h, move_com, acc, accj, acc_x, r_in,
    v_in, perm,
):  # pragma: no cover - compiled
    """The interaction kick of length ``h`` in Jacobi coordinates (``idx``: the
    massive indices of ``gm``; ``ratio``, ``inv``: :func:`_jacobi_factors`); the
    effects evaluated with the bodies in the caller's order (``perm``: see
    :func:`effects_in_order`)."""
    jacobi_to_inertial_pos(qj, gm, eta, ratio, inv, r_in)
    _nbody.newtonian_rows(r_in, gm, idx, 0, acc)
    if has_extra:
        _effects_jacobi(extra, p, uj, gm, eta, h, move_com, acc, acc_x, r_in, v_in, perm)
    _inertial_to_jacobi_acc(acc, gm, inv, accj)
    _kick_interaction(qj, uj, eta, accj, h)


@njit(cache=True, inline="always", error_model="numpy")
def _effects_jacobi(extra, p, uj, gm, eta, h, move_com, acc, acc_x, r_in, v_in, perm):
    # pragma: no cover - compiled
    """The listed effects' accelerations at the inertial rows ``r_in``, ``v_in`` added
    to ``acc`` (and, with ``move_com``, their net force kicking the barycentre's
    velocity ``uj[0]`` by ``h``): see :func:`_kick_jacobi`."""
    n = uj.shape[0]
    effects_in_order(extra, p, r_in, v_in, acc_x, perm)
    m_tot = eta[n - 1]
    for k in range(3):
        a_cm = 0.0
        for i in range(n):
            a_cm += gm[i] * acc_x[i, k]
            acc[i, k] += acc_x[i, k]
        if move_com:
            # the effects' net force moves the barycentre
            uj[0, k] += h * a_cm / m_tot


@njit(cache=True, inline="always", error_model="numpy")
def _kick_interaction(qj, uj, eta, accj, h):  # pragma: no cover - compiled
    """``uj_i += h (aj_i + eta_i qj_i / |qj_i|^3)``, i >= 1: the Jacobi kick, the
    Kepler part of each body's acceleration taken out (it is in the drift)."""
    for i in range(1, qj.shape[0]):
        d2 = qj[i, 0] * qj[i, 0] + qj[i, 1] * qj[i, 1] + qj[i, 2] * qj[i, 2]
        f = eta[i] / (d2 * math.sqrt(d2))
        for k in range(3):
            uj[i, k] += h * (accj[i, k] + f * qj[i, k])


@entry(
    types.int64(ADDRESSES, F1, types.boolean, _I1, F2, F2, F1, F1, types.float64, types.float64,
                F1, F1),
    cache=True, nogil=True,
    error_model="numpy",
)
def corrector_jacobi(extra_addr, p, has_extra, order, qj, uj, gm, eta, dt, sign, a, b):
    # pragma: no cover - compiled
    """Apply a symplectic corrector (``sign = 1``) or its inverse (``-1``): the
    product of ``Z(a_k dt, sign b_k dt)`` over the sequence ``a``, ``b`` (see
    :func:`hamilton_orbits.integrators.wh.corrector_coefficients`), with ``Z(a,
    b)`` = Kepler a, kick -b, Kepler -2a, kick b, Kepler a (Wisdom, Holman &
    Touma 1996).  The sequence is antisymmetric (``(a, b)`` reversed is ``(-a,
    -b)``), so ``sign = -1`` is the exact inverse.  ``order``: row ``i`` is the
    caller's body ``order[i]`` (the effects see the caller's order).  Returns a
    failing index or -1."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    n = qj.shape[0]
    acc = np.empty((n, 3))
    accj = np.empty((n, 3))
    acc_x = np.empty((n, 3))
    r_in = np.empty((n, 3))
    v_in = np.zeros((n, 3))
    perm = _perm(has_extra, order, gm)
    idx = _nbody.massive_indices(gm)
    ratio, inv = jacobi_factors(eta)
    for k in range(a.shape[0]):
        ak = a[k] * dt
        bk = sign * b[k] * dt
        # Z's five stages from one call site each of the drift and of the inlined
        # kick (the kick written out twice, and the drift called thrice, cost 1.3 s
        # more of compilation for the same arithmetic; measured)
        for stage in range(5):
            if stage % 2 == 0:
                bad = _kepler_all(qj, uj, eta, -2.0 * ak if stage == 2 else ak)
                if bad >= 0:
                    return bad
            else:
                _kick_jacobi(
                    extra, p, has_extra, qj, uj, gm, idx, eta, ratio, inv,
                    -bk if stage == 1 else bk, False, acc, accj, acc_x, r_in, v_in, perm,
                )
    return -1


@njit(cache=True, error_model="numpy")
def dh_from_inertial(r, v, g, order, q, u, com):  # pragma: no cover - compiled
    """Heliocentric positions ``q`` and barycentric velocities ``u`` (row ``i`` is
    body ``order[i]``; ``order[0]`` the central body) and the barycentre ``com``
    (position, velocity) from inertial ``r``, ``v``.  (Sums in scalars, not a
    work array: no array constructor to compile for a first run.)"""
    n = r.shape[0]
    m_tot = 0.0
    sx = sy = sz = su = sv = sw = 0.0
    for i in range(n):  # row by row: one pass over memory
        j = order[i]
        gi = g[i]
        m_tot += gi
        if gi != 0.0:
            sx += gi * r[j, 0]
            sy += gi * r[j, 1]
            sz += gi * r[j, 2]
            su += gi * v[j, 0]
            sv += gi * v[j, 1]
            sw += gi * v[j, 2]
    com[0], com[1], com[2] = sx / m_tot, sy / m_tot, sz / m_tot
    com[3], com[4], com[5] = su / m_tot, sv / m_tot, sw / m_tot
    c = order[0]
    cx, cy, cz = r[c, 0], r[c, 1], r[c, 2]
    wx, wy, wz = com[3], com[4], com[5]
    for i in range(n):
        j = order[i]
        q[i, 0] = r[j, 0] - cx
        q[i, 1] = r[j, 1] - cy
        q[i, 2] = r[j, 2] - cz
        u[i, 0] = v[j, 0] - wx
        u[i, 1] = v[j, 1] - wy
        u[i, 2] = v[j, 2] - wz


@njit(cache=True, error_model="numpy")
def dh_to_inertial(q, u, g, com, order, r, v):  # pragma: no cover - compiled
    """Inertial ``r``, ``v`` (body ``order[i]`` from row ``i``) from the
    coordinates of :func:`dh_from_inertial` (sums in scalars, as there)."""
    n = q.shape[0]
    m_tot = g[0]
    sx = sy = sz = su = sv = sw = 0.0
    for i in range(1, n):
        gi = g[i]
        m_tot += gi
        if gi != 0.0:
            sx += gi * q[i, 0]
            sy += gi * q[i, 1]
            sz += gi * q[i, 2]
            su += gi * u[i, 0]
            sv += gi * u[i, 1]
            sw += gi * u[i, 2]
    x0, y0, z0 = com[0] - sx / m_tot, com[1] - sy / m_tot, com[2] - sz / m_tot
    c = order[0]
    r[c, 0], r[c, 1], r[c, 2] = x0, y0, z0
    v[c, 0] = com[3] - su / g[0]
    v[c, 1] = com[4] - sv / g[0]
    v[c, 2] = com[5] - sw / g[0]
    for i in range(1, n):
        j = order[i]
        r[j, 0] = q[i, 0] + x0
        r[j, 1] = q[i, 1] + y0
        r[j, 2] = q[i, 2] + z0
        v[j, 0] = u[i, 0] + com[3]
        v[j, 1] = u[i, 1] + com[4]
        v[j, 2] = u[i, 2] + com[5]


@njit(cache=True, error_model="numpy")
def jacobi_from_inertial(r, v, g, eta, order, q, u):  # pragma: no cover - compiled
    """Jacobi positions and velocities (row 0 the barycentre; row ``i`` is body
    ``order[i]``, ``eta_i = sum_{j<=i} g_j``) from inertial ``r``, ``v``."""
    n = r.shape[0]
    s = np.zeros(6)
    for i in range(n):  # row by row: one pass over memory
        j = order[i]
        if i > 0:
            e = eta[i - 1]
            for k in range(3):
                q[i, k] = r[j, k] - s[k] / e
                u[i, k] = v[j, k] - s[3 + k] / e
        gi = g[i]
        for k in range(3):
            s[k] += gi * r[j, k]
            s[3 + k] += gi * v[j, k]
    for k in range(3):
        q[0, k] = s[k] / eta[n - 1]
        u[0, k] = s[3 + k] / eta[n - 1]


@njit(cache=True, error_model="numpy")
def jacobi_to_inertial(q, u, g, eta, ratio, inv, order, r, v):  # pragma: no cover - compiled
    """Inertial ``r``, ``v`` (body ``order[i]`` from row ``i``) from Jacobi ``q``,
    ``u`` (:func:`jacobi_to_inertial_pos` for both)."""
    n = q.shape[0]
    w = np.empty((n, 3))
    for which in range(2):
        jacobi_to_inertial_pos(q if which == 0 else u, g, eta, ratio, inv, w)
        out = r if which == 0 else v
        for i in range(n):
            j = order[i]
            out[j, 0] = w[i, 0]
            out[j, 1] = w[i, 1]
            out[j, 2] = w[i, 2]


@njit(cache=True, inline="always", error_model="numpy")
def _dh_steps(watched, extra, p, has_extra, q, u, gm, com, dt, n_steps, dt_last, watch, ev_out,
              ev_count, ws, x0, v0, mu, mu_s, kick):  # pragma: no cover - compiled
    """The steps of :func:`advance_dh` (``kick``: its work arrays)."""
    idx, m_tot, acc_m, r_in, v_in, acc_x, order, gm_c = kick
    no_ab = _no_ab()
    t_step = ws[0]
    h = h_next = 0.0
    for s in range(-1, n_steps):  # (s = -1: the first half drift; one call site of the
        if s < 0:  # inlined drift, with its scan: see _drift_watched)
            tau = 0.5 * step_length(0, n_steps, dt, dt_last)
            jump = 0.0
        else:
            h = step_length(s, n_steps, dt, dt_last)
            if has_extra:
                set_clock(p, t_step + 0.5 * h)  # (the kick: the middle of the step)
            _kick_dh(extra, p, has_extra, q, u, gm, idx, com, h, m_tot, acc_m, r_in, v_in,
                     acc_x, order, gm_c)
            h_next = step_length(s + 1, n_steps, dt, dt_last)
            tau = 0.5 * (h + h_next)
            jump = 0.5 * h
        bad = _drift(watched, q, u, mu, tau, False, com, watch, ev_out, ev_count, ws, x0, v0,
                     mu_s, gm, jump, no_ab)
        if bad >= 0:
            return max(s, 0), bad, STATUS_OK
        if s >= 0:
            t_step += h
            if watch is not None and (ws[1] <= t_step or ws[2] > 0.0):
                return s + 1, -1, _stop_here(q, u, mu, 0.5 * h_next, False, com, ws, t_step,
                                             ev_out, ev_count)
    return n_steps, -1, STATUS_OK


@njit(cache=True, inline="always", error_model="numpy")
def _jacobi_steps(watched, extra, p, has_extra, qj, uj, gm, eta, dt, n_steps, dt_last, watch,
                  ev_out, ev_count, ws, x0, v0, kick):  # pragma: no cover - compiled
    """The steps of :func:`advance_jacobi` (``kick``: its work arrays)."""
    idx, ratio, inv, acc, accj, acc_x, r_in, v_in, perm = kick
    no_ab = _no_ab()
    t_step = ws[0]
    h = h_next = 0.0
    for s in range(-1, n_steps):  # (s = -1: the first half drift; one call site of the
        if s < 0:  # inlined drift, as in _dh_steps)
            tau = 0.5 * step_length(0, n_steps, dt, dt_last)
        else:
            h = step_length(s, n_steps, dt, dt_last)
            if has_extra:
                set_clock(p, t_step + 0.5 * h)  # (the kick: the middle of the step)
            _kick_jacobi(
                extra, p, has_extra, qj, uj, gm, idx, eta, ratio, inv, h, True,
                acc, accj, acc_x, r_in, v_in, perm,
            )
            h_next = step_length(s + 1, n_steps, dt, dt_last)
            tau = 0.5 * (h + h_next)
        bad = _drift(watched, qj, uj, eta, tau, True, eta, watch, ev_out, ev_count, ws, x0, v0,
                     eta, gm, 0.0, no_ab)
        if bad >= 0:
            return max(s, 0), bad, STATUS_OK
        if s >= 0:
            t_step += h
            if watch is not None and (ws[1] <= t_step or ws[2] > 0.0):
                return s + 1, -1, _stop_here(qj, uj, eta, 0.5 * h_next, True, eta, ws, t_step,
                                             ev_out, ev_count)
    return n_steps, -1, STATUS_OK


@njit(cache=True, inline="always", error_model="numpy")
def _dh_unwatched_steps(effects_kick, extra, p, q, u, gm, com, dt, n_steps, dt_last, ws, mu,
                        kick, few):  # pragma: no cover - compiled
    """:func:`_dh_steps` watching no event: the same arithmetic in the same order,
    the step's parts called from its own loop.  (Behind the nested inline wrappers of
    :func:`_kick_dh` and :func:`~hamilton_orbits._kernels.nbody.kick_rows`, arrays
    passed two levels deep keep reference counting in the loop: about 40% of a step
    at N = 2.)  A few massive bodies and no test particle: the pairs inlined, as
    ``kick_rows`` does; otherwise its spaced form, called.  ``effects_kick`` is
    :func:`_effects_kick_dh` or None, a constant of the caller: the loop without
    effects has no trace of them (numba prunes the branches on it once this loop
    is inlined; the call, made through this argument, is inlined only where it
    stays: tested on a flag, it was inlined into every entry first and pruned after,
    0.25 s of compilation for nothing).  ``few``
    (True, or None: decided at compile time) for fewer than :data:`LANES_FROM`
    bodies, all massive: only the forms those take are compiled (the pairs, the
    Kepler solver one body after another: :func:`_kepler_few`), the same bits."""
    idx, m_tot, acc_m, r_in, v_in, acc_x, order, gm_c = kick
    compact = idx.shape[0] < _nbody.SIMD_FROM and idx.shape[0] == q.shape[0] - 1
    t_step = ws[0]
    for s in range(-1, n_steps):  # (s = -1: the first half drift; one call site of
        if s < 0:  # the Kepler solver, whose code is large)
            tau = 0.5 * step_length(0, n_steps, dt, dt_last)
        else:
            h = step_length(s, n_steps, dt, dt_last)
            if effects_kick is not None:
                set_clock(p, t_step + 0.5 * h)  # (the kick: the middle of the step)
            _jump(q, u, gm, 0.5 * h)
            if few is not None or compact:  # (one inlined copy of the pairs)
                _nbody.compact_pairs(q, gm, idx, acc_m)
                _nbody.kick_massive(u, idx, h, acc_m)
            else:
                _nbody.kick_rows_spaced(q, gm, idx, 1, h, u, acc_m)
            if effects_kick is not None:
                effects_kick(extra, p, q, u, gm, com, h, m_tot, r_in, v_in, acc_x, order, gm_c)
            _jump(q, u, gm, 0.5 * h)
            h_next = step_length(s + 1, n_steps, dt, dt_last)
            tau = 0.5 * (h + h_next)
            t_step += h
        if few is not None:
            bad = _kepler_few(q, u, mu, tau)
        else:
            bad = _kepler_all(q, u, mu, tau)
        for k in range(3):
            com[k] += tau * com[3 + k]
        ws[0] += tau
        if bad >= 0:
            return max(s, 0), bad, STATUS_OK
    return n_steps, -1, STATUS_OK


@njit(cache=True, inline="always", error_model="numpy")
def _jacobi_unwatched_steps(effects_jacobi, extra, p, qj, uj, gm, eta, dt, n_steps, dt_last,
                            ws, kick, few):  # pragma: no cover - compiled
    """:func:`_jacobi_steps` watching no event, as :func:`_dh_unwatched_steps`
    (``effects_jacobi`` :func:`_effects_jacobi` or None; ``few`` alike): the same
    arithmetic in the same order."""
    idx, ratio, inv, acc, accj, acc_x, r_in, v_in, perm = kick
    compact = idx.shape[0] < _nbody.SIMD_FROM and idx.shape[0] == qj.shape[0]
    t_step = ws[0]
    for s in range(-1, n_steps):  # (s = -1: the first half drift)
        if s < 0:
            tau = 0.5 * step_length(0, n_steps, dt, dt_last)
        else:
            h = step_length(s, n_steps, dt, dt_last)
            if effects_jacobi is not None:
                set_clock(p, t_step + 0.5 * h)  # (the kick: the middle of the step)
            jacobi_to_inertial_pos(qj, gm, eta, ratio, inv, r_in)
            if few is not None or compact:  # (one inlined copy of the pairs)
                _nbody.pairs_rows(r_in, gm, idx, acc)
            else:
                _nbody.newtonian_rows_spaced(r_in, gm, idx, 0, acc)
            if effects_jacobi is not None:
                effects_jacobi(extra, p, uj, gm, eta, h, True, acc, acc_x, r_in, v_in, perm)
            _inertial_to_jacobi_acc(acc, gm, inv, accj)
            _kick_interaction(qj, uj, eta, accj, h)
            h_next = step_length(s + 1, n_steps, dt, dt_last)
            tau = 0.5 * (h + h_next)
            t_step += h
        if few is not None:  # (written out here and in _dh_unwatched_steps: one inline
            bad = _kepler_few(qj, uj, eta, tau)  # helper for both cost 25% of a step
        else:  # of two bodies, measured)
            bad = _kepler_all(qj, uj, eta, tau)
        for k in range(3):
            qj[0, k] += tau * uj[0, k]
        ws[0] += tau
        if bad >= 0:
            return max(s, 0), bad, STATUS_OK
    return n_steps, -1, STATUS_OK


_SPLIT_ARGS = (ADDRESSES, F1, types.boolean, _I1, F2, F2, F1, F1, types.float64, types.int64,
               types.float64)
_RESULT = types.Tuple((types.int64, types.int64, types.int64))
_EVENT_ARGS = (F2, F2, types.int64[::1])


@njit(cache=True, inline="always", error_model="numpy")
def _dh_setup(gm, watched, has_extra, order, gm_c):  # pragma: no cover - compiled
    """The work arrays of a run in democratic heliocentric coordinates: the
    drifts' start states for the events' scan (``watched``), the Kepler
    parameters ``mu`` (and ``mu_s``, the scan's: the central body rests at the
    origin of these coordinates) and the kick's arrays (the effects' only with
    ``has_extra``; the planets' mutual pulls between the massive rows >= 1, found
    once, not per step; ``order`` and ``gm_c`` go with them: see
    :func:`_effects_kick_dh`).  Inlined into each entry (an entry calling one shared
    body would have numba optimise that body's machine code twice)."""
    n = gm.shape[0]
    m = n if has_extra else 0  # the effects' work arrays (n, 3), or none
    r_in = np.empty((m, 3))
    v_in = np.empty((m, 3))
    acc_x = np.empty((m, 3))
    w = n if watched else 0
    x0, v0 = np.empty((w, 3)), np.empty((w, 3))
    m_tot = 0.0
    for i in range(n):
        m_tot += gm[i]
    idx = _nbody.massive_indices(gm)
    if idx.shape[0] > 0 and idx[0] == 0:  # (row 0, unused here, is left out)
        idx = idx[1:]
    acc_m = np.empty((idx.shape[0], 3))
    mu = np.empty(1)  # every body about the central one
    mu[0] = gm[0]
    mu_s = np.empty(w)
    if watched:
        mu_s[:] = gm[0]
        mu_s[0] = 0.0
    return x0, v0, mu, mu_s, (idx, m_tot, acc_m, r_in, v_in, acc_x, order, gm_c)


@entry(_RESULT(*_SPLIT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_dh(
    extra_addr, p, has_extra, order, q, u, gm, com, dt, n_steps, dt_last, ws,
):  # pragma: no cover - compiled
    """``n_steps`` steps (the last of length ``dt_last``) from and to synchronised
    coordinates, in place, watching no events.  ``q``, ``u``: heliocentric
    positions and barycentric velocities (row 0 unused); ``gm[0]`` the central
    body's; ``com``: barycentre position and velocity (6,); ``order``: row ``i``
    is the caller's body ``order[i]`` (the listed effects see the caller's order:
    their parameters name bodies by its indices); ``ws``: see :func:`_drift`
    (``ws[0]`` the start time).  Returns ``(steps, bad, status)`` with ``bad`` the
    index of a body whose Kepler step failed, else -1.  The loop without effects
    has no trace of them (their branches cost up to 30% of a step at N = 2-3)."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, mu, _, kick = _dh_setup(gm, False, False, order, gm)
    return _dh_unwatched_steps(None, extra, p, q, u, gm, com, dt, n_steps, dt_last, ws, mu,
                               kick, None)


@entry(_RESULT(*_SPLIT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_dh_effects(
    extra_addr, p, has_extra, order, q, u, gm, com, dt, n_steps, dt_last, ws,
):  # pragma: no cover - compiled
    """:func:`advance_dh` with the listed effects (``has_extra`` True)."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, mu, _, kick = _dh_setup(gm, False, True, order, caller_gm(gm, order))
    return _dh_unwatched_steps(_effects_kick_dh, extra, p, q, u, gm, com, dt, n_steps, dt_last,
                               ws, mu, kick, None)


@entry(_RESULT(*_SPLIT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_dh_few(
    extra_addr, p, has_extra, order, q, u, gm, com, dt, n_steps, dt_last, ws,
):  # pragma: no cover - compiled
    """:func:`advance_dh` for fewer than :data:`LANES_FROM` bodies, all massive (no
    effect, no event): the same bits, without compiling the lanes of the Kepler
    solver or the spaced kick (a first run of a few bodies compiles less)."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, mu, _, kick = _dh_setup(gm, False, False, order, gm)
    return _dh_unwatched_steps(None, extra, p, q, u, gm, com, dt, n_steps, dt_last, ws, mu,
                               kick, True)


@entry(_RESULT(*_SPLIT_ARGS, *_EVENT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_dh_watched(
    extra_addr, p, has_extra, order, q, u, gm, com, dt, n_steps, dt_last, watch, ev_out, ev_count,
    ws,
):  # pragma: no cover - compiled
    """:func:`advance_dh` watching the events ``watch``, recorded into ``ev_out`` /
    ``ev_count`` (see :func:`_drift`); at ``STATUS_EVENT`` or ``STATUS_DRAIN`` the
    state is synchronised at the end of step ``steps``."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    x0, v0, mu, mu_s, kick = _dh_setup(gm, True, has_extra, order, caller_gm(gm, order))
    return _dh_steps(watch.shape[0] > 0, extra, p, has_extra, q, u, gm, com, dt, n_steps,
                     dt_last, watch, ev_out, ev_count, ws, x0, v0, mu, mu_s, kick)


@njit(cache=True, inline="always", error_model="numpy")
def _jacobi_setup(has_extra, order, gm, eta):  # pragma: no cover - compiled
    """The kick's arrays of a run in Jacobi coordinates and the drifts' start
    states for the events' scan, as :func:`_dh_setup`."""
    n = gm.shape[0]
    acc = np.empty((n, 3))
    accj = np.empty((n, 3))
    acc_x = np.empty((n, 3))
    r_in = np.empty((n, 3))
    v_in = np.zeros((n, 3))
    x0, v0 = np.empty((n, 3)), np.empty((n, 3))
    idx = _nbody.massive_indices(gm)
    ratio, inv = jacobi_factors(eta)
    return x0, v0, (idx, ratio, inv, acc, accj, acc_x, r_in, v_in,
                    _perm(has_extra, order, gm))


@entry(_RESULT(*_SPLIT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_jacobi(
    extra_addr, p, has_extra, order, qj, uj, gm, eta, dt, n_steps, dt_last, ws,
):  # pragma: no cover - compiled
    """As :func:`advance_dh` in Jacobi coordinates (Wisdom & Holman 1991): ``qj``,
    ``uj`` Jacobi positions and velocities, row 0 the barycentre; ``eta_i =
    sum_{j<=i} G m_j``.  Kick: the inertial accelerations (all pairs, and the
    listed effects) in Jacobi form plus ``G eta_i qj_i / |qj_i|^3``, which
    removes the part the Kepler step already accounts for."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, kick = _jacobi_setup(has_extra, order, gm, eta)
    return _jacobi_unwatched_steps(None, extra, p, qj, uj, gm, eta, dt, n_steps, dt_last, ws,
                                   kick, None)


@entry(_RESULT(*_SPLIT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_jacobi_effects(
    extra_addr, p, has_extra, order, qj, uj, gm, eta, dt, n_steps, dt_last, ws,
):  # pragma: no cover - compiled
    """:func:`advance_jacobi` with the listed effects (``has_extra`` True)."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, kick = _jacobi_setup(has_extra, order, gm, eta)
    return _jacobi_unwatched_steps(_effects_jacobi, extra, p, qj, uj, gm, eta, dt, n_steps,
                                   dt_last, ws, kick, None)


@entry(_RESULT(*_SPLIT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_jacobi_few(
    extra_addr, p, has_extra, order, qj, uj, gm, eta, dt, n_steps, dt_last, ws,
):  # pragma: no cover - compiled
    """:func:`advance_jacobi` for fewer than :data:`LANES_FROM` bodies, all massive,
    as :func:`advance_dh_few`."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, kick = _jacobi_setup(has_extra, order, gm, eta)
    return _jacobi_unwatched_steps(None, extra, p, qj, uj, gm, eta, dt, n_steps, dt_last, ws,
                                   kick, True)


@entry(_RESULT(*_SPLIT_ARGS, *_EVENT_ARGS, F1), cache=True, nogil=True, error_model="numpy")
def advance_jacobi_watched(
    extra_addr, p, has_extra, order, qj, uj, gm, eta, dt, n_steps, dt_last, watch, ev_out,
    ev_count, ws,
):  # pragma: no cover - compiled
    """:func:`advance_jacobi` watching the events ``watch`` (see
    :func:`advance_dh_watched`)."""
    extra = accel_at(extra_addr[0], extra_addr[1])
    x0, v0, kick = _jacobi_setup(has_extra, order, gm, eta)
    return _jacobi_steps(watch.shape[0] > 0, extra, p, has_extra, qj, uj, gm, eta, dt,
                         n_steps, dt_last, watch, ev_out, ev_count, ws, x0, v0, kick)
