"""Where will the pole be next year?  Polar-motion prediction and honest hindcasts.

Five methods (``METHODS``), each from the IERS C04 pole coordinates alone, each with
a 1-sigma band from its own model (``m = x_p - i y_p``, IERS sign convention, mas, days):
``"persistence"``, least-squares harmonics ``"ls"``, ``"ls+ar"``, ``"ls+var"`` and the
package's physics, the linearised Liouville equation ``"liouville"`` (each described in
:mod:`rigid.earth.forecasters`, which computes them on plain floats).  This module is
their public layer: :func:`predict` from one start date, :func:`hindcast` from many,
scored against the record.

Every method uses only record epochs at least ``latency`` before the start date ``at``
(default 1 day: data strictly before the start, as in a C04-only hindcast; the
prediction campaigns start from data a few days old, ``latency=3 * u.day`` say).
The horizon counts from ``at``: horizon ``h`` is ``h + latency`` days after the newest
datum.  The lead ``latency + horizon`` is at most ten years (five for ``"persistence"``,
whose band needs pairs at that lag within its ten-year window).

One bad datum: the fitted models extrapolate the newest days, so a spike there moves
the ``"ls+ar"`` 30-day forecast ten times as far as the spike (a 1-arcsec spike made
the ``"ls+ar"``, ``"ls+var"`` and ``"liouville"`` forecasts 1e10-1e15 mas).  A history
whose day-to-day second difference exceeds ``SPIKE_LIMIT`` (100 mas, twice the
largest of the C04 series since 1962) is refused with a ``ValueError`` naming the
coordinate, the index and the value; smaller errors in the data pass to the forecast.

No parameter is fitted to data after the newest datum; the fixed constants
(periods, Q, window lengths, orders) were chosen on hindcasts with start dates in
1985-2004, before both test periods (``docs/pole_wander.md``).

References
----------
Kalarus, M., et al. 2010, J. Geodesy 84, 587 (the 1st EOP PCC, Oct 2005 - Mar 2008).
Śliwińska, J., et al. 2022, Artificial Satellites 57, 237 (the 2nd EOP PCC overview).
Lei, Y., Zhao, D., Guo, M. 2023, Artificial Satellites 58, 42, doi 10.2478/arsa-2023-0004
(LS + AR, LS + VAR and WLS + VAR from C04).
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from typing import Any, Protocol

import astropy.units as u
import numpy as np
from astropy.table import QTable
from astropy.time import Time

from hamilton_orbits.units import TIME, time_quantity
from rigid.earth.ar_models import SingularRegressionError
from rigid.earth.forecasters import (
    METHODS,
    fitted_parameters,
    forecast,
    history_days,
    max_lead,
    propagate_pole,
)


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
    "SPIKE_LIMIT",
    "HindcastScore",
    "PolePrediction",
    "PoleRecord",
    "check_inputs",
    "hindcast",
    "predict",
    "propagate_pole",
    "weekly_starts",
]

DEFAULT_HORIZONS = np.array([10, 30, 90, 150, 270, 365]) * u.day
#: start dates of the 1st EOP PCC (Kalarus et al. 2010), assumed for Lei et al. 2023's test
PAPER_PERIOD = ("2005-10-01", "2008-03-01")
#: the second test period: eight years of weekly starts
RECENT_PERIOD = ("2016-01-01", "2024-01-01")

#: the largest day-to-day second difference (mas) a record may hold in the history a
#: method uses: twice the largest in the IERS 20 C04 series since 1962 (47 mas, 1990)
SPIKE_LIMIT = 100.0

_MAS = u.mas


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
    mjd = np.atleast_1d(np.asarray(record.time.utc.mjd, dtype=np.float64))
    x, y = np.atleast_1d(record.x.to_value(_MAS)), np.atleast_1d(record.y.to_value(_MAS))
    if mjd.size == 0:
        raise ValueError("Expected `record` to hold at least one epoch, got an empty record")
    if x.shape != mjd.shape or y.shape != mjd.shape:
        raise ValueError(f"Expected `record.x` and `record.y` of the shape of `record.time` "
                         f"{mjd.shape}, got {x.shape} and {y.shape}")
    return mjd, x, y


def _whole_days(name: str, value: Any, *, minimum: int, maximum: int,
                single: bool = False, note: str = "") -> np.ndarray:
    """A time (Quantity or TimeDelta) as whole days in [minimum, maximum] (int array)."""
    value = time_quantity(value)  # (a TimeDelta: the Quantity in days it holds)
    if not isinstance(value, u.Quantity):
        raise ValueError(f"Expected `{name}` to be a time Quantity (e.g. 365 * u.day), "
                         f"got {value!r}")
    days = np.atleast_1d(TIME(name, value, u.day))
    if single and days.size != 1:
        raise ValueError(f"Expected `{name}` to be a single time, got {value!r} "
                         f"({days.size} values)")
    whole = np.round(days)
    bad = (np.abs(days - whole) > 1e-9) | (whole < minimum) | (whole > maximum)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ValueError(f"Expected `{name}` in whole days from {minimum} d to {maximum} d, "
                         f"got {float(days[k])!r} d{f' at index {k}' if days.size > 1 else ''}"
                         f"{note}")
    return whole.astype(np.int64)


def _lead_days(method: str, horizon: Any, latency: Any, name: str,
               single: bool) -> tuple[np.ndarray, int]:
    """(horizons, latency) in whole days, their sum within the method's longest lead."""
    most = max_lead(method)
    note = (f" (method {method!r} serves at most {most} d from the newest datum: "
            f"latency + {name} <= {most} d)")
    lat = int(_whole_days("latency", latency, minimum=1, maximum=most, single=True,
                          note=note)[0])
    return _whole_days(name, horizon, minimum=0, maximum=most - lat, single=single,
                       note=note), lat


def _newest_index(name: str, mjd: np.ndarray, at: np.ndarray, latency: int,
                  history: int, method: str) -> np.ndarray:
    """Index of the newest datum ``at - latency`` for each start; checks the span."""
    if mjd[-1] - mjd[0] + 1 < history:  # (no start date at all: say so, not a range
        raise ValueError(  # that ends before it begins)
            f"Expected `record` to span at least the {history} days of history that method "
            f"{method!r} uses before `{name}` (less the {latency} d latency), got "
            f"{mjd[-1] - mjd[0] + 1:.0f} days, from "
            f"{Time(mjd[0], format='mjd', scale='utc').iso[:10]} to "
            f"{Time(mjd[-1], format='mjd', scale='utc').iso[:10]}")
    target = at - latency
    k = np.searchsorted(mjd, target)
    k_safe = np.minimum(k, mjd.size - 1)
    ok = (k < mjd.size) & (mjd[k_safe] == target) & (k_safe - history + 1 >= 0)
    ok &= mjd[k_safe] - mjd[np.maximum(k_safe - history + 1, 0)] == history - 1
    if not np.all(ok):
        i = int(np.argmin(ok))
        first = Time(mjd[0] + history - 1 + latency, format="mjd", scale="utc").iso[:10]
        last = Time(mjd[-1] + latency, format="mjd", scale="utc").iso[:10]
        got = (f"{Time(at[i], format='mjd', scale='utc').iso}"
               f"{f' at index {i}' if at.size > 1 else ''}")
        if mjd[0] + history - 1 <= target[i] <= mjd[-1] and target[i] == round(target[i]):
            raise ValueError(  # (within the span: a day missing, or not a daily record)
                f"Expected a daily record without gaps over the {history} days of history "
                f"up to `{name}` less the {latency} d latency, got {got}: "
                f"{_first_missing(mjd, target[i] - history + 1, target[i])}")
        raise ValueError(
            f"Expected `{name}` at 0h UTC within the record, from {first} ({history} days "
            f"of history plus the {latency} d latency) to {last}, got {got}")
    return k


def _first_missing(mjd: np.ndarray, start: float, end: float) -> str:
    """What keeps ``mjd`` from being one epoch a day from ``start`` to ``end`` (MJD,
    whole days): the first day missing, else the count of epochs there."""
    days = np.arange(start, end + 1)
    missing = days[~np.isin(days, mjd)]
    if missing.size:
        return f"{Time(missing[0], format='mjd', scale='utc').iso[:10]} is not in the record"
    count = int(np.count_nonzero((mjd >= start) & (mjd <= end)))
    return f"the record has {count} epochs over those {days.size} days, not one a day at 0h UTC"


def _as_mjd(name: str, value: Any) -> np.ndarray:
    if not isinstance(value, Time):  # a date string ("2019-01-01") or a list of them
        try:
            value = Time(value, scale="utc")
        except (ValueError, TypeError) as exc:
            raise ValueError(f"Expected `{name}` to be an astropy Time or a date, got "
                             f"{value!r}") from exc
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

    def __repr__(self) -> str:  # a few lines: the arrays summarised, not printed
        n = len(self.x)
        span = (f"{self.t[0].utc.iso[:10]} .. {self.t[-1].utc.iso[:10]}" if n else "empty")
        last = (f"; at the end x = {self.x[-1]:.1f} +- {self.sigma_x[-1]:.1f}, "
                f"y = {self.y[-1]:.1f} +- {self.sigma_y[-1]:.1f}" if n else "")
        return (f"PolePrediction(method={self.method!r}, {n} days {span}, newest datum "
                f"{self.newest_datum.utc.iso[:10]}{last}; parameters: "
                f"{', '.join(map(str, self.parameters)) or 'none'})")


def predict(
    record: PoleRecord, *, at: Time, horizon: u.Quantity, method: str = "liouville",
    latency: u.Quantity = 1 * u.day,
) -> PolePrediction:
    """Predict the pole from ``at`` to ``at + horizon`` with the record before ``at``.

    Parameters
    ----------
    record : PolarMotionRecord
        From :func:`rigid.polar_motion.load_c04`: daily values (0h UTC), without a day
        missing over the method's history before ``at``.
    at : Time or str
        The start date (0h UTC), e.g. ``"2019-01-01"``.  Only epochs up to
        ``at - latency`` are used.
    horizon : Quantity or TimeDelta
        Whole days >= 0.
    method : {"persistence", "ls", "ls+ar", "ls+var", "liouville"}
        See the module docstring.
    latency : Quantity or TimeDelta
        Age of the newest datum at ``at``; whole days >= 1 (default 1 day).

    Returns
    -------
    PolePrediction

    Raises
    ------
    ValueError
        For an unknown method, an empty record, a record shorter than the method's
        history, ``at`` outside the record (or without the method's history before
        it, or with a day missing in it: the first missing day named), a record
        without noise in the history used (its residuals determine no VAR, for
        ``"ls+ar"``, ``"ls+var"`` and ``"liouville"``), a horizon or latency that is not a single
        whole number of days, a latency below a day, a lead ``latency + horizon`` beyond
        the method's ``rigid.earth.forecasters.max_lead`` (ten years; five for
        ``"persistence"``), or data in the history used that are not finite or jump
        off their neighbours (``SPIKE_LIMIT``).

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
    hs, lat = _lead_days(method, horizon, latency, "horizon", single=True)
    n_h = int(hs[0])
    k = int(_newest_index("at", mjd, at_mjd, lat, history_days(method), method)[0])
    _check_history(x, y, k, history_days(method))
    mx, my, vx, vy = _forecast(method, x, y, k, lat + n_h, mjd, "at", None)
    sl = slice(lat - 1, lat + n_h)
    t = Time(at_mjd[0] + np.arange(n_h + 1), format="mjd", scale="utc")
    return PolePrediction(
        t=t, x=mx[sl] * _MAS, y=my[sl] * _MAS, sigma_x=np.sqrt(vx[sl]) * _MAS,
        sigma_y=np.sqrt(vy[sl]) * _MAS, method=method,
        newest_datum=Time(mjd[k], format="mjd", scale="utc"),
        parameters=fitted_parameters(method, x[:k + 1], y[:k + 1]))


def check_inputs(record: PoleRecord, starts: Time, horizons: u.Quantity, method: str, *,
                 latency: u.Quantity = 1 * u.day) -> None:
    """Raise the ``ValueError`` that :func:`hindcast` (or :func:`predict`, for one start)
    would raise for these inputs, without forecasting (a scene's check at load).

    Examples
    --------
    >>> from rigid.polar_motion import load_c04
    >>> check_inputs(load_c04(), Time(["1963-01-01"]), [30] * u.day, "ls")
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `starts` at 0h UTC within the record, from ... got 1963-01-01 ...
    """
    method = _check_method(method)
    mjd, x, y = _check_record(record)
    at = _as_mjd("starts", starts)
    _lead_days(method, horizons, latency, "horizons", single=False)
    lat = int(_whole_days("latency", latency, minimum=1, maximum=max_lead(method),
                          single=True)[0])
    history = history_days(method)
    for k in _newest_index("starts", mjd, at, lat, history, method):
        _check_history(x, y, int(k), history)


def _forecast(method: str, x: np.ndarray, y: np.ndarray, k: int, steps: int,
              mjd: np.ndarray, name: str, index: int | None):
    """:func:`rigid.earth.forecasters.forecast`, a singular VAR fit said of the record
    (the VAR's `series` is no argument of the caller's)."""
    try:
        return forecast(method, x, y, k, steps)
    except SingularRegressionError as exc:
        first = Time(mjd[k - history_days(method) + 1], format="mjd", scale="utc").iso[:10]
        newest = Time(mjd[k], format="mjd", scale="utc").iso[:10]
        where = f"`{name}`" + ("" if index is None else f" at index {index}")
        raise ValueError(
            f"Expected `record` to hold noise in the history used for {where} ({first} to "
            f"{newest}): method {method!r} fits a VAR({exc.order}) to the residuals of its "
            f"fitted terms, and their lagged regression is singular (pivot {exc.pivot} of "
            f"{exc.size}): the residuals of a noise-free record (a synthetic one, say) are "
            f"a few exact sinusoids, which their own lagged values fit exactly; method "
            f"'ls' forecasts such a record") from None


def _check_history(x: np.ndarray, y: np.ndarray, k: int, history: int) -> None:
    """The history used (``history`` days up to index ``k``): finite, and no datum off its
    neighbours by more than ``SPIKE_LIMIT`` (one bad datum ruins the fitted models'
    forecasts: the ``ls+ar`` 30-day forecast moves ten times as far as the newest datum)."""
    first = k - history + 1
    for name, arr in (("record.x", x), ("record.y", y)):
        part = arr[first:k + 1]
        if not np.all(np.isfinite(part)):
            i = first + int(np.argmin(np.isfinite(part)))
            raise ValueError(f"Expected `{name}` finite in the history used, got "
                             f"{float(arr[i])!r} at index {i}")
        curvature = np.abs(np.diff(part, 2))  # at index i: x[i] - 2 x[i-1] + x[i-2]
        if curvature.size and curvature.max() > SPIKE_LIMIT:
            i = first + 2 + int(np.argmax(curvature > SPIKE_LIMIT))  # where the jump shows
            raise ValueError(
                f"Expected `{name}` free of isolated jumps in the history used (second "
                f"difference at most {SPIKE_LIMIT:g} mas), got {float(arr[i])!r} mas at "
                f"index {i} (second difference {float(curvature[i - first - 2]):.6g} mas)")


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
    starts : Time or date strings, optional
        Start dates (0h UTC).  Default: weekly over ``PAPER_PERIOD`` (the 1st EOP
        PCC's Oct 2005 - Mar 2008, assumed for Lei et al. 2023); the second period is
        ``weekly_starts(*RECENT_PERIOD)`` (``rigid.earth.prediction.weekly_starts``).
    horizons : Quantity or TimeDelta
        Whole days >= 0 (default 10, 30, 90, 150, 270, 365 d).
    method : str
        One of ``METHODS``.
    latency : Quantity or TimeDelta
        Age of the newest datum at each start (default 1 day).

    Returns
    -------
    HindcastScore

    Raises
    ------
    ValueError
        For an unknown method, an empty record, no start dates, a start date outside
        the record (naming its index), negative or fractional horizons or a lead beyond
        the method's (as for :func:`predict`), a latency below a day, a record shorter
        than the method's history, or a bad datum in a history used or one without
        noise (as for :func:`predict`).

    Examples
    --------
    >>> from rigid.earth.prediction import weekly_starts
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
    hs, lat = _lead_days(method, horizons, latency, "horizons", single=False)
    if hs.size == 0:
        raise ValueError("Expected `horizons` to hold at least one horizon, got none")
    history = history_days(method)
    ks = _newest_index("starts", mjd, at, lat, history, method)
    ex, ey, sx, sy = (np.full((at.size, hs.size), np.nan) for _ in range(4))
    steps = lat + int(hs.max())
    for i, k in enumerate(ks):  # per start: a few vectorised calls
        _check_history(x, y, int(k), history)
        mx, my, vx, vy = _forecast(method, x, y, int(k), steps, mjd, "starts",
                                   i if at.size > 1 else None)
        j = lat + hs - 1  # forecast index of each horizon
        # (each horizon's outcome found by its date: a record with a day missing
        # after the start is not scored against the day after it; that horizon is
        # then not scored, as one beyond the record)
        day = mjd[k] + lat + hs
        truth = np.minimum(np.searchsorted(mjd, day), mjd.size - 1)
        seen = mjd[truth] == day
        jj, tt = j[seen], truth[seen]
        ex[i, seen], ey[i, seen] = mx[jj] - x[tt], my[jj] - y[tt]
        sx[i, seen], sy[i, seen] = np.sqrt(vx[jj]), np.sqrt(vy[jj])
    table = _score_table(hs, ex, ey, sx, sy)
    return HindcastScore(
        table=table, method=method, starts=Time(at, format="mjd", scale="utc"),
        horizons=hs * u.day, latency=lat * u.day, errors_x=ex * _MAS, errors_y=ey * _MAS,
        sigma_x=sx * _MAS, sigma_y=sy * _MAS, wall_time=_time.perf_counter() - begin)
