"""Body and System: construction, checks, Hamilton's equation (B) and its integrals."""

from __future__ import annotations

import math

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, System
from hamilton_orbits._kernels import nbody as kernels
from hamilton_orbits.initial_states import SOLAR_SYSTEM_GM
from hamilton_orbits.integrals import accelerations_quaternion
from hamilton_orbits.rebound_bridge import from_rebound, rebound_accelerations, to_rebound

EPS = np.finfo(float).eps


def random_system(n: int, seed: int, n_massless: int = 0) -> System:
    rng = np.random.default_rng(seed)
    bodies = [
        Body(f"b{k}", gm=float(rng.uniform(1e-3, 1.0)) if k < n else 0.0,
             r=rng.normal(size=3) * 3, v=rng.normal(size=3))
        for k in range(n + n_massless)
    ]
    return System(bodies)


def direct_accelerations(r: np.ndarray, gm: np.ndarray) -> np.ndarray:
    """Equation (B) summed directly with numpy (no pair symmetry, no kernel)."""
    d = r[None, :, :] - r[:, None, :]  # d[i, j] = r_j - r_i
    dist = np.linalg.norm(d, axis=2)
    np.fill_diagonal(dist, np.inf)
    return np.einsum("j,ijk->ik", gm, d / dist[:, :, None] ** 3)


@pytest.mark.parametrize("n_massless", [0, 3])  # two paths: all massive, or with test particles
@pytest.mark.parametrize(("n", "seed"), [(4, 0), (40, 0)] + [(7, k) for k in range(5)])
def test_kernel_against_direct_and_quaternion_form(n, seed, n_massless):
    # n = 4: the pair form; 7 and 40: the SIMD form (kernels.SIMD_FROM)
    s = random_system(n, seed, n_massless=n_massless)
    acc = s.accelerations()
    ref = direct_accelerations(s._r, s._gm)
    quat = accelerations_quaternion(s._r, s._gm)
    scale = np.einsum("j,ij->i", s._gm, 1.0 / np.where(
        np.eye(len(s)) > 0, np.inf, np.linalg.norm(s._r[None] - s._r[:, None], axis=2)) ** 2)
    # a sum of n terms, each a few roundings: a few ulp of the sum of magnitudes
    tol = 8 * len(s) * EPS * scale[:, None]
    assert np.all(np.abs(acc - ref) <= tol)
    assert np.all(np.abs(acc - quat) <= tol)


def pair_form(r: np.ndarray, gm: np.ndarray) -> np.ndarray:
    """Equation (B) in Python floats with the additions of the pair form, in its
    order: massive pairs once (``i < j``, body i's sum carried on from the pairs
    before it), each test particle over the massive bodies from zero."""
    acc = np.zeros_like(r)
    massive = [k for k in range(len(gm)) if gm[k] != 0.0]
    for a, i in enumerate(massive):
        s = [float(acc[i, c]) for c in range(3)]
        for j in massive[a + 1:]:
            d = [float(r[j, c]) - float(r[i, c]) for c in range(3)]
            d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
            inv3 = 1.0 / (d2 * math.sqrt(d2))
            fi, fj = float(gm[j]) * inv3, float(gm[i]) * inv3
            for c in range(3):
                s[c] += fi * d[c]
                acc[j, c] -= fj * d[c]
        acc[i] = s
    for k in (k for k in range(len(gm)) if gm[k] == 0.0):
        s = [0.0, 0.0, 0.0]
        for i in massive:
            d = [float(r[i, c]) - float(r[k, c]) for c in range(3)]
            d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
            f = float(gm[i]) / (d2 * math.sqrt(d2))
            for c in range(3):
                s[c] += f * d[c]
        acc[k] = s
    return acc


@pytest.mark.parametrize(("n_massive", "n_test"), [
    (2, 0), (5, 0), (6, 0), (9, 0), (10, 0), (17, 0), (40, 0),  # 9, 17: one body by itself
    (kernels.STACK_MASSIVE + 2, 0),  # heap work space
    (3, 2 * kernels.BLOCK + 5), (9, kernels.BLOCK + 1), (kernels.STACK_MASSIVE + 2, 40)])
def test_simd_form_is_the_pair_form_to_the_bit(n_massive, n_test):
    """The SIMD form (every pair twice, vectorised over the bodies that receive)
    adds the pair form's terms in the pair form's order: the same bits, for the
    massive bodies and the test particles (blocks of ``kernels.BLOCK``), with
    the test particles anywhere among the massive bodies."""
    s = random_system(n_massive, n_massive + n_test, n_massless=n_test)
    order = np.random.default_rng(n_test).permutation(len(s))
    r, gm = s._r[order].copy(), s._gm[order].copy()
    want = pair_form(r, gm)
    acc = np.full_like(r, np.nan)
    kernels.newtonian(r, np.zeros_like(r), gm, acc)
    np.testing.assert_array_equal(acc, want)
    # the stepper's entries: rows from ``first`` on, and the kick u += h a
    idx = np.flatnonzero(gm[1:]).astype(np.int64) + 1
    rows = np.full_like(r, np.nan)
    kernels.newtonian_rows(r, gm, idx, 1, rows)
    np.testing.assert_array_equal(rows[1:], pair_form(r[1:], gm[1:]))
    u = np.ones_like(r)
    kernels.kick_rows(r, gm, idx, 1, 0.25, u, np.empty((len(idx), 3)))
    np.testing.assert_array_equal(u[1:], 1.0 + 0.25 * pair_form(r[1:], gm[1:]))
    assert np.all(u[0] == 1.0)


def test_quaternion_form_squares_vectors_to_minus_their_length():
    # Hamilton: (alpha - alpha')^2 = -T^2; a single pair at distance 2 on x
    acc = accelerations_quaternion([[0.0, 0, 0], [2.0, 0, 0]], [3.0, 5.0])
    np.testing.assert_array_equal(acc, [[5.0 / 4, 0, 0], [-3.0 / 4, 0, 0]])


def test_against_rebound_accelerations():
    s = System.solar_system("J2000")
    ours = s.accelerations().to_value(u.au / u.day**2)
    theirs = rebound_accelerations(s)
    scale = np.abs(theirs).max(axis=1, keepdims=True)
    assert np.all(np.abs(ours - theirs) <= 16 * EPS * scale)


def test_massless_particles_cost_nothing_to_the_massive():
    s = random_system(4, 1)
    t = random_system(4, 1, n_massless=50)
    np.testing.assert_array_equal(s.accelerations(), t.accelerations()[:4])


def test_rebound_round_trip_bit_for_bit():
    s = System.solar_system("J2000", bodies=["sun", "earth", "moon", "jupiter"])
    back = System.from_rebound(s.to_rebound(), quantity=True)
    assert back.names == s.names
    np.testing.assert_array_equal(back._r, s._r)
    np.testing.assert_array_equal(back._v, s._v)
    np.testing.assert_array_equal(back._gm, s._gm)
    f = random_system(3, 2, n_massless=2)
    back = from_rebound(to_rebound(f))
    np.testing.assert_array_equal(back._r, f._r)
    np.testing.assert_array_equal(back._v, f._v)
    np.testing.assert_array_equal(back._gm, f._gm)


def test_from_rebound_keeps_its_g_and_radii():
    """A rebound simulation in au, yr and solar masses (G = 4 pi^2): the System's
    energy and angular momentum were G times rebound's (``gm / G`` with G = 1), and
    the particles' radii (a collision's set-up) were dropped."""
    import rebound

    sim = rebound.Simulation()
    sim.G = 4 * np.pi**2
    sim.add(m=1.0, r=0.005)
    sim.add(m=9.5e-4, a=5.2, e=0.05, inc=0.02, r=0.0005)
    sim.add(m=1e-9, a=1.3, e=0.3)  # (no radius: 0 in rebound)
    s = System.from_rebound(sim)
    assert s.G == sim.G
    assert s.energy() == pytest.approx(sim.energy(), rel=1e-14)
    np.testing.assert_allclose(s.angular_momentum(), sim.angular_momentum(), rtol=1e-14)
    np.testing.assert_array_equal(s.as_arrays().radius, [0.005, 0.0005, np.nan])
    back = s.to_rebound()  # (G = 1, m = gm: the same radii)
    assert [p.r for p in back.particles] == [0.005, 0.0005, 0.0]


def test_to_rebound_keeps_a_plain_float_g():
    """A plain-float system of G = 2 went to rebound as G = 1, m = gm: the round trip
    gave G = 1 and rebound's energy and angular momentum were twice the system's.
    rebound is given the system's G and m = gm / G: the round trip keeps G (and gm
    bit for bit for a power of 2, to 1 ulp otherwise), rebound's integrals are the
    system's, its accelerations ours, and its orbit of a pair the circular one."""
    for g in (2.0, 3.7):
        gm = np.array([g, 1e-3 * g])  # (masses 1 and 1e-3)
        a = System([Body("a", gm[0], [0, 0, 0], [0, 0, 0]),
                    Body("b", gm[1], [1, 0, 0], [0, math.sqrt(gm.sum()), 0], radius=0.1)],
                   G=g)
        sim = a.to_rebound()
        assert sim.G == g
        assert sim.energy() == pytest.approx(a.energy(), rel=1e-14)
        np.testing.assert_allclose(sim.angular_momentum(), a.angular_momentum(), rtol=1e-14)
        back = from_rebound(sim)
        assert back.G == g and back.names == a.names
        np.testing.assert_array_equal(back._r, a._r)
        np.testing.assert_array_equal(back._v, a._v)
        np.testing.assert_array_equal(back.as_arrays().radius, [np.nan, 0.1])
        if g == 2.0:
            np.testing.assert_array_equal(back._gm, a._gm)
        else:
            np.testing.assert_allclose(back._gm, a._gm, rtol=EPS, atol=0)
        assert back.energy() == pytest.approx(a.energy(), rel=1e-15)
        scale = np.abs(a.accelerations()).max()
        assert np.abs(rebound_accelerations(a) - a.accelerations()).max() <= 4 * EPS * scale
        # rebound integrates the same pair: the circular orbit of mean motion sqrt(sum gm)
        sim.integrator = "ias15"
        sim.integrate(1.0, exact_finish_time=1)
        rel = np.array(sim.particles[1].xyz) - np.array(sim.particles[0].xyz)
        n = math.sqrt(gm.sum())
        np.testing.assert_allclose(rel, [math.cos(n), math.sin(n), 0.0], rtol=0, atol=1e-13)


def _with_test_particles(kind: int, m_test: float):
    import rebound

    sim = rebound.Simulation()
    sim.add(m=1.0, name="sun")
    sim.add(m=1e-3, a=1.0, name="planet")
    sim.add(m=m_test, a=1.3, name="tp1")
    sim.add(m=m_test, a=1.6, f=2.0, name="tp2")
    sim.add(m=0.0, a=2.0, f=1.0, name="dust")
    sim.N_active, sim.testparticle_type = 2, kind
    return sim


@pytest.mark.parametrize(("kind", "match"), [
    (0, "with testparticle_type = 0 rebound lets them pull on nothing: set their m to 0 "
        "for rebound's physics (massless bodies), or sim.N_active = -1 to make them full "
        "bodies"),
    (1, "with testparticle_type = 1 rebound lets them pull on the active bodies but not on "
        "each other: for rebound's physics set sim.N_active = -1 and integrate with "
        "effects=[{'name': 'semi_active', 'bodies': ['tp1', 'tp2', 'dust']}]"),
], ids=["type0", "type1"])
def test_from_rebound_refuses_massive_test_particles(kind, match):
    """rebound's particles beyond N_active that carry mass (its massive test
    particles: type 0 pull on nothing, type 1 on the active bodies alone) were read
    as full bodies, pulling on each other and on every body: other physics than
    rebound's, unsaid.  They are refused, naming the particle, its mass and what
    reproduces rebound's rule; massless ones are read as massless bodies."""
    import re

    sim = _with_test_particles(kind, 1e-2)
    head = ("Expected `sim`'s particles beyond N_active = 2 (rebound's test particles) to "
            "be massless, got m = 0.01 for particle 2 ('tp1') and 1 more: ")
    for read in (System.from_rebound, from_rebound):
        with pytest.raises(ValueError, match=re.escape(head + match)):
            read(sim)
    with pytest.raises(ValueError, match=r"for particle 2 \('x2'\)"):
        System.from_rebound(sim, names=["x0", "x1", "x2", "x3", "x4"])
    s = System.from_rebound(_with_test_particles(kind, 0.0))  # (massless: accepted)
    assert s.gm.tolist() == [1.0, 1e-3, 0.0, 0.0, 0.0]
    sim.N_active = -1  # (every particle active: full bodies, as asked)
    assert System.from_rebound(sim).gm.tolist() == [1.0, 1e-3, 1e-2, 1e-2, 0.0]


def test_from_rebound_refuses_a_negative_radius():
    """A rebound particle of radius r = -0.1 was read as no radius (rebound's 0),
    unsaid; it is refused, naming the particle and the value (0 is still none)."""
    import rebound

    sim = rebound.Simulation()
    sim.add(m=1.0, r=0.01, name="sun")
    sim.add(m=1e-3, a=1.0, r=-0.1, name="p")
    sim.add(m=0.0, a=2.0)
    with pytest.raises(ValueError, match=r"^Expected `sim`'s particles to have a radius "
                                         r"r >= 0 \(0 for none\), got r = -0\.1 for "
                                         r"particle 1 \('p'\)$"):
        System.from_rebound(sim)
    sim.particles[1].r = 0.0
    np.testing.assert_array_equal(System.from_rebound(sim).as_arrays().radius,
                                  [0.01, np.nan, np.nan])


def test_no_body_is_not_called_massless_bodies():
    """``System.from_arrays`` with no body said "got only massless bodies"."""
    with pytest.raises(ValueError, match=r"^Expected `gm`, `r` and `v` to hold at least one "
                                         r"body, got none \(shape \(0,\)\)$"):
        System.from_arrays(np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)))
    s = random_system(2, 1)
    with pytest.raises(ValueError, match=r"^Expected `keep` to keep at least one body, got "
                                         r"2 False$"):
        s.with_state(s.r, s.v, keep=np.array([False, False]))


def test_from_rebound_of_an_empty_simulation_names_sim():
    """A rebound simulation with no particle blamed ``bodies``, an argument the caller
    never gave: the message names ``sim``, through both front doors."""
    import rebound

    for read in (System.from_rebound, from_rebound):
        with pytest.raises(ValueError, match=r"`sim` to hold at least one particle"):
            read(rebound.Simulation())


def test_solar_system_cites_the_sun_gm_it_uses():
    """``System.solar_system``'s docstring called the Sun's GM the IAU 2015 nominal
    solar mass parameter (1.3271244e20 m^3/s^2 exactly), while the code holds DE440's
    (132712440041.279419 km^3/s^2, Park et al. 2021; the header of the DE440 kernel)
    to 12 digits; the docstring now cites DE440 for it and gives the number used."""
    de440 = 132712440041.279419e9  # m^3/s^2
    assert SOLAR_SYSTEM_GM["sun"] == float(f"{de440:.11e}") == 1.32712440041e20
    doc = " ".join(System.solar_system.__doc__.split())
    gm = doc[doc.index("GM values"):doc.index("Parameters")]
    assert "DE440" in gm and "Park et al. 2021" in gm
    assert "132712440041.279419 km^3/s^2" in gm and "1.32712440041e20 m^3/s^2" in gm
    assert "the Sun's is the IAU 2015 nominal" not in doc
    assert "Mamajek" not in doc  # (no longer cited for a value not used)


def test_solar_system_gms_are_the_shipped_de440_constants():
    """Each GM of SOLAR_SYSTEM_GM is DE440's (Park et al. 2021, AJ 161, 105), as
    shipped (data/de440.npz), to the digits it is written with (at most 1e-10
    apart).  The Earth-Moon barycentre's was 4.03503235502e14, DE430's GMB: 3.1e-10
    below DE440's 4.035032356255e14, which the table's own Earth + Moon give."""
    from hamilton_orbits import ephemeris as de

    si = (de.constant("AU") * 1e3) ** 3 / 86400.0**2  # (au^3/day^2 in m^3/s^2)
    keys = {"sun": "GMS", "mercury": "GM1", "venus": "GM2", "earth-moon-barycenter": "GMB",
            "mars": "GM4", "jupiter": "GM5", "saturn": "GM6", "uranus": "GM7",
            "neptune": "GM8"}
    for name, key in keys.items():
        assert SOLAR_SYSTEM_GM[name] == pytest.approx(de.constant(key) * si, rel=1e-10), name
    for name in ("earth", "moon"):
        assert SOLAR_SYSTEM_GM[name] == pytest.approx(de.gm(name) * si, rel=1e-10), name
    assert SOLAR_SYSTEM_GM["earth-moon-barycenter"] == pytest.approx(
        SOLAR_SYSTEM_GM["earth"] + SOLAR_SYSTEM_GM["moon"], rel=1e-12)


def test_solar_system_offline_and_cited_gm():
    s = System.solar_system("J2000")
    assert s.names == ("sun", "mercury", "venus", "earth-moon-barycenter", "mars",
                       "jupiter", "saturn", "uranus", "neptune")
    # DE440's solar GM to 12 digits
    assert s["sun"].gm.to_value(u.m**3 / u.s**2) == pytest.approx(1.32712440041e20, rel=1e-15)
    # Earth-Moon distance at J2000 from the built-in ephemeris: the Moon is 402,000 km away
    em = System.solar_system("J2000", bodies=["sun", "earth", "moon"])
    d = np.linalg.norm((em.r[2] - em.r[1]).to_value(u.km))
    assert 356_000 < d < 407_000
    # Earth + Moon GM equals the Earth-Moon system GM of DE440 (Park et al. 2021)
    total = SOLAR_SYSTEM_GM["earth"] + SOLAR_SYSTEM_GM["moon"]
    assert total == pytest.approx(SOLAR_SYSTEM_GM["earth-moon-barycenter"], rel=1e-9)
    # Earth's barycentric speed ~ 29.8 km/s
    speed = np.linalg.norm(s["earth-moon-barycenter"].v.to_value(u.km / u.s))
    assert 29.0 < speed < 30.5


def test_hamilton_integrals_of_a_known_pair():
    # two unit masses at distance 1, at rest: E = -G m m / r = -1, L = 0, centre at 0.5
    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 1.0, [1.0, 0, 0], [0, 0, 0])])
    assert s.energy() == -1.0
    np.testing.assert_array_equal(s.angular_momentum(), [0, 0, 0])
    np.testing.assert_array_equal(s.barycentre()[0], [0.5, 0, 0])


def test_quantity_system_units():
    s = System.solar_system("J2000")
    assert s.r.unit == u.au and s.v.unit == u.au / u.day
    assert s.energy().unit == u.J
    assert s.angular_momentum().unit == u.kg * u.m**2 / u.s
    # The solar system's energy is about -2e35 J (dominated by Jupiter: -G M m / 2a)
    assert -1e36 < s.energy().to_value(u.J) < -1e35


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: Body("p", gm=-1.0, r=[1, 0, 0], v=[0, 1, 0]), r"Body 'p'.*gm.*-1.0"),
        (lambda: Body("p", gm=1.0, r=[np.nan, 0, 0], v=[0, 1, 0]), r"Body 'p'.*`r`.*nan"),
        (lambda: Body("p", gm=1.0, r=[1, 0], v=[0, 1, 0]), r"Body 'p'.*`r`.*shape"),
        (lambda: Body("p", gm=1.0 * u.m, r=[1, 0, 0] * u.au, v=[0, 1, 0] * u.km / u.s),
         r"gm"),
        (lambda: System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]),
                         Body("a", 1.0, [1, 0, 0], [0, 0, 0])]), r"Duplicate body name 'a'"),
        (lambda: System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]),
                         Body("b", 0.0, [0, 0, 0], [0, 1, 0])]), r"'a' and 'b'.*one position"),
        (lambda: System([]), r"bodies"),
        (lambda: System([Body("a", 0.0, [0, 0, 0], [0, 0, 0])]), r"gm"),
        (lambda: System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])["b"], r"No body named 'b'"),
        (lambda: System.solar_system("J2000", bodies=["sun", "pluto"]), r"'pluto'"),
        # issue 32, class 6: an infinite radius and a negative gm were accepted
        (lambda: System.from_arrays([1.0, 0.0], [[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]],
                                    radius=[np.inf, 0.1]),
         r"^Expected `radius` to be finite, got inf at index 0$"),
        (lambda: System.from_arrays([1.0, 0.0], [[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]],
                                    radius=[np.nan, -np.inf]), r"`radius`.*-inf at index 1"),
        (lambda: _pair().with_state(_pair().as_arrays().r, _pair().as_arrays().v, gm=[-1, 1e-3]),
         r"^Expected `gm` >= 0, got -1.0 at index 0$"),
        (lambda: _pair().with_state(_pair().as_arrays().r, _pair().as_arrays().v,
                                    gm=[1.0, np.nan]),
         r"^Expected `gm` to be finite, got nan at index 1$"),
        (lambda: _pair().with_state(_pair().as_arrays().r, _pair().as_arrays().v, gm=[0.0, 0.0]),
         r"^Expected at least one body with `gm` > 0, got only massless bodies$"),
        (lambda: _pair().with_state(_pair().as_arrays().r, _pair().as_arrays().v, gm=[1.0]),
         r"^Expected `gm` to have shape \(2,\), got \(1,\)$"),
    ],
)
def test_bad_input_names_the_body_and_value(make, match):
    with pytest.raises((ValueError, u.UnitConversionError), match=match):
        make()


def _pair() -> System:
    return System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 1e-3, [1, 0, 0], [0, 1, 0])])


def test_with_state_takes_new_masses():
    s = _pair().with_state(_pair().as_arrays().r, _pair().as_arrays().v, gm=[2.0, 0.0])
    assert s.as_arrays().gm.tolist() == [2.0, 0.0]


def test_with_state_converts_quantities_and_checks_radius_and_keep():
    """A Quantity in other units lost its unit (1 au given in km stored as 1.5e8
    au); a negative radius was taken; a ``keep`` of the wrong length raised numpy's
    bare IndexError."""
    q = System.from_arrays([1.0, 1e-3] * u.au**3 / u.day**2, [[0, 0, 0], [1, 0, 0]] * u.au,
                           [[0, 0, 0], [0, 1, 0]] * u.au / u.day)
    moved = q.with_state(q.r.to(u.km), q.v.to(u.km / u.s))
    np.testing.assert_allclose(moved.as_arrays().r, q.as_arrays().r, rtol=1e-15, atol=0)
    np.testing.assert_allclose(moved.as_arrays().v, q.as_arrays().v, rtol=1e-15, atol=0)
    with pytest.raises(u.UnitConversionError, match="`r` to be a length"):
        q.with_state(q.r.value * u.s, q.v)
    plain = _pair()
    r, v = plain.as_arrays().r, plain.as_arrays().v
    with pytest.raises(ValueError, match=r"`r` as plain numbers in this system's own units"):
        plain.with_state(r * u.au, v)
    with pytest.raises(ValueError, match=r"Expected `radius` > 0, got -5.0 at index 1"):
        plain.with_state(r, v, radius=[1.0, -5.0])
    with pytest.raises(ValueError, match=r"Expected `keep` to have shape \(2,\), got \(3,\)"):
        plain.with_state(r, v, keep=[True, False, True])
    assert plain.with_state(r, v, radius=[np.nan, 0.1]).names == plain.names


def test_with_state_refuses_what_from_arrays_refuses():
    """A list of Quantities was read as bare numbers in au and au/day (13 km/s as 13
    au/day); bools, text and masked values were taken, a radius of 0 as well: each
    is refused by name, as System.from_arrays and Body refuse it."""
    q = System.from_arrays([1.0, 1e-3] * u.au**3 / u.day**2, [[0, 0, 0], [5, 0, 0]] * u.au,
                           [[0, 0, 0], [0, 0.0075, 0]] * u.au / u.day)
    r, v = q.r, q.v
    kms = [[0, 0, 0] * u.km / u.s, [0, 13, 0] * u.km / u.s]
    with pytest.raises(ValueError, match=r"`v` to be plain numbers or one Quantity array, "
                                         r"got the Quantity \[0. 0. 0.\] km / s at index 0"):
        q.with_state(r, kms)
    assert q.with_state(r, u.Quantity(kms)).v[1, 1].to_value(u.km / u.s) == pytest.approx(
        13.0, rel=1e-15)
    with pytest.raises(ValueError, match=r"`gm` to be numeric, got True at index 0"):
        q.with_state(r, v, gm=[True, False])
    with pytest.raises(ValueError, match=r"`gm` to be numbers, got a masked value at index 1"):
        q.with_state(r, v, gm=np.ma.array([1.0, 5.0], mask=[False, True]))
    with pytest.raises(ValueError, match=r"`r` to be numeric"):
        q.with_state([["1", "0", "0"], ["5", "0", "0"]], v)
    with pytest.raises(ValueError, match=r"`radius` > 0, got 0.0 at index 0"):
        q.with_state(r, v, radius=[0.0, np.nan])
    # plain numbers are the internal units, as before
    same = q.with_state(r.to_value(u.au), v.to_value(u.au / u.day))
    np.testing.assert_array_equal(same.as_arrays().v, q.as_arrays().v)


def test_one_string_is_not_the_names_of_many_bodies():
    # its letters were the names: ('s', 'u', 'n')
    with pytest.raises(ValueError, match=r"`names` to be 3 non-empty strings, got the one "
                                         r"string 'sun'"):
        System.from_arrays([1.0, 0.0, 0.0], np.eye(3), np.zeros((3, 3)), names="sun")
    assert System.from_arrays([1.0], [[0, 0, 0]], [[0, 0, 0]], names=["sun"]).names == ("sun",)


@pytest.mark.parametrize(("scale_gm", "scale_r", "scale_v", "what"), [
    (1e300, 1e300, 1e300, "energy"), (1.0, 1.0, 1e300, "energy"),
    (1.0, 1e200, 1e200, "angular momentum")])
def test_integrals_beyond_float64_are_refused_without_warnings(scale_gm, scale_r, scale_v,
                                                               what):
    """A state whose energy or angular momentum overflows gave nan or inf, with
    numpy's overflow warnings; it is a ValueError saying which."""
    import warnings

    gm = np.array([1.0, 1e-3, 1e-6])
    r = np.array([[0, 0, 0], [1.0, 0, 0], [0, 2.0, 0]])
    v = np.array([[0, 0, 0], [0, 1.0, 0], [-0.7, 0, 0]])
    s = System.from_arrays(gm * scale_gm, r * scale_r, v * scale_v)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=f"a state whose {what} is within float64"):
            s.energy() if what == "energy" else s.angular_momentum()
    assert np.isfinite(_pair().energy()) and np.all(np.isfinite(_pair().angular_momentum()))


def test_two_massless_particles_may_share_a_position():
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 0.0, [1, 0, 0], [0, 1, 0]), Body("q", 0.0, [1, 0, 0], [0, 1.1, 0])])
    assert np.all(np.isfinite(s.accelerations()))


def test_repr_of_a_thousand_bodies_is_one_short_line():
    from hamilton_orbits import Body, System

    bodies = [Body("sun", 1.0, [0, 0, 0], [0, 0, 0])] + [
        Body(f"p{i}", 0.0, [1 + 0.01 * i, 0, 0], [0, 1, 0]) for i in range(999)]
    text = repr(System(bodies))
    assert len(text) < 120 and "\n" not in text and "(1000 bodies)" in text, text
    assert repr(System(bodies[:2])) == "System(['sun', 'p0'])"  # a few bodies: all named


def test_from_rebound_with_quantities_refuses_other_units():
    """A rebound simulation in years (``sim.units = ("yr", "AU", "Msun")``, G = 4 pi^2)
    read with ``quantity=True`` took its speeds in au/yr as au/day and G m as
    au^3/day^2: the Earth at 10 879 km/s, making 365 orbits a year, unsaid.  Other
    units are refused, naming G and the units; au and days (G = 1 with G m as
    masses, as ``to_rebound`` writes, or rebound's ("day", "AU", "Msun")) are read."""
    import astropy.units as u
    import rebound

    for units, ok in ((("yr", "AU", "Msun"), False), (("s", "m", "kg"), False),
                      (("day", "AU", "Msun"), True), (("days", "AU", "Msun"), True),
                      (("d", "aus", "sunmass"), True)):  # (rebound's names for them)
        sim = rebound.Simulation()
        sim.units = units
        m_sun = 1.989e30 if units[2] == "kg" else 1.0
        sim.add(m=m_sun)
        sim.add(m=3e-6 * m_sun, a=1.496e11 if units[1] == "m" else 1.0)
        if ok:
            earth = System.from_rebound(sim, quantity=True)["body1"]
            assert abs(earth.v.to_value(u.km / u.s) @ [0, 1, 0] - 29.8) < 0.1
        else:
            with pytest.raises(ValueError, match=r"Expected `sim` in au and days .*got G = "):
                System.from_rebound(sim, quantity=True)
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    back = System.from_rebound(s.to_rebound(), quantity=True)  # (G = 1, no units: read)
    assert back.names == ("sun", "p")


def test_with_state_refuses_indices_for_keep_and_names_a_bad_state():
    """``with_state(..., keep=np.array([0, 1]))`` read the indices as booleans and kept
    the second body only; ``with_state("x", v)`` said "could not convert string to
    float", not naming `r`."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("earth", 3e-6, [1, 0, 0], [0, 1, 0])])
    with pytest.raises(ValueError, match=r"Expected `keep` to be 2 booleans \(True for a body "
                                         r"kept\), got \[0, 1\]"):
        s.with_state(s.r, s.v, keep=np.array([0, 1]))
    assert s.with_state(s.r, s.v, keep=[True, False]).names == ("sun",)
    with pytest.raises(ValueError, match=r"Expected `r` to be numeric, got 'x'"):
        s.with_state("x", s.v)


def test_accelerations_take_the_time_as_the_system_does():
    """``System.accelerations(t=...)`` on a system of plain floats took a time Quantity
    or a TimeDelta and silently read it in seconds (``t = 1 * u.day`` was 86400 of the
    system's own unit, which ``integrate`` refuses to guess); it is refused now, by
    name.  On a Quantity system a TimeDelta is the Quantity in days it holds, and an
    array of times (a TypeError, "only 0-dimensional arrays...") is refused as a
    ValueError naming `t` and its shape."""
    from astropy.time import TimeDelta

    plain = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                    Body("dust", 0.0, [2.0, 0, 0], [0, 0.7, 0])])
    assert np.array_equal(plain.accelerations(t=3.0), plain.accelerations())
    for t in (1.0 * u.day, TimeDelta(1.0, format="jd"), 0.0 * u.s):
        with pytest.raises(ValueError, match=r"Expected `t` as a plain float for a system "
                                             r"of plain floats .*got <(Quantity|TimeDelta)"):
            plain.accelerations(t=t)
    s = System.solar_system("J2000", bodies=["sun", "mars"])
    days = s.accelerations(["gr"], t=2.5 * u.day)
    assert np.array_equal(s.accelerations(["gr"], t=TimeDelta(2.5, format="jd")), days)
    assert np.array_equal(s.accelerations(["gr"], t=60.0 * u.h), days)
    assert np.array_equal(s.accelerations(["gr"], t=0), s.accelerations(["gr"]))
    for t, message in (([1.0, 2.0] * u.day, r"Expected `t` to be one number, got shape \(2,\)"),
                       (TimeDelta([1.0], format="jd"),
                        r"Expected `t` to be one number, got shape \(1,\)"),
                       (1.5, r"Expected `t` as a time Quantity for a system of Quantities, "
                             r"got 1.5"),
                       (1.0 * u.m, r"Expected `t` to be a time \(convertible to d\), got 1 m")):
        with pytest.raises(ValueError, match=message):
            s.accelerations(t=t)
