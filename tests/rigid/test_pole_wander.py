"""The rigid-Earth wobble from the nonlinear integrator against the Euler period,
the exact free motion and the linear theory (Liouville / linearised Euler)."""

import warnings

import astropy.units as u
import numpy as np
import pytest

from rigid import earth
from rigid.earth.free_wobble import WOBBLE_TOLERANCE
from rigid.polar_motion import LiouvillePole, free_period

# |m| ~ 1e-6 rad: the body-frame omega is stored to ~eps * |omega|, so m = omega_xy / omega_z
# is known to ~eps / |m| ~ 2e-10 relative; the comparisons of paths below use 1e-9.
_FLOOR = 1e-9


@pytest.fixture(scope="module")
def century():
    """100 years, daily output: the splitting integrator and the exact free motion."""
    split = earth.simulate_wobble(100 * u.yr, dt=3 * u.hour, method="splitting4")
    exact = earth.simulate_wobble(100 * u.yr, method="exact")
    return split, exact


def test_century_of_daily_output(century):
    split, exact = century
    assert split.t.size == exact.t.size == 36525 + 1
    assert np.all(np.diff(split.t.to_value(u.day)) == 1.0)


def test_period_from_nonlinear_integration_is_the_euler_period(century):
    """The fitted period equals the triaxial linear Euler period to O(wobble^2 + fit)."""
    split, exact = century
    t_e = earth.euler_period(triaxial=True)
    assert abs(float(split.period() / t_e) - 1) < 1e-10
    assert abs(float(exact.period() / t_e) - 1) < 1e-10
    # and it is ~304.5 sidereal days (REFERENCES: Lambeck 1980, sec. 3.1)
    sidereal = (2 * np.pi * u.rad / earth.OMEGA).to(u.day)
    assert abs(float(split.period() / sidereal) - 304.46) < 0.01


def test_axisymmetric_rigid_earth_wobbles_at_omega_h_over_one_minus_h():
    path = earth.simulate_wobble(20 * u.yr, dt=6 * u.hour, triaxial=False)
    assert abs(float(path.period() / earth.euler_period()) - 1) < 1e-10
    # a circle: |m| is constant to the rounding floor
    assert np.ptp(np.abs(path.m)) < _FLOOR * np.abs(path.m[0])


def test_splitting_matches_the_exact_free_motion(century):
    split, exact = century
    scale = np.max(np.abs(exact.m))
    assert np.max(np.abs(split.m - exact.m)) < _FLOOR * scale
    a, b, c = earth.moments().value
    e = np.sqrt((c - a) * a / ((c - b) * b))  # axis ratio of the polhode ellipse (see below)
    assert abs(scale / (e * (0.2 * u.arcsec).to_value(u.rad)) - 1) < 1e-9


def test_nonlinear_path_matches_the_linear_triaxial_solution(century):
    """Linearised Euler equations: m1 = m0 cos(s t), m2 = m0 e sin(s t),
    e = sqrt((C - A) A / ((C - B) B)) (from A p' = -(C - B) Omega q, B q' = (C - A) Omega p);
    nonlinear corrections are O(m0^2) ~ 1e-12."""
    split, _ = century
    a, b, c = earth.moments().value
    s = 2 * np.pi / earth.euler_period(triaxial=True).to_value(u.day)
    e = np.sqrt((c - a) * a / ((c - b) * b))
    t = split.t.to_value(u.day)
    # (in the principal frame: the path is turned to Greenwich by the A axis's longitude)
    body = split.m * np.exp(-1j * earth.constants.A_AXIS_LONGITUDE.to_value(u.rad))
    m0 = body[0].real
    lin = m0 * (np.cos(s * t) + 1j * e * np.sin(s * t))
    assert np.max(np.abs(body - lin)) < _FLOOR * abs(m0)


def test_liouville_free_matches_nonlinear_axisymmetric_rigid_earth():
    """LiouvillePole("free") with the Euler period against the nonlinear integrator."""
    path = earth.simulate_wobble(30 * u.yr, dt=6 * u.hour, triaxial=False)
    model = LiouvillePole(("free",))
    m = model.solve(path.t, path.m[0])
    assert np.max(np.abs(m - path.m)) < _FLOOR * abs(path.m[0])


def test_the_pole_is_turned_from_the_a_axis_to_greenwich():
    """The body frame's x is the least moment's axis A, at atan2(S22, C22) / 2 =
    -14.93 deg (Lambeck 1980, eq. 2.4.2; IERS 2010 C22, S22): a pole displaced
    towards A read x_p = 200 mas, y_p = 0, where the IERS x_p (towards Greenwich)
    and y_p (towards 90 deg W) are 200 cos(14.93 deg) = 193.25 and 200 sin(14.93
    deg) = 51.52 mas."""
    from rigid.earth.constants import A_AXIS_LONGITUDE, C22_BAR, S22_BAR

    lam = 0.5 * np.arctan2(float(S22_BAR), float(C22_BAR))
    assert A_AXIS_LONGITUDE.to_value(u.rad) == pytest.approx(lam, rel=1e-15)
    assert A_AXIS_LONGITUDE.to_value(u.deg) == pytest.approx(-14.9285, abs=1e-4)
    path = earth.simulate_wobble(2 * u.day, wobble=200 * u.mas, method="exact")
    # (a vector at longitude lam: x_p = r cos(lam), y_p = -r sin(lam), west positive)
    assert path.x[0].to_value(u.mas) == pytest.approx(200 * np.cos(lam), rel=1e-12)
    assert path.y[0].to_value(u.mas) == pytest.approx(-200 * np.sin(lam), rel=1e-12)


def test_x_y_follow_the_iers_sign_convention():
    path = earth.simulate_wobble(400 * u.day, method="exact", triaxial=False)
    assert path.x.unit == u.arcsec
    np.testing.assert_allclose(path.x.to_value(u.rad), path.m.real, rtol=1e-15)
    np.testing.assert_allclose(path.y.to_value(u.rad), -path.m.imag, rtol=1e-15)
    # prograde: m turns anticlockwise, so y_p first goes negative (towards 90 deg E)
    k = round(0.25 * earth.euler_period().to_value(u.day))
    assert path.y[k] < -0.19 * u.arcsec


def test_free_period_refuses_bad_input():
    t = np.arange(20.0)
    with pytest.raises(ValueError, match="wobble"):
        free_period(t, np.zeros(20, complex))
    with pytest.raises(ValueError, match="shape"):
        free_period(t, np.ones(19, complex))
    with pytest.raises(u.UnitConversionError, match="`t`"):
        free_period(t * u.m, np.exp(1j * t))
    # equal times: six LAPACK lines on stderr, a RuntimeWarning, then numpy's
    # "SVD did not converge"; times out of order likewise unchecked
    with pytest.raises(ValueError, match=r"`t` strictly monotonic, got t\[1\] = 0.0 after "
                                         r"t\[0\] = 0.0 \(days\)"):
        free_period(np.zeros(20), np.exp(1j * t))
    with pytest.raises(ValueError, match=r"`t` strictly monotonic, got t\[5\] = 4.0 after"):
        free_period(np.r_[t[:5], t[4:-1]], np.exp(1j * t))
    # a path that does not turn (an offset, a drift) was fitted a period of 2.3 d or
    # of 1e9 d, made up; a backward run's decreasing times are a path like any
    with pytest.raises(ValueError, match=r"`m` to turn about the figure axis at least once"):
        free_period(t, np.full(20, 0.1 + 0.05j))
    with pytest.raises(ValueError, match=r"`m` to turn about the figure axis at least once"):
        free_period(t, 0.1 + 1e-3 * t + 0j)
    assert abs(free_period(-t, np.exp(-1j * t)) / (2 * np.pi * u.day) - 1) < 1e-12


@pytest.mark.parametrize("ratio", [1.0, 0.9, 0.0])
def test_free_period_of_a_wobble_along_a_line(ratio):
    """A path whose prograde and retrograde circles are (nearly) equal, ``|b| ~ |a|``:
    a line, whose phase jumps by pi, so that its mean turn started the fit anywhere
    (a 433-day wobble along x gave 4.4e9 days); the periodogram's peak starts it,
    and the period is found (the model's own case: ``b = 0`` to ``b = a``)."""
    t = np.linspace(0.0, 3000.0, 300)
    sigma = 2 * np.pi / 433.0
    m = 0.1 * np.exp(1j * sigma * t) + ratio * 0.1 * np.exp(-1j * sigma * t + 0.3j)
    assert abs(free_period(t * u.d, m * u.arcsec) / (433.0 * u.d) - 1) < 1e-12


@pytest.mark.parametrize("turns", [3.0, 2.5, 1.2])
@pytest.mark.parametrize("ratio", [0.0, 0.5])
@pytest.mark.parametrize("offset", [0.0, 0.05, 0.1, 0.15, 0.2, 0.5, 1.0, 3.0, 10.0])
def test_free_period_of_a_wobble_about_an_offset_mean_pole(offset, ratio, turns):
    """A wobble of 0.2 about a mean pole ``offset`` from the origin (the IERS pole's
    is 0.31 arcsec off): the model had no constant term, so 0.1 and 0.15 gave 426.1
    and 423.0 days for 433, unflagged, and 0.2 or more was refused.  The model with
    the mean pole is exact for this path, daily and noise-free: the period is found
    to the rounding of the samples (measured <= 6e-16 relative up to 1000 times the
    amplitude), whatever the offset's direction or the number of turns."""
    t = np.arange(0.0, turns * 433.0)
    s = 2 * np.pi / 433.0
    for direction in (0.0, 1.0, 2.5, 4.0):
        m = (offset * np.exp(1j * direction) + 0.2 * np.exp(1j * (s * t + 0.7))
             + ratio * 0.2 * np.exp(-1j * s * t))
        assert abs(free_period(t, m * u.arcsec) / (433.0 * u.d) - 1) < 1e-12


def test_free_period_does_not_depend_on_the_mean_pole():
    """A noisy elliptic wobble (noise 10% of the amplitude, the fitted period 0.3%
    off 433 d): the same path moved by any constant gives the same period, to the
    rounding of ``m + z`` (it moved by up to 2.3% before)."""
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 2000.0, 5.0)
    s = 2 * np.pi / 433.0
    m = (0.2 * np.exp(1j * s * t) + 0.05 * np.exp(-1j * s * t + 1j)
         + 0.02 * (rng.standard_normal(t.size) + 1j * rng.standard_normal(t.size)))
    p0 = free_period(t, m)
    assert abs(p0 / (433.0 * u.d) - 1) < 0.01
    for z in (0.05, 0.15j, -0.3 + 0.2j, 2.0, 1e3):
        assert abs(free_period(t, m + z) / p0 - 1) < 1e-9 * max(1.0, abs(z))


@pytest.mark.parametrize("t", [
    [0.0, 33, 37, 94, 119, 159, 370, 404, 621, 650],  # 1.5 turns, a gap of half a turn
    [0.0, 9, 79, 229, 399, 554, 1248, 1280, 1747, 1818, 1955, 2198, 2229, 2264, 2297,
     2382],  # 5.5 turns in 16 points, a gap of 1.6 turns
])
@pytest.mark.parametrize("ratio", [0.0, 0.3, 1.0])
def test_free_period_of_a_sparse_path(t, ratio):
    """Random times whose phase steps by over a quarter turn (it does not unwrap):
    the fit is started from the periodogram too, on a grid of a quarter turn over the
    span (one turn's grid reads 1.5 turns at 1 or 2, or at an alias; both paths were
    refused); the exact path's period is found, about the origin or off it."""
    t = np.array(t)
    s = 2 * np.pi / 433.0
    m = 0.2 * np.exp(1j * (s * t + 1)) + ratio * 0.2 * np.exp(-1j * s * t + 0.4j)
    for z in (0.0, 0.3):
        assert abs(free_period(t, m + z) / (433.0 * u.d) - 1) < 1e-12


def test_free_period_names_a_constant_path():
    with pytest.raises(ValueError, match=r"`m` to turn about the figure axis at least "
                                         r"once, got a constant path: \(0.1\+0.05j\) at "
                                         r"index 0"):
        free_period(np.arange(20.0), np.full(20, 0.1 + 0.05j))
    # an offset path that drifts is no wobble either, whatever its mean
    t = np.arange(100.0)
    with pytest.raises(ValueError, match=r"`m` to turn about the figure axis at least once"):
        free_period(t, 0.3 - 0.2j + 1e-3 * t)


def test_free_period_of_the_iers_pole():
    """The IERS C04 pole about its mean pole (0.31 arcsec off the origin, so it was
    refused): one wobble fitted to 1962-2000 and 1980-2000 is the Chandler wobble,
    near the 433 d of the record (IERS) and within 1.5 d of fit_wobble's (432.3 and
    434.9 d, which also fits the annual terms and a trend)."""
    from rigid.earth.c04 import mjd_utc
    from rigid.polar_motion import fit_wobble, load_c04

    rec = load_c04()
    for start, end in ((1962, 2000), (1980, 2000)):
        window = rec.select(start, end)
        p = free_period(mjd_utc(window.time), window.m)
        assert abs(p / (433.0 * u.d) - 1) < 0.005
        assert abs(p - fit_wobble(rec, start, end).chandler_period) < 1.5 * u.d


def test_free_period_bias_of_a_large_wobble_is_the_documented_one():
    """The model limit said in free_period's docstring: a large triaxial wobble near
    the separatrix (moments 1 : 2 : 2.9, k^2 = 0.98) over 3.37 turns is fitted 0.18%
    short of its exact period (its polhode has harmonics the model has not)."""
    from rigid import RigidBody, free_motion, free_parameters

    body = RigidBody([1.0, 2.0, 2.9], omega=[1.6, 0.0, 1.0])
    par = free_parameters(body)
    assert par.kind == "periodic" and abs(par.m - 0.98) < 0.001
    t = np.linspace(0.0, 3.37 * par.period, 6000)
    w = free_motion(body, t).omega
    p = free_period(t / 86400.0, (w[:, 0] + 1j * w[:, 1]) / w[:, 2])
    assert -0.0019 < p.to_value(u.s) / par.period - 1 < -0.0017


def test_scipy_dop853_agrees_with_the_exact_rigid_earth():
    """An independent integrator (scipy DOP853, rtol 1e-12) over 200 days: the pole
    agrees with the exact motion to 1e-9 of the wobble (measured 1e-13 over 10 years)."""
    dop = earth.simulate_wobble(200 * u.day, method="dop853")
    exact = earth.simulate_wobble(200 * u.day, method="exact")
    assert np.max(np.abs(dop.m - exact.m)) < _FLOOR * np.max(np.abs(exact.m))


@pytest.mark.parametrize(("kw", "name"), [({"duration": 3.0}, "duration"),
                                         ({"wobble": 0.2}, "wobble"), ({"dt": 60.0}, "dt")])
def test_simulate_wobble_refuses_bare_numbers(kw, name):
    """A bare number was read in one of three units: ``duration=3.0`` as 3 days (the
    default is 100 years), ``wobble=0.2`` as 0.2 rad (a pole 11 degrees off, where
    the default is 0.2 arcsec), ``dt=60.0`` as seconds; each is refused, named."""
    kw = {"duration": 3 * u.day, **kw}
    with pytest.raises(ValueError, match=rf"Expected `{name}` to be a Quantity .* got the "
                                         rf"bare number {kw[name]!r}"):
        earth.simulate_wobble(**kw)


@pytest.mark.parametrize("method", ["exact", "splitting4", "dop853"])
def test_a_path_without_wobble_has_no_error_and_no_warning(method):
    """``wobble=0`` warned (0/0, "invalid value in scalar divide") and kept a NaN
    error; the pole stays on the figure axis, followed exactly: error 0."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = earth.simulate_wobble(20 * u.day, wobble=0 * u.arcsec, method=method)
    assert path.error == 0.0 and not np.any(path.m)


@pytest.mark.parametrize(("dt", "pattern"), [
    (0 * u.s, r"`dt` > 0 and at most 1 day"),      # (was a ZeroDivisionError)
    (-1 * u.hour, r"`dt` > 0 and at most 1 day"),  # (was run with a step of 1 day)
    (1 * u.yr, r"`dt` > 0 and at most 1 day"),     # (idem)
    (np.nan * u.s, r"`dt` to be finite"),
])
def test_simulate_wobble_refuses_a_step_it_cannot_take(dt, pattern):
    with pytest.raises(ValueError, match=pattern):
        earth.simulate_wobble(10 * u.day, dt=dt)


@pytest.mark.parametrize(("omega", "pattern"), [
    ([1e-6, 0.0, 0.0], r"`omega` finite with omega_z != 0 .* at index \(\)"),
    ([[1e-6, 0.0, 1.0], [np.nan, 0.0, 1.0]], r"`omega` finite .* at index \(1,\)"),
    ([1.0, 0.0, 1.0] * u.m, r"`omega` to be an angular speed"),
    ([1.0, 0.0, 1.0] * u.Hz, r"`omega` to be an angular speed, got Hz"),  # (2 pi off)
    ("a", r"`omega` to be numeric, got 'a'"),  # (numpy's bare "could not convert")
])
def test_pole_path_refuses_an_omega_without_a_pole(omega, pattern):
    """``m = omega_xy / omega_z``: omega_z = 0 or a NaN used to give inf or NaN
    silently (a divide-by-zero warning), a length an error that did not name
    ``omega``."""
    with pytest.raises(ValueError, match=pattern):
        earth.pole_path(omega)


@pytest.mark.parametrize(("method", "dt", "warned"), [
    ("splitting4", 1 * u.hour, False), ("splitting4y", 1 * u.hour, True),
    ("splitting4y", 10 * u.s, False), ("splitting2", 10 * u.min, True)])
def test_a_pole_that_departs_from_the_exact_one_is_said_so(method, dt, warned):
    """``splitting4y`` at the default step of an hour gave a wobble period 12% short
    (267.5 d for 303.6) and nothing said so: its energy and angular momentum are
    right to rounding, the pole, a 1e-6 share of the spin, is not.  The path is
    measured against the exact free motion (``PolePath.error``) and a departure
    beyond 1e-4 of the wobble is a RuntimeWarning naming the method."""
    import warnings

    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        path = earth.simulate_wobble(2 * u.yr, method=method, dt=dt)
    exact = earth.simulate_wobble(2 * u.yr, method="exact")
    error = np.max(np.abs(path.m - exact.m)) / np.max(np.abs(exact.m))
    assert path.error == error and exact.error == 0.0
    assert (error > earth.free_wobble.WOBBLE_TOLERANCE) == warned
    assert [str(w.message).startswith(f"simulate_wobble: the {method} pole departs")
            for w in said] == ([True] if warned else [])


def test_simulate_wobble_takes_no_dt_where_it_is_ignored_and_a_record_a_scalar_time_named():
    """``dt=None`` is documented as ignored by "exact" and "dop853" (refused since bare
    numbers are); a record of a scalar Time raised a bare TypeError."""
    from astropy.time import Time

    from rigid.polar_motion import PolarMotionRecord

    assert earth.simulate_wobble(30 * u.day, method="exact", dt=None).error == 0.0
    with pytest.raises(ValueError, match=r"`dt` to be a Quantity"):
        earth.simulate_wobble(30 * u.day, method="splitting4", dt=None)
    with pytest.raises(ValueError, match=r"`time` of shape \(n,\), n >= 1, got \(\)"):
        PolarMotionRecord(Time(51544.0, format="mjd"), 0.1 * u.arcsec, 0.1 * u.arcsec)


def test_the_pole_of_a_run_whose_attitude_drifted_is_not_warned_of():
    # rk4 at a step of a day: |q| drifts (rigid.integrate warns of the attitude), but
    # the pole is read from omega alone, here within 2e-8 of the wobble of the exact
    # free motion: simulate_wobble says nothing of an attitude it does not use
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = earth.simulate_wobble(1 * u.yr, dt=1 * u.day, method="rk4")
    assert path.error < 2e-8 < WOBBLE_TOLERANCE
