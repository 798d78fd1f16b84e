"""Tests of Hamilton's quaternion core (issue 2).

References
----------
Hamilton, W. R. (1845), "On the application of the method of quaternions to some
dynamical questions" (seed; equation numbers below are his).
Cayley, A. (1843), "On the motion of rotation of a solid body" (seed).
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from hamilton_orbits import Quaternion, slerp

EPS = np.finfo(float).eps
TINY = float(np.finfo(float).smallest_subnormal)  # 2**-1074, the subnormal unit
rng = np.random.default_rng(20261122)

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
quat_arrays = arrays(np.float64, (4,), elements=finite).filter(
    lambda a: np.linalg.norm(a) > 1e-3
)
vec_arrays = arrays(np.float64, (3,), elements=finite)


def random_unit(n: int) -> Quaternion:
    return Quaternion.from_array(rng.normal(size=(n, 4))).unit()


# ---------------------------------------------------------------- Hamilton's algebra
def test_hamilton_units_square_to_minus_one():
    """i^2 = j^2 = k^2 = ijk = -1 (Hamilton's defining relations)."""
    one = np.array([1.0, 0, 0, 0])
    i, j, k = Quaternion.from_array(np.eye(4)[1:])
    for u in (i, j, k):
        np.testing.assert_array_equal((u * u).as_array(), -one)
    np.testing.assert_array_equal((i * j * k).as_array(), -one)
    np.testing.assert_array_equal((i * j).as_array(), k.as_array())
    np.testing.assert_array_equal((j * i).as_array(), -k.as_array())


def exact_dot(a, b) -> Fraction:
    """a.b in exact rational arithmetic (the reference for rounded products)."""
    terms = (Fraction(float(x)) * Fraction(float(y)) for x, y in zip(a, b, strict=True))
    return sum(terms, Fraction(0))


@settings(deadline=None, max_examples=200)
@given(vec_arrays, vec_arrays)
# Regressions (issue 7, item 13).  The old tolerance 4 eps (|a| |b| + 1e-300)
# took |a| from np.linalg.norm, which underflows to 0 for |a| ~ 1e-200, so the
# tolerance was 1e-315 where the rounding error of a 1e-197 product is 1e-213;
# a pure relative tolerance is also 0 where products are subnormal, while each
# rounded product is off by up to half a subnormal unit.  The suite's second run
# replayed such an example from the hypothesis database and failed.
@example(np.array([1e-200, 0.0, 3e-201]), np.array([1.0, 1.0, 1.0]))
@example(np.array([1e-200, 3e-201, 7e-201]), np.array([0.1, 0.3, 0.7]))  # error 1.1e-217
@example(np.array([1.5e-162, 0.0, 0.0]), np.array([1.5e-162, 0.0, 0.0]))
@example(np.array([3e-162, -3e-162, 3e-162]), np.array([1e-170, 2e-161, -7e-163]))
@example(np.array([0.0, 0.0, 5e-324]), np.array([0.0, 0.0, 1e3]))
def test_product_of_vectors(a, b):
    """For pure quaternions alpha beta = -alpha.beta + alpha x beta; alpha^2 = -|alpha|^2.

    Error model for each component, a sum of (at most) three rounded products
    p_i: |error| <= 1.5 eps sum |p_i| + 1.5 TINY (half an ulp per product and per
    addition, half a subnormal unit per underflowing product).  ``scale`` =
    3 max|a| max|b| bounds sum |p_i| and, unlike np.linalg.norm, cannot
    underflow for tiny vectors.  The same bound holds for numpy's cross product
    in any summation order or with fused multiply-adds, hence 2x for the cross.
    """
    qa, qb = Quaternion.from_vector(a), Quaternion.from_vector(b)
    prod = (qa * qb).as_array()
    scale = 3.0 * np.max(np.abs(a)) * np.max(np.abs(b))
    # scalar part against the exact rational -a.b
    tol = Fraction(1.5 * EPS * scale) + Fraction(1.5 * TINY)
    assert abs(Fraction(float(prod[0])) + exact_dot(a, b)) <= tol
    np.testing.assert_allclose(prod[1:], np.cross(a, b), rtol=0, atol=3 * EPS * scale + 3 * TINY)
    sq = (qa * qa).as_array()
    exact = exact_dot(a, a)
    assert abs(Fraction(float(sq[0])) + exact) <= 2 * EPS * exact + Fraction(2 * TINY)
    np.testing.assert_array_equal(sq[1:], 0.0)


@settings(deadline=None, max_examples=200)
@given(vec_arrays, vec_arrays)
def test_identity_39(d, e):
    """Hamilton's (39): ((de + ed)/2)^2 = ((de - ed)/2)^2 + d^2 e^2, via quaternion products."""
    qd, qe = Quaternion.from_vector(d), Quaternion.from_vector(e)
    sym = (qd * qe + qe * qd) * 0.5
    anti = (qd * qe - qe * qd) * 0.5
    lhs = (sym * sym).as_array()
    rhs = (anti * anti + (qd * qd) * (qe * qe)).as_array()
    scale = (np.dot(d, d) * np.dot(e, e)) + 1e-300
    # each side is a handful of rounded products of magnitude <= |d|^2|e|^2
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=16 * EPS * scale)


@settings(deadline=None, max_examples=200)
@given(quat_arrays, quat_arrays, quat_arrays)
def test_associative_and_multiplicative_norm(a, b, c):
    """(pq)r = p(qr) and |pq| = |p||q| (the law of the moduli)."""
    p, q, r = Quaternion(a), Quaternion(b), Quaternion(c)
    scale = np.linalg.norm(a) * np.linalg.norm(b) * np.linalg.norm(c)
    np.testing.assert_allclose(
        ((p * q) * r).as_array(), (p * (q * r)).as_array(), rtol=0, atol=16 * EPS * scale
    )
    assert abs((p * q).norm() - p.norm() * q.norm()) <= 8 * EPS * p.norm() * q.norm()


def test_product_broadcasts():
    p = random_unit(5)
    q = Quaternion.from_array(rng.normal(size=(3, 1, 4)))
    pq = q * p
    assert pq.shape == (3, 5)
    np.testing.assert_array_equal(pq[2, 4].as_array(), (q[2, 0] * p[4]).as_array())


# ---------------------------------------------------------------- Cayley 1843
def cayley_direction_cosines(lam, mu, nu):
    """Cayley's rational direction cosines: columns (alpha, alpha', alpha'') etc."""
    kappa = 1 + lam**2 + mu**2 + nu**2
    alpha = np.array([1 + lam**2 - mu**2 - nu**2, 2 * (lam * mu + nu), 2 * (nu * lam - mu)])
    beta = np.array([2 * (lam * mu - nu), 1 + mu**2 - nu**2 - lam**2, 2 * (mu * nu + lam)])
    gamma = np.array([2 * (nu * lam + mu), 2 * (mu * nu - lam), 1 + nu**2 - lam**2 - mu**2])
    # alpha = cos(x1, x), alpha' = cos(x1, y), alpha'' = cos(x1, z): the new x1 axis
    # in the old frame, so (alpha, alpha', alpha'') is the first column.
    return np.stack([alpha, beta, gamma], axis=1) / kappa


@settings(deadline=None, max_examples=200)
@given(arrays(np.float64, (3,), elements=st.floats(-50, 50)))
def test_cayley_direction_cosines(g):
    """kappa alpha = 1 + lambda^2 - mu^2 - nu^2 and the rest, against as_rotation_matrix."""
    R = Quaternion.from_gibbs(g).as_rotation_matrix()
    np.testing.assert_allclose(R, cayley_direction_cosines(*g), rtol=0, atol=8 * EPS)


def cayley_compose(a, b):
    """Cayley's (Pi) formulas for the Rodrigues parameters of the combined displacement.

    Pi = 1 - l l1 - m m1 - n n1, Pi lambda = l + l1 + n1 m - n m1, and cyclically.
    The seed's transcription prints the last terms of the mu and nu lines as
    ``l m1`` and ``m n1``; the cyclic substitution l -> m -> n that Cayley states
    for these formulas gives ``l n1`` and ``m l1``, which is what is used here.
    """
    l, m, n = a
    l1, m1, n1 = b
    pi = 1 - l * l1 - m * m1 - n * n1
    return np.array(
        [l + l1 + n1 * m - n * m1, m + m1 + l1 * n - l * n1, n + n1 + m1 * l - m * l1]
    ) / pi


@settings(deadline=None, max_examples=200)
@given(
    arrays(np.float64, (3,), elements=st.floats(-3, 3)),
    arrays(np.float64, (3,), elements=st.floats(-3, 3)),
)
def test_cayley_composition_is_the_hamilton_product(a, b):
    """Cayley's composition equals q(a) q(b): the displacement b first, then a (active).

    In this package's active convention (v -> q v q^-1) the composite rotation
    R(a) R(b) applies b first; Cayley's formulas give the Gibbs vector of the
    Hamilton product q(a) q(b).
    """
    pi = 1 - np.dot(a, b)
    assume(abs(pi) >= 1e-3)  # near a composed half-turn the Gibbs vector is ill conditioned
    q = Quaternion.from_gibbs(a) * Quaternion.from_gibbs(b)
    expected = cayley_compose(a, b)
    cond = (1 + np.dot(expected, expected)) * (1 + np.dot(a, a)) * (1 + np.dot(b, b))
    np.testing.assert_allclose(q.as_gibbs(), expected, rtol=0, atol=32 * EPS * cond)
    Ra = Quaternion.from_gibbs(a).as_rotation_matrix()
    Rb = Quaternion.from_gibbs(b).as_rotation_matrix()
    np.testing.assert_allclose(q.as_rotation_matrix(), Ra @ Rb, rtol=0, atol=16 * EPS)


def test_cayley_composition_known_values():
    """Two quarter-turns about x and y: hand-derived Gibbs vector of the composite.

    a = (1, 0, 0) (90 deg about x), b = (0, 1, 0) (90 deg about y):
    Pi = 1, (lambda, mu, nu) = (1, 1, 0) + a x b = (1, 1, 1): a 120 deg turn about (1,1,1).
    """
    q = Quaternion.from_gibbs([1.0, 0, 0]) * Quaternion.from_gibbs([0, 1.0, 0])
    np.testing.assert_allclose(q.as_gibbs(), [1.0, 1.0, 1.0], rtol=4 * EPS)
    axis, angle = q.as_axis_angle()
    assert abs(angle - 2 * np.pi / 3) <= 4 * EPS
    np.testing.assert_allclose(axis, np.ones(3) / np.sqrt(3), rtol=4 * EPS)


# ---------------------------------------------------------------- representations
def assert_same_rotation_components(back: Quaternion, q: Quaternion, tol: float) -> None:
    """Componentwise at ``tol``, up to the overall sign (q and -q are one rotation)."""
    a, b = back.as_array(), q.as_array()
    err = min(np.max(np.abs(a - b)), np.max(np.abs(a + b)))
    assert err <= tol, (a, b, err)


@settings(deadline=None, max_examples=300)
@given(quat_arrays)
def test_round_trips(a):
    """Every representation round-trips to the same rotation at a few ulp."""
    q = Quaternion(a).unit().canonical()
    tol = 8 * EPS
    assert_same_rotation_components(Quaternion.from_rotation_matrix(q.as_rotation_matrix()), q, tol)
    axis, angle = q.as_axis_angle()
    assert_same_rotation_components(Quaternion.from_axis_angle(axis, angle), q, tol)
    assert_same_rotation_components(Quaternion.from_mrp(q.as_mrp()), q, tol)
    assert np.linalg.norm(q.as_mrp()) <= 1 + 2 * EPS
    if q.w > 1e-3:  # away from a half-turn the Gibbs vector is well conditioned
        assert_same_rotation_components(Quaternion.from_gibbs(q.as_gibbs()), q, tol)
    assert_same_rotation_components(q.log().exp(), q, tol)


def test_round_trips_batched_all_axis_permutations():
    """Rotations about each axis and its negative, at angles 0 ... 2 pi."""
    angles = np.linspace(0, 2 * np.pi, 65)
    for axis in np.vstack([np.eye(3), -np.eye(3)]):
        q = Quaternion.from_axis_angle(axis, angles)
        back = Quaternion.from_rotation_matrix(q.as_rotation_matrix())
        assert np.max(q.rotation_distance(back)) <= 4 * EPS


def test_agreement_with_scipy_rotation():
    """Matrices and rotated vectors agree with scipy.spatial.transform.Rotation."""
    q = random_unit(1000)
    v = rng.normal(size=(1000, 3))
    r = Rotation.from_quat(q.as_array(), scalar_first=True)
    np.testing.assert_allclose(q.as_rotation_matrix(), r.as_matrix(), rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(
        q.rotate(v), r.apply(v), rtol=0, atol=8 * EPS * np.linalg.norm(v, axis=1).max()
    )
    np.testing.assert_allclose(q.as_mrp(), r.as_mrp(), rtol=0, atol=4 * EPS)
    q2 = Quaternion.from_rotation_matrix(r.as_matrix())
    assert np.max(q.rotation_distance(q2)) <= 4 * EPS
    axis, angle = q.as_axis_angle()
    np.testing.assert_allclose(axis * angle[:, None], r.as_rotvec(), rtol=0, atol=16 * EPS)


def test_rotate_is_q_v_qinv():
    """rotate(v) is literally the Hamilton product q v q^-1 (vector part)."""
    q = Quaternion.from_array(rng.normal(size=(100, 4)))
    v = rng.normal(size=(100, 3))
    full = (q * Quaternion.from_vector(v) * q.inverse()).as_array()
    np.testing.assert_allclose(full[:, 0], 0.0, atol=16 * EPS * np.abs(v).max())
    np.testing.assert_allclose(q.rotate(v), full[:, 1:], rtol=0, atol=16 * EPS * 10)


def test_non_unit_policy():
    """Non-unit quaternions act as their versor in every rotation method."""
    q = random_unit(50)
    s = 10.0 ** rng.uniform(-200, 200, size=50)  # rescaling inside the kernels
    big = q * s
    v = rng.normal(size=(50, 3))
    np.testing.assert_allclose(big.rotate(v), q.rotate(v), rtol=0, atol=16 * EPS * 4)
    np.testing.assert_allclose(
        big.as_rotation_matrix(), q.as_rotation_matrix(), rtol=0, atol=8 * EPS
    )
    np.testing.assert_allclose(big.as_mrp(), q.as_mrp(), rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(big.as_gibbs(), q.as_gibbs(), rtol=16 * EPS)
    assert np.max(big.rotation_distance(q)) <= 4 * EPS


# ---------------------------------------------------------------- exp, log, powers, slerp
@pytest.mark.parametrize("theta", [1e-300, 1e-200, 1e-20, 1e-9, 1e-8, 1e-7, 1e-3, 1.0, 3.0])
def test_exp_log_small_angles(theta):
    """exp and log keep full relative accuracy down to angles of 1e-300."""
    axis = np.array([2.0, -3.0, 6.0]) / 7.0  # exactly representable up to rounding
    v = axis * theta
    q = Quaternion.from_vector(v).exp()
    # exp(v) = (cos|v|, sin|v| v/|v|), evaluated at 50 digits for the float vector
    # v (whose norm is not exactly theta: at theta = 3, |v| = 3 - 2.9e-16, which
    # moves sin|v| by 7 eps relative since cot 3 = -7)
    with mpmath.workdps(50):
        vm = [mpmath.mpf(float(x)) for x in v]
        tm = mpmath.sqrt(sum(x * x for x in vm))
        ref_v = np.array([float(mpmath.sin(tm) * x / tm) for x in vm])
        ref_w = float(mpmath.cos(tm))
    # 4 eps for the arithmetic, plus the rounding (<= 1 ulp) of the computed |v|
    # amplified by the relative condition number |t cot t| of sin (21 at t = 3)
    rtol = (4 + abs(theta / np.tan(theta))) * EPS
    np.testing.assert_allclose(q.vector, ref_v, rtol=rtol)
    assert abs(q.w - ref_w) <= 2 * EPS
    back = q.log()
    np.testing.assert_allclose(back.vector, v, rtol=8 * EPS)
    assert abs(back.w) <= 2 * EPS


@pytest.mark.parametrize("delta", [1e-15, 1e-12, 1e-8, 1e-4])
def test_exp_log_near_pi(delta):
    """log stays accurate near a half-turn: the recovered angle has relative error ~ulp."""
    theta = np.pi - delta  # the angle of the rotation is 2 theta; |log| = theta
    axis = np.array([0.0, 0.6, 0.8])
    q = Quaternion.from_vector(axis * theta).exp()
    back = q.log()
    np.testing.assert_allclose(np.linalg.norm(back.vector), theta, rtol=4 * EPS)
    np.testing.assert_allclose(back.vector / theta, axis, rtol=0, atol=8 * EPS)


def test_log_of_negative_real_and_power():
    """log(-1) = pi i by the documented convention; q^t via exp/log."""
    lg = Quaternion.from_array([-1.0, 0, 0, 0]).log()
    np.testing.assert_array_equal(lg.as_array(), [0.0, np.pi, 0.0, 0.0])
    q = Quaternion.from_axis_angle([0, 0, 1], 0.9)
    half = q**0.5
    np.testing.assert_allclose((half * half).as_array(), q.as_array(), rtol=0, atol=4 * EPS)
    thirds = q ** np.array([0.0, 1 / 3, 1.0])
    assert thirds.shape == (3,)
    np.testing.assert_allclose(thirds.as_axis_angle()[1], [0.0, 0.3, 0.9], rtol=4 * EPS)


def test_slerp_constant_speed_and_shortest_arc():
    q0 = Quaternion.from_axis_angle([1, 0, 0], 0.2)
    q1 = -Quaternion.from_axis_angle([0, 1, 0], 1.1)  # sign must not matter
    t = np.linspace(0, 1, 11)
    path = slerp(q0, q1, t)
    total = q0.rotation_distance(q1)
    np.testing.assert_allclose(q0.rotation_distance(path), t * total, rtol=0, atol=8 * EPS)
    assert path[-1].rotation_distance(q1) <= 4 * EPS
    assert total < np.pi  # shortest arc


def test_slerp_tiny_angle():
    """slerp between rotations 1e-200 rad apart keeps the interpolated angle exact."""
    q0 = Quaternion.from_array([1.0, 0, 0, 0])
    q1 = Quaternion.from_axis_angle([0, 0, 1], 1e-200)
    mid = slerp(q0, q1, 0.5)
    np.testing.assert_allclose(mid.as_axis_angle()[1], 0.5e-200, rtol=4 * EPS)


# ---------------------------------------------------------------- container protocol
def test_indexing_len_shape_equality():
    q = Quaternion.from_array(np.arange(24.0).reshape(2, 3, 4))
    assert q.shape == (2, 3) and q.ndim == 2 and len(q) == 2
    assert q[1].shape == (3,)
    assert q[1, 2].shape == ()
    np.testing.assert_array_equal(q[..., 0].as_array(), q.as_array()[:, 0])
    np.testing.assert_array_equal(q[1, 2].as_array(), [20.0, 21.0, 22.0, 23.0])
    with pytest.raises(IndexError, match="too many indices"):
        q[0, 0, 0]
    with pytest.raises(TypeError):
        len(q[0, 0])
    assert bool(np.all(q == Quaternion(q.as_array().copy())))
    assert not q.allclose(-q)
    p = random_unit(4)
    assert p.rotation_allclose(-p)
    assert [x.shape for x in p] == [()] * 4


def test_a_new_axis_indexes_as_numpy_and_unbroadcastable_comparisons_name_the_operands():
    """``None`` adds an axis and takes none (numpy's ``a[:, None]``), so the outer
    product ``q[:, None] * p[None, :]`` works; ``==`` and ``!=`` of shapes that do not
    broadcast raise the ValueError naming the operands that ``*`` raises."""
    q, p = random_unit(5), random_unit(3)
    a = q.as_array()
    for got, want in ((q[:, None], a[:, None]), (q[None], a[None]),
                      (q[..., None], a[..., None, :]), (q[None, 2], a[None, 2])):
        np.testing.assert_array_equal(got.as_array(), want)
    outer = q[:, None] * p[None, :]
    assert outer.shape == (5, 3)
    np.testing.assert_array_equal(outer[4, 2].as_array(), (q[4] * p[2]).as_array())
    with pytest.raises(IndexError, match="too many indices"):
        q[0, None, 0]
    for op in ("__eq__", "__ne__", "__mul__"):
        with pytest.raises(ValueError, match=r"`self`, `other` to broadcast together, got "
                                             r"shapes \(5,\), \(3,\)"):
            getattr(q, op)(p)


# ---------------------------------------------------------------- bad input and hard cases
def test_zero_quaternion_raises():
    z = Quaternion.from_array([[1.0, 0, 0, 0], [0.0, 0, 0, 0]])
    with pytest.raises(ValueError, match="nonzero quaternion at index 1"):
        z.inverse()
    with pytest.raises(ValueError, match="nonzero"):
        z.unit()
    with pytest.raises(ValueError, match="nonzero"):
        z.rotate([1.0, 0, 0])
    with pytest.raises(ValueError, match="nonzero quaternion at index 1"):
        z.rotate(np.ones((2, 3)))  # the one-vector-per-quaternion fast path
    with pytest.raises(ValueError, match=r"`vectors` to be finite, got nan at index \(1, 2\)"):
        Quaternion.from_array(np.ones((2, 4))).rotate([[0, 0, 0], [0, 0, np.nan]])
    with pytest.raises(ValueError, match="nonzero"):
        z.as_rotation_matrix()
    with pytest.raises(ValueError, match="nonzero"):
        z.log()


def test_nan_and_inf_raise_with_index():
    a = np.ones((3, 4))
    a[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"`array` to be finite, got nan at index \(2, 1\)"):
        Quaternion(a)
    with pytest.raises(ValueError, match="`vector` to be finite, got inf at index 0"):
        Quaternion.from_vector([np.inf, 0, 0])
    with pytest.raises(ValueError, match="`angle` to be finite"):
        Quaternion.from_axis_angle([1, 0, 0], np.nan)


def test_wrong_shape_raises():
    expected = r"Expected `array` to have shape \(\.\.\., 4\), got \(3,\)"
    with pytest.raises(ValueError, match=expected):
        Quaternion([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"`vectors` to have shape \(\.\.\., 3\), got \(2, 4\)"):
        Quaternion.from_array([1.0, 0, 0, 0]).rotate(np.zeros((2, 4)))
    with pytest.raises(ValueError, match=r"`matrix` to have shape \(\.\.\., 3, 3\)"):
        Quaternion.from_rotation_matrix(np.eye(4))
    with pytest.raises(ValueError, match="rotation matrix"):
        Quaternion.from_rotation_matrix(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ValueError, match=r"Expected `axis` to be a nonzero vector at index 1: "
                                         r"a rotation axis must have nonzero length"):
        Quaternion.from_axis_angle([[0, 0, 1], [0, 0, 0]], 1.0)  # (a vector, not a quaternion)


def test_gibbs_near_half_turn_policy():
    """Finite Gibbs vectors are returned (full relative accuracy); a half-turn raises."""
    delta = 1e-12
    # a rotation by pi - delta about z, built from exact components (cos(angle/2)
    # computed from the angle would itself carry a relative error eps / delta)
    q = Quaternion.from_array([np.sin(delta / 2), 0, 0, np.cos(delta / 2)])
    g = q.as_gibbs()
    # tan((pi - delta)/2) = cot(delta/2)
    np.testing.assert_allclose(g[2], np.cos(delta / 2) / np.sin(delta / 2), rtol=EPS)
    half = Quaternion.from_array([[1.0, 0, 0, 0], [0.0, 0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=r"infinite at index 1.*as_mrp"):
        half.as_gibbs()
    np.testing.assert_array_equal(half[1].as_mrp(), [0.0, 0.0, 1.0])


def test_axis_angle_identity_convention():
    axis, angle = Quaternion.from_array([1.0, 0, 0, 0]).as_axis_angle()
    np.testing.assert_array_equal(axis, [1.0, 0.0, 0.0])
    assert angle == 0.0


@pytest.mark.parametrize(("method", "kw", "pattern"), [
    ("allclose", {"rtol": float("nan")}, r"`rtol` to be finite, got nan"),
    ("allclose", {"atol": "a"}, r"`atol` to be numeric, got 'a'"),
    ("allclose", {"atol": [1e-9, 1e-9]}, r"`atol` to be one number, got shape \(2,\)"),
    ("rotation_allclose", {"atol": -1}, r"`atol` >= 0, got -1.0"),
])
def test_closeness_refuses_a_tolerance_that_is_none(method, kw, pattern):
    """A NaN rtol gave numpy's RuntimeWarning, a text atol a bare TypeError, and a
    negative atol called the identical rotation not close (False)."""
    q = Quaternion.from_axis_angle([0.0, 0.0, 1.0], 0.3)
    with pytest.raises(ValueError, match=pattern):
        getattr(q, method)(q, **kw)
    assert getattr(q, method)(q) and getattr(q, method)(q, atol=0.0)


def test_a_quaternion_keeps_its_components_when_the_callers_buffer_changes():
    """``Quaternion(array)`` kept the caller's array and the accessors gave
    writable views: three quaternions built from one reused buffer all had the
    last one's components, and a buffer refilled with NaN after the check gave
    NaN rotation matrices.  The components are copied where shared and
    read-only."""
    buf = np.empty(4)
    made = []
    for angle in (0.1, 0.2, 0.3):
        buf[:] = [np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)]
        made.append(Quaternion(buf))
    np.testing.assert_allclose([q.as_axis_angle()[1] for q in made], [0.1, 0.2, 0.3],
                               rtol=1e-15)
    buf[1] = np.nan
    assert np.isfinite(made[-1].as_rotation_matrix()).all()
    for view in (made[0].as_array(), made[0].w, made[0].vector):
        with pytest.raises(ValueError, match="read-only"):
            view[...] = 5.0
    product = made[0] * made[1]  # (results too)
    with pytest.raises(ValueError, match="read-only"):
        product.as_array()[0] = np.inf


def test_not_equal_is_componentwise_for_a_batch_and_truth_is_refused():
    """``a != b`` of a batch raised "the truth value of an array is ambiguous"
    (Python's fallback ``not (a == b)``), and ``bool(q)`` said "len() of a single
    (0-d) Quaternion"."""
    a = Quaternion(np.eye(4))
    b = Quaternion(np.eye(4)[[0, 2, 1, 3]])
    assert (a != b).tolist() == [False, True, True, False]
    assert (a == b).tolist() == [True, False, False, True]
    with pytest.raises(TypeError, match="truth value of a Quaternion is ambiguous"):
        bool(Quaternion([1.0, 0, 0, 0]))


@pytest.mark.parametrize("t", [1e6, 1e10, 1e16, 1e20, -1e20])
def test_slerp_with_a_large_parameter_stays_a_unit_rotation(t):
    """q0 (q0^-1 q1)^t of unit quaternions is one: the ulp of |q0^-1 q1| in its
    log, times t, shrank it to 0.33 at t = 1e16 and 0 at 1e20 (no rotation)."""
    q0, q1 = Quaternion([1.0, 2.0, 3.0, 4.0]), Quaternion([0.0, 1.0, 0.0, 0.0])
    s = slerp(q0, q1, t)
    assert abs(float(s.norm()) - 1.0) <= 4 * EPS
    # the turn about the same axis by t times the angle, modulo two turns, where
    # that phase means anything (t angle's own rounding below a tenth of a radian)
    p = q0 * (1.0 / float(q0.norm()))
    axis, angle = (p.conj() * q1).canonical().as_axis_angle()
    if abs(t) * angle * EPS < 0.1:
        want = (p * Quaternion.from_axis_angle(axis, np.fmod(t * angle, 4 * np.pi)))
        np.testing.assert_allclose(s.canonical().as_array(), want.canonical().as_array(),
                                   rtol=0, atol=abs(t) * angle * 8 * EPS)


def test_division_is_exact_in_scale():
    """"Every operation is exact in scale" (docs/quaternion.md): 1.7e308 / 1e300
    raised "the quotient overflows" while p * q.inverse() gave 1.7e8; a real over a
    tiny quaternion (1e-10 / 1e-310, 0 / 1e-310) raised where the quotient is 1e300
    and 0."""
    p, q = Quaternion([1.7e308] * 4), Quaternion([1e300] * 4)
    np.testing.assert_allclose((p / q).as_array(), (p * q.inverse()).as_array(), rtol=4 * EPS)
    np.testing.assert_allclose((p / q).as_array(), [1.7e8, 0, 0, 0], rtol=4 * EPS, atol=1e-7)
    tiny = Quaternion([2.0**-1000, 0.0, 0.0, 0.0])
    assert (1e-10 / tiny).as_array().tolist() == [1e-10 * 2.0**1000, -0.0, -0.0, -0.0]
    assert (0.0 / tiny).as_array().tolist() == [0.0, -0.0, -0.0, -0.0]
    with pytest.raises(ValueError, match="quotient"):
        Quaternion([1e300, 0, 0, 0]) / Quaternion([1e-300, 0, 0, 0])  # (1e600: refused)


def test_the_rotation_kernel_gives_nan_for_the_zero_quaternion():
    """``quaternion_kernels.qrot`` of the zero quaternion: NaN, which the caller
    checks (its docstring); it raised ZeroDivisionError, from Python and from a
    user's compiled kernel alike."""
    from numba import njit

    from hamilton_orbits.quaternion_kernels import qrot

    @njit
    def caller(w):
        return qrot(w, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)[0]

    assert all(np.isnan(qrot(0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0)))
    assert np.isnan(caller(0.0))
    assert caller(1.0) == 1.0


def test_hamiltons_products_name_shapes_and_survive_a_large_dot_product():
    """A shape mismatch was reported as "Hamilton's  fits in float64" (an overflow,
    its name empty); r, v of 1e160 with r x v = 1e60 raised, the scalar part
    -r.v of alpha alpha' (which beta does not keep) overflowing."""
    from hamilton_orbits.orbit import hamilton_beta, hamilton_p

    with pytest.raises(ValueError, match=r"Expected `r`, `v` to broadcast together, got "
                                         r"shapes \(2,\), \(3,\)"):
        hamilton_beta(np.ones((2, 3)), np.ones((3, 3)))
    r, v = np.array([1e160, 0.0, 0.0]), np.array([1e160, 1e-100, 0.0])
    assert hamilton_beta(r, v).tolist() == np.cross(r, v).tolist()
    np.testing.assert_allclose(hamilton_p(r, v, 1.0), 1e120, rtol=4 * EPS)
    with pytest.raises(ValueError, match=r"Hamilton's beta fits in float64"):
        hamilton_beta([1e200, 0.0, 0.0], [0.0, 1e200, 0.0])  # (r x v = 1e400 itself)


def test_a_quaternion_of_a_buffer_that_is_no_ndarray_keeps_its_components():
    """The copy was made for an ndarray only: an array.array or a memoryview
    written into after the check changed the quaternion."""
    import array

    for buffer in (array.array("d", [1.0, 0.0, 0.0, 0.0]),):
        q = Quaternion(buffer)
        view = memoryview(buffer)
        r = Quaternion(view)
        buffer[1] = np.nan
        assert q.as_array().tolist() == [1.0, 0.0, 0.0, 0.0]
        assert r.as_array().tolist() == [1.0, 0.0, 0.0, 0.0]


def test_degrees_is_true_or_false():
    # any truthy value read the angle as degrees ("False" and 0.5 included)
    for bad in ("False", 0.5, None):
        with pytest.raises(ValueError, match=f"`degrees` to be True or False, got {bad!r}"):
            Quaternion.from_axis_angle([0, 0, 1], 90.0, degrees=bad)
    for flag, turn in ((np.True_, 90.0), (False, np.pi / 2)):
        q = Quaternion.from_axis_angle([0, 0, 1], turn, degrees=flag)
        # (a quarter turn of a unit vector: rounding of a few ulp of 1 in each part)
        np.testing.assert_allclose(q.rotate([1.0, 0, 0]), [0.0, 1.0, 0.0], rtol=0,
                                   atol=4 * np.finfo(float).eps)
