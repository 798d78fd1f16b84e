"""The unit boundary (units.py) and the shared input validation (_validation.py)."""

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits._validation import (
    ConvergenceError,
    as_float_array,
    broadcast,
    check_positive,
    check_trailing,
)
from hamilton_orbits.units import is_quantity, strip, wrap


def test_strip_converts_quantities_and_passes_floats():
    # the IAU 2012 astronomical unit is exactly 149597870.7 km
    au_km = [1.495978707e8, 2.991957414e8]
    np.testing.assert_array_equal(strip("r", [1.0, 2.0] * u.au, u.km), au_km)
    np.testing.assert_array_equal(strip("r", [1.0, 2.0], u.km), [1.0, 2.0])
    # a dimensionless Quantity is accepted where no unit is named
    assert float(strip("e", 0.5 * u.dimensionless_unscaled, None)) == 0.5


def test_strip_names_the_argument_on_unit_errors():
    with pytest.raises(u.UnitConversionError, match="`mu` in units convertible to km3 / s2"):
        strip("mu", 1.0 * u.km, u.km**3 / u.s**2)


def test_wrap_round_trip():
    assert wrap(np.array([1.0, 2.0]), u.s, True).unit == u.s
    assert not is_quantity(wrap(np.array([1.0, 2.0]), u.s, False))


def test_validation_messages_name_argument_index_and_value():
    a = np.zeros((2, 3))
    a[1, 2] = np.inf
    with pytest.raises(ValueError, match=r"`r` to be finite, got inf at index \(1, 2\)"):
        as_float_array("r", a)
    with pytest.raises(ValueError, match=r"`r` to have shape \(\.\.\., 3\), got \(2, 4\)"):
        check_trailing("r", np.zeros((2, 4)), 3)
    with pytest.raises(ValueError, match=r"`mu` > 0, got -1.0 at index \(1, 0\)"):
        check_positive("mu", np.array([[1.0], [-1.0]]))
    shapes = r"`a`, `b` to broadcast together, got shapes \(2,\), \(3,\)"
    with pytest.raises(ValueError, match=shapes):
        broadcast(("a", "b"), np.zeros(2), np.zeros(3))
    with pytest.raises(ValueError, match="numeric"):
        as_float_array("x", ["a"])
    assert issubclass(ConvergenceError, ValueError)
