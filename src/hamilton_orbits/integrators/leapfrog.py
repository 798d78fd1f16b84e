"""Leapfrog: drift-kick-drift, second order, symplectic, time-reversible.

One step of length ``h``: ``r += h/2 v``; ``v += h a(r)``; ``r += h/2 v``.  The
map is symplectic for forces that derive from a potential, so velocity-dependent
effects are refused.  With ``tol`` and no ``dt``, the step is chosen from the
shortest dynamical time of the initial state (see ``choose_dt``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import leapfrog as _k
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import StopIntegration, _setup, _tangent
from hamilton_orbits.integrators._held import HELD
from hamilton_orbits.integrators._setup import check_step_count, force_arg
from hamilton_orbits.integrators.methods import Leapfrog, check_run
from hamilton_orbits.rhs import run_parameters

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "NAME", "SLICE", "choose_dt", "run", "start"]

NAME = "leapfrog"
#: Steps per compiled call: the driver returns to Python this often (Ctrl-C).
SLICE = 100_000
ACCEPTS_VELOCITY_DEPENDENT = False


def choose_dt(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, tol: float) -> float:
    """A step for a second-order method from the tightest pair's dynamical time.

    ``dt = sqrt(tol) * min_{pairs} sqrt(d^3 / (gm_i + gm_j))``: the local error of a
    second-order method over one dynamical time scales like ``(dt / T)^2``.
    """
    best = _nbody.min_pair_time(np.ascontiguousarray(r0, dtype=np.float64),
                                np.ascontiguousarray(gm, dtype=np.float64))
    return float(np.sqrt(tol) * best)


def run(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_out: np.ndarray,
        **options: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """Integrate with drift-kick-drift leapfrog; see :mod:`hamilton_orbits.integrators`.

    ``max_steps`` bounds the steps of the whole run; more are refused before the
    run starts (``ValueError``).  ``events`` (:mod:`hamilton_orbits.events`) are
    looked for on both straight drifts of every step, exactly for the map's own
    motion; actions take effect at the end of the step.  ``variational`` (a
    :class:`hamilton_orbits.integrators._tangent.Tangent`, ``rhs`` compiled with
    ``variational=True``) carries tangent vectors through the exact tangent map of
    every step (symplectic, as the map); not with ``events``.

    Examples
    --------
    >>> import numpy as np
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]]); v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    >>> r, v, steps = run(newtonian_rhs(), r0, v0, np.array([1.0, 0.0]),
    ...                   np.array([0.0, 2 * np.pi]), dt=2 * np.pi / 1000)
    >>> steps, bool(np.allclose(r[-1, 1], [1, 0, 0], atol=1e-4))
    (1000, True)
    """
    return _setup.run_once(start, Leapfrog, rhs, r0, v0, gm, t_out, **options)


def chosen_step(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, tol: float | None) -> float:
    """The step :func:`start` takes from ``r0``, ``gm`` without ``dt`` (from ``tol``,
    :func:`choose_dt`): a fixed step chosen once, at the start."""
    if tol is None:
        raise ValueError("leapfrog needs a step `dt` or a tolerance `tol`, got neither")
    return choose_dt(r0, v0, gm, tol)


def start(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
          method: Leapfrog, *, dt: float | None, tol: float | None,
          events: EventLog | None = None, variational: Any = None) -> Any:
    """The map's state at ``t0`` (a :class:`~hamilton_orbits.integrators.DriverState`),
    for arguments already checked (``method`` a :class:`Leapfrog`)."""
    check_run(method, dt, tol, variational is not None)
    if dt is None:
        dt = chosen_step(r0, v0, gm, tol)
    if variational is not None:
        return _tangent.LeapfrogTangent(rhs, r0, v0, gm, t0, variational, dt=float(dt),
                                        max_steps=method.max_steps, slice_steps=SLICE)
    return _State(rhs, r0, v0, gm, t0, float(dt), method.max_steps, events)


class _State:
    """The map's state between calls: positions, velocities, masses (merges change
    them), the events log."""

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 dt: float, max_steps: int, events: EventLog | None) -> None:
        self.r = np.ascontiguousarray(r0, dtype=np.float64).copy()
        self.v = np.ascontiguousarray(v0, dtype=np.float64).copy()
        self.gm = np.ascontiguousarray(gm, dtype=np.float64).copy()
        self.log = events if events is not None else EventLog.none(self.r.shape[0])
        self.log.same_approach = float(dt)  # (one approach seen on both sides of a kick)
        self.accel = force_arg(rhs, self.gm, self.log.watch)
        self.p = run_parameters(rhs)  # (the kernels write its clock)
        self.dt, self.max_steps, self.t, self.steps = dt, max_steps, t0, 0

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current positions, velocities and ``G m`` (copies)."""
        return self.r.copy(), self.v.copy(), self.gm.copy()

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` at ``t_out[1:]`` (``t_out[0]`` the current
        time); an event that stops the run raises
        :class:`~hamilton_orbits.events.StopAtEvent` with its row."""
        check_step_count(float(t_out[-1] - t_out[0]), self.dt, self.max_steps, NAME)
        r, v, log, first = self.r, self.v, self.log, self.steps
        for i in range(1, len(t_out)):
            self._interval(t_out, i, stop, first, (r_out[i], v_out[i]))
            r_out[i] = r
            v_out[i] = v
            log.mask(r_out[i], v_out[i])
            if on_output is not None:
                on_output(i, self.steps - first)

    def _act(self, status: int, ws: np.ndarray, row: tuple[np.ndarray, np.ndarray]) -> bool:
        """The events' log drained, and the action of the event the kernel stopped at
        (``status``, ``ws``) taken: True for a stop (its state then in ``row``)."""
        log, r, v = self.log, self.r, self.v
        if status != _k.STATUS_EVENT:
            log.drain()
            return False
        # (act drains the buffer itself: the rows it drains are the step's, each of
        # whose actions it carries out)
        if log.act(int(ws[3]), float(ws[0]), r, v, self.gm, at=float(ws[1])):
            row[0][:], row[1][:] = r, v
            log.mask(row[0], row[1])
            return True
        return False

    def _interval(self, t_out: np.ndarray, i: int, stop: Callable[[], bool] | None, first: int,
                  row: tuple[np.ndarray, np.ndarray]) -> None:
        """The steps from ``t_out[i - 1]`` to ``t_out[i]``, in slices (Ctrl-C and
        ``stop()`` are seen between them); an event that stops the run leaves its
        state in ``row``."""
        r, v, log = self.r, self.v, self.log
        t = float(t_out[i - 1])
        while t < t_out[i]:
            ws = np.array([t, np.inf, 0.0, -1.0])
            args = (self.accel, self.p, r, v, self.gm, t, float(t_out[i]), self.dt)
            with HELD:  # (a Ctrl-C in the call: raised once its steps are counted and its
                if log.watch.shape[0]:  # event acted on; the kernel with the events' code,
                    done, status = _k.advance_watched(  # compiled apart)
                        *args, log.watch, log.buffer, log.count, ws, SLICE)
                else:
                    done, status = _k.advance(*args, None, None, None, ws, SLICE)
                self.steps += int(done)
                t = self.t = float(ws[0])
                stopped = status not in (_k.STATUS_OK, _k.STATUS_SLICE) and self._act(
                    status, ws, row)
            if stopped:  # (raised out of HELD: a Ctrl-C held is raised first)
                raise StopAtEvent(i, t, self.steps - first)
            if status == _k.STATUS_OK:
                break  # t is t_out[i], exactly
            if status == _k.STATUS_SLICE and stop is not None and stop():
                raise StopIntegration  # (Ctrl-C and stop() are seen between slices)
