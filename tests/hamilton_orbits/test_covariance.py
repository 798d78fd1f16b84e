"""Trajectory.covariance: an initial covariance carried through the STM.

Checked against a Monte-Carlo cloud of 1000 clones integrated as massless bodies
(issue 35 item 5): the clones' sample covariance agrees with the mapped one
within the sampling error of 1000 draws from a Gaussian.
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits.covariance import propagate

N_CLONES = 1000


def _asteroid():
    """A unit-mass star and a massless body on an orbit of a = 1.3, e = 0.2."""
    a, e = 1.3, 0.2
    r_p = a * (1 - e)
    v_p = np.sqrt((1 + e) / r_p)  # vis-viva at pericentre, GM = 1
    return np.array([r_p, 0.0, 0.01]), np.array([0.0, v_p, 0.002])


def _cov0(rng):
    scale = np.diag([1e-7] * 3 + [1e-8] * 3)
    root = scale @ rng.normal(size=(6, 6))
    return root @ root.T / 6.0


def test_the_mapped_covariance_is_the_monte_carlo_clouds():
    rng = np.random.default_rng(35)
    r0, v0 = _asteroid()
    cov0 = _cov0(rng)
    times = [0.0, 10.0, 20.0]  # about two orbits
    star = Body("star", 1.0, [0, 0, 0], [0, 0, 0])
    nominal = Simulation(System([star, Body("asteroid", 0.0, r0, v0)]), method="radau15",
                         variational=True, stm=True).integrate(times)
    mapped = nominal.covariance(np.stack([np.zeros((6, 6)), cov0]))[:, 1]  # (star exact)
    assert np.array_equal(mapped[0], cov0)  # Phi(0) = 1
    offsets = rng.multivariate_normal(np.zeros(6), cov0, size=N_CLONES)
    clones = [Body(f"c{k}", 0.0, r0 + d[:3], v0 + d[3:]) for k, d in enumerate(offsets)]
    cloud = Simulation(System([star, *clones]), method="radau15").integrate(times)
    for i in (1, 2):
        states = np.concatenate([cloud.r[i, 1:], cloud.v[i, 1:]], axis=1)
        sample = np.cov(states, rowvar=False)
        c = mapped[i]
        # the standard error of a sample covariance of N Gaussian draws:
        # sqrt((C_ab^2 + C_aa C_bb) / (N - 1)); 5 of them for each of the 36 entries
        err = np.sqrt((c**2 + np.outer(np.diag(c), np.diag(c))) / (N_CLONES - 1))
        z = (sample - c) / err
        assert np.all(np.abs(z) <= 5), z
        # and over the 36 together, the RMS of the deviations in sampling errors: 0.25
        # here; 0.83-0.89 for a mapped covariance 5% off, 1.7 for one 10% off (what
        # 1000 clones resolve)
        assert np.sqrt(np.mean(z**2)) < 1.0, np.sqrt(np.mean(z**2))
        assert np.max(np.diag(c)[:3]) > 100 * np.max(np.diag(cov0)[:3])  # it did grow


def test_each_bodys_block_is_the_one_of_the_joint_covariance():
    """The blocks sum every body's initial error through the coupling: they are the
    diagonal blocks of Phi C0 Phi^T with C0 block-diagonal (a few ulp)."""
    rng = np.random.default_rng(7)
    s = System([Body("a", 1.0, [0, 0, 0], [0, -0.05, 0]),
                Body("b", 0.1, [1.0, 0, 0], [0, 1.0, 0.01]),
                Body("c", 0.01, [0, 2.2, 0.1], [-0.7, 0, 0])])
    traj = Simulation(s, method="radau15", variational=True, stm=True).integrate([0.0, 3.0, 7.0])
    cov0 = np.stack([_cov0(rng) for _ in range(3)])
    blocks = traj.covariance(cov0)
    joint0 = np.zeros((18, 18))
    for j in range(3):
        joint0[6 * j:6 * j + 6, 6 * j:6 * j + 6] = cov0[j]
    for t in range(3):
        joint = traj.stm[t] @ joint0 @ traj.stm[t].T
        for i in range(3):
            want = joint[6 * i:6 * i + 6, 6 * i:6 * i + 6]
            np.testing.assert_allclose(blocks[t, i], want, rtol=1e-13,
                                       atol=1e-13 * np.max(np.abs(want)))
        assert np.array_equal(blocks[t], np.swapaxes(blocks[t], -1, -2))


def test_a_quantity_system_takes_au_and_days():
    gm_sun = 1.32712440018e11 * u.km**3 / u.s**2
    s = System([Body("sun", gm_sun, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                Body("ceres", 0 * gm_sun, [2.77, 0, 0] * u.au, [0, 17.9, 0] * u.km / u.s)])
    traj = Simulation(s, method="radau15", variational=True, stm=True).integrate([0, 100] * u.day)
    cov0 = np.diag([1e-10] * 3 + [1e-14] * 3)  # au^2, au^2/day^2
    c = traj.covariance(cov0)
    assert c.shape == (2, 2, 6, 6) and np.array_equal(c[0, 1], cov0)
    # after 100 days the position error holds the velocity's (100 day)^2 1e-14 au^2/day^2
    assert c[1, 1, 1, 1] > 1e-10 + 0.5 * 100**2 * 1e-14


@pytest.mark.parametrize(("cov0", "match"), [
    (np.eye(5), r"shape \(6, 6\) or \(2, 6, 6\), got \(5, 5\)"),
    (np.eye(6) * u.au**2, r"floats in the state's units .* got a Quantity"),
    # (a (6, 6) cov0's indices are its own: they were said of (n, 6, 6), (0, 5, 5))
    (np.triu(np.ones((6, 6))) + np.eye(6), r"symmetric, got 1.0 and 0.0 at indices "
                                           r"\(0, 1\) and \(1, 0\)"),
    (np.diag([1.0, 1, 1, 1, 1, -1e-3]), r"variances >= 0, got -0.001 at index \(5, 5\)"),
    (np.ones((6, 6)) - 2 * np.eye(6)[::-1], r"positive semi-definite, got its correlation "
                                           r"matrix's eigenvalue .* for every body's \(`cov0`\)"),
    (np.stack([np.eye(6), np.diag([1.0, 1, 1, -1e-3, 1, 1])]),
     r"variances >= 0, got -0.001 at index \(1, 3, 3\)"),
    (np.stack([np.eye(6), np.ones((6, 6)) - 2 * np.eye(6)[::-1]]),
     r"eigenvalue .* for body 1 \(`cov0\[1\]`\)"),
    (np.where(np.eye(6) > 0, 1.0, np.inf), r"finite, got inf at index \(0, 1\)"),
    (np.stack([np.eye(6), np.full((6, 6), np.nan)]), r"finite, got nan at index \(1, 0, 0\)"),
    # (in au and au/day, SI: a velocity block 1e8-1e10 times smaller than the
    # positions' was checked against the largest entry: its faults went through)
    (np.diag([1e4] * 3 + [1e-6, 1e-6, -5e-9]), r"variances >= 0, got -5e-09 at index "
                                                r"\(5, 5\)"),
    (np.diag([1e-6] * 3 + [1e-19] * 3) + 4e-19 * (np.eye(6, k=1) - np.eye(6, k=-1)) * (
        np.arange(6)[:, None] >= 3) * (np.arange(6)[None, :] >= 3),
     r"symmetric, got 4e-19 and -4e-19 at indices \(3, 4\) and \(4, 3\)"),
    (np.diag([1e-6] * 3 + [1e-19] * 3) + 2e-19 * (np.eye(6, k=1) + np.eye(6, k=-1)) * (
        np.arange(6)[:, None] >= 3) * (np.arange(6)[None, :] >= 3),
     r"positive semi-definite, got its correlation matrix's eigenvalue -1.83 for every "),
    ("a", r"`cov0` to be numeric, got 'a'"),  # (numpy's bare "could not convert")
])
def test_a_bad_initial_covariance_is_refused_naming_it(cov0, match):
    with pytest.raises(ValueError, match=match):
        propagate(np.tile(np.eye(12), (2, 1, 1)), cov0, 2)


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_a_non_finite_stm_is_refused_naming_it(value):
    """A NaN in the STM went through to NaN covariances (11 of them), unsaid."""
    phi = np.tile(np.eye(6), (2, 1, 1))
    phi[1, 0, 3] = value
    with pytest.raises(ValueError, match=rf"`stm` finite, got {value} at index \(1, 0, 3\)"):
        propagate(phi, np.diag([1e-12] * 3 + [1e-16] * 3), 1)


def test_a_covariance_near_singular_in_any_units_is_taken():
    """Correlations of 1 - 1e-9 (an orbit fit's), a variance of 0 with no covariance
    beside it, and the same matrices in SI or au: taken, as they are."""
    c = np.diag([1e-6] * 3 + [1e-19] * 3)
    c[0, 3] = c[3, 0] = (1 - 1e-9) * np.sqrt(1e-6 * 1e-19)
    c[2, 2] = 0.0
    for scale in (1.0, 1.496e11**2):  # (au^2 and m^2 alike: the velocities' scale apart)
        out = propagate(np.tile(np.eye(6), (1, 1, 1)), c * scale, 1)
        assert np.array_equal(out[0, 0], c * scale)


def test_covariance_needs_the_stm():
    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
    traj = Simulation(s, method="radau15").integrate(1.0)
    with pytest.raises(ValueError, match=r"integrate with stm=True"):
        traj.covariance(np.eye(6))
