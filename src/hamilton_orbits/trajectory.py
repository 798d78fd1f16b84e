"""What a run returns: ``TrajectoryBase``, the shape every trajectory shares, and
the n-body :class:`Trajectory`.

An n-body :class:`~hamilton_orbits.simulation.Trajectory` and a rigid body's
``rigid.RigidTrajectory`` answer the same first questions the same way: at
which times (``t``), in how many steps (``steps``), in how much wall-clock time
(``wall_time``), with which method, and how well the integrals of the motion
were kept (``energy_error``, ``angular_momentum_error``: Hamilton's law of
vis viva (E) and of areas (D) for the n-body problem; Cayley's free-body
integrals of energy and of the angular momentum in space for a rigid body).

Units follow one rule in both packages: where the caller gave Quantities, the
results are Quantities (in the units documented by each subclass); where the
caller gave plain floats, they are plain floats in the caller's own units.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np

from hamilton_orbits.integrals import LIGHT, relative_change, under_resolved_encounters
from hamilton_orbits.validation import read_only

__all__ = ["Trajectory", "TrajectoryBase", "encounter_check", "encounter_warning", "event_table",
           "make_trajectory", "relative_change"]


class TrajectoryBase:
    """The attributes every trajectory has (an n-body :class:`Trajectory`, a rigid
    body's ``rigid.RigidTrajectory``).

    Attributes
    ----------
    t : ndarray or Quantity, shape (n_t,)
        Output times; ``t[0]`` is the start.
    steps : int
        Steps taken by the integrator (0 for an exact solution).
    wall_time : float
        Seconds of wall-clock time of the integration proper (not the
        validation of the input, nor the wrapping of the output).
    method : str
        The integrator's name.
    energy_error : ndarray, shape (n_t,)
        Relative change of the energy integral from the start (see the subclass).
    angular_momentum_error : ndarray, shape (n_t,)
        Relative change of the angular momentum vector from the start.
    """

    t: Any
    steps: int
    wall_time: float
    method: str
    energy_error: np.ndarray
    angular_momentum_error: np.ndarray

    @property
    def n_outputs(self) -> int:
        """The number of output times (``len(t)``)."""
        return int(np.shape(self.t)[0])


class Trajectory(TrajectoryBase):
    """The states of a system at the output times, with Hamilton's integrals.

    What :meth:`hamilton_orbits.Simulation.integrate` (and ``integrate``) returns:
    one leg of a run, its first row the state the leg started from.  Hamilton's
    integrals are measured from the start of the simulation, so that a run
    continued in legs reports the drift since its beginning; they, the final
    system and the events table are computed on first access (made by
    ``make_trajectory``, whose ``integrals`` is what they are computed from: the
    engine run's arrays, or a callable returning the three error arrays).

    The attributes below come beside those of ``TrajectoryBase`` (``t``,
    ``steps``, ``wall_time``, ``method``, ``energy_error``,
    ``angular_momentum_error``).

    Attributes
    ----------
    t : ndarray or Quantity, shape (n_t,)
        Output times (the first is the leg's start), in the unit the caller gave
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
        (:func:`~hamilton_orbits.integrals.integral_errors`); ``E(0)`` at the start of
        the simulation.
    angular_momentum_error : ndarray, shape (n_t,)
        ``|L(t) - L(0)| / |L(0)|`` (law of areas, (D)); absolute if ``L(0) = 0``.
    barycentre_drift : ndarray, shape (n_t,)
        ``|R(t) - R(0) - V(0) t| / s`` with ``s`` the largest distance from the
        initial centre of mass (law of the centre of gravity, (C)).
    particle_error : ndarray, shape (n_t, n)
        Each test particle's own check, which Hamilton's integrals leave out (a
        massless body does not enter them): the relative change since the start of
        the simulation of its Jacobi constant (two massive bodies on a circular
        orbit: an error), else of its two-body energy about its primary (one
        massive body: an error; several: how much the others changed its orbit);
        NaN for the massive bodies
        (:func:`~hamilton_orbits.integrals.particle_errors`).
    particle_check : tuple of str
        What ``particle_error`` measures for each body: ``"Jacobi constant"``,
        ``"energy about <name>"``, or ``""`` (a massive body).
    under_resolved : astropy.table.QTable
        The close approaches (of test particles, and of massive bodies to
        heavier ones) that a fixed step
        was too long for (longer than 1/30 of the approach's time scale), seen
        at the outputs of this leg: ``particle``, ``body``, ``time``, ``distance``,
        ``timescale``, ``step``, and the particle's osculating ``1/a`` and ``e``
        about ``primary`` before and after; empty for adaptive methods.  A run
        that crosses one warns (:class:`~hamilton_orbits.integrals.UnderResolvedEncounterWarning`,
        once per simulation) (:func:`~hamilton_orbits.integrals.under_resolved_encounters`).
    steps : int
        Steps taken by the integrator in this leg.
    wall_time : float
        Seconds of wall-clock time for the integration proper (the checks and
        any numba compilation, of the right-hand side or of the stepping kernel
        on its first call, are not counted).
    method : str
    effects : tuple of str
    complete : bool
        False when the leg was cut short: ``stop()`` returned True, an output
        callback raised :class:`~hamilton_orbits.integrators.StopIntegration`, or
        Ctrl-C came with ``on_interrupt="keep"`` (the outputs reached are kept).
        An event whose action is ``"stop"`` ends the leg as its result, not a cut:
        ``complete`` stays True, ``stopped_by`` is that event's row and ``t[-1]``
        is before the end asked for (see ``docs/events.md``).
    events : astropy.table.QTable
        One row per event found in this leg (``name``, ``time``, ``bodies``,
        ``distance``, ``speed``, ``action``); empty when none was listed or found.
    stopped_by : astropy.table.Row or None
        The row of the event that ended the leg, if one did.
    megno : ndarray, shape (n_t,) or None
        With ``variational=True``: MEGNO ``<Y>(t)`` (Cincotta & Simo 2000), as
        rebound's ``sim.megno()``; it tends to 2 on a quasi-periodic orbit, 0 on a
        stable periodic one, and grows like ``lambda t / 2`` on a chaotic one.  0 at
        the start.
    lyapunov : ndarray or Quantity, shape (n_t,) or None
        With ``variational=True``: the Lyapunov exponent as rebound's
        ``sim.lyapunov()`` defines it, the slope of the least-squares line through
        ``<Y>(t)`` over the steps so far (Cincotta & Simo 2000, eq. 24), in 1/(the
        unit of ``t``).  For ``|delta|`` growing like ``exp(lambda t)``,
        ``<Y> ~ lambda t / 2``: this slope is ``lambda / 2`` of the growth rate of
        the tangent vector.  On a regular orbit ``<Y>`` levels off and the slope
        tends to 0 from either side: a negative value means no exponential growth
        was measured (``<Y>`` still settling towards its plateau), and its inverse
        is not a time (use ``lyapunov_time``).
    lyapunov_time : ndarray or Quantity, shape (n_t,) or None
        With ``variational=True``: the Lyapunov time ``1 / lyapunov`` where the
        run so far has lasted at least that long (``lyapunov t >= 1``, ``t`` from
        the simulation's start), ``inf`` where it has not or the exponent is not
        positive (no exponential growth measured: the orbit looks regular over
        the run); in the unit of ``t``.
    stm : ndarray, shape (n_t, 6n, 6n) or None
        With ``stm=True``: the state transition matrix ``d(r, v)(t) / d(r, v)(0)``,
        coordinates body by body (x, y, z, vx, vy, vz of body 0, then body 1, ...),
        in the system's internal units (au and days for a Quantity system).
    """

    def __init__(self, *, t: Any, r: Any, v: Any, names: tuple[str, ...], steps: int,
                 wall_time: float, method: str, effects: tuple[str, ...], complete: bool = True,
                 integrals: Any,
                 final_source: Any = None, event_source: Any = None, megno: Any = None,
                 lyapunov: Any = None, stm: Any = None, lyapunov_time: Any = None,
                 under_resolved: Any = ()) -> None:
        # one dict update: a short leg's wrapping is part of the cost of a call
        self.__dict__.update(
            t=read_only(t), r=read_only(r), v=read_only(v), names=names, steps=steps,
            wall_time=wall_time, method=method,
            effects=effects, complete=complete, megno=megno, lyapunov=lyapunov, stm=stm,
            lyapunov_time=lyapunov_time, _integrals=integrals, _final_source=final_source,
            _event_source=event_source, _under_resolved=under_resolved)

    #: what a trajectory without variational equations, events or under-resolved
    #: approaches has (read from the class: a short leg's wrapping sets fewer names)
    megno = lyapunov = stm = lyapunov_time = _event_source = None
    _under_resolved: Any = ()

    @classmethod
    def _plain(cls, values: dict[str, Any]) -> Trajectory:
        """A trajectory from the attributes in ``values`` (those of ``__init__``, the
        sources under their own names), the others the class's defaults: without
        the keyword call, a third of the cost of wrapping a short leg."""
        new = cls.__new__(cls)
        new.__dict__.update(values)
        return new

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"Trajectory is read-only: cannot set {name!r}")

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Unpickled (or deep-copied): its ``t``, ``r``, ``v`` read-only, as made."""
        self.__dict__.update(state)
        for name in ("t", "r", "v"):
            self.__dict__[name] = read_only(state.get(name))

    @property
    def effect_set(self) -> Any:
        """The effects the trajectory was integrated with, with their parameters (an
        :class:`~hamilton_orbits.effects.EffectSet`), or None where it does not hold
        them (``effects`` then gives their names)."""
        source = self._integrals
        return source[6] if isinstance(source, tuple) else None

    @functools.cached_property
    def _errors(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        source = self._integrals
        if source is None:
            raise ValueError(_NO_INTEGRALS)
        return source() if callable(source) else _integrals(*source)

    @property
    def energy_error(self) -> np.ndarray:  # type: ignore[override]
        """Relative change of the energy since the start (see the class notes)."""
        return self._errors[0]

    @property
    def angular_momentum_error(self) -> np.ndarray:  # type: ignore[override]
        """Relative change of the angular momentum since the start."""
        return self._errors[1]

    @property
    def barycentre_drift(self) -> np.ndarray:
        """Drift of the centre of mass from uniform motion, relative to the size."""
        return self._errors[2]

    @functools.cached_property
    def _particles(self) -> tuple[np.ndarray, tuple[str, ...]]:
        source = self._integrals
        if source is None:
            raise ValueError(_NO_INTEGRALS)
        if callable(source):
            n = len(self.names)
            return np.full((len(self.r), n), np.nan), ("",) * n
        errors, checks = _particle_errors(*source)
        names = self.names
        checks = tuple("Jacobi constant" if c == "jacobi"
                       else f"energy about {names[int(c.rsplit(' ', 1)[1])]}" if c else ""
                       for c in checks)
        return errors, checks

    @property
    def particle_error(self) -> np.ndarray:
        """Each test particle's own check (see the class notes); NaN for massive bodies."""
        return self._particles[0]

    @property
    def particle_check(self) -> tuple[str, ...]:
        """What :attr:`particle_error` measures for each body."""
        return self._particles[1]

    @functools.cached_property
    def under_resolved(self) -> Any:
        """The close approaches a fixed step was too long for (a ``QTable``)."""
        if self._final_source is None:
            raise ValueError(_NO_FINAL)
        return _encounter_table(self._under_resolved, self._final_source[0],
                                getattr(self.t, "unit", None))

    @functools.cached_property
    def final(self) -> Any:
        """The system at the last output time.

        Raises
        ------
        ValueError
            For a trajectory of bodies in a field (small bodies in an ephemeris's),
            which are not a System: their states are ``r`` and ``v``.
        """
        if self._final_source is None:
            raise ValueError(_NO_FINAL)
        system, r, v, gm, keep, radius = self._final_source
        return system.with_state(r, v, gm=np.atleast_2d(gm)[-1], keep=keep, check=False,
                                 radius=radius)

    @functools.cached_property
    def _tables(self) -> tuple[Any, Any]:
        rows, stopped, system, unit = self._event_source or (None, None, None, None)
        return event_table(rows, system, unit, stopped)

    @property
    def events(self) -> Any:
        """One row per event found (a ``QTable``; empty when none was listed or found)."""
        return self._tables[0]

    @property
    def stopped_by(self) -> Any:
        """The row of :attr:`events` of the event that ended the run, or None."""
        return self._tables[1]

    def covariance(self, cov0: Any) -> np.ndarray:
        """Each body's covariance of ``(x, y, z, vx, vy, vz)`` at every output, the
        initial one ``cov0`` (``(6, 6)`` for every body or ``(n, 6, 6)``, floats in
        the state's units: au and au/day for a Quantity system) mapped through
        ``stm`` to first order (:func:`hamilton_orbits.covariance.propagate`):
        shape ``(n_t, n, 6, 6)``.

        Raises
        ------
        ValueError
            Without the STM (integrate with ``stm=True``), or for a bad ``cov0``.
        """
        from hamilton_orbits.covariance import propagate

        if self.stm is None:
            raise ValueError("covariance() maps through the STM: integrate with stm=True")
        return propagate(self.stm, cov0, len(self.names))

    def plot(self, plane: str = "xy", ax: Any = None) -> Any:
        """Every body's path about the primary, its start (with the direction of
        motion) and its end: a matplotlib Figure
        (``hamilton_orbits.trajectory_plot.plot_trajectory``)."""
        from hamilton_orbits.trajectory_plot import plot_trajectory

        return plot_trajectory(self, plane, ax)

    def plot3d(self, bodies: Sequence[str] | None = None, origin: str = "primary",
               unit: Any = None, max_frames: int = 200) -> Any:
        """An interactive 3-D view of the paths, with a time slider (plotly).

        Every body's path as a line, its start (open circle), its position at the
        last output (a marker the slider moves along the path) and the origin body
        as a cross; the axes name their origin and unit and keep the data's aspect
        (``hamilton_orbits.trajectory_plot3d.plot_trajectory3d``).

        Parameters
        ----------
        bodies : sequence of str, optional
            The bodies drawn (default: all but the origin body).
        origin : str, default "primary"
            ``"primary"`` (the most massive body), a body's name, or ``"frame"``
            (the integration frame's origin).
        unit : str or astropy.units.Unit, optional
            Length unit of the axes (Quantity trajectories only; default au).
        max_frames : int, default 200
            The most slider steps: the outputs are subsampled evenly to at most
            this many animation frames so that the figure stays small (the lines
            use every output).

        Returns
        -------
        plotly.graph_objects.Figure

        Raises
        ------
        ImportError
            Without plotly: ``pip install 'hamilton-orbits[plot3d]'``.
        ValueError
            For an unknown body or origin, a bad unit, or ``max_frames`` < 2.

        Examples
        --------
        >>> from hamilton_orbits import Body, System, integrate
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
        >>> fig = integrate(s, np.linspace(0, 2 * np.pi, 50)).plot3d()
        >>> [trace.name for trace in fig.data]
        ['earth', 'earth start', 'earth now', 'sun (origin)']
        """
        from hamilton_orbits.trajectory_plot3d import plot_trajectory3d

        return plot_trajectory3d(self, bodies, origin, unit, max_frames)

    def __repr__(self) -> str:
        return (
            f"Trajectory({len(self.names)} bodies, {len(self.r)} outputs, "
            f"method={self.method!r}, effects={self.effects!r}, steps={self.steps}"
            + ("" if self._integrals is None
               else f", max |dE/E|={np.max(np.abs(self.energy_error)):.3g}")
            + ("" if self.complete else ", incomplete") + ")"
        )


_NO_FINAL = ("This trajectory is of bodies in a field (small bodies in an ephemeris's), "
             "not of a System: no final System and no encounter check of its steps; its "
             "states are `r` and `v`")
_NO_INTEGRALS = ("This trajectory keeps no integrals (bodies in a field that changes with "
                 "time, such as small bodies in an ephemeris's): no energy, angular momentum "
                 "or barycentre error")


def event_table(rows: Any, system: Any, unit: Any, stopped: int | None = None
                ) -> tuple[Any, Any]:
    """The events as a ``QTable`` (times in ``unit``, distances in au and speeds in
    au/day for a Quantity system) and the row ``stopped`` (that stopped the run), or
    None.

    ``rows`` is an :class:`~hamilton_orbits.events.EventLog` (every event it
    recorded, and the one that stopped it), an array of recorded rows (k, 7), or
    None (no event).

    Examples
    --------
    >>> table, stopped = event_table(None, None, None)
    >>> len(table), stopped is None
    (0, True)
    """
    import astropy.units as u
    from astropy.table import QTable

    from hamilton_orbits.events import ACTIONS, N_EVENT_COLUMNS, NAMES

    if hasattr(rows, "recorded"):  # an EventLog
        rows, stopped = rows.recorded(), rows.stopped_by
    rows = np.zeros((0, N_EVENT_COLUMNS)) if rows is None else rows
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
    for column in ("time", "distance", "speed"):  # printed in 80 columns: none behind "..."
        table[column].info.format = ".7g"
    return table, (table[stopped] if stopped is not None else None)


def _check_finite(system: Any, method: str, r: np.ndarray, v: np.ndarray,
                  times: np.ndarray, gone: np.ndarray | None) -> None:
    """Refuse a run that lost a body's state (a non-finite position or velocity of a
    body still in the run)."""
    ok = np.isfinite(r).all(axis=2) & np.isfinite(v).all(axis=2)
    if gone is not None:
        ok |= gone[None, :]
    if ok.all():
        return
    k, i = (int(x) for x in np.argwhere(~ok)[0])
    raise ValueError(
        f"The integration with {method!r} lost the state of body "
        f"{system.names[i]!r} at output {k} (t = {times[k]!r}): "
        "a collision or a step too long"
    )


def _from_start(r: np.ndarray, v: np.ndarray, gm: np.ndarray, times: np.ndarray, start: Any
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The outputs with the simulation's start ``start = (r0, v0, gm0)`` at time 0
    prepended (None: the first output is the start)."""
    if start is None:
        return r, v, gm, times
    r0, v0, gm0 = start
    r = np.concatenate((r0[None], r))
    v = np.concatenate((v0[None], v))
    gm = (np.concatenate((gm0[None], gm)) if np.ndim(gm) == 2
          else gm if np.array_equal(gm, gm0) else np.stack([gm0] + [gm] * (len(r) - 1)))
    return r, v, gm, np.concatenate(([0.0], times))


def _integrals(system: Any, r: np.ndarray, v: np.ndarray, gm: np.ndarray, times: np.ndarray,
               gone: np.ndarray | None, effect_set: Any, start: Any
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hamilton's integrals' errors at the outputs, from the simulation's start
    ``start = (r0, v0, gm0)`` at time 0 (None: the first output is the start)."""
    # measured from the simulation's start: prepend it, then drop it
    r, v, gm, times = _from_start(r, v, gm, times, start)
    from hamilton_orbits.effects import effect_energy
    from hamilton_orbits.integrals import integral_errors

    extra = effect_energy(system, effect_set, r, v) if effect_set else None
    errors = integral_errors(r, v, gm, times, extra,
                             gone=np.zeros(r.shape[1], bool) if gone is None else gone)
    return errors if start is None else (errors[0][1:], errors[1][1:], errors[2][1:])


def _particle_errors(system: Any, r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                     times: np.ndarray, gone: np.ndarray | None, effect_set: Any, start: Any
                     ) -> tuple[np.ndarray, tuple[str, ...]]:
    """The test particles' own checks at the outputs, from the simulation's start."""
    r, v, gm, times = _from_start(r, v, gm, times, start)
    from hamilton_orbits.effects import effect_energy
    from hamilton_orbits.integrals import particle_errors

    if not (np.atleast_2d(gm)[0] == 0).any():
        return np.full(r.shape[:2], np.nan)[int(start is not None):], ("",) * r.shape[1]
    extra = effect_energy(system, effect_set, r, v) if effect_set else None
    errors, checks = particle_errors(r, v, gm, extra)
    return (errors if start is None else errors[1:]), checks


def encounter_check(method: Any, dt: float | None, tol: float | None, r0: np.ndarray,
                    gm: np.ndarray) -> tuple[float | None, Any, float] | None:
    """What ``make_trajectory`` checks the close approaches with, for a
    run from positions ``r0``: None for an adaptive method, else ``(step, exempt,
    fraction)``: the fixed step (None: the leg's mean step), ``(body, distance)``,
    the body whose approaches beyond that distance the method integrates exactly
    (``wh``'s central body), or None, and the largest fraction of an approach's
    time scale a step may be (see
    :func:`~hamilton_orbits.integrals.under_resolved_encounters`; 1/3 for
    radau15's fixed steps, of order 15)."""
    from hamilton_orbits.integrals import ENCOUNTER_STEP_FRACTION

    name = getattr(method, "name", method)
    if name == "wh" and np.any(gm > 0):
        c = int(np.argmax(gm))
        if getattr(method, "coordinates", "") == "democratic_heliocentric":
            return dt, (c, 0.0), ENCOUNTER_STEP_FRACTION
        centre = gm @ r0 / gm.sum()  # Kepler motions about the inner bodies' centre of mass
        return dt, (c, 10.0 * float(np.linalg.norm(r0[c] - centre))), ENCOUNTER_STEP_FRACTION
    if name == "leapfrog":
        return dt, None, ENCOUNTER_STEP_FRACTION
    if name == "radau15" and dt is not None and tol is None:
        return dt, None, 1.0 / 3.0
    return None


def encounter_warning(traj: Trajectory) -> Any:
    """An :class:`~hamilton_orbits.integrals.UnderResolvedEncounterWarning` saying
    which close approaches of ``traj`` a fixed step was too long for, or None."""
    found = traj._under_resolved
    if not found:  # (before the import: this runs after every call of a simulation)
        return None
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    names = traj.names
    first = found[0]
    day, au = (" d", " au") if traj._final_source[0].quantity else ("", "")
    more = f" (and {len(found) - 1} more: see `under_resolved`)" if len(found) > 1 else ""
    who = names[first.particle]
    if np.isfinite(first.inv_a[1]) and np.isfinite(first.e[1]):
        across = (f"across it the osculating 1/a of {who!r} about {names[first.primary]!r} went "
                  f"from {first.inv_a[0]:.6g} to {first.inv_a[1]:.6g}{' /au' if au else ''} "
                  f"and e from {first.e[0]:.6g} to {first.e[1]:.6g}: not to be trusted")
    else:  # (taken out of the run after it: "went from -0.31 to nan" before)
        across = (f"{who!r} was taken out of the run after it (its orbit about "
                  f"{names[first.primary]!r} then: 1/a = {first.inv_a[0]:.6g}"
                  f"{' /au' if au else ''}, e = {first.e[0]:.6g}), its path to there not to "
                  f"be trusted")
    return UnderResolvedEncounterWarning(
        f"The step ({first.step:.4g}{day}) was too long for the close approach of "
        f"{who!r} to {names[first.body]!r} ({first.distance:.4g}{au} at "
        f"t = {first.time:.6g}{day}, time scale {first.timescale:.4g}{day}){more}; {across}; "
        "shorten the step or use an adaptive method (radau15)")


#: the screen this module calls after each leg, imported at the first
_KERNELS: dict[str, Any] = {}


def _under_resolved(r: np.ndarray, v: np.ndarray, out: Any, times: np.ndarray,
                    encounters: tuple[float | None, Any, float]) -> Any:
    """The close approaches of an engine run's outputs that its fixed step was too
    long for (``encounters`` from :func:`encounter_check`): one compiled call finds
    that there are none (after nearly every call: 2 us of a continuing call of one
    step of ten bodies), the details only where there are."""
    screen = _KERNELS.get("screen")
    if screen is None:  # (the compiled screen's, imported once: an import statement
        from hamilton_orbits._screening import screen  # per call cost 0.6 us of 10)

        _KERNELS["screen"] = screen
    step, exempt, fraction = encounters
    if step is None:
        step = abs(times[-1] - times[0]) / max(int(out.steps), 1)
    ex, ex_dist = (-1, 0.0) if exempt is None else exempt
    parts = _constant_masses(r, v, out.gm, times)
    found: list[Any] = []
    for rp, vp, gm, tp in parts:
        if screen(rp, vp, gm, tp, float(step), ex, ex_dist, fraction, LIGHT):
            found.extend(under_resolved_encounters(rp, vp, gm, tp, step, exempt, fraction))
    return tuple(found) if len(parts) > 1 else (found or ())


def _constant_masses(r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                     times: np.ndarray) -> list[tuple[np.ndarray, ...]]:
    """A leg's outputs in parts of constant masses, for the screen: the outputs
    between two merges or removals (``gm`` (n_t, n) where they changed), and each
    interval across one with the bodies it changed left out (NaN, massless): the
    change in 1/a across it is the merge's, not the step's, and the approach it
    showed one to a body that had left.  One part, the leg, where nothing changed."""
    if gm.ndim == 1:
        return [(r, v, gm, times)]
    changed = gm[1:] != gm[:-1]
    cut = np.flatnonzero(changed.any(axis=1)) + 1
    parts = [(r[a:b], v[a:b], gm[a], times[a:b])
             for a, b in zip(np.r_[0, cut].tolist(), np.r_[cut, len(times)].tolist(), strict=True)
             if b - a >= 2]
    for k in cut.tolist():  # (the intervals across a change: the few merges of a leg)
        rk, vk, gk = r[k - 1:k + 1].copy(), v[k - 1:k + 1].copy(), gm[k - 1].copy()
        rk[:, changed[k - 1]] = np.nan
        vk[:, changed[k - 1]] = np.nan
        gk[changed[k - 1]] = 0.0
        parts.append((rk, vk, gk, times[k - 1:k + 1]))
    return parts


def _encounter_table(found: Any, system: Any, unit: Any) -> Any:
    """The under-resolved approaches as a ``QTable`` (Quantities for a Quantity system)."""
    import astropy.units as u
    from astropy.table import QTable

    names = list(system.names)
    rows = np.array([[e.time, e.distance, e.timescale, e.step, *e.inv_a, *e.e]
                     for e in found]).reshape(-1, 8)
    q = system.quantity and unit is not None
    table = QTable()
    for col, key in (("particle", "particle"), ("body", "body"), ("primary", "primary")):
        table[col] = [names[getattr(e, key)] for e in found] if found else np.array([], str)
    table["time"] = (rows[:, 0] * u.day).to(unit) if q else rows[:, 0]
    table["distance"] = rows[:, 1] * u.au if q else rows[:, 1]
    table["timescale"] = (rows[:, 2] * u.day).to(unit) if q else rows[:, 2]
    table["step"] = (rows[:, 3] * u.day).to(unit) if q else rows[:, 3]
    for k, col in enumerate(("inv_a_before", "inv_a_after")):
        table[col] = rows[:, 4 + k] / u.au if q else rows[:, 4 + k]
    table["e_before"], table["e_after"] = rows[:, 6], rows[:, 7]
    return table


@functools.lru_cache(maxsize=16)
def _state_units(unit: Any) -> tuple[Any, Any, float]:
    """The units of a Quantity trajectory's positions and velocities (au, au/day) and
    the scale from days to its times' ``unit``: made once per unit, not per call (a
    composite unit built anew costs 8 us, a conversion through a Quantity 5).

    Examples
    --------
    >>> import astropy.units as u
    >>> _state_units(u.yr)[1:] == (u.au / u.day, u.day.to(u.yr))
    True
    """
    import astropy.units as u

    return u.au, u.au / u.day, u.day.to(unit)


def make_trajectory(system: Any, out: Any, unit: Any, method: str,
                    effects: tuple[str, ...], effect_set: Any = None, *, start: Any = None,
                    wall_time: float | None = None, encounters: Any = None) -> Trajectory:
    """The :class:`Trajectory` of an engine run from ``system`` (Quantities for a
    Quantity system, with times in ``unit``); ``effect_set`` (the
    :class:`~hamilton_orbits.effects.EffectSet` run) adds the effects' energies to
    the energy whose error is reported, where they keep one; ``start`` (``(r0, v0,
    gm0)`` at time 0) when the run did not begin there; ``encounters`` (from
    :func:`encounter_check`) to find the close approaches a fixed
    step was too long for (``under_resolved``).

    Raises
    ------
    ValueError
        If the run lost a body's state (a non-finite position or velocity).
    """
    r, v, times = out.r, out.v, out.t
    log = out.events
    gone = log.inactive.copy() if log is not None else None  # the log goes on changing
    if not out.finite:
        _check_finite(system, method, r, v, times, gone)
    integrals = (system, r, v, out.gm, times, gone, effect_set, start)  # for _integrals
    found: Any = ()
    if encounters is not None and r.shape[1] > 1:
        found = _under_resolved(r, v, out, times, encounters)
    final = (system, r[-1], v[-1], out.gm, None if gone is None else ~gone,
             None if out.events is None else out.events.radius.copy())
    if system.quantity:
        import astropy.units as u

        au, au_day, scale = _state_units(unit)
        # (the bits of (times * u.day).to(unit): astropy multiplies by the same scale)
        t_out: Any = u.Quantity(times * scale, unit, copy=False)
        r_out: Any = r << au  # views: no second copy of the history
        v_out: Any = v << au_day
    else:
        t_out, r_out, v_out = times, r, v
    t_out, r_out, v_out = read_only(t_out), read_only(r_out), read_only(v_out)
    values = {"t": t_out, "r": r_out, "v": v_out, "names": system.names,
              "steps": int(out.steps), "method": method, "effects": effects,
              "wall_time": out.wall_time if wall_time is None else wall_time,
              "complete": out.complete, "_integrals": integrals, "_final_source": final}
    if found:
        values["_under_resolved"] = found
    tan = out.variational
    if tan is not None:
        k = len(times)
        lyap, lyap_time = tan.lyapunov[:k].copy(), tan.lyapunov_time[:k].copy()
        if system.quantity:
            lyap = (lyap / u.day).to(1 / unit)
            lyap_time = (lyap_time * u.day).to(unit)
        values.update(megno=tan.megno[:k].copy(), lyapunov=lyap, lyapunov_time=lyap_time,
                      stm=tan.stm[:k].copy() if tan.stm is not None else None)
    if log is not None:
        stopped = log.stopped_by
        values["_event_source"] = (log.recorded()[out.first_event:],
                                   None if stopped is None else stopped - out.first_event,
                                   system, unit)
    return Trajectory._plain(values)
