"""The vector autoregressive recursion (plain floats): forecasts and impulse responses."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def var_recursion(coef, hist, out):  # pragma: no cover - compiled
    """Continue ``z_k = sum_i coef[i] @ z_{k-1-i}`` from the past values ``hist``.

    ``coef``: (p, d, d); ``hist``: (p, d), oldest first (``hist[-1]`` is the newest);
    ``out``: (steps, d), filled with ``z`` at the next ``steps`` epochs.
    """
    p, d = hist.shape
    steps = out.shape[0]
    for k in range(steps):
        for r in range(d):
            acc = 0.0
            for i in range(p):
                back = k - 1 - i  # index into out if >= 0, else into hist
                for c in range(d):
                    z = out[back, c] if back >= 0 else hist[p + back, c]
                    acc += coef[i, r, c] * z
            out[k, r] = acc
