"""Non-gravitational accelerations of comets and asteroids, as an effect kernel.

:func:`nongrav` has the effect signature ``f(r, v, gm, acc, p)`` and ADDS its
acceleration to ``acc``.  Marsden, Sekanina & Yeomans (1973), AJ 78, 211, eq. (1)
and (2): relative to the centre (the Sun),

    a = g(r) (A1 r^ + A2 t^ + A3 n^),   g(r) = alpha (r / r0)^-m (1 + (r / r0)^n)^-k,

``r^`` outward, ``n^`` along ``r x v``, ``t^ = n^ x r^`` (in the orbit's plane, in
the direction of motion).  The force is the body's own (outgassing, radiation
recoil): nothing acts back on the centre.  No astropy here.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def nongrav(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Marsden-Sekanina-Yeomans accelerations of some bodies, ADDED to ``acc``.

    ``p = [c, m_bodies, then per body: index, A1, A2, A3, alpha, r0, m, n, k]``
    (``c`` the centre's index).  Where ``r x v`` vanishes (a radial path) the
    transverse and normal directions are undefined and only ``A1`` acts.
    """
    c = int(p[0])
    for j in range(int(p[1])):
        q = 2 + 9 * j
        b = int(p[q])
        dx = r[b, 0] - r[c, 0]
        dy = r[b, 1] - r[c, 1]
        dz = r[b, 2] - r[c, 2]
        wx = v[b, 0] - v[c, 0]
        wy = v[b, 1] - v[c, 1]
        wz = v[b, 2] - v[c, 2]
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
        x = d / p[q + 5]
        g = p[q + 4] * x ** (-p[q + 6]) * (1.0 + x ** p[q + 7]) ** (-p[q + 8])
        f1 = g * p[q + 1] / d
        ax = f1 * dx
        ay = f1 * dy
        az = f1 * dz
        hx = dy * wz - dz * wy
        hy = dz * wx - dx * wz
        hz = dx * wy - dy * wx
        h = np.sqrt(hx * hx + hy * hy + hz * hz)
        if h > 0.0:
            f3 = g * p[q + 3] / h
            ax += f3 * hx
            ay += f3 * hy
            az += f3 * hz
            f2 = g * p[q + 2] / (h * d)  # t^ = (h x d) / (|h| |d|)
            ax += f2 * (hy * dz - hz * dy)
            ay += f2 * (hz * dx - hx * dz)
            az += f2 * (hx * dy - hy * dx)
        acc[b, 0] += ax
        acc[b, 1] += ay
        acc[b, 2] += az
