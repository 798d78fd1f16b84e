"""hamilton_orbits.integrals: the check of close approaches a fixed step was too long
for, whose compiled screen must find every one the whole check finds."""

from __future__ import annotations

import warnings

import astropy.units as u
import numpy as np
import pytest
from random_legs import random_leg

from hamilton_orbits._kernels import integrals as k
from hamilton_orbits._screening import output_steps
from hamilton_orbits.integrals import (
    ENCOUNTER_STEP_FRACTION,
    LIGHT,
    accelerations_quaternion,
    energy_gm,
    energy_gm_many,
    integral_errors,
    light_as_massless,
)


def _whole_count(r, v, gm, t, step, exempt, exempt_dist, fraction):
    """The count of the whole check (primaries, pruning and all), without the screen."""
    gm0 = light_as_massless(gm)
    top = int(np.argmax(gm0))
    tp = np.array([i for i in range(len(gm)) if i != top], np.int64)
    m = np.flatnonzero(gm0 > 0)
    h = output_steps(t, step)
    prim = k.primaries(r[0], v[0], gm0, np.empty(len(gm), np.int64), True)
    bad = np.zeros((1, len(tp), len(m)), np.bool_)
    none = np.empty((0, 0, 0))
    return k.approaches(r, v, gm0, t, tp, m, prim, exempt, exempt_dist, h, fraction, bad,
                        none, none)


def test_the_screen_passes_every_leg_the_whole_check_finds_approaches_in():
    """The screen rules a leg out by a test without the primaries (which only take
    flags away), in squares: on 3000 random legs of 2 to 6 bodies (test particles,
    bodies as light as ``LIGHT`` and massive ones, close pairs passing between
    outputs, exempt central bodies or none) it passes every leg in which the whole
    check finds an approach (a good share of them, so that the comparison is not one
    of zeros), and rules out most of the others.  The same states at times run
    backwards (``-t``) likewise; and each leg's mirror (velocities reversed, run
    backwards: the same passages) gives both the same answers, to the bit (a run
    backwards looked for a closest point between outputs where the radial velocity
    turned from negative to positive: where the pair recedes, going back in time)."""
    rng = np.random.default_rng(2026)
    found = passed = back_found = back_passed = 0
    for _ in range(3000):
        r, v, gm, t, step, fraction = random_leg(rng)
        exempt = int(rng.integers(-1, len(gm)))
        exempt_dist = float(rng.choice([0.0, 0.05]))
        args = (step, exempt, exempt_dist, fraction)
        whole = _whole_count(r, v, gm, t, *args)
        maybe = k.screen(r, v, gm, t, *args, LIGHT)
        assert maybe or whole == 0
        found += whole > 0
        passed += maybe
        back = _whole_count(r, v, gm, -t, *args)  # (the same states, backwards)
        back_maybe = k.screen(r, v, gm, -t, *args, LIGHT)
        assert back_maybe or back == 0
        back_found += back > 0
        back_passed += back_maybe
        mirror = np.ascontiguousarray(-v)  # (the same passages, backwards)
        assert _whole_count(r, mirror, gm, -t, *args) == whole
        assert k.screen(r, mirror, gm, -t, *args, LIGHT) == maybe
    for f, p in ((found, passed), (back_found, back_passed)):
        assert 300 < f < 2700
        assert p - f < 0.5 * (3000 - f)  # (the ones it lets through in vain)


@pytest.mark.parametrize("sign", [1, -1])
def test_the_screen_rules_out_the_legs_of_an_ordinary_run(sign):
    """The solar system with wh at 4 d (Mercury's period / 22), legs of one step: the
    screen alone answers for every one (a screen by the time scale alone let every
    leg through, the inner planets being "near" for a step that long, so that the
    whole check ran after each call: the Hill spheres rule them out); backwards
    (``sign`` -1) too."""
    import astropy.units as u

    from hamilton_orbits import Simulation, System

    sim = Simulation(System.solar_system("J2000"), method="wh", dt=4 * u.day)
    gm = sim.system.as_arrays().gm
    for _ in range(200):
        traj = sim.integrate(sim.t + sign * 4 * u.day)
        r, v = traj.r.to_value(u.au), traj.v.to_value(u.au / u.day)
        t = traj.t.to_value(u.day)
        # (writable copies, as a run's own states are: the trajectory's read-only
        # views would compile the kernel again for another type, 3 s)
        assert not k.screen(np.array(r), np.array(v), gm, np.array(t), 4.0, 0,
                            0.0, ENCOUNTER_STEP_FRACTION, LIGHT)


def test_accelerations_quaternion_converts_quantities_and_returns_them():
    """Quantities in, Quantities out (au/day^2, as ``System.accelerations``): a km read
    as an au gave a plain [[1, 0, 0], [-1, 0, 0]]; a plain number beside a Quantity is
    refused, as everywhere."""
    gm = [1.0, 1.0] * u.au**3 / u.day**2
    acc = accelerations_quaternion([[0.0, 0, 0], [1.0, 0, 0]] * u.km, gm)
    km = (1.0 * u.km).to_value(u.au)
    assert acc.unit == u.au / u.day**2
    np.testing.assert_allclose(acc.value, [[1 / km**2, 0, 0], [-1 / km**2, 0, 0]], rtol=1e-14)
    with pytest.raises(ValueError, match="`gm` to be a Quantity like `r`"):
        accelerations_quaternion([[0.0, 0, 0], [1.0, 0, 0]] * u.km, [1.0, 1.0])
    plain = accelerations_quaternion([[0.0, 0, 0], [1.0, 0, 0]], [1.0, 1.0])
    assert type(plain) is np.ndarray


@pytest.mark.parametrize(("r", "gm", "message"), [
    ([[0.0, 0, 0], [1.0, 0, 0]], [1.0, -1.0], r"`gm` >= 0, got -1.0 at index 1"),
    ([[0.0, 0, 0], [0.0, 0, 0]], [1.0, 1.0], r"indices 0 and 1 of `r` are at one position"),
    ([[0.0, 0, 0], [np.nan, 0, 0]], [1.0, 1.0], r"`r` to be finite, got nan at index \(1, 0\)"),
    ([[0.0, 0, 0], [1.0, 0, 0]], [1.0, 1.0, 1.0], r"`gm` .*\(3,\).*`r` .*\(2, 3\)"),
    ([0.0, 0, 0], [1.0], r"`gm` .*\(1,\).*`r` .*\(3,\)"),
])
def test_accelerations_quaternion_names_the_argument_index_and_value(r, gm, message):
    """A negative GM was taken; two bodies at one point were blamed on ``self``, a NaN
    on ``vector`` at the wrong index; a ``gm`` too long was an IndexError."""
    with pytest.raises(ValueError, match=message):
        accelerations_quaternion(r, gm)


def _states():
    """Three states of two bodies (n_t, n, 3), their GMs and times."""
    r = np.array([[[0.0, 0, 0], [1.0, 0, 0]]] * 3)
    v = np.zeros((3, 2, 3))
    v[:, 1, 1] = 1.0
    return r, v, np.array([1.0, 1.0]), np.arange(3.0)


@pytest.mark.parametrize(("change", "message"), [
    (lambda r, v, gm, t: (r, v[:2], gm, t), r"`v` .*\(3, 2, 3\).*\(2, 2, 3\)"),
    (lambda r, v, gm, t: (r, v[:, :1], gm, t), r"`v` .*\(3, 2, 3\).*\(3, 1, 3\)"),
    (lambda r, v, gm, t: (r, v, gm, t[:2]), r"`t` to have shape \(3,\).*got \(2,\)"),
    (lambda r, v, gm, t: (r, v, gm[:1], t), r"`gm` to have shape \(2,\).*got \(1,\)"),
    (lambda r, v, gm, t: (r, v, np.array([1.0, np.nan]), t),
     r"`gm` to be finite, got nan at index 1"),
    (lambda r, v, gm, t: (r, v, np.array([1.0, -1.0]), t), r"`gm` >= 0, got -1.0 at index 1"),
    (lambda r, v, gm, t: (r, v, gm, np.array([0.0, np.inf, 2.0])),
     r"`t` to be finite, got inf at index 1"),
    (lambda r, v, gm, t: (r[:0], v[:0], gm, t[:0]), r"`r` to have shape \(n_t, n, 3\)"),
    (lambda r, v, gm, t: (r[..., :2], v[..., :2], gm, t), r"`r` to have shape \(n_t, n, 3\)"),
])
def test_integral_errors_refuses_mismatched_or_bad_input_before_its_kernel(change, message):
    """A ``v`` of fewer outputs than ``r`` was read past its end by the compiled kernel
    (numbers out), a ``t`` too short gave a NaN, a ``v`` of fewer bodies numbers, a
    ``gm`` too short an IndexError, a NaN in ``gm`` "argmax of an empty sequence"."""
    with pytest.raises(ValueError, match=message):
        integral_errors(*change(*_states()))


def test_integral_errors_refuses_extra_energy_and_gone_of_the_wrong_shape():
    r, v, gm, t = _states()
    with pytest.raises(ValueError, match=r"`extra_energy` to have shape \(3, 2\).*got \(3, 1\)"):
        integral_errors(r, v, gm, t, np.zeros((3, 1)))
    with pytest.raises(ValueError, match=r"`gone` to have shape \(2,\).*got \(3,\)"):
        integral_errors(r, v, gm, t, gone=np.zeros(3, bool))


def test_energy_gm_many_refuses_mismatched_shapes_and_coinciding_bodies():
    """A ``v`` of one body for two gave numbers; two massive bodies at one point were
    counted as 1 apart."""
    r, v, gm, _ = _states()
    with pytest.raises(ValueError, match=r"`v` .*\(3, 2, 3\).*\(3, 1, 3\)"):
        energy_gm_many(r, v[:, :1], gm)
    with pytest.raises(ValueError, match=r"`gm` to have shape \(2,\) or \(3, 2\)"):
        energy_gm_many(r, v, np.ones((2, 2)))
    r[2, 1] = r[2, 0]
    with pytest.raises(ValueError, match=r"indices 0 and 1 of `r` are at one position "
                                         r"\[0.0, 0.0, 0.0\] at output 2"):
        energy_gm_many(r, v, gm)


def test_energy_gm_refuses_coinciding_bodies_and_bad_input_without_a_warning():
    """Two bodies at one point gave numpy's divide-by-zero RuntimeWarning and an
    infinite energy."""
    r, v, gm, _ = _states()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"indices 0 and 1 of `r` are at one position"):
            energy_gm(np.zeros((2, 3)), v[0], gm)
        with pytest.raises(ValueError, match=r"`r` to be finite, got nan at index \(1, 0\)"):
            energy_gm(np.array([[0.0, 0, 0], [np.nan, 0, 0]]), v[0], gm)
        with pytest.raises(ValueError, match=r"`gm` to have shape \(2,\).*got \(1,\)"):
            energy_gm(r[0], v[0], gm[:1])
        with pytest.raises(ValueError, match=r"`v` .*\(2, 3\).*\(1, 3\)"):
            energy_gm(r[0], v[0, :1], gm)
    # (a test particle at the massive body's point adds no potential: taken)
    assert energy_gm(np.zeros((2, 3)), v[0], np.array([1.0, 0.0])) == 0.0


def test_integral_errors_compiles_one_type_whatever_the_inputs_writability():
    """A trajectory's arrays are read-only, a run's own states and a merged run's G m
    writable: each mix was another type of the kernel's inputs, compiled again (1.3-1.7
    s a time).  They reach it as read-only views, one type; the same errors."""
    rng = np.random.default_rng(5)
    r = rng.normal(size=(4, 3, 3))
    v = rng.normal(size=(4, 3, 3))
    gm = np.array([1.0, 1e-3, 2e-3])
    t = np.arange(4.0)
    frozen = [a.copy() for a in (r, v, gm, t)]
    for a in frozen:
        a.flags.writeable = False
    before = set(k.integral_errors.signatures)
    plain = integral_errors(r, v, gm, t)
    mixed = integral_errors(frozen[0], v, frozen[2], t)
    read_only = integral_errors(*frozen)
    for errors in (mixed, read_only):
        for a, b in zip(errors, plain, strict=True):
            np.testing.assert_array_equal(a, b)
    added = set(k.integral_errors.signatures) - before
    assert all(all(x.mutable is False for x in sig[:5]) for sig in added), added
