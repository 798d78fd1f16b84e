"""Polar-motion prediction and hindcasts (rigid.earth.prediction, issue 25).

The published bar (Lei et al. 2023, Artificial Satellites 58, 42, table of mean absolute
errors; C04 only) and the campaigns' scoring (Kalarus et al. 2010; Śliwińska et al. 2022)
are in docs/pole_wander.md; the full hindcasts are the slow tests at the end.
"""

from __future__ import annotations

import re
import socket
import time
from types import SimpleNamespace

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from astropy.utils import iers

from rigid import polar_motion
from rigid.earth.forecasters import CHANDLER_PERIOD, LS_SETTINGS
from rigid.earth.prediction import (
    METHODS,
    PAPER_PERIOD,
    RECENT_PERIOD,
    SPIKE_LIMIT,
    hindcast,
    predict,
    propagate_pole,
    weekly_starts,
)
from rigid.polar_motion import LiouvillePole, PolarMotionRecord, load_c04

AT = Time("2019-01-01")


@pytest.fixture(scope="module")
def record():
    """The C04 record, read with downloads off and every socket refused."""
    mp = pytest.MonkeyPatch()
    mp.setattr(iers.conf, "auto_download", False)

    def refuse(*args, **kwargs):
        raise AssertionError("a network connection was attempted")

    mp.setattr(socket, "socket", refuse)
    mp.setattr(socket, "create_connection", refuse)
    yield load_c04()
    mp.undo()


def _subrecord(rec: PolarMotionRecord, stop: int, garbage: str | None = None):
    """The record up to index ``stop`` (excluded), or with the rest replaced."""
    if garbage is None:
        return PolarMotionRecord(rec.time[:stop], rec.x[:stop], rec.y[:stop])
    x, y = rec.x.copy(), rec.y.copy()
    fill = np.nan if garbage == "nan" else 1e3
    x[stop:] = fill * u.arcsec
    y[stop:] = -fill * u.arcsec
    # PolarMotionRecord refuses NaN; predict takes any record with time, x and y
    return SimpleNamespace(time=rec.time, x=x, y=y)


# --------------------------------------------------------------------------
# No look-ahead
# --------------------------------------------------------------------------

@pytest.mark.parametrize("method", METHODS)
def test_prediction_is_the_same_without_the_record_after_the_start(record, method):
    stop = int(np.searchsorted(record.time.mjd, AT.mjd))  # first epoch at or after AT
    ref = predict(record, at=AT, horizon=365 * u.day, method=method)
    for other in (_subrecord(record, stop), _subrecord(record, stop, "nan"),
                  _subrecord(record, stop, "big")):
        pred = predict(other, at=AT, horizon=365 * u.day, method=method)
        for name in ("x", "y", "sigma_x", "sigma_y"):  # bit for bit
            np.testing.assert_array_equal(getattr(pred, name), getattr(ref, name))
    assert ref.newest_datum.iso.startswith("2018-12-31")


def test_latency_moves_the_newest_datum(record):
    pred = predict(record, at=AT, horizon=10 * u.day, method="ls+ar", latency=3 * u.day)
    assert pred.newest_datum.iso.startswith("2018-12-29")
    assert pred.t[0] == AT and len(pred.t) == 11


def test_a_date_string_is_a_time(record):
    for method in ("ls", "liouville"):
        by_string = predict(record, at="2019-01-01", horizon=30 * u.day, method=method)
        by_time = predict(record, at=AT, horizon=30 * u.day, method=method)
        for name in ("x", "y", "sigma_x", "sigma_y"):  # bit for bit
            np.testing.assert_array_equal(getattr(by_string, name), getattr(by_time, name))
    starts = ["2019-01-01", "2019-01-08"]
    a = hindcast(record, starts, [10] * u.day, method="ls")
    b = hindcast(record, Time(starts), [10] * u.day, method="ls")
    np.testing.assert_array_equal(a.errors_x, b.errors_x)


def test_repr_is_a_few_lines_with_the_arrays_summarised(record):
    pred = predict(record, at=AT, horizon=365 * u.day, method="liouville")
    text = repr(pred)
    assert len(text) < 400 and text.count("\n") <= 3, text
    assert "liouville" in text and "366 days" in text and "2018-12-31" in text


# --------------------------------------------------------------------------
# "ls" on a synthetic record with a known answer
# --------------------------------------------------------------------------

N_SYN, AT_SYN = 9000, 8000  # days; ls+ar uses 20 years of history


def _synthetic(noise_mas: float, seed: int = 3):
    """Trend + Chandler (433 d) + annual + semi-annual, plus white noise, mas."""
    t = np.arange(0.0, N_SYN)
    terms = {"chandler+": 150 * np.exp(0.4j), "annual+": 90 * np.exp(-1.1j),
             "annual-": 6 * np.exp(2.0j), "semiannual+": 3 * np.exp(0.3j)}
    freqs = {"chandler+": 2 * np.pi / CHANDLER_PERIOD, "annual+": 2 * np.pi / 365.2422,
             "annual-": -2 * np.pi / 365.2422, "semiannual+": 4 * np.pi / 365.2422}
    tn = t - (AT_SYN - 1)  # the model's time origin: the newest datum of a prediction
    clean = (100 - 300j) + (4 + 1j) * tn / 365.25
    for k, amp in terms.items():
        clean = clean + amp * np.exp(1j * freqs[k] * tn)
    rng = np.random.default_rng(seed)
    noisy = clean + noise_mas * (rng.normal(size=t.size) + 1j * rng.normal(size=t.size))
    time_ = Time(50000.0 + t, format="mjd", scale="utc")
    rec = PolarMotionRecord(time_, noisy.real * u.mas, -noisy.imag * u.mas)
    return rec, clean, terms


def _formal_errors(window: int, sigma: float) -> np.ndarray:
    """Formal 1-sigma of the LS coefficients [1, t/yr, cos, sin x 3] for white noise."""
    t = np.arange(1.0 - window, 1.0)
    cols = [np.ones_like(t), t / 365.25]
    for period in (CHANDLER_PERIOD, 365.2422, 365.2422 / 2):
        cols += [np.cos(2 * np.pi * t / period), np.sin(2 * np.pi * t / period)]
    design = np.stack(cols, -1)
    return sigma * np.sqrt(np.diag(np.linalg.inv(design.T @ design)))


def test_ls_recovers_a_synthetic_wobble_and_predicts_the_noiseless_truth():
    sigma = 1.0
    rec, clean, terms = _synthetic(sigma)
    pred = predict(rec, at=rec.time[AT_SYN], horizon=365 * u.day, method="ls")
    # a complex amplitude (c -+ i s) / 2 from the real cos, sin coefficients of x and y:
    # its error is ~ the formal error of one coefficient (both have about the same);
    # five times that is the tolerance (the Chandler and annual terms share 3 years)
    err = _formal_errors(LS_SETTINGS["ls"]["window"], sigma)
    for i, name in enumerate(("chandler", "annual", "semiannual")):
        tol = 5 * max(err[2 + 2 * i], err[3 + 2 * i])
        for sign in "+-":
            got = pred.parameters[name + sign].to_value(u.mas)
            assert abs(got - terms.get(name + sign, 0.0)) < tol, (name + sign, got, tol)
    assert abs(pred.parameters["mean"].to_value(u.mas) - (100 - 300j)) < 5 * err[0]
    assert abs(pred.parameters["drift"].to_value(u.mas / u.yr) - (4 + 1j)) < 5 * err[1]
    # the year ahead against the noiseless truth: the parameters' error propagated,
    # below the noise of one value (1 mas)
    truth = clean[AT_SYN:AT_SYN + 366]
    assert np.max(np.abs(pred.x.to_value(u.mas) - truth.real)) < sigma
    assert np.max(np.abs(pred.y.to_value(u.mas) + truth.imag)) < sigma
    # the band of white residuals: the sample noise (within 10% for 2 x 1095 values),
    # grown by the leverage of the extrapolation (a few per cent a year ahead)
    band = pred.sigma_x.to_value(u.mas)
    assert np.all((band > 0.9 * sigma) & (band < 1.2 * sigma))


def test_every_method_follows_a_noiseless_synthetic_wobble():
    rec, clean, _ = _synthetic(0.0)
    truth = clean[AT_SYN:AT_SYN + 366]
    for method in ("ls", "ls+ar", "ls+var"):
        pred = predict(rec, at=rec.time[AT_SYN], horizon=365 * u.day, method=method)
        # exact model, no noise: the least squares reproduce it to rounding; the AR of
        # rounding-level residuals adds nothing measurable
        assert np.max(np.abs(pred.x.to_value(u.mas) - truth.real)) < 1e-6, method


def test_a_noise_free_record_is_named_when_its_residuals_determine_no_var():
    """The Liouville method on a noise-free record: its excitation residuals are
    exact sinusoids, which their lagged values fit exactly.  The refusal named
    `series`, no argument of predict's; it names the record, the history used and
    why, as hindcast does with the start's index."""
    rec, _, _ = _synthetic(0.0)
    with pytest.raises(ValueError, match=r"^Expected `record` to hold noise in the history "
                                         r"used for `at` \(2007-09-04 to 2017-09-03\): method "
                                         r"'liouville' fits a VAR\(5\) to the residuals of its "
                                         r"fitted terms, and their lagged regression is "
                                         r"singular \(pivot [0-9]+ of 10\): the residuals of a "
                                         r"noise-free record"):
        predict(rec, at=rec.time[AT_SYN], horizon=30 * u.day, method="liouville")
    with pytest.raises(ValueError, match=r"^Expected `record` to hold noise in the history "
                                         r"used for `starts` at index 0 \(2007-08-28 to "
                                         r"2017-08-27\): method 'liouville'"):
        hindcast(rec, rec.time[[AT_SYN - 7, AT_SYN]], [10] * u.day, "liouville")


@pytest.mark.parametrize("method", ["ls+ar", "ls+var"])
def test_a_record_shorter_than_the_history_of_a_method_says_so(method):
    """A record of 7300 days for the methods of 20 years (7305 days) of history was
    refused with a range that ends before it begins ("from 2000-01-01 (7305 days of
    history plus the 1 d latency) to 1999-12-27")."""
    rec, _, _ = _synthetic(0.0)
    short = PolarMotionRecord(rec.time[:7300], rec.x[:7300], rec.y[:7300])
    with pytest.raises(ValueError, match=rf"^Expected `record` to span at least the 7305 days "
                                         rf"of history that method '{re.escape(method)}' uses "
                                         rf"before `at` \(less the 1 d latency\), got 7300 "
                                         rf"days, from 1995-10-10 to 2015-10-04$"):
        predict(short, at=short.time[-100], horizon=30 * u.day, method=method)


# --------------------------------------------------------------------------
# The Liouville propagator against LiouvillePole.solve
# --------------------------------------------------------------------------

def test_propagator_matches_liouville_pole_for_the_free_damped_wobble():
    period, q, m0 = 433.0 * u.day, 80.0, (150 - 40j) * u.mas
    m = propagate_pole(m0, np.zeros(2000) * u.mas, chandler_period=period, q=q)
    ref = LiouvillePole(("elastic", "damping"), chandler_period=period, Q=q).solve(
        np.arange(0, 2001) * u.day, m0)
    # both exact: exp(i sigma_c t) by a one-step recursion against the closed form; the
    # recursion's rounding grows ~ n eps over 2000 steps, 1e-12 of the amplitude
    np.testing.assert_allclose(m.to_value(u.mas), ref[1:].to_value(u.mas), rtol=0,
                               atol=1e-12 * 155)


def test_propagator_matches_liouville_pole_for_a_steady_excitation():
    chi = (30 + 10j) * u.mas
    t = np.arange(0, 1001) * u.day
    ref = LiouvillePole(("elastic", "damping", "excitation_series"), chandler_period=433 * u.day,
                        Q=80.0, chi_t=[0.0, 1000.0] * u.day, chi=np.full(2, 1.0) * chi).solve(
                            t, 0 * u.mas)
    m = propagate_pole(0 * u.mas, np.full(1000, 1.0) * chi, q=80.0)
    np.testing.assert_allclose(m.to_value(u.mas), ref[1:].to_value(u.mas), rtol=0, atol=1e-11)


def test_propagator_with_daily_mean_annual_excitation_matches_the_continuous_forcing():
    period, q, amp, p_a = 433.0, 80.0, 20.0 * np.exp(0.7j), 365.2422
    w = 2 * np.pi / p_a
    k = np.arange(3000)
    daily_mean = amp * (np.exp(1j * w * (k + 1)) - np.exp(1j * w * k)) / (1j * w)
    m = propagate_pole(100.0 + 0j, daily_mean, chandler_period=period, q=q)
    model = LiouvillePole(("elastic", "damping", "annual_excitation"),
                          chandler_period=period, Q=q, annual_prograde=amp * u.mas,
                          annual_period=p_a)
    ref = model.solve(np.arange(0, 3001.0) * u.day, 100.0 * u.mas).to_value(u.mas)
    # daily means instead of the sinusoid change the forced response from
    # sigma / (sigma - w) to (1 - a)(e^iw - 1) / (i w (e^iw - a)) (a = e^{i sigma}, one-day
    # steps): 2.1e-5 of it, second order in the step.  The free wobble started from the
    # same pole carries the same difference, so the paths differ by at most twice that
    sigma = 2 * np.pi / period * (1 + 0.5j / q)
    a = np.exp(1j * sigma)
    steady = (1 - a) * (np.exp(1j * w) - 1) / (1j * w * (np.exp(1j * w) - a))
    bound = 2 * abs(steady - sigma / (sigma - w)) * abs(amp)
    err = np.max(np.abs(m - ref[1:]))
    assert 0.25 * bound < err < 1.01 * bound  # the difference is this, not a bug


def test_liouville_excitation_round_trip_reproduces_the_record(record):
    """Inverting the propagator on the record and propagating back gives the record."""
    x = record.x.to_value(u.mas)[-4000:]
    y = record.y.to_value(u.mas)[-4000:]
    m = x - 1j * y
    sigma = 2 * np.pi / CHANDLER_PERIOD * (1 + 0.5j / 80.0)
    a = np.exp(1j * sigma)
    chi = (m[1:] - a * m[:-1]) / (1 - a)
    back = propagate_pole(m[0], chi, q=80.0)
    # exact inverse; rounding in 1 / (1 - a) ~ 69 amplifies eps * 500 mas to ~1e-11 per
    # step, and the recursion keeps it (|a| < 1): 1e-9 mas over 4000 steps
    np.testing.assert_allclose(back, m[1:], rtol=0, atol=1e-9)


# --------------------------------------------------------------------------
# The hindcast against a direct loop
# --------------------------------------------------------------------------

@pytest.mark.parametrize("method", METHODS)
def test_hindcast_statistics_match_a_direct_loop(record, method):
    starts = Time(["2012-03-07", "2013-08-14", "2016-01-06", "2026-08-01"])
    horizons = [0, 10, 30, 90] * u.day
    score = hindcast(record, starts, horizons, method, latency=2 * u.day)
    ex, ey, inx, iny = [], [], [], []
    for at in starts:
        pred = predict(record, at=at, horizon=90 * u.day, method=method, latency=2 * u.day)
        row = []
        for h in horizons.to_value(u.day).astype(int):
            k = np.flatnonzero(record.time.mjd == (at + h * u.day).mjd)
            if k.size == 0:  # the record ends before this outcome
                row.append((np.nan,) * 4)
                continue
            dx = (pred.x[h] - record.x[k[0]]).to_value(u.mas)
            dy = (pred.y[h] - record.y[k[0]]).to_value(u.mas)
            row.append((dx, dy, abs(dx) <= pred.sigma_x[h].to_value(u.mas),
                        abs(dy) <= pred.sigma_y[h].to_value(u.mas)))
        r = np.array(row, dtype=float)
        ex.append(r[:, 0]), ey.append(r[:, 1]), inx.append(r[:, 2]), iny.append(r[:, 3])
    ex, ey, inx, iny = map(np.array, (ex, ey, inx, iny))
    np.testing.assert_allclose(score.errors_x.to_value(u.mas), ex, rtol=1e-12, atol=1e-12)
    table = score.table
    assert table["count"].tolist() == [4, 4, 4, 3]  # the last start has no 90-d outcome
    np.testing.assert_allclose(table["mae_x"].to_value(u.mas), np.nanmean(np.abs(ex), 0),
                               rtol=1e-12)
    np.testing.assert_allclose(table["mae_y"].to_value(u.mas), np.nanmean(np.abs(ey), 0),
                               rtol=1e-12)
    np.testing.assert_allclose(table["rms_2d"].to_value(u.mas),
                               np.sqrt(np.nanmean(ex**2 + ey**2, 0)), rtol=1e-12)
    np.testing.assert_allclose(table["coverage_x"], np.nanmean(inx, 0), rtol=1e-12)
    np.testing.assert_allclose(table["coverage_y"], np.nanmean(iny, 0), rtol=1e-12)


def test_small_hindcast_ranks_the_methods_sensibly(record):
    """Ten weekly starts in 2019: the Liouville prediction beats holding the pole."""
    starts = weekly_starts("2019-01-01", "2019-03-12")
    scores = {m: hindcast(record, starts, [10, 90] * u.day, m).table for m in METHODS}
    assert scores["liouville"]["mae_x"][1] < scores["persistence"]["mae_x"][1]
    assert scores["ls+ar"]["mae_x"][0] < scores["ls"]["mae_x"][0]
    assert all(t["count"].tolist() == [10, 10] for t in scores.values())


def test_predict_and_hindcast_are_reexported_by_polar_motion():
    assert polar_motion.predict is predict
    assert polar_motion.hindcast is hindcast
    assert {"predict", "hindcast"} <= set(polar_motion.__all__)


# --------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------

def test_unknown_method_lists_the_known_ones(record):
    with pytest.raises(ValueError, match=r"`method` one of 'persistence', 'ls', 'ls\+ar', "
                                         r"'ls\+var', 'liouville', got 'lsq'"):
        predict(record, at=AT, horizon=10 * u.day, method="lsq")
    with pytest.raises(ValueError, match=r"`method` one of .* got 'kalman'"):
        hindcast(record, weekly_starts("2019-01-01", "2019-02-01"), method="kalman")


@pytest.mark.parametrize("at", ["1965-01-01", "2028-01-01", "2019-01-01T12:00:00"])
def test_start_outside_the_record_names_the_argument_and_the_value(record, at):
    with pytest.raises(ValueError, match=rf"`at` at 0h UTC within the record.*got {at[:10]}"):
        predict(record, at=Time(at), horizon=10 * u.day)


def test_start_dates_outside_the_record_name_the_index(record):
    starts = Time(["2019-01-01", "2019-01-08", "1970-01-01"])
    with pytest.raises(ValueError, match=r"`starts` .* got 1970-01-01.* at index 2"):
        hindcast(record, starts)


@pytest.mark.parametrize(("horizon", "match"), [
    (-1 * u.day, r"`horizon` in whole days from 0 d to 3651 d, got -1.0 d"),
    (10.5 * u.day, r"`horizon` in whole days from 0 d to 3651 d, got 10.5 d"),
    (365, r"`horizon` to be a time Quantity"),
])
def test_bad_horizon(record, horizon, match):
    with pytest.raises(ValueError, match=match):
        predict(record, at=AT, horizon=horizon)


def test_horizon_and_latency_may_be_timedeltas(record):
    from astropy.time import TimeDelta

    a = predict(record, at=AT, horizon=TimeDelta(30, format="jd"), method="ls",
                latency=TimeDelta(2, format="jd"))
    b = predict(record, at=AT, horizon=30 * u.day, method="ls", latency=2 * u.day)
    for name in ("x", "y", "sigma_x", "sigma_y"):  # bit for bit
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    starts = ["2019-01-01", "2019-01-08"]
    h = hindcast(record, starts, TimeDelta([10, 20], format="jd"), method="ls")
    k = hindcast(record, starts, [10, 20] * u.day, method="ls")
    np.testing.assert_array_equal(h.errors_x, k.errors_x)
    with pytest.raises(ValueError, match=r"`horizon` in whole days from 0 d to 3651 d, "
                                         r"got 10.5 d"):
        predict(record, at=AT, horizon=TimeDelta(10.5, format="jd"))


def test_bad_horizons_latency_starts_and_record(record):
    starts = weekly_starts("2019-01-01", "2019-02-01")
    with pytest.raises(ValueError, match=r"`horizons` in whole days from 0 d to 3651 d, "
                                         r"got -5.0 d at index 1"):
        hindcast(record, starts, [10, -5] * u.day)
    with pytest.raises(ValueError, match="`starts` to hold at least one start date"):
        hindcast(record, Time([], format="mjd"))
    with pytest.raises(ValueError, match="`horizons` to hold at least one horizon"):
        hindcast(record, starts, [] * u.day)
    with pytest.raises(ValueError, match=r"`latency` in whole days from 1 d to 3652 d, "
                                         r"got 0.0 d"):
        predict(record, at=AT, horizon=10 * u.day, latency=0 * u.day)
    with pytest.raises(ValueError, match="`record` from load_c04"):
        predict({"x": 1}, at=AT, horizon=10 * u.day)
    with pytest.raises(ValueError, match="`at` to be an astropy Time or a date, got 'soon'"):
        predict(record, at="soon", horizon=10 * u.day)
    with pytest.raises(u.UnitConversionError, match="horizon"):
        predict(record, at=AT, horizon=10 * u.m)


def test_non_finite_history_is_refused(record):
    stop = int(np.searchsorted(record.time.mjd, AT.mjd))
    x = record.x.copy()
    x[stop - 100] = np.nan * u.arcsec
    bad = SimpleNamespace(time=record.time, x=x, y=record.y)
    with pytest.raises(ValueError, match=rf"`record.x` finite .* got nan at index {stop - 100}"):
        predict(bad, at=AT, horizon=10 * u.day)


def test_horizon_and_latency_must_be_single_times(record):
    """Issue 32, class 7: a list of horizons (or latencies) was read as its first value."""
    with pytest.raises(ValueError, match=r"`horizon` to be a single time, got .*10\., 30\."
                                         r".* \(2 values\)"):
        predict(record, at=AT, horizon=[10, 30] * u.day)
    with pytest.raises(ValueError, match=r"`latency` to be a single time, got .*1\., 3\."):
        predict(record, at=AT, horizon=30 * u.day, latency=[1, 3] * u.day)
    with pytest.raises(ValueError, match=r"`latency` to be a single time"):
        hindcast(record, weekly_starts("2019-01-01", "2019-02-01"), [10] * u.day,
                 "persistence", latency=[1, 3] * u.day)


@pytest.mark.parametrize("horizon", [1826, 3651, 3652, 1e12, 1e300])
def test_persistence_refuses_a_lead_beyond_half_its_window(record, horizon):
    """Issue 32, classes 7 and 19: a NaN sigma at 3651 d, an IndexError from 3652 d, a
    MemoryError at 1e12 d, "negative dimensions" at 1e300 d."""
    value = re.escape(repr(float(horizon)))
    with pytest.raises(ValueError, match=rf"`horizon` in whole days from 0 d to 1825 d, got "
                                         rf"{value} d \(method 'persistence' serves at most "
                                         r"1826 d"):
        predict(record, at=AT, horizon=horizon * u.day, method="persistence")
    longest = predict(record, at=AT, horizon=1825 * u.day, method="persistence")
    assert np.all(np.isfinite(longest.sigma_x)) and np.all(np.isfinite(longest.sigma_y))


def test_every_method_refuses_a_lead_beyond_ten_years(record):
    with pytest.raises(ValueError, match=r"`horizon` in whole days from 0 d to 3649 d, got "
                                         r"1e\+300 d \(method 'ls' serves at most 3652 d"):
        predict(record, at=AT, horizon=1e300 * u.day, method="ls", latency=3 * u.day)
    with pytest.raises(ValueError, match=r"`horizons` .* got 9000.0 d at index 1"):
        hindcast(record, Time(["2019-01-01"]), [10, 9000] * u.day, "ls")
    longest = predict(record, at=AT, horizon=3651 * u.day, method="ls")
    assert np.all(np.isfinite(longest.x)) and np.all(np.isfinite(longest.sigma_x))


def test_an_empty_record_is_refused(record):
    """Issue 32, class 19: an IndexError in both predict and hindcast."""
    empty = SimpleNamespace(time=record.time[:0], x=record.x[:0], y=record.y[:0])
    with pytest.raises(ValueError, match="`record` to hold at least one epoch, got an empty"):
        predict(empty, at=AT, horizon=10 * u.day)
    with pytest.raises(ValueError, match="`record` to hold at least one epoch, got an empty"):
        hindcast(empty, Time(["2019-01-01"]), [10] * u.day)


@pytest.mark.parametrize("method", METHODS)
def test_one_bad_datum_is_refused_not_extrapolated(record, method):
    """Issue 32, class 7: a 1-arcsec spike in the newest datum made the ls+ar, ls+var and
    liouville 30-day forecasts 1e10-1e15 mas; such a datum is now refused, by index."""
    k = int(np.searchsorted(record.time.mjd, AT.mjd)) - 1  # the newest datum used
    for where in (k, k - 100):
        x = record.x.copy()
        x[where] += 1 * u.arcsec
        bad = SimpleNamespace(time=record.time, x=x, y=record.y)
        value = float(x[where].to_value(u.mas))
        with pytest.raises(ValueError, match=rf"`record.x` free of isolated jumps .* got "
                                             rf"{value!r} mas at index {where} "):
            predict(bad, at=AT, horizon=30 * u.day, method=method)
    with pytest.raises(ValueError, match=rf"at index {k} "):
        hindcast(SimpleNamespace(time=record.time, x=record.x, y=record.y + _spike(record.y, k)),
                 Time(["2019-01-01"]), [30] * u.day, method)


def _spike(y: u.Quantity, where: int) -> u.Quantity:
    out = np.zeros(y.shape) * u.mas
    out[where] = 150 * u.mas
    return out


def test_the_record_holds_no_jump_beyond_the_spike_limit(record):
    """The limit is twice the largest second difference of the whole C04 record."""
    for coord in (record.x, record.y):
        assert np.max(np.abs(np.diff(coord.to_value(u.mas), 2))) < SPIKE_LIMIT / 2


# --------------------------------------------------------------------------
# The full hindcasts (slow)
# --------------------------------------------------------------------------

@pytest.mark.slow  # five methods, 126 + 418 weekly starts: ~30 s on a 2-core machine
def test_full_hindcast_runs_in_under_a_minute_and_liouville_leads(record):
    begin = time.perf_counter()
    recent = {m: hindcast(record, weekly_starts(*RECENT_PERIOD), method=m) for m in METHODS}
    wall = time.perf_counter() - begin
    assert wall < 60  # the budget for five methods over eight years
    paper = {m: hindcast(record, weekly_starts(*PAPER_PERIOD), method=m) for m in METHODS}
    for scores in (paper, recent):
        liou = scores["liouville"].table
        both = np.concatenate([liou["mae_x"], liou["mae_y"]])
        for m in ("persistence", "ls"):  # at every horizon, both coordinates
            other = scores[m].table
            assert np.all(both < np.concatenate([other["mae_x"], other["mae_y"]])), m
        ls_ar = scores["ls+ar"].table  # the campaigns' reference: better on average
        assert np.mean(both) < np.mean(np.concatenate([ls_ar["mae_x"], ls_ar["mae_y"]]))
        cover = np.concatenate([liou["coverage_x"], liou["coverage_y"]])
        assert np.all((cover > 0.35) & (cover < 0.85))  # see docs/pole_wander.md


# --------------------------------------------------------------------------
# The pole_prediction scene refuses at load what its run would (issue 32, class 18)
# --------------------------------------------------------------------------

def test_scene_start_and_periods_outside_the_record_are_refused_at_load(record):
    from hamilton_orbits import Scene
    from hamilton_orbits.scene import SceneError

    with pytest.raises(SceneError) as info:
        Scene.from_dict({"kind": "pole_prediction", "start": "2040-01-01", "methods": ["ls"],
                         "periods": ["2024-01-01..2027-01-01"], "horizon": "30 d"})
    assert info.value.problems == [
        "<dict>: start: method 'ls': expected the start date at 0h UTC within the record, "
        "from 1964-12-31 (1095 days of history plus the 1 d latency) to 2026-09-30, got "
        "2040-01-01 00:00:00.000",
        "<dict>: periods[0]: method 'ls': expected the weekly start dates at 0h UTC within "
        "the record, from 1964-12-31 (1095 days of history plus the 1 d latency) to "
        "2026-09-30, got 2026-10-05 00:00:00.000 at index 144"]
    with pytest.raises(SceneError, match=r"horizon: method 'persistence': expected `horizon` "
                                         r"in whole days from 0 d to 1825 d, got 2000.0 d"):
        Scene.from_dict({"kind": "pole_prediction", "methods": ["persistence", "ls"],
                         "periods": [], "horizon": "2000 d"})


def test_hindcast_scores_each_horizon_against_its_own_date_across_a_gap(record):
    """A record with a day missing after a start (a user's file, or one built by
    hand): the outcome of horizon h was taken ``h`` rows on, the day after its own
    (60 d from 2019-01-01 scored against 2019-03-03, 46.758 mas for 48.343).  Each
    outcome is found by its date; the missing day's horizon is not scored."""
    drop = int(np.searchsorted(record.time.mjd, Time("2019-02-01").mjd))
    keep = np.ones(len(record), bool)
    keep[drop] = False
    gap = PolarMotionRecord(record.time[keep], record.x[keep], record.y[keep], "a gap")
    score = hindcast(gap, Time(["2019-01-01"]), [10, 31, 60] * u.day, "persistence")
    newest = int(np.searchsorted(record.time.mjd, Time("2018-12-31").mjd))
    for j, date in ((0, "2019-01-11"), (2, "2019-03-02")):
        k = int(np.searchsorted(record.time.mjd, Time(date).mjd))
        assert score.errors_x[0, j] == record.x[newest] - record.x[k]
    assert np.isnan(score.errors_x[0, 1])  # (2019-02-01, the day missing)
    assert score.table["count"].tolist() == [1, 0, 1]


def test_a_day_missing_in_the_history_is_named(record):
    """A record with a day missing in the history before ``at`` (or a weekly one)
    was refused with "Expected `at` within the record, from 1964 to 2026, got
    2019-01-01": a date plainly within it.  The message names the day missing."""
    at = Time("2019-01-01", scale="utc")
    drop = int(np.searchsorted(record.time.mjd, at.mjd)) - 100
    keep = np.ones(len(record), bool)
    keep[drop] = False
    gap = PolarMotionRecord(record.time[keep], record.x[keep], record.y[keep], "a gap")
    missing = record.time[drop].iso[:10]
    with pytest.raises(ValueError, match=rf"Expected a daily record without gaps over the "
                                         rf"\d+ days of history up to `at` less the 1 d "
                                         rf"latency, got 2019-01-01 00:00:00.000: {missing} is "
                                         rf"not in the record"):
        polar_motion.predict(gap, at=at, horizon=30 * u.day, method="ls")
    weekly = PolarMotionRecord(record.time[::7], record.x[::7], record.y[::7])
    with pytest.raises(ValueError, match=r"Expected a daily record without gaps"):
        polar_motion.predict(weekly, at=weekly.time[-100] + 1 * u.day, horizon=30 * u.day,
                             method="ls")
    with pytest.raises(ValueError, match=r"Expected `at` at 0h UTC within the record"):
        polar_motion.predict(record, at=Time("1963-01-01"), horizon=30 * u.day, method="ls")


def test_hindcast_docstring_imports_what_it_uses():
    """The example of hindcast (reached through rigid.polar_motion) imports weekly_starts
    from where it lives: the docstring runs as written in a fresh namespace (issue 34)."""
    import doctest

    from rigid.earth import prediction

    assert "from rigid.earth.prediction import weekly_starts" in polar_motion.hindcast.__doc__
    assert prediction.weekly_starts.__module__ == "rigid.earth.prediction"
    assert "weekly_starts" in prediction.__all__
    (test,) = doctest.DocTestFinder().find(polar_motion.hindcast, "hindcast",
                                           globs={"u": u, "hindcast": polar_motion.hindcast})
    assert doctest.DocTestRunner().run(test).failed == 0


def test_a_scene_of_no_period_draws_its_fan_and_saves_every_file(tmp_path):
    """``periods = []`` (the forecast from ``start`` alone, nothing scored) ran, then
    failed as its figures were saved (a grid of 0 rows of subplots), leaving half
    the files; a period of reversed dates says why it is refused."""
    from hamilton_orbits import Scene
    from hamilton_orbits.scene import SceneError

    scene = Scene.bundled("pole-prediction")
    with pytest.raises(SceneError, match=r"periods\[0\]: .* the first date before the second"):
        scene.with_values({"periods": '["2016-03-01..2016-01-01"]'})
    result = scene.with_values({"periods": "[]", "methods": '["persistence"]'}).run(
        progress=False)
    names = {p.name for p in result.save(tmp_path)}
    assert {"summary.md", "summary.json"} <= names and any(n.endswith(".png") for n in names)
    # the fan's time axis says its time scale (it said "[d]" only)
    fan = result.plotters[0](result)
    assert fan.axes[1].get_xlabel().startswith("time from the start 2019-01-01 00:00 UTC (days "
                                               "of UTC, as the IERS C04 record's MJD;")
    import matplotlib.pyplot as plt
    plt.close(fan)


def test_a_pole_prediction_stopped_between_periods_says_it_is_incomplete():
    """A Ctrl-C (``stop()``) ends the hindcast after the period it is in: the rest
    were dropped from every file with the result saying it was complete (exit 0)."""
    from hamilton_orbits import Scene

    scene = Scene.bundled("pole-prediction").with_values({
        "periods": '["2016-01-01..2016-02-01", "2017-01-01..2017-02-01"]',
        "methods": '["persistence"]'})
    stopped = scene.run(progress=False, stop=lambda: True)
    assert not stopped.complete and len([k for k in stopped.metrics if
                                         k.startswith("hindcast ")]) == 1
    assert scene.run(progress=False).complete


def test_a_record_of_more_than_one_epoch_a_day_is_named(record):
    """Half-day epochs among the days (every day present): the "day missing"
    message looked for a missing day and found none (an IndexError)."""
    sub = record.select(1995, 2019)
    mjd = sub.time.mjd
    t = np.sort(np.concatenate([mjd, mjd[:-1] + 0.5]))
    x = np.interp(t, mjd, sub.x.to_value(u.mas)) * u.mas
    y = np.interp(t, mjd, sub.y.to_value(u.mas)) * u.mas
    twice = PolarMotionRecord(Time(t, format="mjd", scale="utc"), x, y)
    with pytest.raises(ValueError, match=r"Expected a daily record without gaps .*: the "
                                         r"record has \d+ epochs over those \d+ days, not "
                                         r"one a day at 0h UTC"):
        polar_motion.predict(twice, at="2018-06-01", horizon=30 * u.day, method="persistence")
