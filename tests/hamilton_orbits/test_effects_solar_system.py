"""The DE440 effects, each alone against an analytic result or a peer."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, System, integrate
from hamilton_orbits import effects as fx
from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels import figures
from hamilton_orbits._kernels.figures import OF_DATE
from hamilton_orbits.effects.eih import eih_energy
from hamilton_orbits.effects.kuiper_ring import kuiper_ring_gm
from hamilton_orbits.effects.lense_thirring import sun_spin
from hamilton_orbits.rebound_bridge import to_rebound
from hamilton_orbits.rhs import takes_time

ARCSEC = np.pi / (180 * 3600)
C_AU_DAY = de.constant("CLIGHT") * 86400.0 / de.constant("AU")


def _four_bodies() -> System:
    """A compact hierarchical system (G = 1), barycentric."""
    s = System([
        Body("a", 1.0, [0, 0, 0], [0, 0, 0]),
        Body("b", 1e-3, [1.0, 0, 0], [0, 1.0, 0]),
        Body("c", 3e-4, [0, 2.0, 0.1], [-0.72, 0, 0.02]),
        Body("d", 1e-6, [-0.5, -0.3, 0], [0.8, -1.2, 0]),
    ])
    rb, vb = s.barycentre()
    return s.with_state(s.r - rb, s.v - vb)


def _gr_full(system: System, t: float, c: float) -> np.ndarray:
    import reboundx

    sim = to_rebound(system)
    sim.integrator = "ias15"
    rebx = reboundx.Extras(sim)
    gr = rebx.load_force("gr_full")
    rebx.add_force(gr)
    gr.params["c"] = c
    sim.integrate(t, exact_finish_time=1)
    return np.array([[p.x, p.y, p.z] for p in sim.particles])


def test_eih_against_reboundx_gr_full():
    """EIH for every body against reboundx's ``gr_full`` (Newhall et al. 1983).

    Both integrate the EIH equations; ``gr_full`` iterates the accelerations ``a_j``
    inside the correction to convergence, ours uses the Newtonian ones (as Moyer
    2003 and DE440 do), a difference of second post-Newtonian order.  So the two
    agree to a residual that scales as c^-4 (measured: 8.7e-6 at c = 30, 7.3e-12
    at c = 1000 after 20 orbits; (1000/30)^4 = 1.2e6), while the 1PN effect itself
    (ours minus Newton) is ~ c^-2: the check is the scaling, with a factor 3 margin.
    """
    pytest.importorskip("reboundx")
    s = _four_bodies()
    t = 20 * 2 * np.pi
    diff = {}
    for c in (30.0, 300.0):
        theirs = _gr_full(s, t, c)
        ours = integrate(s, t, effects=[{"name": "eih", "c": c}]).final.r
        newton = integrate(s, t).final.r
        diff[c] = np.abs(ours - theirs).max()
        assert diff[c] < 1e-4 * np.abs(newton - theirs).max()
    assert 1e4 / 3 < diff[30.0] / diff[300.0] < 3e4


def test_eih_one_body_limit_is_gr():
    """A test particle around one mass: EIH reduces to the ``gr`` effect (Anderson et
    al. 1975), term by term: the accelerations agree to rounding."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 0.0, [0.4, 0.1, 0.02], [-0.2, 1.4, 0.1])])
    a_eih = s.accelerations([{"name": "eih", "c": 50.0}])
    a_gr = s.accelerations([{"name": "gr", "c": 50.0}])
    assert np.allclose(a_eih, a_gr, rtol=1e-14, atol=0)


def _eih_energy_drift(years: float) -> tuple[float, float]:
    s = System.from_ephemeris()
    tr = integrate(s, np.linspace(0, years * 365.25, 101) * u.day, effects=["eih"])
    r = tr.r.to_value(u.au)
    v = tr.v.to_value(u.au / u.day)
    gm = s.gm.to_value(u.au**3 / u.day**2)
    e = np.array([eih_energy(r[k], v[k], gm, C_AU_DAY) for k in range(len(r))])
    from hamilton_orbits.integrals import energy_gm_many

    newton = energy_gm_many(r, v, gm)
    return float(np.abs(e / e[0] - 1).max()), float(np.abs(newton / newton[0] - 1).max())


def test_eih_conserves_its_energy():
    """The 1PN energy (Landau & Lifshitz eq. 106.17) is conserved to rounding (a few
    1e-16 relative, summed over 11 bodies: 1e-14 allowed) while the Newtonian energy
    of the same trajectory varies by ~2e-9 (the 1PN terms, (v/c)^2 ~ 1e-8)."""
    drift, newton = _eih_energy_drift(10.0)
    assert drift < 1e-14
    assert newton > 1e-10


@pytest.mark.slow
def test_eih_conserves_its_energy_1000_years():
    drift, _ = _eih_energy_drift(1000.0)
    assert drift < 1e-13  # rounding grows as sqrt(steps): 10x the 10-year bound


def _node(r: np.ndarray, v: np.ndarray, pole: np.ndarray) -> np.ndarray:
    h = np.cross(r, v)
    x = np.cross([0.0, 1.0, 0.0], pole)
    x /= np.linalg.norm(x)
    y = np.cross(pole, x)
    node = np.cross(pole, h)
    return np.unwrap(np.arctan2(node @ y, node @ x))


def test_zonal_j2_regresses_the_moon_node():
    """The Earth's J2 alone on the Moon (Earth and Moon only): the node on the Earth's
    equator regresses at -3/2 n J2 (R/p)^2 cos i (first order; ~0.2 deg/century).

    The tolerance 1% covers the second-order terms, J2 (R/p)^2 ~ 3e-7, and the fit
    of 10 years of a short-period oscillation of that relative size.
    """
    s = System.from_ephemeris(bodies=["earth", "moon"])
    t = np.linspace(0, 3652.5, 2001)
    j2 = de.constant("J2E")
    tr = integrate(s, t * u.day, effects=[{"name": "zonal", "j": (j2,)}])
    r = (tr.r[:, 1] - tr.r[:, 0]).to_value(u.au)
    v = (tr.v[:, 1] - tr.v[:, 0]).to_value(u.au / u.day)
    pole = np.array([0.0, 0.0, 1.0])
    rate = np.polyfit(t, _node(r, v, pole), 1)[0]
    mu = s.gm.to_value(u.au**3 / u.day**2).sum()
    h = np.cross(r[0], v[0])
    a = 1.0 / (2.0 / np.linalg.norm(r[0]) - v[0] @ v[0] / mu)
    p = h @ h / mu
    cos_i = h[2] / np.linalg.norm(h)
    radius = de.constant("RE") / de.constant("AU")
    expected = -1.5 * np.sqrt(mu / a**3) * j2 * (radius / p) ** 2 * cos_i
    assert rate == pytest.approx(expected, rel=0.01)
    assert np.degrees(expected) * 36525 == pytest.approx(-0.2, abs=0.05)


def test_zonal_field_is_the_gradient_of_its_potential():
    """J2..J4 against a central-difference gradient of -mu/r sum J_n (R/r)^n P_n
    (step 1e-5: truncation ~1e-10 relative)."""
    k = np.array([0.1, 0.2, 0.9]) / np.linalg.norm([0.1, 0.2, 0.9])
    jn = [1.1e-3, -2.5e-6, -1.6e-6]

    def potential(x):
        d = np.linalg.norm(x)
        s = x @ k / d
        legendre = {2: (3 * s * s - 1) / 2, 3: (5 * s**3 - 3 * s) / 2,
                    4: (35 * s**4 - 30 * s * s + 3) / 8}
        return -2.0 / d * sum(jn[n - 2] * (1.5 / d) ** n * legendre[n] for n in (2, 3, 4))

    r = np.array([[0.0, 0, 0], [3.0, 1.0, 2.0]])
    acc = np.zeros((2, 3))
    figures.zonal_field(r, np.zeros((2, 3)), np.array([2.0, 0.0]), acc,
                        np.array([0, 1.5, *k, *jn]))
    h = 1e-5
    grad = np.array([(potential(r[1] + h * e) - potential(r[1] - h * e)) / (2 * h)
                     for e in np.eye(3)])
    assert np.allclose(acc[1], grad, rtol=1e-8, atol=0)


def test_moon_figure_frame_follows_cassini_and_field_is_its_gradient():
    s = System.from_ephemeris(bodies=["earth", "moon"])
    r = np.ascontiguousarray(s.r.to_value(u.au))
    v = np.ascontiguousarray(s.v.to_value(u.au / u.day))
    ecl = de.ecliptic_pole("icrs")
    inc = np.deg2rad(1.5424)
    axes = figures.moon_frame(r, v, 1, 0, *ecl, inc)
    assert np.allclose(axes @ axes.T, np.eye(3), atol=1e-15)
    h = np.cross(r[0] - r[1], v[0] - v[1])
    # the pole, the ecliptic pole and the orbit normal are coplanar (Cassini's 2nd law),
    # the pole at I from the ecliptic pole, on the other side from the orbit normal
    assert abs(np.linalg.det([axes[2], ecl, h / np.linalg.norm(h)])) < 1e-15
    assert np.arccos(axes[2] @ ecl) == pytest.approx(inc, rel=1e-12)
    assert (axes[2] - ecl) @ h < 0
    # x towards the Earth: the Earth has no y coordinate in the Moon's frame
    assert abs(axes[1] @ (r[0] - r[1])) < 1e-18
    # the field is the gradient of the degree-2 potential in those axes
    j2, c22, rad = 2.03e-4, 2.24e-5, 1.2e-5
    mu = s.gm.to_value(u.au**3 / u.day**2)

    def potential(x):
        q = axes @ (x - r[1])
        d2 = q @ q
        return mu[1] * rad**2 / d2**2.5 * (-j2 * (3 * q[2] ** 2 - d2) / 2
                                           + 3 * c22 * (q[0] ** 2 - q[1] ** 2))

    point = r[1] + np.array([1e-3, -2e-3, 1.5e-3])
    rr = np.vstack([r, point])
    acc = np.zeros((3, 3))
    figures.moon_figure(rr, np.vstack([v, v[1]]), np.array([*mu, 0.0]), acc,
                        np.array([1, 0, rad, j2, c22, *ecl, inc]))
    hstep = 1e-9
    grad = np.array([(potential(point + hstep * e) - potential(point - hstep * e))
                     / (2 * hstep) for e in np.eye(3)])
    assert np.allclose(acc[2], grad, rtol=1e-6, atol=0)


def _coplanar_earth_moon(vz: float = 0.0) -> System:
    """A hand-built Earth and Moon in ecliptic axes, the Moon's orbit in the ecliptic
    tilted by ``vz / 1.022`` rad (its velocity's z, km/s), and two massless probes
    near the Moon, one in the plane, one out of it."""
    gm_e = 398600.4418 * u.km**3 / u.s**2
    return System([
        Body("earth", gm_e, [0, 0, 0] * u.km, [0, 0, 0] * u.km / u.s),
        Body("moon", 4902.8 * u.km**3 / u.s**2, [384400, 0, 0] * u.km,
             [0, 1.022, vz] * u.km / u.s),
        Body("in_plane", 0 * gm_e, [386000, 1200, 0] * u.km, [0, 2.5, 0] * u.km / u.s),
        Body("above", 0 * gm_e, [386400, 0, 300] * u.km, [0, 2.5, 0.2] * u.km / u.s)])


_ECLIPTIC_MOON = {"name": "moon_figure", "frame": "ecliptic"}


def test_moon_figure_is_finite_for_an_orbit_in_the_ecliptic():
    """The Moon's orbit exactly in the ecliptic has no node: ``moon_frame``
    normalised the zero vector, ``accelerations`` was all NaN and ``integrate``
    stopped at once ("the acceleration became non-finite (a collision?)").  At zero
    tilt the Moon's pole is the ecliptic pole (its equator in its orbit's plane):
    the figure pulls the bodies in the plane within it, so the orbit stays in the
    ecliptic, bit for bit."""
    s = _coplanar_earth_moon()
    acc = s.accelerations([_ECLIPTIC_MOON]).to_value(u.km / u.s**2)
    assert np.isfinite(acc).all()
    assert not acc[:3, 2].any()  # (mirror symmetry about the ecliptic: exactly zero)
    tr = integrate(s, [0, 1] * u.day, effects=[_ECLIPTIC_MOON])
    assert np.isfinite(tr.r.value).all() and np.isfinite(tr.v.value).all()
    assert not tr.r[:, :3, 2].value.any()


def test_moon_figure_is_continuous_as_the_orbit_tilts_to_the_ecliptic():
    """The field at a tilt of 1e-9 rad (and 1e-12 rad) against exactly zero tilt.

    Below ``MOON_NODE_TILT`` (1e-6 rad) the pole's inclination to the ecliptic is
    scaled down with the tilt ``t``: the pole turns by ``theta = atan(tan(I) t /
    MOON_NODE_TILT)`` from the ecliptic pole (I = 1.5424 deg), about the Earth
    direction ``x``, which stays put (the orbit normal's part in the ecliptic is
    perpendicular to it).  The degree-2 potential ``mu R^2 q.A q / |q|^5`` of
    principal moments spanning ``3 C22 + 3/2 J2`` then changes by ``|Q A Q^T - A| <=
    theta (3 C22 + 3/2 J2)``, and its gradient ``2 A q / |q|^5 - 5 (q.A q) q /
    |q|^7`` by at most ``7 mu R^2 theta (3 C22 + 3/2 J2) / |q|^4`` on each body.  The
    change is linear in the tilt (it is the first order of a rotation): 1000 times
    as large at 1e-9 rad as at 1e-12 rad, to the rotation's second order
    (``theta`` = 2.7e-5 rad at 1e-9: 1e-4 relative)."""
    fields = {}
    for tilt in (0.0, 1e-12, -1e-12, 1e-9, -1e-9):
        s = _coplanar_earth_moon(1.022 * np.tan(tilt))
        arrays = s.as_arrays()
        p = fx.get("nbody", "moon_figure").params(s, {"frame": "ecliptic"})
        fields[tilt] = np.zeros_like(arrays.r)
        figures.moon_figure(arrays.r, arrays.v, arrays.gm, fields[tilt], p)
    mu, rad, j2, c22, inc = arrays.gm[1], p[2], p[3], p[4], p[8]
    others = [0, 2, 3]  # (the Moon itself feels their sum, pushed back)
    q = np.linalg.norm(arrays.r[others] - arrays.r[1], axis=1)
    for tilt in (1e-12, -1e-12, 1e-9, -1e-9):
        theta = np.arctan(np.tan(inc) * abs(tilt) / figures.MOON_NODE_TILT)
        bound = 7 * mu * rad**2 * theta * (3 * c22 + 1.5 * j2) / q**4
        change = np.linalg.norm(fields[tilt][others] - fields[0.0][others], axis=1)
        assert (change <= bound).all(), (tilt, change, bound)
        # not vacuous: the probes see the pole turn (0.11 and 0.027 of the bound, the
        # worst case over directions); the Earth, on the axis of the turn, sees nothing
        assert (change[1:] > 0.01 * bound[1:]).all(), (tilt, change, bound)
    for sign in (1, -1):
        big, small = (fields[sign * t] - fields[0.0] for t in (1e-9, 1e-12))
        np.testing.assert_allclose(big, 1000 * small, rtol=0, atol=1e-4 * np.abs(big).max())


def test_moon_frame_keeps_cassinis_laws_above_the_node_tilt():
    """Above ``MOON_NODE_TILT`` the pole is at I from the ecliptic pole whatever the
    tilt (Cassini's laws, as before); at half of it, at ``atan(tan(I) / 2)``."""
    ecl = np.array([0.0, 0.0, 1.0])
    inc = np.deg2rad(1.5424)
    for tilt, want in ((0.09, inc), (2e-6, inc), (0.5e-6, np.arctan(np.tan(inc) / 2))):
        arrays = _coplanar_earth_moon(1.022 * np.tan(tilt)).as_arrays()
        axes = figures.moon_frame(arrays.r, arrays.v, 1, 0, *ecl, inc)
        assert np.arccos(axes[2] @ ecl) == pytest.approx(want, rel=1e-9)


def _mean_longitude_offset(system: System, years: float, effects: list) -> tuple:
    t = np.linspace(0, years * 365.25, int(years * 73) + 1)
    out = []
    for eff in ([], effects):
        tr = integrate(system, t * u.day if system.quantity else t, effects=eff)
        d = np.asarray(tr.r[:, 2] - tr.r[:, 1])
        w = np.asarray(tr.v[:, 2] - tr.v[:, 1])
        k = np.cross(d, w).mean(axis=0)
        k /= np.linalg.norm(k)
        x = np.cross([0, 0, 1.0], k) if abs(k[2]) < 0.999 else np.array([1.0, 0, 0])
        x /= np.linalg.norm(x)
        out.append(np.unwrap(np.arctan2(d @ np.cross(k, x), d @ x)))
    return t, out[1] - out[0]


def test_tide_secular_acceleration_constant_lag():
    """A circular equatorial orbit with only the semi-diurnal tide lagging by the
    rotation angle delta = omega tau_R: the mean motion changes at
    ndot = -9/2 k22 (m/M) (R/a)^5 n^2 sin(2 delta)
    (the tangential tidal force 3/2 k2 G m (1 + m/M) R^5 sin(2 delta) / a^7, Gauss's
    equation da/dt = 2 a_t / n).  2% covers the e ~ 1e-4 the tide itself induces and
    the quadratic fit of 20 years of longitude differences."""
    gm_e, gm_m = 1.0, 0.0123
    a = 60.0
    n = np.sqrt((gm_e + gm_m) / a**3)
    moon = Body("moon", gm_m, [a, 0, 0], [0, n * a, 0])
    earth = Body("earth", gm_e, [0, 0, 0], [0, 0, 0])
    s = System([Body("dummy", 1e-30, [1e9, 0, 0], [0, 0, 0]), earth, moon])
    delta, omega, k22 = 0.04, 20 * n, 0.3
    tides = {"name": "earth_tides", "sun": "none", "radius": 1.0, "omega": omega,
             "k2": (0.0, 0.0, k22), "tau": (0, 0, 0, 0, delta / omega), "pole": (0, 0, 1)}
    period = 2 * np.pi / n
    t, dl = _mean_longitude_offset(s, 200 * period / 365.25, [tides])
    ndot = 2 * np.polyfit(t, dl, 2)[0]
    expected = -4.5 * k22 * gm_m / gm_e * (1 / a) ** 5 * n**2 * np.sin(2 * delta)
    assert ndot == pytest.approx(expected, rel=0.02)


def test_tide_gives_the_moon_its_secular_acceleration():
    """DE440's tide model and constants on the real Earth-Moon-Sun at J2000: the
    tidal acceleration of the Moon's mean longitude is -25.82 "/cy^2 for DE430's
    model and constants (Williams & Boggs 2016, Celest. Mech. Dyn. Astr. 126, 89,
    table 5; DE440 keeps the model).  Measured here as the quadratic term of the
    longitude difference with and without the effect over 40 years (-26.2);
    the 1 "/cy^2 tolerance covers the fit over the solar perturbations and the
    time-delay approximation (the delayed position to second order)."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    t, dl = _mean_longitude_offset(s, 40.0, ["earth_tides"])
    ndot = 2 * np.polyfit(t / 36525.0, dl, 2)[0] / ARCSEC
    assert ndot == pytest.approx(-25.82, abs=1.0)


def test_lense_thirring_regresses_the_node():
    """A test particle about a spinning mass (G M = 1, spin J along z, c = 60): the
    node on the equator advances at 2 G M J / (c^2 a^3 (1 - e^2)^(3/2)) (Lense &
    Thirring 1918; e.g. Ciufolini & Pavlis 2004).  The formula is first order in the
    field, whose relative size here is 2 J v / (c^2 r^2) = 1e-3 (at c = 20, 1e-2, the
    measured rate was 2% low); 0.5% covers that and the fit over 40 orbits."""
    spin = 2.0
    c = 60.0
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 0.0, [1.0, 0, 0], [0, np.cos(0.5), np.sin(0.5)])])
    t = np.linspace(0, 40 * 2 * np.pi, 4001)
    tr = integrate(s, t, effects=[{"name": "lense_thirring", "spin": (0, 0, spin), "c": c}])
    r = np.asarray(tr.r[:, 1])
    v = np.asarray(tr.v[:, 1])
    rate = np.polyfit(t, _node(r, v, np.array([0.0, 0.0, 1.0])), 1)[0]
    assert rate == pytest.approx(2 * spin / c**2, rel=0.005)


def test_lense_thirring_defaults_are_de440s():
    """The Sun's spin per unit mass MOISUN ASUN^2 OMGSUN (DE440: 0.0688, 696000 km,
    0.2476 rad/day, a 25.4-day sidereal rotation) along its IAU pole."""
    s = System.from_ephemeris(bodies=["sun", "mercury"])
    p = fx.get("nbody", "lense_thirring").params(s, {})
    spin = p[3:]
    radius = 696000.0 / 149597870.7
    assert np.linalg.norm(spin) == pytest.approx(0.0688400 * radius**2 * 0.24756443290699712,
                                                 rel=1e-12)
    assert np.allclose(spin / np.linalg.norm(spin), de.sun_pole("icrs"))
    assert p[1] == pytest.approx(C_AU_DAY, rel=1e-15)


def test_ring_field_against_its_analytic_potential():
    """Inside the ring: on the axis a_z = -M z / (R^2 + z^2)^(3/2) exactly; in the
    plane the Legendre series of the potential, -M/R sum ((2n)!/(2^2n n!^2))^2
    (rho/R)^2n, differentiated (60 terms: converged at rho/R = 0.7 to 1e-18); the
    centre feels nothing."""
    big_m, rad = 2.0e-11, 44.0
    pts = np.array([[0.0, 0, 0], [0, 0, 10.0], [30.0 * np.cos(0.3), 30.0 * np.sin(0.3), 0],
                    [1e-13, 0, 0]])
    r = np.vstack([[0.0, 0, 0], pts])
    acc = np.zeros_like(r)
    gm = np.array([1.0, 0, 0, 0, 0])
    figures.ring_field(r, np.zeros_like(r), gm, acc, np.array([0, big_m, rad, 0, 0, 1.0]))
    assert np.all(acc[1] == 0)
    assert acc[2] == pytest.approx([0, 0, -big_m * 10 / (rad**2 + 100) ** 1.5], rel=1e-13)
    from math import comb

    x = 30.0 / rad
    da = sum((comb(2 * k, k) / 4**k) ** 2 * 2 * k * x ** (2 * k - 1) for k in range(1, 60))
    a_rho = big_m / rad**2 * da  # -dPhi/drho, outwards
    assert np.linalg.norm(acc[3]) == pytest.approx(a_rho, rel=1e-13)
    assert acc[3] @ pts[2] > 0 and abs(acc[3][2]) == 0
    # near the centre the field is M rho / (2 R^3) (the series' first term)
    assert acc[4] == pytest.approx([big_m * 1e-13 / (2 * rad**3), 0, 0], rel=1e-12)


def test_ring_series_near_the_centre():
    """Within 0.15 R the kernel uses the potential's series to (r/R)^4: against the
    exact field (the same kernel just outside the switch, scaled: the field is
    smooth) and against the central-difference gradient of -2 M K(m) / (pi D+),
    within the truncation bound 1e-3."""
    from scipy.special import ellipk

    big_m, rad = 2.0, 44.0

    def potential(x):
        rho = np.hypot(x[0], x[1])
        dp2 = (rad + rho) ** 2 + x[2] ** 2
        return -2 * big_m * ellipk(4 * rad * rho / dp2) / (np.pi * np.sqrt(dp2))

    for x in ([5.2, 0.1, 0.0], [0.5, 0.2, -5.0], [6.0, 2.0, 1.5]):
        x = np.array(x)
        r = np.array([[0.0, 0, 0], x])
        acc = np.zeros((2, 3))
        figures.ring_field(r, np.zeros((2, 3)), np.array([1.0, 0.0]), acc,
                           np.array([0, big_m, rad, 0, 0, 1.0]))
        h = 1e-4
        grad = np.array([(potential(x + h * e) - potential(x - h * e)) / (2 * h)
                         for e in np.eye(3)])
        assert np.abs(acc[1] + grad).max() < 1e-3 * np.abs(grad).max()


def test_ring_defaults_are_de440s():
    """36 masses MA8201..MA8236 of DE440's comment block: 0.0224 Earth masses at 44 au."""
    s = System.from_ephemeris(bodies=["sun", "neptune"])
    p = fx.get("nbody", "kuiper_ring").params(s, {})
    assert p[1] == kuiper_ring_gm() == pytest.approx(36 * 5.5227699716988214e-13, rel=1e-15)
    assert p[2] == 44.0
    assert np.allclose(p[3:], de.ecliptic_pole("icrs"))


@pytest.mark.parametrize(
    ("effects", "match"),
    [
        ([{"name": "eih", "sources": "sun"}], r"list of body names"),
        ([{"name": "eih", "sources": ("vulcan",)}], r"'vulcan'.*not in the system"),
        ([{"name": "zonal", "body": "mars"}], r"needs `j`"),
        ([{"name": "kuiper_ring", "frame": "galactic"}], r"'icrs' or 'ecliptic'"),
        ([{"name": "earth_tides", "k2": (0.3,)}], r"`k2` to be 3 finite"),
    ],
)
def test_bad_parameters(effects, match):
    s = System.from_ephemeris()
    with pytest.raises(ValueError, match=match):
        s.accelerations(effects)


def test_plain_float_system_needs_its_units():
    s = System([Body("earth", 1.0, [0, 0, 0], [0, 0, 0]), Body("moon", 0.01, [60, 0, 0],
                                                                [0, 0.13, 0])])
    with pytest.raises(ValueError, match=r"needs c in its own units"):
        s.accelerations(["eih"])
    with pytest.raises(ValueError, match=r"radius, omega, tau"):
        s.accelerations(["earth_tides"])


def test_every_effect_is_the_same_in_the_ecliptic_frame():
    """Each DE440 effect in ecliptic axes is the ICRS one rotated (kernel by kernel,
    to rounding): the ecliptic pole, the Sun's pole and spin and the Earth's pole
    follow the system's frame (recognised from the Sun's pole that from_ephemeris
    sets).  This caught an ecliptic pole given in the wrong frame."""
    rot = de.frame_rotation("ecliptic")
    systems = {f: System.from_ephemeris(frame=f) for f in ("icrs", "ecliptic")}
    for name, params in (("eih", {}), ("j2", {"body": "sun"}), ("lense_thirring", {}),
                         ("zonal", {}), ("moon_figure", {}), ("earth_tides", {}),
                         ("kuiper_ring", {}), ("zonal", {"pole": "IAU2006"}),
                         ("earth_tides", {"pole": "IAU2006"})):
        spec = fx.get("nbody", name)
        out = {}
        for frame, s in systems.items():
            r = np.ascontiguousarray(s.r.to_value(u.au))
            v = np.ascontiguousarray(s.v.to_value(u.au / u.day))
            acc = np.zeros_like(r)
            p = spec.params(s, params)
            spec.kernel(r, v, s.gm.to_value(u.au**3 / u.day**2), acc, p,
                        *([36525.0] if takes_time(spec.kernel, 5) else []))  # (a century on)
            out[frame] = acc
        scale = np.abs(out["icrs"]).max()
        assert np.abs(out["ecliptic"] - out["icrs"] @ rot.T).max() < 1e-12 * scale, name
    # the ecliptic pole in ICRS axes is (0, -sin eps, cos eps)
    p = fx.get("nbody", "kuiper_ring").params(systems["icrs"], {})
    eps = np.deg2rad(84381.406 / 3600)
    assert np.allclose(p[3:], [0.0, -np.sin(eps), np.cos(eps)], rtol=0, atol=1e-15)


# ------------------------------------------------------------------ issue 32: units, names
# Effect parameters in the wrong unit (class 3), as Quantities or strings (class 17):
# one rule for every effect (docs/effects.md), each refusal naming the effect, the
# parameter, the value and the effect's index in the list.


def _accelerations(system: System, effects: list) -> np.ndarray:
    return system.accelerations(effects).to_value(u.au / u.day**2)


def _alone(system: System, name: str, params: dict) -> np.ndarray:
    """The effect's own acceleration (its kernel on zeros; au/day^2)."""
    spec = fx.get("nbody", name)
    r = np.ascontiguousarray(system.r.to_value(u.au))
    acc = np.zeros_like(r)
    spec.kernel(r, np.ascontiguousarray(system.v.to_value(u.au / u.day)),
                system.gm.to_value(u.au**3 / u.day**2), acc, spec.params(system, params))
    return acc


def test_a_bare_speed_of_light_on_a_quantity_system_is_refused_not_read_as_au_per_day():
    """``{"name": "eih", "c": 1.0}`` ran as 1 au/day (issue 32)."""
    s = System.from_ephemeris(bodies=["sun", "mercury"])
    msg = ("Effect 'eih': expected `c` as a Quantity (a speed, convertible to m / s; e.g. a "
           "string such as '299792.458 km/s') for a system of Quantities, got the plain "
           "number 1.0 (effects[0])")
    with pytest.raises(ValueError, match=re.escape(msg)):
        s.accelerations([{"name": "eih", "c": 1.0}])


@pytest.mark.parametrize("c", [299792.458 * u.km / u.s, "299792.458 km/s", C_AU_DAY * u.au / u.d])
def test_eih_takes_the_speed_of_light_as_a_quantity_or_a_string(c):
    """DE440's CLIGHT in any unit is the default (a bare TypeError or "could not
    convert string to float" before)."""
    s = System.from_ephemeris(bodies=["sun", "mercury", "venus"])
    p = fx.get("nbody", "eih").params(s, {"c": c})
    assert p[0] == pytest.approx(C_AU_DAY, rel=1e-15)
    assert np.allclose(_accelerations(s, [{"name": "eih", "c": c}]),
                       _accelerations(s, ["eih"]), rtol=1e-15, atol=0)


def test_a_bare_earth_radius_is_refused_not_read_as_6378_au():
    """``zonal`` ``radius=6378`` was 6378 au and died of "step underflowed"."""
    s = System.from_ephemeris(bodies=["earth", "moon"])
    with pytest.raises(ValueError, match=r"Effect 'zonal': expected `radius` as a Quantity "
                                         r"\(a length.*got the plain number 6378 \(effects\[0\]\)"):
        s.accelerations([{"name": "zonal", "radius": 6378}])
    p = fx.get("nbody", "zonal").params(s, {"radius": 6378.1366 * u.km})
    assert p[OF_DATE + 1] == pytest.approx(de.constant("RE") / de.constant("AU"), rel=1e-15)


@pytest.mark.parametrize(("params", "message"), [
    ({"radius": -1738 * u.km}, "Effect 'moon_figure': expected `radius` > 0, got -1738.0 km"),
    ({"radius": 0 * u.km}, "Effect 'moon_figure': expected `radius` > 0, got 0.0 km"),
    ({"radius": -1e-5}, "Effect 'moon_figure': expected `radius` as a Quantity"),
    ({"j2": np.nan}, "Effect 'moon_figure': Expected `j2` to be finite, got nan"),
    ({"c22": "x"}, "Effect 'moon_figure': Expected `c22` to be numeric"),
    ({"inclination_deg": np.nan},
     "Effect 'moon_figure': Expected `inclination_deg` to be finite, got nan"),
    ({"inclination_deg": 1 * u.m},
     "Effect 'moon_figure': Expected `inclination_deg` to be an angle"),
    ({"radius": "1738 kg"}, "Effect 'moon_figure': Expected `radius` to be a length"),
    ({"radius": "big"}, "Effect 'moon_figure': cannot read `radius` = 'big' as a number with "
                        "a unit (e.g. '6378.1366 km')"),
    ({"moon": "earth"}, "Effect 'moon_figure': `moon` and `earth` name one body, 'earth'"),
])
def test_moon_figure_refuses_bad_parameters(params, message):
    """A negative radius ran; NaN J2 or inclination stopped with "(a collision?)"."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    with pytest.raises(ValueError, match=re.escape(message)):
        integrate(s, 1 * u.day, effects=[{"name": "moon_figure", **params}])


def test_moon_figure_takes_its_radius_and_inclination_in_any_unit():
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    spec = fx.get("nbody", "moon_figure")
    p = spec.params(s, {"radius": 1738 * u.km, "inclination_deg": 5552.64 * u.arcsec})
    assert np.allclose(p, spec.params(s, {}), rtol=1e-15, atol=0)
    assert spec.params(s, {"inclination_deg": "1.5424 deg"})[-1] == spec.params(s, {})[-1]


@pytest.mark.parametrize(("effect", "params", "message"), [
    ("earth_tides", {"omega": np.nan}, "Effect 'earth_tides': expected `omega` as a Quantity"),
    ("earth_tides", {"omega": np.nan * u.rad / u.s},
     "Effect 'earth_tides': Expected `omega` to be finite, got nan"),
    ("earth_tides", {"tau": [0.07, 0, 0, 0, 0]},
     "Effect 'earth_tides': expected `tau` as a Quantity (a time"),
    ("earth_tides", {"tau": ["0.07 d"] * 4},
     "Effect 'earth_tides': expected `tau` to be 5 finite numbers"),
    ("earth_tides", {"tau": ["0.07 d", 1, 0, 0, 0]},
     "Effect 'earth_tides': expected `tau` to be values of one dimension"),
    ("lense_thirring", {"c": 0}, "Effect 'lense_thirring': expected `c` as a Quantity"),
    ("lense_thirring", {"c": 0 * u.km / u.s},
     "Effect 'lense_thirring': expected `c` > 0, got 0.0 km / s"),
    ("lense_thirring", {"gamma": np.inf}, "Effect 'lense_thirring': Expected `gamma` to be "
                                          "finite, got inf"),
    ("lense_thirring", {"spin": [0, 0, 1e-7]},
     "Effect 'lense_thirring': expected `spin` as a Quantity (an angular momentum per unit mass"),
    # (R^2 omega with omega in cycles per second: read as radians, 2 pi off; a count of
    # decays per second is no rotation rate at all: both were taken as 1/s)
    ("lense_thirring", {"spin": [0, 0, 1e-7] * u.au**2 * u.Hz},
     "Effect 'lense_thirring': Expected `spin` to be an angular momentum per unit mass, got "
     "AU2 Hz: the hertz counts cycles"),
    ("earth_tides", {"omega": 7.292115e-5 * u.Bq},
     "Effect 'earth_tides': Expected `omega` to be an angular speed, got Bq: a count of decays"),
    ("kuiper_ring", {"gm": 1e-11}, "Effect 'kuiper_ring': expected `gm` as a Quantity"),
    ("kuiper_ring", {"gm": -1e-11 * u.au**3 / u.d**2},
     "Effect 'kuiper_ring': expected `gm` >= 0, got -1e-11 AU3 / d2"),
    ("kuiper_ring", {"radius": "44 d"}, "Effect 'kuiper_ring': Expected `radius` to be a length"),
    ("eih", {"c": -1 * u.km / u.s}, "Effect 'eih': expected `c` > 0, got -1.0 km / s"),
    ("eih", {"beta": np.nan}, "Effect 'eih': Expected `beta` to be finite, got nan"),
    ("eih", {"sources": 3}, "Effect 'eih': expected `sources` to be a list of body names"),
    ("zonal", {"j": ["x"]}, "Effect 'zonal': Expected `j` to be numeric, got ['x']"),
    ("zonal", {"j": [np.nan]}, "Effect 'zonal': expected `j` to be some finite number(s), "
                               "got [nan]"),
    ("earth_tides", {"k2": [0.3, 0.3, 0.3] * u.km},
     "Effect 'earth_tides': Expected `k2` to be dimensionless, got [0.3, 0.3, 0.3] km"),
    ("earth_tides", {"omega": "fast"}, "Effect 'earth_tides': cannot read `omega` = 'fast' as "
                                       "a number with a unit (e.g. '7.292115e-5 rad/s')"),
    ("kuiper_ring", {"normal": ["a", 0, 1]},
     "Effect 'kuiper_ring': Expected `normal` to be numeric, got ['a', 0, 1]"),
])
def test_solar_system_effects_refuse_bad_parameters(effect, params, message):
    """NaN omega and c = 0 stopped with "(a collision?)"; Quantities gave a bare TypeError."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon", "neptune"])
    with pytest.raises(ValueError, match=re.escape(message)):
        integrate(s, 1 * u.day, effects=[{"name": effect, **params}])


def test_solar_system_effects_take_quantities_in_any_unit():
    """Each dimensioned default, given back as a Quantity in other units, is the default."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon", "neptune"])
    c = 299792.458 * u.km / u.s
    day = u.day.to(u.s)
    tau = [de.constant(k) * day for k in ("TAUE0", "TAUE1", "TAUE2", "TAUER1", "TAUER2")]
    cases = {
        "lense_thirring": {"c": c, "spin": sun_spin() * (u.au**2 / u.d).to(u.km**2 / u.s)
                           * u.km**2 / u.s},
        "kuiper_ring": {"gm": kuiper_ring_gm() * (u.au**3 / u.d**2).to(u.km**3 / u.s**2)
                        * u.km**3 / u.s**2, "radius": 44 * u.au.to(u.km) * u.km},
        "earth_tides": {"omega": 7.292115e-5 * u.rad / u.s, "tau": tau * u.s,
                        "radius": "6378.1366 km"},
    }
    for name, params in cases.items():
        spec = fx.get("nbody", name)
        assert np.allclose(spec.params(s, params), spec.params(s, {}), rtol=1e-14, atol=0), name


def test_a_plain_float_system_refuses_quantities_for_the_solar_system_effects():
    s = System([Body("earth", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("moon", 0.01, [60, 0, 0], [0, 0.13, 0.01])])
    with pytest.raises(ValueError, match=re.escape(
            "Effect 'moon_figure': expected `radius` as a plain number in the units of the "
            "system (a system of plain floats), got the Quantity 1738.0 km (effects[0])")):
        s.accelerations([{"name": "moon_figure", "radius": 1738 * u.km, "frame": "icrs"}])


def test_earth_tides_refuses_a_sun_not_in_the_system():
    """``sun="Sun"`` silently dropped the solar tide (issue 32); ``"none"`` leaves it out
    on purpose, and the Sun's tide is there by default."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    with pytest.raises(ValueError, match=re.escape(
            "Effect 'earth_tides': `sun` names body 'Sun', which is not in the system (did you "
            "mean 'sun'?); bodies: sun, earth, moon (effects[0])")):
        s.accelerations([{"name": "earth_tides", "sun": "Sun"}])
    base = _accelerations(s, [])
    both = _accelerations(s, ["earth_tides"])[2] - base[2]
    lunar = _accelerations(s, [{"name": "earth_tides", "sun": "none"}])[2] - base[2]
    # the Sun's index, after the pole of date's numbers
    assert fx.get("nbody", "earth_tides").params(s, {})[OF_DATE + 2] == 0
    assert fx.get("nbody", "earth_tides").params(s, {"sun": None})[OF_DATE + 2] == -1
    # the solar tide is a part of the whole: smaller than the lunar, not nothing
    assert 1e-3 < np.linalg.norm(both - lunar) / np.linalg.norm(lunar) < 1.0


@pytest.mark.parametrize("other", ["gr", "gr_potential",
                                   {"name": "gr", "c": C_AU_DAY * u.au / u.d}])
def test_eih_refuses_gr_beside_it(other):
    """``["eih", "gr"]`` counted the 1PN terms twice (issue 32)."""
    s = System.from_ephemeris(bodies=["sun", "mercury"])
    name = other if isinstance(other, str) else other["name"]
    with pytest.raises(ValueError, match=re.escape(
            f"Effect {name!r} (at index 1) is refused beside 'eih' (at index 0): 'eih' already "
            "computes")):
        integrate(s, 1 * u.day, effects=["eih", other])
    with pytest.raises(ValueError, match=re.escape(f"Effect {name!r} (at index 0) is refused "
                                                   "beside 'eih' (at index 2)")):
        integrate(s, 1 * u.day, effects=[other, "newtonian", "eih"])


def test_moon_figure_on_an_ecliptic_earth_and_moon_without_the_sun():
    """Without the Sun the frame was not recognised and the ICRS's ecliptic pole was used
    on ecliptic axes (27% of the effect wrong): it is recognised from the Earth's and
    the Moon's DE440 poles, and the effect is the ICRS one rotated."""
    rot = de.frame_rotation("ecliptic")
    out = {}
    for frame in ("icrs", "ecliptic"):
        s = System.from_ephemeris(bodies=["earth", "moon"], frame=frame)
        assert fx.parameters.axes_frame(s, {}, "moon_figure") == frame
        out[frame] = _alone(s, "moon_figure", {})
    scale = np.abs(out["icrs"]).max()
    assert np.abs(out["ecliptic"] - out["icrs"] @ rot.T).max() < 1e-12 * scale


def test_an_unknown_frame_whose_orbits_lie_in_x_y_asks_for_frame():
    """A system in ecliptic axes with no poles to recognise them by (as
    ``System.solar_system(frame="ecliptic")`` was, its bodies here without their
    poles): the ring's normal was put along the ICRS's ecliptic pole, 23.4 deg off.
    Now the effect asks for ``frame``; given, it is the ICRS one rotated.  The
    bodies of ``solar_system`` carry their poles (the Sun's here), which tell the
    axes: the same ring, no ``frame`` asked."""
    ecl = System.solar_system(bodies=["sun", "jupiter", "neptune"], frame="ecliptic")
    bare = System([Body(b.name, b.gm, b.r, b.v) for b in ecl.bodies])
    with pytest.raises(ValueError, match=re.escape(
            "Effect 'kuiper_ring': expected `frame` ('icrs' or 'ecliptic'): the system's axes "
            "are not known")):
        bare.accelerations(["kuiper_ring"])
    icrs = System.solar_system(bodies=["sun", "jupiter", "neptune"])
    a_icrs = _alone(icrs, "kuiper_ring", {})  # ICRS axes: taken as such, as before
    a_ecl = _alone(bare, "kuiper_ring", {"frame": "ecliptic"})
    rot = de.frame_rotation("ecliptic")
    assert np.abs(a_ecl - a_icrs @ rot.T).max() < 1e-12 * np.abs(a_icrs).max()
    np.testing.assert_array_equal(_alone(ecl, "kuiper_ring", {}), a_ecl)


def test_a_body_on_the_kuiper_ring_is_refused_by_name():
    """A body exactly on the ring, where its potential is singular: ``System.
    accelerations`` returned NaN (for the Sun too, by the ring's reaction) and a run
    stopped saying only "the acceleration became non-finite (a collision?)".  Both
    refuse it naming the effect, its index, the body and the cause; off the ring
    (0.1 au above it) the field is finite."""
    ring = {"name": "kuiper_ring", "gm": 1e-8, "radius": 44.0, "normal": [0, 0, 1]}

    def system(z):
        return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                       Body("tno", 0.0, [44.0, 0, z], [0, 0.15, 0])])

    message = ("Effect 'kuiper_ring' (effects[0]) at t = 0.0: body 'tno' (index 1) lies on "
               "the ring (radius 44.0, its distance to the ring 0.0): the ring's potential "
               "is singular there; move it off the ring")
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        system(0.0).accelerations([ring])
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        integrate(system(0.0), 1.0, effects=[ring])
    assert np.isfinite(system(0.1).accelerations([ring])).all()


@pytest.mark.parametrize("effect", ["kuiper_ring", "zonal"])
def test_an_unknown_frame_whose_test_particles_orbit_in_x_y_asks_for_frame(effect):
    """The check looked at the angular momentum, to which massless bodies add none: a
    Sun with a massless rock in the ecliptic's x-y plane took ICRS axes silently
    (the ring's normal 23.4 deg off), a hand-built Earth with a massless equatorial
    satellite likewise (docs/effects.md says it asks for ``frame`` there too).  With
    one massive body the test particles' orbits decide."""
    import astropy.units as u

    centre = "sun" if effect == "kuiper_ring" else "earth"
    gm = (2.959e-4 if centre == "sun" else 8.887e-10) * u.au**3 / u.day**2
    d = (1.0 if centre == "sun" else 5e-5) * u.au
    w = np.sqrt(gm / d).to(u.au / u.day)
    zero = [0, 0, 0] * u.au

    def system(r, v):
        return System([Body(centre, gm, zero, zero / u.day, radius=(6.4e3 * u.km).to(u.au)),
                       Body("rock", 0.0 * gm, r, v)])

    plane = system(u.Quantity([0 * d, d, 0 * d]), u.Quantity([-w, 0 * w, 0 * w]))
    with pytest.raises(ValueError, match=re.escape(
            f"Effect {effect!r}: expected `frame` ('icrs' or 'ecliptic')")):
        plane.accelerations([effect])
    assert np.all(np.isfinite(plane.accelerations([{"name": effect, "frame": "icrs"}])))
    tilted = system(u.Quantity([d, 0 * d, 0 * d]), u.Quantity([0 * w, 0 * w, w]))
    assert np.all(np.isfinite(tilted.accelerations([effect])))  # (its orbit far from x-y)



def test_a_default_pole_is_not_taken_for_the_axes():
    """An Earth given ``j2`` and no pole gets the pole z, which is also DE440's Earth
    pole in ICRS axes: a hand-built system in ecliptic axes (its orbits in its x-y
    plane) was taken for an ICRS one, and ``kuiper_ring`` put its normal 23.4 deg
    off the system's ecliptic pole.  A pole along z says nothing about the axes:
    such a system is asked for ``frame`` as one whose Earth has no J2."""
    from hamilton_orbits import Body, System
    from hamilton_orbits.effects import get

    earth = Body("earth", 3e-6, [1, 0, 0], [0, 1, 0.01], radius=4e-5, j2=1e-3)
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), earth,
                Body("moon", 3.7e-8, [1.0026, 0, 0], [0, 1.034, 0.01])])
    with pytest.raises(ValueError, match=r"Effect 'kuiper_ring': expected `frame`"):
        get("nbody", "kuiper_ring").params(s, {"gm": 1e-8, "radius": 44})
    ring = get("nbody", "kuiper_ring").params(s, {"gm": 1e-8, "radius": 44, "frame": "ecliptic"})
    np.testing.assert_allclose(ring[-3:], [0.0, 0.0, 1.0], atol=1e-15)
    # DE440's Earth in ICRS axes (its pole z) with a satellite in a low orbit, no Sun:
    # still taken for ICRS axes (the z pole is doubted only beside the Sun)
    from hamilton_orbits.effects.parameters import axes_frame

    earth = System.from_ephemeris(bodies=["earth"])
    sat = Body("sat", 0.0 * u.km**3 / u.s**2, earth["earth"].r + [7000, 0, 0] * u.km,
               earth["earth"].v + [0, 7.5, 0.1] * u.km / u.s)
    assert axes_frame(System([earth["earth"], sat]), {}, "zonal") == "icrs"


def test_a_time_parameter_takes_a_timedelta_as_the_quantity_it_holds():
    """An effect's time parameter (``earth_tides``' ``tau``) given as an astropy
    TimeDelta, or a list of them, was refused as "the plain number <TimeDelta ...>";
    the reader of the effects' and events' values (``effects.parameters.with_units``)
    now takes a TimeDelta as the time Quantity in days it holds, to the bit, and a
    TimeDelta given for a length is refused as the time it is."""
    from astropy.time import TimeDelta

    s = System.from_ephemeris("J2000", bodies=["sun", "earth", "moon"])
    days = [0.1, 0.2, 0.3, 0.4, 0.5]
    want = s.accelerations([{"name": "earth_tides", "tau": days * u.day}])
    for tau in (TimeDelta(days, format="jd"), [TimeDelta(x, format="jd") for x in days],
                [TimeDelta(days[0], format="jd"), *days[1:] * u.day]):
        got = s.accelerations([{"name": "earth_tides", "tau": tau}])
        assert np.array_equal(got, want)
    with pytest.raises(u.UnitConversionError, match=r"Effect 'earth_tides': Expected `radius` "
                                                    r"to be a length .*got 1 d"):
        s.accelerations([{"name": "earth_tides", "radius": TimeDelta(1.0, format="jd")}])
