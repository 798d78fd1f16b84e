"""Leapfrog: drift-kick-drift, second order, symplectic, time-reversible.

One step of length ``h``: ``r += h/2 v``; ``v += h a(r)``; ``r += h/2 v``.  The
map is symplectic for forces that derive from a potential, so velocity-dependent
effects are refused.  With ``tol`` and no ``dt``, the step is chosen from the
shortest dynamical time of the initial state (see :func:`choose_dt`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import leapfrog as _k
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import StopIntegration, _tangent, output_arrays
from hamilton_orbits.integrators._setup import MAX_FIXED_STEPS, accel_arg, check_step_count

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "NAME", "SLICE", "choose_dt", "run"]

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


def run(
    rhs: Any,
    r0: np.ndarray,
    v0: np.ndarray,
    gm: np.ndarray,
    t_out: np.ndarray,
    *,
    dt: float | None = None,
    tol: float | None = None,
    on_output: Callable[[int, int], None] | None = None,
    out: tuple[np.ndarray, np.ndarray] | None = None,
    max_steps: int = MAX_FIXED_STEPS,
    events: EventLog | None = None,
    variational: Any = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[np.ndarray, np.ndarray, int]:
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
    if dt is None:
        if tol is None:
            raise ValueError("leapfrog needs a step `dt` or a tolerance `tol`, got neither")
        dt = choose_dt(r0, v0, gm, tol)
    check_step_count(float(t_out[-1] - t_out[0]), float(dt), max_steps, NAME)
    if variational is not None:
        return _tangent.run_leapfrog(rhs, np.asarray(r0, np.float64), np.asarray(v0, np.float64),
                                     np.ascontiguousarray(gm, dtype=np.float64), t_out,
                                     variational, dt=float(dt), on_output=on_output, out=out,
                                     stop=stop)
    r = np.ascontiguousarray(r0, dtype=np.float64).copy()
    v = np.ascontiguousarray(v0, dtype=np.float64).copy()
    gm = np.ascontiguousarray(gm, dtype=np.float64)
    out_r, out_v = output_arrays(out, len(t_out), r, v)
    steps = 0
    accel = accel_arg(rhs.accel)
    gm = np.ascontiguousarray(gm, dtype=np.float64).copy()
    log = events if events is not None else EventLog.none(r.shape[0])
    for i in range(1, len(t_out)):
        t = float(t_out[i - 1])
        while t < t_out[i]:
            ws = np.array([t, np.inf, 0.0, -1.0])
            done, status = _k.advance(accel, rhs.p, r, v, gm, t, float(t_out[i]), dt,
                                      log.watch, log.buffer, log.count, ws, SLICE)
            steps += int(done)
            t = float(ws[0])
            if status == _k.STATUS_OK:
                break  # t is t_out[i], exactly
            if status == _k.STATUS_SLICE:  # Ctrl-C and stop() are seen between slices
                if stop is not None and stop():
                    raise StopIntegration
                continue
            log.drain()
            if status == _k.STATUS_EVENT and log.act(int(ws[3]), t, r, v, gm):
                out_r[i], out_v[i] = r, v
                out_r[i, log.inactive] = np.nan
                out_v[i, log.inactive] = np.nan
                raise StopAtEvent(i, t, steps)
        out_r[i] = r
        out_v[i] = v
        out_r[i, log.inactive] = np.nan
        out_v[i, log.inactive] = np.nan
        if on_output is not None:
            on_output(i, steps)
    return out_r, out_v, steps
