"""The IERS 20 C04 polar-motion record, read offline, and the IERS 2010 mean pole.

:func:`load_c04` reads the daily C04 series that ships with ``astropy-iers-data``
into a :class:`PolarMotionRecord` (epochs, ``x_p``, ``y_p``; the complex pole
``m = x_p - i y_p``, IERS convention); :func:`iers2010_mean_pole` is the
conventional mean pole of the IERS Conventions (2010).  The time helpers
:func:`mjd_utc` and :func:`decimal_year` are shared with :mod:`rigid.earth.wobble_fit`.
The public facade is :mod:`rigid.polar_motion`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np
from astropy.time import Time

from hamilton_orbits.units import ANGLE, TIME
from hamilton_orbits.validation import as_float_array

__all__ = ["PolarMotionRecord", "decimal_year", "iers2010_mean_pole", "load_c04", "mjd_utc"]

# the IERS 20 C04 file in astropy-iers-data (offline)
_C04_NAME = "eopc04.1962-now"


@dataclass(frozen=True)
class PolarMotionRecord:
    """Observed polar motion (see :func:`load_c04`).

    Attributes
    ----------
    time : astropy.time.Time, shape (n,)
        Epochs (UTC, 0h of each day).
    x, y : Quantity, shape (n,), arcsec
        The pole coordinates x_p, y_p (IERS).
    source : str
        Where the record was read from.
    """

    time: Time
    x: u.Quantity
    y: u.Quantity
    source: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.time, Time):
            raise ValueError(f"Expected `time` to be an astropy Time, got {type(self.time)}")
        if self.time.ndim != 1 or len(self.time) == 0:
            raise ValueError(f"Expected `time` of shape (n,), n >= 1, got "
                             f"{self.time.shape}")
        days = (self.time.jd1 - self.time.jd1[0]) + (self.time.jd2 - self.time.jd2[0])
        bad = np.nonzero(~(np.diff(days) > 0))[0]
        if bad.size:  # (the fits, select and predict read the record as a time series)
            k = int(bad[0]) + 1
            raise ValueError(f"Expected `time` to increase, got {self.time[k].iso} at index "
                             f"{k} after {self.time[k - 1].iso} at index {k - 1}")
        n = len(self.time)
        for name in ("x", "y"):
            value = getattr(self, name)
            if not isinstance(value, u.Quantity):
                raise u.UnitConversionError(
                    f"Expected `{name}` to be an angle Quantity (e.g. arcsec), got {value!r}"
                )
            arr = ANGLE(name, value, u.arcsec)
            if arr.shape != (n,):
                raise ValueError(f"Expected `{name}` of shape ({n},) like `time`, got {arr.shape}")
            object.__setattr__(self, name, arr * u.arcsec)

    @property
    def m(self) -> u.Quantity:
        """``m = m1 + i m2 = x_p - i y_p`` (IERS convention), complex Quantity (arcsec)."""
        return (self.x.to_value(u.arcsec) - 1j * self.y.to_value(u.arcsec)) * u.arcsec

    def __len__(self) -> int:
        return len(self.x)

    def select(self, start: Any = None, end: Any = None) -> PolarMotionRecord:
        """The part of the record with ``start <= time < end`` (Time, or decimal years).

        A window reaching beyond the record is refused rather than cut short: a
        fit of 2020-2100 on a record that ends in 2026 would be a fit of
        2020-2026 that does not say so.

        Raises
        ------
        ValueError
            For a ``start`` before the record or an ``end`` after it (by more than
            one sampling interval), naming the record's span; for a window with
            fewer than 2 epochs.

        Examples
        --------
        >>> print(load_c04().select(2000, 2001).time[0].iso[:10])
        2000-01-01
        >>> load_c04().select(2020, 2100)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: Expected `end` within the record (1962.00-...), got 2100, after the record...
        """
        yr = decimal_year(self.time)
        step = float(np.median(np.diff(yr))) if yr.size > 1 else 0.0
        keep = np.ones(yr.shape, dtype=bool)
        for name, value in (("start", start), ("end", end)):
            if value is None:
                continue
            y = _year(name, value)
            if not yr[0] - step <= y <= yr[-1] + step:
                raise ValueError(
                    f"Expected `{name}` within the record ({yr[0]:.2f}-{yr[-1]:.2f}, "
                    f"{self.time[0].iso[:10]} to {self.time[-1].iso[:10]}), got {value!r}, "
                    f"{'after the record ends' if y > yr[-1] else 'before it begins'} (leave "
                    f"`{name}` out to {'end' if name == 'end' else 'start'} with the record)")
            keep &= (yr >= y) if name == "start" else (yr < y)
        if keep.sum() < 2:
            raise ValueError(
                f"Expected `start`, `end` to select at least 2 epochs of the record "
                f"({yr[0]:.2f}-{yr[-1]:.2f}), got start={start!r}, end={end!r}"
            )
        return PolarMotionRecord(self.time[keep], self.x[keep], self.y[keep], self.source)


def mjd_utc(time: Time) -> np.ndarray:
    """UTC MJD of ``time`` as floats: whole days between the 0h UTC epochs of the
    record (no scale change for a UTC ``time``).

    Examples
    --------
    >>> mjd_utc(Time(["2000-01-01", "2000-01-02"], scale="utc"))
    array([51544., 51545.])
    """
    return np.asarray(time.utc.mjd if time.scale != "utc" else time.mjd, dtype=np.float64)


def decimal_year(time: Time) -> np.ndarray:
    """Years of 365.25 d counted from 2000-01-01 0h UTC (MJD 51544): 0h on 1 January
    falls on or just after the integer year from 1901 to 2099, so ``start=1970`` keeps
    1970-01-01 and ``end=2010`` drops 2010-01-01.

    Examples
    --------
    >>> decimal_year(Time(["1970-01-01", "2010-01-01"], scale="utc")).round(5)
    array([1970.00137, 2010.00137])
    """
    return 2000.0 + (mjd_utc(time) - 51544.0) / 365.25


def _year(name: str, value: Any) -> float:
    if isinstance(value, Time):
        if value.shape != ():
            raise ValueError(f"Expected `{name}` to be one time, got a Time of shape "
                             f"{value.shape}")
        return float(decimal_year(value))
    if isinstance(value, u.Quantity):
        return TIME.scalar(name, value, u.yr)
    v = as_float_array(name, value)
    if v.shape != ():
        raise ValueError(f"Expected `{name}` to be a scalar, got shape {v.shape}")
    return float(v)


def load_c04(path: Any = None) -> PolarMotionRecord:
    """Read the IERS 20 C04 polar motion that ships with ``astropy-iers-data``.

    The file ``eopc04.1962-now`` (daily since 1962-01-01, columns x_p, y_p in
    arcsec; Bizouard et al. 2019, J. Geodesy 93, 621) is found with
    ``importlib.resources`` and parsed here; nothing is downloaded.

    Parameters
    ----------
    path : str or Path, optional
        Another file in the same format (default: the bundled one).

    Returns
    -------
    PolarMotionRecord

    Raises
    ------
    ValueError
        For a file that is not a C04 table (not text, missing columns, fewer
        than 2 rows, epochs that do not increase, non-finite coordinates),
        naming the file and what is wrong.

    Examples
    --------
    >>> rec = load_c04()
    >>> print(rec.time[0].iso[:10], rec.x.unit, len(rec) > 23000)
    1962-01-01 arcsec True
    """
    if path is None:
        from importlib.resources import files

        path = files("astropy_iers_data") / "data" / _C04_NAME
    data = _read_c04(path)
    time = Time(data[:, 0], format="mjd", scale="utc")
    try:
        return PolarMotionRecord(time, data[:, 1] * u.arcsec, data[:, 2] * u.arcsec, str(path))
    except ValueError as exc:
        raise ValueError(f"Expected `path` ({path}) to hold finite pole coordinates: "
                         f"{exc}") from None


_C04_FORMAT = ("an IERS C04 table: columns year, month, day, 0h UTC, MJD, x_p (arcsec), "
               "y_p (arcsec), ...")


def _read_c04(path: Any) -> np.ndarray:
    """``(MJD, x_p, y_p)`` rows of a C04 file, checked: text, the columns, >= 2 rows,
    epochs increasing."""
    import io

    try:
        with open(str(path), encoding="utf-8") as fh:
            text = fh.read()
    except UnicodeDecodeError as exc:
        raise ValueError(f"Expected `path` ({path}) to be {_C04_FORMAT}; got a file that is "
                         f"not text (byte {exc.object[exc.start]:#04x} at offset "
                         f"{exc.start})") from None
    try:
        data = np.loadtxt(io.StringIO(text), comments="#", usecols=(4, 5, 6), ndmin=2)
    except ValueError as exc:
        raise ValueError(f"Expected `path` ({path}) to be {_C04_FORMAT}; "
                         f"{' '.join(str(exc).split())}") from None
    if data.shape[0] < 2:
        raise ValueError(f"Expected `path` ({path}) to be {_C04_FORMAT} with at least 2 "
                         f"rows, got {data.shape[0]}")
    bad = np.nonzero(~(np.diff(data[:, 0]) > 0))[0]
    if bad.size:
        k = int(bad[0]) + 1
        raise ValueError(f"Expected the epochs (MJD) of `path` ({path}) to increase, got "
                         f"{float(data[k, 0])!r} after {float(data[k - 1, 0])!r} at data row {k}")
    return data


# IERS Conventions (2010), sec. 7.1.4, eq. (7.25) and Table 7.7: the conventional mean
# pole in mas, cubic before 2010.0 and linear after, tau = t - 2000.0 in years.
_MEAN_POLE_2010 = {
    "x_before": (55.974, 1.8243, 0.18413, 0.007024),
    "y_before": (346.346, 1.7896, -0.10729, -0.000908),
    "x_after": (23.513, 7.6141, 0.0, 0.0),
    "y_after": (358.891, -0.6287, 0.0, 0.0),
}


def iers2010_mean_pole(time: Any) -> tuple[u.Quantity, u.Quantity]:
    """The IERS 2010 conventional mean pole ``(x_bar, y_bar)`` in mas.

    IERS Conventions (2010), eq. (7.25) with Table 7.7 (cubic until 2010.0,
    linear after).

    Examples
    --------
    >>> x, y = iers2010_mean_pole(Time("2000-01-01T12:00:00", scale="tt"))
    >>> print(np.round(x, 3), np.round(y, 3))
    55.974 mas 346.346 mas
    """
    if not isinstance(time, Time):  # a date string, or a list of them, is read as UTC
        try:
            time = Time(time, scale="utc")
        except (ValueError, TypeError) as exc:
            raise ValueError(f"Expected `time` to be an astropy Time or a date, got "
                             f"{type(time).__name__}") from exc
    # tau in Julian years from J2000.0 (MJD 51544.5); the UTC-TT offset (~1 min) is
    # irrelevant at the mas level
    tau = (mjd_utc(time) - 51544.5) / 365.25
    before = tau < 10.0
    out = []
    for c in ("x", "y"):
        b = np.polynomial.polynomial.polyval(tau, _MEAN_POLE_2010[f"{c}_before"])
        a = np.polynomial.polynomial.polyval(tau, _MEAN_POLE_2010[f"{c}_after"])
        out.append(np.where(before, b, a) * u.mas)
    return out[0], out[1]


