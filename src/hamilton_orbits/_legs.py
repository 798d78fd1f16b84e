"""The arguments of a :class:`~hamilton_orbits.simulation.Simulation` checked, and a
leg's output times and rows.

:func:`leg_times` makes the output times of a leg from what the caller gave (an end
time or times, a Quantity for a Quantity system); :func:`time_step`, :func:`tolerance`,
:func:`tangent_of` and :func:`event_list` check the simulation's arguments;
:func:`rows_of` and :func:`requested_rows` hide the rows an archive's snapshot
times added to a leg from the caller (its output callback and its trajectory).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

import numpy as np

from hamilton_orbits.engine import EngineRun
from hamilton_orbits.events import EventSet
from hamilton_orbits.integrators import Method
from hamilton_orbits.nbody import DAY, System
from hamilton_orbits.units import DIMENSIONLESS, TIME, is_quantity
from hamilton_orbits.validation import as_float_array

__all__ = ["event_list", "leg_times", "requested_rows", "rows_of", "tangent_of", "time_step",
           "tolerance"]


def leg_times(t: Any, t_now: float, quantity: bool) -> tuple[np.ndarray, Any]:
    """Output times in days (Quantity system) from ``t``, from the simulation's time
    ``t_now`` (added first if missing), with the caller's unit."""
    if type(t) is float and not quantity and t != t_now and math.isfinite(t):
        return np.array([t_now, t]), None  # an end time in the caller's units: the common case
    if quantity and not is_quantity(t):
        raise ValueError(f"Expected `t` as a time Quantity for a Quantity system, got {t!r}")
    if not quantity and is_quantity(t):
        raise ValueError(f"Expected `t` as plain floats for a system of plain floats, got {t!r}")
    unit = t.unit if quantity else None
    arr = np.atleast_1d(TIME("t", t, DAY if quantity else None)).astype(np.float64)
    if arr.size == 0:
        raise ValueError("Expected `t` to be an end time or a non-empty array of times, got []")
    if arr.ndim != 1:
        raise ValueError(f"Expected `t` to be a time or a 1-d array of times, got shape "
                         f"{arr.shape}")
    if arr.size == 1:
        if arr[0] == t_now:
            raise ValueError("Expected `t` to be a nonzero end time, got 0" if t_now == 0.0
                             else f"Expected `t` to differ from the simulation's time "
                                  f"{t_now!r}, got {float(arr[0])!r}")
        arr = np.array([t_now, arr[0]])
    elif arr[0] != t_now:
        arr = np.concatenate(([t_now], arr))
    d = np.diff(arr)
    if not (np.all(d > 0) or np.all(d < 0)):
        k = int(np.argmax(~(d > 0))) if d[0] > 0 else int(np.argmax(~(d < 0)))
        start = "0" if t_now == 0.0 else repr(t_now)
        raise ValueError(
            f"Expected `t` to be strictly monotonic (times after the start {start}), got "
            f"{arr[k + 1]!r} after {arr[k]!r} at index {k + 1}"
        )
    return arr, unit



def tolerance(tol: Any) -> float | None:
    if tol is None:
        return None
    tol = DIMENSIONLESS.scalar("tol", tol)
    if not 0.0 < tol < 1.0:
        raise ValueError(f"Expected `tol` (a relative tolerance) in (0, 1), got {tol!r}")
    return tol



def tangent_of(system: System, variational: Any, stm: Any, vector: Any, method: Method) -> Any:
    """The :class:`~hamilton_orbits.integrators._tangent.Tangent` of a run, or None."""
    if not isinstance(variational, bool) or not isinstance(stm, bool):
        raise ValueError(f"Expected `variational` and `stm` to be True or False, got "
                         f"{variational!r}, {stm!r}")
    if stm and not variational:
        raise ValueError("`stm=True` needs `variational=True` (the STM is integrated with "
                         "the variational equations)")
    if not variational:
        if vector is not None:
            raise ValueError("`tangent` is MEGNO's initial tangent vector: it needs "
                             "`variational=True`")
        if getattr(method, "tangent_control", False):
            raise ValueError("`tangent_control=True` lets the tangent vectors take part in "
                             "the step control: it needs `variational=True`")
        return None
    from hamilton_orbits.integrators._tangent import Tangent

    n = len(system.names)
    if vector is not None:
        vec = as_float_array("tangent", vector)
        if vec.shape not in ((n, 6), (6 * n,)):
            raise ValueError(f"Expected `tangent` to have shape ({n}, 6), got {vec.shape}")
        if not np.any(vec):
            raise ValueError("Expected `tangent` to be nonzero, got all zeros")
        vector = vec.reshape(n, 6)
    return Tangent(n, 1, stm=stm, vector=vector)



def event_list(events: Any) -> list[dict[str, Any]]:
    """The listed events as mappings (as a snapshot records them)."""
    if isinstance(events, (tuple, list)) and not events:
        return []
    return [dict(name=name, **params) for name, params in EventSet.of(events).items]



def time_step(dt: Any, quantity: bool, name: str = "dt") -> float:
    """``dt`` (or the interval ``name``) in days (a Quantity system: a time Quantity
    is required) or the caller's float, positive and finite."""
    if quantity and not is_quantity(dt):
        raise ValueError(f"Expected `{name}` as a time Quantity for a Quantity system, got "
                         f"{dt!r} (a bare number would be read as days)")
    if not quantity and is_quantity(dt):
        raise ValueError(f"Expected `{name}` as a plain float for a system of plain floats, "
                         f"got {dt!r}")
    if type(dt) is float and not quantity:
        step = dt  # checked below
    else:
        step = TIME.scalar(name, dt, DAY if quantity else None)
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"Expected `{name}` > 0, got {step!r}")
    return step



def rows_of(on_output: Callable[[int, int], None] | None,
             asked: np.ndarray) -> Callable[[int, int], None] | None:
    """``on_output`` called with the caller's own output numbers (the archive's
    snapshot rows skipped)."""
    if on_output is None:
        return None
    number = np.cumsum(asked) - 1

    def call(i: int, steps: int) -> None:
        if asked[i]:
            on_output(int(number[i]), steps)

    return call



def requested_rows(out: EngineRun, asked: np.ndarray) -> EngineRun:
    """``out`` without the rows of snapshot times the caller did not ask for (the
    last row kept when the run stopped early)."""
    keep = asked[:len(out.t)].copy()
    if not out.complete or (out.events is not None and out.events.stopped_by is not None):
        keep[-1] = True
    if keep.all():
        return out
    tan = out.variational
    if tan is not None:
        k = len(out.t)
        tan = SimpleNamespace(megno=tan.megno[:k][keep], lyapunov=tan.lyapunov[:k][keep],
                              stm=None if tan.stm is None else tan.stm[:k][keep])
    gm = out.gm[keep] if np.ndim(out.gm) == 2 else out.gm
    return dataclasses.replace(out, t=out.t[keep], r=out.r[keep], v=out.v[keep], gm=gm,
                               variational=tan)
