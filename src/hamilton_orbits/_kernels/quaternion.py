"""Compiled quaternion kernels: Hamilton's product and rotation on plain floats.

Scalar-first components ``(w, x, y, z)``.  The scalar building blocks
:func:`qmul` and :func:`qrot` are inlined into every kernel that needs them,
here and in other modules; the generalised ufuncs broadcast over leading
dimensions without copies.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hamilton_orbits._kernels._dispatch import lazy_guvectorize


@njit(inline="always", cache=True)
def qmul(aw, ax, ay, az, bw, bx, by, bz):  # pragma: no cover - compiled
    """Hamilton product ``a b`` of two quaternions given by components.

    With a = (s, alpha), b = (t, beta): ab = (st - alpha.beta, s beta + t alpha
    + alpha x beta), i.e. for pure vectors alpha beta = -alpha.beta + alpha x beta
    (Hamilton 1845; REFERENCES.md).
    """
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(inline="always", cache=True)
def _qrot_core(w, x, y, z, vx, vy, vz, n2):  # pragma: no cover - compiled
    cx = y * vz - z * vy
    cy = z * vx - x * vz
    cz = x * vy - y * vx
    ccx = y * cz - z * cy
    ccy = z * cx - x * cz
    ccz = x * cy - y * cx
    s = 2.0 / n2
    return (
        vx + s * (w * cx + ccx),
        vy + s * (w * cy + ccy),
        vz + s * (w * cz + ccz),
    )


# Inside these bounds on |q|^2 and |v|^2 (so max|q_i| in (5e-101, 1e100) and
# max|v_i| in (5e-91, 1e90)) every intermediate of _qrot_core (|q|^2 |v| at most,
# |v| 1e-90 |q|^2 at least) stays between 1e-290 and 1e290: no overflow, and no
# underflow that matters at the precision of the result.
_Q2_LO = 1e-200
_Q2_HI = 1e200
_V2_LO = 1e-180
_V2_HI = 1e180


@njit(inline="always", cache=True)
def qrot(w, x, y, z, vx, vy, vz):  # pragma: no cover - compiled
    """``q v q^-1`` for any nonzero ``q`` (the scale of ``q`` cancels).

    Uses v' = v + (2/|q|^2) (w (u x v) + u x (u x v)) with u the vector part,
    which for a unit quaternion is the familiar v + 2w(u x v) + 2u x (u x v).

    Quaternions and vectors of extreme magnitude are first scaled by powers of
    two (exact), q to max|q_i| in [1/2, 1) and v likewise, and the result is
    scaled back: full precision from 1e-308 to 1e308 (issue 7, item 4).  A
    result too large for a float is inf (the caller reports it); the zero
    quaternion gives NaN (callers check for it first).
    """
    n2 = w * w + x * x + y * y + z * z
    v2 = vx * vx + vy * vy + vz * vz
    if _Q2_LO < n2 < _Q2_HI and _V2_LO < v2 < _V2_HI:
        return _qrot_core(w, x, y, z, vx, vy, vz, n2)
    if w == 0.0 and x == 0.0 and y == 0.0 and z == 0.0:  # (2 / |q|^2 would divide by 0:
        nan = math.nan  # a ZeroDivisionError under numba's Python error model)
        return nan, nan, nan
    mv = max(max(abs(vx), abs(vy)), abs(vz))
    if mv == 0.0:
        return vx, vy, vz
    eq = math.frexp(max(max(abs(w), abs(x)), max(abs(y), abs(z))))[1]
    ev = math.frexp(mv)[1]
    w = math.ldexp(w, -eq)
    x = math.ldexp(x, -eq)
    y = math.ldexp(y, -eq)
    z = math.ldexp(z, -eq)
    rx, ry, rz = _qrot_core(
        w,
        x,
        y,
        z,
        math.ldexp(vx, -ev),
        math.ldexp(vy, -ev),
        math.ldexp(vz, -ev),
        w * w + x * x + y * y + z * z,
    )
    return math.ldexp(rx, ev), math.ldexp(ry, ev), math.ldexp(rz, ev)


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64[:])"], "(n),(n)->(n)", cache=True, nopython=True
)
def qmul_gufunc(a, b, out):  # pragma: no cover - compiled
    """Generalised ufunc: Hamilton product over leading dimensions."""
    w, x, y, z = qmul(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3])
    out[0] = w
    out[1] = x
    out[2] = y
    out[3] = z


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64[:])"], "(n),(m)->(m)", cache=True, nopython=True
)
def qrot_gufunc(q, v, out):  # pragma: no cover - compiled
    """Generalised ufunc: ``q v q^-1`` over leading dimensions."""
    x, y, z = qrot(q[0], q[1], q[2], q[3], v[0], v[1], v[2])
    out[0] = x
    out[1] = y
    out[2] = z


@njit(cache=True)
def qmul_flat(a, b, out):  # pragma: no cover - compiled
    """Hamilton products of rows of ``a`` and ``b`` (N, 4) into ``out`` (N, 4).

    Returns True if every component is finite.  An overflow is detected by
    accumulating ``component * 0`` (0 for finite values, NaN for inf), which
    keeps the loop branch-free; no floating-point flags reach numpy, so the
    common case needs no ``np.errstate``.
    """
    acc = 0.0
    for i in range(a.shape[0]):
        w, x, y, z = qmul(a[i, 0], a[i, 1], a[i, 2], a[i, 3], b[i, 0], b[i, 1], b[i, 2], b[i, 3])
        out[i, 0] = w
        out[i, 1] = x
        out[i, 2] = y
        out[i, 3] = z
        acc += (w + x + y + z) * 0.0
    return acc == 0.0


@njit(cache=True)
def rotate_flat(q, v, out):  # pragma: no cover - compiled
    """``q v q^-1`` for rows of ``q`` (N, 4) and ``v`` (N, 3) into ``out`` (N, 3).

    One pass that also validates: returns the first row index whose quaternion
    is zero or whose vector is not finite (``out`` is then incomplete), -2 if a
    rotated vector overflowed (or, rarely, three finite components summed past
    the largest float: the caller then checks properly), else -1.
    """
    acc = 0.0
    for i in range(q.shape[0]):
        w = q[i, 0]
        x = q[i, 1]
        y = q[i, 2]
        z = q[i, 3]
        vx = v[i, 0]
        vy = v[i, 1]
        vz = v[i, 2]
        if w == 0.0 and x == 0.0 and y == 0.0 and z == 0.0:
            return i
        if not (np.isfinite(vx) and np.isfinite(vy) and np.isfinite(vz)):
            return i
        rx, ry, rz = qrot(w, x, y, z, vx, vy, vz)
        acc += (rx + ry + rz) * 0.0  # 0 while finite, NaN once a component overflowed
        out[i, 0] = rx
        out[i, 1] = ry
        out[i, 2] = rz
    return -1 if acc == 0.0 else -2


@njit(cache=True)
def to_matrix_flat(q, out):  # pragma: no cover - compiled
    """Rotation matrices of ``q`` (N, 4) into ``out`` (N, 3, 3); any nonzero scale.

    Returns the index of the first zero quaternion (no rotation), else -1.
    """
    for i in range(q.shape[0]):
        w = q[i, 0]
        x = q[i, 1]
        y = q[i, 2]
        z = q[i, 3]
        if w == 0.0 and x == 0.0 and y == 0.0 and z == 0.0:
            return i
        n2 = w * w + x * x + y * y + z * z
        if not (1e-280 < n2 < 1e280):  # rescale tiny or huge quaternions (exactly)
            e = math.frexp(max(max(abs(w), abs(x)), max(abs(y), abs(z))))[1]
            w = math.ldexp(w, -e)
            x = math.ldexp(x, -e)
            y = math.ldexp(y, -e)
            z = math.ldexp(z, -e)
            n2 = w * w + x * x + y * y + z * z
        s = 2.0 / n2
        xx = s * x * x
        yy = s * y * y
        zz = s * z * z
        xy = s * x * y
        xz = s * x * z
        yz = s * y * z
        wx = s * w * x
        wy = s * w * y
        wz = s * w * z
        out[i, 0, 0] = 1.0 - (yy + zz)
        out[i, 0, 1] = xy - wz
        out[i, 0, 2] = xz + wy
        out[i, 1, 0] = xy + wz
        out[i, 1, 1] = 1.0 - (xx + zz)
        out[i, 1, 2] = yz - wx
        out[i, 2, 0] = xz - wy
        out[i, 2, 1] = yz + wx
        out[i, 2, 2] = 1.0 - (xx + yy)
    return -1


@njit(cache=True)
def from_matrix_flat(m, out):  # pragma: no cover - compiled
    """Unit quaternions (canonical sign, w >= 0) of rotation matrices ``m`` (N, 3, 3).

    Shepperd's method: take the largest of 1 + trace and 1 + 2 R_ii - trace to
    avoid dividing by a small number (Shepperd 1978, J. Guid. Control 1, 223).
    """
    for i in range(m.shape[0]):
        r00 = m[i, 0, 0]
        r11 = m[i, 1, 1]
        r22 = m[i, 2, 2]
        tr = r00 + r11 + r22
        k = 0
        big = tr
        if r00 > big:
            big = r00
            k = 1
        if r11 > big:
            big = r11
            k = 2
        if r22 > big:
            k = 3
        if k == 0:
            w = 1.0 + tr
            x = m[i, 2, 1] - m[i, 1, 2]
            y = m[i, 0, 2] - m[i, 2, 0]
            z = m[i, 1, 0] - m[i, 0, 1]
        elif k == 1:
            w = m[i, 2, 1] - m[i, 1, 2]
            x = 1.0 + 2.0 * r00 - tr
            y = m[i, 0, 1] + m[i, 1, 0]
            z = m[i, 0, 2] + m[i, 2, 0]
        elif k == 2:
            w = m[i, 0, 2] - m[i, 2, 0]
            x = m[i, 0, 1] + m[i, 1, 0]
            y = 1.0 + 2.0 * r11 - tr
            z = m[i, 1, 2] + m[i, 2, 1]
        else:
            w = m[i, 1, 0] - m[i, 0, 1]
            x = m[i, 0, 2] + m[i, 2, 0]
            y = m[i, 1, 2] + m[i, 2, 1]
            z = 1.0 + 2.0 * r22 - tr
        n = np.sqrt(w * w + x * x + y * y + z * z)
        if w < 0.0:
            n = -n
        out[i, 0] = w / n
        out[i, 1] = x / n
        out[i, 2] = y / n
        out[i, 3] = z / n
