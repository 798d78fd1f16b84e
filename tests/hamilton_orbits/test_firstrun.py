"""The first-compile notice: one line on stderr, only when a kernel of the
package really compiles, at most once per process."""

from __future__ import annotations

import gc
import os
import subprocess
import sys
import types
from pathlib import Path

import pytest
from numba import njit
from numba.core import event

from hamilton_orbits import firstrun

SRC = str(Path(__file__).resolve().parents[2] / "src")


def _fresh_function(module: str):
    """A new function whose ``__module__`` is ``module`` (never compiled before)."""
    code = compile("def probe(x):\n    return 2.0 * x + 1.0\n", "<probe>", "exec")
    namespace: dict = {"__name__": module}
    exec(code, namespace)  # a fixed source text
    func = namespace["probe"]
    return types.FunctionType(func.__code__, namespace, "probe")


def test_notice_once_when_our_kernel_compiles(monkeypatch, capsys):
    monkeypatch.setitem(firstrun._state, "printed", False)
    assert njit(_fresh_function("hamilton_orbits._probe"))(1.0) == 3.0
    assert njit(_fresh_function("hamilton_orbits._probe"))(2.0) == 5.0
    err = capsys.readouterr().err
    assert err == firstrun.NOTICE + "\n"  # one line, once


def test_no_notice_for_other_packages(monkeypatch, capsys):
    monkeypatch.setitem(firstrun._state, "printed", False)
    assert njit(_fresh_function("someone_else"))(1.0) == 3.0
    assert capsys.readouterr().err == ""
    assert firstrun._state["printed"] is False


def _run(code: str, cache_dir: str | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=SRC)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    return subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600
    )


CALL = "from hamilton_orbits import solve_kepler; print(float(solve_kepler(0.5, 0.1)))"


class _GcAtStart(event.Listener):
    """Records whether the garbage collector runs when each compilation starts."""

    def __init__(self) -> None:
        self.seen: list[bool] = []

    def on_start(self, ev: event.Event) -> None:
        self.seen.append(gc.isenabled())

    def on_end(self, ev: event.Event) -> None:
        pass


@pytest.mark.parametrize(("module", "paused"), [("hamilton_orbits._probe", True),
                                                ("someone_else", False)])
def test_the_garbage_collector_pauses_while_our_kernels_compile(module, paused):
    """Paused from the start of the package's compilation to its end, restored after;
    another package's compilation is left alone."""
    listener = _GcAtStart()
    with event.install_listener("numba:compile", listener):
        assert njit(_fresh_function(module))(1.0) == 3.0
    assert listener.seen and listener.seen[0] is not paused
    assert gc.isenabled()


def test_a_paused_collector_stays_paused():
    """A collector the caller turned off is not turned on by a compilation."""
    gc.disable()
    try:
        assert njit(_fresh_function("hamilton_orbits._probe"))(1.0) == 3.0
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_no_notice_when_warm():
    first = _run(CALL)  # warms the cache if needed (may print the notice)
    assert first.returncode == 0, first.stderr[-2000:]
    second = _run(CALL)
    assert second.returncode == 0, second.stderr[-2000:]
    assert second.stderr == ""
    assert second.stdout == first.stdout


@pytest.mark.slow
def test_notice_on_cold_cache(tmp_path):
    cold = _run(CALL, str(tmp_path))
    assert cold.returncode == 0, cold.stderr[-2000:]
    assert cold.stderr.splitlines() == [firstrun.NOTICE]
    warm = _run(CALL, str(tmp_path))
    assert warm.stderr == ""


def _caller_of(module: str):
    """A fresh function calling another fresh one (a nested compilation)."""
    inner = njit(_fresh_function(module))
    namespace: dict = {"__name__": module, "inner": inner}
    exec(compile("def outer(x):\n    return inner(x) + 1.0\n", "<outer>", "exec"), namespace)
    return namespace["outer"]


def test_compile_clock_counts_outermost_compilations():
    seconds, count = firstrun.compile_seconds(), firstrun.compile_count()
    assert njit(_caller_of("someone_else"))(1.0) == 4.0
    assert firstrun.compile_count() - count == 1  # the callee's compilation is inside
    assert firstrun.compile_seconds() > seconds


def test_claim_names_what_was_compiled():
    """The summary's line names the kernels compiled since the last claim (the
    outermost function of each compilation), with their seconds."""
    firstrun.claim_compilation()
    assert njit(_caller_of("hamilton_orbits._probe_claim"))(1.0) == 4.0
    seconds, count = firstrun.claim_compilation()
    named = firstrun.last_claim()
    assert count == 1 and [name for name, _ in named] == ["_probe_claim.outer"]
    assert named[0][1] == pytest.approx(seconds, rel=1e-12)
    assert firstrun.describe(named).startswith("_probe_claim.outer ")
    firstrun.claim_compilation()
    assert firstrun.last_claim() == []  # nothing compiled since


def test_integration_time_excludes_compilation():
    """What the summary and the cross-check table call the integration time: the
    trajectory's wall time less the compilation inside the integrator's call (a first
    run compiles the stepping kernel on its first call): here an output callback
    compiles a function inside the timed call."""
    import time

    from hamilton_orbits import Body, Simulation, System

    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
    sim = Simulation(s, method="leapfrog", dt=0.01)
    sim.integrate(0.1)  # the stepping kernel loaded or compiled: not part of what is measured

    def compile_on_output(i: int, steps: int) -> None:
        assert njit(_caller_of("hamilton_orbits._probe_timing"))(1.0) == 4.0  # compiles

    compiled = firstrun.compile_seconds()
    start = time.perf_counter()
    traj = sim.integrate(0.2, on_output=compile_on_output)
    total = time.perf_counter() - start
    compiled = firstrun.compile_seconds() - compiled
    assert compiled > 0.01  # numba needs tens of ms at least to compile two functions
    # what is left is the call itself, not the compilation (both clocks are perf_counter)
    assert traj.wall_time < total - 0.9 * compiled


@pytest.mark.slow  # a cold cache compiles the radau15 path: ~20-40 s on 2 loaded cores
def test_cold_run_reports_compilation_apart(tmp_path):
    code = ("from hamilton_orbits import Scene; "
            "r = Scene.bundled('mercury-gr').with_values({'duration': '2 yr'}).run("
            "progress=False); print(r.wall_time, r.compile_time, r.compile_count); "
            "print(r.summary())")
    env_dirs = {"HAMILTON_ORBITS_CACHE_DIR": str(tmp_path / "ho")}
    cold = _run_env(code, str(tmp_path / "numba"), env_dirs)
    assert cold.returncode == 0, cold.stderr[-2000:]
    wall, compile_time, count = cold.stdout.splitlines()[0].split()
    assert int(count) > 0 and float(compile_time) > 1.0
    assert float(wall) < 0.5 * float(compile_time)
    assert "compiled: " in cold.stdout and "first run only" in cold.stdout
    warm = _run_env(code, str(tmp_path / "numba"), env_dirs)
    assert warm.returncode == 0, warm.stderr[-2000:]
    assert warm.stdout.splitlines()[0].split()[2] == "0"  # the second process compiles nothing
    assert "compiled: nothing" in warm.stdout


def _run_env(code: str, cache_dir: str, extra: dict) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=SRC, NUMBA_CACHE_DIR=cache_dir, **extra)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=900)


def test_session_notice_when_numba_cache_is_cold(tmp_path, monkeypatch):
    """tests/conftest.py says in one line that the first tests compile kernels."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "suite_conftest", Path(__file__).resolve().parents[1] / "conftest.py")
    conftest = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conftest)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert conftest.numba_cache_cold()
    nested = tmp_path / "some" / "path"
    nested.mkdir(parents=True)
    (nested / "radau15.step-42.py311.nbi").write_bytes(b"")
    assert not conftest.numba_cache_cold()


_AHEAD_MODULE = """
from numba import types
from hamilton_orbits._kernels.entry import entry


@entry(types.float64(types.float64), cache=True)
def triple(x):
    return 3.0 * x + {k}.0
"""


def _ahead_module(tmp_path, monkeypatch, name: str, k: int, importable_there: bool):
    """A module with one entry kernel (cached), new to numba's cache, importable
    here and (``importable_there``) in a second process."""
    import importlib

    (tmp_path / f"{name}.py").write_text(_AHEAD_MODULE.format(k=k))
    monkeypatch.syspath_prepend(str(tmp_path))
    if importable_there:
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
            [str(tmp_path), SRC, os.environ.get("PYTHONPATH", "")]))
    return importlib.import_module(name)


def test_a_kernel_compiled_ahead_is_loaded_from_the_cache_and_its_wait_counted(
        tmp_path, monkeypatch):
    """compile_ahead sends a kernel neither compiled nor cached to a second process;
    its first call here waits for it and loads it from numba's cache (a hit, no
    compilation here), and the wait counts as the first run's compilation."""
    from hamilton_orbits._kernels.entry import compile_ahead

    monkeypatch.delenv("HAMILTON_ORBITS_COMPILE_AHEAD", raising=False)
    mod = _ahead_module(tmp_path, monkeypatch, "ahead_probe_sent", 1, True)
    kernel = mod.triple
    assert compile_ahead([kernel]) == ["ahead_probe_sent.triple"]
    assert compile_ahead([kernel]) == []  # (already on its way: not sent twice)
    before, count = firstrun.compile_seconds(), firstrun.compile_count()
    assert kernel(2.0) == 7.0
    stats = kernel.dispatcher().stats
    assert sum(stats.cache_hits.values()) == 1 and sum(stats.cache_misses.values()) == 0
    assert firstrun.compile_count() == count + 1 and firstrun.compile_seconds() > before
    assert firstrun._compiled[-1][0] == ("ahead_probe_sent.triple (waited for, compiled in "
                                          "a second process)")
    assert compile_ahead([kernel]) == []  # compiled here now


def test_a_kernel_the_second_process_cannot_compile_is_compiled_here(tmp_path, monkeypatch):
    """A second process that fails (here: it cannot import the kernel's module)
    costs nothing but its wait: the first call compiles the kernel as before."""
    from hamilton_orbits._kernels.entry import compile_ahead

    monkeypatch.delenv("HAMILTON_ORBITS_COMPILE_AHEAD", raising=False)
    monkeypatch.setenv("PYTHONPATH", SRC)
    mod = _ahead_module(tmp_path, monkeypatch, "ahead_probe_failed", 2, False)
    kernel = mod.triple  # (the module's name is bound to numba's dispatcher at the call)
    assert compile_ahead([kernel]) == ["ahead_probe_failed.triple"]
    assert kernel(2.0) == 8.0
    assert sum(kernel.dispatcher().stats.cache_misses.values()) == 1  # compiled here


def test_compile_ahead_can_be_turned_off(tmp_path, monkeypatch):
    from hamilton_orbits._kernels.entry import compile_ahead

    monkeypatch.setenv("HAMILTON_ORBITS_COMPILE_AHEAD", "0")
    mod = _ahead_module(tmp_path, monkeypatch, "ahead_probe_off", 3, True)
    assert compile_ahead([mod.triple]) == [] and mod.triple(1.0) == 6.0


def test_nothing_is_compiled_ahead_on_one_core(tmp_path, monkeypatch):
    from hamilton_orbits._kernels import entry

    monkeypatch.delenv("HAMILTON_ORBITS_COMPILE_AHEAD", raising=False)
    monkeypatch.setattr(entry, "_cores", lambda: 1)
    mod = _ahead_module(tmp_path, monkeypatch, "ahead_probe_one_core", 4, True)
    assert entry.compile_ahead([mod.triple]) == [] and mod.triple(1.0) == 7.0


def test_compilation_before_the_timed_steps_is_not_taken_from_them(monkeypatch):
    """A compilation in the call but before the steps begin (a right-hand side
    compiled when the integrator is made for it: the force of no effect is compiled
    on demand) is not in the integration time, so it is not subtracted from it
    either: the main job's cold run once showed "1000 yr in 0.00 s of integration".
    Here making the integrator is made to count 100 s of compilation."""
    from hamilton_orbits import Body, Simulation, System
    from hamilton_orbits.engine import Propagation

    made = Propagation.driver_for

    def compiling(self, backward):
        firstrun._clock["seconds"] += 100.0  # (as numba's listener adds a compilation)
        return made(self, backward)

    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 1e-3, [1, 0, 0], [0, 1, 0])])
    monkeypatch.setitem(firstrun._clock, "seconds", firstrun._clock["seconds"])
    monkeypatch.setattr(Propagation, "driver_for", compiling)
    traj = Simulation(s, method="leapfrog", dt=1e-3).integrate(20.0)  # 20,000 steps
    assert 0.0 < traj.wall_time < 100.0
