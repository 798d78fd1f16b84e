"""Tests for Poinsot's construction (rigid.poinsot)."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from hamilton_orbits import Quaternion
from rigid import RigidBody
from rigid.poinsot import plot_poinsot, poinsot

matplotlib.use("Agg")
EPS = np.finfo(float).eps
BODY = RigidBody([1.0, 2.0, 3.0], Quaternion([0.6, -0.2, 0.5, 0.3]).unit(), [1.0, 0.3, 0.8])
T = np.linspace(0.0, 40.0, 401)


def test_rolling_on_the_invariable_plane():
    p = poinsot(BODY, T)
    # The contact point lies on the inertia ellipsoid x . I x = 1 ...
    np.testing.assert_allclose(np.sum(BODY.moments * p.polhode**2, -1), 1.0, rtol=8 * EPS)
    # ... and on the invariable plane at the constant distance sqrt(2T)/|L| (Poinsot).
    d = np.sqrt(2 * BODY.kinetic_energy) / BODY.angular_momentum_norm
    assert p.distance == pytest.approx(d, rel=4 * EPS)
    np.testing.assert_allclose(p.contact @ p.plane_normal, d, rtol=32 * EPS)
    # The ellipsoid's normal at the contact point, I rho, is the plane normal (tangency).
    normal_body = BODY.moments * p.polhode
    from rigid import free_motion
    att, _ = free_motion(BODY, T)
    n_space = att.rotate(normal_body / np.linalg.norm(normal_body, axis=-1, keepdims=True))
    np.testing.assert_allclose(n_space, np.broadcast_to(p.plane_normal, n_space.shape),
                               atol=32 * EPS)
    # Rolling without slipping: the contact point is on the instantaneous axis
    # (rho is parallel to omega), so its velocity omega x rho vanishes by construction;
    # the herpolhode radius stays between its extremes |rho|^2 - d^2.
    r2 = np.sum(p.herpolhode**2, -1)
    np.testing.assert_allclose(r2, np.sum(p.polhode**2, -1) - d * d, atol=64 * EPS)
    # Basis orthonormal and right-handed with the normal.
    e1, e2 = p.plane_basis
    np.testing.assert_allclose(np.cross(e1, e2), p.plane_normal, atol=4 * EPS)


def test_polhode_is_closed_and_herpolhode_is_not():
    from rigid import free_parameters
    period = free_parameters(BODY).period
    p = poinsot(BODY, [0.0, period])
    np.testing.assert_allclose(p.polhode[1], p.polhode[0], atol=1e-13)
    assert np.linalg.norm(p.herpolhode[1] - p.herpolhode[0]) > 1e-3  # generic: not closed


def test_plot_and_errors(tmp_path):
    fig = plot_poinsot(BODY, T)
    fig.savefig(tmp_path / "p.png")
    assert (tmp_path / "p.png").stat().st_size > 1000
    # every axis named with its unit, and the ellipsoid drawn in its own proportions
    # (the 3-D box was a cube: a 1 : 0.71 : 0.58 ellipsoid looked like a sphere)
    ellipsoid, plane = fig.axes
    for label in (ellipsoid.get_xlabel(), ellipsoid.get_zlabel(), plane.get_xlabel(),
                  plane.get_ylabel()):
        assert label.endswith("[(kg m$^2$)$^{-1/2}$]"), label
    box = np.asarray(ellipsoid.get_box_aspect())
    semi = 1.0 / np.sqrt(BODY.moments)
    np.testing.assert_allclose(box / box[0], semi / semi[0], rtol=1e-12)
    import matplotlib.pyplot as plt
    plt.close(fig)
    with pytest.raises(ValueError, match="at rest"):
        poinsot(RigidBody([1.0, 2.0, 3.0]), T)
    with pytest.raises(ValueError, match="RigidBody"):
        poinsot(None, T)
