"""Tests for rigid.body.RigidBody."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Quaternion
from rigid.body import RigidBody

EPS = np.finfo(float).eps


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return Quaternion(q / np.linalg.norm(q)).as_rotation_matrix()


def test_principal_moments_plain_and_quantity():
    body = RigidBody([1.0, 2.0, 2.5], omega=[0.3, -0.2, 0.1])
    assert body.moments.tolist() == [1.0, 2.0, 2.5]
    assert body.omega.tolist() == [0.3, -0.2, 0.1]
    assert np.array_equal(body.attitude.as_array(), [1.0, 0.0, 0.0, 0.0])
    qb = RigidBody(
        [1.0, 2.0, 2.5] * u.g * u.cm**2, omega=[0.3, -0.2, 0.1] * u.deg / u.s
    )
    # 1 g cm^2 = 1e-7 kg m^2 exactly; deg -> rad by pi/180.
    # Quantities in, Quantities out (issue 9, item 6): the state in SI units.
    assert qb.moments.unit == u.kg * u.m**2 and qb.omega.unit == u.rad / u.s
    np.testing.assert_allclose(qb.moments.value, [1e-7, 2e-7, 2.5e-7], rtol=2 * EPS)
    np.testing.assert_allclose(qb.omega.value, np.deg2rad([0.3, -0.2, 0.1]), rtol=2 * EPS)
    assert not isinstance(body.moments, u.Quantity) and not isinstance(body.omega, u.Quantity)


def test_derived_quantities_by_hand():
    # A = 1, B = 2, C = 3, omega = (1, 1, 1): L_body = (1, 2, 3), T = (1 + 2 + 3)/2 = 3.
    body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 1.0, 1.0])
    assert body.angular_momentum_body.tolist() == [1.0, 2.0, 3.0]
    assert body.kinetic_energy == 3.0
    assert body.angular_momentum_norm == np.sqrt(14.0)
    # A quarter turn about z maps body x to space y: L_space = (-2, 1, 3).
    q = Quaternion.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)
    turned = body.with_state(attitude=q)
    np.testing.assert_allclose(turned.angular_momentum_space, [-2.0, 1.0, 3.0], atol=4 * EPS)
    np.testing.assert_allclose(
        turned.invariable_plane, np.array([-2.0, 1.0, 3.0]) / np.sqrt(14.0), atol=4 * EPS
    )


def test_cayley_g_matches_cayley_formula():
    # Cayley (1843), the free-body integrals:
    # kappa g   = A p (1 + l^2 - m^2 - n^2) + 2 B q (l m - n) + 2 C r (n l + m)
    # kappa g'  = 2 A p (l m + n) + B q (1 + m^2 - l^2 - n^2) + 2 C r (m n - l)
    # kappa g'' = 2 A p (n l - m) + 2 B q (m n + l) + C r (1 + n^2 - l^2 - m^2)
    rng = np.random.default_rng(4)
    for _ in range(20):
        moments = np.sort(rng.uniform(1.0, 2.0, 3))
        omega = rng.normal(size=3)
        qa = rng.normal(size=4)
        body = RigidBody(moments, qa, omega)
        lam, mu, nu = body.attitude.as_gibbs()
        kappa = 1 + lam**2 + mu**2 + nu**2
        (a, b, c), (p, q, r) = moments, omega
        g = (a * p * (1 + lam**2 - mu**2 - nu**2) + 2 * b * q * (lam * mu - nu)
             + 2 * c * r * (nu * lam + mu)) / kappa
        g1 = (2 * a * p * (lam * mu + nu) + b * q * (1 + mu**2 - lam**2 - nu**2)
              + 2 * c * r * (mu * nu - lam)) / kappa
        g2 = (2 * a * p * (nu * lam - mu) + 2 * b * q * (mu * nu + lam)
              + c * r * (1 + nu**2 - lam**2 - mu**2)) / kappa
        # Cayley's rational form divides by kappa, which grows as the rotation
        # nears a half-turn; 64 ulp of |L| covers that conditioning.
        scale = np.linalg.norm(moments * omega)
        np.testing.assert_allclose(body.cayley_g, [g, g1, g2], rtol=0, atol=64 * EPS * scale)
        # g^2 + g'^2 + g''^2 = A^2 p^2 + B^2 q^2 + C^2 r^2 (Cayley 1843).
        np.testing.assert_allclose(np.sum(body.cayley_g**2), scale**2, rtol=8 * EPS)


def test_full_tensor_is_diagonalised_consistently():
    rng = np.random.default_rng(1)
    for _ in range(10):
        moments = np.sort(rng.uniform(1.0, 2.0, 3))
        rot = _random_rotation(rng)  # columns: principal axes in the given frame
        tensor = rot @ np.diag(moments) @ rot.T
        tensor = 0.5 * (tensor + tensor.T)
        omega_given = rng.normal(size=3)
        q_given = Quaternion(rng.normal(size=4)).unit()
        body = RigidBody(tensor, q_given, omega_given)
        np.testing.assert_allclose(body.moments, moments, rtol=16 * EPS)
        # Physical invariants do not depend on the frame.
        np.testing.assert_allclose(
            body.kinetic_energy, 0.5 * omega_given @ tensor @ omega_given, rtol=32 * EPS
        )
        l_space = q_given.rotate(tensor @ omega_given)
        np.testing.assert_allclose(body.angular_momentum_space, l_space, atol=64 * EPS)
        # The principal frame is right-handed and the attitude is a unit quaternion.
        np.testing.assert_allclose(body.attitude.norm(), 1.0, atol=4 * EPS)
        np.testing.assert_allclose(np.linalg.det(body.attitude.as_rotation_matrix()), 1.0,
                                   atol=16 * EPS)


def test_disk_limit_is_accepted():
    # Sylvester (1866): a flat disk has C = A + B exactly, the limit of the triangle inequality.
    body = RigidBody([0.1, 0.2, 0.30000000000000004])
    assert body.moments[2] == 0.30000000000000004
    RigidBody([0.1, 0.2, 0.3])


@pytest.mark.parametrize(
    ("inertia", "match"),
    [
        ([1.0, 1.0, 2.5], r"A \+ B >= C, got 2.5 at index 2"),
        ([3.0, 1.0, 1.0], r"A \+ B >= C, got 3.0 at index 0"),
        ([1.0, -1.0, 1.0], r"> 0, got -1.0 at index 1"),
        ([1.0, 0.0, 1.0], r"> 0, got 0.0 at index 1"),
        ([1.0, np.nan, 1.0], "finite, got nan at index 1"),
        ([1.0, 2.0], r"shape \(3,\) or \(3, 3\), got \(2,\)"),
        (np.eye(4), r"shape \(3,\) or \(3, 3\), got \(4, 4\)"),
        ([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], r"symmetric.*inertia\[0, 1\]"),
        (np.diag([1.0, 1.0, -1.0]), "positive definite, got eigenvalue -1.0 at index 0"),
        (np.diag([1.0, 1.0, 3.0]), r"A \+ B >= C, got 3.0 at index 2"),
    ],
)
def test_bad_inertia(inertia, match):
    with pytest.raises(ValueError, match=match):
        RigidBody(inertia)


def test_bad_state():
    with pytest.raises(ValueError, match=r"`omega` to have shape \(3,\), got \(2,\)"):
        RigidBody([1.0, 1.0, 1.0], omega=[1.0, 2.0])
    with pytest.raises(ValueError, match="`omega` to be finite, got inf at index 2"):
        RigidBody([1.0, 1.0, 1.0], omega=[1.0, 2.0, np.inf])
    with pytest.raises(ValueError, match="nonzero quaternion"):
        RigidBody([1.0, 1.0, 1.0], attitude=[0.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"`attitude` to have shape \(4,\)"):
        RigidBody([1.0, 1.0, 1.0], attitude=[1.0, 0.0, 0.0])
    with pytest.raises(u.UnitConversionError, match="inertia"):
        RigidBody([1.0, 1.0, 1.0] * u.m)
    with pytest.raises(ValueError, match="at rest has no invariable plane"):
        _ = RigidBody([1.0, 1.0, 1.0]).invariable_plane


def test_derived_quantities_carry_units():
    """Quantities in, Quantities out: the same numbers as the float body, with units."""
    q = Quaternion.from_axis_angle([1.0, 2.0, 2.0], 0.7)
    plain = RigidBody([1.0, 2.0, 3.0], q, [0.3, -0.2, 1.1])
    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, q, [0.3, -0.2, 1.1] * u.rad / u.s)
    assert body.kinetic_energy.unit == u.J
    assert body.kinetic_energy.value == plain.kinetic_energy
    for name in ("angular_momentum_body", "angular_momentum_space", "cayley_g"):
        value = getattr(body, name)
        assert value.unit == u.kg * u.m**2 / u.s
        np.testing.assert_array_equal(value.value, getattr(plain, name))
    assert body.angular_momentum_norm.to_value(u.g * u.cm**2 / u.s) == pytest.approx(
        1e7 * plain.angular_momentum_norm, rel=1e-15
    )
    assert not isinstance(plain.kinetic_energy, u.Quantity)
    assert body.with_state(omega=[0.0, 0.0, 1.0] * u.rad / u.s).kinetic_energy.unit == u.J
    with pytest.raises(ValueError, match="`omega` as a Quantity like the body's moments"):
        body.with_state(omega=[0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="`omega` as plain floats like the body's moments"):
        plain.with_state(omega=[0.0, 0.0, 1.0] * u.rad / u.s)
    np.testing.assert_array_equal(body.invariable_plane, plain.invariable_plane)


def test_si_view_is_the_state_in_si_floats():
    # 1 g cm^2 = 1e-7 kg m^2 and 180 deg/s = pi rad/s: the view holds SI floats for a
    # body with units and the very same floats for a body of plain SI floats.
    att = Quaternion.from_axis_angle([1.0, 2.0, 2.0], 0.4)
    qb = RigidBody([1.0, 2.0, 2.5] * u.g * u.cm**2, attitude=att,
                   omega=[180.0, 0.0, -90.0] * u.deg / u.s)
    si = qb.si
    np.testing.assert_allclose(si.moments, [1e-7, 2e-7, 2.5e-7], rtol=2 * EPS)
    np.testing.assert_allclose(si.omega, [np.pi, 0.0, -np.pi / 2], rtol=2 * EPS)
    assert np.array_equal(si.attitude, qb.attitude.as_array())
    fb = RigidBody(si.moments, attitude=si.attitude, omega=si.omega)
    assert np.array_equal(fb.si.moments, si.moments) and np.array_equal(fb.si.omega, si.omega)
    # the derived integrals are the floats behind the Quantity properties, bit for bit
    assert si.kinetic_energy == qb.kinetic_energy.to_value(u.J)
    assert np.array_equal(si.angular_momentum_body,
                          qb.angular_momentum_body.to_value(u.kg * u.m**2 / u.s))
    assert np.array_equal(si.angular_momentum_space,
                          qb.angular_momentum_space.to_value(u.kg * u.m**2 / u.s))
    assert si.angular_momentum_norm == qb.angular_momentum_norm.to_value(u.kg * u.m**2 / u.s)
    # copies: writing into the view does not change the body
    si.moments[0] = 99.0
    assert qb.si.moments[0] != 99.0
    # exact power-of-two scales: 2.5e-7 -> 2^-22, pi -> 2
    assert qb.si.scales() == (2.0**-22, 2.0)


def test_from_si_and_quantity_flag():
    b = RigidBody.from_si([1.0, 2.0, 3.0], omega=[0.0, 0.0, 2.0], quantity=True)
    assert b.quantity
    assert b.omega.unit == u.rad / u.s and b.kinetic_energy == 6.0 * u.J
    plain = RigidBody.from_si([1.0, 2.0, 3.0], omega=[0.0, 0.0, 2.0])
    assert not plain.quantity and plain.kinetic_energy == 6.0
    assert RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2).quantity
    # named as from_si names it (it said `inertia`, the constructor's name)
    with pytest.raises(ValueError, match=r"Expected `moments` > 0, got -1.0 at index 0"):
        RigidBody.from_si([-1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"Expected `moments` to be finite, got nan at index 1"):
        RigidBody.from_si([1.0, np.nan, 3.0])
    with pytest.raises(ValueError, match=r"Expected `inertia` > 0, got -1.0 at index 0"):
        RigidBody([-1.0, 2.0, 3.0])
    # any text was true: quantity="no" built a body of Quantities
    with pytest.raises(ValueError, match=r"Expected `quantity` to be True or False, got 'no'"):
        RigidBody.from_si([1.0, 2.0, 3.0], quantity="no")
    assert RigidBody.from_si([1.0, 2.0, 3.0], quantity=np.bool_(True)).quantity


def test_si_view_refuses_integrals_beyond_float64():
    body = RigidBody([1e300, 2e300, 2.5e300], omega=[1e10, 0.0, 0.0])
    with pytest.raises(ValueError, match="representable kinetic energy"):
        _ = body.si.kinetic_energy
