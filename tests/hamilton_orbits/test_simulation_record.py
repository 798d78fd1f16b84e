"""simulation_record: what a saved simulation holds, read back to the bit."""

from __future__ import annotations

import json

import astropy.units as u
import numpy as np
import pytest
from test_simulation_legs import _disc

from hamilton_orbits import Simulation, System
from hamilton_orbits._netcdf3 import RecordBuffer
from hamilton_orbits.restart import flatten
from hamilton_orbits.segment import read_segment
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


def _snapshots(folder):
    """Every snapshot of an archive's segments: its meta (the archive's path out)
    and arrays."""
    out = []
    for path in sorted(folder.glob("segment-*.nc")):
        for number, meta, arrays in read_segment(path).snapshots:
            meta = dict(meta, archive=dict(meta["archive"], path=None))
            out.append((number, meta, arrays))
    return out


@pytest.mark.parametrize("other", [
    dict(method="radau15"),  # (the same kind: the capture it left is taken)
    dict(method="radau15", bodies=4),  # (other shapes: it refuses, the graph walked)
    dict(method="wh", dt=0.05),  # (another driver: it refuses)
])
def test_an_archive_written_through_another_simulations_capture_is_the_one_walked(
        tmp_path, monkeypatch, other):
    """A simulation's first archived snapshot tries the capture the last simulation
    of its kind left (``_RECENT``) before walking its graph: the snapshots are those
    the walk gives, whether the capture fits or refuses."""
    from hamilton_orbits import simulation_record

    other = dict(other)
    bodies = other.pop("bodies", None)
    system = _disc() if bodies is None else System(list(_disc().bodies)[:bodies])
    Simulation(_disc(), method="radau15", archive=tmp_path / "a", every_steps=7).integrate(3.0)
    left = list(simulation_record._RECENT.values())  # (by that first simulation)
    written = {}
    for name in ("b", "c"):
        if name == "c":
            monkeypatch.setattr(simulation_record, "_RECENT", {})
        sim = Simulation(system, archive=tmp_path / name, every_steps=7, **other)
        sim.integrate(2.0)
        if name == "b":
            assert (sim._record_cache["capture"] in left) == (other == {"method": "radau15"}
                                                              and bodies is None)
        sim.integrate(4.0)
        written[name] = _snapshots(tmp_path / name)
    assert len(written["b"]) == len(written["c"]) > 3
    for (nb, mb, ab), (nc, mc, ac) in zip(written["b"], written["c"], strict=True):
        assert nb == nc and mb == mc and ab.keys() == ac.keys()
        assert all(ab[k].dtype == ac[k].dtype and ab[k].shape == ac[k].shape
                   and ab[k].tobytes() == ac[k].tobytes() for k in ab)  # (to the bit)


def test_arrays_that_are_not_floats_come_back_as_they_were():
    """``to_json`` kept any array as a list and ``from_json`` read it back as float64:
    an event's ``bodies`` given as a NumPy array of names (a table's column) made an
    archive that was written, listed as whole, and never loaded ("could not convert
    string to float: 'p1'").  A non-float array now keeps its dtype; a float64 one is
    written as before (and an old file's array, without a dtype, read as float64)."""
    from hamilton_orbits.simulation_record import from_json, to_json

    for a in (np.array(["p1", "jupiter"]), np.arange(3), np.array([True, False]),
              np.array([0.1, np.pi])):
        back = from_json(json.loads(json.dumps(to_json({"x": a}))))["x"]
        assert back.dtype == a.dtype and back.tolist() == a.tolist()
    assert to_json(np.array([0.5])) == {"__array__": [0.5]}
    assert from_json({"__array__": [1, 2]}).dtype == np.float64


def test_an_array_of_names_written_without_its_dtype_reads_as_names():
    """Archives written before the arrays kept their dtype hold an event's names as
    ``{"__array__": ["p1", "p2"]}``: read as floats they failed ("could not convert
    string to float"); an array that is not numbers is read as it was written."""
    from hamilton_orbits.simulation_record import from_json

    assert from_json({"__array__": ["p1", "p2"]}).tolist() == ["p1", "p2"]
    assert from_json({"__array__": [1, 2]}).dtype == np.float64
