"""Serial / parallel dispatch of the batch kernels, and calls from several threads.

Invariants only: the parallel and the serial variant run the same per-row code,
so their results must agree bit for bit, whichever thread calls them.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from hamilton_orbits import KeplerOrbit
from hamilton_orbits._kernels import _dispatch
from hamilton_orbits._kernels import elements as _el
from hamilton_orbits._kernels._dispatch import ParallelKernel

SRC = str(Path(__file__).resolve().parents[2] / "src")


def _states(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    r = rng.normal(size=(n, 3))
    v = rng.normal(size=(n, 3)) * 0.8
    return r, v


def test_serial_when_cores_are_busy(monkeypatch):
    monkeypatch.setattr(_dispatch, "_cores_busy", lambda: True)
    calls = []
    kernel = _el.state_to_elements
    monkeypatch.setattr(kernel, "parallel", lambda *a: calls.append("parallel"))
    monkeypatch.setattr(kernel, "serial", lambda *a: calls.append("serial"))
    big = np.zeros((kernel.threshold, 3))
    kernel(big, big, np.ones(len(big)), np.empty((len(big), _el.NCOL)))
    kernel(big[:2], big[:2], np.ones(2), np.empty((2, _el.NCOL)))
    assert calls == ["serial", "serial"]
    monkeypatch.setattr(_dispatch, "_cores_busy", lambda: False)
    kernel(big, big, np.ones(len(big)), np.empty((len(big), _el.NCOL)))
    assert calls[-1] == "parallel"


def test_load_average_is_read_at_most_once_a_second(monkeypatch):
    reads = []
    monkeypatch.setattr(_dispatch.os, "getloadavg", lambda: reads.append(1) or (0.0, 0.0, 0.0))
    monkeypatch.setitem(_dispatch._state, "load_t", -1e9)
    assert _dispatch._cores_busy() is False
    assert _dispatch._cores_busy() is False
    assert len(reads) == 1


def test_batch_kernels_are_dispatched():
    for name in ("state_to_elements", "state_to_time_since_periapsis", "check_copy_state",
                 "elements_to_state"):
        kernel = getattr(_el, name)
        assert isinstance(kernel, ParallelKernel), name
        assert kernel.threshold > 1


def test_serial_and_parallel_agree_bitwise():
    n = _el.state_to_elements.threshold + 7
    r, v = _states(n, 1)
    mu = np.ones(n)
    a = np.empty((n, _el.NCOL))
    b = np.empty((n, _el.NCOL))
    _el.state_to_elements.serial(r, v, mu, a)
    _el.state_to_elements.parallel(r, v, mu, b)
    np.testing.assert_array_equal(a, b)


def _work(seed: int) -> list[np.ndarray]:
    out = []
    for n in (1, 2, 50, _el.state_to_elements.threshold + 1):
        r, v = _states(n, seed)
        o = KeplerOrbit.from_state(r, v, 1.0)
        out.append(np.stack([o.a, o.e, o.inc, o.lan, o.argp, o.nu, o.M]))
        out.append(np.concatenate(o.propagate(0.25).state(), axis=-1))
    return out


def test_calls_from_four_threads(monkeypatch):
    monkeypatch.setattr(_dispatch, "_cores_busy", lambda: False)  # parallel above threshold
    for name in ("state_to_elements", "state_to_elements_classical", "check_copy_state"):
        monkeypatch.setattr(getattr(_el, name), "threshold", 1000)  # small parallel calls
    expected = [_work(seed) for seed in range(8)]
    with ThreadPoolExecutor(max_workers=4) as pool:
        got = list(pool.map(_work, range(8)))
    for e, g in zip(expected, got, strict=True):
        for x, y in zip(e, g, strict=True):
            np.testing.assert_array_equal(x, y)


def test_threads_with_workqueue_layer_do_not_abort():
    # workqueue aborts the process ("Terminating: Nested parallel kernel launch
    # detected") when two threads launch parallel kernels at once; the
    # dispatcher serialises launches under it.  Needs a fresh process: the layer
    # is fixed at numba's first launch.
    code = textwrap.dedent(
        """
        from concurrent.futures import ThreadPoolExecutor
        import numpy as np
        import numba
        from hamilton_orbits import KeplerOrbit
        from hamilton_orbits._kernels import elements as _el, _dispatch

        _dispatch._cores_busy = lambda: False  # launch in parallel even on a loaded machine
        for k in (_el.state_to_elements_classical, _el.check_copy_state):
            k.threshold = 1000  # many small parallel launches, quickly
        n = 4000
        def work(seed):
            rng = np.random.default_rng(seed)
            s = 0.0
            for _ in range(10):
                o = KeplerOrbit.from_state(rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), 1.0)
                s += float(np.sum(o.e))
            return s
        with ThreadPoolExecutor(max_workers=4) as pool:
            res = list(pool.map(work, range(8)))
        assert res == [work(i) for i in range(8)]
        assert _dispatch._state["layer"] == "workqueue"  # parallel launches did happen
        print(numba.threading_layer())
        """
    )
    env = dict(os.environ, NUMBA_THREADING_LAYER="workqueue", PYTHONPATH=SRC)
    proc = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "workqueue"
