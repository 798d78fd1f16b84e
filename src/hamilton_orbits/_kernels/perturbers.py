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

- ``p[0]`` the number of small bodies ``nb`` (the clock is row ``nb``), ``p[1]``
  1.0 for the time-reversed motion (the velocities given are ``-v``), ``p[2]``,
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
  :data:`CACHE_SLOTS` slots of (time, the perturbers' positions and velocities).
  An integrator's corrector iterations evaluate the field again and again at the
  same stage times: the perturbers' states of a time met in the last
  ``CACHE_SLOTS`` are copied, not evaluated again (the same numbers).  One ``p``
  must therefore serve one run at a time.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hamilton_orbits._kernels.chebyshev import add_state
from hamilton_orbits._kernels.figures import zonal_field
from hamilton_orbits._kernels.nbody import j2_field, newtonian_only
from hamilton_orbits._kernels.nongrav import nongrav
from hamilton_orbits._kernels.relativity import eih_sources

__all__ = ["CACHE_SLOTS", "HEADER", "cache_size", "eih_on_particles", "small_bodies_field"]

#: the entries of ``p`` before the tables
HEADER = 17
#: the stage times whose perturbers' states the cache keeps (radau15 has 8)
CACHE_SLOTS = 8


def cache_size(k_p: int) -> int:
    """The floats of the cache of ``k_p`` perturbers (see the module)."""
    return 1 + CACHE_SLOTS * (1 + 6 * k_p)


@njit(cache=True, error_model="numpy")
def small_bodies_field(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The accelerations of the small bodies (and 0 for the clock), see the module."""
    nb, k_p = int(p[0]), int(p[4])
    n = k_p + nb
    big_r, big_v, big_a = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    big_gm = np.zeros(n)
    _cached_perturbers(p, r[nb, 0], big_r, big_v, big_gm)
    sign = -1.0 if p[1] != 0.0 else 1.0
    for i in range(nb):
        for c in range(3):
            big_r[k_p + i, c] = r[i, c]
            big_v[k_p + i, c] = sign * v[i, c]
    if p[7] > p[6]:
        eih_on_particles(big_r, big_v, big_gm, big_a, p[int(p[6]):int(p[7])], k_p)
    else:
        newtonian_only(big_r, big_v, big_gm, big_a, p[0:0])  # (compiled apart: not inlined)
    if p[9] > p[8]:
        j2_field(big_r, big_v, big_gm, big_a, p[int(p[8]):int(p[9])])
    if p[11] > p[10]:
        zonal_field(big_r, big_v, big_gm, big_a, p[int(p[10]):int(p[11])])
    if p[13] > p[12]:
        nongrav(big_r, big_v, big_gm, big_a, p[int(p[12]):int(p[13])])
    for i in range(nb):
        for c in range(3):
            acc[i, c] = big_a[k_p + i, c]
    for c in range(3):
        acc[nb, c] = 0.0


@njit(cache=True, error_model="numpy")
def eih_on_particles(r, v, gm, acc, p, k_p):  # pragma: no cover - compiled
    """:func:`hamilton_orbits._kernels.relativity.eih` for the massless rows ``k_p``...
    alone, ADDED to their ``acc`` (the massive rows ``0 .. k_p - 1``, whose own
    accelerations are not wanted, left alone): the same terms in the same order,
    so the same bits, without the massive bodies' mutual corrections.  The sources'
    Newtonian accelerations and potentials, which the corrections use, are summed
    over their partners in increasing order as the pair loop of
    :func:`~hamilton_orbits._kernels.relativity.newtonian_and_potential` sums them."""
    ic2 = 1.0 / (p[0] * p[0])
    beta, gamma = p[1], p[2]
    n = r.shape[0]
    src = eih_sources(p, gm)  # (the massless rows never: their gm is 0)
    acc_n, phi = np.zeros((n, 3)), np.zeros(n)
    for m in range(n):
        if m < k_p and not src[m]:
            continue  # (a perturber that is no source: its own field is not needed)
        for k in range(k_p):  # (the massless rows add nothing: +-0 to each sum)
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
def _cached_perturbers(p, days, out_r, out_v, out_gm):  # pragma: no cover - compiled
    """:func:`_perturbers`, through the cache of the last stage times (see the
    module): a time met again is copied."""
    k_p, at = int(p[4]), int(p[16])
    size = 1 + 6 * k_p
    for k in range(k_p):
        out_gm[k] = p[int(p[14]) + 4 * k]
    for slot in range(CACHE_SLOTS):
        row = at + 1 + slot * size
        if p[row] == days:
            for k in range(k_p):
                for c in range(3):
                    out_r[k, c] = p[row + 1 + 6 * k + c]
                    out_v[k, c] = p[row + 4 + 6 * k + c]
            return
    _perturbers(p, days, out_r, out_v, out_gm)
    slot = int(p[at])
    row = at + 1 + slot * size
    p[row] = days
    for k in range(k_p):
        for c in range(3):
            p[row + 1 + 6 * k + c] = out_r[k, c]
            p[row + 4 + 6 * k + c] = out_v[k, c]
    p[at] = (slot + 1) % CACHE_SLOTS


@njit(cache=True, error_model="numpy")
def _perturbers(p, days, out_r, out_v, out_gm):  # pragma: no cover - compiled
    """The perturbers' barycentric states (au, au/day) and GMs at ``days`` from the
    epoch into the first rows of ``out_r``, ``out_v``, ``out_gm`` (each segment
    evaluated once, its state added to those of the chains through it); NaN for a
    time outside their segments (the run then stops as on a non-finite force)."""
    au, k_p, table, segs = p[5], int(p[4]), int(p[14]), int(p[15])
    jd1, jd2 = p[2], p[3] + days
    n_seg = int((table - segs) / 5)
    width = 1
    for s in range(n_seg):
        width = max(width, int(p[segs + 5 * s + 3]))
    t, u = np.empty(width), np.empty(width)
    seg_state = np.zeros((n_seg, 6))
    for s in range(n_seg):
        at = segs + 5 * s
        n_rec, m, first = int(p[at + 2]), int(p[at + 3]), int(p[at + 4])
        coef = p[first:first + 3 * n_rec * m].reshape((3, n_rec, m))
        if not add_state(coef, p[at], p[at + 1], jd1, jd2, seg_state[s], t, u):
            seg_state[s, :] = np.nan
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
