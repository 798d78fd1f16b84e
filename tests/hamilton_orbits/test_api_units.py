"""Every public argument of the two-body API (orbit, kepler, conic) walks through
its unit boundary: a Quantity of the wrong dimension raises UnitConversionError
naming the argument, an angle where a pure number is expected is refused, and
non-numeric / out-of-range Python input is a ValueError naming the argument
(issue 7, item 1)."""

import functools

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import kepler
from hamilton_orbits.orbit import (
    KeplerOrbit,
    hamilton_beta,
    hamilton_epsilon_from_products,
    hamilton_p,
)

KM, KMS, MU, S = u.km, u.km / u.s, u.km**3 / u.s**2, u.s
R = [7000.0, 0.0, 0.0] * KM
V = [0.0, 8.0, 0.5] * KMS
GM = 398600.4418 * MU
ELEMENTS = dict(a=8000.0 * KM, e=0.1, inc=0.2 * u.rad, lan=0.3 * u.rad, argp=0.4 * u.rad,
                nu=0.5 * u.rad, mu=GM)


@functools.cache
def _orbit() -> KeplerOrbit:
    """The orbit of ``R``, ``V``, ``GM``, made at the first test that asks (not at
    collection: every test process would compile the elements' kernel there)."""
    return KeplerOrbit.from_state(R, V, GM)


def _of_orbit(path: str):
    """The orbit's method ``path`` (``"propagate"``, ``"conic.radius"``), called on
    :func:`_orbit`; named as the method is (the test ids)."""
    owner, _, name = path.rpartition(".")

    def call(**kw):
        return getattr(getattr(_orbit(), owner) if owner else _orbit(), name)(**kw)

    call.__qualname__ = f"{'Conic' if owner else 'KeplerOrbit'}.{name}"
    return call


# one wrong-dimension stand-in per kind of argument
WRONG = {
    "length": 1.0 * u.s,
    "speed": 1.0 * u.km,
    "gm": 1.0 * u.km**2 / u.s,
    "time": 1.0 * u.m,
    "angle": 1.0 * u.m,
    "dimensionless": 1.0 * u.m,
}

# (function, valid keyword arguments, {argument: kind})
TABLE = [
    (KeplerOrbit.from_state, dict(r=R, v=V, mu=GM),
     {"r": "length", "v": "speed", "mu": "gm"}),
    (KeplerOrbit.from_elements, ELEMENTS,
     {"a": "length", "e": "dimensionless", "inc": "angle", "lan": "angle", "argp": "angle",
      "nu": "angle", "mu": "gm"}),
    (KeplerOrbit.from_elements, {**{k: x for k, x in ELEMENTS.items() if k != "a"},
                                 "p": 7000.0 * KM}, {"p": "length"}),
    (KeplerOrbit.from_elements, {**{k: x for k, x in ELEMENTS.items() if k not in "anu"},
                                 "q": 7000.0 * KM, "M": 0.3 * u.rad},
     {"q": "length", "M": "angle"}),
    (_of_orbit("propagate"), dict(dt=100.0 * S), {"dt": "time"}),
    (kepler.solve_kepler, dict(M=1.0 * u.rad, e=0.5), {"M": "angle", "e": "dimensionless"}),
    (kepler.mean_anomaly, dict(anomaly=1.0 * u.rad, e=0.5),
     {"anomaly": "angle", "e": "dimensionless"}),
    (kepler.anomaly_from_true, dict(nu=1.0 * u.rad, e=0.5), {"nu": "angle", "e": "dimensionless"}),
    (kepler.true_from_anomaly, dict(anomaly=1.0 * u.rad, e=0.5),
     {"anomaly": "angle", "e": "dimensionless"}),
    (kepler.propagate, dict(r=R, v=V, mu=GM, dt=100.0 * S),
     {"r": "length", "v": "speed", "mu": "gm", "dt": "time"}),
    (hamilton_beta, dict(r=R, v=V), {"r": "length", "v": "speed"}),
    (hamilton_epsilon_from_products, dict(r=R, v=V, mu=GM),
     {"r": "length", "v": "speed", "mu": "gm"}),
    (hamilton_p, dict(r=R, v=V, mu=GM), {"r": "length", "v": "speed", "mu": "gm"}),
    (_of_orbit("conic.radius"), dict(nu=0.5 * u.rad), {"nu": "angle"}),
    (_of_orbit("conic.focal_half_chord"), dict(r=7000.0 * KM), {"r": "length"}),
    (_of_orbit("conic.second_focal_distance"), dict(r=7000.0 * KM), {"r": "length"}),
    (_of_orbit("conic.normal_length"), dict(r=7000.0 * KM), {"r": "length"}),
    (_of_orbit("conic.radius_of_curvature"), dict(r=7000.0 * KM), {"r": "length"}),
    (_of_orbit("conic.radial_speed_squared"), dict(r=7000.0 * KM), {"r": "length"}),
    (_of_orbit("conic.hodograph"), dict(r=R), {"r": "length"}),
]

CASES = [
    pytest.param(f, kw, arg, kind, id=f"{f.__qualname__}-{arg}")
    for f, kw, kinds in TABLE
    for arg, kind in kinds.items()
]


def _call(f, kw):
    out = f(**kw)
    if isinstance(out, KeplerOrbit):  # elements are lazy: ask for them
        out = (out.e, out.state())
    return out


@pytest.mark.parametrize(("f", "kw", "arg", "kind"), CASES)
def test_valid_call_passes(f, kw, arg, kind):
    _call(f, kw)  # the reference call of each row is valid


@pytest.mark.parametrize(("f", "kw", "arg", "kind"), CASES)
def test_wrong_dimension_names_the_argument(f, kw, arg, kind):
    good = kw[arg]
    wrong = WRONG[kind] * np.ones(np.shape(good)) if np.ndim(good) else WRONG[kind]
    with pytest.raises(u.UnitConversionError, match=f"`{arg}`"):
        _call(f, {**kw, arg: wrong})


@pytest.mark.parametrize(("f", "kw", "arg", "kind"), CASES)
def test_none_and_text_name_the_argument(f, kw, arg, kind):
    for bad in (None, "abc"):
        with pytest.raises(ValueError, match=f"`{arg}`"):
            _call(f, {**kw, arg: bad})


ANGLE_FOR_PURE_NUMBER = [c for c in CASES if c.values[3] == "dimensionless"]


@pytest.mark.parametrize(("f", "kw", "arg", "kind"), ANGLE_FOR_PURE_NUMBER)
def test_angle_for_a_pure_number_is_refused(f, kw, arg, kind):
    # 5.7 deg is 0.0995 rad: read as a number it would pass as a plausible e
    with pytest.raises(u.UnitConversionError, match=f"`{arg}` to be dimensionless"):
        _call(f, {**kw, arg: 5.7 * u.deg})


def test_issue7_reproducers_units():
    with pytest.raises(u.UnitConversionError, match="`e`"):
        KeplerOrbit.from_elements(a=1.0, e=5.7 * u.deg, inc=0.0, lan=0.0, argp=0.0, nu=0.0,
                                  mu=1.0)
    with pytest.raises(u.UnitConversionError, match="`e`"):
        kepler.solve_kepler(1.0, 30 * u.deg)
    # a Python int beyond float64 is refused by name, not an OverflowError
    with pytest.raises(ValueError, match="`mu` to be finite"):
        KeplerOrbit.from_state([1.0, 0, 0], [0, 1.0, 0], 10**400)
    with pytest.raises(ValueError, match="`mu` to be finite"):
        KeplerOrbit.from_elements(a=1.0, e=0.1, inc=0.0, lan=0.0, argp=0.0, nu=0.0, mu=10**400)
    with pytest.raises(ValueError, match="`dt` to be finite"):
        kepler.propagate([1.0, 0, 0], [0, 1.0, 0], 1.0, -(10**400))


def test_angles_in_any_unit_and_quantities_out():
    deg = KeplerOrbit.from_elements(a=1.0 * u.km, e=0.1, inc=30 * u.deg, lan=0.0, argp=0.0,
                                    nu=90 * u.deg, mu=1.0 * MU)
    rad = KeplerOrbit.from_elements(a=1.0 * u.km, e=0.1, inc=np.pi / 6, lan=0.0, argp=0.0,
                                    nu=np.pi / 2, mu=1.0 * MU)
    np.testing.assert_array_equal(deg.state()[0].value, rad.state()[0].value)
    assert _orbit().conic.radius(90 * u.deg).unit == KM
    # beta = r x v exactly here (one nonzero product per component)
    beta = hamilton_beta(R, V)
    assert beta.unit == KM * KMS
    np.testing.assert_array_equal(beta.value, np.cross(R.value, V.value))
    assert hamilton_p(R, V, GM).unit == KM
    with pytest.raises(ValueError, match="`v` to be a Quantity like `r`"):
        hamilton_beta(R, V.value)
    with pytest.raises(ValueError, match="`r` nonzero"):
        hamilton_epsilon_from_products([0.0, 0, 0], [0, 1.0, 0], 1.0)
