"""Chebyshev series of JPL's SPK type-2 segments, evaluated compiled.

A type-2 segment (NAIF, *SPK Required Reading*, "Type 2: Chebyshev (position
only)") cuts time into records of equal length ``intlen`` from ``init``; record
``k`` holds, per component, the coefficients ``c_0 ... c_{m-1}`` of
``x(s) = sum c_j T_j(s)`` on ``s = 2 (t - t_k) / intlen - 1`` in [-1, 1], and the
velocity is ``dx/dt = (2 / intlen) sum j c_j U_{j-1}(s)`` (``T_j' = j U_{j-1}``;
the Chebyshev polynomials of the first and second kinds by their three-term
recurrences, stable on [-1, 1]).  Times are TDB Julian dates split in two,
``jd1 + jd2``, so that the offset into the segment keeps its digits.  No astropy
here.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def add_states(coef, init, intlen, jd1, jd2, out):  # pragma: no cover - compiled
    """ADD one segment's states at the times ``jd1 + jd2`` (n_t,) to ``out`` (n_t, 6):
    position (the segment's unit) and velocity (that unit per day).

    ``coef`` (3, n, m): the coefficients of each component in each of ``n`` records
    of ``intlen`` days from the Julian date ``init``.  Returns the index of the first
    time outside the segment (its states left alone), or -1.
    """
    m = coef.shape[2]
    t = np.empty(m)
    u = np.empty(m)
    for i in range(jd1.shape[0]):
        if not add_state(coef, init, intlen, jd1[i], jd2[i], out[i], t, u):
            return i
    return -1


@njit(cache=True, inline="always")
def add_state(coef, init, intlen, jd1, jd2, out, t, u):  # pragma: no cover - compiled
    """ADD one segment's state at the time ``jd1 + jd2`` to ``out`` (6,) (as
    :func:`add_states`, ``t``, ``u`` work space of the coefficients' length); False,
    ``out`` left alone, for a time outside the segment."""
    n, m = coef.shape[1], coef.shape[2]
    k = basis(init, intlen, n, jd1, jd2, m, t, u)
    if k < 0:
        return False
    add_record(coef, k, intlen, t, u, out)
    return True


@njit(cache=True, inline="always")
def _record(init, intlen, n, jd1, jd2):  # pragma: no cover - compiled
    """The record ``k`` of a segment of ``n`` records of ``intlen`` days from
    ``init`` that holds the time ``jd1 + jd2`` (-1 outside the segment) and the
    time's ``s`` in it, in [-1, 1]."""
    d = (jd1 - init) + jd2
    k = int(np.floor(d / intlen))
    if k == n and d <= n * intlen:  # (the segment's last instant)
        k = n - 1
    if k < 0 or k >= n or not np.isfinite(d):
        return -1, 0.0
    return k, 2.0 * (d - k * intlen) / intlen - 1.0


@njit(cache=True, inline="always")
def basis(init, intlen, n, jd1, jd2, m, t, u):  # pragma: no cover - compiled
    """The record ``k`` of a segment of ``n`` records of ``intlen`` days from
    ``init`` that holds the time ``jd1 + jd2`` (-1 outside the segment), and the
    Chebyshev polynomials ``T_j(s)``, ``U_j(s)``, ``j < m``, at its ``s`` into
    ``t``, ``u`` (the same for every segment of the same ``init`` and ``intlen``)."""
    k, s = _record(init, intlen, n, jd1, jd2)
    if k < 0:
        return -1
    t[0] = 1.0
    u[0] = 1.0
    if m > 1:
        t[1] = s
        u[1] = 2.0 * s
    for j in range(2, m):
        t[j] = 2.0 * s * t[j - 1] - t[j - 2]
        u[j] = 2.0 * s * u[j - 1] - u[j - 2]
    return k


@njit(cache=True, inline="always")
def add_record(coef, k, intlen, t, u, out):  # pragma: no cover - compiled
    """ADD record ``k`` of ``coef`` (3, n, m) at the polynomials ``t``, ``u`` of
    :func:`basis` to ``out`` (6,): position, and velocity per day."""
    m = coef.shape[2]
    for c in range(3):
        x = 0.0
        dx = 0.0
        for j in range(m - 1, -1, -1):  # (small terms first)
            x += coef[c, k, j] * t[j]
            if j > 0:
                dx += j * coef[c, k, j] * u[j - 1]
        out[c] += x
        out[3 + c] += dx * 2.0 / intlen


@njit(cache=True, inline="always")
def acceleration_basis(init, intlen, n, jd1, jd2, m, u, du):  # pragma: no cover - compiled
    """As :func:`basis` for the second derivative: the record ``k`` (-1 outside the
    segment), the ``U_j(s)`` into ``u`` and their derivatives ``U_j'(s)`` into
    ``du`` (``U_j' = 2 U_(j-1) + 2 s U_(j-1)' - U_(j-2)'``, from ``U_j = 2 s
    U_(j-1) - U_(j-2)``), ``j < m``."""
    k, s = _record(init, intlen, n, jd1, jd2)
    if k < 0:
        return -1
    u[0] = 1.0
    du[0] = 0.0
    if m > 1:
        u[1] = 2.0 * s
        du[1] = 2.0
    for j in range(2, m):
        u[j] = 2.0 * s * u[j - 1] - u[j - 2]
        du[j] = 2.0 * u[j - 1] + 2.0 * s * du[j - 1] - du[j - 2]
    return k


@njit(cache=True, inline="always")
def add_record_acceleration(coef, k, intlen, du, out):  # pragma: no cover - compiled
    """ADD record ``k``'s acceleration (the unit per day^2) at the derivatives ``du``
    of :func:`acceleration_basis` to ``out`` (3,): ``d2x/dt2 = (2 / intlen)^2 sum
    j c_j U_(j-1)'(s)`` (``T_j'' = j U_(j-1)'``)."""
    m = coef.shape[2]
    scale = (2.0 / intlen) ** 2
    for c in range(3):
        ddx = 0.0
        for j in range(m - 1, 1, -1):  # (small terms first; T_0'' = T_1'' = 0)
            ddx += j * coef[c, k, j] * du[j - 1]
        out[c] += ddx * scale
