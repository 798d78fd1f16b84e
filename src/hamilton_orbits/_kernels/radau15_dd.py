"""radau15 in double-double arithmetic: a reference for the 1e-12 to 1e-14 regime.

The same Gauss-Radau predictor-corrector as :mod:`hamilton_orbits._kernels.radau15`
(Everhart 1985; Rein & Spiegel 2015, eqs. 4-7), at fixed steps, with every
number a double-double ``hi + lo`` (about 32 significant digits; Dekker 1971,
the algorithms of Hida, Li & Bailey's QD library, "Algorithms for quad-double
precision floating point arithmetic", 2001, without fused multiply-add): the
state, the ``b`` and ``g`` coefficients, the Newtonian accelerations (Hamilton's
equation (B)) and every constant.  Rounding then no longer limits what two runs
can agree on: in double precision two IAS15 runs at 0.25- and 0.5-day steps
differ by 4.4e-11 after 1000 years of the solar system (Brouwer's law); here
the truncation error of the 15th-order scheme is what is left, and it falls as
``dt^16``.

A double-double array has a last axis of 2 (``[..., 0]`` the high part,
``[..., 1]`` the low part).  The iteration stops when ``max |delta b6| / max
|a|`` falls below 1e-26, stops decreasing, or after 24 rounds.  The predictor of
``b`` (Rein & Spiegel 2015, section 2.5) runs in double precision: it only
starts the iteration, whose converged value does not depend on it.  No astropy
here; Newtonian gravity only.
"""

from __future__ import annotations

import decimal
from fractions import Fraction

import numpy as np
from numba import njit

from hamilton_orbits._kernels.gauss_radau import exact_tables

__all__ = ["advance", "constants", "spacings"]

_SPLIT = 134217729.0  # 2^27 + 1 (Dekker's splitting of a double into two halves)


def spacings(digits: int = 45) -> list[decimal.Decimal]:
    """The Gauss-Radau spacings ``0 = h_0 < h_1 < ... < h_7 < 1`` to ``digits``
    digits: the roots of ``P_7(2h - 1) + P_8(2h - 1)`` (``P_n`` Legendre), refined
    by Newton's method in decimal arithmetic from their 30-digit values.

    Examples
    --------
    >>> str(spacings()[1])[:34]
    '0.05626256053692214646565219103231'
    """
    from hamilton_orbits._kernels.radau15 import DECIMAL_SPACINGS

    legendre = [[Fraction(1)], [Fraction(0), Fraction(1)]]  # coefficients in x
    for n in range(1, 8):
        a, b = legendre[n], legendre[n - 1]
        nxt = [Fraction(0)] * (n + 2)
        for k, c in enumerate(a):
            nxt[k + 1] += Fraction(2 * n + 1, n + 1) * c
        for k, c in enumerate(b):
            nxt[k] -= Fraction(n, n + 1) * c
        legendre.append(nxt)
    px = [a + b for a, b in zip(legendre[7] + [Fraction(0)], legendre[8], strict=True)]
    # substitute x = 2h - 1 (Horner on polynomials)
    poly = [Fraction(0)]
    for c in reversed(px):
        new = [Fraction(0)] * (len(poly) + 1)
        for k, pk in enumerate(poly):
            new[k + 1] += 2 * pk
            new[k] -= pk
        new[0] += c
        poly = new
    with decimal.localcontext() as ctx:
        ctx.prec = digits + 10
        coef = [decimal.Decimal(c.numerator) / decimal.Decimal(c.denominator) for c in poly]
        dcoef = [k * c for k, c in enumerate(coef)][1:]
        out = [decimal.Decimal(0)]
        for start in DECIMAL_SPACINGS[1:]:
            h = decimal.Decimal(start)
            for _ in range(8):
                f = sum(c * h**k for k, c in enumerate(coef))
                df = sum(c * h**k for k, c in enumerate(dcoef))
                h -= f / df
            out.append(+h)
    return out


def _dd(x: decimal.Decimal | Fraction) -> tuple[float, float]:
    with decimal.localcontext() as ctx:
        ctx.prec = 60
        if isinstance(x, Fraction):
            x = decimal.Decimal(x.numerator) / decimal.Decimal(x.denominator)
        hi = float(x)
        return hi, float(x - decimal.Decimal(hi))


def constants() -> dict[str, np.ndarray]:
    """The scheme's constants as double-double arrays (last axis 2): spacings
    ``h`` (8,), reciprocal differences ``rinv`` (8, 8), ``c`` (b from g) and ``d``
    (g from b) (7, 7), the Horner factors ``kx`` (8, 7) of the positions at each
    spacing, and the accepted step's factors ``ax``, ``av`` (7,) (position and
    velocity weights of ``b_k``)."""
    with decimal.localcontext() as ctx:
        ctx.prec = 60
        h = spacings()
        hf = [Fraction(x) for x in h]
    out = {"h": np.array([_dd(x) for x in hf])}
    recip, c, d = exact_tables(hf)
    out["rinv"] = np.array([[_dd(x) for x in row] for row in recip])
    out["c"] = np.array([[_dd(x) for x in row] for row in c])
    out["d"] = np.array([[_dd(x) for x in row] for row in d])
    # positions at h: (((b6 k8 + b5) k7 + ... + b0) k2 + a0) ..., k_j = (j - 1) h / (j + 1)
    out["kx"] = np.array([[_dd(Fraction(j - 1, j + 1) * x) for j in range(8, 1, -1)] for x in hf])
    out["ax"] = np.array([_dd(Fraction(1, (k + 2) * (k + 3))) for k in range(7)])
    out["av"] = np.array([_dd(Fraction(1, k + 2)) for k in range(7)])
    return out


_K = constants()
_H, _RINV, _C, _D, _KX, _AX, _AV = (_K[k] for k in ("h", "rinv", "c", "d", "kx", "ax", "av"))


# --------------------------------------------------------------- arithmetic
# (plain calls, not ``inline="always"``: numba-IR inlining of these at their hundreds
# of sites was most of :func:`advance`'s compilation, 6.2-7.5 s against 2.9 s; LLVM
# inlines the calls, so the steps take the same time)
@njit(cache=True)
def _two_sum(a, b):  # pragma: no cover - compiled
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@njit(cache=True)
def _quick(a, b):  # pragma: no cover - compiled
    s = a + b
    return s, b - (s - a)


@njit(cache=True)
def _two_prod(a, b):  # pragma: no cover - compiled
    p = a * b
    t = _SPLIT * a
    ah = t - (t - a)
    al = a - ah
    t = _SPLIT * b
    bh = t - (t - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@njit(cache=True)
def _add(ah, al, bh, bl):  # pragma: no cover - compiled
    """Double-double sum (the accurate form: both low parts carried)."""
    s, e = _two_sum(ah, bh)
    t, f = _two_sum(al, bl)
    e += t
    s, e = _quick(s, e)
    e += f
    return _quick(s, e)


@njit(cache=True)
def _mul(ah, al, bh, bl):  # pragma: no cover - compiled
    p, e = _two_prod(ah, bh)
    e += ah * bl + al * bh
    return _quick(p, e)


@njit(cache=True, inline="always")
def _div(ah, al, bh, bl):  # pragma: no cover - compiled
    """Long division, three quotient digits."""
    q1 = ah / bh
    ph, pl = _mul(q1, 0.0, bh, bl)
    rh, rl = _add(ah, al, -ph, -pl)
    q2 = rh / bh
    ph, pl = _mul(q2, 0.0, bh, bl)
    rh, rl = _add(rh, rl, -ph, -pl)
    q3 = rh / bh
    q1, q2 = _quick(q1, q2)
    return _add(q1, q2, q3, 0.0)


@njit(cache=True, inline="always")
def _sqrt(ah, al):  # pragma: no cover - compiled
    """Karp and Markstein's square root: one Newton correction of the double one."""
    if ah <= 0.0:
        return 0.0, 0.0
    x = 1.0 / np.sqrt(ah)
    ax = ah * x
    sh, sl = _mul(ax, 0.0, ax, 0.0)
    rh, _ = _add(ah, al, -sh, -sl)
    return _two_sum(ax, rh * (x * 0.5))


# --------------------------------------------------------------- the force
@njit(cache=True)
def accel(x, gm, a):  # pragma: no cover - compiled
    """Newtonian accelerations (Hamilton's equation (B)) of positions ``x``
    (n, 3, 2) into ``a`` (n, 3, 2), in double-double (``gm`` (n,) exact doubles)."""
    n = x.shape[0]
    a[:, :, :] = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            if gm[i] == 0.0 and gm[j] == 0.0:
                continue
            dx0, dx1 = _add(x[j, 0, 0], x[j, 0, 1], -x[i, 0, 0], -x[i, 0, 1])
            dy0, dy1 = _add(x[j, 1, 0], x[j, 1, 1], -x[i, 1, 0], -x[i, 1, 1])
            dz0, dz1 = _add(x[j, 2, 0], x[j, 2, 1], -x[i, 2, 0], -x[i, 2, 1])
            s0, s1 = _mul(dx0, dx1, dx0, dx1)
            p0, p1 = _mul(dy0, dy1, dy0, dy1)
            s0, s1 = _add(s0, s1, p0, p1)
            p0, p1 = _mul(dz0, dz1, dz0, dz1)
            s0, s1 = _add(s0, s1, p0, p1)
            r0, r1 = _sqrt(s0, s1)
            c0, c1 = _mul(s0, s1, r0, r1)
            f0, f1 = _div(1.0, 0.0, c0, c1)  # 1 / d^3
            _pull(a, i, j, f0, f1, gm[i], gm[j], dx0, dx1, 0)
            _pull(a, i, j, f0, f1, gm[i], gm[j], dy0, dy1, 1)
            _pull(a, i, j, f0, f1, gm[i], gm[j], dz0, dz1, 2)


@njit(cache=True, inline="always")
def _pull(a, i, j, f0, f1, gi, gj, d0, d1, k):  # pragma: no cover - compiled
    """Component ``k`` of the pair's pulls: ``a_i += gm_j d / r^3``, ``a_j -= gm_i d / r^3``."""
    t0, t1 = _mul(f0, f1, d0, d1)
    u0, u1 = _mul(t0, t1, gj, 0.0)
    a[i, k, 0], a[i, k, 1] = _add(a[i, k, 0], a[i, k, 1], u0, u1)
    u0, u1 = _mul(t0, t1, gi, 0.0)
    a[j, k, 0], a[j, k, 1] = _add(a[j, k, 0], a[j, k, 1], -u0, -u1)


# --------------------------------------------------------------- the step
@njit(cache=True, inline="always")
def _positions(ns, dt, b, a0, x, v, xs):  # pragma: no cover - compiled
    """Positions at spacing ``ns`` (Rein & Spiegel 2015, eq. 6, Horner form)."""
    dth0, dth1 = _mul(dt, 0.0, _H[ns, 0], _H[ns, 1])
    for k in range(x.shape[0]):
        p0, p1 = b[6, k, 0], b[6, k, 1]
        for j in range(6):  # ... * k_(8-j) + b_(5-j)
            p0, p1 = _mul(p0, p1, _KX[ns, j, 0], _KX[ns, j, 1])
            p0, p1 = _add(p0, p1, b[5 - j, k, 0], b[5 - j, k, 1])
        p0, p1 = _mul(p0, p1, _KX[ns, 6, 0], _KX[ns, 6, 1])
        p0, p1 = _add(p0, p1, a0[k, 0], a0[k, 1])
        p0, p1 = _mul(p0, p1, 0.5 * dth0, 0.5 * dth1)  # exact halving
        p0, p1 = _add(p0, p1, v[k, 0], v[k, 1])
        p0, p1 = _mul(p0, p1, dth0, dth1)
        xs[k, 0], xs[k, 1] = _add(p0, p1, x[k, 0], x[k, 1])


@njit(cache=True, inline="always")
def _correct(ns, at, a0, g, b):  # pragma: no cover - compiled
    """Update ``g[ns - 1]`` from the acceleration at spacing ``ns`` and carry the
    change into ``b``; returns ``max |delta g|`` (high parts)."""
    j = ns - 1
    worst = 0.0
    for k in range(at.shape[0]):
        g0, g1 = _add(at[k, 0], at[k, 1], -a0[k, 0], -a0[k, 1])
        for i in range(j):
            g0, g1 = _mul(g0, g1, _RINV[ns, i, 0], _RINV[ns, i, 1])
            g0, g1 = _add(g0, g1, -g[i, k, 0], -g[i, k, 1])
        g0, g1 = _mul(g0, g1, _RINV[ns, j, 0], _RINV[ns, j, 1])
        e0, e1 = _add(g0, g1, -g[j, k, 0], -g[j, k, 1])
        g[j, k, 0], g[j, k, 1] = g0, g1
        for i in range(j):
            c0, c1 = _mul(_C[i, j, 0], _C[i, j, 1], e0, e1)
            b[i, k, 0], b[i, k, 1] = _add(b[i, k, 0], b[i, k, 1], c0, c1)
        b[j, k, 0], b[j, k, 1] = _add(b[j, k, 0], b[j, k, 1], e0, e1)
        worst = max(worst, abs(e0))
    return worst


@njit(cache=True, inline="always")
def _g_from_b(b, g):  # pragma: no cover - compiled
    for k in range(b.shape[1]):
        for j in range(7):
            s0, s1 = b[j, k, 0], b[j, k, 1]
            for i in range(j + 1, 7):
                p0, p1 = _mul(_D[j, i, 0], _D[j, i, 1], b[i, k, 0], b[i, k, 1])
                s0, s1 = _add(s0, s1, p0, p1)
            g[j, k, 0], g[j, k, 1] = s0, s1


@njit(cache=True, inline="always")
def _accept(dt, b, a0, x, v):  # pragma: no cover - compiled
    """``x += dt v + dt^2 (a0/2 + sum b_k / ((k+2)(k+3)))``, ``v += dt (a0 + sum
    b_k / (k+2))``, in double-double."""
    for k in range(x.shape[0]):
        px0, px1 = 0.0, 0.0
        pv0, pv1 = 0.0, 0.0
        for i in range(6, -1, -1):
            t0, t1 = _mul(b[i, k, 0], b[i, k, 1], _AX[i, 0], _AX[i, 1])
            px0, px1 = _add(px0, px1, t0, t1)
            t0, t1 = _mul(b[i, k, 0], b[i, k, 1], _AV[i, 0], _AV[i, 1])
            pv0, pv1 = _add(pv0, pv1, t0, t1)
        px0, px1 = _add(px0, px1, 0.5 * a0[k, 0], 0.5 * a0[k, 1])
        pv0, pv1 = _add(pv0, pv1, a0[k, 0], a0[k, 1])
        px0, px1 = _mul(px0, px1, dt, 0.0)
        px0, px1 = _add(px0, px1, v[k, 0], v[k, 1])
        px0, px1 = _mul(px0, px1, dt, 0.0)
        x[k, 0], x[k, 1] = _add(x[k, 0], x[k, 1], px0, px1)
        pv0, pv1 = _mul(pv0, pv1, dt, 0.0)
        v[k, 0], v[k, 1] = _add(v[k, 0], v[k, 1], pv0, pv1)


@njit(cache=True, inline="always")
def _predict(q, b, br, d):  # pragma: no cover - compiled
    """The start of the iteration, in double precision, for a step ``q`` times the
    last one (``q = 0``: no step before, start from zero): the last step's ``b``
    carried over (Rein & Spiegel 2015, section 2.5) plus its difference ``d`` from
    its own prediction.  The prediction's high parts are left in ``br`` for the
    next ``d``.  (Only the start: the converged ``b`` does not depend on it.)"""
    q2 = q * q
    q3 = q2 * q
    q4 = q2 * q2
    for k in range(b.shape[1]):
        b0, b1, b2, b3 = br[0, k], br[1, k], br[2, k], br[3, k]
        b4, b5, b6 = br[4, k], br[5, k], br[6, k]
        e = (q * (7.0 * b6 + 6.0 * b5 + 5.0 * b4 + 4.0 * b3 + 3.0 * b2 + 2.0 * b1 + b0),
             q2 * (21.0 * b6 + 15.0 * b5 + 10.0 * b4 + 6.0 * b3 + 3.0 * b2 + b1),
             q3 * (35.0 * b6 + 20.0 * b5 + 10.0 * b4 + 4.0 * b3 + b2),
             q4 * (35.0 * b6 + 15.0 * b5 + 5.0 * b4 + b3),
             q4 * q * (21.0 * b6 + 6.0 * b5 + b4),
             q3 * q3 * (7.0 * b6 + b5),
             q4 * q3 * b6)
        for i in range(7):
            br[i, k] = e[i]
            b[i, k, 0] = e[i] + d[i, k] if q > 0.0 else 0.0
            b[i, k, 1] = 0.0


@njit(cache=True, nogil=True)
def advance(x, v, gm, dt, n_steps, b, g, br, d, q):  # pragma: no cover - compiled
    """``n_steps`` fixed steps of ``dt`` from ``x``, ``v`` ((n, 3, 2) double-double,
    updated in place); ``b``, ``g`` (7, 3n, 2) and ``br``, ``d`` (7, 3n) carry the
    iteration from step to step; ``q``: ``dt`` over the step before this call's
    first (0 if none).  Returns the largest number of iteration rounds a step
    took.  Releases the GIL (two runs go side by side on two cores)."""
    n = x.shape[0]
    m = 3 * n
    xf, vf = x.reshape((m, 2)), v.reshape((m, 2))
    a0 = np.empty((n, 3, 2))
    at = np.empty((n, 3, 2))
    xs = np.empty((n, 3, 2))
    a0f, atf, xsf = a0.reshape((m, 2)), at.reshape((m, 2)), xs.reshape((m, 2))
    most = 0
    for s in range(n_steps):
        accel(x, gm, a0)
        qs = q if s == 0 else 1.0
        _predict(qs if qs <= 20.0 else 0.0, b, br, d)  # q > 20: from zero, as radau15
        _g_from_b(b, g)
        err, err_last, rounds = 2.0, 3.0, 0
        while err >= 1e-26 and rounds < 24 and not (rounds > 2 and err_last <= err):
            err_last = err
            rounds += 1
            for ns in range(1, 8):
                _positions(ns, dt, b, a0f, xf, vf, xsf)
                accel(xs, gm, at)
                worst = _correct(ns, atf, a0f, g, b)
            scale = 0.0
            for k in range(m):
                scale = max(scale, abs(atf[k, 0]))
            err = worst / scale if scale > 0.0 else 0.0
        most = max(most, rounds)
        _accept(dt, b, a0f, xf, vf)
        for i in range(7):
            for k in range(m):
                d[i, k] = b[i, k, 0] - br[i, k]
                br[i, k] = b[i, k, 0]
    return most
