"""Hamilton's n-body equation (B) as compiled kernels on plain floats.

Hamilton (1845), equation (B): each body's acceleration is the sum over the
others of ``M_j (alpha_j - alpha_i) / T(alpha_j - alpha_i)^3``.  Here ``gm[j]``
stands for Hamilton's ``M_j`` (G times the mass) and positions are rows of
``r``.  Bodies with ``gm == 0`` are massless test particles: they feel every
massive body and pull on none, so each costs O(n_massive).

Acceleration kernels share one signature, ``accel(r, v, gm, acc)``: ``r`` and
``v`` of shape (n, 3), ``gm`` of shape (n,), all float64, and ``acc`` (n, 3) is
overwritten.  Effect kernels have the same signature but *add* into ``acc``.
No astropy here.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def massive_indices(gm):  # pragma: no cover - compiled
    """Indices of the bodies with ``gm != 0``, in order."""
    n = gm.shape[0]
    idx = np.empty(n, dtype=np.int64)
    nm = 0
    for k in range(n):
        if gm[k] != 0.0:
            idx[nm] = k
            nm += 1
    return idx[:nm]


@njit(cache=True)
def newtonian(r, v, gm, acc):  # pragma: no cover - compiled
    """Newtonian accelerations of equation (B); overwrites ``acc``.

    Massive pairs are visited once (both accelerations from one separation);
    test particles are summed over the massive bodies only.
    """
    n = r.shape[0]
    for k in range(n):
        acc[k, 0] = 0.0
        acc[k, 1] = 0.0
        acc[k, 2] = 0.0
    idx = massive_indices(gm)
    nm = idx.shape[0]
    for a in range(nm):
        i = idx[a]
        for b in range(a + 1, nm):
            j = idx[b]
            dx = r[j, 0] - r[i, 0]
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            d2 = dx * dx + dy * dy + dz * dz
            inv3 = 1.0 / (d2 * np.sqrt(d2))
            fi = gm[j] * inv3
            fj = gm[i] * inv3
            acc[i, 0] += fi * dx
            acc[i, 1] += fi * dy
            acc[i, 2] += fi * dz
            acc[j, 0] -= fj * dx
            acc[j, 1] -= fj * dy
            acc[j, 2] -= fj * dz
    if nm == n:
        return
    for k in range(n):
        if gm[k] != 0.0:
            continue
        ax = 0.0
        ay = 0.0
        az = 0.0
        for a in range(nm):
            i = idx[a]
            dx = r[i, 0] - r[k, 0]
            dy = r[i, 1] - r[k, 1]
            dz = r[i, 2] - r[k, 2]
            d2 = dx * dx + dy * dy + dz * dz
            f = gm[i] / (d2 * np.sqrt(d2))
            ax += f * dx
            ay += f * dy
            az += f * dz
        acc[k, 0] = ax
        acc[k, 1] = ay
        acc[k, 2] = az
