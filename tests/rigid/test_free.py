"""Tests for the exact torque-free motion (rigid.free, rigid._kernels.free)."""

from __future__ import annotations

import itertools

import astropy.units as u
import mpmath
import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.special import ellipj, ellipk, elliprf, elliprj

from hamilton_orbits import Quaternion
from rigid import FreeMotion, RigidBody, free_motion, free_motion_arrays, free_parameters
from rigid._kernels import free as fk

EPS = np.finfo(float).eps


def euler_rhs(t, y, moments):
    """Euler's equations A p' = (B - C) q r ... and dq/dt = q (0, omega) / 2 (Cayley 1843)."""
    a, b, c = moments
    p, q, r = y[:3]
    w, x, yy, z = y[3:]
    return np.array([
        (b - c) * q * r / a,
        (c - a) * r * p / b,
        (a - b) * p * q / c,
        0.5 * (-x * p - yy * q - z * r),
        0.5 * (w * p + yy * r - z * q),
        0.5 * (w * q + z * p - x * r),
        0.5 * (w * r + x * q - yy * p),
    ])


def dop853(moments, q0, w0, t, rtol=1e-13):
    sol = solve_ivp(euler_rhs, (0.0, t[-1]), np.concatenate([w0, q0]), method="DOP853",
                    rtol=rtol, atol=1e-16, t_eval=t, args=(np.asarray(moments),))
    assert sol.success
    return sol.y[3:].T, sol.y[:3].T


def qdist(q1, q2):
    """Componentwise distance up to the sign of the quaternion (q and -q are one rotation)."""
    return np.minimum(np.abs(q1 - q2).max(-1), np.abs(q1 + q2).max(-1))


# --- the special-function kernels against independent implementations -------------------


def test_carlson_against_scipy():
    rng = np.random.default_rng(0)
    x, y, z = rng.uniform(0, 3, (3, 200))
    p = rng.uniform(0.1, 3, 200)
    ours_f = np.array([fk.carlson_rf(*a) for a in zip(x, y, z, strict=True)])
    ours_j = np.array([fk.carlson_rj(*a) for a in zip(x, y, z, p, strict=True)])
    np.testing.assert_allclose(ours_f, elliprf(x, y, z), rtol=8 * EPS)
    # R_J adds the R_C series terms; a handful of ulp.
    np.testing.assert_allclose(ours_j, elliprj(x, y, z, p), rtol=16 * EPS)
    assert abs(fk.ellipk_m1(0.3) - ellipk(0.7)) <= 4 * EPS * ellipk(0.7)


def test_jacobi_against_scipy_moderate_m():
    for m in (0.0, 0.3, 0.9):
        kk = ellipk(m)
        for r in np.linspace(-kk, kk, 41):
            s, c, d = fk.jacobi_reduced(r, m, 1.0 - m, kk)
            sr, cr, dr, _ = ellipj(r, m)
            assert abs(s - sr) < 4 * EPS and abs(c - cr) < 4 * EPS and abs(d - dr) < 4 * EPS


@pytest.mark.parametrize("m1", [1e-12, 3e-18, 3e-22])
def test_jacobi_near_separatrix_against_mpmath(m1):
    # m = 1 - m1 with m1 passed directly: scipy's ellipj is wrong by orders of
    # magnitude here (scipy issue 8480).  Near the separatrix sn, cn, dn are taken by
    # descending Landen transformations (products and sums of positive numbers), so
    # they keep their *relative* accuracy where cn and dn are small: 256 eps bounds
    # some ten levels of a few roundings each and the reduction about K (r near K
    # is reflected to K - r, whose rounding is an ulp of K).  The AGM's backward
    # recursion (an asin near 1) lost eps / cn^2: 1e-11 at m1 = 1e-12, 2e-6 at
    # m1 = 3e-22.
    mpmath.mp.dps = 40
    mm = mpmath.mpf(1) - mpmath.mpf(m1)
    kk = fk.ellipk_m1(m1)
    assert abs(kk - float(mpmath.ellipk(mm))) < 4 * EPS * kk
    for r in np.linspace(-kk, kk, 62)[1:-1]:  # (not 0, where mpmath's sn is 1e-46)
        ours = fk.jacobi_reduced(r, 1.0 - m1, m1, kk)
        ref = [mpmath.ellipfun(k, mpmath.mpf(r), m=mm) for k in ("sn", "cn", "dn")]
        for o, e in zip(ours, ref, strict=True):
            assert abs(o - e) <= 256 * EPS * abs(e)


# --- the motion against numerical integration ----------------------------------------


CASES = [
    # moments in every order, both polhode families, both signs of the polar spin
    (np.array(perm), sgn * np.array(w))
    for perm in itertools.permutations((1.0, 2.0, 3.0))
    for w in ((1.0, 0.3, 0.8), (0.9, 0.8, 0.1))
    for sgn in (1.0, -1.0)
]


@pytest.mark.parametrize(("moments", "w0"), CASES)
def test_against_dop853_all_branches(moments, w0):
    w0 = w0[np.argsort(np.argsort(moments))]  # put each component on its moment
    q0 = np.array([0.3, -0.5, 0.7, 0.2])
    q0 /= np.linalg.norm(q0)
    t = np.linspace(0.0, 20.0, 41)
    q, w = free_motion_arrays(moments, q0, w0, t)
    qr, wr = dop853(moments, q0, w0, t)
    # DOP853 at rtol 1e-13 over ~2 periods is good to ~1e-12.
    assert np.abs(w - wr).max() < 5e-12
    assert qdist(q, qr).max() < 5e-12
    # No sign jumps: the returned quaternion is continuous in time.
    assert np.abs(np.diff(q, axis=0)).max() < 0.5


def test_against_dop853_100_periods():
    moments = np.array([1.0, 2.0, 3.0])
    w0 = np.array([1.0, 0.3, 0.8])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    period = free_parameters(RigidBody(moments, q0, w0)).period
    t = np.linspace(0.0, 100 * period, 501)
    q, w = free_motion_arrays(moments, q0, w0, t)
    qr, wr = dop853(moments, q0, w0, t)
    err = max(np.abs(w - wr).max(), qdist(q, qr).max())
    # Measured 1.3e-10 after 100 periods (924 s).  This is DOP853's own error
    # growth: at rtol 2.3e-14 the difference drops to 2.8e-11 (see the slow test
    # below), and after 10 periods it is 9e-13.
    assert err < 3e-10
    assert max(np.abs(w - wr)[:51].max(), qdist(q, qr)[:51].max()) < 2e-12


@pytest.mark.slow
def test_difference_to_dop853_shrinks_with_its_tolerance():
    moments = np.array([1.0, 2.0, 3.0])
    w0 = np.array([1.0, 0.3, 0.8])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    t = np.linspace(0.0, 100 * free_parameters(RigidBody(moments, q0, w0)).period, 201)
    q, w = free_motion_arrays(moments, q0, w0, t)
    errs = []
    for rtol in (1e-13, 2.3e-14):
        qr, wr = dop853(moments, q0, w0, t, rtol=rtol)
        errs.append(max(np.abs(w - wr).max(), qdist(q, qr).max()))
    assert errs[1] < errs[0] / 3 and errs[1] < 5e-11


def _mp_reference(moments, q0, w0, times, dps=25):
    """High-precision Taylor integration (mpmath.odefun) of Euler + quaternion kinematics."""
    mpmath.mp.dps = dps
    a, b, c = (mpmath.mpf(float(x)) for x in moments)

    def f(_t, y):
        p, q, r, w, x, yy, z = y
        return [(b - c) * q * r / a, (c - a) * r * p / b, (a - b) * p * q / c,
                (-x * p - yy * q - z * r) / 2, (w * p + yy * r - z * q) / 2,
                (w * q + z * p - x * r) / 2, (w * r + x * q - yy * p) / 2]

    sol = mpmath.odefun(f, 0, [mpmath.mpf(float(v)) for v in (*w0, *q0)])
    out = np.array([[float(v) for v in sol(mpmath.mpf(float(t)))] for t in times])
    return out[:, 3:], out[:, :3]


def test_near_separatrix_against_high_precision():
    # Moments (2, 5, 6), omega = (1, 0, 1 + 2^-40): L^2 - 2TB = 6 (2^-39 + 2^-80)
    # rounds exactly, so 1 - m = 2^-39 (1 - 2^-39) ~ 1.8e-12 is known to the last bit.
    # DOP853 cannot serve as reference here: its effective m drifts and the time of
    # passage near the saddle is wrong by ~6e-5 s; mpmath's Taylor method is exact
    # to the digits we ask for.
    moments = np.array([2.0, 5.0, 6.0])
    w0 = np.array([1.0, 0.0, 1.0 + 2.0**-40])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    par = free_parameters(RigidBody(moments, q0, w0))
    assert par.kind == "periodic" and abs(par.m1 / 2.0**-39 - 1.0) < 1e-11
    times = np.array([0.5, 0.75]) * par.flip_interval  # the saddle passage and beyond
    q, w = free_motion_arrays(moments, q0, w0, times)
    qr, wr = _mp_reference(moments, q0, w0, times, dps=20)
    # Measured 5e-16 (omega) and 8e-16 (attitude); 4e-15 and 4e-13 before sn, cn, dn
    # near the separatrix were taken by Landen's transformations (the AGM's relative
    # error in cn, ~eps / cn^2, reached the phase).  The bounds leave a decade for
    # another platform's libm.
    assert np.abs(w - wr).max() < 1e-14
    assert qdist(q, qr).max() < 1e-14


def test_exact_separatrix():
    # Moments (2, 5, 6), omega = (1, w2, 1): L^2 - 2TB = 2(2 - 5) + 6(6 - 5) = 0 exactly.
    moments = np.array([2.0, 5.0, 6.0])
    w0 = np.array([1.0, 0.5, 1.0])
    q0 = np.array([0.5, 0.5, 0.5, 0.5])
    body = RigidBody(moments, q0, w0)
    assert free_parameters(body).kind == "separatrix"
    t = np.linspace(0.0, 10.0, 21)
    q, w = free_motion_arrays(moments, q0, w0, t)
    qr, wr = dop853(moments, q0, w0, t)
    # The homoclinic orbit amplifies DOP853's error like exp(lambda t), lambda = 0.68.
    assert np.abs(w - wr).max() < 1e-11 and qdist(q, qr).max() < 1e-11
    # Asymptotically the body spins about the middle axis: omega -> (0, b, 0),
    # b^2 = (2TC - L^2) / (B (C - B)) = (2 * 7.25 * 6 - 42.25) / 5.
    _, w_late = free_motion_arrays(moments, q0, w0, [200.0])
    b = np.sqrt((2 * 0.5 * (2 + 5 * 0.25 + 6) * 6 - (4 + 6.25 + 36)) / 5.0)
    np.testing.assert_allclose(w_late[0], [0.0, b, 0.0], atol=1e-12)
    # The other heteroclinic branch (omega_1 < 0) too.
    w0b = np.array([-1.0, 0.5, 1.0])
    q, w = free_motion_arrays(moments, q0, w0b, t)
    qr, wr = dop853(moments, q0, w0b, t)
    assert np.abs(w - wr).max() < 1e-11 and qdist(q, qr).max() < 1e-11


def test_axisymmetric_closed_form():
    # A = B: omega_3 constant, (p + i q) turns at Omega = (C - A) r / A, and
    # q(t) = exp(L_space t / (2A)) q0 exp(-Omega t e3 / 2)  (Euler's free symmetric top;
    # differentiating gives omega = (L/A) R(Omega t) l0 - Omega e3, which is Euler's solution).
    a, c = 1.5, 2.5
    moments = np.array([a, a, c])
    w0 = np.array([0.4, -0.3, 1.2])
    q0 = Quaternion([0.9, 0.1, -0.3, 0.2]).unit()
    t = np.linspace(0.0, 50.0, 101)
    att, w = free_motion(RigidBody(moments, q0, w0), t)
    omega_b = (c - a) * w0[2] / a
    ang = omega_b * t
    wr = np.stack([w0[0] * np.cos(ang) - w0[1] * np.sin(ang),
                   w0[0] * np.sin(ang) + w0[1] * np.cos(ang), np.full_like(t, w0[2])], -1)
    l_space = q0.rotate(moments * w0)
    prec = Quaternion.from_axis_angle(l_space / np.linalg.norm(l_space),
                                      np.linalg.norm(l_space) / a * t)
    spin = Quaternion.from_axis_angle([0.0, 0.0, 1.0], -omega_b * t)
    qr = (prec * q0 * spin).as_array()
    np.testing.assert_allclose(w, wr, atol=1e-14)
    assert qdist(att.as_array(), qr).max() < 1e-13
    # The prolate case B = C (the polhode circles the A axis).
    moments = np.array([c, a, a])[[0, 1, 2]]
    moments = np.array([1.0, 1.8, 1.8])
    w0 = np.array([1.1, 0.2, -0.6])
    t = np.linspace(0.0, 20.0, 41)
    q, w = free_motion_arrays(moments, q0.as_array(), w0, t)
    qr2, wr2 = dop853(moments, q0.as_array(), w0, t)
    assert np.abs(w - wr2).max() < 1e-12 and qdist(q, qr2).max() < 1e-12


def test_sphere_and_steady_rotations():
    q0 = Quaternion([0.9, 0.1, -0.3, 0.2]).unit()
    t = np.linspace(0.0, 30.0, 7)
    for moments, w0 in [([2.0, 2.0, 2.0], [0.3, -0.4, 1.2]),  # sphere
                        ([1.0, 2.0, 3.0], [0.0, 0.7, 0.0]),  # middle axis (unstable)
                        ([1.0, 2.0, 3.0], [0.0, 0.0, -0.7]),
                        ([1.0, 1.0, 1.5], [0.6, 0.8, 0.0]),  # transverse, A = B
                        ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])]:  # at rest
        att, w = free_motion(RigidBody(moments, q0, w0), t)
        np.testing.assert_array_equal(w, np.broadcast_to(w0, (t.size, 3)))
        wn = np.linalg.norm(w0)
        spin = (Quaternion.from_axis_angle(np.asarray(w0) / wn, wn * t) if wn > 0
                else Quaternion(np.tile([1.0, 0, 0, 0], (t.size, 1))))
        assert qdist(att.as_array(), (q0 * spin).as_array()).max() < 4 * EPS * (1 + wn * 30)


@settings(deadline=None, max_examples=30)
@given(
    st.lists(st.floats(0.5, 2.0), min_size=3, max_size=3),
    st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4),
)
@example([1.0, 1.0, 0.5], [0.0, 0.0, 5.229002104183297e-162], [0.0, 0.0, 0.0, 1.0])
@example([1.0, 1.0, 1.0], [0.0, 0.0, 3.4233491821067394e-156], [0.0, 0.0, 0.0, 1.0])
@example([1.0, 1.5, 2.0], [1e-320, 2e-320, 0.0], [0.5, 0.5, 0.5, 0.5])  # subnormal omega
@example([0.625, 1.25, 1.0], [0.0, 5.788106574260585e-35, 1.5], [0.0, 0.0, 0.0, 1.0])
def test_invariants_to_a_few_ulp(moments, w0, q0):
    moments = np.array(moments)
    assume(moments.max() <= moments.sum() - moments.max() and np.linalg.norm(q0) >= 0.1)
    w0 = np.array(w0)
    t = np.linspace(0.0, 200.0, 50)
    body = RigidBody(moments, q0, w0)
    att, w = free_motion(body, t)
    qa = att.as_array()
    np.testing.assert_allclose(np.linalg.norm(qa, axis=-1), 1.0, atol=4 * EPS)
    # The integrals on omega / s, s the power of two above max|omega0| (exact): for a
    # tiny omega0 (hypothesis drew 5.2e-162) omega^2 underflowed, and with it a
    # tolerance relative to T.  Below 2.2e-308 omega itself lies on the subnormal grid
    # 2^-1074 (2^-1074 / s after scaling): a floor for that rounding of the result.
    s = 2.0 ** float(np.frexp(np.abs(w0).max())[1]) if np.any(w0) else 1.0
    grid = 2.0**-1074 / s
    ws, w0s = w / s, w0 / s
    energy = 0.5 * np.sum(moments * ws * ws, axis=-1)
    e0 = 0.5 * np.sum(moments * w0s * w0s)
    # Near the separatrix (hypothesis drew a spin about the intermediate axis nudged
    # by 5.8e-35: m1 = 1e-70, K = 82) sn, cn and dn at u ~ K, where the body flips,
    # keep sn^2 + cn^2 = 1 less well: 46 eps of T measured there, 13 at K = 36, 2-4
    # below K = 20; so the bound grows with K (16 eps for an ordinary K ~ 2).
    k_m = float(free_parameters(body).K)
    k_m = k_m if np.isfinite(k_m) else 8.0  # (on the separatrix: tanh and sech, exact)
    assert np.all(np.abs(energy - e0) <= 16 * EPS * e0 * max(1.0, k_m / 8.0)
                  + 8 * moments.max() * grid)
    l_space = att.rotate(moments * ws)
    l0 = body.attitude.rotate(moments * w0s)
    lnorm = np.linalg.norm(moments * w0s)
    assert np.all(np.abs(l_space - l0) <= 32 * EPS * lnorm + 4 * moments.max() * grid)
    # The initial state is reproduced.
    np.testing.assert_allclose(ws[0], w0s, rtol=0, atol=8 * EPS * np.abs(w0s).max() + grid)
    assert qdist(qa[0], body.attitude.as_array()) <= 8 * EPS


def test_group_property_many_periods():
    # Evolving t1 then t2 equals evolving t1 + t2 (tests the Pi accumulation 2k Pi(n|m)).
    moments = np.array([3.0, 1.0, 2.5])
    w0 = np.array([0.2, 1.0, -0.4])
    q0 = np.array([0.1, 0.7, -0.1, 0.7])
    t1, t2 = 1234.5, 987.6
    qa, wa = free_motion_arrays(moments, q0, w0, t1)
    qb, wb = free_motion_arrays(moments, qa, wa, t2)
    qc, wc = free_motion_arrays(moments, q0, w0, t1 + t2)
    # ~300 periods: the phase carries ~1e-13 relative error of t.
    assert np.abs(wb - wc).max() < 1e-11 and qdist(qb, qc) < 1e-11


def test_shapes_units_and_errors():
    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[1.0, 0.3, 0.8] * u.rad / u.s)
    att, w = free_motion(body, np.zeros((2, 3)) * u.min)
    assert att.shape == (2, 3) and w.shape == (2, 3, 3) and w.unit == u.rad / u.s
    plain = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])  # plain floats are SI
    att, w = free_motion(plain, 1.0)
    assert att.shape == () and w.shape == (3,) and not isinstance(w, u.Quantity)
    _, w60 = free_motion(body, 1.0 * u.min)
    _, w60s = free_motion(plain, 60.0)
    np.testing.assert_array_equal(w60.value, w60s)
    _, w60p = free_motion(plain, 1.0 * u.min)  # a float body with Quantity times
    assert w60p.unit == u.rad / u.s
    np.testing.assert_array_equal(w60p.value, w60s)
    # a body with units needs times with units: a plain 60 could be s, min or days
    with pytest.raises(ValueError, match="Expected `t` to be a Quantity like `body`"):
        free_motion(body, 60.0)
    with pytest.raises(ValueError, match="`t` to be finite, got nan at index 1"):
        free_motion(body, [0.0, np.nan] * u.s)
    with pytest.raises(ValueError, match="RigidBody"):
        free_motion([1.0, 2.0, 3.0], [0.0])
    with pytest.raises(ValueError, match=r"`q0` to have shape \(4,\)"):
        free_motion_arrays([1.0, 2.0, 3.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0])
    with pytest.raises(ValueError, match=r"`moments` to have shape \(3,\)"):
        free_motion_arrays([1.0, 2.0], [1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0])
    with pytest.raises(u.UnitConversionError):
        free_motion(body, 1.0 * u.m)


def test_free_step_kernel_matches_arrays():
    moments = np.array([1.0, 2.0, 3.0])
    q = np.array([1.0, 0.0, 0.0, 0.0])
    w = np.array([1.0, 0.3, 0.8])
    qr, wr = free_motion_arrays(moments, q, w, 0.7)
    fk.free_step(moments, q, w, 0.7)
    np.testing.assert_array_equal(q, qr)
    np.testing.assert_array_equal(w, wr)


def test_nearly_steady_spin_does_not_underflow():
    """Regression (found by hypothesis): omega = (0, 1, 7.4e-300) on A = B.

    The polhode amplitudes underflow; the motion is the steady spin about
    omega to within a relative 1e-300 * |omega| t, and no division by zero occurs.
    """
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    w0 = np.array([0.0, 1.0, 7.4e-300])
    t = np.array([0.0, 1.0, 1e3])
    q, w = free_motion_arrays([1.0, 1.0, 0.5], q0, w0, t)
    np.testing.assert_array_equal(w, np.broadcast_to(w0, (3, 3)))
    spin = Quaternion(q0) * Quaternion.from_axis_angle(w0, np.linalg.norm(w0) * t)
    assert qdist(q, spin.as_array()).max() < 4 * EPS * 1e3


@pytest.mark.slow
def test_100_periods_against_high_precision():
    """The exact solution over 100 periods against a 20-digit Taylor integration.

    DOP853 cannot check 100 periods at 1e-11 (its own error reaches 1.3e-10 at
    rtol 1e-13, see test_against_dop853_100_periods); mpmath's Taylor
    integrator at 20 digits can (about 2.5 minutes).  Measured: 8e-14.  The
    bound allows for the phase: the exact solution carries ~eps relative error
    in t, i.e. ~|omega| t eps ~ 4e-13 rad at t = 100 periods.
    """
    moments = np.array([1.0, 2.0, 3.0])
    w0 = np.array([1.0, 0.3, 0.8])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    period = free_parameters(RigidBody(moments, q0, w0)).period
    t = np.array([10.0, 50.0, 100.0]) * period
    q, w = free_motion_arrays(moments, q0, w0, t)
    qm, wm = _mp_reference(moments, q0, w0, t, dps=20)
    err = max(np.abs(w - wm).max(), qdist(q, qm).max())
    assert err < 1e-11


# --- thin symmetric bodies (issue 7, item 3) -----------------------------------------------


def _mp_qmul(a, b):
    return [a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]]


def _mp_symmetric_top(a, c, q0, w0, t):
    """Euler's symmetric top (A = B) in 50-digit arithmetic from the float inputs.

    q(t) = exp(t L / (2A)) q0 exp(t nu e3 / 2), L the angular momentum in space and
    nu = L3 (1/C - 1/A) (issue 7, item 3; the body-frame form of Euler's solution,
    cf. test_axisymmetric_closed_form).  Returns the quaternion and the total angle
    turned t (|L|/A + |nu|), the scale of the rounding error of any evaluation.
    """
    with mpmath.workdps(50):
        a, c, t = mpmath.mpf(a), mpmath.mpf(c), mpmath.mpf(t)
        q0 = [mpmath.mpf(x) for x in q0]
        nrm = mpmath.sqrt(sum(x * x for x in q0))
        q0 = [x / nrm for x in q0]
        lb = [a * mpmath.mpf(w0[0]), a * mpmath.mpf(w0[1]), c * mpmath.mpf(w0[2])]
        ls = _mp_qmul(_mp_qmul(q0, [0, *lb]), [q0[0], -q0[1], -q0[2], -q0[3]])[1:]
        ell = mpmath.sqrt(sum(x * x for x in ls))
        nu = lb[2] * (1 / c - 1 / a)
        h1, h2 = t * ell / (2 * a), t * nu / 2
        e1 = [mpmath.cos(h1)] + [mpmath.sin(h1) * x / ell for x in ls]
        q = _mp_qmul(_mp_qmul(e1, q0), [mpmath.cos(h2), 0, 0, mpmath.sin(h2)])
        return q, float(2 * h1 + 2 * abs(h2))


def _mp_angle(ref, q):
    """Rotation angle between an mpmath quaternion and a float one (sign-blind)."""
    with mpmath.workdps(50):
        d = _mp_qmul([ref[0], -ref[1], -ref[2], -ref[3]], [mpmath.mpf(float(x)) for x in q])
        return float(2 * mpmath.atan2(mpmath.sqrt(d[1] ** 2 + d[2] ** 2 + d[3] ** 2),
                                      abs(d[0])))


@pytest.mark.parametrize("moments", [[1.0, 1.0, 1e-6], [1e6, 1e6, 1.0], [1.0, 1.0, 0.5],
                                     [1.0, 1.0, 1.9], [1e-6, 1.0, 1.0]])
@pytest.mark.parametrize("t", [1.0, 1e3, 1e9])
def test_thin_symmetric_body_against_closed_form(moments, t):
    # Issue 7 reproducer: [1, 1, 1e-6] was 2e-9 rad off at t = 1 s and 0.25 rad at
    # t = 1e9 s (error ~ A/C: (L/C) t cancelled against itself).  Expected: a few eps
    # times the angle turned, the conditioning of the closed form itself (1 ulp in
    # C or t moves the angle by eps times the angle).  Measured: <= 1.4 eps * angle.
    q0, w0 = [0.9, 0.1, -0.3, 0.2], [1.0, 0.5, 0.3]
    sym = next(k for k in range(3) if moments.count(moments[k]) == 1)  # the symmetry axis
    perm = [(sym + 1) % 3, (sym + 2) % 3, sym]  # cyclic: a proper relabelling
    q, _ = free_motion_arrays(moments, q0, np.array(w0)[np.argsort(perm)], [t])
    # the reference in the frame with the symmetry axis third (same cyclic relabelling)
    qp = Quaternion.from_rotation_matrix(np.eye(3)[:, perm]).as_array()
    qref, angle = _mp_symmetric_top(moments[perm[0]], moments[sym],
                                    (Quaternion(q0) * Quaternion(qp)).as_array(), w0, t)
    qref = _mp_qmul(qref, [qp[0], -qp[1], -qp[2], -qp[3]])
    assert _mp_angle(qref, q[0]) <= 4 * EPS * (1.0 + angle)


@pytest.mark.parametrize(("a", "c", "w0"), [
    # the property test's reproducer (moments 1e-12, 1e-12 and 1.9e-114 about the axis,
    # omega (0, 1, 1.9e-114)), axes relabelled cyclically so that the needle's axis is
    # the third: C w3^2 (A - C) = 7e-342 underflowed, the kernel divided by zero
    (1e-12, 1.914711231811873e-114, [0.0, 1.0, 1.914711231811873e-114]),
    (1.0, 1e-60, [1.0, 0.5, 1e-130]),  # 1e-320: subnormal, the motion silently wrong
    (1.0, 1e-150, [0.6, -0.8, 1.1e-150]),  # the thinnest body at the slowest axial spin
])
@pytest.mark.parametrize("t", [1.0, 1e3, 1e9])
def test_needle_with_a_slow_axial_spin_against_closed_form(a, c, w0, t):
    # A needle (C / A down to 1e-150) tumbling at ~1 rad/s and spinning about its axis
    # at 1e-130 of that: the kernel's polhode terms J w^2 (J' - J) of the axial spin
    # fall below float64's normal range, so it now takes the rates 2^53 .. 2^268 times
    # larger (exact: the motion is homogeneous in the rates).  The reference is Euler's
    # symmetric top in 50 digits; the bound is a few eps times the angle turned.
    q0 = [0.9, 0.1, -0.3, 0.2]
    q, w = free_motion_arrays([a, a, c], q0, w0, [t])
    qref, angle = _mp_symmetric_top(a, c, q0, w0, t)
    assert _mp_angle(qref, q[0]) <= 4 * EPS * (1.0 + angle)
    # the body-frame omega: the transverse part turns at nu = w3 (1 - C / A) about the
    # axis, w3 constant (to eps of |omega|; the axial angle nu t is tiny up to t = 1e9)
    nu = w0[2] * (1.0 - c / a)
    ref = Quaternion.from_axis_angle([0.0, 0.0, 1.0], -nu * t).rotate(w0)
    np.testing.assert_allclose(w[0], ref, rtol=0, atol=4 * EPS * np.abs(w0).max())
    assert w[0][2] == w0[2]


def test_needle_axial_spin_over_its_own_period():
    # The slow axial rotation of the needle above, over times where it turns by radians:
    # omega_W in the body frame against the closed form, to eps times the angle nu t.
    a, c, w0 = 1.0, 1e-60, np.array([1.0, 0.5, 1e-130])
    nu = w0[2] * (1.0 - c / a)
    t = np.array([0.5, 2.0, 7.0]) / nu
    _, w = free_motion_arrays([a, a, c], [1.0, 0.0, 0.0, 0.0], w0, t)
    for ti, wi in zip(t, w, strict=True):
        ref = Quaternion.from_axis_angle([0.0, 0.0, 1.0], -nu * ti).rotate(w0)
        np.testing.assert_allclose(wi, ref, rtol=0, atol=8 * EPS * (1.0 + nu * ti))


@pytest.mark.parametrize("c", [1e-6, 0.5, 1.9])
def test_near_symmetric_body_is_continuous(c):
    # B = A (1 + d): the attitude departs from the symmetric top linearly in d, with
    # no jump at d = 0 (the elliptic branch, m ~ d, must join the closed form).  The
    # slope |q_d - q_0| / d is the same for d = 2^-36 and 2^-32: 5e-4 relative covers
    # the rounding of the smaller step (~2 ulp / (d * slope) <= 1.2e-4 for C = 1.9)
    # and the curvature of the thin body's slope (~8e4 d = 2e-5 at d = 2^-32).
    q0, w0 = [0.9, 0.1, -0.3, 0.2], [1.0, 0.5, 0.3]
    q_sym, _ = free_motion_arrays([1.0, 1.0, c], q0, w0, [1.0])
    slopes = []
    for d in (2.0**-36, 2.0**-32):
        q, _ = free_motion_arrays([1.0, 1.0 + d, c], q0, w0, [1.0])
        slopes.append(Quaternion(q_sym[0]).inverse() * Quaternion(q[0]))
        slopes[-1] = 2 * np.linalg.norm(slopes[-1].as_array()[1:]) / d
    assert slopes[0] > 0.0
    assert abs(slopes[0] / slopes[1] - 1.0) < 5e-4


@pytest.mark.parametrize(("moments", "w0"), [
    ([1.0, 1.0 + 5e-7, 1e-6], [1.0, 0.5, 0.3]),  # thin axis off the polar axis: n ~ -2e12
    ([1e-6, 1.0, 1.0 + 5e-7], [1.0, 0.5, 0.3]),  # the same, polar axis the thin one
    ([2.0, 1.0 + 1e-9, 1.0], [0.3, 0.5, 1.0]),  # J2 - J3 tiny: n ~ -1e9
])
def test_thin_triaxial_body_against_high_precision(moments, w0):
    # A thin triaxial body is near-symmetric (B <= A + C), and then the characteristic n
    # of the third-kind integral is huge and negative: Pi = F + (n/3) s^3 R_J cancelled
    # to 1e-10 before (issue 7, item 3, the triaxial side).  Pi is now taken from DLMF
    # 19.7.9 there and the secular rate from the form whose terms share a sign.  The
    # reference is a 25-digit Taylor integration; measured error <= 1.5 eps.
    q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
    qr, wr = _mp_reference(moments, q0, w0, [0.25])
    q, w = free_motion_arrays(moments, q0, w0, [0.25])
    assert qdist(q, qr).max() <= 8 * EPS
    assert np.abs(w - wr).max() <= 8 * EPS * np.abs(w0).max()


def test_third_kind_integral_for_large_negative_characteristic():
    # the kernel's Pi(n; phi | m) for n < -1 (DLMF 19.7.9 form) against mpmath's ellippi
    for n in (-1.5, -40.0, -2e12):
        for phi in (-1.2, 0.3, np.pi / 2):
            m = 0.3
            s, c = np.sin(phi), np.cos(phi)
            d = np.sqrt(1.0 - m * s * s)
            ours = fk._pi_reduced(n, m, s, max(c, 0.0), d)
            with mpmath.workdps(30):
                ref = float(mpmath.ellippi(n, phi, m))
            assert ours == pytest.approx(ref, rel=8 * EPS)


def test_free_motion_is_a_named_result():
    # issue 19: a NamedTuple, so that `attitude, omega = free_motion(...)` still works
    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[1.0, 0.3, 0.8] * u.rad / u.s)
    t = [[0.0, 1.0], [2.0, 3.0]] * u.s
    motion = free_motion(body, t)
    assert isinstance(motion, FreeMotion) and motion._fields == ("attitude", "omega")
    attitude, omega = motion
    assert attitude is motion.attitude and omega is motion.omega
    assert motion.attitude.shape == (2, 2) and motion.omega.shape == (2, 2, 3)
    assert motion.omega.unit == u.rad / u.s
    # the same numbers as the kernel-level entry point
    q, w = free_motion_arrays(body.moments, body.attitude, body.omega, t)
    np.testing.assert_array_equal(motion.attitude.as_array(), q)
    np.testing.assert_array_equal(motion.omega.value, w.value)


# --- a spin about the intermediate axis with a tiny perturbation (separatrix limit) -------


def _intermediate_axis_reference(eps):
    """``(K, lambda, k', c)`` at 50 digits for moments (1, 2, 3), omega = (0, 1, eps).

    Landau & Lifshitz, Mechanics §37 (and docs/free_rigid_body.md §2): L^2 - 2TB = 3 eps^2,
    L^2 - 2TA = 2 + 6 eps^2, 2TC - L^2 = 2, so m1 = 1 - m = 6 eps^2 / (2 + 6 eps^2),
    lambda^2 = (2 + 6 eps^2) / 6, a = b = 1, c^2 = (2 + 6 eps^2) / 6; K = R_F(0, m1, 1)
    (DLMF 19.25.1) with mpmath's exponent range (m1 = 3e-600 for eps = 1e-300).
    """
    with mpmath.workdps(50):
        e = mpmath.mpf(eps)
        m1 = 6 * e**2 / (2 + 6 * e**2)
        lam = mpmath.sqrt((2 + 6 * e**2) / 6)
        return mpmath.elliprf(0, m1, 1), lam, mpmath.sqrt(m1), lam


@pytest.mark.parametrize("eps", [1e-19, 5.8e-21, 5.7e-21, 1e-149, 1e-151, 1e-160, 1e-300])
def test_tiny_perturbation_of_the_intermediate_axis_flips(eps):
    # A spin (0, 1, eps) on moments (1, 2, 3) leaves the unstable middle axis like
    # eps e^{lambda t} and flips: omega_2 = b sn(K + lambda t) (L&L §37).  Below
    # |omega_3 / omega_2| ~ 3e-150 it was taken as steady (kind "steady", period inf,
    # omega_2 never flipping), because 1 - m = 3 eps^2 underflows; the kernel now takes
    # k' = sqrt(1 - m) itself and, for k' < 1e-20, K = ln(4/k') (A&S 17.3.26).  The eps
    # straddle that switch (k' = sqrt(3) eps = 1e-20) and the underflow of m1.
    moments = np.array([1.0, 2.0, 3.0])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    w0 = np.array([0.0, 1.0, eps])
    kk, lam, kp, c = _intermediate_axis_reference(eps)
    par = free_parameters(RigidBody(moments, q0, w0))
    assert par.kind == "periodic" and par.polar_axis == 2
    # K = ln(4/k') from the logarithms of k''s factors (|ln k'| <= 746), lambda from a
    # square root: measured within 2 ulp of the period; 8 ulp leave room.
    assert abs(par.period / float(4 * kk / lam) - 1.0) <= 8 * EPS
    # omega at u = K (1 + j/2), j = 1..4, from u0 = K: sn, cn, dn at K/2 are
    # (1 + k')^-1/2, (k' / (1 + k'))^1/2, k'^1/2 (DLMF Table 22.5.2), shifted by K
    # (sn(K + v) = cd v, cn(K + v) = -k' sd v, dn(K + v) = k' nd v: DLMF Table 22.4.3).
    with mpmath.workdps(50):
        h = 1 / mpmath.sqrt(1 + kp)
        refs = [(-mpmath.sqrt(kp) * h, h, c * mpmath.sqrt(kp)), (-1, 0, c),
                (-mpmath.sqrt(kp) * h, -h, c * mpmath.sqrt(kp)), (0, -1, c * kp)]
        t = np.array([float(j * kk / (2 * lam)) for j in (1, 2, 3, 4)])
    refs = np.array([[float(x) for x in r] for r in refs])
    _, w = free_motion_arrays(moments, q0, w0, t)
    # The phase u = K + lambda t <= 3K (<= 2100) is rounded to ~u eps, and at these
    # points |d ln omega_i / du| <= 1 for each nonzero component: measured 2e-13 at
    # eps = 1e-300; 4 u eps.  A zero one moves by du times its slope: b dn = 1 for
    # omega_2 at 2K, a k' for omega_1 at 3K (cn(3K + du) = k' sd du).
    tol = 4.0 * float(3 * kk) * EPS
    nonzero = refs != 0.0
    assert np.all(np.abs(w[nonzero] / refs[nonzero] - 1.0) <= tol)
    assert abs(w[1, 1]) <= tol and abs(w[3, 0]) <= tol * float(kp)


def test_tiny_perturbation_of_the_intermediate_axis_other_family():
    # (eps, 1, 0): L^2 - 2TB = -eps^2 < 0, the polhode encircles the smallest axis (the
    # second family, form B of the precession).  After half a period, u0 + 2K, the
    # components along the middle axis and the polar (smallest) one have come back
    # with omega_2 reversed: (eps, -1, 0) (sn(u + 2K) = -sn u, dn(u + 2K) = dn u).
    moments = np.array([1.0, 2.0, 3.0])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    for eps in (1e-151, 1e-300):
        w0 = np.array([eps, 1.0, 0.0])
        par = free_parameters(RigidBody(moments, q0, w0))
        assert par.kind == "periodic" and par.polar_axis == 0
        _, w = free_motion_arrays(moments, q0, w0, [par.flip_interval])
        # the phase 3K ~ 2100 rounded to ~u eps, as above
        assert abs(w[0, 0] / eps - 1.0) < 2e-12 and abs(w[0, 1] + 1.0) < 2e-12
        assert abs(w[0, 2]) < 2e-12 * eps


@pytest.mark.slow  # (11 s of mpmath's Taylor integration: a study; the branch's rates are
# checked against mpmath's K and DLMF's tables in the default run, its flip by exact_kick)
def test_intermediate_axis_separatrix_limit_attitude_against_high_precision():
    # The separatrix-limit branch (k' < 1e-20) for the attitude too: the precession
    # angle's third-kind integral in its m = 1 form, both families (forms A and B),
    # past the flip (u = K + 1.2 K: the complete part and both reduced ranges), against
    # mpmath's Taylor integration at 20 digits (exact to the digits asked for).
    moments = np.array([1.0, 2.0, 3.0])
    q0 = np.array([0.8, 0.2, -0.4, 0.4])
    for w0 in (np.array([0.0, 1.0, 5.7e-21]), np.array([5.7e-21, 1.0, 0.0])):
        t = np.array([0.6 * free_parameters(RigidBody(moments, q0, w0)).flip_interval])
        q, w = free_motion_arrays(moments, q0, w0, t)
        qr, wr = _mp_reference(moments, q0, w0, t, dps=20)
        # measured 4e-15: the angle turned (~100 rad) times eps, a decade of room
        assert np.abs(w - wr).max() < 1e-13 and qdist(q, qr).max() < 1e-13


def test_exact_kick_leaves_the_intermediate_axis():
    # exact_kick's drift is the exact flow: it took (0, 1, 1e-151) as steady and never
    # flipped; it now matches the exact flow through the flip (t = K / lambda, half of
    # the flip interval).  60 000 steps, each re-deriving the motion from a rounded
    # state: ~n eps relative in the departure, amplified at the saddle; measured 1e-9.
    from rigid import integrate

    body = RigidBody([1.0, 2.0, 3.0], omega=[0.0, 1.0, 1e-151])
    t = 0.5 * free_parameters(body).flip_interval
    tr = integrate(body, [0.0, t], method="exact_kick", dt=0.01)
    _, w = free_motion(body, [t])
    assert abs(w[0, 1]) < 1e-3  # the middle of the flip
    assert np.abs(tr.omega[-1] - w[0]).max() < 1e-6


def test_a_state_on_the_separatrix_by_cancellation_stays_on_it():
    """w(2 s) of the separatrix motion of (2, 5, 6) from (1, 0.5, 1) has D = L^2 - 2 T B
    exactly 0 by the cancellation of two terms of order 1; the separatrix limit's
    rescaling (meant for terms that underflow) recomputed it to a rounding residue and
    called the state periodic (K = 20.7, a flip at 61 s where the motion tends to
    the intermediate axis): the flow from w(2) for 38 s left the flow from w(0) for
    40 s, and time_between refused them as on other branches."""
    from rigid import time_between

    moments = [2.0, 5.0, 6.0]
    body = RigidBody(moments, omega=[1.0, 0.5, 1.0])
    _, w = free_motion(body, [2.0, 40.0])
    later = RigidBody(moments, omega=w[0])
    assert free_parameters(later).kind == "separatrix"
    assert time_between(body, body.omega, w[0]) == pytest.approx(2.0, rel=1e-14)
    _, again = free_motion(later, [38.0])
    np.testing.assert_allclose(again[0], w[1], rtol=0, atol=1e-13)


# rates at the edges of the kernel's steady test, on a needle (moments eps, 1, 1): rest,
# exact principal spins, cross terms just below, at and above 1e-150 of the largest
# moment, and far above it, negative rates, a 1e-300 rate beside them
NEEDLE_EDGES = [(x, *tail) for x in (0.0, 1e-151, -1e-151, 1e-150, 1.5e-150, 1e-149, 1e-140)
                for tail in ((1.0, 0.0), (0.0, -1.0), (1.0, 1.0), (1.0, 1e-300), (0.5, -1.0))]


@pytest.mark.parametrize("eps", [1e-60, 2.0**-400])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_free_scale_sees_a_steady_motion_as_the_kernel_does(eps, axis):
    """``rigid._shared.free_scale`` decides whether the motion is steady before it
    lifts the rates (a steady motion keeps ``pow2(omega)``: nothing of the polhode is
    formed), and must decide it where the kernel's ``free_setup`` does: a motion it
    took for steady that the kernel does not would reach the kernel unlifted (its
    polhode terms subnormal: a division by zero), and one it took for unsteady that
    the kernel takes as steady would be lifted, or refused, for nothing.  On a needle
    every unsteady motion of these rates needs a lift (its term ``eps x^2`` below the
    normal range), so free_scale's answer is seen in its scale; the kernel's is its
    ``KIND`` on the rates free_scale gives it, as ``free_setup_scaled`` runs it."""
    from rigid._shared import free_scale, pow2

    order = [(axis + k) % 3 for k in range(3)]
    moments = np.array([eps, 1.0, 1.0])[order]
    decided = []
    for edge in NEEDLE_EDGES:
        w = np.array(edge)[order]
        sw = free_scale(moments, w, "`omega`")
        prm = fk.free_setup(moments / pow2(moments), np.array([1.0, 0.0, 0.0, 0.0]),
                            np.ascontiguousarray(w / sw))
        assert np.all(np.isfinite(prm)), edge
        steady = prm[fk.KIND] == 0.0
        assert (sw == pow2(w)) == steady, (edge, sw, steady)
        decided.append(steady)
    assert 0 < sum(decided) < len(decided)  # (both answers among the edges)
