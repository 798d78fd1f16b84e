"""Integrate a :class:`~hamilton_orbits.nbody.System`: :func:`integrate`, :class:`Trajectory`.

Every trajectory carries Hamilton's integrals as diagnostics (Hamilton 1845,
equations (C), (D), (E)): the drift of the centre of mass, the relative error of
the total angular momentum (law of areas) and of the energy (vis viva).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import engine
from hamilton_orbits.effects import EffectSet, effect_energy, get
from hamilton_orbits.events import EventLog, EventSet, watch_table
from hamilton_orbits.firstrun import compile_seconds
from hamilton_orbits.integrals import LostStateError, integral_errors
from hamilton_orbits.integrators import INTEGRATORS
from hamilton_orbits.nbody import DAY, System
from hamilton_orbits.rhs import compile_rhs
from hamilton_orbits.trajectory import TrajectoryBase
from hamilton_orbits.units import DIMENSIONLESS, TIME, is_quantity
from hamilton_orbits.validation import as_float_array

__all__ = ["INTEGRATORS", "Trajectory", "check_method", "integrate", "make_trajectory"]


def _accepting_velocity_dependent() -> list[str]:
    return [m for m in INTEGRATORS if engine.integrator(m).ACCEPTS_VELOCITY_DEPENDENT]


@dataclass(frozen=True, eq=False, kw_only=True)
class Trajectory(TrajectoryBase):
    """The states of a system at the output times, with Hamilton's integrals.

    Attributes (beside those of :class:`~hamilton_orbits.trajectory.TrajectoryBase`:
    ``t``, ``steps``, ``wall_time``, ``method``, ``energy_error``,
    ``angular_momentum_error``)
    ----------
    t : ndarray or Quantity, shape (n_t,)
        Output times (the first is the initial time), in the unit the caller gave
        ``t`` in (a Quantity system), or the caller's floats.
    r, v : ndarray or Quantity, shape (n_t, n, 3)
        Positions and velocities (au, au/day for Quantity systems).
    names : tuple of str
    final : System
        The system at the last output time (made on first access from the last
        output row).
    energy_error : ndarray, shape (n_t,)
        ``(E(t) - E(0)) / |E(0)|`` (law of vis viva, (E)), with the listed effects'
        energies where they keep one (``gr``, ``gr_potential``, ``j2``); with one
        massive body, the test particles' specific orbital energies about it
        (:func:`~hamilton_orbits.nbody.integral_errors`).
    angular_momentum_error : ndarray, shape (n_t,)
        ``|L(t) - L(0)| / |L(0)|`` (law of areas, (D)); absolute if ``L(0) = 0``.
    barycentre_drift : ndarray, shape (n_t,)
        ``|R(t) - R(0) - V(0) t| / s`` with ``s`` the largest distance from the
        initial centre of mass (law of the centre of gravity, (C)).
    steps : int
        Steps taken by the integrator.
    wall_time : float
        Seconds of wall-clock time for the integration proper (the checks and
        any numba compilation, of the right-hand side or of the stepping kernel
        on its first call, are not counted).
    method : str
    effects : tuple of str
    events : astropy.table.QTable
        One row per event found (``name``, ``time``, ``bodies``, ``distance``,
        ``speed``, ``action``); empty when none was listed or found.
    stopped_by : astropy.table.Row or None
        The row of the event that ended the run, if one did.
    megno : ndarray, shape (n_t,) or None
        With ``variational=True``: MEGNO ``<Y>(t)`` (Cincotta & Simo 2000), as
        rebound's ``sim.megno()``; it tends to 2 on a quasi-periodic orbit, 0 on a
        stable periodic one, and grows like ``lambda t / 2`` on a chaotic one.  0 at
        the start.
    lyapunov : ndarray or Quantity, shape (n_t,) or None
        With ``variational=True``: the Lyapunov exponent as rebound's
        ``sim.lyapunov()`` defines it, the slope of the least-squares line through
        ``<Y>(t)`` over the steps so far (Cincotta & Simo 2000, eq. 24), in 1/(the
        unit of ``t``); ``1 / lyapunov`` is the Lyapunov time.  For ``|delta|``
        growing like ``exp(lambda t)``, ``<Y> ~ lambda t / 2``: this slope is
        ``lambda / 2`` of the growth rate of the tangent vector.
    stm : ndarray, shape (n_t, 6n, 6n) or None
        With ``stm=True``: the state transition matrix ``d(r, v)(t) / d(r, v)(0)``,
        coordinates body by body (x, y, z, vx, vy, vz of body 0, then body 1, ...),
        in the system's internal units (au and days for a Quantity system).
    """

    r: Any
    v: Any
    names: tuple[str, ...]
    barycentre_drift: np.ndarray
    effects: tuple[str, ...]
    #: What :attr:`final` is made from on first access: the system, the last
    #: state, masses and the bodies still in the run (a copy of the state made
    #: only when asked for: 48 bytes a body).
    final_source: Any = field(default=None, repr=False)
    #: What :attr:`events` and :attr:`stopped_by` are built from, on first access
    #: (the events log, the system and the time unit): an astropy table costs
    #: ~0.1 ms, more than the rest of a short call's wrapping.
    event_source: Any = field(default=None, repr=False)
    megno: Any = None
    lyapunov: Any = None
    stm: Any = None

    @functools.cached_property
    def final(self) -> System:
        """The system at the last output time."""
        system, r, v, gm, keep = self.final_source
        return system.with_state(r, v, gm=gm, keep=keep, check=False)

    @functools.cached_property
    def events(self) -> Any:
        """One row per event found (a ``QTable``; empty when none was listed or found)."""
        return self._event_tables()[0]

    @functools.cached_property
    def stopped_by(self) -> Any:
        """The row of :attr:`events` of the event that ended the run, or None."""
        return self._event_tables()[1]

    def _event_tables(self) -> tuple[Any, Any]:
        if "_tables" not in self.__dict__:
            log, system, unit = self.event_source or (None, None, None)
            self.__dict__["_tables"] = event_table(log, system, unit)
        return self.__dict__["_tables"]

    def __repr__(self) -> str:
        return (
            f"Trajectory({len(self.names)} bodies, {len(self.energy_error)} outputs, "
            f"method={self.method!r}, effects={self.effects!r}, steps={self.steps}, "
            f"max |dE/E|={np.max(np.abs(self.energy_error)):.3g})"
        )


def _times(t: Any, quantity: bool) -> tuple[np.ndarray, Any]:
    """Output times in days (Quantity system) from ``t``, with the caller's unit."""
    if type(t) is float and not quantity and t != 0.0 and math.isfinite(t):
        return np.array([0.0, t]), None  # an end time in the caller's units: the common case
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
        if arr[0] == 0.0:
            raise ValueError("Expected `t` to be a nonzero end time, got 0")
        arr = np.array([0.0, arr[0]])
    elif arr[0] != 0.0:
        arr = np.concatenate(([0.0], arr))
    d = np.diff(arr)
    if not (np.all(d > 0) or np.all(d < 0)):
        k = int(np.argmax(~(d > 0))) if d[0] > 0 else int(np.argmax(~(d < 0)))
        raise ValueError(
            f"Expected `t` to be strictly monotonic (times after the start 0), got "
            f"{arr[k + 1]!r} after {arr[k]!r} at index {k + 1}"
        )
    return arr, unit


def _check_options(module: Any, method: str, options: dict[str, Any]) -> None:
    """Refuse an option the integrator's ``run`` does not take, listing those it does."""
    if not options:
        return
    takes = _options_of(module.run)
    for key, value in options.items():
        if key not in takes:
            raise ValueError(
                f"Unknown option `{key}` = {value!r} for method {method!r}; it takes: "
                + (", ".join(takes) if takes else "no options beyond dt and tol"))


@functools.cache
def _options_of(run: Any) -> list[str]:
    """The options a driver's ``run`` takes (its keyword-only parameters beyond the
    common ones), read once per driver."""
    import inspect

    common = {"dt", "tol", "on_output", "out", "events", "stop", "variational"}
    return [name for name, p in inspect.signature(run).parameters.items()
            if p.kind is p.KEYWORD_ONLY and name not in common]


def integrate(
    system: System,
    t: Any,
    method: str = "radau15",
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
    """Integrate Hamilton's equation (B) (plus the listed effects) for ``system``.

    Parameters
    ----------
    system : System
    t : Quantity or float or array_like
        An end time, or output times (monotonic; a start at 0 is added if missing).
        A time Quantity for a Quantity system, plain floats otherwise.
    method : {"radau15", "wh", "leapfrog", "dop853"}
        The integrator (see :mod:`hamilton_orbits.integrators`).
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
        ``on_output(i, steps)`` after output ``i`` (for scenes and interfaces).
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
        ``coordinates="jacobi"`` and ``corrector=3`` (or 5, 7, 11, 17; see its
        ``run``).  An option the method does not take raises ``ValueError``
        listing those it takes.

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
    if not isinstance(system, System):
        raise ValueError(f"Expected `system` to be a System, got {system!r}")
    eff = check_method(method, effects, options)
    times, unit = _times(t, system.quantity)
    step = None if dt is None else _step(dt, system.quantity)
    if tol is not None:
        tol = DIMENSIONLESS.scalar("tol", tol)
        if not 0.0 < tol < 1.0:
            raise ValueError(f"Expected `tol` (a relative tolerance) in (0, 1), got {tol!r}")
    tan = _tangent(system, len(times), variational, stm, tangent)
    rhs = compile_rhs(system, eff, variational=tan is not None)
    log = event_log(system, events)
    arrays = system.as_arrays()
    with _progress(progress, method, len(times) - 1, on_output) as report:
        compiled = compile_seconds()
        out = engine.run(arrays.r, arrays.v, arrays.gm, times, rhs, method, dt=step, tol=tol,
                         options=options, on_output=report, events=log, variational=tan)
        compiled = compile_seconds() - compiled  # a first call compiles the stepping kernel
    out = dataclasses.replace(out, wall_time=max(out.wall_time - compiled, 0.0))
    if not out.complete:
        raise KeyboardInterrupt
    return make_trajectory(system, out, unit, method, rhs.effects, eff)


def _tangent(system: System, n_t: int, variational: Any, stm: Any, vector: Any) -> Any:
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
        return None
    from hamilton_orbits.integrators._tangent import Tangent

    n = len(system.names)
    if vector is not None:
        vec = as_float_array("tangent", vector)
        if vec.size != 6 * n:
            raise ValueError(f"Expected `tangent` to have shape ({n}, 6), got {vec.shape}")
        if not np.any(vec):
            raise ValueError("Expected `tangent` to be nonzero, got all zeros")
        vector = vec.reshape(n, 6)
    return Tangent(n, n_t, stm=stm, vector=vector)


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


def check_method(method: str, effects: Any, options: Mapping[str, Any]) -> EffectSet:
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
    module = engine.integrator(method)
    _check_options(module, method, dict(options))
    eff = EffectSet.of(effects, "nbody")
    if not module.ACCEPTS_VELOCITY_DEPENDENT:
        for name in eff.names:
            if get("nbody", name).velocity_dependent:
                raise ValueError(
                    f"Effect {name!r} depends on velocities and integrator {method!r} is "
                    f"symplectic; integrators that accept it: "
                    f"{', '.join(_accepting_velocity_dependent())}"
                    + (" (or use 'gr_potential')" if name == "gr" else "")
                )
    return eff


@contextlib.contextmanager
def _progress(enabled: bool, method: str, total: int, on_output: Any) -> Iterator[Any]:
    """An output callback that advances a tqdm bar (when ``enabled``) and calls
    ``on_output``; the bar is closed on the way out."""
    bar = None
    if enabled:
        try:
            from tqdm.auto import tqdm

            bar = tqdm(total=total, desc=method, unit="output", leave=False)
        except ImportError:  # pragma: no cover - tqdm is an optional extra
            bar = None

    def report(i: int, steps: int) -> None:
        if bar is not None:
            bar.update(1)
        if on_output is not None:
            on_output(i, steps)

    try:
        yield report
    finally:
        if bar is not None:
            bar.close()


def make_trajectory(system: System, out: engine.EngineRun, unit: Any, method: str,
                    effects: tuple[str, ...], effect_set: Any = None) -> Trajectory:
    """The :class:`Trajectory` of an engine run from ``system`` (Quantities for a
    Quantity system, with times in ``unit``); ``effect_set`` (the
    :class:`~hamilton_orbits.effects.EffectSet` run) adds the effects' energies to
    the energy whose error is reported, where they keep one.

    Raises
    ------
    ValueError
        If the run lost a body's state (a non-finite position or velocity).
    """
    r, v, times = out.r, out.v, out.t
    gone = out.events.inactive if out.events is not None else None
    try:
        ee, ae, bd = integral_errors(r, v, out.gm, times,
                                     gone=np.zeros(r.shape[1], bool) if gone is None else gone)
    except LostStateError as lost:
        k, i = lost.index
        raise ValueError(
            f"The integration with {method!r} lost the state of body "
            f"{system.names[i]!r} at output {k} (t = {times[k]!r}): "
            "a collision or a step too long"
        ) from None
    if effect_set:  # the energy the equations keep: the effects part added
        ee = integral_errors(r, v, out.gm, times, effect_energy(system, effect_set, r, v))[0]
    final = (system, r[-1], v[-1], np.atleast_2d(out.gm)[-1], None if gone is None else ~gone)
    if system.quantity:
        t_out: Any = (times * u.day).to(unit)
        r_out: Any = r << u.au  # views: no second copy of the history
        v_out: Any = v << (u.au / u.day)
    else:
        t_out, r_out, v_out = times, r, v
    tan = out.variational
    megno = lyap = stm = None
    if tan is not None:
        k = len(times)
        megno, lyap = tan.megno[:k].copy(), tan.lyapunov[:k].copy()
        stm = tan.stm[:k].copy() if tan.stm is not None else None
        if system.quantity:
            lyap = (lyap / u.day).to(1 / unit)
    return Trajectory(
        t=t_out, r=r_out, v=v_out, names=system.names, final_source=final, energy_error=ee,
        angular_momentum_error=ae, barycentre_drift=bd, steps=int(out.steps),
        wall_time=out.wall_time, method=method, effects=effects,
        event_source=(out.events, system, unit), megno=megno, lyapunov=lyap, stm=stm,
    )


def event_table(log: EventLog | None, system: System | None, unit: Any) -> tuple[Any, Any]:
    """The events of a run as a ``QTable`` (times in ``unit``, distances in au and
    speeds in au/day for a Quantity system) and the row that stopped it, or None."""
    from astropy.table import QTable

    from hamilton_orbits.events import ACTIONS, NAMES

    rows = log.recorded() if log is not None else np.zeros((0, 7))
    actions = {code: name for name, code in ACTIONS.items()}
    names = list(system.names) if system is not None else []
    quantity = system is not None and system.quantity
    bodies = [names[int(i)] if j < 0 else f"{names[int(i)]}-{names[int(j)]}"
              for i, j in rows[:, 1:3]]
    table = QTable()
    table["name"] = [NAMES[int(c)] for c in rows[:, 0]] if len(rows) else np.array([], str)
    table["time"] = (rows[:, 3] * u.day).to(unit) if quantity else rows[:, 3]
    table["bodies"] = bodies if len(rows) else np.array([], str)
    table["distance"] = rows[:, 4] * u.au if quantity else rows[:, 4]
    table["speed"] = rows[:, 5] * (u.au / u.day) if quantity else rows[:, 5]
    table["action"] = [actions[int(a)] for a in rows[:, 6]] if len(rows) else np.array([], str)
    stopped = log.stopped_by if log is not None else None
    return table, (table[stopped] if stopped is not None else None)
