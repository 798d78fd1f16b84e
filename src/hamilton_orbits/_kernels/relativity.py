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
No astropy here.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def newtonian_and_potential(r, gm, acc_n, phi, inv_d):  # pragma: no cover - compiled
    """Overwrite ``acc_n`` (n, 3) with the Newtonian accelerations, ``phi`` (n,) with
    the Newtonian potentials ``sum_{k != i} gm_k / r_ik`` and ``inv_d`` (n, n) with the
    inverse distances (pairs of massless bodies left out)."""
    n = r.shape[0]
    for i in range(n):
        acc_n[i, 0] = 0.0
        acc_n[i, 1] = 0.0
        acc_n[i, 2] = 0.0
        phi[i] = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            if gm[i] == 0.0 and gm[j] == 0.0:
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


@njit(cache=True)
def eih(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Newtonian plus first post-Newtonian accelerations (Moyer 2003, eq. 4-26), ADDED
    to ``acc``.  ``p = [c, beta, gamma, j_1, j_2, ...]`` (c in the system's units of
    speed): the post-Newtonian terms of the sources ``j_1, j_2, ...`` (every massive
    body when none is given); every other massive body acts by Newton's law alone,
    on every body."""
    ic2 = 1.0 / (p[0] * p[0])
    beta = p[1]
    gamma = p[2]
    n = r.shape[0]
    acc_n = np.empty((n, 3))
    phi = np.empty(n)
    inv_d = np.empty((n, n))
    newtonian_and_potential(r, gm, acc_n, phi, inv_d)
    for i in range(n):
        acc[i, 0] += acc_n[i, 0]
        acc[i, 1] += acc_n[i, 1]
        acc[i, 2] += acc_n[i, 2]
    k_phi_i = 2.0 * (beta + gamma)
    k_phi_j = 2.0 * beta - 1.0
    k_vj = 1.0 + gamma
    k_vivj = 2.0 * (1.0 + gamma)
    k_wi = 2.0 + 2.0 * gamma
    k_wj = 1.0 + 2.0 * gamma
    k_aj = 0.5 * (3.0 + 4.0 * gamma)
    n_src = p.shape[0] - 3 if p.shape[0] > 3 else n
    src = np.empty(n_src, dtype=np.int64)
    for b in range(n_src):
        src[b] = int(p[3 + b]) if p.shape[0] > 3 else b
    for i in range(n):
        vix = v[i, 0]
        viy = v[i, 1]
        viz = v[i, 2]
        vi2 = vix * vix + viy * viy + viz * viz
        cx = 0.0
        cy = 0.0
        cz = 0.0
        for b in range(n_src):
            j = src[b]
            if j == i or gm[j] == 0.0:
                continue
            dx = r[j, 0] - r[i, 0]  # r_j - r_i
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            inv = inv_d[i, j]
            f = gm[j] * inv * inv * inv
            vjx = v[j, 0]
            vjy = v[j, 1]
            vjz = v[j, 2]
            vj2 = vjx * vjx + vjy * vjy + vjz * vjz
            vivj = vix * vjx + viy * vjy + viz * vjz
            rvj = (dx * vjx + dy * vjy + dz * vjz) * inv  # -(r_i - r_j) . v_j / r_ij
            raj = dx * acc_n[j, 0] + dy * acc_n[j, 1] + dz * acc_n[j, 2]
            bracket = (-k_phi_i * phi[i] - k_phi_j * phi[j] + gamma * vi2 + k_vj * vj2
                       - k_vivj * vivj - 1.5 * rvj * rvj + 0.5 * raj) * ic2
            s = -(dx * (k_wi * vix - k_wj * vjx) + dy * (k_wi * viy - k_wj * vjy)
                  + dz * (k_wi * viz - k_wj * vjz)) * f * ic2
            g = k_aj * gm[j] * inv * ic2
            cx += f * bracket * dx + s * (vix - vjx) + g * acc_n[j, 0]
            cy += f * bracket * dy + s * (viy - vjy) + g * acc_n[j, 1]
            cz += f * bracket * dz + s * (viz - vjz) + g * acc_n[j, 2]
        acc[i, 0] += cx
        acc[i, 1] += cy
        acc[i, 2] += cz


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
