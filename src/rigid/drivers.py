"""The float-level drivers of the rigid-body integrators: each method's run on plain arrays.

:func:`integrate_arrays` is :func:`rigid.integrate` below validation and units: moments,
attitude and angular velocity as float64 arrays in one unit system, output times, a
method (see :mod:`rigid.integrators`).  The fixed-step methods run their time loop
in compiled functions of :mod:`rigid._kernels.euler` (the splittings with the
composition of :func:`rigid.splitting.split_ops`, the exact flow plus kicks, RK4 with
quaternion or Cayley kinematics), called on chunks of at most 65 536 steps (a Ctrl-C
is seen between two: within milliseconds) and of about 1% of the run when a progress
bar is shown or ``stop`` asked, the same steps and bits as one call; DOP853
is the driver of :func:`hamilton_orbits.integrators.dop853.solve` (whose steps a
``Simulation``'s dop853 takes too), on Euler's equations plus ``dq/dt = q omega / 2``.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from hamilton_orbits.integrators import dop853
from rigid._kernels import euler as _k
from rigid.splitting import SPLITTINGS, split_ops

__all__ = ["METHODS", "integrate_arrays"]

# the square root of float64's smallest normal: a norm below it had a subnormal square
_NORMAL_ROOT = float(np.sqrt(np.finfo(np.float64).tiny))

METHODS = ("splitting2", "splitting4", "splitting4y", "exact_kick", "dop853", "rk4",
           "cayley_rk4")


def _steps(t_end: float, dt: float, n_out: int) -> tuple[int, float, np.ndarray]:
    n_steps = max(1, math.ceil(t_end / dt * (1.0 - 1e-12)))
    h = t_end / n_steps
    out_steps = np.unique(np.round(np.linspace(0.0, n_steps, n_out)).astype(np.int64))
    return n_steps, h, out_steps


#: the most steps of one compiled call: a run is cut into calls of at most this
#: many (the same steps and bits), so that a Ctrl-C is seen, and ``stop()`` asked,
#: within some milliseconds (about 10 ms of a splitting's steps)
_CHUNK = 1 << 16


def _progress_chunks(n_steps: int, progress: bool, stop: Any = None) -> tuple[list[int], Any]:
    """Coarse chunk boundaries (in steps) for an optional tqdm bar, or a ``stop``
    asked between chunks (about 1% of the run each; one chunk without them), and
    the bar."""
    bar = _bar(n_steps, "step", progress)
    if bar is None and stop is None:
        return [0, n_steps], None
    return sorted({int(b) for b in np.linspace(0, n_steps, min(n_steps, 100) + 1)}), bar


def _chunks(coarse: list[int]):
    """The chunks ``(a, b)`` (steps ``a + 1`` to ``b``) of the coarse ones, each cut
    into equal ones of at most :data:`_CHUNK` steps (made as they are run: a run of
    1e12 steps has 1.5e7 of them)."""
    for a, b in itertools.pairwise(coarse):
        k = -(-(b - a) // _CHUNK)
        for j in range(k):
            yield a + (b - a) * j // k, a + (b - a) * (j + 1) // k


def _stopped(stop: Any, b: int, n_steps: int, out_steps: np.ndarray) -> int | None:
    """After the chunk ending at step ``b``: the number of outputs reached when
    ``stop()`` asks the run to end there, else None."""
    if stop is None or b >= n_steps or not stop():
        return None
    return int(np.searchsorted(out_steps, b, side="right"))


def _in_chunks(advance: Any, n_steps: int, out_steps: np.ndarray, progress: bool,
               stop: Any) -> int:
    """Run ``advance(a, b, lo, hi)`` (steps ``a + 1`` to ``b``, the outputs ``lo`` to
    ``hi`` among them: ``out_steps`` sorted) over the run's chunks; returns the
    number of outputs reached (all of them unless ``stop()`` ended the run)."""
    coarse, bar = _progress_chunks(n_steps, progress, stop)
    try:
        for a, b in _chunks(coarse):
            lo = 0 if a == 0 else int(np.searchsorted(out_steps, a, side="right"))
            advance(a, b, lo, int(np.searchsorted(out_steps, b, side="right")))
            if bar is not None:
                bar.update(b - a)
            cut = _stopped(stop, b, n_steps, out_steps)
            if cut is not None:
                return cut
    finally:
        if bar is not None:
            bar.close()
    return out_steps.shape[0]


def _run_splitting(method, m, q0, w0, h, n_steps, out_steps, kind, params, progress,
                   stop=None):
    types, fracs, toffs, inv = split_ops(method, m, kind != _k.TORQUE_NONE)
    qh, ql, lh, ll = q0.copy(), np.zeros(4), m * w0, np.zeros(3)
    q_out = np.empty((out_steps.shape[0], 4))
    l_out = np.empty((out_steps.shape[0], 3))
    carry = [0.0, False]  # (the largest drift of |q| at an output, ``pending``)

    def advance(a: int, b: int, lo: int, hi: int) -> None:
        d, carry[1] = _k.run_splitting(types, fracs, toffs, inv, m, qh, ql, lh, ll, a, h,
                                       b - a, out_steps[lo:hi] - a, kind, params,
                                       q_out[lo:hi], l_out[lo:hi], carry[1], b < n_steps)
        carry[0] = max(carry[0], float(d))

    reached = _in_chunks(advance, n_steps, out_steps, progress, stop)
    return q_out[:reached], l_out[:reached] / m, carry[0]


def _run_exact_kick(m, q0, w0, h, n_steps, out_steps, kind, params, progress, stop=None):
    quat, omega = q0.copy(), w0.copy()
    q_out = np.empty((out_steps.shape[0], 4))
    w_out = np.empty((out_steps.shape[0], 3))

    def advance(a: int, b: int, lo: int, hi: int) -> None:
        _k.run_exact_kick(m, quat, omega, a, h, b - a, out_steps[lo:hi] - a, kind, params,
                          q_out[lo:hi], w_out[lo:hi])

    reached = _in_chunks(advance, n_steps, out_steps, progress, stop)
    return q_out[:reached], w_out[:reached]


def _run_rk4(m, q0, w0, h, n_steps, out_steps, kind, params, progress, stop=None):
    """``(y (n, 7), n)``: RK4's rows ``(q, omega)`` (q not normalised) and their count."""
    y = np.concatenate([q0, w0])
    y_out = np.empty((out_steps.shape[0], 7))

    def advance(a: int, b: int, lo: int, hi: int) -> None:
        _k.run_rk4_quaternion(m, y, a, h, b - a, out_steps[lo:hi] - a, kind, params,
                              y_out[lo:hi])

    return y_out, _in_chunks(advance, n_steps, out_steps, progress, stop)


def _run_cayley(m, q0, w0, h, n_steps, out_steps, kind, params, recentre, progress,
                stop=None):
    """``(y (n, 7), n, re-centrings)``: the rows ``(q, omega)`` of RK4 on Cayley's
    parameters, their count and the number of re-centrings."""
    off, y = q0.copy(), np.concatenate([np.zeros(3), w0])
    y_out = np.empty((out_steps.shape[0], 7))
    count = [0]

    def advance(a: int, b: int, lo: int, hi: int) -> None:
        count[0] += int(_k.run_rk4_cayley(m, off, y, a, h, b - a, out_steps[lo:hi] - a, kind,
                                          params, recentre, y_out[lo:hi]))

    reached = _in_chunks(advance, n_steps, out_steps, progress, stop)
    return y_out, reached, count[0]


def _unit_rows(y: np.ndarray) -> tuple[np.ndarray, float]:
    """``(y / |y|, max | |y| - 1 |)`` over the rows of ``y`` (n, 4): the quaternions of
    an unconstrained run, normalised on output, and the drift of their norm.

    A row whose squared norm leaves float64's normal range (RK4 with a step far too
    long: |q| beyond 1e154 or below 1e-154) is normalised on the row scaled by a
    power of two (exact); a norm beyond float64 gives an infinite drift, a zero row
    a NaN row (no attitude): :func:`rigid.integrate` refuses both, naming ``dt``.

    Examples
    --------
    >>> y = np.array([[2.0, 0.0, 0.0, 0.0], np.ldexp([0.0, 3.0, 4.0, 0.0], 700)])
    >>> q, drift = _unit_rows(y)  # |y|^2 of the second row, 25 x 2^1400, overflows
    >>> q.tolist(), drift == 5.0 * 2.0**700
    ([[1.0, 0.0, 0.0, 0.0], [0.0, 0.6, 0.8, 0.0]], True)
    """
    with np.errstate(over="ignore"):  # those rows are taken again below
        qn = np.sqrt(np.sum(y**2, axis=-1))
    odd = ~(qn >= _NORMAL_ROOT) | ~np.isfinite(qn)
    if not np.any(odd):  # the usual case, untouched
        return y / qn[:, None], float(np.max(np.abs(qn - 1.0)))
    big = np.max(np.abs(y[odd]), axis=-1)
    scale = np.ldexp(1.0, np.frexp(np.where(big > 0.0, big, 1.0))[1] - 1)  # powers of two
    ys = y[odd] / scale[:, None]
    ns = np.sqrt(np.sum(ys**2, axis=-1))
    with np.errstate(over="ignore", invalid="ignore"):  # a zero row: no attitude (NaN)
        qn[odd] = ns * scale
        q = y / qn[:, None]
        q[odd] = ys / ns[:, None]
    return q, float(np.max(np.abs(qn - 1.0)))


def _run_fixed(method, m, q0, w0, h, n_steps, out_steps, kind, params, recentre, progress,
               stop=None):
    """``(q, omega, count, drift)`` of a fixed-step method on the step grid (the
    outputs before a ``stop()`` asked between chunks of steps)."""
    count = 0
    drift = 0.0
    if method in SPLITTINGS:
        q, w, drift = _run_splitting(method, m, q0, w0, h, n_steps, out_steps, kind, params,
                                     progress, stop)
    elif method == "exact_kick":
        q, w = _run_exact_kick(m, q0, w0, h, n_steps, out_steps, kind, params, progress,
                               stop)
    elif method == "rk4":
        y, reached = _run_rk4(m, q0, w0, h, n_steps, out_steps, kind, params, progress, stop)
        q, drift = _unit_rows(y[:reached, :4])
        w = y[:reached, 4:]
    elif method == "cayley_rk4":
        y, reached, count = _run_cayley(m, q0, w0, h, n_steps, out_steps, kind, params,
                                        recentre, progress, stop)
        q, w = y[:reached, :4], y[:reached, 4:]
    else:
        raise ValueError(f"Expected `method` to be one of {METHODS}, got {method!r}")
    return q, w, count, drift


def _run_dop853(m, q0, w0, t_out, kind, params, rtol, atol, max_step, progress, stop=None):
    """``(q, omega, steps, nfev, drift)`` by the shared DOP853 driver
    (:func:`hamilton_orbits.integrators.dop853.solve`, dense output; the bar moved,
    output by output, as the steps pass them; the outputs reached when ``stop()``,
    asked every few dozen steps, ended the run)."""
    bar = _bar(t_out.size - 1, "output", progress)
    y, steps, nfev = dop853.solve(
        lambda t, y: _k.rhs_quaternion(t, y, m, kind, params), np.concatenate([q0, w0]),
        t_out, rtol=rtol, atol=atol, max_step=max_step, restart=False,
        on_output=None if bar is None else (lambda i, n: bar.update(1)),
        hint="a shorter span, or a fixed-step method with its dt", stop=stop,
    )
    if bar is not None:
        bar.close()
    q, drift = _unit_rows(y[:, :4])
    return q, y[:, 4:].copy(), int(steps), int(nfev), drift


def _bar(total: int, unit: str, progress: bool) -> Any:
    """A tqdm bar (the ``progress`` extra), or None."""
    if not progress:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - optional extra
        return None
    return tqdm(total=total, unit=unit, leave=False, disable=None)  # (None: quiet off a
    # terminal, a log file keeping each bar's text; a notebook's widget bar shows)


def _grid(t: np.ndarray, dt: float, n_out: int | None) -> tuple[int, float, np.ndarray]:
    """``(n_steps, h, out_steps)`` of a fixed-step run: a whole number of steps of
    ``h <= dt`` spans the last time; each output at the step nearest its time.

    An end time ``t`` (0-d) takes ``n_out`` (default 101) equally spaced outputs,
    as :func:`integrate` always did; an array of times takes one output each.
    """
    if t.ndim == 0:
        return _steps(float(t), dt, 101 if n_out is None else n_out)
    n_steps = max(1, math.ceil(float(t[-1]) / dt * (1.0 - 1e-12)))
    h = float(t[-1]) / n_steps
    out_steps = np.minimum(np.round(t / h).astype(np.int64), n_steps)
    return n_steps, h, out_steps


def integrate_arrays(
    moments: np.ndarray,
    q0: np.ndarray,
    omega0: np.ndarray,
    t: Any,
    *,
    method: str = "splitting4",
    dt: float | None = None,
    n_out: int | None = None,
    kind: int = _k.TORQUE_NONE,
    params: np.ndarray | None = None,
    rtol: float = 1e-12,
    atol: Any = 1e-14,
    recentre: float = 1.0,
    progress: bool = False,
    stop: Any = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int, float]:
    """Kernel-level integration on plain float arrays (no validation, no units).

    ``t`` is an end time (``n_out`` equally spaced outputs, default 101) or an
    increasing array of output times starting at 0.  ``dt`` is the step of the
    fixed-step methods and caps DOP853's step; ``rtol``, ``atol`` (scalar or
    (7,) for ``(q, omega)``) are DOP853's tolerances.  ``stop()``, asked between
    chunks of about 1% of the steps (and of at most 65 536) by the fixed-step
    methods (the same steps and bits), and every 64 steps by DOP853 (the same steps
    and outputs), ends the run there with the outputs reached.

    Returns ``(t (n,), q (n, 4), omega (n, 3), steps, count, norm_drift)``
    with unit quaternions; ``t`` the times reached; ``count`` is the number of
    re-centrings for ``"cayley_rk4"`` and of right-hand-side evaluations for
    ``"dop853"``.  See :func:`rigid.integrate` for the methods.

    Examples
    --------
    >>> t, q, w, steps, count, drift = integrate_arrays(
    ...     np.array([1.0, 2.0, 3.0]), np.array([1.0, 0, 0, 0]), np.array([0.0, 0.0, 1.0]),
    ...     np.array([0.0, 0.5, 1.0]), method="rk4", dt=0.1)
    >>> t, steps, q[-1].round(6)  # a spin about z: q = (cos t/2, 0, 0, sin t/2), RK4
    (array([0. , 0.5, 1. ]), 10, array([0.877583, 0.      , 0.      , 0.479426]))
    """
    params = np.zeros(1) if params is None else np.ascontiguousarray(params, dtype=np.float64)
    m = np.ascontiguousarray(moments, dtype=np.float64)
    q0 = np.ascontiguousarray(q0, dtype=np.float64)
    q0 = q0 / np.sqrt(q0 @ q0)
    w0 = np.ascontiguousarray(omega0, dtype=np.float64)
    t_arr = np.asarray(t, dtype=np.float64)
    if method == "dop853":
        t_out = (np.linspace(0.0, float(t_arr), 101 if n_out is None else n_out)
                 if t_arr.ndim == 0 else t_arr)
        q, w, steps, nfev, drift = _run_dop853(m, q0, w0, t_out, kind, params, rtol, atol,
                                               np.inf if dt is None else float(dt), progress,
                                               stop)
        return t_out[:len(q)], q, w, steps, nfev, drift
    n_steps, h, out_steps = _grid(t_arr, float(dt), n_out)
    q, w, count, drift = _run_fixed(method, m, q0, w0, h, n_steps, out_steps, kind, params,
                                    recentre, progress, stop)
    if len(q) < len(out_steps):  # (stopped: the outputs reached, the steps to the last)
        out_steps = out_steps[:len(q)]
        n_steps = int(out_steps[-1]) if len(q) else 0
    return out_steps * h, q, w, n_steps, count, drift

