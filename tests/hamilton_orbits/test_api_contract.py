"""The two-body API's contract as a property (issue 7): finite input over many
magnitudes gives no warning (the suite runs with warnings as errors), no NaN
and no infinity except where documented (a, b of a parabola, period of an
unbound orbit, ...), or else a ValueError / UnitConversionError that names the
offending argument."""

import re

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hamilton_orbits import KeplerOrbit, kepler
from hamilton_orbits.orbit import hamilton_beta, hamilton_epsilon_from_products, hamilton_p


def magnitude(lo=-150, hi=150, signed=True):
    """Floats m 10^k, |m| in [1, 10), k in [lo, hi], plus exact 0 and small integers."""
    sign = st.sampled_from([-1.0, 1.0]) if signed else st.just(1.0)
    base = st.builds(lambda s, m, k: s * m * 10.0**k, sign,
                     st.floats(1.0, 9.999, allow_nan=False), st.integers(lo, hi))
    return st.one_of(base, st.sampled_from([0.0, 1.0, -1.0, 2.0, 0.5] if signed else [1.0, 2.0]))


vec = st.tuples(magnitude(), magnitude(), magnitude()).map(np.array)
positive = magnitude(signed=False)

# attributes that may be infinite, and when (documented in their docstrings)
MAY_BE_INF = {"a", "period", "n", "mean_longitude"}
ATTRS = ("a", "e", "p", "q", "inc", "lan", "argp", "nu", "M", "anomaly", "n", "period",
         "energy", "varpi", "argument_of_latitude", "true_longitude", "mean_longitude",
         "time_since_periapsis", "areal_vector", "eccentricity_vector", "hamilton_epsilon")


def _names_an_argument(exc, names):
    text = str(exc)
    return any(re.search(f"`{n}`", text) for n in names)


def _check(value, name, may_be_inf=False):
    x = np.asarray(value, dtype=float)
    assert not np.any(np.isnan(x)), f"NaN out of {name}"
    if not may_be_inf:
        assert np.all(np.isfinite(x)), f"inf out of {name}: {x}"


@settings(deadline=None, max_examples=80)
@given(r=vec, v=vec, mu=positive)
def test_from_state_contract(r, v, mu):
    try:
        o = KeplerOrbit.from_state(r, v, mu)
    except ValueError as exc:
        assert _names_an_argument(exc, ("r", "v", "mu")), exc
        return
    for name in ATTRS:
        try:
            value = getattr(o, name)
        except ValueError as exc:
            assert _names_an_argument(exc, ("r", "v", "mu")), exc
            continue
        _check(value, name, name in MAY_BE_INF)
    try:
        assert repr(o).startswith("KeplerOrbit(")
    except ValueError as exc:
        assert _names_an_argument(exc, ("r", "v", "mu")), exc


@settings(deadline=None, max_examples=80)
@given(r=vec, v=vec, mu=positive, dt=magnitude())
def test_propagate_contract(r, v, mu, dt):
    try:
        r1, v1 = kepler.propagate(r, v, mu, dt)
    except ValueError as exc:  # ConvergenceError included
        assert _names_an_argument(exc, ("r", "v", "mu", "dt")) or "propagate" in str(exc), exc
        return
    _check(r1, "r")
    _check(v1, "v")


@settings(deadline=None, max_examples=80)
@given(
    length=magnitude(),
    which=st.sampled_from(["a", "p", "q"]),
    e=st.one_of(st.sampled_from([0.0, 1.0, 1 - 1e-15, 1 + 1e-15]), magnitude(-20, 20)),
    angles=st.tuples(magnitude(-3, 3), magnitude(-3, 3), magnitude(-3, 3)),
    anomaly=magnitude(-30, 30),
    which_anomaly=st.sampled_from(["nu", "M"]),
    mu=positive,
)
def test_from_elements_contract(length, which, e, angles, anomaly, which_anomaly, mu):
    inc, lan, argp = angles
    kw = {which: length, which_anomaly: anomaly}
    names = ("e", "inc", "lan", "argp", "mu", which, which_anomaly)
    try:
        o = KeplerOrbit.from_elements(e=e, inc=inc, lan=lan, argp=argp, mu=mu, **kw)
        r, v = o.state()
    except ValueError as exc:
        assert _names_an_argument(exc, names), exc
        return
    _check(r, "r")
    _check(v, "v")


@settings(deadline=None, max_examples=80)
@given(m=magnitude(-300, 300), e=st.one_of(magnitude(-300, 300, signed=False),
                                           st.sampled_from([0.0, 1.0, 0.999999, 1.000001])))
def test_anomaly_functions_contract(m, e):
    for f, arg in ((kepler.solve_kepler, "M"), (kepler.mean_anomaly, "anomaly"),
                   (kepler.anomaly_from_true, "nu"), (kepler.true_from_anomaly, "anomaly")):
        try:
            out = f(m, e)
        except ValueError as exc:
            assert _names_an_argument(exc, (arg, "e")) or "did not converge" in str(exc), exc
            continue
        _check(out, f.__name__)


@settings(deadline=None, max_examples=50)
@given(r=vec, v=vec, mu=positive, x=magnitude(), nu=magnitude(-3, 3))
def test_conic_and_hamilton_contract(r, v, mu, x, nu):
    names = ("r", "v", "mu")
    for f, args in ((hamilton_beta, (r, v)), (hamilton_epsilon_from_products, (r, v, mu)),
                    (hamilton_p, (r, v, mu))):
        try:
            _check(f(*args), f.__name__)
        except ValueError as exc:
            assert _names_an_argument(exc, names), exc
    try:
        c = KeplerOrbit.from_state(r, v, mu).conic
    except ValueError as exc:
        assert _names_an_argument(exc, names), exc
        return
    for name in ("focal_half_chord", "normal_length", "radius_of_curvature",
                 "radial_speed_squared"):
        try:
            _check(getattr(c, name)(abs(x)), name)
        except ValueError as exc:
            assert _names_an_argument(exc, ("r", "r", "v", "mu")) or "conic with" in str(exc), exc
    try:
        _check(c.radius(nu), "radius")
    except ValueError as exc:
        assert _names_an_argument(exc, ("nu", "r", "v", "mu")), exc
    try:
        rot, fix = c.hodograph(r)
        _check(rot, "hodograph")
        _check(fix, "hodograph")
    except ValueError as exc:
        assert _names_an_argument(exc, names) or "conic with" in str(exc), exc
