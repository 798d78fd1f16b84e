"""Saving, loading, archives and resuming: the part of
:class:`~hamilton_orbits.simulation.Simulation` that never loses a run
(``docs/archive.md``).

:class:`Saving` is a mixin of ``Simulation``: ``save`` and ``load`` (a snapshot
file, or the last snapshot of an archive folder), the archive written while it
integrates (a leg's first snapshot, the scheduled ones, the caller's rows in each)
and ``resume`` (the ``integrate`` call a kill interrupted, finished and returned
whole).  The state itself is flattened by :mod:`hamilton_orbits.restart`, written
by :mod:`hamilton_orbits.snapshot` and scheduled by
:mod:`hamilton_orbits.checkpoint`.
"""

from __future__ import annotations

import copy
import math
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits._legs import leg_run
from hamilton_orbits._output_memory import check_output_memory
from hamilton_orbits.checkpoint import (
    ArchiveWriter,
    LegRows,
    last_snapshot,
    leg_rows,
    leg_times_of,
    on_step_grid,
    path_of,
    snapshot_at,
)
from hamilton_orbits.integrators import method_of
from hamilton_orbits.integrators.methods import FIXED_STEP
from hamilton_orbits.nbody import DAY, System
from hamilton_orbits.restart import LayoutMismatch, restore
from hamilton_orbits.simulation_record import all_active, record, spec, state_values
from hamilton_orbits.snapshot import SnapshotError, read, write
from hamilton_orbits.trajectory import Trajectory
from hamilton_orbits.validation import as_flag

__all__ = ["RestartWarning", "Saving"]


#: what a snapshot's ``extra`` holds of its leg alone (its other parts shared)
_PER_LEG = ("leg", "started")


def _start_row(prop: Any) -> tuple[np.ndarray, np.ndarray]:
    """A leg's first row as the run gives it (the row 0 of
    :meth:`~hamilton_orbits.engine.Propagation.advance`), the bodies gone at NaN:
    where the driver is yet to be made with events watched (the leg's run makes it,
    and with it the collisions already made at the start, recorded as the leg's),
    after those collisions, carried out here on copies of the state and of the
    events log."""
    events, r, v = prop.events, prop.r.copy(), prop.v.copy()
    if events is None:
        return r, v
    if prop.driver is None and len(events.watch):
        events = copy.deepcopy(events)
        events.at_start(prop.t, r, v, prop.gm.copy())
    events.mask(r, v)
    return r, v


class RestartWarning(UserWarning):
    """A snapshot continued from its physical state only (its integrator state was
    written by a version with other integrator internals)."""


def _from_state(prop: Any, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    """Put a snapshot's physical state (time, positions, velocities, masses, the
    bodies taken out of the run, the step count) into a fresh propagation."""
    prop.r, prop.v = arrays["r"].copy(), arrays["v"].copy()
    prop.gm, prop.t = arrays["gm"].copy(), float(arrays["t"])
    prop.steps_before = int(meta["steps"])
    gone = np.flatnonzero(~arrays["active"])
    if prop.events is not None and gone.size:
        prop.r[gone], prop.v[gone] = 0.0, 0.0  # (NaN in the snapshot: masked)
        for k in gone:  # the bodies an event took out, parked as the event parks them
            prop.events.park(int(k), prop.r, prop.v, prop.gm)
        prop.events.gm_changes.append((prop.t, prop.gm.copy()))



def _file_path(path: Any) -> Path:
    """The ``path`` of :meth:`Saving.save` as a Path, refused by name where it ends in
    a separator or names a folder (``Path`` drops a trailing separator: a file was
    written under the folder's name)."""
    out = path_of(path, "path", "a file or folder path")
    raw = os.fspath(path)
    seps = tuple(sep for sep in (os.sep, os.altsep) if sep)
    if (isinstance(raw, str) and raw.endswith(seps)) or out.is_dir():
        raise ValueError(f"Expected `path` to be a file's path, got {path!r}: a folder's "
                         f"(save writes one file, such as {os.path.join(raw, 'sim.nc')!r}; an "
                         f"archive folder is written by Simulation(..., archive=folder))")
    return out


def _numbered_as_the_call(on_output: Any, shift: int, steps: int) -> Any:
    """``on_output`` called by a resumed call as the interrupted call would have: its
    outputs numbered in the call's own times (``shift`` of them passed before the
    resumed part's first) and its steps counted from the call's start (``steps``
    taken before); it was (1, 40) where the call had (6, 240)."""
    if on_output is None:
        return None

    def numbered(i: int, taken: int) -> Any:
        return on_output(i + shift, taken + steps)

    return numbered

class Saving:
    """Saving, loading, the archive and ``resume`` of a
    :class:`~hamilton_orbits.simulation.Simulation` (a mixin: it stands on the
    simulation's propagation, system and specification)."""

    #: an ``integrate`` or ``resume`` call of this simulation is running: its
    #: callbacks (``on_output``, ``stop``) may copy or save the simulation, not
    #: integrate it again (the outer call would go on from a state moved under it,
    #: and its archive would get a second timeline)
    _busy = False

    def _refuse_within(self, what: str) -> None:
        """Refuse ``what`` (``"integrate"`` or ``"resume"``) called from within a call
        of this simulation (:attr:`_busy`)."""
        raise ValueError(f"Simulation.{what}() called from within an integrate or resume "
                         f"call of the same simulation (its on_output or stop callback, or "
                         f"another thread while it runs): "
                         f"it would move the state that call stands on, and write a second "
                         f"timeline into its archive; integrate a copy there "
                         f"(sim.copy(), which writes nothing), or call {what}() after the "
                         f"call has returned")

    def resume(self, *, progress: bool = False, on_output: Any = None, stop: Any = None,
               on_interrupt: str = "raise") -> Trajectory:
        """Finish the ``integrate`` call a killed run was in, from the archive's last
        snapshot (``Simulation.load(folder)``), and return that call's whole
        trajectory: the rows archived before the kill and the rest, the bits of the
        call that was never interrupted.  A kill during ``resume`` is resumed alike.

        Raises
        ------
        ValueError
            When this simulation was not loaded from an archive folder, or has
            integrated since (the interrupted call was left for another); for a
            ``progress`` not True or False; when called from within a call of the
            same simulation (its ``on_output`` or ``stop``).
        SnapshotError
            When a snapshot of the leg is missing or damaged (its rows are lost),
            naming the archive, the file that held it and how to go on.

        Examples
        --------
        >>> import tempfile
        >>> import numpy as np
        >>> from hamilton_orbits import Body, Simulation, System
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
        >>> folder = tempfile.mkdtemp()
        >>> whole = Simulation(s, method="wh", dt=0.01, archive=folder, every=2.0).integrate(
        ...     np.arange(0.0, 7.0))
        >>> again = Simulation.load(folder)              # as after a kill at t = 6.5
        >>> traj = again.resume()                         # the whole call, t = 0 ... 6
        >>> bool(np.array_equal(traj.r, whole.r)), traj.t.tolist() == whole.t.tolist()
        (True, True)
        """
        if self._busy:
            self._refuse_within("resume")
        if self._resumable is None:
            raise ValueError("Nothing to resume: resume() finishes the integrate call of a "
                             "simulation loaded from its archive folder, before it "
                             "integrates anything else")
        progress = as_flag("progress", progress)
        folder, info, upto = self._resumable  # the leg's rows read now, not at load
        times, rows = leg_rows(folder, info["start"], upto)
        prop = self._prop
        check_output_memory(len(times), len(prop.gm), bool(self._spec[6]))
        rest = times[times > prop.t]
        out = None
        if rest.size:
            on_output = _numbered_as_the_call(on_output, times.size - rest.size - 1,
                                              self.steps - info["steps0"])
            self._busy = True  # (its callbacks may copy or save it: see _busy)
            try:
                out = self._advance(np.concatenate(([prop.t], rest)), progress, on_output,
                                    stop, leg=times)
            except BaseException:  # (cut: the next leg's integrals measured from time 0)
                self._start = self._initial
                raise
            finally:
                self._busy = False
            if out.interrupted and on_interrupt == "raise":
                raise KeyboardInterrupt
        whole = leg_run(rows, out, prop, self.steps - info["steps0"], info["first_event"])
        self._start = self._initial
        unit = u.Unit(info["unit"]) if info["unit"] else None
        return self._trajectory(whole, unit, None if info["first"] else self._initial,
                                whole.wall_time)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Save everything needed to continue: ``Simulation.load(path).integrate(t)``
        gives the bits this simulation's ``integrate(t)`` would.

        The file is a self-describing netCDF file (``t``, ``r``, ``v``, ``gm`` readable
        by any netCDF reader; the method, effects, events and the integrator's own
        state for this package), written atomically (``docs/archive.md``).

        Parameters
        ----------
        path : path
            The file to write (replaced if it exists); not a folder, nor a path
            ending in a separator.

        Raises
        ------
        ValueError
            For a ``path`` that is not a path, ends in a separator or names a folder.

        Examples
        --------
        >>> import os, tempfile
        >>> import numpy as np
        >>> from hamilton_orbits import Body, Simulation, System
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
        >>> sim = Simulation(s, method="wh", dt=0.01)
        >>> _ = sim.integrate(1.0)
        >>> with tempfile.TemporaryDirectory() as tmp:
        ...     sim.save(os.path.join(tmp, "sim.nc"))
        ...     again = Simulation.load(os.path.join(tmp, "sim.nc"))
        >>> a, b = sim.integrate(2.0), again.integrate(2.0)
        >>> bool(np.array_equal(a.r, b.r)), again.steps
        (True, 200)
        """
        target = _file_path(path)
        meta, arrays, dims, units = self._record()
        asked = self._asked_times()
        if asked is not None:  # (a fixed-step archive's snapshots are laid from them)
            arrays["asked_times"] = np.asarray(asked, dtype=np.float64)
        write(target, meta, arrays, dims, units, sync=True)

    @classmethod
    def load(cls, path: str | os.PathLike[str], number: int | None = None) -> Any:
        """The simulation saved in ``path`` (:meth:`save`), or the last snapshot of an
        archive folder, which then continues that archive on its schedule.

        A snapshot of an archived run keeps the run's schedule: its snapshot times
        stay among the output times of later legs (nothing is written unless the
        folder itself was loaded), so that it continues with the run's bits.

        Parameters
        ----------
        path : path
            A snapshot file, or an archive folder.
        number : int, optional
            For a folder: snapshot ``number`` of the archive instead of the last
            one, not attached to the folder (it writes nothing).  A snapshot's
            number is the order it was written in, kept in its file
            (``Archive(folder).snapshots[k].number``); ``Archive(folder)[k]`` is the
            ``k``-th of those that read whole, the same one as long as none before
            it is damaged or missing.

        Raises
        ------
        SnapshotError
            For a missing, damaged or foreign file, naming it; for a ``number``
            the folder does not hold whole.
        """
        # (absolute: the folder and file it names are read again later, a leg's rows
        # when it is resumed, whatever directory that is done from)
        path = path_of(path, "path", "a file or folder path").absolute()
        if number is not None and (isinstance(number, (bool, np.bool_))
                                   or not isinstance(number, (int, np.integer))):
            raise ValueError(f"Expected `number` to be a whole number (a snapshot's number), "
                             f"got {number!r}")
        folder = source = path if path.is_dir() else None
        if folder is None:
            if number is not None:
                raise ValueError(f"`number` picks a snapshot of an archive folder; {path} "
                                 f"is not a folder")
            meta, arrays = read(path)
        elif number is None:
            path, meta, arrays = last_snapshot(folder)
        else:
            found = snapshot_at(folder, number)
            if found is None:
                raise SnapshotError(f"the archive {folder} has no whole snapshot {number!r}")
            path, meta, arrays = found
            folder = None  # not attached: a snapshot of the run, writing nothing
        sim = cls._rebuild(meta, arrays, path)
        if source is None and "asked_times" in arrays:  # (a file of save: the leg's
            sim._asked = np.array(arrays["asked_times"], dtype=np.float64)  # times asked)
        schedule = meta.get("archive")
        if schedule:  # the archived run's schedule: written on when its folder is loaded
            sched = {k: schedule[k] for k in ("every", "every_steps", "every_wall", "sync",
                                              "exact")}
            sim._archive = ArchiveWriter(folder, origin=schedule["origin"], **sched)
            sim._archive.last_steps = sim.steps
            sim._archive.continues = True  # (the run of the folder's snapshots)
            if folder is not None:  # (the snapshot it stands at: see ArchiveWriter.loaded)
                sim._archive.loaded_from(int(meta["number"]), path)
        leg = meta.get("leg")
        if leg is not None and source is not None:  # (its leg's times, read if needed)
            sim._asked = (source, int(leg["start"]))
        if folder is not None and leg is not None:  # the leg a kill interrupted
            sim._resumable = (folder, leg, meta["number"])
            sim._leg = LegRows(leg)
        return sim

    @classmethod
    def _rebuild(cls, meta: dict[str, Any], arrays: dict[str, np.ndarray],
                 path: Path) -> Any:
        sp = spec(meta, arrays)
        system = System.from_system_arrays(sp["system"])
        days = (lambda x: x) if not system.quantity else (lambda x: x * DAY)

        # (a wh or leapfrog file of dt and tol both, written before both were refused:
        # its tol was ignored, and is left out)
        tol = None if sp["method"] in FIXED_STEP and sp["dt"] is not None else sp["tol"]

        def fresh() -> Any:
            return cls(system, method_of(sp["method"], sp["options"]),
                       dt=None if sp["dt"] is None else days(sp["dt"]), tol=tol,
                       effects=sp["effects"], events=sp["events"],
                       variational=sp["variational"], stm=sp["stm"])

        sim = fresh()
        prop, layout = sim._prop, sp["layout"]
        if "class" in layout["attrs"]["driver"]:
            prop.driver_for(bool(layout["attrs"]["backward"]["value"]))
        try:
            restore(prop, layout, sp["state"])
        except LayoutMismatch as exc:  # another version's integrator: from the state
            sim = fresh()
            _from_state(sim._prop, meta, arrays)
            warnings.warn(RestartWarning(
                f"{path} holds the integrator state of another version ({exc}); continuing "
                "from its positions, velocities and masses with the integrator started "
                "afresh: not bit for bit the run that wrote it, and events found and MEGNO "
                "sums before it are not carried over"), stacklevel=3)
        if meta.get("started") or meta.get("t", 0.0) != 0.0 or meta.get("steps", 0):
            # (a snapshot taken after time 0, within the first integrate call too,
            # which records started False: the integrals measured from time 0)
            sim._start = sim._initial
        if meta.get("unit"):
            sim._unit = u.Unit(meta["unit"])
        return sim

    def _unit_text(self) -> str | None:
        """The caller's time unit as text (made once per unit)."""
        if self._unit is None:
            return None
        known = self._record_cache.get("unit")
        if known is None or known[0] is not self._unit:
            known = self._record_cache["unit"] = (self._unit, self._unit.to_string())
        return known[1]

    def _extra(self, rows: Any) -> dict[str, Any]:
        """What a snapshot's ``meta`` holds of the simulation beside its propagation."""
        extra = {"started": self._start is not None, "unit": self._unit_text(),
                 "archive": None if self._archive is None else self._archive.schedule()}
        if rows is not None:
            extra["leg"] = rows.info
        return extra

    def _snapshot(self, rows: Any, again: bool = False) -> None:
        """Append the archive's next snapshot (``rows``: the leg's rows since the last,
        ``again``: see :meth:`_appended`).  A snapshot that did not end (Ctrl-C, a full
        disk) leaves the segment to the folder: the next begins one of its own at the
        folder's next number (:meth:`~hamilton_orbits.checkpoint.ArchiveWriter.lost`)."""
        try:
            self._appended(rows, again)
        except BaseException:
            self._archive.lost()
            raise

    def _appended(self, rows: Any, again: bool = False) -> None:
        """Append the archive's next snapshot (``rows``: the leg's rows since the last).

        When the segment being written was begun or last appended to by this
        simulation and the propagation's layout is still the one it shares (the
        usual case between two outputs or two slices of steps), only what changes
        is taken (:class:`~hamilton_orbits.restart.Capture`) and appended; otherwise
        the whole snapshot is made, which begins a new segment if its shared part
        changed.  ``again``: the driver paused again with only its steps run since
        the last snapshot (``_Run.pause``), so the layout is known to be the same
        and is read without its checks (without events: they would drain)."""
        arch, prop, cache = self._archive, self._prop, self._record_cache
        known = cache.get("appended")
        same = known is not None and known[0] is arch.segment and (
            rows is None or rows.times is None)
        if same and again and prop.events is None:
            capture = known[2][0]
            if self._refilled(capture, capture.reread(prop)):
                return
        extra = self._extra(rows)
        if same and known[1] == extra:
            capture, _, index = known[2]
            taken = self._taken(capture)
            if taken is not None:
                if prop.events is None and (rows is None or not rows.rows) and \
                        self._refilled(capture, taken):  # (a scheduled snapshot between
                    return  # outputs, no row pending: the last record refilled)
                arch.append(self._values(capture, index, taken),
                            {} if rows is None else rows.take())
                return
        if known is not None and known[0] is arch.segment and self._leg_appended(
                rows, extra, known):
            cache["appended"] = (arch.segment, extra, known[2])
            return
        arch.write(*self._record(rows, archive=True))
        cache["appended"] = (arch.segment, extra, cache["capture"])

    def _leg_appended(self, rows: Any, extra: dict[str, Any], known: tuple[Any, ...]) -> bool:
        """Whether the first snapshot of a leg of a start and an end (``rows``) was
        appended to the segment this simulation's last leg wrote and goes on in
        (archive format 3) from what changes only
        (:class:`~hamilton_orbits.restart.Capture`, as a snapshot within a leg): the
        same layout, time unit and schedule as the last snapshot (``known``: its
        segment, ``extra`` and capture), so that it shares all the segment's
        snapshots share.  The bytes are those of the whole snapshot.  False,
        nothing written, otherwise (the whole snapshot is then made)."""
        arch = self._archive
        times = None if rows is None else rows.times
        if (times is None or len(times) != 2 or arch.segment is None or not arch.segment.legs
                or any(extra[k] != known[1].get(k) for k in extra if k not in _PER_LEG)
                or known[1].keys() != extra.keys()):
            return False
        capture, _, index = known[2]
        taken = self._taken(capture)
        if taken is None:
            return False
        arch.append_leg(self._values(capture, index, taken), rows.take(),
                        {"started": extra["started"], "leg": extra["leg"]})
        return True

    def _taken(self, capture: Any) -> Any:
        """What ``capture`` takes of the propagation (:meth:`~hamilton_orbits.restart.
        Capture.take`), its events log drained first as a whole snapshot's is; None
        where the propagation's layout is no longer the capture's."""
        prop = self._prop
        if prop.events is not None:
            prop.events.drain()
        return capture.take(prop)

    def _values(self, capture: Any, index: Any, taken: Any) -> dict[str, Any]:
        """A record's values (``t``, ``r``, ..., ``steps``) of what ``capture`` took."""
        prop = self._prop
        values = state_values(prop, taken[0], index, taken[1], capture.ints)
        values["steps"] = prop.steps
        return values

    def _refilled(self, capture: Any, taken: Any) -> bool:
        """Whether the archive appended the propagation's state by refilling its last
        record (:meth:`~hamilton_orbits.checkpoint.ArchiveWriter.refill`) from what
        ``capture`` ``taken``; False, nothing written, where it cannot."""
        prop = self._prop
        return taken is not None and self._archive.refill(
            prop.t, prop.r, prop.v, prop.gm, all_active(prop.r.shape[0]), *taken, prop.steps,
            capture.ints)

    def _record(self, rows: Any = None, archive: bool = False) -> tuple[Any, ...]:
        meta, arrays, dims, units = record(self._system, *self._spec, self._prop,
                                           self._extra(rows), self._record_cache,
                                           split=archive)
        if rows is not None:
            arrays.update(rows.take())
            dims.update(out_r=("out", "body", "xyz"), out_v=("out", "body", "xyz"))
        return meta, arrays, dims, units

    def _new_leg(self, times: np.ndarray) -> None:
        """Begin an archived leg through ``times``: its first snapshot (the leg's
        times, its start) written, so a folder that cannot take it fails now."""
        arch, prop = self._archive, self._prop
        if times[-1] < times[0]:
            if arch.path is None:  # (the schedule of a run it was taken from, writing
                self._asked = None  # nothing: a leg back in time has no snapshot of it
                return  # to keep to, and leaves the run's steps behind)
            raise ValueError(f"A simulation writing an archive integrates forwards in time "
                             f"(its archive {arch.path} is one run's timeline); integrate a "
                             f"copy backwards (Simulation.copy(), which writes nothing)")
        arch.scheduled(float(times[0]), float(times[-1]))  # (too many refused here)
        try:
            arch.open()
            info = {"start": arch.count, "first": self._start is None, "steps0": self.steps,
                    "unit": self._unit_text(),
                    "first_event": 0 if prop.events is None else len(prop.events.recorded())}
            self._leg = LegRows(info, times)
            self._leg.add(prop.t, *_start_row(prop), prop.variational)
            if prop.driver is None and (prop.events is None or not len(prop.events.watch)):
                prop.driver_for(False)  # (made now, not after this snapshot: one segment)
            if arch.path is not None:
                self._snapshot(self._leg)
        except BaseException:
            arch.close()
            raise

    def _archived_times(self, times: np.ndarray, leg: np.ndarray | None = None) -> tuple[
            np.ndarray, np.ndarray, np.ndarray]:
        """The output times with the archive's snapshot times merged in, which rows
        were asked for, and which are scheduled snapshots (the folder claimed).  A
        fixed-step method's snapshots are put on the steps laid from the call's output
        times (``leg``, those of the whole call ``times`` finish, when resumed: the
        steps of the call never interrupted)."""
        arch, prop = self._archive, self._prop
        arch.open()
        extra = arch.times(float(times[0]), float(times[-1]))
        if prop.driver is None and prop.dt is None and prop.method.name in FIXED_STEP:
            prop.driver_for(False)  # (made now, as the leg would next: the step a fixed-step
            # method chooses from the state after the collisions at the start)
        step = prop.fixed_step()
        if not arch.exact and step is not None and prop.method.name != "dop853":
            asked = leg
            if asked is None:
                before = self._asked_before(float(times[0]))
                asked = times if before is None else np.concatenate(([before], times[1:]))
            self._asked = asked
            extra = on_step_grid(extra, asked, step, spread=prop.method.name == "leapfrog")
            extra = extra[extra > times[0]]  # (one moved back onto the start, at the
            # rounding of its step, is not an output after it)
        extra = _onto_near_times(extra, times)
        if not extra.size and bool(np.all(times[1:] > times[:-1])):  # (no snapshot
            # scheduled in the call, as in a loop of short calls: its times as they are)
            return times, np.ones(len(times), bool), np.zeros(len(times), bool)
        merged = np.union1d(times, extra)
        return merged, np.isin(merged, times), np.isin(merged, extra)

    def _asked_times(self) -> np.ndarray | None:
        """The output times asked for in the leg the simulation stands in (a
        fixed-step method's archive lays its snapshots from them), or None."""
        asked = self._asked
        if isinstance(asked, tuple):  # (loaded: read from the archive once, when needed)
            asked = self._asked = leg_times_of(*asked)
        return asked

    def _asked_before(self, t: float) -> float | None:
        """The last output time asked for before ``t`` in the leg the simulation
        stands in, where it stands between two of them (a leg that ended at a
        snapshot, or a simulation loaded from one): a fixed-step method's snapshots
        are put on the steps laid from it, as in the leg never interrupted.  None
        where it stands on one, or no leg is known."""
        asked = self._asked_times()
        if asked is None or not asked[0] < t < asked[-1]:
            return None
        before = asked[asked <= t]
        return None if before[-1] == t else float(before[-1])

    def _step_snapshots(self) -> _EverySteps | _EveryWall | None:
        """The pause that takes an ``every_steps`` snapshot between two steps, or
        looks at the clock there for an ``every_wall`` one (None with the simulation
        time schedule, or when nothing is written)."""
        arch = self._archive
        if arch is None or arch.path is None:
            return None
        if arch.every_steps is not None:
            return _EverySteps(self)
        return None if arch.every_wall is None else _EveryWall(self)

    def _time_snapshots(self, asked: np.ndarray, scheduled: np.ndarray) -> _EveryTime | None:
        """The rows of an ``every`` archive's snapshots that a driver may land on and
        write itself (None with another schedule, or when nothing is written)."""
        arch = self._archive
        if arch is None or arch.path is None or arch.every is None or not scheduled.any():
            return None
        return _EveryTime(self, asked, scheduled)

    def _checkpoint(self, asked: np.ndarray, scheduled: np.ndarray) -> Callable[[int], None]:
        arch, prop, rows = self._archive, self._prop, self._leg
        taken = [False]  # a snapshot of this leg's outputs taken

        def at(i: int) -> None:
            if i == 0:
                return
            if asked[i] and rows is not None and arch.path is not None:
                rows.add(prop.t, prop.r, prop.v, prop.variational)
            if arch.path is not None and (scheduled[i] or arch.due(prop.steps)):
                # (again: since this leg's last snapshot only its steps ran and its
                # outputs put other rows of the same shapes in the propagation's r and
                # v, no row waits to be written: the layout is read as a pause's)
                again = taken[0] and prop.variational is None and (rows is None
                                                                   or not rows.rows)
                self._snapshot(rows, again)  # (a schedule alone writes nothing)
                taken[0] = True

        return at


#: how many ulp apart a scheduled snapshot time and a caller's output time are one
#: time (a snapshot a few ulp from an output would cost a step of that length)
NEAR_ULPS = 4


def _onto_near_times(extra: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The snapshot times ``extra`` (increasing, after ``times[0]``) with those within
    :data:`NEAR_ULPS` ulp of an output time of ``times`` (forwards) taken as that
    output time (the caller's), one on the start left out (the leg's first
    snapshot is there).

    Examples
    --------
    >>> times = np.concatenate(([0.0], np.cumsum(np.full(10, 0.1))))  # (0.6 ... 0.9999999999999999)
    >>> _onto_near_times(0.1 * np.array([5, 6, 10]), times).tolist()  # (0.6000000000000001, 1.0)
    [0.5, 0.6, 0.9999999999999999]
    """
    if not extra.size or times.size < 2:
        return extra
    if extra.size * times.size <= 64:  # (a short call, the usual one: in Python floats,
        ts = times.tolist()  # at a tenth of the cost of the arrays' way below)
        out = extra.tolist()
        for j, e in enumerate(out):
            near = min(ts, key=lambda t, e=e: abs(e - t))
            if abs(e - near) <= NEAR_ULPS * math.ulp(max(abs(e), abs(near))):
                out[j] = near
        if out == extra.tolist():
            return extra
        moved = np.array(out)
        return moved[moved > times[0]]
    k = np.clip(np.searchsorted(times, extra), 1, times.size - 1)
    lo, hi = times[k - 1], times[k]
    near = np.where(extra - lo <= hi - extra, lo, hi)
    close = np.abs(extra - near) <= NEAR_ULPS * np.spacing(np.maximum(np.abs(extra),
                                                                      np.abs(near)))
    if not close.any():
        return extra
    out = np.where(close, near, extra)
    return out[out > times[0]]


#: the steps between two looks at the clock of an ``every_wall`` archive between two
#: steps (radau15 pauses there: about 10 us each, 0.01% of 10^4 steps of 10 bodies)
WALL_CHECK = 10_000


class _EveryWall:
    """An archive's ``every_wall`` snapshots taken between two steps, for a driver
    that can pause there: the clock looked at every :data:`WALL_CHECK` steps (and at
    the outputs, :meth:`Saving._checkpoint`), a snapshot at the first look after
    each interval."""

    def __init__(self, sim: Saving) -> None:
        self.sim, self.arch = sim, sim._archive
        self.next = sim._prop.steps + WALL_CHECK
        #: only the compiled steps ran since this pause's last snapshot (its
        #: ``again``: the layout then read without its checks)
        self.steps_only = False

    @property
    def at(self) -> int:
        """The propagation's step count at which the clock is next looked at."""
        return self.next

    def __call__(self, again: bool = False) -> None:
        prop = self.sim._prop
        self.next = prop.steps + WALL_CHECK
        self.steps_only = self.steps_only and again
        if self.arch.due(prop.steps):
            self.sim._snapshot(self.sim._leg, self.steps_only)
            self.steps_only = True


class _KernelWrites:
    """An archive's snapshots that a stepping kernel may append itself."""

    def __init__(self, sim: Saving) -> None:
        self.sim, self.arch = sim, sim._archive

    def compiled(self, arrays: dict[str, np.ndarray], aliases: list[tuple[np.ndarray, str]],
                 t_at: tuple[str, int], steps: int, times: np.ndarray | None = None,
                 ) -> tuple[np.ndarray, tuple[Any, ...]] | None:
        """The plan with which the driver's kernel appends the next snapshots itself
        (:meth:`~hamilton_orbits.checkpoint.ArchiveWriter.compiled_plan`; ``times``:
        those of an ``every`` schedule it lands on), where the segment being written
        is the one the last snapshot went to (the driver asks only where no events
        are watched); else None."""
        sim, arch = self.sim, self.arch
        known = sim._record_cache.get("appended")
        if known is None or known[0] is not arch.segment:
            return None
        return arch.compiled_plan(arrays, aliases, t_at, steps, times)

    def wrote(self, plan: np.ndarray, last_steps: int) -> None:
        """Count the snapshots the kernel appended with ``plan``, the last after
        ``last_steps`` steps of the simulation."""
        self.arch.compiled_wrote(plan, last_steps)


class _EverySteps(_KernelWrites):
    """An archive's ``every_steps`` snapshots taken between two steps, for a driver
    that can pause there (:meth:`~hamilton_orbits.engine.Propagation.advance`)."""

    @property
    def at(self) -> int:
        """The propagation's step count at which the next snapshot is due."""
        return self.arch.last_steps + self.arch.every_steps

    def __call__(self, again: bool = False) -> None:
        self.sim._snapshot(self.sim._leg, again)


class _EveryTime(_KernelWrites):
    """An archive's ``every`` snapshots at output rows of their own (``only``: the
    scheduled times no caller asked for), which a driver that lands on them may
    write itself (:class:`~hamilton_orbits.engine._Landings`)."""

    def __init__(self, sim: Saving, asked: np.ndarray, scheduled: np.ndarray) -> None:
        super().__init__(sim)
        self.only = scheduled & ~asked
        others = np.flatnonzero(~self.only)  # (the last row is always one: asked)
        self.ends = others[np.searchsorted(others, np.arange(self.only.size))]

    def through(self, i: int) -> int:
        """The first row from ``i`` on that is not a snapshot alone."""
        return int(self.ends[i])
