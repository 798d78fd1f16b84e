"""Wisdom-Holman map in democratic-heliocentric (default) or Jacobi coordinates.

Wisdom & Holman (1991), AJ 102, 1528, in the democratic-heliocentric form of
Duncan, Levison & Lee (1998), AJ 116, 2067, section 3: with heliocentric
positions ``Q_i = r_i - r_0`` and barycentric velocities ``u_i`` of the bodies
``i >= 1`` (the central body is the one of largest GM), the Hamiltonian splits
into

- the Kepler part, each body on a Kepler orbit about ``G M_0`` (advanced
  exactly by the universal-variable kernel
  :func:`hamilton_orbits._kernels.kepler.propagate_uv`, shared, not copied:
  the drift loop inlines its body, ``propagate_uv_inline``);
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
With Jacobi coordinates the third-order symplectic corrector of Wisdom,
Holman & Touma (1996) is available (``corrector=3``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._kernels import wh as _k
from hamilton_orbits._validation import ConvergenceError
from hamilton_orbits.events import EventLog, StopAtEvent
from hamilton_orbits.integrators import StopIntegration, _setup, _tangent, output_arrays

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "COORDINATES", "NAME", "default_step", "run"]

NAME = "wh"
#: Steps per compiled call: the driver returns to Python this often (Ctrl-C).
SLICE = 100_000
ACCEPTS_VELOCITY_DEPENDENT = False
COORDINATES = ("democratic_heliocentric", "jacobi")

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
    coordinates: str = "democratic_heliocentric",
    corrector: int = 0,
    max_steps: int = _setup.MAX_FIXED_STEPS,
    events: EventLog | None = None,
    variational: Any = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[np.ndarray, np.ndarray, int]:
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
    corrector : {0, 3}, optional
        With Jacobi coordinates, 3 applies the third-order symplectic corrector
        of Wisdom, Holman & Touma (1996) before the steps of each output
        interval and its inverse after them (so outputs are in true
        coordinates); it removes the leading O(eps dt^2) error term.
    max_steps : int, optional
        A bound on the steps of the whole run; more are refused before the run
        starts (``ValueError``).
    events : EventLog, optional
        Events to look for in every drift: on the Kepler arcs themselves
        (democratic heliocentric; escapes measured from the central body) or on
        the Hermite interpolant of the inertial states (Jacobi).  Actions take
        effect at the end of the step the event occurred in.
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
    r0, v0, gm, t_out = _setup.check_inputs(r0, v0, gm, t_out)
    dt_f, tol_f = _check_options(rhs, dt, tol, coordinates, corrector, variational is not None)
    c = int(np.argmax(gm))
    if not gm[c] > 0.0:
        raise ValueError("wh needs a central body with `gm` > 0; all `gm` are 0")
    if dt_f is None:
        dt_f = default_step(r0, v0, gm, tol_f)
    _setup.check_step_count(float(t_out[-1] - t_out[0]), dt_f, max_steps, NAME)
    if variational is not None:
        return _tangent.run_wh(rhs, r0, v0, gm, t_out, variational, dt=dt_f,
                               jacobi=coordinates == "jacobi", on_output=on_output, out=out,
                               stop=stop)
    n = r0.shape[0]
    order = np.concatenate([[c], np.delete(np.arange(n), c)])  # the central body first
    extra = _setup.accel_arg(rhs.extra if rhs.extra is not None else _nbody.no_effects)
    gm = gm.copy()
    log = events if events is not None else EventLog.none(n)
    log.index_map = order
    split = _Split(np.ascontiguousarray(gm[order]), coordinates == "jacobi", corrector, extra,
                   rhs.p, rhs.extra is not None)
    q, u = split.to_coordinates(r0[order], v0[order])
    nt = t_out.shape[0]
    r_out, v_out = output_arrays(out, nt, r0, v0)
    total = 0
    inv = np.argsort(order)
    for i in range(1, nt):
        span = t_out[i] - t_out[i - 1]
        n_steps = max(1, math.ceil(span / dt_f * (1.0 - 1e-12)))
        last = span - (n_steps - 1) * dt_f
        done = 0
        while done < n_steps:
            if done and stop is not None and stop():
                raise StopIntegration
            ws = np.array([t_out[i - 1] + done * dt_f, np.inf, 0.0, -1.0])
            n_call = min(n_steps - done, SLICE)  # Ctrl-C and stop() are seen between calls
            steps, bad, status = split.advance(
                q, u, dt_f, n_call, last if done + n_call == n_steps else dt_f,
                log.kernel_watch(), log.buffer, log.count, ws)
            done += steps
            total += steps
            if bad >= 0:
                raise ConvergenceError(
                    f"wh: the Kepler step of body {int(order[bad])} failed between "
                    f"t_out[{i - 1}] = {float(t_out[i - 1])!r} and t_out[{i}] = "
                    f"{float(t_out[i])!r}")
            if status == _k.STATUS_DRAIN:
                log.drain()
            elif status == _k.STATUS_EVENT:
                rr, vv = split.to_inertial(q, u)
                r_now, v_now = rr[inv], vv[inv]
                if log.act(int(ws[3]), float(ws[0]), r_now, v_now, gm):
                    r_out[i], v_out[i] = _masked(r_now, v_now, log)
                    raise StopAtEvent(i, float(ws[0]), total)
                split = _Split(np.ascontiguousarray(gm[order]), split.jacobi, corrector, extra,
                               rhs.p, rhs.extra is not None)
                q, u = split.to_coordinates(r_now[order], v_now[order])
        rr, vv = split.to_inertial(q, u)
        r_out[i], v_out[i] = _masked(rr[inv], vv[inv], log)
        if on_output is not None:
            on_output(i, total)
    return r_out, v_out, total


def _masked(r: np.ndarray, v: np.ndarray, log: EventLog) -> tuple[np.ndarray, np.ndarray]:
    """The state with the bodies taken out of the run as NaN."""
    r = r.copy()
    v = v.copy()
    r[log.inactive] = np.nan
    v[log.inactive] = np.nan
    return r, v


def _check_options(rhs: Any, dt: Any, tol: Any, coordinates: str, corrector: int,
                   variational: bool = False):
    if rhs.velocity_dependent:
        raise ValueError(
            f"wh is a symplectic map and refuses velocity-dependent effects; listed: "
            f"{', '.join(rhs.effects)}.  Use method='radau15' (or 'dop853') for them"
        )
    dt_f, tol_f = _setup.check_dt_tol(dt, tol)
    if coordinates not in COORDINATES:
        raise ValueError(
            f"Expected `coordinates` to be one of {', '.join(map(repr, COORDINATES))}, "
            f"got {coordinates!r}"
        )
    if corrector not in (0, 3):
        raise ValueError(f"Expected `corrector` to be 0 or 3, got {corrector!r}")
    if corrector and coordinates != "jacobi":
        raise ValueError(
            f"Expected coordinates='jacobi' with `corrector` = {corrector}, got {coordinates!r} "
            "(the corrector is defined for the Jacobi splitting)"
        )
    if corrector and variational:
        raise ValueError("wh with variational=True takes no `corrector` (its tangent map "
                         "is not implemented); use corrector=0")
    return dt_f, tol_f


class _Split:
    """The coordinates of one splitting (central body first) and its compiled steps."""

    def __init__(self, g: np.ndarray, jacobi: bool, corrector: int, extra: Any, p: np.ndarray,
                 has_extra: bool) -> None:
        self.g, self.jacobi, self.corrector = g, jacobi, corrector
        self.extra, self.p, self.has_extra = extra, p, has_extra
        self.m_tot = g.sum()
        if jacobi:
            self.eta = np.cumsum(g)
            self.ratio, self.inv_eta = _k.jacobi_factors(self.eta)
        else:
            self.g_p = g.copy()
            self.g_p[0] = 0.0

    def to_coordinates(self, r: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Jacobi positions and velocities (row 0 the barycentre), or heliocentric
        positions and barycentric velocities (the barycentre kept in ``com``)."""
        g = self.g
        if self.jacobi:
            eta = self.eta
            s_r = np.cumsum(g[:, None] * r, axis=0)
            s_v = np.cumsum(g[:, None] * v, axis=0)
            q = np.empty_like(r)
            u = np.empty_like(v)
            q[0] = s_r[-1] / eta[-1]
            u[0] = s_v[-1] / eta[-1]
            q[1:] = r[1:] - s_r[:-1] / eta[:-1, None]
            u[1:] = v[1:] - s_v[:-1] / eta[:-1, None]
            return q, u
        self.com = np.concatenate([(g @ r) / self.m_tot, (g @ v) / self.m_tot])
        return np.ascontiguousarray(r - r[0]), np.ascontiguousarray(v - self.com[3:])

    def advance(self, q, u, dt, n_steps, last, watch, ev_out, ev_count, ws
                ) -> tuple[int, int, int]:
        """``n_steps`` steps (the last of length ``last``), in true coordinates at both
        ends (the corrector applied around them); ``(steps, bad body or -1, status)``."""
        ev = (watch, ev_out, ev_count, ws)
        if not self.jacobi:
            return _k.advance_dh(self.extra, self.p, self.has_extra, q, u, self.g, self.g_p,
                                 self.com, dt, n_steps, last, *ev)
        args = (self.extra, self.p, self.has_extra, q, u, self.g, self.eta)
        bad = _k.corrector_jacobi(*args, dt, 1.0) if self.corrector else -1
        steps, status = 0, _k.STATUS_OK
        if bad < 0:
            steps, bad, status = _k.advance_jacobi(*args, dt, n_steps, last, *ev)
        if bad < 0 and self.corrector:
            bad = _k.corrector_jacobi(*args, dt, -1.0)
        return steps, bad, status

    def to_inertial(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Inertial positions and velocities (central body first)."""
        g = self.g
        if self.jacobi:
            rr = np.empty_like(q)
            vv = np.empty_like(u)
            _k.jacobi_to_inertial_pos(q, g, self.eta, self.ratio, self.inv_eta, rr)
            _k.jacobi_to_inertial_pos(u, g, self.eta, self.ratio, self.inv_eta, vv)
            return rr, vv
        com = self.com
        r0_in = com[:3] - (g[1:] @ q[1:]) / self.m_tot
        v0_in = com[3:] - (g[1:] @ u[1:]) / g[0]
        rr = q + r0_in
        rr[0] = r0_in
        vv = u + com[3:]
        vv[0] = v0_in
        return rr, vv
