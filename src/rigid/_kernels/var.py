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


@njit(cache=True)
def spd_solve(a, b):  # pragma: no cover - compiled
    """Solve ``a x = b`` in place for a symmetric positive-definite ``a`` (Cholesky).

    ``a``: (n, n), overwritten by its Cholesky factor; ``b``: (n, k), overwritten by
    ``x``.  Returns 0, or the 1-based index of the first non-positive pivot (``a`` not
    positive definite; ``b`` is then left partly solved).  Compiled loops on one
    thread: a multithreaded LAPACK call of this size stalls on a loaded 2-core machine.
    """
    n = a.shape[0]
    k = b.shape[1]
    for j in range(n):
        s = a[j, j]
        for m in range(j):
            s -= a[j, m] * a[j, m]
        if not s > 0.0:
            return j + 1
        d = s**0.5
        a[j, j] = d
        for i in range(j + 1, n):
            s = a[i, j]
            for m in range(j):
                s -= a[i, m] * a[j, m]
            a[i, j] = s / d
    for c in range(k):  # forward: L y = b; back: L^T x = y
        for i in range(n):
            s = b[i, c]
            for m in range(i):
                s -= a[i, m] * b[m, c]
            b[i, c] = s / a[i, i]
        for i in range(n - 1, -1, -1):
            s = b[i, c]
            for m in range(i + 1, n):
                s -= a[m, i] * b[m, c]
            b[i, c] = s / a[i, i]
    return 0
