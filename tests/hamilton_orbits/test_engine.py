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
