"""A number with its unit as a string ("0.1 au") is read where the effects read one:
events' `distance` and `small_bodies.propagate(nongrav=..., events=...)`, by the
effects' own reader (effects.parameters.with_units), with its refusals."""

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time

from hamilton_orbits import Body, System, integrate
from hamilton_orbits.small_body_events import encounters

GM_SUN = 1.32712440018e11 * u.km**3 / u.s**2


def _system() -> System:
    """A rock passing a Jupiter-mass planet at 0.015 au after 0.22 yr."""
    return System([
        Body("sun", GM_SUN, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
        Body("jup", 1e-3 * GM_SUN, [1, 0, 0] * u.au, [0, 29.78, 0] * u.km / u.s),
        Body("rock", 0 * GM_SUN, [1.08, 0, 0] * u.au, [0, 29.5, 0] * u.km / u.s)])


def _events(distance, system=None):
    return integrate(_system() if system is None else system, 0.5 * u.yr,
                     events=[{"name": "close_encounter", "distance": distance}]).events


def test_an_event_distance_may_be_a_string():
    a, b = _events("0.1 au"), _events(0.1 * u.au)
    assert len(a) == 1 and list(a["bodies"]) == ["jup-rock"]
    for name in ("time", "distance", "speed"):  # bit for bit
        np.testing.assert_array_equal(a[name], b[name])
    assert len(_events("1e6 km")) == 0  # (0.0067 au: no closer approach)


@pytest.mark.parametrize(("distance", "match"), [
    ("0.1 auu", r"Event at index 0 \('close_encounter'\): cannot read `distance` = "
                r"'0.1 auu' as a number with a unit \(e.g. '6378.1366 km'\)"),
    ("3 d", r"Event at index 0 \('close_encounter'\): expected `distance` to be a length"),
    ("-0.1 au", r"expected `distance` > 0, got '-0.1 au'"),
])
def test_a_bad_event_distance_string_is_refused_by_name(distance, match):
    with pytest.raises(ValueError, match=match):
        _events(distance)


def test_a_distance_string_beside_plain_floats_is_refused_as_a_quantity():
    plain = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                    Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    with pytest.raises(ValueError, match=r"expected `distance` as a plain number in the "
                                         r"system's own length unit .*got '0.1 au'"):
        _events("0.1 au", plain)


def test_a_small_body_encounter_distance_may_be_a_string():
    def one(distance):
        return encounters([{"name": "close_encounter", "bodies": "earth",
                            "distance": distance}], ["rock"], ("earth",))

    assert one("7.5e6 km") == one(7.5e6 * u.km)
    assert one("7.5e6 km")[0].distance == (7.5e6 * u.km).to_value(u.au)
    with pytest.raises(ValueError, match=r"Event at index 0: cannot read `distance` = "
                                         r"'0.05 auu' as a number with a unit"):
        one("0.05 auu")


def _propagate(**kw):
    from hamilton_orbits.small_bodies import propagate
    from hamilton_orbits.spk import EXCERPT, Segments

    return propagate([2.1, -1.3, 0.2] * u.au, [0.004, 0.009, 0.0007] * u.au / u.d,
                     Time("2000-01-01T12:00:00", scale="tdb"), 30 * u.d,
                     ephemeris=Segments.load(EXCERPT), asteroids=False, **kw)


def test_nongrav_of_small_bodies_takes_strings():
    a = _propagate(nongrav={"A2": "-2.9e-8 au/day2", "r0": "1 au"})
    b = _propagate(nongrav={"A2": -2.9e-8 * u.au / u.day**2, "r0": 1 * u.au})
    np.testing.assert_array_equal(a.r.value, b.r.value)
    assert not np.array_equal(a.r.value, _propagate().r.value)  # (A2 pushed it)
    with pytest.raises(ValueError, match=r"`nongrav` at index 0: cannot read `A2` = "
                                         r"'-2.9e-8 auu/day2' as a number with a unit"):
        _propagate(nongrav={"A2": "-2.9e-8 auu/day2"})
    with pytest.raises(u.UnitConversionError, match=r"Expected `nongrav` A2 to be an "
                                                    r"acceleration"):
        _propagate(nongrav={"A2": "1 km"})


def test_nongrav_of_small_bodies_refuses_a_bool_and_takes_a_dimensionless_quantity():
    """``{"A2": True}`` was read as 1 au/day^2 (the body 0.08 au off after a day), and
    ``m`` as ``2 * u.one`` refused as not "a finite number (or Quantity)"."""
    with pytest.raises(ValueError, match=r"Expected `nongrav` A2 a finite number .* got "
                                         r"True at index 0"):
        _propagate(nongrav={"A2": True})
    with pytest.raises(ValueError, match=r"Expected `nongrav` m a finite number .* got "
                                         r"False at index 0"):
        _propagate(nongrav={"A2": -2.9e-8, "m": False})
    a = _propagate(nongrav={"A2": -2.9e-8, "m": 2.0})
    b = _propagate(nongrav={"A2": -2.9e-8, "m": 2 * u.one})
    np.testing.assert_array_equal(a.r.value, b.r.value)
