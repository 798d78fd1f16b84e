"""Rigid-body integrators: Lie-Poisson splitting, exact flow plus kicks, DOP853.

Methods of :func:`integrate` (orders for the free body; with a torque that
depends on (t, attitude) only, the fixed-step methods keep their order):

``"splitting2"``
    The symmetric Lie-Poisson splitting of the free body T = T1 + T2 + T3,
    T_i = L_i^2 / (2 I_i), each flow an exact rotation of the body angular
    momentum and of the attitude about a principal axis (McLachlan 1993, Phys.
    Rev. Lett. 71, 3043; Reich 1994; Touma & Wisdom 1994, AJ 107, 1189):
    R1(h/2) R2(h/2) R3(h) R2(h/2) R1(h/2).  Second order, symplectic and
    Poisson; |L| and the space-frame L are conserved to rounding error, the
    energy to O(h^2) without drift.  A torque enters as kick(h/2) S(h) kick(h/2).
``"splitting4"``
    Fourth order: Blanes & Moan's (2002) S6 composition applied to the split
    T = |L|^2 / (2 I_m) + (1/I_a - 1/I_m) L_a^2 / 2 + (1/I_b - 1/I_m) L_b^2 / 2,
    I_m the middle moment.  The first (Casimir) part turns the attitude about L
    and commutes with everything, so the two remaining axis rotations carry all
    of the splitting error, with coefficients smaller than 1/I_k (cf. Fasso
    2003, J. Comput. Phys. 189, 527): 12 axis rotations plus one rotation about
    L per step; on the 1:2:3 benchmark body its error is ~30x below S6 applied
    to T1 + T2 + T3 and ~4000x below Yoshida's triple jump at equal step.
    Exact for the sphere and the axisymmetric body.  Same invariants as
    ``"splitting2"``; with a torque the composition runs over kick, axis,
    Casimir, axis.
``"splitting4y"``
    Yoshida's (1990) triple jump of ``"splitting2"``: S(w1 h) S(w0 h) S(w1 h),
    w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1 (the ``"splitting4"`` of earlier
    versions; kept for comparison).

All splittings fuse the neighbouring flows of one part (also across steps) and
keep their rounding error at a few ulp per *run*: each rotation is applied as a
compensated (TwoSum) increment with cos - 1 and sin from the half angle, so it
is orthogonal to O(eps h^2) (see :mod:`rigid._kernels.euler`).  The attitude is
normalised on output only (it is not projected inside the run);
``norm_drift`` reports max | |q| - 1 | before that.
``"exact_kick"``
    Kick-drift-kick with the drift the *exact* torque-free motion
    (:func:`rigid.free.free_motion_arrays`): exact for the free body (any h),
    second order in the torque.
``"dop853"``
    scipy's DOP853 through the one driver of both packages,
    :func:`hamilton_orbits.integrators.dop853.solve` (one integration, the
    outputs from DOP853's 7th-order dense output, so that many closely spaced
    outputs do not cap the step), on Euler's
    equations plus dq/dt = q omega / 2.  Tolerances from ``tol``: relative
    ``tol``, absolute ``tol / 100`` on the (unit) quaternion and
    ``tol / 100 max|omega0|`` on omega.  Normalisation policy: q is integrated
    *unconstrained* and normalised only on output.  The exact flow conserves
    |q|, so | |q| - 1 | is a free error estimate (returned as ``norm_drift``)
    rather than something to hide by projection, and projecting inside the
    step control would need a restart per step.
``"rk4"``, ``"cayley_rk4"``
    Classical fourth-order Runge-Kutta on Euler plus the quaternion
    kinematics, or plus Cayley's kinematics in (lambda, mu, nu) with re-centring
    (see :mod:`rigid.rodrigues`).  Reference/demonstration methods.

Every fixed-step method runs its whole time loop in one compiled function.

Output times and units (:func:`integrate`): ``t`` is an end time (101 equally
spaced outputs from 0 to it) or an array of output times from the body's state
(a start at 0 is added if missing).  Where the caller gave Quantities the
result is in Quantities: ``t`` in the unit of the ``t`` given, omega in rad/s,
moments in kg m^2; plain floats are SI.
"""

from __future__ import annotations

import itertools
import math
import time
import warnings
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.integrators import dop853
from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import DIMENSIONLESS, TIME, wrap
from hamilton_orbits.validation import check_positive
from rigid._kernels import euler as _k
from rigid.body import call_units, check_body
from rigid.euler import BodyTorque, GravityGradientTorque, SpaceTorque, encode_torque
from rigid.trajectory import RigidTrajectory, integral_errors

__all__ = [
    "METHODS",
    "BodyTorque",
    "GravityGradientTorque",
    "RigidTrajectory",
    "SpaceTorque",
    "integrate",
    "integrate_arrays",
]

METHODS = ("splitting2", "splitting4", "splitting4y", "exact_kick", "dop853", "rk4",
           "cayley_rk4")
_SPLITTINGS = ("splitting2", "splitting4", "splitting4y")
_FIXED = (*_SPLITTINGS, "exact_kick", "rk4", "cayley_rk4")


_MAX_STEPS = 1e12  # beyond this a fixed-step run is a typo, not a plan (days of CPU)


def _scalar_positive(name: str, value: np.ndarray) -> float:
    if value.shape != ():
        raise ValueError(f"Expected `{name}` to be a scalar, got shape {value.shape}")
    check_positive(name, value)
    return float(value)


def _n_out(n_out: Any) -> int:
    ok = isinstance(n_out, (int, np.integer)) and not isinstance(n_out, bool)
    if isinstance(n_out, (float, np.floating)) and float(n_out).is_integer():
        ok = True
    if not ok or n_out < 2 or n_out > 1e9:
        raise ValueError(f"Expected `n_out` to be an integer in [2, 1e9], got {n_out!r}")
    return int(n_out)


def _steps(t_end: float, dt: float, n_out: int) -> tuple[int, float, np.ndarray]:
    n_steps = max(1, math.ceil(t_end / dt * (1.0 - 1e-12)))
    h = t_end / n_steps
    out_steps = np.unique(np.round(np.linspace(0.0, n_steps, n_out)).astype(np.int64))
    return n_steps, h, out_steps


def _progress_chunks(n_steps: int, progress: bool):
    """Chunk boundaries (in steps) for an optional tqdm bar; one chunk without it."""
    bar = _bar(n_steps, "step", progress)
    if bar is None:
        return [0, n_steps], None
    return sorted({int(b) for b in np.linspace(0, n_steps, min(n_steps, 100) + 1)}), bar


# Yoshida (1990, Phys. Lett. A 150, 262, eq. 5.4) triple jump: a symmetric
# second-order map S2 composed as S2(w1 h) S2(w0 h) S2(w1 h) is of order four.
_CBRT2 = 2.0 ** (1.0 / 3.0)
YOSHIDA_W = (1.0 / (2.0 - _CBRT2), -_CBRT2 / (2.0 - _CBRT2), 1.0 / (2.0 - _CBRT2))

# Blanes & Moan (2002), J. Comput. Appl. Math. 142, 313-330, Table 2, method
# S6 (order 4, 6 stages, symmetric): for H = A + B,
#   e^{a1 A} e^{b1 B} e^{a2 A} e^{b2 B} e^{a3 A} e^{b3 B} e^{a4 A} e^{b3 B} ... e^{a1 A},
# a4 = 1 - 2 (a1 + a2 + a3), b3 = 1/2 - (b1 + b2).
BM_A = (0.0792036964311957, 0.353172906049774, -0.0420650803577195)
BM_B = (0.209515106613362, -0.143851773179818)
_BM_A = (*BM_A, 1.0 - 2.0 * sum(BM_A), *BM_A[::-1])
_BM_B = (*BM_B, 0.5 - sum(BM_B), 0.5 - sum(BM_B), *BM_B[::-1])


def _bm_lie_coefficients() -> tuple[tuple[float, ...], tuple[float, ...]]:
    """S6 as a composition Phi*_{d6} Phi_{c6} ... Phi*_{d1} Phi_{c1} (c_i, d_i).

    With Phi_c = e^{cB} e^{cA} (A first) and Phi*_d = e^{dA} e^{dB} its adjoint,
    the product runs A(c1) B(c1 + d1) A(d1 + c2) ... B(c6 + d6) A(d6): so
    c1 = a1, d_i = b_i - c_i, c_{i+1} = a_{i+1} - d_i (McLachlan 1995, SIAM J.
    Sci. Comput. 16, 151; Hairer, Lubich & Wanner, GNI, sec. III.5).  With Phi
    the Lie-Trotter product of *any* number of exact flows, this composition is
    of order 4 (its order conditions coincide with those of the two-part
    splitting up to order 4; checked by the halving tests).
    """
    c: list[float] = []
    d: list[float] = []
    prev = 0.0
    for a, b in zip(_BM_A[:6], _BM_B, strict=True):
        c.append(a - prev)
        d.append(b - c[-1])
        prev = d[-1]
    return tuple(c), tuple(d)


_BM_C, _BM_D = _bm_lie_coefficients()

_KICK = 3
_CASIMIR = 4


def _strang(w: float, torqued: bool) -> list[tuple[int, float]]:
    """S2(w h) = K(w/2) R1(w/2) R2(w/2) R3(w) R2(w/2) R1(w/2) K(w/2)."""
    ops = [(0, 0.5 * w), (1, 0.5 * w), (2, w), (1, 0.5 * w), (0, 0.5 * w)]
    return [(_KICK, 0.5 * w), *ops, (_KICK, 0.5 * w)] if torqued else ops


def _split_ops(
    method: str, moments: np.ndarray, torqued: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(types, fractions of h, time offsets in h, inverse moments) of one step.

    Types 0-2 are principal-axis rotations, 3 a torque kick, 4 the Casimir flow
    (see :func:`rigid._kernels.euler.run_splitting`).
    """
    inv = np.concatenate([1.0 / moments, [0.0, 0.0]])  # axes 0-2, (kick), Casimir
    # Time (for time-dependent torques) is carried by one part: the one with the
    # full step in the Strang splitting, the Casimir flow in "splitting4".
    time_part = 2
    if method == "splitting2":
        ops = _strang(1.0, torqued)
    elif method == "splitting4y":
        ops = [op for w in YOSHIDA_W for op in _strang(w, torqued)]
    elif method == "splitting4":
        # T = |L|^2 / (2 I_m) + sum over the two other axes of (1/I_k - 1/I_m) L_k^2 / 2,
        # I_m the middle moment: the Casimir part commutes with everything (free
        # body) and the two axis parts are smaller than 1/I_k.  S6 of Blanes &
        # Moan on the two axis parts, in its Lie-Trotter/adjoint form; with a
        # torque the Lie-Trotter product is kick, axis, Casimir, axis.
        ref = int(np.argsort(moments, kind="stable")[1])
        inv[:3] -= 1.0 / moments[ref]
        inv[_CASIMIR] = 1.0 / moments[ref]
        ax = [k for k in range(3) if k != ref]
        parts = [_KICK, ax[0], _CASIMIR, ax[1]] if torqued else ax
        ops = []
        for c, d in zip(_BM_C, _BM_D, strict=True):
            ops += [(p, c) for p in parts]  # Phi_c
            ops += [(p, d) for p in parts[::-1]]  # Phi*_d
        if not torqued:  # the Casimir flow commutes: one per step
            ops.insert(len(ops) // 2, (_CASIMIR, 1.0))
        time_part = _CASIMIR
    else:  # pragma: no cover - guarded by the callers
        raise ValueError(method)
    fused: list[list[float]] = []
    for typ, fr in ops:  # flows of the same part commute: fuse neighbours
        if fused and fused[-1][0] == typ:
            fused[-1][1] += fr
        else:
            fused.append([typ, fr])
    types = np.array([int(t) for t, _ in fused], dtype=np.int64)
    fracs = np.array([fr for _, fr in fused])
    toffs = np.concatenate([[0.0], np.cumsum(np.where(types == time_part, fracs, 0.0))[:-1]])
    return types, fracs, toffs, inv


def _run_splitting(method, m, q0, w0, h, n_steps, out_steps, kind, params, progress):
    types, fracs, toffs, inv = _split_ops(method, m, kind != _k.TORQUE_NONE)
    qh = q0.copy()
    ql = np.zeros(4)
    lh = m * w0
    ll = np.zeros(3)
    nout = out_steps.shape[0]
    q_out = np.empty((nout, 4))
    l_out = np.empty((nout, 3))
    drift = 0.0
    pending = False
    bounds, bar = _progress_chunks(n_steps, progress)
    for a, b in itertools.pairwise(bounds):
        sel = (out_steps >= (a if a == 0 else a + 1)) & (out_steps <= b)
        idx = np.nonzero(sel)[0]
        qo = np.empty((idx.size, 4))
        lo = np.empty((idx.size, 3))
        d, pending = _k.run_splitting(types, fracs, toffs, inv, m, qh, ql, lh, ll, a * h, h,
                                      b - a, out_steps[idx] - a, kind, params, qo, lo,
                                      pending, b < n_steps)
        drift = max(drift, float(d))
        q_out[idx] = qo
        l_out[idx] = lo
        if bar is not None:
            bar.update(b - a)
    if bar is not None:
        bar.close()
    return q_out, l_out / m, drift


def _run_exact_kick(m, q0, w0, h, n_steps, out_steps, kind, params, progress):
    quat = q0.copy()
    omega = w0.copy()
    nout = out_steps.shape[0]
    q_out = np.empty((nout, 4))
    w_out = np.empty((nout, 3))
    bounds, bar = _progress_chunks(n_steps, progress)
    for a, b in itertools.pairwise(bounds):
        idx = np.nonzero((out_steps >= (a if a == 0 else a + 1)) & (out_steps <= b))[0]
        qo = np.empty((idx.size, 4))
        wo = np.empty((idx.size, 3))
        _k.run_exact_kick(m, quat, omega, a * h, h, b - a, out_steps[idx] - a, kind, params,
                          qo, wo)
        q_out[idx] = qo
        w_out[idx] = wo
        if bar is not None:
            bar.update(b - a)
    if bar is not None:
        bar.close()
    return q_out, w_out


def _run_fixed(method, m, q0, w0, h, n_steps, out_steps, kind, params, recentre, progress):
    """``(q, omega, count, drift)`` of a fixed-step method on the step grid."""
    count = 0
    drift = 0.0
    if method in _SPLITTINGS:
        q, w, drift = _run_splitting(method, m, q0, w0, h, n_steps, out_steps, kind, params,
                                     progress)
    elif method == "exact_kick":
        q, w = _run_exact_kick(m, q0, w0, h, n_steps, out_steps, kind, params, progress)
    elif method == "rk4":
        y = np.empty((out_steps.size, 7))
        _k.run_rk4_quaternion(m, np.concatenate([q0, w0]), 0.0, h, n_steps, out_steps, kind,
                              params, y)
        qn = np.sqrt(np.sum(y[:, :4] ** 2, axis=-1))
        drift = float(np.max(np.abs(qn - 1.0)))
        q, w = y[:, :4] / qn[:, None], y[:, 4:]
    elif method == "cayley_rk4":
        y = np.empty((out_steps.size, 7))
        count = int(_k.run_rk4_cayley(m, q0, w0, 0.0, h, n_steps, out_steps, kind, params,
                                      recentre, y))
        q, w = y[:, :4], y[:, 4:]
    else:
        raise ValueError(f"Expected `method` to be one of {METHODS}, got {method!r}")
    return q, w, count, drift


def _run_dop853(m, q0, w0, t_out, kind, params, rtol, atol, max_step, progress):
    """``(q, omega, steps, nfev, drift)`` by the shared DOP853 driver
    (:func:`hamilton_orbits.integrators.dop853.solve`, dense output)."""
    bar = _bar(t_out.size - 1, "output", progress)
    y, steps, nfev = dop853.solve(
        lambda t, y: _k.rhs_quaternion(t, y, m, kind, params), np.concatenate([q0, w0]),
        t_out, rtol=rtol, atol=atol, max_step=max_step, restart=False,
        on_output=None if bar is None else (lambda i, n: bar.update(1)),
    )
    if bar is not None:
        bar.close()
    qn = np.sqrt(np.sum(y[:, :4] ** 2, axis=-1))
    drift = float(np.max(np.abs(qn - 1.0)))
    return y[:, :4] / qn[:, None], y[:, 4:].copy(), int(steps), int(nfev), drift


def _bar(total: int, unit: str, progress: bool) -> Any:
    """A tqdm bar (the ``progress`` extra), or None."""
    if not progress:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - optional extra
        return None
    return tqdm(total=total, unit=unit, leave=False)


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
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int, float]:
    """Kernel-level integration on plain float arrays (no validation, no units).

    ``t`` is an end time (``n_out`` equally spaced outputs, default 101) or an
    increasing array of output times starting at 0.  ``dt`` is the step of the
    fixed-step methods and caps DOP853's step; ``rtol``, ``atol`` (scalar or
    (7,) for ``(q, omega)``) are DOP853's tolerances.

    Returns ``(t (n,), q (n, 4), omega (n, 3), steps, count, norm_drift)``
    with unit quaternions; ``t`` the times reached; ``count`` is the number of
    re-centrings for ``"cayley_rk4"`` and of right-hand-side evaluations for
    ``"dop853"``.  See :func:`integrate` for the methods.

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
                                               np.inf if dt is None else float(dt), progress)
        return t_out, q, w, steps, nfev, drift
    n_steps, h, out_steps = _grid(t_arr, float(dt), n_out)
    q, w, count, drift = _run_fixed(method, m, q0, w0, h, n_steps, out_steps, kind, params,
                                    recentre, progress)
    return out_steps * h, q, w, n_steps, count, drift


_UNSET: Any = object()  # the default of the deprecated keywords


def _deprecated(t: Any, t_end: Any, n_out: Any, rtol: Any, atol: Any, tol: Any) -> tuple:
    """``(t, n_out, rtol, atol)`` from the keywords of before issue 19, with a
    DeprecationWarning naming the new one (None where not given)."""
    def warn(old: str, new: str) -> None:
        warnings.warn(f"`{old}=` is deprecated; {new}", DeprecationWarning, stacklevel=4)

    if t_end is not _UNSET:
        warn("t_end", "pass the end time (or an array of output times) as `t`")
        if t is not None:
            raise ValueError(f"Expected `t` or the deprecated `t_end`, got both: {t!r}, "
                             f"{t_end!r}")
        t = t_end
    if t is None:
        raise ValueError("Expected `t`, an end time or an array of output times, got None")
    if n_out is not _UNSET:
        warn("n_out", "pass an array of output times as `t`, e.g. "
             "np.linspace(0, t_end, n_out)")
        if np.ndim(getattr(t, "value", t)) != 0:
            raise ValueError(f"Expected `n_out` only with an end time `t`, got an array `t` "
                             f"of shape {np.shape(t)}")
        n_out = _n_out(n_out)
    old_tol = {k: v for k, v in (("rtol", rtol), ("atol", atol)) if v is not _UNSET}
    for name, value in old_tol.items():
        warn(name, "pass `tol` (DOP853's relative tolerance; the absolute one follows "
             "from it)")
        if tol is not None:
            raise ValueError(f"Expected `tol` or the deprecated `{name}`, got both: "
                             f"tol = {tol!r}, {name} = {value!r}")
    return (t, None if n_out is _UNSET else n_out, old_tol.get("rtol"), old_tol.get("atol"))


def _output_times(t_s: np.ndarray) -> np.ndarray:
    """A validated end time (0-d, > 0) or times from 0, strictly increasing (a 0 is
    prepended if missing)."""
    if t_s.ndim == 0:
        return np.asarray(_scalar_positive("t", t_s))
    if t_s.ndim != 1 or t_s.size == 0:
        raise ValueError(f"Expected `t` to be an end time or a 1-d array of output times, "
                         f"got shape {t_s.shape}")
    if not t_s[0] >= 0.0:
        raise ValueError(f"Expected `t` >= 0 (times from the body's state), got "
                         f"{float(t_s[0])!r} at index 0")
    bad = np.nonzero(~(np.diff(t_s) > 0.0))[0]
    if bad.size:
        k = int(bad[0]) + 1
        raise ValueError(f"Expected `t` strictly increasing, got {float(t_s[k])!r} after "
                         f"{float(t_s[k - 1])!r} at index {k}")
    if t_s[-1] == 0.0:
        raise ValueError("Expected `t` to reach beyond 0, got [0.0]")
    return t_s if t_s[0] == 0.0 else np.concatenate([[0.0], t_s])


def _step(method: str, dt: Any, t_last: float, tol: Any) -> float | None:
    """The step (fixed-step methods, required) or DOP853's step cap (optional), s."""
    if method in _FIXED:
        if tol is not None:
            raise ValueError(f"Expected `tol` only with method 'dop853' (a fixed-step method "
                             f"takes `dt`), got tol = {tol!r} for method {method!r}")
        if dt is None:
            raise ValueError(f"Expected `dt` for method {method!r}, got None")
    if dt is None:
        return None
    dtf = float(_scalar_positive("dt", TIME("dt", dt)))
    if method in _FIXED and (not math.isfinite(t_last / dtf) or t_last / dtf > _MAX_STEPS):
        raise ValueError(
            f"Expected `dt` to give at most {_MAX_STEPS:.0e} steps over `t`, got "
            f"dt = {dtf!r} s for t = {t_last!r} s"
        )
    return dtf


def _tolerances(tol: Any, rtol: Any, atol: Any, w0: np.ndarray) -> tuple[float, Any]:
    """DOP853's ``(rtol, atol)``: from ``tol`` (relative ``tol``; absolute ``tol / 100``
    on the unit quaternion and ``tol / 100 max|omega0|`` on omega), or the
    deprecated ``rtol``, ``atol`` as given (defaults 1e-12, 1e-14)."""
    if rtol is not None or atol is not None:
        r, a = (float(_scalar_positive(name, DIMENSIONLESS(name, v))) for name, v in
                (("rtol", 1e-12 if rtol is None else rtol),
                 ("atol", 1e-14 if atol is None else atol)))
        return r, a
    tol_f = DEFAULT_TOL if tol is None else float(_scalar_positive("tol", DIMENSIONLESS(
        "tol", tol)))
    w_scale = float(np.max(np.abs(w0)))
    scale = np.array([1.0] * 4 + [w_scale if w_scale > 0.0 else 1.0] * 3)
    return tol_f, 1e-2 * tol_f * scale


#: DOP853's default ``tol`` (relative tolerance).
DEFAULT_TOL = 1e-12


def integrate(
    body: Any,
    t: Any = None,
    *,
    method: str = "splitting4",
    dt: Any = None,
    tol: float | None = None,
    torque: Any = None,
    progress: bool = False,
    recentre: float = 1.0,
    t_end: Any = _UNSET,
    n_out: Any = _UNSET,
    rtol: Any = _UNSET,
    atol: Any = _UNSET,
) -> RigidTrajectory:
    """Integrate a rigid body (free or torqued) from its current state.

    Parameters
    ----------
    body : RigidBody
        Initial state: ``moments`` (3,), ``attitude`` (Quaternion), ``omega`` (3,).
    t : float, array_like or Quantity
        An end time (> 0; 101 equally spaced outputs from 0 to it), or the output
        times from the body's state, shape (n,), strictly increasing (a start at
        0 is added if missing).  s for plain floats; a Quantity if ``body`` was
        built from Quantities.
    method : str, optional
        One of :data:`METHODS` (see the module docstring).  Default
        ``"splitting4"``.
    dt : float or Quantity, optional
        Step of the fixed-step methods (required for them), rounded down so that
        a whole number of steps spans the last time; for ``"dop853"`` a cap on
        the step.  A Quantity exactly when ``t`` is one.
    tol : float, optional
        ``"dop853"`` only: its relative tolerance (default 1e-12; the absolute
        tolerance is ``tol / 100`` on the unit quaternion and
        ``tol / 100 max|omega0|`` on omega).  Refused by the fixed-step methods.
    torque : BodyTorque, SpaceTorque, GravityGradientTorque or None, optional
        External torque (see :mod:`rigid.euler`).  Default None (free body).
    progress : bool, optional
        Show a tqdm progress bar (needs the ``progress`` extra).
    recentre : float, optional
        Re-centring threshold on |g_0| for ``"cayley_rk4"``.

    Other Parameters
    ----------------
    t_end, n_out, rtol, atol
        Deprecated (DeprecationWarning): ``t_end=`` is ``t``; ``n_out=`` is an
        array ``t = np.linspace(0, t_end, n_out)``; ``rtol=``, ``atol=`` are
        ``tol`` (given, they are used as they are, as before).

    Returns
    -------
    RigidTrajectory
        Units: where the caller gave Quantities the result is in Quantities, ``t``
        in the unit of the ``t`` given (or of ``t_end``), omega in rad/s and
        moments in kg m^2 (the units the body answers in); plain floats are SI.
        Fixed-step methods output at the step nearest each time (``t`` holds the
        times reached); ``"dop853"`` at the times themselves.

    Raises
    ------
    ValueError
        For ``body`` not a RigidBody, an unknown method, a bad ``t`` (NaN,
        not > 0, not increasing, naming the index and the value) or ``dt``, a
        missing ``dt``, more than 1e12 steps, ``tol`` with a fixed-step method,
        ``n_out`` not an integer in [2, 1e9], a plain ``dt`` beside a Quantity
        ``t`` (or the reverse, or plain times for a body with units), or an
        unsupported torque.
    astropy.units.UnitConversionError
        For a time of the wrong dimension, naming the argument.

    References
    ----------
    McLachlan, R. I. (1993), Phys. Rev. Lett. 71, 3043; Touma, J. & Wisdom, J.
    (1994), AJ 107, 1189; Yoshida, H. (1990), Phys. Lett. A 150, 262; Blanes, S.
    & Moan, P. C. (2002), J. Comput. Appl. Math. 142, 313; McLachlan, R. I.
    (1995), SIAM J. Sci. Comput. 16, 151; Hairer,
    Lubich & Wanner, *Geometric Numerical Integration*, 2nd ed., sec. VII.5.

    Examples
    --------
    >>> from rigid import RigidBody
    >>> b = RigidBody([1.0, 2.0, 3.0], omega=[0.1, 1.0, 0.1])
    >>> tr = integrate(b, [5.0, 10.0], dt=0.01, method="splitting2")
    >>> tr.t
    array([ 0.,  5., 10.])
    >>> bool(np.all(tr.angular_momentum_error < 1e-14))  # L in space, to rounding
    True
    >>> import astropy.units as u
    >>> integrate(b, 10.0 * u.min, method="dop853", tol=1e-10).t[-1]  # the caller's unit
    <Quantity 10. min>
    """
    body = check_body(body)
    t, n_out, rtol, atol = _deprecated(t, t_end, n_out, rtol, atol, tol)
    si = body.si
    # a body whose I omega^2 or I omega leaves float64 is refused here
    _ = (si.kinetic_energy, si.angular_momentum_norm)
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"Expected `method` to be one of {METHODS}, got {method!r}")
    quantity = call_units(body, ("t", "dt"), (t, dt))
    times = _output_times(TIME("t", t))
    dtf = _step(method, dt, float(times.max()), tol)
    rtol_f, atol_f = _tolerances(tol, rtol, atol, si.omega)
    recentre = float(_scalar_positive("recentre", DIMENSIONLESS("recentre", recentre)))
    kind, params = encode_torque(torque)
    start = time.perf_counter()
    t_f, q, w, steps, count, drift = integrate_arrays(
        si.moments, si.attitude, si.omega, times, method=method, dt=dtf, n_out=n_out,
        kind=kind, params=params, rtol=rtol_f, atol=atol_f, recentre=recentre,
        progress=progress,
    )
    wall = time.perf_counter() - start
    _check_finite(t_f, q, w, method, dtf)
    energy_error, am_error = integral_errors(si.moments, q, w)
    t_unit = getattr(t, "unit", u.s) if quantity else u.s
    return RigidTrajectory(
        t=wrap(t_f / t_unit.to(u.s), t_unit, quantity), steps=int(steps), wall_time=wall,
        method=method, energy_error=energy_error, angular_momentum_error=am_error,
        attitude=Quaternion(q), omega=wrap(w, u.rad / u.s, quantity),
        moments=wrap(si.moments, u.kg * u.m**2, quantity),
        n_recentre=count if method == "cayley_rk4" else 0, norm_drift=drift,
        nfev=count if method == "dop853" else 0,
    )


def _check_finite(t: np.ndarray, q: np.ndarray, w: np.ndarray, method: str, dt: Any) -> None:
    bad = ~(np.isfinite(q).all(axis=-1) & np.isfinite(w).all(axis=-1))
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected `dt` small enough for a finite solution, got a non-finite state at "
            f"t = {float(t[k])!r} s with method {method!r} and dt = {dt!r} s"
        )
