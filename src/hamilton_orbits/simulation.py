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
import math
import sys
import warnings
from collections.abc import Callable, Mapping, Sequence
from types import ModuleType
from typing import Any

import numpy as np

from hamilton_orbits import engine
from hamilton_orbits.effects import EffectSet, get
from hamilton_orbits.events import EventLog, EventSet, watch_table
from hamilton_orbits.firstrun import compile_seconds
from hamilton_orbits.integrators import INTEGRATORS, Method, method_of
from hamilton_orbits.nbody import DAY, System
from hamilton_orbits.rhs import RHS, compile_rhs
from hamilton_orbits.trajectory import (
    Trajectory,
    encounter_check,
    encounter_warning,
    event_table,
    make_trajectory,
)
from hamilton_orbits.units import DIMENSIONLESS, TIME, is_quantity
from hamilton_orbits.validation import as_float_array

__all__ = ["INTEGRATORS", "Simulation", "Trajectory", "check_method", "event_log",
           "event_table", "integrate", "make_trajectory"]


class Simulation:
    """A prepared n-body integration that lives across calls.

    Parameters
    ----------
    system : System
        The bodies at time 0 of the simulation.
    method : str or Method
        ``"radau15"`` (default), ``"wh"``, ``"leapfrog"``, ``"dop853"``, or a typed
        value (:class:`~hamilton_orbits.integrators.Radau15`,
        :class:`~hamilton_orbits.integrators.WH`, ...) that carries the options.
    dt : Quantity or float, optional
        A fixed step (``radau15``, ``wh``, ``leapfrog``) or a step cap
        (``dop853``); a time Quantity for a Quantity system.
    tol : float, optional
        The integrator's tolerance (adaptive methods) or the accuracy from which a
        fixed-step method chooses its step.
    effects : sequence of str or mapping
        Effects beyond Newtonian gravity (:mod:`hamilton_orbits.effects`).
    events : sequence of str or mapping, optional
        Events to find (:mod:`hamilton_orbits.events`).
    variational : bool
        Integrate the first-order variational equations beside the system (MEGNO,
        the Lyapunov exponent; see ``docs/variational.md``).
    stm : bool
        With ``variational``: also the state transition matrix.
    tangent : array_like, shape (n, 6), optional
        MEGNO's initial tangent vector (default: random, as rebound's
        ``init_megno`` draws it, a fixed seed).
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
                 tangent: Any = None, **method_options: Any) -> None:
        if not isinstance(system, System):
            raise ValueError(f"Expected `system` to be a System, got {system!r}")
        typed = method_of(method, method_options)
        eff = check_effects(typed, effects)
        step = None if dt is None else _step(dt, system.quantity)
        tol = _tolerance(tol)
        tan = _tangent(system, variational, stm, tangent, typed)
        rhs = compile_rhs(system, eff, variational=tan is not None)
        arrays = system.as_arrays()
        self._prop = engine.Propagation(arrays.r, arrays.v, arrays.gm, 0.0, rhs, typed, dt=step,
                                        tol=tol, events=event_log(system, events),
                                        variational=tan)
        self._system, self._effects, self._quantity = system, eff, system.quantity
        #: the state at time 0, from which Hamilton's integrals are measured (None
        #: until a first leg has begun there)
        self._start: Any = None
        self._initial = (arrays.r, arrays.v, arrays.gm)
        self._unit: Any = DAY if system.quantity else None

    # ------------------------------------------------------------------ state
    @property
    def method(self) -> Method:
        """The method and its options."""
        return self._prop.method

    @property
    def t(self) -> Any:
        """The simulation's time (see the class notes)."""
        t = self._prop.t
        return t if self._unit is None else (t * DAY).to(self._unit)

    @property
    def steps(self) -> int:
        """Steps taken since time 0."""
        return self._prop.steps

    @property
    def system(self) -> System:
        """The current state as a :class:`~hamilton_orbits.nbody.System` (bodies an
        event took out of the run are left out)."""
        p = self._prop
        keep = None if p.events is None or not p.events.inactive.any() else ~p.events.inactive
        return self._system.with_state(p.r, p.v, gm=p.gm, keep=keep, check=False)

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
        integrating one does not change the other."""
        new = copy.copy(self)
        new._prop = copy.deepcopy(self._prop, _shared(self._prop))
        return new

    # ------------------------------------------------------------------ run
    def integrate(self, t: Any, *, progress: bool = False,
                  on_output: Callable[[int, int], None] | None = None,
                  stop: Callable[[], bool] | None = None,
                  on_interrupt: str = "raise") -> Trajectory:
        """Advance to ``t`` and return the trajectory of this leg.

        Parameters
        ----------
        t : Quantity or float or array_like
            An end time, or output times (monotonic from the simulation's time
            :attr:`t`, which is added as the first output if missing), in the
            simulation's time (0 at the system given); a time Quantity for a
            Quantity system, plain floats otherwise.  Backwards is allowed for
            forces that do not depend on velocities.
        progress : bool
            Show a progress bar (tqdm, on stderr) over the output times.
        on_output : callable, optional
            ``on_output(i, steps)`` after output ``i``; it may raise
            :class:`~hamilton_orbits.engine.StopIntegration` to end the leg there
            (the trajectory then has ``complete == False``).
        stop : callable, optional
            ``stop()`` after every output and between slices of steps; True ends
            the leg there (``complete == False``).
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
            For bad times, or a lost state (a collision or a step too long).
        KeyboardInterrupt
            On Ctrl-C (the run stops within a few thousand steps; the simulation
            keeps the state reached), unless ``on_interrupt="keep"``.
        """
        if on_interrupt not in ("raise", "keep"):
            raise ValueError(f"Expected `on_interrupt` to be 'raise' or 'keep', got "
                             f"{on_interrupt!r}")
        prop = self._prop
        times, unit = _leg_times(t, prop.t, self._quantity)
        if unit is not None:
            self._unit = unit
        close = None
        if progress:
            on_output, close = _progress(prop.method.name, len(times) - 1, on_output)
        try:
            compiled = compile_seconds()
            out = prop.advance(times, on_output=on_output, stop=stop)
            compiled = compile_seconds() - compiled  # a first call compiles the stepping kernel
        finally:
            if close is not None:
                close()
        if out.interrupted and on_interrupt == "raise":
            raise KeyboardInterrupt
        start, self._start = self._start, self._initial  # the first leg begins at time 0
        traj = make_trajectory(self._system, out, unit, prop.method.name, prop.rhs.effects,
                               self._effects, start=start,
                               wall_time=max(out.wall_time - compiled, 0.0),
                               encounters=encounter_check(prop.method, prop.dt, prop.tol,
                                                          *self._initial[::2]))
        warning = encounter_warning(traj)
        if warning is not None and not getattr(self, "_warned", False):
            self._warned = True  # once per simulation
            warnings.warn(warning, stacklevel=_caller_level())
        return traj


def _caller_level() -> int:
    """The ``stacklevel`` of a warning from :meth:`Simulation.integrate` that names
    the line that called into this module (``integrate`` or ``Simulation.integrate``)."""
    level, frame = 2, sys._getframe(2)
    while frame is not None and frame.f_code.co_filename == __file__:
        level, frame = level + 1, frame.f_back
    return level


def _shared(prop: engine.Propagation) -> dict[int, Any]:
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
    t : Quantity or float or array_like
        An end time, or output times (monotonic; a start at 0 is added if missing).
        A time Quantity for a Quantity system, plain floats otherwise.
    method : {"radau15", "wh", "leapfrog", "dop853"} or Method
        The integrator (see :mod:`hamilton_orbits.integrators`), by name or as a
        typed value with its options (``WH(coordinates="jacobi")``).
    dt : Quantity or float, optional
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
        may raise :class:`~hamilton_orbits.engine.StopIntegration` to end the run
        there, the trajectory then incomplete (``complete == False``).
    events : sequence of str or mapping, optional
        Events to find during the run: ``close_encounter``, ``collision``,
        ``escape`` (see :mod:`hamilton_orbits.events`); the trajectory's
        ``events`` table lists them and ``stopped_by`` names the one that ended
        the run, if any.
    variational : bool
        Integrate the first-order variational equations beside the system (every
        listed effect's Jacobian included): the trajectory then has ``megno`` and
        ``lyapunov`` (from one tangent vector, as rebound's MEGNO; see
        ``docs/variational.md``).  Forwards in time, without events.
    stm : bool
        With ``variational``: also the state transition matrix ``traj.stm`` (6n
        more tangent vectors).
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


def _leg_times(t: Any, t_now: float, quantity: bool) -> tuple[np.ndarray, Any]:
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


def _tolerance(tol: Any) -> float | None:
    if tol is None:
        return None
    tol = DIMENSIONLESS.scalar("tol", tol)
    if not 0.0 < tol < 1.0:
        raise ValueError(f"Expected `tol` (a relative tolerance) in (0, 1), got {tol!r}")
    return tol


def _tangent(system: System, variational: Any, stm: Any, vector: Any, method: Method) -> Any:
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


def _step(dt: Any, quantity: bool) -> float:
    """``dt`` in days (a Quantity system: a time Quantity is required) or the
    caller's float, positive and finite."""
    if quantity and not is_quantity(dt):
        raise ValueError(f"Expected `dt` as a time Quantity for a Quantity system, got {dt!r} "
                         "(a bare number would be read as days)")
    if not quantity and is_quantity(dt):
        raise ValueError(f"Expected `dt` as a plain float for a system of plain floats, "
                         f"got {dt!r}")
    if type(dt) is float and not quantity:
        step = dt  # checked below
    else:
        step = TIME.scalar("dt", dt, DAY if quantity else None)
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"Expected `dt` > 0, got {step!r}")
    return step


def check_effects(method: Method, effects: Any) -> EffectSet:
    """The effects as an :class:`~hamilton_orbits.effects.EffectSet`, checked against
    the typed ``method`` (a velocity-dependent effect refused by a symplectic map,
    naming the integrators that accept it)."""
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


def _progress(method: str, total: int, on_output: Any) -> tuple[Any, Callable[[], None] | None]:
    """An output callback that advances a tqdm bar and calls ``on_output``, and the
    bar's ``close`` (``on_output`` itself and None where tqdm is not installed)."""
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - tqdm is an optional extra
        return on_output, None
    bar = tqdm(total=total, desc=method, unit="output", leave=False)

    def report(i: int, steps: int) -> None:
        bar.update(1)
        if on_output is not None:
            on_output(i, steps)

    return report, bar.close
