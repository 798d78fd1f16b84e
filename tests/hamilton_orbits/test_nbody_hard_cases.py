"""A catalogue of published hard cases for the n-body engine, on default settings.

Each case runs with the defaults (radau15, PRS23 step rule, tol 1e-9) and is held
against its published outcome and against rebound's IAS15 from the same state
(issue 20).  The head-on collision (contact time against the radial Kepler
solution) is in ``test_events.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from hamilton_orbits import Body, KeplerOrbit, System, integrate

# ---------------------------------------------------------------------- figure eight
# Chenciner & Montgomery (2000), Ann. Math. 152, 881; the initial data of Simo
# (2002) to 8 digits, unit masses, G = 1, period T.
X1 = np.array([0.97000436, -0.24308753, 0.0])
V3 = np.array([-0.93240737, -0.86473146, 0.0])
T8 = 6.32591398


def _figure_eight() -> System:
    return System([Body("a", 1.0, X1, -V3 / 2), Body("b", 1.0, -X1, -V3 / 2),
                   Body("c", 1.0, [0.0, 0.0, 0.0], V3)])


def _ias15(system: System, t_end: float, **settings):
    sim = system.to_rebound()
    sim.integrator = "ias15"
    for key, value in settings.items():
        setattr(sim.integrator, key, value)
    e0 = sim.energy()
    sim.integrate(t_end, exact_finish_time=1)
    r = np.array([p.xyz for p in sim.particles])
    return r, abs(sim.energy() - e0) / abs(e0)


def test_figure_eight_returns_to_its_start_for_100_periods():
    """The third body starts with exactly zero acceleration (the step rule used to
    divide by it: a step underflow at t = 0).  After k periods the bodies are back
    within a phase drift that grows linearly, k x 4e-8: what the 8-digit period
    (+-5e-9) and state allow, not an instability; the energy is kept at rounding,
    and rebound's IAS15 from the same state lands within 1e-10."""
    s = _figure_eight()
    traj = integrate(s, np.arange(101) * T8)
    d = np.linalg.norm(traj.r - traj.r[0], axis=2).max(axis=1)
    assert d[1] < 1e-7 and d[100] < 1e-5
    assert 8.0 < d[100] / d[10] < 12.0  # linear in k: a phase drift
    assert np.max(np.abs(traj.energy_error)) < 1e-14
    r_reb, de_reb = _ias15(s, 100 * T8)
    assert np.max(np.abs(r_reb - traj.r[-1])) < 1e-10
    assert de_reb < 1e-14


# ---------------------------------------------------------------------- Pythagorean
def _burrau() -> System:
    """Burrau's problem: masses 3, 4, 5 at rest at the corners of a 3-4-5 triangle."""
    return System([Body("m3", 3.0, [1, 3, 0], [0, 0, 0]), Body("m4", 4.0, [-2, -1, 0], [0, 0, 0]),
                   Body("m5", 5.0, [1, -1, 0], [0, 0, 0])])


@pytest.mark.parametrize("criterion", ["prs23", "global"])
def test_burrau_ends_as_a_binary_and_an_escape(criterion):
    """Szebehely & Peters (1967), AJ 72, 876: by t = 70 the bodies of mass 4 and 5
    form a tight binary and the body of mass 3 escapes.  The energy error stays
    within 3x IAS15's at the same tolerance (default 1e-9) and the same rule."""
    s = _burrau()
    traj = integrate(s, 70.0, criterion=criterion)
    r, v = traj.r[-1], traj.v[-1]
    d45 = np.linalg.norm(r[1] - r[2])
    w45 = v[1] - v[2]
    assert 0.5 * w45 @ w45 - 9.0 / d45 < 0  # the 4-5 pair is bound
    cm = (4 * r[1] + 5 * r[2]) / 9
    vcm = (4 * v[1] + 5 * v[2]) / 9
    d3, w3 = np.linalg.norm(r[0] - cm), v[0] - vcm
    assert 0.5 * w3 @ w3 - 12.0 / d3 > 0 and d3 > 20 and (r[0] - cm) @ w3 > 0  # escaping
    _, de_reb = _ias15(s, 70.0, adaptive_mode=2 if criterion == "prs23" else 1)
    assert abs(traj.energy_error[-1]) < 3 * de_reb


# ---------------------------------------------------------------------- Kozai-Lidov
def _kozai_secular(j0, e0, t, tk):
    """The doubly averaged quadrupole equations for a test particle and a perturber
    on a circular orbit in the xy plane (Tremaine, Touma & Kazandjian 2009; e.g.
    Liu, Munoz & Lai 2015, eqs. 17-18, test-particle limit), in vector form."""
    n = np.array([0.0, 0.0, 1.0])

    def rhs(_t, y):
        j, e = y[:3], y[3:]
        jn, en = j @ n, e @ n
        dj = 0.75 / tk * (jn * np.cross(j, n) - 5 * en * np.cross(e, n))
        de = 0.75 / tk * (jn * np.cross(e, n) + 2 * np.cross(j, e) - 5 * en * np.cross(j, n))
        return np.concatenate([dj, de])

    sol = solve_ivp(rhs, (0, t[-1]), np.concatenate([j0, e0]), t_eval=t, rtol=1e-11,
                    atol=1e-13, method="DOP853")
    return np.linalg.norm(sol.y[3:], axis=0)


def test_a_kozai_lidov_cycle_against_the_quadrupole_secular_equations():
    """A test particle (a = 1, e0 = 0.01, i0 = 65 deg) about a star, a perturber of
    equal mass on a circular orbit at 20: the eccentricity rises to
    sqrt(1 - 5/3 cos^2 i0) = 0.838 (Kozai 1962; Lidov 1962) at the time the secular
    equations give.  Tolerances: the quadrupole approximation and the short-period
    terms it averages out (measured: e_max 0.8401 against 0.8381, time 0.7%)."""
    i0 = np.radians(65.0)
    a_out, m_p = 20.0, 1.0
    inner = KeplerOrbit.from_elements(a=1.0, e=0.01, inc=i0, lan=0.0, argp=np.pi / 2, nu=0.3,
                                      mu=1.0)
    ri, vi = inner.state()
    vp = np.sqrt((1.0 + m_p) / a_out)
    r0, v0 = -m_p / 2 * np.array([a_out, 0, 0]), -m_p / 2 * np.array([0, vp, 0])
    s = System([Body("star", 1.0, r0, v0),
                Body("perturber", m_p, -r0 / m_p, -v0 / m_p),
                Body("particle", 0.0, r0 + ri, v0 + vi)])
    tk = a_out**3 / m_p  # (1/n) (m0/mp) (a_out/a)^3 with n = 1
    t = np.linspace(0.0, 4.0 * tk, 1601)
    traj = integrate(s, t)
    orbit = KeplerOrbit.from_state(traj.r[:, 2] - traj.r[:, 0], traj.v[:, 2] - traj.v[:, 0],
                                   np.ones(len(t)))
    e = np.asarray(orbit.e)
    h = np.cross(ri, vi)
    e_sec = _kozai_secular(h / np.linalg.norm(h), np.cross(vi, h) - ri / np.linalg.norm(ri), t, tk)
    assert np.max(e) == pytest.approx(np.sqrt(1 - 5 / 3 * np.cos(i0) ** 2), abs=5e-3)
    assert t[np.argmax(e)] == pytest.approx(t[np.argmax(e_sec)], rel=0.02)
    assert np.max(np.abs(traj.energy_error)) < 1e-13


# ---------------------------------------------------------------------- a comet
def test_a_near_parabolic_comet_keeps_its_jacobi_constant():
    """A comet (q = 0.5, e = 0.9999) through perihelion and out past a Jupiter on a
    circular orbit (the circular restricted three-body problem, G M_sun = 1,
    mass ratio 1e-3, a_J = 5.2): its Jacobi integral
    C = 2 (mu1 / r1 + mu2 / r2) + 2 n (x v_y - y v_x) - v^2 (Jacobi 1836) is kept,
    and rebound's IAS15 from the same state agrees."""
    mu_j, a_j = 1e-3, 5.2
    n = np.sqrt((1 + mu_j) / a_j**3)
    f = mu_j / (1 + mu_j)
    sun = Body("sun", 1.0, [-f * a_j, 0, 0], [0, -f * a_j * n, 0])
    jup = Body("jupiter", mu_j, [(1 - f) * a_j, 0, 0], [0, (1 - f) * a_j * n, 0])
    comet = KeplerOrbit.from_elements(q=0.5, e=0.9999, inc=np.radians(10), lan=0.3, argp=2.0,
                                      M=-1e-4, mu=1.0)
    rc, vc = comet.state()
    s = System([sun, jup, Body("comet", 0.0, rc + sun.r, vc + sun.v)])

    def jacobi(r, v):
        d1 = np.linalg.norm(r[2] - r[0], axis=-1)
        d2 = np.linalg.norm(r[2] - r[1], axis=-1)
        x, y = r[2][..., 0], r[2][..., 1]
        vx, vy = v[2][..., 0], v[2][..., 1]
        return 2 * (1.0 / d1 + mu_j / d2) + 2 * n * (x * vy - y * vx) - np.sum(v[2] ** 2, -1)

    t_end = 600.0  # from 1e-4 of a mean anomaly before perihelion to about 10 au out
    traj = integrate(s, np.linspace(0.0, t_end, 61))
    c = jacobi(np.moveaxis(traj.r, 1, 0), np.moveaxis(traj.v, 1, 0))
    assert np.max(np.abs(c - c[0]) / abs(c[0])) < 1e-12
    assert np.linalg.norm(traj.r[-1, 2] - traj.r[-1, 0]) > 8.0  # it went out past Jupiter
    r_reb, _ = _ias15(s, t_end)
    assert np.max(np.abs(r_reb - traj.r[-1]) / np.linalg.norm(r_reb, axis=1)[:, None]) < 1e-9


# ---------------------------------------------------------------------- a flyby
def test_a_hyperbolic_flyby_at_two_earth_radii_against_the_hyperbola():
    """A spacecraft passes the Earth at q = 2 R_E with v_inf = 7 km/s (km, s): the
    closest approach is found at t = 0 at 2 R_E, and the state 2 days later is the
    hyperbola's, from Kepler's equation for the hyperbola solved here
    (M = e sinh H - H; r = |a| (e - cosh H, sqrt(e^2 - 1) sinh H) in the perifocal
    frame), with the deflection 2 arcsin(1/e)."""
    mu, r_e, v_inf = 398600.4418, 6378.1363, 7.0
    q = 2 * r_e
    a = -mu / v_inf**2
    e = 1 - q / a

    def perifocal(t):
        m = np.sqrt(mu / abs(a) ** 3) * t
        h = brentq(lambda x: e * np.sinh(x) - x - m, -50, 50, xtol=1e-15, rtol=1e-15)
        vh = np.sqrt(mu / abs(a)) / (e * np.cosh(h) - 1)
        return (np.array([abs(a) * (e - np.cosh(h)), abs(a) * np.sqrt(e * e - 1) * np.sinh(h), 0]),
                vh * np.array([-np.sinh(h), np.sqrt(e * e - 1) * np.cosh(h), 0]))

    day = 86400.0
    r0, v0 = perifocal(-2 * day)
    s = System([Body("earth", mu, [0, 0, 0], [0, 0, 0]), Body("craft", 0.0, r0, v0)])
    traj = integrate(s, 4 * day, events=[{"name": "close_encounter", "distance": 1e5}])
    (event,) = traj.events
    assert event["distance"] == pytest.approx(q, rel=1e-12)
    assert event["time"] == pytest.approx(2 * day, rel=1e-12)
    r1, v1 = perifocal(2 * day)
    np.testing.assert_allclose(traj.r[-1, 1], r1, rtol=0, atol=1e-9 * np.linalg.norm(r1))
    np.testing.assert_allclose(traj.v[-1, 1], v1, rtol=0, atol=1e-9 * np.linalg.norm(v1))
    turn = np.arccos(v0 @ traj.v[-1, 1] / (np.linalg.norm(v0) * np.linalg.norm(traj.v[-1, 1])))
    assert turn == pytest.approx(2 * np.arcsin(1 / e), rel=1e-3)  # far from the Earth, not at inf
