"""segment: an archive's snapshots appended to one netCDF file."""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from pathlib import Path

import hypothesis
import numpy as np
import pytest
from hypothesis import strategies as st
from test_archive import RADAU15_STEPPED, flipped_bytes
from test_simulation_legs import _disc, _same

from hamilton_orbits import Archive, Simulation, segment
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
    monkeypatch.setattr(segment, "COMPILED_WRITES", False)  # (every record by Python: the kernel
    # writes none, test_records_written_by_the_kernel_are_those_of_the_python_path)
    direct, refill = SegmentWriter._append_state, SegmentWriter.refill
    taken, refilled = [], []

    def counted(self, *args):
        taken.append(direct(self, *args))
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
    monkeypatch.setattr(SegmentWriter, "_append_state", lambda self, *args: False)
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
    snapshots carry rows: filled straight, their rows' span with them)."""
    system, kw = RADAU15_STEPPED["radau15"]
    times = np.linspace(0.0, 4.0, 9)
    refill, refilled = SegmentWriter.refill, []
    monkeypatch.setattr(segment, "COMPILED_WRITES", False)  # (every record by Python: the
    # kernel writes none, test_records_written_by_the_kernel_are_those_of_the_python_path)

    def counted(self, *args):
        refilled.append(refill(self, *args))
        return refilled[-1]

    monkeypatch.setattr(SegmentWriter, "refill", counted)
    direct = Simulation(system(), archive=tmp_path / "direct", every=0.125, **kw)
    traj = direct.integrate(times)
    assert sum(refilled) >= 20  # (32 snapshots, 8 of them with rows)
    monkeypatch.setattr(SegmentWriter, "_append_state", lambda self, *args: False)
    monkeypatch.setattr(SegmentWriter, "refill", lambda self, *args: False)
    general = Simulation(system(), archive=tmp_path / "general", every=0.125, **kw)
    again = general.integrate(times)
    assert np.array_equal(traj.r, again.r) and np.array_equal(traj.v, again.v)
    one, other = _records(tmp_path / "direct"), _records(tmp_path / "general")
    assert len(one) == len(other) >= 1 and one == other
    archive = Archive(tmp_path / "direct")
    assert [s.t for s in archive.snapshots] == [0.125 * k for k in range(33)]
    assert archive.damaged == [] and archive.torn == []


def _same_snapshot(a, b):
    """Two ``(number, meta, arrays)`` of a segment read back, bit for bit."""
    return (a[0] == b[0] and a[1] == b[1] and a[2].keys() == b[2].keys()
            and all(np.array_equal(x, b[2][k], equal_nan=True) for k, x in a[2].items()))


def _long_segment(tmp_path, every=0.2):
    """A wh run of the sun and the earth archived ``every`` 0.2 through outputs at 0,
    3.1 and 6: one segment of 31 snapshots, the first record the leg's times, its
    rows file holding the row at 3.1 (the rows at 0 and 6, snapshot times, are
    their records' own states, format 4)."""
    from hamilton_orbits import Body, System

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
    Simulation(s, method="wh", dt=0.05, archive=tmp_path, every=every).integrate(
        np.array([0.0, 3.1, 6.0]))
    path, = tmp_path.glob("segment-*.nc")
    return path


def test_the_last_snapshot_and_any_one_read_alone_are_those_of_the_whole_segment(
        tmp_path, monkeypatch):
    """``read_segment(last=True)`` and ``read_segment(number=k)`` read the header, the
    fixed variables and one record with its own rows: the same bits as the whole
    segment read, in O(snapshot) bytes (every ``pread`` counted)."""
    import os

    from hamilton_orbits.segment import read_segment

    path = _long_segment(tmp_path)
    whole = read_segment(path).snapshots
    assert len(whole) == 31 and "leg_times" in whole[0][2]
    record = parse(path.read_bytes()).record_size
    read = []
    pread = os.pread
    monkeypatch.setattr(os, "pread", lambda fd, n, at: read.append(n) or pread(fd, n, at))
    last = read_segment(path, last=True)
    assert len(last.snapshots) == 1 and _same_snapshot(last.snapshots[0], whole[-1])
    assert not last.damaged and not last.torn
    # its header and fixed part (64 KiB asked, the file being shorter), one record,
    # whose one row (the output at 6, a snapshot time) is its own state (format 4)
    assert len(read) == 2 and read[1] == record
    assert last.snapshots[0][2]["out_t"].tolist() == [6.0]
    # the snapshot after the output at 3.1 (not a snapshot time): its row read from
    # the rows file, its header and that one row
    k, = (k for k, (_, _, a) in enumerate(whole) if a["out_t"].tolist() == [3.1])
    read.clear()
    one = read_segment(path, number=k)
    assert _same_snapshot(one.snapshots[0], whole[k]) and whole[k][1]["t"] > 3.1
    assert len(read) == 4 and read[1] == record
    for k in (0, 7, 30):
        one = read_segment(path, number=k).snapshots
        assert len(one) == 1 and _same_snapshot(one[0], whole[k])
    assert read_segment(path, number=31).snapshots == []


def test_a_flipped_byte_is_never_read_as_data_by_the_last_or_one_snapshot_read_alone(
        tmp_path):
    """The bytes of the segment and of its rows file flipped in turn (each one before
    the shared JSON text, the text's every 16th, every 5th after it): the
    snapshot read alone is the original one's bits or none, the last read is never
    older than the whole segment's last, and a last snapshot passed over is listed
    as damaged or torn."""
    from hamilton_orbits.segment import read_segment
    from hamilton_orbits.snapshot import SnapshotError

    path = _long_segment(tmp_path, every=1.0)  # (7 snapshots: the flips are many)
    rows = path.with_name(path.name.replace("segment", "rows"))
    original = {n: (n, m, a) for n, m, a in read_segment(path).snapshots}
    for file in (path, rows):
        for i in flipped_bytes(file, every=5):
            try:
                full = read_segment(path)
            except SnapshotError:
                with pytest.raises(SnapshotError):
                    read_segment(path, last=True)
                continue
            last = read_segment(path, last=True)
            if full.snapshots:
                assert last.snapshots and _same_snapshot(
                    last.snapshots[0], original[last.snapshots[0][0]]), (file.name, i)
                assert last.snapshots[0][0] >= full.snapshots[-1][0], (file.name, i)
                if last.snapshots[0][0] < 6:  # (a count lowered: the records after it torn)
                    assert last.damaged or last.torn, (file.name, i)
            for k in (0, 3, 6):
                one = read_segment(path, number=k).snapshots
                assert one == [] or _same_snapshot(one[0], original[k]), (file.name, i, k)


def test_a_row_that_is_its_snapshots_own_state_is_kept_as_that_state(tmp_path):
    """Format 4: a snapshot's one row that is its own ``t``, ``r``, ``v`` bit for bit
    is not written to the rows file (its record's ``rows`` are ``(-1, -1)``) and is
    read back as those values; a row that differs in one bit (a time of -0.0 at a
    state of 0.0, a position one ulp off) or that carries more (a second row) is
    written and read from the rows file."""
    from scipy.io import netcdf_file

    from hamilton_orbits.segment import OWN_ROW, read_segment

    r = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    snap = {"t": np.float64(0.0), "steps": 0, "r": r, "v": v, "active": np.ones(2, bool)}

    def rows(t, dr=0.0):
        return {"out_t": np.array([t]), "out_r": (r + dr)[None], "out_v": v[None]}

    cases = [("own", rows(0.0)), ("signed", rows(-0.0)),
             ("moved", rows(0.0, np.array([[0.0] * 3, [np.spacing(1.0), 0.0, 0.0]]))),
             ("two", {k: np.concatenate([a, a]) for k, a in rows(0.0).items()})]
    for name, given in cases:
        folder = tmp_path / name
        folder.mkdir()
        seg = SegmentWriter(folder, 0, {"kind": "demo"}, {}, snap, {"r": ("body", "xyz")})
        seg.append(snap, given)
        seg.close()
        own = name == "own"
        assert (folder / "rows-000000.nc").exists() == (not own), name
        with netcdf_file(seg.path, "r", mmap=False) as nc:  # (as any reader sees it)
            span = nc.variables["rows"][0].tolist()
        assert span == ([OWN_ROW, OWN_ROW] if own else [0, len(given["out_t"])]), name
        (_, _, arrays), = read_segment(seg.path).snapshots
        for k in ("t", "r", "v"):
            assert arrays[f"out_{k}"].tobytes() == given[f"out_{k}"].tobytes(), (name, k)


def _kernel_written(monkeypatch):
    """A list whose first item counts the records stepping kernels append."""
    from hamilton_orbits._kernels.records import P_WRITTEN
    from hamilton_orbits.checkpoint import ArchiveWriter

    count, took = [0], ArchiveWriter.compiled_wrote

    def counting(self, plan, last_steps):
        count[0] += int(plan[P_WRITTEN])
        return took(self, plan, last_steps)

    monkeypatch.setattr(ArchiveWriter, "compiled_wrote", counting)
    return count


def _archived_runs(tmp_path, name, compiled, kw, calls, monkeypatch, schedule=None):
    """The files (name -> bytes) of an archive (``every_steps=3``, or ``schedule``)
    written by ``calls`` (end times; a ``"load"`` between two: the run continued by
    a simulation loaded from its archive), in one folder path whichever way it is
    written (the path is in the segments' headers), the trajectories, and the
    records the kernel appended."""
    count = _kernel_written(monkeypatch)
    system, options = RADAU15_STEPPED[kw]
    folder = tmp_path / "run"
    files, trajs = _written(folder, compiled, system(), options,
                            schedule or {"every_steps": 3}, calls)
    folder.rename(tmp_path / name)
    return files, trajs, count[0]


@pytest.mark.parametrize(("kw", "calls"), [
    ("radau15", [6.0]),
    ("radau15", [np.linspace(0.0, 12.0, 4)]),  # (outputs between the snapshots)
    ("radau15", [4.0, 10.0, "load", 16.0]),  # (legs, and a run loaded from its archive)
    ("radau15-effects", [8.0]),
    ("radau15-fixed", [1.0, 3.0]),
])
def test_records_written_by_the_kernel_are_those_of_the_python_path(tmp_path, monkeypatch,
                                                                    kw, calls):
    """radau15 appends most ``every_steps`` snapshots from inside its compiled call
    (after two written by Python in a row); the archive's files are, byte for byte,
    those of the same run whose every snapshot Python writes, as are the run's
    outputs, with outputs, legs, a loaded run, effects and fixed steps."""
    ours, trajs, kernel = _archived_runs(tmp_path, "kernel", True, kw, calls, monkeypatch)
    theirs, ref, none = _archived_runs(tmp_path, "python", False, kw, calls, monkeypatch)
    assert ours.keys() == theirs.keys() and ours == theirs
    assert all(_same(a.r, b.r) and _same(a.v, b.v) for a, b in zip(trajs, ref, strict=True))
    total = len(Archive(tmp_path / "kernel"))
    assert none == 0 and kernel >= total // 2, (kernel, total)


@pytest.mark.parametrize("schedule", [{"every_steps": 3}, {"every": 0.25}])
def test_a_new_segment_s_first_record_is_filled_from_the_run_s_own_arrays(tmp_path,
                                                                         monkeypatch,
                                                                         schedule):
    """The first snapshot of a new segment (a run's first call, at its start) is
    filled straight from the propagation's own arrays, as the snapshots after it
    are: the next two are refills of it, after which the kernel appends the rest
    but the one at the call's end.  Every record Python writes is so filled (the
    start was filled by the general path, the snapshot after it straight, then
    the two refills: a record more by Python); the files are those of the run
    whose every record Python writes."""
    direct, refill = SegmentWriter._append_state, SegmentWriter.refill
    calls = []

    def counted(self, snap, *args):
        calls.append(("straight", type(snap["state"]).__name__, direct(self, snap, *args)))
        return calls[-1][-1]

    def counted_refill(self, *args):
        calls.append(("refill", "", refill(self, *args)))
        return calls[-1][-1]

    monkeypatch.setattr(SegmentWriter, "_append_state", counted)
    monkeypatch.setattr(SegmentWriter, "refill", counted_refill)
    files, _, kernel = _archived_runs(tmp_path, "kernel", True, "radau15", [6.0], monkeypatch,
                                      schedule)
    total = len(Archive(tmp_path / "kernel"))
    assert calls[:3] == [("straight", "Parts", True), ("refill", "", True),
                         ("refill", "", True)], calls
    assert all(ok for *_, ok in calls) and total - kernel == len(calls) == 4, (calls, total,
                                                                                kernel)
    theirs, _, _ = _archived_runs(tmp_path, "python", False, "radau15", [6.0], monkeypatch,
                                  schedule)
    assert files == theirs


def test_no_plan_is_made_for_a_snapshot_the_call_ends_before(tmp_path, monkeypatch):
    """A plan for the kernel to write the next snapshot costs about 0.3 ms: none is
    made after the second pause of a run that ends before its next snapshot (at
    the step size then), which is a short run's case; a run long enough gets one."""
    from hamilton_orbits.checkpoint import ArchiveWriter

    made, plan = [], ArchiveWriter.compiled_plan

    def counted(self, *args, **kwargs):
        out = plan(self, *args, **kwargs)
        made.append(out is not None)
        return out

    monkeypatch.setattr(ArchiveWriter, "compiled_plan", counted)
    system, kw = RADAU15_STEPPED["radau15"]
    probe = Simulation(system(), **kw)
    probe.integrate(6.0)
    every = int(probe.steps * 0.4)  # (snapshots at 0.4 and 0.8 of its steps: the next
    # beyond its end)
    Simulation(system(), archive=tmp_path / "short", every_steps=every, **kw).integrate(6.0)
    assert len(Archive(tmp_path / "short")) == 3 and not any(made), made
    Simulation(system(), archive=tmp_path / "long", every_steps=every // 10,
               **kw).integrate(6.0)
    assert any(made)


EVERY = {"every": 0.25}


@pytest.mark.parametrize(("kw", "calls", "slice_steps", "every"), [
    ("radau15", [6.0], None, EVERY),
    ("radau15", [np.linspace(0.0, 12.0, 4)], None, EVERY),  # (outputs between the snapshots)
    ("radau15", [np.array([0.0, 0.55, 4.0, 4.35, 6.0])], None, EVERY),  # (and on them)
    ("radau15", [4.0, 10.0, "load", 16.0], None, EVERY),  # (legs, a run loaded from its archive)
    ("radau15", [6.0], 2, EVERY),  # (a compiled call of 2 steps at most: landings at its end)
    ("radau15-effects", [8.0], None, EVERY),
    ("radau15-fixed", [1.0, 3.0], None, {"every": 0.05}),  # (snapshots on the steps)
    # (landed on by fixed steps: a step often ends within rounding of a snapshot's time,
    # 0.1 * k, which is then reached without a step, as a call ending there reaches it)
    ("radau15-fixed", [3.0], None, {"every": 0.1, "exact_times": True}),
])
def test_snapshots_the_kernel_lands_on_are_those_of_the_python_path(tmp_path, monkeypatch,
                                                                     kw, calls, slice_steps,
                                                                     every):
    """radau15 lands on most ``every`` snapshot times and appends their snapshots
    from inside its compiled call (after two written by Python in a row between the
    caller's outputs); the archive's files are, byte for byte, those of the same run
    whose every snapshot Python writes at a call of its own to each snapshot time, as
    are the run's outputs, with outputs, legs, a loaded run, effects, fixed steps and
    calls cut short by their budget of steps."""
    from hamilton_orbits.integrators import radau15

    if slice_steps is not None:
        monkeypatch.setattr(radau15, "SLICE", slice_steps)
    ours, trajs, kernel = _archived_runs(tmp_path, "kernel", True, kw, calls, monkeypatch,
                                         every)
    theirs, ref, none = _archived_runs(tmp_path, "python", False, kw, calls, monkeypatch,
                                       every)
    assert ours.keys() == theirs.keys() and ours == theirs
    assert all(_same(a.r, b.r) and _same(a.v, b.v) and _same(a.t, b.t)
               for a, b in zip(trajs, ref, strict=True))
    total = len(Archive(tmp_path / "kernel"))
    # (Python writes at most five in each interval between two outputs: the one at
    # its start, three in a row, the last of which makes the plan, and the one at its end)
    intervals = sum(np.size(t) - (np.size(t) > 1) for t in calls if not isinstance(t, str))
    assert none == 0 and total - kernel <= 5 * intervals, (kernel, total)


def _random_archived_run(rng: np.random.Generator) -> tuple[dict, dict, list, int | None,
                                                            int | None]:
    """A random archived radau15 run: its options, schedule, calls (end times, output
    times, ``"load"``: continued by a simulation loaded from the archive), step
    budget and compiled slice (None: the defaults)."""
    kw = {"method": "radau15"}
    if rng.random() < 0.3:
        kw["dt"] = float(rng.choice([0.01, 0.02, 0.037]))
    elif rng.random() < 0.3:
        kw["tol"] = float(10 ** rng.uniform(-13, -8))
    if rng.random() < 0.3:
        kw["effects"] = [{"name": "gr", "c": 100.0}, {"name": "j2", "body": "star"}]
    if rng.random() < 0.5:
        schedule = {"every_steps": int(rng.choice([1, 2, 3, 17, 60]))}
    else:
        schedule = {"every": float(rng.choice([0.013, 0.05, 0.25, 0.7]))}
        if "dt" in kw:
            schedule["exact_times"] = bool(rng.random() < 0.5)
    calls, t = [], 0.0
    for _ in range(int(rng.integers(1, 4))):
        span, kind = float(rng.uniform(0.2, 4.0)), rng.random()
        if kind < 0.3 and calls:
            calls.append("load")
        elif kind < 0.6:
            times = np.sort(rng.uniform(t, t + span, int(rng.integers(2, 7))))
            if "every" in schedule:  # (some on the snapshot times)
                every = schedule["every"]
                times = np.union1d(times, every * (np.floor(t / every) + np.arange(1, 3)))
            calls.append(np.concatenate([[t], times[times > t]]))
            t = float(calls[-1][-1])
        else:
            t += span
            calls.append(t)
    if isinstance(calls[-1], str):  # (a run loaded last goes on)
        calls.append(t + 1.0)
    budget = int(rng.integers(5, 400)) if rng.random() < 0.15 else None
    slice_steps = int(rng.choice([1, 2, 7, 50])) if rng.random() < 0.3 else None
    return kw, schedule, calls, budget, slice_steps


def _written(folder: Path, compiled: bool, system, kw, schedule, calls, budget=None,
             slice_steps=None) -> tuple[dict[str, bytes], list]:
    """The archive's files and the outputs (each call's trajectory, or a refused
    call's message) of a run of ``calls`` (end times or output times; a ``"load"``:
    the run continued by a simulation loaded from its archive), with a step
    ``budget`` and a compiled ``slice_steps`` or not (:func:`_random_archived_run`),
    the kernel appending records or not."""
    from hamilton_orbits.integrators import radau15
    from hamilton_orbits.validation import ConvergenceError

    before = radau15.SLICE
    segment.COMPILED_WRITES = compiled
    radau15.SLICE = slice_steps or before
    outputs: list = []
    try:
        options = dict(kw, **schedule, **({} if budget is None else {"max_steps": budget}))
        sim = Simulation(system, archive=folder, **options)
        for t in calls:
            if isinstance(t, str):
                sim = Simulation.load(folder)
                continue
            try:
                traj = sim.integrate(t)
            except ConvergenceError as exc:  # (the budget: continued from the archive)
                outputs.append(str(exc))
                sim = Simulation.load(folder)
                continue
            outputs.append(traj)
    finally:
        segment.COMPILED_WRITES, radau15.SLICE = True, before
    files = {p.name: p.read_bytes() for p in folder.iterdir() if not p.name.startswith(".")}
    return files, outputs


@hypothesis.settings(max_examples=40, deadline=None)  # (about 3 s; 200 in 11 s found nothing)
@hypothesis.given(seed=st.integers(0, 2**32 - 1), bodies=st.integers(2, 6))
def test_random_runs_archived_by_the_kernel_are_those_python_archives(seed, bodies):
    """Random radau15 runs, adaptive or of fixed steps, with effects or not, of
    either schedule, of end times, output times (some on the snapshot times), runs
    loaded from their archive, a step budget met and compiled calls cut short: the
    archive's files are byte for byte those of the same run whose every record
    Python writes, and the outputs the same bits."""
    run = _random_archived_run(np.random.default_rng(seed))
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for compiled in (True, False):  # (in one folder: its path is in the headers)
            out.append(_written(Path(tmp) / "run", compiled, _disc(bodies, seed % 1000), *run))
            shutil.rmtree(Path(tmp) / "run")
    ours, theirs = ([x if isinstance(x, str) else [np.asarray(a).tobytes()
                                                   for a in (x.t, x.r, x.v)] for x in outputs]
                    for _, outputs in out)
    assert ours == theirs
    assert out[0][0] == out[1][0]


@pytest.mark.parametrize("schedule", [{"every_steps": 3}, {"every": 0.25}])
def test_a_snapshot_at_the_last_step_allowed_is_written_as_python_writes_it(tmp_path,
                                                                           monkeypatch,
                                                                           schedule):
    """A run whose last step allowed (``max_steps``) ends on a snapshot's time or
    step count, that snapshot among those the kernel appends: the run stops with
    the ConvergenceError, and the archive is byte for byte the one Python writes
    alone (an ``every`` snapshot landed on there written, as Python writes it at
    the end of the call that lands there, before the next is refused; an
    ``every_steps`` one not, as the budget's last step is left to a pause that never
    comes)."""
    from hamilton_orbits.validation import ConvergenceError

    system, kw = RADAU15_STEPPED["radau15"]
    Simulation(system(), archive=tmp_path / "ref", **schedule, **kw).integrate(6.0)
    last = Archive(tmp_path / "ref").snapshots[7].steps
    files, counts = [], []
    for compiled in (True, False):
        monkeypatch.setattr(segment, "COMPILED_WRITES", compiled)
        count = _kernel_written(monkeypatch)
        folder = tmp_path / "run"
        sim = Simulation(system(), archive=folder, max_steps=last, **schedule, **kw)
        with pytest.raises(ConvergenceError, match=f"in {last} steps"):
            sim.integrate(6.0)
        files.append({p.name: p.read_bytes() for p in folder.iterdir()
                      if not p.name.startswith(".")})
        counts.append(count[0])
        folder.rename(tmp_path / f"run-{compiled}")
    assert files[0] == files[1] and counts[0] >= 3 and counts[1] == 0
    steps = Archive(tmp_path / "run-True").snapshots[-1].steps
    assert steps == (last if "every" in schedule else last - 3)


@pytest.mark.parametrize("schedule", [{"every_steps": 3}, {"every": 0.25}])
def test_a_record_the_kernel_fails_to_write_is_written_by_python(tmp_path, monkeypatch,
                                                                  schedule):
    """A write that fails inside the kernel (here every plan's file descriptor made
    one that is not open, so ``pwrite`` fails) ends its call at the snapshot, which
    the Python path then writes: the archive is that of the run written by Python
    alone, and the kernel counted none."""
    from hamilton_orbits._kernels.records import P_FD
    from hamilton_orbits.segment import SegmentWriter

    plan_of = SegmentWriter.compiled_plan
    made = []

    def broken(self, *args):
        out = plan_of(self, *args)
        if out is not None:
            made.append(1)
            out[0][P_FD] = -1
        return out

    ours, trajs, kernel = None, None, None
    with monkeypatch.context() as m:
        m.setattr(SegmentWriter, "compiled_plan", broken)
        ours, trajs, kernel = _archived_runs(tmp_path, "broken", True, "radau15", [6.0], m,
                                             schedule)
    theirs, ref, _ = _archived_runs(tmp_path, "python", False, "radau15", [6.0], monkeypatch,
                                    schedule)
    assert len(made) > 3 and kernel == 0
    assert ours == theirs and _same(trajs[0].r, ref[0].r) and _same(trajs[0].t, ref[0].t)


@pytest.mark.parametrize("schedule", [{"every_steps": 3}, {"every": 0.25}])
def test_a_file_size_limit_met_by_the_kernel_stops_the_run_naming_the_segment(tmp_path,
                                                                             monkeypatch,
                                                                             schedule):
    """A real write failure where the kernel appends the records: a child process
    limited to a file size (``RLIMIT_FSIZE``, as a full disk refuses a write; its
    signal ignored) runs an ``every_steps`` or ``every`` archive past the limit.  The call
    raises the SnapshotError naming the segment and the system's reason, the
    run stands at the snapshot that met the limit, the archive holds only whole
    snapshots, those before it, and the folder's lock is released; the run
    resumed from it (no limit) reaches the bits of the run never stopped."""
    import resource
    import signal

    system, kw = RADAU15_STEPPED["radau15"]
    whole = Simulation(system(), archive=tmp_path / "whole", **schedule, **kw)
    ref = whole.integrate(12.0)
    size = next((tmp_path / "whole").glob("segment-*.nc")).stat().st_size
    count = _kernel_written(monkeypatch)  # (counted in the child)
    folder = tmp_path / "limited"
    ready, done = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: the limit, the run, what it raised, and out
        try:
            os.close(ready)
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (size // 2, resource.RLIM_INFINITY))
            sim = Simulation(system(), archive=folder, **schedule, **kw)
            try:
                sim.integrate(12.0)
                said = "no error"
            except Exception as exc:  # (what the parent checks)
                said = f"{type(exc).__name__}: {exc}"
            os.write(done, f"{count[0]} {sim.steps} {sim.t!r}\n{said}".encode())
        finally:
            os._exit(0)
    os.close(done)
    with os.fdopen(ready, "rb") as fh:
        counts, said = fh.read().decode().split("\n", 1)
    kernel, steps, t = (float(x) for x in counts.split())
    os.waitpid(pid, 0)
    assert re.fullmatch(r"SnapshotError: cannot write the snapshot to .*segment-000000\.nc: "
                        r"File too large", said), said
    archive = Archive(folder)
    assert archive.damaged == [] and archive.torn == [] and kernel >= 5
    assert 5 < len(archive) < len(Archive(tmp_path / "whole"))
    # (stopped at the snapshot that met the limit, the one after the last written)
    last = archive.snapshots[-1]
    assert (steps == last.steps + 3 if "every_steps" in schedule
            else t == 0.25 * (round(last.t / 0.25) + 1) and steps > last.steps)
    assert not (folder / ".hamilton-orbits.lock").exists()
    end = Simulation.load(folder).integrate(12.0)
    assert _same(end.r[-1], ref.r[-1]) and _same(end.v[-1], ref.v[-1])


def test_a_ctrl_c_after_snapshots_the_kernel_landed_on_keeps_them_and_goes_on(tmp_path,
                                                                             monkeypatch):
    """Ctrl-C in a compiled call that landed on ``every`` snapshot times and wrote
    their snapshots, then stepped on (Python's SIGINT handler run as the call
    returns, as CPython runs it; test_held.py): the snapshots are counted and kept,
    the simulation stands at the state the call reached, between two snapshot
    times, and the call made again goes on to the bits of the run never
    interrupted, its archive holding the same states at the same times (and the
    state reached, where the second leg begins)."""
    import signal

    from hamilton_orbits._kernels import radau15 as kernels
    from hamilton_orbits._kernels.records import P_WRITTEN
    from hamilton_orbits.integrators import radau15

    monkeypatch.setattr(radau15, "SLICE", 5)  # (calls of 5 steps, 2-3 between snapshots)
    system, kw = RADAU15_STEPPED["radau15"]
    once = Simulation(system(), archive=tmp_path / "once", every=0.25, **kw)
    ref = once.integrate(6.0)
    pressed, real = [], kernels.advance

    def ctrl_c(*args):  # (as the first call that wrote a snapshot and went on returns)
        out = real(*args)
        t = float(args[6][kernels.ST_T])
        if not pressed and args[-1][P_WRITTEN] >= 1 and t != 0.25 * round(t / 0.25):
            pressed.append(t)
            signal.getsignal(signal.SIGINT)(signal.SIGINT, None)
        return out

    sim = Simulation(system(), archive=tmp_path / "cut", every=0.25, **kw)
    with monkeypatch.context() as patched:
        patched.setattr(kernels, "advance", ctrl_c)
        cut = sim.integrate(6.0, on_interrupt="keep")
    kept = Archive(tmp_path / "cut")
    assert pressed and not cut.complete and sim.t == pressed[0] and 0.0 < sim.t < 6.0
    assert kept.damaged == [] and kept.torn == [] and 0.0 < kept.times[-1] < sim.t
    assert len(kept) == round(kept.times[-1] / 0.25) + 1 >= 5  # (those before it, all)
    end = sim.integrate(6.0)
    assert _same(end.r[-1], ref.r[-1]) and _same(end.v[-1], ref.v[-1])
    assert sim.steps == once.steps
    whole, archive = Archive(tmp_path / "once"), Archive(tmp_path / "cut")
    assert sorted(archive.times) == sorted([*whole.times, pressed[0]])
    at = {s.t: s.number for s in archive.snapshots}
    for snap in whole.snapshots:
        a, b = whole[snap.number].system.as_arrays(), archive[at[snap.t]].system.as_arrays()
        assert _same(a.r, b.r) and _same(a.v, b.v), snap.t
