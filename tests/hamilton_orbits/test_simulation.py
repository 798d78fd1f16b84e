"""integrate and Trajectory: Hamilton's integrals (C), (D), (E), times, hard cases."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, KeplerOrbit, System, Trajectory, crosscheck, integrate

EPS = np.finfo(float).eps


def sun_jupiter_saturn() -> System:
    return System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])


def test_trajectory_shapes_and_units():
    s = sun_jupiter_saturn()
    t = np.linspace(0, 1000, 11) * u.day
    traj = integrate(s, t, method="dop853", tol=1e-12)
    assert isinstance(traj, Trajectory)
    assert traj.t.unit == u.day and traj.r.unit == u.au and traj.v.unit == u.au / u.day
    assert traj.r.shape == (11, 3, 3) and traj.v.shape == (11, 3, 3)
    assert traj.energy_error.shape == (11,) and traj.energy_error[0] == 0.0
    assert traj.names == s.names and traj.final.names == s.names
    np.testing.assert_array_equal(traj.final.r.value, traj.r[-1].value)
    assert traj.steps > 0 and traj.wall_time > 0
    # an end time in years is read as years
    traj_yr = integrate(s, 1000 * u.day.to(u.yr) * u.yr, method="dop853", tol=1e-12)
    assert traj_yr.t[-1].to_value(u.day) == pytest.approx(1000, rel=1e-15)


@pytest.mark.parametrize(
    ("method", "kwargs", "e_tol", "l_tol"),
    [
        # leapfrog: energy error bounded, O(dt^2); 100 steps per Jupiter orbit
        ("leapfrog", {"dt": 4332.6 / 400 * u.day}, 1e-4, 1e-13),
        # dop853: not symplectic; local error at tol per step
        ("dop853", {"tol": 1e-13}, 1e-12, 1e-12),
    ],
)
def test_integrals_conserved(method, kwargs, e_tol, l_tol):
    """(C) centre of mass, (D) areas, (E) vis viva, each at its integrator's level.

    Leapfrog conserves angular momentum exactly up to rounding (it is a symplectic
    map that commutes with rotations) and the centre of mass exactly; its energy
    oscillates at O(dt^2).
    """
    s = sun_jupiter_saturn()
    traj = integrate(s, 10 * 4332.6 * u.day, method=method, **kwargs)
    assert np.max(np.abs(traj.energy_error)) < e_tol
    assert np.max(traj.angular_momentum_error) < l_tol
    assert np.max(traj.barycentre_drift) < 1e-12


def test_backwards_and_forwards_return():
    s = sun_jupiter_saturn()
    fwd = integrate(s, 3000 * u.day, method="leapfrog", dt=5 * u.day)
    back = integrate(fwd.final, -3000 * u.day, method="leapfrog", dt=5 * u.day)
    # leapfrog is time-reversible: rounding only
    np.testing.assert_allclose(back.final._r, s._r, rtol=0, atol=1e-11)


@pytest.mark.parametrize(
    ("t", "match"),
    [
        (0 * u.day, r"nonzero"),
        ([1.0, 3.0, 2.0] * u.day, r"monotonic.*index 3"),
        (5.0, r"time Quantity"),
        (5 * u.m, r"t"),
    ],
)
def test_bad_times(t, match):
    with pytest.raises((ValueError, u.UnitConversionError), match=match):
        integrate(sun_jupiter_saturn(), t, method="leapfrog", dt=1 * u.day)


def test_bad_method_and_arguments():
    s = sun_jupiter_saturn()
    with pytest.raises(ValueError, match=r"Unknown `method` 'rk4'.*radau15, wh, leapfrog, dop853"):
        integrate(s, 1 * u.day, method="rk4")
    with pytest.raises(ValueError, match=r"`system`"):
        integrate(None, 1 * u.day)
    with pytest.raises(ValueError, match=r"`dt` > 0"):
        integrate(s, 1 * u.day, method="leapfrog", dt=-1 * u.day)
    with pytest.raises(ValueError, match=r"leapfrog needs a step"):
        integrate(s, 1 * u.day, method="leapfrog")


def test_comet_through_perihelion():
    """e = 0.9999: an adaptive integrator keeps the two-body orbit to 1e-9 relative."""
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.9999, inc=0.3, lan=0.2, argp=0.1, M=-0.05,
                                      mu=1.0)
    r0, v0 = orbit.state()
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("comet", 0.0, r0, v0)])
    traj = integrate(s, 0.1, method="dop853", tol=1e-14)
    exact, _ = orbit.propagate(0.1).state()
    err = np.linalg.norm(traj.final._r[1] - exact) / np.linalg.norm(exact)
    # DOP853 at its rtol floor 2.2e-14 through a perihelion of q = 1e-4: the error
    # accumulated near perihelion, where the step shrinks by 1e6, stays below 1e-9
    assert err < 1e-9


def test_hyperbolic_flyby_matches_two_body():
    orbit = KeplerOrbit.from_elements(a=-1.0, e=1.5, inc=0.0, lan=0.0, argp=0.0, M=-2.0,
                                      mu=1.0)
    r0, v0 = orbit.state()
    s = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]), Body("probe", 0.0, r0, v0)])
    traj = integrate(s, 4.0, method="dop853", tol=1e-13)
    exact, _ = orbit.propagate(4.0).state()
    assert np.linalg.norm(traj.final._r[1] - exact) < 1e-10 * np.linalg.norm(exact)


def test_dop853_tolerance_is_per_body():
    """A far massless body does not loosen the error control of an inner orbit.

    The inner orbit (a = 1, e = 0.3, ten periods) is checked against the exact
    Kepler propagation.  A second, massless body at 1e4 (no force on the first)
    must leave its error unchanged: with one absolute tolerance scaled by the
    largest coordinate (the former rule) the inner error grew ~1e3-fold.
    """
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.2, lan=0.1, argp=0.4, M=0.0,
                                      mu=1.0)
    r0, v0 = orbit.state()
    star = Body("star", 1.0, [0, 0, 0], [0, 0, 0])
    far = Body("far", 0.0, [1e4, 0, 0], [0, 1e-2, 0])
    t = 20 * np.pi
    exact, _ = orbit.propagate(t).state()
    errs = []
    for bodies in ([star, Body("p", 0.0, r0, v0)], [star, Body("p", 0.0, r0, v0), far]):
        traj = integrate(System(bodies), t, method="dop853", tol=1e-10)
        errs.append(np.linalg.norm(traj.final._r[1] - exact))
    # ~270 steps at rtol 1e-10; the along-track error grows with the phase swept
    # (n t = 20 pi): bound steps x tol x n t = 1.7e-6 (measured 3.5e-7)
    assert errs[0] < 1.7e-6
    # same step sequence up to the far body's own (smooth) demands
    assert errs[1] < 2 * errs[0]


def test_close_encounter_at_1e_4_au():
    """Two small bodies passing within 1e-4 au at 0.2 au/day relative speed.

    The encounter is set up at t = 0.1 (separation 1e-4 au across the relative
    velocity) and traced back with rebound's IAS15 to t = 0.  Ours must come through
    it with the energy held and agree with IAS15 afterwards.
    """
    sun = Body("sun", 1.0, [0, 0, 0], [0, 0, 0])
    a = Body("a", 1e-7, [1.0 - 5e-5, 0, 0], [0, 1.1, 0])
    b = Body("b", 1e-7, [1.0 + 5e-5, 0, 0], [0, 0.9, 0])
    sim = System([sun, a, b]).to_rebound()
    sim.integrate(-0.1, exact_finish_time=1)
    sim.t = 0.0
    system = System.from_rebound(sim)
    t = np.linspace(0.0, 0.2, 2001)
    traj = integrate(system, t, method="dop853", tol=1e-14)
    sep = np.linalg.norm(traj.r[:, 1] - traj.r[:, 2], axis=1)
    assert 1e-5 < sep.min() < 1.2e-4
    assert np.max(np.abs(traj.energy_error)) < 1e-11
    table = crosscheck(system, 0.2, method="dop853", trajectory=traj)
    assert table.relative_position_difference.max() < 1e-9


def test_many_test_particles():
    """10^4 massless particles: O(n_massive) each; their orbits stay Keplerian."""
    rng = np.random.default_rng(3)
    n = 10_000
    rad = rng.uniform(1.0, 2.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    r = np.column_stack((rad * np.cos(phi), rad * np.sin(phi), np.zeros(n)))
    v = np.column_stack((-np.sin(phi), np.cos(phi), np.zeros(n))) / np.sqrt(rad)[:, None]
    bodies = [Body("sun", 1.0, [0, 0, 0], [0, 0, 0])]
    bodies += [Body(f"p{k}", 0.0, r[k], v[k]) for k in range(n)]
    traj = integrate(System(bodies), 1.0, method="leapfrog", dt=1e-3)
    radius = np.linalg.norm(traj.final._r[1:], axis=1)
    # circular orbits under leapfrog with dt = 1e-3: radii kept to O(dt^2)
    np.testing.assert_allclose(radius, rad, rtol=1e-6)


def test_progress_and_output_callback():
    seen = []
    integrate(sun_jupiter_saturn(), np.linspace(0, 100, 6) * u.day, method="leapfrog",
              dt=1 * u.day, on_output=lambda i, steps: seen.append((i, steps)))
    assert [i for i, _ in seen] == [1, 2, 3, 4, 5]
    assert seen[-1][1] == 100
