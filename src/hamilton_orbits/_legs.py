"""The arguments of a :class:`~hamilton_orbits.simulation.Simulation` checked, and a
leg's output times, rows and progress bar.

:func:`leg_times` makes the output times of a leg from what the caller gave (an end
time or times, a Quantity for a Quantity system); :func:`time_step`, :func:`tolerance`,
:func:`tangent_of` and :func:`event_list` check the simulation's arguments;
:func:`rows_of` and :func:`requested_rows` hide the rows an archive's snapshot
times added to a leg from the caller (its output callback and its trajectory).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Callable, Mapping
from types import ModuleType, SimpleNamespace
from typing import Any

import numpy as np

from hamilton_orbits.effects import EffectSet, get
from hamilton_orbits.engine import EngineRun, Propagation
from hamilton_orbits.events import EventLog, EventSet, watch_table
from hamilton_orbits.integrators import INTEGRATORS, Method, method_of
from hamilton_orbits.nbody import DAY, System
from hamilton_orbits.rhs import RHS
from hamilton_orbits.units import DIMENSIONLESS, TIME, is_quantity, time_quantity
from hamilton_orbits.validation import as_float_array

__all__ = [
    "check_effects",
    "check_method",
    "event_list",
    "event_log",
    "leg_run",
    "leg_times",
    "progress_reporter",
    "requested_rows",
    "rows_of",
    "shared_memo",
    "tangent_of",
    "time_step",
    "tolerance",
]


def leg_times(t: Any, t_now: float, quantity: bool) -> tuple[np.ndarray, Any]:
    """Output times in days (Quantity system) from ``t``, from the simulation's time
    ``t_now`` (added first if missing), with the caller's unit."""
    if type(t) is float and not quantity and t != t_now and math.isfinite(t):
        return np.array([t_now, t]), None  # an end time in the caller's units: the common case
    if isinstance(t, (bool, np.bool_)):
        raise ValueError(f"Expected `t` to be a time or an array of times, got {t!r}")
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
    if quantity and unit != DAY and abs(arr[0] - t_now) <= _ROUND_TRIP * abs(t_now):
        arr[0] = t_now  # (the simulation's time given back in the caller's unit: its
        # round trip through that unit may move it by an ulp or two, not a time of its
        # own; in days, the unit it is kept in, a time given is the time meant)
    if arr.size == 1:
        if arr[0] == t_now:
            raise ValueError("Expected `t` to be a nonzero end time, got 0" if t_now == 0.0
                             else f"Expected `t` to differ from the simulation's time "
                                  f"{t_now!r}{' d' if quantity else ''}, got "
                                  f"{float(arr[0])!r}{' d' if quantity else ''}")
        return np.array([t_now, arr[0]]), unit
    added = int(arr[0] != t_now)
    if added:
        arr = np.concatenate(([t_now], arr))
    _check_monotonic(arr, t_now, added, " d" if quantity else "")
    return arr, unit


#: how far (relative) a time given back through another unit may be from the one it
#: was (two roundings each way, with a margin)
_ROUND_TRIP = 8 * np.finfo(np.float64).eps


def _check_monotonic(arr: np.ndarray, t_now: float, added: int, unit: str) -> None:
    """Refuse output times ``arr`` (the simulation's time first, ``added`` to the
    caller's times when 1) that are not strictly monotonic, naming the caller's
    index and value (``unit``: " d" for a Quantity system's days)."""
    d = np.diff(arr)
    if np.all(d > 0) or np.all(d < 0):
        return
    start = "0" if t_now == 0.0 else f"{t_now!r}{unit}"
    rest = d[added:]
    if added and rest.size and (np.all(rest > 0) or np.all(rest < 0)):  # (the caller's
        # times monotonic, the first on the wrong side of the simulation's time)
        raise ValueError(f"Expected `t` to be strictly monotonic from the simulation's time "
                         f"{start}, got {float(arr[1])!r}{unit} at index 0 and "
                         f"{float(arr[2])!r}{unit} at index 1")
    k = int(np.argmax(~(d > 0))) if d[0] > 0 else int(np.argmax(~(d < 0)))
    raise ValueError(
        f"Expected `t` to be strictly monotonic (times after the start {start}), got "
        f"{float(arr[k + 1])!r}{unit} after {float(arr[k])!r}{unit} at index {k + 1 - added}"
    )



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
        with np.errstate(over="ignore", under="ignore"):
            square = float(np.sum(vec * vec))
        if not np.finfo(np.float64).tiny <= square < np.inf:  # (its log-norm kept by MEGNO)
            top = float(np.max(np.abs(vec)))
            raise ValueError(f"Expected `tangent` of a norm of about 1e-150 to 1e150 (MEGNO "
                             f"does not depend on its scale), got a norm of "
                             f"{top * float(np.linalg.norm(vec / top)):.3g}")
        vector = vec.reshape(n, 6)
    return Tangent(n, 1, stm=stm, vector=vector)



def event_list(events: Any) -> list[dict[str, Any]]:
    """The listed events as mappings (as a snapshot records them)."""
    if isinstance(events, (tuple, list)) and not events:
        return []
    return [dict(name=name, **params) for name, params in EventSet.of(events).items]



def time_step(dt: Any, quantity: bool, name: str = "dt") -> float:
    """``dt`` (or the interval ``name``) in days (a Quantity system: a time Quantity
    is required, or a TimeDelta) or the caller's float, positive and finite."""
    dt = time_quantity(dt)
    if isinstance(dt, (bool, np.bool_)):
        raise ValueError(f"Expected `{name}` to be a number, got {dt!r}")
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
    if not np.isfinite(step):
        raise ValueError(f"Expected `{name}` to be finite, got {step!r}")
    if not step > 0:
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
                              lyapunov_time=tan.lyapunov_time[:k][keep],
                              stm=None if tan.stm is None else tan.stm[:k][keep])
    gm = out.gm[keep] if np.ndim(out.gm) == 2 else out.gm
    return dataclasses.replace(out, t=out.t[keep], r=out.r[keep], v=out.v[keep], gm=gm,
                               variational=tan)


def shared_memo(prop: Propagation) -> dict[int, Any]:
    """The memo of a deep copy of ``prop``: what a copy shares instead of copying
    (the compiled right-hand side, the driver module, compiled functions and
    their addresses, the method value)."""
    memo: dict[int, Any] = {}
    seen: set[int] = set()

    def walk(obj: Any) -> None:
        if id(obj) in seen:
            return
        seen.add(id(obj))
        module = type(obj).__module__ or ""
        if isinstance(obj, (RHS, Method, ModuleType)) or module.startswith("numba"):
            memo[id(obj)] = obj
        elif isinstance(obj, (list, tuple)):
            for x in obj:
                walk(x)
        elif isinstance(obj, dict):
            for x in obj.values():
                walk(x)
        elif hasattr(obj, "__dict__") and not isinstance(obj, (np.ndarray, type)):
            for x in vars(obj).values():
                walk(x)

    walk(prop)
    return memo


def event_log(system: System, events: Any) -> EventLog | None:
    """The :class:`~hamilton_orbits.events.EventLog` of ``events`` for ``system``
    (None when no event is listed).

    Examples
    --------
    >>> from hamilton_orbits import Body
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
    >>> event_log(s, [{"name": "escape", "distance": 10.0}]).watch.tolist()
    [[3.0, 1.0, -1.0, 10.0, 0.0]]
    """
    if isinstance(events, (tuple, list)) and not events:
        return None  # none listed (the common case)
    listed = EventSet.of(events)
    if not listed:
        return None
    return EventLog(watch_table(listed, system), system.as_arrays().radius)


def check_effects(method: Method, effects: Any) -> EffectSet:
    """The effects as an :class:`~hamilton_orbits.effects.EffectSet`, checked against
    the typed ``method`` (a velocity-dependent effect refused by a symplectic map, one
    that replaces Newtonian gravity by ``wh``, naming the integrators that accept it)."""
    eff = EffectSet.of(effects, "nbody")
    if not method.accepts_velocity_dependent:
        for name in eff.names:
            if get("nbody", name).velocity_dependent:
                accepting = [m for m in INTEGRATORS
                             if method_of(m).accepts_velocity_dependent]
                raise ValueError(
                    f"Effect {name!r} depends on velocities and integrator {method.name!r} is "
                    f"symplectic; integrators that accept it: {', '.join(accepting)}"
                    + (" (or use 'gr_potential')" if name == "gr" else "")
                )
    for name in eff.names:
        if get("nbody", name).replaces_newtonian and not method.accepts_newtonian_replaced:
            accepting = [m for m in INTEGRATORS if method_of(m).accepts_newtonian_replaced]
            raise ValueError(f"Effect {name!r} replaces Newtonian gravity, which integrator "
                             f"{method.name!r} splits into Kepler drifts and kicks of its "
                             f"own; integrators that accept it: {', '.join(accepting)}")
    return eff


def check_method(method: str | Method, effects: Any, options: Mapping[str, Any]) -> EffectSet:
    """The effects as an :class:`~hamilton_orbits.effects.EffectSet`, checked
    against ``method`` and its ``options``.

    Raises
    ------
    ValueError
        For an unknown method, option or effect, or a velocity-dependent effect
        given to a symplectic integrator (naming the effect and the integrators
        that accept it).

    Examples
    --------
    >>> check_method("wh", ["gr_potential"], {"coordinates": "jacobi"}).names
    ('gr_potential',)
    """
    return check_effects(method_of(method, options), effects)


def progress_reporter(method: str, total: int,
                      on_output: Any) -> tuple[Any, Callable[[], None] | None]:
    """An output callback that advances a tqdm bar and calls ``on_output``, and the
    bar's ``close`` (``on_output`` itself and None where tqdm is not installed)."""
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - tqdm is an optional extra
        return on_output, None
    # (disable=None: quiet where stderr is no terminal, a log file or a pipe, which
    # kept each bar's text; a notebook's widget bar shows)
    bar = tqdm(total=total, desc=method, unit="output", leave=False, disable=None)

    def report(i: int, steps: int) -> None:
        bar.update(1)
        if on_output is not None:
            on_output(i, steps)

    return report, bar.close


def leg_run(rows: dict[str, np.ndarray], out: EngineRun | None, prop: Propagation,
            steps: int, first_event: int) -> EngineRun:
    """A resumed leg as one engine run: its rows from the archive (``out_*``) and
    those of ``out``, the run from the last snapshot (its first row, the snapshot's
    own time, dropped: the archive holds the rows asked for up to it)."""
    t, r, v = rows["out_t"], rows["out_r"], rows["out_v"]
    megno, lyap, stm = rows.get("out_megno"), rows.get("out_lyapunov"), rows.get("out_stm")
    lyap_time = rows.get("out_lyapunov_time")
    if out is not None:
        k = len(out.t)
        t, r, v = (np.concatenate((a, b[1:])) for a, b in ((t, out.t), (r, out.r), (v, out.v)))
        tan = out.variational
        if tan is not None:
            megno = np.concatenate((megno, tan.megno[1:k]))
            lyap = np.concatenate((lyap, tan.lyapunov[1:k]))
            lyap_time = np.concatenate((lyap_time, tan.lyapunov_time[1:k]))
            stm = None if tan.stm is None else np.concatenate((stm, tan.stm[1:k]))
    events = prop.events
    gm = (events.gm_at(t, prop.gm0) if events is not None and events.gm_changes
          else prop.gm0)
    tangent = None if megno is None else SimpleNamespace(
        megno=megno, lyapunov=lyap, lyapunov_time=lyap_time, stm=stm)
    done = out is None or out.complete
    return EngineRun(t, r, v, steps, 0.0 if out is None else out.wall_time, done, events, gm,
                     tangent, out is not None and out.interrupted, first_event,
                     bool(np.isfinite(r).all() and np.isfinite(v).all()))


#: the modules between a caller and the warnings of Simulation.integrate
_OWN = ("hamilton_orbits.simulation", "hamilton_orbits._saving", "hamilton_orbits._legs")


def caller_level() -> int:
    """The ``stacklevel`` of a warning raised in the simulation's modules that names
    the caller's line (of ``integrate``, ``Simulation.integrate`` or ``resume``)."""
    level, frame = 2, sys._getframe(2)
    while frame is not None and frame.f_globals.get("__name__") in _OWN:
        level, frame = level + 1, frame.f_back
    return level
