"""engine: the float-level Propagation and run, and the input they refuse with a name."""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits import engine
from hamilton_orbits.integrators import Radau15
from hamilton_orbits.rhs import newtonian_rhs

R0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
V0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
GM = np.array([1.0, 0.0])


def test_a_list_of_times_is_taken_and_an_end_time_alone_is_refused():
    out = engine.run(R0, V0, GM, [0.0, np.pi, 2 * np.pi], newtonian_rhs(), "radau15")
    assert out.complete and out.t.tolist() == [0.0, np.pi, 2 * np.pi]
    # a circular orbit of period 2 pi: back at the start to the method's accuracy
    np.testing.assert_allclose(out.r[-1], R0, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match=r"Expected `t_out` to be a 1-d array of output times"):
        engine.run(R0, V0, GM, 1.0, newtonian_rhs(), "radau15")


@pytest.mark.parametrize(("kw", "match"), [
    (dict(rhs=None), r"Expected `rhs` to be a compiled right-hand side"),
    (dict(method="rk4"), r"Unknown `method` 'rk4'"),
    (dict(t_out=[0.0, np.nan]), r"Expected `t_out` to be finite, got nan at index 1"),
    (dict(r0=np.zeros((0, 3)), v0=np.zeros((0, 3)), gm=np.zeros(0), method="wh", dt=0.1),
     r"wh needs a central body with `gm` > 0; there are no bodies"),
])
def test_bad_engine_input_is_named(kw, match):
    args = dict(r0=R0, v0=V0, gm=GM, t_out=[0.0, 1.0], rhs=newtonian_rhs(), method="radau15")
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        engine.run(**args)


def test_a_propagation_continues_and_counts_its_steps():
    legs = engine.Propagation(R0, V0, GM, 0.0, newtonian_rhs(), Radau15(), dt=0.1)
    first = legs.advance(np.array([0.0, 1.0]))
    second = legs.advance(np.array([1.0, 2.0]))
    once = engine.run(R0, V0, GM, [0.0, 1.0, 2.0], newtonian_rhs(), "radau15", dt=0.1)
    assert first.steps + second.steps == legs.steps == once.steps == 20
    assert np.array_equal(second.r[-1], once.r[-1]) and legs.t == 2.0


# Issue 32, classes 12 and 16: two massive bodies at one point ran dop853 for
# minutes (scipy turned the NaN derivative into a NaN first step and looped on it).

@pytest.mark.parametrize("method", ["radau15", "wh", "leapfrog", "dop853"])
def test_two_bodies_at_one_point_are_refused_by_name(method):
    r0 = np.array([[0.0, 0, 0], [0.5, 0, 0], [0.5, 0, 0]])
    v0 = np.array([[0.0, 0, 0], [0, 1.0, 0], [0, 1.2, 0]])
    with pytest.raises(ValueError, match=r"Bodies at indices 1 and 2 of `r0` are at one "
                                         r"position \[0.5, 0.0, 0.0\]"):
        engine.run(r0, v0, np.array([1.0, 1e-3, 1e-3]), [0.0, 1.0], newtonian_rhs(), method,
                   dt=0.01)
    # a test particle on a massive body: its acceleration is infinite as well
    with pytest.raises(ValueError, match=r"Bodies at indices 0 and 1 of `r0`"):
        engine.run(R0[[0, 0]], V0, GM, [0.0, 1.0], newtonian_rhs(), method, dt=0.01)
    # two test particles at one point pull on nothing: allowed
    out = engine.run(np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]]), np.array(
        [[0.0, 0, 0], [0, 1.0, 0], [0, 1.0, 0]]), np.array([1.0, 0.0, 0.0]), [0.0, 1.0],
        newtonian_rhs(), method, dt=0.01)
    np.testing.assert_allclose(out.r[-1, 1], out.r[-1, 2], rtol=0, atol=1e-15)


def test_dop853_stops_at_a_non_finite_acceleration_instead_of_looping():
    """Past the checks (a Propagation made directly), two bodies at one point give
    dop853 a non-finite acceleration: a ConvergenceError at once, naming the time."""
    from hamilton_orbits.integrators import DOP853
    from hamilton_orbits.validation import ConvergenceError

    prop = engine.Propagation(np.zeros((2, 3)), V0, np.array([1.0, 1.0]), 0.0,
                              newtonian_rhs(), DOP853())
    with pytest.raises(ConvergenceError, match=r"dop853 stopped at t = 0.0: the acceleration "
                                               r"became non-finite"):
        prop.advance(np.array([0.0, 1.0]))


@pytest.mark.parametrize("kw", [dict(method="radau15"), dict(method="wh", dt=0.01),
                                dict(method="leapfrog", dt=0.01), dict(method="dop853")],
                         ids=["radau15", "wh", "leapfrog", "dop853"])
def test_a_backward_legs_first_row_is_the_state_it_starts_from(kw):
    """The first output of a backward leg is the state it starts from, velocity
    included (it came out negated: the driver's reversed velocities are turned back
    row by row, and the first row was not reversed)."""
    from hamilton_orbits import Body, Simulation, System

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("rock", 0.0, [1.0, 0, 0.1], [0, 1.05, 0.02])])
    back = Simulation(s, **kw).integrate([0.0, -1.0])
    assert np.array_equal(back.v[0], np.asarray(s.v)) and np.array_equal(back.r[0],
                                                                         np.asarray(s.r))
    assert np.abs(back.angular_momentum_error).max() < 1e-12
    sim = Simulation(s, **kw)
    there = sim.integrate(1.0)
    again = sim.integrate(0.0)
    assert np.array_equal(again.v[0], there.v[-1]) and np.array_equal(again.r[0],
                                                                       there.r[-1])


@pytest.mark.parametrize(("method", "kind", "pattern"), [
    ("radau15", "ConvergenceError", r"radau15 stopped at t = -0.90689968\d* before t_out\[1\] "
                                    r"= -1.0: the step underflowed \(dt = 7"),
    ("dop853", "ValueError", r"dop853 failed at t = -0.90689968\d*: the step underflowed"),
])
def test_a_backward_run_names_its_own_times_when_it_fails(method, kind, pattern):
    """A head-on fall (GM 1 and 0.5 at rest 1 apart: they meet at |t| = pi/2
    sqrt(1/3) = 0.90690) integrated to t = -1 failed with "stopped at t = 0.9069
    before t_out[1] = 1.0": the driver's reversed time s = -t.  The message now
    names the run's times."""
    from hamilton_orbits import Body, System, integrate

    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.5, [1, 0, 0], [0, 0, 0])])
    with pytest.raises(Exception, match=pattern) as info:
        integrate(s, -1.0, method=method)
    assert type(info.value).__name__ == kind


def test_a_backward_run_s_messages_are_turned_back_and_a_callback_s_left_alone():
    """The budget's refusal of a backward run read "reached t = -3.18 of 100.0" (or,
    from dop853, ``np.float64(15.05)`` unconverted); and a callback's own ValueError
    mentioning a time was rewritten as if the driver's, its traceback cut.  The
    driver's messages are turned back whole; a callback's error is its own."""
    from hamilton_orbits import Body, Simulation, System, integrate
    from hamilton_orbits.validation import ConvergenceError

    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 1e-3, [1, 0, 0], [0, 1, 0])])
    for method in ("radau15", "dop853"):
        with pytest.raises(ConvergenceError, match=rf"{method} reached t = -\d+\.\d+ of -100.0 "
                                                   r"in \d+ steps"):
            integrate(s, -100.0, method=method, max_steps=20)

    def check(i, steps):
        raise ValueError("my check failed at t = 2.0")

    with pytest.raises(ValueError, match=r"^my check failed at t = 2.0$") as info:
        Simulation(s).integrate(-1.0, on_output=check)
    assert info.traceback[-1].name == "check"
