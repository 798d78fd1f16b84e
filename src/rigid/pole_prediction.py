"""Where will the pole be next year?  Polar-motion prediction and honest hindcasts.

Five methods, each from the IERS C04 pole coordinates alone, each with a 1-sigma band
from its own model (``m = x_p - i y_p``, IERS sign convention, mas, days):

``"persistence"``
    The newest value, held.  Band: the rms change of the pole over the same lag in the
    preceding 10 years (the empirical structure function).
``"ls"``
    Least-squares harmonic extrapolation of each coordinate: a linear trend, the
    Chandler (433.0 d), annual and semi-annual terms fitted to the last years
    (:data:`LS_SETTINGS`).  Band: the least-squares prediction error with white residuals.
``"ls+ar"``
    ``"ls"`` plus a univariate autoregressive model of each coordinate's residuals
    (Kosek et al. 2007; Kalarus et al. 2010, the reference method of the EOP prediction
    comparison campaigns).  Band: the AR forecast error.
``"ls+var"``
    ``"ls"`` plus a bivariate VAR of the x and y residuals together (Lei et al. 2023's
    LS + VAR, with equal weights).  Band: the VAR forecast error.
``"liouville"``
    The package's physics: the linearised Liouville equation
    ``dm/dt = i sigma_c (m - chi)``, ``sigma_c = (2 pi / T_c)(1 + i / (2 Q))``, propagated
    exactly from the newest observed pole with a forecast excitation.  The geodetic
    excitation of the past is recovered from the record by inverting the same
    propagator (exact for an excitation constant over each day); it is modelled as a
    trend with prograde and retrograde annual and semi-annual terms, fitted to the last
    3, 5 and 10 years (an average of the three forecasts), plus a bivariate VAR of what
    is left (the irregular excitation of the atmosphere, oceans and hydrology).  Band:
    the VAR's innovations carried through the Liouville propagator (exact for the
    linear model).

Every method uses only record epochs at least ``latency`` before the start date ``at``
(default 1 day: data strictly before the start, as in a C04-only hindcast; the
prediction campaigns start from data a few days old, ``latency=3 * u.day`` say).
The horizon counts from ``at``: horizon ``h`` is ``h + latency`` days after the newest
datum.  No parameter is fitted to data after the newest datum; the fixed constants
(periods, Q, window lengths, orders) were chosen on hindcasts with start dates in
1985-2004, before both test periods (``docs/pole_wander.md``).

References
----------
Kosek, W., et al. 2007, Artificial Satellites 42, 19 (LS + AR).
Kalarus, M., et al. 2010, J. Geodesy 84, 587 (the 1st EOP PCC, Oct 2005 - Mar 2008).
Śliwińska, J., et al. 2022, Artificial Satellites 57, 237 (the 2nd EOP PCC overview).
Kur, T., et al. 2024, Earth and Space Science 11, e2023EA003278 (its polar motion).
Lei, Y., Zhao, D., Guo, M. 2023, Artificial Satellites 58, 42, doi 10.2478/arsa-2023-0004
(LS + AR, LS + VAR and WLS + VAR from C04).
Wilson, C. R., Vicente, R. O. 1990, Geophys. J. Int. 102, 29 (T_c = 433.0 d).
Gross, R. S. 2007, Treatise on Geophysics 3, 239 (the Liouville equation, eq. 7).
"""

from __future__ import annotations

import functools
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import astropy.units as u
import numpy as np
from astropy.table import QTable
from astropy.time import Time
from scipy.signal import lfilter

from hamilton_orbits.units import DIMENSIONLESS, TIME
from rigid.ar_models import accumulate_covariance, fit_var


class PoleRecord(Protocol):
    """What a record needs here: a :class:`rigid.polar_motion.PolarMotionRecord` (from
    ``load_c04()``) or anything with its attributes.  This module does not import the
    record's module, which re-exports :func:`predict` and :func:`hindcast`."""

    time: Time
    x: u.Quantity
    y: u.Quantity

__all__ = [
    "DEFAULT_HORIZONS",
    "METHODS",
    "PAPER_PERIOD",
    "RECENT_PERIOD",
    "HindcastScore",
    "PolePrediction",
    "PoleRecord",
    "hindcast",
    "predict",
    "propagate_pole",
    "weekly_starts",
]

METHODS = ("persistence", "ls", "ls+ar", "ls+var", "liouville")
DEFAULT_HORIZONS = np.array([10, 30, 90, 150, 270, 365]) * u.day
#: start dates of the 1st EOP PCC (Kalarus et al. 2010), assumed for Lei et al. 2023's test
PAPER_PERIOD = ("2005-10-01", "2008-03-01")
#: the second test period: eight years of weekly starts
RECENT_PERIOD = ("2016-01-01", "2024-01-01")

#: Chandler period (d): Wilson & Vicente 1990, 433.0 +- 1.1 d (from data before 1990); the
#: tuning hindcasts are flat within 0.02% between 433 and 434 d
CHANDLER_PERIOD = 433.0
#: Chandler Q: Wilson & Vicente 1990 (179, 68% range 74-789), also the tuning's best of
#: 50, 80, 120, 179
CHANDLER_Q = 179.0
#: the seasonal excitation's period (d): one tropical year
ANNUAL_PERIOD = 365.2422
_YEAR = 365.25
#: the "ls" family: least-squares window (d); order and window (d) of the residual AR / VAR
#: (chosen on the 1985-2004 tuning hindcasts: benchmarks/tune_pole_prediction.py)
LS_SETTINGS: dict[str, dict[str, int]] = {
    "ls": {"window": int(3 * _YEAR)},
    "ls+ar": {"window": int(20 * _YEAR), "order": 240, "ar_window": int(10 * _YEAR)},
    "ls+var": {"window": int(20 * _YEAR), "order": 120, "ar_window": int(10 * _YEAR)},
}
#: the excitation windows (d) of "liouville" (their forecasts are averaged)
EXCITATION_WINDOWS = (int(3 * _YEAR), int(5 * _YEAR), int(10 * _YEAR))
#: order and window (d) of the VAR of the irregular excitation (the tuning: 5; 1 and 2
#: years score alike, the longer window gives the steadier estimate)
EXCITATION_VAR_ORDER = 5
EXCITATION_VAR_WINDOW = int(2 * _YEAR)
#: window (d) of the persistence band (structure function)
PERSISTENCE_WINDOW = int(10 * _YEAR)

_MAS = u.mas


# --------------------------------------------------------------------------
# The Liouville propagator over days of constant excitation
# --------------------------------------------------------------------------

def _step_factor(period: float, q: float, step: float) -> complex:
    """``exp(i sigma_c step)`` with ``sigma_c = (2 pi / T)(1 + i / (2 Q))``."""
    sigma = 2.0 * np.pi / period * (1.0 + 0.5j / q)
    return complex(np.exp(1j * sigma * step))


def _propagate(m0: complex, chi: np.ndarray, a: complex) -> np.ndarray:
    """``m_{k+1} = a m_k + (1 - a) chi_k`` from ``m_0 = m0``: returns ``m_1 .. m_n``."""
    out, _ = lfilter([1.0 - a], [1.0, -a], np.asarray(chi, dtype=np.complex128),
                     zi=np.array([a * m0]))
    return out


def propagate_pole(
    m0: Any, chi: Any, *, chandler_period: Any = CHANDLER_PERIOD * u.day,
    q: Any = CHANDLER_Q, step: Any = 1.0 * u.day,
) -> Any:
    """The exact Liouville pole for an excitation constant over each step.

    Solves ``dm/dt = i sigma_c (m - chi)``, ``sigma_c = (2 pi / T_c)(1 + i / (2 Q))``
    (the linearised Liouville equation, Gross 2007, eq. 7; IERS ``m = x_p - i y_p``),
    with ``chi(t) = chi_k`` on ``[t0 + k step, t0 + (k + 1) step)``.  Over one step
    ``m - chi_k`` turns and decays by ``a = exp(i sigma_c step)``, so

        m_{k+1} = a m_k + (1 - a) chi_k

    exactly (a linear filter, no Python loop over steps).  The same formula read
    backwards, ``chi_k = (m_{k+1} - a m_k) / (1 - a)``, recovers the excitation of an
    observed pole path (what ``"liouville"`` prediction does).

    Parameters
    ----------
    m0 : complex or complex Quantity (angle)
        The pole at ``t0``.
    chi : array_like, complex, shape (n,)
        The excitation on each step, in the unit of ``m0``.
    chandler_period : Quantity or float (days)
        ``T_c`` (default 433.0 d, Wilson & Vicente 1990).
    q : float
        The quality factor ``Q`` (``np.inf`` for no damping).
    step : Quantity or float (days)
        The step length (default one day).

    Returns
    -------
    ndarray or Quantity, complex, shape (n,)
        ``m`` at ``t0 + step, ..., t0 + n step`` (the unit of ``m0`` if a Quantity).

    Examples
    --------
    >>> import astropy.units as u
    >>> m = propagate_pole(100 * u.mas, np.zeros(433), q=np.inf)  # one free turn
    >>> print(np.round(m[-1], 9))
    (100-0j) mas
    >>> m = propagate_pole(0.0, np.full(20000, 10.0), q=10)  # settles on a steady chi
    >>> print(np.round(abs(m[-1]), 3))
    10.0
    """
    period = float(TIME("chandler_period", chandler_period, u.day))
    qq = float(DIMENSIONLESS("q", q, finite=False))
    h = float(TIME("step", step, u.day))
    if not (period > 0 and qq > 0 and h > 0) or np.isnan(qq):
        raise ValueError(f"Expected `chandler_period`, `q`, `step` > 0, got {period!r} d, "
                         f"{qq!r}, {h!r} d")
    unit = m0.unit if isinstance(m0, u.Quantity) else None
    m0v = complex(m0.to_value(unit) if unit is not None else m0)
    cv = chi.to_value(unit) if unit is not None and isinstance(chi, u.Quantity) else chi
    cv = np.asarray(cv, dtype=np.complex128)
    if cv.ndim != 1:
        raise ValueError(f"Expected `chi` of shape (n,), got {cv.shape}")
    out = _propagate(m0v, cv, _step_factor(period, qq, h))
    return out * unit if unit is not None else out


# --------------------------------------------------------------------------
# The forecasters: plain floats (mas, days); x, y oldest first, the newest datum
# last at t = 0; they return the mean and the variance of x and y at t = 1 .. steps
# --------------------------------------------------------------------------

Forecast = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _structure_function(z: np.ndarray, lags: np.ndarray) -> np.ndarray:
    """``mean_t (z_{t+d} - z_t)^2`` for each lag ``d`` (FFT autocorrelation)."""
    n = z.size
    c2 = np.concatenate([[0.0], np.cumsum(z * z)])
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    f = np.fft.rfft(z, nfft)
    acf = np.fft.irfft(f * np.conj(f), nfft)[lags]
    return (c2[n] - c2[lags] + c2[n - lags] - 2.0 * acf) / (n - lags)


def _persistence(x: np.ndarray, y: np.ndarray, steps: int) -> Forecast:
    xw, yw = x[-PERSISTENCE_WINDOW:], y[-PERSISTENCE_WINDOW:]
    lags = np.arange(1, steps + 1)
    return (np.full(steps, x[-1]), np.full(steps, y[-1]),
            _structure_function(xw, lags), _structure_function(yw, lags))


def _ls_design(t: np.ndarray) -> np.ndarray:
    cols = [np.ones_like(t), t / _YEAR]
    for period in (CHANDLER_PERIOD, ANNUAL_PERIOD, ANNUAL_PERIOD / 2):
        w = 2.0 * np.pi / period
        cols += [np.cos(w * t), np.sin(w * t)]
    return np.stack(cols, axis=-1)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` for a matrix and a vector or thin matrix, without BLAS: a multithreaded
    BLAS on a loaded 2-core machine made these small products 10-100 times slower."""
    return np.einsum("ij,j...->i...", a, b)


@functools.lru_cache(maxsize=16)
def _fit_operator(kind: str, n: int, steps: int):
    """(pseudo-inverse (k, n), future design (steps, k), inverse normal matrix) of a design.

    The designs depend only on the window length: times count from the newest datum,
    so every start date shares them (one SVD per window, not one per start date).
    """
    if kind == "ls":
        past = _ls_design(np.arange(1 - n, 1, dtype=np.float64))
        future = _ls_design(np.arange(1, steps + 1, dtype=np.float64))
    else:  # "excitation": the mid-days before and after t = 0
        past = _excitation_design(np.arange(-n, 0, dtype=np.float64) + 0.5)
        future = _excitation_design(np.arange(steps, dtype=np.float64) + 0.5)
    inv = np.linalg.inv(past.conj().T @ past)
    return np.linalg.pinv(past), future, inv, past


def _ls_fit(x: np.ndarray, y: np.ndarray, steps: int, window: int):
    """Harmonic least squares of both coordinates: (mean (steps, 2), residuals (n, 2),
    residual variance (2,), leverage (steps,))."""
    data = np.stack([x[-window:], y[-window:]], axis=-1)
    n = data.shape[0]
    pinv, future, inv, design = _fit_operator("ls", n, steps)
    coef = _dot(pinv, data)
    resid = data - _dot(design, coef)
    s2 = np.sum(resid**2, axis=0) / (n - design.shape[1])
    leverage = np.einsum("ij,jk,ik->i", future, inv, future)
    return future @ coef, resid, s2, leverage


def _ls(x: np.ndarray, y: np.ndarray, steps: int) -> Forecast:
    mean, _, s2, leverage = _ls_fit(x, y, steps, LS_SETTINGS["ls"]["window"])
    return mean[:, 0], mean[:, 1], s2[0] * (1 + leverage), s2[1] * (1 + leverage)


def _ls_ar(x: np.ndarray, y: np.ndarray, steps: int) -> Forecast:
    cfg = LS_SETTINGS["ls+ar"]
    mean, resid, _, _ = _ls_fit(x, y, steps, cfg["window"])
    out = []
    for c in range(2):
        series = resid[-cfg["ar_window"]:, c]
        model = fit_var(series, cfg["order"])
        var = accumulate_covariance(model.impulse_response(steps), model.cov)[:, 0, 0]
        out.append((mean[:, c] + model.forecast(series, steps)[:, 0], var))
    return out[0][0], out[1][0], out[0][1], out[1][1]


def _ls_var(x: np.ndarray, y: np.ndarray, steps: int) -> Forecast:
    cfg = LS_SETTINGS["ls+var"]
    mean, resid, _, _ = _ls_fit(x, y, steps, cfg["window"])
    series = resid[-cfg["ar_window"]:]
    model = fit_var(series, cfg["order"])
    mean = mean + model.forecast(series, steps)
    cov = accumulate_covariance(model.impulse_response(steps), model.cov)
    return mean[:, 0], mean[:, 1], cov[:, 0, 0], cov[:, 1, 1]


def _excitation_design(t: np.ndarray) -> np.ndarray:
    """Trend and prograde/retrograde annual and semi-annual terms (complex)."""
    w = 2.0 * np.pi / ANNUAL_PERIOD
    cols = [np.ones_like(t), t / _YEAR] + [np.exp(1j * s * w * t) for s in (1, -1, 2, -2)]
    return np.stack(cols, axis=-1).astype(np.complex128)


def _liouville_member(m: np.ndarray, chi: np.ndarray, window: int, steps: int, a: complex):
    """One excitation window: (mean pole (steps,), error covariance (steps, 2, 2))."""
    pinv, future, _, design = _fit_operator("excitation", window, steps)
    coef = _dot(pinv, chi[-window:])
    nv = min(EXCITATION_VAR_WINDOW, window)
    resid = chi[-nv:] - _dot(design[-nv:], coef)
    series = np.stack([resid.real, resid.imag], axis=-1)
    model = fit_var(series, EXCITATION_VAR_ORDER)
    noise = model.forecast(series, steps)
    chi_next = future @ coef + noise[:, 0] + 1j * noise[:, 1]
    mean = _propagate(m[-1], chi_next, a)
    psi = model.impulse_response(steps)  # excitation response to a unit innovation
    g = [_propagate(0j, psi[:, 0, c] + 1j * psi[:, 1, c], a) for c in range(2)]
    response = np.stack([np.stack([g[0].real, g[1].real], -1),
                         np.stack([g[0].imag, g[1].imag], -1)], axis=1)
    return mean, accumulate_covariance(response, model.cov)


def _liouville(x: np.ndarray, y: np.ndarray, steps: int) -> Forecast:
    n = max(EXCITATION_WINDOWS) + 1
    m = x[-n:] - 1j * y[-n:]
    a = _step_factor(CHANDLER_PERIOD, CHANDLER_Q, 1.0)
    chi = (m[1:] - a * m[:-1]) / (1.0 - a)  # the excitation of each past day
    members = [_liouville_member(m, chi, w, steps, a) for w in EXCITATION_WINDOWS]
    means = np.array([mm for mm, _ in members])
    mean = means.mean(axis=0)
    # model averaging: the members' own error variance plus their spread about the mean
    var_x = np.mean([cc[:, 0, 0] for _, cc in members], axis=0) + means.real.var(axis=0)
    var_y = np.mean([cc[:, 1, 1] for _, cc in members], axis=0) + means.imag.var(axis=0)
    return mean.real, -mean.imag, var_x, var_y


_FORECASTERS: dict[str, Callable[[np.ndarray, np.ndarray, int], Forecast]] = {
    "persistence": _persistence,
    "ls": _ls,
    "ls+ar": _ls_ar,
    "ls+var": _ls_var,
    "liouville": _liouville,
}
def _history(method: str) -> int:
    """Days of record a method uses (its longest window)."""
    if method == "persistence":
        return PERSISTENCE_WINDOW
    if method == "liouville":
        return max(EXCITATION_WINDOWS) + 1
    return LS_SETTINGS[method]["window"]


# --------------------------------------------------------------------------
# The public layer: validation, predict, hindcast
# --------------------------------------------------------------------------

def _check_method(method: Any) -> str:
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"Expected `method` one of {', '.join(map(repr, METHODS))}, "
                         f"got {method!r}")
    return method


def _check_record(record: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(UTC MJD, x, y in mas) of a PolarMotionRecord (or anything with its ``time``, ``x``
    and ``y``: this module does not import rigid.polar_motion, which re-exports it)."""
    if not (isinstance(getattr(record, "time", None), Time)
            and isinstance(getattr(record, "x", None), u.Quantity)
            and isinstance(getattr(record, "y", None), u.Quantity)):
        raise ValueError(f"Expected `record` from load_c04() (time, x, y), got "
                         f"{type(record).__name__}")
    mjd = np.asarray(record.time.utc.mjd, dtype=np.float64)
    return mjd, record.x.to_value(_MAS), record.y.to_value(_MAS)


def _whole_days(name: str, value: Any, *, minimum: int) -> np.ndarray:
    """A time (Quantity or days) as whole days >= minimum (int array)."""
    if not isinstance(value, u.Quantity):
        raise ValueError(f"Expected `{name}` to be a time Quantity (e.g. 365 * u.day), "
                         f"got {value!r}")
    days = np.atleast_1d(TIME(name, value, u.day))
    whole = np.round(days)
    bad = (np.abs(days - whole) > 1e-9) | (whole < minimum)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ValueError(f"Expected `{name}` in whole days >= {minimum} d, got "
                         f"{float(days[k])!r} d{f' at index {k}' if days.size > 1 else ''}")
    return whole.astype(np.int64)


def _newest_index(name: str, mjd: np.ndarray, at: np.ndarray, latency: int,
                  history: int) -> np.ndarray:
    """Index of the newest datum ``at - latency`` for each start; checks the span."""
    target = at - latency
    k = np.searchsorted(mjd, target)
    k_safe = np.minimum(k, mjd.size - 1)
    ok = (k < mjd.size) & (mjd[k_safe] == target) & (k_safe - history + 1 >= 0)
    ok &= mjd[k_safe] - mjd[np.maximum(k_safe - history + 1, 0)] == history - 1
    if not np.all(ok):
        i = int(np.argmin(ok))
        first = Time(mjd[0] + history - 1 + latency, format="mjd", scale="utc").iso[:10]
        last = Time(mjd[-1] + latency, format="mjd", scale="utc").iso[:10]
        raise ValueError(
            f"Expected `{name}` at 0h UTC within the record, from {first} ({history} days "
            f"of history plus the {latency} d latency) to {last}, got "
            f"{Time(at[i], format='mjd', scale='utc').iso}"
            f"{f' at index {i}' if at.size > 1 else ''}")
    return k


def _as_mjd(name: str, value: Any) -> np.ndarray:
    if not isinstance(value, Time):
        raise ValueError(f"Expected `{name}` to be an astropy Time, got {value!r}")
    return np.atleast_1d(np.asarray(value.utc.mjd, dtype=np.float64))


@dataclass(frozen=True)
class PolePrediction:
    """A predicted pole path and its 1-sigma band (see :func:`predict`).

    Attributes
    ----------
    t : Time, shape (n,)
        Daily epochs from ``at`` (horizon 0) to ``at + horizon``.
    x, y : Quantity, shape (n,), mas
        The predicted pole coordinates ``x_p``, ``y_p``.
    sigma_x, sigma_y : Quantity, shape (n,), mas
        The method's own 1-sigma prediction error.
    method : str
    newest_datum : Time
        The newest record epoch the prediction used (``at - latency``).
    parameters : dict
        The fitted model, complex amplitudes of ``m = x_p - i y_p`` (mas) at the
        newest datum: for the ``"ls"`` family the trend (``"mean"``, ``"drift"`` per
        year) and the prograde (``"+"``) and retrograde (``"-"``) Chandler, annual and
        semi-annual terms of ``m``; for ``"liouville"`` the Chandler period and Q and,
        per excitation window, the same terms of the excitation ``chi``; empty for
        ``"persistence"``.
    """

    t: Time
    x: u.Quantity
    y: u.Quantity
    sigma_x: u.Quantity
    sigma_y: u.Quantity
    method: str
    newest_datum: Time
    parameters: dict = field(default_factory=dict)


def _forecast_days(method: str, x: np.ndarray, y: np.ndarray, k: int, steps: int) -> Forecast:
    """The forecaster on the history that ends at index ``k`` (nothing after it)."""
    h = _history(method)
    return _FORECASTERS[method](x[k - h + 1:k + 1], y[k - h + 1:k + 1], steps)


def predict(
    record: PoleRecord, *, at: Time, horizon: u.Quantity, method: str = "liouville",
    latency: u.Quantity = 1 * u.day,
) -> PolePrediction:
    """Predict the pole from ``at`` to ``at + horizon`` with the record before ``at``.

    Parameters
    ----------
    record : PolarMotionRecord
        From :func:`rigid.polar_motion.load_c04`.
    at : Time
        The start date (0h UTC).  Only epochs up to ``at - latency`` are used.
    horizon : Quantity
        Whole days >= 0.
    method : {"persistence", "ls", "ls+ar", "ls+var", "liouville"}
        See the module docstring.
    latency : Quantity
        Age of the newest datum at ``at``; whole days >= 1 (default 1 day).

    Returns
    -------
    PolePrediction

    Raises
    ------
    ValueError
        For an unknown method, ``at`` outside the record (or without the method's
        history before it), a negative or fractional horizon, a latency below a day,
        or non-finite data in the history used.

    Examples
    --------
    >>> from rigid.polar_motion import load_c04
    >>> rec = load_c04()
    >>> pred = predict(rec, at=Time("2019-01-01"), horizon=30 * u.day, method="persistence")
    >>> print(pred.t[0].iso[:10], pred.t[-1].iso[:10], len(pred.x), pred.x.unit)
    2019-01-01 2019-01-31 31 mas
    >>> predict(rec, at=Time("2019-01-01"), horizon=30 * u.day, method="ar")
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `method` one of 'persistence', 'ls', ..., 'liouville', got 'ar'
    """
    method = _check_method(method)
    mjd, x, y = _check_record(record)
    at_mjd = _as_mjd("at", at)
    if at_mjd.size != 1:
        raise ValueError(f"Expected `at` to be a single Time, got {at_mjd.size} epochs")
    n_h = int(_whole_days("horizon", horizon, minimum=0)[0])
    lat = int(_whole_days("latency", latency, minimum=1)[0])
    k = int(_newest_index("at", mjd, at_mjd, lat, _history(method))[0])
    _check_finite(x, y, k, _history(method))
    mx, my, vx, vy = _forecast_days(method, x, y, k, lat + n_h)
    sl = slice(lat - 1, lat + n_h)
    t = Time(at_mjd[0] + np.arange(n_h + 1), format="mjd", scale="utc")
    return PolePrediction(
        t=t, x=mx[sl] * _MAS, y=my[sl] * _MAS, sigma_x=np.sqrt(vx[sl]) * _MAS,
        sigma_y=np.sqrt(vy[sl]) * _MAS, method=method,
        newest_datum=Time(mjd[k], format="mjd", scale="utc"),
        parameters=_parameters(method, x[:k + 1], y[:k + 1]))


def _terms(coef: np.ndarray, names: tuple[str, ...]) -> dict[str, u.Quantity]:
    """Complex amplitudes (mas) of the harmonic terms from complex coefficients."""
    return {name: complex(c) * _MAS for name, c in zip(names, coef, strict=True)}


def _parameters(method: str, x: np.ndarray, y: np.ndarray) -> dict[str, Any]:
    """The fitted model of a prediction (history ending at the newest datum)."""
    terms = ("chandler+", "chandler-", "annual+", "annual-", "semiannual+", "semiannual-")
    if method == "persistence":
        return {}
    if method == "liouville":
        n = max(EXCITATION_WINDOWS) + 1
        m = x[-n:] - 1j * y[-n:]
        a = _step_factor(CHANDLER_PERIOD, CHANDLER_Q, 1.0)
        chi = (m[1:] - a * m[:-1]) / (1.0 - a)
        out: dict[str, Any] = {"chandler_period": CHANDLER_PERIOD * u.day, "Q": CHANDLER_Q}
        for w in EXCITATION_WINDOWS:
            coef = _fit_operator("excitation", w, 1)[0] @ chi[-w:]
            fit = _terms(coef, ("mean", "drift", *terms[2:]))
            fit["drift"] = fit["drift"] / u.yr
            out[f"excitation, last {w} d"] = fit
        return out
    window = LS_SETTINGS[method]["window"]
    data = x[-window:] - 1j * y[-window:]
    coef = _fit_operator("ls", window, 1)[0] @ data  # [1, t, cos, sin] per period
    out = {"mean": complex(coef[0]) * _MAS, "drift": complex(coef[1]) * _MAS / u.yr}
    for i, name in enumerate(("chandler", "annual", "semiannual")):
        c, s = coef[2 + 2 * i], coef[3 + 2 * i]  # m = c cos + s sin = A+ e^iwt + A- e^-iwt
        out.update(_terms(np.array([(c - 1j * s) / 2, (c + 1j * s) / 2]),
                          (f"{name}+", f"{name}-")))
    return out


def _check_finite(x: np.ndarray, y: np.ndarray, k: int, history: int) -> None:
    for name, arr in (("record.x", x), ("record.y", y)):
        part = arr[k - history + 1:k + 1]
        if not np.all(np.isfinite(part)):
            i = k - history + 1 + int(np.argmin(np.isfinite(part)))
            raise ValueError(f"Expected `{name}` finite in the history used, got "
                             f"{float(arr[i])!r} at index {i}")


def weekly_starts(first: Any, last: Any) -> Time:
    """Start dates every 7 days from ``first`` (included) to ``last`` (excluded).

    Examples
    --------
    >>> s = weekly_starts(*PAPER_PERIOD)
    >>> print(len(s), s[0].iso[:10], s[-1].iso[:10])
    126 2005-10-01 2008-02-23
    """
    a, b = (Time(v, scale="utc") if not isinstance(v, Time) else v.utc for v in (first, last))
    return Time(np.arange(a.mjd, b.mjd, 7.0), format="mjd", scale="utc")


@dataclass(frozen=True)
class HindcastScore:
    """Predictions from weekly (or any) start dates scored against the record.

    Attributes
    ----------
    table : QTable
        One row per horizon: ``horizon`` (d), ``mae_x``, ``mae_y`` (mean absolute error,
        mas), ``rms_2d`` (``sqrt(mean(dx^2 + dy^2))``, mas), ``coverage_x``,
        ``coverage_y`` (fraction of outcomes within the 1-sigma band) and ``count``
        (start dates whose outcome the record holds).
    method : str
    starts : Time, shape (n,)
    horizons : Quantity, shape (h,), d
    latency : Quantity, d
    errors_x, errors_y : Quantity, shape (n, h), mas
        Prediction minus record; NaN where the record ends before the outcome (those
        entries are left out of ``table``, as ``count`` says).
    sigma_x, sigma_y : Quantity, shape (n, h), mas
        The method's own 1-sigma at each start and horizon.
    wall_time : float
        Seconds the hindcast took.
    """

    table: QTable
    method: str
    starts: Time
    horizons: u.Quantity
    latency: u.Quantity
    errors_x: u.Quantity
    errors_y: u.Quantity
    sigma_x: u.Quantity
    sigma_y: u.Quantity
    wall_time: float


def _score_table(h: np.ndarray, ex: np.ndarray, ey: np.ndarray, sx: np.ndarray,
                 sy: np.ndarray) -> QTable:
    ok = np.isfinite(ex)
    count = ok.sum(axis=0)
    with np.errstate(invalid="ignore"):  # a horizon no start reaches has count 0
        def mean(v: np.ndarray) -> np.ndarray:
            return np.where(count > 0, np.nansum(np.where(ok, v, 0.0), axis=0)
                            / np.maximum(count, 1), np.nan)

        inside_x = np.where(ok, np.abs(ex) <= sx, False).astype(float)
        inside_y = np.where(ok, np.abs(ey) <= sy, False).astype(float)
        return QTable(
            [h * u.day, mean(np.abs(ex)) * _MAS, mean(np.abs(ey)) * _MAS,
             np.sqrt(mean(ex**2 + ey**2)) * _MAS, mean(inside_x), mean(inside_y), count],
            names=("horizon", "mae_x", "mae_y", "rms_2d", "coverage_x", "coverage_y",
                   "count"))


def hindcast(
    record: PoleRecord, starts: Time | None = None,
    horizons: u.Quantity = DEFAULT_HORIZONS, method: str = "liouville", *,
    latency: u.Quantity = 1 * u.day,
) -> HindcastScore:
    """Score a method's predictions from many start dates against the record.

    Each start date is predicted exactly as :func:`predict` would (the newest datum
    ``latency`` before it, nothing later); the prediction at ``start + horizon`` is
    compared with the record there, as in the EOP prediction comparison campaigns
    (mean absolute error per horizon, Kalarus et al. 2010; Śliwińska et al. 2022).
    One forecast per start (a few vectorised calls; no Python loop over days).

    Parameters
    ----------
    record : PolarMotionRecord
    starts : Time, optional
        Start dates (0h UTC).  Default: weekly over :data:`PAPER_PERIOD` (the 1st EOP
        PCC's Oct 2005 - Mar 2008, assumed for Lei et al. 2023); the second period is
        ``weekly_starts(*RECENT_PERIOD)``.
    horizons : Quantity
        Whole days >= 0 (default 10, 30, 90, 150, 270, 365 d).
    method : str
        One of :data:`METHODS`.
    latency : Quantity
        Age of the newest datum at each start (default 1 day).

    Returns
    -------
    HindcastScore

    Raises
    ------
    ValueError
        For an unknown method, no start dates, a start date outside the record (naming
        its index), negative or fractional horizons, or a latency below a day.

    Examples
    --------
    >>> from rigid.polar_motion import load_c04
    >>> score = hindcast(load_c04(), weekly_starts("2019-01-01", "2019-03-01"),
    ...                  [10, 30] * u.day, "persistence")
    >>> print(score.table["count"].tolist(), score.table["mae_x"].unit)
    [9, 9] mas
    """
    begin = _time.perf_counter()
    method = _check_method(method)
    mjd, x, y = _check_record(record)
    at = _as_mjd("starts", weekly_starts(*PAPER_PERIOD) if starts is None else starts)
    if at.size == 0:
        raise ValueError("Expected `starts` to hold at least one start date, got none")
    hs = _whole_days("horizons", horizons, minimum=0)
    if hs.size == 0:
        raise ValueError("Expected `horizons` to hold at least one horizon, got none")
    lat = int(_whole_days("latency", latency, minimum=1)[0])
    history = _history(method)
    ks = _newest_index("starts", mjd, at, lat, history)
    ex, ey, sx, sy = (np.full((at.size, hs.size), np.nan) for _ in range(4))
    steps = lat + int(hs.max())
    for i, k in enumerate(ks):  # per start: a few vectorised calls
        _check_finite(x, y, int(k), history)
        mx, my, vx, vy = _forecast_days(method, x, y, int(k), steps)
        j = lat + hs - 1  # forecast index of each horizon
        truth = k + lat + hs
        seen = truth < mjd.size
        jj, tt = j[seen], truth[seen]
        ex[i, seen], ey[i, seen] = mx[jj] - x[tt], my[jj] - y[tt]
        sx[i, seen], sy[i, seen] = np.sqrt(vx[jj]), np.sqrt(vy[jj])
    table = _score_table(hs, ex, ey, sx, sy)
    return HindcastScore(
        table=table, method=method, starts=Time(at, format="mjd", scale="utc"),
        horizons=hs * u.day, latency=lat * u.day, errors_x=ex * _MAS, errors_y=ey * _MAS,
        sigma_x=sx * _MAS, sigma_y=sy * _MAS, wall_time=_time.perf_counter() - begin)
