"""Generalised ufuncs built on first use, one process at a time (hamilton_orbits.ufuncs).

numba caches a generalised ufunc as two files, the kernel and its loop wrapper; two
processes compiling it at once from a cold cache can leave a mismatched pair that
kills every later caller with a segmentation fault (numba issue #10128).  Measured
here before the lock (2026-11-28, numba 0.68.1): four processes started together on
two cores, then a fifth, left a poisoned cache in 2 of 6 trials with plain
``numba.guvectorize``; with the lock in 0 of 6.
"""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import numba
import numpy as np

from hamilton_orbits import ufuncs
from hamilton_orbits._kernels import _dispatch
from rigid._kernels import euler


def test_the_public_names_are_the_private_objects():
    assert ufuncs.lazy_guvectorize is _dispatch.lazy_guvectorize
    assert ufuncs.lazy_vectorize is _dispatch.lazy_vectorize


def test_rigid_builds_its_gufuncs_through_the_lock():
    for name in ("euler_gufunc", "qdot_gufunc", "gibbs_dot_gufunc", "gibbs_omega_gufunc",
                 "torque_gufunc"):
        assert isinstance(getattr(euler, name), ufuncs.LazyUfunc), name


def test_a_cached_build_waits_for_the_lock(tmp_path, monkeypatch):
    """While another holder has the lock beside the cache, the build does not start;
    it starts, and gives the right values, once the lock is released."""
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    source = tmp_path / "gu_mod.py"
    source.write_text(textwrap.dedent("""
        def twice(x, out):
            for i in range(x.shape[0]):
                out[i] = 2.0 * x[i]
    """))
    namespace: dict = {}
    exec(compile(source.read_text(), str(source), "exec"), namespace)
    func = namespace["twice"]
    func.__module__ = "gu_mod"
    gufunc = ufuncs.lazy_guvectorize(["void(float64[:], float64[:])"], "(n)->(n)",
                                     cache=True)(func)
    lock = Path(_dispatch.lock_path(func))
    assert lock.parent.is_relative_to(tmp_path)
    fd = os.open(lock, os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    out: list = []
    worker = threading.Thread(target=lambda: out.append(gufunc(np.arange(3.0))))
    worker.start()
    worker.join(1.0)
    assert worker.is_alive() and repr(gufunc) == "LazyUfunc(twice, not built)"
    os.close(fd)  # (releases the lock)
    worker.join(60.0)
    assert not worker.is_alive()
    assert out[0].tolist() == [0.0, 2.0, 4.0]


def test_processes_building_at_once_leave_a_cache_later_processes_load(tmp_path):
    """Four processes build two two-signature gufuncs at once from an empty cache,
    then a fifth loads them: every process exits normally with the right values
    (unlocked, the fifth died of a segmentation fault in 2 of 6 such trials)."""
    (tmp_path / "gu_race.py").write_text(textwrap.dedent("""
        from hamilton_orbits.ufuncs import lazy_guvectorize

        SIGS2 = ["void(float64[:], float64[:], float64[:])",
                 "void(float32[:], float32[:], float32[:])"]

        @lazy_guvectorize(SIGS2, "(n),(n)->(n)", cache=True, nopython=True)
        def g(a, b, out):
            for i in range(a.shape[0]):
                out[i] = a[i] * b[i] + 1.0

        @lazy_guvectorize(["void(float64[:], float64[:])", "void(float32[:], float32[:])"],
                          "(n)->(n)", cache=True, nopython=True)
        def h(a, out):
            for i in range(a.shape[0]):
                out[i] = a[i] - 1.0
    """))
    call = textwrap.dedent("""
        import numpy as np, gu_race
        x = np.arange(3.0)
        assert gu_race.g(x, x).tolist() == [1.0, 2.0, 5.0]
        assert gu_race.h(x.astype(np.float32)).tolist() == [-1.0, 0.0, 1.0]
        assert gu_race.g(x.astype(np.float32), x.astype(np.float32)).tolist() == [1.0, 2.0, 5.0]
        print("ok")
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join([str(tmp_path), *sys.path]))
    together = [subprocess.Popen([sys.executable, "-c", call], env=env, cwd=tmp_path,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                for _ in range(4)]
    results = [p.communicate(timeout=300) + (p.returncode,) for p in together]
    later = subprocess.run([sys.executable, "-c", call], env=env, cwd=tmp_path,
                           capture_output=True, text=True, timeout=300)
    for out, err, code in [*results, (later.stdout, later.stderr, later.returncode)]:
        assert (code, out.strip()) == (0, "ok"), err[-2000:]


def test_a_lazy_ufunc_pickles_by_name():
    """``pool.map(solve_ufunc, ...)`` failed: "cannot pickle '_thread.lock'" (the lazy
    wrapper's lock).  A lazy ufunc pickles by name, as a module's function does, and
    comes back as the same object (built in the other process on first use)."""
    import pickle

    from hamilton_orbits._kernels.kepler import solve_ufunc
    from hamilton_orbits._kernels.quaternion import qmul_gufunc

    for f in (solve_ufunc, qmul_gufunc):
        assert pickle.loads(pickle.dumps(f)) is f
    # (the bytes name the module and the ufunc: another process finds it there)
    assert b"hamilton_orbits._kernels.kepler" in pickle.dumps(solve_ufunc)
