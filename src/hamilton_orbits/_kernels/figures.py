"""Extended bodies and tides for solar-system ephemerides, as effect kernels.

Every kernel has the effect signature ``f(r, v, gm, acc, p)`` and ADDS its
acceleration to ``acc``; ``p`` is the float64 parameter vector whose layout each
docstring gives (indices of bodies stored as floats).  Forces between a figure and
a point mass act on both: the point mass ``i`` receives ``a`` and the extended body
``b`` receives ``-(gm_i / gm_b) a``, so that the total momentum is conserved.

- :func:`zonal_field`: zonal harmonics J2..Jn of one body about its pole (the
  Earth's figure acting on the Moon and the other bodies);
- :func:`moon_figure`: the Moon's degree-2 figure (J2, C22) in a frame from the
  Earth-Moon geometry (Cassini's laws), acting on every other body;
- :func:`earth_tides`: the tides the Moon and the Sun raise on the Earth acting on
  the Moon, DE430/DE440's constant-time-lag model in three frequency bands;
- :func:`ring_field`: a uniform circular ring (the Kuiper belt as DE440 models it)
  centred on one body;
- :func:`precessed_pole`: the Earth's pole of date by the IAU 2006 precession;
- :func:`zonal_of_date`, :func:`earth_tides_of_date`: the effects' kernels, which
  know the time (``f(r, v, gm, acc, p, t)``): the two above about the Earth's
  pole of date, or about a fixed pole (:data:`OF_DATE` numbers lead ``p``).

No astropy here.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: arcseconds in a radian
_ARCSEC = np.pi / 648000.0

#: The numbers that lead the ``p`` of a kernel about the Earth's pole of date: 1
#: (0: the fixed pole that follows them), the days from J2000 (TDB) at the
#: simulation's time 0, then the rotation from the ICRS to the system's axes (3 x
#: 3, by rows).
OF_DATE = 11

#: The tilt (rad) of the Moon's orbit to the ecliptic below which :func:`moon_frame`
#: no longer takes the node from the orbit: the node is undefined at zero tilt (the
#: orbit normal along the ecliptic pole) and ill-conditioned near it, so the pole's
#: inclination to the ecliptic is scaled down with the tilt, to zero at zero tilt.
#: 1e-6 rad (0.2"): five orders of magnitude below the Moon's 5.1 deg, where the
#: node's direction is still good to 1e-10 rad (the rounding of the orbit normal).
MOON_NODE_TILT = 1e-6


@njit(cache=True, error_model="numpy")
def precessed_pole(t, out):  # pragma: no cover - compiled
    """The Earth's celestial intermediate pole of date without nutation, a unit
    vector in the GCRS (ICRS) axes into ``out`` (3,), at ``t`` Julian centuries of TT
    from J2000 (TDB serves: they differ by 2 ms).

    Its coordinates ``X``, ``Y`` are the polynomial part of the IAU 2006/2000A
    series (IERS Conventions 2010, eq. 5.16: the frame bias and the IAU 2006
    precession; the pole of ERFA's ``bp06`` to 0.13 mas), ``Z = sqrt(1 - X^2 -
    Y^2)``.  It moves 20" a year from the ICRS pole."""
    x = (-0.016617 + t * (2004.191898 + t * (-0.4297829 + t * (-0.19861834 + t * (
        0.000007578 + t * 0.0000059285))))) * _ARCSEC
    y = (-0.006951 + t * (-0.025896 + t * (-22.4072747 + t * (0.00190059 + t * (
        0.001112526 + t * 0.0000001358))))) * _ARCSEC
    out[0], out[1], out[2] = x, y, np.sqrt(1.0 - x * x - y * y)


@njit(inline="always", cache=True)
def _push(acc, i, b, ax, ay, az, back):  # pragma: no cover - compiled
    acc[i, 0] += ax
    acc[i, 1] += ay
    acc[i, 2] += az
    acc[b, 0] -= back * ax
    acc[b, 1] -= back * ay
    acc[b, 2] -= back * az


@njit(cache=True)
def zonal_field(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Zonal harmonics J2..Jn of body ``b`` about its pole ``k``, on every other body.

    ``p = [b, R, kx, ky, kz, J2, J3, ..., Jn]``.  With ``d`` the position relative to
    the body, ``s = d . k / |d|`` and ``mu = gm[b]``, the potential
    ``-mu / |d| sum_n J_n (R / |d|)^n P_n(s)`` gives

        a = sum_n mu J_n R^n / |d|^(n+2) [ ((n + 1) P_n(s) + s P_n'(s)) d / |d| - P_n'(s) k ]

    (Moyer 1971, eqs. 173-174, zonal part; Legendre polynomials by their recursion).
    """
    b = int(p[0])
    rad = p[1]
    kx = p[2]
    ky = p[3]
    kz = p[4]
    nmax = p.shape[0] - 5 + 1  # J2 .. Jnmax
    mu = gm[b]
    for i in range(r.shape[0]):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        s = (dx * kx + dy * ky + dz * kz) / d
        p_prev = 1.0  # P_0
        p_cur = s  # P_1
        dp_prev = 0.0  # P_0'
        dp_cur = 1.0  # P_1'
        ratio = rad / d  # (R / d)^n built up
        scale = ratio
        radial = 0.0
        polar = 0.0
        for n in range(2, nmax + 1):
            p_next = ((2 * n - 1) * s * p_cur - (n - 1) * p_prev) / n
            dp_next = dp_prev + (2 * n - 1) * p_cur
            p_prev, p_cur = p_cur, p_next
            dp_prev, dp_cur = dp_cur, dp_next
            scale *= ratio
            jn = p[5 + n - 2]
            radial += jn * scale * ((n + 1) * p_cur + s * dp_cur)
            polar += jn * scale * dp_cur
        f = mu / d2
        ar = f * radial / d
        _push(acc, i, b, ar * dx - f * polar * kx, ar * dy - f * polar * ky,
              ar * dz - f * polar * kz, gm[i] / mu)


@njit(inline="always", cache=True)
def _unit(x, y, z):  # pragma: no cover - compiled
    n = np.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n


@njit(cache=True)
def moon_frame(r, v, m, e, ex, ey, ez, inc):  # pragma: no cover - compiled
    """The Moon's principal axes ``(x, y, z)`` (a (3, 3) array, rows) from geometry.

    Cassini's laws: the spin pole ``z`` lies in the plane of the ecliptic pole
    ``(ex, ey, ez)`` and the normal of the Moon's orbit about the Earth, on the other
    side of the ecliptic pole, at the inclination ``inc`` (rad) from it; the long
    axis ``x`` points to the Earth, projected on the equator (the mean sub-Earth
    direction: optical and physical librations are left out).

    An orbit tilted by less than :data:`MOON_NODE_TILT` to the ecliptic has no
    well-defined node: ``z`` is then ``cos(inc) e - sin(inc) (t / MOON_NODE_TILT)
    p`` normalised, ``t`` the tilt's sine and ``p`` the unit vector towards the
    orbit normal in the ecliptic, so that the pole comes continuously to the
    ecliptic pole at zero tilt (the Moon's equator in its orbit's plane), where it
    was 0 / 0 (NaN).  Above that tilt the frame is the one of Cassini's laws, bit
    for bit.
    """
    dx = r[e, 0] - r[m, 0]
    dy = r[e, 1] - r[m, 1]
    dz = r[e, 2] - r[m, 2]
    wx = v[e, 0] - v[m, 0]
    wy = v[e, 1] - v[m, 1]
    wz = v[e, 2] - v[m, 2]
    hx = dy * wz - dz * wy
    hy = dz * wx - dx * wz
    hz = dx * wy - dy * wx
    he = hx * ex + hy * ey + hz * ez
    px = hx - he * ex  # towards the orbit normal, in the ecliptic
    py = hy - he * ey
    pz = hz - he * ez
    pn = np.sqrt(px * px + py * py + pz * pz)  # |h| times the tilt's sine
    scale = max(pn, MOON_NODE_TILT * np.sqrt(hx * hx + hy * hy + hz * hz))
    if scale > 0.0:  # (a unit vector above MOON_NODE_TILT, shorter below it)
        px, py, pz = px / scale, py / scale, pz / scale
    ci = np.cos(inc)
    si = np.sin(inc)
    zx, zy, zz = _unit(ci * ex - si * px, ci * ey - si * py, ci * ez - si * pz)
    dd = dx * zx + dy * zy + dz * zz
    xx, xy, xz = _unit(dx - dd * zx, dy - dd * zy, dz - dd * zz)
    out = np.empty((3, 3))
    out[0, 0] = xx
    out[0, 1] = xy
    out[0, 2] = xz
    out[1, 0] = zy * xz - zz * xy
    out[1, 1] = zz * xx - zx * xz
    out[1, 2] = zx * xy - zy * xx
    out[2, 0] = zx
    out[2, 1] = zy
    out[2, 2] = zz
    return out


@njit(cache=True)
def moon_figure(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The Moon's degree-2 figure (J2, C22) acting on every other body.

    ``p = [moon, earth, R, J2, C22, ex, ey, ez, inc]``: the Moon's radius, its
    unnormalised J2 and C22, the ecliptic pole and the mean inclination of the
    lunar equator to the ecliptic (rad) for :func:`moon_frame`.  In the Moon's
    principal axes, with ``mu = gm[moon]`` and ``q = (x, y, z)`` the body's
    position relative to the Moon, the potential
    ``mu R^2 / |q|^5 [-J2 (3 z^2 - |q|^2) / 2 + 3 C22 (x^2 - y^2)]`` gives

        a = -3/2 J2 mu R^2 / |q|^5 [(1 - 5 z^2/|q|^2) q + 2 z e_z]
            + 3 C22 mu R^2 [2 (x e_x - y e_y) / |q|^5 - 5 (x^2 - y^2) q / |q|^7].
    """
    m = int(p[0])
    e = int(p[1])
    rad2 = p[2] * p[2]
    j2 = p[3]
    c22 = p[4]
    axes = moon_frame(r, v, m, e, p[5], p[6], p[7], p[8])
    mu = gm[m]
    for i in range(r.shape[0]):
        if i == m:
            continue
        dx = r[i, 0] - r[m, 0]
        dy = r[i, 1] - r[m, 1]
        dz = r[i, 2] - r[m, 2]
        x = dx * axes[0, 0] + dy * axes[0, 1] + dz * axes[0, 2]
        y = dx * axes[1, 0] + dy * axes[1, 1] + dz * axes[1, 2]
        z = dx * axes[2, 0] + dy * axes[2, 1] + dz * axes[2, 2]
        q2 = dx * dx + dy * dy + dz * dz
        q5 = q2 * q2 * np.sqrt(q2)
        fj = -1.5 * j2 * mu * rad2 / q5
        g = 1.0 - 5.0 * z * z / q2
        fc = 3.0 * c22 * mu * rad2 / q5
        h = -5.0 * (x * x - y * y) / q2
        # body-frame components of the acceleration
        bx = fj * g * x + fc * (2.0 * x + h * x)
        by = fj * g * y + fc * (-2.0 * y + h * y)
        bz = fj * (g * z + 2.0 * z) + fc * h * z
        ax = bx * axes[0, 0] + by * axes[1, 0] + bz * axes[2, 0]
        ay = bx * axes[0, 1] + by * axes[1, 1] + bz * axes[2, 1]
        az = bx * axes[0, 2] + by * axes[1, 2] + bz * axes[2, 2]
        _push(acc, i, m, ax, ay, az, gm[i] / mu)


@njit(inline="always", cache=True)
def _delayed(x, y, z, u, w, s, tau):  # pragma: no cover - compiled
    """The position ``tau`` earlier, to second order in its length: ``r - tau v``
    rescaled to ``|r| - tau (r . v)/|r|``."""
    d = np.sqrt(x * x + y * y + z * z)
    target = d - tau * (x * u + y * w + z * s) / d
    px = x - tau * u
    py = y - tau * w
    pz = z - tau * s
    scale = target / np.sqrt(px * px + py * py + pz * pz)
    return px * scale, py * scale, pz * scale


@njit(inline="always", cache=True)
def _rotate(x, y, z, kx, ky, kz, angle):  # pragma: no cover - compiled
    """Rodrigues' rotation of ``(x, y, z)`` by ``angle`` about the unit axis ``k``."""
    c = np.cos(angle)
    s = np.sin(angle)
    kd = (kx * x + ky * y + kz * z) * (1.0 - c)
    return (x * c + (ky * z - kz * y) * s + kx * kd,
            y * c + (kz * x - kx * z) * s + ky * kd,
            z * c + (kx * y - ky * x) * s + kz * kd)


@njit(cache=True)
def _tide_band(rx, ry, rz, sx, sy, sz, kx, ky, kz, band):  # pragma: no cover - compiled
    """One frequency band of the tidal acceleration, without its factor
    ``3/2 k2j gm_T R^5 / (r^5 r*^5)``: band 0 long-period, 1 diurnal, 2 semi-diurnal
    (Folkner et al. 2014, eq. 32), ``r`` the Moon's and ``s`` the tide raiser's
    (delayed, rotated) positions relative to the Earth."""
    z = rx * kx + ry * ky + rz * kz
    zs = sx * kx + sy * ky + sz * kz
    qx = rx - z * kx  # rho
    qy = ry - z * ky
    qz = rz - z * kz
    qsx = sx - zs * kx  # rho*
    qsy = sy - zs * ky
    qsz = sz - zs * kz
    r2 = rx * rx + ry * ry + rz * rz
    rho2 = qx * qx + qy * qy + qz * qz
    rhos2 = qsx * qsx + qsy * qsy + qsz * qsz
    qq = qx * qsx + qy * qsy + qz * qsz
    if band == 0:
        sc = -5.0 * ((z * zs) ** 2 + 0.5 * rho2 * rhos2) / r2 + zs * zs + rhos2
        return (2.0 * zs * zs * z * kx + rhos2 * qx + sc * rx,
                2.0 * zs * zs * z * ky + rhos2 * qy + sc * ry,
                2.0 * zs * zs * z * kz + rhos2 * qz + sc * rz)
    if band == 1:
        sc = -10.0 * z * zs * qq / r2
        return (2.0 * (qq * zs * kx + z * zs * qsx) + sc * rx,
                2.0 * (qq * zs * ky + z * zs * qsy) + sc * ry,
                2.0 * (qq * zs * kz + z * zs * qsz) + sc * rz)
    sc = -5.0 * (qq * qq - 0.5 * rho2 * rhos2) / r2
    return (2.0 * qq * qsx - rhos2 * qx + sc * rx,
            2.0 * qq * qsy - rhos2 * qy + sc * ry,
            2.0 * qq * qsz - rhos2 * qz + sc * rz)


@njit(cache=True)
def earth_tides(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Tides raised on the Earth by the Moon and the Sun, acting on the Moon.

    ``p = [earth, moon, sun, R, omega, kx, ky, kz, k20, k21, k22, tau_O0, tau_O1,
    tau_O2, tau_R1, tau_R2]`` (``sun`` < 0: the Moon's tides only; ``omega`` the
    Earth's rotation rate in rad per time unit, ``k`` its pole).  For each tide
    raiser T and band j, its position relative to the Earth is taken ``tau_Oj``
    earlier and turned about the pole by ``omega tau_Rj`` (the Earth's rotation
    during the rotational lag; no turn for j = 0), and the Moon at ``r`` receives

        a = 3/2 k2j gm_T R^5 / (r^5 r*^5) {band j of [2 (r . r*) r* - (5 (r . r*)^2/r^2 - r*^2) r]}

    (Folkner et al. 2014, eq. 32; the three bands add up to the whole bracket);
    the Earth receives ``-(gm_moon / gm_earth) a``.
    """
    e = int(p[0])
    m = int(p[1])
    sun = int(p[2])
    r5 = p[3] ** 5
    omega = p[4]
    kx = p[5]
    ky = p[6]
    kz = p[7]
    rx = r[m, 0] - r[e, 0]
    ry = r[m, 1] - r[e, 1]
    rz = r[m, 2] - r[e, 2]
    rr2 = rx * rx + ry * ry + rz * rz
    ax = 0.0
    ay = 0.0
    az = 0.0
    for t in (m, sun):
        if t < 0:
            continue
        tx = r[t, 0] - r[e, 0]
        ty = r[t, 1] - r[e, 1]
        tz = r[t, 2] - r[e, 2]
        ux = v[t, 0] - v[e, 0]
        uy = v[t, 1] - v[e, 1]
        uz = v[t, 2] - v[e, 2]
        for band in range(3):
            sx, sy, sz = _delayed(tx, ty, tz, ux, uy, uz, p[11 + band])
            if band > 0:
                sx, sy, sz = _rotate(sx, sy, sz, kx, ky, kz, omega * p[13 + band])
            s2 = sx * sx + sy * sy + sz * sz
            f = 1.5 * p[8 + band] * gm[t] * r5 / (rr2 * rr2 * np.sqrt(rr2) * s2 * s2 * np.sqrt(s2))
            bx, by, bz = _tide_band(rx, ry, rz, sx, sy, sz, kx, ky, kz, band)
            ax += f * bx
            ay += f * by
            az += f * bz
    _push(acc, m, e, ax, ay, az, gm[m] / gm[e])


@njit(inline="always", cache=True)
def _ellipke(m):  # pragma: no cover - compiled
    """Complete elliptic integrals K(m), E(m) (parameter m = k^2 < 1) by the
    arithmetic-geometric mean (Abramowitz & Stegun 17.6)."""
    a = 1.0
    b = np.sqrt(1.0 - m)
    c2 = m  # c_0^2
    total = 0.5 * c2
    power = 0.5
    for _ in range(12):  # quadratic convergence: 6 iterations reach m = 0.999
        if abs(a - b) <= 1e-15 * a:  # (c_n^2 ~ 1e-30 adds nothing to E)
            break
        c = 0.5 * (a - b)
        a, b = 0.5 * (a + b), np.sqrt(a * b)
        power *= 2.0
        total += power * c * c
    k = np.pi / (2.0 * a)
    return k, k * (1.0 - total)


@njit(cache=True)
def ring_field(r, v, gm, acc, p):  # pragma: no cover - compiled
    """A uniform circular ring of GM ``M`` and radius ``R`` centred on body ``b``.

    ``p = [b, M, R, kx, ky, kz]`` (``k`` the normal of the ring's plane).  With
    ``z`` and ``rho`` a body's height and distance from the axis, ``D+^2 = (R +
    rho)^2 + z^2``, ``D-^2 = (R - rho)^2 + z^2`` and ``m = 4 R rho / D+^2``, the
    potential ``-2 M K(m) / (pi D+)`` gives (e.g. Fukushima 2010)

        a_z   = -2 M z E(m) / (pi D-^2 D+)
        a_rho = M / (pi rho D+) [E(m) (R^2 - rho^2 + z^2) / D-^2 - K(m)]    (towards +rho);

    the centre ``b`` receives ``-(gm_i / gm_b) a`` (the ring moves with it).  Within
    ``|d| < 0.15 R`` (the planets to Jupiter, the asteroids) the first two terms of
    the Legendre series of the potential, ``-M/R [1 - 1/2 (r/R)^2 P2 + 3/8 (r/R)^4 P4]``,
    stand in for the elliptic integrals: their truncation is < 1e-3 of the ring's
    field there (2.2e-3 at 0.2 R, falling as (r/R)^4), itself < 1e-10 of the Sun's.
    """
    b = int(p[0])
    big_m = p[1]
    rad = p[2]
    kx = p[3]
    ky = p[4]
    kz = p[5]
    for i in range(r.shape[0]):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        z = dx * kx + dy * ky + dz * kz
        d2 = dx * dx + dy * dy + dz * dz
        if d2 < 0.0225 * rad * rad:  # series: a = M/(2R^3) (d - 3 z k) + 3M/(64 R^5) [...]
            f1 = 0.5 * big_m / rad**3
            f2 = 3.0 * big_m / (64.0 * rad**5)
            ck = -3.0 * f1 * z + f2 * (140.0 * z**3 - 60.0 * z * d2)
            cd = f1 + f2 * (12.0 * d2 - 60.0 * z * z)
            _push(acc, i, b, cd * dx + ck * kx, cd * dy + ck * ky, cd * dz + ck * kz,
                  gm[i] / gm[b])
            continue
        qx = dx - z * kx
        qy = dy - z * ky
        qz = dz - z * kz
        rho = np.sqrt(qx * qx + qy * qy + qz * qz)
        dp2 = (rad + rho) ** 2 + z * z
        dm2 = (rad - rho) ** 2 + z * z
        dp = np.sqrt(dp2)
        kk, ee = _ellipke(4.0 * rad * rho / dp2)
        az = -2.0 * big_m * z * ee / (np.pi * dm2 * dp)
        if rho > 1e-12 * rad:
            arho = big_m / (np.pi * rho * dp) * (ee * (rad * rad - rho * rho + z * z) / dm2 - kk)
            fx = arho * qx / rho
            fy = arho * qy / rho
            fz = arho * qz / rho
        else:
            fx = 0.0
            fy = 0.0
            fz = 0.0
        _push(acc, i, b, fx + az * kx, fy + az * ky, fz + az * kz, gm[i] / gm[b])


@njit(cache=True, inline="always")
def about_pole_of_date(p, t, at):  # pragma: no cover - compiled
    """``p[OF_DATE:]``, a copy, its pole (3 numbers from ``at``) the Earth's at time
    ``t`` (days after the simulation's time 0) when ``p[0]`` is 1
    (:func:`precessed_pole` at ``p[1] + t`` days from J2000, turned into the
    system's axes by ``p[2:11]``)."""
    here = p[OF_DATE:].copy()
    if p[0] != 0.0:
        k = np.empty(3)
        precessed_pole((p[1] + t) / 36525.0, k)
        for i in range(3):
            here[at + i] = p[2 + 3 * i] * k[0] + p[3 + 3 * i] * k[1] + p[4 + 3 * i] * k[2]
    return here


@njit(cache=True)
def zonal_of_date(r, v, gm, acc, p, t):  # pragma: no cover - compiled
    """:func:`zonal_field` about the Earth's pole at time ``t`` (``p``:
    :data:`OF_DATE` numbers, then :func:`zonal_field`'s; a 0 first: its fixed
    pole, the same bits as :func:`zonal_field`)."""
    zonal_field(r, v, gm, acc, about_pole_of_date(p, t, 2))


@njit(cache=True)
def earth_tides_of_date(r, v, gm, acc, p, t):  # pragma: no cover - compiled
    """:func:`earth_tides` about the Earth's pole at time ``t`` (``p``:
    :data:`OF_DATE` numbers, then :func:`earth_tides`'s; a 0 first: its fixed
    pole)."""
    earth_tides(r, v, gm, acc, about_pole_of_date(p, t, 5))
