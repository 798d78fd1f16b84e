"""Backward runs with velocity-dependent effects (issue 35 item 4).

A backward leg integrates the time-reversed motion, d2r/ds2 = a(r, -dr/ds) with
s = -t, the effects evaluated at the true velocity (rhs.time_reversed); so a run
forwards and then backwards returns to its start within the method's error, for
every effect, and a backward run is the forward run read in reverse.
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, Simulation, System

SOLAR = ["sun", "mercury", "venus", "earth", "moon", "mars", "jupiter"]
VELOCITY_DEPENDENT = {
    "gr": [{"name": "gr", "c": "299792.458 km/s"}],
    "eih": ["eih"],
    "lense_thirring": ["lense_thirring"],
    "moon_figure": ["moon_figure"],
    "earth_tides": ["earth_tides"],
    "nongrav": [{"name": "nongrav", "body": "mars", "A1": "1e-10 au/day2",
                 "A2": "-3e-11 au/day2", "A3": "2e-11 au/day2"}],
}


@pytest.mark.parametrize("method", ["radau15", "dop853"])
@pytest.mark.parametrize("name", list(VELOCITY_DEPENDENT))
def test_forwards_then_backwards_returns_to_the_start(name, method):
    s = System.from_ephemeris(bodies=SOLAR)
    sim = Simulation(s, method=method, effects=VELOCITY_DEPENDENT[name],
                     tol=1e-12 if method == "dop853" else None)
    sim.integrate(200 * u.day)
    back = sim.integrate(0 * u.day)
    r0, v0 = s.r.to_value(u.au), s.v.to_value(u.au / u.day)
    # radau15 to its rounding over 200 days; dop853 to its tolerance (1e-12)
    limit = 1e-13 if method == "radau15" else 1e-9
    assert np.abs(back.r[-1].to_value(u.au) - r0).max() < limit
    assert np.abs(back.v[-1].to_value(u.au / u.day) - v0).max() < limit


def test_a_backward_run_is_the_forward_run_read_in_reverse():
    """With a transverse non-gravitational push (odd in the velocity: reversing the
    velocities, as the time-reversed run must not, would turn it around), the
    backward run from the forward run's end passes through the forward run's
    states at every output."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("rock", 0.0, [1.0, 0, 0.1], [0, 1.05, 0.02])])
    eff = [{"name": "nongrav", "body": "rock", "A2": 1e-3}]
    times = np.linspace(0.0, 30.0, 7)
    fwd = Simulation(s, method="radau15", effects=eff).integrate(times)
    end = System([Body(n, g, r, v) for n, g, r, v in
                  zip(fwd.names, s.gm, fwd.r[-1], fwd.v[-1], strict=True)])
    bwd = Simulation(end, method="radau15", effects=eff).integrate(times[::-1] - times[-1])
    assert np.abs(bwd.r[::-1] - fwd.r).max() < 1e-12
    assert np.abs(bwd.v[::-1] - fwd.v).max() < 1e-12
    # (the push matters: without it the orbit ends 0.1 away)
    bare = Simulation(s, method="radau15").integrate(times)
    assert np.abs(bare.r[-1] - fwd.r[-1]).max() > 0.05


def test_a_backward_leg_with_a_velocity_dependent_effect_saves_and_continues(tmp_path):
    """Saved in the middle of a backward leg, loaded (the time-reversed right-hand
    side rebuilt with its driver) and continued: the bits of the run never saved."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("rock", 0.0, [1.0, 0, 0.1], [0, 1.05, 0.02])])
    eff = [{"name": "nongrav", "body": "rock", "A1": 2e-4, "A2": 1e-3}]
    whole = Simulation(s, method="radau15", effects=eff)
    whole.integrate(10.0)
    end = whole.integrate([-5.0, -12.0])
    part = Simulation(s, method="radau15", effects=eff)
    part.integrate(10.0)
    part.integrate(-5.0)
    part.save(tmp_path / "mid.nc")
    again = Simulation.load(tmp_path / "mid.nc")
    rest = again.integrate(-12.0)
    assert np.array_equal(rest.r[-1], end.r[-1]) and np.array_equal(rest.v[-1], end.v[-1])
    assert again.steps == whole.steps
