"""N-body integrators on the compiled right-hand side of ``hamilton_orbits.rhs``.

Each integrator is a Python driver here (checks, set-up, the loop over output
times) and a compiled step in ``hamilton_orbits._kernels`` (the loop over
steps).  A driver module satisfies ``Integrator``:

- ``NAME`` (``"leapfrog"``, ``"wh"``, ``"radau15"``, ``"dop853"``);
- ``ACCEPTS_VELOCITY_DEPENDENT`` (bool): symplectic maps refuse velocity-dependent
  effects;
- ``start(rhs, r0, v0, gm, t0, method, *, dt, tol, events=None, variational=None)``
  returning a ``DriverState``: the integrator's whole state at ``t0`` for
  arguments already checked (``method`` its typed value from
  :mod:`~hamilton_orbits.integrators.methods`), advanced leg by leg across calls
  exactly as one run through every output time (what
  :class:`hamilton_orbits.Simulation` stands on);
- ``run(rhs, r0, v0, gm, t_out, *, dt=None, tol=None, on_output=None, out=None,
  **options)`` returning ``(r, v, steps)``: one run, its input checked (``start``
  then one ``advance``): ``rhs`` an ``hamilton_orbits.rhs.RHS``; ``r0``,
  ``v0`` float64 (n, 3) and ``gm`` (n,) in one consistent unit system; ``t_out``
  an increasing float64 array of output times with ``t_out[0]`` the initial time
  (row 0 of the output is the initial state); ``r``, ``v`` of shape (len(t_out),
  n, 3), written into ``out`` when it is given (so that what was reached survives
  an interrupt); ``steps`` the number of steps taken.  ``on_output(i, steps)`` is
  called from Python after output ``i`` is reached (progress bars, stopping
  early); ``stop()`` is asked between slices of steps inside an output interval
  (radau15 every 20000 steps, wh every 100000, leapfrog every 100000; dop853 at
  outputs only), and True ends the run there with :class:`StopIntegration`.

Python only loops over output times (and, for radau15, over slices of many
steps); the public entry point is ``hamilton_orbits.engine.run``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from hamilton_orbits.integrators.methods import (
    DOP853,
    INTEGRATORS,
    WH,
    WH_CORRECTORS,
    Leapfrog,
    Method,
    Radau15,
    method_of,
)

__all__ = ["DOP853", "INTEGRATORS", "WH", "WH_CORRECTORS", "DriverState", "Integrator",
           "Leapfrog", "Method", "Radau15", "StopIntegration", "method_of", "output_arrays"]


class StopIntegration(Exception):
    """Raised to end a run early: by an output callback, or by a driver when its
    ``stop()`` callback, asked between slices of steps, returns True."""


class DriverState(Protocol):
    """An integrator's state between calls (what a driver's ``start`` returns).

    ``t`` is the time of the state and ``steps`` the steps taken since ``start``;
    ``advance(t_out, r_out, v_out, on_output, stop)`` steps through ``t_out``
    (``t_out[0]`` is ``t``) and writes rows 1... of ``r_out``, ``v_out`` (row 0 is
    the caller's), calling ``on_output(i, steps of this call)`` after output ``i``;
    an event that stops the run raises
    :class:`~hamilton_orbits.events.StopAtEvent`, ``stop()`` returning True
    between slices raises :class:`StopIntegration`.  ``state()`` returns copies of
    the current inertial positions, velocities and ``G m``.
    """

    t: float
    steps: int

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None: ...

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


class Integrator(Protocol):
    """What a driver module provides (see the module's notes)."""

    NAME: str
    ACCEPTS_VELOCITY_DEPENDENT: bool

    def start(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
              method: Any, *, dt: float | None, tol: float | None, events: Any = None,
              variational: Any = None) -> DriverState: ...

    def run(
        self,
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
        stop: Callable[[], bool] | None = None,
        **options: Any,
    ) -> tuple[np.ndarray, np.ndarray, int]: ...


def output_arrays(
    out: tuple[np.ndarray, np.ndarray] | None, n_t: int, r0: np.ndarray, v0: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The output arrays (``out``, or new ones) with row 0 the initial state.

    Examples
    --------
    >>> r, v = output_arrays(None, 3, np.ones((2, 3)), np.zeros((2, 3)))
    >>> r.shape, float(r[0, 0, 0])
    ((3, 2, 3), 1.0)
    """
    if out is None:
        r_out = np.empty((n_t,) + r0.shape)
        v_out = np.empty_like(r_out)
    else:
        r_out, v_out = out
    r_out[0] = r0
    v_out[0] = v0
    return r_out, v_out
