"""Adaptive 15th-order Gauss-Radau integrator in the manner of IAS15.

Written from Everhart (1985) and Rein & Spiegel (2015), MNRAS 446, 1424
("IAS15"), section numbers below refer to the latter.

Within a step of length ``dt`` the acceleration is the polynomial (eq. 4)

    a(h) = a0 + b0 h + b1 h^2 + ... + b6 h^7,      h = (t - t0) / dt,

or equivalently (eq. 5) in Newton's divided-difference form on the Gauss-Radau
spacings ``h_0 = 0 < h_1 < ... < h_7 < 1``,

    a(h) = a0 + g0 h + g1 h (h - h1) + ... + g6 h (h - h1) ... (h - h6).

Integrating twice gives positions and velocities at the spacings (eqs. 6, 7);
the accelerations there update the ``g`` (and hence ``b``) by a
predictor-corrector iteration (section 2.2) that stops when the relative change
of ``b6`` is below 1e-16 or stops decreasing.  Position and velocity are
accumulated with compensated (Kahan) summation (section 2.4).  The step error is
estimated from the last term, ``max |b6| / max |a|`` over all bodies (the
global criterion of section 3.2), and the next step is
``dt (epsilon / error)^(1/7)`` (eq. 11) with the safety factor 0.25 of IAS15:
a step whose estimate asks for less than a quarter of itself is rejected and
redone, and steps grow by at most a factor 4.  The ``b`` of the next step are
predicted from the converged ones of the last (section 2.5), with the
difference between the last prediction and its converged values added as a
correction.

The stepping loop between two output times is one compiled call
(``hamilton_orbits._kernels.radau15.advance``, which takes the acceleration
function as its first argument); the last step before an output time is
shortened to land on it exactly.  This module is the driver: checks, the first
step, the state between calls, and the output arrays.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import radau15 as _k
from hamilton_orbits._kernels import records as _rec
from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import StopIntegration, _setup, _tangent
from hamilton_orbits.integrators._held import HELD
from hamilton_orbits.integrators.methods import (
    CRITERIA,
    MAX_STEPS,
    PRECISIONS,
    RADAU15_TOL_FLOOR,
    Radau15,
    check_run,
)
from hamilton_orbits.rhs import run_parameters
from hamilton_orbits.validation import ConvergenceError

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "CRITERIA", "DEFAULT_TOL", "MAX_STEPS", "NAME",
           "PRECISIONS", "RADAU_SPACINGS", "TOL_FLOOR", "compile_ahead", "run", "start"]

NAME = "radau15"
ACCEPTS_VELOCITY_DEPENDENT = True
DEFAULT_TOL = 1e-9  # IAS15's epsilon (Rein & Spiegel 2015, section 3.2)
DEFAULT_CRITERION = "prs23"
#: Gauss-Radau spacings on [0, 1] (see :data:`hamilton_orbits._kernels.radau15.DECIMAL_SPACINGS`).
RADAU_SPACINGS = np.array([float(x) for x in _k.DECIMAL_SPACINGS])
#: Steps per compiled call: the driver returns to Python this often (Ctrl-C).
SLICE = 20000
#: the kernel's archive arguments when it writes no snapshot (a plan of no interval)
_NO_PLAN = (np.zeros(_rec.P_RUNS, np.int64), ())


def compile_ahead(events: bool) -> None:
    """On a first run, the stepping kernel a run in double precision without the
    variational equations calls (with the events' code when ``events``) sent to
    compile in a second process (``hamilton_orbits._kernels.entry.compile_ahead``),
    Hamilton's integrals compiled here while this process waits for it."""
    from hamilton_orbits import integrals
    from hamilton_orbits._kernels.entry import compile_ahead as send

    send([_k.advance_watched if events else _k.advance], meanwhile=[integrals.prepare])


def run(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_out: np.ndarray,
        **options: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """Integrate with the adaptive 15th-order Gauss-Radau scheme (IAS15-like).

    Parameters
    ----------
    rhs : RHS
        The compiled right-hand side (:func:`hamilton_orbits.rhs.newtonian_rhs`
        or one composed from listed effects); velocity-dependent effects are
        accepted.
    r0, v0 : ndarray, shape (n, 3)
        Initial positions and velocities (internal units).
    gm : ndarray, shape (n,)
        ``G m`` of each body, ``>= 0`` (0 for test particles).
    t_out : ndarray, shape (n_t,)
        Increasing output times; ``t_out[0]`` is the initial time.
    dt : float, optional
        With ``tol`` unset: fixed step (the last step before each output time
        is shortened to land on it).  With ``tol``: the first trial step.
    tol : float, optional
        IAS15's epsilon for the step control (default 1e-9 when ``dt`` is not
        given either); ``max |b6| / max |a| ~ tol`` per step.  At least
        :data:`TOL_FLOOR` (float64's rounding; a ValueError below it).
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i`` is reached.
    max_steps : int, optional
        Give up (``ConvergenceError``) after this many steps in the whole run, or
        as soon as the pace so far projects more than 100 times as many
        (default :data:`MAX_STEPS`).
    criterion : {"global", "prs23"}, optional
        The step-size control: ``"global"`` estimates the error from the last
        term, ``dt_new = dt (epsilon / (max |b6| / max |a|))^(1/7)`` (Rein &
        Spiegel 2015, eq. 11 with the global estimate of section 3.2);
        ``"prs23"`` sets ``dt_new = (7! epsilon)^(1/7) min tau`` with the
        timescale ``tau^2 = 2 |a|^2 / (|a'|^2 + |a| |a''|)`` of each body at the
        end of the step (Pham, Rein & Spiegel 2024, the criterion rebound's
        IAS15 uses by default), which takes about half the steps on eccentric
        orbits at the same energy error.
    events : EventLog, optional
        Events to look for after every step on the step's polynomial; an event
        with an action stops or changes the run at its own time
        (:mod:`hamilton_orbits.events`).  A stop raises
        :class:`~hamilton_orbits.events.StopAtEvent` with the output row that
        holds the state at that time.
    tangent_control : bool, optional
        With ``variational``: let the tangent vectors take part in the step-size
        control (default False: the step is chosen from the bodies alone, and the
        tangent vectors, integrated by the same steps, do not shorten it).
    variational : Tangent, optional
        The variational equations to integrate beside the state
        (:class:`hamilton_orbits.integrators._tangent.Tangent`; ``rhs`` compiled with
        ``variational=True``); MEGNO, the Lyapunov exponent and the STM are written
        into it at the outputs.  Not with ``events``.
    precision : {"double", "double-double"}, optional
        ``"double-double"``: every number a double-double (about 32 digits;
        :mod:`hamilton_orbits._kernels.radau15_dd`), at fixed steps of ``dt``
        (required; ``tol`` refused; more than ``max_steps`` of them refused
        before the first, ``ValueError``), Newtonian gravity only (no effects, no
        events), about 200 times the cost of a double-precision step.  What
        is left is the truncation error, which falls as ``dt^16``: two runs at
        ``dt`` and ``dt / 2`` measure it.  For references (the report's solar
        system: 1 day, agreeing with 2 days to 1e-15 after 1000 years); the
        outputs are rounded to doubles.

    Returns
    -------
    r, v : ndarray, shape (n_t, n, 3)
        States at ``t_out`` (row 0 the initial state).
    steps : int
        Accepted steps taken.

    Raises
    ------
    ValueError
        Non-finite or ill-shaped input, negative ``gm``, non-increasing
        ``t_out``, ``dt <= 0`` or ``tol`` below :data:`TOL_FLOOR`.
    ConvergenceError
        If an acceleration becomes non-finite (a collision) or the step
        underflows, naming the time reached.

    Examples
    --------
    A circular orbit of unit radius (G m = 1) over one period:

    >>> import numpy as np
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> r0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    >>> v0 = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> r, v, steps = run(newtonian_rhs(), r0, v0, np.array([1.0, 0.0]),
    ...                   np.array([0.0, 2 * np.pi]))
    >>> bool(np.allclose(r[-1], r0, atol=1e-12))
    True
    """
    return _setup.run_once(start, Radau15, rhs, r0, v0, gm, t_out, **options)


def start(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
          method: Radau15, *, dt: float | None, tol: float | None,
          events: EventLog | None = None, variational: Any = None) -> Any:
    """The integrator's state at ``t0`` (a :class:`~hamilton_orbits.integrators.
    DriverState`), for arguments already checked (``method`` a :class:`Radau15`,
    ``dt`` and ``tol`` positive floats or None); it is advanced output interval by
    output interval, across calls, exactly as one run through all of them.

    The first trial step, when ``dt`` is not given, is :func:`_setup.initial_step`
    (1/100 of the shortest pair free-fall time); the span of a first call does not
    shorten it, so that a run continued in legs takes the steps of one run.
    """
    check_run(method, dt, tol, variational is not None)  # (a `tol` below TOL_FLOOR)
    if method.precision != "double":
        if variational is not None:
            raise ValueError("radau15 in double-double integrates no variational equations; "
                             "use precision='double' with variational=True")
        return _DoubleDouble(rhs, r0, v0, gm, t0, dt, tol, events, method.max_steps)
    if dt is None and tol is None:
        tol = DEFAULT_TOL
    if dt is None:
        dt = _setup.initial_step(r0, v0, gm)
    prs23 = method.criterion == "prs23"
    if variational is not None:
        return _tangent.Radau15Tangent(rhs, r0, v0, gm, t0, variational, dt=dt, tol=tol or 0.0,
                                       prs23=prs23, max_steps=method.max_steps,
                                       slice_steps=SLICE, control=method.tangent_control)
    log = events if events is not None else EventLog.none(r0.shape[0])
    return _Run(rhs, r0, v0, gm.copy(), t0, dt, tol or 0.0, prs23, log, method.max_steps)


class _DoubleDouble:
    """radau15 in double-double (``precision="double-double"``, see :func:`run`): the
    state between calls."""

    #: not saved: where the interval a Ctrl-C cut began and the steps taken in it
    #: (:func:`~hamilton_orbits.integrators._setup.interval_origin`)
    RESTART_SCRATCH = ("cut",)

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 dt: float | None, tol: float | None, events: EventLog | None,
                 max_steps: int) -> None:
        if dt is None or tol is not None:
            raise ValueError("radau15 in double-double runs fixed steps: give `dt` and no "
                             f"`tol`, got dt = {dt!r}, tol = {tol!r}")
        if rhs.effects != ("newtonian",):
            raise ValueError("radau15 in double-double computes Newtonian gravity only; "
                             f"listed: {', '.join(rhs.effects[1:])}")
        if events is not None and len(events.watch):
            raise ValueError("radau15 in double-double watches no events")
        n = r0.shape[0]
        self.x = np.zeros((n, 3, 2))
        self.v = np.zeros((n, 3, 2))
        self.x[:, :, 0], self.v[:, :, 0] = r0, v0
        self.b, self.g = np.zeros((7, 3 * n, 2)), np.zeros((7, 3 * n, 2))
        self.br, self.d = np.zeros((7, 3 * n)), np.zeros((7, 3 * n))
        self.gm = np.array(gm, dtype=np.float64)
        self.dt, self.h_last, self.t, self.steps = dt, 0.0, t0, 0
        self.max_steps = max_steps
        self.cut: tuple[float, int] | None = None

    def _steps(self, h: float, k: int, t_out: np.ndarray, i: int) -> None:
        """``k`` steps of ``h`` (the kernel), a collision named (its double-double
        arithmetic raises ZeroDivisionError where two bodies meet)."""
        from hamilton_orbits._kernels import radau15_dd

        try:
            radau15_dd.advance(self.x, self.v, self.gm, h, k, self.b, self.g, self.br,
                               self.d, h / self.h_last if self.h_last else 0.0)
        except ZeroDivisionError:
            raise ConvergenceError(
                f"radau15 in double-double stopped before t_out[{i}] = {float(t_out[i])!r}: "
                "two bodies met (a division by zero in the acceleration: a collision?)"
            ) from None

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current state rounded to doubles (copies)."""
        return (self.x[:, :, 0] + self.x[:, :, 1], self.v[:, :, 0] + self.v[:, :, 1],
                self.gm.copy())

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Any, stop: Any) -> None:
        """Rows 1... of ``r_out``, ``v_out`` at ``t_out[1:]`` (``t_out[0]`` the current
        time), in slices of ``SLICE // 100`` steps (Ctrl-C is seen between them); more
        than ``max_steps`` steps are refused before the first."""
        dt_f, first = self.dt, self.steps
        _setup.check_step_count(float(t_out[-1] - t_out[0]), dt_f, self.max_steps,
                                "radau15 in double-double")
        for i in range(1, len(t_out)):
            origin, done = _setup.interval_origin(self.cut, i, t_out, dt_f)
            self.cut = None
            n_steps, last = _setup.fixed_steps(float(t_out[i]) - origin, dt_f)
            while done < n_steps:
                k = min(n_steps - 1 - done, SLICE // 100) if done < n_steps - 1 else 1
                h = dt_f if done < n_steps - 1 else last
                with HELD:  # (the state's time and steps those of its arrays, a Ctrl-C
                    self._steps(h, k, t_out, i)  # in the call raised after them)
                    self.h_last = h
                    done += k
                    self.steps += k
                    self.t = origin + done * dt_f if done < n_steps else float(t_out[i])
                    self.cut = (origin, done) if done < n_steps else None
            r_out[i] = self.x[:, :, 0] + self.x[:, :, 1]
            v_out[i] = self.v[:, :, 0] + self.v[:, :, 1]
            if on_output is not None:
                on_output(i, self.steps - first)


class _Run:
    """The integrator's state between compiled calls (see :func:`run`).

    ``pause``, when set (an archive's step schedule), is called between two steps
    once ``steps`` reaches ``pause.at``: the compiled call's budget ends there, so
    the steps are the same as without it.  ``pause(again)``: ``again`` True when
    only the compiled steps ran since the last pause of the same call (no output,
    no event: the state's arrays changed in place, its numbers changed, nothing was
    put in another place; ``stop`` is a question and changes nothing).

    ``landings``, when set (an archive's simulation-time schedule, whose snapshot
    times are output rows no caller sees): the kernel lands on a run of such rows
    and writes their snapshots itself where ``landings`` gives it a plan
    (:meth:`~hamilton_orbits.engine._Landings.compiled`); those rows are then not
    reported to ``on_output``."""

    #: not state: the hook a run sets and clears (:meth:`Propagation.advance`), the
    #: caller's ``stop`` of the call (set by each call: a snapshot's layout, and so
    #: the archive segment it goes in, is the same with it or without), a step's own
    #: ``b`` and ``g`` (written at each step's start from ``br`` and ``d``,
    #: :func:`~hamilton_orbits._kernels.radau15._begin`, before they are read: a
    #: snapshot of 10 bodies is 37% smaller without them) and the kernel's arguments
    #: that hold them (made again by :meth:`restarted`)
    RESTART_SCRATCH = ("pause", "landings", "stop", "scratch", "after_t", "plan")

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 dt: float, tol: float, prs23: bool, log: EventLog, max_steps: int) -> None:
        m = 3 * r0.shape[0]
        self.rhs, self.gm, self.log, self.max_steps = rhs, gm, log, max_steps
        self.accel = _setup.force_arg(rhs, gm, log.watch)
        #: the last step's ``br`` and ``d``, its ``b`` and that less its prediction:
        #: the next step's predictor
        self.work = [np.zeros((7, m)) for _ in range(2)]
        #: a step's ``b`` and ``g``, working space
        self.scratch = (np.zeros((7, m)), np.zeros((7, m)))
        self.csx = np.zeros(m)
        self.csv = np.zeros(m)
        self.st = np.zeros(_k.NSTATE)
        self.st[[_k.ST_T, _k.ST_DT, _k.ST_EPSILON, _k.ST_PRS23]] = t0, dt, tol, float(prs23)
        self.x = np.ascontiguousarray(r0.copy())
        self.w = np.ascontiguousarray(v0.copy())
        self.steps = 0
        self.stop: Callable[[], bool] | None = None
        self.pause: Any = None
        self.landings: Any = None
        #: the kernel's plan of an archive's snapshots while it writes them (and what
        #: the plan's addresses are of, kept: :meth:`_compiled`); else one of none
        self.plan: tuple[np.ndarray, tuple[Any, ...]] = _NO_PLAN
        # the kernel's arguments that stay the same objects between calls (a short
        # call's cost is mostly its arguments; see docs/design.md, "One front door")
        self.before_t = (self.accel, run_parameters(rhs), self.x, self.w, gm)  # (p: the
        # kernels write its clock)
        self.after_t = self._after_t()

    def _after_t(self) -> tuple[Any, ...]:
        """The kernel's arguments after ``t_end``: ``st``, ``b, br, d, g``, ``csx``,
        ``csv`` and whether the forces depend on the velocities."""
        (b, g), (br, d) = self.scratch, self.work
        return (self.st, b, br, d, g, self.csx, self.csv, bool(self.rhs.velocity_dependent))

    def restarted(self) -> None:
        """After :func:`~hamilton_orbits.restart.restore` put a saved state in: the
        kernel's arguments made of the restored arrays.  A state saved before ``b``
        and ``g`` were working space (``work`` of four arrays, ``b, br, d, g``)
        keeps its ``br`` and ``d``: the same steps follow."""
        if len(self.work) == 4:
            self.work = self.work[1:3]
        self.after_t = self._after_t()

    @property
    def t(self) -> float:
        """The time of the state."""
        return float(self.st[_k.ST_T])

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current positions, velocities and ``G m`` (copies)."""
        return self.x.copy(), self.w.copy(), self.gm.copy()

    def state_into(self, r: np.ndarray, v: np.ndarray) -> None:
        """The current positions and velocities copied into ``r`` and ``v`` (a pause's
        own arrays, refilled at each pause)."""
        np.copyto(r, self.x)
        np.copyto(v, self.w)

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Any, stop: Any) -> None:
        """Rows 1... of ``r_out``, ``v_out`` at ``t_out[1:]`` (``t_out[0]`` the current
        time); an event that stops the run raises
        :class:`~hamilton_orbits.events.StopAtEvent` with its row."""
        log, first = self.log, self.steps
        self.stop = stop
        i = 1
        while i < t_out.shape[0]:
            j = self._landing_plan(t_out, i)  # (rows i ... j - 1 landed on by the kernel)
            plan = self.plan[0]
            land = int(plan[_rec.P_LAND])
            stopped = self.advance_to(t_out, j, first)
            if j > i:  # (it stands at row k: j, or the row whose write failed in the
                k = i + int(plan[_rec.P_LAND]) - land  # kernel, which Python then writes)
                r_out[i:k] = self.x  # (the rows the kernel wrote, which no caller sees:
                v_out[i:k] = self.w  # the state, finite as theirs were)
                i = k
            r_out[i] = self.x
            v_out[i] = self.w
            if log.gone:  # (bodies taken out of the run: NaN in the outputs)
                log.mask(r_out[i], v_out[i])
            if stopped:
                raise StopAtEvent(i, self.t, self.steps - first)
            if on_output is not None:
                on_output(i, self.steps - first)
            i += 1

    def _landing_plan(self, t_out: np.ndarray, i: int) -> int:
        """The row to step to next from row ``i - 1``: ``i``, or the row after a
        run of snapshot rows from ``i`` on, whose snapshots the kernel writes, landing
        on their times (the plan set, with their times, where :attr:`landings`
        gives one: after a snapshot written by Python at the row before, no caller's
        ``stop``)."""
        landings = self.landings
        if (landings is None or self.stop is not None or not landings.only[i]
                or not landings.only[i - 1]):
            return i
        j = landings.through(i)
        if j == i:
            return i
        made = landings.compiled(self._arrays(), ("st", _k.ST_T), self.steps, t_out[i:j])
        if made is None:
            return i
        self.plan = _writing(made)
        return j

    def _slice(self, t_end: Any, budget: int) -> tuple[int, int, bool]:
        """One compiled call of at most ``budget`` steps towards ``t_end``: its steps
        counted, the events' log drained where full, and the event it stopped at
        acted on, a Ctrl-C in the call held until all three are done (the state's
        arrays, its counts and the event's action then agree): ``(steps, status,
        whether the event stopped the run)``."""
        log, plan = self.log, self.plan[0]
        if plan[_rec.P_LAND_END]:  # (landing on snapshot times: the record's step
            plan[_rec.P_BASE] = self.steps  # counts are this plus the call's steps)
        with HELD:
            if log.watch.shape[0]:  # the kernel with the events' code, compiled apart
                steps, status = _k.advance_watched(
                    *self.before_t, t_end, *self.after_t, budget, log.watch, log.buffer,
                    log.count, None)
            else:
                steps, status = _k.advance(*self.before_t, t_end, *self.after_t, budget, None,
                                            None, None, plan)
            self.steps += steps
            if plan[_rec.P_WRITTEN]:
                (self.pause or self.landings).wrote(plan, int(plan[_rec.P_LAST]
                                                              + plan[_rec.P_BASE]))
                plan[_rec.P_WRITTEN] = 0
            if status == _k.STATUS_DRAIN:
                log.drain()
            stopped = status == _k.STATUS_EVENT and log.act(
                int(self.st[_k.ST_EVENT_ROW]), self.t, self.x, self.w, self.gm)
        return steps, status, stopped

    def advance_to(self, t_out: np.ndarray, i: int, first: int) -> bool:
        """Step to ``t_out[i]`` in slices; True if an event stopped the run (``first``:
        the steps before this call, for its budget of ``max_steps``)."""
        max_steps, pause = self.max_steps, self.pause
        again = False  # (a pause since which only the kernel ran: see pause's notes)
        left = SLICE  # (of this slice: the pace is judged at its end, pauses or not)
        try:
            while True:  # slices of SLICE steps: Ctrl-C is seen between them
                budget = min(left, max_steps - (self.steps - first))
                cut = False  # (the budget cut short by a pause)
                if pause is not None and not self._compiled(pause):
                    paused = self.steps >= pause.at
                    if paused:
                        pause(again)
                        again = True
                    # (a plan only right after a pause: it wrote what the kernel cannot,
                    # as the rows of the outputs since the snapshot before)
                    if not (paused and self._compiled(pause, ask=self._reaches(pause,
                                                                               t_out[i]))):
                        cut = pause.at - self.steps < budget
                        budget = min(budget, max(pause.at - self.steps, 1))
                steps, status, stopped = self._slice(t_out[i], budget)
                left -= steps
                if status == _k.STATUS_MAXSTEPS:
                    if self.plan[0][_rec.P_FAILED] and self.plan[0][_rec.P_LAND_END]:
                        return False  # (at the snapshot time whose write failed)
                    if not cut:  # (a slice's end or max_steps, where a run without pauses is)
                        _setup.check_pace(self.steps - first, max_steps, self.t, t_out, NAME)
                        left = SLICE
                    if self.stop is not None and self.stop():
                        raise StopIntegration
                elif status == _k.STATUS_DRAIN:
                    again, left = False, SLICE
                elif status == _k.STATUS_EVENT:
                    again, left = False, SLICE
                    if stopped:
                        return True
                elif status == _k.STATUS_OK:
                    return False
                else:
                    raise ConvergenceError(
                        f"radau15 stopped at t = {self.t!r} before t_out[{i}] = "
                        f"{float(t_out[i])!r}: "
                        f"{_tangent.radau15_why(status, self.st, max_steps)}")
        finally:  # (the kernel writes snapshots within one call only)
            if self.plan is not _NO_PLAN:
                self.plan = _NO_PLAN

    def _reaches(self, pause: Any, t_end: float) -> bool:
        """Whether the steps to ``t_end`` may reach the pause's next snapshot, at the
        step size now with half as many again: a plan for the kernel to write it
        (:meth:`_compiled`, about 0.3 ms) is not made for a call that ends before it
        (a short run's last snapshots); if the call reaches it after all, the pause
        writes it, as where no plan could be made, and asks again."""
        step = abs(float(self.st[_k.ST_DT]))
        return not step > 0.0 or (pause.at - self.steps) * step <= 1.5 * abs(t_end - self.t)

    def _compiled(self, pause: Any, ask: bool = False) -> bool:
        """Whether the kernel writes the archive's next snapshots itself (its plan set
        for the next call: where the next is due, the steps so far); ``ask``: a plan
        asked for first, after a pause (:meth:`~hamilton_orbits.engine._Pause.
        compiled`); none while a caller's ``stop`` is asked (it is asked at each
        snapshot, where the call returns).  A plan whose write failed is dropped:
        the pause then writes that snapshot, and says why it cannot."""
        plan = self.plan[0]
        if ask and self.stop is None:
            made = pause.compiled(self._arrays(), ("st", _k.ST_T), self.steps)
            self.plan = _NO_PLAN if made is None else _writing(made)
            plan = self.plan[0]
        if not plan[_rec.P_EVERY]:
            return False
        if plan[_rec.P_FAILED] or pause.at <= self.steps:  # (or one due where the last
            self.plan = _NO_PLAN  # call ended, at its t_end, which the kernel leaves to
            return False  # the pause)
        plan[_rec.P_NEXT], plan[_rec.P_BASE] = pause.at - self.steps, self.steps
        plan[_rec.P_WRITTEN] = 0
        return True

    def _arrays(self) -> dict[str, np.ndarray]:
        """The kernel's arrays that a record's values are read from (by their names in
        :data:`~hamilton_orbits._kernels.records.SOURCES`)."""
        return {"r": self.x, "v": self.w, "gm": self.gm, "p": self.before_t[1], "st": self.st,
                "br": self.work[0], "d": self.work[1], "csx": self.csx, "csv": self.csv}


def _writing(made: tuple[np.ndarray, tuple[Any, ...]]) -> tuple[np.ndarray, tuple[Any, ...]]:
    """An archive's plan ``made`` with the addresses of the function that writes its
    records (:func:`~hamilton_orbits._kernels.records.write_record`: compiled at
    the first plan, not into the kernel)."""
    made[0][_rec.P_WRITER:_rec.P_WRITER + 2] = _setup.addresses(_rec.write_record,
                                                                _rec.RECORD_SIGNATURE)
    return made


#: below this ``tol`` (float64's rounding) a tolerance buys no accuracy, only
#: shorter steps: refused (:data:`~hamilton_orbits.integrators.methods.RADAU15_TOL_FLOOR`)
TOL_FLOOR = RADAU15_TOL_FLOOR

