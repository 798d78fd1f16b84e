"""The archive a simulation writes while it runs, and its folder read back.

:class:`ArchiveWriter` is the schedule of an archive (every ``every`` of
simulation time, every ``every_steps`` steps, every ``every_wall`` seconds) and its
folder: snapshots appended to segments (:mod:`hamilton_orbits.segment`; format 1,
a file per snapshot, is still read), the folder claimed with a lock file (two
processes cannot write one archive; a lock left by a killed run is taken over), a
read-only folder or a full disk refused at the first write.  :class:`LegRows` are
the caller's output rows each snapshot carries; :func:`contents`,
:func:`snapshot_at` and :func:`last_snapshot` read a folder back.  What a snapshot
holds is :mod:`hamilton_orbits.simulation_record`'s.

Examples
--------
>>> import tempfile
>>> from hamilton_orbits import Body, Simulation, System
>>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
>>> folder = Path(tempfile.mkdtemp())
>>> _ = Simulation(s, method="radau15", archive=folder, every=1.0).integrate(3.0)
>>> [float(m["t"]) for _, _, m, _ in contents(folder).snapshots]
[0.0, 1.0, 2.0, 3.0]
"""

from __future__ import annotations

import json
import math
import os
import re
import struct
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hamilton_orbits._kernels.records import P_LAND, P_LAND_END, P_WRITTEN
from hamilton_orbits._netcdf3 import parse
from hamilton_orbits._outdir import FolderError, OutputFolder
from hamilton_orbits.integrators._held import held
from hamilton_orbits.restart import inline
from hamilton_orbits.segment import (
    NO_LEG,
    NO_SPAN,
    SEGMENT_NAME,
    SEGMENT_RE,
    Segment,
    SegmentWriter,
    read_segment,
)
from hamilton_orbits.snapshot import SnapshotError, read

__all__ = [
    "SNAPSHOT_NAME",
    "ArchiveWriter",
    "Contents",
    "LegRows",
    "contents",
    "holds_snapshots",
    "last_snapshot",
    "leg_rows",
    "on_step_grid",
    "path_of",
    "snapshot_at",
    "snapshot_files",
]

#: the layout of an archive folder: 1, a netCDF file per snapshot; 2, segments of
#: snapshots appended (:mod:`hamilton_orbits.segment`), one or more per leg; 3, a
#: segment continued across the legs of one writer; 4, a leg's first row kept as
#: its first record's state (no rows file for legs of a start and an end); every
#: version reads them all
ARCHIVE_VERSION = 4
SNAPSHOT_NAME = "snapshot-{:06d}.nc"
_SNAPSHOT_RE = re.compile(r"^snapshot-(\d{6})\.nc$")
_TORN_RE = re.compile(r"^\.(snapshot|segment|rows)-\d{6}\.nc\.tmp-\d+$")


class LegRows:
    """The caller's output rows of an archived ``integrate`` call (a *leg*), kept
    until the next snapshot takes them, and what resuming the leg needs.

    Every snapshot carries the rows asked for since the snapshot before (O(rows
    since then), never the whole history), and the number of the snapshot where
    its leg began, which carries the leg's output times: from them a leg
    interrupted by a kill is resumed and returned whole
    (:meth:`hamilton_orbits.Simulation.resume`).
    """

    def __init__(self, info: dict[str, Any], times: np.ndarray | None = None) -> None:
        #: number of the leg's first snapshot, time unit, steps and events before it,
        #: whether it began at time 0
        self.info = info
        #: the leg's output times (written in its first snapshot only)
        self.times = times
        self.rows: list[tuple[Any, ...]] = []

    def add(self, t: float, r: np.ndarray, v: np.ndarray, tangent: Any) -> None:
        """Output row at ``t`` (copied); ``tangent``: the variational equations."""
        row: tuple[Any, ...] = (t, r.copy(), v.copy())
        if tangent is not None:
            megno, lyapunov, lyapunov_time, stm = tangent.last
            row += (megno, lyapunov, lyapunov_time, None if stm is None else stm.copy())
        self.rows.append(row)

    def take(self) -> dict[str, np.ndarray]:
        """The rows since the last snapshot as arrays ``out_*`` (and the leg's times
        in its first snapshot), and start afresh."""
        rows, self.rows = self.rows, []
        out: dict[str, np.ndarray] = {}
        if self.times is not None:
            out["leg_times"], self.times = self.times, None
        out["out_t"] = np.array([x[0] for x in rows], dtype=np.float64)
        for k, name in ((1, "out_r"), (2, "out_v"), (3, "out_megno"), (4, "out_lyapunov"),
                        (5, "out_lyapunov_time"), (6, "out_stm")):
            if rows and len(rows[0]) > k and rows[0][k] is not None:
                out[name] = np.array([x[k] for x in rows], dtype=np.float64)
        return out


def leg_rows(folder: Path, start: int, upto: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The output times of the leg that began at snapshot ``start`` of archive
    ``folder`` and its rows archived up to snapshot ``upto`` (each file read once).

    Raises
    ------
    SnapshotError
        When one of those snapshots is missing or damaged (its rows are lost), naming
        the archive, the file that holds it (if one does) and what can be done.
    """
    files = snapshot_files(folder)
    found: dict[int, dict[str, np.ndarray]] = {}
    ends: dict[Path, int] = {}  # (the number after a file's snapshots, where it reads)
    for i, (first, path) in enumerate(files):
        after = files[i + 1][0] if i + 1 < len(files) else upto + 1
        if first > upto or after <= start:
            continue
        try:
            seg = _read_file(path)
        except SnapshotError:
            continue
        ends[path] = seg.first + seg.count
        found.update((k, arrays) for k, _, arrays in seg.snapshots if start <= k <= upto)
    parts: dict[str, list[np.ndarray]] = {}
    for k in range(start, upto + 1):
        if k not in found:
            raise SnapshotError(_lost_row(folder, files, ends, k))
        for name, a in found[k].items():
            if name.startswith("out_") and a.shape[0]:
                parts.setdefault(name, []).append(a)
    rows = {name: np.concatenate(a) for name, a in parts.items()}
    return found[start]["leg_times"], rows


def _lost_row(folder: Path, files: list[tuple[int, Path]], ends: dict[Path, int],
              k: int) -> str:
    """What a resume says of snapshot ``k`` of its call, missing or damaged in archive
    ``folder`` (``files`` by their first number, ``ends``: the number after each
    file's snapshots, for those that read): where it was, and what can be done."""
    holder = [path for first, path in files if first <= k]
    if holder and (holder[-1] not in ends or k < ends[holder[-1]]):
        where = f"damaged in {holder[-1]}"
    else:
        where = "missing: no file of the archive holds it"
    return (f"snapshot {k} of the call being resumed from the archive {folder} is {where}; "
            f"the call's rows it held are lost, so the call cannot be returned whole. Go on "
            f"without them from the archive's last snapshot (Simulation.load("
            f"{str(folder)!r}).integrate(t)), or from an earlier whole one (Archive("
            f"{str(folder)!r})[k], or Simulation.load(folder, number=n)) and integrate from it")


def on_step_grid(extra: np.ndarray, times: np.ndarray, dt: float,
                 spread: bool = False) -> np.ndarray:
    """Snapshot times ``extra`` moved to the end of the step at or after each, for a
    fixed-step method whose steps start afresh at each output time ``times`` (as
    :func:`hamilton_orbits.integrators._setup.fixed_steps` lays them: steps of
    ``dt``, the last shortened; ``spread``: as leapfrog lays them, the interval cut
    into the fewest equal steps of at most ``dt``): the run's steps are then its
    own, to the rounding of a step's length.

    Examples
    --------
    >>> on_step_grid(np.array([1.0, 2.5]), np.array([0.0, 3.0]), 0.3).round(12).tolist()
    [1.2, 2.7]
    >>> on_step_grid(np.array([1.0]), np.array([0.0, 2.6]), 0.3, spread=True).round(12).tolist()
    [1.155555555556]
    """
    k = np.clip(np.searchsorted(times, extra, side="right") - 1, 0, len(times) - 2)
    a, b = times[k], times[k + 1]
    step = (b - a) / np.maximum(np.ceil((b - a) / dt - 1e-12), 1.0) if spread else dt
    moved = a + np.ceil((extra - a) / step * (1.0 - 1e-12)) * step
    return np.unique(np.where(moved >= b, b, moved))


def leg_times_of(folder: Path, start: int) -> np.ndarray | None:
    """The output times of the leg that began at snapshot ``start`` of archive
    ``folder`` (held by that snapshot), or None where it does not read."""
    found = snapshot_at(folder, start)
    times = None if found is None else found[2].get("leg_times")
    return None if times is None else np.asarray(times, dtype=np.float64)


def path_of(path: Any, name: str, what: str) -> Path:
    """``path`` as a Path, refused by name (the argument ``name``, ``what`` it should
    be) when it is not a path or is empty."""
    if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
        raise ValueError(f"Expected `{name}` to be {what}, got {path!r}")
    return Path(path)


def snapshot_files(folder: Path) -> list[tuple[int, Path]]:
    """The files of an archive folder by the number of their (first) snapshot:
    snapshot files (format 1) and segments (format 2).  (The names are matched as
    the folder lists them; only the files found are made paths.)"""
    found = []
    for name in os.listdir(folder) if folder.is_dir() else ():
        m = _SNAPSHOT_RE.match(name) or SEGMENT_RE.match(name)
        if m:
            found.append((int(m.group(1)), folder / name))
    return sorted(found)


def _read_file(path: Path, last: bool = False, number: int | None = None) -> Segment:
    """A file of an archive folder as a segment (a snapshot file: one snapshot);
    ``last``: of a segment's snapshots that read, the last only; ``number``: that
    snapshot alone (a segment's other records not read)."""
    if SEGMENT_RE.match(path.name):
        return read_segment(path, last, number)
    meta, arrays = read(path)
    number = int(meta.get("number", _SNAPSHOT_RE.match(path.name).group(1)))
    return Segment(path, number, 1, [(number, meta, arrays)])


def _whole(meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> tuple[
        dict[str, Any], dict[str, np.ndarray]]:
    """A snapshot of a segment as a snapshot file holds it: the numbers of its state
    put back into its layout."""
    if "scalars" not in arrays:
        return meta, arrays
    arrays = dict(arrays)
    return dict(meta, layout=inline(meta["layout"], arrays.pop("scalars"))), arrays


@dataclass
class Contents:
    """What an archive folder holds: its snapshots ``(number, file, meta, arrays)``,
    the files or records that do not read (with the reason) and the torn writes."""

    snapshots: list[tuple[int, Path, dict[str, Any], dict[str, np.ndarray]]]
    damaged: list[tuple[Path, str]]
    torn: list[Path]


def contents(folder: Path, keep: tuple[str, ...] | None = None) -> Contents:
    """Every snapshot of archive ``folder``, each checked (``keep``: keep only these
    arrays of each, to hold a long archive in memory)."""
    out = Contents([], [], sorted(p for p in folder.iterdir() if _TORN_RE.match(p.name)))
    after: int | None = 0  # (the number after the last file's snapshots, where known)
    for first, path in snapshot_files(folder):
        try:
            seg = _read_file(path)
        except SnapshotError as exc:  # (its damage said: no gap told before or after it,
            out.damaged.append((path, str(exc)))  # how many it held not known)
            after = None
            continue
        if after is not None and first > after:
            out.damaged.append((folder, _missing(folder, after, first - 1)))
        after = seg.first + seg.count
        out.damaged += seg.damaged
        out.torn += seg.torn
        for number, meta, arrays in seg.snapshots:
            if keep is not None:
                arrays = {k: arrays[k] for k in keep}
            out.snapshots.append((number, path, meta, arrays))
    return out


def _missing(folder: Path, a: int, b: int) -> str:
    """What a gap in an archive's numbers, snapshots ``a`` to ``b``, says: no file
    of the folder holds them (a writer numbers its snapshots on from the folder's
    last one: a gap is a file removed or moved)."""
    which = f"snapshot {a} is" if a == b else f"snapshots {a} to {b} are"
    return (f"{folder}: {which} missing: no file of the archive holds them (a file "
            f"removed or moved away?)")


def snapshot_at(folder: Path, number: int) -> tuple[Path, dict[str, Any],
                                                     dict[str, np.ndarray]] | None:
    """Snapshot ``number`` of archive ``folder`` (file, meta, arrays), or None when it
    is missing or does not read."""
    files = [(first, p) for first, p in snapshot_files(folder) if first <= number]
    for _, path in reversed(files):
        try:
            seg = _read_file(path, number=number)
        except SnapshotError:
            continue
        for k, meta, arrays in seg.snapshots:
            if k == number:
                return (path, *_whole(meta, arrays))
        if seg.first <= number < seg.first + seg.count:
            return None  # its file holds it, damaged
    return None


def holds_snapshots(folder: Path) -> bool:
    """Whether archive ``folder`` holds a snapshot (whole or not): a run's to resume,
    which a new run is refused.  A segment begun by a run killed (or stopped by a
    full disk) before its first snapshot was written holds none: a new run replaces
    it."""
    return _next_number(Path(folder)) > 0


def _next_number(folder: Path) -> int:
    """The number after the last snapshot of archive ``folder``."""
    files = snapshot_files(folder)
    if not files:
        return 0
    first, path = files[-1]
    if not SEGMENT_RE.match(path.name):
        return first + 1
    try:  # (a segment of no snapshot, begun by a killed run, is replaced)
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
            try:
                header = parse(head)
            except (ValueError, struct.error):  # a header longer than that
                header = parse(head + fh.read())
        held = (path.stat().st_size - header.record_begin) // max(header.record_size, 1)
        return first + max(min(header.numrecs, held), 0)
    except (OSError, ValueError, struct.error):
        return first + 1


def _signature(path: Path) -> tuple[int, int, int] | None:
    """What tells a file of an archive from another of the same name: its inode, size
    and time of last change (in ns); None where it is not there.  (Not the folder's
    inode alone: a folder removed and made again at once gets the same one.)"""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_ino, st.st_size, st.st_mtime_ns


#: the most snapshots of ``every`` in one ``integrate`` call: 10 GB on disk at
#: least (about a kilobyte each), their times 80 MB in memory
MAX_SNAPSHOTS = 10**7


#: the largest finite float64
_FLOAT_MAX = 1.7976931348623157e308


class ArchiveWriter:
    """The schedule and folder of an archive written while a simulation runs.

    Parameters
    ----------
    path : path or None
        The archive folder (created if missing); None: the schedule only, nothing
        written (a snapshot of an archived run loaded alone keeps its run's output
        times, so that it continues with that run's bits).
    every : float, optional
        A snapshot at every multiple of this interval of simulation time (in the
        simulation's internal time unit: days for a Quantity system), counted from
        ``origin``.
    every_steps : int, optional
        A snapshot every ``every_steps`` steps: between two steps for a driver
        that can pause there (radau15's in double precision), else at the first
        output after.
    every_wall : float, optional
        A snapshot at the first look at the clock after every ``every_wall``
        seconds: at the outputs, and between two steps for a driver that can
        pause there (radau15's in double precision, every 10 000 steps).
    origin : float
        The time the simulation time schedule counts from.
    exact : bool
        Snapshots at exactly the scheduled times (a fixed-step method shortens the
        step before each); False: at the end of the step at or after each (see
        :func:`on_step_grid`).
    sync : bool
        Sync each snapshot to the disk before it counts (survives a power cut, not
        only a killed process; about 10 ms a snapshot on a common disk, against
        under 1 ms without).
    """

    def __init__(self, path: str | Path | None, *, every: float | None = None,
                 every_steps: int | None = None, every_wall: float | None = None,
                 origin: float = 0.0, sync: bool = False, exact: bool = True) -> None:
        given = [k for k, x in (("every", every), ("every_steps", every_steps),
                                ("every_wall", every_wall)) if x is not None]
        if len(given) != 1:
            raise ValueError(f"An archive takes one of `every`, `every_steps`, `every_wall`, "
                             f"got {', '.join(given) or 'none'}")
        for name, x in (("every", every), ("every_wall", every_wall)):
            if x is not None and not (isinstance(x, (int, float)) and not isinstance(x, bool)
                                      and 0 < x <= _FLOAT_MAX):  # (an int beyond
                # float64 compares, where math.isfinite would overflow)
                raise ValueError(f"Expected `{name}` > 0 and finite, got {x!r}")
        if every_steps is not None and (isinstance(every_steps, bool)
                                        or not isinstance(every_steps, (int, np.integer))
                                        or every_steps < 1):
            raise ValueError(f"Expected `every_steps` to be a whole number >= 1, got "
                             f"{every_steps!r}")
        every_steps = None if every_steps is None else int(every_steps)  # (kept as JSON)
        self.path = None if path is None else path_of(path, "archive", "a folder's path").absolute()
        # (made absolute once: a relative folder is the one of the directory it was
        # given in, whatever directory a later call is made from)
        self.every, self.every_steps, self.every_wall = every, every_steps, every_wall
        if not isinstance(exact, bool):
            raise ValueError(f"Expected `exact_times` to be True or False, got {exact!r}")
        self.origin, self.sync, self.exact = float(origin), sync, exact
        self.folder: OutputFolder | None = None
        #: the segment being appended to
        self.segment: SegmentWriter | None = None
        self.count = 0
        #: the last segment this writer closed: its path, its size and the number
        #: after its last snapshot (:meth:`_continued`)
        self.left: tuple[Path, int, int] | None = None
        #: that segment, when its records hold their leg: the next leg goes on in it
        #: if it is there as it was left
        self.parked: SegmentWriter | None = None
        #: the number of the snapshot a simulation loaded from the folder stands at,
        #: until this writer has written there (:meth:`_gone_on`: after that, its
        #: last segment is what tells another writer's coming)
        self.loaded: int | None = None
        #: the files of the folder this writer closed, or its simulation was loaded
        #: from, each as it left it (:func:`_signature`): a folder that holds
        #: snapshots and none of them is no longer this run's (removed and used
        #: again by another run: :meth:`open` refuses it)
        self.mine: dict[Path, tuple[int, int, int] | None] = {}
        #: the leg of the snapshots being appended (a record's ``leg``)
        self.leg: tuple[float, ...] = NO_LEG
        #: the wall clock of ``every_wall`` (seconds)
        self.clock: Callable[[], float] = time.monotonic
        #: the snapshots already in the folder are this writer's run's (it wrote them,
        #: or its simulation was loaded from the folder): appended to; otherwise a
        #: folder holding snapshots is refused (another run's: the two would mix)
        self.continues = False
        #: the folder was made by this writer's claim and no segment begun in it yet
        self.fresh = False
        self.last_steps, self.last_wall = 0, self.clock()

    def schedule_only(self) -> ArchiveWriter:
        """The same schedule writing nothing (for a copy of the simulation)."""
        sched = {k: getattr(self, k) for k in ("every", "every_steps", "every_wall", "sync",
                                               "exact")}
        out = ArchiveWriter(None, origin=self.origin, **sched)
        out.last_steps = self.last_steps
        return out

    def schedule(self) -> dict[str, Any]:
        """The schedule as JSON-able values (kept in every snapshot)."""
        return {"path": None if self.path is None else str(self.path), "every": self.every,
                "every_steps": self.every_steps, "every_wall": self.every_wall,
                "origin": self.origin, "sync": self.sync, "exact": self.exact}

    @held
    def open(self) -> None:
        """Claim the folder (lock) and find the next snapshot number."""
        if self.folder is not None or self.path is None:
            return
        folder = OutputFolder(self.path, "archive")
        try:
            folder.__enter__()
        except FolderError as exc:
            raise SnapshotError(str(exc).replace("; nothing was run", "")) from None
        except BaseException:  # (Ctrl-C as the lock was taken: released if it is this one's)
            folder.__exit__(None, None, None)
            raise
        self.folder = folder
        known = self._continued()
        #: a folder this claim made holds no file of a snapshot: none listed, and no
        #: file of the first segment's number replaced (:class:`SegmentWriter`'s
        #: ``fresh``) until one is begun
        self.fresh = folder.made
        self.count = (0 if folder.made else _next_number(self.path)) if known is None else known
        if known is None and self.count and self.mine and not self._holds_mine():
            self._refuse_replaced()  # (read only where the folder is not as left)
        if known is None and self._gone_on():
            self.close()
            raise SnapshotError(
                f"the archive {self.path} has gone on without this simulation: another "
                f"simulation (loaded from it, or writing it as well) wrote its snapshots from "
                f"number {self.left[2] if self.left else self.loaded + 1} on; continue from "
                f"the archive's last snapshot with Simulation.load({str(self.path)!r}), or "
                f"give this simulation another folder")
        if self.count and not self.continues:
            self.close()
            raise SnapshotError(
                f"the archive {self.path} holds the snapshots of another run (the last "
                f"numbered {self.count - 1}); continue that run with Simulation.load("
                f"{str(self.path)!r}), or give this simulation another folder")
        self.continues = True
        parked, self.parked = self.parked, None
        if known is not None and parked is not None and parked.reopen():
            self.segment = parked  # (the next leg goes on in it, if it shares the same)

    def loaded_from(self, number: int, path: Path) -> None:
        """Attach this writer to the folder its simulation was loaded from, standing at
        snapshot ``number`` (:attr:`loaded`) of its file ``path`` (one of the run's,
        :attr:`mine`)."""
        self.loaded = number
        self.mine[path] = _signature(path)

    def _holds_mine(self) -> bool:
        """Whether one of the files this writer left (:attr:`mine`) is in the folder
        as it left it: the folder is still its run's (a file of it removed, say; not
        removed as a whole and made again by another run)."""
        return any(known is not None and _signature(path) == known
                   for path, known in reversed(self.mine.items()))

    def _refuse_replaced(self) -> None:
        """Release the folder and refuse it: it holds snapshots and none of the files
        this writer left there, so it is no longer the folder of this run (removed,
        and made again by another run)."""
        self.close()
        raise SnapshotError(
            f"the archive {self.path} is no longer the folder this simulation wrote: its "
            f"files are gone, and it holds the snapshots of another run now (the last "
            f"numbered {self.count - 1}; the folder removed and written again?), which "
            f"this simulation's would mix with (one archive holds one run); continue that "
            f"run with Simulation.load({str(self.path)!r}), and this simulation from a copy "
            f"(sim.copy(), which writes nothing) or a file (sim.save(path))")

    def _continued(self) -> int | None:
        """The next snapshot number without listing the folder (whose listing grows
        with the archive: one segment per call), when the last segment this writer
        closed is there as it left it and no file holds that number yet (no other
        writer came after it: a writer begins a segment of its own at the folder's
        next number); None otherwise, and the folder is read."""
        if self.left is None:
            return None
        path, size, count = self.left
        try:
            if os.stat(path).st_size != size:
                return None
        except OSError:
            return None
        if self._numbered(count):
            return None
        return count

    def _gone_on(self) -> bool:
        """Whether another writer has written in the folder after this one's last
        snapshot (a snapshot file begun at the number after it), or after the
        snapshot this writer's simulation was loaded from (a whole snapshot after it:
        a damaged or torn one after it is the run's own, passed over by the load):
        its snapshots would interleave with that writer's."""
        if self.left is not None:
            return self._numbered(self.left[2])
        if self.loaded is not None and self.count > self.loaded + 1:
            return snapshot_at(self.path, self.count - 1) is not None
        return False

    def _numbered(self, count: int) -> bool:
        """Whether the folder holds a file (a segment, or a file of format 1) that
        begins at snapshot number ``count``."""
        folder = os.fspath(self.path)
        return any(os.path.exists(os.path.join(folder, name.format(count)))
                   for name in (SEGMENT_NAME, SNAPSHOT_NAME))

    @held
    def close(self) -> None:
        """Close the segment being written and release the folder's lock (again after
        a Ctrl-C amid them: the segment let go before its files are closed, the lock
        after it is released)."""
        seg, self.segment = self.segment, None
        try:
            if seg is not None:
                self.left, self.loaded = (seg.path, seg.size, self.count), None
                self.parked = seg if seg.legs else None
                seg.close()
                self.mine[seg.path] = _signature(seg.path)  # (one stat a call)
        finally:
            if self.folder is not None:
                self.folder.__exit__(None, None, None)
                self.folder = None

    @held
    def lost(self) -> None:
        """After a snapshot whose writing did not end (Ctrl-C, an error): the segment
        cut back to its counted records, closed and left, so that the next snapshot
        begins a segment of its own at the folder's next number, read from its files
        (the counts kept here may be behind them: a record written and counted in the
        file, not yet here)."""
        seg, self.segment = self.segment, None
        self.left = self.parked = None
        if seg is not None:
            try:
                seg.trim()  # (no torn tail left by a write this process broke off)
            finally:
                seg.close()
                self.mine[seg.path] = _signature(seg.path)

    def times(self, t0: float, t1: float) -> np.ndarray:
        """The scheduled snapshot times in ``(t0, t1]`` (simulation time schedule)."""
        span = self.scheduled(t0, t1)
        if span is None:
            return np.empty(0)
        ts = self.origin + self.every * np.arange(span[0], span[1] + 1, dtype=np.float64)
        return ts[(ts > t0) & (ts <= t1)]

    def scheduled(self, t0: float, t1: float) -> tuple[int, int] | None:
        """The multiples ``(k0, k1)`` of ``every`` from ``origin`` in ``(t0, t1]``
        (None without ``every``, or backwards).

        Raises
        ------
        ValueError
            When more than :data:`MAX_SNAPSHOTS` fall in it (``every`` named): asked
            before the call writes its first snapshot.
        """
        if self.every is None or not t1 > t0:
            return None
        n = (t1 - t0) / self.every  # (inf where it overflows: refused as well)
        if not n <= MAX_SNAPSHOTS - 1:
            raise ValueError(
                f"Expected `every` to schedule at most {MAX_SNAPSHOTS:.0e} snapshots in one "
                f"call, got every={self.every!r}: {n:.3g} snapshots from t = {t0!r} to "
                f"{t1!r} (in the simulation's time unit: days for a system of Quantities); "
                f"choose a longer `every`, or integrate in shorter calls")
        return (math.floor((t0 - self.origin) / self.every) + 1,
                math.floor((t1 - self.origin) / self.every))

    def due(self, steps: int) -> bool:
        """True if a steps or wall-clock snapshot is due after ``steps`` steps."""
        if self.every_steps is not None:
            return steps - self.last_steps >= self.every_steps
        if self.every_wall is not None:
            return self.clock() - self.last_wall >= self.every_wall
        return False

    @held
    def write(self, meta: dict[str, Any], arrays: Mapping[str, np.ndarray],
              dims: Mapping[str, tuple[str, ...]], units: Mapping[str, str]) -> Path | None:
        """Append the next snapshot (numbered after the last one in the folder) to the
        segment being written, a new leg's too, or begin a segment (a change in what
        the snapshots share, a leg of more output times than its end); nothing
        without a folder.  Returns the segment's path."""
        self.open()
        if self.path is None:
            return None
        shared = {k: x for k, x in meta.items() if k not in ("t", "steps", "leg", "started")}
        shared["archive"] = self.schedule()
        self.leg, times = _record_leg(meta), arrays.get("leg_times")
        # (a leg's times in its first record when they are its start and its end; more
        # of them are a fixed variable of a segment that leg begins)
        span = tuple(float(x) for x in times) if times is not None and len(times) == 2 else NO_SPAN
        arrays = {**{k: x for k, x in arrays.items() if k != "leg_times" or span is NO_SPAN},
                  "steps": meta["steps"], "leg": self.leg, "leg_span": span}
        seg = self.segment
        if seg is None or "leg_times" in arrays or not _same(seg, shared):
            if seg is not None:
                seg.close()
            fixed = {k: x for k, x in arrays.items()
                     if k.startswith("initial_") or k == "leg_times"}
            fresh, self.fresh = self.fresh, False
            seg = self.segment = SegmentWriter(self.path, self.count, shared, fixed, arrays,
                                               dims, units, self.sync, fresh=fresh)
        seg.shared = shared  # (equal: its parts now the ones a next snapshot may share)
        self.append(arrays, {k: x for k, x in arrays.items() if k.startswith("out_")})
        return seg.path

    @held
    def refill(self, t: float, r: np.ndarray, v: np.ndarray, gm: np.ndarray,
               active: np.ndarray, state: list[np.ndarray], scalars: list[Any], steps: int,
               ints: list[int]) -> bool:
        """Append the snapshot after the last of the same arrays, their values changed
        in place (:meth:`~hamilton_orbits.segment.SegmentWriter.refill`); False,
        nothing written, where it cannot."""
        if self.segment is None or not self.segment.refill(t, r, v, gm, active, state,
                                                           scalars, steps, ints):
            return False
        self.count, self.loaded = self.count + 1, None  # (written: its own from here)
        self.last_steps, self.last_wall = steps, self.clock()
        return True

    def compiled_plan(self, arrays: Mapping[str, np.ndarray],
                      aliases: list[tuple[np.ndarray, str]], t_at: tuple[str, int],
                      steps: int, times: np.ndarray | None = None,
                      ) -> tuple[np.ndarray, tuple[Any, ...]] | None:
        """The plan with which a stepping kernel appends the next ``every_steps``
        snapshots itself (:meth:`~hamilton_orbits.segment.SegmentWriter.compiled_plan`),
        or, given ``times`` (an ``every`` schedule's, increasing), those at these
        simulation times, landing on each (the times after the plan's runs, from
        ``P_LAND`` to ``P_LAND_END``: :func:`~hamilton_orbits._kernels.records.
        next_landing`); or None."""
        if self.segment is None or (self.every_steps if times is None else self.every) is None:
            return None
        made = self.segment.compiled_plan(arrays, aliases, t_at, steps, self.every_steps or 0)
        if made is None or times is None:
            return made
        plan = np.concatenate([made[0], np.ascontiguousarray(times, np.float64).view(np.int64)])
        plan[P_LAND], plan[P_LAND_END] = made[0].size, plan.size
        return plan, made[1]

    @held
    def compiled_wrote(self, plan: np.ndarray, last_steps: int) -> None:
        """Count the snapshots a kernel appended with ``plan`` (the last after
        ``last_steps`` steps of the simulation)."""
        self.segment.compiled_wrote(plan)
        self.count, self.loaded = self.count + int(plan[P_WRITTEN]), None
        self.last_steps, self.last_wall = last_steps, self.clock()

    @held
    def append_leg(self, values: Mapping[str, Any], rows: dict[str, np.ndarray],
                   meta: Mapping[str, Any]) -> None:
        """Append a leg's first snapshot to the segment being written, which its
        last leg wrote (format 3) and whose shared part it shares: as :meth:`append`,
        its record holding the leg that ``meta`` gives (``started``, ``leg``: as a
        whole snapshot's ``meta``) and the leg's start and end (``rows``'
        ``leg_times``, taken out of them)."""
        span = tuple(float(x) for x in rows.pop("leg_times"))
        self.leg = _record_leg(meta)
        self.append({**values, "leg": self.leg, "leg_span": span}, rows)

    @held
    def append(self, values: Mapping[str, Any], rows: Mapping[str, np.ndarray]) -> None:
        """Append a snapshot that shares everything but ``values`` (its record: ``t``,
        ``steps``, ``r``, ... as :func:`state_values` gives them) and its output ``rows``
        with the last one, to the segment being written (in the same leg)."""
        if "leg" not in values:
            values = {**values, "leg": self.leg, "leg_span": NO_SPAN}
        self.segment.append(values, rows)
        self.count, self.loaded = self.count + 1, None  # (written: its own from here)
        self.last_steps, self.last_wall = int(values["steps"]), self.clock()


def _record_leg(meta: Mapping[str, Any]) -> tuple[float, ...]:
    """A record's ``leg`` (:data:`~hamilton_orbits.segment.NO_LEG`) from what a
    snapshot's ``meta`` says of its ``integrate`` call."""
    started = float(meta["started"]) if "started" in meta else math.nan
    leg = meta.get("leg")
    if leg is None:
        return (started, *NO_LEG[1:])
    return (started, float(leg["start"]), float(leg["first"]), float(leg["steps0"]),
            float(leg["first_event"]))


def _same(seg: SegmentWriter, shared: dict[str, Any]) -> bool:
    """Whether a snapshot sharing ``shared`` belongs in segment ``seg`` (compared as
    values, then as JSON text: a NaN is not equal to itself)."""
    return seg.shared == shared or seg.text == json.dumps(shared, sort_keys=True,
                                                           allow_nan=True)


def last_snapshot(folder: str | Path) -> tuple[Path, dict[str, Any], dict[str, np.ndarray]]:
    """The last snapshot of archive ``folder`` that reads whole (file, meta, arrays):
    a damaged last one is passed over for the one before.

    Raises
    ------
    SnapshotError
        When the folder has no snapshot that reads, naming it.
    """
    folder = Path(folder)
    problems = []
    for _, path in reversed(snapshot_files(folder)):
        try:
            seg = _read_file(path, last=True)
            if not seg.snapshots and seg.count:  # (the last one's rows damaged: all)
                seg = _read_file(path)
        except SnapshotError as exc:
            problems.append(str(exc))
            continue
        problems += [why for _, why in seg.damaged]
        if seg.snapshots:
            _, meta, arrays = seg.snapshots[-1]
            return (path, *_whole(meta, arrays))
    why = f" ({'; '.join(problems)})" if problems else ""
    raise SnapshotError(f"no readable snapshot in the archive {folder}{why}")
