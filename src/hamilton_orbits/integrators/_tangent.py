"""The variational equations in every integrator (``variational=True``).

:class:`Tangent` is what a run is asked for: one tangent vector for MEGNO and the
Lyapunov exponent (random, as rebound's ``init_megno`` draws it, or given), and,
with ``stm=True``, the ``6n`` columns of the state transition matrix (the
identity at the start); it holds the MEGNO state and receives the outputs.  The
drivers here carry the tangent vectors through each method, beside the state:

- ``radau15`` integrates the augmented system (bodies, then tangent vectors) with
  the same steps; the step size comes from the bodies alone unless
  ``tangent_control=True`` (:func:`hamilton_orbits._kernels.radau15.advance_variational`);
- ``wh`` and ``leapfrog`` apply the exact tangent map of each step (the Kepler
  drift's derivative, the kick's Jacobian: :mod:`hamilton_orbits._kernels.wh_tangent`,
  :func:`hamilton_orbits._kernels.variational.advance_leapfrog`), symplectic like
  the map itself;
- ``dop853`` integrates the augmented system, the MEGNO integral one more
  component, with the tangent components left out of the error control unless
  ``tangent_control=True``.

Tangent vectors are ``(dr, dv)`` arrays of shape (k n, 3), row ``m n + i`` body
``i`` of vector ``m``; vector 0 is MEGNO's, vectors ``1 + 6 i + c`` start as the
unit displacement of coordinate ``c`` (x, y, z, vx, vy, vz) of body ``i``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import radau15 as _radau
from hamilton_orbits._kernels import variational as _var
from hamilton_orbits._kernels import wh as _wh
from hamilton_orbits._kernels import wh_tangent as _wht
from hamilton_orbits.integrators import StopIntegration
from hamilton_orbits.integrators._held import HELD
from hamilton_orbits.integrators._setup import (
    accel_arg,
    addresses,
    check_finite,
    check_pace,
    check_step_count,
    fixed_steps,
)
from hamilton_orbits.integrators.methods import MAX_FIXED_STEPS, MAX_STEPS
from hamilton_orbits.rhs import run_parameters
from hamilton_orbits.validation import ConvergenceError

__all__ = ["DEFAULT_SEED", "SLICE", "DOP853Tangent", "LeapfrogTangent", "Radau15Tangent",
           "Tangent", "WHTangent", "megno_vector", "radau15_why"]

#: The seed of the random tangent vector of MEGNO when none is given.
DEFAULT_SEED = 2275
#: Steps per compiled call of the fixed-step tangent maps (as the plain drivers of
#: wh and leapfrog): ``stop()`` and Ctrl-C are seen between calls.
SLICE = 100_000


def megno_vector(n: int, seed: int = DEFAULT_SEED) -> np.ndarray:
    """MEGNO's default initial tangent vector of ``n`` bodies, (n, 6): as rebound's
    ``init_megno``, each body's six components drawn from a standard normal
    distribution (seed ``seed``) and scaled to unit length.

    Examples
    --------
    >>> bool(np.allclose(np.linalg.norm(megno_vector(3), axis=1), 1.0))
    True
    """
    vector = np.random.default_rng(seed).normal(size=(n, 6))
    return vector / np.linalg.norm(vector, axis=1, keepdims=True)


class Tangent:
    """The tangent vectors of one run and what is computed from them.

    Parameters
    ----------
    n : int
        Bodies.
    n_t : int
        Output times.
    stm : bool
        Also carry the ``6n`` columns of the state transition matrix.
    vector : ndarray, shape (n, 6), optional
        MEGNO's initial tangent vector (x, y, z, vx, vy, vz per body).  Default: as
        rebound's ``init_megno``, each body's six components drawn from a standard
        normal distribution and scaled to unit length (seed :data:`DEFAULT_SEED`).

    Attributes
    ----------
    megno, lyapunov : ndarray, shape (n_t,)
        MEGNO ``<Y>`` and the Lyapunov exponent at the outputs (0 at the start).
    lyapunov_time : ndarray, shape (n_t,)
        ``1 / lyapunov`` where the run so far spans at least that time
        (``lyapunov (t - t0) >= 1``), else ``inf``: no exponential growth measured
        (a non-positive exponent is the slope of a ``<Y>`` that has levelled off,
        not the inverse of a time; see :meth:`record`).
    stm : ndarray, shape (n_t, 6n, 6n) or None
        The state transition matrices at the outputs (never rescaled; MEGNO's
        vector is, inside the kernels, when it passes 1e100: see
        :func:`hamilton_orbits._kernels.variational.renormalise`).
    ms : ndarray
        The MEGNO state (:data:`hamilton_orbits._kernels.variational.MEGNO_FIELDS`).

    Examples
    --------
    >>> tan = Tangent(2, 3, stm=True)
    >>> tan.k, tan.dr0.shape, tan.stm[0].tolist() == np.eye(12).tolist()
    (13, (26, 3), True)
    >>> bool(np.allclose(np.linalg.norm(np.hstack([tan.dr0[:2], tan.dv0[:2]]), axis=1), 1))
    True
    """

    def __init__(self, n: int, n_t: int, *, stm: bool = False, vector: Any = None,
                 seed: int = DEFAULT_SEED) -> None:
        if vector is None:
            vector = megno_vector(n, seed)
        vector = np.asarray(vector, dtype=np.float64).reshape(n, 6)
        self.n = n
        self.k = 1 + (6 * n if stm else 0)
        self.dr0 = np.zeros((self.k * n, 3))
        self.dv0 = np.zeros((self.k * n, 3))
        self.dr0[:n] = vector[:, :3]
        self.dv0[:n] = vector[:, 3:]
        for j in range(6 * n if stm else 0):
            i, c = divmod(j, 6)
            (self.dr0 if c < 3 else self.dv0)[(1 + j) * n + i, c % 3] = 1.0
        self.ms = np.zeros(len(_var.MEGNO_FIELDS))
        #: MEGNO, the Lyapunov exponent and the STM at the last output recorded (the
        #: first row of the next leg's outputs)
        self.last: tuple[float, float, float, np.ndarray | None] = (
            0.0, 0.0, math.inf, np.eye(6 * n) if stm else None)
        self.new_leg(n_t)

    def new_leg(self, n_t: int) -> None:
        """Fresh output arrays for a leg of ``n_t`` outputs, row 0 the last recorded."""
        megno, lyapunov, lyapunov_time, stm = self.last
        self.megno = np.zeros(n_t)
        self.lyapunov = np.zeros(n_t)
        self.lyapunov_time = np.full(n_t, math.inf)
        self.megno[0], self.lyapunov[0], self.lyapunov_time[0] = megno, lyapunov, lyapunov_time
        self.stm = None
        if stm is not None:
            self.stm = np.zeros((n_t,) + stm.shape)
            self.stm[0] = stm

    def start(self, t0: float) -> None:
        """Start MEGNO at ``t0`` (``<Y> = 0`` there)."""
        self.ms[:] = 0.0
        self.ms[0] = t0
        self.ms[8] = _var.log_norm(self.dr0, self.dv0, self.n, 0)

    def record(self, i: int, t: float, dr: np.ndarray, dv: np.ndarray) -> None:
        """Output ``i`` at time ``t``: ``<Y> = Yss / (t - t0)``, the Lyapunov
        exponent ``cov(t, <Y>) / var(t)`` from the MEGNO state (rebound's
        ``sim.lyapunov()``), the Lyapunov time, and the STM's columns from tangent
        vectors 1 ... 6n.

        The exponent is the least-squares slope of ``<Y>(t)``: on a chaotic orbit
        ``<Y>`` grows like ``lambda t`` and the slope measures it; on a regular one
        ``<Y>`` levels off at 2 (0 if periodic) and the slope falls to zero from
        either side, as ``<Y>`` settles (negative while it comes down to its
        plateau: -1e-5 per year for a Saturn-mass planet at 8 au over 1000 orbits
        of Jupiter).  Its inverse is then not a time: the Lyapunov time is
        ``1 / lyapunov`` only where the run has lasted that long
        (``lyapunov (t - t0) >= 1``), ``inf`` (none measured) otherwise."""
        ms = self.ms
        s = t - ms[0]
        self.megno[i] = ms[2] / s if s > 0 else 0.0
        lam = ms[6] / ms[7] if ms[7] > 0 else 0.0
        self.lyapunov[i] = lam
        self.lyapunov_time[i] = 1.0 / lam if lam * s >= 1.0 else math.inf
        if self.stm is not None:
            n = self.n
            cols = np.concatenate([dr[n:].reshape(6 * n, n, 3), dv[n:].reshape(6 * n, n, 3)],
                                  axis=2)
            self.stm[i] = cols.reshape(6 * n, 6 * n).T
        self.last = (self.megno[i], self.lyapunov[i], self.lyapunov_time[i],
                     None if self.stm is None else self.stm[i])


class Radau15Tangent:
    """``radau15`` with the tangent vectors (:func:`hamilton_orbits._kernels.radau15.
    advance_variational`): the augmented state (bodies, then tangent vectors)
    between calls; the arguments as the driver has checked them, ``control`` True
    to let the tangent vectors take part in the step control; ``stop()`` asked
    between slices of ``slice_steps`` steps (True raises :class:`StopIntegration`)."""

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 tangent: Tangent, *, dt: float, tol: float, prs23: bool, max_steps: int,
                 slice_steps: int, control: bool) -> None:
        self.n = n = r0.shape[0]
        self.rhs, self.tangent, self.max_steps, self.slice = rhs, tangent, max_steps, slice_steps
        self.p = run_parameters(rhs)  # (the kernels write its clock)
        self.gm = np.array(gm, dtype=np.float64)  # writable (the kernels take no read-only)
        self.x = np.ascontiguousarray(np.vstack([r0, tangent.dr0]))
        self.w = np.ascontiguousarray(np.vstack([v0, tangent.dv0]))
        m = 3 * self.x.shape[0]
        self.work = [np.zeros((7, m)) for _ in range(4)]  # b, br, d, g
        self.csx, self.csv = np.zeros(m), np.zeros(m)
        self.st = np.zeros(_radau.NSTATE)
        self.st[[_radau.ST_T, _radau.ST_DT, _radau.ST_EPSILON, _radau.ST_PRS23]] = (
            t0, dt, tol, float(prs23))
        self.accel = accel_arg(rhs.augmented)
        self.n_phys = self.x.shape[0] if control else n
        tangent.start(t0)
        self.steps = 0

    @property
    def t(self) -> float:
        """The time of the state."""
        return float(self.st[_radau.ST_T])

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The bodies' positions, velocities and ``G m`` (copies)."""
        n = self.n
        return self.x[:n].copy(), self.w[:n].copy(), self.gm.copy()

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` (and the tangent's outputs) at ``t_out[1:]``."""
        n, x, w, st, first = self.n, self.x, self.w, self.st, self.steps
        for i in range(1, t_out.shape[0]):
            while True:
                left = self.max_steps - (self.steps - first)
                with HELD:  # (a Ctrl-C in the call: raised once its steps are counted)
                    steps, status = _radau.advance_variational(
                        self.accel, self.p, x, w, self.gm, t_out[i], st, *self.work, self.csx,
                        self.csv, bool(self.rhs.velocity_dependent), min(self.slice, left),
                        self.n_phys, self.tangent.ms)
                    self.steps += steps
                if status == _radau.STATUS_OK:
                    break
                if status != _radau.STATUS_MAXSTEPS:
                    raise ConvergenceError(
                        f"radau15 (variational) stopped at t = {self.t!r} before t_out[{i}] "
                        f"= {float(t_out[i])!r}: {radau15_why(status, st, self.max_steps)}")
                # (a slice's end or max_steps: the budget and the pace judged as the
                # plain run's, in its words)
                check_pace(self.steps - first, self.max_steps, self.t, t_out, "radau15")
                if stop is not None and stop():
                    raise StopIntegration
            r_out[i], v_out[i] = x[:n], w[:n]
            self.tangent.record(i, float(t_out[i]), x[n:], w[n:])
            if on_output is not None:
                on_output(i, self.steps - first)


def radau15_why(status: int, st: np.ndarray, max_steps: int) -> str:
    """Why radau15's kernel (plain or variational) stopped with ``status``, its state
    ``st``, short of its output time: the words of the ConvergenceError.

    Examples
    --------
    >>> radau15_why(_radau.STATUS_NONFINITE, np.zeros(_radau.NSTATE), 10)
    'the acceleration became non-finite (a collision?)'
    """
    return {
        _radau.STATUS_NONFINITE: "the acceleration became non-finite (a collision?)",
        _radau.STATUS_UNDERFLOW: f"the step underflowed (dt = {float(st[_radau.ST_DT])!r}; a "
                                 "collision, or an encounter closer than float64 resolves at "
                                 "this time?)",
        _radau.STATUS_MAXSTEPS: f"more than max_steps = {max_steps} steps were needed",
    }.get(status, f"status {status}")


def _tangent_arg(fn: Any) -> np.ndarray:
    """The addresses of a tangent right-hand side for a stepping kernel (as
    :func:`_setup.accel_arg`)."""
    from hamilton_orbits._kernels.jacobians import TANGENT_SIGNATURE

    return addresses(fn, TANGENT_SIGNATURE)


def _to_split(r: np.ndarray, v: np.ndarray, g: np.ndarray, jacobi: bool
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jacobi coordinates (row 0 the barycentre), or heliocentric positions,
    barycentric velocities and the barycentre (6,), of states ``(..., n, 3)`` with
    the central body first; linear, so tangent vectors transform alike."""
    m_tot = g.sum()
    s_r = np.cumsum(g[:, None] * r, axis=-2)
    s_v = np.cumsum(g[:, None] * v, axis=-2)
    if jacobi:
        eta = np.cumsum(g)
        q, u = np.empty_like(r), np.empty_like(v)
        q[..., 0, :], u[..., 0, :] = s_r[..., -1, :] / m_tot, s_v[..., -1, :] / m_tot
        q[..., 1:, :] = r[..., 1:, :] - s_r[..., :-1, :] / eta[:-1, None]
        u[..., 1:, :] = v[..., 1:, :] - s_v[..., :-1, :] / eta[:-1, None]
        return q, u, np.zeros(r.shape[:-2] + (6,))
    com = np.concatenate([s_r[..., -1, :], s_v[..., -1, :]], axis=-1) / m_tot
    return r - r[..., :1, :], v - com[..., None, 3:], com


def _from_split(q: np.ndarray, u: np.ndarray, com: np.ndarray, g: np.ndarray, jacobi: bool
                ) -> tuple[np.ndarray, np.ndarray]:
    """The inverse of :func:`_to_split` (inertial states, central body first)."""
    if jacobi:
        eta = np.cumsum(g)
        ratio, inv = _wh.jacobi_factors(eta)
        rr, vv = np.empty_like(q), np.empty_like(u)
        for src, dst in ((q, rr), (u, vv)):
            for blk in range(src.shape[0] if src.ndim == 3 else 1):
                a = src[blk] if src.ndim == 3 else src
                b = dst[blk] if dst.ndim == 3 else dst
                _wh.jacobi_to_inertial_pos(np.ascontiguousarray(a), g, eta, ratio, inv, b)
        return rr, vv
    m_tot = g.sum()
    r0 = com[..., :3] - np.einsum("i,...ic->...c", g[1:], q[..., 1:, :]) / m_tot
    v0 = com[..., 3:] - np.einsum("i,...ic->...c", g[1:], u[..., 1:, :]) / g[0]
    rr = q + r0[..., None, :]
    rr[..., 0, :] = r0
    vv = u + com[..., None, 3:]
    vv[..., 0, :] = v0
    return rr, vv




class LeapfrogTangent:
    """``leapfrog`` with the exact tangent map of each step
    (:func:`hamilton_orbits._kernels.variational.advance_leapfrog`), in slices of
    ``slice_steps`` steps as the plain driver (``stop()`` asked between them)."""

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 tangent: Tangent, *, dt: float, max_steps: int = MAX_FIXED_STEPS,
                 slice_steps: int = SLICE) -> None:
        self.max_steps = max_steps
        self.r = np.ascontiguousarray(r0, dtype=np.float64).copy()
        self.v = np.ascontiguousarray(v0, dtype=np.float64).copy()
        self.gm = np.array(gm, dtype=np.float64)  # writable (the kernel takes no read-only)
        self.dr, self.dv = tangent.dr0.copy(), tangent.dv0.copy()
        self.accel, self.jac = accel_arg(rhs.accel), _tangent_arg(rhs.tangent)
        self.rhs, self.tangent, self.dt, self.slice = rhs, tangent, dt, slice_steps
        self.p = run_parameters(rhs)  # (the kernels write its clock)
        tangent.start(t0)
        self.t, self.steps = t0, 0

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current positions, velocities and ``G m`` (copies)."""
        return self.r.copy(), self.v.copy(), self.gm.copy()

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` (and the tangent's outputs) at ``t_out[1:]``."""
        dt, first = self.dt, self.steps
        check_step_count(float(t_out[-1] - t_out[0]), dt, self.max_steps, "leapfrog")
        for i in range(1, t_out.shape[0]):
            t, t1 = float(t_out[i - 1]), float(t_out[i])
            while True:  # the steps and times of the plain kernel's slices
                n_left = max(1, math.ceil((t1 - t) / dt - 1e-12))
                with HELD:  # (a Ctrl-C in the call: raised once its steps are counted)
                    done = _var.advance_leapfrog(self.accel, self.jac, self.p, self.r, self.v,
                                                 self.gm, self.dr, self.dv, t, t1, dt,
                                                 self.tangent.ms, self.slice)
                    self.steps += done
                    finished = done >= n_left
                    if not finished:
                        t = t + done * ((t1 - t) / n_left)
                    self.t = t1 if finished else t
                if finished:
                    break
                if stop is not None and stop():
                    raise StopIntegration
            self.t = t1
            r_out[i], v_out[i] = self.r, self.v
            self.tangent.record(i, t1, self.dr, self.dv)
            if on_output is not None:
                on_output(i, self.steps - first)


class WHTangent:
    """``wh`` (synchronised steps, :mod:`hamilton_orbits._kernels.wh_tangent`) with the
    exact tangent map; the central body (largest GM) first inside; in slices of
    ``slice_steps`` steps as the plain driver (``stop()`` asked between them).  The
    state stays in the splitting's coordinates between calls."""

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 tangent: Tangent, *, dt: float, jacobi: bool, max_steps: int = MAX_FIXED_STEPS,
                 slice_steps: int = SLICE) -> None:
        self.max_steps = max_steps
        n, k = r0.shape[0], tangent.k
        c = int(np.argmax(gm))
        self.order = order = np.concatenate([[c], np.delete(np.arange(n), c)]).astype(np.int64)
        self.inv_order = np.argsort(order)
        self.g = g = np.ascontiguousarray(gm[order])
        self.q, self.u, self.com = (np.ascontiguousarray(a)
                                    for a in _to_split(r0[order], v0[order], g, jacobi))
        dq, du, self.dcom = (np.ascontiguousarray(a) for a in _to_split(
            tangent.dr0.reshape(k, n, 3)[:, order], tangent.dv0.reshape(k, n, 3)[:, order], g,
            jacobi))
        self.dq, self.du = dq.reshape(k * n, 3), du.reshape(k * n, 3)
        self.has_extra = has_extra = rhs.extra is not None
        self.extra = accel_arg(rhs.extra if has_extra else rhs.accel)
        if jacobi:
            self.eta = np.cumsum(g)
            self.jac = _tangent_arg(rhs.tangent)
        else:
            self.g_p = g.copy()
            self.g_p[0] = 0.0
            self.jac = _tangent_arg(rhs.tangent_extra if has_extra else rhs.tangent)
        self.rhs, self.tangent, self.dt, self.jacobi, self.slice = (rhs, tangent, dt, jacobi,
                                                                     slice_steps)
        self.p = run_parameters(rhs)  # (the kernels write its clock)
        tangent.start(t0)
        self.t, self.steps = t0, 0

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current inertial positions, velocities and ``G m``, in the caller's order."""
        rr, vv = _from_split(self.q, self.u, self.com, self.g, self.jacobi)
        return rr[self.inv_order], vv[self.inv_order], self.g[self.inv_order]

    def _steps(self, n_call: int, h_last: float, t_call: float) -> tuple[int, int]:
        if self.jacobi:
            return _wht.advance_jacobi(self.extra, self.jac, self.p, self.has_extra,
                                       self.order, self.q, self.u, self.g, self.eta, self.dq,
                                       self.du, self.dt, n_call, h_last, t_call, self.tangent.ms)
        return _wht.advance_dh(self.extra, self.jac, self.p, self.has_extra, self.order,
                               self.q, self.u, self.g, self.g_p, self.com, self.dq, self.du,
                               self.dcom, self.dt, n_call, h_last, t_call, self.tangent.ms)

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` (and the tangent's outputs) at ``t_out[1:]``."""
        dt, first, k, n = self.dt, self.steps, self.tangent.k, self.g.shape[0]
        check_step_count(float(t_out[-1] - t_out[0]), dt, self.max_steps, "wh")
        for i in range(1, t_out.shape[0]):
            n_steps, last = fixed_steps(t_out[i] - t_out[i - 1], dt)
            done = 0
            while done < n_steps:
                if done and stop is not None and stop():
                    raise StopIntegration
                n_call = min(n_steps - done, self.slice)  # stop() is asked between calls
                h_last = last if done + n_call == n_steps else dt
                with HELD:  # (a Ctrl-C in the call: raised once its steps are counted)
                    steps, bad = self._steps(n_call, h_last, float(t_out[i - 1] + done * dt))
                    done += steps
                    self.steps += steps
                    self.t = float(t_out[i - 1] + done * dt)
                if bad >= 0:
                    raise ConvergenceError(
                        f"wh: the Kepler step of body {int(self.order[bad])} failed between "
                        f"t_out[{i - 1}] = {float(t_out[i - 1])!r} and t_out[{i}] = "
                        f"{float(t_out[i])!r}")
            self.t = float(t_out[i])
            r_out[i], v_out[i], _ = self.state()
            drr, dvv = _from_split(self.dq.reshape(k, n, 3), self.du.reshape(k, n, 3),
                                   self.dcom, self.g, self.jacobi)
            dr_in = np.ascontiguousarray(drr[:, self.inv_order].reshape(k * n, 3))
            dv_in = np.ascontiguousarray(dvv[:, self.inv_order].reshape(k * n, 3))
            self.tangent.record(i, self.t, dr_in, dv_in)
            if on_output is not None:
                on_output(i, self.steps - first)


class DOP853Tangent:
    """``dop853`` on the augmented system ``(r, dr, v, dv, Ys)``: the bodies, the
    tangent vectors (:attr:`RHS.augmented`) and MEGNO's integral
    ``Ys' = 2 (t - t0) delta'.delta / |delta|^2``, step by step (scipy's stepper),
    MEGNO's averages and regression updated after every step as rebound does.
    MEGNO's vector is not rescaled here (a chaotic run long enough to take it
    past 1e308 overflows: use radau15 or wh for those).
    ``atol``: the bodies' absolute tolerances (6n,); the tangent components and
    ``Ys`` are left out of the error control (infinite ``atol``) unless ``control``."""

    def __init__(self, rhs: Any, r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t0: float,
                 tangent: Tangent, *, tol: float, atol: np.ndarray, max_step: float,
                 control: bool, max_steps: int = MAX_STEPS) -> None:
        n, k = r0.shape[0], tangent.k
        self.rows = rows = n * (1 + k)
        self.n, self.gm, self.tangent, self.tol, self.max_step = (
            n, np.array(gm, dtype=np.float64), tangent, tol, max_step)
        self.max_steps = max_steps
        self.rhs, self.t0, self.acc = rhs, t0, np.empty((rows, 3))
        self.p = run_parameters(rhs)  # (its clock set at each evaluation)
        self.y = np.concatenate((r0.ravel(), tangent.dr0.ravel(), v0.ravel(),
                                 tangent.dv0.ravel(), [0.0]))
        scale_t = np.full(6 * n * k, np.inf)
        if control:
            scale_t = tol * np.maximum(np.abs(np.concatenate((tangent.dr0.ravel(),
                                                              tangent.dv0.ravel()))), 1.0)
        self.atol = np.concatenate((atol[: 3 * n], scale_t[: 3 * n * k], atol[3 * n:],
                                    scale_t[3 * n * k:], [np.inf]))
        tangent.start(t0)
        self.t, self.steps = t0, 0

    def f(self, t: float, y: np.ndarray) -> np.ndarray:
        """``dy/dt`` of the augmented system (a method, not a closure: a copy of the
        state computes with its own arrays)."""
        n, rows, acc, rhs = self.n, self.rows, self.acc, self.rhs
        x = y[: 3 * rows].reshape(rows, 3)
        w = y[3 * rows: 6 * rows].reshape(rows, 3)
        p = self.p
        p[-1] = t  # (the clock)
        rhs.augmented(x, w, self.gm, acc, p)
        check_finite(acc, t, "dop853")
        dx, dw, da = x[n:2 * n], w[n:2 * n], acc[n:2 * n]
        den = float(np.sum(dx * dx) + np.sum(dw * dw))
        rate = float(np.sum(dx * dw) + np.sum(dw * da)) / den if den > 0 else 0.0
        return np.concatenate((y[3 * rows: 6 * rows], acc.ravel(),
                               [2.0 * (t - self.t0) * rate]))

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current positions, velocities and ``G m`` (copies)."""
        n, rows = self.n, self.rows
        return (self.y[: 3 * n].reshape(n, 3).copy(),
                self.y[3 * rows: 3 * rows + 3 * n].reshape(n, 3).copy(), self.gm.copy())

    def advance(self, t_out: np.ndarray, r_out: np.ndarray, v_out: np.ndarray,
                on_output: Callable[[int, int], None] | None,
                stop: Callable[[], bool] | None) -> None:
        """Rows 1... of ``r_out``, ``v_out`` (and the tangent's outputs) at ``t_out[1:]``;
        ``stop`` is asked at the outputs (by the engine)."""
        from scipy.integrate import DOP853

        n, rows, first = self.n, self.rows, self.steps
        for i in range(1, t_out.shape[0]):
            solver = DOP853(self.f, float(t_out[i - 1]), self.y, float(t_out[i]), rtol=self.tol,
                            atol=self.atol, max_step=self.max_step)
            while solver.status == "running":
                if self.steps - first >= self.max_steps:  # (exact: no step beyond it)
                    check_pace(self.steps - first, self.max_steps, solver.t, t_out, "dop853")
                t_prev, ys_prev = solver.t, solver.y[-1]
                with HELD:  # (a Ctrl-C in the step: raised once it is the state kept)
                    if solver.step() is not None:
                        raise ConvergenceError(f"dop853 (variational) failed at t = {t_prev}")
                    self.steps += 1
                    _var.megno_update(self.tangent.ms, float(solver.y[-1] - ys_prev),
                                      float(solver.t), float(solver.t - t_prev))
                    self.y, self.t = solver.y, float(solver.t)  # (scipy makes a new y a step)
                if (self.steps - first) % 100 == 0:
                    check_pace(self.steps - first, self.max_steps, solver.t, t_out, "dop853")
            self.y = solver.y.copy()
            self.t = float(t_out[i])
            x = self.y[: 3 * rows].reshape(rows, 3)
            w = self.y[3 * rows: 6 * rows].reshape(rows, 3)
            r_out[i], v_out[i] = x[:n], w[:n]
            self.tangent.record(i, self.t, x[n:], w[n:])
            if on_output is not None:
                on_output(i, self.steps - first)
