"""The symplectic correctors of the Wisdom-Holman map in Jacobi coordinates.

Wisdom, Holman & Touma (1996), with the orders WHFast offers (Rein & Tamayo 2015):
the coefficients of the corrector of order 3, 5, 7, 11 or 17, computed here in
exact rational arithmetic (:func:`corrector_coefficients`) and applied by
:func:`hamilton_orbits._kernels.wh.corrector_jacobi` (see the notes of
:mod:`hamilton_orbits.integrators.wh`).
"""

from __future__ import annotations

import decimal
import functools
import math
from fractions import Fraction

import numpy as np

from hamilton_orbits.integrators.methods import WH_CORRECTORS

__all__ = ["CORRECTORS", "CORRECTOR_ALPHA_SQUARED", "corrector_coefficients",
           "corrector_series"]


#: The symplectic correctors' orders (Wisdom, Holman & Touma 1996; Rein & Tamayo 2015).
CORRECTORS = WH_CORRECTORS


#: The spacing of the correctors' Kepler drifts, ``a_k = k alpha dt`` with
#: ``alpha = sqrt(7/40)`` (Wisdom, Holman & Touma 1996; Rein & Tamayo 2015).
CORRECTOR_ALPHA_SQUARED = Fraction(7, 40)


def corrector_series(k_max: int) -> list[Fraction]:
    """The coefficients ``g_0, g_2, ..., g_{2 k_max}`` of ``(z/2) / sinh(z/2) =
    sum_k g_{2k} z^{2k}``, exactly.

    The Wisdom-Holman kernel ``K = exp(h/2 A) exp(h eps B) exp(h/2 A)`` is, to first
    order in ``eps``, ``exp(h A + eps h g(h ad_A) B)`` with ``g(z) = (z/2) /
    sinh(z/2)`` (the symmetric Baker-Campbell-Hausdorff formula), so its error
    terms linear in ``eps`` are ``eps h^(2k+1) g_{2k} ad_A^(2k) B``, ``k >= 1``.

    Examples
    --------
    >>> corrector_series(2)
    [Fraction(1, 1), Fraction(-1, 24), Fraction(7, 5760)]
    """
    # 1 / (sinh(z/2) / (z/2)), the series in w = z^2 inverted term by term
    s = [Fraction(1, math.factorial(2 * k + 1) * 4**k) for k in range(k_max + 1)]
    g = [Fraction(1)]
    for k in range(1, k_max + 1):
        g.append(-sum((s[j] * g[k - j] for j in range(1, k + 1)), Fraction(0)))
    return g


@functools.cache
def corrector_coefficients(order: int) -> tuple[np.ndarray, np.ndarray]:
    """The drifts and kicks ``(a, b)`` (in units of the step) of the symplectic
    corrector of ``order`` 3, 5, 7, 11 or 17, as the sequence of ``Z(a_k, b_k)``
    that :func:`hamilton_orbits._kernels.wh.corrector_jacobi` applies.

    Construction (Wisdom, Holman & Touma 1996, section 3; the orders of Rein &
    Tamayo 2015, section 4.1): the corrector ``C = exp(eps W)`` turns the kernel
    into ``C K C^-1``, whose error terms linear in ``eps`` vanish through
    ``eps h^p`` when ``ad_A W = g(h ad_A) B - B`` holds through ``h^p``
    (:func:`corrector_series`), i.e. ``W = sum_k g_{2k} h^{2k} ad_A^(2k-1) B``,
    ``k = 1 .. m``, ``m = (order - 1) / 2``.  ``Z(a, b)`` (Kepler ``a``, kick
    ``-b``, Kepler ``-2a``, kick ``b``, Kepler ``a``) is ``exp(-2 b eps sum_{odd
    n} a^n / n! ad_A^n B)`` to first order in ``eps``; the sequence ``(a_m, b_m)
    ... (a_1, b_1), (-a_1, -b_1) ... (-a_m, -b_m)`` with ``a_i = i alpha``
    therefore needs

        sum_i b_i (i alpha)^n = -n! g_{n+1} / 4,      n = 1, 3, ..., 2m - 1,

    a Vandermonde system in ``i^2`` solved here in rationals (``b_i alpha`` is
    rational because ``alpha^2 = 7/40`` is) and rounded once.  The sequence
    reversed with ``a`` negated is itself with ``b`` negated, so the corrector
    with ``-b`` is its exact inverse.  The values agree with rebound's
    ``reb_whfast_corrector_b_*`` to the last digit of a double.

    Raises
    ------
    ValueError
        For an order other than 3, 5, 7, 11, 17.

    Examples
    --------
    >>> a, b = corrector_coefficients(3)
    >>> a.tolist() == [math.sqrt(7 / 40), -math.sqrt(7 / 40)]
    True
    >>> float(b[0])  # 1 / (96 alpha) = sqrt(10/7) / 48 = 0.02490059602779986749...
    0.024900596027799867
    """
    if order not in CORRECTORS or order == 0:
        raise ValueError(f"Expected a corrector order in 3, 5, 7, 11, 17, got {order!r}")
    m = (order - 1) // 2
    g = corrector_series(m)
    ns = [2 * j + 1 for j in range(m)]
    # c_i = b_i alpha: sum_i c_i i^n = -n! g_{n+1} / (4 alpha^(n-1))
    rows = [[Fraction(i) ** n for i in range(1, m + 1)]
            + [-math.factorial(n) * g[(n + 1) // 2] / (4 * CORRECTOR_ALPHA_SQUARED ** (n // 2))]
            for n in ns]
    for col in range(m):  # Gauss-Jordan elimination, exact
        pivot = rows[col][col]
        rows[col] = [x / pivot for x in rows[col]]
        for r in range(m):
            if r != col and rows[r][col] != 0:
                f = rows[r][col]
                rows[r] = [x - f * y for x, y in zip(rows[r], rows[col], strict=True)]
    with decimal.localcontext() as ctx:
        ctx.prec = 40
        alpha = (decimal.Decimal(CORRECTOR_ALPHA_SQUARED.numerator)
                 / decimal.Decimal(CORRECTOR_ALPHA_SQUARED.denominator)).sqrt()
        c = [decimal.Decimal(row[m].numerator) / decimal.Decimal(row[m].denominator)
             for row in rows]
        a_half = [float(i * alpha) for i in range(m, 0, -1)]
        b_half = [float(c[i - 1] / alpha) for i in range(m, 0, -1)]
    a = np.array(a_half + [-x for x in reversed(a_half)])
    b = np.array(b_half + [-x for x in reversed(b_half)])
    return a, b
