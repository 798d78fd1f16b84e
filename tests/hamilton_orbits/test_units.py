"""The unit boundary (units.py) and the shared input validation (validation.py)."""

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits.units import is_quantity, strip, wrap
from hamilton_orbits.validation import (
    ConvergenceError,
    as_float_array,
    broadcast,
    check_positive,
    check_trailing,
)


def test_strip_converts_quantities_and_passes_floats():
    # the IAU 2012 astronomical unit is exactly 149597870.7 km
    au_km = [1.495978707e8, 2.991957414e8]
    np.testing.assert_array_equal(strip("r", [1.0, 2.0] * u.au, u.km), au_km)
    np.testing.assert_array_equal(strip("r", [1.0, 2.0], u.km), [1.0, 2.0])
    # a dimensionless Quantity is accepted where no unit is named
    assert float(strip("e", 0.5 * u.dimensionless_unscaled, None)) == 0.5


def test_strip_names_the_argument_on_unit_errors():
    msg = r"`mu` to be a quantity \(convertible to km3 / s2\), got 1 km$"
    with pytest.raises(u.UnitConversionError, match=msg):
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


def test_kinds_read_angles_in_any_unit_and_refuse_them_where_dimensionless():
    from hamilton_orbits.units import ANGLE, ANGULAR_SPEED, DIMENSIONLESS, LENGTH, TIME

    # 90 degrees is a quarter turn: pi/2 to the last bit (astropy's deg is pi/180 rad)
    assert float(ANGLE("angle", 90 * u.deg)) == np.pi / 2
    assert float(ANGLE("angle", 1.0 * u.arcsec)) == np.pi / 648000
    with pytest.raises(u.UnitConversionError, match=r"`e` to be dimensionless, got 5\.7 deg"):
        DIMENSIONLESS("e", 5.7 * u.deg)
    with pytest.raises(u.UnitConversionError, match=r"`angle` to be an angle \(convertible to rad"):
        ANGLE("angle", 1.0 * u.m)
    with pytest.raises(u.UnitConversionError, match="`dt` to be a time"):
        TIME("dt", 1.0 * u.m)
    assert float(ANGULAR_SPEED("omega", 2.0 / u.s)) == 2.0
    assert float(LENGTH("a", 1.0 * u.km)) == 1000.0


def test_mixing_quantities_and_plain_numbers_is_refused():
    from hamilton_orbits.units import require_consistent

    assert require_consistent(("t", "dt"), (1.0, 0.1)) is False
    assert require_consistent(("t", "dt"), (1.0 * u.s, None)) is True
    with pytest.raises(ValueError, match=r"`dt` to be a Quantity like `t`.*the plain number 0\.1"):
        require_consistent(("t", "dt"), (1.0 * u.s, 0.1))
    # a TimeDelta was called "the plain number <TimeDelta ...>"
    from astropy.time import TimeDelta

    with pytest.raises(ValueError, match=r"like `t` \(1.0 s\), got a TimeDelta <TimeDelta"):
        require_consistent(("t", "dt"), (1.0 * u.s, TimeDelta(1.0, format="sec")))


def test_a_masked_value_is_refused_not_read_from_under_its_mask():
    """numpy.asarray reads a masked array's values under the mask: an orbit built
    from a catalogue column with a missing ``a`` took whatever number lay there."""
    from hamilton_orbits.orbit import KeplerOrbit

    with pytest.raises(ValueError, match=r"`x` to be numbers, got a masked value at index 1"):
        as_float_array("x", np.ma.array([1.0, 2.0, 3.0], mask=[0, 1, 0]))
    with pytest.raises(ValueError, match=r"`a` to be numbers, got a masked value at index 1"):
        KeplerOrbit.from_elements(a=np.ma.array([1.0, 2.0], mask=[0, 1]), e=[0.1, 0.2],
                                  inc=[0, 0], lan=[0, 0], argp=[0, 0], nu=[0, 0], mu=1.0)
    np.testing.assert_array_equal(as_float_array("x", np.ma.array([1.0, 2.0])), [1.0, 2.0])


def test_complex_input_is_refused_not_truncated():
    with pytest.raises(ValueError, match="`x` to be real, got complex"):
        as_float_array("x", [1.0 + 2.0j])


@pytest.mark.parametrize("unit", [u.Hz, u.kHz, u.mHz, u.daHz, u.Hz / u.s * u.s])
def test_an_angular_speed_in_hertz_is_refused_by_name(unit):
    """A rotation rate in hertz counts cycles per second, 2 pi rad each; the
    equivalency that reads 1/s as rad/s would take it 2 pi too small, so it is
    refused (ISO 80000-3: angular speeds in rad/s, never Hz); 1/s (the SI base
    form of rad/s) and cycle/s (turns per second) are read as such."""
    from hamilton_orbits.units import ANGULAR_SPEED

    with pytest.raises(u.UnitConversionError, match=r"Expected `spin` to be an angular speed, "
                                                    r"got .*Hz.*cycle / s"):
        ANGULAR_SPEED("spin", 2.0 * unit)
    assert float(ANGULAR_SPEED("spin", 2.0 / u.s)) == 2.0
    assert float(ANGULAR_SPEED("spin", 1.0 * u.cycle / u.s)) == 2 * np.pi
    assert float(ANGULAR_SPEED("spin", 360.0 * u.deg / u.s)) == 2 * np.pi


@pytest.mark.parametrize("unit", [u.Bq, u.MBq, u.Ci])
def test_an_angular_speed_in_decays_per_second_is_refused_by_name(unit):
    """The becquerel and the curie are equal to 1/s for astropy (as the hertz is),
    and were read as radians per second."""
    from hamilton_orbits.units import ANGULAR_SPEED

    with pytest.raises(u.UnitConversionError, match=r"Expected `spin` to be an angular speed, "
                                                    r"got .*: a count of decays per second"):
        ANGULAR_SPEED("spin", 2.0 * unit)


def test_an_angular_momentum_in_hertz_is_refused_by_name():
    """I omega with omega in cycles per second, 2 pi off as a rate in hertz is."""
    from hamilton_orbits.units import ANGULAR_MOMENTUM

    with pytest.raises(u.UnitConversionError, match=r"`L` to be an angular momentum, got .*Hz"):
        ANGULAR_MOMENTUM("L", 2.0 * u.kg * u.m**2 * u.Hz)
    assert float(ANGULAR_MOMENTUM("L", 2.0 * u.kg * u.m**2 * u.cycle / u.s)) == 4 * np.pi


def test_a_number_without_a_unit_where_a_unit_is_asked_is_named_so():
    """A dimensionless Quantity (an effect's string '1.5424', read without a unit)
    where an angle is asked was refused as "got " (the empty unit)."""
    from hamilton_orbits.units import ANGLE

    with pytest.raises(u.UnitConversionError, match=r"Expected `inc` to be an angle "
                                                    r"\(convertible to rad\), got 1.5 \(a "
                                                    r"number without a unit\)$"):
        ANGLE("inc", 1.5 * u.dimensionless_unscaled)


def test_a_zero_dimensional_object_array_is_read_as_its_value():
    """A 0-d object array (of a float, a Fraction) was read as its value; the check of
    None in object arrays broke it (iterating a scalar)."""
    from fractions import Fraction

    assert float(as_float_array("x", np.array(1.5, dtype=object))) == 1.5
    assert float(as_float_array("x", np.array(Fraction(1, 2), dtype=object))) == 0.5
    with pytest.raises(ValueError, match=r"Expected `x` to be numeric, got None$"):
        as_float_array("x", np.array(None, dtype=object))


def test_a_wrong_unit_is_named_with_its_value_and_a_mass_for_a_gm_so():
    """A unit of the wrong dimension was named without its value ("got kg"), and a
    mass given for a GM (const.M_sun, a body's mass) had no word of what to give."""
    import astropy.constants as const

    from hamilton_orbits import Body, KeplerOrbit

    with pytest.raises(u.UnitConversionError,
                       match=r"expected `gm` to be a gravitational parameter GM \(convertible "
                             r"to AU3 / d2\), got 1 solMass; a mass: give G times it "
                             r"\(astropy.constants.G \* m\), or the GM itself$"):
        Body("sun", 1 * u.M_sun, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s)
    with pytest.raises(u.UnitConversionError, match=r"got 5.97217e\+24 kg; a mass: give G"):
        KeplerOrbit.from_elements(a=7000 * u.km, e=0.1, inc=0 * u.deg, lan=0 * u.deg,
                                  argp=0 * u.deg, M=0 * u.deg, mu=const.M_earth)
    with pytest.raises(u.UnitConversionError, match=r"to be a speed \(convertible to AU / d\), "
                                                    r"got \[0, 29.78, 0\] km$"):
        Body("p", 0.0 * u.km**3 / u.s**2, [1, 0, 0] * u.au, [0, 29.78, 0] * u.km)


def test_a_non_cartesian_differential_is_refused_by_name_with_the_way_to_convert_it():
    """A ``SphericalDifferential`` (or any differential but a CartesianDifferential)
    given as a velocity was passed on as it was and refused as "`r`, `v`, `mu` ... got
    a mix", which it is not; its components are Cartesian only with the position they
    are taken at, so it is refused naming the argument, the value, what is taken and
    how to convert it (``v.to_cartesian(base=position)``, which is then taken)."""
    from astropy.coordinates import (
        CartesianRepresentation,
        SphericalCosLatDifferential,
        SphericalDifferential,
        SphericalRepresentation,
    )

    from hamilton_orbits import KeplerOrbit
    from hamilton_orbits.conic import Conic
    from hamilton_orbits.units import as_quantity

    mu = 398600.4418 * u.km**3 / u.s**2
    r = SphericalRepresentation(30 * u.deg, 0 * u.deg, 7000 * u.km)
    v = SphericalDifferential(1e-3 * u.rad / u.s, 0 * u.deg / u.s, 0 * u.km / u.s)
    message = (r"Expected `v` to be Cartesian \(a Quantity of shape \(\.\.\., 3\), a "
               r"coordinate representation or a CartesianDifferential\), got a "
               r"SphericalDifferential <SphericalDifferential \(d_lon, d_lat, d_distance\) "
               r".*give `v.to_cartesian\(base=position\)`")
    with pytest.raises(ValueError, match=message):
        as_quantity("v", v, vector=True)
    with pytest.raises(ValueError, match=message):
        KeplerOrbit.from_state(r, v, mu)
    with pytest.raises(ValueError, match=message):
        Conic.from_state(r, v, mu)
    cos_lat = SphericalCosLatDifferential(1e-3 * u.rad / u.s, 0 * u.deg / u.s, 0 * u.km / u.s)
    with pytest.raises(ValueError, match=r"Expected `r` to be Cartesian .*got a "
                                         r"SphericalCosLatDifferential"):
        KeplerOrbit.from_state(cos_lat, [0, 7.5, 0] * u.km / u.s, mu)
    assert as_quantity("v", v) is v  # (not a vector argument: the caller refuses it)
    # the way the message gives: 7 km/s along the local east, at longitude 30 deg
    o = KeplerOrbit.from_state(r, v.to_cartesian(base=r), mu)
    _, vel = o.state()
    assert isinstance(v.to_cartesian(base=r), CartesianRepresentation)
    assert np.allclose(vel.to_value(u.km / u.s), [-3.5, 7 * np.cos(np.radians(30)), 0.0],
                       rtol=0, atol=1e-12)
