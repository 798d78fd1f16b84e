"""Tests for rigid.euler: Euler's equations, quaternion kinematics, torques."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from hamilton_orbits import Quaternion
from rigid.euler import (
    BodyTorque,
    GravityGradientTorque,
    SpaceTorque,
    euler_equations,
    quaternion_rate,
    torque_on,
)

EPS = np.finfo(float).eps
GRID = 2.0**-1074  # the spacing of float64 below the normal range (subnormals)
finite = st.floats(-3.0, 3.0, allow_nan=False)
positive = st.floats(0.1, 5.0)
vec3 = st.tuples(finite, finite, finite).map(np.array)
# principal moments of a body (A + B >= C for every order: the sums of pairs of three
# positive numbers are every such triple)
moments3 = st.tuples(positive, positive, positive).map(
    lambda x: np.array([x[0] + x[1], x[1] + x[2], x[2] + x[0]]) / 2.0)
quat4 = st.tuples(finite, finite, finite, finite).map(np.array).filter(
    lambda q: np.linalg.norm(q) > 0.1
)


def test_euler_hand_values():
    # Hand-derived from A p' + (C - B) q r = N_x etc. (Cayley 1843): with
    # (A, B, C) = (1, 2, 3), omega = (1, 1, 1), N = (1, 0, 3):
    # p' = (1 - 1)/1 = 0, q' = (0 - (1 - 3))/2 = 1, r' = (3 - (2 - 1))/3 = 2/3.
    got = euler_equations([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [1.0, 0.0, 3.0])
    np.testing.assert_allclose(got, [0.0, 1.0, 2.0 / 3.0], rtol=2 * EPS, atol=0)


@settings(deadline=None, max_examples=60)
@given(moments3, vec3, vec3)
@example(np.array([2.6, 5.0, 2.5]), np.array([3.0, -1e-310, 2e-320]), np.array([5e-324, 0.0, -3.0]))
@example(np.array([2.5, 2.5, 5.0]), np.array([1e-160, 2e-160, -3e-160]), np.array([1e-300] * 3))
def test_euler_energy_and_momentum_rates(m, w, n):
    # Identities of Euler's equations: dT/dt = omega . N (the gyroscopic terms
    # cancel) and d|L|^2/dt / 2 = L . N.  Both to a few ulp of the term sizes.
    wd = euler_equations(m, w, n)
    # Below the normal range (tiny w or n) the relative bounds underflow and each
    # rounding costs up to GRID / 2 absolute, a rounding of omega' (or of A omega')
    # weighted by |A omega| and A: the floor (measured <= a fifth of it; was 1e-300,
    # 1e23 GRID, which checked nothing for terms below ~1e-284)
    floor = 32 * (1.0 + np.abs(m * w).sum()) * (1.0 + m.max()) * GRID
    scale = np.sum(np.abs(m * w * wd)) + np.sum(np.abs(w * n))
    assert abs(np.sum(m * w * wd) - np.sum(w * n)) <= 8 * EPS * scale + floor
    ell = m * w
    scale = np.sum(np.abs(ell * m * wd)) + np.sum(np.abs(ell * n))
    assert abs(np.sum(ell * m * wd) - np.sum(ell * n)) <= 8 * EPS * scale + floor


def test_euler_broadcast_and_quantities():
    m = np.array([[1.0, 2.0, 3.0], [2.0, 2.0, 2.0]])
    w = np.array([1.0, 1.0, 1.0])
    got = euler_equations(m, w)
    assert got.shape == (2, 3)
    np.testing.assert_array_equal(got[1], [0.0, 0.0, 0.0])  # sphere, no torque
    q = euler_equations(m * u.kg * u.m**2, w * u.rad / u.s, [1.0, 1.0, 1.0] * u.N * u.m)
    assert q.unit.is_equivalent(u.rad / u.s**2)
    np.testing.assert_allclose(q.to_value(u.rad / u.s**2)[1], [0.5, 0.5, 0.5], rtol=EPS)
    # a number is no torque vector: it was taken as (N, N, N), sqrt(3) times as large
    with pytest.raises(ValueError, match=r"`torque` to have shape \(\.\.\., 3\), got \(\)"):
        euler_equations(m, w, 1.0)


def test_moments_of_no_body_are_refused():
    # Sylvester (1866): each principal moment "must be not greater than the sum of the
    # other two"; RigidBody refuses [1, 1, 3], and so do the functions taking moments
    with pytest.raises(ValueError, match=r"`moments` to satisfy A \+ B >= C, got 3.0 at "
                                         r"index 2 > 2.0"):
        euler_equations([1.0, 1.0, 3.0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"A \+ B >= C, got 3.5 at index \(1, 2\) > 2.0"):
        euler_equations([[1.0, 2.0, 3.0], [1.0, 1.0, 3.5]], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"`moments` to satisfy A \+ B >= C, got 3.0 at index 2"):
        torque_on(BodyTorque([1.0, 0.0, 0.0]), [1.0, 1.0, 3.0], Quaternion([1.0, 0, 0, 0]))
    # a flat disk (C = A + B, built in floating point) is a body
    np.testing.assert_array_equal(euler_equations([0.1, 0.2, 0.1 + 0.2], [0.0, 0.0, 1.0]),
                                  [0.0, 0.0, 0.0])


@settings(deadline=None, max_examples=60)
@given(quat4, vec3)
@example(np.array([3.0, -3.0, 0.1, 2.0]), np.array([5e-324, -2e-323, 1e-310]))
def test_quaternion_rate_orthogonal_and_linear(q, w):
    # dq/dt = q omega / 2 is orthogonal to q (|q| conserved): q . q' = 0 to ulp.
    qd = quaternion_rate(Quaternion(q), w).as_array()
    # (a floor of the subnormal grid for a tiny w: GRID / 2 per rounding of q' and of
    # the products with q; measured <= 10 GRID)
    floor = 16 * (1.0 + np.abs(q).sum()) * GRID
    assert abs(np.dot(q, qd)) <= 8 * EPS * np.linalg.norm(q) ** 2 * np.abs(w).max() * 2 + floor
    # and it equals the Hamilton product q (0, omega) / 2 of the core.
    ref = (Quaternion(q) * Quaternion.from_vector(w)).as_array() / 2
    np.testing.assert_allclose(qd, ref, rtol=0, atol=4 * EPS * np.abs(ref).max() + 4 * GRID)


def test_quaternion_rate_matches_finite_difference():
    # Constant omega: q(t) = q0 (cos(|w| t/2), sin(|w| t/2) w/|w|).  Five-point
    # central difference, h = 1e-3: truncation h^4/30 |q'''''| ~ 1e-14, rounding
    # ~ eps/h ~ 2e-13; tolerance 1e-11 covers both.
    q0 = Quaternion.from_axis_angle([0.3, -0.2, 0.9], 1.1)
    w = np.array([0.4, -1.3, 0.7])
    wn = np.linalg.norm(w)

    def q(t):
        return (q0 * Quaternion.from_axis_angle(w / wn, wn * t)).as_array()

    h = 1e-3
    fd = (-q(2 * h) + 8 * q(h) - 8 * q(-h) + q(-2 * h)) / (12 * h)
    np.testing.assert_allclose(quaternion_rate(q0, w).as_array(), fd, rtol=0, atol=1e-11)


def test_body_and_space_torque():
    q = Quaternion.from_axis_angle([1.0, 2.0, -0.5], 0.8)
    np.testing.assert_array_equal(torque_on(BodyTorque([1.0, 2.0, 3.0]), [1, 1, 1], q),
                                  [1.0, 2.0, 3.0])
    n_space = np.array([0.3, -1.0, 2.0])
    got = torque_on(SpaceTorque(n_space), [1.0, 2.0, 3.0], q)
    # body = R^T N_space with R the body-to-space matrix.
    ref = q.as_rotation_matrix().T @ n_space
    np.testing.assert_allclose(got, ref, rtol=0, atol=8 * EPS * np.linalg.norm(n_space))


def test_gravity_gradient_pitch_torque():
    # Body turned by theta about the orbit normal z from the local vertical (x):
    # c_body = (cos th, -sin th, 0), N_z = -3 n^2 (B - A) sin th cos th, the
    # classical pitch gravity-gradient torque (Hughes 1986, Spacecraft Attitude
    # Dynamics, ch. 8: pitch libration frequency^2 = 3 n^2 (B - A) / C).
    m = np.array([1.0, 2.0, 2.5])
    th = np.linspace(-1.0, 1.0, 7)
    q = Quaternion.from_axis_angle(np.array([0.0, 0.0, 1.0]), th)
    got = torque_on(GravityGradientTorque(0.49), m, q)
    ref = -3 * 0.49 * (m[1] - m[0]) * np.sin(th) * np.cos(th)
    np.testing.assert_allclose(got[:, 2], ref, rtol=0, atol=16 * EPS)
    np.testing.assert_allclose(got[:, :2], 0.0, rtol=0, atol=16 * EPS)


def test_gravity_gradient_turning_direction():
    # At time t the primary is at angle n t: the torque on a body turned by the
    # same angle about z (its x axis on the vertical) vanishes; zero also for
    # each principal axis along the vertical (equilibria).
    gg = GravityGradientTorque(1.0, mean_motion=0.3, phase=0.1)
    t = np.array([0.0, 1.0, 5.0, 20.0])
    q = Quaternion.from_axis_angle(np.array([0.0, 0.0, 1.0]), 0.3 * t + 0.1)
    got = torque_on(gg, [1.0, 2.0, 3.0], q, t)
    np.testing.assert_allclose(got, 0.0, rtol=0, atol=32 * EPS)
    gq = GravityGradientTorque(4.0e-6 / u.s**2)
    assert torque_on(gq, [1.0, 2.0, 3.0] * u.kg * u.m**2, q).unit == u.N * u.m


def test_bad_input():
    with pytest.raises(ValueError, match=r"`omega`.*nan at index 1"):
        euler_equations([1.0, 2.0, 3.0], [1.0, np.nan, 0.0])
    with pytest.raises(ValueError, match=r"`moments` > 0, got -2.0 at index 1"):
        euler_equations([1.0, -2.0, 3.0], [1.0, 1.0, 0.0])
    with pytest.raises(ValueError, match=r"`omega` to have shape \(\.\.\., 3\), got \(2,\)"):
        euler_equations([1.0, 2.0, 3.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="broadcast"):
        euler_equations(np.ones((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError, match=r"`attitude` to have shape \(\.\.\., 4\)"):
        quaternion_rate([1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"`attitude` to be a nonzero quaternion, got \[0.0, 0"):
        quaternion_rate([0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"`torque` to have shape \(3,\)"):
        BodyTorque([1.0, 2.0])
    with pytest.raises(ValueError, match=r"`torque` to be finite, got inf at index 2"):
        SpaceTorque([1.0, 2.0, np.inf])
    with pytest.raises(ValueError, match=r"`gm_over_r3` >= 0"):
        GravityGradientTorque(-1.0)
    with pytest.raises(ValueError, match="`e1` to be a unit vector"):
        GravityGradientTorque(1.0, e1=[2.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="orthogonal"):
        GravityGradientTorque(1.0, e2=[1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="Expected `torque` to be None"):
        torque_on("gravity", [1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0])


# --- a plain number beside Quantities: GM / R^3 and the mean motion of the gravity
# gradient, and a torque's numbers beside a body of Quantities, were read as SI


def test_gravity_gradient_refuses_a_quantity_beside_a_plain_rate():
    with pytest.raises(ValueError, match=r"Expected `mean_motion` to be a Quantity like "
                                         r"`gm_over_r3` \(1e-06 1 / s2\), got the plain "
                                         r"number 0.001$"):
        GravityGradientTorque(1e-6 / u.s**2, mean_motion=1e-3)
    with pytest.raises(ValueError, match=r"Expected `gm_over_r3` to be a Quantity like "
                                         r"`mean_motion`.*got the plain number 1e-06$"):
        GravityGradientTorque(1e-6, mean_motion=1e-3 * u.rad / u.s)
    # a plain zero (the default mean motion) is zero in every unit; a plain phase is
    # radians, beside Quantities too (the package's angles), as documented
    a = GravityGradientTorque(1e-6 / u.s**2, phase=0.5).encode()[1]
    b = GravityGradientTorque(1e-6 / u.s**2, 0.0 * u.rad / u.s, 0.5 * u.rad).encode()[1]
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(("torque", "name", "value", "index"), [
    (BodyTorque([0.0, 0.0, 2.0]), "torque", 2.0, " at index 2"),
    (SpaceTorque([0.0, -1.0, 0.0]), "torque", -1.0, " at index 1"),
    (GravityGradientTorque(1e-6), "gm_over_r3", 1e-06, ""),
], ids=["body", "space", "gravity-gradient"])
def test_a_plain_torque_beside_a_body_of_quantities_is_refused(torque, name, value, index):
    from rigid import RigidBody, integrate

    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.1, 0.2, 0.3] * u.rad / u.s)
    kind = type(torque).__name__
    got = rf"got the plain number {value}{index}$"
    with pytest.raises(ValueError, match=rf"Expected {kind}'s `{name}` to be a Quantity like "
                                         rf"`body` \(\[1. 2. 3.\] m2 kg\), {got}"):
        integrate(body, [0.0, 1.0] * u.s, dt=0.5 * u.s, torque=torque)
    with pytest.raises(ValueError, match=rf"{kind}'s `{name}` to be a Quantity like "
                                         rf"`moments`.*{got}"):
        torque_on(torque, body.moments, [1.0, 0.0, 0.0, 0.0])
    # zeros are zero in every unit; a body of plain numbers (SI) takes either
    torque_on(BodyTorque([0.0, 0.0, 0.0]), body.moments, [1.0, 0.0, 0.0, 0.0])
    plain = torque_on(BodyTorque([0.0, 0.0, 2.0] * u.N * u.m), [1.0, 2.0, 3.0], [1, 0, 0, 0])
    np.testing.assert_array_equal(plain, [0.0, 0.0, 2.0])
