"""Entry kernels: an explicit signature, compiled at the first call, not at import.

numba compiles a function decorated with an explicit signature when the module is
imported.  The stepping kernels of every method are imported together (the
integrators' package imports them all), so the first run of one method used to
compile the kernels of all of them: the main job (radau15) spent 70 of its 126 s
of compilation on Wisdom-Holman, tangent and corrector kernels it never called.

:func:`entry` keeps the explicit signature (arguments converted to it, one
machine-code version, the same cache entry as before) but compiles on the first
call: the first call of the kernel object, which then puts the compiled dispatcher
in its module under its own name, so that later calls through the module
(``_k.advance(...)``) go straight to numba with no wrapper in between.
"""

from __future__ import annotations

import atexit
import os
import subprocess
import sys
import threading
import time
import types
from collections.abc import Callable, Sequence
from typing import Any

from numba import njit
from numba.core.registry import CPUDispatcher

__all__ = ["compile_ahead", "entry", "on_disk"]

_lock = threading.Lock()
#: Kernels being compiled into the on-disk cache by another process
#: (:func:`compile_ahead`): ``module.name`` -> that process
_AHEAD: dict[str, subprocess.Popen] = {}
#: What to compile here while waiting for that process (:func:`compile_ahead`)
_MEANWHILE: list[Callable[[], object]] = []


class EntryKernel:
    """A numba function with one explicit signature, compiled on its first call.

    Calling it compiles (or loads from the on-disk cache) the signature, binds the
    compiled dispatcher in the defining module in place of this object, and calls
    it.  :meth:`dispatcher` gives the compiled dispatcher.

    Examples
    --------
    >>> from numba import types
    >>> twice = EntryKernel(lambda x: 2.0 * x, types.float64(types.float64), {})
    >>> twice.compiled
    False
    >>> twice(3)
    6.0
    >>> twice.compiled, twice.dispatcher().signatures
    (True, [(float64,)])
    """

    def __init__(self, py_func: Any, signature: Any, options: dict[str, Any]) -> None:
        self.py_func = py_func
        self.signature = signature
        self.options = options
        self._compiled: CPUDispatcher | None = None
        self.__name__ = py_func.__name__
        self.__qualname__ = py_func.__qualname__
        self.__module__ = py_func.__module__
        self.__doc__ = py_func.__doc__

    @property
    def compiled(self) -> bool:
        """Whether the signature has been compiled (or loaded from the cache)."""
        return self._compiled is not None

    @property
    def key(self) -> str:
        """``module.name``, as :func:`compile_ahead` and its helper process name it."""
        return f"{self.__module__}.{self.__name__}"

    def cached(self) -> bool:
        """Whether numba's on-disk cache holds the signature (True when it cannot
        tell: nothing is then compiled ahead)."""
        try:
            disp = njit(**self.options)(self.py_func)
            return disp._cache.load_overload(self.signature, disp.targetctx) is not None
        except Exception:  # (numba's cache API is its own: never fail a run on it)
            return True

    def dispatcher(self) -> CPUDispatcher:
        """The numba dispatcher, its signature compiled and further compilation off
        (when another process is compiling it into the cache, after waiting for
        it: then loaded, not compiled twice)."""
        if self._compiled is None:
            with _lock:
                if self._compiled is None:
                    _wait_for(self.key)
                    disp = njit(**self.options)(self.py_func)
                    disp.compile(self.signature)
                    disp.disable_compile()
                    module = sys.modules.get(self.__module__)
                    if module is not None and getattr(module, self.__name__, None) is self:
                        setattr(module, self.__name__, disp)
                    self._compiled = disp
        return self._compiled

    def __call__(self, *args: Any) -> Any:
        return self.dispatcher()(*args)

    def __repr__(self) -> str:
        state = "compiled" if self.compiled else "not compiled yet"
        return f"<entry kernel {self.__module__}.{self.__qualname__} ({state})>"


def on_disk(dispatcher: Any, args: tuple) -> bool:
    """Whether numba's on-disk cache holds the lazily compiled ``dispatcher`` (an
    ``njit(cache=True)`` function) for the types of ``args``, without compiling it
    (True when it cannot tell: the caller then compiles, as it would have).

    Examples
    --------
    >>> from numba import njit
    >>> on_disk(njit(cache=False)(lambda x: x + 1), (1.0,))  # (no cache: cannot tell)
    True
    """
    try:
        from numba import typeof

        cache = dispatcher._cache
        if type(cache).__name__ == "NullCache":  # (no cache: nothing to look at)
            return True
        sig = tuple(typeof(a) for a in args)
        return cache.load_overload(sig, dispatcher.targetctx) is not None
    except Exception:  # (numba's cache API is its own: never fail a run on it)
        return True


def compile_ahead(kernels: Sequence[EntryKernel],
                  meanwhile: Sequence[Callable[[], object]] = ()) -> list[str]:
    """Compile ``kernels`` that are neither compiled here nor in numba's on-disk
    cache in a second process, into that cache, while this one goes on (compiling
    what it needs meanwhile: the first run's compilation then takes about the
    longer of the two instead of their sum on two cores).  A first call of one of
    them waits for that process and loads it from the cache; if the process
    failed, the call compiles it as before.  ``meanwhile``: calls that compile
    what this process will need later, made while it waits (their errors
    ignored: the later call meets them).  The names of those sent ahead.

    ``HAMILTON_ORBITS_COMPILE_AHEAD=0`` turns it off; on one core (nothing to gain),
    with numba's JIT disabled, or for a kernel not cached on disk, nothing is sent.
    """
    if os.environ.get("HAMILTON_ORBITS_COMPILE_AHEAD", "1") == "0" or os.environ.get(
            "NUMBA_DISABLE_JIT", "0") not in ("", "0") or _cores() < 2:
        return []
    todo = [k for k in kernels if isinstance(k, EntryKernel) and not k.compiled
            and k.key not in _AHEAD and k.options.get("cache") and not k.cached()]
    if not todo:
        return []
    code = ("import importlib, sys\n"
            "for key in sys.argv[1:]:\n"
            "    module, name = key.rsplit('.', 1)\n"
            "    getattr(importlib.import_module(module), name).dispatcher()\n"
            "    print(key, flush=True)\n")
    try:
        proc = subprocess.Popen([sys.executable, "-c", code, *(k.key for k in todo)],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                stdin=subprocess.DEVNULL, text=True)
    except OSError:  # (no second process here: each is compiled at its first call)
        return []
    for k in todo:
        _AHEAD[k.key] = proc
    _MEANWHILE.extend(meanwhile)
    from hamilton_orbits import firstrun

    firstrun.notice()
    return [k.key for k in todo]


def _cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # (not on Linux)
        return os.cpu_count() or 1


def _wait_for(key: str) -> None:
    """Wait until the process compiling ``key`` ahead has saved it (or ended)."""
    proc = _AHEAD.pop(key, None)
    if proc is None:
        return
    while _MEANWHILE:  # (compiled here, beside that process, before waiting on it)
        try:
            _MEANWHILE.pop(0)()
        except Exception:
            pass
    start = time.perf_counter()
    done = set()
    while key not in done:  # (the keys it printed, in its order)
        line = proc.stdout.readline() if proc.stdout is not None else ""
        if not line:
            break
        done.add(line.strip())
    for other in done - {key}:
        _AHEAD.pop(other, None)
    if not any(p is proc for p in _AHEAD.values()):
        _end(proc)
    from hamilton_orbits import firstrun  # (its clock: the wait is the first run's)

    short = key.removeprefix("hamilton_orbits._kernels.")
    firstrun.add_compilation(f"{short} (waited for, compiled in a second process)",
                             time.perf_counter() - start)


def _end(proc: subprocess.Popen, stop: bool = False) -> None:
    """Wait for (``stop``: end) a process compiling ahead, its pipe closed."""
    if stop:
        proc.terminate()
    if proc.stdout is not None:
        proc.stdout.close()
    proc.wait()


@atexit.register
def _stop_ahead() -> None:
    """End the processes still compiling ahead when this one ends."""
    for proc in set(_AHEAD.values()):
        _end(proc, stop=True)
    _AHEAD.clear()
    _MEANWHILE.clear()


def entry(signature: Any, name: str | None = None, **options: Any) -> Any:
    """Decorator: ``njit(signature, **options)``, compiled at the first call.

    ``name``: the kernel's name, when one Python body serves several entries
    (each with its own signature, e.g. ``None`` for the arguments of a feature it
    goes without, pruned at compile time).  The entry then *is* that body, not a
    wrapper calling it: numba optimises a callee's machine code again in every
    caller it is linked into, so a wrapper level costs a second optimisation of the
    whole loop (0.6 s of radau15's first run, measured).

    Examples
    --------
    >>> from numba import types
    >>> @entry(types.int64(types.int64), cache=False)
    ... def inc(i):
    ...     return i + 1
    >>> inc(41), inc.compiled
    (42, True)
    >>> def _add(i, j=None):
    ...     return i if j is None else i + j
    >>> plus = entry(types.int64(types.int64, types.int64), name="plus", cache=False)(_add)
    >>> same = entry(types.int64(types.int64, types.none), name="same", cache=False)(_add)
    >>> plus(1, 2), same(1, None), plus.__name__
    (3, 1, 'plus')
    """

    def wrap(py_func: Any) -> EntryKernel:
        if name is not None:
            py_func = _renamed(py_func, name)
        return EntryKernel(py_func, signature, options)

    return wrap


def _renamed(fn: Any, name: str) -> Any:
    """A copy of the Python function ``fn`` named ``name`` (numba's cache files are
    named after it: each entry keeps its own)."""
    new = types.FunctionType(fn.__code__, fn.__globals__, name, fn.__defaults__, fn.__closure__)
    new.__qualname__ = name
    new.__doc__ = fn.__doc__
    new.__module__ = fn.__module__
    return new
