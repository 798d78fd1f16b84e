"""The IERS 20 C04 record shipped with astropy-iers-data, read offline, and the wobble fit.

Published Chandler periods: 433 d (0.843 cycles/yr) from maximum likelihood on a
century of polar motion (Wilson & Vicente 1990, Geophys. J. Int. 102, 29; Kuehne,
Wilson & Johnson 1996, J. Geophys. Res. 101, 13573, who also find 439.5 d with proxy
excitation); reviews quote 430-435 d depending on span and method (Gross 2007,
Treatise on Geophysics 3, 239).  The annual wobble is forced at one year.
"""

import socket

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from astropy.utils import iers

from rigid import earth
from rigid.polar_motion import (
    PolarMotionRecord,
    fit_wobble,
    iers2010_mean_pole,
    load_c04,
    periodogram,
)


@pytest.fixture(scope="module")
def offline():
    """No downloads: astropy's auto_download off and every socket refused."""
    mp = pytest.MonkeyPatch()
    mp.setattr(iers.conf, "auto_download", False)

    def refuse(*args, **kwargs):
        raise AssertionError("a network connection was attempted")

    mp.setattr(socket, "socket", refuse)
    mp.setattr(socket, "create_connection", refuse)
    yield
    mp.undo()


@pytest.fixture(scope="module")
def record(offline):
    return load_c04()


@pytest.fixture(scope="module")
def fits(record):
    return {
        "all": fit_wobble(record),
        "1970-2010": fit_wobble(record, 1970, 2010),
        "1980-2020": fit_wobble(record, Time("1980-01-01"), Time("2020-01-01")),
    }


def test_record_is_read_offline_with_the_iers_sign_convention(record):
    assert record.time[0].iso.startswith("1962-01-01")
    assert np.all(np.diff(record.time.mjd) == 1.0)  # daily, no gaps
    # first line of the file: x = -0.012700", y = 0.213000"
    assert record.x[0] == -0.0127 * u.arcsec and record.y[0] == 0.213 * u.arcsec
    assert record.m[0] == (-0.0127 - 0.213j) * u.arcsec  # m1 = x_p, m2 = -y_p
    assert "eopc04" in record.source


def test_chandler_period_within_published_range(fits):
    fit = fits["all"]
    t_c = fit.chandler_period.to_value(u.day)
    assert 430.0 < t_c < 436.0
    assert 0 < fit.chandler_period_error < 3 * u.day
    # the formal error ignores the correlation of daily residuals and is far smaller
    assert fit.chandler_period_error_formal < 0.1 * fit.chandler_period_error
    # well separated from the rigid-Earth Euler period (the elastic Earth lengthens it)
    assert t_c > 1.4 * earth.euler_period().to_value(u.day)


def test_annual_period_within_a_day_of_a_year(fits):
    for fit in fits.values():
        assert abs(fit.annual_period.to_value(u.day) - 365.25) < 1.0


def test_results_stable_when_the_window_changes(fits):
    periods = [f.chandler_period.to_value(u.day) for f in fits.values()]
    errors = [f.chandler_period_error.to_value(u.day) for f in fits.values()]
    for i in range(len(periods)):
        for j in range(i):
            assert abs(periods[i] - periods[j]) < 3 * np.hypot(errors[i], errors[j])
    # amplitudes: Chandler 100-200 mas and annual 70-100 mas before 2010 (REFERENCES)
    for key in ("1970-2010", "all"):
        assert 100 * u.mas < fits[key].chandler_amplitude < 200 * u.mas
        assert 70 * u.mas < fits[key].annual_amplitude < 110 * u.mas
        assert fits[key].annual_retrograde_amplitude < 0.1 * fits[key].annual_amplitude


def test_linear_trend_and_iers_mean_pole_agree(record, fits):
    fit = fit_wobble(record, 1970, 2010, trend="iers2010")
    ref = fits["1970-2010"]
    assert abs(fit.chandler_period - ref.chandler_period) < ref.chandler_period_error
    assert abs(fit.chandler_amplitude - ref.chandler_amplitude) < 5 * u.mas


def test_chandler_amplitude_collapsed_after_2010(fits):
    table = fits["all"].amplitude_by_decade
    amp = dict(zip(table["decade"], table["chandler_amplitude"], strict=True))
    before = np.mean(u.Quantity([amp[d] for d in (1970, 1980, 1990, 2000)]))
    assert amp[2010] < 0.5 * before
    assert table["chandler_amplitude"].unit == u.mas


def test_model_reproduces_the_record_to_the_residual_scatter(record, fits):
    fit = fits["1970-2010"]
    sub = record.select(1970, 2010)
    res = sub.m.to(u.mas) - fit.model(sub.time)
    rms = np.sqrt(np.mean(np.abs(res.value) ** 2) / 2) * u.mas
    assert abs(rms / fit.rms_residual - 1) < 0.01


def test_periodogram_peaks(record):
    f = np.linspace(-1.3, 1.3, 261) / u.yr
    pg = periodogram(record, f)
    amp = pg["amplitude"].to_value(u.mas)
    pro = f.value > 0
    k = np.argmax(np.where(pro, amp, 0))
    assert 420 < pg["period"][k].to_value(u.day) < 445  # the Chandler line (0.01 cpy grid)
    # the annual line is the next (prograde), the retrograde side is small
    k_annual = np.argmin(np.abs(f.value - 1.0))
    assert amp[k_annual] > 50
    assert np.max(amp[~pro & (f.value < -0.5)]) < 0.2 * amp[k]
    # frequencies in 1/day work the same
    pg_day = periodogram(record, (f.to(1 / u.day))[:5])
    np.testing.assert_allclose(pg_day["amplitude"].value, amp[:5], rtol=1e-10)


def test_periodogram_of_one_frequency_and_refusals(record):
    """One frequency (a scalar Quantity) raised numpy's "too many indices"; it is
    a table of one row, the value of the same frequency in an array.  A frequency
    in metres named no argument; an empty record was accepted, and every fit then
    raised a bare IndexError."""
    one = periodogram(record, 1 / (433 * u.day))
    many = periodogram(record, [1 / 433, 1 / 365.25] / u.day)
    assert len(one) == 1
    # (the sum over 20 000 days by a matrix-vector product of one row or of two:
    # BLAS may add in another order, a few ulp apart)
    np.testing.assert_allclose(one["amplitude"][0].value, many["amplitude"][0].value,
                               rtol=1e-13)
    with pytest.raises(u.UnitConversionError, match="`frequency` to be a Quantity of 1/time"):
        periodogram(record, [1 / 433] * u.m)
    with pytest.raises(ValueError, match=r"`time` of shape \(n,\), n >= 1, got \(0,\)"):
        PolarMotionRecord(Time([], format="mjd"), [] * u.arcsec, [] * u.arcsec)


def test_q_estimate_comes_with_its_caveat(fits):
    fit = fits["all"]
    assert 10 < fit.q_estimate < 1000
    assert "not a measurement" in fit.q_caveat and "resolution" in fit.q_caveat
    assert "upper bound" not in fit.q_caveat


def test_a_q_of_a_line_wider_than_the_band_searched_is_said_a_bound(record):
    """Over 2010-2014 the Chandler line's half-power points lie beyond the band
    searched (f_C +- 0.04 cycles/yr): the width was the band's and Q (11) read as
    an estimate.  It is said to be an upper bound, the window too short to part the
    Chandler line from the annual one."""
    fit = fit_wobble(record, 2010, 2014)
    assert fit.q_caveat.startswith(
        f"The Chandler line is wider than the band searched (f_C +- 0.04 cycles/yr): Q "
        f"is at most {fit.q_estimate:.0f}, an upper bound, not an estimate")


def test_units_degrees_work_and_metres_raise(record):
    sub = record.select(1970, 1990)
    deg = PolarMotionRecord(sub.time, sub.x.to(u.deg), sub.y.to(u.deg))
    assert deg.x.unit == u.arcsec
    np.testing.assert_allclose(deg.x.value, sub.x.value, rtol=1e-15, atol=1e-18)
    with pytest.raises(u.UnitConversionError, match="`x`"):
        PolarMotionRecord(sub.time, sub.x.value * u.m, sub.y)
    with pytest.raises(u.UnitConversionError, match="`y`"):
        PolarMotionRecord(sub.time, sub.x, sub.y.value)
    a = fit_wobble(deg, chandler_guess=433 * u.day)
    b = fit_wobble(sub, chandler_guess=(433 * u.day).to(u.yr))
    assert abs(a.chandler_period / b.chandler_period - 1) < 1e-9
    with pytest.raises(u.UnitConversionError, match="chandler_guess"):
        fit_wobble(sub, chandler_guess=433 * u.m)
    with pytest.raises(u.UnitConversionError, match="frequency"):
        periodogram(sub, np.array([0.8, 0.9]))


def test_bad_windows_raise(record):
    with pytest.raises(ValueError, match="Chandler periods"):
        fit_wobble(record, 2000, 2002)
    with pytest.raises(ValueError, match=r"`start` within the record .*got 2100, after"):
        fit_wobble(record, 2100, 2200)
    with pytest.raises(ValueError, match="at least 2 epochs"):
        record.select(2000, 2000.001)
    # (a Time of two dates was a raw TypeError from astropy's float conversion)
    with pytest.raises(ValueError, match=r"Expected `start` to be one time, got a Time of "
                                         r"shape \(2,\)"):
        record.select(Time(["2000-01-01", "2001-01-01"]))
    with pytest.raises(ValueError, match="trend"):
        fit_wobble(record, trend="quadratic")


def test_iers2010_mean_pole_branches():
    """IERS Conventions (2010) eq. 7.25, Table 7.7 (values at 2000.0 and 2010.0)."""
    x, y = iers2010_mean_pole(Time(["2000-01-01T12:00:00", "2010-01-01T12:00:00"],
                                   scale="utc"))
    assert abs(x[0] - 55.974 * u.mas) < 0.001 * u.mas
    assert abs(y[0] - 346.346 * u.mas) < 0.001 * u.mas
    # 2010.0 lies on the linear branch, tau in Julian years from J2000
    tau = (55197.5 - 51544.5) / 365.25
    assert abs(x[1] - (23.513 + 7.6141 * tau) * u.mas) < 1e-9 * u.mas
    assert abs(y[1] - (358.891 - 0.6287 * tau) * u.mas) < 1e-9 * u.mas
    # a date string is a Time (UTC), the same numbers
    xs, ys = iers2010_mean_pole(["2000-01-01T12:00:00", "2010-01-01T12:00:00"])
    np.testing.assert_array_equal(xs, x)
    np.testing.assert_array_equal(ys, y)


def test_fit_recovers_a_synthetic_wobble_exactly():
    """Noise-free data built from the model: the fit returns its parameters (the
    least-squares minimum is exact, so only the solver tolerance 1e-12 remains)."""
    mjd = 44000.0 + np.arange(0.0, 30 * 365.25)
    t = mjd - 0.5 * (mjd[0] + mjd[-1])
    t_c, t_a = 431.7, 365.3
    c_c, c_a, c_r = 150 * np.exp(0.3j), 80 * np.exp(-1.1j), 6 * np.exp(2.0j)
    m = ((40 - 300j) + (0.01 - 0.02j) * t + c_c * np.exp(2j * np.pi * t / t_c)
         + c_a * np.exp(2j * np.pi * t / t_a) + c_r * np.exp(-2j * np.pi * t / t_a))
    rec = PolarMotionRecord(Time(mjd, format="mjd", scale="utc"), m.real * u.mas,
                            -m.imag * u.mas)
    fit = fit_wobble(rec)
    assert abs(fit.chandler_period.to_value(u.day) / t_c - 1) < 1e-9
    assert abs(fit.annual_period.to_value(u.day) / t_a - 1) < 1e-9
    assert abs(fit.chandler_amplitude.to_value(u.mas) - 150) < 1e-6
    assert abs(fit.chandler_phase.to_value(u.rad) - 0.3) < 1e-8
    assert abs(fit.annual_amplitude.to_value(u.mas) - 80) < 1e-6
    assert abs(fit.annual_retrograde_amplitude.to_value(u.mas) - 6) < 1e-6
    assert abs(fit.drift.to_value(u.mas / u.yr) - (0.01 - 0.02j) * 365.25) < 1e-6
    assert fit.rms_residual < 1e-6 * u.mas


def test_error_bars_cover_the_truth_with_white_noise():
    """With white noise (the case the formal covariance is built for) the fitted period
    lies within 4 sigma of the truth for a fixed seed."""
    rng = np.random.default_rng(2024)
    mjd = 44000.0 + np.arange(0.0, 20 * 365.25)
    t = mjd - 0.5 * (mjd[0] + mjd[-1])
    m = 120 * np.exp(2j * np.pi * t / 433.0) + 90 * np.exp(2j * np.pi * t / 365.25)
    m = m + 20 * (rng.normal(size=t.size) + 1j * rng.normal(size=t.size))
    rec = PolarMotionRecord(Time(mjd, format="mjd", scale="utc"), m.real * u.mas,
                            -m.imag * u.mas)
    fit = fit_wobble(rec)
    assert abs(fit.residual_autocorrelation) < 0.05  # white: the AR(1) factor is ~1
    err = fit.chandler_period_error.to_value(u.day)
    assert abs(fit.chandler_period.to_value(u.day) - 433.0) < 4 * err
    assert 0.9 < fit.rms_residual.to_value(u.mas) / 20 < 1.1


@pytest.mark.parametrize("every", [5, 7, 30])
def test_decade_amplitudes_of_a_record_sampled_every_few_days(record, every):
    """The decades of a record not sampled daily (a 5-day, weekly or monthly
    series) were dropped: two years of span were counted as 730 samples.  The
    amplitudes per decade of the sub-sampled record are those of the daily one
    (the same lines, fewer points: 0.3 mas apart at most, measured)."""
    daily = fit_wobble(record).amplitude_by_decade
    sub = PolarMotionRecord(record.time[::every], record.x[::every], record.y[::every])
    table = fit_wobble(sub).amplitude_by_decade
    assert list(table["decade"]) == list(daily["decade"])
    np.testing.assert_allclose(table["chandler_amplitude"].to_value(u.mas),
                               daily["chandler_amplitude"].to_value(u.mas), rtol=0, atol=1.0)


@pytest.mark.parametrize("guess", [380.0, 303.6, 550.0])
def test_a_chandler_guess_far_from_the_line_is_refused(record, guess):
    """A guess more than 10% off (the rigid Euler period, say) gave a sidelobe of a
    few mas as the Chandler line, the record's 120 mas at 433 d unsaid."""
    with pytest.raises(ValueError, match=rf"Expected `chandler_guess` within 10% of the "
                                         rf"record's Chandler line: the guess {guess:.1f} d "
                                         rf"led to a line of .* mas at .* d, but the record "
                                         rf"has one of 1[0-9][0-9] mas at 43[0-9] d"):
        fit_wobble(record, chandler_guess=guess * u.day)


@pytest.mark.parametrize("guess", [365.0, 350.0])
def test_a_chandler_guess_near_one_year_is_refused(record, guess):
    """A guess of 340-375 d over 1970-2010 gave a degenerate fit: "Chandler" and
    annual lines at 368.0 and 367.5 d of 574 and 644 mas cancelling each other,
    three times the residual.  Refused: the record has 11 mas at 368 d once the
    annual terms are projected out, and ~150 mas at 433 d."""
    with pytest.raises(ValueError, match=rf"Expected `chandler_guess` within 10% of the "
                                         rf"record's Chandler line: the guess {guess:.1f} d "
                                         rf"led to a line of [0-9]+\.[0-9] mas at 36[0-9]\.[0-9] "
                                         rf"d, but the record has one of 1[0-9][0-9] mas at "
                                         rf"43[0-9] d"):
        fit_wobble(record, 1970, 2010, chandler_guess=guess * u.day)


@pytest.mark.parametrize("guess", [420.0, 445.0])
def test_a_chandler_guess_within_10_percent_gives_the_fit_of_433_d(record, fits, guess):
    """The guesses within 10% of the record's line still find it: the fit of the
    default guess (433 d), to the solver's tolerance (1e-12 relative in the
    parameters; the start differs)."""
    fit, ref = fit_wobble(record, 1970, 2010, chandler_guess=guess * u.day), fits["1970-2010"]
    for name in ("chandler_period", "annual_period", "chandler_amplitude", "rms_residual"):
        assert abs(getattr(fit, name) / getattr(ref, name) - 1) < 1e-9, name


def test_a_record_whose_epochs_do_not_increase_is_refused(record):
    """Two decades joined in the wrong order were taken, and the fits, select and
    predict then failed with windows of -1 d and ranges that end before they begin."""
    a, b = record.select(1990, 2000), record.select(1980, 1990)
    time = Time(np.concatenate([a.time.mjd, b.time.mjd]), format="mjd", scale="utc")
    x, y = np.concatenate([a.x, b.x]), np.concatenate([a.y, b.y])
    k = len(a)
    with pytest.raises(ValueError, match=rf"Expected `time` to increase, got 1980-01-01 "
                                         rf"00:00:00.000 at index {k} after 1999-12-31 "
                                         rf"00:00:00.000 at index {k - 1}"):
        PolarMotionRecord(time, x, y)
    with pytest.raises(ValueError, match=r"Expected `time` to increase, .* at index 1 after"):
        PolarMotionRecord(Time([51544.0, 51544.0], format="mjd"), [0, 0] * u.mas,
                          [0, 0] * u.mas)
