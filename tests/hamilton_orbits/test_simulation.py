"""integrate and Trajectory: Hamilton's integrals (C), (D), (E), times, hard cases."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import (
    Archive,
    Body,
    KeplerOrbit,
    Simulation,
    System,
    Trajectory,
    crosscheck,
    integrate,
)

EPS = np.finfo(float).eps


def sun_jupiter_saturn() -> System:
    return System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])


def test_trajectory_shapes_and_units():
    s = sun_jupiter_saturn()
    t = np.linspace(0, 1000, 11) * u.day
    traj = integrate(s, t, method="dop853", tol=1e-12)
    assert isinstance(traj, Trajectory)
    assert traj.t.unit == u.day and traj.r.unit == u.au and traj.v.unit == u.au / u.day
    assert traj.r.shape == (11, 3, 3) and traj.v.shape == (11, 3, 3)
    assert traj.energy_error.shape == (11,) and traj.energy_error[0] == 0.0
    assert traj.names == s.names and traj.final.names == s.names
    np.testing.assert_array_equal(traj.final.r.value, traj.r[-1].value)
    assert traj.steps > 0 and traj.wall_time > 0
    # an end time in years is read as years
    traj_yr = integrate(s, 1000 * u.day.to(u.yr) * u.yr, method="dop853", tol=1e-12)
    assert traj_yr.t[-1].to_value(u.day) == pytest.approx(1000, rel=1e-15)


@pytest.mark.parametrize(
    ("method", "kwargs", "e_tol", "l_tol"),
    [
        # leapfrog: energy error bounded, O(dt^2); 100 steps per Jupiter orbit
        ("leapfrog", {"dt": 4332.6 / 400 * u.day}, 1e-4, 1e-13),
        # dop853: not symplectic; local error at tol per step
        ("dop853", {"tol": 1e-13}, 1e-12, 1e-12),
    ],
)
def test_integrals_conserved(method, kwargs, e_tol, l_tol):
    """(C) centre of mass, (D) areas, (E) vis viva, each at its integrator's level.

    Leapfrog conserves angular momentum exactly up to rounding (it is a symplectic
    map that commutes with rotations) and the centre of mass exactly; its energy
    oscillates at O(dt^2).
    """
    s = sun_jupiter_saturn()
    traj = integrate(s, 10 * 4332.6 * u.day, method=method, **kwargs)
    assert np.max(np.abs(traj.energy_error)) < e_tol
    assert np.max(traj.angular_momentum_error) < l_tol
    assert np.max(traj.barycentre_drift) < 1e-12


def test_backwards_and_forwards_return():
    s = sun_jupiter_saturn()
    fwd = integrate(s, 3000 * u.day, method="leapfrog", dt=5 * u.day)
    back = integrate(fwd.final, -3000 * u.day, method="leapfrog", dt=5 * u.day)
    # leapfrog is time-reversible: rounding only
    np.testing.assert_allclose(back.final._r, s._r, rtol=0, atol=1e-11)


@pytest.mark.parametrize(
    ("t", "match"),
    [
        (0 * u.day, r"nonzero"),
        ([1.0, 3.0, 2.0] * u.day, r"monotonic.*got 2.0 d after 3.0 d at index 2"),
        (5.0, r"time Quantity"),
        (5 * u.m, r"t"),
    ],
)
def test_bad_times(t, match):
    with pytest.raises((ValueError, u.UnitConversionError), match=match):
        integrate(sun_jupiter_saturn(), t, method="leapfrog", dt=1 * u.day)


def test_bad_method_and_arguments():
    s = sun_jupiter_saturn()
    with pytest.raises(ValueError, match=r"Unknown `method` 'rk4'.*radau15, wh, leapfrog, dop853"):
        integrate(s, 1 * u.day, method="rk4")
    with pytest.raises(ValueError, match=r"`system`"):
        integrate(None, 1 * u.day)
    with pytest.raises(ValueError, match=r"`dt` > 0"):
        integrate(s, 1 * u.day, method="leapfrog", dt=-1 * u.day)
    with pytest.raises(ValueError, match=r"leapfrog needs a step"):
        integrate(s, 1 * u.day, method="leapfrog")


def test_comet_through_perihelion():
    """e = 0.9999: an adaptive integrator keeps the two-body orbit to 1e-9 relative."""
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.9999, inc=0.3, lan=0.2, argp=0.1, M=-0.05,
                                      mu=1.0)
    r0, v0 = orbit.state()
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("comet", 0.0, r0, v0)])
    traj = integrate(s, 0.1, method="dop853", tol=1e-14)
    exact, _ = orbit.propagate(0.1).state()
    err = np.linalg.norm(traj.final._r[1] - exact) / np.linalg.norm(exact)
    # DOP853 at its rtol floor 2.2e-14 through a perihelion of q = 1e-4: the error
    # accumulated near perihelion, where the step shrinks by 1e6, stays below 1e-9
    assert err < 1e-9


def test_hyperbolic_flyby_matches_two_body():
    orbit = KeplerOrbit.from_elements(a=-1.0, e=1.5, inc=0.0, lan=0.0, argp=0.0, M=-2.0,
                                      mu=1.0)
    r0, v0 = orbit.state()
    s = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]), Body("probe", 0.0, r0, v0)])
    traj = integrate(s, 4.0, method="dop853", tol=1e-13)
    exact, _ = orbit.propagate(4.0).state()
    assert np.linalg.norm(traj.final._r[1] - exact) < 1e-10 * np.linalg.norm(exact)


def test_dop853_tolerance_is_per_body():
    """A far massless body does not loosen the error control of an inner orbit.

    The inner orbit (a = 1, e = 0.3, ten periods) is checked against the exact
    Kepler propagation.  A second, massless body at 1e4 (no force on the first)
    must leave its error unchanged: with one absolute tolerance scaled by the
    largest coordinate (the former rule) the inner error grew ~1e3-fold.
    """
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.2, lan=0.1, argp=0.4, M=0.0,
                                      mu=1.0)
    r0, v0 = orbit.state()
    star = Body("star", 1.0, [0, 0, 0], [0, 0, 0])
    far = Body("far", 0.0, [1e4, 0, 0], [0, 1e-2, 0])
    t = 20 * np.pi
    exact, _ = orbit.propagate(t).state()
    errs = []
    for bodies in ([star, Body("p", 0.0, r0, v0)], [star, Body("p", 0.0, r0, v0), far]):
        traj = integrate(System(bodies), t, method="dop853", tol=1e-10)
        errs.append(np.linalg.norm(traj.final._r[1] - exact))
    # ~270 steps at rtol 1e-10; the along-track error grows with the phase swept
    # (n t = 20 pi): bound steps x tol x n t = 1.7e-6 (measured 3.5e-7)
    assert errs[0] < 1.7e-6
    # same step sequence up to the far body's own (smooth) demands
    assert errs[1] < 2 * errs[0]


def test_close_encounter_at_1e_4_au():
    """Two small bodies passing within 1e-4 au at 0.2 au/day relative speed.

    The encounter is set up at t = 0.1 (separation 1e-4 au across the relative
    velocity) and traced back with rebound's IAS15 to t = 0.  Ours must come through
    it with the energy held and agree with IAS15 afterwards.
    """
    sun = Body("sun", 1.0, [0, 0, 0], [0, 0, 0])
    a = Body("a", 1e-7, [1.0 - 5e-5, 0, 0], [0, 1.1, 0])
    b = Body("b", 1e-7, [1.0 + 5e-5, 0, 0], [0, 0.9, 0])
    sim = System([sun, a, b]).to_rebound()
    sim.integrate(-0.1, exact_finish_time=1)
    sim.t = 0.0
    system = System.from_rebound(sim)
    t = np.linspace(0.0, 0.2, 2001)
    traj = integrate(system, t, method="dop853", tol=1e-14)
    sep = np.linalg.norm(traj.r[:, 1] - traj.r[:, 2], axis=1)
    assert 1e-5 < sep.min() < 1.2e-4
    assert np.max(np.abs(traj.energy_error)) < 1e-11
    table = crosscheck(system, 0.2, method="dop853", trajectory=traj)
    assert table.relative_position_difference.max() < 1e-9


def test_many_test_particles():
    """10^4 massless particles: O(n_massive) each; their orbits stay Keplerian."""
    rng = np.random.default_rng(3)
    n = 10_000
    rad = rng.uniform(1.0, 2.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    r = np.column_stack((rad * np.cos(phi), rad * np.sin(phi), np.zeros(n)))
    v = np.column_stack((-np.sin(phi), np.cos(phi), np.zeros(n))) / np.sqrt(rad)[:, None]
    bodies = [Body("sun", 1.0, [0, 0, 0], [0, 0, 0])]
    bodies += [Body(f"p{k}", 0.0, r[k], v[k]) for k in range(n)]
    traj = integrate(System(bodies), 1.0, method="leapfrog", dt=1e-3)
    radius = np.linalg.norm(traj.final._r[1:], axis=1)
    # circular orbits under leapfrog with dt = 1e-3: radii kept to O(dt^2)
    np.testing.assert_allclose(radius, rad, rtol=1e-6)


def test_progress_and_output_callback():
    seen = []
    integrate(sun_jupiter_saturn(), np.linspace(0, 100, 6) * u.day, method="leapfrog",
              dt=1 * u.day, on_output=lambda i, steps: seen.append((i, steps)))
    assert [i for i, _ in seen] == [1, 2, 3, 4, 5]
    assert seen[-1][1] == 100


@pytest.mark.parametrize("method", ["radau15", "dop853"])
def test_a_progress_bar_is_quiet_when_stderr_is_no_terminal(capsys, method):
    """``progress=True`` with stderr a log file or a pipe wrote each bar's text
    there (a stuck "radau15: 0%| 0/19" per call, 2355 bytes for 23 calls); off a
    terminal the bar is quiet, as the scenes' are.  (rigid's likewise.)"""
    pytest.importorskip("tqdm")
    import rigid

    def runs(progress):
        integrate(sun_jupiter_saturn(), np.linspace(0, 100, 6) * u.day, method=method,
                  progress=progress)
        body = rigid.RigidBody([1.0, 2.0, 3.0], omega=[0.4, 1.1, -0.3])
        rigid.integrate(body, 2.0, dt=0.01, progress=progress)
        rigid.integrate(body, 2.0, method="dop853", progress=progress)

    runs(False)  # (compiled first: a cold cache's one-line notice of it is not the bar's)
    capsys.readouterr()
    runs(True)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("progress", ["no", "False", "", 0, 1, None])
def test_progress_that_is_not_a_bool_is_refused_by_name(progress):
    """``progress="no"`` drew a bar (any non-empty text is true) while a text for
    ``variational`` was refused: ``integrate``, ``Simulation.integrate`` and
    ``resume`` refuse anything but True or False by name, with the value, a falsy
    one (0, None, "") on the lean path too."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    pattern = rf"`progress` to be True or False, got {re.escape(repr(progress))}"
    with pytest.raises(ValueError, match=pattern):
        integrate(s, 1.0, method="leapfrog", dt=0.1, progress=progress)
    with pytest.raises(ValueError, match=pattern):
        Simulation(s, method="leapfrog", dt=0.1).integrate([0.0, 1.0], progress=progress)
    sim = Simulation(s, method="leapfrog", dt=0.1)
    assert sim.integrate(1.0, progress=np.False_).t[-1] == 1.0  # (numpy's bool: one)


def test_resume_refuses_a_progress_that_is_not_a_bool(tmp_path):
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    Simulation(s, method="wh", dt=0.01, archive=tmp_path / "a", every=2.0).integrate(
        np.arange(0.0, 3.0))
    with pytest.raises(ValueError, match=r"`progress` to be True or False, got 'no'"):
        Simulation.load(tmp_path / "a").resume(progress="no")


# -- issue 32 item 8: each test particle's own check; under-resolved encounters --------

def _comet_scene_system() -> System:
    from hamilton_orbits import Scene
    from hamilton_orbits.scenes.nbody.build import build_system

    return build_system(Scene.bundled("comet-encounter").spec)


def _inv_a(traj: Trajectory, body: str, about: str = "sun") -> float:
    """The last state's osculating 1/a of ``body`` about ``about`` (1/au)."""
    names = list(traj.names)
    i, c = names.index(body), names.index(about)
    gm = traj.final.as_arrays().gm[c]
    d = (traj.r[-1, i] - traj.r[-1, c]).to_value(u.au)
    w = (traj.v[-1, i] - traj.v[-1, c]).to_value(u.au / u.day)
    return 2 / np.linalg.norm(d) - w @ w / gm


def test_comet_ruined_by_wh_reports_its_own_check_and_warns():
    """The issue's reproducer: ``run comet-encounter`` with ``wh`` at 1 d (output
    steps 0.25 d) ends on a = -1080 au where radau15 gives +138.6 au, and reported
    only the massive bodies' energy error, 1.4e-12.  Now the comet's own check
    (its energy about the Sun: no conserved quantity with three massive bodies)
    stands beside it, the encounter with Jupiter is listed as under-resolved, and
    the run warns, once, naming the comet, Jupiter and the 1/a across it."""
    from hamilton_orbits import Scene
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    scene = Scene.bundled("comet-encounter")
    ref = scene.with_values({"crosscheck": False}).run(progress=False)
    assert "under-resolved encounters" not in ref.metrics  # radau15: adaptive steps
    bad = scene.with_values({"integrator.method": "wh", "integrator.dt": "1 d",
                             "crosscheck": False})
    with pytest.warns(UnderResolvedEncounterWarning) as caught:
        res = bad.run(progress=False)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert "'comet' to 'jupiter'" in message and "1/a of 'comet' about 'sun'" in message
    assert res.metrics["max |relative energy error|"] < 1e-11  # the massive bodies: clean
    key = "max |relative change of a test particle's energy about its primary|"
    assert res.metrics[key] > 1.0 and "comet (energy about sun)" in res.summary()
    assert res.metrics["under-resolved encounters"] == 1
    (row,) = next(rows for title, rows in res.tables.items() if "under-resolved" in title)
    assert row["particle"] == "comet" and row["body"] == "jupiter"
    assert abs(row["time"].to_value(u.day) - 329.5) < 5  # radau15's closest approach
    assert row["1/a after"].value < 0  # what wh ended on: hyperbolic
    # the reference (radau15) ends on 1/a = 1/138.6 au, the wh run far from it
    assert ref.metrics["comet orbit after: a"].to_value(u.au) == pytest.approx(138.62, rel=1e-3)
    assert res.metrics["comet orbit after: a"].to_value(u.au) < 0


@pytest.mark.parametrize(("method", "options", "dt"), [
    ("wh", {"coordinates": "jacobi"}, 1.0),  # Kepler about the inner bodies' centre of mass
    ("leapfrog", {}, 1.0),
    ("wh", {}, 0.1),  # 1/a off by twice the encounter's change (0.02 d: 3e-6 of it)
])
def test_under_resolved_approaches_are_found(method, options, dt):
    """The issue's variants that "found no encounter" (the Jacobi splitting and
    leapfrog, ending on a = -0.15 au: the perihelion at 0.01 au, time scale
    0.041 d, crossed in 1-day steps) and wh at 0.1 d past Jupiter (a = 79 au where
    radau15 gives 138.6) warn; wh at 0.01 d does not, and matches radau15."""
    from hamilton_orbits import Simulation
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    s = _comet_scene_system()
    t = np.arange(0, 548.0001, 0.25) * u.day
    sim = Simulation(s, method, dt=dt * u.day, **options)
    with pytest.warns(UnderResolvedEncounterWarning) as caught:
        traj = sim.integrate(t)
    assert caught[0].filename == __file__  # stacklevel=2: the caller's line
    body = "jupiter" if dt < 1 else "sun"
    assert body in set(traj.under_resolved["body"])
    assert abs(_inv_a(traj, "comet") - 1 / 138.6245981906832) > 1e-3
    good = Simulation(s, "wh", dt=0.01 * u.day).integrate(t)  # warns not (warnings are errors)
    assert len(good.under_resolved) == 0
    assert _inv_a(good, "comet") == pytest.approx(1 / 138.6245981906832, rel=1e-6)


def test_under_resolved_warns_once_per_simulation_and_tables_in_units():
    """Once per simulation however many legs cross encounters; the table in the
    trajectory's units (times in the unit of ``t``, distances in au, 1/a in 1/au)."""
    import warnings

    from hamilton_orbits import Simulation
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    sim = Simulation(_comet_scene_system(), "leapfrog", dt=1 * u.day)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        first = sim.integrate(np.arange(0, 30.0001, 0.25) * u.day)
        sim.integrate(np.arange(30, 548.0001, 0.25) * u.day)
    assert [w.category for w in caught] == [UnderResolvedEncounterWarning]
    table = first.under_resolved
    assert table["time"].unit == u.day and table["distance"].unit == u.au
    assert table["inv_a_before"].unit == 1 / u.au and table["step"].unit == u.day
    assert table["distance"][0].to_value(u.au) == pytest.approx(0.01, rel=0.1)  # q


def test_particle_error_with_one_massive_body_is_its_energy_error():
    """With one massive body, each particle's check is its two-body energy about
    it, and ``energy_error`` is, at each time, the largest of them: the same
    numbers (checked against the formula computed here)."""
    sun = Body("sun", gm=1.0, r=[0, 0, 0], v=[0, 0, 0])
    p1 = Body("p1", gm=0.0, r=[1.0, 0, 0], v=[0, 1.0, 0])
    p2 = Body("p2", gm=0.0, r=[0, 2.0, 0], v=[-0.6, 0, 0.1])
    traj = integrate(System([sun, p1, p2]), np.linspace(0, 20, 41), method="leapfrog",
                     dt=0.01)
    assert traj.particle_check == ("", "energy about sun", "energy about sun")
    err = traj.particle_error
    assert np.isnan(err[:, 0]).all()
    eps = (0.5 * np.sum((traj.v[:, 1:] - traj.v[:, :1]) ** 2, axis=2)
           - 1.0 / np.linalg.norm(traj.r[:, 1:] - traj.r[:, :1], axis=2))
    np.testing.assert_allclose(err[:, 1:], (eps - eps[0]) / np.abs(eps[0]), rtol=1e-9,
                               atol=1e-15)
    pick = np.argmax(np.abs(err[:, 1:]), axis=1) + 1
    np.testing.assert_array_equal(traj.energy_error, err[np.arange(41), pick])
    assert len(traj.under_resolved) == 0  # 630 steps per orbit: resolved


def test_particle_error_is_the_jacobi_constant_in_the_circular_restricted_problem():
    """Two massive bodies on a circular orbit: each test particle's check is its
    Jacobi constant, checked against the rotating-frame formula
    ``C = 2 U + n^2 (x^2 + y^2) - |v_rot|^2``; radau15 keeps it to 1e-12 and a
    leapfrog with 60 steps per period does not (the massive pair's energy does), and
    warns that its step was too long for the particle's approaches."""
    mu = 0.01
    n = 1.0  # the pair's angular velocity: unit separation, G(m1 + m2) = 1
    b1 = Body("m1", gm=1 - mu, r=[-mu, 0, 0], v=[0, -mu * n, 0])
    b2 = Body("m2", gm=mu, r=[1 - mu, 0, 0], v=[0, (1 - mu) * n, 0])
    tp = Body("tp", gm=0.0, r=[0.45, 0.5, 0.02], v=[-0.4, 0.3, 0.0])
    s = System([b1, b2, tp])
    t = np.linspace(0, 4 * np.pi, 21)
    traj = integrate(s, t, method="radau15", tol=1e-12)
    assert traj.particle_check == ("", "", "Jacobi constant")
    ang = -n * t
    c, sn = np.cos(ang), np.sin(ang)
    x, v = traj.r[:, 2], traj.v[:, 2]
    rot = np.stack([c * x[:, 0] - sn * x[:, 1], sn * x[:, 0] + c * x[:, 1]], axis=1)
    vin = np.stack([c * v[:, 0] - sn * v[:, 1], sn * v[:, 0] + c * v[:, 1]], axis=1)
    vrot = vin - n * np.stack([-rot[:, 1], rot[:, 0]], axis=1)
    pot = ((1 - mu) / np.linalg.norm(x - traj.r[:, 0], axis=1)
           + mu / np.linalg.norm(x - traj.r[:, 1], axis=1))
    jac = 2 * pot + n**2 * np.sum(rot**2, axis=1) - np.sum(vrot**2, axis=1) - v[:, 2] ** 2
    np.testing.assert_allclose(traj.particle_error[:, 2], (jac - jac[0]) / abs(jac[0]),
                               atol=1e-12)
    assert np.max(np.abs(traj.particle_error[:, 2])) < 1e-12
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    with pytest.warns(UnderResolvedEncounterWarning, match="'tp' to 'm1'") as caught:
        coarse = integrate(s, t, method="leapfrog", dt=2 * np.pi / 60)
    assert caught[0].filename == __file__  # through integrate(): still the caller's line
    assert np.max(np.abs(coarse.energy_error)) < 1e-3  # the pair: only itself
    assert np.max(np.abs(coarse.particle_error[:, 2])) > 1e-3


def test_no_test_particles_no_particle_check():
    traj = integrate(sun_jupiter_saturn(), 100 * u.day, method="wh", dt=10 * u.day)
    assert traj.particle_check == ("", "", "") and np.isnan(traj.particle_error).all()
    assert len(traj.under_resolved) == 0


def test_copy_module_copies_are_independent_and_pickling_says_what_to_do(tmp_path):
    """``copy.copy(sim)`` shared the state (integrating the copy moved the original);
    ``copy.deepcopy`` and ``pickle`` failed with "cannot pickle 'module' object".
    Both copies are ``sim.copy()`` (the archive's writing left to the original);
    pickling is refused naming save/load and copy."""
    import copy
    import pickle

    sim = Simulation(sun_jupiter_saturn(), archive=tmp_path / "a", every=10 * u.day)
    sim.integrate(20 * u.day)
    for made in (copy.copy(sim), copy.deepcopy(sim)):
        made.integrate(40 * u.day)
        assert sim.t == 20 * u.day and made.t == 40 * u.day
    assert len(Archive(tmp_path / "a")) == 3  # (only the original wrote: 0, 10, 20 days)
    with pytest.raises(TypeError, match=r"sim.save\(path\) .* Simulation.load\(path\); copy "
                                        r"it with sim.copy\(\)"):
        pickle.dumps(sim)


def test_a_wh_file_of_dt_and_tol_from_before_their_refusal_still_loads(tmp_path):
    """wh and leapfrog refuse dt and tol together now (tol was ignored); a file saved
    before, with both, must still load and continue (it failed with the refusal),
    on the same steps as the run never saved (its tol was ignored then too)."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    sim = Simulation(s, method="wh", dt=0.01)
    sim.integrate(1.0)
    spec = list(sim._spec)
    spec[2] = 1e-8  # (the tol a file of the last version kept beside dt)
    sim._spec = tuple(spec)
    sim.save(tmp_path / "old.nc")
    loaded = Simulation.load(tmp_path / "old.nc")
    np.testing.assert_array_equal(loaded.integrate(2.0).r[-1], sim.integrate(2.0).r[-1])
    with pytest.raises(ValueError, match=r"`dt` or `tol` with method 'wh'"):
        Simulation(s, method="wh", dt=0.01, tol=1e-8)


@pytest.mark.parametrize(("kw", "pattern"), [
    (dict(method="leapfrog"), r"leapfrog needs a step `dt` or a tolerance `tol`"),
    (dict(method="wh", dt=0.01, coordinates="jacobi", corrector=11, variational=True),
     r"wh with variational=True takes no `corrector`")])
def test_what_the_driver_refuses_is_refused_as_the_simulation_is_made(tmp_path, kw, pattern):
    """Refused only at the first integrate: an archived simulation had made its folder,
    empty, which Simulation.load then called "no readable snapshot"."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    with pytest.raises(ValueError, match=pattern):
        Simulation(s, archive=tmp_path / "a", every=1.0, **kw)
    assert not (tmp_path / "a").exists()


def test_an_under_resolved_approach_is_dated_at_its_periapsis_not_the_next_output():
    """A comet (q = 0.006, periapsis at t = 0.3 sqrt(27) = 1.559 from M = -0.3, n =
    1/sqrt(27)) stepped by leapfrog at 0.01, outputs at 0 and 10 only: the
    encounter was reported "at t = 10", the output after it, where the comet is
    5 away; it is dated at its two-body periapsis between the two outputs (from the
    under-resolved state after it: to 1e-3)."""
    from hamilton_orbits import KeplerOrbit
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    orb = KeplerOrbit.from_elements(a=3.0, e=1 - 0.006 / 3.0, inc=0.3, lan=0.2, argp=0.1,
                                    M=-0.3, mu=1.0)
    r, v = orb.state()
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("comet", 0.0, list(r), list(v))])
    with pytest.warns(UnderResolvedEncounterWarning, match=r"\(0.006 at t = 1.55"):
        traj = integrate(s, 10.0, method="leapfrog", dt=0.01)
    assert traj.under_resolved["time"][0] == pytest.approx(0.3 * np.sqrt(27.0), abs=1e-3)


@pytest.mark.parametrize("method", ["wh", "leapfrog"])
def test_a_comet_of_negligible_mass_is_checked_as_a_test_particle(method):
    """A sungrazing comet (q = 0.004) of GM 1e-12 beside Jupiter, stepped too
    coarsely, ended tens of units off radau15's with no word, where the same comet
    of GM 0 was warned of: a body of at most 1e-10 of the largest GM is checked as
    a test particle."""
    from hamilton_orbits import KeplerOrbit
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    orb = KeplerOrbit.from_elements(a=3.0, e=1 - 0.004 / 3.0, inc=0.3, lan=0.2, argp=0.1,
                                    M=-0.3, mu=1.0)
    r, v = orb.state()
    bodies = [Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
              Body("jupiter", 1e-3, [5.2, 0, 0], [0, 5.2**-0.5, 0])]
    for gm in (0.0, 1e-12):
        s = System([*bodies, Body("comet", gm, list(r), list(v))])
        with pytest.warns(UnderResolvedEncounterWarning, match=r"'comet' to 'sun'"):
            traj = integrate(s, 10.0, method=method,  # (wh in Jacobi coordinates: the
                             # democratic-heliocentric drifts take the Sun's approaches exactly)
                             **(dict(dt=0.1, coordinates="jacobi") if method == "wh"
                                else dict(dt=0.01)))
        assert "comet" in set(traj.under_resolved["particle"])


@pytest.mark.parametrize("a", [3.0, -3.0])
def test_an_under_resolved_approach_of_a_backward_run_is_dated_at_its_periapsis(a):
    """Backwards (outputs every 0.5 down to -10), the periapsis at -1.559 was
    reported at the output -1.5: the passage lies on the other side of the output
    the run found it at."""
    from hamilton_orbits import KeplerOrbit
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    orb = KeplerOrbit.from_elements(a=a, e=1 + np.sign(-a) * 0.006 / 3.0, inc=0.3, lan=0.2,
                                    argp=0.1, M=0.3, mu=1.0)
    r, v = orb.state()
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("comet", 0.0, list(r), list(v))])
    with pytest.warns(UnderResolvedEncounterWarning):
        traj = integrate(s, -np.arange(0, 10.01, 0.5), method="leapfrog", dt=0.01)
    assert traj.under_resolved["time"][0] == pytest.approx(
        -float(orb.time_since_periapsis), abs=1e-3)


def _mirrored(system):
    """``system`` with its velocities reversed: run backward, it passes through the
    states of ``system`` run forward (at ``-t``), velocities reversed."""
    a = system.as_arrays()
    return System([Body(name, gm, list(r), list(-v))
                   for name, gm, r, v in zip(system.names, a.gm, a.r, a.v, strict=True)])


def _sungrazer(gm_planet=None):
    """A comet (q = 0.006) 1.559 before its periapsis about a star of GM 1 (and a
    planet of ``gm_planet`` at 5.2)."""
    orb = KeplerOrbit.from_elements(a=3.0, e=1 - 0.006 / 3.0, inc=0.3, lan=0.2, argp=0.1,
                                    M=-0.3, mu=1.0)
    r, v = orb.state()
    planet = [] if gm_planet is None else [
        Body("planet", gm_planet, [5.2, 0, 0], [0, 5.2**-0.5, 0])]
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), *planet,
                   Body("comet", 0.0, list(r), list(v))])


def _head_on_pair():
    """Two planets of GM 1e-3 falling into each other beside a star of GM 1."""
    return System([Body("b0", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("b1", 1e-3, [1.0, 0.1, 0], [0, -0.3, 0]),
                   Body("b2", 1e-3, [1.0, -0.1, 0], [0, 0.3, 0])])


@pytest.mark.parametrize(("system", "kw", "pair"), [
    (_sungrazer, dict(method="leapfrog", dt=0.01), ("comet", "sun")),
    (_sungrazer, dict(method="radau15", dt=0.01), ("comet", "sun")),
    (lambda: _sungrazer(1e-3), dict(method="wh", dt=0.1, coordinates="jacobi"),
     ("comet", "sun")),
    (_head_on_pair, dict(method="wh", dt=0.01), ("b2", "b1")),
    (_head_on_pair, dict(method="leapfrog", dt=0.01), ("b2", "b1")),
])
def test_a_closest_point_between_outputs_of_a_backward_run_is_found(system, kw, pair):
    """An approach whose closest point falls between two outputs (only the ends
    here) warns run forward; run backward through the same passage (from the mirrored
    state: velocities reversed) it did not: the passage between outputs was looked
    for where the radial velocity turned from negative to positive, which going back
    in time is the receding of a pair, not its approach.  The same encounter now, at
    the same distance, dated at ``-t``."""
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    with pytest.warns(UnderResolvedEncounterWarning):
        ahead = integrate(system(), 2.0, **kw)
    with pytest.warns(UnderResolvedEncounterWarning):
        back = integrate(_mirrored(system()), -2.0, **kw)
    assert len(ahead.t) == len(back.t) == 2
    for table in (ahead.under_resolved, back.under_resolved):
        assert [(str(row["particle"]), str(row["body"])) for row in table] == [pair]
    (one,), (other,) = ahead.under_resolved, back.under_resolved
    assert other["distance"] == pytest.approx(one["distance"], rel=1e-6)
    assert other["time"] == pytest.approx(-one["time"], abs=1e-6)
    for key in ("inv_a_before", "inv_a_after", "e_before", "e_after"):  # (the mirror's
        assert other[key] == pytest.approx(one[key], rel=1e-6)  # orbits: the same)


@pytest.mark.parametrize("method", ["wh", "leapfrog"])
def test_massive_bodies_through_each_other_at_a_fixed_step_warn(method):
    """Two planets of GM 1e-3 falling head-on into each other beside a star, stepped
    at 0.01 through the fall (radau15 stops there, at t = 0.301, its step
    underflowed): wh and leapfrog passed through the singularity and flew apart at
    1e5 a unit of time, the energy error 6e9 (wh) and 6e6 (leapfrog), without a
    word: only test particles' approaches were checked.  The lighter body of a
    massive pair (of two equal, the later) is now checked against the heavier with
    the pair's summed GM, dated at the passage between the outputs 0 and 2."""
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    s = System([Body("b0", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("b1", 1e-3, [1.0, 0.1, 0], [0, -0.3, 0]),
                Body("b2", 1e-3, [1.0, -0.1, 0], [0, 0.3, 0])])
    with pytest.warns(UnderResolvedEncounterWarning, match="of 'b2' to 'b1'"):
        traj = integrate(s, 2.0, method=method, dt=0.01)
    row = traj.under_resolved[0]
    assert (row["particle"], row["body"], row["primary"]) == ("b2", "b1", "b0")
    assert 0.30 < row["time"] < 0.33 and row["distance"] < 1e-3
    assert row["inv_a_after"] < 0 < row["inv_a_before"]  # (flung out of the system)


def _massless(system, name):
    """``system`` with body ``name`` a test particle (GM 0)."""
    a = system.as_arrays()
    gm = a.gm.copy()
    gm[list(system.names).index(name)] = 0.0
    return System.from_arrays(gm * u.au**3 / u.day**2, a.r * u.au, a.v * u.au / u.day,
                              names=system.names)


def test_a_closest_point_between_outputs_is_taken_only_where_the_conic_is_the_path():
    """Mars (a test particle here, as before the massive pairs were checked; massive
    now, the same) over 5 years of wh at 4 d, outputs at the ends: its closest point
    to Jupiter between them was taken from their two-body conic, "0.74 au at t =
    1374 d", and warned of, where the two never came within 3.5 au: both go about the
    Sun, and no conic of theirs is their path.  The conic is taken about the primary,
    or where the pair is within the Hill sphere at an output."""
    import warnings

    s = System.solar_system("J2000")
    for system in (_massless(s, "mars"), s):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            traj = integrate(system, 5 * u.yr, method="wh", dt=4 * u.day)
        assert len(traj.under_resolved) == 0


@pytest.mark.parametrize("every", [None, 4.0, 100.0])
def test_the_solar_system_run_backwards_at_a_fixed_step_warns_of_nothing(every):
    """The solar system (and with Mars a test particle) 10 years back with wh at 4 d,
    outputs at the ends, every step, or every 100 d: no approach is under-resolved
    (backwards, the closest points between outputs are looked for where the pairs'
    distances shrink, then grow, going back in time)."""
    import warnings

    s = System.solar_system("J2000")
    t = -10 * u.yr if every is None else -np.arange(0, 3653, every) * u.day
    for system in (_massless(s, "mars"), s):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            traj = integrate(system, t, method="wh", dt=4 * u.day)
        assert len(traj.under_resolved) == 0 and traj.t[-1] <= -3600 * u.day


def test_the_hill_sphere_of_the_body_passed_is_its_own_about_its_primary():
    """A particle about the Earth (the Moon, massless) passing Venus at 0.3-0.4 au
    was "within three Hill radii" of Venus measured about the Earth (twice their
    distance) and warned of 8 times in 10 years of wh at 2 d; Venus's are 0.02 au
    about the Sun."""
    import warnings

    s = System.solar_system("J2000", bodies=["sun", "venus", "earth", "moon"])
    t = np.arange(2, 3653, 2.0) * u.day
    for system in (_massless(s, "moon"), s):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            traj = integrate(system, t, method="wh", dt=2 * u.day)
        assert len(traj.under_resolved) == 0


def test_a_moon_s_conic_about_the_sun_is_not_its_path():
    """A massive moon (Callisto about Jupiter) with leapfrog at 0.5 d, daily outputs:
    its closest point to the Sun between two outputs was taken from their two-body
    conic ("0.46 at t = 2", never nearer than 5.18): the most massive body has no
    Hill sphere to be within, and is not the moon's primary (the review's case)."""
    import warnings

    mu_s, mu_j, mu_c, a, rho = 2.9591220828e-4, 2.825e-7, 1.6e-11, 5.2, 0.01259
    vj, vc, th = np.sqrt(mu_s / a), np.sqrt(mu_j / rho), np.radians(-40)
    rel = rho * np.array([-np.cos(th), -np.sin(th), 0])
    vrel = vc * np.array([np.sin(th), -np.cos(th), 0])
    s = System([Body("sun", mu_s, [0, 0, 0], [0, 0, 0]),
                Body("jupiter", mu_j, [a, 0, 0], [0, vj, 0]),
                Body("callisto", mu_c, list([a, 0, 0] + rel), list([0, vj, 0] + vrel))])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        traj = integrate(s, np.arange(0, 30.0, 1.0), method="leapfrog", dt=0.5)
    assert len(traj.under_resolved) == 0


def test_massive_pairs_are_checked_in_systems_of_at_most_32_massive_bodies():
    """The head-on pair beside 29 (then 30) distant bodies of GM 1e-9: with 32 massive
    bodies it is listed, with 33 not (checking every pair at every output would cost
    about a force evaluation per output: twelve times a one-step call of 300
    bodies; the test particles' are checked at any size)."""
    from hamilton_orbits._kernels.integrals import MASSIVE_PAIRS_MAX

    def system(extra):  # (the star, the pair, and extra bodies far out)
        far = [Body(f"x{k}", 1e-9, [30.0 + k, 0, 0], [0, 0.18, 0]) for k in range(extra)]
        return System([Body("b0", 1.0, [0, 0, 0], [0, 0, 0]),
                       Body("b1", 1e-3, [1.0, 0.1, 0], [0, -0.3, 0]),
                       Body("b2", 1e-3, [1.0, -0.1, 0], [0, 0.3, 0]), *far])

    assert MASSIVE_PAIRS_MAX == 32
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        few = integrate(system(29), 2.0, method="wh", dt=0.01).under_resolved  # (32)
        many = integrate(system(30), 2.0, method="wh", dt=0.01).under_resolved  # (33)
    assert [(str(r["particle"]), str(r["body"])) for r in few] == [("b2", "b1")]
    assert len(many) == 0


@pytest.mark.parametrize("method", ["wh", "leapfrog"])
def test_a_moon_about_its_planet_about_a_star_is_no_approach(method):
    """A moon (GM 3.7e-8, 0.00257 from its planet of 3e-6: the Moon and the Earth)
    stepped 55 times an orbit: its orbit about the planet, whose pace it keeps, and
    the planet's and its own about the star (the moon inside the star's "Hill
    sphere" about the planet: the approach's time scale is the year's) are no
    approaches the step is too long for."""
    d, gm_p, gm_m = 0.00257, 3e-6 * 2.959e-4, 3.7e-8 * 2.959e-4
    w = np.sqrt((gm_p + gm_m) / d)
    vp = np.sqrt(2.959e-4)
    s = System([Body("star", 2.959e-4, [0, 0, 0], [0, 0, 0]),
                Body("planet", gm_p, [1.0, 0, 0], [0, vp, 0]),
                Body("moon", gm_m, [1.0 + d, 0, 0], [0, vp + w, 0])])
    traj = integrate(s, np.linspace(0, 365.25, 37), method=method, dt=0.5)
    assert len(traj.under_resolved) == 0  # (and no warning: warnings are errors here)
    assert abs(traj.energy_error).max() < 1e-3


def test_energy_error_of_one_centre_after_a_removal_is_the_particles():
    """One massive body and test particles: an escape that removed a particle made
    ``gm`` vary over the run, and the energy error fell back to Hamilton's E of the
    one massive body, identically 0 for the whole run (a 3.9% drift of a comet
    integrated with far too long a step read as perfect).  It is the particles'
    own energies, as without the removal (the comet's two-body energy about the Sun
    computed here from the trajectory)."""
    import astropy.units as u

    from hamilton_orbits import Body, System, integrate

    gm = 1.32712440018e11 * u.km**3 / u.s**2
    s = System([Body("sun", gm, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                Body("comet", 0 * gm, [0.3, 0, 0] * u.au, [0, 70, 0] * u.km / u.s),
                Body("x", 0 * gm, [1, 0.1, 0] * u.au, [0, 60, 0] * u.km / u.s)])
    times = np.linspace(0, 3, 7) * u.yr
    with pytest.warns(UserWarning):  # (the step is too long for the comet's perihelion)
        rem = integrate(s, times, method="leapfrog", dt=8 * u.day,
                        events=[{"name": "escape", "distance": 3 * u.au, "action": "remove"}])
    mu = gm.to_value(u.au**3 / u.day**2)
    d = (rem.r[:, 1] - rem.r[:, 0]).to_value(u.au)
    w = (rem.v[:, 1] - rem.v[:, 0]).to_value(u.au / u.day)
    eps = 0.5 * (w**2).sum(1) - mu / np.linalg.norm(d, axis=1)
    assert len(rem.events) == 1 and np.isnan(rem.r[-1, 2].value).all()
    np.testing.assert_allclose(rem.energy_error, (eps - eps[0]) / abs(eps[0]), rtol=1e-12,
                               atol=1e-15)
    assert np.max(np.abs(rem.energy_error)) > 0.03
    # every particle taken out: 0 from then on (the one body keeps its energy), no NaN
    lone = System([Body("sun", gm, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                   Body("x", 0 * gm, [1, 0.1, 0] * u.au, [0, 60, 0] * u.km / u.s)])
    gone = integrate(lone, times, events=[{"name": "escape", "distance": 3 * u.au,
                                          "action": "remove"}])
    assert len(gone.events) == 1 and np.all(np.isfinite(gone.energy_error))
    assert gone.energy_error[-1] == 0.0


def test_energy_error_of_an_energy_near_zero_is_relative_to_its_terms():
    """A parabolic comet (E(0) = -5e-20 beside terms of 2e-4, its rounding residue)
    integrated to rounding read ``max |dE/E| = 1``, and an equal-mass pair at escape
    speed 0.5: changes of rounding size relative to a rounding residue.  Where
    ``|E(0)|`` is below 2^-26 of its terms, the error is relative to the terms; the
    run then reads at rounding level (bound 1e-14: radau15's error on these runs).
    A bound orbit's error is unchanged."""
    import astropy.units as u

    from hamilton_orbits import Body, KeplerOrbit, System, integrate
    from hamilton_orbits.integrals import integral_errors

    mu = 1.32712440018e11 * u.km**3 / u.s**2
    o = KeplerOrbit.from_elements(q=1 * u.au, e=1.0, inc=10 * u.deg, lan=0 * u.deg,
                                  argp=0 * u.deg, nu=-60 * u.deg, mu=mu)
    r, v = o.state()
    comet = System([Body("sun", mu, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                    Body("comet", 0 * mu, r, v)])
    vv = np.sqrt(0.5)
    pair = System([Body("a", 1.0, [-1, 0, 0], [0, -vv, 0]), Body("b", 1.0, [1, 0, 0], [0, vv, 0])])
    for system, times in ((comet, np.linspace(0, 1, 5) * u.yr), (pair, np.linspace(0, 10, 5))):
        assert np.max(np.abs(integrate(system, times).energy_error)) < 1e-14
    # a bound pair: the error relative to |E(0)| as before (relative to the terms, 1.44
    # |E(0)| here, it would read 0.69 of it); the change, 7e-10 of E, is known to about
    # 1e-6 of itself in float64 (the cancellation of E(1) - E(0)), hence the tolerance
    rr = np.array([[[-1.0, 0, 0], [1.0, 0, 0]], [[-1.0, 0, 0], [1.0, 0, 0]]])
    vb = np.zeros((2, 2, 3))
    vb[:, 0, 1], vb[:, 1, 1] = -0.3, 0.3
    vb[1, 1, 1] = 0.3 + 2.0**-30
    e0 = 0.5 * 0.09 * 2 - 0.5
    e1 = 0.5 * (0.09 + (0.3 + 2.0**-30) ** 2) - 0.5
    assert integral_errors(rr, vb, np.array([1.0, 1.0]), np.array([0.0, 1.0]))[0][1] == \
        pytest.approx((e1 - e0) / abs(e0), rel=1e-6)


def test_a_trajectory_s_arrays_are_read_only():
    """``tr.r`` and ``tr.v`` were writable views of the arrays ``energy_error`` and
    ``final`` are computed from (lazily): made heliocentric in place, they changed
    the energy error to 1e-3 and put the Sun at the origin of ``final``; and
    ``tr.r -= ...`` changed the data before refusing the attribute.  They are
    read-only; a copy is the caller's own."""
    from hamilton_orbits import Body, System, integrate

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    tr = integrate(s, np.linspace(0.0, 2.0, 5))
    before = tr.r.copy()
    with pytest.raises(ValueError, match="read-only"):
        r = tr.r
        r -= tr.r[:, :1]
    np.testing.assert_array_equal(tr.r, before)
    helio = tr.r - tr.r[:, :1]  # (a new array: the caller's)
    helio[0] = 0.0
    assert not tr.t.flags.writeable and not tr.v.flags.writeable
    import copy
    import pickle

    for again in (pickle.loads(pickle.dumps(tr)), copy.deepcopy(tr)):  # (an ensemble's
        # members come back pickled)
        assert not (again.t.flags.writeable or again.r.flags.writeable
                    or again.v.flags.writeable)


def test_dt_is_the_fixed_step_in_the_system_s_units():
    """``Simulation.dt``: the fixed step made with (days for a Quantity system), or
    None where the method chooses it, or ``tol`` does."""
    s = System.solar_system("J2000", bodies=["sun", "earth"])
    assert Simulation(s, "wh", dt=2 * u.day).dt == 2 * u.day
    assert Simulation(s, "wh", dt=1 * u.yr).dt.unit == u.day
    assert Simulation(s).dt is None and Simulation(s, "wh", tol=1e-9).dt is None
    plain = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
    assert Simulation(plain, "radau15", dt=0.01).dt == 0.01


def test_every_wall_takes_a_timedelta_as_the_quantity_it_holds(tmp_path):
    """``Simulation(..., archive=..., every_wall=TimeDelta(...))`` was refused as
    "Expected `every_wall` > 0 and finite", while the time Quantity it holds was taken:
    a TimeDelta is now that Quantity in days, in seconds as the archive keeps it; an
    array of them is refused by name."""
    from astropy.time import TimeDelta

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-5, [1, 0, 0], [0, 1, 0])])
    for k, given in enumerate([TimeDelta(90.0, format="sec"), TimeDelta(0.25, format="jd")]):
        sim = Simulation(s, archive=tmp_path / f"td{k}", every_wall=given)
        same = Simulation(s, archive=tmp_path / f"q{k}", every_wall=given.to(u.day))
        seconds = sim._archive.every_wall
        assert seconds == same._archive.every_wall and type(seconds) is float
        assert seconds == pytest.approx(given.to_value(u.s), rel=1e-15)
    with pytest.raises(ValueError, match=r"Expected `every_wall` to be one number, got "
                                         r"shape \(2,\)"):
        Simulation(s, archive=tmp_path / "two", every_wall=TimeDelta([1.0, 2.0], format="sec"))


def _ring(n: int) -> System:
    """A star and ``n - 1`` massless bodies on circular orbits (G M = 1)."""
    radius = np.linspace(1.0, 3.0, n - 1)
    r = np.vstack([[0.0, 0, 0], np.c_[radius, np.zeros((n - 1, 2))]])
    v = np.vstack([[0.0, 0, 0], np.c_[np.zeros(n - 1), 1 / np.sqrt(radius), np.zeros(n - 1)]])
    return System.from_arrays(np.r_[1.0, np.zeros(n - 1)], r, v)


def test_stm_outputs_beyond_the_memory_limit_are_refused_before_the_run(monkeypatch):
    """``stm=True`` for 300 bodies at 1001 outputs raised numpy's ``MemoryError:
    Unable to allocate 24.2 GiB`` after the setting up (and a request a little under
    the machine's memory was granted, then ran it out of memory): it is refused by
    ``stm``'s name, with the outputs, the bodies and the size, before any step."""
    from hamilton_orbits import _output_memory
    from hamilton_orbits.scene import OUTPUT_LIMIT

    assert _output_memory.OUTPUT_LIMIT is OUTPUT_LIMIT  # (one limit, the scenes')
    assert _output_memory.memory_limit() >= OUTPUT_LIMIT
    # (the limit of a machine with 2 GiB: the same refusal on any machine)
    monkeypatch.setattr(_output_memory, "memory_limit", lambda: OUTPUT_LIMIT)
    sim = Simulation(_ring(300), variational=True, stm=True)
    with pytest.raises(ValueError, match=r"`stm` = True\) to fit in memory: 1001 outputs of "
                                         r"300 bodies would take 48\.3 GiB, beyond the limit "
                                         r"of 1 GiB .* at most 20 outputs"):
        sim.integrate(np.linspace(0, 10, 1001)[1:])
    assert sim.t == 0.0 and sim.steps == 0
    with pytest.raises(ValueError, match=r"`stm` = True\) .* 2 outputs of 3000 bodies .* "
                                         r"not even the start and the end fit: fewer bodies"):
        Simulation(_ring(3000), variational=True, stm=True)


def test_outputs_beyond_the_memory_limit_are_refused_by_t(monkeypatch, tmp_path):
    """The positions and velocities of many outputs of many bodies alike, by ``t``'s
    name; a call within the limit runs, and resume() checks its call's outputs."""
    from hamilton_orbits import _output_memory

    monkeypatch.setattr(_output_memory, "memory_limit", lambda: 2**20)
    sim = Simulation(_ring(3), method="leapfrog", dt=0.01)
    with pytest.raises(ValueError, match=r"`t` to ask for outputs that fit in memory: "
                                         r"1e\+04 outputs of 3 bodies would take 1\.68 MiB, "
                                         r"beyond the limit of 1 MiB .* at most 5957 outputs"):
        sim.integrate(np.linspace(0, 1, 10_000))
    assert sim.t == 0.0 and sim.steps == 0
    assert sim.integrate(np.linspace(0, 1, 5000)).r.shape == (5000, 3, 3)
    Simulation(_ring(3), method="wh", dt=0.01, archive=tmp_path / "a", every=2.0).integrate(
        np.arange(0.0, 7.0))
    again = Simulation.load(tmp_path / "a")
    monkeypatch.setattr(_output_memory, "memory_limit", lambda: 1000)
    with pytest.raises(ValueError, match=r"`t` .* 7 outputs of 3 bodies would take 1\.2 KiB"):
        again.resume()


def test_crosscheck_refuses_a_progress_that_is_no_bool_with_a_trajectory_given():
    # with a trajectory given, progress went unused and unchecked ("no" taken)
    system = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                     Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    traj = integrate(system, 0.5, method="dop853")
    with pytest.raises(ValueError, match="`progress` to be True or False, got 'no'"):
        crosscheck(system, 0.5, method="dop853", trajectory=traj, progress="no")


def test_integrate_from_within_its_own_call_is_refused_and_a_copy_goes_on():
    """``sim.integrate`` from ``on_output`` or ``stop`` of a call of the same
    simulation ran a second integration under the first (the lean path's one end
    time, or output times), the outer call then going on from a moved state (1.4
    off at its end): refused, naming the copy to integrate there instead, the
    simulation standing where its call was cut and going on as the run does."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    times = np.linspace(0.0, 2.0, 5)
    plain = Simulation(s, method="wh", dt=0.01).integrate(times)
    within = r"Simulation\.integrate\(\) called from within an integrate or resume call .* " \
             r"integrate a copy there \(sim\.copy\(\), which writes nothing\)"
    for again in (9.0, [1.0, 9.0]):
        for where in ("on_output", "stop"):
            sim = Simulation(s, method="wh", dt=0.01)
            callback = (lambda i, steps, again=again, sim=sim: i == 2 and sim.integrate(again)) \
                if where == "on_output" else (lambda again=again, sim=sim: sim.t == 1.0 and
                                              sim.integrate(again))
            with pytest.raises(ValueError, match=within):
                sim.integrate(times, **{where: callback})
            assert sim.t == 1.0 and sim.steps == 100  # (where the call was cut)
            rest = sim.integrate(times[times > 1.0])  # (no longer within a call)
            assert np.array_equal(rest.r, plain.r[2:]) and sim.steps == plain.steps
    sim, branches = Simulation(s, method="wh", dt=0.01), []

    def on_output(i, steps):
        branches.append(sim.copy())
        branches[-1].integrate(9.0)  # (a copy: integrated there)

    traj = sim.integrate(times, on_output=on_output)
    assert np.array_equal(traj.r, plain.r) and branches[-1].t == 9.0
