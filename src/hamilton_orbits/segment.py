"""Archive segments: snapshots appended to one netCDF file while a run goes on.

An archive folder (``docs/archive.md``) of format 2 holds *segments*.  A segment
``segment-NNNNNN.nc`` (``NNNNNN``: the number of its first snapshot) is a netCDF-3
file (64-bit offsets) with an unlimited dimension ``snapshot``:

- written once, when the segment begins: the global attribute ``meta`` (JSON: what
  every snapshot of the segment shares, i.e. the system's names, the method and its
  options, the effects, the events, the integrator state's layout and the
  archive's schedule) and the fixed variables (the system at time 0, ``initial_*``;
  a leg's output times ``leg_times`` when the segment begins a leg of more than
  its start and its end), with their SHA-256 in the attribute ``sha256``;
- one record per snapshot: ``t``, ``r(body, xyz)``, ``v``, ``gm``, ``active``, the
  integrator's packed ``state`` and the numbers of its state ``scalars`` (times,
  step counts: :func:`hamilton_orbits.restart.flatten`), ``steps``, its ``leg``
  (:data:`NO_LEG`: whether a leg ran before this one's, the number of the leg's
  first snapshot, whether it began at time 0, the steps and events before it),
  ``leg_span`` (the leg's start and end times, in its first record), ``rows``
  (the first and the end of the caller's output rows in the companion file that
  belong to it; :data:`OWN_ROW` twice for one row that is the record's own
  ``t``, ``r`` and ``v``, format 4) and ``check``, the CRC-32 of the record's
  other bytes.

The caller's output rows go to a companion ``rows-NNNNNN.nc`` of the same form
(unlimited dimension ``row``: ``t``, ``r``, ``v``, the variational equations'
values, ``check``).  A segment begins when what its snapshots share changes (an
event merged two bodies: the layout changed) or a leg of more output times
begins; a writer's next leg goes on in the segment it left, when that is as it
left it (format 3; in format 2 each leg began a segment, its leg in ``meta``).
A new process never appends to another's segment.

Appending a snapshot writes its record after the last one, then the number of
records in the header (4 bytes stored through a mapping of the file's first
bytes, or written and synced with ``sync``): O(snapshot), whatever the size of the
archive.  A kill during the record leaves bytes past the counted records: the
segment is then listed as torn and those bytes are never read; a kill between the
two writes loses that one snapshot.  A record whose CRC does not match its bytes
is damaged, listed, never read as data.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> fixed = {"initial_gm": np.array([1.0, 1e-3])}
>>> snap = {"t": np.float64(0.5), "steps": 5, "r": np.zeros((2, 3)), "active": np.ones(2, bool)}
>>> seg = SegmentWriter(folder, 0, {"kind": "demo"}, fixed, snap, {"r": ("body", "xyz")})
>>> seg.append(snap, {}); seg.append(dict(snap, t=np.float64(1.0), steps=10), {})
>>> seg.close()
>>> [(n, meta["t"], meta["steps"]) for n, meta, _ in read_segment(seg.path).snapshots]
[(0, 0.5, 5), (1, 1.0, 10)]
"""

from __future__ import annotations

import json
import math
import mmap
import operator
import os
import re
import struct
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from itertools import compress
from pathlib import Path
from typing import Any

import numpy as np

from hamilton_orbits._kernels import records as _rec
from hamilton_orbits._netcdf3 import NUMRECS_AT, Header, Parts, RecordBuffer, encode, parse
from hamilton_orbits.integrators._held import held
from hamilton_orbits.snapshot import (
    INT_EXACT,
    SnapshotError,
    beyond_float,
    checksum,
    stored,
    variable,
    write_bytes,
)

__all__ = ["SEGMENT_FORMAT", "SEGMENT_NAME", "SEGMENT_RE", "Segment", "SegmentWriter",
           "read_segment"]

SEGMENT_FORMAT = "hamilton-orbits archive segment"
#: the archive format that segments are: 4, a leg's first row kept as its first
#: record's state (3: written in the rows file too; 3 and 4 continue a segment
#: across the legs of one writer, each record holding its leg; 2: a segment per
#: leg; 1 was a file per snapshot)
SEGMENT_VERSION = 4
SEGMENT_NAME, ROWS_NAME = "segment-{:06d}.nc", "rows-{:06d}.nc"
#: a record's ``rows`` (both ends) when its one output row is its own state, not
#: written in the rows file (format 4: a leg's first row, at its start)
OWN_ROW = -1
SEGMENT_RE = re.compile(r"^segment-(\d{6})\.nc$")
#: whether a stepping kernel may append the snapshots of a run itself, where it
#: can (:meth:`SegmentWriter.compiled_plan`); False: every record written by Python
COMPILED_WRITES = True
#: a segment's or a rows file's name, with the number of its first snapshot
_NUMBERED_RE = re.compile(r"^(?:segment|rows)-(\d{6})\.nc$")
#: the record of a snapshot of a propagation's state, in its stored order
_STATE_RECORD = ["t", "r", "v", "gm", "state", "scalars", "steps", "rows", "active"]
#: the same with the snapshot's leg (format 3: a segment continued across legs)
_STATE_RECORD_LEGS = ["t", "r", "v", "gm", "state", "scalars", "steps", "leg", "leg_span",
                      "rows", "active"]
#: a record's ``leg`` (whether the simulation had begun a leg before this one, the
#: number of the leg's first snapshot, whether it began at time 0, the steps and
#: the events recorded before it) when it has none, and its ``leg_span`` (the leg's
#: start and end times, in its first record) after the leg's first record
NO_LEG, NO_SPAN = (math.nan,) * 5, (math.nan,) * 2
_ROWS = ("out_t", "out_r", "out_v", "out_megno", "out_lyapunov", "out_lyapunov_time",
         "out_stm")


class _Appender:
    """One netCDF file of records appended (a segment, or its rows): its header
    (with the SHA-256 of its text attributes and of ``summed``, the fixed variables'
    values) written once, atomically."""

    def __init__(self, path: Path, attrs: dict[str, Any], fixed: list[Any],
                 template: list[tuple[str, tuple[str, ...], np.ndarray, str]],
                 record_dim: str, sync: bool,
                 summed: Mapping[str, np.ndarray] | None = None,
                 units: Mapping[str, str] | None = None) -> None:
        units = units or {}
        records = [(name, dims, values, {"dtype_saved": kind}
                    | ({"units": units[name]} if name in units else {}))
                   for name, dims, values, kind in template]
        records.append(("check", (), np.zeros((), np.float64), {"dtype_saved": "uint32"}))
        attrs = dict(attrs, records=_record_text([(n, v.shape, a["dtype_saved"])
                                                  for n, _, v, a in records]))
        attrs["sha256"] = checksum(_signed(attrs), summed or {})
        header = encode(attrs, fixed, records, record_dim=record_dim)
        #: one record's bytes, reused (its last variable the CRC-32 of the others)
        self.buffer = RecordBuffer([values for _, _, values, _ in records])
        #: the bytes the CRC-32 is of (all the record's but ``check``'s)
        self.signed = memoryview(self.buffer.data)[:-8]
        self.path, self.sync, self.count, self.end = path, sync, 0, len(header)
        self.begin = len(header)  # (where the records begin)
        self.fd = write_bytes(path, header, sync=sync, keep_open=True)
        #: the count in the header, mapped (a store, not a system call, per append;
        #: its page is the file's own: a killed process leaves it written), or None
        #: (``sync``: a write then a sync, in order; or a file that does not map)
        self.numrecs = None if sync else _mapped_count(self.fd)

    def append(self, rows: list[list[Any]]) -> None:
        """Append records (each its record variables' values but ``check``, cast to
        the types they are stored as), then count them in the header."""
        buffer, parts = self.buffer, []
        for values in rows:
            buffer.fill([*values, 0.0])
            parts.append(self.checked() if len(rows) == 1 else bytes(self.checked()))
            # (the buffer is reused)
        self.write(parts[0] if len(parts) == 1 else b"".join(parts), len(rows))

    def checked(self) -> bytearray:
        """The buffer's record with its CRC-32 put in its ``check`` (its last 8 bytes,
        a big-endian float64)."""
        data = self.buffer.data
        struct.pack_into(">d", data, len(data) - 8, zlib.crc32(self.signed))
        return data

    def write(self, data: bytes | bytearray, count: int) -> None:
        """Write ``count`` whole records ``data`` after the last, then count them (a
        write that takes part of them goes on with the rest: a file that then
        refuses it, full, raises before they are counted)."""
        try:
            view, at = memoryview(data), self.end
            while view:
                done = os.pwrite(self.fd, view, at)
                view, at = view[done:], at + done
            if self.numrecs is not None:  # (after the records: the count never runs ahead)
                struct.pack_into(">i", self.numrecs, NUMRECS_AT, self.count + count)
            else:
                if self.sync:
                    os.fsync(self.fd)
                os.pwrite(self.fd, struct.pack(">i", self.count + count), NUMRECS_AT)
                if self.sync:
                    os.fsync(self.fd)
        except OSError as exc:
            raise SnapshotError(f"cannot write the snapshot to {self.path}: "
                                f"{exc.strerror or exc}") from None
        self.count += count
        self.end += len(data)

    def trim(self) -> None:
        """After a write that did not end (Ctrl-C, an error): the file cut back to the
        records its header counts, and this appender's counts made the file's (a
        record may have been written and counted there, not yet here)."""
        if self.fd < 0:
            return
        try:
            count = struct.unpack(">i", os.pread(self.fd, 4, NUMRECS_AT))[0]
            end = self.begin + count * len(self.buffer.data)
            os.ftruncate(self.fd, end)
        except OSError:  # (left as it is: a torn tail is told apart on reading)
            return
        self.count, self.end = count, end

    def close(self) -> None:
        """Close the file (each part let go before it is closed: a Ctrl-C amid them
        leaves none to be closed twice, whose descriptor may be another's by then)."""
        numrecs, self.numrecs = self.numrecs, None
        fd, self.fd = self.fd, -1
        try:
            if numrecs is not None:
                numrecs.close()
        finally:
            if fd >= 0:
                os.close(fd)

    def reopen(self) -> bool:
        """Open the file closed by :meth:`close` again, to append after its last
        record; False, nothing open, where it is not as this appender left it (its
        size, its count of records)."""
        try:
            fd = os.open(self.path, os.O_RDWR)
        except OSError:
            return False
        try:
            if (os.fstat(fd).st_size != self.end
                    or os.pread(fd, 4, NUMRECS_AT) != struct.pack(">i", self.count)):
                os.close(fd)
                return False
        except OSError:
            os.close(fd)
            return False
        self.fd = fd
        self.numrecs = None if self.sync else _mapped_count(fd)
        return True


def _exact(numbers: list[Any]) -> bool:
    """Whether every integer of ``numbers`` (bools, ints, floats) is exact in a
    float64 (the bounds first: one pass of two built-ins, where they hold)."""
    if not numbers or (-INT_EXACT < min(numbers) and max(numbers) < INT_EXACT):
        return True
    return not any(type(x) is int and not -INT_EXACT < x < INT_EXACT for x in numbers)


def _exact_arrays(arrays: list[np.ndarray], ints: list[int]) -> bool:
    """Whether the integer arrays ``arrays[k]``, ``k`` in ``ints``, hold only values
    exact in a float64 (one value read as a Python int, more by
    :func:`~hamilton_orbits.snapshot.beyond_float`)."""
    for k in ints:
        a = arrays[k]
        if a.size == 1:
            if not -INT_EXACT < a.item() < INT_EXACT:
                return False
        elif beyond_float(a):
            return False
    return True


def _mapped_count(fd: int) -> mmap.mmap | None:
    """The first bytes of file ``fd``, through the count of records, mapped for
    writing (None where the file system does not map files)."""
    try:
        return mmap.mmap(fd, NUMRECS_AT + 4, access=mmap.ACCESS_WRITE)
    except (OSError, ValueError):
        return None


def _packed_like(value: Any) -> Any:
    """``value``, or for :class:`~hamilton_orbits._netcdf3.Parts` float64 values of
    the size they pack into (a record variable's shape and type, for its template)."""
    if type(value) is Parts:
        return np.zeros(sum(a.size for a in value))
    return value


def _own_row(snapshot: Mapping[str, Any], rows: Mapping[str, np.ndarray]) -> bool:
    """Whether the one output row of ``rows`` is ``snapshot``'s own state: its time,
    positions and velocities the snapshot's bit for bit, and nothing else in it."""
    if rows.keys() != {"out_t", "out_r", "out_v"}:
        return False
    return all(_same_bits(rows[f"out_{k}"][0], snapshot.get(k)) for k in ("t", "r", "v"))


def _same_bits(a: np.ndarray, b: Any) -> bool:
    """Whether ``b`` is float64 values of ``a``'s shape and bits (-0.0 is not 0.0,
    a NaN is its own payload)."""
    b = np.asarray(b)
    return b.dtype == np.float64 and b.shape == a.shape and b.tobytes() == a.tobytes()


def _varying(history: tuple[tuple[float, list[Any], int], ...],
             steps: int) -> list[tuple[int, int | None]] | None:
    """The numbers of a record that changed between the two records of ``history``
    (each its time, numbers and step count), each as ``(position, first)``: ``first``
    None for the record's time, else a step count, ``first`` plus the kernel's steps
    (``steps`` now); None where one changed otherwise (the kernel cannot write it)."""
    (t0, old, n0), (t1, new, n1) = history
    out: list[tuple[int, int | None]] = []
    for j, (x0, x1) in enumerate(zip(old, new, strict=True)):
        if type(x0) is type(x1) and (x0 == x1 if type(x1) is not float
                                     else _bits(x0) == _bits(x1)):
            continue
        if type(x1) is float and type(x0) is float and _bits(x1) == _bits(t1) \
                and _bits(x0) == _bits(t0):
            out.append((j, None))
        elif type(x1) is int and type(x0) is int and x1 - x0 == n1 - n0 > 0:
            out.append((j, x1 - steps))
        else:
            return None
    return out


def _bits(x: float) -> bytes:
    return struct.pack("<d", x)


def _joinable(arrays: list[np.ndarray]) -> tuple[list[Any], list[tuple[int, np.ndarray]]]:
    """``arrays`` as pieces whose native bytes join into float64 values: the
    contiguous float64 arrays themselves (their values read when joined), and the
    others (position, array), to convert at each join."""
    pieces: list[Any] = []
    convert = []
    for k, a in enumerate(arrays):
        live = a.dtype == np.float64 and a.dtype.isnative and a.flags.c_contiguous
        pieces.append(a if live else None)
        if not live:
            convert.append((k, a))
    return pieces, convert


def _record_text(variables: list[tuple[str, tuple[int, ...], str]]) -> str:
    """The record variables' names, shapes and saved types as JSON (kept in the
    header and checked on reading: the format's own entries are not summed)."""
    return json.dumps([[n, list(shape), kind] for n, shape, kind in variables])


def _signed(attrs: Mapping[str, Any]) -> str:
    """The text the header's SHA-256 covers, beside the fixed variables."""
    return "\0".join(str(attrs.get(k, "")) for k in ("format", "first", "meta", "records"))


def _stored(name: str, value: Any) -> np.ndarray:
    """A record variable's values as the file can store them (cast into the record by
    :class:`~hamilton_orbits._netcdf3.RecordBuffer`): integers checked below 2**53,
    other types than float and bool refused (:func:`~hamilton_orbits.snapshot.stored`)."""
    kind = type(value)
    if kind is Parts or (kind is np.ndarray and value.dtype.kind in "fb"):
        return value  # (parts of a record variable, checked: cast when it is filled)
    if kind is int and abs(value) < INT_EXACT:
        return np.float64(value)  # (a step count)
    a = np.asarray(value)
    return a if a.dtype.kind in "fb" else stored(name, a)[0]


class SegmentWriter:
    """A segment being written: its snapshots (and their output rows) appended.

    Parameters
    ----------
    folder : Path
        The archive folder.
    first : int
        The number of the segment's first snapshot.
    shared : dict
        What the segment's snapshots share (JSON-able: the global attribute ``meta``).
    fixed : mapping of str to ndarray
        The fixed variables (``initial_*``, ``leg_times``).
    like : mapping of str to ndarray
        A snapshot's record values (``t``, ``steps``, ``r``, ...), for their shapes.
    dims, units : mapping, optional
        Dimension names and ``units`` attributes of the variables.
    sync : bool
        ``fsync`` each append (survives a power cut, not only a killed process).
    fresh : bool
        The folder holds no file of this number (made by the writer's claim, no
        segment begun in it): no rows file of a killed run's segment to remove.
    """

    def __init__(self, folder: Path, first: int, shared: dict[str, Any],
                 fixed: Mapping[str, np.ndarray], like: Mapping[str, Any],
                 dims: Mapping[str, tuple[str, ...]] | None = None,
                 units: Mapping[str, str] | None = None, sync: bool = False,
                 fresh: bool = False) -> None:
        dims, units = dict(dims or {}), dict(units or {})
        self.shared, self.first, self.folder, self.sync = shared, first, folder, sync
        self.dims, self.units = dims, units
        text = json.dumps(shared, sort_keys=True, allow_nan=True)
        fixed_vars = [variable(k, np.asarray(a), dims.get(k), units.get(k))
                      for k, a in fixed.items()]
        attrs = {"format": SEGMENT_FORMAT, "format_version": SEGMENT_VERSION, "first": first,
                 "meta": text}
        #: the record variables: the snapshot's values but the fixed ones and the rows
        names = [k for k in like if k not in fixed and not k.startswith("out_")]
        template = [(k, self._dims(k, x), *stored(k, np.asarray(x)))
                    for k in names for x in [_packed_like(like[k])]]
        template.append(("rows", ("from_to",), np.zeros(2, np.float64), "int64"))
        # (the float64 variables first: a record is then filled by few concatenations)
        template.sort(key=lambda var: var[2].dtype != np.float64)
        self.names = [var[0] for var in template]
        self.text = text
        self.path = folder / SEGMENT_NAME.format(first)
        self._file = _Appender(self.path, attrs, fixed_vars, template, "snapshot", sync, fixed,
                               units)
        self._rows: _Appender | None = None
        #: the records hold their leg (``leg``, ``leg_span``): the segment goes on
        #: across legs (format 3)
        self.legs = "leg" in self.names
        #: what a record holds after ``steps`` when no leg begins there: its leg and
        #: no span (with ``legs``)
        self.tail: tuple[float, ...] = (*NO_LEG, *NO_SPAN) if self.legs else ()
        #: a record of a propagation's state is filled by :meth:`_append_state`, the
        #: flat views of its state's arrays kept while they are the same arrays
        floats = len(self.names) - 1
        self._direct = (self.names in (_STATE_RECORD, _STATE_RECORD_LEGS)
                        and self._file.buffer.runs[0][:2] == (0, floats))
        self._kept: tuple[list[np.ndarray], list[np.ndarray]] = ([], [])
        #: what the last :meth:`_append_state` filled from, for :meth:`refill`
        self._last: tuple[Any, ...] | None = None
        #: the time, numbers and step count of the last two records, where each was
        #: written by :meth:`refill` right after the other (:meth:`compiled_plan`)
        self._history: tuple[tuple[float, list[Any], int], ...] = ()
        if not fresh:  # (rows of a segment of this number that a killed run began and
            (folder / ROWS_NAME.format(first)).unlink(missing_ok=True)  # this replaces)

    def _dims(self, name: str, value: Any) -> tuple[str, ...]:
        shape = np.shape(value)
        given = self.dims.get(name.removeprefix("out_"), ())
        if len(given) == len(shape):
            return given
        return tuple(f"{name}_{k}" for k in range(len(shape)))

    @property
    def count(self) -> int:
        """The snapshots appended."""
        return self._file.count

    @property
    def size(self) -> int:
        """The segment file's bytes written (its size on disk)."""
        return self._file.end

    def append(self, snapshot: Mapping[str, Any], rows: Mapping[str, np.ndarray]) -> None:
        """Append the caller's output ``rows`` (``out_t``, ``out_r``, ... of
        :meth:`~hamilton_orbits.checkpoint.LegRows.take`) and then the snapshot.  A
        row that is the snapshot's own state (a leg's first, at its start: the
        snapshot's ``t``, ``r`` and ``v``, bit for bit, nothing else) is not written
        twice: the record's ``rows`` say so (:data:`OWN_ROW`, format 4), and a
        segment of such legs has no rows file."""
        n = len(rows.get("out_t", ()))
        start = 0 if self._rows is None else self._rows.count
        if n == 1 and _own_row(snapshot, rows):
            n, start = 0, OWN_ROW
        if n:
            names = [k for k in _ROWS if k in rows]
            if self._rows is None:
                template = [(k, self._dims(k, rows[k][0]), np.asarray(rows[k][0]), "float64")
                            for k in names]
                self._rows = _Appender(self.folder / ROWS_NAME.format(self.first),
                                       {"format": SEGMENT_FORMAT + " rows",
                                        "format_version": SEGMENT_VERSION, "first": self.first,
                                        "meta": "{}"}, [], template, "row", self.sync,
                                       units={f"out_{k}": x for k, x in self.units.items()})
            self._rows.append([[np.asarray(rows[k][i], np.float64) for k in names]
                               for i in range(n)])
        if self.legs:
            self.tail = (*snapshot["leg"], *NO_SPAN)
        self._history = ()
        end = start + n if start != OWN_ROW else OWN_ROW
        if self._direct and type(snapshot["state"]) is Parts and self._append_state(
                snapshot, start, end):
            return
        span = np.array([start, end], dtype=np.float64)
        self._file.append([[span if k == "rows" else _stored(k, snapshot[k])
                            for k in self.names]])

    def _append_state(self, snap: Mapping[str, Any], start: int, end: int) -> bool:
        """Append a snapshot of a propagation's state, its output rows those from
        ``start`` to ``end`` of the rows file (the bytes :meth:`append` writes): the
        float64 variables, ``t`` to ``rows``, filled by one concatenation, then
        ``active``.  False, nothing written, where a value is not of its variable's
        shape or a step count not exact in a float64 (the general path then says
        why)."""
        file = self._file
        views, state, kept = file.buffer.views, snap["state"], self._kept
        if len(kept[0]) != len(state):
            flat = [a.reshape(-1) for a in state]
            if sum(a.size for a in flat) != views[4].size:
                return False
            kept = self._kept = (list(state), flat)
        elif not all(map(operator.is_, kept[0], state)):
            # (some arrays replaced, as the propagation's r and v at each pause: their
            # flat views remade, the others kept, the total size unchanged)
            for k, (old, a) in enumerate(zip(kept[0], state, strict=True)):
                if old is not a:
                    if a.shape != old.shape:
                        return self._forget()
                    kept[0][k], kept[1][k] = a, a.reshape(-1)
        r, v, gm, scalars, active, steps = (snap["r"], snap["v"], snap["gm"], snap["scalars"],
                                            snap["active"], snap["steps"])
        tail = (*snap["leg"], *snap["leg_span"]) if self.legs else ()
        if (r.shape != views[1].shape or v.shape != views[2].shape or gm.shape != views[3].shape
                or scalars.shape != views[5].shape or np.shape(active) != views[-2].shape
                or type(steps) is not int or not -INT_EXACT < steps < INT_EXACT
                or len(tail) != len(self.tail)):
            return False
        head = file.buffer.runs[0][2]  # (t, r, v, gm, state, scalars, steps, [leg,
        # leg_span,] rows)
        head[0] = snap["t"]
        np.concatenate([r.reshape(-1), v.reshape(-1), gm, *kept[1], scalars,
                        (steps, *tail, start, end)], out=head[1:], casting="unsafe")
        views[-2][...] = active  # (the last variable is check)
        file.write(file.checked(), 1)
        self._last = (r, v, gm, active, *_joinable([r, v, gm, *kept[0]]))
        return True

    def refill(self, t: float, r: np.ndarray, v: np.ndarray, gm: np.ndarray,
               active: np.ndarray, state: list[np.ndarray], scalars: list[Any],
               steps: int, ints: list[int]) -> bool:
        """Append the snapshot after one :meth:`_append_state` appended, of the same
        arrays (``r``, ``v``, ``gm``, ``active`` read-only, the ``state`` arrays: their
        values changed in place; ``r``, ``v`` and state arrays may be others of the
        same shapes and types, as an output's rows) with their new numbers: what
        :meth:`append` would write, without building the snapshot.  False, nothing
        written, where an array is not such, ``gm`` or ``active`` another, or a
        number does not fit (``ints``: the positions of the integer arrays of
        ``state``, checked below 2**53)."""
        last, kept = self._last, self._kept[0]
        if last is not None and (r is not last[0] or v is not last[1] or len(state) != len(kept)
                                 or not all(map(operator.is_, kept, state))):
            last = self._moved(r, v, state)  # (an output's rows: other arrays, the same
            # shapes and types; the state's arrays then those kept)
        if (last is None or r is not last[0] or v is not last[1] or gm is not last[2]
                or active is not last[3] or active.flags.writeable
                or type(steps) is not int or not -INT_EXACT < steps < INT_EXACT
                or len(scalars) != self._file.buffer.views[5].size
                or not _exact(scalars) or not _exact_arrays(state, ints)):
            return False
        file, pieces = self._file, last[4]
        start = 0 if self._rows is None else self._rows.count  # (rows written since the
        # last fill by the general path count)
        if last[5]:  # (arrays not float64 or not contiguous: their values as float64)
            pieces = pieces.copy()
            for k, a in last[5]:
                pieces[k] = np.ascontiguousarray(a, dtype=np.float64)
        head = file.buffer.runs[0][2]
        head[0] = t
        # (the native bytes joined, then turned big-endian by one copy: the bytes the
        # concatenation of :meth:`_append_state` gives, in a third of its time)
        head[1:] = np.frombuffer(b"".join(
            [*pieces, np.array([*scalars, steps, *self.tail, start, start], dtype=np.float64)]))
        file.write(file.checked(), 1)
        self._history = (*self._history[-1:], (t, list(scalars), steps))
        return True

    def compiled_plan(self, arrays: Mapping[str, np.ndarray],
                      aliases: list[tuple[np.ndarray, str]], t_at: tuple[str, int],
                      steps: int, every: int) -> tuple[np.ndarray, tuple[Any, ...]] | None:
        """The plan (and what it reads and writes, to be kept while it is used: its
        addresses are theirs) with which a stepping kernel appends the
        next snapshots itself, every ``every`` of its steps, while only it runs
        (:mod:`hamilton_orbits._kernels.records`); None where it cannot: the last two
        records were not written by :meth:`refill` one after the other, a number
        changed from one to the other in a way the steps do not explain, or the
        segment is synced or the system has no ``pwrite`` for it.

        ``arrays`` are the kernel's own (by their names in
        :data:`~hamilton_orbits._kernels.records.SOURCES`), ``aliases`` other arrays
        of the record that hold the same values as one of them at a snapshot (a
        pause's copies of the positions and velocities), ``t_at`` where the kernel
        keeps the time (the array's name and the index), and ``steps`` the
        kernel's count of steps now, the record's step counts being that plus a
        fixed number each.  The record's other values stay as :meth:`refill` wrote
        them.
        """
        last, file = self._last, self._file
        if last is None or len(self._history) < 2 or self.sync or file.fd < 0:
            return None
        pwrite, crc = _rec.c_functions() if COMPILED_WRITES else (0, 0)
        if not pwrite:
            return None
        if arrays.keys() != set(_rec.SOURCES) or not all(
                a.dtype == np.float64 and a.flags.c_contiguous for a in arrays.values()):
            return None
        names = {id(a): (_rec.SOURCES.index(k), a.size) for k, a in arrays.items()}
        names.update((id(a), names[id(arrays[k])]) for a, k in aliases)
        runs = [(_rec.SOURCES.index(t_at[0]), t_at[1], 0, 1)]
        slot, convert = 1, dict(last[5])
        for k, a in enumerate(last[4]):
            size = convert[k].size if a is None else a.size
            source = None if a is None else names.get(id(a))
            if source is None and k < 2:  # (the positions and velocities: the kernel's
                return None  # own, or no plan)
            if source is not None:
                if source[1] != size:
                    return None
                runs.append((source[0], 0, slot, size))
            slot += size
        counters = _varying(self._history, steps)
        if counters is None:
            return None
        t_run = runs[0]
        for j, first in counters:  # (the time, or a step count: that plus the steps)
            runs.append((*t_run[:2], slot + j, 1) if first is None
                        else (_rec.SRC_STEPS, first, slot + j, 1))
        slot += len(self._history[-1][1])
        runs.append((_rec.SRC_STEPS, self._history[-1][2] - steps, slot, 1))
        if slot + 1 + len(self.tail) + 2 != file.buffer.runs[0][2].size:
            return None
        rec = np.frombuffer(file.buffer.data, np.uint8)  # (kept with the plan: its
        # buffer then stays where it is)
        plan = np.zeros(_rec.P_RUNS + 4 * len(runs), np.int64)
        plan[[_rec.P_EVERY, _rec.P_FD, _rec.P_END, _rec.P_COUNT, _rec.P_PWRITE, _rec.P_CRC,
              _rec.P_NRUNS, _rec.P_REC, _rec.P_SIZE]] = (
            every, file.fd, file.end, file.count, pwrite, crc, len(runs), rec.ctypes.data,
            rec.size)
        plan[_rec.P_ADDRESSES:_rec.P_RUNS] = [arrays[k].ctypes.data for k in _rec.SOURCES]
        plan[_rec.P_RUNS:] = np.array(runs, np.int64).reshape(-1)
        return plan, (rec, *arrays.values())

    def compiled_wrote(self, plan: np.ndarray) -> None:
        """Take the records a kernel appended with ``plan`` (:meth:`compiled_plan`) as
        written: counted here as in the file."""
        self._file.count, self._file.end = int(plan[_rec.P_COUNT]), int(plan[_rec.P_END])
        self._history = ()

    def _moved(self, r: np.ndarray, v: np.ndarray,
               state: list[np.ndarray]) -> tuple[Any, ...] | None:
        """The last fill's parts with ``r``, ``v`` and the ``state`` arrays put in the
        places of those it took (kept for the next :meth:`refill`), or None, nothing
        changed, where one is not a contiguous array of the same shape and type as
        the one it replaces, taken whole by the last fill."""
        last, kept = self._last, self._kept
        if len(state) != len(kept[0]):
            return None
        pieces = list(last[4])  # (r, v, gm, the state's arrays: gm is not replaced)
        olds, news = (last[0], last[1], last[2], *kept[0]), (r, v, last[2], *state)
        # (the places replaced, found in C: among the state's arrays usually only the
        # propagation's r and v, the record's own)
        places = list(compress(range(len(olds)), map(operator.is_not, olds, news)))
        for k in places:
            old, a = olds[k], news[k]
            if (type(a) is not np.ndarray or a.shape != old.shape or a.dtype != old.dtype
                    or pieces[k] is None or not a.flags.c_contiguous):
                return None
            pieces[k] = a
        for k in places:  # (all checked: the kept views follow)
            if k >= 3:
                kept[0][k - 3], kept[1][k - 3] = news[k], news[k].reshape(-1)
        self._last = (r, v, last[2], last[3], pieces, last[5])
        return self._last

    def _forget(self) -> bool:
        """Drop the kept views (a state of another shape: the general path follows)."""
        self._kept, self._last = ([], []), None
        return False

    def trim(self) -> None:
        """Cut the files back to their counted records (:meth:`_Appender.trim`)."""
        self._history = ()
        self._file.trim()
        if self._rows is not None:
            self._rows.trim()

    def close(self) -> None:
        """Close the files (what was appended stays)."""
        self._history = ()
        try:
            self._file.close()
        finally:
            if self._rows is not None:
                self._rows.close()

    def reopen(self) -> bool:
        """Open the files closed by :meth:`close` again, to go on appending (a
        segment whose records hold their leg, continued by the next leg of the same
        writer); False, nothing open, where one is not as this writer left it."""
        if not self._file.reopen():
            return False
        if self._rows is not None and not self._rows.reopen():
            self._file.close()
            return False
        return True


@dataclass
class Segment:
    """A segment read back: its snapshots as ``(number, meta, arrays)`` (the
    ``meta`` and arrays a single snapshot file holds), the ones damaged, and whether
    it ends in a torn write."""

    path: Path
    first: int
    count: int  # the records counted in the header, damaged ones included
    snapshots: list[tuple[int, dict[str, Any], dict[str, np.ndarray]]] = field(
        default_factory=list)
    damaged: list[tuple[Path, str]] = field(default_factory=list)
    torn: list[Path] = field(default_factory=list)


def _fixed_array(header: Header, data: bytes, name: str) -> np.ndarray:
    var = header.variables[name]
    kind = var.attrs.get("dtype_saved", "float64")
    shape = var.attrs.get("empty_shape")
    if shape is not None:
        return np.zeros(tuple(int(k) for k in shape.split(",")), dtype=kind)
    return header.values(data, name).astype(kind)


def _record_at(header: Header, data: bytes | bytearray, k: int) -> dict[str, np.ndarray] | None:
    """Record ``k`` of ``data`` (the file's bytes, or the bytes before its first
    record followed by record ``k``'s alone, read as record 0) decoded, or None
    where its CRC-32 does not match its bytes."""
    names = _record_names(header)
    if not _checks(header, data, k, _spans(header, names)):
        return None
    # (the types and shapes were checked with the header: a record that checks decodes)
    return {n: header.values(data, n, k).astype(header.variables[n].attrs.get(
        "dtype_saved", "float64")) for n in names}


def _records(header: Header, data: bytes, last: bool = False) -> tuple[
        list[dict[str, np.ndarray]], list[tuple[int, str]], bool]:
    """The records that check (``last``: the last of them only), the damaged ones
    (index, reason), and a torn tail."""
    end = header.record_begin + header.numrecs * header.record_size
    good, bad = [], []
    held = max(len(data) - header.record_begin, 0) // max(header.record_size, 1)
    if header.numrecs > held:  # a header counting records the file does not hold
        bad.append((held, f"the header counts {header.numrecs} records, the file holds "
                          f"{held}"))
    names = _record_names(header)
    failed, spans = [], _spans(header, names)
    for k in range(min(header.numrecs, held)):
        (good if _checks(header, data, k, spans) else failed).append(k)
    bad += [(k, "its CRC-32 does not match") for k in failed]
    ks = good[-1:] if last else good
    # (each variable of the records that check decoded at once, through a strided
    # view of the file's bytes; a record's values are then views of those)
    columns = {n: _column(header, data, n, ks) for n in names}
    return ([dict({n: columns[n][i, ...] for n in names}, _index=np.int64(k))
             for i, k in enumerate(ks)], bad, len(data) > end)


def _record_names(header: Header) -> list[str]:
    """A segment's or rows file's record variables, but ``check``."""
    return [n for n, v in header.variables.items() if v.is_record and n != "check"]


def _row_arrays(header: Header, records: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Rows ``records`` of a rows file as arrays ``out_*`` (a rows file without
    times is damaged: ``KeyError``)."""
    out = {n: np.array([r[n] for r in records], dtype=np.float64).reshape(
        (len(records), *header.variables[n].shape)) for n in _record_names(header)}
    out["out_t"].shape  # noqa: B018 - (a rows file without times is damaged)
    return out


def _checks(header: Header, data: bytes | bytearray, k: int,
            spans: list[tuple[int, int]]) -> bool:
    """Whether record ``k``'s CRC-32 matches its bytes (those of its variables, in
    record 0 at ``spans`` (:func:`_spans`), without the padding between them)."""
    at = k * header.record_size
    check = header.variables.get("check")
    stored = b"" if check is None else data[check.begin + at:check.begin + at + 8]
    if len(stored) != 8:
        return False
    crc, view = 0, memoryview(data)
    for begin, end in spans:
        crc = zlib.crc32(view[begin + at:end + at], crc)
    return crc == struct.unpack(">d", stored)[0]


def _spans(header: Header, names: list[str]) -> list[tuple[int, int]]:
    """The byte ranges of variables ``names`` in record 0, those that follow one
    another without padding joined into one."""
    out: list[tuple[int, int]] = []
    for v in (header.variables[n] for n in names):
        if out and out[-1][1] == v.begin:
            out[-1] = (out[-1][0], v.begin + v.size)
        else:
            out.append((v.begin, v.begin + v.size))
    return out


def _column(header: Header, data: bytes, name: str, ks: list[int]) -> np.ndarray:
    """Record variable ``name`` of records ``ks`` (increasing) as one native array,
    its first axis the records (the type it was saved as)."""
    var = header.variables[name]
    count = math.prod(var.shape)
    if not ks:
        return np.empty((0, *var.shape), var.attrs.get("dtype_saved", "float64"))
    every = np.ndarray((ks[-1] + 1, count), var.dtype, data, var.begin,
                       (header.record_size, var.dtype.itemsize))
    return every[ks].astype(var.dtype.newbyteorder("=")).reshape(
        (len(ks), *var.shape)).astype(var.attrs.get("dtype_saved", "float64"))


def _head(fd: int) -> bytes | None:
    """The bytes of an open segment or rows file before its first record (its header
    and fixed variables), or None where its header does not parse from its first
    64 KiB (the caller then reads the whole file, which says why)."""
    data = os.pread(fd, 1 << 16, 0)
    try:
        begin = parse(data).record_begin
    except Exception:  # (a damaged header fails in many ways; the whole read names it)
        return None
    if begin > len(data):
        data += os.pread(fd, begin - len(data), len(data))
    return data[:begin] if begin else None


def _open(path: Path) -> tuple[Header, bytes, dict[str, np.ndarray]]:
    """A segment's or rows file's header, bytes and fixed variables, its SHA-256 and
    its record variables checked."""
    try:
        data = path.read_bytes()
    except Exception as exc:  # (as a damaged header is named)
        raise SnapshotError(f"{path} cannot be read as an archive segment (damaged: "
                            f"{type(exc).__name__}: {exc})") from None
    header, fixed = _checked(path, data)
    return header, data, fixed


def _checked(path: Path, data: bytes) -> tuple[Header, dict[str, np.ndarray]]:
    """The header and fixed variables of ``data`` (the bytes of file ``path``, at
    least those before its first record), its SHA-256 and its record variables
    checked."""
    try:
        header = parse(data)
        fmt = header.attrs.get("format")
        if fmt not in (SEGMENT_FORMAT, SEGMENT_FORMAT + " rows"):
            raise SnapshotError(f"{path} is not a hamilton-orbits archive segment "
                                f"(format {fmt!r})")
        if int(header.attrs.get("format_version", 0)) > SEGMENT_VERSION:
            raise SnapshotError(f"{path} has format version {header.attrs['format_version']};"
                                f" this version of hamilton-orbits reads up to "
                                f"{SEGMENT_VERSION}")
        fixed = {k: _fixed_array(header, data, k) for k, v in header.variables.items()
                 if not v.is_record}
        good = checksum(_signed(header.attrs), fixed) == header.attrs.get("sha256")
        records = _record_text([(n, v.shape, v.attrs.get("dtype_saved", ""))
                                for n, v in header.variables.items() if v.is_record])
    except SnapshotError:
        raise
    except Exception as exc:  # any damage of the header surfaces as some error
        raise SnapshotError(f"{path} cannot be read as an archive segment (damaged: "
                            f"{type(exc).__name__}: {exc})") from None
    named = _NUMBERED_RE.match(path.name)
    if good and named and int(named.group(1)) != int(header.attrs.get("first", -1)):
        raise SnapshotError(f"{path} holds the snapshots from number {header.attrs['first']}"
                            f" on, not from {int(named.group(1))} as its name says (a file "
                            f"renamed or copied): not read as its name's")
    if not good or records != header.attrs.get("records"):
        raise SnapshotError(f"{path} is corrupted: its checksum does not match its "
                            f"shared contents")
    return header, fixed


def read_segment(path: Path, last: bool = False, number: int | None = None) -> Segment:
    """A segment and its rows, every checksum verified (see the module notes);
    ``last``: of its snapshots that read, the last only; ``number``: snapshot
    ``number`` alone (none where the segment does not hold it whole).  Either reads
    only the records it gives and those passed over (:func:`_read_back`).

    Raises
    ------
    SnapshotError
        When the segment's header or shared part does not read or check (then none
        of its snapshots can be trusted), naming the path.
    """
    if last or number is not None:
        seg = _read_back(path, number)
        if seg is not None:
            return seg
    header, data, fixed = _open(path)
    first, shared = _shared(path, header)
    seg = Segment(path, first, min(header.numrecs, len(data)))
    records, bad, torn = _records(header, data, last)
    seg.damaged = [(path, f"{path}: snapshot {first + k} is damaged ({why})")
                   for k, why in bad]
    if torn:
        seg.torn.append(path)
    rows, rows_torn = _rows(path.with_name(ROWS_NAME.format(first)))
    seg.torn += rows_torn
    _split(seg, shared, fixed, records, rows)
    return seg


def _shared(path: Path, header: Header) -> tuple[int, dict[str, Any]]:
    """A segment's first snapshot number and what its snapshots share."""
    try:
        return int(header.attrs["first"]), json.loads(header.attrs["meta"])
    except Exception as exc:  # (summed: only another program's file gets here)
        raise SnapshotError(f"{path} cannot be read as an archive segment ({exc})") from None


@held
def _read_back(path: Path, number: int | None = None) -> Segment | None:
    """:func:`read_segment` with ``last`` (``number`` None) or ``number``, reading
    only the bytes before the first record (checked as the whole file's are) and
    the records from the end back to the first that checks, with that one's own
    output rows (or snapshot ``number``'s record alone): O(snapshot), whatever the
    segment's length (a long run's archive loads at once).  The records passed over
    are listed as damaged; the earlier ones are not read.  None where the file's
    first bytes do not hold its header (the whole file is then read, which says
    why)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return None
    try:
        try:
            size, head = os.fstat(fd).st_size, _head(fd)
        except OSError:  # (not a file: a folder of a segment's name; the whole read says so)
            return None
        if head is None:
            return None
        try:
            header, fixed = _checked(path, head)
        except SnapshotError:  # (the whole read says why, or reads what it can)
            return None
        first, shared = _shared(path, header)
        seg = Segment(path, first, min(header.numrecs, size))
        begin, length = header.record_begin, header.record_size
        held = max(size - begin, 0) // max(length, 1)
        bad = [(held, f"the header counts {header.numrecs} records, the file holds {held}")
               ] if header.numrecs > held else []
        if size > begin + header.numrecs * length:
            seg.torn.append(path)
        rows_path = path.with_name(ROWS_NAME.format(first))
        count = min(header.numrecs, held)
        ks = range(count - 1, -1, -1) if number is None else (
            [number - first] if 0 <= number - first < count else [])
        for k in ks:
            rec = _record_at(header, head + os.pread(fd, length, begin + k * length), 0)
            if rec is None:
                bad.append((k, "its CRC-32 does not match"))
                continue
            before, end = (int(x) for x in rec["rows"])
            rows, torn = (None, []) if before == OWN_ROW else _rows_span(rows_path, before, end)
            rec["_index"] = np.int64(k)
            if before != OWN_ROW:
                rec["rows"] = np.array([0.0, end - before])
            _split(seg, shared, dict(fixed), [rec], rows)
            if seg.snapshots:
                seg.torn += torn
                break
    finally:
        os.close(fd)
    seg.damaged[:0] = [(path, f"{path}: snapshot {first + k} is damaged ({why})")
                       for k, why in sorted(bad)]
    return seg


@held
def _rows_span(path: Path, before: int, end: int) -> tuple[dict[str, np.ndarray] | None,
                                                             list[Path]]:
    """Rows ``before`` to ``end`` of a segment's companion file, as :func:`_rows`
    gives them all (None without the file; an empty dict where one of them, or the
    header, does not check), read alone, and the file if it ends in a torn write."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except FileNotFoundError:
        return None, []
    except OSError:
        return {}, []
    try:
        size, head = os.fstat(fd).st_size, _head(fd)
        try:
            header, _ = _checked(path, head)
        except SnapshotError:  # (the whole file read, as its header may still say)
            rows, torn = _rows(path)
            if rows is None or not rows or end > len(rows["out_t"]):
                return (None if rows is None else {}), torn
            return {n: a[before:end] for n, a in rows.items()}, torn
        begin, length = header.record_begin, header.record_size
        if end > min(header.numrecs, max(size - begin, 0) // length):
            return {}, []
        records = [_record_at(header, head + os.pread(fd, length, begin + j * length), 0)
                   for j in range(before, end)]
        if any(r is None for r in records):
            return {}, []
        out = _row_arrays(header, records)
        torn = size > begin + header.numrecs * length
    except Exception:  # a damaged header: no row can be trusted
        return {}, []
    finally:
        os.close(fd)
    return out, [path] if torn else []


def _split(seg: Segment, shared: dict[str, Any], fixed: dict[str, np.ndarray],
           records: list[dict[str, np.ndarray]], rows: dict[str, np.ndarray] | None) -> None:
    """Each record of ``seg`` as a snapshot's ``(number, meta, arrays)``, its output
    rows the ones of the rows file its record names."""
    leg_times = fixed.pop("leg_times", None)
    for rec in records:
        k = int(rec.pop("_index"))
        before, end = (int(x) for x in rec.pop("rows"))
        number = seg.first + k
        meta = {**shared, "t": float(rec["t"]), "steps": int(rec["steps"]), "number": number}
        if "leg" in rec:  # (format 3: the record's own leg, and its times at its start)
            leg, span = rec.pop("leg"), rec.pop("leg_span")
            if not np.isnan(leg[0]):
                meta["started"] = bool(leg[0])
            if not np.isnan(leg[1]):
                meta["leg"] = {"start": int(leg[1]), "first": bool(leg[2]),
                               "steps0": int(leg[3]), "unit": shared.get("unit"),
                               "first_event": int(leg[4])}
            if not np.isnan(span[0]):
                rec["leg_times"] = span
        arrays = {**fixed, **rec}
        arrays["t"] = np.float64(rec["t"])
        if k == 0 and leg_times is not None:
            arrays["leg_times"] = leg_times
        if before == OWN_ROW:  # (its one row its own state, format 4)
            arrays.update(out_t=arrays["t"].reshape(1), out_r=rec["r"][None], out_v=rec["v"][None])
            seg.snapshots.append((number, meta, arrays))
        elif (end > before and rows is None) or (rows is not None and (
                not rows or end > len(rows["out_t"]))):  # (its rows file gone, or short)
            seg.damaged.append((seg.path, f"{seg.path}: the output rows of snapshot "
                                          f"{number} are missing or damaged"))
        else:
            if rows is not None:
                arrays.update({n: a[before:end] for n, a in rows.items()})
            seg.snapshots.append((number, meta, arrays))


def _rows(path: Path) -> tuple[dict[str, np.ndarray] | None, list[Path]]:
    """The output rows of a segment's companion file up to the first that does not
    check (None without the file; an empty dict when its header is damaged: the
    segment's snapshots are then damaged), and the file if it ends in a torn
    write."""
    if not path.exists():
        return None, []
    try:
        header, data, _ = _open(path)
        records, bad, torn = _records(header, data)
        if bad:
            records = records[:bad[0][0]]
        out = _row_arrays(header, records)
    except Exception:  # a damaged header: no row can be trusted
        return {}, []
    return out, [path] if torn else []
