"""The compiled step of the 15th-order Gauss-Radau integrator (IAS15-like).

The driver is :mod:`hamilton_orbits.integrators.radau15`; the method and its
references are described there.  This module holds the arithmetic: the
predictor of the ``b`` coefficients (Rein & Spiegel 2015, section 2.5), the
predictor-corrector iteration over the Gauss-Radau spacings (eqs. 4-7, section
2.2), the two step-size rules (section 3.2, and Pham, Rein & Spiegel 2024), the
compensated update of the state (section 2.4), and :func:`advance`, the loop
over steps between two output times.

Every function takes plain float64 arrays; the acceleration is a first-class
function ``accel(r, v, gm, acc, p)`` of the type
:data:`hamilton_orbits._kernels.signatures.ACCEL_TYPE` (by its addresses), so :func:`advance` is
compiled once and cached for every right-hand side.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels import events as _ev
from hamilton_orbits._kernels.entry import entry
from hamilton_orbits._kernels.gauss_radau import exact_tables
from hamilton_orbits._kernels.records import (
    P_EVERY,
    P_LAND,
    P_NEXT,
    P_WRITER,
    next_landing,
    record_at,
)
from hamilton_orbits._kernels.signatures import ADDRESSES, accel_at, set_clock
from hamilton_orbits._kernels.variational import megno_update

__all__ = [
    "DECIMAL_SPACINGS",
    "NSTATE",
    "STATUS_DRAIN",
    "STATUS_EVENT",
    "STATUS_MAXSTEPS",
    "STATUS_NONFINITE",
    "STATUS_OK",
    "STATUS_UNDERFLOW",
    "ST_DT",
    "ST_DT_LAST",
    "ST_EPSILON",
    "ST_EVENT_ROW",
    "ST_HAVE_LAST",
    "ST_PC_ITERS",
    "ST_PRS23",
    "ST_T",
    "ST_T_CS",
    "advance",
    "advance_variational",
    "advance_watched",
    "coefficients",
    "radau_weights",
]

#: Gauss-Radau spacings on [0, 1] (Everhart 1985, table; Rein & Spiegel 2015,
#: section 2.1): ``h_0 = 0`` and the 7 roots of ``P_7(2h - 1) + P_8(2h - 1)``
#: other than ``h = 0`` (``P_n`` Legendre polynomials).
DECIMAL_SPACINGS = (
    "0",
    "0.0562625605369221464656521910318",
    "0.180240691736892364987579942780",
    "0.352624717113169637373907769648",
    "0.547153626330555383001448554766",
    "0.734210177215410531523210605558",
    "0.885320946839095768090359771030",
    "0.977520613561287501891174488626",
)

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_UNDERFLOW = 2
STATUS_MAXSTEPS = 3
#: An event with an action (stop, merge, remove) occurred: the state is at its
#: time and ``st[ST_EVENT_ROW]`` holds its watch row.
STATUS_EVENT = 4
#: The event buffer may not hold another step's events: drain it and call again.
STATUS_DRAIN = 5

#: The integrator state ``st`` that :func:`advance` reads and updates, slot by slot:
#: the time, its Kahan compensation, the next step, the last step done, epsilon (0:
#: fixed steps), whether a last step exists (for the predictor), the
#: predictor-corrector rounds so far, the criterion (1: prs23, 0: global), and the
#: watch row of the event that stopped a call.
ST_T, ST_T_CS, ST_DT, ST_DT_LAST, ST_EPSILON, ST_HAVE_LAST, ST_PC_ITERS, ST_PRS23, \
    ST_EVENT_ROW = range(9)
NSTATE = 9

_SAFETY = 0.25  # IAS15's safety factor: reject below a quarter, grow at most 4x
# These kernels keep numba's default (Python) error model, measured 10% faster here
# than numpy's; every division is guarded instead (a ZeroDivisionError raised
# inside a compiled kernel would be lost, not reported).
_EPS = 2.220446049250313e-16


def coefficients() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reciprocal differences ``1 / (h_n - h_i)``, and the matrices ``C`` (b = C g)
    and ``D = C^-1`` (g = D b), computed exactly in rationals from the 30-digit
    spacings and rounded once: a constant's rounding error is repeated in every
    step, so it must be the smallest possible (a biased constant is a systematic
    error, which breaks Brouwer's law).  The rationals come from
    :func:`~hamilton_orbits._kernels.gauss_radau.exact_tables`.
    """
    recip, c, d = exact_tables([Fraction(x) for x in DECIMAL_SPACINGS])
    to_array = np.vectorize(float)
    return tuple(to_array(np.array(t, dtype=object)) for t in (recip, c, d))


_RINV, _C, _D = coefficients()
_H = np.array([float(x) for x in DECIMAL_SPACINGS])

_F1 = types.float64[::1]
_F2 = types.float64[:, ::1]


@njit(cache=True, inline="always")
def _kahan(p, cs, k, inp):  # pragma: no cover - compiled
    """Compensated ``p[k] += inp`` (the true sum is ``p[k] - cs[k]``)."""
    y = inp - cs[k]
    t = p[k] + y
    cs[k] = (t - p[k]) - y
    p[k] = t


@njit(cache=True, inline="always")
def _kahan2(p, cs, i, k, inp):  # pragma: no cover - compiled
    """Compensated ``p[i, k] += inp``."""
    y = inp - cs[i, k]
    t = p[i, k] + y
    cs[i, k] = (t - p[i, k]) - y
    p[i, k] = t


@njit(cache=True, inline="always")
def _predicted(q, br, k):  # pragma: no cover - compiled
    """The prediction of component ``k``'s ``b`` for a step ``q`` times the last
    completed one, from that step's converged ``br`` (Rein & Spiegel 2015, section
    2.5): ``a(1 + q h')`` expanded in powers of ``h'``."""
    q2 = q * q
    q3 = q2 * q
    q4 = q2 * q2
    q5 = q4 * q
    q6 = q3 * q3
    q7 = q6 * q
    b0, b1, b2, b3 = br[0, k], br[1, k], br[2, k], br[3, k]
    b4, b5, b6 = br[4, k], br[5, k], br[6, k]
    return (q * (7.0 * b6 + 6.0 * b5 + 5.0 * b4 + 4.0 * b3 + 3.0 * b2 + 2.0 * b1 + b0),
            q2 * (21.0 * b6 + 15.0 * b5 + 10.0 * b4 + 6.0 * b3 + 3.0 * b2 + b1),
            q3 * (35.0 * b6 + 20.0 * b5 + 10.0 * b4 + 4.0 * b3 + b2),
            q4 * (35.0 * b6 + 15.0 * b5 + 5.0 * b4 + b3),
            q5 * (21.0 * b6 + 6.0 * b5 + b4),
            q6 * (7.0 * b6 + b5),
            q7 * b6)


@njit(cache=True, inline="always")
def _predict(q, b, br, d):  # pragma: no cover - compiled
    """Predict ``b`` for a step ``q`` times the last completed one: the prediction
    from that step's converged ``br`` plus ``d``, the difference between ``br`` and
    the prediction it had started from (Rein & Spiegel 2015, section 2.5).  ``q >
    20``: start from zero."""
    m = b.shape[1]
    if q > 20.0:
        b[:, :] = 0.0
        return
    for k in range(m):
        e = _predicted(q, br, k)
        for i in range(7):
            b[i, k] = e[i] + d[i, k]


@njit(cache=True, inline="always")
def _keep(q, predicted, b, br, d):  # pragma: no cover - compiled
    """At an accepted step: ``d = b - prediction`` (the prediction recomputed from
    the old ``br`` with the same ``q``, rather than stored: 7 numbers a component
    fewer; zero when the step started from zero) and ``br = b``."""
    for k in range(b.shape[1]):
        if predicted:
            e = _predicted(q, br, k)
            for i in range(7):
                d[i, k] = b[i, k] - e[i]
        else:
            for i in range(7):
                d[i, k] = b[i, k]
        for i in range(7):
            br[i, k] = b[i, k]


@njit(cache=True, inline="always")
def _g_from_b(b, g):  # pragma: no cover - compiled
    """``g = D b`` (Rein & Spiegel 2015, eq. 5 from eq. 4)."""
    for k in range(b.shape[1]):
        for j in range(7):
            acc = b[j, k]
            for i in range(j + 1, 7):
                acc += _D[j, i] * b[i, k]
            g[j, k] = acc


@njit(cache=True, inline="always")
def _positions_at(hn, dt, b, a0, v0, x0, csx0, xs):  # pragma: no cover - compiled
    """Positions at spacing ``hn``, eq. (6) of Rein & Spiegel (2015) in Horner form
    (one rounding per coefficient, no large powers)."""
    k8 = 7.0 * hn / 9.0
    k7 = 3.0 * hn / 4.0
    k6 = 5.0 * hn / 7.0
    k5 = 2.0 * hn / 3.0
    k4 = 3.0 * hn / 5.0
    k3 = hn / 2.0
    k2 = hn / 3.0
    dth = dt * hn
    dth2 = dth / 2.0
    for k in range(xs.shape[0]):
        poly = (((b[6, k] * k8 + b[5, k]) * k7 + b[4, k]) * k6 + b[3, k]) * k5 + b[2, k]
        poly = ((poly * k4 + b[1, k]) * k3 + b[0, k]) * k2 + a0[k]
        xs[k] = ((poly * dth2 + v0[k]) * dth - csx0[k]) + x0[k]


@njit(cache=True, inline="always")
def _velocities_at(hn, dt, b, a0, v0, csv0, vs):  # pragma: no cover - compiled
    """Velocities at spacing ``hn``, eq. (7) of Rein & Spiegel (2015) in Horner form."""
    dth = dt * hn
    for k in range(vs.shape[0]):
        poly = b[4, k] / 6.0 + hn * (b[5, k] / 7.0 + hn * b[6, k] / 8.0)
        poly = b[2, k] / 4.0 + hn * (b[3, k] / 5.0 + hn * poly)
        poly = b[0, k] / 2.0 + hn * (b[1, k] / 3.0 + hn * poly)
        vs[k] = (dth * (a0[k] + hn * poly) - csv0[k]) + v0[k]


@njit(cache=True, inline="always")
def _correct(ns, at, a0, g, b, csb):  # pragma: no cover - compiled
    """Update ``g[ns - 1]`` from the acceleration ``at`` at spacing ``ns`` and
    carry the change into ``b`` with compensated sums (a biased rounding here
    would be repeated every step).  At ``ns = 7`` returns ``max |delta g|`` and
    ``max |at|`` over finite components (the convergence measure), else zeros."""
    j = ns - 1
    maxak = 0.0
    maxdb = 0.0
    for k in range(at.shape[0]):
        gk = at[k] - a0[k]
        for i in range(j):
            gk = gk * _RINV[ns, i] - g[i, k]
        gk = gk * _RINV[ns, j]
        delta = gk - g[j, k]
        g[j, k] = gk
        for i in range(j + 1):  # _C[j, j] = 1 (a monic polynomial): delta itself
            _kahan2(b, csb, i, k, _C[i, j] * delta)
        if ns == 7:  # the convergence measure, on the last substep only
            ak = abs(at[k])
            if ak > maxak and ak < math.inf:
                maxak = ak
            dk = abs(delta)
            if dk > maxdb and dk < math.inf:
                maxdb = dk
    return maxdb, maxak


@njit(cache=True, inline="always")
def _iterate(accel, p, gm, t, dt, b, g, csb, a0, x0, v0, csx0, csv0, xs, vs, at, need_v):
    # pragma: no cover - compiled
    """The predictor-corrector iteration of one step from ``t`` (Rein & Spiegel 2015,
    section 2.2): stops when ``max |delta b6| / max |a|`` falls below 1e-16 or
    stops decreasing (after 2 iterations), or after 12.  Returns the iterations.
    ``xs``, ``vs``, ``at`` are (n, 3) work arrays (their flat views are used)."""
    m = a0.shape[0]
    xsf = xs.reshape(m)
    vsf = vs.reshape(m)
    atf = at.reshape(m)
    pc_err = 2.0
    pc_err_last = 3.0
    iters = 0
    while pc_err >= 1e-16 and iters < 12 and not (iters > 2 and pc_err_last <= pc_err):
        pc_err_last = pc_err
        iters += 1
        for ns in range(1, 8):
            _positions_at(_H[ns], dt, b, a0, v0, x0, csx0, xsf)
            if need_v:
                _velocities_at(_H[ns], dt, b, a0, v0, csv0, vsf)
            set_clock(p, t + _H[ns] * dt)
            accel(xs, vs, gm, at, p)
            maxdb, maxak = _correct(ns, atf, a0, g, b, csb)
        pc_err = maxdb / maxak if maxak > 0.0 else 0.0
    return iters


@njit(cache=True, inline="always")
def _prs23_sums(a0, b, i, f):  # pragma: no cover - compiled
    """Body ``i``'s ``|a0|^2`` and the ``|a|^2``, ``|a'|^2``, ``|a''|^2`` of the
    polynomial at the end of the step, every component multiplied by ``f`` before
    it is squared (``f = 1``: the plain sums), and the largest magnitude of those
    components before ``f``."""
    a0i = 0.0
    y2 = 0.0
    y3 = 0.0
    y4 = 0.0
    top = 0.0
    for k in range(3 * i, 3 * i + 3):
        tmp = a0[k]
        top = max(top, abs(tmp))
        tmp *= f
        a0i += tmp * tmp
        tmp = a0[k] + b[0, k] + b[1, k] + b[2, k] + b[3, k] + b[4, k] + b[5, k] + b[6, k]
        top = max(top, abs(tmp))
        tmp *= f
        y2 += tmp * tmp
        tmp = (b[0, k] + 2.0 * b[1, k] + 3.0 * b[2, k] + 4.0 * b[3, k] + 5.0 * b[4, k]
               + 6.0 * b[5, k] + 7.0 * b[6, k])
        top = max(top, abs(tmp))
        tmp *= f
        y3 += tmp * tmp
        tmp = (2.0 * b[1, k] + 6.0 * b[2, k] + 12.0 * b[3, k] + 20.0 * b[4, k]
               + 30.0 * b[5, k] + 42.0 * b[6, k])
        top = max(top, abs(tmp))
        tmp *= f
        y4 += tmp * tmp
    return a0i, y2, y3, y4, top


@njit(cache=True, inline="always")
def _squares_ok(a0i, y2, y3, y4):  # pragma: no cover - compiled
    """Whether the sums of :func:`_prs23_sums` neither over- nor underflowed."""
    return (2.2250738585072014e-308 <= a0i < math.inf
            and 2.2250738585072014e-308 <= y2 < math.inf and y3 < math.inf
            and (y4 == 0.0 or 2.2250738585072014e-308 <= y4 * y2 < math.inf))


@njit(cache=True, inline="always")
def _tau2(a0, b, i):  # pragma: no cover - compiled
    """Body ``i``'s ``tau^2`` of :func:`_dt_prs23` (inf where it is left out), and the
    squares of its acceleration at the end and at the start of the step and of its
    derivative per unit step (each component scaled alike, by 1 or the power of two
    that keeps the squares within float64)."""
    if a0[3 * i] == 0.0 and a0[3 * i + 1] == 0.0 and a0[3 * i + 2] == 0.0:
        return math.inf, 0.0, 0.0, 0.0
    f = 1.0
    for attempt in range(2):  # one call site (inlined once): plain, then scaled
        a0i, y2, y3, y4, top = _prs23_sums(a0, b, i, f)
        if attempt == 1 or _squares_ok(a0i, y2, y3, y4):
            break
        if not (top > 0.0 and top < math.inf):
            return math.inf, 0.0, 0.0, 0.0
        f = math.ldexp(1.0, -math.frexp(top)[1])
    if not (a0i >= 2.2250738585072014e-308 and a0i < math.inf):
        return math.inf, 0.0, 0.0, 0.0
    if not (y2 > 0.0 and y2 < math.inf):
        return math.inf, 0.0, 0.0, 0.0
    den = y3 + math.sqrt(y4 * y2)
    if not den > 0.0:  # a constant acceleration: no timescale (no division by 0)
        return math.inf, 0.0, 0.0, 0.0
    tau2 = 2.0 * y2 / den
    return tau2 if tau2 > 0.0 else math.inf, y2, a0i, y3


#: a body whose acceleration is falling and, at the pace it falls, would reach zero
#: within this many roundings of ``t`` is at a zero crossing of its acceleration
#: (:func:`_dt_prs23`; at the step's underflow, each step a quarter of what is left
#: to the crossing, it is there within about 16)
_CROSSING = 64.0 * _EPS
#: a body whose acceleration (its largest component) is at most this fraction of the
#: largest body's is left out of :func:`_dt_prs23`'s timescale: such an acceleration
#: is most often the rounding residue of pulls that cancel (the central body of a
#: point-symmetric system: 1e-19 of its planets' 1), whose ``tau`` measures noise and
#: sent the step to underflow at the start, as IAS15's does.  The price: a body whose
#: acceleration is physical and that small while its pace is the fastest (a subsystem
#: 1e14 times smaller in its accelerations than the rest and faster than it, e.g. a
#: particle 1e-17 from a body of GM 1e-48 beside a pair of GM 1 at 1e8) no longer sets
#: the step, and is integrated at the pace of the others (the global criterion,
#: ``Radau15(criterion="global")``, still follows it)
_RESIDUE = 64.0 * _EPS


@njit(cache=True, inline="always")
def _dt_prs23(a0, b, n, dt_done, eps, t):  # pragma: no cover - compiled
    """Pham, Rein & Spiegel (2024): the shortest timescale ``tau^2 = 2 |a|^2 / (|a'|^2 +
    |a| |a''|)`` over bodies, with ``a, a', a''`` from the polynomial at the end of the
    step (derivatives per unit h).  A body whose acceleration at the start of the step
    is zero (the third body of the figure-eight at t = 0, a body at an equilibrium) is
    left out, as rebound's IAS15 does: its timescale measures the zero crossing of
    ``a``, not a fast motion; so is a body whose acceleration is within :data:`_RESIDUE`
    of zero relative to the largest (the rounding residue of pulls that cancel).  Where
    the squares over- or underflow (a system of a very small or very large length scale:
    accelerations beyond 1e150 or below 1e-150) the components are first scaled by a
    power of two (``tau`` is a ratio, the scale cancels), so that the step follows the
    motion at every scale instead of leaving the body out.

    A body whose acceleration passes through zero elsewhere (a particle crossing
    the midpoint of a pair, Sitnikov's problem) has ``tau -> 0`` as the step's end
    nears the crossing: each step covers a quarter of what is left to it, and the
    steps fall to the rounding of ``t`` without reaching it (rebound's IAS15 then
    takes thousands of steps that do not advance ``t``).  Where the step would no
    longer advance the time it starts from (``t``, the start of the step just taken,
    where it is rejected and taken again; its end otherwise), the bodies at such a
    crossing (an acceleration that fell over the step and, at that pace, reaches zero
    within :data:`_CROSSING` of ``t``: ``|a| dt / |a' dt| <= 64 eps |t|``, a test
    free of the system's scale and of ``t``'s) are left out and the step is that of
    the others; a collision (accelerations that grow) or a tolerance below rounding
    (accelerations far from zero) still underflow, as before.  Elsewhere the rule
    is the paper's, to the bit.  Returns the next step."""
    min_tau2 = math.inf
    min_rest = math.inf  # (over the bodies not at a crossing)
    near = (_CROSSING * abs(t) / dt_done) ** 2  # (the crossing's test, in squares)
    top = 0.0
    for k in range(3 * n):
        top = max(top, abs(a0[k]))
    residue = _RESIDUE * top if top < math.inf else 0.0
    for i in range(n):
        if max(abs(a0[3 * i]), abs(a0[3 * i + 1]), abs(a0[3 * i + 2])) <= residue:
            continue  # (a rounding residue: see _RESIDUE)
        tau2, y2, a0i, y3 = _tau2(a0, b, i)
        if tau2 < min_tau2:
            min_tau2 = tau2
        if tau2 < min_rest and not (y2 < a0i and y2 <= y3 * near):
            min_rest = tau2
    if min_tau2 < math.inf:
        dt_new = math.sqrt(min_tau2) * dt_done * (eps * 5040.0) ** (1.0 / 7.0)
        start = t if dt_new < _SAFETY * dt_done else t + dt_done  # (:func:`_next_dt`)
        if dt_new <= 4.0 * _EPS * abs(start) and min_rest < math.inf:  # (as
            # :func:`_try_length` would refuse it)
            return math.sqrt(min_rest) * dt_done * (eps * 5040.0) ** (1.0 / 7.0)
        return dt_new
    return dt_done / _SAFETY


@njit(cache=True, inline="always")
def _dt_global(at, b, x, v, n, dt_done, eps):  # pragma: no cover - compiled
    """Rein & Spiegel (2015), section 3.2: ``dt (eps / (max |b6| / max |a|))^(1/7)``
    over the normal components, leaving out bodies whose acceleration varies
    slowly over the step (``|v|^2 dt^2 / |x|^2 < 1e-16``, as rebound's IAS15
    does: their ``b6`` is rounding noise).  Returns the next step."""
    maxak = 0.0
    maxb6 = 0.0
    for i in range(n):
        v2 = v[3 * i] ** 2 + v[3 * i + 1] ** 2 + v[3 * i + 2] ** 2
        x2 = x[3 * i] ** 2 + x[3 * i + 1] ** 2 + x[3 * i + 2] ** 2
        if v2 * dt_done * dt_done < 1e-16 * x2:
            continue
        for k in range(3 * i, 3 * i + 3):
            ak = abs(at[k])
            if ak >= 2.2250738585072014e-308 and ak < math.inf and ak > maxak:
                maxak = ak
            bk = abs(b[6, k])
            if bk >= 2.2250738585072014e-308 and bk < math.inf and bk > maxb6:
                maxb6 = bk
    err = maxb6 / maxak if maxak > 0.0 else 0.0
    if err > 0.0 and err < math.inf:
        return dt_done * (eps / err) ** (1.0 / 7.0)
    return dt_done / _SAFETY


#: ``b[j] / _XDIV[j]`` and ``b[j] / _VDIV[j]``: the coefficients of eqs. (6) and (7) of
#: Rein & Spiegel (2015) at ``h = 1``
_XDIV = np.array([6.0, 12.0, 20.0, 30.0, 42.0, 56.0, 72.0])
_VDIV = np.array([2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0])


@njit(cache=True, inline="always")
def _accept(x, v, csx, csv, b, a0, v0, dt):  # pragma: no cover - compiled
    """Compensated update of positions and velocities at the end of an accepted
    step, the smallest terms first (``dt^2`` is not precomputed: with a fixed step
    its rounding would be a bias).  ``v0`` may be ``v`` itself: each component's
    position is updated before its velocity."""
    for k in range(x.shape[0]):
        for j in range(6, -1, -1):
            _kahan(x, csx, k, b[j, k] / _XDIV[j] * dt * dt)
        _kahan(x, csx, k, a0[k] / 2.0 * dt * dt)
        _kahan(x, csx, k, v0[k] * dt)
        for j in range(6, -1, -1):
            _kahan(v, csv, k, b[j, k] / _VDIV[j] * dt)
        _kahan(v, csv, k, a0[k] * dt)


@njit(cache=True, inline="always")
def _all_finite(x):  # pragma: no cover - compiled
    for k in range(x.shape[0]):
        if not math.isfinite(x[k]):
            return False
    return True


@njit(cache=True, inline="always")
def _start_step(accel, p, r, v, gm, a0_2, x0, v0):  # pragma: no cover - compiled
    """Evaluate the acceleration at the start of a step into ``a0_2`` (n, 3) and,
    when events are watched (``x0``, ``v0`` not empty), save the start state for
    their scan; returns whether the acceleration is finite.  (The state itself is
    not changed before the step is accepted, so a rejected step needs no
    restoring and the iteration reads the start state from ``r``, ``v``.)"""
    m = a0_2.shape[0] * 3
    if x0.shape[0] > 0:
        xf = r.reshape(m)
        vf = v.reshape(m)
        for k in range(m):
            x0[k] = xf[k]
            v0[k] = vf[k]
    accel(r, v, gm, a0_2, p)
    return _all_finite(a0_2.reshape(m))


@njit(cache=True, inline="always")
def _try_length(t, t_end, dt):  # pragma: no cover - compiled
    """The next step's length (``dt``, or what is left to ``t_end``), whether it
    lands on ``t_end``, and ``0`` to take it, ``1`` when what is left is at the
    rounding level of ``t`` (finish exactly at ``t_end``), ``2`` when the step
    would not advance ``t`` (an underflow)."""
    dt_try = min(dt, t_end - t)
    landing = dt_try == t_end - t
    if dt_try > 4.0 * _EPS * abs(t):
        return dt_try, landing, 0
    if landing and dt_try > 0.0 and dt_try <= dt:
        return dt_try, landing, 1
    return dt_try, landing, 2


@njit(cache=True, inline="always")
def _begin(accel, p, r, v, gm, a0_2, x0, v0, t, q, b, br, d, g, csb):
    # pragma: no cover - compiled
    """A step's attempt from ``t`` up to its predictor-corrector iteration: the
    start's accelerations, ``b`` predicted from the last step (:func:`_predict`,
    ``q`` the ratio of the step lengths; zero after a change of more than 20x).
    False when an acceleration is not finite."""
    set_clock(p, t)
    if not _start_step(accel, p, r, v, gm, a0_2, x0, v0):
        return False
    if q <= 20.0:
        _predict(q, b, br, d)
    else:
        b[:, :] = 0.0
    csb[:, :] = 0.0
    _g_from_b(b, g)
    return True


@njit(cache=True, inline="always")
def _corrected(accel, p, r, v, gm, a0_2, x0, v0, t, dt_try, q, st, b, br, d, g, csb, a0, xf,
               vf, csx, csv, xs, vs, at, need_v):  # pragma: no cover - compiled
    """One step's attempt from ``t`` up to its acceptance test (:func:`_begin`, then
    the iteration, its rounds counted in ``st[ST_PC_ITERS]``).  False when a number
    is not finite."""
    if not _begin(accel, p, r, v, gm, a0_2, x0, v0, t, q, b, br, d, g, csb):
        return False
    st[ST_PC_ITERS] += _iterate(accel, p, gm, t, dt_try, b, g, csb, a0, xf, vf, csx, csv, xs, vs,
                                at, need_v)
    return _all_finite(b[6])


@njit(cache=True)
def _next_dt(st, a0, b, at, r, v, dt_done, dt, landing, t):  # pragma: no cover - compiled
    """The step after one of ``dt_done`` (planned ``dt``) begun at ``t``, and whether to
    accept it.
    (Called from the loop, not inlined: inlined, its two rules cost 0.5 s more of
    a first run's compilation; called once a step, the call costs nothing measurable.)

    Adaptive (``st[ST_EPSILON] > 0``): rejects when the rule asks for less than a quarter
    of the step; growth is limited to 4x relative to the step that was planned
    (a step shortened to land on an output time does not slow the next one)."""
    eps = st[ST_EPSILON]
    if not eps > 0.0:
        return dt, True
    n = r.shape[0]
    m = 3 * n
    if st[ST_PRS23] != 0.0:
        dt_new = _dt_prs23(a0, b, n, dt_done, eps, t)
    else:
        dt_new = _dt_global(at.reshape(m), b, r.reshape(m), v.reshape(m), n, dt_done, eps)
    if dt_new < _SAFETY * dt_done:
        return dt_new, False
    base = dt if landing else dt_done
    return min(dt_new, base / _SAFETY), True


@njit(cache=True, inline="always")
def _after_step(t, t_cs, dt_try, t_end, landing, q, b, br, d):  # pragma: no cover - compiled
    """The time after an accepted step (exactly ``t_end`` when it landed there, else
    with Kahan's compensation ``t_cs``), and the step's ``b`` kept for the next
    prediction (:func:`_keep`)."""
    if landing:
        t = t_end
        t_cs = 0.0
    else:
        y = dt_try - t_cs
        tn = t + y
        t_cs = (tn - t) - y
        t = tn
    _keep(q, q <= 20.0, b, br, d)
    return t, t_cs


@njit(cache=True, inline="always")
def _save(st, t, t_cs, dt, dt_last, have_last):  # pragma: no cover - compiled
    """The step state back into ``st`` at the end of a call."""
    st[ST_T], st[ST_T_CS], st[ST_DT], st[ST_DT_LAST] = t, t_cs, dt, dt_last
    st[ST_HAVE_LAST] = 1.0 if have_last else 0.0


@njit(cache=True)
def _watch_step(watch, t, dt, x0, v0, r, v, a0, b, gm, ev_out, ev_count, st, csx, csv):
    # pragma: no cover - compiled
    """Scan the accepted step for events; returns the ``h`` of the first event with an
    action (its watch row in ``st[ST_EVENT_ROW]``; ``r``, ``v`` then put at its time from the
    step's polynomial), or 2 if none."""
    n = r.shape[0]
    cm = np.zeros(9)
    total = 0.0
    for k in range(n):
        total += gm[k]
        for c in range(3):
            cm[c] += gm[k] * x0[3 * k + c]
            cm[3 + c] += gm[k] * v0[3 * k + c]
            cm[6 + c] += gm[k] * r[k, c]
    if total > 0.0:  # (massless rows alone, small bodies': no centre of mass, no escape)
        for c in range(9):
            cm[c] /= total
    h, row = _ev.scan_radau(watch, _ev.RADAU, t, dt, x0.reshape((n, 3)), v0.reshape((n, 3)), r, v,
                      a0, b, gm, cm, ev_out, ev_count)
    st[ST_EVENT_ROW] = row
    if h <= 1.0:
        _ev.state_at_radau(_ev.RADAU, h, dt, x0.reshape((n, 3)), v0.reshape((n, 3)), r, v, a0,
                           b, gm, r, v)
        csx[:] = 0.0
        csv[:] = 0.0
    return h


@njit(cache=True, inline="always")
def _archived(plan, st, t, t_cs, dt, dt_last, have_last, steps, snap_at, t_end):
    # pragma: no cover - compiled
    """An archive's record of the state after ``steps`` steps of :func:`_steps`
    appended (its numbers saved into ``st`` first, as at the call's end;
    :func:`hamilton_orbits._kernels.records.write_record`, called at the plan's
    addresses of it).  Returns ``(written, snap_at, t_stop)``, where the next
    snapshot is due: after one due at ``snap_at`` steps, ``plan[P_EVERY]`` steps
    later; after one at a time, at the plan's next time (or ``t_end``, none left);
    after a failed write, ``snap_at`` and ``t`` as they were."""
    _save(st, t, t_cs, dt, dt_last, have_last)
    if not record_at(plan[P_WRITER], plan[P_WRITER + 1])(plan, steps):
        return False, snap_at, t
    if steps == snap_at:
        return True, snap_at + plan[P_EVERY], t_end
    plan[P_LAND] += 1
    return True, snap_at, next_landing(plan, t_end)


def _steps(
    accel_addr, p, r, v, gm, t_end, st, b, br, d, g, csx, csv, need_v, max_steps, watch, ev_out,
    ev_count, plan,
):  # pragma: no cover - compiled
    """The loop of :func:`advance` and :func:`advance_watched`, and their body (each
    compiled from it with its own signature, not a wrapper calling it: numba would
    optimise the loop's machine code again in the wrapper, 0.6 s of a first run):
    step from ``st[ST_T]`` to ``t_end`` in place; returns ``(steps, status)``.
    ``accel_addr`` are the addresses of the right-hand side (a first-class function
    inside); ``watch`` None (no events) or an array.

    ``st`` is the :data:`NSTATE` state (``epsilon = 0``: fixed steps of ``dt``;
    ``prs23 != 0``: the rule of Pham, Rein & Spiegel 2024, else the global one
    of IAS15).  ``b, br, d, g`` are (7, 3n): the step's ``b``, the last accepted
    step's, its difference from the prediction it started from (for the next
    prediction, :func:`_predict`), and ``g``; ``csx, csv`` the Kahan
    compensations (3n,).  ``r, v`` (n, 3) are updated.  ``status`` is one of the
    ``STATUS_*`` codes; at ``STATUS_MAXSTEPS`` the state is consistent and the
    call may be repeated to go on.  ``watch`` (m, 5) are the events to look for
    after every step on the step's polynomial (:func:`hamilton_orbits._kernels.
    events.scan`), recorded into ``ev_out`` / ``ev_count``; at ``STATUS_EVENT`` the
    state is that of the event's time.

    ``plan`` (None: no archive code compiled): an archive's records
    written between two steps, every ``plan[P_EVERY]`` steps from step
    ``plan[P_NEXT]`` of the call
    (:func:`hamilton_orbits._kernels.records.write_record`), or at the plan's
    snapshot times (:func:`hamilton_orbits._kernels.records.next_landing`), each
    landed on as a call ending there lands (the same steps: the state is kept
    between two calls as it is between two steps); but not at ``t_end``, nor
    ``plan[P_EVERY]``'s after the budget's last step (the caller writes those, as it
    does without a plan).  A failed write ends the call at ``STATUS_MAXSTEPS`` at
    its snapshot, which the caller then writes.

    Memory per body: the four (7, 3) arrays above and ``csb`` (840 bytes), the
    work arrays at, a0 (and vs for velocity-dependent forces) (48-72 bytes), and
    the start state only when events are watched.
    """
    accel = accel_at(accel_addr[0], accel_addr[1])
    n, m = r.shape[0], 3 * r.shape[0]
    # the start of a step, for the events' scan (``watch is None`` is decided at
    # compile time: numba prunes the branches, so no event code is compiled)
    n_watch = 0 if watch is None else watch.shape[0]
    w = m if n_watch > 0 else 0
    x0, v0 = np.empty(w), np.empty(w)
    xs, vs, at, a0_2 = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    xsf, vsf, atf, a0 = xs.reshape(m), vs.reshape(m), at.reshape(m), a0_2.reshape(m)
    xf, vf = r.reshape(m), v.reshape(m)
    csb = np.zeros((7, m))
    t, t_cs, dt, dt_last = st[ST_T], st[ST_T_CS], st[ST_DT], st[ST_DT_LAST]
    have_last = st[ST_HAVE_LAST] != 0.0
    steps, status = 0, STATUS_OK
    snap_at = -1 if plan is None or plan[P_EVERY] <= 0 else plan[P_NEXT]
    t_stop = t_end if plan is None else next_landing(plan, t_end)
    while t < t_end and status == STATUS_OK:
        # (a snapshot due: at one of its times; or after its steps, not the budget's last)
        if plan is not None and (t_stop <= t or (steps == snap_at and steps < max_steps)):
            written, snap_at, t_stop = _archived(plan, st, t, t_cs, dt, dt_last, have_last,
                                                 steps, snap_at, t_end)
            if not written:
                status = STATUS_MAXSTEPS
                break
        if steps >= max_steps:
            status = STATUS_MAXSTEPS
            break
        if watch is not None and n_watch > 0 and ev_count[0] + n_watch > ev_out.shape[0]:
            status = STATUS_DRAIN
            break
        dt_try, landing, short = _try_length(t, t_stop, dt)
        if short:  # (1: a remainder at rounding level of t: there exactly, no step)
            t, status = (t_stop, status) if short == 1 else (t, STATUS_UNDERFLOW)
            continue
        q = dt_try / dt_last if have_last else math.inf
        if not _begin(accel, p, r, v, gm, a0_2, x0, v0, t, q, b, br, d, g, csb):
            status = STATUS_NONFINITE
            break
        # :func:`_iterate`'s loop, here in the step loop: behind the inline wrappers
        # the arrays passed on keep reference counting in it (7% of a step at N = 2-3)
        pc_err, pc_err_last, iters = 2.0, 3.0, 0
        while pc_err >= 1e-16 and iters < 12 and not (iters > 2 and pc_err_last <= pc_err):
            pc_err_last = pc_err
            iters += 1
            for ns in range(1, 8):
                _positions_at(_H[ns], dt_try, b, a0, vf, xf, csx, xsf)
                if need_v:
                    _velocities_at(_H[ns], dt_try, b, a0, vf, csv, vsf)
                set_clock(p, t + _H[ns] * dt_try)
                accel(xs, vs, gm, at, p)
                maxdb, maxak = _correct(ns, atf, a0, g, b, csb)
            pc_err = maxdb / maxak if maxak > 0.0 else 0.0
        st[ST_PC_ITERS] += iters
        if not _all_finite(b[6]):
            status = STATUS_NONFINITE
            break
        # adaptive: the step-size rule (called, not inlined); fixed steps: no call
        dt_new, ok = _next_dt(st, a0, b, at, r, v, dt_try, dt, landing, t) \
            if st[ST_EPSILON] > 0.0 else (dt, True)
        if not ok:
            dt = dt_new
            continue
        _accept(xf, vf, csx, csv, b, a0, vf, dt_try)
        if watch is not None and n_watch > 0:
            h_ev = _watch_step(watch, t, dt_try, x0, v0, r, v, a0, b, gm, ev_out, ev_count, st,
                               csx, csv)
            if h_ev <= 1.0:  # an event with an action: the state is at its time
                t, t_cs, have_last = t + h_ev * dt_try, 0.0, False
                steps += 1
                status = STATUS_EVENT
                break
        t, t_cs = _after_step(t, t_cs, dt_try, t_stop, landing, q, b, br, d)
        dt_last, have_last, dt = dt_try, True, dt_new
        steps += 1
    _save(st, t, t_cs, dt, dt_last, have_last)
    return steps, status


_ADVANCE_ARGS = (ADDRESSES, _F1, _F2, _F2, _F1, types.float64, _F1, _F2, _F2, _F2, _F2, _F1, _F1,
                 types.boolean, types.int64)
_RESULT = types.Tuple((types.int64, types.int64))

#: Step from ``st[ST_T]`` to ``t_end`` in place, watching no events (the last three
#: arguments None); returns ``(steps, status)`` (see :func:`_steps`).  No event code
#: is compiled into it.
advance = entry(_RESULT(*_ADVANCE_ARGS, types.none, types.none, types.none, types.int64[::1]),
                name="advance", cache=True, nogil=True)(_steps)
#: :func:`advance` watching the events ``watch`` (at least one row), recorded into
#: ``ev_out`` / ``ev_count``.
advance_watched = entry(_RESULT(*_ADVANCE_ARGS, _F2, _F2, types.int64[::1], types.none),
                        name="advance_watched", cache=True, nogil=True)(_steps)


# ---------------------------------------------------------------------------
# The variational equations (``variational=True``): the state of ``n_phys``
# bodies followed by the tangent vectors, integrated together by the same steps.


def radau_weights() -> np.ndarray:
    """The weights of the Gauss-Radau quadrature on the spacings, scaled to sum to
    2 (as rebound's IAS15 tabulates them): ``sum_n w_n f(h_n) ~ 2 int_0^1 f``,
    exact for polynomials of degree 14; from the 30-digit spacings in rationals.

    Examples
    --------
    >>> w = radau_weights()
    >>> round(float(w.sum()), 15), round(float(w[0]), 15)
    (2.0, 0.03125)
    """
    h = [Fraction(x) for x in DECIMAL_SPACINGS]
    # the Vandermonde system sum_n W_n h_n^j = 1/(j + 1), j = 0..7, by elimination
    a = [[h[n] ** j for n in range(8)] + [Fraction(1, j + 1)] for j in range(8)]
    for col in range(8):
        piv = next(r for r in range(col, 8) if a[r][col] != 0)
        a[col], a[piv] = a[piv], a[col]
        for r in range(8):
            if r != col and a[r][col] != 0:
                f = a[r][col] / a[col][col]
                a[r] = [x - f * y for x, y in zip(a[r], a[col], strict=True)]
    return np.array([float(2 * a[n][8] / a[n][n]) for n in range(8)])


_W = radau_weights()


@njit(cache=True)
def _megno_radau(ms, t, dt, b, a0, x0, v0, lo, hi):  # pragma: no cover - compiled
    """The MEGNO update of an accepted step from ``t`` of length ``dt``: ``dY = dt
    sum_n w_n (t + h_n dt - t0) (delta'.delta / |delta|^2)(h_n)`` by the
    Gauss-Radau quadrature (weights :func:`radau_weights`) as rebound's IAS15
    does, the tangent vector (components ``lo`` to ``hi`` of the flat state), its
    velocity and acceleration evaluated at the spacings from the step's
    polynomial (eqs. 4, 6, 7 of Rein & Spiegel 2015)."""
    dy = 0.0
    for node in range(8):
        hn = _H[node]
        dth = dt * hn
        num = 0.0
        den = 0.0
        for k in range(lo, hi):
            px = (((b[6, k] * 7.0 * hn / 9.0 + b[5, k]) * 3.0 * hn / 4.0 + b[4, k])
                  * 5.0 * hn / 7.0 + b[3, k]) * 2.0 * hn / 3.0 + b[2, k]
            px = ((px * 3.0 * hn / 5.0 + b[1, k]) * hn / 2.0 + b[0, k]) * hn / 3.0 + a0[k]
            x = (px * dth / 2.0 + v0[k]) * dth + x0[k]
            pv = b[4, k] / 6.0 + hn * (b[5, k] / 7.0 + hn * b[6, k] / 8.0)
            pv = b[2, k] / 4.0 + hn * (b[3, k] / 5.0 + hn * pv)
            pv = b[0, k] / 2.0 + hn * (b[1, k] / 3.0 + hn * pv)
            w = dth * (a0[k] + hn * pv) + v0[k]
            a = b[6, k]
            for j in range(5, -1, -1):
                a = a * hn + b[j, k]
            a = a0[k] + hn * a
            num += x * w + w * a
            den += x * x + w * w
        if den > 0.0:
            dy += _W[node] * (t + dth - ms[0]) * num / den
    megno_update(ms, dt * dy, t + dt, dt)


@njit(cache=True)
def _renormalise(r, v, b, br, d, g, csx, csv, n):  # pragma: no cover - compiled
    """Scale MEGNO's tangent vector (rows ``n .. 2n-1``) down by its largest
    component when that exceeds 1e100, in the state, the step's polynomial (``b``,
    ``g``, the last step's ``br`` and its difference from its prediction ``d``) and
    the compensations alike (the tangent dynamics are linear; MEGNO depends on its
    direction only)."""
    big = 0.0
    for i in range(n, 2 * n):
        for c in range(3):
            big = max(big, abs(r[i, c]), abs(v[i, c]))
    if not (big > 1e100 and big < math.inf):
        return
    f = 1.0 / big
    for i in range(n, 2 * n):
        for c in range(3):
            r[i, c] *= f
            v[i, c] *= f
            k = 3 * i + c
            csx[k] *= f
            csv[k] *= f
            for j in range(7):
                b[j, k] *= f
                br[j, k] *= f
                d[j, k] *= f
                g[j, k] *= f


@entry(
    types.Tuple((types.int64, types.int64))(
        ADDRESSES, _F1, _F2, _F2, _F1, types.float64, _F1, _F2, _F2, _F2, _F2, _F1, _F1,
        types.boolean, types.int64, types.int64, _F1,
    ),
    cache=True, nogil=True,
)
def advance_variational(
    accel_addr, p, r, v, gm, t_end, st, b, br, d, g, csx, csv, need_v, max_steps, n_phys, ms,
):  # pragma: no cover - compiled
    """:func:`advance` for the state of the bodies (``gm``'s, ``nb`` of them)
    followed by tangent vectors (``r``, ``v`` of ``nb (1 + k)`` rows; ``accel``
    the augmented right-hand side, :mod:`hamilton_orbits.rhs`): the same steps and
    the same predictor-corrector iteration over every component (as rebound's
    IAS15 with variational particles), the step size chosen from the first
    ``n_phys`` rows (the bodies alone, ``nb``: the tangent vectors, which grow, do
    not drive it; or every row, ``tangent_control``), and after each accepted
    step the MEGNO update from tangent vector 0, rows ``nb`` to ``2 nb``
    (:func:`_megno_radau`, from the step's start state, which stays in ``r``,
    ``v`` until the step is accepted).  No events."""
    accel = accel_at(accel_addr[0], accel_addr[1])
    n = r.shape[0]
    m = 3 * n
    nb = gm.shape[0]
    x0, v0 = np.empty(0), np.empty(0)  # no events: the start state is not saved
    xs, vs, at, a0_2 = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    a0 = a0_2.reshape(m)
    xf = r.reshape(m)
    vf = v.reshape(m)
    csb = np.zeros((7, m))
    t, t_cs, dt, dt_last = st[ST_T], st[ST_T_CS], st[ST_DT], st[ST_DT_LAST]
    have_last = st[ST_HAVE_LAST] != 0.0
    steps = 0
    status = STATUS_OK
    while t < t_end:
        if steps >= max_steps:
            status = STATUS_MAXSTEPS
            break
        dt_try, landing, short = _try_length(t, t_end, dt)
        if short:
            if short == 1:
                t = t_end  # a remainder at rounding level of t: finish exactly
            else:
                status = STATUS_UNDERFLOW
            break
        q = dt_try / dt_last if have_last else math.inf
        if not _corrected(accel, p, r, v, gm, a0_2, x0, v0, t, dt_try, q, st, b, br, d, g,
                          csb, a0, xf, vf, csx, csv, xs, vs, at, need_v):
            status = STATUS_NONFINITE
            break
        dt_new, ok = _next_dt(st, a0, b, at[:n_phys], r[:n_phys], v[:n_phys], dt_try, dt,
                              landing, t)
        if not ok:
            dt = dt_new
            continue
        _megno_radau(ms, t, dt_try, b, a0, xf, vf, 3 * nb, 6 * nb)
        _accept(xf, vf, csx, csv, b, a0, vf, dt_try)
        _renormalise(r, v, b, br, d, g, csx, csv, nb)
        t, t_cs = _after_step(t, t_cs, dt_try, t_end, landing, q, b, br, d)
        dt_last = dt_try
        have_last = True
        dt = dt_new
        steps += 1
    _save(st, t, t_cs, dt, dt_last, have_last)
    return steps, status
