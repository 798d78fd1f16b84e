"""The Quaternion API's input contract (issue 7): units, extreme magnitudes, bad operands.

Every reproducer quoted in issue 7 for the quaternion core is a test here, with
its exact answer; a property test then walks the public API with finite input
of any magnitude in [1e-300, 1e300] and asserts the contract: no warning, no
NaN or inf out, or a ValueError / UnitConversionError naming the argument.

References
----------
Hamilton, W. R. (1845), seed: q v q^-1 rotates v (the rotation by theta about a
unit axis is q = cos(theta/2) + sin(theta/2) axis).
Schaub, H. & Junkins, J. L., *Analytical Mechanics of Space Systems*, 4th ed.,
section 3.5: modified Rodrigues parameters, q = (1 - s^2, 2 s) / (1 + s^2).
"""

from __future__ import annotations

import re
import warnings

import astropy.units as u
import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from hamilton_orbits import Quaternion, slerp

EPS = np.finfo(float).eps


# ---------------------------------------------------------------- item 1: units
@pytest.mark.parametrize(
    "angle",
    [
        90 * u.deg,
        0.25 * u.cycle,
        6 * u.hourangle,
        5400 * u.arcmin,
        324000 * u.arcsec,
        np.pi / 2 * u.rad,
    ],
)
def test_axis_angle_reads_any_angular_unit(angle):
    """A quarter turn about z in any angular unit takes x to y (Hamilton's q v q^-1)."""
    q = Quaternion.from_axis_angle([0, 0, 1], angle)
    # 90 deg -> pi/2 rad is one rounding; cos(pi/4) and sin(pi/4) are then exact to 1 ulp
    np.testing.assert_allclose(q.as_array(), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)], atol=2 * EPS)
    np.testing.assert_allclose(q.rotate([1.0, 0, 0]), [0, 1.0, 0], atol=4 * EPS)
    # and it is the rotation of the documented plain-float forms
    assert q.rotation_distance(Quaternion.from_axis_angle([0, 0, 1], 90.0, degrees=True)) <= (
        4 * EPS
    )


QUARTER = Quaternion.from_axis_angle([0, 0, 1], np.pi / 2)

# (call, the argument it must name): each gets a Quantity of the wrong dimension
WRONG_UNITS = [
    (lambda: Quaternion.from_axis_angle([0, 0, 1], 1 * u.m), "angle"),
    (lambda: Quaternion.from_axis_angle([0, 0, 1], 1 * u.s), "angle"),
    (lambda: Quaternion.from_axis_angle([0, 0, 1] * u.m, 1.0), "axis"),
    (lambda: Quaternion.from_array([1, 0, 0, 0] * u.m), "array"),
    (lambda: Quaternion.from_array([1, 0, 0, 0] * u.deg), "array"),
    (lambda: Quaternion([1, 0, 0, 0] * u.kg), "array"),
    (lambda: Quaternion.from_vector([1, 2, 3] * u.km), "vector"),
    (lambda: Quaternion.from_gibbs([1, 2, 3] * u.deg), "gibbs"),
    (lambda: Quaternion.from_mrp([0.1, 0.2, 0.3] * u.rad), "mrp"),
    (lambda: Quaternion.from_rotation_matrix(np.eye(3) * u.m), "matrix"),
    (lambda: QUARTER ** (0.5 * u.deg), "t"),
    (lambda: QUARTER ** (0.5 * u.s), "t"),
    (lambda: slerp(QUARTER, QUARTER, 0.5 * u.rad), "t"),
    (lambda: QUARTER * (2 * u.m), "other"),
    (lambda: (2 * u.m) * QUARTER, "other"),
    (lambda: QUARTER / (2 * u.s), "other"),
    (lambda: QUARTER + 1 * u.m, "other"),
    (lambda: QUARTER - 1 * u.deg, "other"),
]


@pytest.mark.parametrize(("call", "name"), WRONG_UNITS)
def test_wrong_dimension_names_the_argument(call, name):
    """Dimensionless arguments refuse units and angles; angles refuse other dimensions."""
    with pytest.raises(u.UnitConversionError, match=f"`{name}`"):
        call()


def test_dimensionless_quantities_are_accepted():
    q = Quaternion.from_array([1.0, 0, 0, 0] * u.one)
    np.testing.assert_array_equal(q.as_array(), [1.0, 0, 0, 0])
    half = QUARTER ** (0.5 * u.dimensionless_unscaled)
    assert abs(half.as_axis_angle()[1] - np.pi / 4) <= 2 * EPS


def test_degrees_flag_with_a_quantity_is_refused():
    with pytest.raises(ValueError, match=r"`angle`.*degrees=True"):
        Quaternion.from_axis_angle([0, 0, 1], 90 * u.deg, degrees=True)


def test_rotate_keeps_the_unit_of_quantity_vectors():
    r = QUARTER.rotate([[1.0, 0, 0], [0, 2.0, 0]] * u.km)
    assert r.unit == u.km
    np.testing.assert_allclose(r.value, [[0, 1.0, 0], [-2.0, 0, 0]], atol=8 * EPS)
    broadcast = QUARTER.rotate([[1.0, 0, 0], [0, 2.0, 0]] * u.km)  # one q, two vectors
    assert broadcast.unit == u.km


# ---------------------------------------------------------------- item 4: magnitudes
def test_rotate_huge_quaternion_and_vector():
    """Issue 7: Quaternion([1e120, 1e120, 0, 0]).rotate([1e80, 0, 1e80]) returned -inf.

    q ~ (1, 1, 0, 0) is a quarter turn about x: (x, y, z) -> (x, -z, y).
    """
    r = Quaternion([1e120, 1e120, 0, 0]).rotate([1e80, 0, 1e80])
    # a few roundings of size eps |v| (|v| = 1.4e80)
    np.testing.assert_allclose(r, [1e80, -1e80, 0.0], rtol=0, atol=8 * EPS * 1.5e80)


def test_rotate_tiny_quaternion_and_vector():
    """Issue 7: Quaternion([0, 1e-131, 0, 0]).rotate([0, 1e-81, 0]) came back unrotated.

    q ~ i is a half-turn about x: (0, 1, 0) -> (0, -1, 0).
    """
    r = Quaternion([0, 1e-131, 0, 0]).rotate([0, 1e-81, 0])
    # the scalings by 2^k are exact; v + 2 (u x (u x v)) rounds a couple of times
    np.testing.assert_allclose(r, [0.0, -1e-81, 0.0], rtol=0, atol=4 * EPS * 1e-81)
    r2 = Quaternion([[0, 1e-131, 0, 0]]).rotate([[0, 1e-81, 0], [0, 0, 3e-300]])  # gufunc path
    np.testing.assert_allclose(r2[0], [0.0, -1e-81, 0.0], rtol=0, atol=4 * EPS * 1e-81)
    np.testing.assert_allclose(r2[1], [0.0, 0.0, -3e-300], rtol=0, atol=4 * EPS * 3e-300)


@pytest.mark.parametrize("kq", [-1070, -600, -340, -200, 0, 200, 340, 600, 1000])
@pytest.mark.parametrize("kv", [-1040, -500, -280, 0, 280, 500, 1000])
def test_rotation_is_scale_free(kq, kv):
    """rotate(2^kq q, 2^kv v) = 2^kv rotate(q, v): the scale of q cancels and rotation is linear.

    At kq = -1070 or kv = -1040 the scaled inputs are subnormal and have lost
    bits; the reference is then the rotation of the stored inputs scaled back
    (scaling up by 2^k is exact).  Tolerance: the rotation is accurate to a few
    eps |v| (16 eps, as in test_quaternion.test_non_unit_policy), plus the
    rounding of a subnormal result.
    """
    rng = np.random.default_rng(10_000 + kq + 3 * kv)
    q = np.ldexp(rng.normal(size=(20, 4)), kq)
    v = np.ldexp(rng.normal(size=(20, 3)), kv)
    ref = Quaternion(np.ldexp(q, -kq)).rotate(np.ldexp(v, -kv))
    back = np.ldexp(Quaternion(q).rotate(v), -kv)
    scale = np.linalg.norm(np.ldexp(v, -kv), axis=-1, keepdims=True)
    # a rotated vector of size 2^-1040 is itself subnormal: its rounding to a
    # multiple of 2^-1074 is an absolute error, 2^(-1074 - kv) after scaling back
    output_underflow = 2 * np.ldexp(1.0, -1074 - kv)
    assert np.all(np.abs(back - ref) <= 16 * EPS * scale + output_underflow)


def test_from_mrp_huge():
    """Issue 7: from_mrp([1e200, 0, 0]) gave NaN.  q = (1 - s^2, 2 s)/(1 + s^2) (Schaub 3.5)."""
    q = Quaternion.from_mrp([1e200, 0, 0]).as_array()
    # w = -1 + 2/(1 + s^2) rounds to -1; x = 2 s / (1 + s^2) = 2e-200 to one rounding
    assert q[0] == -1.0
    assert abs(q[1] - 2e-200) <= 2 * EPS * 2e-200
    np.testing.assert_array_equal(q[2:], 0.0)
    # just above |s| = 1 the two forms of the formula meet continuously
    below = Quaternion.from_mrp([1.0, 0, 0]).as_array()
    above = Quaternion.from_mrp([np.nextafter(1.0, 2.0), 0, 0]).as_array()
    assert np.max(np.abs(below - above)) <= 4 * EPS


def test_from_axis_angle_subnormal_axis():
    """Issue 7: from_axis_angle([1e-320, 0, 0], 1.0) gave NaN; the axis length is irrelevant."""
    q = Quaternion.from_axis_angle([1e-320, 0, 0], 1.0).as_array()
    np.testing.assert_array_equal(q, [np.cos(0.5), np.sin(0.5), 0.0, 0.0])
    # exact: the axis is scaled by a power of two and sqrt(c^2) = c, so the unit axis is 1
    q = Quaternion.from_axis_angle([1e300, 1e300, 0], 1.0).as_array()
    ref = Quaternion.from_axis_angle([1.0, 1.0, 0], 1.0).as_array()
    np.testing.assert_allclose(q, ref, rtol=2 * EPS)  # unit axes agree to rounding


def test_exp_overflow_raises_and_split_exponential():
    """Issue 7: Quaternion([1e3, 0, 0, 0]).exp() gave NaN parts; e^1000 is not a float."""
    with pytest.raises(ValueError, match=r"`self`.*1000.*overflows"):
        Quaternion([1e3, 0, 0, 0]).exp()
    with pytest.raises(ValueError, match=r"`self` .* at index 1"):
        Quaternion([[0.0, 1, 0, 0], [1e3, 0, 0, 0]]).exp()
    # e^710 overflows alone, but e^710 cos(pi/4) = 1.58e308 is a float: computed
    q = Quaternion([710.0, np.pi / 4, 0, 0]).exp().as_array()
    with mpmath.workdps(40):
        ref = float(mpmath.exp(710) * mpmath.cos(mpmath.mpf(np.pi / 4)))
        ref_x = float(mpmath.exp(710) * mpmath.sin(mpmath.mpf(np.pi / 4)))
    # exp(w/2)^2 instead of exp(w): two more roundings (documented in _exp)
    assert abs(q[0] - ref) <= 4 * EPS * ref
    assert abs(q[1] - ref_x) <= 4 * EPS * ref_x


def test_log_and_norm_of_huge_quaternions():
    """log|q| of |q| = 2e308 is a float although |q| is not; norm() refuses to return inf."""
    q = Quaternion([1e308, 1e308, 1e308, 1e308])
    with mpmath.workdps(40):
        ref = float(mpmath.log(2 * mpmath.mpf(1e308)))
    lg = q.log().as_array()
    assert abs(lg[0] - ref) <= 2 * EPS * ref
    # V log q = atan2(|v|, w) v/|v| = (pi/3) (1, 1, 1)/sqrt 3
    np.testing.assert_allclose(lg[1:], np.pi / 3 / np.sqrt(3), rtol=4 * EPS)
    with pytest.raises(ValueError, match=r"`self` to keep the norm finite"):
        q.norm()
    np.testing.assert_allclose(q.unit().as_array(), 0.5, rtol=EPS)


def test_inverse_extremes():
    """q^-1 = K q/|q|^2, exact for powers of two down to 2^-1022; 1e-310 has none."""
    inv = Quaternion([2.0**-1022, 0, 0, 0]).inverse().as_array()
    np.testing.assert_array_equal(inv, [2.0**1022, 0, 0, 0])
    inv = Quaternion([0, 0, 2.0**1000, 0]).inverse().as_array()
    np.testing.assert_array_equal(inv, [0, 0, -(2.0**-1000), 0])
    with pytest.raises(ValueError, match=r"`self` to keep the inverse finite"):
        Quaternion([1e-310, 0, 0, 0]).inverse()


def test_products_and_quotients_near_the_float_limits():
    big, small = Quaternion([1e200, 0, 0, 0]), Quaternion([0, 1e-200, 0, 0])
    np.testing.assert_allclose((big * small).as_array(), [0, 1.0, 0, 0], rtol=2 * EPS)
    with pytest.raises(ValueError, match=r"`other` to keep the product finite"):
        big * big
    with pytest.raises(ValueError, match=r"`other` to keep the quotient finite"):
        big / small
    # a product whose terms overflow although the result does not: the scaled retry
    a = Quaternion([1e308, -1e308, 0, 0])
    b = Quaternion([1.5, 1.0, 0, 0])
    # w = 1.5e308 + 1e308 overflows; x = 1e308 - 1.5e308 does not
    with pytest.raises(ValueError, match="product"):
        a * b
    c = Quaternion([1.5e308, 1e308, 0, 0]) * Quaternion([0.5, -0.5, 0, 0])
    np.testing.assert_allclose(c.as_array(), [1.25e308, -0.25e308, 0, 0], rtol=2 * EPS)
    # division by a tiny quaternion is exact in scale
    d = Quaternion([1.0, 0, 0, 0]) / Quaternion([0, 2.0**-1000, 0, 0])
    np.testing.assert_array_equal(d.as_array(), [0, -(2.0**1000), 0, 0])


# ---------------------------------------------------------------- items 6 and 7
@pytest.mark.parametrize("bad", [None, "abc", [1j], object()])
def test_bad_operands_name_other(bad):
    """Issue 7: Quaternion * None gave NaN."""
    for op in (
        lambda: QUARTER * bad,
        lambda: bad * QUARTER,
        lambda: QUARTER / bad,
        lambda: QUARTER + bad,
        lambda: QUARTER - bad,
    ):
        with pytest.raises(ValueError, match="`other`"):
            op()
    with pytest.raises(ValueError, match="`other`"):
        QUARTER.rotation_distance(bad)
    with pytest.raises(ValueError, match="`q1`"):
        slerp(QUARTER, bad, 0.5)


def test_complex_input_refused():
    with pytest.raises(ValueError, match="`array` to be real"):
        Quaternion([1j, 0, 0, 0])
    with pytest.raises(ValueError, match="`vectors` to be real"):
        QUARTER.rotate(np.array([1j, 0, 0]))
    with pytest.raises(ValueError, match="`angle` to be real"):
        Quaternion.from_axis_angle([0, 0, 1], 1j)
    with pytest.raises(ValueError, match="`t` to be real"):
        QUARTER ** (0.5 + 0j)


SHAPES = [
    (lambda: Quaternion.from_axis_angle(np.ones((2, 3)), np.ones(3)), r"`axis`, `angle`"),
    (lambda: Quaternion(np.ones((2, 4))).rotate(np.ones((3, 3))), r"`self`, `vectors`"),
    (
        lambda: slerp(Quaternion(np.ones((2, 4))), Quaternion(np.ones((3, 4))), 0.5),
        r"`q0`, `q1`, `t`",
    ),
    (lambda: slerp(Quaternion(np.ones((2, 4))), QUARTER, np.ones(3)), r"`q0`, `q1`, `t`"),
    (lambda: Quaternion(np.ones((2, 4))) * Quaternion(np.ones((3, 4))), r"`self`, `other`"),
    (lambda: Quaternion(np.ones((2, 4))) / Quaternion(np.ones((3, 4))), r"`self`, `other`"),
    (lambda: Quaternion(np.ones((2, 4))) + Quaternion(np.ones((3, 4))), r"`self`, `other`"),
    (lambda: Quaternion(np.ones((2, 4))) * np.ones(3), r"`self`, `other`"),
    (lambda: Quaternion(np.ones((2, 4))) ** np.ones(3), r"`self`, `t`"),
    (
        lambda: Quaternion(np.ones((2, 4))).rotation_distance(Quaternion(np.ones((3, 4)))),
        r"`self`, `other`",
    ),
]


@pytest.mark.parametrize(("call", "names"), SHAPES)
def test_shape_mismatch_names_arguments_and_shapes(call, names):
    with pytest.raises(ValueError, match=names + r" to broadcast together, got shapes \(") as e:
        call()
    assert "operands could not be broadcast" not in str(e.value)


# ---------------------------------------------------------------- item 14: repr
def test_repr_single_and_batch():
    q = Quaternion([0.5, -0.5, 0.5, 0.5])
    assert repr(q) == "Quaternion([0.5, -0.5, 0.5, 0.5])"
    assert eval(repr(q), {"Quaternion": Quaternion}) == q  # round-trip exact
    batch = Quaternion(np.arange(24.0).reshape(2, 3, 4))
    assert repr(batch) == (
        "Quaternion(shape=(2, 3), w in [0, 20], x in [1, 21], y in [2, 22], z in [3, 23])"
    )
    assert repr(Quaternion(np.zeros((0, 4)))) == "Quaternion(shape=(0,))"


# ---------------------------------------------------------------- the contract, as a property
def _magnitudes():
    """0 or +-10^x with x uniform in [-300, 300]: every scale of finite input."""
    scaled = st.tuples(st.sampled_from([-1.0, 1.0]), st.floats(-300, 300)).map(
        lambda se: se[0] * 10.0 ** se[1]
    )
    return st.one_of(st.just(0.0), scaled)


Q4 = arrays(np.float64, (4,), elements=_magnitudes())
V3 = arrays(np.float64, (3,), elements=_magnitudes())
SCALAR = _magnitudes()


def _check(name_set: set[str], call) -> None:
    """The contract: a finite result, or a ValueError/UnitConversionError naming an argument."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            out = call()
        except (ValueError, u.UnitConversionError) as exc:
            named = set(re.findall(r"`(\w+)`", str(exc)))
            assert named & name_set, (str(exc), name_set)
            return
    parts = out if isinstance(out, tuple) else (out,)
    for part in parts:
        a = part.as_array() if isinstance(part, Quaternion) else np.asarray(part)
        assert np.all(np.isfinite(a)), (call, a)


@settings(deadline=None, max_examples=150)
@given(Q4, Q4, V3, SCALAR)
def test_contract_over_the_public_api(a, b, v, s):
    """No warning, no NaN/inf out of finite input of any magnitude; else a named ValueError."""
    q, p = Quaternion(a), Quaternion(b)
    me, both = {"self"}, {"self", "other"}
    _check({"vector"}, lambda: Quaternion.from_vector(v))
    _check({"axis", "angle"}, lambda: Quaternion.from_axis_angle(v, s))
    _check({"gibbs"}, lambda: Quaternion.from_gibbs(v))
    _check({"mrp"}, lambda: Quaternion.from_mrp(v))
    for method in ("norm", "unit", "inverse", "conj", "log", "exp", "canonical"):
        _check(me, getattr(q, method))
    for method in ("as_rotation_matrix", "as_axis_angle", "as_gibbs", "as_mrp"):
        _check(me, getattr(q, method))
    _check({"self", "vectors"}, lambda: q.rotate(v))
    _check({"self", "t"}, lambda: q**s)
    for op in ("__mul__", "__truediv__", "__add__", "__sub__"):
        _check(both, lambda op=op: getattr(q, op)(p))
        _check(both, lambda op=op: getattr(q, op)(s))
    _check(both, lambda: s / q)
    _check(both, lambda: q.rotation_distance(p))
    _check({"q0", "q1", "t"}, lambda: slerp(q, p, s))
    try:
        matrix = q.as_rotation_matrix()
    except ValueError:
        return
    _check({"matrix"}, lambda: Quaternion.from_rotation_matrix(matrix))
