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
  (km, days).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hamilton_orbits._kernels.chebyshev import add_state
from hamilton_orbits._kernels.figures import zonal_field
from hamilton_orbits._kernels.nbody import j2_field, newtonian
from hamilton_orbits._kernels.nongrav import nongrav
from hamilton_orbits._kernels.relativity import eih

__all__ = ["HEADER", "small_bodies_field"]

#: the entries of ``p`` before the tables
HEADER = 16


@njit(cache=True, error_model="numpy")
def small_bodies_field(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The accelerations of the small bodies (and 0 for the clock), see the module."""
    nb, k_p = int(p[0]), int(p[4])
    n = k_p + nb
    big_r, big_v, big_a = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    big_gm = np.zeros(n)
    _perturbers(p, r[nb, 0], big_r, big_v, big_gm)
    sign = -1.0 if p[1] != 0.0 else 1.0
    for i in range(nb):
        for c in range(3):
            big_r[k_p + i, c] = r[i, c]
            big_v[k_p + i, c] = sign * v[i, c]
    if p[7] > p[6]:
        eih(big_r, big_v, big_gm, big_a, p[int(p[6]):int(p[7])])
    else:
        newtonian(big_r, big_v, big_gm, big_a)
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
def _perturbers(p, days, out_r, out_v, out_gm):  # pragma: no cover - compiled
    """The perturbers' barycentric states (au, au/day) and GMs at ``days`` from the
    epoch into the first rows of ``out_r``, ``out_v``, ``out_gm``; NaN for a time
    outside their segments (the run then stops as on a non-finite force)."""
    au, k_p, table, segs = p[5], int(p[4]), int(p[14]), int(p[15])
    jd1, jd2 = p[2], p[3] + days
    state = np.empty(6)
    width = 1
    for s in range(int((table - segs) / 5)):
        width = max(width, int(p[segs + 5 * s + 3]))
    t, u = np.empty(width), np.empty(width)
    for k in range(k_p):
        row = table + 4 * k
        out_gm[k] = p[row]
        state[:] = 0.0
        for link in range(int(p[row + 1])):
            at = segs + 5 * int(p[row + 2 + link])
            n_rec, m, first = int(p[at + 2]), int(p[at + 3]), int(p[at + 4])
            coef = p[first:first + 3 * n_rec * m].reshape((3, n_rec, m))
            if not add_state(coef, p[at], p[at + 1], jd1, jd2, state, t, u):
                state[:] = np.nan
                break
        for c in range(3):
            out_r[k, c] = state[c] / au
            out_v[k, c] = state[3 + c] / au
