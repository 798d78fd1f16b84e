"""The linear recursion of the exact Liouville propagator (plain complex floats)."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def linear_recurrence(a, b, x0, out):  # pragma: no cover - compiled
    """``out[0] = x0``, ``out[k+1] = a[k] out[k] + b[k]`` (complex128 arrays)."""
    out[0] = x0
    for k in range(a.size):
        out[k + 1] = a[k] * out[k] + b[k]
