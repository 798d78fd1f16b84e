"""Tests for Sylvester's theorems (rigid.sylvester) against the exact motion."""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits import Quaternion
from rigid import RigidBody, free_motion, free_parameters
from rigid.sylvester import (
    confocal,
    confocal_rotation,
    contrafocal,
    disk_equivalent,
    time_between,
)

EPS = np.finfo(float).eps
BODY = RigidBody([1.0, 2.0, 2.5], Quaternion([0.8, 0.2, -0.4, 0.4]).unit(), [1.0, 0.5, 0.2])
T = np.linspace(0.0, 60.0, 121)


def _axes_cosines(att: Quaternion, lhat: np.ndarray) -> np.ndarray:
    """cos of the angles between the principal axes (in space) and the invariable line."""
    return att.as_rotation_matrix().transpose(0, 2, 1) @ lhat  # rows of R^T = axes


def _qdist(q1, q2):
    return np.minimum(np.abs(q1 - q2).max(-1), np.abs(q1 + q2).max(-1))


@pytest.mark.parametrize("lam", [-0.1, 0.1, 0.7])
def test_confocal_theorem(lam):
    # Sylvester (1866): the principal axes stay equally inclined to the invariable line,
    # and the bodies differ only by a uniform rotation L lam t about it.
    other = confocal(BODY, lam)
    np.testing.assert_allclose(1 / other.moments - 1 / BODY.moments, lam, atol=8 * EPS)
    np.testing.assert_allclose(other.angular_momentum_space, BODY.angular_momentum_space,
                               atol=8 * EPS)
    att, _ = free_motion(BODY, T)
    att2, _ = free_motion(other, T)
    lhat = BODY.invariable_plane
    np.testing.assert_allclose(_axes_cosines(att2, lhat), _axes_cosines(att, lhat), atol=1e-13)
    rot = confocal_rotation(BODY, lam, T)
    assert _qdist((rot * att).as_array(), att2.as_array()).max() < 1e-12
    # The sign matters: the opposite rotation is wrong as soon as lam L t is not small.
    wrong = confocal_rotation(BODY, -lam, T)
    assert _qdist((wrong * att).as_array(), att2.as_array()).max() > 0.1


@pytest.mark.parametrize("lam", [1.8, 2.0, 2.4])
def test_contrafocal_theorem(lam):
    other = contrafocal(BODY, lam)
    np.testing.assert_allclose(1 / other.moments + 1 / BODY.moments, lam, atol=8 * EPS)
    np.testing.assert_allclose(other.angular_momentum_space, -BODY.angular_momentum_space,
                               atol=8 * EPS)
    att, _ = free_motion(BODY, T)
    att2, _ = free_motion(other, T)
    lhat = BODY.invariable_plane
    # Equal but contrary inclinations: each body's axes against its own invariable
    # line (the couples are contrary) make supplementary angles.
    np.testing.assert_allclose(other.invariable_plane, -lhat, atol=8 * EPS)
    np.testing.assert_allclose(_axes_cosines(att2, other.invariable_plane),
                               -_axes_cosines(att, lhat), atol=1e-13)
    # (so against the invariable line of BODY the angles are the same, not
    # supplementary, as contrafocal's docstring said before)
    np.testing.assert_allclose(_axes_cosines(att2, lhat), _axes_cosines(att, lhat), atol=1e-13)
    rot = confocal_rotation(BODY, -lam, T)
    assert _qdist((rot * att).as_array(), att2.as_array()).max() < 1e-12


def test_related_body_errors():
    with pytest.raises(ValueError, match="reciprocal moment positive"):
        confocal(BODY, -1.5)
    with pytest.raises(ValueError, match="A \\+ B >= C"):
        contrafocal(BODY, 1.5)
    with pytest.raises(ValueError, match="RigidBody"):
        confocal([1.0, 2.0, 3.0], 0.1)


@pytest.mark.parametrize(
    "omega", [[1.0, 0.5, 0.2], [0.2, 0.5, 1.0], [0.6, 0.1, 0.5], [-0.1, 0.9, 0.3]]
)
def test_disk_theorem(omega):
    body = BODY.with_state(omega=omega)
    disk, rel, _lam, delta = disk_equivalent(body)
    m = np.sort(disk.moments)
    assert abs(m[2] - m[0] - m[1]) <= 16 * EPS * m[2]  # a flat disk: C' = A' + B'
    # Sylvester's choice: direct if L^2 / 2T > B, supplemental otherwise.
    d = np.sum(body.angular_momentum_body**2) / (2 * body.kinetic_energy)
    assert rel == ("confocal" if d > 2.0 else "contrafocal")
    _, w = free_motion(body, T)
    _, v = free_motion(disk, T)
    diff = np.sum(v * v, -1) - np.sum(w * w, -1)
    # The difference of squared angular velocities is constant and equals delta.
    np.testing.assert_allclose(diff, delta, rtol=0, atol=64 * EPS * np.sum(v * v, -1).max())
    # On the disk, the angular velocity in its own plane has constant magnitude
    # (Sylvester 1866, "the angular velocity with which the disk turns about a line
    # in its own plane is constant").
    k = int(np.argmax(disk.moments))
    inplane = np.sum(np.delete(v, k, axis=-1) ** 2, -1)
    np.testing.assert_allclose(inplane, inplane[0], rtol=64 * EPS)
    # And the disk keeps the original's inclinations to its own invariable line
    # (equal for the direct reduction, supplementary for the supplemental one).
    att, _ = free_motion(body, T)
    att_d, _ = free_motion(disk, T)
    sgn = 1.0 if rel == "confocal" else -1.0
    np.testing.assert_allclose(_axes_cosines(att_d, disk.invariable_plane),
                               sgn * _axes_cosines(att, body.invariable_plane), atol=1e-13)


@pytest.mark.parametrize("moments", [
    [542514.1220844062, 815675.8214228445, 1358189.9435072506],  # C = A + B in floats
    [1.0, 1.5, 2.5],
])
def test_disk_equivalent_of_a_disk_is_itself(moments):
    # A body already flat: Sylvester's root lam is 0 (or a rounding of it, 1e-16).
    # Where it came out exactly 0 the disk was refused as "beyond float64" while its
    # neighbour with lam = -1.1e-16 was returned: now both are the body itself, confocal.
    body = RigidBody(moments, [0.8, 0.2, -0.4, 0.4], [7.3e-8, 7.0e-6, -4.2e-6])
    disk, rel, lam, delta = disk_equivalent(body)
    assert rel == "confocal"
    assert abs(lam) <= 4 * EPS / min(moments)
    np.testing.assert_allclose(disk.moments, body.moments, rtol=4 * EPS)
    np.testing.assert_allclose(disk.omega, body.omega, rtol=4 * EPS)
    assert abs(delta) <= 8 * EPS * np.sum(body.omega**2)
    if lam == 0.0:  # the exact root: the very same body
        np.testing.assert_array_equal(disk.moments, body.moments)
        np.testing.assert_array_equal(disk.omega, body.omega)
        assert delta == 0.0


def test_time_between_positions():
    body = BODY
    period = free_parameters(body).period
    for t in (0.3, 2.5, 0.49 * period, 0.9 * period, 3.2 * period):
        _, w = free_motion(body, t)
        got = time_between(body, body.omega, w)
        assert abs(got - np.mod(t, period)) < 1e-12 * period
    # Between two later positions.
    _, w = free_motion(body, [1.0, 4.0])
    assert abs(time_between(body, w[0], w[1]) - 3.0) < 1e-12 * period
    with pytest.raises(ValueError, match="same T and"):
        time_between(body, body.omega, 1.1 * body.omega)
    # (the refusal quoted the internally rescaled 2T and L^2 as np.float64 reprs,
    # not the body's: now the relative differences, the body's as the problem's)
    other = RigidBody([1.0, 2.0, 2.5], omega=[1.0, 0.5, 0.2])  # 2T = 1.6, L^2 = 2.25
    with pytest.raises(ValueError, match=r"got its 2T \+0.0781 and its L\^2 \+0.139 "
                                         r"\(relative\) off those of `omega1`"):
        time_between(other, [1.0, 0.5, 0.2], [1.0, 0.5, 0.3])  # 1.725, 2.5625
    with pytest.raises(ValueError, match=r"`omega2` to have shape \(3,\)"):
        time_between(body, body.omega, [1.0, 2.0])
    # a body at rest: a divide-by-zero warning, then `omega2` blamed ("+inf off")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"`omega1` nonzero \(a body at rest stays at "
                                             r"rest.*got \[0.0, 0.0, 0.0\]"):
            time_between(body, [0.0, 0.0, 0.0], body.omega)


def test_time_between_on_separatrix():
    body = RigidBody([2.0, 5.0, 6.0], omega=[1.0, 0.5, 1.0])  # L^2 = 2TB exactly
    _, w = free_motion(body, 3.0)
    assert abs(time_between(body, body.omega, w) - 3.0) < 1e-12
    with pytest.raises(ValueError, match="after `omega1`"):
        time_between(body, w, body.omega)


def test_time_between_refuses_another_arc_of_the_separatrix():
    # Body (2, 5, 6), omega1 = (1, 0.5, 1): L^2 = 46.25 = 2 T B exactly (the separatrix).
    # On it omega_1 = a sech(tau), omega_2 = b tanh(tau), omega_3 = c sech(tau) (Landau &
    # Lifshitz, Mechanics §37): omega_1 keeps its sign, so the states with omega_1 = -1
    # (same T and |L|) lie on another heteroclinic arc and are never reached.  The first
    # was answered 0.0 s, the second refused as "before" omega1.
    body = RigidBody([2.0, 5.0, 6.0], omega=[1.0, 0.5, 1.0])
    assert free_parameters(body).kind == "separatrix"
    for w2 in ([-1.0, -0.5, 1.0], [-1.0, 0.5, 1.0]):
        with pytest.raises(ValueError, match=r"`omega2` on the arc of the separatrix of "
                                             r"`omega1`.*on another arc, never reached"):
            time_between(body, body.omega, w2)
    # on the same arc: the time from sinh(u) = (omega_2 / b) / (omega_1 / a), with
    # a^2 = (2T C - L^2) / (A (C - A)) = 9.25 / 8, b^2 = (2T C - L^2) / (B (C - B)) = 9.25 / 5,
    # lambda^2 = (C - B)(L^2 - 2 T A) / (A B C) = 27.75 / 60 (L&L §37): omega1 -> (1, -0.5, 1)
    # goes from u0 to -u0, backwards (refused), and (1, -0.5, 1) -> omega1 takes
    # 2 asinh(0.5 sqrt(5/8)) / lambda.
    with pytest.raises(ValueError, match="got it before"):
        time_between(body, body.omega, [1.0, -0.5, 1.0])
    expected = 2.0 * np.arcsinh(0.5 * np.sqrt(0.625)) / np.sqrt(27.75 / 60.0)
    got = time_between(body, [1.0, -0.5, 1.0], body.omega)
    assert abs(got - expected) <= 1e-14 * expected  # a few ulp of asinh and sqrt
