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
    # the coordinates are x . I x = 1 times sqrt(C), free of units: a body of plain
    # numbers claims none (they were labelled in (kg m^2)^-1/2 whatever the input)
    ellipsoid = fig.axes[0]
    for ax in fig.axes:
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert "sqrt{C}" in label and "kg" not in label, label
    assert "3 in the caller's units" in fig.texts[0].get_text()
    box = np.asarray(ellipsoid.get_box_aspect())
    semi = np.sqrt(3.0 / BODY.moments)
    np.testing.assert_allclose(box / box[0], semi / semi[0], rtol=1e-12)
    import matplotlib.pyplot as plt
    plt.close(fig)
    with pytest.raises(ValueError, match="at rest"):
        poinsot(RigidBody([1.0, 2.0, 3.0]), T)
    with pytest.raises(ValueError, match="RigidBody"):
        poinsot(None, T)


def test_plot_of_the_earth_in_si_is_of_order_one():
    # The Earth in SI: the axes had offset texts 1e19 and 1e-28 over their labels, the
    # polhode was invisible on the ellipsoid and the herpolhode, sampled 3 times a day
    # for a daily circle, a solid ring of chords.
    import astropy.units as u
    import matplotlib.pyplot as plt
    om = 7.292115e-5
    earth = RigidBody([8.0101e37, 8.0103e37, 8.0365e37] * u.kg * u.m**2,
                      omega=[om * 1e-6, 0.0, om] * u.rad / u.s)
    fig = plot_poinsot(earth, np.linspace(0.0, 600.0, 2000) * u.d)
    fig.canvas.draw()
    polhode, plane = fig.axes[1:]
    assert "8.037e+37 kg m$^2$" in fig.texts[0].get_text()
    for ax in (polhode, plane):
        for axis in (ax.xaxis, ax.yaxis):
            assert axis.get_offset_text().get_text() == ""
    # the polhode framed on itself, seen along axis 3, in units of 1e-6 stated in the labels
    assert polhode.get_title().startswith("polhode seen along body axis 3")
    assert polhode.get_xlabel().endswith("/ $10^{-6}$")
    x, y = polhode.lines[0].get_data()
    assert 0.9 < np.max(np.hypot(x, y)) < 1.1
    np.testing.assert_allclose(polhode.get_xlim(), [-1.0, 1.0], atol=0.6)
    # the herpolhode (a circle of 3.3e-9 turned once a day) as unjoined points
    assert plane.get_xlabel().endswith("/ $10^{-9}$")
    line = plane.lines[0]
    assert line.get_linestyle() == "None" and line.get_marker() == "."
    np.testing.assert_allclose(np.hypot(*line.get_data()), 3.285, rtol=1e-2)
    assert "too far apart" in plane.get_title()
    plt.close(fig)


def test_plot_of_one_time_is_its_point():
    # One time drew two empty panels: its point is marked on each.
    import matplotlib.pyplot as plt
    fig = plot_poinsot(BODY, [5.0])
    p = poinsot(BODY, [5.0])
    plane = fig.axes[2]
    marks = [line for line in plane.lines if line.get_marker() == "o"]
    np.testing.assert_allclose(np.ravel(marks[0].get_data()), p.herpolhode[0] * np.sqrt(3.0))
    assert all(any(line.get_marker() == "o" for line in ax.lines) for ax in fig.axes)
    assert "one time" in plane.get_title()
    plt.close(fig)
