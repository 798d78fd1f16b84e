"""The compiled step of the drift-kick-drift leapfrog (driver:
:mod:`hamilton_orbits.integrators.leapfrog`)."""

from __future__ import annotations

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels.signatures import ACCEL_TYPE, F1, F2

__all__ = ["advance"]


# explicit signature with ``accel`` as a first-class function type: compiled once
# and loaded from the cache in later processes, whatever the right-hand side
@njit(types.int64(ACCEL_TYPE, F1, F2, F2, F1, types.float64, types.float64, types.float64),
      cache=True, error_model="numpy")
def advance(accel, p, r, v, gm, t0, t1, dt):  # pragma: no cover - compiled
    """Steps of at most ``dt`` from ``t0`` to exactly ``t1`` (the steps equal, the
    count rounded up), each ``r += h/2 v; v += h a(r); r += h/2 v``, in place.
    Returns the number of steps."""
    n_steps = int(np.ceil((t1 - t0) / dt - 1e-12))
    if n_steps < 1:
        n_steps = 1
    h = (t1 - t0) / n_steps
    acc = np.empty_like(r)
    n = r.shape[0]
    for _ in range(n_steps):
        for i in range(n):
            for k in range(3):
                r[i, k] += 0.5 * h * v[i, k]
        accel(r, v, gm, acc, p)
        for i in range(n):
            for k in range(3):
                v[i, k] += h * acc[i, k]
                r[i, k] += 0.5 * h * v[i, k]
    return n_steps
