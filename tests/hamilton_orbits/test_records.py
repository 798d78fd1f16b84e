"""_kernels.records: an archive record appended from inside a stepping kernel."""

from __future__ import annotations

import os
import struct
import zlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hamilton_orbits._kernels import records as R

pytestmark = pytest.mark.skipif(R.c_functions() == (0, 0),
                                reason="no pwrite or zlib crc32 here: Python writes every "
                                       "record, tested in test_segment")


def _plan(fd: int, end: int, count: int, rec: np.ndarray, sources: dict[str, np.ndarray],
          runs: list[tuple[int, int, int, int]]) -> np.ndarray:
    plan = np.zeros(R.P_RUNS + 4 * len(runs), np.int64)
    plan[R.P_EVERY], plan[R.P_FD], plan[R.P_END], plan[R.P_COUNT] = 1, fd, end, count
    plan[R.P_PWRITE], plan[R.P_CRC] = R.c_functions()
    plan[R.P_NRUNS], plan[R.P_REC], plan[R.P_SIZE] = len(runs), rec.ctypes.data, rec.size
    plan[R.P_ADDRESSES:R.P_RUNS] = [sources[k].ctypes.data for k in R.SOURCES]
    plan[R.P_RUNS:] = np.array(runs, np.int64).reshape(-1)
    return plan


FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=40, deadline=None)
@given(values=st.lists(FLOATS, min_size=9, max_size=9), steps=st.integers(1, 10**6),
       base=st.integers(0, 2**40), pad=st.integers(0, 12), count=st.integers(0, 2**30))
def test_a_record_is_written_then_counted_as_the_python_path_writes_it(
        tmp_path_factory, values, steps, base, pad, count):
    """The runs' values go big-endian into the record's float64 slots (a step count as
    its run's first plus the base plus the steps), the other bytes stay as they
    were, the last eight hold the CRC-32 of the others (zlib's) as a big-endian
    float64, the record goes after the last, and the header's count (big-endian,
    at byte 4) is one more: the bytes ``struct`` and ``zlib`` give."""
    sources = {k: np.array([values[j], -values[j], 0.5 * j]) for j, k in enumerate(R.SOURCES)}
    n_slots = 6
    size = 8 * n_slots + pad + 8  # (other variables after the floats, then the check)
    rec = np.frombuffer(bytearray(os.urandom(size)), np.uint8)
    other = rec[8 * n_slots:size - 8].tobytes()
    runs = [(R.SOURCES.index("r"), 0, 0, 2), (R.SOURCES.index("csv"), 1, 2, 2),
            (R.SRC_STEPS, 7, 4, 1), (R.SOURCES.index("st"), 2, 5, 1)]
    path = tmp_path_factory.mktemp("rec") / "seg"
    path.write_bytes(bytes(16))
    fd = os.open(path, os.O_RDWR)
    try:
        plan = _plan(fd, 16, count, rec, sources, runs)
        plan[R.P_BASE] = base
        assert R.write_record(plan, steps)
    finally:
        os.close(fd)
    floats = [values[0], -values[0], -values[8], 0.5 * 8, float(7 + base + steps), 0.5 * 4]
    body = struct.pack(">6d", *floats) + other
    expected = body + struct.pack(">d", float(zlib.crc32(body)))
    data = path.read_bytes()
    assert data[16:] == expected and data[4:8] == struct.pack(">i", count + 1)
    assert data[:4] == bytes(4) and data[8:16] == bytes(8)
    assert (plan[R.P_END], plan[R.P_COUNT], plan[R.P_WRITTEN], plan[R.P_LAST],
            plan[R.P_FAILED]) == (16 + size, count + 1, 1, steps, 0)


def test_a_write_that_fails_counts_nothing(tmp_path):
    """A ``pwrite`` that fails (a descriptor open for reading only) returns False with
    the plan's failure set, its counts unchanged and nothing in the file."""
    rec = np.zeros(24, np.uint8)
    sources = {k: np.zeros(2) for k in R.SOURCES}
    path = tmp_path / "seg"
    path.write_bytes(bytes(16))
    fd = os.open(path, os.O_RDONLY)
    try:
        plan = _plan(fd, 16, 3, rec, sources, [(0, 0, 0, 2)])
        assert not R.write_record(plan, 5)
    finally:
        os.close(fd)
    assert plan[R.P_FAILED] == 1 and plan[R.P_COUNT] == 3 and plan[R.P_END] == 16
    assert plan[R.P_WRITTEN] == 0 and path.read_bytes() == bytes(16)
