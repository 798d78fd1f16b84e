"""Events between steps: close approaches, contacts and escapes on the step's interpolant.

:func:`scan` looks at one step (or one drift) from ``h = 0`` to ``h = 1`` of length
``dt`` and, for every row of the watch table (see :mod:`hamilton_orbits.events`),
finds what happened *inside* it, not only at its ends, on the integrator's own
interpolant of the motion:

- ``RADAU``: radau15's polynomial of the step (Rein & Spiegel 2015, eqs. 6, 7);
- ``LINE``: straight lines at constant velocity (a leapfrog drift);
- ``KEPLER``: every body on its Kepler arc about the origin with its own ``mu``
  (the central body at rest at the origin);
- ``DH``: a Wisdom-Holman drift in democratic-heliocentric coordinates (see
  :func:`_dh_constants`): heliocentric positions on their Kepler arcs about the
  central body, moved together by the "jump" ``sum m_k u_k / m_0`` that the
  drift leaves to the steps' ends, so that relative positions and velocities
  are the inertial ones (with barycentric velocities ``u`` alone, a body's
  velocity relative to the central body would lack ``sum m_k u_k / m_0``: a
  third of it when ``m_1 = m_0 / 2``), and the centre of mass where the masses
  put it;
- ``HERMITE``: the cubic Hermite interpolant of the positions and velocities at
  both ends (the generic case);
- ``JACOBI``: Jacobi coordinates on their Kepler arcs about ``mu = eta`` (the
  partial sums of ``G m``; row 0 the barycentre in uniform motion), turned into
  inertial positions (a Wisdom-Holman drift in Jacobi coordinates).

A closest approach is a root of ``f(h) = d . w`` (``d``, ``w`` the relative
position and velocity) where ``f`` goes from negative to non-negative; a contact a
root of ``|d|^2 - R^2`` before the closest approach; an escape a root of
``|x - x_cm|^2 - D^2`` going up.  Each root is bracketed and bisected to the last
bit of ``h``: the time to rounding of ``t + h dt``, the distance at the minimum of
a quadratic to rounding.
"""

from __future__ import annotations

import math
import types

import numpy as np
from numba import njit

from hamilton_orbits._kernels import kepler as _kepler

__all__ = ["DH", "HERMITE", "JACOBI", "KEPLER", "LINE", "RADAU", "scan", "scan_line",
           "scan_radau", "scan_steps", "state_at", "state_at_hermite", "state_at_radau"]

RADAU = 0
LINE = 1
KEPLER = 2
HERMITE = 3
JACOBI = 4
DH = 5

#: The interpolant these functions are compiled for: -1 (here) any, read from their
#: ``kind`` argument at run time; in the copies of :func:`_for_kind`, that one alone
#: (every ``kind ==`` test then a constant, and numba prunes the other kinds' branches
#: before it compiles them).
_KIND = -1

_CODE_ENCOUNTER = 1
_CODE_COLLISION = 2
_CODE_ESCAPE = 3


@njit(cache=True, error_model="numpy")
def _state(kind, k, h, dt, x0, v0, x1, v1, a0, b, mu, out):  # pragma: no cover - compiled
    """Position and velocity of body ``k`` at ``h`` into ``out`` (6,) (not ``DH``:
    :func:`_dh_state`)."""
    kind = _KIND if _KIND >= 0 else kind  # (a constant in :func:`_for_kind`'s copies)
    if kind == DH:
        raise ValueError("events: the DH interpolant needs the drift's constants (_dh_state)")
    if kind == JACOBI:
        _jacobi_state(k, h * dt, x0, v0, mu, out)
        return
    if kind == KEPLER:
        if mu[k] == 0.0:  # the central body: at rest at its place in these coordinates
            for c in range(3):
                out[c] = x0[k, c]
                out[3 + c] = 0.0
            return
        x, y, z, vx, vy, vz = _kepler.propagate_uv(x0[k, 0], x0[k, 1], x0[k, 2], v0[k, 0],
                                                   v0[k, 1], v0[k, 2], mu[k], h * dt)
        out[0], out[1], out[2], out[3], out[4], out[5] = x, y, z, vx, vy, vz
        return
    for c in range(3):
        m = 3 * k + c
        if kind == RADAU:
            pos = b[4, m] / 42.0 + h * (b[5, m] / 56.0 + h * b[6, m] / 72.0)
            pos = b[1, m] / 12.0 + h * (b[2, m] / 20.0 + h * (b[3, m] / 30.0 + h * pos))
            pos = a0[m] / 2.0 + h * (b[0, m] / 6.0 + h * pos)
            vel = b[4, m] / 6.0 + h * (b[5, m] / 7.0 + h * b[6, m] / 8.0)
            vel = b[1, m] / 3.0 + h * (b[2, m] / 4.0 + h * (b[3, m] / 5.0 + h * vel))
            vel = a0[m] + h * (b[0, m] / 2.0 + h * vel)
            out[c] = x0[k, c] + h * dt * (v0[k, c] + h * dt * pos)
            out[3 + c] = v0[k, c] + h * dt * vel
        elif kind == LINE:
            out[c] = x0[k, c] + h * dt * v0[k, c]
            out[3 + c] = v0[k, c]
        else:  # HERMITE
            h2 = h * h
            h3 = h2 * h
            out[c] = ((2.0 * h3 - 3.0 * h2 + 1.0) * x0[k, c] + (h3 - 2.0 * h2 + h) * dt * v0[k, c]
                      + (3.0 * h2 - 2.0 * h3) * x1[k, c] + (h3 - h2) * dt * v1[k, c])
            out[3 + c] = ((6.0 * h2 - 6.0 * h) * (x0[k, c] - x1[k, c]) / dt
                          + (3.0 * h2 - 4.0 * h + 1.0) * v0[k, c] + (3.0 * h2 - 2.0 * h) * v1[k, c])


@njit(cache=True, error_model="numpy")
def _jacobi_state(k, tau, qj, uj, eta, out):  # pragma: no cover - compiled
    """Inertial position and velocity of body ``k`` after every Jacobi coordinate has
    moved ``tau`` on its Kepler arc (see :func:`_jacobi_all`)."""
    n = qj.shape[0]
    r = np.empty((n, 3))
    v = np.empty((n, 3))
    _jacobi_all(tau, qj, uj, eta, r, v)
    for c in range(3):
        out[c] = r[k, c]
        out[3 + c] = v[k, c]


@njit(cache=True, error_model="numpy")
def _jacobi_all(tau, qj, uj, eta, r, v):  # pragma: no cover - compiled
    """Every body's inertial position and velocity after each Jacobi coordinate has
    moved ``tau`` on its Kepler arc about ``eta`` (row 0, the barycentre, moving
    uniformly): ``r_k = qj_k + S_(k-1) / eta_(k-1)`` with the partial centres of
    mass ``S`` unwound from the total down (Wisdom & Holman 1991)."""
    n = qj.shape[0]
    q = np.empty((n, 3))
    u = np.empty((n, 3))
    for c in range(3):
        q[0, c] = qj[0, c] + tau * uj[0, c]
        u[0, c] = uj[0, c]
    for m in range(1, n):
        if tau == 0.0:
            for c in range(3):
                q[m, c] = qj[m, c]
                u[m, c] = uj[m, c]
            continue
        x, y, z, vx, vy, vz = _kepler.propagate_uv(qj[m, 0], qj[m, 1], qj[m, 2], uj[m, 0],
                                                   uj[m, 1], uj[m, 2], eta[m], tau)
        q[m, 0], q[m, 1], q[m, 2], u[m, 0], u[m, 1], u[m, 2] = x, y, z, vx, vy, vz
    for c in range(3):
        sx = eta[n - 1] * q[0, c]  # the total centre of mass times the total mass
        sv = eta[n - 1] * u[0, c]
        for m in range(n - 1, 0, -1):
            ratio = eta[m - 1] / eta[m]
            g = eta[m] - eta[m - 1]
            sx = (sx - g * q[m, c]) * ratio
            sv = (sv - g * u[m, c]) * ratio
            r[m, c] = q[m, c] + sx / eta[m - 1]
            v[m, c] = u[m, c] + sv / eta[m - 1]
        r[0, c] = sx / eta[0]
        v[0, c] = sv / eta[0]


@njit(cache=True, error_model="numpy")
def _dh_sums(h, dt, x0, v0, x1, v1, g, mu, out):  # pragma: no cover - compiled
    """``sum g_k (x_k(h) - x_k(0))`` into ``out[0:3]`` and ``sum g_k u_k(h)`` into
    ``out[3:6]`` over the massive rows ``k >= 1`` on their Kepler arcs (the ends
    themselves at ``h = 0`` and ``1``)."""
    for c in range(6):
        out[c] = 0.0
    for k in range(1, x0.shape[0]):
        if g[k] == 0.0 or mu[k] == 0.0:
            continue
        if h == 0.0 or h == 1.0:
            xe, ve = (x0, v0) if h == 0.0 else (x1, v1)
            x, y, z, vx, vy, vz = xe[k, 0], xe[k, 1], xe[k, 2], ve[k, 0], ve[k, 1], ve[k, 2]
        else:
            x, y, z, vx, vy, vz = _kepler.propagate_uv(x0[k, 0], x0[k, 1], x0[k, 2], v0[k, 0],
                                                       v0[k, 1], v0[k, 2], mu[k], h * dt)
        out[0] += g[k] * (x - x0[k, 0])
        out[1] += g[k] * (y - x0[k, 1])
        out[2] += g[k] * (z - x0[k, 2])
        out[3] += g[k] * vx
        out[4] += g[k] * vy
        out[5] += g[k] * vz


@njit(cache=True, error_model="numpy")
def _dh_constants(x0, v0, x1, v1, g, mu, a, dt):  # pragma: no cover - compiled
    """The constants of a democratic-heliocentric drift's interpolant:
    ``[m_0, M, a, dt, P_s (3), c (3), S_0 (3)]``.

    The map is ``... kick, jump a, drift dt, jump b, kick ...`` (``a`` the jump
    before the drift: 0 after a synchronised state, else half the step before;
    ``b = dt - a`` the one after it), and a jump moves every heliocentric position
    ``Q_k`` by its time times ``P / m_0``, ``P = sum_k m_k u_k``.  The interpolant
    moves all ``Q_k`` together by ``(-a P_s + sum_k m_k (x_k(h) - x_k(0)) + h c) /
    m_0`` besides their Kepler arcs ``x_k``: it starts where the kick before saw
    the bodies (``-a P_s / m_0``), ends where the kick after sees them (``b P_e /
    m_0``: ``c`` closes the gap, ``O(dt^2)``), and its rate is ``(P(h) + c / dt) /
    m_0``, the central body's velocity relative to the barycentre to ``O(dt^2)``.
    ``S_0 = sum_k m_k x_k(0)`` places the centre of mass."""
    out = np.zeros(13)
    m0 = g[0]
    total = 0.0
    for k in range(g.shape[0]):
        total += g[k]
    s = np.empty(6)
    _dh_sums(1.0, dt, x0, v0, x1, v1, g, mu, s)
    out[0], out[1], out[2], out[3] = m0, total, a, dt
    for k in range(1, g.shape[0]):
        if g[k] == 0.0 or mu[k] == 0.0:
            continue
        for c in range(3):
            out[4 + c] += g[k] * v0[k, c]
            out[10 + c] += g[k] * x0[k, c]
    for c in range(3):
        out[7 + c] = (dt - a) * s[3 + c] - (s[c] - a * out[4 + c])
    return out


@njit(cache=True, error_model="numpy")
def _dh_frame(h, dt, x0, v0, x1, v1, g, mu, fc, fr):  # pragma: no cover - compiled
    """At ``h``: the common offset of the heliocentric positions and its rate
    (``fr[0:6]``) and the centre of mass's position and velocity relative to the
    central body (``fr[6:12]``); ``fc`` from :func:`_dh_constants`."""
    s = np.empty(6)
    _dh_sums(h, dt, x0, v0, x1, v1, g, mu, s)
    m0, total, a, tau = fc[0], fc[1], fc[2], fc[3]
    for c in range(3):
        off = (s[c] - a * fc[4 + c] + h * fc[7 + c]) / m0
        rate = (s[3 + c] + fc[7 + c] / tau) / m0
        fr[c] = off
        fr[3 + c] = rate
        fr[6 + c] = (fc[10 + c] + s[c] + (total - m0) * off) / total
        fr[9 + c] = (s[3 + c] + (total - m0) * rate) / total


@njit(cache=True, error_model="numpy")
def _dh_state(k, h, dt, x0, v0, mu, fr, out):  # pragma: no cover - compiled
    """Body ``k``'s position and velocity relative to the central body at ``h`` (the
    central body itself at rest at the origin); ``fr`` from :func:`_dh_frame`."""
    if mu[k] == 0.0:
        for c in range(6):
            out[c] = 0.0
        return
    x, y, z, vx, vy, vz = _kepler.propagate_uv(x0[k, 0], x0[k, 1], x0[k, 2], v0[k, 0],
                                               v0[k, 1], v0[k, 2], mu[k], h * dt)
    out[0], out[1], out[2] = x + fr[0], y + fr[1], z + fr[2]
    out[3], out[4], out[5] = vx + fr[3], vy + fr[4], vz + fr[5]


@njit(cache=True, error_model="numpy")
def _relative(kind, i, j, h, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj):
    # pragma: no cover - compiled
    """``(|d|^2, d . w, |w|)`` of body ``i`` relative to body ``j`` (``j < 0``: the
    centre of mass, ``cm = [x_cm(0), v_cm, x_cm(1) ...]`` moving uniformly; for
    ``DH``, ``a0`` the rows' ``G m`` and ``cm`` from :func:`_dh_constants`)."""
    kind = _KIND if _KIND >= 0 else kind  # (a constant in :func:`_for_kind`'s copies)
    if kind == DH and (j < 0 or mu[i] == 0.0 or mu[j] == 0.0):
        fr = np.empty(12)
        _dh_frame(h, dt, x0, v0, x1, v1, a0, mu, cm, fr)
        _dh_state(i, h, dt, x0, v0, mu, fr, si)
        if j >= 0:
            _dh_state(j, h, dt, x0, v0, mu, fr, sj)
        else:
            for c in range(6):
                sj[c] = fr[6 + c]
    elif kind == DH:  # neither is the central body: the common offset cancels
        _state(KEPLER, i, h, dt, x0, v0, x1, v1, a0, b, mu, si)
        _state(KEPLER, j, h, dt, x0, v0, x1, v1, a0, b, mu, sj)
    else:
        _state(kind, i, h, dt, x0, v0, x1, v1, a0, b, mu, si)
        if j >= 0:
            _state(kind, j, h, dt, x0, v0, x1, v1, a0, b, mu, sj)
        else:
            for c in range(3):
                sj[c] = cm[c] + h * (cm[6 + c] - cm[c])
                sj[3 + c] = cm[3 + c]
    d2 = 0.0
    f = 0.0
    w2 = 0.0
    for c in range(3):
        d = si[c] - sj[c]
        w = si[3 + c] - sj[3 + c]
        d2 += d * d
        f += d * w
        w2 += w * w
    return d2, f, math.sqrt(w2)


@njit(cache=True, error_model="numpy")
def _ends(kind, x0, v0, x1, v1, mu, a0, cm, ce):  # pragma: no cover - compiled
    """The positions and velocities at both ends of the step in the frame the
    events are watched in (computed once per step: O(n), not O(n) per pair), and
    into ``ce`` (12,) the centre of mass's position and velocity at both ends."""
    kind = _KIND if _KIND >= 0 else kind  # (a constant in :func:`_for_kind`'s copies)
    for c in range(3):  # uniform motion (every kind but DH)
        ce[c], ce[3 + c], ce[6 + c], ce[9 + c] = cm[c], cm[3 + c], cm[6 + c], cm[3 + c]
    if kind == DH:  # relative to the central body, the common offset added
        p0, w0, p1, w1 = x0.copy(), v0.copy(), x1.copy(), v1.copy()
        fr = np.empty(12)
        for end in range(2):
            _dh_frame(float(end), cm[3], x0, v0, x1, v1, a0, mu, cm, fr)
            p, w = (p0, w0) if end == 0 else (p1, w1)
            for k in range(mu.shape[0]):
                for c in range(3):
                    p[k, c] = 0.0 if mu[k] == 0.0 else p[k, c] + fr[c]
                    w[k, c] = 0.0 if mu[k] == 0.0 else w[k, c] + fr[3 + c]
            for c in range(6):
                ce[6 * end + c] = fr[6 + c]
        return p0, w0, p1, w1
    if kind == JACOBI:
        n = x0.shape[0]
        p0, w0, p1, w1 = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
        _jacobi_all(0.0, x0, v0, mu, p0, w0)
        _jacobi_all(0.0, x1, v1, mu, p1, w1)
        return p0, w0, p1, w1
    if kind == KEPLER:  # the central body (mu = 0) rests in heliocentric coordinates
        p0, w0, p1, w1 = x0.copy(), v0.copy(), x1.copy(), v1.copy()
        for k in range(mu.shape[0]):
            if mu[k] == 0.0:
                w0[k, :] = 0.0
                w1[k, :] = 0.0
        return p0, w0, p1, w1
    return x0, v0, x1, v1


@njit(cache=True, error_model="numpy")
def _deviation_bound(kind, p0, w0, p1, w1, mu, dt, a0, b):  # pragma: no cover - compiled
    """Per body, how far its path can leave the straight line of its start velocity
    within the step (``a dt^2 / 2`` with ``a`` a bound on its acceleration): for
    radau15's polynomial, ``|a0| + sum |b_k|``; for the Kepler arcs,
    ``mu / r_min^2`` with ``r_min`` the smallest distance from the centre over the
    step (the periapsis where it is passed), doubled for Jacobi coordinates, for
    ``DH`` (given the arcs themselves) with the common offset's own,
    ``sum m_k bound_k / m_0`` (``a0`` the rows' ``G m``), added; infinite (no
    filter) for the other interpolants."""
    kind = _KIND if _KIND >= 0 else kind  # (a constant in :func:`_for_kind`'s copies)
    n = p0.shape[0]
    out = np.full(n, np.inf)
    if kind == RADAU:  # |a(h)| <= |a0| + sum |b_k| on [0, 1], per component
        for k in range(n):
            a2 = 0.0
            for c in range(3):
                m = 3 * k + c
                amax = abs(a0[m])
                for q in range(7):
                    amax += abs(b[q, m])
                a2 += amax * amax
            out[k] = 0.5 * math.sqrt(a2) * dt * dt
        return out
    if kind != KEPLER and kind != JACOBI and kind != DH:
        return out
    for k in range(n):
        if mu[k] == 0.0:
            out[k] = 0.0
            continue
        r0 = math.sqrt(p0[k, 0] ** 2 + p0[k, 1] ** 2 + p0[k, 2] ** 2)
        r1 = math.sqrt(p1[k, 0] ** 2 + p1[k, 1] ** 2 + p1[k, 2] ** 2)
        r_min = min(r0, r1)
        s0 = p0[k, 0] * w0[k, 0] + p0[k, 1] * w0[k, 1] + p0[k, 2] * w0[k, 2]
        s1 = p1[k, 0] * w1[k, 0] + p1[k, 1] * w1[k, 1] + p1[k, 2] * w1[k, 2]
        if s0 < 0.0 <= s1:  # the periapsis is passed: q = h^2 / (mu (1 + e))
            w2 = w0[k, 0] ** 2 + w0[k, 1] ** 2 + w0[k, 2] ** 2
            h2 = r0 * r0 * w2 - s0 * s0
            e = math.sqrt(max(1.0 + (w2 - 2.0 * mu[k] / r0) * h2 / (mu[k] * mu[k]), 0.0))
            r_min = min(r_min, max(h2, 0.0) / (mu[k] * (1.0 + e)))
        scale = 2.0 if kind == JACOBI else 1.0
        out[k] = scale * 0.5 * mu[k] / (r_min * r_min) * dt * dt
    if kind == DH:  # the common offset's deviation: sum m_k bound_k / m_0
        shift = 0.0
        for k in range(1, n):
            if mu[k] != 0.0:
                shift += a0[k] * out[k] / a0[0]
        for k in range(n):
            if mu[k] != 0.0:
                out[k] += shift
    return out


@njit(cache=True, inline="always", error_model="numpy")
def _too_far(i, j, p0, w0, dt, d2a, fa, thr2, bound):  # pragma: no cover - compiled
    """True if the pair cannot come within ``sqrt(thr2)`` in the step: the straight
    relative path from the start stays farther than that by more than both bodies'
    possible deviations from it (:func:`_deviation_bound`)."""
    dev = bound[i] + (bound[j] if j >= 0 else 0.0)
    if not dev < math.inf:
        return False
    w2 = 0.0
    for c in range(3):
        dw = w0[i, c] - (w0[j, c] if j >= 0 else 0.0)
        w2 += dw * dw
    tau = -fa / w2 if w2 > 0.0 else 0.0  # the straight path's closest time (> 0: f < 0)
    tau = min(tau, dt)
    d2_line = max(d2a + 2.0 * fa * tau + w2 * tau * tau, 0.0)
    reach = math.sqrt(thr2) + dev
    return d2_line > reach * reach


@njit(cache=True, inline="always", error_model="numpy")
def _at_end(i, j, p, w, ce, at):  # pragma: no cover - compiled
    """``(|d|^2, d . w)`` at an end of the step, from its states (``at``: 0 at the
    start, 6 at the end, the centre of mass's slot in ``ce``, see :func:`_ends`)."""
    d2 = 0.0
    f = 0.0
    for c in range(3):
        if j >= 0:
            d = p[i, c] - p[j, c]
            dw = w[i, c] - w[j, c]
        else:
            d = p[i, c] - ce[at + c]
            dw = w[i, c] - ce[at + 3 + c]
        d2 += d * d
        f += d * dw
    return d2, f


@njit(cache=True, error_model="numpy")
def _bisect(kind, i, j, lo, hi, target2, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj):
    # pragma: no cover - compiled
    """The root in ``[lo, hi]`` of ``f`` (``target2 < 0``: ``d . w``, negative at ``lo``)
    or of ``|d|^2 - target2`` (``target2 >= 0``), bracketed: Illinois steps (regula
    falsi that halves a stale end's value), a bisection whenever the bracket did not
    halve, until it is two adjacent floats (a few to a dozen evaluations instead of
    fifty for bisection alone).  (Which root, from the sign of ``target2`` rather
    than from a flag: a constant flag made numba compile one copy of this function
    for each value, 0.4-0.9 s more of a first run.)"""
    g_lo = _g(kind, i, j, lo, target2, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj)
    g_hi = _g(kind, i, j, hi, target2, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj)
    if g_hi == 0.0:
        return hi
    side = 0
    width = hi - lo
    for it in range(300):
        if it % 2 == 1 and hi - lo > 0.5 * width:  # the bracket stalled: bisect
            x = 0.5 * (lo + hi)
        else:
            x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo)
        width = hi - lo
        if not (lo < x < hi):
            x = 0.5 * (lo + hi)
            if not (lo < x < hi):
                break
        g = _g(kind, i, j, x, target2, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj)
        if g == 0.0:
            return x
        if (g < 0.0) == (g_lo < 0.0):
            lo, g_lo = x, g
            if side == -1:
                g_hi *= 0.5
            side = -1
        else:
            hi, g_hi = x, g
            if side == 1:
                g_lo *= 0.5
            side = 1
    return hi


@njit(cache=True, inline="always", error_model="numpy")
def _g(kind, i, j, h, target2, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj):
    # pragma: no cover - compiled
    d2, f, _ = _relative(kind, i, j, h, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj)
    return f if target2 < 0.0 else d2 - target2


@njit(cache=True, error_model="numpy")
def _record(out, count, code, i, j, t, dist, speed, action):  # pragma: no cover - compiled
    """Append one event row; False when the buffer is full (the caller drains it)."""
    k = count[0]
    if k >= out.shape[0]:
        return False
    out[k, 0], out[k, 1], out[k, 2], out[k, 3] = code, i, j, t
    out[k, 4], out[k, 5], out[k, 6] = dist, speed, action
    count[0] = k + 1
    return True


@njit(cache=True, error_model="numpy")
def scan(watch, kind, t0, dt, x0, v0, x1, v1, a0, b, mu, cm, out, count):
    # pragma: no cover - compiled
    """Look for events in one step; returns ``(h, row)``: the earliest ``h`` at which
    an event with an action (stop, merge, remove) occurred and its watch row, or
    ``(2.0, -1)`` if none did.  ``(-1.0, -1)``: the buffer filled up (drain it and
    scan the step again).

    ``watch`` (m, 5): code, i, j, threshold, action.  ``x0, v0, x1, v1`` (n, 3): the
    states at both ends; ``a0`` (3n,), ``b`` (7, 3n): radau15's polynomial;
    ``mu`` (n,): the Kepler arcs' ``mu``; ``cm`` (9,): the centre of mass at both
    ends and its velocity.  ``DH``: ``x``, ``v`` heliocentric positions and
    barycentric velocities (row 0 the central body, ``mu[0] = 0``), ``a0`` (n,) the
    rows' ``G m``, ``cm[0]`` the jump before the drift (see :func:`_dh_constants`).
    """
    if _KIND >= 0 and kind != _KIND:
        raise ValueError("events: scan called for another interpolant than its copy's")
    kind = _KIND if _KIND >= 0 else kind  # (a constant in :func:`_for_kind`'s copies)
    si = np.empty(6)
    sj = np.empty(6)
    ce = np.empty(12)
    if kind == DH:  # the drift's constants take the place of the centre of mass
        cm = _dh_constants(x0, v0, x1, v1, a0, mu, cm[0], dt)
    p0, w0, p1, w1 = _ends(kind, x0, v0, x1, v1, mu, a0, cm, ce)
    if kind == DH:
        bound = _deviation_bound(kind, x0, v0, x1, v1, mu, dt, a0, b)
    else:
        bound = _deviation_bound(kind, p0, w0, p1, w1, mu, dt, a0, b)
    first_h = 2.0
    first_row = -1
    for r in range(watch.shape[0]):
        code = int(watch[r, 0])
        i = int(watch[r, 1])
        j = int(watch[r, 2])
        thr2 = watch[r, 3] * watch[r, 3]
        action = watch[r, 4]
        d2a, fa = _at_end(i, j, p0, w0, ce, 0)
        d2b, fb = _at_end(i, j, p1, w1, ce, 6)
        h = -1.0
        if code == _CODE_ESCAPE:
            if d2a < thr2 <= d2b:
                h = _bisect(kind, i, j, 0.0, 1.0, thr2, dt, x0, v0, x1, v1, a0, b, mu, cm,
                            si, sj)
        else:
            h_min = 1.0
            if not fa < 0.0:
                continue  # receding at the start: a minimum inside needs f < 0 first
            if _too_far(i, j, p0, w0, dt, d2a, fa, thr2, bound):
                continue  # cannot come within the distance in this step
            if 0.0 <= fb:
                h_min = _bisect(kind, i, j, 0.0, 1.0, -1.0, dt, x0, v0, x1, v1, a0, b, mu,
                                cm, si, sj)
            d2m = d2b  # approaching all through the step: the end is the closest
            if h_min < 1.0:
                d2m, _, _ = _relative(kind, i, j, h_min, dt, x0, v0, x1, v1, a0, b, mu, cm, si,
                                      sj)
            if code == _CODE_ENCOUNTER:
                if fa < 0.0 <= fb and d2m < thr2:
                    h = h_min
            elif d2a > thr2 >= d2m:
                h = _bisect(kind, i, j, 0.0, h_min, thr2, dt, x0, v0, x1, v1, a0, b, mu, cm,
                            si, sj)
        if h < 0.0:
            continue
        d2h, _, speed = _relative(kind, i, j, h, dt, x0, v0, x1, v1, a0, b, mu, cm, si, sj)
        if not _record(out, count, code, i, j, t0 + h * dt, math.sqrt(d2h), speed, action):
            return -1.0, -1
        if action != 0.0 and h < first_h:
            first_h = h
            first_row = r
    return first_h, first_row


@njit(cache=True, error_model="numpy")
def state_at(kind, h, dt, x0, v0, x1, v1, a0, b, mu, r, v):  # pragma: no cover - compiled
    """Every body's position and velocity at ``h`` into ``r``, ``v`` (n, 3) (any kind
    but ``DH``)."""
    if _KIND >= 0 and kind != _KIND:
        raise ValueError("events: state_at called for another interpolant than its copy's")
    s = np.empty(6)
    for k in range(r.shape[0]):
        _state(kind, k, h, dt, x0, v0, x1, v1, a0, b, mu, s)
        for c in range(3):
            r[k, c] = s[c]
            v[k, c] = s[3 + c]


@njit(cache=True, error_model="numpy")
def scan_steps(watch, ts, xs, vs, gm, out, count):  # pragma: no cover - compiled
    """:func:`scan` with the ``HERMITE`` interpolant over consecutive step states
    ``xs``, ``vs`` (k+1, n, 3) at times ``ts`` (k+1,).  Returns ``(step, h, row)`` of
    the first event with an action (``step = -1``: none); ``step = -2``: the
    buffer filled up at ``ts[h]`` (drain it and scan again from there)."""
    n = xs.shape[1]
    no_a0 = np.zeros(1)
    no_b = np.zeros((7, 1))
    cm = np.zeros(9)
    total = 0.0
    for k in range(n):
        total += gm[k]
    for s in range(ts.shape[0] - 1):
        if count[0] + watch.shape[0] > out.shape[0]:
            return -2, float(s), -1
        cm[:] = 0.0
        for k in range(n if total > 0.0 else 0):  # (massless rows alone: no centre of mass)
            for c in range(3):
                cm[c] += gm[k] * xs[s, k, c] / total
                cm[3 + c] += gm[k] * vs[s, k, c] / total
                cm[6 + c] += gm[k] * xs[s + 1, k, c] / total
        h, row = _scan_hermite(watch, HERMITE, ts[s], ts[s + 1] - ts[s], xs[s], vs[s], xs[s + 1],
                      vs[s + 1], no_a0, no_b, gm, cm, out, count)
        if row >= 0:
            return s, h, row
    return -1, 2.0, -1


#: the functions whose code depends on the interpolant, directly or through a call
_BY_KIND = ("_state", "_relative", "_ends", "_deviation_bound", "_bisect", "_g", "scan",
            "state_at")


def _for_kind(kind: int, suffix: str) -> dict:
    """Copies of :data:`_BY_KIND` compiled for the interpolant ``kind`` alone, by name
    (each ``name + "_" + suffix``, its own cache files).  They share one table of
    globals in which ``_KIND`` is ``kind`` and each name is its copy, so that they
    call one another; the arithmetic is the same code (the same bits).

    Why: compiled with ``kind`` a run-time number, :func:`scan` compiles every
    interpolant's code (the Kepler solver, the Jacobi and democratic-heliocentric
    frames) for every caller: on a cold cache (CPU seconds, medians of 2 runs)
    radau15's ``advance_watched`` compiled in 19.6 s, 9.5 s with its ``RADAU`` copy;
    ``scan_steps`` (dop853) in 10.8 s, 3.2 s with its ``HERMITE`` copy; leapfrog's
    watched steps with its ``LINE`` copy in 8.2 s instead of 19.4 s.  wh keeps the
    generic :func:`scan` (its kernels call it for both ``JACOBI`` and ``DH``): copies
    of their own, tried 2026-12-01, cut a first watched wh run (democratic-
    heliocentric) from 23.4 to 20.0 s but cost a Jacobi run after it 4 s more."""
    table = dict(globals())
    table["_KIND"] = kind
    copies = {}
    for name in _BY_KIND:
        dispatcher = globals()[name]
        func = dispatcher.py_func
        copy = types.FunctionType(func.__code__, table, f"{func.__name__}_{suffix}",
                                  func.__defaults__, func.__closure__)
        copy.__qualname__ = f"{func.__qualname__}_{suffix}"
        copy.__doc__ = func.__doc__
        copy.__kwdefaults__ = func.__kwdefaults__
        options = {k: v for k, v in dispatcher.targetoptions.items() if k != "nopython"}
        copies[name] = njit(cache=True, **options)(copy)
    table.update(copies)
    return copies


_RADAU_COPIES = _for_kind(RADAU, "radau")
#: :func:`scan` and :func:`state_at` for radau15's polynomial alone (``kind`` must be
#: ``RADAU``)
scan_radau, state_at_radau = _RADAU_COPIES["scan"], _RADAU_COPIES["state_at"]
_HERMITE_COPIES = _for_kind(HERMITE, "hermite")
#: :func:`scan` and :func:`state_at` for the cubic Hermite interpolant alone (``kind``
#: must be ``HERMITE``; dop853's, through :func:`scan_steps`)
_scan_hermite, state_at_hermite = _HERMITE_COPIES["scan"], _HERMITE_COPIES["state_at"]
#: :func:`scan` for straight drifts alone (``kind`` must be ``LINE``; leapfrog's)
scan_line = _for_kind(LINE, "line")["scan"]
