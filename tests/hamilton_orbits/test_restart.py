"""Simulation.save / Simulation.load: a saved simulation continues bit for bit.

The reference of every test here is the simulation that was never saved: loading
its snapshot in a fresh build and integrating on must give the same bits
(positions, velocities, steps, the integrals' errors measured from time 0, MEGNO,
the STM, the events found) for every method, with effects, events that merge
bodies and the variational equations (restart.py, snapshot.py).
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from test_simulation_legs import _disc, _merging, _same, _variants

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits._saving import RestartWarning
from hamilton_orbits.restart import LayoutMismatch, flatten, restore
from hamilton_orbits.snapshot import SnapshotError, read, write


@pytest.mark.parametrize(("system", "kw"), list(_variants()))
def test_a_loaded_simulation_continues_with_the_bits_of_the_saved_one(system, kw, tmp_path):
    sim = Simulation(system(), **kw)
    sim.integrate(1.7)  # the merge (about t = 1.4) happens before the save
    sim.save(tmp_path / "sim.nc")
    again = Simulation.load(tmp_path / "sim.nc")
    assert again.t == sim.t and again.steps == sim.steps and again.method == sim.method
    assert again.system.names == sim.system.names
    a, b = sim.integrate([2.9, 4.0]), again.integrate([2.9, 4.0])
    for name in ("r", "v", "energy_error", "angular_momentum_error", "barycentre_drift",
                 "megno", "lyapunov", "stm"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None and y is None) or _same(x, y), name
    assert a.steps == b.steps and sim.steps == again.steps
    assert list(a.events["time"]) == list(b.events["time"])
    if "events" in kw:
        assert sim.system.names == again.system.names == ("a", "c")  # merged before the save


def test_a_simulation_saved_before_its_first_step_is_the_new_one(tmp_path):
    sim = Simulation(_disc(), method="radau15")
    sim.save(tmp_path / "fresh.nc")
    a = Simulation.load(tmp_path / "fresh.nc").integrate(3.0)
    b = sim.integrate(3.0)
    assert _same(a.r, b.r) and _same(a.energy_error, b.energy_error)


def test_a_quantity_simulation_keeps_its_units_and_bits(tmp_path):
    gm_sun = 1.32712440041e20 * u.m**3 / u.s**2  # DE440's, to 12 digits
    s = System([Body("sun", gm_sun, [0, 0, 0] * u.au, [0, 0, 0] * u.km / u.s),
                Body("earth", 3.986004e14 * u.m**3 / u.s**2, [1, 0, 0] * u.au,
                     [0, 29.78, 0] * u.km / u.s)])
    sim = Simulation(s, method="wh", dt=1 * u.day, effects=[{"name": "gr_potential"}])
    sim.integrate(0.5 * u.yr)
    sim.save(tmp_path / "q.nc")
    again = Simulation.load(tmp_path / "q.nc")
    assert again.t == sim.t and again.t.unit == u.yr
    a, b = sim.integrate(1 * u.yr), again.integrate(1 * u.yr)
    assert _same(a.r.value, b.r.value) and b.r.unit == u.au
    np.testing.assert_array_equal(again.system.as_arrays().gm, sim.system.as_arrays().gm)


def test_a_backward_leg_is_saved_in_its_direction(tmp_path):
    sim = Simulation(_disc(), method="radau15")
    sim.integrate(-2.0)
    sim.save(tmp_path / "back.nc")
    a, b = sim.integrate(-3.5), Simulation.load(tmp_path / "back.nc").integrate(-3.5)
    assert _same(a.r, b.r) and a.steps == b.steps


@pytest.mark.parametrize(("method", "kw"), [
    ("radau15", dict(effects=[{"name": "gr", "c": 30.0}])), ("wh", dict(dt=0.02)),
    ("dop853", dict(tol=1e-12, effects=[{"name": "gr", "c": 30.0}])),
    ("leapfrog", dict(dt=0.002))])
def test_a_backward_variational_run_saved_and_continued_has_one_calls_bits(method, kw,
                                                                         tmp_path):
    """The variational equations backwards (the time-reversed motion's tangent
    vectors, the STM turned back at the outputs): a run saved at t = -1.5 and
    loaded continues with the bits of the saved one, and both with those of one
    call through the same times (positions, MEGNO, the STM)."""
    def fresh():
        return Simulation(_disc(), method=method, variational=True, stm=True, **kw)

    sim = fresh()
    sim.integrate(-1.5)
    sim.save(tmp_path / "back.nc")
    a = sim.integrate([-2.0, -3.0])
    b = Simulation.load(tmp_path / "back.nc").integrate([-2.0, -3.0])
    one = fresh().integrate([-1.5, -2.0, -3.0])
    for name in ("r", "v", "megno", "lyapunov", "stm"):
        assert _same(getattr(a, name), getattr(b, name)), name
        assert _same(getattr(a, name), getattr(one, name)[1:]), name


def test_what_a_build_makes_is_not_read_back():
    sim = Simulation(_merging(), method="radau15")
    sim.integrate(0.5)
    layout, arrays = flatten(sim._prop)
    attrs = layout["attrs"]
    assert attrs["rhs"] == attrs["method"] == attrs["module"] == {"built": True}
    # the addresses of the compiled right-hand side differ between processes
    assert attrs["driver"]["attrs"]["accel"] == {"built": True}
    assert all(a.dtype != np.int64 or a.shape != (2,) for a in arrays)


@pytest.mark.parametrize("kw", [dict(), dict(effects=[{"name": "gr", "c": 50.0},
                                                {"name": "j2", "body": "star"}]),
                                dict(events=[{"name": "close_encounter", "distance": 0.5}])],
                         ids=["newton", "gr+j2", "events"])
def test_radau15s_b_and_g_are_working_space_not_state(kw):
    """A step's ``b`` and ``g`` are written from the last step's ``br`` and ``d``
    before they are read (``_kernels.radau15._begin``), so a snapshot leaves them
    out: garbage put in them between two calls changes no bit of what follows."""
    sim, plain = Simulation(_disc(), method="radau15", **kw), Simulation(_disc(), method="radau15",
                                                                         **kw)
    sim.integrate(1.3)
    plain.integrate(1.3)
    driver = sim._prop.driver
    rng = np.random.default_rng(5)
    for a in driver.scratch:
        a[...] = rng.normal(size=a.shape) * 1e3
    driver.scratch[0][3, 4] = np.nan
    a, b = sim.integrate([2.9, 4.0]), plain.integrate([2.9, 4.0])
    assert _same(a.r, b.r) and _same(a.v, b.v) and a.steps == b.steps
    _, arrays = flatten(sim._prop)
    assert not any(x is y for x in arrays for y in driver.scratch)
    assert sum(x is y for x in arrays for y in driver.work) == 2  # br and d are state


def test_a_radau15_snapshot_holding_b_and_g_continues_bit_for_bit():
    """``data/snapshot-radau15-71a03d1.nc`` was saved by the version of commit 71a03d1,
    when radau15's state held ``b`` and ``g`` (``work`` four arrays): the system
    below, radau15 at its default tolerance, ``integrate(10.0)``, ``save``.  This
    version takes its ``br`` and ``d`` and continues with the bits of a run that was
    never saved (no ``RestartWarning``: the warnings are errors in the tests)."""
    from pathlib import Path

    def system() -> System:
        return System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]),
                       Body("inner", 1e-3, [1.0, 0, 0], [0, 1.0, 0.01]),
                       Body("outer", 3e-4, [0, 2.1, 0], [-0.69, 0, 0])])

    path = Path(__file__).parent / "data" / "snapshot-radau15-71a03d1.nc"
    meta, _ = read(path)
    assert len(meta["layout"]["attrs"]["driver"]["attrs"]["work"]["items"]) == 4
    ref = Simulation(system(), method="radau15")
    ref.integrate(10.0)
    sim = Simulation.load(path)
    assert sim.t == ref.t and sim.steps == ref.steps
    a, b = sim.integrate([15.0, 20.0]), ref.integrate([15.0, 20.0])
    assert _same(a.r, b.r) and _same(a.v, b.v) and a.steps == b.steps
    assert len(sim._prop.driver.work) == 2


def test_a_layout_of_other_internals_is_refused():
    sim = Simulation(_disc(), method="wh", dt=0.02)
    sim.integrate(0.5)
    layout, arrays = flatten(sim._prop)
    layout["attrs"]["driver"]["attrs"]["renamed"] = layout["attrs"]["driver"]["attrs"].pop("dt")
    fresh = Simulation(_disc(), method="wh", dt=0.02)
    fresh._prop.driver_for(False)
    with pytest.raises(LayoutMismatch, match=r"state.driver: saved attributes .*'renamed'"):
        restore(fresh._prop, layout, arrays)
    other = Simulation(_disc(), method="leapfrog", dt=0.02)
    other._prop.driver_for(False)
    with pytest.raises(LayoutMismatch, match=r"saved 'hamilton_orbits.integrators.wh._State'"):
        restore(other._prop, flatten(sim._prop)[0], arrays)


def test_load_names_a_missing_or_foreign_file(tmp_path):
    with pytest.raises(SnapshotError, match=r"no snapshot file .*nothing.nc"):
        Simulation.load(tmp_path / "nothing.nc")
    (tmp_path / "other.nc").write_bytes(b"CDF\x01" + b"\0" * 60)
    with pytest.raises(SnapshotError, match=r"other.nc"):
        Simulation.load(tmp_path / "other.nc")


@pytest.mark.parametrize("system", [_disc, _merging], ids=["disc", "merged"])
def test_a_snapshot_of_other_internals_continues_from_its_state_with_a_warning(system,
                                                                              tmp_path):
    """A snapshot whose integrator state this version cannot take (written by a
    version with other internals) is continued from its physical state."""
    kw = {"events": [{"name": "collision", "action": "merge"}]} if system is _merging else {}
    sim = Simulation(system(), method="radau15", **kw)
    sim.integrate(1.7)
    sim.save(tmp_path / "s.nc")
    meta, arrays = read(tmp_path / "s.nc")
    attrs = meta["layout"]["attrs"]
    attrs["renamed"] = attrs.pop("tol")  # as another version's Propagation would be
    write(tmp_path / "s.nc", meta, arrays)
    with pytest.warns(RestartWarning, match=r"another version .* not bit for bit"):
        again = Simulation.load(tmp_path / "s.nc")
    assert again.t == sim.t and again.steps == sim.steps
    assert again.system.names == sim.system.names
    np.testing.assert_array_equal(again.system.as_arrays().r, sim.system.as_arrays().r)
    a, b = sim.integrate(4.0), again.integrate(4.0)
    # radau15 from the same state with a fresh first step: the method's accuracy
    np.testing.assert_allclose(b.r[-1], a.r[-1], rtol=0, atol=1e-10)
