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

from hamilton_orbits import _firstrun

SRC = str(Path(__file__).resolve().parents[2] / "src")


def _fresh_function(module: str):
    """A new function whose ``__module__`` is ``module`` (never compiled before)."""
    code = compile("def probe(x):\n    return 2.0 * x + 1.0\n", "<probe>", "exec")
    namespace: dict = {"__name__": module}
    exec(code, namespace)  # a fixed source text
    func = namespace["probe"]
    return types.FunctionType(func.__code__, namespace, "probe")


def test_notice_once_when_our_kernel_compiles(monkeypatch, capsys):
    monkeypatch.setitem(_firstrun._state, "printed", False)
    assert njit(_fresh_function("hamilton_orbits._probe"))(1.0) == 3.0
    assert njit(_fresh_function("hamilton_orbits._probe"))(2.0) == 5.0
    err = capsys.readouterr().err
    assert err == _firstrun.NOTICE + "\n"  # one line, once


def test_no_notice_for_other_packages(monkeypatch, capsys):
    monkeypatch.setitem(_firstrun._state, "printed", False)
    assert njit(_fresh_function("someone_else"))(1.0) == 3.0
    assert capsys.readouterr().err == ""
    assert _firstrun._state["printed"] is False


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
    assert cold.stderr.splitlines() == [_firstrun.NOTICE]
    warm = _run(CALL, str(tmp_path))
    assert warm.stderr == ""
