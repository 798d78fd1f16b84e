"""Universal-variable propagation (hamilton_orbits.kepler.propagate)."""

from __future__ import annotations

import math

import astropy.units as u
import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from hamilton_orbits import ConvergenceError, KeplerOrbit
from hamilton_orbits.kepler import propagate

EPS = np.finfo(float).eps
# a fixed rotation (rows orthonormal: 3-4-5 triangles) so that no orbit lies in
# a coordinate plane
ROT = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])
E_DOP = [0.0, 0.5, 0.9, 0.99999, 1.0, 1.00001, 2.0, 10.0]


def _periapsis_state(e: float, q: float = 1.0, mu: float = 1.0):
    vp = math.sqrt(mu * (1.0 + e) / q)
    return ROT @ np.array([q, 0.0, 0.0]), ROT @ np.array([0.0, vp, 0.0])


def _kepler_rhs(mu):
    def rhs(_t, y):
        r = y[:3]
        return np.concatenate([y[3:], -mu * r / np.linalg.norm(r) ** 3])

    return rhs


def _rel(a, b):
    return np.linalg.norm(a - b, axis=-1) / np.linalg.norm(b, axis=-1)


def test_vallado_example_2_4():
    # Vallado, Fundamentals of Astrodynamics and Applications, 4th ed. (2013),
    # Example 2-4 (KEPLER), pp. 94-95: mu = 398600.4418 km^3/s^2, dt = 40 min.
    # Tolerance: half a unit in the last digit the book prints (4 and 6 decimals).
    r0 = np.array([1131.340, -2282.343, 6672.423])
    v0 = np.array([-5.64305, 4.30333, 2.42879])
    r, v = propagate(r0, v0, 398600.4418, 40 * 60.0)
    np.testing.assert_allclose(r, [-4219.7527, 4363.0292, -3958.7666], rtol=0, atol=5e-5)
    np.testing.assert_allclose(v, [3.689866, -1.916735, -6.112511], rtol=0, atol=5e-7)


def test_vallado_example_2_4_quantities():
    r0 = [1131.340, -2282.343, 6672.423] * u.km
    v0 = [-5.64305, 4.30333, 2.42879] * u.km / u.s
    mu = 398600.4418 * u.km**3 / u.s**2
    r, v = propagate(r0, v0, mu, 40 * u.min)
    assert r.unit == u.km and v.unit == u.km / u.s
    rf, vf = propagate(r0.value, v0.value, mu.value, 2400.0)
    # the SI round trip (km -> m -> km) rounds r, v, mu once each, and the
    # 40-min flow amplifies that a few times (measured 9 ulp)
    np.testing.assert_allclose(r.value, rf, rtol=32 * EPS)
    np.testing.assert_allclose(v.value, vf, rtol=32 * EPS)


@pytest.mark.parametrize("e", E_DOP)
def test_against_dop853(e):
    """scipy DOP853 at rtol 1e-13 over an orbit (open orbits: 30 time units
    through periapsis).  Measured agreement: <= 8e-13 relative in position and
    velocity for every e here (DOP853's own global error at this rtol), so
    3e-12 is a ~4x margin over the integrator, not over us."""
    r0, v0 = _periapsis_state(e)
    span = 2 * math.pi * (1.0 / (1.0 - e)) ** 1.5 if e < 0.9 else 30.0
    # start a third of the span before periapsis, so periapsis is crossed
    r0, v0 = propagate(r0, v0, 1.0, -span / 3)
    ts = np.linspace(0.0, span, 9)[1:]
    sol = solve_ivp(
        _kepler_rhs(1.0), (0.0, span), np.concatenate([r0, v0]),
        method="DOP853", rtol=1e-13, atol=1e-16, t_eval=ts,
    )
    r, v = propagate(r0, v0, 1.0, ts)
    assert np.max(_rel(r, sol.y[:3].T)) < 3e-12
    assert np.max(_rel(v, sol.y[3:].T)) < 3e-12


def test_against_rebound_ias15():
    import rebound
    for e in [0.0, 0.7, 0.99, 1.5]:
        r0, v0 = _periapsis_state(e)
        r0, v0 = propagate(r0, v0, 1.0, -2.0)
        sim = rebound.Simulation()
        sim.G = 1.0
        sim.add(m=1.0)
        sim.add(m=0.0, x=r0[0], y=r0[1], z=r0[2], vx=v0[0], vy=v0[1], vz=v0[2])
        sim.integrator = "ias15"
        sim.integrate(6.0, exact_finish_time=1)
        p, s = sim.particles[1], sim.particles[0]
        rr = np.array([p.x - s.x, p.y - s.y, p.z - s.z])
        vv = np.array([p.vx - s.vx, p.vy - s.vy, p.vz - s.vz])
        r, v = propagate(r0, v0, 1.0, 6.0)
        # IAS15 holds ~machine precision per step; over this arc (<= 1 orbit)
        # we measured <= 3e-15 relative, so 1e-13 leaves room for its
        # step-size control on other platforms
        assert _rel(r, rr) < 1e-13 and _rel(v, vv) < 1e-13, e


@pytest.mark.parametrize("e", [0.0, 1e-8, 0.5, 0.9, 0.99999, 1.0, 1.00001, 2.0, 10.0, 1e6])
def test_round_trip_and_invariants(e):
    r0, v0 = _periapsis_state(e)
    dts = np.array([1e-6, 0.3, -2.0, 7.0, -25.0])
    r1, v1 = propagate(r0, v0, 1.0, dts)
    rb, vb = propagate(r1, v1, 1.0, -dts)
    # forward then back: 1e-13 relative, except where physics forbids it: the
    # far state's rounding (eps |r1|, eps |v1|) moves the return by about
    # eps |dt| v_p; we allow 50x that (measured <= 10x, e = 1e6, dt = -25)
    tol = 1e-13 + 50 * EPS * np.abs(dts) * np.linalg.norm(v0) / np.linalg.norm(r0)
    assert np.all(_rel(rb, r0) < tol)
    assert np.all(_rel(vb, v0) < tol)
    h0 = np.cross(r0, v0)
    h1 = np.cross(r1, v1)
    # areal vector: the transverse velocity is h x r / r^2, so r x v = h up to
    # the rounding of the returned state itself, which is eps |r| |v| per
    # component in the cross product (measured <= 1.2 eps |r||v|; bound 4)
    dh = np.linalg.norm(h1 - h0, axis=-1)
    rv = np.linalg.norm(r1, axis=-1) * np.linalg.norm(v1, axis=-1)
    assert np.all(dh <= 4 * EPS * rv)
    # energy: a few ulp of the sum of its terms v^2/2 + mu/r (the energy itself
    # may be ~0, e.g. the parabola, so its relative error is meaningless)
    en0 = 0.5 * v0 @ v0 - 1.0 / np.linalg.norm(r0)
    en1 = 0.5 * np.sum(v1 * v1, -1) - 1.0 / np.linalg.norm(r1, axis=-1)
    scale = 0.5 * np.sum(v1 * v1, -1) + 1.0 / np.linalg.norm(r1, axis=-1)
    assert np.max(np.abs(en1 - en0) / scale) <= 8 * EPS


def test_long_open_arcs_round_trip_physics_limited():
    """Going out for 1e7 time units and back: the return to periapsis is as
    accurate as the far state allows.  Its rounding (eps |r|, eps |v|) shifts
    the time of periapsis passage by ~ eps dt, i.e. ~ eps dt v_p in position;
    we allow 200 times that (measured at most ~80x, for e = 10, where the
    return leg is anchored at periapsis and sums tp0 + tau ~ 1e7 to ~0)."""
    dt = 1e7
    for e in [0.99999, 1.0, 1.00001, 2.0, 10.0, 1e6]:
        r0, v0 = _periapsis_state(e)
        r1, v1 = propagate(r0, v0, 1.0, dt)
        rb, _ = propagate(r1, v1, 1.0, -dt)
        vp = np.linalg.norm(v0)
        assert _rel(rb, r0) < 200 * EPS * dt * vp, e


def test_many_periods():
    """dt = N periods + x equals dt = x, up to the phase error N P eps that
    forming N P in floating point costs (the reduction itself is exact)."""
    for e in [0.0, 0.3, 0.9, 0.999]:
        r0, v0 = _periapsis_state(e)
        a = 1.0 / (2.0 / np.linalg.norm(r0) - v0 @ v0)
        period = 2 * math.pi * a**1.5
        for n in [1.0, 1e3, 1e6]:
            r_ref, _ = propagate(r0, v0, 1.0, 0.37)
            r, _ = propagate(r0, v0, 1.0, n * period + 0.37)
            vmax = math.sqrt((1 + e) / (1 - e)) if e < 1 else 1.0
            tol = 4 * EPS * (n * period) * vmax / np.linalg.norm(r_ref) + 1e-14
            assert _rel(r, r_ref) <= tol, (e, n)


def test_radial_orbits():
    """Zero angular momentum: radial hyperbola / parabola / ellipse against
    DOP853 (away from the collision), and the regularised bounce."""
    rhat = ROT @ np.array([1.0, 0.0, 0.0])
    for v_out in [2.0, math.sqrt(2.0), 1.0]:  # E > 0, E = 0, E < 0 from r = 1
        r0, v0 = rhat, v_out * rhat
        span = 0.8
        ts = np.linspace(-0.4, span, 7)
        sol_f = solve_ivp(_kepler_rhs(1.0), (0, span), np.concatenate([r0, v0]),
                          method="DOP853", rtol=1e-13, atol=1e-16, t_eval=ts[ts > 0])
        r, v = propagate(r0, v0, 1.0, ts[ts > 0])
        assert np.max(_rel(r, sol_f.y[:3].T)) < 3e-12
        assert np.max(_rel(v, sol_f.y[3:].T)) < 3e-12
        # velocity stays exactly radial (no transverse part from rounding)
        assert np.max(np.linalg.norm(np.cross(r, v), axis=-1)) <= 4 * EPS * np.max(
            np.linalg.norm(r, axis=-1) * np.linalg.norm(v, axis=-1)
        )
    # bound radial orbit dropped from rest at r = 1: collision at t_c = pi/(2 sqrt 2)
    # (half the period of a = 1/2); the regularised continuation is a bounce,
    # symmetric about t_c
    r0, v0 = rhat, 0.0 * rhat
    tc = math.pi / (2 * math.sqrt(2.0))
    s = np.array([0.05, 0.2, 0.5])
    r_before, v_before = propagate(r0, v0, 1.0, tc - s)
    r_after, v_after = propagate(r0, v0, 1.0, tc + s)
    np.testing.assert_allclose(r_after, r_before, rtol=1e-12)
    np.testing.assert_allclose(v_after, -v_before, rtol=1e-12)
    assert np.all(r_after @ rhat > 0)


def test_broadcasting_shapes():
    r0 = np.stack([_periapsis_state(e)[0] for e in (0.1, 0.5)])  # (2, 3)
    v0 = np.stack([_periapsis_state(e)[1] for e in (0.1, 0.5)])
    dt = np.array([[0.5], [1.0], [2.0]])  # (3, 1)
    r, v = propagate(r0, v0, 1.0, dt)
    assert r.shape == (3, 2, 3) and v.shape == (3, 2, 3)
    r11, _ = propagate(r0[1], v0[1], 1.0, 1.0)
    np.testing.assert_array_equal(r[1, 1], r11)
    r_, v_ = propagate(r0[0], v0[0], 1.0, 0.0)
    np.testing.assert_array_equal(r_, r0[0])
    np.testing.assert_array_equal(v_, v0[0])


def test_scale_invariance():
    """Lengths x L, times x T (mu x L^3/T^2): the state scales exactly up to rounding."""
    r0, v0 = _periapsis_state(0.7)
    r1, v1 = propagate(r0, v0, 1.0, 3.3)
    for L, T in [(1e-10, 1e-5), (1e10, 1e12), (6.4e6, 1e3)]:
        mu = L**3 / T**2
        r, v = propagate(r0 * L, v0 * L / T, mu, 3.3 * T)
        np.testing.assert_allclose(r / L, r1, rtol=1e-14)
        np.testing.assert_allclose(v * T / L, v1, rtol=1e-14)


@pytest.mark.parametrize(
    ("args", "exc", "match"),
    [
        (([0.0, 0, 0], [0, 1.0, 0], 1.0, 1.0), ValueError, r"`r` nonzero"),
        (([[1.0, 0, 0], [0, 0, 0]], [0, 1.0, 0], 1.0, 1.0), ValueError, r"`r` nonzero.*index 1"),
        (([1.0, 0, 0], [0, 1.0, 0], [1.0, -1.0], 1.0), ValueError, r"`mu` > 0, got -1.0 at ind"),
        (([1.0, 0, 0], [0, 1.0], 1.0, 1.0), ValueError, r"`v` to have shape \(..., 3\)"),
        (([1.0, 0, np.nan], [0, 1.0, 0], 1.0, 1.0), ValueError, r"`r` to be finite"),
        (([1.0, 0, 0], [0, 1.0, 0], 1.0, [1.0, np.inf]), ValueError, r"`dt` to be finite"),
        (([[1.0, 0, 0]] * 2, [0, 1.0, 0], 1.0, [1.0] * 3), ValueError, r"broadcast"),
    ],
)
def test_bad_input(args, exc, match):
    with pytest.raises(exc, match=match):
        propagate(*args)


def test_mixed_quantities_rejected():
    with pytest.raises(ValueError, match="all Quantities or all plain floats"):
        propagate([7000.0, 0, 0] * u.km, [0, 7.5, 0] * u.km / u.s, 398600.4418, 60.0)
    with pytest.raises(u.UnitConversionError):
        propagate([7000.0, 0, 0] * u.km, [0, 7.5, 0] * u.km, 1 * u.km**3 / u.s**2, 1 * u.s)


def test_hyperbolic_overflow_raises_convergence_error():
    # after 1e300 time units the hyperbolic anomaly exceeds the float range
    r0, v0 = _periapsis_state(2.0)
    with pytest.raises(ConvergenceError, match="propagate failed"):
        propagate(r0, v0, 1.0, 1e300)


@settings(deadline=None, max_examples=150)
@given(
    e=st.one_of(st.floats(0.0, 0.99), st.floats(1.01, 50.0), st.just(1.0)),
    nu0=st.floats(-1.5, 1.5),
    dt=st.floats(-20.0, 20.0),
)
def test_hypothesis_round_trip(e, nu0, dt):
    r0, v0 = _periapsis_state(e)
    # move to a generic starting point first
    r0, v0 = propagate(r0, v0, 1.0, nu0)
    r1, v1 = propagate(r0, v0, 1.0, dt)
    rb, _vb = propagate(r1, v1, 1.0, -dt)
    # physics-limited: the far state's rounding shifts the return by ~eps |dt| |v|
    slack = 1e-13 + 50 * EPS * abs(dt) * np.linalg.norm(v0) / np.linalg.norm(r0)
    assert _rel(rb, r0) < slack
    dh = np.linalg.norm(np.cross(r1, v1) - np.cross(r0, v0))
    assert dh <= 4 * EPS * np.linalg.norm(r1) * np.linalg.norm(v1)


def test_one_thread_gives_the_bits_of_the_threaded_kernel():
    """``threads=False`` runs the serial copy of the batch kernel on a batch large
    enough for threads: every row the same bits (and a non-bool refused)."""
    rng = np.random.default_rng(7)
    n = 70_000  # (above the threaded kernel's 65536 rows)
    r = rng.normal(size=(n, 3))
    v = rng.normal(size=(n, 3)) * 0.8
    dt = rng.uniform(-20.0, 20.0, n)
    threaded = propagate(r, v, 1.0, dt)
    serial = propagate(r, v, 1.0, dt, threads=False)
    assert np.array_equal(threaded[0], serial[0]) and np.array_equal(threaded[1], serial[1])
    with pytest.raises(ValueError, match="`threads`"):
        propagate(r[0], v[0], 1.0, 1.0, threads=1)



def _universal_mp(r0, v0, dt, mu=1.0, dps=50):
    """``(r, v, s)`` after ``dt`` by the universal Kepler equation solved in
    ``dps``-digit arithmetic (a doubling bracket, bisection to 1e-6, then Newton;
    the Stumpff functions in closed form), for the float state ``r0, v0`` with the
    float ``1/a = 2/|r0| - |v0|^2/mu`` that :func:`propagate` forms (see the test
    below for why); ``s = sqrt(-1/a) |chi|``, the argument of the hyperbolic
    functions."""
    rf = math.sqrt(sum(float(x) * float(x) for x in r0))
    inv_a = 2.0 / rf - sum(float(x) * float(x) for x in v0) / mu
    with mp.workdps(dps):
        rr = [mp.mpf(float(x)) for x in r0]
        vv = [mp.mpf(float(x)) for x in v0]
        m, alpha, tau = mp.mpf(mu), mp.mpf(inv_a), mp.sqrt(mu) * mp.mpf(float(dt))
        rn = mp.sqrt(sum(x * x for x in rr))
        sigma0 = sum(a * b for a, b in zip(rr, vv, strict=True)) / mp.sqrt(m)

        def funcs(chi):  # U1, U2, U3 for alpha < 0 (hyperbola) or alpha = 0
            if alpha == 0:
                return chi, chi**2 / 2, chi**3 / 6
            s = mp.sqrt(-alpha)
            return (mp.sinh(s * chi) / s, (mp.cosh(s * chi) - 1) / -alpha,
                    (mp.sinh(s * chi) - s * chi) / (-alpha * s))

        def residual(chi):
            u1, u2, u3 = funcs(chi)
            return rn * u1 + sigma0 * u2 + u3 - tau, rn + sigma0 * u1 - alpha * rn * u2 + u2

        sgn = 1 if tau > 0 else -1
        lo, hi = mp.mpf(0), mp.mpf(sgn)
        while sgn * residual(hi)[0] < 0:
            lo, hi = hi, 2 * hi
        while abs(hi - lo) > mp.mpf(10) ** -6 * abs(hi):  # bisection, then Newton
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if sgn * residual(mid)[0] < 0 else (lo, mid)
        chi = hi
        for _ in range(30):
            f, df = residual(chi)
            step = f / df
            chi -= step
            if abs(step) <= mp.mpf(10) ** (5 - dps) * abs(chi):
                break
        u1, u2, u3 = funcs(chi)
        r = rn + sigma0 * u1 - alpha * rn * u2 + u2
        f, g = 1 - u2 / rn, (tau - u3) / mp.sqrt(m)
        fd, gd = -mp.sqrt(m) * u1 / (r * rn), 1 - u2 / r
        return ([float(f * a + g * b) for a, b in zip(rr, vv, strict=True)],
                [float(fd * a + gd * b) for a, b in zip(rr, vv, strict=True)],
                float(mp.sqrt(-alpha) * abs(chi)))


def _barker_time_mp(r, v, q, mu=1.0, dps=50):
    """Time since periapsis on the parabola of periapsis distance ``q`` through
    the float state ``r, v``, by Barker's equation ``t = sqrt(2 q^3/mu) (D +
    D^3/3)`` with ``D = tan(nu/2) = (r.v)/sqrt(2 q mu)`` (no anomaly from the
    state's direction: far out its transverse velocity is below its rounding)."""
    with mp.workdps(dps):
        rv = sum(mp.mpf(float(a)) * mp.mpf(float(b)) for a, b in zip(r, v, strict=True))
        qq, m = mp.mpf(float(q)), mp.mpf(mu)
        d = rv / mp.sqrt(2 * qq * m)
        return float(mp.sqrt(2 * qq**3 / m) * (d + d**3 / 3))


def test_near_parabolic_and_parabolic_steps_of_any_size_converge():
    """Regression: near e = 1 the universal Kepler equation was not solved at
    scattered large dt (e = 1 + 1e-6: dt = 1e15, 10^15.5, 1e16; 1 + 1e-9: 8 values
    ~1e20-1e23; 1 + 1e-12: 16 values ~1e24-1e31; the parabola: 350 values from
    ~3e102), far from any overflow: ConvergenceError.  Laguerre's last step there
    is below half an ulp of chi (an ulp of chi moves T by many ulps of tau) and was
    taken for a step out of the bracket, whose doubling or bisection used up the
    iterations; a long parabolic step started at tau/r0 ~ 1e102 for a root ~ 1e34.
    Every dt = +-10^k, k = 0, 0.25, ..., 150 now gives a state.

    References, independent of the kernel's solver and its Stumpff series:

    * the parabola, every point: Barker's equation with D = (r.v)/sqrt(2 q mu) of
      the returned state (50 digits) gives back dt within 64 eps (measured at most
      25: t ~ D^3 triples the few eps of r and v);
    * the hyperbolas, every fifth decade: the universal Kepler equation solved in
      50 digits with sinh / cosh.  It takes 1/a as the kernel forms it in floats:
      at periapsis 2/r0 - v0^2 cancels to e - 1 = 1e-12, so the float state's
      own 1/a is known to ~1e-4 only, and far out the state scales with
      sqrt(-1/a); that conditioning is not the solver's.  |r| within
      16 (1 + s) eps (measured at most 7 s eps at dt = 1e150, s = 317): chi holds
      53 bits and psi = chi^2/a carries a few eps, moving e^s by s times that;
      v within 32 eps (measured 8)."""
    dts = 10.0 ** np.arange(0.0, 150.001, 0.25)
    dts = np.concatenate([dts, -dts])
    for e in [1.0 + 1e-12, 1.0 + 1e-9, 1.0 + 1e-6, 1.0, 1.001, 1.0 - 1e-12]:
        r0, v0 = _periapsis_state(e)
        r, v = propagate(r0, v0, 1.0, dts)  # (ConvergenceError before the fix)
        assert np.all(np.isfinite(r)) and np.all(np.isfinite(v)), e
        if e == 1.0:
            q = 0.5 * np.sum(np.cross(r0, v0) ** 2)
            for i in range(len(dts)):
                t = _barker_time_mp(r[i], v[i], q)
                assert abs(t - dts[i]) <= 64 * EPS * abs(dts[i]), (dts[i], t)
        elif 1.0 < e < 1.001:
            for i in range(0, len(dts), 20):
                ref_r, ref_v, s = _universal_mp(r0, v0, dts[i])
                big = np.max(np.abs(ref_r))  # (|r|^2 may overflow)
                assert _rel(r[i] / big, np.array(ref_r) / big) <= 16 * (1 + s) * EPS, (e, dts[i])
                assert _rel(v[i], np.array(ref_v)) <= 32 * EPS, (e, dts[i])


def test_long_steps_near_parabolic_converge_up_to_the_float_range():
    """Three more ways the solver ran out of iterations before a state it could
    return (ConvergenceError before the fix, each):

    * a parabola of periapsis distance q = 1e-34 (nearly radial: the periapsis
      of a nearly radial orbit is tiny) from its periapsis: the first guess
      tau/q is ~1e50 times the root from dt = 1e70, and Laguerre's step gains
      only ~2.7 per iteration from there (Barker's equation as in the test
      above: within 64 eps of dt);
    * a hyperbola (e = 1 + 1e-15) going back through its periapsis to |r| ~ 7e153,
      where 16 r^2 in Laguerre's step overflows (checked against the 50-digit
      universal solution as above; the step anchored at periapsis carries ~s eps
      in v too, measured 1.3 s eps here and at dt = -1e50 on the old code, so v
      gets the bound of r);
    * the parabola up to |r| = 7.7e153 (dt = 10^230.5).

    Beyond, where |r|^2 of the result leaves the float range (the parabola at dt =
    1e231, |r| = 1.65e154), ConvergenceError is still raised."""
    q = 1e-34
    r0, v0 = ROT @ np.array([q, 0.0, 0.0]), ROT @ np.array([0.0, math.sqrt(2.0 / q), 0.0])
    dts = 10.0 ** np.arange(70.0, 200.001, 10.0) * np.resize([1.0, -1.0], 14)
    r, v = propagate(r0, v0, 1.0, dts)
    q = 0.5 * np.sum(np.cross(r0, v0) ** 2)
    for i, dt in enumerate(dts):
        assert abs(_barker_time_mp(r[i], v[i], q) - dt) <= 64 * EPS * abs(dt), dt

    r0, v0 = KeplerOrbit.from_elements(q=1e-3, e=1.0 + 1e-15, inc=0.4, lan=0.5, argp=0.6,
                                       M=0.5, mu=1.0).state()
    for dt in [-7.943282347242789e159, -1.2e160]:
        r, v = propagate(r0, v0, 1.0, dt)
        ref_r, ref_v, s = _universal_mp(r0, v0, dt)
        big = np.max(np.abs(ref_r))
        assert _rel(r / big, np.array(ref_r) / big) <= 16 * (1 + s) * EPS, dt
        assert _rel(v, np.array(ref_v)) <= 16 * (1 + s) * EPS, dt

    r0, v0 = [1.0, 0.0, 0.0], [0.0, math.sqrt(2.0), 0.0]
    r, v = propagate(r0, v0, 1.0, 10.0**230.5)
    q = 0.5 * np.sum(np.cross(r0, v0) ** 2)
    assert abs(_barker_time_mp(r, v, q) - 10.0**230.5) <= 64 * EPS * 10.0**230.5
    with pytest.raises(ConvergenceError, match="propagate failed"):
        propagate(r0, v0, 1.0, 1e231)
