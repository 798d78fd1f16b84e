"""The float-level engine under every public entry point.

:class:`Propagation` is one integration's whole state on plain arrays (positions,
velocities, GMs in one consistent unit system), a compiled right-hand side
(:class:`hamilton_orbits.rhs.RHS`), the method as a typed value
(:mod:`hamilton_orbits.integrators.methods`), the events log and the variational
equations; :meth:`Propagation.advance` takes it through output times and returns
that leg's plain arrays and step count (:class:`EngineRun`), and the next call
continues from where the last one ended exactly as one call through both legs'
output times would have.  :func:`run` is one propagation advanced once.  Neither
validates what the public layer has validated already, nor converts units.

:class:`hamilton_orbits.Simulation` (and through it ``integrate``, the scenes and
the ensembles), ``crosscheck`` and the report stand on it; none of them calls
another public entry point in a loop.

Stopping early
--------------
``stop()`` is asked after every output; when it returns True, when an output
callback raises :class:`StopIntegration`, or when the user presses Ctrl-C
(``KeyboardInterrupt``) during the run, the engine returns what was reached
(``complete=False``; ``interrupted=True`` for Ctrl-C) instead of losing it.  The
integrators return to Python at least every few thousand steps (radau15) or
every output (the fixed-step maps), so an interrupt is seen promptly.  An event
whose action is ``"stop"`` ends the run as its result, not a cut
(``complete=True``, ``events.stopped_by``); the next leg goes on from there, where
a close approach or an escape is not found again, but not from a collision's
contact (a ``ValueError`` names the pair).

Backward integration
--------------------
Output times that decrease are integrated as the time-reversed motion: forwards
in ``s = -t`` on the reversed velocities ``w = -v``, ``d2r/ds2 = a(r, -w)`` (the
velocity-dependent effects evaluated at the true velocity by
:func:`hamilton_orbits.rhs.time_reversed`; for forces that do not depend on
velocities this is the same right-hand side).  A leg in the other direction from
the one before starts the integrator afresh from the state reached.
"""

from __future__ import annotations

import importlib
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from hamilton_orbits._kernels.checks import all_finite
from hamilton_orbits.events import ACTIONS, W_ACTION, EventLog, StopAtEvent
from hamilton_orbits.firstrun import compile_seconds
from hamilton_orbits.integrators import (
    INTEGRATORS,
    Integrator,
    Method,
    StopIntegration,
    method_of,
)
from hamilton_orbits.integrators._setup import check_dt_tol, check_inputs
from hamilton_orbits.integrators.methods import FIXED_STEP
from hamilton_orbits.rhs import RHS, time_reversed
from hamilton_orbits.validation import ConvergenceError

__all__ = ["EngineRun", "Propagation", "StopIntegration", "integrator", "run"]

#: a number in a driver's message
_NUMBER = r"(-?(?:\d[\d.]*(?:e[+-]?\d+)?|inf))"
#: the times in a driver's message: ``between t = 0.5 and 0.9``, ``reached t = 0.5 of
#: 1.0``, ``t = 0.9``, ``t_out[1] = 1.0`` (not ``dt = ...``)
_TIME_IN_MESSAGE = re.compile(
    rf"(?<![\w.])(?:(between t = ){_NUMBER}( and ){_NUMBER}|(reached t = ){_NUMBER}( of )"
    rf"{_NUMBER}|(t = |t_out\[\d+\] = ){_NUMBER})")


def _turn_back(exc: BaseException) -> None:
    """A driver's error of a backward run, its message's times turned back in place
    (:func:`_turned_back`; its traceback kept)."""
    if isinstance(exc, (ConvergenceError, ValueError)) and exc.args \
            and isinstance(exc.args[0], str):
        exc.args = (_turned_back(exc.args[0]), *exc.args[1:])


def _turned_back(message: str) -> str:
    """A driver's message about a backward run, which it integrates in ``s = -t``:
    its times turned back to the run's (``stopped at t = 0.9068 before t_out[1] =
    1.0`` of a run to t = -1 reads ``t = -0.9068 ... t_out[1] = -1.0``).

    Examples
    --------
    >>> _turned_back("radau15 stopped at t = 0.5 before t_out[1] = 1.0 (dt = 1e-16)")
    'radau15 stopped at t = -0.5 before t_out[1] = -1.0 (dt = 1e-16)'
    """
    def back(match: re.Match[str]) -> str:
        parts = [x for x in match.groups() if x is not None]  # (words, numbers in turn)
        return "".join(x if k % 2 == 0 else (x[1:] if x.startswith("-") else "-" + x)
                       for k, x in enumerate(parts))

    return _TIME_IN_MESSAGE.sub(back, message)


@dataclass(slots=True)
class EngineRun:
    """What :func:`run` and :meth:`Propagation.advance` return: the outputs reached,
    in the caller's units.

    Attributes
    ----------
    t : ndarray, shape (k,)
        The output times reached (``k = len(t_out)`` when ``complete`` and no event
        stopped the run).
    r, v : ndarray, shape (k, n, 3)
        The states at those times.
    steps : int
        Steps taken in this call up to the last output reached (a run stopped
        inside an output interval took more: the propagation's ``steps`` counts
        them).
    wall_time : float
        Seconds of the integration proper (numba's compilation during it left out).
    complete : bool
        False if the run was cut short (``stop()``, :class:`StopIntegration` from
        an output callback, or Ctrl-C).  A stop by an event's action is the run's
        end, not a cut: ``complete`` stays True (``events.stopped_by`` says it).
    events : EventLog or None
        The events found (when any were watched); an event that stopped the run
        is ``events.stopped_by``, and ``t[-1]`` is its time (or, with wh and
        leapfrog, the end of the step it occurred in).
    gm : ndarray, shape (n,) or (k, n)
        ``G m`` of every body; per output, (k, n), when merges or removals
        changed it during the run.
    variational : Tangent or None
        The variational equations of the run (MEGNO, the Lyapunov exponent and the
        STM at the outputs), when they were asked for.
    interrupted : bool
        True if Ctrl-C ended the run (``complete`` is then False).
    first_event : int
        The index in ``events.recorded()`` of the first event found in this call.
    finite : bool
        True if every position and velocity of the outputs is finite (False also
        when bodies taken out of the run are NaN).
    """

    t: np.ndarray
    r: np.ndarray
    v: np.ndarray
    steps: int
    wall_time: float
    complete: bool
    events: EventLog | None
    gm: np.ndarray
    variational: Any = None
    interrupted: bool = False
    first_event: int = 0
    finite: bool = True


def integrator(method: str) -> Integrator:
    """The driver module of ``method`` (ValueError listing the known ones).

    Examples
    --------
    >>> integrator("leapfrog").NAME
    'leapfrog'
    >>> integrator("rk4")
    Traceback (most recent call last):
    ...
    ValueError: Unknown `method` 'rk4'; known: radau15, wh, leapfrog, dop853
    """
    module = _MODULES.get(method)
    if module is None:
        if method not in INTEGRATORS:
            raise ValueError(f"Unknown `method` {method!r}; known: {', '.join(INTEGRATORS)}")
        module = _MODULES[method] = importlib.import_module(
            f"hamilton_orbits.integrators.{method}")
    return module


_MODULES: dict[str, Integrator] = {}


class Propagation:
    """One integration's state on plain arrays, advanced leg by leg.

    Parameters
    ----------
    r0, v0 : ndarray, shape (n, 3)
    gm : ndarray, shape (n,)
    t0 : float
        The time of ``r0``, ``v0``.
    rhs : RHS
        The compiled right-hand side (:func:`hamilton_orbits.rhs.compile_rhs`).
    method : Method
        The method and its options, checked
        (:func:`hamilton_orbits.integrators.methods.method_of`).
    dt, tol : float, optional
        The integrator's step and tolerance, positive and finite (or None).
    events : EventLog, optional
        Events to watch (:mod:`hamilton_orbits.events`); backwards, those that
        only record (their times turned back from the reversed motion's).
    variational : Tangent, optional
        Tangent vectors to integrate beside the state
        (:class:`hamilton_orbits.integrators._tangent.Tangent`; ``rhs`` compiled with
        ``variational=True``); without events, in one direction (a backward run
        integrates the time-reversed motion's tangent vectors, its STM turned
        back at the outputs).

    Examples
    --------
    Two legs give the bits of one call through both legs' output times:

    >>> from hamilton_orbits.integrators import Radau15
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]]); v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    >>> gm = np.array([1.0, 0.0])
    >>> legs = Propagation(r0, v0, gm, 0.0, newtonian_rhs(), Radau15())
    >>> _ = legs.advance(np.array([0.0, 1.0]))
    >>> second = legs.advance(np.array([1.0, 2.5]))
    >>> once = Propagation(r0, v0, gm, 0.0, newtonian_rhs(), Radau15()).advance(
    ...     np.array([0.0, 1.0, 2.5]))
    >>> bool(np.array_equal(second.r[-1], once.r[-1])), legs.t, legs.steps == once.steps
    (True, 2.5, True)
    """

    def __init__(self, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float, rhs: Any,
                 method: Method, *, dt: float | None = None, tol: float | None = None,
                 events: EventLog | None = None, variational: Any = None) -> None:
        # C-contiguous float64, not copied when it is already (read-only is fine: the
        # drivers copy what they change)
        self.r, self.v, self.gm0 = (
            x if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous
            else np.require(x, np.float64, ["C"]) for x in (r0, v0, gm))
        self.gm = self.gm0
        self.t, self.rhs, self.method, self.dt, self.tol = float(t0), rhs, method, dt, tol
        if variational is not None and events is not None and len(events.watch):
            raise ValueError("The variational equations are integrated without events; list "
                             "no events, or integrate them apart")
        self.events, self.variational = events, variational
        self.module = integrator(method.name)
        #: the driver's state (made on the first leg, when the direction is known)
        self.driver: Any = None
        self.backward = False
        #: steps taken by earlier drivers (a change of direction starts a new one)
        self.steps_before = 0
        #: a collision at the start stops the first leg there
        self.stop_at_start = False

    @property
    def steps(self) -> int:
        """Steps taken since the start."""
        return self.steps_before + (self.driver.steps if self.driver is not None else 0)

    def fixed_step(self) -> float | None:
        """The step of a run of fixed steps: ``dt``, or the one a fixed-step method
        (wh, leapfrog) chooses at the start without it (its driver's, once made;
        before, the one it will choose from the state it starts from); None for an
        adaptive method, or one not yet known: events watched, the driver not made)."""
        if self.dt is not None or self.method.name not in FIXED_STEP:
            return self.dt
        if self.driver is not None:
            return float(self.driver.dt)
        if self.events is not None and len(self.events.watch):
            return None  # (chosen from the state after the collisions at the start, which
            # the driver's making carries out: not known before)
        return self.module.chosen_step(self.r, self.v, self.gm, self.tol)

    def _check(self, backward: bool) -> None:
        watched = self.events is not None and len(self.events.watch)
        if self.variational is not None and self.driver is not None:
            raise ValueError(f"The variational equations are integrated in one direction: "
                             f"this run went {'back' if self.backward else 'for'}wards (to t = "
                             f"{self.t!r}); start a new run from the state reached")
        if self.variational is not None and backward and \
                time_reversed(self.rhs).augmented is None:
            raise ValueError("The variational equations of this right-hand side are not "
                             "integrated backwards (its time-reversed form has none)")
        if watched and backward and np.any(self.events.watch[:, W_ACTION] != ACTIONS["record"]):
            raise ValueError("Events with an action (stop, merge, remove) are watched forwards "
                             "in time only; a backward run records them (action 'record')")
        if backward and self.events is not None and (self.events.gone
                                                     or self.events.gm_changes):
            raise ValueError(f"This run merged or removed bodies (events) before t = "
                             f"{self.t!r}: it goes on forwards only (backwards the bodies "
                             f"would not come apart); start a new run from the state "
                             f"reached to integrate it backwards")

    def driver_for(self, backward: bool) -> Any:
        """The driver's state for a leg in this direction (a new one from the state
        reached when the direction changes)."""
        if self.driver is not None and backward == self.backward:
            return self.driver
        self._check(backward)
        if self.driver is not None:
            self.steps_before += self.driver.steps
        watched = self.events is not None and len(self.events.watch)
        sign = -1.0 if backward else 1.0
        if self.driver is None and watched:
            self._collisions_at_start()
        # the log also masks the bodies taken out of the run in the outputs, after the
        # last watched pair has gone with them
        log = self.events if watched or (self.events is not None and self.events.gone
                                         and not backward) else None
        if backward and self.variational is not None:  # (tangent vectors (dr, -dv))
            self.variational.dv0 = -self.variational.dv0
        if self.events is not None:  # (the rows found so far in the last direction's time)
            self.events.drain()
            self.events.sign = -1.0 if backward else 1.0
        # backwards: the motion in s = -t, on w = -v (its effects at the velocity -w)
        self.driver = self.module.start(
            time_reversed(self.rhs) if backward else self.rhs, self.r,
            -self.v if backward else self.v, self.gm, sign * self.t,
            self.method, dt=self.dt, tol=self.tol, events=log, variational=self.variational)
        self.backward = backward
        return self.driver

    def _collisions_at_start(self) -> None:
        """Bodies that overlap at the start: their collisions happen here, at the first
        leg's start (:meth:`~hamilton_orbits.events.EventLog.at_start`), on copies of
        the state; a stop is kept for :meth:`advance` to end the leg at its start."""
        r, v, gm = self.r.copy(), self.v.copy(), self.gm.copy()
        self.stop_at_start = self.events.at_start(self.t, r, v, gm)
        if self.events.gm_changes:
            self.r, self.v, self.gm = r, v, gm

    def advance(self, t_out: np.ndarray, *, on_output: Callable[[int, int], None] | None = None,
                stop: Callable[[], bool] | None = None,
                checkpoint: Callable[[int], None] | None = None,
                pause: Any = None, landings: Any = None) -> EngineRun:
        """Integrate through ``t_out`` (strictly monotonic, ``t_out[0]`` the current
        time :attr:`t`, forwards or backwards); see :func:`run`.  ``checkpoint(i)``
        (forwards only) is called at output ``i`` with the propagation standing there
        as a leg ending at ``t_out[i]`` would leave it (a snapshot taken then
        continues bit for bit).  ``pause()`` (forwards only; a driver that can pause
        between steps, radau15's) is called between two steps once :attr:`steps`
        reaches ``pause.at``, the propagation standing at the driver's own state
        (the steps unchanged: a snapshot taken then continues bit for bit).
        ``landings`` (forwards only, with ``checkpoint``): the output rows that are
        snapshots alone (``landings.only``), which a driver that can land on them and
        write them itself (radau15's) may leave unreported (:class:`_Landings`).
        ``on_output(i, steps)`` and ``stop()`` after output ``i`` see the propagation
        standing there as ``checkpoint`` does (a snapshot or copy taken in them
        continues as the run does).  A leg forwards from where a collision stopped
        the run is refused with a ``ValueError`` naming the pair
        (:meth:`~hamilton_orbits.events.EventLog.refuse_going_on`)."""
        n_t = t_out.shape[0]
        backward = n_t > 1 and t_out[-1] < t_out[0]
        events = self.events
        first_event = self._leg_events(n_t > 1 and not backward)
        driver = self._driver_for_leg(backward)
        rows = np.empty((2, n_t) + self.r.shape)  # positions and velocities, one block
        r_out, v_out = rows[0], rows[1]
        r_out[0], v_out[0] = self.r, self.v
        if backward:  # (stored as the driver's rows are, turned back below with them)
            np.negative(v_out[0], out=v_out[0])
        if events is not None:
            events.mask(r_out[0], v_out[0])
        if self.variational is not None:
            self.variational.new_leg(n_t)
        reached = [0, 0]  # last output index, steps
        calling = [False]  # (a callback's own error is not the driver's: left as it is)
        stand = checkpoint is not None or on_output is not None or stop is not None

        def report(i: int, steps: int) -> None:
            reached[0], reached[1] = i, steps
            calling[0] = True
            if stand:  # (a callback sees the output it is told of: see above)
                self._stand_at(float(t_out[i]), r_out[i], -v_out[i] if backward else v_out[i])
            if checkpoint is not None:
                checkpoint(i)
            if on_output is not None:
                on_output(i, steps)
            if stop is not None and stop():
                raise StopIntegration
            calling[0] = False

        t_reached = t_out
        start, steps0 = time.perf_counter(), driver.steps
        compiled = compile_seconds()  # (a first call compiles: not integration)
        complete, interrupted = True, False
        try:
            if self.stop_at_start:  # a collision at the start stops the run there
                self.stop_at_start = False
                raise StopAtEvent(0, self.t, 0)
            self._drive(driver, -t_out if backward else t_out, (r_out, v_out), report, stop,
                        (pause, landings))
            reached[0], reached[1] = n_t - 1, driver.steps - steps0
        except StopAtEvent as stopped:
            reached[0], reached[1] = stopped.index, stopped.steps
            t_reached = np.array(t_out, dtype=np.float64)  # the caller's array unchanged
            t_reached[stopped.index] = stopped.t
        except StopIntegration:
            complete = False
        except KeyboardInterrupt:
            complete, interrupted = False, True
        except BaseException as exc:  # (an error, the driver's or a callback's: the
            self._between_outputs(driver)  # propagation keeps the state reached, as on
            if backward and not calling[0]:  # Ctrl-C; a driver's message in the run's time)
                _turn_back(exc)
            raise
        wall = max(time.perf_counter() - start - (compile_seconds() - compiled), 0.0)
        k = reached[0] + 1
        if backward:  # in place: no second copy of the history
            np.negative(v_out, out=v_out)
            _stm_forwards(self.variational, k)
        t_end = float(t_reached[k - 1])
        if driver.t == (-t_end if backward else t_end):  # the driver stands at the last output
            self.r, self.v, self.t = r_out[k - 1], v_out[k - 1], t_end
            if events is not None and events.gm_changes:
                self.gm = events.gm_at(np.array([t_end]), self.gm0)[0]
        else:
            self._between_outputs(driver)
        gm_out = (events.gm_at(t_reached[:k], self.gm0)
                  if events is not None and events.gm_changes else self.gm0)
        if k < n_t:
            t_reached, r_out, v_out, rows = t_reached[:k], r_out[:k], v_out[:k], rows[:, :k]
        finite = all_finite(rows.reshape(-1))  # one compiled pass over both
        return EngineRun(t_reached, r_out, v_out, reached[1], wall, complete, events, gm_out,
                         self.variational, interrupted, first_event, finite)

    def _leg_events(self, onwards: bool) -> int:
        """The number of events recorded before a leg begins (0 without events), the
        last leg's stop forgotten; a leg ``onwards`` (forwards, past its start) from
        where a collision stopped the run refused, naming the pair."""
        events = self.events
        if events is None:
            return 0
        if onwards:  # (not on through a collision's stop)
            events.refuse_going_on(when=self.t)
        events.stopped_by = None
        return len(events.recorded())

    def _driver_for_leg(self, backward: bool) -> Any:
        """The driver of a leg in this direction; made afresh where bodies are in
        contact as the leg begins (a contact no crossing will reveal, not one a
        collision stopped the run at, which :meth:`advance` refuses): they collide
        at its start, as at a first leg's (:meth:`driver_for`)."""
        if (self.events is not None and self.driver is not None and not backward
                and not self.backward and self.events.overlapping(self.r)):
            self.steps_before += self.driver.steps
            self.driver = None
        if self.driver is not None and backward == self.backward:
            return self.driver
        return self.driver_for(backward)

    def advance_end(self, t_end: float) -> EngineRun | None:
        """A leg to the one later time ``t_end`` (a finite Python float), forwards,
        with nothing watched, called back or asked: the same steps and the same
        bits as ``advance(np.array([t, t_end]))``, with less wrapping around them
        (the continuing call of a prepared simulation: its cost is mostly wrapping).
        None when the leg is not of that kind (no driver yet, a backward leg, events
        or variational equations): the caller then calls :meth:`advance`.  On
        Ctrl-C or an error the propagation keeps the driver's state, as
        :meth:`advance` does, and the exception goes on."""
        driver = self.driver
        if (driver is None or self.backward or self.events is not None
                or self.variational is not None or not self.t < t_end < np.inf):
            return None
        t_out = np.array((self.t, t_end))
        rows = np.empty((2, 2) + self.r.shape)  # positions and velocities, one block
        r_out, v_out = rows[0], rows[1]
        r_out[0], v_out[0] = self.r, self.v
        start, steps0, compiled = time.perf_counter(), driver.steps, compile_seconds()
        try:
            driver.advance(t_out, r_out, v_out, None, None)
        except BaseException:  # (Ctrl-C, or an error such as max_steps reached)
            self._between_outputs(driver)
            raise
        wall = max(time.perf_counter() - start - (compile_seconds() - compiled), 0.0)
        if driver.t == t_end:  # (as advance: else the driver's own state is kept)
            self.r, self.v, self.t = r_out[1], v_out[1], t_end
        else:  # pragma: no cover - no driver stops between outputs unasked
            self._between_outputs(driver)
        return EngineRun(t_out, r_out, v_out, driver.steps - steps0, wall, True, None, self.gm0,
                         None, False, 0, all_finite(rows.reshape(-1)))

    def _drive(self, driver: Any, t_out: np.ndarray, rows: tuple[np.ndarray, np.ndarray],
               report: Callable[[int, int], None], stop: Any,
               snapshots: tuple[Any, Any]) -> None:
        """``driver.advance`` through ``t_out``, ``snapshots`` (``pause``, ``landings``:
        see :meth:`advance`) set on a driver that takes them (and cleared after);
        ``stop()``, which the driver asks between slices of
        steps, asked with the propagation standing at the driver's state (its time,
        as its step count is; the bodies taken out at NaN)."""
        if stop is not None:
            asked = stop

            def stop() -> bool:
                r, v, _ = driver.state()  # (copies: the driver's own kept)
                if self.events is not None:
                    self.events.mask(r, v)
                sign = -1.0 if self.backward else 1.0  # (gm as at the outputs: not
                self._stand_at(sign * driver.t, r, sign * v)  # replaced when unchanged)
                return asked()

        pause, landings = snapshots
        pausing = pause is not None and hasattr(driver, "pause")
        landing = landings is not None and hasattr(driver, "landings") and stop is None
        if pausing:
            driver.pause = _Pause(self, pause)
        if landing:
            driver.landings = _Landings(self, landings)
        try:
            driver.advance(t_out, *rows, report, stop)
        finally:
            if pausing:
                driver.pause = None
            if landing:
                driver.landings = None

    def _stand_at(self, t: float, r: np.ndarray, v: np.ndarray) -> None:
        """Stand at time ``t`` with its state (``v`` the true velocities), as a leg
        ending there (``gm`` replaced only where events changed it)."""
        self.r, self.v, self.t = r, v, t
        if self.events is not None and self.events.gm_changes:
            self.gm = self.events.gm_of(t, self.gm0)

    def _between_outputs(self, driver: Any) -> None:
        """Keep the state of a leg stopped between outputs: the driver's own state at
        its own time."""
        r_now, v_now, self.gm = driver.state()
        sign = -1.0 if self.backward else 1.0
        self.r, self.v, self.t = r_now, sign * v_now, sign * driver.t


class _Written:
    """What a driver's kernel wrote for a caller (``caller``: its ``pause`` or
    ``landings``), counted in the propagation's steps."""

    def __init__(self, prop: Propagation, caller: Any) -> None:
        self.prop, self.caller = prop, caller

    def wrote(self, plan: np.ndarray, last: int) -> None:
        """Count the snapshots the kernel wrote with ``plan``, the last after ``last``
        of the driver's steps."""
        self.caller.wrote(plan, self.prop.steps_before + last)


class _Pause(_Written):
    """A caller's ``pause`` as the driver sees it: ``at`` counted in the driver's own
    steps, and the propagation made to stand at the driver's state before it."""

    def __init__(self, prop: Propagation, pause: Any) -> None:
        super().__init__(prop, pause)
        self.mine: tuple[np.ndarray, np.ndarray] | None = None  # (the r, v it put)

    @property
    def at(self) -> int:
        return self.caller.at - self.prop.steps_before

    def __call__(self, again: bool = False) -> None:
        """Stand at the driver's state and pause (``again``: as the driver says, only
        its steps since the last pause; then also only ``r``, ``v``, ``t`` of the
        propagation were put in their places)."""
        prop, mine, driver = self.prop, self.mine, self.prop.driver
        if again and mine is not None and prop.r is mine[0] and prop.v is mine[1]:
            r, v = mine  # (its own arrays, seen by no one else: refilled, a snapshot's
            driver.state_into(r, v)  # record then finds the same arrays)
        else:
            r, v, _ = driver.state()
            self.mine = (r, v)
        if prop.events is not None:  # (the bodies taken out at NaN, as in the outputs:
            prop.events.mask(r, v)  # the driver keeps their parked state to go on)
        prop._stand_at(driver.t, r, v)
        self.caller(again)

    def compiled(self, arrays: dict[str, np.ndarray],
                 t_at: tuple[str, int], steps: int) -> tuple[np.ndarray, tuple[Any, ...]] | None:
        """The plan with which the driver's kernel (its arrays ``arrays``, its time at
        ``t_at``, ``steps`` its steps) writes the caller's next snapshots itself, or
        None (see ``_EverySteps.compiled``); the positions and velocities this pause
        puts in the propagation are the kernel's at a snapshot."""
        ask = getattr(self.caller, "compiled", None)
        if ask is None or self.mine is None or self.prop.events is not None:
            return None
        return ask(arrays, [(self.mine[0], "r"), (self.mine[1], "v")], t_at, steps)


class _Landings(_Written):
    """A caller's snapshot rows as the driver sees them: ``only[i]`` where output row
    ``i`` is a snapshot alone (no caller's output, so not reported when the driver
    writes it), and the plan with which the driver's kernel lands on such rows and
    writes their snapshots itself, with the propagation standing at the last
    reported row."""

    @property
    def only(self) -> np.ndarray:
        """Whether each output row is a snapshot alone."""
        return self.caller.only

    def through(self, i: int) -> int:
        """The first row from ``i`` on that is not a snapshot alone."""
        return self.caller.through(i)

    def compiled(self, arrays: dict[str, np.ndarray], t_at: tuple[str, int], steps: int,
                 times: np.ndarray) -> tuple[np.ndarray, tuple[Any, ...]] | None:
        """The plan with which the driver's kernel (its arrays ``arrays``, its time at
        ``t_at``, ``steps`` its steps) lands on ``times`` and writes their snapshots,
        or None (events watched); asked right after a snapshot row, where the
        positions and velocities the propagation stands at are the kernel's."""
        prop = self.prop
        if prop.events is not None:
            return None
        return self.caller.compiled(arrays, [(prop.r, "r"), (prop.v, "v")], t_at, steps,
                                      times)


def _stm_forwards(tangent: Any, k: int) -> None:
    """The STMs of a backward leg's outputs 1 ... ``k - 1``, made of the time-reversed
    motion's tangent vectors ``(dr, dw)`` that started as ``(dr, -dv)``, turned into
    those of ``(r, v)``: their velocity rows negated (``D M D`` with ``D = diag(1, -1)``
    per body, the columns' ``D`` given at the start)."""
    if tangent is None or tangent.stm is None or k < 2:
        return
    rows = tangent.stm[1:k].reshape(k - 1, tangent.n, 6, -1)
    np.negative(rows[:, :, 3:], out=rows[:, :, 3:])


def run(
    r0: np.ndarray,
    v0: np.ndarray,
    gm: np.ndarray,
    t_out: np.ndarray,
    rhs: Any,
    method: str | Method,
    *,
    dt: float | None = None,
    tol: float | None = None,
    options: dict[str, Any] | None = None,
    on_output: Callable[[int, int], None] | None = None,
    stop: Callable[[], bool] | None = None,
    events: EventLog | None = None,
    variational: Any = None,
) -> EngineRun:
    """Integrate from ``(r0, v0)`` at ``t_out[0]`` through the output times.

    Parameters
    ----------
    r0, v0 : ndarray, shape (n, 3)
    gm : ndarray, shape (n,)
    t_out : ndarray, shape (n_t,)
        Strictly monotonic output times, ``t_out[0]`` the start (forwards or
        backwards).
    rhs : RHS
        The compiled right-hand side (:func:`hamilton_orbits.rhs.compile_rhs`).
    method : str or Method
        One of :data:`hamilton_orbits.integrators.INTEGRATORS`, or its typed value.
    dt, tol : float, optional
        The integrator's step and tolerance (see each integrator).
    options : dict, optional
        The integrator's own options (e.g. ``coordinates`` for ``wh``) beside a
        method's name.
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i``; may raise
        :class:`StopIntegration`.
    stop : callable, optional
        ``stop()`` after every output; True ends the run there.
    events : EventLog, optional
        Events to watch (:mod:`hamilton_orbits.events`); an event whose action is
        ``"stop"`` ends the run at its time (the last output row).
    variational : Tangent, optional
        Tangent vectors to integrate beside the state
        (:class:`hamilton_orbits.integrators._tangent.Tangent`; ``rhs`` compiled with
        ``variational=True``); without events, in one direction (a backward run
        integrates the time-reversed motion's tangent vectors, its STM turned
        back at the outputs).

    Returns
    -------
    EngineRun

    Examples
    --------
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]]); v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    >>> out = run(r0, v0, np.array([1.0, 0.0]), np.array([0.0, np.pi, 2 * np.pi]),
    ...           newtonian_rhs(), "radau15")
    >>> out.complete, out.r.shape, bool(np.allclose(out.r[-1], r0, atol=1e-12))
    (True, (3, 2, 3), True)
    >>> half = run(r0, v0, np.array([1.0, 0.0]), np.array([0.0, np.pi, 2 * np.pi]),
    ...            newtonian_rhs(), "radau15", stop=lambda: True)
    >>> half.complete, half.t.tolist() == [0.0, np.pi]
    (False, True)
    """
    typed = method_of(method, options)
    if not isinstance(rhs, RHS):
        raise ValueError(f"Expected `rhs` to be a compiled right-hand side "
                         f"(hamilton_orbits.rhs.compile_rhs), got {rhs!r}")
    t_arr = np.asarray(t_out, dtype=np.float64)
    if t_arr.ndim != 1 or t_arr.shape[0] < 1:
        raise ValueError(f"Expected `t_out` to be a 1-d array of output times (the start "
                         f"first), got {t_out!r}")
    t_arr = np.ascontiguousarray(t_arr)
    backward = t_arr.shape[0] > 1 and t_arr[-1] < t_arr[0]
    r0, v0, gm, _ = check_inputs(r0, v0, gm, -t_arr if backward else t_arr)
    dt, tol = check_dt_tol(dt, tol)
    return Propagation(r0, v0, gm, float(t_arr[0]), rhs, typed, dt=dt, tol=tol, events=events,
                       variational=variational).advance(t_arr, on_output=on_output, stop=stop)
