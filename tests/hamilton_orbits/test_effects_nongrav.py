"""The effect ``nongrav``: Marsden, Sekanina & Yeomans (1973) A1, A2, A3 g(r).

References are closed-form solutions of a massless body about a unit-GM Sun at
rest, with g = (1 / r)^2 (the asteroid form) on a circular orbit of radius 1:
- A1 (radial) is a weaker Sun, GM' = 1 - A1: the circle of that GM stays exact;
- A2 (transverse) drifts the semi-major axis by Gauss's equation,
  da/dt = 2 A2 g / n = 2 A2 a^-1/2, so a(t) = (1 + 3 A2 t)^(2/3);
- A3 (normal) lifts the orbit out of its plane, z(t) = A3 (1 - cos t) to first order.
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits._kernels.nongrav import nongrav
from hamilton_orbits.effects.nongrav import COMET_G


def _circle(speed: float = 1.0) -> System:
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("rock", 0.0, [1.0, 0, 0], [0, speed, 0])])


def _run(effect: dict, times, speed: float = 1.0, **kw):
    return Simulation(_circle(speed), method="radau15",
                      effects=[{"name": "nongrav", "body": "rock", **effect}], **kw
                      ).integrate(times)


def test_a_radial_acceleration_is_a_weaker_sun():
    a1 = 1e-3
    w = np.sqrt(1.0 - a1)
    t = np.linspace(0.0, 10.0, 6)
    traj = _run({"A1": a1}, t, speed=w)
    circle = np.stack([np.cos(w * t), np.sin(w * t), 0 * t], axis=1)
    assert np.abs(traj.r[:, 1] - circle).max() < 1e-12  # (radau15's error on a circle)


def test_a_transverse_acceleration_drifts_the_semi_major_axis_as_gauss_says():
    a2 = 1e-6
    t = np.linspace(0.0, 200.0, 41)  # 32 orbits
    traj = _run({"A2": a2}, t)
    r = np.linalg.norm(traj.r[:, 1], axis=1)
    a = 1.0 / (2.0 / r - np.sum(traj.v[:, 1] ** 2, axis=1))
    want = (1.0 + 3.0 * a2 * t) ** (2.0 / 3.0)
    # the osculating a oscillates about the mean drift by O(A2 / n^2) relative to it
    assert np.abs(a - want).max() < 1e-6 * (want[-1] - 1.0)
    slower = _run({"A2": -a2}, t)  # (an Apophis-like negative A2 shrinks the orbit)
    assert np.linalg.norm(slower.v[-1, 1]) > np.linalg.norm(traj.v[-1, 1])


def test_a_normal_acceleration_lifts_the_orbit_out_of_its_plane():
    a3 = 1e-6
    t = np.linspace(0.0, 2 * np.pi, 9)
    traj = _run({"A3": a3}, t)
    # first order in A3: the relative error is O(A3)
    np.testing.assert_allclose(traj.r[:, 1, 2], a3 * (1 - np.cos(t)), rtol=0,
                               atol=1e-6 * 2 * a3)


def test_the_comet_form_of_g_is_normalised_at_one_au():
    """Marsden et al. (1973) chose alpha so that g(1 au) = 1; the kernel applies
    A1 g(r) along r^ (here at 1 and 3 au, pure A1)."""
    p = [0, 1, 1, 1.0, 0.0, 0.0, *(COMET_G[k] for k in ("alpha", "r0", "m", "n", "k"))]
    for d, g in ((1.0, 1.0000000023534097), (3.0, 0.0016973748092543766)):
        r = np.array([[0.0, 0, 0], [0, d, 0]])
        acc = np.zeros((2, 3))
        nongrav(r, np.zeros((2, 3)), np.array([1.0, 0.0]), acc, np.array(p, dtype=float))
        np.testing.assert_allclose(acc[1], [0, g, 0], rtol=1e-15)
        assert not acc[0].any()  # (nothing acts back on the Sun)
    assert abs(1.0000000023534097 - 1.0) < 1e-8


def test_a_quantity_system_takes_accelerations_with_units():
    gm_sun = 1.32712440018e11 * u.km**3 / u.s**2
    s = System([Body("sun", gm_sun, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                Body("apophis", 0 * gm_sun, [0.92, 0, 0] * u.au, [0, 31.0, 0] * u.km / u.s)])
    kw = dict(method="radau15")
    plain = Simulation(s, **kw).integrate([0, 3650] * u.day)
    pushed = Simulation(s, effects=[{"name": "nongrav", "body": "apophis",
                                     "A2": "-2.9e-14 au/day2"}], **kw).integrate(
        [0, 3650] * u.day)
    shift = (pushed.r[-1, 1] - plain.r[-1, 1]).to_value(u.km)
    velocity = plain.v[-1, 1].to_value(u.km / u.s)
    ahead = shift @ velocity / np.linalg.norm(velocity)  # along-track, + along the motion
    # A negative A2 takes energy away: the semi-major axis shrinks (Gauss: da/dt = 2 A2
    # g / n), the mean motion rises, and the body runs AHEAD of the unpushed one by
    # -(3/2) A2 g t^2, the secular along-track drift of a constant transverse
    # acceleration (Hill / Clohessy-Wiltshire; Vallado 2013, sec. 6.8): about 103 km
    # after ten years (the radial part, da t, is 2 km)
    mu = s.gm[0].to_value(u.au**3 / u.day**2)
    r0, v0 = 0.92, (31.0 * u.km / u.s).to_value(u.au / u.day)
    a = 1.0 / (2.0 / r0 - v0**2 / mu)  # vis-viva: 0.9169 au (e = 0.0034), not 0.92
    e = abs(r0 / a - 1.0)  # (r0 is an apsis: v is perpendicular to r)
    want = -1.5 * (-2.9e-14) * a**-2 * 3650.0**2 * u.au.to(u.km)
    assert ahead > 0, ahead  # ahead along the velocity, not behind
    # the offset in mean longitude becomes a distance along the track through r and
    # the flight-path angle, which differ from the circle's by O(e) = 0.34%: 2 e
    # (measured: 0.17%)
    assert abs(ahead - want) < 2 * e * want, (ahead, want)


def test_the_variational_equations_follow_the_effect():
    """The STM (central differences of the kernel) against finite differences of
    whole runs, to the accuracy of a difference quotient."""
    eff = [{"name": "nongrav", "body": "rock", "A1": 1e-4, "A2": 3e-5, "A3": 2e-5}]
    times = [0.0, 5.0]
    traj = Simulation(_circle(), method="radau15", effects=eff, variational=True,
                      stm=True).integrate(times)
    h = 1e-7
    for k, axis in [(1, 0), (1, 1)]:  # d / dx0, d / dy0 of the rock
        runs = []
        for sign in (1, -1):
            s = _circle()
            r0 = np.array(s.r)
            r0[k, axis] += sign * h
            moved = System([Body(n, g, rr, vv) for n, g, rr, vv in
                            zip(s.names, s.gm, r0, s.v, strict=True)])
            runs.append(Simulation(moved, method="radau15", effects=eff).integrate(times))
        fd = (runs[0].r[-1, 1] - runs[1].r[-1, 1]) / (2 * h)
        np.testing.assert_allclose(traj.stm[-1, 6:9, 6 + axis], fd, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize(("effect", "match"), [
    ({}, r"expected `body`"),
    ({"body": "comet"}, r"comet"),
    ({"body": "sun"}, r"the centre 'sun' cannot be one of the bodies"),
    ({"body": ["rock", "rock"]}, r"each body once .* 'rock' twice"),
    ({"body": "rock", "A2": [1e-8, 2e-8]}, r"`A2` to be one value or 1"),
    ({"body": "rock", "r0": -1.0}, r"r0"),
    ({"body": "rock", "A1": float("nan")}, r"A1"),
])
def test_bad_parameters_are_refused_naming_them(effect, match):
    with pytest.raises(ValueError, match=match):
        Simulation(_circle(), method="radau15", effects=[{"name": "nongrav", **effect}])


def test_a_symplectic_map_refuses_it():
    with pytest.raises(ValueError, match=r"nongrav"):
        Simulation(_circle(), method="wh", dt=0.01,
                   effects=[{"name": "nongrav", "body": "rock", "A2": 1e-8}])


def test_each_body_takes_its_own_coefficients_and_form_of_g():
    """Two bodies in one entry, each with its own A2 and g: each moves as it does
    alone with its own (the lists are one per body)."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("rock", 0.0, [1.0, 0, 0], [0, 1.0, 0]),
                Body("comet", 0.0, [0, 2.0, 0.1], [-0.6, 0, 0.05])])
    both = {"name": "nongrav", "body": ["rock", "comet"], "A2": [1e-6, 3e-6],
            **{k: [1.0, v] for k, v in COMET_G.items()}}
    together = Simulation(s, method="radau15", effects=[both]).integrate(20.0)
    for j, name in enumerate(("rock", "comet")):
        alone = {"name": "nongrav", "body": name, "A2": both["A2"][j],
                 **{k: both[k][j] for k in COMET_G}}
        one = Simulation(s, method="radau15", effects=[alone]).integrate(20.0)
        k = s.names.index(name)
        # (the step control sees both pushes, so the steps may differ: 2e-15 here)
        np.testing.assert_allclose(together.r[-1, k], one.r[-1, k], rtol=0, atol=1e-13)
    with pytest.raises(ValueError, match=r"expected `m` within \[0, 100\] .*, got \[1.0, -2.0\] "
                                         r"\(body 1\)"):
        Simulation(s, method="radau15", effects=[{**both, "m": [1.0, -2.0]}])


def test_an_exponent_m_that_overflows_g_is_refused_by_name():
    """``m = 1e6`` made ``(r / r0)^-m`` overflow: ``System.accelerations`` returned NaN
    (infinity times the A1 of zero) and a run stopped saying only "the acceleration
    became non-finite (a collision?)".  ``m`` beyond 100 is refused with the
    parameters; a state where ``g`` still overflows (m = 100 at 5e-5 r0) is refused
    naming the effect, its index and the body."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("sat", 0.0, [0.5, 0, 0],
                                                            [0, 1.4, 0])])
    with pytest.raises(ValueError, match=r"^Effect 'nongrav': expected `m` within \[0, 100\] "
                                         r".* got 1000000.0 \(body 0\) \(effects\[0\]\)$"):
        s.accelerations([{"name": "nongrav", "body": "sat", "A2": 1e-9, "m": 1e6}])
    far = {"name": "nongrav", "body": "sat", "A2": 1e-9, "m": 100.0, "r0": 1e4}
    with pytest.raises(ValueError, match=r"^Effect 'nongrav' \(effects\[1\]\) at t = 0.0: the "
                                         r"acceleration of body 'sat' \(index 1\) is not "
                                         r"finite$"):
        s.accelerations(["newtonian", far])
    with pytest.raises(ValueError, match=r"^Effect 'nongrav' \(effects\[0\]\)"):
        Simulation(s, effects=[far])  # (refused as the run is set up, not at its step)
    assert np.isfinite(s.accelerations([{**far, "r0": 1.0}])).all()
