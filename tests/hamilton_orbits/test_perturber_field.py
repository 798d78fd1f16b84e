"""perturber_field: the field of bodies read from an ephemeris (its checks; the field
itself is tested through small_bodies.propagate in test_small_bodies.py)."""

from __future__ import annotations

import pytest

from hamilton_orbits import ephemeris as de
from hamilton_orbits.perturber_field import perturber_chain


@pytest.mark.parametrize("name", ["earth", "Earth", " EARTH "])
def test_a_perturbers_chain_is_found_in_any_case(name):
    """"Earth" was a bare KeyError; names are case-insensitive elsewhere."""
    assert perturber_chain(name) == ((0, 3), (3, 399))
    assert perturber_chain("Ceres") == de.ASTEROID_CHAINS["ceres"]


@pytest.mark.parametrize("name", ["vulcan", 3, None])
def test_an_unknown_perturber_is_refused_naming_the_argument_and_the_known(name):
    """"vulcan" was a bare KeyError, naming neither the argument nor the names known."""
    with pytest.raises(ValueError, match=rf"`name` to be a perturber's name, got {name!r}; "
                                         r"known: sun, mercury, .*, pluto, ceres, .*interamnia"):
        perturber_chain(name)
