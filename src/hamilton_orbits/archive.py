"""Reading an archive: the snapshots a simulation wrote while it ran.

``Simulation(system, ..., archive="run.archive", every=1000 * u.yr)`` writes a
snapshot at every multiple of ``every`` (``docs/archive.md``); :class:`Archive`
opens the folder, lists the snapshots that read whole (each one's checksum
verified), says which were torn by a killed write or damaged afterwards, returns
any snapshot as a :class:`~hamilton_orbits.simulation.Simulation`, and opens the
whole as an ``xarray.Dataset`` (the ``archive`` extra).  ``Simulation.load``
of the folder continues the run from its last snapshot, on the same schedule.

Examples
--------
>>> import tempfile
>>> import numpy as np
>>> from hamilton_orbits import Body, Simulation, System
>>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
>>> with tempfile.TemporaryDirectory() as tmp:
...     sim = Simulation(s, method="wh", dt=0.01, archive=tmp, every=1.0)
...     _ = sim.integrate(3.5)
...     archive = Archive(tmp)
...     middle = archive[2]              # the snapshot at t = 2, as a Simulation
...     _ = middle.integrate(3.5)
...     print(len(archive), archive.times.tolist(), middle.steps == sim.steps)
4 [0.0, 1.0, 2.0, 3.0] True
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hamilton_orbits._outdir import live_holder
from hamilton_orbits._saving import RestartWarning
from hamilton_orbits.checkpoint import contents, path_of, snapshot_files
from hamilton_orbits.segment import ROWS_NAME
from hamilton_orbits.simulation import Simulation
from hamilton_orbits.snapshot import SnapshotError

__all__ = ["Archive", "ArchiveIndexError", "RestartWarning", "Snapshot", "SnapshotError"]


class ArchiveIndexError(IndexError, ValueError):
    """An index that is not the position of one of an archive's snapshots (an
    ``IndexError``, which ends a loop over the archive, and a ``ValueError``, as
    other bad input)."""


@dataclass(frozen=True)
class Snapshot:
    """One snapshot of an archive: its number, file (a segment holds many),
    simulation time and steps."""

    number: int
    path: Path
    t: float
    steps: int


class Archive:
    """The snapshots of an archive folder.

    Parameters
    ----------
    path : path
        The folder a simulation with ``archive=path`` wrote.

    Attributes
    ----------
    snapshots : list of Snapshot
        The snapshots that read whole, in the order written.
    damaged : list of (Path, str)
        Files or snapshots that do not read (a flipped byte, a truncated file), and
        snapshot numbers no file holds (a file removed), with the reason: never read
        as data.
    torn : list of Path
        Files ending in a write that never finished (the process was killed while
        writing): the snapshot it was to become does not exist, and those bytes are
        never read.
    writing : int or None
        The PID of a live run of this machine writing into the folder now (its
        lock held), else None.
    in_progress : list of Path
        That run's newest files, whose last write was still going on as they were
        read (they would otherwise be listed as torn); the snapshots before it are
        read as any.

    Raises
    ------
    SnapshotError
        When ``path`` is not a folder.
    """

    def __init__(self, path: str | Path) -> None:
        # (absolute: its snapshots are read later, from whatever directory)
        self.path = path_of(path, "path", "an archive folder's path").absolute()
        if not self.path.is_dir():
            raise SnapshotError(f"no archive folder {self.path}")
        before = live_holder(self.path)  # (and after: a call may begin or end meanwhile)
        found = contents(self.path, keep=("t", "r", "v", "gm", "active"))
        self.snapshots = [Snapshot(number, file, float(meta["t"]), int(meta["steps"]))
                          for number, file, meta, _ in found.snapshots]
        self.damaged: list[tuple[Path, str]] = found.damaged
        self.writing = live_holder(self.path) or before
        self.torn, self.in_progress = _in_progress(self.path, found.torn, self.writing)
        self._arrays = [arrays for *_, arrays in found.snapshots]
        last = found.snapshots[-1][2] if found.snapshots else None
        self._names: tuple[str, ...] = () if last is None else tuple(last["system"]["names"])
        self._quantity = False if last is None else bool(last["system"]["quantity"])

    def __len__(self) -> int:
        return len(self.snapshots)

    @property
    def times(self) -> np.ndarray:
        """The simulation times of the snapshots (days for a Quantity system)."""
        return np.array([s.t for s in self.snapshots])

    def __getitem__(self, k: int) -> Simulation:
        """Snapshot ``k`` (of :attr:`snapshots`; negative from the end) as a
        Simulation, not attached to the archive (``Simulation.load(folder)``
        continues the archive itself).

        Raises
        ------
        ArchiveIndexError
            (an ``IndexError`` and a ``ValueError``) When ``k`` is not an integer or
            not the position of a snapshot, naming it and the archive.
        """
        n = len(self.snapshots)
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise ArchiveIndexError(f"Expected the index of an archive's snapshot to be an "
                                    f"integer, got {k!r} ({self.path})")
        if not -n <= k < n:
            raise ArchiveIndexError(f"Archive index {int(k)} out of range: {self.path} holds "
                                    f"{n} snapshots")
        return Simulation.load(self.path, number=self.snapshots[k].number)

    def __repr__(self) -> str:
        span = (f"t = {float(self.times[0])!r} ... {float(self.times[-1])!r}" if self.snapshots
                else "empty")
        more = "".join(f", {len(x)} {what}" for x, what in ((self.damaged, "damaged"),
                                                           (self.torn, "torn")) if x)
        return f"Archive({str(self.path)!r}: {len(self)} snapshots, {span}{more})"

    def to_xarray(self) -> Any:
        """The snapshots' states as an ``xarray.Dataset`` (dimensions ``time``,
        ``body``, ``xyz``; variables ``r``, ``v``, ``gm``, ``active``; body names
        as a coordinate; units in the attributes for a Quantity system).

        A snapshot that repeats the one before it (the same time, step count and
        state, bit for bit: the first snapshot of an ``integrate`` call whose call
        before ended on a scheduled snapshot) is in it once, so that the times
        are those of distinct states; ``snapshots`` lists both.

        Raises
        ------
        SnapshotError
            For an archive of no whole snapshot, or one whose snapshots hold
            different numbers of bodies (not of one run), naming it.
        """
        try:
            import xarray as xr
        except ImportError:
            raise ImportError("Archive.to_xarray needs xarray: pip install "
                              "'hamilton-orbits[archive]'") from None
        shapes = {a["r"].shape for a in self._arrays}
        if len(shapes) != 1:  # (none, or of two runs: an archive holds one run's)
            raise SnapshotError(
                f"the archive {self.path} has no whole snapshot to put in a Dataset"
                if not shapes else f"the snapshots of the archive {self.path} hold different "
                f"numbers of bodies ({', '.join(str(x[0]) for x in sorted(shapes))}): they "
                f"are not of one run")
        stack = {k: np.stack([a[k] for a in self._arrays]) for k in ("r", "v", "gm", "active")}
        times, steps = self.times, np.array([s.steps for s in self.snapshots], dtype=np.int64)
        keep = ~_repeats(times, steps, stack)
        units = ({"r": "au", "v": "au/day", "gm": "au3/day2", "time": "day"}
                 if self._quantity else {})
        data = {"r": (("time", "body", "xyz"), stack["r"][keep], _units(units, "r")),
                "v": (("time", "body", "xyz"), stack["v"][keep], _units(units, "v")),
                "gm": (("time", "body"), stack["gm"][keep], _units(units, "gm")),
                "active": (("time", "body"), stack["active"][keep])}
        coords = {"time": ("time", times[keep], _units(units, "time")),
                  "body": ("body", list(self._names)), "xyz": ("xyz", ["x", "y", "z"]),
                  "steps": ("time", steps[keep])}
        return xr.Dataset(data, coords=coords, attrs={"archive": str(self.path)})


def _in_progress(folder: Path, torn: list[Path],
                 writing: int | None) -> tuple[list[Path], list[Path]]:
    """``torn`` split into the files torn and those a live writer (PID ``writing``)
    is writing: its temporary files and the newest numbered files of the folder
    (a segment and its rows), whose last record is being appended as they are read."""
    if writing is None or not torn:
        return torn, []
    files = snapshot_files(folder)
    newest = {files[-1][1], folder / ROWS_NAME.format(files[-1][0])} if files else set()
    live = [p for p in torn if p.name.endswith(f".tmp-{writing}") or p in newest]
    return [p for p in torn if p not in live], live


def _repeats(times: np.ndarray, steps: np.ndarray, stack: dict[str, np.ndarray]) -> np.ndarray:
    """Which snapshots repeat the one before them: the same time and step count and
    the same arrays of ``stack``, bit for bit (a NaN equal to itself)."""
    same = np.zeros(times.shape[0], dtype=bool)
    if times.shape[0] < 2:
        return same
    same[1:] = (times[1:] == times[:-1]) & (steps[1:] == steps[:-1])
    for a in stack.values():
        bits = a.reshape(a.shape[0], -1)
        bits = bits.view(np.uint64) if bits.dtype == np.float64 else bits
        same[1:] &= (bits[1:] == bits[:-1]).all(axis=1)
    return same


def _units(units: dict[str, str], name: str) -> dict[str, str]:
    return {"units": units[name]} if name in units else {}
