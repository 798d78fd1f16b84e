"""The Gauss-Radau scheme's tables in exact rationals (Everhart 1985; Rein & Spiegel
2015, eqs. 4-5), from which :mod:`hamilton_orbits._kernels.radau15` rounds its
double constants once and :mod:`hamilton_orbits._kernels.radau15_dd` its
double-double ones.

A table computed in floating point would carry its rounding into every step as a
systematic error; computed exactly and rounded once, each constant is the nearest
representable value.

References
----------
E. Everhart, "An efficient integrator that uses Gauss-Radau spacings", in *Dynamics
of Comets: Their Origin and Evolution*, IAU Colloq. 83, 185 (1985).
H. Rein, D. S. Spiegel, "IAS15: a fast, adaptive, high-order integrator for
gravitational dynamics", MNRAS 446, 1424 (2015).
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

__all__ = ["exact_tables"]

Table = list[list[Fraction]]


def exact_tables(h: Sequence[Fraction]) -> tuple[Table, Table, Table]:
    """The reciprocal differences ``1 / (h_n - h_i)`` (8 x 8, zero for ``i >= n``)
    and the matrices ``C`` (b = C g) and ``D = C^-1`` (g = D b) (7 x 7), exactly,
    from the eight spacings ``h`` (``h[0] = 0``).

    ``C[k][j]`` is the coefficient of ``h^(k+1)`` in ``prod_{m=0..j} (h - h_m)``
    (Rein & Spiegel 2015, eq. 5 expanded into eq. 4).

    Examples
    --------
    >>> recip, c, d = exact_tables([Fraction(k, 8) for k in range(8)])
    >>> recip[1][0], c[0][0], d[0][0]
    (Fraction(8, 1), Fraction(1, 1), Fraction(1, 1))
    >>> all(sum(c[i][m] * d[m][j] for m in range(7)) == (i == j)
    ...     for i in range(7) for j in range(7))
    True
    """
    recip = [[Fraction(0)] * 8 for _ in range(8)]
    for n in range(1, 8):
        for i in range(n):
            recip[n][i] = 1 / (h[n] - h[i])
    c = [[Fraction(0)] * 7 for _ in range(7)]
    for j in range(7):
        poly = [Fraction(1)]  # coefficients, lowest order first
        for m in range(j + 1):
            new = [Fraction(0)] * (len(poly) + 1)
            for p, coef in enumerate(poly):
                new[p] -= h[m] * coef
                new[p + 1] += coef
            poly = new
        for k in range(j + 1):
            c[k][j] = poly[k + 1]
    d = [[Fraction(0)] * 7 for _ in range(7)]
    for j in range(7):
        d[j][j] = Fraction(1)
        for k in range(j - 1, -1, -1):
            d[k][j] = -sum((c[k][m] * d[m][j] for m in range(k + 1, j + 1)), Fraction(0))
    return recip, c, d
