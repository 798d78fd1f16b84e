"""Adaptive 15th-order Gauss-Radau integrator in the manner of IAS15.

Written from Everhart (1985) and Rein & Spiegel (2015), MNRAS 446, 1424
("IAS15"), section numbers below refer to the latter.

Within a step of length ``dt`` the acceleration is the polynomial (eq. 4)

    a(h) = a0 + b0 h + b1 h^2 + ... + b6 h^7,      h = (t - t0) / dt,

or equivalently (eq. 5) in Newton's divided-difference form on the Gauss-Radau
spacings ``h_0 = 0 < h_1 < ... < h_7 < 1``,

    a(h) = a0 + g0 h + g1 h (h - h1) + ... + g6 h (h - h1) ... (h - h6).

Integrating twice gives positions and velocities at the spacings (eqs. 6, 7);
the accelerations there update the ``g`` (and hence ``b``) by a
predictor-corrector iteration (section 2.2) that stops when the relative change
of ``b6`` is below 1e-16 or stops decreasing.  Position and velocity are
accumulated with compensated (Kahan) summation (section 2.4).  The step error is
estimated from the last term, ``max |b6| / max |a|`` over all bodies (the
global criterion of section 3.2), and the next step is
``dt (epsilon / error)^(1/7)`` (eq. 11) with the safety factor 0.25 of IAS15:
a step whose estimate asks for less than a quarter of itself is rejected and
redone, and steps grow by at most a factor 4.  The ``b`` of the next step are
predicted from the converged ones of the last (section 2.5), with the
difference between the last prediction and its converged values added as a
correction.

The whole stepping loop between two output times is one compiled call that
takes the acceleration function as its first argument; the last step before an
output time is shortened to land on it exactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit, types

from hamilton_orbits._validation import ConvergenceError
from hamilton_orbits.integrators import _setup

__all__ = ["ACCEPTS_VELOCITY_DEPENDENT", "DEFAULT_TOL", "NAME", "RADAU_SPACINGS", "run"]

NAME = "radau15"
ACCEPTS_VELOCITY_DEPENDENT = True
DEFAULT_TOL = 1e-9  # IAS15's epsilon (Rein & Spiegel 2015, section 3.2)
#: Step-size criteria: ``"global"`` (Rein & Spiegel 2015, section 3.2) and
#: ``"prs23"`` (Pham, Rein & Spiegel 2024, IAS15's default since rebound 4).
CRITERIA = ("global", "prs23")
DEFAULT_CRITERION = "prs23"

#: Gauss-Radau spacings on [0, 1] (Everhart 1985, table; Rein & Spiegel 2015,
#: section 2.1): ``h_0 = 0`` and the 7 roots of ``P_7(2h - 1) + P_8(2h - 1)``
#: other than ``h = 0`` (``P_n`` Legendre polynomials).
_H_DECIMAL = (
    "0",
    "0.0562625605369221464656521910318",
    "0.180240691736892364987579942780",
    "0.352624717113169637373907769648",
    "0.547153626330555383001448554766",
    "0.734210177215410531523210605558",
    "0.885320946839095768090359771030",
    "0.977520613561287501891174488626",
)
RADAU_SPACINGS = np.array([float(x) for x in _H_DECIMAL])


def _coefficients() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reciprocal differences ``1 / (h_n - h_i)``, and the matrices ``C`` (b = C g) and ``D = C^-1``
    (g = D b), computed exactly in rationals from the 30-digit spacings and
    rounded once: a constant's rounding error is repeated in every step, so
    it must be the smallest possible (a biased constant is a systematic error,
    which breaks Brouwer's law).

    ``C[k, j]`` is the coefficient of ``h^(k+1)`` in ``prod_{m=0..j} (h - h_m)``
    (Rein & Spiegel 2015, eq. 5 expanded into eq. 4).
    """
    from fractions import Fraction

    h = [Fraction(x) for x in _H_DECIMAL]
    rr = np.zeros((8, 8))
    for n in range(1, 8):
        for i in range(n):
            rr[n, i] = float(1 / (h[n] - h[i]))
    c = [[Fraction(0)] * 7 for _ in range(7)]
    for j in range(7):
        poly = [Fraction(1)]  # coefficients, lowest order first
        for m in range(j + 1):
            new = [Fraction(0)] * (len(poly) + 1)
            for p, coef in enumerate(poly):
                new[p] -= h[m] * coef
                new[p + 1] += coef
            poly = new
        for k in range(j + 1):
            c[k][j] = poly[k + 1]
    d = [[Fraction(0)] * 7 for _ in range(7)]
    for j in range(7):
        d[j][j] = Fraction(1)
        for k in range(j - 1, -1, -1):
            d[k][j] = -sum((c[k][m] * d[m][j] for m in range(k + 1, j + 1)), Fraction(0))
    to_array = np.vectorize(float)
    return rr, to_array(np.array(c, dtype=object)), to_array(np.array(d, dtype=object))


_RINV, _C, _D = _coefficients()
_H = RADAU_SPACINGS

_F1 = types.float64[::1]
_F2 = types.float64[:, ::1]

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_UNDERFLOW = 2
STATUS_MAXSTEPS = 3


@njit(cache=True)
def _kahan(p, cs, k, inp):  # pragma: no cover - compiled
    """Compensated ``p[k] += inp`` (the true sum is ``p[k] - cs[k]``)."""
    y = inp - cs[k]
    t = p[k] + y
    cs[k] = (t - p[k]) - y
    p[k] = t


@njit(cache=True)
def _kahan2(p, cs, i, k, inp):  # pragma: no cover - compiled
    """Compensated ``p[i, k] += inp``."""
    y = inp - cs[i, k]
    t = p[i, k] + y
    cs[i, k] = (t - p[i, k]) - y
    p[i, k] = t


@njit(cache=True)
def _predict(q, b, e, br, er):  # pragma: no cover - compiled
    """Predict ``b`` (and save the prediction in ``e``) for a step ``q`` times the
    last completed one, from that step's converged ``br`` and its prediction
    ``er`` (Rein & Spiegel 2015, section 2.5).  ``q > 20``: start from zero."""
    m = b.shape[1]
    if q > 20.0:
        for i in range(7):
            for k in range(m):
                b[i, k] = 0.0
                e[i, k] = 0.0
        return
    q1 = q
    q2 = q1 * q1
    q3 = q2 * q1
    q4 = q2 * q2
    q5 = q4 * q1
    q6 = q3 * q3
    q7 = q6 * q1
    for k in range(m):
        b0 = br[0, k]
        b1 = br[1, k]
        b2 = br[2, k]
        b3 = br[3, k]
        b4 = br[4, k]
        b5 = br[5, k]
        b6 = br[6, k]
        # a(1 + q h') expanded in powers of h'
        e0 = q1 * (7.0 * b6 + 6.0 * b5 + 5.0 * b4 + 4.0 * b3 + 3.0 * b2 + 2.0 * b1 + b0)
        e1 = q2 * (21.0 * b6 + 15.0 * b5 + 10.0 * b4 + 6.0 * b3 + 3.0 * b2 + b1)
        e2 = q3 * (35.0 * b6 + 20.0 * b5 + 10.0 * b4 + 4.0 * b3 + b2)
        e3 = q4 * (35.0 * b6 + 15.0 * b5 + 5.0 * b4 + b3)
        e4 = q5 * (21.0 * b6 + 6.0 * b5 + b4)
        e5 = q6 * (7.0 * b6 + b5)
        e6 = q7 * b6
        b[0, k] = e0 + (b0 - er[0, k])
        b[1, k] = e1 + (b1 - er[1, k])
        b[2, k] = e2 + (b2 - er[2, k])
        b[3, k] = e3 + (b3 - er[3, k])
        b[4, k] = e4 + (b4 - er[4, k])
        b[5, k] = e5 + (b5 - er[5, k])
        b[6, k] = e6 + (b6 - er[6, k])
        e[0, k] = e0
        e[1, k] = e1
        e[2, k] = e2
        e[3, k] = e3
        e[4, k] = e4
        e[5, k] = e5
        e[6, k] = e6


@njit(
    types.Tuple((types.int64, types.int64))(
        _setup.ACCEL_TYPE,
        _F2,
        _F2,
        _F1,
        types.float64,
        _F1,
        _F2,
        _F2,
        _F2,
        _F2,
        _F2,
        _F1,
        _F1,
        types.boolean,
        types.int64,
    ),
    cache=True,
)
def _advance(
    accel, r, v, gm, t_end, st, b, e, br, er, g, csx, csv, need_v, max_steps
):  # pragma: no cover - compiled
    """Step from ``st[0]`` to ``t_end`` in place; returns ``(steps, status)``.

    ``st`` holds ``[t, t_cs, dt, dt_last_done, epsilon, have_last, pc_iters,
    prs23]`` (``epsilon = 0``: fixed steps of ``dt``; ``prs23 != 0``: the step
    criterion of Pham, Rein & Spiegel 2024, else the global one of IAS15).
    ``b, e, br, er, g`` are (7, 3n);
    ``csx, csv`` the Kahan compensations (3n,).  ``r, v`` (n, 3) are updated.
    """
    n = r.shape[0]
    m = 3 * n
    h = _H
    c = _C
    d = _D
    rinv = _RINV
    safety = 0.25
    xf = r.reshape(m)
    vf = v.reshape(m)
    x0 = np.empty(m)
    v0 = np.empty(m)
    a0 = np.empty(m)
    xs = np.empty((n, 3))
    vs = np.empty((n, 3))
    at = np.empty((n, 3))
    a02 = np.empty((n, 3))
    xsf = xs.reshape(m)
    vsf = vs.reshape(m)
    atf = at.reshape(m)
    a0f = a02.reshape(m)
    csx0 = np.empty(m)
    csv0 = np.empty(m)
    t = st[0]
    t_cs = st[1]
    dt = st[2]
    dt_last = st[3]
    eps = st[4]
    have_last = st[5] != 0.0
    adaptive = eps > 0.0
    prs23 = st[7] != 0.0
    steps = 0
    status = 0
    csb = np.zeros((7, m))
    while t < t_end:
        if steps >= max_steps:
            status = STATUS_MAXSTEPS
            break
        remaining = t_end - t
        dt_try = dt
        landing = False
        if dt_try >= remaining:
            dt_try = remaining
            landing = True
        if not (dt_try > 4.0 * 2.220446049250313e-16 * max(abs(t), abs(t_end))):
            if landing and dt_try > 0.0 and dt_try <= dt:
                # a remainder at rounding level of t: finish exactly
                t = t_end
                break
            status = STATUS_UNDERFLOW
            break
        # state at the start of the step
        for k in range(m):
            x0[k] = xf[k]
            v0[k] = vf[k]
            csx0[k] = csx[k]
            csv0[k] = csv[k]
        accel(r, v, gm, a02)
        ok = True
        for k in range(m):
            a0[k] = a0f[k]
            if not math.isfinite(a0[k]):
                ok = False
        if not ok:
            status = STATUS_NONFINITE
            break
        # predicted b for this step, and g from b (g = D b)
        if have_last:
            _predict(dt_try / dt_last, b, e, br, er)
        else:
            for i in range(7):
                for k in range(m):
                    b[i, k] = 0.0
                    e[i, k] = 0.0
        for i in range(7):
            for k in range(m):
                csb[i, k] = 0.0
        for k in range(m):
            for j in range(7):
                acc = b[j, k]
                for i in range(j + 1, 7):
                    acc += d[j, i] * b[i, k]
                g[j, k] = acc
        # predictor-corrector iteration
        pc_err = 2.0
        pc_err_last = 3.0
        iters = 0
        while True:
            if pc_err < 1e-16:
                break
            if iters > 2 and pc_err_last <= pc_err:
                break
            if iters >= 12:
                break
            pc_err_last = pc_err
            iters += 1
            for ns in range(1, 8):
                hn = h[ns]
                # positions at h_n, eq. (6) of Rein & Spiegel (2015) in Horner
                # form (one rounding per coefficient, no large powers)
                k8 = 7.0 * hn / 9.0
                k7 = 3.0 * hn / 4.0
                k6 = 5.0 * hn / 7.0
                k5 = 2.0 * hn / 3.0
                k4 = 3.0 * hn / 5.0
                k3 = hn / 2.0
                k2 = hn / 3.0
                dth = dt_try * hn
                dth2 = dth / 2.0
                for k in range(m):
                    poly = (
                        (
                            (
                                (
                                    (
                                        (((b[6, k] * k8 + b[5, k]) * k7 + b[4, k]) * k6 + b[3, k])
                                        * k5
                                        + b[2, k]
                                    )
                                    * k4
                                    + b[1, k]
                                )
                                * k3
                                + b[0, k]
                            )
                            * k2
                            + a0[k]
                        )
                        * dth2
                        + v0[k]
                    ) * dth
                    xsf[k] = (poly - csx0[k]) + x0[k]
                if need_v:
                    for k in range(m):
                        vsf[k] = (
                            dth
                            * (
                                a0[k]
                                + hn
                                * (
                                    b[0, k] / 2.0
                                    + hn
                                    * (
                                        b[1, k] / 3.0
                                        + hn
                                        * (
                                            b[2, k] / 4.0
                                            + hn
                                            * (
                                                b[3, k] / 5.0
                                                + hn
                                                * (
                                                    b[4, k] / 6.0
                                                    + hn * (b[5, k] / 7.0 + hn * b[6, k] / 8.0)
                                                )
                                            )
                                        )
                                    )
                                )
                            )
                            - csv0[k]
                        ) + v0[k]
                accel(xs, vs, gm, at)
                j = ns - 1
                maxak = 0.0
                maxdb = 0.0
                for k in range(m):
                    gk = atf[k] - a0[k]
                    for i in range(j):
                        gk = gk * rinv[ns, i] - g[i, k]
                    gk = gk * rinv[ns, j]
                    delta = gk - g[j, k]
                    g[j, k] = gk
                    # compensated updates of b (a biased rounding here would
                    # be repeated every step)
                    for i in range(j):
                        _kahan2(b, csb, i, k, c[i, j] * delta)
                    _kahan2(b, csb, j, k, delta)
                    if ns == 7:
                        ak = abs(atf[k])
                        if ak > maxak and ak < math.inf:
                            maxak = ak
                        dk = abs(delta)
                        if dk > maxdb and dk < math.inf:
                            maxdb = dk
                if ns == 7:
                    if maxak > 0.0:
                        pc_err = maxdb / maxak
                    else:
                        pc_err = 0.0
        st[6] += iters
        ok = True
        for k in range(m):
            if not math.isfinite(b[6, k]):
                ok = False
        if not ok:
            status = STATUS_NONFINITE
            break
        dt_done = dt_try
        if adaptive and prs23:
            # Pham, Rein & Spiegel (2024): the shortest timescale
            # tau^2 = 2 |a|^2 / (|a'|^2 + |a| |a''|) over bodies, with a, a', a''
            # from the polynomial at the end of the step (derivatives per unit h)
            min_tau2 = math.inf
            for i in range(n):
                y2 = 0.0
                y3 = 0.0
                y4 = 0.0
                for k in range(3 * i, 3 * i + 3):
                    tmp = (
                        a0[k] + b[0, k] + b[1, k] + b[2, k] + b[3, k] + b[4, k] + b[5, k] + b[6, k]
                    )
                    y2 += tmp * tmp
                    tmp = (
                        b[0, k]
                        + 2.0 * b[1, k]
                        + 3.0 * b[2, k]
                        + 4.0 * b[3, k]
                        + 5.0 * b[4, k]
                        + 6.0 * b[5, k]
                        + 7.0 * b[6, k]
                    )
                    y3 += tmp * tmp
                    tmp = (
                        2.0 * b[1, k]
                        + 6.0 * b[2, k]
                        + 12.0 * b[3, k]
                        + 20.0 * b[4, k]
                        + 30.0 * b[5, k]
                        + 42.0 * b[6, k]
                    )
                    y4 += tmp * tmp
                if not (y2 > 0.0 and y2 < math.inf):
                    continue
                tau2 = 2.0 * y2 / (y3 + math.sqrt(y4 * y2))
                if tau2 > 0.0 and tau2 < min_tau2:
                    min_tau2 = tau2
            if min_tau2 < math.inf:
                dt_new = math.sqrt(min_tau2) * dt_done * (eps * 5040.0) ** (1.0 / 7.0)
            else:
                dt_new = dt_done / safety
        if adaptive and not prs23:
            # Rein & Spiegel (2015), section 3.2: global max |b6| / max |a|
            maxak = 0.0
            maxb6 = 0.0
            for k in range(m):
                ak = abs(atf[k])
                if ak > maxak:
                    maxak = ak
                bk = abs(b[6, k])
                if bk > maxb6:
                    maxb6 = bk
            err = maxb6 / maxak if maxak > 0.0 else 0.0
            if err > 0.0 and math.isfinite(err):
                dt_new = dt_done * (eps / err) ** (1.0 / 7.0)
            else:
                dt_new = dt_done / safety
        if adaptive:
            if dt_new < safety * dt_done:
                # reject: restore the start of the step and try again
                for k in range(m):
                    xf[k] = x0[k]
                    vf[k] = v0[k]
                dt = dt_new
                continue
            # growth limited relative to the step that was planned (a step
            # shortened to land on an output time does not slow the next one)
            base = dt if landing else dt_done
            if dt_new > base / safety:
                dt_new = base / safety
        else:
            dt_new = dt
        # accept: compensated update of positions and velocities (dt^2 is
        # not precomputed: with a fixed step its rounding would be a bias)
        for k in range(m):
            _kahan(xf, csx, k, b[6, k] / 72.0 * dt_done * dt_done)
            _kahan(xf, csx, k, b[5, k] / 56.0 * dt_done * dt_done)
            _kahan(xf, csx, k, b[4, k] / 42.0 * dt_done * dt_done)
            _kahan(xf, csx, k, b[3, k] / 30.0 * dt_done * dt_done)
            _kahan(xf, csx, k, b[2, k] / 20.0 * dt_done * dt_done)
            _kahan(xf, csx, k, b[1, k] / 12.0 * dt_done * dt_done)
            _kahan(xf, csx, k, b[0, k] / 6.0 * dt_done * dt_done)
            _kahan(xf, csx, k, a0[k] / 2.0 * dt_done * dt_done)
            _kahan(xf, csx, k, v0[k] * dt_done)
            _kahan(vf, csv, k, b[6, k] / 8.0 * dt_done)
            _kahan(vf, csv, k, b[5, k] / 7.0 * dt_done)
            _kahan(vf, csv, k, b[4, k] / 6.0 * dt_done)
            _kahan(vf, csv, k, b[3, k] / 5.0 * dt_done)
            _kahan(vf, csv, k, b[2, k] / 4.0 * dt_done)
            _kahan(vf, csv, k, b[1, k] / 3.0 * dt_done)
            _kahan(vf, csv, k, b[0, k] / 2.0 * dt_done)
            _kahan(vf, csv, k, a0[k] * dt_done)
        if landing:
            t = t_end
            t_cs = 0.0
        else:
            y = dt_done - t_cs
            tn = t + y
            t_cs = (tn - t) - y
            t = tn
        for i in range(7):
            for k in range(m):
                br[i, k] = b[i, k]
                er[i, k] = e[i, k]
        dt_last = dt_done
        have_last = True
        dt = dt_new
        steps += 1
    st[0] = t
    st[1] = t_cs
    st[2] = dt
    st[3] = dt_last
    st[5] = 1.0 if have_last else 0.0
    return steps, status


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
    max_steps: int = 100_000_000,
    criterion: str = DEFAULT_CRITERION,
) -> tuple[np.ndarray, np.ndarray, int]:
    """Integrate with the adaptive 15th-order Gauss-Radau scheme (IAS15-like).

    Parameters
    ----------
    rhs : RHS
        The compiled right-hand side (:func:`hamilton_orbits.effects.newtonian_rhs`
        or one composed from listed effects); velocity-dependent effects are
        accepted.
    r0, v0 : ndarray, shape (n, 3)
        Initial positions and velocities (internal units).
    gm : ndarray, shape (n,)
        ``G m`` of each body, ``>= 0`` (0 for test particles).
    t_out : ndarray, shape (n_t,)
        Increasing output times; ``t_out[0]`` is the initial time.
    dt : float, optional
        With ``tol`` unset: fixed step (the last step before each output time
        is shortened to land on it).  With ``tol``: the first trial step.
    tol : float, optional
        IAS15's epsilon for the step control (default 1e-9 when ``dt`` is not
        given either); ``max |b6| / max |a| ~ tol`` per step.
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i`` is reached.
    max_steps : int, optional
        Give up (``ConvergenceError``) after this many steps in one output interval.
    criterion : {"global", "prs23"}, optional
        The step-size control: ``"global"`` estimates the error from the last
        term, ``dt_new = dt (epsilon / (max |b6| / max |a|))^(1/7)`` (Rein &
        Spiegel 2015, eq. 11 with the global estimate of section 3.2);
        ``"prs23"`` sets ``dt_new = (7! epsilon)^(1/7) min tau`` with the
        timescale ``tau^2 = 2 |a|^2 / (|a'|^2 + |a| |a''|)`` of each body at the
        end of the step (Pham, Rein & Spiegel 2024, the criterion rebound's
        IAS15 uses by default), which takes about half the steps on eccentric
        orbits at the same energy error.

    Returns
    -------
    r, v : ndarray, shape (n_t, n, 3)
        States at ``t_out`` (row 0 the initial state).
    steps : int
        Accepted steps taken.

    Raises
    ------
    ValueError
        Non-finite or ill-shaped input, negative ``gm``, non-increasing
        ``t_out``, ``dt <= 0`` or ``tol <= 0``.
    ConvergenceError
        If an acceleration becomes non-finite (a collision) or the step
        underflows, naming the time reached.

    Examples
    --------
    A circular orbit of unit radius (G m = 1) over one period:

    >>> import numpy as np
    >>> from hamilton_orbits.effects import newtonian_rhs
    >>> r0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    >>> v0 = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> r, v, steps = run(newtonian_rhs(), r0, v0, np.array([1.0, 0.0]),
    ...                   np.array([0.0, 2 * np.pi]))
    >>> bool(np.allclose(r[-1], r0, atol=1e-12))
    True
    """
    r0, v0, gm, t_out = _setup.check_inputs(r0, v0, gm, t_out)
    if criterion not in CRITERIA:
        raise ValueError(
            f"Expected `criterion` to be one of {', '.join(map(repr, CRITERIA))}, got {criterion!r}"
        )
    crit = criterion
    dt_f, tol_f = _setup.check_dt_tol(dt, tol)
    if dt_f is None and tol_f is None:
        tol_f = DEFAULT_TOL
    n = r0.shape[0]
    nt = t_out.shape[0]
    r_out = np.empty((nt, n, 3))
    v_out = np.empty((nt, n, 3))
    r_out[0] = r0
    v_out[0] = v0
    if dt_f is None:
        dt_f = _setup.initial_step(r0, v0, gm)
    span = t_out[-1] - t_out[0]
    if span > 0.0:
        dt_f = min(dt_f, span)
    m = 3 * n
    b = np.zeros((7, m))
    e = np.zeros((7, m))
    br = np.zeros((7, m))
    er = np.zeros((7, m))
    g = np.zeros((7, m))
    csx = np.zeros(m)
    csv = np.zeros(m)
    st = np.array([t_out[0], 0.0, dt_f, 0.0, tol_f or 0.0, 0.0, 0.0, float(crit == "prs23")])
    x = np.ascontiguousarray(r0.copy())
    w = np.ascontiguousarray(v0.copy())
    need_v = bool(rhs.velocity_dependent)
    total = 0
    accel = _setup.accel_arg(rhs.accel)
    for i in range(1, nt):
        steps, status = _advance(
            accel, x, w, gm, t_out[i], st, b, e, br, er, g, csx, csv, need_v, max_steps
        )
        total += steps
        if status != STATUS_OK:
            why = {
                STATUS_NONFINITE: "the acceleration became non-finite (a collision?)",
                STATUS_UNDERFLOW: f"the step underflowed (dt = {st[2]!r})",
                STATUS_MAXSTEPS: f"more than max_steps = {max_steps} steps were needed",
            }[status]
            raise ConvergenceError(
                f"radau15 stopped at t = {st[0]!r} before t_out[{i}] = {t_out[i]!r}: {why}"
            )
        r_out[i] = x
        v_out[i] = w
        if on_output is not None:
            on_output(i, total)
    return r_out, v_out, total
