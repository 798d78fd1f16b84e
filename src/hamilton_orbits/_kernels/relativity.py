"""The Einstein-Infeld-Hoffmann equations (first post-Newtonian n-body) as a kernel.

``eih(r, v, gm, acc, p)`` ADDS to ``acc`` the whole point-mass acceleration of
every body: the Newtonian sum of Hamilton's equation (B) plus its first
post-Newtonian correction, for the PPN parameters beta and gamma, in the form JPL
integrates its ephemerides (Moyer 2003, eq. 4-26; Park et al. 2021, section 3):

    a_i = sum_{j != i} mu_j (r_j - r_i) / r_ij^3 {
              1 - 2(beta + gamma)/c^2 sum_{k != i} mu_k / r_ik
          - (2 beta - 1)/c^2 sum_{k != j} mu_k / r_jk + gamma v_i^2 / c^2 + (1 + gamma) v_j^2 / c^2
              - 2 (1 + gamma)/c^2 v_i . v_j - 3/(2 c^2) [(r_i - r_j) . v_j / r_ij]^2
              + 1/(2 c^2) (r_j - r_i) . a_j }
          + 1/c^2 sum_{j != i} mu_j / r_ij^3
                [(r_i - r_j) . ((2 + 2 gamma) v_i - (1 + 2 gamma) v_j)] (v_i - v_j)
          + (3 + 4 gamma)/(2 c^2) sum_{j != i} mu_j a_j / r_ij

with ``a_j`` the Newtonian acceleration of body j (the difference is of second
post-Newtonian order).  Massless bodies feel the field and add nothing to it.
*Semi-active* bodies (rebound's ``testparticle_type = 1``) pull on every other
body and feel every other body, but not each other: their pairs are left out of
the sums (``hamilton_orbits._kernels.nbody.newtonian_semi_active`` is Newton's
law alone with that rule).
No astropy here.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def newtonian_and_potential(r, gm, semi, acc_n, phi, inv_d):  # pragma: no cover - compiled
    """Overwrite ``acc_n`` (n, 3) with the Newtonian accelerations, ``phi`` (n,) with
    the Newtonian potentials ``sum_{k != i} gm_k / r_ik`` and ``inv_d`` (n, n) with the
    inverse distances (pairs of massless bodies, and of two semi-active bodies,
    ``semi`` (n,) True, left out)."""
    n = r.shape[0]
    for i in range(n):
        acc_n[i, 0] = 0.0
        acc_n[i, 1] = 0.0
        acc_n[i, 2] = 0.0
        phi[i] = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            if (gm[i] == 0.0 and gm[j] == 0.0) or (semi[i] and semi[j]):
                continue
            dx = r[j, 0] - r[i, 0]
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            d2 = dx * dx + dy * dy + dz * dz
            inv = 1.0 / np.sqrt(d2)
            inv_d[i, j] = inv
            inv_d[j, i] = inv
            inv3 = inv * inv * inv
            fi = gm[j] * inv3
            fj = gm[i] * inv3
            acc_n[i, 0] += fi * dx
            acc_n[i, 1] += fi * dy
            acc_n[i, 2] += fi * dz
            acc_n[j, 0] -= fj * dx
            acc_n[j, 1] -= fj * dy
            acc_n[j, 2] -= fj * dz
            phi[i] += gm[j] * inv
            phi[j] += gm[i] * inv


@njit(cache=True, inline="always")
def eih_sources(p, gm):  # pragma: no cover - compiled
    """Which bodies are the post-Newtonian sources of :func:`eih`'s ``p = [c, beta,
    gamma, j_1, j_2, ...]``: those listed (every body when none is, but the
    semi-active ones, :func:`semi_active_of`), massive."""
    n = gm.shape[0]
    src = np.zeros(n, dtype=np.bool_)
    listed = False
    for b in range(3, p.shape[0]):
        if p[b] >= 0.0:
            src[int(p[b])] = True
            listed = True
    if not listed:
        semi = semi_active_of(p, n)
        for b in range(n):
            src[b] = not semi[b]
    for i in range(n):
        if gm[i] == 0.0:
            src[i] = False
    return src


@njit(cache=True, inline="always")
def semi_active_of(p, n):  # pragma: no cover - compiled
    """The semi-active bodies of :func:`eih`'s ``p``, (n,) True: body ``s`` listed
    after the sources as ``-1 - s``."""
    semi = np.zeros(n, dtype=np.bool_)
    for b in range(3, p.shape[0]):
        if p[b] < 0.0:
            semi[-1 - int(p[b])] = True
    return semi


@njit(cache=True)
def eih(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Newtonian plus first post-Newtonian accelerations (Moyer 2003, eq. 4-26), ADDED
    to ``acc``.  ``p = [c, beta, gamma, j_1, j_2, ..., -1 - s_1, ...]`` (c in the
    system's units of speed): the post-Newtonian terms of the sources ``j_1, j_2,
    ...`` (every massive body but the semi-active ones when none is given); every
    other massive body acts by Newton's law alone, on every body; the semi-active
    bodies ``s_1, ...`` not on each other (none of them a source).  One pass over the
    pairs for the Newtonian sums, one for the corrections (both directions of a pair
    at once)."""
    ic2 = 1.0 / (p[0] * p[0])
    beta = p[1]
    gamma = p[2]
    n = r.shape[0]
    acc_n = np.empty((n, 3))
    phi = np.empty(n)
    inv_d = np.empty((n, n))
    newtonian_and_potential(r, gm, semi_active_of(p, n), acc_n, phi, inv_d)
    src = eih_sources(p, gm)
    k = np.empty(7)
    k[0] = 2.0 * (beta + gamma) * ic2  # phi of the receiver
    k[1] = (2.0 * beta - 1.0) * ic2  # phi of the source
    k[2] = gamma * ic2  # v_receiver^2
    k[3] = (1.0 + gamma) * ic2  # v_source^2
    k[4] = 2.0 * (1.0 + gamma) * ic2  # v_i . v_j
    k[5] = 2.0 + 2.0 * gamma  # (2 + 2 gamma) v_receiver - (1 + 2 gamma) v_source
    k[6] = 1.0 + 2.0 * gamma
    k_aj = 0.5 * (3.0 + 4.0 * gamma) * ic2
    corr = np.zeros((n, 3))
    for i in range(n):
        for j in range(i + 1, n):
            if not (src[i] or src[j]):
                continue
            inv = inv_d[i, j]
            dx = r[j, 0] - r[i, 0]  # r_j - r_i
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            vi2 = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
            vj2 = v[j, 0] * v[j, 0] + v[j, 1] * v[j, 1] + v[j, 2] * v[j, 2]
            vivj = v[i, 0] * v[j, 0] + v[i, 1] * v[j, 1] + v[i, 2] * v[j, 2]
            dvi = dx * v[i, 0] + dy * v[i, 1] + dz * v[i, 2]
            dvj = dx * v[j, 0] + dy * v[j, 1] + dz * v[j, 2]
            common = -k[4] * vivj
            inv3 = inv * inv * inv
            if src[j]:  # j acts on i
                f = gm[j] * inv3
                rv = dvj * inv
                bracket = (-k[0] * phi[i] - k[1] * phi[j] + k[2] * vi2 + k[3] * vj2 + common
                           - 1.5 * ic2 * rv * rv
                           + 0.5 * ic2 * (dx * acc_n[j, 0] + dy * acc_n[j, 1] + dz * acc_n[j, 2]))
                sv = -(k[5] * dvi - k[6] * dvj) * f * ic2
                g = k_aj * gm[j] * inv
                fb = f * bracket
                corr[i, 0] += fb * dx + sv * (v[i, 0] - v[j, 0]) + g * acc_n[j, 0]
                corr[i, 1] += fb * dy + sv * (v[i, 1] - v[j, 1]) + g * acc_n[j, 1]
                corr[i, 2] += fb * dz + sv * (v[i, 2] - v[j, 2]) + g * acc_n[j, 2]
            if src[i]:  # i acts on j: the same with r_i - r_j = -d
                f = gm[i] * inv3
                rv = dvi * inv
                bracket = (-k[0] * phi[j] - k[1] * phi[i] + k[2] * vj2 + k[3] * vi2 + common
                           - 1.5 * ic2 * rv * rv
                           - 0.5 * ic2 * (dx * acc_n[i, 0] + dy * acc_n[i, 1] + dz * acc_n[i, 2]))
                sv = (k[5] * dvj - k[6] * dvi) * f * ic2
                g = k_aj * gm[i] * inv
                fb = -f * bracket
                corr[j, 0] += fb * dx + sv * (v[j, 0] - v[i, 0]) + g * acc_n[i, 0]
                corr[j, 1] += fb * dy + sv * (v[j, 1] - v[i, 1]) + g * acc_n[i, 1]
                corr[j, 2] += fb * dz + sv * (v[j, 2] - v[i, 2]) + g * acc_n[i, 2]
    for i in range(n):
        acc[i, 0] += acc_n[i, 0] + corr[i, 0]
        acc[i, 1] += acc_n[i, 1] + corr[i, 1]
        acc[i, 2] += acc_n[i, 2] + corr[i, 2]


@njit(cache=True)
def lense_thirring(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The Lense-Thirring (gravitomagnetic) field of one rotating body, ADDED to ``acc``.

    ``p = [b, c, gamma, Jx, Jy, Jz]``: ``J`` the body's spin angular momentum per unit
    mass (length^2/time).  With ``d``, ``w`` a body's position and velocity relative
    to ``b`` and ``mu = gm[b]`` (IERS Conventions 2010, eq. 10.12),

        a = (1 + gamma) mu / (c^2 |d|^3) [3 / |d|^2 (d x w)(d . J) + w x J];

    ``b`` receives ``-(gm_i / mu) a``.
    """
    b = int(p[0])
    f0 = (1.0 + p[2]) * gm[b] / (p[1] * p[1])
    jx = p[3]
    jy = p[4]
    jz = p[5]
    for i in range(r.shape[0]):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        wx = v[i, 0] - v[b, 0]
        wy = v[i, 1] - v[b, 1]
        wz = v[i, 2] - v[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        f = f0 / (d2 * np.sqrt(d2))
        g = 3.0 * (dx * jx + dy * jy + dz * jz) / d2
        ax = f * (g * (dy * wz - dz * wy) + (wy * jz - wz * jy))
        ay = f * (g * (dz * wx - dx * wz) + (wz * jx - wx * jz))
        az = f * (g * (dx * wy - dy * wx) + (wx * jy - wy * jx))
        back = gm[i] / gm[b]
        acc[i, 0] += ax
        acc[i, 1] += ay
        acc[i, 2] += az
        acc[b, 0] -= back * ax
        acc[b, 1] -= back * ay
        acc[b, 2] -= back * az
