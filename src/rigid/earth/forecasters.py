"""The five polar-motion prediction methods, on plain floats (mas, days).

Each method forecasts the pole from the IERS C04 pole coordinates alone, with a 1-sigma
band from its own model (``m = x_p - i y_p``, IERS sign convention, mas, days); the
public layer, :func:`rigid.earth.prediction.predict` and
:func:`rigid.earth.prediction.hindcast`, validates, picks the history and wraps units:

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

Here a method is a function of the history (``x``, ``y`` oldest first, the newest datum
last at ``t = 0``) that returns the mean and the variance of ``x`` and ``y`` at
``t = 1 .. steps`` (:func:`forecast`); :func:`history_days` is how many days it uses, and
:func:`fitted_parameters` the model it fitted.  The fixed constants (periods, Q, window
lengths, orders) were chosen on hindcasts with start dates in 1985-2004
(``benchmarks/tune_pole_prediction.py``, which sets them on this module).

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
from collections.abc import Callable
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.units import DIMENSIONLESS, TIME
from hamilton_orbits.validation import check_unmasked
from rigid.earth.ar_models import accumulate_covariance, fit_var

__all__ = [
    "ANNUAL_PERIOD",
    "CHANDLER_PERIOD",
    "CHANDLER_Q",
    "EXCITATION_VAR_ORDER",
    "EXCITATION_VAR_WINDOW",
    "EXCITATION_WINDOWS",
    "LS_SETTINGS",
    "MAX_LEAD",
    "METHODS",
    "PERSISTENCE_WINDOW",
    "Forecast",
    "fitted_parameters",
    "forecast",
    "history_days",
    "max_lead",
    "propagate_pole",
]

METHODS = ("persistence", "ls", "ls+ar", "ls+var", "liouville")

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
#: the longest lead (latency + horizon, d) of any method: ten years of extrapolation
MAX_LEAD = int(10 * _YEAR)

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
    from scipy.signal import lfilter  # here: scipy.signal takes 0.3 s to import

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
    check_unmasked("m0", m0)  # (complex values: not through a unit kind's check)
    check_unmasked("chi", chi)
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


def history_days(method: str) -> int:
    """Days of record a method uses (its longest window)."""
    if method == "persistence":
        return PERSISTENCE_WINDOW
    if method == "liouville":
        return max(EXCITATION_WINDOWS) + 1
    return LS_SETTINGS[method]["window"]


def max_lead(method: str) -> int:
    """The longest lead (latency + horizon, days after the newest datum) a method serves.

    Ten years (:data:`MAX_LEAD`) for every method but ``"persistence"``, whose band at
    lag ``d`` averages the ``n - d`` pairs of its ``n``-day window: half the window, so
    that every lag rests on at least half of the pairs.
    """
    return PERSISTENCE_WINDOW // 2 if method == "persistence" else MAX_LEAD


def forecast(method: str, x: np.ndarray, y: np.ndarray, k: int, steps: int) -> Forecast:
    """The forecaster on the history that ends at index ``k`` (nothing after it)."""
    h = history_days(method)
    return _FORECASTERS[method](x[k - h + 1:k + 1], y[k - h + 1:k + 1], steps)


def _terms(coef: np.ndarray, names: tuple[str, ...]) -> dict[str, u.Quantity]:
    """Complex amplitudes (mas) of the harmonic terms from complex coefficients."""
    return {name: complex(c) * _MAS for name, c in zip(names, coef, strict=True)}


def fitted_parameters(method: str, x: np.ndarray, y: np.ndarray) -> dict[str, Any]:
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

