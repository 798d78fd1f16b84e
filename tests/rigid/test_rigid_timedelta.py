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
