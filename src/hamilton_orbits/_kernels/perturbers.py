"""Small bodies in the field of bodies read from an ephemeris, compiled.

:func:`small_bodies_field` is a right-hand side ``accel(r, v, gm, acc, p)``
(:mod:`hamilton_orbits._kernels.signatures`) whose state holds only the small
bodies, massless, and last a *clock*: a massless row whose x coordinate is the time
in days from the epoch (its velocity 1, its acceleration 0, so that every
integrator carries the time of each of its stages exactly as it carries a
position: the extended phase space of a time-dependent field).  At each call the
perturbers' barycentric states at that time are read from Chebyshev segments
(:func:`hamilton_orbits._kernels.chebyshev.add_state`), put before the small
bodies, and the forces are those of the n-body kernels on the whole: Newton's, or
the Einstein-Infeld-Hoffmann equations (:func:`hamilton_orbits._kernels.
relativity.eih`), then a J2 field and a zonal field; the small bodies' rows are
kept, the perturbers' dropped (they follow the ephemeris).  No astropy here.

``p`` (float64):

- ``p[0]`` the number of small bodies ``nb`` (the clock is row ``nb``; its
  velocity -1 says that the motion is the time-reversed one, the velocities
  given ``-v``), ``p[1]`` 1.0 for the zonal field about the Earth's pole of date
  (:func:`~hamilton_orbits._kernels.figures.precessed_pole`; 0: the pole its
  parameters give), ``p[2]``,
  ``p[3]`` the epoch's TDB Julian date in two parts, ``p[4]`` the number of
  perturbers ``K``, ``p[5]`` the kilometres in an au;
- ``p[6:14]`` four (start, end) pairs: the parameters of ``eih``, ``j2_field``,
  ``zonal_field`` and ``nongrav`` in ``p`` (start = end: not applied; no ``eih``:
  Newton);
- ``p[14]`` the start of the perturbers' table, rows ``(gm, links, segment,
  segment)`` (the chain of segments whose states add up to the barycentric one,
  one or two); ``p[15]`` the start of the segments' table, rows ``(init, intlen,
  records, coefficients, start of the coefficients (3, records, coefficients))``
  (km, days);
- ``p[16]`` the start of a cache the kernel writes: the next slot, then
  :data:`CACHE_SLOTS` slots of (time, the perturbers' positions and velocities,
  and, with ``eih``, the sources' Newtonian accelerations and potentials).  An
  integrator's corrector iterations evaluate the field again and again at the
  same stage times: what depends on the time alone, for a time met in the last
  ``CACHE_SLOTS``, is copied, not computed again (the same numbers).  One ``p``
  must therefore serve one run at a time.
- ``p[17]`` the number of *shadow* rows ``ns``, after the clock (rows ``nb + 1``
  ... ``nb + ns``), ``p[18]`` the start of their table: the perturber each one
  follows.  A shadow row is given the acceleration of its perturber's ephemeris
  (:func:`~hamilton_orbits._kernels.chebyshev.add_record_acceleration`), so that,
  started on the perturber's state, it follows the ephemeris to the integrator's
  accuracy: the rows the events between a small body and a perturber watch
  (``small_bodies.propagate(events=...)``).  It acts on nothing;
- the last element: the integrators' clock (unused here: the clock row holds
  the time).

What is computed per call is what the small bodies feel: Newton's law from the
perturbers alone (:func:`hamilton_orbits._kernels.nbody.massless_rows`; the
perturbers' mutual pull, which the ephemeris already holds, is never summed),
or, with ``eih``, the small bodies' Newtonian sums and corrections
(:func:`eih_on_particles`) on the sources' sums of the cache.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hamilton_orbits._kernels.chebyshev import (
    acceleration_basis,
    add_record,
    add_record_acceleration,
    basis,
)
from hamilton_orbits._kernels.figures import precessed_pole, zonal_field
from hamilton_orbits._kernels.jacobians import fd_add, fd_scales, fd_shift
from hamilton_orbits._kernels.nbody import j2_field, massless_rows
from hamilton_orbits._kernels.nongrav import nongrav
from hamilton_orbits._kernels.relativity import eih_sources

__all__ = ["CACHE_SLOTS", "HEADER", "cache_size", "eih_on_particles", "small_bodies_augmented",
           "small_bodies_field", "source_sums"]

#: the entries of ``p`` before the tables
HEADER = 19
#: the stage times whose perturbers' states the cache keeps (radau15 has 8)
CACHE_SLOTS = 8
#: J2000.0 as a TDB Julian date (the origin of the pole of date's centuries)
_J2000 = 2451545.0


def cache_size(k_p: int) -> int:
    """The floats of the cache of ``k_p`` perturbers (see the module): a slot holds
    the time, then ``(r, v, a_N, phi)`` of each (10 floats)."""
    return 1 + CACHE_SLOTS * (1 + 10 * k_p)


@njit(cache=True, error_model="numpy")
def small_bodies_field(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The accelerations of the small bodies (and 0 for the clock), see the module."""
    nb, k_p = int(p[0]), int(p[4])
    # (the clock's velocity: 1, or -1 in the time-reversed motion)
    big_r, big_v, big_a, big_gm, acc_n, phi = _whole(r, v, p, v[nb, 0])
    if p[7] > p[6]:
        eih_on_particles(big_r, big_v, big_gm, big_a, p[int(p[6]):int(p[7])], k_p, acc_n, phi)
    else:
        massless_rows(big_r, big_gm, k_p, big_a)
    if p[9] > p[8]:
        _figure_on_particles(0.0, big_r, big_v, big_gm, big_a, p[int(p[8]):int(p[9])], k_p,
                             np.nan)
    if p[11] > p[10]:
        of_date = ((p[2] - _J2000) + (p[3] + r[nb, 0])) / 36525.0 if p[1] != 0.0 else np.nan
        _figure_on_particles(1.0, big_r, big_v, big_gm, big_a, p[int(p[10]):int(p[11])], k_p,
                             of_date)
    if p[13] > p[12]:
        nongrav(big_r, big_v, big_gm, big_a, p[int(p[12]):int(p[13])])
    for i in range(nb):
        for c in range(3):
            acc[i, c] = big_a[k_p + i, c]
    for c in range(3):
        acc[nb, c] = 0.0
    if p[17] > 0:
        _shadows(p, r[nb, 0], acc[nb + 1:nb + 1 + int(p[17])])


@njit(cache=True, error_model="numpy")
def small_bodies_augmented(r, v, gm, acc, p):  # pragma: no cover - compiled
    """:func:`small_bodies_field` and its variational equations on ``n + k n`` rows
    (``n = nb + 1``: the small bodies and the clock, then ``k`` tangent vectors of
    ``n`` rows; the form of :func:`hamilton_orbits.rhs.compile_rhs`'s
    ``augmented``).

    The Jacobian is applied by central differences of the field along each tangent
    vector (:func:`~hamilton_orbits._kernels.jacobians.fd_shift`, its step a
    :data:`~hamilton_orbits._kernels.jacobians.FD_EPS` of the closest distance
    between two bodies apart, one of them massive (:func:`~hamilton_orbits._kernels.
    jacobians.fd_scales`), at this time), the small bodies all shifted at once: none pulls on
    another, so each one's difference is its own.  The clock is never shifted and
    its tangent rows get 0: a tangent vector that starts without a clock part keeps
    none (the time is not varied)."""
    nb = int(p[0])
    n = nb + 1
    rb, vb, gb, ab = r[:n], v[:n], gm[:n], acc[:n]
    small_bodies_field(rb, vb, gb, ab, p)
    k = r.shape[0] // n - 1
    dr, dv, da = r[n:], v[n:], acc[n:]
    da[:] = 0.0
    if k == 0:
        return
    length, speed = _scales(rb, vb, p)
    rs, vs, ap, am = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    parts = 2 if (p[7] > p[6] or p[13] > p[12]) else 1  # (velocities: eih, nongrav)
    for m in range(k):
        for part in range(parts):
            h = fd_shift(rb, vb, dr, dv, m, part, length, speed, 1.0, rs, vs, ap)
            if not h > 0.0:
                continue
            _keep_clock(rb, vb, rs, vs, nb)
            small_bodies_field(rs, vs, gb, ap, p)
            fd_shift(rb, vb, dr, dv, m, part, length, speed, -1.0, rs, vs, am)
            _keep_clock(rb, vb, rs, vs, nb)
            small_bodies_field(rs, vs, gb, am, p)
            fd_add(ap, am, h, da, m)


@njit(cache=True, inline="always")
def _keep_clock(r, v, rs, vs, nb):  # pragma: no cover - compiled
    """The clock's row of the shifted state put back (the time is not varied)."""
    for c in range(3):
        rs[nb, c], vs[nb, c] = r[nb, c], v[nb, c]


@njit(cache=True, error_model="numpy")
def _scales(r, v, p):  # pragma: no cover - compiled
    """:func:`~hamilton_orbits._kernels.jacobians.fd_scales` of the perturbers (at the
    clock's time) and the small bodies together."""
    big_r, big_v, _, big_gm, _, _ = _whole(r, v, p, 1.0)
    return fd_scales(big_r, big_v, big_gm)


@njit(cache=True, inline="always", error_model="numpy")
def _whole(r, v, p, sign):  # pragma: no cover - compiled
    """The perturbers at the clock's time (through the cache) followed by the small
    bodies (their velocities times ``sign``): positions, velocities, accelerations
    (zeros), GMs, and the sources' Newtonian sums and potentials, in one
    allocation (it costs as much as the sums of a cache hit)."""
    nb, k_p = int(p[0]), int(p[4])
    n = k_p + nb
    work = np.zeros(14 * n)
    big_r, big_v = work[0:3 * n].reshape((n, 3)), work[3 * n:6 * n].reshape((n, 3))
    big_a, acc_n = work[6 * n:9 * n].reshape((n, 3)), work[9 * n:12 * n].reshape((n, 3))
    big_gm, phi = work[12 * n:13 * n], work[13 * n:14 * n]
    _cached_perturbers(p, r[nb, 0], big_r, big_v, big_gm, acc_n, phi)
    for i in range(nb):
        for c in range(3):
            big_r[k_p + i, c] = r[i, c]
            big_v[k_p + i, c] = sign * v[i, c]
    return big_r, big_v, big_a, big_gm, acc_n, phi


@njit(cache=True, error_model="numpy")
def _figure_on_particles(zonal, r, v, gm, acc, q, k_p, of_date):  # pragma: no cover
    """:func:`~hamilton_orbits._kernels.figures.zonal_field` (``zonal`` 1.0) or
    :func:`~hamilton_orbits._kernels.nbody.j2_field` (0.0) of the body ``q[0]`` ADDED to
    the rows ``k_p``... alone (the same bits: each row's term depends on that row
    and the body only): both run on the body and those rows, not on every
    perturber.  A finite ``of_date`` (Julian centuries from J2000): the zonal field
    about the pole of that date, not ``q``'s."""
    b, n = int(q[0]), r.shape[0] - k_p + 1
    work = np.empty(10 * n)
    sr, sv = work[0:3 * n].reshape((n, 3)), work[3 * n:6 * n].reshape((n, 3))
    sa, sg = work[6 * n:9 * n].reshape((n, 3)), work[9 * n:10 * n]
    for i in range(n):
        row = b if i == 0 else k_p + i - 1
        sg[i] = gm[row]
        for c in range(3):
            sr[i, c], sv[i, c], sa[i, c] = r[row, c], v[row, c], acc[row, c]
    here = q.copy()
    here[0] = 0.0
    # (``zonal`` a float: a constant bool made numba compile this function once for
    # True and once for False, 0.4 s more of a first run)
    if zonal != 0.0 and np.isfinite(of_date):
        precessed_pole(of_date, here[2:5])
    if zonal != 0.0:
        zonal_field(sr, sv, sg, sa, here)
    else:
        j2_field(sr, sv, sg, sa, here)
    for i in range(1, n):
        for c in range(3):
            acc[k_p + i - 1, c] = sa[i, c]


@njit(cache=True, error_model="numpy")
def source_sums(r, gm, p, k_p, acc_n, phi):  # pragma: no cover - compiled
    """The Newtonian accelerations ``acc_n`` and potentials ``phi`` of the
    post-Newtonian sources among the first ``k_p`` rows (:func:`~hamilton_orbits.
    _kernels.relativity.eih`'s ``p``), summed over their partners among those rows
    in increasing order, as the pair loop of :func:`~hamilton_orbits._kernels.
    relativity.newtonian_and_potential` sums them (the massless rows after them
    add nothing: +-0 to each sum); the other rows left alone.

    Every source at once for each partner (the loop the compiler vectorises): a
    term is the pair loop's to the bit, ``r_k - r_m`` being minus its separation
    exactly when ``k < m``, and a source's own row adds ``+0``."""
    src = eih_sources(p, gm)
    ns = 0
    for m in range(k_p):
        ns += 1 if src[m] else 0
    w = np.zeros((8, ns))  # x, y, z, the sums of a_x, a_y, a_z and phi, the row
    a = 0
    for m in range(k_p):
        if src[m]:
            w[0, a], w[1, a], w[2, a], w[7, a] = r[m, 0], r[m, 1], r[m, 2], m
            a += 1
    for k in range(k_p):
        xk, yk, zk, gk = r[k, 0], r[k, 1], r[k, 2], gm[k]
        for a in range(ns):
            dx = xk - w[0, a]
            dy = yk - w[1, a]
            dz = zk - w[2, a]
            d2 = dx * dx + dy * dy + dz * dz
            own = w[7, a] == k
            inv = 1.0 / np.sqrt(1.0 if own else d2)
            g = 0.0 if own else gk
            f = g * (inv * inv * inv)
            w[3, a] += f * dx
            w[4, a] += f * dy
            w[5, a] += f * dz
            w[6, a] += g * inv
    for a in range(ns):
        m = int(w[7, a])
        acc_n[m, 0], acc_n[m, 1], acc_n[m, 2], phi[m] = w[3, a], w[4, a], w[5, a], w[6, a]


@njit(cache=True, inline="always", error_model="numpy")
def _newtonian_sum(r, gm, m, k_p, acc_n, phi):  # pragma: no cover - compiled
    """Row ``m``'s Newtonian acceleration and potential from rows ``0 .. k_p - 1``
    (see :func:`source_sums`)."""
    for k in range(k_p):
        if k == m or (gm[k] == 0.0 and gm[m] == 0.0):
            continue
        lo, hi = (k, m) if k < m else (m, k)
        dx = r[hi, 0] - r[lo, 0]
        dy = r[hi, 1] - r[lo, 1]
        dz = r[hi, 2] - r[lo, 2]
        inv = 1.0 / np.sqrt(dx * dx + dy * dy + dz * dz)
        f = gm[k] * (inv * inv * inv)
        if k > m:
            acc_n[m, 0] += f * dx
            acc_n[m, 1] += f * dy
            acc_n[m, 2] += f * dz
        else:
            acc_n[m, 0] -= f * dx
            acc_n[m, 1] -= f * dy
            acc_n[m, 2] -= f * dz
        phi[m] += gm[k] * inv


@njit(cache=True, error_model="numpy")
def eih_on_particles(r, v, gm, acc, p, k_p, acc_n, phi):  # pragma: no cover - compiled
    """:func:`hamilton_orbits._kernels.relativity.eih` for the massless rows ``k_p``...
    alone, ADDED to their ``acc`` (the massive rows ``0 .. k_p - 1``, whose own
    accelerations are not wanted, left alone), the sources' sums ``acc_n``, ``phi``
    given (:func:`source_sums`): the same terms in the same order, so the same bits,
    without the massive bodies' mutual corrections."""
    ic2 = 1.0 / (p[0] * p[0])
    beta, gamma = p[1], p[2]
    src = eih_sources(p, gm)  # (the massless rows never: their gm is 0)
    for m in range(k_p, r.shape[0]):
        _newtonian_sum(r, gm, m, k_p, acc_n, phi)
    _particle_corrections(r, v, gm, acc, acc_n, phi, src, k_p, ic2, beta, gamma)


@njit(cache=True, inline="always", error_model="numpy")
def _particle_corrections(r, v, gm, acc, acc_n, phi, src, k_p, ic2, beta,
                          gamma):  # pragma: no cover - compiled
    """The post-Newtonian corrections of the sources on the massless rows, as
    :func:`~hamilton_orbits._kernels.relativity.eih` writes them for a source ``i``
    acting on a receiver ``j`` later in the list, then ``acc += acc_n + corr``."""
    k0 = 2.0 * (beta + gamma) * ic2
    k1 = (2.0 * beta - 1.0) * ic2
    k2 = gamma * ic2
    k3 = (1.0 + gamma) * ic2
    k4 = 2.0 * (1.0 + gamma) * ic2
    k5 = 2.0 + 2.0 * gamma
    k6 = 1.0 + 2.0 * gamma
    k_aj = 0.5 * (3.0 + 4.0 * gamma) * ic2
    for j in range(k_p, r.shape[0]):  # (the receiver)
        c0, c1, c2 = 0.0, 0.0, 0.0
        for i in range(k_p):  # (a source, before it in the list)
            if not src[i]:
                continue
            dx = r[j, 0] - r[i, 0]
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            inv = 1.0 / np.sqrt(dx * dx + dy * dy + dz * dz)
            vi2 = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
            vj2 = v[j, 0] * v[j, 0] + v[j, 1] * v[j, 1] + v[j, 2] * v[j, 2]
            vivj = v[i, 0] * v[j, 0] + v[i, 1] * v[j, 1] + v[i, 2] * v[j, 2]
            dvi = dx * v[i, 0] + dy * v[i, 1] + dz * v[i, 2]
            dvj = dx * v[j, 0] + dy * v[j, 1] + dz * v[j, 2]
            common = -k4 * vivj
            inv3 = inv * inv * inv
            f = gm[i] * inv3
            rv = dvi * inv
            bracket = (-k0 * phi[j] - k1 * phi[i] + k2 * vj2 + k3 * vi2 + common
                       - 1.5 * ic2 * rv * rv
                       - 0.5 * ic2 * (dx * acc_n[i, 0] + dy * acc_n[i, 1] + dz * acc_n[i, 2]))
            sv = (k5 * dvj - k6 * dvi) * f * ic2
            g = k_aj * gm[i] * inv
            fb = -f * bracket
            c0 += fb * dx + sv * (v[j, 0] - v[i, 0]) + g * acc_n[i, 0]
            c1 += fb * dy + sv * (v[j, 1] - v[i, 1]) + g * acc_n[i, 1]
            c2 += fb * dz + sv * (v[j, 2] - v[i, 2]) + g * acc_n[i, 2]
        acc[j, 0] += acc_n[j, 0] + c0
        acc[j, 1] += acc_n[j, 1] + c1
        acc[j, 2] += acc_n[j, 2] + c2


@njit(cache=True, error_model="numpy")
def _cached_perturbers(p, days, out_r, out_v, out_gm, acc_n, phi):  # pragma: no cover
    """:func:`_perturbers` (and, with ``eih``, :func:`source_sums` into ``acc_n``,
    ``phi``, zeros), through the cache of the last stage times (see the module): a
    time met again is copied."""
    k_p, at = int(p[4]), int(p[16])
    size = 1 + 10 * k_p
    for k in range(k_p):
        out_gm[k] = p[int(p[14]) + 4 * k]
    for slot in range(CACHE_SLOTS):
        row = at + 1 + slot * size
        if p[row] == days:
            _slot_copy(p, row + 1, k_p, out_r, out_v, acc_n, phi, False)
            return
    _perturbers(p, days, out_r, out_v, out_gm)
    if p[7] > p[6]:
        source_sums(out_r, out_gm, p[int(p[6]):int(p[7])], k_p, acc_n, phi)
    slot = int(p[at])
    row = at + 1 + slot * size
    p[row] = days
    _slot_copy(p, row + 1, k_p, out_r, out_v, acc_n, phi, True)
    p[at] = (slot + 1) % CACHE_SLOTS


@njit(cache=True, inline="always")
def _slot_copy(p, at, k_p, out_r, out_v, acc_n, phi, store):  # pragma: no cover - compiled
    """Copy the cache slot's values from ``p[at:]`` to the first ``k_p`` rows of
    ``out_r``, ``out_v``, ``acc_n``, ``phi`` (``store``: the other way)."""
    for k in range(k_p):
        base = at + 10 * k
        for c in range(3):
            if store:
                p[base + c], p[base + 3 + c] = out_r[k, c], out_v[k, c]
                p[base + 6 + c] = acc_n[k, c]
            else:
                out_r[k, c], out_v[k, c] = p[base + c], p[base + 3 + c]
                acc_n[k, c] = p[base + 6 + c]
        if store:
            p[base + 9] = phi[k]
        else:
            phi[k] = p[base + 9]


@njit(cache=True, inline="always")
def _width(p):  # pragma: no cover - compiled
    """The most coefficients a segment of ``p``'s table has (at least 1)."""
    segs = int(p[15])
    width = 1
    for s in range(int((int(p[14]) - segs) / 5)):
        width = max(width, int(p[segs + 5 * s + 3]))
    return width


@njit(cache=True, error_model="numpy")
def _shadows(p, days, acc):  # pragma: no cover - compiled
    """The accelerations (au/day^2) of the perturbers the shadow rows follow, at
    ``days`` from the epoch, into ``acc`` (ns, 3): the second derivative of each
    segment of the perturber's chain, summed (NaN outside the segments)."""
    au, table, segs = p[5], int(p[14]), int(p[15])
    jd1, jd2 = p[2], p[3] + days
    width = _width(p)
    u, du = np.empty(width), np.empty(width)
    for s in range(acc.shape[0]):
        row = table + 4 * int(p[int(p[18]) + s])
        for c in range(3):
            acc[s, c] = 0.0
        for link in range(int(p[row + 1])):
            at = segs + 5 * int(p[row + 2 + link])
            n_rec, m, first = int(p[at + 2]), int(p[at + 3]), int(p[at + 4])
            k = acceleration_basis(p[at], p[at + 1], n_rec, jd1, jd2, m, u, du)
            if k < 0:
                acc[s, :] = np.nan
                break
            coef = p[first:first + 3 * n_rec * m].reshape((3, n_rec, m))
            add_record_acceleration(coef, k, p[at + 1], du, acc[s])
        for c in range(3):
            acc[s, c] /= au


@njit(cache=True, error_model="numpy")
def _perturbers(p, days, out_r, out_v, out_gm):  # pragma: no cover - compiled
    """The perturbers' barycentric states (au, au/day) and GMs at ``days`` from the
    epoch into the first rows of ``out_r``, ``out_v``, ``out_gm`` (each segment
    evaluated once, its state added to those of the chains through it); NaN for a
    time outside their segments (the run then stops as on a non-finite force)."""
    au, k_p, table, segs = p[5], int(p[4]), int(p[14]), int(p[15])
    jd1, jd2 = p[2], p[3] + days
    n_seg = int((table - segs) / 5)
    width = _width(p)
    t, u = np.empty(width), np.empty(width)
    seg_state = np.zeros((n_seg, 6))
    k = -1
    for s in range(n_seg):
        at = segs + 5 * s
        n_rec, m, first = int(p[at + 2]), int(p[at + 3]), int(p[at + 4])
        if s == 0 or p[at] != p[at - 5] or p[at + 1] != p[at - 4] or p[at + 2] != p[at - 3]:
            # (a new grid of records; the segments are sorted by grid, perturber_field._tables)
            k = basis(p[at], p[at + 1], n_rec, jd1, jd2, width, t, u)
        if k < 0:
            seg_state[s, :] = np.nan
            continue
        coef = p[first:first + 3 * n_rec * m].reshape((3, n_rec, m))
        add_record(coef, k, p[at + 1], t, u, seg_state[s])
    state = np.empty(6)
    for k in range(k_p):
        row = table + 4 * k
        out_gm[k] = p[row]
        state[:] = 0.0
        for link in range(int(p[row + 1])):
            s = int(p[row + 2 + link])
            for c in range(6):
                state[c] += seg_state[s, c]
        for c in range(3):
            out_r[k, c] = state[c] / au
            out_v[k, c] = state[3 + c] / au
