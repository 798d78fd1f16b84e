"""An astropy TimeDelta is taken wherever a time Quantity is: converted once at the
boundary (units.time_quantity) to the Quantity in days it holds, it gives the bits of
that Quantity, and beside plain floats it is refused with the Quantity's message."""

import re

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time, TimeDelta

from hamilton_orbits import Body, KeplerOrbit, Simulation, System, integrate, kepler
from hamilton_orbits.archive import Archive

GM_SUN = 1.32712440018e11 * u.km**3 / u.s**2


def _system() -> System:
    return System([Body("sun", GM_SUN, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                   Body("p", 1e-6 * GM_SUN, [1, 0, 0] * u.au, [0, 29.78, 0] * u.km / u.s)])


def _plain() -> System:
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("p", 1e-6, [1.0, 0, 0], [0, 1.0, 0])])


def _same(a, b) -> None:
    """Equal bit for bit, in the same unit."""
    assert getattr(a, "unit", None) == getattr(b, "unit", None)
    np.testing.assert_array_equal(np.asarray(getattr(a, "value", a)),
                                  np.asarray(getattr(b, "value", b)))


def test_time_quantity_is_the_quantity_in_days_and_leaves_the_rest():
    from hamilton_orbits.units import time_quantity

    q = time_quantity(TimeDelta([0.0, 1.5, 365.25], format="jd"))
    assert q.unit == u.day
    np.testing.assert_array_equal(q.value, [0.0, 1.5, 365.25])
    # both doubles of a TimeDelta summed: a second in days as 1/86400 rounds it
    assert time_quantity(TimeDelta(1.0, format="sec")).value == 1.0 / 86400.0
    for other in (2.0, 3.0 * u.s, "1 d", None, Time("J2000")):
        assert time_quantity(other) is other


def test_integrate_and_simulation_take_a_timedelta_as_the_quantity_in_days():
    s = _system()
    for t in (TimeDelta(365.25, format="jd"), TimeDelta([10.0, 200.0, 365.25], format="jd")):
        q = t.jd * u.day
        a, b = integrate(s, t), integrate(s, q)
        _same(a.t, b.t), _same(a.r, b.r), _same(a.v, b.v)
        a = Simulation(s, method="wh", dt=TimeDelta(1.0, format="jd")).integrate(t)
        b = Simulation(s, method="wh", dt=1.0 * u.day).integrate(q)
        _same(a.t, b.t), _same(a.r, b.r)


def test_an_archive_takes_every_as_a_timedelta(tmp_path):
    s, kw = _system(), dict(method="wh", dt=1.0 * u.day)
    Simulation(s, archive=tmp_path / "td", every=TimeDelta(30.0, format="jd"),
               **kw).integrate(100.0 * u.day)
    Simulation(s, archive=tmp_path / "q", every=30.0 * u.day, **kw).integrate(100.0 * u.day)
    a, b = Archive(tmp_path / "td"), Archive(tmp_path / "q")
    np.testing.assert_array_equal(a.times, [0.0, 30.0, 60.0, 90.0])
    np.testing.assert_array_equal(a.times, b.times)


def test_crosscheck_takes_a_timedelta():
    pytest.importorskip("rebound")
    from hamilton_orbits import crosscheck

    s = _system()
    a = crosscheck(s, TimeDelta(100.0, format="jd"), method="dop853", tol=1e-12)
    b = crosscheck(s, 100.0 * u.day, method="dop853", tol=1e-12)
    _same(a.relative_position_difference, b.relative_position_difference)
    # a trajectory checked against its end given as a TimeDelta
    traj = integrate(s, 100.0 * u.day, method="dop853", tol=1e-12)
    c = crosscheck(s, TimeDelta(100.0, format="jd"), method="dop853", trajectory=traj)
    _same(c.relative_position_difference, b.relative_position_difference)


def test_kepler_propagation_takes_a_timedelta():
    o = KeplerOrbit.from_elements(a=7000 * u.km, e=0.1, inc=98 * u.deg, lan=10 * u.deg,
                                  argp=20 * u.deg, M=0 * u.deg,
                                  mu=398600.4418 * u.km**3 / u.s**2)
    td = TimeDelta([0.0, 0.0625, 0.5], format="jd")
    (r, v), (rq, vq) = o.propagate(td).state(), o.propagate([0.0, 0.0625, 0.5] * u.day).state()
    _same(r, rq), _same(v, vq)
    r0, v0 = o.state()
    r, v = kepler.propagate(r0, v0, 398600.4418 * u.km**3 / u.s**2, td)
    rq, vq = kepler.propagate(r0, v0, 398600.4418 * u.km**3 / u.s**2,
                              [0.0, 0.0625, 0.5] * u.day)
    _same(r, rq), _same(v, vq)


def test_accelerations_at_a_timedelta():
    s = _system()
    _same(s.accelerations(effects=["gr"], t=TimeDelta(3.0, format="jd")),
          s.accelerations(effects=["gr"], t=3.0 * u.day))


def _message(call, value):
    with pytest.raises(ValueError) as info:
        call(value)
    return str(info.value)


@pytest.mark.parametrize("call", [
    lambda t: integrate(_plain(), t),
    lambda t: Simulation(_plain(), method="wh", dt=t),
    lambda t: Simulation(_plain(), method="wh", dt=0.1, archive="unused", every=t),
    lambda t: KeplerOrbit.from_elements(a=1.0, e=0.1, inc=0.1, lan=0.2, argp=0.3, M=0.4,
                                        mu=1.0).propagate(t),
], ids=["integrate", "dt", "every", "propagate"])
def test_beside_plain_floats_a_timedelta_is_refused_as_the_quantity(call, tmp_path,
                                                                   monkeypatch):
    monkeypatch.chdir(tmp_path)  # (an archive folder is never made: refused before)
    got = _message(call, TimeDelta(2.0, format="jd"))
    assert got == _message(call, 2.0 * u.day)
    assert re.search(r"plain floats?|a Quantity exactly when", got)
    assert not (tmp_path / "unused").exists()


def test_small_bodies_propagate_takes_a_timedelta():
    from hamilton_orbits.small_bodies import propagate
    from hamilton_orbits.spk import EXCERPT, Segments

    kw = dict(ephemeris=Segments.load(EXCERPT), asteroids=False)
    r0, v0 = [2.1, -1.3, 0.2] * u.au, [0.004, 0.009, 0.0007] * u.au / u.d
    epoch = Time("2000-01-01T12:00:00", scale="tdb")
    a = propagate(r0, v0, epoch, TimeDelta([10.0, 30.0], format="jd"), **kw)
    b = propagate(r0, v0, epoch, [10.0, 30.0] * u.day, **kw)
    _same(a.r, b.r), _same(a.v, b.v)
    with pytest.raises(ValueError, match=r"a time Quantity, a TimeDelta or an astropy Time, "
                                         r"got 30\.0"):
        propagate(r0, v0, epoch, 30.0, **kw)


def test_an_effect_parameter_as_a_timedelta_is_saved_archived_and_continued_as_the_quantity(
        tmp_path):
    """An effect's time parameter given as a TimeDelta (``earth_tides``' ``tau``) was
    read as the Quantity it holds but kept raw in the effects: ``Simulation.save`` and
    an archive's first snapshot failed with "TypeError: Object of type TimeDelta is
    not JSON serializable" (the archive's folder left empty).  The effects hold the
    Quantity in days: saved, loaded and continued, and archived, to the bits of the
    run given that Quantity."""
    s = System.from_ephemeris("J2000", bodies=["sun", "earth", "moon"])
    days = [0.1, 0.2, 0.3, 0.4, 0.5]
    runs = {}
    for label, tau in (("q", days * u.day), ("td", TimeDelta(days, format="jd")),
                       ("list", [TimeDelta(x, format="jd") for x in days])):
        sim = Simulation(s, "dop853", tol=1e-9, effects=[{"name": "earth_tides", "tau": tau}])
        sim.integrate(1.0 * u.day)
        sim.save(tmp_path / f"{label}.nc")
        loaded = Simulation.load(tmp_path / f"{label}.nc")
        _same(loaded.effects.as_list()[0]["tau"], days * u.day)
        after = loaded.integrate([1.0, 2.0] * u.day)
        archived = Simulation(s, "dop853", tol=1e-9,
                              effects=[{"name": "earth_tides", "tau": tau}],
                              archive=tmp_path / label, every=0.5 * u.day)
        whole = archived.integrate(2.0 * u.day)
        np.testing.assert_array_equal(Archive(tmp_path / label).times,
                                      [0.0, 0.5, 1.0, 1.5, 2.0])
        resumed = Simulation.load(tmp_path / label).integrate(3.0 * u.day)
        runs[label] = (after, whole, resumed)
    for label in ("td", "list"):
        for got, want in zip(runs[label], runs["q"], strict=True):
            _same(got.t, want.t), _same(got.r, want.r), _same(got.v, want.v)


# --- numpy's timedelta64 (and pandas' and the standard library's durations) -----------
# numpy defines np.timedelta64(1, "m") / np.timedelta64(1, "s") == 60; these were read as
# their counts (a minute as 1 s, 1000 ms as 1000 s), silently


def test_a_numpy_duration_is_the_time_quantity_it_is():
    import datetime

    import pandas as pd

    from hamilton_orbits.units import time_quantity

    q = time_quantity(np.array([90, 120], dtype="timedelta64[m]"))
    assert q.unit == u.min
    np.testing.assert_array_equal(q.value, [90.0, 120.0])
    for given, seconds in ((np.timedelta64(1, "m"), 60.0), (np.timedelta64(1500, "ms"), 1.5),
                           (np.timedelta64(2, "W"), 14 * 86400.0),
                           (datetime.timedelta(minutes=1, microseconds=5), 60.000005),
                           (pd.Timedelta(1, "ns"), 1e-9)):
        assert time_quantity(given).to_value(u.s) == pytest.approx(seconds, rel=1e-15, abs=0)
    series = time_quantity(pd.Series(pd.to_timedelta([1, 2], unit="m")))
    np.testing.assert_array_equal(series.to_value(u.s), [60.0, 120.0])
    # not a fixed duration (numpy's calendar year, no unit): left for the argument's check
    for other in (np.timedelta64(1, "Y"), np.timedelta64(5)):
        assert time_quantity(other) is other


def test_rigid_and_orbit_entries_read_a_numpy_duration_in_its_unit():
    from rigid import RigidBody, free_motion
    from rigid import integrate as rigid_integrate

    body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])
    _same(free_motion(body, np.timedelta64(1, "m")).omega, free_motion(body, 1.0 * u.min).omega)
    run = rigid_integrate(body, np.timedelta64(2, "s"), dt=np.timedelta64(100, "ms"),
                          method="rk4")
    assert run.steps == 20
    orbit = KeplerOrbit.from_state([7000.0, 0, 0] * u.km, [0, 7.5, 0] * u.km / u.s,
                                   398600.4418 * u.km**3 / u.s**2)
    _same(orbit.propagate(np.timedelta64(10, "m")).state()[0],
          orbit.propagate(10.0 * u.min).state()[0])
    a = Simulation(_system(), method="radau15").integrate(np.timedelta64(36, "h"))
    b = Simulation(_system(), method="radau15").integrate(36.0 * u.h)
    _same(a.t, b.t), _same(a.r, b.r)


def test_a_numpy_date_duration_or_record_that_is_no_number_is_refused_by_name():
    from rigid import RigidBody, free_motion

    body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])
    for bad, why in ((np.datetime64("2020-01-01"), "a numpy datetime64"),
                     (np.array([(60.0,)], dtype=[("a", "f8")]), "a structured array"),
                     (np.timedelta64(1, "Y"), "a numpy timedelta64"),
                     (np.timedelta64(5), "a numpy timedelta64")):
        with pytest.raises(ValueError, match=f"Expected `t` to be numeric, got {why}"):
            free_motion(body, bad)
    with pytest.raises(ValueError, match="Expected `t` to be finite, got nan at index 1"):
        free_motion(body, np.array([1, "NaT"], dtype="timedelta64[s]"))
    # beside plain floats, refused as the Quantity it is (as a TimeDelta)
    with pytest.raises(ValueError, match="plain floats for a system of plain floats"):
        Simulation(_plain()).integrate(np.timedelta64(2, "D"))
    # a duration where a number of no time is due
    with pytest.raises(ValueError, match="`e` to be dimensionless, got 1 s"):
        kepler.solve_kepler(1.0, np.timedelta64(1, "s"))


def test_a_masked_numpy_duration_is_refused_as_masked():
    # np.asarray dropped the mask: the masked value was read as data
    from hamilton_orbits.units import TIME

    masked = np.ma.array(np.array([1, 2], "m8[s]"), mask=[False, True])
    with pytest.raises(ValueError, match="`t` to be numbers, got a masked value at index 1"):
        TIME("t", masked, "s")
    unmasked = np.ma.array(np.array([1, 2], "m8[m]"))  # (nothing masked: read)
    np.testing.assert_array_equal(TIME("t", unmasked, "s"), [60.0, 120.0])


def test_propagate_names_an_epoch_and_quotes_the_value():
    """An astropy Time given for ``dt`` is an epoch, said so; a string or a number beside
    an orbit of units is quoted (the message had no value)."""
    o = KeplerOrbit.from_elements(a=7000 * u.km, e=0.1, inc=98 * u.deg, lan=10 * u.deg,
                                  argp=20 * u.deg, M=0 * u.deg,
                                  mu=398600.4418 * u.km**3 / u.s**2)
    plain = KeplerOrbit.from_elements(a=1.0, e=0.1, inc=0.1, lan=0.2, argp=0.3, M=0.4, mu=1.0)
    for orbit in (o, plain):
        with pytest.raises(ValueError, match=r"^Expected `dt` to be a duration, got the epoch "
                                             r"<Time .*2020-01-01.*>: .*TimeDelta"):
            orbit.propagate(Time("2020-01-01"))
    with pytest.raises(ValueError, match=r"units \(it has: .*\), got '30 min' \(a string: "
                                         r"u\.Quantity\('30 min'\) reads it\)$"):
        o.propagate("30 min")
    with pytest.raises(ValueError, match=r"units \(it has: .*\), got 1800\.0$"):
        o.propagate(1800.0)
    with pytest.raises(ValueError, match=r"units \(it has none: .*\), got 2 h$"):
        plain.propagate(2 * u.h)
