"""Compiled kernels: Kepler's equation, anomalies, universal-variable propagation.

Plain floats only (nothing here imports astropy).  Conventions, by eccentricity:

* ``e < 1``  anomaly = eccentric anomaly E,   M = E - e sin E;
* ``e == 1`` anomaly = parabolic anomaly D = tan(nu/2),  M = D + D^3/3 (Barker);
* ``e > 1``  anomaly = hyperbolic anomaly F,  M = e sinh F - F.

With periapsis distance q and gravitational parameter mu the time since
periapsis is ``t = M / n`` with ``n = sqrt(mu / |a|^3)`` for ``e != 1`` and
``n = sqrt(mu / (2 q^3))`` for the parabola (Barker's equation
``sqrt(mu/p^3) t = (D + D^3/3)/2`` with ``p = 2q``).

Every M(anomaly) is evaluated without cancellation by the splittings
``E - e sin E = (1-e) E + e (E - sin E)`` and
``e sinh F - F = (e-1) sinh F + (sinh F - F)``, both a sum of two terms of the
same sign, with ``E - sin E`` and ``sinh F - F`` summed as series near zero.

Scalar kernels signal failure (no convergence, argument outside the domain) by
returning NaN; the public layer turns that into an exception naming the index.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from hamilton_orbits._kernels._dispatch import lazy_vectorize, parallel_kernel

EPS = 2.220446049250313e-16
PI = math.pi
# 2 pi = TWO_PI_HI + TWO_PI_LO to about 1e-32 (Cody-Waite reduction).
TWO_PI_HI = 6.283185307179586
TWO_PI_LO = 2.4492935982947064e-16
MAXIT = 100

# 1/(2k+3)!, k = 0..14: coefficients of x - sin x and sinh x - x = sum x^(2k+3)/(2k+3)!
_S = tuple(1.0 / math.factorial(2 * k + 3) for k in range(15))
# 1/(2k+2)!, k = 0..9: coefficients of c2(psi) = sum (-psi)^k/(2k+2)!  (|psi| < 1)
_C = tuple(1.0 / math.factorial(2 * k + 2) for k in range(10))
# below this |x|, x - sin x and sinh x - x are summed as series: at |x| = 3 the
# 15th term is 3^31/31! ~ 8e-20 of the sum, and above it the direct forms lose
# at most a factor (x + |sin x|)/(x - sin x) < 1.4 (sinh: < 1.9)
_SERIES_MAX = 3.0


# ---------------------------------------------------------------------------
# cancellation-free pieces
# ---------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _series_s(z, sign):  # pragma: no cover - compiled
    """sum_k (sign z)^k / (2k+3)!  (Horner; 15 terms, 7 when |z| < 0.1 where
    the 8th is below 0.1^7/17! ~ 3e-22 of the sum, 5 when |z| < 0.01 (the 6th:
    6e-12/13! ~ 1e-19) and 4 when |z| < 1e-3 (the 5th: 6e-12/11! ~ 2e-19); the
    short sums serve the small psi of a Wisdom-Holman step)."""
    az = abs(z)
    top = (3 if az < 1e-3 else 4) if az < 0.01 else (6 if az < 0.1 else 14)
    acc = _S[top]
    for k in range(top - 1, -1, -1):
        acc = _S[k] + sign * z * acc
    return acc


@njit(cache=True)
def x_minus_sin(x):  # pragma: no cover - compiled
    """``x - sin x`` to full relative precision (series for |x| < 3)."""
    if abs(x) >= _SERIES_MAX:
        return x - math.sin(x)
    z = x * x
    return x * z * _series_s(z, -1.0)


@njit(cache=True)
def sinh_minus_x(x):  # pragma: no cover - compiled
    """``sinh x - x`` to full relative precision (series for |x| < 3)."""
    if abs(x) >= _SERIES_MAX:
        return math.sinh(x) - x
    z = x * x
    return x * z * _series_s(z, 1.0)


@njit(cache=True)
def _reduce_2pi(x):  # pragma: no cover - compiled
    """Return ``(k, r)`` with ``x = 2 pi k + r`` and ``-pi < r <= pi`` (Cody-Waite).

    The rounded quotient can pick the neighbouring k at a tie: ``x = pi`` (the
    float, just below pi) gave ``k = 1, r = -pi - 1.2e-16``, beyond -pi; such an r
    is moved back into range with the other k."""
    k = math.floor(x / TWO_PI_HI + 0.5)
    r = (x - k * TWO_PI_HI) - k * TWO_PI_LO
    if r < -PI:
        k -= 1.0
        r = (x - k * TWO_PI_HI) - k * TWO_PI_LO
    elif r > PI:
        k += 1.0
        r = (x - k * TWO_PI_HI) - k * TWO_PI_LO
    return k, r


@njit(cache=True)
def two_prod(a, b):  # pragma: no cover - compiled
    """Dekker's exact product: ``a * b = p + err`` exactly (no overflow assumed)."""
    p = a * b
    c = 134217729.0 * a
    ah = c - (c - a)
    al = a - ah
    c = 134217729.0 * b
    bh = c - (c - b)
    bl = b - bh
    err = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, err


@njit(cache=True, inline="always")
def _two_sum(a, b):  # pragma: no cover - compiled
    """Knuth's exact sum: ``a + b = s + err`` exactly."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@njit(cache=True, inline="always")
def _ulp(x):  # pragma: no cover - compiled
    """The spacing of the floats at ``x`` (``2^(exponent - 52)``; 0 at 0)."""
    return math.ldexp(1.0, math.frexp(x)[1] - 53) if x != 0.0 else 0.0


# ---------------------------------------------------------------------------
# Kepler's equation and the anomalies
# ---------------------------------------------------------------------------


@njit(cache=True)
def mean_from_anomaly(anom, e):  # pragma: no cover - compiled
    """Mean anomaly M from the eccentric / parabolic / hyperbolic anomaly.

    Elliptic ``M = (1-e) E + e (E - sin E)``; parabolic (``e == 1``)
    ``M = D + D^3/3``; hyperbolic ``M = (e-1) sinh F + (sinh F - F)``.
    """
    if e < 1.0:
        if abs(anom) >= 9007199254740992.0:  # 2^53: |M - E| <= e < 1 <= half a spacing
            return anom
        k, r = _reduce_2pi(anom)
        m = (1.0 - e) * r + e * x_minus_sin(r)
        if k == 0.0:
            return m
        return k * TWO_PI_HI + (m + k * TWO_PI_LO)
    if e == 1.0:
        return anom * (1.0 + anom * anom / 3.0)
    return (e - 1.0) * math.sinh(anom) + sinh_minus_x(anom)


@njit(cache=True)
def anomaly_from_nu(nu, e):  # pragma: no cover - compiled
    """Eccentric / parabolic / hyperbolic anomaly from the true anomaly ``nu``.

    Half-angle forms: ``tan(E/2) = sqrt((1-e)/(1+e)) tan(nu/2)`` evaluated as an
    atan2 (the revolution count of ``nu`` is kept); ``D = tan(nu/2)``;
    ``tanh(F/2) = sqrt((e-1)/(e+1)) tan(nu/2)``.  For ``e >= 1`` a ``nu`` beyond
    the asymptote (``1 + e cos nu <= 0``) gives NaN.
    """
    if e >= 1.0 and not abs(nu) < 9007199254740992.0:
        return math.nan  # no open orbit's nu is resolved beyond 2^53 (refused)
    if e < 1.0 and abs(nu) >= 9007199254740992.0:
        # beyond 2^53 the floats are >= 2 apart: no revolution can be resolved and
        # E (within pi of nu, same revolution) is nu to the input's precision
        return nu
    k, r = _reduce_2pi(nu)
    h = 0.5 * r
    if e < 1.0:
        a = 2.0 * math.atan2(math.sqrt(1.0 - e) * math.sin(h), math.sqrt(1.0 + e) * math.cos(h))
        if k == 0.0:
            return a
        return k * TWO_PI_HI + (a + k * TWO_PI_LO)
    # open orbits: nu must lie strictly inside (-nu_inf, nu_inf)
    s = math.sin(h)
    c = math.cos(h)
    if e == 1.0:
        if c <= 0.0 or abs(r) >= PI:
            return math.nan
        return s / c
    # tanh(F/2) = sqrt(e-1) sin(h) / (sqrt(e+1) cos(h)); must be < 1 in magnitude
    num = math.sqrt(e - 1.0) * s
    den = math.sqrt(e + 1.0) * c
    if not (abs(num) < den):
        return math.nan
    return 2.0 * math.atanh(num / den)


@njit(cache=True)
def nu_from_anomaly(anom, e):  # pragma: no cover - compiled
    """True anomaly from the eccentric / parabolic / hyperbolic anomaly.

    ``nu = 2 atan2(sqrt(1+e) sin(E/2), sqrt(1-e) cos(E/2))`` (revolution count
    kept); ``nu = 2 atan(D)``; ``nu = 2 atan2(sqrt(e+1) tanh(F/2), sqrt(e-1))``
    (no overflow for any finite F).
    """
    if e < 1.0:
        if abs(anom) >= 9007199254740992.0:  # 2^53: as in anomaly_from_nu
            return anom
        k, r = _reduce_2pi(anom)
        h = 0.5 * r
        a = 2.0 * math.atan2(math.sqrt(1.0 + e) * math.sin(h), math.sqrt(1.0 - e) * math.cos(h))
        if k == 0.0:
            return a
        return k * TWO_PI_HI + (a + k * TWO_PI_LO)
    if e == 1.0:
        return 2.0 * math.atan(anom)
    return 2.0 * math.atan2(math.sqrt(e + 1.0) * math.tanh(0.5 * anom), math.sqrt(e - 1.0))


@njit(cache=True)
def _cubic_root(p, q):  # pragma: no cover - compiled
    """The real root of ``x^3 + 3 p x - 2 q = 0`` for ``p > 0``, ``q >= 0``.

    ``x = 2 sqrt(p) sinh(asinh(q / p^(3/2)) / 3)``: no cancellation for any q.
    """
    sp = math.sqrt(p)
    d = p * sp
    if not (q < 1e100 * d):
        # p -> 0 (e -> 1 in the callers, or p * sp underflows): x = (2 q)^(1/3),
        # the limit of the form below (relative difference ~ (q/d)^(-2/3))
        return np.cbrt(2.0 * q)
    return 2.0 * sp * math.sinh(math.asinh(q / d) / 3.0)


@njit(inline="always", cache=True)
def _halley_step(x, xp, f, fp, fpp, a, b):  # pragma: no cover - compiled
    """One safeguarded Halley step for an increasing convex/concave f in [a, b].

    Shrinks the bracket with the sign of f, takes the Halley step (Newton if its
    denominator is not positive), bisects if the step leaves the bracket, and
    reports convergence: a step of a few ulp, a bracket of a few ulp, or a
    2-cycle between neighbouring floats (the residual is at its rounding floor).
    """
    if f < 0.0:
        a = x
    else:
        b = x
    den = fp * fp - 0.5 * f * fpp
    if den > 0.0:
        xn = x - f * fp / den
    else:
        xn = x - f / fp
    if not (a <= xn <= b):
        xn = 0.5 * (a + b)
    done = abs(xn - x) <= 4.0 * EPS * abs(xn) or b - a <= 8.0 * EPS * abs(b) or xn == xp
    return xn, a, b, done


@njit(cache=True)
def _solve_elliptic(m, e):  # pragma: no cover - compiled
    """E in [0, pi] with E - e sin E = m, for 0 <= m <= pi, 0 < e < 1.

    Safeguarded Halley iteration on the convex function
    f(E) = (1-e) E + e (E - sin E) - m inside the bracket [lo, hi]: lo is the
    larger of m and the root of the cubic (1-e) E + e E^3/6 = m (both lower
    bounds, as E - sin E <= E^3/6 and E = m + e sin E >= m); hi = min(m + e, pi).
    """
    if m == 0.0:
        return 0.0
    om = 1.0 - e
    lo = m
    if e > 0.1:  # the cubic matters near e = 1; for tiny e its p overflows
        lo = max(m, _cubic_root(2.0 * om / e, 3.0 * m / e))
    hi = m + e
    if m <= PI and hi > PI:
        hi = PI
    if lo > hi:
        lo = hi
    a = lo * (1.0 - 4.0 * EPS)  # the rounded cubic root may lie an ulp above E
    b = hi
    x = lo
    xp = math.nan
    for _ in range(MAXIT):
        sx = math.sin(x)
        sh = math.sin(0.5 * x)
        f = om * x + e * x_minus_sin(x) - m
        if f == 0.0:
            return x
        fp = om + 2.0 * e * sh * sh
        fpp = e * sx
        xn, a, b, done = _halley_step(x, xp, f, fp, fpp, a, b)
        if done:
            return xn
        xp = x
        x = xn
    return math.nan


@njit(cache=True)
def _solve_hyperbolic(m, e):  # pragma: no cover - compiled
    """F >= 0 with e sinh F - F = m, for m >= 0, e > 1.

    Safeguarded Halley iteration on the convex f(F) = (e-1) sinh F +
    (sinh F - F) - m.  Bracket: lo = asinh((m + asinh(m/e))/e) (two steps of
    the fixed point F = asinh((m + F)/e) from below, good for large m); hi is
    the smaller of asinh(m/(e-1)) and the root of (e-1) F + e F^3/6 = m (upper
    bounds since sinh F >= F + F^3/6), good near F = 0 and e near 1.
    """
    if m == 0.0:
        return 0.0
    em = e - 1.0
    f1 = math.asinh(m / e)
    lo = math.asinh((m + f1) / e)
    if m > 1e20:
        # F = asinh((m + F)/e) contracts by 1/(m + F) < 1e-20 per step: lo is two
        # steps from F = 0, one more is F to rounding (and no sinh can overflow)
        return math.asinh((m + lo) / e)
    hi = _cubic_root(2.0 * em / e, 3.0 * m / e)
    if em > 0.0:
        hi = min(math.asinh(m / em), hi)
    if m > 2.5:
        # sinh F - F >= sinh(F)/2 for F >= 2.2 (the root, as m > 2.26): the
        # bound that keeps the radial orbit's (e = 1) cubic bound from overflowing
        hi = min(math.asinh(2.0 * m), hi)
    if hi < lo:
        hi = lo
    flo = f1 - lo  # f(lo) up to rounding, <= 0
    fhi = sinh_minus_x(hi) - m
    if em > 0.0:  # (em = 0: the radial orbit, whose cubic bound may overflow sinh)
        fhi += em * math.sinh(hi)
    a = lo
    b = hi * (1.0 + 4.0 * EPS)  # the rounded cubic root may lie an ulp below F
    x = lo if abs(flo) <= abs(fhi) else hi
    xp = math.nan
    for _ in range(MAXIT):
        sx = math.sinh(x)
        sh = math.sinh(0.5 * x)
        f = em * sx + sinh_minus_x(x) - m
        if f == 0.0:
            return x
        fp = em + 2.0 * e * sh * sh
        fpp = e * sx
        if e > 1e100:  # f / e has the same root and Halley step; fp^2 cannot overflow
            f /= e
            fp /= e
            fpp /= e
        xn, a, b, done = _halley_step(x, xp, f, fp, fpp, a, b)
        if done:
            return xn
        xp = x
        x = xn
    return math.nan


@njit(cache=True)
def _nearest_elliptic(x, m, e):  # pragma: no cover - compiled
    """The float nearest the root of ``E - e sin E = m`` from ``x`` within a few ulp of it.

    The solver's convergence test stops within a few ulp, and reassembling
    ``2 pi k + E`` rounds twice: up to 1.8 ulp off (Tudat's random test found 1 in
    2000 draws past its 1e-15 bound, and M = pi at e = 0.48 gave E one ulp beyond
    pi, past apoapsis).  One Newton step on the residual computed with exact
    products and sums (``x - m - e sin x``, or ``(1-e) x + e (x - sin x) - m``
    for |x| < 3, whichever has the smaller rounding bound), rounded once when
    added to ``x``: within 0.7 ulp of the root (correctly rounded but within a
    fraction of an ulp of a midpoint).  Where that bound is not below half the
    residual's change over one ulp (E near 0 with e near 1: f' = 1 - e cos E
    tiny) ``x`` is kept as the solver left it.
    """
    if x == 0.0:
        return x
    h = math.sin(0.5 * x)
    fp = (1.0 - e) + 2.0 * e * h * h
    s = math.sin(x)
    err_sin = e * _ulp(s)
    om = 1.0 - e
    w = 0.0
    err_xms = math.inf
    if abs(x) < _SERIES_MAX:
        w = x_minus_sin(x)
        err_xms = 2.0 * e * _ulp(w) + (0.0 if e >= 0.5 else _ulp(om) * abs(x))
    if min(err_sin, err_xms) > 0.5 * fp * _ulp(x):
        return x
    if err_xms < err_sin:
        a, al = two_prod(om, x)
        b, bl = two_prod(e, w)
        c, cl = _two_sum(a, b)
        f = (c - m) + (cl + al + bl)
    else:
        d, dl = _two_sum(x, -m)
        p, pl = two_prod(e, s)
        f = (d - p) + (dl - pl)
    return x - f / fp


@njit(cache=True)
def solve_parabolic(m):  # pragma: no cover - compiled
    """Barker: the real root D of D + D^3/3 = m, in closed form.

    ``D = 2 sinh(asinh(3 m / 2) / 3)`` (Cardano's root written without the
    cancellation of ``w - 1/w``), then one Newton polish.
    """
    if abs(m) > 1e300:  # 1.5 m may overflow; D^3 = 3 m to 1e-200 relative here
        return np.cbrt(3.0) * np.cbrt(m)
    d = 2.0 * math.sinh(math.asinh(1.5 * m) / 3.0)
    if abs(d) < 1e100:
        d -= (d * (1.0 + d * d / 3.0) - m) / (1.0 + d * d)
    return d


@njit(cache=True)
def solve(m, e):  # pragma: no cover - compiled
    """The anomaly (E, D or F by ``e``) solving Kepler's equation for mean anomaly m.

    Elliptic M is reduced to [-pi, pi] (Cody-Waite) and the revolution count is
    added back, so E is monotone in M; the result is then rounded to the float
    nearest the root (:func:`_nearest_elliptic`).  NaN for e < 0 or no
    convergence.
    """
    if not (e >= 0.0) or not math.isfinite(m) or not math.isfinite(e):
        return math.nan
    if e < 1.0:
        if e == 0.0 or abs(m) >= 9007199254740992.0:
            # beyond 2^53 the spacing of floats is >= 2 > 2 e >= 2 |E - M|: M is
            # the float nearest to E (and no reduction mod 2 pi is meaningful)
            return m
        k, r = _reduce_2pi(m)
        if r < 0.0:
            x = -_solve_elliptic(-r, e)
        else:
            x = _solve_elliptic(r, e)
        if not math.isfinite(x):
            return x
        if k == 0.0:
            return _nearest_elliptic(x, r, e)
        return _nearest_elliptic(k * TWO_PI_HI + (x + k * TWO_PI_LO), m, e)
    if e == 1.0:
        return solve_parabolic(m)
    if m < 0.0:
        return -_solve_hyperbolic(-m, e)
    return _solve_hyperbolic(m, e)


@njit(cache=True)
def solve_radial(m, inv_a):  # pragma: no cover - compiled
    """The anomaly of a radial (rectilinear, e = 1) orbit for mean anomaly ``m``.

    Bound (``inv_a > 0``): E in [-pi, pi] with ``E - sin E = m`` for
    |m| <= pi, so that ``r = a (1 - cos E)``; unbound (``inv_a < 0``): F with
    ``sinh F - F = m``, ``r = |a| (cosh F - 1)``.  Solved directly (the
    limits e -> 1 of the elliptic and hyperbolic solvers, started from the
    cubic ``E^3/6 = m``), so a tiny m keeps full relative precision: the
    anomaly is ``(6 m)^(1/3)`` to first order.  NaN outside the domain.
    """
    if not math.isfinite(m) or not (inv_a != 0.0) or not math.isfinite(inv_a):
        return math.nan
    am = abs(m)
    if inv_a > 0.0:
        if am > PI:
            return math.nan
        x = _solve_elliptic(am, 1.0)
    else:
        x = _solve_hyperbolic(am, 1.0)
    return -x if m < 0.0 else x


@lazy_vectorize(["float64(float64, float64)"], cache=True)
def solve_radial_ufunc(m, inv_a):  # pragma: no cover - compiled
    """Broadcasting ufunc of :func:`solve_radial`."""
    return solve_radial(m, inv_a)


@lazy_vectorize(["float64(float64, float64)"], cache=True)
def solve_ufunc(m, e):  # pragma: no cover - compiled
    """Broadcasting ufunc of :func:`solve`."""
    return solve(m, e)


@lazy_vectorize(["float64(float64, float64)"], cache=True)
def mean_from_anomaly_ufunc(anom, e):  # pragma: no cover - compiled
    """Broadcasting ufunc of :func:`mean_from_anomaly`."""
    return mean_from_anomaly(anom, e)


@lazy_vectorize(["float64(float64, float64)"], cache=True)
def anomaly_from_nu_ufunc(nu, e):  # pragma: no cover - compiled
    """Broadcasting ufunc of :func:`anomaly_from_nu`."""
    return anomaly_from_nu(nu, e)


@lazy_vectorize(["float64(float64, float64)"], cache=True)
def nu_from_anomaly_ufunc(anom, e):  # pragma: no cover - compiled
    """Broadcasting ufunc of :func:`nu_from_anomaly`."""
    return nu_from_anomaly(anom, e)


# ---------------------------------------------------------------------------
# universal variables
# ---------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _stumpff_series(psi):  # pragma: no cover - compiled
    """``(c2, c3)`` by their power series, for |psi| < 1 (see :func:`stumpff_c2c3`)."""
    z = -psi
    # omitted terms relative to c2 = 1/2: 0.1^7/16! ~ 5e-21, 0.01^5/12! ~
    # 4e-19, 0.001^4/10! ~ 6e-19
    az = abs(z)
    top = (3 if az < 1e-3 else 4) if az < 0.01 else (6 if az < 0.1 else 9)
    c2 = _C[top]
    for k in range(top - 1, -1, -1):
        c2 = _C[k] + z * c2
    return c2, _series_s(psi, -1.0)


@njit(cache=True)
def stumpff_c2c3(psi):  # pragma: no cover - compiled
    """Stumpff functions ``c2(psi) = (1 - cos sqrt psi)/psi`` and
    ``c3(psi) = (sqrt psi - sin sqrt psi)/sqrt(psi)^3`` (continued to psi <= 0).

    Power series for |psi| < 1; otherwise ``2 sin^2(s/2)/psi`` and
    ``(s - sin s)/s^3`` (and their hyperbolic counterparts) with ``s - sin s``
    from :func:`x_minus_sin`, so there is no cancellation anywhere.
    """
    if abs(psi) < 1.0:
        return _stumpff_series(psi)
    if psi > 0.0:
        s = math.sqrt(psi)
        sh = math.sin(0.5 * s)
        return 2.0 * sh * sh / psi, x_minus_sin(s) / (psi * s)
    s = math.sqrt(-psi)
    sh = math.sinh(0.5 * s)
    return 2.0 * sh * sh / (-psi), sinh_minus_x(s) / (-psi * s)


@njit(cache=True, inline="always")
def _uv_from_stumpff(chi, chi2, psi, c2, c3, r0, sigma0, alpha):  # pragma: no cover
    """The tuple of :func:`_uv_eval` from ``c2(psi)``, ``c3(psi)``."""
    u0 = 1.0 - psi * c2
    u1 = chi * (1.0 - psi * c3)
    u2 = chi2 * c2
    u3 = chi2 * chi * c3
    t = r0 * u1 + sigma0 * u2 + u3
    r = r0 * u0 + sigma0 * u1 + u2
    rp = sigma0 * u0 + (1.0 - alpha * r0) * u1
    return t, r, rp, u0, u1, u2, u3


@njit(cache=True)
def _uv_eval(chi, r0, sigma0, alpha):  # pragma: no cover - compiled
    """Universal functions at ``chi``: (T(chi), r(chi), r'(chi), U0, U1, U2, U3).

    ``U0 = 1 - psi c2``, ``U1 = chi (1 - psi c3)``, ``U2 = chi^2 c2``,
    ``U3 = chi^3 c3``; ``T = r0 U1 + sigma0 U2 + U3`` (= sqrt(mu) t),
    ``r = r0 U0 + sigma0 U1 + U2`` (= dT/dchi) and
    ``r' = sigma0 U0 + (1 - alpha r0) U1``.
    """
    chi2 = chi * chi
    psi = alpha * chi2
    c2, c3 = stumpff_c2c3(psi)
    return _uv_from_stumpff(chi, chi2, psi, c2, c3, r0, sigma0, alpha)


@njit(cache=True, inline="always")
def _uv_eval_series(chi, r0, sigma0, alpha):  # pragma: no cover - compiled
    """:func:`_uv_eval` for ``|alpha chi^2| < 1`` (the Stumpff series only, no
    branch to the trigonometric forms; inlined into the short-step solver)."""
    chi2 = chi * chi
    psi = alpha * chi2
    c2, c3 = _stumpff_series(psi)
    return _uv_from_stumpff(chi, chi2, psi, c2, c3, r0, sigma0, alpha)


# Below this relative Halley step the universal functions are carried to the
# new point by their Taylor series to second order instead of being evaluated
# again: the omitted third-order terms and the error left by Halley's step (of
# order step^3) are below 1e-18 of each function.
_TAYLOR_STEP = 1e-6


@njit(cache=True, inline="always")
def _taylor_carry(xn, dx, u0, u1, u2, u3, r0, sigma0, alpha):  # pragma: no cover - compiled
    """``(xn, T, r, U0, U1, U2, U3)`` at ``xn = x + dx`` from the functions at ``x``
    by their second-order Taylor series (see :func:`_solve_uv_short`)."""
    h2 = 0.5 * dx * dx
    v0 = u0 - alpha * (dx * u1 + h2 * u0)
    v1 = u1 + dx * u0 - alpha * h2 * u1
    v2 = u2 + dx * u1 + h2 * u0
    v3 = u3 + dx * u2 + h2 * u1
    return xn, r0 * v1 + sigma0 * v2 + v3, r0 * v0 + sigma0 * v1 + v2, v0, v1, v2, v3


@njit(cache=True, inline="always")
def _solve_uv_short(tau, x, r0, sigma0, alpha):  # pragma: no cover - compiled
    """:func:`_solve_uv` for a short step from a first guess ``x`` on the right
    side of 0 (the reversed series): Halley's method, T being increasing and
    smooth there, at most 8 evaluations; chi = NaN if it does not settle (the
    caller then takes the bracketed solver).

    Convergence as in :func:`_solve_uv` (a step of at most 4 ulp with the
    residual at rounding level).  When the step is below ``_TAYLOR_STEP``
    relative, the point after it is not evaluated again: with
    ``U0' = -alpha U1``, ``U1' = U0``, ``U2' = U1``, ``U3' = U2`` the functions
    move to ``x + dx`` by their second-order Taylor series (the series guess of
    a Wisdom-Holman step of the planets is within 1e-8 of the root, so this
    saves the second evaluation that confirms it)."""
    nan = math.nan
    xp = nan
    for _ in range(8):
        if not (x * x * abs(alpha) < 1.0):
            break
        t, r, rp, u0, u1, u2, u3 = _uv_eval_series(x, r0, sigma0, alpha)
        f = t - tau
        if f == 0.0:
            return x, t, r, u0, u1, u2, u3
        # Halley: dx = -f / (T' - f T'' / (2 T'))  with T' = r, T'' = r'
        den = r * r - 0.5 * f * rp
        if not (den > 0.0 and r > 0.0):
            break
        dx = -f * r / den
        xn = x + dx
        if xn * x <= 0.0:
            break
        small = abs(dx) <= 4.0 * EPS * abs(xn)
        if small or xn == xp:
            if abs(f) <= 2.0 * EPS * abs(tau) or xn == xp:
                return x, t, r, u0, u1, u2, u3
        if small or abs(dx) <= _TAYLOR_STEP * abs(x):
            return _taylor_carry(xn, dx, u0, u1, u2, u3, r0, sigma0, alpha)
        xp = x
        x = xn
    return nan, nan, nan, nan, nan, nan, nan


@njit(cache=True, inline="always")
def _series_guess(tau, sgn, r0, sigma0, alpha):  # pragma: no cover - compiled
    """First guesses ``(x1, x, short)`` of the universal anomaly for :func:`_solve_uv`.

    ``x1 = tau / r0`` (a radial orbit anchored at the collision, ``r0 = 0``:
    ``x1 = (6 tau)^(1/3)``, as ``T ~ chi^3/6`` there) and ``x`` the reversed
    Taylor series of ``T(chi)``: with ``T/r0 = chi + c2 chi^2 + c3 chi^3 + c4
    chi^4 + c5 chi^5 + ...`` (``c2 = sigma0/(2 r0)``, ``c3 = (1 - alpha r0)/(6
    r0)``, ``c4 = -alpha sigma0/(24 r0)``, ``c5 = -alpha c3 / 20``) and ``y =
    tau/r0``: ``chi = y - c2 y^2 + (2 c2^2 - c3) y^3 + (5 c2 c3 - c4 - 5 c2^3)
    y^4 + (14 c2^4 - 21 c2^2 c3 + 6 c2 c4 + 3 c3^2 - c5) y^5 + O(y^6)``.  The
    fifth-order guess is within 3e-9 (Mercury) and 2e-10 (Venus..Mars) of the
    root for a 4-day step of the planets (the fourth-order one: 3e-6 and
    6e-9), so that the short-step solver needs one evaluation for each of them
    (the Wisdom-Holman drift); the second-order one is kept when the series is
    not small.  ``short``: the fifth-order guess is on the right side of 0 with
    ``|psi| < 1/4`` (Halley from it, :func:`_solve_uv_short`, without the
    bracket)."""
    if not (r0 * r0 * r0 > 0.0):  # (near-)radial orbit anchored at the collision
        x1 = sgn * (6.0 * abs(tau)) ** (1.0 / 3.0)
        return x1, x1, False
    x1 = tau / r0
    ir = 1.0 / r0
    c2 = 0.5 * sigma0 * ir
    # z^2 below 1 with z = |x1| (|sigma0|/r0 + sqrt(1/r0 + |alpha|))
    if not (2.0 * x1 * x1 * (4.0 * c2 * c2 + ir + abs(alpha)) < 1.0):
        return x1, x1 - c2 * x1 * x1, False
    x = _series_x(x1, ir, c2, r0, sigma0, alpha)
    return x1, x, x * sgn > 0.0 and x * x * abs(alpha) < 0.25


@njit(cache=True, inline="always")
def _series_x(x1, ir, c2, r0, sigma0, alpha):  # pragma: no cover - compiled
    """The fifth-order reversed series of :func:`_series_guess` at ``x1 = tau / r0``
    (``ir = 1 / r0``, ``c2 = sigma0 / (2 r0)``)."""
    c3 = (1.0 - alpha * r0) * ir * (1.0 / 6.0)
    c4 = -alpha * sigma0 * ir * (1.0 / 24.0)
    k3 = 2.0 * c2 * c2 - c3
    k4 = c2 * (5.0 * c3 - 5.0 * c2 * c2) - c4
    c5 = -alpha * c3 * (1.0 / 20.0)
    s2 = c2 * c2
    k5 = s2 * (14.0 * s2 - 21.0 * c3) + 6.0 * c2 * c4 + 3.0 * c3 * c3 - c5
    return x1 * (1.0 + x1 * (-c2 + x1 * (k3 + x1 * (k4 + x1 * k5))))


# A first guess of the bracketed solver within this factor of the cubic bound
# (_long_guess) is kept: from there Laguerre's ~2.7 per step costs at most ~90 of
# its 200 iterations (after at most ~40 bisections while T overflows, for a
# result whose |r|^2 fits a float), and the results settled from such guesses
# keep their bits
# (2^20 changed 1.5% of 2e5 random states by a few ulps, long parabolic steps;
# 2^128 changed 84 nearly radial ones, h < 1e-15 r v, ill-conditioned anyway).
_CAP_RATIO = 2.0**128


@njit(cache=True, inline="always")
def _long_guess(tau, sgn, x1, x, sigma0, alpha):  # pragma: no cover - compiled
    """The first guess of the bracketed solver: ``x`` from :func:`_series_guess`
    unless the step is long (``|x1| sqrt|alpha| > 1/2``) or ``x`` is on the wrong
    side of 0: then the mean-motion guess ``tau alpha`` (elliptic) or a
    logarithmic one (hyperbolic), else ``x1``.

    On an open orbit moving away from periapsis (``alpha <= 0``, ``sigma0 tau >=
    0``) all terms of T have the sign of tau and ``|U3| >= |chi|^3/6``, so the
    root lies within ``(6 |tau|)^(1/3)``; a guess more than :data:`_CAP_RATIO`
    times that bound is replaced by it.  ``x1 = tau/r0`` is far above the root
    on a very long parabolic step (1e102 at dt = 1e102, the root ~ 1e34), or from
    the tiny periapsis distance of a nearly radial orbit; T, r^2 or f r'
    overflowed there and the solver bisected, or Laguerre's step gained only a
    factor ~2.7 per iteration, until the iterations ran out."""
    if alpha > 0.0:
        if abs(x1) * math.sqrt(alpha) > 0.5 or x * sgn <= 0.0:
            x = tau * alpha
    elif alpha < 0.0:
        sa = math.sqrt(-alpha)
        if abs(x1) * sa > 0.5 or x * sgn <= 0.0:
            xm = sgn * math.asinh(abs(tau) * sa * sa * sa) / sa
            x = xm if abs(xm) < abs(x1) else x1
    else:
        if x * sgn <= 0.0:
            x = x1
    if x * sgn <= 0.0 or not math.isfinite(x):
        x = x1
    if alpha <= 0.0 and sigma0 * sgn >= 0.0:
        xc = (6.0 * abs(tau)) ** (1.0 / 3.0)  # (a guess: pow compiles faster than cbrt)
        if abs(x) > _CAP_RATIO * xc:
            x = sgn * xc
    return x


@njit(cache=True, inline="always")
def _solve_uv_bracketed(tau, sgn, x1, x, r0, sigma0, alpha):  # pragma: no cover - compiled
    """:func:`_solve_uv` by Laguerre's method inside a bracket, from the guess ``x``.

    The bracket starts as (0, chi_max) on the side of ``sgn`` with chi_max =
    2 pi/sqrt(alpha) for a bound orbit, else (0, inf), grown by doubling from
    ``max(|x|, |x1|)``; a step that leaves it is replaced by bisection.  A step
    below half an ulp of chi while the bracket is still open is convergence;
    where r^2 or f r' overflows Laguerre's step is formed in ratios, and a NaN
    T (terms that overflow) bounds the far end of the bracket."""
    big = 2.0 * PI / math.sqrt(alpha) if alpha > 0.0 else math.inf
    if sgn > 0.0:
        a = 0.0
        b = big
    else:
        a = -big
        b = 0.0
    if not (a < x < b):
        x = 0.5 * (a + b) if math.isfinite(b - a) else x1
    xp = math.nan
    for _ in range(MAXIT + 100):
        t, r, rp, u0, u1, u2, u3 = _uv_eval(x, r0, sigma0, alpha)
        f = t - tau
        if f == 0.0:
            return x, t, r, u0, u1, u2, u3
        if f < 0.0 or (sgn < 0.0 and not f > 0.0):
            # (a NaN T, the inf - inf or 0 inf of terms that overflow, puts x
            # beyond the root: it bounded the wrong end going backwards, where
            # the doubling then went on to chi^2 = inf, e.g. the parabola at dt = -1e155)
            a = x
        else:
            b = x
        # Laguerre, n = 5: dx = n f / (f' + sign(f') sqrt|(n-1)^2 f'^2 - n(n-1) f f''|)
        disc = math.sqrt(abs(16.0 * r * r - 20.0 * f * rp))
        if not math.isfinite(disc) and math.isfinite(f) and 0.0 < r < math.inf:
            # r^2 or f r' overflows (r beyond ~3e153): the same in ratios
            disc = r * math.sqrt(abs(16.0 - 20.0 * (f / r) * (rp / r)))
        den = r + disc if r >= 0.0 else r - disc
        if den != 0.0 and math.isfinite(den):
            xn = x - 5.0 * f / den
        else:
            xn = math.nan
        if xn == x and math.isinf(b - a):
            # the step is below half an ulp of chi: x is the root to the floats,
            # though at large chi r (an ulp of chi moves T by many ulps of tau)
            # its residual may exceed the 2 ulps tested below.  x bounds the
            # bracket now, so the step is not inside it, and with the bracket
            # still open the safeguard below would double away from the root
            # (to 2 tau/r0, where T overflows, and the bisection back used up the
            # iterations: e = 1 + 1e-6, dt = 1e15).  (A finite bracket's
            # bisection stays next to x and ends by the 8-ulp test.)
            return x, t, r, u0, u1, u2, u3
        if not (a < xn < b):
            if math.isinf(b):
                xn = 2.0 * max(abs(x), abs(x1))
            elif math.isinf(a):
                xn = -2.0 * max(abs(x), abs(x1))
            else:
                xn = 0.5 * (a + b)
        if abs(xn - x) <= 4.0 * EPS * abs(xn) or xn == xp:
            if abs(f) <= 2.0 * EPS * abs(tau) or xn == xp:
                return x, t, r, u0, u1, u2, u3
            # x is a few ulp from the root but that is a time error above
            # rounding (large chi r): use the refined point
            t, r, rp, u0, u1, u2, u3 = _uv_eval(xn, r0, sigma0, alpha)
            return xn, t, r, u0, u1, u2, u3
        if math.isfinite(b - a) and (b - a) <= 8.0 * EPS * max(abs(a), abs(b)):
            return x, t, r, u0, u1, u2, u3
        xp = x
        x = xn
    nan = math.nan
    return nan, nan, nan, nan, nan, nan, nan


@njit(cache=True)
def _solve_uv(tau, r0, sigma0, alpha):  # pragma: no cover - compiled
    """The universal anomaly chi with ``T(chi) = tau`` (``tau = sqrt(mu) dt``),
    returned with the universal functions evaluated there:
    ``(chi, T, r, U0, U1, U2, U3)``.

    T is increasing (dT/dchi = r >= 0).  A short step is solved by Halley's
    method from the reversed Taylor series (:func:`_series_guess`,
    :func:`_solve_uv_short`); otherwise, or if that does not settle, by
    Laguerre's method (n = 5, Conway 1986) inside a bracket
    (:func:`_solve_uv_bracketed`) from the guess of :func:`_long_guess`.  On
    convergence (a step of at most 4 ulp, a 2-cycle between neighbouring
    floats, or a bracket of 8 ulp) the last evaluated point is returned if its
    residual T - tau is already at rounding level (2 ulp of tau), which saves
    one evaluation; otherwise the refined point is evaluated.  chi = NaN on
    failure.
    """
    if tau == 0.0:
        return 0.0, 0.0, r0, 1.0, 0.0, 0.0, 0.0
    sgn = 1.0 if tau > 0.0 else -1.0
    x1, x, short = _series_guess(tau, sgn, r0, sigma0, alpha)
    if short:
        sol = _solve_uv_short(tau, x, r0, sigma0, alpha)
        if math.isfinite(sol[0]):
            return sol
    x = _long_guess(tau, sgn, x1, x, sigma0, alpha)
    return _solve_uv_bracketed(tau, sgn, x1, x, r0, sigma0, alpha)


@njit(cache=True)
def solve_universal(tau, r0, sigma0, alpha):  # pragma: no cover - compiled
    """The universal anomaly chi with ``T(chi) = tau``; NaN on failure (see
    :func:`_solve_uv`)."""
    return _solve_uv(tau, r0, sigma0, alpha)[0]


@njit(cache=True, inline="always")
def _g_first_form(tau, r0, sigma0, u1, u2, u3, r, dchi_err):  # pragma: no cover
    """Whether ``g sqrt(mu) = r0 U1 + sigma0 U2`` is expected more accurate than
    ``tau - U3`` (the two are equal by the universal Kepler equation): an error
    dchi moves the first by ``(r - U2) dchi`` and the second by ``U2 dchi``, and
    each carries the rounding of its own terms (the first cancels when moving
    towards periapsis from far out)."""
    e1 = abs(r - u2) * dchi_err + EPS * (abs(r0 * u1) + abs(sigma0 * u2))
    e2 = abs(u2) * dchi_err + EPS * (abs(tau) + abs(u3))
    return e1 <= e2


@njit(cache=True, inline="always")
def _reduce_period(dt, mu, smu, alpha):  # pragma: no cover - compiled
    """``dt`` of a bound orbit (``alpha > 0``) reduced modulo the period
    ``P = 2 pi / (sqrt(mu) alpha^1.5)`` with an exact (Dekker) product, when
    ``|dt| > P/2``; ``dt`` itself otherwise."""
    t = dt
    # |t| > P/2 is only possible when t^2 mu alpha^3 > pi^2 (tested below pi^2
    # and NaN-safe, without the root and the division that the period costs;
    # the exact test follows)
    if alpha > 0.0 and not (
        (t * alpha) * (t * alpha) * (mu * alpha) <= 0.2499 * TWO_PI_HI * TWO_PI_HI
    ):
        sa = math.sqrt(alpha)
        period = TWO_PI_HI / (smu * alpha * sa)
        if abs(t) > 0.5 * period:
            k = math.floor(t / period + 0.5)
            p, err = two_prod(k, period)
            t = (t - p) - err
    return t


@njit(cache=True, inline="always")
def _step_anchored(tau, r0, sigma0, alpha, pp, e2, smu):  # pragma: no cover - compiled
    """``(r, U1, U2, g)`` after ``tau = sqrt(mu) dt`` towards periapsis, with the
    universal Kepler equation anchored at periapsis (all its terms of one sign
    there): chi0 of the initial state from ``sigma0 = e U1(chi0)``, then
    ``q U1(chi1) + U3(chi1) = q U1(chi0) + U3(chi0) + tau`` for chi1; the
    functions at ``dchi = chi1 - chi0``.  ``pp = h^2/mu``, ``e2 = e^2``.
    r = NaN on failure."""
    ecc = math.sqrt(e2)
    q = pp / (1.0 + ecc)
    if alpha > 0.0:
        sa = math.sqrt(alpha)
        chi0 = math.atan2(sigma0 * sa, 1.0 - r0 * alpha) / sa
    elif alpha < 0.0:
        sa = math.sqrt(-alpha)
        chi0 = math.asinh(sigma0 * sa / ecc) / sa
    else:
        chi0 = sigma0 / ecc
    tp0 = _uv_eval(chi0, q, 0.0, alpha)[0]
    sol = _solve_uv(tp0 + tau, q, 0.0, alpha)
    chi1 = sol[0]
    if not math.isfinite(chi1):
        return math.nan, 0.0, 0.0, 0.0
    r = sol[2]
    dchi = chi1 - chi0
    _t, _r, _rp, _u0, u1, u2, u3 = _uv_eval(dchi, r0, sigma0, alpha)
    # as in _step_direct: the form of g that the last-bit error of dchi moves
    # least; r0 U1 + sigma0 U2 also keeps f gdot - fdot g = 1, i.e. the state on
    # the orbit (a long parabolic step turned the eccentricity vector by 1.5e-13
    # rad with tau - U3 alone).  Radial orbits (pp = 0) keep tau - U3, which
    # measured better through the collision.
    dchi_err = EPS * (abs(chi1) + abs(chi0))
    if pp > 0.0 and _g_first_form(tau, r0, sigma0, u1, u2, u3, r, dchi_err):
        g = (r0 * u1 + sigma0 * u2) / smu
    else:
        g = (tau - u3) / smu
    return r, u1, u2, g


@njit(cache=True, inline="always")
def _step_direct(tau, r0, sigma0, alpha, h2, smu):  # pragma: no cover - compiled
    """``(r, U1, U2, g)`` after ``tau = sqrt(mu) dt`` from the universal Kepler
    equation ``T(chi) = tau`` solved directly; r = NaN on failure."""
    chi, _t, r, _u0, u1, u2, u3 = _solve_uv(tau, r0, sigma0, alpha)
    if not math.isfinite(chi):
        return math.nan, 0.0, 0.0, 0.0
    # g = (r0 U1 + sigma0 U2)/sqrt(mu) = (tau - U3)/sqrt(mu): the last-bit
    # error of chi moves the first by (r - U2) dchi, the second by U2 dchi;
    # take the smaller (on a fast hyperbola U3 << tau: g ~ dt exactly; the
    # step r = (1, 0, 0), v = (0, 1e5, 0), dt = 1.234567 went from 54 ulp to 0.2)
    if h2 > 0.0 and not _g_first_form(tau, r0, sigma0, u1, u2, u3, r, EPS * abs(chi)):
        g = (tau - u3) / smu
    else:
        g = (r0 * u1 + sigma0 * u2) / smu
    return r, u1, u2, g


@njit(cache=True, inline="always")
def _fg_state(rx, ry, rz, vx, vy, vz, r0, r, u1, u2, g, smu, hx, hy, hz):  # pragma: no cover
    """The state from Lagrange's f and g (``f = 1 - U2/r0``, ``fdot = -sqrt(mu)
    U1/(r r0)``, ``gdot = 1 - U2/r``): the position ``f r0 + g v0``; the
    velocity its radial part of the f-g velocity plus the exact transverse
    part ``h x r / |r|^2`` (``h = r0 x v0`` is constant).  fdot r0 + gdot v0
    cancels heavily in its transverse part when r >> r0; this form keeps
    r x v = h to rounding (and gives exactly zero transverse velocity on radial
    orbits).  NaN if ``r`` is not a positive float or ``|r|^2`` overflows."""
    nan = math.nan
    if not (r > 0.0) or not math.isfinite(r):
        return nan, nan, nan, nan, nan, nan
    x, y, z, wx, wy, wz, rr = _fg_sums(rx, ry, rz, vx, vy, vz, r0, r, u1, u2, g, smu)
    if not (0.0 < rr < math.inf):  # |r|^2 overflows: report, never garbage
        return nan, nan, nan, nan, nan, nan
    return _fg_velocity(x, y, z, wx, wy, wz, rr, hx, hy, hz)


@njit(cache=True, inline="always")
def _fg_sums(rx, ry, rz, vx, vy, vz, r0, r, u1, u2, g, smu):  # pragma: no cover - compiled
    """The position ``f r0 + g v0``, the f-g velocity ``fdot r0 + gdot v0`` and
    ``|r|^2`` (:func:`_fg_state` without its checks)."""
    f = 1.0 - u2 / r0
    fd = -smu * u1 / (r * r0)
    gd = 1.0 - u2 / r
    x = f * rx + g * vx
    y = f * ry + g * vy
    z = f * rz + g * vz
    wx = fd * rx + gd * vx
    wy = fd * ry + gd * vy
    wz = fd * rz + gd * vz
    return x, y, z, wx, wy, wz, x * x + y * y + z * z


@njit(cache=True, inline="always")
def _fg_velocity(x, y, z, wx, wy, wz, rr, hx, hy, hz):  # pragma: no cover - compiled
    """The state of :func:`_fg_state`: the radial part of the f-g velocity ``w`` plus
    ``h x r / |r|^2`` (``rr = |r|^2``)."""
    vr = (x * wx + y * wy + z * wz) / rr
    return (
        x,
        y,
        z,
        vr * x + (hy * z - hz * y) / rr,
        vr * y + (hz * x - hx * z) / rr,
        vr * z + (hx * y - hy * x) / rr,
    )


#: 1/a = 2/r - v^2/mu is taken as zero (a parabola) within this many ulps of the
#: sum of its two terms (:func:`parabolic`)
PARABOLA_TOL = 4.0 * EPS


@njit(cache=True, inline="always")
def parabolic(inv_a, r, v2, mu):  # pragma: no cover - compiled
    """Whether a state of ``1/a = inv_a`` (``2/r - v2/mu``) is a parabola: ``1/a`` zero
    to within the rounding of its two terms (the rule of the elements,
    :mod:`hamilton_orbits._kernels.elements`)."""
    return abs(inv_a) <= PARABOLA_TOL * (2.0 / r + v2 / mu)


@njit(cache=True, inline="always")
def _propagate(rx, ry, rz, vx, vy, vz, mu, dt, exact_parabola):  # pragma: no cover
    """:func:`propagate_uv`'s body; ``exact_parabola``: a state that is a parabola
    (:func:`parabolic`) moved on the parabola, ``1/a`` exactly 0, to a state that
    is one (:func:`_escape_speed`).  (Its ``1/a`` of a few ulps of ``2/r``, kept by
    the motion, is no longer within the rounding of ``2/r`` far out: a comet
    propagated 10 years became an ellipse or a hyperbola of ``a`` ~ 1e15 au.)"""
    nan = math.nan
    r0 = math.sqrt(rx * rx + ry * ry + rz * rz)
    if not (r0 > 0.0):
        return nan, nan, nan, nan, nan, nan
    if dt == 0.0:
        return rx, ry, rz, vx, vy, vz
    v2 = vx * vx + vy * vy + vz * vz
    smu = math.sqrt(mu)
    sigma0 = (rx * vx + ry * vy + rz * vz) / smu
    alpha = 2.0 / r0 - v2 / mu
    on_parabola = exact_parabola and parabolic(alpha, r0, v2, mu)
    if on_parabola:
        alpha = 0.0  # (a parabola's: its state's rounding kept out of the motion)
    tau = smu * _reduce_period(dt, mu, smu, alpha)
    hx = ry * vz - rz * vy
    hy = rz * vx - rx * vz
    hz = rx * vy - ry * vx
    h2 = hx * hx + hy * hy + hz * hz
    # anchor only when it matters: heading for periapsis with a step long
    # enough that sigma0 U2 ~ sigma0 chi^2/2 (chi ~ tau/r0) reaches r0 U1 / 20,
    # and e^2 = 1 - alpha p >= 1/4
    anchor = False
    pp = 0.0
    e2 = 0.0
    if sigma0 * tau < 0.0 and abs(sigma0 * tau) > 0.1 * r0 * r0:
        pp = h2 / mu
        e2 = 1.0 - alpha * pp
        anchor = e2 >= 0.25
    if anchor:
        r, u1, u2, g = _step_anchored(tau, r0, sigma0, alpha, pp, e2, smu)
    else:
        r, u1, u2, g = _step_direct(tau, r0, sigma0, alpha, h2, smu)
    out = _fg_state(rx, ry, rz, vx, vy, vz, r0, r, u1, u2, g, smu, hx, hy, hz)
    return _escape_speed(out, mu) if on_parabola else out


@njit(cache=True, inline="always")
def _escape_speed(state, mu):  # pragma: no cover - compiled
    """``state`` with its speed made the escape speed ``sqrt(2 mu / r)`` (a change of
    a few ulps on a state moved on a parabola: its ``1/a`` then 0 to within the
    rounding of ``2/r``, so the state is a parabola by :func:`parabolic`)."""
    x, y, z, a, b, c = state
    r2 = x * x + y * y + z * z
    w2 = a * a + b * b + c * c
    if not (r2 > 0.0 and w2 > 0.0 and math.isfinite(r2 + w2)):
        return state
    f = math.sqrt(2.0 * mu / math.sqrt(r2) / w2)
    return x, y, z, a * f, b * f, c * f


@njit(cache=True)
def propagate_uv(rx, ry, rz, vx, vy, vz, mu, dt):  # pragma: no cover - compiled
    """Two-body state after time ``dt`` by universal variables (f and g series).

    Returns ``(rx, ry, rz, vx, vy, vz)``, all NaN on failure.

    * A bound orbit's ``dt`` is first reduced modulo the period
      (:func:`_reduce_period`), so |dt| may be many periods.
    * Moving away from periapsis (``sigma0 dt >= 0``, or a nearly circular
      orbit) the universal Kepler equation ``T(chi) = sqrt(mu) dt`` is a sum
      of terms of one sign and is solved directly (:func:`_step_direct`).
      g is computed either from chi alone, ``g = (r0 U1 + sigma0 U2)/sqrt(mu)``,
      so that f gdot - fdot g = 1 holds identically and the state stays on the
      initial orbit whatever the solver's last-bit error, or as
      ``(tau - U3)/sqrt(mu)``, whichever the last-bit error of chi and the
      rounding of the terms move least (:func:`_g_first_form`; on a fast
      hyperbola U3 << tau and g ~ dt).
    * Moving towards periapsis (``sigma0 dt < 0``, e^2 >= 1/4, and a step
      long enough, ``|sigma0 tau| > r0^2 / 10``, to matter), the terms of
      T(chi) cancel (for an open orbit that starts far out the loss is about
      r0/q in relative accuracy).  The equation is then anchored at
      periapsis, where all terms have one sign (:func:`_step_anchored`;
      radial orbits keep ``g = dt - U3/sqrt(mu)``) and
      ``r = q U0(chi1) + U2(chi1)``.
    * The state follows from f and g (:func:`_fg_state`).

    :data:`propagate_uv_inline` is this function compiled to be inlined (at
    numba's IR level) into the loop that calls it.
    """
    return _propagate(rx, ry, rz, vx, vy, vz, mu, dt, False)


# The Wisdom-Holman drift loop (over bodies with the same mu and dt) calls this
# one instead: propagate_uv's body inlined there, the work on consecutive bodies
# overlaps and what depends on mu and dt alone leaves the loop (about 20% less
# time per body for the planets).  The same Python function, so one definition;
# not cached on its own (only ever compiled into its callers).
propagate_uv_inline = njit(inline="always")(propagate_uv.py_func)


# ---------------------------------------------------------------------------
# propagate_uv for many states at once (the Wisdom-Holman drift)

#: The columns of :func:`propagate_lanes`' work array, each ``m`` lanes long: the
#: input position and velocity (0-5), ``mu`` (6) and ``sqrt(mu)`` (7), the output
#: position and velocity (8-13) and whether a lane is done (14: 1.0 or 0.0).
LANE_COLUMNS = 15


@njit(cache=True, error_model="numpy")
def propagate_lanes(w, m, dt):  # pragma: no cover - compiled
    """:func:`propagate_uv` by ``dt`` for the ``m`` states in the columns of ``w``
    (:data:`LANE_COLUMNS` of them, each ``m`` long), on its common path
    only: moving away from periapsis or a short step (no anchoring), no period to
    reduce, a short step whose first Halley evaluation settles
    (:func:`_solve_uv_short`).  A lane done (``w[14 m + i] = 1``) holds
    propagate_uv's result to the bit: the same operations in the same order,
    each branch of the scalar path a comparison here; the others are left to the
    scalar kernel (``dt = 0`` too).

    Lanes are states: the loop is straight-line code that the compiler turns into
    vector instructions (8 states at once; the scalar solves of consecutive
    bodies, chains of divisions and Stumpff sums, hardly overlap).  The loop runs
    over all ``m`` lanes: the compiler proves the columns apart only then."""
    for i in range(m):
        rx, ry, rz = w[i], w[m + i], w[2 * m + i]
        vx, vy, vz = w[3 * m + i], w[4 * m + i], w[5 * m + i]
        mu, smu = w[6 * m + i], w[7 * m + i]
        r0 = math.sqrt(rx * rx + ry * ry + rz * rz)
        v2 = vx * vx + vy * vy + vz * vz
        sigma0 = (rx * vx + ry * vy + rz * vz) / smu
        alpha = 2.0 / r0 - v2 / mu
        tau = smu * dt
        hx = ry * vz - rz * vy
        hy = rz * vx - rx * vz
        hz = rx * vy - ry * vx
        h2 = hx * hx + hy * hy + hz * hz
        ok = _lane_direct(r0, sigma0, alpha, mu, dt, tau, h2)
        sgn = 1.0 if tau > 0.0 else -1.0
        x1 = tau / r0
        ir = 1.0 / r0
        c2 = 0.5 * sigma0 * ir
        ok = ok & (2.0 * x1 * x1 * (4.0 * c2 * c2 + ir + abs(alpha)) < 1.0)
        x = _series_x(x1, ir, c2, r0, sigma0, alpha)
        ok = ok & (x * sgn > 0.0) & (x * x * abs(alpha) < 0.25)
        chi, r, u1, u2, u3, settled = _lane_halley(tau, x, r0, sigma0, alpha)
        ok = ok & settled & (abs(chi) < math.inf) & (r > 0.0) & (r < math.inf)
        # _step_direct's choice of g, both forms formed
        ga = (tau - u3) / smu
        gb = (r0 * u1 + sigma0 * u2) / smu
        second = (h2 > 0.0) & (not _g_first_form(tau, r0, sigma0, u1, u2, u3, r,
                                                  EPS * abs(chi)))
        g = ga if second else gb
        x, y, z, wx, wy, wz, rr = _fg_sums(rx, ry, rz, vx, vy, vz, r0, r, u1, u2, g, smu)
        ok = ok & (0.0 < rr) & (rr < math.inf)
        x, y, z, wx, wy, wz = _fg_velocity(x, y, z, wx, wy, wz, rr, hx, hy, hz)
        w[8 * m + i], w[9 * m + i], w[10 * m + i] = x, y, z
        w[11 * m + i], w[12 * m + i], w[13 * m + i] = wx, wy, wz
        w[14 * m + i] = 1.0 if ok else 0.0


@njit(cache=True, inline="always")
def _lane_direct(r0, sigma0, alpha, mu, dt, tau, h2):  # pragma: no cover - compiled
    """Whether :func:`propagate_uv` takes the path of :func:`propagate_lanes`
    before its solver: ``r0 > 0`` (and not radial, ``r0^3 > 0``), no period to
    reduce (:func:`_reduce_period`'s test) and no anchoring."""
    ok = (r0 > 0.0) & (r0 * r0 * r0 > 0.0)
    reduce = (alpha > 0.0) & (not ((dt * alpha) * (dt * alpha) * (mu * alpha)
                                   <= 0.2499 * TWO_PI_HI * TWO_PI_HI))
    e2 = 1.0 - alpha * (h2 / mu)
    anchor = (sigma0 * tau < 0.0) & (abs(sigma0 * tau) > 0.1 * r0 * r0) & (e2 >= 0.25)
    return ok & (not reduce) & (not anchor)


@njit(cache=True, inline="always")
def _lane_halley(tau, x, r0, sigma0, alpha):  # pragma: no cover - compiled
    """The first iteration of :func:`_solve_uv_short` from ``x`` without its
    branches: ``(chi, r, U1, U2, U3, settled)``, ``settled`` when the scalar
    solver returns after it (its result, to the bit, then)."""
    chi2 = x * x
    psi = alpha * chi2
    c2, c3 = _stumpff_lanes(psi)
    t, r, rp, u0, u1, u2, u3 = _uv_from_stumpff(x, chi2, psi, c2, c3, r0, sigma0, alpha)
    f = t - tau
    exact = f == 0.0
    den = r * r - 0.5 * f * rp
    dx = -f * r / den
    xn = x + dx
    small = abs(dx) <= 4.0 * EPS * abs(xn)
    done = small & (abs(f) <= 2.0 * EPS * abs(tau))
    taylor = small | (abs(dx) <= _TAYLOR_STEP * abs(x))
    moved = (den > 0.0) & (r > 0.0) & (xn * x > 0.0) & (done | taylor)
    carry = (not exact) & (not done)
    xc, _t, rc, _v0, v1, v2, v3 = _taylor_carry(xn, dx, u0, u1, u2, u3, r0, sigma0, alpha)
    return (xc if carry else x, rc if carry else r, v1 if carry else u1,
            v2 if carry else u2, v3 if carry else u3, exact | moved)


@njit(cache=True, inline="always")
def _stumpff_lanes(psi):  # pragma: no cover - compiled
    """:func:`_stumpff_series` without branches: every lane sums the longest series
    it may need, and restarts it where :func:`_stumpff_series` and :func:`_series_s`
    start theirs for its ``|psi|`` (their ``top``), so that it adds the same terms
    in the same order.  Written out term by term: a loop over the coefficients
    (a tuple indexed by the loop variable compiles to a switch, and the loop is
    not unrolled) keeps the loop of :func:`propagate_lanes` from being vectorised."""
    z = -psi
    az = abs(z)
    m1 = az >= 1e-3
    m2 = az >= 0.01
    m3 = az >= 0.1
    c2 = _masked(_C[8], z, _C[9], m3)
    c2 = _masked(_C[7], z, c2, m3)
    c2 = _masked(_C[6], z, c2, m3)
    zs = -1.0 * psi
    c3 = _S[14]
    for k in (13, 12, 11, 10, 9, 8, 7, 6):  # a tuple of constants: unrolled
        c3 = _masked(_S[k], zs, c3, m3)
    return _masked_tail(_C, z, c2, m1, m2), _masked_tail(_S, zs, c3, m1, m2)


@njit(cache=True, inline="always")
def _masked_tail(c, z, acc, m1, m2):  # pragma: no cover - compiled
    """The last six Horner steps (coefficients ``c[5] .. c[0]``) of
    :func:`_stumpff_lanes`' series: both series start at ``c[5]`` from ``|psi| =
    0.01`` on and at ``c[3]`` from ``1e-3``."""
    acc = _masked(c[5], z, acc, m2)
    acc = _masked(c[4], z, acc, m2)
    acc = _masked(c[3], z, acc, m1)
    acc = c[2] + z * acc
    acc = c[1] + z * acc
    return c[0] + z * acc


@njit(cache=True, inline="always")
def _masked(c, z, acc, use):  # pragma: no cover - compiled
    """One Horner step ``c + z acc`` where the series has begun (``use``), else its
    first coefficient ``c``."""
    nxt = c + z * acc
    return nxt if use else c


# Below 1e-50 or above 1e50 a product of the kernels (h^2 ~ r^2 v^2, r.v h,
# mu r, ...) may leave the float range; such states are scaled first.
_SAFE_LO = 1e-50
_SAFE_HI = 1e50


# The kernels square e (1 - e^2 = p / a): |r| |v|^2 / mu ~ e must stay below
# 2^450 ~ 3e135 so that e^2 and its companions fit in the float range.
MAX_E_EXPONENT = 450


@njit(inline="always")
def state_in_safe_range(rx, ry, rz, vx, vy, vz, mu):  # pragma: no cover - compiled
    """Whether :func:`state_scales` leaves the state as it is: every magnitude in
    [1e-50, 1e50] (``v`` may be 0) and ``|r| |v|^2 / mu < 1e60`` (False for NaN).

    One branch for its caller: the tests are combined with ``&``, not ``and``
    (the elements kernel tests this inline, 3-5% of its time, and calls the
    scaling path only when it fails)."""
    mr = max(abs(rx), abs(ry), abs(rz))
    mv = max(abs(vx), abs(vy), abs(vz))
    return (
        (_SAFE_LO < mr) & (mr < _SAFE_HI) & (_SAFE_LO < mu) & (mu < _SAFE_HI)
        & (((_SAFE_LO < mv) & (mv < _SAFE_HI)) | (mv == 0.0)) & (mr * mv * mv < 1e60 * mu)
    )


@njit(cache=True)
def state_scales(rx, ry, rz, vx, vy, vz, mu):  # pragma: no cover - compiled
    """Exponents ``(er, ev, ok)`` of the powers of two that bring ``(r, v, mu)`` to order 1.

    Two-body motion is homogeneous: ``r -> r / 2^er``, ``v -> v / 2^ev``,
    ``mu -> mu / 2^(er + 2 ev)``, ``t -> t 2^(ev - er)`` leave every angle, the
    eccentricity and the anomalies unchanged, so a kernel can work on the scaled
    state and scale lengths, speeds and times back exactly (powers of two).
    ``er`` makes ``|r| ~ 1``; ``ev`` makes ``|v| ~ 1`` unless ``mu`` would then
    leave 2^(+-400) (a state nearly at rest), in which case ``mu ~ 1``.
    ``(0, 0, True)`` when every magnitude lies in [1e-50, 1e50] and
    ``|r| |v|^2 / mu < 1e60`` already (the common case: no scaling, bit for bit
    the unscaled kernels).  ``ok`` is False when ``|r| |v|^2 / mu`` (~ e, the
    one dimensionless number of the state) exceeds 2^MAX_E_EXPONENT.
    """
    if state_in_safe_range(rx, ry, rz, vx, vy, vz, mu):
        return 0, 0, True
    mr = max(abs(rx), abs(ry), abs(rz))
    mv = max(abs(vx), abs(vy), abs(vz))
    er = math.frexp(mr)[1]
    emu = math.frexp(mu)[1]
    ev_mu = (emu - er) // 2
    if mv == 0.0:
        return er, ev_mu, True
    ev = math.frexp(mv)[1]
    eq = er + 2 * ev - emu  # exponent of |r| |v|^2 / mu
    if eq > MAX_E_EXPONENT:
        return er, ev, False
    if eq < -400:
        ev = ev_mu
    return er, ev, True


@njit(cache=True)
def propagate_scaled(rx, ry, rz, vx, vy, vz, mu, dt):  # pragma: no cover - compiled
    """:func:`propagate_uv` on the state scaled to order 1 (:func:`state_scales`),
    so that no intermediate product overflows or underflows, a parabola moved on
    the parabola (``1/a`` exactly 0, so that it stays one); NaN for a ``dt`` that
    is not finite."""
    er, ev, ok = state_scales(rx, ry, rz, vx, vy, vz, mu)
    if not ok or not math.isfinite(dt):
        nan = math.nan
        return nan, nan, nan, nan, nan, nan
    if er == 0 and ev == 0:
        return _propagate(rx, ry, rz, vx, vy, vz, mu, dt, True)
    x, y, z, a, b, c = _propagate(
        math.ldexp(rx, -er), math.ldexp(ry, -er), math.ldexp(rz, -er),
        math.ldexp(vx, -ev), math.ldexp(vy, -ev), math.ldexp(vz, -ev),
        math.ldexp(mu, -er - 2 * ev), math.ldexp(dt, ev - er), True,
    )
    return (
        math.ldexp(x, er), math.ldexp(y, er), math.ldexp(z, er),
        math.ldexp(a, ev), math.ldexp(b, ev), math.ldexp(c, ev),
    )


@parallel_kernel
def propagate_batch(r, v, mu, dt, r_out, v_out):  # pragma: no cover - compiled
    """Loop :func:`propagate_scaled` over rows (threads share the rows from
    :data:`hamilton_orbits._kernels._dispatch.DEFAULT_THRESHOLD` rows on); returns
    the first failing row or -1."""
    for i in prange(r.shape[0]):
        x, y, z, a, b, c = propagate_scaled(
            r[i, 0], r[i, 1], r[i, 2], v[i, 0], v[i, 1], v[i, 2], mu[i], dt[i]
        )
        r_out[i, 0] = x
        r_out[i, 1] = y
        r_out[i, 2] = z
        v_out[i, 0] = a
        v_out[i, 1] = b
        v_out[i, 2] = c
    for i in range(r.shape[0]):  # after the threads: the first failure, in order
        s = r_out[i, 0] + r_out[i, 1] + r_out[i, 2] + v_out[i, 0] + v_out[i, 1] + v_out[i, 2]
        if not math.isfinite(s):
            if not (math.isfinite(r_out[i, 0]) and math.isfinite(r_out[i, 1])
                    and math.isfinite(r_out[i, 2]) and math.isfinite(v_out[i, 0])
                    and math.isfinite(v_out[i, 1]) and math.isfinite(v_out[i, 2])):
                return i
    return -1


__all__ = [
    "EPS",
    "anomaly_from_nu",
    "anomaly_from_nu_ufunc",
    "mean_from_anomaly",
    "mean_from_anomaly_ufunc",
    "nu_from_anomaly",
    "nu_from_anomaly_ufunc",
    "propagate_batch",
    "propagate_lanes",
    "propagate_uv",
    "propagate_uv_inline",
    "sinh_minus_x",
    "solve",
    "solve_parabolic",
    "solve_ufunc",
    "solve_universal",
    "stumpff_c2c3",
    "x_minus_sin",
]
