"""A masked value (an astropy ``Masked`` Quantity or array, or a numpy masked array)
is refused by name and index where rigid converts its arguments: its mask was
dropped and the number under it used (``Quantity.to_value`` keeps the mask,
``numpy.asarray`` then drops it)."""

import astropy.units as u
import numpy as np
import pytest
from astropy.utils.masked import Masked

from rigid import (
    GravityGradientTorque,
    RigidBody,
    confocal_rotation,
    free_motion,
    integrate,
)
from rigid.earth import simulate_wobble
from rigid.earth.forecasters import propagate_pole
from rigid.earth.liouville import LiouvillePole, free_period

I = [1.0, 2.0, 3.0] * u.kg * u.m**2
W = [0.1, 0.2, 0.3] * u.rad / u.s
T = [0.0, 1.0, 2.0] * u.s


def _masked(q, k):
    """``q`` with its element ``k`` masked."""
    return Masked(q, mask=np.arange(np.size(q)) == k)


BODY = RigidBody(I, omega=W)
CASES = [
    ("inertia", 1, lambda: RigidBody(_masked(I, 1), omega=W)),
    ("omega", 2, lambda: RigidBody(I, omega=_masked(W, 2))),
    ("omega", 1, lambda: BODY.with_state(omega=_masked(W, 1))),
    ("t", 1, lambda: free_motion(BODY, _masked(T, 1))),
    ("t", 2, lambda: integrate(BODY, _masked(T, 2), dt=0.1 * u.s)),
    ("t", 1, lambda: confocal_rotation(BODY, 0.1 / (u.kg * u.m**2), _masked(T, 1))),
    ("gm_over_r3", None, lambda: GravityGradientTorque(Masked(1e-6 / u.s**2, mask=True))),
    ("duration", None, lambda: simulate_wobble(Masked(20 * u.day, mask=True), method="exact")),
    ("t", 1, lambda: LiouvillePole(("elastic",), chandler_period=433.0).solve(
        _masked([0.0, 1.0] * u.day, 1), 0.1 * u.arcsec)),
    ("chi", 2, lambda: propagate_pole(100 * u.mas, _masked(np.zeros(5) * u.mas, 2))),
    ("chi", 2, lambda: propagate_pole(100.0, np.ma.array(np.zeros(5), mask=[0, 0, 1, 0, 0]))),
    ("m0", None, lambda: propagate_pole(Masked(100 * u.mas, mask=True), np.zeros(5))),
    ("m", 3, lambda: free_period(np.arange(20.0) * u.day,
                                 _masked(np.exp(0.3j * np.arange(20.0)) * u.mas, 3))),
]


@pytest.mark.parametrize(("name", "index", "call"), CASES,
                         ids=[f"{k}-{c[0]}" for k, c in enumerate(CASES)])
def test_a_masked_argument_is_refused_by_name_and_index(name, index, call):
    where = "" if index is None else f" at index {index}"
    with pytest.raises(ValueError, match=rf"`{name}` to be numbers, got a masked value"
                                         rf"{where}$"):
        call()


def test_nothing_masked_is_taken_as_the_values():
    a = free_motion(BODY, Masked(T, mask=[False] * 3))
    b = free_motion(BODY, T)
    np.testing.assert_array_equal(a.omega.value, b.omega.value)


_SERIES = dict(chandler_period=433.0, chi_t=[0.0, 100.0, 200.0, 300.0])
COMPLEX_CASES = [
    ("chi", 2, lambda: LiouvillePole(
        ("elastic", "excitation_series"), **_SERIES,
        chi=np.ma.array([0, 1e-7 + 1e-7j, 2e-7, 0], mask=[0, 0, 1, 0])).excitation([150.0])),
    ("m0", None, lambda: LiouvillePole(("elastic",), chandler_period=433.0).solve(
        [0.0, 1.0], np.ma.array(1e-6 + 0j, mask=True))),
    ("m0", 0, lambda: LiouvillePole(("elastic",), chandler_period=433.0).solve(
        [0.0, 1.0], np.ma.array([1e-6 + 0j], mask=[1]))),
    ("annual_prograde", None, lambda: LiouvillePole(
        ("annual_excitation",), annual_prograde=np.ma.array(1e-7 + 1e-8j, mask=True))),
    ("annual_retrograde", None, lambda: LiouvillePole(
        ("annual_excitation",), annual_prograde=1e-7,
        annual_retrograde=np.ma.array(1e-8 + 0j, mask=True))),
]


@pytest.mark.parametrize(("name", "index", "call"), COMPLEX_CASES,
                         ids=[f"{k}-{c[0]}" for k, c in enumerate(COMPLEX_CASES)])
def test_a_masked_complex_angle_of_the_liouville_pole_is_refused(name, index, call):
    """The complex angles of ``LiouvillePole`` (``chi``, ``m0`` of ``solve``, the
    annual amplitudes) as numpy masked arrays were read through ``np.asarray``, the
    values under the mask used ("excitation([150.0])" interpolated the masked 2e-7);
    they are refused by name and index, as ``propagate_pole`` refuses them."""
    where = "" if index is None else f" at index {index}"
    with pytest.raises(ValueError, match=rf"^Expected `{name}` to be numbers, got a masked "
                                         rf"value{where}$"):
        call()
