"""Simulation: the prepared object that continues bit for bit, copies, stops early.

The reference of every test here is the run that was never split: continuing a
simulation in legs must reach the same bits (positions, velocities, steps, the
integrals' errors measured from the start, MEGNO, the STM, the events found) as one
call through every output time, for every method, with effects, events and the
variational equations.
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Archive, Body, Simulation, System, integrate
from hamilton_orbits.engine import StopIntegration
from hamilton_orbits.integrators import DOP853, WH, Leapfrog, Radau15


def _disc(n: int = 6, seed: int = 11) -> System:
    """A star and planets on near-circular, slightly inclined orbits (masses 1e-5 to
    1e-3), the oblate star carrying a J2 (so that ``j2`` has something to do)."""
    rng = np.random.default_rng(seed)
    a = np.sort(rng.uniform(1.0, 6.0, n - 1))
    ph = rng.uniform(0, 2 * np.pi, n - 1)
    inc = rng.uniform(0, 0.05, n - 1)
    bodies = [Body("star", 1.0, [0, 0, 0], [0, 0, 0], radius=0.005, j2=1e-3, pole=[0, 0, 1])]
    for k in range(n - 1):
        r = a[k] * np.array([np.cos(ph[k]), np.sin(ph[k]) * np.cos(inc[k]),
                             np.sin(ph[k]) * np.sin(inc[k])])
        s = 1 / np.sqrt(a[k])
        v = s * np.array([-np.sin(ph[k]), np.cos(ph[k]) * np.cos(inc[k]),
                          np.cos(ph[k]) * np.sin(inc[k])])
        bodies.append(Body(f"p{k}", 10.0 ** rng.uniform(-5, -3), r, v))
    return System(bodies)


def _merging() -> System:
    """Two bodies falling into contact (they merge about t = 1.4) and a bystander."""
    return System([Body("a", 1.0, [0, 0, 0], [0, 0.01, 0], radius=0.01),
                   Body("b", 0.5, [1.0, 0, 0], [0, -0.02, 0.005], radius=0.02),
                   Body("c", 0.0, [5.0, 0, 0], [0, 0.4, 0])])


GR = {"name": "gr", "c": 100.0}
GR_POTENTIAL = {"name": "gr_potential", "c": 100.0}
J2 = {"name": "j2", "body": "star"}
METHODS = {
    "radau15": dict(method="radau15"),
    "radau15-fixed": dict(method="radau15", dt=0.02),
    "wh-dh": dict(method="wh", dt=0.02),
    "wh-jacobi-11": dict(method="wh", dt=0.02, coordinates="jacobi", corrector=11),
    "leapfrog": dict(method="leapfrog", dt=0.01),
    "dop853": dict(method="dop853", tol=1e-10),
}
SYMPLECTIC = {"wh-dh", "wh-jacobi-11", "leapfrog"}


def _variants():
    for name, kw in METHODS.items():
        effects = [GR_POTENTIAL, J2] if name in SYMPLECTIC else [GR, J2]
        yield pytest.param(_disc, kw, id=f"{name}-plain")
        yield pytest.param(_disc, dict(kw, effects=effects), id=f"{name}-effects")
        yield pytest.param(_merging, dict(kw, events=[{"name": "collision", "action": "merge"}]),
                           id=f"{name}-merge")
        if name != "wh-jacobi-11":  # wh's tangent map takes no corrector
            yield pytest.param(_disc, dict(kw, variational=True, stm=True),
                               id=f"{name}-variational")


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True))


@pytest.mark.parametrize(("system", "kw"), list(_variants()))
def test_two_legs_reach_the_bits_of_one_call(system, kw):
    system = system()
    t1, t2, t3 = 1.3, 2.9, 4.0
    sim = Simulation(system, **kw)
    first = sim.integrate(t1)
    second = sim.integrate([t2, t3])
    once = Simulation(system, **kw).integrate([t1, t2, t3])
    assert first.t.tolist() == [0.0, t1] and second.t.tolist() == [t1, t2, t3]
    for leg, rows in ((first, slice(0, 2)), (second, slice(1, 4))):
        assert _same(leg.r, once.r[rows]) and _same(leg.v, once.v[rows])
        # Hamilton's integrals measured from the start of the simulation in both
        assert _same(leg.energy_error, once.energy_error[rows])
        assert _same(leg.angular_momentum_error, once.angular_momentum_error[rows])
        assert _same(leg.barycentre_drift, once.barycentre_drift[rows])
        if once.megno is not None:
            assert _same(leg.megno, once.megno[rows]) and _same(leg.lyapunov, once.lyapunov[rows])
            assert _same(leg.stm, once.stm[rows])
    assert first.steps + second.steps == once.steps == sim.steps
    assert sim.t == t3
    events = list(first.events["time"]) + list(second.events["time"])
    assert events == list(once.events["time"])
    if "events" in kw:
        assert len(events) == 1 and sim.system.names == ("a", "c")  # the merge happened
    assert sim.system.names == once.final.names
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.final.as_arrays().r)



def _crossing() -> System:
    """Seven planets of radius 0.15 on crossing orbits about a star: p6 merges into p1
    at t = 3.159, and the merged body (its radius grown to 0.189, its centre moved)
    is then in contact with p3 (0.319 apart, 0.339 their radii)."""
    rng = np.random.default_rng(7)
    bodies = [Body("sun", 1.0, [0, 0, 0], [0, 0, 0], radius=0.01)]
    for i in range(1, 8):
        a, th = 0.6 + 0.25 * i, rng.uniform(0, 2 * np.pi)
        w = 1.15 / np.sqrt(a) if i % 2 else 1 / np.sqrt(a) / 1.15
        bodies.append(Body(f"p{i}", 1e-4, [a * np.cos(th), a * np.sin(th), 0.002 * i],
                           [-w * np.sin(th), w * np.cos(th), 0.0], radius=0.15))
    return System(bodies)


@pytest.mark.parametrize("kw", list(METHODS.values()), ids=list(METHODS))
def test_a_merged_body_in_contact_with_another_merges_with_it_in_every_leg(kw):
    """A merge that leaves the merged body in contact with a third: it collides with
    it at once (at the merge's time; wh and leapfrog at the end of the step), as a
    leg begun there does.  Before, one call went on with the two overlapping, while
    a leg begun after the merge merged them at its start from the last output row,
    whose merged-away body was NaN: every force NaN, the leg failed ("the
    acceleration became non-finite", "the Kepler step of body 6 failed"), and so
    did resuming from a snapshot there."""
    events = [{"name": "collision", "action": "merge"}]
    sim = Simulation(_crossing(), events=events, **kw)
    first, second = sim.integrate(3.2), sim.integrate([3.33, 5.0])
    once = Simulation(_crossing(), events=events, **kw).integrate([3.2, 3.33, 5.0])
    assert [str(b) for b in once.events["bodies"]] == ["p1-p6", "p1-p3"]
    assert once.events["time"][0] < 3.2 and once.events["time"][1] < 3.2
    assert list(first.events["time"]) + list(second.events["time"]) == list(
        once.events["time"])
    assert _same(second.r, once.r[1:]) and _same(second.v, once.v[1:])
    assert first.steps + second.steps == once.steps
    assert sim.system.names == once.final.names == ("sun", "p1", "p2", "p4", "p5", "p7")


@pytest.mark.parametrize(("system", "kw"), list(_variants()))
def test_legs_of_one_end_time_each_reach_the_bits_of_one_call(system, kw, monkeypatch):
    """A continuing call to one end time (a float), nothing watched or asked, takes
    the engine's lean path (``Propagation.advance_end``, not ``advance``); events
    and the variational equations take the whole one.  Either way every leg has
    the rows, integrals and steps of the call that was never split."""
    from hamilton_orbits import engine

    system = system()
    times = (1.3, 2.9, 4.0)
    once = Simulation(system, **kw).integrate(list(times))
    sim = Simulation(system, **kw)
    whole = []
    advance = engine.Propagation.advance
    monkeypatch.setattr(engine.Propagation, "advance",
                        lambda self, *a, **k: whole.append(1) or advance(self, *a, **k))
    legs = [sim.integrate(t) for t in times]
    lean = "events" not in kw and "variational" not in kw
    assert len(whole) == (1 if lean else 3)  # (the first leg makes the integrator)
    for k, leg in enumerate(legs):
        rows = slice(k, k + 2)
        assert leg.t.tolist() == once.t[rows].tolist() and leg.complete
        assert _same(leg.r, once.r[rows]) and _same(leg.v, once.v[rows])
        assert _same(leg.energy_error, once.energy_error[rows])
        assert _same(leg.angular_momentum_error, once.angular_momentum_error[rows])
        assert _same(leg.barycentre_drift, once.barycentre_drift[rows])
        assert (leg.megno is None) == (once.megno is None)
        if once.megno is not None:
            assert _same(leg.megno, once.megno[rows]) and _same(leg.stm, once.stm[rows])
    assert sum(leg.steps for leg in legs) == once.steps == sim.steps
    assert sum(len(leg.events) for leg in legs) == len(once.events)
    assert legs[-1].stopped_by is None and len(legs[-1].under_resolved) == 0
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.final.as_arrays().r)


def test_ctrl_c_in_a_lean_leg_keeps_the_state_reached(monkeypatch):
    """Ctrl-C during a continuing call's lean path (here as the leg's state is
    turned to inertial coordinates, after its steps) raises ``KeyboardInterrupt``
    with the simulation standing where its integrator stands, as on the whole
    path: it then continues with the bits of the run that was never
    interrupted."""
    from hamilton_orbits._kernels import wh as kernels

    kw = dict(method="wh", dt=0.02)
    once = Simulation(_disc(), **kw).integrate([1.0, 2.0, 3.0])
    sim = Simulation(_disc(), **kw)
    sim.integrate(1.0)
    to_inertial = kernels.dh_to_inertial
    pressed = []

    def interrupted(*args):
        if not pressed:
            pressed.append(1)
            raise KeyboardInterrupt
        return to_inertial(*args)

    monkeypatch.setattr(kernels, "dh_to_inertial", interrupted)
    with pytest.raises(KeyboardInterrupt):
        sim.integrate(2.0)
    assert pressed and sim.t == 2.0 and sim.steps == 100
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.r[2])
    assert _same(sim.integrate(3.0).r[-1], once.r[3])


def test_integrate_is_a_simulation_integrated_once():
    s = _disc()
    one = integrate(s, [0.5, 2.0], method="wh", dt=0.02, effects=[GR_POTENTIAL])
    sim = Simulation(s, method="wh", dt=0.02, effects=[GR_POTENTIAL]).integrate([0.5, 2.0])
    assert _same(one.r, sim.r) and _same(one.energy_error, sim.energy_error)


def test_typed_methods_are_the_string_forms():
    s = _disc()
    for typed, name, options in ((WH(coordinates="jacobi", corrector=11), "wh",
                                  {"coordinates": "jacobi", "corrector": 11}),
                                 (Radau15(criterion="global"), "radau15", {"criterion": "global"}),
                                 (Leapfrog(), "leapfrog", {}), (DOP853(), "dop853", {})):
        kw = {"dt": 0.02} if name in ("wh", "leapfrog") else {}
        a = integrate(s, 1.0, method=typed, **kw)
        b = integrate(s, 1.0, method=name, **kw, **options)
        assert _same(a.r, b.r) and a.method == b.method == name
        assert Simulation(s, method=typed, **kw).method == typed


@pytest.mark.parametrize(("kw", "match"), [
    (dict(method=WH(), coordinates="jacobi"), r"Options coordinates given beside the method"),
    (dict(method="wh", coordinates="Jacobians"), r"Expected `coordinates` to be one of"),
    (dict(method="radau15", tangent_control="no"), r"Expected `tangent_control` to be True"),
    (dict(method="radau15", tangent_control=True), r"`tangent_control=True` .* needs "
                                                   r"`variational=True`"),
    (dict(method="dop853", criterion="global"), r"Unknown option `criterion` = 'global' for "
                                               r"method 'dop853'; it takes: tangent_control"),
    (dict(method="radau15", max_steps=0), r"Expected `max_steps` to be a positive integer"),
    (dict(method="leapfrog", dt=0.1, effects=[GR]), r"Effect 'gr' depends on velocities"),
])
def test_bad_simulations_are_refused_with_the_argument_named(kw, match):
    with pytest.raises(ValueError, match=match):
        Simulation(_disc(), **kw)


def test_capital_jacobi_is_jacobi():
    s = _disc()
    a = integrate(s, 1.0, method="wh", dt=0.02, coordinates="Jacobi")
    b = integrate(s, 1.0, method="wh", dt=0.02, coordinates="jacobi")
    assert _same(a.r, b.r)


@pytest.mark.parametrize("kw", [METHODS["radau15"], METHODS["wh-dh"],
                                dict(METHODS["leapfrog"], variational=True)])
def test_a_copy_is_independent_and_continues_alike(kw):
    s = _disc()
    sim = Simulation(s, **kw)
    sim.integrate(1.0)
    branch = sim.copy()
    far = branch.integrate(3.0)  # the copy goes on ...
    assert sim.t == 1.0 and sim.steps < branch.steps  # ... the original does not move
    near = sim.integrate(3.0)
    assert _same(far.r, near.r) and _same(far.energy_error, near.energy_error)
    if far.megno is not None:
        assert _same(far.megno, near.megno)


@pytest.mark.parametrize("kw", [METHODS["radau15"], METHODS["dop853"], METHODS["leapfrog"]])
def test_a_copy_with_events_keeps_its_own_log_and_masses(kw):
    """A copy merges on its own: its log, its masses and the forces it computes with
    them (dop853's right-hand side reads the copy's masses, not the original's)."""
    sim = Simulation(_merging(), events=[{"name": "collision", "action": "merge"}], **kw)
    sim.integrate(0.5)
    branch = sim.copy()
    merged = branch.integrate(3.0)
    assert len(merged.events) == 1 and branch.system.names == ("a", "c")
    assert sim.system.names == ("a", "b", "c")  # the original has not merged
    again = sim.integrate(3.0)
    assert _same(again.r, merged.r) and list(again.events["time"]) == list(merged.events["time"])


@pytest.mark.parametrize("method", ["radau15", "wh", "leapfrog", "dop853"])
def test_stop_integration_from_a_callback_returns_what_was_reached(method):
    """An output callback that raises StopIntegration used to come out of integrate
    as a bare KeyboardInterrupt with every output lost: the trajectory now ends at
    the output reached, incomplete, and the simulation stands there."""
    s = _disc()
    kw = {"dt": 0.02} if method in ("wh", "leapfrog") else {}

    def on_output(i: int, steps: int) -> None:
        if i == 3:
            raise StopIntegration

    sim = Simulation(s, method=method, **kw)
    traj = sim.integrate(np.linspace(0, 2, 9), on_output=on_output)
    assert not traj.complete and len(traj.t) == 4 and traj.t[-1] == 0.75
    assert "incomplete" in repr(traj)
    whole = integrate(s, np.linspace(0, 2, 9), method=method, **kw)
    assert whole.complete and _same(traj.r, whole.r[:4])
    assert sim.t == 0.75  # and it continues from there, as one run would have
    rest = sim.integrate(np.linspace(0, 2, 9)[4:])
    assert _same(rest.r[-1], whole.r[-1])
    stopped = integrate(s, np.linspace(0, 2, 9), method=method, on_output=on_output, **kw)
    assert not stopped.complete and _same(stopped.r, whole.r[:4])


def test_ctrl_c_still_raises_keyboard_interrupt():
    def on_output(i: int, steps: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        integrate(_disc(), [1.0, 2.0], on_output=on_output)


@pytest.mark.parametrize("days", [99.0, 102.0])
def test_the_simulations_time_given_back_in_another_unit_is_its_time(days):
    """``sim.t`` in years, given back as the first output time (as documented: the
    simulation's time, added if missing), comes back through the unit an ulp off:
    99 d made a leg of 1e-14 d and one step more, 102 d a refusal naming the wrong
    index and value."""
    s = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])
    plain, given = (Simulation(s, method="wh", dt=3 * u.day) for _ in range(2))
    for sim in (plain, given):
        sim.integrate(days * u.day)
    assert given.t.to(u.yr).to_value(u.day) != days  # (the round trip moves it)
    rest = plain.integrate([0.9, 1.0] * u.yr)
    back = given.integrate(u.Quantity([given.t.to(u.yr), 0.9 * u.yr, 1.0 * u.yr]))
    assert given.steps == plain.steps and len(back.t) == len(rest.t)
    np.testing.assert_array_equal(back.r[-1].value, rest.r[-1].value)


def test_output_times_that_turn_back_from_the_start_are_named_by_the_callers_index():
    sim = Simulation(_disc(), method="wh", dt=0.02)
    sim.integrate(1.0)
    with pytest.raises(ValueError, match=r"monotonic from the simulation's time 1.0, got 0.5 at "
                                         r"index 0 and 2.0 at index 1"):
        sim.integrate([0.5, 2.0])
    with pytest.raises(ValueError, match=r"from the simulation's time 1.0, got 2.0 at index 0 "
                                         r"and 1.5 at index 1"):
        sim.integrate([2.0, 1.5])  # (backwards from 1.0 with a first time after it)
    sim.integrate(2.5)
    for times, message in (([2.0, 1.0, 1.5], "got 1.5 after 1.0 at index 2"),
                           ([2.0, 1.0, 0.5, 0.7], "got 0.7 after 0.5 at index 3")):
        with pytest.raises(ValueError, match=message):  # (backwards, then turning: the
            sim.integrate(times)  # first time that turns named, not the first two)


def test_a_time_given_in_days_a_few_ulp_from_the_simulations_is_its_own():
    """Days are the unit a Quantity system keeps its time in: a time given in days
    went through no other unit, and is the time asked for, however near (it was
    taken as the simulation's own, a row asked for dropped silently)."""
    s = System.solar_system("J2000", bodies=["sun", "jupiter"])
    sim = Simulation(s, method="wh", dt=4 * u.day)
    sim.integrate(4096 * u.day)
    near = 4096.000000000003
    leg = sim.integrate([near, 4106.0] * u.day)
    assert len(leg.t) == 3 and leg.t[1].to_value(u.day) == near


def test_time_steps_and_state_of_a_quantity_system():
    s = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])
    sim = Simulation(s, method="wh", dt=5 * u.day)
    assert sim.t == 0 * u.day and sim.steps == 0 and sim.system.names == s.names
    leg = sim.integrate(1 * u.yr)
    assert sim.t.unit == u.yr and sim.t == 1 * u.yr and leg.t[0] == 0 * u.yr
    assert sim.steps == leg.steps == 74  # 365.25 / 5 rounded up
    np.testing.assert_array_equal(sim.system.r.value, leg.r[-1].value)
    leg2 = sim.integrate(400 * u.day)  # in days from here on
    assert leg2.t.unit == u.day and leg2.t[0].to_value(u.day) == pytest.approx(365.25)
    with pytest.raises(ValueError, match=r"Expected `t` as a time Quantity"):
        sim.integrate(500.0)
    # (in days, the unit it is kept in: "... time 400.0, got 400.0" named none)
    with pytest.raises(ValueError, match=r"Expected `t` to differ from the simulation's time "
                                         r"400.0 d, got 400.0 d"):
        sim.integrate(400 * u.day)
    with pytest.raises(ValueError, match=r"strictly monotonic from the simulation's time "
                                         r"400.0 d, got 500.0 d at index 0 and 450.0 d"):
        sim.integrate([500, 450] * u.day)  # (backwards from 400 d with a first time after)



def test_quantity_legs_of_one_end_time_reach_the_bits_of_one_call(monkeypatch):
    """A Quantity system continued by scalar end times takes the engine's lean path
    too, in days or in years (the simulation's unit then the end time's, as the
    whole path makes it); the first, which makes the integrator, the whole path; a
    length, the whole path's error.  All give the rows and steps of one call, and
    every trajectory's times are the bits of ``(t_days * u.day).to(unit)``."""
    from hamilton_orbits import engine

    s = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])
    days = [100.0, 250.0, 400.0, 400.0 + 365.25]
    once = Simulation(s, method="wh", dt=5 * u.day).integrate(days * u.day)
    sim = Simulation(s, method="wh", dt=5 * u.day)
    whole = []
    advance = engine.Propagation.advance
    monkeypatch.setattr(engine.Propagation, "advance",
                        lambda self, *a, **k: whole.append(1) or advance(self, *a, **k))
    legs = [sim.integrate(d * u.day) for d in days[:3]]
    assert len(whole) == 1  # (the first leg makes the integrator)
    assert sim.t.unit is u.day and sim.t == 400.0 * u.day
    legs.append(sim.integrate(sim.t.to(u.yr) + 1 * u.yr))  # years: lean too
    assert len(whole) == 1 and legs[-1].t.unit == u.yr and sim.t.unit == u.yr
    with pytest.raises(ValueError, match=r"Expected `t` to be a time"):
        sim.integrate(3 * u.km)  # (not a time: the whole path says so)
    assert sim.t.unit == u.yr
    for k, leg in enumerate(legs):
        rows = slice(k, k + 2)
        assert _same(leg.r.to_value(u.au), once.r[rows].to_value(u.au))
        assert _same(leg.v.to_value(u.au / u.day), once.v[rows].to_value(u.au / u.day))
        assert leg.r.unit == u.au and leg.v.unit == u.au / u.day
        t_days = np.array([0.0, *days])[rows]
        expected = (t_days * u.day).to(leg.t.unit)
        assert leg.t.unit is expected.unit and _same(leg.t.value, expected.value)
    assert sum(leg.steps for leg in legs) == once.steps == sim.steps


@pytest.mark.parametrize("unit", [u.day, u.yr, u.s, u.h, u.min, u.week, u.Myr,
                                  u.Unit("2 day"), u.Unit("1000 yr"), u.Unit("0.001 d")])
def test_a_quantity_trajectorys_times_are_the_bits_of_astropys_conversion(unit):
    """The times of a Quantity trajectory are its days scaled to the caller's unit
    with the bits of ``(t_days * u.day).to(unit)`` (the scale made once per unit)."""
    s = System.solar_system("J2000", bodies=["sun", "jupiter"])
    t = np.array([0.37, 1.5, 2.25]) * (400 * u.day).to(unit)
    traj = integrate(s, t, method="leapfrog", dt=7 * u.day)
    expected = (np.concatenate(([0.0], t.to_value(u.day))) * u.day).to(unit)
    assert traj.t.unit is expected.unit and _same(traj.t.value, expected.value)

def test_backward_legs_continue_and_a_turn_restarts_from_the_state_reached():
    s = _disc()
    sim = Simulation(s, method="radau15")
    sim.integrate(-1.0)
    back = sim.integrate(-2.5)
    once = integrate(s, [-1.0, -2.5])
    assert _same(back.r[-1], once.r[-1]) and sim.t == -2.5
    home = sim.integrate(0.0)  # forwards again: a new integrator from the state reached
    np.testing.assert_allclose(home.r[-1], s.as_arrays().r, rtol=0, atol=1e-9)
    assert home.energy_error[0] == once.energy_error[-1]


def test_repr_names_method_effects_time_and_steps():
    sim = Simulation(_disc(), method="wh", dt=0.02, effects=[GR_POTENTIAL])
    sim.integrate(0.1)
    assert repr(sim).startswith("Simulation(6 bodies, method=WH(coordinates=")
    assert "effects=('gr_potential',), t=0.1, steps=5)" in repr(sim)


@pytest.mark.parametrize("archived", [False, True])
def test_an_error_in_a_leg_keeps_the_state_reached(tmp_path, archived):
    """A leg that ends in an error (here ``max_steps`` reached between two outputs)
    leaves the simulation where its integrator stands, as Ctrl-C does: the next leg
    goes on with the bits of the run never stopped, as does the archive's last
    snapshot, and the next leg's first snapshot holds the state at its time.  (It
    used to keep the time and state of the leg's
    start, or of its last snapshot, so that the next leg returned the integrator's
    later state under the times asked, 3.4 length units off.)"""
    from hamilton_orbits.validation import ConvergenceError

    kw = dict(archive=tmp_path / "a", every_steps=20) if archived else {}
    sim = Simulation(_disc(), method="radau15", max_steps=200, **kw)
    with pytest.raises(ConvergenceError, match="in 200 steps"):
        sim.integrate(100.0)
    t = sim.t
    assert 0.0 < t < 100.0 and sim.steps == 200
    once = Simulation(_disc(), method="radau15").integrate(t + 5.0)
    if archived:
        loaded = Archive(tmp_path / "a")[-1]  # (its last snapshot, before the error; not
        # attached: the simulation goes on writing the archive below)
        assert loaded.t < t and loaded.steps == 180
        assert _same(loaded.integrate(t + 5.0).r[-1], once.r[-1])
    leg = sim.integrate(t + 5.0)
    assert leg.t[0] == t and _same(leg.r[-1], once.r[-1])
    if archived:  # (the second leg's first snapshot: the time and state reached)
        archive = Archive(tmp_path / "a")
        first = archive[list(archive.times).index(t)]
        assert first.t == t and first.steps == 200
        assert _same(first.integrate(t + 5.0).r[-1], once.r[-1])


@pytest.mark.parametrize("kw", [dict(method="radau15"), dict(method="wh", dt=0.02),
                                dict(method="leapfrog", dt=0.02), dict(method="dop853")])
def test_an_error_from_on_output_keeps_the_output_reached(kw):
    """An exception from ``on_output`` ends the leg at that output with the
    simulation standing there (not at the leg's start): the next leg continues with
    the bits of the run that was never stopped."""
    once = Simulation(_disc(), **kw).integrate([1.0, 2.0, 3.0, 4.0])

    def fail(i, steps):
        if i == 2:
            raise RuntimeError("the caller's own error")

    sim = Simulation(_disc(), **kw)
    with pytest.raises(RuntimeError, match="own error"):
        sim.integrate([1.0, 2.0, 3.0, 4.0], on_output=fail)
    assert sim.t == 2.0
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.r[2])
    assert _same(sim.integrate([3.0, 4.0]).r[-1], once.r[-1])


@pytest.mark.parametrize("kw", [dict(method="wh", dt=0.02), dict(method="leapfrog", dt=0.02),
                                dict(method="radau15"), dict(method="dop853")])
def test_a_callback_stands_at_the_output_it_is_told_of(tmp_path, kw):
    """Inside ``on_output`` and ``stop`` the simulation stands at the output reached
    (its time, state and integrator), not at the leg's start: a snapshot saved or a
    copy taken there continues with the bits of the run never stopped.  (Without an
    archive they showed the leg's start beside the current step count: a save at
    t = 2 loaded at t = 0, and wh continued from its t = 2 state under t = 0.)"""
    times = [1.0, 2.0, 3.0, 4.0]
    once = Simulation(_disc(), **kw).integrate(times)
    sim = Simulation(_disc(), **kw)
    seen, copies = [], []

    def on_output(i, steps):
        seen.append((sim.t, sim.steps == steps, _same(sim.system.as_arrays().r, once.r[i]),
                     _same(sim.system.as_arrays().v, once.v[i])))
        if i == 2:
            sim.save(tmp_path / "mid.nc")
            copies.append(sim.copy())

    def stop():
        seen.append(sim.t)
        return False

    whole = sim.integrate(times, on_output=on_output, stop=stop)
    assert _same(whole.r, once.r) and whole.steps == once.steps
    assert seen == [x for t in times for x in ((t, True, True, True), t)]
    for later in (Simulation.load(tmp_path / "mid.nc"), copies[0]):
        assert later.t == 2.0
        rest = later.integrate([3.0, 4.0])
        assert _same(rest.r, once.r[2:]) and _same(rest.v, once.v[2:])
        assert later.steps == once.steps
        # (Hamilton's integrals from time 0: a copy of the first call measured them
        # from its own state, 0.0 at t = 2)
        assert _same(rest.energy_error, once.energy_error[2:])
        assert _same(rest.angular_momentum_error, once.angular_momentum_error[2:])


def test_a_callback_of_a_backward_leg_stands_at_its_output():
    """A backward leg's callback sees the output's time and true velocities."""
    sim = Simulation(_disc(), method="radau15")
    seen = []
    back = sim.integrate([-1.0, -2.0],
                         on_output=lambda i, steps: seen.append((sim.t, sim.system.as_arrays())))
    assert [t for t, _ in seen] == [-1.0, -2.0]
    for (_, s), r, v in zip(seen, back.r[1:], back.v[1:], strict=True):
        assert _same(s.r, r) and _same(s.v, v)


def _same_integrals(a, b) -> bool:
    return all(_same(getattr(a, k), getattr(b, k)) for k in (
        "energy_error", "angular_momentum_error", "barycentre_drift"))


@pytest.mark.parametrize("kw", [dict(method="wh", dt=0.02), dict(method="radau15")])
def test_a_snapshot_of_the_first_call_measures_the_integrals_from_time_0(tmp_path, kw):
    """A simulation loaded from a snapshot taken within its first integrate call (an
    archive's, or one saved from ``on_output``) measures Hamilton's integrals from
    the system at time 0, as the run never stopped does: the same bits.  (It
    measured them from its own first row, 0.0 at the snapshot's time.)"""
    times = [1.0, 2.0, 3.0, 3.5]
    once = Simulation(_disc(), **kw).integrate(times)
    sim = Simulation(_disc(), archive=tmp_path / "a", every=1.0, **kw)
    sim.integrate(times,
                  on_output=lambda i, steps: i == 2 and sim.save(tmp_path / "mid.nc"))
    archive = Archive(tmp_path / "a")
    for later in (archive[list(archive.times).index(2.0)], Simulation.load(tmp_path / "mid.nc")):
        assert later.t == 2.0
        rest = later.integrate([3.0, 3.5])
        assert _same(rest.r, once.r[2:])
        assert _same_integrals(rest, _Rows(once, slice(2, None)))
        assert rest.energy_error[0] != 0.0


@pytest.mark.parametrize("cut", [KeyboardInterrupt, RuntimeError])
@pytest.mark.parametrize("kw", [dict(method="leapfrog", dt=0.05), dict(method="dop853")])
def test_a_first_call_cut_short_measures_the_next_legs_integrals_from_time_0(kw, cut):
    """Ctrl-C (``on_interrupt="raise"``) or an error ending the first integrate call:
    the next leg measures Hamilton's integrals from the system at time 0, as the
    run never cut does (it measured them from the state the cut left)."""
    once = Simulation(_disc(), **kw).integrate([1.0, 2.0, 3.0])
    sim = Simulation(_disc(), **kw)

    def cut_at_2(i, steps):
        if i == 2:
            raise cut

    with pytest.raises(cut):
        sim.integrate([1.0, 2.0, 3.0], on_output=cut_at_2)
    rest = sim.integrate(3.0)
    assert _same(rest.r[-1], once.r[-1])
    assert _same_integrals(rest, _Rows(once, slice(2, None)))


class _Rows:
    """The rows ``rows`` of a trajectory's integrals."""

    def __init__(self, traj, rows):
        for k in ("energy_error", "angular_momentum_error", "barycentre_drift"):
            setattr(self, k, getattr(traj, k)[rows])


@pytest.mark.parametrize(("kw", "end"), [(dict(method="wh", dt=1e-4), 15.0),
                                         (dict(method="leapfrog", dt=1e-4), 15.0),
                                         (dict(method="radau15"), 1e4)])
def test_stop_asked_between_slices_of_steps_sees_the_state_reached(tmp_path, kw, end):
    """``stop()`` asked between two slices of steps (within an output interval) sees
    the simulation at the time its step count is at, with that state, and a
    snapshot saved there loads at that time (it saw the leg's start, t = 0, beside
    100 000 steps)."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    sim = Simulation(s, **kw)
    seen = []

    def stop():
        if not seen:
            seen.append((sim.t, sim.steps, sim.system.as_arrays()))
            sim.save(tmp_path / "between.nc")
        return False

    sim.integrate(end, stop=stop)
    t, steps, state = seen[0]
    assert 0.0 < t < end and steps >= 20_000
    if "dt" in kw:
        assert t == pytest.approx(steps * kw["dt"], rel=1e-12)
    there = Simulation(s, **kw).integrate(t)  # (another run, ending there: radau15's
    # last step is cut to land on t, so to the method's error, not to the bit)
    np.testing.assert_allclose(state.r, there.r[-1], rtol=0, atol=1e-8)
    loaded = Simulation.load(tmp_path / "between.nc")
    assert loaded.t == t and loaded.steps == steps
    assert _same(loaded.integrate(end).r[-1], sim.system.as_arrays().r)  # (the same run)
