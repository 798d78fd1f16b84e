"""Ctrl-C in a compiled stepping call (``hamilton_orbits.integrators._held``).

CPython runs a pending signal's Python handler at the end of the call instruction
that was running when it came: after a compiled kernel has stepped the state's
arrays in place, before the driver has counted the steps and the time it reached.
The in-process tests wrap each driver's kernel so that, once it has returned,
Python's SIGINT handler runs there, as CPython runs it: what the handler does (raise,
or hold until the counts are taken) is the package's.  The subprocess test sends a
real SIGINT to a real run.  In both, the simulation kept after the Ctrl-C
continues with the bits and the step count of the run never interrupted: before,
a ``wh`` run went on from a state a slice ahead of its clock (19 au off over 6000
time units), ``radau15`` counted a slice of steps too few.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits._kernels import leapfrog as leapfrog_kernels
from hamilton_orbits._kernels import radau15 as radau15_kernels
from hamilton_orbits._kernels import radau15_dd, variational, wh_tangent
from hamilton_orbits._kernels import wh as wh_kernels
from hamilton_orbits.integrators import leapfrog, radau15, wh
from hamilton_orbits.integrators._held import HELD

DT = 1 / 64  # (a power of two: the slices' times t0 + k dt are exact)


def _pressing(real, when):
    """``real`` wrapped so that after a call whose result ``when(out)`` picks,
    Python's SIGINT handler runs, as CPython runs it as a compiled call returns
    (what the handler then does is the package's)."""
    def wrapper(*args):
        out = real(*args)
        if when(out):
            signal.getsignal(signal.SIGINT)(signal.SIGINT, None)
        return out
    return wrapper


def _nth(n, calls):
    """A ``when`` of :func:`_pressing` picking the ``n``-th call (counted in ``calls``)."""
    def when(out):
        calls.append(1)
        return len(calls) == n
    return when


def _first(found, pressed):
    """A ``when`` picking the first call whose result ``found(out)`` picks."""
    def when(out):
        if found(out) and not pressed:
            pressed.append(1)
            return True
        return False
    return when


def _planets(n: int = 4) -> System:
    rng = np.random.default_rng(5)
    bodies = [Body("star", 1.0, [0, 0, 0], [0, 0, 0])]
    for k, a in enumerate(np.linspace(1.0, 3.0, n - 1)):
        ph = rng.uniform(0, 2 * np.pi)
        bodies.append(Body(f"p{k}", 1e-4, [a * np.cos(ph), a * np.sin(ph), 0.01 * k],
                           [-np.sin(ph) / np.sqrt(a), np.cos(ph) / np.sqrt(a), 0.0]))
    return System(bodies)


#: (Simulation options, the kernels' module and names to wrap, the driver's module
#: whose SLICE is made small: several calls to the first end time)
CASES = {
    "radau15": (dict(method="radau15"), radau15_kernels, ["advance"], radau15, 8),
    "radau15-dd": (dict(method="radau15", dt=1 / 8, precision="double-double"), radau15_dd,
                   ["advance"], radau15, 300),
    "wh": (dict(method="wh", dt=DT), wh_kernels, ["advance_dh", "advance_dh_few"], wh, 50),
    "wh-jacobi-corrected": (dict(method="wh", dt=DT, coordinates="jacobi", corrector=11),
                            wh_kernels, ["advance_jacobi", "advance_jacobi_few"], wh, 50),
    "leapfrog": (dict(method="leapfrog", dt=DT), leapfrog_kernels, ["advance"], leapfrog, 50),
    "radau15-variational": (dict(method="radau15", variational=True), radau15_kernels,
                            ["advance_variational"], radau15, 8),
    "wh-variational": (dict(method="wh", dt=DT, variational=True), wh_tangent,
                       ["advance_dh", "advance_jacobi"], wh, 50),
    "leapfrog-variational": (dict(method="leapfrog", dt=DT, variational=True), variational,
                             ["advance_leapfrog"], leapfrog, 50),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_ctrl_c_in_a_compiled_call_keeps_a_state_that_continues_bit_for_bit(case,
                                                                            monkeypatch):
    options, kernels, names, driver, slice_steps = CASES[case]
    monkeypatch.setattr(driver, "SLICE", slice_steps)  # (wh's bits depend on the slices:
    once = Simulation(_planets(), **options)  # the same in both runs)
    once.integrate(12.0)
    calls = []
    sim = Simulation(_planets(), **options)
    with monkeypatch.context() as patched:
        for name in names:  # (Ctrl-C in the third call: mid-leg)
            patched.setattr(kernels, name, _pressing(getattr(kernels, name), _nth(3, calls)))
        cut = sim.integrate(8.0, on_interrupt="keep")
    assert len(calls) == 3 and not cut.complete
    assert 0.0 < sim.t < 8.0  # (the state reached between outputs is the one kept)
    sim.integrate(12.0)
    assert sim.steps == once.steps
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.system.as_arrays().r)
    np.testing.assert_array_equal(sim.system.as_arrays().v, once.system.as_arrays().v)


def test_held_raises_as_it_is_left_and_a_second_ctrl_c_at_once():
    with pytest.raises(KeyboardInterrupt), HELD:
        HELD.interrupt()
        reached = True  # (held: the block goes on to its end)
    assert reached and HELD.depth == 0 and not HELD.pending
    with pytest.raises(KeyboardInterrupt), HELD:
        HELD.interrupt()
        HELD.interrupt()  # (a second: raised here, not held)
        pytest.fail("the second Ctrl-C was held")  # pragma: no cover
    assert HELD.depth == 0 and not HELD.pending


def test_a_ctrl_c_left_pending_outside_is_not_raised_by_the_next_call(monkeypatch):
    """A second Ctrl-C between ``__exit__``'s count and its look at ``pending`` is
    raised at once (HELD is then at depth 0) and leaves the first's ``pending``: it
    was raised again, stale, as the next call's HELD was left."""
    monkeypatch.setattr(HELD, "pending", True)  # (as that second Ctrl-C leaves it)
    try:
        with HELD:
            pass
    except KeyboardInterrupt:  # (caught: pytest would take it for the user's own)
        pytest.fail("the stale Ctrl-C was raised")
    assert not HELD.pending


def test_an_error_within_is_not_replaced_by_the_ctrl_c_held():
    with pytest.raises(ZeroDivisionError), HELD:
        HELD.interrupt()
        1 / 0  # noqa: B018
    assert HELD.depth == 0 and not HELD.pending
    with pytest.raises(KeyboardInterrupt):  # (outside: at once)
        HELD.interrupt()


_REAL = textwrap.dedent("""
    import json, os, signal, sys, threading
    import numpy as np
    from hamilton_orbits import Body, Simulation, System

    bodies = [Body("star", 1.0, [0, 0, 0], [0, 0, 0])]
    for k, a in enumerate(np.linspace(1.0, 6.0, 9)):
        bodies.append(Body(f"p{k}", 1e-5, [a, 0.0, 0.01 * k], [0.0, a ** -0.5, 0.0]))
    system = System(bodies)
    Simulation(system, method="wh", dt=2.0 ** -10).integrate(1.0)  # (kernels loaded)
    sim = Simulation(system, method="wh", dt=2.0 ** -10)
    timer = threading.Timer(0.15, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    cut = sim.integrate(2000.0, on_interrupt="keep")  # (some 1 s: cut at 0.15 s)
    timer.join()
    t_cut = float(sim.t)
    sim.integrate(2000.0)
    once = Simulation(system, method="wh", dt=2.0 ** -10)
    once.integrate(2000.0)
    print(json.dumps(dict(complete=cut.complete, t_cut=t_cut, steps=[sim.steps, once.steps],
                          dr=float(np.abs(sim.system.as_arrays().r
                                          - once.system.as_arrays().r).max()))))
""")


def test_a_real_ctrl_c_in_a_wh_run_keeps_a_state_that_continues_bit_for_bit():
    """SIGINT from a timer 0.15 s into a run of some 1 s (2 million steps in slices of
    100 000, some 0.05 s each): the Ctrl-C comes in a compiled call."""
    proc = subprocess.run([sys.executable, "-c", _REAL], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.splitlines()[-1])
    assert not out["complete"] and 0.0 < out["t_cut"] < 2000.0, out
    assert out["steps"][0] == out["steps"][1] and out["dr"] == 0.0, out


@pytest.mark.parametrize("options", [
    dict(), dict(events=[{"name": "close_encounter", "distance": 0.01}]),
    dict(variational=True)], ids=["plain", "events", "variational"])
def test_a_ctrl_c_in_a_dop853_step_keeps_the_state_of_its_steps(options, monkeypatch):
    """dop853 steps through scipy's stepper in Python: a Ctrl-C in a step kept the
    state of the last output (t = 0 here: a one-end-time run lost all its work),
    with events the steps taken since counted; the state kept is now the last
    step's, with its count."""
    from scipy.integrate import DOP853

    options = dict(method="dop853", **options)
    once = Simulation(_planets(), **options)
    once.integrate(12.0)
    real, reached = DOP853.step, []

    def step(solver):
        out = real(solver)
        reached.append(solver.t)
        if len(reached) == 3:  # (the Python handler, within the step)
            signal.getsignal(signal.SIGINT)(signal.SIGINT, None)
        return out

    sim = Simulation(_planets(), **options)
    with monkeypatch.context() as patched:
        patched.setattr(DOP853, "step", step)
        cut = sim.integrate(8.0, on_interrupt="keep")
    assert not cut.complete and len(reached) == 3
    assert sim.t == reached[-1] > 0.0 and sim.steps == 3
    sim.integrate(12.0)  # (its own steps from there, laid apart from the run's after the
    # cut: the two agree to the method's error at its default tolerance, 2e-14 au here)
    np.testing.assert_allclose(sim.system.as_arrays().r, once.system.as_arrays().r,
                               rtol=0, atol=1e-12)


def _merging() -> System:
    """Two bodies falling into contact (they merge about t = 1.4) and a bystander."""
    return System([Body("a", 1.0, [0, 0, 0], [0, 0.01, 0], radius=0.01),
                   Body("b", 0.5, [1.0, 0, 0], [0, -0.02, 0.005], radius=0.02),
                   Body("c", 0.0, [5.0, 0, 0], [0, 0.4, 0])])


#: (Simulation options, the kernels' module and the watched kernels' names: the
#: call that stops at the event, and the status it returns it with)
EVENT_CASES = {
    "radau15": (dict(method="radau15"), radau15_kernels, ["advance_watched"]),
    "wh": (dict(method="wh", dt=DT), wh_kernels, ["advance_dh_watched"]),
    "leapfrog": (dict(method="leapfrog", dt=DT), leapfrog_kernels, ["advance_watched"]),
}


@pytest.mark.parametrize("case", sorted(EVENT_CASES))
def test_a_ctrl_c_in_the_call_that_finds_a_merge_leaves_it_done(case, monkeypatch):
    """The call that stops at an event returns early; a Ctrl-C anywhere in it was
    raised as the steps were counted, before the event's action: the bodies stayed
    apart, and the next leg found them in contact at its start and recorded the
    collision again.  The action is now taken before the Ctrl-C is raised."""
    options, kernels, names = EVENT_CASES[case]
    options = dict(options, events=[{"name": "collision", "action": "merge"}])
    once = Simulation(_merging(), **options)
    whole = once.integrate(3.0)
    pressed = []
    at_event = _first(lambda out: out[-1] == kernels.STATUS_EVENT, pressed)
    sim = Simulation(_merging(), **options)
    with monkeypatch.context() as patched:
        for name in names:
            patched.setattr(kernels, name, _pressing(getattr(kernels, name), at_event))
        cut = sim.integrate(3.0, on_interrupt="keep")
    assert pressed and not cut.complete and len(cut.events) == 1
    assert len(sim.system.names) == 2  # (merged: a + b, and c)
    rest = sim.integrate(3.0)
    assert len(rest.events) == 0 and sim.steps == once.steps
    assert len(whole.events) == 1
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.system.as_arrays().r)


def test_a_ctrl_c_in_a_dop853_step_that_holds_an_event_leaves_it_found(monkeypatch):
    """dop853 scans each step for events after taking it: a Ctrl-C in the step
    was raised before its scan, and the continued run began after the step, so
    that the step's events were never found (nor their actions taken)."""
    from hamilton_orbits._kernels import events as event_kernels

    options = dict(method="dop853", events=[{"name": "collision", "action": "merge"}])
    once = Simulation(_merging(), **options)
    once.integrate(3.0)
    pressed = []
    scan = _pressing(event_kernels.scan_steps, _first(lambda out: out[0] >= 0, pressed))
    sim = Simulation(_merging(), **options)
    with monkeypatch.context() as patched:  # (Ctrl-C in the step holding the event)
        patched.setattr(event_kernels, "scan_steps", scan)
        cut = sim.integrate(3.0, on_interrupt="keep")
    assert pressed and not cut.complete and len(cut.events) == 1
    assert len(sim.system.names) == 2
    assert len(sim.integrate(3.0).events) == 0
    # (both restart the stepper at the merge; the cut run's leg after it is a call of
    # its own: its steps agree with the run's to the method's error)
    np.testing.assert_allclose(sim.system.as_arrays().r, once.system.as_arrays().r,
                               rtol=0, atol=1e-12)


def test_python_s_default_handler_put_back_is_replaced_again(monkeypatch):
    """Jupyter puts Python's default SIGINT handler back before each cell: the held
    handler, installed once, was then gone for good, and a Ctrl-C in a compiled
    call left the state a slice ahead again (8 au off over the rest of the run)."""
    options, kernels, names, driver, slice_steps = CASES["wh"]
    monkeypatch.setattr(driver, "SLICE", slice_steps)
    once = Simulation(_planets(), **options)
    once.integrate(12.0)  # (the held handler installed)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # (a new cell)
    try:
        calls = []
        kernel = _pressing(getattr(kernels, names[1]), _nth(3, calls))
        sim = Simulation(_planets(), **options)
        with monkeypatch.context() as patched:
            patched.setattr(kernels, names[1], kernel)
            cut = sim.integrate(8.0, on_interrupt="keep")
        assert len(calls) == 3 and not cut.complete
        sim.integrate(12.0)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert sim.steps == once.steps
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.system.as_arrays().r)


@pytest.mark.parametrize("case", [*sorted(EVENT_CASES), "dop853"])
def test_a_ctrl_c_in_the_call_that_finds_a_stop_is_raised(case, monkeypatch):
    """A stop found in the call a Ctrl-C came in: the stop's ``StopAtEvent`` was
    raised within HELD, which then let the Ctrl-C go (a run asked to raise on
    Ctrl-C returned, stopped); the Ctrl-C is raised, the state the stop's."""
    from hamilton_orbits._kernels import events as event_kernels

    if case == "dop853":
        options, kernels, names = dict(method="dop853"), event_kernels, ["scan_steps"]
    else:
        options, kernels, names = EVENT_CASES[case]
    options = dict(options, events=[{"name": "collision", "action": "stop"}])
    once = Simulation(_merging(), **options)
    t_stop = float(once.integrate(3.0).t[-1])
    pressed = []
    at_event = _first((lambda out: out[0] >= 0) if case == "dop853" else
                      (lambda out: out[-1] == kernels.STATUS_EVENT), pressed)
    sim = Simulation(_merging(), **options)
    with monkeypatch.context() as patched:
        for name in names:
            patched.setattr(kernels, name, _pressing(getattr(kernels, name), at_event))
        with pytest.raises(KeyboardInterrupt):
            sim.integrate(3.0)
    assert pressed and sim.t == t_stop < 3.0


@pytest.mark.parametrize(("method", "how"), [("wh", "ctrl-c"), ("wh", "stop"),
                                           ("radau15-dd", "ctrl-c")])
def test_a_cut_mid_interval_goes_on_with_the_bits_of_the_run_never_cut(method, how,
                                                                       monkeypatch):
    """A step not a power of two (0.01): the leg going on from a cut laid the cut
    interval's steps again from the time reached, its last step rounded otherwise
    (the run never cut's bits lost).  It lays them from the interval's start."""
    if method == "wh":
        options, kernels, name, end = dict(method="wh", dt=0.01), wh_kernels, \
            "advance_dh_few", 100.0
        monkeypatch.setattr(wh, "SLICE", 1000)
    else:
        options, kernels, name, end = dict(method="radau15", dt=0.01,
                                           precision="double-double"), radau15_dd, \
            "advance", 2.0
        monkeypatch.setattr(radau15, "SLICE", 2000)  # (slices of 20 steps)
    once = Simulation(_planets(), **options)
    once.integrate(end)
    sim = Simulation(_planets(), **options)
    if how == "stop":
        looks = []
        cut = sim.integrate(end, stop=lambda: len(looks.append(1) or looks) >= 3,
                            on_interrupt="keep")
    else:
        with monkeypatch.context() as patched:
            patched.setattr(kernels, name, _pressing(getattr(kernels, name), _nth(3, [])))
            cut = sim.integrate(end, on_interrupt="keep")
    assert not cut.complete and 0.0 < sim.t < end
    sim.integrate(end)
    assert sim.steps == once.steps
    np.testing.assert_array_equal(sim.system.as_arrays().r, once.system.as_arrays().r)


def test_a_ctrl_c_while_a_kernel_compiles_is_raised_at_once():
    """A Ctrl-C while numba compiles a call's kernel (a first run, seconds on a
    cold cache) was held like one during its steps: it waited for the compilation
    and then for the first slice of steps.  No step is taken yet: it is raised at
    once (a real compilation, the Ctrl-C pressed as it starts), and the function
    compiles when called again."""
    import numba
    from numba.core import event

    from hamilton_orbits.integrators._held import HELD

    @numba.njit
    def kernel(x):
        return x + 1.0

    class Press(event.Listener):
        def on_start(self, ev):
            signal.getsignal(signal.SIGINT)(signal.SIGINT, None)

        def on_end(self, ev):
            pass

    reached = []
    with event.install_listener("numba:compile", Press()):
        with pytest.raises(KeyboardInterrupt):
            with HELD:
                reached.append(kernel(1.0))
    assert reached == [] and not HELD.pending and HELD.depth == 0
    assert kernel(1.0) == 2.0


def test_a_ctrl_c_held_in_a_file_section_that_fails_is_raised_not_lost():
    """A held file section (``held``: Simulation.save's write, the archive's) that
    raised (a full disk) while a Ctrl-C was held cleared it: the caller that handled
    the error went on as if no Ctrl-C had come.  The Ctrl-C is raised, the error its
    cause; a section that ends well raises it as before."""
    from hamilton_orbits.integrators._held import held

    @held
    def fails():
        signal.getsignal(signal.SIGINT)(signal.SIGINT, None)  # (a Ctrl-C within)
        raise OSError("No space left on device")

    @held
    def ends():
        signal.getsignal(signal.SIGINT)(signal.SIGINT, None)
        return 1

    with pytest.raises(KeyboardInterrupt) as info:
        fails()
    assert isinstance(info.value.__cause__, OSError)
    with pytest.raises(KeyboardInterrupt):
        ends()
    assert HELD.depth == 0 and not HELD.pending
