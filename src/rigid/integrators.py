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

This module is the public layer (validation once, units, the deprecated keywords);
each method runs on plain arrays in :mod:`rigid.drivers` (:func:`integrate_arrays`,
re-exported here), and the splittings' compositions (:data:`~rigid.splitting.BM_A`,
:data:`~rigid.splitting.BM_B`, :data:`~rigid.splitting.YOSHIDA_W`) are
:mod:`rigid.splitting`.
"""

from __future__ import annotations

import math
import time
import warnings
from typing import Any, NoReturn

import astropy.units as u
import numpy as np

from hamilton_orbits.quaternion import Quaternion
from hamilton_orbits.units import DIMENSIONLESS, TIME, time_quantity, wrap
from hamilton_orbits.validation import ConvergenceError, as_flag, check_positive
from rigid._kernels import euler as _euler_k
from rigid._shared import free_scale, pow2
from rigid.body import call_units, check_body
from rigid.drivers import METHODS, integrate_arrays
from rigid.euler import (
    BodyTorque,
    GravityGradientTorque,
    SpaceTorque,
    check_torque_units,
    encode_torque,
)
from rigid.splitting import BM_A, BM_B, SPLITTINGS, YOSHIDA_W  # noqa: F401  (their old home)
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

_FIXED = (*SPLITTINGS, "exact_kick", "rk4", "cayley_rk4")


_MAX_STEPS = 1e12  # beyond this a fixed-step run is a typo, not a plan (days of CPU)

#: the largest drift of the attitude quaternion's norm, max | |q| - 1 |, that
#: :func:`integrate` returns without a warning: the exact flow keeps |q| = 1, and a
#: run whose |q| has moved by more (a step far too long for rk4, a loose ``tol``) has
#: an attitude no better than that, which normalising the output would hide
NORM_DRIFT_WARNING = 1e-3


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


def _step(method: str, dt: Any, t_last: float) -> float | None:
    """The step (fixed-step methods, required) or DOP853's step cap (optional), s."""
    if method in _FIXED and dt is None:
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
    stop: Any = None,
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
    t : float, array_like, Quantity or TimeDelta
        An end time (> 0; 101 equally spaced outputs from 0 to it), or the output
        times from the body's state, shape (n,), strictly increasing (a start at
        0 is added if missing).  s for plain floats; a Quantity if ``body`` was
        built from Quantities (an astropy TimeDelta is the Quantity in days it
        holds).
    method : str, optional
        One of ``METHODS`` (see the module docstring).  Default
        ``"splitting4"``.
    dt : float, Quantity or TimeDelta, optional
        Step of the fixed-step methods (required for them), rounded down so that
        a whole number of steps spans the last time; for ``"dop853"`` a cap on
        the step.  A Quantity exactly when ``t`` is one.
    tol : float, optional
        ``"dop853"`` only: its relative tolerance (default 1e-12; the absolute
        tolerance is ``tol / 100`` on the unit quaternion and
        ``tol / 100 max|omega0|`` on omega).  Refused by the fixed-step methods
        (and so are the deprecated ``rtol``, ``atol``).
    torque : BodyTorque, SpaceTorque, GravityGradientTorque or None, optional
        External torque (see :mod:`rigid.euler`).  Default None (free body).  For a
        ``body`` built from Quantities its dimensional values (a ``BodyTorque``'s or
        ``SpaceTorque``'s ``torque``, a gravity gradient's ``gm_over_r3`` and
        ``mean_motion``) are Quantities too: a plain non-zero number is refused (its
        unit cannot be guessed; zeros are taken), as
        ``check_torque_units`` says.
    progress : bool, optional
        Show a tqdm progress bar (needs the ``progress`` extra).
    recentre : float, optional
        Re-centring threshold on ``|g_0|`` for ``"cayley_rk4"``.
    stop : callable, optional
        ``stop()``, asked between chunks of about 1% of the steps (and of at
        most 65 536) by the fixed-step methods, and every 64 steps by
        ``"dop853"`` (their steps and bits unchanged): True ends the run there,
        the trajectory then holding the outputs reached (as a scene does on
        Ctrl-C).

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
        ``t`` (or the reverse, or plain times for a body with units), an
        unsupported torque or one beyond float64 beside the moments, a torque of
        plain non-zero numbers for a body of Quantities (naming the torque's
        argument, the index and the value), a ``stop``
        that is not callable, an angle
        turned ``t |omega|`` beyond float64, or a run whose state leaves float64
        (a step far too long for the method: naming ``dt``).
    hamilton_orbits.validation.ConvergenceError
        For ``"dop853"`` over a span it cannot finish: more than 1e8 steps, or a
        pace after its first steps that projects more than 1e10 (a ValueError).
    astropy.units.UnitConversionError
        For a time of the wrong dimension, naming the argument.

    Warns
    -----
    RuntimeWarning
        When the attitude quaternion's norm drifted by more than
        ``NORM_DRIFT_WARNING`` (1e-3; the trajectory's ``norm_drift``): a step far
        too long for the method, or a loose ``tol``.

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
    progress = as_flag("progress", progress)  # ("no" was a bar: any text is true)
    t, n_out, rtol, atol = _deprecated(t, t_end, n_out, rtol, atol, tol)
    t, dt = time_quantity(t), time_quantity(dt)  # (a TimeDelta: the Quantity in days)
    si = body.si
    # a body whose I omega^2 or I omega leaves float64 is refused here
    _ = (si.kinetic_energy, si.angular_momentum_norm)
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"Expected `method` to be one of {METHODS}, got {method!r}")
    if stop is not None and not callable(stop):
        raise ValueError(f"Expected `stop` to be callable or None, got {stop!r}")
    quantity = call_units(body, ("t", "dt"), (t, dt))
    times = _output_times(TIME("t", t))
    for name, given in (("tol", tol), ("rtol", rtol), ("atol", atol)):
        if given is not None and method in _FIXED:  # (the deprecated ones as `tol`)
            raise ValueError(f"Expected `{name}` only with method 'dop853' (a fixed-step "
                             f"method takes `dt`), got {name} = {given!r} for method "
                             f"{method!r}")
    dtf = _step(method, dt, float(times.max()))
    rtol_f, atol_f = _tolerances(tol, rtol, atol, si.omega)
    recentre = float(_scalar_positive("recentre", DIMENSIONLESS("recentre", recentre)))
    check_torque_units(torque, body.quantity, f"`body` ({body.moments})")
    kind, params = encode_torque(torque)
    moments, params, sw = _scaled_problem(si, kind, params, method, times, dtf)
    start = time.perf_counter()
    asked = _Asked(stop)
    try:
        # a value beyond float64 on the way leaves a non-finite result, refused below
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            t_f, q, w, steps, count, drift = integrate_arrays(
                moments, si.attitude, si.omega / sw, times * sw, method=method,
                dt=None if dtf is None else dtf * sw, n_out=n_out, kind=kind,
                params=params, rtol=rtol_f, atol=atol_f, recentre=recentre,
                progress=progress, stop=None if stop is None else asked,
            )
    except (ZeroDivisionError, ValueError) as exc:
        if exc is asked.raised:  # (the caller's own: not the run's failure)
            raise
        _refuse_failed(exc, method, dtf)
    wall = time.perf_counter() - start
    t_f = t_f / sw
    with np.errstate(over="ignore"):  # a rate beyond float64: refused by _check_finite
        w = w * sw
    _check_finite(t_f, q, w, method, dtf, drift)
    if drift > NORM_DRIFT_WARNING:
        warnings.warn(f"integrate: the attitude quaternion's norm drifted by {drift:.3g} in "
                      f"this {method} run (it is normalised on output): the attitude is no "
                      f"better than that; give a " + ("smaller `tol`" if dtf is None else
                                                      f"shorter `dt` than {dtf!r} s"),
                      RuntimeWarning, stacklevel=2)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        energy_error, am_error = integral_errors(si.moments, q, w)
    if not (np.all(np.isfinite(energy_error)) and np.all(np.isfinite(am_error))):
        raise _failed(method, dtf, "a change of the energy or of L beyond float64")
    t_unit = getattr(t, "unit", u.s) if quantity else u.s
    return RigidTrajectory(
        t=wrap(t_f / t_unit.to(u.s), t_unit, quantity), steps=int(steps), wall_time=wall,
        method=method, energy_error=energy_error, angular_momentum_error=am_error,
        attitude=Quaternion(q), omega=wrap(w, u.rad / u.s, quantity),
        moments=wrap(si.moments, u.kg * u.m**2, quantity),
        n_recentre=count if method == "cayley_rk4" else 0, norm_drift=drift,
        nfev=count if method == "dop853" else 0,
    )


def _scaled_problem(
    si: Any, kind: int, params: np.ndarray, method: str, times: np.ndarray, dt: float | None
) -> tuple[np.ndarray, np.ndarray, float]:
    """``(moments, params, sw)``: the run's moments, torque and rates scaled by powers of
    two (exact: the same bits for every problem whose numbers stay normal).

    Euler's equations ``I omega' = N - omega x I omega`` keep their solution when the
    moments and the torque are scaled alike (the gravity gradient is proportional to
    the moments already): the kernels see moments of order one, and 1e-300 kg m^2 no
    longer underflows.  The motion is also homogeneous in the rates, ``omega(t; s
    omega0) = s omega(s t; omega0)`` with the torque's rates scaled alike (GM/R^3 and a
    constant torque by s^2, the mean motion by s): the kernels see ``omega / sw`` over
    the times ``t sw`` (:func:`_rate_scale`), so 1e-200 rad/s no longer underflows in
    Euler's equations (omega^2), nor 1e154 rad/s overflows.

    Raises
    ------
    ValueError
        If the torque is beyond float64 beside the moments (``torque``), or the angle
        turned is (``t``).
    """
    sm = pow2(si.moments)
    if kind in (_euler_k.TORQUE_BODY, _euler_k.TORQUE_SPACE):
        with np.errstate(over="ignore"):
            scaled = params / sm
        if not np.all(np.isfinite(scaled)):
            raise ValueError(f"Expected `torque` / the moments within float64, got torque "
                             f"{params.tolist()} N m beside moments {si.moments.tolist()} "
                             f"kg m^2")
        params = scaled
    moments = si.moments / sm
    sw = _rate_scale(moments, si.omega, kind, params, method, times, dt)
    if sw != 1.0:
        params = params.copy()
        if kind == _euler_k.TORQUE_GRAVITY_GRADIENT:
            params[0] = params[0] / sw / sw  # GM / R^3, a rate squared
            params[1] = params[1] / sw  # the mean motion
        elif kind != _euler_k.TORQUE_NONE:
            params[:3] = params[:3] / sw / sw  # N / I, a rate squared
    return moments, params, sw


def _rate_scale(moments: np.ndarray, omega: np.ndarray, kind: int, params: np.ndarray,
                method: str, times: np.ndarray, dt: float | None) -> float:
    """The power of two ``sw`` by which the kernels take the rates (1: unscaled).

    The free body: :func:`rigid._shared.free_scale` (the largest rate in [1, 2),
    smaller for a needle whose polhode would underflow); with a torque the largest of
    ``|omega|``, ``sqrt(GM / R^3)``, ``n`` and ``sqrt(|N| / I)``.  The step stays a
    normal number (a rate of 1e-300 rad/s over steps of 1e-300 s turns by 1e-600 rad:
    the kernels then see smaller rates instead).  DOP853's step-size heuristics hold
    absolute constants: its rates are scaled only beyond 2^-64 .. 2^64.

    Raises
    ------
    ValueError
        If ``t`` times ``|omega|`` or the torque's rate, the angle turned, is beyond
        float64, naming ``t``.
    """
    if kind == _euler_k.TORQUE_NONE:
        sw = free_scale(moments, omega, "`body`")
    else:
        rates = [float(np.max(np.abs(omega)))]
        if kind == _euler_k.TORQUE_GRAVITY_GRADIENT:
            rates += [math.sqrt(params[0]), abs(params[1])]
        else:
            rates.append(math.sqrt(np.max(np.abs(params[:3]))) / math.sqrt(np.min(moments)))
        sw = pow2(np.array(rates))
    if method not in _FIXED and 2.0**-64 <= sw <= 2.0**64:
        return 1.0
    t_end = float(times.max())
    shortest = t_end if dt is None or method not in _FIXED else min(t_end, dt / 4.0)
    floor = math.ldexp(1.0, -960) / shortest  # no step of a fixed-step run is below dt / 4
    if sw < floor:
        sw = 2.0 * pow2(np.array([floor]))
    rate = max(pow2(omega), sw)  # |omega|, or the torque's rate where that is faster
    if not math.isfinite(t_end * rate):
        raise ValueError(f"Expected `t` * |omega| to be finite (the angle turned), got "
                         f"t = {t_end!r} s with |omega| (or the torque's rate) ~ {rate!r} "
                         f"rad/s")
    return sw


class _Asked:
    """``stop`` asked, the exception it raised (if any) kept: told apart from the
    run's own failures, it reaches the caller as it is."""

    __slots__ = ("raised", "stop")

    def __init__(self, stop: Any) -> None:
        self.stop, self.raised = stop, None

    def __call__(self) -> Any:
        try:
            return self.stop()
        except BaseException as exc:
            self.raised = exc
            raise


def _refuse_failed(exc: ZeroDivisionError | ValueError, method: str, dt: Any) -> NoReturn:
    """Raise the refusal of a run that failed with ``exc``."""
    if isinstance(exc, ZeroDivisionError):  # a kernel's state left float64 (norm 0 or inf)
        raise _failed(method, dt, "a division by zero in the kernel") from None
    if isinstance(exc, ConvergenceError):  # DOP853's step budget (times in the scaled unit)
        raise ConvergenceError(f"method 'dop853' cannot finish this span: {exc}") from None
    if method != "dop853":  # pragma: no cover - the fixed-step drivers raise none
        raise exc
    raise _failed(method, dt, str(exc)) from None  # (scipy's step size collapsed)


def _failed(method: str, dt: Any, what: str) -> ValueError:
    """The refusal of a run whose state left float64 (a step far too long)."""
    if method == "dop853":
        return ValueError(f"Expected `tol` and `dt` within DOP853's reach, got {what}")
    if method == "exact_kick":  # its drift is the exact flow: a state beyond its range
        return ValueError(f"Expected `body` and `torque` within the range of the exact free "
                          f"flow of method 'exact_kick' (dt = {dt!r} s), got {what}")
    return ValueError(f"Expected `dt` small enough for a representable solution, got {what} "
                      f"with method {method!r} and dt = {dt!r} s")


def _check_finite(t: np.ndarray, q: np.ndarray, w: np.ndarray, method: str, dt: Any,
                  drift: float) -> None:
    bad = ~(np.isfinite(q).all(axis=-1) & np.isfinite(w).all(axis=-1))
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        hint = ("" if method != "cayley_rk4" else
                " (or a `recentre` of about 1: Cayley's parameters grow without bound as "
                "the attitude nears a half turn from its offset)")
        raise ValueError(
            f"Expected `dt` small enough for a finite solution, got a non-finite state at "
            f"t = {float(t[k])!r} s with method {method!r} and dt = {dt!r} s{hint}"
        )
    if not math.isfinite(drift):
        raise _failed(method, dt, "|q| beyond float64 (its norm drift)")
