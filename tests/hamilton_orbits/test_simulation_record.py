"""simulation_record: what a saved simulation holds, read back to the bit."""

from __future__ import annotations

import json

import astropy.units as u
import numpy as np
import pytest
from test_simulation_legs import _disc

from hamilton_orbits import Simulation
from hamilton_orbits._netcdf3 import RecordBuffer
from hamilton_orbits.restart import flatten
from hamilton_orbits.simulation_record import (
    from_json,
    pack,
    state_values,
    to_json,
    unpack,
)
from hamilton_orbits.snapshot import SnapshotError


def test_the_json_form_keeps_quantities_arrays_and_every_bit():
    rng = np.random.default_rng(3)
    x = rng.normal(size=5) * 10.0 ** rng.integers(-300, 300, size=5)
    value = {"c": x[0] * u.km / u.s, "pole": x[:3] * u.deg, "a": x, "n": np.int64(7),
             "nested": [{"g": x[4] * u.au**3 / u.day**2}, None, "sun", True]}
    back = from_json(json.loads(json.dumps(to_json(value))))
    assert back["c"].unit == u.km / u.s and back["c"].value == x[0]
    assert np.array_equal(back["pole"].value, x[:3]) and back["pole"].unit == u.deg
    assert np.array_equal(back["a"], x) and back["n"] == 7 and type(back["n"]) is int
    assert back["nested"][0]["g"].value == x[4] and back["nested"][1:] == [None, "sun", True]


def test_packed_arrays_come_back_with_their_types_and_shapes():
    rng = np.random.default_rng(5)
    arrays = [rng.normal(size=(3, 2)), np.arange(-4, 5, dtype=np.int64).reshape(3, 3),
              np.array([True, False, True]), np.zeros((0, 4)), np.float64(2.5) * np.ones(())]
    flat, index = pack(arrays)
    again = unpack(flat, index)
    assert all(a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)
               for a, b in zip(arrays, again, strict=True))
    assert np.array_equal(pack(arrays, index)[0], flat)  # (the index known: the same vector)


def test_integers_a_float64_cannot_hold_are_refused():
    for a in (np.array([2**53], np.int64), np.full(100, -(2**60), np.int64)):
        with pytest.raises(SnapshotError, match=r"integers beyond 2\*\*53"):
            pack([np.zeros(2), a])


def test_a_record_of_parts_is_the_record_of_the_packed_state():
    """An archive's record takes the state as parts (never packed on its own): its
    bytes are those of the packed state."""
    sim = Simulation(_disc(), method="radau15",
                     events=[{"name": "close_encounter", "distance": 2.0}])
    sim.integrate(3.0)
    prop = sim._prop
    prop.events.drain()
    numbers: list = []
    _, state = flatten(prop, numbers)
    whole = state_values(prop, state, None, numbers)
    index = whole.pop("state_arrays")
    ints = [k for k, a in enumerate(state) if a.dtype.kind in "iu"]
    assert ints  # (the events' counts)
    parts = state_values(prop, state, index, numbers, ints)
    assert parts.keys() == whole.keys()
    names = list(whole)
    buf = RecordBuffer([np.zeros(np.shape(whole[k]), np.int8 if whole[k].dtype == bool
                                 else np.float64) for k in names])
    first = bytes(buf.fill([whole[k] for k in names]))
    assert bytes(buf.fill([parts[k] for k in names])) == first
