"""KeplerOrbit (and Conic) take a list of Quantities as the one Quantity
``u.Quantity(list)`` makes, and an astropy representation as its Cartesian
coordinates (units.as_quantity, at the state's and the elements' boundary)."""

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import KeplerOrbit

MU = 398600.4418 * u.km**3 / u.s**2
ELEMENTS = dict(e=0.1, inc=98 * u.deg, lan=10 * u.deg, argp=20 * u.deg, M=0 * u.deg, mu=MU)


def _same(a: KeplerOrbit, b: KeplerOrbit) -> None:
    for x, y in zip(a.state(), b.state(), strict=True):
        assert x.unit == y.unit
        np.testing.assert_array_equal(x.value, y.value)


def test_from_elements_takes_a_list_of_quantities():
    a = KeplerOrbit.from_elements(a=[7000 * u.km, 1 * u.Mm], **ELEMENTS)
    b = KeplerOrbit.from_elements(a=[7000.0, 1000.0] * u.km, **ELEMENTS)
    _same(a, b)
    kw = {**ELEMENTS, "M": [0 * u.deg, 0.5 * u.rad]}
    _same(KeplerOrbit.from_elements(a=7000 * u.km, **kw),
          KeplerOrbit.from_elements(a=7000 * u.km, **{**ELEMENTS, "M": [0.0, 0.5] * u.rad}))


def test_from_state_takes_a_list_of_quantities():
    a = KeplerOrbit.from_state([7000 * u.km, 0 * u.km, 0 * u.m], [0, 7.5, 0] * u.km / u.s, MU)
    b = KeplerOrbit.from_state([7000, 0, 0] * u.km, [0, 7.5, 0] * u.km / u.s, MU)
    _same(a, b)
    rows = [[7000 * u.km, 0 * u.km, 0 * u.km], [0 * u.km, 7.1 * u.Mm, 0 * u.km]]
    c = KeplerOrbit.from_state(rows, [[0, 7.5, 0], [-7.5, 0, 0]] * u.km / u.s, MU)
    assert len(c) == 2 and c.state()[0][1, 1] == 7100 * u.km


def test_from_state_takes_astropy_representations():
    from astropy.coordinates import CartesianDifferential, CartesianRepresentation

    r, v = [7000.0, 100.0, -50.0] * u.km, [0.1, 7.5, 0.3] * u.km / u.s
    a = KeplerOrbit.from_state(CartesianRepresentation(r), CartesianRepresentation(v), MU)
    _same(a, KeplerOrbit.from_state(r, v, MU))
    b = KeplerOrbit.from_state(CartesianRepresentation(r), CartesianDifferential(v), MU)
    _same(b, a)
    many = CartesianRepresentation(np.stack([r, 2 * r], axis=-1))  # (shape (2,): xyz first)
    c = KeplerOrbit.from_state(many, v, MU)
    assert len(c) == 2
    np.testing.assert_array_equal(c.state()[0].value, np.stack([r, 2 * r]).value)


@pytest.mark.parametrize("given", [[7000 * u.km, 2.0], [7000 * u.km, 1 * u.s]])
def test_a_list_that_is_not_one_quantity_is_refused_by_name(given):
    with pytest.raises(ValueError, match=r"Expected `a` to be values of one dimension, each "
                                         r"with its unit, got \[<Quantity 7000\. km>, "):
        KeplerOrbit.from_elements(a=given, **ELEMENTS)
    with pytest.raises(ValueError, match=r"Expected `r` to be values of one dimension"):
        KeplerOrbit.from_state([*given, 0 * u.km], [0, 7.5, 0] * u.km / u.s, MU)


def test_a_conic_takes_a_list_of_quantities_and_a_representation():
    from astropy.coordinates import CartesianRepresentation

    from hamilton_orbits.conic import Conic

    r, v = [7000.0, 100.0, -50.0] * u.km, [0.1, 7.5, 0.3] * u.km / u.s
    a = Conic.from_state([7 * u.Mm, 100 * u.km, -50 * u.km], CartesianRepresentation(v), MU)
    b = Conic.from_state(r, v, MU)
    assert a.e == b.e and a.p == b.p
