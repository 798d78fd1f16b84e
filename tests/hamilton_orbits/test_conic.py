"""Hamilton's conic geometry (seed eqs. 15-66) against independent computations."""

from __future__ import annotations

import math

import astropy.units as u
import mpmath
import numpy as np
import pytest
from hard_cases import CASES, perifocal_state

from hamilton_orbits.conic import Conic
from hamilton_orbits.orbit import KeplerOrbit

EPS = np.finfo(float).eps
ECCS = (0.0, 0.3, 0.9, 1.0, 1.5, 10.0)


def _states(e, n=7):
    """States at several true anomalies (inside the asymptotes for e >= 1)."""
    lim = math.pi if e < 1 else 0.9 * math.acos(-1.0 / e)
    out = []
    for nu in np.linspace(-lim, lim, n + 2)[1:-1]:
        out.append(perifocal_state(1.3, e, 0.6, 0.4, 1.9, float(nu), 0.7))
    return np.array([s[0] for s in out]), np.array([s[1] for s in out])


@pytest.mark.parametrize("e", ECCS)
def test_curvature_normal_chord_relations(e):
    """sqrt(R N) = C = 2 r r'/(r + r'), R/C = C/N = N/p (eqs. 63-64); N from eq. 65;
    R from the dynamics: curvature |v x acc| / |v|^3 = mu h / (r^3 v^3)."""
    r, v = _states(e)
    c = Conic.from_state(r, v, 0.7)
    rn = np.linalg.norm(r, axis=-1)
    C = c.focal_half_chord(rn)
    N = c.normal_length(rn)
    R = c.radius_of_curvature(rn)
    p = c.p
    tol = 16 * EPS
    assert np.all(np.abs(np.sqrt(R * N) / C - 1) <= tol)
    assert np.all(np.abs((R / C) / (C / N) - 1) <= tol)
    assert np.all(np.abs((C / N) / (N / p) - 1) <= tol)
    if e != 1.0:
        r2 = c.second_focal_distance(rn)
        assert np.all(np.abs(2 * rn * r2 / (rn + r2) / C - 1) <= 1e3 * EPS)  # r + r' = 2a cancels
    # eq. 65, first form: N = |r eps - alpha| with Hamilton's epsilon
    N65 = np.linalg.norm(rn[:, None] * c.hamilton_epsilon - r, axis=-1)
    assert np.all(np.abs(N65 / N - 1) <= 64 * EPS)
    # independent: radius of curvature of the trajectory from velocity and acceleration
    h = np.linalg.norm(np.cross(r, v), axis=-1)
    vn = np.linalg.norm(v, axis=-1)
    R_dyn = rn**3 * vn**3 / (0.7 * h)
    assert np.all(np.abs(R_dyn / R - 1) <= 64 * EPS)


@pytest.mark.parametrize("e", ECCS)
def test_hodograph_and_radial_law(e):
    r, v = _states(e)
    c = Conic.from_state(r, v, 0.7)
    rot, fix = c.hodograph(r)
    scale = np.linalg.norm(v, axis=-1)[:, None]
    assert np.all(np.abs(rot + fix - v) <= 16 * EPS * scale)
    h = math.sqrt(0.7 * float(c.p[0]))
    assert np.all(np.abs(np.linalg.norm(rot, axis=-1) - 0.7 / h) <= 8 * EPS * 0.7 / h)
    fixn = np.linalg.norm(fix, axis=-1)
    assert np.all(np.abs(fixn - e * 0.7 / h) <= 8 * EPS * max(1, e) * 0.7 / h)
    assert np.all(np.abs(np.einsum("ij,ij->i", rot, r)) <= 8 * EPS * scale[:, 0] * 2)
    # fixed part parallel to the velocity at perihelion
    _rp, vp = perifocal_state(1.3, e, 0.6, 0.4, 1.9, 0.0, 0.7)
    if e > 0:
        cosang = fix @ vp / (np.linalg.norm(fix, axis=-1) * np.linalg.norm(vp))
        assert np.all(cosang >= 1 - 8 * EPS)
    # (66): (dr/dt)^2 = mu (2/r - 1/a - p/r^2)
    rn = np.linalg.norm(r, axis=-1)
    rdot = np.einsum("ij,ij->i", r, v) / rn
    lhs = c.radial_speed_squared(rn)
    assert np.all(np.abs(lhs - rdot**2) <= 64 * EPS * 0.7 * (2 / rn + c.p / rn**2))


@pytest.mark.parametrize("e", (0.0, 0.3, 0.9, 1.5, 10.0))
def test_foci_centre_axes(e):
    """Sum (ellipse) or difference (hyperbola) of focal distances = 2a (eq. 31);
    b = a sqrt(1 - e^2) (eq. 43); centre halfway; second focus on the apoapsis side."""
    r, v = _states(e)
    c = Conic.from_state(r, v, 0.7)
    a = float(c.a[0])
    d1 = np.linalg.norm(r, axis=-1)
    d2 = np.linalg.norm(r - c.second_focus, axis=-1)
    if e < 1:
        # d2 = |r - 2 a eps| rounds each component at the scale |r| + 2 a e <= 4 a
        assert np.all(np.abs(d1 + d2 - 2 * a) <= 64 * EPS * a)
        assert abs(float(c.b[0]) - a * math.sqrt(1 - e * e)) <= 8 * EPS * a
    else:
        assert np.all(np.abs(np.abs(d1 - d2) - 2 * abs(a)) <= 64 * EPS * (d1 + d2))
        assert abs(float(c.b[0]) - abs(a) * math.sqrt(e * e - 1)) <= 8 * EPS * abs(a)
    assert np.allclose(c.centre, 0.5 * c.second_focus, rtol=0, atol=4 * EPS * abs(a))
    if e > 0:
        # ellipse: second focus towards apoapsis; hyperbola: beyond the periapsis
        s = np.sign(c.second_focus[0] @ c.periapsis_direction[0])
        assert s == (-1 if e < 1 else 1)
    # directrix: r = e * (distance to the directrix), eq. 15/20
    if e > 0:
        x = r @ c.periapsis_direction[0]
        assert np.all(np.abs(d1 - e * (c.directrix_distance[0] - x)) <= 64 * EPS * d1 * max(1, e))


def test_parabola_limits():
    r, v = _states(1.0)
    c = Conic.from_state(r, v, 0.7)
    assert np.all(c.a == np.inf) and np.all(c.b == np.inf)
    # (r = 2 >= q = 1.3: on the conic; below q the point is not on it and is refused)
    assert np.all(c.second_focal_distance(2.0) == np.inf)
    with pytest.raises(ValueError, match="parabola"):
        _ = c.second_focus
    # C = 2 r (harmonic mean of r and r' = inf), finite N and R
    rn = np.linalg.norm(r, axis=-1)
    assert np.all(c.focal_half_chord(rn) == 2 * rn)


def test_centre_of_a_batch_names_the_parabola_by_index():
    """The refusal of a batch's centre or second focus did not say which conic is the
    parabola."""
    c = Conic.from_elements([1.44, 2.0, 1.0], [0.44, 1.0, 1.0], [0.56, 0.0, 0.0], 0, 0, 0, 1.0)
    for name in ("centre", "second_focus"):
        with pytest.raises(ValueError, match=rf"^Expected a conic with a centre for `{name}`, "
                                             r"got a parabola \(e = 1, .*\) at index 1$"):
            getattr(c, name)
    with pytest.raises(ValueError, match=r"at infinity\)$"):  # one conic: no index
        _ = Conic.from_elements(2.0, 1.0, 0.0, 0, 0, 0, 1.0).centre


def test_orbit_conic_matches_state():
    o = KeplerOrbit.from_elements(a=2.0, e=0.4, inc=math.pi, lan=0.0, argp=1.0, nu=0.5, mu=1.0)
    c = o.conic
    assert np.allclose(c.periapsis_direction, o.eccentricity_vector / 0.4, atol=8 * EPS)
    assert np.allclose(c.normal, o.areal_vector / np.linalg.norm(o.areal_vector), atol=4 * EPS)


@pytest.mark.parametrize("quantity", [False, True])
def test_conic_from_state_and_from_elements_equal_the_orbits(quantity):
    """Conic.from_state (built on twobody.check_state and classical_columns, not
    on KeplerOrbit) and Conic.from_elements of the orbit's floats give the
    orbit's conic bit for bit, units included."""
    r, v = _states(1.5)
    r, v = np.vstack([r, [[1.0, 0, 0]]]), np.vstack([v, [[0.5, 0, 0]]])  # and a radial one
    mu = 0.7
    if quantity:
        r, v, mu = r * u.km, v * u.km / u.s, mu * u.km**3 / u.s**2
    o = KeplerOrbit.from_state(r, v, mu)
    ref = o.conic

    def floats(x):
        return x.value if quantity else x

    built = Conic.from_elements(
        floats(ref.p), ref.e, floats(ref.inv_a), floats(o.inc), floats(o.lan), floats(o.argp),
        floats(o.mu), quantity=quantity,
    )
    for c in (Conic.from_state(r, v, mu), built):
        for name in ("p", "e", "inv_a", "mu", "periapsis_direction", "normal"):
            x, y = getattr(c, name), getattr(ref, name)
            assert type(x) is type(y), name
            np.testing.assert_array_equal(x, y, err_msg=name)


def test_conic_from_state_refuses_bad_states_by_name():
    with pytest.raises(ValueError, match=r"Expected `r` to be nonzero, got \[0.0, 0.0, 0.0\]"):
        Conic.from_state([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0)
    with pytest.raises(ValueError, match=r"`mu` > 0, got -1\.0"):
        Conic.from_state([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], -1.0)


def test_quantities_in_quantities_out():
    """A conic from a Quantity orbit speaks km and km/s; plain floats are not mixed in."""
    r = [6524.834, 6862.875, 6448.296] * u.km  # Vallado, 4th ed., Example 2-5
    v = [4.901327, 5.533756, -1.976341] * u.km / u.s
    orbit = KeplerOrbit.from_state(r, v, 398600.4418 * u.km**3 / u.s**2)
    c = orbit.conic
    assert c.a.unit == u.km and abs(c.a - orbit.a) <= 4 * EPS * orbit.a
    assert c.second_focus.unit == u.km and c.hodograph(r)[0].unit == u.km / u.s
    rn = np.linalg.norm(r)
    assert abs(c.radius(orbit.nu) - rn) <= 8 * EPS * rn
    rot, fix = c.hodograph(r)
    np.testing.assert_allclose((rot + fix).to_value(u.km / u.s), v.value, rtol=16 * EPS)
    vr2 = (np.dot(r, v) / rn) ** 2
    # eq. (66) subtracts terms of the size of v^2: allow a few dozen eps of v^2
    assert abs(c.radial_speed_squared(rn) - vr2) <= 64 * EPS * np.dot(v, v)
    assert c.focal_half_chord(rn.to(u.m)).unit == u.km
    with pytest.raises(ValueError, match="`r` as a Quantity"):
        c.focal_half_chord(7000.0)


def test_points_off_the_conic_are_refused():
    """Issue 7 item 6: outside the conic the formulas returned NaN, inf or a
    negative radius; now a ValueError naming the argument, value and range."""
    hyp = Conic.from_state([1.0, 0, 0], [0, 2.0, 0], 1.0)  # e = 3, q = 1
    with pytest.raises(ValueError, match=r"`nu` inside the asymptotes, \|nu\| < arccos\(-1/e\) "
                                         r"= 1.9106332362490186 rad \(e = 3.0\), got 3.14159"):
        hyp.radius(math.pi)
    # just inside the asymptote: a large but finite radius (p / (1 + e cos nu) > 0)
    assert 0 < hyp.radius(math.acos(-1 / 3) - 1e-9) < np.inf
    par = Conic.from_state([1.0, 0, 0], [0, math.sqrt(2.0), 0], 1.0)
    with pytest.raises(ValueError, match="`nu` inside the asymptotes"):
        par.radius([0.0, math.pi])
    ell = Conic.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)  # q = 1, Q = 18/7
    for method in ("normal_length", "focal_half_chord", "radius_of_curvature",
                   "radial_speed_squared", "second_focal_distance"):
        with pytest.raises(ValueError, match=r"`r` on the conic, q <= r <= Q .* got 10.0"):
            getattr(ell, method)(10.0)  # beyond apoapsis
        with pytest.raises(ValueError, match=r"got 0.5 at index 1"):
            getattr(ell, method)([1.5, 0.5])  # inside periapsis
        with pytest.raises(ValueError, match=r"Q = inf"):
            getattr(hyp, method)(0.5)
    # the end points themselves are on the conic: C = r (2 - r/a) = p there (eq. 63)
    # up to the rounding of a = 1/inv_a and Q = 2a - q
    assert ell.normal_length(18 / 7) == pytest.approx(math.sqrt(1.44 * 1.44), rel=16 * EPS)
    assert ell.radial_speed_squared(1.0) == pytest.approx(0.0, abs=8 * EPS)
    with pytest.raises(ValueError, match=r"`r` a nonzero position .*got \[0.0, 0.0, 0.0\]"):
        ell.hodograph([0, 0, 0])
    radial = Conic.from_state([1.0, 0, 0], [0.5, 0, 0], 1.0)
    with pytest.raises(ValueError, match="angular momentum"):
        radial.hodograph([1.0, 0, 0])


def test_hodograph_scale_free():
    # the direction of r is what matters: |r| = 1e-170 or 1e300 gives the same velocity
    c = Conic.from_state([1.0, 0, 0], [0, 1.2, 0], 1.0)
    for s in (1e-170, 1e300):
        rot, fix = c.hodograph([s, 0, 0])
        assert (rot + fix).tolist() == pytest.approx([0.0, 1.2, 0.0], abs=4 * EPS)


@pytest.mark.parametrize(("length", "time"), [(1e160, 1e240), (1e-160, 1e-240)])
def test_the_vectors_and_the_conics_lengths_scale_with_the_state(length, time):
    """The same orbit in units of ``length`` and ``time`` (mu = 1 still): the
    eccentricity vector and Hamilton's epsilon are the same, the conic's lengths
    scale by ``length`` and its speeds squared by ``(length / time)^2``, to a few ulp.
    ``r . r``, ``r r`` and ``p c`` over- or underflowed at these scales: the
    eccentricity vector came out 1.22 long for e = 0.484, ``radial_speed_squared``
    6.8x too big, ``normal_length`` refused."""
    r0, v0 = np.array([1.0, 0.3, 0.1]), np.array([0.1, 1.1, 0.2])
    one = KeplerOrbit.from_state(r0, v0, 1.0)
    scaled = KeplerOrbit.from_state(r0 * length, v0 * (length / time), 1.0)
    for name in ("eccentricity_vector", "hamilton_epsilon"):
        np.testing.assert_allclose(getattr(scaled, name), getattr(one, name), rtol=0,
                                   atol=8 * np.finfo(float).eps)
    rn = np.linalg.norm(r0)
    for name, factor in (("radius_of_curvature", length), ("normal_length", length),
                         ("focal_half_chord", length),
                         ("radial_speed_squared", (length / time) ** 2)):
        want = getattr(one.conic, name)(rn) * factor
        assert getattr(scaled.conic, name)(rn * length) == pytest.approx(want, rel=8e-16)


# p, e, inv_a, inc, lan, argp, mu of the ellipse of the docstrings (p/a = 1 - e^2 exactly)
GOOD = {"p": 1.44, "e": 0.44, "inv_a": 0.56, "inc": 0.1, "lan": 0.2, "argp": 0.3, "mu": 1.0}


@pytest.mark.parametrize(("bad", "message"), [
    ({"e": [0.44, np.nan]}, r"Expected `e` to be finite, got nan at index 1"),
    ({"e": [0.44, 0.44, -0.5]}, r"Expected `e` >= 0, got -0.5 at index 2"),
    ({"p": -1.0}, r"Expected `p` >= 0, got -1.0$"),
    ({"p": [1.44, np.inf]}, r"Expected `p` to be finite, got inf at index 1"),
    ({"p": 0.0}, r"Expected `p` > 0 for e != 1 \(p = 0 is a radial orbit, e = 1\), got 0.0$"),
    ({"inv_a": -0.75}, r"Expected `inv_a` > 0 for e < 1 \(inv_a and e inconsistent\), got -0.75$"),
    ({"inv_a": 0.0}, r"Expected `inv_a` > 0 for e < 1 .*got 0.0$"),
    ({"p": 1.25, "e": 1.5, "inv_a": [-1.0, 0.5]}, r"Expected `inv_a` < 0 for e > 1 .*got 0.5 at "
                                                 r"index 1"),
    ({"inv_a": 100.0}, r"Expected `inv_a` = \(1 - e\^2\)/p = 0.56.* \(inv_a, p and e "
                       r"inconsistent\), got 100.0$"),
    ({"e": 1.0, "inv_a": 0.1}, r"Expected `inv_a` = \(1 - e\^2\)/p = 0.0 .*got 0.1$"),
    ({"inc": 5.0}, r"Expected `inc` in \[0, pi\] rad, got 5.0$"),
    ({"inc": [0.1, -0.1]}, r"Expected `inc` in \[0, pi\] rad, got -0.1 at index 1"),
    ({"lan": np.nan}, r"Expected `lan` to be finite, got nan$"),
    ({"argp": [0.3, -np.inf]}, r"Expected `argp` to be finite, got -inf at index 1"),
    ({"mu": -1.0}, r"Expected `mu` > 0, got -1.0$"),
    ({"mu": np.inf}, r"Expected `mu` to be finite, got inf$"),
    ({"mu": None}, r"Expected `mu` to be numeric, got None"),
    ({"p": 1.44 * u.km}, r"Expected `inv_a` to be a Quantity like `p` \(1.44 km\), got the "
                         r"plain number 0.56"),
    ({"e": [0.44, 0.44], "p": [1.44, 1.44, 1.44]}, r"Expected `p`, `e`, .* to broadcast"),
])
def test_from_elements_refuses_bad_elements_by_name(bad, message):
    """Conic.from_elements checked nothing: e = NaN gave a NaN second focus and
    later "nu inside the asymptotes (e = nan)"; e = -0.5 gave radius(0) = 2.0;
    p = -1 gave b = NaN with a RuntimeWarning, radius(0) = -0.67 and a hodograph
    refused as "a radial orbit (p = 0)"; inc = 5 rad, 1/a < 0 with e < 1 and
    1/a far from (1 - e^2)/p were taken; mu = -1 made the hodograph blame `r`.
    Now a ValueError naming the argument, the first offending index and the value."""
    args = {**GOOD, **bad}
    with pytest.raises(ValueError, match=message):
        Conic.from_elements(*args.values())


def test_from_elements_takes_quantities():
    """``Conic.from_elements`` refused every Quantity ("Expected `p` as plain floats");
    it now converts them as ``KeplerOrbit.from_elements`` does: lengths to km, ``1/a``
    to 1/km, ``mu`` to km^3/s^2 and angles of any unit to radians, the conic being one
    of Quantities; plain floats are read as before."""
    au_km = (1.0 * u.au).to_value(u.km)
    mu_sun = 1.32712440041e20 * u.m**3 / u.s**2
    c = Conic.from_elements(1.3 * u.au, 0.3, [0.7, 0.7] / u.au, 30 * u.deg, 0.5 * u.rad,
                            [10, 20] * u.deg, mu_sun)
    floats = Conic.from_elements(1.3 * au_km, 0.3, 0.7 / au_km, np.radians(30.0), 0.5,
                                 np.radians([10.0, 20.0]), 1.32712440041e11, quantity=True)
    for name in ("p", "inv_a", "mu"):
        assert getattr(c, name).unit == getattr(floats, name).unit
        assert np.allclose(getattr(c, name).value, getattr(floats, name).value,
                           rtol=4 * EPS, atol=0), name
    assert np.allclose(c.normal, floats.normal, rtol=0, atol=4 * EPS)
    assert np.allclose(c.periapsis_direction, floats.periapsis_direction, rtol=0,
                       atol=4 * EPS)
    assert c.a.unit == u.km and c.a.value == pytest.approx(au_km / 0.7, rel=1e-15)
    assert float(c.e) == 0.3
    assert Conic.from_elements(1.44, 0.44 * u.one, 0.56, 0, 0, 0, 1.0).e == 0.44  # (e: a
    # dimensionless Quantity too)
    # a plain float is read as before: radians, in the caller's own units
    plain = Conic.from_elements(*GOOD.values())
    assert not isinstance(plain.p, u.Quantity) and float(plain.p) == 1.44
    # a list of Quantities is the one Quantity it joins into
    joined = Conic.from_elements([1 * u.au, 149597870.7 * u.km], 0.0, 1 / u.au, 0, 0, 0,
                                 mu_sun)
    assert np.allclose(joined.p.to_value(u.km), au_km, rtol=4 * EPS, atol=0)


@pytest.mark.parametrize(("bad", "message"), [
    ({"p": 1.0 * u.s}, r"Expected `p` to be a length \(convertible to km\), got 1 s"),
    ({"inv_a": 1.0 * u.km}, r"Expected `inv_a` to be a reciprocal length \(convertible to "
                            r"1 / km\), got 1 km"),
    ({"e": 5.7 * u.deg}, r"Expected `e` to be dimensionless, got 5.7 deg \(an angle\)"),
    ({"inc": 0.1 * u.m}, r"Expected `inc` to be an angle \(convertible to rad\), got 0.1 m"),
    ({"mu": 1.0 * u.kg}, r"Expected `mu` to be a gravitational parameter GM .*got 1 kg"),
    ({"mu": 1.0}, r"Expected `mu` to be a Quantity like `p` \(1.44 km\), got the plain "
                  r"number 1.0"),
    ({"inc": [0.1, 200.0] * u.deg}, r"Expected `inc` in \[0, pi\] rad, got 200.0 deg at "
                                     r"index 1$"),
])
def test_from_elements_refuses_bad_quantities_by_name(bad, message):
    """A Quantity of the wrong dimension, or beside a plain float where a unit would
    have to be guessed, is a ValueError (UnitConversionError is one) naming the
    argument and the value (as given: an angle in its own unit)."""
    args = {**GOOD, "p": 1.44 * u.km, "inv_a": 0.56 / u.km, "mu": 1.0 * u.km**3 / u.s**2,
            **bad}
    with pytest.raises(ValueError, match=message):
        Conic.from_elements(*args.values())


_AU_CONIC = {"p": 1.0 * u.au, "e": 0.5, "inv_a": 0.75 / u.au, "inc": 0.0, "lan": 0.0,
             "argp": 0.0, "mu": 1.32712440041e20 * u.m**3 / u.s**2}


@pytest.mark.parametrize(("bad", "message"), [
    ({"p": -1.0 * u.au}, r"Expected `p` >= 0, got -1.0 AU$"),
    ({"p": [1.0, 0.0] * u.au}, r"Expected `p` > 0 for e != 1 .*, got 0.0 AU at index 1$"),
    ({"inc": 200.0 * u.deg}, r"Expected `inc` in \[0, pi\] rad, got 200.0 deg$"),
    ({"inv_a": -0.75 / u.au}, r"Expected `inv_a` > 0 for e < 1 .*, got -0.75 1 / AU$"),
    ({"inv_a": 1.0 / u.au}, r"Expected `inv_a` = \(1 - e\^2\)/p = 0.75\d* 1 / AU \(inv_a, p "
                            r"and e inconsistent\), got 1.0 1 / AU$"),
    ({"mu": -1.32712440041e20 * u.m**3 / u.s**2}, r"Expected `mu` > 0, got -1.32712440041e\+20 "
                                                   r"m3 / s2$"),
])
def test_from_elements_quotes_a_bad_quantity_as_given(bad, message):
    """A bad element given as a Quantity was quoted in the conic's internal units
    without a unit ("Expected `p` >= 0, got -149597870.7" for -1 au, "got
    3.490658503988659" for 200 deg); it is quoted as given, with its unit, as
    ``KeplerOrbit.from_elements`` quotes its own."""
    with pytest.raises(ValueError, match=message):
        Conic.from_elements(*{**_AU_CONIC, **bad}.values())
    assert float(Conic.from_elements(*_AU_CONIC.values()).e) == 0.5


def test_from_elements_refuses_a_quantity_flag_that_is_not_a_bool():
    """``quantity="no"`` (any non-empty text is true) made the conic one of Quantities."""
    with pytest.raises(ValueError, match=r"Expected `quantity` to be True or False, got 'no'"):
        Conic.from_elements(*GOOD.values(), quantity="no")


def test_from_elements_takes_every_conic_the_orbits_make():
    """The domain's edges stay open: the radial orbit (p = 0, e = 1, any 1/a), the
    parabola (1/a = 0), the quasi-rectilinear e = 1 with p/a ~ eps, the circle,
    inc = 0 and pi; and the conic of every hard-case orbit."""
    for p, e, inv_a in ((0.0, 1.0, 0.5), (0.0, 1.0, 0.0), (0.0, 1.0, -0.5), (2.0, 1.0, 0.0),
                        (1e-20, 1.0, 1.0), (1.0, 0.0, 1.0), (1.25, 1.5, -1.0)):
        for inc in (0.0, math.pi):
            c = Conic.from_elements(p, e, inv_a, inc, 0.0, 0.0, 1.0)
            assert c.normal.tolist() == [0.0, 0.0, 1.0 if inc == 0 else -1.0]
    r = np.array([c.r for c in CASES])
    v = np.array([c.v for c in CASES])
    mu = np.array([c.mu for c in CASES])
    conic = KeplerOrbit.from_state(r, v, mu).conic
    assert conic.e.shape == (len(CASES),)


#: a conic's attributes as Conic() takes them (those of GOOD's elements)
ATTRS = {"p": 1.44, "e": 0.44, "inv_a": 0.56, "periapsis_direction": [0.6, 0.8, 0.0],
         "normal": [0.0, 0.0, 1.0], "mu": 1.0}


@pytest.mark.parametrize(("bad", "message"), [
    ({"e": -0.5}, r"Expected `e` >= 0, got -0.5$"),
    ({"p": [1.44, -1.0], "inv_a": [0.56, -0.56]}, r"Expected `p` >= 0, got -1.0 at index 1"),
    ({"inv_a": 0.7}, r"Expected `inv_a` = \(1 - e\^2\)/p = 0.56.*got 0.7$"),
    ({"e": 1.5}, r"Expected `inv_a` < 0 for e > 1 .*got 0.56$"),
    ({"mu": 0.0}, r"Expected `mu` > 0, got 0.0$"),
    ({"e": np.nan}, r"Expected `e` to be finite, got nan$"),
    ({"normal": [0.0, 0.0, 2.0]}, r"Expected `normal` of unit length, got the length 2.0$"),
    ({"periapsis_direction": [[0.6, 0.8, 0.0], [1.0, 0.0, 1e-3]]},
     r"Expected `periapsis_direction` of unit length, got the length 1.0000004.* at index 1"),
    ({"normal": [0.0, 1.0, 0.0]}, r"orthogonal to `normal`, got their dot product 0.8$"),
    ({"periapsis_direction": [1.0, 0.0]}, r"`periapsis_direction` to have shape \(\.\.\., 3\)"),
    ({"normal": [0.0, 0.0, np.inf]}, r"Expected `normal` to be finite, got inf at index 2"),
    ({"p": 1.44 * u.km}, r"Expected `p` as plain floats .*got the Quantity 1.44 km"),
    ({"e": [0.44, 0.44], "p": [1.44] * 3}, r"Expected `p`, `e`, .* to broadcast"),
    ({"quantity": "no"}, r"Expected `quantity` to be True or False, got 'no'"),
])
def test_init_refuses_what_is_not_a_conic(bad, message):
    """``Conic(...)`` from its attributes checked nothing: e = -0.5, p < 0, 1/a far
    from (1 - e^2)/p, mu = 0, axes of length 2 or not orthogonal were all taken (a
    normal of length 2 doubled the hodograph's speeds, axes 37 deg apart put the
    second focus out of the plane).  Refused now as from_elements refuses its
    elements, the axes unit and orthogonal to 64 eps."""
    with pytest.raises(ValueError, match=message):
        Conic(**{**ATTRS, **bad})


def test_init_takes_what_from_elements_and_from_state_make():
    """Every conic the orbits make rebuilds from its attributes, unchanged (the axes
    of sines and cosines are unit and orthogonal within a few eps)."""
    r = np.array([c.r for c in CASES])
    v = np.array([c.v for c in CASES])
    mu = np.array([c.mu for c in CASES])
    conic = KeplerOrbit.from_state(r, v, mu).conic
    again = Conic(conic.p, conic.e, conic.inv_a, conic.periapsis_direction, conic.normal,
                  conic.mu)
    for name in ("p", "e", "inv_a", "periapsis_direction", "normal", "mu"):
        np.testing.assert_array_equal(getattr(again, name), getattr(conic, name))


def test_an_axis_of_one_row_is_named_without_an_index():
    """An axis of shape (1, 3) not unit was refused "... at index 0", unlike every
    other refusal of one value (which names no index)."""
    with pytest.raises(ValueError, match=r"Expected `periapsis_direction` of unit length, got "
                                         r"the length 1.0049875621120892$"):
        Conic(**{**ATTRS, "periapsis_direction": [[0.6, 0.8, 0.1]]})


# ------------------------------------------------------------- radius near nu = pi
# q = 1 conics of eccentricity at and around 1 (p = q (1 + e), 1/a = (1 - e)(1 + e)/p)
NEAR_PARABOLIC = (1.0, 1.0 - 1e-12, 1.0 + 1e-12, 1.0 - 1e-6, 1.0 + 1e-6)


def _near_parabolic(e):
    p = 1.0 + e
    return Conic.from_elements(p, e, (1.0 - e) * (1.0 + e) / p, 0.0, 0.0, 0.0, 1.0)


def _exact_radius(p, e, nu):
    """``p / (1 + e cos nu)`` of the floats ``p``, ``e``, ``nu`` at 50 digits, and the
    condition number ``kappa = (|1 - e| + 2 e cos^2(nu/2)) / (1 + e cos nu)`` of the
    sum the denominator is computed as: its terms are rounded to an ulp or two
    (``cos`` to one, ``1 - e`` exact here), so the radius is good to a few ulp
    times kappa (1 for ``e <= 1``, ``~2 (e - 1) / (1 + e cos nu)`` near a hyperbola's
    asymptote)."""
    with mpmath.workdps(50):
        e_, nu_ = mpmath.mpf(e), mpmath.mpf(nu)
        den = 1 + e_ * mpmath.cos(nu_)
        terms = abs(1 - e_) + 2 * e_ * mpmath.cos(nu_ / 2) ** 2
        return mpmath.mpf(p) / den, float(terms / den), den


def _anomalies_towards_the_asymptote(e):
    """Float anomalies approaching pi (closed conics, parabola) or arccos(-1/e)
    (hyperbolas) from inside, both signs, up to the last float inside."""
    with mpmath.workdps(50):
        lim = mpmath.pi if e <= 1.0 else mpmath.acos(-1 / mpmath.mpf(e))
        gap = mpmath.pi - lim if e > 1.0 else mpmath.mpf(1)
        nus = [float(lim - gap * mpmath.mpf(10) ** -k) for k in range(16)]
        # the last float inside: exactly, 1 + e cos nu > 0 (the parabola's below the
        # float pi, which stands for pi; an ellipse's the float pi)
        top = math.nextafter(np.pi, 0.0) if e == 1.0 else float(lim)
        while not (1 + mpmath.mpf(e) * mpmath.cos(mpmath.mpf(top)) > 0) or top >= lim:
            top = math.nextafter(top, 0.0)
        nus.append(top)
    nus = sorted({x for x in nus if x < top or x == top})
    return np.array(nus + [-x for x in nus])


@pytest.mark.parametrize("e", NEAR_PARABOLIC)
def test_radius_near_pi_and_the_asymptote_against_mpmath(e):
    """``Conic.radius`` evaluated ``p / (1 + e cos nu)``, which cancels near
    ``nu = pi``: 8e-4 relative for the parabola at pi - 1e-7 (4.0032e14 for
    4.0000e14), a refusal at pi - 1e-8 and below, 5e-9 for e = 1 - 1e-12 at
    pi - 1e-4, and near a hyperbola's asymptote errors of eps / (1 + e cos nu)
    instead of eps 2 (e - 1) / (1 + e cos nu).  Now ``(1 - e) + 2 e cos^2(nu/2)``:
    within 4 eps times the condition number of that sum (``_exact_radius``), for
    every anomaly towards pi or the asymptote down to the last float inside."""
    conic = _near_parabolic(e)
    p = float(conic.p)
    nus = _anomalies_towards_the_asymptote(e)
    got = conic.radius(nus)
    for nu, r in zip(nus, got, strict=True):
        exact, kappa, _ = _exact_radius(p, e, nu)
        assert abs(float(r / exact - 1)) <= 4 * EPS * max(kappa, 1.0), (nu, r, exact, kappa)


@pytest.mark.parametrize("e", [x for x in NEAR_PARABOLIC if x >= 1.0])
def test_the_asymptote_refused_exactly_where_the_radius_ends(e):
    """The refusal and the value agree: ``nu`` is refused exactly where
    ``1 + e cos nu <= 0`` for the float ``nu`` (exactly, the floats on each side of
    a hyperbola's asymptote), and for the parabola at the float pi alone, which
    stands for pi (as in ``KeplerOrbit``).  The parabola refused every nu from
    pi - 1e-8 with "|nu| < arccos(-1/e) = 3.141593 rad (e = 1.0), got
    3.141592643589793" (a nu below the limit it named); near a hyperbola's
    asymptote the rounding of ``e cos nu`` decided."""
    conic = _near_parabolic(e)
    p = float(conic.p)
    if e == 1.0:
        for nu in (np.pi, -np.pi):
            with pytest.raises(ValueError, match=r"`nu` inside the asymptotes, \|nu\| < pi "
                                                 r"\(e = 1.0\), got -?3.141592653589793$"):
                conic.radius(nu)
        below = math.nextafter(np.pi, 0.0)  # 2 p / (pi - nu)^2 = 1.5e31: taken
        exact, _, _ = _exact_radius(p, e, below)
        assert float(conic.radius(below)) == pytest.approx(float(exact), rel=4 * EPS)
        return
    with mpmath.workdps(50):
        start = float(mpmath.acos(-1 / mpmath.mpf(e)))  # the asymptote, rounded
    nu = start
    for _ in range(6):
        nu = math.nextafter(nu, 0.0)
    for _ in range(12):
        exact, kappa, den = _exact_radius(p, e, nu)
        if den > 0:
            assert abs(float(conic.radius(nu) / exact - 1)) <= 4 * EPS * kappa
        else:
            with pytest.raises(ValueError, match=r"`nu` inside the asymptotes, \|nu\| < "
                                                 r"arccos\(-1/e\) = ") as info:
                conic.radius(nu)
            # the limit named is the asymptote to 2 ulp (arccos of the float -1/e was
            # 3.140178440616719 for e = 1 + 1e-6, below accepted anomalies)
            named = float(str(info.value).split("= ")[1].split(" rad")[0])
            assert abs(named - start) <= 2 * np.spacing(start)
        nu = math.nextafter(nu, 4.0)


# ------------------------------------------------------------------ shapes
def _three_conics():
    r = np.array([[1.0, 0.0, 0.0]] * 3)
    v = np.array([[0.0, 1.2, 0.0], [0.0, 2.0, 0.0], [0.0, 2.0**0.5, 0.0]])
    return Conic.from_state(r, v, 1.0)  # an ellipse, a hyperbola, a parabola: shape (3,)


@pytest.mark.parametrize("method", ["radius", "focal_half_chord", "second_focal_distance",
                                    "normal_length", "radius_of_curvature",
                                    "radial_speed_squared"])
def test_a_point_not_broadcasting_against_the_conic_is_refused_by_name(method):
    """The methods at a point gave numpy's message for a point of another shape
    ("operands could not be broadcast together with shapes (3,) (2,)"); now a
    ValueError naming the argument and both shapes.  Shapes that broadcast are
    taken, each conic at its own point."""
    c = _three_conics()
    name = "nu" if method == "radius" else "r"
    with pytest.raises(ValueError, match=rf"Expected `{name}` of a shape broadcasting against "
                                         r"the conic's shape \(3,\), got shape \(2,\)$"):
        getattr(c, method)([1.0, 1.0])
    with pytest.raises(ValueError, match=r"the conic's shape \(3,\), got shape \(4, 2\)$"):
        getattr(c, method)(np.ones((4, 2)))
    assert getattr(c, method)(np.ones((4, 1))).shape == (4, 3)
    assert getattr(c, method)(1.0).shape == (3,)
    single = getattr(c, method)([0.5, 1.0, 1.5] if name == "nu" else [1.0, 1.1, 1.2])
    for k in range(3):
        one = Conic(c.p[k], c.e[k], c.inv_a[k], c.periapsis_direction[k], c.normal[k], 1.0)
        x = [0.5, 1.0, 1.5][k] if name == "nu" else [1.0, 1.1, 1.2][k]
        assert getattr(one, method)(x) == single[k]


def test_hodograph_positions_not_broadcasting_against_the_conic_are_refused_by_name():
    """``hodograph`` gave numpy's "shape mismatch: objects cannot be broadcast to a
    single shape" for positions of another leading shape; now named with both
    shapes.  Leading shapes that broadcast are taken."""
    c = _three_conics()
    with pytest.raises(ValueError, match=r"Expected `r` of shape \(\.\.\., 3\) with leading "
                                         r"dimensions broadcasting against the conic's shape "
                                         r"\(3,\), got shape \(2, 3\)$"):
        c.hodograph(np.array([[1.0, 0.0, 0.0]] * 2))
    rot, _ = c.hodograph(np.ones((4, 1, 3)))
    assert rot.shape == (4, 3, 3)
    rot, fix = c.hodograph([1.0, 0.0, 0.0])  # one position for the three conics
    np.testing.assert_allclose(rot + fix, [[0, 1.2, 0], [0, 2.0, 0], [0, 2**0.5, 0]],
                               rtol=0, atol=4 * EPS)


def test_from_elements_broadcasts_the_angles():
    """``from_elements`` stacked the axes' components unbroadcast: angles of
    different shapes that broadcast together (one ``inc``, two ``lan``) gave numpy's
    "all input arrays must have the same shape"; now each conic's axes are those
    of its own angles."""
    c = Conic.from_elements(1.44, 0.44, 0.56, 0.3, [0.0, 0.1], [[0.2], [0.4], [0.5]], 1.0)
    assert c.periapsis_direction.shape == c.normal.shape == (3, 2, 3)
    one = Conic.from_elements(1.44, 0.44, 0.56, 0.3, 0.1, 0.4, 1.0)
    np.testing.assert_array_equal(c.periapsis_direction[1, 1], one.periapsis_direction)
    np.testing.assert_array_equal(c.normal[1, 1], one.normal)


def test_from_elements_keeps_its_own_arrays():
    # the conic copies what it is given: the caller's later writes do not reach it
    p, e, mu = np.array([1.44, 1.44]), np.array([0.44, 0.44]), np.array([1.0, 1.0])
    c = Conic.from_elements(p, e, 0.56, 0.0, 0.0, 0.0, mu)
    p[0], e[0], mu[0] = 99.0, 0.9, 100.0
    np.testing.assert_array_equal(c.p, [1.44, 1.44])
    np.testing.assert_array_equal(c.e, [0.44, 0.44])
    np.testing.assert_array_equal(c.mu, [1.0, 1.0])
    with pytest.raises(ValueError, match="read-only"):
        c.e[0] = 0.9


def _beyond_a_orbit():
    # an ellipse with e = 1 - 2e-10 and a ~ 5e309: 1/a is subnormal, a beyond float64
    v = float(np.sqrt(2e-300 * (1 - 1e-10)))
    return KeplerOrbit.from_state([[1e300, 0.0, 0.0], [1.0, 0, 0]], [[0.0, v, 0.0], [0, 1.2, 0]],
                                  1.0)


def test_a_beyond_float64_refused_by_name(recwarn):
    c = _beyond_a_orbit().conic
    for name in ("a", "centre", "second_focus"):
        with pytest.raises(ValueError, match=rf"`{name}` fits in float64, got inv_a=2\.0.*e-310 "
                                             r"at index 0"):
            getattr(c, name)
    # b = sqrt(p / inv_a) ~ 1e305 fits: sqrt(p) / sqrt(inv_a), each rounding correct
    # (sqrt of the subnormal inv_a too) and a division: within 2 ulp of mpmath's
    mpmath.mp.dps = 40
    want = float(mpmath.sqrt(mpmath.mpf(float(c.p[0])) / mpmath.mpf(float(c.inv_a[0]))))
    assert abs(float(c.b[0]) - want) <= 2 * np.spacing(want)
    assert repr(_beyond_a_orbit()[0]) == (
        "KeplerOrbit(q=1e+300, e=1, inc=0, lan=0, argp=0, nu=0, mu=1)")
    assert not recwarn.list


def test_from_elements_inc_of_180_degrees_in_mas():
    # 648 000 000 mas converts to one ulp above pi: the retrograde normal (0, 0, -1) exactly
    c = Conic.from_elements(1.44, 0.44, 0.56, 648_000_000 * u.mas, 0.0, 0.0, 1.0)
    assert c.normal.tolist() == [0.0, -0.0, -1.0]


def test_b_of_a_conic_whose_attributes_broadcast():
    # p of shape (2, 4) or (3, 1) beside inv_a of shape (4,): the refusal's mask was
    # taken for a vector's and failed to broadcast (numpy's ValueError)
    direction, normal = np.array([1.0, 0, 0]), np.array([0, 0, 1.0])
    for p in (np.ones((2, 4)), np.ones((3, 1))):
        c = Conic(p, 0.5, np.full(4, 0.75), direction, normal, 1.0)
        np.testing.assert_array_equal(c.b, np.broadcast_to(np.sqrt(1.0 / 0.75), (len(p), 4)))


def test_b_of_a_tiny_conic():
    # p / inv_a below float64's normal range lost its digits under the root: a = 1e-165,
    # e = 0.5 gave b = 0 (8.66e-166 = a sqrt(1 - e^2)); each root apart, within 2 ulp
    # of mpmath's (two roots and a division of exact inputs)
    mpmath.mp.dps = 40
    for a in (1e-165, 1e-160, 1e-150):
        c = Conic.from_elements(a * 0.75, 0.5, 1.0 / a, 0.3, 0.2, 0.1, 1.0)
        want = float(mpmath.sqrt(mpmath.mpf(float(c.p)) / mpmath.mpf(float(c.inv_a))))
        assert abs(float(c.b) - want) <= 2 * np.spacing(want), (a, float(c.b), want)
