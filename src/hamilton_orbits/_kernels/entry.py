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

import sys
import threading
from typing import Any

from numba import njit
from numba.core.registry import CPUDispatcher

__all__ = ["entry"]

_lock = threading.Lock()


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

    def dispatcher(self) -> CPUDispatcher:
        """The numba dispatcher, its signature compiled and further compilation off."""
        if self._compiled is None:
            with _lock:
                if self._compiled is None:
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


def entry(signature: Any, **options: Any) -> Any:
    """Decorator: ``njit(signature, **options)``, compiled at the first call.

    Examples
    --------
    >>> from numba import types
    >>> @entry(types.int64(types.int64), cache=False)
    ... def inc(i):
    ...     return i + 1
    >>> inc(41), inc.compiled
    (42, True)
    """

    def wrap(py_func: Any) -> EntryKernel:
        return EntryKernel(py_func, signature, options)

    return wrap
