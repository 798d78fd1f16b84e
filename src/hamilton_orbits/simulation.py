"""The one front door: a prepared, stateful :class:`Simulation`, and :func:`integrate`.

A :class:`Simulation` is validated and compiled once: the system, the method and
its options (a typed value, :mod:`hamilton_orbits.integrators.methods`), the
step or tolerance, the effects (their compiled right-hand side), the events to
watch and the variational equations.  ``sim.integrate(t)`` advances it and
returns that leg's :class:`~hamilton_orbits.trajectory.Trajectory`; the next call
continues from the integrator's own state (radau15's step and predictor, the
Wisdom-Holman coordinates, the MEGNO sums, the events found), so that

    sim.integrate(t1); sim.integrate(t2)

reaches ``t2`` with the same bits as one ``sim.integrate([t1, t2])``.  Times are
the simulation's own, from 0 at the system given.  ``integrate(system, t, **kw)``
is ``Simulation(system, **kw).integrate(t)``; scenes and ensembles stand on it.

Every trajectory carries Hamilton's integrals as diagnostics (Hamilton 1845,
equations (C), (D), (E)): the drift of the centre of mass, the relative error of
the total angular momentum (law of areas) and of the energy (vis viva), from the
start of the simulation.
"""

from __future__ import annotations

import copy
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import engine
from hamilton_orbits._legs import (
    caller_level,
    check_effects,
    check_method,
    event_list,
    event_log,
    leg_times,
    progress_reporter,
    requested_rows,
    rows_of,
    shared_memo,
    tangent_of,
    time_step,
    tolerance,
)
from hamilton_orbits._output_memory import check_output_memory
from hamilton_orbits._saving import Saving
from hamilton_orbits.checkpoint import (
    ArchiveWriter,
    LegRows,
)
from hamilton_orbits.effects import EffectSet
from hamilton_orbits.integrals import WARN_UNDER_RESOLVED
from hamilton_orbits.integrators import INTEGRATORS, Method, method_of
from hamilton_orbits.integrators._setup import check_step_count
from hamilton_orbits.integrators.methods import FIXED_STEP, check_run
from hamilton_orbits.nbody import DAY, System
from hamilton_orbits.rhs import RHS, compile_rhs, refuse_nonfinite
from hamilton_orbits.trajectory import (
    Trajectory,
    encounter_check,
    encounter_warning,
    event_table,
    make_trajectory,
)
from hamilton_orbits.units import TIME, is_quantity, time_quantity
from hamilton_orbits.validation import as_flag

__all__ = ["INTEGRATORS", "Simulation", "Trajectory", "check_method", "event_log",
           "event_table", "integrate", "make_trajectory"]




class Simulation(Saving):
    """A prepared n-body integration that lives across calls.

    Parameters
    ----------
    system : System
        The bodies at time 0 of the simulation.
    method : str or Method
        ``"radau15"`` (default), ``"wh"``, ``"leapfrog"``, ``"dop853"``, or a typed
        value (:class:`~hamilton_orbits.Radau15`,
        :class:`~hamilton_orbits.WH`, ...) that carries the options.
    dt : Quantity, TimeDelta or float, optional
        A fixed step (``radau15``, ``wh``, ``leapfrog``) or a step cap
        (``dop853``); a time Quantity (or an astropy TimeDelta, the Quantity in
        days it holds) for a Quantity system.
    tol : float, optional
        The integrator's tolerance (adaptive methods) or the accuracy from which a
        fixed-step method chooses its step.
    effects : sequence of str or mapping
        Effects beyond Newtonian gravity (:mod:`hamilton_orbits.effects`).
    events : sequence of str or mapping, optional
        Events to find (:mod:`hamilton_orbits.events`).  An action ``"stop"``
        ends the leg at the event (its trajectory complete, ``stopped_by`` the
        event's row); the next :meth:`integrate` goes on from there, the event
        not found again, but not from a collision's contact (a ``ValueError``).
    variational : bool
        Integrate the first-order variational equations beside the system (MEGNO,
        the Lyapunov exponent; see ``docs/variational.md``).
    stm : bool
        With ``variational``: also the state transition matrix, ``(6n)^2`` values an
        output: a call whose outputs would take more than half the machine's
        memory is refused (``ValueError``) before it runs.
    tangent : array_like, shape (n, 6), optional
        MEGNO's initial tangent vector (default: random, as rebound's
        ``init_megno`` draws it, a fixed seed).
    archive : path, optional
        A folder to write snapshots into while the simulation integrates
        (``docs/archive.md``), on one of these schedules:
    every : Quantity, TimeDelta or float, optional
        A snapshot at every multiple of this much simulation time (a TimeDelta:
        the Quantity in days it holds);
    every_steps : int, optional
        or every so many steps: radau15 (double precision, without the
        variational equations) takes it between two steps, at the end of every
        ``every_steps``-th, its steps unchanged; the other methods at the first
        output after;
    every_wall : float, Quantity or TimeDelta, optional
        or every so many seconds (or a time Quantity, or a TimeDelta) of
        wall-clock time, at the first look at the clock after each: at the
        outputs, and for radau15 (double precision, without the variational
        equations) also between two steps, every 10 000 steps.
    exact_times : bool, optional
        Snapshots at exactly the scheduled times (the default of the adaptive
        methods, which end a step there by their own step control), or at the end
        of the step at or after each (the default of the fixed-step methods, whose
        steps then stay their own: wh and leapfrog, with a ``dt`` given or the step
        they choose without it, and radau15 with ``dt``).
    archive_sync : bool
        Sync each snapshot to the disk before the run goes on, so that the archive
        survives a power cut or a crash of the machine, not only a killed process
        (two syncs a snapshot: 0.3 ms on the virtual disk of the benchmarks,
        milliseconds on a common disk; default False: the operating system writes
        the file when it will).
    **method_options
        The method's options beside its name (``coordinates="jacobi"``,
        ``corrector=11`` for ``wh``; see :mod:`hamilton_orbits.integrators.methods`).

    Attributes
    ----------
    t : float or Quantity
        The simulation's time (a Quantity in the unit of the last times given, days
        at first, for a Quantity system).
    system : System
        The current state.
    steps : int
        Steps taken since time 0.
    method : Method
        The method and its options.

    Raises
    ------
    ValueError
        For an unknown method, option or effect, a velocity-dependent effect
        given to a symplectic integrator, or a bad step or tolerance.

    Examples
    --------
    >>> import numpy as np
    >>> from hamilton_orbits import Body, Simulation, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
    >>> sim = Simulation(s, method="wh", dt=0.01)
    >>> leg = sim.integrate(np.pi)       # to t = pi
    >>> leg = sim.integrate(2 * np.pi)   # on to t = 2 pi: continues the same steps
    >>> once = Simulation(s, method="wh", dt=0.01).integrate([np.pi, 2 * np.pi])
    >>> bool(np.array_equal(leg.r[-1], once.r[-1])), sim.t, sim.steps
    (True, 6.283185307179586, 630)
    >>> branch = sim.copy()              # an independent copy, for ensembles
    >>> _ = branch.integrate(3 * np.pi)
    >>> sim.t, branch.t
    (6.283185307179586, 9.42477796076938)
    """

    def __init__(self, system: System, method: str | Method = "radau15", dt: Any = None,
                 tol: float | None = None, effects: Sequence[str | Mapping[str, Any]] = (),
                 events: Any = (), variational: bool = False, stm: bool = False,
                 tangent: Any = None, archive: Any = None, every: Any = None,
                 every_steps: int | None = None, every_wall: float | None = None,
                 exact_times: bool | None = None, archive_sync: bool = False,
                 **method_options: Any) -> None:
        if not isinstance(system, System):
            raise ValueError(f"Expected `system` to be a System, got {system!r}")
        typed = method_of(method, method_options)
        eff = check_effects(typed, () if effects is None else effects)
        step = None if dt is None else time_step(dt, system.quantity)
        tol = tolerance(tol)
        if step is not None and tol is not None and typed.name in FIXED_STEP:
            raise ValueError(f"Expected `dt` or `tol` with method {typed.name!r} (a fixed step, "
                             f"or a tolerance that chooses it), got both: dt = {dt!r}, tol = "
                             f"{tol!r} (the tolerance would be ignored)")
        check_run(typed, step, tol, bool(variational))  # (before any folder is made)
        if all(isinstance(x, bool | np.bool_) and x for x in (variational, stm)):  # (every
            # leg keeps two outputs, its start and end; asked before the tangent's (6n)^2
            # identity is made: 2.6 GB and 6 s for 3000 bodies; other values checked there)
            check_output_memory(2, len(system.names), True)
        tan = tangent_of(system, variational, stm, tangent, typed)
        rhs = compile_rhs(system, eff, variational=tan is not None)
        arrays = system.as_arrays()
        if eff and not rhs.per_run:  # (an effect singular at the start: refused by name)
            refuse_nonfinite(system, eff, rhs.acceleration(arrays.r, arrays.v, arrays.gm),
                             arrays.r, arrays.v, arrays.gm)
        self._prop = engine.Propagation(arrays.r, arrays.v, arrays.gm, 0.0, rhs, typed, dt=step,
                                        tol=tol, events=event_log(system, events),
                                        variational=tan)
        self._system, self._effects, self._quantity = system, eff, system.quantity
        #: the state at time 0, from which Hamilton's integrals are measured (None
        #: until a first leg has begun there)
        self._start: Any = None
        self._initial = (arrays.r, arrays.v, arrays.gm)
        self._unit: Any = DAY if system.quantity else None
        self._spec = (typed, step, tol, eff.as_list(), event_list(events), variational, stm)
        self._archive = _archive_of(archive, (every, every_steps, every_wall), exact_times,
                                    typed.name, step is not None or typed.name in FIXED_STEP,
                                    system.quantity,
                                    archive_sync)
        #: the archived leg in progress, and what resume() finishes (after a load)
        self._leg: LegRows | None = None
        self._resumable: Any = None
        #: the output times asked for in the last archived leg, or where to read them
        #: (``Saving._asked_before``)
        self._asked: Any = None
        self._warned = False  # an under-resolved encounter is warned of once
        #: the parts of a snapshot that never change, made at the first (simulation_record.record)
        self._record_cache: dict[str, Any] = {}
        #: how a leg's close approaches are checked: fixed for the simulation (method,
        #: step, tolerance, the state at time 0), so found once, not per call
        self._encounters = encounter_check(typed, step, tol, arrays.r, arrays.gm)
        if len(arrays.gm) < 2:
            self._encounters = None  # one body: nothing to check per leg

    # ------------------------------------------------------------------ state
    @property
    def method(self) -> Method:
        """The method and its options."""
        return self._prop.method

    @property
    def t(self) -> Any:
        """The simulation's time (see the class notes)."""
        t, unit = self._prop.t, self._unit
        if unit is None:
            return t
        return t * DAY if unit is DAY else (t * DAY).to(unit)  # (the same value)

    @property
    def steps(self) -> int:
        """Steps taken since time 0."""
        return self._prop.steps

    @property
    def dt(self) -> Any:
        """The fixed step the simulation was made with (a Quantity in days for a
        Quantity system), or None: a step the method chooses (radau15, dop853), or
        one from ``tol`` (wh, leapfrog)."""
        step = self._spec[1]
        return step if step is None or self._unit is None else step * DAY

    @property
    def system(self) -> System:
        """The current state as a :class:`~hamilton_orbits.nbody.System` (bodies an
        event took out of the run are left out)."""
        p = self._prop
        keep = None if p.events is None or not p.events.inactive.any() else ~p.events.inactive
        radius = None if p.events is None else p.events.radius  # (merged bodies' own)
        return self._system.with_state(p.r, p.v, gm=p.gm, keep=keep, check=False,
                                       radius=radius)

    @property
    def initial_system(self) -> System:
        """The system at time 0 this simulation integrates from: as it was given, or,
        for a simulation loaded from a snapshot, as the snapshot recorded it (not as a
        file it was once read from reads now).

        Examples
        --------
        >>> from hamilton_orbits import Body, System
        >>> sim = Simulation(System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
        ...                          Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])]))
        >>> _ = sim.integrate(1.0)
        >>> sim.initial_system["p"].r.tolist(), sim.system["p"].r.tolist() != [1.0, 0, 0]
        ([1.0, 0.0, 0.0], True)
        """
        return self._system

    @property
    def effects(self) -> EffectSet:
        """The effects beyond Newtonian gravity."""
        return self._effects

    @property
    def rhs(self) -> RHS:
        """The compiled right-hand side."""
        return self._prop.rhs

    def __repr__(self) -> str:
        return (f"Simulation({len(self._system.names)} bodies, method={self.method!r}, "
                f"effects={self._effects.names!r}, t={self.t!r}, steps={self.steps})")

    def copy(self) -> Simulation:
        """An independent copy (its own state; the compiled right-hand side shared):
        integrating one does not change the other.  The copy of an archived
        simulation keeps its schedule but writes nothing."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.__dict__.pop("_busy", None)  # (a copy taken in a callback is not running)
        memo = shared_memo(self._prop)
        pause = getattr(self._prop.driver, "pause", None)
        if pause is not None:  # (taken in a callback of an archived call: the step
            # schedule's pause holds this simulation, whose copy would copy it again;
            # the copy's driver pauses for nothing, as between two calls)
            memo[id(pause)] = None
        new._prop = copy.deepcopy(self._prop, memo)
        if new._start is None and (self._prop.t != 0.0 or self._prop.steps):
            new._start = new._initial  # (a copy taken within the first call, from a
            # callback: its integrals from time 0, as a snapshot loaded there has them)
        if self._archive is not None:  # the same output times; only the original writes
            new._archive = self._archive.schedule_only()
        return new

    def __copy__(self) -> Simulation:
        # (copy.copy shared the state: integrating the copy moved the original)
        return self.copy()

    def __deepcopy__(self, memo: dict) -> Simulation:
        # (it failed: "cannot pickle 'module' object")
        return self.copy()

    def __reduce__(self) -> Any:
        raise TypeError("A Simulation is not pickled (its compiled kernels are this "
                        "process's): save it with sim.save(path) and continue it anywhere "
                        "with Simulation.load(path); copy it with sim.copy()")

    # ------------------------------------------------------------------ run
    def integrate(self, t: Any, *, progress: bool = False,
                  on_output: Callable[[int, int], None] | None = None,
                  stop: Callable[[], bool] | None = None,
                  on_interrupt: str = "raise") -> Trajectory:
        """Advance to ``t`` and return the trajectory of this leg.

        Parameters
        ----------
        t : Quantity, TimeDelta, float or array_like
            An end time, or output times (monotonic from the simulation's time
            :attr:`t`, which is added as the first output if missing), in the
            simulation's time (0 at the system given); a time Quantity (or an
            astropy TimeDelta, the Quantity in days it holds) for a Quantity
            system, plain floats otherwise.  Backwards is allowed with
            every effect (the time-reversed motion is integrated, velocity-dependent
            effects at the true velocity), with the variational equations and with
            events that record only (not those that stop, merge or remove), not while
            writing an archive (a copy, which writes nothing, may go back).
        progress : bool
            Show a progress bar (tqdm, on stderr) over the output times.
        on_output : callable, optional
            ``on_output(i, steps)`` after output ``i``; it may raise
            :class:`~hamilton_orbits.integrators.StopIntegration` to end the leg there
            (the trajectory then has ``complete == False``).  The simulation stands
            at output ``i`` while it runs (:attr:`t`, :attr:`system`, :attr:`steps`):
            a ``save`` or ``copy`` there continues to the run's bits (integrate the
            copy there, not the simulation itself: that is refused).
        stop : callable, optional
            ``stop()`` after every output and between slices of steps; True ends
            the leg there (``complete == False``).  It sees the simulation at the
            output, or between slices at the time and state its integrator reached.
        on_interrupt : {"raise", "keep"}
            What Ctrl-C does: raise ``KeyboardInterrupt`` (default), or end the leg
            at the last output reached and return it (``complete == False``), as a
            scene does.

        Returns
        -------
        Trajectory

        Raises
        ------
        ValueError
            For bad times, a ``progress`` not True or False, outputs that would take
            more than half the machine's memory (naming ``stm`` when its matrices
            do), or a lost state (a collision or a step too long); for a
            leg forwards from where a collision (action ``"stop"``) ended the run,
            naming its bodies, which are in contact there (go on with a new
            simulation of :attr:`system` in which they are merged or one is
            removed, or watch the collision with action ``"merge"``).  A stop at a
            close approach or an escape goes on: that event is not found again.
            Called from within a call of the same simulation (its ``on_output`` or
            ``stop``), naming ``sim.copy()`` to integrate there instead.
        KeyboardInterrupt
            On Ctrl-C (the run stops within a slice of steps; the simulation keeps
            the state reached, its time and step count with it), unless
            ``on_interrupt="keep"``.  Continued, every method but dop853 gives the
            bits of the run never interrupted (the fixed steps laid from the cut
            interval's start, as after a ``stop()``, in this process; a simulation
            saved then and loaded lays them from the time reached); dop853 begins
            its own steps there.  A Ctrl-C during a compiled call is held until its
            steps are counted and its event acted on (the drivers' ``_held``); a
            second is raised at once.
        """
        if self._busy:  # (from a callback of its own call: refused, see Saving._busy)
            self._refuse_within("integrate")
        t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
        progress = as_flag("progress", progress)  # ("no" was a bar: any text is true)
        if (self._archive is None and on_output is None and stop is None and not progress
                and on_interrupt == "raise"):  # one end time, no archive: the engine's
            # (the integrals measured from time 0 once a leg has begun: after Ctrl-C too)
            start, self._start = self._start, self._initial
            out = self._lean(t)  # lean path, when it can
            if out is not None:
                return self._trajectory(out, self._unit, start, out.wall_time)
            self._start = start
        if on_interrupt not in ("raise", "keep"):
            raise ValueError(f"Expected `on_interrupt` to be 'raise' or 'keep', got "
                             f"{on_interrupt!r}")
        for name, given in (("on_output", on_output), ("stop", stop)):
            if given is not None and not callable(given):  # (not after the first output)
                raise ValueError(f"Expected `{name}` to be callable or None, got {given!r}")
        prop = self._prop
        times, unit = leg_times(t, prop.t, self._quantity)
        if prop.events is not None and times[-1] > times[0]:  # (refused before the
            prop.events.refuse_going_on(self._system.names, self.t)  # leg's snapshot)
        check_output_memory(len(times), len(prop.gm), bool(self._spec[6]))  # (before the
        # leg's arrays: numpy's MemoryError came after the setting up, or never)
        if unit is not None:
            self._unit = unit
        self._resumable = None  # (a call begun: the call a kill interrupted is left)
        step = None if self._archive is None else prop.fixed_step()
        if step is not None and prop.method.name in FIXED_STEP:  # (a call of too many steps
            check_step_count(abs(float(times[-1] - times[0])), step,  # refused before the
                             prop.method.max_steps, prop.method.name)  # leg's first snapshot)
        start, begun = self._start, False  # (start None: this leg begins at time 0)
        self._busy = True  # (its callbacks may copy or save it, not integrate it)
        try:
            if self._archive is not None:
                self._new_leg(times)
            begun = True
            out = self._advance(times, progress, on_output, stop)
        except BaseException:  # (Ctrl-C between the two: the folder released all the same)
            if self._archive is not None:
                self._archive.close()
            if begun:  # (a leg cut by Ctrl-C or an error: the next measures Hamilton's
                self._start = self._initial  # integrals from time 0, as it would have)
            raise
        finally:
            self._busy = False
        self._start = self._initial  # the first leg begins at time 0
        if out.interrupted and on_interrupt == "raise":
            raise KeyboardInterrupt
        return self._trajectory(out, unit, start, out.wall_time)

    def _lean(self, t: Any) -> engine.EngineRun | None:
        """The leg to ``t`` on the engine's lean path (:meth:`engine.Propagation.advance_end`)
        when ``t`` is one end time, a float for a system of floats or a scalar time
        Quantity for a Quantity system (in days as the whole path converts it; the
        simulation's unit then ``t``'s, as the whole path makes it); None otherwise,
        nothing done."""
        if type(t) is float:
            return None if self._unit is not None else self._prop.advance_end(t)
        if not (self._quantity and is_quantity(t) and t.ndim == 0):
            return None
        try:
            end = float(t.to_value(DAY))
        except u.UnitConversionError:  # (not a time: the whole path says so)
            return None
        out = self._prop.advance_end(end)
        if out is not None:
            self._unit = t.unit
        return out

    def _trajectory(self, out: engine.EngineRun, unit: Any, start: Any,
                    wall_time: float) -> Trajectory:
        """The Trajectory of a leg, its close approaches checked against a fixed step
        (a warning, once per simulation, of an encounter a step was too long for)."""
        prop = self._prop
        traj = make_trajectory(self._system, out, unit, prop.method.name, prop.rhs.effects,
                               self._effects, start=start, wall_time=wall_time,
                               encounters=self._encounters)
        warning = encounter_warning(traj)
        if warning is not None and not self._warned and WARN_UNDER_RESOLVED.get():
            self._warned = True  # once per simulation
            warnings.warn(warning, stacklevel=caller_level())
        return traj

    def _advance(self, times: np.ndarray, progress: bool, on_output: Any,
                 stop: Any, leg: np.ndarray | None = None) -> engine.EngineRun:
        """The propagation through ``times`` (the archive's snapshots taken on the
        way); ``leg``: the output times of the whole call that ``times`` finish (a
        resumed call), whose steps a fixed-step method's snapshots are put on."""
        prop = self._prop
        close = None
        try:  # (the archive's folder, claimed by the leg's first snapshot, released below
            # whatever happens: Ctrl-C included)
            if progress:
                on_output, close = progress_reporter(prop.method.name, len(times) - 1,
                                                     on_output)
            archived = (None if self._archive is None or times[-1] < times[0]  # (backwards:
                        else self._archived_times(times, leg))  # no snapshot, see _new_leg)
            if archived is None:
                return prop.advance(times, on_output=on_output, stop=stop)
            out = prop.advance(archived[0], on_output=rows_of(on_output, archived[1]),
                               stop=stop, checkpoint=self._checkpoint(*archived[1:]),
                               pause=self._step_snapshots(),
                               landings=self._time_snapshots(*archived[1:]))
            if prop.events is not None and prop.events.stopped_by is not None:
                self._asked = None  # (stopped at an event's time: the next leg's steps
                # are laid from there, and its snapshots with them)
            return requested_rows(out, archived[1])
        finally:
            if close is not None:
                close()
            if self._archive is not None:
                self._archive.close()

def _archive_of(path: Any, schedule: tuple[Any, Any, Any], exact_times: Any, method: str,
                stepped: bool, quantity: bool, sync: Any) -> ArchiveWriter | None:
    """The archive a simulation of ``method`` (``stepped``: of fixed steps, a ``dt``
    given or chosen by a fixed-step method) writes while it runs (None without
    ``path``)."""
    every, every_steps, every_wall = schedule
    if not isinstance(sync, bool):
        raise ValueError(f"Expected `archive_sync` to be True or False, got {sync!r}")
    if path is None:
        if schedule != (None, None, None) or sync or exact_times is not None:
            raise ValueError("`every`, `every_steps`, `every_wall`, `exact_times` and "
                             "`archive_sync` are an archive's: give `archive` (a folder) "
                             "too")
        return None
    fixed = stepped and method != "dop853"  # (a fixed step's own grid)
    if exact_times is False and not fixed:
        which = "dop853" if method == "dop853" else f"{method} without `dt`"
        raise ValueError(f"Expected `exact_times` True or None with {which}: an adaptive "
                         f"step ends exactly at each snapshot time by its own step "
                         f"control; False takes the snapshots on a fixed step's own steps")
    return ArchiveWriter(path, every=None if every is None else time_step(every, quantity, "every"),
                         every_steps=every_steps, every_wall=_wall_seconds(every_wall),
                         exact=not fixed if exact_times is None else exact_times, sync=sync)


def _wall_seconds(every_wall: Any) -> Any:
    """``every_wall`` in seconds: a time Quantity converted (a TimeDelta as the
    Quantity in days it holds), a NumPy number made a float (the schedule is JSON in
    every snapshot); anything else as given (the archive refuses what is not a
    positive number)."""
    every_wall = time_quantity(every_wall)
    if is_quantity(every_wall):
        return TIME.scalar("every_wall", every_wall, u.s)
    if isinstance(every_wall, (np.floating, np.integer)):
        return float(every_wall)
    return every_wall


def integrate(
    system: System,
    t: Any,
    method: str | Method = "radau15",
    dt: Any = None,
    tol: float | None = None,
    effects: Sequence[str | Mapping[str, Any]] = (),
    progress: bool = False,
    on_output: Any = None,
    events: Any = (),
    variational: bool = False,
    stm: bool = False,
    tangent: Any = None,
    **options: Any,
) -> Trajectory:
    """Integrate Hamilton's equation (B) (plus the listed effects) for ``system``:
    ``Simulation(system, ...).integrate(t)``.

    Parameters
    ----------
    system : System
    t : Quantity, TimeDelta, float or array_like
        An end time, or output times (monotonic; a start at 0 is added if missing).
        A time Quantity (or an astropy TimeDelta, the Quantity in days it holds)
        for a Quantity system, plain floats otherwise.
    method : {"radau15", "wh", "leapfrog", "dop853"} or Method
        The integrator (see :mod:`hamilton_orbits.integrators`), by name or as a
        typed value with its options (``WH(coordinates="jacobi")``).
    dt : Quantity, TimeDelta or float, optional
        A fixed step (``radau15``, ``wh``, ``leapfrog``) or a step cap (``dop853``).
    tol : float, optional
        The integrator's tolerance (adaptive methods) or the accuracy from which a
        fixed-step method chooses its step.
    effects : sequence of str or mapping
        Effects beyond Newtonian gravity: ``"gr"``, ``"gr_potential"``,
        ``{"name": "j2", "body": "earth"}``; see :mod:`hamilton_orbits.effects`.
    progress : bool
        Show a progress bar (tqdm, on stderr) over the output times.
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i`` (for scenes and interfaces); it
        may raise :class:`~hamilton_orbits.integrators.StopIntegration` to end the run
        there, the trajectory then incomplete (``complete == False``).
    events : sequence of str or mapping, optional
        Events to find during the run: ``close_encounter``, ``collision``,
        ``escape`` (see :mod:`hamilton_orbits.events`); the trajectory's
        ``events`` table lists them and ``stopped_by`` names the one that ended
        the run, if any (an end, not a cut: ``complete`` stays True).
    variational : bool
        Integrate the first-order variational equations beside the system (every
        listed effect's Jacobian included): the trajectory then has ``megno`` and
        ``lyapunov`` (from one tangent vector, as rebound's MEGNO; see
        ``docs/variational.md``).  Forwards or backwards (one direction per run),
        without events.
    stm : bool
        With ``variational``: also the state transition matrix ``traj.stm`` (6n
        more tangent vectors; ``(6n)^2`` values an output).  Outputs that would take
        more than half the machine's memory (the STM's counted twice: the
        integrator's and the trajectory's) are refused by name before the run.
    tangent : array_like, shape (n, 6), optional
        MEGNO's initial tangent vector (x, y, z, vx, vy, vz per body, internal
        units); default: random, each body's six components of unit length, as
        rebound's ``init_megno`` draws it (a fixed seed).
    **options
        Options of the chosen integrator, e.g. for ``wh``
        ``coordinates="jacobi"`` and ``corrector=3`` (or 5, 7, 11, 17; see
        :mod:`hamilton_orbits.integrators.methods`).  An option the method does not
        take raises ``ValueError`` listing those it takes.

    Returns
    -------
    Trajectory

    Raises
    ------
    ValueError
        For an unknown method or effect, a velocity-dependent effect given to a
        symplectic integrator (naming the effect and the integrators that accept
        it), or bad times.
    KeyboardInterrupt
        On Ctrl-C (the run stops within a few thousand steps).

    Examples
    --------
    >>> from hamilton_orbits import Body, System, integrate
    >>> import numpy as np
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    >>> traj = integrate(s, 2 * np.pi, method="leapfrog", dt=2 * np.pi / 2000)
    >>> bool(np.allclose(traj.final["dust"].r, [1, 0, 0], atol=1e-4))
    True
    >>> jac = integrate(s, 2 * np.pi, method="wh", dt=0.1, coordinates="jacobi", corrector=3)
    >>> bool(np.allclose(jac.final["dust"].r, [1, 0, 0], atol=1e-12))  # a Kepler orbit: exact
    True
    >>> var = integrate(s, 2 * np.pi, method="wh", dt=0.1, variational=True, stm=True)
    >>> var.stm.shape, var.megno.shape  # d(r, v)(t)/d(r, v)(0) of both bodies; MEGNO
    ((2, 12, 12), (2,))
    >>> integrate(s, 1.0, method="leapfrog", dt=0.1, effects=["gr"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'gr' depends on velocities and integrator 'leapfrog' is symplectic...
    """
    sim = Simulation(system, method, dt, tol, effects, events, variational, stm, tangent,
                     **options)
    return sim.integrate(t, progress=progress, on_output=on_output)


