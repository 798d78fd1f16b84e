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
    scipy's ``solve_ivp(method="DOP853")`` on Euler's equations plus
    dq/dt = q omega / 2 with tolerances ``rtol``, ``atol``.  Normalisation
    policy: q is integrated *unconstrained* and normalised only on output.  The
    exact flow conserves |q|, so | |q| - 1 | is a free error estimate
    (returned as ``norm_drift``) rather than something to hide by projection,
    and projecting inside solve_ivp's step control would need a restart per step.
``"rk4"``, ``"cayley_rk4"``
    Classical fourth-order Runge-Kutta on Euler plus the quaternion
    kinematics, or plus Cayley's kinematics in (lambda, mu, nu) with re-centring
    (see :mod:`rigid.rodrigues`).  Reference/demonstration methods.

Every fixed-step method runs its whole time loop in one compiled function.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits._validation import check_positive
from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import DIMENSIONLESS, TIME, wrap
from rigid._kernels import euler as _k
from rigid.body import call_units, check_body
from rigid.euler import BodyTorque, GravityGradientTorque, SpaceTorque, encode_torque

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


@dataclass(frozen=True)
class RigidTrajectory:
    """The result of :func:`integrate`.

    Attributes
    ----------
    t : ndarray or Quantity, shape (n,)
        Output times (a Quantity in the unit of ``t_end`` when the call used
        Quantities).
    attitude : Quaternion, shape (n,)
        Unit body-to-space attitudes.
    omega : ndarray or Quantity, shape (n, 3)
        Body-frame angular velocities (rad/s when the call used Quantities).
    moments : ndarray or Quantity, shape (3,)
        Principal moments (A, B, C) (kg m^2 when the call used Quantities).
    method : str
        Integrator name.
    n_steps : int
        Steps taken (fixed-step methods; 0 for DOP853, whose step count
        scipy does not report: see ``nfev``).
    n_recentre : int
        Re-centrings of Cayley's parameters (``"cayley_rk4"`` only, else 0).
    norm_drift : float
        max | |q| - 1 | before the output normalisation (0 for ``"exact_kick"``,
        which renormalises every step).
    nfev : int
        Right-hand-side evaluations (DOP853 only, else 0).
    """

    t: Any
    attitude: Quaternion
    omega: Any
    moments: np.ndarray
    method: str
    n_steps: int
    n_recentre: int = 0
    norm_drift: float = 0.0
    nfev: int = 0

    def _quantity(self) -> bool:
        return isinstance(self.t, u.Quantity)

    def _omega_f(self) -> np.ndarray:
        w = self.omega
        return w.to_value(u.rad / u.s) if isinstance(w, u.Quantity) else np.asarray(w)

    def _moments_f(self) -> np.ndarray:
        m = self.moments
        return m.to_value(u.kg * u.m**2) if isinstance(m, u.Quantity) else np.asarray(m)

    @property
    def angular_momentum_body(self) -> Any:
        """L = I omega in the body frame, shape (n, 3) (kg m^2/s for Quantity calls)."""
        return wrap(self._moments_f() * self._omega_f(), _L_UNIT, self._quantity())

    @property
    def angular_momentum_space(self) -> Any:
        """q L q^-1, Cayley's (g, g', g''), shape (n, 3) (kg m^2/s for Quantity calls)."""
        ell = self.attitude.rotate(self._moments_f() * self._omega_f())
        return wrap(np.asarray(ell), _L_UNIT, self._quantity())

    @property
    def kinetic_energy(self) -> Any:
        """T = (A p^2 + B q^2 + C r^2) / 2, shape (n,) (J for Quantity calls)."""
        w = self._omega_f()
        return wrap(0.5 * np.sum(self._moments_f() * w * w, axis=-1), u.J, self._quantity())


_L_UNIT = u.kg * u.m**2 / u.s
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
    if not progress:
        return [0, n_steps], None
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - optional extra
        return [0, n_steps], None
    bounds = sorted({int(b) for b in np.linspace(0, n_steps, min(n_steps, 100) + 1)})
    return bounds, tqdm(total=n_steps, unit="step", leave=False)


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


def integrate_arrays(
    moments: np.ndarray,
    q0: np.ndarray,
    omega0: np.ndarray,
    t_end: float,
    *,
    method: str = "splitting4",
    dt: float | None = None,
    n_out: int = 101,
    kind: int = _k.TORQUE_NONE,
    params: np.ndarray | None = None,
    rtol: float = 1e-12,
    atol: float = 1e-14,
    recentre: float = 1.0,
    progress: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int, float]:
    """Kernel-level integration on plain float arrays (no validation, no units).

    Returns ``(t (n,), q (n, 4), omega (n, 3), n_steps, count, norm_drift)``
    with unit quaternions; ``count`` is the number of re-centrings for
    ``"cayley_rk4"`` and of right-hand-side evaluations for ``"dop853"``.
    See :func:`integrate` for the methods.
    """
    params = np.zeros(1) if params is None else np.ascontiguousarray(params, dtype=np.float64)
    m = np.ascontiguousarray(moments, dtype=np.float64)
    q0 = np.ascontiguousarray(q0, dtype=np.float64)
    q0 = q0 / np.sqrt(q0 @ q0)
    w0 = np.ascontiguousarray(omega0, dtype=np.float64)
    n_recentre = 0
    drift = 0.0
    if method == "dop853":
        from scipy.integrate import solve_ivp

        t_out = np.linspace(0.0, t_end, n_out)
        sol = solve_ivp(
            lambda t, y: _k.rhs_quaternion(t, y, m, kind, params),
            (0.0, t_end),
            np.concatenate([q0, w0]),
            method="DOP853",
            t_eval=t_out,
            rtol=rtol,
            atol=atol,
        )
        if not sol.success:  # pragma: no cover - scipy failure
            raise ValueError(f"DOP853 failed: {sol.message}")
        y = sol.y.T
        qn = np.sqrt(np.sum(y[:, :4] ** 2, axis=-1))
        drift = float(np.max(np.abs(qn - 1.0)))
        return t_out, y[:, :4] / qn[:, None], y[:, 4:].copy(), 0, int(sol.nfev), drift
    n_steps, h, out_steps = _steps(t_end, float(dt), n_out)
    t_out = out_steps * h
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
        n_recentre = int(_k.run_rk4_cayley(m, q0, w0, 0.0, h, n_steps, out_steps, kind, params,
                                           recentre, y))
        q, w = y[:, :4], y[:, 4:]
    else:
        raise ValueError(f"Expected `method` to be one of {METHODS}, got {method!r}")
    return t_out, q, w, n_steps, n_recentre, drift


def integrate(
    body: Any,
    t_end: Any,
    *,
    dt: Any = None,
    method: str = "splitting4",
    torque: Any = None,
    n_out: int = 101,
    rtol: float = 1e-12,
    atol: float = 1e-14,
    recentre: float = 1.0,
    progress: bool = False,
) -> RigidTrajectory:
    """Integrate a rigid body (free or torqued) from its current state.

    Parameters
    ----------
    body : RigidBody
        Initial state: ``moments`` (3,), ``attitude`` (Quaternion), ``omega`` (3,).
    t_end : float or Quantity
        Time span, > 0 (s for plain floats).  Must be a Quantity if ``body`` was
        built from Quantities.
    dt : float or Quantity, optional
        Step of the fixed-step methods (required for them; ignored by
        ``"dop853"``).  Rounded down so that a whole number of steps spans
        ``t_end``.  A Quantity exactly when ``t_end`` is one.
    method : str, optional
        One of :data:`METHODS` (see the module docstring).  Default
        ``"splitting4"``.
    torque : BodyTorque, SpaceTorque, GravityGradientTorque or None, optional
        External torque (see :mod:`rigid.euler`).  Default None (free body).
    n_out : int, optional
        Number of equally spaced output times, including 0 and ``t_end``
        (fixed-step methods output at the nearest step).  Default 101.
    rtol, atol : float, optional
        Tolerances for ``"dop853"``.
    recentre : float, optional
        Re-centring threshold on |g_0| for ``"cayley_rk4"``.
    progress : bool, optional
        Show a tqdm progress bar (splitting and exact_kick methods; needs the
        ``progress`` extra).

    Returns
    -------
    RigidTrajectory
        In Quantities (``t`` in the unit of ``t_end``, omega in rad/s, moments in
        kg m^2) when the call was; else plain SI floats.

    Raises
    ------
    ValueError
        For ``body`` not a RigidBody, an unknown method, a non-positive or NaN
        ``t_end`` / ``dt``, a missing ``dt``, more than 1e12 steps, ``n_out`` not
        an integer in [2, 1e9], a plain ``dt`` beside a Quantity ``t_end`` (or
        the reverse, or plain times for a body with units), or an unsupported
        torque.
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
    >>> tr = integrate(b, 10.0, dt=0.01, method="splitting2", n_out=3)
    >>> tr.t
    array([ 0.,  5., 10.])
    >>> L = np.linalg.norm(tr.angular_momentum_body, axis=-1)
    >>> bool(np.all(np.abs(L / L[0] - 1.0) < 1e-14))
    True
    """
    body = check_body(body)
    si = body.si
    # a body whose I omega^2 or I omega leaves float64 is refused here
    _ = (si.kinetic_energy, si.angular_momentum_norm)
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"Expected `method` to be one of {METHODS}, got {method!r}")
    quantity = call_units(body, ("t_end", "dt"), (t_end, dt))
    te = _scalar_positive("t_end", TIME("t_end", t_end))
    if method in _FIXED:
        if dt is None:
            raise ValueError(f"Expected `dt` for method {method!r}, got None")
        dtf: float | None = float(_scalar_positive("dt", TIME("dt", dt)))
        if not math.isfinite(te / dtf) or te / dtf > _MAX_STEPS:
            raise ValueError(
                f"Expected `dt` to give at most {_MAX_STEPS:.0e} steps over `t_end`, got "
                f"dt = {dtf!r} s for t_end = {te!r} s"
            )
    else:
        dtf = None
    n_out = _n_out(n_out)
    rtol, atol, recentre = (
        float(_scalar_positive(name, DIMENSIONLESS(name, v)))
        for name, v in (("rtol", rtol), ("atol", atol), ("recentre", recentre))
    )
    kind, params = encode_torque(torque)
    moments, q0, w0 = si.moments, si.attitude, si.omega
    t, q, w, n_steps, count, drift = integrate_arrays(
        moments, q0, w0, te, method=method, dt=dtf, n_out=n_out, kind=kind,
        params=params, rtol=rtol, atol=atol, recentre=recentre, progress=progress,
    )
    bad = ~(np.isfinite(q).all(axis=-1) & np.isfinite(w).all(axis=-1))
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected `dt` small enough for a finite solution, got a non-finite state at "
            f"t = {float(t[k])!r} s with method {method!r} and dt = {dtf!r} s"
        )
    t_unit = t_end.unit if quantity and isinstance(t_end, u.Quantity) else u.s
    return RigidTrajectory(
        t=wrap(t * u.s.to(t_unit), t_unit, quantity),
        attitude=Quaternion(q),
        omega=wrap(w, u.rad / u.s, quantity),
        moments=wrap(moments.copy(), u.kg * u.m**2, quantity),
        method=method,
        n_steps=n_steps,
        n_recentre=count if method == "cayley_rk4" else 0,
        norm_drift=drift,
        nfev=count if method == "dop853" else 0,
    )
