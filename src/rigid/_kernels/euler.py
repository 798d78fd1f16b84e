"""Compiled kernels for Euler's equations, the kinematics and the rigid-body integrators.

Plain floats in one consistent unit system (SI when the caller used Quantities);
no astropy.  Conventions of the ``rigid`` package: the attitude q carries body
vectors to space (v_s = q v_b q^-1), omega = (p, q, r) is the body-frame angular
velocity, dq/dt = q (0, omega) / 2 and A p' + (C - B) q r = N_x, cyclically
(Cayley 1843).

Torques are encoded as ``(kind, params)`` so that the whole time loop stays
inside one compiled function:

* ``TORQUE_NONE``: no torque.
* ``TORQUE_BODY``: constant body-frame torque ``params[0:3]``.
* ``TORQUE_SPACE``: constant space-frame torque ``params[0:3]`` (turned into the
  body frame by q^-1 N q).
* ``TORQUE_GRAVITY_GRADIENT``: the gravity-gradient torque of a point mass on a
  circular orbit, N = 3 (GM/R^3) c x (I c), c the unit vector from the body
  towards the primary in the body frame.  ``params = [GM/R^3, n, phase, e1 (3),
  e2 (3)]``: in space c_s(t) = cos(n t + phase) e1 + sin(n t + phase) e2.

All of these depend on (t, q) only, never on omega, so the "kick"
omega <- omega + I^-1 N(t, q) h with q frozen is the *exact* flow of the torque
part of the vector field; this is what makes the kick-drift-kick splittings
symplectic and of the stated order.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hamilton_orbits.quaternion_kernels import qmul, qrot
from hamilton_orbits.ufuncs import lazy_guvectorize

# (numba's cache of these kernels is keyed on this file alone: the exact-flow kernels
# they compile in from free.py are stale in a warm cache when free.py changes and this
# file does not; this line changed with free.py's separatrix limit, session 26, so
# that a pull of that change recompiles them too)
from rigid._kernels.free import free_step

TORQUE_NONE = 0
TORQUE_BODY = 1
TORQUE_SPACE = 2
TORQUE_GRAVITY_GRADIENT = 3


# --------------------------------------------------------------------------
# Scalar building blocks (inlined)
# --------------------------------------------------------------------------


@njit(inline="always", cache=True)
def euler_scalar(a, b, c, p, q, r, nx, ny, nz):  # pragma: no cover - compiled
    """Euler's equations: (p', q', r') from A p' + (C - B) q r = N_x, cyclically."""
    return (
        (nx - (c - b) * q * r) / a,
        (ny - (a - c) * r * p) / b,
        (nz - (b - a) * p * q) / c,
    )


@njit(inline="always", cache=True)
def qdot_scalar(w, x, y, z, p, q, r):  # pragma: no cover - compiled
    """Quaternion kinematics dq/dt = q (0, omega) / 2 (omega in the body frame)."""
    dw, dx, dy, dz = qmul(w, x, y, z, 0.0, p, q, r)
    return 0.5 * dw, 0.5 * dx, 0.5 * dy, 0.5 * dz


@njit(inline="always", cache=True)
def gibbs_dot_scalar(lam, mu, nu, p, q, r):  # pragma: no cover - compiled
    """Cayley's kinematic equations in Rodrigues' parameters (Cayley 1843, p. 228).

    2 lambda' = (1 + lambda^2) p + (lambda mu - nu) q + (nu lambda + mu) r,
    2 mu'     = (lambda mu + nu) p + (1 + mu^2) q + (mu nu - lambda) r,
    2 nu'     = (nu lambda - mu) p + (mu nu + lambda) q + (1 + nu^2) r.
    """
    return (
        0.5 * ((1.0 + lam * lam) * p + (lam * mu - nu) * q + (nu * lam + mu) * r),
        0.5 * ((lam * mu + nu) * p + (1.0 + mu * mu) * q + (mu * nu - lam) * r),
        0.5 * ((nu * lam - mu) * p + (mu * nu + lam) * q + (1.0 + nu * nu) * r),
    )


@njit(inline="always", cache=True)
def _circular_direction(params, t):  # pragma: no cover - compiled
    ang = params[1] * t + params[2]
    ca = math.cos(ang)
    sa = math.sin(ang)
    return (
        ca * params[3] + sa * params[6],
        ca * params[4] + sa * params[7],
        ca * params[5] + sa * params[8],
    )


@njit(inline="always", cache=True)
def torque_scalar(kind, params, a, b, c, t, w, x, y, z):  # pragma: no cover - compiled
    """Body-frame torque (N_x, N_y, N_z) of the encoded torque at time t, attitude q."""
    if kind == TORQUE_BODY:
        return params[0], params[1], params[2]
    if kind == TORQUE_SPACE:
        # body = q^-1 N q: rotate by the conjugate.
        return qrot(w, -x, -y, -z, params[0], params[1], params[2])
    if kind == TORQUE_GRAVITY_GRADIENT:
        sx, sy, sz = _circular_direction(params, t)
        cx, cy, cz = qrot(w, -x, -y, -z, sx, sy, sz)
        k = 3.0 * params[0]
        icx = a * cx
        icy = b * cy
        icz = c * cz
        return (
            k * (cy * icz - cz * icy),
            k * (cz * icx - cx * icz),
            k * (cx * icy - cy * icx),
        )
    return 0.0, 0.0, 0.0


# --------------------------------------------------------------------------
# Vectorised right-hand sides (generalised ufuncs)
# --------------------------------------------------------------------------


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64[:], float64[:])"],
    "(n),(n),(n)->(n)",
    cache=True,
    nopython=True,
)
def euler_gufunc(moments, omega, torque, out):  # pragma: no cover - compiled
    """d omega / dt from Euler's equations, over leading dimensions."""
    dp, dq, dr = euler_scalar(
        moments[0], moments[1], moments[2], omega[0], omega[1], omega[2],
        torque[0], torque[1], torque[2],
    )
    out[0] = dp
    out[1] = dq
    out[2] = dr


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64[:])"], "(n),(m)->(n)", cache=True, nopython=True
)
def qdot_gufunc(quat, omega, out):  # pragma: no cover - compiled
    """dq/dt = q (0, omega) / 2 over leading dimensions."""
    dw, dx, dy, dz = qdot_scalar(quat[0], quat[1], quat[2], quat[3], omega[0], omega[1], omega[2])
    out[0] = dw
    out[1] = dx
    out[2] = dy
    out[3] = dz


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64[:])"], "(n),(n)->(n)", cache=True, nopython=True
)
def gibbs_dot_gufunc(gibbs, omega, out):  # pragma: no cover - compiled
    """Cayley's d(lambda, mu, nu)/dt over leading dimensions."""
    a, b, c = gibbs_dot_scalar(gibbs[0], gibbs[1], gibbs[2], omega[0], omega[1], omega[2])
    out[0] = a
    out[1] = b
    out[2] = c


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64[:])"], "(n),(n)->(n)", cache=True, nopython=True
)
def gibbs_omega_gufunc(gibbs, gdot, out):  # pragma: no cover - compiled
    """Cayley's kappa p = 2 (lambda' + nu mu' - nu' mu), cyclically: omega from g, g'."""
    lam = gibbs[0]
    mu = gibbs[1]
    nu = gibbs[2]
    kap = 1.0 + lam * lam + mu * mu + nu * nu
    out[0] = 2.0 * (gdot[0] + nu * gdot[1] - gdot[2] * mu) / kap
    out[1] = 2.0 * (-nu * gdot[0] + gdot[1] + lam * gdot[2]) / kap
    out[2] = 2.0 * (mu * gdot[0] - lam * gdot[1] + gdot[2]) / kap


@lazy_guvectorize(
    ["void(float64[:], float64[:], float64, int64, float64[:], float64[:])"],
    "(n),(m),(),(),(k)->(n)",
    cache=True,
    nopython=True,
)
def torque_gufunc(moments, quat, t, kind, params, out):  # pragma: no cover - compiled
    """Body-frame torque of an encoded torque at time ``t`` and attitude ``quat`` (4,)."""
    nx, ny, nz = torque_scalar(
        kind, params, moments[0], moments[1], moments[2], t,
        quat[0], quat[1], quat[2], quat[3],
    )
    out[0] = nx
    out[1] = ny
    out[2] = nz


# --------------------------------------------------------------------------
# Lie-Poisson splitting of the free body, with torque kicks
# --------------------------------------------------------------------------
#
# A splitting method is a sequence of "ops" per step, built in Python
# (rigid.splitting.split_ops): op type 0, 1, 2 is the exact flow of
# g L_axis^2 / 2 (a rotation about that principal axis; g = 1 / I_axis in the
# plain splitting), type 3 the exact flow of the torque (a kick), type 4 that of
# the Casimir part g |L|^2 / 2 (a rotation of the attitude about L).  Rounding
# is kept at the level of one ulp per *run* rather than per op:
#
# * each rotation is applied as an increment, L <- L + ((cos t - 1) L_i +
#   sin t L_j, ...), with cos t - 1 = -2 sin^2(t/2) and 1 - cos(t/2) computed
#   directly (no cancellation), so the rotation matrix is orthogonal to
#   O(eps t^2) instead of O(eps): the plain c = cos t, s = sin t of libm give
#   c^2 + s^2 - 1 = O(eps) with a sign that persists while t changes slowly
#   (cos t is 1 - t^2/2 rounded the same way step after step), which made |L|
#   (hence the energy, hence the phase) drift systematically: 4e-12 after 2e7
#   steps of 7e-6 s, a 1e-9 error floor;
# * the state is carried as an unevaluated sum hi + lo (Kahan / Moller
#   compensated summation, with Knuth's branch-free TwoSum), so the rounding of
#   each increment's addition is fed back into the next one;
# * the state lives in registers inside the loop (arrays would make every
#   rotation wait for a store and a reload: ~3x slower).


SIN_C = (-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0, -1.0 / 39916800.0)
VERS_C = (-1.0 / 12.0, 1.0 / 360.0, -1.0 / 20160.0, 1.0 / 1814400.0, -1.0 / 239500800.0)


@njit(inline="always", cache=True)
def _two_sum(a, b):  # pragma: no cover - compiled
    """s = fl(a + b) and the exact rounding error e, a + b = s + e (Knuth)."""
    s = a + b
    bp = s - a
    ap = s - bp
    return s, (a - ap) + (b - bp)


@njit(inline="always", cache=True)
def sin_versin(x):  # pragma: no cover - compiled
    """(sin x, 1 - cos x), both to about an ulp *relative* (no cancellation).

    Taylor polynomials for |x| < 1/4 (truncation < 1e-17 relative, cheaper than
    two libm calls), else sin x and 2 sin^2(x/2).
    """
    ax = abs(x)
    if ax < 0.015625:
        # |x| < 1/64: the x^9 (sin) and x^8 (1 - cos) terms are below 1e-19 relative
        x2 = x * x
        x4 = x2 * x2
        ps = (SIN_C[0] + x2 * SIN_C[1]) + x4 * SIN_C[2]
        pv = (VERS_C[0] + x2 * VERS_C[1]) + x4 * VERS_C[2]
        return x + (x * x2) * ps, 0.5 * x2 + (0.5 * x4) * pv
    if ax < 0.25:
        # Estrin's scheme: shorter dependency chain than Horner (the loop is
        # latency bound: every rotation angle depends on the previous rotation)
        x2 = x * x
        x4 = x2 * x2
        x8 = x4 * x4
        ps = (SIN_C[0] + x2 * SIN_C[1]) + x4 * (SIN_C[2] + x2 * SIN_C[3]) + x8 * SIN_C[4]
        pv = (VERS_C[0] + x2 * VERS_C[1]) + x4 * (VERS_C[2] + x2 * VERS_C[3]) + x8 * VERS_C[4]
        return x + (x * x2) * ps, 0.5 * x2 + (0.5 * x4) * pv
    s2 = math.sin(0.5 * x)
    return math.sin(x), 2.0 * s2 * s2


@njit(inline="always", cache=True)
def _turn_pair(sh, vh, li, lj, ei, ej):  # pragma: no cover - compiled
    """(L_i, L_j) turned by -theta (sin theta/2 = sh, 1 - cos theta/2 = vh), compensated.

    Returns the new (L_i, L_j, e_i, e_j), e the compensation terms.  The
    increments (cos theta - 1) L_i + sin theta L_j = 2 sh (L_j - sh L_i - vh L_j)
    carry no O(eps) orthogonality error.
    """
    s2 = 2.0 * sh
    ni, ei = _two_sum(li, s2 * (lj - (sh * li + vh * lj)) + ei)
    nj, ej = _two_sum(lj, -s2 * (li + (sh * lj - vh * li)) + ej)
    return ni, nj, ei, ej


@njit(inline="always", cache=True)
def _qturn(sh, vh, w, x, y, z, pw, px, py, pz, ew, ex, ey, ez):  # pragma: no cover
    """q (cos, sin u) = q - vh q + sh q u for q = (w, x, y, z), q u = (pw, ...), compensated."""
    w1, ew = _two_sum(w, (sh * pw - vh * w) + ew)
    x1, ex = _two_sum(x, (sh * px - vh * x) + ex)
    y1, ey = _two_sum(y, (sh * py - vh * y) + ey)
    z1, ez = _two_sum(z, (sh * pz - vh * z) + ez)
    return w1, x1, y1, z1, ew, ex, ey, ez


@njit(inline="always", cache=True, fastmath={"contract"})
def _axis_turn(axis, fj, l0, l1, l2, e0, e1, e2, w, x, y, z, ew, ex, ey, ez):  # pragma: no cover
    """Op types 0-2: the body L turned by -theta about ``axis`` and q <- q (cos theta/2,
    sin theta/2 e_axis), theta/2 = ``fj`` L_axis; returns the new compensated state."""
    if axis == 0:
        sh, vh = sin_versin(fj * l0)
        l1, l2, e1, e2 = _turn_pair(sh, vh, l1, l2, e1, e2)
        w, x, y, z, ew, ex, ey, ez = _qturn(sh, vh, w, x, y, z, -x, w, z, -y, ew, ex, ey, ez)
    elif axis == 1:
        sh, vh = sin_versin(fj * l1)
        l2, l0, e2, e0 = _turn_pair(sh, vh, l2, l0, e2, e0)
        w, x, y, z, ew, ex, ey, ez = _qturn(sh, vh, w, x, y, z, -y, -z, w, x, ew, ex, ey, ez)
    else:
        sh, vh = sin_versin(fj * l2)
        l0, l1, e0, e1 = _turn_pair(sh, vh, l0, l1, e0, e1)
        w, x, y, z, ew, ex, ey, ez = _qturn(sh, vh, w, x, y, z, -z, y, -x, w, ew, ex, ey, ez)
    return l0, l1, l2, e0, e1, e2, w, x, y, z, ew, ex, ey, ez


@njit(inline="always", cache=True, fastmath={"contract"})
def _casimir_turn(fj, l0, l1, l2, e0, e1, e2, w, x, y, z, ew, ex, ey, ez):  # pragma: no cover
    """Op type 4: q <- q (cos phi, sin phi L / |L|), phi = ``fj`` |L|; L unchanged."""
    lx = l0 + e0
    ly = l1 + e1
    lz = l2 + e2
    nl = math.sqrt(lx * lx + ly * ly + lz * lz)
    if nl > 0.0:
        sh, vh = sin_versin(fj * nl)
        pw, px, py, pz = qmul(w, x, y, z, 0.0, lx / nl, ly / nl, lz / nl)
        w, x, y, z, ew, ex, ey, ez = _qturn(sh, vh, w, x, y, z, pw, px, py, pz, ew, ex, ey, ez)
    return w, x, y, z, ew, ex, ey, ez


@njit(inline="always", cache=True, fastmath={"contract"})
def _kick(fj, nx, ny, nz, l0, l1, l2, e0, e1, e2):  # pragma: no cover - compiled
    """Op type 3: L <- L + N tau (``fj`` = tau), compensated; q is unchanged."""
    l0, e0 = _two_sum(l0, fj * nx + e0)
    l1, e1 = _two_sum(l1, fj * ny + e1)
    l2, e2 = _two_sum(l2, fj * nz + e2)
    return l0, l1, l2, e0, e1, e2


@njit(inline="always", cache=True, fastmath={"contract"})
def _op_factors(types, fracs, inv, h):  # pragma: no cover - compiled
    """The factor of each op: tau = fracs h for a kick, theta/2 per unit L_axis
    (inv[axis] tau / 2) for a rotation."""
    nops = types.shape[0]
    f = np.empty(nops)
    for j in range(nops):
        f[j] = fracs[j] * h if types[j] == 3 else 0.5 * fracs[j] * h * inv[types[j]]
    return f


@njit(cache=True, fastmath={"contract"})
def run_splitting(
    types, fracs, toffs, inv, moments, qh, ql, lh, ll, n0, h, n_steps, out_steps, kind, params,
    q_out, l_out, pending, more,
):  # pragma: no cover - compiled
    """Run ``n_steps`` steps of a splitting method given as ops, after step ``n0``
    (time ``n0 h``: step ``n`` of the call begins at ``(n0 + n - 1) h``, the same
    time however a run is cut into calls); the time loop is compiled.

    Op ``j`` of a step is the flow of type ``types[j]`` for time tau = ``fracs[j] h``,
    at time t_step + ``toffs[j]`` h:

    * 0-2: the flow of inv[axis] L_axis^2 / 2 (``inv`` (5,) holds the parts'
      inverse moments, 1 / I_axis for the plain splitting).  omega = inv[axis]
      L_axis e_axis is constant along it, so the body L turns by -theta about
      e_axis (dL/dt = L x omega) and the attitude by q <- q (cos theta/2,
      sin theta/2 e_axis), theta = inv[axis] L_axis tau: exact rotations, |L| and
      the space-frame L = q L q^-1 are unchanged up to rounding.
    * 3: a kick, the exact flow of the torque part: L <- L + N(t, q) tau, q frozen.
    * 4: the flow of the Casimir part inv[4] |L|^2 / 2: the body L is fixed and
      q <- q (cos phi, sin phi L / |L|), phi = inv[4] |L| tau / 2.  It commutes
      with every other part of the free body.

    When the last op of a step and the first of the next have the same type
    (e.g. R1(h/2) R1(h/2)), they are fused into one (their flows commute) unless
    an output falls between them.  ``pending``: the first op of the first step
    was already applied (fused) by the previous call; ``more``: another call
    continues this run, so the last step may fuse into it.  (A run in chunks, as
    every long run is, is then bitwise identical to one call.)

    The state is the compensated pair (``qh + ql``, ``lh + ll``), advanced in
    place (held in registers inside the loop).  The state after step
    ``out_steps[k]`` (sorted, 0 = initial state) is written to ``q_out[k]``
    (normalised: the flows preserve |q| to O(eps theta^2), the state itself is
    not projected) and ``l_out[k]`` (body angular momentum).  Returns
    (max | |q| - 1 | over the outputs, ``pending`` for the next call).
    """
    f = _op_factors(types, fracs, inv, h)
    last = types.shape[0] - 1
    fuse = last > 0 and types[0] == types[last]
    f_fused = f[0] + f[last]
    a = moments[0]
    b = moments[1]
    c = moments[2]
    l0, l1, l2, e0, e1, e2 = lh[0], lh[1], lh[2], ll[0], ll[1], ll[2]
    w, x, y, z = qh[0], qh[1], qh[2], qh[3]
    ew, ex, ey, ez = ql[0], ql[1], ql[2], ql[3]
    drift = 0.0
    k = 0
    nout = out_steps.shape[0]
    for n in range(0, n_steps + 1):
        if n > 0:
            ts = (n0 + n - 1) * h
            out_here = k < nout and out_steps[k] == n
            for j in range(1 if pending else 0, last + 1):
                fj = f[j]
                if j == last:
                    pending = fuse and (n < n_steps or more) and not out_here
                    if pending:
                        fj = f_fused
                typ = types[j]
                if typ <= 2:
                    l0, l1, l2, e0, e1, e2, w, x, y, z, ew, ex, ey, ez = _axis_turn(
                        typ, fj, l0, l1, l2, e0, e1, e2, w, x, y, z, ew, ex, ey, ez)
                elif typ == 3:
                    nx, ny, nz = torque_scalar(kind, params, a, b, c, ts + toffs[j] * h,
                                               w, x, y, z)
                    l0, l1, l2, e0, e1, e2 = _kick(fj, nx, ny, nz, l0, l1, l2, e0, e1, e2)
                else:
                    w, x, y, z, ew, ex, ey, ez = _casimir_turn(
                        fj, l0, l1, l2, e0, e1, e2, w, x, y, z, ew, ex, ey, ez)
        while k < nout and out_steps[k] == n:
            qw = w + ew
            qx = x + ex
            qy = y + ey
            qz = z + ez
            nq = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
            drift = max(drift, abs(nq - 1.0))
            q_out[k, 0] = qw / nq
            q_out[k, 1] = qx / nq
            q_out[k, 2] = qy / nq
            q_out[k, 3] = qz / nq
            l_out[k, 0] = l0 + e0
            l_out[k, 1] = l1 + e1
            l_out[k, 2] = l2 + e2
            k += 1
    lh[0], lh[1], lh[2], ll[0], ll[1], ll[2] = l0, l1, l2, e0, e1, e2
    qh[0], qh[1], qh[2], qh[3] = w, x, y, z
    ql[0], ql[1], ql[2], ql[3] = ew, ex, ey, ez
    return drift, pending


@njit(inline="always", cache=True)
def _normalise(quat):  # pragma: no cover - compiled
    n = math.sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3])
    quat[0] /= n
    quat[1] /= n
    quat[2] /= n
    quat[3] /= n


# --------------------------------------------------------------------------
# Classical Runge-Kutta on Euler + kinematics (quaternion or Cayley form)
# --------------------------------------------------------------------------


# The RK4 loops call their right-hand side (_rhs_quat, _rhs_cayley) at four sites: as
# compiled calls, not inlined into each (numba's inline="always" typed and optimised
# four copies).  Measured 2026-12-01 from empty caches (first call, CPU time, 2 cores):
# rk4 8.3 -> 3.6 s of compilation and its steps twice as fast (122 -> 62 ms for 1e6);
# cayley_rk4 7.0 -> 1.9 s, its steps about 30% slower (245 -> 315 ms), a demonstration
# method whose first run matters more.  The arithmetic is the same: the same bits.
@njit(cache=True)
def _rhs_quat(kind, params, moments, t, y, dy):  # pragma: no cover - compiled
    """y = (w, x, y, z, p, q, r): Euler's equations plus dq/dt = q omega / 2."""
    a = moments[0]
    b = moments[1]
    c = moments[2]
    nx, ny, nz = torque_scalar(kind, params, a, b, c, t, y[0], y[1], y[2], y[3])
    dp, dq, dr = euler_scalar(a, b, c, y[4], y[5], y[6], nx, ny, nz)
    dw, dx, dyy, dz = qdot_scalar(y[0], y[1], y[2], y[3], y[4], y[5], y[6])
    dy[0] = dw
    dy[1] = dx
    dy[2] = dyy
    dy[3] = dz
    dy[4] = dp
    dy[5] = dq
    dy[6] = dr


@njit(cache=True)
def rhs_quaternion(t, y, moments, kind, params):  # pragma: no cover - compiled
    """Right-hand side for scipy's solve_ivp: y (7,) = (quaternion, omega)."""
    dy = np.empty(7)
    _rhs_quat(kind, params, moments, t, y, dy)
    return dy


@njit(cache=True)  # not inlined: see _rhs_quat
def _rhs_cayley(kind, params, moments, t, off, y, dy):  # pragma: no cover - compiled
    """y = (lambda0, mu0, nu0, p, q, r); the attitude is off (1, g0) / sqrt(kappa0).

    Left multiplication by the constant ``off`` commutes with the right-invariant
    kinematics, so g0 obeys Cayley's equations with the same body omega (his P_0
    system: the general solution is the composition of a particular one with
    arbitrary constants l, m, n).
    """
    kap = math.sqrt(1.0 + y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
    w, x, yy, z = qmul(off[0], off[1], off[2], off[3], 1.0 / kap, y[0] / kap, y[1] / kap,
                       y[2] / kap)
    a = moments[0]
    b = moments[1]
    c = moments[2]
    nx, ny, nz = torque_scalar(kind, params, a, b, c, t, w, x, yy, z)
    dp, dq, dr = euler_scalar(a, b, c, y[3], y[4], y[5], nx, ny, nz)
    gl, gm, gn = gibbs_dot_scalar(y[0], y[1], y[2], y[3], y[4], y[5])
    dy[0] = gl
    dy[1] = gm
    dy[2] = gn
    dy[3] = dp
    dy[4] = dq
    dy[5] = dr


@njit(cache=True)
def run_rk4_quaternion(
    moments, y, n0, h, n_steps, out_steps, kind, params, y_out
):  # pragma: no cover - compiled
    """Classical RK4 on y = (q, omega), q not normalised inside (only on output):
    ``n_steps`` steps after step ``n0`` (time ``n0 h``), ``y`` advanced in place;
    outputs as in :func:`run_splitting`."""
    k1 = np.empty(7)
    k2 = np.empty(7)
    k3 = np.empty(7)
    k4 = np.empty(7)
    tmp = np.empty(7)
    k = 0
    nout = out_steps.shape[0]
    while k < nout and out_steps[k] == 0:
        y_out[k, :] = y
        k += 1
    for n in range(1, n_steps + 1):
        t = (n0 + n - 1) * h
        _rhs_quat(kind, params, moments, t, y, k1)
        for i in range(7):
            tmp[i] = y[i] + 0.5 * h * k1[i]
        _rhs_quat(kind, params, moments, t + 0.5 * h, tmp, k2)
        for i in range(7):
            tmp[i] = y[i] + 0.5 * h * k2[i]
        _rhs_quat(kind, params, moments, t + 0.5 * h, tmp, k3)
        for i in range(7):
            tmp[i] = y[i] + h * k3[i]
        _rhs_quat(kind, params, moments, t + h, tmp, k4)
        for i in range(7):
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        while k < nout and out_steps[k] == n:
            y_out[k, :] = y
            k += 1


@njit(cache=True)
def run_rk4_cayley(
    moments, off, y, n0, h, n_steps, out_steps, kind, params, recentre, y_out
):  # pragma: no cover - compiled
    """Classical RK4 on Cayley's (lambda0, mu0, nu0) and Euler's equations.

    The attitude is off (1, g0) / sqrt(kappa0) with an offset ``off`` (a unit
    quaternion) and ``y = (g0, omega)``, g0 = 0 at the start of a run.  After a
    step that takes |g0| above ``recentre`` the offset absorbs it, off <- off (1, g0)
    (Cayley's composition formula in homogeneous form: (P_0, P_0 lambda,
    P_0 mu, P_0 nu)), and g0 restarts at 0.  ``n_steps`` steps after step ``n0``
    (time ``n0 h``), ``off`` and ``y`` advanced in place; rows of ``y_out`` hold
    the attitude quaternion (4) and omega (3) (outputs as in
    :func:`run_splitting`).  Returns the number of re-centrings.
    """
    k1 = np.empty(6)
    k2 = np.empty(6)
    k3 = np.empty(6)
    k4 = np.empty(6)
    tmp = np.empty(6)
    r2 = recentre * recentre
    n_recentre = 0
    k = 0
    nout = out_steps.shape[0]
    for n in range(0, n_steps + 1):
        if n > 0:
            t = (n0 + n - 1) * h
            _rhs_cayley(kind, params, moments, t, off, y, k1)
            for i in range(6):
                tmp[i] = y[i] + 0.5 * h * k1[i]
            _rhs_cayley(kind, params, moments, t + 0.5 * h, off, tmp, k2)
            for i in range(6):
                tmp[i] = y[i] + 0.5 * h * k2[i]
            _rhs_cayley(kind, params, moments, t + 0.5 * h, off, tmp, k3)
            for i in range(6):
                tmp[i] = y[i] + h * k3[i]
            _rhs_cayley(kind, params, moments, t + h, off, tmp, k4)
            for i in range(6):
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            if y[0] * y[0] + y[1] * y[1] + y[2] * y[2] > r2:
                w, x, yy, z = qmul(off[0], off[1], off[2], off[3], 1.0, y[0], y[1], y[2])
                off[0] = w
                off[1] = x
                off[2] = yy
                off[3] = z
                _normalise(off)
                y[0] = 0.0
                y[1] = 0.0
                y[2] = 0.0
                n_recentre += 1
        while k < nout and out_steps[k] == n:
            kap = math.sqrt(1.0 + y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
            w, x, yy, z = qmul(off[0], off[1], off[2], off[3], 1.0 / kap, y[0] / kap,
                               y[1] / kap, y[2] / kap)
            y_out[k, 0] = w
            y_out[k, 1] = x
            y_out[k, 2] = yy
            y_out[k, 3] = z
            y_out[k, 4] = y[3]
            y_out[k, 5] = y[4]
            y_out[k, 6] = y[5]
            k += 1
    return n_recentre


# --------------------------------------------------------------------------
# Exact free flow plus torque kicks
# --------------------------------------------------------------------------


@njit(cache=True)
def run_exact_kick(
    moments, quat, omega, n0, h, n_steps, out_steps, kind, params, q_out, w_out
):  # pragma: no cover - compiled
    """Kick(h/2) exact-free-drift(h) kick(h/2), advancing ``quat``, ``omega`` in place.

    The drift is the closed-form torque-free motion of :mod:`rigid.free`
    (``free_step``); the kicks are the exact flow of the (t, q)-dependent torque.
    Symmetric, hence second order in the torque, and exact for the free body.
    ``n0`` and the outputs as in :func:`run_splitting`.
    """
    k = 0
    nout = out_steps.shape[0]
    a = moments[0]
    b = moments[1]
    c = moments[2]
    while k < nout and out_steps[k] == 0:
        q_out[k, :] = quat
        w_out[k, :] = omega
        k += 1
    for n in range(1, n_steps + 1):
        t = (n0 + n - 1) * h
        if kind != TORQUE_NONE:
            nx, ny, nz = torque_scalar(kind, params, a, b, c, t, quat[0], quat[1], quat[2],
                                       quat[3])
            omega[0] += 0.5 * h * nx / a
            omega[1] += 0.5 * h * ny / b
            omega[2] += 0.5 * h * nz / c
        free_step(moments, quat, omega, h)
        if kind != TORQUE_NONE:
            nx, ny, nz = torque_scalar(kind, params, a, b, c, t + h, quat[0], quat[1], quat[2],
                                       quat[3])
            omega[0] += 0.5 * h * nx / a
            omega[1] += 0.5 * h * ny / b
            omega[2] += 0.5 * h * nz / c
        _normalise(quat)
        while k < nout and out_steps[k] == n:
            q_out[k, :] = quat
            w_out[k, :] = omega
            k += 1
