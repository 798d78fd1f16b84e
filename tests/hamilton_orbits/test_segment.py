"""segment: an archive's snapshots appended to one netCDF file."""

from __future__ import annotations

import numpy as np
import pytest
from test_archive import RADAU15_STEPPED

from hamilton_orbits import Archive, Simulation
from hamilton_orbits._netcdf3 import parse
from hamilton_orbits.segment import SegmentWriter


def _records(folder):
    """The records of every segment of ``folder``: the bytes after each header."""
    out = []
    for path in sorted(folder.glob("segment-*.nc")):
        data = path.read_bytes()
        out.append(data[parse(data).record_begin:])
    return out


@pytest.mark.parametrize("case", ["radau15", "radau15-events", "radau15-merge"])
def test_a_state_filled_straight_into_its_record_is_the_record_of_the_general_path(
        tmp_path, monkeypatch, case):
    """A snapshot of a propagation's state is filled straight into its record (one
    concatenation); the bytes are those the general fill writes, for a run with
    integer state arrays (the events' counts) and one whose layout changes (a merge
    begins a new segment)."""
    system, kw = RADAU15_STEPPED[case]
    times = np.linspace(0.0, 4.0, 5)[1:]
    direct, refill = SegmentWriter._append_state, SegmentWriter.refill
    taken, refilled = [], []

    def counted(self, snap, start):
        taken.append(direct(self, snap, start))
        return taken[-1]

    def counted_refill(self, *args):
        refilled.append(refill(self, *args))
        return refilled[-1]

    monkeypatch.setattr(SegmentWriter, "_append_state", counted)
    monkeypatch.setattr(SegmentWriter, "refill", counted_refill)
    Simulation(system(), archive=tmp_path / "direct", every_steps=1, **kw).integrate(times)
    if "events" in kw:  # (the straight fill at each snapshot after an output)
        assert sum(taken) >= 4
    else:  # (the refill between two pauses and after an output; the straight fill
        assert sum(taken) >= 1 and sum(refilled) > 10  # once, after the leg's start)
    monkeypatch.setattr(SegmentWriter, "_append_state", lambda self, snap, start: False)
    monkeypatch.setattr(SegmentWriter, "refill", lambda self, *args: False)
    Simulation(system(), archive=tmp_path / "general", every_steps=1, **kw).integrate(times)
    one, other = _records(tmp_path / "direct"), _records(tmp_path / "general")
    assert len(one) == len(other) >= 1 and one == other


def test_a_refill_writes_nothing_where_its_arrays_or_numbers_are_not_the_last_ones(
        tmp_path, monkeypatch):
    """``SegmentWriter.refill`` (the snapshot after the last, between two pauses of one
    compiled run, or after an output) refuses, writing nothing, an array of another
    shape or type than the one it replaces (or a writable ``active``, or another
    ``gm``), a step count or an integer number beyond 2**53, and a number missing;
    the archive then holds exactly its snapshots."""
    refill, refused = SegmentWriter.refill, []

    def probing(self, t, r, v, gm, active, state, scalars, steps, ints):
        count = self._file.count
        bad = [(t, r[:, :2].copy(), v, gm, active, state, scalars, steps, ints),
               (t, r, v.astype(np.float32), gm, active, state, scalars, steps, ints),
               (t, r, v, gm.copy(), active, state, scalars, steps, ints),
               (t, r, v, gm, active.copy(), state, scalars, steps, ints),
               (t, r, v, gm, active, [*state[:-1], state[-1][:-1].copy()], scalars, steps,
                ints),
               (t, r, v, gm, active, [*state[:-1], state[-1].astype(np.float32)], scalars,
                steps, ints),
               (t, r, v, gm, active, state, scalars, 2**53, ints),
               (t, r, v, gm, active, state, [*scalars[:-1], -(2**53)], steps, ints),
               (t, r, v, gm, active, state, scalars[:-1], steps, ints)]
        refused.extend(refill(self, *args) for args in bad)
        assert self._file.count == count
        return refill(self, t, r, v, gm, active, state, scalars, steps, ints)

    monkeypatch.setattr(SegmentWriter, "refill", probing)
    system, kw = RADAU15_STEPPED["radau15"]
    sim = Simulation(system(), archive=tmp_path, every_steps=2, **kw)
    sim.integrate(np.linspace(0.0, 2.0, 3))
    archive = Archive(tmp_path)
    assert len(refused) >= 9 and not any(refused)
    assert [s.steps for s in archive.snapshots] == list(range(0, sim.steps + 1, 2))
    assert archive.damaged == [] and archive.torn == []


def test_a_snapshot_at_a_scheduled_time_is_refilled_with_the_outputs_arrays(tmp_path,
                                                                           monkeypatch):
    """An ``every`` snapshot lands on an output of the compiled run, whose positions
    and velocities are other arrays (the rows of that output): the refill puts them
    in the places of the last ones and writes the bytes the general fill writes,
    for a run whose caller asks for outputs between the snapshots too (those
    snapshots carry rows: the general path)."""
    system, kw = RADAU15_STEPPED["radau15"]
    times = np.linspace(0.0, 4.0, 9)
    refill, refilled = SegmentWriter.refill, []

    def counted(self, *args):
        refilled.append(refill(self, *args))
        return refilled[-1]

    monkeypatch.setattr(SegmentWriter, "refill", counted)
    direct = Simulation(system(), archive=tmp_path / "direct", every=0.125, **kw)
    traj = direct.integrate(times)
    assert sum(refilled) >= 20  # (32 snapshots, 8 of them with rows)
    monkeypatch.setattr(SegmentWriter, "_append_state", lambda self, snap, start: False)
    monkeypatch.setattr(SegmentWriter, "refill", lambda self, *args: False)
    general = Simulation(system(), archive=tmp_path / "general", every=0.125, **kw)
    again = general.integrate(times)
    assert np.array_equal(traj.r, again.r) and np.array_equal(traj.v, again.v)
    one, other = _records(tmp_path / "direct"), _records(tmp_path / "general")
    assert len(one) == len(other) >= 1 and one == other
    archive = Archive(tmp_path / "direct")
    assert [s.t for s in archive.snapshots] == [0.125 * k for k in range(33)]
    assert archive.damaged == [] and archive.torn == []
