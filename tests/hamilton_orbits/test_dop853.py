"""DOP853's step budget: scipy's solver takes none, so a run of far too many steps
(a step far shorter than the span) used to run for ever; it now stops with a
ConvergenceError naming ``max_steps``, at the budget or as soon as its pace projects
more than 100 times the budget, on each of DOP853's paths (plain, with events,
with the variational equations)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits.integrators.methods import DOP853
from hamilton_orbits.validation import ConvergenceError


def _pair() -> System:
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0], radius=1e-3),
                   Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0], radius=1e-5)])


@pytest.mark.parametrize("kw", [{}, {"events": [{"name": "collision", "action": "stop"}]},
                                {"variational": True}], ids=["plain", "events", "variational"])
def test_a_run_beyond_the_step_budget_stops_naming_max_steps(kw):
    # 2 pi / 1000 per orbit at tol 1e-12 is some 50 steps an orbit: 1e4 orbits are
    # ~5e5 steps, 5000 times a budget of 100
    Simulation(_pair(), method="dop853", **kw).integrate(0.1)  # (compiled before the clock)
    sim = Simulation(_pair(), method=DOP853(max_steps=100), **kw)
    start = time.perf_counter()
    with pytest.raises(ConvergenceError, match=r"dop853 reached t = .* of 62831.8\d* in "
                                               r"\d+ steps; at this pace the run needs about "
                                               r".* more than max_steps = 100"):
        sim.integrate(2e4 * np.pi)
    # stopped at its first check, not after hours (the run compiled above; 60 s: a
    # machine busy with other work)
    assert time.perf_counter() - start < 60.0


@pytest.mark.parametrize("kw", [{}, {"events": [{"name": "collision", "action": "stop"}]},
                                {"variational": True}], ids=["plain", "events", "variational"])
def test_max_steps_below_the_pace_check_is_exact(kw):
    """``max_steps`` held exactly below the pace check's 100 steps: a run of ``n``
    steps completes with ``max_steps = n`` and stops naming it with ``n - 1`` (one
    orbit with max_steps=10 took 44 steps and returned)."""
    n = Simulation(_pair(), method="dop853", **kw).integrate(2 * np.pi).steps
    assert 10 < n < 100
    assert Simulation(_pair(), method=DOP853(max_steps=n), **kw).integrate(2 * np.pi).steps == n
    for cap in (10, n - 1):
        sim = Simulation(_pair(), method=DOP853(max_steps=cap), **kw)
        with pytest.raises(ConvergenceError, match=rf"dop853 reached t = .* in {cap} steps; "
                                                   rf".* more than max_steps = {cap} "):
            sim.integrate(2 * np.pi)


def test_a_run_within_the_budget_is_unchanged():
    """The budget only counts: the same run with and without a tight-enough budget
    gives the same bits."""
    free = Simulation(_pair(), method="dop853").integrate(10.0)
    capped = Simulation(_pair(), method=DOP853(max_steps=1000)).integrate(10.0)
    np.testing.assert_array_equal(free.r, capped.r)
    assert free.steps == capped.steps < 1000


def test_max_steps_is_checked_naming_it():
    with pytest.raises(ValueError, match=r"Expected `max_steps` to be a positive integer, got 0"):
        DOP853(max_steps=0)


def test_solve_in_one_integration_is_scipys_dense_solution_output_by_output():
    """``solve(restart=False)`` (rigid's DOP853) steps scipy's DOP853 itself: each
    output, read as its step passes it, is bit for bit what ``solve_ivp(...,
    dense_output=True)`` gives there (an output on a step's end taken from the step
    ending there, as scipy's ``OdeSolution`` does), forwards and backwards;
    ``on_output`` is called as the steps pass each output (a progress bar moved
    only at the end), and the dense output is made only for steps that hold one."""
    from scipy.integrate import solve_ivp

    from hamilton_orbits.integrators.dop853 import solve

    calls = []

    def pendulum(t, y):
        calls.append(t)
        return np.array([y[1], -np.sin(y[0]) + 0.1 * np.cos(0.7 * t)])

    for t_out in (np.linspace(0.0, 40.0, 23), -np.linspace(0.0, 25.0, 9),
                  np.array([0.0, 1e-9, 0.5, 0.5 + 1e-12, 30.0])):
        calls.clear()
        seen = []
        y, steps, nfev = solve(pendulum, np.array([1.0, 0.0]), t_out, rtol=1e-10, atol=1e-12,
                               restart=False, on_output=lambda i, n, seen=seen: seen.append(
                                   len(calls)))
        total = len(calls)
        ref = solve_ivp(pendulum, (t_out[0], t_out[-1]), [1.0, 0.0], method="DOP853",
                        rtol=1e-10, atol=1e-12, dense_output=True)
        np.testing.assert_array_equal(y[1:], ref.sol(t_out[1:]).T)
        assert steps == ref.t.size - 1 and nfev == total < ref.nfev
        assert len(seen) == len(t_out) - 1 and seen[0] < total // 2 and seen == sorted(seen)


def test_a_body_at_1e300_sets_its_tolerance_without_overflow():
    # its |r| as norm(): the squares overflowed to inf (numpy's overflow warning, an
    # error in this suite) and its absolute tolerance with them; by hypot it is 1e300
    # (a tenth of the way in float64 headroom: tol * 1e300 is finite)
    from hamilton_orbits import System, integrate

    s = System.from_arrays([1.0, 1e-3], [[0, 0, 0], [1e300, 0, 0]], [[0, 0, 0], [0, 1, 0]])
    run = integrate(s, 1.0, method="dop853")
    # (y = t exactly, no force at 1e300; the stage sums of the step round: a few ulp)
    np.testing.assert_allclose(run.r[-1], [[0.0, 0.0, 0.0], [1e300, 1.0, 0.0]],
                               rtol=4 * np.finfo(float).eps, atol=0)
