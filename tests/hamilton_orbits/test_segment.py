"""segment: an archive's snapshots appended to one netCDF file."""

from __future__ import annotations

import numpy as np
import pytest
from test_archive import RADAU15_STEPPED

from hamilton_orbits import Simulation
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
    direct = SegmentWriter._append_state
    taken = []

    def counted(self, snap, start):
        taken.append(direct(self, snap, start))
        return taken[-1]

    monkeypatch.setattr(SegmentWriter, "_append_state", counted)
    Simulation(system(), archive=tmp_path / "direct", every_steps=1, **kw).integrate(times)
    assert sum(taken) > 10  # (the straight fill was taken)
    monkeypatch.setattr(SegmentWriter, "_append_state", lambda self, snap, start: False)
    Simulation(system(), archive=tmp_path / "general", every_steps=1, **kw).integrate(times)
    one, other = _records(tmp_path / "direct"), _records(tmp_path / "general")
    assert len(one) == len(other) >= 1 and one == other
