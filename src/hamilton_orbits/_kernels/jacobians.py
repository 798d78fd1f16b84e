"""Jacobians of the accelerations: the right-hand side of the variational equations.

The first-order variational equations of ``r'' = a(r, v)`` are

    delta_r'' = (da/dr) delta_r + (da/dv) delta_v,

one copy per tangent vector.  A *tangent kernel* computes that product for ``k``
tangent vectors at once, never forming the 3n x 3n matrices: for each pair of
bodies the 3 x 3 block is built once and applied to every tangent vector
(``O(n^2 k)``, and for one tangent vector about the cost of one force
evaluation).

Signature
---------
``jac(r, v, gm, dr, dv, da, p)``: ``r``, ``v`` (n, 3) the state; ``dr``, ``dv``,
``da`` (k n, 3) the tangent vectors, row ``m n + i`` the displacement of body
``i`` in tangent vector ``m``; ``p`` the effect's own parameter vector (as its
acceleration kernel takes it).  The Newtonian kernel (:func:`newtonian_jvp`)
*overwrites* ``da``; effect kernels *add* to it, exactly as acceleration kernels
do with ``acc``.  Masses (``gm``) and parameters are not varied.

Effects without an analytic Jacobian are differentiated by central differences
along each tangent vector (:func:`fd_scales`, :func:`fd_shift`, :func:`fd_add`;
the loop that calls the effect's kernel is generated in
:mod:`hamilton_orbits.rhs`).  No astropy here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels.figures import about_pole_of_date
from hamilton_orbits._kernels.signatures import F1, F2, function_at

__all__ = [
    "FD_EPS",
    "TANGENT_SIGNATURE",
    "TANGENT_TYPE",
    "fd_add",
    "fd_scales",
    "fd_shift",
    "gr_anderson_jvp",
    "gr_potential_jvp",
    "j2_field_jvp",
    "lense_thirring_jvp",
    "newtonian_jvp",
    "tangent_at",
    "zero_jvp",
    "zonal_field_jvp",
    "zonal_of_date_jvp",
]

#: ``void(r, v, gm, dr, dv, da, p)``
TANGENT_SIGNATURE = types.void(F2, F2, F1, F2, F2, F2, F1)

#: The first-class function type of a tangent right-hand side.
TANGENT_TYPE = types.FunctionType(TANGENT_SIGNATURE)

#: ``tangent_at(c_addr, jit_addr)``: the tangent right-hand side at those addresses
#: (see :mod:`hamilton_orbits._kernels.signatures`).
tangent_at = function_at(TANGENT_TYPE)


@njit(cache=True, error_model="numpy")
def zero_jvp(r, v, gm, dr, dv, da):  # pragma: no cover - compiled
    """Overwrites ``da`` with zeros (the start of a tangent right-hand side whose
    effects compute the point-mass interaction themselves)."""
    for a in range(da.shape[0]):
        da[a, 0] = 0.0
        da[a, 1] = 0.0
        da[a, 2] = 0.0


@njit(inline="always", cache=True, error_model="numpy")
def _apply_sym(t00, t01, t02, t11, t12, t22, ex, ey, ez):  # pragma: no cover - compiled
    """The symmetric 3 x 3 matrix ``t`` times ``e``."""
    return (t00 * ex + t01 * ey + t02 * ez, t01 * ex + t11 * ey + t12 * ez,
            t02 * ex + t12 * ey + t22 * ez)


@njit(cache=True, error_model="numpy")
def newtonian_jvp(r, v, gm, dr, dv, da):  # pragma: no cover - compiled
    """The Jacobian of Hamilton's equation (B) applied to every tangent vector;
    overwrites ``da``.

    With ``d = r_j - r_i`` and ``T = (I - 3 d d^T / |d|^2) / |d|^3`` (symmetric),
    ``a_i = sum_j gm_j d / |d|^3`` varies by ``gm_j T (delta r_j - delta r_i)`` and
    ``a_j`` by the opposite times ``gm_i``.  Pairs of massless bodies are skipped.
    """
    n = r.shape[0]
    k = dr.shape[0] // n
    for a in range(da.shape[0]):
        da[a, 0] = 0.0
        da[a, 1] = 0.0
        da[a, 2] = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            gi = gm[i]
            gj = gm[j]
            if gi == 0.0 and gj == 0.0:
                continue
            dx = r[j, 0] - r[i, 0]
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            d2 = dx * dx + dy * dy + dz * dz
            inv1 = 1.0 / np.sqrt(d2)  # one division per pair
            inv2 = inv1 * inv1
            inv3 = inv2 * inv1
            c = -3.0 * inv3 * inv2
            t00 = inv3 + c * dx * dx
            t11 = inv3 + c * dy * dy
            t22 = inv3 + c * dz * dz
            t01 = c * dx * dy
            t02 = c * dx * dz
            t12 = c * dy * dz
            for m in range(k):
                ai = m * n + i
                aj = m * n + j
                tx, ty, tz = _apply_sym(t00, t01, t02, t11, t12, t22, dr[aj, 0] - dr[ai, 0],
                                        dr[aj, 1] - dr[ai, 1], dr[aj, 2] - dr[ai, 2])
                da[ai, 0] += gj * tx
                da[ai, 1] += gj * ty
                da[ai, 2] += gj * tz
                da[aj, 0] -= gi * tx
                da[aj, 1] -= gi * ty
                da[aj, 2] -= gi * tz


@njit(inline="always", cache=True, error_model="numpy")
def _push_pair(da, ai, as_, x, y, z, back):  # pragma: no cover - compiled
    """Add ``x, y, z`` to row ``ai`` and the reaction ``-back (x, y, z)`` to ``as_``."""
    da[ai, 0] += x
    da[ai, 1] += y
    da[ai, 2] += z
    da[as_, 0] -= back * x
    da[as_, 1] -= back * y
    da[as_, 2] -= back * z


@njit(cache=True, error_model="numpy")
def gr_potential_jvp(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled
    """Jacobian of :func:`hamilton_orbits._kernels.nbody.gr_potential` (adds).

    ``a = f d`` with ``f = -6 mu^2 / (c^2 |d|^4)`` gives
    ``da/dd = f (I - 4 d d^T / |d|^2)``; the source receives ``-(gm_i / mu)``
    times the change.
    """
    s = int(p[0])
    c2 = p[1] * p[1]
    mu = gm[s]
    n = r.shape[0]
    k = dr.shape[0] // n
    for i in range(n):
        if i == s:
            continue
        dx = r[i, 0] - r[s, 0]
        dy = r[i, 1] - r[s, 1]
        dz = r[i, 2] - r[s, 2]
        d2 = dx * dx + dy * dy + dz * dz
        f = -6.0 * mu * mu / (c2 * d2 * d2)
        g = -4.0 * f / d2
        back = gm[i] / mu
        for m in range(k):
            ai = m * n + i
            as_ = m * n + s
            ex = dr[ai, 0] - dr[as_, 0]
            ey = dr[ai, 1] - dr[as_, 1]
            ez = dr[ai, 2] - dr[as_, 2]
            de = g * (dx * ex + dy * ey + dz * ez)
            _push_pair(da, ai, as_, f * ex + de * dx, f * ey + de * dy, f * ez + de * dz, back)


@njit(cache=True, error_model="numpy")
def gr_anderson_jvp(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled
    """Jacobian of :func:`hamilton_orbits._kernels.nbody.gr_anderson` (adds).

    ``a = f [(4 mu/|d| - w^2) d + 4 (d.w) w]`` with ``f = mu / (c^2 |d|^3)``, ``d``,
    ``w`` relative to the source.  With ``e``, ``u`` the relative tangent
    displacements and ``A`` the bracket,

        delta a = -3 f (d.e)/|d|^2 A + f [(4 mu/|d| - w^2) e - 4 mu (d.e)/|d|^3 d
                  + 4 (e.w) w] + f [-2 (w.u) d + 4 (d.u) w + 4 (d.w) u].
    """
    s = int(p[0])
    c2 = p[1] * p[1]
    mu = gm[s]
    n = r.shape[0]
    k = dr.shape[0] // n
    for i in range(n):
        if i == s:
            continue
        dx = r[i, 0] - r[s, 0]
        dy = r[i, 1] - r[s, 1]
        dz = r[i, 2] - r[s, 2]
        wx = v[i, 0] - v[s, 0]
        wy = v[i, 1] - v[s, 1]
        wz = v[i, 2] - v[s, 2]
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        w2 = wx * wx + wy * wy + wz * wz
        dw = dx * wx + dy * wy + dz * wz
        f = mu / (c2 * d2 * d)
        q = 4.0 * mu / d - w2
        bx = q * dx + 4.0 * dw * wx
        by = q * dy + 4.0 * dw * wy
        bz = q * dz + 4.0 * dw * wz
        back = gm[i] / mu
        for m in range(k):
            ai = m * n + i
            as_ = m * n + s
            ex = dr[ai, 0] - dr[as_, 0]
            ey = dr[ai, 1] - dr[as_, 1]
            ez = dr[ai, 2] - dr[as_, 2]
            ux = dv[ai, 0] - dv[as_, 0]
            uy = dv[ai, 1] - dv[as_, 1]
            uz = dv[ai, 2] - dv[as_, 2]
            de = dx * ex + dy * ey + dz * ez
            ew = ex * wx + ey * wy + ez * wz
            wu = wx * ux + wy * uy + wz * uz
            du = dx * ux + dy * uy + dz * uz
            c_b = -3.0 * f * de / d2
            c_d = f * (-4.0 * mu * de / (d2 * d) - 2.0 * wu)
            c_w = f * 4.0 * (ew + du)
            c_u = f * 4.0 * dw
            _push_pair(da, ai, as_, c_b * bx + f * q * ex + c_d * dx + c_w * wx + c_u * ux,
                       c_b * by + f * q * ey + c_d * dy + c_w * wy + c_u * uy,
                       c_b * bz + f * q * ez + c_d * dz + c_w * wz + c_u * uz, back)


@njit(cache=True, error_model="numpy")
def j2_field_jvp(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled
    """Jacobian of :func:`hamilton_orbits._kernels.nbody.j2_field` (adds).

    ``a = f [g d + 2 z k]`` with ``f = -3/2 J2 mu R^2 / |d|^5``,
    ``g = 1 - 5 z^2 / |d|^2``, ``z = d.k``; along ``e``:

        delta a = -5 f (d.e)/|d|^2 [g d + 2 z k]
                  + f [g e + (10 z^2 (d.e)/|d|^4 - 10 z (k.e)/|d|^2) d + 2 (k.e) k].
    """
    b = int(p[0])
    j2 = p[1]
    rad2 = p[2] * p[2]
    kx = p[3]
    ky = p[4]
    kz = p[5]
    mu = gm[b]
    n = r.shape[0]
    k = dr.shape[0] // n
    for i in range(n):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        z = dx * kx + dy * ky + dz * kz
        f = -1.5 * j2 * mu * rad2 / (d2 * d2 * d)
        g = 1.0 - 5.0 * z * z / d2
        ax = g * dx + 2.0 * z * kx
        ay = g * dy + 2.0 * z * ky
        az = g * dz + 2.0 * z * kz
        back = gm[i] / mu
        for m in range(k):
            ai = m * n + i
            ab = m * n + b
            ex = dr[ai, 0] - dr[ab, 0]
            ey = dr[ai, 1] - dr[ab, 1]
            ez = dr[ai, 2] - dr[ab, 2]
            de = dx * ex + dy * ey + dz * ez
            ke = kx * ex + ky * ey + kz * ez
            c_a = -5.0 * f * de / d2
            c_d = f * (10.0 * z * z * de / (d2 * d2) - 10.0 * z * ke / d2)
            c_k = 2.0 * f * ke
            _push_pair(da, ai, ab, c_a * ax + f * g * ex + c_d * dx + c_k * kx,
                       c_a * ay + f * g * ey + c_d * dy + c_k * ky,
                       c_a * az + f * g * ez + c_d * dz + c_k * kz, back)


@njit(inline="always", cache=True, error_model="numpy")
def _cross(ax, ay, az, bx, by, bz):  # pragma: no cover - compiled
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(cache=True, error_model="numpy")
def lense_thirring_jvp(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled
    """Jacobian of :func:`hamilton_orbits._kernels.relativity.lense_thirring` (adds).

    ``a = F [G (d x w) + w x J]`` with ``F = f0 / |d|^3``, ``G = 3 (d.J) / |d|^2``;
    along ``(e, u)``:

        delta a = -3 F (d.e)/|d|^2 [G (d x w) + w x J]
                  + F [(3 (e.J)/|d|^2 - 6 (d.J)(d.e)/|d|^4) (d x w) + G (e x w)]
                  + F [G (d x u) + u x J].
    """
    b = int(p[0])
    f0 = (1.0 + p[2]) * gm[b] / (p[1] * p[1])
    jx = p[3]
    jy = p[4]
    jz = p[5]
    n = r.shape[0]
    k = dr.shape[0] // n
    for i in range(n):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        wx = v[i, 0] - v[b, 0]
        wy = v[i, 1] - v[b, 1]
        wz = v[i, 2] - v[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        big_f = f0 / (d2 * np.sqrt(d2))
        dj = dx * jx + dy * jy + dz * jz
        big_g = 3.0 * dj / d2
        hx, hy, hz = _cross(dx, dy, dz, wx, wy, wz)
        wjx, wjy, wjz = _cross(wx, wy, wz, jx, jy, jz)
        back = gm[i] / gm[b]
        for m in range(k):
            ai = m * n + i
            ab = m * n + b
            ex = dr[ai, 0] - dr[ab, 0]
            ey = dr[ai, 1] - dr[ab, 1]
            ez = dr[ai, 2] - dr[ab, 2]
            ux = dv[ai, 0] - dv[ab, 0]
            uy = dv[ai, 1] - dv[ab, 1]
            uz = dv[ai, 2] - dv[ab, 2]
            de = dx * ex + dy * ey + dz * ez
            c_a = -3.0 * big_f * de / d2
            c_h = big_f * (3.0 * (ex * jx + ey * jy + ez * jz) / d2 - 6.0 * dj * de / (d2 * d2))
            ewx, ewy, ewz = _cross(ex, ey, ez, wx, wy, wz)
            dux, duy, duz = _cross(dx, dy, dz, ux, uy, uz)
            ujx, ujy, ujz = _cross(ux, uy, uz, jx, jy, jz)
            fg = big_f * big_g
            _push_pair(da, ai, ab,
                       c_a * (big_g * hx + wjx) + c_h * hx + fg * (ewx + dux) + big_f * ujx,
                       c_a * (big_g * hy + wjy) + c_h * hy + fg * (ewy + duy) + big_f * ujy,
                       c_a * (big_g * hz + wjz) + c_h * hz + fg * (ewz + duz) + big_f * ujz,
                       back)


@njit(cache=True, error_model="numpy")
def zonal_field_jvp(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled
    """Jacobian of :func:`hamilton_orbits._kernels.figures.zonal_field` (adds).

    Per degree, ``a = C [alpha(s) d / |d|^(n+3) - beta(s) k / |d|^(n+2)]`` with
    ``C = mu J_n R^n``, ``alpha = (n + 1) P_n + s P_n'``, ``beta = P_n'``,
    ``s = d.k / |d|``.  Along ``e``, with ``s_e = (k.e)/|d| - s (d.e)/|d|^2``,
    ``alpha' = (n + 2) P_n' + s P_n''`` and ``beta' = P_n''``:

        delta a = C [alpha' s_e d / |d|^(n+3) + alpha e / |d|^(n+3)
                     - (n + 3) alpha (d.e) d / |d|^(n+5)
                     - beta' s_e k / |d|^(n+2) + (n + 2) beta (d.e) k / |d|^(n+4)],

    the Legendre derivatives by ``P''_(n+1) = P''_(n-1) + (2n + 1) P'_n``.
    """
    b = int(p[0])
    rad = p[1]
    kx = p[2]
    ky = p[3]
    kz = p[4]
    nmax = p.shape[0] - 5 + 1
    mu = gm[b]
    n_b = r.shape[0]
    k = dr.shape[0] // n_b
    for i in range(n_b):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        s = (dx * kx + dy * ky + dz * kz) / d
        # the coefficients of e, (d.e) d, s_e d, s_e k, (d.e) k summed over degrees
        c_e = 0.0
        c_dd = 0.0
        c_sd = 0.0
        c_sk = 0.0
        c_dk = 0.0
        p_prev, p_cur = 1.0, s
        dp_prev, dp_cur = 0.0, 1.0
        ddp_prev, ddp_cur = 0.0, 0.0
        scale = rad / d  # (R / d)^n / d^? built below
        for deg in range(2, nmax + 1):
            p_next = ((2 * deg - 1) * s * p_cur - (deg - 1) * p_prev) / deg
            dp_next = dp_prev + (2 * deg - 1) * p_cur
            ddp_next = ddp_prev + (2 * deg - 1) * dp_cur
            p_prev, p_cur = p_cur, p_next
            dp_prev, dp_cur = dp_cur, dp_next
            ddp_prev, ddp_cur = ddp_cur, ddp_next
            scale *= rad / d
            c = mu * p[5 + deg - 2] * scale  # mu J_n (R/d)^n
            alpha = (deg + 1) * p_cur + s * dp_cur
            alpha_p = (deg + 2) * dp_cur + s * ddp_cur
            # C / d^(n+3) = c / d^3 and C / d^(n+2) = c / d^2
            c_e += c * alpha / (d2 * d)
            c_dd -= c * (deg + 3) * alpha / (d2 * d2 * d)
            c_sd += c * alpha_p / (d2 * d)
            c_sk -= c * ddp_cur / d2
            c_dk += c * (deg + 2) * dp_cur / (d2 * d2)
        back = gm[i] / mu
        for m in range(k):
            ai = m * n_b + i
            ab = m * n_b + b
            ex = dr[ai, 0] - dr[ab, 0]
            ey = dr[ai, 1] - dr[ab, 1]
            ez = dr[ai, 2] - dr[ab, 2]
            de = dx * ex + dy * ey + dz * ez
            s_e = (kx * ex + ky * ey + kz * ez) / d - s * de / d2
            cd = c_dd * de + c_sd * s_e
            ck = c_sk * s_e + c_dk * de
            _push_pair(da, ai, ab, c_e * ex + cd * dx + ck * kx, c_e * ey + cd * dy + ck * ky,
                       c_e * ez + cd * dz + ck * kz, back)


# ---------------------------------------------------------------------------
# Central differences along a tangent vector, for effects without an analytic
# Jacobian.  The generated loop (rhs.py) calls, per tangent vector m and part
# (0: positions, 1: velocities): fd_shift(+1), kernel, fd_shift(-1), kernel, fd_add.

#: The relative size of a central-difference step: eps^(1/3), which balances the
#: truncation error (h^2) against the rounding error (eps / h).
FD_EPS = 6.055454452393343e-06


@njit(cache=True, error_model="numpy")
def fd_scales(r, v, gm):  # pragma: no cover - compiled
    """``(L, V)``: the shortest distance between two bodies one of which is massive,
    and the relative speed of that pair (at least 1e-6 of the largest speed), the
    scales against which a displacement of positions and of velocities is small.
    Bodies at one point (perturbers put together, as a made-up field of one point
    does) give no scale: a zero length would make every displacement zero, and the
    Jacobian with it."""
    n = r.shape[0]
    best = math.inf
    bi = 0
    bj = 0
    vmax = 0.0
    for i in range(n):
        vv = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
        if vv > vmax:
            vmax = vv
        for j in range(i + 1, n):
            if gm[i] == 0.0 and gm[j] == 0.0:
                continue
            d2 = ((r[j, 0] - r[i, 0]) ** 2 + (r[j, 1] - r[i, 1]) ** 2
                  + (r[j, 2] - r[i, 2]) ** 2)
            if 0.0 < d2 < best:
                best = d2
                bi = i
                bj = j
    w2 = (v[bj, 0] - v[bi, 0]) ** 2 + (v[bj, 1] - v[bi, 1]) ** 2 + (v[bj, 2] - v[bi, 2]) ** 2
    speed = max(np.sqrt(w2), 1e-6 * np.sqrt(vmax))
    if not speed > 0.0:
        speed = 1.0
    length = np.sqrt(best) if best < math.inf else 1.0
    return length, speed


@njit(cache=True, error_model="numpy")
def fd_shift(r, v, dr, dv, m, part, length, speed, sign, rs, vs, acc):  # pragma: no cover
    """``rs, vs = r + sign h dr_m, v`` (part 0) or ``r, v + sign h dv_m`` (part 1), with
    ``h`` such that the largest displacement is :data:`FD_EPS` of ``length``
    (``speed``); zeroes ``acc``.  Returns ``h`` (0 if the tangent vector has no
    such part)."""
    n = r.shape[0]
    src = dr if part == 0 else dv
    big = 0.0
    for i in range(n):
        for c in range(3):
            x = abs(src[m * n + i, c])
            if x > big:
                big = x
    h = 0.0
    if big > 0.0:
        h = FD_EPS * (length if part == 0 else speed) / big
    for i in range(n):
        for c in range(3):
            rs[i, c] = r[i, c]
            vs[i, c] = v[i, c]
            acc[i, c] = 0.0
            if part == 0:
                rs[i, c] += sign * h * src[m * n + i, c]
            else:
                vs[i, c] += sign * h * src[m * n + i, c]
    return h


@njit(cache=True, error_model="numpy")
def fd_add(ap, am, h, da, m):  # pragma: no cover - compiled
    """``da_m += (ap - am) / (2 h)`` (nothing when ``h`` is 0)."""
    if not h > 0.0:
        return
    n = ap.shape[0]
    f = 0.5 / h
    for i in range(n):
        for c in range(3):
            da[m * n + i, c] += f * (ap[i, c] - am[i, c])


@njit(cache=True)
def zonal_of_date_jvp(r, v, gm, dr, dv, da, p, t):  # pragma: no cover - compiled
    """Jacobian of :func:`hamilton_orbits._kernels.figures.zonal_of_date` (adds): that
    of :func:`zonal_field_jvp` about the pole of time ``t``."""
    zonal_field_jvp(r, v, gm, dr, dv, da, about_pole_of_date(p, t, 2))
