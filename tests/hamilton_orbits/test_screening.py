"""hamilton_orbits._screening: numpy's looser test asked before the compiled screen of
close approaches is compiled; it must never rule out what the screen would flag."""

from __future__ import annotations

import warnings

import astropy.units as u
import numpy as np
import pytest
from random_legs import random_leg

from hamilton_orbits import Simulation, System, _screening
from hamilton_orbits._kernels import integrals as k
from hamilton_orbits.integrals import (
    ENCOUNTER_STEP_FRACTION,
    LIGHT,
    UnderResolvedEncounterWarning,
    light_as_massless,
)

_WITH_MOON = ["sun", "mercury", "venus", "earth", "mars", "jupiter", "saturn", "uranus",
              "neptune", "moon"]


def test_numpy_never_rules_out_a_leg_the_screen_flags():
    """On 1500 random legs, forwards and backwards, with and without an exempt body:
    wherever the compiled screen answers True, numpy's test does too (a good share
    of them, so that the comparison is not one of zeros), and it rules out most of
    the legs the screen rules out (it is looser, not useless)."""
    rng = np.random.default_rng(2027)
    flagged = ruled_out = kept_out = 0
    for _ in range(1500):
        r, v, gm, t, step, fraction = random_leg(rng)
        for times in (t, -t):
            for exempt in (-1, int(rng.integers(len(gm)))):
                dist = float(rng.choice([0.0, 0.05]))
                near = _screening.may_be_near(r, v, gm, times, step, (exempt, dist), fraction,
                                              LIGHT)
                maybe = k.screen(r, v, gm, times, step, exempt, dist, fraction, LIGHT)
                assert near or not maybe
                flagged += maybe
                ruled_out += not maybe
                kept_out += not near and not maybe
    assert flagged > 2000 and ruled_out > 2000  # (of 6000: 3152 and 2848)
    assert kept_out > 0.5 * ruled_out


def test_the_primaries_are_the_kernel_s_to_the_bit():
    """numpy's primaries (every body's, the most massive's -1) are those the screen
    finds, on random states and on the solar system with its Moon."""
    rng = np.random.default_rng(7)
    states = [(rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-3, 0.5), rng.normal(size=(n, 3)),
               rng.choice([0.0, 1e-12, 1e-5, 1e-3, 1.0], size=n))
              for n in rng.integers(2, 9, 500)]
    arrays = System.solar_system("J2000", bodies=_WITH_MOON).as_arrays()
    states.append((arrays.r, arrays.v, arrays.gm))
    for r, v, gm in states:
        gm0 = light_as_massless(gm)
        if not gm0.max() > 0:
            continue
        ours = _screening.primaries(r, v, gm0)
        theirs = k.primaries(r, v, gm0, np.empty(len(gm0), np.int64), True)
        assert ours.tolist() == theirs.tolist()
    assert ours.tolist() == [-1] + [0] * 8 + [3]  # (the Moon's the Earth)


@pytest.mark.parametrize("moon", [False, True])
def test_numpy_rules_out_an_ordinary_run_of_the_solar_system(moon):
    """The solar system (with its Moon: the Earth the Moon's primary, the Sun
    beyond every Hill sphere) with wh at 4 d, outputs every 4 d over ten years,
    forwards and backwards, its Sun exempt (wh's democratic-heliocentric kick
    integrates the approaches to it exactly): numpy's test rules it out alone, as
    the screen does, so that a first run of it compiles no screen."""
    system = System.solar_system("J2000", bodies=_WITH_MOON if moon else None)
    sim = Simulation(system, method="wh", dt=4 * u.day)
    gm = sim.system.as_arrays().gm
    for sign in (1, -1):
        traj = Simulation(sim.system, method="wh", dt=4 * u.day).integrate(
            sign * np.arange(1, 914) * 4 * u.day)
        # (writable copies, as a run's own states are: the trajectory's read-only
        # views would compile the kernel again for another type, 3 s)
        r = np.array(traj.r.to_value(u.au))
        v = np.array(traj.v.to_value(u.au / u.day))
        t = np.array(traj.t.to_value(u.day))
        assert not k.screen(r, v, gm, t, 4.0, 0, 0.0, ENCOUNTER_STEP_FRACTION, LIGHT)
        assert not _screening.may_be_near(r, v, gm, t, 4.0, (0, 0.0), ENCOUNTER_STEP_FRACTION,
                                          LIGHT)


class _Counting:
    """The compiled screen, counted, as a process that has not compiled it sees it."""

    def __init__(self):
        self.kernel = k.screen
        self.calls = 0
        self.signatures: list = []

    def __call__(self, *args):
        self.calls += 1
        return self.kernel(*args)


@pytest.fixture
def uncompiled(monkeypatch):
    """A process in which the screen is neither compiled nor on disk."""
    counting = _Counting()
    monkeypatch.setattr(k, "screen", counting)
    monkeypatch.setattr(_screening, "_state", {"ready": False, "looked": True, "calls": 0})
    return counting


def _comet():
    """A comet (q = 0.006, GM 1 units) 1.559 before its periapsis: stepped by leapfrog
    at 0.01 to t = 10, its passage goes under-resolved (as in
    ``test_simulation.py``'s test of its date)."""
    from hamilton_orbits import Body, KeplerOrbit

    orb = KeplerOrbit.from_elements(a=3.0, e=1 - 0.006 / 3.0, inc=0.3, lan=0.2, argp=0.1,
                                    M=-0.3, mu=1.0)
    r, v = orb.state()
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("comet", 0.0, list(r), list(v))])


def test_a_first_run_asks_the_screen_only_where_numpy_cannot_rule_it_out(uncompiled):
    """An ordinary first wh run is ruled out by numpy alone (the screen not called:
    not compiled); a run with an under-resolved perihelion passage asks the screen
    and warns as before; after :data:`PREFILTER_CALLS` calls (a loop of calls) the
    screen answers alone."""
    sun_jupiter = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Simulation(sun_jupiter, method="wh", dt=10 * u.day).integrate(1000 * u.day)
    assert uncompiled.calls == 0
    with pytest.warns(UnderResolvedEncounterWarning, match="comet"):
        Simulation(_comet(), method="leapfrog", dt=0.01).integrate(10.0)
    asked = uncompiled.calls  # (by the check after the leg, and by the whole check)
    assert asked > 0
    sim = Simulation(sun_jupiter, method="wh", dt=10 * u.day)
    _screening._state["calls"] = 0
    for _ in range(_screening.PREFILTER_CALLS):
        sim.integrate(sim.t + 10 * u.day)
    assert uncompiled.calls == asked
    sim.integrate(sim.t + 10 * u.day)  # (the screen from then on)
    sim.integrate(sim.t + 10 * u.day)
    assert uncompiled.calls == asked + 2


def test_a_nan_is_left_to_the_screen():
    """A NaN GM or time, which the screen's comparisons pass over and numpy's do not:
    numpy defers to the screen (a NaN GM of a third body hid the approach of the
    first two on a first run)."""
    t = np.array([0.0, 1.0])
    r = np.zeros((2, 3, 3))
    v = np.zeros((2, 3, 3))
    r[:, 1, 0], v[:, 1, 1], r[:, 2, 0], v[:, 2, 1] = 0.01, 20.0, 5.0, 0.3
    none = (-1, 0.0)
    assert _screening.may_be_near(r, v, np.array([1.0, 0.0, np.nan]), t, 0.1, none, 1 / 30,
                                  LIGHT)
    assert _screening.may_be_near(r, v, np.array([1.0, 0.0, 1e-3]), np.array([0.0, np.nan]),
                                  0.1, none, 1 / 30, LIGHT)
    assert k.screen(r, v, np.array([1.0, 0.0, np.nan]), t, 0.1, -1, 0.0, 1 / 30, LIGHT)


def test_on_disk_looks_at_numba_s_cache(tmp_path, monkeypatch):
    """False for a cached kernel not compiled yet (a module of its own, new), True
    once compiled into the cache, and True where there is no cache to look at."""
    import importlib

    from numba import njit

    from hamilton_orbits._kernels.entry import on_disk

    (tmp_path / "tiny_kernel.py").write_text(
        "from numba import njit\n\n\n@njit(cache=True)\ndef f(x):\n    return x + 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    tiny = importlib.import_module("tiny_kernel")
    assert not on_disk(tiny.f, (1.0,))
    assert tiny.f(1.0) == 2.0
    assert on_disk(tiny.f, (1.0,)) and not on_disk(tiny.f, (1,))  # (int64: not compiled)
    assert on_disk(njit(cache=False)(lambda x: x + 1), (1.0,))
