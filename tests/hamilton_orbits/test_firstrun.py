"""The first-compile notice: one line on stderr, only when a kernel of the
package really compiles, at most once per process."""

from __future__ import annotations

import os
import subprocess
import sys
import types
from pathlib import Path

import pytest
from numba import njit

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
