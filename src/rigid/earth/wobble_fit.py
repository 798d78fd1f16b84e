"""The wobble fit of an observed pole path: Chandler and annual terms, spectrum, Q.

:func:`fit_wobble` fits the Chandler and annual wobbles (periods, amplitudes,
phases, a trend) to a :class:`~rigid.earth.c04.PolarMotionRecord`, with the amplitudes
by decade and a resolution-limited Q estimate (:class:`WobbleFit`);
:func:`periodogram` is the two-sided amplitude spectrum of the pole path;
:func:`free_period` fits the period of a free wobble to any pole path (a
simulated one, :meth:`rigid.earth.PolePath.period`, or a model's,
:class:`rigid.earth.liouville.LiouvillePole`).  Conventions (IERS): ``m = x_p - i y_p``,
a prograde term is ``exp(+i sigma t)``.  The public facade is
:mod:`rigid.polar_motion`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import astropy.units as u
import numpy as np
from astropy.time import Time

from hamilton_orbits.units import TIME
from hamilton_orbits.validation import as_float_array, check_unmasked
from rigid._shared import positive_scalar
from rigid.earth.c04 import PolarMotionRecord, decimal_year, iers2010_mean_pole, mjd_utc

if TYPE_CHECKING:  # astropy.table takes 0.17 s to import: only the fit's table needs it
    from astropy.table import QTable

__all__ = ["WobbleFit", "fit_wobble", "free_period", "periodogram"]


def _harmonic_design(t: np.ndarray, freqs: np.ndarray, n_trend: int) -> np.ndarray:
    cols = [t**k for k in range(n_trend)]
    cols += [np.exp(1j * f * t) for f in freqs]
    return np.stack(cols, axis=-1).astype(np.complex128)


def _project(t: np.ndarray, m: np.ndarray, freqs: np.ndarray, n_trend: int):
    """Complex linear least squares at fixed frequencies: (coefficients, residual)."""
    design = _harmonic_design(t, freqs, n_trend)
    coef, *_ = np.linalg.lstsq(design, m, rcond=None)
    return coef, m - design @ coef


def free_period(t: Any, m: Any) -> u.Quantity:
    """The period of a free wobble fitted to a pole path.

    The model is ``m(t) = c + a exp(i sigma t) + b exp(-i sigma t)``: the ellipse
    of the triaxial linear theory (``b = 0`` for an axisymmetric body) about a
    mean pole ``c`` (the IERS C04 pole of 1962-2026 turns about ``x_p = 52``,
    ``y_p = 303`` mas, 0.31 arcsec from the origin).  It is fitted by nonlinear
    least squares in ``sigma``, with ``c``, ``a`` and ``b`` solved linearly at each
    trial ``sigma``, so the period does not depend on the offset: ``free_period(t,
    m + z)`` is ``free_period(t, m)`` for any constant ``z``, to the rounding of
    ``m + z``.  (The model had no ``c`` before: a 433-day wobble of 0.2 about a
    centre 0.1 or 0.15 off the origin gave 426.1 or 423.0 days, unflagged; larger
    offsets were refused.)  A mean pole that drifts is not modelled:
    :func:`fit_wobble` fits a trend.  The starting value
    is the mean rate of the unwrapped phase of ``m - mean(m)``; where that fits less
    than half of the path (a wobble near a line, whose phase jumps by pi) or where
    the phase steps by over a quarter turn between samples (a sparse path, whose
    phase does not unwrap), the fit is also started from the highest peak of the
    periodogram in both senses, and the better fit kept.

    The model is exact for the linear theory only.  A large wobble of a triaxial
    body has a polhode with harmonics of its period, and the single-frequency fit
    is then biased, the more so the nearer the separatrix and the fewer the turns
    fitted: for moments 1 : 2 : 2.9, against the exact period of
    :func:`rigid.free_parameters` (``k^2`` its elliptic parameter ``m``), -0.14% at
    ``k^2 = 0.65`` and -0.60% at ``k^2 = 0.98`` over 3 turns, -0.18% at ``k^2 =
    0.98`` over 3.37 turns, and at ``k^2 = 0.9993`` -3.5% over 1.5 turns, -0.08% over
    10.5.  The rigid Earth's wobble (``|m| ~ 1e-6`` rad, nonlinear terms
    ~ ``|m|^2``) is fitted to 1e-12 of its linear Euler period.

    Parameters
    ----------
    t : Quantity or array_like, shape (n,)
        Times (days if plain floats), strictly monotonic.
    m : array_like, complex, shape (n,)
        The pole path ``m1 + i m2`` (any angular unit; its offset from the origin,
        its size and its sense do not change the period).

    Returns
    -------
    Quantity, day
        ``2 pi / sigma``.

    Raises
    ------
    ValueError
        For fewer than 8 points, mismatched shapes, times not strictly monotonic,
        a value not finite (named with its index), or a path without a wobble: a
        constant one (a value and its index named) or one that no wobble turning
        at least once within the span explains half of (its spread about its mean).

    Examples
    --------
    >>> t = np.arange(0.0, 2000.0)
    >>> print(f"{free_period(t, 1e-6 * np.exp(2j * np.pi * t / 433.0)):.6f}")
    433.000000 d

    A wobble of 0.2 arcsec about a mean pole 0.15 arcsec from the origin:

    >>> m = 0.15 + 0.2 * np.exp(2j * np.pi * t / 433.0)
    >>> print(f"{free_period(t, m):.6f}")
    433.000000 d
    """
    tt = TIME("t", t, u.day)
    check_unmasked("m", m)  # (a complex path: not through the unit kinds' check)
    mm = np.asarray(m.value if isinstance(m, u.Quantity) else m, dtype=np.complex128)
    if tt.ndim != 1 or mm.shape != tt.shape or tt.size < 8:
        raise ValueError(
            f"Expected `t` and `m` of one shape (n,), n >= 8, got {tt.shape} and {mm.shape}"
        )
    if not np.all(np.isfinite(mm)):
        k = int(np.argmin(np.isfinite(mm)))
        raise ValueError(f"Expected `m` to be finite, got {mm[k]!r} at index {k}")
    scale = float(np.max(np.abs(mm)))
    if scale == 0.0:
        raise ValueError("Expected `m` to wobble, got a path identically zero")
    step = np.diff(tt) * (1.0 if tt[-1] >= tt[0] else -1.0)  # (a backward run's too)
    if not np.all(step > 0):
        k = int(np.argmin(step > 0)) + 1
        raise ValueError(f"Expected `t` strictly monotonic, got t[{k}] = {float(tt[k])!r} "
                         f"after t[{k - 1}] = {float(tt[k - 1])!r} (days)")
    # (the mean pole: the fit's constant term ``c`` takes it exactly; the path is
    # centred first so that the start below, the phase's turn, turns about the centre)
    mc = mm - mm.mean()
    spread = float(np.max(np.abs(mc)))
    if spread <= 64.0 * np.finfo(float).eps * scale:  # (a constant, to rounding)
        k = int(np.argmax(np.abs(mc)))
        raise ValueError(f"Expected `m` to turn about the figure axis at least once, got a "
                         f"constant path: {complex(mm[k])!r} at index {k}, every value "
                         f"within {spread:.3g} of the mean {complex(mm.mean())!r}")
    t0 = tt - tt[0]
    phase = np.unwrap(np.angle(mc))
    sigma0 = float(np.polyfit(t0, phase, 1)[0])
    mn = mc / spread
    # (least_squares' cost is half the sum of squares: a cost over ``var`` leaves more
    # than half of the path's spread about its mean unexplained)
    var = 0.25 * float(np.vdot(mn, mn).real)
    sol = _fit_sigma(t0, mn, sigma0) if sigma0 != 0.0 else None
    jump = float(np.max(np.abs(np.angle(mc[1:] * mc[:-1].conj()))))
    if sol is None or sol.cost > var or jump > 0.5 * np.pi:
        # (the mean turn of the phase no start: a path near a line, |a| ~ |b|, whose
        # phase jumps by pi, or one sampled too sparsely for its phase to unwrap, a
        # step of over a quarter turn (16 random points over 2.7 turns, a gap of 0.6
        # turn, went from a start of 5800 d to a false minimum at 847 d); the
        # periodogram's highest peak then starts a second fit, the better one kept)
        other = _fit_sigma(t0, mn, _peak(t0, mn))
        sol = other if sol is None or other.cost < sol.cost else sol
    span = abs(float(t0[-1]))
    if not abs(float(sol.x[0])) * span >= 2.0 * np.pi or sol.cost > var:
        # (no wobble that turns once within the span and explains half of the path's
        # spread about its mean: a drift, fitted by a "period" of 1e20 days, made up)
        raise ValueError(f"Expected `m` to turn about the figure axis at least once in the "
                         f"span of `t` ({span:.6g} d), got no such wobble that explains the "
                         f"path")
    return (2.0 * np.pi / abs(float(sol.x[0]))) * u.day


def _fit_sigma(t0: np.ndarray, mn: np.ndarray, sigma0: float) -> Any:
    """scipy's least-squares fit of :func:`free_period`'s ``sigma`` from ``sigma0``."""
    from scipy.optimize import least_squares  # here: 0.2 s to import, rarely needed

    def resid(x):
        _, r = _project(t0, mn, np.array([x[0], -x[0]]), 1)  # (c + a e^ist + b e^-ist)
        return np.concatenate([r.real, r.imag])

    return least_squares(resid, [sigma0], x_scale=[abs(sigma0)], xtol=1e-15, ftol=1e-15,
                         gtol=1e-15)


def _peak(t0: np.ndarray, mn: np.ndarray) -> float:
    """The angular frequency (> 0) of the highest peak of the power of ``mn`` in
    both senses, ``|sum mn e^(-i s t)|^2 + |sum mn e^(i s t)|^2``, on a grid of
    ``s`` from one turn over the span to the mean sampling's Nyquist rate (at
    most 4096 points; steps of a quarter turn over the span where that stays within
    them, so that a wobble of 1.5 turns is not read at 1 or 2, or at an alias)."""
    span = abs(float(t0[-1]))
    top = min(len(t0) // 2, 4096)
    over = max(1, min(4, 4096 // max(top, 1)))
    s = 2.0 * np.pi * np.arange(over, over * top + 1) / (over * span)
    top = s.size
    power = np.empty(top)
    for k in range(0, top, 256):  # (256 frequencies at a time: memory O(256 n))
        e = np.exp(-1j * np.outer(s[k:k + 256], t0))
        power[k:k + 256] = np.abs(e @ mn) ** 2 + np.abs(e.conj() @ mn) ** 2
    return float(s[np.argmax(power)])


@dataclass(frozen=True)
class WobbleFit:
    """The least-squares wobble fit of :func:`fit_wobble`.

    Periods and their errors are in days, amplitudes in mas, phases in degrees
    (the argument of the complex amplitude at ``epoch``; prograde terms are
    ``A exp(i (w (t - epoch) + phase))``, the retrograde annual term
    ``A exp(-i (w (t - epoch)) + i phase)``).

    ``rms_residual`` is per component (x or y) of the residual.  The errors are the
    formal ones scaled by the residual scatter and by an
    AR(1) effective sample size ``n (1 - rho) / (1 + rho)`` (``rho`` the lag-one
    autocorrelation of the residuals, close to 1 for daily data).  The residuals
    remain correlated over months (unmodelled excitation), so even these
    errors are indicative, not rigorous.
    """

    chandler_period: u.Quantity
    chandler_period_error: u.Quantity
    chandler_period_error_formal: u.Quantity
    annual_period: u.Quantity
    annual_period_error: u.Quantity
    chandler_amplitude: u.Quantity
    chandler_phase: u.Quantity
    annual_amplitude: u.Quantity
    annual_phase: u.Quantity
    annual_retrograde_amplitude: u.Quantity
    annual_retrograde_phase: u.Quantity
    mean_pole: u.Quantity
    drift: u.Quantity
    rms_residual: u.Quantity
    residual_autocorrelation: float
    epoch: Time
    start: Time
    end: Time
    n: int
    trend: str
    amplitude_by_decade: QTable
    q_estimate: float
    q_caveat: str

    def __repr__(self) -> str:
        """One line of the fitted lines (the dataclass's own was 2300 characters, a
        table of decades inside it); every field stays an attribute.

        Examples
        --------
        >>> from rigid.earth.c04 import load_c04
        >>> fit_wobble(load_c04().select(1980, 2000))  # doctest: +NORMALIZE_WHITESPACE
        WobbleFit(1980.0-2000.0, 7305 epochs, trend linear: Chandler 434.9 +- 0.7 d,
        179.0 mas; annual 365.5 +- 1.1 d, 80.5 mas (retrograde 3.1 mas); rms residual
        22.8 mas, Q 17)
        """
        def line(name: str, period: Any, error: Any, amp: Any) -> str:
            return (f"{name} {period.to_value(u.day):.1f} +- {error.to_value(u.day):.1f} d, "
                    f"{amp.to_value(u.mas):.1f} mas")

        span = f"{self.start.decimalyear:.1f}-{self.end.decimalyear:.1f}"
        chandler = line("Chandler", self.chandler_period, self.chandler_period_error,
                        self.chandler_amplitude)
        annual = line("annual", self.annual_period, self.annual_period_error,
                      self.annual_amplitude)
        retro = self.annual_retrograde_amplitude.to_value(u.mas)
        return (f"WobbleFit({span}, {self.n} epochs, trend {self.trend}: {chandler}; {annual} "
                f"(retrograde {retro:.1f} mas); rms residual "
                f"{self.rms_residual.to_value(u.mas):.1f} mas, Q {self.q_estimate:.0f})")

    def model(self, time: Time) -> u.Quantity:
        """The fitted ``m(t)`` (complex, mas) at ``time``, trend included.

        Examples
        --------
        >>> from rigid.earth.c04 import load_c04
        >>> rec = load_c04().select(1980, 2000)
        >>> fit = fit_wobble(rec)
        >>> res = rec.m - fit.model(rec.time)
        >>> bool(np.sqrt(np.mean(np.abs(res) ** 2) / 2) < 1.01 * fit.rms_residual)
        True
        """
        t = mjd_utc(time) - float(self.epoch.mjd)
        mean = self.mean_pole.to_value(u.mas) + self.drift.to_value(u.mas / u.yr) * t / 365.25
        if self.trend == "iers2010":
            xb, yb = iers2010_mean_pole(time)
            mean = mean + xb.to_value(u.mas) - 1j * yb.to_value(u.mas)
        wc = 2 * np.pi / self.chandler_period.to_value(u.day)
        wa = 2 * np.pi / self.annual_period.to_value(u.day)

        def c(a, p):
            return a.to_value(u.mas) * np.exp(1j * p.to_value(u.rad))

        return (mean + c(self.chandler_amplitude, self.chandler_phase) * np.exp(1j * wc * t)
                + c(self.annual_amplitude, self.annual_phase) * np.exp(1j * wa * t)
                + c(self.annual_retrograde_amplitude, self.annual_retrograde_phase)
                * np.exp(-1j * wa * t)) * u.mas


def _wobble_resid(x, t, m, n_trend):
    """Residuals and Jacobian of the model for real parameters
    x = [w_c, w_a, Re/Im of (trend..., chandler, annual+, annual-)]."""
    wc, wa = x[0], x[1]
    coef = x[2::2] + 1j * x[3::2]
    design = _harmonic_design(t, np.array([wc, wa, -wa]), n_trend)
    r = m - design @ coef
    n_c = n_trend
    jac_c = np.empty((t.size, x.size), dtype=np.complex128)
    jac_c[:, 0] = -coef[n_c] * 1j * t * design[:, n_c]
    jac_c[:, 1] = -(coef[n_c + 1] * 1j * t * design[:, n_c + 1]
                    - coef[n_c + 2] * 1j * t * design[:, n_c + 2])
    jac_c[:, 2::2] = -design
    jac_c[:, 3::2] = -1j * design
    return r, jac_c


def _fit_core(t: np.ndarray, m: np.ndarray, n_trend: int, t_c0: float, t_a0: float,
              detrended: np.ndarray):
    """Nonlinear least squares; returns (x, covariance (scaled), residual, rho, rms).
    ``detrended``: ``m`` with the trend and the annual terms of period ``t_a0``
    projected out (:func:`_without_annual`)."""
    # start: the highest prograde line within +-10% of the guess, once the trend and the
    # annual terms are removed (one matrix product instead of a nonlinear search)
    grid = np.linspace(0.9 * t_c0, 1.1 * t_c0, 61)  # 0.33% steps; the line is ~2% wide
    amp = np.abs(np.exp(-2j * np.pi * np.outer(1.0 / grid, t)) @ detrended)
    tc = float(grid[int(np.argmax(amp))])
    freqs = 2 * np.pi / np.array([tc, t_a0, -t_a0])
    coef, _ = _project(t, m, freqs, n_trend)
    x0 = np.concatenate([[freqs[0], freqs[1]], np.column_stack([coef.real, coef.imag]).ravel()])

    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def evaluate(x):  # fun and jac at the same x share one evaluation
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            r, j = _wobble_resid(x, t, m, n_trend)
            cache[key] = (np.concatenate([r.real, r.imag]), np.concatenate([j.real, j.imag]))
        return cache[key]

    def fun(x):
        return evaluate(x)[0]

    def jac(x):
        return evaluate(x)[1]

    scale = np.concatenate([[1e-4 * freqs[0], 1e-4 * freqs[1]],
                            np.full(x0.size - 2, max(np.std(np.abs(m)), 1e-300))])
    from scipy.optimize import least_squares

    sol = least_squares(fun, x0, jac=jac, x_scale=scale, xtol=1e-12, ftol=1e-12, gtol=1e-12,
                        method="lm")
    r, jc = _wobble_resid(sol.x, t, m, n_trend)
    jr = np.concatenate([jc.real, jc.imag])
    dof = 2 * t.size - sol.x.size
    s2 = float(np.sum(np.abs(r) ** 2)) / dof
    cov = np.linalg.inv(jr.T @ jr) * s2
    rc = r - r.mean()
    rho = float(np.real(np.vdot(rc[:-1], rc[1:])) / np.real(np.vdot(rc, rc)))
    return sol.x, cov, r, rho, np.sqrt(s2)


def _amp_phase(c: complex) -> tuple[u.Quantity, u.Quantity]:
    return abs(c) * u.mas, (np.degrees(np.angle(c)) * u.deg)


def fit_wobble(
    record: PolarMotionRecord,
    start: Any = None,
    end: Any = None,
    *,
    trend: str = "linear",
    chandler_guess: Any = 433 * u.day,
) -> WobbleFit:
    """Fit the Chandler and annual wobbles to an observed pole path.

    Model (complex, ``m = x_p - i y_p``, mas, ``t`` in days from the window's
    mid epoch)::

        m(t) = mean + drift t + c_C exp(i w_C t) + c_A exp(i w_A t) + c_R exp(-i w_A t)

    with ``mean + drift t`` a linear trend (``trend="linear"``), or the IERS 2010
    mean pole (``trend="iers2010"``, IERS Conventions 2010 eq. 7.25) plus a
    constant offset.  ``w_C`` and ``w_A`` are fitted nonlinearly (Levenberg-
    Marquardt, scipy ``least_squares``, from a grid search of ``w_C`` with the
    linear parameters projected out).

    Parameters
    ----------
    record : PolarMotionRecord
        From :func:`load_c04`.
    start, end : Time, decimal year or None
        The window (default: the whole record); within the record (a window
        beyond it is refused, see ``rigid.earth.c04.PolarMotionRecord.select``).
    trend : {"linear", "iers2010"}
    chandler_guess : Quantity
        Centre of the grid search (+-10%).

    Returns
    -------
    WobbleFit
        Also ``amplitude_by_decade`` (the Chandler and annual amplitudes fitted per
        calendar decade, of two years' span or more, with the periods of the whole
        window held fixed) and a Q estimate with its caveat.

    Raises
    ------
    ValueError
        A window under 3 Chandler periods; a ``chandler_guess`` more than 10% from
        the record's line: the line found from it (its amplitude in the record, the
        trend and the annual terms projected out) more than twice weaker than one
        beyond the 10% searched (a guess near one year gave a Chandler and an
        annual line at 368.0 and 367.5 d, of 574 and 644 mas cancelling each
        other, where the record has 11 mas).

    Examples
    --------
    >>> from rigid.earth.c04 import load_c04
    >>> fit = fit_wobble(load_c04(), 1970, 2010)
    >>> print(round(fit.chandler_period.to_value(u.day)), round(fit.annual_period.to_value(u.day)))
    433 365
    """
    if not isinstance(record, PolarMotionRecord):
        raise ValueError(f"Expected `record` from load_c04(), got {type(record).__name__}")
    if trend not in ("linear", "iers2010"):
        raise ValueError(f"Expected `trend` 'linear' or 'iers2010', got {trend!r}")
    rec = record.select(start, end)
    t_c0 = float(positive_scalar("chandler_guess", TIME("chandler_guess", chandler_guess,
                                                         u.day)))
    days = mjd_utc(rec.time)
    mid = 0.5 * (days[0] + days[-1])
    epoch = Time(mid, format="mjd", scale="utc")
    t = days - mid
    span = float(t[-1] - t[0])
    if span < 3 * t_c0:
        raise ValueError(
            f"Expected a window of at least 3 Chandler periods ({3 * t_c0:.0f} d) to separate "
            f"the Chandler and annual terms, got {span:.0f} d"
        )
    m = rec.m.to_value(u.mas)
    n_trend = 2
    if trend == "iers2010":
        xb, yb = iers2010_mean_pole(rec.time)
        m = m - (xb.to_value(u.mas) - 1j * yb.to_value(u.mas))
        n_trend = 1
    detrended = _without_annual(t, m, n_trend, 365.25)
    x, cov, _r, rho, rms = _fit_core(t, m, n_trend, t_c0, 365.25, detrended)
    wc, wa = x[0], x[1]
    coef = x[2::2] + 1j * x[3::2]
    _check_guess(t, detrended, 2 * np.pi / wc, abs(coef[n_trend]), t_c0)
    inflate = np.sqrt((1 + rho) / (1 - rho)) if rho < 1 else np.inf
    err_wc = np.sqrt(cov[0, 0])
    err_wa = np.sqrt(cov[1, 1])
    t_c = 2 * np.pi / wc
    t_a = 2 * np.pi / wa
    ca, cp = _amp_phase(coef[n_trend])
    aa, ap = _amp_phase(coef[n_trend + 1])
    ra, rp = _amp_phase(coef[n_trend + 2])
    drift = (coef[1] * 365.25 if n_trend == 2 else 0j) * u.mas / u.yr
    decades = _amplitude_by_decade(rec, wc, wa)
    q, caveat = _q_estimate(rec, t_c)
    return WobbleFit(
        chandler_period=t_c * u.day,
        chandler_period_error=t_c * err_wc / wc * inflate * u.day,
        chandler_period_error_formal=t_c * err_wc / wc * u.day,
        annual_period=t_a * u.day,
        annual_period_error=t_a * err_wa / wa * inflate * u.day,
        chandler_amplitude=ca, chandler_phase=cp,
        annual_amplitude=aa, annual_phase=ap,
        annual_retrograde_amplitude=ra, annual_retrograde_phase=rp,
        mean_pole=coef[0] * u.mas, drift=drift,
        rms_residual=rms * u.mas,
        residual_autocorrelation=rho,
        epoch=epoch, start=rec.time[0], end=rec.time[-1], n=len(rec), trend=trend,
        amplitude_by_decade=decades, q_estimate=q, q_caveat=caveat,
    )


def _without_annual(t: np.ndarray, m: np.ndarray, n_trend: int, t_a: float) -> np.ndarray:
    """``m`` with the trend and the annual lines (period ``t_a``, both senses)
    projected out."""
    return _project(t, m, 2 * np.pi / np.array([t_a, -t_a]), n_trend)[1]


def _check_guess(t: np.ndarray, detrended: np.ndarray, t_c: float, amp: float,
                 t_c0: float) -> None:
    """Refuse a Chandler line found from a guess more than 10% off.

    The fitted line (period ``t_c``, amplitude ``amp``) is refused when the record
    has a prograde line more than twice as strong as it beyond 10% of the guess
    ``t_c0``, within 0.6-1.6 ``t_c`` (the annual lines projected out first:
    ``detrended``).  The fitted line's strength is the smaller of ``amp`` and its
    amplitude in ``detrended``: a fit whose Chandler and annual lines come together
    has huge cancelling amplitudes that are no line of the record.  (A guess of
    380 d, or the rigid Euler period, gave a sidelobe of 16 or 4 mas as "the
    Chandler line", the record's 122 mas at 433 d unsaid; 365 d gave lines of 574
    and 644 mas at 368.0 and 367.5 d over 1970-2010.)"""
    f = np.linspace(1 / (1.6 * t_c), 1 / (0.6 * t_c), 101)
    f = f[np.abs(f * 365.25 - 1) > 0.03]  # (the annual line's place, projected out)
    lines = np.abs(np.exp(-2j * np.pi * np.outer(f, t)) @ detrended) / t.size
    k = int(np.argmax(lines))
    here = min(amp, float(np.abs(np.exp(-2j * np.pi * t / t_c) @ detrended)) / t.size)
    if lines[k] > 2 * here and abs(1 / (f[k] * t_c0) - 1) > 0.1:
        raise ValueError(
            f"Expected `chandler_guess` within 10% of the record's Chandler line: the guess "
            f"{t_c0:.1f} d led to a line of {here:.1f} mas at {t_c:.1f} d, but the record "
            f"has one of {lines[k]:.0f} mas at {1 / f[k]:.0f} d, beyond the 10% searched "
            f"about the guess (the periodogram() shows the lines)")


def _amplitude_by_decade(rec: PolarMotionRecord, wc: float, wa: float) -> QTable:
    """Chandler and annual amplitudes per calendar decade, periods held fixed."""
    from astropy.table import QTable

    yr = decimal_year(rec.time)
    rows = []
    first = int(np.floor(yr[0] / 10.0) * 10)
    for dec in range(first, int(yr[-1]) + 1, 10):
        sel = (yr >= dec) & (yr < dec + 10)
        if sel.sum() < 10 or yr[sel][-1] - yr[sel][0] < 2.0:  # under two years (of any
            continue  # sampling): the terms cannot be separated
        sub = PolarMotionRecord(rec.time[sel], rec.x[sel], rec.y[sel])
        days = mjd_utc(sub.time)
        t = days - 0.5 * (days[0] + days[-1])
        coef, _ = _project(t, sub.m.to_value(u.mas), np.array([wc, wa, -wa]), 2)
        rows.append((dec, float(yr[sel][0]), float(yr[sel][-1]), abs(coef[2]), abs(coef[3]),
                     abs(coef[4])))
    cols = list(zip(*rows, strict=True)) if rows else [[]] * 6
    return QTable(
        [np.array(cols[0], dtype=int), np.array(cols[1]) * u.yr, np.array(cols[2]) * u.yr,
         np.array(cols[3]) * u.mas, np.array(cols[4]) * u.mas, np.array(cols[5]) * u.mas],
        names=("decade", "from", "to", "chandler_amplitude", "annual_amplitude",
               "annual_retrograde_amplitude"),
    )


def _q_estimate(rec: PolarMotionRecord, t_c: float) -> tuple[float, str]:
    """Q from the half-power width of the Chandler line (resolution limited)."""
    days = mjd_utc(rec.time)
    years = (days[-1] - days[0]) / 365.25
    f_c = 365.25 / t_c
    freqs = np.linspace(f_c - 0.04, f_c + 0.04, 81)
    pg = periodogram(rec, freqs / u.yr)
    power = pg["amplitude"].to_value(u.mas) ** 2
    k = int(np.argmax(power))
    half = power[k] / 2
    lo = k
    while lo > 0 and power[lo] > half:
        lo -= 1
    hi = k
    while hi < power.size - 1 and power[hi] > half:
        hi += 1
    fwhm = float(freqs[hi] - freqs[lo])
    q = f_c / fwhm
    # (a half-power point not reached within the searched band: the line is wider than
    # the band, and Q at most this; a short window blends it with the annual line)
    bound = power[lo] > half or power[hi] > half
    caveat = (
        (f"The Chandler line is wider than the band searched (f_C +- 0.04 cycles/yr): "
         f"Q is at most {q:.0f}, an upper bound, not an estimate; a window of "
         f"{years:.1f} yr resolves {1 / years:.3f} cycles/yr, too coarse to part the "
         f"Chandler line from the annual one (0.16 cycles/yr apart).  " if bound else "")
        + f"Q = f_C / FWHM of the Chandler line = {q:.0f}.  The window's own resolution "
        f"({1 / years:.3f} cycles/yr over {years:.1f} yr) limits the width, so this is of "
        "the order of the largest Q the record can resolve, not a measurement of the "
        "damping: the wobble is re-excited continuously (atmosphere, ocean, hydrology), so a "
        "line width mixes damping and excitation.  Published estimates range from ~50 to "
        "~200 (e.g. Wilson & Vicente 1990, GJI 102, 29: Q ~ 179; Furuya & Chao 1996, GJI "
        "127, 693: Q ~ 49-250)."
    )
    return q, caveat


def periodogram(
    record: PolarMotionRecord, frequency: Any = None, *, trend: str = "linear"
) -> QTable:
    """The complex (two-sided) amplitude spectrum of the pole path.

    ``A(f) = |(1/n) sum_k (m_k - trend_k) exp(-2 pi i f t_k)|`` (mas), ``f`` in
    cycles per year: positive ``f`` is prograde, negative retrograde.  For a pure
    term ``a exp(2 pi i f0 t)``, ``A(f0) = |a|``.

    Parameters
    ----------
    record : PolarMotionRecord
    frequency : Quantity, optional
        Frequencies (1/yr, 1/day, cycle/yr ...; negative: retrograde); default
        -1.5 .. 1.5 cycles/yr, 1201 points.
    trend : {"linear", "iers2010"}
        What is removed first (a least-squares line, or the IERS 2010 mean pole).

    Returns
    -------
    astropy.table.QTable
        Columns ``frequency`` (1/yr), ``period`` (d, signed) and ``amplitude`` (mas).

    Examples
    --------
    >>> from rigid.earth.c04 import load_c04
    >>> pg = periodogram(load_c04(), np.linspace(0.8, 0.9, 101) / u.yr)
    >>> print(f'{pg["period"][np.argmax(pg["amplitude"])]:.0f}')  # the Chandler line
    432 d
    """
    if not isinstance(record, PolarMotionRecord):
        raise ValueError(f"Expected `record` from load_c04(), got {type(record).__name__}")
    if frequency is None:
        f = np.linspace(-1.5, 1.5, 1201)
    else:
        if not isinstance(frequency, u.Quantity):
            raise u.UnitConversionError(
                f"Expected `frequency` to be a Quantity of 1/time, got {frequency!r}"
            )
        if frequency.unit.is_equivalent(u.cycle / u.yr):  # (cycles per year: turns)
            frequency = frequency / u.cycle
        try:
            per_year = frequency.to_value(1 / u.yr)
        except u.UnitConversionError:
            raise u.UnitConversionError(f"Expected `frequency` to be a Quantity of 1/time, "
                                        f"got {frequency!r}") from None
        f = np.atleast_1d(as_float_array("frequency", per_year))
        if f.ndim != 1:
            raise ValueError(f"Expected `frequency` of shape (n,), got {f.shape}")
    days = mjd_utc(record.time)
    t = (days - days[0]) / 365.25
    m = record.m.to_value(u.mas)
    if trend == "iers2010":
        xb, yb = iers2010_mean_pole(record.time)
        m = m - (xb.to_value(u.mas) - 1j * yb.to_value(u.mas))
        m = m - m.mean()
    elif trend == "linear":
        _coef, m = _project(t, m, np.zeros(0), 2)
    else:
        raise ValueError(f"Expected `trend` 'linear' or 'iers2010', got {trend!r}")
    amp = np.empty(f.size)
    chunk = max(1, 2_000_000 // max(t.size, 1))
    for i in range(0, f.size, chunk):  # chunks of frequencies, vectorised over time
        fs = f[i:i + chunk]
        amp[i:i + chunk] = np.abs(np.exp(-2j * np.pi * np.outer(fs, t)) @ m) / t.size
    with np.errstate(divide="ignore"):
        period = np.where(f != 0, 365.25 / np.where(f != 0, f, 1.0), np.inf)
    from astropy.table import QTable

    return QTable([f / u.yr, period * u.day, amp * u.mas],
                 names=("frequency", "period", "amplitude"))
