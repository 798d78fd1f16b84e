"""Wisdom-Holman map in democratic-heliocentric (default) or Jacobi coordinates.

Wisdom & Holman (1991), AJ 102, 1528, in the democratic-heliocentric form of
Duncan, Levison & Lee (1998), AJ 116, 2067, section 3: with heliocentric
positions ``Q_i = r_i - r_0`` and barycentric velocities ``u_i`` of the bodies
``i >= 1`` (the central body is the one of largest GM), the Hamiltonian splits
into

- the Kepler part, each body on a Kepler orbit about ``G M_0`` (advanced
  exactly by the universal-variable kernel
  ``hamilton_orbits._kernels.kepler.propagate_uv``, shared, not copied:
  the drift loop inlines its body, ``propagate_uv_inline``, calls it for a few
  bodies without effects, and from four bodies on solves several side by side,
  ``propagate_lanes``);
- the interaction part, the mutual attraction of the bodies ``i >= 1``
  (Hamilton's equation (B) without the central body), a kick of the ``u_i``;
- the "jump" ``|sum_i m_i u_i|^2 / (2 m_0)``, a drift of every ``Q_i`` by
  ``dt sum_i G m_i u_i / (G m_0)``;

and the barycentre moves uniformly.  One step is the second-order symmetric
composition that rebound's WHFast uses for these coordinates (Rein & Tamayo
2015, MNRAS 452, 376): Kepler dt/2, jump dt/2, interaction dt, jump dt/2,
Kepler dt/2; the Kepler halves of consecutive steps are merged, so each step
costs one Kepler solve per body and one force evaluation.  Effects listed in
the right-hand side (``rhs.extra``, velocity-independent only) are added to
the interaction kick, evaluated at the inertial positions; their net
acceleration of the barycentre moves the barycentre.

With ``coordinates="jacobi"`` (Wisdom & Holman 1991) body ``i`` moves on a
Kepler orbit about the total mass ``eta_i`` of the bodies up to it, about the
barycentre of the bodies before it; the kick is the inertial acceleration in
Jacobi form plus ``G eta_i r'_i / |r'_i|^3`` (the part the Kepler step already
took), and there is no jump.

Velocity-dependent effects are refused (the kick would not be symplectic).

Symplectic correctors
---------------------
With Jacobi coordinates the symplectic correctors of Wisdom, Holman & Touma
(1996) of order 3, 5, 7, 11 and 17 (the orders WHFast offers, Rein & Tamayo
2015) are available (``corrector=``): the corrector ``C`` is applied at the
start of each output interval and ``C^-1`` at its end, so the steps in between
are those of the uncorrected map on corrected coordinates and every output is
in true coordinates.  The coefficients are computed here
(``corrector_coefficients``): the corrector of order ``p`` removes the terms
``eps dt^2, eps dt^4, ..., eps dt^(p-1)`` (``eps`` the planet-to-star mass ratio)
of the map's error Hamiltonian; what remains is ``eps dt^(p+1)`` and the
``eps^2 dt^2`` terms no corrector of this kind removes.  The democratic-heliocentric map has no
corrector here: its kernel includes the "jump" term, whose error terms are not
of the form the WHT96 construction removes (Wisdom 2006 derives correctors for
heliocentric coordinates with a different kernel); WHFast likewise offers its
correctors for Jacobi coordinates only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._kernels import wh as _k
from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import StopIntegration, _setup, _tangent
from hamilton_orbits.integrators._held import HELD
from hamilton_orbits.integrators.methods import WH, check_run
from hamilton_orbits.integrators.methods import WH_COORDINATES as COORDINATES
from hamilton_orbits.integrators.wh_correctors import (
    CORRECTOR_ALPHA_SQUARED,
    CORRECTORS,
    corrector_coefficients,
    corrector_series,
)
from hamilton_orbits.rhs import run_parameters
from hamilton_orbits.validation import ConvergenceError

__all__ = [
    "ACCEPTS_VELOCITY_DEPENDENT",
    "COORDINATES",
    "CORRECTORS",
    "CORRECTOR_ALPHA_SQUARED",
    "NAME",
    "corrector_coefficients",
    "corrector_series",
    "default_step",
    "run",
    "start",
]

NAME = "wh"
#: Steps per compiled call: the driver returns to Python this often (Ctrl-C).
SLICE = 100_000
ACCEPTS_VELOCITY_DEPENDENT = False


def default_step(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, tol: float | None = None) -> float:
    """The step ``run`` takes when ``dt`` is not given.

    ``P_min / 20`` with ``P_min`` the shortest Kepler period of a bound body
    about the central one; with ``tol``, ``P_min min(1/20, sqrt(tol / eps))``
    where ``eps`` is the largest mass ratio to the central body, from the
    Wisdom-Holman energy error ``~ eps (dt / P)^2`` (Wisdom & Holman 1991).

    Examples
    --------
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    >>> v0 = np.array([[0.0, 0, 0], [0.0, 1, 0]])
    >>> round(default_step(r0, v0, np.array([1.0, 0.0])) * 20 / (2 * np.pi), 12)
    1.0
    """
    c = int(np.argmax(gm))
    mu = gm[c]
    rel_r = np.delete(r0 - r0[c], c, axis=0)
    rel_v = np.delete(v0 - v0[c], c, axis=0)
    others = np.delete(gm, c)
    d = np.linalg.norm(rel_r, axis=1)
    inv_a = 2.0 / d - np.sum(rel_v**2, axis=1) / (mu + others)
    bound = inv_a > 0.0
    if not np.any(bound):
        raise ValueError("wh needs `dt`: no body is bound to the central body")
    period = float(np.min(2.0 * np.pi / np.sqrt((mu + others[bound]) * inv_a[bound] ** 3)))
    frac = 1.0 / 20.0
    if tol is not None:
        eps = float(np.max(others / mu)) if others.size else 0.0
        if eps > 0.0:
            frac = min(frac, math.sqrt(tol / eps))
    return period * frac


def run(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_out: np.ndarray,
        **options: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """Integrate with the Wisdom-Holman map (democratic-heliocentric or Jacobi).

    Parameters
    ----------
    rhs : RHS
        The compiled right-hand side; its Newtonian part is split as above and
        ``rhs.extra`` (the listed effects) joins the kick.  Velocity-dependent
        effects raise ``ValueError``.
    r0, v0 : ndarray, shape (n, 3)
        Initial inertial positions and velocities (internal units).
    gm : ndarray, shape (n,)
        ``G m >= 0``; the body of largest GM is the central one.
    t_out : ndarray, shape (n_t,)
        Increasing output times; ``t_out[0]`` is the initial time.
    dt : float, optional
        The step; the last step before an output time is shortened to land on
        it.  Default: :func:`default_step`.
    tol : float, optional
        Used only without ``dt``, to choose it (see :func:`default_step`).
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i`` is reached.
    coordinates : {"democratic_heliocentric", "jacobi"}, optional
        The splitting: democratic-heliocentric (default; Duncan, Levison & Lee
        1998) or Jacobi (Wisdom & Holman 1991; the central body first, then the
        others in the order given, each on a Kepler orbit about the total mass
        inside it).  Both are WHFast's maps of the same names.
    corrector : {0, 3, 5, 7, 11, 17}, optional
        With Jacobi coordinates, the symplectic corrector of that order
        (Wisdom, Holman & Touma 1996; see the module's notes) before the steps
        of each output interval and its inverse after them (so outputs are in
        true coordinates); order ``p`` removes the error terms ``eps dt^2``
        ... ``eps dt^(p-1)``.  Each application costs about ``p - 1`` steps'
        work (``3 (p - 1)`` Kepler solves, ``2 (p - 1)`` kicks), twice per
        output interval.
    max_steps : int, optional
        A bound on the steps of the whole run; more are refused before the run
        starts (``ValueError``).
    events : EventLog, optional
        Events to look for in every drift, on its Kepler arcs: heliocentric
        (democratic heliocentric, with the jump that the steps apply around the
        kick spread over the drift, so that relative velocities and the centre
        of mass are the inertial ones) or Jacobi coordinates turned into
        inertial positions.  Escapes are measured from the centre of mass.
        Actions take effect at the end of the step the event occurred in.
    variational : Tangent, optional
        Tangent vectors to carry through the exact tangent map of every step
        (:class:`hamilton_orbits.integrators._tangent.Tangent`; ``rhs`` compiled
        with ``variational=True``): the Kepler drift's derivative and the kick's
        Jacobian, symplectic as the map.  The steps are then synchronised one by
        one (as WHFast's ``safe_mode``); not with ``events`` or ``corrector``.

    Returns
    -------
    r, v : ndarray, shape (n_t, n, 3)
        Inertial states at ``t_out`` (row 0 the initial state).
    steps : int
        Steps taken.

    Raises
    ------
    ValueError
        Bad input (naming the argument), a velocity-dependent effect, or no
        massive central body.
    ConvergenceError
        If a Kepler step fails (a body on a collision orbit with the centre).

    Examples
    --------
    Two planets on circular orbits; after 100 steps the energy is kept to
    about (dt / P)^2 times the planet-to-star mass ratio:

    >>> import numpy as np
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 2.0, 0]])
    >>> v0 = np.array([[0.0, 0, 0], [0.0, 1.0, 0], [-0.5**0.5, 0, 0]])
    >>> r, v, steps = run(newtonian_rhs(), r0, v0, np.array([1.0, 1e-3, 1e-3]),
    ...                   np.array([0.0, 10.0]), dt=0.1)
    >>> steps
    100
    """
    return _setup.run_once(start, WH, rhs, r0, v0, gm, t_out, **options)


def chosen_step(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, tol: float | None) -> float:
    """The step :func:`start` takes from ``r0``, ``v0``, ``gm`` without ``dt``
    (:func:`default_step`): a fixed step chosen once, at the start."""
    return default_step(r0, v0, gm, tol)


def start(rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float, method: WH, *,
          dt: float | None, tol: float | None, events: EventLog | None = None,
          variational: Any = None) -> Any:
    """The map's state at ``t0`` (a :class:`~hamilton_orbits.integrators.DriverState`),
    for arguments already checked (``method`` a :class:`WH`); it keeps the
    splitting's coordinates between calls, so that a run continued in legs takes
    the steps of one run and never goes through the inertial frame and back."""
    if rhs.velocity_dependent:
        raise ValueError(
            f"wh is a symplectic map and refuses velocity-dependent effects; listed: "
            f"{', '.join(rhs.effects)}.  Use method='radau15' (or 'dop853') for them"
        )
    check_run(method, dt, None, variational is not None)
    if r0.shape[0] == 0 or not gm[int(gm.argmax())] > 0.0:
        raise ValueError("wh needs a central body with `gm` > 0; "
                         + ("there are no bodies" if r0.shape[0] == 0 else "all `gm` are 0"))
    if dt is None:
        dt = chosen_step(r0, v0, gm, tol)
    if variational is not None:
        return _tangent.WHTangent(rhs, r0, v0, gm, t0, variational, dt=dt, jacobi=method.jacobi,
                                  max_steps=method.max_steps, slice_steps=SLICE)
    return _State(rhs, r0, v0, gm, t0, method, dt, events)


class _State:
    """The map's state between calls: the splitting (its coordinates and compiled
    steps), the events log and the masses (merges change them)."""

    #: not saved: where the interval a Ctrl-C or ``stop()`` cut began and the steps
    #: taken in it, so that the leg going on from there in this process lays its
    #: steps as the run never cut does (a loaded one lays them from its time)
    RESTART_SCRATCH = ("cut",)

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 method: WH, dt: float, events: EventLog | None) -> None:
        n = r0.shape[0]
        order = _central_first(gm)  # (row i of the coordinates is body order[i])
        extra = _setup.accel_arg(rhs.extra if rhs.extra is not None else _nbody.no_effects)
        self.gm = np.array(gm, dtype=np.float64)  # merges change it
        self.log = events if events is not None else EventLog.none(n)
        self.log.index_map = _index_map(order)
        self.split = _Split(self.gm, order, method.jacobi, method.corrector, extra,
                            run_parameters(rhs), rhs.extra is not None)  # (p: the kernels
        # write its clock)
        self.split.from_inertial(r0, v0, np.empty_like(r0), np.empty_like(v0))
        self.watch = self.log.kernel_watch()
        self.ws = np.array([t0, np.inf, 0.0, -1.0])  # the events' work space of the kernels
        # (see _drift; only ws[0], the clock, is used when no event is watched)
        self.dt, self.max_steps, self.t, self.steps = dt, method.max_steps, t0, 0
        self.cut: tuple[float, int] | None = None

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current inertial positions, velocities and ``G m`` (copies)."""
        r, v = np.empty_like(self.split.q), np.empty_like(self.split.u)
        self.split.to_inertial(r, v)
        return r, v, self.gm.copy()

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` at ``t_out[1:]`` (``t_out[0]`` the current
        time); an event that stops the run raises
        :class:`~hamilton_orbits.events.StopAtEvent` with its row."""
        times = t_out.tolist()  # (Python floats: the same numbers, cheaper arithmetic)
        span = times[-1] - times[0]
        if abs(span) > 0.5 * self.max_steps * self.dt:  # (only a leg near the limit can
            _setup.check_step_count(span, self.dt, self.max_steps, NAME)  # be refused)
        first = self.steps
        for i in range(1, len(times)):
            row = r_out[i], v_out[i]
            self._interval(i, times, row, stop, first)
            self.t = times[i]
            self.split.to_inertial(*row)
            if self.log.gone:  # (bodies taken out of the run: NaN in the outputs)
                self.log.mask(*row)
            if on_output is not None:
                on_output(i, self.steps - first)

    def _interval(self, i: int, times: list[float], row: tuple[np.ndarray, np.ndarray],
                  stop: Callable[[], bool] | None, first: int) -> None:
        """The steps from ``times[i - 1]`` to ``times[i]`` (the last shortened to land
        on it), events acted on at the end of their step (a merge or a removal
        renews the split).  An event that stops the run leaves its state in ``row``
        (output ``i``).  The steps go in slices of ``SLICE``: Ctrl-C and ``stop()``
        are seen between them."""
        dt, log, ws = self.dt, self.log, self.ws
        origin, done = _setup.interval_origin(self.cut, i, times, dt)
        self.cut = None
        n_steps, last = _setup.fixed_steps(times[i] - origin, dt)
        watched = self.watch.shape[0] > 0
        while done < n_steps:
            if done and stop is not None and stop():
                raise StopIntegration
            ws[0] = origin + done * dt
            if watched:  # (the events' part of the work space: see _drift)
                ws[1], ws[2], ws[3] = np.inf, 0.0, -1.0
            n_call = min(n_steps - done, SLICE)
            with HELD:  # (a Ctrl-C in the calls: raised once their steps are counted and
                steps, bad, status = self.split.advance(  # their event acted on)
                    dt, n_call, last if done + n_call == n_steps else dt, self.watch,
                    log.buffer, log.count, ws)
                done += steps
                self.steps += steps
                self.t = origin + done * dt
                self.cut = (origin, done) if done < n_steps else None
                stopped = None
                if bad < 0 and status == _k.STATUS_DRAIN:
                    log.drain()
                elif bad < 0 and status == _k.STATUS_EVENT:
                    stopped = self._act(i, row, ws, first)
            if bad >= 0:
                raise ConvergenceError(
                    f"wh: the Kepler step of body {int(self.split.order[bad])} failed between "
                    f"t_out[{i - 1}] = {times[i - 1]!r} and t_out[{i}] = {times[i]!r}")
            if stopped is not None:  # (raised out of HELD: a Ctrl-C held is raised first)
                raise stopped

    def _act(self, i: int, row: tuple[np.ndarray, np.ndarray], ws: np.ndarray,
             first: int) -> StopAtEvent | None:
        """The action of the event in ``ws`` at the end of its step: a stop leaves the
        state in ``row`` and returns the :class:`StopAtEvent` to raise; a merge or a
        removal renews the split from the changed inertial state."""
        r_now, v_now = np.empty_like(self.split.q), np.empty_like(self.split.u)
        self.split.to_inertial(r_now, v_now)
        changes = len(self.log.gm_changes)
        stop = self.log.act(int(ws[3]), float(ws[0]), r_now, v_now, self.gm, at=float(ws[1]))
        if len(self.log.gm_changes) > changes or not stop:  # (a merge or a removal of the
            self._renew(r_now, v_now)  # step, with a stop too: the next leg goes on from it)
        if stop:
            row[0][:], row[1][:] = r_now, v_now
            self.log.mask(row[0], row[1])
            self.t = float(ws[0])  # the end of the step (the split holds that state)
            self.cut = None  # (a stop ends the call: the next lays its steps afresh)
            return StopAtEvent(i, float(ws[0]), self.steps - first)
        return None

    def _renew(self, r_now: np.ndarray, v_now: np.ndarray) -> None:
        """The split made afresh from the inertial state ``r_now``, ``v_now`` after a
        merge or a removal changed the bodies (their ``gm``, the central body)."""
        order = self.split.order
        if self.gm[order[0]] < self.gm.max():  # (the central body merged into another,
            order = _central_first(self.gm)  # which keeps the lower index: the largest
            self.log.index_map = _index_map(order)  # GM is the centre)
        self.split = self.split.renewed(self.gm, order)
        self.split.from_inertial(r_now, v_now, self.split.q, self.split.u)
        self.watch = self.log.kernel_watch()


def _central_first(gm: np.ndarray) -> np.ndarray:
    """The bodies' order in the coordinates: the one of largest ``gm`` (the central
    body) first, the others as they are."""
    n, c = len(gm), int(np.argmax(gm))
    return np.arange(n) if c == 0 else np.concatenate([[c], np.delete(np.arange(n), c)])


def _index_map(order: np.ndarray) -> np.ndarray | None:
    """The events log's kernel-to-system body numbers for ``order`` (None: the same)."""
    return order if order[0] != 0 else None


class _Split:
    """The coordinates of one splitting (central body first: row ``i`` is body
    ``order[i]``), held in the arrays ``q``, ``u`` it is given, and its compiled
    steps."""

    #: not state: whether the few-body entries serve it, found on the first call
    RESTART_SCRATCH = ("few",)

    def __init__(self, gm: np.ndarray, order: np.ndarray, jacobi: bool, corrector: int,
                 extra: Any, p: np.ndarray, has_extra: bool) -> None:
        g = np.ascontiguousarray(gm[order])  # a writeable copy, the order of the rows
        order = np.ascontiguousarray(order, dtype=np.int64)
        self.gm, self.g, self.order, self.jacobi, self.corrector = gm, g, order, jacobi, corrector
        self.extra, self.p, self.has_extra = extra, p, has_extra
        self.q = self.u = np.empty((0, 3))
        self.few: bool | None = None
        if jacobi:
            self.eta = np.cumsum(g)
            self.ratio, self.inv_eta = _k.jacobi_factors(self.eta)
            if corrector:
                self.coef = corrector_coefficients(corrector)
        else:
            self.com = np.empty(6)

    def renewed(self, gm: np.ndarray, order: np.ndarray) -> _Split:
        """The same splitting for new ``gm`` (after a merge or a removal) and the
        bodies in ``order``, on the same arrays."""
        new = _Split(gm, order, self.jacobi, self.corrector, self.extra, self.p,
                     self.has_extra)
        new.q, new.u = self.q, self.u
        return new

    def from_inertial(self, r: np.ndarray, v: np.ndarray, q: np.ndarray, u: np.ndarray) -> None:
        """Into ``q``, ``u`` (kept as the state): Jacobi positions and velocities (row 0
        the barycentre), or heliocentric positions and barycentric velocities (the
        barycentre kept in ``com``)."""
        self.q, self.u = q, u
        if self.jacobi:
            _k.jacobi_from_inertial(r, v, self.g, self.eta, self.order, q, u)
        else:
            _k.dh_from_inertial(r, v, self.g, self.order, q, u, self.com)

    def advance(self, dt, n_steps, last, watch, ev_out, ev_count, ws) -> tuple[int, int, int]:
        """``n_steps`` steps (the last of length ``last``), in true coordinates at both
        ends (the corrector applied around them); ``(steps, bad body or -1, status)``."""
        # the kernels with the events' code and with the effects' are compiled apart,
        # each for the runs that need it
        watched = watch.shape[0] > 0
        ev = (watch, ev_out, ev_count, ws) if watched else (ws,)
        q, u = self.q, self.u
        # (a few bodies, all massive: the same bits from an entry that compiles less;
        # found once, a numpy test costing a tenth of a short call)
        if self.few is None:
            self.few = not self.has_extra and q.shape[0] - 1 < _k.LANES_FROM \
                and bool((self.g > 0.0).all())
        few = self.few and not watched
        if not self.jacobi:
            kernel = (_k.advance_dh_watched if watched else
                      _k.advance_dh_effects if self.has_extra else
                      _k.advance_dh_few if few else _k.advance_dh)
            return kernel(self.extra, self.p, self.has_extra, self.order, q, u, self.g,
                          self.com, dt, n_steps, last, *ev)
        args = (self.extra, self.p, self.has_extra, self.order, q, u, self.g, self.eta)
        advance = (_k.advance_jacobi_watched if watched else
                   _k.advance_jacobi_effects if self.has_extra else
                   _k.advance_jacobi_few if few else _k.advance_jacobi)
        if not self.corrector:
            return advance(*args, dt, n_steps, last, *ev)
        # the corrector conjugates a run of equal steps: a shortened last step gets
        # its own (C(dt) K(dt)^(n-1) C(dt)^-1, then C(h) K(h) C(h)^-1, as WHFast does
        # when its step changes)
        runs = ((dt, n_steps - 1), (last, 1)) if n_steps > 1 and last != dt else (
            (dt if n_steps > 1 else last, n_steps),)
        done, bad, status = 0, -1, _k.STATUS_OK
        t = float(ws[0])  # (the corrector's kicks at the time it is applied at: the clock)
        for h, k in runs:
            self.p[-1] = t
            bad = _k.corrector_jacobi(*args, h, 1.0, *self.coef)
            if bad < 0:
                steps, bad, status = advance(*args, h, k, h, *ev)
                done += steps
                t += steps * h
            if bad < 0:
                self.p[-1] = t
                bad = _k.corrector_jacobi(*args, h, -1.0, *self.coef)
            if bad >= 0 or status != _k.STATUS_OK:
                break
        return done, bad, status

    def to_inertial(self, r: np.ndarray, v: np.ndarray, q: np.ndarray | None = None,
                    u: np.ndarray | None = None) -> None:
        """Inertial positions and velocities into ``r``, ``v`` (the caller's order)
        from the coordinates ``q``, ``u`` (default the state); ``r is q`` (in place)
        when the central body is first."""
        q = self.q if q is None else q
        u = self.u if u is None else u
        if self.jacobi:
            if r is q:
                _k.jacobi_to_inertial_pos(q, self.g, self.eta, self.ratio, self.inv_eta, q)
                _k.jacobi_to_inertial_pos(u, self.g, self.eta, self.ratio, self.inv_eta, u)
            else:
                _k.jacobi_to_inertial(q, u, self.g, self.eta, self.ratio, self.inv_eta,
                                      self.order, r, v)
        else:
            _k.dh_to_inertial(q, u, self.g, self.com, self.order, r, v)
