"""Serial / parallel dispatch of the batch kernels, and a thread-safe threading layer.

A loop over ``prange`` pays for itself only above some size: below it the
start-up and join of the thread team cost more than the work, and on a loaded
machine an OpenMP team can busy-wait for a core another process holds (calls
on two orbits took up to 15 ms).  :func:`parallel_kernel` compiles a batch
kernel twice, with ``parallel=True`` and without (``prange`` is then
``range``), and calls the parallel one only for at least ``threshold`` rows
and, while the load average leaves no core free, only for at least
:data:`BUSY_THRESHOLD` rows.

The threading layer must be chosen before numba starts its first thread team.
``workqueue`` aborts the process when two Python threads launch parallel
kernels at the same time; ``omp`` and ``tbb`` do not.  So, unless the user
chose a layer (``NUMBA_THREADING_LAYER``), the package asks numba for a
thread-safe one when one of them can be loaded.  If the layer in use is still
``workqueue`` (chosen by the user, or nothing else available), parallel launches
are serialised by a lock: a thread that finds the lock taken runs the serial
variant instead of waiting.

Both variants are cached on disk (``cache=True``): the serial one is compiled
from a copy of the Python function under another ``__qualname__``, so that the
two never share a cache entry.
"""

from __future__ import annotations

import contextlib
import inspect
import os
import re
import tempfile
import threading
import time
import types
from collections.abc import Callable, Iterator
from typing import Any

import numba
from numba import njit

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

# Rows below which the serial variant runs.  The elements kernel costs ~0.15-0.25
# us a row; a parallel launch some 10-50 us on idle cores, so there it pays from a
# few thousand rows on.  But when another process holds a core, a launch costs a
# scheduler time slice instead: measured 15 ms per launch on the 2-core
# development machine shared with other jobs, at 256 rows as at 16384, even with
# a load average below the core count (the load average lags bursts).  65536
# rows (~15 ms serially) bound that stall to about the work itself, and still
# gain on free cores.  With the load average at the core count the serial
# variant runs whatever the size (see _cores_busy).
DEFAULT_THRESHOLD = 65536
# Rows from which the parallel variant runs even while the load average reaches
# the core count.  Another process then holds a core, but the scheduler shares
# the cores among runnable threads: a team of two gets two shares where one
# thread gets one (measured with 4 other jobs on the 2-core machine: propagate of
# 1e6 orbits 1.4-1.8x faster on two threads), and 2^19 rows (~45 ms of
# propagation) make the launch's wait for a time slice (~15 ms) the smaller part.
BUSY_THRESHOLD = 2**19
_LOAD_TTL = 1.0  # seconds between two reads of the load average

_SAFE_LAYERS = ("tbb", "omp")
_layer_lock = threading.Lock()
_launch_lock = threading.Lock()
_state: dict[str, Any] = {"layer": None, "load_t": -1e9, "busy": False}


def _cores_busy() -> bool:
    """Whether the 1-minute load average reaches the number of cores (read at
    most once a second): a thread team would then wait for time slices."""
    now = time.monotonic()
    if now - _state["load_t"] > _LOAD_TTL:
        try:
            busy = os.getloadavg()[0] >= (os.cpu_count() or 1)
        except (AttributeError, OSError):  # pragma: no cover - no load average (Windows)
            busy = False
        _state["busy"] = busy
        _state["load_t"] = now
    return _state["busy"]


def _loadable(layer: str) -> bool:
    """Whether numba's ``layer`` threading backend can be loaded here."""
    try:
        if layer == "tbb":
            from numba.np.ufunc import tbbpool  # noqa: F401
        elif layer == "omp":
            from numba.np.ufunc import omppool  # noqa: F401
        else:  # pragma: no cover - only the two above are asked for
            return False
    except (ImportError, OSError):
        return False
    return True


def _choose_layer() -> str:
    """Pick a thread-safe layer (once, before numba's first thread launch) and
    return the name of the layer numba then uses."""
    with _layer_lock:
        if _state["layer"] is not None:
            return _state["layer"]
        from numba.np.ufunc import parallel as _npar

        user_chose = "NUMBA_THREADING_LAYER" in os.environ
        if not user_chose and not _npar._is_initialized:
            if numba.config.THREADING_LAYER == "default" and any(
                _loadable(x) for x in _SAFE_LAYERS
            ):
                numba.config.THREADING_LAYER = "threadsafe"
        _npar._launch_threads()
        layer = numba.threading_layer()
        _state["layer"] = layer
        return layer


def _serial_copy(func: Callable) -> Callable:
    """A copy of ``func`` with its own ``__qualname__`` (its own cache entry)."""
    copy = types.FunctionType(
        func.__code__, func.__globals__, func.__name__ + "_serial",
        func.__defaults__, func.__closure__,
    )
    copy.__qualname__ = func.__qualname__ + "_serial"
    copy.__module__ = func.__module__
    copy.__doc__ = func.__doc__
    return copy


class ParallelKernel:
    """A batch kernel compiled twice; calls dispatch on the number of rows.

    The number of rows is ``args[0].shape[0]``.  Attributes ``serial`` and
    ``parallel`` are the two numba dispatchers, ``py_func`` the Python function.
    """

    def __init__(self, func: Callable, threshold: int) -> None:
        self.py_func = func
        self.threshold = threshold
        self.parallel = njit(cache=True, parallel=True)(func)
        self.serial = njit(cache=True)(_serial_copy(func))
        self.__doc__ = func.__doc__
        self.__name__ = func.__name__
        self.__qualname__ = func.__qualname__
        self.__module__ = func.__module__

    def __call__(self, *args: Any) -> Any:
        rows = args[0].shape[0]
        if rows < self.threshold or (rows < max(BUSY_THRESHOLD, self.threshold)
                                     and _cores_busy()):
            return self.serial(*args)
        layer = _state["layer"] or _choose_layer()
        if layer != "workqueue":
            return self.parallel(*args)
        # workqueue is not thread-safe: one parallel launch at a time
        if not _launch_lock.acquire(blocking=False):
            return self.serial(*args)
        try:
            return self.parallel(*args)
        finally:
            _launch_lock.release()

    def __repr__(self) -> str:
        return f"ParallelKernel({self.__qualname__}, threshold={self.threshold})"


def parallel_kernel(
    func: Callable | None = None, *, threshold: int = DEFAULT_THRESHOLD
) -> Any:
    """Decorator: ``@parallel_kernel`` or ``@parallel_kernel(threshold=n)``.

    Replaces ``@njit(cache=True, parallel=True)`` on a batch kernel whose first
    argument has one row per item.

    Examples
    --------
    >>> import numpy as np
    >>> from hamilton_orbits._kernels.elements import state_to_elements, empty_elements
    >>> state_to_elements  # doctest: +ELLIPSIS
    ParallelKernel(state_to_elements, threshold=...)
    >>> out = empty_elements(1)
    >>> state_to_elements(np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]), np.ones(1), out)
    >>> float(out[0, 1])  # a circle (served by the serial variant: one row)
    0.0
    """
    if func is None:
        return lambda f: ParallelKernel(f, threshold)
    return ParallelKernel(func, threshold)


@contextlib.contextmanager
def one_process_at_a_time(func: Callable, cached: bool) -> Iterator[None]:
    """Hold an exclusive lock on a file of ``func``'s own beside numba's cache of it
    (:func:`lock_path`) while the block runs: one process at a time builds a
    cached (g)ufunc; the others wait, then load what it wrote.

    numba caches a generalised ufunc as two files, the kernel and its loop
    wrapper, and the wrapper calls the kernel by a symbol whose tag counts the
    compilations of the process that made it.  Two processes compiling the same
    gufunc at once (Dask workers, a cluster's array job, a parallel test run,
    all from a cold cache) can leave a kernel from one and a wrapper from the
    other: every later call, in every later process, dies of a segmentation
    fault (numba issue #10128, open in numba 0.68).  Under the lock the second
    process finds both files written by the first and loads them.  (An entry
    kernel is cached as one file and needs no lock to be safe; a lock tried to
    spare the second process its compilation gained nothing measurable: the
    suite's cold run on two workers took 363 s locked, 331 s unlocked, 2026-11-29,
    a spread the machine shows alone.)  Where files cannot be locked (no
    ``fcntl``: Windows; a file system that refuses) the block runs unlocked."""
    if not cached or fcntl is None:
        yield
        return
    try:
        fd = os.open(lock_path(func), os.O_RDWR | os.O_CREAT, 0o666)
    except OSError:  # (a folder numba reads but cannot write: it compiles in memory)
        yield
        return
    try:
        with contextlib.suppress(OSError):  # (no locks on this file system)
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # (closing releases the lock)


def lock_path(func: Callable) -> str:
    """The lock file of :func:`one_process_at_a_time` for ``func``: named for its
    module and name, in the folder numba caches it in.

    Examples
    --------
    >>> from hamilton_orbits._kernels.quaternion import qmul_gufunc
    >>> os.path.basename(lock_path(qmul_gufunc.py_func))
    'hamilton_orbits._kernels.quaternion.qmul_gufunc.lock'
    """
    name = re.sub(r"[^\w.-]", "_", f"{func.__module__}.{func.__qualname__}")
    return os.path.join(_cache_dir(func), name + ".lock")


def _cache_dir(func: Callable) -> str:
    """The folder numba caches ``func`` in: the first of its locators that
    applies (``NUMBA_CACHE_DIR``, beside the source, the user's cache), as
    numba's own cache chooses; the temporary folder if none does."""
    from numba.core import caching

    source = inspect.getfile(func)
    for locator in (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator,
                    caching.UserWideCacheLocator):
        try:
            found = locator.from_function(func, source)
            if found is not None:
                found.ensure_cache_path()
                return found.get_cache_path()
        except OSError:
            continue
    return tempfile.gettempdir()


class LazyUfunc:
    """A numba (g)ufunc built on first use instead of at import.

    ``@vectorize([...])`` and ``@guvectorize([...])`` with explicit signatures
    compile (or load from the cache) when the module is imported, which costs
    about a second before the first call of anything.  This wrapper defers that
    to the first call; attributes (``nin``, ``reduce``, ...) are those of the
    built ufunc.  With ``cache=True`` the build runs under
    ``_dispatch.one_process_at_a_time`` (why: numba issue #10128, told there).
    """

    def __init__(self, builder: Callable, args: tuple, kwargs: dict, func: Callable) -> None:
        self._builder = builder
        self._args = args
        self._kwargs = kwargs
        self._ufunc: Any = None
        self._lock = threading.Lock()
        self.py_func = func
        self.__doc__ = func.__doc__
        self.__name__ = func.__name__
        self.__qualname__ = func.__qualname__
        self.__module__ = func.__module__

    def _build(self) -> Any:
        with self._lock:
            if self._ufunc is None:
                with one_process_at_a_time(self.py_func, self._kwargs.get("cache", False)):
                    self._ufunc = self._builder(*self._args, **self._kwargs)(self.py_func)
        return self._ufunc

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return (self._ufunc or self._build())(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") or name in ("_builder", "_args", "_kwargs", "_ufunc", "_lock"):
            raise AttributeError(name)
        return getattr(self._ufunc or self._build(), name)

    def __repr__(self) -> str:
        state = "built" if self._ufunc is not None else "not built"
        return f"LazyUfunc({self.__qualname__}, {state})"

    def __reduce__(self) -> str:
        """Pickled by name, as a module's function is (its lock is not picklable:
        ``pool.map(solve_ufunc, ...)`` failed "cannot pickle '_thread.lock'"); the
        other process finds it in its module, built there on first use."""
        return self.__qualname__


def lazy_vectorize(*args: Any, **kwargs: Any) -> Any:
    """``numba.vectorize`` with its arguments, built on first use; as numba's, also
    bare (``@lazy_vectorize`` over a function: a ufunc compiled for the types it is
    called with).

    Examples
    --------
    >>> from hamilton_orbits._kernels.kepler import solve_ufunc
    >>> float(solve_ufunc(0.0, 0.5))
    0.0
    >>> import numpy as np
    >>> @lazy_vectorize
    ... def twice(x):
    ...     return 2 * x
    >>> twice(np.arange(3.0)).tolist()
    [0.0, 2.0, 4.0]
    """
    from numba import vectorize

    if len(args) == 1 and not kwargs and callable(args[0]) and not isinstance(args[0], str):
        return LazyUfunc(vectorize, (), {}, args[0])
    return lambda func: LazyUfunc(vectorize, args, kwargs, func)


def lazy_guvectorize(*args: Any, **kwargs: Any) -> Callable[[Callable], LazyUfunc]:
    """``numba.guvectorize`` with its arguments, built on first use (with
    ``cache=True`` by one process at a time: see :class:`LazyUfunc`).

    Examples
    --------
    >>> import numpy as np
    >>> from hamilton_orbits._kernels.quaternion import qmul_gufunc
    >>> qmul_gufunc(np.array([0.0, 1, 0, 0]), np.array([0.0, 0, 1, 0])).tolist()
    [0.0, 0.0, 0.0, 1.0]
    """
    from numba import guvectorize

    return lambda func: LazyUfunc(guvectorize, args, kwargs, func)
