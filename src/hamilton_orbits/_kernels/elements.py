"""Compiled kernels: state vectors <-> orbital elements for every conic.

Plain floats only (nothing here imports astropy).  The conventions (documented
in ``docs/elements.md``) in brief:

* ``p = h^2/mu`` (Hamilton's ``p = -beta^2/M``, seed eq. 16), ``inv_a = 2/r - v^2/mu``
  (vis viva, the reciprocal semi-major axis, 0 for the parabola), and
  ``1 - e^2 = p inv_a``.
* ``e`` is the length of the modern eccentricity vector when that is below 1/2
  (no cancellation for near-circular orbits) and ``sqrt(1 - p inv_a)`` above
  (no cancellation for near-radial orbits); ``e`` below ``4 eps`` is set to 0.
  The orbit is parabolic when ``|inv_a| <= 4 eps (2/r + v^2/mu)`` (vis viva's 0
  to within the rounding of its two terms, :func:`~hamilton_orbits._kernels.
  kepler.parabolic`; then ``inv_a = 0`` and ``e = 1``; a parabola propagated
  stays one), and radial when ``|r x v| <= 8 eps |r| |v|`` (then ``e = 1``,
  ``p = 0``).
* The true anomaly comes from ``e sin nu = (r.v) h / (mu r)`` and
  ``e cos nu = (h^2 - mu r)/(mu r)`` (an atan2, full relative precision near
  periapsis); the argument of latitude ``u`` is an atan2 of ``r`` in the node
  basis; ``argp = u - nu``.  So ``u`` is accurate to rounding even when ``e``
  or ``argp`` is not defined.
* Undefined angles are 0: ``lan`` for ``inc`` in {0, pi}, ``argp`` for ``e = 0``.
* Anomalies, mean anomaly and true anomaly lie in (-pi, pi]; ``lan``, ``argp``,
  ``u`` in [0, 2 pi).
* Radial orbits (``h = 0``): the line is put in the plane through it that is
  least inclined to the reference plane (``inc`` = |latitude of periapsis
  direction|), ``nu = pi``, the anomaly is E with ``r = a (1 - cos E)`` or F with
  ``r = |a| (cosh F - 1)``; the radial parabola has no finite mean motion and
  its anomaly and M are 0.

Output columns of :func:`state_to_elements` are listed in ``COLUMNS``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

# the column layout and the conic kinds are numba-free (for the Python side)
from hamilton_orbits._columns import (  # noqa: F401  (re-exported)
    CLASSICAL,
    COLUMNS,
    ELLIPSE,
    HYPERBOLA,
    NCLASSICAL,
    NCOL,
    ONE_ORBIT_SIZE,
    PARABOLA,
    RADIAL_ELLIPSE,
    RADIAL_HYPERBOLA,
    RADIAL_PARABOLA,
)
from hamilton_orbits._kernels._dispatch import parallel_kernel
from hamilton_orbits._kernels.kepler import (
    anomaly_from_nu,
    mean_from_anomaly,
    parabolic,
    sinh_minus_x,
    state_in_safe_range,
    state_scales,
    two_prod,
    x_minus_sin,
)

EPS = 2.220446049250313e-16
PI = math.pi
TWO_PI = 2.0 * math.pi
FOUR_PI = 4.0 * math.pi

_CIRC_TOL = 4.0 * EPS
# (a parabola: |1/a| below 4 eps of (2/r + v^2/mu), the rounding bound of vis viva
# (each term carries ~1.5 eps from the state's own rounding and the arithmetic),
# is indistinguishable from the parabola's 0: kepler.parabolic)
_RADIAL_TOL = 8.0 * EPS
# |r.v| below this many eps of |r| |v| near apoapsis: the sign of r.v is not
# fixed by the rounding of the state (and of r.v), so it is at apoapsis to its
# precision, and nu, E, M are +pi there (the documented (-pi, pi])
_APO_TOL = 4.0 * EPS


@njit(cache=True)
def wrap_2pi(x):  # pragma: no cover - compiled
    """``x`` reduced to [0, 2 pi)."""
    # fast path for -2 pi < x < 4 pi, bit for bit what the floored ``%`` below
    # gives (there fmod is exact: x, or x - 2 pi by Sterbenz's lemma); written
    # as selects, as the sign of x is a coin toss; NaN fails the test
    if -TWO_PI < x < FOUR_PI:
        y = x + (TWO_PI if x < 0.0 else (-TWO_PI if x >= TWO_PI else 0.0))
        return 0.0 if y >= TWO_PI else y
    y = x % TWO_PI
    if y >= TWO_PI:
        y = 0.0
    if y < 0.0:
        y += TWO_PI
        if y >= TWO_PI:
            y = 0.0
    return y


@njit(cache=True)
def wrap_pi(x):  # pragma: no cover - compiled
    """``x`` reduced to (-pi, pi]."""
    if -PI < x <= PI:
        return x
    y = wrap_2pi(x)
    if y > PI:
        y -= TWO_PI
    return y


@njit(cache=True)
def _node_basis(hx, hy, hz):  # pragma: no cover - compiled
    """From a unit normal: ``inc, lan`` and the node basis ``n`` (to the
    ascending node) and ``m = h x n``; ``lan = 0`` and ``n = x`` when the plane
    is the reference plane (the ascending node is undefined)."""
    rho = math.hypot(hx, hy)
    inc = math.atan2(rho, hz)
    if rho > 0.0:
        nx = -hy / rho
        ny = hx / rho
        lan = wrap_2pi(math.atan2(ny, nx))
    else:
        nx = 1.0
        ny = 0.0
        lan = 0.0
    mx = -hz * ny
    my = hz * nx
    mz = hx * ny - hy * nx
    return inc, lan, nx, ny, mx, my, mz


@njit(cache=True)
def _radial_normal(dx, dy, dz):  # pragma: no cover - compiled
    """Conventional unit normal for a radial orbit along unit ``d``: the plane
    through ``d`` least inclined to the reference plane (normal closest to +z);
    for ``d = +-z`` the normal is ``-y`` (node on +x)."""
    rho = math.hypot(dx, dy)
    if rho == 0.0:
        return 0.0, -1.0, 0.0
    return -dz * dx / rho, -dz * dy / rho, rho


@njit(cache=True)
def _hyperbolic_anomaly(sn, cn, e, em1):  # pragma: no cover - compiled
    """F from tanh(F/2) = sqrt((e-1)/(e+1)) tan(nu/2), with (sn, cn) = k (sin nu, cos nu).

    ``em1`` = e - 1 computed accurately by the caller; tan(nu/2) is taken as
    sn/(k + cn) (cn >= 0) or (k - cn)/sn (cn < 0), without cancellation.  A state
    whose rounding puts it on or beyond the asymptote gets the largest finite F
    of the same sign rather than NaN.
    """
    k = math.hypot(sn, cn)
    if cn >= 0.0:
        th = math.sqrt(em1 / (e + 1.0)) * (sn / (k + cn))
    elif sn != 0.0:
        th = math.sqrt(em1 / (e + 1.0)) * ((k - cn) / sn)
    else:  # nu = pi: beyond the asymptote by rounding (clamped below)
        th = 1.0
    if abs(th) >= 1.0:
        th = math.copysign(1.0 - EPS / 2.0, th)
    return 2.0 * math.atanh(th)


@njit(cache=True)
def _dot3_compensated(ax, ay, az, bx, by, bz):  # pragma: no cover - compiled
    """``a.b`` as if computed in twice the working precision (Ogita, Rump and
    Oishi, SIAM J. Sci. Comput. 26 (2005), algorithm Dot2): exact products by
    Dekker's splitting, TwoSum of the products, then the errors added.  Near
    periapsis r.v cancels (r is nearly perpendicular to v); this keeps its
    relative accuracy."""
    p1, e1 = two_prod(ax, bx)
    p2, e2 = two_prod(ay, by)
    p3, e3 = two_prod(az, bz)
    s = p1 + p2
    z = s - p1
    t = (p1 - (s - z)) + (p2 - z)
    s2 = s + p3
    z = s2 - s
    t += (s - (s2 - z)) + (p3 - z)
    return s2 + (t + (e1 + e2 + e3))


@njit(cache=True, inline="always")
def _rectilinear_anomaly(r, v2, rv, inv_a, mu, smu):  # pragma: no cover - compiled
    """``(anomaly, M, kind, tau)`` of a radial or quasi-rectilinear orbit
    (``e = 1``, ``inv_a != 0``): E with ``r = a (1 - cos E)``, ``cos E = 1 - r/a
    = r v^2/mu - 1``, ``sin E = r.v / sqrt(mu a)`` (F with ``r = |a| (cosh F -
    1)``, ``sinh F = r.v / sqrt(mu |a|)``), M = E - sin E (sinh F - F)."""
    c = r * v2 / mu - 1.0  # cos E (cosh F): 1 - r/a
    if inv_a > 0.0:
        anom = math.atan2(rv * math.sqrt(inv_a) / smu, c)  # sin E = r.v / sqrt(mu a)
        m = x_minus_sin(anom)
        kind = RADIAL_ELLIPSE
    else:
        anom = math.asinh(rv * math.sqrt(-inv_a) / smu)  # sinh F
        m = sinh_minus_x(anom)
        kind = RADIAL_HYPERBOLA
    n = smu * abs(inv_a) * math.sqrt(abs(inv_a))
    return anom, m, kind, m / n


@njit(cache=True, inline="always")
def _radial_elements(rx, ry, rz, r, v2, rv, inv_a, mu):  # pragma: no cover - compiled
    """The tuple of ``COLUMNS`` of a radial (rectilinear) orbit: e = 1, p = 0,
    the body at nu = pi, the plane through the line least inclined to the
    reference plane (:func:`_radial_normal`)."""
    dx = -rx / r
    dy = -ry / r
    dz = -rz / r
    nx_, ny_, nz_ = _radial_normal(dx, dy, dz)
    inc, lan, nx, ny, mx, my, mz = _node_basis(nx_, ny_, nz_)
    u = wrap_2pi(math.atan2(rx * mx + ry * my + rz * mz, rx * nx + ry * ny))
    argp = wrap_2pi(u - PI)
    if parabolic(inv_a, r, v2, mu):
        # radial parabola: time since collision t = sqrt(2/mu) r^1.5 / 3
        tau = math.sqrt(2.0 / mu) * r * math.sqrt(r) / 3.0
        if rv < 0.0:
            tau = -tau
        return 0.0, 1.0, 0.0, inc, lan, argp, PI, 0.0, 0.0, u, RADIAL_PARABOLA, tau
    anom, m, kind, tau = _rectilinear_anomaly(r, v2, rv, inv_a, mu, math.sqrt(mu))
    return 0.0, 1.0, inv_a, inc, lan, argp, PI, anom, m, u, kind, tau


@njit(cache=True, inline="always")
def _eccentricity(rx, ry, rz, vx, vy, vz, r, v2, rv, h, p, inv_a, mu):  # pragma: no cover
    """``(e, 1 - e, inv_a)`` of a non-radial orbit with the decisions of the
    module docstring (circular: e = 0; parabolic: inv_a = 0, e = 1; e rounding
    to 1 with inv_a != 0: quasi-rectilinear unless a parabola costs less).

    ``e = |e_vec|`` below 1/2, else ``e = 1 - (1 - e^2)/(1 + e)``: the nearest
    float to e, with 1 - e as accurate as ``1 - e^2 = p inv_a`` is
    (``sqrt(1 - w)`` can be an ulp off); both are cheap, so both are computed
    and one selected (no branch).  ``1 - e`` to the accuracy of p/a: near e = 1
    the float e holds 1 - e only to eps absolute, which would spoil the
    anomalies and M of near-parabolic orbits."""
    w = p * inv_a  # 1 - e^2
    f = v2 - mu / r
    ex = (f * rx - rv * vx) / mu
    ey = (f * ry - rv * vy) / mu
    ez = (f * rz - rv * vz) / mu
    ev = math.sqrt(ex * ex + ey * ey + ez * ez)
    ome_w = w / (1.0 + math.sqrt(max(1.0 - w, 0.0)))  # 1 - e, from 1 - e^2 = p/a
    ew = 1.0 - ome_w
    e = ev if ev < 0.5 else ew
    ome = 1.0 - ev if ev < 0.5 else ome_w
    if e <= _CIRC_TOL:
        e = 0.0
    if parabolic(inv_a, r, v2, mu):
        # 1/a = 2/r - v^2/mu is zero to within the rounding of its two terms
        inv_a = 0.0
        e = 1.0
    elif e == 1.0:
        # 1 - e^2 is below the resolution of e: keep the energy (a quasi-
        # rectilinear orbit) unless treating it as a parabola costs less
        if abs(inv_a) * r <= h / (r * math.sqrt(v2)):
            inv_a = 0.0
    return e, ome, inv_a


@njit(cache=True, inline="always")
def _plane(rx, ry, rz, hx, hy, hz, h):  # pragma: no cover - compiled
    """``(inc, lan, u)`` from the areal vector ``h = r x v`` (not normalised:
    inc, lan and u are angles, so fewer roundings and divisions than through
    the unit normal): ``n = (-hy, hx)/rho`` towards the ascending node (x when
    the plane is the reference plane: lan = 0), ``h x n = h m`` with ``m =
    (-hz ny, hz nx, rho)/h``, ``u = atan2(r.m, r.n)``."""
    rho = math.hypot(hx, hy)
    inc = math.atan2(rho, hz)
    if rho > 0.0:
        nx = -hy / rho
        ny = hx / rho
        lan = wrap_2pi(math.atan2(hx, -hy))
    else:
        nx = 1.0
        ny = 0.0
        lan = 0.0
    u = wrap_2pi(math.atan2(hz * (ry * nx - rx * ny) + rz * rho, h * (rx * nx + ry * ny)))
    return inc, lan, u


@njit(cache=True, inline="always")
def _conic_anomaly(p, e, ome, inv_a, nu, r, v2, rv, h, mu, smu, accurate):  # pragma: no cover
    """The anomaly (E, F or D by ``e``) of a non-radial orbit that is not
    quasi-rectilinear.

    Near apoapsis and around E = pi/2 of an eccentric orbit the half-angle
    form amplifies the rounding of nu by dE/dnu = r/b; there the vis-viva
    form e sin E = r.v/sqrt(mu a), e cos E = r v^2/mu - 1 is better, as
    inv_a has no cancellation (2/r and v^2/mu differ by r inv_a / 2).
    Estimated position errors (units of eps): |a sin E|/b for the first,
    (|a sin E|/r)^2 for the second; the vis-viva form only for e >= 1/2.
    Computed without branches (safe denominators where unused): whether
    e >= 1/2 is a coin toss in a batch."""
    ai = abs(inv_a)
    ok_sc = (e >= 0.5) & (ai != 0.0)
    ai_ = ai if ok_sc else 1.0
    e_ = e if ok_sc else 1.0
    aa = 1.0 / ai_
    s_ = rv * math.sqrt(ai_) / smu  # e sin E or e sinh F
    t_ = abs(s_) * aa / e_
    err_nu = t_ / math.sqrt(aa * p)
    err_sc = (t_ / r) * (t_ / r)
    use_sc = ok_sc & (err_sc < err_nu)
    if 0.0 < e < 1.0:
        # E = atan2(s_, r v^2/mu - 1) (vis viva), or by half angles
        # E = 2 atan2(sqrt(1-e) sin(nu/2), sqrt(1+e) cos(nu/2)) with the half
        # angles of nu straight from (sn, cn) = k (sin nu, cos nu), k > 0, as
        # tan(nu/2) = sn/(k + cn) for cn >= 0 and (k - cn)/sn for cn < 0 (no
        # cancellation in either, none of nu's rounding near apoapsis, and no
        # sin/cos calls); one atan2 call on selected arguments
        sn = rv * h
        cn = h * h - mu * r
        asn = abs(sn)
        big = max(asn, abs(cn))
        if 1e-150 < big < 1e150:
            k = math.sqrt(sn * sn + cn * cn)
        else:
            k = math.hypot(sn, cn)
        se = math.sqrt(ome) if accurate else math.sqrt(1.0 - e)
        ce = math.sqrt(2.0 - ome) if accurate else math.sqrt(1.0 + e)
        pos = cn >= 0.0
        y_half = se * sn if pos else math.copysign(se * (k - cn), sn)
        x_half = ce * (k + cn if pos else asn)
        y_ = s_ if use_sc else y_half
        x_ = r * v2 / mu - 1.0 if use_sc else x_half
        return (1.0 if use_sc else 2.0) * math.atan2(y_, x_)
    if use_sc and inv_a < 0.0:
        return math.asinh(s_ / e)
    if accurate and e > 1.0:
        return _hyperbolic_anomaly(rv * h, h * h - mu * r, e, -ome)
    return anomaly_from_nu(nu, e)


@njit(cache=True, inline="always")
def _anomaly_columns(p, e, ome, inv_a, nu, r, v2, rv, h, mu, accurate):  # pragma: no cover
    """``(anomaly, M, kind, tau)`` of a non-radial orbit (``accurate``: with
    ``1 - e = ome``, see :func:`state_to_elements_one`)."""
    smu = math.sqrt(mu)  # only here: the classical columns do not need it
    if e == 1.0 and inv_a != 0.0:  # quasi-rectilinear: as for the radial orbit
        return _rectilinear_anomaly(r, v2, rv, inv_a, mu, smu)
    anom = _conic_anomaly(p, e, ome, inv_a, nu, r, v2, rv, h, mu, smu, accurate)
    if e < 1.0 and -3.0 < anom < 3.0:
        # mean_from_anomaly without its 2 pi reduction (k = 0 here), bit for bit
        m = (ome if accurate else 1.0 - e) * anom + e * x_minus_sin(anom)
    elif accurate and e > 1.0:
        m = -ome * math.sinh(anom) + sinh_minus_x(anom)  # (e - 1) sinh F + (sinh F - F)
    elif accurate and 0.0 < e < 1.0:
        m = ome * anom + e * x_minus_sin(anom)  # |anom| <= pi here: no reduction
    else:
        m = mean_from_anomaly(anom, e)
    if e < 1.0:
        if abs(m) > abs(anom):
            # |M| <= |E| for |E| <= pi (e sin E has the sign of E): only the
            # rounding crosses it, and M of E = pi would leave (-pi, pi]
            m = anom
        kind = ELLIPSE
        n = smu * inv_a * math.sqrt(inv_a)
    elif e == 1.0:
        kind = PARABOLA
        q = 0.5 * p
        n = smu / (math.sqrt(2.0 * q) * q)
    else:
        kind = HYPERBOLA
        n = smu * (-inv_a) * math.sqrt(-inv_a)
    return anom, m, kind, m / n


@njit(cache=True)
def state_to_elements_one(
    rx, ry, rz, vx, vy, vz, mu, accurate=False, full=True
):  # pragma: no cover - compiled
    """Elements of one state; returns the tuple of ``COLUMNS``.

    With ``full=False`` the anomaly, M and tau of a non-radial orbit are NaN
    (not computed); every other column is the same.

    With ``accurate=False`` the anomaly and M are those of the element set as
    floats: computed with the float ``e``, so that ``(p, e, M)`` reproduce the
    state.  With ``accurate=True`` they use 1 - e to the accuracy of
    1 - e^2 = p/a instead, i.e. the true mean anomaly of the state; the two
    differ by ~eps/|1 - e| relative, which matters only near e = 1 (where a
    float e cannot hold 1 - e).  The time since periapsis (last column) is
    meaningful with ``accurate=True``.

    The pieces: :func:`_radial_elements` (``h = 0``), :func:`_eccentricity`,
    :func:`_plane`, the true anomaly, then :func:`_anomaly_columns`.
    """
    r2 = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r2)
    v2 = vx * vx + vy * vy + vz * vz
    if accurate:  # the time since periapsis: r.v to full relative precision
        rv = _dot3_compensated(rx, ry, rz, vx, vy, vz)
    else:
        rv = rx * vx + ry * vy + rz * vz
    hx = ry * vz - rz * vy
    hy = rz * vx - rx * vz
    hz = rx * vy - ry * vx
    h = math.sqrt(hx * hx + hy * hy + hz * hz)
    inv_a = 2.0 / r - v2 / mu
    if h <= _RADIAL_TOL * r * math.sqrt(v2):
        # + 0.0: r.v = -0.0 at the apex is +0.0, so that E there is +pi, not -pi
        return _radial_elements(rx, ry, rz, r, v2, rv + 0.0, inv_a, mu)
    p = h * h / mu
    e, ome, inv_a = _eccentricity(rx, ry, rz, vx, vy, vz, r, v2, rv, h, p, inv_a, mu)
    inc, lan, u = _plane(rx, ry, rz, hx, hy, hz, h)
    cn = h * h - mu * r
    if cn < 0.0 and abs(rv) <= _APO_TOL * r * math.sqrt(v2):
        # at apoapsis to the state's rounding (r.v = -0.0 there too): nu, the
        # anomaly and M are +pi, as documented ((-pi, pi]), not the -pi of a
        # state rounded a hair past it
        rv = 0.0
    if e == 0.0:
        nu = wrap_pi(u)
        argp = 0.0
    else:
        nu = math.atan2(rv * h, cn)  # (e sin nu, e cos nu) mu r / h
        argp = wrap_2pi(u - nu)
    if not full:
        if e == 1.0 and inv_a != 0.0:
            kind = RADIAL_ELLIPSE if inv_a > 0.0 else RADIAL_HYPERBOLA
        else:
            kind = ELLIPSE if e < 1.0 else (PARABOLA if e == 1.0 else HYPERBOLA)
        return p, e, inv_a, inc, lan, argp, nu, math.nan, math.nan, u, kind, math.nan
    anom, m, kind, tau = _anomaly_columns(p, e, ome, inv_a, nu, r, v2, rv, h, mu, accurate)
    return p, e, inv_a, inc, lan, argp, nu, anom, m, u, kind, tau


@njit(cache=True)
def state_to_elements_scaled(
    rx, ry, rz, vx, vy, vz, mu, accurate=False, full=True
):  # pragma: no cover - compiled
    """:func:`state_to_elements_one` on the state scaled to order 1
    (:func:`hamilton_orbits._kernels.kepler.state_scales`): ``p``, ``inv_a`` and
    the time are scaled back exactly, every other column is scale-free."""
    er, ev, ok = state_scales(rx, ry, rz, vx, vy, vz, mu)
    if not ok:  # e beyond 2^MAX_E_EXPONENT: NaN row, refused by the caller
        nan = math.nan
        return nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan
    # one call of state_to_elements_one on the (possibly) scaled state, not one
    # call per branch (two copies of the large function in one body measured
    # ~5% slower in the batch kernels, 1e6 orbits on one thread)
    scaled = er != 0 or ev != 0
    if scaled:
        rx = math.ldexp(rx, -er)
        ry = math.ldexp(ry, -er)
        rz = math.ldexp(rz, -er)
        vx = math.ldexp(vx, -ev)
        vy = math.ldexp(vy, -ev)
        vz = math.ldexp(vz, -ev)
        mu = math.ldexp(mu, -er - 2 * ev)
    p, e, inv_a, inc, lan, argp, nu, anom, m, u, kind, tau = state_to_elements_one(
        rx, ry, rz, vx, vy, vz, mu, accurate, full
    )
    if scaled:
        p = math.ldexp(p, er)
        inv_a = math.ldexp(inv_a, -er)
        tau = math.ldexp(tau, er - ev)
    return p, e, inv_a, inc, lan, argp, nu, anom, m, u, kind, tau


@parallel_kernel
def state_to_elements(r, v, mu, out):  # pragma: no cover - compiled
    """Rows of ``r`` (N, 3), ``v`` (N, 3), ``mu`` (N,) into ``out`` (N, NCOL)."""
    for i in prange(r.shape[0]):
        res = state_to_elements_scaled(
            r[i, 0], r[i, 1], r[i, 2], v[i, 0], v[i, 1], v[i, 2], mu[i]
        )
        for j in range(NCOL):
            out[i, j] = res[j]


# state_to_elements_one inlined at numba's IR level where it is called with
# constant flags (the classical columns): the branches on ``accurate`` and
# ``full`` then fold away and the tuple never leaves registers.  Measured on one
# thread, 1e6 orbits against the minimal kernel of benchmarks/bench_overhead.py:
# 1.06x inlined against 1.17x as a call; with the range test inline and the
# scaling path a call only where the test fails, 1.035x.
_elements_one_inlined = njit(inline="always")(state_to_elements_one.py_func)


@njit(cache=True)
def classical_one(rx, ry, rz, vx, vy, vz, mu):  # pragma: no cover - compiled
    """One orbit's ``CLASSICAL`` columns: those of :func:`state_to_elements_one`
    with ``full=False`` (bit for bit the full kernel's), then ``a``.

    ``a = 1/inv_a`` (``inf`` for the parabolas, ``inv_a = 0``).  ``a`` is NaN when
    another column is not finite or ``a`` is infinite for an orbit that is not a
    parabola: the state's elements do not fit in float64, and the caller takes
    the general path, which names the arguments.  So nothing out of this kernel
    needs a floating-point-error guard.
    """
    if state_in_safe_range(rx, ry, rz, vx, vy, vz, mu):  # the common case: inlined
        p, e, inv_a, inc, lan, argp, nu, _anom, _m, _u, kind, _tau = _elements_one_inlined(
            rx, ry, rz, vx, vy, vz, mu, False, False
        )
    else:  # scaled first (a NaN row if e is beyond 2^MAX_E_EXPONENT): a call
        p, e, inv_a, inc, lan, argp, nu, _anom, _m, _u, kind, _tau = state_to_elements_scaled(
            rx, ry, rz, vx, vy, vz, mu, False, False
        )
    if inv_a == 0.0:
        a = math.inf if kind == PARABOLA or kind == RADIAL_PARABOLA else math.nan
    else:
        a = 1.0 / inv_a
        if not math.isfinite(a):
            a = math.nan
    s = p + e + inv_a + inc + lan + argp + nu
    if s - s != 0.0:  # NaN for any inf or NaN
        a = math.nan
    return p, e, inv_a, inc, lan, argp, nu, a


_classical_inlined = njit(inline="always")(classical_one.py_func)


@parallel_kernel
def state_to_elements_classical(r, v, mu, out):  # pragma: no cover - compiled
    """Rows of :func:`classical_one` into ``out`` (N, NCLASSICAL): the
    ``CLASSICAL`` columns, ``a`` NaN where it or another column is beyond float64.

    Returns the number of rows with such a NaN ``a`` (0 in the common case), so
    that the caller needs no second pass over ``out`` to find out (it then
    names the first such row, or refuses to read ``a`` there).
    """
    bad = 0
    for i in prange(r.shape[0]):
        p, e, inv_a, inc, lan, argp, nu, a = _classical_inlined(
            r[i, 0], r[i, 1], r[i, 2], v[i, 0], v[i, 1], v[i, 2], mu[i]
        )
        # one store per column (no loop over a tuple: faster under parallel=True)
        out[i, 0] = p
        out[i, 1] = e
        out[i, 2] = inv_a
        out[i, 3] = inc
        out[i, 4] = lan
        out[i, 5] = argp
        out[i, 6] = nu
        out[i, 7] = a
        if a != a:
            bad += 1
    return bad


@parallel_kernel
def state_to_time_since_periapsis(r, v, mu, out):  # pragma: no cover - compiled
    """Time since periapsis of rows of ``r``, ``v`` (N, 3), ``mu`` (N,) into ``out`` (N,).

    Uses the true mean anomaly (``accurate=True``): exact to the state's rounding
    also for near-parabolic orbits, continuous across e = 1.
    """
    for i in prange(r.shape[0]):
        res = state_to_elements_scaled(
            r[i, 0], r[i, 1], r[i, 2], v[i, 0], v[i, 1], v[i, 2], mu[i], True
        )
        out[i] = res[NCOL - 1]


@njit(inline="always")
def state_valid(rx, ry, rz, vx, vy, vz, mu):  # pragma: no cover - compiled
    """Whether a state is one an orbit can be built from: every value finite,
    ``mu > 0`` and ``r != 0`` (the one statement of the rule).

    Without branches (so that a loop over rows vectorises): ``0 * x`` is +-0
    for a finite x and NaN for inf or NaN, so the sum is 0 iff all are finite."""
    z = (rx * 0.0 + ry * 0.0 + rz * 0.0) + (vx * 0.0 + vy * 0.0 + vz * 0.0) + mu * 0.0
    return (z == 0.0) & (mu > 0.0) & ((rx != 0.0) | (ry != 0.0) | (rz != 0.0))


@parallel_kernel
def check_copy_state(r, v, mu, r_out, v_out, mu_out):  # pragma: no cover - compiled
    """Copy rows of ``r``, ``v`` (N, 3) and ``mu`` (N,) or (1,) (broadcast) into
    ``r_out``, ``v_out``, ``mu_out`` (N,) in one pass; return the number of rows
    that are not :func:`state_valid` (the caller then finds and names the first
    one)."""
    n = r.shape[0]
    one = mu.shape[0] == 1
    bad = 0
    for i in prange(n):
        rx = r[i, 0]
        ry = r[i, 1]
        rz = r[i, 2]
        vx = v[i, 0]
        vy = v[i, 1]
        vz = v[i, 2]
        m = mu[0] if one else mu[i]
        r_out[i, 0] = rx
        r_out[i, 1] = ry
        r_out[i, 2] = rz
        v_out[i, 0] = vx
        v_out[i, 1] = vy
        v_out[i, 2] = vz
        mu_out[i] = m
        bad += np.int64(not state_valid(rx, ry, rz, vx, vy, vz, m))
    return bad


@njit(cache=True)
def one_orbit(out, r, v, mu):  # pragma: no cover - compiled
    """One orbit given as plain floats, checked and its elements computed in one call.

    ``r``, ``v``: three floats each, as a float64 array or a tuple; ``mu`` a
    float.  ``out`` (``ONE_ORBIT_SIZE``,) receives the state ``rx, ry, rz,
    vx, vy, vz, mu`` and then, if the state is :func:`state_valid`, its
    ``CLASSICAL`` columns (:func:`classical_one`).  Returns 0 if the state is
    not valid (the caller then names the bad value), 1 if it is, 2 if it is
    but an element is beyond float64 (``a`` NaN: the caller then refuses it
    by name when it is read).  Checking a state costs about as much as
    computing its elements here, so one orbit's cost is one call, not two.
    """
    rx = r[0]
    ry = r[1]
    rz = r[2]
    vx = v[0]
    vy = v[1]
    vz = v[2]
    out[0] = rx
    out[1] = ry
    out[2] = rz
    out[3] = vx
    out[4] = vy
    out[5] = vz
    out[6] = mu
    if not state_valid(rx, ry, rz, vx, vy, vz, mu):
        return 0
    p, e, inv_a, inc, lan, argp, nu, a = _classical_inlined(rx, ry, rz, vx, vy, vz, mu)
    out[7] = p
    out[8] = e
    out[9] = inv_a
    out[10] = inc
    out[11] = lan
    out[12] = argp
    out[13] = nu
    out[14] = a
    return 1 if a == a else 2


@njit(cache=True)
def elements_to_state_one(p, e, inv_a, inc, lan, argp, anom, mu):  # pragma: no cover
    """State from ``p, e`` and the anomaly (E, D or F by ``e``).

    The perifocal coordinates are taken from the anomaly, not from the true
    anomaly, because ``r = a ((1 - e) + 2 e sin^2(E/2))`` (and its hyperbolic
    and parabolic analogues) is a sum of terms of one sign, whereas
    ``p / (1 + e cos nu)`` cancels near the apoapsis of an eccentric orbit.
    ``e == 1`` with ``inv_a != 0`` is a rectilinear (or quasi-rectilinear,
    ``0 <= p`` below the resolution of ``e``) orbit with ``a = 1/inv_a``.
    Returns ``(rx, ry, rz, vx, vy, vz)``; NaN where no state exists (the
    radial parabola, ``p < 0``).
    """
    nan = math.nan
    smu = math.sqrt(mu)
    if e == 1.0 and inv_a == 0.0:
        # parabola: r = q (1 + D^2), x = q (1 - D^2), y = 2 q D
        if not (p > 0.0):
            return nan, nan, nan, nan, nan, nan
        q = 0.5 * p
        d = anom
        d2 = d * d
        x = q * (1.0 - d2)
        y = 2.0 * q * d
        k = math.sqrt(mu / p) / (1.0 + d2)  # sqrt(mu/p) (-sin nu, 1 + cos nu)
        vx_ = -2.0 * d * k
        vy_ = 2.0 * k
    elif e < 1.0 or (e == 1.0 and inv_a > 0.0):
        if e < 1.0:
            a = p / ((1.0 - e) * (1.0 + e))
        else:
            a = 1.0 / inv_a
        if not (a > 0.0) or not (p >= 0.0):
            return nan, nan, nan, nan, nan, nan
        sh = math.sin(0.5 * anom)
        s2 = 2.0 * sh * sh  # 1 - cos E
        se = math.sin(anom)
        r = a * ((1.0 - e) + e * s2)
        if not (r > 0.0):
            return nan, nan, nan, nan, nan, nan
        x = a * ((1.0 - e) - s2)  # a (cos E - e)
        y = math.sqrt(a * p) * se  # b sin E
        k = math.sqrt(mu * a) / r
        vx_ = -k * se
        vy_ = k * math.sqrt(p / a) * (1.0 - s2)
    else:
        if e > 1.0:
            a = p / ((e - 1.0) * (e + 1.0))  # |a|
        else:
            a = -1.0 / inv_a
        if not (a > 0.0) or not (p >= 0.0):
            return nan, nan, nan, nan, nan, nan
        sh = math.sinh(0.5 * anom)
        s2 = 2.0 * sh * sh  # cosh F - 1
        se = math.sinh(anom)
        r = a * ((e - 1.0) + e * s2)
        if not (r > 0.0) or not math.isfinite(r):
            return nan, nan, nan, nan, nan, nan
        x = a * ((e - 1.0) - s2)  # |a| (e - cosh F)
        y = math.sqrt(a * p) * se
        k = smu * math.sqrt(a) / r
        vx_ = -k * se
        vy_ = k * math.sqrt(p / a) * (1.0 + s2)
    cl = math.cos(lan)
    sl = math.sin(lan)
    if inc == PI:
        ci = -1.0
        si = 0.0
    else:
        ci = math.cos(inc)
        si = math.sin(inc)
    cw = math.cos(argp)
    sw = math.sin(argp)
    # node basis n = (cl, sl, 0), m = h x n = (-ci sl, ci cl, si);
    # periapsis P = cw n + sw m, Q = h x P = -sw n + cw m
    px = cw * cl - sw * ci * sl
    py = cw * sl + sw * ci * cl
    pz = sw * si
    qx = -sw * cl - cw * ci * sl
    qy = -sw * sl + cw * ci * cl
    qz = cw * si
    return (
        x * px + y * qx,
        x * py + y * qy,
        x * pz + y * qz,
        vx_ * px + vy_ * qx,
        vx_ * py + vy_ * qy,
        vx_ * pz + vy_ * qz,
    )


@njit(cache=True)
def elements_to_state_scaled(p, e, inv_a, inc, lan, argp, anom, mu):  # pragma: no cover
    """:func:`elements_to_state_one` with the lengths (``p``, or ``1/|inv_a|`` of
    a radial orbit) and ``mu`` scaled to order 1 by powers of two when they lie
    outside [1e-50, 1e50], and the state scaled back exactly (see
    :func:`hamilton_orbits._kernels.kepler.state_scales`)."""
    length = p if p > 0.0 else (1.0 / abs(inv_a) if inv_a != 0.0 else 1.0)
    if 1e-50 < length < 1e50 and 1e-50 < mu < 1e50 and abs(inv_a) < 1e50:
        return elements_to_state_one(p, e, inv_a, inc, lan, argp, anom, mu)
    if not (0.0 < length < math.inf) or not (0.0 < mu < math.inf):
        return elements_to_state_one(p, e, inv_a, inc, lan, argp, anom, mu)
    er = math.frexp(length)[1]
    ev = (math.frexp(mu)[1] - er) // 2
    x, y, z, a, b, c = elements_to_state_one(
        math.ldexp(p, -er), e, math.ldexp(inv_a, er), inc, lan, argp, anom,
        math.ldexp(mu, -er - 2 * ev),
    )
    return (
        math.ldexp(x, er), math.ldexp(y, er), math.ldexp(z, er),
        math.ldexp(a, ev), math.ldexp(b, ev), math.ldexp(c, ev),
    )


@parallel_kernel
def elements_to_state(el, mu, r_out, v_out):  # pragma: no cover - compiled
    """Rows of ``el`` (N, 7: p, e, inv_a, inc, lan, argp, anomaly) and ``mu``
    into ``r_out``, ``v_out`` (N, 3)."""
    for i in prange(el.shape[0]):
        x, y, z, a, b, c = elements_to_state_scaled(
            el[i, 0], el[i, 1], el[i, 2], el[i, 3], el[i, 4], el[i, 5], el[i, 6], mu[i]
        )
        r_out[i, 0] = x
        r_out[i, 1] = y
        r_out[i, 2] = z
        v_out[i, 0] = a
        v_out[i, 1] = b
        v_out[i, 2] = c


def empty_elements(n: int) -> np.ndarray:
    """An uninitialised (n, NCOL) output array."""
    return np.empty((n, NCOL))


def row_columns(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``r`` (n, 3), ``v`` (n, 3) and ``mu`` (n,) of state rows ``rows`` (n, 7), each
    C-ordered (a copy of the columns): the kernels above then see one type of array.
    The columns of many rows are strided views, of one row contiguous ones, and each
    layout compiled a kernel again (2-2.5 s of a first run that reads one orbit's
    elements and then many orbits')."""
    return (np.ascontiguousarray(rows[:, :3]), np.ascontiguousarray(rows[:, 3:6]),
            np.ascontiguousarray(rows[:, 6]))
