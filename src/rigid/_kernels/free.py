"""Compiled kernels for the exact torque-free motion (plain floats, no astropy).

Contents
--------
* Carlson's symmetric integrals ``R_F``, ``R_C`` and ``R_J`` by the duplication
  algorithm (Carlson 1995, Numer. Algorithms 10, 13-26; DLMF 19.36.i).
* Jacobi ``sn, cn, dn`` with the complementary parameter ``m1 = 1 - m`` passed
  separately, by the arithmetic-geometric mean / descending Landen
  transformation (Abramowitz & Stegun 16.4.3; DLMF 22.20.ii), on the reduced
  argument ``|r| <= K`` and with the quarter-period reflection
  ``sn(K - v) = cd v``, ``cn(K - v) = sqrt(m1) sd v``, ``dn(K - v) = sqrt(m1) nd v``
  (DLMF 22.4.iii) for ``|r| > K/2``, so every value keeps its *relative*
  accuracy up to ``m = 1 - 1e-300``.
* The closed-form free motion: :func:`free_setup` reduces a state to a small
  parameter vector, :func:`free_eval` evaluates it at many times,
  :func:`free_flow` does both.  The derivation, the signs and the branches are
  in ``docs/free_rigid_body.md``.

Parameter vector layout (``free_setup``), in the working frame W (a proper
signed permutation of the body axes, ``v_body = P v_W``; moments J1, J2, J3 with
J3 the axis the polhode encircles, omega_W3 >= 0).  The slot indices below are
public: the callers (:mod:`rigid.free`, :mod:`rigid.sylvester`) read
``prm[KIND]``, ``prm[P:P + 9]``, ``prm[LAM]``, ``prm[K]``, ``prm[M]``, ``prm[M1]``,
``prm[N]`` and ``prm[U0]``; a slot's meaning is part of this module's contract.
Near the intermediate axis (``k' = sqrt(m1) < 1e-20``, slot ``KP``) the periodic
motion is evaluated in the separatrix limit (:func:`jacobi_limit`; ``M1`` may then
underflow to 0 while ``KP`` and ``K`` stay exact).
The rates (``LAM``, ``L``) are in the time unit of the ``omega`` given.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hamilton_orbits.quaternion_kernels import qmul

# Parameter-vector slots (public: the layout that free_setup writes).
KIND = 0  # 0 steady (sphere, rest, rotation about a principal axis), 1 periodic, 2 separatrix
P = 1  # 9 entries, row-major, v_body = P v_W
C0 = 10  # 4 entries: q0 * qP * qa(0)
QPI = 14  # 4 entries: qP^-1
A = 18  # amplitude a of omega_W1 = a cn u (signed on the separatrix)
B = 19  # amplitude of omega_W2 = b sn u, signed
C = 20  # amplitude c of omega_W3 = c dn u
LAM = 21  # rate lambda of the argument u = u0 + lambda t
M = 22  # parameter m
M1 = 23  # complementary parameter m1 = 1 - m (computed directly)
K = 24  # complete elliptic integral K(m)
PIC = 25  # complete: Pi(n | m) (form A) or Pi(n | m) - K(m) (form B)
N = 26  # characteristic n = -J3 (J2 - J1) / (J1 (J3 - J2))
U0 = 27  # initial argument u0
L = 28  # |L|
J1 = 29  # moments in the working frame
J2 = 30
J3 = 31
COEF = 32  # L (J3 - J1) / (J1 J3 lam)
PI0 = 33  # Pi(n; am u0 | m) (form A) or Pi - u0 (form B), with its secular part
ALPHA0 = 34  # azimuth of l_W at u0
RHO = 35  # signed ratio in the continuous azimuth of l in the W frame
SB = 36  # sign of b (= sign(J3 - J1))
W0 = 37  # 3 entries: omega in the body frame (steady case)
Q0 = 40  # 4 entries: q0 (steady case)
FORM = 44  # 1: secular (L/J3) t + coef Pi (J3 > J1); 0: (L/J1) t + coef (Pi - u)
KP = 45  # k' = sqrt(m1), computed without underflow (m1 itself may underflow)
NPARAM = 46

# Below this k' (m1 < 1e-40) the periodic motion is evaluated in the separatrix limit
# (A&S 16.15, 17.3.26): sn = tanh, cn = dn = sech for |r| <= K/2 and the reflection
# sn = 1, cn = k' sinh v, dn = k' cosh v beyond (v = K - |r|), K = ln(4/k'), Pi from its
# m = 1 form.  The neglected terms are of relative size m1 e^{2|r|} / 16 <= k' / 4
# (below 2.5e-21, under the rounding of float64); the general formulas would need
# m1 = k'^2, which underflows for a spin within ~1e-154 of the intermediate axis.
_KP_LIMIT = 1e-20
_LN4 = math.log(4.0)

_R = 2.0**-53
_QF = (3.0 * _R) ** (-1.0 / 6.0)
_QJ = (0.25 * _R) ** (-1.0 / 6.0)


# ---------------------------------------------------------------------------
# Carlson's symmetric integrals
# ---------------------------------------------------------------------------


@njit(cache=True)
def carlson_rf(x, y, z):  # pragma: no cover - compiled
    """``R_F(x, y, z)`` for ``x, y, z >= 0``, at most one zero (Carlson 1995, alg. 1)."""
    a0 = (x + y + z) / 3.0
    q = _QF * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    a = a0
    xm, ym, zm = x, y, z
    f = 1.0
    for _ in range(100):
        if f * q < abs(a):
            break
        sx = math.sqrt(xm)
        sy = math.sqrt(ym)
        sz = math.sqrt(zm)
        lam = sx * sy + sx * sz + sy * sz
        xm = 0.25 * (xm + lam)
        ym = 0.25 * (ym + lam)
        zm = 0.25 * (zm + lam)
        a = 0.25 * (a + lam)
        f *= 0.25
    xx = (a0 - x) * f / a
    yy = (a0 - y) * f / a
    zz = -xx - yy
    e2 = xx * yy - zz * zz
    e3 = xx * yy * zz
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)


@njit(cache=True)
def carlson_rc1(e):  # pragma: no cover - compiled
    """``R_C(1, 1 + e)`` for ``e > -1`` (DLMF 19.2.18-19.2.19), series near 0."""
    if abs(e) < 1e-4:
        # 1 - e/3 + e^2/5 - e^3/7 + e^4/9: the next term is below 1e-20.
        return 1.0 + e * (-1.0 / 3.0 + e * (0.2 + e * (-1.0 / 7.0 + e / 9.0)))
    if e > 0.0:
        s = math.sqrt(e)
        return math.atan(s) / s
    s = math.sqrt(-e)
    return math.atanh(s) / s


@njit(cache=True)
def carlson_rj(x, y, z, p):  # pragma: no cover - compiled
    """``R_J(x, y, z, p)`` for ``x, y, z >= 0`` (at most one zero), ``p > 0``.

    Carlson (1995), algorithm 3 (the real case).
    """
    a0 = (x + y + z + 2.0 * p) / 5.0
    delta = (p - x) * (p - y) * (p - z)
    q = _QJ * max(abs(a0 - x), abs(a0 - y), abs(a0 - z), abs(a0 - p))
    a = a0
    xm, ym, zm, pm = x, y, z, p
    f = 1.0
    f3 = 1.0
    total = 0.0
    for _ in range(100):
        if f * q < abs(a):
            break
        sx = math.sqrt(xm)
        sy = math.sqrt(ym)
        sz = math.sqrt(zm)
        sp = math.sqrt(pm)
        lam = sx * sy + sx * sz + sy * sz
        d = (sp + sx) * (sp + sy) * (sp + sz)
        e = f3 * delta / (d * d)
        total += f * carlson_rc1(e) / d
        xm = 0.25 * (xm + lam)
        ym = 0.25 * (ym + lam)
        zm = 0.25 * (zm + lam)
        pm = 0.25 * (pm + lam)
        a = 0.25 * (a + lam)
        f *= 0.25
        f3 *= 1.0 / 64.0
    xx = (a0 - x) * f / a
    yy = (a0 - y) * f / a
    zz = (a0 - z) * f / a
    pp = -0.5 * (xx + yy + zz)
    e2 = xx * yy + xx * zz + yy * zz - 3.0 * pp * pp
    e3 = xx * yy * zz + 2.0 * e2 * pp + 4.0 * pp * pp * pp
    e4 = (2.0 * xx * yy * zz + e2 * pp + 3.0 * pp * pp * pp) * pp
    e5 = xx * yy * zz * pp * pp
    series = (
        1.0
        - 3.0 * e2 / 14.0
        + e3 / 6.0
        + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
    )
    return f * series / (a * math.sqrt(a)) + 6.0 * total


# ---------------------------------------------------------------------------
# Jacobi elliptic functions
# ---------------------------------------------------------------------------


@njit(cache=True)
def _agm_sncn(u, m, m1):  # pragma: no cover - compiled
    """``(sn, cn)`` by the AGM (A&S 16.4.3); accurate for ``|u| <= K/2``."""
    if m == 0.0:
        return math.sin(u), math.cos(u)
    ratios = np.empty(64)
    a = 1.0
    b = math.sqrt(m1)
    c = math.sqrt(m)
    n = 0
    while abs(c) > 1e-17 * a and n < 63:
        an = 0.5 * (a + b)
        cn = 0.25 * c * c / an  # c_n = (a_{n-1} - b_{n-1}) / 2 without cancellation
        b = math.sqrt(a * b)
        a = an
        c = cn
        n += 1
        ratios[n] = c / a
    phi = (2.0**n) * a * u
    for j in range(n, 0, -1):
        phi = 0.5 * (phi + math.asin(ratios[j] * math.sin(phi)))
    return math.sin(phi), math.cos(phi)


@njit(cache=True)
def _landen_sncn(u, m, m1):  # pragma: no cover - compiled
    """``(sn, cn)`` of ``0 <= u <= K/2`` by descending Landen transformations (DLMF
    22.7.1-22.7.2): the modulus ``k_{j+1} = k_j^2 / (1 + k'_j)^2`` (so ``k' =
    2 sqrt(k'_j) / (1 + k'_j)``) and the argument ``u / (1 + k_{j+1})`` taken down
    until ``k^2`` is below 1e-34 (then ``sn = sin``, ``cn = cos``: DLMF 22.10.1-2),
    and back up by ``sn = (1 + k1) s / (1 + k1 s^2)``, ``cn = c d / (1 + k1 s^2)``
    with ``d = sqrt(k1'^2 + k1^2 c^2)``.  Every step multiplies, divides or adds
    positive numbers, and at the bottom the argument is at most ``pi/4`` (``u/K``
    is kept): ``cn`` keeps its relative accuracy where it is small, near the
    separatrix (``m1 -> 0``, ``cn(K/2) = sqrt(k'/(1 + k'))``), which the AGM's
    ``asin`` recursion lost (``eps / cn^2``)."""
    if m == 0.0:
        return math.sin(u), math.cos(u)
    if m1 == 0.0:  # (the separatrix itself: DLMF 22.5.iv)
        return math.tanh(u), 1.0 / math.cosh(u)
    ks = np.empty(64)
    kps = np.empty(64)
    k2 = m
    kp = math.sqrt(m1)
    n = 0
    while k2 > 1e-34 and n < 63:
        one = 1.0 + kp
        k1 = k2 / (one * one)
        kp = 2.0 * math.sqrt(kp) / one
        u = u / (1.0 + k1)
        n += 1
        ks[n] = k1
        kps[n] = kp
        k2 = k1 * k1
    s = math.sin(u)
    c = math.cos(u)
    for j in range(n, 0, -1):
        k1 = ks[j]
        d = math.sqrt(kps[j] * kps[j] + k1 * k1 * c * c)  # dn at level j
        den = 1.0 + k1 * s * s
        s, c = (1.0 + k1) * s / den, c * d / den
    return s, c


@njit(cache=True)
def _sncn(u, m, m1):  # pragma: no cover - compiled
    """``(sn, cn)`` of ``0 <= u <= K/2``: by the AGM (within an ulp or two where
    ``cn`` is not small; its relative error grows as ``eps / cn^2``), and where it
    gives ``cn^2 < 1/8`` (near the separatrix, ``m1 -> 0``) by Landen's
    transformations instead (a few ulp, whatever ``cn``)."""
    s, c = _agm_sncn(u, m, m1)
    if c * c < 0.125:
        return _landen_sncn(u, m, m1)
    return s, c


@njit(cache=True)
def jacobi_reduced(r, m, m1, kk):  # pragma: no cover - compiled
    """``sn, cn, dn`` of ``r`` with ``|r| <= K`` (``kk`` = K(m)), ``m + m1 = 1``.

    For ``|r| > K/2`` the reflection about the quarter period keeps the relative
    accuracy of ``cn`` and ``dn`` when they are small (DLMF 22.4.iii).
    """
    v = abs(r)
    if v <= 0.5 * kk:
        s, c = _sncn(v, m, m1)
        d = math.sqrt(m1 + m * c * c)
    else:
        s1, c1 = _sncn(kk - v, m, m1)
        d1 = math.sqrt(m1 + m * c1 * c1)
        k1 = math.sqrt(m1)
        s = c1 / d1
        c = k1 * s1 / d1
        d = k1 / d1
    if r < 0.0:
        s = -s
    return s, c, d


@njit(cache=True)
def jacobi_limit(r, kp, kk):  # pragma: no cover - compiled
    """``sn, cn, dn`` of ``|r| <= K`` (``kk`` = K(m)) for ``k' = sqrt(1 - m) < 1e-20``.

    The separatrix limit (A&S 16.15.1-16.15.3 to first order in ``m1 = k'^2``):
    ``sn = tanh r``, ``cn = dn = sech r`` for ``|r| <= K/2``, and beyond it the
    quarter-period reflection (DLMF 22.4.iii) of those, ``sn = 1``,
    ``cn = k' sinh v``, ``dn = k' cosh v`` with ``v = K - |r|``: relative errors of
    at most ``m1 e^{2 min(|r|, v)} / 16 <= k' / 4``, and ``k'`` is passed itself
    (``m1`` underflows below ``k' ~ 1e-154``).
    """
    v = abs(r)
    if v <= 0.5 * kk:
        e = math.exp(-v)
        s = math.tanh(v)
        c = 2.0 * e / (1.0 + e * e)
        d = c
    else:
        w = kk - v
        if w < 0.0:  # rounding at the upper edge
            w = 0.0
        s = 1.0
        c = kp * math.sinh(w)
        d = kp * math.cosh(w)
    if r < 0.0:
        s = -s
    return s, c, d


@njit(cache=True)
def ellipk_m1(m1):  # pragma: no cover - compiled
    """``K(m)`` from the complementary parameter ``m1 = 1 - m`` (DLMF 19.25.1)."""
    return carlson_rf(0.0, m1, 1.0)


@njit(cache=True)
def _pi_minus_f(n, s, c, d):  # pragma: no cover - compiled
    """``Pi(n; phi | m) - F(phi | m)`` for ``|phi| <= pi/2`` from ``sin, cos phi``, ``dn``.

    DLMF 19.25.14: Pi = s R_F(c^2, d^2, 1) + (n/3) s^3 R_J(c^2, d^2, 1, 1 - n s^2),
    and s R_F(c^2, d^2, 1) = F(phi | m) (DLMF 19.25.5).  Only the difference is
    computed: with ``phi = am r`` the ``F`` part is ``r`` itself, which the caller
    adds *exactly* in the secular term (no cancellation for thin bodies).
    """
    if n == 0.0 or s == 0.0:
        return 0.0
    s2 = s * s
    return n / 3.0 * s * s2 * carlson_rj(c * c, d * d, 1.0, 1.0 - n * s2)


@njit(cache=True)
def _pi_reduced(n, m, s, c, d):  # pragma: no cover - compiled
    """``Pi(n; phi | m)`` for ``|phi| <= pi/2`` and ``n < -1``, from ``sin, cos phi``, ``dn``.

    For ``-1 <= n <= 0`` the callers use ``r + (Pi - F)`` (:func:`_pi_minus_f`, with
    ``F(phi) = r`` exact and ``Pi >= F / 2``: no cancellation).  For ``n < -1`` that
    sum would cancel (``Pi ~ 1/sqrt(-n)`` while ``F ~ 1``), so ``Pi`` is taken from
    DLMF 19.7.9 with ``alpha^2 = n``, ``omega^2 = m/n``:

        Pi(n) = -(m/n)/3 s^3 R_J(c^2, d^2, 1, 1 - (m/n) s^2)
                + atan(s sqrt(g) / (c d)) / sqrt(g),   g = 1 + m - n - m/n,

    where the second term is ``s R_C(c^2 d^2, (1 - n s^2)(1 - (m/n) s^2))`` in closed
    form (``y - x = s^2 g`` exactly; DLMF 19.2.18).  Both terms are small and of
    one sign: full relative accuracy.
    """
    g = 1.0 + m - n - m / n
    sg = math.sqrt(g)
    val = math.atan2(s * sg, c * d) / sg
    if m != 0.0 and s != 0.0:
        nm = m / n
        s2 = s * s
        val -= nm / 3.0 * s * s2 * carlson_rj(c * c, d * d, 1.0, 1.0 - nm * s2)
    return val


# ---------------------------------------------------------------------------
# The free motion
# ---------------------------------------------------------------------------


@njit(cache=True)
def _sign(x):  # pragma: no cover - compiled
    return 1.0 if x >= 0.0 else -1.0


@njit(cache=True)
def _quat_from_signed_permutation(p):  # pragma: no cover - compiled
    """Unit quaternion of a proper rotation matrix (Shepperd 1978), ``p`` (3, 3)."""
    tr = p[0, 0] + p[1, 1] + p[2, 2]
    k = 0
    big = tr
    for i in range(3):
        if p[i, i] > big:
            big = p[i, i]
            k = i + 1
    d0 = 1.0 + tr
    d1 = 1.0 + 2.0 * p[0, 0] - tr
    d2 = 1.0 + 2.0 * p[1, 1] - tr
    d3 = 1.0 + 2.0 * p[2, 2] - tr
    if k == 0:
        w, x, y, z = d0, p[2, 1] - p[1, 2], p[0, 2] - p[2, 0], p[1, 0] - p[0, 1]
    elif k == 1:
        w, x, y, z = p[2, 1] - p[1, 2], d1, p[0, 1] + p[1, 0], p[0, 2] + p[2, 0]
    elif k == 2:
        w, x, y, z = p[0, 2] - p[2, 0], p[0, 1] + p[1, 0], d2, p[1, 2] + p[2, 1]
    else:
        w, x, y, z = p[1, 0] - p[0, 1], p[0, 2] + p[2, 0], p[1, 2] + p[2, 1], d3
    nrm = math.sqrt(w * w + x * x + y * y + z * z)
    return w / nrm, x / nrm, y / nrm, z / nrm


@njit(cache=True)
def _periodic_at(prm, u):  # pragma: no cover - compiled
    """Working-frame omega, the third-kind term and the continuous azimuth at ``u``.

    The third-kind term is ``Pi(n; am u | m)`` in form A and ``Pi - u`` in form B
    (slot ``FORM``), each summed from its complete part and the reduced argument.
    """
    kk = prm[K]
    k = math.floor((u + kk) / (2.0 * kk))
    r = u - 2.0 * kk * k
    if r > kk:  # rounding at the upper edge
        r = kk
    limit = prm[KP] < _KP_LIMIT
    if limit:
        s, c, d = jacobi_limit(r, prm[KP], kk)
    else:
        s, c, d = jacobi_reduced(r, prm[M], prm[M1], kk)
    sg = 1.0 if (int(k) & 1) == 0 else -1.0
    w1 = prm[A] * sg * c
    w2 = prm[B] * sg * s
    w3 = prm[C] * d
    n = prm[N]
    if limit:
        # Pi(n; am r | m) = (r + sqrt(nu) atan(sqrt(nu) tanh r)) / (1 + nu), nu = -n, the
        # m = 1 form (as in _separatrix_at), to O(k' K) absolute over all |r| <= K (where
        # sn^2 and tanh^2 both differ from 1 by at most ~k' beyond K/2).
        nu = -n
        snu = math.sqrt(nu)
        th = math.tanh(r)
        if prm[FORM] == 0.0:
            pi_u = 2.0 * k * prm[PIC] + (snu * math.atan(snu * th) - nu * r) / (1.0 + nu)
        else:
            pi_u = 2.0 * k * prm[PIC] + (r + snu * math.atan(snu * th)) / (1.0 + nu)
    elif prm[FORM] == 0.0:
        pi_u = 2.0 * k * prm[PIC] + _pi_minus_f(n, s, c, d)
    elif n >= -1.0:
        pi_u = 2.0 * k * prm[PIC] + (r + _pi_minus_f(n, s, c, d))
    else:
        pi_u = 2.0 * k * prm[PIC] + _pi_reduced(n, prm[M], s, c, d)
    alpha = prm[SB] * k * math.pi + math.atan2(prm[RHO] * s, c)
    return w1, w2, w3, pi_u, alpha


@njit(cache=True)
def _separatrix_at(prm, u):  # pragma: no cover - compiled
    """Working-frame omega, the third-kind term (as in :func:`_periodic_at`) and the
    azimuth on the separatrix."""
    e = math.exp(-abs(u))
    sech = 2.0 * e / (1.0 + e * e)
    th = math.tanh(u)
    a = prm[A]
    w1 = a * sech
    w2 = prm[B] * th
    w3 = prm[C] * sech
    nu = -prm[N]
    snu = math.sqrt(nu)
    # Pi(n; am u | 1) = (u + sqrt(nu) atan(sqrt(nu) tanh u)) / (1 + nu), nu = -n.
    if prm[FORM] == 0.0:
        pi_u = (snu * math.atan(snu * th) - nu * u) / (1.0 + nu)
    else:
        pi_u = (u + snu * math.atan(snu * th)) / (1.0 + nu)
    alpha = math.atan2(prm[RHO] * th, sech)
    return w1, w2, w3, pi_u, alpha


@njit(cache=True)
def is_steady(moments, w0):  # pragma: no cover - compiled
    """Whether the motion is taken as steady (sphere, rest, principal axis).

    ``I omega`` parallel to ``omega``, tested on omega / max|omega| so that nothing
    underflows, with a relative threshold of 1e-150 -- except near the intermediate
    axis.  Near the largest or the smallest axis (stable) the polhode's squared
    amplitudes (p1, p3 in :func:`_setup_shape`) would underflow below that threshold,
    while the true motion stays within a relative 1e-150 of the steady spin (its
    phase within 1e-150 |omega| t): invisible.  About the intermediate axis (its
    moment strictly between the others: unstable) a departure ``eps`` grows like
    ``eps e^{lambda t}`` and the body flips after ``t ~ ln(4 / k') / lambda``
    (``k' ~ eps``; Landau & Lifshitz, Mechanics §37): there only an exact spin
    (no cross term at all) is steady, and the rest is periodic, evaluated in the
    separatrix limit (``_KP_LIMIT``).

    The one definition of the test: :func:`rigid._shared.free_scale` runs this same
    source as Python (``is_steady.py_func`` on floats, no compile) to see the motion
    as the kernel will.
    """
    i0, i1, i2 = moments[0], moments[1], moments[2]
    wn = max(abs(w0[0]), abs(w0[1]), abs(w0[2]))
    if wn == 0.0:
        return True
    s0_, s1_, s2_ = w0[0] / wn, w0[1] / wn, w0[2] / wn
    cx = (i1 - i2) * s1_ * s2_
    cy = (i2 - i0) * s2_ * s0_
    cz = (i0 - i1) * s0_ * s1_
    cross = max(abs(cx), abs(cy), abs(cz))
    if cross == 0.0:
        return True
    if cross > 1e-150 * max(i0, i1, i2):
        return False
    # the dominant axis: steady unless it is strictly the intermediate one
    if abs(s0_) == 1.0:
        j, o1, o2 = i0, i1, i2
    elif abs(s1_) == 1.0:
        j, o1, o2 = i1, i2, i0
    else:
        j, o1, o2 = i2, i0, i1
    return not (min(o1, o2) < j < max(o1, o2))


_D_FLOOR = 2.0**-900


@njit(cache=True)
def _scaled_d(ja, va, jb, vb, jmid):  # pragma: no cover - compiled
    """``(D / s^2, s)`` for ``D = Ja va^2 (Ja - Jmid) + Jb vb^2 (Jb - Jmid)``: ``s`` the
    power of two near the larger amplitude ``|v| sqrt(J |J - Jmid|)`` (exact; a term
    with no amplitude is 0), so that the larger term is of order one."""
    fa = math.sqrt(ja * abs(ja - jmid))
    fb = math.sqrt(jb * abs(jb - jmid))
    ea = -100000
    eb = -100000
    if fa > 0.0 and va != 0.0:
        ea = math.frexp(va)[1] + math.frexp(fa)[1]
    if fb > 0.0 and vb != 0.0:
        eb = math.frexp(vb)[1] + math.frexp(fb)[1]
    e = max(ea, eb)
    if e == -100000:
        return 0.0, 1.0
    s = math.ldexp(1.0, e)
    ta = 0.0
    tb = 0.0
    if ea != -100000:
        xa = va / s
        ta = ja * xa * xa * (ja - jmid)
    if eb != -100000:
        xb = vb / s
        tb = jb * xb * xb * (jb - jmid)
    return ta + tb, s


@njit(cache=True)
def _kprime(j1, j2, j3, v1, v3, p1):  # pragma: no cover - compiled
    """``(k', ln k')``: ``k'^2 = m1 = (J3 - J1) D / ((J3 - J2) P1)`` with
    ``D = J1 v1^2 (J1 - J2) + J3 v3^2 (J3 - J2)``; where ``D`` is below 2^-900 it is
    taken on ``v / s`` (:func:`_scaled_d`), so that ``k'`` does not underflow where
    ``m1`` does (a spin within ~1e-154 of the intermediate axis); ``ln k'`` from
    ``ln s`` and the scaled rest, accurate even when ``k'`` is subnormal."""
    t1 = j1 * v1 * v1 * (j1 - j2)
    t3 = j3 * v3 * v3 * (j3 - j2)
    dm = t1 + t3
    # (the magnitude: D is recomputed here in another order of the products than in
    # _polar_order, and where it is at the level of its rounding its sign may differ)
    if max(abs(t1), abs(t3)) >= _D_FLOOR:  # as before: k' = sqrt(m1)
        kp = math.sqrt(min(abs((j3 - j1) * dm / ((j3 - j2) * p1)), 1.0))
        if kp == 0.0:  # (D = 0 in this order of the products: as below)
            return 5e-324, math.log(5e-324)
        return kp, math.log(kp)
    ds, s = _scaled_d(j1, v1, j3, v3, j2)
    g2 = abs((j3 - j1) * ds / ((j3 - j2) * p1))
    if g2 == 0.0:  # D = 0 to rounding, though _polar_order saw it nonzero: the
        # separatrix to rounding; the smallest k' keeps K finite (ln(4/k') ~ 745)
        return 5e-324, math.log(5e-324)
    g = math.sqrt(g2)
    return s * g, math.log(s) + math.log(g)


@njit(cache=True)
def _polar_order(moments, w0):  # pragma: no cover - compiled
    """``(order, kind)``: the body axes in working-frame order (the polar axis last)
    and the kind, 1.0 periodic or 2.0 on the separatrix (``L^2 = 2 T B``)."""
    # Sort the axes: imin, imid, imax (stable for ties).
    idx = np.array([0, 1, 2])
    for a in range(3):
        for b in range(2 - a):
            if moments[idx[b]] > moments[idx[b + 1]]:
                idx[b], idx[b + 1] = idx[b + 1], idx[b]
    imin, imid, imax = idx[0], idx[1], idx[2]
    jmin, jmid, jmax = moments[imin], moments[imid], moments[imax]
    # L^2 - 2 T B, without cancellation beyond its own conditioning; where it is below
    # 2^-900, on the rates scaled by a power of two (exact) so that its sign survives
    # near the intermediate axis, where it underflows (only its sign is used).
    ta = jmin * w0[imin] ** 2 * (jmin - jmid)
    tb = jmax * w0[imax] ** 2 * (jmax - jmid)
    d2 = ta + tb
    if max(abs(ta), abs(tb)) < _D_FLOOR:  # (both terms that small: not a cancellation
        # of two large ones, whose 0 is the separatrix to rounding, kept so)
        d2, _ = _scaled_d(jmin, w0[imin], jmax, w0[imax], jmid)
    kind = 1.0
    if d2 > 0.0 or (d2 == 0.0 and jmid == jmin):
        order = (imin, imid, imax)
    elif d2 < 0.0 or (d2 == 0.0 and jmid == jmax):
        order = (imax, imid, imin)
    else:
        order = (imin, imid, imax)
        kind = 2.0
    return order, kind


@njit(cache=True)
def _working_frame(moments, w0, order):  # pragma: no cover - compiled
    """``(pm, j1, j2, j3, v1, v2, v3)``: the proper signed permutation ``pm``
    (``v_body = pm v_W``), the moments and omega in the working frame, ``v3 >= 0``."""
    # Proper signed permutation: columns e_o1, e_o2, s e_o3.
    pm = np.zeros((3, 3))
    o1, o2, o3 = order
    s3 = 1.0 if (o2 - o1) % 3 == 1 else -1.0  # cyclic order of the axes is even
    pm[o1, 0] = 1.0
    pm[o2, 1] = 1.0
    pm[o3, 2] = s3
    j1, j2, j3 = moments[o1], moments[o2], moments[o3]
    v1, v2, v3 = w0[o1], w0[o2], s3 * w0[o3]
    if v3 < 0.0:  # half-turn about the first W axis so that omega_W3 > 0
        pm[o2, 1] = -1.0
        pm[o3, 2] = -s3
        v2 = -v2
        v3 = -v3
    return pm, j1, j2, j3, v1, v2, v3


@njit(cache=True)
def _setup_shape(prm, kind, j1, j2, j3, v1, v2, v3):  # pragma: no cover - compiled
    """Write the slots common to both kinds (KIND, C, LAM, N, L, J1-J3, COEF, FORM);
    return ``(a, b, p1, p3, dm)`` for the kind-specific parts."""
    lsq = (j1 * v1) ** 2 + (j2 * v2) ** 2 + (j3 * v3) ** 2
    ell = math.sqrt(lsq)
    p3 = j1 * v1 * v1 * (j3 - j1) + j2 * v2 * v2 * (j3 - j2)  # 2 T J3 - L^2
    p1 = j2 * v2 * v2 * (j2 - j1) + j3 * v3 * v3 * (j3 - j1)  # L^2 - 2 T J1
    dm = j1 * v1 * v1 * (j1 - j2) + j3 * v3 * v3 * (j3 - j2)  # L^2 - 2 T J2
    a = math.sqrt(p3 / (j1 * (j3 - j1)))
    b = math.sqrt(p3 / (j2 * (j3 - j2)))
    c = math.sqrt(p1 / (j3 * (j3 - j1)))
    lam = math.sqrt((j3 - j2) * p1 / (j1 * j2 * j3))
    nchar = -j3 * (j2 - j1) / (j1 * (j3 - j2))
    prm[KIND] = kind
    prm[C] = c
    prm[LAM] = lam
    prm[N] = nchar
    prm[L] = ell
    prm[J1] = j1
    prm[J2] = j2
    prm[J3] = j3
    prm[COEF] = ell * (j3 - j1) / (j1 * j3 * lam)
    # Psi' = L/J3 + L (J3 - J1)/(J1 J3) / (1 - n sn^2) = L/J1 + L (J3 - J1)/(J1 J3) n sn^2 /
    # (1 - n sn^2), n <= 0: form A (secular L/J3 and Pi) has terms of one sign when
    # J3 > J1, form B (secular L/J1 and Pi - u) when J3 < J1.  The other form would
    # cancel a rate ~ L / min(J1, J3) against itself (thin bodies, error ~ J1/J3).
    prm[FORM] = 1.0 if j3 > j1 else 0.0
    return a, b, p1, p3, dm


@njit(cache=True)
def _setup_periodic(prm, j1, j2, j3, v1, v2, v3, a, b, p1, p3, dm):  # pragma: no cover - compiled
    """Write the slots of a periodic motion; return omega_W, Pi and alpha at ``u0``."""
    nchar = prm[N]
    sb = _sign(j3 - j1)
    # Continuous azimuth of l_W = atan2(J2 w2, J1 w1) written as atan2(rho sn, cn).
    rho = sb * (j2 / j1) * math.sqrt(j1 * (j3 - j1) / (j2 * (j3 - j2)))
    m = (j2 - j1) * p3 / ((j3 - j2) * p1)
    m1 = (j3 - j1) * dm / ((j3 - j2) * p1)
    m = min(max(m, 0.0), 1.0)
    m1 = min(max(m1, 0.0), 1.0)
    kp, log_kp = _kprime(j1, j2, j3, v1, v3, p1)
    if kp < _KP_LIMIT:
        # the separatrix limit: K = ln(4/k') + (m1/4)(ln(4/k') - 1) + ... (A&S 17.3.26),
        # ln k' from its unrounded factors; Pi(n | m) = (K + sqrt(nu) atan sqrt(nu)) /
        # (1 + nu) (the m = 1 form at u = K, nu = -n; see _periodic_at)
        lk = _LN4 - log_kp
        kk = lk + 0.25 * m1 * (lk - 1.0)
        nu = -nchar
        snu = math.sqrt(nu)
        if prm[FORM] == 1.0:
            pic = (kk + snu * math.atan(snu)) / (1.0 + nu)
        else:
            pic = (snu * math.atan(snu) - nu * kk) / (1.0 + nu)
    else:
        kk = ellipk_m1(m1)
        pic = 0.0  # Pi(n | m) - K(m)
        if nchar != 0.0:
            pic = nchar / 3.0 * carlson_rj(0.0, m1, 1.0, 1.0 - nchar)
        if prm[FORM] == 1.0:  # the complete Pi(n | m) itself
            pic = kk + pic if nchar >= -1.0 else _pi_reduced(nchar, m, 1.0, 0.0, math.sqrt(m1))
    prm[A] = a
    prm[B] = sb * b
    prm[M] = m
    prm[M1] = m1
    prm[KP] = kp
    prm[K] = kk
    prm[PIC] = pic
    prm[RHO] = rho
    prm[SB] = sb
    # Initial phase u0 = F(phi0 | m), sn = omega2 / b, cn = omega1 / a.
    s0 = v2 / (sb * b)
    c0 = v1 / a
    h = math.hypot(s0, c0)
    s0 /= h
    c0 /= h
    if kp < _KP_LIMIT:
        # F(phi0 | m) in the separatrix limit (see jacobi_limit): sinh F = |sn / cn| up
        # to K/2 (cn^2 > k' there), else sinh(K - F) = |cn| / k'
        ac = abs(c0)
        if ac * ac > kp:
            f = _sign(s0) * math.asinh(abs(s0) / ac)
        else:
            f = _sign(s0) * (kk - math.asinh(ac / kp))
    else:
        dd = m1 + m * c0 * c0
        f = s0 * carlson_rf(c0 * c0, dd, 1.0)
    if c0 >= 0.0:
        u0 = f
    else:
        u0 = _sign(s0) * 2.0 * kk - f
    prm[U0] = u0
    _, _, _, pi0, alpha0 = _periodic_at(prm, u0)
    w1, w2, w3, _, _ = _periodic_at(prm, u0)
    return w1, w2, w3, pi0, alpha0


@njit(cache=True)
def _setup_separatrix(prm, j1, j2, j3, v1, v2, a, b):  # pragma: no cover - compiled
    """Write the slots of a motion on the separatrix; return omega_W, Pi and alpha
    at ``u0``."""
    sa = _sign(v1)
    prm[A] = sa * a
    prm[B] = sa * b
    prm[M] = 1.0
    prm[M1] = 0.0
    prm[RHO] = (j2 / j1) * math.sqrt(j1 * (j3 - j1) / (j2 * (j3 - j2)))
    prm[SB] = 1.0
    # sinh u0 = tanh / sech = (omega2 / b) / (omega1 / a)
    u0 = math.asinh((v2 / (sa * b)) / (v1 / (sa * a)))
    prm[U0] = u0
    return _separatrix_at(prm, u0)


@njit(cache=True)
def _setup_attitude(prm, q0, pm, j1, j2, j3, w1, w2, w3):  # pragma: no cover - compiled
    """Write C0 = q0 qP qa(0) and QPI = qP^-1 (qa(0) the shortest arc from e3 to
    l_W(0), from omega_W at u0)."""
    ell = prm[L]
    l1, l2, l3 = j1 * w1 / ell, j2 * w2 / ell, j3 * w3 / ell
    nq = math.sqrt((1.0 + l3) ** 2 + l1 * l1 + l2 * l2)
    qaw, qax, qay = (1.0 + l3) / nq, -l2 / nq, l1 / nq
    pw, px, py, pz = _quat_from_signed_permutation(pm)
    tw, tx, ty, tz = qmul(q0[0], q0[1], q0[2], q0[3], pw, px, py, pz)
    cw, cx_, cy_, cz_ = qmul(tw, tx, ty, tz, qaw, qax, qay, 0.0)
    prm[C0] = cw
    prm[C0 + 1] = cx_
    prm[C0 + 2] = cy_
    prm[C0 + 3] = cz_
    prm[QPI] = pw
    prm[QPI + 1] = -px
    prm[QPI + 2] = -py
    prm[QPI + 3] = -pz


@njit(cache=True)
def free_setup(moments, q0, w0):  # pragma: no cover - compiled
    """Reduce ``(moments (3,), q0 (4,) unit, omega0 (3,))`` to the parameter vector.

    Steady motion (:func:`is_steady`) keeps only ``KIND = 0``, ``W0`` and ``Q0``;
    otherwise the working frame (:func:`_polar_order`, :func:`_working_frame`),
    the elliptic parameters (:func:`_setup_shape` and :func:`_setup_periodic` or
    :func:`_setup_separatrix`) and the attitude constants
    (:func:`_setup_attitude`) fill the slots listed in the module docstring.
    """
    prm = np.zeros(NPARAM)
    for i in range(3):
        prm[W0 + i] = w0[i]
    for i in range(4):
        prm[Q0 + i] = q0[i]
    if is_steady(moments, w0):
        prm[KIND] = 0.0
        return prm
    order, kind = _polar_order(moments, w0)
    pm, j1, j2, j3, v1, v2, v3 = _working_frame(moments, w0, order)
    for i in range(3):
        for j in range(3):
            prm[P + 3 * i + j] = pm[i, j]
    a, b, p1, p3, dm = _setup_shape(prm, kind, j1, j2, j3, v1, v2, v3)
    if kind == 1.0:
        w1, w2, w3, pi0, alpha0 = _setup_periodic(prm, j1, j2, j3, v1, v2, v3, a, b, p1, p3,
                                                  dm)
    else:
        w1, w2, w3, pi0, alpha0 = _setup_separatrix(prm, j1, j2, j3, v1, v2, a, b)
    prm[PI0] = pi0
    prm[ALPHA0] = alpha0
    _setup_attitude(prm, q0, pm, j1, j2, j3, w1, w2, w3)
    return prm


@njit(cache=True)
def free_eval(prm, t, out_q, out_w):  # pragma: no cover - compiled
    """Evaluate ``prm`` at times ``t`` (n,) into ``out_q`` (n, 4) and ``out_w`` (n, 3)."""
    kind = prm[KIND]
    if kind == 0.0:
        w1, w2, w3 = prm[W0], prm[W0 + 1], prm[W0 + 2]
        wn = math.sqrt(w1 * w1 + w2 * w2 + w3 * w3)
        for i in range(t.shape[0]):
            out_w[i, 0] = w1
            out_w[i, 1] = w2
            out_w[i, 2] = w3
            if wn == 0.0:
                ew, ex, ey, ez = 1.0, 0.0, 0.0, 0.0
            else:
                half = 0.5 * wn * t[i]
                sh = math.sin(half) / wn
                ew, ex, ey, ez = math.cos(half), sh * w1, sh * w2, sh * w3
            qw, qx, qy, qz = qmul(
                prm[Q0], prm[Q0 + 1], prm[Q0 + 2], prm[Q0 + 3], ew, ex, ey, ez
            )
            out_q[i, 0] = qw
            out_q[i, 1] = qx
            out_q[i, 2] = qy
            out_q[i, 3] = qz
        return
    ell = prm[L]
    j1, j2, j3 = prm[J1], prm[J2], prm[J3]
    lam = prm[LAM]
    u0 = prm[U0]
    for i in range(t.shape[0]):
        ti = t[i]
        u = u0 + lam * ti
        if kind == 1.0:
            w1, w2, w3, pi_u, alpha = _periodic_at(prm, u)
        else:
            w1, w2, w3, pi_u, alpha = _separatrix_at(prm, u)
        # Precession angle about the invariable line, in the shortest-arc gauge:
        # Psi = (L/J3) t + L (J3 - J1)/(J1 J3 lam) [Pi(u) - Pi(u0)] - (alpha - alpha0).
        # Form B: with Pi(u) = u + D(u) and u - u0 = lam t the two secular terms add
        # up to (L/J1) t exactly (see free_setup for the choice of the form).
        sec = ell / j1 if prm[FORM] == 0.0 else ell / j3
        psi = sec * ti + prm[COEF] * (pi_u - prm[PI0]) - (alpha - prm[ALPHA0])
        l1, l2, l3 = j1 * w1 / ell, j2 * w2 / ell, j3 * w3 / ell
        nq = math.sqrt((1.0 + l3) ** 2 + l1 * l1 + l2 * l2)
        # qa^-1 qP^-1
        bw, bx, by, bz = qmul(
            (1.0 + l3) / nq, l2 / nq, -l1 / nq, 0.0,
            prm[QPI], prm[QPI + 1], prm[QPI + 2], prm[QPI + 3],
        )
        zw, zz = math.cos(0.5 * psi), math.sin(0.5 * psi)
        aw, ax, ay, az = qmul(prm[C0], prm[C0 + 1], prm[C0 + 2], prm[C0 + 3], zw, 0.0, 0.0, zz)
        qw, qx, qy, qz = qmul(aw, ax, ay, az, bw, bx, by, bz)
        out_q[i, 0] = qw
        out_q[i, 1] = qx
        out_q[i, 2] = qy
        out_q[i, 3] = qz
        for r in range(3):
            out_w[i, r] = prm[P + 3 * r] * w1 + prm[P + 3 * r + 1] * w2 + prm[P + 3 * r + 2] * w3


@njit(cache=True)
def free_flow(moments, q0, w0, t, out_q, out_w):  # pragma: no cover - compiled
    """Exact torque-free motion from ``(q0, w0)`` at times ``t``; see module docs."""
    prm = free_setup(moments, q0, w0)
    free_eval(prm, t, out_q, out_w)


@njit(cache=True)
def free_step(moments, q, w, h):  # pragma: no cover - compiled
    """Advance ``q`` (4,) and ``w`` (3,) in place by the exact free flow over ``h``.

    For use inside other kernels (the exact-flow-plus-kicks splitting).
    """
    tt = np.empty(1)
    tt[0] = h
    oq = np.empty((1, 4))
    ow = np.empty((1, 3))
    free_flow(moments, q, w, tt, oq, ow)
    for i in range(4):
        q[i] = oq[0, i]
    for i in range(3):
        w[i] = ow[0, i]
