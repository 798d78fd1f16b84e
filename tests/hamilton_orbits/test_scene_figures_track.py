"""scenes.nbody.figures: the two-body arcs drawn between a body's outputs."""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits.kepler import propagate
from hamilton_orbits.scenes.nbody.figures import _arcs, refined_track


def _states(rng, m, speeds):
    """``m`` states about mu = 1 at distance ~1, speeds from ``speeds`` (1.414:
    escape), directions spread (inclined, prograde)."""
    r = rng.normal(size=(m, 3)) * [1.0, 1.0, 0.2]
    r /= np.linalg.norm(r, axis=-1)[:, None]
    t_hat = np.cross([0.1, 0.2, 1.0], r)
    t_hat /= np.linalg.norm(t_hat, axis=-1)[:, None]
    v = rng.choice(speeds, m)[:, None] * (t_hat + 0.2 * rng.normal(size=(m, 3)))
    return r, v


def _time_on_ellipse(x, r0, v0, mu=1.0):
    """The time after ``r0, v0`` at which its ellipse passes through ``x`` (the
    first pass: the change of eccentric anomaly in [0, 2 pi)), by Kepler's equation."""
    h = np.cross(r0, v0)
    ecc = np.cross(v0, h) / mu - r0 / np.linalg.norm(r0)
    e = np.linalg.norm(ecc)
    a = 1 / (2 / np.linalg.norm(r0) - v0 @ v0 / mu)
    p, q = ecc / e, np.cross(h, ecc) / (e * np.linalg.norm(h))
    b = a * np.sqrt(1 - e * e)

    def anomaly(y):
        return np.arctan2(y @ q / b, y @ p / a + e)

    e0, e1 = anomaly(r0), anomaly(x)
    e1 = e0 + np.mod(e1 - e0, 2 * np.pi)
    return ((e1 - e * np.sin(e1)) - (e0 - e * np.sin(e0))) / np.sqrt(mu / a**3)


def test_elliptic_arcs_lie_on_the_two_body_motion_at_their_own_times():
    """Each point of an elliptic arc (equal steps of the eccentric anomaly) is the
    two-body state at the time Kepler's equation gives for it, by the universal
    solver (another method: 1e-13 of the orbit's size, measured 3.5e-15: the rounding
    of Newton's steps, of the trigonometry and of the time recovered; orbits of e
    0.13 to 0.73 here); the arc's end is the state at its
    span."""
    rng = np.random.default_rng(3)
    r, v = _states(rng, 12, [0.45, 0.8, 1.0, 1.25])
    e = np.linalg.norm(np.cross(v, np.cross(r, v)) - r, axis=-1)
    keep = e < 0.9
    r, v = r[keep], v[keep]
    a = 1 / (2 / np.linalg.norm(r, axis=-1) - np.einsum("ij,ij->i", v, v))
    span = rng.uniform(0.05, 0.999, len(r)) * 2 * np.pi * a**1.5  # (at most a revolution,
    # as the track asks)
    n = rng.integers(2, 40, len(r))
    inner, ends = _arcs(r, v, 1.0, span, n)
    assert inner.shape == (int((n - 1).sum()), 3) and ends.shape == (len(r), 3)
    at = 0
    for i in range(len(r)):
        pts = inner[at:at + n[i] - 1]
        at += n[i] - 1
        times = [_time_on_ellipse(x, r[i], v[i]) for x in pts]
        assert np.all(np.diff(times) > 0) and 0 < times[0] and times[-1] < span[i]
        want = propagate(np.tile(r[i], (len(pts), 1)), np.tile(v[i], (len(pts), 1)), 1.0,
                         np.array(times))[0]
        np.testing.assert_allclose(pts, want, rtol=0, atol=1e-13 * np.abs(want).max())
        end = propagate(r[i], v[i], 1.0, span[i])[0]
        np.testing.assert_allclose(ends[i], end, rtol=0, atol=1e-13 * np.abs(end).max())


def test_steep_and_unbound_arcs_are_the_universal_solution_at_equal_times():
    """Hyperbolic, near-parabolic and e >= 0.95 arcs: the universal solver at equal
    steps of time, exactly."""
    rng = np.random.default_rng(5)
    r, v = _states(rng, 6, [1.3, 1.41, 1.6])
    span, n = rng.uniform(0.5, 3.0, 6), rng.integers(2, 20, 6)
    inner, ends = _arcs(r, v, 1.0, span, n)
    at = 0
    for i in range(6):
        tau = np.arange(1, n[i]) / n[i] * span[i]
        want = propagate(np.tile(r[i], (len(tau), 1)), np.tile(v[i], (len(tau), 1)), 1.0, tau)
        assert np.array_equal(inner[at:at + n[i] - 1], want[0])
        at += n[i] - 1
        assert np.array_equal(ends[i], propagate(r[i], v[i], 1.0, span[i])[0])


@pytest.mark.parametrize("speed", [0.8, 1.0, 1.6])
def test_a_track_keeps_its_outputs_in_order_and_breaks_after_whole_orbits(speed):
    """The outputs are all drawn, in order, with arcs between; a whole revolution
    between two outputs ends in a NaN row (no chord across the plot)."""
    rng = np.random.default_rng(int(speed * 10))
    r0, v0 = np.array([1.0, 0.0, 0.1]), speed * np.array([0.0, 1.0, 0.05])
    t = np.concatenate([[0.0], np.cumsum(rng.choice([0.03, 0.3, 3.0, 20.0], 40))])
    r, v = propagate(np.tile(r0, (len(t), 1)), np.tile(v0, (len(t), 1)), 1.0, t)
    r = r * (1 + 1e-3 * rng.standard_normal((len(t), 1)))  # (not on one conic)
    pts, refined = refined_track(t, r, v, 1.0)
    assert refined and len(pts) > len(r)
    rows = [np.flatnonzero((pts == x).all(axis=1)) for x in r]
    assert all(len(k) for k in rows)
    assert np.all(np.diff([k[0] for k in rows]) > 0)
    assert np.isfinite(pts).all(axis=1).sum() + np.isnan(pts).all(axis=1).sum() == len(pts)
    assert np.isnan(pts).any() == (speed < 1.4)  # (bound: some outputs a revolution apart)
