"""The float-level engine under every public entry point.

:func:`run` takes plain arrays (positions, velocities, GMs in one consistent unit
system), a compiled right-hand side (:class:`hamilton_orbits.rhs.RHS`), the method
and its options, the output times, an output callback and a stop callback, and
returns plain arrays and step counts (:class:`EngineRun`).  It validates nothing
the public layer has validated already and converts no units.

``integrate`` (:mod:`hamilton_orbits.simulation`), the scenes, the ensembles,
``crosscheck`` and the report all call it; none of them calls another public
entry point in a loop.

Stopping early
--------------
``stop()`` is asked after every output; when it returns True, or when the user
presses Ctrl-C (``KeyboardInterrupt``) during the run, the engine returns what
was reached (``complete=False``) instead of losing it.  The integrators return
to Python at least every few thousand steps (radau15) or every output (the
fixed-step maps), so an interrupt is seen promptly.

Backward integration
--------------------
Output times that decrease are integrated as forward times with the velocities
reversed, which is exact for forces that do not depend on velocities; a
velocity-dependent right-hand side is refused there.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import INTEGRATORS, Integrator, StopIntegration

__all__ = ["EngineRun", "StopIntegration", "integrator", "run"]


@dataclass(frozen=True)
class EngineRun:
    """What :func:`run` returns: the outputs reached, in the caller's units.

    Attributes
    ----------
    t : ndarray, shape (k,)
        The output times reached (``k = len(t_out)`` when ``complete``).
    r, v : ndarray, shape (k, n, 3)
        The states at those times.
    steps : int
        Steps taken.
    wall_time : float
        Seconds of the integration proper.
    complete : bool
        False if the run stopped early (``stop()`` or Ctrl-C).
    events : EventLog or None
        The events found (when any were watched); an event that stopped the run
        is ``events.stopped_by``, and ``t[-1]`` is its time.
    gm : ndarray, shape (n,) or (k, n)
        ``G m`` of every body; per output, (k, n), when merges or removals
        changed it during the run.
    variational : Tangent or None
        The variational equations of the run (MEGNO, the Lyapunov exponent and the
        STM at the outputs), when they were asked for.
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


def run(
    r0: np.ndarray,
    v0: np.ndarray,
    gm: np.ndarray,
    t_out: np.ndarray,
    rhs: Any,
    method: str,
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
    method : str
        One of :data:`hamilton_orbits.integrators.INTEGRATORS`.
    dt, tol : float, optional
        The integrator's step and tolerance (see each integrator).
    options : dict, optional
        The integrator's own options (e.g. ``coordinates`` for ``wh``).
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
        ``variational=True``); forwards in time and without events.

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
    module = integrator(method)
    # C-contiguous float64, not copied when it is already (read-only is fine: the
    # drivers copy what they change)
    r0, v0, gm = (x if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous
                  else np.require(x, np.float64, ["C"]) for x in (r0, v0, gm))
    backward = t_out.shape[0] > 1 and t_out[-1] < t_out[0]
    if backward and rhs.velocity_dependent:
        raise ValueError("Backward integration with a velocity-dependent effect is not "
                         "supported; integrate forwards from the final state")
    n_t = t_out.shape[0]
    r_out = np.empty((n_t,) + np.shape(r0))
    v_out = np.empty_like(r_out)
    reached = [0, 0]  # last output index, steps

    def report(i: int, steps: int) -> None:
        reached[0], reached[1] = i, steps
        if on_output is not None:
            on_output(i, steps)
        if stop is not None and stop():
            raise StopIntegration

    kw = dict(options or {})
    if variational is not None:
        if backward or (events is not None and len(events.watch)):
            raise ValueError("The variational equations are integrated forwards in time and "
                             "without events; integrate forwards, with no events listed")
        kw["variational"] = variational
    if events is not None and len(events.watch):
        if backward:
            raise ValueError("Events are watched forwards in time only; integrate forwards")
        kw["events"] = events
    t_reached = np.array(t_out, dtype=np.float64)
    start = time.perf_counter()
    complete = True
    try:
        _, _, steps = module.run(rhs, r0, -v0 if backward else v0, gm,
                                 -t_out if backward else t_out, dt=dt, tol=tol,
                                 on_output=report, out=(r_out, v_out), stop=stop, **kw)
        reached[0], reached[1] = n_t - 1, steps
    except StopAtEvent as stopped:
        reached[0], reached[1] = stopped.index, stopped.steps
        t_reached[stopped.index] = stopped.t
    except (StopIntegration, KeyboardInterrupt):
        complete = False
    wall = time.perf_counter() - start
    k = reached[0] + 1
    gm_out = (events.gm_at(t_reached[:k], gm) if events is not None and events.gm_changes
              else gm)
    if backward:  # in place: no second copy of the history
        np.negative(v_out, out=v_out)
    return EngineRun(t_reached[:k], r_out[:k], v_out[:k], reached[1], wall, complete,
                     events, gm_out, variational)
