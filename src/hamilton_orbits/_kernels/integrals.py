"""Hamilton's integrals (C), (D), (E) of many states in one compiled pass.

:func:`integral_sums` is what ``integrate`` computes for every trajectory: per
output state, the vis-viva energy (E) ``sum gm v^2 / 2 - sum_{pairs} gm gm' / d``,
the areal vector (D) ``sum gm r x v`` and the moments of the centre of gravity
(C) ``sum gm``, ``sum gm r``, ``sum gm v``.  Bodies whose state is not finite
(taken out of the run by an event) count as absent; test particles (``gm = 0``)
add nothing and cost one pass over their rows.  The energy's sums are
compensated (Neumaier), so that its rounding does not grow with the number of
pairs.  :func:`approaches` finds the close approaches (of test particles, and of
massive bodies to heavier ones) a fixed step was too long for
(:func:`hamilton_orbits.integrals.under_resolved_encounters`), :func:`primaries`
each body's primary, :func:`screen` the whole check in one call.  No astropy here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["COLUMNS", "MASSIVE_PAIRS_MAX", "approaches", "integral_errors", "integral_sums",
           "primaries", "screen"]

#: The most massive bodies whose pairs' close approaches are checked (beyond, only
#: test particles' are): the check of every pair at every output costs about a
#: force evaluation of its own (three times a one-step call of 30 bodies, twelve
#: times one of 300), which a run of more bodies pays at each output.
MASSIVE_PAIRS_MAX = 32

#: Columns of :func:`integral_sums`'s output.
COLUMNS = ("energy", "lx", "ly", "lz", "gm", "rx", "ry", "rz", "vx", "vy", "vz")


@njit(cache=True, inline="always", error_model="numpy")
def _add(s, c, x):  # pragma: no cover - compiled
    """Neumaier's compensated ``s + x``: returns the new ``(s, c)`` (an overflowed sum
    is infinite, not NaN: its compensation is dropped)."""
    t = s + x
    if not abs(t) < math.inf:
        return t, 0.0
    if abs(s) >= abs(x):
        c += (s - t) + x
    else:
        c += (x - t) + s
    return t, c


@njit(cache=True, error_model="numpy")
def integral_sums(r, v, gm, gone, out):  # pragma: no cover - compiled
    """Fill ``out`` (k, 11) with the sums of :data:`COLUMNS` for states ``r``,
    ``v`` (k, n, 3); ``gm`` (m, n) with ``m = 1`` (one set of masses) or ``k``.

    Returns the flat index ``t * n + i`` of the first body whose state is not
    finite while ``gone[i]`` is False (a state lost by the integration), else -1.
    """
    k, n = r.shape[0], r.shape[1]
    lost = -1
    idx = np.empty(n, dtype=np.int64)
    for t in range(k):
        g = gm[t if gm.shape[0] > 1 else 0]
        ek, ck = 0.0, 0.0
        lx, ly, lz, total = 0.0, 0.0, 0.0, 0.0
        rx, ry, rz, vx, vy, vz = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        nm = 0
        for i in range(n):
            x0, x1, x2 = r[t, i, 0], r[t, i, 1], r[t, i, 2]
            w0, w1, w2 = v[t, i, 0], v[t, i, 1], v[t, i, 2]
            if not math.isfinite(x0 + x1 + x2 + w0 + w1 + w2):
                if lost < 0 and not gone[i]:
                    lost = t * n + i
                continue
            gi = g[i]
            if gi == 0.0:
                continue
            idx[nm] = i
            nm += 1
            ek, ck = _add(ek, ck, 0.5 * gi * (w0 * w0 + w1 * w1 + w2 * w2))
            lx += gi * (x1 * w2 - x2 * w1)
            ly += gi * (x2 * w0 - x0 * w2)
            lz += gi * (x0 * w1 - x1 * w0)
            total += gi
            rx += gi * x0
            ry += gi * x1
            rz += gi * x2
            vx += gi * w0
            vy += gi * w1
            vz += gi * w2
        ep, cp = 0.0, 0.0
        for a in range(nm):
            i = idx[a]
            for b in range(a + 1, nm):
                j = idx[b]
                dx = r[t, i, 0] - r[t, j, 0]
                dy = r[t, i, 1] - r[t, j, 1]
                dz = r[t, i, 2] - r[t, j, 2]
                d = math.sqrt(dx * dx + dy * dy + dz * dz)
                if d > 0.0:
                    ep, cp = _add(ep, cp, g[i] * g[j] / d)
        out[t, 0] = (ek + ck) - (ep + cp)
        out[t, 1], out[t, 2], out[t, 3], out[t, 4] = lx, ly, lz, total
        out[t, 5], out[t, 6], out[t, 7] = rx, ry, rz
        out[t, 8], out[t, 9], out[t, 10] = vx, vy, vz
    return lost


@njit(cache=True, error_model="numpy")
def integral_errors(r, v, gm, t, gone, ee, ae, bd):  # pragma: no cover - compiled
    """Hamilton's integrals' changes from the first state (the arithmetic of
    :func:`hamilton_orbits.nbody.integral_errors`) into ``ee``, ``ae``, ``bd``
    (k,): ``(E - E_0) / |E_0|``, ``|L - L_0| / |L_0|`` (absolute where the first
    value is 0) and ``|R - R_0 - V_0 (t - t_0)| / s``, ``s`` the largest distance
    of a finite body from the first centre of mass (1 if 0).  Returns as
    :func:`integral_sums`."""
    k = r.shape[0]
    sums = np.empty((k, 11))
    lost = integral_sums(r, v, gm, gone, sums)
    e0 = abs(sums[0, 0])
    l0 = math.sqrt(sums[0, 1] ** 2 + sums[0, 2] ** 2 + sums[0, 3] ** 2)
    c0 = np.empty(6)
    for c in range(6):
        c0[c] = sums[0, 5 + c] / sums[0, 4]
    scale = 0.0
    for i in range(r.shape[1]):
        d2 = (r[0, i, 0] - c0[0]) ** 2 + (r[0, i, 1] - c0[1]) ** 2 + (r[0, i, 2] - c0[2]) ** 2
        if d2 > scale and d2 < math.inf:
            scale = d2
    scale = math.sqrt(scale) if scale > 0.0 else 1.0
    for j in range(k):
        de = sums[j, 0] - sums[0, 0]
        ee[j] = de / e0 if e0 > 0.0 else de
        dl = math.sqrt((sums[j, 1] - sums[0, 1]) ** 2 + (sums[j, 2] - sums[0, 2]) ** 2
                       + (sums[j, 3] - sums[0, 3]) ** 2)
        ae[j] = dl / l0 if l0 > 0.0 else dl
        d2 = 0.0
        for c in range(3):
            x = sums[j, 5 + c] / sums[j, 4] - c0[c] - (t[j] - t[0]) * c0[3 + c]
            d2 += x * x
        bd[j] = math.sqrt(d2) / scale
    return lost


@njit(cache=True, error_model="numpy")
def primaries(r, v, gm, out, massive=False):  # pragma: no cover - compiled
    """``out[i]``: the primary of test particle ``i`` in the state ``r``, ``v`` (n, 3)
    (the massive body it is bound to with the largest ``1/a``, else the first of
    largest GM), -1 for a massive body (:func:`hamilton_orbits.integrals.primaries`).
    ``massive``: a massive body's too, but the first of largest GM's (-1): the
    heavier body (of two equal, the earlier) it is bound to with the largest ``1/a``
    (``mu`` their summed GM), else the first of largest GM (the Moon's is the Earth,
    a planet's the Sun)."""
    n = len(gm)
    big = -1
    for j in range(n):
        if gm[j] > 0 and (big < 0 or gm[j] > gm[big]):
            big = j
    for i in range(n):
        out[i] = -1
        if (gm[i] != 0 and not massive) or big < 0 or i == big:
            continue
        out[i] = _primary_of(r, v, gm, i, big)
    return out


@njit(cache=True, error_model="numpy")
def _primary_of(r, v, gm, i, big):  # pragma: no cover - compiled
    """Body ``i``'s primary in the state ``r``, ``v`` (n, 3) (see :func:`primaries`;
    ``big`` the first of largest GM)."""
    best, best_inv = big, 0.0
    for j in range(len(gm)):
        if gm[j] > gm[i] or (gm[j] == gm[i] and j < i and gm[j] > 0):
            d2, w2 = 0.0, 0.0
            for k in range(3):
                d2 += (r[i, k] - r[j, k]) ** 2
                w2 += (v[i, k] - v[j, k]) ** 2
            mu = gm[j] + gm[i]
            if w2 * w2 * d2 >= 4.0 * mu * mu and gm[i] > 0:
                continue  # unbound to it (1/a <= 0: no square root to take)
            inv_a = 2.0 / math.sqrt(d2) - w2 / mu
            if inv_a > best_inv:
                best, best_inv = j, inv_a
    return best


@njit(cache=True, inline="always", error_model="numpy")
def _periapsis(d2, u2, rad, mu):  # pragma: no cover - compiled
    """The two-body periapsis ``q`` and ``1/a`` from ``|d|^2``, ``|u|^2``, ``d . u``."""
    inv_a = 2.0 / math.sqrt(d2) - u2 / mu
    h2 = max(d2 * u2 - rad * rad, 0.0)
    ecc = math.sqrt(max(1.0 - h2 / mu * inv_a, 0.0))
    return h2 / mu / (1.0 + ecc), inv_a


@njit(cache=True, inline="always", error_model="numpy")
def _ahead(t, k):  # pragma: no cover - compiled
    """The direction of time over the leg from output ``k - 1`` to ``k`` of the times
    ``t``: 1.0 forwards, -1.0 backwards, 0.0 for the first output (no leg) or a leg of
    no time.  A pair passed its closest point in the leg where its radial velocity
    ``d . u`` times it turned from negative to positive (approaching, then receding,
    in the run's direction: backwards, ``d . u`` from positive to negative), exactly
    (a product by +-1 rounds nothing)."""
    if k == 0:
        return 0.0
    return 1.0 if t[k] > t[k - 1] else (-1.0 if t[k] < t[k - 1] else 0.0)


@njit(cache=True, error_model="numpy")
def _within_hill(r, gm, j, cj, t, d2):  # pragma: no cover - compiled
    """Whether a distance ``sqrt(d2)`` from body ``j`` is within three of its Hill
    radii about its primary ``cj`` at output ``t``, ``3 (gm_j / 3 gm_cj)^(1/3) |r_j -
    r_cj|``, in sixth powers (no root to take); always for the most massive body
    (``cj`` -1: it has no primary)."""
    if cj < 0:
        return True
    sep2 = 0.0
    for k in range(3):
        sep2 += (r[t, j, k] - r[t, cj, k]) ** 2
    return d2 * d2 * d2 * gm[cj] * gm[cj] <= 81.0 * gm[j] * gm[j] * sep2 * sep2 * sep2


@njit(cache=True, error_model="numpy")
def approaches(r, v, gm, t_out, tp, m, prim, exempt, exempt_dist, h, fraction, bad, dist,
               tau):  # pragma: no cover - compiled
    """For the bodies ``tp`` (test particles, and massive bodies other than the most
    massive) and massive bodies ``m`` over states ``r``, ``v`` (n_t, n, 3) at times
    ``t_out`` (increasing, or decreasing: a run backwards): ``bad[t, p, j]`` where
    the step ``h[t]`` exceeds ``fraction`` of the approach's time scale,
    with the distance and time scale in ``dist``, ``tau`` (n_t, n_tp, n_m); when
    ``dist`` has no rows, neither is stored and ``bad`` (1, n_tp, n_m) is set where
    any output is; returns the count.

    A pair is checked once, from its lighter body (of two equal, the later one),
    with ``mu`` the pair's summed GM.  An approach is one to the body's primary
    ``prim[tp[p]]`` faster than a tenth of the orbit's pace ``1 / n`` at the first
    output (any, unbound), or within three Hill radii of another body (about that
    body's own primary), not to ``exempt`` beyond ``exempt_dist``; at an
    output its distance is ``|d|``, between outputs where the pair passed its
    closest point, the radial velocity turned from approaching to receding in the
    direction of the run (from negative to positive forwards, from positive to
    negative backwards: :func:`_ahead`; the pair about the primary, or within the
    Hill sphere at one of the two) the larger two-body periapsis of the two
    outputs; its time scale ``min(dist / speed, sqrt(dist^3 / mu))``."""
    n_t = r.shape[0]
    keep = dist.shape[0] > 0
    count = 0
    for p in range(len(tp)):
        i = tp[p]
        c = prim[i]
        for jj in range(len(m)):
            j = m[jj]
            if j == i or gm[j] < gm[i] or (gm[j] == gm[i] and j > i):
                continue  # (the pair is checked from its other body)
            if gm[i] > 0 and j == c:
                continue  # a massive body's own orbit: its energy shows how it went
            mu = gm[j] + gm[i]
            pace = math.inf
            if j == c:  # the orbit's own pace 1 / n at the first output (inf: unbound)
                d2, u2 = 0.0, 0.0
                for k in range(3):
                    d2 += (r[0, i, k] - r[0, j, k]) ** 2
                    u2 += (v[0, i, k] - v[0, j, k]) ** 2
                inv_a0 = 2.0 / math.sqrt(d2) - u2 / mu
                if inv_a0 > 0:
                    pace = 1.0 / math.sqrt(inv_a0 ** 3 * mu)
            cj = prim[j]  # (the Hill sphere is j's about its own primary)
            pd2, pu2, rad0, near0 = 0.0, 0.0, 0.0, False
            for t in range(n_t):
                ahead = _ahead(t_out, t)
                d2, u2, rad = 0.0, 0.0, 0.0
                for k in range(3):
                    dk = r[t, i, k] - r[t, j, k]
                    uk = v[t, i, k] - v[t, j, k]
                    d2 += dk * dk
                    u2 += uk * uk
                    rad += dk * uk
                # (the most massive body, cj -1, has no Hill sphere to be within: a
                # moon's conic about the Sun is not its path, 0.46 for 5.2 au)
                near = j == c or (cj >= 0 and _within_hill(r, gm, j, cj, t, d2))
                # (square roots only where needed: most pairs of most runs are far apart)
                dd, dd2, speed = math.sqrt(d2) if keep else -1.0, d2, -1.0
                if ahead * rad0 < 0 and ahead * rad > 0 and (near or near0):
                    # a closest point passed between, on the pair's two-body conic where
                    # it means one: about the primary, or within the Hill sphere at an
                    # end (Mars and Jupiter's, both about the Sun, was no path: 0.74 au)
                    q0, inv0 = _periapsis(pd2, pu2, rad0, mu)
                    q, inv_a = _periapsis(d2, u2, rad, mu)
                    qmax = max(q0, q)
                    if qmax < math.sqrt(min(pd2, d2)):
                        dd, dd2 = qmax, qmax * qmax
                        speed = math.sqrt(max(mu * (2.0 / qmax - max(inv0, inv_a)), 0.0))
                pd2, pu2, rad0, near0 = d2, u2, rad, near
                far = j == exempt and dd2 > exempt_dist * exempt_dist
                if not far and j != c:
                    far = not _within_hill(r, gm, j, cj, t, dd2)
                ts = math.inf  # (beyond the Hill sphere, or integrated exactly there)
                if not far:
                    if dd < 0.0:
                        dd = math.sqrt(dd2)
                    if speed < 0.0:
                        speed = math.sqrt(u2)
                    ts = math.sqrt(dd * dd * dd / mu)
                    if speed > 0:
                        ts = min(dd / speed, ts)
                    if j == c and not ts < 0.1 * pace:  # not faster than the orbit: its
                        ts = math.inf  # pace, not an approach
                flag = h[t] > fraction * ts
                count += flag
                if keep:
                    bad[t, p, jj] = flag
                    dist[t, p, jj] = dd
                    tau[t, p, jj] = ts
                elif flag:
                    bad[0, p, jj] = True
    return count


@njit(cache=True, error_model="numpy")
def screen(r, v, gm, t, step, exempt, exempt_dist, fraction, light):
    # pragma: no cover - compiled
    """Whether :func:`approaches` could find any approach in states ``r``, ``v``
    (n_t, n, 3) at times ``t`` of a run of fixed ``step`` (``gm`` (n,): bodies of at
    most ``light`` of the largest GM checked as test particles): False rules it
    out in one compiled call, which a run whose every approach is resolved (nearly
    all) leaves at (a continuing call of one step of ten bodies: 1 us); True (a
    pair close enough for its speed) calls for the whole check.  Small, so that a
    first run compiles it quickly, the whole check only where it is needed.

    Its test is that of :func:`approaches`, with each body's primary found only for
    a pair near enough to need it, the approach's time scale compared in squares
    with a margin of 1e-9 for their rounding, and without the pruning of an approach
    at the orbit's own pace (which only takes flags away).  For each body and
    output, the other bodies in one loop without branches (:func:`_rows`: the
    compiler's vector instructions; a disc of 1000 massive bodies costs about a
    force evaluation); the pairs it finds near looked at one by one
    (:func:`_flagged`).  Two levels of compiled calls, no more: numba optimises a
    function with every function it calls linked in, so each level of calls
    compiles its callees' code again (a third level, this function's loop apart
    from its set-up, and a fourth, the primaries' cache, cost a first fixed-step
    run 0.7 s more of its 3.1 s for this function, CPU time on this machine)."""
    n_t, n = r.shape[0], r.shape[1]
    if n_t < 2 or n < 2:
        return False
    top = 0
    for i in range(n):
        if gm[i] > gm[top]:
            top = i
    if not gm[top] > 0:
        return False
    gm0 = np.empty(n)
    for i in range(n):
        gm0[i] = 0.0 if gm[i] <= light * gm[top] else gm[i]
    h = np.empty(n_t)
    for k in range(n_t):
        gap = abs(t[max(k, 1)] - t[max(k, 1) - 1])
        if k + 1 < n_t:
            gap = max(gap, abs(t[k + 1] - t[k]))
        h[k] = min(step, gap)
    slack = 1.0 + 1e-9
    ex2 = (exempt_dist * slack) ** 2
    last = np.empty((4, n))  # |d|^2, |u|^2, d . u of each pair at the output before
    now = np.empty((4, n))  # (and in row 3, 1.0 where a pair is to be looked at)
    pair = np.empty(n)  # 1.0 where (i, j) is a pair checked from i
    prim = np.full(n, -2)  # the bodies' primaries, found where needed (-2: not yet)
    massive = 0
    for i in range(n):
        massive += gm0[i] > 0
    for i in range(n):
        if i == top or (gm0[i] > 0 and massive > MASSIVE_PAIRS_MAX):
            continue
        for j in range(n):
            pair[j] = 1.0 if (j != i and gm0[j] > 0 and (gm0[j] > gm0[i] or (
                gm0[j] == gm0[i] and j < i))) else 0.0
        for k in range(n_t):
            reach2 = (h[k] / fraction * slack) ** 2  # flagged: ts^2 < reach2
            ahead = _ahead(t, k)
            if _rows(r[k], v[k], i, gm0, pair, reach2, now, last, ahead):  # (a pair near
                # now, or a closest point passed between: looked at one by one)
                for j in range(n):
                    if now[3, j] > 0 and _flagged(r, v, gm0, top, prim, k, ahead, i, j,
                                                  now[:, j], last[:, j], reach2, slack,
                                                  j == exempt, ex2):
                        return True
            now, last = last, now  # (this output's rows are the next one's before)
    return False


@njit(cache=True, inline="always", error_model="numpy")
def _primary_cached(r, v, gm0, top, prim, i):  # pragma: no cover - compiled
    """Body ``i``'s primary at the first output, found once (-1: the most massive)."""
    if prim[i] == -2:
        prim[i] = -1 if i == top else _primary_of(r[0], v[0], gm0, i, top)
    return prim[i]


@njit(cache=True, error_model="numpy")
def _flagged(r, v, gm0, top, prim, t, ahead, i, j, now, last, reach2, slack, exempt, ex2):
    # pragma: no cover - compiled
    """The test of :func:`approaches` for the pair ``(i, j)`` at output ``t`` (``now``,
    ``last``: its ``|d|^2``, ``|u|^2``, ``d . u`` there and at the output before;
    ``ahead`` the leg's direction of time, :func:`_ahead`), but for the pruning at
    the orbit's pace and with the time scale in squares."""
    c = _primary_cached(r, v, gm0, top, prim, i)
    if gm0[i] > 0 and j == c:
        return False  # (a massive body's own orbit: not checked)
    cj = _primary_cached(r, v, gm0, top, prim, j)
    mu = gm0[i] + gm0[j]
    near = j == c or (cj >= 0 and _within_hill(r, gm0, j, cj, t, now[0]))
    dd2, speed2 = now[0], now[1]
    if ahead * last[2] < 0 and ahead * now[2] > 0 and (
            near or (cj >= 0 and _within_hill(r, gm0, j, cj, t - 1, last[0]))):
        q0, inv0 = _periapsis(last[0], last[1], last[2], mu)  # (as approaches: the
        q, inv_a = _periapsis(now[0], now[1], now[2], mu)  # closest point between)
        qmax = max(q0, q)
        if qmax < math.sqrt(min(last[0], now[0])):
            dd2 = qmax * qmax
            speed2 = max(mu * (2.0 / qmax - max(inv0, inv_a)), 0.0)
    if exempt and dd2 > ex2:
        return False
    if j != c and not _within_hill(r, gm0, j, cj, t, dd2):
        return False
    # ts the lesser of d / speed and sqrt(d^3 / mu)
    return dd2 < reach2 * speed2 or dd2 * dd2 * dd2 < (reach2 * mu) ** 2 * slack


@njit(cache=True, error_model="numpy")
def _rows(rt, vt, i, gm0, pair, reach2, now, last, ahead):
    # pragma: no cover - compiled
    """``now``: each pair's ``|d|^2``, ``|u|^2``, ``d . u`` of body ``i`` with the
    others in the states ``rt``, ``vt`` (n, 3); whether one of ``pair`` is within the
    flagging test ignoring an exempt body, or passed its closest point since ``last``
    in the direction of time ``ahead`` of the leg (:func:`_ahead`: 0.0, none to
    pass; no branch in the loop: vectorised)."""
    any_hit = 0.0
    for j in range(rt.shape[0]):
        dx, dy, dz = rt[i, 0] - rt[j, 0], rt[i, 1] - rt[j, 1], rt[i, 2] - rt[j, 2]
        ux, uy, uz = vt[i, 0] - vt[j, 0], vt[i, 1] - vt[j, 1], vt[i, 2] - vt[j, 2]
        d2 = dx * dx + dy * dy + dz * dz
        u2 = ux * ux + uy * uy + uz * uz
        rad = dx * ux + dy * uy + dz * uz
        now[0, j], now[1, j], now[2, j] = d2, u2, rad
        mu = gm0[i] + gm0[j]
        near = (d2 < reach2 * u2) | (d2 * d2 * d2 < 2.0 * (reach2 * mu) ** 2)
        passed = (ahead * last[2, j] < 0.0) & (ahead * rad > 0.0)
        look = pair[j] * max(near, passed)
        now[3, j] = look
        any_hit = max(any_hit, look)
    return any_hit > 0

