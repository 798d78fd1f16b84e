"""Effects: registry, composition, GR perihelion advance, J2 nodal regression, reboundx."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, KeplerOrbit, System, integrate
from hamilton_orbits import effects as fx
from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels import nbody as kernels
from hamilton_orbits.rebound_bridge import run_rebound
from hamilton_orbits.rhs import compile_rhs

ARCSEC = np.pi / (180 * 3600)


def perihelion_longitude(r: np.ndarray, v: np.ndarray, gm: float) -> np.ndarray:
    """Angle of the eccentricity vector in the initial orbital plane, unwrapped."""
    h = np.cross(r, v)
    ev = np.cross(v, h) / gm - r / np.linalg.norm(r, axis=1)[:, None]
    e0 = ev[0] / np.linalg.norm(ev[0])
    q = np.cross(h[0] / np.linalg.norm(h[0]), e0)
    return np.unwrap(np.arctan2(ev @ q, ev @ e0))


def test_no_effect_is_the_newtonian_kernel_itself():
    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
    rhs = compile_rhs(s, ())
    assert rhs.accel is kernels.newtonian_only and rhs.extra is None
    assert rhs.effects == ("newtonian",)
    # listing "newtonian" changes nothing
    assert compile_rhs(s, ["newtonian"]).accel is kernels.newtonian_only


def test_unknown_effect_lists_the_known_ones():
    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
    msg = r"'grr'.*did you mean 'gr'.*known: .*gr, gr_potential, j2"
    with pytest.raises(ValueError, match=msg):
        compile_rhs(s, ["grr"])


@pytest.mark.parametrize(
    ("effects", "match"),
    [
        ([{"name": "j2", "body": "mars"}], r"'mars'.*not in the system"),
        ([{"name": "j2"}], r"needs the `body`"),
        ([{"name": "gr", "src": "sun"}], r"`src`: unknown parameter of effect 'gr'"),
        (["gr", "gr"], r"listed twice"),
        ([3], r"index 0"),
        (["gr"], r"speed of light `c`"),
    ],
)
def test_bad_effects(effects, match):
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 0.0, [1, 0, 0], [0, 1, 0])])
    with pytest.raises(ValueError, match=match):
        compile_rhs(s, effects)


def test_velocity_dependent_effect_refused_by_symplectic_map():
    s = System.solar_system("J2000", bodies=["sun", "mercury"])
    msg = r"'gr' depends on velocities.*'leapfrog'.*accept it:.*dop853"
    with pytest.raises(ValueError, match=msg):
        integrate(s, 1 * u.day, method="leapfrog", dt=0.1 * u.day, effects=["gr"])
    # the potential form is accepted
    traj = integrate(s, 1 * u.day, method="leapfrog", dt=0.1 * u.day, effects=["gr_potential"])
    assert traj.effects == ("newtonian", "gr_potential")


def test_gr_mercury_perihelion_advance():
    """42.98 arcsec per century (REFERENCES.md; 6 pi GM / (c^2 a (1 - e^2)) per orbit).

    Sun and Mercury from the built-in ephemeris at J2000, 10 years, the longitude of
    perihelion from the simulated heliocentric state, a straight-line fit.  The
    tolerance 0.1 arcsec/cy is the issue's; the short-period oscillation of the
    osculating perihelion (~ GM/(c^2 a) ~ 0.005 arcsec) averages out in the fit.
    """
    s = System.solar_system("J2000", bodies=["sun", "mercury"])
    t = np.linspace(0.0, 10 * 365.25, 1001) * u.day
    traj = integrate(s, t, method="dop853", tol=1e-13, effects=["gr"])
    r = traj.r.to_value(u.au)
    v = traj.v.to_value(u.au / u.day)
    ang = perihelion_longitude(r[:, 1] - r[:, 0], v[:, 1] - v[:, 0], float(s._gm.sum()))
    rate = np.polyfit(t.to_value(u.day), ang, 1)[0] * 36525 / ARCSEC
    assert rate == pytest.approx(42.98, abs=0.1)


def test_gr_against_reboundx():
    """Our 1PN correction against reboundx 'gr' on Sun + Mercury over 10 orbits.

    Both implement one dominant mass; they differ in how they treat the Sun's own
    motion, at order (m_mercury / m_sun) of the correction.  The position displacement
    that GR causes must agree to 1e-4 of itself.
    """
    pytest.importorskip("reboundx")
    s = System.solar_system("J2000", bodies=["sun", "mercury"])
    t_end = 880.0
    newton, _ = run_rebound(s, t_end)
    rebx, _ = run_rebound(s, t_end, effects=["gr"])
    ours = integrate(s, t_end * u.day, method="dop853", tol=1e-14, effects=["gr"])

    def rel(sim):
        return np.array(sim.particles[1].xyz) - np.array(sim.particles[0].xyz)

    r_ours = ours.r[-1, 1].to_value(u.au) - ours.r[-1, 0].to_value(u.au)
    shift = np.linalg.norm(rel(rebx) - rel(newton))
    assert shift > 3e-7  # the effect is there (6e-7 au after 10 orbits)
    assert np.linalg.norm(r_ours - rel(rebx)) < 1e-4 * shift


@pytest.mark.parametrize("effect", ["gr", "gr_potential"])
def test_the_cross_check_of_gr_does_not_depend_on_where_the_sun_is(effect):
    """reboundx takes particle 0 as GR's source whichever particle ``gr_source``
    marks: with the Sun listed last the cross-check compared our GR run with a
    Newtonian one, 3e-5 and 8e-5 apart (1e4 km) where the Sun first gives 4e-11
    and 9e-13.  rebound is given the source first; the table is in our order."""
    from hamilton_orbits import crosscheck

    pytest.importorskip("reboundx")
    first = System.solar_system("J2000", bodies=["sun", "mercury", "jupiter"])
    last = System.solar_system("J2000", bodies=["mercury", "jupiter", "sun"])
    a = crosscheck(first, 10 * u.yr, method="radau15", effects=[effect])
    b = crosscheck(last, 10 * u.yr, method="radau15", effects=[effect])
    assert b.names == ("mercury", "jupiter", "sun")
    # (the same integrations, rebound's given the same order and ours with the bodies
    # listed in another: its accelerations summed in another order, which changes the
    # last bits (1.3e-13 au over the 10 years on a host with AVX-512; equal on another
    # host): the rows of one table in another order, to 1e-12, where the source taken
    # wrongly put them 3e-5 apart)
    np.testing.assert_allclose(b.relative_position_difference,
                               a.relative_position_difference[[1, 2, 0]], rtol=0, atol=1e-12)
    assert b.relative_position_difference.max() < 1e-10


def test_the_cross_check_of_eih_runs_reboundx_gr_full():
    """``crosscheck`` refused ``eih`` ("no reboundx counterpart") though it is the
    n-body 1PN equation of reboundx's ``gr_full``: run beside it, with the same
    ``c``.  Sun, Mercury and Jupiter over a year: Mercury's 1PN shift (3.9e-7 au from
    Newton's law) agrees to 1e-12 au.  What ``gr_full`` cannot run (some massive body
    not a source, a semi-active body, beta or gamma other than 1) is refused by name."""
    from hamilton_orbits import crosscheck

    pytest.importorskip("reboundx")
    s = System.solar_system("J2000", bodies=["sun", "mercury", "jupiter"])
    table = crosscheck(s, 1 * u.yr, effects=["eih"])
    assert table.peer == "rebound ias15 + reboundx"
    assert table.position_difference.max() < 1e-12
    for effect, pattern in (({"sources": ["sun"]}, r"leave out `sources` \(it leaves out "
                                                    r"\['mercury', 'jupiter'\]\)"),
                            ({"semi_active": ["jupiter"]}, r"leave out `semi_active`"),
                            ({"gamma": 0.5}, r"leave `gamma` at 1, got 0.5")):
        with pytest.raises(ValueError, match=r"^Effect 'eih': reboundx's gr_full .*" + pattern):
            crosscheck(s, 1 * u.yr, effects=[{"name": "eih", **effect}])


def leo(inc_deg: float = 50.0, e: float = 0.001):
    gm, radius, j2 = 3.986004418e14, 6378136.6, 1.0826359e-3  # IERS Conventions 2010
    a = 7000e3
    orbit = KeplerOrbit.from_elements(a=a, e=e, inc=np.radians(inc_deg), lan=0.3, argp=0.2,
                                      nu=0.0, mu=gm)
    r0, v0 = orbit.state()
    s = System([Body("earth", gm, [0, 0, 0], [0, 0, 0], radius=radius, j2=j2),
                Body("sat", 0.0, r0, v0)])
    return s, gm, radius, j2, a, e, np.radians(inc_deg)


def test_j2_nodal_regression_first_order():
    """dOmega/dt = -3/2 n J2 (R/p)^2 cos i (Vallado 2013, eq. 9-41), within 1%.

    The first-order formula is for mean elements; starting from osculating ones
    shifts the rate by O(J2) ~ 1e-3, well inside the issue's 1%.
    """
    s, gm, radius, j2, a, e, inc = leo()
    n = np.sqrt(gm / a**3)
    t = np.linspace(0, 20 * 2 * np.pi / n, 1001)
    traj = integrate(s, t, method="dop853", tol=1e-12, effects=[{"name": "j2", "body": "earth"}])
    h = np.cross(traj.r[:, 1] - traj.r[:, 0], traj.v[:, 1] - traj.v[:, 0])
    node = np.unwrap(np.arctan2(h[:, 0], -h[:, 1]))
    rate = np.polyfit(t, node, 1)[0]
    expected = -1.5 * n * j2 * (radius / (a * (1 - e**2))) ** 2 * np.cos(inc)
    assert rate == pytest.approx(expected, rel=0.01)


def test_j2_against_reboundx_gravitational_harmonics():
    pytest.importorskip("reboundx")
    s, gm, _radius, _j2, a, _e, _inc = leo()
    t_end = 10 * 2 * np.pi * np.sqrt(a**3 / gm)
    newton, _ = run_rebound(s, t_end)
    rebx, _ = run_rebound(s, t_end, effects=[{"name": "j2", "body": "earth"}])
    ours = integrate(s, t_end, method="dop853", tol=1e-13,
                     effects=[{"name": "j2", "body": "earth"}])

    def rel(sim):
        return np.array(sim.particles[1].xyz) - np.array(sim.particles[0].xyz)

    shift = np.linalg.norm(rel(rebx) - rel(newton))
    assert shift > 1e5  # metres: the J2 displacement after 10 orbits
    # same force model: agreement at the integrators' accuracy, ~1e-12 of the orbit
    assert np.linalg.norm(ours.r[-1, 1] - ours.r[-1, 0] - rel(rebx)) < 1e-9 * a


def test_j2_of_the_earth_is_the_same_physics_in_ecliptic_axes():
    """``System.solar_system(frame="ecliptic")`` gave the Earth no pole (``from_ephemeris``
    gives one), so ``j2`` took the ecliptic's z axis for it, 23.4 degrees off: its pull
    on the Moon was 57 % away from the ICRS run's.  The Sun, the Earth and the Moon
    carry their poles in the system's axes; the J2 acceleration (the effect alone,
    ``rhs.extra``) in ecliptic axes is the ICRS one rotated by the IAU 2006 obliquity
    at J2000, 84381.406" (Hilton et al. 2006; IERS Conventions 2010, chapter 5), to
    1e-12."""
    effect = [{"name": "j2", "body": "earth", "j2": de.constant("J2E"),  # DE440's
               "radius": de.constant("RE") * u.km}]
    bodies = ["sun", "earth", "moon"]
    acc = {}
    for frame in ("icrs", "ecliptic"):
        s = System.solar_system("J2000", bodies=bodies, frame=frame)
        assert s["earth"].pole == tuple(de.pole("earth", frame))
        arrays = s.as_arrays()
        rhs = compile_rhs(s, effect)
        acc[frame] = np.zeros((3, 3))
        rhs.extra(arrays.r.copy(), arrays.v.copy(), arrays.gm.copy(), acc[frame], rhs.p)
    eps = np.deg2rad(84381.406 / 3600.0)
    to_ecliptic = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(eps), np.sin(eps)],
                            [0.0, -np.sin(eps), np.cos(eps)]])
    moon = acc["icrs"][2]
    assert np.linalg.norm(moon) > 1e-11  # au/day^2: the Earth's J2 on the Moon
    np.testing.assert_allclose(acc["ecliptic"], acc["icrs"] @ to_ecliptic.T, rtol=0,
                               atol=1e-12 * np.linalg.norm(moon))


def test_effect_with_momentum_conserving_reaction():
    """gr, gr_potential and j2 push the source back: total momentum is conserved."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0], radius=0.01, j2=0.1),
                Body("p", 1e-3, [1.0, 0.1, 0.2], [0, 1.0, 0.1]),
                Body("q", 2e-3, [-1.5, 0.3, -0.1], [0.1, -0.8, 0])])
    for eff in ([{"name": "gr_potential", "c": 50.0}], [{"name": "gr", "c": 50.0}],
                [{"name": "j2", "body": "sun"}]):
        rhs = compile_rhs(s, eff)
        arrays = s.as_arrays()
        acc = np.zeros((3, 3))
        rhs.extra(arrays.r.copy(), arrays.v.copy(), arrays.gm.copy(), acc, rhs.p)
        assert np.abs(acc).max() > 0
        total = arrays.gm @ acc
        assert np.all(np.abs(total) <= 4 * np.finfo(float).eps * (arrays.gm @ np.abs(acc)))


def test_registry_plugs_in_new_effects():
    spec = fx.register(fx.EffectSpec(
        "constant_push", "nbody", "a uniform acceleration (test)",
        parameters={"g": "acceleration along x"},
        kernel=_push,
        params=lambda system, params: np.array([params.get("g", 1.0)]),
    ))
    try:
        s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
        acc = s.accelerations([{"name": "constant_push", "g": 2.0}])
        np.testing.assert_allclose(acc[:, 0], [2.0, -1.0 + 2.0])
    finally:
        fx.registry._REGISTRY["nbody"].pop(spec.name)


from numba import njit  # noqa: E402


@njit
def _push(r, v, gm, acc, p):  # pragma: no cover - compiled
    for i in range(r.shape[0]):
        acc[i, 0] += p[0]


def test_each_built_in_effect_lives_in_its_own_module():
    """Issue 30: one effect in one place. Registered in a fixed order from
    ``effects.BUILT_IN``; each effect's spec, builder and energy are in the module
    named for it, and its kernel and Jacobian are imported there."""
    import importlib

    assert list(fx.registry._REGISTRY["nbody"])[:10] == [
        "newtonian", "gr", "gr_potential", "j2", "eih", "lense_thirring", "zonal",
        "moon_figure", "earth_tides", "kuiper_ring"]
    homes = {"newtonian": "newtonian", "gr": "relativity", "gr_potential": "relativity",
             "j2": "j2", "eih": "eih", "lense_thirring": "lense_thirring", "zonal": "zonal",
             "moon_figure": "moon_figure", "earth_tides": "tides", "kuiper_ring": "kuiper_ring"}
    for name, home in homes.items():
        module = importlib.import_module(f"hamilton_orbits.effects.{home}")
        spec = fx.get("nbody", name)
        assert spec in module.SPECS and spec in fx.BUILT_IN, name
        for part in (spec.params, spec.energy):
            assert part is None or part.__module__ == module.__name__, (name, part)
        for compiled in (spec.kernel, spec.jacobian):
            assert compiled is None or compiled.py_func.__name__ in vars(module), (name, compiled)


def test_the_old_solar_system_module_warns_and_gives_the_same_objects():
    import importlib

    from hamilton_orbits.effects import eih, kuiper_ring, lense_thirring, moon_figure, tides

    old = importlib.import_module("hamilton_orbits.effects_solar_system")
    moved = {"eih_energy": eih, "kuiper_ring_gm": kuiper_ring, "sun_spin": lense_thirring,
             "KUIPER_RING_RADIUS_AU": kuiper_ring, "EARTH_ROTATION_RATE": tides,
             "MOON_EQUATOR_INCLINATION_DEG": moon_figure}
    for name, module in moved.items():
        with pytest.warns(DeprecationWarning, match=rf"use {module.__name__}\.{name}"):
            assert getattr(old, name) is getattr(module, name)
    with pytest.warns(DeprecationWarning, match=r"BUILT_IN"):
        specs = old.SPECS
    assert [s["name"] for s in specs] == ["eih", "lense_thirring", "zonal", "moon_figure",
                                          "earth_tides", "kuiper_ring"]
    assert all(fx.EffectSpec(**s) == fx.get("nbody", s["name"]) for s in specs)
    with pytest.raises(AttributeError):
        old.nothing_here  # noqa: B018


def test_a_bad_parameter_names_the_effect_the_value_and_its_index():
    """Issue 32: a refusal names the argument (`effects`), the index and the value."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 0.0, [1, 0, 0], [0, 1, 0])])
    effects = [{"name": "gr", "c": 10.0}, {"name": "j2", "body": "sun", "j2": 1e-3,
                                           "radius": -0.1}]
    with pytest.raises(ValueError, match=re.escape(
            "Effect 'j2': expected `radius` > 0, got -0.1 (effects[1])")):
        integrate(s, 1.0, effects=effects)
    with pytest.raises(ValueError, match=re.escape(
            "Effect 'j2' needs the `body` whose oblateness acts, e.g. {'name': 'j2', 'body': "
            "'earth'} (effects[0])")):
        fx.EffectSet.of(["j2"]).parameters(s)
    # the index is the caller's, an explicit "newtonian" counted
    with pytest.raises(ValueError, match=re.escape("expected `c` > 0, got 0.0 (effects[2])")):
        integrate(s, 1.0, effects=["newtonian", {"name": "j2", "body": "sun", "j2": 1e-3,
                                                 "radius": 0.1}, {"name": "gr", "c": 0.0}])
    assert fx.EffectSet.of(["newtonian", "gr"]) == fx.EffectSet.of(["gr"])


def test_effects_that_exclude_each_other():
    """``EffectSpec.excludes``: listing both would count the same terms twice."""
    assert fx.get("nbody", "eih").excludes.keys() == {"gr", "gr_potential"}
    assert fx.exclusion_problems(["gr", "j2"]) == []
    assert [k for k, _ in fx.exclusion_problems(["gr_potential", "eih", "gr"])] == [1, 2, 2]
    fx.register(fx.EffectSpec("ex_a", "test-excl", "a", excludes={"ex_b": "b's terms"}))
    fx.register(fx.EffectSpec("ex_b", "test-excl", "b"))
    try:
        assert fx.exclusion_problems(["ex_b", "ex_a"], "test-excl") == [
            (1, "effect 'ex_b' (at index 0) is refused beside 'ex_a' (at index 1): 'ex_a' "
                "already computes b's terms, which would count twice; list one of them")]
        with pytest.raises(ValueError, match=r"^Effect 'ex_b' \(at index 0\) is refused"):
            fx.EffectSet.of(["ex_b", "ex_a"], "test-excl")
    finally:  # the registry is the process's: leave no kind behind for later tests
        fx.registry._REGISTRY.pop("test-excl", None)


def test_gr_and_gr_potential_are_refused_together():
    """``gr`` (the 1PN force of a dominant body) and ``gr_potential`` (a potential
    of the same perihelion advance) listed together counted Mercury's 43" a
    century twice (86"); refused, naming both and their indices."""
    assert fx.exclusion_problems(["gr", "j2"]) == []
    with pytest.raises(ValueError, match=r"^Effect 'gr_potential' \(at index 1\) is refused "
                                         r"beside 'gr' \(at index 0\): 'gr' already computes "
                                         r"the relativistic perihelion advance"):
        fx.EffectSet.of(["gr", "gr_potential"])
    with pytest.raises(ValueError, match=r"'gr_potential' \(at index 0\) is refused beside "
                                         r"'gr' \(at index 2\)"):
        fx.EffectSet.of(["gr_potential", "j2", "gr"])


def _earth_moon():
    return System.from_ephemeris("J2000", bodies=["sun", "earth", "moon"])


def test_j2_and_zonal_on_the_same_body_are_refused():
    """``j2`` on the Earth beside ``zonal`` (the Earth's J2, J3, J4 by default) applied
    the Earth's J2 twice: its pull on the Moon doubled (1.99998 times ``zonal``'s).
    Refused with the system, naming both effects, their indices and the body; ``j2``
    on another body, or ``zonal`` without its J2, is no double count."""
    s = _earth_moon()
    message = ("Effect 'j2' (at index 0) is refused beside 'zonal' (at index 1) on body "
               "'earth': 'zonal' already computes its body's J2 (the first of its `j`), "
               "which would count twice; list one of them, or put 'j2' on another body")
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        s.accelerations([{"name": "j2", "body": "earth"}, "zonal"])
    with pytest.raises(ValueError, match=r"^Effect 'j2' \(at index 2\) is refused beside "
                                         r"'zonal' \(at index 0\) on body 'earth'"):
        integrate(s, 1.0 * u.day, effects=["zonal", "gr", {"name": "j2", "body": "earth"}])
    # the Sun's J2 beside the Earth's zonal harmonics: two bodies, nothing twice
    s.accelerations([{"name": "j2", "body": "sun", "j2": 2.2e-7, "radius": 696000 * u.km},
                     "zonal"])
    # zonal's J2 set to zero, the J2 left to j2: nothing twice either
    j = [0.0, de.constant("J3E"), de.constant("J4E")]
    s.accelerations([{"name": "j2", "body": "earth"}, {"name": "zonal", "j": j}])


def test_j2_or_zonal_on_the_moon_beside_moon_figure_is_refused():
    """``moon_figure`` applies the Moon's J2 (J2M) itself: ``j2`` on the Moon (which
    ``System.from_ephemeris`` gives J2M) beside it counted it twice, and so would
    ``zonal`` on the Moon.  With ``moon_figure``'s ``j2`` zero (its C22 alone) the
    Moon's J2 is counted once."""
    s = _earth_moon()
    with pytest.raises(ValueError, match="^" + re.escape(
            "Effect 'j2' (at index 1) is refused beside 'moon_figure' (at index 0) on body "
            "'moon': 'moon_figure' already computes the Moon's J2 (its `j2`, DE440's J2M by "
            "default), which would count twice; list one of them, or put 'j2' on another "
            "body") + "$"):
        s.accelerations(["moon_figure", {"name": "j2", "body": "moon"}])
    moon_zonal = {"name": "zonal", "body": "moon", "j": [2.03e-4, 8.5e-6],
                  "radius": 1738.0 * u.km}
    with pytest.raises(ValueError, match=r"^Effect 'zonal' \(at index 0\) is refused beside "
                                         r"'moon_figure' \(at index 1\) on body 'moon'"):
        s.accelerations([moon_zonal, "moon_figure"])
    # a moon_figure named by its own `moon` parameter: the same body, another name
    renamed = System([b if b.name != "moon" else Body("luna", b.gm, b.r, b.v,
                                                      radius=b.radius, j2=b.j2, pole=b.pole)
                      for b in s.bodies])
    with pytest.raises(ValueError, match=r"on body 'luna'"):
        renamed.accelerations([{"name": "moon_figure", "moon": "luna"},
                               {"name": "j2", "body": "luna"}])
    # legitimate: the Moon's J2 once (moon_figure's C22 alone), the Earth's J2 beside it
    s.accelerations([{"name": "moon_figure", "j2": 0.0}, {"name": "j2", "body": "moon"}])
    s.accelerations(["moon_figure", {"name": "j2", "body": "earth"}, "earth_tides"])


def _massless(system, name):
    """``system`` with body ``name`` massless."""
    bodies = list(system.bodies)
    k = system.names.index(name)
    b = bodies[k]
    bodies[k] = Body(b.name, 0.0 * b.gm.unit, b.r, b.v, radius=b.radius, j2=b.j2, pole=b.pole)
    return System(bodies)


@pytest.mark.parametrize(("effect", "massless", "key"), [
    ({"name": "zonal"}, "earth", "body"),
    ({"name": "earth_tides"}, "earth", "earth"),
    ({"name": "moon_figure"}, "moon", "moon"),
    ({"name": "lense_thirring"}, "sun", "body"),
    ({"name": "kuiper_ring"}, "sun", "centre"),
])
def test_an_effect_whose_field_is_a_massless_bodys_is_refused(effect, massless, key):
    """These effects push back on their body by ``gm_i / gm_body``: a massless one
    failed at the first step (a non-finite acceleration, or a bare
    ZeroDivisionError), as ``gr`` and ``j2`` refuse it at setup."""
    with pytest.raises(ValueError, match=rf"`{key}` names body '{massless}', which is "
                                         r"massless"):
        compile_rhs(_massless(_earth_moon(), massless), [effect])


def test_a_massless_eih_source_is_refused_as_gr_refuses_it():
    """``eih`` took a massless body in `sources` and dropped its 1PN terms silently
    (``gr`` refused the same body as its `source`): refused, naming the argument, the
    index and the body."""
    with pytest.raises(ValueError, match=r"^Effect 'eih': `sources` names body 'moon' \(at "
                                         r"index 1\), which is massless \(gm = 0\)"):
        compile_rhs(_massless(_earth_moon(), "moon"),
                    [{"name": "eih", "sources": ["sun", "moon"]}])


@pytest.mark.parametrize(("effect", "key", "typo", "meant"), [
    ({"name": "gr"}, "source", "son", "sun"), ({"name": "j2"}, "body", "jupyter", "jupiter"),
    ({"name": "gr_potential"}, "source", "Sun", "sun")])
def test_a_misspelt_source_body_is_answered_with_the_closest_name(effect, key, typo, meant):
    """docs/effects.md: "the closest names are suggested"; ``gr``'s and ``j2``'s body
    named no suggestion, only every body (``nongrav`` and the DE440 effects did)."""
    system = System.solar_system("J2000", bodies=["sun", "jupiter"])
    with pytest.raises(ValueError, match=rf"`{key}` names body '{typo}', which is not in the "
                                         rf"system \(did you mean '{meant}'\?\); bodies: sun, "
                                         r"jupiter"):
        compile_rhs(system, [{**effect, key: typo}])


@pytest.mark.parametrize("effect", [
    {"name": "zonal", "frame": "galactic"},
    {"name": "earth_tides", "frame": "ICRS"},
    {"name": "kuiper_ring", "normal": [0, 0, 1], "frame": "galactic"},
    {"name": "lense_thirring", "spin": [0.0, 0.0, 1e-7] * u.au**2 / u.day, "frame": 42},
])
def test_a_wrong_frame_is_refused_where_it_is_not_used(effect):
    """A frame the effect's given directions make unused was taken silently."""
    with pytest.raises(ValueError, match=r"expected `frame` 'icrs' or 'ecliptic'"):
        compile_rhs(_earth_moon(), [effect])


@pytest.mark.parametrize(("effect", "pattern"), [
    ({"name": "semi_active", "bodies": ["sun", "earth", "moon"]}, r"lists every body"),
    ({"name": "eih", "semi_active": ["sun", "earth", "moon"]}, r"lists every body"),
    ({"name": "nongrav", "body": [], "A1": 1e-9 * u.au / u.day**2}, r"got an empty list"),
    ({"name": "zonal", "j": []}, r"at least J2, got an empty list"),
    ({"name": "gr", "c": True}, r"expected `c` to be a number, got True"),
])
def test_effects_that_would_do_nothing_or_misread_a_bool_are_refused(effect, pattern):
    """Every body semi-active turned gravity off (free flight); an empty list of
    bodies or harmonics was a silent no-op; ``c=True`` was read as c = 1."""
    with pytest.raises(ValueError, match=pattern):
        compile_rhs(_earth_moon(), [effect])


def test_an_epoch_given_as_a_time_is_saved_and_continued_to_the_bit(tmp_path):
    """docs/effects.md's own example, ``epoch=Time(...)``, could not be saved (a bare
    TypeError from JSON): the epoch is kept as its two-part Julian date, scale and
    format, and the simulation loaded goes on with the bits of the one saved."""
    from astropy.time import Time

    from hamilton_orbits import Simulation

    epoch = Time("1950-01-01", scale="tdb")
    sim = Simulation(_earth_moon(), effects=[{"name": "zonal", "pole": "IAU2006",
                                              "epoch": epoch}])
    sim.integrate(1 * u.day)
    sim.save(tmp_path / "sim.nc")
    again = Simulation.load(tmp_path / "sim.nc")
    kept = again.effects.as_list()[0]["epoch"]
    assert kept.scale == "tdb" and kept.jd1 == epoch.jd1 and kept.jd2 == epoch.jd2
    a, b = sim.integrate(3 * u.day), again.integrate(3 * u.day)
    assert np.array_equal(a.r.value, b.r.value)


def test_one_effect_given_alone_is_the_list_of_it():
    """``effects`` as one mapping or one name, which the normaliser takes as the list
    of it, failed in the effect set with ``zip() argument 2 is shorter than
    argument 1``; the run is the listed one's, and an error in it names
    ``effects[0]``."""
    from hamilton_orbits import Simulation

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-5, [1.0, 0, 0], [0, 1.0, 0])])
    alone = Simulation(s, effects={"name": "gr", "c": 100.0}).integrate(5.0)
    listed = Simulation(s, effects=[{"name": "gr", "c": 100.0}]).integrate(5.0)
    assert np.array_equal(alone.r, listed.r) and alone.effects == ("newtonian", "gr")
    assert Simulation(s, effects="newtonian").integrate(1.0).effects == ("newtonian",)
    with pytest.raises(ValueError, match=r"speed of light `c`.*\(effects\[0\]\)"):
        Simulation(s, effects={"name": "gr"})


def test_a_string_parameter_on_a_system_of_floats_is_named_as_the_string_given():
    """A string such as ``"1e4"`` for ``c`` on a system of plain floats is read as a
    Quantity and refused; the message showed "got the Quantity 10000.0", a value
    the user never wrote: it names the string."""
    from hamilton_orbits import Simulation

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-5, [1.0, 0, 0], [0, 1.0, 0])])
    with pytest.raises(ValueError, match=r"plain number in the units of the system .*got "
                                          r"the string '1e4' \(read as a Quantity\)"):
        Simulation(s, effects=[{"name": "gr", "c": "1e4"}])
