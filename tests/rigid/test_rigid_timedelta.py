"""rigid takes an astropy TimeDelta wherever it takes a time Quantity: the Quantity in
days it holds (hamilton_orbits.units.time_quantity), to the bit."""

import astropy.units as u
import numpy as np
import pytest
from astropy.time import TimeDelta

import rigid
from rigid import RigidBody, free_motion, free_motion_arrays, poinsot


def _body() -> RigidBody:
    return RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.4, 1.1, -0.3] * u.rad / u.s)


def _same(a, b) -> None:
    """Equal bit for bit, in the same unit."""
    assert getattr(a, "unit", None) == getattr(b, "unit", None)
    np.testing.assert_array_equal(np.asarray(getattr(a, "value", a)),
                                  np.asarray(getattr(b, "value", b)))


DAYS = [0.0, 2.0**-14, 2.0**-12]  # (0, 5.27 s, 21.1 s)


@pytest.mark.parametrize("method", ["cayley_rk4", "dop853"])
def test_integrate_takes_timedeltas_for_t_and_dt(method):
    dt, dtq = TimeDelta(2.0**-20, format="jd"), 2.0**-20 * u.day
    a = rigid.integrate(_body(), TimeDelta(DAYS, format="jd"), dt=dt, method=method)
    b = rigid.integrate(_body(), DAYS * u.day, dt=dtq, method=method)
    _same(a.t, b.t), _same(a.omega, b.omega)
    np.testing.assert_array_equal(a.attitude.as_array(), b.attitude.as_array())
    # a TimeDelta beside a Quantity: one Quantity call
    c = rigid.integrate(_body(), TimeDelta(DAYS[-1], format="jd"), dt=dtq, method=method)
    _same(c.t[-1], b.t[-1])


def test_free_motion_and_poinsot_take_a_timedelta():
    td = TimeDelta(DAYS, format="jd")
    a, b = free_motion(_body(), td), free_motion(_body(), DAYS * u.day)
    _same(a.omega, b.omega)
    np.testing.assert_array_equal(a.attitude.as_array(), b.attitude.as_array())
    p, q = poinsot(_body(), td), poinsot(_body(), DAYS * u.day)
    _same(p.contact, q.contact), _same(p.t, q.t)
    moments = [1.0, 2.0, 3.0] * u.kg * u.m**2
    x = free_motion_arrays(moments, [1, 0, 0, 0], [0.4, 1.1, -0.3] * u.rad / u.s, td)
    y = free_motion_arrays(moments, [1, 0, 0, 0], [0.4, 1.1, -0.3] * u.rad / u.s,
                           DAYS * u.day)
    _same(x[0], y[0]), _same(x[1], y[1])


def test_a_plain_body_answers_a_timedelta_in_quantities_as_a_quantity():
    plain = RigidBody([1.0, 2.0, 3.0], omega=[0.4, 1.1, -0.3])
    a = free_motion(plain, TimeDelta(DAYS, format="jd"))
    b = free_motion(plain, DAYS * u.day)
    _same(a.omega, b.omega)
    assert a.omega.unit == u.rad / u.s


# --- the entries that converted their times through the time kind alone (units.TIME):
# a TimeDelta was "not numeric" or "a bare number" there; the kind now takes it

TD = TimeDelta([0.0, 0.3, 1.7], format="jd")


def _both(call, *tds):
    """``call`` on TimeDeltas and on the Quantities in days they hold."""
    from hamilton_orbits.units import time_quantity

    return call(*tds), call(*(time_quantity(td) for td in tds))


def test_confocal_rotation_and_torque_on_take_a_timedelta():
    from rigid import confocal_rotation
    from rigid.euler import GravityGradientTorque, torque_on

    a, b = _both(lambda t: confocal_rotation(_body(), 0.1 / (u.kg * u.m**2), t), TD)
    np.testing.assert_array_equal(a.as_array(), b.as_array())
    gg = GravityGradientTorque(1e-2 / u.s**2, mean_motion=1e-3 * u.rad / u.s)
    a, b = _both(lambda t: torque_on(gg, [1.0, 2.0, 3.0] * u.kg * u.m**2, [1, 0, 0, 0], t), TD)
    _same(a, b)
    # beside plain numbers, refused as the Quantity is
    plain = RigidBody([1.0, 2.0, 3.0], omega=[0.4, 1.1, -0.3])
    msgs = []
    for t in _both(lambda t: t, TD):
        with pytest.raises(ValueError, match=r"`lam` to be a Quantity like `t`") as info:
            confocal_rotation(plain, 0.1, t)
        msgs.append(str(info.value))
    assert msgs[0] == msgs[1]


def test_the_earths_pole_entries_take_a_timedelta():
    from rigid.earth import simulate_wobble
    from rigid.earth.forecasters import propagate_pole
    from rigid.earth.liouville import LiouvillePole, free_period

    day = TimeDelta(1.0, format="jd")
    a, b = _both(lambda d, h: simulate_wobble(d, dt=h, method="splitting4"),
                 TimeDelta(20.0, format="jd"), TimeDelta(0.125, format="jd"))
    _same(a.t, b.t), _same(a.m, b.m)
    n = np.arange(200.0)
    m = np.exp(2j * np.pi * n / 150.0) * u.mas
    _same(*_both(lambda t: free_period(t, m), TimeDelta(n, format="jd")))
    _same(*_both(lambda p, h: propagate_pole(100 * u.mas, np.zeros(5), chandler_period=p,
                                             step=h), TimeDelta(433.0, format="jd"), day))

    def solve(p, t, t0):
        model = LiouvillePole(("elastic", "annual_excitation"), chandler_period=p,
                              annual_prograde=1e-7, annual_epoch=t0)
        return model.solve(t, 0.1 * u.arcsec, t0=t0), model.excitation(t)

    a, b = _both(solve, TimeDelta(433.0, format="jd"), TD, TimeDelta(0.1, format="jd"))
    _same(a[0], b[0]), _same(a[1], b[1])


def test_cayley_propagate_takes_a_timedelta_end():
    # its grid of n_out times was made from the TimeDelta itself (an array of
    # TimeDelta objects, refused as "the plain number array([<TimeDelta ...")
    from rigid.rodrigues import cayley_propagate

    a, b = _both(lambda te, h: cayley_propagate(_body(), te, h, n_out=3),
                 TimeDelta(2.0**-14, format="jd"), TimeDelta(2.0**-20, format="jd"))
    _same(a.t, b.t), _same(a.omega, b.omega)
    np.testing.assert_array_equal(a.attitude.as_array(), b.attitude.as_array())
