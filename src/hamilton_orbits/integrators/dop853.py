"""DOP853 (Dormand-Prince 8(5,3)) through :func:`scipy.integrate.solve_ivp`.

For anything generic: it accepts every effect, velocity-dependent ones included,
and controls its local error with ``rtol = tol`` and a per-body absolute
tolerance ``atol = tol * |r_i|`` on the three position components of body ``i``
and ``tol * |v_i|`` on its velocity components (initial state; bodies at rest
at the origin take the largest of the others).  One absolute tolerance for all
components would let an inner planet's velocity go with an error set by the
outer planets' distances; a pure relative tolerance would stall where one
component crosses zero.  ``tol`` is raised to scipy's floor of 100 eps.  ``dt``, if
given, caps the step (``max_step``).  Not symplectic: its energy error drifts
linearly with time.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import events as _ev
from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import _setup, _tangent
from hamilton_orbits.integrators._held import HELD
from hamilton_orbits.integrators.methods import DOP853
from hamilton_orbits.rhs import run_parameters

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "DEFAULT_TOL", "NAME", "RTOL_FLOOR", "run", "solve",
           "start"]

NAME = "dop853"
ACCEPTS_VELOCITY_DEPENDENT = True
DEFAULT_TOL = 1e-12


def run(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_out: np.ndarray,
        **options: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """Integrate with scipy's DOP853; see :mod:`hamilton_orbits.integrators`.

    ``variational`` (a :class:`hamilton_orbits.integrators._tangent.Tangent`, ``rhs``
    compiled with ``variational=True``) integrates the augmented system (the
    bodies, the tangent vectors and MEGNO's integral); the tangent vectors take
    part in the error control only with ``tangent_control=True``.  Not with
    ``events``.

    ``events`` (:mod:`hamilton_orbits.events`) are looked for in every step on the
    cubic Hermite interpolant of the step's ends; actions take effect at the
    event's time (the integration restarts there).  ``stop`` is not asked inside
    an output interval (scipy's solver runs it through): the run ends at the
    next output.

    Examples
    --------
    >>> import numpy as np
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]]); v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    >>> r, v, steps = run(newtonian_rhs(), r0, v0, np.array([1.0, 0.0]),
    ...                   np.array([0.0, 2 * np.pi]), tol=1e-12)
    >>> bool(np.allclose(r[-1, 1], [1, 0, 0], atol=1e-9))
    True
    """
    return _setup.run_once(start, DOP853, rhs, r0, v0, gm, t_out, **options)


def start(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
          method: DOP853, *, dt: float | None, tol: float | None,
          events: EventLog | None = None, variational: Any = None) -> Any:
    """The integrator's state at ``t0`` (a :class:`~hamilton_orbits.integrators.
    DriverState`); the absolute tolerances come from this first state and are kept
    for the whole run, so that a run continued in legs takes the steps of one run."""
    # scipy refuses rtol below 100 eps (with a warning); that is DOP853's floor here
    tol = max(DEFAULT_TOL if tol is None else float(tol), RTOL_FLOOR)
    atol = tol * np.concatenate((_body_scale(r0), _body_scale(v0)))
    max_step = np.inf if dt is None else float(dt)
    if variational is not None:
        return _tangent.DOP853Tangent(rhs, r0, v0, gm, t0, variational, tol=tol, atol=atol,
                                      max_step=max_step, control=method.tangent_control,
                                      max_steps=method.max_steps)
    return _State(rhs, r0, v0, gm, t0, tol, atol, max_step, events, method.max_steps)


class _State:
    """The state between calls: ``y = (r, v)`` flattened, the masses (merges change
    them), the tolerances, the events log."""

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 tol: float, atol: np.ndarray, max_step: float, events: EventLog | None,
                 max_steps: int = DOP853.max_steps) -> None:
        self.n = n = r0.shape[0]
        self.gm = np.array(gm, dtype=np.float64)  # merges change it
        self.rhs, self.acc = rhs, np.empty((n, 3))
        self.p = run_parameters(rhs)  # (its clock set at each evaluation)
        self.y = np.concatenate((np.ravel(r0), np.ravel(v0))).astype(np.float64)
        self.tol, self.atol, self.max_step, self.log = tol, atol, max_step, events
        self.t, self.steps, self.max_steps = t0, 0, max_steps

    def f(self, t: float, y: np.ndarray) -> np.ndarray:
        """``dy/dt`` of the bodies (positions, then velocities, flattened), with the
        masses of now (a method, not a closure: a copy of the state computes with its
        own masses); a non-finite acceleration raises
        (:func:`~hamilton_orbits.integrators._setup.check_finite`)."""
        n = self.n
        r = y[: 3 * n].reshape(n, 3)
        v = y[3 * n :].reshape(n, 3)
        p = self.p
        p[-1] = t  # (the clock)
        self.rhs.accel(r, v, self.gm, self.acc, p)
        _setup.check_finite(self.acc, t, NAME)
        return np.concatenate((y[3 * n :], self.acc.ravel()))

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current positions, velocities and ``G m`` (copies)."""
        n = self.n
        return (self.y[: 3 * n].reshape(n, 3).copy(), self.y[3 * n:].reshape(n, 3).copy(),
                self.gm.copy())

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` at ``t_out[1:]`` (``t_out[0]`` the current
        time); ``stop`` is asked at the outputs only (by the engine)."""
        n, first = self.n, self.steps

        def store(i: int, steps: int, y: np.ndarray, reached: bool = True) -> None:
            r_out[i] = y[: 3 * n].reshape(n, 3)
            v_out[i] = y[3 * n :].reshape(n, 3)
            if self.log is not None:
                self.log.mask(r_out[i], v_out[i])
            if on_output is not None and reached:  # (not a row of an event that stopped
                on_output(i, steps - first)  # the run before ``t_out[i]``: as radau15's)

        watched = self.log is not None and len(self.log.watch) > 0
        for i in range(1, len(t_out)):
            solver = self._stepper(t_out[i])
            while solver.status == "running":
                scanned = None
                if watched:  # (each step scanned for events before the next is taken)
                    scanned = functools.partial(self._scanned, solver, solver.t,
                                                solver.y.copy(), i, store, first)
                acted = self._step(solver, t_out, first, scanned)
                if isinstance(acted, StopAtEvent):  # (raised out of HELD: a Ctrl-C held
                    raise acted  # is raised first)
                if acted:  # (an event's action: the integration restarted at its time)
                    solver = self._stepper(t_out[i])
            self.t, self.y = float(t_out[i]), solver.y.copy()
            store(i, self.steps, self.y)

    def _stepper(self, t_end: Any) -> Any:
        """scipy's DOP853 stepper from the state towards ``t_end`` (stepped as
        ``solve_ivp`` steps it: the same bits)."""
        from scipy.integrate import DOP853 as Stepper

        return Stepper(self.f, self.t, self.y, float(t_end), rtol=self.tol, atol=self.atol,
                       max_step=self.max_step)

    def _step(self, solver: Any, t_out: np.ndarray, first: int,
              scanned: Callable[[], Any] | None = None) -> Any:
        """One step of scipy's stepper ``solver``, its state kept as the run's, and
        ``scanned()`` (the step's events acted on: True where one did, the state then
        its, or the :class:`StopAtEvent` of a stop), a Ctrl-C in them held until they
        are done; a step beyond ``max_steps`` in this call refused before it is taken
        (the limit exact, as radau15's), the pace judged every 100 steps.  Returns
        what ``scanned`` does (False without it)."""
        if self.steps - first >= self.max_steps:  # (one integer compare a step)
            _setup.check_pace(self.steps - first, self.max_steps, solver.t, t_out, NAME)
        t_prev = solver.t
        with HELD:
            if solver.step() is not None:
                raise ValueError(f"dop853 failed at t = {t_prev}: the step underflowed")
            self.steps += 1
            self.t, self.y = float(solver.t), solver.y  # (scipy makes a new y a step)
            acted = scanned is not None and scanned()
        if (self.steps - first) % 100 == 0:
            _setup.check_pace(self.steps - first, self.max_steps, solver.t, t_out, NAME)
        return acted

    def _scanned(self, solver: Any, t_prev: float, y_prev: np.ndarray, i: int,
                 store: Callable[..., None], first: int) -> bool | StopAtEvent:
        """The step of ``solver`` from ``t_prev`` (state ``y_prev``) scanned for events
        on the cubic Hermite interpolant of its ends: True where one acted (the state
        then the event's, at its time: the caller restarts the stepper there); a stop
        leaves its state in output ``i`` and returns the :class:`StopAtEvent` to
        raise."""
        log, n = self.log, self.n
        if log.count[0] + len(log.watch) > log.buffer.shape[0]:
            log.drain()
        xs = np.ascontiguousarray(np.stack([y_prev, solver.y])[:, : 3 * n].reshape(2, n, 3))
        vs = np.ascontiguousarray(np.stack([y_prev, solver.y])[:, 3 * n :].reshape(2, n, 3))
        k, h, row = _ev.scan_steps(log.watch, np.array([t_prev, solver.t]), xs, vs, self.gm,
                                   log.buffer, log.count)
        if k < 0:
            return False
        r, v = np.empty((n, 3)), np.empty((n, 3))
        _ev.state_at_hermite(_ev.HERMITE, h, solver.t - t_prev, xs[0], vs[0], xs[1], vs[1],
                             np.zeros(1), np.zeros((7, 1)), self.gm, r, v)
        self.t = float(t_prev + h * (solver.t - t_prev))
        stop = log.act(int(row), self.t, r, v, self.gm)
        self.y = np.concatenate((r.ravel(), v.ravel()))
        if stop:
            store(i, self.steps, self.y, reached=False)
            return StopAtEvent(i, self.t, self.steps - first)
        return True


#: scipy's smallest accepted relative tolerance (100 eps); below it scipy warns.
RTOL_FLOOR = 100 * np.finfo(float).eps


def solve(
    f: Callable[[float, np.ndarray], np.ndarray],
    y0: np.ndarray,
    t_out: np.ndarray,
    *,
    rtol: float,
    atol: Any,
    max_step: float = np.inf,
    on_output: Callable[[int, int], None] | None = None,
    restart: bool = True,
    max_steps: int = DOP853.max_steps,
    hint: str | None = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[np.ndarray, int, int]:
    """The DOP853 driver of a whole run (rigid's): ``y' = f(t, y)`` from ``y0`` at
    ``t_out[0]``, restarted at each output time (so that an output is a step end,
    not an interpolation).  A ``Simulation``'s dop853 takes the same steps, stepping
    scipy's stepper itself to keep each step's state (Ctrl-C).

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` on float64 arrays of shape (m,).
    y0 : ndarray, shape (m,)
    t_out : ndarray, shape (n_t,)
        Output times, monotonic; ``t_out[0]`` is the start.
    rtol, atol : float or ndarray
        scipy's tolerances (``rtol`` at least :data:`RTOL_FLOOR`).
    max_step : float
        A cap on the step.
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i``.
    restart : bool, optional
        True (default): a new integration from each output time, so that every
        output is a step end.  False: one integration, the outputs read from
        DOP853's 7th-order dense output (many closely spaced outputs then do not
        cap the step), each as its step is taken (``on_output`` then called).
    max_steps : int, optional
        Give up after about this many steps, or as soon as the pace projects more
        than 100 times as many (:class:`~hamilton_orbits.integrators._setup.
        StepBudget`); ``hint``: what the error then advises.
    stop : callable, optional
        With ``restart=False``: ``stop()`` asked every :data:`STOP_EVERY` steps;
        True ends the run there, ``y`` then holding the outputs reached (the
        steps before it unchanged).

    Returns
    -------
    y : ndarray, shape (n_t, m)
        The state at each output time (row 0 is ``y0``; the rows reached, when
        ``stop()`` ended the run).
    steps, nfev : int
        Accepted steps and right-hand-side evaluations.

    Raises
    ------
    ValueError
        If scipy reports a failure, naming the interval.
    ConvergenceError
        When the run needs more than ``max_steps`` steps (a ValueError).

    Examples
    --------
    >>> y, steps, nfev = solve(lambda t, y: -y, np.array([1.0]), np.array([0.0, 1.0]),
    ...                        rtol=1e-12, atol=1e-14)
    >>> bool(abs(y[-1, 0] - np.exp(-1.0)) < 1e-12)
    True
    """
    from scipy.integrate import solve_ivp

    f = _setup.StepBudget(f, t_out, max_steps, NAME, hint)
    y_out = np.empty((len(t_out), len(y0)))
    y_out[0] = y0
    y = np.asarray(y0, dtype=np.float64)
    steps = nfev = 0
    if not restart and len(t_out) > 1:
        return _dense_run(f, y_out, t_out, max(float(rtol), RTOL_FLOOR), atol, max_step,
                          on_output, stop)
    for i in range(1, len(t_out)):
        sol = solve_ivp(f, (float(t_out[i - 1]), float(t_out[i])), y, method="DOP853",
                        rtol=max(float(rtol), RTOL_FLOOR), atol=atol, max_step=max_step)
        if not sol.success:
            raise ValueError(f"dop853 failed between t = {t_out[i - 1]} and {t_out[i]}: "
                             f"{sol.message}")
        y = sol.y[:, -1]
        steps += max(len(sol.t) - 1, 0)
        nfev += int(sol.nfev)
        y_out[i] = y
        if on_output is not None:
            on_output(i, steps)
    return y_out, steps, nfev


#: steps between two questions to ``stop()`` in :func:`solve` (``restart=False``)
STOP_EVERY = 64


def _dense_run(f: Callable[[float, np.ndarray], np.ndarray], y_out: np.ndarray,
               t_out: np.ndarray, rtol: float, atol: Any, max_step: float,
               on_output: Callable[[int, int], None] | None,
               stop: Callable[[], bool] | None) -> tuple[np.ndarray, int, int]:
    """:func:`solve` with ``restart=False``: scipy's DOP853 stepped from ``y_out[0]``
    at ``t_out[0]`` to ``t_out[-1]``, each output read from the dense output of the
    step that reaches it (a step ending on it: that step's), as it is passed (the
    values ``solve_ivp(..., dense_output=True)`` gives, whose interpolants are the
    same steps'); ``stop()`` asked every :data:`STOP_EVERY` steps."""
    from scipy.integrate import DOP853 as Stepper

    t0, t1 = float(t_out[0]), float(t_out[-1])
    solver = Stepper(f, t0, y_out[0], t1, rtol=rtol, atol=atol, max_step=max_step)
    ahead = 1.0 if t1 >= t0 else -1.0
    steps, i, n = 0, 1, len(t_out)
    while i < n:
        message = solver.step()
        if solver.status == "failed":
            raise ValueError(f"dop853 failed between t = {t0} and {t1}: at t = "
                             f"{solver.t}, {message}")
        steps += 1
        dense = None
        while i < n and ahead * (float(t_out[i]) - solver.t) <= 0.0:
            dense = solver.dense_output() if dense is None else dense
            y_out[i] = dense(float(t_out[i]))
            if on_output is not None:
                on_output(i, steps)
            i += 1
        if i < n and stop is not None and steps % STOP_EVERY == 0 and stop():
            return y_out[:i], steps, int(solver.nfev)
    return y_out, steps, int(solver.nfev)


def _body_scale(x: np.ndarray) -> np.ndarray:
    """|x_i| for each body, repeated over its three components (a zero row takes the
    largest, so that a body at rest at the origin does not demand zero error); by
    ``hypot``, whose squares do not overflow (a body at 1e300: ``norm`` gave inf and
    numpy's overflow warning)."""
    norm = np.hypot(np.hypot(x[:, 0], x[:, 1]), x[:, 2])
    top = float(np.max(norm)) if norm.size else 0.0
    norm = np.where(norm > 0, norm, top if top > 0 else 1.0)
    return np.repeat(norm, 3)
