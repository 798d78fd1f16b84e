"""Tests for rigid.rodrigues: Cayley's parameters, kinematics, composition, re-centring."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from hamilton_orbits import Quaternion
from rigid import RigidBody, integrate
from rigid.euler import GravityGradientTorque, quaternion_rate
from rigid.rodrigues import (
    cayley_propagate,
    compose_gibbs,
    direction_cosines,
    gibbs_rate,
    omega_from_gibbs_rate,
    relative_gibbs,
)

EPS = np.finfo(float).eps
GRID = 2.0**-1074  # the spacing of float64 below the normal range (subnormals)
comp = st.floats(-4.0, 4.0, allow_nan=False)
vec3 = st.tuples(comp, comp, comp).map(np.array)


@settings(deadline=None, max_examples=80)
@given(vec3)
def test_direction_cosines_are_the_attitude_matrix(g):
    # Cayley's kappa alpha = 1 + lambda^2 - mu^2 - nu^2, kappa alpha' = 2(lambda mu + nu)...
    # equal the body-to-space rotation matrix of q = (1, g)/sqrt(kappa): Cayley's
    # (lambda, mu, nu) is q_vec/q_w of our attitude (active v -> q v q^-1).
    r = direction_cosines(g)
    ref = Quaternion.from_gibbs(g).as_rotation_matrix()
    np.testing.assert_allclose(r, ref, rtol=0, atol=16 * EPS)
    # Cayley's inverse relations (p. 226): with upsilon = 1 + alpha + beta' + gamma''
    # = 4/kappa, lambda upsilon = beta'' - gamma', mu upsilon = gamma - alpha'',
    # nu upsilon = alpha' - beta.
    ups = 1.0 + np.trace(r)
    kap = 1.0 + g @ g
    np.testing.assert_allclose(ups, 4.0 / kap, rtol=16 * EPS * kap)
    got = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    np.testing.assert_allclose(got, g * ups, rtol=0, atol=32 * EPS)


@settings(deadline=None, max_examples=80)
@given(vec3, vec3)
# a subnormal w (the kappa' check's relative bound underflowed to 0: found by hypothesis)
@example(np.array([3.9, -2.7, 1.1]), np.array([5e-324, -1e-323, 2.5e-320]))
@example(np.array([-4.0, 4.0, -4.0]), np.array([1e-310, 3e-300, -7e-315]))
def test_gibbs_rate_is_quaternion_kinematics(g, w):
    # g = v/w  =>  g' = (w v' - v w')/w^2 with q' = q (0, omega)/2: Cayley's
    # 2 lambda' = (1 + lambda^2) p + ... is the same equation.
    q = Quaternion.from_gibbs(g)
    qd = quaternion_rate(q, w).as_array()
    a = q.as_array()
    ref = (a[0] * qd[1:] - a[1:] * qd[0]) / a[0] ** 2
    got = gibbs_rate(g, w)
    kap = 1.0 + g @ g
    scale = kap * np.abs(w).max()  # not norm(): w^2 may underflow
    # Below the normal range (a tiny or subnormal w) the relative bound underflows
    # and every rounding costs up to GRID / 2 absolute: a floor of a few GRID, times
    # kappa (the division by q_w^2 = 1 / kappa); measured <= 2 kappa GRID
    np.testing.assert_allclose(got, ref, rtol=0, atol=32 * EPS * scale + 8 * kap * GRID)
    # kappa' = kappa (lambda p + mu q + nu r) (Cayley 1843, p. 228); the floor as above,
    # times 1 + |g|_1 for the products with g (measured <= kappa (1 + |g|_1) GRID)
    np.testing.assert_allclose(2 * g @ got, kap * (g @ w), rtol=0,
                               atol=32 * EPS * kap * scale
                               + 8 * kap * (1.0 + np.abs(g).sum()) * GRID)


@settings(deadline=None, max_examples=80)
@given(vec3, vec3)
@example(np.array([3.9, -2.7, 1.1]), np.array([5e-324, -1e-323, 2.5e-320]))
@example(np.array([0.5, 0.0, -1.0]), np.array([1e-200, 0.0, 3e-201]))
def test_omega_round_trip(g, w):
    # kappa p = 2(lambda' + nu mu' - nu' mu) ... inverts the kinematic equations.
    back = omega_from_gibbs_rate(g, gibbs_rate(g, w))
    # relative to |w| (was 1e-13 absolute for any |w| < 1: no check at all of a tiny w)
    # with the floor of the subnormal grid, both times kappa (measured <= 1.8 eps kappa
    # |w| and <= 3 kappa GRID)
    kap = 1.0 + g @ g
    np.testing.assert_allclose(back, w, rtol=0,
                               atol=32 * EPS * kap * np.abs(w).max() + 32 * kap * GRID)


@settings(deadline=None, max_examples=80)
@given(vec3, vec3)
def test_compose_is_hamilton_product(a, b):
    pi = 1.0 - a @ b
    assume(abs(pi) >= 1e-3)  # near a composed half-turn the Gibbs vector is ill-conditioned
    got = compose_gibbs(a, b)
    qa = np.array([1.0, *a])
    qb = np.array([1.0, *b])
    prod = (Quaternion(qa) * Quaternion(qb)).as_array()
    ref = prod[1:] / prod[0]
    cond = (1 + np.abs(a).max()) * (1 + np.abs(b).max()) / abs(pi)
    np.testing.assert_allclose(got, ref, rtol=0, atol=16 * EPS * cond * (1 + abs(ref).max()))
    # relative_gibbs inverts Cayley's P_0 system: compose(l, g0) = g.
    back = compose_gibbs(relative_gibbs(got, b), b)
    np.testing.assert_allclose(back, got, rtol=0, atol=1e-12 * cond**2 * (1 + abs(got).max()))


def test_relative_gibbs_printed_note_sign():
    # The seed's Note prints (1 + g.g0) l = lambda - lambda_0 + nu_0 mu - nu mu_0;
    # this does not invert its own P_0 system (the cross term has the wrong sign),
    # while relative_gibbs does.  Values chosen so the cross term is not small.
    g = np.array([0.4, 0.5, -0.6])
    g0 = np.array([0.1, -0.2, 0.3])
    printed = (g - g0 + np.cross(g, g0)) / (1 + g @ g0)
    assert np.abs(compose_gibbs(printed, g0) - g).max() > 0.1
    np.testing.assert_allclose(compose_gibbs(relative_gibbs(g, g0), g0), g, atol=8 * EPS)


def test_compose_half_turn_raises():
    with pytest.raises(ValueError, match=r"`first`, `second` whose composition is not a "
                                         r"half-turn, got Cayley's Pi = 0.0 at index 1"):
        compose_gibbs([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]], [[0.0, 0.0, 0.5], [0.0, 0.0, 1.0]])


def test_direction_cosines_near_a_half_turn():
    # Gibbs vector tan(theta/2) e: at 1e200 (theta = pi - 2e-200) the matrix is the
    # half-turn about e, 2 e e^T - I, to rounding; before, lam^2 overflowed to NaN.
    e = np.array([1.0, 2.0, 2.0]) / 3.0
    r = direction_cosines(1e200 * e)
    np.testing.assert_allclose(r, 2.0 * np.outer(e, e) - np.eye(3), atol=4 * EPS)
    # two rotations near half-turns compose to an ordinary one: (1, a)(1, b) with a.b
    # and a x b of 1e400 (their ratio exact), refused before as beyond float64
    np.testing.assert_allclose(compose_gibbs([1e200, 1e200, 0.0], [0.0, 1e200, 1e200]),
                               [-1.0, 1.0, -1.0], rtol=4 * EPS)


def test_sphere_through_half_turns_matches_exact():
    # A sphere keeps omega constant: q(t) = q0 exp(omega t / 2) exactly.  5 s at
    # |omega| = 1.9 rad/s is 9.5 rad: three half-turns.  RK4 with h = 1e-3 on
    # Cayley's (nonlinear) equations: truncation ~ t (|w| h)^4 ~ 1e-13.
    w = np.array([0.5, -1.2, 1.4])
    q0 = Quaternion.from_axis_angle([1.0, 1.0, 0.0], 2.5)
    body = RigidBody([2.0, 2.0, 2.0], attitude=q0, omega=w)
    tr = cayley_propagate(body, 5.0, 1e-3, n_out=51)
    wn = np.linalg.norm(w)
    exact = q0 * Quaternion.from_axis_angle(w / wn, wn * np.asarray(tr.t))
    assert tr.n_recentre >= 3
    assert np.max(tr.attitude.rotation_distance(exact)) < 1e-12
    # the path really passes half-turns relative to the start
    assert np.max(tr.attitude.rotation_distance(q0)) > 3.0


def test_cayley_matches_quaternion_path_asymmetric_torqued():
    # Euler's equations + Cayley kinematics vs Euler + quaternion kinematics, the
    # same RK4 (h = 1e-3) on a torqued asymmetric body over 12 s (several half-
    # turns): the two paths agree to ~1e-12 (both within RK4's truncation error
    # of the true path, which is ~1e-13 here).
    body = RigidBody([1.0, 2.0, 3.0], attitude=Quaternion.from_axis_angle([0, 1, 0], 0.4),
                     omega=[0.3, 1.5, -0.4])
    tq = GravityGradientTorque(0.2, mean_motion=0.45)
    a = cayley_propagate(body, 12.0, 1e-3, n_out=61, torque=tq)
    b = integrate(body, np.linspace(0.0, 12.0, 61), dt=1e-3, method="rk4", torque=tq)
    assert a.n_recentre >= 3
    assert np.max(a.attitude.rotation_distance(b.attitude)) < 1e-12
    np.testing.assert_allclose(a.omega, b.omega, rtol=0, atol=1e-12)
    # and both agree with DOP853 at tight tolerance to ~1e-11 (RK4 truncation)
    c = integrate(body, np.linspace(0.0, 12.0, 61), method="dop853", tol=1e-13, torque=tq)
    assert np.max(a.attitude.rotation_distance(c.attitude)) < 1e-11


def test_cayley_bad_input():
    body = RigidBody([1.0, 2.0, 3.0], omega=[0.3, 1.5, -0.4])
    with pytest.raises(ValueError, match="`recentre` > 0"):
        cayley_propagate(body, 1.0, 0.1, recentre=0.0)
    with pytest.raises(ValueError, match=r"`gibbs` to be finite, got nan at index 2"):
        gibbs_rate([0.0, 0.0, np.nan], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"`gibbs_dot` to have shape \(\.\.\., 3\)"):
        omega_from_gibbs_rate([0.0, 0.0, 0.0], [1.0, 0.0])
    with pytest.raises(ValueError, match="broadcast"):
        compose_gibbs(np.zeros((2, 3)), np.zeros((4, 3)))


def test_omega_from_gibbs_rate_takes_the_quantity_gibbs_rate_gives():
    """``omega_from_gibbs_rate`` is documented as the inverse of ``gibbs_rate``, which
    answers a Quantity (1/s) for a Quantity ``omega``; given it back, it refused
    it ("Expected `gibbs_dot` to be dimensionless, got 1 / s").  The round trip
    gives the rates back, in rad/s, to rounding (Cayley 1843, p. 228, both ways)."""
    import astropy.units as u

    from rigid.rodrigues import gibbs_rate, omega_from_gibbs_rate

    g = np.array([[0.1, -0.2, 0.3], [2.0, 0.5, -1.0]])
    w = np.array([[0.2, 0.4, 0.6], [-1.0, 0.3, 0.7]]) * u.rad / u.s
    back = omega_from_gibbs_rate(g, gibbs_rate(g, w))
    assert back.unit == u.rad / u.s
    # (a few ulp of rates of order 1: the map and its inverse each round a few times)
    np.testing.assert_allclose(back.to_value(u.rad / u.s), w.value, rtol=0, atol=1e-15)
    per_day = omega_from_gibbs_rate(g, gibbs_rate(g, w).to(1 / u.day))
    np.testing.assert_allclose(per_day.to_value(u.rad / u.s), w.value, rtol=1e-15, atol=0)
    with pytest.raises(u.UnitConversionError, match=r"Expected `gibbs_dot` to be a rate"):
        omega_from_gibbs_rate(g, [0.0, 0.0, 1.0] * u.m)


def test_compose_gibbs_applies_its_second_argument_first():
    """The docstring's example said "quarter turns about x then y" of
    compose_gibbs(x, y): the result, q(x) q(y), turns about y first (z to x), then
    about x (x stays), as active rotations compose (docs/quaternion.md)."""
    g = compose_gibbs([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    z_to = Quaternion([1.0, *g]).rotate([0.0, 0.0, 1.0])
    np.testing.assert_allclose(z_to, [1.0, 0.0, 0.0], atol=4 * EPS)
    assert "``second`` is applied first, then ``first``" in compose_gibbs.__doc__


def test_compose_and_relative_gibbs_of_large_vectors_keep_their_scale():
    """Gibbs vectors of 1e155 (rotations within 1e-155 of a half-turn): Cayley's Pi
    and the cross products, unscaled, overflowed (a "nan" error, or -0 for a
    component of 1e-310): the homogeneous form scaled by a power of two gives the
    quaternion product's Gibbs vector."""
    def reference(a, b, sign=1.0):
        qa, qb = np.array([1.0, *a]), np.array([1.0, *(sign * np.asarray(b))])
        s = 2.0**-520  # (the quaternions scaled: their product cannot overflow)
        p = (Quaternion(qa * s) * Quaternion(qb * s)).as_array()
        return p[1:] / p[0]

    for a, b in (([1e155, 0, 0], [1e155, 1e155, 0]), ([1e155, 0, 0], [1e155, 1, 0])):
        np.testing.assert_allclose(compose_gibbs(a, b), reference(a, b), rtol=8 * EPS)
    g, g0 = [1e155, 0, 0], [-1e155, 1e155, 0]
    np.testing.assert_allclose(relative_gibbs(g, g0), reference(g, g0, -1.0), rtol=8 * EPS)
    assert compose_gibbs([0.1, 0.2, 0.3], [0.3, -0.1, 0.2]).tolist() == (
        (np.array([0.1, 0.2, 0.3]) + [0.3, -0.1, 0.2] + np.cross([0.1, 0.2, 0.3], [0.3, -0.1, 0.2]))
        / (1 - np.dot([0.1, 0.2, 0.3], [0.3, -0.1, 0.2]))).tolist()  # (ordinary: the same bits)
